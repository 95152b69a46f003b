"""What a learner's call can change for the whole notebook: torch's, numpy's and the warnings' global settings, and
the global generators.

A function may switch gradients off (or on), change torch's default dtype, change numpy's floating-point error
handling (np.seterr) or the warning filters (warnings.filterwarnings, warnings.simplefilter), or seed numpy's,
Python's or torch's global random generator. The check reads these before and after each call:
:func:`global_settings` and :func:`restore_settings` set the settings back (:func:`settings_message` names the
change; the warning filters a module adds while its code is run by an import, which :func:`imports_watched` gathers
from the adding thread's own stack, are the module's and stay), and :func:`rng_states`, :func:`other_rng_states` and
:func:`reseeded_generators` tell a function that seeds a generator (two runs from different states end in one
state) from one that only draws from it. Kept apart from running the call (:mod:`.learner_calls`), which uses the
settings half, and from the hints built on the generators' states (:mod:`.across_calls`).
"""
from __future__ import annotations

import builtins
import functools
import importlib
import random
import sys
import threading
import warnings
from typing import Callable

import numpy as np

from .outputs import is_tensor


def global_settings() -> dict:
    """The global settings a function may change for the whole notebook: numpy's floating-point error handling,
    the warning filters, and (once torch is imported) torch's gradients on or off, default float dtype, autograd's
    anomaly detection and deterministic algorithms (each with its second flag: NaN checks, warnings only)."""
    out = {"numpy errors": np.geterr(), "warning filters": tuple(warnings.filters)}
    torch = sys.modules.get("torch")
    if torch is not None:
        out.update(grad=torch.is_grad_enabled(), dtype=torch.get_default_dtype())
        nan = getattr(torch, "is_anomaly_check_nan_enabled", lambda: True)
        warn_only = getattr(torch, "is_deterministic_algorithms_warn_only_enabled", lambda: False)
        out.update(anomaly=(torch.is_anomaly_enabled(), nan()),
                   deterministic=(torch.are_deterministic_algorithms_enabled(), warn_only()))
    return out


class _Watch:
    """One open :func:`imports_watched`: the list it yields, and the frame of the code that opened it (a filter is
    this watch's module's only where an import frame lies between that frame and the code that adds the filter)."""
    __slots__ = ("added", "frame")

    def __init__(self, frame):
        self.added: list = []
        self.frame = frame


_WATCHES: dict[int, list[_Watch]] = {}   # thread id -> that thread's open watches, innermost last
_WATCHES_LOCK = threading.RLock()
_HOOKED: list = []      # (where, name, original, wrapper) while a watch is open anywhere
_BOOTSTRAP = ("<frozen importlib._bootstrap>", "<frozen importlib._bootstrap_external>")


def _hookable() -> bool:
    """Whether warnings.filterwarnings and warnings.simplefilter both add through warnings._add_filter (CPython 3.11,
    3.12), which can then be watched; elsewhere the import calls are (:func:`_watched`)."""
    if not callable(getattr(warnings, "_add_filter", None)):
        return False
    codes = [getattr(getattr(warnings, f, None), "__code__", None) for f in ("filterwarnings", "simplefilter")]
    return all(code is not None and "_add_filter" in code.co_names for code in codes)


def _import_frame(frame) -> bool:
    """A frame of the import machinery (importlib's bootstrap: an import statement, __import__,
    importlib.import_module, a LazyLoader's module on first use, importlib.reload), or the top level of a module
    other than the notebook's (``__main__``) while it runs."""
    code = frame.f_code
    if code.co_filename in _BOOTSTRAP:
        return True
    if code.co_name != "<module>":
        return False
    name = frame.f_globals.get("__name__")
    module = sys.modules.get(name) if isinstance(name, str) and name != "__main__" else None
    try:       # object.__getattribute__: a LazyLoader's module not loaded yet would load on a plain attribute read
        return module is not None and object.__getattribute__(module, "__dict__") is frame.f_globals
    except Exception:
        return False


def _note_module_filter(entry, frame) -> None:
    """Give ``entry``, a filter just added by code running in ``frame`` (the caller of warnings._add_filter), to the
    watches it is a module's for: a watch of this thread when an import frame lies between the watch's own frame
    and ``frame``; every other thread's watch when this thread's stack holds an import frame at all."""
    with _WATCHES_LOCK:
        own = list(_WATCHES.get(threading.get_ident(), ()))
        others = [w for t, ws in _WATCHES.items() if t != threading.get_ident() for w in ws]
    keep, importing = [], False
    while frame is not None:
        if importing:
            keep += [w for w in own if w.frame is frame]
        elif _import_frame(frame):
            importing = True        # a watch opened in this very frame is the module's own code: not for it
        frame = frame.f_back
    if importing:
        keep += others
    for watch in keep:
        watch.added.append(entry)


def _watched_add_filter(original: Callable) -> Callable:
    """``original`` (warnings._add_filter, which filterwarnings and simplefilter call), noting the entry it adds in
    the open watches it is a module's for (:func:`_note_module_filter`)."""
    @functools.wraps(original)
    def adding(*item, append):
        before = list(warnings.filters)          # kept alive, so that no new entry can share an id with one of them
        seen = {id(f) for f in before}
        result = original(*item, append=append)
        added = [f for f in warnings.filters if id(f) not in seen and f == item]
        if added:
            _note_module_filter(added[0], sys._getframe(1))
        return result
    return adding


def _watched(original: Callable) -> Callable:
    """Where warnings._add_filter cannot be watched (:func:`_hookable`): ``original`` (builtins.__import__ or
    importlib.import_module), noting the warning filters added while it ran in this thread's open watches: a module
    imported for the first time runs its own code then, and its filters are its own."""
    @functools.wraps(original)
    def importing(*args, **kwargs):
        before = list(warnings.filters)          # kept alive, so that no new entry can share an id with one of them
        seen = {id(f) for f in before}
        try:
            return original(*args, **kwargs)
        finally:
            added = [f for f in warnings.filters if id(f) not in seen]
            for watch in list(_WATCHES.get(threading.get_ident(), ())):
                watch.added.extend(added)
    return importing


def _hook() -> None:
    if _hookable():
        targets = [(warnings, "_add_filter", _watched_add_filter)]
    else:
        targets = [(builtins, "__import__", _watched), (importlib, "import_module", _watched)]
    for where, name, wrap in targets:
        original = getattr(where, name)
        wrapper = wrap(original)
        _HOOKED.append((where, name, original, wrapper))
        setattr(where, name, wrapper)


def _unhook() -> None:
    while _HOOKED:
        where, name, original, wrapper = _HOOKED.pop()
        if getattr(where, name) is wrapper:      # else someone wrapped it again: ours stays, and only passes through
            setattr(where, name, original)


class imports_watched:
    """While the block runs, the warning filters that a module adds while it is imported (an import statement,
    __import__, importlib.import_module, a module loaded lazily on first use; numpy's and torch's submodules load
    lazily, and some add filters) are gathered into the list it yields, for :func:`restore_settings` to keep: they
    are the module's, not the caller's. A filter counts as a module's when the thread that adds it is running the
    import machinery or a module's top level at that moment (below the ``with``, for this thread), so the caller's
    own filter, set beside an import or in another thread while one imports, is not among them. Watches may nest,
    and may be open in several threads at once."""

    def __init__(self) -> None:
        self._watch: _Watch | None = None

    def __enter__(self) -> list:
        try:
            watch = self._watch = _Watch(sys._getframe(1))
            with _WATCHES_LOCK:
                if not _WATCHES:
                    _hook()
                _WATCHES.setdefault(threading.get_ident(), []).append(watch)
            return watch.added
        except BaseException:       # an interrupt half way in: nothing of this watch is left behind
            self.__exit__()
            raise

    def __exit__(self, *exc) -> None:
        watch, self._watch = self._watch, None
        with _WATCHES_LOCK:
            for thread, watches in list(_WATCHES.items()):
                watches[:] = [w for w in watches if w is not watch]     # this watch's own entry, by identity
                if not watches:
                    del _WATCHES[thread]
            if not _WATCHES:
                _unhook()
        if watch is not None:
            watch.frame = None


def _same_entries(a: list, b: list) -> bool:
    return len(a) == len(b) and all(x is y for x, y in zip(a, b))


def _filters_to_keep(before: list, now: list, imported: list) -> list:
    """The warning filters to set back: ``before``'s, with those of ``now`` that an import added (``imported``), in
    the places they hold now (in front, unless added with append=True) where the caller left ``before``'s own
    entries in order, else in front. An entry of ``before`` that is gone from ``now`` and equal to one an import added
    was replaced by it (warnings.filterwarnings removes an equal filter before it inserts the new one in front)."""
    ours = {id(f) for f in imported}
    added = [f for f in now if id(f) in ours]
    if not added:
        return list(before)
    present = {id(f) for f in now}
    before = [f for f in before if id(f) in present or not any(f == a for a in added)]
    old = {id(f) for f in before}
    kept = [f for f in now if id(f) in ours or id(f) in old]
    if _same_entries([f for f in kept if id(f) in old], before):
        return kept
    return added + before


def restore_settings(before: dict | None, imported: list = ()) -> dict:
    """The settings changed since ``before`` ({name: (before, now)}), each set back to what it was. Warning filters
    added while a module's code ran under an import are the module's, and stay: ``imported``, the filters that
    :func:`imports_watched` gathered while the call ran; any other change of the filters is named."""
    if before is None:
        return {}
    now = global_settings()
    changed = {k: (before[k], now[k]) for k in before if k in now and now[k] != before[k]}
    filters = None
    if "warning filters" in changed:
        filters = _filters_to_keep(list(before["warning filters"]), list(now["warning filters"]), list(imported))
        if filters == list(now["warning filters"]):
            del changed["warning filters"]     # only the modules' own filters were added
    torch = sys.modules.get("torch")
    if "grad" in changed and torch is not None:
        torch.set_grad_enabled(before["grad"])
    if "dtype" in changed and torch is not None:
        torch.set_default_dtype(before["dtype"])
    if "anomaly" in changed and torch is not None:
        mode, check_nan = before["anomaly"]
        torch.autograd.set_detect_anomaly(mode, check_nan=check_nan)
    if "deterministic" in changed and torch is not None:
        mode, warn_only = before["deterministic"]
        torch.use_deterministic_algorithms(mode, warn_only=warn_only)
    if "numpy errors" in changed:
        np.seterr(**before["numpy errors"])
    if "warning filters" in changed:
        warnings.filters[:] = filters
        getattr(warnings, "_filters_mutated", lambda: None)()      # the C side caches the filters' version
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
    if "anomaly" in changed:
        on = changed["anomaly"][1][0]
        parts.append("it switched autograd's anomaly detection on for the whole notebook "
                     "(torch.autograd.set_detect_anomaly(True)), so every later backward pass records a traceback for "
                     "each operation and runs several times slower (and a NaN anywhere stops a training run with an "
                     "error); use `with torch.autograd.detect_anomaly():` around the lines you are debugging, which "
                     "switches it off at its end, and remove it once the NaN is found" if on else
                     "it switched autograd's anomaly detection off for the whole notebook "
                     "(torch.autograd.set_detect_anomaly(False)), where an earlier cell had switched it on; leave "
                     "the notebook's setting alone")
    if "deterministic" in changed:
        parts.append(f"it changed torch's deterministic-algorithms setting for the whole notebook "
                     f"(torch.use_deterministic_algorithms({changed['deterministic'][1][0]})), so later cells' "
                     "operations that have no deterministic version raise an error (or run otherwise); nothing "
                     "here asks for it: remove the call (results here are deterministic already)")
    if "numpy errors" in changed:
        old, new = changed["numpy errors"]
        diff = ", ".join(f"{k}={new[k]!r}" for k in new if new[k] != old.get(k))
        parts.append(f"it changed numpy's floating-point error handling for the whole notebook (np.seterr({diff})), "
                     "so every later cell's divisions by zero, logs of 0 and overflows are handled that way too "
                     "(silently ignored, or raised as errors); use `with np.errstate(divide='ignore'):` around the "
                     "line that needs it, which sets the handling back at its end")
    if "warning filters" in changed:
        parts.append("it changed the warning filters for the whole notebook (warnings.filterwarnings or "
                     "warnings.simplefilter), so later cells' warnings (the kit's own \"the cells below use the "
                     "reference solution\" among them) are hidden or changed too; put the filter inside `with "
                     "warnings.catch_warnings():`, which sets the filters back at its end (or, for numpy's own "
                     "warnings, use `with np.errstate(...):`)")
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
