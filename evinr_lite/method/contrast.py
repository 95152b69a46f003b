"""The contrast thresholds fitted from a recording's frames: ΔL ≈ C+ n+ - C- n- between frames.

Events fire each time a pixel's log intensity moves by a threshold (up by C+ for an ON event, down
by C- for an OFF one), so between two APS frames the ON and OFF counts n+ and n- and the frames'
log change ΔL satisfy ΔL ≈ C+ n+ - C- n- on well-exposed pixels, up to the part of a step not yet
completed at either frame (less than one threshold).

- :func:`frame_log_changes` collects (ΔL, n) pairs with the net count n = n+ - n- and
  :func:`estimate_contrast_threshold` fits one C by least squares (notebooks 09 and 11);
- :func:`frame_event_counts` keeps n+ and n- apart; :func:`fit_contrast` fits C+ and C- with a
  seeded bootstrap and returns a :class:`ContrastFit` (``print(fit)``; ``EvINRConfig(C=fit.C)``).

How :func:`fit_contrast` is robust, and why (each choice measured on the zoo, table below):

- span "trajectory": each pixel's log intensity at every frame against its cumulative counts, with
  one free offset per pixel. Consecutive pairs ("pairs") are biased low: most pairs hold one or two
  events, and the unfinished step (up to one C at each end) is then as large as the signal.
- pixels with fewer than ``min_events`` events over the frames used carry no information about C
  (ΔL ≈ 0 with n = 0) and are dropped; dark and saturated samples are masked (``exposed``).
- Huber weights: hot pixels fire without any brightness change (outliers in ΔL - fit).
- method "iv": background activity adds ON and OFF events that no brightness change caused; noise in
  the counts biases every least-squares fit towards 0 (by 11-12 % at 0.5 Hz on noisy_gravel, by
  23 % without Huber weights). The mean count of the 4 neighbours is used as an instrument (it
  follows the same image, but not this pixel's noise), which removes that bias at the price of a
  small upward one (+1 to +5 %) on clean scenes.
- the bootstrap resamples blocks of 16 x 16 pixels (neighbours share texture and motion), its
  standard errors measure sampling noise only, not the model biases above (a few %).

Zoo scenes (``evinr_lite.sim.zoo``), true vs fitted C+ / C- with the defaults (trajectory, iv), APS
frames = the scene's intensity at 20 frames/s as uint8 (``python benchmarks/contrast_fit.py``)::

    scene               true C+  true C-  fitted C+       fitted C-       error C+  error C-
    camera_translate     0.200    0.200   0.208 ± 0.001   0.203 ± 0.001    +3.8 %   +1.3 %
    astronaut_rotzoom    0.200    0.200   0.201 ± 0.000   0.201 ± 0.000    +0.6 %   +0.7 %
    coffee_warp          0.240    0.160   0.246 ± 0.001   0.163 ± 0.001    +2.3 %   +1.7 %
    chelsea_speed        0.200    0.200   0.209 ± 0.001   0.203 ± 0.001    +4.6 %   +1.6 %
    object_static_cam    0.200    0.200   0.198 ± 0.000   0.203 ± 0.000    -1.1 %   +1.3 %
    lowtex_light         0.200    0.200   0.218 ± 0.008   0.191 ± 0.015    +8.9 %   -4.6 %
    noisy_gravel         0.220    0.180   0.235 ± 0.000   0.190 ± 0.000    +6.6 %   +5.4 %
    grass_light_noisy    0.200    0.200   0.210 ± 0.000   0.208 ± 0.000    +5.2 %   +3.8 %
    camera_240x180       0.200    0.200   0.208 ± 0.000   0.204 ± 0.000    +4.0 %   +2.1 %

All nine within 10 % (Huber without instruments: 8 of 9, noisy_gravel -11 % / -12 %; least
squares: 7; consecutive pairs: 6 with Huber, 5 with least squares, lowtex_light refused). The
worst, lowtex_light (blurred moon under a light change), has few textured pixels (43,000 samples
against 300,000 to 1,700,000 elsewhere) and the widest intervals. At 10 and 40 frames/s
(``--rate``) no error changes by more than 0.2 percentage points: 9 of 9 within 10 % again.

What the pair buys (kit default, ``python benchmarks/contrast_fit.py --reconstruct``): CLAHE-SSIM /
SSIM with the mean C, the true pair and the fitted pair: coffee_warp 0.590 / 0.600, 0.599 / 0.606,
0.600 / 0.609; noisy_gravel 0.521 / 0.492, 0.536 / 0.504, 0.554 / 0.521. On the real slider_depth
chunk the fitted pair (C+ 0.66, C- 0.40) moves the scores by less than 0.01 against C = 1.
"""
from __future__ import annotations

import math
from dataclasses import asdict, dataclass, replace

import numpy as np

from ..core.checks import choice, require, short_repr, whole_number
from ..core.events import EventDataError, Events
from ..core.frames import Frames
from ..core.guard import dense_array
from .anchor import check_frame_eps
from .binning import events_to_frames

__all__ = ["frame_log_changes", "estimate_contrast_threshold", "frame_event_counts", "frame_trajectories",
           "fit_contrast", "fit_contrast_arrays", "ContrastFit", "FIT_METHODS"]


def _check_pairing(frames, events, eps, exposed) -> float:
    """The frames, events, ``eps`` and ``exposed`` of a comparison of frames with events, checked (those of
    :func:`fit_contrast`, :func:`frame_log_changes`, :func:`frame_event_counts` and :func:`frame_trajectories`):
    a Frames and an Events of one sensor, eps a finite number >= 0 (:func:`~evinr_lite.method.anchor.check_frame_eps`,
    the anchor's one rule; 0 worked for the helpers and is taken by fit_contrast too: the exposed mask leaves black
    pixels out), exposed (low, high) with 0 <= low < high <= 1. Returns
    eps as a float. (Frames of another size than the events' sensor were compared pixel by pixel without a word,
    an eps of None or text and an exposed of None, one number or text were Python's or numpy's errors.)"""
    require(frames, Frames, "frames")
    require(events, Events, "events")
    eps = check_frame_eps(eps)
    try:
        lo, hi = (float(v) for v in exposed)
    except (TypeError, ValueError):
        lo = hi = math.nan
    if not 0.0 <= lo < hi <= 1.0:
        raise EventDataError(f"exposed= must be (low, high) with 0 <= low < high <= 1 (intensities in [0, 1]), "
                             f"got {exposed!r}")
    if tuple(frames.size) != tuple(events.sensor_size):
        raise EventDataError(f"frames are {frames.size} but the events' sensor is {events.sensor_size} (H, W); "
                             "they cannot be compared")
    return eps


def _usable_pairs(frames: Frames, events: Events) -> np.ndarray:
    t = frames.t     # in time order, distinct (:func:`_in_order`)
    if len(t) < 2 or len(events) == 0:
        raise EventDataError(f"{len(t)} frame(s) and {len(events)} event(s): fitting C needs at least two frames "
                             "with events between them")
    usable = np.flatnonzero((t[:-1] >= events.t[0]) & (t[1:] <= events.t[-1]))
    if usable.size == 0:
        raise EventDataError("no two consecutive frames lie inside the events' time span; a frame pair with "
                             "events between them is needed")
    return usable


def _in_order(frames: Frames) -> Frames:
    """The frames in time order (a list of frames out of order is a fit of the same C), refusing two at one time."""
    return require(frames, Frames, "frames").sorted_distinct("fitting C")


def _counts(events: Events, t: np.ndarray, usable: np.ndarray) -> np.ndarray:
    """int64 [K, H, W]: the sum of polarities in (t_k, t_{k+1}] for each usable pair k."""
    boundaries = np.unique(np.concatenate([t[usable], t[usable + 1]]))
    counts = events_to_frames(events, boundaries, C=1.0).frames
    index = np.searchsorted(boundaries, t[usable])      # bin of each usable pair
    return np.rint(counts[index]).astype(np.int64)


def _log_changes(frames: Frames, usable: np.ndarray, eps: float, exposed):
    images = frames.as_float().astype(np.float64)
    a, b = images[usable], images[usable + 1]
    dL = np.log(b + eps) - np.log(a + eps)
    lo, hi = exposed
    mask = (a > lo) & (a < hi) & (b > lo) & (b < hi)
    return dL, mask


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
        :func:`frame_event_counts` gives the ON and OFF counts apart.
    """
    eps = _check_pairing(frames, events, eps, exposed)
    frames = _in_order(frames)
    usable = _usable_pairs(frames, events)
    dL, mask = _log_changes(frames, usable, eps, exposed)
    return dL, _counts(events, frames.t, usable), mask


def frame_event_counts(frames: Frames, events: Events, *, eps: float = 1 / 255, exposed=(0.05, 0.95)):
    """:func:`frame_log_changes` with the ON and OFF counts kept apart (for a fit of C+ and C-).

    Returns:
        (dL, n_on, n_off, mask): float64 [K, H, W] log changes; int64 [K, H, W] ON events and OFF
        events (both >= 0) in (t_k, t_{k+1}]; bool [K, H, W] the well-exposed pixels.
        ``n_on - n_off`` is :func:`frame_log_changes`'s net count.
    """
    eps = _check_pairing(frames, events, eps, exposed)
    frames = _in_order(frames)
    usable = _usable_pairs(frames, events)
    dL, mask = _log_changes(frames, usable, eps, exposed)
    n_on = _counts(events.take(events.p > 0), frames.t, usable)
    n_off = -_counts(events.take(events.p < 0), frames.t, usable)
    return dL, n_on, n_off, mask


def estimate_contrast_threshold(log_changes, net_counts):
    """Least-squares C in log_changes ≈ C * net_counts (a line through the origin).

    Args:
        log_changes: float [M], ΔL of M pixels (already masked).
        net_counts: int [M], ON minus OFF events of the same pixels over the same intervals.
    Returns:
        float C = sum(ΔL n) / sum(n^2); NaN when every net count is 0 or no pixel is given (no event says what C
        is: an ON-only recording's OFF pixels, ``estimate_contrast_threshold(dL[off], n[off])``, are none).
    Raises:
        EventDataError: values that are no numbers (None was NaN, text numpy's error), NaN or inf, or two shapes
            (numpy's broadcast error). One count for every pixel (a scalar broadcast) is refused too: it summed
            ΔL n over the M pixels but n^2 once (estimate_contrast_threshold(dL, 1) was sum(dL), not C).
    """
    d, n = (_pixel_values(v, name) for v, name in ((log_changes, "log_changes"), (net_counts, "net_counts")))
    if d.shape != n.shape:
        raise EventDataError(f"log_changes and net_counts must be one value per pixel each, of one shape, got shapes "
                             f"{d.shape} and {n.shape}; mask both with the same mask")
    with np.errstate(invalid="ignore", divide="ignore"):     # 0 / 0: no count says what C is (NaN, documented)
        return float(np.sum(d * n) / np.sum(n * n))


def _pixel_values(value, name: str) -> np.ndarray:
    """``value`` (one number per pixel) as float64: numbers, finite (none at all is taken: C is NaN)."""
    arr = None if value is None or isinstance(value, (str, bytes)) else \
        dense_array(value, f"{name}=", error=EventDataError, want="one number per pixel (a 1-D array)")
    if arr is None or arr.dtype.kind not in "iuf":
        raise EventDataError(f"{name}= must be one number per pixel (a 1-D array of numbers), got {short_repr(value)}")
    arr = arr.astype(np.float64)
    if not np.isfinite(arr).all():
        raise EventDataError(f"{name}= holds {int((~np.isfinite(arr)).sum()):,} NaN or infinite value(s); mask "
                             "them out")
    return arr


# ---- C+ and C- -------------------------------------------------------------------------------

FIT_METHODS = ("iv", "huber", "lsq")
SPANS = ("trajectory", "pairs")
HUBER_K = 1.345        # Huber's tuning constant (95 % efficiency under Gaussian noise), in robust sigmas


@dataclass(frozen=True)
class ContrastFit:
    """C+ and C- fitted from frames (log units per event).

    Attributes:
        c_pos, c_neg: the fitted ON and OFF thresholds. c_pos_se, c_neg_se: their bootstrap
            standard errors. c_pos_interval, c_neg_interval: 95 % bootstrap percentile intervals.
        c_single: one threshold fitted to the net counts by the same method (ΔL ≈ C n).
        n_used: samples in the fit (pixel x frame for span "trajectory", pixel x frame pair for
            "pairs"): well exposed, on pixels with at least ``min_events`` events. n_pixels: pixels used.
        n_frames: frames used. residual: robust spread (1.4826 MAD) of ΔL - fit, log units.
        method, span, n_bootstrap, seed: how it was fitted (see :func:`fit_contrast`).
    """

    c_pos: float
    c_neg: float
    c_pos_se: float
    c_neg_se: float
    c_pos_interval: tuple
    c_neg_interval: tuple
    c_single: float
    n_used: int
    n_pixels: int
    n_frames: int
    residual: float
    method: str
    span: str
    n_bootstrap: int
    seed: int

    @property
    def C(self) -> tuple[float, float]:
        """(c_pos, c_neg), as EvINRConfig(C=...) takes it."""
        return (self.c_pos, self.c_neg)

    def as_dict(self) -> dict:
        """Plain JSON types (for run.json)."""
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in asdict(self).items()}

    def __str__(self) -> str:
        unit = "pixel-frame samples" if self.span == "trajectory" else "pixel pairs"
        return (f"C+ = {self.c_pos:.3f} ± {self.c_pos_se:.3f}, C- = {self.c_neg:.3f} ± {self.c_neg_se:.3f} "
                f"(n = {self.n_used:,} {unit}, {self.n_pixels:,} pixels, {self.n_frames} frames; "
                f"one C: {self.c_single:.3f}; {self.method} fit)")


def _robust_sigma(r: np.ndarray) -> float:
    """1.4826 x the median absolute residual (a strided subsample of at most 200,000: the scale of the
    Huber weights needs two digits, not the exact median)."""
    r = r[::max(1, r.size // 200_000)]
    return float(1.4826 * np.median(np.abs(r))) or float(np.std(r)) or 1e-12


def _solve(Z: list, X: list, y: np.ndarray, w: np.ndarray) -> np.ndarray:
    """beta of the weighted normal equations Z' W X beta = Z' W y (Z = X: least squares); columns as lists."""
    Zw = [w * z for z in Z]
    A = np.array([[zw @ x for x in X] for zw in Zw])
    if not np.all(np.isfinite(A)) or np.linalg.cond(A) > 1e12:
        raise EventDataError("the fit of C is singular: too few pixels with ON and with OFF events; use a window "
                             "with more frames and motion, or give C yourself (e.g. C=0.2)")
    return np.linalg.solve(A, np.array([zw @ y for zw in Zw]))


class _Centre:
    """Weighted per-label demeaning (one free offset per label), or nothing when labels is None."""

    def __init__(self, labels):
        self.labels = None if labels is None else np.unique(labels, return_inverse=True)[1]
        self.n = 0 if labels is None else int(self.labels.max()) + 1

    def __call__(self, columns: list, w: np.ndarray) -> list:
        if self.labels is None:
            return list(columns)
        sw = np.maximum(np.bincount(self.labels, w, self.n), 1e-300)
        return [v - (np.bincount(self.labels, w * v, self.n) / sw)[self.labels] for v in columns]


def _irls(y, X: list, Z: list | None, centre: _Centre, method: str, iters: int = 50):
    """(beta, weights, centred y, X, Z): Huber IRLS (or one least-squares pass), instrumental when Z is given.

    With per-pixel offsets the centring is redone with each new set of weights (the weighted
    fixed-effects estimator)."""
    w = np.ones(len(y))
    beta = None
    for it in range(iters):
        Yc, *cols = centre([y, *X, *(Z or [])], w)
        Xc, Zc = cols[:len(X)], (cols[len(X):] if Z else cols[:len(X)])
        new = _solve(Zc, Xc, Yc, w)
        converged = beta is not None and np.allclose(new, beta, rtol=1e-4, atol=1e-8)
        beta = new
        if method == "lsq" or converged or it == iters - 1:
            break
        r = Yc - sum(b * x for b, x in zip(beta, Xc))
        a = np.abs(r) / (HUBER_K * _robust_sigma(r))
        w = np.minimum(1.0, 1.0 / np.maximum(a, 1e-300))
    return beta, w, Yc, Xc, Zc


def fit_contrast_arrays(dL, n_on, n_off, *, offsets=None, instruments=None, groups=None, method: str = "huber",
                        n_bootstrap: int = 200, seed: int = 0, n_frames: int = 0, span: str = "pairs") -> ContrastFit:
    """Fit ΔL ≈ C+ n_on - C- n_off (+ one free offset per ``offsets`` label) over M samples.

    Args:
        dL: float [M] log changes (or log intensities, with ``offsets``); n_on, n_off: [M] ON and OFF
            counts (>= 0; cumulative counts with ``offsets``).
        offsets: int [M] labels (e.g. the pixel): samples sharing a label share an unknown offset,
            removed by weighted demeaning. None: the line goes through the origin.
        instruments: (z_on, z_off) [M] each, instruments for n_on and n_off (method "iv"): counts
            correlated with the true ones but not with their noise (e.g. the neighbours' counts).
        groups: int [M] block labels for the bootstrap (a block is resampled whole); None: each sample.
        method: "huber", "lsq" or "iv" (Huber weights, instrumental-variable equations).
        n_bootstrap: bootstrap resamples (the fit's weights held at their final values); seed: its seed.
        n_frames, span: recorded in the result.
    Returns:
        ContrastFit. Raises EventDataError when too few samples hold ON or OFF events, or the fit
        is not positive.
    """
    method = choice(method, FIT_METHODS, "method")   # an array was numpy's "truth value ... is ambiguous"
    if method == "iv" and instruments is None:
        raise EventDataError("method 'iv' needs instruments=(z_on, z_off)")
    y = np.asarray(dL, dtype=np.float64).ravel()
    on = np.asarray(n_on, dtype=np.float64).ravel()
    off = np.asarray(n_off, dtype=np.float64).ravel()
    g = np.arange(y.size) if groups is None else np.asarray(groups).ravel()
    lab = None if offsets is None else np.asarray(offsets).ravel()
    if not (y.shape == on.shape == off.shape == g.shape) or (lab is not None and lab.shape != y.shape):
        raise EventDataError(f"dL, n_on, n_off (and groups, offsets) must have one shape, got {y.shape}, "
                             f"{on.shape}, {off.shape}, {g.shape}")
    n_pos = n_neg = 0
    if y.size:     # samples whose counts vary (around the pixel's mean, with offsets): they inform the fit
        centre = _Centre(lab)
        span_on, span_off = (on, off) if lab is None else centre([on, off], np.ones_like(on))
        n_pos, n_neg = int(np.count_nonzero(span_on)), int(np.count_nonzero(span_off))
    if min(n_pos, n_neg) < 20:
        raise EventDataError(f"too few usable samples to fit C+ and C- ({n_pos} with ON events, {n_neg} with OFF "
                             "events, 20 of each needed): use a window with more frames and motion, or give C "
                             "yourself (e.g. C=0.2 or C=(0.22, 0.18))")
    X = [on, -off]
    Z = None if method != "iv" else [np.asarray(instruments[0], np.float64).ravel(),
                                     -np.asarray(instruments[1], np.float64).ravel()]
    robust = "lsq" if method == "lsq" else "huber"
    beta, w, Yc, Xc, Zc = _irls(y, X, Z, centre, robust)
    c_single = float(_irls(y, [on - off], None if Z is None else [Z[0] + Z[1]], centre, robust)[0][0])
    r = Yc - beta[0] * Xc[0] - beta[1] * Xc[1]
    residual = float(1.4826 * np.median(np.abs(r - np.median(r))))
    # bootstrap over blocks: per-block sums of the weighted (centred) normal equations
    _, block = np.unique(g, return_inverse=True)
    nb = int(block.max()) + 1
    terms = [Zc[i] * Xc[j] for i in range(2) for j in range(2)] + [Zc[i] * Yc for i in range(2)]
    stats = np.stack([np.bincount(block, w * t, nb) for t in terms], axis=1)        # [nb, 6]
    rng = np.random.default_rng(seed)
    boot = []
    for _ in range(int(n_bootstrap)):
        s = np.bincount(rng.integers(0, nb, nb), minlength=nb) @ stats
        A = s[:4].reshape(2, 2)
        if np.linalg.cond(A) < 1e12:
            boot.append(np.linalg.solve(A, s[4:]))
    boot = np.array(boot) if len(boot) > 1 else np.full((2, 2), np.nan)
    se = boot.std(axis=0, ddof=1)
    lo, hi = np.percentile(boot, [2.5, 97.5], axis=0)
    c_pos, c_neg = float(beta[0]), float(beta[1])
    if not (c_pos > 0 and c_neg > 0 and math.isfinite(c_pos) and math.isfinite(c_neg)):
        raise EventDataError(f"the fit gave C+ = {c_pos:.3g}, C- = {c_neg:.3g} (not positive): the frames and events "
                             "do not agree (check the time alignment and exposure), or give C yourself (e.g. C=0.2)")
    return ContrastFit(c_pos=c_pos, c_neg=c_neg, c_pos_se=float(se[0]), c_neg_se=float(se[1]),
                       c_pos_interval=(float(lo[0]), float(hi[0])), c_neg_interval=(float(lo[1]), float(hi[1])),
                       c_single=c_single, n_used=int(y.size),
                       n_pixels=int(np.unique(lab).size) if lab is not None else 0, n_frames=int(n_frames),
                       residual=residual, method=method, span=span, n_bootstrap=int(n_bootstrap), seed=int(seed))


def _neighbour_mean(N: np.ndarray) -> np.ndarray:
    """[K, H, W] mean of the 4 neighbours of every pixel (edges repeated): the instrument for "iv"."""
    P = np.pad(N, ((0, 0), (1, 1), (1, 1)), mode="edge")
    return 0.25 * (P[:, :-2, 1:-1] + P[:, 2:, 1:-1] + P[:, 1:-1, :-2] + P[:, 1:-1, 2:])


def frame_trajectories(frames: Frames, events: Events, *, eps: float = 1 / 255, exposed=(0.05, 0.95),
                       max_frames: int = 64):
    """Every pixel's log intensity at the frames and its cumulative ON and OFF counts (span "trajectory").

    Uses the frames inside the events' time span, at most ``max_frames`` of them, evenly spread.
    Returns:
        (t, logI, N_on, N_off, mask): float64 [K] frame times (s); float64 [K, H, W] log(I + eps);
        float64 [K, H, W] ON and OFF events (>= 0) in (t_0, t_k] (zero at k = 0); bool [K, H, W] the
        well-exposed samples.
    """
    eps = _check_pairing(frames, events, eps, exposed)
    max_frames = whole_number(max_frames, "max_frames", lo=2)
    frames = _in_order(frames)
    t = frames.t
    if len(events) == 0:
        raise EventDataError("no events: fitting C needs events between frames")
    inside = np.flatnonzero((t >= events.t[0]) & (t <= events.t[-1]))
    if inside.size < 2:
        raise EventDataError(f"{inside.size} frame(s) lie inside the events' time span "
                             f"[{events.t[0]:.6f}, {events.t[-1]:.6f}] s; fitting C needs at least two")
    if inside.size > max_frames:
        inside = inside[np.unique(np.round(np.linspace(0, inside.size - 1, max_frames)).astype(np.int64))]
    tk = t[inside]
    images = frames.as_float().astype(np.float64)[inside]
    logI = np.log(images + eps)
    zero = np.zeros((1, *images.shape[1:]))
    N_on = np.concatenate([zero, np.cumsum(events_to_frames(events.take(events.p > 0), tk).frames, 0,
                                           dtype=np.float64)])
    N_off = np.concatenate([zero, -np.cumsum(events_to_frames(events.take(events.p < 0), tk).frames, 0,
                                             dtype=np.float64)])
    lo, hi = exposed
    return tk, logI, N_on, N_off, (images > lo) & (images < hi)


def fit_contrast(frames: Frames, events: Events, *, method: str = "iv", span: str = "trajectory",
                 min_events: int = 3, eps: float = 1 / 255, exposed=(0.05, 0.95), max_frames: int = 64,
                 block: int = 16, n_bootstrap: int = 200, seed: int = 0) -> ContrastFit:
    """C+ and C- of a recording from its APS frames and the events between them.

    Args:
        frames: the frames (uint8 or [0, 1]) on the events' clock; at least two inside the events' span.
        events: the events.
        method: "iv" (default: Huber weights, the 4 neighbours' counts as instruments, which removes
            the bias of background activity), "huber" or "lsq" (see the module docstring).
        span: "trajectory" (default: each pixel's log intensity at every frame against its
            cumulative counts, with one free offset per pixel) or "pairs" (consecutive frame pairs,
            ΔL against the counts between them, through the origin).
        min_events: pixels ("trajectory") or pixel pairs ("pairs") with fewer events are left out.
        eps, exposed: see :func:`frame_log_changes`. max_frames: frames used at most ("trajectory").
        block: the bootstrap resamples blocks of block x block pixels (of one frame pair for "pairs").
        n_bootstrap, seed: the bootstrap (seeded: the same inputs give the same intervals).
    Returns:
        ContrastFit (print it: "C+ = 0.212 ± 0.004, C- = 0.187 ± 0.003 (n = ...)").
    Raises:
        EventDataError: fewer than two frames in the events' span, too few pixels with events, a
            non-positive fit; the message says to give C instead.
    """
    require(frames, Frames, "frames")          # every argument checked where it enters
    require(events, Events, "events")
    method = choice(method, FIT_METHODS, "method")   # an array was numpy's "truth value ... is ambiguous"
    span = choice(span, SPANS, "span")
    min_events = whole_number(min_events, "min_events", lo=0)
    max_frames = whole_number(max_frames, "max_frames", lo=2)
    block = whole_number(block, "block", lo=1)
    n_bootstrap = whole_number(n_bootstrap, "n_bootstrap", lo=0)
    seed = whole_number(seed, "seed", lo=0)
    eps = _check_pairing(frames, events, eps, exposed)
    if span == "pairs":
        y, n_on, n_off, mask = frame_event_counts(frames, events, eps=eps, exposed=exposed)
        n_on, n_off = n_on.astype(np.float64), n_off.astype(np.float64)
        mask &= (n_on + n_off) >= max(min_events, 1)
    else:
        _, y, n_on, n_off, mask = frame_trajectories(frames, events, eps=eps, exposed=exposed, max_frames=max_frames)
    K, H, W = y.shape
    k, yy, xx = np.indices((K, H, W))
    bw = -(-W // block)
    pixel = yy * W + xx
    if span == "pairs":
        groups, labels = (k * (-(-H // block)) + yy // block) * bw + xx // block, None
    else:
        groups, labels = (yy // block) * bw + xx // block, pixel
        total = n_on + n_off
        lo = np.where(mask, total, np.inf).min(axis=0)
        hi = np.where(mask, total, -np.inf).max(axis=0)
        mask &= ((mask.sum(axis=0) >= 2) & (hi - lo >= max(min_events, 1)))[None]
    inst = None
    if method == "iv":
        inst = (_neighbour_mean(n_on)[mask], _neighbour_mean(n_off)[mask])
    fit = fit_contrast_arrays(y[mask], n_on[mask], n_off[mask], offsets=None if labels is None else labels[mask],
                              instruments=inst, groups=groups[mask], method=method, n_bootstrap=n_bootstrap,
                              seed=seed, n_frames=K + (span == "pairs"), span=span)
    return replace(fit, n_pixels=int(np.count_nonzero(mask.any(axis=0))))
