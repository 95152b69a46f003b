"""The one event container used everywhere: `Events`.

Conventions (every module relies on them):

- ``t``: float64 seconds, sorted (non-decreasing). Times are stored relative to
  ``t_origin`` (also seconds), so that absolute clocks of about 1.5e9 s keep
  nanosecond resolution: ``absolute_time = t_origin + t``. Readers pick an
  integer ``t_origin`` (the whole seconds of the first event) when timestamps are
  large, and 0 otherwise.
- ``x``: column, ``y``: row, both integer pixel indices; images are indexed
  ``[y, x]``.
- ``p``: polarity in {-1, +1} (int8). Encodings {0, 1} and bool are converted
  explicitly (0/False -> -1), never dropped.
- ``sensor_size``: ``(H, W)``, rows first.
"""
from __future__ import annotations

import numbers
from dataclasses import dataclass, field
from decimal import Decimal

import numpy as np

import math

from .guard import EventDataError, InputError, dense_array, host_array   # the guard maps it to exit status 2; defined there so that the guard needs no numpy
from .options import choice

__all__ = ["Events", "EventDataError", "InputError", "normalize_polarity", "check_sensor_size", "relative_seconds", "TIME_UNITS", "LARGE_T",
           "TimeUnitWarning", "check_t_origin", "resolve_time_unit", "check_time_span", "check_time_range", "MAX_SPAN_S",
           "MAX_SENSOR_SIDE", "fall_back_hint", "wrap_hint"]

WRAP_BITS = (32, 31)   # counters that wrap: unsigned 32-bit (0 .. 2**32 - 1) and signed 32-bit (to -2**31)


def wrap_hint(before, after, scales=(1.0,)) -> str:
    """The fix for timestamps that fall from ``before`` to ``after`` (numbers, one unit) because a 32-bit counter
    wrapped around (uint32 microseconds every 71.6 minutes, int32 every 35.8), or "" when the fall is no such
    wrap. ``scales``: the factors that take the values to the counter's unit (1 for a file's raw numbers; 1e3,
    1e6, 1e9 for seconds, whose counter may have counted ms, us or ns). A sort would interleave the laps."""
    for scale in scales:
        a, b = float(before) * scale, float(after) * scale
        for bits in WRAP_BITS:
            lap = 2.0 ** 32
            low = 0.0 if bits == 32 else -2.0 ** 31          # the counter's smallest value
            top = low + lap                                  # one past its largest
            # from just below the top to just above the bottom: the step over the wrap is short (under 1/1024 lap)
            if a < top + 1 and b >= low - 1 and -1 <= b + lap - a < lap / 1024:
                unit = {1e3: " milliseconds", 1e6: " microseconds", 1e9: " nanoseconds"}.get(scale, "")
                every = f" (every {lap / scale / 60:,.1f} minutes)" if scale > 1 else ""
                return (f"; they fall from {a:.0f} to {b:.0f}, across {'2**32' if bits == 32 else '2**31 to -2**31'}: a "
                        f"{'signed ' if bits == 31 else ''}32-bit counter of{unit or ' ticks'} wrapped around{every}, "
                        "so a sort would interleave its laps: unwrap the times in their own unit before anything else, "
                        "t = t.astype(np.int64); t = t + 2**32 * np.cumsum(np.diff(t, prepend=t[0]) < 0), and save them as "
                        "64-bit numbers")
    return ""


def fall_back_hint(n_falls: int, before=None, after=None, scales=(1.0,)) -> str:
    """What to add to an unsorted-times refusal when the times fall back exactly once (``n_falls``, the
    decreasing steps found): two recordings joined, or a clock that restarted, where a sort would
    interleave the two parts instead of repairing them. ``before`` / ``after``: the first fall's values,
    to name a 32-bit counter that wrapped around (:func:`wrap_hint`) whatever the number of falls."""
    if before is not None and after is not None:
        wrapped = wrap_hint(before, after, scales)
        if wrapped:
            return wrapped
    if n_falls != 1:
        return ""
    return ("; they fall back only once, so if two recordings were joined or the clock restarted there, a sort would "
            "interleave the two parts: split the file at that event, or shift the second part's times past the "
            "first part's last one")


# Seconds per unit for timestamps given in other units.
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}
LARGE_T = 1e5  # seconds; clocks whose first timestamp is at least this large get a whole-second t_origin
MAX_SENSOR_SIDE = 1 << 16   # pixels per side; no event camera is larger (headers, file attributes, --sensor)


POLARITY_ENCODINGS = ("auto", "pm1", "01", "bool")   # normalize_polarity's encodings


def normalize_polarity(p, encoding: str = "auto") -> np.ndarray:
    """Return polarities as int8 in {-1, +1}.

    Args:
        p: array [N] of polarities (bool, {0, 1} or {-1, +1}; any numeric dtype).
        encoding: ``"auto"`` (decide from the values), ``"pm1"`` (must be -1/+1),
            ``"01"`` (0 = OFF -> -1, 1 = ON -> +1) or ``"bool"`` (False -> -1).

    Raises:
        EventDataError: values outside the encoding, or a mix of encodings.
    """
    encoding = choice(encoding, POLARITY_ENCODINGS, "polarity", hint="the polarity encoding")   # an array: "truth value"
    p = np.asarray(p)
    if p.ndim != 1:
        raise EventDataError(f"polarity must be a 1-D array, got shape {p.shape}")
    if p.size == 0:
        return p.astype(np.int8)
    if p.dtype == bool:
        if encoding not in ("auto", "bool"):
            raise EventDataError(f"polarity is boolean but encoding={encoding!r} was requested; use encoding='bool' or 'auto'")
        return np.where(p, 1, -1).astype(np.int8)
    if p.dtype.kind not in "iuf":
        raise EventDataError(f"polarity must be numbers (-1/+1 or 0/1) or booleans, got dtype {p.dtype}; convert "
                             "them to -1 (OFF) / +1 (ON) before loading")
    if not np.all(np.isfinite(p)):
        raise EventDataError("polarity contains NaN or inf; every event needs a polarity of -1/+1 (or 0/1)")
    values = np.unique(p)
    if encoding == "auto":
        if np.all(np.isin(values, (-1, 1))):
            encoding = "pm1"
        elif np.all(np.isin(values, (0, 1))):
            encoding = "01"
        else:
            shown = ", ".join(str(v) for v in values[:6])
            raise EventDataError(
                f"polarity values {{{shown}}} are neither -1/+1 nor 0/1 "
                "(a mix of both, or other numbers). Convert them to -1 (OFF) / +1 (ON) before loading."
                + _two_value_hint(values)
            )
    if encoding == "pm1":
        if not np.all(np.isin(values, (-1, 1))):
            raise EventDataError(
                f"polarity must be -1/+1 but contains {sorted(set(values.tolist()) - {-1, 1})[:6]}; "
                "if OFF events are stored as 0, pass polarity='01'"
            )
        return p.astype(np.int8)
    if encoding in ("01", "bool"):
        if not np.all(np.isin(values, (0, 1))):
            raise EventDataError(
                f"polarity encoding {encoding!r} expects 0/1 but found {sorted(set(values.tolist()) - {0, 1})[:6]}"
            )
        return np.where(p > 0, 1, -1).astype(np.int8)
    raise EventDataError(f"unknown polarity encoding {encoding!r}; use 'auto', 'pm1', '01' or 'bool'")


def _two_value_hint(values: np.ndarray) -> str:
    """The conversion for polarities stored as two other values: 0/255 (an 8-bit image's black and white), 1/2
    (counted from 1, as MATLAB indexes) or any other pair (the larger taken as ON)."""
    if values.size != 2:
        return ""
    lo, hi = (v.item() for v in values)
    why = {(0, 255): "0/255 are an 8-bit image's black and white: ",
           (1, 2): "1/2 count from 1 (as MATLAB indexes): "}.get((lo, hi), "")
    return (f" {why[:1].upper() + why[1:] if why else ''}if {hi:g} is ON and {lo:g} OFF, convert them with "
            f"p = np.where(p == {hi:g}, 1, -1)")


class TimeUnitWarning(UserWarning):
    """The unit of the timestamps was not given and was assumed (the message says which, and how to set it)."""


MAX_SPAN_S = 1e5        # seconds; a recording longer than about 28 hours is taken as a wrong time unit
MIN_RATE_PER_S = 10.0   # events per second; thousands of events at a lower mean rate also mean a wrong unit
MAX_RATE_PER_S = 1e10   # events per second; no camera comes near (about 1e9 at the most), so a wrong unit


def resolve_time_unit(t, time_unit: str | None, source, *, flag: str = "time_unit") -> str:
    """The unit of timestamps ``t``: ``time_unit`` when given, else detected.

    Detection ('auto' or None): integer timestamps are microseconds (Prophesee, AEDAT4 exports, DSEC,
    Tonic), with a :class:`TimeUnitWarning` that says so and how to choose another unit
    (nanoseconds: ESIM); floating-point timestamps are seconds.
    """
    if time_unit not in (None, "auto"):
        if not (isinstance(time_unit, str) and time_unit in TIME_UNITS):   # a list was "unhashable type"
            raise EventDataError(f"unknown {flag}={time_unit!r}; use one of {', '.join(TIME_UNITS)}")
        return time_unit
    kind = np.asarray(t).dtype.kind if not isinstance(t, str) else t
    if kind in "iu":
        import warnings

        warnings.warn(f"{source}: the timestamps are integers; read them as microseconds (as Prophesee, AEDAT4 "
                      f"exports and DSEC write them); if they are nanoseconds (ESIM) or another unit, pass "
                      f"{flag}='ns' (or 's', 'ms', 'us')", TimeUnitWarning, stacklevel=3)
        return "us"
    return "s"


def check_time_span(t, source, time_unit: str, *, flag: str = "time_unit") -> None:
    """Refuse timestamps (seconds, sorted or not) whose span is implausible for an event recording:
    longer than :data:`MAX_SPAN_S`, at least 1000 events at under :data:`MIN_RATE_PER_S` per second, or
    a mean rate over :data:`MAX_RATE_PER_S`; each means the unit is wrong. The message names the unit used and the option to change it."""
    arr = None if t is None or isinstance(t, (str, bytes)) else np.asarray(host_array(t))
    if arr is None or arr.dtype.kind not in "iuf":   # None and text passed unchecked, bools were numpy's subtract error
        raise EventDataError(f"{source}: timestamps must be numbers (seconds), got "
                             f"{type(t).__name__ if arr is None else arr.dtype}; pass the events' times as an array of "
                             f"numbers (e.g. np.asarray(t, dtype=np.float64))")
    t = arr
    if t.size < 2:
        return
    finite = t[np.isfinite(t)]
    if finite.size < 2:
        return
    span = float(finite.max() - finite.min())
    rate = t.size / span if span > 0 else math.inf
    if span > MAX_SPAN_S or (t.size >= 1000 and rate < MIN_RATE_PER_S) or (t.size >= 1000 and rate > MAX_RATE_PER_S):
        others = [u for u in ("ms", "us", "ns") if u != time_unit]
        raise EventDataError(
            f"{source}: read in {time_unit!r}, the timestamps span {span:,.6g} s ({span / 3600:,.3g} hours) with "
            f"{t.size:,} events ({rate:,.3g} per second); that is implausible for an event recording, so "
            f"the time unit is probably wrong: pass {flag}={others[0]!r} (or {', '.join(repr(u) for u in others[1:])})")


def check_time_range(value, name: str, error=None) -> tuple[float, float]:
    """``(start, end)`` in seconds, both finite with end > start, as two floats.

    The one check of a time range given as a pair (a coordinate network's ``t_range``, a converted
    file's ``eval_window``); ``error`` is the exception class raised (default EventDataError), and the
    message names ``name``.
    """
    error = error or EventDataError
    try:
        # text ("0", "1") was parsed, True taken as 1 s and a dict's keys as the range: none is a pair of seconds
        if isinstance(value, (str, bytes, dict, set, frozenset)):
            raise TypeError
        value = tuple(value)   # a generator or other one-pass iterable: read once (the scan below consumed it)
        if any(isinstance(v, (str, bytes, bool, np.bool_)) for v in value):
            raise TypeError
        lo, hi = (float(v) for v in value)
    except (TypeError, ValueError):
        raise error(f"{name} must be (start, end) in seconds, two numbers; got {value!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and hi > lo):
        raise error(f"{name} [{lo}, {hi}] s is empty, reversed or not finite; the end must exceed the start")
    return lo, hi


def _check_integer_seconds(t: np.ndarray) -> None:
    """Integer timestamps given to ``Events()`` (which takes seconds): the time-span plausibility rule of
    the readers (:func:`check_time_span`) refuses those that cannot be seconds; the others are taken
    as seconds with a :class:`TimeUnitWarning` that names the assumption and the override."""
    fix = "Events.from_arrays(t, x, y, p, sensor_size, time_unit='us') (or 'ns', 'ms')"
    try:
        check_time_span(t, "Events(): integer timestamps", "s", flag="time_unit")
    except EventDataError as err:
        raise EventDataError(f"{err}; Events() takes float64 seconds: for integer microseconds use {fix}") from None
    if t.size:
        import warnings

        warnings.warn(f"Events(): the timestamps are integers; taken as whole seconds. If they are microseconds "
                      f"or nanoseconds, use {fix}; for seconds pass them as float64 to silence this note",
                      TimeUnitWarning, stacklevel=4)


def auto_origin(t_first: float) -> float:
    """Whole seconds of the first timestamp when it is large (an absolute clock), else 0."""
    return float(math.floor(t_first)) if math.isfinite(t_first) and abs(t_first) >= LARGE_T else 0.0


def relative_seconds(t, time_unit: str = "s") -> tuple[np.ndarray, float]:
    """Timestamps [N] in ``time_unit`` -> (float64 seconds relative to t_origin, t_origin in seconds).

    t_origin is the whole seconds of the earliest timestamp on an absolute clock (>= 1e5 s), else 0.
    Integer timestamps (us, ns) are shifted in integer arithmetic and then divided (correctly
    rounded), so no precision is lost; float timestamps are shifted in float64 (exact for large values).
    """
    if not (isinstance(time_unit, str) and time_unit in TIME_UNITS):
        raise EventDataError(f"unknown time_unit {time_unit!r}; use one of {sorted(TIME_UNITS)}")
    per_s = round(1 / TIME_UNITS[time_unit])  # 1, 1000, 10**6, 10**9 units per second
    t = np.asarray(host_array(t))
    if t.dtype.kind not in "iuf":
        raise EventDataError(f"timestamps must be numbers, got dtype {t.dtype}; pass them as an array of numbers "
                             f"(float seconds, or whole units with time_unit=, e.g. 'us')")
    if t.ndim != 1:   # a 0-d array came back as a number, [N, 2] as rows of "times"
        raise EventDataError(f"timestamps must be a 1-D array [N], got shape {t.shape}; flatten one time per row with "
                             "np.ravel(t)")
    if t.size == 0:
        return t.astype(np.float64), 0.0
    if t.dtype.kind in "iu":
        t0 = int(t.min())
        origin_units = (t0 // per_s) * per_s if abs(t0) >= LARGE_T * per_s else 0
        rel = (t.astype(np.int64) - origin_units).astype(np.float64) / per_s
        return rel, float(origin_units // per_s)
    if t.dtype.kind != "f":
        raise EventDataError(f"timestamps must be numbers, got dtype {t.dtype}")
    if t.dtype != np.float64 and time_unit == "s":
        return t, 0.0  # let Events refuse float32 seconds with its explanation
    ts = t.astype(np.float64) / per_s
    finite = ts[np.isfinite(ts)]
    origin = auto_origin(float(finite.min())) if finite.size else 0.0
    return ts - origin, origin


def _is_number(value) -> bool:
    """A real number: a Python or numpy int or float, or a 0-d numeric array (not a bool, not text)."""
    return not isinstance(value, (str, bytes)) and np.ndim(value) == 0 and np.asarray(value).dtype.kind in "iuf"


def check_t_origin(t_origin) -> float:
    """``t_origin`` (seconds, the absolute time of t = 0) as a finite float, or an EventDataError.

    A number: a Python or numpy int or float, a 0-d array or tensor holding one, a Fraction or a Decimal (the
    text readers turn it into nanoseconds exactly, through Fraction). Text, None, lists and bools are refused:
    True is no 1 s and False no 0 s (a flag given where a time belongs)."""
    exact = isinstance(t_origin, (numbers.Rational, Decimal)) and not isinstance(t_origin, (bool, np.bool_))
    try:
        finite = (exact or _is_number(t_origin)) and math.isfinite(float(t_origin))
    except (OverflowError, ValueError):   # 10**400; Decimal("sNaN")
        finite = False
    if not finite:
        raise EventDataError(f"t_origin must be a finite number of seconds (the absolute time of t = 0; 0 when the "
                             f"times are already relative), got {t_origin!r}")
    return float(t_origin)


def check_sensor_size(sensor_size) -> tuple[int, int]:
    """(H, W) as two positive ints, or an EventDataError that says what is wrong."""
    try:
        if isinstance(sensor_size, (dict, set, frozenset)):   # a dict's keys (or a set's order) were taken as (H, W)
            raise ValueError
        values = list(sensor_size)
        if len(values) != 2:
            raise ValueError
        # whole numbers only: int() would silently make 30.7 rows into 30 (and True into 1)
        if any(isinstance(v, (bool, np.bool_, str, bytes)) or float(v) != int(v) for v in values):
            raise ValueError
        H, W = (int(v) for v in values)
    except (TypeError, ValueError, OverflowError):
        raise EventDataError(f"sensor_size must be (H, W), two positive whole numbers (rows, columns); got "
                             f"{sensor_size!r}") from None
    if H <= 0 or W <= 0:
        raise EventDataError(f"sensor_size must be (H, W) with positive sizes; got {(H, W)}")
    if H > MAX_SENSOR_SIDE or W > MAX_SENSOR_SIDE:   # a typo or a wrong field: each image would be gigabytes
        raise EventDataError(f"sensor_size (H, W) = {(H, W)} is larger than any event camera (at most "
                             f"{MAX_SENSOR_SIDE} pixels per side); check the size: (H, W) = (rows, columns), e.g. "
                             f"(480, 640)")
    return H, W


def _checked_take_index(index, n: int, t=None) -> np.ndarray:
    """``Events.take``'s index as a boolean mask of length ``n`` or integers in [0, n) that keep the times ``t``
    (float64 [n], s) in order: events with the same timestamp may come in any order."""
    a = np.asarray(index)
    if a.dtype == bool:
        if a.shape != (n,):
            raise EventDataError(f"take: a boolean mask must have one value per event, shape ({n},), got shape "
                                 f"{a.shape}; build it from the events' own columns (e.g. events.p > 0)")
        return a
    if a.ndim == 1 and a.size == 0:   # [] (numpy makes it float64): no event
        return a.astype(np.int64)
    if a.ndim != 1 or a.dtype.kind not in "iu":
        raise EventDataError(f"take: index must be a slice, a boolean mask of shape ({n},) or 1-D whole-number "
                             f"indices, got {a.dtype} of shape {a.shape}"
                             + ("; convert whole numbers with index.astype(np.int64)" if a.dtype.kind == "f" else ""))
    if a.size and (a.min() < 0 or a.max() >= n):
        raise EventDataError(f"take: indices span [{a.min()}, {a.max()}] but there are {n} events (indices 0 .. "
                             f"{n - 1}); drop the indices outside")
    if a.size > 1 and np.any(np.diff(a) < 0) and (t is None or np.any(np.diff(t[a]) < 0)):
        raise EventDataError("take: the indices put the events out of time order (a later event's index before an "
                             "earlier one's); sort them first (np.sort(index)); events with the same timestamp may "
                             "come in any order")
    return a


def _narrow_integer(a: np.ndarray, size: int):
    """np.iinfo of the integer type of coordinates ``a`` when it cannot hold every pixel index below ``size``
    (uint8 on a sensor wider than 256), else None."""
    if a.dtype.kind not in "iu" or a.dtype.itemsize > 2:
        return None
    info = np.iinfo(a.dtype)
    return info if size - 1 > info.max else None


@dataclass(frozen=True, eq=False)
class Events:
    """A stream of N events on a sensor of ``sensor_size = (H, W)`` pixels.

    Attributes:
        t: float64 [N], seconds relative to ``t_origin``, non-decreasing.
        x: int32 [N], column index in [0, W).
        y: int32 [N], row index in [0, H).
        p: int8 [N], polarity in {-1, +1}.
        sensor_size: (H, W).
        t_origin: float, seconds; absolute time of t = 0 (0 when times are already relative).

    Construct with ``Events(t, x, y, p, sensor_size)``: inputs are validated and
    converted; bad input raises :class:`EventDataError` naming the problem and the fix.
    Use :meth:`from_arrays` for unsorted data, other time units or an explicit
    polarity encoding.
    """

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    p: np.ndarray
    sensor_size: tuple[int, int]
    t_origin: float = 0.0
    polarity_encoding: str = field(default="auto", repr=False)

    def __post_init__(self):
        H, W = check_sensor_size(host_array(self.sensor_size))
        # torch tensors too (on any device, requiring grad or not); a ragged nest is refused by name
        t, x, y, p = (dense_array(getattr(self, k), f"Events.{k}", error=EventDataError) for k in "txyp")
        arrays = {"t": t, "x": x, "y": y, "p": p}
        for name, a in arrays.items():
            if a.ndim != 1:
                raise EventDataError(f"events.{name} must be a 1-D array, got shape {a.shape}")
        n = {name: a.shape[0] for name, a in arrays.items()}
        if len(set(n.values())) != 1:
            raise EventDataError(f"t, x, y, p must have the same length, got {n}")
        if t.dtype.kind in "mM":   # numpy's datetime64 / timedelta64: a clock, not seconds
            raise EventDataError(f"timestamps must be numbers (seconds), got dtype {t.dtype}; convert them to float64 "
                                 "seconds, e.g. (t - t[0]) / np.timedelta64(1, 's')")
        if t.dtype.kind not in "fiu":
            raise EventDataError(f"timestamps must be numbers (seconds), got dtype {t.dtype}" +
                                 ("; if they are numbers kept as objects, convert them: np.asarray(t, dtype=np.float64)"
                                  if t.dtype == object else ""))
        if t.dtype == np.float32 or t.dtype == np.float16:
            raise EventDataError(
                "timestamps are float32/float16, which loses microseconds (and whole seconds on absolute "
                "clocks); keep them float64 (or integer us/ns with Events.from_arrays(..., time_unit='us'))"
            )
        if t.dtype.kind in "iu":   # seconds are floats: integers are usually us or ns, so say so or refuse
            _check_integer_seconds(t)
        t = t.astype(np.float64, copy=False)
        if not np.all(np.isfinite(t)):
            bad = int(np.flatnonzero(~np.isfinite(t))[0])
            raise EventDataError(
                f"timestamp {bad} is {t[bad]} (non-finite); drop or repair those events before loading"
            )
        if t.size > 1:
            dec = np.flatnonzero(np.diff(t) < 0)
            if dec.size:
                i = int(dec[0])
                origin = float(self.t_origin) if _is_number(self.t_origin) else 0.0   # a wrapped counter is absolute
                raise EventDataError(
                    f"timestamps are not sorted: t[{i}] = {float(t[i])!r} > t[{i + 1}] = {float(t[i + 1])!r} "
                    f"({dec.size} decreasing steps); sort the events by time, e.g. "
                    "Events.from_arrays(..., sort=True)"
                    + fall_back_hint(dec.size, float(t[i]) + origin, float(t[i + 1]) + origin, scales=(1e6, 1e9, 1e3))
                )
        for name, a, size, axis in (("x", x, W, "column, width W"), ("y", y, H, "row, height H")):
            if a.dtype.kind == "f":
                if not np.all(np.isfinite(a)) or np.any(a != np.round(a)):
                    raise EventDataError(f"{name} coordinates must be whole pixel indices; found non-integer values")
            elif a.dtype.kind not in "iu":
                raise EventDataError(f"{name} coordinates must be integers, got dtype {a.dtype}" +
                                     (f"; if they are whole numbers kept as objects, convert them: np.asarray({name}, "
                                      "dtype=np.int64)" if a.dtype == object else ""))
            narrow = _narrow_integer(a, size)   # a type too small for the sensor: values past its top wrapped
            if narrow is not None and narrow.kind == "u" and a.size and a.max() == narrow.max:
                raise EventDataError(
                    f"{name} is stored as {a.dtype}, which holds only 0 .. {narrow.max}, but the sensor is {size} "
                    f"{'columns wide' if name == 'x' else 'rows high'} and {name} reaches {narrow.max}: the "
                    f"{'columns' if name == 'x' else 'rows'} past {narrow.max} wrapped around to 0 when the events were "
                    f"saved, so those events sit at the wrong pixels; save {name} as uint16 or wider from the camera's "
                    f"data (if they really stop at {narrow.max}, pass {name}.astype(np.int32))")
            if a.size and (a.min() < 0 or a.max() >= size):
                swapped = (x.size and y.size and x.min() >= 0 and y.min() >= 0 and x.max() < H and y.max() < W
                           and H != W)
                # 1 .. W and 1 .. H: counted from 1 (MATLAB, Julia, R), one past the sensor at the far edge
                one_based = (not swapped and x.size and y.size and x.min() >= 1 and y.min() >= 1 and x.max() <= W
                             and y.max() <= H and y.dtype.kind in "iuf" and x.dtype.kind in "iuf")
                raise EventDataError(
                    f"{name} ({axis}) coordinates span [{a.min()}, {a.max()}] but sensor_size (H, W) = "
                    f"{(H, W)} allows [0, {size - 1}]; check the sensor size (it is (H, W), rows first) "
                    "and that x is the column and y the row"
                    + (f"; the events fit ({W}, {H}), the size given the other way round (on the command line "
                       f"--sensor {W}x{H}, or correct the size the file records)" if swapped else "")
                    + ("; no coordinate is 0 and they reach the sensor's far edge: they count pixels from 1 (as "
                       "MATLAB, Julia and R index), so subtract 1 from x and y (pixels count from 0 here)"
                       if one_based else "")
                    + (f"; {name} is stored as {a.dtype}, which holds only {narrow.min} .. {narrow.max}: the values past "
                       f"{narrow.max} wrapped around to negative numbers when the events were saved; save {name} as "
                       "int16 or wider from the camera's data" if narrow is not None and a.min() < 0 else "")
                )
        p = normalize_polarity(arrays["p"], self.polarity_encoding)
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "x", x.astype(np.int32, copy=False))
        object.__setattr__(self, "y", y.astype(np.int32, copy=False))
        object.__setattr__(self, "p", p)
        object.__setattr__(self, "sensor_size", (H, W))
        object.__setattr__(self, "t_origin", check_t_origin(self.t_origin))
        object.__setattr__(self, "polarity_encoding", "pm1")

    # ---- construction -------------------------------------------------------------
    @classmethod
    def from_arrays(cls, t, x, y, p, sensor_size, *, time_unit: str = "s", polarity: str = "auto",
                    sort: bool = False, t_origin: float = 0.0) -> "Events":
        """Build events from raw columns.

        Args:
            t: [N] timestamps in ``time_unit`` ('s', 'ms', 'us' or 'ns'). Other units are converted
                exactly; an absolute clock (>= 1e5 s) given in ms/us/ns is split into whole seconds,
                added to ``t_origin``, and a relative ``t``.
            x, y: [N] column and row indices.
            p: [N] polarities; see :func:`normalize_polarity` for ``polarity``.
            sensor_size: (H, W).
            sort: sort by time (stable) instead of raising on unsorted input.
            t_origin: seconds to add to ``t`` to get the absolute clock.
        """
        if not (isinstance(time_unit, str) and time_unit in TIME_UNITS):   # a list was "unhashable type"
            raise EventDataError(f"unknown time_unit {time_unit!r}; use one of {sorted(TIME_UNITS)}")
        t, x, y, p = (host_array(a) for a in (t, x, y, p))
        t = dense_array(t, "Events.t", error=EventDataError)   # a ragged nest: named, not numpy's ValueError
        if time_unit != "s":
            t, shift = relative_seconds(t, time_unit)
            t_origin = t_origin + shift
        if sort:   # the columns' shapes are checked first: indexing would raise numpy's IndexError on a mismatch
            x, y, p = (dense_array(a, f"Events.{k}", error=EventDataError) for a, k in ((x, "x"), (y, "y"), (p, "p")))
            shapes = {k: np.shape(a) for k, a in zip("txyp", (t, x, y, p))}
            if any(len(shape) != 1 for shape in shapes.values()) or len({shape[0] for shape in shapes.values()}) != 1:
                raise EventDataError(f"t, x, y, p must be 1-D arrays of the same length [N] to be sorted, got shapes "
                                     f"{shapes}; give one value per event in each (np.ravel a column [N, 1])")
            order = np.argsort(t, kind="stable")
            t, x, y, p = (a[order] for a in (t, x, y, p))
        return cls(t, x, y, p, sensor_size, t_origin=t_origin, polarity_encoding=polarity)

    @classmethod
    def from_array(cls, array, sensor_size, *, columns: str = "txyp", **kwargs) -> "Events":
        """Build events from an [N, 4] array whose columns are named by ``columns`` (e.g. 'txyp', 'xytp')."""
        a = np.asarray(host_array(array))
        if a.ndim != 2 or a.shape[1] != 4:
            raise EventDataError(
                f"an event array must have shape [N, 4] with columns {tuple(columns)}; got shape {a.shape}"
            )
        if sorted(columns) != sorted("txyp"):
            raise EventDataError(f"columns must be a permutation of 'txyp', got {columns!r}")
        col = {c: a[:, i] for i, c in enumerate(columns)}
        x, y = col["x"], col["y"]
        return cls.from_arrays(col["t"], x, y, col["p"], sensor_size, **kwargs)

    @classmethod
    def empty(cls, sensor_size, t_origin: float = 0.0) -> "Events":
        z = np.zeros(0)
        return cls(z, z.astype(np.int32), z.astype(np.int32), z.astype(np.int8), sensor_size, t_origin=t_origin)

    @classmethod
    def concatenate(cls, parts: list["Events"], sort: bool = True) -> "Events":
        """Merge event streams on the same sensor and clock (sorted by time, stable)."""
        if isinstance(parts, Events):
            raise EventDataError("concatenate takes a list of Events, got one Events; pass them in a list: "
                                 "Events.concatenate([a, b])")
        if isinstance(parts, (str, bytes, dict)) or not hasattr(parts, "__iter__"):
            raise EventDataError(f"concatenate takes a list of Events, got a {type(parts).__name__}; pass them in a "
                                 "list: Events.concatenate([a, b])")
        parts = list(parts)
        if not parts:
            raise EventDataError("nothing to concatenate: pass at least one Events")
        for i, e in enumerate(parts):
            if not isinstance(e, Events):
                raise EventDataError(f"concatenate: parts[{i}] is a {type(e).__name__}, not Events; pass a list of "
                                     "Events (build each with Events.from_arrays(t, x, y, p, sensor_size))")
        size, origin = parts[0].sensor_size, parts[0].t_origin
        for e in parts[1:]:
            if e.sensor_size != size or e.t_origin != origin:
                raise EventDataError(f"cannot concatenate events with different sensor_size or t_origin (got "
                                     f"{size}, t_origin {origin} and {e.sensor_size}, t_origin {e.t_origin}); put "
                                     "them on one clock first (t + t_origin - common_origin) and one sensor")
        cat = [np.concatenate([getattr(e, k) for e in parts]) for k in "txyp"]
        return cls.from_arrays(*cat, size, sort=sort, t_origin=origin)

    # ---- views --------------------------------------------------------------------
    def __len__(self) -> int:
        return int(self.t.shape[0])

    def __repr__(self) -> str:
        span = f"{self.t[0]:.6f}..{self.t[-1]:.6f} s" if len(self) else "empty"
        return f"Events(n={len(self)}, sensor_size={self.sensor_size}, t={span}, t_origin={self.t_origin})"

    @property
    def duration(self) -> float:
        """Seconds from the first to the last event (0 for fewer than two events)."""
        return float(self.t[-1] - self.t[0]) if len(self) > 1 else 0.0

    def take(self, index) -> "Events":
        """Events selected by a slice, boolean mask or sorted integer index (no re-validation of values).

        The index itself is checked (EventDataError): a mask of another length, indices that are not whole
        numbers, out of range or that put the events out of time order (the events must stay sorted by time;
        events with the same timestamp may be taken in any order)."""
        if not isinstance(index, slice):
            index = _checked_take_index(index, len(self), self.t)
        new = object.__new__(Events)
        for k in "txyp":
            object.__setattr__(new, k, getattr(self, k)[index])
        for k in ("sensor_size", "t_origin", "polarity_encoding"):
            object.__setattr__(new, k, getattr(self, k))
        return new

    def slice_time(self, t_start: float | None = None, t_end: float | None = None,
                   *, allow_empty: bool = False) -> "Events":
        """Events with ``t_start <= t < t_end`` (seconds, same clock as ``self.t``).

        Raises:
            EventDataError: if the window is empty or reversed (unless ``allow_empty``).
        """
        for name, value in (("t_start", t_start), ("t_end", t_end)):
            if value is not None and (not _is_number(value) or math.isnan(float(value))):
                raise EventDataError(f"slice_time: {name} must be seconds (a number, or None for no bound), got "
                                     f"{value!r}")
        lo = 0 if t_start is None else int(np.searchsorted(self.t, t_start, side="left"))
        hi = len(self) if t_end is None else int(np.searchsorted(self.t, t_end, side="left"))
        if t_start is not None and t_end is not None and t_end <= t_start:
            raise EventDataError(f"time window [{t_start}, {t_end}) is empty or reversed; t_end must exceed t_start")
        if hi <= lo and not allow_empty:
            span = f"[{self.t[0]:.6f}, {self.t[-1]:.6f}] s" if len(self) else "nothing (no events)"
            raise EventDataError(
                f"no events in the window [{t_start}, {t_end}) s; the events cover {span} "
                f"(relative to t_origin = {self.t_origin}); choose a window inside that range"
            )
        return self.take(slice(lo, hi))

    def to_array(self) -> np.ndarray:
        """[N, 4] float64 array with columns (t, x, y, p); t relative to ``t_origin``."""
        return np.stack([self.t, self.x, self.y, self.p], axis=1).astype(np.float64)
