"""The static image's coarse structure from the integrated events (``EvINRConfig.offset_coarse_px``).

Events never fix a pixel's offset, so the solver picks the static image, the one image added to
every frame, as the one that makes the frames' gradients sparsest (:mod:`evinr_lite.method.offset`).
That solve reads the static image best from the integrated events' staircase: each pixel stays
exactly constant until a threshold is crossed, sparse in time as its prior assumes. From the INR's
smooth frames it recovers less of it: on camera_translate the least-squares gain from the solved
static image to the truth's is 0.89 from the integrated events and 0.71 from the kit's frames
(docs/defaults.md). The integrated events carry their noise at fine scales, where the INR's frames
are clean. So :func:`coarse_correction` gives the static image its spatial frequencies below
``coarse_px`` from the integrated events and keeps the finer ones, and every change in time, from
the INR:

    correction = lowpass( mean_t(I) + offset(I) - mean_t(F) ),

with I the events integrated at G times over the span and F the INR's frames there with their own
offset. Integration drifts as the span grows (noise, threshold mismatch and drift): on spans longer
than ``MAX_SPAN_S`` the INR's static image was the better one on every recording measured (drift_clock,
8 s, and the 20 s and 60 s recordings; docs/defaults.md), so the correction is applied only up to it.
"""
from __future__ import annotations

import numpy as np

from ..core.checks import checked_span, require, seconds_array
from ..core.events import EventDataError
from .binning import events_to_frames_chunked
from .config import EvINRConfig
from .offset import gaussian_lowpass, gaussian_lowpass_unchecked, offset_image

__all__ = ["gaussian_lowpass", "coarse_correction", "coarse_applies", "coarse_times", "integrated_frames", "MAX_SPAN_S"]

FRAMES = 32          # the integrated events are solved at every other time of the 64-frame offset grid: half the
                     # L1 solve's time, the same zoo mean as all 64 (16 cost camera_240x180's MSE 0.0114 -> 0.0117)
MAX_SPAN_S = 3.0     # seconds: longer spans keep the INR's static image (integration drifts; docs/defaults.md)


def coarse_applies(config, t_start: float, t_end: float) -> bool:
    """Whether :func:`coarse_correction` is part of a reconstruction of [t_start, t_end] (s) with ``config``:
    an offset solve, ``offset_coarse_px`` set, and a span of at most ``MAX_SPAN_S``."""
    require(config, EvINRConfig, "coarse_applies: config")   # None was "has no attribute 'offset_solve'"
    t_start, t_end = checked_span(t_start, t_end, "coarse_applies")   # NaN was False, a reversed span True
    return (config.offset_solve != "none" and config.offset_coarse_px is not None
            and t_end - t_start <= MAX_SPAN_S + 1e-9)


def coarse_times(times) -> np.ndarray:
    """The times (float64 [G'], s) of the offset grid ``times`` [G] at which the events are integrated: about
    ``FRAMES`` of them, evenly spread (every other one of a 64-frame grid)."""
    t = _grid_times(times, allow_empty=True)
    return t[::max(1, len(t) // FRAMES)]


def _grid_times(times, *, allow_empty: bool = False) -> np.ndarray:
    """The offset grid's times: finite, increasing seconds [G] (a 0-d array was "len() of unsized object", a 2-D
    one taken as rows)."""
    t = seconds_array(times, "times", allow_empty=allow_empty)
    if np.any(np.diff(t) <= 0):
        raise EventDataError("times must be strictly increasing seconds (the offset grid, e.g. np.linspace(t_start, "
                             "t_end, 64)); sort them and drop repeats (np.unique(times))")
    return t


def integrated_frames(chunks, times, C, sensor_size) -> np.ndarray | None:
    """float32 [G, H, W]: the events weighed +C+ (ON) and -C- (OFF), summed up to each of ``times`` [G]
    (increasing seconds; from times[0] - 1 s on: what came before is the same constant in every frame).
    ``chunks``: time-ordered :class:`~evinr_lite.core.events.Events` on a sensor of ``sensor_size``
    (a list of one, or a recording read window by window); None when they hold no event."""
    t = _grid_times(times)   # none was numpy's IndexError
    ef = events_to_frames_chunked(chunks, np.concatenate([[t[0] - 1.0], t]), C=C, sensor_size=sensor_size)
    return np.cumsum(ef.frames, axis=0, out=ef.frames) if ef.counts.sum() else None


def coarse_correction(chunks, C, times, frames, coarse_px: float, method: str, rest: float | None = None) -> np.ndarray:
    """The image [H, W] (float32, mean 0) to add to every frame so that the static image's spatial
    frequencies below ``coarse_px`` come from the integrated events (the module's docstring).

    Args:
        chunks: the (prepared) events the INR was trained on over the span, as time-ordered
            :class:`~evinr_lite.core.events.Events` chunks (``[events]`` when they are in memory).
        C: the thresholds the INR used (one C or the pair C+, C-).
        times: float64 [G] increasing seconds of ``frames``.
        frames: [G, H, W] the INR's log intensities with their offset added (the offset grid).
        coarse_px: the Gaussian's sigma (pixels) below which the integrated events set the static image.
        method: the integrated events' offset solve ("median_gradient" or "l1_gradient").
        rest: None, or log units: a static camera's solve (:func:`~evinr_lite.method.offset.l1_gradient_offset`).
    """
    F = np.asarray(frames)
    H, W = F.shape[1:]
    t = np.asarray(times, np.float64)
    I = integrated_frames(chunks, coarse_times(t), C, (H, W))
    if I is None:
        return np.zeros((H, W), np.float32)
    static = I.mean(axis=0, dtype=np.float64) + offset_image(I, method, rest)
    del I
    # unchecked: a diverged network's NaN reaches the solver's result check, which names the settings to change
    d = gaussian_lowpass_unchecked(static - F.mean(axis=0, dtype=np.float64), coarse_px)
    return (d - d.mean()).astype(np.float32)
