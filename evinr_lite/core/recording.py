"""`Recording`: the events of one recording with its ground-truth frames and metadata."""
from __future__ import annotations

from dataclasses import dataclass

from .events import Events
from .frames import Frames

__all__ = ["Recording"]


@dataclass(frozen=True, eq=False)
class Recording:
    """Events with their ground-truth frames and metadata.

    Attributes:
        events: the event stream.
        frames: ground-truth frames on the same clock (same ``t_origin``) as the events, or None.
        meta: at least ``{"format": str, "path": str}``, plus what the file provides (e.g. ``calib``).
    """

    events: Events
    frames: Frames | None
    meta: dict

    def __repr__(self) -> str:
        return f"Recording({self.meta.get('format')!r}, {self.events!r}, frames={self.frames!r})"
