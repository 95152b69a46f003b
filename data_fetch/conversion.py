"""`convert`: any supported raw recording -> canonical file (format detected from the path)."""
from __future__ import annotations

import logging
import shutil
import zipfile
from pathlib import Path, PurePosixPath

from .errors import ConversionError, DataFetchError
from .registry import DATASETS, Dataset, Sequence

__all__ = ["convert", "guess_sequence", "extract_member"]

log = logging.getLogger("data_fetch")
_UNSET = object()


def guess_sequence(path: Path) -> tuple[Dataset, Sequence] | None:
    """The registered (dataset, sequence) a raw file name belongs to, e.g. slider_depth.zip -> IJRR."""
    stem = path.name if path.is_dir() else path.stem
    for name in (stem, stem.removesuffix("_data")):
        hits = [(ds, ds.sequences[name]) for ds in DATASETS.values() if name in ds.sequences]
        if len(hits) == 1:
            return hits[0]
    return None


def extract_member(archive: Path, member_name: str, dest: Path) -> Path:
    """Copy the archive member whose base name is ``member_name`` to ``dest`` (streamed, atomic)."""
    try:
        with zipfile.ZipFile(archive) as z:
            members = [n for n in z.namelist() if PurePosixPath(n).name == member_name and "__MACOSX" not in n]
            if not members:
                bags = sorted(PurePosixPath(n).name for n in z.namelist() if n.endswith(".bag"))
                raise ConversionError(f"{archive} holds no {member_name}; it holds {bags or 'no bags'}")
            dest.parent.mkdir(parents=True, exist_ok=True)
            tmp = dest.with_name(f".{dest.name}.partial")
            with z.open(members[0]) as src, open(tmp, "wb") as out:
                shutil.copyfileobj(src, out, 1 << 20)
            tmp.replace(dest)
    except (zipfile.BadZipFile, EOFError, OSError) as err:
        if isinstance(err, DataFetchError):
            raise
        raise ConversionError(f"{archive}: cannot be read as a zip archive ({type(err).__name__}: {err}); it is "
                              "damaged or incomplete: delete it and run the command again to download it anew") from None
    return dest


def _kind(path: Path) -> str:
    from evinr_lite.io.formats.registry import is_ros2_bag

    if path.is_dir():
        if (path / "events.txt").exists() or any(path.glob("*/events.txt")):
            return "ijrr"
        if is_ros2_bag(path):
            return "bag2"
        raise ConversionError(f"{path}: a folder without events.txt or a ROS2 bag's metadata.yaml; data_fetch converts "
                              "IJRR folders, ROS2 bag folders, .zip, .bag and .h5/.hdf5 files (an AED sequence folder: "
                              "add --dataset aed)")
    suffix = path.suffix.lower()
    if suffix == ".bag":
        return "bag"
    if suffix in (".db3", ".mcap") and is_ros2_bag(path.parent):
        raise ConversionError(f"{path}: one storage file of a ROS2 bag; pass the bag's folder {path.parent} (with "
                              "its metadata.yaml)")
    if suffix in (".h5", ".hdf5"):
        return "h5"
    if suffix == ".zip":
        try:
            with zipfile.ZipFile(path) as z:
                names = z.namelist()
        except (zipfile.BadZipFile, OSError) as err:
            raise ConversionError(f"{path}: not a readable zip archive ({err}); the download is damaged or "
                                  "incomplete: delete it and run the command again to download it anew") from None
        if any(PurePosixPath(n).name == "events.txt" for n in names):
            return "ijrr"
        if any(n.endswith(".bag") for n in names):
            return "bag-zip"
        raise ConversionError(f"{path}: a zip with neither events.txt (IJRR) nor .bag files (CED)")
    if suffix == ".txt":
        raise ConversionError(f"{path}: pass the IJRR folder or zip (events.txt with images.txt), not events.txt "
                              "alone; or read a bare events.txt with evinr_lite.io.readers.read_events_txt")
    raise ConversionError(f"{path}: unknown raw format {suffix or '(none)'!r}; data_fetch converts IJRR zips/folders, "
                          "ROS1 .bag files, ROS2 bag folders, CED zips of bags, MVSEC .hdf5 and HQF-style .h5")


def check_writable_folder(folder: Path, what: str) -> None:
    """Refuse (DataFetchError) a folder that cannot be created or written, before any download or conversion
    (:func:`evinr_lite.io.output.check_writable`, with data_fetch's fix and error class)."""
    from evinr_lite.io.output import OutputError, check_writable

    try:
        check_writable(folder, f"the {what} {folder}", "set EVINR_DATA to a folder you can write (or choose another "
                       "--out)")
    except OutputError as err:
        raise DataFetchError(str(err)) from None


def check_settings(*, C=None, sensor_size=None, eval_window=None, time_unit=None) -> None:
    """Values that are stored in the converted file, checked before converting (DataFetchError)."""
    import math

    from evinr_lite.core.events import TIME_UNITS, EventDataError, check_sensor_size, check_time_range

    if C is not None and (isinstance(C, bool) or not isinstance(C, (int, float)) or not math.isfinite(C) or C <= 0):
        raise DataFetchError(f"C must be a positive finite contrast threshold, got {C!r} (--C)")
    if sensor_size is not None:
        try:   # the kit's one check: whole numbers only (int() made 2.5 rows into 2 and True into 1)
            check_sensor_size(sensor_size)
        except EventDataError as err:
            raise DataFetchError(f"sensor size: {err} (--sensor-size H W)") from None
    if eval_window not in (None, _UNSET):
        check_time_range(eval_window, "eval_window", DataFetchError)
    if time_unit not in (None, "auto") and not (isinstance(time_unit, str) and time_unit in TIME_UNITS):
        raise DataFetchError(f"time unit must be one of {', '.join(TIME_UNITS)}, got {time_unit!r} (--time-unit)")


def convert(raw, out=None, *, dataset: str | None = None, sequence: str | None = None, sensor_size=None,
            C: float | None = None, eval_window=_UNSET, event_topic: str | None = None, image_topic=None,
            progress: bool = True, overwrite: bool = False, time_unit: str | None = None, cfa=_UNSET,
            grey: bool = False) -> Path:
    """Convert a raw recording to the canonical HDF5 file and return its path.

    Args:
        raw: an IJRR ``.zip`` or folder, a ROS1 ``.bag`` (HQF, CED, MVSEC, IJRR), a ROS2 bag's folder
            (dvs_msgs/EventArray and sensor_msgs/Image, rewritten as a ROS1 bag first), a CED zip of bags
            (pass ``sequence``), an MVSEC ``_data.hdf5``, an HQF-style ``.h5``, or an AED sequence
            folder with ``dataset="aed"`` (layout: :mod:`data_fetch.convert_aed`; ``sensor_size`` is
            then the raw Quad Bayer event sensor).
        out: the ``.h5`` to write, or a folder for ``<sequence>.h5``; None:
            ``<cache>/<dataset>/<sequence>.h5`` (``<cache>/converted/`` for unknown recordings).
        dataset, sequence: registry names; guessed from the file name when None (e.g.
            ``slider_depth.zip`` -> ijrr/slider_depth), which fills in sensor size, C and the
            evaluation window.
        sensor_size: (H, W), overrides the registry's.
        C: contrast threshold to store (registry's, else 1.0).
        eval_window: (start, end) seconds after the sequence's zero, or None for the whole
            sequence; default: the registry's.
        event_topic, image_topic: bag topics (defaults: see :func:`data_fetch.convert_bag.convert_bag`).
        overwrite: replace an existing file at ``out`` (refused otherwise, whatever it holds).
        time_unit: unit of the raw timestamps of text recordings (IJRR folders / zips) and HQF-style
            h5 ('s', 'ms', 'us', 'ns'); None: decimals are seconds, integers microseconds.
        cfa: colour filter of a colour camera's bag ("RGGB", "GRBG", "GBRG", "BGGR"; None: mono);
            default: the registry's (CED: "RGGB"), stored as the canonical ``cfa`` attribute.
        grey: store grey frames only (the layout before colour was kept); default False keeps
            colour frames (/frames/rgb) beside their grey version.
    """
    from . import cache_dir

    check_settings(C=C, sensor_size=sensor_size, eval_window=eval_window, time_unit=time_unit)
    if sequence is not None:   # it names the output <sequence>.h5: "../evil" or "a/b" wrote outside the cache
        from .registry import sequence_name

        sequence_name(sequence)
    if cfa is not _UNSET:
        from evinr_lite.core.cfa import check_cfa

        cfa = check_cfa(cfa, DataFetchError)
    raw = Path(raw).expanduser()
    if not raw.exists():
        raise DataFetchError(f"no such file or folder: {raw}")
    ds = seq = None
    if dataset is not None:
        from .registry import get_dataset, get_sequence

        ds = get_dataset(dataset)
        if sequence is not None and ds.method != "manual":
            seq = get_sequence(ds.name, sequence)
    else:
        guess = guess_sequence(raw)
        if guess is not None and sequence in (None, guess[1].name):
            ds, seq = guess
            log.info("data_fetch: %s is %s / %s", raw.name, ds.name, seq.name)
    name = sequence or (seq.name if seq else (raw.name if raw.is_dir() else raw.stem.removesuffix("_data")))
    if out is None:
        out = cache_dir() / (ds.name if ds else "converted") / f"{name}.h5"
    else:
        out = Path(out).expanduser()
        if out.is_dir() or out.suffix.lower() not in (".h5", ".hdf5"):
            out = out / f"{name}.h5"
    if out.resolve() == raw.resolve() or raw.resolve() in out.resolve().parents:
        raise DataFetchError(f"the output {out} is (or lies inside) the raw recording itself; choose another --out")
    if out.is_dir():
        raise DataFetchError(f"the output {out} is a folder; choose a file name ending in .h5 as --out")
    if out.exists() and not overwrite:
        raise DataFetchError(f"the output {out} already exists; it is left as it is: choose another --out or pass "
                             "--overwrite (overwrite=True) to replace it")
    check_writable_folder(out.parent, "output folder")
    topics_given = [flag for flag, value in (("--event-topic (event_topic=)", event_topic),
                                             ("--image-topic (image_topic=)", image_topic)) if value]
    if topics_given and ds is not None and ds.method == "manual":
        raise DataFetchError(f"{raw}: {' and '.join(topics_given)} {'pick' if len(topics_given) > 1 else 'picks'} the topics of a ROS bag, but this is a "
                             f"{ds.name} sequence folder, which has none; leave {'them' if len(topics_given) > 1 else 'it'} out")
    if ds is not None and ds.method == "manual":   # AED: a sequence folder placed by hand (layout: convert_aed.py)
        from .convert_aed import convert_aed

        return convert_aed(raw, out, raw_sensor_size=sensor_size, C=float(C if C is not None else ds.C),
                           eval_window=None if eval_window is _UNSET else eval_window, dataset=ds.name,
                           sequence=name, source=ds.title, progress=progress,
                           time_unit=None if time_unit in (None, "auto") else time_unit)
    kind = _kind(raw)
    common = dict(
        sensor_size=sensor_size if sensor_size is not None else (ds.sensor_size if ds else None),
        C=float(C if C is not None else (ds.C if ds else 1.0)),
        eval_window=(seq.eval_window if seq else None) if eval_window is _UNSET else eval_window,
        dataset=ds.name if ds else "", sequence=name, source=(ds.title if ds else ""),
        source_url=(seq.url or ds.homepage) if (ds and seq) else "", progress=progress)
    if ds is None and C is None:
        log.warning("data_fetch: %s is not a registered sequence; storing C = 1.0 and no evaluation window", raw)

    if time_unit not in (None, "auto") and kind not in ("ijrr", "h5"):
        raise DataFetchError(f"{raw}: a {kind} recording stores its time unit itself; leave --time-unit out")
    if cfa not in (_UNSET, None) and kind not in ("bag", "bag2", "bag-zip"):
        raise DataFetchError(f"{raw}: cfa= applies to ROS bags (CED) only, not a {kind} recording; leave it out")
    if topics_given and kind not in ("bag", "bag2", "bag-zip"):   # else silently ignored: the user expects them used
        raise DataFetchError(f"{raw}: {' and '.join(topics_given)} {'pick' if len(topics_given) > 1 else 'picks'} the topics of a ROS bag, but this is a {kind} "
                             f"recording, which has none; leave {'them' if len(topics_given) > 1 else 'it'} out")
    if kind == "ijrr":
        from .convert_ijrr import convert_ijrr

        return convert_ijrr(raw, out, **common, time_unit=time_unit or "auto")
    if kind == "h5":
        from .convert_h5 import convert_h5

        return convert_h5(raw, out, **common, time_unit=time_unit)
    from .convert_bag import convert_bag

    topics = dict(event_topic=event_topic or (ds.event_topic if ds else None),
                  image_topic=image_topic or ((ds.image_topics or None) if ds else None),
                  cfa=(ds.cfa if ds else None) if cfa is _UNSET else cfa, grey=grey)
    if kind == "bag":
        return convert_bag(raw, out, **common, **topics)
    if kind == "bag2":   # a ROS2 bag: rewritten as a ROS1 bag beside the output, converted, the copy deleted
        from .convert_bag import ros2_to_ros1

        out.parent.mkdir(parents=True, exist_ok=True)
        bag = ros2_to_ros1(raw, out.parent / f".{raw.name}.ros1.bag")
        try:
            return convert_bag(bag, out, **common, **topics)
        except ConversionError as err:   # name the user's bag, not its temporary ROS1 copy
            raise ConversionError(str(err).replace(str(bag), str(raw))) from None
        finally:
            bag.unlink(missing_ok=True)
    # a CED-style zip of bags: take out the one bag, convert it, delete the copy
    member = (seq.archive_member if seq and seq.archive_member else f"{name}.bag")
    bag = extract_member(raw, member, out.parent / f".{member}")
    try:
        return convert_bag(bag, out, **common, **topics)
    finally:
        bag.unlink(missing_ok=True)
