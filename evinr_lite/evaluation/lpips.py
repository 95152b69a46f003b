"""LPIPS (Zhang et al. 2018), AlexNet backbone, linear heads v0.1, without torchvision.

    model = load_lpips()                      # LPIPSUnavailable (with the fetch command) if no weights
    d = lpips_distance(pred, gt, model)       # grey [H, W] images in [0, 1] -> float, 0 = identical

The network is what the reference ``lpips`` package computes for ``LPIPS(net="alex", version="0.1")``:

1. grey images are copied to 3 channels and mapped from [0, 1] to [-1, 1];
2. a fixed scaling layer: (x - shift) / scale per channel (:data:`SHIFT`, :data:`SCALE`);
3. AlexNet's convolutional trunk (torchvision's ``features`` up to the fifth ReLU); the five ReLU
   outputs (64, 192, 384, 256, 256 channels) are the features;
4. per layer: each feature vector is divided by its L2 norm over channels (+1e-10), the squared
   difference of the two images' normalised features is weighted per channel by a 1x1 linear head
   (no bias; ``lin{k}.model.1.weight`` [1, C, 1, 1]) and averaged over space;
5. the distance is the sum of the five layer terms.

Weights: torchvision's ImageNet AlexNet (``alexnet-owt-7be5be79.pth``; only the ``features.*``
tensors are used) and the LPIPS v0.1 heads (``alex.pth``). Fetch them once with
``python -m data_fetch get lpips all`` (sha256-pinned, cached in ``<cache>/weights/lpips/``).
State-dict key names are torchvision's and lpips' own, so the published files load unchanged.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import torch
from torch import nn

from ..core.checks import blank_path, check_image_values, check_path_type, numbers_array
from ..core.events import EventDataError
from ..core.runtime import weights_dir

__all__ = ["LPIPS", "LPIPSUnavailable", "load_lpips", "lpips_distance", "lpips_distances", "lpips_paths",
           "FETCH_COMMAND", "ALEXNET_FILE", "LINEAR_FILE", "SHIFT", "SCALE", "CHANNELS"]

FETCH_COMMAND = "python -m data_fetch get lpips all"
ALEXNET_FILE = "alexnet-owt-7be5be79.pth"
LINEAR_FILE = "alex.pth"
SHIFT = (-0.030, -0.088, -0.188)    # the LPIPS scaling layer: (x - shift) / scale, per RGB channel
SCALE = (0.458, 0.448, 0.450)
CHANNELS = (64, 192, 384, 256, 256)  # channels of the five AlexNet ReLU outputs
_TAPS = (1, 4, 7, 9, 11)             # indices of those ReLUs in torchvision's `features`
MIN_SIZE = 32                        # smaller images vanish in AlexNet's strides and pools
EPS = 1e-10


class LPIPSUnavailable(RuntimeError):
    """The LPIPS weight files are not in the cache; the message says how to fetch them."""


class _LinearHead(nn.Module):
    """lpips' ``NetLinLayer``: dropout (identity in eval mode) then a 1x1 convolution without bias."""

    def __init__(self, channels: int):
        super().__init__()
        self.model = nn.Sequential(nn.Dropout(), nn.Conv2d(channels, 1, 1, bias=False))

    def forward(self, x):
        return self.model(x)


class LPIPS(nn.Module):
    """LPIPS distance with an AlexNet trunk and v0.1 linear heads (weights loaded separately).

    ``forward(x0, x1)`` takes two RGB batches [B, 3, H, W] in [-1, 1] and returns [B] distances.
    Parameters: ``features.{0,3,6,8,10}.{weight,bias}`` (torchvision's names) and
    ``lin{0..4}.model.1.weight``; the scaling constants are buffers outside the state dict.
    """

    def __init__(self):
        super().__init__()
        c = CHANNELS
        self.features = nn.Sequential(
            nn.Conv2d(3, c[0], 11, stride=4, padding=2), nn.ReLU(), nn.MaxPool2d(3, 2),
            nn.Conv2d(c[0], c[1], 5, padding=2), nn.ReLU(), nn.MaxPool2d(3, 2),
            nn.Conv2d(c[1], c[2], 3, padding=1), nn.ReLU(),
            nn.Conv2d(c[2], c[3], 3, padding=1), nn.ReLU(),
            nn.Conv2d(c[3], c[4], 3, padding=1), nn.ReLU(),
        )
        for k, ch in enumerate(c):
            self.add_module(f"lin{k}", _LinearHead(ch))
        self.register_buffer("shift", torch.tensor(SHIFT).view(1, 3, 1, 1), persistent=False)
        self.register_buffer("scale", torch.tensor(SCALE).view(1, 3, 1, 1), persistent=False)
        self.eval()

    def layer_features(self, x: torch.Tensor) -> list[torch.Tensor]:
        """The five ReLU outputs for RGB input [B, 3, H, W] in [-1, 1] (after the scaling layer)."""
        h = (x - self.shift) / self.scale
        out = []
        for i, layer in enumerate(self.features):
            h = layer(h)
            if i in _TAPS:
                out.append(h)
        return out

    def forward(self, x0: torch.Tensor, x1: torch.Tensor) -> torch.Tensor:
        if x0.shape != x1.shape or x0.ndim != 4 or x0.shape[1] != 3:
            raise ValueError(f"LPIPS takes two RGB batches [B, 3, H, W] of one shape, got {tuple(x0.shape)} "
                             f"and {tuple(x1.shape)}")
        if min(x0.shape[-2:]) < MIN_SIZE:
            raise EventDataError(f"LPIPS needs images of at least {MIN_SIZE} x {MIN_SIZE} pixels, got {tuple(x0.shape[-2:])}")
        total = 0
        for k, (f0, f1) in enumerate(zip(self.layer_features(x0), self.layer_features(x1))):
            n0 = f0 / (f0.pow(2).sum(dim=1, keepdim=True).sqrt() + EPS)
            n1 = f1 / (f1.pow(2).sum(dim=1, keepdim=True).sqrt() + EPS)
            total = total + getattr(self, f"lin{k}")((n0 - n1) ** 2).mean(dim=(2, 3))
        return total[:, 0]

    def load_weights(self, alexnet_state: dict, linear_state: dict) -> "LPIPS":
        """Load torchvision AlexNet's ``features.*`` tensors and the ``lin*`` heads (other keys ignored).

        Raises:
            ValueError: a tensor is missing or has the wrong shape (names which, and what was expected).
        """
        own = self.state_dict()
        merged = {}
        for source, prefix, name in ((alexnet_state, "features.", ALEXNET_FILE), (linear_state, "lin", LINEAR_FILE)):
            for key in (k for k in own if k.startswith(prefix)):
                if key not in source:
                    raise ValueError(f"{name}: tensor {key!r} is missing (it holds {sorted(source)[:6]}...); "
                                     f"is this the right file? Fetch the published one with `{FETCH_COMMAND}`")
                value = torch.as_tensor(source[key])
                if tuple(value.shape) != tuple(own[key].shape):
                    raise ValueError(f"{name}: tensor {key!r} has shape {tuple(value.shape)}, expected "
                                     f"{tuple(own[key].shape)}")
                merged[key] = value.float()
        self.load_state_dict(merged)
        return self


def lpips_paths(cache_dir=None) -> tuple[Path, Path]:
    """(AlexNet file, linear-heads file) in ``cache_dir`` (default: ``<cache>/weights/lpips``, where
    ``python -m data_fetch get lpips all`` puts them)."""
    if cache_dir is not None:   # a number or a list was Python's "expected str, bytes or os.PathLike object"
        check_path_type(cache_dir, "cache_dir", "a folder holding the LPIPS weights",
                        "or None for the kit's cache (where `python -m data_fetch get lpips all` puts them)")
        if blank_path(cache_dir):   # "" was the current folder (Path(".") names it on purpose)
            raise EventDataError(f"cache_dir= is empty ({cache_dir!r}, blank text, which paths read as the current folder): pass the folder holding the LPIPS weights "
                                 "(Path.cwd() for the current folder), or None for the kit's cache")
    cache_dir = Path(weights_dir("lpips") if cache_dir is None else cache_dir)
    return cache_dir / ALEXNET_FILE, cache_dir / LINEAR_FILE


def load_lpips(cache_dir=None, device=None) -> LPIPS:
    """The LPIPS(alex, v0.1) network with the published weights, in eval mode on ``device``.

    Args:
        cache_dir: folder holding ``alexnet-owt-7be5be79.pth`` and ``alex.pth`` (default: where
            ``python -m data_fetch get lpips all`` puts them).
        device: torch device or name (default: :func:`evinr_lite.core.runtime.default_device`).

    Raises:
        LPIPSUnavailable: a weight file is absent; the message names the command that fetches it.
    """
    from ..core.runtime import default_device

    alex, lin = lpips_paths(cache_dir)
    missing = [p for p in (alex, lin) if not p.is_file()]
    if missing:
        raise LPIPSUnavailable(
            f"LPIPS is unavailable: {', '.join(str(p) for p in missing)} not found. Fetch the two weight files "
            f"(about 233 MB, sha256-pinned) once with `{FETCH_COMMAND}`, or place them there by hand.")
    model = LPIPS().load_weights(torch.load(alex, map_location="cpu", weights_only=True),
                                 torch.load(lin, map_location="cpu", weights_only=True))
    device = default_device(device) if device is None or isinstance(device, str) else device
    return model.to(device).eval()


def _as_batch(images, device) -> torch.Tensor:
    """Grey [F, H, W] in [0, 1] (clipped; uint8 / 255) -> RGB [F, 3, H, W] in [-1, 1]."""
    a = np.asarray(images)
    a = a.astype(np.float32) / 255.0 if a.dtype == np.uint8 else np.clip(a.astype(np.float32), 0.0, 1.0)
    t = torch.as_tensor(a, device=device)[:, None]
    return (2.0 * t - 1.0).expand(-1, 3, -1, -1)


@torch.no_grad()
def lpips_distances(pred, gt, model: LPIPS, batch_size: int = 8) -> np.ndarray:
    """LPIPS of matched grey frames: pred, gt [F, H, W] in [0, 1] -> float64 [F] (0 = identical)."""
    pred, gt = np.asarray(pred), np.asarray(gt)
    if pred.shape != gt.shape or pred.ndim != 3:
        raise ValueError(f"expected two [F, H, W] stacks of the same shape, got {pred.shape} and {gt.shape}")
    device = next(model.parameters()).device
    out = []
    for i in range(0, len(pred), batch_size):
        d = model(_as_batch(pred[i:i + batch_size], device), _as_batch(gt[i:i + batch_size], device))
        out.append(d.double().cpu().numpy())
    return np.concatenate(out) if out else np.zeros(0)


def lpips_distance(pred, gt, model: LPIPS) -> float:
    """LPIPS of two grey images [H, W] in [0, 1] (copied to 3 channels, mapped to [-1, 1])."""
    if not isinstance(model, LPIPS):   # None was "has no attribute 'parameters'"
        raise EventDataError(f"model= must be the LPIPS network, got {type(model).__name__}; load it with "
                             f"load_lpips() (its weights: `{FETCH_COMMAND}`)")
    pred, gt = (numbers_array(a, name, "a grey image [H, W] in [0, 1]") for a, name in ((pred, "pred"), (gt, "gt")))
    if pred.ndim != 2 or pred.shape != gt.shape:
        raise EventDataError(f"expected two grey images [H, W] of one shape, got {pred.shape} and {gt.shape}; "
                             "pass pred and gt as grey images [H, W] of one size")
    for a, name in ((pred, "pred"), (gt, "gt")):   # NaN gave NaN; floats in 0..255 were clipped to white
        check_image_values(a, name, clipped=True)
    return float(lpips_distances(pred[None], gt[None], model)[0])
