"""What every speed benchmark shares: best-of-k timing, the machine's own matmul peak, result rows.

Timings on a shared machine are noisy: other programs steal cores at random moments. So every
number here is the fastest of several repeats (noise only ever adds time), and every comparison
is a ratio of two quantities measured in the same process, alternately, under the same load.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np
import torch

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))


def sync(device) -> None:
    """Wait for the GPU to finish (timings of CUDA work need it); nothing on a CPU."""
    if torch.device(device).type == "cuda":
        torch.cuda.synchronize(device)


def best_time(fn, repeats: int = 3, device="cpu") -> float:
    """Fastest wall-clock seconds of ``repeats`` calls of fn()."""
    best = float("inf")
    for _ in range(max(1, repeats)):
        sync(device)
        t0 = time.perf_counter()
        fn()
        sync(device)
        best = min(best, time.perf_counter() - t0)
    return best


def alternate(fns: dict, repeats: int = 3, device="cpu") -> dict:
    """Best seconds of each fn in ``fns`` (name -> fn), calling them in turn ``repeats`` times.

    Alternating puts every candidate under the same stretch of machine load, so their ratio is
    fair even when the absolute times are not.
    """
    best = {name: float("inf") for name in fns}
    for r in range(max(1, repeats)):
        names = list(fns) if r % 2 == 0 else list(fns)[::-1]
        for name in names:
            best[name] = min(best[name], best_time(fns[name], 1, device))
    return best


def matmul_peak_gflops(device="cpu", n: int | None = None, repeats: int = 5) -> float:
    """This machine's fp32 matmul rate (GFLOP/s): torch.matmul of two n x n float32 matrices.

    Same process and threads as the benchmark that compares with it. n defaults to 4096 on a
    CPU (large enough to reach the plateau) and 8192 on a GPU. TF32 is left off (fp32 peak).
    """
    device = torch.device(device)
    n = n or (8192 if device.type == "cuda" else 4096)
    g = torch.Generator(device="cpu").manual_seed(0)
    a = torch.randn(n, n, generator=g).to(device)
    b = torch.randn(n, n, generator=g).to(device)
    out = torch.empty(n, n, device=device)
    torch.matmul(a, b, out=out)                                   # warm-up: kernels, pages
    seconds = best_time(lambda: torch.matmul(a, b, out=out), repeats, device)
    return 2 * n ** 3 / seconds / 1e9


def row(name: str, measured: float, unit: str, target: float | None = None, higher_is_better: bool = True,
        note: str = "", **extra) -> dict:
    """One line of the summary table.

    ratio = measured / target when higher is better, else target / measured, so ratio >= 1 always
    means the target is met. Rows without a target are reported for information (met = None).
    """
    ratio = met = None
    if target is not None and measured is not None and np.isfinite(measured) and measured > 0:
        ratio = measured / target if higher_is_better else target / measured
        met = bool(ratio >= 1)
    return {"name": name, "measured": measured, "unit": unit, "target": target,
            "target_kind": None if target is None else (">=" if higher_is_better else "<="),
            "ratio": ratio, "met": met, "note": note, **extra}


def fmt(v) -> str:
    if v is None:
        return "-"
    if isinstance(v, float):
        if v == 0 or 0.01 <= abs(v) < 1e5:
            return f"{v:.3g}" if abs(v) < 100 else f"{v:.0f}"
        return f"{v:.2e}"
    return str(v)


def print_table(rows: list[dict], log=print) -> None:
    """The summary: benchmark | target | measured | ratio | met?"""
    head = ("benchmark", "target", "measured", "ratio", "met?")
    lines = []
    for r in rows:
        target = "-" if r["target"] is None else f"{r['target_kind']} {fmt(r['target'])} {r['unit']}"
        met = {True: "yes", False: "NO", None: "info"}[r["met"]]
        lines.append((r["name"], target, f"{fmt(r['measured'])} {r['unit']}", fmt(r["ratio"]), met))
    widths = [max(len(str(x[i])) for x in [head] + lines) for i in range(len(head))]
    sep = "  "
    log(sep.join(h.ljust(w) for h, w in zip(head, widths)))
    log(sep.join("-" * w for w in widths))
    for line in lines:
        log(sep.join(str(x).ljust(w) for x, w in zip(line, widths)))
    notes = [(r["name"], r["note"]) for r in rows if r.get("note")]
    if notes:
        log("")
        for name, note in notes:
            log(f"  {name}: {note}")


def machine() -> dict:
    """What the numbers were measured on."""
    info = {"python": platform.python_version(), "torch": torch.__version__, "numpy": np.__version__,
            "cpu": platform.processor() or platform.machine(), "cpu_count": os.cpu_count(),
            "torch_threads": torch.get_num_threads(), "cuda": torch.cuda.is_available()}
    try:
        with open("/proc/cpuinfo") as f:
            names = [line.split(":", 1)[1].strip() for line in f if line.startswith("model name")]
        info["cpu"] = names[0] if names else info["cpu"]
    except OSError:
        pass
    if torch.cuda.is_available():
        info["gpu"] = torch.cuda.get_device_name(0)
    if hasattr(os, "getloadavg"):
        info["load_average_1min"] = os.getloadavg()[0]
    return info


def write_json(path, obj) -> None:
    """Write JSON atomically (temporary file, then rename)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.partial")
    tmp.write_text(json.dumps(obj, indent=1, default=float) + "\n")
    os.replace(tmp, path)


def devices(requested: str | None = None) -> list[str]:
    """["cpu"], plus "cuda" when a GPU is present (or exactly the one device asked for)."""
    if requested:
        return [requested]
    return ["cpu", "cuda"] if torch.cuda.is_available() else ["cpu"]


def parser(doc: str, quick_help: str, *, device: bool = True, repeats: bool = True) -> argparse.ArgumentParser:
    """The options every benchmark script takes: --quick, --device, --repeats, --json."""
    p = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help=quick_help)
    if device:
        p.add_argument("--device", default=None, help="cpu or cuda (default: cpu, and cuda when present)")
    if repeats:
        p.add_argument("--repeats", type=int, default=None)
    p.add_argument("--json", default=None, help="also write the rows to this JSON file")
    return p


def report(rows: list[dict], json_path=None) -> None:
    """Print the rows' table and, when asked, write them to a JSON file."""
    print()
    print_table(rows)
    if json_path:
        write_json(json_path, rows)
