"""The registry of formats: detection, ``read_recording`` and the capability tables, all derived from
the ``FileFormat`` each format module declares.

Adding a format is one new module in this package that defines its reader and a ``FORMAT`` (found
here by walking the package); detection, :func:`read_recording`, :data:`SUPPORTED_FORMATS`,
:func:`~evinr_lite.io.source.open_recording` and the tables the command line uses follow from it.
"""
from __future__ import annotations

import errno
import importlib
import os
import pkgutil
import re
import stat
from pathlib import Path

from ...core.checks import ArgumentTypeError, check_path_type
from ...core.events import EventDataError, Events
from ...core.recording import Recording
from .base import FileFormat, file_path

__all__ = ["FORMATS", "get_format", "detect_format", "read_recording", "read_events", "sniff_format",
           "SUPPORTED_FORMATS", "RECORDING_SUFFIXES", "SIZE_FREE_FORMATS", "READER_WINDOW_FORMATS",
           "SENSOR_ARG_FORMATS", "TIME_UNIT_FORMATS", "FIXED_UNITS", "is_recording_folder", "is_ros2_bag",
           "recording_path", "UnknownOptionError"]

HEAD_BYTES = 64
_AEDAT_FIX = "AEDAT 3.1 and AEDAT4 are read: convert it with iniVation's DV software (Convert to AEDAT4) or export " \
             "the events to a `t x y p` text file"
_ROS2_FIX = "pass the bag's folder (the one with metadata.yaml) to `python -m data_fetch convert FOLDER`, which " \
            "writes the canonical .h5 that evinr-lite reads"
_UNPACK = "decompress it first ({tool} FILE) and pass the file it gives"
UNSUPPORTED = {   # first bytes of files that are recognised but not read -> (sniff_format's name, the fix)
    b"#!AER-DAT3": ("aedat30", f"an AEDAT 3.0 file (not 3.1); {_AEDAT_FIX}"),
    b"#!AER-DAT2": ("aedat2", f"an AEDAT2 file; {_AEDAT_FIX}"),
    b"#!AER-DAT1": ("aedat2", f"an AEDAT2 file; {_AEDAT_FIX}"),
    b"PK\x03\x04": ("zip", "a zip archive; unzip it first and pass the folder (IJRR / EVREAL) or the file inside"),
    b"\x1f\x8b": ("gzip", f"a gzip-compressed file; {_UNPACK.format(tool='gunzip -k')}"),
    b"BZh": ("bzip2", f"a bzip2-compressed file; {_UNPACK.format(tool='bunzip2 -k')}"),
    b"\xfd7zXZ\x00": ("xz", f"an xz-compressed file; {_UNPACK.format(tool='unxz -k')}"),
    b"\x28\xb5\x2f\xfd": ("zstd", f"a zstd-compressed file; {_UNPACK.format(tool='unzstd')}"),
    b"7z\xbc\xaf\x27\x1c": ("7z", "a 7-Zip archive; extract it first (7z x FILE) and pass the folder (IJRR / EVREAL) "
                                 "or the file inside"),
    b"#ROSBAG V2.0": ("rosbag", "a ROS1 bag, which is not read directly; convert it with `python -m data_fetch convert "
                                "FILE.bag` (dvs_msgs event arrays and the APS images, or event_camera_msgs packets, to "
                                "the canonical .h5 that evinr-lite reads)"),
    b"\x89MCAP": ("mcap", f"an MCAP file, the storage of a ROS2 bag, which is not read directly; {_ROS2_FIX}"),
    b"SQLite format 3\x00": ("sqlite", "an SQLite database, such as a ROS2 bag's .db3 storage, which is not read "
                                       f"directly; for a bag, {_ROS2_FIX}"),
}
ROS2_METADATA = "rosbag2_bagfile_information"   # the key a ROS2 bag's metadata.yaml opens with


def is_ros2_bag(folder) -> bool:
    """True for a ROS2 bag's folder: a metadata.yaml that names itself rosbag2_bagfile_information."""
    meta = Path(folder) / "metadata.yaml"
    try:
        return meta.is_file() and ROS2_METADATA in meta.read_text(errors="replace")[:4096]
    except OSError:
        return False


def _collect() -> tuple[FileFormat, ...]:
    """Every FORMAT / FORMATS of the package's modules, in the order they are tried (``priority``)."""
    found = []
    for info in pkgutil.iter_modules(importlib.import_module(__package__).__path__):
        module = importlib.import_module(f"{__package__}.{info.name}")
        declared = getattr(module, "FORMATS", None) or getattr(module, "FORMAT", None)
        if declared is not None:
            found.extend(declared if isinstance(declared, tuple) else (declared,))
    return tuple(sorted(found, key=lambda fmt: (fmt.priority, fmt.name)))


FORMATS: tuple[FileFormat, ...] = _collect()
_BY_NAME = {fmt.name: fmt for fmt in FORMATS}

SUPPORTED_FORMATS = "; ".join(fmt.description for fmt in FORMATS)
RECORDING_SUFFIXES = tuple(dict.fromkeys(s for fmt in FORMATS for s in fmt.suffixes))   # files taken from a folder
SIZE_FREE_FORMATS = tuple(fmt.name for fmt in FORMATS if fmt.needs_sensor_size)     # may not record the sensor size
READER_WINDOW_FORMATS = tuple(fmt.name for fmt in FORMATS if fmt.windowed)          # read only a window from disk
SENSOR_ARG_FORMATS = tuple(fmt.name for fmt in FORMATS if fmt.takes_sensor_size)    # take sensor_size=
TIME_UNIT_FORMATS = tuple(fmt.name for fmt in FORMATS if fmt.time_unit is None and "time_unit" in fmt.options)
FIXED_UNITS = {fmt.name: fmt.time_unit for fmt in FORMATS if fmt.time_unit is not None}


def get_format(name: str) -> FileFormat:
    """The declaration of the format called ``name``."""
    if not isinstance(name, str):   # a list or an array: Python's "unhashable type"
        raise ArgumentTypeError(f"get_format: name= must be a format's name (text), got {type(name).__name__}; "
                                f"known: {', '.join(_BY_NAME)}")
    try:
        return _BY_NAME[name]
    except KeyError:
        raise EventDataError(f"unknown format {name!r}; known: {', '.join(_BY_NAME)}") from None


def recording_path(path) -> Path:
    """The recording's path as a Path, ``~`` and ``~user`` expanded (as the output folder's are; a Python caller
    or a quoted argument passes them as they are); an empty path or an unknown user is an EventDataError."""
    if not isinstance(path, (str, bytes, os.PathLike)):   # None, a number: Python's "expected str, bytes or ..."
        check_path_type(path, "path", "the recording's file or folder")
    if isinstance(path, (str, bytes)) and not path.strip():   # Path("") is ".", the current folder
        raise EventDataError("the recording's path is empty; pass the file or folder to read")
    if isinstance(path, bytes):
        path = os.fsdecode(path)
    try:
        return Path(path).expanduser()
    except (RuntimeError, KeyError):   # ~someone who is no user here, or no home folder to expand ~ to
        head = Path(path).parts[0]
        raise EventDataError(f"{path}: {head} names no user's home folder on this machine; write the folder's full "
                             "path (e.g. /home/me/data/...)") from None


def _no_such(path: Path, given) -> str:
    """Why ``path`` (which does not exist) was not found, and the fix."""
    text = os.fspath(given) if isinstance(given, (str, os.PathLike)) else str(given)
    if re.match(r"(https?|ftp|s3|gs)://?", text):
        text = re.sub(r"^(\w+):/(?!/)", r"\1://", text)   # Path() has made '://' into ':/'
        return (f"{text} is a web address, not a file on this machine; download it first (for the datasets the kit "
                "knows: `python -m data_fetch get DATASET SEQUENCE`) and pass the file")
    return f"no such file or folder: {path}; check the path"


# the files of an IJRR or EVREAL folder: a folder holding one is a damaged recording folder, not a folder of recordings
RECORDING_FOLDER_FILES = frozenset({"events.txt", "images.txt", "calib.txt", "groundtruth.txt", "imu.txt",
                                    "depthmaps.txt", "metadata.json", "events_ts.npy", "events_xy.npy", "events_p.npy",
                                    "images.npy", "images_ts.npy"})


def _recordings_inside(folder: Path) -> list[str]:
    """The names of the recordings directly inside ``folder`` (files with a recording suffix, recording folders)."""
    found = []
    try:
        children = sorted(folder.iterdir())
    except OSError:
        return found
    if any(child.name in RECORDING_FOLDER_FILES for child in children):   # a recording folder that lacks a part
        return found
    for child in children:
        if child.name.startswith("."):
            continue
        if child.is_file() and child.suffix.lower() in RECORDING_SUFFIXES or child.is_dir() and \
                any(fmt.folder and fmt.sniff(child, None) for fmt in FORMATS):
            found.append(child.name + ("/" if child.is_dir() else ""))
    return found


def _checked_path(path) -> Path:
    given = path
    path = recording_path(path)
    if not path.exists() and path.is_symlink():   # a link that leads nowhere is no missing file: say which it is
        try:
            os.stat(path)
        except OSError as err:
            if err.errno == errno.ELOOP:
                raise EventDataError(f"{path} goes through a loop of symbolic links, so it leads to no file; fix or "
                                     "remove the link, or pass the recording itself") from None
        raise EventDataError(f"{path} is a symbolic link to {os.readlink(path)}, which does not exist (moved or "
                             "deleted?); point the link at the recording again, or pass the recording itself")
    if not path.exists():
        raise EventDataError(_no_such(path, given))
    try:
        mode = path.stat().st_mode
    except OSError as err:
        raise EventDataError(f"{path}: cannot be read ({err.strerror})") from None
    if not (stat.S_ISDIR(mode) or stat.S_ISREG(mode)):
        raise EventDataError(f"{path} is not a regular file or folder (a FIFO, pipe or device); save the recording "
                             "to a file first")
    return path


def detect_format(path) -> str:
    """The format of a recording, from its content first and its name second.

    Returns the name of one of :data:`FORMATS` ("ijrr", "evreal", "canonical", "h5", "aedat4",
    "prophesee_raw", "prophesee_dat", "npy", "txt"). Raises EventDataError naming the supported
    formats otherwise.
    """
    path = _checked_path(path)
    if path.is_dir():
        if not os.access(path, os.R_OK | os.X_OK):
            raise EventDataError(f"{path}: no permission to read this folder")
        for fmt in FORMATS:
            if fmt.folder and fmt.sniff(path, None):
                return fmt.name
        if is_ros2_bag(path):
            raise EventDataError(f"{path}: a ROS2 bag, which is not read directly; convert it with `python -m data_fetch "
                                 f"convert {path}` (dvs_msgs event arrays and the APS images, or event_camera_msgs "
                                 "packets, to the canonical .h5 that evinr-lite reads)")
        inside = _recordings_inside(path)
        if inside:   # a folder of recordings, not a recording folder
            shown = ", ".join(inside[:5]) + (f" and {len(inside) - 5} more" if len(inside) > 5 else "")
            raise EventDataError(f"{path}: a folder holding {len(inside)} recording(s) ({shown}), not one recording "
                                 f"(such as an IJRR or EVREAL folder); pass one of them, e.g. {path / inside[0]}, or "
                                 f"give the folder to `evinr-lite batch {path} --out DIR`, which reads every recording "
                                 "in it")
        raise EventDataError(f"{path}: folder of unknown format (no events.txt or events_ts.npy); "
                             f"supported formats: {SUPPORTED_FORMATS}")
    if path.stat().st_size == 0:
        raise EventDataError(f"{path} is empty (0 bytes); the file was not written completely: copy it again")
    try:
        with open(path, "rb") as f:
            head = f.read(HEAD_BYTES)
        for fmt in FORMATS:
            if not fmt.folder and fmt.sniff(path, head):
                return fmt.name
    except OSError as err:
        raise EventDataError(f"{path}: cannot be read ({err.strerror}); check its permissions") from None
    if head.startswith(b"PK\x03\x04"):
        _refuse_npz(path)
    for magic, (_, problem) in UNSUPPORTED.items():
        if head.startswith(magic):
            raise EventDataError(f"{path}: {problem}")
    suffix = path.suffix.lower()
    for fmt in FORMATS:
        if fmt.by_suffix and suffix in fmt.suffixes:
            return fmt.name
    raise EventDataError(f"{path}: unknown format {suffix or '(no extension)'!r} (and its content is none of "
                         f"the known ones); supported formats: {SUPPORTED_FORMATS}")


def _refuse_npz(path: Path) -> None:
    """Refuse numpy's .npz (a zip of .npy arrays) with the fix: unzipped, its arrays are no recording either."""
    import zipfile

    try:
        with zipfile.ZipFile(path) as archive:
            members = archive.namelist()
    except (zipfile.BadZipFile, OSError, ValueError):
        return   # a damaged zip: the zip message applies
    if not members or not all(m.endswith(".npy") for m in members):
        return
    keys = [m[:-4] for m in members]
    shown = ", ".join(keys[:8]) + (", ..." if len(keys) > 8 else "")
    raise EventDataError(f"{path}: a numpy .npz archive (arrays {shown}), which is not read; save the events as one "
                         "[N, 4] .npy array with columns t, x, y, p, e.g. a = np.load(path); np.save('events.npy', "
                         "np.stack([a['t'], a['x'], a['y'], a['p']], axis=1)) with your arrays' names, and pass "
                         "that with --sensor HxW")


def is_recording_folder(path) -> bool:
    """True when ``path`` is a folder in a recording format (IJRR, EVREAL), not a folder of recordings."""
    path = Path(path)
    return path.is_dir() and any(fmt.folder and fmt.sniff(path, None) for fmt in FORMATS)


def sniff_format(path) -> str | None:
    """The format of a file from its first bytes alone: a format's name, 'hdf5' for any HDF5 file,
    'aedat2' / 'aedat30' / 'zip' / 'gzip' (and the other compressors) / 'rosbag' / 'mcap' / 'sqlite' for files
    recognised but not read, or None (not recognised: maybe text, or empty); a folder or a missing file is an
    EventDataError naming it (Python's IsADirectoryError or FileNotFoundError)."""
    path = file_path(path)
    with open(path, "rb") as f:
        head = f.read(HEAD_BYTES)
    if head.startswith(b"\x89HDF\r\n\x1a\n"):
        return "hdf5"
    for fmt in FORMATS:
        if not fmt.folder and not fmt.by_suffix and fmt.sniff(path, head):
            return fmt.name
    return next((name for magic, (name, _) in UNSUPPORTED.items() if head.startswith(magic)), None)


def read_recording(path, **options) -> Recording:
    """Read any supported recording; the format is detected by :func:`detect_format`.

    ``options`` go to that format's reader (e.g. ``sensor_size=``, ``time_unit=``, ``t_start=`` /
    ``t_end=`` for the formats that read only a window). ``meta["format"]`` names the format read.
    """
    path = recording_path(path)
    fmt = get_format(detect_format(path))
    check_options(fmt, options, path)
    return fmt.reader(path, **options)


class UnknownOptionError(EventDataError, TypeError):
    """A keyword a reader does not take: an EventDataError that lists the ones it does, and the TypeError Python
    raises for an unexpected keyword, so that code catching that still does."""


def check_options(fmt, options: dict, path) -> None:
    """Refuse keyword options that ``fmt``'s reader does not take (e.g. ``camera=`` for an IJRR folder), naming the
    ones it does, before anything is read (a reader called with them raised a bare TypeError)."""
    import inspect

    params = inspect.signature(fmt.reader).parameters
    if any(p.kind is p.VAR_KEYWORD for p in params.values()):   # read_npy / read_txt / read_csv pass **options on:
        taken = (["sensor_size"] if fmt.takes_sensor_size else []) + list(fmt.options) + \
            (["t_start", "t_end"] if fmt.windowed else [])    # their declaration names what the reader takes
    else:
        taken = [n for n, p in list(params.items())[1:] if p.kind in (p.KEYWORD_ONLY, p.POSITIONAL_OR_KEYWORD)]  # [0]: the path
    unknown = sorted(set(options) - set(taken))
    if unknown:
        hint = " (camera= is for MVSEC's stereo files)" if "camera" in unknown else ""
        raise UnknownOptionError(f"{path}: {fmt.description} takes no option {', '.join(map(repr, unknown))}{hint}; "
                             f"its reader takes {', '.join(taken) or 'no options'}")


def read_events(path, **options) -> Events:
    """Only the events of :func:`read_recording`."""
    return read_recording(path, **options).events
