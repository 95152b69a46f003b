"""Errors of data_fetch. Every message names the problem and the fix (often a path to place a file at)."""
from __future__ import annotations

__all__ = ["DataFetchError", "DownloadError", "ChecksumError", "ConversionError", "NotDownloadable"]


class DataFetchError(RuntimeError):
    """Base class: something data_fetch could not do. The message says what and how to fix it."""


class DownloadError(DataFetchError):
    """A source could not be reached or answered with an error (404, refused, offline)."""


class ChecksumError(DataFetchError):
    """A downloaded file does not match its pinned checksum (the file was deleted)."""


class ConversionError(DataFetchError):
    """A raw file is damaged, truncated or not in the expected format."""


class NotDownloadable(DataFetchError):
    """The dataset is not publicly downloadable: the user must place the files by hand."""
