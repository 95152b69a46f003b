"""Event frames (Eq. 2 of the paper): per-pixel sums of p*C over time bins.

Bin i holds the events with ``b[i] < t <= b[i+1]`` (bin 0 also holds events at exactly
``b[0]``), so that a model can compare F(b[i+1]) - F(b[i]) with exactly the events that
fired in between. Events outside [b[0], b[-1]] are not counted.
"""
from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from ..core.checks import ArgumentTypeError, host_array, real_number, require, whole_number
from ..core.events import EventDataError, Events, check_sensor_size
from ..core.guard import dense_array

__all__ = ["EventFrames", "fixed_duration_boundaries", "equal_count_boundaries", "events_to_frames",
           "events_to_frames_chunked", "bisect_boundaries", "event_rate", "as_thresholds", "check_boundaries"]


def as_thresholds(C, name: str = "C") -> tuple[float, float]:
    """(c_pos, c_neg) from a contrast threshold given as one number or a pair (log units per event).

    One number c means (c, c); a pair (c_pos, c_neg) weighs ON events by +c_pos and OFF events by
    -c_neg (real sensors differ, see :mod:`evinr_lite.method.contrast`). The one parser of C for
    the binning, the integration, the baselines and the solver.

    Raises:
        EventDataError naming ``name`` when C is not a positive finite number or a pair of them.
    """
    C = host_array(C)
    if isinstance(C, np.ndarray) and C.ndim == 0 and C.dtype.kind in "iuf":   # np.array(0.2), t.max(): a number
        C = C.item()
    if isinstance(C, (str, bytes, bool, np.bool_)):
        values = None
    elif np.ndim(C) == 0:
        values = (C, C)
    else:
        values = tuple(np.asarray(C, dtype=object).ravel()) if np.ndim(C) == 1 else None
    if values is None or len(values) != 2 or not all(
            not isinstance(c, (bool, np.bool_)) and isinstance(c, (int, float, np.integer, np.floating))
            and math.isfinite(c) and c > 0 for c in values):
        raise EventDataError(f"{name} must be a positive number or a pair (c_pos, c_neg) of positive numbers "
                             f"(log units per event, e.g. {name}=0.2 or {name}=(0.22, 0.18)), got {C!r}")
    if max(values) > MAX_C:   # plausibility: beyond it the frames overflow to inf, or saturate to black/white
        raise EventDataError(f"{name}={C!r} is not a plausible contrast threshold: it is the log-intensity change of "
                             f"one event, 0.05 to 1.5 for event cameras, and at most {MAX_C:g} here (e^{MAX_C:g} = "
                             f"{math.exp(MAX_C):,.0f} times brighter per event); pass the camera's C (e.g. {name}=0.2), "
                             "or fit it from the APS frames (C='auto' on the command line: --C auto)")
    return float(values[0]), float(values[1])


MAX_C = 10.0   # log units per event; the largest contrast threshold accepted (see as_thresholds)


@dataclass(frozen=True, eq=False)
class EventFrames:
    """Binned events.

    Attributes:
        frames: float32 [B, H, W], C * sum of polarities of the events in each bin (with a pair
            C = (c_pos, c_neg): c_pos * #ON - c_neg * #OFF).
        boundaries: float64 [B + 1], bin edges in seconds (same clock as the events).
        counts: int64 [B], number of events per bin.
    """

    frames: np.ndarray
    boundaries: np.ndarray
    counts: np.ndarray

    @property
    def centers(self) -> np.ndarray:
        """float64 [B], bin mid-points (where the paper's Eq. 4 evaluates dL/dt)."""
        return 0.5 * (self.boundaries[1:] + self.boundaries[:-1])

    @property
    def durations(self) -> np.ndarray:
        """float64 [B], bin lengths t2 - t1 in seconds."""
        return np.diff(self.boundaries)

    def __len__(self) -> int:
        return int(self.frames.shape[0])


MAX_BINS = 10**9   # edges of more bins than this would not fit in memory (8 GB); refused before they are made


def fixed_duration_boundaries(t_start: float, t_end: float, bin_duration: float = 1 / 32) -> np.ndarray:
    """Edges of consecutive bins of ``bin_duration`` seconds covering [t_start, t_end].

    The last bin is shortened to end exactly at ``t_end``. Returns float64 [B + 1].
    """
    # numbers (0-d arrays and tensors too) by name: text or None were numpy's ufunc or Python's TypeError
    t_start = real_number(t_start, "t_start", hint="the bins' start in seconds")
    t_end = real_number(t_end, "t_end", hint="the bins' end in seconds")
    if t_end <= t_start:
        raise EventDataError(f"bin range [{t_start}, {t_end}] is empty or reversed; t_end must exceed t_start")
    bin_duration = real_number(bin_duration, "bin_duration", lo=0, lo_open=True,
                               hint="positive seconds (the bins' length)")
    n = (t_end - t_start) / bin_duration
    if not n <= MAX_BINS:   # checked before the edges are allocated (1e-12 s over 1000 s: 7 PiB of edges)
        raise EventDataError(f"bins of {bin_duration:g} s over [{t_start}, {t_end}] s would be {n:,.0f} bins (at most "
                             f"{MAX_BINS:,}); use a longer bin_duration or a shorter range")
    n = int(np.ceil(n - 1e-9))
    edges = t_start + bin_duration * np.arange(n + 1, dtype=np.float64)
    edges[-1] = t_end
    return edges


def equal_count_boundaries(events: Events, events_per_bin: int | None = None, n_bins: int | None = None) -> np.ndarray:
    """Edges of bins holding (nearly) equal numbers of events, as the public reference code bins.

    Give exactly one of ``events_per_bin`` or ``n_bins``. Inner edges sit half-way between the
    last event of one bin and the first of the next; the outer edges are the first and last
    event times. Returns float64 [B + 1].
    """
    events = require(events, Events, "events")
    n = len(events)
    if n < 2:
        raise EventDataError(f"equal-count bins need at least 2 events, got {n}; choose a longer time window")
    if (events_per_bin is None) == (n_bins is None):
        raise EventDataError("give exactly one of events_per_bin or n_bins")
    if n_bins is None:
        events_per_bin = real_number(events_per_bin, "events_per_bin", lo=1, hint="events in each bin")
        n_bins = max(1, int(round(n / events_per_bin)))
    n_bins = whole_number(n_bins, "n_bins", lo=1)   # 2.5 and "3" were Python's TypeErrors
    if not 1 <= n_bins <= n:
        raise EventDataError(f"n_bins must be between 1 and the number of events ({n}), got {n_bins}")
    # split index k: bin i holds events [k_i, k_{i+1})
    k = np.round(np.linspace(0, n, n_bins + 1)).astype(np.int64)
    t = events.t
    inner = 0.5 * (t[k[1:-1] - 1] + t[k[1:-1]])
    return np.concatenate([[t[0]], inner, [t[-1]]])


_GROUP_CELLS = 1 << 16   # bins x pixels summed per np.bincount call: small enough to stay in cache


def check_boundaries(boundaries) -> np.ndarray:
    """Bin edges as float64 [B + 1]: numbers, finite, strictly increasing, at least 2; else an EventDataError."""
    b = None if isinstance(boundaries, (str, bytes)) else dense_array(boundaries, "boundaries", error=EventDataError)
    if b is None or b.dtype.kind not in "iuf":   # text was numpy's "could not convert string to float"
        raise EventDataError(f"boundaries must be numbers (bin edges in seconds), got {boundaries!r:.60}")
    b = b.astype(np.float64)
    if b.ndim != 1 or b.size < 2:
        raise EventDataError(f"boundaries must be a 1-D array of at least 2 edges, got shape {b.shape}")
    if not np.all(np.isfinite(b)):
        raise EventDataError("boundaries contain NaN or inf; bin edges must be finite seconds")
    if np.any(np.diff(b) <= 0):
        raise EventDataError("boundaries must be strictly increasing")
    return b


_check_boundaries = check_boundaries


def _bin_edges(t: np.ndarray, b: np.ndarray) -> np.ndarray:
    """int64 [B + 1] event indices: bin i holds events e[i]:e[i+1] (b[i] < t <= b[i+1]; t == b[0] in bin 0).

    Events are sorted by time, so B + 1 binary searches replace one per event.
    """
    e = np.searchsorted(t, b, side="right")
    e[0] = np.searchsorted(t, b[0], side="left")
    return e


def _polarity_sums(events: Events, e: np.ndarray, weights: np.ndarray | None = None):
    """Yield (i0, i1, sums) for runs of consecutive bins [i0, i1) that hold events.

    sums: float64 [(i1 - i0) * H * W], the polarity sum per (bin, row, column), flattened (the sum
    of ``weights`` [N] instead of the polarities when given). Each run
    covers about ``_GROUP_CELLS`` cells, so np.bincount's counters stay in cache; the flat index is
    built in place in one int64 array (pixel = y * W + x, plus the bin's offset).
    """
    H, W = events.sensor_size
    HW = H * W
    per = max(1, _GROUP_CELLS // HW)
    B = len(e) - 1
    for i0 in range(0, B, per):
        i1 = min(B, i0 + per)
        s, stop = int(e[i0]), int(e[i1])
        if stop == s:
            continue
        flat = events.y[s:stop].astype(np.int64)
        flat *= W
        flat += events.x[s:stop]
        if i1 - i0 > 1:
            flat += np.repeat(np.arange(i1 - i0, dtype=np.int64) * HW, np.diff(e[i0:i1 + 1]))
        w = events.p[s:stop] if weights is None else weights[s:stop]
        yield i0, i1, np.bincount(flat, weights=w, minlength=(i1 - i0) * HW)


def events_to_frames(events: Events, boundaries, C: float | tuple = 1.0) -> EventFrames:
    """Sum p * C per pixel and bin (vectorised; no Python loop over events).

    Args:
        events: the events (sorted by time, as `Events` guarantees).
        boundaries: float64 [B + 1] increasing bin edges in seconds; see
            :func:`fixed_duration_boundaries` and :func:`equal_count_boundaries`.
        C: contrast threshold (log-intensity step per event), or a pair (c_pos, c_neg): ON events
            weigh +c_pos, OFF events -c_neg (:func:`as_thresholds`). (c, c) gives exactly the frames of c.

    Returns:
        EventFrames with frames [B, H, W] float32, the boundaries and per-bin counts.
    """
    events = require(events, Events, "events")
    b = _check_boundaries(boundaries)
    c_pos, c_neg = as_thresholds(C)
    H, W = events.sensor_size
    B = b.size - 1
    e = _bin_edges(events.t, b)
    frames = np.zeros((B, H, W), np.float32)
    flat = frames.reshape(-1)
    if c_pos == c_neg:   # one threshold: the polarity sums times C (the float path, unchanged)
        weights, scale = None, c_pos
    else:                # each event weighs its own polarity's threshold
        weights, scale = np.where(events.p > 0, c_pos, -c_neg), 1.0
    for i0, i1, sums in _polarity_sums(events, e, weights):
        np.multiply(sums, scale, out=flat[i0 * H * W:i1 * H * W], casting="unsafe")
    return EventFrames(frames=frames, boundaries=b, counts=np.diff(e))


def events_to_frames_chunked(chunks, boundaries, C: float | tuple = 1.0, sensor_size=None) -> EventFrames:
    """:func:`events_to_frames` of a recording given as time-ordered chunks of Events.

    For recordings that do not fit in memory (e.g. ``evinr_lite.io.canonical.iter_canonical_events``):
    only one chunk of events is held at a time, plus the frames themselves. Per-pixel polarity
    sums are accumulated exactly (int32) and multiplied by C at the end, so the result equals
    ``events_to_frames`` of all the events at once, bit for bit.

    Args:
        chunks: iterable of Events, in time order, all on one sensor (chunks may be empty).
        boundaries: float64 [B + 1] bin edges (seconds). C: contrast threshold, or a pair
            (c_pos, c_neg) (then ON and OFF counts are accumulated apart: twice the int32 memory).
        sensor_size: (H, W); default: the first chunk's.

    Returns:
        EventFrames with frames [B, H, W] float32 and counts [B].
    """
    b = _check_boundaries(boundaries)
    c_pos, c_neg = as_thresholds(C)
    # checked before the first chunk is read (a sensor_size of 5 or (2.5, 3) was Python's unpack error or a frame
    # of 2 rows; chunks of None, a number or text were "not iterable" or "'str' object has no attribute")
    sensor_size = None if sensor_size is None else check_sensor_size(sensor_size)
    if isinstance(chunks, Events):
        raise ArgumentTypeError("chunks= must be an iterable of Events (chunks in time order), got one Events; pass "
                                "[events], or events_to_frames(events, boundaries, C)")
    if isinstance(chunks, (str, bytes)) or not isinstance(chunks, Iterable):
        raise ArgumentTypeError(f"chunks= must be an iterable of Events (chunks in time order, e.g. "
                                f"iter_canonical_events(path)), got {type(chunks).__name__}")
    split = c_pos != c_neg       # asymmetric: OFF counts kept apart in `off` (ON counts in `sums`)
    B = b.size - 1
    sums = counts = off = None
    t_last = -np.inf
    for k, events in enumerate(chunks):
        require(events, Events, f"chunks[{k}]")
        if sums is None:
            H, W = events.sensor_size if sensor_size is None else sensor_size
            sums = np.zeros((B, H, W), np.int32)
            off = np.zeros((B, H, W), np.int32) if split else None
            counts = np.zeros(B, np.int64)
        if tuple(events.sensor_size) != (H, W):
            raise EventDataError(f"chunk on a sensor of {tuple(events.sensor_size)} but the frames are {(H, W)}; "
                                 "all chunks must come from one recording")
        if len(events) == 0:
            continue
        if events.t[0] < t_last:
            raise EventDataError(f"chunks are not in time order (a chunk starts at {events.t[0]} s after one "
                                 f"that ended at {t_last} s); pass them in time order")
        t_last = events.t[-1]
        e = _bin_edges(events.t, b)
        counts += np.diff(e)
        flat = sums.reshape(-1)
        on_w = (events.p > 0).astype(np.float64) if split else None
        for i0, i1, s in _polarity_sums(events, e, on_w):
            flat[i0 * H * W:i1 * H * W] += s.astype(np.int32)
        if split:
            off_flat = off.reshape(-1)
            for i0, i1, s in _polarity_sums(events, e, (events.p < 0).astype(np.float64)):
                off_flat[i0 * H * W:i1 * H * W] += s.astype(np.int32)
    if sums is None:
        if sensor_size is None:
            raise EventDataError("no chunks given and no sensor_size; pass sensor_size=(H, W)")
        H, W = sensor_size
        sums, counts = np.zeros((B, H, W), np.int32), np.zeros(B, np.int64)
        off = np.zeros((B, H, W), np.int32) if split else None
    # int32 -> float32 in place, a few bins at a time (no second [B, H, W] array)
    frames = sums.view(np.float32)
    step = max(1, _GROUP_CELLS // (H * W))
    for i in range(0, B, step):
        if split:
            frames[i:i + step] = c_pos * sums[i:i + step].astype(np.float64) - c_neg * off[i:i + step]
        else:
            frames[i:i + step] = c_pos * sums[i:i + step].astype(np.float64)
    return EventFrames(frames=frames, boundaries=b, counts=counts)


def bisect_boundaries(events: Events, boundaries) -> np.ndarray:
    """Split every bin into two halves holding equal numbers of events (coarse-to-fine, Sec. 3.3).

    A bin (b_i, b_{i+1}] holding n >= 2 events is cut half-way between its event n//2 - 1 and
    event n//2 (0-based, in time order); a bin with fewer than 2 events, or whose cut would
    coincide with an edge, is cut at its time mid-point. Returns float64 [2B + 1].
    """
    events = require(events, Events, "events")
    b = _check_boundaries(boundaries)   # NaN edges came back NaN, decreasing ones reversed, one edge an IndexError
    t = events.t
    # index range of each bin's events under the (b_i, b_{i+1}] convention (bin 0 closed on the left)
    start = np.searchsorted(t, b[:-1], side="right")
    start[0] = np.searchsorted(t, b[0], side="left")
    stop = np.searchsorted(t, b[1:], side="right")
    n = stop - start
    k = start + n // 2
    enough = n >= 2
    cut = 0.5 * (b[:-1] + b[1:])
    kk = np.clip(k, 1, max(len(t) - 1, 1))
    if len(t) >= 2:
        median_cut = 0.5 * (t[kk - 1] + t[kk])
        ok = enough & (median_cut > b[:-1]) & (median_cut < b[1:])
        cut = np.where(ok, median_cut, cut)
    out = np.empty(2 * len(b) - 1)
    out[0::2] = b
    out[1::2] = cut
    return out


def event_rate(events: Events, bin_s: float, t_range=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ON and OFF events per second over the whole sensor, in consecutive bins of ``bin_s`` seconds.

    Args:
        events: the events.
        bin_s: bin length (s); the last bin is shortened to end at ``t_range[1]``.
        t_range: (t0, t1) seconds; default the first and last event times.

    Returns:
        (edges float64 [B + 1], on_rate float64 [B], off_rate float64 [B]), rates in events/s.
        Bin i holds the events with ``edges[i] < t <= edges[i+1]`` (bin 0 also those at edges[0]),
        so ``rate * np.diff(edges)`` gives the counts.
    """
    events = require(events, Events, "events")
    if t_range is None:
        if len(events) < 2:
            raise EventDataError("event_rate needs t_range when there are fewer than 2 events")
        t_range = (events.t[0], events.t[-1])
    if isinstance(t_range, (str, bytes)) or np.ndim(t_range) != 1 or len(t_range) != 2:   # 3 values: 2 used
        raise EventDataError(f"t_range must be (t0, t1), two times in seconds, got {t_range!r}")
    # named as the caller gave them, not as fixed_duration_boundaries' t_start / t_end / bin_duration
    t0 = real_number(t_range[0], "t_range[0]", hint="seconds")
    t1 = real_number(t_range[1], "t_range[1]", lo=t0, lo_open=True, hint="seconds, after t_range[0]")
    bin_s = real_number(bin_s, "bin_s", lo=0, lo_open=True, hint="a positive number of seconds per bin (e.g. 0.01)")
    edges = fixed_duration_boundaries(t0, t1, bin_s)
    B = edges.size - 1
    idx = np.searchsorted(edges, events.t, side="left") - 1
    idx[events.t == edges[0]] = 0
    keep = (idx >= 0) & (idx < B)
    dur = np.diff(edges)
    on = np.bincount(idx[keep & (events.p > 0)], minlength=B) / dur
    off = np.bincount(idx[keep & (events.p < 0)], minlength=B) / dur
    return edges, on, off


# ---- figures ------------------------------------------------------------------------------
