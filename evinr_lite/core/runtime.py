"""Runtime choices shared by every layer: where torch runs, fast mode, and the cache folder.

- ``default_device``: a GPU when present, never required (``EVINR_DEVICE`` overrides).
- ``cpu_threads``: how many threads the kit's numpy / scipy work may use (torch's thread count,
  which the command line and batch workers set).
- ``fast_mode`` / ``pick``: smaller sizes and fewer iterations so that every notebook runs in CI
  within minutes. Switched by ``EVINR_FAST`` ("1" on, "0" off); when it is unset, fast mode is on
  under pytest/nbval (``tests/conftest.py`` sets it) and in CI (``CI`` set).
- ``cache_dir`` / ``weights_dir``: where downloads, converted sequences and model weights live
  (``$EVINR_DATA`` or ``~/.cache/evinr-lite``); ``data_fetch`` writes there, the kit reads there.
"""
from __future__ import annotations

import os
from pathlib import Path

from .guard import InputError   # standard library only: the command's start-up stays light

__all__ = ["default_device", "DeviceUnavailable", "cpu_threads", "fast_mode", "pick", "cache_dir", "weights_dir", "FAST_ENV_VAR", "CACHE_ENV_VAR"]

CACHE_ENV_VAR = "EVINR_DATA"


class DeviceUnavailable(InputError, RuntimeError):
    """A device was asked for that this machine does not have (a bad input: the message names the device to
    use instead); still a RuntimeError, as it was."""


def default_device(preference: str | None = None) -> "torch.device":
    """The torch device to use.

    Args:
        preference: "cpu", "cuda" or None (auto: cuda when available, else cpu). The
            environment variable ``EVINR_DEVICE`` overrides auto. (Apple's "mps" can be asked for
            explicitly, but it has no float64, which event timestamps need, so auto never picks it.)

    Raises:
        DeviceUnavailable (an InputError and a RuntimeError): a device this machine does not have
        ("cuda" without a CUDA GPU, "cuda:N" beyond the GPUs, "mps" without an Apple GPU).
    """
    import torch   # here, not at the top: data_fetch and the command's --help stay light

    preference = preference or os.environ.get("EVINR_DEVICE") or "auto"
    if preference == "auto":
        if torch.cuda.is_available():
            return torch.device("cuda")
        return torch.device("cpu")
    if preference.startswith("cuda") and not torch.cuda.is_available():
        raise DeviceUnavailable(f"device {preference!r} requested but no CUDA GPU is available here; use device='cpu' "
                                "(or None: a GPU when present)")
    if preference.startswith("cuda:") and preference[5:].isdigit() and int(preference[5:]) >= torch.cuda.device_count():
        raise DeviceUnavailable(f"device {preference!r} requested but this machine has {torch.cuda.device_count()} CUDA "
                                f"GPU(s), numbered from 0; use device='cuda:0' (or 'cuda')")
    if preference == "mps" and not (hasattr(torch.backends, "mps") and torch.backends.mps.is_available()):
        raise DeviceUnavailable("device 'mps' requested but no Apple GPU (MPS) is available here; use device='cpu' "
                                "(or None: a GPU when present)")
    return torch.device(preference)


def cpu_threads() -> int:
    """Threads for CPU work outside torch (scipy's DCT workers, the offset's median blocks): torch's own
    thread count, so one setting (``--torch-threads``, a batch worker's share) governs both."""
    import torch

    return max(1, torch.get_num_threads())


FAST_ENV_VAR = "EVINR_FAST"


def fast_mode() -> bool:
    """True when notebooks and examples should use their small sizes."""
    value = os.environ.get(FAST_ENV_VAR)
    if value is not None:
        return value.strip().lower() not in ("", "0", "false", "no", "off")
    return bool(os.environ.get("CI")) or "PYTEST_CURRENT_TEST" in os.environ


def pick(fast, full):
    """``fast`` in fast mode, ``full`` otherwise (e.g. ``n_iters = pick(50, 300)``)."""
    return fast if fast_mode() else full


def cache_dir() -> Path:
    """Folder for downloads, converted sequences and weights: ``$EVINR_DATA`` or ``~/.cache/evinr-lite``."""
    return Path(os.environ.get(CACHE_ENV_VAR) or Path.home() / ".cache" / "evinr-lite").expanduser()


def weights_dir(name: str) -> Path:
    """Folder of a weight set (e.g. "lpips"): ``<cache>/weights/<name>``."""
    return cache_dir() / "weights" / name.lower()
