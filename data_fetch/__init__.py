"""data_fetch: download and convert real event datasets (IJRR, HQF, CED, MVSEC, AED) into one format.

Only the cache location lives here so far; the downloaders and converters arrive with the
real-data issue. Everything it produces is read by ``evinr_lite``'s readers.
"""
from __future__ import annotations

import os
from pathlib import Path

__all__ = ["cache_dir"]

ENV_VAR = "EVINR_DATA"


def cache_dir() -> Path:
    """Folder for downloads and converted sequences: ``$EVINR_DATA`` or ``~/.cache/evinr-lite``."""
    path = Path(os.environ.get(ENV_VAR) or Path.home() / ".cache" / "evinr-lite")
    return path.expanduser()
