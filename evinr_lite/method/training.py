"""Training the ensemble's networks on event frames: bins, Adam, the losses of one step, the closed-form head.

:func:`train_frame_inr` trains one :class:`~evinr_lite.method.models.FrameINR` network per window,
all in one batched computation: event frames at the coarsest stage (bisected at ``c2f_iters`` with
coarse-to-fine), Adam on temporal loss + lambda * regularizer, then (``head_solve``) the output
layer's exact optimum (:mod:`evinr_lite.method.head_solve`).
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import torch

from ..core.events import EventDataError, Events
from ..core.runtime import default_device
from .binning import bisect_boundaries, equal_count_boundaries, events_to_frames
from .config import EvINRConfig
from .fused import head_losses
from .head_solve import solve_head
from .losses import temporal_loss_derivative, temporal_loss_difference, tikhonov, total_variation
from .models import FrameINR

__all__ = ["make_adam", "step_losses", "train_frame_inr"]


def _initial_boundaries(events: Events, windows: np.ndarray, cfg: EvINRConfig) -> list[np.ndarray]:
    """Bin edges per window at the coarsest stage: 2^n_bisections times coarser than the final bins."""
    factor = 2 ** cfg.n_bisections
    out = []
    if cfg.binning == "fixed":
        n_final = max(factor, cfg.min_bins, int(round((windows[0, 1] - windows[0, 0]) / cfg.final_bin_duration())))
        n0 = max(1, int(round(n_final / factor)))
        for lo, hi in windows:
            out.append(np.linspace(lo, hi, n0 + 1))
        return out
    for lo, hi in windows:
        ev = events.slice_time(lo, hi, allow_empty=True)
        n0 = max(1, int(round(len(ev) / (cfg.events_per_bin * factor))))
        if len(ev) < 2 * n0:
            raise EventDataError(f"window [{lo:.3f}, {hi:.3f}] s holds {len(ev)} events, too few for equal-count "
                                 "bins; use binning='fixed' or a longer window")
        b = equal_count_boundaries(ev, n_bins=n0)
        b[0], b[-1] = lo, hi
        out.append(b)
    n = {len(b) for b in out}
    if len(n) > 1:  # equal-count bins must agree in number across networks to batch them
        n0 = min(n) - 1
        out = [np.interp(np.linspace(0, len(b) - 1, n0 + 1), np.arange(len(b)), b) for b in out]
    return out


@dataclass
class _Bins:
    """Event frames of all windows, stacked for batched training (tensors on the device)."""

    boundaries: torch.Tensor   # float64 [N, B + 1] seconds
    centers: torch.Tensor      # float64 [N, B]
    durations: torch.Tensor    # float32 [N, B]
    frames: torch.Tensor       # float32 [N, B, H, W], C * sum of p per bin

    @classmethod
    def build(cls, events: Events, boundaries: list[np.ndarray], C: float | tuple, device) -> "_Bins":
        b = np.stack(boundaries)
        frames = np.stack([events_to_frames(events, bb, C).frames for bb in boundaries])
        return cls(
            boundaries=torch.as_tensor(b, device=device),
            centers=torch.as_tensor(0.5 * (b[:, 1:] + b[:, :-1]), device=device),
            durations=torch.as_tensor(np.diff(b, axis=1), dtype=torch.float32, device=device),
            frames=torch.as_tensor(frames, device=device),
        )


def make_adam(param_groups, lr: float) -> torch.optim.Optimizer:
    """Adam, fused into one kernel per step where this torch build has it (CPU and CUDA float32).

    The same update as the default implementation up to float rounding; on a 240x180 head
    (22 M weights) the fused step reads and writes each state tensor once instead of about ten
    times (see benchmarks/train_step.py).
    """
    try:
        return torch.optim.Adam(param_groups, lr=lr, fused=True)
    except (RuntimeError, TypeError, ValueError):   # no fused kernel for this device / dtype
        return torch.optim.Adam(param_groups, lr=lr)


def step_losses(model: FrameINR, bins: "_Bins", temporal_loss: str, regularizer: str, fused: bool = True,
                buffers: dict | None = None):
    """(temporal loss, regularizer) of one training step, scalars averaged over networks, bins and pixels.

    ``fused=False`` is the readable path (``model.forward_with_derivative`` or ``model(...)``, then
    the functions of :mod:`evinr_lite.method.losses`); ``fused=True`` computes the same numbers with the
    output layer and the losses in one autograd node (:func:`~evinr_lite.method.fused.head_losses`),
    which touches the [N, B, H, W] tensors far fewer times. ``buffers``: a dict kept across the steps
    of one training loop, in which the fused path reuses its large work arrays.
    """
    times = bins.centers if temporal_loss == "derivative" else bins.boundaries
    if fused:
        h, dh = model.features(times, with_derivative=temporal_loss == "derivative")
        return head_losses(h, dh, model.head_weight, model.head_bias, bins.frames,
                           bins.durations if dh is not None else None, regularizer, buffers)
    if temporal_loss == "derivative":
        F, dF = model.forward_with_derivative(times)
        temporal = temporal_loss_derivative(dF, bins.frames, bins.durations)
    else:
        F = model(times)
        temporal = temporal_loss_difference(F, bins.frames)
    regularize = {"tikhonov": tikhonov, "tv": total_variation, "none": None}[regularizer]
    reg = regularize(F) if regularize is not None else torch.zeros((), device=F.device)
    return temporal, reg


def train_frame_inr(events: Events, windows: np.ndarray, cfg: EvINRConfig, log=None, *,
                    model: FrameINR | None = None, fast: bool = True):
    """Train one FrameINR per window, all in one batched computation.

    Args:
        events, windows ([N, 2] seconds), cfg: what to train on and how.
        model: a FrameINR with N networks to start from (trained in place, on its own device);
            None builds one from ``cfg`` (seeded by ``cfg.seed``).
        fast: True uses the fused Adam kernel and the fused output layer + losses
            (:func:`step_losses`); False the readable reference path. Same results up to float
            rounding (tests/test_perf_equivalence.py).

    Returns:
        (model, history) with history = {"loss", "temporal", "regularizer": per-iteration floats,
        "n_bins": bins per network at each iteration, "train_time_s": float}.
    """
    if model is None:
        device = default_device(cfg.device)
        model = FrameINR(events.sensor_size, windows, cfg.hidden_features, cfg.hidden_layers,
                         cfg.omega_0, cfg.first_layer_omega(windows), seed=cfg.seed).to(device)
    device = model.head_weight.device
    if cfg.lam == "auto":   # reconstruct() resolves it over the whole span; a direct call, from these events
        from dataclasses import replace

        from .balance import polarity_counts
        from .smoothing import auto_lam, covered_fraction

        cfg = replace(cfg, lam=auto_lam(*polarity_counts(events), covered_fraction(windows)))
    if model.n_models != len(windows):
        raise ValueError(f"model holds {model.n_models} networks but {len(windows)} windows were given")
    head = [model.head_weight, model.head_bias]
    trunk = [p for n, p in model.named_parameters() if not n.startswith("head_")]
    groups = [{"params": trunk}, {"params": head, "lr": cfg.lr * cfg.head_lr_scale}]
    if cfg.n_iters > 0:   # no optimizer when nothing is trained: torch's first Adam costs about 1 s (lazy imports)
        opt = make_adam(groups, lr=cfg.lr) if fast else torch.optim.Adam(groups, lr=cfg.lr)
        sched = torch.optim.lr_scheduler.StepLR(opt, step_size=cfg.lr_decay_every, gamma=cfg.lr_decay)
    boundaries = _initial_boundaries(events, windows, cfg)
    bins = _Bins.build(events, boundaries, cfg.C, device)
    regularizer = cfg.regularizer if cfg.lam > 0 else "none"
    history = {"loss": [], "temporal": [], "regularizer": [], "n_bins": [], "lam": float(cfg.lam)}
    bisect_at = set(cfg.c2f_iters) if cfg.coarse_to_fine else set()
    buffers = {}   # the fused path's work arrays, reused from step to step

    from tqdm.auto import tqdm

    t0 = time.perf_counter()
    bar = tqdm(range(cfg.n_iters), desc="EvINR", disable=not cfg.progress, leave=False)
    for it in bar:
        if it in bisect_at:
            boundaries = [bisect_boundaries(events, b) for b in boundaries]
            bins = _Bins.build(events, boundaries, cfg.C, device)
        temporal, reg = step_losses(model, bins, cfg.temporal_loss, regularizer, fused=fast, buffers=buffers)
        # per-network means summed over networks: each network gets its own gradient, whatever N
        loss = model.n_models * (temporal + cfg.lam * reg)
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()
        sched.step()
        history["loss"].append(loss.item() / model.n_models)
        history["temporal"].append(temporal.item())
        history["regularizer"].append(reg.item())
        history["n_bins"].append(int(bins.frames.shape[1]))
        if it % 10 == 0:
            bar.set_postfix(loss=f"{history['loss'][-1]:.4g}", bins=history["n_bins"][-1])
    bar.close()
    if cfg.head_solve:   # the output layer's exact optimum for the (trained or initial) hidden layers
        solved = solve_head(model, bins.boundaries, bins.frames, cfg.temporal_loss, regularizer, cfg.lam,
                            order=cfg.spatial_order, time_order=cfg.prior_time_order)
        history["head_solve_s"] = solved["seconds"]
        history["temporal_after_solve"] = solved["temporal"]
    history["final_bins"] = int(bins.frames.shape[1])
    if device.type == "cuda":
        torch.cuda.synchronize(device)
    history["train_time_s"] = time.perf_counter() - t0
    return model, history
