"""PNG output: frames written in turn (``save_png``) against :class:`evinr_lite.io.output.PngWriter` (worker threads).

    python benchmarks/png_writer.py             # 40 frames of 1280x720 (a 2 s HD run at 20 fps)
    python benchmarks/png_writer.py --quick     # 40 frames of 360x480

The frames are a smooth ramp with texture (a reconstruction's statistics, not noise, which zlib cannot
compress). Both ways run alternately in one process (``benchmarks.common.alternate``, best of 3) into
temporary folders, and the files are checked equal byte for byte.
"""
from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

try:
    from benchmarks.common import alternate
except ImportError:  # run as a script
    from common import alternate

from evinr_lite.core.runtime import cpu_threads  # noqa: E402
from evinr_lite.io.output import PngWriter, save_png  # noqa: E402


def frames(n: int, size) -> list:
    H, W = size
    rng = np.random.default_rng(0)
    base = rng.random((H, W)) * 0.3 + np.linspace(0.0, 0.6, W)[None]
    return [(np.clip(base + 0.05 * k / n, 0, 1) * 255 + 0.5).astype(np.uint8) for k in range(n)]


def run(quick: bool = False) -> dict:
    size = (360, 480) if quick else (720, 1280)
    stack = frames(40, size)
    with tempfile.TemporaryDirectory() as tmp:
        a, b = Path(tmp, "turn"), Path(tmp, "threads")
        a.mkdir()
        b.mkdir()

        def in_turn():
            for i, f in enumerate(stack):
                save_png(a / f"{i}.png", f)

        def threaded():
            with PngWriter() as png:
                for i, f in enumerate(stack):
                    png.write(b / f"{i}.png", f)

        best = alternate({"in turn": in_turn, "PngWriter": threaded}, repeats=3)
        same = all((a / f"{i}.png").read_bytes() == (b / f"{i}.png").read_bytes() for i in range(len(stack)))
    out = {"frames": len(stack), "size": list(size), "threads": cpu_threads(), "in_turn_s": best["in turn"],
           "png_writer_s": best["PngWriter"], "ratio": best["PngWriter"] / best["in turn"], "same_bytes": same}
    print(f"{len(stack)} frames of {size[1]}x{size[0]}, {cpu_threads()} threads: in turn {best['in turn']:.2f} s, "
          f"PngWriter {best['PngWriter']:.2f} s (x{out['ratio']:.2f}); files equal byte for byte: {same}")
    return out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help="360x480 frames")
    run(p.parse_args(argv).quick)


if __name__ == "__main__":
    main()
