"""Batched ensemble: N = 10 networks trained in one batched pass versus the same 10 one after another.

    python benchmarks/ensemble_speed.py             # the paper's network size and the notebooks' fast size
    python benchmarks/ensemble_speed.py --quick

Both runs go through the solver's own training function, ``train_frame_inr``: once with the 10
windows together (one FrameINR holding 10 networks, stacked weights, ``torch.bmm``), and once per
window with a one-network copy of the same initial weights (``FrameINR.network(k)``). Same bins
(1/32 s, fixed), same optimiser, same number of steps: the same work, so the predictions must
agree up to float rounding (checked here and in tests/test_perf_equivalence.py). The two alternate
``--repeats`` times and the fastest of each is kept; times are wall-clock for the whole training
call (bins, optimiser, steps).

Settings:
- paper: 240x180 px, SIREN 512 x 3, windows of 5 s (tau) overlapping by 0.5 s, 160 bins per
  network, a few steps without coarse-to-fine (every step costs the same; the ratio is per step);
- fast: the notebooks' fast mode, 32x40 px, SIREN 64 x 2, windows of 0.6 s, 60 steps with
  coarse-to-fine. Tiny matmuls: per-step overheads (Python, autograd, optimiser) dominate;
- small (for information): the same networks on 64x80 px, where the work per step has grown
  enough that overheads matter less.

Events are uniform random (their content does not change the amount of work).
"""
from __future__ import annotations

import copy
import sys
import time

import numpy as np
import torch

try:
    from benchmarks.common import devices, parser, report, row, sync
except ImportError:  # run as a script
    from common import devices, parser, report, row, sync

from evinr_lite import Events  # noqa: E402
from evinr_lite.method.models import FrameINR  # noqa: E402
from evinr_lite.method.solver import EvINRConfig, predict_networks, split_windows, train_frame_inr  # noqa: E402

SETTINGS = {
    "paper": dict(size=(180, 240), hidden=512, layers=3, tau=5.0, overlap=0.5, iters=3, c2f=False, rate=5e4),
    "fast": dict(size=(32, 40), hidden=64, layers=2, tau=0.6, overlap=0.1, iters=60, c2f=True, rate=5e4),
    "small": dict(size=(64, 80), hidden=64, layers=2, tau=0.6, overlap=0.1, iters=60, c2f=True, rate=5e4),
}
TARGETS = {"paper": 3.0, "fast": 3.0, "small": None}


def random_events(n, t_end, size, seed=0) -> Events:
    rng = np.random.default_rng(seed)
    H, W = size
    p = (rng.integers(0, 2, n, dtype=np.int8) * 2 - 1).astype(np.int8)
    return Events(np.sort(rng.uniform(0.0, t_end, n)), rng.integers(0, W, n), rng.integers(0, H, n), p, size)


def compare(setting: str, n_models: int = 10, repeats: int = 2, device="cpu", iters=None, log=print) -> dict:
    s = dict(SETTINGS[setting])
    iters = iters or s["iters"]
    span = n_models * s["tau"] - (n_models - 1) * s["overlap"]
    windows = split_windows(0.0, span, s["tau"] + 1e-9, s["overlap"])
    assert len(windows) == n_models, len(windows)
    events = random_events(int(s["rate"] * span), span, s["size"])
    c2f = (iters // 3, 2 * iters // 3)
    cfg = EvINRConfig.v0_1(C=0.2, hidden_features=s["hidden"], hidden_layers=s["layers"], n_iters=iters,
                      coarse_to_fine=s["c2f"], c2f_iters=c2f, tau=s["tau"], overlap=s["overlap"],
                      device=device, progress=False)
    init = FrameINR(s["size"], windows, s["hidden"], s["layers"], cfg.omega_0, cfg.first_layer_omega(windows), seed=0).to(device)

    def batched():
        model = copy.deepcopy(init)
        sync(device)
        t0 = time.perf_counter()
        train_frame_inr(events, windows, cfg, model=model)
        sync(device)
        return time.perf_counter() - t0, [model]

    def sequential():
        singles = [init.network(k) for k in range(n_models)]
        sync(device)
        t0 = time.perf_counter()
        for k, single in enumerate(singles):
            train_frame_inr(events, windows[k:k + 1], cfg, model=single)
        sync(device)
        return time.perf_counter() - t0, singles

    warm_cfg = EvINRConfig.v0_1(**{**cfg.__dict__, "n_iters": 1, "coarse_to_fine": False})
    train_frame_inr(events, windows[:1], warm_cfg, model=init.network(0))        # warm-up (allocations, kernels)
    train_frame_inr(events, windows, warm_cfg, model=copy.deepcopy(init))
    times = {"batched": [], "sequential": []}
    models = {}
    for r in range(max(1, repeats)):
        order = ("batched", "sequential") if r % 2 == 0 else ("sequential", "batched")
        for name in order:
            seconds, models[name] = (batched if name == "batched" else sequential)()
            times[name].append(seconds)
    tb, ts = min(times["batched"]), min(times["sequential"])
    # the trained predictions of both runs at three times inside every window
    diff = scale = 0.0
    for k in range(n_models):
        tk = np.linspace(windows[k, 0], windows[k, 1], 3)
        a = predict_networks(models["batched"][0], tk)[k]
        b = predict_networks(models["sequential"][k], tk)[0]
        diff, scale = max(diff, float(np.abs(a - b).max())), max(scale, float(np.abs(b).max()))
    same = diff <= 1e-4 * scale
    log(f"ensemble [{setting}, {device}]: N = {n_models}, {s['size'][1]}x{s['size'][0]} px, SIREN {s['hidden']} x "
        f"{s['layers']}, {iters} steps: batched {tb:.2f} s, sequential {ts:.2f} s -> {ts / tb:.2f}x; "
        f"max |difference| of predictions {diff:.1e} (largest |prediction| {scale:.2f}); same up to rounding: {same}")
    return {"setting": setting, "device": device, "n_models": n_models, "iters": iters, "batched_s": tb,
            "sequential_s": ts, "ratio": ts / tb, "ms_per_step_batched": 1e3 * tb / iters,
            "ms_per_network_step_sequential": 1e3 * ts / (iters * n_models), "max_abs_diff": diff,
            "prediction_scale": scale, "same_predictions": same, **{k: v for k, v in s.items() if k != "iters"}}


def run(quick: bool = False, device: str | None = None, repeats: int | None = None, log=print) -> list[dict]:
    repeats = repeats or (2 if quick else 3)
    rows = []
    for dev in devices(device):
        for setting in ("fast", "small", "paper"):
            iters = (2 if setting == "paper" else 30) if quick else None
            r = compare(setting, 10, repeats, dev, iters, log)
            explain = ("same FLOPs either way; each step is a few large matmuls, so batching saves only per-step "
                       "overhead" if setting == "paper" else "tiny matmuls: per-step Python/autograd/optimiser overhead "
                       "dominates and batching pays it once for 10 networks")
            rows.append(row(f"ensemble N=10, batched vs sequential, {setting} size [{dev}]", r["ratio"], "x",
                            target=TARGETS[setting],
                            note=(f"batched {r['batched_s']:.2f} s, sequential {r['sequential_s']:.2f} s "
                                  f"({r['ms_per_step_batched']:.1f} ms per batched step, "
                                  f"{r['ms_per_network_step_sequential']:.1f} ms per network-step one after another); "
                                  f"same predictions: {r['same_predictions']} (max diff {r['max_abs_diff']:.1e}); "
                                  + explain),
                            **r))
            torch.cuda.empty_cache() if dev == "cuda" else None
    return rows


def main(argv=None) -> int:
    p = parser(__doc__, "fewer steps, one repeat")
    a = p.parse_args(argv)
    rows = run(a.quick, a.device, a.repeats)
    report(rows, a.json)
    return 0 if all(r["same_predictions"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
