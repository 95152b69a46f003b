"""data_fetch's canonical writer: :class:`evinr_lite.io.canonical.CanonicalWriter` (which owns the layout)
raising data_fetch's :class:`~data_fetch.errors.ConversionError`."""
from __future__ import annotations

from evinr_lite.io import canonical

from .errors import ConversionError

__all__ = ["CanonicalWriter"]


class CanonicalWriter(canonical.CanonicalWriter):
    """:class:`evinr_lite.io.canonical.CanonicalWriter` whose problems are ``ConversionError``."""

    error = ConversionError
