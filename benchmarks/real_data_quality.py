"""Quality on the real recording beside the project (IJRR slider_depth chunk), for a few EvINR settings.

    python benchmarks/real_data_quality.py                 # the paper's recipe, head learning-rate scales, difference + TV
    python benchmarks/real_data_quality.py --iters 100     # shorter training

Every method is scored at the APS frame timestamps inside the events' span, without equalisation
and with CLAHE (evinr_lite.evaluation.scoring). The largest training loss of the first 100 iterations is
printed too: spikes there mean a learning rate too high for the data.
"""
from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from evinr_lite.evaluation.scoring import evaluate, results_table  # noqa: E402
from evinr_lite.io.readers import read_recording  # noqa: E402
from evinr_lite.evaluation.scoring import frames_to_score  # noqa: E402
from evinr_lite.io.sample_data import sample_recording_path  # noqa: E402
from evinr_lite.method.solver import EvINRConfig  # noqa: E402


def variants(n_iters: int) -> dict[str, EvINRConfig]:
    paper = EvINRConfig.v0_1(n_iters=n_iters, c2f_iters=(n_iters // 3, 2 * n_iters // 3), progress=False)
    out = {f"paper, head_lr_scale {s:g}": replace(paper, head_lr_scale=s) for s in (30.0, 10.0, 3.0, 1.0)}
    out["difference + TV"] = replace(paper, temporal_loss="difference", regularizer="tv")
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--iters", type=int, default=300, help="training iterations (default: 300, the paper's)")
    p.add_argument("--recording", default=None, help="a recording with frames (default: the shared slider_depth chunk)")
    a = p.parse_args(argv)
    path = a.recording or sample_recording_path()
    if path is None:
        print("no recording: pass --recording, or put shared/data/ijrr_slider_depth_chunk beside the project")
        return 2
    rec = read_recording(path)
    idx = frames_to_score(rec.frames.t, rec.events)
    gt, gt_t = rec.frames.images[idx], rec.frames.t[idx]
    print(f"{path}: {len(rec.events):,} events, {len(idx)} frames scored")
    rows = evaluate(rec.events, gt, gt_t, methods=("integration", "hf"), config=EvINRConfig.v0_1(progress=False),
                    lpips_model=False)
    for name, cfg in variants(a.iters).items():
        new = evaluate(rec.events, gt, gt_t, methods=("evinr",), config=cfg, lpips_model=False, keep_frames=True)
        loss = np.asarray(new[0]["reconstruction"].history["loss"])
        print(f"{name}: largest loss in the first 100 iterations {loss[:100].max():.3g}, final {loss[-10:].mean():.3g}")
        rows += [{k: v for k, v in {**r, "method": f"evinr, {name}"}.items() if k not in ("frames", "reconstruction")}
                 for r in new]
    print(results_table(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
