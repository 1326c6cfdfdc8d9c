# SPDX-License-Identifier: Apache-2.0
"""The wirefish command: its verbs come from the installed packages by entry point."""
