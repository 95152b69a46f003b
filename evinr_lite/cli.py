"""The ``evinr-lite`` command (also ``python -m evinr_lite``)."""
from __future__ import annotations

import argparse
import sys

__all__ = ["main"]


def _size(text: str) -> tuple[int, int]:
    try:
        h, w = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"size must be HxW (rows x columns), e.g. 120x160; got {text!r}") from None
    if h <= 0 or w <= 0:
        raise argparse.ArgumentTypeError(f"size must be positive, got {text!r}")
    return h, w


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="evinr-lite", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
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
    return parser


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    from .events import EventDataError

    try:
        if args.command == "demo":
            from .demo import run_demo
            from .solver import EvINRConfig

            config = EvINRConfig(C=args.C, n_iters=args.iters, seed=args.seed,
                                 c2f_iters=(args.iters // 3, 2 * args.iters // 3))
            run_demo(args.out, scene=args.scene, sensor_size=args.size, duration=args.duration, C=args.C,
                     n_frames=args.frames, seed=args.seed, overwrite=args.overwrite, config=config)
    except (EventDataError, FileExistsError, ValueError) as exc:
        print(f"evinr-lite: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("evinr-lite: interrupted; nothing was written", file=sys.stderr)
        return 130
    return 0
