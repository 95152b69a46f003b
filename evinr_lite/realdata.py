"""Real recordings in notebook 09: the event rate, and which ground-truth frames an evaluation scores.

Exercise (reference registered with :mod:`evinr_lite.exercises` at import):

- ``event_rate``: events per second in fixed bins, the first look at any recording.

The contrast threshold fitted from APS frames (notebook 09's second exercise) is
:func:`evinr_lite.recording_exercises.estimate_contrast_threshold`, which notebook 11 applies again
to the reader's own recording.
"""
from __future__ import annotations

import numpy as np

from . import exercises
from .events import EventDataError, Events

__all__ = ["event_rate", "frames_to_score"]


def event_rate(t, bin_s):
    """Event rate over time.

    Args:
        t: float64 [N] event timestamps (s), sorted.
        bin_s: bin width (s).

    Returns:
        (centers, rate): float64 [B] bin centres (s) and events per second in each bin, with bins
        [t0 + k * bin_s, t0 + (k + 1) * bin_s) starting at t0 = t[0] and covering every event.
    """
    t = np.asarray(t, dtype=np.float64)
    n_bins = max(int(np.floor((t[-1] - t[0]) / bin_s)) + 1, 1)
    counts = np.bincount(np.minimum(((t - t[0]) / bin_s).astype(np.int64), n_bins - 1), minlength=n_bins)
    centers = t[0] + (np.arange(n_bins) + 0.5) * bin_s
    return centers, counts / bin_s


def frames_to_score(frame_t, events: Events, margin: float = 0.005) -> np.ndarray:
    """Indices of the frames whose timestamps lie in [first event - margin, last event + margin] (s)."""
    frame_t = np.asarray(frame_t, dtype=np.float64)
    if len(events) == 0:
        raise EventDataError("no events: nothing to reconstruct or score; choose a window with events")
    keep = (frame_t >= events.t[0] - margin) & (frame_t <= events.t[-1] + margin)
    if not keep.any():
        raise EventDataError(f"no frame lies within the events' span [{events.t[0]:.4f}, {events.t[-1]:.4f}] s; "
                             "pick a window that contains frames")
    return np.flatnonzero(keep)


# ---- exercise registrations -----------------------------------------------------------------

def _inputs_rate(rng):
    cases = []
    for n, span, bin_s in ((50, 1.0, 0.1), (200, 0.37, 0.05), (7, 2.0, 0.5)):
        t = np.sort(rng.uniform(0.0, span, n)) + rng.uniform(0, 3)
        cases.append(dict(t=t, bin_s=bin_s))
    return cases


exercises.register(
    "event_rate", event_rate, _inputs_rate,
    hints={"divide the counts by the bin width to get events per second":
           lambda t, bin_s: (event_rate(t, bin_s)[0], event_rate(t, bin_s)[1] * bin_s),
           "return the bin centres, not the left edges":
           lambda t, bin_s: (event_rate(t, bin_s)[0] - bin_s / 2, event_rate(t, bin_s)[1])})
