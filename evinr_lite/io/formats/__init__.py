"""One module per recording format; each declares a :class:`~.base.FileFormat` (suffixes, sniffing,
sensor size, time unit, windowed reading, reader), and :mod:`.registry` derives detection,
``read_recording``, ``SUPPORTED_FORMATS`` and the capability tables from them."""
from .aedat4 import read_aedat4
from .base import FileFormat
from .prophesee import RAW_VERSIONS, read_prophesee
from .registry import (FIXED_UNITS, FORMATS, READER_WINDOW_FORMATS, RECORDING_SUFFIXES, SENSOR_ARG_FORMATS,
                       SIZE_FREE_FORMATS, SUPPORTED_FORMATS, TIME_UNIT_FORMATS, detect_format, get_format,
                       is_recording_folder, is_ros2_bag, read_events, read_recording, recording_path, sniff_format)

__all__ = ["read_aedat4", "read_prophesee", "sniff_format", "RAW_VERSIONS", "FileFormat", "FORMATS", "get_format",
           "detect_format", "read_recording", "read_events", "is_recording_folder", "is_ros2_bag", "SUPPORTED_FORMATS",
           "RECORDING_SUFFIXES", "SIZE_FREE_FORMATS", "READER_WINDOW_FORMATS", "SENSOR_ARG_FORMATS",
           "TIME_UNIT_FORMATS", "FIXED_UNITS", "recording_path"]
