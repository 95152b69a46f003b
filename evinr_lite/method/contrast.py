"""The contrast threshold C fitted from a recording's frames: ΔL ≈ C n between consecutive frames.

Events fire each time a pixel's log intensity moves by C, so over the interval between two APS
frames the net event count n (ON minus OFF) and the frames' log change ΔL satisfy ΔL ≈ C n on
well-exposed pixels. :func:`frame_log_changes` collects (ΔL, n) pairs and
:func:`estimate_contrast_threshold` fits C by least squares (notebooks 09 and 11).
"""
from __future__ import annotations

import numpy as np

from ..core.events import EventDataError, Events
from ..core.frames import Frames
from .binning import events_to_frames

__all__ = ["frame_log_changes", "estimate_contrast_threshold"]


def frame_log_changes(frames: Frames, events: Events, *, eps: float = 1 / 255, exposed=(0.05, 0.95)):
    """Log-intensity changes between consecutive frames and the net event counts between them.

    Only frame pairs whose whole interval is covered by events are used (the first and last
    frames often lie outside the event stream).

    Args:
        frames: ground-truth frames (uint8 or [0, 1]), on the events' clock.
        eps: added to intensities in [0, 1] before the log (dark pixels).
        exposed: (low, high) intensities; pixels outside this range in either frame are masked
            (dark noise and saturation break ΔL = C n).
    Returns:
        (dL, n, mask): float64 [K, H, W] log(I_{k+1} + eps) - log(I_k + eps); int64 [K, H, W] ON minus
        OFF events in (t_k, t_{k+1}]; bool [K, H, W] the well-exposed pixels. K = usable pairs.
    """
    t = frames.t
    usable = np.flatnonzero((t[:-1] >= events.t[0]) & (t[1:] <= events.t[-1]))
    if usable.size == 0:
        raise EventDataError("no two consecutive frames lie inside the events' time span; a frame pair with "
                             "events between them is needed")
    images = frames.as_float().astype(np.float64)
    a, b = images[usable], images[usable + 1]
    dL = np.log(b + eps) - np.log(a + eps)
    boundaries = np.unique(np.concatenate([t[usable], t[usable + 1]]))
    counts = events_to_frames(events, boundaries, C=1.0).frames
    index = np.searchsorted(boundaries, t[usable])      # bin of each usable pair
    n = np.rint(counts[index]).astype(np.int64)
    lo, hi = exposed
    mask = (a > lo) & (a < hi) & (b > lo) & (b < hi)
    return dL, n, mask


def estimate_contrast_threshold(log_changes, net_counts):
    """Least-squares C in log_changes ≈ C * net_counts (a line through the origin).

    Args:
        log_changes: float [M], ΔL of M pixels (already masked).
        net_counts: int [M], ON minus OFF events of the same pixels over the same intervals.
    Returns:
        float C = sum(ΔL n) / sum(n^2).
    """
    d = np.asarray(log_changes, dtype=np.float64)
    n = np.asarray(net_counts, dtype=np.float64)
    return float(np.sum(d * n) / np.sum(n * n))
