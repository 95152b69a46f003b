"""`Recording`: the events of one recording with its ground-truth frames and metadata."""
from __future__ import annotations

from dataclasses import dataclass

from .events import EventDataError, Events
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

    def __post_init__(self):
        from .checks import require   # checked where it enters, in the API's one message style

        require(self.events, Events, "events")
        require(self.frames, Frames, "frames", none_ok=True)
        if not isinstance(self.meta, dict):
            raise EventDataError(f"meta= must be a dict (e.g. {{'format': 'npy', 'path': 'events.npy'}}, or {{}}), "
                                 f"got {type(self.meta).__name__}")

    def __repr__(self) -> str:
        return f"Recording({self.meta.get('format')!r}, {self.events!r}, frames={self.frames!r})"
