"""Notes from the readers: what a reader assumed or converted (a unit, a clock, an order), said aloud.

A reader that converts something evident (frame stamps in microseconds against events in seconds,
frames out of time order) does so and says it: a :class:`ReadNote` warning, and the same sentence in
``meta["read_notes"]`` of the Recording, so ``info`` and the run files can show it. Anything not evident
is refused with an EventDataError instead.
"""
from __future__ import annotations

import warnings

__all__ = ["ReadNote", "note"]


class ReadNote(UserWarning):
    """A reader converted or assumed something; the message says what, and how to change it."""


def note(meta: dict | None, message: str) -> None:
    """Warn with ``message`` (a :class:`ReadNote`) and append it to ``meta["read_notes"]`` (when meta is given)."""
    warnings.warn(message, ReadNote, stacklevel=3)
    if meta is not None:
        meta.setdefault("read_notes", []).append(message)
