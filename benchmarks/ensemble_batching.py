"""N EvINR networks trained in one batched pass versus the same N trained one after another.

    python benchmarks/ensemble_batching.py                          # 64x80 px, 256 wide, N = 1, 2, 4, 8
    python benchmarks/ensemble_batching.py --n 1 4 16 --hidden 64   # small networks: overheads dominate
    python benchmarks/ensemble_batching.py --device cuda            # on a GPU, where batching is meant to pay

Protocol: a synthetic scene (cameraman drifting at a varying speed, C = 0.2) is cut into N equal
windows with ``split_windows``; each network gets its window's fixed 1/32 s bins. The batched run
trains one ``FrameINR`` holding N networks (stacked weights, ``torch.baddbmm``); the sequential run
trains N one-network ``FrameINR``s whose initial weights are copies of the batched model's slices,
one after another, for the same number of steps: the same work, the same optimiser (Adam; the loss
is averaged per network and summed, so each network's gradient is the same both ways). After a short
warm-up the two runs alternate ``--repeats`` times (which goes first alternates too) and the fastest
of each is kept; the ratio is measured within one run, on the same machine load. The N = 1 row does the same computation both
ways, so its ratio shows the timing noise. Finally the trained predictions of the two are compared
at the bin centres: they should agree to float rounding.

Times are wall-clock on this machine and noisy when other jobs share it; ``--threads`` sets torch's
CPU threads (default 1: on a shared CPU, small networks run faster and more steadily on one thread).
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from evinr_lite import make_scene, simulate_scene  # noqa: E402
from evinr_lite.teaching.accel_exercises import VaryingSpeedScene, batched_vs_sequential  # noqa: E402
from evinr_lite.method.solver import split_windows  # noqa: E402


def run(n_models=(1, 2, 4, 8), size=(64, 80), duration=4.0, hidden=256, layers=3, iters=50, repeats=3,
        C=0.2, overlap=0.1, seed=0, device=None, log=print) -> dict:
    base = make_scene("camera", sensor_size=size, duration=duration, velocity=(8.0, 4.0), rotation=0.1, zoom=0.05)
    events = simulate_scene(VaryingSpeedScene(base), 0.0, duration, C=C, seed=seed)
    dev = torch.device(device) if device else None
    log(f"scene {size[0]}x{size[1]} px, {duration:g} s, {len(events):,} events; SIREN {hidden} wide x {layers} hidden "
        f"layers; {iters} steps per network; fastest of {repeats}; device "
        f"{device or ('cuda' if torch.cuda.is_available() else 'cpu')}, {torch.get_num_threads()} CPU thread(s)")
    log(f"{'N':>4s} {'window (s)':>10s} {'bins/net':>8s} {'params':>11s} {'batched (s)':>12s} {'sequential (s)':>15s} "
        f"{'seq./batched':>13s} {'max |diff|':>11s} {'pred. std':>10s}")
    rows = []
    for n in n_models:
        tau = None if n == 1 else (duration + (n - 1) * overlap) / n + 1e-9
        windows = split_windows(0.0, duration, tau, overlap)
        if len(windows) != n:
            raise RuntimeError(f"split_windows gave {len(windows)} windows for N = {n}")
        r = batched_vs_sequential(events, windows, hidden_features=hidden, hidden_layers=layers, n_iters=iters, C=C,
                                  repeats=repeats, seed=seed, device=dev)
        length = windows[0, 1] - windows[0, 0]
        r.update(window_s=float(length), bins_per_network=max(1, round(length * 32)))
        rows.append(r)
        log(f"{n:4d} {length:10.3f} {r['bins_per_network']:8d} {r['n_parameters']:11,d} {r['batched_s']:12.2f} "
            f"{r['sequential_s']:15.2f} {r['ratio']:13.2f} {r['max_abs_diff']:11.1e} {r['pred_scale']:10.3f}")
    worst = max(r["max_abs_diff"] / max(r["pred_scale"], 1e-12) for r in rows)
    log(f"largest prediction difference, relative to the predictions' spread: {worst:.1e} "
        f"({'same predictions up to float noise' if worst < 1e-3 else 'PREDICTIONS DIFFER'})")
    return {"size": list(size), "duration_s": duration, "hidden": hidden, "layers": layers, "iters": iters,
            "repeats": repeats, "n_events": len(events), "threads": torch.get_num_threads(), "rows": rows,
            "same_predictions": bool(worst < 1e-3)}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--n", type=int, nargs="+", default=[1, 2, 4, 8], help="numbers of networks N")
    p.add_argument("--size", default="64x80", help="sensor HxW (default 64x80)")
    p.add_argument("--duration", type=float, default=4.0, help="seconds of events (default 4)")
    p.add_argument("--hidden", type=int, default=256, help="SIREN width (paper: 512)")
    p.add_argument("--layers", type=int, default=3, help="hidden layers (paper: 3)")
    p.add_argument("--iters", type=int, default=50, help="training steps per network (default 50)")
    p.add_argument("--repeats", type=int, default=3, help="alternating timing repeats; the fastest is kept")
    p.add_argument("--threads", type=int, default=1, help="torch CPU threads (0: torch's default)")
    p.add_argument("--device", default=None, help="cpu or cuda (default: cuda when available)")
    p.add_argument("--json", default=None, help="also write the results to this JSON file")
    args = p.parse_args(argv)
    if args.threads:
        torch.set_num_threads(args.threads)
    H, W = (int(v) for v in args.size.lower().split("x"))
    result = run(args.n, (H, W), args.duration, args.hidden, args.layers, args.iters, args.repeats, device=args.device)
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=1))
    return 0 if result["same_predictions"] else 1


if __name__ == "__main__":
    sys.exit(main())
