"""Real recordings in notebook 09: event rate, the contrast threshold read off the APS frames, and the
frames that an evaluation scores.

Exercises (references registered with :mod:`evinr_lite.exercises` at import):

- ``event_rate``: events per second in fixed bins, the first look at any recording;
- ``fit_contrast_threshold``: the least-squares C that best explains the APS frames' log-intensity
  changes by the events between them (C_hat = sum(dL * n) / sum(n^2) over the active pixels).
"""
from __future__ import annotations

import numpy as np

from . import exercises
from .binning import events_to_frames
from .events import EventDataError, Events

__all__ = ["event_rate", "fit_contrast_threshold", "frame_log_intensity", "frame_pair_changes", "frames_to_score",
           "scored_span"]


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


def frame_log_intensity(images, eps: float = 1.0 / 255):
    """Log intensity of APS frames: log(I + eps) with I = uint8 / 255. float64 [F, H, W]."""
    return np.log(np.asarray(images, dtype=np.float64) / 255.0 + eps)


def fit_contrast_threshold(dL, n):
    """Least-squares contrast threshold: the C minimising sum (dL - C * n)^2 over pixels with events.

    Args:
        dL: float64 [..., H, W] log-intensity change between consecutive frames.
        n: [..., H, W] net event count (sum of polarities) between the same frames.

    Returns:
        float: sum(dL * n) / sum(n^2) (pixels with n = 0 do not change it).
    """
    dL = np.asarray(dL, dtype=np.float64)
    n = np.asarray(n, dtype=np.float64)
    return float(np.sum(dL * n) / np.sum(n * n))


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


def scored_span(frame_t, events: Events, eval_window=None):
    """(t_start, t_end) to reconstruct: the evaluation window when the recording covers it, else the events' span."""
    if eval_window is not None and events.t[0] <= eval_window[0] and events.t[-1] >= eval_window[1]:
        return float(eval_window[0]), float(eval_window[1])
    return float(events.t[0]), float(events.t[-1])


def frame_pair_changes(events: Events, frame_t, images):
    """For consecutive frames: (dL [F-1, H, W] from the images, n [F-1, H, W] net events between them)."""
    L = frame_log_intensity(images)
    n = events_to_frames(events, np.asarray(frame_t, np.float64), C=1.0).frames
    return L[1:] - L[:-1], n


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


def _inputs_fit(rng):
    cases = []
    for shape, C in (((2, 4, 5), 0.2), ((3, 6, 6), 0.35), ((1, 3, 3), 0.1)):
        n = rng.integers(-4, 5, size=shape).astype(np.float64)
        dL = C * n + rng.normal(0, 0.05, size=shape)
        cases.append(dict(dL=dL, n=n))
    return cases


exercises.register(
    "fit_contrast_threshold", fit_contrast_threshold, _inputs_fit,
    hints={"fit dL = C * n (dL / n on average is biased by small n): C = sum(dL * n) / sum(n^2)":
           lambda dL, n: float(np.mean(np.asarray(dL)[np.asarray(n) != 0] / np.asarray(n)[np.asarray(n) != 0])),
           "C is sum(dL * n) / sum(n^2), not sum(n^2) / sum(dL * n)":
           lambda dL, n: float(np.sum(np.asarray(n) ** 2) / np.sum(np.asarray(dL) * np.asarray(n)))})
