"""The scene zoo: reconstruction quality and time on scenes nobody tuned to, against the baselines.

    python benchmarks/quality_zoo.py                       # every short scene, every method (15-20 min on 2 cores)
    python benchmarks/quality_zoo.py --long                # also the 20 s and 60 s recordings (about 15 min more)
    python benchmarks/quality_zoo.py --quick               # smaller sensors, shorter scenes (a few minutes)
    python benchmarks/quality_zoo.py --heldout             # the held-out scenes no default was chosen on
    python benchmarks/quality_zoo.py --stress              # scenes with settings outside both sets' ranges
    python benchmarks/quality_zoo.py --large               # three scenes at 360x480 (4x the zoo's largest)
    python benchmarks/quality_zoo.py --fresh 11            # 16 scenes drawn at random the zoo's ways (--n-fresh N)
    python benchmarks/quality_zoo.py --scenes camera_translate,noisy_gravel --methods kit,integration
    python benchmarks/quality_zoo.py --variant "lam 0.1=lam=0.1"        # add an EvINR variant (NAME=field=value,...)
    python -m benchmarks --only zoo                        # the same, from the benchmark runner

Each scene is seeded and documented in one line in ``evinr_lite.sim.zoo.ZOO``; together they vary texture
(natural images, a low-texture scene, printed text), motion (translation, rotation + zoom, shear and
perspective, non-uniform speed, a static camera with an object moving over a static background,
to-and-fro pans, hand-held shake), light (a global change, vignetting, a scene going dark), the sensor
(background activity, background activity growing as light falls, hot pixels incl. ON-only ones,
C+ != C- given as one nominal C, threshold mismatch and drift, a refractory period), size (120x160 to
180x240) and length (2-8 s; with ``--long`` also 20 s and 60 s at an IJRR-like event rate). The real
IJRR slider_depth chunk beside the project is scored too when present. ``--heldout`` scores instead
``evinr_lite.sim.zoo.HELDOUT``: ten scenes (one of 20 s) built the same ways with other images, motions and seeds,
on which no default was chosen (they check that the defaults carry over; the real chunk is skipped,
and the results go to ``zoo_results_heldout.*``). ``--stress`` scores ``evinr_lite.sim.zoo.STRESS`` the
same way: eleven scenes built the same ways with settings outside both sets' ranges (a threshold of 0.1
or 0.45, 64x64 and 90x320 sensors, a speed that nearly stops, 2 Hz of background activity, an OFF-heavy
pair, 15 % mismatch, a bar sweeping over a flat background); results in ``zoo_results_stress.*``.
``--large`` scores ``evinr_lite.sim.zoo.LARGE``: three scenes at 360x480 (twice the zoo's largest sensor
along each side, motions and hot pixels scaled with it); results in ``zoo_results_large.*``.
``--fresh SEED`` scores ``evinr_lite.sim.zoo.fresh(SEED, N)``: N scenes (16 by default) drawn at random
from the zoo's scene classes, images, motions and sensor faults, none of which anyone looked at
before the run; results in ``zoo_results_fresh.*`` (the seed in the JSON).

Methods: ``kit`` (``EvINRConfig()``, the kit's default), ``paper`` (``EvINRConfig.paper()``, the
paper's recipe exactly), ``v0_1`` (the kit's default before the zoo; paper and v0_1 are skipped on the
long scenes, minutes each), the baselines ``integration`` and ``hf`` at their defaults, ``hf_best`` and
``leaky_best`` (HF's cutoff and leaky integration's leak swept per scene, 0.03-3 Hz, the best by
CLAHE-SSIM against the truth: tuned with the answer in hand, which the kit never has; the sweep is in
the JSON and the markdown), ``integration_offset`` (integration + the kit's own offset solve,
``EvINRConfig().offset_solve``: what the INR must beat), ``kit_windows`` (long scenes: the kit on independent 2 s windows),
``kit_unfiltered`` (only when named in ``--methods``: the kit with ``background="keep"``, its default
before the background filter), and the
oracle: the events integrated from the true frame at the first scored time, as linear intensity with
the true level (``oracle_linear``) and shown by the display with its level anchored like every
method's (``oracle_tonemapped``). The oracle is what the events carry once the unknown per-pixel offset
is given; no method sees that frame. Every method is shown by the kit's display (``DISPLAY``: its tone
map and level, ``EvINRConfig().tonemap`` and ``display_mean``): paper and v0_1 train their recipes
exactly and are displayed like the kit, so the rows differ by the reconstruction alone.

Every method is scored at 10 ground-truth times (2 per second on long scenes) through
``evinr_lite.evaluation.score_sequence`` under both protocols (no equalisation, and CLAHE on both
images), with MSE beside the SSIMs and the level error (mean prediction minus mean truth) per quarter
of the recording, and what each MSE is made of (``evinr_lite.evaluation.error_parts``): the MSE at the
truth's level (the one gain over the recording that events never give, set from the truth) and its
static part coarser than 8 px (the per-pixel offsets' large-scale error), with both SSIMs at the
truth's level; three diagnostic rows, beside the issue's own targets, compare the kit with the best
baseline and with v0_1 at the truth's level, and give the long scenes' level error at it (drift). The best baseline is the best of hf_best, leaky_best and integration_offset. The
issue's targets (issue 21) are printed at the end and stored in the JSON ("targets"). Writes JSON
(``--json``), a markdown table (``--md``) and one figure (``--figure``: ground truth and every method
at mid-sequence on four scenes).
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from evinr_lite.core.events import Events  # noqa: E402
from evinr_lite.evaluation.level import error_parts  # noqa: E402
from evinr_lite.evaluation.metrics import SCORE_PROTOCOLS  # noqa: E402
from evinr_lite.evaluation.scoring import frames_to_score, score_sequence  # noqa: E402
from evinr_lite.method import EvINRConfig, integrate_events, reconstruct, reconstruct_baseline  # noqa: E402
from evinr_lite.method.tonemap import anchor_mean, to_display  # noqa: E402
from evinr_lite.sim.zoo import HELDOUT, LARGE, STRESS, ZOO, default_scenes, effective_C, quick, simulate  # noqa: E402
from evinr_lite.sim.zoo import fresh as zoo_fresh  # noqa: E402

BASELINES = ("integration", "hf")                   # the baselines at their default settings
SWEPT = ("hf_best", "leaky_best")                   # HF's cutoff / leaky integration's leak picked per scene
NAMED = ("integration_offset",)                     # integration + the kit's own offset solve
BEST_OF = SWEPT + NAMED                             # the baselines the kit must beat (issue 21)
ORACLES = ("oracle_linear", "oracle_tonemapped")
EVINR = ("kit", "paper", "v0_1")
WINDOWED = ("kit_windows",)                         # long scenes: the kit on independent 2 s windows
METHODS = EVINR + BASELINES + SWEPT + NAMED + ORACLES + WINDOWED
OPTIONAL = ("kit_unfiltered",)                     # on request only: the kit without its background filter
EXTRA = NAMED                                       # kept for older callers (robustness, denoise)
SLOW = ("paper", "v0_1")                            # trained recipes: skipped on long scenes (minutes each)
SWEEP = {"hf_best": ("hf", "cutoff_hz", (0.03, 0.1, 0.3, 1.0, 3.0)),
         "leaky_best": ("leaky", "leak_hz", (0.03, 0.1, 0.3, 1.0, 3.0))}
WINDOW_S = 2.0
# every method is shown by the kit's display (tone map and level), so the rows differ by the reconstruction
# alone: the trained recipes (paper, v0_1) too, though their presets keep the paper's Reinhard display
DISPLAY = {"tonemap": EvINRConfig().tonemap, "display_mean": EvINRConfig().display_mean}


def evinr_config(name: str, C, variants: dict) -> EvINRConfig:
    base = {"kit": EvINRConfig, "paper": EvINRConfig.paper, "v0_1": EvINRConfig.v0_1,
            "kit_unfiltered": lambda **kw: EvINRConfig(background="keep", **kw)}
    if name in base:
        return base[name](C=C, progress=False, **DISPLAY)
    return EvINRConfig(**{**variants[name], "C": C, "progress": False})


def windowed(events: Events, times: np.ndarray, C, variants: dict, name: str = "kit", window: float = WINDOW_S):
    """frames [Q, H, W]: ``name`` run on independent windows of ``window`` seconds, each query time
    answered by the window that holds it (what a user gets by cutting the recording up)."""
    t0, t1 = float(min(events.t[0], times.min())), float(max(events.t[-1], times.max()))
    n = max(1, int(round((t1 - t0) / window)))
    edges = np.linspace(t0, t1, n + 1)
    out = np.empty((len(times), *events.sensor_size), np.float32)
    k = np.clip(np.searchsorted(edges, times, side="right") - 1, 0, n - 1)
    for i in np.unique(k):
        sel = k == i
        ev = events.slice_time(edges[i], np.nextafter(edges[i + 1], np.inf), allow_empty=True)
        out[sel] = reconstruct(ev, times[sel], evinr_config(name, C, variants), t_start=edges[i],
                               t_end=edges[i + 1]).frames
    return out


def sweep_baseline(name: str, events: Events, times, C, gt) -> tuple[np.ndarray, dict]:
    """(frames of the best setting by CLAHE-SSIM against the ground truth, {setting: scores, "best"}):
    the baseline tuned per scene with the truth in hand (fair to the baseline; the kit has no truth)."""
    method, param, values = SWEEP[name]
    table, best, best_frames = {}, -np.inf, None
    for v in values:
        f = reconstruct_baseline(events, times, method, C=C, **{param: v}).frames
        sc = score(f, times, gt, times)
        table[f"{v:g}"] = {k: sc[k] for k in ("ssim_clahe", "ssim_none", "mse_none")}
        if sc["ssim_clahe"] > best:
            best, best_frames, table["best"] = sc["ssim_clahe"], f, f"{param}={v:g}"
    return best_frames, table


def run_method(name: str, events: Events, times: np.ndarray, C, variants: dict, L_first=None, gt=None):
    """(frames [Q, H, W] in [0, 1], seconds) of one method. A swept baseline (hf_best, leaky_best) needs
    the ground truth ``gt`` and leaves its sweep in ``run_method.last_sweep`` (else None)."""
    t0 = time.perf_counter()
    run_method.last_sweep = None
    if name in BASELINES:
        frames = reconstruct_baseline(events, times, name, C=C).frames
    elif name in SWEPT:
        frames, run_method.last_sweep = sweep_baseline(name, events, times, C, gt)
    elif name == "integration_offset":
        frames = reconstruct_baseline(events, times, "integration", C=C,
                                      offset_solve=EvINRConfig().offset_solve).frames
    elif name in ORACLES:
        L = L_first + integrate_events(events, times, C=C) - integrate_events(events, times[:1], C=C)
        frames = (np.clip(np.exp(L), 0, 1) if name == "oracle_linear" else
                  to_display(anchor_mean(L, **DISPLAY), DISPLAY["tonemap"]))
    elif name in WINDOWED:
        frames = windowed(events, times, C, variants)
    else:
        frames = reconstruct(events, times, evinr_config(name, C, variants)).frames
    return np.asarray(frames, np.float32), time.perf_counter() - t0


run_method.last_sweep = None


def score(frames, times, gt, gt_t) -> dict:
    out = {}
    for eq in SCORE_PROTOCOLS:
        s = score_sequence(frames, times, gt, gt_t, eq, lpips_model=False)
        out[f"mse_{eq}"], out[f"ssim_{eq}"] = s["mse"], s["ssim"]
    return out


def level_scores(frames, times, gt, duration: float | None = None) -> dict:
    """What each MSE is made of (:func:`evinr_lite.evaluation.error_parts`: the MSE at the truth's level, its
    static part coarser than 8 px, the level's gain), both SSIMs at the truth's level (a level shown too
    bright also clips highlights, which CLAHE does not undo) and, given the recording's ``duration``,
    the level error per quarter at the truth's level: drift alone. ``frames`` [Q, H, W] are predictions at
    the ground-truth frames ``gt`` [Q, H, W], both at ``times``."""
    parts = error_parts(frames, gt)
    out = {"mse_at_level": parts["mse_at_level"], "static_coarse": parts["static_coarse"], "level_gain": parts["gain"]}
    for eq in SCORE_PROTOCOLS:
        out[f"ssim_{eq}_at_level"] = score_sequence(parts["matched"].astype(np.float32), times, gt, times, eq,
                                                    lpips_model=False)["ssim"]
    if duration is not None:
        out["level_error_at_level"] = level_error(parts["matched"], gt, times, duration)
    return out


def level_error(frames, gt, times, duration: float) -> list:
    """Mean prediction minus mean truth (display units, [0, 1]) in each quarter of [0, duration]:
    float [4] (None for a quarter without a scored time)."""
    q = np.clip((np.asarray(times) / duration * 4).astype(int), 0, 3)
    d = np.asarray(frames, np.float64).mean(axis=(1, 2)) - np.asarray(gt, np.float64).mean(axis=(1, 2))
    return [float(d[q == i].mean()) if np.any(q == i) else None for i in range(4)]


def summarise(rows: dict) -> dict:
    """Per-scene ratios: kit against the best baseline (best HF, best leaky, integration + offset; CLAHE-SSIM
    and MSE), the oracle, v0.1, integration + offset, and its own independent windows (long scenes)."""
    kit = rows.get("kit")
    base = {m: rows[m] for m in BEST_OF if m in rows} or {m: rows[m] for m in BASELINES if m in rows}
    orac = [rows[m] for m in ORACLES if m in rows]
    out = {}
    if kit and base:
        best_c = max(b["ssim_clahe"] for b in base.values())
        best_n = max(b["ssim_none"] for b in base.values())
        best_m = min(b["mse_none"] for b in base.values())
        out.update(best_baseline=max(base, key=lambda m: base[m]["ssim_clahe"]), best_baseline_clahe=best_c,
                   kit_over_best_baseline_clahe=kit["ssim_clahe"] / best_c,
                   kit_plain_ssim_minus_best_baseline=kit["ssim_none"] - best_n,
                   kit_mse_over_best_baseline_mse=kit["mse_none"] / best_m)
        if "mse_at_level" in kit and all("mse_at_level" in b for b in base.values()):
            best_l = min(base, key=lambda m: base[m]["mse_at_level"])
            out.update(best_baseline_at_level=best_l,
                       kit_mse_at_level_over_best_baseline=kit["mse_at_level"] / base[best_l]["mse_at_level"])
    if kit and orac:
        out["kit_over_oracle_clahe"] = kit["ssim_clahe"] / max(o["ssim_clahe"] for o in orac)
    if orac:
        out["oracle_clahe"] = max(o["ssim_clahe"] for o in orac)
    if kit and "integration_offset" in rows:
        out["kit_over_integration_offset_clahe"] = kit["ssim_clahe"] / rows["integration_offset"]["ssim_clahe"]
    if kit and "v0_1" in rows:
        v = rows["v0_1"]
        out.update(kit_minus_v0_1_clahe=kit["ssim_clahe"] - v["ssim_clahe"],
                   kit_minus_v0_1_ssim=kit["ssim_none"] - v["ssim_none"],
                   kit_mse_minus_v0_1=kit["mse_none"] - v["mse_none"],
                   kit_time_over_v0_1=kit["time_s"] / max(v["time_s"], 1e-9))
        if "mse_at_level" in kit and "mse_at_level" in v:
            out.update(kit_mse_at_level_minus_v0_1=kit["mse_at_level"] - v["mse_at_level"],
                       kit_minus_v0_1_clahe_at_level=kit["ssim_clahe_at_level"] - v["ssim_clahe_at_level"],
                       kit_minus_v0_1_ssim_at_level=kit["ssim_none_at_level"] - v["ssim_none_at_level"])
    if kit and kit.get("level_error"):
        out["kit_level_error_max_abs"] = max(abs(v) for v in kit["level_error"] if v is not None)
    if kit and kit.get("level_error_at_level"):
        out["kit_level_error_at_level_max_abs"] = max(abs(v) for v in kit["level_error_at_level"] if v is not None)
    if kit and "kit_windows" in rows:
        w = rows["kit_windows"]
        out.update(whole_minus_windows_clahe=kit["ssim_clahe"] - w["ssim_clahe"],
                   whole_minus_windows_ssim=kit["ssim_none"] - w["ssim_none"],
                   whole_mse_minus_windows=kit["mse_none"] - w["mse_none"])
    return out


def run_zoo(scenes, methods, variants, log=print) -> dict:
    results = {}
    for z in scenes:
        scene, events, times, gt = simulate(z)
        C = effective_C(z)
        L_first = scene.log_intensity(times[0])
        log(f"{z.name}: {z.size[0]}x{z.size[1]}, {z.duration:g} s, {len(events):,} events ({z.doc})")
        rows, frames = {}, {}
        for m in methods:
            if (z.long and m in SLOW) or (m in WINDOWED and not z.long):
                continue
            f, seconds = run_method(m, events, times, C, variants, L_first, gt)
            rows[m] = {**score(f, times, gt, times), **level_scores(f, times, gt, z.duration), "time_s": seconds,
                       "level_error": level_error(f, gt, times, z.duration)}
            if run_method.last_sweep is not None:
                rows[m]["sweep"] = run_method.last_sweep
            frames[m] = f[len(f) // 2]
            lv = " ".join(f"{v:+.3f}" for v in rows[m]["level_error"] if v is not None)
            log(f"    {m:<22s} SSIM {rows[m]['ssim_none']:.3f}  CLAHE-SSIM {rows[m]['ssim_clahe']:.3f}  "
                f"MSE {rows[m]['mse_none']:.4f}  level/quarter {lv}  {seconds:6.1f} s"
                + (f"  ({run_method.last_sweep['best']})" if run_method.last_sweep else ""))
        results[z.name] = {"doc": z.doc, "size": list(z.size), "duration_s": z.duration, "n_events": len(events),
                           "noise_free": z.noise_free, "long": z.long, "C_given": C, "rows": rows,
                           "summary": summarise(rows), "figure": {"gt": gt[len(gt) // 2], **frames}}
    return results


def real_chunk(log=print):
    """(recording, scored frames [K, H, W], their times [K]) of the IJRR slider_depth chunk beside the
    project, or None (with a note) when it is not there. Shared by the benchmarks that score on it."""
    from evinr_lite.io.readers import read_recording
    from evinr_lite.io.sample_data import sample_recording_path

    path = sample_recording_path()
    if path is None:
        log("real chunk: not found (shared/data/ijrr_slider_depth_chunk); skipped")
        return None
    rec = read_recording(path)
    idx = frames_to_score(rec.frames.t, rec.events)
    return rec, rec.frames.images[idx], rec.frames.t[idx]


def run_real(methods, variants, log=print) -> dict | None:
    """The IJRR slider_depth chunk beside the project, C = 1 (the paper's for IJRR); no oracle."""
    found = real_chunk(log)
    if found is None:
        return None
    rec, gt, gt_t = found
    log(f"real slider_depth chunk: {len(rec.events):,} events, {len(gt_t)} frames")
    rows, frames = {}, {}
    for m in [m for m in methods if m not in ORACLES and m not in WINDOWED]:
        f, seconds = run_method(m, rec.events, gt_t, 1.0, variants, gt=gt)
        rows[m] = {**score(f, gt_t, gt, gt_t), **level_scores(f, gt_t, gt), "time_s": seconds}
        if run_method.last_sweep is not None:
            rows[m]["sweep"] = run_method.last_sweep
        frames[m] = f[len(f) // 2]
        log(f"    {m:<22s} SSIM {rows[m]['ssim_none']:.3f}  CLAHE-SSIM {rows[m]['ssim_clahe']:.3f}  "
            f"MSE {rows[m]['mse_none']:.4f}  {seconds:6.1f} s"
            + (f"  ({run_method.last_sweep['best']})" if run_method.last_sweep else ""))
    return {"doc": "IJRR slider_depth chunk (real DAVIS240C), C = 1", "rows": rows, "summary": summarise(rows),
            "figure": {"gt": gt[len(gt) // 2].astype(np.float32) / 255.0, **frames}}


def markdown(results: dict, methods) -> str:
    cols = ("kit_over_best_baseline_clahe", "kit_mse_over_best_baseline_mse", "kit_over_oracle_clahe",
            "kit_over_integration_offset_clahe")
    lines = ["| scene | " + " | ".join(methods) + " | kit / best baseline (CLAHE) | kit MSE / best baseline's | "
             "kit / oracle (CLAHE) | kit / integration+offset (CLAHE) |",
             "|---" * (len(methods) + 5) + "|"]
    for name, r in results.items():
        cells = []
        for m in methods:
            row = r["rows"].get(m)
            cells.append("-" if row is None else f"{row['ssim_clahe']:.3f} / {row['ssim_none']:.3f} / "
                                                 f"{row['mse_none']:.4f} / {row['time_s']:.1f} s")
        s = r["summary"]
        lines.append(f"| {name} | " + " | ".join(cells) + " | "
                     + " | ".join(f"{s[k]:.3f}" if k in s else "-" for k in cols) + " |")
    synth = {n: r for n, r in results.items() if n != "real_slider_chunk"}
    means = []
    for m in methods:
        vals = [r["rows"][m] for r in synth.values() if m in r["rows"] and not r.get("long")]
        means.append("-" if not vals else f"{np.mean([v['ssim_clahe'] for v in vals]):.3f} / "
                                          f"{np.mean([v['ssim_none'] for v in vals]):.3f} / "
                                          f"{np.mean([v['mse_none'] for v in vals]):.4f} / "
                                          f"{np.mean([v['time_s'] for v in vals]):.1f} s")
    lines.append("| **zoo mean (short scenes)** | " + " | ".join(means) + " | | | | |")
    lines += ["", "Cells: CLAHE-SSIM / SSIM / MSE (no equalisation) / wall time. Scored at 10 ground-truth times per "
              "scene (2 per second on long ones) through evinr_lite.evaluation.score_sequence (SSIM: gaussian sigma "
              "1.5, data_range 1; CLAHE: cv2, clip 2.0, 8x8 tiles, on both images). hf_best / leaky_best: the "
              "cutoff / leak picked per scene by CLAHE-SSIM against the ground truth (sweep below); the best baseline "
              "is the best of hf_best, leaky_best and integration_offset. The mean is over the short scenes (the "
              "long ones skip paper and v0_1).", "",
              "Level error (mean prediction minus mean truth, display units) per quarter of each recording:", ""]
    lines += quarter_table(synth, methods, "level_error")
    if any("level_error_at_level" in row for r in synth.values() for row in r["rows"].values()):
        lines += ["", "The same at the truth's level (each method's one gain over the recording set from the truth, "
                  "as in the MSE parts below): what is left is drift within the recording:", ""]
        lines += quarter_table(synth, methods, "level_error_at_level")
    if any("mse_at_level" in row for r in results.values() for row in r["rows"].values()):
        lines += ["", "What each MSE is made of (evinr_lite.evaluation.error_parts), and the SSIMs at the truth's "
                  "level: CLAHE-SSIM / SSIM / MSE of the prediction times the one gain over the recording that gives it "
                  "the truth's mean (the level events never give; a level shown too bright also clips highlights) / of "
                  "that MSE, the static part coarser than 8 px (the error's temporal mean, Gaussian sigma 8 px: the "
                  "per-pixel offsets' large-scale error) / the gain (1 = the truth's level; above 1: shown too dark):",
                  "",
                  "| scene | " + " | ".join(methods) + " |", "|---" * (len(methods) + 1) + "|"]
        for name, r in results.items():
            cells = []
            for m in methods:
                row = r["rows"].get(m, {})
                cells.append("-" if "mse_at_level" not in row else
                             f"{row['ssim_clahe_at_level']:.3f} / {row['ssim_none_at_level']:.3f} / "
                             f"{row['mse_at_level']:.4f} / {row['static_coarse']:.4f} / {row['level_gain']:.2f}")
            lines.append(f"| {name} | " + " | ".join(cells) + " |")
    sweeps = [(n, m, r["rows"][m]["sweep"]) for n, r in results.items() for m in SWEPT
              if m in r["rows"] and r["rows"][m].get("sweep")]
    if sweeps:
        lines += ["", "Baseline sweeps (CLAHE-SSIM / SSIM / MSE per setting; the best by CLAHE-SSIM is used):", "",
                  "| scene | baseline | " + " | ".join(f"{SWEEP[m][1]} {v:g}" for m in SWEPT[:1]
                                                        for v in SWEEP[m][2]) + " | best |",
                  "|---" * (len(SWEEP[SWEPT[0]][2]) + 3) + "|"]
        for n, m, sw in sweeps:
            vals = [sw.get(f"{v:g}") for v in SWEEP[m][2]]
            lines.append(f"| {n} | {m} | " + " | ".join(
                "-" if c is None else f"{c['ssim_clahe']:.3f} / {c['ssim_none']:.3f} / {c['mse_none']:.4f}"
                for c in vals) + f" | {sw['best']} |")
        lines.append("")
        lines.append("Columns are the five settings in order: " + "; ".join(
            f"{m} {SWEEP[m][1]} = {', '.join(f'{v:g}' for v in SWEEP[m][2])} Hz" for m in SWEPT) + ".")
    return "\n".join(lines)


def quarter_table(results: dict, methods, key: str) -> list[str]:
    """Markdown lines: a scene per row, a method per column, each cell the four quarters of ``key``."""
    lines = ["| scene | " + " | ".join(methods) + " |", "|---" * (len(methods) + 1) + "|"]
    for name, r in results.items():
        cells = []
        for m in methods:
            lv = r["rows"].get(m, {}).get(key)
            cells.append("-" if not lv else " ".join("-" if v is None else f"{v:+.3f}" for v in lv))
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return lines


def figure(results: dict, names, methods, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cols = ["gt"] + [m for m in methods]
    fig, axes = plt.subplots(len(names), len(cols), figsize=(1.9 * len(cols), 1.7 * len(names)), squeeze=False)
    for i, n in enumerate(names):
        for j, m in enumerate(cols):
            ax = axes[i, j]
            img = results[n]["figure"].get(m)
            if img is not None:
                ax.imshow(img, cmap="gray", vmin=0, vmax=1)
            ax.set_xticks([]), ax.set_yticks([])
            if i == 0:
                ax.set_title("ground truth" if m == "gt" else m, fontsize=9)
            if j == 0:
                ax.set_ylabel(n, fontsize=9)
    fig.suptitle("The scene zoo at mid-sequence (no equalisation)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def target_rows(results: dict) -> list[dict]:
    """The issue's targets (issue 21) as rows of the benchmark table (benchmarks/common.row)."""
    from benchmarks.common import row

    synth = {n: r for n, r in results.items() if n != "real_slider_chunk"}
    rows = []

    def summary(key, which=lambda r: True):
        got = {n: r["summary"].get(key) for n, r in synth.items() if which(r)}
        return {n: v for n, v in got.items() if v is not None}

    ratios = summary("kit_over_best_baseline_clahe")
    if ratios:
        worst = min(ratios, key=ratios.get)
        rows.append(row("zoo: kit CLAHE-SSIM / best baseline's, worst scene", ratios[worst], "x", 1.10,
                        note=f"worst: {worst}; {sum(v >= 1.10 for v in ratios.values())} of {len(ratios)} scenes >= 1.10"))
        # how far the 1.10x target can be met at all: the oracle (the events integrated from the true
        # first frame) is what the events carry once the unknown offset is given
        above = sorted(n for n, r in synth.items() if r["summary"].get("oracle_clahe") is not None
                       and "best_baseline_clahe" in r["summary"]
                       and 1.10 * r["summary"]["best_baseline_clahe"] > r["summary"]["oracle_clahe"])
        rows.append(row("zoo: scenes where 1.10x the best baseline exceeds the oracle's CLAHE-SSIM", len(above),
                        "scenes", note=", ".join(above) or "none"))
    mse = summary("kit_mse_over_best_baseline_mse")
    if mse:
        worst = max(mse, key=mse.get)
        rows.append(row("zoo: kit MSE / best baseline's, worst scene", mse[worst], "x", 1.0, higher_is_better=False,
                        note=f"worst: {worst}; {sum(v <= 1.0 for v in mse.values())} of {len(mse)} scenes <= 1"))
    at_level = summary("kit_mse_at_level_over_best_baseline")
    if at_level:   # a diagnostic, not the target: each method's level set to the truth's (evaluation.level)
        worst = max(at_level, key=at_level.get)
        rows.append(row("zoo (diagnostic): kit MSE / best baseline's, each at the truth's level, worst scene",
                        at_level[worst], "x", 1.0, higher_is_better=False,
                        note=f"worst: {worst}; {sum(v <= 1.0 for v in at_level.values())} of {len(at_level)} "
                             "scenes <= 1 once the level events never give is removed"))
    level = summary("kit_level_error_max_abs", lambda r: r.get("long"))
    if level:
        worst = max(level, key=level.get)
        rows.append(row("long scenes: kit |level error| per quarter, worst", level[worst], "", 0.05,
                        higher_is_better=False, note=f"worst: {worst}"))
    drift = summary("kit_level_error_at_level_max_abs", lambda r: r.get("long"))
    if drift:      # a diagnostic: the recording's one gain set from the truth, what is left is drift
        worst = max(drift, key=drift.get)
        rows.append(row("long scenes (diagnostic): kit |level error| per quarter at the truth's level, worst",
                        drift[worst], "", 0.05, higher_is_better=False,
                        note=f"worst: {worst}; the level over the whole recording set from the truth, the rest is drift"))
    whole = {n: r["rows"]["kit"]["ssim_clahe"] / r["rows"]["kit_windows"]["ssim_clahe"] for n, r in synth.items()
             if "kit" in r["rows"] and "kit_windows" in r["rows"]}
    if whole:
        worst = min(whole, key=whole.get)
        mse_ok = sum(synth[n]["summary"]["whole_mse_minus_windows"] <= 0 for n in whole)
        rows.append(row("long scenes: whole recording / independent 2 s windows (CLAHE-SSIM), worst", whole[worst],
                        "x", 1.0, note=f"worst: {worst}; MSE no higher on {mse_ok} of {len(whole)}"))
    oracle = summary("kit_over_oracle_clahe", lambda r: r["noise_free"])
    if oracle:
        worst = min(oracle, key=oracle.get)
        rows.append(row("zoo: kit / oracle CLAHE-SSIM, worst noise-free scene", oracle[worst], "x", 0.95,
                        note=f"worst: {worst}; mean {np.mean(list(oracle.values())):.3f}"))
    noisy = {n: r["summary"] for n, r in synth.items() if not r["noise_free"] and "kit_minus_v0_1_clahe" in r["summary"]}
    if noisy:
        ok = [n for n, s in noisy.items() if s["kit_minus_v0_1_clahe"] >= 0 and s["kit_minus_v0_1_ssim"] >= 0
              and s["kit_mse_minus_v0_1"] <= 0]
        rows.append(row("noisy scenes: kit >= v0.1 in CLAHE-SSIM, SSIM and MSE", len(ok), "scenes", len(noisy),
                        note="short of it: " + (", ".join(sorted(set(noisy) - set(ok))) or "none")))
        if not ok:                                       # row() leaves a measured 0 unjudged; 0 of n is not met
            rows[-1].update(met=False, ratio=0.0)
        lv = {n: s for n, s in noisy.items() if "kit_mse_at_level_minus_v0_1" in s}
        if lv:
            ok_l = sorted(n for n, d in lv.items() if d["kit_minus_v0_1_clahe_at_level"] >= 0
                          and d["kit_minus_v0_1_ssim_at_level"] >= 0 and d["kit_mse_at_level_minus_v0_1"] <= 0)
            rows.append(row("noisy scenes (diagnostic): kit >= v0.1 in CLAHE-SSIM, SSIM and MSE, each at the truth's "
                            "level", len(ok_l), "scenes", len(lv),
                            note="short of it: " + (", ".join(sorted(set(lv) - set(ok_l))) or "none")))
            if not ok_l:
                rows[-1].update(met=False, ratio=0.0)
        slow = max(noisy, key=lambda n: noisy[n]["kit_time_over_v0_1"])
        rows.append(row("noisy scenes: kit time / v0.1 time, worst", noisy[slow]["kit_time_over_v0_1"], "x", 0.2,
                        higher_is_better=False, note=f"worst: {slow}"))
    short = [r["rows"] for r in synth.values() if not r.get("long") and "kit" in r["rows"]
             and "integration_offset" in r["rows"]]
    if short:
        k = np.mean([r["kit"]["ssim_clahe"] for r in short])
        i = np.mean([r["integration_offset"]["ssim_clahe"] for r in short])
        rows.append(row("zoo mean: kit CLAHE-SSIM / integration + offset's", k / i, "x", 1.05,
                        note=f"{k:.3f} vs {i:.3f} over {len(short)} short scenes"))
    both = [r["rows"] for r in synth.values() if "kit" in r["rows"] and "v0_1" in r["rows"]]
    if both:
        t_old, t_new = sum(r["v0_1"]["time_s"] for r in both), sum(r["kit"]["time_s"] for r in both)
        q_old = np.mean([r["v0_1"]["ssim_clahe"] for r in both])
        q_new = np.mean([r["kit"]["ssim_clahe"] for r in both])
        rows.append(row("zoo: v0.1 default time / kit default time (same run)", t_old / t_new, "x", 5.0,
                        note=f"zoo-mean CLAHE-SSIM {q_new:.3f} (kit) vs {q_old:.3f} (v0.1); "
                             f"{t_new:.0f} s vs {t_old:.0f} s in all"))
    if "camera_240x180" in synth and "kit" in synth["camera_240x180"]["rows"]:
        rows.append(row("zoo: kit default on 240x180, 2 s (camera_240x180), wall time",
                        synth["camera_240x180"]["rows"]["kit"]["time_s"], "s", 3.0, higher_is_better=False))
    real = results.get("real_slider_chunk")
    pool = BEST_OF + BASELINES
    if real and "kit" in real["rows"] and any(m in real["rows"] for m in pool):
        for eq, label in (("clahe", "CLAHE-SSIM"), ("none", "SSIM")):
            best = max(pool, key=lambda m: real["rows"][m][f"ssim_{eq}"] if m in real["rows"] else -1)
            rows.append(row(f"real slider chunk: kit {label} / best baseline's",
                            real["rows"]["kit"][f"ssim_{eq}"] / real["rows"][best][f"ssim_{eq}"], "x", 1.0,
                            note=f"best: {best}"))
        if "integration_offset" in real["rows"]:
            rows.append(row("real slider chunk: kit CLAHE-SSIM / integration + offset's",
                            real["rows"]["kit"]["ssim_clahe"] / real["rows"]["integration_offset"]["ssim_clahe"],
                            "x", 1.05))
    return rows


def run(quick: bool = False, log=print) -> list[dict]:
    """The whole zoo (``python -m benchmarks`` calls this): writes the JSON, markdown and figure beside
    this script (``zoo_results[_quick].*``) and returns the target rows."""
    suffix = "_quick" if quick else ""
    results = zoo_main((["--quick"] if quick else []) + [f"--json=benchmarks/zoo_results{suffix}.json",
                                                        f"--md=benchmarks/zoo_results{suffix}.md",
                                                        f"--figure=benchmarks/zoo_figure{suffix}.png"])
    return target_rows(results)


def parse_variant(text: str) -> tuple[str, dict]:
    """'NAME=field=value,field=value' -> (NAME, {field: value}); values parsed as Python literals."""
    import ast

    name, _, rest = text.partition("=")
    out = {}
    for item in filter(None, rest.split(",")):
        k, _, v = item.partition("=")
        try:
            out[k.strip()] = ast.literal_eval(v.strip())
        except (ValueError, SyntaxError):
            out[k.strip()] = v.strip()
    return name.strip(), out


def main(argv=None) -> int:
    zoo_main(argv)
    return 0


def zoo_main(argv=None) -> dict:
    """The command line's work; returns the results {scene: {"rows", "summary", ...}}."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help="smaller, shorter scenes")
    p.add_argument("--long", action="store_true", help="also the long recordings (20 s and 60 s; minutes more)")
    p.add_argument("--scenes", default=None, help="comma-separated scene names (default: all but the long ones)")
    p.add_argument("--methods", default=",".join(METHODS), help=f"comma-separated, from {METHODS} and variants")
    p.add_argument("--variant", action="append", default=[], help="an EvINR variant NAME=field=value,... (repeat)")
    p.add_argument("--heldout", action="store_true",
                   help="the held-out scenes (zoo.HELDOUT) instead of the zoo; no real chunk; *_heldout.* outputs")
    p.add_argument("--stress", action="store_true",
                   help="the stress scenes (zoo.STRESS) instead of the zoo; no real chunk; *_stress.* outputs")
    p.add_argument("--large", action="store_true",
                   help="the 360x480 scenes (zoo.LARGE) instead of the zoo; no real chunk; *_large.* outputs")
    p.add_argument("--fresh", type=int, default=None, metavar="SEED",
                   help="scenes drawn at random the zoo's ways from SEED (zoo.fresh) instead of the zoo; no real "
                        "chunk; *_fresh.* outputs")
    p.add_argument("--n-fresh", type=int, default=16, help="how many --fresh scenes (default 16)")
    p.add_argument("--no-real", action="store_true", help="skip the real slider_depth chunk")
    p.add_argument("--json", default=None, help="default benchmarks/zoo_results[_heldout|_stress|_large|_fresh].json")
    p.add_argument("--md", default=None, help="default benchmarks/zoo_results[_heldout|_stress|_large|_fresh].md")
    p.add_argument("--figure", default=None, help="default benchmarks/zoo_figure[_heldout|_stress|_large|_fresh].png")
    a = p.parse_args(argv)
    fresh_set = a.fresh is not None
    if fresh_set and a.n_fresh < 1:
        p.error(f"--n-fresh must be at least 1, got {a.n_fresh}")
    if a.heldout + a.stress + a.large + fresh_set > 1:
        p.error("--heldout, --stress, --large and --fresh are other sets of scenes: give one of them")
    other = a.heldout or a.stress or a.large or fresh_set   # a set other than the zoo: all its scenes, no real chunk
    suffix = "_heldout" if a.heldout else "_stress" if a.stress else "_large" if a.large else \
        "_fresh" if fresh_set else ""
    a.json = f"benchmarks/zoo_results{suffix}.json" if a.json is None else a.json
    a.md = f"benchmarks/zoo_results{suffix}.md" if a.md is None else a.md
    a.figure = f"benchmarks/zoo_figure{suffix}.png" if a.figure is None else a.figure
    variants = dict(parse_variant(v) for v in a.variant)
    methods = [m for m in a.methods.split(",") if m] + [v for v in variants if v not in a.methods.split(",")]
    unknown = [m for m in methods if m not in METHODS + OPTIONAL and m not in variants]
    if unknown:
        p.error(f"unknown methods {unknown}; use {METHODS + OPTIONAL} or add --variant NAME=...")
    pool = HELDOUT if a.heldout else STRESS if a.stress else LARGE if a.large else \
        zoo_fresh(a.fresh, a.n_fresh) if fresh_set else ZOO
    if a.scenes is None:
        scenes = list(pool) if other else default_scenes(a.long)
    else:
        scenes = [z for z in pool if z.name in a.scenes.split(",")]
    if a.scenes and len(scenes) != len(a.scenes.split(",")):
        p.error(f"unknown scenes in {a.scenes}; {suffix[1:] + ' set' if other else 'the zoo'} holds "
                f"{[z.name for z in pool]}")
    scenes = [quick(z) for z in scenes] if a.quick else scenes
    t0 = time.perf_counter()
    results = run_zoo(scenes, methods, variants)
    if not (a.no_real or other):
        real = run_real(methods, variants)
        if real is not None:
            results["real_slider_chunk"] = real
    md = markdown(results, methods)
    print("\n" + md)
    print(f"\nzoo run: {time.perf_counter() - t0:.0f} s")
    for r in target_rows(results):
        print(f"  {r['name']}: {r['measured']:.3g} {r['unit']} (target {r['target_kind'] or ''} {r['target']}; "
              f"met: {r['met']}) {r.get('note', '')}")
    shown = [n for n in ("camera_translate", "noisy_gravel", "unequal_onhot", "long_pan_20s") if n in results][:4] or \
        list(results)[:4]
    if a.figure:
        figure(results, shown, methods, Path(a.figure))
        print(f"figure: {a.figure}")
    if a.md:
        Path(a.md).write_text(md + "\n")
    if a.json:
        clean = {n: {k: v for k, v in r.items() if k != "figure"} for n, r in results.items()}
        Path(a.json).write_text(json.dumps({"quick": a.quick, "long": a.long, "heldout": a.heldout, "stress": a.stress, "large": a.large, "fresh_seed": a.fresh, "methods": methods, "variants": variants,
                                            "scenes": clean, "targets": target_rows(results)}, indent=2,
                                           default=float) + "\n")
        print(f"json: {a.json}")
    return results


if __name__ == "__main__":
    sys.exit(main())
