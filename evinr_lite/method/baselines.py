"""Baselines without learning: direct, leaky and high-pass-filtered event integration.

All three solve the per-pixel equation dL/dt = E(t) - rate * (L - L_rest), where
E(t) = sum_i C p_i delta(t - t_i) is the event stream of that pixel:

- ``integration``: rate = 0, L(t) = L0 + C sum p (Eq. 2; :func:`evinr_lite.method.integration.integrate_events`).
- ``leaky``: every event's contribution fades as exp(-leak_hz * age): L(t) = L0 + sum C p exp(-leak (t - t_i)).
  The start image L0 does not fade (L_rest = L0): a leak only forgets accumulated noise.
- ``hf``: the high-pass filter of Scheerlinck et al. (ACCV 2018, "Continuous-time intensity
  estimation using event cameras", without frames), the 'HF' row of the EvINR paper's Table 1.
  Its state, L0 included, decays towards 0 at alpha = 2 pi cutoff_hz rad/s (L_rest = 0), and each
  event adds C p. Per pixel, at each event:  L <- exp(-alpha (t - t_last)) L + C p;  t_last <- t.
  Low temporal frequencies (static scene content, drift, and the unknown L0) are filtered out.

Both decays are computed exactly (no time step): between query times every pixel's state is
multiplied by exp(-rate dt) and the events in between are added with their own decay factors, so the
vectorised form costs O(N + Q H W) and agrees with the per-event loop to rounding.

:func:`reconstruct_baseline` turns any of them into frames exactly like the EvINR solver does
(brightness anchor, then Reinhard tone mapping), so baselines and EvINR are scored by one path
(:mod:`evinr_lite.evaluation.scoring`).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..core.checks import (ArgumentTypeError, check_reach, check_seconds_precision, choice, host_array, is_real_number,
                           numbers_array, optional_seconds, real_number, require, seconds_array)
from ..core.events import EventDataError, Events, check_sensor_size
from ..core.guard import dense_array
from ..core.frames import Frames
from .anchor import frame_log, linear_frames_unchecked
from .binning import as_thresholds
from .integration import integrate_events
from .offset import OFFSET_SOLVES, offset_image
from .tonemap import DEFAULT_DISPLAY_MEAN, DEFAULT_TONEMAP, TONEMAPS, display_shift, to_display

__all__ = ["leaky_integration", "highpass_filter", "highpass_per_event", "reconstruct_baseline",
           "BaselineReconstruction", "BASELINES", "DEFAULT_CUTOFF_HZ", "complementary_filter", "DEFAULT_GAIN",
           "FRAME_BASELINES", "BASELINE_PARAMS"]

BASELINES = ("integration", "leaky", "hf")
FRAME_BASELINES = ("complementary",)   # baselines that need APS frames (reconstruct_baseline(frames=...))
BASELINE_PARAMS = {"integration": ("L0",), "leaky": ("leak_hz", "L0"), "hf": ("cutoff_hz", "L0"),
                   "complementary": ("gain",)}   # the keyword parameters each baseline takes
DEFAULT_CUTOFF_HZ = 1.0   # alpha = 2 pi rad/s; a tunable choice (Scheerlinck et al. expose it as a parameter)


# ---- argument checks -------------------------------------------------------------------------

def _rate(value, name: str) -> float:
    """A rate as a float: a finite number >= 0, a 0-d array or tensor too (as C is taken); else an EventDataError."""
    value = host_array(value)
    if not (is_real_number(value) and np.isfinite(value) and value >= 0):
        raise EventDataError(f"{name} must be a finite number >= 0 (per second), got {value!r}")
    return float(value)


def _query(t_query) -> np.ndarray:
    t_query = host_array(t_query)
    arr = None if isinstance(t_query, (str, bytes)) else dense_array(t_query, "query times", error=EventDataError)
    if arr is None or arr.dtype.kind not in "iuf":
        raise EventDataError(f"query times must be seconds (a number, a list or a 1-D array of numbers), got "
                             f"{t_query!r:.60}")
    check_seconds_precision(arr, "query_times")
    tq = arr.astype(np.float64)
    if tq.ndim > 1 or tq.size == 0 or not np.all(np.isfinite(tq)):
        raise EventDataError(f"query times must be a finite scalar or a non-empty 1-D array of seconds, got shape {tq.shape}")
    return tq


def _initial(L0, sensor_size) -> np.ndarray | float:
    if L0 is None:
        return 0.0
    arr = None if isinstance(L0, (str, bytes)) else dense_array(L0, "L0", error=EventDataError)
    if arr is None or arr.dtype.kind not in "iuf":   # text and complex were Python's float() errors
        raise EventDataError(f"L0 must be log intensities (a number or an [H, W] array of numbers), got {L0!r:.60}")
    L0 = arr.astype(np.float64)
    if np.ndim(L0) not in (0, 2) or (np.ndim(L0) == 2 and L0.shape != tuple(sensor_size)):
        raise EventDataError(f"L0 must be a scalar or an [H, W] = {tuple(sensor_size)} array, got shape {np.shape(L0)}")
    if not np.all(np.isfinite(L0)):   # NaN gave NaN frames
        raise EventDataError(f"L0 must be finite log intensities, but it holds {int(np.sum(~np.isfinite(L0)))} NaN or "
                             "inf value(s); take the log of intensities clipped above 0")
    return L0


def _start_time(events: Events, tq: np.ndarray, t_start) -> float:
    first = events.t[0] if len(events) else tq.min()
    t_start = optional_seconds(t_start, "t_start")   # NaN gave NaN frames, "0" was read as a number
    t0 = min(first, tq.min()) if t_start is None else t_start
    if tq.min() < t0:
        raise EventDataError(f"query time {tq.min()} s is before t_start = {t0} s; query at or after the start")
    return t0


# ---- the shared core --------------------------------------------------------------------------

def _decayed_sums(events: Events, t_sorted: np.ndarray, C_pos: float, C_neg: float, rate: float,
                  t_start: float) -> np.ndarray:
    """float64 [Q, H, W]: sum over events with t_start <= t_i <= t_q of C p_i exp(-rate (t_q - t_i)).

    ``t_sorted`` must be increasing. One pass over the queries; the events between two queries are
    added with np.bincount (no Python loop over events).
    """
    H, W = events.sensor_size
    t = events.t
    pix = events.y.astype(np.int64) * W + events.x
    weight = np.where(events.p > 0, C_pos, -C_neg)
    state = np.zeros(H * W)
    out = np.empty((len(t_sorted), H, W))
    lo = int(np.searchsorted(t, t_start, side="left"))
    ends = np.searchsorted(t, t_sorted, side="right")
    t_prev = t_start
    for q, (tq, hi) in enumerate(zip(t_sorted, ends)):
        if rate > 0:
            state *= math.exp(-rate * (tq - t_prev))
        if hi > lo:
            w = weight[lo:hi] if rate == 0 else weight[lo:hi] * np.exp(-rate * (tq - t[lo:hi]))
            state += np.bincount(pix[lo:hi], weights=w, minlength=H * W)
        out[q] = state.reshape(H, W)
        t_prev, lo = tq, max(lo, int(hi))
    return out


def _per_query(fn, tq: np.ndarray) -> np.ndarray:
    """Evaluate fn(sorted unique times) -> [U, H, W] and return it in the order of tq (scalar -> [H, W])."""
    uniq, inverse = np.unique(np.atleast_1d(tq), return_inverse=True)
    L = fn(uniq)[inverse.ravel()]
    return L[0] if tq.ndim == 0 else L


# ---- the baselines ----------------------------------------------------------------------------

def leaky_integration(events: Events, query_times, C=0.2, leak_hz: float = 0.0, L0=None, *,
                      t_start: float | None = None) -> np.ndarray:
    """Leaky event integration: L(t) = L0 + sum over events t_i <= t of C p_i exp(-leak_hz (t - t_i)).

    Args:
        events: the events (same clock as the query times).
        query_times: seconds, a scalar or [Q] (any order, repeats allowed).
        C: contrast threshold (log units), or (C_pos, C_neg).
        leak_hz: decay rate in 1/s (an event's contribution falls to 1/e after 1/leak_hz s);
            0 gives plain integration (== :func:`evinr_lite.method.integration.integrate_events`).
        L0: log intensity at the start (scalar or [H, W]); default 0. It does not leak.
        t_start: events before it are ignored; default: the first event (or query).

    Returns:
        float64 [Q, H, W] log intensity ([H, W] for a scalar query).
    """
    events = require(events, Events, "events")
    tq = _query(query_times)
    C_pos, C_neg = as_thresholds(C)
    leak = _rate(leak_hz, "leak_hz")
    L0 = _initial(L0, events.sensor_size)
    t0 = _start_time(events, tq, t_start)
    return _per_query(lambda u: L0 + _decayed_sums(events, u, C_pos, C_neg, leak, t0), tq)


LOOPS = ("vectorised", "per_event")   # how highpass_filter and complementary_filter run


def highpass_filter(events: Events, query_times, C=0.2, cutoff_hz: float = DEFAULT_CUTOFF_HZ, L0=None,
                    method: str = "vectorised", *, t_start: float | None = None) -> np.ndarray:
    """The high-pass filter of Scheerlinck et al. (ACCV 2018): log intensity from events alone.

    Per pixel, dL/dt = E(t) - alpha L with alpha = 2 pi cutoff_hz (rad/s) and L(t_start) = L0:
    L(t) = L0 exp(-alpha (t - t_start)) + sum over t_i <= t of C p_i exp(-alpha (t - t_i)).

    Args:
        events, query_times, C, t_start: as in :func:`leaky_integration`.
        cutoff_hz: cut-off frequency in Hz (>= 0); 0 gives plain integration.
        L0: state at t_start (scalar or [H, W]); default 0. It decays like everything else.
        method: "vectorised" (default) or "per_event" (a plain Python loop over events, the
            filter's published per-event update; slow, a reference for tests and teaching).

    Returns:
        float64 [Q, H, W] ([H, W] for a scalar query).
    """
    events = require(events, Events, "events")
    tq = _query(query_times)
    C_pos, C_neg = as_thresholds(C)
    alpha = 2 * math.pi * _rate(cutoff_hz, "cutoff_hz")
    L0 = _initial(L0, events.sensor_size)
    t0 = _start_time(events, tq, t_start)
    method = choice(method, LOOPS, "method")   # an array was numpy's "truth value ... is ambiguous"
    if method == "vectorised":
        def fn(u):
            return np.exp(-alpha * (u - t0))[:, None, None] * L0 + _decayed_sums(events, u, C_pos, C_neg, alpha, t0)
    elif method == "per_event":
        def fn(u):
            return _highpass_loop(events, u, C_pos, C_neg, alpha, t0, L0)
    return _per_query(fn, tq)


def _highpass_loop(events: Events, t_sorted, C_pos, C_neg, alpha, t_start, L0) -> np.ndarray:
    """The per-event update in a plain loop; snapshots at the (sorted) query times. [Q, H, W]."""
    H, W = events.sensor_size
    state = np.zeros((H, W)) + L0
    t_last = np.full((H, W), t_start)
    out = np.empty((len(t_sorted), H, W))
    q = 0
    for t, x, y, p in zip(events.t, events.x, events.y, events.p):
        if t < t_start:
            continue
        while q < len(t_sorted) and t_sorted[q] < t:        # snapshot: every pixel decayed to the query time
            out[q] = state * np.exp(-alpha * (t_sorted[q] - t_last))
            q += 1
        state[y, x] = math.exp(-alpha * (t - t_last[y, x])) * state[y, x] + (C_pos if p > 0 else -C_neg)
        t_last[y, x] = t
    for k in range(q, len(t_sorted)):
        out[k] = state * np.exp(-alpha * (t_sorted[k] - t_last))
    return out


def highpass_per_event(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    """The high-pass filter, one event at a time (exercise reference).

    Every pixel starts at 0 at ``t_start``. For each event in time order, at pixel (y, x):
    decay its state by exp(-alpha * (t - t_last)), where t_last is the time of that pixel's
    previous event (or t_start), then add C * p, then set t_last = t. At the end every pixel
    is decayed to ``t_end``.

    Args:
        t: float64 [N] seconds, sorted. x, y: int [N] column and row. p: int [N] in {-1, +1}.
        sensor_size: (H, W). C: contrast threshold. alpha: cut-off in rad/s. t_end: seconds.

    Returns:
        float64 [H, W], the log intensity at t_end.
    """
    t, x, y, p, (H, W), C, alpha, t_end, t_start = _check_per_event(t, x, y, p, sensor_size, C, alpha, t_end, t_start)
    state = np.zeros((H, W))
    t_last = np.full((H, W), float(t_start))
    for ti, xi, yi, pi in zip(t, x, y, p):
        state[yi, xi] = np.exp(-alpha * (ti - t_last[yi, xi])) * state[yi, xi] + C * pi
        t_last[yi, xi] = ti
    return state * np.exp(-alpha * (t_end - t_last))


def _check_per_event(t, x, y, p, sensor_size, C, alpha, t_end, t_start) -> tuple:
    """highpass_per_event's arguments, checked before its loop: columns of one length (t numbers in time order, its
    dtype kept; x, y whole pixels on the sensor; p finite numbers, not bools), C, alpha and the times finite numbers, t_start at or
    before the first event and t_end at or after the last (a t_end before it grew the state). alpha may be any finite
    number: the exercise's wrong solutions pass -alpha."""
    H, W = check_sensor_size(sensor_size)
    if getattr(host_array(p), "dtype", None) == bool or (isinstance(p, (list, tuple)) and p and
                                                          all(isinstance(v, (bool, np.bool_)) for v in p)):
        # bool polarities used to add C for True and nothing for False: OFF events were lost without a word
        raise EventDataError("p= must be polarities +1/-1 (one number per event), got bools (ON/OFF flags); pass "
                             "np.where(p, 1, -1)")
    cols = []
    for name, col in (("t", t), ("x", x), ("y", y), ("p", p)):
        arr = numbers_array(col, name, "one number per event (a 1-D array)")
        if arr.ndim != 1:
            raise EventDataError(f"{name}= must be a 1-D array (one value per event), got shape {arr.shape}")
        cols.append(arr)
    t, x, y, p = cols
    if not len(t) == len(x) == len(y) == len(p):
        raise EventDataError(f"t, x, y and p must have one value per event, got lengths {len(t)}, {len(x)}, {len(y)} "
                             f"and {len(p)}")
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) < 0):
        raise EventDataError("t= must be finite seconds in time order (sorted); sort the events by time first")
    for name, col, n in (("x", x, W), ("y", y, H)):
        if col.dtype.kind == "f" and not np.all(col == np.round(col)) or len(col) and (col.min() < 0 or col.max() >= n):
            raise EventDataError(f"{name}= must be whole pixel indices in [0, {n - 1}] for sensor_size {(H, W)} (H, W); "
                                 f"got values in [{col.min() if len(col) else 0}, {col.max() if len(col) else 0}]")
    x, y = x.astype(np.int64), y.astype(np.int64)
    if not np.all(np.isfinite(p)):   # the state became NaN (or inf) at that pixel, without a word
        bad = int(np.flatnonzero(~np.isfinite(p))[0])
        raise EventDataError(f"p= must be finite polarities (+1/-1), but p[{bad}] = {p[bad]}; drop those events or "
                             "give them their polarity")
    C = real_number(C, "C", hint="the contrast threshold in log units (e.g. 0.2)")
    alpha = real_number(alpha, "alpha", hint="the cut-off in rad/s")
    t_start = real_number(t_start, "t_start", hint="seconds: every pixel starts at 0 then")
    t_end = real_number(t_end, "t_end", hint="seconds: the time of the returned state")
    if len(t) and t_start > t[0]:
        raise EventDataError(f"t_start={t_start:g} s is after the first event (t[0]={t[0]:g} s): pass t_start <= t[0] "
                             "and t_end >= t[-1] (the span the events lie in)")
    if len(t) and t_end < t[-1]:   # the state grew: the last events' decay ran backwards
        raise EventDataError(f"t_end={t_end:g} s is before the last event (t[-1]={t[-1]:g} s): pass t_start <= t[0] "
                             "and t_end >= t[-1] (the span the events lie in)")
    if t_end < t_start:
        raise EventDataError(f"t_end={t_end:g} s comes before t_start={t_start:g} s; t_end must not come first")
    return t, x, y, p, (H, W), C, alpha, t_end, t_start


# ---- the complementary filter: events plus APS frames ------------------------------------------

DEFAULT_GAIN = 2 * math.pi   # rad/s: Scheerlinck et al.'s crossover of about 1 Hz


def _frame_logs(frames, sensor_size):
    """(times [F], log frames [F, H, W]) of APS frames, checked and sorted (log(I + eps), anchor.frame_log)."""
    if not isinstance(frames, Frames) or len(frames) == 0:
        raise EventDataError("the complementary filter needs APS frames: pass frames= as a non-empty "
                             "evinr_lite.core.frames.Frames (e.g. recording.frames) on the events' clock")
    if tuple(frames.size) != tuple(sensor_size):
        raise EventDataError(f"the APS frames are {frames.size} (H, W) but the events' sensor is {tuple(sensor_size)}; "
                             "pass the frames of the same camera")
    frames = frames.sorted()
    return frames.t, frame_log(frames.images)


def complementary_filter(events: Events, frames, query_times, C=0.2, gain: float = DEFAULT_GAIN,
                         method: str = "vectorised", *, t_start: float | None = None) -> np.ndarray:
    """The complementary filter of Scheerlinck, Barnes, Mahony (ACCV 2018): events plus APS frames.

    Per pixel, dL/dt = E(t) - alpha (L - L_F(t)), where E(t) = sum C p_i delta(t - t_i) and L_F(t) is
    the log of the latest APS frame (log(I + eps), eps = 1/255, as :mod:`evinr_lite.method.anchor`),
    starting from L(t_start) = L_F(t_start). Events carry the high temporal frequencies, frames the
    low ones; alpha = ``gain`` (rad/s) is the crossover. With no frame update the state relaxes to
    the latest frame as exp(-alpha dt); gain 0 is direct integration from the first frame; with
    L_F = 0 it is :func:`highpass_filter`. Solved exactly between events and frames: the event part
    is the high-pass filter's decayed sum, the frame part X solves dX/dt = -alpha (X - L_F) exactly on
    each interval where L_F is constant.

    Args:
        events: the events. frames: APS frames (:class:`~evinr_lite.core.frames.Frames`, same clock
            and sensor size); only those up to a query time reach it (causal).
        query_times: seconds, scalar or [Q], at or after t_start.
        C: contrast threshold (or (C_pos, C_neg)). gain: alpha in rad/s (>= 0).
        method: "vectorised" or "per_event" (the published per-event update in a plain loop; a
            reference for tests).
        t_start: where the filter starts (seconds); default the first frame's time. A frame must lie
            at or before it.

    Returns:
        float64 [Q, H, W] log intensity ([H, W] for a scalar query).
    """
    events = require(events, Events, "events")
    tq = _query(query_times)
    C_pos, C_neg = as_thresholds(C)
    alpha = _rate(gain, "gain")
    ft, LF = _frame_logs(frames, events.sensor_size)
    t_start = optional_seconds(t_start, "t_start")   # NaN was said to lie before the first frame
    t0 = float(ft[0]) if t_start is None else t_start
    if not ft[0] <= t0:
        raise EventDataError(f"the complementary filter starts from an APS frame, but t_start = {t0} s is before the "
                             f"first frame ({ft[0]} s); pass t_start at or after it")
    if tq.min() < t0:
        raise EventDataError(f"query time {tq.min()} s is before the filter's start {t0} s (the first frame); "
                             "query at or after it")
    method = choice(method, LOOPS, "method")   # an array was numpy's "truth value ... is ambiguous"
    if method == "vectorised":
        def fn(u):
            return _frame_part(ft, LF, u, alpha, t0) + _decayed_sums(events, u, C_pos, C_neg, alpha, t0)
    elif method == "per_event":
        def fn(u):
            return _complementary_loop(events, ft, LF, u, C_pos, C_neg, alpha, t0)
    return _per_query(fn, tq)


def _frame_part(ft, LF, t_sorted, alpha, t0) -> np.ndarray:
    """X at sorted times [Q]: dX/dt = -alpha (X - L_F(t)), X(t0) = L_F(t0); [Q, H, W] float64."""
    k = int(np.searchsorted(ft, t0, side="right")) - 1           # the latest frame at t0
    X, cur, t_prev = LF[k].copy(), LF[k], t0
    out = np.empty((len(t_sorted), *LF.shape[1:]))
    for q, t in enumerate(t_sorted):
        while k + 1 < len(ft) and ft[k + 1] <= t:                # frame switches on the way to t
            k += 1
            X = cur + (X - cur) * math.exp(-alpha * (ft[k] - t_prev))
            cur, t_prev = LF[k], ft[k]
        out[q] = cur + (X - cur) * math.exp(-alpha * (t - t_prev))
    return out


def _complementary_loop(events: Events, ft, LF, t_sorted, C_pos, C_neg, alpha, t0) -> np.ndarray:
    """The per-event update in a plain loop over events and frames; snapshots at sorted queries."""
    k = int(np.searchsorted(ft, t0, side="right")) - 1
    state, cur = LF[k].copy(), LF[k]
    t_last = np.full(state.shape, t0)
    out = np.empty((len(t_sorted), *state.shape))
    ev = [(t, 1, (x, y, p)) for t, x, y, p in zip(events.t, events.x, events.y, events.p) if t >= t0]
    fr = [(ft[j], 0, j) for j in range(k + 1, len(ft))]
    q = 0
    for t, kind, item in sorted(ev + fr, key=lambda e: (e[0], e[1])):
        while q < len(t_sorted) and t_sorted[q] < t:
            out[q] = cur + (state - cur) * np.exp(-alpha * (t_sorted[q] - t_last))
            q += 1
        if kind == 0:                                           # a new frame: every pixel brought to t first
            state = cur + (state - cur) * np.exp(-alpha * (t - t_last))
            t_last[:] = t
            cur = LF[item]
        else:
            x, y, p = item
            state[y, x] = cur[y, x] + (state[y, x] - cur[y, x]) * math.exp(-alpha * (t - t_last[y, x])) + \
                (C_pos if p > 0 else -C_neg)
            t_last[y, x] = t
    for j in range(q, len(t_sorted)):
        out[j] = cur + (state - cur) * np.exp(-alpha * (t_sorted[j] - t_last))
    return out


# ---- frames, as the EvINR solver makes them ----------------------------------------------------

@dataclass(eq=False)
class BaselineReconstruction:
    """A baseline's predictions, interchangeable with :class:`evinr_lite.method.solver.Reconstruction`.

    Attributes:
        times: float64 [Q] query times (s). log_intensity: float64 [Q, H, W], anchored.
        frames: float32 [Q, H, W] tone-mapped, in [0, 1]. method: "integration", "leaky" or "hf".
        params: the method's parameters (C, gamma, leak_hz / cutoff_hz, ...).
        offset: the constant added by the brightness anchor. history: {"train_time_s": 0.0, "time_s": ...}.
    """

    times: np.ndarray
    log_intensity: np.ndarray
    frames: np.ndarray
    method: str
    params: dict
    offset: float
    history: dict = field(repr=False, default_factory=dict)
    _fn: object = field(repr=False, default=None)       # times [Q] -> log intensity before the anchor

    def at(self, times) -> np.ndarray:
        """Anchored log intensity at other times: float64 [Q, H, W] (recomputed from the events)."""
        return self._fn(seconds_array(times, "times", allow_empty=True)) + self.offset   # "0.1", True refused

    def frames_at(self, times) -> np.ndarray:
        if self.method in FRAME_BASELINES:     # in the APS frames' own intensity space
            return linear_frames_unchecked(self.at(times))
        return to_display(self.at(times), self.params["tonemap"], self.params["gamma"]).astype(np.float32)


def reconstruct_baseline(events: Events, query_times, method: str = "integration", C=0.2, gamma: float = 0.6,
                         display_mean: float = DEFAULT_DISPLAY_MEAN, *, t_start: float | None = None,
                         t_end: float | None = None, offset_solve: str = "none", frames=None,
                         tonemap: str = DEFAULT_TONEMAP, **params) -> BaselineReconstruction:
    """Frames from a baseline, made like the EvINR solver's: anchor, then the display's tone map.

    The brightness anchor is the solver's: one constant is added so that the log intensity over 64
    times spread over [t_start, t_end] displays at ``display_mean``
    (:func:`~evinr_lite.method.tonemap.display_shift`). ``tonemap`` and ``display_mean`` default to
    the kit's (:class:`~evinr_lite.method.config.EvINRConfig`), so a baseline and the kit are shown,
    and scored, alike; pass ``tonemap="reinhard", display_mean=0.5`` for the paper's display.

    Args:
        events: the events. query_times: [Q] seconds.
        method: "integration", "leaky" (params: leak_hz, L0) or "hf" (params: cutoff_hz, L0).
        C: contrast threshold (or (C_pos, C_neg)). gamma: Reinhard's exponent. tonemap: "linear" or "reinhard".
        t_start, t_end: span of the anchor (default: first/last event, widened to the queries).
        offset_solve: "none" (one constant, as always), or "median_gradient" / "l1_gradient": the
            per-pixel offset of :mod:`evinr_lite.method.offset`, the kit's ghost solve, applied to the
            baseline (an ablation: ``benchmarks/quality_zoo.py --methods integration_offset``).
        frames: APS frames, for method "complementary" (params: gain in rad/s): the
            :func:`complementary_filter`, which starts at the first frame (default t_start). Its
            level is the frames': no anchor, no tone map; its frames are the frames' linear
            intensity, clip(exp(L) - eps, 0, 1) (:func:`evinr_lite.method.anchor.linear_frames`).

    Returns:
        BaselineReconstruction with ``.frames`` [Q, H, W] in [0, 1].
    """
    events = require(events, Events, "events")                 # every argument checked before any work
    choice(tonemap, TONEMAPS, "tonemap")
    choice(method, BASELINES + FRAME_BASELINES, "method")
    choice(offset_solve, OFFSET_SOLVES, "offset_solve")
    t_start, t_end = optional_seconds(t_start, "t_start"), optional_seconds(t_end, "t_end")
    if t_start is not None and t_end is not None and not t_end > t_start:
        raise EventDataError(f"the span [t_start, t_end] = [{t_start}, {t_end}] s is empty or reversed; t_end must "
                             "exceed t_start (or leave both out)")
    if tonemap == "reinhard":
        real_number(gamma, "gamma", lo=0, lo_open=True, hint="Reinhard's exponent (the paper's 0.6)")
    real_number(display_mean, "display_mean", lo=0, hi=1, lo_open=True, hint="the mean displayed level (e.g. 0.4)")
    if method == "complementary":
        return _complementary_reconstruction(events, query_times, C, frames, params.get("gain", DEFAULT_GAIN),
                                             t_start, offset_solve, gamma, display_mean, set(params) - {"gain"})
    if frames is not None:
        raise ArgumentTypeError(f"baseline {method!r} takes no frames (events only); frames= is for "
                                "method='complementary'")
    extra = set(params) - set(BASELINE_PARAMS[method])
    if extra:
        raise ArgumentTypeError(f"baseline {method!r} takes parameters {BASELINE_PARAMS[method]}, not {sorted(extra)}")
    q = _query(query_times)
    q = np.atleast_1d(q)
    first, last = (events.t[0], events.t[-1]) if len(events) else (q.min(), q.max())
    lo = min(first, q.min()) if t_start is None else float(t_start)
    hi = max(last, q.max()) if t_end is None else float(t_end)
    check_reach(lo, hi, events.t, events.t_origin, "query_times= (or t_start, t_end)")
    if method == "integration":
        def fn(t):
            return integrate_events(events, t, C=C, L0=params.get("L0"))
    elif method == "leaky":
        def fn(t):
            return leaky_integration(events, t, C, params.get("leak_hz", 0.0), params.get("L0"), t_start=lo)
    else:
        def fn(t):
            return highpass_filter(events, t, C, params.get("cutoff_hz", DEFAULT_CUTOFF_HZ), params.get("L0"),
                                   t_start=lo)
    t0 = time.perf_counter()
    grid = np.linspace(lo, hi, 64)
    L_all = fn(np.concatenate([grid, q]))
    g = offset_image(L_all[:len(grid)], offset_solve) if offset_solve != "none" else 0.0
    offset = g + display_shift(L_all[:len(grid)] + g, tonemap, gamma, display_mean)
    L = L_all[len(grid):] + offset
    frames = to_display(L, tonemap, gamma).astype(np.float32)
    seconds = time.perf_counter() - t0
    rec = BaselineReconstruction(q, L, frames, method, {"C": C, "tonemap": tonemap, "gamma": gamma, "display_mean": display_mean,
                                                        "offset_solve": offset_solve, **{k: v for k, v in params.items() if k != "L0"}},
                                 offset, {"train_time_s": 0.0, "time_s": seconds}, fn)
    return rec


def _complementary_reconstruction(events, query_times, C, frames, gain, t_start, offset_solve, gamma, display_mean,
                                  extra) -> BaselineReconstruction:
    """reconstruct_baseline(method="complementary"): the filter's log intensity, in the frames' own level."""
    if extra:
        raise ArgumentTypeError(f"baseline 'complementary' takes parameters ('gain',), not {sorted(extra)}")
    if offset_solve != "none":
        raise EventDataError("offset_solve must be 'none' for the complementary filter: the frames fix its offset")
    q = np.atleast_1d(_query(query_times))

    def fn(t):
        return complementary_filter(events, frames, t, C, gain, t_start=t_start)

    t0 = time.perf_counter()
    L = fn(q)
    seconds = time.perf_counter() - t0
    return BaselineReconstruction(q, L, linear_frames_unchecked(L), "complementary",
                                  {"C": C, "gamma": gamma, "display_mean": display_mean, "offset_solve": "none",
                                   "gain": float(gain), "output": "linear"}, 0.0,
                                  {"train_time_s": 0.0, "time_s": seconds}, fn)
