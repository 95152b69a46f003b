"""How much spatial smoothing a window needs: the regularizer's weight lam chosen from the events.

The closed-form head fits the event frames almost exactly, and the Tikhonov term is what keeps a
frame's *changes* (F_t minus the window's mean frame) spatially smooth: it damps the per-pixel
quantization noise of the events (each pixel's change is a whole number of thresholds, off by up
to one C whatever the scene did), and it also damps real texture, most where a frame differs most
from the window's mean (a pan's turning points). Which of the two matters depends on how much
texture went past each pixel in the window:

    signal of the changes ~ (m C)^2,   quantization noise ~ C^2,   so   lam ~ 1 / m^2,

with ``m`` the events per pixel per network window that came *and went*: ``2 min(n_on, n_off)``,
averaged over the sensor. A global change of light (every pixel firing the same polarity) carries
no texture and does not count; hot pixels are left out before (:mod:`~evinr_lite.method.balance`).
So ``lam = LAM_SCALE / m^2``, kept within [LAM_MIN, LAM_MAX]: a few events per pixel (sparse texture,
a short window, a static camera) keep the earlier fixed default 0.01; busy windows (a textured pan,
20-30 events per pixel) get less smoothing.

Chosen on the whole zoo and the real chunk (``python benchmarks/lam_rule.py`` prints each scene's
activity, the lam it gets and the CLAHE-SSIM of a sweep of fixed lam values), never on one scene.
"""
from __future__ import annotations

import numpy as np

from ..core.checks import real_number
from ..core.events import EventDataError
from ..core.guard import dense_array
from .denoise import check_count_pair

__all__ = ["activity", "auto_lam", "covered_fraction", "window_fraction", "LAM_SCALE", "LAM_MIN", "LAM_MAX"]

LAM_SCALE = 0.3     # lam x m^2: lam reaches LAM_MAX below about 5.5 events per pixel per window
LAM_MIN = 0.002     # the least smoothing: below it the zoo's long pans lose more than its busy scenes gain
LAM_MAX = 0.01      # the most: the fixed default before issue 21 (sparser windows gain or lose little above it)


def activity(n_on, n_off) -> float:
    """Mean over pixels of ``2 min(n_on, n_off)`` ([H, W] counts): events that came and went."""
    n_on, n_off = check_count_pair(n_on, n_off, grid=False)   # NaN or negative counts gave LAM_MAX silently
    return float(2 * np.minimum(n_on, n_off).mean()) if n_on.size else 0.0


def covered_fraction(windows) -> float:
    """The share of the span of ``windows`` [N, 2] (s) that the first window covers (1 for one window)."""
    w = dense_array(windows, "windows", error=EventDataError)
    if w.dtype.kind not in "iuf" or w.ndim != 2 or w.shape[0] < 1 or w.shape[1] != 2:   # was numpy's IndexError
        raise EventDataError(f"windows must be [N, 2] (start, end) pairs in seconds, at least one, got shape {w.shape}")
    w = w.astype(np.float64)
    span = float(w[-1, 1] - w[0, 0])
    return float(min(1.0, (w[0, 1] - w[0, 0]) / span)) if span > 0 else 1.0


def window_fraction(t_start: float, t_end: float, tau: float | None, overlap: float) -> float:
    """The share of the span [t_start, t_end] (s) that one network window covers (1 for one window)."""
    from .ensemble import split_windows

    t_start, t_end = real_number(t_start, "t_start", hint="seconds"), real_number(t_end, "t_end", hint="seconds")
    if not t_end - t_start > 0:   # a NaN span was 1 without a word
        return 1.0
    return covered_fraction(split_windows(t_start, t_end, tau, overlap))


def auto_lam(n_on, n_off, fraction: float = 1.0) -> float:
    """lam for a span whose per-pixel ON / OFF counts are ``n_on``, ``n_off`` [H, W], trained in
    windows that each cover ``fraction`` of it: LAM_SCALE / m^2 within [LAM_MIN, LAM_MAX], with m the
    activity per window (:func:`activity` x fraction)."""
    fraction = real_number(fraction, "fraction", lo=0, hi=1, lo_open=True,
                           hint="the share of the span one network window covers")
    m = activity(n_on, n_off) * fraction
    if not m > 0:
        return LAM_MAX
    return float(np.clip(LAM_SCALE / m ** 2, LAM_MIN, LAM_MAX))
