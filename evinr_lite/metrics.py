"""Image quality metrics with a stated protocol (MSE, SSIM on [0, 1] floats).

SSIM follows EVREAL's current protocol: gaussian window sigma 1.5, no sample covariance,
K1 = 0.01, K2 = 0.03 and data_range = 1.0 (scikit-image would otherwise assume 2 for floats).
"""
from __future__ import annotations

import numpy as np
from skimage.metrics import structural_similarity

__all__ = ["mse", "ssim", "SSIM_PROTOCOL"]

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
