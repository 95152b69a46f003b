"""Choosing where torch runs: a GPU when present, never required."""
from __future__ import annotations

import os

import torch

__all__ = ["default_device"]


def default_device(preference: str | None = None) -> torch.device:
    """The torch device to use.

    Args:
        preference: "cpu", "cuda" or None (auto: cuda when available, else cpu). The
            environment variable ``EVINR_DEVICE`` overrides auto. (Apple's "mps" can be asked for
            explicitly, but it has no float64, which event timestamps need, so auto never picks it.)

    Raises:
        RuntimeError: if a device is asked for that this machine does not have.
    """
    preference = preference or os.environ.get("EVINR_DEVICE") or "auto"
    if preference == "auto":
        if torch.cuda.is_available():
            return torch.device("cuda")
        return torch.device("cpu")
    if preference.startswith("cuda") and not torch.cuda.is_available():
        raise RuntimeError("device 'cuda' requested but no CUDA GPU is available here; use device='cpu'")
    return torch.device(preference)
