"""The wirefish command: its verbs come from the installed packages by entry point."""
