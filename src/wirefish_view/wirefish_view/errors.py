# SPDX-License-Identifier: Apache-2.0
"""The errors of wirefish_view."""

from __future__ import annotations

from enum import Enum


class Refusal(Enum):
    """Why a client's input was refused: the key of the per-client rate limit of statuses."""

    CHANNEL = 'channel'        # a client channel other than cmd_vel as a Twist
    UNADVERTISED = 'unadvertised'  # a message on a channel the view did not accept
    MALFORMED = 'malformed'    # not a Twist, not JSON, a bad service request
    OUT_OF_LIMITS = 'out of limits'  # a Twist outside the drive limits


class ViewError(Exception):
    """Base of the view's errors."""


class RefusedInput(ViewError):
    """A client's message that the view does not pass on (the reason is the message)."""

    def __init__(self, message: str, kind: Refusal = Refusal.MALFORMED) -> None:
        """Keep the reason and its kind."""
        super().__init__(message)
        self.kind = kind


class UnknownType(ViewError):
    """A message type whose definition is not installed (no share/<pkg>/msg/<Type>.msg)."""
