"""C+ and C- fitted from simulated APS frames on every zoo scene: true vs fitted, per fit method.

    python benchmarks/contrast_fit.py [--quick] [--rate 20] [--fits trajectory:iv,trajectory:huber,pairs:huber]

Each scene's events come from ``zoo.simulate`` (its own sensor model: C+ / C-, mismatch, refractory
period, background activity, hot pixels); its APS frames are the scene's intensity at ``--rate``
frames per second, quantised to uint8 as a camera's are. Prints one row per scene and method with
the relative errors, and the number of scenes within 10 % of both thresholds.

``--reconstruct``: on the zoo's scenes with C+ != C-, the kit default (EvINRConfig()) given the mean
C (what the zoo gives every method), the true pair and the fitted pair, scored at the zoo's times.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from evinr_lite.core.events import EventDataError
from evinr_lite.core.frames import Frames
from evinr_lite.evaluation.metrics import SCORE_PROTOCOLS
from evinr_lite.method.contrast import fit_contrast
from evinr_lite.sim import zoo


def aps_frames(scene, duration: float, rate: float) -> Frames:
    """The scene's intensity at ``rate`` frames per second over [0, duration], as uint8."""
    t = np.arange(0.0, duration + 1e-9, 1.0 / rate)
    images = np.clip(np.rint(255.0 * scene.intensity(t)), 0, 255).astype(np.uint8)
    return Frames(images, t)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true", help="the zoo's quick scenes (smaller, shorter)")
    ap.add_argument("--rate", type=float, default=20.0, help="APS frames per second (default 20)")
    ap.add_argument("--reconstruct", action="store_true",
                    help="also reconstruct the asymmetric scenes with the mean C, the true and the fitted pair")
    ap.add_argument("--fits", default="trajectory:iv,trajectory:huber,trajectory:lsq,pairs:huber,pairs:lsq",
                    help="span:method pairs, comma-separated (fit_contrast's span= and method=)")
    a = ap.parse_args(argv)
    methods = a.fits.split(",")
    print(f"{'scene':<20} {'true C+':>7} {'true C-':>7} {'fit':>16} {'fit C+':>14} {'fit C-':>14} "
          f"{'err+':>6} {'err-':>6} {'one C':>6} {'samples':>9} {'s':>5}")
    within = {m: 0 for m in methods}
    for z in zoo.ZOO:
        z = zoo.quick(z) if a.quick else z
        scene, events, _, _ = zoo.simulate(z)
        frames = aps_frames(scene, z.duration, a.rate)
        cp = z.C if z.C_pos is None else z.C_pos
        cn = z.C if z.C_neg is None else z.C_neg
        for m in methods:
            t0 = time.perf_counter()
            span, method = m.split(":")
            try:
                f = fit_contrast(frames, events, method=method, span=span)
            except EventDataError as err:
                print(f"{z.name:<20} {cp:7.3f} {cn:7.3f} {m:>16} refused: {err}", flush=True)
                continue
            s = time.perf_counter() - t0
            ep, en = f.c_pos / cp - 1, f.c_neg / cn - 1
            within[m] += abs(ep) <= 0.1 and abs(en) <= 0.1
            print(f"{z.name:<20} {cp:7.3f} {cn:7.3f} {m:>16} {f.c_pos:7.3f}±{f.c_pos_se:.3f} "
                  f"{f.c_neg:7.3f}±{f.c_neg_se:.3f} {100 * ep:+5.1f}% {100 * en:+5.1f}% {f.c_single:6.3f} "
                  f"{f.n_used:9,} {s:5.2f}", flush=True)
    print("scenes with both C+ and C- within 10 %: " + ", ".join(f"{m} {n}/{len(zoo.ZOO)}" for m, n in within.items()))
    if a.reconstruct:
        reconstruct_asymmetric(a.quick, a.rate)


def reconstruct_asymmetric(quick: bool, rate: float) -> None:
    """Kit default with the mean C, the true pair and the fitted pair on the scenes with C+ != C-."""
    from evinr_lite.evaluation.scoring import score_sequence
    from evinr_lite.method.solver import EvINRConfig, reconstruct

    for z in zoo.ZOO:
        if z.C_pos is None:
            continue
        z = zoo.quick(z) if quick else z
        scene, events, times, gt = zoo.simulate(z)
        fit = fit_contrast(aps_frames(scene, z.duration, rate), events)
        for label, C in (("mean C", zoo.effective_C(z)), ("true pair", (z.C_pos, z.C_neg)), ("fitted pair", fit.C)):
            rec = reconstruct(events, times, EvINRConfig(C=C, progress=False))
            s = {eq: score_sequence(rec.frames, times, gt, times, equalization=eq, lpips_model=False)
                 for eq in SCORE_PROTOCOLS}
            print(f"{z.name:<20} {label:<12} C = {np.round(C, 3)}: SSIM {s['none']['ssim']:.3f}, CLAHE-SSIM "
                  f"{s['clahe']['ssim']:.3f}, MSE {s['none']['mse']:.4f}", flush=True)


if __name__ == "__main__":
    main()
