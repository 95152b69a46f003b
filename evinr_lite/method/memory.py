"""How much memory a reconstruction needs, estimated before anything is allocated, and the check against what is free.

    est = estimate_memory((H, W), t_start, t_end, n_events, n_frames, config)   # bytes, by part
    check_memory((H, W), t_start, t_end, n_events, n_frames, config, "cpu")      # EventDataError if it cannot fit

Sizes are (H, W) pixels, times seconds, memory bytes.
"""
from __future__ import annotations

import math
import os

from ..core.events import EventDataError
from .config import EvINRConfig
from .ensemble import split_windows

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


def estimate_memory(sensor_size, t_start: float, t_end: float, n_events: int, n_frames: int,
                    config: EvINRConfig) -> dict:
    """Bytes a reconstruction of [t_start, t_end] (seconds) will need, by part, before anything is allocated.

    What it counts: ``networks`` (each window's SIREN with its H*W head: weights, gradients and
    Adam's two moments, float32; one network per window of :func:`~evinr_lite.method.ensemble.split_windows`),
    ``bins`` (the event frames and the loss terms over them: 3 float32 [B, H, W]), ``frames`` (the
    ``n_frames`` queried log intensities and tone-mapped frames). Not counted: the events themselves,
    the Python process and torch's own workspace. An estimate (within a factor of about 2).

    Returns:
        {"total": bytes, "parts": {"networks", "bins", "frames"}, "n_windows", "n_bins", "n_frames", "span_s"}.
    """
    span = max(float(t_end) - float(t_start), 0.0)
    H, W = sensor_size
    pixels = float(H) * float(W)
    if config.tau is not None and span > MAX_WINDOWS * (config.tau - config.overlap):
        n_windows = MAX_WINDOWS   # far beyond any memory: not worth allocating the windows to count them
    else:
        n_windows = len(split_windows(0.0, span, config.tau, config.overlap)) if span > 0 else 1
    hidden = config.hidden_features
    params = 2 * hidden + config.hidden_layers * (hidden * hidden + hidden) + (hidden + 1) * pixels
    if config.binning == "fixed":
        n_bins = math.ceil(span / config.bin_duration)
    else:
        n_bins = math.ceil(n_events / config.events_per_bin)
    n_bins = max(n_bins, 1)
    n_frames = int(n_frames)
    parts = {"networks": 16.0 * params * n_windows, "bins": 3 * 4.0 * n_bins * pixels,
             "frames": 2 * 16.0 * n_frames * pixels}
    return {"total": sum(parts.values()), "parts": parts, "n_windows": n_windows, "n_bins": n_bins,
            "n_frames": n_frames, "span_s": span}


def _gib(n_bytes: float) -> str:
    return f"{n_bytes / 2**30:,.1f} GiB"


def check_memory(sensor_size, t_start: float, t_end: float, n_events: int, n_frames: int, config: EvINRConfig,
                 device: str = "cpu", *, fraction: float = 0.8, events_span=None) -> dict:
    """Refuse (EventDataError) a reconstruction whose :func:`estimate_memory` exceeds ``fraction`` of
    the free memory (:func:`available_bytes`), naming the estimate and the parameter to change.

    ``events_span``: (first, last) event time in seconds, named in the advice (default: the window).
    Returns the estimate.
    """
    est = estimate_memory(sensor_size, t_start, t_end, n_events, n_frames, config)
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
                 f"{config.bin_duration:g} s); shorten the window with t_start=/t_end= (the events cover "
                 f"[{ev_lo:.6f}, {ev_hi:.6f}] s) or use a longer bin_duration"),
        "frames": (f"{est['n_frames']:,} output frames of {H}x{W} pixels; ask for fewer frames with fps= or at=, "
                   "or shorten the window with t_start=/t_end="),
    }[worst]
    raise EventDataError(f"this reconstruction needs about {_gib(est['total'])} of memory but about {_gib(free)} is "
                         f"free on {device}: most of it for {fix}")


def check_times_memory(n_times: int, sensor_size, what: str, *, fraction: float = 0.8) -> None:
    """Refuse (EventDataError) ``n_times`` query times before they are allocated, when the times alone
    would not fit in ``fraction`` of the free memory (:func:`check_memory` then counts the frames).
    ``what`` says where the times come from (e.g. "1,000 frames at 30 per second over [0, 1] s")."""
    need, free = n_times * BYTES_PER_TIME, available_bytes("cpu")
    if need > fraction * free:
        H, W = sensor_size
        raise EventDataError(f"{what}: this reconstruction needs about {_gib(need)} of memory but about {_gib(free)} "
                             f"is free: most of it for {n_times:,} output frames of {H}x{W} pixels; ask for fewer "
                             "frames with fps= or at=, or shorten the window with t_start=/t_end=")
