"""Argument and result checks at the public API's doors: one place for the rules, one message style.

Every public function checks its arguments where they enter, with these helpers, so that a wrong
type or value is an :class:`~evinr_lite.core.events.InputError` naming the argument, what it must
be, what it got and the fix, never an AttributeError, "math domain error" or "has no len()" from
deep inside. The same module checks results: output that is not finite, or constant where the
input is not, is an error (:class:`ResultError`), never a success.
"""
from __future__ import annotations

import math
import numbers

import numpy as np

from .events import EventDataError
from .guard import InputError

__all__ = ["require", "whole_number", "real_number", "check_image_values", "check_result_frames", "ResultError",
           "TypeFix", "ArgumentTypeError", "seconds_array", "optional_seconds", "choice", "is_real_number"]

# (expected class name, given class name) -> how to turn the one into the other
TypeFix = {
    ("Events", "ndarray"): "build them with Events.from_array(array, sensor_size, columns='txyp') (or "
                           "Events(t, x, y, p, sensor_size))",
    ("Events", "Recording"): "pass recording.events (and recording.frames as frames= for anchors)",
    ("Events", "Frames"): "pass the events; frames go as frames=",
    ("Events", "list"): "build them with Events(t, x, y, p, sensor_size)",
    ("Events", "tuple"): "build them with Events(t, x, y, p, sensor_size)",
    ("Frames", "ndarray"): "wrap the images with their timestamps: Frames(images, t) (images [F, H, W], t [F] seconds)",
    ("Frames", "Recording"): "pass recording.frames",
    ("Frames", "list"): "wrap the images with their timestamps: Frames(images, t)",
    ("EvINRConfig", "dict"): "pass EvINRConfig(**that_dict) (or EvINRConfig.paper(**changes))",
    ("Events", "str"): "read the file first: read_recording(path).events",
    ("Events", "PosixPath"): "read the file first: read_recording(path).events",
}


def require(value, kind, name: str, *, none_ok: bool = False):
    """``value`` when it is an instance of ``kind`` (a class or tuple), else an InputError naming ``name``,
    the expected and the given type and, for the usual mix-ups, the fix."""
    if value is None and none_ok:
        return value
    if isinstance(value, kind):
        return value
    kinds = kind if isinstance(kind, tuple) else (kind,)
    want = " or ".join(k.__name__ for k in kinds)
    got = type(value).__name__
    fix = next((TypeFix[(k.__name__, got)] for k in kinds if (k.__name__, got) in TypeFix), None)
    raise EventDataError(f"{name}= must be {want}, got {got}" + (f"; {fix}" if fix else "")
                     + (" (or None)" if none_ok and not fix else ""))


class ArgumentTypeError(EventDataError, TypeError):
    """An argument of the wrong kind (an unknown keyword, frames where none are taken): an InputError whose
    message names the fix, and still a TypeError, as Python raises for a wrong argument."""


def seconds_array(value, name: str, *, allow_empty: bool = False) -> np.ndarray:
    """``value`` (a number, a list or a 1-D array of seconds) as float64 [Q]; else an InputError naming ``name``.

    Refused: text, objects and booleans (not seconds), arrays of 2 or more dimensions (a column [Q, 1] is not
    taken as Q times: pass ``np.ravel(times)``), NaN or inf, and no times at all (unless ``allow_empty``)."""
    arr = np.asarray(value) if not isinstance(value, (str, bytes)) else np.asarray([value])
    if arr.dtype.kind not in "iuf" or arr.dtype == bool:
        raise EventDataError(f"{name}= must be seconds (a number, a list or a 1-D array of numbers), got "
                             f"{_short(value)}")
    arr = np.atleast_1d(arr.astype(np.float64))
    if arr.size == 0 and not allow_empty:
        raise EventDataError(f"{name}= is empty (shape {arr.shape}); pass a non-empty 1-D array: at least one time in "
                             "seconds")
    if arr.ndim != 1:
        raise EventDataError(f"{name}= must be a 1-D array of seconds [Q], got shape {arr.shape}; flatten it "
                             f"with np.ravel({name}) if it holds one time per row")
    finite = np.isfinite(arr)
    if not finite.all():
        bad = int(np.flatnonzero(~finite)[0])
        raise EventDataError(f"{name}= must be finite seconds, but {name}[{bad}] is {arr[bad]}; drop or repair it")
    return arr


def optional_seconds(value, name: str) -> float | None:
    """``value`` as a finite float (seconds), or None when None; else an InputError naming ``name``."""
    if value is None:
        return None
    return real_number(value, name, hint="pass seconds on the events' clock (or None for the default)")


def choice(value, allowed, name: str):
    """``value`` when it is one of ``allowed``; else an InputError listing them."""
    try:
        ok = value in allowed
    except TypeError:   # an unhashable value (a list) against a set
        ok = False
    if not ok:
        raise EventDataError(f"{name} must be one of {tuple(allowed)}, got {_short(value)}")
    return value


def _short(value) -> str:
    text = repr(value)
    return text if len(text) <= 60 else f"{type(value).__name__} {text[:50]}..."


def whole_number(value, name: str, *, lo: int | None = None, hi: int | None = None) -> int:
    """``value`` as an int when it is a whole number (not a bool, not 1.5) in [lo, hi]; else an InputError."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        if isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_)) and \
                math.isfinite(float(value)) and float(value) == int(value):
            value = int(value)
        else:
            raise EventDataError(f"{name}= must be a whole number{_range(lo, hi)}, got {value!r}")
    value = int(value)
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        raise EventDataError(f"{name}= must be a whole number{_range(lo, hi)}, got {value}")
    return value


def is_real_number(value) -> bool:
    """A real number: an int or a float, numpy's too (not a bool, not text, not an array)."""
    return isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))


def real_number(value, name: str, *, lo: float | None = None, hi: float | None = None, lo_open: bool = False,
                hint: str = "") -> float:
    """``value`` as a float when it is a finite number in [lo, hi] (``lo_open``: (lo, hi]); else an InputError."""
    ok = is_real_number(value)
    v = float(value) if ok else math.nan
    if not ok or not math.isfinite(v) or (lo is not None and (v <= lo if lo_open else v < lo)) or \
            (hi is not None and v > hi):
        span = _range(lo, hi, lo_open)
        raise EventDataError(f"{name}= must be a finite number{span}, got {value!r}" + (f"; {hint}" if hint else ""))
    return v


def _range(lo, hi, lo_open: bool = False) -> str:
    if lo is not None and hi is not None:
        return f" in {'(' if lo_open else '['}{lo:g}, {hi:g}]"
    if lo is not None:
        return f" {'>' if lo_open else '>='} {lo:g}"
    if hi is not None:
        return f" <= {hi:g}"
    return ""


FLOAT_IMAGE_SLACK = 1.0 / 255.0   # float images may overshoot [0, 1] by rounding, not by a factor of 255


def check_image_values(images, name: str = "images", *, clipped: bool = False) -> np.ndarray:
    """Images [.., H, W] that are uint8 (0..255) or float in [0, 1]; returns them as given.

    Float images must be finite and lie in [0, 1] (within rounding): float images in 0..255 are
    refused (dividing by 255 is the fix), not silently taken as [0, 1]; NaN or inf is refused.
    ``clipped``: the caller clips to [0, 1] (a reconstruction may overshoot a little), so only a
    range that cannot be [0, 1] (beyond [-1, 2]: the 0..255 scale) is refused.
    """
    images = np.asarray(images)
    if images.dtype == np.uint8:
        return images
    if images.dtype.kind == "f":
        finite = np.isfinite(images)
        if not finite.all():
            bad = int(np.size(finite) - np.count_nonzero(finite))
            raise EventDataError(f"{name} contain {bad:,} NaN or inf value(s); repair or drop those frames (an image "
                             "must be finite to be scored)")
        if images.size:
            lo, hi = float(images.min()), float(images.max())
            slack = 1.0 if clipped else FLOAT_IMAGE_SLACK
            if hi > 1.0 + slack or lo < -slack:
                scale = " (they look like 0..255: divide by 255, or pass uint8)" if hi > 2.0 else ""
                raise EventDataError(f"{name} are floats in [{lo:.4g}, {hi:.4g}]; float images must lie in [0, 1]"
                                 f"{scale}")
        return images
    if images.dtype.kind in "iu":
        raise EventDataError(f"{name} are {images.dtype} integers; pass uint8 (0..255) or float in [0, 1]")
    raise EventDataError(f"{name} must be uint8 (0..255) or float in [0, 1], got dtype {images.dtype}")


class ResultError(EventDataError):
    """A computation gave output that is not a result (not finite, or constant where the input is not);
    the message names what happened and which setting to change."""


def check_result_frames(frames, *, what: str, input_varies: bool, fix: str) -> np.ndarray:
    """Refuse output frames [Q, H, W] that are not finite, or constant (every pixel of every frame
    equal) although the input varies; ``what`` names the computation and ``fix`` the settings to change."""
    frames = np.asarray(frames)
    finite = np.isfinite(frames)
    if not finite.all():
        bad = int(np.size(finite) - np.count_nonzero(finite))
        raise ResultError(f"{what} gave {bad:,} NaN or infinite value(s) of {frames.size:,}: that is not a result; "
                          f"{fix}")
    if input_varies and frames.size and float(frames.max()) == float(frames.min()):
        raise ResultError(f"{what} gave constant frames (every pixel {float(frames.min()):.6g}) although the input "
                          f"varies: that is not a result; {fix}")
    return frames
