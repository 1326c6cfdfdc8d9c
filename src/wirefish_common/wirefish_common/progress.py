# SPDX-License-Identifier: Apache-2.0
"""
Progress of a long command: a bar on a terminal, a line per step otherwise, with an estimate.

``Progress(label, total)``; ``step(done, text)`` after each finished step. On a terminal the
bar is redrawn in place; into a file or pipe each step is one line (at most one per
``LINE_EVERY`` of the total, so a log stays readable). The estimate is the time so far per
step times the steps left. ``end_line()`` ends a bar left mid-line, so that whatever is
printed next (an interruption's one line) starts on a line of its own.
"""

from __future__ import annotations

from collections.abc import Callable
import math
import sys
import time
from typing import TextIO

BAR_WIDTH = 24
LINE_EVERY = 0.05  # of the total, between two lines when not on a terminal
_open_bars: list[Progress] = []


def duration_text(seconds: float) -> str:
    """Return ``seconds`` for a person: '45 s', '3 min 20 s', '1 h 05 min'."""
    seconds = max(0.0, seconds)
    if seconds < 60.0:
        return f'{seconds:.0f} s'
    minutes, secs = divmod(int(round(seconds)), 60)
    if minutes < 60:
        return f'{minutes} min {secs:02d} s'
    hours, minutes = divmod(minutes, 60)
    return f'{hours} h {minutes:02d} min'


def estimate_text(done: int, total: int, elapsed_s: float) -> str:
    """Return what is left: 'about 2 min 10 s left', or 'estimating' before the first step."""
    if done >= total:
        return f'done in {duration_text(elapsed_s)}'
    if done <= 0 or not math.isfinite(elapsed_s):
        return 'estimating'
    return f'about {duration_text(elapsed_s / done * (total - done))} left'


def progress_text(label: str, done: int, total: int, elapsed_s: float, text: str = '',
                  bar: bool = False) -> str:
    """Return one progress line: label, (bar,) done/total, the estimate, the step's text."""
    shown = f'{label}: '
    if bar:
        filled = round(BAR_WIDTH * min(done, total) / total) if total else BAR_WIDTH
        shown += f'[{"#" * filled}{"." * (BAR_WIDTH - filled)}] '
    shown += f'{done}/{total}, {estimate_text(done, total, elapsed_s)}'
    return f'{shown} | {text}' if text else shown


class Progress:
    """The progress of ``total`` steps, shown on ``stream`` (stderr by default)."""

    def __init__(self, label: str, total: int, stream: TextIO | None = None,
                 clock: Callable[[], float] = time.monotonic) -> None:
        """Start the clock; nothing is shown until the first step."""
        self.label, self.total = label, max(1, total)
        self._stream = stream if stream is not None else sys.stderr
        self._clock = clock
        self._started = clock()
        self._bar = self._stream.isatty()
        self._last_line_fraction = -1.0
        self.done = 0

    def step(self, done: int | None = None, text: str = '') -> None:
        """Show that ``done`` steps (default: one more) are finished; ``text`` says which."""
        self.done = self.done + 1 if done is None else done
        line = progress_text(self.label, self.done, self.total, self._clock() - self._started,
                             text, bar=self._bar)
        if self._bar:
            self._stream.write(f'\r\x1b[K{line}')
            if self.done >= self.total:
                self._stream.write('\n')
                _forget(self)
            elif self not in _open_bars:
                _open_bars.append(self)
        else:
            fraction = self.done / self.total
            if fraction >= 1.0 or fraction - self._last_line_fraction >= LINE_EVERY \
                    or self._last_line_fraction < 0.0:
                self._stream.write(line + '\n')
                self._last_line_fraction = fraction
        self._stream.flush()


def _forget(progress: Progress) -> None:
    if progress in _open_bars:
        _open_bars.remove(progress)


def end_line() -> None:
    """End every bar left mid-line (an interrupted command's next line starts clean)."""
    while _open_bars:
        progress = _open_bars.pop()
        progress._stream.write('\n')
        progress._stream.flush()
