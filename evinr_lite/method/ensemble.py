"""The ensemble of networks over time: windows, predictions, blending and alignment.

The span [t_start, t_end] is cut into N overlapping windows (:func:`split_windows`), one network
each. Every network is queried at any times (:func:`predict_networks`), the networks are chained
onto each other over their overlaps (:func:`alignment_offsets`) and cross-faded linearly across
them (:func:`blend_weights`, :func:`blend_networks`), so no seam shows.

Times are float64 seconds; windows float64 [N, 2]; images float32 [.., H, W].
"""
from __future__ import annotations

import math

import numpy as np
import torch

from ..core.checks import real_number
from ..core.events import EventDataError
from .models import FrameINR

__all__ = ["split_windows", "predict_networks", "blend_weights", "blend_networks", "alignment_offsets"]


def split_windows(t_start: float, t_end: float, tau: float | None, overlap: float) -> np.ndarray:
    """N equal windows covering [t_start, t_end], each at most ``tau`` s, neighbours sharing ``overlap`` s.

    Returns float64 [N, 2] (seconds). N = 1 when tau is None or the span fits in one window.
    """
    # numbers by name (0-d arrays and tensors too): NaN, inf or text were Python's conversion errors
    t_start, t_end = real_number(t_start, "t_start", hint="seconds"), real_number(t_end, "t_end", hint="seconds")
    if tau is not None:
        tau = real_number(tau, "tau", lo=0, lo_open=True, hint="each window's length in seconds (None: one window)")
        overlap = real_number(overlap, "overlap", lo=0, hint="seconds shared by neighbouring windows")
        if not tau > overlap:   # tau == overlap was a ZeroDivisionError; a negative overlap left gaps
            raise EventDataError(f"tau = {tau:g} s must exceed the overlap ({overlap:g} s): each window has to reach "
                                 "past the one before it; use a longer tau or a shorter overlap")
    span = t_end - t_start
    if not span > 0:
        raise EventDataError(f"time span [{t_start}, {t_end}] is empty; t_end must exceed t_start")
    if tau is None or span <= tau:
        return np.array([[t_start, t_end]], dtype=np.float64)
    n = math.ceil((span - overlap) / (tau - overlap))
    length = (span + (n - 1) * overlap) / n
    if length < 2 * overlap:  # then three windows would share some instants
        raise EventDataError(f"windows of {length:.3g} s with overlap {overlap:g} s would overlap three at a "
                             "time; use tau of at least twice the overlap")
    starts = t_start + np.arange(n) * (length - overlap)
    windows = np.stack([starts, starts + length], axis=1)
    windows[-1, 1] = t_end
    return windows


@torch.no_grad()
def predict_networks(model: FrameINR, times: np.ndarray, chunk: int = 256) -> np.ndarray:
    """Every network at every time: float32 [N, Q, H, W] (no offsets)."""
    device = model.head_weight.device
    times = np.asarray(times, dtype=np.float64)
    # torch's allocation (64-byte aligned) keeps the matmul's rounding the same from run to run
    out = torch.empty((model.n_models, len(times), *model.sensor_size), dtype=torch.float32)
    in_place = device.type == "cpu" and model.n_models == 1 and model.head_weight.dtype == torch.float32
    for i in range(0, len(times), chunk):
        t = torch.as_tensor(times[i:i + chunk], device=device).expand(model.n_models, -1)
        if in_place:
            model(t, out=out[:, i:i + chunk])                            # written in place: no copy
        else:
            out[:, i:i + chunk] = model(t).float().cpu()
    return out.numpy()


def blend_weights(windows: np.ndarray, times: np.ndarray) -> np.ndarray:
    """[N, Q] weights: linear ramps across overlaps, zero outside a window, summing to 1."""
    lo, hi = windows[:, :1], windows[:, 1:]
    inside = (times >= lo - 1e-9) & (times <= hi + 1e-9)
    if not np.all(inside.any(axis=0)):
        bad = times[~inside.any(axis=0)][0]
        raise EventDataError(f"query time {bad} s is outside the reconstructed span "
                             f"[{windows[0, 0]}, {windows[-1, 1]}] s")
    if len(windows) == 1:
        return inside.astype(np.float64)
    overlap = max(windows[0, 1] - windows[1, 0], 1e-9)
    ramp = np.clip(np.minimum(times - lo, hi - times) / overlap, 1e-6, 1.0)
    ramp[0] = np.where(times < windows[1, 0], 1.0, ramp[0])      # no fade-in at the sequence start
    ramp[-1] = np.where(times > windows[-2, 1], 1.0, ramp[-1])   # nor fade-out at its end
    w = np.where(inside, ramp, 0.0)
    return w / w.sum(axis=0, keepdims=True)


def blend_networks(model, windows, times, offsets, chunk=256) -> np.ndarray:
    """The ensemble's log intensity at times [Q]: each network plus its offset [N, H, W], blended
    with :func:`blend_weights`. Returns float32 [Q, H, W]."""
    F = predict_networks(model, times, chunk)
    F += offsets[:, None]   # in place: one [N, Q, H, W] array, not two
    w = blend_weights(windows, times)
    return np.einsum("nq,nqhw->qhw", w, F).astype(np.float32)


def alignment_offsets(model: FrameINR, windows: np.ndarray, n_samples: int = 8) -> np.ndarray:
    """Per-network, per-pixel offsets [N, H, W] chaining each network onto its predecessor.

    Over the overlap of windows k-1 and k, offset_k = offset_{k-1} + mean_t (F_{k-1}(t) - F_k(t)).
    """
    H, W = model.sensor_size
    offsets = np.zeros((len(windows), H, W), np.float32)
    for k in range(1, len(windows)):
        ts = np.linspace(windows[k, 0], windows[k - 1, 1], n_samples)
        F = predict_networks(model, ts)
        offsets[k] = offsets[k - 1] + (F[k - 1] - F[k]).mean(axis=0)
    return offsets
