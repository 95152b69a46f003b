"""Integrating a gradient field (notebook 05, Exercise 5): the Poisson step of the kit's offset solve.

The median-gradient offset (notebook 05, Exercise 4) gives the gradient (gx, gy) that the per-pixel
offset g should have. A field that comes from data is not exactly the gradient of any image, so g is
chosen in the least-squares sense:

    minimise  sum (g[:, 1:] - g[:, :-1] - gx)^2 + sum (g[1:, :] - g[:-1, :] - gy)^2,   mean(g) = 0

With D the stacked forward-difference matrix, that is the normal equations D^T D g = D^T b (a
Poisson equation with Neumann borders); D^T D has the constant images as its null space, which the
zero mean removes.

Exercise (reference solution registered with :mod:`evinr_lite.teaching.exercises` at import):

- ``integrate_gradients(gx, gy)``: that solve, for small images (a sparse solve: the
  images of notebook 05 have thousands of pixels). Stated
  rules, each with a check case: the result has mean exactly 0; a single row (gy of shape [0, W]), a
  single column (gx of shape [H, 0]) and a single pixel are valid; an exact gradient field is
  recovered exactly; a field that is not a gradient is fitted in least squares, not along one path.

The reference is pinned to the library's DCT solve :func:`evinr_lite.method.offset.poisson_integrate`
by ``tests/test_poisson_exercises.py``; notebook 05 uses the learner's function in its place.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse
import scipy.sparse.linalg

from . import exercises

__all__ = ["integrate_gradients"]


def _differences(H: int, W: int) -> scipy.sparse.csr_matrix:
    """D [(H (W-1) + (H-1) W), H W]: forward differences along x (columns), then along y (rows)."""
    idx = np.arange(H * W).reshape(H, W)
    rows, cols, vals = [], [], []
    r = 0
    for a, b in ((idx[:, :-1], idx[:, 1:]), (idx[:-1, :], idx[1:, :])):
        n = a.size
        rows += [np.arange(r, r + n)] * 2
        cols += [b.ravel(), a.ravel()]
        vals += [np.ones(n), -np.ones(n)]
        r += n
    return scipy.sparse.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                                   shape=(r, H * W))


def integrate_gradients(gx, gy):
    """The zero-mean image whose forward differences best match a gradient field, in least squares.

    Args:
        gx: float [H, W-1], the wanted g[:, j+1] - g[:, j] (x is the column index).
        gy: float [H-1, W], the wanted g[i+1, :] - g[i, :] (y is the row index).

    Returns:
        g: float64 [H, W] with mean 0, minimising |Dx g - gx|^2 + |Dy g - gy|^2.
    """
    gx = np.asarray(gx, dtype=np.float64)
    gy = np.asarray(gy, dtype=np.float64)
    H, W = gx.shape[0], gy.shape[1]
    if H * W == 1:
        return np.zeros((1, 1))
    D = _differences(H, W).tocsc()
    b = np.concatenate([gx.ravel(), gy.ravel()])
    # constants are the null space of D: pin g[0, 0] = 0 (drop its column), solve the sparse normal
    # equations for the rest, then shift to mean 0; the least-squares fit is the same
    D1 = D[:, 1:]
    h = scipy.sparse.linalg.spsolve((D1.T @ D1).tocsc(), D1.T @ b)
    g = np.concatenate([[0.0], np.atleast_1d(h)]).reshape(H, W)
    return g - g.mean()


# ---- exercise registration ---------------------------------------------------------------------------

def _inputs(rng):
    cases = []
    # an exact gradient field (of a random image): recovered exactly, up to the mean
    # (a steep ramp under it would catch a float32 answer, but also fail scipy.sparse's iterative solvers at
    # their usual tolerances, which notebook 05 invites: float32 stays open, tests/test_exercise_wrong_solutions_round9.py)
    img = rng.normal(size=(4, 5))
    cases.append(dict(gx=np.diff(img, axis=1), gy=np.diff(img, axis=0)))
    # a field that is no image's gradient: least squares over every difference
    cases.append(dict(gx=rng.normal(size=(3, 4)), gy=rng.normal(size=(2, 5))))
    # a single row, a single column, a single pixel
    cases.append(dict(gx=rng.normal(size=(1, 5)), gy=np.zeros((0, 6))))
    cases.append(dict(gx=np.zeros((4, 0)), gy=rng.normal(size=(3, 1))))
    cases.append(dict(gx=np.zeros((1, 0)), gy=np.zeros((0, 1))))
    # a zero field on a square image: g = 0 (a square one, where H and W cannot be told apart by shape alone)
    cases.append(dict(gx=np.zeros((4, 3)), gy=np.zeros((3, 4))))
    return cases


def _anchored_at_first_pixel(gx, gy):
    g = integrate_gradients(gx, gy)
    return g - g.flat[0]


def _path_integral(gx, gy):
    """Cumulative sums down the first column, then along every row: exact only for a true gradient."""
    gx, gy = np.asarray(gx, dtype=np.float64), np.asarray(gy, dtype=np.float64)
    H, W = gx.shape[0], gy.shape[1]
    g = np.zeros((H, W))
    g[1:, 0] = np.cumsum(gy[:, 0])
    g[:, 1:] = g[:, :1] + np.cumsum(gx, axis=1)
    return g - g.mean()


def _path_integral_rows_first(gx, gy):
    """Cumulative sums along the first row, then down every column: the other path, exact only for a gradient."""
    gx, gy = np.asarray(gx, dtype=np.float64), np.asarray(gy, dtype=np.float64)
    H, W = gx.shape[0], gy.shape[1]
    g = np.zeros((H, W))
    g[0, 1:] = np.cumsum(gx[0])
    g[1:, :] = g[:1, :] + np.cumsum(gy, axis=0)
    return g - g.mean()


def _zeros_for_a_line(gx, gy):
    """A single row or column answered with zeros, as if it had nothing to integrate."""
    gx, gy = np.asarray(gx, dtype=np.float64), np.asarray(gy, dtype=np.float64)
    H, W = gx.shape[0], gy.shape[1]
    return np.zeros((H, W)) if H == 1 or W == 1 else integrate_gradients(gx, gy)


exercises.register(
    "integrate_gradients", integrate_gradients, _inputs, rtol=1e-6, atol=1e-8,
    hints={
        "shift the result to mean 0: differences never see a constant, the zero mean is what fixes it":
            _anchored_at_first_pixel,
        "a path integral (cumulative sums along one path) is exact only for a true gradient; least squares "
        "uses every difference: solve D^T D g = D^T b (with the zero-mean condition)":
            _path_integral,
        "cumulative sums along the first row and then down the columns are a path integral too: exact only for a "
        "true gradient; least squares uses every difference (D^T D g = D^T b, then the zero mean)":
            _path_integral_rows_first,
        "a single row (or column) is an image too: its differences along the row still fix g up to the constant "
        "(there g is the running sum of gx, shifted to mean 0); only a single pixel has nothing to integrate":
            _zeros_for_a_line,
    })
