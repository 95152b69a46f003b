"""The per-pixel offset that events cannot fix, chosen explicitly: the ghost solved.

Events constrain only changes of log intensity, so any image g(x, y) can be added to every frame
of a reconstruction without changing a single loss term of the events. Training leaves g to the
spatial regularizer, which moves it slowly under Adam (a smooth, low-frequency ghost) and, once
converged, picks the worst image for a moving scene: with Tikhonov, sum_t |D(F_t + g)|^2 is
smallest for g = -mean_t F_t (up to a constant), which subtracts the temporal mean image from
every frame (notebook 05 shows it).

A better rule for moving scenes: natural images have sparse gradients, and a pixel that sees a
moving scene sees an edge only now and then, so the *median* over time of the true frames'
gradients at a pixel is near zero, while the reconstruction's gradient there is off by the
gradient of the unknown offset. :func:`median_gradient_offset` therefore takes as the offset's
gradient minus the temporal median of the frames' gradients, and integrates that gradient field
in the least-squares sense (a Poisson equation with Neumann borders, solved exactly with the
DCT). For a static background the median is the background's own gradient, which is removed
(events never see it; an APS frame would be needed). One convex solve on one H x W image.
"""
from __future__ import annotations

import numpy as np
import scipy.fft

from .head_solve import laplacian_eigenvalues

__all__ = ["median_gradient_offset", "poisson_integrate"]


def poisson_integrate(gx: np.ndarray, gy: np.ndarray) -> np.ndarray:
    """The image g [H, W] whose forward differences best match (gx [H, W-1], gy [H-1, W]) in least
    squares: (Dx^T Dx + Dy^T Dy) g = Dx^T gx + Dy^T gy, solved with the DCT; mean(g) = 0."""
    H, W = gx.shape[0], gy.shape[1]
    div = np.zeros((H, W))
    div[:, :-1] -= gx
    div[:, 1:] += gx
    div[:-1, :] -= gy
    div[1:, :] += gy
    mu = laplacian_eigenvalues((H, W))
    mu[0, 0] = 1.0
    g = scipy.fft.dctn(div, type=2, norm="ortho") / mu
    g[0, 0] = 0.0
    return scipy.fft.idctn(g, type=2, norm="ortho")


def median_gradient_offset(frames) -> np.ndarray:
    """The offset g [H, W] (float64, mean 0) to add to every frame of ``frames`` [K, H, W] (log
    intensities over the sequence) so that the temporal median of each pixel's gradient is zero."""
    frames = np.asarray(frames)
    if frames.ndim != 3 or frames.shape[0] < 1:
        raise ValueError(f"frames must be [K, H, W] log intensities, got shape {frames.shape}")
    # a block of rows at a time, with time as the contiguous axis: the same float64 differences and
    # medians as on the whole stack, a few times faster, and work arrays of one block (about 2 M
    # cells) instead of three float64 copies of the stack (which matters at HD, where K is 64 or more)
    K, H, W = frames.shape
    rows = max(1, (1 << 21) // max(K * W, 1))
    gx = np.empty((H, W - 1))
    gy = np.empty((H - 1, W))
    for r0 in range(0, H, rows):
        r1 = min(H, r0 + rows)
        block = np.asarray(frames[:, r0:min(H, r1 + 1)], dtype=np.float64)   # one extra row for dy
        dx = np.moveaxis(np.diff(block[:, :r1 - r0], axis=2), 0, -1)          # [rows, W - 1, K]
        gx[r0:r1] = -np.median(np.ascontiguousarray(dx), axis=-1)
        if r1 - r0 + (r1 < H) > 1:
            dy = np.moveaxis(np.diff(block, axis=1), 0, -1)                   # [rows (- 1 at the end), W, K]
            gy[r0:r0 + dy.shape[0]] = -np.median(np.ascontiguousarray(dy), axis=-1)
    return poisson_integrate(gx, gy)
