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

import numpy as np
import torch

from ..core.events import EventDataError

__all__ = ["temporal_loss_derivative", "temporal_loss_difference", "tikhonov", "total_variation", "spatial_differences"]


def _frames_tensor(value, name: str, what: str = "[..., B, H, W]") -> torch.Tensor:
    """``value`` when it is a torch tensor of at least three axes (frames over bins); None, text or a numpy array
    were Python's or torch's errors ("'NoneType' object is not subscriptable", "too many indices")."""
    if not isinstance(value, torch.Tensor):
        raise EventDataError(f"{name} must be a torch tensor {what}, got {type(value).__name__}"
                             + ("; torch.from_numpy(a) makes one" if type(value).__module__ == "numpy" else ""))
    if value.ndim < 3:
        raise EventDataError(f"{name} must be frames {what} (at least 3 axes), got shape {tuple(value.shape)}")
    return value


def _same_frames(a: torch.Tensor, b: torch.Tensor, names: str, extra_bin: int = 0) -> None:
    """Two stacks of frames over bins that go together (``a`` has ``extra_bin`` more bins): their bins agree and
    the other axes (the leading ones and H x W) broadcast, as torch broadcasts them (torch's "size of tensor a (5)
    must match" named neither)."""
    try:
        torch.broadcast_shapes(a.shape[:-3] + (1,) + a.shape[-2:], b.shape[:-3] + (1,) + b.shape[-2:])
        fits = a.shape[-3] == b.shape[-3] + extra_bin
    except RuntimeError:
        fits = False
    if not fits:
        raise EventDataError(f"{names} do not go together: shapes {tuple(a.shape)} and {tuple(b.shape)}"
                             + (f" (the first must have one more bin: B + 1 boundaries for B bins, of one H x W)"
                                if extra_bin else " (one frame per bin each, of one H x W)"))


def _check_durations(durations, dF_dt: torch.Tensor) -> None:
    """``durations`` a torch tensor that broadcasts over dF_dt [..., B, H, W] as ``durations[..., None, None]``:
    a 0-d tensor (one length for every bin), or a last axis of B or 1 and leading axes that broadcast with
    dF_dt's (torch's "size of tensor a must match" named neither)."""
    B = dF_dt.shape[-3]
    fits = isinstance(durations, torch.Tensor)
    if fits and durations.ndim:
        try:
            torch.broadcast_shapes(durations.shape[:-1], dF_dt.shape[:-3])
            fits = durations.shape[-1] in (B, 1)
        except RuntimeError:
            fits = False
    if not fits:
        shape = f" {tuple(durations.shape)}" if hasattr(durations, "shape") else ""
        raise EventDataError(f"durations must be a torch tensor [..., B] of the {B} bins' lengths in seconds (a last "
                             f"axis of 1 or a 0-d tensor: one length for all), its leading axes broadcasting with "
                             f"dF_dt's {tuple(dF_dt.shape[:-3])}, got {type(durations).__name__}{shape}")


def temporal_loss_derivative(dF_dt: torch.Tensor, event_frames: torch.Tensor, durations: torch.Tensor) -> torch.Tensor:
    """Eq. 5-6. dF_dt, event_frames: [..., B, H, W]; durations: [..., B] seconds. Returns a scalar."""
    _same_frames(_frames_tensor(dF_dt, "dF_dt"), _frames_tensor(event_frames, "event_frames"),
                 "dF_dt and event_frames")
    _check_durations(durations, dF_dt)
    predicted = dF_dt * durations[..., None, None]
    return torch.mean((event_frames - predicted) ** 2)


def temporal_loss_difference(F_boundaries: torch.Tensor, event_frames: torch.Tensor) -> torch.Tensor:
    """F at the B + 1 bin boundaries [..., B + 1, H, W] against event frames [..., B, H, W]. Scalar."""
    _same_frames(_frames_tensor(F_boundaries, "F_boundaries", "[..., B + 1, H, W]"),
                 _frames_tensor(event_frames, "event_frames"), "F_boundaries and event_frames", extra_bin=1)
    predicted = F_boundaries[..., 1:, :, :] - F_boundaries[..., :-1, :, :]
    return torch.mean((event_frames - predicted) ** 2)


def _frame_tensor(F, numpy_too: bool = False):
    """``F`` when it is frames [..., H, W] (at least 2 axes): a torch tensor, or with ``numpy_too`` a numpy array
    (:func:`spatial_differences` slices either; the losses need torch's mean)."""
    if not isinstance(F, (torch.Tensor, np.ndarray) if numpy_too else torch.Tensor) or F.ndim < 2:
        hint = "; torch.from_numpy(a) makes one" if type(F).__module__ == "numpy" and not numpy_too else ""
        shape = f" of shape {tuple(F.shape)}" if hasattr(F, "shape") else ""
        kinds = "a torch tensor or numpy array" if numpy_too else "a torch tensor"
        raise EventDataError(f"F must be {kinds} of frames [..., H, W], got {type(F).__name__}{shape}{hint}")
    return F


def spatial_differences(F: torch.Tensor):
    """Forward differences along x (columns) and y (rows): ([..., H, W-1], [..., H-1, W]). ``F``: a torch tensor or
    a numpy array of at least 2 axes (plain slicing: numpy arrays worked and still do)."""
    _frame_tensor(F, numpy_too=True)
    return F[..., :, 1:] - F[..., :, :-1], F[..., 1:, :] - F[..., :-1, :]


def tikhonov(F: torch.Tensor) -> torch.Tensor:
    """Eq. 9 by finite differences: mean (dF/dx)^2 + mean (dF/dy)^2 over frames F [..., H, W]."""
    dx, dy = spatial_differences(_frame_tensor(F))
    return torch.mean(dx ** 2) + torch.mean(dy ** 2)


def total_variation(F: torch.Tensor) -> torch.Tensor:
    """Anisotropic TV: mean |dF/dx| + mean |dF/dy| over frames F [..., H, W]."""
    dx, dy = spatial_differences(_frame_tensor(F))
    return torch.mean(dx.abs()) + torch.mean(dy.abs())
