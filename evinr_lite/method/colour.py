"""Colour reconstruction from colour events: one EvINR per channel, tone-mapped to RGB.

    streams = demosaic_events_rgb(events, phase)          # (R, G, B) Events at the reduced grid
    rec = reconstruct_colour(streams, query_times, EvINRConfig(...), C=0.2)
    rec.frames            # [Q, h, w, 3] in [0, 1]

Each channel is solved on its own (:func:`evinr_lite.method.solver.reconstruct`) with its own effective
threshold (C / 4, C / 8, C / 4 for Quad Bayer, :func:`evinr_lite.core.cfa.effective_thresholds`).

The white balance is not in the events. Events give changes of log intensity only; each channel's
constant offset is unknown, and a colour cast *is* a difference of channel offsets. ``reconstruct``
anchors every channel's mean at the same grey, so by default the result is white-balanced by the
"grey world" rule (the mean colour of the sequence is grey). Pass ``channel_offsets`` (log units per
channel, e.g. :func:`channel_offsets_from` of one reference RGB frame) to restore the colours.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..core.cfa import CHANNELS, QUAD_BAYER, effective_thresholds
from ..core.checks import numbers_array, require, seconds_array
from ..core.events import EventDataError, Events
from .solver import EvINRConfig, reconstruct
from .tonemap import to_display

__all__ = ["ColourReconstruction", "reconstruct_colour", "channel_offsets_from", "chroma_correlation"]


@dataclass(eq=False)
class ColourReconstruction:
    """Three channel reconstructions combined.

    Attributes:
        times: float64 [Q] seconds. log_intensity: float32 [Q, h, w, 3] (offsets applied).
        frames: float32 [Q, h, w, 3] tone-mapped (Eq. 12, per channel) in [0, 1].
        channels: the (R, G, B) :class:`~evinr_lite.method.solver.Reconstruction` objects.
        thresholds: the C used per channel. channel_offsets: float [3] log offsets added.
    """

    times: np.ndarray
    log_intensity: np.ndarray
    frames: np.ndarray
    channels: tuple
    thresholds: tuple
    channel_offsets: np.ndarray

    @property
    def train_time_s(self) -> float:
        """Training time of the three channels together (seconds)."""
        return float(sum(r.history["train_time_s"] for r in self.channels))


def channel_offsets_from(rgb) -> np.ndarray:
    """Log offsets [3] that give the channels the colour balance of a reference RGB image.

    log(mean of channel c) minus the mean of those three logs, so that the offsets sum to zero
    and leave the overall brightness anchor alone. ``rgb``: [..., 3] positive linear intensities.
    """
    rgb = numbers_array(rgb, "rgb", "linear intensities [..., 3]").astype(np.float64)   # text: numpy's error
    if rgb.ndim < 2 or rgb.shape[-1] != 3 or not np.all((rgb > 0) & np.isfinite(rgb)):   # inf gave NaN offsets
        raise EventDataError(f"rgb must be positive finite intensities of shape [..., 3], got {rgb.shape}")
    logs = np.log(rgb.reshape(-1, 3).mean(axis=0))
    return logs - logs.mean()


def reconstruct_colour(streams, query_times, config: EvINRConfig | None = None, *, C: float | None = None,
                       thresholds=None, block: int = QUAD_BAYER, channel_offsets=None,
                       t_start: float | None = None, t_end: float | None = None) -> ColourReconstruction:
    """Reconstruct RGB frames from per-channel event streams.

    Args:
        streams: (R, G, B) Events on one grid (e.g. :func:`~evinr_lite.sim.quadbayer.demosaic_events_rgb`).
        query_times: [Q] seconds.
        config: EvINRConfig for every channel; its ``C`` is replaced per channel.
        C: the photosites' contrast threshold; the channels then use ``effective_thresholds(C, block)``.
        thresholds: (C_R, C_G, C_B) to use instead (e.g. a tuned value for all three).
        channel_offsets: [3] log offsets added to the channels after anchoring (None: grey world).
        t_start, t_end: span (s); default: the union of the streams' spans and the query times.

    Returns:
        ColourReconstruction with frames [Q, h, w, 3] in [0, 1].
    """
    cfg = EvINRConfig() if config is None else require(config, EvINRConfig, "config")   # {} was taken as None
    if not isinstance(streams, (str, bytes, Events)) and hasattr(streams, "__iter__"):   # any container or iterator
        streams = tuple(streams)
    if not isinstance(streams, tuple) or len(streams) != 3 or not all(isinstance(s, Events) for s in streams):
        raise EventDataError("streams must be three Events streams (R, G, B); use quadbayer.demosaic_events_rgb")
    if len({s.sensor_size for s in streams}) != 1:
        raise EventDataError(f"the three streams must share one grid, got {[s.sensor_size for s in streams]}")
    if thresholds is None:
        if C is None:
            raise EventDataError("pass C (the photosites' threshold) or thresholds=(C_R, C_G, C_B)")
        eff = effective_thresholds(C, block)
        thresholds = tuple(eff[name] for name in CHANNELS)
    try:
        thresholds = tuple(float(c) for c in thresholds)
    except (TypeError, ValueError):      # text, or not a sequence: Python's own error named nothing
        raise EventDataError(f"thresholds must be three positive numbers (C_R, C_G, C_B), got {thresholds!r}") from None
    if len(thresholds) != 3 or not all(c > 0 for c in thresholds):
        raise EventDataError(f"thresholds must be three positive numbers, got {thresholds!r}")
    q = seconds_array(query_times, "query_times")      # none at all was numpy's error on an empty minimum
    if channel_offsets is not None:
        offsets = np.asarray(channel_offsets, dtype=np.float64)
        if offsets.shape != (3,) or not np.all(np.isfinite(offsets)):   # NaN made every frame NaN
            raise EventDataError(f"channel_offsets must be 3 finite numbers (log units), got {channel_offsets!r}")
    firsts = [s.t[0] for s in streams if len(s)]
    lasts = [s.t[-1] for s in streams if len(s)]
    t_start = float(min(firsts + [q.min()])) if t_start is None else float(t_start)
    t_end = float(max(lasts + [q.max()])) if t_end is None else float(t_end)
    recs = tuple(reconstruct(s, q, dataclasses.replace(cfg, C=c), t_start=t_start, t_end=t_end)
                 for s, c in zip(streams, thresholds))
    offsets = np.zeros(3) if channel_offsets is None else offsets
    L = np.stack([r.log_intensity for r in recs], axis=-1) + offsets.astype(np.float32)
    frames = to_display(L, cfg.tonemap, cfg.gamma).astype(np.float32)
    return ColourReconstruction(q, L.astype(np.float32), frames, recs, thresholds, offsets)


def chroma_correlation(L_rgb, L_rgb_true) -> dict:
    """How well the colour differences match the truth: Pearson correlation of log(R/G) and of
    log(B/G) with the true ones, pooled over frames after removing each frame's mean (offsets are
    unknown to events, so only the spatial colour pattern counts).

    Args:
        L_rgb, L_rgb_true: log intensities [Q, H, W, 3] on one grid.
    Returns:
        {"R-G": float, "B-G": float}, each in [-1, 1] (1: the colour pattern is right; 0: none of it).
    """
    est = numbers_array(L_rgb, "L_rgb", "log intensities [Q, H, W, 3]").astype(np.float64)   # text: numpy's error
    true = numbers_array(L_rgb_true, "L_rgb_true", "log intensities [Q, H, W, 3]").astype(np.float64)
    if est.shape != true.shape or est.ndim != 4 or est.shape[-1] != 3:
        raise EventDataError(f"expected two [Q, H, W, 3] stacks of one shape, got {est.shape} and {true.shape}")
    if not (np.all(np.isfinite(est)) and np.all(np.isfinite(true))):      # a correlation of NaN is NaN
        raise EventDataError("the log intensities contain NaN or inf; the colour pattern cannot be compared (the "
                             "truth's log of a black pixel needs an eps: np.log(rgb + 1 / 255))")
    out = {}
    for name, c in (("R-G", 0), ("B-G", 2)):
        e, t = est[..., c] - est[..., 1], true[..., c] - true[..., 1]
        e = e - e.mean(axis=(1, 2), keepdims=True)
        t = t - t.mean(axis=(1, 2), keepdims=True)
        out[name] = float((e * t).sum() / max(np.sqrt((e * e).sum() * (t * t).sum()), 1e-300))
    return out
