"""Writing results so that nothing is ever lost or half-written.

An output folder is reserved for the whole run by :class:`OutputDir`, before any long work:

1. **checks** (:func:`check_output_path`): the path is not a symbolic link, not an existing file, not
   the input recording, does not contain it and does not lie inside it, is not the current folder
   when it would be replaced; its parent can be created and written; its name leaves room for the
   temporary names on this file system; an existing folder is refused unless ``overwrite``.
2. **lock**: ``.<name>.lock`` beside the folder (a ``filelock`` lock, released by the kernel when a
   process dies): a second run into the same folder is refused at once, naming the first.
3. **recovery**: hidden ``.<name>.partial-<pid>-*`` folders of dead runs are named and removed; an
   old result renamed aside (``.<name>.old-*``) by a run killed mid-replacement is put back.
4. **staging**: results are written into ``.<name>.partial-<pid>-<random>`` beside the folder
   (created at once, so an unwritable place is found before training).
5. **commit**: with SIGINT, SIGTERM and SIGHUP held back, the old folder is renamed aside, the new
   one renamed in, and only then is the old one deleted: at every instant the old or the new
   result is complete under its name (or, after a hard kill between the two renames, complete
   under ``.<name>.old-*``, and put back by the next run).

On an exception or an interruption the staging folder, the lock file and any parent folders the
run created are removed; an existing folder is left as it was.
"""
from __future__ import annotations

import json
import os
import secrets
import shutil
import signal
import socket
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np
from PIL import Image

from ..core.checks import ArgumentTypeError, check_log, check_path_type, true_or_false
from ..core.events import InputError
from ..core.frames import to_uint8
from ..core.guard import TERMINATION_SIGNALS, Interrupted, signals_deferred, termination_signals  # re-exported

__all__ = ["atomic_output_dir", "given_output_path", "CloseOrAbort", "OutputDir", "OutputError", "OutputExistsError", "check_output_path", "Interrupted",
           "termination_signals", "signals_deferred", "save_png", "PngWriter", "save_json", "first_existing", "check_writable",
           "TERMINATION_SIGNALS", "PARTIAL_MARKER", "mark_partial", "remove_stale_partials", "remove_lock_file",
           "resolve_path", "written_beside"]

_TEMP_ROOM = len(".partial-4194304-") + 16 + 1   # bytes a temporary name adds to the folder's name


class OutputError(InputError):
    """The output path cannot be used as given; the message names the problem and the fix."""


class OutputExistsError(OutputError, FileExistsError):
    """The output folder exists and ``overwrite`` is False."""


def first_existing(path: Path) -> Path:
    """``path`` or its nearest existing ancestor: where a folder that does not exist yet would be created."""
    while not os.path.lexists(path) and path != path.parent:
        path = path.parent
    return path


def check_writable(folder, what: str, fix: str) -> Path:
    """Refuse, before any work, a folder that cannot be created or written: its nearest existing ancestor
    must be a folder this process may write in. The one such check (``data_fetch`` uses it too).

    Args:
        folder: the folder (it need not exist yet).
        what: how the message names it, e.g. "the output folder rec".
        fix: what to do instead; ends the message.

    Returns:
        The nearest existing ancestor (``folder`` itself when it exists).

    Raises:
        OutputError: "cannot create <what>: <ancestor> is a file, not a folder; <fix>" or
        "cannot write <what>: no permission to write in <ancestor>; <fix>".
    """
    anchor = first_existing(Path(folder))
    if not anchor.is_dir():
        raise OutputError(f"cannot create {what}: {anchor} is a file, not a folder; {fix}")
    if not os.access(anchor, os.W_OK | os.X_OK):
        raise OutputError(f"cannot write {what}: no permission to write in {anchor}; {fix}")
    return anchor


def resolve_path(path, what: str = "the path") -> Path:
    """``Path(path).resolve()``, with a symbolic-link loop or an unreadable link as an OutputError naming
    the path (Python raises RuntimeError or OSError there, which would read as an internal error)."""
    check_path_type(path, "path", f"{what} (a file or folder)")   # None was Python's "expected str, bytes or os.PathLike"
    try:
        return Path(path).resolve()
    except (RuntimeError, OSError) as err:
        raise OutputError(f"{what} {str(path)!r} cannot be followed: it goes through a loop of symbolic links "
                          f"or a link that cannot be read ({err}); fix or remove the link, or choose another "
                          "path") from None


def _inside(a: Path, b: Path) -> bool:
    """True when a is b or lies inside b (both resolved)."""
    return a == b or b in a.parents


def given_output_path(out_dir) -> Path:
    """``out_dir`` as a Path (``~`` expanded); an empty or blank name is an OutputError, not the current folder
    (``Path("")`` is ".") nor a folder named by spaces; None or a number is refused naming out_dir= (Python's
    "expected str, bytes or os.PathLike object" named nothing)."""
    check_path_type(out_dir, "out_dir", "a folder")   # bytes too: Path(b"x") is Python's TypeError
    if isinstance(out_dir, str) and not out_dir.strip():
        raise OutputError(f"out_dir={out_dir!r} is empty or blank (an empty path would be the current folder); pass "
                          "the folder to write, e.g. out_dir=rec")
    name = os.fspath(out_dir)   # a str: bytes were refused above
    if "\0" in name:   # no file name holds one: os calls raise a bare ValueError
        raise OutputError(f"out_dir={name!r} holds a NUL character (\\x00), which no file name can; "
                          "pass the folder's name without it")
    try:
        return Path(out_dir).expanduser()
    except (RuntimeError, KeyError):   # ~someone who is no user here, or no home folder to expand ~ to
        raise OutputError(f"out_dir={name!r} starts with {Path(name).parts[0]}, which "
                          "names no user's home folder on this machine; write the folder's full path (e.g. "
                          "/home/me/results)") from None


def check_output_path(out_dir, *, overwrite: bool = False, inputs=()) -> Path:
    """Every check of an output folder that can be made before any work; returns its absolute path.

    Args:
        out_dir: the folder to write.
        overwrite: an existing folder may be replaced.
        inputs: paths the run reads (the recording): the output may not be, contain, or lie inside one.
    Raises:
        OutputError naming the problem and the fix.
    """
    given = given_output_path(out_dir)
    out = Path(os.path.abspath(given))
    if out == out.parent or not out.name:
        raise OutputError(f"out_dir={str(given)!r} is the root of the file system; choose a folder to create, e.g. out_dir=rec")
    real = resolve_path(out.parent, "out_dir=") / out.name
    for source in inputs:
        if source is None:
            continue
        source = resolve_path(Path(source).expanduser(), "the input")
        if _inside(source, resolve_path(real, "out_dir=") if out.is_symlink() else real):
            what = "is the input recording" if source == real else f"contains the input recording {source}"
            raise OutputError(f"the output folder {given} {what}; writing there would replace the input; "
                              "choose another out_dir=")
        if source.is_dir() and _inside(real, source):
            raise OutputError(f"the output folder {given} lies inside the input folder {source}; write the result "
                              "elsewhere (choose another out_dir=)")
    if out.is_symlink():
        raise OutputError(f"the output {given} is a symbolic link (to {os.readlink(out)}); pass the folder it points "
                          "to, or another name, as out_dir=")
    if out.exists() and not out.is_dir():
        raise OutputError(f"the output {given} exists and is a file, not a folder; it is left as it is: choose "
                          "another out_dir= (or delete the file yourself)")
    if out.exists() and not overwrite:
        raise OutputExistsError(f"output folder {given} already exists; choose another out_dir= or pass overwrite=True")
    if out.exists() and _inside(Path.cwd().resolve(), real):
        raise OutputError(f"the output folder {given} is the current folder (or contains it); replacing it would "
                          "delete the folder you are working in: choose a new folder, e.g. out_dir=rec")
    anchor = check_writable(out.parent, f"the output folder {given}",
                            "choose another out_dir=, in a folder you can write")
    try:
        name_max = os.pathconf(anchor, "PC_NAME_MAX")
    except (OSError, ValueError):
        name_max = 255
    longest = max(len(part.encode()) for part in out.relative_to(anchor).parts)
    if longest + _TEMP_ROOM > name_max:
        raise OutputError(f"the output folder name in {given} is {longest} bytes long; this file system allows "
                          f"{name_max} per name and {_TEMP_ROOM} are needed for a temporary name beside it: choose "
                          f"a name of at most {name_max - _TEMP_ROOM} bytes as out_dir=")
    return out


PARTIAL_MARKER = ".evinr-partial"   # inside every staging folder this package makes: recovery removes only those


def mark_partial(folder: Path, command: str = "") -> None:
    """Mark a staging folder as this package's own (so that recovery may delete it, and nothing else)."""
    (Path(folder) / PARTIAL_MARKER).write_text(json.dumps({"pid": os.getpid(), "host": socket.gethostname(),
                                                            "command": command}) + "\n")


def remove_stale_partials(parent, name: str = "*", *, log=None) -> list[Path]:
    """Remove ``.<name>.partial-*`` folders in ``parent`` that runs of this package left behind.

    Only folders that carry :data:`PARTIAL_MARKER` (or are empty: a run killed right after creating
    one) are removed; a folder of the same pattern without the marker is someone else's and is left
    as it is, with a note. The caller must hold the lock that proves those runs have ended.
    Returns the folders removed.
    """
    log = log or (lambda message: None)
    removed = []
    for stale in sorted(Path(parent).glob(f".{name}.partial-*")):
        if stale.is_symlink() or not stale.is_dir():
            continue
        try:
            ours = (stale / PARTIAL_MARKER).is_file() or not any(stale.iterdir())
        except OSError:
            ours = False
        if not ours:
            log(f"note: left {stale} as it is: it looks like an unfinished result but carries no "
                f"{PARTIAL_MARKER} marker, so this package did not make it; delete it yourself if it is not needed")
            continue
        pid = stale.name.rsplit(".partial-", 1)[1].split("-")[0]
        shutil.rmtree(stale, ignore_errors=True)
        removed.append(stale)
        log(f"note: removed {stale.name}, an unfinished result of an earlier run (process {pid}) that was killed")
    return removed


def remove_lock_file(path) -> None:
    """Delete a lock file this process holds or failed to fill (never leaves an empty lock behind)."""
    try:
        Path(path).unlink(missing_ok=True)
    except OSError:
        pass


class OutputDir:
    """An output folder reserved for one run: checked, locked, written beside, renamed into place.

    Use as a context manager around the whole run (before training)::

        with OutputDir("rec", overwrite=True, inputs=[recording]) as out:
            ... long work ...
            write files into out.staging
            out.commit()

    Leaving the block without :meth:`commit` (an error, Ctrl-C, SIGTERM, SIGHUP) removes
    everything the run created and leaves an existing folder as it was. ``note`` says afterwards,
    in words, what happened to the folder (for messages).
    """

    def __init__(self, out_dir, *, overwrite: bool = False, inputs=(), log=None, command: str = ""):
        self.given = given_output_path(out_dir)
        self.overwrite = true_or_false(overwrite, "overwrite")   # "no" is a true value: it replaced the folder
        check_log(log, none_ok=True)
        if not isinstance(command, str):   # it is written into the lock for a second run to read
            raise ArgumentTypeError(f"command= must be text (the command line, recorded in the lock), got {command!r}")
        self.inputs = tuple(inputs)
        self.log = log or (lambda message: None)
        self.command = command
        self.path = Path(os.path.abspath(self.given))
        self.staging: Path | None = None
        self.state = "new"           # new -> staged -> committed | aborted
        self.existed = os.path.lexists(self.path)
        self._lock = None
        self._lock_path = self.path.parent / f".{self.path.name}.lock"
        self._created: list[Path] = []

    # ---- opening -------------------------------------------------------------------------------
    def open(self) -> "OutputDir":
        from filelock import FileLock, Timeout

        check_output_path(self.given, overwrite=self.overwrite, inputs=self.inputs)
        with signals_deferred():
            self._make_parents()
            info = json.dumps({"pid": os.getpid(), "host": socket.gethostname(), "command": self.command,
                               "started": time.strftime("%Y-%m-%d %H:%M:%S")}).encode()

            def write_holder(fd):
                os.ftruncate(fd, 0)
                os.write(fd, info)

            existed = os.path.lexists(self._lock_path)
            try:
                lock = FileLock(self._lock_path, timeout=0, on_acquired=write_holder)
                lock.acquire()
            except Timeout:
                self._remove_created_parents()
                raise OutputError(f"the output folder {self.given} is being written by another run "
                                  f"({self._holder()}); wait for it to finish or choose another out_dir=") from None
            except OSError as err:   # e.g. no space left while writing the holder: no empty lock is left
                if not existed:
                    remove_lock_file(self._lock_path)
                self._remove_created_parents()
                raise OutputError(f"cannot lock the output folder {self.given} ({err.strerror}: {self._lock_path}); "
                                  "choose an out_dir= in a folder you can write") from None
            self._lock = lock
        try:
            self._recover()
            self.existed = os.path.lexists(self.path)
            check_output_path(self.given, overwrite=self.overwrite, inputs=self.inputs)  # again, under the lock
            with signals_deferred():
                tmp = self.path.parent / f".{self.path.name}.partial-{os.getpid()}-{secrets.token_hex(8)}"
                try:
                    tmp.mkdir()
                except OSError as err:
                    raise OutputError(f"cannot write the output folder {self.given} ({err.strerror}); choose an "
                                      "out_dir= in a folder you can write") from None
                self.staging = tmp
                try:
                    mark_partial(tmp, self.command)
                except OSError as err:
                    raise OutputError(f"cannot write the output folder {self.given} ({err.strerror}); choose an "
                                      "out_dir= in a folder you can write") from None
                self.state = "staged"
        except BaseException:
            self._cleanup()
            raise
        return self

    def _make_parents(self):
        missing = []
        p = self.path.parent
        while not os.path.lexists(p):
            missing.append(p)
            p = p.parent
        for p in reversed(missing):
            try:
                p.mkdir()
            except FileExistsError:
                continue
            except OSError as err:
                self._remove_created_parents()
                raise OutputError(f"cannot create {p} for the output folder {self.given} ({err.strerror}); choose "
                                  "another out_dir=") from None
            self._created.append(p)

    def _remove_created_parents(self):
        for p in reversed(self._created):
            try:
                p.rmdir()
            except OSError:
                break
        self._created = []

    def _holder(self) -> str:
        try:
            holder = json.loads(self._lock_path.read_text() or "{}")
        except (OSError, ValueError):
            return "its lock file could not be read"
        parts = [f"process {holder.get('pid', '?')} on {holder.get('host', '?')}",
                 f"started {holder.get('started', '?')}"]
        if holder.get("command"):
            parts.append(f"`{holder['command']}`")
        return ", ".join(parts)

    def _recover(self):
        """Under the lock: put back an old result left aside, remove partial folders of dead runs."""
        parent, name = self.path.parent, self.path.name
        for old in sorted(parent.glob(f".{name}.old-*")):
            if not os.path.lexists(self.path):
                os.rename(old, self.path)
                self.log(f"note: put back {self.path} from {old.name}, left aside by a replacement that was killed")
            else:
                shutil.rmtree(old, ignore_errors=True)
                self.log(f"note: removed {old.name}, an old result left aside by a replacement that was killed")
        remove_stale_partials(parent, name, log=self.log)   # the lock proves that their runs have ended

    # ---- closing -------------------------------------------------------------------------------
    def commit(self) -> Path:
        """Put the staging folder in place (renames only; the old result is deleted last)."""
        if self.state != "staged":
            raise RuntimeError(f"commit() on an output folder in state {self.state!r}")
        with signals_deferred():
            aside = None
            if os.path.lexists(self.path):
                if not (self.overwrite and self.path.is_dir() and not self.path.is_symlink()):
                    raise OutputError(f"{self.given} appeared while this run was working; the result was not "
                                      "written: choose another out_dir=")
                aside = self.path.parent / f".{self.path.name}.old-{os.getpid()}-{secrets.token_hex(8)}"
                os.rename(self.path, aside)
            (self.staging / PARTIAL_MARKER).unlink(missing_ok=True)   # a finished result carries no marker
            os.rename(self.staging, self.path)
            self.state = "committed"
            self.staging = None
            if aside is not None:
                shutil.rmtree(aside, ignore_errors=True)
                if os.path.lexists(aside):
                    self.log(f"warning: could not delete the old result, now {aside}; delete it by hand")
            self._release()
        return self.path

    def abort(self) -> None:
        with signals_deferred():
            if self.state == "staged":
                self.state = "aborted"
            self._cleanup()

    def _cleanup(self):
        if self.staging is not None:
            shutil.rmtree(self.staging, ignore_errors=True)
            self.staging = None
        self._release()
        self._remove_created_parents()

    def _release(self):
        if self._lock is not None:
            try:
                remove_lock_file(self._lock_path)   # while held: waiters see an unlinked inode and retry
            finally:
                self._lock.release()
                self._lock = None

    @property
    def note(self) -> str:
        """What happened to the folder, in words."""
        if self.state == "committed":
            return f"{self.given} was complete before that and is in place"
        if self.existed:
            return f"the existing {self.given} was left as it was"
        return f"{self.given} was not written"

    def __enter__(self) -> "OutputDir":
        return self.open()

    def __exit__(self, exc_type, exc, tb):
        if self.state != "committed":
            self.abort()
        if exc is not None:
            try:
                exc.output_note = self.note
            except AttributeError:
                pass
        return False


@contextmanager
def atomic_output_dir(out_dir, overwrite: bool = False, *, inputs=(), log=None):
    """Yield a temporary folder beside ``out_dir``; on success it replaces ``out_dir`` (see :class:`OutputDir`).

    On an exception (or Ctrl-C) the temporary folder is removed and ``out_dir`` is untouched.

    Raises:
        OutputError: ``out_dir`` exists and ``overwrite`` is False, or cannot be written (see
            :func:`check_output_path`).
    """
    with OutputDir(out_dir, overwrite=overwrite, inputs=inputs, log=log) as target:
        yield target.staging
        target.commit()


PNG_COMPRESS_LEVEL = 1   # zlib level (OpenCV's default): 3.6x faster than PIL's 6 at 1280x720, files 1.25x larger


def save_png(path, image) -> None:
    """Save a grey image [H, W] or an RGB image [H, W, 3] (float in [0, 1], clipped, or uint8) as an 8-bit PNG
    (lossless at any level)."""
    from ..core.checks import check_image_values
    from ..core.events import EventDataError

    image = np.asarray(image)
    if not (image.ndim == 2 or (image.ndim == 3 and image.shape[-1] in (3, 4))) or image.size == 0:
        raise EventDataError(f"save_png writes one image [H, W] (grey) or [H, W, 3] (RGB), got shape {image.shape}"
                             + ("; for a stack of frames use save_frames_png(folder, frames)" if image.ndim == 3 else ""))
    check_image_values(image, "the image to write", clipped=True)   # uint8, or finite floats in [0, 1]
    # the kit's one float -> uint8 mapping (round(255 x) in float64), as save_frames_png and the scores' CLAHE:
    # (x * 255 + 0.5) in the image's own float32 wrote other levels for some pixels than the frames/ PNGs
    Image.fromarray(to_uint8(image)).save(path, compress_level=PNG_COMPRESS_LEVEL)


class CloseOrAbort:
    """A writer used as a context manager: ``close()`` (finish, raising what went wrong) when the block
    ends normally, ``abort()`` (drop what is unfinished, raise nothing) when it raises. The kit's
    writers (PNGs, canonical files, log intensities) share this protocol, so a failure never leaves a
    file that looks complete."""

    def close(self) -> None:
        raise NotImplementedError

    def abort(self) -> None:
        raise NotImplementedError

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        if exc_type is None:
            self.close()
        else:
            self.abort()
        return False


class PngWriter(CloseOrAbort):
    """PNGs written on worker threads while the caller goes on computing (zlib releases the GIL: 40 frames of
    1280x720 took 0.68 s on two threads against 1.35 s in turn, ``python benchmarks/png_writer.py``).

        with PngWriter() as png:
            for i, frame in enumerate(frames):
                png.write(folder / f"frame_{i:05d}.png", frame)     # returns at once (a copy is queued)
        # here every file is written, or the first write's error was raised

    The files are the ones :func:`save_png` writes, byte for byte. At most ``2 x threads`` frames wait at
    once (``write`` blocks until one is done), so memory stays a few frames. Leaving the block on an
    exception or an interruption cancels the writes not yet started and waits for the running ones, so no
    thread writes into a folder its caller is about to remove (an :class:`OutputDir`'s staging folder).
    ``threads``: None (the kit's CPU threads, :func:`~evinr_lite.core.runtime.cpu_threads`) or a number
    (1 writes in turn on one worker).
    """

    def __init__(self, threads: int | None = None):
        from concurrent.futures import ThreadPoolExecutor

        from ..core.runtime import cpu_threads

        self.threads = max(1, int(threads or cpu_threads()))
        self._pool = ThreadPoolExecutor(self.threads, thread_name_prefix="evinr-png")
        self._pending = []

    def write(self, path, image) -> None:
        """Queue ``image`` (as :func:`save_png` takes it) for ``path``; an earlier write's error is raised here."""
        waiting = []
        for f in self._pending:
            if f.done():
                f.result()                      # a finished write's error is raised here
            else:
                waiting.append(f)
        self._pending = waiting
        while len(self._pending) >= 2 * self.threads:
            self._pending.pop(0).result()
        self._pending.append(self._pool.submit(save_png, path, np.array(image, copy=True)))

    def close(self) -> None:
        """Wait for every queued write; raises the first one's error (the others are still waited for)."""
        try:
            for f in self._pending:
                f.result()
        finally:
            self._pending = []
            self._pool.shutdown(wait=True)

    def abort(self) -> None:
        """Drop the writes not yet started and wait for the running ones (their errors are not raised)."""
        self._pool.shutdown(wait=True, cancel_futures=True)
        self._pending = []



@contextmanager
def written_beside(path):
    """A temporary name beside ``path`` to write to (hidden, unique, with the same suffix: writers pick the
    format by it); renamed onto ``path`` when the block ends, removed when it fails, so ``path`` is never
    half-written (an interrupted or failed write leaves the file that was there, or none)."""
    check_path_type(path, "path", "the file to write")   # None was Python's "expected str, bytes or os.PathLike"
    path = Path(path)
    if not path.name:   # "" or "/": no name to write beside (pathlib's "has an empty name")
        raise OutputError(f"path= {str(path)!r} names no file; pass the file to write (e.g. out/run.json)")
    tmp = path.with_name(f".{path.stem}.partial-{os.getpid()}-{secrets.token_hex(4)}{path.suffix}")
    try:
        yield tmp
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def save_json(path, obj) -> None:
    """``obj`` as indented JSON text in the file ``path``. The text is made before the file is opened, so an object
    JSON cannot hold (a numpy number, a tensor, a Path) leaves no half-written file; that is an ArgumentTypeError
    naming the fix (``apps.results.jsonable`` makes numpy values and tuples plain), and a folder that cannot be written
    an OutputError. ``path``: a str, a Path or bytes (as ``open`` takes them); None or a number is refused."""
    if not isinstance(path, bytes):   # bytes paths are os.open's and were written before: taken as they were
        check_path_type(path, "path", "the JSON file to write")   # 5 was written to file descriptor 5
    try:
        text = json.dumps(obj, indent=2) + "\n"
    except (TypeError, ValueError) as err:   # the file had been opened and half written
        raise ArgumentTypeError(f"cannot write {path} as JSON: {err}; make the values plain Python numbers, text, lists "
                             "and dicts first (e.g. float(x), x.tolist(), str(path))") from None
    try:
        with open(path, "w") as f:
            f.write(text)
    except (IsADirectoryError, FileNotFoundError, NotADirectoryError, PermissionError) as err:
        raise OutputError(f"cannot write {path}: {err.strerror}; choose a file in a folder that exists and can be "
                          "written") from None
