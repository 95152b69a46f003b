"""Runtime choices shared by every layer: where torch runs, fast mode, and the cache folder.

- ``default_device``: a GPU when present, never required (``EVINR_DEVICE`` overrides).
- ``cpu_threads``: how many threads the kit's numpy / scipy work may use (torch's thread count,
  which the command line and batch workers set).
- ``fast_mode`` / ``pick``: smaller sizes and fewer iterations so that every notebook runs in CI
  within minutes. Switched by ``EVINR_FAST`` ("1" on, "0" off); when it is unset, fast mode is on
  under pytest/nbval (``tests/conftest.py`` sets it) and in CI (``CI`` set).
- ``cache_dir`` / ``weights_dir``: where downloads, converted sequences and model weights live
  (``$EVINR_DATA`` or ``~/.cache/evinr-lite``); ``data_fetch`` writes there, the kit reads there.
- ``command_page_policy``: the commands' numpy arrays on ordinary memory pages, not transparent
  huge pages (``NUMPY_MADVISE_HUGEPAGE``; why below).
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

from .guard import InputError   # standard library only: the command's start-up stays light

__all__ = ["default_device", "DeviceUnavailable", "cpu_threads", "fast_mode", "pick", "cache_dir", "weights_dir", "FAST_ENV_VAR", "CACHE_ENV_VAR",
           "command_page_policy", "HUGEPAGE_ENV_VAR"]

CACHE_ENV_VAR = "EVINR_DATA"


class DeviceUnavailable(InputError, RuntimeError):
    """A device was asked for that this machine does not have (a bad input: the message names the device to
    use instead); still a RuntimeError, as it was."""


def default_device(preference: str | None = None) -> "torch.device":
    """The torch device to use.

    Args:
        preference: "cpu", "cuda" or None (auto: cuda when available, else cpu). The
            environment variable ``EVINR_DEVICE`` overrides auto (a bad value there is named as
            EVINR_DEVICE's). (Apple's "mps" can be asked for explicitly, but it has no float64, which
            event timestamps need, so auto never picks it.)

    Raises:
        DeviceUnavailable (an InputError and a RuntimeError): a device this machine does not have
        ("cuda" without a CUDA GPU, "cuda:N" beyond the GPUs, "mps" without an Apple GPU).
    """
    import torch   # here, not at the top: data_fetch and the command's --help stay light

    if preference is not None and not isinstance(preference, str):   # a torch.device: its name, as torch takes it
        if not isinstance(preference, torch.device):
            # 5, True or a list were Python's "has no attribute 'startswith'", 0 and [] read as None
            raise DeviceUnavailable(f"device= must be 'cpu', 'cuda', 'cuda:N', 'mps' or None (a GPU when present), "
                                    f"got {type(preference).__name__} {preference!r}")
        preference = str(preference)
    from_env = not preference and bool(os.environ.get("EVINR_DEVICE"))
    preference = preference or os.environ.get("EVINR_DEVICE") or "auto"
    if preference == "auto":
        if torch.cuda.is_available():
            return torch.device("cuda")
        return torch.device("cpu")
    # a value from the environment is named as such, with the fix there (device= is not what the caller passed)
    asked = f"EVINR_DEVICE={preference!r}" if from_env else f"device {preference!r}"

    def fix(use: str) -> str:
        return f"unset EVINR_DEVICE or set it to {use}" if from_env else \
            f"use device='{use}' (or None: a GPU when present)"

    if preference.startswith("cuda") and not torch.cuda.is_available():
        raise DeviceUnavailable(f"{asked} requested but no CUDA GPU is available here; {fix('cpu')}")
    if preference.startswith("cuda:") and preference[5:].isdigit() and int(preference[5:]) >= torch.cuda.device_count():
        raise DeviceUnavailable(f"{asked} requested but this machine has {torch.cuda.device_count()} CUDA "
                                f"GPU(s), numbered from 0; " + ("unset EVINR_DEVICE or set it to cuda:0 (or cuda)"
                                                                 if from_env else "use device='cuda:0' (or 'cuda')"))
    if preference == "mps" and not (hasattr(torch.backends, "mps") and torch.backends.mps.is_available()):
        raise DeviceUnavailable(f"{asked} requested but no Apple GPU (MPS) is available here; {fix('cpu')}")
    try:
        return torch.device(preference)
    except RuntimeError:   # "x" was torch's "Expected one of cpu, cuda, ipu, xpu, ..." naming no argument
        if from_env:
            raise DeviceUnavailable(f"EVINR_DEVICE={preference!r} is no device name; unset it or set it to cpu, cuda, "
                                    "cuda:N or mps") from None
        raise DeviceUnavailable(f"device {preference!r} is no device name; use device='cpu', 'cuda', 'cuda:N', 'mps' "
                                "or None (a GPU when present)") from None


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


HUGEPAGE_ENV_VAR = "NUMPY_MADVISE_HUGEPAGE"


def command_page_policy() -> bool:
    """Ask numpy for ordinary (4 KiB) memory pages for the rest of this process, unless the user chose
    (``NUMPY_MADVISE_HUGEPAGE`` set) or numpy is already imported (numpy reads the variable once, when
    it is imported); returns whether the setting was made. ``evinr-lite`` and ``python -m data_fetch``
    call it on their first line, when they are the process; a library call leaves numpy as it is.

    Why: numpy asks the kernel for transparent huge pages (2 MiB) for every array of 4 MiB and more.
    On virtual machines that back their memory lazily, as the machines this kit is developed and tested
    on do, a huge page touched for the first time is far dearer than ordinary pages: 1.5 GB of fresh
    float32 arrays took 9.1-9.6 s there against 0.6-0.7 s without huge pages (a new process each, 6 s
    apart), and a 1280x720 2 s ``reconstruct``, whose arrays reach 1.5 GB, spent 10 of its 22 s in
    the kernel (docs/scale.md). Arrays below 4 MiB (a 240x180 scene's) are not affected, and on a
    machine where huge pages pay, ``NUMPY_MADVISE_HUGEPAGE=1`` keeps them."""
    if HUGEPAGE_ENV_VAR in os.environ or "numpy" in sys.modules:
        return False
    os.environ[HUGEPAGE_ENV_VAR] = "0"
    return True
