"""The ON/OFF balance from the events alone: C+ and C- when only a nominal C is known.

Real sensors fire ON and OFF events at different thresholds (C+ != C-), while users usually know one
nominal C. Integrated with one C, every event then carries a small error of the same sign for its
polarity, and a busy pixel's level drifts linearly with its event count: on a 20 s recording with
C+ 0.25 and C- 0.20 given as C = 0.225, the mean brightness error of the kit went from +0.45 to
-0.31 (issue 21). The drift is what events cannot tell apart from a real change of light, so it must
be removed by an assumption, stated here:

    a pixel that watches a moving scene keeps returning to log intensities it had before: over a
    span its net change ``C+ n+ - C- n-`` is bounded (a few log units at most), while its event
    count ``n+ + n-`` grows with the span.

So over a long span ``C+ / C- -> n- / n+`` at every pixel. Pooled over pixels, the imbalance
``b = (n- - n+) / (n- + n+)`` gives ``C+ = C (1 + b)`` and ``C- = C (1 - b)`` with their mean kept at
the nominal C (the nominal C sets the contrast, the balance only the drift).

How the estimate is made robust (:func:`balance_from_counts`):

- hot pixels fire without a brightness change, often of one polarity (ON-only hot pixels climb
  without bound): pixels above :func:`~evinr_lite.method.denoise.hot_threshold` are left out, and so
  are pixels whose net level, balanced with the first estimate, lies beyond OUTLIER_LOG = 4 log
  units (a 55x change of intensity: no pixel of a natural scene goes there and comes back), which
  catches hot pixels that a busy texture hides from the count rule;
- the imbalance is pooled over pixels, ``b = sum(n-  - n+) / sum(n- + n+)``: the pixels' real net
  changes ``dL_i`` enter as ``-sum dL_i / (C sum n_i)``, i.e. the change of the *mean* log brightness
  over the span divided by C times the mean event count. Pixel changes of both signs cancel; a
  change of the mean brightness (new content entering a short window, a change of light) does not;
- so the estimate is only trusted as far as the span carries evidence: with an uncertainty
  ``s = NET_CHANGE / (C mean n)`` (NET_CHANGE = 0.5 log units: the spread of the change of the mean
  log brightness over a span) and a prior spread ``PRIOR = 0.1`` of real sensors' imbalance (C+ / C-
  about 1.2), the pooled value is shrunk by ``PRIOR^2 / (PRIOR^2 + s^2)`` (the posterior mean of a
  normal prior and a normal error). Both spreads are the root mean square over the zoo's 15 scenes
  (``evinr_lite.sim.zoo``, long ones included): the truth's mean log change from the first to the
  last scored frame, 0.50 (dark_falling's -1.79 the largest, most below 0.1), and the simulated
  imbalance, 0.084 (0 on nine scenes, 0.10-0.20 on six). On a 2 s window (mean n about 10-20
  events per pixel at C 0.2) a quarter or less is corrected, where little drift builds up either;
  on 20 s (mean n 50-90) 80-95 %;
- background activity fires ON and OFF with equal probability: it dilutes the imbalance slightly
  towards 0 (less correction, never a wrong sign);
- ``max_imbalance`` caps the correction (0.3: C+ / C- within 0.54 and 1.86).

Measured on the zoo's scenes (``python benchmarks/balance.py`` prints the table,
benchmarks/balance_results.md): the pooled imbalance is within 0.01 of the truth where the mean
brightness does not change (noisy_gravel: +0.099 for +0.100; long_ijrr_60s +0.099 for +0.100) and
off by the change of mean brightness where it does (camera_translate: +0.193 for 0, mean log change
-0.35 over 1.7 s with 13 events per pixel), which is what the shrinkage is for.

Everything works from per-pixel counts, so a streamed recording can carry :class:`PolarityCounts`
from window to window and estimate the balance from all the events seen so far. Where the solver
applies it (with the hot pixels, the background filter and lam): :mod:`evinr_lite.method.prepare`.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.events import EventDataError, Events
from .binning import as_thresholds
from .denoise import hot_threshold

__all__ = ["BalanceFit", "PolarityCounts", "polarity_counts", "balance_from_counts", "estimate_balance",
           "BALANCE_MODES", "HOT_PIXEL_MODES", "MIN_EVENTS", "MAX_IMBALANCE", "PRIOR", "NET_CHANGE"]

BALANCE_MODES = ("none", "events")
HOT_PIXEL_MODES = ("keep", "drop")
MIN_EVENTS = 1            # pixels with fewer events over the span are left out of the estimate
MAX_IMBALANCE = 0.3       # |b| is capped here: C+ / C- within (0.7 / 1.3, 1.3 / 0.7)
MIN_PIXELS = 50           # fewer usable pixels: no estimate, the nominal C is kept
PRIOR = 0.1               # prior spread of real sensors' imbalance b (C+ / C- about 1.2)
OUTLIER_LOG = 4.0         # log units: a pixel's balanced net level beyond this (55x in intensity) is left out
NET_CHANGE = 0.5          # log units: spread of the change of the mean log brightness over a span


@dataclass
class BalanceFit:
    """The ON/OFF balance of a span of events.

    Attributes:
        C: (c_pos, c_neg) log units per event, mean = the nominal C.
        imbalance: b applied, (C+ - C-) / (C+ + C-) = shrink x raw_imbalance, capped.
        raw_imbalance: the pooled b = sum(n- - n+) / sum(n- + n+) over the usable pixels.
        shrink: the weight given to the raw value (0: nominal C kept, 1: raw value used).
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

    def summary(self) -> dict:
        return {"C": [float(c) for c in self.C], "imbalance": self.imbalance, "raw_imbalance": self.raw_imbalance,
                "shrink": self.shrink, "mean_events": self.mean_events, "n_pixels": self.n_pixels,
                "n_hot": self.n_hot, "applied": self.applied}


def polarity_counts(events: Events) -> tuple[np.ndarray, np.ndarray]:
    """(n_on, n_off): int64 [H, W] ON and OFF event counts per pixel."""
    H, W = events.sensor_size
    flat = events.y.astype(np.int64) * W + events.x
    on = events.p > 0
    n_on = np.bincount(flat[on], minlength=H * W).reshape(H, W)
    n_off = np.bincount(flat[~on], minlength=H * W).reshape(H, W)
    return n_on, n_off


@dataclass
class PolarityCounts:
    """Running per-pixel ON / OFF counts, carried from window to window of a streamed recording.

        counts = PolarityCounts((H, W))
        for window in windows:
            counts.update(window_events)
            fit = counts.fit(C)          # the balance of everything seen so far

    ``decay`` in (0, 1]: the counts so far are multiplied by it before each update (1: all windows
    count alike; < 1 follows a balance that changes over the recording).
    """

    sensor_size: tuple
    decay: float = 1.0
    n_on: np.ndarray = field(default=None, repr=False)
    n_off: np.ndarray = field(default=None, repr=False)

    def __post_init__(self):
        if not (0 < float(self.decay) <= 1):
            raise EventDataError(f"decay must be in (0, 1], got {self.decay!r}")
        H, W = self.sensor_size
        self.n_on = np.zeros((H, W)) if self.n_on is None else np.asarray(self.n_on, np.float64)
        self.n_off = np.zeros((H, W)) if self.n_off is None else np.asarray(self.n_off, np.float64)

    def update(self, events: Events) -> "PolarityCounts":
        if tuple(events.sensor_size) != tuple(self.sensor_size):
            raise EventDataError(f"events of sensor_size {tuple(events.sensor_size)} do not match the counts' "
                                 f"{tuple(self.sensor_size)}")
        on, off = polarity_counts(events)
        self.n_on = self.n_on * self.decay + on
        self.n_off = self.n_off * self.decay + off
        return self

    def fit(self, C) -> BalanceFit:
        return balance_from_counts(self.n_on, self.n_off, C)


def balance_from_counts(n_on, n_off, C, *, min_events: int = MIN_EVENTS, max_imbalance: float = MAX_IMBALANCE,
                        prior: float = PRIOR, net_change: float = NET_CHANGE) -> BalanceFit:
    """The balance from per-pixel counts (see the module docstring for the assumption and the shrinkage).

    Args:
        n_on, n_off: [H, W] ON and OFF counts per pixel (floats allowed: decayed running sums).
        C: the nominal threshold (one number; a pair is returned unchanged with ``applied=False``,
            since whoever gave C+ and C- already knows the balance).
        min_events: pixels with fewer events are left out. max_imbalance: cap on |b|.
        prior, net_change: the shrinkage's prior spread of b and plausible mean log change (log units).

    Returns:
        :class:`BalanceFit` with C = (C (1 + b), C (1 - b)).
    """
    n_on = np.asarray(n_on, np.float64)
    n_off = np.asarray(n_off, np.float64)
    if n_on.shape != n_off.shape:
        raise EventDataError(f"n_on {n_on.shape} and n_off {n_off.shape} must have the same shape")
    c_pos, c_neg = as_thresholds(C)
    if np.ndim(C) != 0:
        return BalanceFit((c_pos, c_neg), 0.0, 0.0, 0.0, 0.0, 0, 0, False)
    n = n_on + n_off
    hot = n > hot_threshold(np.rint(n), rule="mad")
    usable = (n >= min_events) & ~hot
    if usable.sum() < MIN_PIXELS:
        return BalanceFit((c_pos, c_neg), 0.0, 0.0, 0.0, 0.0, int(usable.sum()), int(hot.sum()), False)
    raw = float((n_off[usable] - n_on[usable]).sum() / n[usable].sum())
    # second pass: a pixel whose net level, once balanced, lies beyond any natural scene's range is not
    # watching the scene (a hot pixel below the count rule, a broken one): leave it out too
    stray = usable & (c_pos * np.abs((n_off - n_on) - raw * n) > OUTLIER_LOG)
    if stray.any() and (usable & ~stray).sum() >= MIN_PIXELS:
        usable &= ~stray
        hot |= stray
        raw = float((n_off[usable] - n_on[usable]).sum() / n[usable].sum())
    mean_n = float(n[usable].mean())
    s = net_change / (c_pos * mean_n)
    shrink = prior ** 2 / (prior ** 2 + s ** 2)
    b = float(np.clip(shrink * raw, -max_imbalance, max_imbalance))
    return BalanceFit((c_pos * (1 + b), c_neg * (1 - b)), b, raw, shrink, mean_n, int(usable.sum()),
                      int(hot.sum()), True)


def estimate_balance(events: Events, C, **kw) -> BalanceFit:
    """:func:`balance_from_counts` on the counts of ``events`` (one span, e.g. one window)."""
    from ..core.checks import require

    events = require(events, Events, "events")
    if len(events) == 0:
        raise EventDataError("no events to estimate the ON/OFF balance from; pass a span with events")
    return balance_from_counts(*polarity_counts(events), C, **kw)
