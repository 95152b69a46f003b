"""Binning and loading: events -> event frames (events per second), and a 10^8-event file end to end.

    python benchmarks/binning_speed.py             # 10^7 events in memory; a 10^8-event file (about 1 minute)
    python benchmarks/binning_speed.py --quick     # 2 x 10^6 in memory; a 10^7-event file

In memory: N uniform random events on 240x180 over 5 s, binned at 1/32 s (160 bins) by
``events_to_frames``, timed alternately with the previous implementation (one binary search per
event, one flat int64 index, one np.bincount over all bins; kept below as ``previous_events_to_frames``)
and checked equal to it.

Large file: a synthetic recording of 10^8 events (1 M events/s for 100 s, 240x180) is written in
chunks into a canonical h5 (``data_fetch.canonical.CanonicalWriter``, the converters' writer) in a
temporary folder, then read back chunk by chunk (``evinr_lite.io.canonical.iter_canonical_events``)
and binned incrementally at 1/32 s (``events_to_frames_chunked``: 3200 frames). Each phase runs in
its own subprocess, so its peak resident memory (VmHWM of /proc/self/status; ru_maxrss elsewhere)
is that job's alone; the file is deleted afterwards.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

try:
    from benchmarks.common import alternate, parser, report, row
except ImportError:  # run as a script
    from common import alternate, parser, report, row

from evinr_lite import Events  # noqa: E402
from evinr_lite.method.binning import events_to_frames, fixed_duration_boundaries  # noqa: E402

SENSOR = (180, 240)
RATE = 1e6            # events per second of the synthetic large recording
CHUNK = 1 << 22       # events per chunk when writing and reading the large file


def previous_events_to_frames(events: Events, b: np.ndarray, C: float = 1.0):
    """The implementation before this benchmark (for the speed comparison): frames [B, H, W], counts [B]."""
    H, W = events.sensor_size
    B = b.size - 1
    lo = int(np.searchsorted(events.t, b[0], side="left"))
    hi = int(np.searchsorted(events.t, b[-1], side="right"))
    idx = np.searchsorted(b, events.t[lo:hi], side="left") - 1
    np.maximum(idx, 0, out=idx)
    flat = idx * (H * W) + events.y[lo:hi].astype(np.int64) * W + events.x[lo:hi]
    sums = np.bincount(flat, weights=events.p[lo:hi], minlength=B * H * W)
    return (C * sums).astype(np.float32).reshape(B, H, W), np.bincount(idx, minlength=B)


def random_events(n: int, duration: float, sensor_size=SENSOR, seed: int = 0, t0: float = 0.0) -> Events:
    rng = np.random.default_rng(seed)
    H, W = sensor_size
    t = t0 + np.sort(rng.uniform(0.0, duration, n))
    p = (rng.integers(0, 2, n, dtype=np.int8) * 2 - 1).astype(np.int8)
    return Events(t, rng.integers(0, W, n, dtype=np.int32), rng.integers(0, H, n, dtype=np.int32), p, sensor_size)


def in_memory(n: int, repeats: int, log=print) -> list[dict]:
    events = random_events(n, 5.0)
    b = fixed_duration_boundaries(0.0, 5.0, 1 / 32)
    new, old = events_to_frames(events, b, 0.2), previous_events_to_frames(events, b, 0.2)
    same = bool(np.array_equal(new.frames, old[0]) and np.array_equal(new.counts, old[1]))
    times = alternate({"new": lambda: events_to_frames(events, b, 0.2),
                       "previous": lambda: previous_events_to_frames(events, b, 0.2)}, repeats)
    rate, rate_old = n / times["new"] / 1e6, n / times["previous"] / 1e6
    log(f"events_to_frames: {n:,} events, {len(b) - 1} bins of 240x180: {rate:.0f} M events/s "
        f"(previous implementation {rate_old:.0f} M events/s); identical output: {same}")
    return [row("binning: events_to_frames, 240x180, 1/32 s bins", rate, "Mev/s", target=50.0,
                note=f"{n:.0e} events; previous implementation {rate_old:.0f} Mev/s; identical output: {same}",
                n_events=n, previous_mev_s=rate_old, identical=same),
            row("binning: speed-up over the previous implementation", rate / rate_old, "x")]


# ---- the large file, one subprocess per phase ----------------------------------------------------

def _peak_rss_mb() -> float:
    """This process's peak resident memory (MiB).

    /proc/self/status VmHWM where there is one: ru_maxrss would also count the pages this process
    shared with its parent between fork and exec (a large parent would inflate it).
    """
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024                  # kB
    except OSError:
        pass
    return _ru_maxrss_mb()


def _ru_maxrss_mb() -> float:
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return rss / 2 ** 20 if sys.platform == "darwin" else rss / 1024   # bytes on macOS, KiB on Linux


def worker_write(path: str, n: int) -> dict:
    from data_fetch.canonical import CanonicalWriter

    duration = n / RATE
    t0 = time.perf_counter()
    with CanonicalWriter(path, sensor_size=SENSOR, dataset="synthetic", sequence="benchmark",
                         source="benchmarks/binning_speed.py", converter="benchmark") as writer:
        for k, start in enumerate(range(0, n, CHUNK)):
            m = min(CHUNK, n - start)
            ev = random_events(m, m / RATE, seed=k, t0=start / RATE)
            writer.add_events(ev.t, ev.x.astype(np.uint16), ev.y.astype(np.uint16), ev.p)
    return {"seconds": time.perf_counter() - t0, "peak_rss_mb": _peak_rss_mb(), "ru_maxrss_mb": _ru_maxrss_mb(),
            "duration_s": duration,
            "file_mb": os.path.getsize(path) / 2 ** 20}


def worker_bin(path: str, n: int) -> dict:
    from evinr_lite.method.binning import events_to_frames_chunked
    from evinr_lite.io.canonical import iter_canonical_events

    t0 = time.perf_counter()
    b = fixed_duration_boundaries(0.0, n / RATE, 1 / 32)
    read = [0.0]

    def chunks():          # time spent reading (h5 decompression + validation), separately from binning
        it = iter_canonical_events(path, chunk_events=CHUNK)
        while True:
            r0 = time.perf_counter()
            try:
                ev = next(it)
            except StopIteration:
                return
            read[0] += time.perf_counter() - r0
            yield ev

    ef = events_to_frames_chunked(chunks(), b, C=1.0)
    total = time.perf_counter() - t0
    return {"seconds": total, "read_seconds": read[0], "bin_seconds": total - read[0],
            "peak_rss_mb": _peak_rss_mb(), "ru_maxrss_mb": _ru_maxrss_mb(), "n_binned": int(ef.counts.sum()),
            "n_bins": len(ef),
            "frames_mb": ef.frames.nbytes / 2 ** 20}


def _subprocess(phase: str, path: Path, n: int) -> dict:
    out = subprocess.run([sys.executable, __file__, "--worker", phase, str(path), str(n)],
                         capture_output=True, text=True, check=False)
    if out.returncode != 0:
        raise RuntimeError(f"{phase} worker failed:\n{out.stderr[-3000:]}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def large_file(n: int, log=print) -> list[dict]:
    tmp = Path(tempfile.mkdtemp(prefix="evinr-bench-"))
    try:
        path = tmp / "synthetic.h5"
        w = _subprocess("write", path, n)
        log(f"large file: wrote {n:,} events ({w['duration_s']:.0f} s at 1 M ev/s) to a canonical h5 of "
            f"{w['file_mb']:.0f} MiB in {w['seconds']:.1f} s (peak RSS {w['peak_rss_mb']:.0f} MiB)")
        r = _subprocess("bin", path, n)
        log(f"large file: read in chunks of {CHUNK:,} and binned into {r['n_bins']} frames in {r['seconds']:.1f} s "
            f"(reading {r['read_seconds']:.1f} s, binning {r['bin_seconds']:.1f} s); peak RSS {r['peak_rss_mb']:.0f} MiB "
            f"(the frames alone: {r['frames_mb']:.0f} MiB); events binned: {r['n_binned']:,} of {n:,}")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    peak = max(w["peak_rss_mb"], r["peak_rss_mb"])
    ok = r["n_binned"] == n
    return [row(f"binning: {n:.0e}-event file, load in chunks + bin, peak RSS", peak / 1024, "GiB", target=4.0,
                higher_is_better=False,
                note=(f"write {w['seconds']:.1f} s ({n / w['seconds'] / 1e6:.1f} Mev/s), read+bin {r['seconds']:.1f} s "
                      f"({n / r['seconds'] / 1e6:.1f} Mev/s; reading {r['read_seconds']:.1f} s); file "
                      f"{w['file_mb']:.0f} MiB; all events binned: {ok}"),
                write=w, read_bin=r, all_events_binned=ok),
            row(f"loading: {n:.0e}-event file read + binned", n / r["seconds"] / 1e6, "Mev/s")]


def run(quick: bool = False, repeats: int | None = None, large: bool = True, log=print) -> list[dict]:
    repeats = repeats or (3 if quick else 5)
    rows = in_memory(2_000_000 if quick else 10_000_000, repeats, log)
    if large:
        rows += large_file(10_000_000 if quick else 100_000_000, log)
    return rows


def main(argv=None) -> int:
    p = parser(__doc__, "2e6 events in memory, a 1e7-event file", device=False)
    p.add_argument("--no-large", action="store_true", help="skip the large-file benchmark")
    p.add_argument("--worker", nargs=3, metavar=("PHASE", "PATH", "N"), help=argparse.SUPPRESS)
    a = p.parse_args(argv)
    if a.worker:
        phase, path, n = a.worker
        print(json.dumps((worker_write if phase == "write" else worker_bin)(path, int(n))))
        return 0
    rows = run(a.quick, a.repeats, not a.no_large)
    report(rows, a.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
