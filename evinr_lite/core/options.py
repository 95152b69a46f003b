"""One option among a few allowed values, matched by kind: the rule every option argument of the kit goes through.

Below :mod:`evinr_lite.core.events` (which checks its polarity encoding with it) and
:mod:`evinr_lite.core.checks` (which re-exports it with the other argument checks).
"""
from __future__ import annotations

import math
import numbers

import numpy as np

from .guard import EventDataError

__all__ = ["choice", "short_repr"]


def choice(value, allowed, name: str, hint: str | None = None):
    """The entry of ``allowed`` that ``value`` is, else an InputError listing ``allowed`` (and ``hint``: what the
    options mean, in parentheses after them). Options are matched by kind, never with ``==`` across kinds: text as
    text (``np.str_`` too: it is text), whole numbers as whole numbers (numpy's too; not True or False, not a tensor
    or an array), None and other constants as themselves. So an array, a list, a dict, a tensor, a number or None
    given for a text option is named, not numpy's "truth value of an array is ambiguous", Python's "unhashable
    type" or a branch taken without a word. Returns the entry of ``allowed`` (a plain str for an ``np.str_``)."""
    for option in allowed:
        if _same_option(value, option):
            return option
    fix = ""
    texts = [o for o in allowed if isinstance(o, str)]
    if isinstance(value, str):
        close = [o for o in texts if o.lower() == value.strip().lower()]
        if close:
            fix = f"; did you mean {close[0]!r}?"
    elif isinstance(value, (np.ndarray, list, tuple, set, dict)) or type(value).__module__.startswith("torch"):
        size = value.size if isinstance(value, np.ndarray) else value.numel() if hasattr(value, "numel") else \
            len(value) if isinstance(value, (list, tuple)) else 0
        inner = (value.tolist() if hasattr(value, "tolist") else list(value)) if size == 1 else None
        while isinstance(inner, list) and len(inner) == 1:
            inner = inner[0]
        held = next((o for o in allowed if _same_option(inner, o)), None)
        what = f"not a {type(value).__name__}"
        fix = (f"; pass the option itself ({name.rstrip('=')}={held!r}), {what}" if held is not None else
               f"; pass one of them as text (e.g. {name.rstrip('=')}={texts[0]!r}), {what}"
               if len(texts) == len(allowed) else f"; pass one of them itself, {what}")
    about = f" ({hint})" if hint else ""
    raise EventDataError(f"{name} must be one of {tuple(allowed)}{about}, got {short_repr(value)}{fix}")


def _same_option(value, option) -> bool:
    """Whether ``value`` is the option ``option`` (see :func:`choice`): compared only with values of its kind."""
    if isinstance(option, str):
        return isinstance(value, str) and str.__eq__(value, option)
    if option is None:
        return value is None
    if isinstance(option, (bool, np.bool_)):
        return isinstance(value, (bool, np.bool_)) and bool(value) == bool(option)
    if isinstance(option, numbers.Integral):   # a whole float (2.0) is that whole number, as sizes are (whole_number)
        if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
            return False
        return (isinstance(value, numbers.Integral) or (math.isfinite(value) and float(value).is_integer())) \
            and int(value) == option
    return type(value) is type(option) and value == option


def short_repr(value) -> str:
    """``repr(value)`` for a message, cut to about 60 characters (a long array names its type instead)."""
    text = repr(value)
    return text if len(text) <= 60 else f"{type(value).__name__} {text[:50]}..."
