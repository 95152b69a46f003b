"""Display: log intensity F -> frames in [0, 1], and the level that events never fix.

Two tone maps (``EvINRConfig.tonemap``):

- ``"reinhard"``, the paper's Eq. 12: I = exp(F) and Gamma(I) = (I / (I + 1))^gamma. Since
  I / (I + 1) = sigmoid(F), this is computed as sigmoid(F)^gamma, which never overflows. It
  compresses contrast (a power gamma = 0.6 of the intensity in the shadows, flattening towards white)
  and keeps every highlight on screen.
- ``"linear"``, the kit's default: clip(exp(F), 0, 1), the inverse of the event model. Events are
  fired by changes of log(I) of the camera's intensity I, so exp(F) is that intensity again, with
  its own contrast; only highlights beyond 1 are clipped.

Both depend on the absolute level of F: adding a constant c to F (the unknown offset that events
cannot see) brightens or darkens every pixel, so a reconstruction is only comparable with ground
truth once its level is anchored (:func:`display_shift`, used by every solver and baseline):

- reinhard: the mean of F over the sequence maps to ``display_mean`` (0.5, mid-grey; the paper's
  recipe);
- linear: the frames' mean over the sequence, clipped as displayed, is ``display_mean`` (0.4 by
  default, a little below mid-grey: of 0.35, 0.4 and 0.45, the one value at which the linear display
  beats the Reinhard one in CLAHE-SSIM, SSIM and MSE on both the zoo mean and the real chunk).

Why linear is the default (``python benchmarks/quality_zoo.py``, docs/defaults.md "The display"):
ground truth frames, simulated or APS, are linear intensities, and the Reinhard curve halves their
contrast (the kit's frames had half the standard deviation of the truth's on the clean zoo scenes).
"""
from __future__ import annotations

import math

import numpy as np

from ..core.checks import choice, host_array, is_real_number, real_number
from ..core.events import EventDataError

__all__ = ["TONEMAPS", "DEFAULT_TONEMAP", "DEFAULT_DISPLAY_MEAN", "DISPLAY_MEANS", "tonemap_reinhard", "tonemap_linear", "to_display", "display_formula", "display_shift", "anchor_level",
           "anchor_mean", "reinhard_unchecked", "linear_unchecked"]

TONEMAPS = ("linear", "reinhard")
DEFAULT_TONEMAP = "linear"  # the kit's display (EvINRConfig and the baselines share it)
DEFAULT_DISPLAY_MEAN = 0.4   # linear: the frames' mean over the sequence
DISPLAY_MEANS = {"linear": DEFAULT_DISPLAY_MEAN, "reinhard": 0.5}   # each tone map's level (Reinhard: the paper's)
SHIFT_SAMPLES = 1 << 20     # values of the reference used to find the linear level (an even stride through it)


def tonemap_reinhard(L, gamma: float = 0.6):
    """(exp(L) / (exp(L) + 1)) ** gamma, elementwise; numpy array or torch tensor, any shape.

    Args:
        L: log intensity.
        gamma: contrast exponent (paper: 0.6).
    Returns:
        Same type and shape as ``L``, values in (0, 1).
    """
    if isinstance(gamma, (bool, np.bool_, str, bytes)) or not np.isscalar(gamma) or not gamma > 0 or \
            not np.isfinite(gamma):
        raise EventDataError(f"gamma must be a positive finite number (the paper's 0.6), got {gamma!r}")
    return reinhard_unchecked(_log_values(L), gamma)


def _log_values(L, name: str = "L"):
    """``L`` (numpy: as an array) after refusing what is no log intensity: not numbers, or NaN (it would come out as
    NaN frames); a torch tensor is checked for NaN and passed through. +-inf are log intensities of 0 and of
    saturation, displayed as 0 and 1."""
    if hasattr(L, "sigmoid"):   # torch: a NaN tensor gave NaN frames, where a NaN array was refused
        n_nan = int(L.isnan().sum())
    else:
        L = np.asarray(L) if not isinstance(L, (str, bytes)) else np.asarray([L])
        if L.dtype.kind not in "iuf" or L.dtype == bool:
            raise EventDataError(f"{name} must be log intensities (numbers), got dtype {L.dtype}")
        n_nan = int(np.isnan(L).sum())
    if n_nan:
        raise EventDataError(f"{name} contains {n_nan:,} NaN value(s); a log intensity must be a number "
                             "(log of an intensity clipped above 0)")
    return L


def reinhard_unchecked(L, gamma: float):
    """:func:`tonemap_reinhard` without its argument checks (the solver's own, already checked values)."""
    if hasattr(L, "sigmoid"):  # torch tensor
        return L.sigmoid() ** gamma
    L = np.asarray(L, dtype=np.float64)
    return (0.5 * (1.0 + np.tanh(0.5 * L))) ** gamma  # sigmoid without overflow warnings


def tonemap_linear(L):
    """clip(exp(L), 0, 1), elementwise; numpy array or torch tensor, any shape (float64 for numpy). ``L`` must be
    numbers without NaN (as :func:`tonemap_reinhard`'s)."""
    return linear_unchecked(_log_values(L))


def linear_unchecked(L):
    """:func:`tonemap_linear` without its argument checks (the solver's own, already checked values)."""
    if hasattr(L, "exp"):  # torch tensor
        return L.clamp(max=0.0).exp()
    L = np.asarray(L, dtype=np.float64)
    return np.exp(np.minimum(L, 0.0))


def to_display(L, tonemap: str = DEFAULT_TONEMAP, gamma: float = 0.6):
    """Frames in [0, 1] from log intensity ``L`` (any shape) by the tone map ``tonemap``
    ("linear" or "reinhard"; gamma is Reinhard's exponent)."""
    tonemap = choice(tonemap, TONEMAPS, "tonemap")
    if tonemap == "linear":
        return linear_unchecked(L)
    if tonemap == "reinhard":
        return reinhard_unchecked(L, gamma)
    raise EventDataError(f"tonemap must be one of {TONEMAPS}, got {tonemap!r}")


def _check_display_mean(display_mean) -> float:
    if not (is_real_number(display_mean) and 0 < float(host_array(display_mean)) < 1):
        raise EventDataError(f"display_mean= must be a finite number in (0, 1), got {display_mean!r}")
    return float(host_array(display_mean))


def _check_gamma(gamma) -> float:
    return real_number(gamma, "gamma", lo=0, lo_open=True, hint="Reinhard's exponent (the paper's 0.6)")


def display_formula(tonemap: str = DEFAULT_TONEMAP, gamma: float = 0.6) -> str:
    """:func:`to_display` in words, for files that keep the log intensity L (``log_intensity.h5``)."""
    tonemap = choice(tonemap, TONEMAPS, "tonemap")
    if tonemap == "linear":
        return "frames = clip(exp(L), 0, 1)"
    if tonemap == "reinhard":
        return f"frames = sigmoid(L) ** {gamma:g}"
    raise EventDataError(f"tonemap must be one of {TONEMAPS}, got {tonemap!r}")


def display_shift(reference, tonemap: str = DEFAULT_TONEMAP, gamma: float = 0.6,
                  display_mean: float = DEFAULT_DISPLAY_MEAN) -> float:
    """The constant c to add to log intensities so that ``reference + c`` (log intensities on a time
    grid, any shape) displays at ``display_mean`` by the tone map ``tonemap``.

    - reinhard: the mean of ``reference + c`` is :func:`anchor_level` (the paper's anchor);
    - linear: the mean of clip(exp(reference + c), 0, 1) is ``display_mean``. Clipped pixels count
      as 1, so a few hot pixels or highlights cannot darken the rest. Solved by bisection on the
      sorted values (at most SHIFT_SAMPLES of them, an even stride through ``reference``).
    """
    display_mean = _check_display_mean(display_mean)
    tonemap = choice(tonemap, TONEMAPS, "tonemap")   # an array was numpy's "truth value ... is ambiguous"
    reference = np.asarray(reference)
    if reference.dtype.kind not in "iuf" or reference.dtype == bool:
        raise EventDataError(f"reference must be log intensities (numbers), got dtype {reference.dtype}")
    if tonemap == "reinhard":   # NaN gave a NaN shift, no values numpy's "mean of empty slice" and NaN
        level = anchor_level(gamma, display_mean)
        mean = float(np.mean(reference)) if reference.size else math.nan
        if not math.isfinite(mean):
            raise EventDataError(f"display_shift needs finite log intensities, got {reference.size:,} value(s) whose "
                                 f"mean is {mean} (NaN or inf among them, or none)")
        return level - mean
    v = reference.reshape(-1)
    v = np.sort(v[::max(1, -(-v.size // SHIFT_SAMPLES))].astype(np.float64))
    if v.size == 0 or not np.isfinite(v[0]) or not np.isfinite(v[-1]):
        raise EventDataError("display_shift needs finite log intensities")
    top = v[-1]
    below = np.concatenate([[0.0], np.cumsum(np.exp(v - top))])   # below[k] = sum of exp(v_i - top), i < k
    n = v.size

    def shown_mean(c):   # mean of min(exp(v + c), 1)
        k = np.searchsorted(v, -c)                                 # v_i < -c are not clipped
        if top + c < 700:
            return (below[k] * math.exp(top + c) + (n - k)) / n
        # values spread over more than e^700 (a network that diverged in time): exp(top + c) overflowed
        # while below[k] underflowed; their product is summed directly (each exp(v_i + c) < 1 for i < k)
        return (float(np.exp(v[:k] + c).sum()) + (n - k)) / n

    lo, hi = math.log(display_mean) - top, -v[0]                   # shown_mean(lo) <= display_mean <= shown_mean(hi) = 1
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if shown_mean(mid) < display_mean else (lo, mid)
    return 0.5 * (lo + hi)


def anchor_level(gamma: float = 0.6, display_mean: float = 0.5) -> float:
    """The log intensity that tone-maps to ``display_mean``: logit(display_mean ** (1 / gamma)).

    Events fix log intensity only up to a constant; the solvers shift their output so that its
    mean sits at this level (mid-grey on screen by default).
    """
    display_mean = _check_display_mean(display_mean)
    s = display_mean ** (1.0 / _check_gamma(gamma))   # gamma 0 was a ZeroDivisionError, -1 a "math domain error"
    return math.log(s / (1.0 - s))


def anchor_mean(L, gamma: float = 0.6, display_mean: float = 0.5, reference=None, tonemap: str = "reinhard"):
    """``L`` shifted by one constant so that ``reference`` (default: ``L``) displays at
    ``display_mean`` by ``tonemap`` (:func:`display_shift`; for "reinhard", the default here, its mean
    is :func:`anchor_level`). numpy, any shape.

    The one brightness anchor of the kit: the solvers, the baselines and the notebooks all use it.
    Pass log intensities on a time grid as ``reference`` to anchor a few frames the way
    :func:`evinr_lite.method.solver.reconstruct` anchors a whole sequence.
    """
    L = _log_values(L) if not hasattr(L, "sigmoid") else np.asarray(L)
    return L + display_shift(L if reference is None else reference, tonemap, gamma, display_mean)
