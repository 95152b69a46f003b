"""Batch evaluation on Dask: 2 workers against 1 (each one process with one torch thread).

    python benchmarks/batch_speed.py            # 4 recordings of 60x80 px, 1 s, 100 iterations
    python benchmarks/batch_speed.py --quick    # 4 recordings of 40x56 px, 0.5 s, 40 iterations

The same 4 synthetic IJRR-style recordings (``write_example_recording``, different scenes, seeded)
go through :func:`evinr_lite.apps.batch.run_batch` on a LocalCluster of 1 worker and one of 2
workers (both started once, before timing; each run writes into a fresh folder). The two runs
alternate ``--repeats`` times and the fastest of each is kept: wall-clock seconds of the whole
``run_batch`` call (scheduling, reading, training, scoring, PNGs, summary). The summaries must be
equal (checked). On 2 cores the ideal speed-up is 2; the target is 1.6.
"""
from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

try:
    from benchmarks.common import alternate, machine, parser, report, row
except ImportError:  # run as a script
    from common import alternate, machine, parser, report, row

from evinr_lite.apps.batch import run_batch  # noqa: E402
from evinr_lite.sim.recordings import write_example_recording  # noqa: E402

SCENES = ("camera", "astronaut", "coffee", "moon")
TARGET_SPEEDUP = 1.6


def run(quick: bool = False, repeats: int | None = None) -> list[dict]:
    from distributed import Client, LocalCluster

    size, duration, iters = ((40, 56), 0.5, 40) if quick else ((60, 80), 1.0, 100)
    repeats = repeats or 2
    with tempfile.TemporaryDirectory(prefix="batch_speed-") as tmp:
        tmp = Path(tmp)
        data = tmp / "recordings"
        data.mkdir()
        for i, scene in enumerate(SCENES):
            write_example_recording(data / scene, scene=scene, sensor_size=size, duration=duration,
                                    frame_rate=20.0, seed=i)
        clusters = {n: LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                                    env={"OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}) for n in (1, 2)}
        clients = {n: Client(c) for n, c in clusters.items()}
        summaries, count = {}, [0]
        try:
            def batch(n):
                def go():
                    count[0] += 1
                    out = tmp / f"out-{count[0]}"
                    summaries[n] = run_batch([data], out, client=clients[n], n_iters=iters, progress=False,
                                             log=lambda *a, **k: None)
                    shutil.rmtree(out)
                return go

            for n in (1, 2):          # warm-up: workers import torch and evinr_lite once
                batch(n)()
            best = alternate({"1 worker": batch(1), "2 workers": batch(2)}, repeats=repeats)
        finally:
            for c in clients.values():
                c.close()
            for c in clusters.values():
                c.close()
    if summaries[1]["pooled"] != summaries[2]["pooled"]:
        raise AssertionError("1 and 2 workers gave different pooled scores")
    speedup = best["1 worker"] / best["2 workers"]
    what = f"{len(SCENES)} recordings {size[0]}x{size[1]}, {duration:g} s, {iters} iterations"
    return [
        row("batch, 1 worker", best["1 worker"], "s", note=what),
        row("batch, 2 workers", best["2 workers"], "s", note=what),
        row("batch speed-up, 2 workers vs 1", speedup, "x", TARGET_SPEEDUP,
            note=f"ideal 2 on 2 cores; machine: {machine()['cpu_count']} cores, "
                 f"load {machine().get('load_average_1min', float('nan')):.1f}"),
    ]


def main(argv=None) -> None:
    args = parser(__doc__, "smaller recordings and fewer iterations (about 30 s)", device=False).parse_args(argv)
    report(run(args.quick, args.repeats), args.json)


if __name__ == "__main__":
    main(sys.argv[1:])
