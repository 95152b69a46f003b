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
import os
from decimal import Decimal

import numpy as np

from .events import EventDataError
from .guard import InputError, check_unmasked, dense_array, host_array
from .options import choice, short_repr   # re-exported: the kit's checks import them from here

__all__ = ["require", "numbers_array", "whole_number", "real_number", "check_image_values", "check_result_frames", "ResultError",
           "TypeFix", "ArgumentTypeError", "seconds_array", "optional_seconds", "choice", "is_real_number",
           "host_array", "short_repr", "check_seconds_precision", "check_reach", "image_stack", "checked_span",
           "true_or_false", "check_reader_window", "decimal_as_float", "check_log", "check_path_type",
           "SEED_LIMIT", "check_seed", "pixel_mask", "value_list",
           "blank_path"]


SECONDS_STEP = 1e-6   # seconds; the events' resolution: times stored more coarsely than this lose information


def check_seconds_precision(arr, name: str) -> None:
    """Refuse times ``arr`` (seconds, as given: before any cast to float64) stored as float16, or as float32
    where float32's step at their largest magnitude is coarser than the events' microsecond (from 16 s on):
    the times asked for are then not the times meant, and no cast afterwards brings the digits back. Anything
    that is no array of floats (text, a ragged list) passes: the caller's own checks refuse it with their message."""
    try:
        arr = np.asarray(host_array(arr))
    except (TypeError, ValueError):
        return
    if arr.dtype.kind != "f" or arr.dtype.itemsize >= 8 or arr.size == 0:
        return
    finite = arr[np.isfinite(arr)]
    top = float(np.max(np.abs(finite))) if finite.size else 0.0
    step = float(np.spacing(arr.dtype.type(top)))
    if arr.dtype.itemsize < 4 or step > SECONDS_STEP:
        raise EventDataError(f"{name}= are {arr.dtype} seconds, which keep about {np.finfo(arr.dtype).precision} "
                             f"digits: at {top:g} s their step is {step:.3g} s, coarser than the events' microseconds, "
                             f"so the times used are not the times meant; make them float64 where they are made "
                             f"(np.linspace and np.arange give float64; torch: dtype=torch.float64)")


def check_reach(lo: float, hi: float, events_t, t_origin: float, name: str) -> None:
    """Refuse a span [lo, hi] (seconds, the events' span widened to the query times, or the one given) longer
    than :data:`~evinr_lite.core.events.MAX_SPAN_S` when the events' own span is not: times in microseconds,
    or on the absolute clock, given as seconds on the events' (relative) clock."""
    from .events import MAX_SPAN_S

    first, last = (float(events_t[0]), float(events_t[-1])) if len(events_t) else (lo, lo)
    if hi - lo > MAX_SPAN_S and last - first <= MAX_SPAN_S:
        raise EventDataError(f"{name} reach [{lo:.6g}, {hi:.6g}] s but the events cover [{first:.6g}, {last:.6g}] s "
                             f"(relative to t_origin = {t_origin:.6g} s): a span of {hi - lo:,.6g} s, which no "
                             f"recording has; give seconds on the events' clock: divide microseconds by 1e6 (ns by "
                             f"1e9), and subtract events.t_origin from absolute times")


def image_stack(a, name: str) -> np.ndarray:
    """Grey images [F, H, W] from [F, H, W] or [F, H, W, 1] (a trailing channel of one, as image readers give);
    colour [F, H, W, 3] and other shapes are refused naming the fix, and so are images of different sizes (a
    ragged list). Values are not checked here."""
    a = dense_array(a, name, error=EventDataError, want="images of one size [H, W] each (crop or resize them to "
                                                       "one size first)")
    if a.ndim == 4 and a.shape[-1] == 1:
        return a[..., 0]
    if a.ndim != 3:
        fix = ("; one image [H, W] is a stack of one: image[None]" if a.ndim == 2 else
               "; colour images: make them grey first (e.g. frames.mean(axis=-1), or to_grey_uint8)"
               if a.ndim == 4 and a.shape[-1] in (3, 4) else "")
        raise EventDataError(f"{name} must be a stack [F, H, W] (or [F, H, W, 1]), got shape {a.shape}{fix}")
    return a



def value_list(values, name: str, what: str, *, text: bool = False) -> list:
    """``values`` as a list: any iterable but text (a name is no list of its letters), bytes, a dict, None or a 0-d
    array or tensor (which numpy and torch call iterable, then refuse to iterate: "iteration over a 0-d array").
    ``text``: each value must be a str. Else an EventDataError naming ``name`` and ``what`` the list holds; a 0-d
    array or tensor (and, with ``text``, one name) is told to pass ``[value]``."""
    zero_d = not isinstance(values, (str, bytes, dict)) and getattr(values, "ndim", None) == 0
    one = f"; for one, pass [{values.item()!r}]" if zero_d else \
        f"; for one, pass [{values!r}]" if text and isinstance(values, str) else ""
    if values is None or isinstance(values, (str, bytes, dict)) or zero_d:
        raise EventDataError(f"{name}= must be a list of {what}, got {values!r:.60}{one}")
    try:
        values = list(values)
    except TypeError:   # a number, or an object that is not iterable
        raise EventDataError(f"{name}= must be a list of {what}, got {values!r:.60}") from None
    if text:
        bad = [v for v in values if not isinstance(v, str)]
        if bad:
            raise EventDataError(f"{name}= must hold text ({what}), got {bad[0]!r:.60}")
    return values


def pixel_mask(mask, shape, name: str = "mask", fix: str = "") -> np.ndarray:
    """``mask`` as a bool array [H, W] of ``shape`` (one value per pixel: True where the pixel is meant); a list or a
    tensor of bools is taken. Else an EventDataError naming ``name``, the shape wanted, what was given and ``fix``
    (numbers were taken as indices, a mask of another shape numpy's IndexError)."""
    arr = None if mask is None or isinstance(mask, (str, bytes)) else \
        dense_array(mask, f"{name}=", error=EventDataError, want=f"a bool array of shape (H, W) = {tuple(shape)}")
    if arr is None or arr.dtype != bool or arr.shape != tuple(shape):
        got = f"{arr.dtype} array of shape {arr.shape}" if arr is not None else short_repr(mask)
        arg = name.rsplit(": ", 1)[-1]
        numeric = (f"; for a 0/1 (or 0/255) mask pass {arg} != 0" if arr is not None and arr.dtype.kind in "iuf"
                   and arr.shape == tuple(shape) else "")
        raise EventDataError(f"{name}= must be a bool array of the sensor's shape (H, W) = {tuple(shape)} (True where "
                             f"a pixel is meant), got {got}{numeric}" + (f"; {fix}" if fix else ""))
    return arr


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
    ("EvINRConfig", "NoneType"): "pass EvINRConfig() for the kit's defaults (or EvINRConfig.paper())",
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
    check_unmasked(value, name + "=", EventDataError)   # np.asarray would use the values under the mask as times
    try:
        arr = np.asarray(host_array(value)) if not isinstance(value, (str, bytes)) else np.asarray([value])
    except (TypeError, ValueError):   # a ragged list ([[0.1], [0.2, 0.3]]): no array of times
        arr = np.asarray([None])
    if arr.dtype.kind not in "iuf" or arr.dtype == bool:
        raise EventDataError(f"{name}= must be seconds (a number, a list or a 1-D array of numbers), got "
                             f"{short_repr(value)}")
    check_seconds_precision(arr, name)
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


def decimal_as_float(value):
    """A finite Decimal as its float, anything else as given: Decimal is no ``numbers.Real`` (so
    :func:`is_real_number` refuses it), but the canonical file's reader and writer and the text readers' t_origin
    took it (through ``float()`` / ``math.isfinite``) before their checks; a NaN Decimal stays one, to be refused."""
    return float(value) if isinstance(value, Decimal) and value.is_finite() else value


def check_reader_window(t_start, t_end) -> tuple:
    """A reader's window ``[t_start, t_end)`` (seconds on the recording's clock), checked before any reading: each
    bound None or a finite number (:func:`optional_seconds`: a Python or numpy int or float, a 0-d array or tensor, a
    Fraction; a Decimal too), and t_end after t_start; else an InputError naming the bound. Text, lists and bools
    (True was 1 s, False 0 s: a flag is no time) are refused.

    Returns the bounds to search with: a Python or numpy int or float as given (the readers compared them so
    before, float32 included), any other number (0-d array, tensor, Fraction, Decimal) as a float."""
    bounds = []
    for name, value in (("t_start", t_start), ("t_end", t_end)):
        try:
            seconds = optional_seconds(decimal_as_float(value), name)
        except EventDataError:
            raise EventDataError(f"{name}= must be a finite number of seconds (on the recording's clock; None for its "
                                 f"{'start' if name == 't_start' else 'end'}), got {short_repr(value)}") from None
        plain = isinstance(value, (int, float, np.integer, np.floating))   # bools were refused above
        bounds.append(value if plain or value is None else seconds)
    lo, hi = bounds
    if lo is not None and hi is not None and hi <= lo:
        raise EventDataError(f"time window [{t_start}, {t_end}) is empty or reversed; t_end must exceed t_start")
    return lo, hi


def whole_number(value, name: str, *, lo: int | None = None, hi: int | None = None) -> int:
    """``value`` as an int when it is a whole number (not a bool, not 1.5) in [lo, hi]; else an InputError.
    A 0-d array or tensor holding one counts as that number (what ``np.argmax`` or ``t.sum()`` give)."""
    if not isinstance(value, numbers.Real) and is_real_number(value):   # 0-d numeric array or tensor
        value = host_array(value)[()]
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


SEED_LIMIT = 2**63   # seeds are whole numbers in [0, 2**63): EvINRConfig's range (network_seed works modulo 2**63)


def check_seed(value, name: str = "seed") -> int:
    """``value`` as an int when it is a whole number in [0, 2**63) (whole floats and numpy's too, as
    :func:`whole_number` takes them); else an InputError naming ``name`` and the range as EvINRConfig's says it."""
    try:
        seed = whole_number(value, name)
    except EventDataError:
        seed = None
    if seed is None or not 0 <= seed < SEED_LIMIT:
        raise EventDataError(f"{name}= must be a whole number in [0, 2**63), got {short_repr(value)}")
    return seed


def true_or_false(value, name: str) -> bool:
    """``value`` as a bool when it is True or False (numpy's too) or the whole number 0 or 1; else an InputError.
    Text ("no" is a true value), None and other numbers are refused, not read as their truth."""
    if isinstance(value, (bool, np.bool_)) or (isinstance(value, (int, np.integer)) and value in (0, 1)):
        return bool(value)
    raise EventDataError(f"{name}= must be True or False, got {short_repr(value)}")


def check_log(log, *, none_ok: bool = False):
    """``log`` when it is a function ``log(text)`` (or None when ``none_ok``); else an ArgumentTypeError before any
    work (a log of 5 failed only when the job first logged, after its work)."""
    if (log is None and none_ok) or callable(log):
        return log
    raise ArgumentTypeError(f"log= must be a function log(text) (e.g. print){' or None' if none_ok else ''}, got "
                            f"{type(log).__name__}")


def check_path_type(value, name: str, what: str, hint: str = ""):
    """``value`` when it is a path: a str or an os.PathLike giving one; else an ArgumentTypeError naming ``name``
    and ``what`` it must be (None, a number or a list were Python's "expected str, bytes or os.PathLike object",
    which names no argument; bytes are refused here too: ``Path(b"x")`` is that TypeError)."""
    if not isinstance(value, (str, os.PathLike)) or isinstance(os.fspath(value), bytes):
        raise ArgumentTypeError(f"{name}= must be {what} (a str or Path), got {type(value).__name__}"
                                + (f"; {hint}" if hint else ""))
    return value


def blank_path(value) -> bool:
    """Whether a path (checked by :func:`check_path_type`) is blank text: "" or spaces, a mistake callers refuse.
    A Path is never blank: ``Path("")`` is ``Path(".")``, the current folder, which a user may name on purpose."""
    return isinstance(value, str) and not value.strip()


def is_real_number(value) -> bool:
    """A real number: an int or a float, numpy's too, or a 0-d numeric array or tensor holding one (what
    ``t.max()`` gives); not a bool, not text, not an array of several values."""
    if isinstance(value, numbers.Real):
        return not isinstance(value, (bool, np.bool_))
    value = host_array(value)
    return isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf"


def checked_span(t_start, t_end, name: str) -> tuple:
    """(t_start, t_end) as floats: finite seconds, t_end >= t_start; else an EventDataError naming ``name``."""
    a = real_number(t_start, f"{name}: t_start", hint="seconds on the events' clock")
    b = real_number(t_end, f"{name}: t_end", hint="seconds on the events' clock")
    if b < a:
        raise EventDataError(f"{name}: the span [{a}, {b}] s is reversed; t_end must not come before t_start")
    return a, b


def real_number(value, name: str, *, lo: float | None = None, hi: float | None = None, lo_open: bool = False,
                hint: str = "") -> float:
    """``value`` as a float when it is a finite number in [lo, hi] (``lo_open``: (lo, hi]); else an InputError."""
    ok = is_real_number(value)
    v = float(host_array(value)) if ok else math.nan
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


def numbers_array(value, name: str, what: str, *, flags: bool = False) -> np.ndarray:
    """``value`` as an array of numbers, its dtype kept (``what``: what it must be, in the message): text and None
    refused by ``name``, booleans too unless ``flags`` (read as 0 and 1, as numpy reads them); values not checked."""
    arr = None if value is None or isinstance(value, (str, bytes)) else \
        dense_array(value, f"{name}=", error=EventDataError, want=what)
    if arr is None or arr.dtype.kind not in ("biuf" if flags else "iuf"):
        raise EventDataError(f"{name}= must be {what} (numbers), got {short_repr(value)}")
    return arr


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
                scale = (" (they look like 0..255: divide by 255, or pass uint8)" if hi > 10.0 else
                         " (clip them to [0, 1], or check their scale)")
                raise EventDataError(f"{name} are floats in [{lo:.4g}, {hi:.4g}]; float images must lie in [0, 1]"
                                 f"{scale}")
        return images
    if images.dtype.kind in "iu":
        top = int(images.max()) if images.size else 0
        scale = ("; for float divide by their full scale (e.g. frames / 65535.0 for 16-bit images)" if top > 255
                 else "; if they are 0..255, .astype(np.uint8)")
        raise EventDataError(f"{name} are {images.dtype} integers (up to {top}); pass uint8 (0..255) or float in "
                             f"[0, 1]{scale}")
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
    # one value (a 1 x 1 sensor at one time) cannot vary: it was refused as if the settings had failed
    if input_varies and frames.size > 1 and float(frames.max()) == float(frames.min()):
        raise ResultError(f"{what} gave constant frames (every pixel {float(frames.min()):.6g}) although the input "
                          f"varies: that is not a result; {fix}")
    return frames
