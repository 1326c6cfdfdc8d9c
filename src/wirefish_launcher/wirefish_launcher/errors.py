# SPDX-License-Identifier: Apache-2.0
"""The errors of wirefish_launcher that a caller may catch and report in one line."""


class QemuBoardError(RuntimeError):
    """The emulated fish board could not be built, started or found on its pseudo-terminal."""
