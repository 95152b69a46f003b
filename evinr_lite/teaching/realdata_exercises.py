"""Notebook 09 (real data): the event-rate exercise.

- ``event_rate``: events per second in fixed bins, the first look at any recording. The reference
  below is the teaching version (times only, one rate); it re-implements, on purpose, the
  library's :func:`evinr_lite.method.binning.event_rate` (ON and OFF rates of an ``Events``),
  and ``tests/test_realdata.py`` pins the two together.

The contrast threshold fitted from APS frames (notebook 09's second exercise) is
:func:`evinr_lite.method.contrast.estimate_contrast_threshold`, which notebook 11 applies again
to the reader's own recording.
"""
from __future__ import annotations

import numpy as np

from . import exercises

__all__ = ["event_rate"]


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
