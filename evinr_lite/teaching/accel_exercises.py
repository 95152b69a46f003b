"""Making EvINR fast (paper Sec. 3.3, Tables 2-3): the pieces of notebook 06 and its exercises.

The reference solutions of the notebook's exercises live here and are registered with
:mod:`evinr_lite.teaching.exercises` at import:

- :func:`bisect_equal_count`: coarse-to-fine's step, every bin cut into two halves holding equal
  numbers of events (the same rule as :func:`evinr_lite.method.binning.bisect_boundaries`, on bare
  timestamps).
- :func:`crossfade_weights`: how an ensemble's predictions are mixed, linear ramps across each
  overlap (the same weights as the solver's ``blend_weights``).
- :func:`chain_offsets`: ensemble alignment, each network's per-pixel offset chained onto its
  predecessor's over their overlap (the same rule as the solver's ``alignment_offsets``, re-exported
  here; ``tests/test_accel_exercises.py`` pins the two together). :func:`overlap_predictions` gives
  its inputs from a trained model.

Helpers for the experiments:

- :func:`within_bin_detail`: the part of coarse-to-fine's loss jump at a bisection that comes from
  the events themselves (their change within each coarse bin).
- :class:`~evinr_lite.sim.scenes.VaryingSpeedScene` (re-exported here): a scene played at a speed that swings up and down, so that the event
  rate varies in time (equal-count bins then differ from equal-duration bins).
- :func:`ensemble_predictions`: an ensemble's log intensity with or without the offset alignment
  and with or without the cross-fade (a hard switch at the middle of each overlap).
- :func:`frame_change`: how fast the predicted frames change, per second, to see seams.
- Batched versus sequential training of N networks with identical initial weights:
  :func:`window_bins`, :func:`per_network_loss`, :func:`train_networks`, :func:`single_copies` and
  :func:`batched_vs_sequential` (used by ``benchmarks/ensemble_batching.py``).

Times are float64 seconds; windows are float64 [N, 2] (see :func:`evinr_lite.method.solver.split_windows`).
"""
from __future__ import annotations

import copy
import time

import numpy as np
import torch

from . import exercises
from ..method.binning import events_to_frames
from ..core.runtime import default_device
from ..core.events import Events
from ..method.losses import spatial_differences
from ..method.models import FrameINR
from ..sim.scenes import VaryingSpeedScene
from ..method.solver import alignment_offsets, blend_networks, predict_networks

__all__ = [
    "bisect_equal_count", "within_bin_detail", "crossfade_weights", "VaryingSpeedScene", "ensemble_predictions", "frame_change",
    "overlap_mask", "window_bins", "per_network_loss", "train_networks", "single_copies",
    "batched_vs_sequential", "chain_offsets", "overlap_predictions", "alignment_offsets", "predict_networks",
]


# ---- exercise 1: coarse-to-fine bisection -------------------------------------------------

def bisect_equal_count(t_events, boundaries) -> np.ndarray:
    """Cut every bin (b_i, b_{i+1}] into two halves holding equal numbers of events.

    A bin with n >= 2 events is cut half-way between its events n//2 - 1 and n//2 (0-based, in time
    order), so each half holds n//2 or n - n//2 of them. A bin with fewer than 2 events, or whose
    cut would land on one of its edges (events at equal times), is cut at its time mid-point.
    Bin 0 also holds events at exactly b_0 (the convention of :mod:`evinr_lite.method.binning`).

    Args:
        t_events: float [M] sorted event times (s).
        boundaries: float [B + 1] increasing bin edges (s).

    Returns:
        float64 [2B + 1]: the old edges at even positions, the cuts at odd positions.
    """
    t = np.asarray(t_events, dtype=np.float64)
    b = np.asarray(boundaries, dtype=np.float64)
    cuts = []
    for i, (lo, hi) in enumerate(zip(b[:-1], b[1:])):
        in_bin = t[((t > lo) | ((i == 0) & (t == lo))) & (t <= hi)]
        n = len(in_bin)
        cut = 0.5 * (lo + hi)                                   # too few events: the time mid-point
        if n >= 2:
            median = 0.5 * (in_bin[n // 2 - 1] + in_bin[n // 2])
            if lo < median < hi:
                cut = median
        cuts.append(cut)
    out = np.empty(2 * len(b) - 1)
    out[0::2] = b
    out[1::2] = cuts
    return out


def _inputs_bisect(rng):
    cases = []
    # a busy start and a quiet end; one bin with no event and one with a single event
    t = np.sort(np.concatenate([rng.uniform(0.0, 0.3, 40), rng.uniform(0.3, 1.0, 12)]))
    cases.append(dict(t_events=t, boundaries=np.linspace(0.0, 1.0, 5)))
    # and a burst of 8 events at b_0 = 0, more than half of bin 0's: the cut between its middle events would
    # land on the bin's first edge, so the bin is cut at its time mid-point (lo < median, not lo <= median)
    t = np.sort(np.concatenate([rng.uniform(0.0, 0.5, 9), [0.8], np.zeros(8)]))
    cases.append(dict(t_events=t, boundaries=np.array([0.0, 0.25, 0.5, 0.75, 1.0])))
    t = np.sort(rng.uniform(0.0, 2.0, 101))
    # bins that start at b_0 = 0.0625, not at 0, with an event exactly there: bin 0 holds it (`t == b_0`, not
    # `t == 0`), and the events before it belong to no bin. 0.0625 is exact in float32 too
    b = np.concatenate([[0.0625], np.sort(rng.uniform(0.1, 1.9, 6)), [2.0]])
    t[np.searchsorted(t, b[0]) - 1] = b[0]
    cases.append(dict(t_events=t, boundaries=b))
    # the boundary rule: events exactly on the edges. Those at b_1 = 1.25 and b_2 = 2.25 belong to the bin that
    # ends there, the one at b_0 = 0.25 to bin 0; a half-open [b_i, b_{i+1}) or a strict t < b_{i+1} moves them.
    # Bin (1.25, 2.25] holds 1.75 and three events at 2.25: its cut between events 1 and 2 would land on the
    # edge 2.25, so the bin is cut at its time mid-point instead. The times start at 0.25, not 0 (exact in
    # binary, so the equalities hold): bin 0's closed left edge is t == b_0, and its 5 events (an odd count)
    # put the cut elsewhere when the event at b_0 is left out (`t == 0` in place of `t == b_0`). The last bin
    # (2.25, 3.25] holds 2.75, 3.0, 3.15 and one event exactly at its end b_B = 3.25: 4 events cut at 3.075; a
    # last bin open at its end (t < b_B) leaves 3 and cuts at 2.875
    cases.append(dict(t_events=np.array([0.0, 0.2, 0.6, 1.0, 1.0, 1.5, 2.0, 2.0, 2.0, 2.5, 2.75, 2.9, 3.0]) + 0.25,
                      boundaries=np.array([0.0, 1.0, 2.0, 3.0]) + 0.25))
    return cases


def _midpoints(t_events, boundaries):
    b = np.asarray(boundaries, dtype=np.float64)
    out = np.empty(2 * len(b) - 1)
    out[0::2] = b
    out[1::2] = 0.5 * (b[:-1] + b[1:])
    return out


def _cut_at_mean(t_events, boundaries):
    t = np.asarray(t_events, dtype=np.float64)
    out = _midpoints(t, boundaries)
    for i, (lo, hi) in enumerate(zip(out[0:-1:2], out[2::2])):
        in_bin = t[(t > lo) & (t <= hi)]
        if len(in_bin) >= 2:
            out[2 * i + 1] = in_bin.mean()
    return out


def _cut_at_event(t_events, boundaries):
    t = np.asarray(t_events, dtype=np.float64)
    out = _midpoints(t, boundaries)
    for i, (lo, hi) in enumerate(zip(out[0:-1:2], out[2::2])):
        in_bin = t[(t > lo) & (t <= hi)]
        if len(in_bin) >= 2:
            out[2 * i + 1] = in_bin[len(in_bin) // 2]
    return out


def _median_cuts(t_events, boundaries, in_bin):
    """The reference's cut with another membership rule (the wrong versions below): ``in_bin(t, i, lo, hi)``
    -> bool mask of bin i's events."""
    t = np.asarray(t_events, dtype=np.float64)
    out = _midpoints(t, boundaries)
    for i, (lo, hi) in enumerate(zip(out[0:-1:2], out[2::2])):
        inside = t[in_bin(t, i, lo, hi)]
        n = len(inside)
        if n >= 2 and lo < 0.5 * (inside[n // 2 - 1] + inside[n // 2]) < hi:
            out[2 * i + 1] = 0.5 * (inside[n // 2 - 1] + inside[n // 2])
    return out


def _left_closed_bins(t_events, boundaries):
    """The mistake of bins [b_i, b_{i+1}) (searchsorted side='left' at both ends, or t < b_{i+1})."""
    return _median_cuts(t_events, boundaries, lambda t, i, lo, hi: (t >= lo) & (t < hi))


def _cut_on_first_edge(t_events, boundaries):
    """The mistake of a cut allowed on the bin's first edge (lo <= median): a burst at b_0 makes an empty half."""
    t = np.asarray(t_events, dtype=np.float64)
    out = _midpoints(t, boundaries)
    for i, (lo, hi) in enumerate(zip(out[0:-1:2], out[2::2])):
        inside = t[((t > lo) | ((i == 0) & (t == lo))) & (t <= hi)]
        n = len(inside)
        if n >= 2 and lo <= 0.5 * (inside[n // 2 - 1] + inside[n // 2]) < hi:
            out[2 * i + 1] = 0.5 * (inside[n // 2 - 1] + inside[n // 2])
    return out


def _first_edge_at_zero(t_events, boundaries):
    """The mistake of bin 0's closed left edge written as `t == 0`: right only when b_0 = 0."""
    return _median_cuts(t_events, boundaries, lambda t, i, lo, hi: ((t > lo) | ((i == 0) & (t == 0))) & (t <= hi))


def _bisect_np_median(t_events, boundaries):
    """np.median of the bin's events: for an odd count, that is the middle event itself."""
    t = np.asarray(t_events, dtype=np.float64)
    b = np.asarray(boundaries, dtype=np.float64)
    out = [b[0]]
    for i, (lo, hi) in enumerate(zip(b[:-1], b[1:])):
        in_bin = t[((t > lo) | ((i == 0) & (t == lo))) & (t <= hi)]
        cut = 0.5 * (lo + hi)
        if len(in_bin) >= 2 and lo < np.median(in_bin) < hi:
            cut = np.median(in_bin)
        out += [cut, hi]
    return np.array(out)


def _bisect_sparse_at_edge(t_events, boundaries):
    out = bisect_equal_count(t_events, boundaries)
    t, b = np.asarray(t_events, dtype=np.float64), np.asarray(boundaries, dtype=np.float64)
    for i, (lo, hi) in enumerate(zip(b[:-1], b[1:])):
        if np.count_nonzero(((t > lo) | ((i == 0) & (t == lo))) & (t <= hi)) < 2:
            out[2 * i + 1] = lo
    return out


def _bisect_closed_both(t_events, boundaries):
    return _median_cuts(t_events, boundaries, lambda t, i, lo, hi: (t >= lo) & (t <= hi))


def _bisect_cuts_only(t_events, boundaries):
    return bisect_equal_count(t_events, boundaries)[1::2]


def _bisect_edges_then_cuts(t_events, boundaries):
    out = bisect_equal_count(t_events, boundaries)
    return np.concatenate([out[0::2], out[1::2]])


def _bisect_round_half(t_events, boundaries):
    """The middle taken as round(n / 2): Python rounds halves to even, so for n = 3, 7, 11, ... it is n // 2 + 1."""
    t = np.asarray(t_events, dtype=np.float64)
    b = np.asarray(boundaries, dtype=np.float64)
    out = bisect_equal_count(t, b)
    for i, (lo, hi) in enumerate(zip(b[:-1], b[1:])):
        s = t[((t > lo) | ((i == 0) & (t == lo))) & (t <= hi)]
        if len(s) >= 2:
            m = round(len(s) / 2)
            cut = 0.5 * (s[m - 1] + s[m]) if m < len(s) else 0.5 * (lo + hi)
            out[2 * i + 1] = cut if lo < cut < hi else 0.5 * (lo + hi)
    return out


def _last_bin_open(t_events, boundaries):
    """The last bin open at its end: an event exactly at b_B left out."""
    t = np.asarray(t_events, dtype=np.float64)
    b = np.asarray(boundaries, dtype=np.float64)
    return bisect_equal_count(t[t < b[-1]], b)


exercises.register(
    "bisect_equal_count", bisect_equal_count, _inputs_bisect,
    hints={
        "an event exactly on an edge b_{i+1} belongs to bin i, which ends there: bins are (b_i, b_{i+1}] "
        "(t > b_i and t <= b_{i+1}; bin 0 also holds t == b_0), not [b_i, b_{i+1})": _left_closed_bins,
        "you cut every bin at its time mid-point: that halves the duration, not the number of events; "
        "cut between the two middle events instead": _midpoints,
        "you cut at the mean event time; equal counts need the median (half-way between events "
        "n//2 - 1 and n//2)": _cut_at_mean,
        "you cut exactly at event n//2; cut half-way between events n//2 - 1 and n//2, so that no event "
        "sits on an edge": _cut_at_event,
        "bin 0 takes the events at exactly b_0 = boundaries[0], which need not be 0: test `t == b_0`, "
        "not `t == 0`": _first_edge_at_zero,
        "a cut on the bin's first edge leaves its first half empty (a burst of events at b_0): when the "
        "middle events sit on an edge, cut at the time mid-point (test lo < median < hi)": _cut_on_first_edge,
        "np.median of an odd number of events is the middle event itself; cut half-way between events n//2 - "
        "1 and n//2 (0-based) whatever n":
            _bisect_np_median,
        "return the old edges too, the cuts between them: [b_0, cut_0, b_1, cut_1, ..., b_B] (2B + 1 values)":
            _bisect_cuts_only,
        "a bin with fewer than 2 events is cut at its time mid-point (lo + hi) / 2, not at its first edge":
            _bisect_sparse_at_edge,
        "bins are (b_i, b_{i+1}], open on the left: with both ends closed an event exactly on an inner edge "
        "counts in two bins":
            _bisect_closed_both,
        "interleave the edges and the cuts, [b_0, cut_0, b_1, cut_1, ..., b_B] (in time order), not all the edges "
        "followed by all the cuts (np.concatenate([b, cuts])); out[0::2] = b, out[1::2] = cuts":
            _bisect_edges_then_cuts,
        "an event exactly at the last edge b_B belongs to the last bin (b_{B-1}, b_B]: the bins are closed at their "
        "end, the last one too (no strict t < b_B)": _last_bin_open,
        "round(n / 2) is not n // 2: Python (and np.round) round a half to the even neighbour, so round(3.5) is 4 "
        "and round(2.5) is 2, and for n = 3, 7, 11, ... events the cut moves one event up; take the integer "
        "division n // 2":
            _bisect_round_half,
    })


# ---- coarse-to-fine: what the loss does at a bisection ----------------------------------------

def within_bin_detail(events: Events, coarse, fine, C: float) -> float:
    """The per-bin temporal loss, on the halves ``fine`` of the bins ``coarse``, of a model that fits
    every coarse bin exactly with a constant slope inside it: mean over halves and pixels of
    (E_half - E_bin / 2)^2 (log units squared).

    It measures the change *within* each coarse bin that the coarse stage could not see. Right after
    a bisection, a trained network's loss on the halves exceeds this by whatever it does between
    the old bin mid-points, where the derivative loss never constrained it.

    Args:
        events: the events. coarse: float [B + 1] bin edges (s). fine: float [2B + 1], the coarse edges
            at even positions and one cut inside each bin (e.g. :func:`bisect_equal_count`). C: threshold.
    """
    coarse, fine = np.asarray(coarse, dtype=np.float64), np.asarray(fine, dtype=np.float64)
    if fine.shape != (2 * len(coarse) - 1,) or not np.array_equal(fine[0::2], coarse):
        raise ValueError(f"fine ({fine.shape[0]} edges) must hold the {len(coarse)} coarse edges at even positions "
                         "and one cut inside each bin: pass the output of a bisection of coarse")
    E0 = events_to_frames(events, coarse, C).frames.astype(np.float64)
    E1 = events_to_frames(events, fine, C).frames.astype(np.float64)
    return float(((E1 - np.repeat(E0 / 2, 2, axis=0)) ** 2).mean())


# ---- exercise 2: cross-fade weights ---------------------------------------------------------

def crossfade_weights(windows, times) -> np.ndarray:
    """Blend weights [N, Q] of N overlapping windows at the query times.

    Over the overlap of windows k-1 and k, window k's weight rises linearly from 0 at its start
    (windows[k, 0]) to 1 at the end of window k-1 (windows[k-1, 1]), and window k-1's weight falls
    from 1 to 0; elsewhere the one window that covers t has weight 1, and a window that does not
    cover t has weight 0. The first window does not fade in, nor the last fade out. Columns sum to 1.

    Args:
        windows: float [N, 2] seconds, equal overlaps between neighbours (as split_windows makes them).
        times: float [Q] seconds inside [windows[0, 0], windows[-1, 1]].

    Returns:
        float64 [N, Q].
    """
    windows = np.asarray(windows, dtype=np.float64)
    t = np.asarray(times, dtype=np.float64)
    if len(windows) == 1:
        return np.ones((1, len(t)))
    lo, hi = windows[:, :1], windows[:, 1:]
    overlap = windows[0, 1] - windows[1, 0]
    fade_in = np.clip((t - lo) / overlap, 0.0, 1.0)
    fade_out = np.clip((hi - t) / overlap, 0.0, 1.0)
    fade_in[0] = 1.0                      # the sequence starts inside window 0
    fade_out[-1] = 1.0                    # and ends inside the last window
    w = np.minimum(fade_in, fade_out)
    return w / w.sum(axis=0, keepdims=True)


def _inputs_crossfade(rng):
    from ..method.solver import split_windows

    cases = []
    # the first sequence starts at 1.5 s, not 0: windows and times are absolute (a version that builds the
    # windows from 0, or shifts the caller's windows in place, fails)
    for start, span, tau, overlap in ((1.5, 3.0, 1.2, 0.3), (0.0, 6.0, 2.2, 0.5), (0.0, 2.0, 1.1, 0.1)):
        w = split_windows(start, start + span, tau, overlap)
        edges = np.concatenate([w.ravel(), 0.5 * (w[1:, 0] + w[:-1, 1])])
        t = np.sort(np.concatenate([edges, rng.uniform(start, start + span, 9)]))
        cases.append(dict(windows=w, times=t))
    cases.append(dict(windows=np.array([[0.0, 1.0]]), times=np.array([0.0, 0.3, 1.0])))
    return cases


def _hard_switch_weights(windows, times):
    windows = np.asarray(windows, dtype=np.float64)
    t = np.asarray(times, dtype=np.float64)
    centres = 0.5 * (windows[1:, 0] + windows[:-1, 1])
    k = np.searchsorted(centres, t)
    w = np.zeros((len(windows), len(t)))
    w[k, np.arange(len(t))] = 1.0
    return w


def _fades_at_both_ends(windows, times):
    windows = np.asarray(windows, dtype=np.float64)
    t = np.asarray(times, dtype=np.float64)
    if len(windows) == 1:
        return np.ones((1, len(t)))
    overlap = windows[0, 1] - windows[1, 0]
    w = np.minimum(np.clip((t - windows[:, :1]) / overlap, 0, 1), np.clip((windows[:, 1:] - t) / overlap, 0, 1))
    with np.errstate(invalid="ignore", divide="ignore"):
        return w / w.sum(axis=0, keepdims=True)


def _not_normalised(windows, times):
    windows = np.asarray(windows, dtype=np.float64)
    t = np.asarray(times, dtype=np.float64)
    return ((t >= windows[:, :1]) & (t <= windows[:, 1:])).astype(np.float64)


def _windows_from_zero(windows, times):
    """The windows rebuilt from their length and step as if the sequence started at 0 (k * step, k * step + tau)."""
    windows = np.asarray(windows, dtype=np.float64)
    if len(windows) == 1:
        return np.ones((1, len(np.asarray(times))))
    tau, step = windows[0, 1] - windows[0, 0], windows[1, 0] - windows[0, 0]
    lo = step * np.arange(len(windows))
    return crossfade_weights(np.stack([lo, lo + tau], axis=1), times)


def _normalised_over_times(windows, times):
    """The ramps divided by their sums over the times (axis 1) instead of over the windows (axis 0)."""
    windows = np.asarray(windows, dtype=np.float64)
    t = np.asarray(times, dtype=np.float64)
    if len(windows) == 1:
        return np.ones((1, len(t)))
    overlap = windows[0, 1] - windows[1, 0]
    fade_in = np.clip((t - windows[:, :1]) / overlap, 0.0, 1.0)
    fade_out = np.clip((windows[:, 1:] - t) / overlap, 0.0, 1.0)
    fade_in[0], fade_out[-1] = 1.0, 1.0
    w = np.minimum(fade_in, fade_out)
    return w / w.sum(axis=1, keepdims=True)


def _crossfade_over_max(windows, times):
    """A wrong version (for the hint): the ramps divided by their column's largest weight, not its sum (a column's
    scale cancels, so the reference's weights over their maximum are the ramps over theirs)."""
    w = crossfade_weights(windows, times)
    return w / w.max(axis=0, keepdims=True)


exercises.register(
    "crossfade_weights", crossfade_weights, _inputs_crossfade, atol=1e-5,
    hints={
        "the weights of a column sum to 1: divide by the column's sum (w / w.sum(axis=0)), not by its largest "
        "weight":
            _crossfade_over_max,
        "these are hard switches (0 or 1); ramp the weights linearly across each overlap": _hard_switch_weights,
        "the first window must not fade in at the start of the sequence, nor the last fade out at its end "
        "(there is no neighbour to hand over to)": _fades_at_both_ends,
        "every window covering t has weight 1: the weights of each time must sum to 1": _not_normalised,
        "read each window's start and end from `windows` (absolute times): the sequence need not start at 0":
            _windows_from_zero,
        "normalise over the windows, w / w.sum(axis=0): each time's weights (a column of [N, Q]) sum to 1; "
        "w.sum(axis=1) adds one window's weights over all the times":
            _normalised_over_times,
    })


# ---- ensemble alignment ----------------------------------------------------------------------

def chain_offsets(prev, nxt) -> np.ndarray:
    """Per-network, per-pixel offsets that chain every network onto its predecessor.

    Args:
        prev, nxt: float [K, S, H, W]: for each overlap k = 1..K, network k-1 (``prev[k-1]``) and
            network k (``nxt[k-1]``) at the same S sample times inside their overlap (K = N - 1;
            K = 0 for a single network).

    Returns:
        float64 [K + 1, H, W]: offset_0 = 0 and offset_k = offset_{k-1} + mean over the S samples of
        (F_{k-1} - F_k), so that network k plus its offset agrees on average with network k-1 plus
        its own over their overlap.
    """
    prev = np.asarray(prev, dtype=np.float64)
    nxt = np.asarray(nxt, dtype=np.float64)
    steps = (prev - nxt).mean(axis=1)                                  # [K, H, W]
    return np.concatenate([np.zeros((1,) + prev.shape[2:]), np.cumsum(steps, axis=0)])


def overlap_predictions(model, windows, n_samples: int = 8):
    """(prev, nxt) float32 [N - 1, n_samples, H, W]: networks k-1 and k at the sample times of overlap k
    (``n_samples`` evenly spaced, both ends included), the inputs of :func:`chain_offsets`."""
    windows = np.asarray(windows, dtype=np.float64)
    H, W = model.sensor_size
    prev = np.zeros((len(windows) - 1, n_samples, H, W), np.float32)
    nxt = np.zeros_like(prev)
    for k in range(1, len(windows)):
        F = predict_networks(model, np.linspace(windows[k, 0], windows[k - 1, 1], n_samples))
        prev[k - 1], nxt[k - 1] = F[k - 1], F[k]
    return prev, nxt


def _inputs_chain(rng):
    cases = []
    for K, S, shape in ((3, 4, (2, 3)), (1, 8, (3, 2)), (4, 1, (2, 2))):   # S = 1: a single sample
        prev = rng.normal(size=(K, S) + shape)
        # each overlap: one offset apart, plus a disagreement that varies from sample to sample (so that the
        # mean over the samples differs from one sample's difference or their median)
        nxt = prev + rng.normal(size=(K, 1) + shape) + 0.3 * rng.exponential(size=(K, S) + shape)
        cases.append(dict(prev=prev, nxt=nxt))
    prev = rng.normal(size=(2, 3, 2, 2))
    cases.append(dict(prev=prev, nxt=prev.copy()))                     # networks that already agree: offsets 0
    cases.append(dict(prev=np.zeros((0, 5, 2, 3)), nxt=np.zeros((0, 5, 2, 3))))   # one network, no overlap
    return cases


def _not_chained(prev, nxt):
    prev, nxt = np.asarray(prev, dtype=np.float64), np.asarray(nxt, dtype=np.float64)
    return np.concatenate([np.zeros((1,) + prev.shape[2:]), (prev - nxt).mean(axis=1)])


def _next_minus_prev(prev, nxt):
    return chain_offsets(nxt, prev)


def _no_leading_zero(prev, nxt):
    return chain_offsets(prev, nxt)[1:]


def _chain_mean_over_overlaps(prev, nxt):
    prev = np.asarray(prev, dtype=np.float64)
    nxt = np.asarray(nxt, dtype=np.float64)
    steps = (prev - nxt).mean(axis=0)
    return np.concatenate([np.zeros((1,) + prev.shape[2:]), np.cumsum(steps, axis=0)])


def _chain_median(prev, nxt):
    steps = np.median(np.asarray(prev, dtype=np.float64) - np.asarray(nxt, dtype=np.float64), axis=1)
    return np.concatenate([np.zeros((1,) + np.shape(prev)[2:]), np.cumsum(steps, axis=0)])


def _chain_first_sample(prev, nxt):
    return chain_offsets(np.asarray(prev)[:, :1], np.asarray(nxt)[:, :1])


def _chain_last_left_at_zero(prev, nxt):
    out = chain_offsets(prev, nxt)
    if len(out) > 1:
        out[-1] = 0.0
    return out


def _chain_cumsum_flat(prev, nxt):
    prev = np.asarray(prev, dtype=np.float64)
    nxt = np.asarray(nxt, dtype=np.float64)
    steps = (prev - nxt).mean(axis=1)
    return np.concatenate([np.zeros((1,) + prev.shape[2:]), np.cumsum(steps).reshape(steps.shape)])


def _chain_steps_before(prev, nxt):
    """offset_k = the sum of the steps of the overlaps before k only (an exclusive running sum): one step short."""
    out = chain_offsets(prev, nxt)
    return np.concatenate([out[:1], out[:-1]])


def _chain_floor_division(prev, nxt):
    """The mean over the samples as sum // S: floor division rounds every step down to a whole number."""
    prev, nxt = np.asarray(prev, dtype=np.float64), np.asarray(nxt, dtype=np.float64)
    steps = (prev - nxt).sum(axis=1) // prev.shape[1]
    return np.concatenate([np.zeros((1,) + prev.shape[2:]), np.cumsum(steps, axis=0)])


def _chain_len_divisor(prev, nxt):
    """The sum over the samples divided by len(prev), the number of overlaps K, not the samples S."""
    prev, nxt = np.asarray(prev, dtype=np.float64), np.asarray(nxt, dtype=np.float64)
    steps = (prev - nxt).sum(axis=1) / max(len(prev), 1)
    return np.concatenate([np.zeros((1,) + prev.shape[2:]), np.cumsum(steps, axis=0)])


exercises.register(
    "chain_offsets", chain_offsets, _inputs_chain, atol=1e-9,
    hints={
        "chain the offsets: offset_k = offset_{k-1} + mean(F_{k-1} - F_k) (np.cumsum over the overlaps), "
        "not each overlap's difference on its own": _not_chained,
        "the offset moves network k onto network k-1: mean(F_{k-1} - F_k), not F_k - F_{k-1}": _next_minus_prev,
        "network 0 keeps offset 0: return K + 1 offsets, the first one zero": _no_leading_zero,
        "average over the S samples, axis 1 of [K, S, H, W], not over the K overlaps (axis 0)":
            _chain_mean_over_overlaps,
        "np.cumsum without axis= runs over the flattened array (across pixels): use np.cumsum(steps, axis=0)":
            _chain_cumsum_flat,
        "average the differences over the S samples with the mean, not the median":
            _chain_median,
        "use all S samples of each overlap (the mean over axis 1), not only the first one":
            _chain_first_sample,
        "every network gets an offset, the last one too: offset_k for k = 1 .. K (a loop over range(1, K + 1), "
        "or np.cumsum over all K steps), not range(1, K)":
            _chain_last_left_at_zero,
        "offset_k includes overlap k's own step: offset_k = offset_{k-1} + mean(F_{k-1} - F_k), so offset_1 is the "
        "first step (np.cumsum(steps, axis=0) after the leading 0), not the sum of the steps before it":
            _chain_steps_before,
        "len(prev) is K, the number of overlaps (the first axis): the mean over the S samples divides by "
        "prev.shape[1] (or use .mean(axis=1))":
            _chain_len_divisor,
        "`//` is floor division, also on float arrays: the sum over the S samples // S rounds each step down to a "
        "whole number; divide with `/`, or take .mean(axis=1)":
            _chain_floor_division,
    })


# ---- a scene whose event rate varies --------------------------------------------------------

# ---- seams ----------------------------------------------------------------------------------

def ensemble_predictions(rec, times, *, align: bool = True, crossfade: bool = True) -> np.ndarray:
    """Log intensity [Q, H, W] of a Reconstruction's networks, mixed four ways.

    align: add the alignment offsets (``rec.offsets``); otherwise every network gets network 0's
        offset (the global brightness anchor only), i.e. the raw networks.
    crossfade: linear ramps across the overlaps (what ``reconstruct`` does); otherwise a hard switch
        from network k-1 to k at the middle of their overlap.
    """
    times = np.atleast_1d(np.asarray(times, dtype=np.float64))
    offsets = rec.offsets if align else np.broadcast_to(rec.offsets[:1], rec.offsets.shape).copy()
    if crossfade:
        return blend_networks(rec.model, rec.windows, times, offsets)
    centres = 0.5 * (rec.windows[1:, 0] + rec.windows[:-1, 1])
    k = np.searchsorted(centres, times)
    F = predict_networks(rec.model, times)                                   # [N, Q, H, W]
    return (F[k, np.arange(len(times))] + offsets[k]).astype(np.float32)


def frame_change(L, times) -> np.ndarray:
    """Mean |dL/dt| between consecutive frames, [Q - 1] (log units per second), at the mid-times."""
    L = np.asarray(L, dtype=np.float64)
    return np.abs(np.diff(L, axis=0)).mean(axis=(1, 2)) / np.diff(np.asarray(times, dtype=np.float64))


def overlap_mask(windows, times) -> np.ndarray:
    """bool [Q]: the times that lie inside an overlap of two neighbouring windows."""
    windows = np.asarray(windows, dtype=np.float64)
    t = np.asarray(times, dtype=np.float64)
    mask = np.zeros(t.shape, bool)
    for k in range(1, len(windows)):
        mask |= (t > windows[k, 0]) & (t < windows[k - 1, 1])
    return mask


# ---- batched versus sequential training -----------------------------------------------------

def window_bins(events: Events, windows, bin_duration: float, C: float, device=None) -> dict:
    """Equal-duration bins of about ``bin_duration`` s in every window, the same number per window.

    Returns a dict of tensors on ``device``: "centers" float64 [N, B] (s), "durations" float32 [N, B]
    (s) and "frames" float32 [N, B, H, W] (C times the summed polarities per pixel and bin).
    """
    windows = np.asarray(windows, dtype=np.float64)
    n_bins = max(1, int(round((windows[0, 1] - windows[0, 0]) / bin_duration)))
    edges = [np.linspace(lo, hi, n_bins + 1) for lo, hi in windows]
    frames = np.stack([events_to_frames(events, e, C).frames for e in edges])
    b = np.stack(edges)
    device = default_device(None) if device is None else torch.device(device)
    return {"centers": torch.as_tensor(0.5 * (b[:, 1:] + b[:, :-1]), device=device),
            "durations": torch.as_tensor(np.diff(b, axis=1), dtype=torch.float32, device=device),
            "frames": torch.as_tensor(frames, device=device)}


def _take(bins: dict, k: int) -> dict:
    return {name: v[k:k + 1] for name, v in bins.items()}


def per_network_loss(model: FrameINR, bins: dict, lam: float = 0.05) -> torch.Tensor:
    """Each network's loss, [N]: temporal (Eq. 5-6, derivative form) + lam * Tikhonov (Eq. 9).

    Averaged within a network and never across networks, so that network k's gradient is the same
    whether it is trained alone or inside a batch (the sum of these is what the batch minimises).
    """
    F, dF = model.forward_with_derivative(bins["centers"])
    temporal = ((bins["frames"] - dF * bins["durations"][..., None, None]) ** 2).mean(dim=(1, 2, 3))
    dx, dy = spatial_differences(F)
    return temporal + lam * ((dx ** 2).mean(dim=(1, 2, 3)) + (dy ** 2).mean(dim=(1, 2, 3)))


def train_networks(model: FrameINR, bins: dict, n_iters: int, *, lr: float = 1e-4, head_lr_scale: float = 30.0,
                   lam: float = 0.05) -> float:
    """Train ``model`` (all its networks at once) for n_iters Adam steps in place; returns seconds.

    The optimiser is the solver's (Adam, head learning rate x head_lr_scale), without the schedule.
    """
    head = [model.head_weight, model.head_bias]
    trunk = [p for name, p in model.named_parameters() if not name.startswith("head_")]
    opt = torch.optim.Adam([{"params": trunk}, {"params": head, "lr": lr * head_lr_scale}], lr=lr)
    t0 = time.perf_counter()
    for _ in range(n_iters):
        loss = per_network_loss(model, bins, lam).sum()
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()
    if bins["frames"].is_cuda:
        torch.cuda.synchronize()
    return time.perf_counter() - t0


def single_copies(model: FrameINR) -> list[FrameINR]:
    """N one-network FrameINRs holding exactly the weights of ``model``'s N networks (copies)."""
    d = model.weights[0].shape[-1]
    out = []
    for k in range(model.n_models):
        single = FrameINR(model.sensor_size, model.windows[k:k + 1].cpu().numpy(), d, len(model.weights) - 1,
                          model.omega_0, model.first_omega_0)
        single.load_state_dict({name: v[k:k + 1].clone() for name, v in model.state_dict().items()})
        out.append(single.to(model.head_weight.device))
    return out


def batched_vs_sequential(events: Events, windows, *, hidden_features: int = 64, hidden_layers: int = 2,
                          n_iters: int = 30, bin_duration: float = 1 / 32, C: float = 0.2, lam: float = 0.05,
                          repeats: int = 2, seed: int = 0, device=None) -> dict:
    """Train N networks (one per window) in one batched pass, and the same N one after another.

    Both start from identical weights (the sequential networks are :func:`single_copies` of the
    batched model's initial weights) and do the same work: N networks x n_iters steps on the same
    bins. The two timings alternate ``repeats`` times after a short warm-up (which one goes first
    alternates too); the fastest of each is kept, so both see the same machine load as far as possible.

    Returns:
        dict with "n_models", "batched_s", "sequential_s", "ratio" (sequential / batched),
        "max_abs_diff" (largest difference of the trained predictions at the bin centres, log
        units), "pred_scale" (their standard deviation) and "n_parameters" (all N networks).
    """
    device = default_device(None) if device is None else torch.device(device)
    windows = np.asarray(windows, dtype=np.float64)
    bins = window_bins(events, windows, bin_duration, C, device)
    init = FrameINR(events.sensor_size, windows, hidden_features, hidden_layers, 30.0, 10.0, seed=seed).to(device)
    # warm-up: the first steps allocate memory and pick kernels
    train_networks(copy.deepcopy(init), bins, 2, lam=lam)
    train_networks(single_copies(init)[0], _take(bins, 0), 2, lam=lam)
    batched_s, sequential_s = [], []
    for r in range(max(1, repeats)):
        batched, singles = copy.deepcopy(init), single_copies(init)
        order = ("batched", "sequential") if r % 2 == 0 else ("sequential", "batched")   # which goes first alternates
        for which in order:
            if which == "batched":
                batched_s.append(train_networks(batched, bins, n_iters, lam=lam))
            else:
                sequential_s.append(sum(train_networks(m, _take(bins, k), n_iters, lam=lam)
                                        for k, m in enumerate(singles)))
    with torch.no_grad():
        F_batched = batched(bins["centers"])
        F_single = torch.cat([m(bins["centers"][k:k + 1]) for k, m in enumerate(singles)])
    return {"n_models": len(windows), "batched_s": min(batched_s), "sequential_s": min(sequential_s),
            "ratio": min(sequential_s) / min(batched_s),
            "max_abs_diff": float((F_batched - F_single).abs().max()),
            "pred_scale": float(F_batched.std()), "n_parameters": init.num_parameters()}
