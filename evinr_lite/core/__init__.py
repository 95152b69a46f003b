"""Events, frames, recordings and runtime choices: the types every layer shares.

Names are imported when first used (PEP 562): ``evinr_lite.core.guard`` (the commands' main guard)
must be importable without numpy, so that a command handles signals from its first line.
"""
_HOME = {"Events": "events", "EventDataError": "events", "normalize_polarity": "events",
         "check_sensor_size": "events", "Frames": "frames", "to_uint8": "frames", "to_grey_uint8": "frames",
         "Recording": "recording", "default_device": "runtime", "fast_mode": "runtime", "pick": "runtime",
         "cache_dir": "runtime", "weights_dir": "runtime"}

__all__ = ["Events", "EventDataError", "normalize_polarity", "check_sensor_size", "Frames",
           "to_uint8", "to_grey_uint8", "Recording", "default_device", "fast_mode", "pick",
           "cache_dir", "weights_dir"]


def __getattr__(name):
    import importlib

    if name in _HOME:
        value = getattr(importlib.import_module(f".{_HOME[name]}", __name__), name)
        globals()[name] = value
        return value
    try:
        return importlib.import_module(f".{name}", __name__)   # a submodule: evinr_lite.core.runtime
    except ModuleNotFoundError:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None


def __dir__():
    return sorted(set(globals()) | set(_HOME))
