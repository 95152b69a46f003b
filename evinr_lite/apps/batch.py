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
import time
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from ..core.checks import check_log, check_path_type, true_or_false
from ..core.events import EventDataError
from ..core.runtime import cache_dir
from ..evaluation.scoring import pool
from ..io.formats import (RECORDING_SUFFIXES, detect_format, is_recording_folder, is_ros2_bag,  # formats: io.formats
                          recording_path)
from .options import BATCH_FIELDS, RunOptions
from .recon_job import EQUALIZATIONS, run_reconstruct

__all__ = ["run_batch", "resolve_inputs", "evaluate_recording", "summarize", "estimate_task_memory_mb",
           "RECORDING_SUFFIXES", "input_identity", "result_state", "result_settings", "check_batch_out",
           "check_scheduler_address", "OWNER_MARKER"]

SCHEDULER_TIMEOUT = "20s"   # how long a --scheduler address is tried before "cannot reach" (distributed retries)

SETTINGS_FILE = "batch.json"           # the settings a DIR was made with (a rerun must use the same) and its recordings
OWNER_MARKER = ".evinr-batch.json"     # inside each DIR/<name>/ a batch wrote: the input's identity and the settings
LOCK_FILE = ".batch.lock"
SUMMARY_FILES = ("summary.json", "summary.csv", "summary.md")
SCHEDULER_ADDRESS = re.compile(r"^((tcp|tls|inproc|ucx|ws|wss)://)?(\[[0-9a-fA-F:]+\]|[A-Za-z0-9_.\-]+)(:\d{1,5})?/?$")
DATASET_NAME = re.compile(r"^([a-z][a-z0-9_]*)(?::([A-Za-z0-9_.\-]+))?$")
KILLED_NOTE = ("its worker died on every try (killed, or out of memory: see the memory one task needs in "
               "docs/batch.md)")


# ---- inputs ----------------------------------------------------------------------------------

def _real_path(path) -> Path:
    """The absolute path with every symbolic link followed; a loop is an EventDataError naming it."""
    try:
        return Path(os.path.abspath(Path(path).expanduser())).resolve()
    except (RuntimeError, OSError) as err:
        raise EventDataError(f"{path}: cannot be followed (a loop of symbolic links, or a link that cannot be "
                             f"read: {err}); fix the link or pass the recording's real path") from None


def _file_key(path) -> tuple:
    """What makes two paths the same recording: the device and inode of the file or folder."""
    try:
        st = os.stat(path)
        return (st.st_dev, st.st_ino)
    except OSError:
        return (str(path),)


def input_identity(path) -> dict:
    """The identity of an input by which results are resumed: its real path, size and modification
    time (for a folder, those of every file in it), as {"path", "fingerprint"}. A different file
    under the same name, or the same file changed since, has another fingerprint."""
    import hashlib

    real = _real_path(path)
    h = hashlib.sha256()
    try:
        if real.is_dir():
            for root, dirs, files in os.walk(real):
                dirs.sort()
                for name in sorted(files):
                    f = Path(root) / name
                    st = f.stat()
                    h.update(f"{f.relative_to(real)}\0{st.st_size}\0{st.st_mtime_ns}\n".encode())
        else:
            st = real.stat()
            h.update(f"{st.st_size}\0{st.st_mtime_ns}".encode())
    except OSError as err:
        raise EventDataError(f"{path}: cannot be read ({err.strerror or err}); check the path and its "
                             "permissions") from None
    return {"path": str(real), "fingerprint": h.hexdigest()[:32]}


def _is_recording_dir(path: Path) -> bool:
    return is_recording_folder(path)


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


def _input_list(inputs) -> list:
    """``inputs`` (one path or name, or an iterable of them) as a list; EventDataError for what is neither."""
    if isinstance(inputs, (str, os.PathLike)):
        return [inputs]
    if inputs is None or isinstance(inputs, (bytes, dict)) or not hasattr(inputs, "__iter__"):
        raise EventDataError(f"inputs= must be a recording, a folder or a data_fetch name (a str or Path), or a list "
                             f"of them, got {type(inputs).__name__}")
    return list(inputs)


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
    inputs = _input_list(inputs)
    for k, spec in enumerate(inputs):   # all of them, before any is looked at
        if not isinstance(spec, (str, os.PathLike)) or isinstance(os.fspath(spec), bytes):
            raise EventDataError(f"inputs[{k}] must be a path or a data_fetch name (a str or Path), got "
                                 f"{type(spec).__name__} {spec!r:.60}")
        if isinstance(spec, str) and not spec.strip():   # Path("") is the current folder, Path(" ") a folder " "
            raise EventDataError(f"inputs[{k}] is {spec!r}, a blank name (no recording, folder or data_fetch name; "
                                 "\"\" would read the current folder); pass recordings, folders of recordings or "
                                 "data_fetch names")
    if cache is not None and not isinstance(cache, (str, os.PathLike)):
        raise EventDataError(f"cache= must be a folder (a str or Path) or None (the data_fetch cache), got "
                             f"{type(cache).__name__}")
    cache = Path(cache) if cache is not None else cache_dir()
    items = []
    for spec in inputs:
        path = recording_path(spec) if str(spec).startswith("~") else Path(spec)   # ~ as reconstruct reads it
        if path.exists():
            path = _real_path(path)
            if path.is_dir() and is_ros2_bag(path):
                raise EventDataError(f"{spec}: a ROS2 bag, which is not read directly; convert it with `python -m "
                                     f"data_fetch convert {spec}` and pass the .h5 it writes")
            if path.is_dir() and not _is_recording_dir(path):
                found = []
                for child in sorted(path.iterdir()):
                    if child.name.startswith("."):
                        continue
                    if child.is_file() and child.suffix.lower() in RECORDING_SUFFIXES or \
                            child.is_dir() and _is_recording_dir(child):
                        found.append({"path": str(child), "dataset": path.name, "name": child.stem})
                    elif child.is_dir() and is_ros2_bag(child) or child.suffix.lower() == ".bag":
                        log(f"batch: skipped {child} (a ROS bag, which is not read directly: convert it with "
                            f"`python -m data_fetch convert {child}` and pass the .h5 it writes)")
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
    for item in items:                      # the same recording named twice (any path to it) runs once
        item["path"] = str(_real_path(item["path"]))
        key = _file_key(item["path"])
        if key not in seen:
            seen.add(key)
            unique.append(item)
    counts = {}
    for item in unique:
        counts[item["name"]] = counts.get(item["name"], 0) + 1
    names = set()
    # labels depend on the recordings, not on the order they were given in: assigned in path order
    for item in sorted(unique, key=lambda i: i["path"]):
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


def _read_json(path: Path):
    """A JSON file's contents, None when it is missing or damaged (not readable as a JSON object)."""
    try:
        value = json.loads(path.read_text())
    except (FileNotFoundError, NotADirectoryError, json.JSONDecodeError, UnicodeDecodeError):
        return None
    return value if isinstance(value, dict) else None


def result_state(folder: Path, item: dict, settings: dict, claimed: bool = False) -> tuple[str, dict | None]:
    """Whether ``folder`` (DIR/<name>) may be written for ``item``, and whether it is already done.

    Returns (state, run.json): "absent" (nothing there), "finished" (this batch's result for this
    very input, same identity and result settings), "stale" (this batch's, but for another input or
    other settings, or unfinished: it is reconstructed again) or "foreign" (not provably written by
    this batch: never touched). Proof of ownership is the OWNER_MARKER inside, or a claim in
    batch.json together with a run.json that names this input (a task killed between its commit and
    its marker).
    """
    if not os.path.lexists(folder):
        return "absent", None
    if folder.is_symlink() or not folder.is_dir():
        return "foreign", None
    marker = _read_json(folder / OWNER_MARKER)
    run = _read_json(folder / "run.json")
    if marker is None:
        if claimed and run is not None and run.get("input") == item["path"]:
            return "stale", None
        return "foreign", None
    # a marker written before a setting existed lacks it: its default is what that result was made with
    stored = marker.get("settings")
    same = (marker.get("input") == item.get("identity") and isinstance(stored, dict)
            and result_settings(stored) == result_settings(settings))
    return ("finished", run) if same and run is not None else ("stale", None)


def result_settings(settings: dict) -> dict:
    """The settings that change a result (RESULT_SETTINGS, defaults filled in), as JSON stores them."""
    return json.loads(json.dumps({k: settings.get(k, SETTING_DEFAULTS.get(k)) for k in RESULT_SETTINGS}))


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
    # None, text or a dict without its keys was Python's "not subscriptable" or a KeyError, raised (the failures this
    # returns are the recording's, not a call's)
    if not isinstance(item, dict) or any(not isinstance(item.get(k), str) for k in ("name", "dataset", "path")):
        raise EventDataError(f"item= must be a dict with the text 'name', 'dataset' and 'path' (one of resolve_inputs' "
                             f"items), got {item!r:.80}")
    if not isinstance(settings, dict):
        raise EventDataError(f"settings= must be a dict of the batch's settings (e.g. {{'C': 0.2, 'fps': 30}}; {{}} for "
                             f"the defaults), got {type(settings).__name__}")
    out = Path(check_path_type(out_dir, "out_dir", "the batch's output folder")) / item["name"]
    if "identity" not in item:
        item = {**item, "identity": input_identity(item["path"])}
    state, done = result_state(out, item, settings, claimed=bool(item.get("claimed")))
    if state == "finished":
        return _row(item, done, "skipped", None)
    if state == "foreign":   # appeared since the batch checked: never replaced
        return {"name": item["name"], "dataset": item["dataset"], "input": item["path"], "status": "failed",
                "error": f"{out} exists and was not written by this batch; it was left as it is (move it away "
                         "or choose another --out)", "time_s": None}
    import torch

    threads_before = torch.get_num_threads()
    if settings.get("torch_threads"):
        torch.set_num_threads(int(settings["torch_threads"]))
    t0 = time.perf_counter()
    try:
        t_start, t_end = _eval_window(item["path"])
        options = RunOptions.from_settings({"video": False, **settings}, t_start=t_start, t_end=t_end, progress=False)
        run = run_reconstruct(item["path"], out, options,
                              overwrite=state == "stale",   # only a folder this batch proved its own
                              log=lambda *a, **k: None)
        _write_atomic(out / OWNER_MARKER, json.dumps({"input": item["identity"],
                                                      "settings": result_settings(settings)}, indent=2) + "\n")
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
    if rows is None or isinstance(rows, (str, bytes, dict)) or not hasattr(rows, "__iter__"):
        raise EventDataError(f"rows= must be a list of the per-recording rows a batch makes (dicts), got "
                             f"{type(rows).__name__}")
    if settings is not None and not isinstance(settings, Mapping):
        raise EventDataError(f"settings= must be a dict (the batch's settings, or another Mapping) or None, got "
                             f"{type(settings).__name__}")
    if settings is not None and not isinstance(settings, dict):   # a MappingProxyType: stored as a plain dict
        settings = dict(settings)
    rows = list(rows)
    for k, r in enumerate(rows):
        if not isinstance(r, dict):
            raise EventDataError(f"rows[{k}] must be a dict (a batch's per-recording row), got {type(r).__name__}")
        missing = [key for key in ("name", "dataset", "status") if key not in r]
        if missing:
            raise EventDataError(f"rows[{k}] has no {missing[0]!r}; pass the rows a batch makes (they hold 'name', "
                                 "'dataset' and 'status')")
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
    from ..io.output import written_beside

    with written_beside(path) as tmp:
        tmp.write_text(text)


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
                            config=None, streaming: bool = False) -> float:
    """A rough upper estimate of one task's memory in MiB (docs/batch.md explains it).

    The worker process itself (PROCESS_MIB: Python, torch, the libraries, a reader and the scoring), the
    events while they are read (17 bytes each: t float64, x and y int32, p int8; twice while they are
    read), and the reconstruction as :func:`evinr_lite.method.memory.estimate_memory` counts it beside
    them (each network's weights, gradients and Adam moments with its H*W head, one network per window
    of ``tau`` seconds; the event bins; the ``n_frames`` queried frames) for ``config`` (default: the
    kit's); its own process and events parts are left out, PROCESS_MIB and the read events covering
    them. ``streaming``: the run goes window by window (an events-only run without denoise or a fit of
    C, :func:`evinr_lite.apps.stream_job.streamable`), so one window's events and network count.
    """
    from ..method.config import EvINRConfig
    from ..method.memory import PROCESS_BYTES, estimate_memory

    size = tuple(int(v) for v in sensor_size)
    est = estimate_memory(size, 0.0, float(duration_s), int(n_events), max(int(n_frames), 1),
                          config or EvINRConfig(progress=False), streaming=bool(streaming))
    if streaming:   # one window's events, read twice, are in the estimate already
        return PROCESS_MIB + (est["total"] - PROCESS_BYTES) / 1024.0 ** 2
    # the whole solve holds every event once; reading holds them twice
    return PROCESS_MIB + (2 * 17 * n_events + est["total"] - PROCESS_BYTES - est["parts"]["events"]) / 1024.0 ** 2


# ---- the whole batch -------------------------------------------------------------------------

def _clean_partials(out_dir: Path, log=None) -> None:
    """Temporary folders that killed tasks left behind (``.<name>.partial-*`` carrying the package's marker)."""
    from ..io.output import remove_stale_partials

    remove_stale_partials(out_dir, log=log)


def _load_settings(out_dir: Path) -> dict | None:
    """batch.json of ``out_dir`` (None when there is none); a damaged one is an EventDataError with the fix."""
    path = out_dir / SETTINGS_FILE
    if not os.path.lexists(path):
        return None
    try:
        before = json.loads(path.read_text())
        if not isinstance(before, dict):
            raise ValueError(f"a JSON {type(before).__name__}, not an object")
        if not isinstance(before.get("recordings", {}), dict):
            raise ValueError("its 'recordings' is not an object")
    except (OSError, ValueError) as err:
        raise EventDataError(f"{path} is damaged ({err}); it records which results in {out_dir} this batch wrote, "
                             f"so nothing there is touched: delete {out_dir} (or only {path.name}, to start the "
                             "batch over) or choose another out_dir=") from None
    return before


def _remove_quietly(path: Path) -> None:
    try:
        Path(path).unlink(missing_ok=True)
    except OSError:
        pass


def _rmdir_quietly(path: Path) -> None:
    try:
        Path(path).rmdir()
    except OSError:
        pass


def _check_settings(out_dir: Path, settings: dict, before: dict | None) -> None:
    if before is None:
        return
    changed = {}
    for k in RESULT_SETTINGS:
        a, b = before.get(k, SETTING_DEFAULTS.get(k)), settings.get(k, SETTING_DEFAULTS.get(k))
        if a != b:
            changed[k] = (a, b)
    if changed:
        what = ", ".join(f"{k}: {a!r} -> {b!r}" for k, (a, b) in changed.items())
        raise EventDataError(f"{out_dir} holds results made with other settings ({what}); resuming would mix "
                             "them: choose another out_dir= or delete that folder")


def _inside(a: Path, b: Path) -> bool:
    return a == b or b in a.parents


def check_batch_out(out_dir, inputs, items) -> Path:
    """The batch ownership rule, checked before any work; returns ``out_dir``'s real path.

    ``out_dir`` may be new, an empty folder, or a folder this batch made (it holds batch.json). It
    may not be, or lie inside, an input folder, nor contain an input. Raises EventDataError with the
    fix otherwise.
    """
    given = Path(out_dir)
    real = _real_path(given)
    folders = {_real_path(spec) for spec in inputs if isinstance(spec, (str, os.PathLike)) and Path(spec).is_dir()}
    folders |= {Path(i["path"]) for i in items if Path(i["path"]).is_dir()}
    for folder in sorted(folders):
        if _inside(real, folder):
            raise EventDataError(f"out_dir={str(given)!r} is, or lies inside, the input folder {folder}; batch "
                                 "never writes among its inputs: choose an out_dir= outside it")
    for i in items:
        if _inside(Path(i["path"]), real):
            raise EventDataError(f"out_dir={str(given)!r} contains the input {i['path']}; batch never writes "
                                 "among its inputs: choose an out_dir= that holds no input")
    if os.path.lexists(real) and not real.is_dir():
        raise EventDataError(f"out_dir={str(given)!r} exists and is not a folder; choose another out_dir=")
    if real.is_dir() and not os.path.lexists(real / SETTINGS_FILE):
        try:
            others = sorted(p.name for p in real.iterdir() if p.name != LOCK_FILE)
        except OSError as err:
            raise EventDataError(f"out_dir={str(given)!r} cannot be read ({err.strerror}); choose another "
                                 "out_dir=") from None
        if others:
            shown = ", ".join(others[:5]) + (", ..." if len(others) > 5 else "")
            raise EventDataError(f"out_dir={str(given)!r} already holds files that evinr-lite batch did not write "
                                 f"({shown}; no {SETTINGS_FILE}); batch writes only into a new or empty folder, or "
                                 "one it made: choose another out_dir=")
    return real


def check_scheduler_address(address: str) -> str:
    """A Dask scheduler address (``tcp://host:8786``, ``host:8786``), else an EventDataError with an example."""
    if not isinstance(address, str) or not SCHEDULER_ADDRESS.match(address.strip()):
        raise EventDataError(f"scheduler={address!r} is not a Dask scheduler address; give one like "
                             "tcp://host:8786 (the address `dask scheduler` prints)")
    return address.strip()


RESULT_SETTINGS = ("C", "fps", "n_iters", "recipe", "seed", "sensor_size", "denoise", "anchor",
                   "keep_background", "static_camera", "lam", "temporal_scale", "tonemap",
                   "display_mean")   # change the frames and scores
SETTING_DEFAULTS = {"denoise": False, "anchor": "none", "keep_background": False, "static_camera": False,
                    "lam": None, "temporal_scale": None, "tonemap": None,
                    "display_mean": None}   # what a batch.json written before these options meant


def run_batch(inputs, out_dir, options: RunOptions | None = None, *, scheduler: str | None = None,
              workers: int | None = None, client=None, sequential: bool = False, torch_threads: int = 1,
              cache=None, log=print, **fields) -> dict:
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
        options: a :class:`~evinr_lite.apps.options.RunOptions`, or its fields as keywords (the
            keywords replace fields of ``options``): C, fps, n_iters, recipe, seed, device, video, save_log,
            sensor_size, denoise, keep_background, static_camera, lam, anchor as for ``evinr-lite reconstruct`` (``video`` off by default:
            PNG frames and scores only; ``C`` may be a number, a pair (c_pos, c_neg) or "auto":
            fitted per recording from its APS frames), progress (the batch's progress bar).
    Returns:
        the summary (see :func:`summarize`), also written to ``out_dir/summary.json|csv|md``.
    """
    from filelock import FileLock, Timeout

    from ..io.output import given_output_path

    out_dir = given_output_path(out_dir)   # no path, bytes and "" refused ("" is not taken as the current folder)
    sequential = true_or_false(sequential, "sequential")   # True / False, numpy's, 0 / 1; "yes" and 2 refused
    check_log(log)   # it is called after the batch has run
    if client is not None and not callable(getattr(client, "submit", None)):
        raise EventDataError(f"client= must be a distributed.Client (or None), got {type(client).__name__}")
    # every option checked, once; a batch writes no video unless asked
    options = RunOptions.of(options, **fields) if options is not None else RunOptions(**{"video": False, **fields})
    options.check_batch()
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, (int, np.integer)) or workers < 1):
        raise EventDataError(f"workers= must be a whole number of at least 1, got {workers!r}")
    if isinstance(torch_threads, bool) or not isinstance(torch_threads, (int, np.integer)) or torch_threads < 1:
        raise EventDataError(f"torch_threads= must be a whole number of at least 1, got {torch_threads!r}")
    if sum(x is not None for x in (scheduler, workers, client)) + bool(sequential) > 1:
        raise EventDataError("give at most one of scheduler=, workers=, client= and sequential=True")
    inputs = _input_list(inputs)   # once: a generator is used up by resolve_inputs, a str is no list
    items = resolve_inputs(inputs, cache=cache, log=log)
    # as batch.json stores them (pairs and sizes as lists), so a resume compares equal
    settings = {**options.to_dict(BATCH_FIELDS), "torch_threads": int(torch_threads)}
    if scheduler is not None:
        scheduler = check_scheduler_address(scheduler)
    for item in items:
        item["identity"] = input_identity(item["path"])
    real = check_batch_out(out_dir, inputs, items)          # the ownership rule, before anything is written
    created_out = not os.path.lexists(real)
    try:
        real.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise EventDataError(f"cannot create out_dir={str(out_dir)!r} ({err.strerror}); choose an out_dir= in a "
                             "folder you can write") from None
    lock_path = real / LOCK_FILE
    lock_existed = os.path.lexists(lock_path)
    lock = FileLock(str(lock_path))
    try:
        lock.acquire(timeout=0)
    except Timeout:
        raise EventDataError(f"another batch is writing into {out_dir}; wait for it or choose another out_dir=") from None
    except OSError as err:   # e.g. no space left: no empty lock file and no empty folder stay behind
        if not lock_existed:
            _remove_quietly(lock_path)
        if created_out:
            _rmdir_quietly(real)
        raise EventDataError(f"cannot lock out_dir={str(out_dir)!r} ({err.strerror}); choose an out_dir= in a "
                             "folder you can write") from None
    created_settings = False
    try:
        before = _load_settings(real)
        check_batch_out(out_dir, inputs, items)             # again, under the lock
        _check_settings(real, settings, before)
        claimed = dict((before or {}).get("recordings", {}))
        foreign = []
        for item in items:
            item["claimed"] = item["name"] in claimed
            state, _ = result_state(real / item["name"], item, settings, claimed=item["claimed"])
            if state == "foreign":
                foreign.append(str(real / item["name"]))
        if foreign:
            raise EventDataError(f"{', '.join(foreign)} exist(s) in out_dir= but were not written by this batch (no "
                                 f"{OWNER_MARKER} inside, not listed in {SETTINGS_FILE}); batch never replaces what it "
                                 "did not write: move them away or choose another out_dir=")
        for item in items:                                 # claimed before any task runs
            claimed[item["name"]] = item["path"]
            item["claimed"] = True
        created_settings = before is None
        _write_atomic(real / SETTINGS_FILE, json.dumps({**(before or {}), **settings, "owner": "evinr-lite batch",
                                                        "recordings": claimed}, indent=2) + "\n")
        _clean_partials(real, log)
        rows = _run(items, real, settings, scheduler=scheduler, workers=workers, client=client,
                    sequential=sequential, progress=options.progress, log=log)
        _clean_partials(real, log)
        summary = summarize(rows, settings)
        for name, text in _summary_files(summary).items():
            _write_atomic(real / name, text)
    except BaseException:
        # nothing was done (e.g. the scheduler could not be reached): leave no batch.json that blocks a rerun
        if created_settings and not any((real / i["name"]).exists() for i in items):
            _remove_quietly(real / SETTINGS_FILE)
        raise
    finally:
        _remove_quietly(lock_path)        # while held: no .batch.lock stays behind
        lock.release()
        if created_out:
            _rmdir_quietly(real)          # only when empty: a batch that did nothing leaves nothing
    done = sum(r["status"] in ("done", "unscored") for r in rows)
    skipped = sum(r["status"].startswith("skipped") for r in rows)
    log(f"batch: {len(rows)} recording(s): {done} reconstructed now, {skipped} already finished, "
        f"{len(summary['failed'])} failed; summary in {out_dir}/summary.md")
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
        state, done = result_state(out_dir / item["name"], item, settings, claimed=item.get("claimed", False))
        if state == "finished":
            rows.append(_row(item, done, "skipped", None))
        else:
            if state == "stale":
                log(f"batch: {item['name']}: the result there was made from another input or with other settings "
                    f"(or is unfinished); it is reconstructed again")
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
            try:
                client = own_client = Client(scheduler, timeout=SCHEDULER_TIMEOUT)
            except (OSError, ValueError, TypeError) as err:
                raise EventDataError(f"cannot reach the Dask scheduler at {scheduler} ({type(err).__name__}: {err}); "
                                     "check that it is running and the address (tcp://host:port), or leave "
                                     "--scheduler out to use this machine") from None
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
