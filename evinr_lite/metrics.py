"""Image quality metrics with a stated protocol (MSE, SSIM on [0, 1] floats).

SSIM follows EVREAL's current protocol: gaussian window sigma 1.5, no sample covariance,
K1 = 0.01, K2 = 0.03 and data_range = 1.0 (scikit-image would otherwise assume 2 for floats).

Optional histogram equalisation of both images before scoring (``equalize``): "none", "global",
or "clahe" (the EvINR paper's protocol). CLAHE here is scikit-image's ``equalize_adapthist`` on
the image quantised to 256 levels, with 8 x 8 tiles and clip limit 0.01 (a fraction of each tile's
pixels), which approximates OpenCV's clipLimit 2.0 (2 x the mean bin height of 256 bins).
"""
from __future__ import annotations

import numpy as np
from skimage.metrics import structural_similarity

__all__ = ["mse", "ssim", "equalize", "score_frames", "SSIM_PROTOCOL", "EQUALIZATIONS"]

EQUALIZATIONS = ("none", "global", "clahe")

SSIM_PROTOCOL = "SSIM: gaussian window sigma 1.5, data_range 1.0, no equalisation; images clipped to [0, 1]"


def _pair(pred, gt):
    pred = np.clip(np.asarray(pred, dtype=np.float64), 0.0, 1.0)
    gt = np.asarray(gt, dtype=np.float64)
    if pred.shape != gt.shape:
        raise ValueError(f"prediction {pred.shape} and ground truth {gt.shape} differ in shape")
    return pred, gt


def mse(pred, gt) -> float:
    """Mean squared error of images in [0, 1] (prediction clipped first). Shapes [H, W]."""
    pred, gt = _pair(pred, gt)
    return float(np.mean((pred - gt) ** 2))


def ssim(pred, gt) -> float:
    """SSIM of two grey images [H, W] in [0, 1] (prediction clipped first)."""
    pred, gt = _pair(pred, gt)
    return float(structural_similarity(pred, gt, gaussian_weights=True, sigma=1.5,
                                       use_sample_covariance=False, data_range=1.0))


def equalize(img, method: str = "none") -> np.ndarray:
    """Histogram equalisation of a grey image [H, W] in [0, 1]: "none", "global" or "clahe"."""
    from skimage import exposure

    img = np.clip(np.asarray(img, dtype=np.float64), 0.0, 1.0)
    if method == "none":
        return img
    img = np.round(img * 255) / 255  # as the protocol does on uint8
    if method == "global":
        return exposure.equalize_hist(img, nbins=256)
    if method == "clahe":
        H, W = img.shape
        return exposure.equalize_adapthist(img, kernel_size=(max(H // 8, 1), max(W // 8, 1)),
                                           clip_limit=0.01, nbins=256)
    raise ValueError(f"equalization must be one of {EQUALIZATIONS}, got {method!r}")


def score_frames(pred, gt, equalization: str = "none") -> dict:
    """Mean MSE and SSIM over frames [F, H, W] (both in [0, 1]) after the same equalisation of both.

    Returns {"mse": float, "ssim": float, "n_frames": int, "protocol": str}.
    """
    pred, gt = np.asarray(pred), np.asarray(gt)
    if pred.shape != gt.shape or pred.ndim != 3:
        raise ValueError(f"expected two [F, H, W] stacks of the same shape, got {pred.shape} and {gt.shape}")
    p = [equalize(a, equalization) for a in pred]
    g = [equalize(b, equalization) for b in gt]
    return {"mse": float(np.mean([mse(a, b) for a, b in zip(p, g)])),
            "ssim": float(np.mean([ssim(a, b) for a, b in zip(p, g)])),
            "n_frames": len(p), "protocol": f"equalization={equalization}; " + SSIM_PROTOCOL.replace(", no equalisation", "")}
