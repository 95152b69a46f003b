"""End to end: one 5 s sub-sequence of 240x180 events with the paper's defaults; wall time and quality.

    python benchmarks/end_to_end.py                 # 240x180, 5 s, 300 iterations with coarse-to-fine
    python benchmarks/end_to_end.py --quick         # 120x160, 2 s, 100 iterations (a smoke run)
    python benchmarks/end_to_end.py --device cuda   # on a GPU (the paper: about 8 s per sequence on an RTX 3090)

Protocol: the built-in "camera" scene (natural image drifting, rotating, zooming) on 240x180 for
5 s, events simulated with C = 0.2 (seed 0). ``reconstruct`` with ``EvINRConfig.v0_1(C=0.2)`` and
otherwise the paper's defaults: SIREN 512 x 3, 300 Adam iterations (lr 1e-4, x0.95 every 10),
coarse-to-fine bisection at iterations 100 and 200 ending at 1/32 s bins, Tikhonov lambda = 0.05,
tau = 5 s (one network for this sub-sequence). Reported: training time (the optimisation loop),
reconstruction wall time (``reconstruct`` from events to 20 tone-mapped frames: binning, training,
alignment, anchoring, queries) and the quality of those 20 frames against the ground truth
(tone-mapped true log intensity): MSE and SSIM without equalisation and with CLAHE on both images.
The event simulation is not part of the timed reconstruction; its time is reported separately.

The same reconstruction is then run once more with the readable reference training path
(``train_frame_inr(..., fast=False)``: no fused kernels) to show what the optimisations bought and
that they did not change the result: the largest difference between the two runs' frames is
reported (float rounding, amplified a little by 300 steps of training). The fast path runs before
and after it and the faster of its two times is reported. ``--no-reference`` skips both extra runs.
"""
from __future__ import annotations

import functools
import sys
import time

import numpy as np

try:
    from benchmarks.common import devices, parser, report, row, sync
except ImportError:  # run as a script
    from common import devices, parser, report, row, sync

from evinr_lite import make_scene, simulate_scene, tonemap_reinhard  # noqa: E402
from evinr_lite.evaluation.metrics import SCORE_PROTOCOLS, score_frames  # noqa: E402
from evinr_lite.method import solver  # noqa: E402
from evinr_lite.method.solver import EvINRConfig, reconstruct  # noqa: E402

PAPER_SECONDS = 8.0   # per sequence on one RTX 3090 (Sec. 4)


def timed(fn, device):
    """(result, wall-clock seconds) of fn()."""
    sync(device)
    t0 = time.perf_counter()
    out = fn()
    sync(device)
    return out, time.perf_counter() - t0


def reconstruct_reference(events, q, cfg):
    """``reconstruct`` with the readable training path (``train_frame_inr(..., fast=False)``)."""
    fast = solver.train_frame_inr
    solver.train_frame_inr = functools.partial(fast, fast=False)
    try:
        return reconstruct(events, q, cfg)
    finally:
        solver.train_frame_inr = fast


def run(quick: bool = False, device: str | None = None, reference: bool = True, log=print) -> list[dict]:
    size, duration, iters = ((120, 160), 2.0, 100) if quick else ((180, 240), 5.0, 300)
    scene = make_scene("camera", sensor_size=size, duration=duration)
    t0 = time.perf_counter()
    events = simulate_scene(scene, 0.0, duration, C=0.2, seed=0)
    simulate_s = time.perf_counter() - t0
    q = np.linspace(0.025 * duration, 0.975 * duration, 20)
    gt = tonemap_reinhard(scene.log_intensity(q))
    log(f"end to end: {size[1]}x{size[0]}, {duration:g} s, {len(events):,} events (simulated in {simulate_s:.1f} s)")
    rows = []
    for dev in devices(device):
        cfg = EvINRConfig.v0_1(C=0.2, n_iters=iters, c2f_iters=(iters // 3, 2 * iters // 3), device=dev, progress=False)
        rec, wall = timed(lambda: reconstruct(events, q, cfg), dev)
        if reference:   # reference path, then the fast path again: the two fast runs bracket it
            ref, wall_ref = timed(lambda: reconstruct_reference(events, q, cfg), dev)
            again, wall_again = timed(lambda: reconstruct(events, q, cfg), dev)
            wall = min(wall, wall_again)
            train = min(rec.history["train_time_s"], again.history["train_time_s"])
        else:
            train = rec.history["train_time_s"]
        scores = {eq: score_frames(rec.frames, gt, eq) for eq in SCORE_PROTOCOLS}
        quality = (f"MSE {scores['none']['mse']:.4f} SSIM {scores['none']['ssim']:.3f} | CLAHE: MSE "
                   f"{scores['clahe']['mse']:.4f} SSIM {scores['clahe']['ssim']:.3f}")
        log(f"end to end [{dev}]: reconstruct {wall:.1f} s (training {train:.1f} s, {iters} iterations, "
            f"bins {rec.history['n_bins'][0]} -> {rec.history['n_bins'][-1]}); {quality}")
        rows.append(row(f"end to end: {size[1]}x{size[0]}, {duration:g} s, {iters} it. + C2F, wall time [{dev}]",
                        wall, "s", note=f"training {train:.1f} s; {quality}; paper: ~{PAPER_SECONDS:g} s on an RTX 3090",
                        device=dev, train_s=train, simulate_s=simulate_s, n_events=len(events),
                        scores={eq: {k: scores[eq][k] for k in ("mse", "ssim")} for eq in scores},
                        paper_s=PAPER_SECONDS, quick=quick))
        rows.append(row(f"end to end: quality SSIM (CLAHE) [{dev}]", scores["clahe"]["ssim"], "",
                        note=f"MSE (CLAHE) {scores['clahe']['mse']:.4f}; without equalisation SSIM "
                             f"{scores['none']['ssim']:.3f}, MSE {scores['none']['mse']:.4f}"))
        if not reference:
            continue
        diff = float(np.abs(ref.frames - rec.frames).max())
        rerun = float(np.abs(again.frames - rec.frames).max())
        ssim_ref = score_frames(ref.frames, gt, "clahe")["ssim"]
        log(f"end to end [{dev}], reference training path: reconstruct {wall_ref:.1f} s (training "
            f"{ref.history['train_time_s']:.1f} s), {wall_ref / wall:.2f}x the fast path's best; SSIM (CLAHE) "
            f"{ssim_ref:.3f}; largest |frame difference| from the fast path {diff:.1e} (frames in [0, 1]); "
            f"the fast path run twice: {rerun:.1e}")
        rows.append(row(f"end to end: reference / fast path wall time [{dev}]", wall_ref / wall, "x",
                        note=f"reference path {wall_ref:.1f} s (one run), fast path {wall:.1f} s (best of the two "
                             f"runs around it); SSIM (CLAHE) {ssim_ref:.3f}",
                        reference_s=wall_ref, fast_s=wall, device=dev))
        rows.append(row(f"end to end: largest |frame difference|, fast vs reference path [{dev}]", diff, "",
                        target=1e-3, higher_is_better=False, max_frame_diff=diff, rerun_max_diff=rerun,
                        note=f"frames in [0, 1]: the same result up to float rounding (1/255 = 3.9e-03); the fast "
                             f"path run twice differs by {rerun:.1e}"))
    return rows


def main(argv=None) -> int:
    p = parser(__doc__, "120x160, 2 s, 100 iterations", repeats=False)
    p.add_argument("--no-reference", action="store_true", help="skip the run with the reference training path")
    a = p.parse_args(argv)
    rows = run(a.quick, a.device, not a.no_reference)
    report(rows, a.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
