"""Event frames (Eq. 2 of the paper): per-pixel sums of p*C over time bins.

Bin i holds the events with ``b[i] < t <= b[i+1]`` (bin 0 also holds events at exactly
``b[0]``), so that a model can compare F(b[i+1]) - F(b[i]) with exactly the events that
fired in between. Events outside [b[0], b[-1]] are not counted.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .events import EventDataError, Events

__all__ = ["EventFrames", "fixed_duration_boundaries", "equal_count_boundaries", "events_to_frames",
           "bisect_boundaries"]


@dataclass(frozen=True, eq=False)
class EventFrames:
    """Binned events.

    Attributes:
        frames: float32 [B, H, W], C * sum of polarities of the events in each bin.
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


def fixed_duration_boundaries(t_start: float, t_end: float, bin_duration: float = 1 / 32) -> np.ndarray:
    """Edges of consecutive bins of ``bin_duration`` seconds covering [t_start, t_end].

    The last bin is shortened to end exactly at ``t_end``. Returns float64 [B + 1].
    """
    if not (np.isfinite(t_start) and np.isfinite(t_end)) or t_end <= t_start:
        raise EventDataError(f"bin range [{t_start}, {t_end}] is empty or reversed; t_end must exceed t_start")
    if not bin_duration > 0:
        raise EventDataError(f"bin_duration must be positive seconds, got {bin_duration}")
    n = int(np.ceil((t_end - t_start) / bin_duration - 1e-9))
    edges = t_start + bin_duration * np.arange(n + 1, dtype=np.float64)
    edges[-1] = t_end
    return edges


def equal_count_boundaries(events: Events, events_per_bin: int | None = None, n_bins: int | None = None) -> np.ndarray:
    """Edges of bins holding (nearly) equal numbers of events, as the public reference code bins.

    Give exactly one of ``events_per_bin`` or ``n_bins``. Inner edges sit half-way between the
    last event of one bin and the first of the next; the outer edges are the first and last
    event times. Returns float64 [B + 1].
    """
    n = len(events)
    if n < 2:
        raise EventDataError(f"equal-count bins need at least 2 events, got {n}; choose a longer time window")
    if (events_per_bin is None) == (n_bins is None):
        raise EventDataError("give exactly one of events_per_bin or n_bins")
    if n_bins is None:
        if events_per_bin < 1:
            raise EventDataError(f"events_per_bin must be >= 1, got {events_per_bin}")
        n_bins = max(1, int(round(n / events_per_bin)))
    if not 1 <= n_bins <= n:
        raise EventDataError(f"n_bins must be between 1 and the number of events ({n}), got {n_bins}")
    # split index k: bin i holds events [k_i, k_{i+1})
    k = np.round(np.linspace(0, n, n_bins + 1)).astype(np.int64)
    t = events.t
    inner = 0.5 * (t[k[1:-1] - 1] + t[k[1:-1]])
    return np.concatenate([[t[0]], inner, [t[-1]]])


def events_to_frames(events: Events, boundaries, C: float = 1.0) -> EventFrames:
    """Sum p * C per pixel and bin (vectorised; no Python loop over events).

    Args:
        events: the events (sorted by time, as `Events` guarantees).
        boundaries: float64 [B + 1] increasing bin edges in seconds; see
            :func:`fixed_duration_boundaries` and :func:`equal_count_boundaries`.
        C: contrast threshold (log-intensity step per event).

    Returns:
        EventFrames with frames [B, H, W] float32, the boundaries and per-bin counts.
    """
    b = np.asarray(boundaries, dtype=np.float64)
    if b.ndim != 1 or b.size < 2:
        raise EventDataError(f"boundaries must be a 1-D array of at least 2 edges, got shape {b.shape}")
    if np.any(np.diff(b) <= 0):
        raise EventDataError("boundaries must be strictly increasing")
    H, W = events.sensor_size
    B = b.size - 1
    # bin index: b[i] < t <= b[i+1]  ->  searchsorted(left) - 1; t == b[0] joins bin 0
    lo = int(np.searchsorted(events.t, b[0], side="left"))
    hi = int(np.searchsorted(events.t, b[-1], side="right"))
    t = events.t[lo:hi]
    idx = np.searchsorted(b, t, side="left") - 1
    np.maximum(idx, 0, out=idx)
    flat = idx * (H * W) + events.y[lo:hi].astype(np.int64) * W + events.x[lo:hi]
    sums = np.bincount(flat, weights=events.p[lo:hi], minlength=B * H * W)
    frames = (C * sums).astype(np.float32).reshape(B, H, W)
    counts = np.bincount(idx, minlength=B).astype(np.int64)
    return EventFrames(frames=frames, boundaries=b, counts=counts)


def bisect_boundaries(events: Events, boundaries) -> np.ndarray:
    """Split every bin into two halves holding equal numbers of events (coarse-to-fine, Sec. 3.3).

    A bin (b_i, b_{i+1}] holding n >= 2 events is cut half-way between its event n//2 - 1 and
    event n//2 (0-based, in time order); a bin with fewer than 2 events, or whose cut would
    coincide with an edge, is cut at its time mid-point. Returns float64 [2B + 1].
    """
    b = np.asarray(boundaries, dtype=np.float64)
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
