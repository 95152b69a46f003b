"""data_fetch: download and convert real event datasets (IJRR, HQF, CED, MVSEC, AED) into one format.

    import data_fetch
    path = data_fetch.get("ijrr", "slider_depth")     # download (resumable, cached) + convert
    rec = data_fetch.read(path, t_start=1.0, t_end=2.5) # evinr_lite Recording(events, frames, meta)

The command line does the same: ``python -m data_fetch list | get <dataset> <sequence> |
convert <raw path> [--out ...] | info <file.h5>``.

Files live in :func:`cache_dir` (``$EVINR_DATA``, default ``~/.cache/evinr-lite``): raw downloads in
``raw/<dataset>/``, converted sequences in ``<dataset>/<sequence>.h5`` (the canonical layout of
:mod:`evinr_lite.io.canonical`). Heavy libraries (pooch, requests, gdown, rosbags, h5py) are imported
only when a function needs them, so ``import data_fetch`` is fast.
"""
from __future__ import annotations

import logging
from pathlib import Path

from .errors import ChecksumError, ConversionError, DataFetchError, DownloadError, NotDownloadable

__all__ = [
    "cache_dir", "get", "get_all", "convert", "read", "info", "list_datasets", "raw_path", "canonical_path",
    "weights_dir", "get_weights",
    "DataFetchError", "DownloadError", "ChecksumError", "ConversionError", "NotDownloadable",
]

log = logging.getLogger("data_fetch")


def cache_dir() -> Path:
    """Folder for downloads and converted sequences: ``$EVINR_DATA`` or ``~/.cache/evinr-lite``
    (:func:`evinr_lite.core.runtime.cache_dir`, so the kit and data_fetch agree)."""
    from evinr_lite.core import runtime   # imported here: `import data_fetch` stays light

    return runtime.cache_dir()


def canonical_path(dataset: str, sequence: str) -> Path:
    """Where the converted sequence is (or will be): ``<cache>/<dataset>/<sequence>.h5``."""
    from .registry import get_dataset, sequence_name

    ds = get_dataset(dataset)
    return cache_dir() / ds.name / f"{sequence_name(sequence)}.h5"


def raw_path(dataset: str, sequence: str) -> Path:
    """Where the raw download is (or is to be placed by hand): ``<cache>/raw/<dataset>/<file>``."""
    from .registry import get_dataset, get_sequence, sequence_name

    ds = get_dataset(dataset)
    if ds.method == "manual":
        return cache_dir() / "raw" / ds.name / sequence_name(sequence)
    return cache_dir() / "raw" / ds.name / get_sequence(ds.name, sequence).raw_file


def _manual_message(ds, sequence: str) -> str:
    return (f"{ds.title} is not publicly downloadable. Ask the EvINR authors for it, then place "
            f"the files of sequence {sequence!r} in {cache_dir() / 'raw' / ds.name / sequence}/ . and run this command again: it "
            f"converts them (Quad Bayer demosaicing; expected layout in data_fetch/convert_aed.py). A sequence already converted to the canonical format is found at "
            f"{cache_dir() / ds.name / (sequence + '.h5')} and returned by data_fetch.get.")


def weights_dir(name: str) -> Path:
    """Folder of a weight set (e.g. "lpips"): ``<cache>/weights/<name>``."""
    from .registry import get_weight_set

    from evinr_lite.core import runtime

    get_weight_set(name)
    return runtime.weights_dir(name)


def get_weights(name: str, files=("all",), *, verify: bool = True, progress: bool = True,
                retries: int = 3, **_ignored) -> dict[str, Path]:
    """Download (once, sha256-verified, atomic) the files of a weight set; {file name: path}.

    ``python -m data_fetch get lpips all`` does the same from the command line.
    """
    from .download import fetch_url
    from .registry import get_weight_set

    entries = get_weight_set(name)
    given = files   # for the message: what was passed, not its tuple
    if isinstance(files, str):   # one name, not its letters ("alexnet" was "has no file 'a'")
        files = (files,)
    try:
        files = tuple(files) if not isinstance(files, bytes) else (files,)   # bytes: no tuple of numbers
    except TypeError:   # None, 5: "argument of type 'NoneType' is not iterable"
        files = (None,)
    if not all(isinstance(f, str) for f in files):
        raise DataFetchError(f"files= must be a file name or a list of them ({', '.join(entries)}, or 'all'), got "
                             f"{given!r:.80}")
    wanted = list(entries) if "all" in files else list(files)
    unknown = [f for f in wanted if f not in entries]
    if unknown:
        raise DataFetchError(f"weight set {name!r} has no file {unknown[0]!r}; known: {', '.join(entries)}, all")
    from .conversion import check_writable_folder

    folder = weights_dir(name)
    check_writable_folder(cache_dir(), "cache folder")
    return {f: fetch_url(entries[f].url, folder / entries[f].file, known_hash=entries[f].known_hash if verify else None,
                         progress=progress, retries=retries) for f in wanted}


def _is_weight_set(name: str) -> bool:
    from .registry import WEIGHTS

    return isinstance(name, str) and name.lower() in WEIGHTS


def get(dataset: str, sequence: str, *, url: str | None = None, known_hash: str | None = None,
        verify: bool = True, force: bool = False, keep_raw: bool = True, progress: bool = True,
        retries: int = 3) -> Path:
    """Download (if needed) and convert one sequence; return the canonical ``.h5`` path.

    Args:
        dataset: "ijrr" (alias "ecd"), "hqf", "ced", "mvsec" or "aed".
        sequence: a sequence name (``python -m data_fetch list <dataset>``).
        url: download from this address instead (a mirror); its checksum is ``known_hash``.
        known_hash: checksum to verify ("sha256:<hex>" or "md5:<hex>"); default: the registry's.
        verify: False skips checksum verification.
        force: convert again even if the canonical file exists.
        keep_raw: keep the raw download after conversion (False deletes it).
        progress: progress bars and log lines.
        retries: resumptions of a dropped connection within this call.

    Raises:
        DownloadError (unreachable, 404: the message says where to place the file by hand),
        ChecksumError, ConversionError (damaged raw file), NotDownloadable (AED).
    """
    from evinr_lite.io.canonical import is_canonical

    from .registry import get_dataset, get_sequence, sequence_name

    if _is_weight_set(dataset):        # model weights (e.g. "lpips"): no conversion
        sequence_name(sequence)   # a weight file's name, checked as given (5 was blamed on get_weights' files=(5,))
        if url:
            raise DataFetchError(f"--url is not supported for weight files; place the file by hand in "
                                 f"{weights_dir(dataset)}/ instead")
        paths = get_weights(dataset, (sequence,), verify=verify, progress=progress, retries=retries)
        return weights_dir(dataset) if sequence == "all" else paths[sequence]
    if progress and not logging.getLogger().handlers and not log.handlers:
        handler = logging.StreamHandler()
        handler.setFormatter(logging.Formatter("%(message)s"))
        log.addHandler(handler)
        log.setLevel(logging.INFO)
    from .conversion import check_writable_folder

    ds = get_dataset(dataset)
    seq = get_sequence(ds.name, sequence)     # an unknown name is refused here, before any download
    out = canonical_path(ds.name, sequence)
    if not force and is_canonical(out):
        return out
    check_writable_folder(cache_dir(), "cache folder")
    if ds.method == "manual":
        placed = raw_path(ds.name, sequence)
        if placed.is_dir():
            from .conversion import convert as _convert
            return _convert(placed, out, dataset=ds.name, sequence=sequence, progress=progress, overwrite=True)
        raise NotDownloadable(_manual_message(ds, sequence))
    raw = raw_path(ds.name, seq.name)
    pinned = known_hash if (known_hash or url) else seq.known_hash
    pinned = pinned if verify else None
    if seq.archive_member:                              # CED: a bag placed by hand wins over the zip
        placed = raw.parent / seq.archive_member
        if placed.exists():
            raw, pinned = placed, None
    from .download import fetch_gdrive_file, fetch_url

    try:
        if url or ds.method == "http":
            fetch_url(url or seq.url, raw, known_hash=pinned, progress=progress, retries=retries,
                      homepage=ds.homepage)
        elif ds.method == "gdrive":
            fetch_gdrive_file(ds.homepage, seq.raw_file, raw, progress=progress, known_hash=pinned)
    except DownloadError as err:
        if seq.name in ds.sequences:
            raise
        raise DownloadError(f"{err} Note: {seq.name!r} is not one of the registered {ds.name} sequences "
                            f"({', '.join(ds.sequences)}); check the name.") from None
    from .conversion import convert as _convert

    path = _convert(raw, out, dataset=ds.name, sequence=seq.name, progress=progress, overwrite=True)
    if not keep_raw and raw.exists():
        raw.unlink()
    return path


def get_all(dataset: str, **kwargs) -> dict[str, Path]:
    """:func:`get` every registered evaluation sequence of a dataset; {sequence: path}."""
    from .registry import get_dataset

    if _is_weight_set(dataset):
        return get_weights(dataset, ("all",), **kwargs)
    ds = get_dataset(dataset)
    if ds.method == "manual":
        raise NotDownloadable(_manual_message(ds, "<sequence>"))
    return {name: get(ds.name, name, **kwargs) for name, s in ds.sequences.items() if s.evaluation}


def convert(raw, out=None, **kwargs) -> Path:
    """Convert a raw recording to the canonical file; see :func:`data_fetch.conversion.convert`."""
    from .conversion import convert as _convert

    return _convert(raw, out, **kwargs)


def read(path, t_start: float | None = None, t_end: float | None = None, **kwargs):
    """Read a canonical file (optionally a time window) as an evinr_lite ``Recording``."""
    from evinr_lite.io.canonical import read_canonical

    return read_canonical(path, t_start, t_end, **kwargs)


def info(path) -> dict:
    """The attributes of a canonical file (dataset, sequence, sensor size, C, eval window, counts)."""
    from evinr_lite.io.canonical import canonical_info

    return canonical_info(path)


def list_datasets(dataset: str | None = None) -> list[dict]:
    """What can be fetched, with the local state of each sequence.

    Returns one dict per sequence (or per dataset for AED): dataset, sequence, method, sensor_size,
    C, eval_window, url, known_hash, raw (path or None if absent), converted (path or None).
    """
    from evinr_lite.io.canonical import is_canonical

    from .registry import DATASETS, get_dataset

    rows = []
    for ds in ([get_dataset(dataset)] if dataset else DATASETS.values()):
        if not ds.sequences:
            rows.append(dict(dataset=ds.name, sequence=None, method=ds.method, sensor_size=ds.sensor_size, C=ds.C,
                             eval_window=None, url=None, known_hash=None, raw=None, converted=None,
                             evaluation=True, note=ds.note))
            continue
        for seq in ds.sequences.values():
            raw = raw_path(ds.name, seq.name)
            out = canonical_path(ds.name, seq.name)
            rows.append(dict(dataset=ds.name, sequence=seq.name, method=ds.method, sensor_size=ds.sensor_size,
                             C=ds.C, eval_window=seq.eval_window, url=seq.url or ds.homepage,
                             known_hash=seq.known_hash, raw=raw if raw.exists() else None,
                             converted=out if is_canonical(out) else None, evaluation=seq.evaluation,
                             note=ds.note))
    return rows
