"""An ESIM-style event simulator: log-intensity samples in, `Events` out (Sec. 3.1 of the paper).

The model (one pixel; every pixel is independent):

- The pixel remembers a reference level ``L_ref``, at first ``L(t[0])``.
- An ON event (p = +1) fires when ``L`` rises to ``L_ref + C_pos``; an OFF event (p = -1)
  when it falls to ``L_ref - C_neg``. The reference then moves by exactly that step, so a
  pixel fires one event per level crossed, possibly several between two samples.
- Between samples ``L`` is taken to be linear, so the crossing time of a level is found by
  linear interpolation. When ``L`` is a Python function (1-D simulator), each crossing is
  refined by bisection on ``L`` itself, so timestamps are exact to float64 resolution.

What this guarantees (Eq. 2 of the paper): without noise and refractory period, at every
pixel and sample time ``t[k]``,
``L(t[k]) - L(t[0]) - (C_pos * #ON - C_neg * #OFF with t_event <= t[k])`` lies in
``[0, C_pos)`` after a rise and ``(-C_neg, 0]`` after a fall, so always within one threshold.
:func:`evinr_lite.method.integration.integrate_events` computes the event sum.

Non-idealities (all optional, all seeded):

- ``threshold_sigma``: per-pixel threshold mismatch, *relative*: a pixel's ON threshold is
  drawn once from N(C_pos, (threshold_sigma * C_pos)^2) and its OFF threshold independently
  from N(C_neg, (threshold_sigma * C_neg)^2), each clipped below at
  ``MIN_THRESHOLD_FRACTION`` (0.1) times its nominal value. See :func:`sample_thresholds`.
- ``refractory`` (s): an event that comes less than ``refractory`` after the previous
  *emitted* event at its pixel is dropped. ESIM convention: the reference level still moves
  for a dropped event (the change is consumed, not reported), so the integrated events fall
  short of ``L`` by the dropped steps. (v2e instead holds the reference and reports the change
  late.) Noise events are emitted events too: they start a refractory period.
- ``threshold_drift`` (:func:`simulate_scene`): every threshold scaled by a factor linear in time,
  nominal at mid-span (a sensor warming up); the reference moves by the step in force.
- ``noise_rate`` (Hz per pixel): background events, an independent Poisson process per pixel
  with uniform times in ``[t[0], t[-1]]`` and polarity +1 or -1 with probability 1/2.
  They do not move the reference level.

Randomness: ``seed`` is an int or a ``np.random.Generator``. From it the simulator draws, in
this order, the thresholds (only when ``threshold_sigma > 0``, via :func:`sample_thresholds`)
and then the noise (only when ``noise_rate > 0``). The same seed gives identical events.

All three simulators share one core, :func:`_simulate_samples`, which loops over sample
intervals (a Python loop over time) and is vectorised over pixels and events.
"""
from __future__ import annotations

import math
from typing import Callable, Iterable, Iterator

import numpy as np

from ..core.checks import (ArgumentTypeError, check_seconds_precision, decimal_as_float, host_array, is_real_number,
                           optional_seconds, real_number, require, short_repr, whole_number)
from ..core.guard import dense_array
from ..core.events import MAX_SPAN_S, EventDataError, Events

__all__ = ["simulate_events_1d", "pixel_events", "add_background_noise", "add_hot_pixels", "add_light_noise", "simulate_video", "simulate_scene", "sample_thresholds",
           "MIN_THRESHOLD_FRACTION", "MAX_PX_PER_SAMPLE"]

MIN_THRESHOLD_FRACTION = 0.1   # mismatched thresholds are clipped below at this x nominal
MAX_PX_PER_SAMPLE = 0.5        # simulate_scene's default sampling: at most this motion per sample
MAX_SAMPLE_RATE = 1e6          # samples per second: 1 us, the timestamp resolution of event cameras
MIN_C = 1e-3                   # log units; sensors have about 0.05 to 1.5, and events grow as 1 / C
MAX_NOISE_EVENTS = 10**9       # noise events one call may add (about 17 GB of events): beyond, a rate or span is wrong
N_BISECTION = 50               # halvings when refining a crossing of a callable L
_REFINE_CHUNK = 1 << 22        # values of L evaluated per call during refinement (bounds memory)
_SCENE_CHUNK = 1 << 21         # pixels x samples rendered per scene.log_intensity call


# ---- argument checks ---------------------------------------------------------------------

def _as_rng(seed) -> np.random.Generator:
    if isinstance(seed, np.random.Generator):
        return seed
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer)) or seed < 0:
        why = (" (None would draw other events on every call: the simulations are seeded so that they repeat)"
               if seed is None else "")
        raise EventDataError(f"seed must be a whole number >= 0 or a np.random.Generator, got {seed!r}{why}")
    return np.random.default_rng(int(seed))


def _not_complex(value, name: str):
    """``value`` as it is, after refusing complex numbers by name (numpy's cast to float drops the imaginary part
    with only a ComplexWarning, and the events would be those of the real part)."""
    kind = getattr(getattr(host_array(value), "dtype", None), "kind", None)
    if kind is None and isinstance(value, (list, tuple)):
        try:
            kind = np.asarray(value).dtype.kind
        except (TypeError, ValueError):
            kind = None
    if kind == "c" or isinstance(value, complex):
        raise EventDataError(f"{name} are complex numbers; pass real values (e.g. np.real({name.split()[0]}) or "
                             f"np.abs(...), whichever you mean)")
    return value


def _check_times(t) -> np.ndarray:
    t = _not_complex(host_array(t), "t (sample times)")
    check_seconds_precision(t, "t (sample times)")
    t = dense_array(t, "t (sample times)", np.float64, EventDataError)
    if t.ndim != 1 or t.size < 2:
        raise EventDataError(f"sample times t must be a 1-D array of at least 2 times (seconds), got shape {t.shape}")
    if not np.all(np.isfinite(t)):
        raise EventDataError("sample times t contain NaN or inf; pass finite seconds")
    if np.any(np.diff(t) <= 0):
        raise EventDataError("sample times t must be strictly increasing (seconds); sort them and drop duplicates")
    if t[-1] - t[0] > MAX_SPAN_S:   # the events' plausibility rule (check_time_span): not seconds
        raise EventDataError(f"sample times t span {t[-1] - t[0]:,.6g} s ({(t[-1] - t[0]) / 3600:,.3g} hours), longer "
                             f"than any event recording; t is in seconds: divide microseconds by 1e6 (ns by 1e9)")
    return t


def _check_thresholds(C, C_pos, C_neg, *, n_pixels: int | None = None, where: str = "") -> tuple:
    """(C_pos, C_neg), each C where not given: the kit's one rule for a contrast threshold, a finite number > 0 (log
    units) and at least MIN_C. With ``n_pixels`` (:func:`sample_thresholds`) each may also be one per pixel, a 1-D
    array of ``n_pixels`` such numbers (or of one), returned as float64; else floats. ``where``: the caller, before
    the message."""
    alias = "" if n_pixels is not None else " (or C)"
    out = []
    for name, value in (("C_pos", C if C_pos is None else C_pos), ("C_neg", C if C_neg is None else C_neg)):
        value = host_array(value)   # a 0-d array or tensor is a number
        what = f"{where}contrast threshold {name}{alias}"
        per_pixel = n_pixels is not None and not isinstance(value, (str, bytes)) and np.ndim(value) == 1
        if per_pixel:
            arr = np.asarray(value)
            ok = (arr.dtype.kind in "iuf" and len(arr) in (1, n_pixels)
                  and bool(np.all(np.isfinite(arr) & (arr > 0))))
            low = float(arr.min()) if ok and arr.size else None
        else:
            ok = is_real_number(value) and math.isfinite(float(value)) and value > 0
            low = float(value) if ok else None
        if not ok:
            pair = " (for two thresholds pass C_pos= and C_neg=)" if isinstance(value, (tuple, list)) and \
                n_pixels is None else ""
            each = f" (or one per pixel: a 1-D array of {n_pixels} of them)" if n_pixels is not None else ""
            raise EventDataError(f"{what} must be a positive number in log units{each}, got {short_repr(value)}{pair}")
        if low is not None and low < MIN_C:
            raise EventDataError(f"{what} = {low!r} log units is far below any sensor's (about 0.05 to 1.5): each "
                                 f"pixel would fire |change of log intensity| / C events, millions of them; use C >= "
                                 f"{MIN_C:g} (e.g. C=0.2)")
        out.append(np.asarray(value, np.float64) if per_pixel else float(value))
    return tuple(out)


def _noise_span(events, t_start, t_end, *, allow_empty: bool = False) -> tuple[float, float]:
    """(t0, t1) of the noise: ``t_start`` / ``t_end`` (finite seconds) or the events' first / last time; refused
    when the events are empty and a limit is missing, or the span is reversed (or empty, unless ``allow_empty``)."""
    t0, t1 = optional_seconds(t_start, "t_start"), optional_seconds(t_end, "t_end")
    if (t0 is None or t1 is None) and len(events) == 0:
        raise EventDataError("there are no events, so they give no span for the noise; pass t_start= and t_end= "
                             "(seconds) for the span to fill")
    t0 = float(events.t[0]) if t0 is None else t0
    t1 = float(events.t[-1]) if t1 is None else t1
    if not (t1 > t0 or (allow_empty and t1 == t0)):
        raise EventDataError(f"noise span [{t0}, {t1}] s is empty; give t_end > t_start")
    return t0, t1


def _check_noise_count(expected: float, what: str) -> None:
    """Refuse noise whose expected number of events (a rate x a span x pixels) no memory holds."""
    if expected > MAX_NOISE_EVENTS:
        raise EventDataError(f"{what} would add about {expected:,.3g} events (rate x span x pixels), more than "
                             f"{MAX_NOISE_EVENTS:,} fit in memory; the rate is in events per second (per pixel) and "
                             "the span in seconds: check both")


def _check_nonnegative(**values) -> None:
    for name, value in values.items():
        value = host_array(value)
        if not (is_real_number(value) and np.isfinite(value) and value >= 0):
            raise EventDataError(f"{name} must be a finite number >= 0, got {value!r}")


def sample_thresholds(n_pixels: int, C_pos: float, C_neg: float, threshold_sigma: float = 0.0,
                      rng: np.random.Generator | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Per-pixel ON and OFF contrast thresholds.

    With ``threshold_sigma = s > 0``: ON thresholds ~ N(C_pos, (s * C_pos)^2), then OFF
    thresholds ~ N(C_neg, (s * C_neg)^2) (relative mismatch, drawn in that order from ``rng``),
    each clipped below at ``MIN_THRESHOLD_FRACTION`` times its nominal value. With ``s = 0``
    nothing is drawn and every pixel gets the nominal values.

    Returns:
        (C_pos_pix, C_neg_pix): float64 [n_pixels] each, log units.
    """
    n_pixels = whole_number(n_pixels, "sample_thresholds: n_pixels", lo=0)
    C_pos, C_neg = _check_thresholds(None, decimal_as_float(C_pos), decimal_as_float(C_neg), n_pixels=n_pixels,
                                     where="sample_thresholds: ")
    threshold_sigma = real_number(decimal_as_float(threshold_sigma), "sample_thresholds: threshold_sigma", lo=0,
                                  hint="the thresholds' relative spread (0: every pixel the nominal C; e.g. 0.03)")
    if threshold_sigma > 0 and rng is not None and not callable(getattr(rng, "standard_normal", None)):
        raise ArgumentTypeError(f"sample_thresholds: rng= must be Generator-like (a random generator with "
                                f"standard_normal: np.random.default_rng(seed), or np.random.RandomState(seed)), got "
                                f"{type(rng).__name__}")
    C_pos_pix = np.full(n_pixels, C_pos, dtype=np.float64)
    C_neg_pix = np.full(n_pixels, C_neg, dtype=np.float64)
    if threshold_sigma > 0:
        if rng is None:
            raise EventDataError("threshold_sigma > 0 needs a generator: pass rng=np.random.default_rng(seed)")
        C_pos_pix *= 1.0 + threshold_sigma * rng.standard_normal(n_pixels)
        C_neg_pix *= 1.0 + threshold_sigma * rng.standard_normal(n_pixels)
        np.maximum(C_pos_pix, MIN_THRESHOLD_FRACTION * C_pos, out=C_pos_pix)
        np.maximum(C_neg_pix, MIN_THRESHOLD_FRACTION * C_neg, out=C_neg_pix)
    return C_pos_pix, C_neg_pix


# ---- the core: threshold crossings between samples ---------------------------------------

def _expand(pixels: np.ndarray, counts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Repeat pixel i counts[i] times; also return j = 1..counts[i] within each repeat."""
    rep = np.repeat(pixels, counts)
    starts = np.cumsum(counts) - counts
    j = np.arange(rep.size) - np.repeat(starts, counts) + 1
    return rep, j


def _crossings(t: np.ndarray, frames: Iterable[np.ndarray], C_pos: np.ndarray, C_neg: np.ndarray,
               scale: np.ndarray | None = None):
    """All threshold crossings of per-pixel signals sampled at times ``t``.

    Args:
        t: float64 [T] sample times (s), strictly increasing.
        frames: T arrays [P] of log intensity, one per sample time (consumed one at a time,
            so a long video never needs to be in memory at once).
        C_pos, C_neg: float64 [P] thresholds.
        scale: float64 [T] or None: threshold drift, the thresholds during interval (t[k-1], t[k]]
            are ``scale[k] * C_pos`` and ``scale[k] * C_neg`` (the reference then moves by the step
            in force when the event fired, so the events still sum exactly to the change crossed).

    Returns:
        t_ev float64 [N] (linear interpolation), pix int64 [N], p int8 [N],
        level float64 [N] (the level crossed), k int64 [N] (index of the sample that ends the
        interval holding the crossing). Sorted by time (stable).
    """
    it = iter(frames)
    L_prev = np.asarray(next(it), dtype=np.float64).ravel()
    L_init = L_prev.copy()
    n_on = np.zeros(L_init.size, np.int64)     # ON events so far, per pixel
    n_off = np.zeros(L_init.size, np.int64)    # OFF events so far, per pixel
    ref = L_init.copy()                        # = L_init + n_on * C_pos - n_off * C_neg (no drift)
    out = []
    for k in range(1, t.size):
        L_next = np.asarray(next(it), dtype=np.float64).ravel()
        if L_next.shape != L_init.shape:
            raise EventDataError(f"sample {k} has {L_next.size} pixels but sample 0 has {L_init.size}")
        d = L_next - ref
        if scale is not None:
            cp, cn = scale[k] * C_pos, scale[k] * C_neg
            up, down = np.floor(d / cp), np.floor(-d / cn)
            parts = _drifting_parts(t, k, L_prev, L_next, ref, up, down, cp, cn)
            L_prev = L_next
            if parts:
                t_ev, rep, p, level = (np.concatenate(c) for c in zip(*parts))
                order = np.argsort(t_ev, kind="stable")
                out.append((t_ev[order], rep[order], p[order], level[order], np.full(rep.size, k, np.int64)))
            continue
        up = np.floor(d / C_pos)
        down = np.floor(-d / C_neg)
        parts = []
        for sign, steps, C in ((1, up, C_pos), (-1, down, C_neg)):
            pixels = np.flatnonzero(steps > 0)
            if pixels.size == 0:
                continue
            counts = steps[pixels].astype(np.int64)
            rep, j = _expand(pixels, counts)
            if sign > 0:
                level = L_init[rep] + (n_on[rep] + j) * C_pos[rep] - n_off[rep] * C_neg[rep]
                n_on[pixels] += counts
            else:
                level = L_init[rep] + n_on[rep] * C_pos[rep] - (n_off[rep] + j) * C_neg[rep]
                n_off[pixels] += counts
            ref[pixels] = L_init[pixels] + n_on[pixels] * C_pos[pixels] - n_off[pixels] * C_neg[pixels]
            a, b = L_prev[rep], L_next[rep]
            frac = np.clip((level - a) / (b - a), 0.0, 1.0)
            t_ev = t[k - 1] + frac * (t[k] - t[k - 1])
            parts.append((t_ev, rep, np.full(rep.size, sign, np.int8), level))
        if parts:
            t_ev, rep, p, level = (np.concatenate(c) for c in zip(*parts))
            order = np.argsort(t_ev, kind="stable")
            out.append((t_ev[order], rep[order], p[order], level[order], np.full(rep.size, k, np.int64)))
        L_prev = L_next
    if not out:
        e = np.zeros(0)
        return e, e.astype(np.int64), e.astype(np.int8), e, e.astype(np.int64)
    return tuple(np.concatenate(c) for c in zip(*out))


def _drifting_parts(t, k, L_prev, L_next, ref, up, down, cp, cn) -> list:
    """One sample interval of :func:`_crossings` with thresholds ``cp``/``cn`` [P] in force there;
    ``ref`` [P] moves in place by the steps taken (levels are ref + j * step, so they chain exactly)."""
    parts = []
    for sign, steps, C in ((1, up, cp), (-1, down, cn)):
        pixels = np.flatnonzero(steps > 0)
        if pixels.size == 0:
            continue
        counts = steps[pixels].astype(np.int64)
        rep, j = _expand(pixels, counts)
        level = ref[rep] + sign * j * C[rep]
        ref[pixels] += sign * counts * C[pixels]
        a, b = L_prev[rep], L_next[rep]
        frac = np.clip((level - a) / (b - a), 0.0, 1.0)
        parts.append((t[k - 1] + frac * (t[k] - t[k - 1]), rep, np.full(rep.size, sign, np.int8), level))
    return parts


def _refine(L: Callable, n_pixels: int, t: np.ndarray, pix, p, level, k) -> np.ndarray:
    """Bisection on a callable ``L`` for each crossing inside its sample interval [t[k-1], t[k]].

    g(s) = p * (L(s) - level) is < 0 at t[k-1] and >= 0 at t[k] (the simulator's invariant), so
    halving keeps a bracket of the crossing. Cost: N_BISECTION calls of L on all N event times,
    each returning [N, P] (in chunks, to bound memory). Returns float64 [N] refined times.
    """
    lo, hi = t[k - 1], t[k]
    for _ in range(N_BISECTION):
        mid = 0.5 * (lo + hi)
        below = p * (_eval_at(L, mid, pix, n_pixels) - level) < 0
        lo = np.where(below, mid, lo)
        hi = np.where(below, hi, mid)
    return hi


def _eval_at(L: Callable, s: np.ndarray, pix: np.ndarray, n_pixels: int) -> np.ndarray:
    """L at times s [N], reading pixel pix[i] at time s[i] -> float64 [N]."""
    out = np.empty(s.size)
    chunk = max(1, _REFINE_CHUNK // n_pixels)
    for i in range(0, s.size, chunk):
        si = s[i:i + chunk]
        v = np.asarray(host_array(L(si)), dtype=np.float64).reshape(si.size, n_pixels)
        out[i:i + chunk] = v[np.arange(si.size), pix[i:i + chunk]]
    return out


def _noise(n_pixels: int, t0: float, t1: float, rate: float, rng: np.random.Generator):
    """Poisson background events: per-pixel counts ~ Poisson(rate * (t1 - t0)), uniform times."""
    counts = rng.poisson(rate * (t1 - t0), size=n_pixels)
    pix = np.repeat(np.arange(n_pixels, dtype=np.int64), counts)
    t_ev = t0 + (t1 - t0) * rng.random(pix.size)
    p = np.where(rng.random(pix.size) < 0.5, -1, 1).astype(np.int8)
    return t_ev, pix, p


def _refractory_keep(t_ev: np.ndarray, pix: np.ndarray, refractory: float) -> np.ndarray:
    """Mask [N] of events kept by a per-pixel refractory period (greedy in time).

    An event is kept if it comes at least ``refractory`` seconds after the previous *kept* event
    of its pixel. Vectorised over pixels: each pass of the loop jumps every pixel to its next
    kept event, so the loop runs (max kept events per pixel) times. The jump is an exact
    integer search on the key (pixel, rank of the time among all times).
    """
    n = t_ev.size
    order = np.lexsort((t_ev, pix))
    ts, ps = t_ev[order], pix[order].astype(np.int64)
    t_all = np.sort(t_ev)
    key = ps * (n + 1) + np.searchsorted(t_all, ts, side="left")
    cur = np.flatnonzero(np.r_[True, ps[1:] != ps[:-1]])     # first event of every pixel
    keep_sorted = np.zeros(n, bool)
    while cur.size:
        keep_sorted[cur] = True
        target = ps[cur] * (n + 1) + np.searchsorted(t_all, ts[cur] + refractory, side="left")
        nxt = np.maximum(np.searchsorted(key, target, side="left"), cur + 1)
        ok = nxt < n
        cur, nxt = cur[ok], nxt[ok]
        cur = nxt[ps[nxt] == ps[cur]]
    keep = np.empty(n, bool)
    keep[order] = keep_sorted
    return keep


def _simulate_samples(t, frames, n_pixels, C_pos, C_neg, threshold_sigma, refractory, noise_rate, rng,
                      L_callable=None, threshold_drift: float = 0.0):
    """Shared core of the 1-D and 2-D simulators.

    Args:
        t: float64 [T] sample times (s). frames: T arrays [P] (log intensity at t[k]).
        n_pixels: P. C_pos, C_neg: nominal thresholds. threshold_sigma, refractory (s),
        noise_rate (Hz per pixel): see the module docstring. rng: np.random.Generator.
        L_callable: if given, crossings are refined by bisection on it (see :func:`_refine`).
        threshold_drift: relative change of every threshold over [t[0], t[-1]], linear in time:
            thresholds x (1 + threshold_drift * ((t - t[0]) / (t[-1] - t[0]) - 1/2)), so the
            nominal values hold at mid-recording (0: no drift).

    Returns:
        t_ev float64 [N] sorted, pix int64 [N] (flat pixel index), p int8 [N].
    """
    C_pos_pix, C_neg_pix = sample_thresholds(n_pixels, C_pos, C_neg, threshold_sigma, rng)
    scale = None
    if threshold_drift:
        scale = 1.0 + threshold_drift * ((t - t[0]) / (t[-1] - t[0]) - 0.5)
        if np.any(scale < MIN_THRESHOLD_FRACTION):
            raise EventDataError(f"threshold_drift {threshold_drift} takes the thresholds below "
                                 f"{MIN_THRESHOLD_FRACTION} x nominal; use |threshold_drift| < 1.8")
    t_ev, pix, p, level, k = _crossings(t, frames, C_pos_pix, C_neg_pix, scale)
    if L_callable is not None and t_ev.size:
        t_ev = _refine(L_callable, n_pixels, t, pix, p, level, k)
    if noise_rate > 0:
        tn, pn, poln = _noise(n_pixels, t[0], t[-1], noise_rate, rng)
        t_ev, pix, p = np.concatenate([t_ev, tn]), np.concatenate([pix, pn]), np.concatenate([p, poln])
    order = np.argsort(t_ev, kind="stable")          # nearly sorted already: cheap
    t_ev, pix, p = t_ev[order], pix[order], p[order]
    if refractory > 0 and t_ev.size:
        keep = _refractory_keep(t_ev, pix, refractory)
        t_ev, pix, p = t_ev[keep], pix[keep], p[keep]
    return t_ev, pix, p


# ---- public simulators --------------------------------------------------------------------

def simulate_events_1d(L, t, C=0.2, *, C_pos=None, C_neg=None, threshold_sigma=0.0, refractory=0.0,
                       noise_rate=0.0, seed=0, refine=True) -> Events:
    """Events of P independent pixels whose log intensities are 1-D signals of time.

    Args:
        L: either a function ``L(s)`` taking an array of times [M] (s) and returning log
            intensities [M] (one pixel) or [M, P]; or the samples themselves, an array [T] or
            [T, P] at the times ``t``.
        t: float64 [T] sample times in seconds, strictly increasing. Crossings are found
            between consecutive samples, so sample finely enough that L is monotone between
            samples (each crossing of the sampled signal is one event).
        C: contrast threshold (log units), used for both polarities unless ``C_pos`` /
            ``C_neg`` are given.
        threshold_sigma: relative per-pixel threshold mismatch (see :func:`sample_thresholds`).
        refractory: seconds; events closer than this to the previous emitted event of their
            pixel are dropped (the reference still moves: ESIM convention).
        noise_rate: background events per pixel per second (Poisson, random polarity).
        seed: int or np.random.Generator.
        refine: when L is a function, refine each crossing by bisection on L (exact time
            to ~1e-15 s relative; costs 50 calls of L on all event times). Ignored for samples.

    Returns:
        Events on a sensor of size (1, P): y = 0, x = pixel index, sorted by time, all
        times in [t[0], t[-1]]. The reference level starts at L(t[0]) per pixel.
    """
    t = _check_times(t)
    if not isinstance(refine, (bool, np.bool_)):   # "no" is truthy: it would refine
        raise EventDataError(f"refine must be True or False, got {refine!r}")
    what = "L(t)" if callable(L) else "L"
    samples = dense_array(_not_complex(L(t) if callable(L) else L, what), what, np.float64, EventDataError,
                          want="one value per time [T] or [T, P] for P pixels")
    if samples.ndim == 1:
        samples = samples[:, None]
    if samples.ndim != 2 or samples.shape[0] != t.size:
        what = "L(t)" if callable(L) else "L"
        raise EventDataError(
            f"{what} has shape {samples.shape} but t has {t.size} samples; L must give [T] (one pixel) "
            "or [T, P] values (P pixels), one row per sample time")
    if not np.all(np.isfinite(samples)):
        raise EventDataError("L contains NaN or inf; log intensities must be finite (clip intensities above 0 before the log)")
    C_pos, C_neg = _check_thresholds(C, C_pos, C_neg)
    _check_nonnegative(threshold_sigma=threshold_sigma, refractory=refractory, noise_rate=noise_rate)
    P = samples.shape[1]
    t_ev, pix, p = _simulate_samples(
        t, iter(samples), P, C_pos, C_neg, threshold_sigma, refractory, noise_rate, _as_rng(seed),
        L_callable=L if (callable(L) and refine) else None)
    return Events(t_ev, pix.astype(np.int32), np.zeros(pix.size, np.int32), p, (1, P))


def pixel_events(events, pixel: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(t, p) of one pixel: from an ``Events`` with sensor_size (1, P) (x = pixel index), or a
    ``(t, p)`` pair of arrays passed through (as float64 [N] each; ``([], [])`` is no events). Anything
    else (None, ``[]``, an [N, 2] array) is an ArgumentTypeError, and a pair whose t and p differ in
    length an EventDataError, each naming the fix."""
    pixel = whole_number(pixel, "pixel", lo=0)   # 1.5 matched no event, "0" was Python's TypeError
    if isinstance(events, Events):
        H, W = events.sensor_size
        if H != 1:
            raise EventDataError(f"1-D helpers expect events with sensor_size (1, P), got {(H, W)}")
        if not 0 <= pixel < W:
            raise EventDataError(f"pixel {pixel} is outside the {W} pixels of these events")
        keep = events.x == pixel
        return events.t[keep], events.p[keep].astype(np.float64)
    want = "an Events with sensor_size (1, P) or a (t, p) pair of arrays (([], []) for no events)"
    if events is None:
        raise ArgumentTypeError(f"events is None; pass {want}")
    try:
        t, p = events
    except (TypeError, ValueError):   # said "a (t, p) pair" of [], of an [N, 2] array, of (t, p, x): which fix?
        raise ArgumentTypeError(f"events must be {want}, got {_what(events)}") from None
    if pixel != 0:   # a pair is one pixel's events: the pixel would be ignored
        raise EventDataError(f"pixel={pixel} picks a pixel of an Events with sensor_size (1, P); a (t, p) pair is "
                             "the events of one pixel already: leave pixel out (or pass the Events)")
    t = np.ravel(dense_array(t, "events: t", error=EventDataError))
    p = np.ravel(dense_array(p, "events: p", error=EventDataError))
    if t.dtype.kind not in "iuf" or p.dtype.kind not in "iufb":
        raise EventDataError(f"events: t and p must be numbers (seconds and polarities), got dtypes {t.dtype} and "
                             f"{p.dtype}")
    t, p = t.astype(np.float64), p.astype(np.float64)
    if t.shape != p.shape:   # plot_signal_and_events stopped on numpy's boolean-index error
        raise EventDataError(f"events: {t.size} event time(s) but {p.size} polarities; pass one polarity per event")
    finite = np.isfinite(t)
    if not finite.all():
        bad = int(np.flatnonzero(~finite)[0])
        raise EventDataError(f"events: t[{bad}] is {t[bad]}; event times must be finite seconds: drop or repair it")
    return t, p


def _what(events) -> str:
    """What :func:`pixel_events` was given instead of events, with the fix for an array of columns."""
    shape = getattr(events, "shape", None)
    if shape is not None:
        fix = "; columns [N, 2] are (events[:, 0], events[:, 1])" if len(shape) == 2 and shape[1] == 2 else ""
        return f"an array of shape {tuple(shape)}{fix}"
    if not hasattr(events, "__len__"):
        return type(events).__name__
    n = len(events)
    return f"an empty {type(events).__name__}" if n == 0 else f"a {type(events).__name__} of {n} items"


def _check_video(log_frames, t) -> tuple[np.ndarray, np.ndarray]:
    t = _check_times(t)
    log_frames = dense_array(log_frames, "log_frames", error=EventDataError,
                             want="frames of one shape, stacked [T, H, W] (np.stack(frames))")
    if log_frames.ndim != 3 or log_frames.shape[0] != t.size:
        raise EventDataError(
            f"log_frames must have shape [T, H, W] with T = len(t) = {t.size}, got {log_frames.shape}")
    if log_frames.dtype.kind not in "fiu":
        raise EventDataError(f"log_frames must be numbers (log intensity), got dtype {log_frames.dtype}")
    if log_frames.dtype in (np.uint8, np.uint16):   # camera images, not their log
        raise EventDataError(f"log_frames are {log_frames.dtype} (images as a camera stores them), not log intensities; "
                             f"pass np.log(frames / {np.iinfo(log_frames.dtype).max} + 1e-3) (float)")
    if not np.all(np.isfinite(log_frames)):
        raise EventDataError("log_frames contain NaN or inf; take the log of intensities clipped above 0")
    return log_frames, t


def _video_events(t, frames: Iterable[np.ndarray], sensor_size, C, C_pos, C_neg, threshold_sigma,
                  refractory, noise_rate, seed, threshold_drift=0.0) -> Events:
    C_pos, C_neg = _check_thresholds(C, C_pos, C_neg)
    _check_nonnegative(threshold_sigma=threshold_sigma, refractory=refractory, noise_rate=noise_rate)
    threshold_sigma, refractory, noise_rate = (float(host_array(v)) for v in (threshold_sigma, refractory, noise_rate))
    if not (is_real_number(threshold_drift) and np.isfinite(threshold_drift)):
        raise EventDataError(f"threshold_drift must be a finite relative change, got {threshold_drift!r}")
    H, W = sensor_size
    t_ev, pix, p = _simulate_samples(t, frames, H * W, C_pos, C_neg, threshold_sigma, refractory,
                                     noise_rate, _as_rng(seed), threshold_drift=float(threshold_drift))
    y, x = np.divmod(pix, W)
    return Events(t_ev, x.astype(np.int32), y.astype(np.int32), p, (H, W))


def simulate_video(log_frames, t, C=0.2, *, C_pos=None, C_neg=None, threshold_sigma=0.0, refractory=0.0,
                   noise_rate=0.0, seed=0) -> Events:
    """Events of a video given as log-intensity frames (ESIM-style).

    Args:
        log_frames: [T, H, W] log intensities at the times ``t`` (any float dtype; computed in
            float64 one frame at a time). Between frames, each pixel's L is linear, so a pixel can
            fire several events per frame interval, with linearly interpolated timestamps.
        t: float64 [T] sample times (s), strictly increasing.
        C, C_pos, C_neg, threshold_sigma, refractory, noise_rate, seed: as in
            :func:`simulate_events_1d`.

    Returns:
        Events on a sensor of size (H, W), sorted by time, within [t[0], t[-1]].
    """
    log_frames, t = _check_video(log_frames, t)
    H, W = log_frames.shape[1:]
    frames = (f.reshape(-1) for f in log_frames)
    return _video_events(t, frames, (H, W), C, C_pos, C_neg, threshold_sigma, refractory, noise_rate, seed)


def _scene_frames(scene, t: np.ndarray) -> Iterator[np.ndarray]:
    """scene.log_intensity at times t, rendered in chunks and yielded one flat frame [H*W] at a time."""
    H, W = scene.sensor_size
    chunk = max(1, _SCENE_CHUNK // (H * W))
    for i in range(0, t.size, chunk):
        block = np.asarray(scene.log_intensity(t[i:i + chunk]), dtype=np.float64)
        if not np.all(np.isfinite(block)):
            raise EventDataError(f"scene.log_intensity returned NaN or inf near t = {t[i]:.6f} s")
        yield from block.reshape(block.shape[0], H * W)


def simulate_scene(scene, t_start=0.0, t_end=None, *, sample_rate=None, C=0.2, **kwargs) -> Events:
    """Events of a synthetic scene (see :mod:`evinr_lite.sim.scenes`) between t_start and t_end.

    Args:
        scene: a Scene (``sensor_size``, ``duration``, ``log_intensity(t)``, ``max_speed``).
        t_start, t_end: seconds; ``t_end`` defaults to ``scene.duration``.
        sample_rate: samples per second of ``scene.log_intensity``. Default:
            ``scene.max_speed / MAX_PX_PER_SAMPLE`` so the image moves at most 0.5 px between
            samples (at least 100 Hz), which keeps the linear interpolation between samples accurate.
        C: contrast threshold; ``**kwargs`` go on to :func:`simulate_video` (C_pos, C_neg,
            threshold_sigma, refractory, noise_rate, seed), and ``threshold_drift``: the relative
            change of every threshold over [t_start, t_end], linear in time, nominal at mid-span
            (e.g. 0.3: from 0.85x to 1.15x, as a sensor warming up; default 0).

    Returns:
        Events on ``scene.sensor_size``. Frames are rendered in chunks, never all at once.
    """
    missing = [a for a in ("sensor_size", "duration", "log_intensity", "max_speed") if not hasattr(scene, a)]
    if missing:
        raise EventDataError(f"scene= must be a Scene (it has no {', '.join(missing)}), got {type(scene).__name__}; "
                             f"build one with make_scene(name, sensor_size=(H, W), duration=seconds)")
    t_end = scene.duration if t_end is None else t_end
    if not (is_real_number(t_start) and is_real_number(t_end)):
        raise EventDataError(f"t_start and t_end must be seconds (numbers), got {t_start!r} and {t_end!r}")
    t_start, t_end = float(host_array(t_start)), float(host_array(t_end))   # 0-d arrays and tensors too
    if not (np.isfinite(t_start) and np.isfinite(t_end) and t_end > t_start):
        raise EventDataError(f"time range [{t_start}, {t_end}] s is empty or reversed; t_end must exceed t_start")
    if sample_rate is None:
        sample_rate = max(100.0, float(scene.max_speed) / MAX_PX_PER_SAMPLE)
    if not (is_real_number(sample_rate) and np.isfinite(sample_rate) and sample_rate > 0):
        raise EventDataError(f"sample_rate must be a positive number of samples per second, got {sample_rate!r}")
    sample_rate = float(host_array(sample_rate))
    if sample_rate > MAX_SAMPLE_RATE:
        raise EventDataError(f"sample_rate={sample_rate!r} samples per second is finer than the 1 us timestamps of event "
                             f"cameras and would render {sample_rate * (t_end - t_start):,.0f} frames; use at most "
                             f"{MAX_SAMPLE_RATE:g} (or None: fine enough that the image moves at most "
                             f"{MAX_PX_PER_SAMPLE} px between samples)")
    n = max(2, int(np.ceil((t_end - t_start) * sample_rate - 1e-9)) + 1)
    t = np.linspace(t_start, t_end, n)
    unknown = set(kwargs) - {"C_pos", "C_neg", "threshold_sigma", "refractory", "noise_rate", "seed",
                             "threshold_drift"}
    if unknown:
        raise TypeError(f"simulate_scene got unexpected arguments {sorted(unknown)}; it accepts C_pos, C_neg, "
                        "threshold_sigma, refractory, noise_rate, seed, threshold_drift")
    opts = dict(C_pos=None, C_neg=None, threshold_sigma=0.0, refractory=0.0, noise_rate=0.0, seed=0,
                threshold_drift=0.0)
    opts.update(kwargs)
    return _video_events(t, _scene_frames(scene, t), tuple(scene.sensor_size), C, **opts)


# ---- sensor noise added to simulated events ------------------------------------------------

def add_background_noise(events: Events, rate_hz: float, seed=0, t_start: float | None = None,
                         t_end: float | None = None, *, return_labels: bool = False):
    """The events plus background noise: per pixel a Poisson process of ``rate_hz`` events per second,
    uniform times in [t_start, t_end] (default: the events' span), polarity +1 or -1 with probability 1/2.

    Args:
        seed: int or np.random.Generator.
        return_labels: also return ``added``, bool [N_out], True for the noise events this call added
            (the truth for measuring a denoiser). The same seed gives the same events either way.

    Returns:
        The merged events (sorted by time, stable: the input events keep their order, so labels of
        the input carry over as ``labels_out[~added] = labels_in``); with ``return_labels``,
        ``(events, added)``.
    """
    events = require(events, Events, "events")
    rate_hz = _rate(rate_hz, "rate_hz", "events per pixel per second")
    rng = _as_rng(seed)
    t0, t1 = _noise_span(events, t_start, t_end)
    H, W = events.sensor_size
    _check_noise_count(rate_hz * (t1 - t0) * H * W, "add_background_noise")
    counts = rng.poisson(rate_hz * (t1 - t0), size=H * W)
    pix = np.repeat(np.arange(H * W), counts)
    t = t0 + (t1 - t0) * rng.random(pix.size)
    p = np.where(rng.random(pix.size) < 0.5, -1, 1)
    noise = Events.from_arrays(t, pix % W, pix // W, p, (H, W), sort=True, t_origin=events.t_origin)
    return _merge(events, noise, return_labels)


def _rate(value, name: str, unit: str) -> float:
    """A rate (``unit``) as a float: a finite number >= 0 (a 0-d array or tensor too); else an EventDataError."""
    value = host_array(value)
    if not (is_real_number(value) and np.isfinite(value) and value >= 0):
        raise EventDataError(f"{name} must be a finite number >= 0 ({unit}), got {value!r}")
    return float(value)


def _merge(events: Events, noise: Events, return_labels: bool):
    """Events.concatenate([events, noise]), and optionally the bool [N] mask of the noise events in it."""
    merged = Events.concatenate([events, noise])
    if not return_labels:
        return merged
    # concatenate sorts the joined times stably; the same sort of the joined labels follows them
    order = np.argsort(np.concatenate([events.t, noise.t]), kind="stable")
    added = np.concatenate([np.zeros(len(events), bool), np.ones(len(noise), bool)])[order]
    return merged, added


def add_hot_pixels(events: Events, n_pixels: int, rate_hz: float, seed=0, t_start: float | None = None,
                   t_end: float | None = None, *, return_labels: bool = False, on_only: bool = False):
    """The events plus ``n_pixels`` hot pixels, each firing a Poisson process of ``rate_hz`` events
    per second over [t_start, t_end] (default: the events' span), nearly all of one polarity (90 %,
    the pixel's own sign), as a stuck or leaky DVS pixel does.

    Args:
        on_only: every hot-pixel event is ON (+1), as a leaky pixel's reset does on real DVS
            sensors: integrated, each hot pixel then climbs without bound. The same random draws
            are made either way, so the pixels and times do not change with this flag.
        return_labels: also return ``added``, bool [N_out], True for the hot-pixel events this call
            added (the events the input already had at those pixels stay False).

    Returns:
        (events, hot): the merged events and the hot pixels' flat indices y * W + x (int64 [n_pixels]);
        with ``return_labels``, (events, hot, added). The input events keep their order (stable merge).
    """
    events = require(events, Events, "events")
    rate_hz = _rate(rate_hz, "rate_hz", "events per second")
    rng = _as_rng(seed)
    H, W = events.sensor_size
    n_pixels = whole_number(n_pixels, "n_pixels", lo=0, hi=H * W)
    t0, t1 = _noise_span(events, t_start, t_end, allow_empty=True)
    _check_noise_count(rate_hz * (t1 - t0) * n_pixels, "add_hot_pixels")
    hot = np.sort(rng.choice(H * W, size=n_pixels, replace=False)).astype(np.int64)
    sign = np.where(rng.random(hot.size) < 0.5, -1, 1)
    counts = rng.poisson(rate_hz * (t1 - t0), size=hot.size)
    pix = np.repeat(hot, counts)
    t = t0 + (t1 - t0) * rng.random(pix.size)
    p = np.repeat(sign, counts) * np.where(rng.random(pix.size) < 0.9, 1, -1)
    if on_only:
        p = np.ones_like(p)
    noise = Events.from_arrays(t, pix % W, pix // W, p, (H, W), sort=True, t_origin=events.t_origin)
    if return_labels:
        merged, added = _merge(events, noise, True)
        return merged, hot, added
    return _merge(events, noise, False), hot


def add_light_noise(events: Events, scene, rate_hz: float, seed=0, t_start: float | None = None,
                    t_end: float | None = None, *, max_gain: float = 30.0, n_frames_per_s: float = 20.0,
                    return_labels: bool = False):
    """The events plus background activity that grows as light falls: at pixel x and time t, a Poisson
    process of ``rate_hz * min(1 / I(t, x), max_gain)`` events per second (I = exp(L) the scene's
    intensity, 1 = full scale), polarity +1 or -1 with probability 1/2. DVS leak and shot noise rise in
    the dark, so a dimming scene gets noisier exactly where and when it is darkest.

    Drawn by thinning: candidates at the top rate ``rate_hz * max_gain``, each kept with probability
    gain(t, x) / max_gain, with I read from the scene rendered ``n_frames_per_s`` times a second
    (nearest frame; light changes slowly next to events).

    Args:
        scene: the :class:`~evinr_lite.sim.scenes.Scene` the events came from (sensor size must match).
        rate_hz: events per pixel per second at full scale (I = 1). seed: int or np.random.Generator.
        return_labels: also return ``added``, bool [N_out], True for the events this call added.

    Returns:
        The merged events (stable merge), with ``return_labels`` ``(events, added)``.
    """
    events = require(events, Events, "events")
    rate_hz = _rate(rate_hz, "rate_hz", "events per pixel per second")
    max_gain = host_array(max_gain)
    if not (is_real_number(max_gain) and np.isfinite(max_gain) and max_gain >= 1):
        raise EventDataError(f"max_gain must be a number >= 1 (the noise's largest factor), got {max_gain!r}")
    max_gain = float(max_gain)
    n_frames_per_s = real_number(n_frames_per_s, "n_frames_per_s", lo=0, lo_open=True,
                                 hint="the scene's frames per second that set the light (e.g. 20)")
    if not all(hasattr(scene, a) for a in ("sensor_size", "log_intensity")):
        raise EventDataError(f"scene= must be a Scene (the one the events came from: its light sets the noise), got "
                             f"{type(scene).__name__}")
    if tuple(scene.sensor_size) != tuple(events.sensor_size):
        raise EventDataError(f"scene sensor_size {tuple(scene.sensor_size)} != events' {tuple(events.sensor_size)}")
    rng = _as_rng(seed)
    t0, t1 = _noise_span(events, t_start, t_end)
    H, W = events.sensor_size
    _check_noise_count(rate_hz * max_gain * (t1 - t0) * H * W, "add_light_noise")
    counts = rng.poisson(rate_hz * max_gain * (t1 - t0), size=H * W)
    pix = np.repeat(np.arange(H * W), counts)
    t = t0 + (t1 - t0) * rng.random(pix.size)
    n_frames = max(2, int(np.ceil((t1 - t0) * n_frames_per_s)) + 1)
    ft = np.linspace(t0, t1, n_frames)
    k = np.clip(np.rint((t - t0) / (t1 - t0) * (n_frames - 1)).astype(np.int64), 0, n_frames - 1)
    gain = np.empty(pix.size)
    order = np.argsort(k, kind="stable")
    bounds = np.searchsorted(k[order], np.arange(n_frames + 1))
    for i in range(n_frames):                       # one frame at a time: bounded memory on long scenes
        sel = order[bounds[i]:bounds[i + 1]]
        if sel.size:
            L = np.asarray(scene.log_intensity(ft[i]), dtype=np.float64).ravel()
            gain[sel] = np.minimum(np.exp(-L[pix[sel]]), max_gain)
    keep = rng.random(pix.size) * max_gain < gain
    pix, t = pix[keep], t[keep]
    p = np.where(rng.random(pix.size) < 0.5, -1, 1)
    noise = Events.from_arrays(t, pix % W, pix // W, p, (H, W), sort=True, t_origin=events.t_origin)
    return _merge(events, noise, return_labels)
