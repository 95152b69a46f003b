"""The kit's canonical HDF5 file (what ``data_fetch`` converts every dataset to).

Its layout, reader, writer and windowed source live in :mod:`evinr_lite.io.canonical` (the reader
and the writer side by side); this module declares it to the registry. A window is found through
the stored (and checked) time index, and only its events are read.
"""
from __future__ import annotations

from ..canonical import CanonicalSource, is_canonical, read_canonical
from .base import FileFormat

__all__ = ["FORMAT"]


def _sniff(path, head) -> bool:
    return head is not None and head.startswith(b"\x89HDF\r\n\x1a\n") and is_canonical(path)


FORMAT = FileFormat(
    name="canonical", description="a data_fetch canonical .h5 file", reader=read_canonical,
    suffixes=(".h5", ".hdf5"), sniff=_sniff, time_unit="s", windowed=True, open_source=CanonicalSource,
    options=("frames",), priority=10)
