"""Fast mode: smaller sizes and fewer iterations so that every notebook runs in CI within minutes.

Switched by one environment variable, ``EVINR_FAST`` ("1" on, "0" off). When it is unset,
fast mode is on under pytest/nbval (``tests/conftest.py`` sets it) and in CI (``CI`` set).
"""
from __future__ import annotations

import os

__all__ = ["fast_mode", "pick"]

ENV_VAR = "EVINR_FAST"


def fast_mode() -> bool:
    """True when notebooks and examples should use their small sizes."""
    value = os.environ.get(ENV_VAR)
    if value is not None:
        return value.strip().lower() not in ("", "0", "false", "no", "off")
    return bool(os.environ.get("CI")) or "PYTEST_CURRENT_TEST" in os.environ


def pick(fast, full):
    """``fast`` in fast mode, ``full`` otherwise (e.g. ``n_iters = pick(50, 300)``)."""
    return fast if fast_mode() else full
