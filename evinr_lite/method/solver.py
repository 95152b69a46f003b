"""EvINR's solver: train frame-based INRs on events and query them at any time.

    rec = reconstruct(events, query_times, EvINRConfig(C=0.2))
    rec.frames          # [Q, H, W] tone-mapped, in [0, 1]
    rec.log_intensity   # [Q, H, W] log intensity
    rec.at(t)           # log intensity at other times

The recipe (paper Sec. 3-4; defaults in :class:`EvINRConfig`):

1. Cut [t_start, t_end] into N overlapping windows of at most ``tau`` seconds (ensembling), one
   network each, all trained together in one batched computation (:class:`~evinr_lite.method.models.FrameINR`).
2. Stack each window's events into event frames. With coarse-to-fine, training starts with bins
   4x longer than ``bin_duration`` and bisects every bin into halves of equal event count at
   iterations 100 and 200, ending at ``bin_duration`` on average (with "fixed" binning the final
   bins are equal-count halves, so their lengths vary with the event rate); without it, training
   uses fixed bins of ``bin_duration`` throughout (the paper's Base).
3. Minimise temporal loss + lambda * spatial regularizer with Adam (lr 1e-4, x0.95 every 10 steps).
4. Align the networks: each network's per-pixel offset is matched to its predecessor's over their
   overlap, and predictions are cross-faded linearly across the overlap, so no seam shows.
5. Anchor the brightness. Events only constrain changes of log intensity: adding any constant to
   F leaves every loss unchanged, and a per-pixel constant is only set by the regularizer. The
   global level is therefore a choice, not a measurement: by default F is shifted so that its mean
   over the sequence tone-maps to ``display_mean`` (0.5, mid-grey). Metrics with histogram
   equalisation (CLAHE) are insensitive to it; others should say how the level was set.
"""
from __future__ import annotations

import math
import re
import time
from dataclasses import asdict, dataclass, field

import numpy as np
import torch

from .binning import as_thresholds, bisect_boundaries, equal_count_boundaries, events_to_frames
from ..core.runtime import default_device
from ..core.events import EventDataError, Events
from .fused import head_losses
from .head_solve import solve_head
from .losses import temporal_loss_derivative, temporal_loss_difference, tikhonov, total_variation
from .anchor import ANCHOR_MODES, fit_anchor, frames_in_window, linear_frames
from .models import FrameINR
from .offset import median_gradient_offset
from .tonemap import anchor_level, tonemap_reinhard

__all__ = ["EvINRConfig", "Reconstruction", "reconstruct", "split_windows", "train_frame_inr",
           "predict_networks", "blend_weights", "blend_networks", "alignment_offsets"]


@dataclass
class EvINRConfig:
    """Every setting of the frame-based solver.

    Three named recipes (``benchmarks/quality_zoo.py`` compares them in one run):

    - ``EvINRConfig()``: the kit's default, chosen on the mean of the scene zoo (nine seeded scenes,
      ``evinr_lite.sim.zoo``) and the real slider_depth chunk, never on one scene;
    - ``EvINRConfig.paper()``: the paper's recipe exactly (Sec. 3-4);
    - ``EvINRConfig.v0_1()``: the kit's earlier default (the paper's plus first_omega_0 = 10 and
      head_lr_scale = 30, tuned on the demo scene alone); notebooks 03-11 train it.

    The kit's default departs from the paper in these fields. Zoo means (CLAHE-SSIM / SSIM / MSE; wall
    time per scene, 2 CPU cores shared with other jobs):
    ``python benchmarks/quality_zoo.py``: kit 0.555 / 0.583 / 0.030 in 1.6 s, paper 0.320 / 0.402 /
    0.051 in 92 s, v0.1 0.499 / 0.527 / 0.042 in 69 s, integration 0.425 / 0.513 / 0.042, high-pass
    filter 0.464 / 0.507 / 0.047.

    - head_solve=True, n_iters=0, coarse_to_fine=False: the output layer is solved in closed form
      for the SIREN's initial hidden layers. Training the hidden layers first (60 Adam steps) changed
      the zoo means by less than 0.002 at 4x the time, so no Adam step is taken.
    - temporal_loss="difference": the closed form fits the exact integral form; the mid-point
      derivative is a first-order approximation.
    - offset_solve="median_gradient": the per-pixel offset that events never fix is solved
      explicitly instead of drifting under the regularizer (the ghost).
    - lam=0.01 instead of 0.05: with the exact head, less smoothing wins on the zoo (quick zoo,
      CLAHE-SSIM mean: 0.293 at lam 1, 0.403 at 0.2, 0.482 at 0.05, 0.528 at 0.01). On the real chunk,
      lam from 0.003 to 1 moves CLAHE-SSIM only between 0.256 and 0.272.
    - hidden_features=256: the same zoo scores as 512 (within 0.002) at a quarter of the solve's
      d^2 work.
    - min_bins=64: short windows get shorter bins (at least 64 per window). The zoo's windows are
      2-3 s, so at 1/32 s they hold 64-96 bins and nothing changes there; on the 0.17 s real chunk
      (5 bins at 1/32 s) CLAHE-SSIM / SSIM go from 0.272 / 0.339 to 0.349 / 0.415. The cost: on the
      quick zoo (1.5-2.25 s scenes) the mean CLAHE-SSIM drops from 0.528 to 0.522.

    Events and bins:
        C: contrast threshold (log units per event; paper: 1 for IJRR/HQF, 0.25 for AED), or a pair
            (c_pos, c_neg): ON events weigh +c_pos, OFF events -c_neg (real sensors differ; fit both
            from APS frames with :func:`evinr_lite.method.contrast.fit_contrast`).
        bin_duration: final event-frame length in seconds (paper: 1/32 s).
        min_bins: at least this many final fixed-duration bins per network window (shorter bins
            in short windows; 0: bin_duration alone decides, as in the paper).
        binning: "fixed" (paper: fixed-duration bins) or "equal_count" (the reference code).
        events_per_bin: final events per bin for "equal_count". The reference code fixes the number
            of bins instead (50, then 100 after one bisection at n_iters / 2, over the whole window):
            emulate it with events_per_bin = n_events // 100 and c2f_iters = (n_iters // 2,)
            (``ablation.recipe_variants`` does).
    Losses:
        temporal_loss: "derivative" (paper, Eq. 5-6: dF/dt at bin mid-points times bin length) or
            "difference" (F(b_{i+1}) - F(b_i) at bin boundaries: exact integral form).
        regularizer: "tikhonov" (paper, Eq. 9), "tv" (reference code) or "none".
        lam: weight lambda of the regularizer (paper: 0.05; finite differences in pixel units).
    Network (SIREN):
        hidden_features, hidden_layers: width and depth (paper: 512, 3).
        omega_0: frequency factor of the hidden layers (SIREN's default 30).
        first_omega_0: frequency factor of the first layer, which sets how fast F can vary in time
            (not in the paper; the reference code uses 10 everywhere). With 30, the network fits
            dF/dt at the bin mid-points while wandering between them, so integrated changes are
            wrong (notebook 01 shows the same in 1-D); 10 keeps F smooth at the scale of a bin.
            Each network maps its own window to [-1, 1], so shorter ensemble windows allow faster
            wiggles per second: with short windows prefer temporal_loss="difference" (notebook 06).
    Optimisation:
        n_iters: iterations (paper: 300). lr, lr_decay, lr_decay_every: Adam with lr x lr_decay
            every lr_decay_every iterations (paper: 1e-4, 0.95, 10).
        head_lr_scale: learning-rate factor for the H*W output layer. Not in the paper: the public
            reference code multiplies the head's output by omega_0, which under Adam makes the head
            learn omega_0 times faster. We keep SIREN's small initial output and scale the head's
            learning rate instead (default 30 = omega_0); with 1, 300 iterations at lr 1e-4 leave
            the frames far from converged (see benchmarks/solver_quality.py).
        coarse_to_fine: bisect the bins at ``c2f_iters`` (paper: 3 stages, at 100 and 200).
    Ensembling:
        tau: longest window per network in seconds (paper: 5); None for one network.
        overlap: seconds shared by neighbouring windows (used to align and cross-fade them).
    Beyond the paper:
        head_solve: after the Adam iterations (if any), set the H*W output layer to the exact optimum
            of the loss for the hidden layers (a linear least-squares problem solved in closed form,
            :mod:`evinr_lite.method.head_solve`; needs regularizer "tikhonov" or "none").
        offset_solve: how the per-pixel offset that events cannot fix is chosen: "none" (left to the
            regularizer, as in the paper) or "median_gradient" (:mod:`evinr_lite.method.offset`:
            the offset that makes the temporal median of each pixel's gradient zero).
        anchor: APS frames as anchors (:mod:`evinr_lite.method.anchor`; pass ``frames=`` to
            :func:`reconstruct`): "none" (events only, the default), "first" (the first frame in the
            window sets the per-pixel offset) or "all" (every ``anchor_every``-th frame is a soft
            constraint on a slowly varying per-pixel offset; the others are held out for scoring).
            Anchored output is the frames' linear intensity, clip(exp(L) - 1/255, 0, 1), instead of
            the tone map; offset_solve and display_mean are then unused.
        anchor_every: with anchor "all", frames 0, k, 2k, ... of the window are anchors (k >= 1;
            default 2: every other frame is held out for scoring).
        anchor_smoothing: with anchor "all", the time scale s (seconds, >= 0) over which the offset
            may drift between anchors: 0 passes through every anchor frame, large s fits one
            least-squares offset per pixel.
    Output:
        gamma: tone-mapping exponent (paper: 0.6). display_mean: the tone-mapped value that the
            mean log intensity is anchored to (see the module docstring).
    Runtime:
        seed: seeds the initialisation. device: "cpu", "cuda" or None (GPU when present).
        progress: show a progress bar (terminal or notebook).
    """

    C: float | tuple = 1.0
    bin_duration: float = 1 / 32
    min_bins: int = 64
    binning: str = "fixed"
    events_per_bin: int = 100
    temporal_loss: str = "difference"
    regularizer: str = "tikhonov"
    lam: float = 0.01
    hidden_features: int = 256
    hidden_layers: int = 3
    omega_0: float = 30.0
    first_omega_0: float | None = 10.0
    n_iters: int = 0
    lr: float = 1e-4
    lr_decay: float = 0.95
    lr_decay_every: int = 10
    head_lr_scale: float = 30.0
    coarse_to_fine: bool = False
    c2f_iters: tuple = (100, 200)
    tau: float | None = 5.0
    overlap: float = 0.5
    gamma: float = 0.6
    display_mean: float = 0.5
    head_solve: bool = True
    offset_solve: str = "median_gradient"
    anchor: str = "none"
    anchor_every: int = 2
    anchor_smoothing: float = 0.03
    seed: int = 0
    device: str | None = None
    progress: bool = True

    def __post_init__(self):
        # Every field checked here (EventDataError, a ValueError): a bad value never reaches training.
        choices = {"binning": ("fixed", "equal_count"), "temporal_loss": ("derivative", "difference"),
                   "regularizer": ("tikhonov", "tv", "none"), "offset_solve": ("none", "median_gradient")}
        for name, allowed in choices.items():
            if getattr(self, name) not in allowed:
                raise EventDataError(f"{name} must be one of {allowed}, got {getattr(self, name)!r}")
        if self.head_solve and self.regularizer == "tv":
            raise EventDataError("head_solve=True needs regularizer 'tikhonov' or 'none' (TV has no closed form); "
                                 "pass head_solve=False to train the head with Adam")
        if self.anchor not in ANCHOR_MODES:
            raise EventDataError(f"anchor must be one of {ANCHOR_MODES}, got {self.anchor!r}")
        if isinstance(self.anchor_every, bool) or not isinstance(self.anchor_every, (int, np.integer)) or \
                self.anchor_every < 1:
            raise EventDataError(f"anchor_every must be a whole number >= 1, got {self.anchor_every!r}")
        self.anchor_every = int(self.anchor_every)
        if isinstance(self.anchor_smoothing, bool) or not isinstance(self.anchor_smoothing, (int, float, np.integer, np.floating)) \
                or not (math.isfinite(self.anchor_smoothing) and self.anchor_smoothing >= 0):
            raise EventDataError(f"anchor_smoothing must be a finite number of seconds >= 0, got {self.anchor_smoothing!r}")
        self.anchor_smoothing = float(self.anchor_smoothing)

        def number(name, value, *, integer=False):
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) or (
                    integer and not float(value).is_integer()) or not math.isfinite(value):
                raise EventDataError(f"{name} must be a finite {'whole ' if integer else ''}number, got {value!r}")
            return int(value) if integer else float(value)

        if isinstance(self.C, (tuple, list, np.ndarray)):   # (c_pos, c_neg), checked by the one parser of C
            self.C = as_thresholds(self.C, "C")
        elif not number("C", self.C) > 0:
            raise EventDataError(f"C must be positive (or a pair (c_pos, c_neg) of positive numbers), got {self.C}")
        for name in ("bin_duration", "lr", "gamma", "omega_0", "head_lr_scale"):
            if not number(name, getattr(self, name)) > 0:
                raise EventDataError(f"{name} must be positive, got {getattr(self, name)}")
        if self.first_omega_0 is not None and not number("first_omega_0", self.first_omega_0) > 0:
            raise EventDataError(f"first_omega_0 must be positive (or None), got {self.first_omega_0}")
        for name, low in (("n_iters", 0 if self.head_solve else 1), ("min_bins", 0), ("hidden_features", 1), ("hidden_layers", 0), ("lr_decay_every", 1),
                          ("events_per_bin", 1)):
            if number(name, getattr(self, name), integer=True) < low:
                raise EventDataError(f"{name} must be at least {low}, got {getattr(self, name)}")
            setattr(self, name, int(getattr(self, name)))
        if not number("lam", self.lam) >= 0:
            raise EventDataError(f"lam must be zero or positive, got {self.lam}")
        if not 0 < number("lr_decay", self.lr_decay) <= 1:
            raise EventDataError(f"lr_decay must be in (0, 1], got {self.lr_decay}")
        if not 0 < number("display_mean", self.display_mean) < 1:
            raise EventDataError(f"display_mean must be in (0, 1), got {self.display_mean}")
        if self.tau is not None and not number("tau", self.tau) > number("overlap", self.overlap) >= 0:
            raise EventDataError(f"need tau > overlap >= 0 seconds, got tau={self.tau}, overlap={self.overlap}")
        for name in ("head_solve", "coarse_to_fine", "progress"):
            if not isinstance(getattr(self, name), (bool, np.bool_)):
                raise EventDataError(f"{name} must be True or False, got {getattr(self, name)!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) or not 0 <= self.seed < 2**63:
            raise EventDataError(f"seed must be a whole number in [0, 2**63), got {self.seed!r}")
        if self.device is not None and not (isinstance(self.device, str) and
                                            re.fullmatch(r"cpu|mps|cuda(:\d+)?", self.device)):
            raise EventDataError(f"device must be 'cpu', 'cuda', 'cuda:N', 'mps' or None (a GPU when present), "
                                 f"got {self.device!r}")
        self.c2f_iters = tuple(number("c2f_iters", i, integer=True) for i in self.c2f_iters)
        if self.coarse_to_fine:
            if any(i < 1 for i in self.c2f_iters) or list(self.c2f_iters) != sorted(set(self.c2f_iters)):
                raise EventDataError(f"c2f_iters must be increasing iterations >= 1, got {self.c2f_iters}")
            late = [i for i in self.c2f_iters if i >= self.n_iters]
            if late:   # a warning, not an error: fast-mode notebooks shorten n_iters under the default stages
                import warnings

                fix = (f"c2f_iters=({self.n_iters // 3}, {2 * self.n_iters // 3})" if self.n_iters >= 3
                       else "coarse_to_fine=False")
                warnings.warn(f"c2f_iters {late} are not inside the run of n_iters={self.n_iters} iterations: those "
                              f"bisections never happen, so the final bins are coarser than bin_duration; pass {fix}",
                              stacklevel=3)

    @classmethod
    def paper(cls, **overrides) -> "EvINRConfig":
        """The paper's recipe exactly (Sec. 3-4): SIREN 3 x 512 with omega_0 = 30 in every layer, the
        derivative loss (Eq. 5-6) on 1/32 s bins, Tikhonov with lambda 0.05, Adam lr 1e-4 x 0.95 every
        10 iterations for 300 iterations, coarse-to-fine at 100 and 200, 5 s sub-sequences; one
        learning rate for every layer; no head or offset solve."""
        return cls(**{"C": 1.0, "bin_duration": 1 / 32, "binning": "fixed", "temporal_loss": "derivative",
                      "min_bins": 0, "regularizer": "tikhonov", "lam": 0.05, "hidden_features": 512, "hidden_layers": 3,
                      "omega_0": 30.0, "first_omega_0": None, "n_iters": 300, "lr": 1e-4, "lr_decay": 0.95,
                      "lr_decay_every": 10, "head_lr_scale": 1.0, "coarse_to_fine": True, "c2f_iters": (100, 200),
                      "tau": 5.0, "overlap": 0.5, "gamma": 0.6, "head_solve": False, "offset_solve": "none",
                      **overrides})

    @classmethod
    def v0_1(cls, **overrides) -> "EvINRConfig":
        """The kit's default of version 0.1 (before the scene zoo): the paper's recipe with
        first_omega_0 = 10 and head_lr_scale = 30, tuned on the demo scene alone. Kept so that
        benchmarks compare today's default with it in the same run."""
        return cls.paper(**{"first_omega_0": 10.0, "head_lr_scale": 30.0, **overrides})

    @classmethod
    def base(cls, **overrides) -> "EvINRConfig":
        """The paper's ablation 'Base': no spatial regularization, no coarse-to-fine."""
        return cls.v0_1(**{"regularizer": "none", "coarse_to_fine": False, **overrides})

    @classmethod
    def reference_code(cls, **overrides) -> "EvINRConfig":
        """The public reference code's choices where they differ from the paper (as far as this
        solver expresses them): anisotropic TV, equal-count bins, a boundary-difference temporal
        term (evaluated at the boundaries, without the code's half-bin shift), omega_0 = 10.

        Its bin count depends on the data (the code uses 100 bins over the window, 50 before one
        bisection at n_iters / 2): pass ``events_per_bin=n_events // 100, c2f_iters=(n_iters // 2,)``.
        Not expressible here: AdamW at a fixed lr 3e-4 for 1000 steps, the extra regularizer terms,
        the sigmoid tone mapping."""
        return cls.paper(**{"regularizer": "tv", "binning": "equal_count", "temporal_loss": "difference",
                            "omega_0": 10.0, "first_omega_0": 10.0, "head_lr_scale": 10.0, **overrides})

    @property
    def n_bisections(self) -> int:
        """How many times the bins are halved during training."""
        return len(self.c2f_iters) if self.coarse_to_fine else 0


def split_windows(t_start: float, t_end: float, tau: float | None, overlap: float) -> np.ndarray:
    """N equal windows covering [t_start, t_end], each at most ``tau`` s, neighbours sharing ``overlap`` s.

    Returns float64 [N, 2] (seconds). N = 1 when tau is None or the span fits in one window.
    """
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


def _initial_boundaries(events: Events, windows: np.ndarray, cfg: EvINRConfig) -> list[np.ndarray]:
    """Bin edges per window at the coarsest stage: 2^n_bisections times coarser than the final bins."""
    factor = 2 ** cfg.n_bisections
    out = []
    if cfg.binning == "fixed":
        n_final = max(factor, cfg.min_bins, int(round((windows[0, 1] - windows[0, 0]) / cfg.bin_duration)))
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
                         cfg.omega_0, cfg.first_omega_0, seed=cfg.seed).to(device)
    device = model.head_weight.device
    if model.n_models != len(windows):
        raise ValueError(f"model holds {model.n_models} networks but {len(windows)} windows were given")
    head = [model.head_weight, model.head_bias]
    trunk = [p for n, p in model.named_parameters() if not n.startswith("head_")]
    groups = [{"params": trunk}, {"params": head, "lr": cfg.lr * cfg.head_lr_scale}]
    opt = make_adam(groups, lr=cfg.lr) if fast else torch.optim.Adam(groups, lr=cfg.lr)
    sched = torch.optim.lr_scheduler.StepLR(opt, step_size=cfg.lr_decay_every, gamma=cfg.lr_decay)
    boundaries = _initial_boundaries(events, windows, cfg)
    bins = _Bins.build(events, boundaries, cfg.C, device)
    regularizer = cfg.regularizer if cfg.lam > 0 else "none"
    history = {"loss": [], "temporal": [], "regularizer": [], "n_bins": []}
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
        solved = solve_head(model, bins.boundaries, bins.frames, cfg.temporal_loss, regularizer, cfg.lam)
        history["head_solve_s"] = solved["seconds"]
        history["temporal_after_solve"] = solved["temporal"]
    history["final_bins"] = int(bins.frames.shape[1])
    if device.type == "cuda":
        torch.cuda.synchronize(device)
    history["train_time_s"] = time.perf_counter() - t0
    return model, history


@dataclass(eq=False)
class Reconstruction:
    """A trained EvINR and its predictions.

    Attributes:
        times: float64 [Q] query times (seconds, the events' clock).
        log_intensity: float32 [Q, H, W] anchored log intensity at ``times``.
        frames: float32 [Q, H, W] tone-mapped frames in [0, 1].
        model: the trained FrameINR (N networks). windows: [N, 2] their time windows (s).
        offsets: float32 [N, H, W] per-network offsets added by the alignment and the anchor.
        config: the EvINRConfig used. history: training curves and time (see train_frame_inr).
        anchor: the :class:`~evinr_lite.method.anchor.AnchorFit` of an anchored reconstruction
            (``config.anchor`` "first" or "all"), else None; ``anchor_times`` the frames it used.
    """

    times: np.ndarray
    log_intensity: np.ndarray
    frames: np.ndarray
    model: FrameINR
    windows: np.ndarray
    offsets: np.ndarray
    config: EvINRConfig
    history: dict = field(repr=False)
    anchor: object = field(default=None, repr=False)

    @property
    def anchor_times(self) -> np.ndarray:
        """float64 [K] times (s) of the APS frames used as anchors (empty when events only): not to be scored."""
        return np.zeros(0) if self.anchor is None else self.anchor.times.copy()

    def at(self, times, chunk: int = 256) -> np.ndarray:
        """Anchored log intensity at any times (seconds) inside the windows: float32 [Q, H, W]."""
        t = np.atleast_1d(np.asarray(times, np.float64))
        L = blend_networks(self.model, self.windows, t, self.offsets, chunk)
        return L if self.anchor is None else L + self.anchor.offset_at(t)

    def frames_at(self, times) -> np.ndarray:
        """Frames in [0, 1] at any times: float32 [Q, H, W]; tone-mapped, or the APS frames' linear
        intensity when anchored (:func:`evinr_lite.method.anchor.linear_frames`)."""
        if self.anchor is not None:
            return linear_frames(self.at(times))
        return tonemap_reinhard(self.at(times), self.config.gamma).astype(np.float32)


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
    F = predict_networks(model, times, chunk) + offsets[:, None]
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


def reconstruct(events: Events, query_times, config: EvINRConfig | None = None, *,
                t_start: float | None = None, t_end: float | None = None, frames=None) -> Reconstruction:
    """Reconstruct log intensity and tone-mapped frames at ``query_times`` from events alone.

    Args:
        events: the events (their sensor_size gives H, W).
        query_times: [Q] seconds on the events' clock, inside [t_start, t_end].
        config: EvINRConfig (paper defaults when None).
        t_start, t_end: span to reconstruct (seconds); default: from the first to the last event,
            widened to include the query times.
        frames: the APS frames (:class:`~evinr_lite.core.frames.Frames`, on the events' clock) for
            ``config.anchor`` "first" or "all" (:mod:`evinr_lite.method.anchor`); frames outside
            [t_start, t_end] are ignored. Needed by an anchored config, refused by an events-only one.

    Returns:
        Reconstruction with frames [Q, H, W] in [0, 1] and log intensities [Q, H, W].
    """
    cfg = config or EvINRConfig()
    q = np.atleast_1d(np.asarray(query_times, dtype=np.float64))
    if len(events) < 2:
        raise EventDataError(f"need at least 2 events to reconstruct, got {len(events)}; choose a longer window")
    if q.size == 0 or not np.all(np.isfinite(q)):
        raise EventDataError("query_times must be a non-empty array of finite seconds")
    t_start = min(events.t[0], q.min()) if t_start is None else float(t_start)
    t_end = max(events.t[-1], q.max()) if t_end is None else float(t_end)
    if q.min() < t_start or q.max() > t_end:
        raise EventDataError(f"query times span [{q.min()}, {q.max()}] s, outside [t_start, t_end] = "
                             f"[{t_start}, {t_end}] s; widen the span or drop those times")
    events = events.slice_time(t_start, np.nextafter(t_end, np.inf), allow_empty=True)
    if len(events) < 2:
        raise EventDataError(f"fewer than 2 events in [{t_start}, {t_end}] s; choose a window with events")
    windows = split_windows(t_start, t_end, cfg.tau, cfg.overlap)
    if cfg.anchor != "none":   # checked before training
        frames = frames_in_window(frames, events.sensor_size, t_start, t_end, cfg.anchor)
    elif frames is not None:
        raise EventDataError("frames= were given but config.anchor is 'none' (events only): pass "
                             "EvINRConfig(anchor='first') or anchor='all' to use them, or leave frames= out")
    model, history = train_frame_inr(events, windows, cfg)
    model.eval()
    offsets = alignment_offsets(model, windows)
    if cfg.anchor != "none":   # the frames fix the per-pixel offset and the level: no solve, no mean anchor
        fit = fit_anchor(lambda t: blend_networks(model, windows, t, offsets), frames, cfg.anchor,
                         every=cfg.anchor_every, smoothing=cfg.anchor_smoothing)
        history["config"] = asdict(cfg)
        history["anchor"] = fit.summary()
        L = blend_networks(model, windows, q, offsets) + fit.offset_at(q)       # = Reconstruction.at(q)
        return Reconstruction(q, L, linear_frames(L), model, windows, offsets, cfg, history, fit)
    n_grid = min(64, 8 * len(windows))          # the anchor's times (as the paper's recipe always had them)
    if cfg.offset_solve == "median_gradient":
        n_grid = max(64, 8 * len(windows))      # a temporal median wants many frames; the anchor shares them
    grid = np.linspace(t_start, t_end, n_grid)
    if cfg.offset_solve == "median_gradient":   # one offset image for all networks: the alignment stays
        offsets += median_gradient_offset(blend_networks(model, windows, grid, offsets)).astype(np.float32)
    # anchor: mean log intensity over the sequence tone-maps to display_mean
    mean_L = float(blend_networks(model, windows, grid, offsets).mean())
    offsets += np.float32(anchor_level(cfg.gamma, cfg.display_mean) - mean_L)
    L = blend_networks(model, windows, q, offsets)
    frames = tonemap_reinhard(L, cfg.gamma).astype(np.float32)
    history["config"] = asdict(cfg)
    return Reconstruction(q, L, frames, model, windows, offsets, cfg, history)
