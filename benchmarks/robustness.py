"""Robustness sweeps, as EVREAL does: how each method degrades when the events are thinned, noisy, or C is wrong.

    python benchmarks/robustness.py                      # 3 scenes, 3 sweeps, 5 methods (10-25 min on 2 shared cores)
    python benchmarks/robustness.py --quick              # one small scene, 3 levels a sweep, no paper recipe (< 1 min)
    python benchmarks/robustness.py --paper-levels 0     # without the paper recipe (a few minutes)
    python benchmarks/robustness.py --paper-levels 3 --paper-scenes all   # the paper recipe everywhere (an hour)
    python benchmarks/robustness.py --scenes camera_translate --out /tmp/rob   # writes /tmp/rob.json, .md, _figure.png
    python -m benchmarks --only robustness               # the same, from the benchmark runner

Three sweeps, each varying one thing away from the clean condition (all events, no added noise,
C = ``zoo.effective_C``) and leaving the others there:

- ``keep``: the fraction of events kept, 0.1-1.0, drawn by a seeded generator (one uniform number
  per event, kept when below the level, so a lower level's events are a subset of a higher one's);
- ``noise_hz``: background activity added on top of the scene's own sensor, 0-3 Hz per pixel
  (``evinr_lite.sim.simulate.add_background_noise``, seeded per scene);
- ``C_scale``: the C given to every method over the scene's effective C, x0.5 to x2 (the events
  are the clean ones; only the method's belief about the threshold is wrong).

Scenes (from ``evinr_lite.sim.zoo``), chosen to differ: ``camera_translate`` (clean sensor, rich
texture, steady motion), ``chelsea_speed`` (speed swinging 0.2x-1.8x, 4 % threshold mismatch and a
refractory period: the hardest scene for the ghost solve), ``noisy_gravel`` (180x240, a sensor that
is already noisy: background activity, hot pixels, C+ != C-; the noise sweep adds on top of it).

Methods are the zoo's (``benchmarks/quality_zoo.run_method``): ``kit`` (``EvINRConfig()``),
``paper`` (``EvINRConfig.paper()``, 15-35 s a run on an idle machine and several minutes on a shared
one, so by default only on ``camera_translate`` and only at both ends of each sweep plus the clean
condition, 5 runs: see ``--paper-levels`` and ``--paper-scenes``; a method not run on every scene
has no mean over the scenes and appears in the per-scene tables only), the baselines ``integration`` and ``hf``, and
``integration_offset`` (integration with the kit's per-pixel offset solve, an ablation). Every run
is scored at the zoo's 10 ground-truth times through ``evinr_lite.evaluation.score_sequence``
under both protocols (CLAHE on both images, and none): CLAHE-SSIM, SSIM, and MSE.

Writes ``OUT.json`` (every scene's scores), ``OUT.md`` (a table per sweep: method x level, means over
the scenes, then per-scene tables) and a figure (``evinr_lite.viz.plot_robustness``), OUT defaulting to
``benchmarks/robustness_results`` (figure ``benchmarks/robustness_figure.png``; OUT's name with
"_results" dropped, plus "_figure.png"). A hand-written interpretation at the top of an existing OUT.md,
between the two ``<!-- interpretation -->`` markers, is kept when the file is rewritten.
"""
from __future__ import annotations

import argparse
import os
import re
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.common import row, write_json  # noqa: E402
from benchmarks.quality_zoo import run_method, score  # noqa: E402
from evinr_lite.core.events import Events  # noqa: E402
from evinr_lite.sim.simulate import add_background_noise  # noqa: E402
from evinr_lite.sim.zoo import ZOO, ZooScene, effective_C, quick, simulate  # noqa: E402

SCENES = ("camera_translate", "chelsea_speed", "noisy_gravel")
METHODS = ("kit", "paper", "integration", "hf", "integration_offset")
CLEAN = {"keep": 1.0, "noise_hz": 0.0, "C_scale": 1.0}
LEVELS = {"keep": [0.1, 0.2, 0.3, 0.5, 0.7, 1.0],
          "noise_hz": [0.0, 0.25, 0.5, 1.0, 2.0, 3.0],
          "C_scale": [0.5, 0.71, 1.0, 1.41, 2.0]}
QUICK_LEVELS = {"keep": [0.1, 0.5, 1.0], "noise_hz": [0.0, 1.0, 3.0], "C_scale": [0.5, 1.0, 2.0]}
LABELS = {"keep": "fraction of events kept", "noise_hz": "added background noise (Hz per pixel)",
          "C_scale": "C given / true C (x)"}
METRICS = ("ssim_clahe", "ssim_none", "mse_none")
KEEP_SEED, NOISE_SEED = 7000, 8000     # added to the scene's seed: the sweeps' own generators
BEGIN, END = "<!-- interpretation -->", "<!-- /interpretation -->"


def perturb(z: ZooScene, events: Events, condition: dict) -> tuple[Events, float]:
    """(events, C given) under ``condition`` {"keep", "noise_hz", "C_scale"}; seeded by the scene."""
    keep, noise, c_scale = condition["keep"], condition["noise_hz"], condition["C_scale"]
    if not (0 < keep <= 1 and noise >= 0 and c_scale > 0):
        raise ValueError(f"condition {condition} out of range: keep in (0, 1], noise_hz >= 0, C_scale > 0")
    if keep < 1:
        # the same generator at every level: the uniform numbers are the same, so subsets nest
        u = np.random.default_rng(z.seed + KEEP_SEED).random(len(events))
        events = events.take(u < keep)
    if noise > 0:
        events = add_background_noise(events, noise, seed=z.seed + NOISE_SEED, t_start=0.0, t_end=z.duration)
    return events, c_scale * effective_C(z)


def paper_subset(levels: list, n: int, clean: float) -> list:
    """n levels spread over ``levels`` (both ends first), plus the clean one; [] when n == 0."""
    if n <= 0:
        return []
    idx = np.unique(np.linspace(0, len(levels) - 1, min(n, len(levels))).round().astype(int))
    return sorted(set([levels[i] for i in idx]) | ({clean} if clean in levels else set()))


def run_sweeps(scenes, methods=METHODS, levels=None, paper_levels: int = 2, paper_scenes=None, log=print) -> dict:
    """Every method on every scene at every level of every sweep.

    Args:
        scenes: ZooScene objects (their ``simulate`` gives the events and ground truth).
        methods: names from :data:`METHODS` (``benchmarks.quality_zoo.run_method`` runs them).
        levels: {sweep: [levels]} for some of "keep", "noise_hz", "C_scale" (default :data:`LEVELS`).
        paper_levels: how many levels a sweep the paper recipe runs on (0: none; see :func:`paper_subset`).
        paper_scenes: names of the scenes the paper recipe runs on (None: all).

    Returns:
        {"scenes": [names], "methods": [...], "sweeps": {sweep: {"label", "levels", "clean",
        "scores": {method: {scene: [ {metric: value, "time_s", "n_events"} or None per level ]}},
        "means": {method: {metric: [mean over scenes or None per level]}}}}}. The clean condition is
        run once per scene and method and shared by the three sweeps.
    """
    levels = LEVELS if levels is None else levels
    unknown = set(levels) - set(CLEAN)
    if unknown:
        raise ValueError(f"unknown sweeps {sorted(unknown)}; choose from {list(CLEAN)}")
    out = {"scenes": [z.name for z in scenes], "methods": list(methods), "sweeps": {}}
    for s, lv in levels.items():
        out["sweeps"][s] = {"label": LABELS[s], "levels": [float(v) for v in lv], "clean": CLEAN[s],
                            "scores": {m: {z.name: [None] * len(lv) for z in scenes} for m in methods}}
    for z in scenes:
        _, events, times, gt = simulate(z)
        log(f"{z.name}: {z.size[0]}x{z.size[1]}, {z.duration:g} s, {len(events):,} events, C {effective_C(z):.3f}")
        done = {}                                      # (condition, method) -> scores: the clean run is shared
        for s, lv in levels.items():
            run_at = {m: (paper_subset(list(lv), paper_levels, CLEAN[s]) if m == "paper" else list(lv))
                      for m in methods}
            for i, level in enumerate(lv):
                cond = {**CLEAN, s: float(level)}
                key = tuple(cond.values())
                ev, C = perturb(z, events, cond)
                for m in methods:
                    if level not in run_at[m] or (m == "paper" and paper_scenes is not None
                                                  and z.name not in paper_scenes):
                        continue
                    if (key, m) not in done:
                        frames, seconds = run_method(m, ev, times, C, {})
                        done[key, m] = {**score(frames, times, gt, times), "time_s": seconds, "n_events": len(ev)}
                        r = done[key, m]
                        log(f"    {s}={level:<5g} {m:<19s} CLAHE-SSIM {r['ssim_clahe']:.3f}  SSIM {r['ssim_none']:.3f}"
                            f"  MSE {r['mse_none']:.4f}  {seconds:5.1f} s")
                    out["sweeps"][s]["scores"][m][z.name][i] = done[key, m]
    for sw in out["sweeps"].values():
        sw["means"] = {m: {k: [None if any(per[i] is None for per in sw["scores"][m].values())
                               else float(np.mean([per[i][k] for per in sw["scores"][m].values()]))
                               for i in range(len(sw["levels"]))] for k in METRICS + ("time_s",)}
                       for m in methods}
    return out


def retained(sweep: dict, method: str, metric: str = "ssim_clahe", vals=None) -> float | None:
    """The method's mean score at the sweep's worst level over its clean score (None if either is missing).

    ``vals``: one scene's scores [levels] instead of the means.
    """
    lv = sweep["levels"]
    vals = sweep["means"][method][metric] if vals is None else vals
    have = [i for i, v in enumerate(vals) if v is not None]
    clean = [i for i in have if lv[i] == sweep["clean"]]
    if not clean or len(have) < 2:
        return None
    return min(vals[i] for i in have) / vals[clean[0]]


def verdicts(results: dict) -> list[str]:
    """One generated line per sweep and protocol: each method's mean at the extreme levels, retained fraction."""
    lines = []
    for s, sw in results["sweeps"].items():
        lv = sw["levels"]
        for metric, name in (("ssim_clahe", "CLAHE-SSIM"), ("ssim_none", "SSIM")):
            parts = []
            for m in results["methods"]:
                vals = sw["means"][m][metric]
                if all(v is None for v in vals):
                    continue
                at = [f"{vals[i]:.3f} at {lv[i]:g}" for i in (0, len(lv) - 1) if vals[i] is not None]
                r = retained(sw, m, metric)
                if at:
                    parts.append(f"{m} " + ", ".join(at) + ("" if r is None else f" (worst/clean {r:.2f})"))
            lines.append(f"- **{s}**, {name}: " + "; ".join(parts) + ".")
    return lines


def markdown(results: dict) -> str:
    """A table per sweep: method x level, cells CLAHE-SSIM / SSIM / MSE, means over the scenes."""
    scenes = ", ".join(results["scenes"])
    lines = [f"Scenes: {scenes} (means over them). Cells: CLAHE-SSIM / SSIM / MSE (no equalisation), scored at "
             "the zoo's 10 ground-truth times per scene through evinr_lite.evaluation.score_sequence; '-': not "
             "run at that level. Command: `nice -n 10 python benchmarks/robustness.py`"
             + (" --quick" if results.get("quick") else "") + f"; {results.get('seconds', 0):.0f} s in all.", ""]
    for s, sw in results["sweeps"].items():
        lines += [f"### {s}: {sw['label']} (clean: {sw['clean']:g})", "",
                  "| method | " + " | ".join(f"{v:g}" for v in sw["levels"]) + " | worst / clean (CLAHE) |",
                  "|---" * (len(sw["levels"]) + 2) + "|"]
        for m in results["methods"]:
            mm = sw["means"][m]
            if all(v is None for v in mm["ssim_clahe"]):
                continue                               # not run on every scene: see the per-scene tables
            cells = ["-" if mm["ssim_clahe"][i] is None else
                     f"{mm['ssim_clahe'][i]:.3f} / {mm['ssim_none'][i]:.3f} / {mm['mse_none'][i]:.4f}"
                     for i in range(len(sw["levels"]))]
            r = retained(sw, m)
            lines.append(f"| {m} | " + " | ".join(cells) + f" | {'-' if r is None else f'{r:.2f}'} |")
        lines.append("")
    lines += ["### Per scene (CLAHE-SSIM / SSIM)", ""]
    for s, sw in results["sweeps"].items():
        lines += [f"{s}:", "", "| scene | method | " + " | ".join(f"{v:g}" for v in sw["levels"])
                  + " | worst / clean (CLAHE) |", "|---" * (len(sw["levels"]) + 3) + "|"]
        for scene in results["scenes"]:
            for m in results["methods"]:
                per = sw["scores"][m][scene]
                if all(v is None for v in per):
                    continue
                r = retained(sw, m, vals=[None if v is None else v["ssim_clahe"] for v in per])
                lines.append(f"| {scene} | {m} | " + " | ".join("-" if v is None else
                                                               f"{v['ssim_clahe']:.3f} / {v['ssim_none']:.3f}"
                                                               for v in per)
                             + f" | {'-' if r is None else f'{r:.2f}'} |")
        lines.append("")
    lines += ["Generated summary (means at the two ends of each sweep; worst/clean = the mean at the sweep's "
              "worst level over the clean mean):", ""] + verdicts(results)
    return "\n".join(lines)


def kept_interpretation(path: Path) -> str:
    """The hand-written block between the interpretation markers of an existing file ('' if none)."""
    if not path.exists():
        return ""
    m = re.search(re.escape(BEGIN) + ".*?" + re.escape(END), path.read_text(), re.S)
    return m.group(0) + "\n\n" if m else ""


def write_text(path: Path, text: str) -> None:
    tmp = path.with_name(f".{path.name}.partial")
    tmp.write_text(text)
    os.replace(tmp, path)


def write_outputs(results: dict, out: str) -> list[Path]:
    """OUT.json, OUT.md and OUT_figure.png, each written beside and renamed into place."""
    import matplotlib
    matplotlib.use("Agg")
    from evinr_lite.viz import plot_robustness

    base = Path(out)
    png = base.with_name(base.name.replace("_results", "") + "_figure.png")    # robustness_figure.png
    js, md = base.with_suffix(".json"), base.with_suffix(".md")
    write_json(js, results)
    write_text(md, "# Robustness sweeps\n\n" + kept_interpretation(md) + markdown(results) + "\n")
    fig = plot_robustness(results)
    tmp = png.with_name(f".{png.stem}.partial.png")
    fig.savefig(tmp, dpi=110)
    os.replace(tmp, png)
    import matplotlib.pyplot as plt
    plt.close(fig)
    return [js, md, png]


def target_rows(results: dict) -> list[dict]:
    """Rows for ``python -m benchmarks``: the kit's and the best baseline's retained CLAHE-SSIM per sweep (info)."""
    rows = []
    for s, sw in results["sweeps"].items():
        kit = retained(sw, "kit") if "kit" in sw["means"] else None
        base = {m: retained(sw, m) for m in ("integration", "hf") if m in sw["means"]}
        base = {m: v for m, v in base.items() if v is not None}
        if kit is not None:
            note = ", ".join(f"{m} {v:.2f}" for m, v in base.items())
            rows.append(row(f"robustness {s}: kit CLAHE-SSIM worst level / clean", kit, "x", note=note))
    return rows


def run(quick_run: bool = False, log=print) -> list[dict]:
    """``python -m benchmarks --only robustness`` calls this: the full sweep (or --quick) and its rows."""
    return target_rows(sweep_main(["--quick"] if quick_run else [], log=log))


def main(argv=None) -> int:
    sweep_main(argv)
    return 0


def sweep_main(argv=None, log=print) -> dict:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help="one small scene (camera_translate at 3/5 size), 3 levels "
                                                        "a sweep, no paper recipe (< 1 min)")
    p.add_argument("--scenes", default=None, help=f"comma-separated zoo scenes (default: {','.join(SCENES)}; "
                                                  "--quick: camera_translate)")
    p.add_argument("--methods", default=None, help=f"comma-separated, from {','.join(METHODS)} (default: all; "
                                                   "--quick: all but paper)")
    p.add_argument("--paper-levels", type=int, default=2, help="levels a sweep for the paper recipe, spread over "
                                                               "the sweep, plus the clean one (0: skip it; default 2: "
                                                               "both ends)")
    p.add_argument("--paper-scenes", default="camera_translate", help="comma-separated scenes the paper recipe runs "
                                                                      "on, or 'all' (default: camera_translate)")
    p.add_argument("--out", default=None, help="output path without suffix (default: benchmarks/robustness_results, "
                                               "--quick: benchmarks/robustness_results_quick)")
    a = p.parse_args(argv)
    names = a.scenes.split(",") if a.scenes else (["camera_translate"] if a.quick else list(SCENES))
    zoo = {z.name: z for z in ZOO}
    bad = [n for n in names if n not in zoo]
    if bad:
        p.error(f"unknown scenes {bad}; the zoo holds {list(zoo)}")
    methods = a.methods.split(",") if a.methods else [m for m in METHODS if not (a.quick and m == "paper")]
    bad = [m for m in methods if m not in METHODS]
    if bad:
        p.error(f"unknown methods {bad}; choose from {list(METHODS)}")
    paper_scenes = None if a.paper_scenes == "all" else a.paper_scenes.split(",")
    if "paper" in methods and paper_scenes is not None and not set(paper_scenes) & set(names):
        p.error(f"--paper-scenes {a.paper_scenes} names none of the scenes run ({names}); add them or use 'all'")
    if a.paper_levels < 0:
        p.error(f"--paper-levels must be >= 0, got {a.paper_levels}")
    if a.paper_levels == 0 and "paper" in methods:
        methods.remove("paper")
    out = a.out or ("benchmarks/robustness_results_quick" if a.quick else "benchmarks/robustness_results")
    if not Path(out).parent.is_dir():                  # check before the long work, not after it
        p.error(f"--out {out}: folder {Path(out).parent} does not exist; create it or choose another")
    scenes = [quick(zoo[n]) if a.quick else zoo[n] for n in names]
    t0 = time.perf_counter()
    results = run_sweeps(scenes, methods, QUICK_LEVELS if a.quick else LEVELS, a.paper_levels, paper_scenes, log=log)
    command = " ".join(["python benchmarks/robustness.py"] + list(sys.argv[1:] if argv is None else argv))
    results.update(quick=a.quick, paper_levels=a.paper_levels, paper_scenes=paper_scenes or names, seconds=time.perf_counter() - t0, command=command)
    md = markdown(results)
    log("\n" + md)
    for path in write_outputs(results, out):
        log(f"wrote {path}")
    return results


if __name__ == "__main__":
    sys.exit(main())
