"""`Frames`: ground-truth intensity frames with their timestamps (e.g. DAVIS APS frames)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .checks import check_image_values
from .events import EventDataError, InputError, check_t_origin
from .guard import dense_array

__all__ = ["Frames", "in_window", "to_grey_uint8", "to_uint8", "GREY_WEIGHTS"]

GREY_WEIGHTS = np.array([0.2125, 0.7154, 0.0721])   # ITU-R 709 luminance of (R, G, B): every RGB -> grey here


@dataclass(frozen=True, eq=False)
class Frames:
    """F grey frames of size (H, W) and their timestamps.

    Attributes:
        images: [F, H, W], uint8 (0..255) or float in [0, 1] (finite; floats in 0..255 are refused);
            indexed [frame, y (row), x (column)].
        t: float64 [F], seconds relative to ``t_origin`` (the same clock as the events they go with);
            readers return them sorted, :meth:`sorted` sorts others.
        t_origin: float, seconds; absolute time of t = 0.
    """

    images: np.ndarray
    t: np.ndarray
    t_origin: float = 0.0

    def __post_init__(self):
        images = dense_array(self.images, "Frames.images", error=EventDataError,
                             want="images of one size [H, W] each (crop or resize them to one size first)")
        if images.ndim == 4 and images.shape[-1] == 1:
            images = images[..., 0]
        if images.dtype != np.uint8 and images.dtype.kind != "f":
            raise EventDataError(f"frames must be uint8 (0..255) or float in [0, 1], got dtype {images.dtype}")
        if images.ndim != 3:
            raise EventDataError(f"frames must have shape [F, H, W] (grey), got {images.shape}")
        try:   # the scorer's rule, here too: float images in [0, 1], finite (0..255 floats are refused)
            check_image_values(images, "frame images")
        except InputError as err:
            raise EventDataError(str(err)) from None
        t = dense_array(self.t, "Frames.t", np.float64, error=EventDataError,
                        want="one timestamp (seconds) per frame, a 1-D list or array")
        if t.shape != (images.shape[0],):
            raise EventDataError(f"{images.shape[0]} frames but {t.shape[0] if t.ndim == 1 else t.shape} timestamps")
        if not np.all(np.isfinite(t)):
            raise EventDataError("frame timestamps contain NaN or inf; repair or drop those frames")
        object.__setattr__(self, "images", images)
        object.__setattr__(self, "t", t)
        object.__setattr__(self, "t_origin", check_t_origin(self.t_origin))

    def __len__(self) -> int:
        return int(self.images.shape[0])

    def __repr__(self) -> str:
        return f"Frames(n={len(self)}, size={self.size}, t_origin={self.t_origin})"

    @property
    def size(self) -> tuple[int, int]:
        """(H, W)."""
        return int(self.images.shape[1]), int(self.images.shape[2])

    def as_float(self) -> np.ndarray:
        """Images as float32 in [0, 1] (uint8 is divided by 255)."""
        if self.images.dtype == np.uint8:
            return self.images.astype(np.float32) / 255.0
        return self.images.astype(np.float32)

    def slice_time(self, t_start: float | None = None, t_end: float | None = None) -> "Frames":
        """Frames with ``t_start <= t < t_end`` (seconds)."""
        keep = in_window(self.t, t_start, t_end)
        return Frames(self.images[keep], self.t[keep], self.t_origin)

    def sorted(self) -> "Frames":
        """Frames in time order (some recordings store one frame out of order)."""
        order = np.argsort(self.t, kind="stable")
        return Frames(self.images[order], self.t[order], self.t_origin)

    def sorted_distinct(self, use: str) -> "Frames":
        """:meth:`sorted`, refusing two frames at one timestamp (which of them holds at that time is unknown:
        an anchor, or a log change over no time, would be made of either); ``use`` names what needs them."""
        out = self.sorted()
        same = np.flatnonzero(np.diff(out.t) == 0)
        if same.size:
            raise EventDataError(f"{use}: {same.size} APS frame(s) share a timestamp with the previous one (first at "
                                 f"t = {out.t[same[0]]:.6f} s); frames need distinct times: drop the duplicates "
                                 "(e.g. keep = np.r_[True, np.diff(frames.t) > 0] on sorted frames)")
        return out


def in_window(t, t_start: float | None = None, t_end: float | None = None) -> np.ndarray:
    """bool [N]: which of the times ``t`` [N] (seconds) lie in [t_start, t_end) (None: open on that side)."""
    t = np.asarray(t)
    keep = np.ones(t.shape, bool)
    if t_start is not None:
        keep &= t >= t_start
    if t_end is not None:
        keep &= t < t_end
    return keep


def to_uint8(img) -> np.ndarray:
    """Images in [0, 1] (clipped) as uint8 ``round(255 * x)``, element by element, any shape (an image
    [H, W], a stack [F, H, W] or colour [..., 3]); uint8 input is returned as is. The one conversion
    used by scoring (equalisation) and export."""
    img = np.asarray(img)
    if img.dtype == np.uint8:
        return img
    return np.round(np.clip(img.astype(np.float64), 0.0, 1.0) * 255.0).astype(np.uint8)


def to_grey_uint8(img: np.ndarray, source) -> np.ndarray:
    """An image [H, W], [H, W, 1], [H, W, 3] or [H, W, 4] -> grey uint8 [H, W] (ITU-R 709 weights)."""
    img = np.asarray(img)
    if img.ndim == 3 and img.shape[-1] == 1:
        img = img[..., 0]
    if img.dtype == np.uint16:
        img = img / 257.0
    elif img.dtype.kind == "f":
        check_image_values(img, f"{source}: images", clipped=True)   # NaN became 0, floats in 0..255 white
        img = np.clip(img, 0.0, 1.0) * 255.0
    elif img.dtype != np.uint8:
        raise EventDataError(f"{source}: images must be 8- or 16-bit grey or RGB, got dtype {img.dtype}")
    if img.ndim == 3 and img.shape[-1] in (3, 4):
        img = img[..., :3].astype(np.float64) @ GREY_WEIGHTS
    if img.ndim != 2:
        raise EventDataError(f"{source}: expected a grey or RGB image, got shape {img.shape}")
    if img.dtype != np.uint8:
        img = np.clip(np.round(img), 0, 255).astype(np.uint8)
    return img
