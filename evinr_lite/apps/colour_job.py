"""Colour reconstruction of a recording from a colour event camera (``evinr-lite reconstruct --colour``).

A colour recording carries its colour filter in ``meta["cfa"]`` (canonical files converted from CED,
:func:`evinr_lite.sim.colour_davis.colour_davis_recording`): a 2 x 2 Bayer filter named by the
colours of photosites (0, 0), (0, 1), (1, 0), (1, 1), e.g. "RGGB". The steps::

    streams = split_colour_events(rec)                        # (R, G, B) Events on (H/2, W/2)
    result = reconstruct_colour_recording(rec, times, cfg)    # ColourResult, frames [Q, H/2, W/2, 3]
    scores, colour = score_colour_recording(result, rec, recon_job.score_predictions)   # grey + chroma

Every 2 x 2 window of photosites becomes one pixel of each channel (the split of
:func:`evinr_lite.sim.quadbayer.demosaic_events_rgb` with ``block=1``), so the reconstruction is on
the (H/2, W/2) grid (an odd last row or column, which holds no full window, is left out), each
channel with its effective threshold (C for R and B, C/2 for G). The white balance is the grey
world of :func:`evinr_lite.method.colour.reconstruct_colour` (events carry no channel offsets).

Scores: the colour frames converted to grey (ITU-R 709, as the grey frames) against the
ground-truth frames averaged over the same 2 x 2 windows, under both protocols; and, when the
recording has colour frames, the chroma correlation (log R/G and log B/G against the truth's, each
frame's mean removed: 1 = the colour pattern is right, 0 = none of it).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.cfa import BAYER, cfa_phase
from ..core.checks import ArgumentTypeError, require
from ..core.events import EventDataError, Events
from ..core.frames import GREY_WEIGHTS, Frames
from ..core.recording import Recording
from ..method.colour import chroma_correlation, reconstruct_colour
from ..method.solver import EvINRConfig
from ..method.tonemap import to_display
from ..sim.quadbayer import demosaic_events_rgb, reduce_mean

__all__ = ["check_colour_recording", "split_colour_events", "colour_frames", "ColourResult",
           "reconstruct_colour_recording", "score_colour_recording"]



def check_colour_recording(rec: Recording) -> str:
    """The recording's colour filter name, or an EventDataError naming the fix when it has none."""
    require(rec, Recording, "rec")   # None or Events was "has no attribute 'meta'"
    cfa = rec.meta.get("cfa")
    source = rec.meta.get("path") or "the recording"
    if cfa is None:
        raise EventDataError(f"{source}: --colour needs a colour recording but this one has no colour filter (no "
                             "cfa attribute: a mono sensor, or a format that does not store it); drop --colour, or "
                             "convert the colour camera's raw recording with `python -m data_fetch convert` (CED "
                             "bags keep their RGGB filter) into a canonical .h5 that records it")
    cfa_phase(cfa)   # a valid name
    return cfa


def split_colour_events(rec: Recording):
    """(R, G, B) Events on (H // 2, W // 2), split by the recording's colour filter (``meta["cfa"]``);
    an odd last row or column of photosites is left out (it holds no full 2 x 2 window)."""
    phase = cfa_phase(check_colour_recording(rec))
    ev = rec.events
    H, W = ev.sensor_size
    if H < 2 or W < 2:      # was refused as a sensor of (0, W) nobody gave
        raise EventDataError(f"{rec.meta.get('path') or 'the recording'}: a {H} x {W} sensor holds no full 2 x 2 "
                             "window of its colour filter; --colour needs at least 2 x 2 photosites (check the "
                             "sensor size, H x W)")
    if H % 2 or W % 2:
        ev = ev.take((ev.x < W - W % 2) & (ev.y < H - H % 2))
        ev = Events(ev.t, ev.x, ev.y, ev.p, (H - H % 2, W - W % 2), t_origin=ev.t_origin, polarity_encoding="pm1")
    return demosaic_events_rgb(ev, phase, block=BAYER)


def colour_frames(rec: Recording) -> np.ndarray | None:
    """The colour ground-truth frames uint8 [F, H, W, 3], one per frame of ``rec.frames`` (matched by
    time: ``meta["frames_rgb_t"]``), or None when the recording has no colour frames."""
    require(rec, Recording, "rec")
    rgb, t = rec.meta.get("frames_rgb"), rec.meta.get("frames_rgb_t")
    if rgb is None or t is None or rec.frames is None or not len(rec.frames):
        return None
    t = np.asarray(t, np.float64)
    idx = np.searchsorted(t, rec.frames.t)
    idx = np.minimum(idx, len(t) - 1)
    if not np.all(t[idx] == rec.frames.t):
        return None   # the grey frames are not a subset of the colour ones
    return np.asarray(rgb)[idx]


@dataclass(eq=False)
class ColourResult:
    """A colour reconstruction in the shape the export expects.

    Attributes:
        times: float64 [Q] s. frames: float32 [Q, h, w, 3] in [0, 1]. log_intensity: [Q, h, w, 3].
        channels: the (R, G, B) Reconstructions. thresholds: C per channel. channel_offsets: [3].
        windows: [N, 2] the time windows (of the R channel; all three share them).
        history: {"config", "train_time_s", "thresholds", "cfa"}.
    """

    times: np.ndarray
    frames: np.ndarray
    log_intensity: np.ndarray
    channels: tuple
    thresholds: tuple
    channel_offsets: np.ndarray
    windows: np.ndarray
    history: dict = field(repr=False)

    def at(self, times) -> np.ndarray:
        """Log intensity of the three channels at any times in the windows: float32 [Q, h, w, 3]."""
        L = np.stack([r.at(times) for r in self.channels], axis=-1)
        return (L + self.channel_offsets.astype(np.float32)).astype(np.float32)

    def frames_at(self, times) -> np.ndarray:
        """Colour frames in [0, 1] (the config's tone map) at any times: float32 [Q, h, w, 3]."""
        cfg = self.channels[0].config
        return to_display(self.at(times), cfg.tonemap, cfg.gamma).astype(np.float32)


def reconstruct_colour_recording(rec: Recording, times, config: EvINRConfig | None = None) -> ColourResult:
    """One EvINR per colour channel over the recording's window (``meta["window"]``), at ``times``.

    ``config.C`` is the photosites' threshold; the channels use C, C/2, C (R, G, B of a 2 x 2 filter).
    """
    cfg = config or EvINRConfig()
    cfa = check_colour_recording(rec)
    streams = split_colour_events(rec)
    empty = [name for name, s in zip("RGB", streams) if len(s) < 2]
    if empty:
        raise EventDataError(f"{rec.meta.get('path') or 'the recording'}: fewer than 2 {'/'.join(empty)} events in "
                             "the window; choose a longer window, or check the colour filter (meta['cfa'])")
    lo, hi = rec.meta.get("window", (None, None))
    cr = reconstruct_colour(streams, times, cfg, C=cfg.C, block=BAYER, t_start=lo, t_end=hi)
    first = cr.channels[0]
    history = {"config": first.history.get("config"), "train_time_s": cr.train_time_s,
               "thresholds": list(cr.thresholds), "cfa": cfa}
    return ColourResult(cr.times, cr.frames, cr.log_intensity, cr.channels, cr.thresholds, cr.channel_offsets,
                        first.windows, history)


def _reduce_rgb(rgb_uint8: np.ndarray) -> np.ndarray:
    """uint8 [F, H, W, 3] -> float64 [F, H/2, W/2, 3] in [0, 1]: the mean of each 2 x 2 window."""
    rgb = np.asarray(rgb_uint8, np.float64) / 255.0
    return np.stack([reduce_mean(rgb[..., c], 2) for c in range(3)], axis=-1)


def score_colour_recording(result: ColourResult, rec: Recording, score_predictions) -> tuple[dict | None, dict | None]:
    """Score a colour reconstruction against the recording's frames in its span.

    Args:
        score_predictions: the grey scorer, :func:`evinr_lite.apps.recon_job.score_predictions`
            (passed in: recon_job imports this module, so this module does not import it back).
    Returns (scores, colour): ``scores`` from ``score_predictions`` (grey: the reconstruction's
    luminance against the frames averaged over 2 x 2 windows, both protocols) or None without
    frames; ``colour`` = {"chroma_correlation": {"R-G", "B-G"}, "chroma_correlation_mean",
    "n_frames"} when the frames are colour, else None.
    """
    require(result, ColourResult, "result")
    require(rec, Recording, "rec")
    if not callable(score_predictions):
        raise ArgumentTypeError(f"score_predictions= must be the grey scorer (evinr_lite.apps.results."
                                f"score_predictions), got {type(score_predictions).__name__}")
    gt = rec.frames
    if gt is None or not len(gt):
        return None, None
    lo, hi = result.windows[0, 0], result.windows[-1, 1]
    keep = (gt.t >= lo) & (gt.t <= hi)
    if not keep.any():
        return None, None
    rgb = colour_frames(rec)
    h, w = result.frames.shape[1:3]
    if tuple(gt.size) != tuple(rec.events.sensor_size) or gt.size[0] // 2 != h or gt.size[1] // 2 != w:
        raise EventDataError(f"ground-truth frames are {gt.size} but the colour events' sensor is "
                             f"{rec.events.sensor_size} (H, W); they cannot be compared")
    t = gt.t[keep]
    if rgb is not None:
        true_rgb = _reduce_rgb(rgb[keep][:, :2 * h, :2 * w])
        grey_gt = true_rgb @ GREY_WEIGHTS
    else:
        grey = np.asarray(gt.images[keep][:, :2 * h, :2 * w], np.float64)
        grey_gt = reduce_mean(grey / (255.0 if gt.images.dtype == np.uint8 else 1.0), 2)
        true_rgb = None
    L = result.at(t)
    cfg = result.channels[0].config
    pred = to_display(L, cfg.tonemap, cfg.gamma).astype(np.float32)
    scores = score_predictions(pred @ GREY_WEIGHTS.astype(np.float32), t,
                               Frames(np.clip(grey_gt, 0.0, 1.0).astype(np.float32), t, gt.t_origin))
    colour = None
    if true_rgb is not None:
        chroma = chroma_correlation(L, np.log(true_rgb + 1.0 / 255.0))
        colour = {"chroma_correlation": chroma, "chroma_correlation_mean": float(np.mean(list(chroma.values()))),
                  "n_frames": int(len(t))}
    return scores, colour
