"""A simulated colour DAVIS (e.g. the Color DAVIS346 of CED): a 2 x 2 Bayer filter over the events
and debayered colour APS frames, as a :class:`~evinr_lite.core.recording.Recording` or a canonical file.

    rec = colour_davis_recording("coffee", sensor_size=(48, 64), duration=0.5)
    rec.meta["cfa"]            # "RGGB": the colours of photosites (0, 0), (0, 1), (1, 0), (1, 1)
    rec.events                 # colour events at the photosites, (H, W)
    rec.frames                 # grey APS frames [F, H, W] uint8 (ITU-R 709 of the colour ones)
    rec.meta["frames_rgb"]     # colour APS frames [F, H, W, 3] uint8, as a camera's debayered topic

The scene is a :class:`~evinr_lite.sim.quadbayer.QuadBayerScene` with ``block=1`` (the plain Bayer
tile R G / G B; ``phase`` from the filter name), so each photosite fires on its own channel's log
intensity. The APS frames are the scene's colour intensity at every photosite (what a perfect
debayering of the APS mosaic gives), 8-bit. Split the events with
``quadbayer.demosaic_events_rgb(events, cfa_phase(cfa), block=1)``: each channel's events then carry
``effective_thresholds(C, block=1)`` = C, C/2, C for R, G, B on the (H/2, W/2) grid.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..core.checks import check_path_type, real_number, true_or_false
from ..core.events import EventDataError
from ..core.frames import Frames, to_grey_uint8
from ..core.recording import Recording
from ..io.canonical import CFA_NAMES, CanonicalWriter, cfa_phase, check_cfa
from .quadbayer import BAYER, QuadBayerScene
from .simulate import simulate_scene

__all__ = ["colour_davis_recording", "write_colour_davis_recording"]


def colour_davis_recording(image="coffee", *, sensor_size=(48, 64), duration: float = 0.5, C: float = 0.2,
                           frame_rate: float = 20.0, cfa: str = "RGGB", seed: int = 0,
                           **motion) -> Recording:
    """Colour events and colour APS frames of an RGB image moving in front of a 2 x 2 Bayer sensor.

    Args:
        image: a scikit-image colour sample name ("coffee", "astronaut", "chelsea") or [h, w, 3].
        sensor_size: (H, W) photosites, even. duration: seconds. C: contrast threshold (log units).
        frame_rate: APS frames per second (the first at t = 0).
        cfa: the filter ("RGGB", "GRBG", "GBRG", "BGGR"). seed: the simulator's noise.
        **motion: velocity, rotation, zoom, ... of :class:`~evinr_lite.sim.scenes.MovingImageScene`.
    Returns:
        Recording(events on (H, W), grey Frames uint8 [F, H, W], meta) with meta["cfa"],
        meta["frames_rgb"] (uint8 [F, H, W, 3]), meta["frames_rgb_t"] (= frames.t), meta["C"] and
        meta["format"] = "simulated".
    """
    cfa = check_cfa(cfa)
    if cfa is None:
        raise EventDataError(f"cfa must name a colour filter ({', '.join(CFA_NAMES)}), got None")
    frame_rate = real_number(frame_rate, "frame_rate", lo=0, lo_open=True, hint="APS frames per second (e.g. 20)")
    scene = QuadBayerScene(image, sensor_size, duration, phase=cfa_phase(cfa), block=BAYER, **motion)
    events = simulate_scene(scene, 0.0, duration, C=C, seed=seed)
    t = np.arange(0.0, duration + 1e-9, 1.0 / frame_rate)
    rgb = np.round(np.clip(np.exp(scene.rgb_log_intensity(t)), 0.0, 1.0) * 255.0).astype(np.uint8)
    grey = np.stack([to_grey_uint8(im, "simulated frame") for im in rgb])
    meta = {"format": "simulated", "path": None, "cfa": cfa, "frames_rgb": rgb, "frames_rgb_t": t.copy(),
            "C": float(C), "scene": repr(scene)}
    return Recording(events, Frames(grey, t), meta)


def write_colour_davis_recording(out, image="coffee", *, overwrite: bool = False, **kwargs) -> Path:
    """:func:`colour_davis_recording` written as a canonical ``.h5`` (with its ``cfa`` attribute and
    /frames/rgb), atomically (written beside and renamed). ``kwargs`` as colour_davis_recording.
    Returns the path."""
    out = Path(check_path_type(out, "out", "the .h5 file to write"))
    overwrite = true_or_false(overwrite, "overwrite")   # "no" replaced an existing file
    if out.exists() and not overwrite:
        raise EventDataError(f"{out} already exists; choose another path or pass overwrite=True")
    rec = colour_davis_recording(image, **kwargs)
    ev = rec.events
    with CanonicalWriter(out, sensor_size=ev.sensor_size, dataset="simulated", sequence=out.stem,
                         source="evinr_lite.sim.colour_davis", C=rec.meta["C"], converter="colour_davis",
                         cfa=rec.meta["cfa"], meta={"scene": rec.meta["scene"]}) as w:
        w.add_events(ev.t, ev.x, ev.y, ev.p)
        for im, t in zip(rec.meta["frames_rgb"], rec.frames.t):
            w.add_frame(im, float(t))
    return out
