"""The one exception type for bad input, and its message template.

Every check on user input in polind (model parameters, motion files, system
files, command-line options) raises :class:`InputError`, a ``ValueError``
whose message is one line naming the parameter, file, row or key, the value
received and what was expected.  The command line turns it into exit status
2 (the documentation's "Command line", :ref:`cli-exit-status`).
"""

from __future__ import annotations

__all__ = ["InputError", "describe"]


class InputError(ValueError):
    """Bad input: a one-line message names what, where, got and expected."""

    def __init__(self, message: str):
        # Keep the message on one line whatever the caller built.
        super().__init__(" ".join(str(message).split()))


class ValidityWarning(UserWarning):
    """A result computed outside the validity of its physics (e.g. elastic asperities at
    pressures no metal bears): it is returned, and this says plainly why it may be wrong."""


def describe(value) -> str:
    """Short printable form of a received value for error messages.

    >>> describe(10 ** 5000)
    'an integer of 5001 digits'

    A NumPy scalar reads as its number, not as its type (NumPy 2's repr):

    >>> import numpy as np
    >>> describe(np.float64("nan")), describe(np.int64(3))
    ('nan', '3')
    """
    if type(value).__module__ == "numpy" and getattr(value, "shape", None) == () \
            and hasattr(value, "item"):
        value = value.item()       # np.float64(2.5) -> 2.5, np.float32 -> its exact double
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 200:
        # repr refuses integers of more than 4300 digits: count them instead.
        digits = len(str(abs(value))) if value.bit_length() < 14000 else \
            int(value.bit_length() * 0.30102999566398120) + 1
        return f"an integer of {digits} digits"
    try:
        text = repr(value)
    except (ValueError, RecursionError):
        text = f"a {type(value).__name__} that cannot be printed"
    return text if len(text) <= 60 else text[:57] + "..."
