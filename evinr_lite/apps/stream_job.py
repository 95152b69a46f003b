"""The reconstruct job over a stream of windows: bounded memory at any recording length, resumable.

:func:`~evinr_lite.apps.recon_job.run_reconstruct` hands events-only runs here
(:func:`streamable`). The recording is opened as a source (only each window's events are read,
:func:`~evinr_lite.io.load.open_recording`), reconstructed window by window
(:func:`~evinr_lite.method.streaming.stream_reconstruct`, the same result as the whole-sequence
solve), and its frames are written into the run's staging folder a batch at a time.

Resume: while it runs, a folder ``.<name>.resume`` beside the output holds the stream's state after
every window and the log intensities finished so far (a spill file, 4 bytes x H x W per frame),
with a marker naming the input (resolved path, size, modification time) and the result settings.
A run that is stopped after a finished window leaves it behind (and says so; one stopped
before any leaves nothing); ``resume=True`` (``evinr-lite reconstruct ... --resume``)
continues from the last finished window when the marker matches, and refuses otherwise; a run
without ``resume`` replaces it. It is removed once every frame is in the staging folder. The output folder
itself stays all-or-nothing (:class:`~evinr_lite.io.output.OutputDir`), and its lock covers the
resume folder too.
"""
from __future__ import annotations

import hashlib
import json
import os
import shutil
import time
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np

from ..core.events import EventDataError, Events
from ..core.frames import Frames
from ..core.guard import signals_deferred
from ..core.recording import Recording

__all__ = ["streamable", "run_streaming", "check_disk", "resume_folder", "video_fps", "display_attrs", "RESUME_MARKER",
           "GIF_LIMIT_BYTES"]

RESUME_MARKER = ".evinr-resume.json"   # inside the resume folder: the proof it is this job's own
GIF_LIMIT_BYTES = 512 << 20            # uint8 frames kept for the GIF; beyond, the GIF is skipped (the MP4 streams)


def streamable(options) -> bool:
    """True for runs the stream can do: events only, grey, without the steps that need every event of
    the window at once (denoise, C fitted from the frames)."""
    return options.anchor == "none" and not options.colour and not options.denoise and options.C != "auto"


def resume_folder(out_path: Path) -> Path:
    """The resume folder of an output folder: ``.<name>.resume`` beside it."""
    out_path = Path(os.path.abspath(out_path))
    return out_path.parent / f".{out_path.name}.resume"


def _identity(path) -> dict:
    """The input's identity: resolved path, size and modification time (a folder: of its files too)."""
    p = Path(path).resolve()
    st = p.stat()
    ident = {"path": str(p), "size": st.st_size, "mtime_ns": st.st_mtime_ns}
    if p.is_dir():
        ident["files"] = sorted((str(f.relative_to(p)), f.stat().st_size, f.stat().st_mtime_ns)
                                for f in p.rglob("*") if f.is_file())
    return ident


def report_balance(C, used, settings: dict, log) -> None:
    """When one C was given and the ON/OFF balance (method/balance.py) made it a pair: log the pair and
    record it in ``settings["C_used"]`` (the in-memory and the streamed job both)."""
    from ..method.recipes import format_contrast

    if np.ndim(C) != 0 or used is None or np.ndim(used) == 0 or len(used) != 2:
        return
    settings["C_used"] = [float(c) for c in used]
    log(f"ON/OFF balance from the events: C+ = {used[0]:.4f}, C- = {used[1]:.4f}, their mean the given "
        f"C = {format_contrast(C)} (pass --C {format_contrast(C)},{format_contrast(C)} to use it for both)")


def report_lam(lam, used, settings: dict, log) -> None:
    """When the regularizer's weight was chosen from the events (``lam="auto"``): log the value and record it in
    ``settings["lam_used"]`` (the in-memory and the streamed job both)."""
    if lam != "auto" or used is None:
        return
    settings["lam_used"] = float(used)
    log(f"spatial smoothing chosen from the events' activity: lam = {float(used):.4g} (pass --lam to set it; more "
        "smooths more, e.g. 0.03-0.1 under heavy background activity)")


def report_temporal_scale(scale, used, bin_duration: float, settings: dict, log) -> None:
    """When the temporal scale was read from the events (``temporal_scale="auto"``, method/tempo.py): record it
    in ``settings["temporal_scale_used"]`` and, when it is above 1 (fast motion), log the bins it gave (the
    in-memory and the streamed job both)."""
    if scale != "auto" or used is None:
        return
    settings["temporal_scale_used"] = float(used)
    if used > 1:
        log(f"fast changes: the pixels reverse polarity often, so the bins are {float(used):.3g}x shorter (at most "
            f"{1000 * bin_duration / used:.3g} ms, not {1000 * bin_duration:.3g}) and the temporal prior "
            f"{float(used):.3g}x faster (pass --temporal-scale 1 to keep them)")


def report_background(background, used, dt, settings: dict, log) -> None:
    """When the background filter's window was chosen from the events (``background="auto"``): log the choice
    and record it in ``settings["background_used"]`` (the in-memory and the streamed job both)."""
    if background != "auto" or used is None:
        return
    settings["background_used"] = {"background": used, "background_dt": float(dt) if used == "filter" else None}
    if used == "filter":
        log(f"background activity filtered with a {float(dt):g} s window chosen from the events' share of noise "
            "(pass --keep-background to train on every event)")
    else:
        log("no background filter: the events' share of noise is too small to pay for one (every event kept)")


def report_level(options, config, log) -> None:
    """When the frames' level is the tone map's prior (no ``display_mean`` given, no APS anchor): say so once,
    with the option that sets it (the in-memory and the streamed job both)."""
    if options.display_mean is not None or options.anchor != "none":
        return
    level = ("at a mean brightness of" if config.tonemap == "linear" else "with their mean log intensity at")
    log(f"frames shown {level} {config.display_mean:g} over the window: events never give the level (pass "
        "--display-mean to set it, e.g. 0.2 for a dark scene)")


def report_reach(lo: float, hi: float, first: float, last: float, log, slack: float = 1.0) -> None:
    """A note when the window [lo, hi] (s) reaches more than ``slack`` seconds beyond the events, which lie
    in [first, last] (s): frames there are asked of a time nothing was recorded in (both jobs)."""
    parts = ([f"{first - lo:.1f} s before the first event ({first:.6f} s)"] if first - lo > slack else []) + \
            ([f"{hi - last:.1f} s after the last ({last:.6f} s)"] if hi - last > slack else [])
    if parts:
        log(f"note: the window [{lo:.6f}, {hi:.6f}] s reaches {' and '.join(parts)}; nothing fires there, so its "
            "frames repeat the state at the nearest event (compare --start / --end with `evinr-lite info`)")


def _key(path, config, times, window) -> dict:
    """What a saved state must match to be resumed: the input, the settings, the times and the span."""
    digest = hashlib.sha256(np.ascontiguousarray(times, np.float64).tobytes()).hexdigest()
    cfg = {k: v for k, v in asdict(config).items() if k not in ("progress",)}
    return json.loads(json.dumps({"input": _identity(path), "config": cfg, "times_sha256": digest,
                                  "window": [float(window[0]), float(window[1])]}, default=str))


def _prepare_resume(folder: Path, key: dict, resume: bool, log):
    """The StreamState to resume from (or None), the folder made ready. A folder without this job's
    marker is never touched."""
    from ..method.streaming import StreamState

    marker = folder / RESUME_MARKER
    if folder.exists() or folder.is_symlink():
        if folder.is_symlink() or not marker.is_file():
            raise EventDataError(f"{folder} exists but was not made by evinr-lite (no {RESUME_MARKER} inside); "
                                 "move it away, or choose another output folder")
        try:
            saved = json.loads(marker.read_text())
        except (OSError, ValueError):
            saved = None
        state_file = folder / "state.npz"
        if resume and saved == key and state_file.is_file():
            try:
                state = StreamState.load(state_file)
            except (OSError, ValueError, KeyError) as err:
                raise EventDataError(f"{state_file}: the saved state cannot be read ({err}); run without --resume "
                                     "to start again") from None
            log(f"resuming from {folder}: {state.next_window} of {len(state.windows)} window(s) already done")
            return state
        if resume:
            what = "another input or other settings" if saved != key else "no finished window"
            raise EventDataError(f"--resume: the stopped run in {folder} was for {what}; run without --resume to "
                                 "start again (its state is then replaced)")
        log(f"a stopped run's state in {folder} is replaced (pass --resume to continue it instead)")
        shutil.rmtree(folder)
    elif resume:
        log(f"--resume: no stopped run to continue ({folder} does not exist); starting from the first window")
    folder.mkdir(parents=True)
    tmp = folder / f".{RESUME_MARKER}.partial"
    tmp.write_text(json.dumps(key))
    tmp.replace(marker)
    return None


def _header(path, options, log):
    """(source, span (lo, hi), ground-truth Frames in the span or None, a Recording carrying the
    metadata and the span, with no events) after every check that needs no training."""
    from ..io.load import open_recording

    source = open_recording(path, sensor_size=options.sensor_size, time_unit=options.time_unit, camera=options.camera)
    first, last = source.t_span
    lo = first if options.t_start is None else float(options.t_start)
    hi = last if options.t_end is None else float(options.t_end)
    if source.n_events is not None and source.n_events < 2:   # not a window problem: say what the file holds
        source.close()
        held = "no events" if source.n_events == 0 else f"only 1 event (at t = {first:.6f} s)"
        raise EventDataError(f"{path}: the recording holds {held}; a reconstruction needs at least 2 events at "
                             "different times: use a longer recording (see `evinr-lite info`)")
    if source.n_events == 0 or not (hi > lo) or lo > last or hi < first:
        source.close()
        raise EventDataError(f"{path}: no events in the window [{options.t_start}, {options.t_end}) s; the events "
                             f"cover [{first:.6f}, {last:.6f}] s; choose a window inside it (see `evinr-lite info`)")
    report_reach(lo, hi, first, last, log)
    frames = source.frames
    if frames is not None:   # only frames the events can reach: inside [lo, hi]
        keep = (frames.t >= lo) & (frames.t <= hi)
        frames = Frames(frames.images[keep], frames.t[keep], frames.t_origin) if keep.any() else None
    H, W = source.sensor_size
    empty = Events(np.zeros(0), np.zeros(0, np.int32), np.zeros(0, np.int32), np.zeros(0, np.int8), (H, W),
                   source.t_origin)
    meta = {**source.meta, "format": source.format, "path": str(path), "window": (lo, hi)}
    return source, (lo, hi), frames, Recording(empty, frames, meta)


def run_streaming(path, target, options, *, resume: bool = False, log=print, t0: float | None = None):
    """The body of ``evinr-lite reconstruct`` for a :func:`streamable` run, into the opened
    :class:`~evinr_lite.io.output.OutputDir` ``target``. Returns (run.json's contents, times, scores)."""
    from ..core.runtime import default_device
    from ..io.export import save_timestamps
    from ..method.memory import check_memory
    from ..method.recipes import DEFAULT_C, format_contrast, resolve_contrast
    from ..method.streaming import stream_reconstruct
    from .options import choose_times
    from .results import score_predictions, write_results

    t0 = time.perf_counter() if t0 is None else t0
    try:
        device_name = str(default_device(options.device))
    except RuntimeError as err:
        raise EventDataError(str(err)) from None
    source, (lo, hi), gt, rec = _header(path, options, log)
    with source:
        H, W = source.sensor_size
        n_events = source.n_events if source.n_events is not None else 0
        gt_t = gt.t if gt is not None else np.zeros(0)

        def fits(n_query: int, config, n_times: int | None = None) -> dict:   # memory, then disk
            est = check_memory((H, W), lo, hi, n_events, n_query, config, device_name, events_span=source.t_span,
                               streaming=True)
            check_disk(n_query, (H, W), target.staging, log_frames=(n_query if n_times is None else n_times)
                       if options.save_log else 0)
            return est

        # before the times are built (the memory estimate does not depend on C), and again once C is known
        times, times_source = choose_times(rec, fps=options.fps, at=options.at,
                                           check=lambda n: fits(n + len(gt_t), options.config(DEFAULT_C)))
        C, C_source, _ = resolve_contrast(rec, options.C, path, log)
        config = options.config(C)
        query = np.unique(np.concatenate([times, gt_t]))        # sorted: the exported times and the scored ones
        est = fits(len(query), config, len(times))
        log(f"streaming {source.format} {H}x{W} over [{lo:.6f}, {hi:.6f}] s"
            + (f" ({n_events:,} events)" if source.n_events is not None else "")
            + (f", {len(gt)} ground-truth frames" if gt is not None else ", no frames")
            + f"; memory estimate {est['total'] / 2**30:.2f} GiB")
        log(f"reconstructing {times_source} with EvINR ({options.recipe} recipe, C = {format_contrast(C)} {C_source}, "
            f"{config.n_iters} Adam iterations{' + the closed-form output layer' if config.head_solve else ''}, "
            f"{device_name}), window by window")
        folder = resume_folder(target.path)
        made = False   # the resume folder is this run's to keep or remove once _prepare_resume has returned
        history = {}
        writer = None
        try:
            with signals_deferred():   # a signal here is acted on after `made` is set, inside this try
                state = _prepare_resume(folder, _key(path, config, times, (lo, hi)), resume, log)
                made = True
            writer = _FrameWriter(target.staging, times, query, gt_t, options.video, log,
                                  log_intensity=dict(frame_shape=(H, W), t_origin=source.t_origin, **display_attrs(config))
                                  if options.save_log else None)
            # the state after the last window is not saved: writing it (the offset grid: 240 MB at 1280x720)
            # took as long as a third of that window's training, which is all a resume from it would spare
            parts = stream_reconstruct(source, query, config, t_start=lo, t_end=hi, workdir=folder, state=state,
                                       on_state=lambda s: s.save(folder / "state.npz") if s.next_window < len(s.windows)
                                       else None, progress=options.progress)
            for part in parts:
                writer.add(part)
                history = part.history
            writer.close()   # every PNG and log intensity on disk (or the first write's error) before the resume state goes
        except BaseException:   # interrupted or failed: finished windows stay for --resume, else nothing stays
            # (not made: refused before the folder was ready, e.g. one that is not this job's; left untouched)
            if writer is not None:
                writer.abort()
            if made and (folder / "state.npz").is_file():
                log(f"the finished windows are kept in {folder}; the same command with --resume continues from them")
            elif made:
                shutil.rmtree(folder, ignore_errors=True)
            raise
    # every frame is in the staging folder: nothing is left to resume, and from here on an interruption
    # leaves nothing behind (the export is short)
    shutil.rmtree(folder, ignore_errors=True)
    save_timestamps(target.staging / "timestamps.txt", times, source.t_origin)
    written = ["frames/", "timestamps.txt"] + writer.finish()
    scores = score_predictions(writer.gt_frames(), gt.t, gt) if gt is not None else None
    used = history.get("C_used")
    resolved = config if used is None or len(used) != 2 else replace(config, C=tuple(used))
    if history.get("background_used") is not None:     # what background="auto" chose, so run.json reproduces it
        resolved = replace(resolved, background=history["background_used"],
                           background_dt=history["background_dt_used"])
    # lam="auto" and temporal_scale="auto" resolved too, as the in-memory job's run.json records them
    if history.get("lam_used") is not None:
        resolved = replace(resolved, lam=float(history["lam_used"]))
    if history.get("temporal_scale_used") is not None:
        resolved = replace(resolved, temporal_scale=float(history["temporal_scale_used"]))
    history = {**history, "config": asdict(resolved), "streamed": True}
    settings = {"C": C, "C_source": C_source, "times_source": times_source, "device": device_name,
                "seed": options.seed, "memory_estimate_bytes": est["total"]}
    report_balance(C, used, settings, log)
    report_lam(config.lam, history.get("lam_used"), settings, log)
    report_temporal_scale(config.temporal_scale, history.get("temporal_scale_used"), config.bin_duration, settings, log)
    report_background(config.background, history.get("background_used"), history.get("background_dt_used"),
                      settings, log)
    report_level(options, config, log)
    if writer.video_fps is not None:
        settings["video_fps"] = writer.video_fps
    run = write_results(target.staging, rec, times, history, scores, settings=settings, written=written,
                        n_events=n_events)
    target.commit()
    return run, times, scores


def check_disk(n_frames: int, sensor_size, folder, *, fraction: float = 0.8, log_frames: int = 0) -> dict:
    """Refuse (EventDataError) a run whose frames would not fit on the disk of ``folder``.

    A streamed run keeps its frames on disk, not in memory: each one is spilled as float32 log
    intensities (4 bytes a pixel) until the offset is known, then written as a PNG (at most one byte a
    pixel, and at least one 4 KiB file-system block). ``log_frames``: frames also kept as float32 log
    intensities in the output (``save_log``; 4 bytes a pixel each). Returns {"total", "free"} in bytes.
    """
    H, W = sensor_size
    need = float(n_frames) * (4.0 * H * W + max(4096.0, float(H * W))) + float(log_frames) * 4.0 * H * W
    free = float(shutil.disk_usage(Path(folder).parent if not Path(folder).exists() else folder).free)
    if need > fraction * free:
        raise EventDataError(f"this reconstruction needs about {need / 2**30:,.1f} GiB of disk for its {n_frames:,} "
                             f"output frames of {H}x{W} pixels but about {free / 2**30:,.1f} GiB is free beside "
                             f"the output; ask for fewer frames with fps=/--fps or at=/--at, or shorten the window "
                             "with t_start=/t_end= (--start/--end)")
    return {"total": need, "free": free}


class _FrameWriter:
    """Writes each finished frame of the exported times as a PNG (and into the MP4, and its log
    intensity into log_intensity.h5 when ``log_intensity`` gives that file's attributes) as it
    arrives, and keeps the frames at the ground-truth times for scoring."""

    def __init__(self, staging: Path, times, query, gt_t, video: bool, log, log_intensity: dict | None = None):
        from ..io.export import LOG_INTENSITY_FILE, LogIntensityWriter
        from ..io.output import PngWriter

        self.folder = staging / "frames"
        self.hdr = None if log_intensity is None else \
            LogIntensityWriter(staging / LOG_INTENSITY_FILE, times, **log_intensity)
        self.png = PngWriter()   # encoded on worker threads while the next frames are computed
        self.folder.mkdir(parents=True, exist_ok=True)
        self.staging, self.log = staging, log
        self.export_at = np.searchsorted(query, times)          # query index of each exported frame
        self.gt_at = np.searchsorted(query, gt_t)
        self.export_of = {}                                      # query index -> the exported frames at that time
        for i, q in enumerate(self.export_at.tolist()):          # (a time asked for twice is written twice)
            self.export_of.setdefault(q, []).append(i)
        self.gt_of = {int(q): i for i, q in enumerate(self.gt_at)}
        self.gt = [None] * len(gt_t)
        self.video = video
        self.video_fps = video_fps(times) if video else None
        self.mp4 = None
        self.gif = [] if video else None
        self.n_times = len(times)
        self.range = (np.inf, -np.inf)   # of every frame written: a constant output is refused at the end

    def add(self, part) -> None:
        from ..core.checks import check_result_frames
        from ..core.frames import to_uint8
        from ..method.solver import RESULT_FIX

        # as reconstruct refuses them: output that is not finite (here, per part), or constant (at the end)
        check_result_frames(part.log_intensity, what="EvINR's log intensity", input_varies=False, fix=RESULT_FIX)
        if part.frames.size:
            self.range = (min(self.range[0], float(part.frames.min())), max(self.range[1], float(part.frames.max())))
        u8 = to_uint8(part.frames)
        for j, q in enumerate(part.indices.tolist()):
            for i in self.export_of.get(q, ()):
                self.png.write(self.folder / f"frame_{i:05d}.png", u8[j])
                if self.hdr is not None:
                    self.hdr.write(i, part.log_intensity[j])
                if self.video:
                    self._video_frame(u8[j])
            g = self.gt_of.get(q)
            if g is not None:
                self.gt[g] = part.frames[j].copy()

    def _video_frame(self, img: np.ndarray) -> None:
        if self.mp4 is None:
            self.mp4 = _Mp4(self.staging / "reconstruction.mp4", self.video_fps, img.shape, self.log)
        self.mp4.write(img)
        if self.gif is not None:
            if (len(self.gif) + 1) * img.size > GIF_LIMIT_BYTES:
                self.log(f"note: the GIF is skipped ({self.n_times:,} frames of {img.shape[0]}x{img.shape[1]} would "
                         f"need over {GIF_LIMIT_BYTES >> 20} MB); the PNGs and the MP4 hold every frame")
                self.gif = None
            else:
                self.gif.append(img)

    def close(self) -> None:
        """Wait for every PNG and close log_intensity.h5; raises the first write's error, or the file's when a
        frame is missing from it."""
        self.png.close()
        if self.hdr is not None:
            self.hdr.close()

    def finish(self) -> list:
        """The video files, once the PNGs are all written (:meth:`close`); returns the names of every file
        written beside the PNGs."""
        from ..core.checks import check_result_frames
        from ..io.export import save_gif
        from ..method.solver import RESULT_FIX

        check_result_frames(np.array(self.range, np.float32)[:, None, None], what="EvINR's frames", input_varies=True,
                            fix=RESULT_FIX)
        written = [] if self.hdr is None else [self.hdr.path.name]
        if self.mp4 is not None and self.mp4.close():
            written.append("reconstruction.mp4")
        if self.gif:
            save_gif(self.staging / "reconstruction.gif", np.stack(self.gif), self.video_fps)
            written.append("reconstruction.gif")
        return written

    def abort(self) -> None:
        """Drop the PNGs not yet started and wait for the running ones: no thread writes into the staging
        folder once the run has failed or been interrupted (it is removed next)."""
        self.png.abort()
        if self.hdr is not None:
            self.hdr.abort()
        if self.mp4 is not None:
            self.mp4.close()

    def gt_frames(self) -> np.ndarray:
        return np.stack(self.gt)


class _Mp4:
    """An MP4 written frame by frame (OpenCV), as :func:`~evinr_lite.io.export.save_mp4` writes a stack."""

    def __init__(self, path: Path, fps: float, shape, log):
        import cv2

        H, W = shape
        self.pad = (H % 2, W % 2)   # most players need even sizes
        self.writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"mp4v"), float(fps),
                                      (W + self.pad[1], H + self.pad[0]), isColor=False)
        self.ok = self.writer.isOpened()
        if not self.ok:
            log(f"warning: OpenCV could not open an MP4 writer for {path}; the PNGs are still written")

    def write(self, img: np.ndarray) -> None:
        if self.ok:
            self.writer.write(np.pad(img, ((0, self.pad[0]), (0, self.pad[1]))))

    def close(self) -> bool:
        self.writer.release()
        return self.ok


def display_attrs(config) -> dict:
    """The tone map, gamma, display formula and anchor mode of an EvINRConfig (or its dict): the attributes of a
    ``log_intensity.h5`` (:class:`~evinr_lite.io.export.LogIntensityWriter`). An anchored config's frames are the
    APS frames' linear intensity whatever its tone map (:func:`evinr_lite.method.anchor.linear_frames`): "linear",
    with that formula (its own tone map's was written, one grey level off, or Eq. 12 for a Reinhard recipe), and
    ``anchor`` the mode, so a reader knows ``to_display(L, "linear")`` is not the frames."""
    from ..method.anchor import ANCHORED_DISPLAY
    from ..method.tonemap import display_formula

    get = config.get if isinstance(config, dict) else lambda name: getattr(config, name)
    if get("anchor") not in (None, "none"):
        return {"tonemap": "linear", "gamma": get("gamma"), "display": ANCHORED_DISPLAY, "anchor": get("anchor")}
    return {"tonemap": get("tonemap"), "gamma": get("gamma"), "display": display_formula(get("tonemap"), get("gamma")),
            "anchor": "none"}


def video_fps(times: np.ndarray) -> float:
    """Playback rate: the median spacing of the frames, kept between 2 and 60 frames per second."""
    if len(times) < 2:
        return 10.0
    step = float(np.median(np.diff(times)))
    return float(np.clip(1.0 / step, 2.0, 60.0)) if step > 0 else 10.0
