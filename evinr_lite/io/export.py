"""Writing reconstructed frames: numbered PNGs, an animated GIF (Pillow), an MP4 (OpenCV), and the
log intensity itself (HDF5, float32), which the 8-bit files clip.

Frames are grey float arrays [F, H, W] or colour (R, G, B) arrays [F, H, W, 3], in [0, 1] (or
uint8); colour frames give colour PNGs, GIF and MP4. These functions write into a folder
they are given; the reconstruct job hands them the temporary folder of
:func:`evinr_lite.io.output.atomic_output_dir`, so an interrupted export never looks complete.
"""
from __future__ import annotations

import csv
import os
import re
import shutil
from pathlib import Path

import numpy as np
from PIL import Image

from ..core.checks import check_image_values, choice, host_array, real_number, seconds_array
from ..core.events import EventDataError
from ..core.frames import Frames, to_uint8
from .output import CloseOrAbort, PngWriter, written_beside

__all__ = ["save_frames_png", "save_gif", "gif_delays_ms", "save_mp4", "save_timestamps", "save_csv", "LogIntensityWriter",
           "save_log_intensity", "read_log_intensity", "LOG_INTENSITY_FILE"]

LOG_INTENSITY_FILE = "log_intensity.h5"   # its name in a run folder


def _stack_uint8(frames) -> np.ndarray:
    """[F, H, W] or [F, H, W, 3] floats in [0, 1] (clipped) or uint8 -> uint8 of the same shape
    (:func:`~evinr_lite.core.frames.to_uint8`, after checking that it is a stack of frames)."""
    if isinstance(frames, Frames):
        frames = frames.images
    frames = np.asarray(frames)
    if not (frames.ndim == 3 or (frames.ndim == 4 and frames.shape[-1] == 3)):
        raise EventDataError(f"frames must have shape [F, H, W] (grey) or [F, H, W, 3] (colour), got {frames.shape}"
                             + ("; one image [H, W] is a stack of one: image[None]" if frames.ndim == 2 else ""))
    if frames.shape[0] == 0 or frames.size == 0:
        raise EventDataError(f"no frames to write (shape {frames.shape}); pass at least one frame")
    check_image_values(frames, "frames to write", clipped=True)   # uint8, or finite floats in [0, 1] (clipped)
    return to_uint8(frames)


def _output_file(path, suffix: str, what: str, *, any_suffix: bool = False) -> Path:
    """``path`` as a Path, checked before anything is encoded: a file name ending in ``suffix`` (the writers pick
    the format by it; ``any_suffix``: any name, ``suffix`` is only the example's), in a folder that exists, and not
    a folder itself; else EventDataError naming the fix."""
    if not isinstance(path, (str, Path)) and not hasattr(path, "__fspath__"):
        raise EventDataError(f"{what}: path must be a file name (str or Path), got {type(path).__name__}")
    path = Path(path).expanduser()
    if path.is_dir():
        raise EventDataError(f"{what}: {path} is a folder; pass a file name in it, e.g. {path / ('frames' + suffix)}")
    if not any_suffix and path.suffix.lower() != suffix:
        raise EventDataError(f"{what}: {path} does not end in {suffix} (the file's format follows its name); name it "
                             f"{path.with_name(path.name + suffix) if not path.suffix else path.with_suffix(suffix)}")
    if not path.parent.is_dir():
        raise EventDataError(f"{what}: the folder {path.parent} does not exist (or is a file); create it first "
                             f"(Path({str(path.parent)!r}).mkdir(parents=True)) or write elsewhere")
    return path


def _frame_files(folder: Path, prefix: str) -> list[Path]:
    """The numbered frames ``<prefix>NNNNN.png`` in ``folder`` (as save_frames_png names them)."""
    pattern = re.compile(re.escape(prefix) + r"\d{5}\.png")
    return sorted(p for p in folder.iterdir() if pattern.fullmatch(p.name)) if folder.is_dir() else []


def save_frames_png(folder, frames, prefix: str = "frame_", *, overwrite: bool = False) -> list[Path]:
    """Write frames [F, H, W] or [F, H, W, 3] as ``folder/<prefix>00000.png``, ... (8-bit grey or RGB).
    Returns the paths.

    A new folder is written beside and renamed into place when every frame is written (a failed write leaves
    none). Frames named ``<prefix>NNNNN.png`` already in the folder are refused (the new ones would mix with
    those beyond their count), unless ``overwrite``: then they are replaced, and those beyond the new count
    removed."""
    if not isinstance(prefix, str) or "/" in prefix or "\\" in prefix or "\0" in prefix:
        raise EventDataError(f"prefix must be the start of a file name, without a folder ('/'), got {prefix!r}; "
                             "put the folder in folder= (e.g. save_frames_png('out/frames', frames, prefix='f_'))")
    folder = Path(folder).expanduser()
    if folder.exists() and not folder.is_dir():
        raise EventDataError(f"{folder} is a file, not a folder; pass the folder to write the PNGs into (a new one "
                             "is created)")
    images = _stack_uint8(frames)     # checked before anything is created
    old = _frame_files(folder, prefix)
    if old and not overwrite:
        raise EventDataError(f"{folder} already holds {len(old)} frame(s) named {prefix}NNNNN.png ({old[0].name} "
                             f"..); the {len(images)} new ones would mix with them: write into a new folder, or pass "
                             "overwrite=True to replace them")
    new_folder = not folder.exists()
    if new_folder:
        folder.parent.mkdir(parents=True, exist_ok=True)
    target = folder.with_name(f".{folder.name}.partial-{os.getpid()}") if new_folder else folder
    paths = [folder / f"{prefix}{i:05d}.png" for i in range(len(images))]
    try:
        target.mkdir(exist_ok=not new_folder)
        with PngWriter() as png:          # encoded on the kit's threads; the same bytes as save_png in turn
            for path, img in zip(paths, images):
                png.write(target / path.name, img)
        if new_folder:
            os.replace(target, folder)   # a new folder: no other is there to replace
    except BaseException:
        if new_folder:
            shutil.rmtree(target, ignore_errors=True)
        raise
    for stale in old[len(images):]:   # overwrite: the old frames beyond the new count would pass for new ones
        stale.unlink(missing_ok=True)
    return paths


VIDEO_FPS = (0.01, 65535.0)   # frames per second a video file can state: MPEG-4's time base (and a GIF's delay)


def _check_fps(fps) -> None:
    if isinstance(fps, (bool, np.bool_, str, bytes)) or not (np.isscalar(fps) and np.isfinite(fps) and fps > 0):
        raise EventDataError(f"fps must be positive: a finite number of frames per second (e.g. 10), got {fps!r}")
    lo, hi = VIDEO_FPS
    if not lo <= fps <= hi:   # beyond them OpenCV fails (or libavcodec aborts the process), Pillow overflows
        raise EventDataError(f"fps={fps!r} is beyond what a video file can state ({lo} to {hi:.0f} frames per "
                             "second); it is the playback rate, not the rate the frames were reconstructed at: "
                             "pass a rate to watch, e.g. 10 (or 30)")


def save_gif(path, frames, fps: float) -> Path:
    """An animated GIF of frames [F, H, W] (grey) or [F, H, W, 3] (colour) at ``fps`` frames per second (at most 50
    per second), looping. GIF delays are whole hundredths of a second, so frame k starts at round(100 k / fps)
    hundredths: the delays alternate (30 per second: 30, 30, 40 ms, ...) and the whole lasts F / fps seconds to
    10 ms, where one rounded delay (30 ms) made it 10 % short. Above 50 per second every frame is shown 20 ms: the
    GIF plays at 50 per second, F x 20 ms, longer than F / fps (every frame is kept). Pillow merges a frame identical to the one before
    into it (their delays add up), so the file can hold fewer frames than ``frames``, never another duration."""
    _check_fps(fps)
    path = _output_file(path, ".gif", "save_gif")
    images = [Image.fromarray(img) for img in _stack_uint8(frames)]
    with written_beside(path) as tmp:
        images[0].save(tmp, save_all=True, append_images=images[1:], duration=gif_delays_ms(len(images), fps), loop=0)
    return Path(path)


def gif_delays_ms(n_frames: int, fps: float) -> list[int]:
    """The delays (ms, multiples of 10) of ``n_frames`` GIF frames shown at ``fps`` per second: frame k starts at
    round(100 k / fps) hundredths of a second, so they add up to n_frames / fps to 10 ms; at least 20 ms each
    (browsers show shorter delays as 100 ms), so above 50 per second every delay is 20 ms and they add up to
    n_frames / 50 s, longer than n_frames / fps."""
    if fps > 50:
        return [20] * n_frames
    starts = np.floor(np.arange(n_frames + 1) * (100.0 / fps) + 0.5).astype(np.int64)
    return (10 * np.diff(starts)).tolist()


def save_mp4(path, frames, fps: float) -> Path:
    """An MP4 video (MPEG-4 part 2, 'mp4v') of frames [F, H, W] or [F, H, W, 3] (RGB) at ``fps`` per second.

    Odd widths or heights are padded by one black row / column (most players need even sizes).
    Raises RuntimeError when OpenCV cannot open a writer (an OpenCV build without video support).
    """
    import cv2

    _check_fps(fps)
    path = _output_file(path, ".mp4", "save_mp4")
    frames = _stack_uint8(frames)
    colour = frames.ndim == 4
    F, H, W = frames.shape[:3]
    frames = np.pad(frames, ((0, 0), (0, H % 2), (0, W % 2)) + (((0, 0),) if colour else ()))
    if colour:
        frames = np.ascontiguousarray(frames[..., ::-1])   # OpenCV writes BGR
    with written_beside(path) as tmp:
        writer = cv2.VideoWriter(str(tmp), cv2.VideoWriter_fourcc(*"mp4v"), float(fps),
                                 (frames.shape[2], frames.shape[1]), isColor=colour)
        if not writer.isOpened():
            raise RuntimeError(f"OpenCV could not open an MP4 writer for {path}; the GIF and PNGs are still written")
        try:
            for img in frames:
                writer.write(img)
        finally:
            writer.release()
    return Path(path)


def save_timestamps(path, times, t_origin: float = 0.0) -> Path:
    """One line per frame: `index t_seconds` (relative to t_origin), with a header comment."""
    times = seconds_array(times, "times", allow_empty=True)
    t_origin = real_number(t_origin, "t_origin", hint="seconds: the absolute time of t = 0 (0 when relative)")
    path = _output_file(path, ".txt", "save_timestamps", any_suffix=True)
    with written_beside(path) as tmp, open(tmp, "w") as f:
        f.write(f"# frame index, time in seconds relative to t_origin = {t_origin!r} s\n")
        for i, t in enumerate(times):
            f.write(f"{i} {t:.9f}\n")
    return path


def save_csv(path, rows: list[dict]) -> Path:
    """A CSV file with one row per dict (columns: the keys of the first row)."""
    if isinstance(rows, dict) or isinstance(rows, (str, bytes)) or not hasattr(rows, "__iter__"):
        raise EventDataError(f"rows must be a list of dicts (one per CSV row), got {type(rows).__name__}"
                             + ("; wrap one row in a list: [row]" if isinstance(rows, dict) else ""))
    rows = list(rows)
    if not rows:
        raise EventDataError("no rows to write; pass a list of one or more dicts")
    for i, r in enumerate(rows):
        if not isinstance(r, dict):
            raise EventDataError(f"rows[{i}] is a {type(r).__name__}, not a dict; every row is a dict of column: value")
        extra = [k for k in r if k not in rows[0]]
        if extra:
            raise EventDataError(f"rows[{i}] has column(s) {extra} that the first row lacks (the columns are the first "
                                 "row's keys); give every row the same keys")
    path = _output_file(path, ".csv", "save_csv", any_suffix=True)
    with written_beside(path) as tmp, open(tmp, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    return path


# ---- the log intensity, unclipped ---------------------------------------------------------------
# An event camera's reason to exist is its dynamic range: the reconstruction's log intensity spans
# whatever the scene did, while a PNG holds 256 levels of what the display shows, with every highlight
# above the display's white clipped. The HDF5 file keeps the float32 values, so a user can tone-map
# them again (another level, another curve) or feed them to their own pipeline.

TONEMAPS = ("linear", "reinhard")   # evinr_lite.method.tonemap.TONEMAPS (io sits below method; a test keeps them equal)
ANCHORS = ("none", "first", "all")   # evinr_lite.method.anchor.ANCHOR_MODES (likewise)


class LogIntensityWriter(CloseOrAbort):
    """An HDF5 file of log intensities written frame by frame (a streamed run's frames arrive in parts).

    Layout: ``log_intensity`` float32 [F, H, W] (or [F, H, W, 3] for colour), one chunk per frame,
    uncompressed (float noise barely compresses and a chunk per frame keeps the writes streaming);
    ``t`` float64 [F], seconds relative to the attribute ``t_origin``; attributes saying what the
    values are (``units``) and how the run's frames were drawn from them (``display``, ``tonemap``,
    ``gamma``, ``anchor``). Rows not yet written read as NaN, so a file closed early cannot pass for complete;
    :meth:`close` refuses one with rows missing, and :meth:`write` refuses NaN or infinite values (a written
    NaN frame would read as a missing one).

    Args:
        path: the file to create (inside a staging folder: the caller renames the folder into place).
        times: float64 [F] the frames' times (seconds on the events' clock, relative to ``t_origin``).
        frame_shape: (H, W) or (H, W, 3).
        t_origin: seconds, the absolute time of t = 0 (0 when relative).
        tonemap, gamma, display: the display the run used: ``tonemap`` one of :data:`TONEMAPS`, ``gamma`` a
            finite number > 0, ``display`` its formula in words (a str).
        anchor: the run's anchor mode, one of :data:`ANCHORS` ("none": events only). An anchored run's frames are
            ``evinr_lite.method.linear_frames(L)`` whatever ``tonemap`` says (the writer's "linear"), so a reader
            tells them apart by this attribute.
    """

    def __init__(self, path, times, frame_shape, *, t_origin: float = 0.0, tonemap: str = "linear",
                 gamma: float = 0.6, display: str = "", anchor: str = "none"):
        import h5py

        times = seconds_array(times, "times")
        t_origin = real_number(t_origin, "t_origin", hint="seconds: the absolute time of t = 0 (0 when relative)")
        tonemap = str(choice(tonemap, TONEMAPS, "tonemap"))   # np.str_ too (h5py stores no numpy text)
        anchor = str(choice(anchor, ANCHORS, "anchor"))
        gamma = real_number(gamma, "gamma", lo=0, lo_open=True, hint="the display's gamma (e.g. 0.6)")
        if not isinstance(display, str):
            raise EventDataError(f"display= must be a str (the display's formula in words), got "
                                 f"{type(display).__name__}; pass the formula as text, e.g. "
                                 "evinr_lite.method.tonemap.display_formula(tonemap, gamma)")
        frame_shape = tuple(int(v) for v in frame_shape)
        if len(frame_shape) not in (2, 3) or min(frame_shape) < 1 or (len(frame_shape) == 3 and frame_shape[2] != 3):
            raise EventDataError(f"frame_shape must be (H, W) or (H, W, 3), got {frame_shape}")
        self.path = Path(path)
        self.shape = (len(times), *frame_shape)
        self.done = np.zeros(len(times), bool)
        self.file = h5py.File(self.path, "w")
        try:
            self.data = self.file.create_dataset("log_intensity", shape=self.shape, dtype="float32",
                                                 chunks=(1, *frame_shape), fillvalue=np.nan)
            self.file.create_dataset("t", data=times)
            self.file.attrs.update({
                "units": "natural log of intensity; events fix it up to one constant per recording, which the "
                         "display's level set (docs/defaults.md, 'The display')",
                "t_units": "seconds relative to t_origin", "t_origin": t_origin, "tonemap": tonemap,
                "gamma": float(gamma), "display": display, "anchor": anchor, "writer": "evinr-lite"})
        except BaseException:
            self.file.close()
            raise

    def write(self, i: int, image) -> None:
        """Frame ``i`` (0-based, in the order of ``times``): an array of ``frame_shape``."""
        with np.errstate(over="ignore"):   # past float32's range: inf, refused below
            image = np.asarray(host_array(image), np.float32)
        if image.shape != self.shape[1:]:
            raise EventDataError(f"frame {i} has shape {image.shape}, expected {self.shape[1:]}")
        if not np.isfinite(image).all():   # unwritten rows read as NaN: a NaN frame would pass for a missing one
            raise EventDataError(f"frame {i} holds NaN or infinite log intensities (as float32); a log intensity "
                                 "must be finite: repair or drop that frame")
        self.data[i] = image
        self.done[i] = True

    def close(self) -> None:
        """Close the file; EventDataError when a frame was never written (the file is then incomplete)."""
        if self.file.id.valid:
            self.file.close()
        if not self.done.all():
            missing = np.flatnonzero(~self.done)
            raise EventDataError(f"{self.path}: {missing.size} of {self.done.size} frames were never written (first: "
                                 f"{int(missing[0])}); the file is incomplete")

    def abort(self) -> None:
        """Close the file without the completeness check (a failed or interrupted run; its folder goes)."""
        if self.file.id.valid:
            self.file.close()


def save_log_intensity(path, log_intensity, times, **kw) -> Path:
    """Write log intensities [F, H, W] (or [F, H, W, 3]) at ``times`` [F] (s) as one HDF5 file
    (:class:`LogIntensityWriter`'s layout; keywords: its t_origin, tonemap, gamma, display, anchor). The values must be
    finite numbers (as float32): all are checked before the file is created."""
    L = np.asarray(host_array(log_intensity))
    if L.ndim not in (3, 4) or L.shape[0] != len(np.atleast_1d(times)):
        raise EventDataError(f"log_intensity must be [F, H, W] or [F, H, W, 3] with one frame per time, got shape "
                             f"{L.shape} for {len(np.atleast_1d(times))} time(s)")
    if L.dtype.kind not in "iuf":
        raise EventDataError(f"log_intensity must be numbers (float32 log intensities), got dtype {L.dtype}")
    for i, img in enumerate(L):   # a frame at a time: no float32 copy of the whole stack
        with np.errstate(over="ignore"):   # 1e39 becomes inf as float32: refused below
            finite = np.isfinite(img.astype(np.float32, copy=False)).all()
        if not finite:
            raise EventDataError(f"log_intensity[{i}] holds NaN or infinite values (as float32); a log intensity "
                                 "must be finite: repair or drop that frame (nothing was written)")
    path = _output_file(path, ".h5", "save_log_intensity", any_suffix=True)
    with written_beside(path) as tmp, LogIntensityWriter(tmp, times, L.shape[1:], **kw) as out:
        for i, img in enumerate(L):
            out.write(i, img)
    return path


def read_log_intensity(path, frames=None) -> tuple[np.ndarray, np.ndarray, dict]:
    """(log intensity float32 [F, H, W] or [F, H, W, 3], times float64 [F] s, attributes) of a file
    :class:`LogIntensityWriter` wrote (``evinr-lite reconstruct --save-log``: ``log_intensity.h5``).

    ``frames``: which frames to read (None: all; a slice, e.g. ``slice(0, 100)``, or an index): only
    those are read from disk, so a long HD run's file (110 MB a second at 1280x720 and 30 frames per
    second) can be read a part at a time. ``attrs["display"]`` names the formula that drew the run's frames:

    - an anchored run (``--anchor first|all``; ``attrs["anchor"]`` is "first" or "all"): the APS frames'
      intensity ``clip(exp(L) - 1/255, 0, 1)``, i.e. ``evinr_lite.method.linear_frames(L)``, whatever
      ``attrs["tonemap"]`` says ("linear": ``to_display(L, "linear")`` is one grey level off there);
    - otherwise (``attrs["anchor"] == "none"``): ``evinr_lite.method.tonemap.to_display(L, attrs["tonemap"],
      attrs["gamma"])``: ``clip(exp(L), 0, 1)`` for "linear" (the kit's display), ``sigmoid(L) ** gamma`` for
      "reinhard".

    A file written before the ``anchor`` attribute existed reads with ``attrs["anchor"] = None`` (not recorded;
    an anchored run's file of then also named another ``display``: use ``linear_frames`` if the run was anchored).
    """
    import h5py

    if frames is None:
        frames = slice(None)
    if isinstance(frames, (bool, np.bool_)) or not isinstance(frames, (slice, int, np.integer)):
        raise EventDataError(f"frames= must be None, a slice or an index, got {frames!r}")
    try:
        with h5py.File(path, "r") as f:
            if "log_intensity" not in f or "t" not in f:
                raise EventDataError(f"{path}: not a log-intensity file (no 'log_intensity' and 't' datasets); it is "
                                     "written by `evinr-lite reconstruct --save-log` as log_intensity.h5")
            n = f["t"].shape[0]
            if not isinstance(frames, slice) and not -n <= int(frames) < n:
                raise EventDataError(f"{path}: frame {int(frames)} does not exist; the file holds {n} frames")
            attrs = dict(f.attrs)
            attrs.setdefault("anchor", None)   # files from before the attribute: not recorded
            return f["log_intensity"][frames], f["t"][frames], attrs
    except OSError as err:
        raise EventDataError(f"{path}: cannot be read as HDF5 ({err}); pass the log_intensity.h5 of a run folder") from None
