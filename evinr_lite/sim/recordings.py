"""Synthetic recordings on disk, for examples, tests and notebooks that run without real data.

- :func:`write_example_recording`: a moving image's events and frames as an IJRR-style folder;
- :func:`synthetic_recording`: the same, read back as a :class:`~evinr_lite.core.recording.Recording`;
- :func:`find_recording`: the recording to work on: yours, the shared real chunk, or a synthetic one.
"""
from __future__ import annotations

import json
import tempfile
from pathlib import Path

import numpy as np

from ..core.checks import blank_path, check_path_type, real_number, whole_number
from ..core.events import EventDataError
from ..io.output import atomic_output_dir, save_png
from ..io.readers import read_recording
from ..io.sample_data import ENV_VAR as SHARED_ENV_VAR
from ..io.sample_data import SLIDER_DEPTH_CHUNK, sample_recording_path
from .scenes import make_scene
from .simulate import simulate_scene

__all__ = ["write_example_recording", "synthetic_recording", "find_recording"]


def write_example_recording(folder, *, scene: str = "camera", sensor_size=(60, 80), duration: float = 0.5,
                            C: float = 0.25, frame_rate: float = 20.0, seed: int = 0) -> Path:
    """Write a synthetic recording as an IJRR-style folder (events.txt, images.txt, images/).

    Events are simulated from a moving image (:func:`evinr_lite.sim.simulate.simulate_scene`) with
    contrast threshold C; frames are the scene's linear intensity (like a camera's APS frames,
    about [0.05, 1] -> uint8) at ``frame_rate`` per second. The folder is written atomically.
    Returns the folder's path.
    """
    # before any work: 0 was a ZeroDivisionError, -1 a recording without frames, NaN numpy's arange error
    frame_rate = real_number(frame_rate, "frame_rate", lo=0, lo_open=True, hint="APS frames per second (e.g. 20)")
    sc = make_scene(scene, sensor_size=sensor_size, duration=duration)
    events = simulate_scene(sc, 0.0, duration, C=C, seed=seed)
    frame_t = np.arange(0.0, duration + 1e-9, 1.0 / frame_rate)
    intensity = np.exp(sc.log_intensity(frame_t))
    with atomic_output_dir(folder, overwrite=False) as tmp:
        (tmp / "images").mkdir()
        with open(tmp / "images.txt", "w") as f:
            for i, (t, img) in enumerate(zip(frame_t, intensity)):
                save_png(tmp / "images" / f"frame_{i:08d}.png", np.clip(img, 0.0, 1.0))
                f.write(f"{t:.9f} images/frame_{i:08d}.png\n")
        columns = np.stack([events.t, events.x, events.y, (events.p > 0).astype(np.int64)], axis=1)
        np.savetxt(tmp / "events.txt", columns, fmt=["%.9f", "%d", "%d", "%d"])
        (tmp / "simulation.json").write_text(json.dumps({"scene": scene, "sensor_size": list(sensor_size), "C": C,
                                                   "duration_s": duration, "frame_rate": frame_rate,
                                                   "seed": seed}, indent=2) + "\n")
    return Path(folder)


def synthetic_recording(sensor_size=(90, 120), duration: float = 0.5, n_frames: int = 6, C: float = 0.2,
                        seed: int = 0):
    """A stand-in Recording when no real data is around: the 'camera' scene's events and ``n_frames``
    ground-truth frames spread over ``duration`` seconds (written and read back as an IJRR folder by
    :func:`write_example_recording`)."""
    # the first frame at 0 and the last at duration: 1 frame was a ZeroDivisionError, 2.5 frames two
    n_frames = whole_number(n_frames, "n_frames", lo=2)
    # the frame rate is derived from it: a bad duration would be blamed on a frame_rate nobody passed
    duration = real_number(duration, "duration", lo=0, lo_open=True, hint="seconds (e.g. 0.5)")
    with tempfile.TemporaryDirectory() as tmp:
        folder = write_example_recording(Path(tmp) / "synthetic", sensor_size=sensor_size, duration=duration, C=C,
                                         frame_rate=(n_frames - 1) / duration, seed=seed)
        return read_recording(folder)


def find_recording(path=None, scratch=None, *, start=None) -> tuple[Path, str]:
    """The recording to work on, and where it came from.

    In order: ``path`` if given; the real IJRR chunk ``ijrr_slider_depth_chunk`` in the shared data
    folder (:func:`evinr_lite.io.sample_data.find_shared_data`: ``$EVINR_SHARED_DATA``, else
    ``shared/data`` found walking up from ``start``, default the current folder); else a synthetic
    recording (IJRR layout, with frames) written into ``scratch``.
    """
    if path is not None:
        check_path_type(path, "path", "a recording (a file or a folder)", "or None to find one")
        if blank_path(path):   # "" was the current folder, "given" (Path(".") names it on purpose)
            raise EventDataError(f"path= is empty ({path!r}, blank text, which paths read as the current folder): pass the recording's path (Path.cwd() for the "
                                 "current folder), or None to find one")
        path = Path(path)
        if not path.exists():
            raise EventDataError(f"no such recording: {path}; check the path")
        return path, "given"
    for name, value in (("scratch", scratch), ("start", start)):
        if value is not None:   # a number was Python's "expected str, bytes or os.PathLike object" (or never looked at)
            check_path_type(value, name, "a folder", "or None")
    shared = sample_recording_path(SLIDER_DEPTH_CHUNK, start=start)
    if shared is not None and (shared / "events.txt").exists():
        return shared, "the shared IJRR slider_depth chunk"
    if scratch is None:
        raise EventDataError(f"no recording found: pass a path, set {SHARED_ENV_VAR} to a data folder holding "
                             f"{SLIDER_DEPTH_CHUNK}, or give a scratch folder for a synthetic one")
    target = Path(scratch) / "synthetic_recording"
    if not target.exists():
        write_example_recording(target, sensor_size=(90, 120), duration=0.5, C=0.25, frame_rate=25.0, seed=0)
    return target, "a synthetic recording (moving 'camera' image, C = 0.25)"
