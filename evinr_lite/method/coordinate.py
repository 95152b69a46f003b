"""The basic EvINR (paper Sec. 3.2): a coordinate network F(x, y, t) -> L, trained from events.

This is the version the paper starts from and then abandons for speed (Sec. 3.3, "coordinate-based
to frame-based optimization"). One SIREN takes a single space-time point and returns one log
intensity::

    model = CoordinateINR((H, W), t_range=(0.0, 1.0))
    F = model(x, y, t)                                   # [M] pixels, pixels, seconds -> [M]
    F, dF_dt, dF_dx, dF_dy = model.derivatives(x, y, t)  # autograd, ready for double back-propagation

Coordinates are mapped to [-1, 1] inside the model: x (column) from [0, W - 1], y (row) from
[0, H - 1] and t from ``t_range``. The derivatives are returned in the caller's units (chain rule):
dF/dt in log units per **second**, dF/dx and dF/dy in log units per **pixel**, so the losses below
mean the same thing whatever the window length or sensor size.

Training (:func:`train_coordinate_inr`) samples, at every iteration, a minibatch of M (bin, pixel)
pairs out of the B * H * W of the event frames (fixed-duration bins, :mod:`evinr_lite.method.binning`) and
minimises, over that minibatch,

- the temporal loss (Eq. 5-6): ``(E_b(y, x) - dF/dt(x, y, c_b) * (t2 - t1))^2`` at the bin mid-point
  c_b, with E the event frame (C times the summed polarities in the bin);
- plus ``lam`` times Tikhonov (Eq. 9) on the autograd spatial gradient:
  ``(dF/dx)^2 + (dF/dy)^2`` at the same points.

Every term is a derivative of the network, so each step back-propagates through a backward pass
("double back-propagation"), for each of the M points. That is why this model is slow: the frame
model ``F(t) -> [H, W]`` (:mod:`evinr_lite.method.solver`) gets all H * W pixels of a bin from one network
evaluation, while here each of the H * W * B coordinates is a separate input (notebook 03 measures
the difference).

The brightness offset: events constrain only changes of L, so F + c fits exactly as well as F for
any constant c. :func:`reconstruct_coordinate` anchors the level as the frame solver does: F is
shifted so that its mean over the time span equals ``logit(display_mean ** (1 / gamma))``, i.e. the
mean log intensity tone-maps to ``display_mean`` (0.5, mid-grey) with the paper's Reinhard curve.

The reference solutions of notebook 03's exercises live here and are registered with
:mod:`evinr_lite.teaching.exercises` at import (``split_index``, ``tikhonov_autograd``).
"""
from __future__ import annotations

import math
import numbers
import time
from dataclasses import asdict, dataclass, field
from typing import Callable

import numpy as np
import torch
from torch import nn

from .binning import events_to_frames, fixed_duration_boundaries
from ..core.checks import check_seed, real_number, seconds_array, true_or_false, whole_number
from ..core.runtime import default_device
from ..core.events import EventDataError, Events, check_sensor_size, check_time_range
from .siren import Siren
from .tonemap import anchor_level, reinhard_unchecked

__all__ = ["CoordinateINR", "CoordinateConfig", "CoordinateBins", "CoordinateReconstruction",
           "bin_events", "split_index", "temporal_loss", "tikhonov_autograd", "train_coordinate_inr",
           "predict_anchored", "reconstruct_coordinate"]

_RENDER_CHUNK = 1 << 16   # coordinates evaluated at once by render()


def _check_range(t_range) -> tuple[float, float]:
    return check_time_range(t_range, "t_range")


# ---- the network -----------------------------------------------------------------------

class CoordinateINR(nn.Module):
    """F(x, y, t) -> log intensity: a SIREN with 3 inputs and 1 output (paper Sec. 3.2).

    Args:
        sensor_size: (H, W) pixels; x in [0, W - 1] and y in [0, H - 1] map to [-1, 1].
        t_range: (t_start, t_end) seconds, mapped to [-1, 1].
        hidden_features, hidden_layers: width and depth of the SIREN (the paper: 512, 3).
        omega_0: SIREN frequency factor of every sine layer (SIREN's default 30).
        seed: seeds the initialisation (the global torch RNG is left untouched).
        first_omega_0: frequency factor of the first layer (None: ``omega_0``).

    Shapes: ``forward(x, y, t)`` with three tensors [M] -> [M] (the model's dtype, float32 unless converted).
    """

    def __init__(self, sensor_size, t_range, hidden_features: int = 256, hidden_layers: int = 3,
                 omega_0: float = 30.0, seed: int = 0, first_omega_0: float | None = None):
        super().__init__()
        H, W = check_sensor_size(sensor_size)
        self.sensor_size = (H, W)
        self.t_range = _check_range(t_range)
        with torch.random.fork_rng(devices=[]):
            torch.manual_seed(int(seed))
            self.siren = Siren(3, 1, hidden_features, hidden_layers, omega_0, first_omega_0)

    # ---- units -----------------------------------------------------------------------
    @property
    def scales(self) -> tuple[float, float, float]:
        """(d x_n / dx, d y_n / dy, d t_n / dt): normalised units per pixel, per pixel, per second."""
        H, W = self.sensor_size
        t0, t1 = self.t_range
        return 2.0 / max(W - 1, 1), 2.0 / max(H - 1, 1), 2.0 / (t1 - t0)

    def normalize(self, x: torch.Tensor, y: torch.Tensor, t: torch.Tensor) -> torch.Tensor:
        """Pixels and seconds [M] -> normalised coordinates [M, 3] (columns x, y, t), in the model's dtype.

        t is shifted in float64 before the cast, so times far from zero keep their resolution.
        A sensor one pixel wide (or high) maps that coordinate to 0.
        """
        for name, v in (("x", x), ("y", y), ("t", t)):
            if not torch.is_tensor(v):
                raise TypeError(f"{name} must be a torch tensor, got {type(v).__name__}")
        if not (x.shape == y.shape == t.shape) or x.ndim != 1:
            raise ValueError(f"x, y, t must be 1-D tensors of the same length, got shapes "
                             f"{tuple(x.shape)}, {tuple(y.shape)}, {tuple(t.shape)}")
        H, W = self.sensor_size
        sx, sy, st = self.scales
        t0, t1 = self.t_range
        p = self.siren.net[0].linear.weight
        kw = dict(device=p.device, dtype=p.dtype)
        xn = x.to(**kw) * sx - 1.0 if W > 1 else torch.zeros(x.shape, **kw)
        yn = y.to(**kw) * sy - 1.0 if H > 1 else torch.zeros(y.shape, **kw)
        tn = ((t.to(device=p.device, dtype=torch.float64) - 0.5 * (t0 + t1)) * st).to(p.dtype)
        return torch.stack([xn, yn, tn], dim=-1)

    # ---- evaluation ------------------------------------------------------------------
    def forward(self, x: torch.Tensor, y: torch.Tensor, t: torch.Tensor) -> torch.Tensor:
        """Log intensity at M points: x (column, pixels), y (row, pixels), t (seconds), each [M] -> [M]."""
        return self.siren(self.normalize(x, y, t))[:, 0]

    def derivatives(self, x: torch.Tensor, y: torch.Tensor, t: torch.Tensor, create_graph: bool = True):
        """F and its first derivatives at M points, by autograd.

        Args:
            x, y, t: [M] pixels, pixels, seconds (gradients with respect to them are not needed).
            create_graph: keep the graph of the derivatives so that a loss on them can be
                back-propagated into the weights (double back-propagation, Eq. 5); False for
                evaluation only.

        Returns:
            (F, dF/dt, dF/dx, dF/dy), four tensors [M]: log units, per second, per pixel, per pixel.
        """
        with torch.enable_grad():
            coords = self.normalize(x, y, t).detach().requires_grad_(True)
            F = self.siren(coords)[:, 0]
            (g,) = torch.autograd.grad(F, coords, grad_outputs=torch.ones_like(F), create_graph=create_graph)
        sx, sy, st = self.scales
        return F, g[:, 2] * st, g[:, 0] * sx, g[:, 1] * sy

    @torch.no_grad()
    def render(self, t, chunk: int = _RENDER_CHUNK) -> np.ndarray:
        """Every pixel at time(s) t (seconds): float32 numpy [H, W] for a scalar, [T, H, W] for [T].

        Evaluated in chunks of ``chunk`` coordinates, without gradients.
        """
        times = np.asarray(t, dtype=np.float64)
        if times.ndim > 1 or not np.all(np.isfinite(times)):
            raise EventDataError(f"t must be a finite scalar or a 1-D array of seconds, got shape {times.shape}")
        H, W = self.sensor_size
        device = self.siren.net[0].linear.weight.device
        tt = torch.as_tensor(np.atleast_1d(times), device=device)
        T = tt.numel()
        n = T * H * W
        out = torch.empty(n, dtype=self.siren.net[0].linear.weight.dtype, device=device)
        for start in range(0, n, chunk):
            k = torch.arange(start, min(start + chunk, n), device=device)
            b, y, x = split_index(k, (H, W))
            out[start:start + k.numel()] = self(x, y, tt[b])
        out = out.reshape(T, H, W).float().cpu().numpy()
        return out[0] if times.ndim == 0 else out

    def num_parameters(self) -> int:
        return sum(p.numel() for p in self.parameters())


# ---- minibatch pieces (the notebook's loop is made of these) ------------------------------

def split_index(index: torch.Tensor, sensor_size) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Flat indices into event frames [B, H, W] (row-major) -> (bin b, row y, column x), each like ``index``.

    ``index = b * H * W + y * W + x``: x is the column (fastest), y the row, b the bin.
    """
    H, W = check_sensor_size(sensor_size)   # (0, W) was torch's ZeroDivisionError, (12.5, W) float indices
    _check_flat_index(index)
    return index // (H * W), (index // W) % H, index % W


def _check_flat_index(index) -> None:
    """split_index's ``index``: whole flat indices (a tensor or array of integers) or one whole index; a type test
    per call (the training loop's): no pass over the values, no device sync."""
    if isinstance(index, (numbers.Integral, np.integer)) and not isinstance(index, bool):
        return   # one whole index (5, np.int64(5)): taken before, split as such
    if not isinstance(index, (torch.Tensor, np.ndarray)) or index.dtype in (torch.bool, np.bool_) or \
            (index.is_floating_point() or index.is_complex() if isinstance(index, torch.Tensor)
             else index.dtype.kind not in "iu"):
        array = isinstance(index, (torch.Tensor, np.ndarray))
        raise EventDataError(f"index= must be a tensor (or numpy array) of whole flat indices (torch.long), or one "
                             f"whole index, got {type(index).__name__}{' of ' + str(index.dtype) if array else ''}; "
                             "e.g. torch.randint(B * H * W, (M,))")


def temporal_loss(dF_dt: torch.Tensor, event_values: torch.Tensor, durations: torch.Tensor) -> torch.Tensor:
    """Eq. 5-6 over a minibatch: mean of (E - dF/dt * (t2 - t1))^2.

    Args:
        dF_dt: [M] per second, at the bin mid-points. event_values: [M] event-frame values
            (C times summed polarities). durations: [M] bin lengths in seconds.
    Returns:
        a scalar tensor.
    """
    return torch.mean((event_values - dF_dt * durations) ** 2)


def tikhonov_autograd(dF_dx: torch.Tensor, dF_dy: torch.Tensor) -> torch.Tensor:
    """Eq. 9 over a minibatch, from autograd gradients [M] (per pixel): mean of dF/dx^2 + dF/dy^2."""
    _check_gradient_pair(dF_dx, dF_dy)
    return torch.mean(dF_dx ** 2 + dF_dy ** 2)


def _check_gradient_pair(dF_dx, dF_dy) -> None:
    """tikhonov_autograd's inputs: float tensors [M] of one shape, M > 0 (type and shape tests only: no pass over the
    values). Two shapes broadcast (or were torch's error); none gave NaN."""
    for name, g in (("dF_dx", dF_dx), ("dF_dy", dF_dy)):
        if not isinstance(g, torch.Tensor) or not g.is_floating_point():
            raise EventDataError(f"{name}= must be a float tensor of gradients [M] (autograd's), got "
                                 f"{type(g).__name__}{' of ' + str(g.dtype) if isinstance(g, torch.Tensor) else ''}; "
                                 "pass torch.as_tensor(values, dtype=torch.float32)")
    if dF_dx.shape != dF_dy.shape or dF_dx.numel() == 0:
        raise EventDataError(f"dF_dx and dF_dy must be gradients [M] of one shape, one per sampled pixel, M > 0; got "
                             f"shapes {tuple(dF_dx.shape)} and {tuple(dF_dy.shape)}")


@dataclass(eq=False)
class CoordinateBins:
    """Event frames prepared for coordinate sampling (tensors on the training device).

    Attributes:
        frames: float32 [B, H, W], C times the summed polarities per bin (b_i < t <= b_{i+1}).
        centers: float64 [B], bin mid-points (s), where dF/dt is evaluated (Eq. 4).
        durations: float32 [B], bin lengths t2 - t1 (s).
        boundaries: float64 numpy [B + 1], the bin edges (s).
    """

    frames: torch.Tensor
    centers: torch.Tensor
    durations: torch.Tensor
    boundaries: np.ndarray

    @property
    def sensor_size(self) -> tuple[int, int]:
        return tuple(self.frames.shape[1:])

    def __len__(self) -> int:
        """B * H * W: the number of (bin, pixel) coordinates the network has to fit."""
        return int(self.frames.numel())


def bin_events(events: Events, t_range, C: float, bin_duration: float = 1 / 32, device=None) -> CoordinateBins:
    """Fixed-duration event frames over ``t_range`` (the last bin may be shorter) as :class:`CoordinateBins`."""
    t0, t1 = _check_range(t_range)
    b = fixed_duration_boundaries(t0, t1, bin_duration)
    ef = events_to_frames(events, b, C)
    device = default_device(device) if not isinstance(device, torch.device) else device
    return CoordinateBins(
        frames=torch.as_tensor(ef.frames, device=device),
        centers=torch.as_tensor(ef.centers, device=device),
        durations=torch.as_tensor(ef.durations, dtype=torch.float32, device=device),
        boundaries=b,
    )


# ---- training ----------------------------------------------------------------------------

@dataclass
class CoordinateConfig:
    """Settings of the coordinate-based EvINR. Paper values where the paper gives them.

    Events:
        C: contrast threshold, log units per event (paper: 1 for IJRR/HQF, 0.25 for AED).
        bin_duration: event-frame length in seconds (paper: 1/32 s).
    Loss:
        lam: weight of the Tikhonov term (paper: 0.05; gradients per pixel, as in the frame solver).
    Network (SIREN F(x, y, t)):
        hidden_features, hidden_layers: width and depth (paper: 512 x 3; default 256 x 3 here to
            keep the teaching runs short). omega_0, first_omega_0: SIREN frequency factors.
    Optimisation:
        n_iters: minibatch steps (default 2000: about 6 passes over 240x180 pixels x 32 bins).
        batch_size: (pixel, bin) coordinates per step.
        lr: Adam learning rate. The paper gives none for the coordinate network (its 1e-4 is the
            frame model's); 3e-4 worked best on notebook 03's scenes for widths 128-256, and 1e-3
            made a 256-wide network collapse to a constant.
        lr_decay, lr_decay_every: multiply the learning rate by ``lr_decay`` every
            ``lr_decay_every`` steps. The paper's frame model decays by 0.95 every 10 of its 300
            steps; a minibatch step sees only a fraction of the coordinates, so the default
            (``lr_decay_every=None``) stretches the same 30 decays over ``n_iters`` steps. Give
            ``lr_decay_every=10`` for the paper's literal schedule.
    Output:
        gamma: Reinhard exponent (paper: 0.6). display_mean: the tone-mapped value the mean log
            intensity is anchored to (see the module docstring).
    Runtime:
        seed: seeds the initialisation and the minibatch draws. device: "cpu", "cuda" or None
            (GPU when present). progress: show a tqdm progress bar.
    """

    C: float = 1.0
    bin_duration: float = 1 / 32
    lam: float = 0.05
    hidden_features: int = 256
    hidden_layers: int = 3
    omega_0: float = 30.0
    first_omega_0: float | None = None
    n_iters: int = 2000
    batch_size: int = 4096
    lr: float = 3e-4
    lr_decay: float = 0.95
    lr_decay_every: int | None = None
    gamma: float = 0.6
    display_mean: float = 0.5
    seed: int = 0
    device: str | None = None
    progress: bool = True

    def __post_init__(self):
        # Every field checked by name before any training (EventDataError, a ValueError as before): lam, the
        # sizes, lr_decay and display_mean of None, text or a list were Python's TypeErrors; True was taken as 1
        # for C, lr, lam and every size; hidden_layers, omega_0, first_omega_0, seed, device and progress were
        # not checked at all (NaN, -1 or text failed inside the training, or trained a network of NaN). Numbers
        # are kept as given; the sizes and the seed are stored as the ints they hold (n_iters=2.0 or
        # batch_size=16.0 were taken and then failed inside the training: "'float' object cannot be interpreted
        # as an integer", torch.randint's error), the flag as a bool.
        for name, hint in (("C", "log intensity per event"), ("bin_duration", "seconds"), ("lr", "Adam's step"),
                           ("gamma", "Reinhard's exponent (paper: 0.6)"), ("omega_0", "SIREN's frequency (30)")):
            real_number(getattr(self, name), name, lo=0, lo_open=True, hint=hint)
        if self.first_omega_0 is not None:
            real_number(self.first_omega_0, "first_omega_0", lo=0, lo_open=True, hint="None: omega_0")
        real_number(self.lam, "lam", lo=0, hint="the Tikhonov weight (paper: 0.05)")
        for name, lo in (("n_iters", 1), ("batch_size", 1), ("hidden_features", 1), ("hidden_layers", 0)):
            setattr(self, name, whole_number(getattr(self, name), name, lo=lo))
        real_number(self.lr_decay, "lr_decay", lo=0, hi=1, lo_open=True)
        if self.lr_decay_every is not None:
            self.lr_decay_every = whole_number(self.lr_decay_every, "lr_decay_every", lo=1)
        if not 0 < real_number(self.display_mean, "display_mean", lo=0, hi=1, lo_open=True) < 1:
            raise EventDataError(f"display_mean= must be in (0, 1), got {self.display_mean!r}")
        self.seed = check_seed(self.seed)
        if self.device is not None and not isinstance(self.device, (str, torch.device)):
            raise EventDataError(f"device= must be 'cpu', 'cuda', 'cuda:N', 'mps' or None (a GPU when present), got "
                                 f"{type(self.device).__name__} {self.device!r}")
        self.progress = true_or_false(self.progress, "progress")

    @property
    def decay_every(self) -> int:
        """Steps between learning-rate decays (``lr_decay_every``, or n_iters / 30 when None)."""
        return int(self.lr_decay_every) if self.lr_decay_every is not None else max(1, round(self.n_iters / 30))


def _check_events(events) -> None:
    if not isinstance(events, Events):
        raise TypeError(f"events must be an evinr_lite.Events, got {type(events).__name__}")
    if len(events) < 2:
        raise EventDataError(f"need at least 2 events to train, got {len(events)}; choose a longer time window")


def train_coordinate_inr(events: Events, config: CoordinateConfig | None = None, t_range=None,
                         callback: Callable[[int, CoordinateINR], None] | None = None):
    """Fit F(x, y, t) to events by minibatches of coordinates (Eq. 5-6 + lam * Eq. 9).

    Args:
        events: the events (their sensor_size gives H, W).
        config: :class:`CoordinateConfig` (defaults when None).
        t_range: (t_start, t_end) seconds to model; default: first to last event.
        callback: ``callback(iteration, model)`` after every step (e.g. to evaluate snapshots);
            its time is excluded from the timings.

    Returns:
        (model, history): the trained :class:`CoordinateINR` and a dict of per-step lists
        ``"loss"``, ``"temporal"``, ``"regularizer"``, ``"time_s"`` (cumulative training seconds
        after each step), plus ``"train_time_s"`` (float) and ``"n_coordinates"`` (B * H * W).
        The loss is not offset-anchored: any F + c has the same loss.
    """
    cfg = config or CoordinateConfig()
    _check_events(events)
    t_range = (events.t[0], events.t[-1]) if t_range is None else t_range
    t0, t1 = _check_range(t_range)
    device = default_device(cfg.device)
    bins = bin_events(events, (t0, t1), cfg.C, cfg.bin_duration, device)
    model = CoordinateINR(events.sensor_size, (t0, t1), cfg.hidden_features, cfg.hidden_layers,
                          cfg.omega_0, seed=cfg.seed, first_omega_0=cfg.first_omega_0).to(device)
    opt = torch.optim.Adam(model.parameters(), lr=cfg.lr)
    sched = torch.optim.lr_scheduler.StepLR(opt, step_size=cfg.decay_every, gamma=cfg.lr_decay)
    gen = torch.Generator().manual_seed(int(cfg.seed))
    history = {"loss": [], "temporal": [], "regularizer": [], "time_s": [], "n_coordinates": len(bins)}

    from tqdm.auto import tqdm

    elapsed = 0.0
    bar = tqdm(range(cfg.n_iters), desc="coordinate EvINR", disable=not cfg.progress, leave=False)
    for it in bar:
        start = time.perf_counter()
        index = torch.randint(len(bins), (cfg.batch_size,), generator=gen).to(device)
        b, y, x = split_index(index, bins.sensor_size)
        _, dF_dt, dF_dx, dF_dy = model.derivatives(x, y, bins.centers[b])
        temporal = temporal_loss(dF_dt, bins.frames[b, y, x], bins.durations[b])
        reg = tikhonov_autograd(dF_dx, dF_dy)
        loss = temporal + cfg.lam * reg
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()
        sched.step()
        history["loss"].append(loss.item())       # .item() waits for the GPU: the timing is honest
        history["temporal"].append(temporal.item())
        history["regularizer"].append(reg.item())
        elapsed += time.perf_counter() - start
        history["time_s"].append(elapsed)
        if it % 10 == 0:
            bar.set_postfix(loss=f"{history['loss'][-1]:.4g}")
        if callback is not None:
            callback(it, model)
    bar.close()
    history["train_time_s"] = elapsed
    model.eval()
    return model, history


# ---- brightness anchor and reconstruction ----------------------------------------------

MAX_ANCHORS = 4096   # predict_anchored's anchor frames: each is rendered [H, W]; 16 set the offset as well as more


def predict_anchored(model: CoordinateINR, query_times, gamma: float = 0.6, display_mean: float = 0.5,
                     n_anchor: int = 16) -> tuple[np.ndarray, float]:
    """Anchored log intensity at ``query_times`` [Q] (s): (float32 [Q, H, W], the offset added).

    The offset is set on ``n_anchor`` evenly spaced times over the model's whole ``t_range``
    (not on the query times), so it does not depend on which frames are asked for.
    """
    if not isinstance(model, CoordinateINR):
        raise EventDataError(f"model= must be a CoordinateINR (e.g. reconstruct_coordinate(...).model), got "
                             f"{type(model).__name__}")
    # 0 anchors gave NaN frames, 1.5 or None numpy's linspace error, 10**12 a MemoryError
    n_anchor = whole_number(n_anchor, "n_anchor", lo=1, hi=MAX_ANCHORS)
    query_times = seconds_array(query_times, "query_times", allow_empty=True)   # text was numpy's ValueError
    grid = np.linspace(*model.t_range, n_anchor)
    offset = anchor_level(gamma, display_mean) - float(model.render(grid).mean())   # as tonemap.anchor_mean
    L = model.render(np.atleast_1d(np.asarray(query_times, dtype=np.float64))) + np.float32(offset)
    return L.astype(np.float32), offset


@dataclass(eq=False)
class CoordinateReconstruction:
    """A trained coordinate EvINR and its predictions (the fields match the frame solver's).

    Attributes:
        times: float64 [Q] query times (s). log_intensity: float32 [Q, H, W], anchored.
        frames: float32 [Q, H, W] tone-mapped (Reinhard, ``config.gamma``), in [0, 1].
        model: the trained :class:`CoordinateINR`. offset: the constant added by the anchor.
        config: the :class:`CoordinateConfig`. history: see :func:`train_coordinate_inr`.
    """

    times: np.ndarray
    log_intensity: np.ndarray
    frames: np.ndarray
    model: CoordinateINR
    offset: float
    config: CoordinateConfig
    history: dict = field(repr=False)

    def at(self, times) -> np.ndarray:
        """Anchored log intensity at any times (s): float32 [Q, H, W]."""
        return (self.model.render(seconds_array(times, "times", allow_empty=True)) + np.float32(self.offset))

    def frames_at(self, times) -> np.ndarray:
        """Tone-mapped frames in [0, 1] at any times: float32 [Q, H, W]."""
        return reinhard_unchecked(self.at(times), self.config.gamma).astype(np.float32)


def reconstruct_coordinate(events: Events, query_times, config: CoordinateConfig | None = None, *,
                           t_start: float | None = None, t_end: float | None = None,
                           callback: Callable[[int, CoordinateINR], None] | None = None) -> CoordinateReconstruction:
    """Train a coordinate EvINR on the events and return anchored, tone-mapped frames at ``query_times``.

    Args:
        events: the events. query_times: [Q] seconds inside [t_start, t_end].
        config: :class:`CoordinateConfig`. t_start, t_end: the span to model (default: first
            to last event, widened to include the query times). callback: see
            :func:`train_coordinate_inr`.

    Returns:
        :class:`CoordinateReconstruction` with frames [Q, H, W] in [0, 1].
    """
    cfg = config or CoordinateConfig()
    _check_events(events)
    q = np.atleast_1d(np.asarray(query_times, dtype=np.float64))
    if q.size == 0 or q.ndim != 1 or not np.all(np.isfinite(q)):
        raise EventDataError("query_times must be a non-empty 1-D array of finite seconds")
    t_start = min(events.t[0], q.min()) if t_start is None else float(t_start)
    t_end = max(events.t[-1], q.max()) if t_end is None else float(t_end)
    _check_range((t_start, t_end))
    if q.min() < t_start or q.max() > t_end:
        raise EventDataError(f"query times span [{q.min()}, {q.max()}] s, outside [t_start, t_end] = "
                             f"[{t_start}, {t_end}] s; widen the span or drop those times")
    model, history = train_coordinate_inr(events, cfg, (t_start, t_end), callback=callback)
    L, offset = predict_anchored(model, q, cfg.gamma, cfg.display_mean)
    frames = reinhard_unchecked(L, cfg.gamma).astype(np.float32)
    history["config"] = asdict(cfg)
    return CoordinateReconstruction(q, L, frames, model, offset, cfg, history)
