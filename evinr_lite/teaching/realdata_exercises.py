"""Notebook 09 (real data): the event-rate and contrast-threshold exercises.

- ``event_rate``: events per second in fixed bins, the first look at any recording. The reference
  below is the teaching version (times only, one rate); it re-implements, on purpose, the
  library's :func:`evinr_lite.method.binning.event_rate` (ON and OFF rates of an ``Events``),
  and ``tests/test_realdata.py`` pins the two together. Bins follow the kit's one rule,
  (b_k, b_{k+1}] (bin 0 also holds an event at b_0), as every binning of the library does: an event
  exactly on an edge belongs to the earlier bin, and the check has such events.
- ``estimate_contrast_threshold``: the least-squares C relating the log-intensity change of APS
  frames to the net event count between them, ΔL ≈ C n. The reference is the library's
  :func:`evinr_lite.method.contrast.estimate_contrast_threshold`, which notebook 11 applies to the
  reader's own recording (the exercise is notebook 09's only: one C-fit exercise in the series).
- ``anchor_first_offset``: the per-pixel offset with which one APS frame anchors an events-only
  reconstruction (``EvINRConfig(anchor="first")``): g = log(I0 + eps) - L(t0), I0 the first frame
  in [0, 1] (uint8 / 255), L(t0) the network's log intensity at the frame's time before anchoring.
  The reference re-implements :func:`evinr_lite.method.anchor.fit_anchor`'s "first" mode, and
  ``tests/test_exercises_09_11.py`` pins the two together.
"""
from __future__ import annotations

import numpy as np

from ..method.anchor import FRAME_EPS
from ..method.contrast import estimate_contrast_threshold
from . import exercises

__all__ = ["event_rate", "estimate_contrast_threshold", "anchor_first_offset"]


def event_rate(t, bin_s):
    """Event rate over time.

    Args:
        t: float64 [N] event timestamps (s), sorted.
        bin_s: bin width (s).

    Returns:
        (centers, rate): float64 [B] bin centres (s) and events per second in each bin, with bins
        (t0 + k * bin_s, t0 + (k + 1) * bin_s] starting at t0 = t[0] (bin 0 also holds the events at
        t0) and B = ceil((t[-1] - t0) / bin_s), at least 1, so that every event is counted once: an
        event exactly on an edge counts in the earlier bin, the kit's one rule.
    """
    t = np.asarray(t, dtype=np.float64)
    n_bins = max(int(np.ceil((t[-1] - t[0]) / bin_s)), 1)
    k = np.clip(np.ceil((t - t[0]) / bin_s).astype(np.int64) - 1, 0, n_bins - 1)
    counts = np.bincount(k, minlength=n_bins)
    centers = t[0] + (np.arange(n_bins) + 0.5) * bin_s
    return centers, counts / bin_s


# ---- exercise registrations -----------------------------------------------------------------

def _inputs_rate(rng):
    cases = []
    for n, span, bin_s in ((50, 1.0, 0.1), (200, 0.37, 0.05), (7, 2.0, 0.5)):
        t = np.sort(rng.uniform(0.0, span, n)) + rng.uniform(0, 3)
        cases.append(dict(t=t, bin_s=bin_s))
    # events exactly on bin edges (dyadic times, so t - t0 and the edges are exact in float64): the
    # rule (b_k, b_{k+1}] puts each in the earlier bin; a [b_k, b_{k+1}) rule (floor, or
    # searchsorted(side="right")) moves them one bin up and adds a bin for a last event on an edge.
    # Ties: several events at one time; the first event (t0) sits on edge b_0 and belongs to bin 0.
    cases.append(dict(t=np.array([1.0, 1.125, 1.25, 1.25, 1.3, 1.5, 1.625, 2.0]), bin_s=0.125))
    cases.append(dict(t=np.array([0.5, 0.5, 0.75, 1.0, 1.0, 1.0, 1.5]), bin_s=0.25))
    # an empty bin in the middle, and a single event (one bin)
    cases.append(dict(t=np.array([0.0, 0.25, 1.0]), bin_s=0.25))
    cases.append(dict(t=np.array([3.0]), bin_s=0.5))
    return cases


def _rate_edges_to_later_bin(t, bin_s):
    """The mistake: bins [b_k, b_{k+1}) (floor, or searchsorted(edges, t, side="right") - 1)."""
    t = np.asarray(t, dtype=np.float64)
    n_bins = max(int(np.floor((t[-1] - t[0]) / bin_s)) + 1, 1)
    k = np.minimum(((t - t[0]) / bin_s).astype(np.int64), n_bins - 1)
    counts = np.bincount(k, minlength=n_bins)
    return t[0] + (np.arange(n_bins) + 0.5) * bin_s, counts / bin_s


def _rate_edges_to_later_bin_clipped(t, bin_s):
    """Bins [b_k, b_{k+1}) with B = ceil(...) bins, the last one closed (np.histogram on edges t0 + k bin_s, or
    floor clipped to B - 1): an event on an inner edge goes to the later bin."""
    t = np.asarray(t, dtype=np.float64)
    n_bins = max(int(np.ceil((t[-1] - t[0]) / bin_s)), 1)
    k = np.clip(np.floor((t - t[0]) / bin_s).astype(np.int64), 0, n_bins - 1)
    return t[0] + (np.arange(n_bins) + 0.5) * bin_s, np.bincount(k, minlength=n_bins) / bin_s


def _rate_bins_from_zero(t, bin_s):
    """The mistake: bins counted from time 0 (edges k bin_s) instead of from the first event t0 = t[0]."""
    t = np.asarray(t, dtype=np.float64)
    n_bins = max(int(np.ceil(t[-1] / bin_s)), 1)
    k = np.clip(np.ceil(t / bin_s).astype(np.int64) - 1, 0, n_bins - 1)
    return (np.arange(n_bins) + 0.5) * bin_s, np.bincount(k, minlength=n_bins) / bin_s


def _rate_bins_rounded_down(t, bin_s):
    """B = int((t[-1] - t0) / bin_s): the events of the last, partial bin are clipped into the one before."""
    t = np.asarray(t, dtype=np.float64)
    n_bins = max(int((t[-1] - t[0]) / bin_s), 1)
    k = np.clip(np.ceil((t - t[0]) / bin_s).astype(np.int64) - 1, 0, n_bins - 1)
    return t[0] + (np.arange(n_bins) + 0.5) * bin_s, np.bincount(k, minlength=n_bins) / bin_s


def _rate_firing_bins_only(t, bin_s):
    """Only the bins that hold an event (np.unique of the bin numbers), the empty ones left out."""
    t = np.asarray(t, dtype=np.float64)
    k = np.maximum(np.ceil((t - t[0]) / bin_s).astype(np.int64) - 1, 0)
    ks, counts = np.unique(k, return_counts=True)
    return t[0] + (ks + 0.5) * bin_s, counts / bin_s


def _rate_bins_from_one(t, bin_s):
    """Bin numbers ceil((t - t0) / bin_s), counted from 1 (the - 1 forgotten), clipped into 0 .. B - 1."""
    t = np.asarray(t, dtype=np.float64)
    n_bins = max(int(np.ceil((t[-1] - t[0]) / bin_s)), 1)
    k = np.clip(np.ceil((t - t[0]) / bin_s).astype(np.int64), 0, n_bins - 1)
    return t[0] + (np.arange(n_bins) + 0.5) * bin_s, np.bincount(k, minlength=n_bins) / bin_s


exercises.register(
    "event_rate", event_rate, _inputs_rate,
    hints={"divide the counts by the bin width to get events per second":
           lambda t, bin_s: (event_rate(t, bin_s)[0], event_rate(t, bin_s)[1] * bin_s),
           "return the bin centres, not the left edges":
           lambda t, bin_s: (event_rate(t, bin_s)[0] - bin_s / 2, event_rate(t, bin_s)[1]),
           "return the bin centres t0 + (k + 1/2) bin_s, not the right edges t0 + (k + 1) bin_s":
           lambda t, bin_s: (event_rate(t, bin_s)[0] + bin_s / 2, event_rate(t, bin_s)[1]),
           "an event exactly on a bin edge t0 + k bin_s belongs to bin k - 1 (bins are (b_k, b_{k+1}], the "
           "library's rule; bin 0 also holds t0): use ceil((t - t0) / bin_s) - 1 clipped at 0, or "
           "searchsorted(edges, t, side='left') - 1, not floor or side='right'":
           _rate_edges_to_later_bin,
           "an event exactly on an inner bin edge t0 + k bin_s belongs to bin k - 1, which ends there (bins are "
           "(b_k, b_{k+1}]): np.histogram's bins are [b_k, b_{k+1}) but its last, and floor((t - t0) / bin_s) puts "
           "the event in bin k; use ceil((t - t0) / bin_s) - 1 clipped at 0, or searchsorted(edges, t, side='left') - 1":
           _rate_edges_to_later_bin_clipped,
           "count the bins from the first event t0 = t[0] (edges t0 + k bin_s), not from time 0: a recording's "
           "clock rarely starts at 0":
           _rate_bins_from_zero,
           "B = ceil((t[-1] - t0) / bin_s) bins: int() rounds down and drops the last, partial bin":
           _rate_bins_rounded_down,
           "a rate is events per second: divide each bin's count by the bin width bin_s, not by the number of "
           "events (that is the fraction of the events in each bin)":
           lambda t, bin_s: (event_rate(t, bin_s)[0], event_rate(t, bin_s)[1] * bin_s / len(t)),
           "every bin from t0 to t[-1] is part of the result, the empty ones too (rate 0): np.unique of the bin "
           "numbers gives only the bins that hold events; count with np.bincount(k, minlength=B)":
           _rate_firing_bins_only,
           "bins are numbered from 0: bin k is (t0 + k bin_s, t0 + (k + 1) bin_s], so k = ceil((t - t0) / bin_s) - 1 "
           "(clipped at 0 for t0 itself); without the - 1 every event lands one bin late and the last bin takes "
           "two bins' events":
           _rate_bins_from_one,
           "several events can share a timestamp and each one counts: np.unique(t) (or a set, or a dict keyed by "
           "time) merges them; count the events as they are":
           lambda t, bin_s: event_rate(np.unique(np.asarray(t, dtype=np.float64)), bin_s)})


def _inputs_threshold(rng):
    cases = []
    # the second case's noise flips the sign of some single-event pixels' ΔL (a fit on |ΔL| and |n| fails)
    for C, M, noise in ((0.3, 50, 0.05), (0.8, 200, 0.6), (0.15, 30, 0.0)):
        n = rng.integers(-4, 5, M)
        n[0] = 3                      # never all zero
        cases.append(dict(log_changes=C * n + noise * rng.standard_normal(M), net_counts=n))
    return cases


def _mean_of_ratios(log_changes, net_counts):
    d, n = np.asarray(log_changes, float), np.asarray(net_counts, float)
    keep = n != 0
    return float(np.mean(d[keep] / n[keep]))


def _threshold_ratio_of_sums(log_changes, net_counts):
    return float(np.sum(log_changes) / np.sum(net_counts))


def _threshold_rms_ratio(log_changes, net_counts):
    d, n = np.asarray(log_changes, float), np.asarray(net_counts, float)
    return float(np.sqrt(np.sum(d * d) / np.sum(n * n)))


def _threshold_of_magnitudes(log_changes, net_counts):
    d, n = np.abs(np.asarray(log_changes, float)), np.abs(np.asarray(net_counts, float))
    return float(np.sum(d * n) / np.sum(n * n))


def _threshold_column_times_row(log_changes, net_counts):
    """n as a column [M, 1] times ΔL [M]: an [M, M] table of every pair, whose sum is sum(ΔL) sum(n)."""
    d, n = np.asarray(log_changes, float), np.asarray(net_counts, float)[:, None]
    return float(np.sum(d * n) / np.sum(n * n))


def _threshold_means_over_other_pixels(log_changes, net_counts):
    """np.mean(ΔL n) over all pixels divided by np.mean(n^2) over the pixels with n != 0: two different counts."""
    d, n = np.asarray(log_changes, float), np.asarray(net_counts, float)
    return float(np.mean(d * n) / np.mean(n[n != 0] ** 2))


exercises.register(
    "estimate_contrast_threshold", estimate_contrast_threshold, _inputs_threshold, rtol=1e-6,
    hints={
        "every pixel counts, those with more OFF than ON events (n < 0) too: n^2 and ΔL n do not care about the sign":
            lambda log_changes, net_counts: estimate_contrast_threshold(
                np.asarray(log_changes)[np.asarray(net_counts) > 0], np.asarray(net_counts)[np.asarray(net_counts) > 0]),
        "C multiplies n: the least-squares slope is sum(ΔL n) / sum(n^2), not sum(n^2) / sum(ΔL n)":
            lambda log_changes, net_counts: float(np.sum(np.square(np.asarray(net_counts, float)))
                                                  / np.sum(np.asarray(log_changes) * net_counts)),
        "a mean of per-pixel ratios ΔL / n weights noisy single-event pixels as much as the rest; "
        "fit the line through all pixels at once":
            _mean_of_ratios,
        "regressing n on ΔL gives sum(ΔL^2) / sum(ΔL n), biased by the noise in ΔL; regress ΔL on n":
            lambda log_changes, net_counts: float(np.sum(np.square(log_changes))
                                                  / np.sum(np.asarray(log_changes) * net_counts)),
        "a line through the origin has no intercept: sum(ΔL n) / sum(n^2), not the slope of a fit with an "
        "intercept (np.polyfit(n, ΔL, 1))":
            lambda log_changes, net_counts: float(np.polyfit(np.asarray(net_counts, float),
                                                             np.asarray(log_changes, float), 1)[0]),
        "sum(ΔL) / sum(n) lets rising and falling pixels cancel: the least-squares slope is sum(ΔL n) / "
        "sum(n^2)":
            _threshold_ratio_of_sums,
        "divide by sum(n^2), not sum(|n|): the least-squares slope of ΔL ≈ C n is sum(ΔL n) / sum(n^2)":
            lambda log_changes, net_counts: float(np.sum(np.asarray(log_changes, float) * net_counts)
                                                  / np.sum(np.abs(np.asarray(net_counts, float)))),
        "divide by sum(n^2), not by the number of pixels: sum(ΔL n) / M is a covariance, not the slope":
            lambda log_changes, net_counts: float(np.sum(np.asarray(log_changes, float) * net_counts)
                                                  / len(np.asarray(net_counts))),
        "the least-squares slope is sum(ΔL n) / sum(n^2), not sqrt(sum(ΔL^2) / sum(n^2)) (a ratio of RMS values, "
        "which noise in ΔL inflates)":
            _threshold_rms_ratio,
        "keep the signs: a fit on |ΔL| and |n| lets a pixel whose ΔL has the wrong sign (noise) count as agreeing":
            _threshold_of_magnitudes,
        "C is the least-squares slope sum(ΔL n) / sum(n^2) over all pixels, not the median of the per-pixel ratios "
        "ΔL / n (each pixel weighs as much as its n^2 in least squares)":
            lambda log_changes, net_counts: float(np.median(
                np.asarray(log_changes, float)[np.asarray(net_counts) != 0]
                / np.asarray(net_counts, float)[np.asarray(net_counts) != 0])),
        "take both sums over the same pixels: np.mean(ΔL n) over all of them divided by np.mean(n^2) over the pixels "
        "that fired divides by two different counts; the ratio of sums, sum(ΔL n) / sum(n^2), needs no means":
            _threshold_means_over_other_pixels,
        "one of the two is a column ([M, 1]: n[:, None], reshape(-1, 1), keepdims) and the other 1-D ([M]): their "
        "product broadcasts to an [M, M] table of every pair of pixels, whose sum is sum(ΔL) sum(n); keep both 1-D "
        "(np.ravel) so that ΔL * n pairs each pixel with itself":
            _threshold_column_times_row,
    })


# ---- exercise 3: the per-pixel offset that one APS frame fixes ---------------------------------

def anchor_first_offset(first_frame, L_t0, eps: float = FRAME_EPS) -> np.ndarray:
    """The per-pixel offset of ``anchor="first"``: what to add to the network's L at every time.

    Events fix only changes of log intensity; the first APS frame fixes the level, pixel by pixel:
    g = log(I0 + eps) - L(t0), so that L(t0) + g is the frame's log exactly and L(t) + g carries
    the frame forward by the network's changes.

    Args:
        first_frame: [H, W] the first APS frame, uint8 (0..255, divided by 255) or float in [0, 1].
        L_t0: float [H, W] the network's log intensity at the frame's time, before anchoring.
        eps: added to the intensity before the log (black pixels stay finite).
    Returns:
        float64 [H, W] offsets g (log units).
    """
    a = np.asarray(first_frame)
    intensity = a / 255.0 if a.dtype == np.uint8 else np.clip(np.asarray(a, np.float64), 0.0, 1.0)
    return np.log(intensity + eps) - np.asarray(L_t0, np.float64)


def _inputs_anchor(rng):
    cases = []
    # uint8 frames with black (0) and saturated (255) pixels: eps keeps log finite, / 255 puts them in [0, 1]
    img = rng.integers(0, 256, (6, 8)).astype(np.uint8)
    img[0, 0], img[0, 1], img[5, 7] = 0, 255, 0
    cases.append(dict(first_frame=img, L_t0=rng.normal(-1.0, 0.5, (6, 8))))
    cases.append(dict(first_frame=rng.integers(0, 256, (4, 5)).astype(np.uint8), L_t0=np.zeros((4, 5)), eps=0.01))
    # a float frame in [0, 1] (taken as it is) and a network far from the frame's level
    cases.append(dict(first_frame=rng.uniform(0, 1, (5, 3)), L_t0=rng.normal(2.0, 1.0, (5, 3))))
    return cases


def _offset_wrong_sign(first_frame, L_t0, eps=FRAME_EPS):
    return -anchor_first_offset(first_frame, L_t0, eps)


def _offset_no_scaling(first_frame, L_t0, eps=FRAME_EPS):
    return np.log(np.asarray(first_frame, np.float64) + eps) - np.asarray(L_t0, np.float64)


def _offset_eps_outside(first_frame, L_t0, eps=FRAME_EPS):
    a = np.asarray(first_frame)
    intensity = a / 255.0 if a.dtype == np.uint8 else np.asarray(a, np.float64)
    with np.errstate(divide="ignore"):
        return np.log(intensity) + eps - np.asarray(L_t0, np.float64)


def _offset_mean_only(first_frame, L_t0, eps=FRAME_EPS):
    g = anchor_first_offset(first_frame, L_t0, eps)
    return np.full_like(g, g.mean())


def _offset_float_divided(first_frame, L_t0, eps: float = FRAME_EPS):
    """The mistake of dividing every frame by 255, a float frame (already in [0, 1]) too."""
    return np.log(np.asarray(first_frame, np.float64) / 255.0 + eps) - np.asarray(L_t0, np.float64)


def _offset_default_eps(first_frame, L_t0, eps=FRAME_EPS):
    """The module's FRAME_EPS used whatever ``eps`` the caller passes."""
    return anchor_first_offset(first_frame, L_t0)


def _offset_over_256(first_frame, L_t0, eps=FRAME_EPS):
    a = np.asarray(first_frame)
    return anchor_first_offset(a / 256.0 if a.dtype == np.uint8 else a, L_t0, eps)


def _offset_log1p(first_frame, L_t0, eps=FRAME_EPS):
    return anchor_first_offset(first_frame, L_t0, 1.0)


def _offset_floor_division(first_frame, L_t0, eps=FRAME_EPS):
    a = np.asarray(first_frame)
    if a.dtype != np.uint8:
        return anchor_first_offset(a, L_t0, eps)
    return np.log((a // 255).astype(np.float64) + eps) - np.asarray(L_t0, np.float64)


def _offset_clipped_before_scaling(first_frame, L_t0, eps=FRAME_EPS):
    """np.clip(frame, 0, 1) on a uint8 frame before dividing by 255: every lit pixel becomes 1 / 255."""
    a = np.asarray(first_frame)
    clipped = np.clip(a, 0, 1)
    intensity = clipped / 255.0 if a.dtype == np.uint8 else np.asarray(clipped, np.float64)
    return np.log(intensity + eps) - np.asarray(L_t0, np.float64)


def _offset_exp_of_network(first_frame, L_t0, eps=FRAME_EPS):
    a = np.asarray(first_frame)
    intensity = a / 255.0 if a.dtype == np.uint8 else np.clip(np.asarray(a, np.float64), 0.0, 1.0)
    return np.log(intensity + eps) - np.exp(np.asarray(L_t0, np.float64))


def _offset_log10(first_frame, L_t0, eps=FRAME_EPS):
    a = np.asarray(first_frame)
    intensity = a / 255.0 if a.dtype == np.uint8 else np.clip(np.asarray(a, np.float64), 0.0, 1.0)
    return np.log10(intensity + eps) - np.asarray(L_t0, np.float64)


def _offset_dtype_tested_with_is(first_frame, L_t0, eps=FRAME_EPS):
    """`first_frame.dtype is np.uint8` is always False: a uint8 frame taken as a float one (clipped to [0, 1])."""
    a = np.asarray(first_frame)
    return np.log(np.clip(a.astype(np.float64), 0.0, 1.0) + eps) - np.asarray(L_t0, np.float64)


def _offset_eps_floor(first_frame, L_t0, eps=FRAME_EPS):
    """eps as a floor, log(max(I0, eps)), not added."""
    a = np.asarray(first_frame)
    intensity = a / 255.0 if a.dtype == np.uint8 else np.clip(np.asarray(a, np.float64), 0.0, 1.0)
    return np.log(np.maximum(intensity, eps)) - np.asarray(L_t0, np.float64)


def _offset_eps_twice(first_frame, L_t0, eps=FRAME_EPS):
    """eps added to the intensity and again inside the log."""
    a = np.asarray(first_frame)
    intensity = a / 255.0 if a.dtype == np.uint8 else np.clip(np.asarray(a, np.float64), 0.0, 1.0)
    return np.log(intensity + 2 * eps) - np.asarray(L_t0, np.float64)


exercises.register(
    "anchor_first_offset", anchor_first_offset, _inputs_anchor, rtol=1e-6, atol=1e-9,
    hints={
        "the offset is what to add to the network: g = log(I0 + eps) - L(t0), not L(t0) - log(I0 + eps)":
            _offset_wrong_sign,
        "a uint8 frame is 0..255: divide by 255 first, so that I0 is in [0, 1] as the solver's frames are":
            _offset_no_scaling,
        "eps goes inside the log, log(I0 + eps): log(I0) is -inf on a black pixel": _offset_eps_outside,
        "one offset per pixel, not one for the whole image: events never fix any pixel's level":
            _offset_mean_only,
        "divide by 255 only a uint8 frame (first_frame.dtype == np.uint8): a float frame is already in [0, 1]":
            _offset_float_divided,
        "use the `eps` argument the caller passes, not its default 1 / 255 written in the code":
            _offset_default_eps,
        "a uint8 frame's largest value is 255: divide by 255, not 256":
            _offset_over_256,
        "log intensities are natural logs (np.log), not base 10 (np.log10)":
            _offset_log10,
        "np.log1p(I) is log(1 + I): the offset needs log(I0 + eps) with the small `eps`, not 1":
            _offset_log1p,
        "`first_frame // 255` is integer division (0 for every pixel but the saturated ones): divide with `/`":
            _offset_floor_division,
        "clip to [0, 1] after dividing a uint8 frame by 255, not before: np.clip(frame, 0, 1) on 0..255 turns "
        "every lit pixel into 1 (then 1 / 255)":
            _offset_clipped_before_scaling,
        "L_t0 is already a log intensity: subtract it as it is, g = log(I0 + eps) - L_t0 (no np.exp)":
            _offset_exp_of_network,
        "compare dtypes with ==, not `is`: `first_frame.dtype is np.uint8` is always False (a dtype object is not "
        "the scalar type np.uint8), so the uint8 frame was taken as a float one; test `first_frame.dtype == "
        "np.uint8`":
            _offset_dtype_tested_with_is,
        "eps is added to the intensity, log(I0 + eps): a floor (np.maximum(I0, eps), np.clip(I0, eps, 1)) keeps "
        "the bright pixels' log(I0) without the eps, and the two differ on every pixel":
            _offset_eps_floor,
        "eps is added once, inside the log: log(I0 + eps) with I0 the frame in [0, 1] (no eps in I0 itself, then "
        "another in the log)":
            _offset_eps_twice,
    })
