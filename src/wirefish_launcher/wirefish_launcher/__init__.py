# SPDX-License-Identifier: Apache-2.0
"""Process management: wirefish up, its supervisor and status, the emulated board, two hosts."""
