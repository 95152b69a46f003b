"""C+ and C- fitted from simulated APS frames on every zoo scene: true vs fitted, per fit method.

    python benchmarks/contrast_fit.py [--quick] [--rate 20] [--fits trajectory:iv,trajectory:huber,pairs:huber]

Each scene's events come from ``zoo.simulate`` (its own sensor model: C+ / C-, mismatch, refractory
period, background activity, hot pixels); its APS frames are the scene's intensity at ``--rate``
frames per second, quantised to uint8 as a camera's are. Prints one row per scene and method with
the relative errors, and the number of scenes within 10 % of both thresholds.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

from evinr_lite.core.events import EventDataError
from evinr_lite.core.frames import Frames
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


if __name__ == "__main__":
    main()
