"""What an MSE is made of: the level that events never give, and the static large-scale error.

Events fix log intensity only up to one constant per pixel, and the solvers choose every pixel's
constant but one: the level of the whole recording, which :func:`~evinr_lite.method.tonemap.display_shift`
sets by a prior (the frames' mean is 0.4). Under the linear display that constant is one gain on
every displayed value: the frames are g x the truth when everything else is right. MSE then charges
the gain twice, once as a level error and once as a contrast error (a frame with g times the truth's
contrast), so a flat reconstruction can score a lower MSE than a correct one shown at the wrong
level. To tell the two apart:

- :func:`match_level`: the prediction times the one gain g (clipped to [0, 1] as displayed) that
  gives it the truth's mean over the whole sequence: the level the truth knows and events do not;
- :func:`error_parts`: the MSE, the MSE at the truth's level, and of the latter the part that is the
  same in every frame and coarser than ``coarse_px`` (the temporal mean of the error, blurred by a
  Gaussian of that sigma): the error of the per-pixel offsets at large scales, which events never
  fix either (a static large-scale ramp, a wrong vignette).

These are diagnostics beside the protocol (``../shared/notes/evaluation-and-datasets.md``), never a
replacement for it: the protocol's MSE is the one every table reports. The gain is exact for the
linear display (the kit's default); for the Reinhard curve it is an approximation.
"""
from __future__ import annotations

import numpy as np

from ..core.checks import check_image_values, real_number
from ..core.events import EventDataError
from ..core.guard import dense_array
from ..method.offset import gaussian_lowpass

__all__ = ["match_level", "error_parts", "COARSE_PX"]

COARSE_PX = 8.0    # the Gaussian's sigma (pixels) above which an error counts as large-scale (offset_coarse_px)


def _frames(a, name: str) -> np.ndarray:
    a = dense_array(a, name, error=EventDataError, want="frames of one size [K, H, W] (crop or resize them to one size)")
    if a.ndim != 3 or a.size == 0:
        raise EventDataError(f"{name} must be a stack [K, H, W] of frames, got shape {a.shape}"
                             + ("; one image [H, W] is a stack of one: image[None]" if a.ndim == 2 else
                                "; no frame or no pixel to score" if a.ndim == 3 else ""))
    check_image_values(a, name, clipped=(name == "pred"))   # uint8, or finite floats in [0, 1] (not 0..255)
    f = a.astype(np.float64) / 255.0 if a.dtype == np.uint8 else a.astype(np.float64)
    return np.clip(f, 0.0, 1.0)     # predictions as displayed (the protocol clips them too)


def _pair(pred, gt) -> tuple[np.ndarray, np.ndarray]:
    p, g = _frames(pred, "pred"), _frames(gt, "gt")
    if p.shape != g.shape:
        raise EventDataError(f"pred {p.shape} and gt {g.shape} must be the same frames [K, H, W]: pair each "
                             "ground-truth frame with its prediction first (evaluation.match_frames)")
    return p, g


def match_level(pred, gt) -> tuple[np.ndarray, float]:
    """(pred x g clipped to [0, 1]: float64 [K, H, W], the gain g): the one gain over the whole sequence
    that gives the prediction the truth's mean (found by bisection on log g, to 1e-12).

    Args:
        pred: [K, H, W] predicted frames in [0, 1] (or uint8), each paired with ``gt``'s frame.
        gt: [K, H, W] ground truth in [0, 1] (or uint8 / 255).
    Raises:
        EventDataError: shapes differ, values are not finite, or the prediction is black everywhere
            (no gain can give it a level).
    """
    p, g = _pair(pred, gt)
    target = float(g.mean())
    if not p.max() > 0:
        raise EventDataError("pred is 0 everywhere: no gain gives it the truth's level (a black reconstruction)")
    if target <= 0:
        return np.zeros_like(p), 0.0

    def shown(c):
        return np.minimum(p * np.exp(c), 1.0).mean()

    lo = np.log(target) - np.log(p.max()) - 1.0                  # every value below the target: mean below it
    hi = np.log(target) - np.log(p.mean()) + 1.0
    while shown(hi) < target and hi < lo + 60.0:                  # clipping can hold the mean below the target
        hi += 5.0
    for _ in range(80):       # shown(c) grows with c: bisection on log g
        mid = 0.5 * (lo + hi)
        if shown(mid) < target:
            lo = mid
        else:
            hi = mid
        if hi - lo < 1e-12:
            break
    gain = float(np.exp(0.5 * (lo + hi)))
    return np.minimum(p * gain, 1.0), gain


def error_parts(pred, gt, coarse_px: float = COARSE_PX) -> dict:
    """The MSE of ``pred`` against ``gt`` and what it is made of (the module's docstring).

    Returns:
        {"mse": the protocol's MSE (no equalisation), "mse_at_level": the MSE after :func:`match_level`,
        "static_coarse": of the latter, the mean square of the error's temporal mean blurred by a
        Gaussian of ``coarse_px`` pixels, "gain": the level's gain (1 = the truth's level), "matched":
        the frames at the truth's level, float64 [K, H, W] (to score them further without a second match)}.
    """
    coarse_px = real_number(coarse_px, "coarse_px", lo=0.0, lo_open=True, hint="a Gaussian's sigma in pixels (8)")
    p, g = _pair(pred, gt)
    matched, gain = match_level(p, g)
    err = matched - g
    static = gaussian_lowpass(err.mean(axis=0), coarse_px)
    return {"mse": float(np.mean((p - g) ** 2)), "mse_at_level": float(np.mean(err ** 2)),
            "static_coarse": float(np.mean(static ** 2)), "gain": gain, "matched": matched}
