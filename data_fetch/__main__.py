"""Command line: ``python -m data_fetch list | get | convert | info``.

    python -m data_fetch list                        datasets, sequences, what is already local
    python -m data_fetch list ijrr                   one dataset's sequences with windows and URLs
    python -m data_fetch get ijrr slider_depth       download + convert -> prints the .h5 path
    python -m data_fetch get ijrr all                every evaluation sequence of a dataset
    python -m data_fetch convert RAW [--out PATH]    a raw file you already have
    python -m data_fetch info FILE.h5                what a converted file holds

Exit status: 0 done; 2 bad input or an environment problem (``data_fetch: error: ...``: an unknown
dataset or sequence, a damaged or missing file, an unreachable server, a cache folder that cannot be
written, an existing --out without --overwrite); 1 an internal error (a bug: rerun with --debug for
the traceback); 128 + n after signal n (130 Ctrl-C, 143 SIGTERM, 129 SIGHUP): nothing half-written
is left, and the same command resumes a download.
"""
from __future__ import annotations

import argparse
import logging
import math
import sys

from . import DataFetchError, cache_dir


def _fmt_window(w) -> str:
    try:
        lo, hi = (float(v) for v in w)
    except (TypeError, ValueError):
        return "whole" if w is None else f"{w!r} (unexpected)"
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return "whole"
    return f"[{lo:g}, {hi:g}] s"


def _cmd_list(args) -> int:
    from . import list_datasets
    from .registry import DATASETS, ECD_NAMES, get_dataset

    print(f"cache folder: {cache_dir()}  (set EVINR_DATA to move it)")
    if args.dataset is None:
        for ds in DATASETS.values():
            rows = list_datasets(ds.name)
            n_eval = sum(1 for r in rows if r["sequence"] and r["evaluation"])
            n_win = sum(1 for r in rows if r["eval_window"] is not None)
            done = sum(1 for r in rows if r["converted"])
            H, W = ds.sensor_size
            how = {"http": "direct download", "gdrive": "Google Drive folder (gdown)",
                   "manual": "NOT downloadable: place files by hand"}[ds.method]
            windows = f" ({n_win} with an evaluation window, the rest scored whole)" if 0 < n_win < n_eval else ""
            seqs = f"{n_eval} sequences{windows}" if ds.sequences else "sequences on request"
            print(f"\n{ds.name:6s} {ds.title}\n       {W}x{H}, C = {ds.C:g}, {seqs}, {how}; {done} converted here")
        from .registry import WEIGHTS
        for name, files in WEIGHTS.items():
            print(f"\n{name:6s} weights: {', '.join(f.file for f in files.values())} (`python -m data_fetch get {name} all`)")
        print("\n`python -m data_fetch list <dataset>` lists the sequences; "
              "`python -m data_fetch get <dataset> <sequence>` fetches one.")
        return 0
    ds = get_dataset(args.dataset)
    print(f"{ds.name}: {ds.title}\n  {ds.note}\n  home: {ds.homepage}\n  cite: {ds.citation}")
    if not ds.sequences:
        print(f"  place the files of a sequence in {cache_dir() / 'raw' / ds.name}/<sequence>/ by hand")
        return 0
    print(f"\n  {'sequence':38s} {'window':16s} {'state':10s} checksum")
    for r in list_datasets(ds.name):
        if not r["evaluation"] and not args.all:
            continue
        state = "converted" if r["converted"] else ("raw" if r["raw"] else "-")
        check = (r["known_hash"] or "none published").split(":")[0]
        print(f"  {r['sequence']:38s} {_fmt_window(r['eval_window']):16s} {state:10s} {check}")
    hidden = sum(1 for r in list_datasets(ds.name) if not r["evaluation"])
    by_name = [n for n in ECD_NAMES if n not in ds.sequences] if ds.name == "ijrr" else []
    if args.all and by_name:   # `get` builds these from the URL pattern: no evaluation window, scored whole
        print(f"  also fetched by name (whole sequence, no evaluation window): {', '.join(by_name)}")
    elif (hidden or by_name) and not args.all:
        print(f"  (+{hidden + len(by_name)} sequences outside the evaluation protocol: --all)")
    return 0


def _cmd_get(args) -> int:
    from . import get, get_all

    kwargs = dict(url=args.url, known_hash=args.sha256 and f"sha256:{args.sha256}", verify=not args.no_verify,
                  force=args.force, keep_raw=not args.delete_raw, progress=not args.quiet)
    if args.sequences == ["all"]:
        if args.url:
            raise DataFetchError("--url names one file; it cannot be used with 'all'")
        for name, path in get_all(args.dataset, **kwargs).items():
            print(path)
        return 0
    for name in args.sequences:
        print(get(args.dataset, name, **kwargs))
    return 0


def _cmd_convert(args) -> int:
    from . import convert

    print(convert(args.raw, args.out, dataset=args.dataset, sequence=args.sequence,
                  sensor_size=tuple(args.sensor_size) if args.sensor_size else None, C=args.C,
                  event_topic=args.event_topic, image_topic=args.image_topic, progress=not args.quiet,
                  overwrite=args.overwrite, time_unit=args.time_unit, grey=args.grey,
                  **({} if args.cfa is None else {"cfa": None if args.cfa == "none" else args.cfa})))
    return 0


def _show(value, spec: str = "", unit: str = "") -> str:
    """One attribute for the description: formatted when present and of the right kind, else "?" (a
    file written by another tool may lack an optional attribute; that is not a crash of this command)."""
    if value is None:
        return "?"
    try:
        return f"{value:{spec}}{unit}"
    except (TypeError, ValueError):
        return f"{value!r}{unit} (unexpected)"


def _cmd_info(args) -> int:
    from . import info

    i = info(args.file)
    size = i.get("sensor_size")
    try:
        H, W = (int(v) for v in size)
        sensor = f"{W}x{H} (W x H, as datasheets write it)"
    except (TypeError, ValueError):
        sensor = "?"
    print(f"{args.file}\n  {i.get('dataset') or '?'} / {i.get('sequence') or '?'}: {i.get('source') or ''}")
    print(f"  {_show(i.get('n_events'))} events over [{_show(i.get('t_first'), '.6f')}, {_show(i.get('t_last'), '.6f')}] s "
          f"(t_origin {_show(i.get('t_origin'), '.0f')} s), {_show(i.get('n_frames'))} frames, sensor {sensor}, "
          f"C = {_show(i.get('C'), 'g')}")
    print(f"  evaluation window {_fmt_window(i.get('eval_window'))} on the file's clock "
          f"(published {_fmt_window(i.get('eval_window_published'))} after t_zero = {_show(i.get('t_zero'), '.6f')} s)")
    if i.get("meta"):
        print(f"  meta: {', '.join(sorted(map(str, i['meta'])))}")
    return 0


EXIT_ERROR, EXIT_INTERNAL = 2, 1


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        self.exit(EXIT_ERROR, f"data_fetch: error: {message} (see `{self.prog} --help`)\n")


def build_parser() -> argparse.ArgumentParser:
    p = _Parser(prog="python -m data_fetch", description=__doc__,
                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--debug", action="store_true", help="show the traceback of an internal error")
    sub = p.add_subparsers(dest="command", required=True)
    q = sub.add_parser("list", help="datasets and sequences")
    q.add_argument("dataset", nargs="?")
    q.add_argument("--all", action="store_true", help="also sequences outside the evaluation protocol")
    q.set_defaults(func=_cmd_list)
    q = sub.add_parser("get", help="download and convert sequences")
    q.add_argument("dataset")
    q.add_argument("sequences", nargs="+", metavar="sequence", help="sequence names, or 'all'")
    q.add_argument("--url", help="download from this address instead (a mirror)")
    q.add_argument("--sha256", help="checksum to verify the download against")
    q.add_argument("--no-verify", action="store_true", help="skip the pinned checksum")
    q.add_argument("--force", action="store_true", help="convert again even if converted")
    q.add_argument("--delete-raw", action="store_true", help="delete the raw download after converting")
    q.add_argument("--quiet", action="store_true", help="no progress bars")
    q.set_defaults(func=_cmd_get)
    q = sub.add_parser("convert", help="convert a raw file you already have (an IJRR zip or folder, a ROS1 .bag, "
                                       "a ROS2 bag's folder, a CED zip, an MVSEC / HQF .h5)")
    q.add_argument("raw")
    q.add_argument("--out", help="output .h5 file or folder (default: the cache)")
    q.add_argument("--dataset")
    q.add_argument("--sequence")
    q.add_argument("--sensor-size", nargs=2, type=int, metavar=("H", "W"))
    q.add_argument("--C", type=float, help="contrast threshold to store (default: the dataset's)")
    q.add_argument("--time-unit", choices=("s", "ms", "us", "ns"),
                   help="unit of the raw timestamps of IJRR text and HQF-style h5 (default: decimals are seconds, "
                        "integers microseconds)")
    q.add_argument("--overwrite", action="store_true", help="replace an existing output file")
    q.add_argument("--event-topic")
    q.add_argument("--image-topic")
    q.add_argument("--cfa", choices=("RGGB", "GRBG", "GBRG", "BGGR", "none"),
                   help="colour filter of a colour camera's bag (default: the dataset's; CED: RGGB); none: mono")
    q.add_argument("--grey", action="store_true", help="store grey frames only (default: colour frames stay colour)")
    q.add_argument("--quiet", action="store_true")
    q.set_defaults(func=_cmd_convert)
    q = sub.add_parser("info", help="describe a converted .h5")
    q.add_argument("file")
    q.set_defaults(func=_cmd_info)
    return p


def main(argv=None) -> int:
    """Run the command; 0 ok, 2 bad input, 1 internal error (``--debug`` shows the traceback), 128 + n after signal n.

    The guard is evinr-lite's (:func:`evinr_lite.core.guard.run_guarded`): signals handled from the
    first line, a closed stdout pipe harmless, a deleted current folder refused."""
    from evinr_lite.core.guard import run_guarded   # standard library only
    from evinr_lite.core.runtime import command_page_policy   # standard library only

    owns_process = argv is None
    if owns_process:                       # numpy not imported yet: its page policy (core/runtime.py)
        command_page_policy()
    argv = list(sys.argv[1:] if argv is None else argv)
    seen = {}

    def body() -> int:
        args = build_parser().parse_args([str(a) for a in argv])
        seen["args"] = args
        log = logging.getLogger("data_fetch")
        if not log.handlers:
            handler = logging.StreamHandler()
            handler.setFormatter(logging.Formatter("%(message)s"))
            log.addHandler(handler)
            log.propagate = False
        log.setLevel(logging.WARNING if getattr(args, "quiet", False) else logging.INFO)
        return args.func(args)

    def describe(err) -> str:
        return f"{err.filename}: {err.strerror}" if isinstance(err, OSError) and err.strerror and err.filename \
            else str(err)

    return run_guarded("data_fetch", body, argv, expected=(DataFetchError,), describe=describe,
                       interrupted_note=lambda exc: "nothing half-written was kept: run the same command again "
                                                    "to resume",
                       debug=lambda: getattr(seen.get("args"), "debug", False), owns_process=owns_process)


if __name__ == "__main__":
    sys.exit(main())
