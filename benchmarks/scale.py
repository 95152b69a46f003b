"""Scale: wall time, training time and peak memory of ``evinr-lite reconstruct`` against length and pixels.

    python benchmarks/scale.py            # 2 -> 120 s at 240x180; 240x180 .. 1280x720 at 2 s and 20 s
    python benchmarks/scale.py --quick    # 2, 10, 20 s at 240x180; 240x180 and 346x260 at 2 s
    python -m benchmarks --only scale

Each recording is ``make_scene("camera")`` + ``simulate_scene`` (2 s, C = 0.2, seed 0) at the
sensor's size, with time-shifted copies concatenated for length (as issue 22 built them), written
to a canonical .h5 file in a temporary folder and read back through ``evinr-lite reconstruct
FILE --out DIR --fps 20 --no-video --quiet`` with the kit's default (PNGs written, MP4/GIF not).
Every run is its own process, started from a small wrapper process that reports
``resource.getrusage(RUSAGE_CHILDREN)``: the peak resident memory (ru_maxrss) and the CPU seconds
of the run alone. Training seconds and the memory estimate come from the run's run.json.

Results: ``benchmarks/scale_results.json`` / ``.md`` and ``benchmarks/scale_figure.png``. Wall
times on a machine shared with other jobs are inflated: the load average is recorded beside them,
and the CPU seconds (user + system) are less sensitive to it.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.common import row  # noqa: E402

HERE = Path(__file__).resolve().parent
FPS = 20
BASE = (180, 240)
DURATIONS = (2, 10, 20, 60, 120)
SENSORS = ((180, 240), (260, 346), (480, 640), (720, 1280))
SENSOR_DURATIONS = (2, 20)
QUICK_DURATIONS = (2, 10, 20)
QUICK_SENSORS = ((180, 240), (260, 346))
QUICK_SENSOR_DURATIONS = (2,)
# issue 22's targets (2 CPU cores, the kit default, PNGs included)
TARGETS = {"wall_60": 20.0, "rss_60": 1.5e9, "ratio_120_60": 2.2, "wall_hd20": 180.0, "rss_hd20": 4e9,
           "wall_hd2": 15.0, "estimate_error": 0.25}

_WRAPPER = """
import json, resource, subprocess, sys, time
t0 = time.perf_counter()
rc = subprocess.run(sys.argv[1:]).returncode
wall = time.perf_counter() - t0
u = resource.getrusage(resource.RUSAGE_CHILDREN)
print(json.dumps({"rc": rc, "wall_s": wall, "peak_rss_bytes": u.ru_maxrss * 1024, "cpu_s": u.ru_utime + u.ru_stime}))
"""


def make_recording(path: Path, sensor, seconds: float) -> int:
    """Write the camera scene at ``sensor`` (H, W), repeated to ``seconds``, as a canonical file; returns
    the number of events."""
    from evinr_lite import make_scene, simulate_scene
    from evinr_lite.io.canonical import CanonicalWriter

    ev = simulate_scene(make_scene("camera", sensor_size=tuple(sensor), duration=2.0), C=0.2, seed=0)
    n = 0
    with CanonicalWriter(path, sensor_size=tuple(sensor), C=0.2, dataset="scale benchmark") as w:
        for k in range(int(np.ceil(seconds / 2.0))):
            keep = ev.t + 2.0 * k < seconds
            w.add_events(ev.t[keep] + 2.0 * k, ev.x[keep], ev.y[keep], ev.p[keep])
            n += int(keep.sum())
    return n


def measure(path: Path, out: Path, extra=()) -> dict:
    """One ``evinr-lite reconstruct`` run in its own process: wall, CPU seconds, peak RSS, training, estimate."""
    cmd = [sys.executable, "-m", "evinr_lite", "reconstruct", str(path), "--out", str(out), "--fps", str(FPS),
           "--no-video", "--quiet", *extra]
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else None
    res = subprocess.run([sys.executable, "-c", _WRAPPER, *cmd], capture_output=True, text=True)
    got = json.loads(res.stdout.strip().splitlines()[-1])
    if got["rc"] != 0:
        raise RuntimeError(f"reconstruct failed ({got['rc']}): {res.stderr[-2000:]}")
    run = json.loads((out / "run.json").read_text())
    got.update(train_s=run.get("train_time_s"), estimate_bytes=run.get("memory_estimate_bytes"),
               n_frames=run.get("n_frames_written"), load_1min=load)
    return got


def run_cases(cases, log=print) -> list[dict]:
    results = []
    with tempfile.TemporaryDirectory(prefix="evinr-scale-") as tmp:
        for sensor, seconds in cases:
            path = Path(tmp) / f"camera_{sensor[0]}x{sensor[1]}_{seconds}s.h5"
            n_events = make_recording(path, sensor, seconds)
            got = measure(path, Path(tmp) / f"out_{sensor[0]}x{sensor[1]}_{seconds}")
            got.update(sensor=list(sensor), seconds=seconds, n_events=n_events)
            results.append(got)
            log(f"  {sensor[1]}x{sensor[0]} {seconds:>4g} s  {n_events / 1e6:6.2f} M events  wall {got['wall_s']:6.1f} s  "
                f"cpu {got['cpu_s']:6.1f} s  training {got['train_s']:6.1f} s  peak {got['peak_rss_bytes'] / 2**30:5.2f} GiB"
                f"  estimate {got['estimate_bytes'] / 2**30:5.2f} GiB  load {got['load_1min']:.1f}")
            path.unlink()
    return results


def _find(results, sensor, seconds):
    for r in results:
        if tuple(r["sensor"]) == tuple(sensor) and r["seconds"] == seconds:
            return r
    return None


def target_rows(results) -> list[dict]:
    rows = []
    errors = [abs(r["estimate_bytes"] - r["peak_rss_bytes"]) / r["peak_rss_bytes"] for r in results]
    rows.append(row("scale: memory estimate vs peak RSS, worst relative error", max(errors), "fraction",
                    TARGETS["estimate_error"], higher_is_better=False))
    r60, r120 = _find(results, BASE, 60), _find(results, BASE, 120)
    if r60:
        rows.append(row("scale: 240x180 60 s wall", r60["wall_s"], "s", TARGETS["wall_60"], higher_is_better=False,
                        note=f"cpu {r60['cpu_s']:.1f} s, load {r60['load_1min']:.1f}"))
        rows.append(row("scale: 240x180 60 s peak RSS", r60["peak_rss_bytes"] / 1e9, "GB", TARGETS["rss_60"] / 1e9,
                        higher_is_better=False))
    if r60 and r120:
        rows.append(row("scale: 120 s / 60 s wall", r120["wall_s"] / r60["wall_s"], "x", TARGETS["ratio_120_60"],
                        higher_is_better=False, note=f"cpu ratio {r120['cpu_s'] / r60['cpu_s']:.2f}"))
    for seconds, key in ((2, "hd2"), (20, "hd20")):
        r = _find(results, (720, 1280), seconds)
        if r:
            rows.append(row(f"scale: 1280x720 {seconds} s wall", r["wall_s"], "s", TARGETS[f"wall_{key}"],
                            higher_is_better=False, note=f"cpu {r['cpu_s']:.1f} s, load {r['load_1min']:.1f}"))
            if key == "hd20":
                rows.append(row("scale: 1280x720 20 s peak RSS", r["peak_rss_bytes"] / 1e9, "GB",
                                TARGETS["rss_hd20"] / 1e9, higher_is_better=False))
    return rows


def markdown(results, info) -> str:
    lines = ["# Scale: `evinr-lite reconstruct` against length and pixels", "",
             f"Command: `python benchmarks/scale.py{' --quick' if info['quick'] else ''}` on {info['cpu_count']} CPUs "
             f"(torch threads {info['torch_threads']}); 1-min load average {info['load_start']:.1f} at the start, "
             f"{info['load_end']:.1f} at the end (a machine shared with other jobs: wall times are inflated, CPU "
             "seconds less so). Kit default, --fps 20, PNGs written (no MP4/GIF), each run its own process.", "",
             "| sensor (W x H) | length | events | frames | wall | CPU | training | peak RSS | estimate | est. / peak | load |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        lines.append(f"| {r['sensor'][1]}x{r['sensor'][0]} | {r['seconds']:g} s | {r['n_events'] / 1e6:.2f} M | "
                     f"{r['n_frames']} | {r['wall_s']:.1f} s | {r['cpu_s']:.1f} s | {r['train_s']:.1f} s | "
                     f"{r['peak_rss_bytes'] / 2**30:.2f} GiB | {r['estimate_bytes'] / 2**30:.2f} GiB | "
                     f"{r['estimate_bytes'] / r['peak_rss_bytes']:.2f} | {r['load_1min']:.1f} |")
    return "\n".join(lines) + "\n"


def figure(results, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    base = sorted((r for r in results if tuple(r["sensor"]) == BASE), key=lambda r: r["seconds"])
    ax = axes[0]
    if base:
        s = [r["seconds"] for r in base]
        ax.plot(s, [r["wall_s"] for r in base], "o-", label="wall (s)")
        ax.plot(s, [r["cpu_s"] for r in base], "s--", label="CPU (s)")
        ax2 = ax.twinx()
        ax2.plot(s, [r["peak_rss_bytes"] / 2**30 for r in base], "^-", color="C3", label="peak RSS (GiB)")
        ax2.plot(s, [r["estimate_bytes"] / 2**30 for r in base], "v:", color="C3", label="estimate (GiB)")
        ax2.set_ylabel("memory (GiB)", fontsize=9)
        ax2.set_ylim(bottom=0)
        ax2.legend(loc="upper center", fontsize=9)
    ax.set_xlabel("recording length (s), 240x180", fontsize=9)
    ax.set_ylabel("seconds", fontsize=9)
    ax.set_ylim(bottom=0)
    ax.legend(loc="upper left", fontsize=9)
    ax.set_title("time and memory against length", fontsize=10)
    ax = axes[1]
    for seconds, marker in ((2, "o"), (20, "s")):
        rs = sorted((r for r in results if r["seconds"] == seconds and list(r["sensor"]) in [list(x) for x in SENSORS]),
                    key=lambda r: r["sensor"][0] * r["sensor"][1])
        if len(rs) < 2 and seconds == 20:
            continue
        px = [r["sensor"][0] * r["sensor"][1] / 1e6 for r in rs]
        ax.plot(px, [r["wall_s"] for r in rs], marker + "-", label=f"wall, {seconds} s (s)")
        ax.plot(px, [r["peak_rss_bytes"] / 2**30 for r in rs], marker + ":", label=f"peak RSS, {seconds} s (GiB)")
    ax.set_xlabel("pixels (millions)", fontsize=9)
    ax.set_ylabel("seconds / GiB", fontsize=9)
    ax.set_ylim(bottom=0)
    ax.legend(fontsize=9)
    ax.set_title("time and memory against pixels", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def run(quick: bool = False, log=print, write: bool = True) -> list[dict]:
    import torch

    durations = QUICK_DURATIONS if quick else DURATIONS
    sensors, sensor_durations = (QUICK_SENSORS, QUICK_SENSOR_DURATIONS) if quick else (SENSORS, SENSOR_DURATIONS)
    cases = [(BASE, s) for s in durations]
    cases += [(sensor, s) for s in sensor_durations for sensor in sensors if (tuple(sensor), s) not in
              [(tuple(c[0]), c[1]) for c in cases]]
    info = {"quick": quick, "cpu_count": os.cpu_count(), "torch_threads": torch.get_num_threads(),
            "load_start": os.getloadavg()[0], "started": time.strftime("%Y-%m-%d %H:%M:%S %Z")}
    results = run_cases(cases, log)
    info["load_end"] = os.getloadavg()[0]
    if write:
        (HERE / "scale_results.json").write_text(json.dumps({"info": info, "results": results}, indent=2) + "\n")
        (HERE / "scale_results.md").write_text(markdown(results, info))
        figure(results, HERE / "scale_figure.png")
        log(f"wrote {HERE / 'scale_results.json'}, scale_results.md and scale_figure.png")
    return target_rows(results)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help="2, 10, 20 s at 240x180; 240x180 and 346x260 at 2 s")
    a = p.parse_args(argv)
    from benchmarks.common import print_table

    print_table(run(a.quick))
    return 0


if __name__ == "__main__":
    sys.exit(main())
