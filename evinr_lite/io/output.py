"""Writing results so that nothing is ever half-written: everything goes to a temporary folder
that is renamed into place only when complete."""
from __future__ import annotations

import json
import os
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path

import numpy as np
from PIL import Image

__all__ = ["atomic_output_dir", "save_png", "save_json"]


@contextmanager
def atomic_output_dir(out_dir, overwrite: bool = False):
    """Yield a temporary folder beside ``out_dir``; on success it replaces ``out_dir``.

    On an exception (or Ctrl-C) the temporary folder is removed and ``out_dir`` is untouched.

    Raises:
        FileExistsError: ``out_dir`` exists and ``overwrite`` is False.
    """
    out_dir = Path(out_dir)
    if out_dir.exists() and not overwrite:
        raise FileExistsError(f"output folder {out_dir} already exists; choose another out_dir= or pass overwrite=True")
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.partial-", dir=out_dir.parent))
    try:
        yield tmp
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    if out_dir.exists():
        shutil.rmtree(out_dir)
    os.replace(tmp, out_dir)


def save_png(path, image) -> None:
    """Save a grey image [H, W] (float in [0, 1] or uint8) as an 8-bit PNG."""
    image = np.asarray(image)
    if image.dtype != np.uint8:
        image = (np.clip(image, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)
    Image.fromarray(image).save(path)


def save_json(path, obj) -> None:
    with open(path, "w") as f:
        json.dump(obj, f, indent=2)
        f.write("\n")
