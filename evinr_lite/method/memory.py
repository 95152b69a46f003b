"""How much memory a reconstruction needs, estimated before anything is allocated, and the check against what is free.

    est = estimate_memory((H, W), t_start, t_end, n_events, n_frames, config)   # bytes, by part
    check_memory((H, W), t_start, t_end, n_events, n_frames, config, "cpu")      # EventDataError if it cannot fit

Sizes are (H, W) pixels, times seconds, memory bytes.
"""
from __future__ import annotations

import math
import os

import numpy as np

from ..core.checks import checked_span, real_number, require, whole_number
from ..core.events import EventDataError, check_sensor_size
from .config import EvINRConfig
from .ensemble import split_windows
from .coarse import coarse_applies, coarse_times
from .offset import MIN_TREND_FRAMES, offset_grid, trend_intervals
from .stream_sizes import MIN_BATCH, PREDICT_CELLS, TONEMAP_CELLS

__all__ = ["estimate_memory", "check_memory", "check_times_memory", "available_bytes"]

MAX_WINDOWS = 10**6        # a span needing more windows is refused without listing them
BYTES_PER_TIME = 40.0   # one query time while the times are made, sorted and checked (float64 copies)


def available_bytes(device: str = "cpu") -> int:
    """Memory free for the run: the GPU's free memory on cuda, else the system's available memory."""
    if str(device).startswith("cuda"):
        import torch

        return int(torch.cuda.mem_get_info()[0])
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return 1 << 62


PROCESS_BYTES = 370e6   # the evinr-lite process with its libraries loaded (peak RSS 0.35 GiB on a 32x24 recording)
EVENT_BYTES = 17.0      # one event in memory: t float64, x, y int32, p int8
READ_BYTES = 2 * EVENT_BYTES   # while a window is read and converted (the file's columns, then Events)


def _offset_solve_frames(span: float, G: int, config: EvINRConfig) -> int:
    """Of the G grid frames, those that one offset solve looks at (method/offset.py: offset_trend): the
    whole grid for one image, else the frames within ``offset_window`` of a knot (at least 8)."""
    window = config.offset_window
    if span <= 0 or trend_intervals(span, window) == 1:
        return G
    return int(min(G, max(MIN_TREND_FRAMES, math.floor(2 * window / span * (G - 1)) + 1)))


def _n_windows(span: float, config: EvINRConfig) -> int:
    if config.tau is not None and span > MAX_WINDOWS * (config.tau - config.overlap):
        return MAX_WINDOWS   # far beyond any memory: not worth allocating the windows to count them
    return len(split_windows(0.0, span, config.tau, config.overlap)) if span > 0 else 1


def _final_bins(window_s: float, n_window_events: float, config: EvINRConfig) -> int:
    """Final bins of one network window (as training.initial boundaries and the bisections give them)."""
    if config.binning == "fixed":
        n = max(2 ** config.n_bisections, config.min_bins, int(round(window_s / config.final_bin_duration())))
    else:
        n = math.ceil(n_window_events / config.events_per_bin)
    return max(int(n), 1)


def estimate_memory(sensor_size, t_start: float, t_end: float, n_events: int, n_frames: int,
                    config: EvINRConfig, *, streaming: bool = False, n_kept: int = 0) -> dict:
    """Peak bytes a reconstruction of [t_start, t_end] (seconds) will need, by part, before anything is allocated.

    What it counts (float32 unless said; P = H * W pixels, d = hidden_features, B final bins per
    window, N windows, Q = ``n_frames`` query times):

    - ``process``: the interpreter and the libraries (PROCESS_BYTES);
    - ``events``: the events held (all of them; streaming: one window's, while it is read);
    - ``networks``: the H*W heads (d + 1) P, times 4 with Adam (weights, gradients, two moments),
      N of them (streaming: one);
    - ``bins``: the event frames B x P of every window, twice while they are stacked (streaming: one window),
      plus the fused training step's three B x P work arrays when n_iters > 0;
    - ``frames``: whole solve: every network at every query time [N, Q, P], its offset copy, the
      float64 blend and the float64 tone map [Q, P]; streaming: one prediction batch
      (stream_sizes.PREDICT_CELLS frames x pixels, at least MIN_BATCH frames) with its tone-mapped and
      uint8 copies and the tone map's float64 work arrays (TONEMAP_CELLS); the events and bins are
      freed before it, so the larger of the two phases counts; beside them, all run long: the offset
      grid (max(64, 8 N) frames), the overlap's partial blends and ``n_kept`` frames kept in memory
      (those at ground-truth times), counted with ``process``;
    - ``offset``: with ``offset_solve="l1_gradient"``, how far its phase (the ADMM's work arrays over the
      grid frames of its largest single solve, ``offset_solve_bytes``, or on spans up to 3 s the
      static image's coarse part if larger: the events summed on half the grid's times and their own
      solve, :mod:`evinr_lite.method.coarse`; beside what is alive then) exceeds the parts above; 0 otherwise.

    Measured against peak RSS in ``benchmarks/scale.py`` (the target: within 25 %).

    Returns:
        {"total": bytes, "parts": {...}, "n_windows", "n_bins" (per window), "n_frames", "span_s", "streaming",
        "offset_solve_bytes" (the L1 offset solve's work arrays alone), "coarse_bytes" (the static image's
        coarse part's, alone; 0 where it does not run)}.
    """
    H, W = check_sensor_size(sensor_size)                   # before any size is multiplied (None, 10.5 or 0 rows)
    t_start, t_end = checked_span(t_start, t_end, "estimate_memory")   # NaN, inf, text or reversed: no estimate
    n_events = whole_number(n_events, "n_events", lo=0)
    n_frames = whole_number(n_frames, "n_frames", lo=0)
    n_kept = whole_number(n_kept, "n_kept", lo=0)
    config = require(config, EvINRConfig, "config")
    span = max(t_end - t_start, 0.0)
    P = float(H) * float(W)
    N = _n_windows(span, config)
    window_s = span if N == 1 else (span + (N - 1) * config.overlap) / N
    per_window_events = float(n_events) * (window_s / span if span > 0 else 1.0)
    B = _final_bins(window_s, per_window_events, config)
    d = config.hidden_features
    head = 4.0 * (d + 1) * P * (4 if config.n_iters > 0 else 1)
    trunk = 4.0 * (2 * d + config.hidden_layers * (d * d + d)) * (4 if config.n_iters > 0 else 1)
    bins = 4.0 * B * P * (2 + (3 if config.n_iters > 0 else 0))
    Q = float(n_frames)
    if streaming:
        batch = min(Q, max(MIN_BATCH, PREDICT_CELLS // P)) * P
        grid = float(max(64, 8 * N)) * P
        overlap_frames = Q * min(1.0, config.overlap / span) if span > 0 and N > 1 else 0.0
        # what lives through the run, then the larger of the two phases of a window: training (its
        # events, the network, the bins) or prediction (the network, a batch with its tone-mapped and
        # uint8 copies, the tone map's float64 work arrays); the events and bins are freed in between
        persistent = PROCESS_BYTES + grid * 4 + overlap_frames * P * 8 + float(n_kept) * P * 4
        train = READ_BYTES * per_window_events + head + trunk + bins
        predict = head + trunk + batch * 12 + TONEMAP_CELLS * 24
        if train >= predict:
            parts = {"process": persistent, "events": READ_BYTES * per_window_events, "networks": head + trunk,
                     "bins": bins, "frames": 0.0}
        else:
            parts = {"process": persistent, "events": 0.0, "networks": head + trunk, "bins": 0.0,
                     "frames": batch * 12 + TONEMAP_CELLS * 24}
    else:
        parts = {"process": PROCESS_BYTES, "events": EVENT_BYTES * float(n_events),
                 "networks": (head + trunk) * N, "bins": bins * N,
                 "frames": Q * P * (2 * 4 * N + 8 + 16 + 4 + 4)}
    # offset_solve "l1_gradient": its ADMM holds each edge's values over the frames of one solve (float32,
    # x and y edges) and a few per-edge vectors (method/offset.py; measured with tracemalloc: 12.1 bytes
    # per frame and pixel at 64 x 360 x 640), plus the copy of those frames that a trend's knot takes: 17
    # bytes per frame and pixel of the largest single solve. It runs in a phase of its own, after training
    # (streaming: after the last window, beside what lives through the run; whole solve: beside the events,
    # the networks and the offset grid), so it counts only as far as that phase exceeds the others.
    G = len(offset_grid(0.0, max(span, 1e-9), N, config.offset_solve))
    offset_work = 17.0 * _offset_solve_frames(span, G, config) * P if config.offset_solve == "l1_gradient" else 0.0
    # the static image's coarse part (method/coarse.py, spans up to 3 s) runs after that solve, in two steps:
    # the events summed on its Gc (about coarse.FRAMES) times, exactly (int32 ON and OFF sums, then float32
    # frames; streaming reads the span again a window's length at a time), then the L1 solve over those Gc
    # frames beside them. Gc is half the grid, so it raises the phase only where the grid's solve is small.
    coarse = 0.0
    if coarse_applies(config, 0.0, span):
        Gc = float(len(coarse_times(np.arange(G))))
        binning = 12.0 * (Gc + 1) * P + (READ_BYTES * per_window_events if streaming else 0.0)
        solve = 4.0 * (Gc + 1) * P + 17.0 * Gc * P if config.offset_solve == "l1_gradient" else 0.0
        coarse = max(binning, solve)
    work = max(offset_work, coarse)
    if streaming:
        offset_phase = persistent + work
    else:
        offset_phase = parts["process"] + parts["events"] + parts["networks"] + 4.0 * G * P + work
    parts["offset"] = max(0.0, offset_phase - sum(parts.values()))
    return {"total": sum(parts.values()), "parts": parts, "n_windows": N, "n_bins": B, "n_frames": int(n_frames),
            "span_s": span, "streaming": bool(streaming), "offset_solve_bytes": offset_work, "coarse_bytes": coarse}


def gib(n_bytes: float) -> str:
    """``n_bytes`` as text in GiB (one decimal), as the memory messages print it."""
    return f"{n_bytes / 2**30:,.1f} GiB"


def check_memory(sensor_size, t_start: float, t_end: float, n_events: int, n_frames: int, config: EvINRConfig,
                 device: str = "cpu", *, fraction: float = 0.8, events_span=None, streaming: bool = False,
                 n_kept: int = 0) -> dict:
    """Refuse (EventDataError) a reconstruction whose :func:`estimate_memory` exceeds ``fraction`` of
    the free memory (:func:`available_bytes`), naming the estimate and the parameter to change.

    ``events_span``: (first, last) event time in seconds, named in the advice (default: the window).
    Returns the estimate.
    """
    fraction = real_number(fraction, "fraction", lo=0.0, lo_open=True, hi=1.0,
                           hint="the share of the free memory a run may take (0.8)")
    est = estimate_memory(sensor_size, t_start, t_end, n_events, n_frames, config, streaming=streaming,
                          n_kept=n_kept)
    free = available_bytes(device)
    if est["total"] <= fraction * free:
        return est
    H, W = sensor_size
    worst = max(est["parts"], key=est["parts"].get)
    ev_lo, ev_hi = events_span if events_span is not None else (t_start, t_end)
    fix = {
        "networks": (f"{est['n_windows']:,} network(s) with a head of {H}x{W} pixels (windows of tau = {config.tau} s "
                     f"over {est['span_s']:.6g} s); shorten the window with t_start=/t_end= (the events cover "
                     f"[{ev_lo:.6f}, {ev_hi:.6f}] s) or check the sensor size (sensor_size=(H, W))"),
        "bins": (f"{est['n_bins']:,} event bins of {H}x{W} pixels ({est['span_s']:.6g} s in bins of "
                 f"{config.final_bin_duration():g} s); shorten the window with t_start=/t_end= (the events cover "
                 f"[{ev_lo:.6f}, {ev_hi:.6f}] s) or use a longer bin_duration"),
        "frames": (f"{est['n_frames']:,} output frames of {H}x{W} pixels; ask for fewer frames with fps= or at=, "
                   "or shorten the window with t_start=/t_end="),
        "events": (f"the events in memory ({est['span_s']:.6g} s of them); shorten the window with t_start=/t_end= "
                   f"(the events cover [{ev_lo:.6f}, {ev_hi:.6f}] s)"),
        "process": "the libraries alone; free some memory first",
        "offset": (f"the offset solve over {H}x{W} pixels (its grid of frames, and on spans up to 3 s the integrated "
                   "events beside it); check the sensor size (sensor_size=(H, W)), or pass offset_coarse_px=None "
                   "or offset_solve=\"median_gradient\""),
    }[worst]
    if worst == "bins" and config.scale() > 1:   # the events shortened the bins (method/tempo.py)
        fix += (f"; or temporal_scale=1 (the events' fast changes set {config.scale():.3g}, for bins of "
                f"{config.final_bin_duration():g} s instead of {config.bin_duration:g} s)")
    if est.get("streaming") and worst in ("networks", "bins"):   # one window at a time: the window sets it
        fix = (f"one window's network and bins at {H}x{W} pixels ({est['n_bins']:,} bins of {config.final_bin_duration():g} s, "
               f"{config.hidden_features} hidden features); use a longer bin_duration, a shorter tau or fewer "
               "hidden_features, or check the sensor size (sensor_size=(H, W))"
               + (f"; or temporal_scale=1 (the events' fast changes set {config.scale():.3g})" if config.scale() > 1 else ""))
    raise EventDataError(f"this reconstruction needs about {gib(est['total'])} of memory but about {gib(free)} is "
                         f"free on {device}: most of it for {fix}")


def check_times_memory(n_times: int, sensor_size, what: str, *, fraction: float = 0.8) -> None:
    """Refuse (EventDataError) ``n_times`` query times before they are allocated, when the times alone
    would not fit in ``fraction`` of the free memory (:func:`check_memory` then counts the frames).
    ``what`` says where the times come from (e.g. "1,000 frames at 30 per second over [0, 1] s")."""
    n_times = whole_number(n_times, "n_times", lo=0)
    fraction = real_number(fraction, "fraction", lo=0.0, lo_open=True, hi=1.0,
                           hint="the share of the free memory a run may take (0.8)")
    need, free = n_times * BYTES_PER_TIME, available_bytes("cpu")
    if need > fraction * free:
        H, W = sensor_size
        raise EventDataError(f"{what}: this reconstruction needs about {gib(need)} of memory but about {gib(free)} "
                             f"is free: most of it for {n_times:,} output frames of {H}x{W} pixels; ask for fewer "
                             "frames with fps= or at=, or shorten the window with t_start=/t_end=")
