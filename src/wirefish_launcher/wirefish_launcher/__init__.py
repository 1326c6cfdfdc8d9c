"""Process management: wirefish up, its supervisor and status, the emulated board, two hosts."""
