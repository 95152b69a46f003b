"""Batch evaluation of whole datasets on Dask: one ``dask.distributed`` task per recording.

    evinr-lite batch INPUTS... --out DIR [--scheduler ADDRESS | --workers N] [--C C] [--iters N] ...

From Python (a notebook)::

    from evinr_lite.apps.batch import run_batch
    summary = run_batch(["ijrr"], "table1", workers=2)      # or scheduler="tcp://host:8786", or client=...
    summary["pooled"]        # frame-weighted means per dataset and protocol, as EVREAL pools them

INPUTS are recordings (any format ``evinr-lite reconstruct`` reads), folders of recordings, or
converted ``data_fetch`` sequences named ``ijrr`` (every converted IJRR sequence in the cache),
``ijrr:slider_depth`` (one) or ``hqf:all``. evinr_lite never imports data_fetch: names are looked
up in its cache layout, ``<cache>/<dataset>/<sequence>.h5`` (``$EVINR_DATA``), so fetch first
(``python -m data_fetch get ijrr all``). A canonical file's evaluation window (``eval_window``) is
the window reconstructed and scored, as ``data_fetch.read(path, *window)`` reads it.

Each task is :func:`evaluate_recording`: :func:`~evinr_lite.apps.recon_job.run_reconstruct` into
``DIR/<name>/`` (written to a temporary folder renamed into place when complete, so a folder with
``run.json`` is a finished recording), scored at the ground-truth frame times without equalisation
and with CLAHE. A rerun skips finished recordings. A recording that fails (bad input) is reported
in the summary and the others go on; a worker that dies mid-task (killed, out of memory) is replaced
and its task runs again elsewhere (Dask's scheduler retries it; after 3 deaths it is reported as
failed). At the end ``DIR/summary.json``, ``summary.csv`` and ``summary.md`` hold the pooled table.
"""
from __future__ import annotations

import csv
import io
import json
import math
import os
import re
import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from ..core.events import EventDataError
from ..core.runtime import cache_dir
from ..evaluation.scoring import pool
from ..io.readers import detect_format
from .recon_job import EQUALIZATIONS, check_run_options, run_reconstruct

__all__ = ["run_batch", "resolve_inputs", "evaluate_recording", "summarize", "estimate_task_memory_mb",
           "RECORDING_SUFFIXES"]

RECORDING_SUFFIXES = (".h5", ".hdf5", ".txt", ".npy", ".aedat4", ".raw", ".dat")  # files taken from a folder
SETTINGS_FILE = "batch.json"           # the settings a DIR was made with; a rerun must use the same
DATASET_NAME = re.compile(r"^([a-z][a-z0-9_]*)(?::([A-Za-z0-9_.\-]+))?$")
KILLED_NOTE = ("its worker died on every try (killed, or out of memory: see the memory one task needs in "
               "the README's batch section)")


# ---- inputs ----------------------------------------------------------------------------------

def _is_recording_dir(path: Path) -> bool:
    try:
        detect_format(path)
        return True
    except EventDataError:
        return False


def _from_cache(spec: str, cache: Path) -> list[dict]:
    """`ijrr`, `ijrr:all`, `ijrr:slider_depth` -> converted sequences in <cache>/<dataset>/."""
    dataset, sequence = DATASET_NAME.match(spec).groups()
    folder = cache / dataset
    if sequence in (None, "all"):
        files = sorted(folder.glob("*.h5")) if folder.is_dir() else []
        if not files:
            raise EventDataError(f"{spec}: no converted {dataset} sequences in {folder}; fetch them first with "
                                 f"`python -m data_fetch get {dataset} all` (EVINR_DATA sets the cache folder; on "
                                 "a cluster it must be a folder every worker can read)")
        return [{"path": str(f), "dataset": dataset, "name": f.stem} for f in files]
    path = folder / f"{sequence}.h5"
    if not path.exists():
        raise EventDataError(f"{spec}: no converted sequence at {path}; fetch it first with "
                             f"`python -m data_fetch get {dataset} {sequence}` (EVINR_DATA sets the cache folder; "
                             "on a cluster it must be a folder every worker can read)")
    return [{"path": str(path), "dataset": dataset, "name": sequence}]


def resolve_inputs(inputs, *, cache=None, log=print) -> list[dict]:
    """The recordings that INPUTS name, each {"name", "dataset", "path"} (names unique, order kept).

    Args:
        inputs: recordings (files or IJRR/EVREAL folders), folders holding recordings (files with a
            suffix in RECORDING_SUFFIXES and recording folders; other entries are skipped with a
            note), or data_fetch names ``dataset``, ``dataset:all``, ``dataset:sequence``.
        cache: the data_fetch cache folder (default ``$EVINR_DATA`` or ``~/.cache/evinr-lite``).
    The dataset of a recording, by which results are pooled, is the data_fetch dataset, else the
    name of the folder holding it.
    Raises:
        EventDataError: an input that is neither an existing path nor a converted sequence (the
            message says how to fetch it), or inputs that name no recording at all.
    """
    if isinstance(inputs, (str, os.PathLike)):
        inputs = [inputs]
    cache = Path(cache) if cache is not None else cache_dir()
    items = []
    for spec in inputs:
        path = Path(spec)
        if path.exists():
            path = path.resolve()
            if path.is_dir() and not _is_recording_dir(path):
                found = []
                for child in sorted(path.iterdir()):
                    if child.name.startswith("."):
                        continue
                    if child.is_file() and child.suffix.lower() in RECORDING_SUFFIXES or \
                            child.is_dir() and _is_recording_dir(child):
                        found.append({"path": str(child), "dataset": path.name, "name": child.stem})
                    else:
                        log(f"batch: skipped {child} (not a recording)")
                if not found:
                    raise EventDataError(f"{spec}: a folder without recordings (files {', '.join(RECORDING_SUFFIXES)} "
                                         "or IJRR/EVREAL folders); pass recordings or folders holding them")
                items += found
            else:
                items.append({"path": str(path), "dataset": path.parent.name or "recordings", "name": path.stem})
        elif DATASET_NAME.match(str(spec)):
            items += _from_cache(str(spec), cache)
        else:
            raise EventDataError(f"{spec}: no such recording or folder, and not a data_fetch name "
                                 "(dataset or dataset:sequence, e.g. ijrr:slider_depth); check the path")
    unique, seen = [], set()
    for item in items:                      # the same file named twice runs once
        if item["path"] not in seen:
            seen.add(item["path"])
            unique.append(item)
    counts = {}
    for item in unique:
        counts[item["name"]] = counts.get(item["name"], 0) + 1
    names = set()
    for item in unique:                     # two recordings called the same: prefix their dataset
        name = item["name"] if counts[item["name"]] == 1 else f"{item['dataset']}-{item['name']}"
        base, k = name, 2
        while name in names:
            name, k = f"{base}-{k}", k + 1
        names.add(name)
        item["name"] = name
    if not unique:
        raise EventDataError("no recordings given; pass recordings, folders of recordings or data_fetch names")
    return unique


# ---- one task --------------------------------------------------------------------------------

def _eval_window(path: str) -> tuple[float | None, float | None]:
    """A canonical (data_fetch) file's evaluation window on its own clock, else the whole recording."""
    if detect_format(path) == "canonical":
        from ..io.canonical import canonical_info

        window = canonical_info(path).get("eval_window")
        if window is not None:
            return float(window[0]), float(window[1])
    return None, None


def _peak_rss_mb() -> float | None:
    try:
        import resource

        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0   # kilobytes on Linux
    except (ImportError, OSError):
        return None


def _row(item: dict, run: dict, status: str, seconds: float | None) -> dict:
    scores = run.get("scores") or {}
    row = {"name": item["name"], "dataset": item["dataset"], "input": item["path"], "status": status,
           "time_s": seconds, "train_time_s": run.get("train_time_s"), "n_events": run.get("n_events"),
           "window_s": run.get("window_s"), "scores": scores}
    if not scores:
        row["status"] = "unscored" if status != "skipped" else "skipped-unscored"
        row["note"] = "no ground-truth frames in the window: reconstructed, not scored"
    return row


def _finished(out: Path) -> dict | None:
    try:
        return json.loads((out / "run.json").read_text())
    except (FileNotFoundError, json.JSONDecodeError):
        return None


def evaluate_recording(item: dict, out_dir, settings: dict) -> dict:
    """One task: reconstruct and score one recording into ``out_dir/<name>/`` (or skip it if done).

    Args:
        item: {"name", "dataset", "path"} from :func:`resolve_inputs`.
        settings: {"C", "fps", "n_iters", "seed", "device", "video", "sensor_size", "torch_threads"}.
    Returns:
        {"name", "dataset", "input", "status" ("done", "skipped", "unscored", "failed"), "scores"
        {"none"|"clahe": {"mse", "ssim", "lpips", "n_frames", "protocol"}}, "time_s", ...}; a
        failure is returned (status "failed", "error"), never raised, so one bad recording does not
        stop the batch.
    """
    out = Path(out_dir) / item["name"]
    done = _finished(out)
    if done is not None:
        return _row(item, done, "skipped", None)
    import torch

    threads_before = torch.get_num_threads()
    if settings.get("torch_threads"):
        torch.set_num_threads(int(settings["torch_threads"]))
    t0 = time.perf_counter()
    try:
        t_start, t_end = _eval_window(item["path"])
        run = run_reconstruct(item["path"], out, sensor_size=settings.get("sensor_size"), C=settings.get("C"),
                              fps=settings.get("fps"), t_start=t_start, t_end=t_end, device=settings.get("device"),
                              n_iters=settings.get("n_iters"), recipe=settings.get("recipe", "kit"),
                              seed=int(settings.get("seed", 0)), denoise=bool(settings.get("denoise", False)),
                              anchor=settings.get("anchor", "none"),
                              overwrite=True, video=bool(settings.get("video", False)), progress=False,
                              log=lambda *a, **k: None)
    except Exception as exc:   # a bad recording is a result, not a crash of the batch
        return {"name": item["name"], "dataset": item["dataset"], "input": item["path"], "status": "failed",
                "error": f"{type(exc).__name__}: {exc}", "time_s": time.perf_counter() - t0}
    finally:
        torch.set_num_threads(threads_before)
    row = _row(item, run, "done", time.perf_counter() - t0)
    row["peak_rss_mb"] = _peak_rss_mb()
    return row


# ---- the summary -----------------------------------------------------------------------------

def summarize(rows, settings: dict | None = None) -> dict:
    """Pool per-recording rows as EVREAL does: frame-weighted means per dataset and protocol.

    Returns {"pooled": [{"dataset", "equalization", "mse", "ssim", "lpips", "n_frames",
    "n_sequences", "protocol"}], "protocols": {eq: text}, "recordings": rows (sorted by name),
    "failed": [{"name", "input", "error"}], "settings"}.
    """
    rows = sorted(rows, key=lambda r: (r["dataset"], r["name"]))
    pooled, protocols = [], {}
    for dataset in sorted({r["dataset"] for r in rows}):
        scored = [r for r in rows if r["dataset"] == dataset and r.get("scores")]
        for eq in EQUALIZATIONS:
            per = [{**r["scores"][eq], "equalization": eq} for r in scored if eq in r["scores"]]
            if not per:
                continue
            p = pool(per)
            protocols.setdefault(eq, p["protocol"])
            pooled.append({"dataset": dataset, "equalization": eq, "mse": p["mse"], "ssim": p["ssim"],
                           "lpips": p["lpips"], "n_frames": p["n_frames"], "n_sequences": p["n_sequences"],
                           "protocol": p["protocol"]})
    failed = [{"name": r["name"], "input": r["input"], "error": r["error"]} for r in rows if r["status"] == "failed"]
    return {"pooled": pooled, "protocols": protocols,
            "pooling": "frame-weighted means over the sequences of each dataset (EVREAL): "
                       "sum(n_frames * score) / sum(n_frames), per protocol",
            "recordings": rows, "failed": failed, "settings": settings or {}}


def _write_atomic(path: Path, text: str) -> None:
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "w") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _summary_files(summary: dict) -> dict[str, str]:
    fields = ["dataset", "equalization", "n_sequences", "n_frames", "mse", "ssim", "lpips"]
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=fields + ["protocol"], lineterminator="\n")
    writer.writeheader()
    for p in summary["pooled"]:
        writer.writerow({k: p[k] for k in fields + ["protocol"]})
    md = ["# Batch evaluation: EvINR", ""]
    if summary["pooled"]:
        md += ["Pooled per dataset: " + summary["pooling"] + ".", "",
               "| dataset | protocol | sequences | frames | MSE | SSIM | LPIPS |", "|---|---|---|---|---|---|---|"]
        for p in summary["pooled"]:
            lpips = "n/a" if p["lpips"] is None else f"{p['lpips']:.3f}"
            md.append(f"| {p['dataset']} | {p['equalization']} | {p['n_sequences']} | {p['n_frames']} | "
                      f"{p['mse']:.4f} | {p['ssim']:.3f} | {lpips} |")
        md.append("")
        md += [f"Protocol ({eq}): {text}" for eq, text in summary["protocols"].items()] + [""]
    else:
        md += ["No recording was scored (none finished with ground-truth frames).", ""]
    md += ["## Recordings", "", "| recording | dataset | status | frames | MSE | SSIM | CLAHE MSE | CLAHE SSIM | time (s) |",
           "|---|---|---|---|---|---|---|---|---|"]
    for r in summary["recordings"]:
        s = r.get("scores") or {}

        def cell(eq, key, digits=4):
            return f"{s[eq][key]:.{digits}f}" if eq in s else ""

        frames = s["none"]["n_frames"] if "none" in s else ""
        seconds = "" if r.get("time_s") is None else f"{r['time_s']:.1f}"
        md.append(f"| {r['name']} | {r['dataset']} | {r['status']} | {frames} | {cell('none', 'mse')} | "
                  f"{cell('none', 'ssim', 3)} | {cell('clahe', 'mse')} | {cell('clahe', 'ssim', 3)} | {seconds} |")
    if summary["failed"]:
        md += ["", "## Failed", ""] + [f"- {f['name']} ({f['input']}): {f['error']}" for f in summary["failed"]]
    return {"summary.json": json.dumps(summary, indent=2) + "\n", "summary.csv": buf.getvalue(),
            "summary.md": "\n".join(md) + "\n"}


# ---- memory ----------------------------------------------------------------------------------

PROCESS_MIB = 900.0   # a worker with Python, torch and the libraries loaded, reading and scoring (measured ~740-950)


def estimate_task_memory_mb(sensor_size, duration_s: float, n_events: int, *, n_frames: int = 0,
                            config=None) -> float:
    """A rough upper estimate of one task's memory in MiB (the README's batch section explains it).

    The process itself (PROCESS_MIB: Python, torch, the libraries, a reader and the scoring), the
    events in memory (17 bytes each: t float64, x and y int32, p int8; twice while they are read),
    and the reconstruction as :func:`evinr_lite.apps.recon_job.estimate_memory` counts it (each
    network's weights, gradients and Adam moments with its H*W head, one network per ``tau``
    seconds; the event bins; the ``n_frames`` queried frames) for ``config`` (default: the paper's).
    """
    from ..core.events import Events
    from ..core.recording import Recording
    from ..method.solver import EvINRConfig
    from .recon_job import estimate_memory

    rec = Recording(Events.empty(tuple(int(v) for v in sensor_size)), None, {"window": (0.0, float(duration_s))})
    solver = estimate_memory(rec, np.zeros(max(int(n_frames), 1)), config or EvINRConfig(progress=False))["total"]
    return PROCESS_MIB + (2 * 17 * n_events + solver) / 1024.0 ** 2


# ---- the whole batch -------------------------------------------------------------------------

def _clean_partials(out_dir: Path) -> None:
    """Temporary folders that a killed task left behind (``.<name>.partial-*``)."""
    for tmp in out_dir.glob(".*.partial-*"):
        shutil.rmtree(tmp, ignore_errors=True)


def _check_settings(out_dir: Path, settings: dict) -> None:
    path = out_dir / SETTINGS_FILE
    if path.exists():
        before = json.loads(path.read_text())
        changed = {}
        for k in RESULT_SETTINGS:
            a, b = before.get(k, SETTING_DEFAULTS.get(k)), settings.get(k, SETTING_DEFAULTS.get(k))
            if a != b:
                changed[k] = (a, b)
        if changed:
            what = ", ".join(f"{k}: {a!r} -> {b!r}" for k, (a, b) in changed.items())
            raise EventDataError(f"{out_dir} holds results made with other settings ({what}); resuming would mix "
                                 "them: choose another out_dir= or delete that folder")
    else:
        _write_atomic(path, json.dumps(settings, indent=2) + "\n")


RESULT_SETTINGS = ("C", "fps", "n_iters", "recipe", "seed", "sensor_size", "denoise", "anchor")   # change the scores
SETTING_DEFAULTS = {"denoise": False, "anchor": "none"}     # what a batch.json written before these options meant


def run_batch(inputs, out_dir, *, scheduler: str | None = None, workers: int | None = None, client=None,
              sequential: bool = False, torch_threads: int = 1, C: float | None = None, fps: float | None = None,
              n_iters: int | None = None, recipe: str = "kit", seed: int = 0, device: str | None = None,
              video: bool = False, denoise: bool = False, anchor: str = "none",
              sensor_size=None, cache=None, progress: bool = True, log=print) -> dict:
    """Reconstruct and score every recording of ``inputs``, one Dask task each; returns the summary.

    Args:
        inputs: see :func:`resolve_inputs` (recordings, folders of them, data_fetch names).
        out_dir: results: ``<name>/`` per recording (as ``evinr-lite reconstruct`` writes it),
            ``summary.json|csv|md`` and ``batch.json`` (the settings; a rerun must use the same).
        scheduler: address of a running Dask scheduler (``tcp://host:8786``); its workers must see
            ``out_dir`` and the inputs at the same paths (shared storage).
        workers: worker processes of the LocalCluster started otherwise (default: one per CPU core,
            at most one per recording).
        client: an existing ``distributed.Client`` to use instead (a notebook's).
        sequential: run the tasks one after the other in this process, without Dask (a reference).
        torch_threads: torch threads per task (default 1: one per worker process).
        C, fps, n_iters, recipe, seed, device, video, sensor_size, denoise, anchor: as for
            ``evinr-lite reconstruct`` (``video`` off by default: PNG frames and scores only; ``C`` may be
            a number, a pair (c_pos, c_neg) or "auto": fitted per recording from its APS frames).
    Returns:
        the summary (see :func:`summarize`), also written to ``out_dir/summary.json|csv|md``.
    """
    from filelock import FileLock, Timeout

    out_dir = Path(out_dir)
    if n_iters is not None and n_iters < 1:
        raise EventDataError(f"n_iters= must be at least 1 (or None: the recipe's own), got {n_iters}")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1):
        raise EventDataError(f"workers= must be a whole number of at least 1, got {workers!r}")
    if isinstance(torch_threads, bool) or not isinstance(torch_threads, (int, np.integer)) or torch_threads < 1:
        raise EventDataError(f"torch_threads= must be a whole number of at least 1, got {torch_threads!r}")
    check_run_options(C=C, fps=fps, n_iters=n_iters, seed=seed, recipe=recipe, anchor=anchor)
    if sum(x is not None for x in (scheduler, workers, client)) + bool(sequential) > 1:
        raise EventDataError("give at most one of scheduler=, workers=, client= and sequential=True")
    items = resolve_inputs(inputs, cache=cache, log=log)
    if isinstance(C, (tuple, list, np.ndarray)):
        C = [float(c) for c in C]                       # as batch.json stores it, so a resume compares equal
    settings = {"C": C, "fps": fps, "n_iters": None if n_iters is None else int(n_iters), "recipe": recipe,
                "seed": int(seed), "device": device, "video": bool(video),
                "sensor_size": list(sensor_size) if sensor_size is not None else None,
                "torch_threads": int(torch_threads), "denoise": bool(denoise), "anchor": anchor}
    out_dir.mkdir(parents=True, exist_ok=True)
    lock = FileLock(str(out_dir / ".batch.lock"))
    try:
        lock.acquire(timeout=0)
    except Timeout:
        raise EventDataError(f"another batch is writing into {out_dir}; wait for it or choose another out_dir=") from None
    try:
        _check_settings(out_dir, settings)
        _clean_partials(out_dir)
        rows = _run(items, out_dir, settings, scheduler=scheduler, workers=workers, client=client,
                    sequential=sequential, progress=progress, log=log)
        _clean_partials(out_dir)
        summary = summarize(rows, settings)
        for name, text in _summary_files(summary).items():
            _write_atomic(out_dir / name, text)
    finally:
        lock.release()
    done = sum(r["status"] in ("done", "unscored") for r in rows)
    skipped = sum(r["status"].startswith("skipped") for r in rows)
    log(f"batch: {done} recording(s) run, {skipped} already finished, {len(summary['failed'])} failed; "
        f"summary in {out_dir}/summary.md")
    for p in summary["pooled"]:
        log(f"  {p['dataset']:<16} {p['equalization']:<6} MSE {p['mse']:.4f}  SSIM {p['ssim']:.3f}  "
            f"({p['n_sequences']} sequences, {p['n_frames']} frames)")
    for f in summary["failed"]:
        log(f"  failed: {f['name']}: {f['error']}")
    return summary


def _run(items, out_dir: Path, settings: dict, *, scheduler, workers, client, sequential, progress, log) -> list[dict]:
    from tqdm.auto import tqdm

    rows = []
    todo = []
    for item in items:                       # finished recordings are read back, not scheduled
        done = _finished(out_dir / item["name"])
        if done is not None:
            rows.append(_row(item, done, "skipped", None))
        else:
            todo.append(item)
    if not todo:
        return rows
    if sequential:
        for item in tqdm(todo, unit="recording", desc="batch", disable=not progress):
            rows.append(evaluate_recording(item, out_dir, settings))
        return rows

    from distributed import Client, LocalCluster, as_completed

    cluster = own_client = bar = None
    try:
        if client is None and scheduler is not None:
            client = own_client = Client(scheduler)
            log(f"batch: scheduler {scheduler}, {len(client.scheduler_info().get('workers', {}))} worker(s)")
        elif client is None:
            n = workers or max(1, min(os.cpu_count() or 1, len(todo)))
            threads = str(settings["torch_threads"])
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                                   env={"OMP_NUM_THREADS": threads, "MKL_NUM_THREADS": threads})
            client = own_client = Client(cluster)
            log(f"batch: a LocalCluster of {n} worker process(es), {threads} torch thread(s) each")
        bar = tqdm(total=len(todo), unit="recording", desc="batch", disable=not progress)
        futures = {client.submit(evaluate_recording, item, str(out_dir.resolve()), settings, pure=False,
                                 key=f"evinr-batch-{item['name']}-{os.getpid()}-{time.time_ns()}"): item
                   for item in todo}
        for future in as_completed(futures):
            item = futures[future]
            try:
                rows.append(future.result())
            except Exception as exc:   # KilledWorker after repeated deaths, or a worker-side import error
                note = KILLED_NOTE if type(exc).__name__ == "KilledWorker" else f"{type(exc).__name__}: {exc}"
                rows.append({"name": item["name"], "dataset": item["dataset"], "input": item["path"],
                             "status": "failed", "error": note, "time_s": None})
            bar.update()
    finally:
        if bar is not None:
            bar.close()
        if own_client is not None:
            own_client.close()
        if cluster is not None:
            cluster.close()
    return rows
