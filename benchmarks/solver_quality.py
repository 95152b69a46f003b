"""Quality and time of EvINR variants and baselines on a built-in synthetic scene with ground truth.

    python benchmarks/solver_quality.py                     # 120x160, 2 s, C = 0.2 (about 3 minutes)
    python benchmarks/solver_quality.py --size 48x64 --duration 1 --iters 100   # a quick look

Protocol: frames at ``--frames`` evenly spaced times; ground truth = tonemap_reinhard(true log
intensity, gamma 0.6); predictions are the solvers' tone-mapped frames with their own brightness
anchor (mean tone-mapped level 0.5; integration is anchored the same way). MSE and SSIM (gaussian
sigma 1.5, data_range 1) with no equalisation and with CLAHE on both images (the EvINR paper's
protocol). Times are wall-clock training times on this machine, measured in the same run.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from evinr_lite import integrate_events, make_scene, simulate_scene, tonemap_reinhard  # noqa: E402
from evinr_lite.metrics import score_frames  # noqa: E402
from evinr_lite.tonemap import anchor_mean  # noqa: E402
from evinr_lite.solver import EvINRConfig, reconstruct  # noqa: E402


def variants(C: float, iters: int) -> dict:
    c2f = (iters // 3, 2 * iters // 3)
    common = dict(C=C, n_iters=iters, c2f_iters=c2f, progress=False)
    return {
        "EvINR Base (no reg., no C2F)": EvINRConfig.base(**common),
        "EvINR Base + Reg.": EvINRConfig(**{**common, "coarse_to_fine": False}),
        "EvINR Base + C2F": EvINRConfig(**{**common, "regularizer": "none"}),
        "EvINR Full (paper recipe)": EvINRConfig(**common),
        "EvINR Full, boundary difference + TV": EvINRConfig(**{**common, "temporal_loss": "difference",
                                                               "regularizer": "tv"}),
    }


def run(size=(120, 160), duration=2.0, C=0.2, iters=300, n_frames=10, scene_name="camera", seed=0, log=print):
    scene = make_scene(scene_name, sensor_size=size, duration=duration)
    events = simulate_scene(scene, 0.0, duration, C=C, seed=seed)
    q = np.linspace(0.05 * duration, 0.95 * duration, n_frames)
    gt = tonemap_reinhard(scene.log_intensity(q))
    log(f"scene {scene_name} {size[0]}x{size[1]}, {duration:g} s, C = {C:g}: {len(events):,} events "
        f"({len(events) / (size[0] * size[1]):.1f} per pixel); {n_frames} frames scored")
    rows = {}

    def score(name, frames, seconds):
        rows[name] = {"time_s": seconds,
                      **{f"{k}_{eq}": v for eq in ("none", "clahe")
                         for k, v in score_frames(frames, gt, eq).items() if k in ("mse", "ssim")}}
        r = rows[name]
        log(f"  {name:<40} MSE {r['mse_none']:.4f}  SSIM {r['ssim_none']:.3f}  | CLAHE: MSE {r['mse_clahe']:.4f}"
            f"  SSIM {r['ssim_clahe']:.3f}  | {seconds:6.1f} s")

    t0 = time.perf_counter()
    L_int = integrate_events(events, q, C=C)
    score("direct integration (L0 = 0)", tonemap_reinhard(anchor_mean(L_int)), time.perf_counter() - t0)
    for name, cfg in variants(C, iters).items():
        rec = reconstruct(events, q, cfg)
        score(name, rec.frames, rec.history["train_time_s"])
    return {"scene": scene_name, "size": list(size), "duration_s": duration, "C": C, "iterations": iters,
            "n_events": len(events), "n_frames": n_frames,
            "protocol": "GT = tonemap_reinhard(true L, 0.6); predictions anchored to mean tone-mapped 0.5; "
                        "SSIM gaussian sigma 1.5, data_range 1; 'none' and 'clahe' equalisation of both images",
            "rows": rows}


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
        Path(a.json).write_text(json.dumps(result, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
