"""What a learner's call can change for the whole notebook: torch's global settings and the global generators.

A function may switch gradients off (or on), change torch's default dtype, or seed numpy's, Python's or torch's
global random generator. The check reads these before and after each call: :func:`torch_settings` and
:func:`restore_torch_settings` set torch's settings back (:func:`settings_message` names the change), and
:func:`rng_states`, :func:`other_rng_states` and :func:`reseeded_generators` tell a function that seeds a generator
(two runs from different states end in one state) from one that only draws from it. Kept apart from running the
call (:mod:`.learner_calls`), which uses the settings half, and from the hints built on the generators' states
(:mod:`.across_calls`).
"""
from __future__ import annotations

import random
import sys

import numpy as np

from .outputs import is_tensor


def torch_settings() -> dict | None:
    """torch's global settings a function may change for the whole notebook: gradients on or off, the default
    float dtype; None when torch is not imported."""
    torch = sys.modules.get("torch")
    if torch is None:
        return None
    return {"grad": torch.is_grad_enabled(), "dtype": torch.get_default_dtype()}


def restore_torch_settings(before: dict | None) -> dict:
    """The settings changed since ``before`` ({name: (before, now)}), each set back to what it was."""
    torch = sys.modules.get("torch")
    if before is None or torch is None:
        return {}
    now = torch_settings()
    changed = {k: (before[k], now[k]) for k in before if now[k] != before[k]}
    if "grad" in changed:
        torch.set_grad_enabled(before["grad"])
    if "dtype" in changed:
        torch.set_default_dtype(before["dtype"])
    return changed


def settings_message(changed: dict) -> str:
    parts = []
    if "grad" in changed and changed["grad"][0]:
        parts.append("it turned gradients off for the whole notebook (torch.set_grad_enabled(False), or "
                     "torch.no_grad().__enter__() without its exit), so every later training step runs without "
                     "autograd; use `with torch.no_grad():` around the lines that need it, which switches gradients "
                     "back on at its end")
    elif "grad" in changed:
        parts.append("it turned gradients on for the whole notebook (torch.set_grad_enabled(True)), where an earlier "
                     "cell had switched them off: the cells after it now record autograd graphs the notebook chose "
                     "to do without; use `with torch.enable_grad():` around the lines that need gradients, which "
                     "leaves the notebook's setting as it was at its end")
    if "dtype" in changed:
        parts.append(f"it changed torch's default dtype from {changed['dtype'][0]} to {changed['dtype'][1]} "
                     "(torch.set_default_dtype) for the whole notebook, so every tensor made later (a model's "
                     "weights, torch.zeros, torch.tensor of floats) has the new dtype; give the dtype where you need "
                     "it (x.double(), torch.zeros(..., dtype=torch.float64)) and leave the default alone")
    return "; and ".join(parts) + " (the check has set it back)"


def rng_states() -> dict:
    """The states of the global random generators a learner may seed: numpy's, Python's, torch's (CPU)."""
    states = {"numpy": np.random.get_state(), "random": random.getstate()}
    torch = sys.modules.get("torch")
    if torch is not None:
        states["torch"] = torch.random.get_rng_state()
    return states


def set_rng_states(states: dict) -> None:
    np.random.set_state(states["numpy"])
    random.setstate(states["random"])
    torch = sys.modules.get("torch")
    if torch is not None and "torch" in states:
        torch.random.set_rng_state(states["torch"])


def other_rng_states(states: dict) -> dict:
    """States of the global generators that differ from ``states`` (built from generators of their own, so that
    nothing else is seeded: CUDA's generators stay as they are)."""
    for seed in (20240607, 7):
        other = {"numpy": np.random.RandomState(seed).get_state(), "random": random.Random(seed).getstate()}
        torch = sys.modules.get("torch")
        if torch is not None:
            other["torch"] = torch.Generator().manual_seed(seed).get_state()
        if not any(same_rng_state(states[k], other[k]) for k in other if k in states):
            return other
    return other


def same_rng_state(a, b) -> bool:
    if isinstance(a, tuple) and isinstance(b, tuple):
        return len(a) == len(b) and all(same_rng_state(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return bool(np.array_equal(a, b))
    if is_tensor(a) and is_tensor(b):
        return a.shape == b.shape and bool((a == b).all())
    return a == b


SEED_CALLS = {"numpy": "np.random.seed", "random": "random.seed", "torch": "torch.manual_seed"}


def reseeded_generators(before: dict, other: dict, after: dict, again: dict) -> list[str]:
    """The generators that two runs, started from different states (``before``, ``other``), left in one state
    (``after``, ``again``): the function seeded them."""
    out = []
    for name, call in SEED_CALLS.items():
        if all(name in d for d in (before, other, after, again)):
            try:
                if not same_rng_state(before[name], other[name]) and same_rng_state(after[name], again[name]):
                    out.append(call)
            except Exception:
                continue
    return out
