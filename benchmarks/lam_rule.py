"""lam="auto" against fixed values of lam, on every zoo scene and the real chunk, in one run.

    python benchmarks/lam_rule.py             # the short scenes and the real chunk (about 2 min on 2 cores)
    python benchmarks/lam_rule.py --long      # also the 20 s and 60 s recordings (several minutes more)
    python benchmarks/lam_rule.py --quick     # the quick zoo's smaller scenes
    python benchmarks/lam_rule.py --heldout   # the held-out scenes the rule was not chosen on (zoo.HELDOUT)
    python benchmarks/lam_rule.py --stress    # the stress scenes, settings outside both sets' ranges (zoo.STRESS)
    python benchmarks/lam_rule.py --fresh 11  # 16 scenes drawn at random the zoo's ways (zoo.fresh), as quality_zoo.py --fresh

For each scene: the activity m (events per pixel per network window that came and went,
``evinr_lite.method.smoothing.activity``), the lam that ``EvINRConfig(lam="auto")`` gives, and
CLAHE-SSIM / SSIM / MSE of the kit's default with lam "auto" and with each fixed lam of the sweep. The
best fixed lam per scene is what a user with the ground truth in hand would pick; the rule has only
the events. Writes benchmarks/lam_rule_results.{json,md}.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.common import write_json  # noqa: E402
from benchmarks.quality_zoo import real_chunk, score  # noqa: E402
from evinr_lite.method.balance import polarity_counts  # noqa: E402
from evinr_lite.method.prepare import prepare_events  # noqa: E402
from evinr_lite.method.config import EvINRConfig  # noqa: E402
from evinr_lite.method.smoothing import activity, window_fraction  # noqa: E402
from evinr_lite.method.solver import reconstruct  # noqa: E402
from evinr_lite.sim.zoo import HELDOUT, STRESS, default_scenes, effective_C, fresh, quick, simulate  # noqa: E402

SWEEP = (0.001, 0.002, 0.005, 0.01, 0.03, 0.1)


def scene_row(name, events, times, gt, C, log=print) -> dict:
    t0, t1 = float(min(events.t[0], times.min())), float(max(events.t[-1], times.max()))
    cfg = EvINRConfig(C=C, progress=False)
    fraction = window_fraction(t0, t1, cfg.tau, cfg.overlap)
    kept, planned = prepare_events(events, cfg, (t0, t1))        # what reconstruct trains on: hot pixels, background
    m = activity(*polarity_counts(kept)) * fraction
    row = {"activity": m, "lam_auto": planned.lam, "scores": {}}
    for lam in ("auto",) + SWEEP:
        t = time.perf_counter()
        rec = reconstruct(events, times, EvINRConfig(C=C, lam=lam, progress=False))
        row["scores"][str(lam)] = {**{k: v for k, v in score(rec.frames, times, gt, times).items()
                                      if k in ("ssim_clahe", "ssim_none", "mse_none")},
                                   "time_s": time.perf_counter() - t}
    fixed = {k: v for k, v in row["scores"].items() if k != "auto"}
    row["best_fixed"] = max(fixed, key=lambda k: fixed[k]["ssim_clahe"])
    s = row["scores"]
    log(f"{name:20s} m {m:5.1f}  lam auto {planned.lam:.4f}  CLAHE-SSIM auto {s['auto']['ssim_clahe']:.3f}  "
        + "  ".join(f"{k}: {v['ssim_clahe']:.3f}" for k, v in fixed.items()) + f"  (best fixed {row['best_fixed']})")
    return row


def markdown(rows: dict, heldout: bool = False, label: str | None = None) -> str:
    head = "| scene | activity m | lam auto | auto | " + " | ".join(f"lam {v:g}" for v in SWEEP) + " | best fixed |"
    lines = [head, "|" + "---|" * (5 + len(SWEEP))]
    for name, r in rows.items():
        cells = [f"{r['scores'][k]['ssim_clahe']:.3f} / {r['scores'][k]['ssim_none']:.3f} / {r['scores'][k]['mse_none']:.4f}"
                 for k in ("auto",) + tuple(str(v) for v in SWEEP)]
        lines.append(f"| {name} | {r['activity']:.1f} | {r['lam_auto']:.4f} | " + " | ".join(cells) + f" | {r['best_fixed']} |")
    short = [r for n, r in rows.items() if not r.get("long") and n != "real_slider_chunk"]
    if short:
        label = label or ("held-out" if heldout else "zoo")
        means = [np.mean([r["scores"][k]["ssim_clahe"] for r in short]) for k in ("auto",) + tuple(str(v) for v in SWEEP)]
        lines.append(f"| **mean, {len(short)} short {label} scenes (CLAHE-SSIM)** | | | " + " | ".join(f"{v:.3f}" for v in means)
                     + " | |")
    lines += ["", "Cells: CLAHE-SSIM / SSIM / MSE of the kit's default (EvINRConfig()) with lam \"auto\" and with each "
              "fixed lam; activity m: events per pixel per network window that came and went "
              "(evinr_lite.method.smoothing). Written by `python benchmarks/lam_rule.py`."]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--quick", action="store_true")
    p.add_argument("--long", action="store_true")
    p.add_argument("--heldout", action="store_true", help="the held-out scenes instead (no real chunk)")
    p.add_argument("--stress", action="store_true", help="the stress scenes instead (no real chunk)")
    p.add_argument("--fresh", type=int, default=None, metavar="SEED",
                   help="16 scenes drawn at random the zoo's ways from SEED instead (zoo.fresh; no real chunk)")
    p.add_argument("--json", default=None, help="default benchmarks/lam_rule_results[_heldout|_stress|_fresh].json")
    p.add_argument("--md", default=None, help="default benchmarks/lam_rule_results[_heldout|_stress|_fresh].md")
    a = p.parse_args(argv)
    if a.heldout + a.stress + (a.fresh is not None) > 1:
        p.error("--heldout, --stress and --fresh are other sets of scenes: give one of them")
    suffix = "_heldout" if a.heldout else "_stress" if a.stress else "_fresh" if a.fresh is not None else ""
    a.json = a.json or f"benchmarks/lam_rule_results{suffix}.json"
    a.md = a.md or f"benchmarks/lam_rule_results{suffix}.md"
    rows = {}
    pool = HELDOUT if a.heldout else STRESS if a.stress else fresh(a.fresh) if a.fresh is not None else \
        default_scenes(long=a.long)
    for z in pool:
        z = quick(z) if a.quick else z
        scene, events, times, gt = simulate(z)
        rows[z.name] = {**scene_row(z.name, events, times, gt, effective_C(z)), "long": z.long}
    found = None if a.heldout or a.stress or a.fresh is not None else real_chunk()
    if found is not None:
        rec, gt, gt_t = found
        rows["real_slider_chunk"] = scene_row("real_slider_chunk", rec.events, gt_t, gt, 1.0)
    write_json(a.json, {"quick": a.quick, "heldout": a.heldout, "stress": a.stress, "fresh_seed": a.fresh,
                        "sweep": list(SWEEP), "scenes": rows})
    Path(a.md).write_text(markdown(rows, a.heldout, "stress" if a.stress else f"fresh (seed {a.fresh})"
                                   if a.fresh is not None else None))
    print(f"json: {a.json}\nmarkdown: {a.md}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
