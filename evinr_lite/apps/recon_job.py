"""The reconstruct job: load a recording -> pick a window and times -> EvINR -> score -> export.

The ``evinr-lite reconstruct`` command is :func:`run_reconstruct`; notebook 11 calls the steps
one by one::

    rec = load_recording("my_recording.aedat4", t_start=1.0, t_end=2.5)   # events + frames of a window
    print(format_info(describe_recording(rec)))
    times, source = choose_times(rec, fps=30)          # or at=[...]; default: the GT frame times
    result = reconstruct_recording(rec, times, EvINRConfig(C=1.0))
    scores = score_recording(result, rec.frames)       # None without frames
    export_reconstruction("out", rec, result, scores)  # PNGs, MP4, GIF, metrics.json/.csv, run.json

Times are seconds on the recording's clock: relative to its ``t_origin`` (the whole seconds of the
first event on an absolute clock, else 0), as ``describe_recording`` prints them.
"""
from __future__ import annotations

import math
import os
import time
from pathlib import Path

import numpy as np

from ..core.events import TIME_UNITS, EventDataError
from ..core.frames import Frames
from ..core.recording import Recording
from ..io.readers import detect_format, read_recording
from .describe import (FIXED_UNITS, READER_WINDOW_FORMATS, SENSOR_ARG_FORMATS, SIZE_FREE_FORMATS,  # noqa: F401
                       TIME_UNIT_FORMATS, describe_recording, format_info, read_any)
from ..evaluation.scoring import score_sequence
from ..method.binning import as_thresholds
from ..method.contrast import fit_contrast
from ..method.solver import EvINRConfig, Reconstruction, reconstruct
from ..method.anchor import ANCHOR_MODES, held_out

__all__ = ["read_any", "load_recording", "describe_recording", "format_info", "choose_times", "reconstruct_recording",
           "score_predictions", "score_recording", "export_reconstruction", "run_reconstruct",
           "check_run_options", "contrast_option", "resolve_contrast", "format_contrast", "estimate_memory", "check_memory", "DEFAULT_FPS", "DEFAULT_C", "EQUALIZATIONS", "RECIPES",
           "recipe_config"]

DEFAULT_FPS = 30.0      # frames per second when neither times nor ground-truth frames are given
DEFAULT_C = 1.0         # the paper's contrast threshold for DAVIS recordings (IJRR, HQF)
EQUALIZATIONS = ("none", "clahe")   # scored without equalisation, and with CLAHE (the paper's)


# ---- load ------------------------------------------------------------------------------------

def load_recording(path, *, sensor_size=None, t_start: float | None = None, t_end: float | None = None,
                   time_unit: str | None = None) -> Recording:
    """Read a recording (any supported format) restricted to the window [t_start, t_end).

    Args:
        path, sensor_size, time_unit: see :func:`read_any`.
        t_start, t_end: seconds on the recording's clock; None: from the first / to the last event.
    Returns:
        Recording whose events lie in the window and whose frames lie in [start, end], the span
        to reconstruct, stored as ``meta["window"]`` = (start, end) seconds.
    Raises:
        EventDataError: missing file, unknown format, wrong sensor size, empty window (each
            message says what to do).
    """
    for name, value in (("t_start", t_start), ("t_end", t_end)):
        if value is not None and not math.isfinite(value):
            raise EventDataError(f"{name}= must be a finite number of seconds, got {value}")
    rec = read_any(path, sensor_size=sensor_size, t_start=t_start, t_end=t_end, time_unit=time_unit)
    events, frames = rec.events, rec.frames
    if rec.meta["format"] not in READER_WINDOW_FORMATS:
        events = events.slice_time(t_start, t_end)
    if len(events) < 2:
        raise EventDataError(f"{path}: only {len(events)} event(s) in the window [{t_start}, {t_end}) s; "
                             "choose a longer window (see `evinr-lite info` for the time span)")
    start = float(events.t[0]) if t_start is None else float(t_start)
    end = float(events.t[-1]) if t_end is None else float(t_end)
    if frames is not None:  # only frames the events can reach: inside [start, end]
        keep = (frames.t >= start) & (frames.t <= end)
        frames = Frames(frames.images[keep], frames.t[keep], frames.t_origin) if keep.any() else None
    return Recording(events, frames, {**rec.meta, "window": (start, end)})


# ---- times and reconstruction ----------------------------------------------------------------

def _parse_times(at) -> np.ndarray:
    """Seconds from an array, a list, '0.1,0.2' text, or a file with one time per line."""
    if isinstance(at, (str, Path)) and Path(at).is_file():
        try:
            text = Path(at).read_bytes().decode("utf-8-sig")
        except UnicodeDecodeError as err:
            raise EventDataError(f"{at}: not UTF-8 text (byte {err.start}); save the times as plain text, one number "
                                 "of seconds per line") from None
        at = [tok for line in text.splitlines() if line.strip() and not line.lstrip().startswith("#")
              for tok in line.replace(",", " ").split()[-1:]]
    elif isinstance(at, str):
        at = [tok for tok in at.replace(",", " ").split()]
    try:
        times = np.atleast_1d(np.asarray(at, dtype=np.float64))
    except ValueError:
        raise EventDataError(f"could not read times from at={at!r}; give seconds separated by commas "
                             "(e.g. 0.5,0.75,1.0) or a file with one time per line") from None
    if times.size == 0 or not np.all(np.isfinite(times)):
        raise EventDataError("at=: give at least one finite time in seconds")
    return np.sort(times)


def choose_times(rec: Recording, *, fps: float | None = None, at=None) -> tuple[np.ndarray, str]:
    """The times to reconstruct and where they come from.

    Args:
        fps: frames per second over the window (the first half a frame period after its start).
        at: explicit times (array, '0.1,0.2' text, or a file with one time per line).
        Neither: the ground-truth frame times when the recording has frames, else DEFAULT_FPS.
    Returns:
        (times float64 [Q] seconds, a short description of the choice).
    """
    if fps is not None and at is not None:
        raise EventDataError("give either fps= or at=, not both")
    lo, hi = rec.meta["window"]
    if at is not None:
        times = _parse_times(at)
        outside = times[(times < lo) | (times > hi)]
        if outside.size:
            raise EventDataError(f"requested time {outside[0]} s is outside the reconstructed window "
                                 f"[{lo:.6f}, {hi:.6f}] s; choose times inside it (or widen t_start=/t_end=)")
        return times, f"{len(times)} requested times"
    if fps is None and rec.frames is not None:
        inside = rec.frames.t[(rec.frames.t >= lo) & (rec.frames.t <= hi)]
        if inside.size:
            return inside.copy(), f"the {inside.size} ground-truth frame times"
    fps = DEFAULT_FPS if fps is None else float(fps)
    if not (math.isfinite(fps) and fps > 0):
        raise EventDataError(f"fps= must be a positive number of frames per second, got {fps}")
    n = int(math.floor((hi - lo) * fps))
    H, W = rec.events.sensor_size
    need, free = n * 40.0, _available_bytes("cpu")   # the times alone, before np.arange allocates them (check_memory
    # then counts the frames)
    if need > 0.8 * free:
        raise EventDataError(f"{n:,} frames at {fps:g} per second over [{lo:.6f}, {hi:.6f}] s: this reconstruction "
                             f"needs about {need / 2**30:,.1f} GiB of memory but about {free / 2**30:,.1f} GiB is free: "
                             f"most of it for {n:,} output frames of {H}x{W} pixels; ask for fewer frames with fps= or "
                             "at=, or shorten the window with t_start=/t_end=")
    times = lo + (np.arange(n) + 0.5) / fps if n >= 1 else np.array([0.5 * (lo + hi)])
    return times, f"{len(times)} frames at {fps:g} per second"


def reconstruct_recording(rec: Recording, times, config: EvINRConfig | None = None) -> Reconstruction:
    """EvINR over the recording's window (``meta["window"]``), queried at ``times`` (seconds); an
    anchored config (``anchor`` "first" / "all") takes the recording's APS frames as anchors."""
    lo, hi = rec.meta["window"]
    config = config or EvINRConfig()
    frames = rec.frames if config.anchor != "none" else None
    return reconstruct(rec.events, times, config, t_start=lo, t_end=hi, frames=frames)


# ---- scoring ---------------------------------------------------------------------------------

def _score_one(pred, pred_times, gt: Frames, equalization: str) -> dict:
    """One protocol of :func:`evinr_lite.evaluation.scoring.score_sequence`, as JSON-ready lists."""
    s = score_sequence(pred, pred_times, gt.images, gt.t, equalization=equalization)
    per = s["per_frame"]
    return {"mse": s["mse"], "ssim": s["ssim"], "lpips": s.get("lpips"), "n_frames": s["n_frames"],
            "protocol": s["protocol"], "per_frame_index": np.asarray(per["gt_index"]).tolist(),
            "per_frame_mse": np.asarray(per["mse"]).tolist(), "per_frame_ssim": np.asarray(per["ssim"]).tolist()}


def score_predictions(pred_frames, pred_times, gt: Frames) -> dict:
    """Score frames [Q, H, W] in [0, 1] at ``pred_times`` against ground truth, without equalisation
    and with CLAHE: {"none": {...}, "clahe": {...}}, each with mse, ssim, lpips (None unless its
    weights are present), n_frames, protocol (text) and per-frame lists (per_frame_t_s the GT times)."""
    pred_times = np.asarray(pred_times, np.float64)
    scores = {eq: _score_one(np.asarray(pred_frames), pred_times, gt, eq) for eq in EQUALIZATIONS}
    for s in scores.values():
        s["per_frame_t_s"] = gt.t[s["per_frame_index"]].tolist()
    return scores


def score_recording(result: Reconstruction, gt: Frames | None) -> dict | None:
    """Score the reconstruction at every ground-truth frame time (see :func:`score_predictions`).

    The trained network is queried at the frames' own timestamps, so the scores do not depend on
    which times were exported. Frames used as anchors (``result.anchor_times``) are not scored.
    Returns None when no other frame lies in the reconstructed span.
    """
    if gt is None or not len(gt):
        return None
    lo, hi = result.windows[0, 0], result.windows[-1, 1]
    keep = (gt.t >= lo) & (gt.t <= hi) & held_out(gt.t, getattr(result, "anchor_times", ()))
    if not keep.any():
        return None
    gt = Frames(gt.images[keep], gt.t[keep], gt.t_origin)
    if tuple(gt.size) != tuple(result.frames.shape[1:]):
        raise EventDataError(f"ground-truth frames are {gt.size} but the events' sensor is "
                             f"{tuple(result.frames.shape[1:])} (H, W); they cannot be compared")
    return score_predictions(result.frames_at(gt.t), gt.t, gt)


# ---- export ----------------------------------------------------------------------------------

def _video_fps(times: np.ndarray) -> float:
    """Playback rate: the median spacing of the frames, kept between 2 and 60 frames per second."""
    if len(times) < 2:
        return 10.0
    step = float(np.median(np.diff(times)))
    return float(np.clip(1.0 / step, 2.0, 60.0)) if step > 0 else 10.0


def export_reconstruction(out_dir, rec: Recording, result: Reconstruction, scores: dict | None = None, *,
                          settings: dict | None = None, overwrite: bool = False, video: bool = True,
                          log=print) -> dict:
    """Write a finished reconstruction into ``out_dir`` (atomically: all or nothing).

    Layout: ``frames/frame_00000.png`` ... (the reconstruction), ``timestamps.txt`` (one time per
    frame), ``reconstruction.mp4`` and ``.gif`` (``video``), ``gt/`` (the ground-truth frames in the
    window) with ``metrics.json`` and ``metrics.csv`` (per frame, both protocols) when scored, and
    ``run.json`` (input, format, window, settings, EvINR config, timings).

    ``out_dir`` may also be an :class:`~evinr_lite.io.output.OutputDir` opened (checked and locked)
    before the long work, as :func:`run_reconstruct` does; it is committed here.

    Returns:
        The contents of run.json.
    Raises:
        OutputError (FileExistsError): ``out_dir`` exists and ``overwrite`` is False, or it cannot be
            written (see :func:`evinr_lite.io.output.check_output_path`).
    """
    from ..io.output import OutputDir

    if isinstance(out_dir, OutputDir):
        run = _write_reconstruction(out_dir.staging, rec, result, scores, settings=settings, video=video, log=log)
        out_dir.commit()
        return run
    with OutputDir(out_dir, overwrite=overwrite, inputs=[rec.meta.get("path")], log=log) as target:
        run = _write_reconstruction(target.staging, rec, result, scores, settings=settings, video=video, log=log)
        target.commit()
    return run


def _write_reconstruction(tmp: Path, rec: Recording, result: Reconstruction, scores: dict | None, *,
                          settings: dict | None, video: bool, log) -> dict:
    from ..io.export import save_csv, save_frames_png, save_gif, save_mp4, save_timestamps
    from ..io.output import save_json

    written = ["frames/", "timestamps.txt"]
    run = {"input": rec.meta.get("path"), "format": rec.meta.get("format"),
           "sensor_size": list(rec.events.sensor_size), "t_origin": rec.events.t_origin,
           "window_s": list(rec.meta["window"]), "n_events": len(rec.events),
           "n_frames_written": len(result.times), "times_s": result.times.tolist(),
           **(settings or {}), "evinr_config": result.history.get("config"),
           "train_time_s": result.history.get("train_time_s")}
    # into the staging folder; the caller renames it into place
    save_frames_png(tmp / "frames", result.frames)
    save_timestamps(tmp / "timestamps.txt", result.times, rec.events.t_origin)
    if video:
        fps = _video_fps(result.times)
        save_gif(tmp / "reconstruction.gif", result.frames, fps)
        written.append("reconstruction.gif")
        try:
            save_mp4(tmp / "reconstruction.mp4", result.frames, fps)
            written.append("reconstruction.mp4")
        except RuntimeError as err:
            log(f"warning: {err}")
        run["video_fps"] = fps
    if scores is not None:
        gt = rec.frames
        save_frames_png(tmp / "gt", gt.images)
        save_timestamps(tmp / "gt" / "timestamps.txt", gt.t, gt.t_origin)
        summary = {eq: {k: v for k, v in s.items() if not k.startswith("per_frame")} for eq, s in scores.items()}
        save_json(tmp / "metrics.json", {"scored_at": "the ground-truth frame times in the window",
                                         "protocols": summary,
                                         "per_frame": {eq: {k: v for k, v in s.items() if k.startswith("per_frame")}
                                                       for eq, s in scores.items()}})
        first = next(iter(scores.values()))
        rows = []
        for k, gi in enumerate(first["per_frame_index"]):
            row = {"gt_index": gi, "t_s": f"{first['per_frame_t_s'][k]:.9f}"}
            for eq, s in scores.items():
                row[f"mse_{eq}"] = f"{s['per_frame_mse'][k]:.6f}"
                row[f"ssim_{eq}"] = f"{s['per_frame_ssim'][k]:.6f}"
            rows.append(row)
        save_csv(tmp / "metrics.csv", rows)
        written += ["gt/", "metrics.json", "metrics.csv"]
        run["scores"] = summary
    run["files"] = written + ["run.json"]
    save_json(tmp / "run.json", _jsonable(run))
    return run


def _jsonable(obj):
    """numpy scalars/arrays and tuples -> plain JSON types."""
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    return obj


# ---- the whole job ---------------------------------------------------------------------------

RECIPES = {"kit": EvINRConfig, "paper": EvINRConfig.paper, "v0_1": EvINRConfig.v0_1}


def recipe_config(recipe: str = "kit", n_iters: int | None = None, **fields) -> EvINRConfig:
    """The EvINRConfig of a named recipe: "kit" (``EvINRConfig()``, the default), "paper" (the paper's
    recipe exactly) or "v0_1" (the kit's default before the scene zoo).

    ``n_iters`` None keeps the recipe's own (kit: no Adam iteration, the output layer solved in closed
    form; paper: 300). Given, it sets the Adam iterations; for the recipes with coarse-to-fine the two
    bisections move to n_iters / 3 and 2 n_iters / 3 (the paper's 100 and 200 of 300).
    """
    if recipe not in RECIPES:
        raise EventDataError(f"recipe= must be one of {tuple(RECIPES)}, got {recipe!r}")
    make = RECIPES[recipe]
    if n_iters is not None:
        fields["n_iters"] = int(n_iters)
        if make().coarse_to_fine:
            c2f = (n_iters // 3, 2 * n_iters // 3) if n_iters >= 3 else ()
            fields.update(c2f_iters=c2f, coarse_to_fine=bool(c2f))
    return make(**fields)


def contrast_option(C):
    """run_reconstruct's ``C=`` checked: None (the file's, else DEFAULT_C), a positive number, a pair
    (c_pos, c_neg) of positive numbers, or "auto" (fitted from the APS frames: :func:`resolve_contrast`).
    Returns None, "auto", a float or a (c_pos, c_neg) tuple; EventDataError naming C= otherwise."""
    if C is None or (isinstance(C, str) and C == "auto"):
        return C
    if isinstance(C, (tuple, list, np.ndarray)):
        return as_thresholds(C, "C=")
    if isinstance(C, bool) or not isinstance(C, (int, float, np.integer, np.floating)) or not math.isfinite(C):
        raise EventDataError(f"C= must be a finite number, a pair (c_pos, c_neg) or 'auto', got {C!r}")
    if not C > 0:
        raise EventDataError(f"C= must be positive (a contrast threshold in log units), got {C}")
    return float(C)


def format_contrast(C) -> str:
    """'0.2' for one threshold, 'C+ 0.22 / C- 0.18' for a pair."""
    return f"{C:g}" if np.ndim(C) == 0 else f"C+ {C[0]:.4g} / C- {C[1]:.4g}"


def resolve_contrast(rec: Recording, C, path=None, log=print, *, colour: bool = False):
    """(C for EvINRConfig, where it came from, the ContrastFit or None) for a checked ``C=`` option.

    "auto" fits C+ and C- from the recording's APS frames in the window
    (:func:`evinr_lite.method.contrast.fit_contrast`) and logs the fit with its uncertainty; None
    takes the file's C, else DEFAULT_C. Raises EventDataError when "auto" finds no frames or too
    few usable ones (the message says to pass a number instead).
    """
    fit = None
    if C == "auto":
        lo, hi = rec.meta["window"]
        if rec.frames is None or len(rec.frames) < 2:
            n = 0 if rec.frames is None else len(rec.frames)
            raise EventDataError(f"{path}: C='auto' fits C from the recording's APS frames, but the window "
                                 f"[{lo:.6f}, {hi:.6f}] s holds {n} frame(s) (2 or more needed); pass a number instead "
                                 "(e.g. C=0.2), or widen the window with t_start=/t_end=")
        try:
            fit = fit_contrast(rec.frames, rec.events)
        except EventDataError as err:
            raise EventDataError(f"{path}: C='auto' could not fit C from the frames in [{lo:.6f}, {hi:.6f}] s: "
                                 f"{err}") from None
        log(f"C from the APS frames: {fit}")
        C, source = fit.C, "fitted from the APS frames (auto)"
    elif C is not None:
        source = "given"
    else:
        source = "from the file" if rec.meta.get("C") else "default (pass C=)"
        C = float(rec.meta.get("C") or DEFAULT_C)
    if colour and np.ndim(C) != 0:
        raise EventDataError("colour reconstruction takes one C (the photosites' threshold), not a pair or 'auto'; "
                             "pass a number (e.g. C=0.2)")
    return C, source, fit


def check_run_options(*, C=None, fps=None, t_start=None, t_end=None, n_iters: int | None = None, seed: int = 0,
                      time_unit=None, recipe: str = "kit", anchor: str = "none") -> None:
    """Every option of :func:`run_reconstruct` checked before any file is read (EventDataError naming it)."""
    def finite(name, value):
        if value is None:
            return None
        if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) or not math.isfinite(value):
            raise EventDataError(f"{name} must be a finite number, got {value!r}")
        return float(value)

    contrast_option(C)
    if anchor not in ANCHOR_MODES:
        raise EventDataError(f"anchor= must be one of {ANCHOR_MODES}, got {anchor!r}")
    if finite("fps=", fps) is not None and not fps > 0:
        raise EventDataError(f"fps= must be a positive number of frames per second, got {fps}")
    finite("t_start=", t_start)
    finite("t_end=", t_end)
    if t_start is not None and t_end is not None and not t_end > t_start:
        raise EventDataError(f"time window [{t_start}, {t_end}) is empty or reversed; t_end= must exceed t_start=")
    if n_iters is not None and (isinstance(n_iters, bool) or not isinstance(n_iters, (int, np.integer)) or n_iters < 1):
        raise EventDataError(f"n_iters= must be a whole number of at least 1 (or None: the recipe's own), got {n_iters!r}")
    if recipe not in RECIPES:
        raise EventDataError(f"recipe= must be one of {tuple(RECIPES)}, got {recipe!r}")
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= seed < 2**63:
        raise EventDataError(f"seed must be a whole number in [0, 2**63), got {seed!r}")
    if time_unit is not None and time_unit not in TIME_UNITS:
        raise EventDataError(f"time_unit= must be one of {', '.join(TIME_UNITS)}, got {time_unit!r}")


def _available_bytes(device: str) -> int:
    """Memory free for the run: the GPU's free memory on cuda, else the system's available memory."""
    if device.startswith("cuda"):
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


def estimate_memory(rec: Recording, times, config: EvINRConfig) -> dict:
    """Bytes a reconstruction will need, by part, before anything is allocated.

    Parts: ``networks`` (each window's SIREN with its H*W head: weights, gradients and Adam's two
    moments, float32), ``bins`` (the event frames and the loss terms over them), ``frames`` (the
    queried log intensities and tone-mapped frames). An estimate (within a factor of about 2).
    """
    lo, hi = rec.meta["window"]
    span = max(float(hi) - float(lo), 0.0)
    H, W = rec.events.sensor_size
    pixels = float(H) * float(W)
    if config.tau is None or span <= config.tau:
        n_windows = 1
    else:
        n_windows = math.ceil((span - config.overlap) / (config.tau - config.overlap))
    hidden = config.hidden_features
    params = 2 * hidden + config.hidden_layers * (hidden * hidden + hidden) + (hidden + 1) * pixels
    if config.binning == "fixed":
        n_bins = math.ceil(span / config.bin_duration)
    else:
        n_bins = math.ceil(len(rec.events) / config.events_per_bin)
    n_bins = max(n_bins, 1)
    parts = {"networks": 16.0 * params * n_windows, "bins": 3 * 4.0 * n_bins * pixels,
             "frames": 2 * 16.0 * len(np.atleast_1d(times)) * pixels}
    return {"total": sum(parts.values()), "parts": parts, "n_windows": n_windows, "n_bins": n_bins,
            "n_frames": len(np.atleast_1d(times)), "span_s": span}


def check_memory(rec: Recording, times, config: EvINRConfig, device: str = "cpu", *, fraction: float = 0.8) -> dict:
    """Refuse (EventDataError) a reconstruction whose :func:`estimate_memory` exceeds ``fraction`` of
    the free memory, naming the estimate and the parameter to change. Returns the estimate."""
    est = estimate_memory(rec, times, config)
    free = _available_bytes(device)
    if est["total"] <= fraction * free:
        return est
    gib = lambda b: f"{b / 2**30:,.1f} GiB"  # noqa: E731
    H, W = rec.events.sensor_size
    lo, hi = rec.meta["window"]
    worst = max(est["parts"], key=est["parts"].get)
    ev_lo, ev_hi = (float(rec.events.t[0]), float(rec.events.t[-1])) if len(rec.events) else (lo, hi)
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
    raise EventDataError(f"this reconstruction needs about {gib(est['total'])} of memory but about {gib(free)} is "
                         f"free on {device}: most of it for {fix}")


# ---- the whole job ---------------------------------------------------------------------------

def denoise_recording(rec: Recording, path, log=print):
    """(the recording with its events denoised, the DenoiseReport); refuses a window left with < 2 events."""
    from ..method.denoise import denoise as denoise_events

    events, report = denoise_events(rec.events)
    log(report.summary())
    if len(events) < 2:
        raise EventDataError(f"{path}: denoising left {len(events)} event(s) of {report.n_in:,} in the window; "
                             "run without --denoise (denoise=False) or choose a longer window")
    return Recording(events, rec.frames, rec.meta), report


def run_reconstruct(path, out_dir, *, sensor_size=None, C: float | tuple | str | None = None, fps: float | None = None, at=None,
                    t_start: float | None = None, t_end: float | None = None, device: str | None = None,
                    n_iters: int | None = None, seed: int = 0, overwrite: bool = False, video: bool = True,
                    progress: bool = True, time_unit: str | None = None, log=print, command: str = "",
                    recipe: str = "kit", colour: bool = False, anchor: str = "none", denoise: bool = False) -> dict:
    """load -> window -> reconstruct -> score -> export; the ``evinr-lite reconstruct`` command.

    Every check that can fail runs before training: the options, the output folder (checked,
    locked for the whole run against a second run, a staging folder created beside it), the
    device, the file, its format, the sensor size, the window, the times and the memory needed.
    C: the contrast threshold; a pair (c_pos, c_neg) for ON and OFF events; "auto" fits C+ and C-
    from the APS frames in the window (logged with its uncertainty, recorded in run.json as
    "C_fit"); None takes the file's (canonical files store it), else DEFAULT_C = 1
    (the paper's for DAVIS data). time_unit: the unit of integer or text timestamps ('s', 'ms',
    'us', 'ns'; None: the reader's detection). ``command`` is recorded in the lock so a second run
    can name this one. colour: reconstruct in colour from a recording with a colour filter
    (``meta["cfa"]``; :mod:`evinr_lite.apps.colour_job`), writing colour frames at (H/2, W/2).
    anchor: "none" (events only), "first" or "all": the recording's APS frames as anchors
    (:mod:`evinr_lite.method.anchor`); the anchor frames are not scored, run.json's "anchor" says which.
    denoise: remove hot pixels and background activity from the window's events first
    (:func:`evinr_lite.method.denoise.denoise`, its defaults); run.json's settings["denoise"] is the report.
    Returns the contents of run.json (with "scores" when the recording has frames).
    """
    from ..core.runtime import default_device
    from ..io.output import OutputDir

    t0 = time.perf_counter()
    check_run_options(C=C, fps=fps, t_start=t_start, t_end=t_end, n_iters=n_iters, seed=seed, time_unit=time_unit,
                      recipe=recipe, anchor=anchor)
    if anchor != "none" and colour:
        raise EventDataError("anchored colour reconstruction is not supported; pass anchor='none' with colour")
    with OutputDir(out_dir, overwrite=overwrite, inputs=[path], log=log, command=command) as target:
        try:
            device_name = str(default_device(device))
        except RuntimeError as err:
            raise EventDataError(str(err)) from None
        rec = load_recording(path, sensor_size=sensor_size, t_start=t_start, t_end=t_end, time_unit=time_unit)
        denoise_report = None
        if denoise:   # before anything reads the events: times, memory, training, the scores
            rec, denoise_report = denoise_recording(rec, path, log)
        if anchor != "none" and rec.frames is None:   # before any training
            lo, hi = rec.meta["window"]
            raise EventDataError(f"{path}: anchor='{anchor}' needs APS frames, but the recording has none in the window "
                                 f"[{lo:.6f}, {hi:.6f}] s; use a recording with frames (DAVIS APS frames, an IJRR folder "
                                 "with images.txt), widen the window with t_start=/t_end=, or pass anchor='none'")
        if colour:   # before any training: a mono recording is refused with the fix
            from .colour_job import check_colour_recording

            check_colour_recording(rec)
        times, source = choose_times(rec, fps=fps, at=at)
        C, C_source, C_fit = resolve_contrast(rec, contrast_option(C), path, log, colour=colour)
        config = recipe_config(recipe, n_iters, C=C, seed=seed, device=device, progress=progress, anchor=anchor)
        check_memory(rec, times, config, device_name)
        lo, hi = rec.meta["window"]
        H, W = rec.events.sensor_size
        log(f"read {len(rec.events):,} events ({rec.meta['format']}, {H}x{W}) in [{lo:.6f}, {hi:.6f}] s"
            + (f", {len(rec.frames)} ground-truth frames" if rec.frames is not None else ", no frames")
            + f" in {time.perf_counter() - t0:.1f} s")
        log(f"reconstructing {source} with EvINR ({recipe} recipe, C = {format_contrast(C)} {C_source}, {config.n_iters} Adam "
            f"iterations{' + the closed-form output layer' if config.head_solve else ''}, {device_name})")
        if colour:   # one EvINR per channel of the colour filter (apps/colour_job.py)
            from .colour_job import reconstruct_colour_recording, score_colour_recording

            result = reconstruct_colour_recording(rec, times, config)
            scores, colour_scores = score_colour_recording(result, rec, score_predictions)
        else:
            result = reconstruct_recording(rec, times, config)
            scores = score_recording(result, rec.frames)
        settings = {"C": C, "C_source": C_source, "times_source": source, "device": device_name, "seed": seed}
        if C_fit is not None:   # --C auto: the fit, its uncertainty and what it used
            settings["C_fit"] = C_fit.as_dict()
        if denoise_report is not None:
            settings["denoise"] = denoise_report.to_dict()
        if anchor != "none":   # which frames fixed the offset (not scored) and how many were scored
            settings["anchor"] = {**result.history["anchor"],
                                  "n_scored": scores["none"]["n_frames"] if scores else 0}
        if colour:
            settings["colour"] = {"cfa": result.history["cfa"], "thresholds": result.history["thresholds"],
                                  "grid": list(result.frames.shape[1:3]), **(colour_scores or {})}
        run = export_reconstruction(target, rec, result, scores, settings=settings, video=video, log=log)
    seconds = time.perf_counter() - t0
    out_dir = target.given
    line = (f"wrote {len(times)} frames to {out_dir}/ in {seconds:.1f} s "
            f"(training {result.history['train_time_s']:.1f} s)")
    if scores:
        parts = [f"{eq}: MSE {s['mse']:.4f} SSIM {s['ssim']:.3f}" + (f" LPIPS {s['lpips']:.3f}" if s.get("lpips") else "")
                 for eq, s in scores.items()]
        line += f"; scored against {scores['none']['n_frames']} ground-truth frames ({'; '.join(parts)})"
    else:
        line += "; no ground-truth frames, not scored"
    if anchor != "none":
        a = run["anchor"]
        line += (f"; anchored ({anchor}) on {a['n_anchors']} APS frame(s) at t = "
                 f"{', '.join(f'{t:.6f}' for t in a['anchor_times_s'])} s, not scored")
    chroma = (run.get("colour") or {}).get("chroma_correlation")
    if chroma:
        line += f"; colour (grey world): chroma correlation R-G {chroma['R-G']:.3f}, B-G {chroma['B-G']:.3f}"
    log(line)
    run["total_time_s"] = seconds
    return run
