"""One training step of the frame-based INR at 240x180: achieved GFLOP/s against this machine's fp32 matmul peak.

    python benchmarks/train_step.py                 # 240x180, 512 x 3, 160 and 40 bins, fast and reference paths
    python benchmarks/train_step.py --profile       # also the top operations of each path (torch.profiler)

Protocol: one network (N = 1) of the paper's size, the derivative-form temporal loss + Tikhonov, Adam;
bins of a 5 s window at 1/32 s (B = 160, the last coarse-to-fine stage) and 4x coarser (B = 40, the
first). The fast path is what ``reconstruct`` runs (fused Adam, the output layer and losses fused in
one autograd node); the reference path is the readable one (``forward_with_derivative`` + the loss
functions + PyTorch's default Adam). Each step is timed alternately with the matmul peak
(``torch.matmul`` of two 4096 x 4096 fp32 matrices, same process and threads); the fastest of
``--repeats`` is kept for each.

FLOPs counted (matmuls only, 2 m n k each; backward = 2 matmuls per forward matmul, so 3x forward):
    hidden layers: L x (h path + dh path) = L x 2 x 2 T d^2
    output layer:  [h; dh] (2T x d) @ (d x H W) = 2 x 2T x d x H W
    total = 3 x N x (4 L T d^2 + 4 T d H W)
The first layer (input width 1) and the sines are elementwise and not counted.
"""
from __future__ import annotations

import sys

import numpy as np
import torch

try:
    from benchmarks.common import alternate, devices, matmul_peak_gflops, parser, report, row
except ImportError:  # run as a script
    from common import alternate, devices, matmul_peak_gflops, parser, report, row

from evinr_lite.method.models import FrameINR  # noqa: E402
from evinr_lite.method.training import _Bins, make_adam, step_losses  # noqa: E402


def step_flops(n_models: int, bins: int, hidden: int, layers: int, pixels: int) -> float:
    """Matmul FLOPs of one training step (forward + backward), as in the module docstring."""
    return 3.0 * n_models * (4 * layers * bins * hidden ** 2 + 4 * bins * hidden * pixels)


def make_step(sensor_size=(180, 240), n_bins=160, hidden=512, layers=3, n_models=1, fast=True, device="cpu",
              lam=0.05, seed=0):
    """A closure running one training step of a FrameINR (what train_frame_inr does per iteration)."""
    H, W = sensor_size
    window = 5.0
    windows = np.array([[k * window, (k + 1) * window] for k in range(n_models)])
    model = FrameINR(sensor_size, windows, hidden, layers, 30.0, 10.0, seed=seed).to(device)
    b = np.stack([np.linspace(lo, hi, n_bins + 1) for lo, hi in windows])
    g = torch.Generator().manual_seed(seed)
    frames = (0.2 * torch.randint(-2, 3, (n_models, n_bins, H, W), generator=g)).float()
    bins = _Bins(boundaries=torch.as_tensor(b, device=device),
                 centers=torch.as_tensor(0.5 * (b[:, 1:] + b[:, :-1]), device=device),
                 durations=torch.as_tensor(np.diff(b, axis=1), dtype=torch.float32, device=device),
                 frames=frames.to(device))
    head = [model.head_weight, model.head_bias]
    trunk = [p for name, p in model.named_parameters() if not name.startswith("head_")]
    groups = [{"params": trunk}, {"params": head, "lr": 3e-3}]
    opt = make_adam(groups, lr=1e-4) if fast else torch.optim.Adam(groups, lr=1e-4)

    buffers = {} if fast else None            # as train_frame_inr: work arrays reused from step to step

    def step():
        temporal, reg = step_losses(model, bins, "derivative", "tikhonov", fused=fast, buffers=buffers)
        loss = model.n_models * (temporal + lam * reg)
        opt.zero_grad(set_to_none=True)
        loss.backward()
        opt.step()
        return loss

    return step


def profile_table(step, device, rows=12) -> str:
    step()
    activities = [torch.profiler.ProfilerActivity.CPU]
    if torch.device(device).type == "cuda":
        activities.append(torch.profiler.ProfilerActivity.CUDA)
    with torch.profiler.profile(activities=activities) as prof:
        step()
    table = prof.key_averages()
    if torch.device(device).type == "cuda":
        for key in ("self_device_time_total", "self_cuda_time_total"):   # the name changed across torch versions
            try:
                return table.table(sort_by=key, row_limit=rows)
            except (AttributeError, KeyError, ValueError):
                continue
    return table.table(sort_by="self_cpu_time_total", row_limit=rows)


def run(quick: bool = False, device: str | None = None, repeats: int | None = None, profile: bool = False,
        sizes=((180, 240),), log=print) -> list[dict]:
    repeats = repeats or (3 if quick else 5)
    rows = []
    for dev in devices(device):
        peak_candidates = []
        for size in sizes:
            H, W = size
            for n_bins in ((160,) if quick else (160, 40)):
                flops = step_flops(1, n_bins, 512, 3, H * W)
                steps = {"fast": make_step(size, n_bins, fast=True, device=dev),
                         "reference": make_step(size, n_bins, fast=False, device=dev)}
                for s in steps.values():                       # warm-up: allocations, kernel choice
                    s()
                peak = {}
                times = alternate({"peak": lambda: peak.setdefault("v", []).append(matmul_peak_gflops(dev, repeats=2)),
                                   **steps}, repeats, dev)
                peak_gflops = max(peak["v"])
                peak_candidates.append(peak_gflops)
                label = f"train step {H}x{W}, B={n_bins} [{dev}]"
                for path in ("fast", "reference"):
                    gflops = flops / times[path] / 1e9
                    frac = 100 * gflops / peak_gflops
                    log(f"{label} {path:9s}: {times[path] * 1e3:7.1f} ms/step, {gflops:6.1f} GFLOP/s = "
                        f"{frac:5.1f}% of the {peak_gflops:.0f} GFLOP/s matmul peak")
                    rows.append(row(f"{label}: % of matmul peak ({path} path)", frac, "%",
                                    target=50.0 if path == "fast" and n_bins == 160 else None,
                                    note=(f"{gflops:.0f} of {peak_gflops:.0f} GFLOP/s, {times[path] * 1e3:.0f} ms/step"
                                          if path == "fast" else ""),
                                    gflops=gflops, ms_per_step=times[path] * 1e3, peak_gflops=peak_gflops,
                                    flops_per_step=flops, device=dev, bins=n_bins, path=path))
                speedup = times["reference"] / times["fast"]
                log(f"{label}: fast path {speedup:.2f}x faster than the reference path")
                rows.append(row(f"{label}: fast / reference speed", speedup, "x", device=dev))
                if profile:
                    for path, s in steps.items():
                        log(f"--- {label} {path} path: top operations ---")
                        log(profile_table(s, dev))
                del steps
        rows.append(row(f"fp32 matmul peak [{dev}]", max(peak_candidates), "GFLOP/s", device=dev,
                        note="torch.matmul 4096^2 (8192^2 on a GPU), best of the runs above"))
    return rows


def main(argv=None) -> int:
    p = parser(__doc__, "only B = 160, fewer repeats")
    p.add_argument("--profile", action="store_true", help="print the top operations of each path")
    a = p.parse_args(argv)
    rows = run(a.quick, a.device, a.repeats, a.profile)
    report(rows, a.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
