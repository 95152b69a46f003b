"""Quad Bayer colour sensors (the ALPIX-Eiger of the paper's AED dataset, Sec. 3.4): the colour
filter, mosaicing, colour events, and demosaicing of frames and events to grey and to colour.
The filter's helpers (tile, channel of a photosite, pattern, names, thresholds) live in
:mod:`evinr_lite.core.cfa` and are importable from here too.

The colour filter array (CFA)
    The tile (:mod:`evinr_lite.core.cfa`): 2 x 2 same-colour blocks R / G / G / B (``block = 2`` for
    Quad Bayer, ``block = 1`` for plain Bayer), period ``P = 2 * block``, and ``phase = (dy, dx)``,
    where the sensor's photosite (row 0, column 0) sits in the tile. A sensor whose top-left block
    is blue has phase (2, 2); cropping one row off the top of a phase-(0, 0) sensor gives phase (1, 0).

The reduced grid (the paper's demosaicing to grey)
    Every P x P window aligned on the sensor grid (rows P*i .. P*i + P - 1, columns P*j ..) holds
    exactly one period of the filter *whatever the phase*: 4 R, 8 G and 4 B photosites for Quad
    Bayer (block^2 x (1, 2, 1) in general). The paper's reduction gives one grey pixel per window:
    events 1632 x 1224 -> 408 x 306, frames 3264 x 2448 -> 816 x 612 (a factor 4 per axis each).
    A grey frame pixel is the mean intensity of the window's n = P^2 photosites, which is
    (R + 2 G + B) / 4 of the window's channel means. Sizes must be multiples of P.

Demosaicing events, and what a merged event means
    Photosite k fires an event whenever its own log intensity L_k has moved by C since its last
    event. The grey pixel of window w has log intensity L_w = log(mean_k I_k), which equals the
    mean of the logs, (1/n) sum_k L_k, up to half the variance of the L_k (Jensen's gap; zero for
    a window of one colour and one brightness, small where the window is smooth). So over any
    time interval

        Delta L_w ~ (1/n) sum_k Delta L_k ~ (C / n) * (sum of p over the window's events),

    each photosite's Delta L_k being C times its summed polarity up to one threshold.
    :func:`demosaic_events` therefore keeps **every** event with its timestamp and polarity
    unchanged and maps (x, y) -> (x // P, y // P): counts and polarity sums per window are
    conserved exactly, and the merged stream satisfies the event generation model with an
    **effective threshold of C / n per event** (C / 16 for Quad Bayer). Use that value as the
    ``C`` of :func:`~evinr_lite.method.integration.integrate_events` or ``EvINRConfig``.
    Per colour channel (:func:`demosaic_events_rgb`) the same argument with the n_c photosites of
    colour c per window gives C / n_c: C/4 for R and B, C/8 for G. :func:`effective_thresholds`
    returns these numbers. What is *not* done: re-thresholding (emitting a grey event only when
    the mean has moved by a full C), which would drop events and shift timestamps. A grey stream
    therefore holds up to n times more events than a grey sensor with threshold C would fire.

Colour events
    :class:`QuadBayerScene` wraps an RGB moving image; its ``log_intensity`` is the raw mosaic
    (each photosite sees only its own channel's log intensity), so the existing simulator
    (:func:`~evinr_lite.sim.simulate.simulate_scene`) turns it into colour events.
    :func:`simulate_colour_video` does the same for an RGB video given as arrays.
"""
from __future__ import annotations

import numpy as np
from scipy import ndimage

from ..core.cfa import (BAYER, CHANNELS, QUAD_BAYER, TILE_COLOURS, cfa_channel, cfa_pattern, cfa_tile,  # noqa: F401
                        check_block, check_phase, effective_thresholds, period, photosites_per_window)
from ..core.checks import ArgumentTypeError, whole_number
from ..core.events import EventDataError, Events, check_sensor_size
from ..core.guard import dense_array
from .scenes import MOTION_PARAMETERS, MovingImageScene, check_intensity_range, real_image

__all__ = ["CHANNELS", "QUAD_BAYER", "BAYER", "TILE_COLOURS", "period", "photosites_per_window", "cfa_tile",
           "cfa_channel", "cfa_pattern", "mosaic", "demosaic_grey", "demosaic_rgb", "demosaic_rgb_full",
           "debayer_bilinear",
           "effective_thresholds", "demosaic_events", "demosaic_events_rgb", "QuadBayerScene",
           "simulate_colour_video", "reduce_mean", "mosaic_display", "checker_amplitude"]


def _image(a, name: str, want: str = "a mosaic [..., H, W]", *, finite: bool = True) -> np.ndarray:
    """``a`` as an array of 2 or more dimensions of real numbers (and, with ``finite``, no NaN or inf); else an
    EventDataError naming ``name`` (text, complex numbers, a ragged list, None or one row were numpy's errors,
    a sensor size's, or NaN results)."""
    a = dense_array(a, f"{name}=", error=EventDataError, want=f"{want}, all of one size")
    if a.ndim < 2:
        raise EventDataError(f"{name}= must be {want}, got shape {a.shape}" +
                             ("; one row is an image of one row: a[None]" if a.ndim == 1 else ""))
    if a.dtype.kind not in "biuf":
        kind = "complex numbers" if a.dtype.kind == "c" else f"dtype {a.dtype}"
        raise EventDataError(f"{name}= must be numbers (linear intensities), got {kind}")
    if finite and a.dtype.kind == "f":
        bad = int(a.size - np.count_nonzero(np.isfinite(a)))
        if bad:
            raise EventDataError(f"{name}= holds {bad:,} NaN or infinite value(s) of {a.size:,}; repair or drop them "
                                 "(NaN or inf has no colour to show, average or demosaic)")
    return a


def mosaic(rgb, phase=(0, 0), block: int = QUAD_BAYER) -> np.ndarray:
    """What the photosites see: each keeps only its own channel of an RGB image or video.

    Args:
        rgb: [..., H, W, 3] (intensities, or log intensities: the selection is the same).
    Returns:
        [..., H, W] of the same dtype (the raw mosaic).
    """
    rgb = dense_array(rgb, "rgb=", error=EventDataError, want="colour images [..., H, W, 3], all of one size")
    if rgb.ndim < 3 or rgb.shape[-1] != 3:
        raise EventDataError(f"rgb must have shape [..., H, W, 3], got {rgb.shape}")
    if rgb.dtype.kind not in "biuf":   # complex numbers kept their imaginary part, text was taken
        kind = "complex numbers" if rgb.dtype.kind == "c" else f"dtype {rgb.dtype}"
        raise EventDataError(f"rgb= must be numbers (intensities or log intensities), got {kind}")
    pattern = cfa_pattern(rgb.shape[-3:-1], phase, block)
    return np.take_along_axis(rgb, np.broadcast_to(pattern[..., None], rgb.shape[:-1] + (1,)).astype(np.intp),
                              axis=-1)[..., 0]


def mosaic_display(raw, phase=(0, 0), block: int = QUAD_BAYER) -> np.ndarray:
    """A raw mosaic [..., H, W] as colours for display: each photosite's value in its own channel,
    the other two zero. Returns float64 [..., H, W, 3] (scale ``raw`` to [0, 1] first)."""
    raw = np.asarray(_image(raw, "raw"), dtype=np.float64)
    pattern = cfa_pattern(raw.shape[-2:], phase, block)
    return np.stack([np.where(pattern == c, raw, 0.0) for c in range(3)], axis=-1)


# ---- demosaicing frames ------------------------------------------------------------------

def _check_raw(raw, block: int) -> tuple[np.ndarray, int]:
    raw = _image(raw, "raw")
    P = period(block)
    H, W = raw.shape[-2:]
    if not (H and W):   # an empty stack of frames [0, H, W] is a valid video of no frames; a frame of no photosite is not
        raise EventDataError(f"raw= has no photosite (shape {raw.shape}); pass a mosaic of at least one {P} x {P} "
                             "tile")
    if H % P or W % P:
        raise EventDataError(f"raw mosaic is {H} x {W} (H x W) but both must be multiples of the tile period {P}; "
                             f"crop it to {H - H % P} x {W - W % P} first (cropping from the top/left changes the phase)")
    return raw, P


def reduce_mean(image, factor: int) -> np.ndarray:
    """Mean over non-overlapping factor x factor windows of [..., H, W] -> float64 [..., H/f, W/f]."""
    factor = whole_number(factor, "factor", lo=1)
    image = np.asarray(_image(image, "image", "an image [..., H, W]", finite=False), dtype=np.float64)
    H, W = image.shape[-2:]
    if H % factor or W % factor:
        raise EventDataError(f"image {H} x {W} is not a multiple of the reduction factor {factor}")
    return image.reshape(image.shape[:-2] + (H // factor, factor, W // factor, factor)).mean(axis=(-3, -1))


def demosaic_grey(raw, block: int = QUAD_BAYER) -> np.ndarray:
    """The paper's reduction: one grey pixel per P x P window, the mean of its photosites.

    Every aligned window holds one full CFA period whatever the phase, so the result is
    (R + 2 G + B) / 4 of the window's channel means, and needs no phase.

    Args:
        raw: [..., H, W] linear intensities (H, W multiples of P).
    Returns:
        float64 [..., H / P, W / P].
    """
    raw, P = _check_raw(raw, block)
    return reduce_mean(raw, P)


def demosaic_rgb(raw, phase=(0, 0), block: int = QUAD_BAYER) -> np.ndarray:
    """Colour at the reduced grid: per window, the mean of each channel's photosites.

    Args:
        raw: [..., H, W] linear intensities.
    Returns:
        float64 [..., H / P, W / P, 3] (R, G, B).
    """
    raw, P = _check_raw(raw, block)
    pattern = cfa_pattern(raw.shape[-2:], phase, block)
    counts = photosites_per_window(block)
    out = [reduce_mean(np.where(pattern == c, raw, 0.0), P) * (P * P / counts[name])
           for c, name in enumerate(CHANNELS)]
    return np.stack(out, axis=-1)


def demosaic_rgb_full(raw, phase=(0, 0), block: int = QUAD_BAYER) -> np.ndarray:
    """Colour at full resolution by normalised convolution (a simple demosaic, for display).

    Each channel at each photosite is the mean of that channel's photosites inside the
    (P + 1) x (P + 1) neighbourhood (which always holds some of every colour). Blurrier than a
    real ISP, but phase-correct.

    Args:
        raw: [H, W] or [T, H, W] linear intensities.
    Returns:
        float64 [..., H, W, 3].
    """
    raw, P = _check_raw(raw, block)
    pattern = cfa_pattern(raw.shape[-2:], phase, block)
    size = (1,) * (raw.ndim - 2) + (P + 1, P + 1)
    out = []
    for c in range(3):
        mask = (pattern == c).astype(np.float64)
        num = ndimage.uniform_filter(np.asarray(raw, np.float64) * mask, size=size, mode="mirror")
        den = ndimage.uniform_filter(np.broadcast_to(mask, raw.shape).astype(np.float64), size=size, mode="mirror")
        out.append(num / den)
    return np.stack(out, axis=-1)


def debayer_bilinear(raw, phase=(0, 0)) -> np.ndarray:
    """A standard 2 x 2 Bayer mosaic [H, W] -> colour [H, W, 3] (R, G, B), bilinear, float64.

    Every photosite keeps its own value in its own channel; a missing channel is the weighted mean
    of that channel's nearest photosites (kernel 1 2 1 / 2 4 2 / 1 2 1: the 2 or 4 neighbours), as a
    camera driver's debayered topic (DAVIS346 colour, CED). ``phase``: the filter's phase (cfa_tile).
    """
    raw = _image(raw, "raw", "a mosaic [H, W]")
    if raw.ndim != 2:
        raise EventDataError(f"raw= must be one mosaic [H, W], got shape {raw.shape}; debayer one frame at a time "
                             "(raw[i])")
    if min(raw.shape) < 2:
        raise EventDataError(f"raw= must be at least 2 x 2 photosites (one whole Bayer tile), got {raw.shape[0]} x "
                             f"{raw.shape[1]}: the missing colours of a smaller one have no neighbour to come from; pass a mosaic of "
                             "at least one 2 x 2 tile")
    values = np.asarray(raw, np.float64)
    pattern = cfa_pattern(values.shape, phase, block=BAYER)
    kernel = np.array([[1.0, 2.0, 1.0], [2.0, 4.0, 2.0], [1.0, 2.0, 1.0]])
    out = []
    for c in range(3):
        mask = (pattern == c).astype(np.float64)
        num = ndimage.convolve(values * mask, kernel, mode="mirror")
        den = ndimage.convolve(mask, kernel, mode="mirror")
        out.append(np.where(mask > 0, values, num / den))
    return np.stack(out, axis=-1)


# ---- demosaicing events ------------------------------------------------------------------

def _check_events(events: Events, block: int) -> tuple[int, int, int]:
    if not isinstance(events, Events):
        raise EventDataError(f"expected an Events stream on the raw (mosaic) sensor, got {type(events).__name__}")
    P = period(block)
    H, W = events.sensor_size
    if H % P or W % P:
        raise EventDataError(f"the raw event sensor is {H} x {W} (H x W) but both must be multiples of the tile "
                             f"period {P}; crop the events (e.g. keep x < {W - W % P}, y < {H - H % P}) first")
    return P, H // P, W // P


def demosaic_events(events: Events, block: int = QUAD_BAYER) -> Events:
    """Merge the events of every P x P window into one grey pixel (x // P, y // P).

    Every event is kept with its timestamp and polarity, so counts and polarity sums per window
    are conserved and the stream stays sorted. Each merged event stands for a grey log-intensity
    step of ``effective_thresholds(C)["grey"]`` = C / 16 (Quad Bayer; see the module docstring).

    Returns:
        Events on (H / P, W / P), same clock and t_origin.
    """
    P, h, w = _check_events(events, block)
    return Events(events.t, events.x // P, events.y // P, events.p, (h, w), t_origin=events.t_origin,
                  polarity_encoding="pm1")


def demosaic_events_rgb(events: Events, phase=(0, 0), block: int = QUAD_BAYER) -> tuple[Events, Events, Events]:
    """Split colour events by the CFA channel of their photosite and merge each per window.

    Returns:
        (R, G, B) Events, each on (H / P, W / P); every input event is in exactly one of them, at
        (x // P, y // P), with its timestamp and polarity. Channel c's events each stand for
        ``effective_thresholds(C)[c]`` (C/4, C/8, C/4 for Quad Bayer).
    """
    P, h, w = _check_events(events, block)
    channel = cfa_channel(events.y, events.x, phase, block)
    out = []
    for c in range(3):
        sel = events.take(channel == c)
        out.append(Events(sel.t, sel.x // P, sel.y // P, sel.p, (h, w), t_origin=events.t_origin,
                          polarity_encoding="pm1"))
    return tuple(out)


def checker_amplitude(images) -> float:
    """RMS of the period-2 patterns of images [..., H, W] (H, W even): the grid artefact of a wrong split.

    Each 2 x 2 block [[a, b], [c, d]] has three components at the highest spatial frequency,
    (a - b + c - d) / 4 (columns alternate), (a + b - c - d) / 4 (rows alternate) and
    (a - b - c + d) / 4 (a checkerboard); this is sqrt(mean over blocks of their summed squares):
    half the difference between alternating values (a checkerboard of 0 and 1 gives 0.5). A smooth
    image gives about half its gradient per pixel; a channel whose pixels alternate between colours
    gives about half the colour difference.
    """
    x = np.asarray(_image(images, "images", "images [..., H, W]"), dtype=np.float64)
    H, W = x.shape[-2:]
    if H < 2 or W < 2:
        raise EventDataError(f"images= must be at least 2 x 2 pixels (one period-2 block), got shape {x.shape}; "
                             "pass images of at least 2 x 2 pixels")
    if H % 2 or W % 2:
        x = x[..., :H - H % 2, :W - W % 2]
    a, b, c, d = x[..., 0::2, 0::2], x[..., 0::2, 1::2], x[..., 1::2, 0::2], x[..., 1::2, 1::2]
    parts = [(a - b + c - d) / 4, (a + b - c - d) / 4, (a - b - c + d) / 4]
    return float(np.sqrt(sum(np.mean(p ** 2) for p in parts)))


# ---- colour events -----------------------------------------------------------------------

class QuadBayerScene:
    """An RGB natural image moving in front of a (Quad) Bayer sensor, with ground truth at any time.

    Each colour channel is a :class:`~evinr_lite.sim.scenes.MovingImageScene` with the same motion, so
    the colour image moves rigidly. Channels are scaled jointly (one min-max over all three, then
    mapped to ``intensity_range``), which keeps the image's colours (up to the small change of each
    channel's range by the anti-aliasing blur).

    ``log_intensity(t)`` is the **raw mosaic** of log intensities [.., H, W] (each photosite sees
    its own channel), so :func:`~evinr_lite.sim.simulate.simulate_scene` gives colour events directly.

    Args:
        image: a scikit-image colour sample name (e.g. "coffee", "astronaut", "chelsea") or an
            array [h, w, 3].
        sensor_size: (H, W) of the raw sensor (photosites), multiples of P.
        duration: seconds. phase, block: the CFA (module docstring).
        intensity_range: (low, high) intensities the darkest and brightest channel values map to.
        **motion: velocity, rotation, zoom, scale, blur, order of MovingImageScene (sensor pixels).
    """

    def __init__(self, image="coffee", sensor_size=(64, 96), duration=1.0, *, phase=(0, 0),
                 block: int = QUAD_BAYER, intensity_range=(0.05, 1.0), **motion):
        self.block = check_block(block)
        self.phase = check_phase(phase, self.block)
        P = 2 * self.block
        H, W = check_sensor_size(sensor_size)
        if H % P or W % P:
            raise EventDataError(f"sensor_size {(H, W)} must be multiples of the tile period {P}")
        unknown = sorted(set(motion) - set(MOTION_PARAMETERS))
        if unknown:   # was MovingImageScene.__init__'s TypeError, naming a class nobody called
            raise ArgumentTypeError(f"QuadBayerScene got unknown parameter(s) {unknown}; it takes phase, block, "
                                    f"intensity_range and the motion {', '.join(MOTION_PARAMETERS)}")
        rgb = self._load(image)
        lo, hi = check_intensity_range(intensity_range)
        span = rgb.max() - rgb.min()
        self.channels = []
        for c in range(3):
            ch = rgb[..., c]
            # the channel's own range inside the joint one: MovingImageScene min-max normalises each
            # channel, so hand it the joint range back through intensity_range
            c_lo = lo + (hi - lo) * (ch.min() - rgb.min()) / span
            c_hi = lo + (hi - lo) * (ch.max() - rgb.min()) / span
            if c_hi - c_lo < 1e-6 * (hi - lo):     # a flat channel: keep it (nearly) flat
                ch = ch + np.linspace(0, 1e-3, ch.shape[1])[None]
                c_hi = c_lo + 1e-3 * (hi - lo)
            self.channels.append(MovingImageScene(ch, (H, W), duration, intensity_range=(c_lo, c_hi), **motion))
        self.sensor_size = (H, W)
        self.duration = float(duration)
        self.pattern = cfa_pattern((H, W), self.phase, self.block)

    @staticmethod
    def _load(image) -> np.ndarray:
        if isinstance(image, str):
            import skimage.data

            if not hasattr(skimage.data, image):
                raise EventDataError(f"unknown scikit-image sample {image!r}; try 'coffee', 'astronaut' or 'chelsea'")
            image = getattr(skimage.data, image)()
        rgb = real_image(image).astype(np.float64)
        if rgb.ndim != 3 or rgb.shape[-1] not in (3, 4) or min(rgb.shape[:2]) < 4:
            raise EventDataError(f"image must be colour [h, w, 3], at least 4 x 4; got shape {rgb.shape}")
        rgb = rgb[..., :3]
        if not np.all(np.isfinite(rgb)) or rgb.max() <= rgb.min():
            raise EventDataError("image must be finite and not constant")
        return rgb

    @property
    def max_speed(self) -> float:
        """Bound on the image motion, raw pixels per second (sets the simulator's sampling)."""
        return max(ch.max_speed for ch in self.channels)

    @property
    def reduced_size(self) -> tuple[int, int]:
        """(H / P, W / P): the grid of the demosaiced grey and colour images."""
        P = 2 * self.block
        return self.sensor_size[0] // P, self.sensor_size[1] // P

    def rgb_log_intensity(self, t) -> np.ndarray:
        """Log intensity of the three channels at every photosite: float64 [..., H, W, 3]."""
        return np.stack([ch.log_intensity(t) for ch in self.channels], axis=-1)

    def log_intensity(self, t) -> np.ndarray:
        """The raw mosaic of log intensities, float64 [H, W] (scalar t) or [T, H, W]."""
        return mosaic(self.rgb_log_intensity(t), self.phase, self.block)

    def raw_intensity(self, t) -> np.ndarray:
        """exp(log_intensity(t)): what the photosites measure (linear)."""
        return np.exp(self.log_intensity(t))

    def grey(self, t) -> np.ndarray:
        """Ground truth at the reduced grid: mean intensity of each window, float64 [..., H/P, W/P]."""
        return demosaic_grey(self.raw_intensity(t), self.block)

    def rgb(self, t) -> np.ndarray:
        """Ground-truth colour at the reduced grid: per-window channel means, float64 [..., H/P, W/P, 3]."""
        return demosaic_rgb(self.raw_intensity(t), self.phase, self.block)

    def __repr__(self) -> str:
        return (f"QuadBayerScene(sensor_size={self.sensor_size}, duration={self.duration}, phase={self.phase}, "
                f"block={self.block})")


def simulate_colour_video(rgb_frames, t, C=0.2, *, phase=(0, 0), block: int = QUAD_BAYER, **kwargs) -> Events:
    """Colour events of an RGB video through the CFA: each photosite sees its own channel.

    Args:
        rgb_frames: [T, H, W, 3] linear intensities (> 0) at the times ``t``.
        t: float64 [T] seconds. C, **kwargs: as :func:`~evinr_lite.sim.simulate.simulate_video`
            (C_pos, C_neg, threshold_sigma, refractory, noise_rate, seed).
    Returns:
        Events on the raw sensor (H, W).
    """
    from .simulate import simulate_video

    rgb = dense_array(rgb_frames, "rgb_frames", error=EventDataError, want="frames of one size [T, H, W, 3]")
    if rgb.dtype.kind not in "iuf" or rgb.dtype == bool:
        kind = "complex numbers" if rgb.dtype.kind == "c" else f"dtype {rgb.dtype}"
        raise EventDataError(f"rgb_frames must be numbers (linear intensities > 0), got {kind}")
    rgb = rgb.astype(np.float64)
    if rgb.ndim != 4 or rgb.shape[-1] != 3:
        raise EventDataError(f"rgb_frames must have shape [T, H, W, 3], got {rgb.shape}")
    finite = np.isfinite(rgb)
    if not finite.all():
        n_nan, n_inf = int(np.isnan(rgb).sum()), int(np.isinf(rgb).sum())
        raise EventDataError(f"rgb_frames contain {n_nan:,} NaN and {n_inf:,} inf value(s); intensities must be finite "
                             "(repair or drop those frames)")
    if not np.all(rgb > 0):
        raise EventDataError("rgb_frames must be positive intensities (the simulator takes their log); clip them above 0")
    return simulate_video(np.log(mosaic(rgb, phase, block)), t, C, **kwargs)
