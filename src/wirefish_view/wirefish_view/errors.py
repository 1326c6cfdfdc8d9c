"""The errors of wirefish_view."""


class ViewError(Exception):
    """Base of the view's errors."""


class RefusedInput(ViewError):
    """A client's message that the view does not pass on (the reason is the message)."""


class UnknownType(ViewError):
    """A message type whose definition is not installed (no share/<pkg>/msg/<Type>.msg)."""
