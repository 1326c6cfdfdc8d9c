# SPDX-License-Identifier: Apache-2.0
"""
A stop asked for by SIGINT or SIGTERM, acted on by the process's own loop between two steps.

`wirefish up` and `wirefish twohost` stop what they started before they exit, so a signal must
not end them where it arrives: ``stop_on_signals()`` makes both signals set a ``StopFlag``,
which their loops read. The handlers run in the main thread, the loops' own: a bool does.
"""

from dataclasses import dataclass
import signal


@dataclass
class StopFlag:
    """Whether a stop was asked for; ``request`` is a signal handler."""

    requested: bool = False

    def request(self, _signum: int = 0, _frame: object = None) -> None:
        """Ask for the stop (the signature of a signal handler)."""
        self.requested = True


def stop_on_signals() -> StopFlag:
    """Return a flag that SIGINT and SIGTERM set from now on, instead of ending the process."""
    flag = StopFlag()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, flag.request)
    return flag
