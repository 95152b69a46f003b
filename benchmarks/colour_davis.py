"""Colour reconstruction on simulated colour DAVIS scenes (issue 15 item 5): the chroma correlation and
the grey scores of ``reconstruct --colour``'s pipeline, with the true colour filter (RGGB) and the three
wrong phases, on three colour images. A quality measurement (the unit tests only check its direction).

    python -m benchmarks.colour_davis        (about 2 minutes on one CPU core)
"""
from __future__ import annotations

import time

from evinr_lite.apps.colour_job import reconstruct_colour_recording, score_colour_recording
from evinr_lite.apps.recon_job import score_predictions
from evinr_lite.core.recording import Recording
from evinr_lite.method.solver import EvINRConfig
from evinr_lite.sim.colour_davis import colour_davis_recording

IMAGES = ("coffee", "astronaut", "chelsea")
FILTERS = ("RGGB", "GRBG", "GBRG", "BGGR")   # the scenes are simulated with RGGB


def main() -> None:
    for image in IMAGES:
        rec = colour_davis_recording(image, sensor_size=(48, 64), duration=0.5, C=0.2, seed=0)
        print(f"{image} (simulated with RGGB, 48x64, 0.5 s, C = 0.2, {len(rec.events):,} events)")
        for cfa in FILTERS:
            r = Recording(rec.events, rec.frames, {**rec.meta, "cfa": cfa, "window": (0.0, 0.5)})
            t0 = time.perf_counter()
            result = reconstruct_colour_recording(r, rec.frames.t, EvINRConfig(C=0.2, progress=False))
            scores, colour = score_colour_recording(result, r, score_predictions)
            chroma = colour["chroma_correlation"]
            print(f"  {cfa}: chroma correlation {colour['chroma_correlation_mean']:+.3f} (R-G {chroma['R-G']:+.3f}, "
                  f"B-G {chroma['B-G']:+.3f}); grey SSIM none {scores['none']['ssim']:.3f}, "
                  f"clahe {scores['clahe']['ssim']:.3f}  [{time.perf_counter() - t0:.1f} s]", flush=True)


if __name__ == "__main__":
    main()
