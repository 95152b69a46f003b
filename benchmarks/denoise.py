"""Denoising measured against the truth: which removed events were noise, the reconstruction gain, tonic.

    python benchmarks/denoise.py               # zoo noisy scenes + stress variants (a few minutes on 2 cores)
    python benchmarks/denoise.py --quick       # smaller, shorter scenes, fewer settings
    python -m benchmarks --only denoise        # the same, from the benchmark runner

Scenes: every zoo scene with sensor noise (background activity or hot pixels: ``noisy_gravel``,
``grass_light_noisy``), simulated exactly as ``evinr_lite.sim.zoo.simulate`` does but with the
simulator's labels (``return_labels=True``), so each event is known to be signal, background or
hot-pixel. The zoo's noise is mild (0.2-0.5 Hz per pixel, hot pixels at 50 Hz), so each is also
run as a ``_stress`` variant (2 Hz per pixel, 40 hot pixels at 200 Hz, the top of the robustness
sweep's range), and so is the clean ``camera_translate``. ``signal only`` (the true noise removed)
is the ceiling any denoiser can reach.

Per scene and setting: the fraction of hot-pixel and background events removed, the fraction of
signal events kept, the precision of the removed events, and the kit's (``EvINRConfig(background="keep")``:
the default without its own background filter, so each setting is the only filter)
CLAHE-SSIM and SSIM through the zoo's scoring (``score_sequence``, 10 ground-truth times), with
the gain over no denoising. The real IJRR slider_depth chunk beside the project is scored too
(no labels there: what the default removes and the gain). Speed: ``correlation_filter`` in events per second. tonic: when it
imports, ``tonic.functional.denoise_numpy`` and ``identify_hot_pixel`` on the same events
(agreement of the keep/drop decisions with matched semantics, and speed).
Writes ``benchmarks/denoise_results[_quick].md`` and ``.json``.
"""
from __future__ import annotations

import argparse
import importlib.util
import json
import sys
import time
from dataclasses import asdict, replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from evinr_lite.core.events import Events  # noqa: E402
from evinr_lite.evaluation.metrics import SCORE_PROTOCOLS  # noqa: E402
from evinr_lite.method.denoise import DEFAULT_DT, correlation_filter, denoise_mask, hot_pixel_mask  # noqa: E402
from evinr_lite.sim import zoo  # noqa: E402

SIGNAL, BACKGROUND, HOT = zoo.SIGNAL, zoo.BACKGROUND, zoo.HOT
STRESS = dict(noise_hz=2.0, hot_pixels=40, hot_hz=200.0)

# name -> denoise() keyword arguments (default: two-sided, same polarity, 50 ms); None: no denoising;
# "oracle": the true noise removed
SETTINGS = {
    "none": None,
    "signal only": "oracle",
    "default": {},
    "hot pixels only": dict(background=False),
    "Delbruck 5 ms": dict(dt=5e-3, window="before", same_polarity=False),
    "Delbruck 10 ms": dict(dt=10e-3, window="before", same_polarity=False),
    "Delbruck 30 ms": dict(dt=30e-3, window="before", same_polarity=False),
    "two-sided 10 ms": dict(dt=10e-3, window="both", same_polarity=False),
    "two-sided 30 ms": dict(dt=30e-3, window="both", same_polarity=False),
    "two-sided same pol 20 ms": dict(dt=20e-3, window="both", same_polarity=True),
    "two-sided same pol 30 ms": dict(dt=30e-3, window="both", same_polarity=True),
    "causal same pol 30 ms": dict(dt=30e-3, window="before", same_polarity=True),
    "causal same pol 50 ms": dict(dt=50e-3, window="before", same_polarity=True),
}
QUICK_SETTINGS = ("none", "signal only", "default", "hot pixels only", "Delbruck 5 ms", "Delbruck 30 ms")


def noisy_scenes(quick: bool) -> list:
    base = [z for z in zoo.ZOO if z.noise_hz > 0 or z.hot_pixels > 0]
    stress = [replace(z, name=z.name + "_stress", doc=z.doc + "; stress noise", **STRESS)
              for z in base + [zoo.get("camera_translate")]]
    scenes = base + stress
    return [zoo.quick(z) for z in scenes] if quick else scenes


def simulate_labeled(z):
    """``zoo.simulate(z)`` with labels: (events, labels int8 [N] (0 signal, 1 background, 2 hot),
    hot pixels' flat indices, times [10], gt [10, H, W]). Same seeds, same draws, same events, and the
    same ground truth (clipped at 1): it is ``zoo.simulate(z, labels=True)``."""
    _, events, times, gt, labels, hot = zoo.simulate(z, labels=True)
    return events, labels, hot, times, gt


def kept_mask(events: Events, labels: np.ndarray, setting) -> tuple[np.ndarray, float]:
    """(bool [N] kept, seconds) for one setting."""
    t0 = time.perf_counter()
    if setting is None:
        keep = np.ones(len(events), bool)
    elif setting == "oracle":
        keep = labels == SIGNAL
    else:
        keep, _ = denoise_mask(events, **setting)
    return keep, time.perf_counter() - t0


def pr(labels: np.ndarray, keep: np.ndarray) -> dict:
    removed = ~keep
    noise = labels != SIGNAL
    out = {"signal_kept": float(keep[labels == SIGNAL].mean())}
    for name, k in (("background", BACKGROUND), ("hot", HOT)):
        m = labels == k
        out[f"{name}_removed"] = float(removed[m].mean()) if m.any() else None
    out["noise_removed"] = float(removed[noise].mean()) if noise.any() else None
    out["precision"] = float((removed & noise).sum() / removed.sum()) if removed.any() else None
    return out


def reconstruct_score(events: Events, times, gt, C) -> dict:
    from benchmarks.quality_zoo import run_method, score

    # the kit without its own background filter (background="keep"): the settings below are the only filter
    frames, seconds = run_method("kit_unfiltered", events, times, C, {})
    return {**score(frames, times, gt, times), "recon_s": seconds}


# ---- tonic ---------------------------------------------------------------------------------

def load_tonic():
    """tonic's denoise and drop_pixel modules (functional files only: tonic's __init__ pulls in
    librosa and dataset readers), or None when tonic is not installed."""
    spec = importlib.util.find_spec("tonic")
    if spec is None or not spec.submodule_search_locations:
        return None
    root = Path(list(spec.submodule_search_locations)[0]) / "functional"
    mods = {}
    for name in ("denoise", "drop_pixel"):
        s = importlib.util.spec_from_file_location(f"_tonic_{name}", root / f"{name}.py")
        m = importlib.util.module_from_spec(s)
        s.loader.exec_module(m)
        mods[name] = m
    try:
        import importlib.metadata as md
        mods["version"] = md.version("tonic")
    except Exception:  # noqa: BLE001 - the version is informational
        mods["version"] = "?"
    return mods


def compare_tonic(tonic, events: Events, labels, dt: float) -> dict:
    """tonic's Denoise (4 neighbours, strict, earlier in the stream) next to ours on whole-us times."""
    t_us = np.round(events.t * 1e6).astype(np.int64)
    ft = int(round(dt * 1e6))
    arr = np.zeros(len(events), dtype=[("x", "<i8"), ("y", "<i8"), ("t", "<i8"), ("p", "<i8")])
    arr["x"], arr["y"], arr["t"], arr["p"] = events.x, events.y, t_us, events.p
    arr["t"] -= t_us[0]                              # tonic's timestamp map starts at filter_time
    t0 = time.perf_counter()
    kept = tonic["denoise"].denoise_numpy(arr, filter_time=ft)
    t_tonic = time.perf_counter() - t0
    # tonic returns the kept events in order; mark them (t, x, y unique enough with the index merge)
    keep_tonic = np.zeros(len(arr), bool)
    j = 0
    for row in kept:                                 # subsequence merge, linear
        while not (arr[j]["t"] == row["t"] and arr[j]["x"] == row["x"] and arr[j]["y"] == row["y"]
                   and arr[j]["p"] == row["p"]):
            j += 1
        keep_tonic[j] = True
        j += 1
    ev_us = Events((t_us - t_us[0]) * 1e-6, events.x, events.y, events.p, events.sensor_size)
    t0 = time.perf_counter()
    # tonic keeps t_i - t_j < ft (strict) on whole us: the same as <= ft - 0.5 us
    matched = correlation_filter(ev_us, (ft - 0.5) * 1e-6, neighbourhood=4)
    t_ours = time.perf_counter() - t0
    ours8 = correlation_filter(ev_us, dt)
    after = ev_us.t >= ft * 1e-6                     # tonic passes every event of the first filter_time
    agree = keep_tonic == matched
    return {"filter_time_us": ft, "agreement_matched": float(agree.mean()),
            "agreement_matched_after_first_window": float(agree[after].mean()),
            "agreement_with_default_8_neighbours": float((keep_tonic == ours8).mean()),
            "tonic_kept": float(keep_tonic.mean()), "ours_matched_kept": float(matched.mean()),
            "tonic_pr": pr(labels, keep_tonic), "tonic_events_per_s": len(events) / t_tonic,
            "ours_matched_events_per_s": len(events) / t_ours}


def compare_tonic_hot(tonic, events: Events, hot_true: np.ndarray, freqs=(10.0, 50.0)) -> dict:
    """tonic's identify_hot_pixel at fixed frequencies next to hot_pixel_mask, against the true hot pixels."""
    H, W = events.sensor_size
    arr = np.zeros(len(events), dtype=[("x", "<i8"), ("y", "<i8"), ("t", "<i8"), ("p", "<i8")])
    arr["x"], arr["y"], arr["t"], arr["p"] = events.x, events.y, np.round(events.t * 1e6), events.p
    truth = np.zeros(H * W, bool)
    truth[hot_true] = True
    out = {}
    t0 = time.perf_counter()
    ours = hot_pixel_mask(events).ravel()
    out["ours"] = {"true_hot_found": int((ours & truth).sum()), "false_hot": int((ours & ~truth).sum()),
                   "seconds": time.perf_counter() - t0}
    for f in freqs:
        t0 = time.perf_counter()
        xy = tonic["drop_pixel"].identify_hot_pixel(arr, hot_pixel_frequency=f)
        flagged = np.zeros(H * W, bool)
        if len(xy):
            flagged[xy[:, 1] * W + xy[:, 0]] = True
        seconds = time.perf_counter() - t0
        t0 = time.perf_counter()
        tonic["drop_pixel"].drop_pixel_numpy(arr, xy)
        out[f"tonic_{f:g}Hz"] = {"true_hot_found": int((flagged & truth).sum()),
                                 "false_hot": int((flagged & ~truth).sum()), "seconds": seconds,
                                 "drop_seconds": time.perf_counter() - t0}
    out["n_true_hot"] = int(truth.sum())
    return out


# ---- speed ---------------------------------------------------------------------------------

def speed(quick: bool) -> list[dict]:
    """correlation_filter throughput (best of 3) on the gravel stream as simulated and 10x denser in time."""
    z = zoo.get("noisy_gravel")
    z = zoo.quick(z) if quick else z
    _, ev, _, _ = zoo.simulate(z)
    rows = []
    for label, factor in (("as simulated", 1.0), ("10x the rate", 0.1)):
        e = Events(ev.t * factor, ev.x, ev.y, ev.p, ev.sensor_size)
        for dt, kw in ((5e-3, dict(window="before", same_polarity=False)), (DEFAULT_DT, {})):
            correlation_filter(e, dt, **kw)          # warm-up: pages, caches
            wall, cpu = zip(*[_time(lambda: correlation_filter(e, dt, **kw)) for _ in range(3)])
            rows.append({"stream": label, "events": len(e), "rate_ev_per_s": len(e) / e.duration, "dt": dt,
                         "options": kw or "defaults", "events_per_s": len(e) / min(wall),
                         "events_per_cpu_s": len(e) / min(cpu)})
    return rows


def _load() -> str:
    try:
        import os
        return f"{os.getloadavg()[0]:.1f}"
    except (OSError, AttributeError):
        return "?"


def _time(fn) -> tuple[float, float]:
    """(wall seconds, this process's CPU seconds) of fn(): on a shared machine the CPU time is the fairer."""
    t0, c0 = time.perf_counter(), time.process_time()
    fn()
    return time.perf_counter() - t0, time.process_time() - c0


# ---- the run -------------------------------------------------------------------------------

def run_scene(z, settings, tonic, log=print) -> dict:
    events, labels, hot, times, gt = simulate_labeled(z)
    C = zoo.effective_C(z)
    counts = {n: int((labels == k).sum()) for n, k in (("signal", SIGNAL), ("background", BACKGROUND), ("hot", HOT))}
    log(f"{z.name}: {z.size[0]}x{z.size[1]}, {z.duration:g} s, {len(events):,} events {counts}")
    rows = {}
    for name in settings:
        keep, seconds = kept_mask(events, labels, SETTINGS[name])
        r = {**pr(labels, keep), **reconstruct_score(events.take(keep), times, gt, C), "denoise_s": seconds}
        rows[name] = r
        log(f"    {name:<22s} signal kept {r['signal_kept']:.3f}  bg removed {r['background_removed'] or 0:.3f}  "
            f"hot removed {r['hot_removed'] or 0:.3f}  CLAHE-SSIM {r['ssim_clahe']:.4f}  SSIM {r['ssim_none']:.4f}")
    for name, r in rows.items():
        for eq in SCORE_PROTOCOLS:
            r[f"gain_{eq}"] = r[f"ssim_{eq}"] / rows["none"][f"ssim_{eq}"]
    out = {"doc": z.doc, "size": list(z.size), "duration_s": z.duration, "counts": counts, "rows": rows}
    if tonic is not None:
        out["tonic_denoise"] = compare_tonic(tonic, events, labels, 10e-3)
        out["tonic_hot"] = compare_tonic_hot(tonic, events, hot)
        td = out["tonic_denoise"]
        log(f"    tonic Denoise(10 ms): agreement {td['agreement_matched']:.4f} (after the first window "
            f"{td['agreement_matched_after_first_window']:.4f}); {td['tonic_events_per_s'] / 1e6:.2f} M ev/s vs "
            f"ours {td['ours_matched_events_per_s'] / 1e6:.1f} M ev/s")
    return out


def run_real(log=print) -> dict | None:
    """The real IJRR slider_depth chunk (no labels): what the default removes and the kit's scores, C = 1."""
    from benchmarks.quality_zoo import real_chunk

    found = real_chunk(log)
    if found is None:
        return None
    rec, gt, gt_t = found
    keep, report = denoise_mask(rec.events)
    out = {"report": report.to_dict(), "rows": {}}
    for name, ev in (("none", rec.events), ("default", rec.events.take(keep))):
        out["rows"][name] = reconstruct_score(ev, gt_t, gt, 1.0)
    for eq in SCORE_PROTOCOLS:
        out[f"gain_{eq}"] = out["rows"]["default"][f"ssim_{eq}"] / out["rows"]["none"][f"ssim_{eq}"]
    log(f"real slider chunk: {report.summary()}; CLAHE-SSIM {out['rows']['none']['ssim_clahe']:.4f} -> "
        f"{out['rows']['default']['ssim_clahe']:.4f}, SSIM {out['rows']['none']['ssim_none']:.4f} -> "
        f"{out['rows']['default']['ssim_none']:.4f}")
    return out


def markdown(results: dict, speed_rows: list, tonic_version, real=None) -> str:
    lines = ["## Removed events and reconstruction gain (the kit without its own filter, EvINRConfig(background='keep'))", "",
             "| scene | setting | signal kept | background removed | hot removed | precision | CLAHE-SSIM | gain | "
             "SSIM | gain |", "|---" * 10 + "|"]
    f = (lambda v, d=3: "-" if v is None else f"{v:.{d}f}")
    for scene, r in results.items():
        for name, row in r["rows"].items():
            lines.append(f"| {scene} | {name} | {f(row['signal_kept'])} | {f(row['background_removed'])} | "
                         f"{f(row['hot_removed'])} | {f(row['precision'])} | {row['ssim_clahe']:.4f} | "
                         f"{row['gain_clahe']:.3f} | {row['ssim_none']:.4f} | {row['gain_none']:.3f} |")
    lines += ["", "Targets: >= 0.90 of background and hot events removed with >= 0.95 of signal kept; CLAHE-SSIM "
              "gain >= 1.05. 'signal only' removes exactly the injected noise (the ceiling)."]
    if real:
        r = real["rows"]
        lines += ["", f"Real IJRR slider_depth chunk (no labels; C = 1): default denoise removed "
                      f"{real['report']['n_hot']} hot-pixel and {real['report']['n_background']} background events of "
                      f"{real['report']['n_in']:,}; CLAHE-SSIM {r['none']['ssim_clahe']:.4f} -> {r['default']['ssim_clahe']:.4f} "
                      f"(x{real['gain_clahe']:.3f}), SSIM {r['none']['ssim_none']:.4f} -> {r['default']['ssim_none']:.4f} "
                      f"(x{real['gain_none']:.3f})."]
    lines += ["",
              "## Speed of correlation_filter (best of 3)", "",
              "| stream | events | rate (ev/s) | dt | options | events/s (wall) | events per CPU second |",
              "|---|---|---|---|---|---|---|"]
    for s in speed_rows:
        lines.append(f"| {s['stream']} | {s['events']:,} | {s['rate_ev_per_s']:.3g} | {s['dt'] * 1e3:g} ms | "
                     f"{s['options']} | {s['events_per_s'] / 1e6:.1f} M | {s['events_per_cpu_s'] / 1e6:.1f} M |")
    lines += ["", f"1-min load average during the run: {_load()} (2 CPU cores shared with other jobs; the CPU-second "
              "rate is the fairer figure)"]
    if tonic_version:
        lines += ["", f"## tonic {tonic_version} side by side", "",
                  "| scene | agreement (matched: 4 neighbours, strict, 10 ms) | after the first 10 ms | vs our default "
                  "8 neighbours | tonic M ev/s | ours M ev/s | hot: ours found/false | tonic 10 Hz | tonic 50 Hz |",
                  "|---" * 9 + "|"]
        for scene, r in results.items():
            td, th = r.get("tonic_denoise"), r.get("tonic_hot")
            if not td:
                continue
            hot = (lambda k: f"{th[k]['true_hot_found']}/{th[k]['false_hot']} of {th['n_true_hot']}")
            lines.append(f"| {scene} | {td['agreement_matched']:.4f} | {td['agreement_matched_after_first_window']:.4f} | "
                         f"{td['agreement_with_default_8_neighbours']:.4f} | {td['tonic_events_per_s'] / 1e6:.2f} | "
                         f"{td['ours_matched_events_per_s'] / 1e6:.1f} | {hot('ours')} | {hot('tonic_10Hz')} | "
                         f"{hot('tonic_50Hz')} |")
    return "\n".join(lines)


def target_rows(results: dict, speed_rows: list) -> list[dict]:
    from benchmarks.common import row

    rows = []
    zoo_names = [n for n in results if not n.endswith("_stress")]
    for label, names in (("zoo noisy scenes", zoo_names), ("stress variants", [n for n in results if n.endswith("_stress")])):
        if not names:
            continue
        d = [results[n]["rows"]["default"] for n in names]
        noise = [min(v for v in (r["background_removed"], r["hot_removed"]) if v is not None) for r in d]
        rows.append(row(f"denoise default, {label}: worst of background/hot removed", min(noise), "fraction", 0.90,
                        note=f"signal kept >= {min(r['signal_kept'] for r in d):.3f} (target 0.95)"))
        rows.append(row(f"denoise default, {label}: worst signal kept", min(r["signal_kept"] for r in d), "fraction",
                        0.95))
        rows.append(row(f"denoise default, {label}: worst CLAHE-SSIM gain", min(r["gain_clahe"] for r in d), "x", 1.05,
                        note="ceiling (true noise removed): "
                             f"{min(results[n]['rows']['signal only']['gain_clahe'] for n in names):.3f}"))
    for s in speed_rows:
        rows.append(row(f"correlation_filter, gravel {s['stream']}, dt {s['dt'] * 1e3:g} ms {s['options']}",
                        s["events_per_cpu_s"] / 1e6, "M events/CPU-s", 20.0,
                        note=f"wall clock {s['events_per_s'] / 1e6:.1f} M events/s"))
    return rows


def run(quick: bool = False, log=print) -> list[dict]:
    """``python -m benchmarks --only denoise`` calls this."""
    results, speed_rows = denoise_main(["--quick"] if quick else [])
    return target_rows(results, speed_rows)


def denoise_main(argv=None):
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help="smaller, shorter scenes and fewer settings")
    p.add_argument("--scenes", default=None, help="comma-separated scene names (default: all noisy and stress)")
    p.add_argument("--no-tonic", action="store_true", help="skip the tonic comparison even if tonic imports")
    p.add_argument("--no-real", action="store_true", help="skip the real slider_depth chunk")
    p.add_argument("--json", default=None, help="default: benchmarks/denoise_results[_quick].json")
    p.add_argument("--md", default=None, help="default: benchmarks/denoise_results[_quick].md")
    a = p.parse_args(argv)
    suffix = "_quick" if a.quick else ""
    scenes = noisy_scenes(a.quick)
    if a.scenes:
        wanted = a.scenes.split(",")
        unknown = sorted(set(wanted) - {z.name for z in scenes})
        if unknown:
            p.error(f"unknown scenes {unknown}; choose from {[z.name for z in scenes]}")
        scenes = [z for z in scenes if z.name in wanted]
    settings = QUICK_SETTINGS if a.quick else tuple(SETTINGS)
    tonic = None if a.no_tonic else load_tonic()
    print(f"tonic: {'not installed' if tonic is None else tonic['version']}")
    t0 = time.perf_counter()
    results = {z.name: run_scene(z, settings, tonic) for z in scenes}
    real = None if a.no_real else run_real()
    speed_rows = speed(a.quick)
    for s in speed_rows:
        print(f"speed: {s['stream']}, dt {s['dt'] * 1e3:g} ms {s['options']}: {s['events_per_s'] / 1e6:.1f} M events/s "
              f"(wall), {s['events_per_cpu_s'] / 1e6:.1f} M per CPU second")
    md = markdown(results, speed_rows, tonic and tonic["version"], real)
    print("\n" + md + f"\n\ndenoise benchmark: {time.perf_counter() - t0:.0f} s")
    for r in target_rows(results, speed_rows):
        print(f"  {r['name']}: {r['measured']:.3g} {r['unit']} (target {r['target']}; met: {r['met']}) {r.get('note', '')}")
    Path(a.md or f"benchmarks/denoise_results{suffix}.md").write_text(md + "\n")
    Path(a.json or f"benchmarks/denoise_results{suffix}.json").write_text(json.dumps(
        {"quick": a.quick, "settings": {k: SETTINGS[k] for k in settings}, "stress": STRESS,
         "tonic": tonic and tonic["version"], "scenes": results, "real_slider_chunk": real,
         "speed": speed_rows}, indent=2, default=float) + "\n")
    return results, speed_rows


def main(argv=None) -> int:
    denoise_main(argv)
    return 0


if __name__ == "__main__":
    sys.exit(main())
