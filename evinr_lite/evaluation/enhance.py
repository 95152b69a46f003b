"""Event enhancement (paper Sec. 4.4): events re-rendered from a trained EvINR, scored against clean events.

A trained model F(t) is a smooth, denoised description of the log intensity. Thresholding its
integrated change at C, the way a camera does, renders a new event stream:

    per pixel, reference r = F(b_0); at each boundary b_k:  n = trunc((F(b_k) - r) / C);  r <- r + n C

so n > 0 means n ON events in (b_{k-1}, b_k] and n < 0 means |n| OFF events. Isolated noise
events do not survive the fit (one noise event changes no smooth F by a whole C), while the
edges that many events agree on do.

Scoring compares per-pixel, per-bin event counts, ON and OFF separately, with those of the clean
events (a simulation without noise): true positives are min(count, clean count) per cell, so
precision = TP / events rendered, recall = TP / clean events, F1 their harmonic mean; plus the RMS
error of the signed event frames (C sum p per bin).
"""
from __future__ import annotations

import numpy as np

from ..core.checks import ArgumentTypeError, host_array, real_number, require
from ..core.events import EventDataError, Events
from ..core.guard import dense_array
from ..method.binning import check_boundaries
from ..sim.simulate import add_background_noise  # noqa: F401  (notebook 08 imports it from here too)

__all__ = ["render_event_counts", "render_counts", "signed_to_polarity_counts", "event_counts", "model_event_counts",
           "add_background_noise", "count_scores"]


def render_event_counts(L_boundaries, C: float) -> np.ndarray:
    """Signed event counts per bin from log intensities at the bin boundaries (an ideal camera).

    Args:
        L_boundaries: float [B + 1, H, W] (or [B + 1, P]) log intensity at b_0 .. b_B.
        C: contrast threshold (log units).

    Returns:
        int64 [B, H, W]: n_k = trunc((L(b_{k+1}) - r_k) / C) with r_0 = L(b_0) and
        r_{k+1} = r_k + n_k C (the reference moves by whole steps; the rest carries over).
    """
    return render_counts(L_boundaries, C, np.trunc)


MAX_STEPS = 2.0**53   # render_counts: counts beyond float64's whole numbers (and int64's range) are no counts


def render_counts(L_boundaries, C, whole_steps=np.trunc):
    """Counts from a moving reference: n_k = whole_steps((L(b_{k+1}) - r_k) / C), r_{k+1} = r_k + n_k C."""
    # C 0 or NaN gave garbage counts (inf or NaN cast to int64), a negative C counts of the wrong sign
    C = real_number(C, "C", lo=0, lo_open=True, hint="the contrast threshold in log units (e.g. 0.2)")
    L = dense_array(L_boundaries, "L_boundaries", error=EventDataError, want="log intensities [B + 1, H, W]")
    if L.dtype.kind not in "iuf":   # complex kept its real part, text was numpy's error
        kind = "complex numbers" if L.dtype.kind == "c" else f"dtype {L.dtype}"
        raise EventDataError(f"L_boundaries must be numbers (log intensities at the bin boundaries), got {kind}")
    L = L.astype(np.float64)
    if L.ndim < 1 or L.shape[0] < 1:   # was numpy's IndexError
        raise EventDataError(f"L_boundaries must hold at least one boundary [B + 1, ...], got shape {L.shape}")
    finite = np.isfinite(L)
    if not finite.all():
        raise EventDataError(f"L_boundaries contain {int(L.size - finite.sum()):,} NaN or inf value(s); log "
                             "intensities must be finite to count events")
    if not callable(whole_steps):   # was "'str' object is not callable" at the first step
        raise ArgumentTypeError(f"whole_steps= must be a function rounding to whole steps (np.trunc, np.floor, "
                                f"np.round), got {type(whole_steps).__name__}")
    if L.size and (float(L.max()) - float(L.min())) / C > MAX_STEPS:   # int64's wrap: -9223372036854775808 events
        raise EventDataError(f"L_boundaries span {float(L.max()) - float(L.min()):.3g} log units, over {MAX_STEPS:.3g} "
                             f"steps of C = {C:g}: no count of events is that large; check C (log units per event, "
                             "e.g. 0.2) and that L holds log intensities")
    ref = L[0].copy()
    out = np.empty((L.shape[0] - 1,) + L.shape[1:], dtype=np.int64)
    for k in range(1, L.shape[0]):
        n = whole_steps((L[k] - ref) / C)
        ref += n * C
        out[k - 1] = n
    return out


def signed_to_polarity_counts(signed) -> np.ndarray:
    """Signed counts [B, H, W] -> non-negative [2, B, H, W] (ON counts, OFF counts)."""
    try:
        s = None if isinstance(signed, (str, bytes)) or signed is None else np.asarray(host_array(signed))
    except (TypeError, ValueError):   # a ragged list
        s = None
    ok = s is not None and s.dtype.kind in "iuf"
    if ok and s.dtype.kind == "f":   # NaN became an arbitrary integer, 0.5 became 0
        ok = bool(np.all(np.isfinite(s))) and bool(np.all(s == np.round(s)))
    if not ok:
        raise EventDataError("signed: counts must be whole numbers (ON minus OFF events per cell, [B, H, W]); got "
                             + (f"dtype {s.dtype}" if s is not None and s.dtype.kind not in "iuf" else
                                "NaN, infinite or fractional values" if s is not None else repr(signed)[:60]))
    return np.stack([np.maximum(s, 0), np.maximum(-s, 0)]).astype(np.int64)


def event_counts(events: Events, boundaries) -> np.ndarray:
    """Events per pixel and bin, ON and OFF apart: int64 [2, B, H, W].

    Bin k holds the events with b_k < t <= b_{k+1} (bin 0 also t == b_0), as in
    :func:`evinr_lite.method.binning.events_to_frames`; events outside [b_0, b_B] are not counted.
    """
    events = require(events, Events, "events")
    b = check_boundaries(boundaries)   # NaN and inf edges were taken (NaN never compares, so it was skipped)
    H, W = events.sensor_size
    B = b.size - 1
    lo = int(np.searchsorted(events.t, b[0], side="left"))
    hi = int(np.searchsorted(events.t, b[-1], side="right"))
    k = np.maximum(np.searchsorted(b, events.t[lo:hi], side="left") - 1, 0)
    pol = (events.p[lo:hi] < 0).astype(np.int64)                       # 0 = ON, 1 = OFF
    flat = ((pol * B + k) * H + events.y[lo:hi]) * W + events.x[lo:hi]
    return np.bincount(flat, minlength=2 * B * H * W).reshape(2, B, H, W).astype(np.int64)


def model_event_counts(rec, boundaries, C: float) -> np.ndarray:
    """Events re-rendered from a trained reconstruction (anything with ``.at(times)``): int64 [2, B, H, W]."""
    if not callable(getattr(rec, "at", None)):
        raise EventDataError(f"rec must be a reconstruction (anything with .at(times), e.g. reconstruct(...)'s "
                             f"result), got {type(rec).__name__}")
    L = np.asarray(rec.at(check_boundaries(boundaries)), dtype=np.float64)
    return signed_to_polarity_counts(render_event_counts(L, C))


def _whole_counts(value, name: str) -> np.ndarray:
    """Event counts as int64: whole numbers >= 0 (NaN, 0.5 or -3 were cast to int64 and scored)."""
    arr = None if isinstance(value, (str, bytes)) else dense_array(value, name, error=EventDataError)
    ok = arr is not None and arr.dtype.kind in "biuf"
    if ok and arr.dtype.kind == "f":
        ok = bool(np.all(np.isfinite(arr))) and bool(np.all(arr == np.round(arr)))
    if not ok or (arr.size and arr.min() < 0):
        raise EventDataError(f"{name}: counts must be whole numbers >= 0 (events per cell, [2, B, H, W]); got "
                             + (f"dtype {arr.dtype}" if arr is not None and arr.dtype.kind not in "biuf" else
                                "NaN, fractional or negative values" if arr is not None else repr(value)[:60]))
    return arr.astype(np.int64)


def count_scores(counts, clean_counts, C: float = 1.0) -> dict:
    """How well event counts [2, B, H, W] match the clean ones.

    Returns:
        {"precision", "recall", "f1": floats in [0, 1]; "frame_rmse": RMS of the difference of the
        signed event frames C (ON - OFF) per pixel and bin; "n_events", "n_clean": totals}.
    """
    a, c = _whole_counts(counts, "counts"), _whole_counts(clean_counts, "clean_counts")
    C = real_number(C, "C", lo=0, lo_open=True, hint="the contrast threshold in log units")
    if a.shape != c.shape or a.ndim != 4 or a.shape[0] != 2:
        raise ValueError(f"expected two [2, B, H, W] count arrays of one shape, got {a.shape} and {c.shape}")
    tp = float(np.minimum(a, c).sum())
    n, n_clean = float(a.sum()), float(c.sum())
    precision = tp / n if n else 0.0
    recall = tp / n_clean if n_clean else 0.0
    f1 = 2 * precision * recall / (precision + recall) if precision + recall else 0.0
    rmse = float(np.sqrt(np.mean((C * ((a[0] - a[1]) - (c[0] - c[1]))) ** 2)))
    return {"precision": precision, "recall": recall, "f1": f1, "frame_rmse": rmse,
            "n_events": int(n), "n_clean": int(n_clean)}
