"""Every speed benchmark in one command: one table (target / measured / ratio / met?) and a JSON file.

    python -m benchmarks                    # everything, full size (about 10 minutes on 2 CPU cores)
    python -m benchmarks --quick            # smaller sizes, fewer repeats (a few minutes)
    python -m benchmarks --only binning inference --json bench.json
    python -m benchmarks --device cuda      # GPU rows only (the CPU rows run too when no device is named)

Benchmarks (each is also a script with its own --help):
    train_step   benchmarks/train_step.py      training step GFLOP/s against the fp32 matmul peak
    ensemble     benchmarks/ensemble_speed.py  N = 10 networks batched versus one after another
    binning      benchmarks/binning_speed.py   events -> frames (events/s); a 10^8-event file's peak memory
    simulate     benchmarks/simulate_speed.py  the 2-D simulator on 1000 frames of 240x180
    inference    benchmarks/inference.py       frames per second at 240x180 and 408x306
    end_to_end   benchmarks/end_to_end.py      a 5 s 240x180 sequence with the paper's defaults: time and quality
    zoo          benchmarks/quality_zoo.py     quality and time on the scene zoo (kit, paper, v0.1, baselines, oracle)
    robustness   benchmarks/robustness.py      quality as events are thinned, noise added, C mis-given (3 zoo scenes)
    denoise      benchmarks/denoise.py         hot pixels and background removed vs the truth, the gain, tonic
    scale        benchmarks/scale.py           reconstruct's wall time, training and peak memory, 2-120 s, up to 1280x720

ratio >= 1 means the target is met (measured / target, or target / measured for times and memory).
Times are wall-clock on this machine, the fastest of several repeats; on a machine shared with
other jobs they are slower and noisier, while the ratios measured within one benchmark (fast
versus reference path, batched versus sequential, step versus matmul peak) are fairer.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks import (binning_speed, denoise, end_to_end, ensemble_speed, inference, quality_zoo,  # noqa: E402
                        robustness, scale, simulate_speed, train_step)
from benchmarks.common import machine, print_table, write_json  # noqa: E402

BENCHMARKS = {
    "train_step": lambda a: train_step.run(a.quick, a.device),
    "ensemble": lambda a: ensemble_speed.run(a.quick, a.device),
    "binning": lambda a: binning_speed.run(a.quick, large=not a.no_large),
    "simulate": lambda a: simulate_speed.run(a.quick),
    "inference": lambda a: inference.run(a.quick, a.device),
    "end_to_end": lambda a: end_to_end.run(a.quick, a.device),
    "zoo": lambda a: quality_zoo.run(a.quick),
    "robustness": lambda a: robustness.run(a.quick),
    "denoise": lambda a: denoise.run(a.quick),
    "scale": lambda a: scale.run(a.quick),
}


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--quick", action="store_true", help="smaller sizes and fewer repeats (a 10^7-event file)")
    p.add_argument("--only", nargs="+", choices=list(BENCHMARKS), help="run only these benchmarks")
    p.add_argument("--device", default=None, help="cpu or cuda for the torch benchmarks (default: cpu, and cuda "
                                                 "when present)")
    p.add_argument("--no-large", action="store_true", help="skip the large-file (10^8 events) benchmark")
    p.add_argument("--json", default="benchmarks/results.json", help="where to write all rows (default: %(default)s)")
    a = p.parse_args(argv)
    info = machine()
    print(f"machine: {info['cpu']}, {info['cpu_count']} CPUs, torch {info['torch']} with {info['torch_threads']} "
          f"threads, GPU: {info.get('gpu', 'none')}; 1-min load average at start: {info.get('load_average_1min', '?')}")
    rows, seconds = [], {}
    for name in a.only or BENCHMARKS:
        print(f"\n== {name} ==", flush=True)
        t0 = time.perf_counter()
        rows += BENCHMARKS[name](a)
        seconds[name] = time.perf_counter() - t0
    info_end = machine()
    print(f"\n== summary ({'quick' if a.quick else 'full'} run; 1-min load average at the end: "
          f"{info_end.get('load_average_1min', '?')}) ==")
    print_table(rows)
    write_json(a.json, {"machine": info, "load_average_end": info_end.get("load_average_1min"), "quick": a.quick,
                        "seconds": seconds, "rows": rows})
    print(f"\nwrote {a.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
