"""Inference: frames per second when querying a frame INR at 240x180 and 408x306 (paper, Table 4).

    python benchmarks/inference.py
    python benchmarks/inference.py --quick

Protocol: one network of the paper's size (SIREN 512 x 3 hidden layers, H*W outputs). Its weights
do not change the amount of work, so it is not trained here. Two measurements per size, the
fastest of ``--repeats``:

- forward: ``model(t)`` on a batch of 256 times under ``torch.no_grad`` (the tensor stays on the device);
- query: ``solver.predict_networks(model, times)`` for 1024 times, which is what ``Reconstruction.at``
  runs: batches of 256, results gathered into one float32 numpy array [1, Q, H, W] on the host.

The paper reports 178 fps (240x180) and 55 fps (408x306) on a GPU (Table 4), one frame at a time;
the target here is batched, on this CPU: at least 1000 fps at 240x180.
"""
from __future__ import annotations

import sys

import numpy as np
import torch

try:
    from benchmarks.common import best_time, devices, parser, report, row
except ImportError:  # run as a script
    from common import best_time, devices, parser, report, row

from evinr_lite.method.models import FrameINR  # noqa: E402
from evinr_lite.method.solver import predict_networks  # noqa: E402

PAPER_FPS = {(180, 240): 178, (306, 408): 55}


def run(quick: bool = False, device: str | None = None, repeats: int | None = None, log=print) -> list[dict]:
    repeats = repeats or (3 if quick else 5)
    rows = []
    for dev in devices(device):
        for size in ((180, 240), (306, 408)):
            H, W = size
            model = FrameINR(size, [[0.0, 5.0]], 512, 3, 30.0, 10.0, seed=0).to(dev).eval()
            t = torch.linspace(0.0, 5.0, 256, dtype=torch.float64, device=dev)[None]
            times = np.linspace(0.0, 5.0, 256 if quick else 1024)
            with torch.no_grad():
                model(t)
                forward_s = best_time(lambda: model(t), repeats, dev)
            predict_networks(model, times[:256])
            query_s = best_time(lambda: predict_networks(model, times), repeats, dev)
            fps_forward, fps_query = 256 / forward_s, len(times) / query_s
            gflops = 2 * 512 * H * W * fps_forward / 1e9
            log(f"inference {H}x{W} [{dev}]: forward {fps_forward:.0f} fps ({gflops:.0f} GFLOP/s in the output layer), "
                f"query (predict_networks -> numpy) {fps_query:.0f} fps; paper (GPU, Table 4) {PAPER_FPS[size]} fps")
            target = 1000.0 if size == (180, 240) and dev == "cpu" else None
            rows.append(row(f"inference {W}x{H}, query in batches [{dev}]", fps_query, "fps", target=target,
                            note=f"forward alone {fps_forward:.0f} fps; paper {PAPER_FPS[size]} fps on an RTX 3090",
                            forward_fps=fps_forward, device=dev, size=list(size), paper_fps=PAPER_FPS[size]))
    return rows


def main(argv=None) -> int:
    p = parser(__doc__, "256 query times, fewer repeats")
    a = p.parse_args(argv)
    rows = run(a.quick, a.device, a.repeats)
    report(rows, a.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
