"""Files in and out: one module per format (formats/), detection, loading a window, streaming sources,
the canonical HDF5 format, export, sample data."""
from .readers import (read_recording, read_events, detect_format, SUPPORTED_FORMATS, read_events_npy, read_events_txt, read_ijrr_folder, read_evreal_folder, read_h5)
from .formats import read_aedat4, read_prophesee
from .canonical import CanonicalWriter, read_canonical, iter_canonical_events, canonical_info, is_canonical
from .export import save_frames_png, save_gif, save_mp4, save_timestamps, save_csv
from .output import atomic_output_dir, save_png, save_json
from .sample_data import find_shared_data, sample_recording_path
from .source import RecordingSource, as_source
from .load import open_recording, read_any, load_recording, describe_recording, format_info
from .notes import ReadNote

__all__ = ["read_recording", "read_events", "detect_format", "SUPPORTED_FORMATS",
           "read_events_npy", "read_events_txt", "read_ijrr_folder", "read_evreal_folder",
           "read_h5", "read_aedat4", "read_prophesee", "CanonicalWriter", "read_canonical",
           "iter_canonical_events", "canonical_info", "is_canonical", "save_frames_png",
           "save_gif", "save_mp4", "save_timestamps", "save_csv", "atomic_output_dir", "save_png",
           "save_json", "find_shared_data", "sample_recording_path", "RecordingSource", "open_recording",
           "as_source", "read_any", "load_recording", "describe_recording", "format_info", "ReadNote"]
