"""Image quality metrics with a stated protocol: MSE, SSIM (and LPIPS in :mod:`evinr_lite.evaluation.lpips`).

The protocol follows EVREAL's current one (``../shared/notes/evaluation-and-datasets.md``):

- images are grey [H, W] floats in [0, 1]; the prediction is clipped to [0, 1];
- MSE is the mean of squared differences on [0, 1] (not x 255^2);
- SSIM (Wang et al. 2004) uses a gaussian window of sigma 1.5 (truncated at 3.5 sigma: 11 x 11),
  population (co)variances, K1 = 0.01, K2 = 0.03 and data_range = 1.0 (scikit-image would assume
  2 for floats and inflate SSIM), averaged over the pixels at least 5 px from the border;
- optionally, both images are histogram-equalised first (:func:`equalize`): "none", "global"
  (``cv2.equalizeHist``) or "clahe" (``cv2.createCLAHE(clipLimit=2.0, tileGridSize=(8, 8))``,
  the EvINR paper's protocol, after SSL-E2VID), each on the image quantised to uint8 as
  ``round(255 * x)`` and mapped back to [0, 1] as ``/ 255``.

Every result carries its protocol text (:data:`PROTOCOLS`, :func:`protocol_description`).
"""
from __future__ import annotations

import numpy as np
from skimage.metrics import structural_similarity

from ..core.checks import check_image_values, choice, host_array, image_stack
from ..core.events import EventDataError
from ..core.frames import to_uint8

__all__ = ["SSIM_MIN_SIDE", "mse", "ssim", "equalize", "score_pairs", "score_frames", "protocol_description", "PROTOCOLS",
           "SCORE_PROTOCOLS", "METRIC_PROTOCOL", "SSIM_PROTOCOL", "EQUALIZATIONS", "CLAHE_CLIP_LIMIT", "CLAHE_TILES"]

EQUALIZATIONS = ("none", "global", "clahe")   # every equalisation equalize() knows
# The protocols every result of the kit is reported under (run folders, batch summaries, the demo, the
# benchmarks, ablations): no equalisation, and CLAHE (the EvINR paper's). One constant, so that a
# table never silently drops one of the two.
SCORE_PROTOCOLS = ("none", "clahe")
CLAHE_CLIP_LIMIT = 2.0
CLAHE_TILES = (8, 8)

SSIM_PROTOCOL = ("SSIM: gaussian window sigma 1.5 (truncate 3.5, 11x11; 5 px borders excluded), K1 0.01, "
                 "K2 0.03, population covariance, data_range 1.0")
METRIC_PROTOCOL = ("prediction clipped to [0, 1], ground truth in [0, 1] (uint8 / 255); MSE on [0, 1]; " + SSIM_PROTOCOL
                   + "; LPIPS: AlexNet trunk, linear heads v0.1, grey copied to 3 channels, [0, 1] -> [-1, 1]")
PROTOCOLS = {
    "none": "no histogram equalisation; " + METRIC_PROTOCOL,
    "global": ("global histogram equalisation of both images (cv2.equalizeHist on uint8 round(255 x), "
               "back to [0, 1] as / 255); " + METRIC_PROTOCOL),
    "clahe": (f"CLAHE on both images (cv2.createCLAHE(clipLimit={CLAHE_CLIP_LIMIT}, tileGridSize={CLAHE_TILES}) "
              "on uint8 round(255 x), back to [0, 1] as / 255; the EvINR paper's protocol); " + METRIC_PROTOCOL),
}


def protocol_description(equalization: str = "none") -> str:
    """The full scoring protocol (equalisation and metric parameters) as one line of text."""
    return PROTOCOLS[choice(equalization, EQUALIZATIONS, "equalization")]


def _image(a, name: str) -> np.ndarray:
    """An image as float64: uint8 divided by 255 (as :func:`equalize` reads it), floats as they are; NaN, inf,
    text and empty images are refused (a metric of them would be NaN or meaningless). [H, W, 1] (a trailing
    channel of one, as image readers give) is the grey image [H, W]; other shapes (a number, a 1-D signal, a stack
    [F, H, W], colour [H, W, 3]) are refused naming the fix (no caller in the kit passes them)."""
    a = np.asarray(host_array(a))
    if a.ndim == 3 and a.shape[-1] == 1:
        a = a[..., 0]
    if a.dtype.kind not in "uif" or a.dtype == bool:
        raise EventDataError(f"{name} must be an image of numbers (uint8 0..255 or float in [0, 1]), got dtype {a.dtype}")
    if a.size == 0:
        raise EventDataError(f"{name} is empty (shape {a.shape}); pass an image [H, W]")
    if a.ndim != 2:   # a stack or a signal was scored as one image: its mean, or SSIM over a volume or a line
        fix = ("make it grey first (e.g. image.mean(axis=-1))" if a.ndim == 3 and a.shape[-1] in (3, 4) else
               "for a stack [F, H, W] use score_frames(pred, gt), or score each frame" if a.ndim == 3 else
               "a 1-D array (or a number) is not an image: reshape it to [H, W]" if a.ndim < 3 else
               "pass one grey image [H, W]")
        raise EventDataError(f"{name} must be one grey image [H, W] (or [H, W, 1]), got shape {a.shape}; {fix}")
    if a.dtype == np.uint8:
        return a.astype(np.float64) / 255.0
    if a.dtype.kind in "iu":   # uint16 / int64: refused with their own fix (cast to float, they read as 0..255)
        check_image_values(a, f"{name} values")
    a = a.astype(np.float64)
    if not np.all(np.isfinite(a)):
        raise EventDataError(f"{name} contains NaN or inf; repair or drop that frame (an image must be finite to be "
                             "scored)")
    return a


def _pair(pred, gt):
    pred = _image(pred, "prediction")
    check_image_values(pred, "predictions", clipped=True)   # 0..255 floats were clipped to white, not refused
    pred = np.clip(pred, 0.0, 1.0)
    gt = _image(gt, "ground truth")
    check_image_values(gt, "ground-truth images")   # floats on the 0..255 scale are refused, not scored
    if pred.shape != gt.shape:
        raise EventDataError(f"prediction {pred.shape} and ground truth {gt.shape} differ in shape")
    return pred, gt


def mse(pred, gt) -> float:
    """Mean squared error of two grey images [H, W] (or [H, W, 1]) in [0, 1] (prediction clipped first).

    Other shapes are refused: a stack [F, H, W] goes to :func:`score_frames`."""
    return _mse(*_pair(pred, gt))


def ssim(pred, gt) -> float:
    """SSIM of two grey images [H, W] (or [H, W, 1]) in [0, 1] (prediction clipped first); see the module
    docstring. Other shapes are refused (SSIM of a stack would be one 3-D SSIM over the volume): a stack
    [F, H, W] goes to :func:`score_frames`."""
    pred, gt = _pair(pred, gt)
    _check_ssim_size(pred.shape)
    return _ssim(pred, gt)


def _mse(pred: np.ndarray, gt: np.ndarray) -> float:
    """MSE of two float64 images already checked (:func:`_pair`, or :func:`score_pairs`' stacks)."""
    return float(np.mean((pred - gt) ** 2))


def _ssim(pred: np.ndarray, gt: np.ndarray) -> float:
    """SSIM of two float64 images already checked, of at least 11 x 11 pixels."""
    return float(structural_similarity(pred, gt, gaussian_weights=True, sigma=1.5,
                                       use_sample_covariance=False, data_range=1.0))


SSIM_MIN_SIDE = 11   # pixels: SSIM's gaussian window (sigma 1.5, truncated at 3.5 sigma) is 11 x 11


def _check_ssim_size(shape) -> None:
    if min(shape) < SSIM_MIN_SIDE:
        raise EventDataError(f"SSIM needs images of at least {SSIM_MIN_SIDE} x {SSIM_MIN_SIDE} pixels (its gaussian "
                             f"window), got {shape}")


def equalize(img, method: str = "none") -> np.ndarray:
    """Histogram equalisation of a grey image [H, W] in [0, 1] (or uint8).

    Args:
        method: "none" (clip to [0, 1] only), "global" (``cv2.equalizeHist``) or "clahe"
            (``cv2.createCLAHE(clipLimit=2.0, tileGridSize=(8, 8))``), both on ``to_uint8(img)``.

    Returns:
        float64 [H, W] in [0, 1].
    """
    method = choice(method, EQUALIZATIONS, "equalization")   # an array was numpy's "truth value ... is ambiguous"
    img = np.asarray(img)
    if img.ndim != 2:
        raise EventDataError(f"equalize takes one grey image [H, W], got shape {img.shape}")
    if img.dtype.kind == "f" and not np.all(np.isfinite(img)):   # NaN would become 0 silently
        raise EventDataError("the image to equalise contains NaN or inf; repair or drop that frame (an image must be "
                             "finite to be scored)")
    if img.size == 0:
        raise EventDataError(f"the image to equalise is empty (shape {img.shape}); pass an image [H, W]")
    check_image_values(img, "the image's values", clipped=True)   # 0..255 floats or uint16 became white
    if method == "none":
        if img.dtype == np.uint8:
            return img.astype(np.float64) / 255.0
        return np.clip(img.astype(np.float64), 0.0, 1.0)
    import cv2

    u = to_uint8(img)
    if method == "global":
        out = cv2.equalizeHist(u)
    else:
        out = cv2.createCLAHE(clipLimit=CLAHE_CLIP_LIMIT, tileGridSize=CLAHE_TILES).apply(u)
    return out.astype(np.float64) / 255.0


def score_pairs(pred, gt, equalization: str = "none") -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per-frame MSE and SSIM of matched frame pairs, after the same equalisation of both.

    The one scoring loop: :func:`score_frames` averages it, and
    :func:`evinr_lite.evaluation.scoring.score_sequence` runs it on timestamp-matched frames (and
    LPIPS on the equalised stacks it returns).

    Args:
        pred, gt: [F, H, W] each, in [0, 1] (or uint8), pair i is (pred[i], gt[i]).
        equalization: "none", "global" or "clahe" (:func:`equalize`).

    Returns:
        (pred_eq, gt_eq, mse, ssim): the equalised stacks float64 [F, H, W] in [0, 1], and the
        per-frame scores float64 [F].
    """
    pred, gt = image_stack(pred, "predicted frames"), image_stack(gt, "ground-truth frames")   # [F, H, W(, 1)]
    if len(pred) == 0 or len(pred) != len(gt):
        raise EventDataError(f"need one or more matched frame pairs, got {len(pred)} predictions and {len(gt)} "
                         "ground-truth frames; pass stacks [F, H, W] of the same length F >= 1")
    # the plausibility rule of Frames and the readers: NaN, and floats on the 0..255 scale, are refused
    check_image_values(gt, "ground-truth frames")
    check_image_values(pred, "predicted frames", clipped=True)   # clipped to [0, 1] below: small overshoot is fine
    pred_eq = np.stack([equalize(a, equalization) for a in pred])   # float64 in [0, 1], finite
    gt_eq = np.stack([equalize(b, equalization) for b in gt])
    if pred_eq.shape != gt_eq.shape:
        raise EventDataError(f"prediction {pred_eq.shape[1:]} and ground truth {gt_eq.shape[1:]} differ in shape")
    _check_ssim_size(pred_eq.shape[1:])
    # the stacks were checked above, once: the per-frame metrics need not check every frame again
    m = np.array([_mse(a, b) for a, b in zip(pred_eq, gt_eq)])
    s = np.array([_ssim(a, b) for a, b in zip(pred_eq, gt_eq)])
    return pred_eq, gt_eq, m, s


def score_frames(pred, gt, equalization: str = "none") -> dict:
    """Mean MSE and SSIM over frames [F, H, W] (both in [0, 1]) after the same equalisation of both.

    Frames are taken as already matched (for matching by timestamp and LPIPS see
    :func:`evinr_lite.evaluation.scoring.score_sequence`).

    Returns:
        {"mse": float, "ssim": float, "n_frames": int, "protocol": str}.
    """
    pred, gt = image_stack(pred, "predicted frames"), image_stack(gt, "ground-truth frames")   # [F, H, W(, 1)]
    if pred.shape != gt.shape or pred.ndim != 3:
        raise EventDataError(f"expected two [F, H, W] stacks of the same shape, got {pred.shape} and {gt.shape}")
    _, _, m, s = score_pairs(pred, gt, equalization)
    return {"mse": float(np.mean(m)), "ssim": float(np.mean(s)),
            "n_frames": len(m), "protocol": f"equalization={equalization}: " + protocol_description(equalization)}
