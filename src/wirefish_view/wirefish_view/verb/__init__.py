# SPDX-License-Identifier: Apache-2.0
"""The verbs of the `wirefish` command that this package adds (one module each)."""
