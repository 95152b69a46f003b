"""APS frames as anchors (``EvINRConfig(anchor=...)``) against the complementary filter, on held-out frames.

    nice -n 10 python benchmarks/anchors.py                        # object_static_cam + the zoo + the real chunk
    nice -n 10 python benchmarks/anchors.py --scenes object_static_cam --smoothing 0,0.1
    nice -n 10 python benchmarks/anchors.py --scenes object_static_cam,camera_translate --no-real \
        --frame-noise 0.03 --smoothing 0.03,0,0.1 --json /tmp/a.json --md /tmp/a.md   # noisy APS frames

Per scene the APS frames are simulated: the zoo scene's true intensity at 20 frames/s over [0, duration]
as uint8 (a camera's frames); the real IJRR slider_depth chunk brings its own frames (C = 1, the paper's
for IJRR). Methods, every one scored only on frames it did not use as anchors:

- ``events_only``: the kit default (``EvINRConfig()``), tone-mapped; scored on every frame but the first;
- ``first``: ``anchor="first"``: frame 0 sets the offset; scored on frames 1, 2, ...;
- ``all``: ``anchor="all"`` (anchors 0, 2, 4, ...; ``anchor_smoothing`` from --smoothing, the first
  value is the default's row); scored on the odd frames;
- ``cf_first``: the complementary filter (Scheerlinck et al. 2018, gain 2 pi rad/s) fed frame 0 only:
  like for like with ``first``; scored on frames 1, 2, ...;
- ``cf_anchors``: the filter fed the even frames (the anchors of ``all``): like for like; odd frames;
- ``cf_every_frame``: the filter fed every frame as it arrives (its design; it sees each held-out
  frame's predecessors, i.e. far more frames than ``first``); scored on frames 1, 2, ...

Two output protocols: ``linear`` (the frames' intensity, clip(exp(L) - 1/255, 0, 1): what anchored runs
and the filter produce) and ``tone-mapped`` (the paper's Eq. 12 display, Reinhard after the mean anchor: the kit's display
until issue 21 made it linear; a fixed protocol here, so the committed results stay comparable);
each scored without equalisation (plain SSIM) and with CLAHE. Writes benchmarks/anchors_results.json|md.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from evinr_lite.core.frames import Frames, to_uint8  # noqa: E402
from evinr_lite.evaluation.metrics import SCORE_PROTOCOLS  # noqa: E402
from evinr_lite.evaluation.scoring import frames_to_score, score_sequence  # noqa: E402
from evinr_lite.method import EvINRConfig, reconstruct, reconstruct_baseline  # noqa: E402
from evinr_lite.method.baselines import DEFAULT_GAIN  # noqa: E402
from evinr_lite.method.tonemap import anchor_mean, tonemap_reinhard  # noqa: E402
from evinr_lite.sim.zoo import ZOO, effective_C, simulate  # noqa: E402

FRAME_RATE = 20.0
TARGET_SCENE = "object_static_cam"
METHODS = ("events_only", "first", "all", "cf_first", "cf_anchors", "cf_every_frame")


def score(frames, times, gt, sel) -> dict:
    """{eq: SSIM} on the frames ``sel`` (indices) only."""
    return {eq: score_sequence(frames[sel], times[sel], gt[sel], times[sel], eq, lpips_model=False)["ssim"]
            for eq in SCORE_PROTOCOLS}


def run_scene(events, frames: Frames, gt, C: float, smoothing, gains=(), log=print) -> dict:
    """Every method on one scene: {method: {"linear": {eq: ssim}, "tonemapped": {...}, "scored": n, "time_s"}}."""
    ft = frames.t
    later = np.arange(1, len(ft))
    odd = np.arange(1, len(ft), 2)
    rows = {}

    def add(name, L, linear, sel, seconds, extra=None):
        tm = tonemap_reinhard(anchor_mean(L)).astype(np.float32)
        rows[name] = {"linear": None if linear is None else score(linear, ft, gt, sel),
                      "tonemapped": score(tm, ft, gt, sel), "scored": int(len(sel)), "time_s": seconds, **(extra or {})}
        lin = rows[name]["linear"] or rows[name]["tonemapped"]
        log(f"    {name:<22s} SSIM {lin['none']:.3f}  CLAHE-SSIM {lin['clahe']:.3f}  "
            f"(tone-mapped {rows[name]['tonemapped']['none']:.3f} / {rows[name]['tonemapped']['clahe']:.3f}) "
            f"on {len(sel)} frames, {seconds:.1f} s")

    t0 = time.perf_counter()
    rec = reconstruct(events, ft, EvINRConfig(C=C, progress=False))
    add("events_only", rec.log_intensity, None, later, time.perf_counter() - t0)
    for mode in ("first", "all"):
        for k, s in enumerate(smoothing if mode == "all" else [0.1]):
            t0 = time.perf_counter()
            kw = {"anchor_smoothing": s} if mode == "all" else {}
            rec = reconstruct(events, ft, EvINRConfig(C=C, progress=False, anchor=mode, **kw), frames=frames)
            held = np.flatnonzero(~np.isin(ft, rec.anchor_times))
            assert np.array_equal(held, later if mode == "first" else odd)
            name = mode if k == 0 else f"all (smoothing {s:g} s)"
            add(name, rec.log_intensity, rec.frames, held, time.perf_counter() - t0,
                {"anchor_times_s": rec.anchor_times.tolist()} if k == 0 else {"anchor_smoothing": s})
    cf = [("cf_first", [0], later, DEFAULT_GAIN), ("cf_anchors", list(range(0, len(ft), 2)), odd, DEFAULT_GAIN),
          ("cf_every_frame", list(range(len(ft))), later, DEFAULT_GAIN)]
    cf += [(f"cf_first (gain {g:g})", [0], later, g) for g in gains]
    for name, fed, sel, gain in cf:
        t0 = time.perf_counter()
        b = reconstruct_baseline(events, ft, "complementary", C=C, gain=gain,
                                 frames=Frames(frames.images[fed], ft[fed], frames.t_origin))
        add(name, b.log_intensity, b.frames, sel, time.perf_counter() - t0, {"frames_fed": len(fed), "gain": gain})
    return rows


def zoo_frames(z, frame_noise: float = 0.0):
    """(events, APS frames at FRAME_RATE as uint8 with Gaussian noise of sd ``frame_noise`` (seeded), the
    true intensity at the frame times [F, H, W])."""
    scene, events, _, _ = simulate(z)
    ft = np.arange(0.0, z.duration + 1e-9, 1.0 / FRAME_RATE)
    gt = scene.intensity(ft).astype(np.float32)
    aps = gt + np.random.default_rng(z.seed + 200).normal(0.0, frame_noise, gt.shape) if frame_noise > 0 else gt
    return events, Frames(to_uint8(aps), ft), gt


def verdicts(results: dict) -> list[str]:
    out = []
    t = results.get(TARGET_SCENE)
    if t:
        r = t["rows"]
        out.append(f"{TARGET_SCENE}: first plain SSIM {r['first']['linear']['none']:.3f} (target >= 0.85: "
                   f"{'met' if r['first']['linear']['none'] >= 0.85 else 'NOT met'}); events only "
                   f"{r['events_only']['tonemapped']['none']:.3f}")
    for name, res in results.items():
        r = res["rows"]
        for cf in ["cf_first", "cf_every_frame"] + [m for m in r if m.startswith("cf_first (gain")]:
            wins = [f"{p}/{eq}" for p in ("linear", "tonemapped") for eq in SCORE_PROTOCOLS
                    if r["first"][p][eq] > r[cf][p][eq]]
            out.append(f"{name}: first beats {cf} in {len(wins)} of 4 (output/equalisation): {', '.join(wins) or '-'}")
        wins = [f"{p}/{eq}" for p in ("linear", "tonemapped") for eq in SCORE_PROTOCOLS
                if r["all"][p][eq] > r["cf_anchors"][p][eq]]
        out.append(f"{name}: all beats cf_anchors in {len(wins)} of 4: {', '.join(wins) or '-'}")
    return out


def markdown(results: dict) -> str:
    names = list(next(iter(results.values()))["rows"])
    lines = ["| scene | " + " | ".join(names) + " |", "|---" * (len(names) + 1) + "|"]
    for scene, res in results.items():
        cells = []
        for m in names:
            r = res["rows"][m]
            lin = r["linear"]
            tm = r["tonemapped"]
            cells.append((f"{lin['none']:.3f} / {lin['clahe']:.3f}" if lin else "-") +
                         f" ({tm['none']:.3f} / {tm['clahe']:.3f}) [{r['scored']}]")
        lines.append(f"| {scene} | " + " | ".join(cells) + " |")
    synth = [r for n, r in results.items() if n != "real_slider_chunk"]
    if len(synth) > 1:
        means = []
        for m in names:
            lin = [r["rows"][m]["linear"] for r in synth]
            tm = [r["rows"][m]["tonemapped"] for r in synth]
            means.append((f"{np.mean([v['none'] for v in lin]):.3f} / {np.mean([v['clahe'] for v in lin]):.3f}"
                          if lin[0] else "-") +
                         f" ({np.mean([v['none'] for v in tm]):.3f} / {np.mean([v['clahe'] for v in tm]):.3f})")
        lines.append("| **zoo mean** | " + " | ".join(means) + " |")
    lines += ["", "Cells: SSIM / CLAHE-SSIM of the linear output (clip(exp(L) - 1/255, 0, 1)), then (the same for the "
              "tone-mapped output), then [frames scored]; only frames not used as anchors are scored. Zoo scenes: "
              f"APS frames simulated at {FRAME_RATE:g} frames/s as uint8, scored against the true intensity; the "
              "real chunk: its own frames, C = 1. events_only has no linear output (its level is unknown). "
              "Made by `nice -n 10 python benchmarks/anchors.py`."]
    return "\n".join(lines)


def main(argv=None) -> dict:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--scenes", default=None, help="comma-separated zoo scenes (default: all; object_static_cam first)")
    p.add_argument("--smoothing", default="0.03,0,0.1", help="anchor_smoothing values (s) for 'all'; the first "
                   "(the default's) is the row 'all'")
    p.add_argument("--cf-gains", default="0", help="extra gains (rad/s) of the filter fed frame 0 (0: integration "
                   "from the first frame)")
    p.add_argument("--frame-noise", type=float, default=0.0, help="sd of Gaussian noise added to the zoo's APS "
                   "frames (intensity units, before uint8)")
    p.add_argument("--no-real", action="store_true", help="skip the real slider_depth chunk")
    p.add_argument("--json", default="benchmarks/anchors_results.json")
    p.add_argument("--md", default="benchmarks/anchors_results.md")
    a = p.parse_args(argv)
    smoothing = [float(v) for v in a.smoothing.split(",") if v]
    gains = [float(v) for v in a.cf_gains.split(",") if v]
    names = [z.name for z in ZOO] if a.scenes is None else a.scenes.split(",")
    names = sorted(names, key=lambda n: n != TARGET_SCENE)
    scenes = {z.name: z for z in ZOO}
    unknown = [n for n in names if n not in scenes]
    if unknown:
        p.error(f"unknown scenes {unknown}; the zoo holds {list(scenes)}")
    t0 = time.perf_counter()
    results = {}
    for n in names:
        z = scenes[n]
        events, frames, gt = zoo_frames(z, a.frame_noise)
        print(f"{n}: {z.size[0]}x{z.size[1]}, {z.duration:g} s, {len(events):,} events, {len(frames)} APS frames")
        results[n] = {"doc": z.doc, "C": effective_C(z), "n_frames": len(frames),
                      "rows": run_scene(events, frames, gt, effective_C(z), smoothing, gains)}
    if not a.no_real:
        from evinr_lite.io.readers import read_recording
        from evinr_lite.io.sample_data import sample_recording_path

        path = sample_recording_path()
        if path is None:
            print("real chunk: not found (shared/data/ijrr_slider_depth_chunk); skipped")
        else:
            rec = read_recording(path)
            idx = frames_to_score(rec.frames.t, rec.events)
            frames = Frames(rec.frames.images[idx], rec.frames.t[idx], rec.frames.t_origin)
            print(f"real slider_depth chunk: {len(rec.events):,} events, {len(frames)} APS frames, C = 1")
            gt = frames.as_float()
            results["real_slider_chunk"] = {"doc": "IJRR slider_depth chunk (real DAVIS240C), C = 1", "C": 1.0,
                                            "n_frames": len(frames),
                                            "rows": run_scene(rec.events, frames, gt, 1.0, smoothing, gains)}
    md = markdown(results)
    lines = verdicts(results)
    print("\n" + md + "\n\n" + "\n".join(lines))
    print(f"\nanchors run: {time.perf_counter() - t0:.0f} s")
    if a.md:
        Path(a.md).write_text(md + "\n\n" + "\n".join(f"- {v}" for v in lines) + "\n")
    if a.json:
        Path(a.json).write_text(json.dumps({"frame_rate": FRAME_RATE, "smoothing": smoothing, "cf_gains": gains,
                                            "frame_noise": a.frame_noise, "scenes": results,
                                            "verdicts": lines}, indent=2, default=float) + "\n")
        print(f"json: {a.json}, md: {a.md}")
    return results


if __name__ == "__main__":
    main()
    sys.exit(0)
