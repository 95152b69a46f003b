"""The readers' public names where they were first published; each format lives in its own module
under :mod:`evinr_lite.io.formats` (``npy``, ``txt``, ``ijrr``, ``evreal``, ``hqf``, ``canonical``,
``aedat4``, ``prophesee``), and :mod:`evinr_lite.io.formats.registry` detects and dispatches.

Every reader returns :class:`~evinr_lite.core.events.Events` (or a :class:`Recording`: events plus
ground-truth frames plus metadata) in the package conventions: t float64 seconds relative to
``t_origin``, x column, y row, p in {-1, +1}, sensor_size (H, W).
"""
from .formats.evreal import read_evreal_folder
from .formats.hqf import read_h5
from .formats.ijrr import read_frames_ijrr, read_ijrr_folder
from .formats.npy import read_events_npy
from .formats.registry import SUPPORTED_FORMATS, detect_format, read_events, read_recording
from .formats.txt import read_events_txt

__all__ = ["read_events_npy", "read_events_txt", "read_frames_ijrr", "read_ijrr_folder", "read_evreal_folder",
           "read_h5", "read_recording", "read_events", "detect_format", "SUPPORTED_FORMATS"]
