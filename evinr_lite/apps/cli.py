"""The ``evinr-lite`` command (also ``python -m evinr_lite``).

    evinr-lite info RECORDING                 what a recording holds (format, sensor, events, frames)
    evinr-lite reconstruct RECORDING --out DIR [--sensor HxW] [--C C|C+,C-|auto] [--fps N | --at TIMES]
                                              [--start S] [--end S] [--device cpu|cuda] [--overwrite]
    evinr-lite demo [--out DIR]               the built-in synthetic scene, no download
    evinr-lite batch INPUTS... --out DIR [--scheduler ADDRESS | --workers N]
                                              every recording of INPUTS on Dask; a pooled table at the end

Exit status: 0 done; 2 bad input (``evinr-lite: error: ...``: missing or damaged file, unknown
format, wrong sensor size, empty window, a bad option, an output folder that exists or cannot be
written, not enough memory); 1 an internal error (a bug: rerun with ``--debug`` for the traceback);
128 + n after signal n: 130 Ctrl-C (SIGINT), 143 SIGTERM, 129 SIGHUP. An interrupted run leaves no
partial output and an existing output folder as it was.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import re
import sys

__all__ = ["main", "build_parser", "EXIT_ERROR", "EXIT_INTERNAL", "EXIT_INTERRUPTED"]

EXIT_ERROR = 2          # bad input
EXIT_INTERNAL = 1       # a bug: "internal error", --debug shows the traceback
EXIT_INTERRUPTED = 130  # 128 + SIGINT; SIGTERM gives 143, SIGHUP 129
TIME_UNIT_CHOICES = ("s", "ms", "us", "ns")


def _finite(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return value


def _positive(text: str) -> float:
    value = _finite(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be positive, got {text!r}")
    return value


def _level(text: str) -> float:
    """--display-mean: a number from 0.01 to 0.99 (options.DISPLAY_MEAN_RANGE, spelled here: no import at start)."""
    value = _finite(text)
    if not 0.01 <= value <= 0.99:
        raise argparse.ArgumentTypeError(f"must lie between 0.01 and 0.99 (how bright the frames are; 0.4 is the "
                                         f"kit's; beyond that every frame is black or white), got {text!r}")
    return value


def _contrast(text: str):
    """--C of reconstruct: a positive number, a pair "C+,C-" of positive numbers, or "auto"."""
    if text.strip().lower() == "auto":
        return "auto"
    if "," not in text:
        return _positive(text)
    parts = text.split(",")
    try:
        if len(parts) != 2:
            raise argparse.ArgumentTypeError("")
        return tuple(_positive(part) for part in parts)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"expected a positive number, a pair C+,C- of positive numbers (e.g. "
                                         f"0.22,0.18) or auto, got {text!r}") from None


def _auto_or(text: str, positive: bool, bound: str | None = None):
    """"auto", or a finite number >= 0 (> 0 when ``positive``): --lam and --temporal-scale (``bound``: the range in
    the message, when the caller checks more)."""
    bound = bound or ("> 0" if positive else ">= 0")
    if text.strip().lower() == "auto":
        return "auto"
    try:
        value = _finite(text)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"expected auto or a number {bound}, got {text!r}") from None
    if not (value > 0 if positive else value >= 0):
        raise argparse.ArgumentTypeError(f"must be auto or a number {bound}, got {text!r}")
    return value


def _lam(text: str):
    """--lam: "auto" or a number >= 0."""
    return _auto_or(text, positive=False)


def _count(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, got {text!r}")
    return value


def _seed(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if not 0 <= value < 2**63:
        raise argparse.ArgumentTypeError(f"must be in [0, 2**63), got {text!r}")
    return value


def _size(text: str) -> tuple[int, int]:
    try:
        h, w = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"size must be HxW (rows x columns), e.g. 120x160; got {text!r}") from None
    if h <= 0 or w <= 0:
        raise argparse.ArgumentTypeError(f"size must be positive, got {text!r}")
    from ..core.events import MAX_SENSOR_SIDE   # here: numpy only when --sensor is given

    if h > MAX_SENSOR_SIDE or w > MAX_SENSOR_SIDE:
        raise argparse.ArgumentTypeError(f"size {text!r} is larger than any event camera (at most {MAX_SENSOR_SIDE} "
                                         "per side)")
    return h, w


class _Parser(argparse.ArgumentParser):
    """argparse with errors in the command's one style: ``evinr-lite: error: ...`` (status 2)."""

    def error(self, message):
        self.exit(EXIT_ERROR, f"evinr-lite: error: {message} (see `{self.prog} --help`)\n")


RECIPE_CHOICES = ("kit", "paper", "v0_1")
RECIPE_HELP = ("the solver's recipe: kit (default; the closed-form output layer and the explicit per-pixel offset, "
               "chosen on the scene zoo), paper (the paper's recipe exactly), v0_1 (the kit's earlier default)")
TONEMAP_CHOICES = ("linear", "reinhard")          # method.tonemap.TONEMAPS, spelled here (no torch import at start)
TONEMAP_HELP = ("how frames are shown: linear (the intensity itself, clip(exp(F), 0, 1), the frames' mean at 0.4; "
                "the kit's) or reinhard (the paper's Eq. 12, (I / (I + 1))^0.6 with the mean log intensity at 0.5: "
                "compresses contrast and keeps the highlights of a high-dynamic-range scene on screen); "
                "default: the recipe's own")
STATIC_CAMERA_HELP = ("the camera stood still (a tripod) and things moved in front of it: solve each pixel's offset "
                      "from the frames where something moved over it, so the background an object passed over "
                      "appears (EvINRConfig(camera='static'); kit recipe, events only). Not for a moving camera")
KEEP_BACKGROUND_HELP = ("train on every event: skip the kit recipe's background-activity filter (an event is kept "
                        "when a neighbouring pixel fired one of the same polarity within a window the recipe chooses "
                        "from the events' share of noise, 50-400 ms, or every event is kept on a clean recording; "
                        "EvINRConfig.background); for sparse recordings whose isolated events are signal. paper and "
                        "v0_1 keep every event anyway")
SAVE_LOG_HELP = ("also write the frames' log intensity, unclipped, as float32 in log_intensity.h5 (4 bytes a pixel "
                 "a frame): the dynamic range the 8-bit PNGs clip, to tone-map again or to use as data")
DISPLAY_MEAN_HELP = ("how bright the frames are, from 0.01 to 0.99: the level events never give. linear: the frames' "
                     "mean over the window (default 0.4); reinhard: the value the mean log intensity is shown at "
                     "(default 0.5). Lower for a dark scene, higher for a bright one. Not with --anchor, whose APS "
                     "frames give the level")
CAMERA_CHOICES = ("left", "right")
CAMERA_HELP = ("which camera of an MVSEC stereo file (davis/left or davis/right; default: the left one, or the "
               "one the file has); other formats hold one camera")
LAM_HELP = ("the spatial regularizer's weight lambda: auto (the kit's: chosen from the events' activity) or a "
            "number >= 0; more smooths more (e.g. 0.03-0.1 for a recording with heavy background activity); "
            "default: the recipe's own (auto for kit, 0.05 for paper and v0_1)")
SCALE_HELP = ("how much shorter the event bins are, and faster the temporal prior, than the recipe's: auto (the "
              "kit's: 1 unless the pixels reverse polarity more than 2.5 times a second, as under a fast shake; at "
              "most 4) or a number from 1/64 up (1: the recipe's 1/32 s bins as they are); default: the recipe's own "
              "(auto for kit, 1 for paper and v0_1)")
ITERS_HELP = ("Adam iterations (default: the recipe's own: none for kit, whose output layer is solved in closed "
              "form; 300 for paper and v0_1, with coarse-to-fine at a third and two thirds)")


def _scale(text: str):
    """--temporal-scale: "auto" or a number > 0 (RunOptions refuses one below tempo.MIN_SCALE, naming the floor)."""
    return _auto_or(text, positive=True, bound="from 1/64 up")


def build_parser() -> argparse.ArgumentParser:
    from ..io.readers import SUPPORTED_FORMATS

    parser = _Parser(prog="evinr-lite", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--debug", action="store_true", help="show the traceback of an internal error")
    common = _Parser(add_help=False)
    common.add_argument("--debug", action="store_true", default=argparse.SUPPRESS,
                        help="show the traceback of an internal error")
    sub = parser.add_subparsers(dest="command", required=True)
    unit_help = ("unit of the timestamps for .npy, text, .csv, IJRR, EVREAL and HQF h5 recordings (default: the "
                 "unit a .csv header names; else integers are microseconds, with a note; decimals seconds)")

    info = sub.add_parser("info", help="what a recording holds: format, sensor size, events, frames",
                          description=f"Supported formats: {SUPPORTED_FORMATS}.", parents=[common])
    info.add_argument("recording", help="file or folder (format detected from content and name)")
    info.add_argument("--sensor", type=_size, help="sensor size HxW, for files that do not record it (.npy, "
                                                   "text without a header, .csv without %%geometry, DSEC .h5, "
                                                   "some Prophesee .raw)")
    info.add_argument("--json", action="store_true", help="print the description as JSON")
    info.add_argument("--time-unit", choices=TIME_UNIT_CHOICES, help=unit_help)
    info.add_argument("--camera", choices=CAMERA_CHOICES, help=CAMERA_HELP)

    rec = sub.add_parser("reconstruct", help="reconstruct frames from a recording with EvINR",
                         description="Reconstruct frames with EvINR and write PNGs, an MP4 and a GIF; when the "
                                     "recording has frames, score against them (metrics.json / metrics.csv). "
                                     f"Supported formats: {SUPPORTED_FORMATS}.", parents=[common])
    rec.add_argument("recording", help="file or folder (format detected from content and name)")
    rec.add_argument("--out", required=True, help="output folder (refused if it exists, unless --overwrite)")
    rec.add_argument("--sensor", type=_size, help="sensor size HxW (rows x columns), for files that do not "
                                                  "record it; checked against the file's otherwise")
    rec.add_argument("--C", type=_contrast, help="contrast threshold: a number, a pair C+,C- (e.g. 0.22,0.18) for ON "
                                                 "and OFF events, or auto (fit C+ and C- from the recording's APS "
                                                 "frames in the window; printed with its uncertainty, kept in "
                                                 "run.json); default: the file's, else 1 as in the paper")
    rec.add_argument("--time-unit", choices=TIME_UNIT_CHOICES, help=unit_help)
    rec.add_argument("--camera", choices=CAMERA_CHOICES, help=CAMERA_HELP)
    when = rec.add_mutually_exclusive_group()
    when.add_argument("--fps", type=_positive, help="reconstruct this many frames per second over the window")
    when.add_argument("--at", help="reconstruct at these times (seconds, comma-separated, or a file with "
                                   "one per line); default: the ground-truth frame times, else 30 per second")
    rec.add_argument("--start", type=_finite, help="window start, seconds on the recording's clock (see `info`)")
    rec.add_argument("--end", type=_finite, help="window end, seconds on the recording's clock (see `info`)")
    rec.add_argument("--device", choices=("cpu", "cuda"), help="where to train (default: a GPU when present)")
    rec.add_argument("--recipe", choices=RECIPE_CHOICES, default="kit", help=RECIPE_HELP)
    rec.add_argument("--tonemap", choices=TONEMAP_CHOICES, default=None, help=TONEMAP_HELP)
    rec.add_argument("--display-mean", type=_level, default=None, metavar="M", help=DISPLAY_MEAN_HELP)
    rec.add_argument("--iters", type=_count, default=None, help=ITERS_HELP)
    rec.add_argument("--lam", type=_lam, default=None, help=LAM_HELP)
    rec.add_argument("--temporal-scale", type=_scale, default=None, metavar="S", help=SCALE_HELP)
    rec.add_argument("--seed", type=_seed, default=0)
    rec.add_argument("--colour", action="store_true",
                     help="reconstruct in colour from a colour event camera (a recording with a 2x2 colour filter, "
                          "e.g. CED converted by data_fetch): one EvINR per channel, colour frames at half the "
                          "sensor's size; scored on grey, plus the chroma correlation against colour frames")
    rec.add_argument("--anchor", choices=("none", "first", "all"), default="none",
                     help="use the recording's APS frames as anchors (beyond the paper): none (default, events "
                          "only), first (the first frame in the window sets each pixel's offset; a static "
                          "background appears), all (every other frame is a soft anchor, the rest are scored); "
                          "anchor frames are not scored, run.json says which; output in the frames' intensity")
    rec.add_argument("--denoise", action="store_true",
                     help="remove hot pixels and background activity from the window's events before "
                          "reconstructing, for any recipe (evinr_lite.method.denoise defaults); run.json records "
                          "what was removed. The kit recipe filters them anyway, inside the method "
                          "(EvINRConfig.background), without the report")
    rec.add_argument("--keep-background", action="store_true", help=KEEP_BACKGROUND_HELP)
    rec.add_argument("--static-camera", action="store_true", help=STATIC_CAMERA_HELP)
    rec.add_argument("--no-video", action="store_true", help="write PNGs only (no MP4 / GIF)")
    rec.add_argument("--save-log", action="store_true", help=SAVE_LOG_HELP)
    rec.add_argument("--overwrite", action="store_true", help="replace --out if it exists")
    rec.add_argument("--resume", action="store_true",
                     help="continue a stopped run into the same --out from its last finished window (events-only "
                          "runs stream window by window and keep their state in .OUT.resume beside --out)")
    rec.add_argument("--quiet", action="store_true", help="no progress bar")

    demo = sub.add_parser("demo", help="reconstruct a built-in synthetic scene and score it (no download)",
                          parents=[common])
    demo.add_argument("--out", default="evinr_demo", help="output folder (default: evinr_demo)")
    demo.add_argument("--scene", default="camera", help="built-in scene: camera, astronaut, bar, ... (default: camera)")
    demo.add_argument("--size", type=_size, default=(120, 160), help="sensor size HxW (default: 120x160)")
    demo.add_argument("--duration", type=_positive, default=2.0, help="seconds of events (default: 2)")
    demo.add_argument("--C", type=_positive, default=0.2, help="contrast threshold (default: 0.2)")
    demo.add_argument("--frames", type=_count, default=8, help="number of frames to reconstruct (default: 8)")
    demo.add_argument("--recipe", choices=RECIPE_CHOICES, default="kit", help=RECIPE_HELP)
    demo.add_argument("--tonemap", choices=TONEMAP_CHOICES, default=None, help=TONEMAP_HELP)
    demo.add_argument("--iters", type=_count, default=None, help=ITERS_HELP)
    demo.add_argument("--seed", type=_seed, default=0)
    demo.add_argument("--overwrite", action="store_true", help="replace --out if it exists")

    batch = sub.add_parser("batch", help="reconstruct and score many recordings on Dask (one task each)",
                           description="Reconstruct and score every recording of INPUTS, one dask.distributed "
                                       "task each, into DIR/<name>/; a rerun skips finished recordings; at the end "
                                       "DIR/summary.json|csv|md pool the scores per dataset (frame-weighted, as "
                                       "EVREAL). See docs/batch.md for real clusters.")
    batch.add_argument("inputs", nargs="+", metavar="INPUT",
                       help="recordings, folders of recordings, or data_fetch names (ijrr, ijrr:slider_depth, "
                            "hqf:all) looked up in the cache folder ($EVINR_DATA)")
    batch.add_argument("--out", required=True, help="results folder (a rerun with the same settings resumes)")
    where = batch.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS", help="a running Dask scheduler, e.g. tcp://host:8786 "
                                                             "(its workers must see the inputs and --out)")
    where.add_argument("--workers", type=_count, help="worker processes of a LocalCluster on this machine "
                                                   "(default: one per CPU core, at most one per recording)")
    batch.add_argument("--torch-threads", type=_count, default=1, help="torch threads per task (default: 1)")
    batch.add_argument("--sensor", type=_size, help="sensor size HxW, for files that do not record it")
    batch.add_argument("--C", type=_contrast, help="contrast threshold: a number, a pair C+,C- or auto (fitted per "
                                                  "recording from its APS frames) (default: each file's, else 1)")
    batch.add_argument("--denoise", action="store_true", help="remove hot pixels and background activity first "
                                                              "(as reconstruct --denoise)")
    batch.add_argument("--keep-background", action="store_true", help=KEEP_BACKGROUND_HELP)
    batch.add_argument("--static-camera", action="store_true", help=STATIC_CAMERA_HELP)
    batch.add_argument("--anchor", choices=("none", "first", "all"), default="none",
                       help="use each recording's APS frames as anchors (as reconstruct --anchor; anchor frames "
                            "are not scored)")
    batch.add_argument("--fps", type=_positive, help="frames to write per second (default: the ground-truth frame "
                                                 "times); scores are always taken at the ground-truth frames")
    batch.add_argument("--device", choices=("cpu", "cuda"), help="where to train (default: a GPU when present)")
    batch.add_argument("--recipe", choices=RECIPE_CHOICES, default="kit", help=RECIPE_HELP)
    batch.add_argument("--tonemap", choices=TONEMAP_CHOICES, default=None, help=TONEMAP_HELP)
    batch.add_argument("--display-mean", type=_level, default=None, metavar="M", help=DISPLAY_MEAN_HELP)
    batch.add_argument("--iters", type=_count, default=None, help=ITERS_HELP)
    batch.add_argument("--lam", type=_lam, default=None, help=LAM_HELP)
    batch.add_argument("--temporal-scale", type=_scale, default=None, metavar="S", help=SCALE_HELP)
    batch.add_argument("--seed", type=_seed, default=0)
    batch.add_argument("--video", action="store_true", help="also write MP4 / GIF per recording")
    batch.add_argument("--save-log", action="store_true", help=SAVE_LOG_HELP)
    batch.add_argument("--quiet", action="store_true", help="no progress bar")
    return parser


def _info(args) -> None:
    from .describe import describe_recording, format_info, open_recording   # no torch: info needs none

    with open_recording(args.recording, sensor_size=args.sensor, time_unit=args.time_unit, camera=args.camera) as source:
        info = describe_recording(source)   # reads only what the format can tell cheaply (seconds on GB files)
    print(json.dumps(info, indent=2) if args.json else format_info(info))


def _run_options(args):
    """The RunOptions of reconstruct's or batch's flags: the one place a flag is matched to its option."""
    from .options import RunOptions

    video = not args.no_video if hasattr(args, "no_video") else args.video   # reconstruct writes video by default
    return RunOptions(sensor_size=args.sensor, C=args.C, fps=args.fps, at=getattr(args, "at", None),
                      t_start=getattr(args, "start", None), t_end=getattr(args, "end", None),
                      time_unit=getattr(args, "time_unit", None), camera=getattr(args, "camera", None),
                      device=args.device, recipe=args.recipe,
                      n_iters=args.iters, seed=args.seed, anchor=args.anchor, denoise=args.denoise,
                      keep_background=args.keep_background, static_camera=args.static_camera,
                      colour=getattr(args, "colour", False), lam=args.lam, temporal_scale=args.temporal_scale,
                      tonemap=args.tonemap,
                      display_mean=args.display_mean, video=video,
                      progress=not args.quiet, save_log=args.save_log)


def _reconstruct(args) -> None:
    from .recon_job import run_reconstruct

    run_reconstruct(args.recording, args.out, _run_options(args), overwrite=args.overwrite, resume=args.resume,
                    command=" ".join(["evinr-lite", *sys.argv[1:]]))


def _demo(args) -> None:
    from .demo import run_demo
    from ..method.recipes import recipe_config

    config = recipe_config(args.recipe, args.iters, args.tonemap, C=args.C, seed=args.seed)
    run_demo(args.out, scene=args.scene, sensor_size=args.size, duration=args.duration, C=args.C,
             n_frames=args.frames, seed=args.seed, overwrite=args.overwrite, config=config)


def _batch(args) -> None:
    from .batch import run_batch
    from ..core.events import EventDataError

    try:
        summary = run_batch(args.inputs, args.out, _run_options(args), scheduler=args.scheduler,
                            workers=args.workers, torch_threads=args.torch_threads)
    except KeyboardInterrupt as exc:   # finished recordings stay: the same command resumes
        exc.output_note = f"finished recordings stay in {args.out}/; run the same command again to resume"
        raise
    if summary["failed"] and len(summary["failed"]) == len(summary["recordings"]):
        raise EventDataError(f"every recording failed; see {args.out}/summary.md")


# Library errors name Python parameters; on the command line the same advice names the flags.
FLAG_FOR = [
    # advice already naming both spellings ("fps=/--fps", "t_start=/t_end= (--start/--end)") keeps the flag only
    (re.compile(r"\bt_start=/t_end= \(--start/--end\)"), "--start/--end"),
    (re.compile(r"\b\w+=/(--[\w-]+)"), r"\1"),
    (re.compile(r"sensor_size=\((\d+), (\d+)\)"), r"--sensor \1x\2"),
    (re.compile(r"sensor_size=\(H, W\)"), "--sensor HxW"),
    (re.compile(r"\bsensor_size="), "--sensor "),
    (re.compile(r"\bt_start=/t_end="), "--start/--end"),
    (re.compile(r"\boverwrite=True"), "--overwrite"),
    (re.compile(r"\bdevice='(\w+)'"), r"--device \1"),
    (re.compile(r"(--device \w+) \(or None: a GPU when present\)"), r"\1 (or leave --device out: a GPU when present)"),
    (re.compile(r"\btime_unit='(\w+)'"), r"--time-unit \1"),
    (re.compile(r"\bcamera='(left|right)'"), r"--camera \1"),
    (re.compile(r"\bleave camera= out"), "leave --camera out"),
    (re.compile(r"\banchor='(\w+)'"), r"--anchor \1"),
    (re.compile(r"\bEvINRConfig\(background='keep'\)"), "--keep-background"),
    (re.compile(r"\bstatic_camera \(--static-camera\)"), "--static-camera"),
    (re.compile(r"\bleave static_camera out"), "leave --static-camera out"),
    (re.compile(r"\brecipe='(\w+)'"), r"--recipe \1"),
    # solver settings with no flag: the command line keeps the advice it can follow
    (re.compile(r",? or pass offset_coarse_px=None or offset_solve=\"median_gradient\""), ""),
    (re.compile(r"use a longer bin_duration, a shorter tau or fewer hidden_features, or "), ""),
    (re.compile(r" or use a longer bin_duration"), ""),
    (re.compile(r"\btemporal_scale=1\b"), "--temporal-scale 1"),
    (re.compile(r"\btemporal_scale=(?=[\d.])"), "--temporal-scale "),
    (re.compile(r"\b(t_start|t_end|n_iters|out_dir|fps|at|C|time_unit)=(?=[\w'\"(.+-])"),
     lambda m: FLAGS[m.group(1)] + " "),
    (re.compile(r"\b(t_start|t_end|n_iters|out_dir|fps|at|C|time_unit)="), lambda m: FLAGS[m.group(1)]),
]
FLAGS = {"t_start": "--start", "t_end": "--end", "n_iters": "--iters", "out_dir": "--out", "fps": "--fps",
         "at": "--at", "C": "--C", "time_unit": "--time-unit"}


def _message(exc: BaseException) -> str:
    """The error's text with each parameter named as its command-line flag."""
    text = str(exc) or type(exc).__name__
    if isinstance(exc, OSError) and exc.strerror and exc.filename:
        text = f"{exc.filename}: {exc.strerror}"
    for pattern, flag in FLAG_FOR:
        text = pattern.sub(flag, text)
    return re.sub(r" {2,}", " ", text)


def _show_note(message, category, filename, lineno, file=None, line=None):
    print(f"evinr-lite: note: {_message(Warning(str(message)))}", file=sys.stderr)


def _out_of_memory(exc: BaseException) -> str | None:
    """The message for an exception that means memory ran out, else None."""
    torch = sys.modules.get("torch")
    oom = getattr(torch, "OutOfMemoryError", None) if torch is not None else None
    if isinstance(exc, MemoryError) or (oom is not None and isinstance(exc, oom)) or \
            (isinstance(exc, RuntimeError) and "out of memory" in str(exc).lower()):
        return ("ran out of memory (the estimate made before training was too low); shorten the window with "
                "--start/--end or ask for fewer frames with --fps/--at")
    return None


def main(argv=None) -> int:
    """Run the command; returns the exit status (0 ok, 2 bad input, 1 internal error, 128 + n after signal n).

    The one guard of every command (:func:`evinr_lite.core.guard.run_guarded`, shared with
    ``python -m data_fetch``), in force from this function's first line, before anything heavy is
    imported: a known input problem prints ``evinr-lite: error: ...`` (status 2); anything else
    prints ``evinr-lite: internal error: ...`` with the command to rerun with ``--debug``, which
    shows the traceback (status 1). SIGINT, SIGTERM and SIGHUP stop the run, which cleans up and
    says what happened to the output folder; a closed stdout pipe does not change the result.
    """
    from ..core.guard import run_guarded   # standard library only
    from ..core.runtime import command_page_policy   # standard library only

    owns_process = argv is None            # the command itself, not a call from Python
    if owns_process:                       # numpy not imported yet: its page policy (core/runtime.py)
        command_page_policy()
    argv = list(sys.argv[1:] if argv is None else argv)
    seen = {}

    def body() -> int:
        import warnings
        from pathlib import Path

        args = build_parser().parse_args([str(a) for a in argv])
        seen["args"] = args
        out = getattr(args, "out", None)
        try:
            seen["existed"] = out is not None and os.path.lexists(out)
        except (OSError, ValueError):
            seen["existed"] = False
        commands = {"info": _info, "reconstruct": _reconstruct, "demo": _demo, "batch": _batch}
        with warnings.catch_warnings():
            warnings.simplefilter("default")
            warnings.showwarning = _show_note
            commands[args.command](args)
        return 0

    def interrupted_note(exc):
        note = getattr(exc, "output_note", None)
        out = getattr(seen.get("args"), "out", None)
        if note is None and out is not None:
            note = f"the existing {out} was left as it was" if seen.get("existed") else f"{out} was not written"
        return note

    return run_guarded("evinr-lite", body, argv, describe=_message, interrupted_note=interrupted_note,
                       out_of_memory=_out_of_memory, debug=lambda: getattr(seen.get("args"), "debug", False),
                       owns_process=owns_process)


if __name__ == "__main__":   # `python -m evinr_lite.apps.cli ...` runs the command (it did nothing, with status 0)
    sys.exit(main())
