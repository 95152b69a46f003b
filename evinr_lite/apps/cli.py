"""The ``evinr-lite`` command (also ``python -m evinr_lite``).

    evinr-lite info RECORDING                 what a recording holds (format, sensor, events, frames)
    evinr-lite reconstruct RECORDING --out DIR [--sensor HxW] [--C C] [--fps N | --at TIMES]
                                              [--start S] [--end S] [--device cpu|cuda] [--overwrite]
    evinr-lite demo [--out DIR]               the built-in synthetic scene, no download
    evinr-lite batch INPUTS... --out DIR [--scheduler ADDRESS | --workers N]
                                              every recording of INPUTS on Dask; a pooled table at the end

Bad input (missing file, unknown format, wrong sensor size, empty window, existing output folder)
prints ``evinr-lite: error: ...`` and exits with status 2; Ctrl-C exits with 130 and leaves no
output folder behind.
"""
from __future__ import annotations

import argparse
import json
import re
import sys

__all__ = ["main", "build_parser"]

EXIT_ERROR = 2
EXIT_INTERRUPTED = 130


def _size(text: str) -> tuple[int, int]:
    try:
        h, w = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"size must be HxW (rows x columns), e.g. 120x160; got {text!r}") from None
    if h <= 0 or w <= 0:
        raise argparse.ArgumentTypeError(f"size must be positive, got {text!r}")
    return h, w


def build_parser() -> argparse.ArgumentParser:
    from ..io.readers import SUPPORTED_FORMATS

    parser = argparse.ArgumentParser(prog="evinr-lite", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)

    info = sub.add_parser("info", help="what a recording holds: format, sensor size, events, frames",
                          description=f"Supported formats: {SUPPORTED_FORMATS}.")
    info.add_argument("recording", help="file or folder (format detected from content and name)")
    info.add_argument("--sensor", type=_size, help="sensor size HxW, for files that do not record it (.npy, "
                                                   "text without a header, some Prophesee .raw)")
    info.add_argument("--json", action="store_true", help="print the description as JSON")

    rec = sub.add_parser("reconstruct", help="reconstruct frames from a recording with EvINR",
                         description="Reconstruct frames with EvINR and write PNGs, an MP4 and a GIF; when the "
                                     "recording has frames, score against them (metrics.json / metrics.csv). "
                                     f"Supported formats: {SUPPORTED_FORMATS}.")
    rec.add_argument("recording", help="file or folder (format detected from content and name)")
    rec.add_argument("--out", required=True, help="output folder (refused if it exists, unless --overwrite)")
    rec.add_argument("--sensor", type=_size, help="sensor size HxW (rows x columns), for files that do not "
                                                  "record it; checked against the file's otherwise")
    rec.add_argument("--C", type=float, help="contrast threshold (default: the file's, else 1 as in the paper)")
    when = rec.add_mutually_exclusive_group()
    when.add_argument("--fps", type=float, help="reconstruct this many frames per second over the window")
    when.add_argument("--at", help="reconstruct at these times (seconds, comma-separated, or a file with "
                                   "one per line); default: the ground-truth frame times, else 30 per second")
    rec.add_argument("--start", type=float, help="window start, seconds on the recording's clock (see `info`)")
    rec.add_argument("--end", type=float, help="window end, seconds on the recording's clock (see `info`)")
    rec.add_argument("--device", choices=("cpu", "cuda"), help="where to train (default: a GPU when present)")
    rec.add_argument("--iters", type=int, default=300, help="training iterations (default: 300, the paper's)")
    rec.add_argument("--seed", type=int, default=0)
    rec.add_argument("--no-video", action="store_true", help="write PNGs only (no MP4 / GIF)")
    rec.add_argument("--overwrite", action="store_true", help="replace --out if it exists")
    rec.add_argument("--quiet", action="store_true", help="no progress bar")

    demo = sub.add_parser("demo", help="reconstruct a built-in synthetic scene and score it (no download)")
    demo.add_argument("--out", default="evinr_demo", help="output folder (default: evinr_demo)")
    demo.add_argument("--scene", default="camera", help="built-in scene: camera, astronaut, bar, ... (default: camera)")
    demo.add_argument("--size", type=_size, default=(120, 160), help="sensor size HxW (default: 120x160)")
    demo.add_argument("--duration", type=float, default=2.0, help="seconds of events (default: 2)")
    demo.add_argument("--C", type=float, default=0.2, help="contrast threshold (default: 0.2)")
    demo.add_argument("--frames", type=int, default=8, help="number of frames to reconstruct (default: 8)")
    demo.add_argument("--iters", type=int, default=300, help="EvINR training iterations (default: 300, the paper's)")
    demo.add_argument("--seed", type=int, default=0)
    demo.add_argument("--overwrite", action="store_true", help="replace --out if it exists")

    batch = sub.add_parser("batch", help="reconstruct and score many recordings on Dask (one task each)",
                           description="Reconstruct and score every recording of INPUTS, one dask.distributed "
                                       "task each, into DIR/<name>/; a rerun skips finished recordings; at the end "
                                       "DIR/summary.json|csv|md pool the scores per dataset (frame-weighted, as "
                                       "EVREAL). See the README's batch section for real clusters.")
    batch.add_argument("inputs", nargs="+", metavar="INPUT",
                       help="recordings, folders of recordings, or data_fetch names (ijrr, ijrr:slider_depth, "
                            "hqf:all) looked up in the cache folder ($EVINR_DATA)")
    batch.add_argument("--out", required=True, help="results folder (a rerun with the same settings resumes)")
    where = batch.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS", help="a running Dask scheduler, e.g. tcp://host:8786 "
                                                             "(its workers must see the inputs and --out)")
    where.add_argument("--workers", type=int, help="worker processes of a LocalCluster on this machine "
                                                   "(default: one per CPU core, at most one per recording)")
    batch.add_argument("--torch-threads", type=int, default=1, help="torch threads per task (default: 1)")
    batch.add_argument("--sensor", type=_size, help="sensor size HxW, for files that do not record it")
    batch.add_argument("--C", type=float, help="contrast threshold (default: each file's, else 1)")
    batch.add_argument("--fps", type=float, help="frames to write per second (default: the ground-truth frame "
                                                 "times); scores are always taken at the ground-truth frames")
    batch.add_argument("--device", choices=("cpu", "cuda"), help="where to train (default: a GPU when present)")
    batch.add_argument("--iters", type=int, default=300, help="training iterations (default: 300, the paper's)")
    batch.add_argument("--seed", type=int, default=0)
    batch.add_argument("--video", action="store_true", help="also write MP4 / GIF per recording")
    batch.add_argument("--quiet", action="store_true", help="no progress bar")
    return parser


def _info(args) -> None:
    from .recon_job import describe_recording, format_info, read_any

    rec = read_any(args.recording, sensor_size=args.sensor)
    info = describe_recording(rec)
    print(json.dumps(info, indent=2) if args.json else format_info(info))


def _reconstruct(args) -> None:
    from .recon_job import run_reconstruct

    run_reconstruct(args.recording, args.out, sensor_size=args.sensor, C=args.C, fps=args.fps, at=args.at,
                    t_start=args.start, t_end=args.end, device=args.device, n_iters=args.iters, seed=args.seed,
                    overwrite=args.overwrite, video=not args.no_video, progress=not args.quiet)


def _demo(args) -> None:
    from pathlib import Path

    from .demo import run_demo
    from ..method.solver import EvINRConfig

    if Path(args.out).exists() and not args.overwrite:  # say so before training, not after
        raise FileExistsError(f"output folder {args.out} already exists; choose another --out or pass --overwrite")
    config = EvINRConfig(C=args.C, n_iters=args.iters, seed=args.seed,
                         c2f_iters=(args.iters // 3, 2 * args.iters // 3))
    run_demo(args.out, scene=args.scene, sensor_size=args.size, duration=args.duration, C=args.C,
             n_frames=args.frames, seed=args.seed, overwrite=args.overwrite, config=config)


def _batch(args) -> None:
    from .batch import run_batch
    from ..core.events import EventDataError

    try:
        summary = run_batch(args.inputs, args.out, scheduler=args.scheduler, workers=args.workers,
                            torch_threads=args.torch_threads, sensor_size=args.sensor, C=args.C, fps=args.fps,
                            device=args.device, n_iters=args.iters, seed=args.seed, video=args.video,
                            progress=not args.quiet)
    except KeyboardInterrupt as exc:   # finished recordings stay: the same command resumes
        exc.output_note = f"finished recordings stay in {args.out}/; run the same command again to resume"
        raise
    if summary["failed"] and len(summary["failed"]) == len(summary["recordings"]):
        raise EventDataError(f"every recording failed; see {args.out}/summary.md")


# Library errors name Python parameters; on the command line the same advice names the flags.
FLAG_FOR = [
    (re.compile(r"sensor_size=\((\d+), (\d+)\)"), r"--sensor \1x\2"),
    (re.compile(r"sensor_size=\(H, W\)"), "--sensor HxW"),
    (re.compile(r"\bt_start=/t_end="), "--start/--end"),
    (re.compile(r"\bt_start="), "--start "),
    (re.compile(r"\bt_end="), "--end "),
    (re.compile(r"\bn_iters="), "--iters"),
    (re.compile(r"\bout_dir="), "--out"),
    (re.compile(r"\boverwrite=True"), "--overwrite"),
    (re.compile(r"\bdevice='(\w+)'"), r"--device \1"),
    (re.compile(r"\bfps="), "--fps"),
    (re.compile(r"\bat="), "--at "),
    (re.compile(r"\bC="), "--C "),
]


def _message(exc: BaseException) -> str:
    """The error's text with each parameter named as its command-line flag."""
    text = str(exc) or type(exc).__name__
    for pattern, flag in FLAG_FOR:
        text = pattern.sub(flag, text)
    return re.sub(r" {2,}", " ", text)


def main(argv=None) -> int:
    """Run the command; returns the exit status (0 ok, 2 bad input, 130 interrupted)."""
    args = build_parser().parse_args(argv)
    from ..core.events import EventDataError

    commands = {"info": _info, "reconstruct": _reconstruct, "demo": _demo, "batch": _batch}
    try:
        commands[args.command](args)
    except (EventDataError, FileExistsError, FileNotFoundError, PermissionError, IsADirectoryError,
            NotADirectoryError, ValueError) as exc:
        print(f"evinr-lite: error: {_message(exc)}", file=sys.stderr)
        return EXIT_ERROR
    except KeyboardInterrupt:
        out = getattr(args, "out", None)
        where = f"; {out} was not written or changed" if out else ""
        print(f"\nevinr-lite: interrupted{where} (partial results are deleted)", file=sys.stderr)
        return EXIT_INTERRUPTED
    return 0
