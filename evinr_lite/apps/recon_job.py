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

import os
import time
from pathlib import Path

import numpy as np

from ..core.checks import check_path_type, true_or_false
from ..core.events import EventDataError
from ..core.recording import Recording
from ..io.load import (FIXED_UNITS, READER_WINDOW_FORMATS, SENSOR_ARG_FORMATS, SIZE_FREE_FORMATS,  # noqa: F401
                       TIME_UNIT_FORMATS, describe_recording, format_info, load_recording, read_any)
from ..method.config import EvINRConfig
from ..method.memory import check_memory
from ..method.recipes import (DEFAULT_C, RECIPES, contrast_option, format_contrast, recipe_config,  # noqa: F401
                              resolve_contrast)
from ..method.solver import Reconstruction, reconstruct
from .options import DEFAULT_FPS, RunOptions, check_run_options, choose_times, parse_times  # noqa: F401
from .results import EQUALIZATIONS, score_predictions, score_recording, write_results  # noqa: F401
from .stream_job import (check_disk, display_attrs, report_background, report_balance, report_lam, report_level,
                         report_reach, report_temporal_scale, run_streaming, streamable, video_fps)

__all__ = ["read_any", "load_recording", "describe_recording", "format_info", "choose_times", "reconstruct_recording",
           "score_predictions", "score_recording", "export_reconstruction", "run_reconstruct",
           "DEFAULT_FPS", "DEFAULT_C", "EQUALIZATIONS"]



# ---- times and reconstruction ----------------------------------------------------------------

def reconstruct_recording(rec: Recording, times, config: EvINRConfig | None = None) -> Reconstruction:
    """EvINR over the recording's window (``meta["window"]``), queried at ``times`` (seconds); an
    anchored config (``anchor`` "first" / "all") takes the recording's APS frames as anchors."""
    lo, hi = rec.meta["window"]
    config = config or EvINRConfig()
    frames = rec.frames if config.anchor != "none" else None
    return reconstruct(rec.events, times, config, t_start=lo, t_end=hi, frames=frames)


# ---- export ----------------------------------------------------------------------------------

def export_reconstruction(out_dir, rec: Recording, result: Reconstruction, scores: dict | None = None, *,
                          settings: dict | None = None, overwrite: bool = False, video: bool = True,
                          save_log: bool = False, log=print) -> dict:
    """Write a finished reconstruction into ``out_dir`` (atomically: all or nothing).

    Layout: ``frames/frame_00000.png`` ... (the reconstruction), ``timestamps.txt`` (one time per
    frame), ``reconstruction.mp4`` and ``.gif`` (``video``), ``log_intensity.h5`` (``save_log``: the
    frames' log intensity, float32, unclipped; :func:`evinr_lite.io.export.read_log_intensity`),
    ``gt/`` (the ground-truth frames in the window) with ``metrics.json`` and ``metrics.csv`` (per
    frame, both protocols) when scored, and ``run.json`` (input, format, window, settings, EvINR
    config, timings).

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
        run = _write_reconstruction(out_dir.staging, rec, result, scores, settings=settings, video=video,
                                    save_log=save_log, log=log)
        out_dir.commit()
        return run
    with OutputDir(out_dir, overwrite=overwrite, inputs=[rec.meta.get("path")], log=log) as target:
        run = _write_reconstruction(target.staging, rec, result, scores, settings=settings, video=video,
                                    save_log=save_log, log=log)
        target.commit()
    return run


def _write_reconstruction(tmp: Path, rec: Recording, result: Reconstruction, scores: dict | None, *,
                          settings: dict | None, video: bool, save_log: bool, log) -> dict:
    from ..io.export import LOG_INTENSITY_FILE, save_frames_png, save_gif, save_log_intensity, save_mp4, save_timestamps

    written = ["frames/", "timestamps.txt"]
    settings = dict(settings or {})
    # into the staging folder; the caller renames it into place
    save_frames_png(tmp / "frames", result.frames)
    save_timestamps(tmp / "timestamps.txt", result.times, rec.events.t_origin)
    if save_log:
        save_log_intensity(tmp / LOG_INTENSITY_FILE, result.log_intensity, result.times, t_origin=rec.events.t_origin,
                           **display_attrs(result.config if isinstance(result, Reconstruction) else result.history["config"]))
        written.append(LOG_INTENSITY_FILE)
    if video:
        fps = video_fps(result.times)
        save_gif(tmp / "reconstruction.gif", result.frames, fps)
        written.append("reconstruction.gif")
        try:
            save_mp4(tmp / "reconstruction.mp4", result.frames, fps)
            written.append("reconstruction.mp4")
        except RuntimeError as err:
            log(f"warning: {err}")
        settings["video_fps"] = fps
    return write_results(tmp, rec, result.times, result.history, scores, settings=settings, written=written)


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


def run_reconstruct(path, out_dir, options: RunOptions | None = None, *, overwrite: bool = False, log=print,
                    command: str = "", resume: bool = False, **fields) -> dict:
    """load -> window -> reconstruct -> score -> export; the ``evinr-lite reconstruct`` command.

    The run's options are a :class:`~evinr_lite.apps.options.RunOptions` (``options``), or its
    fields given as keywords (``C=0.2, fps=30, ...``), or both (the keywords replace fields of
    ``options``): sensor_size, C ("auto" fits C+ and C- from the APS frames, recorded in run.json
    as "C_fit"; None: the file's, else DEFAULT_C), fps / at, t_start / t_end, time_unit, device,
    recipe / n_iters / seed, anchor (APS frames as anchors, not scored; run.json's "anchor" says
    which), denoise (run.json's "denoise" is the report), colour (one EvINR per channel
    of the colour filter, frames at (H/2, W/2)), video, progress.

    Every check that can fail runs before training: the options, the output folder (checked,
    locked for the whole run against a second run, a staging folder created beside it), the
    device, the file, its format, the sensor size, the window, the times and the memory needed.
    ``overwrite`` replaces ``out_dir``; ``command`` is recorded in the lock so a second run can
    name this one. Returns the contents of run.json (with "scores" when the recording has frames).

    Events-only grey runs without denoise or C="auto" stream (:mod:`evinr_lite.apps.stream_job`):
    only each window's events are read, memory is set by the window and the sensor, and a run
    that is killed can be continued with ``resume=True`` (``--resume``) without recomputing its
    finished windows. The others read the window into memory and solve it whole.
    """
    from ..core.runtime import default_device
    from ..io.output import OutputDir

    t0 = time.perf_counter()
    if isinstance(path, bytes):   # as read_recording takes them (io.formats.registry.recording_path)
        path = os.fsdecode(path)
    check_path_type(path, "path", "a recording, a file or folder")   # None: "expected str, bytes or os.PathLike"
    resume = true_or_false(resume, "resume")   # "yes" and 5 were taken as true
    options = RunOptions.of(options, **fields)   # every option checked, once, before anything is touched
    anchor, colour = options.anchor, options.colour
    if streamable(options):
        with OutputDir(out_dir, overwrite=overwrite, inputs=[path], log=log, command=command) as target:
            run, times, scores = run_streaming(path, target, options, resume=resume, log=log, t0=t0)
        return _finish(run, times, scores, target.given, t0, options, log)
    if resume:
        log("note: --resume applies to streamed runs (events only, without --denoise, --C auto, --anchor or "
            "--colour); this run starts from the beginning")
    with OutputDir(out_dir, overwrite=overwrite, inputs=[path], log=log, command=command) as target:
        try:
            device_name = str(default_device(options.device))
        except RuntimeError as err:
            raise EventDataError(str(err)) from None
        rec = load_recording(path, sensor_size=options.sensor_size, t_start=options.t_start, t_end=options.t_end,
                             time_unit=options.time_unit, camera=options.camera)
        denoise_report = None
        if options.denoise:   # before anything reads the events: times, memory, training, the scores
            rec, denoise_report = denoise_recording(rec, path, log)
        if anchor != "none" and rec.frames is None:   # before any training
            lo, hi = rec.meta["window"]
            raise EventDataError(f"{path}: anchor='{anchor}' needs APS frames, but the recording has none in the window "
                                 f"[{lo:.6f}, {hi:.6f}] s; use a recording with frames (DAVIS APS frames, an IJRR folder "
                                 "with images.txt), widen the window with t_start=/t_end=, or pass anchor='none'")
        if colour:   # before any training: a mono recording is refused with the fix
            from .colour_job import check_colour_recording

            check_colour_recording(rec)
        lo, hi = rec.meta["window"]
        if len(rec.events):
            report_reach(lo, hi, float(rec.events.t[0]), float(rec.events.t[-1]), log)
        H, W = rec.events.sensor_size

        def fits(n_times: int, config) -> None:
            check_memory((H, W), lo, hi, len(rec.events), n_times, config, device_name,
                         events_span=(float(rec.events.t[0]), float(rec.events.t[-1])))

        # before the times are built (the memory estimate does not depend on C), and again once C is known
        times, source = choose_times(rec, fps=options.fps, at=options.at,
                                     check=lambda n: fits(n, options.config(DEFAULT_C)))
        C, C_source, C_fit = resolve_contrast(rec, options.C, path, log, colour=colour)
        config = options.config(C)
        fits(len(times), config)
        if options.save_log:   # the log intensities go to disk: 4 bytes a pixel a frame (and the PNGs)
            check_disk(len(times), (H, W), target.staging)
        log(f"read {len(rec.events):,} events ({rec.meta['format']}, {H}x{W}) in [{lo:.6f}, {hi:.6f}] s"
            + (f", {len(rec.frames)} ground-truth frames" if rec.frames is not None else ", no frames")
            + f" in {time.perf_counter() - t0:.1f} s")
        log(f"reconstructing {source} with EvINR ({options.recipe} recipe, C = {format_contrast(C)} {C_source}, {config.n_iters} Adam "
            f"iterations{' + the closed-form output layer' if config.head_solve else ''}, {device_name})")
        if colour:   # one EvINR per channel of the colour filter (apps/colour_job.py)
            from .colour_job import reconstruct_colour_recording, score_colour_recording

            result = reconstruct_colour_recording(rec, times, config)
            scores, colour_scores = score_colour_recording(result, rec, score_predictions)
        else:
            result = reconstruct_recording(rec, times, config)
            scores = score_recording(result, rec.frames)
        settings = {"C": C, "C_source": C_source, "times_source": source, "device": device_name, "seed": options.seed}
        if not colour:
            report_balance(C, result.config.C, settings, log)
            report_lam(config.lam, result.config.lam, settings, log)
            report_temporal_scale(config.temporal_scale, result.config.scale(), config.bin_duration, settings, log)
            report_background(config.background, result.config.background, result.config.background_dt, settings, log)
        report_level(options, config, log)
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
        run = export_reconstruction(target, rec, result, scores, settings=settings, video=options.video,
                                    save_log=options.save_log, log=log)
    return _finish(run, times, scores, target.given, t0, options, log)


def _finish(run: dict, times, scores, out_dir, t0: float, options, log) -> dict:
    """The run's closing line (frames, time, scores, anchors, colour) and its total time."""
    anchor = options.anchor
    seconds = time.perf_counter() - t0
    line = (f"wrote {len(times)} frame{'' if len(times) == 1 else 's'} to {out_dir}/ in {seconds:.1f} s "
            f"(training {run.get('train_time_s') or 0.0:.1f} s)")
    if scores:
        parts = [f"{eq}: MSE {s['mse']:.4f} SSIM {s['ssim']:.3f}" + (f" LPIPS {s['lpips']:.3f}" if s.get("lpips") else "")
                 + (f" (MSE {s['mse_at_level']:.4f} at the truth's level, gain {s['level_gain']:.2f})"
                    if "mse_at_level" in s else "") for eq, s in scores.items()]
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
