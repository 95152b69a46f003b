"""Downloads: resumable HTTP into the cache (pooch + a Range-aware downloader), and Google Drive (gdown).

Who does what:
- pooch (``pooch.retrieve``) owns the cache logic: it skips files already present, downloads into
  a temporary file beside the target, verifies the pinned checksum (sha256 or md5), and only then
  moves the file into place (an atomic rename on one file system); a file that fails the check is
  deleted. With no pinned checksum it logs the file's sha256 so that it can be pinned.
- :class:`ResumableDownloader` (here) is the HTTP part that pooch calls. pooch's own HTTP
  downloader restarts from zero after an interruption, which is costly for multi-GB bags, so this
  one keeps the bytes in ``<file>.part`` and continues with an HTTP ``Range`` request, both within a
  call (a dropped connection is retried) and across calls (an interrupted command run again).
- gdown lists the public HQF Drive folder and downloads one file from it (with resume).

Every failure raises :class:`~data_fetch.errors.DownloadError` or ``ChecksumError`` with what could
not be reached and where to place the file by hand.
"""
from __future__ import annotations

import json
import logging
import os
import re
import time
from pathlib import Path

from .errors import ChecksumError, DataFetchError, DownloadError

__all__ = ["fetch_url", "fetch_gdrive_file", "ResumableDownloader", "file_hash"]

log = logging.getLogger("data_fetch")
BLOCK = 1 << 16      # bytes per read: at most this much is lost (and fetched again) when a transfer drops
BACKOFF_S = 1.0      # seconds before retry k is k * BACKOFF_S (tests set it to 0)


def _place_by_hand(url: str, dest: Path, homepage: str | None) -> str:
    where = f" (see {homepage})" if homepage else ""
    return (f"To place it by hand: download {url}{where} on a machine with internet access and copy it to "
            f"{dest} (exactly this path; set the cache folder with the EVINR_DATA environment variable), "
            "then run the same command again.")


class _Incomplete(Exception):
    pass


def _content_range(value: str | None) -> tuple[int | None, int | None]:
    """'bytes 100-199/1000' -> (100, 1000); 'bytes */1000' -> (None, 1000)."""
    m = re.match(r"bytes\s+(\d+|\*)(?:-\d+)?/(\d+|\*)", value or "")
    if not m:
        return None, None
    start = None if m.group(1) == "*" else int(m.group(1))
    total = None if m.group(2) == "*" else int(m.group(2))
    return start, total


class ResumableDownloader:
    """A pooch downloader that resumes from ``part_path`` with HTTP Range requests.

    Args:
        part_path: where the received bytes are kept between attempts (``<file>.part``).
        progress: show a tqdm progress bar.
        retries: how many times a dropped connection is resumed within one call.
        timeout: requests timeout (connect, read) in seconds.
        backoff: seconds to wait before retry k (times k).
    """

    def __init__(self, part_path, *, progress: bool = True, retries: int = 3,
                 timeout=(15, 60), backoff: float | None = None):
        self.part = Path(part_path)
        self.progress = progress
        self.retries = retries
        self.timeout = timeout
        self.backoff = BACKOFF_S if backoff is None else backoff
        self.requests_made: list[dict] = []  # (for tests and logs) the Range header of each request

    def _bar(self, total, initial, name):
        from tqdm.auto import tqdm

        return tqdm(total=total, initial=initial, unit="B", unit_scale=True, unit_divisor=1024,
                    desc=name, disable=not self.progress, leave=True)

    def _attempt(self, url: str) -> None:
        import requests

        offset = self.part.stat().st_size if self.part.exists() else 0
        headers = {"Range": f"bytes={offset}-"} if offset else {}
        self.requests_made.append(dict(headers))
        with requests.get(url, headers=headers, stream=True, timeout=self.timeout) as r:
            if r.status_code == 416 and offset:
                _, total = _content_range(r.headers.get("Content-Range"))
                if total == offset:
                    return  # the part file is already complete
                log.warning("data_fetch: %s: the server refused to resume at byte %d; starting again", url, offset)
                self.part.unlink()
                raise _Incomplete("range not satisfiable")
            if r.status_code >= 400:
                reason = f"{r.status_code} {r.reason}" if r.reason else str(r.status_code)
                why = (" (the name is wrong or the file has moved)" if r.status_code in (404, 410) else
                       " (access refused)" if r.status_code in (401, 403) else "")
                raise DownloadError(f"the server answered {reason} for {url}{why}")
            if r.status_code == 206:
                start, total = _content_range(r.headers.get("Content-Range"))
                if start != offset:
                    self.part.unlink()
                    raise _Incomplete(f"the server resumed at byte {start}, not {offset}")
                mode = "ab"
            else:
                if offset:
                    log.warning("data_fetch: %s: the server does not resume downloads; starting again", url)
                offset, mode = 0, "wb"
                length = r.headers.get("Content-Length")
                total = int(length) if length and length.isdigit() else None
            with open(self.part, mode) as out, self._bar(total, offset, self.part.name[:-5]) as bar:
                for block in r.iter_content(BLOCK):
                    out.write(block)
                    bar.update(len(block))
            size = self.part.stat().st_size
            if total is not None and size != total:
                if size > total:
                    self.part.unlink()
                raise _Incomplete(f"received {size} of {total} bytes")

    def __call__(self, url: str, output_file: str, pooch=None, check_only: bool = False):
        import requests

        if check_only:
            try:
                return requests.head(url, timeout=self.timeout, allow_redirects=True).status_code < 400
            except requests.exceptions.RequestException:
                return False
        self.part.parent.mkdir(parents=True, exist_ok=True)
        attempt = 0
        while True:
            try:
                self._attempt(url)
                break
            except (requests.exceptions.ConnectionError, requests.exceptions.Timeout,
                    requests.exceptions.ChunkedEncodingError, _Incomplete) as err:
                attempt += 1
                have = self.part.stat().st_size if self.part.exists() else 0
                never_reached = isinstance(err, requests.exceptions.ConnectionError) and have == 0 \
                    and not isinstance(err, requests.exceptions.ChunkedEncodingError)
                if never_reached and attempt > min(self.retries, 1):
                    raise DownloadError(f"could not reach {url} ({type(err).__name__}: {err}); "
                                        "this machine may be offline or the server may be down") from None
                if attempt > self.retries:
                    raise DownloadError(
                        f"the download of {url} was interrupted {attempt} times ({err}); {have} bytes are kept "
                        f"in {self.part}: run the same command again to resume from there") from None
                if never_reached:
                    log.warning("data_fetch: could not connect to %s (%s); trying once more", url, err)
                else:
                    log.warning("data_fetch: %s: connection lost after %d bytes (%s); resuming (%d/%d)",
                                url, have, err, attempt, self.retries)
                time.sleep(self.backoff * attempt)
        os.replace(self.part, output_file)  # pooch checks the hash, then renames into the cache


def file_hash(path, alg: str = "sha256") -> str:
    """Hex digest of a file (read in 1 MiB blocks)."""
    import hashlib

    h = hashlib.new(alg)
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(BLOCK), b""):
            h.update(block)
    return h.hexdigest()


def _already_here(dest: Path, known_hash) -> bool:
    """Make dest's folder; True when dest is already there (and matches known_hash, if given)."""
    dest.parent.mkdir(parents=True, exist_ok=True)
    if not dest.exists():
        return False
    if known_hash:
        _check_existing(dest, known_hash)
    return True


def _check_existing(dest: Path, known_hash: str) -> None:
    alg, _, expected = known_hash.rpartition(":")
    alg = alg or "sha256"
    got = file_hash(dest, alg)
    if got != expected.lower():
        raise ChecksumError(
            f"{dest} is already there but its {alg} is {got}, not the pinned {expected}: it is damaged, "
            "incomplete or a different file. Delete it and run the command again to download it anew "
            "(or pass verify=False / --no-verify if you are sure it is the right file).")


def _lock(dest: Path):
    from filelock import FileLock, Timeout

    locks = dest.parent / ".locks"  # kept apart so that the data folder holds only data
    locks.mkdir(exist_ok=True)
    lock = FileLock(str(locks / (dest.name + ".lock")))
    try:
        lock.acquire(timeout=0)
    except Timeout:
        raise DataFetchError(f"another process is downloading {dest} (it holds {lock.lock_file}); wait for it "
                             "to finish, then run the command again") from None
    return lock


def fetch_url(url: str, dest, *, known_hash: str | None = None, progress: bool = True,
              retries: int = 3, timeout=(15, 60), backoff: float | None = None,
              homepage: str | None = None) -> Path:
    """Download ``url`` to ``dest`` (resumable, verified, atomic) unless it is already there.

    Args:
        url: http(s) address.
        dest: final path of the file (its folder is created).
        known_hash: pinned checksum, "sha256:<hex>" or "md5:<hex>" (a bare hex string is sha256);
            None: not verified (pooch logs the sha256 to pin).
        progress: tqdm progress bar.
        retries: resumptions of a dropped connection within this call.
        homepage: named in error messages (where to get the file by hand).

    Returns:
        ``dest``.

    Raises:
        DownloadError: unreachable, HTTP error (e.g. 404), interrupted too often (the ``.part``
            file is kept for the next call). ChecksumError: wrong checksum (nothing is left in
            the cache: the next call downloads again).
    """
    import pooch

    dest = Path(dest)
    if _already_here(dest, known_hash):
        return dest
    lock = _lock(dest)
    try:
        downloader = ResumableDownloader(dest.with_name(dest.name + ".part"), progress=progress,
                                         retries=retries, timeout=timeout, backoff=backoff)
        pooch.get_logger().setLevel(logging.WARNING)   # its messages speak of pooch's API; ours follow
        if progress:
            log.info("data_fetch: downloading %s to %s", url, dest)
        try:
            pooch.retrieve(url, known_hash=known_hash, fname=dest.name, path=dest.parent, downloader=downloader)
        except DownloadError as err:
            raise DownloadError(f"{err}. {_place_by_hand(url, dest, homepage)}") from None
        except ValueError as err:
            if "hash" not in str(err).lower():
                raise
            raise ChecksumError(
                f"{url}: the downloaded file does not match its pinned checksum and was deleted ({err}). "
                "Run the command again (a transfer error); if it keeps failing the file on the server has "
                f"changed: report it, or pass verify=False / --no-verify to accept it. "
                f"{_place_by_hand(url, dest, homepage)}") from None
    finally:
        lock.release()
    if not known_hash and progress and log.isEnabledFor(logging.INFO):
        log.info("data_fetch: %s has sha256 %s (no checksum is published for it: nothing to verify against)",
                 dest.name, file_hash(dest))
    return dest


def _drive_listing(folder_url: str, cache_file: Path, progress: bool, refresh: bool = False) -> tuple[dict, bool]:
    """({file name: Drive file id}, fresh) of a public Drive folder (gdown), cached in ``cache_file``."""
    if cache_file.exists() and not refresh:
        try:
            return json.loads(cache_file.read_text()), False
        except ValueError:
            cache_file.unlink()
    import gdown

    try:
        files = gdown.download_folder(url=folder_url, skip_download=True, quiet=not progress)
    except Exception as err:  # gdown raises requests errors, its own errors, or ValueError
        raise DownloadError(f"could not list the Google Drive folder {folder_url} with gdown "
                            f"({type(err).__name__}: {err})") from None
    listing = {Path(f.path).name: f.id for f in files or []}
    if not listing:
        raise DownloadError(f"gdown found no files in the Google Drive folder {folder_url}")
    tmp = cache_file.with_name(cache_file.name + ".tmp")
    tmp.write_text(json.dumps(listing, indent=1, sort_keys=True))
    os.replace(tmp, cache_file)
    return listing, True


def fetch_gdrive_file(folder_url: str, filename: str, dest, *, progress: bool = True,
                      known_hash: str | None = None) -> Path:
    """Download ``filename`` from a public Google Drive folder to ``dest`` with gdown (resumable).

    The folder listing is cached beside ``dest`` (``.drive_listing.json``, listed again when a file
    is missing from it); gdown keeps partial downloads in a temporary file beside ``dest`` and
    resumes from it on the next call.
    """
    dest = Path(dest)
    if _already_here(dest, known_hash):
        return dest
    hint = (f"To place it by hand: open {folder_url} in a browser, download {filename} and copy it to "
            f"{dest} (exactly this path; set the cache folder with the EVINR_DATA environment variable), "
            "then run the same command again.")
    lock = _lock(dest)
    try:
        listing_file = dest.parent / ".drive_listing.json"
        try:
            listing, fresh = _drive_listing(folder_url, listing_file, progress)
            if filename not in listing and not fresh:
                listing, fresh = _drive_listing(folder_url, listing_file, progress, refresh=True)
        except DownloadError as err:
            raise DownloadError(f"{err}. {hint}") from None
        if filename not in listing:
            raise DownloadError(f"{filename} is not in the Google Drive folder {folder_url} (it holds "
                                f"{', '.join(sorted(listing))}). {hint}")
        import gdown

        if progress:
            log.info("data_fetch: downloading %s from %s to %s (gdown)", filename, folder_url, dest)
        try:
            out = gdown.download(id=listing[filename], output=str(dest), quiet=not progress, resume=True, retries=3)
        except Exception as err:
            raise DownloadError(f"gdown could not download {filename} from {folder_url} "
                                f"({type(err).__name__}: {err}); a partial file beside {dest} is resumed "
                                f"next time. {hint}") from None
        if not out or not dest.exists():
            raise DownloadError(f"gdown did not produce {dest} (Drive may limit downloads of large files "
                                f"for a while). {hint}")
        if known_hash:
            try:
                _check_existing(dest, known_hash)
            except ChecksumError:
                dest.unlink()
                raise
    finally:
        lock.release()
    return dest
