"""One pixel, one dimension: the event generation equation (Eq. 1-6) in its smallest form.

Notebook 01 teaches with these pieces; the reference solutions of its exercises live here
and are registered with :mod:`evinr_lite.teaching.exercises` at import.

- :func:`integrate_events_1d`: Eq. 2, the log-intensity change since t0 from the events.
- :func:`event_rate_derivative`: Eq. 4's right-hand side, the event rate per window.
- :func:`temporal_loss`: Eq. 5-6, (Delta L - dF/dt * (t2 - t1))^2 averaged over windows.
- :func:`taylor_error`, :func:`eq4_error_vs_window`: how good Eq. 3's mid-point derivative is.
- :func:`fit_siren_1d`: solve Eq. 4 for one pixel with a small SIREN F(t).
- :func:`bin_residuals`: does a fitted F match each window's events at the mid-point only, or over the window?

Times are float64 seconds; polarities are +-1; C is the contrast threshold (log units).
"""
from __future__ import annotations

import copy
import time
from typing import Callable

import numpy as np
import torch
from torch import nn

from ..core.checks import ArgumentTypeError, real_number, require, seconds_array, whole_number
from ..core.events import EventDataError
from ..core.runtime import default_device
from ..method.siren import Siren, input_gradient
from ..sim.simulate import pixel_events
from . import exercises

__all__ = [
    "integrate_events_1d", "event_rate_derivative", "window_sums", "temporal_loss",
    "taylor_error", "eq4_error_vs_window", "TimeSiren1D", "time_derivative",
    "fit_siren_1d", "evaluate_temporal_loss", "bin_residuals",
]


# ---- Eq. 2 and Eq. 4 from events ----------------------------------------------------

def integrate_events_1d(t_events, p_events, C, t_query):
    """Eq. 2: L(t_q) - L(t0) estimated as C times the sum of the polarities of the events
    with ``t_event <= t_q``.

    Args:
        t_events: float [N] sorted event times (s).
        p_events: [N] polarities (+-1).
        C: contrast threshold.
        t_query: float [Q] query times (s).

    Returns:
        float64 [Q].
    """
    t_events = np.asarray(t_events, dtype=np.float64)
    csum = np.concatenate([[0.0], np.cumsum(np.asarray(p_events, dtype=np.float64))])
    n_before = np.searchsorted(t_events, np.asarray(t_query, dtype=np.float64), side="right")
    return C * csum[n_before]


def _window_index(t_events: np.ndarray, boundaries: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Window index of every event inside [b0, b_end] (b_i < t <= b_{i+1}; t == b0 joins window 0)."""
    inside = (t_events >= boundaries[0]) & (t_events <= boundaries[-1])
    idx = np.searchsorted(boundaries, t_events[inside], side="left") - 1
    return np.maximum(idx, 0), inside


def window_sums(t_events, p_events, C, boundaries) -> np.ndarray:
    """Delta L per window (Eq. 2): C times the summed polarities in each window. float64 [B]."""
    C = _contrast(C)
    b = _edges(boundaries, strict=False)   # a repeated edge is an empty window (an input clipped to [0, 1])
    t, p = _pixel_pair(t_events, p_events)
    idx, inside = _window_index(t, b)
    return C * np.bincount(idx, weights=p[inside], minlength=b.size - 1)


# ---- argument checks of the helpers below (the exercises' reference solutions stay as the notebooks show them) ----

MAX_WINDOWS = 10_000_000   # windows in one call: more is a window length in the wrong unit, not a plan


def _contrast(C) -> float:
    return real_number(C, "C", lo=0.0, lo_open=True, hint="the contrast threshold in log units, e.g. 0.2")


def _edges(boundaries, name: str = "boundaries", strict: bool = True) -> np.ndarray:
    """Window edges as float64 [B + 1]: numbers, finite, at least two, increasing (``strict``: no repeats)."""
    b = seconds_array(boundaries, name)
    if b.size < 2:
        raise EventDataError(f"{name}= holds {b.size} edge; windows need at least 2 edges (B + 1 edges make B "
                             f"windows), e.g. np.linspace(0.0, 1.0, 11)")
    step = np.diff(b)
    bad = ~(step > 0) if strict else step < 0
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise EventDataError(f"{name}= must increase{' strictly' if strict else ''}, but {name}[{k + 1}] = "
                             f"{b[k + 1]:g} comes after {name}[{k}] = {b[k]:g}; sort them (np.sort)"
                             + (" and drop repeats (np.unique)" if strict else ""))
    return b


def _pixel_pair(t_events, p_events) -> tuple[np.ndarray, np.ndarray]:
    """One pixel's events as float64 [N] times and polarities: numbers, one polarity per time, finite."""
    t = seconds_array(t_events, "t_events", allow_empty=True)
    p = np.asarray(p_events) if not isinstance(p_events, (str, bytes)) else np.asarray([p_events])
    if p.dtype.kind not in "iufb" or p.ndim > 1:
        raise EventDataError(f"p_events= must be a 1-D array of polarities (+-1), got "
                             f"{'shape ' + str(p.shape) if p.dtype.kind in 'iufb' else repr(p_events)[:60]}")
    p = np.atleast_1d(p).astype(np.float64)
    if p.shape != t.shape:
        raise EventDataError(f"{t.size} event time(s) in t_events but {p.size} polarities in p_events; pass one "
                             f"polarity per event")
    if not np.isfinite(p).all():
        raise EventDataError("p_events= holds NaN or inf; polarities are +1 (ON) or -1 (OFF)")
    return t, p


def _span(t_range, name: str = "t_range") -> tuple[float, float]:
    """(t0, t1) as finite floats, t0 < t1."""
    try:
        t0, t1 = t_range
    except (TypeError, ValueError):
        raise EventDataError(f"{name}= must be a pair (t0, t1) of seconds, e.g. (0.0, 1.0), got "
                             f"{repr(t_range)[:60]}") from None
    t0 = real_number(t0, f"{name}: t0", hint="seconds, e.g. (0.0, 1.0)")
    t1 = real_number(t1, f"{name}: t1", hint="seconds, e.g. (0.0, 1.0)")
    if not t1 > t0:
        raise EventDataError(f"{name}= must be increasing, got ({t0:g}, {t1:g}); give (t0, t1) with t0 < t1")
    return t0, t1


def _model(model):
    """A fitted 1-D model: a TimeSiren1D, or anything with its t_range, predict and derivative (a reader's own)."""
    if not all(hasattr(model, a) for a in ("t_range", "predict", "derivative")):
        raise ArgumentTypeError(f"model= must be a fitted TimeSiren1D (fit_siren_1d(...)['model']) or a model with "
                                f"its t_range, predict and derivative, got {type(model).__name__}")
    return model


def _callable(fn, name: str, *, none_ok: bool = False):
    if (fn is None and none_ok) or callable(fn):
        return fn
    raise ArgumentTypeError(f"{name}= must be a function of time (seconds -> log intensity), e.g. lambda t: "
                            f"np.sin(t), got {type(fn).__name__}" + (" (or None)" if none_ok else ""))


def _window_count(span: float, window: float) -> int:
    n = span / window
    if n > MAX_WINDOWS:
        raise EventDataError(f"window={window:g} s cuts the span of {span:g} s into {n:,.0f} windows (at most "
                             f"{MAX_WINDOWS:,}): give both in seconds (a span given in microseconds, (0, 1e6), "
                             f"or a window in ms written as 2.5e-8 s does this)")
    return int(n)


FORMS = ("derivative", "difference")


def _form(form) -> str:
    if not isinstance(form, str) or form not in FORMS:
        raise EventDataError(f"form must be 'derivative' (Eq. 5) or 'difference' (F(t2) - F(t1)), got {form!r}")
    return form


def event_rate_derivative(t_events, p_events, C, boundaries):
    """Eq. 4's right-hand side: (1 / (t2 - t1)) * C * (sum of polarities in (t1, t2]) per window (an
    event exactly at the first edge b_0 counts in the first window).

    It estimates dL/dt at the window mid-points ``(b[i] + b[i+1]) / 2``.

    Args:
        t_events: float [N] sorted event times (s).
        p_events: [N] polarities (+-1).
        C: contrast threshold.
        boundaries: float [B + 1] increasing window edges (s).

    Returns:
        float64 [B], in log units per second.
    """
    b = np.asarray(boundaries, dtype=np.float64)
    return window_sums(t_events, p_events, C, b) / np.diff(b)


def temporal_loss(dF_dt, delta_L, durations):
    """Eq. 5-6 averaged over windows: mean((delta_L - dF_dt * durations)^2).

    Args:
        dF_dt: torch [B], the model's time derivative at the window mid-points.
        delta_L: torch [B], summed events per window (Eq. 2).
        durations: torch [B], window lengths t2 - t1.

    Returns:
        torch scalar (shape ()), differentiable.
    """
    return torch.mean((delta_L - dF_dt * durations) ** 2)


# ---- exercises (reference solutions above) --------------------------------------------

def _sorted_events(rng, n, t0=0.0, t1=1.0):
    t = np.sort(rng.uniform(t0, t1, n))
    p = rng.choice(np.array([-1, 1], dtype=np.int8), n)
    return t, p


def _inputs_integrate(rng):
    cases = []
    t, p = _sorted_events(rng, 40)
    tq = np.sort(np.concatenate([[-0.1, 1.1], rng.uniform(0, 1, 7)]))
    tq = tq[rng.permutation(9)]                 # query times in any order (a sweep that assumes them sorted fails)
    cases.append(dict(t_events=t, p_events=p, C=0.25, t_query=tq))
    # 150 ON events on an absolute clock (t ~ 1000 s): the running sum passes 127, which int8 polarities summed
    # as int8 wrap round (a loop `s = 0; s += p[i]` stays int8 in NumPy 2, so does an int8 buffer); and four
    # queries sit 10 us before an event, which float32 timestamps (spacing 61 us at 1000 s) cannot tell apart. C is
    # the first case's, the events are not: a running sum kept from one call to the next (cached per C) fails here
    t = 1000.0 + np.sort(rng.uniform(0, 1, 150))
    tq = np.sort(np.concatenate([[999.9, 1001.1], t[[10, 40, 80, 120]] - 1e-5, [t[130]]]))
    cases.append(dict(t_events=t, p_events=np.ones(150, np.int8), C=0.25, t_query=tq))
    # the boundary rule t_i <= t_q: queries exactly at event times (and at a repeated time) count
    # the event, so side="left" or a strict `<` fails here
    t = np.array([0.1, 0.25, 0.25, 0.5, 0.8])
    p = np.array([1, 1, 1, -1, 1], dtype=np.int8)
    cases.append(dict(t_events=t, p_events=p, C=0.2, t_query=np.array([0.0, 0.1, 0.25, 0.3, 0.5, 0.8, 1.0])))
    # last, a pixel that never fired: no events at all (every query reads 0; csum[n - 1] or t_events[0] raises)
    cases.append(dict(t_events=np.zeros(0), p_events=np.zeros(0, np.int8), C=0.2,
                      t_query=np.array([-0.1, 0.0, 0.3, 0.5, 0.9, 1.1])))
    return cases


def _inputs_rate(rng):
    cases = []
    # events in [0, 1]; the second case's last window (1.1, 1.3] holds no event (a sum per window even when
    # it is 0: np.bincount needs minlength), the third's windows cover [0.1, 0.9] only (events outside every
    # window count nowhere, not in the first or last one)
    for n, B, C, (lo, hi), empty_end in ((6, 3, 0.2, (0.0, 1.0), False), (30, 5, 0.5, (0.0, 1.3), True),
                                         (80, 8, 0.25, (0.1, 0.9), False)):
        t, p = _sorted_events(rng, n)
        inner = np.sort(rng.uniform(lo + 0.05, min(hi, 1.0) - 0.05, B - 1 - empty_end))
        b = np.concatenate([[lo], inner, [1.1] if empty_end else [], [hi]])
        # the events before b_0 (and after b_B) must not sum to 0, or a version that counts them in the first
        # (last) window passes by luck: flip the first (last) one's polarity when they do
        for outside, k in ((t < lo, 0), (t > hi, -1)):
            if outside.any() and p[outside].sum() == 0:
                p[np.flatnonzero(outside)[k]] *= -1
        cases.append(dict(t_events=t, p_events=p, C=C, boundaries=b))
    # the boundary rule (b_k, b_{k+1}]: events exactly on an inner edge and on the last edge belong to
    # the window that ends there, so `<` in place of `<=` (or side="left" / "right" swapped) fails here;
    # the one exactly on the first edge b_0 opens window 0 (as the kit's binning), so a strict b_0 < t loses it
    b = np.array([0.0, 0.25, 0.5, 0.75, 1.0])
    t = np.array([0.0, 0.1, 0.25, 0.25, 0.4, 0.5, 0.6, 0.75, 1.0])
    p = np.array([1, 1, 1, -1, 1, 1, -1, 1, 1], dtype=np.int8)
    cases.append(dict(t_events=t, p_events=p, C=0.5, boundaries=b))
    return cases


def _integrate_strict(t_events, p_events, C, t_query):
    """A wrong version (for the hint): events exactly at t_q left out (t_i < t_q)."""
    csum = np.concatenate([[0.0], np.cumsum(np.asarray(p_events, dtype=np.float64))])
    return C * csum[np.searchsorted(np.asarray(t_events, float), np.asarray(t_query, float), side="left")]


def _rate_no_first_edge(t_events, p_events, C, boundaries):
    """A wrong version (for the hint): an event exactly at b_0 left out (b_0 < t for window 0 too)."""
    t = np.asarray(t_events, dtype=np.float64)
    keep = t != np.asarray(boundaries, dtype=np.float64)[0]
    return event_rate_derivative(t[keep], np.asarray(p_events)[keep], C, boundaries)


def _rate_open(t_events, p_events, C, boundaries):
    """A wrong version (for the hint): windows (b_k, b_{k+1}) with a strict `<`, edge events dropped."""
    t, b = np.asarray(t_events, float), np.asarray(boundaries, float)
    p = np.asarray(p_events, float)
    sums = [p[(t > b1) & (t < b2)].sum() for b1, b2 in zip(b[:-1], b[1:])]
    return C * np.array(sums) / np.diff(b)


def _rate_left_closed(t_events, p_events, C, boundaries):
    """A wrong version (for the hint): windows [b_k, b_{k+1}) instead of (b_k, b_{k+1}]."""
    t, b = np.asarray(t_events, float), np.asarray(boundaries, float)
    p = np.asarray(p_events, float)
    sums = [p[(t >= b1) & (t < b2)].sum() for b1, b2 in zip(b[:-1], b[1:])]
    return C * np.array(sums) / np.diff(b)


def _rate_clipped(t_events, p_events, C, boundaries):
    """A wrong version (for the hint): events before b_0 / after b_B counted in the first / last window
    (the window index clipped into 0 .. B - 1 instead of the events dropped)."""
    b = np.asarray(boundaries, float)
    i = np.clip(np.searchsorted(b, np.asarray(t_events, float), side="left") - 1, 0, b.size - 2)
    return C * np.bincount(i, weights=np.asarray(p_events, float), minlength=b.size - 1) / np.diff(b)


def _rate_early_in_first(t_events, p_events, C, boundaries):
    """A wrong version (for the hint): events before b_0 counted in the first window (only the end b_B
    checked, then the window index raised to 0 with np.maximum)."""
    t, b = np.asarray(t_events, float), np.asarray(boundaries, float)
    keep = t <= b[-1]
    i = np.maximum(np.searchsorted(b, t[keep], side="left") - 1, 0)
    return C * np.bincount(i, weights=np.asarray(p_events, float)[keep], minlength=b.size - 1) / np.diff(b)


def _rate_histogram(t_events, p_events, C, boundaries):
    """A wrong version (for the hint): np.histogram's bins, [b_k, b_{k+1}) with the last one closed."""
    sums, _ = np.histogram(np.asarray(t_events, float), bins=np.asarray(boundaries, float),
                           weights=np.asarray(p_events, float))
    return C * sums / np.diff(np.asarray(boundaries, float))


def _inputs_loss(rng):
    g = torch.Generator().manual_seed(0)
    cases = []
    for B in (4, 9):
        dF = (torch.randn(B, generator=g) * 5).requires_grad_(True)   # the loss must stay differentiable
        dur = torch.rand(B, generator=g) * 0.05 + 0.01
        dL = torch.randint(-3, 4, (B,), generator=g).float() * 0.2
        cases.append(dict(dF_dt=dF, delta_L=dL, durations=dur))
    return cases


def _integrate_no_leading_zero(t_events, p_events, C, t_query):
    """csum[n - 1] without a leading 0: a query before the first event reads csum[-1], the total."""
    csum = np.cumsum(np.asarray(p_events, dtype=np.float64))
    n = np.searchsorted(np.asarray(t_events, np.float64), np.asarray(t_query, np.float64), side="right")
    return C * csum[n - 1]


def _integrate_int8_sum(t_events, p_events, C, t_query):
    """A wrong version (for the hint): the running sum kept in the polarities' int8 (a loop `s += p[i]`)."""
    p = np.asarray(p_events)
    csum = np.concatenate([np.zeros(1, p.dtype), np.cumsum(p, dtype=p.dtype)])
    return C * csum[np.searchsorted(np.asarray(t_events, np.float64), np.asarray(t_query, np.float64), side="right")]


def _integrate_float32_times(t_events, p_events, C, t_query):
    """A wrong version (for the hint): times compared in float32."""
    return integrate_events_1d(np.asarray(t_events, np.float32), p_events, C, np.asarray(t_query, np.float32))


def _integrate_on_only(t_events, p_events, C, t_query):
    """A wrong version (for the hint): only the ON events counted (p > 0), OFF events ignored."""
    return integrate_events_1d(t_events, (np.asarray(p_events) > 0).astype(np.float64), C, t_query)


def _integrate_first_event_lost(t_events, p_events, C, t_query):
    """A wrong version (for the hint): the running sum starts at the second event (np.cumsum(p[1:]))."""
    p = np.asarray(p_events, dtype=np.float64).copy()
    p[:1] = 0.0
    return integrate_events_1d(t_events, p, C, t_query)


def _integrate_interpolated(t_events, p_events, C, t_query):
    """A wrong version (for the hint): the running sum read by np.interp, a straight line between events."""
    t = np.asarray(t_events, dtype=np.float64)
    if t.size == 0:
        return np.zeros(np.shape(t_query))
    return C * np.interp(np.asarray(t_query, dtype=np.float64), t, np.cumsum(np.asarray(p_events, np.float64)), left=0.0)


def _integrate_one_event_per_time(t_events, p_events, C, t_query):
    """A wrong version (for the hint): one event per timestamp (a dict keyed by time keeps the last of a tie)."""
    d = dict(zip(np.asarray(t_events, np.float64).tolist(), np.asarray(p_events, np.float64).tolist()))
    t, p = np.array(list(d), dtype=np.float64), np.array(list(d.values()), dtype=np.float64)
    return integrate_events_1d(t, p, C, t_query)


def _integrate_events_before(t_events, p_events, C, t_query):
    """A wrong version (for the hint): np.cumsum(p) - p, the sum of the events before each one, read at the last
    event up to t_q (which is then left out)."""
    p = np.asarray(p_events, dtype=np.float64)
    n = np.searchsorted(np.asarray(t_events, np.float64), np.asarray(t_query, np.float64), side="right") - 1
    before = np.cumsum(p) - p
    return C * np.where(n >= 0, before[np.maximum(n, 0)] if p.size else 0.0, 0.0)


def _integrate_isclose(t_events, p_events, C, t_query):
    """A wrong version (for the hint): t_event < t_q or np.isclose(t_event, t_q), a tolerance for the equal case
    (rtol 1e-5 of 1000 s is 10 ms)."""
    t, q = np.asarray(t_events, np.float64), np.asarray(t_query, np.float64)
    before = (t[None, :] < q[:, None]) | np.isclose(t[None, :], q[:, None])
    return C * (before * np.asarray(p_events, np.float64)).sum(axis=1)


exercises.register(
    "integrate_events_1d", integrate_events_1d, _inputs_integrate,
    hints={
        "an event counts when t_event <= t_q exactly: a tolerance for the equal case (np.isclose, whose rtol 1e-5 "
        "of a clock at 1000 s is 10 ms) counts events after the query; compare with `<=` (np.searchsorted(..., "
        "side=\"right\"))":
            _integrate_isclose,
        "did you forget the sign of the polarity? ON events add C, OFF events subtract C":
            lambda t_events, p_events, C, t_query: integrate_events_1d(t_events, np.abs(p_events), C, t_query),
        "did you forget to multiply by the contrast threshold C?":
            lambda t_events, p_events, C, t_query: integrate_events_1d(t_events, p_events, 1.0, t_query),
        "an event exactly at a query time counts (t_i <= t_q): use side=\"right\" in np.searchsorted, "
        "or `<=` rather than `<`":
            _integrate_strict,
        "a query before the first event counts no event, but csum[n - 1] with n = 0 reads csum[-1], the "
        "total: prepend a 0 (np.concatenate([[0.0], np.cumsum(p)])) and read csum[n]":
            _integrate_no_leading_zero,
        "the running sum overflowed: int8 polarities summed as int8 wrap round past 127 (a loop `s = 0; s += "
        "p[i]` stays int8 in NumPy 2, and so does an int8 buffer); sum in float64 (s = 0.0, or "
        "np.cumsum(np.asarray(p, dtype=np.float64)))":
            _integrate_int8_sum,
        "timestamps must stay float64: in float32 a time near 1000 s is rounded to 61 us, so a query 10 us "
        "before an event counts it":
            _integrate_float32_times,
        "OFF events count too: add C for every ON event and subtract C for every OFF event (sum p, not the "
        "number of ON events)":
            _integrate_on_only,
        "the first event is lost: the running sum must include event 0 (np.cumsum(p), then a leading 0 for "
        "'no event yet'), not start at p[1]":
            _integrate_first_event_lost,
        "multiply by C once: C * sum(p), not C * C * sum(p)":
            lambda t_events, p_events, C, t_query: C * integrate_events_1d(t_events, p_events, C, t_query),
        "the running sum is a step function: it jumps at each event and stays flat in between, but np.interp draws "
        "straight lines between the events; count the events up to t_q (np.searchsorted(t, t_q, side='right'))":
            _integrate_interpolated,
        "several events can share a timestamp, and each one counts: a dict keyed by time (or np.unique(t)) keeps "
        "only one of them; sum over the events themselves":
            _integrate_one_event_per_time,
        "np.cumsum(p) - p is the sum of the events *before* each one: read at the last event up to t_q it leaves "
        "that event out; np.cumsum(p)[n - 1] (or a leading 0 and csum[n]) includes it":
            _integrate_events_before,
    })

def _rate_per_event(t_events, p_events, C, boundaries):
    """A wrong version (for the hint): each window's sum divided by its number of events, not its length."""
    b = np.asarray(boundaries, dtype=np.float64)
    t = np.asarray(t_events, dtype=np.float64)
    idx, inside = _window_index(t, b)
    n = np.bincount(idx, minlength=b.size - 1)
    return window_sums(t, p_events, C, b) / np.maximum(n, 1)


def _rate_closed_both(t_events, p_events, C, boundaries):
    """A wrong version (for the hint): windows [b_k, b_{k+1}] closed at both ends (an edge event counted twice)."""
    t, b = np.asarray(t_events, float), np.asarray(boundaries, float)
    p = np.asarray(p_events, float)
    return C * np.array([p[(t >= lo) & (t <= hi)].sum() for lo, hi in zip(b[:-1], b[1:])]) / np.diff(b)


def _rate_nearest_centre(t_events, p_events, C, boundaries):
    """A wrong version (for the hint): each event given to the window whose centre is nearest (off by half a
    window where the windows differ in length)."""
    b, t = np.asarray(boundaries, float), np.asarray(t_events, float)
    centres = 0.5 * (b[1:] + b[:-1])
    keep = (t >= b[0]) & (t <= b[-1])
    i = np.argmin(np.abs(t[keep, None] - centres[None, :]), axis=1)
    return C * np.bincount(i, weights=np.asarray(p_events, float)[keep], minlength=centres.size) / np.diff(b)


def _rate_cumsum_no_leading_zero(t_events, p_events, C, boundaries):
    """A wrong version (for the hint): differences of csum[n] read at the edges, csum without its leading 0, so an
    edge before every event reads csum[-1], the total."""
    b, t = np.asarray(boundaries, float), np.asarray(t_events, float)
    csum = np.cumsum(np.asarray(p_events, float))
    n = np.searchsorted(t, b, side="right") - 1
    n[0] = np.searchsorted(t, b[0], side="left") - 1
    return C * np.diff(csum[n]) / np.diff(b)


def _rate_interpolated_sums(t_events, p_events, C, boundaries):
    """A wrong version (for the hint): the running sum read at the edges by np.interp (straight lines between
    events) instead of counted."""
    t, b = np.asarray(t_events, float), np.asarray(boundaries, float)
    at = np.interp(b, t, np.cumsum(np.asarray(p_events, float)), left=0.0)
    return C * np.diff(at) / np.diff(b)


def _rate_first_window_length(t_events, p_events, C, boundaries):
    b = np.asarray(boundaries, dtype=np.float64)
    return window_sums(t_events, p_events, C, b) / (b[1] - b[0])


exercises.register(
    "event_rate_derivative", event_rate_derivative, _inputs_rate,
    hints={
        "did you forget to divide by the window length t2 - t1 (Eq. 4)?":
            lambda t_events, p_events, C, boundaries: window_sums(t_events, p_events, C, boundaries),
        "divide each window's sum by its own length (np.diff(boundaries)): the windows differ in length":
            lambda t_events, p_events, C, boundaries: window_sums(t_events, p_events, C, boundaries)
            / np.mean(np.diff(np.asarray(boundaries, dtype=np.float64))),
        "did you forget the sign of the polarity? (count ON minus OFF, not all events)":
            lambda t_events, p_events, C, boundaries: event_rate_derivative(t_events, np.abs(p_events), C, boundaries),
        "did you forget to multiply by the contrast threshold C?":
            lambda t_events, p_events, C, boundaries: event_rate_derivative(t_events, p_events, 1.0, boundaries),
        "windows are (b_k, b_{k+1}]: an event exactly on an edge belongs to the window that ends there "
        "(b_k < t <= b_{k+1}), not to the one that starts there":
            _rate_left_closed,
        "an event exactly on a window's end edge b_{k+1} belongs to that window: (b_k, b_{k+1}] needs "
        "`t <= b_{k+1}`, not a strict `<`":
            _rate_open,
        "an event exactly on the first edge b_0 opens window 0 (nothing at the start is lost): add it to "
        "the first window's sum":
            _rate_no_first_edge,
        "np.histogram's bins are [b_k, b_{k+1}) (only the last one closed): an event exactly on an inner edge "
        "belongs to the window that ends there, (b_k, b_{k+1}], so count with `(t > b_k) & (t <= b_{k+1})` "
        "or np.searchsorted(boundaries, t, side='left') - 1":
            _rate_histogram,
        "events before b_0 or after b_B belong to no window: drop them (a window index below 0 or above "
        "B - 1), do not clip them into the first or last window":
            _rate_clipped,
        "events before b_0 belong to no window: drop them (t >= b_0) before np.maximum(index, 0), which "
        "would put them in the first window":
            _rate_early_in_first,
        "divide each window's sum by its own length, np.diff(boundaries), not the first window's length (b[1] "
        "- b[0]): the windows differ in length":
            _rate_first_window_length,
        "divide by the window's length in seconds (b_{k+1} - b_k), not by the number of events in it: Eq. 4 is "
        "a rate per second":
            _rate_per_event,
        "divide each window's sum by its own length, not by the whole span b_B - b_0":
            lambda t_events, p_events, C, boundaries: window_sums(t_events, p_events, C, boundaries)
            / (float(np.asarray(boundaries, dtype=np.float64)[-1]) - float(np.asarray(boundaries, dtype=np.float64)[0])),
        "divide by the window length t2 - t1, do not multiply by it":
            lambda t_events, p_events, C, boundaries: window_sums(t_events, p_events, C, boundaries)
            * np.diff(np.asarray(boundaries, dtype=np.float64)),
        "windows are (b_k, b_{k+1}], open on the left: with both ends closed, [b_k, b_{k+1}], an event exactly on "
        "an inner edge counts in two windows":
            _rate_closed_both,
        "an event belongs to the window whose edges hold it, b_k < t <= b_{k+1}, not to the window whose centre is "
        "nearest: where the windows differ in length the centres' half-way points are not the edges":
            _rate_nearest_centre,
        "an edge before the first event has a running sum of 0, but csum[n] with n = -1 reads csum[-1], the total: "
        "prepend a 0 (np.concatenate([[0.0], np.cumsum(p)])) before taking differences at the edges":
            _rate_cumsum_no_leading_zero,
        "an event exactly at the last edge b_B belongs to the last window (b_{B-1}, b_B]: no strict t < b_B at the "
        "end (only the events after b_B are left out)":
            lambda t_events, p_events, C, boundaries: event_rate_derivative(
                np.asarray(t_events)[np.asarray(t_events) < boundaries[-1]],
                np.asarray(p_events)[np.asarray(t_events) < boundaries[-1]], C, boundaries),
        "the running sum of the polarities is a step function (flat between events): np.interp at the edges draws "
        "straight lines between the events and splits an event between two windows; count the events in each "
        "window instead":
            _rate_interpolated_sums,
    })

def _loss_rates(dF_dt, delta_L, durations):
    return torch.mean((delta_L / durations - dF_dt) ** 2)


def _loss_root(dF_dt, delta_L, durations):
    return torch.sqrt(torch.mean((delta_L - dF_dt * durations) ** 2))


def _loss_durations_on_events(dF_dt, delta_L, durations):
    return torch.mean((delta_L * durations - dF_dt) ** 2)


def _loss_mean_duration(dF_dt, delta_L, durations):
    """A wrong version (for the hint): every window's dF/dt times the mean window length."""
    return torch.mean((delta_L - dF_dt * durations.mean()) ** 2)


exercises.register(
    "temporal_loss", temporal_loss, _inputs_loss,
    hints={
        "multiply each window's dF/dt by its own length (durations, elementwise), not by their mean: the windows "
        "differ in length":
            _loss_mean_duration,
        "use the mean over windows, not the sum":
            lambda dF_dt, delta_L, durations: torch.sum((delta_L - dF_dt * durations) ** 2),
        "Eq. 6 is the plain mean of the squared differences: no factor 1/2 in front":
            lambda dF_dt, delta_L, durations: 0.5 * torch.mean((delta_L - dF_dt * durations) ** 2),
        "multiply dF/dt by the window length t2 - t1 before comparing with delta_L (Eq. 5)":
            lambda dF_dt, delta_L, durations: torch.mean((delta_L - dF_dt) ** 2),
        "Eq. 6 squares the difference; an absolute value gives a different loss":
            lambda dF_dt, delta_L, durations: torch.mean(torch.abs(delta_L - dF_dt * durations)),
        "Eq. 5 compares changes: multiply dF/dt by the window length (delta_L - dF_dt * durations); dividing "
        "delta_L by it compares rates and weighs the windows differently":
            _loss_rates,
        "Eq. 6 is the mean of the squares, without a square root (that is the RMS error)":
            _loss_root,
        "multiply dF/dt by the window length, not delta_L: delta_L is already a change over the window":
            _loss_durations_on_events,
        "the mean over B windows divides by B, not B - 1 (that is a sample variance's correction)":
            lambda dF_dt, delta_L, durations: torch.sum((delta_L - dF_dt * durations) ** 2) / (delta_L.numel() - 1),
        "square each window's difference, then average: torch.mean(d ** 2), not torch.mean(d) ** 2 (the brackets)":
            lambda dF_dt, delta_L, durations: torch.mean(delta_L - dF_dt * durations) ** 2,
        "the model's change over a window is +dF/dt * (t2 - t1), the same sign as the events' delta_L: the "
        "residual is delta_L - dF_dt * durations, not delta_L + dF_dt * durations":
            lambda dF_dt, delta_L, durations: torch.mean((delta_L + dF_dt * durations) ** 2),
        "durations[:, None] is a column [B, 1]: against the [B] vectors it broadcasts to a [B, B] table (every "
        "window's dF/dt times every window's length) and the mean runs over B * B entries; keep all three as [B]":
            lambda dF_dt, delta_L, durations: torch.mean((delta_L - dF_dt * durations[:, None]) ** 2),
    })


# ---- how good is the mid-point derivative (Eq. 3)? -------------------------------------

def _derivative(L: Callable, t: np.ndarray, dLdt: Callable | None, h: float = 1e-6) -> np.ndarray:
    if dLdt is not None:
        return np.asarray(dLdt(t), dtype=np.float64)
    return (np.asarray(L(t + h)) - np.asarray(L(t - h))) / (2 * h)


def taylor_error(L: Callable, t_mid, window: float, dLdt: Callable | None = None) -> np.ndarray:
    """|Delta L / (t2 - t1) - dL/dt(mid)| for windows of length ``window`` centred at ``t_mid``:
    the error of Eq. 3 alone (exact Delta L, no events).

    Args:
        L: callable, float [T] seconds -> float [T] log intensity.
        t_mid: float [M] window mid-points (s).
        window: window length t2 - t1 (s).
        dLdt: the exact derivative of L if known (else a central difference is used).

    Returns:
        float64 [M], log units per second.
    """
    _callable(L, "L")
    _callable(dLdt, "dLdt", none_ok=True)
    seconds_array(t_mid, "t_mid", allow_empty=True)
    window = real_number(window, "window", lo=0.0, lo_open=True, hint="the window length t2 - t1 in seconds")
    t_mid = np.asarray(t_mid, dtype=np.float64)
    slope = (np.asarray(L(t_mid + window / 2)) - np.asarray(L(t_mid - window / 2))) / window
    return np.abs(slope - _derivative(L, t_mid, dLdt))


def eq4_error_vs_window(L: Callable, windows, t_range, *, t_events=None, p_events=None, C=None,
                        dLdt: Callable | None = None) -> dict:
    """Mean absolute error of dL/dt estimates at window mid-points, for each window length.

    Windows of each length tile ``t_range`` (whole windows only). Two estimates are compared
    with the true derivative:

    - ``"taylor"``: Eq. 3 with the exact Delta L (error grows like window^2);
    - ``"events"``: Eq. 4 with events (adds the quantisation of Delta L into steps of C,
      an error up to about C / window), when ``t_events``, ``p_events`` and ``C`` are given.

    Returns:
        dict with float64 arrays [K]: ``"window"``, ``"taylor"`` and (with events) ``"events"``.
    """
    _callable(L, "L")
    _callable(dLdt, "dLdt", none_ok=True)
    t0, t1 = _span(t_range)
    windows = seconds_array(windows, "windows", allow_empty=True)
    if (windows <= 0).any():
        raise EventDataError(f"windows= must be window lengths > 0 s, got {windows[windows <= 0][0]:g}")
    out = {"window": windows, "taylor": np.empty_like(windows)}
    with_events = t_events is not None
    if with_events or p_events is not None or C is not None:
        if t_events is None or p_events is None or C is None:
            raise EventDataError("the event estimate needs t_events, p_events and C together (one of them is "
                                 "None); pass all three, or none for the Taylor error alone")
        _contrast(C)
        _pixel_pair(t_events, p_events)
        out["events"] = np.empty_like(windows)
    for k, w in enumerate(windows):
        _window_count(t1 - t0, w)
        n = int(np.floor((t1 - t0) / w + 1e-9))
        if n < 1:
            raise ValueError(f"window {w} s is longer than t_range {t_range}")
        b = t0 + w * np.arange(n + 1)
        mid = 0.5 * (b[1:] + b[:-1])
        true = _derivative(L, mid, dLdt)
        out["taylor"][k] = np.mean(np.abs((np.asarray(L(b[1:])) - np.asarray(L(b[:-1]))) / w - true))
        if with_events:
            out["events"][k] = np.mean(np.abs(event_rate_derivative(t_events, p_events, C, b) - true))
    return out


# ---- a SIREN for one pixel ----------------------------------------------------------------

class TimeSiren1D(nn.Module):
    """F(t): one pixel's log intensity as a SIREN of time.

    Times in seconds are mapped linearly from ``t_range`` to [-1, 1] inside ``forward``, so
    autograd's derivative with respect to the input is dF/dt in log units per second.
    ``offset`` is a constant added to the output (see :meth:`shifted`).

    The defaults (64 wide, 2 hidden layers, omega_0 = 10 as in the public code, first layer
    omega 5) suit a signal with a few oscillations per ``t_range``: a higher first-layer
    frequency lets F match every mid-point derivative exactly while jumping in between.

    Shapes: forward(t [N] seconds) -> [N].
    """

    def __init__(self, t_range, hidden_features: int = 64, hidden_layers: int = 2,
                 omega_0: float = 10.0, first_omega_0: float | None = 5.0):
        super().__init__()
        t0, t1 = _span(t_range)
        self.t_range = (t0, t1)
        self.siren = Siren(1, 1, hidden_features, hidden_layers, omega_0, first_omega_0)
        self.register_buffer("offset", torch.zeros(()))

    def forward(self, t: torch.Tensor) -> torch.Tensor:
        t0, t1 = self.t_range
        s = (t - 0.5 * (t0 + t1)) * (2.0 / (t1 - t0))
        return self.siren(s[:, None])[:, 0] + self.offset

    def predict(self, t) -> np.ndarray:
        """F at times ``t`` (numpy, seconds) as float64 numpy [N]."""
        p = next(self.parameters())
        t = seconds_array(t, "t", allow_empty=True)   # a scalar is one time; text, a 2-D array or NaN are refused here
        with torch.no_grad():
            return self(torch.as_tensor(t, dtype=p.dtype, device=p.device)).double().cpu().numpy()

    def derivative(self, t) -> np.ndarray:
        """dF/dt at times ``t`` (numpy, seconds) as float64 numpy [N]."""
        p = next(self.parameters())
        t = seconds_array(t, "t", allow_empty=True)
        tt = torch.as_tensor(t, dtype=p.dtype, device=p.device).requires_grad_(True)
        return time_derivative(self, tt, create_graph=False).detach().double().cpu().numpy()

    def shifted(self, c: float) -> "TimeSiren1D":
        """A copy computing F(t) + c: the same derivative everywhere, so the same temporal loss."""
        c = real_number(c, "c", hint="a constant in log units added to F")
        new = copy.deepcopy(self)
        with torch.no_grad():
            new.offset += c
        return new


def time_derivative(model: nn.Module, t: torch.Tensor, create_graph: bool = True) -> torch.Tensor:
    """dF/dt at times ``t`` [N] (requires_grad) by autograd; ``create_graph=True`` lets a loss
    on it be back-propagated into the weights (double back-propagation, Eq. 5). -> [N]."""
    if not isinstance(t, torch.Tensor):
        raise ArgumentTypeError(f"t must be a torch tensor [N] that requires grad, got {type(t).__name__}; "
                                f"torch.tensor(t, dtype=torch.float32, requires_grad=True)")
    return input_gradient(model(t), t, create_graph=create_graph)


def _prepare_windows(events, t_range, C, window, pixel):
    C = _contrast(C)
    window = real_number(window, "window", lo=0.0, lo_open=True, hint="the window length in seconds, e.g. 0.025")
    t0, t1 = _span(t_range)
    t_e, p_e = pixel_events(events, pixel)
    _window_count(t1 - t0, window)
    n = max(1, int(round((t1 - t0) / window)))
    b = np.linspace(t0, t1, n + 1)
    return b, window_sums(t_e, p_e, C, b)


def evaluate_temporal_loss(model: TimeSiren1D, events, C: float, window: float, t_range=None,
                           pixel: int = 0, form: str = "derivative") -> float:
    """The temporal loss (Eq. 6, mean over windows) of a fitted model, as a float."""
    _model(model)
    t_range = model.t_range if t_range is None else t_range
    form = _form(form)
    b, dL = _prepare_windows(events, t_range, C, window, pixel)
    p = next(model.parameters())
    kw = dict(dtype=p.dtype, device=p.device)
    pred = _predicted_change(model, torch.as_tensor(b, **kw), form, create_graph=False)
    return float(torch.mean((torch.as_tensor(dL, **kw) - pred.detach()) ** 2))


def _predicted_change(model, b: torch.Tensor, form: str, create_graph: bool) -> torch.Tensor:
    if form == "derivative":  # Eq. 5: dF/dt at the mid-point times the window length
        mid = (0.5 * (b[1:] + b[:-1])).detach().requires_grad_(True)
        return time_derivative(model, mid, create_graph=create_graph) * (b[1:] - b[:-1])
    if form == "difference":  # Eq. 2 directly: F(t2) - F(t1)
        F = model(b)
        return F[1:] - F[:-1]
    raise ValueError(f"form must be 'derivative' (Eq. 5) or 'difference' (F(t2) - F(t1)), got {form!r}")


def bin_residuals(model: TimeSiren1D, boundaries, delta_L) -> dict:
    """How well a fitted F explains each window's events, measured two ways (log units, RMS over windows).

    - ``"slope"``: dF/dt at the mid-point times the window length minus Delta L: what the
      derivative loss (Eq. 5-6) penalises;
    - ``"change"``: F(b_{k+1}) - F(b_k) minus Delta L: what the events actually say about F over
      the window (Eq. 2). A small ``"slope"`` with a large ``"change"`` residual means F has the
      right slope at every mid-point but wanders in between.

    Args:
        model: a fitted :class:`TimeSiren1D`.
        boundaries: float [B + 1] window edges (s).
        delta_L: float [B] summed events per window (:func:`window_sums`).

    Returns:
        dict of floats ``"slope"``, ``"change"``.
    """
    _model(model)
    b = _edges(boundaries)
    dL = np.asarray(delta_L) if not isinstance(delta_L, (str, bytes)) else np.asarray([delta_L])
    if dL.dtype.kind not in "iuf" or dL.ndim != 1 or not np.isfinite(dL).all():
        raise EventDataError(f"delta_L= must be a 1-D array of finite numbers (log units, one per window), got "
                             f"{repr(delta_L)[:60]}")
    dL = dL.astype(np.float64)
    if dL.size != b.size - 1:
        raise EventDataError(f"delta_L= holds {dL.size} value(s) but boundaries= make {b.size - 1} window(s); pass "
                             f"one Delta L per window: window_sums(t_events, p_events, C, boundaries)")
    slope = model.derivative(0.5 * (b[1:] + b[:-1])) * np.diff(b)
    change = np.diff(model.predict(b))
    return {"slope": float(np.sqrt(np.mean((slope - dL) ** 2))),
            "change": float(np.sqrt(np.mean((change - dL) ** 2)))}


def fit_siren_1d(events, t_range, C: float, n_iters: int = 300, window: float = 0.025, seed: int = 0, *,
                 anchor: tuple[float, float] | None = None, prior_mean: float | None = None,
                 anchor_weight: float = 1.0, form: str = "derivative", lr: float = 3e-3,
                 lr_decay: float = 0.98, hidden_features: int = 64, hidden_layers: int = 2, omega_0: float = 10.0,
                 first_omega_0: float | None = 5.0, pixel: int = 0, device=None,
                 ) -> tuple[TimeSiren1D, dict]:
    """Solve Eq. 4 for one pixel: fit F(t) so that dF/dt(mid) * (t2 - t1) matches the summed
    events of every window (Eq. 5-6), by Adam with double back-propagation.

    Args:
        events: ``Events`` with sensor_size (1, P) (``pixel`` picks one), or a (t, p) pair.
        t_range: (t0, t1) seconds covered by the windows.
        C: contrast threshold used to turn events into Delta L.
        n_iters: Adam steps (full batch: every window at every step).
        window: window length (s); the range is cut into round((t1 - t0) / window) equal windows.
        seed: seeds the network's initialisation (the fit is deterministic on CPU).
        anchor: ``(t_a, L_a)``: also penalise ``anchor_weight * (F(t_a) - L_a)^2`` (a known frame).
        prior_mean: also penalise ``anchor_weight * (mean of F over the windows - prior_mean)^2``
            (a prior on the overall brightness instead of a known frame).
        form: ``"derivative"`` (Eq. 5, the paper) or ``"difference"`` (F(t2) - F(t1)).
        lr, lr_decay: Adam learning rate, multiplied by ``lr_decay`` every 10 steps: the form of the
            paper's schedule, not its values (the paper trains whole videos with lr 1e-4, x0.95; the
            defaults 3e-3, x0.98 are this kit's choice for one pixel).
        hidden_features, hidden_layers, omega_0, first_omega_0: the SIREN (see :class:`Siren`).
        device: torch device (default: :func:`evinr_lite.core.runtime.default_device`).

    Without ``anchor`` or ``prior_mean`` nothing fixes F's constant offset: any F + c fits the
    events equally well, and the offset is whatever the initialisation gives.

    Returns:
        (model, history): the fitted :class:`TimeSiren1D` (on CPU) and a dict of per-step lists
        ``"loss"`` (total), ``"temporal"``, ``"anchor"`` and the float ``"seconds"`` spent.
    """
    device = default_device() if device is None else torch.device(device)
    n_iters = whole_number(n_iters, "n_iters", lo=0)
    seed = whole_number(seed, "seed")   # None would leave the fit unrepeatable
    form = _form(form)
    lr = real_number(lr, "lr", lo=0.0, lo_open=True, hint="Adam's learning rate, e.g. 3e-3")
    lr_decay = real_number(lr_decay, "lr_decay", lo=0.0, lo_open=True, hint="the factor every 10 steps, e.g. 0.98")
    anchor_weight = real_number(anchor_weight, "anchor_weight", lo=0.0)
    if anchor is not None:
        try:
            t_a, L_a = anchor
        except (TypeError, ValueError):
            raise EventDataError(f"anchor= must be a pair (t_a, L_a): a time in seconds and the log intensity "
                                 f"there, got {repr(anchor)[:60]}") from None
        anchor = (real_number(t_a, "anchor: t_a"), real_number(L_a, "anchor: L_a"))
    if prior_mean is not None:
        prior_mean = real_number(prior_mean, "prior_mean", hint="a mean log intensity, e.g. np.log(0.5)")
    b, dL = _prepare_windows(events, t_range, C, window, pixel)
    torch.manual_seed(seed)
    model = TimeSiren1D(t_range, hidden_features, hidden_layers, omega_0, first_omega_0).to(device)
    kw = dict(dtype=torch.float32, device=device)
    b_t, dL_t = torch.as_tensor(b, **kw), torch.as_tensor(dL, **kw)
    mid = 0.5 * (b_t[1:] + b_t[:-1])
    opt = torch.optim.Adam(model.parameters(), lr=lr)
    sched = torch.optim.lr_scheduler.StepLR(opt, step_size=10, gamma=lr_decay)
    hist = {"loss": [], "temporal": [], "anchor": []}
    start = time.perf_counter()
    for _ in range(int(n_iters)):
        opt.zero_grad(set_to_none=True)
        temporal = torch.mean((dL_t - _predicted_change(model, b_t, form, create_graph=True)) ** 2)
        extra = torch.zeros((), **kw)
        if anchor is not None:
            t_a, L_a = anchor
            extra = extra + anchor_weight * (model(torch.tensor([float(t_a)], **kw))[0] - float(L_a)) ** 2
        if prior_mean is not None:
            extra = extra + anchor_weight * (model(mid).mean() - float(prior_mean)) ** 2
        loss = temporal + extra
        loss.backward()
        opt.step()
        sched.step()
        hist["loss"].append(loss.item())
        hist["temporal"].append(temporal.item())
        hist["anchor"].append(extra.item())
    hist["seconds"] = time.perf_counter() - start
    return model.cpu().eval(), hist
