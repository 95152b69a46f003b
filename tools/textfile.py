"""Writing a text file the safe way, for the tools that rewrite docs and notebooks."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path


def write_beside(path, text: str) -> None:
    """Write ``text`` to a temporary file beside ``path``, then rename it into place: a reader never
    sees half a file, and a failed write leaves the old one (and no temporary file) behind."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise
