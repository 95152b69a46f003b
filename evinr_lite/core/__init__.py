"""Events, frames, recordings and runtime choices: the types every layer shares."""
from .events import Events, EventDataError, normalize_polarity, check_sensor_size
from .frames import Frames, to_uint8, to_grey_uint8
from .recording import Recording
from .runtime import default_device, fast_mode, pick, cache_dir, weights_dir

__all__ = ["Events", "EventDataError", "normalize_polarity", "check_sensor_size", "Frames",
           "to_uint8", "to_grey_uint8", "Recording", "default_device", "fast_mode", "pick",
           "cache_dir", "weights_dir"]
