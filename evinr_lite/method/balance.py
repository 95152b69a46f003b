"""The ON/OFF balance from the events alone: C+ and C- when only a nominal C is known.

Real sensors fire ON and OFF events at different thresholds (C+ != C-), while users usually know one
nominal C. Integrated with one C, every event then carries a small error of the same sign for its
polarity, and a busy pixel's level drifts linearly with its event count: on a 20 s recording with
C+ 0.25 and C- 0.20 given as C = 0.225, the mean brightness error of the kit went from +0.45 to
-0.31 (issue 21). Events cannot tell that drift from a real change of light, so it is removed by
assumptions. Two are stated here, each giving an estimate of the imbalance
``b = (C+ - C-) / (C+ + C-)`` (then ``C+ = C (1 + b)``, ``C- = C (1 - b)``, their mean kept at the
nominal C: the nominal C sets the contrast, the balance only the drift):

1. **Counts** (:func:`pooled_imbalance`): a pixel that watches a moving scene keeps returning to log
   intensities it had before: over a span its net change ``C+ n+ - C- n-`` is bounded while its
   event count grows. Pooled over pixels, ``b = sum(n- - n+) / sum(n- + n+)``. Its error is the
   change of the *mean* log brightness over the span divided by C times the mean event count: new
   content entering, a change of light (camera_translate: +0.20 for 0; dark_falling, light falling
   7x: +0.61 for 0).
2. **Intervals** (:func:`interval_imbalance`): within a run of ON events a pixel's log intensity
   rises by C+ from one event to the next, so the interval is ``C+ / |dL/dt|``; within a run of OFF
   events it is ``C- / |dL/dt|``. If the scene's rising and falling slopes have the same spread, the
   mean log ON interval minus the mean log OFF interval is ``r = log(C+ / C-)``, and
   ``b = tanh(r / 2)``. A change of the mean brightness does not enter (camera_translate: +0.02),
   but textures whose rising and falling edges differ do (chelsea_speed +0.21 for 0), and so does a
   change of light (dark_falling: the falling light adds slow falls on flat regions, so the OFF
   intervals grow: -0.43 for 0). Falling light biases the counts the other way (more OFF events).

3. **Edges** (:func:`gradient_imbalance`): a wrong b adds ``C (b_true - b) n`` to every pixel, an
   image of its event count, growing in the frames. Across an edge between two pixels the scene's own
   gradient changes with the texture passing but does not follow their count difference, so b is
   fitted as the value that leaves each edge's change over the span's 8 time slices least correlated
   with that difference. A change of light common to all pixels changes no gradient, and a change of
   the mean brightness does not enter (camera_240x180: pooled counts +0.17 for 0, edges +0.07). It
   errs where the events' own pattern grows with the light: a change of light on a sensor whose
   pixels' thresholds differ, or whose noise grows in the dark (dark_falling +0.43 for 0).

Their assumptions fail on different scenes, and a real imbalance moves all of them alike. So the
default rule (``rule="consensus"``) takes the **minmod** of the edges' estimate (the pooled counts
where no slice counts are given) and the intervals': the one nearer 0 when they agree in sign, 0 when
they do not. A change of light pushes the edges and the intervals apart (dark_falling +0.43 and
-0.43), as it did the pooled counts and the intervals. The edges took the pooled counts' place
because the pooled counts' error, the mean log change, is a one-signed error of a scene as a whole
and often larger (``python benchmarks/balance.py --fresh``; figures in docs/defaults.md).

The counts' and the intervals' errors scale differently: the counts' error is the mean log change over
the events per pixel, ``s = NET_CHANGE / (C mean n)``, which falls as events accumulate, while the
intervals' bias is a property of the scene (+0.05 to +0.2 on most natural scenes of the simulator with
C+ = C-; text_shake +0.11, brick_speed_noisy -0.24) that no length of recording removes. So where
``s <= COUNTS_ALONE`` (0.1, below the intervals' typical bias) the **counts are taken alone**, unless
the intervals differ from them by more than ``max_imbalance`` (a strong change of light pushes the two
apart: dark_falling +0.61 and -0.43). Alone, they are fitted with an intercept
(:func:`slope_imbalance`: ``n- - n+ = b n - dL / C`` at every pixel, so a change of light common to
all pixels goes to the intercept): on a long recording a change of light is bounded while the events
keep coming, and the pooled counts would read the light falling 7x over the 20 s pan as b = +0.10,
the slope as +0.008 (``python benchmarks/balance.py --light``). The slope has an error of its own, the
part of the scene's per-pixel change that goes with the event count: on a busy shake that stops
mid-swing (fresh24_07_shake_brick, 174 events per pixel) it read -0.009 for -0.064, while the pooled
counts, the edges and the intervals read -0.066, -0.065 and -0.075. Those three err for other reasons
(a change of light pushes the first two one way and the intervals the other), so where all three lie
on one side of the slope, the slope is **bounded by their range** (taken as the nearest of them);
where they bracket it, it stands. Without slice counts (no edges' estimate) the slope stands alone.

Where the counts are not taken alone and the edges and the intervals disagree in sign, the minmod gives
0. A change of light is what pushes those two apart, and the counts can tell whether the light changed:
the pooled counts read a change of light common to all pixels as an imbalance, the slope does not, and
their difference times ``C mean n`` is the span's mean log change. Where it is at most STEADY_LIGHT (0.1
log units) and the counts' error scale at most COUNTS_OVER_INTERVALS (0.5), no change of light explains
the disagreement: it is the intervals' own bias (+0.05 to +0.2 on natural scenes) that flips their sign
where b < 0, and the **smallest of the edges, the slope and the pooled counts** is taken where the three
agree in sign (``chosen == "agreement"``). fresh11_07_pan_gravel (b = -0.102): edges -0.107, slope
-0.094, pooled counts -0.095, intervals +0.105; b = 0 before, -0.094 now. On the 39 rows of the balance
benchmarks, fresh seeds 11-28 and the stress set that take it, the error of b falls from 0.089 to 0.020
rms (37 nearer the truth, 2 farther), and on the 34 of them the zoo runs can score, the level's drift
over the span (the last quarter's error less the first's) from 0.045 to 0.011 in the mean
(docs/defaults.md). ``BalanceFit.chosen`` says which was taken.

The edges' estimate took the pooled counts' place in the minmod on 2026-12-04: rms error of the applied
b 0.104 -> 0.092 on the off-heavy short scenes, 0.069 -> 0.063 on 44 fresh random sensors
(``python benchmarks/balance.py --fresh``), 0.019 -> 0.016 held out, the zoo's unchanged (docs/defaults.md
has the scores; the figures below are from before it, the pooled counts in the minmod).

Measured on the zoo's 15 scenes and the 10 held-out ones, long ones included (their simulated b is 0
on 16, 0.10-0.22 on 9), on the events the kit trains on: the estimate is within 0.05 of the truth on
24 and 0.10 short on unequal_onhot (+0.085 for +0.182); its root mean square error is 0.027 on the zoo
and 0.019 held out, against 0.087 and 0.100 for the counts rule (below), which was up to 0.19 off
where C+ != C- and applied +0.19 to dark_falling. ``python benchmarks/balance.py [--heldout]`` prints
both estimates per scene. Every one of those imbalances is positive. With C- > C+ (``--off-heavy``: the
22 short scenes with their pairs swapped, or b = -0.15, and the three long ones) the intervals'
positive bias cancels part of a negative b, and the minmod keeps the smaller value: the rms error on
the short ones is 0.104 (0.116 by the minmod alone, 0.146 by the counts rule). On the long ones the
counts alone give -0.113, -0.120 and -0.102 for -0.111, -0.116 and -0.100, where the minmod gave
-0.073, 0 and 0: a level drift of 0.25 over cat_slider_20s, and of 0.95 over long_ijrr_60s
(CLAHE-SSIM 0.294 against 0.696 now).

How the estimate is made robust (:func:`balance_from_counts`):

- hot pixels fire without a brightness change, often of one polarity (ON-only hot pixels climb
  without bound): pixels above :func:`~evinr_lite.method.denoise.hot_threshold` are left out, and so
  are pixels whose net level, balanced with the counts' estimate, lies beyond OUTLIER_LOG = 4 log
  units (a 55x change of intensity: no pixel of a natural scene goes there and comes back), which
  catches hot pixels that a busy texture hides from the count rule; both estimates use the pixels
  left;
- background activity fires ON and OFF with equal probability: it dilutes both estimates slightly
  towards 0 (less correction, never a wrong sign);
- ``max_imbalance`` caps the correction (0.3: C+ / C- within 0.54 and 1.86).

``rule="counts"`` (``EvINRConfig(balance="counts")``) is the rule before the intervals, kept to
compare with: the counts' estimate shrunk towards 0 as far as the span carries little evidence, with
an uncertainty ``s = NET_CHANGE / (C mean n)`` and a prior spread ``PRIOR`` of real sensors'
imbalance, by ``PRIOR^2 / (PRIOR^2 + s^2)`` (both spreads the zoo's root mean squares: 0.50 log
units and 0.084). On 2 s it kept a quarter or less of a real imbalance (noisy_gravel +0.026 for
+0.100); the consensus needs no shrinkage, since neither estimate's error grows as the span gets
shorter the way a drift does.

Everything works from per-pixel sums, so a streamed recording carries :class:`PolarityCounts` from
window to window (with each pixel's last event, so intervals across a chunk's edge count) and
estimates the balance from all the events seen so far. Where the solver applies it (with the hot
pixels, the background filter and lam): :mod:`evinr_lite.method.prepare`.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.checks import (checked_span, choice, decimal_as_float, is_real_number, pixel_mask, real_number, require,
                           whole_number)
from ..core.events import EventDataError, Events, check_sensor_size
from .binning import as_thresholds
from .denoise import check_count_pair, check_counts, hot_threshold

__all__ = ["BalanceFit", "PolarityCounts", "polarity_counts", "interval_sums", "interval_stride",
           "balance_from_counts", "estimate_balance", "pooled_imbalance", "slope_imbalance", "interval_imbalance", "minmod",
           "gradient_imbalance", "slice_counts", "span_slices", "BALANCE_MODES", "RULES", "HOT_PIXEL_MODES", "MIN_EVENTS",
           "MAX_IMBALANCE", "PRIOR", "NET_CHANGE", "COUNTS_ALONE", "STEADY_LIGHT", "COUNTS_OVER_INTERVALS",
           "SLICES"]

BALANCE_MODES = ("none", "events", "counts")   # EvINRConfig.balance: "events" is the consensus rule
RULES = ("consensus", "counts")
HOT_PIXEL_MODES = ("keep", "drop")
MIN_EVENTS = 1            # pixels with fewer events over the span are left out of the estimate
MAX_IMBALANCE = 0.3       # |b| is capped here: C+ / C- within (0.7 / 1.3, 1.3 / 0.7)
MIN_PIXELS = 50           # fewer usable pixels: no estimate, the nominal C is kept
PRIOR = 0.1               # prior spread of real sensors' imbalance b (C+ / C- about 1.2)
OUTLIER_LOG = 4.0         # log units: a pixel's balanced net level beyond this (55x in intensity) is left out
NET_CHANGE = 0.5          # log units: spread of the change of the mean log brightness over a span
COUNTS_ALONE = 0.1        # the counts' error scale NET_CHANGE / (C mean n) at or below which they are used alone
STEADY_LIGHT = 0.1        # log units: a span whose mean log change (C mean n |pooled - slope|) is at most this ...
COUNTS_OVER_INTERVALS = 0.5   # ... and whose counts' error scale is at most this: the counts overrule the intervals
MIN_INTERVAL = 1e-6       # s: intervals between events are floored here (the timestamp resolution)
LOG_GRID = 2.0 ** 16      # log intervals are rounded to 1 / LOG_GRID (exact sums in any order)
MAX_INTERVAL_PIXELS = 1 << 16   # pixels whose intervals are timed at most (interval_stride: a grid on larger sensors)
BAND_ROWS = 64            # rows of the sensor the edges' estimate holds at once (float64 [SLICES + 1, 65, W] arrays)
SLICES = 8                # time slices of the span whose counts the edges' estimate (gradient_imbalance) compares


@dataclass
class BalanceFit:
    """The ON/OFF balance of a span of events.

    Attributes:
        C: (c_pos, c_neg) log units per event, mean = the nominal C.
        imbalance: b applied, (C+ - C-) / (C+ + C-), capped: minmod(gradient_imbalance (or
            raw_imbalance without slice counts), interval_imbalance) or slope_imbalance (bounded by the
            range of raw, gradient and interval imbalance where the gradient's is finite) by the consensus
            rule, or minmod(gradient, slope, raw imbalance) where the minmod of the first two is 0 and the
            counts show a steady light (``chosen == "agreement"``); shrink x raw_imbalance by the counts rule.
        raw_imbalance: the counts' pooled b = sum(n- - n+) / sum(n- + n+) over the usable pixels.
        interval_imbalance: the intervals' b (NaN where not computed: the counts rule, no interval sums).
        shrink: the counts rule's weight for the raw value (0: nominal C kept, 1: raw value used).
        rule: the rule that gave ``imbalance`` ("consensus" or "counts").
        chosen: what the consensus took: "counts" (the counts alone, their error scale at most
            COUNTS_ALONE), "minmod" (the smaller estimate), "agreement" (the edges and the intervals
            disagree, the counts show no change of light: the smallest of the edges, the slope and the
            pooled counts) or "nominal" (b = 0: the estimates disagree in sign, or no estimate); the
            counts rule says "counts".
        counts_error: the counts' error scale ``s = NET_CHANGE / (C mean_events)`` (NaN: no estimate).
        slope_imbalance: the counts' estimate with an intercept (:func:`slope_imbalance`), the one
            taken alone, bounded by the other three (NaN where the counts do not vary).
        gradient_imbalance: the edges' estimate (:func:`gradient_imbalance`), the minmod's partner of
            the intervals (NaN without slice counts: the pooled counts stand in).
        mean_events: mean event count of the usable pixels. n_pixels: usable pixels.
        n_hot: pixels left out as hot (by count, or by a net level beyond OUTLIER_LOG). applied: False when no estimate was made (a C pair was
        given, or too few pixels fired); C is then the given one.
    """

    C: tuple
    imbalance: float
    raw_imbalance: float
    shrink: float
    mean_events: float
    n_pixels: int
    n_hot: int
    applied: bool
    interval_imbalance: float = float("nan")
    rule: str = "consensus"
    chosen: str = "nominal"
    counts_error: float = float("nan")
    slope_imbalance: float = float("nan")
    gradient_imbalance: float = float("nan")

    def summary(self) -> dict:
        return {"C": [float(c) for c in self.C], "imbalance": self.imbalance, "raw_imbalance": self.raw_imbalance,
                "interval_imbalance": self.interval_imbalance, "rule": self.rule, "chosen": self.chosen,
                "counts_error": self.counts_error, "slope_imbalance": self.slope_imbalance,
                "gradient_imbalance": self.gradient_imbalance,
                "shrink": self.shrink, "mean_events": self.mean_events, "n_pixels": self.n_pixels,
                "n_hot": self.n_hot, "applied": self.applied}


def polarity_counts(events: Events) -> tuple[np.ndarray, np.ndarray]:
    """(n_on, n_off): int64 [H, W] ON and OFF event counts per pixel."""
    require(events, Events, "polarity_counts: events")
    H, W = events.sensor_size
    flat = events.y.astype(np.int64) * W + events.x
    on = events.p > 0
    n_on = np.bincount(flat[on], minlength=H * W).reshape(H, W)
    n_off = np.bincount(flat[~on], minlength=H * W).reshape(H, W)
    return n_on, n_off


def slice_counts(events: Events, edges) -> tuple[np.ndarray, np.ndarray]:
    """(on, off): float32 [K, H, W] ON and OFF counts per pixel in each of the K time slices whose
    boundaries are ``edges`` (float64 [K + 1], s, increasing; an event at a boundary counts in the slice
    it opens); events before the first or after the last boundary count in the first or last slice.
    The events are time-ordered, so each slice is one run of them, counted on its own (the memory
    beyond the result is one [H, W] count)."""
    require(events, Events, "slice_counts: events")
    H, W = events.sensor_size
    edges = _slice_edges(edges, "slice_counts: edges")
    K = len(edges) - 1
    t = np.asarray(events.t, np.float64)
    cut = np.concatenate([[0], np.searchsorted(t, edges[1:-1], side="left"), [len(t)]])
    out = (np.zeros((K, H, W), np.float32), np.zeros((K, H, W), np.float32))
    for k in range(K):
        if cut[k + 1] > cut[k]:
            out[0][k], out[1][k] = polarity_counts(events.take(slice(int(cut[k]), int(cut[k + 1]))))
    return out


def _slice_edges(edges, name: str) -> np.ndarray:
    """Slice boundaries as float64 [K + 1]: at least two finite, increasing times (s)."""
    arr = None if isinstance(edges, (str, bytes)) or edges is None else np.asarray(edges)
    if arr is None or arr.dtype.kind not in "iuf" or arr.ndim != 1 or len(arr) < 2:
        raise EventDataError(f"{name} must be at least two increasing times in seconds (a slice's boundaries, as "
                             f"span_slices(t_start, t_end) gives), got {edges!r:.80}")
    arr = arr.astype(np.float64)
    if not (np.isfinite(arr).all() and np.all(np.diff(arr) > 0)):
        raise EventDataError(f"{name} must be finite, increasing times (s), got {arr!r:.80}")
    return arr


def interval_stride(sensor_size) -> int:
    """The stride s of the pixel grid whose intervals are timed: every pixel (s = 1) up to
    MAX_INTERVAL_PIXELS pixels, else every s-th row and column, the least s that keeps the grid within
    it (1280 x 720: s = 4, 57,600 pixels). The estimate pools their pairs; more pixels add time, not
    evidence, and a grid below 2^16 pixels sorts in one 16-bit radix pass."""
    H, W = check_sensor_size(sensor_size)
    s = 1
    while -(-H // s) * -(-W // s) > MAX_INTERVAL_PIXELS:
        s += 1
    return s


def _check_last(last, shape) -> tuple:
    """interval_sums' ``last``: (last_t, last_p), float64 [H, W] times (NaN: none) and polarities -1, 0 or +1."""
    want = (f"last must be (last_t, last_p), two [H, W] = {shape} arrays (each pixel's last time, NaN where none, and "
            "its polarity +1, -1 or 0), as interval_sums returned them for the span before; or None")
    if isinstance(last, (str, bytes)) or not hasattr(last, "__len__") or len(last) != 2:
        raise EventDataError(f"{want}; got {last!r:.80}")
    t, p = np.asarray(last[0]), np.asarray(last[1])
    if t.shape != tuple(shape) or p.shape != tuple(shape) or t.dtype.kind not in "iuf" or p.dtype.kind not in "iuf":
        raise EventDataError(f"{want}; got arrays of shapes {t.shape} and {p.shape} (dtypes {t.dtype}, {p.dtype})")
    if not np.isin(p, (-1, 0, 1)).all():
        odd = p[~np.isin(p, (-1, 0, 1))][0]
        raise EventDataError(f"{want}; last_p holds other values than -1, 0 and +1 (e.g. {odd!r})")
    if (np.isnan(t) != (p == 0)).any() if t.dtype.kind == "f" else (p == 0).any():
        raise EventDataError(f"{want}; last_t is NaN exactly where last_p is 0 (no event before)")
    return np.array(t, np.float64), np.array(p, np.int8)


def interval_sums(events: Events, last=None, with_flips: bool = False) -> tuple:
    """Per-pixel sums of the log intervals between consecutive events of the same polarity.

    Within a run of ON events a pixel's log intensity rises by C+ between two events, so the interval is
    ``C+ / |dL/dt|``; within a run of OFF events it is ``C- / |dL/dt|`` (see the module docstring).
    Pixels off the grid of :func:`interval_stride` get no pairs (large sensors only).

    Args:
        events: one span, time-ordered (as :class:`~evinr_lite.core.events.Events` always is).
        last: (last_t, last_p) float64 [H, W] and int8 [H, W]: each pixel's event before this span
            (NaN and 0 where none), so a streamed recording's chunks give the sums of the whole span.
        with_flips: also return each pixel's polarity reversals (an event whose polarity differs from
            the pixel's event before it): float64 [H, W], on the same grid, appended last.

    Returns:
        (log_on, k_on, log_off, k_off, last_t, last_p): [H, W] sums of log(interval / 1 s) and their
        counts for ON-ON and OFF-OFF pairs, and each pixel's last event after the span. Intervals are
        floored at MIN_INTERVAL (1 us, the timestamp resolution of event cameras). With ``with_flips``,
        (..., last_t, last_p, flips).
    """
    require(events, Events, "interval_sums: events")
    H, W = events.sensor_size
    s = interval_stride((H, W))
    Hs, Ws = -(-H // s), -(-W // s)
    last_t, last_p = (np.full((H, W), np.nan), np.zeros((H, W), np.int8)) if last is None else _check_last(last, (H, W))
    x, y, t, p = events.x, events.y, np.asarray(events.t, np.float64), events.p
    if s > 1:
        on_grid = (x % s == 0) & (y % s == 0)
        x, y, t, p = x[on_grid], y[on_grid], t[on_grid], p[on_grid]
    grid_t, grid_p = last_t[::s, ::s].ravel(), last_p[::s, ::s].ravel()       # copies, written back below
    cell = ((y // s) * Ws + x // s).astype(np.uint16 if Hs * Ws <= 1 << 16 else np.int64)
    order = np.argsort(cell, kind="stable")              # by pixel; time order kept within a pixel
    f, t, p = cell[order].astype(np.int64), t[order], p[order]
    first = np.ones(len(f), bool)
    first[1:] = f[1:] != f[:-1]
    prev_t = np.empty(len(f))
    prev_p = np.empty(len(f), np.int8)
    prev_t[1:], prev_p[1:] = t[:-1], p[:-1]
    prev_t[first], prev_p[first] = grid_t[f[first]], grid_p[f[first]]
    pair = prev_p == p                                   # the same polarity as the pixel's event before
    dt = np.log(np.maximum(t[pair] - prev_t[pair], MIN_INTERVAL))
    # on a grid of 2^-16 log units the sums are exact whatever their order, so a recording counted in
    # chunks gives the same C pair as the whole span, bit for bit
    dt = np.rint(dt * LOG_GRID) / LOG_GRID
    fp, on = f[pair], p[pair] > 0
    sums = []
    for sel in (on, ~on):
        for w in (dt[sel], None):
            full = np.zeros((H, W))
            full[::s, ::s] = np.bincount(fp[sel], w, minlength=Hs * Ws).reshape(Hs, Ws)
            sums.append(full)
    if with_flips:   # a reversal: the pixel's event before had the other polarity (0: there was none)
        flips = np.zeros((H, W))
        flips[::s, ::s] = np.bincount(f[(prev_p != p) & (prev_p != 0)], minlength=Hs * Ws).reshape(Hs, Ws)
    end = np.ones(len(f), bool)
    end[:-1] = f[1:] != f[:-1]
    grid_t[f[end]], grid_p[f[end]] = t[end], p[end]
    last_t[::s, ::s], last_p[::s, ::s] = grid_t.reshape(Hs, Ws), grid_p.reshape(Hs, Ws)
    return (*sums, last_t, last_p, flips) if with_flips else (*sums, last_t, last_p)


@dataclass
class PolarityCounts:
    """Running per-pixel ON / OFF counts (and interval sums), carried from window to window of a
    streamed recording.

        counts = PolarityCounts((H, W))
        for window in windows:
            counts.update(window_events)
            fit = counts.fit(C)          # the balance of everything seen so far

    ``decay`` in (0, 1]: the counts so far are multiplied by it before each update (1: all windows
    count alike; < 1 follows a balance that changes over the recording). The interval sums
    (:func:`interval_sums`) and the polarity reversals (``flips``, for the temporal scale,
    :mod:`~evinr_lite.method.tempo`) follow the last event of each pixel across updates, so chunks give
    the sums of the whole span. ``slices``: the boundaries (float64 [K + 1], s) of the span's time slices
    for the edges' estimate (:func:`slice_counts`; None: not counted, and the pooled counts stand in
    for it); they take 8 K bytes per pixel (59 MB at 1280 x 720 with K = 8). ``counts_only``: the ON /
    OFF counts alone (the intervals and slices stay zero), for a pass that only finds hot pixels.
    """

    sensor_size: tuple
    decay: float = 1.0
    n_on: np.ndarray = field(default=None, repr=False)
    n_off: np.ndarray = field(default=None, repr=False)
    intervals: tuple = field(default=None, repr=False)     # (log_on, k_on, log_off, k_off), [H, W] each
    flips: np.ndarray = field(default=None, repr=False)    # polarity reversals per pixel, [H, W] (interval grid)
    last: tuple = field(default=None, repr=False)          # (last_t, last_p), [H, W] each
    slices: object = None                                   # float64 [K + 1] slice boundaries (s), or None
    sliced: tuple = field(default=None, repr=False)        # (on, off), float32 [K, H, W] each
    counts_only: bool = False                               # n_on / n_off alone (a hot-pixel pass)

    def __post_init__(self):
        self.decay = real_number(self.decay, "decay", lo=0, hi=1, lo_open=True,
                                 hint="the weight of the counts so far at each update (1: all windows alike)")
        H, W = self.sensor_size = check_sensor_size(self.sensor_size)
        self.n_on = np.zeros((H, W)) if self.n_on is None else np.asarray(self.n_on, np.float64)
        self.n_off = np.zeros((H, W)) if self.n_off is None else np.asarray(self.n_off, np.float64)
        if self.intervals is None:
            self.intervals = tuple(np.zeros((H, W)) for _ in range(4))
        self.flips = np.zeros((H, W)) if self.flips is None else np.asarray(self.flips, np.float64)
        if self.slices is not None:
            self.slices = _slice_edges(self.slices, "slices")
            if self.sliced is None:
                K = len(self.slices) - 1
                self.sliced = (np.zeros((K, H, W), np.float32), np.zeros((K, H, W), np.float32))

    def update(self, events: Events) -> "PolarityCounts":
        if tuple(events.sensor_size) != tuple(self.sensor_size):
            raise EventDataError(f"events of sensor_size {tuple(events.sensor_size)} do not match the counts' "
                                 f"{tuple(self.sensor_size)}")
        on, off = polarity_counts(events)
        self.n_on = self.n_on * self.decay + on
        self.n_off = self.n_off * self.decay + off
        if self.counts_only:
            return self
        *new, last_t, last_p, flips = interval_sums(events, self.last, with_flips=True)
        self.intervals = tuple(old * self.decay + add for old, add in zip(self.intervals, new))
        self.flips = self.flips * self.decay + flips
        self.last = (last_t, last_p)
        if self.slices is not None:
            self.sliced = tuple(old * np.float32(self.decay) + add
                                for old, add in zip(self.sliced, slice_counts(events, self.slices)))
        return self

    def fit(self, C, rule: str = "consensus") -> BalanceFit:
        return balance_from_counts(self.n_on, self.n_off, C, intervals=self.intervals, rule=rule, sliced=self.sliced)


def interval_imbalance(intervals, usable) -> float:
    """The imbalance b read from the intervals of the ``usable`` pixels (bool [H, W]): with r the pooled
    mean log ON interval minus the mean log OFF interval, an estimate of log(C+ / C-),
    ``b = (e^r - 1) / (e^r + 1) = tanh(r / 2)``. NaN when either polarity has fewer than MIN_PIXELS pairs."""
    log_on, k_on, log_off, k_off = (np.asarray(a, np.float64)[usable] for a in intervals)
    if k_on.sum() < MIN_PIXELS or k_off.sum() < MIN_PIXELS:
        return float("nan")
    r = log_on.sum() / k_on.sum() - log_off.sum() / k_off.sum()
    return float(np.tanh(r / 2))


def minmod(a: float, b: float, *more: float) -> float:
    """The smallest in magnitude of estimates that all agree in sign, 0 when any two disagree (a NaN estimate
    agrees with none: 0)."""
    values = tuple(decimal_as_float(v) for v in (a, b) + more)   # a Decimal as its float, as before
    for k, v in enumerate(values):   # None or text was Python's "'>' not supported", an array numpy's "ambiguous"
        if not is_real_number(v):
            raise EventDataError(f"minmod: estimate {k + 1} must be a number (an imbalance b), got {v!r:.60}; pass "
                                 "one number per estimate: minmod(b1, b2, ...)")
    values = tuple(float(v) for v in values)
    a = values[0]
    if all(v > 0 for v in values) or all(v < 0 for v in values):
        return float(np.sign(a) * min(abs(v) for v in values))
    return 0.0


def _check_usable(n_on, n_off, usable, name: str, *, grid: bool = False) -> tuple:
    """The balance estimates' arguments: two counts of one shape (``grid``: [K, H, W] slices) and ``usable``, a
    bool mask of their pixels' shape; None, text, lists of another shape or a 0/1 mask were Python's or numpy's
    errors, or taken (an int mask indexed pixels 0 and 1). Bool counts are refused; whole-number counts come back
    as int64 (unsigned ones wrapped around in the differences), float counts in their dtype."""
    names = ("on", "off") if grid else ("n_on", "n_off")
    on, off = (check_counts(a, f"{name}: {k}") for a, k in zip((n_on, n_off), names))   # float dtypes kept
    for arr, k in zip((on, off), names):   # bool counts were numpy's "boolean subtract" error (or read as 0/1)
        if arr.dtype == bool:
            raise EventDataError(f"{name}: {k} must be event counts per pixel (numbers >= 0), got a bool array; "
                                 f"pass the counts themselves (e.g. from polarity_counts), or {k}.astype(int) if "
                                 "the 0/1 values are meant as counts")
    # whole-number counts as int64: uint16 counts wrapped around in n- - n+ (3210.6 for an estimate in [-1, 1])
    on, off = (a.astype(np.int64) if a.dtype.kind in "iu" else a for a in (on, off))
    if on.shape != off.shape or (grid and on.ndim != 3):
        raise EventDataError(f"{name}: {names[0]} and {names[1]} must be counts of one shape"
                             + (" per time slice [K, H, W] (as slice_counts gives them)" if grid else
                                " (one count per pixel)") + f", got shapes {on.shape} and {off.shape}")
    shape = on.shape[1:] if grid else on.shape
    usable = pixel_mask(usable, shape, f"{name}: usable", "the pixels to pool (e.g. (n_on + n_off) >= 4)")
    return on, off, usable


def pooled_imbalance(n_on, n_off, usable) -> float:
    """The counts' estimate of b over the ``usable`` pixels (bool [H, W]): sum(n- - n+) / sum(n- + n+)."""
    return _pooled_imbalance(*_check_usable(n_on, n_off, usable, "pooled_imbalance"))


def _pooled_imbalance(n_on, n_off, usable) -> float:   # balance_from_counts' call: its arguments are checked
    n = n_on[usable] + n_off[usable]
    return float((n_off[usable] - n_on[usable]).sum() / n.sum())


def slope_imbalance(n_on, n_off, usable) -> float:
    """The counts' estimate of b with an intercept: the least-squares slope of ``n- - n+`` against
    ``n = n+ + n-`` over the ``usable`` pixels (bool [H, W]). At every pixel ``C+ n+ - C- n- = dL``, so
    ``n- - n+ = b n - dL / C`` exactly: a change dL common to all pixels (a change of light, uniform in
    log intensity) goes to the intercept and the imbalance to the slope. What is left is the part of
    the scene's own per-pixel change that goes with the event count, which falls as events
    accumulate. NaN when the counts do not vary."""
    return _slope_imbalance(*_check_usable(n_on, n_off, usable, "slope_imbalance"))


def _slope_imbalance(n_on, n_off, usable) -> float:
    d = (np.asarray(n_off, np.float64) - np.asarray(n_on, np.float64))[usable]
    n = (np.asarray(n_on, np.float64) + np.asarray(n_off, np.float64))[usable]
    nc = n - n.mean()
    var = float((nc * nc).sum())
    return float((nc * (d - d.mean())).sum() / var) if var > 0 else float("nan")


def gradient_imbalance(on, off, usable) -> float:
    """The edges' estimate of b from the counts of K time slices (``on``, ``off``: [K, H, W], as
    :func:`slice_counts` gives) over the edges between two ``usable`` pixels (bool [H, W]).

    Integrated with C+ = C (1 + b) and C- = C (1 - b), a pixel's change since the span's start is
    ``C (net + b n)`` (net = n+ - n-, n = n+ + n-, both counted up to each slice's end). The difference
    of two neighbours, ``g + b h`` (g and h the differences of their net and total counts), is the
    change of the image's gradient across that edge. Where the scene moves, the gradient across an
    edge changes with the texture passing, but nothing makes it follow the difference of the two
    pixels' event counts, while a wrong b adds ``(b_true - b) h``, which does: an image of the event
    counts growing into the frames. So b is the one that leaves the edges' changes least correlated
    with their count differences: the least-squares fit of ``g + b h`` to a constant per edge over the
    K + 1 times (the start included), ``b = -sum(g' h') / sum(h' h')`` with g', h' less their mean over
    time. C cancels. A change of light common to all pixels changes no gradient; the error left is
    what the texture's changes share with the counts. NaN when no edge's count difference changes."""
    return _gradient_imbalance(*_check_usable(on, off, usable, "gradient_imbalance", grid=True))


def _gradient_imbalance(on, off, usable) -> float:
    K, H, W = np.shape(on)
    num = den = 0.0
    for r0 in range(0, H, BAND_ROWS):            # bands of rows (and the row below), so memory stays a band's
        n_rows = min(BAND_ROWS, H - r0)          # rows whose horizontal edges and downward edges this band owns
        band = slice(r0, min(H, r0 + n_rows + 1))
        o, f = (np.asarray(a[:, band], np.float64) for a in (on, off))
        zero = np.zeros((1,) + o.shape[1:])
        net = np.concatenate([zero, np.cumsum(o - f, axis=0)])
        tot = np.concatenate([zero, np.cumsum(o + f, axis=0)])
        u = usable[band]
        for axis in (1, 2):
            if axis == 1:
                both = u[1:, :] & u[:-1, :]
            else:
                both = np.zeros_like(u[:, 1:])
                both[:n_rows] = u[:n_rows, 1:] & u[:n_rows, :-1]
            g = np.diff(net, axis=axis)[:, both]
            h = np.diff(tot, axis=axis)[:, both]
            g -= g.mean(axis=0)
            h -= h.mean(axis=0)
            num += float((g * h).sum())
            den += float((h * h).sum())
    return -num / den if den > 0 else float("nan")


def balance_from_counts(n_on, n_off, C, *, intervals=None, sliced=None, rule: str = "consensus", min_events: int = MIN_EVENTS,
                        max_imbalance: float = MAX_IMBALANCE, prior: float = PRIOR,
                        net_change: float = NET_CHANGE) -> BalanceFit:
    """The balance from per-pixel sums (see the module docstring for the assumptions and the rules).

    Args:
        n_on, n_off: [H, W] ON and OFF counts per pixel (floats allowed: decayed running sums).
        C: the nominal threshold (one number; a pair is returned unchanged with ``applied=False``,
            since whoever gave C+ and C- already knows the balance).
        intervals: (log_on, k_on, log_off, k_off) [H, W] from :func:`interval_sums` (or
            :attr:`PolarityCounts.intervals`). Without them the consensus cannot be formed and the
            counts rule is used (``fit.rule`` says so).
        sliced: (on, off) [K, H, W] counts per time slice (:func:`slice_counts`, or
            :attr:`PolarityCounts.sliced`) for the edges' estimate, the intervals' partner in the
            minmod; without them the pooled counts take its place.
        rule: "consensus" (minmod of the edges' (or the pooled counts') and the intervals' estimates, or
            the counts' slope alone, bounded by the range of the pooled counts, the edges and the intervals,
            where their error scale is at most COUNTS_ALONE; where the edges and the intervals disagree
            and the counts show a steady light, the smallest of the edges, the slope and the pooled counts)
            or "counts" (the counts' pooled estimate shrunk by its evidence).
        min_events: pixels with fewer events are left out. max_imbalance: cap on |b| in [0, 1), and
            how far the intervals may lie from the counts for the counts to be taken alone.
        prior, net_change: the counts rule's prior spread of b and plausible mean log change (log units);
            net_change also sets the counts' error scale s = net_change / (C mean n) that the consensus
            compares with COUNTS_ALONE and COUNTS_OVER_INTERVALS.

    Returns:
        :class:`BalanceFit` with C = (C (1 + b), C (1 - b)).
    """
    rule = choice(rule, RULES, "rule")   # an array was numpy's "truth value ... is ambiguous"
    if not (is_real_number(max_imbalance) and 0 <= max_imbalance < 1):
        raise EventDataError(f"max_imbalance must be a number in [0, 1) (|b| = |C+ - C-| / (C+ + C-) < 1), "
                             f"got {max_imbalance!r}")
    # [H, W] only where the edges' estimate needs a sensor's neighbours (sliced); other shapes pool their pixels
    n_on, n_off = check_count_pair(n_on, n_off, grid=sliced is not None)
    min_events = real_number(decimal_as_float(min_events), "min_events", lo=0,
                             hint="the fewest events a pixel needs to count (e.g. 4)")
    if intervals is not None and (len(intervals) != 4 or any(np.shape(a) != n_on.shape for a in intervals)):
        raise EventDataError(f"intervals must be four arrays of the counts' shape {n_on.shape} (log_on, k_on, "
                             "log_off, k_off, as interval_sums returns)")
    if sliced is not None and (len(sliced) != 2 or any(np.ndim(a) != 3 or np.shape(a)[1:] != n_on.shape
                                                       or np.shape(a) != np.shape(sliced[0]) for a in sliced)):
        raise EventDataError(f"sliced must be two arrays [K, H, W] with (H, W) = {n_on.shape} (on, off, as "
                             "slice_counts returns)")
    c_pos, c_neg = as_thresholds(C)
    if np.ndim(C) != 0:
        return BalanceFit((c_pos, c_neg), 0.0, 0.0, 0.0, 0.0, 0, 0, False, rule=rule)
    rule = rule if intervals is not None else "counts"
    n = n_on + n_off
    hot = n > hot_threshold(np.rint(n), rule="mad")
    usable = (n >= min_events) & ~hot
    if usable.sum() < MIN_PIXELS:
        return BalanceFit((c_pos, c_neg), 0.0, 0.0, 0.0, 0.0, int(usable.sum()), int(hot.sum()), False, rule=rule)
    raw = _pooled_imbalance(n_on, n_off, usable)
    # second pass: a pixel whose net level, once balanced, lies beyond any natural scene's range is not
    # watching the scene (a hot pixel below the count rule, a broken one): leave it out too
    stray = usable & (c_pos * np.abs((n_off - n_on) - raw * n) > OUTLIER_LOG)
    if stray.any() and (usable & ~stray).sum() >= MIN_PIXELS:
        usable &= ~stray
        hot |= stray
        raw = _pooled_imbalance(n_on, n_off, usable)
    mean_n = float(n[usable].mean())
    s = net_change / (c_pos * mean_n)
    shrink = prior ** 2 / (prior ** 2 + s ** 2)
    slope = _slope_imbalance(n_on, n_off, usable)
    grad = _gradient_imbalance(*sliced, usable) if sliced is not None and rule == "consensus" else float("nan")
    if rule == "consensus":
        ivl = interval_imbalance(intervals, usable)
        if not np.isfinite(ivl):
            b, chosen = 0.0, "nominal"                 # no runs of one polarity to time: no evidence
        elif s <= COUNTS_ALONE and np.isfinite(slope) and abs(slope - ivl) <= max_imbalance:
            # enough events that the counts' error (the mean log change over C mean n) is below the
            # intervals' own bias, and the intervals do not contradict them: the counts fitted with an
            # intercept, so that a change of light common to all pixels is not read as an imbalance.
            # With the edges' estimate there are three others whose errors have other causes (a change
            # of light pushes the pooled counts and the edges one way, the intervals the other): where
            # all three lie on one side of the slope, it is the slope that errs, and it is bounded by
            # their range (the module docstring has the figures)
            b, chosen = slope, "counts"
            if np.isfinite(grad):
                b = float(np.clip(slope, min(raw, grad, ivl), max(raw, grad, ivl)))
        else:
            # the edges' estimate where there are slice counts (a change of light common to all pixels
            # does not enter it, as it enters the pooled counts), else the pooled counts
            b = minmod(grad if np.isfinite(grad) else raw, ivl)
            chosen = "minmod" if b != 0.0 else "nominal"
            if b == 0.0 and np.isfinite(grad) and np.isfinite(slope) and s <= COUNTS_OVER_INTERVALS \
                    and c_pos * mean_n * abs(raw - slope) <= STEADY_LIGHT:
                # the edges and the intervals disagree, and the counts show no change of light (the pooled
                # counts, which read one, agree with the slope, which does not): a change of light is what
                # pushes those two apart, so here it is the intervals' own bias (+0.05 to +0.2 on natural
                # scenes) that flips their sign; the three counts' estimates agree, and the smallest is taken
                b = minmod(grad, slope, raw)
                chosen = "agreement" if b != 0.0 else "nominal"
    else:
        ivl, b, chosen = float("nan"), shrink * raw, "counts"
    b = float(np.clip(b, -max_imbalance, max_imbalance))
    return BalanceFit((c_pos * (1 + b), c_neg * (1 - b)), b, raw, shrink, mean_n, int(usable.sum()),
                      int(hot.sum()), True, ivl, rule, chosen, s, slope, grad)


def estimate_balance(events: Events, C, **kw) -> BalanceFit:
    """:func:`balance_from_counts` on the counts of ``events`` (one span, e.g. one window)."""
    events = require(events, Events, "events")
    if len(events) == 0:
        raise EventDataError("no events to estimate the ON/OFF balance from; pass a span with events")
    counts = PolarityCounts(tuple(events.sensor_size), slices=span_slices(events.t[0], events.t[-1])).update(events)
    return balance_from_counts(counts.n_on, counts.n_off, C, intervals=counts.intervals, sliced=counts.sliced, **kw)


def span_slices(t_start: float, t_end: float, k: int = SLICES) -> np.ndarray:
    """Boundaries (float64 [k + 1], s) of k equal time slices of [t_start, t_end] (a span of zero length
    gets one of 1 us, so that the boundaries increase)."""
    t_start, t_end = checked_span(decimal_as_float(t_start), decimal_as_float(t_end), "span_slices")
    k = whole_number(k, "span_slices: k", lo=1)
    return np.linspace(t_start, max(t_end, t_start + MIN_INTERVAL), k + 1)
