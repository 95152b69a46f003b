"""The options of a run, spelled once: :class:`RunOptions` for ``evinr-lite reconstruct`` / ``batch``,
:func:`~evinr_lite.apps.recon_job.run_reconstruct` and :func:`~evinr_lite.apps.batch.run_batch`, and
:func:`parse_times`, the one reader of a list of times (``--at``).

    options = RunOptions(C=0.2, fps=30, t_start=1.0, t_end=2.5)   # every option checked here, once
    run_reconstruct("rec.h5", "out", options)                      # or run_reconstruct("rec.h5", "out", C=0.2, ...)
    options.config(C)                                              # the EvINRConfig of its recipe

Times are seconds on the recording's clock; sensor sizes (H, W).
"""
from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..core.checks import choice
from ..core.events import TIME_UNITS, EventDataError
from ..method.anchor import ANCHOR_MODES
from ..method.tempo import MIN_SCALE, SCALE_RANGE, scale_floor_message
from ..core.recording import Recording
from ..io.formats.mvsec import CAMERAS
from ..io.text import MAX_CLOCK_S
from ..method.config import EvINRConfig
from ..method.memory import check_times_memory
from ..method.recipes import RECIPES, contrast_option, recipe_config
from ..method.tonemap import TONEMAPS

__all__ = ["RunOptions", "parse_times", "choose_times", "check_run_options", "lam_option", "temporal_scale_option",
           "BATCH_FIELDS", "DEFAULT_FPS"]

DEFAULT_FPS = 30.0      # frames per second when neither times nor ground-truth frames are given
DISPLAY_MEAN_RANGE = (0.01, 0.99)   # --display-mean: beyond it the frames clip to black or white (a mean of
                                    # 0.999999 left every pixel at 1, refused as constant frames)

# the options a batch takes (each recording's window and times are its own), as batch.json stores them
BATCH_FIELDS = ("C", "fps", "n_iters", "recipe", "seed", "device", "video", "sensor_size", "denoise", "anchor", "tonemap",
                "keep_background", "static_camera", "lam", "temporal_scale", "save_log", "display_mean")
MAX_PATH_CHARS = 255   # longer text is never a file name (most file systems' limit for one name)
_INDEX_TIME = re.compile(r"\s*(\d+)\s+(\S+)\s*")   # one line of timestamps.txt: `index time`


def _time_tokens(text: str) -> list[str]:
    """The time tokens of a text: lines (blank ones and '#' comments skipped), each split at commas
    and white space. The table evinr-lite writes (timestamps.txt: `index time` lines with indexes
    0, 1, 2, ...) gives its time column: recognised by its header comment, or by two or more lines
    whose first fields count 0, 1, 2, ...; any other text gives every number in it."""
    lines = text.splitlines()
    header = any(line.lstrip().startswith("# frame index") for line in lines)
    data = [line for line in lines if line.strip() and not line.lstrip().startswith("#")]
    rows = [_INDEX_TIME.fullmatch(line) for line in data]
    if data and all(rows) and [int(r.group(1)) for r in rows] == list(range(len(rows))) and \
            (header or len(rows) >= 2):
        return [r.group(2) for r in rows]
    return [tok for line in data for tok in line.replace(",", " ").split()]


def _first_non_number(tokens):
    """The first of ``tokens`` (a list of texts or values) that float() refuses, or None."""
    if not isinstance(tokens, (list, tuple)):
        return None
    for tok in tokens:
        try:
            float(tok)
        except (ValueError, TypeError):
            return tok
    return None


def _times_file(at) -> Path | None:
    """``at`` as the path of a file of times, or None when it is a list written out in text."""
    if isinstance(at, Path):
        if not at.exists():
            raise EventDataError(f"at={str(at)!r}: no such file of times; check the path")
    elif not isinstance(at, str) or not at.strip() or len(at) > MAX_PATH_CHARS or "\n" in at:
        return None
    try:
        path = Path(at)
        is_dir, is_file = path.is_dir(), path.is_file()
    except (OSError, ValueError):   # not a possible file name (too long, a NUL byte): a list
        return None
    if is_dir:
        raise EventDataError(f"at={str(at)!r} is a folder; give a file with the times (seconds, one per line or "
                             "separated by commas) or the times themselves (e.g. 0.5,0.75,1.0)")
    return path if is_file else None


def parse_times(at) -> np.ndarray:
    """Sorted float64 [Q] seconds from an array, a list, text ('0.1,0.2' or '0.1 0.2') or a text file.

    The one reader of ``--at``: a file and the command line give the same times for the same text
    (``0.1, 0.2, 0.3, 0.4`` is four times on one line of a file as on the command line; a file may
    also hold one time per line, '#' comments, or evinr-lite's own timestamps.txt). Text longer
    than 255 characters is never taken for a file name.

    Raises:
        EventDataError: text that is not numbers, a file that is not UTF-8 text, a folder, no time,
            or a time that is not finite.
    """
    path = _times_file(at)
    given = at
    if path is not None:
        try:
            text = path.read_bytes().decode("utf-8-sig")
        except UnicodeDecodeError as err:
            raise EventDataError(f"{at}: not UTF-8 text (byte {err.start}); save the times as plain text, one number "
                                 "of seconds per line") from None
        at = _time_tokens(text)
    elif isinstance(at, str):
        at = _time_tokens(at)
    try:
        times = np.atleast_1d(np.asarray(at, dtype=np.float64))
    except (ValueError, TypeError):
        bad = _first_non_number(at)
        where = f"the file {str(path)!r}" if path is not None else f"at={given!r}"
        what = "" if bad is None else f" ({bad!r} is not a number of seconds" + \
            ("; a header line? remove it or start it with #)" if path is not None else ")")
        raise EventDataError(f"could not read times from {where}{what}; give seconds separated by commas "
                             "(e.g. 0.5,0.75,1.0) or a file with one time per line") from None
    if times.ndim != 1:
        raise EventDataError(f"at= must be a flat list of seconds, got an array of shape {times.shape}")
    if times.size == 0 or not np.all(np.isfinite(times)):
        raise EventDataError("at=: give at least one finite time in seconds")
    return np.sort(times)


def lam_option(value) -> float | str:
    """``lam=`` checked: "auto" or a finite number >= 0 (as a float); EventDataError naming the fix."""
    if isinstance(value, str) and value.strip().lower() == "auto":
        return "auto"
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not math.isfinite(value) or value < 0:
        raise EventDataError(f"lam= must be 'auto' (chosen from the events) or a number >= 0 (e.g. 0.01; more "
                             f"smooths more), got {value!r}")
    return float(value)


def temporal_scale_option(value) -> float | str:
    """``temporal_scale=`` checked: "auto" or a finite number >= tempo.MIN_SCALE (as a float); EventDataError naming
    the fix."""
    if isinstance(value, str) and value.strip().lower() == "auto":
        return "auto"
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) \
            or not math.isfinite(value) or value <= 0:
        raise EventDataError(f"temporal_scale= must be 'auto' (read from the events) or {SCALE_RANGE} (1: the "
                             f"recipe's bins and temporal prior as they are; 2: bins half as long), got {value!r}")
    if value < MIN_SCALE:
        raise EventDataError(scale_floor_message("temporal_scale", value))
    return float(value)


def _finite(name: str, value) -> float | None:
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) or not math.isfinite(value):
        raise EventDataError(f"{name} must be a finite number, got {value!r}")
    return float(value)


def _flag(name: str, value) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise EventDataError(f"{name}= must be True or False, got {value!r}")
    return bool(value)


@dataclass(frozen=True, eq=False)
class RunOptions:
    """Every option of one reconstruction run, checked on construction (EventDataError naming it).

    Attributes:
        sensor_size: (H, W) for formats that do not record it; else checked against the file's.
        C: the contrast threshold: None (the file's, else :data:`~evinr_lite.method.recipes.DEFAULT_C`),
            a positive number, a pair (c_pos, c_neg), or "auto" (fitted from the APS frames).
        fps: frames per second over the window; at: explicit times (see :func:`parse_times`; kept
            as the parsed float64 [Q] seconds). Neither: the ground-truth frame times, else 30 per second.
        t_start, t_end: the window, seconds on the recording's clock (None: the events' first / last).
        time_unit: the unit of integer or text timestamps ('s', 'ms', 'us', 'ns'; None: detected).
        camera: 'left' or 'right': which camera of an MVSEC stereo file (None: its left one, or the one it
            has); refused for formats with one camera, and by a batch.
        device: "cpu", "cuda" or None (a GPU when present; checked when the run starts).
        recipe: "kit", "paper" or "v0_1" (:mod:`evinr_lite.method.recipes`); n_iters: its Adam
            iterations (None: the recipe's own); seed: seeds the networks.
        anchor: "none", "first" or "all" (:mod:`evinr_lite.method.anchor`); denoise: denoise the
            window's events first; colour: one EvINR per colour channel (not with an anchor).
        keep_background: train on every event, skipping the kit recipe's background-activity filter
            (``EvINRConfig(background="keep")``; paper and v0_1 keep every event anyway): for sparse
            recordings whose isolated events are signal.
        static_camera: the camera stood still (a tripod): ``EvINRConfig(camera="static")``, the offset
            solved from the frames where something moved over each pixel, so the background an object
            passed over is recovered (kit recipe; ``python benchmarks/static_camera.py``).
        lam: the spatial regularizer's weight (``EvINRConfig.lam``): None (the recipe's own: "auto" for kit,
            chosen from the events' activity; 0.05 for paper and v0_1), "auto", or a number >= 0. More
            smoothing for a recording with heavy background activity (docs/defaults.md, "Stress scenes": 2 Hz of
            background activity wants about 0.1), less for a busy, clean one.
        temporal_scale: the bins' and the temporal prior's scale (``EvINRConfig.temporal_scale``): None (the
            recipe's own: "auto" for kit, read from how often the pixels reverse polarity, 1 unless the scene moves
            fast; 1 for paper and v0_1), "auto", or a number > 0 (bins bin_duration / s, a prior s times faster).
        tonemap: how the frames are shown: None (the recipe's own: linear for kit, the paper's Eq. 12 for
            paper and v0_1), "linear" or "reinhard", each at its own level (:mod:`evinr_lite.method.tonemap`).
        display_mean: the frames' mean brightness over the window, in [0.01, 0.99]: the level events never give
            (``EvINRConfig.display_mean``; None: the tone map's own, 0.4 for linear, 0.5 for reinhard). Lower
            for a dark scene, higher for a bright one; refused with an anchor, whose APS frames give the level.
        video: also write MP4 / GIF; progress: show a progress bar.
        save_log: also write the frames' log intensity, unclipped, as float32 (``log_intensity.h5``,
            :func:`evinr_lite.io.export.read_log_intensity`): the dynamic range the 8-bit PNGs clip.
    """

    sensor_size: tuple | None = None
    C: float | tuple | str | None = None
    fps: float | None = None
    at: np.ndarray | None = None
    t_start: float | None = None
    t_end: float | None = None
    time_unit: str | None = None
    camera: str | None = None
    device: str | None = None
    recipe: str = "kit"
    n_iters: int | None = None
    seed: int = 0
    anchor: str = "none"
    denoise: bool = False
    keep_background: bool = False
    static_camera: bool = False
    colour: bool = False
    lam: float | str | None = None
    temporal_scale: float | str | None = None
    tonemap: str | None = None
    display_mean: float | None = None
    video: bool = True
    progress: bool = True
    save_log: bool = False

    def __post_init__(self):
        checked = {"C": contrast_option(self.C)}
        if self.tonemap is not None:   # arrays were numpy's "truth value ... is ambiguous", lists "unhashable type"
            choice(self.tonemap, TONEMAPS, "tonemap=", hint="or None: the recipe's own")
        choice(self.anchor, ANCHOR_MODES, "anchor=")
        if self.fps is not None and self.at is not None:
            raise EventDataError("give either fps= or at=, not both")
        if _finite("fps=", self.fps) is not None and not self.fps > 0:
            raise EventDataError(f"fps= must be a positive number of frames per second, got {self.fps}")
        checked.update(fps=_finite("fps=", self.fps), t_start=_finite("t_start=", self.t_start),
                       t_end=_finite("t_end=", self.t_end))
        for name in ("t_start", "t_end"):   # 1e308 would overflow the frame count (an internal error), not be refused
            if checked[name] is not None and abs(checked[name]) > MAX_CLOCK_S:
                raise EventDataError(f"{name}={getattr(self, name)!r} s is beyond any recording's clock (over "
                                     f"{MAX_CLOCK_S:.3g} s, 285 million years); give seconds on the recording's clock, "
                                     "as `evinr-lite info` prints its span (or leave it out: the whole recording)")
        if self.t_start is not None and self.t_end is not None and not self.t_end > self.t_start:
            raise EventDataError(f"time window [{self.t_start}, {self.t_end}) is empty or reversed; t_end= must "
                                 "exceed t_start=")
        if self.at is not None:
            times = parse_times(self.at)
            times.flags.writeable = False
            checked["at"] = times
        if self.n_iters is not None and (isinstance(self.n_iters, bool) or
                                         not isinstance(self.n_iters, (int, np.integer)) or self.n_iters < 1):
            raise EventDataError(f"n_iters= must be a whole number of at least 1 (or None: the recipe's own), "
                                 f"got {self.n_iters!r}")
        choice(self.recipe, tuple(RECIPES), "recipe=")
        if isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) or not 0 <= self.seed < 2**63:
            raise EventDataError(f"seed must be a whole number in [0, 2**63), got {self.seed!r}")
        if self.camera is not None:
            choice(self.camera, CAMERAS, "camera=", hint="an MVSEC stereo file's cameras")
        if self.time_unit is not None:
            choice(self.time_unit, TIME_UNITS, "time_unit=")
        if self.device is not None and not isinstance(self.device, str):
            raise EventDataError(f"device= must be 'cpu', 'cuda' or None (a GPU when present), got {self.device!r}")
        if self.sensor_size is not None:
            size = tuple(self.sensor_size) if isinstance(self.sensor_size, (tuple, list, np.ndarray)) else ()
            if len(size) != 2 or not all(isinstance(v, (int, np.integer)) and not isinstance(v, bool) and v > 0
                                         for v in size):
                raise EventDataError(f"sensor_size=(H, W) must be two positive whole numbers, got {self.sensor_size!r}")
            checked["sensor_size"] = (int(size[0]), int(size[1]))
        for name in ("denoise", "keep_background", "static_camera", "colour", "video", "progress", "save_log"):
            checked[name] = _flag(name, getattr(self, name))
        if checked["static_camera"] and (self.recipe != "kit" or self.anchor != "none"):
            raise EventDataError(f"static_camera (--static-camera) changes the kit recipe's offset solve; the "
                                 f"{self.recipe!r} recipe with anchor={self.anchor!r} has none to change (the paper's "
                                 "recipes leave the offset to the regularizer, APS anchors set it): use recipe='kit' "
                                 "and anchor='none', or leave static_camera out")
        if self.anchor != "none" and checked["colour"]:
            raise EventDataError("anchored colour reconstruction is not supported; pass anchor='none' with colour")
        if self.lam is not None:
            checked["lam"] = lam_option(self.lam)
        if self.temporal_scale is not None:
            checked["temporal_scale"] = temporal_scale_option(self.temporal_scale)
        if self.display_mean is not None:
            level = _finite("display_mean=", self.display_mean)
            if not DISPLAY_MEAN_RANGE[0] <= level <= DISPLAY_MEAN_RANGE[1]:
                raise EventDataError(f"display_mean= is how bright the frames are, from {DISPLAY_MEAN_RANGE[0]} to "
                                     f"{DISPLAY_MEAN_RANGE[1]} (0.4 is the kit's; lower for a dark scene; beyond that "
                                     f"range every frame is black or white), got {self.display_mean!r}")
            if self.anchor != "none":
                raise EventDataError(f"display_mean= sets the level that events never give; with anchor="
                                     f"{self.anchor!r} the APS frames give it: leave display_mean out, or use "
                                     "anchor='none'")
            checked["display_mean"] = level
        if self.n_iters is not None:
            checked["n_iters"] = int(self.n_iters)
        checked["seed"] = int(self.seed)
        for name, value in checked.items():   # normalised values (a frozen dataclass: set once, here)
            object.__setattr__(self, name, value)

    @classmethod
    def of(cls, options: "RunOptions | None" = None, **fields) -> "RunOptions":
        """``options`` with ``fields`` replaced (checked again), or new options from ``fields``."""
        if options is None:
            return cls(**fields)
        if not isinstance(options, cls):
            raise EventDataError(f"options= must be a RunOptions, got {type(options).__name__}")
        return dataclasses.replace(options, **fields) if fields else options

    @classmethod
    def from_settings(cls, settings: dict, **fields) -> "RunOptions":
        """The options of a batch's settings (batch.json: BATCH_FIELDS, missing ones at their
        defaults; other keys ignored), with ``fields`` added."""
        return cls(**{k: settings[k] for k in BATCH_FIELDS if settings.get(k) is not None}, **fields)

    def check_batch(self) -> "RunOptions":
        """These options, refused (EventDataError) if they set one that a batch does not take."""
        own = [name for name in ("at", "t_start", "t_end", "time_unit", "camera") if getattr(self, name) is not None]
        own += ["colour"] if self.colour else []
        if own:
            raise EventDataError(f"a batch reconstructs each recording's own evaluation window at its frame times: "
                                 f"{', '.join(n + '=' for n in own)} cannot apply; leave them out")
        return self

    def config(self, C) -> EvINRConfig:
        """The EvINRConfig of this run's recipe with the resolved threshold ``C`` (a number or a pair).
        With ``denoise`` the events were filtered before (and reported), so the recipe's own background
        filter is not run a second time."""
        extra = {"background": "keep"} if self.denoise or self.keep_background else {}
        if self.static_camera:
            extra["camera"] = "static"
        if self.lam is not None:
            extra["lam"] = self.lam
        if self.temporal_scale is not None:
            extra["temporal_scale"] = self.temporal_scale
        if self.display_mean is not None:
            extra["display_mean"] = self.display_mean
        return recipe_config(self.recipe, self.n_iters, self.tonemap, C=C, seed=self.seed, device=self.device,
                             progress=self.progress, anchor=self.anchor, **extra)

    def to_dict(self, names=None) -> dict:
        """JSON-ready values of the named fields (all by default): pairs and sizes as lists."""
        names = [f.name for f in dataclasses.fields(self)] if names is None else names
        out = {}
        for name in names:
            value = getattr(self, name)
            out[name] = value.tolist() if isinstance(value, np.ndarray) else \
                list(value) if isinstance(value, tuple) else value
        return out


def check_run_options(**fields) -> RunOptions:
    """Every option of :func:`~evinr_lite.apps.recon_job.run_reconstruct` checked before any file is
    read: :class:`RunOptions` (EventDataError naming the option)."""
    return RunOptions(**fields)


def _times_hint(times: np.ndarray, lo: float, hi: float, t_origin: float) -> str:
    """Why times outside [lo, hi] may be so: given in ms / us / ns, or on the absolute clock (with t_origin)."""
    for unit, scale in (("milliseconds", 1e-3), ("microseconds", 1e-6), ("nanoseconds", 1e-9)):
        if np.all((times * scale >= lo) & (times * scale <= hi)):
            shown = ",".join(f"{v * scale:.9g}" for v in times[:3]) + ("..." if len(times) > 3 else "")
            return f"; they look like {unit}: the times are seconds, e.g. {shown}"
    if t_origin and np.all((times - t_origin >= lo) & (times - t_origin <= hi)):
        return (f"; they are on the recording's absolute clock: the times are seconds after t_origin = {t_origin!r} "
                "(see `evinr-lite info`), so subtract it")
    return ""


def choose_times(rec: Recording, *, fps: float | None = None, at=None, check=None) -> tuple[np.ndarray, str]:
    """The times to reconstruct and where they come from.

    Args:
        fps: frames per second over the window (the first half a frame period after its start).
        at: explicit times (array, '0.1,0.2' text, or a file: :func:`~evinr_lite.apps.options.parse_times`).
        Neither: the ground-truth frame times when the recording has frames, else DEFAULT_FPS.
        check: called with the number of frames an fps asks for before their times are built (a
            job's own memory or disk check, which raises EventDataError): a huge fps is refused at
            once instead of after building and sorting millions of times.
    Returns:
        (times float64 [Q] seconds, a short description of the choice).
    """
    if fps is not None and at is not None:
        raise EventDataError("give either fps= or at=, not both")
    lo, hi = rec.meta["window"]
    if at is not None:
        times = parse_times(at)
        outside = times[(times < lo) | (times > hi)]
        if outside.size:
            raise EventDataError(f"requested time {outside[0]} s is outside the reconstructed window "
                                 f"[{lo:.6f}, {hi:.6f}] s; choose times inside it (or widen t_start=/t_end=)"
                                 + _times_hint(times, lo, hi, rec.events.t_origin))
        return times, f"{len(times)} requested times"
    if fps is None and rec.frames is not None:
        inside = rec.frames.t[(rec.frames.t >= lo) & (rec.frames.t <= hi)]
        if inside.size:
            return inside.copy(), f"the {inside.size} ground-truth frame times"
    fps = DEFAULT_FPS if fps is None else float(fps)
    if not (math.isfinite(fps) and fps > 0):
        raise EventDataError(f"fps= must be a positive number of frames per second, got {fps}")
    n = int(math.floor((hi - lo) * fps))
    check_times_memory(n, rec.events.sensor_size, f"{n:,} frames at {fps:g} per second over [{lo:.6f}, {hi:.6f}] s")
    if check is not None:
        check(max(n, 1))
    times = lo + (np.arange(n) + 0.5) / fps if n >= 1 else np.array([0.5 * (lo + hi)])
    return times, f"{len(times)} frames at {fps:g} per second"
