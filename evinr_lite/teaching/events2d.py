"""Many pixels: events from a moving picture, and event frames (Eq. 2). Notebook 02.

The reference solutions of notebook 02's exercises live here and are registered with
:mod:`evinr_lite.teaching.exercises` at import:

- :func:`esim_interval`: one pixel, one frame interval of the ESIM-style simulator: every
  level crossed between two samples is one event, with a linearly interpolated timestamp.
  :func:`evinr_lite.sim.simulate.simulate_video` does exactly this for all pixels at once.
- :func:`events_to_frames_fixed`: Eq. 2 per pixel and bin, C times the sum of polarities of
  the events in (b_i, b_{i+1}], written with ``np.add.at``.
  :func:`evinr_lite.method.binning.events_to_frames` is the package's version (with ``np.bincount``).
- :func:`interval_imbalance`: the ON/OFF imbalance from the intervals between consecutive events of
  one polarity at each pixel, pooled over the sensor. :func:`evinr_lite.method.balance.interval_sums`
  and :func:`~evinr_lite.method.balance.interval_imbalance` are the package's (per-pixel sums carried
  across chunks, hot pixels left out), and the kit takes its minmod with the edges' estimate (b that keeps each edge's change from following
  its two pixels' count difference; the counts alone on spans with many events per pixel).

Small helpers for the notebook: :func:`pixel_trace` (one pixel's events) and
:func:`busiest_pixel`.

Times are float64 seconds; polarities are +-1; C is the contrast threshold (log units).
"""
from __future__ import annotations

import numpy as np

from . import exercises
from ..core.checks import require, whole_number
from ..core.events import EventDataError, Events

__all__ = ["esim_interval", "events_to_frames_fixed", "interval_imbalance", "pixel_trace", "busiest_pixel"]


# ---- exercise 1: the simulator for one pixel and one frame interval ------------------------

def esim_interval(L_a, L_b, t_a, t_b, ref, C):
    """Events of one pixel between two samples of its log intensity (ESIM-style).

    Between the samples (t_a, L_a) and (t_b, L_b), L is taken to be linear. The pixel fires an
    ON event at each level ``ref + k*C`` (k = 1, 2, ...) that L reaches on the way up, or an OFF
    event at each level ``ref - k*C`` on the way down; the time of an event is where the
    straight line from L_a to L_b crosses its level.

    Args:
        L_a, L_b: log intensity at the two samples (floats).
        t_a, t_b: the sample times (s), t_a < t_b.
        ref: the pixel's reference level (log intensity of its last event, or L at the start).
        C: contrast threshold (log units), the same for ON and OFF.

    Returns:
        (times float64 [n], polarities int8 [n], new reference level float): n >= 0 events in
        time order, and the reference moved by exactly n steps of C (not set to L_b).
    """
    d = L_b - ref
    p = 1 if d > 0 else -1
    n = int(np.floor(abs(d) / C))                        # levels crossed
    levels = ref + p * C * np.arange(1, n + 1)
    times = t_a + (levels - L_a) / (L_b - L_a) * (t_b - t_a) if n else np.zeros(0)
    return times.astype(np.float64), np.full(n, p, dtype=np.int8), float(ref + p * n * C)


def _inputs_esim(rng):
    cases = []
    for L_a, L_b, ref in ((0.0, 0.55, 0.0),            # rise through 2 levels of 0.25
                          (0.1, -0.62, 0.08),          # fall through 3 levels
                          (0.3, 0.35, 0.2),            # small change: no event
                          (-1.0, -1.0, -1.1)):         # no change at all
        cases.append(dict(L_a=L_a, L_b=L_b, t_a=0.5, t_b=0.52, ref=ref, C=0.25))
    # the boundary rule "a level that L reaches fires": L_b lands exactly on ref + 2C (and on ref - C),
    # so counting only levels strictly passed (a strict `<`, or ceil - 1) fails here
    cases.append(dict(L_a=0.1, L_b=0.5, t_a=0.0, t_b=0.01, ref=0.0, C=0.25))
    cases.append(dict(L_a=0.0, L_b=-0.25, t_a=0.0, t_b=0.01, ref=0.0, C=0.25))
    for _ in range(3):                                 # random slopes, several crossings
        ref = rng.normal()
        L_a = ref + rng.uniform(-0.19, 0.19)
        cases.append(dict(L_a=L_a, L_b=L_a + rng.normal(0, 0.8), t_a=1.0, t_b=1.0 + rng.uniform(0.001, 0.02),
                          ref=ref, C=0.2))
    return cases


def _esim_at_sample_times(L_a, L_b, t_a, t_b, ref, C):
    times, p, new_ref = esim_interval(L_a, L_b, t_a, t_b, ref, C)
    return np.full(times.size, float(t_b)), p, new_ref


def _esim_ref_to_L(L_a, L_b, t_a, t_b, ref, C):
    times, p, _ = esim_interval(L_a, L_b, t_a, t_b, ref, C)
    return times, p, float(L_b) if times.size else float(ref)


def _esim_strict(L_a, L_b, t_a, t_b, ref, C):
    """A wrong version (for the hint): a level that L_b lands on exactly does not fire."""
    n = max(int(np.ceil(abs(L_b - ref) / C)) - 1, 0)
    p = 1 if L_b > ref else -1
    levels = ref + p * C * np.arange(1, n + 1)
    times = t_a + (levels - L_a) / (L_b - L_a) * (t_b - t_a) if n else np.zeros(0)
    return times.astype(np.float64), np.full(n, p, dtype=np.int8), float(ref + p * n * C)


def _esim_from_sample(L_a, L_b, t_a, t_b, ref, C):
    return esim_interval(L_a, L_b, t_a, t_b, L_a, C)


def _esim_off_polarity_zero(L_a, L_b, t_a, t_b, ref, C):
    times, p, new_ref = esim_interval(L_a, L_b, t_a, t_b, ref, C)
    return times, np.maximum(p, 0).astype(np.int8), new_ref


def _esim_levels_sorted(L_a, L_b, t_a, t_b, ref, C):
    times, p, new_ref = esim_interval(L_a, L_b, t_a, t_b, ref, C)
    return times[::-1] if len(p) and p[0] < 0 else times, p, new_ref


def _esim_line_from_ref(L_a, L_b, t_a, t_b, ref, C):
    d = L_b - ref
    p = 1 if d > 0 else -1
    n = int(np.floor(abs(d) / C))
    levels = ref + p * C * np.arange(1, n + 1)
    times = t_a + (levels - ref) / (L_b - ref) * (t_b - t_a) if n else np.zeros(0)
    return times.astype(np.float64), np.full(n, p, dtype=np.int8), float(ref + p * n * C)


def _esim_counted(L_a, L_b, t_a, t_b, ref, C, whole):
    d = L_b - ref
    p = 1 if d > 0 else -1
    n = int(whole(abs(d) / C))
    levels = ref + p * C * np.arange(1, n + 1)
    times = t_a + (levels - L_a) / (L_b - L_a) * (t_b - t_a) if n else np.zeros(0)
    return np.asarray(times, np.float64), np.full(n, p, dtype=np.int8), float(ref + p * n * C)


def _esim_rounded(L_a, L_b, t_a, t_b, ref, C):
    return _esim_counted(L_a, L_b, t_a, t_b, ref, C, np.round)


def _esim_ceil(L_a, L_b, t_a, t_b, ref, C):
    return _esim_counted(L_a, L_b, t_a, t_b, ref, C, np.ceil)


def _esim_half_levels(L_a, L_b, t_a, t_b, ref, C):
    """A wrong version (for the hint): the events timed at the half-way levels ref + (k - 1/2) C."""
    times, p, new_ref = esim_interval(L_a, L_b, t_a, t_b, ref, C)
    if not len(p):
        return times, p, new_ref
    levels = ref + p[0] * C * (np.arange(1, len(p) + 1) - 0.5)
    return t_a + (levels - L_a) / (L_b - L_a) * (t_b - t_a), p, new_ref


def _esim_ref_always_up(L_a, L_b, t_a, t_b, ref, C):
    times, p, _ = esim_interval(L_a, L_b, t_a, t_b, ref, C)
    return times, p, float(ref + len(p) * C)


def _esim_interp_unsorted(L_a, L_b, t_a, t_b, ref, C):
    """A wrong version (for the hint): np.interp(levels, [L_a, L_b], [t_a, t_b]), whose x-points must increase."""
    times, p, new_ref = esim_interval(L_a, L_b, t_a, t_b, ref, C)
    levels = ref + (p[0] if len(p) else 1) * C * np.arange(1, len(p) + 1)
    return np.interp(levels, [L_a, L_b], [t_a, t_b]).astype(np.float64), p, new_ref


exercises.register(
    "esim_interval", esim_interval, _inputs_esim,
    hints={
        "the timestamps should be interpolated inside the interval, not put at the sample time t_b":
            _esim_at_sample_times,
        "move the reference by n * C (to the last level crossed), not to L_b: the remainder L_b - level "
        "counts towards the next event":
            _esim_ref_to_L,
        "measure the change from the reference level `ref`, not from the previous sample L_a":
            _esim_from_sample,
        "a level that L reaches exactly fires too: the number of levels crossed is floor(|L_b - ref| / C), "
        "so L_b == ref + 2C gives 2 events":
            _esim_strict,
        "an OFF event has polarity -1, not 0: polarities are +1 (ON) and -1 (OFF)":
            _esim_off_polarity_zero,
        "return the events in time order: on the way down the levels are ref - C, ref - 2C, ... (sorting them "
        "ascending reverses the OFF events)":
            _esim_levels_sorted,
        "the straight line runs from (t_a, L_a) to (t_b, L_b): t = t_a + (level - L_a) / (L_b - L_a) (t_b - "
        "t_a), measured from L_a, not from ref":
            _esim_line_from_ref,
        "a level counts only once L reaches it: n = floor(|L_b - ref| / C), not round (a level half-way there "
        "has not fired yet)":
            _esim_rounded,
        "a level counts only once L reaches it: n = floor(|L_b - ref| / C), not ceil (which counts the level "
        "L_b is still short of)":
            _esim_ceil,
        "move the reference in the direction of the events: ref + p * n * C (down for OFF events), not ref + n * C":
            _esim_ref_always_up,
        "an event fires when L reaches the level ref + k C itself (k = 1, 2, ...), not half-way between two levels: "
        "levels = ref + p * C * np.arange(1, n + 1)":
            _esim_half_levels,
        "np.interp needs increasing x-points: on a fall (L_b < L_a) np.interp(levels, [L_a, L_b], [t_a, t_b]) "
        "returns an end point silently; use the line t_a + (level - L_a) / (L_b - L_a) (t_b - t_a), or give "
        "np.interp the points in increasing order":
            _esim_interp_unsorted,
    })


# ---- exercise 3: event frames over bins (Eq. 2) --------------------------------------------

def events_to_frames_fixed(events: Events, boundaries, C):
    """Event frames: ``frames[i, y, x] = C * sum of p`` over the events at (x, y) with
    ``b_i < t <= b_{i+1}`` (bin 0 also takes an event at exactly b_0; events outside
    [b_0, b_B] are dropped).

    Args:
        events: an :class:`Events` (t sorted, x column, y row, p +-1, sensor_size (H, W)).
        boundaries: float [B + 1] increasing bin edges (s).
        C: contrast threshold.

    Returns:
        float32 [B, H, W].
    """
    b = np.asarray(boundaries, dtype=np.float64)
    H, W = events.sensor_size
    B = b.size - 1
    i = np.searchsorted(b, events.t, side="left") - 1   # b[i] < t <= b[i+1]
    i[events.t == b[0]] = 0                              # bin 0 is closed on the left
    keep = (i >= 0) & (i < B)
    frames = np.zeros((B, H, W), dtype=np.float64)
    np.add.at(frames, (i[keep], events.y[keep], events.x[keep]), events.p[keep])
    return (C * frames).astype(np.float32)


def _random_events(rng, n, sensor_size, t0=0.0, t1=1.0) -> Events:
    H, W = sensor_size
    t = np.sort(rng.uniform(t0, t1, n))
    return Events(t, rng.integers(0, W, n), rng.integers(0, H, n), rng.choice(np.array([-1, 1]), n), (H, W))


def _inputs_frames(rng):
    cases = []
    ev = _random_events(rng, 40, (4, 4))
    # and a hot pixel (x 3, y 0) that fires 130 ON events in the second bin: more than int8, the polarities' dtype,
    # holds, so frames summed in it wrap round
    t = np.concatenate([ev.t, np.linspace(0.3, 0.45, 130)])
    order = np.argsort(t, kind="stable")
    x, y = np.concatenate([ev.x, np.full(130, 3)]), np.concatenate([ev.y, np.zeros(130, int)])
    ev = Events(t[order], x[order], y[order], np.concatenate([ev.p, np.ones(130, int)])[order], (4, 4))
    cases.append(dict(events=ev, boundaries=np.array([0.0, 0.25, 0.5, 0.75, 1.0]), C=0.2))
    # events exactly on the edges, at the first edge and outside the range
    t = np.array([0.0, 0.1, 0.25, 0.25, 0.3, 0.5, 0.6, 0.9])
    ev = Events(t, np.array([0, 1, 1, 2, 0, 2, 1, 0]), np.array([0, 0, 1, 1, 1, 0, 0, 1]),
                np.array([1, -1, 1, 1, -1, 1, 1, -1]), (2, 3))
    cases.append(dict(events=ev, boundaries=np.array([0.0, 0.25, 0.5]), C=0.5))
    ev = _random_events(rng, 300, (5, 7))
    # on a 6 x 8 sensor whose last row and last column never fire: frames sized from the events (y.max() + 1,
    # x.max() + 1) come out too small
    ev = Events(ev.t, ev.x, ev.y, ev.p, (6, 8))
    # bins that start at b_0 = 0.125, not at 0, with one event exactly there: bin 0 takes it (`t == b_0`, not
    # `t == 0`). 0.125 is exact in float32 too, so times and edges held in float32 still meet on it
    t = ev.t.copy()
    t[np.searchsorted(t, 0.125) - 1] = 0.125
    ev = Events(t, ev.x, ev.y, ev.p, ev.sensor_size)
    cases.append(dict(events=ev, boundaries=np.array([0.125, 0.2, 0.45, 0.5, 0.8, 0.95]), C=0.15))
    return cases


def _frames_of_bins(events, n_bins: int, i, C):
    """The wrong versions' last step: C x the polarities summed into bins ``i`` [N] (those outside 0..n_bins-1
    dropped), float32 [n_bins, H, W]."""
    H, W = events.sensor_size
    keep = (i >= 0) & (i < n_bins)
    frames = np.zeros((n_bins, H, W))
    np.add.at(frames, (i[keep], events.y[keep], events.x[keep]), events.p[keep])
    return (C * frames).astype(np.float32)


def _frames_right(events, boundaries, C):
    b = np.asarray(boundaries, dtype=np.float64)
    return _frames_of_bins(events, b.size - 1, np.searchsorted(b, events.t, side="right") - 1, C)


def _frames_fancy_index(events, boundaries, C):
    """A wrong version (for the hint): ``frames[i, y, x] += p`` adds a repeated (bin, y, x) only once."""
    b = np.asarray(boundaries, dtype=np.float64)
    H, W = events.sensor_size
    i = np.searchsorted(b, events.t, side="left") - 1
    i[events.t == b[0]] = 0
    keep = (i >= 0) & (i < b.size - 1)
    frames = np.zeros((b.size - 1, H, W))
    frames[i[keep], events.y[keep], events.x[keep]] += events.p[keep]
    return (C * frames).astype(np.float32)


def _frames_abs(events, boundaries, C):
    ones = Events(events.t, events.x, events.y, np.ones(len(events), np.int8), events.sensor_size)
    return events_to_frames_fixed(ones, boundaries, C)


def _frames_xy_swapped(events, boundaries, C):
    """Frames indexed [bin, x, y]: the transposed frames (on a sensor that is not square, an IndexError or this)."""
    return events_to_frames_fixed(events, boundaries, C).transpose(0, 2, 1)


def _frames_first_edge_at_zero(events, boundaries, C):
    """A wrong version (for the hint): bin 0's closed left edge written as `t == 0`, right only when b_0 = 0."""
    b = np.asarray(boundaries, dtype=np.float64)
    i = np.searchsorted(b, events.t, side="left") - 1
    i[events.t == 0] = 0
    return _frames_of_bins(events, b.size - 1, i, C)


def _frames_clipped(events, boundaries, C):
    """A wrong version (for the hint): events outside [b_0, b_B] clipped into the first or last bin."""
    b = np.asarray(boundaries, dtype=np.float64)
    return _frames_of_bins(events, b.size - 1, np.clip(np.searchsorted(b, events.t, side="left") - 1, 0, b.size - 2), C)


def _frames_no_first_edge(events, boundaries, C):
    b = np.asarray(boundaries, dtype=np.float64)
    return events_to_frames_fixed(events.take(events.t != b[0]), b, C)


def _frames_histogramdd(events, boundaries, C):
    """np.histogramdd: bins [b_i, b_{i+1}), only the last closed."""
    H, W = events.sensor_size
    counts, _ = np.histogramdd((events.t, events.y, events.x), weights=events.p,
                               bins=(np.asarray(boundaries, np.float64), np.arange(H + 1), np.arange(W + 1)))
    return (C * counts).astype(np.float32)


def _frames_mean_polarity(events, boundaries, C):
    """A wrong version (for the hint): each (bin, pixel) holds C times the mean polarity of its events."""
    ones = Events(events.t, events.x, events.y, np.ones(len(events), np.int8), events.sensor_size)
    n = events_to_frames_fixed(ones, boundaries, 1.0)
    return (events_to_frames_fixed(events, boundaries, C) / np.maximum(n, 1)).astype(np.float32)


def _frames_normalised_per_frame(events, boundaries, C):
    """A wrong version (for the hint): every frame divided by its largest |value| (a display step)."""
    f = events_to_frames_fixed(events, boundaries, C)
    m = np.abs(f).max(axis=(1, 2), keepdims=True)
    return (f / np.where(m > 0, m, 1)).astype(np.float32)


def _frames_last_edge_open(events, boundaries, C):
    """The last bin open at its end: an event exactly at b_B dropped."""
    keep = events.t < np.asarray(boundaries, dtype=np.float64)[-1]
    return events_to_frames_fixed(Events(events.t[keep], events.x[keep], events.y[keep], events.p[keep],
                                         events.sensor_size), boundaries, C)


def _frames_int8_sums(events: Events, boundaries, C):
    """A wrong version (for the hint): the polarities summed per bin and pixel in their own int8."""
    b = np.asarray(boundaries, dtype=np.float64)
    H, W = events.sensor_size
    i = np.searchsorted(b, events.t, side="left") - 1
    i[events.t == b[0]] = 0
    keep = (i >= 0) & (i < b.size - 1)
    sums = np.zeros((b.size - 1, H, W), np.int8)
    np.add.at(sums, (i[keep], events.y[keep], events.x[keep]), events.p[keep].astype(np.int8))
    return (C * sums).astype(np.float32)


exercises.register(
    "events_to_frames_fixed", events_to_frames_fixed, _inputs_frames,
    hints={
        "a hot pixel fires hundreds of times in one bin: polarities summed in their own int8 (np.zeros(..., "
        "dtype=p.dtype)) wrap past 127; sum them in float64 (or int64)":
            _frames_int8_sums,
        "an event exactly on an edge b_{i+1} belongs to bin i, (b_i, b_{i+1}]: use "
        "np.searchsorted(boundaries, t, side='left') - 1":
            _frames_right,
        "`frames[bin, y, x] += p` adds a repeated (bin, y, x) only once (numpy buffers fancy-index "
        "assignments): accumulate with np.add.at(frames, (bin, y, x), p) or np.bincount on a flat index":
            _frames_fancy_index,
        "did you forget the sign of the polarity? ON events add C, OFF events subtract C":
            _frames_abs,
        "did you forget to multiply by the contrast threshold C?":
            lambda events, boundaries, C: events_to_frames_fixed(events, boundaries, 1.0),
        "an event at exactly t = b_0 belongs to bin 0 (the first bin is closed on the left)":
            _frames_no_first_edge,
        "images are indexed [y, x] (row, column)":
            _frames_xy_swapped,
        "bin 0 takes the events at exactly b_0 = boundaries[0], which need not be 0: test `t == boundaries[0]`, "
        "not `t == 0`":
            _frames_first_edge_at_zero,
        "events before b_0 or after b_B belong to no bin: drop them (keep 0 <= bin < B), do not clip them "
        "into the first or last bin":
            _frames_clipped,
        "np.histogramdd's (and np.histogram's) bins are [b_i, b_{i+1}), only the last closed: an event "
        "exactly on an inner edge belongs to the bin that ends there, (b_i, b_{i+1}]":
            _frames_histogramdd,
        "sum the polarities, do not average them: divide by nothing (a bin's value is C times the net count, "
        "not the mean polarity of its events)":
            _frames_mean_polarity,
        "multiply by C once: C * sum(p), not C * C * sum(p)":
            lambda events, boundaries, C: C * events_to_frames_fixed(events, boundaries, C),
        "do not normalise the frames (each by its largest value): a frame holds C times the net count, in log "
        "units, the same scale in every bin (scaling is for display only)":
            _frames_normalised_per_frame,
        "an event exactly at the last edge b_B belongs to the last bin (b_{B-1}, b_B]: keep it (only the events "
        "after b_B are dropped, no strict t < b_B)": _frames_last_edge_open,
    })


# ---- exercise 2: the ON/OFF balance from the intervals between events --------------------

MIN_INTERVAL = 1e-6   # s: intervals are floored here (the timestamp resolution), as evinr_lite.method.balance does


def interval_imbalance(events: Events) -> float:
    """The imbalance b = (C+ - C-) / (C+ + C-) read from the intervals between events of one polarity.

    At every pixel, an interval counts between two *consecutive* events of that pixel with the same
    polarity (an ON run: C+ / |dL/dt|; an OFF run: C- / |dL/dt|). Pooled over all pixels,
    r = mean log ON interval - mean log OFF interval estimates log(C+ / C-), and b = tanh(r / 2).

    Args:
        events: an :class:`Events` (t sorted, seconds; x column, y row; p +-1).

    Returns:
        b (float); NaN when the events hold no ON pair or no OFF pair.
    """
    H, W = events.sensor_size
    pix = events.y.astype(np.int64) * W + events.x
    order = np.argsort(pix, kind="stable")              # by pixel, time order kept within a pixel
    pix, t, p = pix[order], np.asarray(events.t, np.float64)[order], events.p[order]
    pair = (pix[1:] == pix[:-1]) & (p[1:] == p[:-1])   # consecutive at one pixel, same polarity
    log_dt = np.log(np.maximum(np.diff(t), MIN_INTERVAL))
    on = p[1:] > 0
    if not (pair & on).any() or not (pair & ~on).any():
        return float("nan")
    r = log_dt[pair & on].mean() - log_dt[pair & ~on].mean()
    return float(np.tanh(r / 2))


def _inputs_intervals(rng):
    from ..sim.scenes import OscillatingScene
    from ..sim.simulate import simulate_scene

    cases = []
    for b in (0.2, -0.15):                             # a small picture moving to and fro, C+ != C-
        scene = OscillatingScene("camera", (8, 10), 1.0, path=((3.0, 2.0, 3.0, 0.0), (1.0, 1.5, 2.0, 1.0)))
        cases.append(dict(events=simulate_scene(scene, C=0.2, C_pos=0.2 * (1 + b), C_neg=0.2 * (1 - b), seed=0)))
    # two OFF events at one pixel with the same timestamp (a sensor's burst): the floor at MIN_INTERVAL
    t = np.array([0.0, 0.1, 0.2, 0.2, 0.3, 0.35])
    cases.append(dict(events=Events(t, np.zeros(6, np.int64), np.zeros(6, np.int64),
                                    np.array([1, 1, -1, -1, -1, 1]), (1, 1))))
    # two pixels by hand: (0, 0) ON at 0, 0.1, 0.3, OFF at 0.4, 0.45, ON at 0.9; (0, 1) OFF at 0.05, 0.25;
    # interleaved in time, so pairs must be taken per pixel
    t = np.array([0.0, 0.05, 0.1, 0.25, 0.3, 0.4, 0.45, 0.9])
    cases.append(dict(events=Events(t, np.array([0, 1, 0, 1, 0, 0, 0, 0]), np.zeros(8, np.int64),
                                    np.array([1, -1, 1, -1, 1, -1, -1, 1]), (1, 2))))
    # a sensor taller than wide (H = 4 > W = 3): the pixel number x * W + y gives two pixels one number here (x = 0,
    # y = 3 and x = 1, y = 0), as y * H + x does on the wide sensors above; x * H + y and y * W + x are both one-to-one
    cases.append(dict(events=_random_events(rng, 400, (4, 3))))
    # ON runs only, and OFF events that never follow one another: no OFF pair, so no estimate (NaN)
    cases.append(dict(events=Events(np.array([0.0, 0.1, 0.2, 0.3, 0.5]), np.zeros(5, np.int64),
                                    np.zeros(5, np.int64), np.array([1, 1, -1, 1, 1]), (1, 1))))
    return cases


def _b_from(log_dt, pair, on):
    """The wrong versions' last step, as :func:`interval_imbalance` takes it: tanh of half the mean log ON interval
    minus the mean log OFF one over the pairs ``pair`` (``on``: the pair's polarity is ON); NaN without both."""
    if not (pair & on).any() or not (pair & ~on).any():
        return float("nan")
    return float(np.tanh((log_dt[pair & on].mean() - log_dt[pair & ~on].mean()) / 2))


def _intervals_unsorted(events):
    """A wrong version (for the hint): consecutive events of the whole stream, not of one pixel."""
    t, p = np.asarray(events.t, np.float64), events.p
    pair = p[1:] == p[:-1]
    log_dt = np.log(np.maximum(np.diff(t), MIN_INTERVAL))
    return _b_from(log_dt, pair, p[1:] > 0)


def _by_pixel(events):
    """(pix, t, p, pair) for the wrong versions below: the events sorted by pixel (time order kept within one),
    and pair [N - 1], True where two consecutive events share a pixel and a polarity."""
    H, W = events.sensor_size
    pix = events.y.astype(np.int64) * W + events.x
    order = np.argsort(pix, kind="stable")
    pix, t, p = pix[order], np.asarray(events.t, np.float64)[order], events.p[order]
    return pix, t, p, (pix[1:] == pix[:-1]) & (p[1:] == p[:-1])


def _intervals_no_floor(events):
    """A wrong version (for the hint): log(0) for two events with the same timestamp."""
    pix, t, p, pair = _by_pixel(events)
    with np.errstate(divide="ignore", invalid="ignore"):
        log_dt = np.log(np.diff(t))
        on = p[1:] > 0
        return float(np.tanh((log_dt[pair & on].mean() - log_dt[pair & ~on].mean()) / 2))


def _intervals_per_polarity(events):
    """A wrong version (for the hint): each polarity's events of a pixel differenced on their own, so a
    gap across a run of the other polarity counts as an interval."""
    H, W = events.sensor_size
    means = []
    for sel in (events.p > 0, events.p < 0):
        pix = events.y[sel].astype(np.int64) * W + events.x[sel]
        order = np.argsort(pix, kind="stable")
        pix, t = pix[order], np.asarray(events.t, np.float64)[sel][order]
        same = pix[1:] == pix[:-1]
        means.append(np.log(np.maximum(np.diff(t), MIN_INTERVAL))[same].mean())
    return float(np.tanh((means[0] - means[1]) / 2))


def _intervals_of_means(events):
    """A wrong version (for the hint): the log of the ratio of the mean intervals."""
    pix, t, p, pair = _by_pixel(events)
    dt = np.maximum(np.diff(t), MIN_INTERVAL)
    on = p[1:] > 0
    return float(np.tanh(np.log(dt[pair & on].mean() / dt[pair & ~on].mean()) / 2))


def _intervals_pixel_index_h(events):
    """A wrong version (for the hint): the pixel number y * H + x, which gives two pixels one number
    when H != W (y = 1, x = 0 and y = 0, x = H)."""
    H, W = events.sensor_size
    pix = events.y.astype(np.int64) * H + events.x
    return _imbalance_of_pixel_numbers(events, pix, "stable")


def _intervals_pixel_index_x_w(events):
    """A wrong version (for the hint): the pixel number x * W + y, which gives two pixels one number when H > W
    (x = 0, y = W and x = 1, y = 0)."""
    H, W = events.sensor_size
    return _imbalance_of_pixel_numbers(events, events.x.astype(np.int64) * W + events.y, "stable")


def _intervals_unstable_sort(events):
    """A wrong version (for the hint): np.argsort's default sort, which need not keep each pixel's events in
    time order (some intervals become negative and are floored, others are paired out of order)."""
    H, W = events.sensor_size
    return _imbalance_of_pixel_numbers(events, events.y.astype(np.int64) * W + events.x, "quicksort")


def _imbalance_of_pixel_numbers(events, pix, kind):
    order = np.argsort(pix, kind=kind)
    pix, t, p = pix[order], np.asarray(events.t, np.float64)[order], events.p[order]
    pair = (pix[1:] == pix[:-1]) & (p[1:] == p[:-1])
    log_dt = np.log(np.maximum(np.diff(t), MIN_INTERVAL))
    return _b_from(log_dt, pair, p[1:] > 0)


def _intervals_stat(events, log=np.log, stat=np.mean, to_b=lambda r: np.tanh(r / 2), none=float("nan")):
    pix, t, p, pair = _by_pixel(events)
    log_dt = log(np.maximum(np.diff(t), MIN_INTERVAL))
    on = p[1:] > 0
    if not (pair & on).any() or not (pair & ~on).any():
        return none
    return float(to_b(stat(log_dt[pair & on]) - stat(log_dt[pair & ~on])))


def _intervals_log10(events):
    return _intervals_stat(events, log=np.log10)


def _intervals_tanh_r(events):
    return _intervals_stat(events, to_b=np.tanh)


def _intervals_median(events):
    return _intervals_stat(events, stat=np.median)


def _intervals_zero_not_nan(events):
    return _intervals_stat(events, none=0.0)


def _intervals_per_pixel_means(events):
    """A wrong version (for the hint): each pixel's mean log interval first, then the mean over pixels."""
    pix, t, p, pair = _by_pixel(events)
    log_dt = np.log(np.maximum(np.diff(t), MIN_INTERVAL))
    on, px = p[1:] > 0, pix[1:]
    means = []
    for sel in (pair & on, pair & ~on):
        if not sel.any():
            return float("nan")
        means.append(np.mean([log_dt[sel & (px == k)].mean() for k in np.unique(px[sel])]))
    return float(np.tanh((means[0] - means[1]) / 2))


def _intervals_floor_added(events):
    """A wrong version (for the hint): MIN_INTERVAL added to every interval instead of a floor."""
    pix, t, p, pair = _by_pixel(events)
    log_dt = np.log(np.diff(t) + MIN_INTERVAL)
    return _b_from(log_dt, pair, p[1:] > 0)


def _intervals_floor_in_ms(events):
    """A wrong version (for the hint): the floor at a millisecond, 1e-3 s."""
    pix, t, p, pair = _by_pixel(events)
    log_dt = np.log(np.maximum(np.diff(t), 1e-3))
    return _b_from(log_dt, pair, p[1:] > 0)


def _intervals_across_pixels(events):
    """A wrong version (for the hint): sorted by pixel, but a pair only needs the same polarity (the last event of
    one pixel pairs with the first of the next)."""
    pix, t, p, _ = _by_pixel(events)
    pair = p[1:] == p[:-1]
    with np.errstate(divide="ignore", invalid="ignore"):
        log_dt = np.log(np.maximum(np.diff(t), MIN_INTERVAL))
    return _b_from(log_dt, pair, p[1:] > 0)


def _intervals_lexsort_by_time(events):
    """A wrong version (for the hint): np.lexsort((pix, t)), which sorts by its last key, the time."""
    H, W = events.sensor_size
    pix = events.y.astype(np.int64) * W + events.x
    order = np.lexsort((pix, np.asarray(events.t, np.float64)))
    pix, t, p = pix[order], np.asarray(events.t, np.float64)[order], events.p[order]
    pair = (pix[1:] == pix[:-1]) & (p[1:] == p[:-1])
    log_dt = np.log(np.maximum(np.diff(t), MIN_INTERVAL))
    return _b_from(log_dt, pair, p[1:] > 0)


def _intervals_log_ratio(events):
    """A wrong version (for the hint): r itself, log(C+ / C-), instead of b."""
    return float(2 * np.arctanh(interval_imbalance(events)))


def _imbalance_pixels_sorted_alone(events: Events) -> float:
    """A wrong version (for the hint): np.sort of the pixel numbers, the times and polarities left in time order."""
    H, W = events.sensor_size
    pix = np.sort(events.y.astype(np.int64) * W + events.x)
    t, p = np.asarray(events.t, np.float64), events.p
    pair = (pix[1:] == pix[:-1]) & (p[1:] == p[:-1])
    log_dt = np.log(np.maximum(np.diff(t), MIN_INTERVAL))
    on = p[1:] > 0
    if not (pair & on).any() or not (pair & ~on).any():
        return float("nan")
    return float(np.tanh((log_dt[pair & on].mean() - log_dt[pair & ~on].mean()) / 2))


exercises.register(
    "interval_imbalance", interval_imbalance, _inputs_intervals, rtol=1e-6, atol=1e-9,
    hints={
        "np.sort(pix) sorts the pixel numbers alone: the times and polarities stay in time order, so the pairs "
        "mix pixels; sort all three by one order (order = np.argsort(pix, kind=\"stable\"), then pix[order], "
        "t[order], p[order])":
            _imbalance_pixels_sorted_alone,
        "take the pairs per pixel: sort the events by pixel first (a stable sort keeps their time order), "
        "then pair each event with the one before it at the same pixel":
            _intervals_unsorted,
        "an interval counts only between two consecutive events of the pixel with the same polarity: "
        "differencing the ON events alone also counts the gaps across OFF runs":
            _intervals_per_polarity,
        "average the log intervals, then subtract: the log of the ratio of mean intervals weighs the long "
        "ones most":
            _intervals_of_means,
        "return b = tanh(r / 2) = (C+ - C-) / (C+ + C-), not r = log(C+ / C-)":
            _intervals_log_ratio,
        "ON minus OFF: longer ON intervals mean a larger C+, so b > 0":
            lambda events: -interval_imbalance(events),
        "floor each interval at MIN_INTERVAL (1 us) before its log: two events with the same timestamp "
        "give log(0) = -inf":
            _intervals_no_floor,
        "number the pixels y * W + x, W = sensor_size[1] (the row length): y * H + x gives two pixels one "
        "number when the sensor is not square":
            _intervals_pixel_index_h,
        "number the pixels y * W + x (the row times the row length W, plus the column): x * W + y gives two pixels "
        "one number when the sensor is taller than wide (x * H + y, column by column, would do too)":
            _intervals_pixel_index_x_w,
        "sort with np.argsort(pix, kind=\"stable\"): the default sort need not keep each pixel's events in "
        "time order, so consecutive events of a pixel are paired out of order":
            _intervals_unstable_sort,
        "log intervals are natural logs (np.log): with np.log10 r is log10(C+ / C-), 2.3 times too small":
            _intervals_log10,
        "b = tanh(r / 2), with the half: (C+ - C-) / (C+ + C-) = tanh(log(C+ / C-) / 2)":
            _intervals_tanh_r,
        "average the log intervals with the mean, not the median (the mean of the logs is the log of the "
        "geometric mean, which estimates log C+ - log C-)":
            _intervals_median,
        "with no ON pair or no OFF pair there is nothing to compare: return NaN (float('nan')), not 0 (0 would "
        "claim a balanced sensor)":
            _intervals_zero_not_nan,
        "pool the intervals of all pixels: one mean over every ON pair and one over every OFF pair, not a mean of "
        "per-pixel means (a pixel with one pair would weigh as much as one with a hundred)":
            _intervals_per_pixel_means,
        "floor each interval at MIN_INTERVAL, np.maximum(dt, MIN_INTERVAL): adding it (dt + MIN_INTERVAL) lengthens "
        "every interval, not only the zero ones":
            _intervals_floor_added,
        "MIN_INTERVAL is 1e-6 s (a microsecond, the timestamps' resolution): a floor at 1e-3 s (a millisecond) "
        "lifts every interval shorter than that":
            _intervals_floor_in_ms,
        "a pair is two consecutive events of one pixel with the same polarity: after sorting by pixel, the last "
        "event of one pixel and the first of the next are no pair (test pix[1:] == pix[:-1] too)":
            _intervals_across_pixels,
        "np.lexsort sorts by its last key first: np.lexsort((pix, t)) sorts by time (pixel only among equal times); "
        "to sort by pixel with time order kept use np.lexsort((t, pix)) or np.argsort(pix, kind='stable')":
            _intervals_lexsort_by_time,
    })


# ---- helpers --------------------------------------------------------------------------------

def pixel_trace(events: Events, x: int, y: int) -> tuple[np.ndarray, np.ndarray]:
    """(t float64 [n], p int8 [n]) of the events of the pixel at column ``x``, row ``y``."""
    require(events, Events, "events")
    H, W = events.sensor_size
    x = whole_number(x, "x", lo=0, hi=W - 1)   # outside the sensor matched no event, silently
    y = whole_number(y, "y", lo=0, hi=H - 1)
    keep = (events.x == x) & (events.y == y)
    return events.t[keep], events.p[keep]


def busiest_pixel(events: Events) -> tuple[int, int]:
    """(x, y) of the pixel with the most events (the first in row-major order on a tie)."""
    require(events, Events, "events")
    if len(events) == 0:   # was (0, 0), a pixel that never fired
        raise EventDataError("events hold no event, so no pixel is the busiest; pass events that hold some")
    H, W = events.sensor_size
    counts = np.bincount(events.y.astype(np.int64) * W + events.x, minlength=H * W)
    y, x = divmod(int(np.argmax(counts)), W)
    return x, y
