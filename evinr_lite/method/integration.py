"""Integrating events back into log intensity (Eq. 2 of the paper).

    L(x, y, t) ~ L0(x, y) + C * sum of p over the events at (x, y) with t_event <= t

Without noise this recovers a simulated signal to within one threshold (see
:mod:`evinr_lite.sim.simulate`); on real data, noise and threshold mismatch make it drift, which is
what EvINR's regularised fit avoids.
"""
from __future__ import annotations

import numpy as np

from .binning import as_thresholds, events_to_frames
from ..core.checks import check_seconds_precision, host_array
from ..core.guard import dense_array
from ..core.events import EventDataError, Events

__all__ = ["integrate_events"]


def _event_sums(events: Events, t_sorted: np.ndarray) -> np.ndarray:
    """float64 [Q, H, W]: sum of p over the events with t_event <= t_sorted[q] (t_sorted increasing, unique)."""
    # bin 0 = (b0, t_sorted[0]] with b0 before every event, so it holds everything up to t_sorted[0]
    first = events.t[0] if len(events) else t_sorted[0]
    b0 = min(first, t_sorted[0]) - 1.0
    boundaries = np.concatenate([[b0], t_sorted])
    per_bin = events_to_frames(events, boundaries, C=1.0).frames      # integer sums, exact in float32
    return np.cumsum(per_bin, axis=0, dtype=np.float64)


def integrate_events(events: Events, t_query, C=1.0, L0=None) -> np.ndarray:
    """Log intensity from events: ``L0 + C * (sum of p over events with t <= t_query[q])``.

    Args:
        events: the events (times on the same clock as ``t_query``).
        t_query: seconds, a scalar or an array [Q] (any order, repeats allowed).
        C: contrast threshold (log units), or a pair ``(C_pos, C_neg)`` to weigh ON events by
            +C_pos and OFF events by -C_neg.
        L0: log intensity at the start, a scalar or an array [H, W]; default 0.

    Returns:
        float64 [Q, H, W] ([H, W] for a scalar ``t_query``).
    """
    H, W = events.sensor_size
    t_query = host_array(t_query)
    check_seconds_precision(t_query, "t_query")
    tq = dense_array(t_query, "t_query", np.float64, EventDataError)
    if tq.ndim > 1 or tq.size == 0 or not np.all(np.isfinite(tq)):
        raise EventDataError(f"t_query must be a finite scalar or a non-empty 1-D array of seconds, got shape {tq.shape}")
    C_pos, C_neg = as_thresholds(C)
    L0 = 0.0 if L0 is None else np.asarray(L0, dtype=np.float64)
    if np.ndim(L0) not in (0, 2) or (np.ndim(L0) == 2 and L0.shape != (H, W)):
        raise EventDataError(f"L0 must be a scalar or an [H, W] = {(H, W)} array, got shape {np.shape(L0)}")
    uniq, inverse = np.unique(np.atleast_1d(tq), return_inverse=True)
    if C_pos == C_neg:
        L = C_pos * _event_sums(events, uniq)
    else:
        on = events.take(events.p > 0)
        off = events.take(events.p < 0)
        L = C_pos * _event_sums(on, uniq) + C_neg * _event_sums(off, uniq)   # off sums are negative
    L = L[inverse.ravel()] + L0
    return L[0] if tq.ndim == 0 else L
