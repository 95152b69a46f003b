"""What a recording holds, read without torch: ``evinr-lite info`` imports only this, io and core.

The loading knowledge lives in :mod:`evinr_lite.io.load` (the formats' capabilities come from
their declarations in :mod:`evinr_lite.io.formats`); these names are kept here for the apps.
"""
from __future__ import annotations

from ..io.load import (FIXED_UNITS, READER_WINDOW_FORMATS, SENSOR_ARG_FORMATS, SIZE_FREE_FORMATS,  # noqa: F401
                       TIME_UNIT_FORMATS, describe_recording, format_info, open_recording, read_any)

__all__ = ["read_any", "open_recording", "describe_recording", "format_info", "SIZE_FREE_FORMATS",
           "READER_WINDOW_FORMATS", "SENSOR_ARG_FORMATS", "TIME_UNIT_FORMATS", "FIXED_UNITS"]
