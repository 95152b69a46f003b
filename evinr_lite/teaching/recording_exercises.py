"""Notebook 11 (your own recording): exercise references and helpers.

Exercises (registered with :mod:`evinr_lite.teaching.exercises` at import):

- ``estimate_contrast_threshold``: the least-squares C relating the log-intensity change of
  ground-truth frames to the net event count between them, ΔL ≈ C n (the reference is the
  library's :func:`evinr_lite.method.contrast.estimate_contrast_threshold`);
- ``event_count_windows``: cut a recording into windows of (nearly) equal event counts, so each
  reconstruction costs about the same and fits in memory.

Helpers: :func:`windows_from_indices` and :func:`window_table`. The recording to use comes from
:func:`evinr_lite.sim.recordings.find_recording`; ΔL and n between frame pairs from
:func:`evinr_lite.method.contrast.frame_log_changes`.
"""
from __future__ import annotations

import math

import numpy as np

from ..core.events import EventDataError, Events
from ..core.frames import Frames
from ..method.contrast import estimate_contrast_threshold
from . import exercises

__all__ = ["event_count_windows", "windows_from_indices", "window_table"]


# ---- exercise 1: the contrast threshold from frames ---------------------------------------

def _inputs_threshold(rng):
    cases = []
    for C, M, noise in ((0.3, 50, 0.05), (0.8, 200, 0.2), (0.15, 30, 0.0)):
        n = rng.integers(-4, 5, M)
        n[0] = 3                      # never all zero
        cases.append(dict(log_changes=C * n + noise * rng.standard_normal(M), net_counts=n))
    return cases


def _mean_of_ratios(log_changes, net_counts):
    d, n = np.asarray(log_changes, float), np.asarray(net_counts, float)
    keep = n != 0
    return float(np.mean(d[keep] / n[keep]))


exercises.register(
    "estimate_contrast_threshold", estimate_contrast_threshold, _inputs_threshold, rtol=1e-6,
    hints={
        "C multiplies n: the least-squares slope is sum(ΔL n) / sum(n^2), not sum(n^2) / sum(ΔL n)":
            lambda log_changes, net_counts: float(np.sum(np.square(np.asarray(net_counts, float)))
                                                  / np.sum(np.asarray(log_changes) * net_counts)),
        "a mean of per-pixel ratios ΔL / n weights noisy single-event pixels as much as the rest; "
        "fit the line through all pixels at once":
            _mean_of_ratios,
        "regressing n on ΔL gives sum(ΔL^2) / sum(ΔL n), biased by the noise in ΔL; regress ΔL on n":
            lambda log_changes, net_counts: float(np.sum(np.square(log_changes))
                                                  / np.sum(np.asarray(log_changes) * net_counts)),
    })


# ---- exercise 2: windows of equal event counts -----------------------------------------------

def event_count_windows(n_events: int, max_events: int) -> np.ndarray:
    """Split N events into the fewest windows of at most ``max_events`` events, as equal as possible.

    Args:
        n_events: N >= 1. max_events: the most events a window may hold (>= 1).
    Returns:
        int64 [w + 1] event indices: window k holds events idx[k] .. idx[k + 1] - 1, with
        w = ceil(N / max_events) and idx[k] = floor(k * N / w) (so idx[0] = 0, idx[w] = N).
    """
    w = max(1, math.ceil(n_events / max_events))
    return (np.arange(w + 1, dtype=np.int64) * n_events) // w


def _inputs_windows(rng):
    return [dict(n_events=10, max_events=3), dict(n_events=12, max_events=4), dict(n_events=7, max_events=100),
            dict(n_events=int(rng.integers(5000, 9000)), max_events=1000), dict(n_events=1, max_events=1)]


def _compare_windows(got, expected) -> str | None:
    got = np.asarray(got)
    if got.ndim != 1 or got.dtype.kind not in "iu":
        return f"expected a 1-D integer array of event indices, got {got.dtype} of shape {list(got.shape)}"
    if len(got) != len(expected):
        return (f"{len(got) - 1} windows, expected {len(expected) - 1}: the fewest windows of at most max_events "
                "events each")
    if not np.array_equal(got, expected):
        k = int(np.flatnonzero(got != expected)[0])
        return f"idx[{k}] = {got[k]}, expected {expected[k]}"
    return None


exercises.register(
    "event_count_windows", event_count_windows, _inputs_windows, compare=_compare_windows,
    hints={
        "use ceil(N / max_events) windows: with floor, some windows hold more than max_events":
            lambda n_events, max_events: (np.arange(max(1, n_events // max_events) + 1, dtype=np.int64) * n_events)
            // max(1, n_events // max_events),
        "the windows should be as equal as possible (idx[k] = floor(k N / w)), not max_events each with a "
        "short remainder":
            lambda n_events, max_events: np.append(np.arange(0, n_events, max_events, dtype=np.int64), n_events),
    })


def windows_from_indices(t, idx) -> list[tuple[float, float | None]]:
    """(start, end) seconds of the windows given by event indices ``idx`` [w + 1] (end None: to the
    last event), for ``load_recording(path, t_start=start, t_end=end)``."""
    t = np.asarray(t)
    idx = np.asarray(idx)
    if idx[0] != 0 or idx[-1] != len(t) or np.any(np.diff(idx) <= 0):
        raise EventDataError(f"window indices must rise strictly from 0 to {len(t)}, got {idx[:5]}...")
    return [(float(t[a]), float(t[b]) if b < len(t) else None) for a, b in zip(idx[:-1], idx[1:])]


def window_table(events: Events, frames: Frames | None, windows) -> list[dict]:
    """For each (start, end) window: duration, events, events per pixel, ground-truth frames inside."""
    H, W = events.sensor_size
    rows = []
    for k, (start, end) in enumerate(windows):
        stop = events.t[-1] if end is None else end
        n = int(np.searchsorted(events.t, stop, side="right" if end is None else "left")
                - np.searchsorted(events.t, start, side="left"))
        inside = 0 if frames is None else int(np.sum((frames.t >= start) & (frames.t <= stop)))
        rows.append({"window": k, "start_s": start, "end_s": float(stop), "duration_s": float(stop - start),
                     "events": n, "events_per_pixel": n / (H * W), "gt_frames": inside})
    return rows
