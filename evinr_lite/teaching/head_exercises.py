"""The output layer in closed form (notebook 04, section 10): the kit's default, as an exercise.

A frame INR is F(t) = h(t) W + b: h(t) [d] the last hidden layer, shared by every pixel, and W [d, P]
the head, one column per pixel (P = H * W). With the boundary-difference loss, bin i compares the event
frame E_i [P] with F(b_{i+1}) - F(b_i) = (h(b_{i+1}) - h(b_i)) W = A_i W (the bias cancels). For fixed
hidden layers the loss is quadratic in W, so its minimum is one linear solve:

    minimise  |A W - E|^2 + ridge |W|^2     (sums of squares over bins and pixels)
    =>        (A^T A + ridge I) W = A^T E    one d x d matrix for every pixel

Exercise (reference solution registered with :mod:`evinr_lite.teaching.exercises` at import):

- ``head_closed_form(A, E, ridge)``: that solve. Stated rules, each with a check case: ``ridge`` may be
  exactly 0 (then A must have full column rank, as in every case the check builds); a bin with no
  events (a zero row of E) still says "no change here" and stays in the sum; a pixel that never fired
  (a zero column of E) gets a zero column of W; a tie (two equal rows of A) is fine.

The reference is pinned to the library's :func:`evinr_lite.method.head_solve.solve_head` with
``regularizer="none"`` (its ridge is 1e-7 of trace(A^T A) / d) by ``tests/test_head_exercises.py``.
"""
from __future__ import annotations

import numpy as np

from . import exercises

__all__ = ["head_closed_form", "bin_feature_changes"]


def head_closed_form(A, E, ridge):
    """The head W that minimises |A W - E|^2 + ridge |W|^2.

    Args:
        A: float64 [B, d], the change of the hidden features over each bin, h(b_{i+1}) - h(b_i).
        E: float64 [B, P], the event frames (C times the summed polarities), one column per pixel.
        ridge: float >= 0 (0 allowed when A has full column rank).

    Returns:
        W: float64 [d, P], the solution of (A^T A + ridge I) W = A^T E.
    """
    A = np.asarray(A, dtype=np.float64)
    E = np.asarray(E, dtype=np.float64)
    d = A.shape[1]
    return np.linalg.solve(A.T @ A + ridge * np.eye(d), A.T @ E)


def bin_feature_changes(model, boundaries):
    """A [B, d] float64 for network 0 of a FrameINR: h(b_{i+1}) - h(b_i) at the bin edges (seconds, [B + 1])."""
    import torch

    with torch.no_grad():
        h, _ = model.features(torch.as_tensor(np.asarray(boundaries, dtype=np.float64))[None])
    h = h[0].double().numpy()
    return h[1:] - h[:-1]


# ---- exercise registration ---------------------------------------------------------------------------

def _inputs(rng):
    cases = []
    # a plain case, ridge > 0
    A = rng.normal(size=(9, 4))
    cases.append(dict(A=A, E=rng.normal(size=(9, 6)), ridge=0.3))
    # ridge exactly 0 (the boundary of the stated range), full column rank
    A = rng.normal(size=(7, 3))
    cases.append(dict(A=A, E=rng.normal(size=(7, 5)), ridge=0.0))
    # empty bins (zero rows of E) and a pixel that never fired (a zero column)
    A = rng.normal(size=(8, 3))
    E = np.round(rng.normal(size=(8, 4)) * 3) * 0.2
    E[[1, 5]] = 0.0
    E[:, 2] = 0.0
    cases.append(dict(A=A, E=E, ridge=0.5))
    # ties: two bins with the same feature change, and a large ridge
    A = rng.normal(size=(6, 3))
    A[4] = A[2]
    cases.append(dict(A=A, E=rng.normal(size=(6, 3)), ridge=5.0))
    return cases


def _no_ridge(A, E, ridge):
    return head_closed_form(A, E, 0.0)


def _ridge_per_bin(A, E, ridge):
    return head_closed_form(A, E, ridge * np.asarray(A).shape[0])


def _drops_empty_bins(A, E, ridge):
    A, E = np.asarray(A, dtype=np.float64), np.asarray(E, dtype=np.float64)
    keep = np.any(E != 0, axis=1)
    return head_closed_form(A[keep], E[keep], ridge)


def _gradient_step(A, E, ridge):
    """One gradient step from W = 0 instead of the solve: A^T E (the right-hand side alone)."""
    A, E = np.asarray(A, dtype=np.float64), np.asarray(E, dtype=np.float64)
    return A.T @ E


def _head_ridge_everywhere(A, E, ridge):
    """`A.T @ A + ridge`: ridge added to every entry, not to the diagonal."""
    A = np.asarray(A, dtype=np.float64)
    return np.linalg.solve(A.T @ A + ridge, A.T @ np.asarray(E, dtype=np.float64))


def _ridge_over_bins(A, E, ridge):
    """The ridge divided by the number of bins (a mean-squared loss's normal equations)."""
    return head_closed_form(A, E, ridge / np.asarray(A).shape[0])


def _head_diagonal_set(A, E, ridge):
    """A wrong version (for the hint): np.fill_diagonal(A^T A, ridge), which sets the diagonal, not adds to it."""
    A = np.asarray(A, dtype=np.float64)
    M = A.T @ A
    np.fill_diagonal(M, ridge)
    return np.linalg.solve(M, A.T @ np.asarray(E, dtype=np.float64))


exercises.register(
    "head_closed_form", head_closed_form, _inputs, rtol=1e-6, atol=1e-9,
    hints={
        "np.fill_diagonal(M, ridge) replaces the diagonal of A^T A by ridge (its squared column norms are lost): "
        "add to it, A.T @ A + ridge * np.eye(d)":
            _head_diagonal_set,
        "the penalty is ridge |W|^2: add ridge * I to A^T A, not ridge ** 2 * I":
            lambda A, E, ridge: head_closed_form(A, E, ridge ** 2),
        "add ridge times the identity to A^T A (the ridge term is part of the loss being minimised)":
            _no_ridge,
        "the ridge is added once to A^T A, not once per bin (the loss is a sum, |A W - E|^2 + ridge |W|^2)":
            _ridge_per_bin,
        "an empty bin (a zero row of E) is a measurement too: it says the change there is 0; keep its row":
            _drops_empty_bins,
        "A^T E is only the right-hand side: solve (A^T A + ridge I) W = A^T E (np.linalg.solve)":
            _gradient_step,
        "`A.T @ A + ridge` adds ridge to every entry: add ridge * np.eye(d), to the diagonal only":
            _head_ridge_everywhere,
        "the loss is a sum of squares, |A W - E|^2 + ridge |W|^2: add ridge itself to A^T A, not ridge / B (that "
        "is the normal equations of a mean over bins)":
            _ridge_over_bins,
    })
