"""Find the small real recording that ships beside the project, for notebooks and tests that run offline.

The one finder of shared data: :func:`evinr_lite.sim.recordings.find_recording` (notebook 11) and
the ablations use it, and a synthetic stand-in lives in :mod:`evinr_lite.sim.recordings`.

The project is developed with a ``shared/`` folder next to the repository
(``shared/data/ijrr_slider_depth_chunk``: 0.17 s of IJRR slider_depth with its APS frames).
Set ``EVINR_SHARED_DATA`` to point at another ``data`` folder.
"""
from __future__ import annotations

import os
from pathlib import Path


__all__ = ["find_shared_data", "sample_recording_path", "SLIDER_DEPTH_CHUNK", "ENV_VAR"]

ENV_VAR = "EVINR_SHARED_DATA"
SLIDER_DEPTH_CHUNK = "ijrr_slider_depth_chunk"


def find_shared_data(start=None) -> Path | None:
    """The ``shared/data`` folder: ``$EVINR_SHARED_DATA``, else the first ``shared/data`` found walking up
    from ``start`` (default: the current folder) or from this package. None when there is none."""
    env = os.environ.get(ENV_VAR)
    if env:
        path = Path(env).expanduser()
        return path if path.is_dir() else None
    starts = [Path(start) if start is not None else Path.cwd(), Path(__file__).resolve().parent]
    for base in starts:
        for folder in [base.resolve(), *base.resolve().parents]:
            candidate = folder / "shared" / "data"
            if candidate.is_dir():
                return candidate
    return None


def sample_recording_path(name: str = SLIDER_DEPTH_CHUNK, start=None) -> Path | None:
    """Path of a recording inside the shared data folder (default: the slider_depth chunk), or None."""
    data = find_shared_data(start)
    if data is None or not (data / name).exists():
        return None
    return data / name
