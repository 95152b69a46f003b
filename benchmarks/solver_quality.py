"""Quality and time of EvINR variants and baselines on a built-in synthetic scene with ground truth.

    python benchmarks/solver_quality.py                     # 120x160, 2 s, C = 0.2 (about 3 minutes)
    python benchmarks/solver_quality.py --size 48x64 --duration 1 --iters 100   # a quick look

Protocol (evinr_lite.evaluation.ablation.run_variants, printed under the table): frames at ``--frames`` evenly
spaced times; ground truth = tonemap_reinhard(true log intensity, gamma 0.6); predictions are the
solvers' tone-mapped frames with their own brightness anchor (mean tone-mapped level 0.5;
integration is anchored the same way). MSE and SSIM (gaussian sigma 1.5, data_range 1) with no
equalisation and with CLAHE on both images (the EvINR paper's protocol). Times are wall-clock
training times on this machine, measured in the same run. Notebook 07 runs the full set of ablations.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from evinr_lite.evaluation import ablation  # noqa: E402
from evinr_lite import make_scene, simulate_scene, tonemap_reinhard  # noqa: E402
from evinr_lite.method.solver import EvINRConfig  # noqa: E402


def variants(C: float, iters: int) -> dict:
    """Table 2's four variants (evinr_lite.evaluation.ablation.table2_variants), the reference code's loss and
    regularizer on top of Full, and direct integration."""
    common = dict(C=C, n_iters=iters, c2f_iters=(iters // 3, 2 * iters // 3))
    table2 = ablation.table2_variants(**common)
    return {"direct integration (L0 = 0)": ablation.integration_baseline(C),
            "EvINR Base (no reg., no C2F)": table2["Base"],
            "EvINR Base + Reg.": table2["Base + Reg."],
            "EvINR Base + C2F": table2["Base + C2F"],
            "EvINR Full (paper recipe)": table2["Full"],
            "EvINR Full, boundary difference + TV": EvINRConfig.v0_1(**{**common, "temporal_loss": "difference",
                                                                   "regularizer": "tv"})}


def run(size=(120, 160), duration=2.0, C=0.2, iters=300, n_frames=10, scene_name="camera", seed=0, log=print):
    scene = make_scene(scene_name, sensor_size=size, duration=duration)
    events = simulate_scene(scene, 0.0, duration, C=C, seed=seed)
    q = np.linspace(0.05 * duration, 0.95 * duration, n_frames)
    gt = tonemap_reinhard(scene.log_intensity(q))
    log(f"scene {scene_name} {size[0]}x{size[1]}, {duration:g} s, C = {C:g}: {len(events):,} events "
        f"({len(events) / (size[0] * size[1]):.1f} per pixel); {n_frames} frames scored")
    rows = ablation.run_variants(events, gt, q, variants(C, iters), log=log)
    log("\n" + ablation.ablation_table(rows))
    keys = ("train_time_s", "inference_fps", "fps", "mse_none", "ssim_none", "mse_clahe", "ssim_clahe")
    return {"scene": scene_name, "size": list(size), "duration_s": duration, "C": C, "iterations": iters,
            "n_events": len(events), "n_frames": n_frames, "protocol": rows[0]["protocol"],
            "rows": {r["name"]: {"time_s": r["train_time_s"], **{k: r[k] for k in keys}} for r in rows}}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--size", default="120x160", help="HxW (default 120x160)")
    p.add_argument("--duration", type=float, default=2.0)
    p.add_argument("--C", type=float, default=0.2)
    p.add_argument("--iters", type=int, default=300)
    p.add_argument("--frames", type=int, default=10)
    p.add_argument("--scene", default="camera")
    p.add_argument("--json", help="also write the results here")
    a = p.parse_args(argv)
    size = tuple(int(v) for v in a.size.lower().split("x"))
    result = run(size, a.duration, a.C, a.iters, a.frames, a.scene)
    if a.json:
        out = Path(a.json)
        tmp = out.with_name(f".{out.name}.partial")
        tmp.write_text(json.dumps(result, indent=2) + "\n")
        os.replace(tmp, out)  # atomic: never a half-written file
    return 0


if __name__ == "__main__":
    sys.exit(main())
