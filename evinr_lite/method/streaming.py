"""Streaming reconstruction: one window at a time, in memory set by the window and the sensor.

    for part in stream_reconstruct(open_recording(path), times, EvINRConfig()):
        save(part.times, part.frames)          # frames of the times this window finished

:func:`~evinr_lite.method.solver.reconstruct` trains the N networks of a sequence together and
keeps them all, so its memory grows with the recording (N heads of d x H x W values, N x Q
predictions). Here window k is read from the source (only its events), its network is trained
(:func:`train_window`), chained onto its predecessor (:func:`chain_offset`), queried at the times
inside it (:func:`network_at`), and its finished frames are handed out before window k + 1 is
read. What one window hands to the next is a :class:`StreamState` of a few images, never a
network, so a run can be saved after every window and resumed.

What is the same as the whole-sequence solve, and what is not (tests/test_streaming.py):

- network k: the same seed (:func:`~evinr_lite.method.models.network_seed`), the same bins and the
  same training, so the same network up to float rounding;
- the alignment over each overlap and the linear cross-fade: the same (the previous network's
  values at the shared sample times and query times are carried);
- the per-pixel offset image (``offset_solve``) and the level anchor (``display_mean``): the
  whole-sequence solve takes them from a time grid over the whole span, which is only known at
  the end. Streaming takes them from the same grid over the *first window* (64 frames) and
  carries them: identical when the span is one window (the zoo's scenes, the real chunk); for
  longer spans the offset image is estimated from the first ``tau`` seconds.
- anchored configs (``anchor`` "first" / "all") fit over the whole span; they are refused here
  (use :func:`~evinr_lite.method.solver.reconstruct`).

Times are float64 seconds; images float32 [.., H, W].
"""
from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import torch

from ..core.events import EventDataError, Events
from ..core.runtime import default_device
from .config import EvINRConfig
from .ensemble import blend_weights, predict_networks, split_windows
from .models import FrameINR
from .offset import median_gradient_offset
from .tonemap import anchor_level, tonemap_reinhard
from .training import train_frame_inr

__all__ = ["stream_reconstruct", "StreamPart", "StreamState", "train_window", "network_at", "chain_offset",
           "alignment_times", "first_window_offset", "offset_grid", "PREDICT_CELLS", "N_ALIGN_SAMPLES"]

PREDICT_CELLS = 1 << 24     # frames x pixels per prediction batch (64 MB of float32), whatever the sensor
N_ALIGN_SAMPLES = 8         # times at which neighbouring networks are compared (as ensemble.alignment_offsets)
_EDGE = 1e-9                # seconds: a time this close to a window belongs to it (as ensemble.blend_weights)


@dataclass
class StreamPart:
    """The frames one window finished: times float64 [Q_k] (s), log_intensity and frames float32
    [Q_k, H, W] (anchored log intensity; tone-mapped in [0, 1]), ``indices`` int64 [Q_k] their
    positions in the query times, ``window`` (index, t_lo, t_hi) and the window's training history."""

    times: np.ndarray
    indices: np.ndarray
    log_intensity: np.ndarray
    frames: np.ndarray
    window: tuple
    history: dict = field(repr=False)


@dataclass
class StreamState:
    """What window k hands to window k + 1: images, never a network (so a run can resume).

    Attributes:
        next_window: index of the next window to train.
        align: float32 [H, W] the last network's alignment offset (the chain of overlap means).
        offset: float32 [H, W] offset image + level from the first window (None before it).
        samples: float32 [S, H, W] the last network at the alignment times shared with the next
            one (None for the last window).
        pending: int64 [M] query indices that wait for the next network; pending_sum float32
            [M, H, W] their blend so far.
        train_time_s: training seconds so far. windows: float64 [N, 2] the plan (checked on resume).
    """

    next_window: int
    align: np.ndarray
    offset: np.ndarray | None
    samples: np.ndarray | None
    pending: np.ndarray
    pending_sum: np.ndarray
    train_time_s: float
    windows: np.ndarray

    def save(self, path) -> None:
        """Write to ``path`` (.npz), beside and then renamed into place (never half-written)."""
        path = Path(path)
        tmp = path.with_name(f".{path.name}.partial")
        arrays = {k: v for k, v in dataclasses.asdict(self).items() if v is not None}
        with open(tmp, "wb") as f:
            np.savez(f, **{k: np.asarray(v) for k, v in arrays.items()})
        tmp.replace(path)

    @classmethod
    def load(cls, path) -> "StreamState":
        with np.load(path) as z:
            get = {k: z[k] for k in z.files}
        return cls(next_window=int(get["next_window"]), align=get["align"], offset=get.get("offset"),
                   samples=get.get("samples"), pending=get["pending"].astype(np.int64),
                   pending_sum=get["pending_sum"], train_time_s=float(get["train_time_s"]),
                   windows=get["windows"])


def offset_grid(t_start: float, t_end: float, n_windows: int, config: EvINRConfig) -> np.ndarray:
    """float64 [G] times (s) at which the offset solve and the level anchor look at a span of
    ``n_windows`` windows (the whole-sequence solve's grid; streaming uses it over the first window)."""
    n_grid = min(64, 8 * n_windows)          # the level anchor's times (as the paper's recipe always had them)
    if config.offset_solve == "median_gradient":
        n_grid = max(64, 8 * n_windows)      # a temporal median wants many frames; the level anchor shares them
    return np.linspace(t_start, t_end, n_grid)


def alignment_times(windows: np.ndarray, k: int) -> np.ndarray:
    """float64 [S] times (s) at which networks k - 1 and k are compared: their overlap."""
    return np.linspace(windows[k, 0], windows[k - 1, 1], N_ALIGN_SAMPLES)


def network_at(model: FrameINR, times: np.ndarray) -> np.ndarray:
    """A one-network model's output (no offset) at ``times`` [Q] (s): float32 [Q, H, W], predicted
    a bounded number of frames at a time (PREDICT_CELLS), whatever the sensor."""
    H, W = model.sensor_size
    chunk = max(1, PREDICT_CELLS // (H * W))
    return predict_networks(model, np.asarray(times, np.float64), chunk)[0]


def train_window(events: Events, windows: np.ndarray, k: int, config: EvINRConfig):
    """Train network k of the plan ``windows`` [N, 2] on ``events`` (at least those of its window):
    (model, history), the model a one-network FrameINR initialised as network k of the ensemble."""
    device = default_device(config.device)
    solve_only = config.head_solve and config.n_iters == 0   # the head is solved, never trained: no draws
    model = FrameINR(events.sensor_size, windows[k:k + 1], config.hidden_features, config.hidden_layers,
                     config.omega_0, config.first_omega_0, seed=config.seed, first_index=k,
                     init_head=not solve_only).to(device)
    model, history = train_frame_inr(events, windows[k:k + 1], config, model=model)
    model.eval()
    return model, history


def chain_offset(previous_align: np.ndarray, previous_samples: np.ndarray, model: FrameINR,
                 times: np.ndarray) -> np.ndarray:
    """Network k's alignment offset [H, W]: its predecessor's plus the mean over their overlap of
    (predecessor - network k) at ``times`` (as :func:`~evinr_lite.method.ensemble.alignment_offsets`)."""
    return previous_align + (previous_samples - network_at(model, times)).mean(axis=0)


def first_window_offset(model: FrameINR, window, config: EvINRConfig) -> np.ndarray:
    """The offset image + level [H, W] float32 that every network gets, from the first window.

    Same grid, same steps and same float32 order as the whole-sequence solve over one window
    (:func:`offset_grid`, median_gradient_offset, the level anchor), so a one-window span gives
    the identical result."""
    grid = offset_grid(float(window[0]), float(window[1]), 1, config)
    F = network_at(model, grid)
    H, W = model.sensor_size
    offset = np.zeros((H, W), np.float32)
    if config.offset_solve == "median_gradient":
        offset += median_gradient_offset(F).astype(np.float32)
    F += offset
    offset += np.float32(anchor_level(config.gamma, config.display_mean) - float(F.mean()))
    return offset


def _check(source, query_times, config, t_start, t_end):
    cfg = config or EvINRConfig()
    if cfg.anchor != "none":
        raise EventDataError(f"streaming does not take anchored configs (anchor={cfg.anchor!r}): the APS frames fit "
                             "the offset over the whole span; use reconstruct(...) for them")
    q = np.atleast_1d(np.asarray(query_times, dtype=np.float64))
    if q.size == 0 or not np.all(np.isfinite(q)):
        raise EventDataError("query_times must be a non-empty array of finite seconds")
    if np.any(np.diff(q) < 0):
        raise EventDataError("query_times must be sorted (increasing seconds) for streaming; pass np.sort(times)")
    first, last = source.t_span
    t_start = min(first, q.min()) if t_start is None else float(t_start)
    t_end = max(last, q.max()) if t_end is None else float(t_end)
    if q.min() < t_start or q.max() > t_end:
        raise EventDataError(f"query times span [{q.min()}, {q.max()}] s, outside [t_start, t_end] = "
                             f"[{t_start}, {t_end}] s; widen the span or drop those times")
    return cfg, q, t_start, t_end


def stream_reconstruct(source, query_times, config: EvINRConfig | None = None, *, t_start: float | None = None,
                       t_end: float | None = None, state: StreamState | None = None, on_window=None,
                       progress: bool | None = None):
    """Reconstruct window after window, yielding each window's finished frames (:class:`StreamPart`).

    Args:
        source: a :class:`~evinr_lite.io.source.RecordingSource` (``open_recording(path)``), or a
            Recording / Events in memory (wrapped with ``as_source``).
        query_times: float64 [Q] sorted seconds inside [t_start, t_end].
        config: EvINRConfig (the kit's default when None); anchored configs are refused.
        t_start, t_end: the span (default: the source's events, widened to the query times).
        state: a :class:`StreamState` saved by ``on_window`` to resume from (its plan must match).
        on_window: called as on_window(part, state) after each window, once its frames are final
            (the place to write them and save the state).
        progress: a tqdm bar counting windows with an ETA (default: ``config.progress``).

    Memory: one network, its window's events and bins, and a bounded batch of predictions (plus the
    frames of one overlap), whatever the recording's length.
    """
    from ..io.source import as_source
    from tqdm.auto import tqdm

    source = as_source(source)
    cfg, q, t_start, t_end = _check(source, query_times, config, t_start, t_end)
    windows = split_windows(t_start, t_end, cfg.tau, cfg.overlap)
    N = len(windows)
    H, W = source.sensor_size
    if state is None:
        state = StreamState(0, np.zeros((H, W), np.float32), None, None, np.zeros(0, np.int64),
                            np.zeros((0, H, W), np.float32), 0.0, windows)
    elif state.windows.shape != windows.shape or not np.allclose(state.windows, windows, rtol=0, atol=1e-9):
        raise EventDataError("the saved streaming state belongs to another plan of windows (another span, tau or "
                             "overlap); start again without it")
    quiet = dataclasses.replace(cfg, progress=False)   # one bar for the windows, none per window
    show = cfg.progress if progress is None else progress
    bar = tqdm(total=N, initial=state.next_window, desc="EvINR windows", unit="window", disable=not show)
    try:
        for k in range(state.next_window, N):
            lo, hi = windows[k]
            end = np.nextafter(hi, np.inf)      # the last window's end is inclusive (as reconstruct's span)
            events = source.events(lo, end)
            if len(events) < 2:
                raise EventDataError(f"window {k} [{lo:.6f}, {hi:.6f}] s holds {len(events)} event(s); EvINR needs "
                                     "events in every window: choose a span with events throughout or a longer tau")
            t0 = time.perf_counter()
            model, history = train_window(events, windows, k, quiet)
            del events
            align = state.align if k == 0 else chain_offset(state.align, state.samples, model,
                                                            alignment_times(windows, k))
            offset = first_window_offset(model, windows[0], cfg) if k == 0 else state.offset
            total = align + offset if k else offset.copy()    # k = 0: align is zero
            part = _blend_window(model, windows, k, q, total, state)
            samples = network_at(model, alignment_times(windows, k + 1)) if k + 1 < N else None
            del model
            history["window_s"] = time.perf_counter() - t0
            state = StreamState(k + 1, align.astype(np.float32), offset, samples, part.pop("pending"),
                                part.pop("pending_sum"), state.train_time_s + history["train_time_s"], windows)
            L = part["L"]
            out = StreamPart(q[part["idx"]], part["idx"], L, tonemap_reinhard(L, cfg.gamma).astype(np.float32),
                             (k, float(lo), float(hi)), history)
            if on_window is not None:
                on_window(out, state)
            bar.update(1)
            yield out
    finally:
        bar.close()


def _blend_window(model, windows, k, q, total_offset, state) -> dict:
    """Network k's share of the cross-fade at the query times inside its window: the finished
    times' log intensities, and the times still waiting for network k + 1 with their partial sums."""
    lo, hi = windows[k]
    a, b = np.searchsorted(q, lo - _EDGE, "left"), np.searchsorted(q, hi + _EDGE, "right")
    idx = np.arange(a, b, dtype=np.int64)
    H, W = model.sensor_size
    if idx.size == 0:
        return {"idx": idx, "L": np.zeros((0, H, W), np.float32), "pending": idx,
                "pending_sum": np.zeros((0, H, W), np.float32)}
    w = blend_weights(windows, q[idx])                 # [N, Q_k]: the whole plan's weights
    L = network_at(model, q[idx])
    L += total_offset
    if len(windows) > 1:                               # the cross-fade; one window: weight 1 everywhere
        L *= w[k].astype(np.float32)[:, None, None]
        if state.pending.size:                         # the predecessor's share of the shared times
            where = np.searchsorted(idx, state.pending)
            L[where] += state.pending_sum
    waiting = w[k + 1] > 0 if k + 1 < len(windows) else np.zeros(idx.size, bool)
    return {"idx": idx[~waiting], "L": L[~waiting], "pending": idx[waiting], "pending_sum": L[waiting]}
