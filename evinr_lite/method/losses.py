"""EvINR's losses on frame-shaped predictions (torch), all averaged over pixels and bins.

Temporal terms compare the model with the event frames E_i = C * sum p over (b_i, b_{i+1}]:

- ``temporal_loss_derivative`` (the paper's Eq. 5-6): (E_i - dF/dt(c_i) * (b_{i+1} - b_i))^2 at
  the bin mid-points c_i. A first-order Taylor approximation: it is exact only when L is linear
  in time over the bin.
- ``temporal_loss_difference``: (E_i - (F(b_{i+1}) - F(b_i)))^2, the integral form of Eq. 2
  evaluated at the bin boundaries, exact for any L. (The public reference code uses this form
  but evaluates F at bin mid-points, a half-bin misalignment; boundaries remove it.)

Spatial regularizers act on frames F [..., H, W] by finite differences (pixel units):

- ``tikhonov`` (the paper's Eq. 9): mean of (dF/dx)^2 + (dF/dy)^2.
- ``total_variation`` (anisotropic, what the reference code uses): mean of |dF/dx| + |dF/dy|.

These are the equations as written, for reading and teaching. The solver's fast path fuses the
output layer with them in one autograd node (:mod:`evinr_lite.method.fused`); the equivalence
tests keep the two equal.
"""
from __future__ import annotations

import torch

__all__ = ["temporal_loss_derivative", "temporal_loss_difference", "tikhonov", "total_variation", "spatial_differences"]


def temporal_loss_derivative(dF_dt: torch.Tensor, event_frames: torch.Tensor, durations: torch.Tensor) -> torch.Tensor:
    """Eq. 5-6. dF_dt, event_frames: [..., B, H, W]; durations: [..., B] seconds. Returns a scalar."""
    predicted = dF_dt * durations[..., None, None]
    return torch.mean((event_frames - predicted) ** 2)


def temporal_loss_difference(F_boundaries: torch.Tensor, event_frames: torch.Tensor) -> torch.Tensor:
    """F at the B + 1 bin boundaries [..., B + 1, H, W] against event frames [..., B, H, W]. Scalar."""
    predicted = F_boundaries[..., 1:, :, :] - F_boundaries[..., :-1, :, :]
    return torch.mean((event_frames - predicted) ** 2)


def spatial_differences(F: torch.Tensor):
    """Forward differences along x (columns) and y (rows): ([..., H, W-1], [..., H-1, W])."""
    return F[..., :, 1:] - F[..., :, :-1], F[..., 1:, :] - F[..., :-1, :]


def tikhonov(F: torch.Tensor) -> torch.Tensor:
    """Eq. 9 by finite differences: mean (dF/dx)^2 + mean (dF/dy)^2 over frames F [..., H, W]."""
    dx, dy = spatial_differences(F)
    return torch.mean(dx ** 2) + torch.mean(dy ** 2)


def total_variation(F: torch.Tensor) -> torch.Tensor:
    """Anisotropic TV: mean |dF/dx| + mean |dF/dy| over frames F [..., H, W]."""
    dx, dy = spatial_differences(F)
    return torch.mean(dx.abs()) + torch.mean(dy.abs())
