"""Tone mapping (Eq. 12): log intensity F -> display values in [0, 1].

I = exp(F) and Gamma(I) = (I / (I + 1))^gamma. Since I / (I + 1) = sigmoid(F), this is computed
as sigmoid(F)^gamma, which never overflows. The result depends on the absolute level of F: adding a
constant c to F (the unknown offset that events cannot see) brightens or darkens every pixel, so a
reconstruction is only comparable with ground truth once its offset is anchored (see each solver).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["tonemap_reinhard", "anchor_level", "anchor_mean"]


def tonemap_reinhard(L, gamma: float = 0.6):
    """(exp(L) / (exp(L) + 1)) ** gamma, elementwise; numpy array or torch tensor, any shape.

    Args:
        L: log intensity.
        gamma: contrast exponent (paper: 0.6).
    Returns:
        Same type and shape as ``L``, values in (0, 1).
    """
    if not gamma > 0:
        raise ValueError(f"gamma must be positive, got {gamma}")
    if hasattr(L, "sigmoid"):  # torch tensor
        return L.sigmoid() ** gamma
    L = np.asarray(L, dtype=np.float64)
    return (0.5 * (1.0 + np.tanh(0.5 * L))) ** gamma  # sigmoid without overflow warnings


def anchor_level(gamma: float = 0.6, display_mean: float = 0.5) -> float:
    """The log intensity that tone-maps to ``display_mean``: logit(display_mean ** (1 / gamma)).

    Events fix log intensity only up to a constant; the solvers shift their output so that its
    mean sits at this level (mid-grey on screen by default).
    """
    if not 0 < display_mean < 1:
        raise ValueError(f"display_mean must be in (0, 1), got {display_mean}")
    s = display_mean ** (1.0 / gamma)
    return math.log(s / (1.0 - s))


def anchor_mean(L, gamma: float = 0.6, display_mean: float = 0.5, reference=None):
    """``L`` shifted by one constant so that the mean of ``reference`` (default: ``L``) is
    :func:`anchor_level`, i.e. tone-maps to ``display_mean``. numpy, any shape.

    The one brightness anchor of the kit: the solvers, the baselines and the notebooks all use it.
    Pass log intensities on a time grid as ``reference`` to anchor a few frames the way
    :func:`evinr_lite.method.solver.reconstruct` anchors a whole sequence.
    """
    L = np.asarray(L)
    mean = L.mean() if reference is None else np.mean(reference)
    return L + (anchor_level(gamma, display_mean) - float(mean))
