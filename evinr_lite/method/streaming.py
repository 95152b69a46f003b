"""Streaming reconstruction: one window at a time, in memory set by the window and the sensor.

    for part in stream_reconstruct(open_recording(path), times, EvINRConfig()):
        save(part.indices, part.frames)        # finished frames, in time order

:func:`~evinr_lite.method.solver.reconstruct` trains the N networks of a sequence together and
keeps them all, so its memory grows with the recording (N heads of d x H x W values, N x Q
predictions). Here window k is read from the source (only its events), its network is trained
(:func:`train_window`), chained onto its predecessor (:func:`chain_offset`) and queried at the
times inside it (:func:`network_at`), and it is dropped before window k + 1 is read. What one
window hands to the next is a :class:`StreamState` of a few images, never a network, so a run can
be saved after every window and resumed (``on_state``, ``state=``).

What is the same as the whole-sequence solve (tests/test_streaming.py):

- network k: the same seed (:func:`~evinr_lite.method.models.network_seed`), the same bins and the
  same training and the same events: hot pixels, background filter, ON/OFF balance and lam from
  counting passes over the span, each window read with the background filter's reach beyond its
  edges (:func:`~evinr_lite.method.prepare.prepare_source`);
- the alignment over each overlap and the linear cross-fade (the previous network's values at
  the shared times are carried);
- the per-pixel offset image (``offset_solve``) and the level anchor (``display_mean``), which the
  whole-sequence solve takes from a time grid over the whole span. ``offset_from="span"`` (the
  default) collects that grid window by window and spills each window's log intensities to disk,
  then applies the offset in a final pass: the whole-sequence result up to float32 rounding (and
  bit-identical for one window). ``offset_from="first_window"`` takes them from the first window's
  grid and hands out each window's frames as it finishes (on the zoo's 20 s pan: CLAHE-SSIM 0.4559
  against 0.4944 for the whole span).
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

from ..core.checks import check_reach, choice, optional_seconds, require, seconds_array
from ..core.events import EventDataError, Events
from ..core.runtime import default_device
from .memory import check_memory
from .prepare import prepare_source, read_chunks
from .stream_sizes import MIN_BATCH, PREDICT_CELLS, TONEMAP_CELLS
from .config import EvINRConfig
from .ensemble import blend_weights, predict_networks, split_windows
from .models import FrameINR
from .coarse import coarse_applies, coarse_correction
from .offset import OffsetTrend, offset_trend, offset_grid, offset_image, trend_knots
from .tonemap import display_shift, to_display
from .training import train_frame_inr

__all__ = ["stream_reconstruct", "StreamPart", "StreamState", "train_window", "network_at", "chain_offset",
           "alignment_times", "first_window_offset", "offset_grid", "span_offset", "tonemap",
           "OFFSET_FROM", "PREDICT_CELLS", "MIN_BATCH", "N_ALIGN_SAMPLES"]

N_ALIGN_SAMPLES = 8         # times at which neighbouring networks are compared (as ensemble.alignment_offsets)
_EDGE = 1e-9                # seconds: a time this close to a window belongs to it (as ensemble.blend_weights)
OFFSET_FROM = ("span", "first_window")


@dataclass
class StreamPart:
    """Finished frames: times float64 [Q_k] (s), ``indices`` int64 [Q_k] their positions in the query
    times, log_intensity and frames float32 [Q_k, H, W] (anchored log intensity; tone-mapped in
    [0, 1]), ``window`` (index, t_lo, t_hi) of the window that finished them (None for the final
    pass of ``offset_from="span"``) and ``history`` (training so far: train_time_s, n_windows, per window;
    C_used: [C] or [C+, C-], the thresholds the events were integrated with, after the ON/OFF balance;
    lam_used: the regularizer's weight trained with, ``lam="auto"`` resolved; background_used and
    background_dt_used: the background filter applied, ``background="auto"`` resolved to "filter" with its
    window in seconds, or "keep"; temporal_scale_used: the bins' and the temporal prior's scale,
    ``temporal_scale="auto"`` resolved, :mod:`~evinr_lite.method.tempo`)."""

    times: np.ndarray
    indices: np.ndarray
    log_intensity: np.ndarray
    frames: np.ndarray
    window: tuple | None
    history: dict = field(repr=False)


_ARRAYS = ("align", "offset", "samples", "q_pending", "q_sum", "g_pending", "g_sum", "grid", "windows")


@dataclass
class StreamState:
    """What window k hands to window k + 1: images, never a network (so a run can resume).

    Attributes:
        next_window: index of the next window to train. windows: float64 [N, 2] the plan.
        align: float32 [H, W] the last network's alignment offset (the chain of overlap means).
        offset: float32 [H, W] offset image + level (``offset_from="first_window"``: set by window 0;
            "span": None until every window is done).
        samples: float32 [S, H, W] the last network at the alignment times shared with the next one.
        q_pending, g_pending: int64 query / grid indices waiting for the next network, with their
            blends so far q_sum, g_sum float32 [M, H, W].
        grid: float32 [G_done, H, W] the finished frames of the offset grid (mode "span").
        n_spilled: query frames written to the spill file (mode "span"). train_time_s: seconds so far.
        windows_log: per-window records (events, bins, seconds).
    """

    next_window: int
    windows: np.ndarray
    align: np.ndarray
    offset: np.ndarray | None = None
    samples: np.ndarray | None = None
    q_pending: np.ndarray | None = None
    q_sum: np.ndarray | None = None
    g_pending: np.ndarray | None = None
    g_sum: np.ndarray | None = None
    grid: np.ndarray | None = None
    n_spilled: int = 0
    train_time_s: float = 0.0
    windows_log: list = field(default_factory=list)

    @classmethod
    def start(cls, windows: np.ndarray, sensor_size) -> "StreamState":
        H, W = sensor_size
        none, empty = np.zeros(0, np.int64), np.zeros((0, H, W), np.float32)
        return cls(0, windows, np.zeros((H, W), np.float32), q_pending=none, q_sum=empty, g_pending=none,
                   g_sum=empty.copy(), grid=empty.copy())

    def save(self, path) -> None:
        """Write to ``path`` (.npz), beside and then renamed into place (never half-written)."""
        import json

        path = Path(path)
        tmp = path.with_name(f".{path.name}.partial")
        arrays = {k: np.asarray(getattr(self, k)) for k in _ARRAYS if getattr(self, k) is not None}
        scalars = {"next_window": self.next_window, "n_spilled": self.n_spilled, "train_time_s": self.train_time_s,
                   "windows_log": self.windows_log}
        with open(tmp, "wb") as f:
            np.savez(f, scalars=np.array(json.dumps(scalars)), **arrays)
        tmp.replace(path)

    @classmethod
    def load(cls, path) -> "StreamState":
        import json

        with np.load(path) as z:
            arrays = {k: z[k] for k in z.files}
        scalars = json.loads(str(arrays.pop("scalars")))
        return cls(**{k: arrays.get(k) for k in _ARRAYS}, **scalars)


def _spill_path(workdir) -> Path:
    return Path(workdir) / "log_intensity.f32"



def alignment_times(windows: np.ndarray, k: int) -> np.ndarray:
    """float64 [S] times (s) at which networks k - 1 and k are compared: their overlap."""
    return np.linspace(windows[k, 0], windows[k - 1, 1], N_ALIGN_SAMPLES)


def network_at(model: FrameINR, times: np.ndarray) -> np.ndarray:
    """A one-network model's output (no offset) at ``times`` [Q] (s): float32 [Q, H, W], predicted
    a bounded number of frames at a time (PREDICT_CELLS), whatever the sensor."""
    H, W = model.sensor_size
    return predict_networks(model, np.asarray(times, np.float64), _batch(H * W))[0]


def _batch(pixels: int) -> int:
    """Frames per prediction batch for a sensor of ``pixels``."""
    return max(MIN_BATCH, PREDICT_CELLS // max(pixels, 1))


def tonemap(L: np.ndarray, config: EvINRConfig) -> np.ndarray:
    """:func:`~evinr_lite.method.tonemap.to_display` of L [Q, H, W] by the config's tone map, as float32,
    a few frames at a time (the same values; its float64 work arrays stay small)."""
    out = np.empty(L.shape, np.float32)
    step = max(1, TONEMAP_CELLS // max(int(np.prod(L.shape[1:])), 1))
    for i in range(0, len(L), step):
        out[i:i + step] = to_display(L[i:i + step], config.tonemap, config.gamma)
    return out


def train_window(events: Events, windows: np.ndarray, k: int, config: EvINRConfig):
    """Train network k of the plan ``windows`` [N, 2] on ``events`` (at least those of its window):
    (model, history), the model a one-network FrameINR initialised as network k of the ensemble."""
    device = default_device(config.device)
    solve_only = config.head_solve and config.n_iters == 0   # the head is solved, never trained: no draws
    model = FrameINR(events.sensor_size, windows[k:k + 1], config.hidden_features, config.hidden_layers,
                     config.omega_0, config.first_layer_omega(windows), seed=config.seed, first_index=k,
                     init_head=not solve_only).to(device)
    model, history = train_frame_inr(events, windows[k:k + 1], config, model=model)
    model.eval()
    return model, history


def chain_offset(previous_align: np.ndarray, previous_samples: np.ndarray, model: FrameINR,
                 times: np.ndarray) -> np.ndarray:
    """Network k's alignment offset [H, W]: its predecessor's plus the mean over their overlap of
    (predecessor - network k) at ``times`` (as :func:`~evinr_lite.method.ensemble.alignment_offsets`)."""
    return previous_align + (previous_samples - network_at(model, times)).mean(axis=0)


def first_window_offset(model: FrameINR, window, config: EvINRConfig, events=None) -> np.ndarray:
    """The offset image + level [H, W] float32 that every network gets, from the first window.

    Same grid, same steps and same float32 order as the whole-sequence solve over one window
    (:func:`offset_grid`, the offset image, the static image's coarse part from ``events``, the
    window's prepared events, when :func:`~evinr_lite.method.coarse.coarse_applies`, the level
    anchor), so a one-window span gives the identical result."""
    lo, hi = float(window[0]), float(window[1])
    grid = offset_grid(lo, hi, 1, config.offset_solve)
    F = network_at(model, grid)
    H, W = model.sensor_size
    offset = np.zeros((H, W), np.float32)
    if config.offset_solve != "none":
        offset += offset_image(F, config.offset_solve, config.offset_rest()).astype(np.float32)
    F += offset
    if coarse_applies(config, lo, hi):
        if events is None:
            raise ValueError("first_window_offset needs the window's events for the static image's coarse part")
        coarse = coarse_correction([events], config.C, grid, F, config.offset_coarse_px, config.offset_solve,
                                   config.offset_rest())
        offset += coarse
        F += coarse
    offset += np.float32(display_shift(F, config.tonemap, config.gamma, config.display_mean))
    return offset


def _check(source, query_times, config, t_start, t_end, offset_from):
    cfg = EvINRConfig() if config is None else require(config, EvINRConfig, "config")   # {} ran the default
    if cfg.anchor != "none":
        raise EventDataError(f"streaming does not take anchored configs (anchor={cfg.anchor!r}): the APS frames fit "
                             "the offset over the whole span; use reconstruct(...) for them")
    offset_from = choice(offset_from, OFFSET_FROM, "offset_from")   # an array was numpy's "truth value ... is ambiguous"
    q = seconds_array(query_times, "query_times")     # True, text, ragged or complex times were numpy's errors
    if np.any(np.diff(q) < 0):
        raise EventDataError("query_times must be sorted (increasing seconds) for streaming; pass np.sort(times)")
    first, last = source.t_span
    t_start, t_end = optional_seconds(t_start, "t_start"), optional_seconds(t_end, "t_end")
    t_start = min(first, q.min()) if t_start is None else t_start
    t_end = max(last, q.max()) if t_end is None else t_end
    # times in ms or us, or on the absolute clock: a span no recording has, counted for hours before any window
    check_reach(min(t_start, q.min()), max(t_end, q.max()), np.array(source.t_span if source.n_events != 0 else []),
                source.t_origin, "query_times and t_start / t_end")
    if q.min() < t_start or q.max() > t_end:
        raise EventDataError(f"query times span [{q.min()}, {q.max()}] s, outside [t_start, t_end] = "
                             f"[{t_start}, {t_end}] s; widen the span or drop those times")
    return cfg, q, t_start, t_end


def _check_hooks(progress, on_state, state, workdir) -> None:
    """The run's switches and hooks, before any pass over the recording (a bad on_state failed after the first
    window had trained; progress="no" showed the bar)."""
    if progress is not None and not isinstance(progress, (bool, np.bool_)):
        raise EventDataError(f"progress= must be True, False or None (the config's), got {progress!r}")
    if on_state is not None and not callable(on_state):
        raise EventDataError(f"on_state= must be a function on_state(state) called after each window (or None), got "
                             f"{type(on_state).__name__}")
    require(state, StreamState, "state", none_ok=True)
    if workdir is not None and not isinstance(workdir, (str, Path)):
        import os

        if not isinstance(workdir, os.PathLike):
            raise EventDataError(f"workdir= must be a folder (a str or Path) for the spill file, or None for a "
                                 f"temporary one; got {type(workdir).__name__}")


def _check_two_events(source, t_start: float, t_end: float) -> None:
    """Refuse, before any pass over the recording, a span [t_start, t_end] holding fewer than 2 events, as
    :func:`~evinr_lite.method.solver.reconstruct` does (a window between two events trained networks on nothing:
    a frame of the networks' initial noise, or lam='auto' never resolved). Read in chunks that double from 1 ms,
    stopping at the second event: a few reads, whatever the span."""
    first, last = source.t_span
    if source.n_events is not None and t_start <= first and t_end >= last:   # the whole recording: no read needed
        found = source.n_events
    else:
        found = _count_up_to_two(source, t_start, t_end)
    if found < 2:
        raise EventDataError(f"fewer than 2 events in [{t_start}, {t_end}] s; choose a window with events (the "
                             f"recording's events cover [{first:.6f}, {last:.6f}] s)")


def _count_up_to_two(source, t_start: float, t_end: float) -> int:
    """The events in [t_start, t_end] (end included), counted until there are 2."""
    found, a, step = 0, float(t_start), 1e-3
    while a <= t_end and found < 2:
        b = min(a + step, float(t_end))
        found += len(source.events(a, np.nextafter(b, np.inf) if b >= t_end else b))
        if b >= t_end:
            break
        a, step = b, step * 2
    return found


def _resolved(cfg, used) -> dict:
    """What the events chose, for a part's history: the thresholds, lam, the background filter and the
    temporal scale."""
    return {"C_used": used, "lam_used": float(cfg.lam), "background_used": cfg.background,
            "background_dt_used": float(cfg.background_dt), "temporal_scale_used": cfg.scale()}


def stream_reconstruct(source, query_times, config: EvINRConfig | None = None, *, t_start: float | None = None,
                       t_end: float | None = None, offset_from: str = "span", workdir=None,
                       state: StreamState | None = None, on_state=None, progress: bool | None = None):
    """Reconstruct window after window; yield the finished frames (:class:`StreamPart`) in time order.

    Args:
        source: a :class:`~evinr_lite.io.source.RecordingSource` (``open_recording(path)``), or a
            Recording / Events in memory (wrapped with ``as_source``).
        query_times: float64 [Q] sorted seconds inside [t_start, t_end].
        config: EvINRConfig (the kit's default when None); anchored configs are refused.
        t_start, t_end: the span (default: the source's events, widened to the query times).
        offset_from: where the offset image and the level come from. "span" (default): from the
            whole-sequence solve's grid over the whole span, so the result is that of
            :func:`~evinr_lite.method.solver.reconstruct` up to float rounding; each window's log
            intensities are written to a spill file in ``workdir`` as it finishes, and the frames
            are handed out in one final pass (about 4 bytes x H x W per query time on disk).
            "first_window": from the grid over the first window; each window's frames are final
            (and handed out) as soon as it finishes; identical when the span is one window. It
            keeps one offset image for the whole recording: the slow trend of
            ``config.offset_window`` (:func:`~evinr_lite.method.offset.offset_trend`)
            needs the whole span, so only mode "span" applies it.
        workdir: folder for the spill file (mode "span"; default: a temporary folder, removed at the
            end). To resume, pass the same folder and the saved ``state``.
        state: a :class:`StreamState` saved by ``on_state`` to resume from (its plan must match).
        on_state: called as on_state(state) after each window, once what it finished is handed out
            or spilled (the place to save the state for a resume).
        progress: a tqdm bar counting windows with an ETA (default: ``config.progress``).

    Memory: one network, its window's events and bins, a bounded batch of predictions, the frames
    of one overlap, and the offset grid (64 frames, 8 per window beyond 8 windows), whatever the
    recording's length.
    """
    import tempfile

    from ..io.source import as_source

    source = as_source(source)
    cfg, q, t_start, t_end = _check(source, query_times, config, t_start, t_end, offset_from)
    _check_hooks(progress, on_state, state, workdir)
    _check_two_events(source, t_start, t_end)
    show = cfg.progress if progress is None else bool(progress)
    # hot pixels, background, ON/OFF balance, lam (method/prepare.py)
    cfg, source = prepare_source(source, t_start, t_end, cfg, progress=show)
    if cfg.scale() > 1:   # the events asked for shorter bins (method/tempo.py): a window's bins grow; check again
        check_memory(tuple(source.sensor_size), t_start, t_end, source.n_events or 0, len(q), cfg,
                     str(default_device(cfg.device)), streaming=True)
    windows = split_windows(t_start, t_end, cfg.tau, cfg.overlap)
    if state is None:
        state = StreamState.start(windows, source.sensor_size)
    elif state.windows.shape != windows.shape or not np.allclose(state.windows, windows, rtol=0, atol=1e-9):
        raise EventDataError("the saved streaming state belongs to another plan of windows (another span, tau or "
                             "overlap); start again without it")
    grid = offset_grid(t_start, t_end, len(windows), cfg.offset_solve) if offset_from == "span" else np.zeros(0)
    used = [float(c) for c in np.atleast_1d(cfg.C)]           # the thresholds the events are integrated with
    if offset_from == "first_window":
        for part, _ in _windows(source, q, grid, cfg, state, None, on_state, show):
            part.history.update(_resolved(cfg, used))
            yield part
        return
    with tempfile.TemporaryDirectory(prefix="evinr-stream-") if workdir is None else _nothing(workdir) as folder:
        spill = _spill_path(folder)
        for _, state in _windows(source, q, grid, cfg, state, spill, on_state, show):
            pass
        offset = span_offset(state.grid, cfg, grid, read_chunks(source, t_start, t_end, cfg.tau or t_end - t_start),
                             progress=show)
        yield from _final_pass(spill, q, offset, cfg, source.sensor_size, {**_history(state), **_resolved(cfg, used)},
                               progress=show)


class _nothing:
    """A context manager that hands out a folder it does not own."""

    def __init__(self, folder):
        self.folder = Path(folder)

    def __enter__(self):
        self.folder.mkdir(parents=True, exist_ok=True)
        return self.folder

    def __exit__(self, *exc):
        return False


def span_offset(grid_frames: np.ndarray, config: EvINRConfig, grid_times, chunks=None,
                progress: bool = False) -> OffsetTrend:
    """The offset + level from the aligned log intensities on the whole span's grid [G, H, W] at
    ``grid_times`` [G] (s), by the steps and float32 order of the whole-sequence solve: an
    :class:`~evinr_lite.method.offset.OffsetTrend` whose images include the level (one knot, one
    image, unless ``config.offset_window`` makes the offset a trend over a long span). ``chunks``:
    the span's prepared events in time-ordered chunks (an iterable of Events), read for the static
    image's coarse part when :func:`~evinr_lite.method.coarse.coarse_applies` to the span. ``progress``:
    a bar counting the solves (each offset image, then the coarse part)."""
    from tqdm.auto import tqdm

    H, W = grid_frames.shape[1:]
    offset = np.zeros((H, W), np.float32)
    trend = None
    coarse_too = coarse_applies(config, float(grid_times[0]), float(grid_times[-1]))
    n_solves = ((trend_knots(float(grid_times[-1] - grid_times[0]), config.offset_window)
                 if config.offset_solve != "none" else 0) + int(coarse_too))
    with tqdm(total=n_solves, desc="EvINR offset", unit="solve", disable=not (progress and n_solves)) as bar:
        if config.offset_solve != "none":
            trend = offset_trend(grid_times, grid_frames, config.offset_window, config.offset_solve,
                                 on_image=lambda: bar.update(1), rest=config.offset_rest())
            if len(trend.knots) == 1:
                offset += trend.images[0]
                trend = None
        shifted = grid_frames + offset
        if trend is not None:
            trend.add_to(shifted, grid_times)
        if coarse_too:
            if chunks is None:
                raise ValueError("span_offset needs the span's events for the static image's coarse part")
            coarse = coarse_correction(chunks, config.C, grid_times, shifted, config.offset_coarse_px,
                                       config.offset_solve, config.offset_rest())
            offset += coarse
            shifted += coarse
            bar.update(1)
    offset += np.float32(display_shift(shifted, config.tonemap, config.gamma, config.display_mean))
    if trend is None:
        return OffsetTrend(np.zeros(1), offset[None])
    return OffsetTrend(trend.knots, trend.images + offset)


def _history(state: StreamState) -> dict:
    return {"train_time_s": state.train_time_s, "n_windows": len(state.windows), "windows": list(state.windows_log)}


def _windows(source, q, grid, cfg, state, spill, on_state, progress):
    """Train, align and blend window after window from ``state``; yield (StreamPart, state) in mode
    "first_window" (spill None), else append the finished log intensities to ``spill`` and yield
    (None, state) (once at least, so the caller always gets the last state)."""
    from tqdm.auto import tqdm

    windows = state.windows
    N = len(windows)
    quiet = dataclasses.replace(cfg, progress=False)   # one bar for the windows, none per window
    if spill is not None:   # resume: drop frames spilled after the state was saved
        P = int(np.prod(source.sensor_size))
        with open(spill, "ab") as f:
            f.truncate(state.n_spilled * P * 4)
    bar = tqdm(total=N, initial=state.next_window, desc="EvINR windows", unit="window", disable=not progress)
    if state.next_window >= N:
        yield None, state
    try:
        for k in range(state.next_window, N):
            lo, hi = windows[k]
            events = source.events(lo, np.nextafter(hi, np.inf))   # the last window's end is inclusive
            t0 = time.perf_counter()
            model, history = train_window(events, windows, k, quiet)
            n_events = len(events)
            align = state.align if k == 0 else chain_offset(state.align, state.samples, model,
                                                            alignment_times(windows, k)).astype(np.float32)
            if spill is None:
                offset = first_window_offset(model, windows[0], cfg, events) if k == 0 else state.offset
                total = offset.copy() if k == 0 else align + offset      # k = 0: align is zero
            else:
                offset, total = None, align
            del events                                 # the first window's offset solve was its last use
            q_idx, q_L, q_pending, q_sum = _blend_window(model, windows, k, q, total, state.q_pending, state.q_sum)
            g_idx, g_L, g_pending, g_sum = _blend_window(model, windows, k, grid, total, state.g_pending, state.g_sum)
            samples = network_at(model, alignment_times(windows, k + 1)) if k + 1 < N else None
            del model
            log = {"window": k, "t_s": [float(lo), float(hi)], "n_events": n_events,
                   "final_bins": history.get("final_bins"), "train_time_s": history["train_time_s"],
                   "seconds": time.perf_counter() - t0}
            new = StreamState(k + 1, windows, align, offset, samples, q_pending, q_sum, g_pending, g_sum,
                              np.concatenate([state.grid, g_L]) if g_L.size else state.grid,
                              state.n_spilled, state.train_time_s + history["train_time_s"],
                              state.windows_log + [log])
            part = None
            if spill is None:
                part = StreamPart(q[q_idx], q_idx, q_L, tonemap(q_L, cfg),
                                  (k, float(lo), float(hi)), _history(new))
            else:
                with open(spill, "ab") as f:
                    np.ascontiguousarray(q_L, np.float32).tofile(f)
                new.n_spilled += len(q_idx)
            state = new
            bar.update(1)
            yield part, state                          # handed out (or spilled) before the state is saved
            if on_state is not None:
                on_state(state)
    finally:
        bar.close()


def _final_pass(spill, q, offset: OffsetTrend, cfg, sensor_size, history, progress: bool = False):
    """The spilled log intensities plus the offset (trend), tone-mapped, a bounded batch at a time;
    ``progress``: a bar counting the frames handed out (and written by the caller)."""
    from tqdm.auto import tqdm

    H, W = sensor_size
    P = H * W
    step = _batch(P)
    with open(spill, "rb") as f, tqdm(total=len(q), desc="EvINR frames", unit="frame", disable=not progress) as bar:
        for i0 in range(0, len(q), step):
            n = min(step, len(q) - i0)
            L = np.fromfile(f, np.float32, n * P).reshape(n, H, W)
            if L.shape[0] != n:
                raise EventDataError(f"the spill file {spill} is short ({i0 + L.shape[0]} of {len(q)} frames); "
                                     "it was changed while the run was stopped: start again without resuming")
            idx = np.arange(i0, i0 + n, dtype=np.int64)
            offset.add_to(L, q[idx])
            yield StreamPart(q[idx], idx, L, tonemap(L, cfg), None, history)
            bar.update(n)


def _blend_window(model, windows, k, times, total_offset, pending, pending_sum):
    """Network k's share of the cross-fade at the ``times`` inside its window.

    Returns (finished indices, their log intensities, indices waiting for network k + 1, their
    partial sums). ``pending`` / ``pending_sum``: the times network k - 1 left waiting."""
    H, W = model.sensor_size
    lo, hi = windows[k]
    a, b = np.searchsorted(times, lo - _EDGE, "left"), np.searchsorted(times, hi + _EDGE, "right")
    idx = np.arange(a, b, dtype=np.int64)
    if idx.size == 0:
        none = np.zeros(0, np.int64)
        return none, np.zeros((0, H, W), np.float32), none, np.zeros((0, H, W), np.float32)
    w = blend_weights(windows, times[idx])             # [N, Q_k]: the whole plan's weights
    L = network_at(model, times[idx])
    L += total_offset
    if len(windows) > 1:                               # the cross-fade; one window: weight 1 everywhere
        L *= w[k].astype(np.float32)[:, None, None]
        if pending.size:                               # the predecessor's share of the shared times
            L[np.searchsorted(idx, pending)] += pending_sum
    waiting = w[k + 1] > 0 if k + 1 < len(windows) else np.zeros(idx.size, bool)
    return idx[~waiting], L[~waiting], idx[waiting], L[waiting]

