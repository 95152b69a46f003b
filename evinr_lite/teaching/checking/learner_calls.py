"""Running a learner's function, and what the call did besides returning.

:func:`run` calls a function on a deep copy of a case's inputs (so a case can be run again, and the learner's function
cannot change the exercise's data), within a time limit (:func:`time_limit`, :data:`CALL_TIME_LIMIT_S`: a call that
never returns is stopped with :class:`TooSlow`; sys.exit(), and exit() in a notebook (:func:`notebook_exit_refused`),
become :class:`ExitCalled`), and sets the notebook's global settings (torch's, numpy's error handling, the warning
filters) back after it, whether it returns or raises. When it raises, :func:`where_raised` names the learner's own line
(not numpy's or torch's, nor the check's), and :func:`cache_raised` tells an unhashable argument given to a cache. When
it returns, :func:`changed_inputs` lists the inputs it changed in place and :func:`in_place_message` says what to do
instead. Over a whole check, :func:`watching` gathers what the learner's function changed of those settings. Before a
call, :func:`poison_freed_memory` fills freed memory of the result's sizes with a pattern, so that an array made with
np.empty (:func:`uses_uninitialised`, read off the bytecode: ``empty`` called on numpy or torch) holds that pattern
rather than zeros by chance. :func:`multiplies_rows` reads off the bytecode whether a function multiplies a list that
holds a list (rows aliased by ``[[0.0] * W] * H``), for the wording of that hint. :func:`module_flags` reads what a call
can leave changed in a model besides its parameters (its mode, which parameters require grad), :func:`tensor_flags` the
same of the input tensors (requires_grad), and :func:`refill_in_place` writes one case's values into another case's
objects without changing their identity (a cache keyed by id()). :func:`caught_errors` runs a call again under a
tracer of the learner's own frames and lists the errors that the function the check called caught with its own
`try`/`except`, and whether that `except` made the result (returned it, or set a name the return uses, read off the
source); :func:`swallowed_message` names the last one that did.
"""
from __future__ import annotations

import ast
import contextlib
import copy
import dis
import functools
import inspect
import os
import re
import signal
import site
import sys
import sysconfig
import textwrap
import threading
import time
import traceback
import types
from typing import Any, Callable, Iterator, NamedTuple

import numpy as np

from .outputs import input_name, is_tensor, named_inputs, to_numpy
from .global_state import global_settings, imports_watched, restore_settings


def learner_function(fn: Callable) -> Callable:
    """The learner's own function behind the check's notebook-call wrapper (signature.notebook_caller sets its
    ``wraps_learner_function``), ``fn`` itself otherwise: what the readers of code, globals and defaults read, while
    the check calls the wrapper."""
    return getattr(fn, "wraps_learner_function", fn)


def library_file(filename: str) -> bool:
    """A file of an installed library or of Python itself (numpy, torch, the standard library), not the learner's
    notebook or module (nor this kit, whose frames say which of its functions the learner's call broke)."""
    if filename.startswith("<frozen "):          # Python's own modules frozen into the interpreter (_sitebuiltins)
        return True
    path = os.path.realpath(filename)
    if path.startswith(KIT_ROOT + os.sep):          # the kit itself, installed into site-packages or not
        return False
    return any(path.startswith(root + os.sep) for root in LIBRARY_ROOTS)


def _site_dirs() -> list:
    """site-packages folders beyond sysconfig's: the system's (Debian's dist-packages) and the user's (some
    virtualenvs' site module lacks either function)."""
    user = getattr(site, "getusersitepackages", lambda: None)()
    return [*getattr(site, "getsitepackages", lambda: [])(), *([user] if user else [])]


# evinr_lite/, three folders above this file (evinr_lite/teaching/checking/learner_calls.py)
KIT_ROOT = os.path.realpath(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
# Python's own folders and every site-packages folder: a frame in one is a library's, not the learner's
LIBRARY_ROOTS = tuple(sorted({os.path.realpath(p) for p in
                               [*(sysconfig.get_paths().get(k) for k in ("stdlib", "platstdlib", "purelib", "platlib")),
                                *_site_dirs()] if p}))


_HERE = os.path.dirname(__file__)
_EXERCISES_FILE = os.path.join(os.path.dirname(_HERE), "exercises.py")


def _check_file(filename: str) -> bool:
    """A frame never reported as the learner's line: a module of this package (the check's own frames, its loop
    and :func:`run`, which stand between the report and the learner's code), or exercises.py, because a learner's
    code may call the registry (``exercises.get``, ``exercises.reference``): an error raised there is reported at
    the learner's line that called it, as before the check moved out of exercises.py."""
    return os.path.dirname(filename) == _HERE or filename == _EXERCISES_FILE


def cache_raised(fn: Callable, err: BaseException) -> bool:
    """An "unhashable type" TypeError that a cache raised: ``fn`` is an lru_cache (it has ``cache_info``), the
    error came from no line of the learner's code (the cache's wrapper, in C, builds the key before the call), or
    the learner's line that raised calls a notebook function that is an lru_cache (a cached helper)."""
    fn = learner_function(fn)
    if hasattr(fn, "cache_info"):
        return True
    frames = [f for f in traceback.extract_tb(err.__traceback__) if not _check_file(f.filename)]
    own = [f for f in frames if not library_file(f.filename)]
    if not own:
        return True
    namespace = getattr(fn, "__globals__", None)
    line = own[-1].line or ""
    if isinstance(namespace, dict) and line:
        for name in re.findall(r"[A-Za-z_][A-Za-z0-9_]*(?=\s*\()", line):
            if hasattr(namespace.get(name), "cache_info"):
                return True
    return False


def where_raised(err: BaseException) -> list[str]:
    """The line of the learner's code that raised: the last frame outside the check's own files and outside the
    libraries it called (an error raised deep inside numpy or torch is reported at the learner's line that called
    them)."""
    frames = [f for f in traceback.extract_tb(err.__traceback__) if not _check_file(f.filename)]
    if not frames:
        return []
    own = [f for f in frames if not library_file(f.filename)]
    f = (own or frames)[-1]
    code = f": `{f.line.strip()}`" if f.line else ""
    return [f"raised in {f.name}, line {f.lineno}{code}"]


def _deepcopy_with_grads(x):
    """``copy.deepcopy(x)``, also copying the ``.grad`` of torch parameters (which deepcopy drops),
    so that a case can hold a model with gradients left from an earlier step."""
    memo: dict = {}
    y = copy.deepcopy(x, memo)
    for orig in memo.get(id(memo), []):
        grad = getattr(orig, "grad", None) if is_tensor(orig) else None
        new = memo.get(id(orig))
        if grad is not None and new is not None and new is not orig and getattr(new, "grad", None) is None:
            new.grad = grad.detach().clone()
    return y


# (the learner's function, what its calls changed of the settings, the copies of inputs it was handed), one per
# running check
_WATCHED: list = []


@contextlib.contextmanager
def watching(fn: Callable) -> Iterator[dict]:
    """While the block runs, what any call of ``fn`` through :func:`run` changes of the global settings (the hints'
    calls too) is gathered into the dict it yields, {name: (before, after)}, the first change of each name kept.
    The copies of the inputs that :func:`run` hands ``fn`` are kept alive until the block ends, so that no two of
    them ever have the same id(): Python hands a freed object's id to the next one, and a result kept by id() would
    then be found or missed by chance, the report changing from run to run. Checks may nest (a check run from inside
    a learner's function): the innermost one's ``fn`` is watched."""
    seen: dict = {}
    _WATCHED.append((fn, seen, []))
    try:
        yield seen
    finally:
        _WATCHED.pop()


# seconds one call of a function may take before the check stops it: every case is small (a reference takes at most
# a few tens of milliseconds), so only a call that never ends (or waits for something) comes near
CALL_TIME_LIMIT_S = 5.0


class TooSlow(Exception):
    """A call stopped after :data:`CALL_TIME_LIMIT_S` seconds (an endless loop, or a call that waits); its traceback
    runs through the learner's frames to the line it was on when stopped."""

    def __init__(self, seconds: float):
        super().__init__(f"the call did not return within {seconds:g} s and was stopped")
        self.seconds = seconds


class ExitCalled(Exception):
    """The learner's function called sys.exit(), exit() or quit() (a SystemExit, which `except Exception` lets
    through: the check would stop with it and print a traceback), or, in a notebook, IPython's exit() or quit(),
    which raises nothing but asks the kernel to shut down once the cell has run (:func:`notebook_exit_refused`).
    ``how`` names the call (``"sys.exit()"``, ``"exit()"``), ``notebook`` says it was IPython's; its traceback, where
    there is one, runs through the learner's line that called it."""

    def __init__(self, code, how: str = "sys.exit()", notebook: bool = False):
        super().__init__(f"{how} in a notebook: the kernel was asked to shut down" if notebook else
                         f"SystemExit({code!r}): the function called sys.exit(), exit() or quit()")
        self.code = code
        self.how = how
        self.notebook = notebook


class _NotebookExit(SystemExit):
    """Raised inside the call in place of IPython's ask_exit (see :func:`notebook_exit_refused`), so that the call
    stops at the learner's exit() as it does in plain Python, with a traceback through that line."""


def _exit_how(err: SystemExit) -> str:
    """``"exit()"`` for Python's exit() or quit() (raised in their frozen module, _sitebuiltins) and IPython's,
    ``"sys.exit()"`` otherwise."""
    if isinstance(err, _NotebookExit):
        return "exit()"
    frames = traceback.extract_tb(err.__traceback__)
    return "exit()" if frames and "_sitebuiltins" in frames[-1].filename else "sys.exit()"


def _ipython_shell():
    """The running IPython shell (a notebook's kernel, the terminal's), where IPython is imported already and one
    runs; None otherwise (nothing is imported for it)."""
    ipython = sys.modules.get("IPython")
    get = getattr(ipython, "get_ipython", None)
    try:
        return get() if callable(get) else None
    except Exception:
        return None


_UNSET = object()


@contextlib.contextmanager
def notebook_exit_refused() -> Iterator[list]:
    """In IPython (a notebook's kernel), exit() and quit() raise nothing: they call the shell's ask_exit, which sets
    ``exit_now`` (the kernel then shuts down once the cell has run, every variable lost) and adds an "ask_exit"
    payload, and the function goes on. While the block runs, the shell's ask_exit raises :class:`_NotebookExit` (a
    SystemExit) at the learner's exit() instead, and the keepkernel_on_exit that exit() sets first is put back.
    A call that sets ``exit_now`` another way (an ask_exit taken before the block, ``get_ipython().exit_now =
    True``; or terminal IPython's ``keep_running``) has it set back, with no notice to the shell's observers while
    the block runs (ipykernel's stops the kernel's event loop on it), and the "ask_exit" payloads it added removed;
    the list the block gets then holds True, for the caller to report. Outside IPython it does nothing."""
    asked: list = []
    shell = _ipython_shell()
    if shell is None or not hasattr(shell, "__dict__"):
        yield asked
        return
    own = {name: vars(shell).get(name, _UNSET) for name in ("ask_exit", "notify_change")}
    exit_now = getattr(shell, "exit_now", _UNSET)
    keep_running = getattr(shell, "keep_running", _UNSET)
    keepkernel = getattr(shell, "keepkernel_on_exit", _UNSET)
    payloads = getattr(shell, "payload_manager", None)
    payloads_before = list(payloads.read_payload()) if hasattr(payloads, "read_payload") else None
    notify = getattr(shell, "notify_change", None)

    def refuse():
        raise _NotebookExit(None)

    def notify_but_exit_now(change):                # traitlets' notice of a change of one of the shell's traits
        if getattr(change, "name", None) != "exit_now" and callable(notify):
            notify(change)
    try:
        shell.ask_exit = refuse
        shell.notify_change = notify_but_exit_now
        yield asked
    finally:
        try:
            if exit_now is not _UNSET and not exit_now and getattr(shell, "exit_now", False):
                shell.exit_now = False                      # while the observers hear nothing of exit_now
                asked.append(True)
            if keep_running is not _UNSET and keep_running and not getattr(shell, "keep_running", True):
                shell.keep_running = True
                asked.append(True)
            if keepkernel is not _UNSET and getattr(shell, "keepkernel_on_exit", keepkernel) is not keepkernel:
                shell.keepkernel_on_exit = keepkernel
            if payloads_before is not None:
                now = list(payloads.read_payload())
                if any(isinstance(p, dict) and p.get("source") == "ask_exit"
                       and not any(p is q for q in payloads_before) for p in now):
                    payloads.clear_payload()
                    for p in payloads_before:
                        payloads.write_payload(p, single=False)
                    asked.append(True)
        finally:
            for name, value in own.items():
                if value is _UNSET:
                    vars(shell).pop(name, None)
                else:
                    setattr(shell, name, value)


class _Stop(BaseException):
    """Raised inside the call by :func:`time_limit`'s alarm: a BaseException, so that the learner's own
    `except Exception:` around a loop does not swallow it."""


def _drain_signals() -> None:
    """Nothing: calling a Python function lets the interpreter run the handlers of signals that arrived (a
    pending SIGALRM is handled here, in a frame of this file, where :func:`time_limit`'s handler raises nothing)."""


@contextlib.contextmanager
def time_limit(seconds: float) -> Iterator[None]:
    """Stop the block with :class:`TooSlow` after ``seconds`` (SIGALRM through setitimer; again every second after
    that, in case the learner's code swallows the first). No limit where it cannot be set: not on the main thread,
    no setitimer (Windows), a SIGALRM handler set outside Python, or an outer timer (the mutation tool's, pytest's)
    that fires first; an outer timer that fires later is set again afterwards with the time it has left.

    The alarm raises only in a frame of the call (the learner's code, or a library it called): in a frame of this
    file or of contextlib (the call has returned, and the check is leaving the block) it does nothing, so that no
    alarm at the limit's boundary escapes the block or skips the code that puts the outer handler back. That code
    stops the timer first, lets a signal that already arrived be handled by the kit's handler (which does nothing
    there), and only then puts the outer handler and timer back."""
    if not seconds or not hasattr(signal, "setitimer") or threading.current_thread() is not threading.main_thread():
        yield
        return
    outer_handler = signal.getsignal(signal.SIGALRM)
    outer_left, outer_interval = signal.getitimer(signal.ITIMER_REAL)
    if outer_handler is None or (outer_left and outer_left <= seconds):
        yield
        return

    def stop(signum, frame):
        if frame is not None and frame.f_code.co_filename in _NO_STOP_FILES:
            return                  # the call has returned: the check is leaving the block (re-fired in 1 s else)
        raise _Stop()

    start = time.monotonic()
    signal.signal(signal.SIGALRM, stop)
    try:
        signal.setitimer(signal.ITIMER_REAL, seconds, 1.0)
        try:
            yield
        except _Stop as err:
            raise TooSlow(seconds).with_traceback(err.__traceback__) from None
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0, 0)
        _drain_signals()
        signal.signal(signal.SIGALRM, outer_handler)
        if outer_left:
            signal.setitimer(signal.ITIMER_REAL, max(outer_left - (time.monotonic() - start), 1e-3), outer_interval)


# the files in whose frames time_limit's alarm raises nothing: this one, and contextlib's (the `with` statement's
# exit), as the interpreter names them in code objects
_NO_STOP_FILES = frozenset({_drain_signals.__code__.co_filename, contextlib.contextmanager.__code__.co_filename})


def run(fn, args, kwargs, observe=None, inputs_after: list | None = None, settings_changed: dict | None = None,
        copy_inputs: bool = True, seconds: list | None = None):
    """``fn`` on a deep copy of the inputs (one copy, so objects shared between inputs stay shared,
    e.g. a model and its optimiser); with ``observe``, what it says to compare. ``inputs_after``, a list,
    receives the copied ``(args, kwargs)`` as they are after the call; ``seconds``, a list, the time the call
    itself took (not the copy's), whether it returned or raised.

    A call that takes longer than :data:`CALL_TIME_LIMIT_S` is stopped with :class:`TooSlow`, and one that calls
    sys.exit() (or exit(), in a notebook too: :func:`notebook_exit_refused`) raises :class:`ExitCalled`: both are
    Exceptions, reported like the learner's other errors.
    The global settings (torch's grad mode and default dtype, numpy's error handling, the warning filters) are set
    back after every call, whether it returns or
    raises, so that a function that changes them on one input changes nothing for the calls after it (the
    reference's, the hints' wrong versions) nor for the notebook; ``settings_changed``, a dict, receives what
    the call changed ({name: (before, after)}); warning filters that a module adds while an import runs its code
    during the call are the module's, and stay (:func:`.global_state.imports_watched`). What the learner's function
    changed on any call of the check (the hints' calls too) is also kept for the report (see :func:`watching`).
    ``copy_inputs=False`` hands the function the objects themselves (to call it twice on the same objects)."""
    if copy_inputs:
        args, kwargs = _deepcopy_with_grads((args, kwargs))
        if _WATCHED and fn is _WATCHED[-1][0]:
            _WATCHED[-1][2].append((args, kwargs))        # kept alive: see watching()
    settings = global_settings()
    with imports_watched() as imported:
        start = time.perf_counter()
        try:
            with notebook_exit_refused() as asked_exit, time_limit(CALL_TIME_LIMIT_S):
                result = fn(*args, **kwargs)
            if asked_exit:                  # a notebook's exit_now set otherwise than through exit(): no line to name
                raise ExitCalled(None, "exit()", notebook=True)
        except SystemExit as err:        # sys.exit() or exit(): no Exception, so the check would stop with it
            raise ExitCalled(err.code, _exit_how(err), isinstance(err, _NotebookExit)).with_traceback(
                err.__traceback__) from None
        finally:
            if seconds is not None:
                seconds.append(time.perf_counter() - start)
            changed = restore_settings(settings, imported)
            if settings_changed is not None:
                settings_changed.update(changed)
            if changed and _WATCHED and fn is _WATCHED[-1][0]:
                for name, change in changed.items():
                    _WATCHED[-1][1].setdefault(name, change)
    if inputs_after is not None:
        inputs_after.append((args, kwargs))
    return result if observe is None else observe(result, args, kwargs)


def copy_inputs(inputs: tuple[tuple, dict]) -> tuple[list, dict]:
    """A deep copy of a case's (args, kwargs), the args as a list, for :func:`run` with ``copy_inputs=False``."""
    args, kwargs = _deepcopy_with_grads(inputs)
    return list(args), kwargs


def refill_in_place(holder: tuple[list, dict], new: tuple[tuple, dict]) -> bool:
    """Write the values of ``new`` (a case's args and kwargs) into the objects of ``holder`` (another case's, made
    by :func:`copy_inputs`), in place: each numpy array keeps its identity (resized where the sizes differ, to another
    number of axes too), as do the arrays inside an object such as ``Events``, a tensor (its ``.data`` replaced,
    its requires_grad kept), and a dict or list input (emptied and refilled with a copy of the new items); plain
    numbers are replaced, tuples by a copy (never the case's own objects). False (and ``holder`` perhaps partly
    written) where that cannot be done: another structure, dtype or device, an array that something else still
    refers to (a resize would leave it pointing at freed memory, and numpy refuses it), or two inputs (or two fields
    of one) that share memory, such as one array passed twice (``f(x, x)``): writing one would write the other."""
    (h_args, h_kwargs), (n_args, n_kwargs) = holder, new
    if len(h_args) != len(n_args) or set(h_kwargs) != set(n_kwargs):
        return False
    if _share_memory([a for v in [*h_args, *h_kwargs.values()] for _, a in _arrays_of(v)]):
        return False
    slots = [(h_args, k, v) for k, v in enumerate(n_args)] + [(h_kwargs, k, v) for k, v in n_kwargs.items()]
    return all(_refill_slot(box, key, value) for box, key, value in slots)


def _share_memory(arrays: list) -> bool:
    """Two of ``arrays`` (numpy arrays or tensors) share memory: the same object twice, a view of another, tensors
    on one storage."""
    for i, a in enumerate(arrays):
        for b in arrays[i + 1:]:
            if a is b:
                return True
            if isinstance(a, np.ndarray) and isinstance(b, np.ndarray) and np.shares_memory(a, b):
                return True
            if is_tensor(a) and is_tensor(b) and a.numel() and b.numel() \
                    and a.untyped_storage().data_ptr() == b.untyped_storage().data_ptr():
                return True
    return False


def _refill_slot(box, key, value) -> bool:
    """``box[key]`` given ``value``'s contents in place (see :func:`refill_in_place`). The array is never bound to a
    local name before a resize: numpy counts the references, and a local one would make it refuse."""
    if isinstance(value, np.ndarray):
        if type(box[key]) is not np.ndarray or box[key].dtype != value.dtype:
            return False
        if box[key].shape != value.shape:
            try:
                box[key].resize(value.shape)
            except (ValueError, TypeError):
                return False
        box[key][...] = value
        return True
    if is_tensor(value):
        return _refill_tensor(box[key], value)
    fields = getattr(value, "__dict__", None)
    if isinstance(fields, dict) and not hasattr(value, "parameters"):
        target = getattr(box[key], "__dict__", None)
        if type(box[key]) is not type(value) or not isinstance(target, dict) or set(target) != set(fields):
            return False
        return all(_refill_slot(target, name, v) for name, v in fields.items())
    if isinstance(value, dict) and type(box[key]) is dict:     # a table: the same dict object, new rows
        box[key].clear()
        box[key].update(copy.deepcopy(value))
        return True
    if isinstance(value, list) and type(box[key]) is list:
        box[key][:] = copy.deepcopy(value)
        return True
    if isinstance(value, (int, float, complex, str, bytes, tuple, type(None), np.generic)):
        box[key] = copy.deepcopy(value)       # a tuple of arrays: copies, never the case's own arrays
        return True
    return False


def _refill_tensor(t, value) -> bool:
    """The tensor ``t`` given a copy of ``value``'s values and gradient, its identity and requires_grad kept (its
    ``.data`` replaced, which a leaf that requires grad allows, to any shape); False for another type, dtype,
    device or requires_grad, or a tensor that is no leaf."""
    if type(t) is not type(value) or t.dtype != value.dtype or t.device != value.device \
            or t.requires_grad != value.requires_grad or not t.is_leaf:
        return False
    torch = sys.modules["torch"]
    with torch.no_grad():
        t.data = value.detach().clone()
    t.grad = None if value.grad is None else value.grad.detach().clone()
    return True


def _arrays_of(v) -> list[tuple[str, Any]]:
    """The arrays (or tensors) an input holds: itself, or the array fields of an object such as ``Events``."""
    if isinstance(v, np.ndarray) or is_tensor(v):
        return [("", v)]
    fields = getattr(v, "__dict__", None)
    if isinstance(fields, dict) and not hasattr(v, "parameters"):
        return [(f".{k}", a) for k, a in fields.items() if isinstance(a, np.ndarray) or is_tensor(a)]
    return []


def module_flags(inputs: tuple[tuple, dict]) -> dict[str, tuple]:
    """{input name: (each submodule's training mode, each parameter's requires_grad)} for the torch modules among
    ``inputs`` (args, kwargs): what a call can leave changed in a model besides its parameters' values."""
    return {name: (tuple(bool(m.training) for m in v.modules()), tuple(bool(q.requires_grad) for q in v.parameters()))
            for name, v in named_inputs(*inputs) if not isinstance(v, type)      # a class (nn.Linear) is no model
            and callable(getattr(v, "modules", None)) and callable(getattr(v, "parameters", None))
            and type(v).__module__.split(".")[0] != "numpy"}


def tensor_flags(inputs: tuple[tuple, dict]) -> dict[str, bool]:
    """{input name: requires_grad} for the torch tensors among ``inputs`` (args, kwargs), and the tensor fields of
    an input object (``events.t``): a flag a call can change on the caller's tensor without changing a value."""
    return {f"{name}{field}": bool(a.requires_grad) for name, v in named_inputs(*inputs)
            for field, a in _arrays_of(v) if is_tensor(a)}


def tensor_flags_message(got: dict, expected: dict) -> str | None:
    """What the learner's call changed of the inputs' requires_grad where the reference's left it (see
    :func:`tensor_flags`), or None."""
    on = [n for n in expected if n in got and got[n] and not expected[n]]
    off = [n for n in expected if n in got and not got[n] and expected[n]]
    if on:
        names = ", ".join(f"`{n}`" for n in on)
        already = [n for n in expected if expected[n]]
        source = (f"the result gets its gradients from the inputs that require grad already "
                  f"({', '.join(f'`{n}`' for n in already)})" if already else
                  "no input requires grad in the reference's call, so the result needs none through them")
        return (f"set requires_grad on its input {names} (`.requires_grad_()`, or `.requires_grad = True`), and the "
                "caller's tensor keeps it: later cells then record autograd graphs through the data, numpy refuses "
                "it (`.numpy()` of a tensor that requires grad), and a loss back-propagates into it; "
                f"{source}: leave the inputs as they are (for a tensor of your own that needs gradients, "
                "`x = x.detach().clone().requires_grad_()`)")
    if off:
        names = ", ".join(f"`{n}`" for n in off)
        return (f"switched requires_grad off on its input {names} (`.requires_grad_(False)`, `.detach_()`), and "
                "the caller's tensor keeps it: it is cut off from the autograd graph for every later cell, so "
                "nothing is trained through it; use `.detach()` (a new tensor) where you need values without "
                "gradients, and leave the inputs as they are")
    return None


def module_flags_message(got: dict, expected: dict) -> str | None:
    """What the learner's call left otherwise than the reference's in a model (see :func:`module_flags`), or None."""
    for name in expected:
        if name not in got:
            continue
        (train_g, grad_g), (train_e, grad_e) = got[name], expected[name]
        if train_g != train_e:
            mode = "evaluation mode (`model.eval()`)" if not all(train_g) and all(train_e) else \
                "another mode (`model.train()` / `model.eval()`)"
            return (f"leaves `{name}` in {mode} after the call, where the reference leaves it as it was: the "
                    "notebook's later steps (and dropout or batch-norm layers) then run in that mode; put the mode "
                    "back before returning (`model.train()`), or switch it only inside a `try: ... finally:`")
        if grad_g != grad_e:
            return _requires_grad_message(name, grad_g, grad_e)
    return None


def _requires_grad_message(name: str, got: tuple, expected: tuple) -> str:
    """Which parameters of the model ``name`` require grad after the learner's call (``got``) and not after the
    reference's (``expected``), or the reverse: each direction has its own fix."""
    off = sum(e and not g for g, e in zip(got, expected))      # the learner's call froze them, the reference's not
    on = sum(g and not e for g, e in zip(got, expected))       # the reference's call froze them, the learner's not
    n = len(expected)
    parts = []
    if off:
        parts.append(f"{off} of {n} no longer require grad after your call (`p.requires_grad_(False)`, "
                     "`model.requires_grad_(False)`), where the reference's call leaves them trainable: every later "
                     "step then trains nothing through them; leave them as they are (use torch.no_grad() or "
                     ".detach() for a value you only want to look at)")
    if on:
        parts.append(f"{on} of {n} still require grad after your call, where the reference's call freezes them: "
                     "later steps then go on training what the exercise holds fixed; freeze them as the exercise "
                     "asks (`p.requires_grad_(False)` for each, or `layer.requires_grad_(False)`)")
    return f"changes which parameters of `{name}` require grad otherwise than the reference: " + "; and ".join(parts)


def same_array(a, b) -> bool:
    try:
        a, b = to_numpy(a), to_numpy(b)
        return a.shape == b.shape and a.dtype == b.dtype and bool(np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"))
    except Exception:
        return True          # cannot tell: say nothing


def _same_contents(a, b) -> bool:
    """``a`` and ``b`` hold the same keys, items and values (dicts, lists and tuples compared recursively, arrays
    entry by entry); an object that cannot be compared counts as the same (say nothing)."""
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same_contents(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return type(a) is type(b) and len(a) == len(b) and all(_same_contents(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray) or is_tensor(a) or isinstance(b, np.ndarray) or is_tensor(b):
        return same_array(a, b)
    if isinstance(a, (bool, int, float, complex, str, bytes, np.generic, type(None))):
        try:
            return type(a) is type(b) and (bool(a == b) or bool(a != a and b != b))
        except Exception:
            return True
    return True


def changed_inputs(before: tuple[tuple, dict], after: tuple[tuple, dict]) -> list[str]:
    """Names of the array inputs (or array fields of an input), and of the dict and list inputs (a key added,
    removed or changed, an item appended, the list sorted), that the call changed in place."""
    (args0, kwargs0), (args1, kwargs1) = before, after
    pairs = [(input_name(k), a, b) for k, (a, b) in enumerate(zip(args0, args1))]
    pairs += [(name, kwargs0[name], kwargs1[name]) for name in kwargs0 if name in kwargs1]
    changed = []
    for name, v0, v1 in pairs:
        if isinstance(v0, (dict, list)):
            if not _same_contents(v0, v1):
                changed.append(name)
            continue
        for (field_name, a0), (_, a1) in zip(_arrays_of(v0), _arrays_of(v1)):
            if not same_array(a0, a1):
                changed.append(f"{name}{field_name}")
    return changed


def in_place_message(changed: list[str], containers: tuple = ()) -> str:
    names = ", ".join(f"`{n}`" for n in changed)
    if containers and set(changed) <= set(containers):
        return (f"changed its input {names} in place (a key added, changed or removed: `row[key] = ...`, "
                "`row.pop(key)`, `del row[key]`; or a list appended to or sorted): the caller's table must stay "
                "as it was, so build a new dict (`{name: ... for name, row in table.items()}`) or work on "
                "`copy.deepcopy(...)` of it")
    return (f"changed its input {names} in place (`x += ...`, `x[...] = ...`, `np.exp(x, out=x)`; "
            "`np.asarray(x, dtype=...)` is x itself when the dtype already matches): the caller's data must "
            "stay as it was, so compute a new array (`x = x + ...`) or work on a copy (`np.array(x, dtype=float)`)")


def container_names(args: tuple, kwargs: dict) -> tuple:
    """The names `changed_inputs` gives the dict and list inputs."""
    return tuple(name for name, v in named_inputs(args, kwargs) if isinstance(v, (dict, list)))


POISON_LIMIT = 1 << 20     # the largest block poison_freed_memory fills (1 MiB): eight of each size are made


def poison_freed_memory(like, byte: int = 0x7F) -> None:
    """Fill memory in the sizes of the arrays in ``like`` (their bytes, and 2, 4, 8 times more or fewer: a float64
    buffer for a float32 result, int64 counts for a bool mask) with ``byte`` (0x7f), and free it again. numpy and the
    C library hand freed blocks of one size out again, last freed first, so a learner's np.empty of such a size
    then starts from 0x7f bytes (1.4e306 as float64, 127 as int8) instead of whatever the last array left there,
    which may be zeros and pass by chance. Only blocks of up to :data:`POISON_LIMIT` (1 MiB) are filled: memory
    for a larger array is not, and np.empty there may hold zeros by chance."""
    sizes = set()
    stack = [like]
    while stack:
        v = stack.pop()
        if isinstance(v, dict):
            stack.extend(v.values())
        elif isinstance(v, (tuple, list)):
            stack.extend(v)
        elif isinstance(v, np.ndarray) or is_tensor(v):
            n = int(to_numpy(v).nbytes)
            sizes.update(n * f for f in (1, 2, 4, 8))
            sizes.update(n // f for f in (2, 4, 8) if n % f == 0)
    for size in sorted(s for s in sizes if 0 < s <= POISON_LIMIT):
        blocks = [np.full(size, byte, np.uint8) for _ in range(8)]
        del blocks


_ARRAY_MODULES = ("numpy", "torch")
_EMPTY = ("empty", "empty_like")
_LOADS = ("LOAD_GLOBAL", "LOAD_NAME", "LOAD_FAST", "LOAD_DEREF", "LOAD_CLASSDEREF")


def _array_module(value) -> bool:
    return isinstance(value, types.ModuleType) and value.__name__.split(".")[0] in _ARRAY_MODULES


def _empty_function(value) -> bool:
    """``value`` is np.empty, np.empty_like, torch.empty or torch.empty_like (a name imported from the module)."""
    for module in map(sys.modules.get, _ARRAY_MODULES):
        if module is not None and any(value is getattr(module, name, None) for name in _EMPTY):
            return True
    return False


def uses_uninitialised(fn) -> bool:
    """Whether the code of ``fn`` (its nested functions too) calls np.empty, np.empty_like, torch.empty or
    torch.empty_like: ``empty`` read off np, numpy or torch (or another name for either module, in the notebook or
    imported in the function), or a name imported from them (``from numpy import empty``). Another object's
    ``empty`` (a queue's ``q.empty()``, a DataFrame's ``.empty``) is not one."""
    fn = learner_function(fn)
    namespace = getattr(fn, "__globals__", None)
    namespace = namespace if isinstance(namespace, dict) else {}
    modules = {"np", "numpy", "torch"} | {k for k, v in namespace.items() if _array_module(v)}
    codes = [getattr(fn, "__code__", None)]
    while codes:
        code = codes.pop()
        if code is None:
            continue
        prev = importing = None
        for ins in dis.get_instructions(code):
            if ins.opname in ("LOAD_ATTR", "LOAD_METHOD") and ins.argval in _EMPTY and prev is not None \
                    and prev.opname in _LOADS and prev.argval in modules:
                return True
            if ins.opname == "IMPORT_NAME":
                importing = str(ins.argval).split(".")[0]
            if ins.opname == "IMPORT_FROM" and ins.argval in _EMPTY and importing in _ARRAY_MODULES:
                return True             # `from numpy import zeros, empty` inside the function
            if ins.opname in ("LOAD_GLOBAL", "LOAD_NAME") and _empty_function(namespace.get(ins.argval)):
                return True
            if ins.opname.startswith("STORE_") and prev is not None and prev.opname == "IMPORT_NAME" \
                    and str(prev.argval).split(".")[0] in _ARRAY_MODULES:
                modules.add(ins.argval)          # `import numpy as onp` inside the function
            prev = ins
        codes.extend(c for c in code.co_consts if hasattr(c, "co_names"))
    return False


_NAME_LOADS = ("LOAD_FAST", "LOAD_NAME", "LOAD_DEREF", "LOAD_GLOBAL", "LOAD_CLASSDEREF", "LOAD_CLOSURE")
_NAME_STORES = ("STORE_FAST", "STORE_NAME", "STORE_DEREF", "STORE_GLOBAL")


def multiplies_rows(fn) -> bool:
    """Whether the code of ``fn`` (its nested functions and comprehensions too) multiplies a list that holds a list:
    ``[[0.0] * W] * H``, or ``[row] * H`` where ``row = [0.0] * W``, H references to one row list. Read off the
    bytecode by following what each value on the stack is (a list of numbers, a list holding a list, anything
    else) through list displays, ``*`` and the names they are stored in; runs nothing."""
    codes = [getattr(learner_function(fn), "__code__", None)]
    while codes:
        code = codes.pop()
        if code is None:
            continue
        stack: list[str] = []
        names: dict[str, str] = {}

        def pop() -> str:
            return stack.pop() if stack else "other"
        for ins in dis.get_instructions(code):
            op = ins.opname
            if op == "BUILD_LIST":
                items = [pop() for _ in range(ins.arg or 0)]
                stack.append("rows" if any(t in ("list", "rows") for t in items) else "list")
            elif op == "BINARY_OP" and ins.argrepr in ("*", "*="):
                kinds = (pop(), pop())
                if "rows" in kinds:
                    return True
                stack.append("list" if "list" in kinds else "other")
            elif op in _NAME_STORES:
                names[ins.argval] = pop()
            elif op in _NAME_LOADS or op == "LOAD_CONST":
                try:
                    pushed = dis.stack_effect(ins.opcode, ins.arg)
                except (ValueError, TypeError):
                    pushed = 1
                stack.extend(["other"] * (pushed - 1))             # the NULL that LOAD_GLOBAL may push first
                stack.append("const" if op == "LOAD_CONST" else names.get(ins.argval, "other"))
            else:
                try:
                    effect = dis.stack_effect(ins.opcode, ins.arg if ins.opcode >= dis.HAVE_ARGUMENT else None)
                except (ValueError, TypeError):
                    effect = 0
                for _ in range(-effect):
                    pop()
                if effect >= 0 and stack:
                    stack[-1] = "other"                             # an operation on the value on top
                stack.extend(["other"] * max(effect, 0))
        codes.extend(c for c in code.co_consts if hasattr(c, "co_names"))
    return False


# ---- errors the learner's own code caught -------------------------------------------------------------------------

SWALLOWED = "an error was raised inside your function and caught by its own `except`"   # a hint's start


# errors that code catches on purpose (a key not there yet, an optional import, the end of an iterator): never named
_EXPECTED_ERRORS = (StopIteration, StopAsyncIteration, GeneratorExit, KeyError, ImportError)


@functools.lru_cache(maxsize=4096)
def _learner_file(filename: str) -> bool:
    """A frame of the learner's code: not a library's, not the kit's (its reference, its check). Kept per file
    name: the tracer asks it at every call, numpy's and torch's too (os.path.realpath on each one made a traced
    call some 35 times slower than a plain one)."""
    if library_file(filename) or _check_file(filename):
        return False
    return not os.path.realpath(filename).startswith(KIT_ROOT + os.sep)


class Caught(NamedTuple):
    """An error the learner's function caught itself (:func:`caught_errors`)."""
    error: BaseException
    filename: str
    line: int                   # where it was raised: the first of the learner's frames it was seen in
    function: str
    handler: int | None         # the line of the function's `except` clause whose body ran for it (None: none)
    how: str | None             # "return": the function returned from that body; a name: the body set it, and the
    #                             function's return uses it (or a name computed from it); None: neither
    returned: int | None        # the line the function returned from


class _Handler(NamedTuple):
    clause: range               # the lines of the `except ...:` clause itself
    body: range                 # the lines of an `except` clause's body (the clause's own line not among them)
    sets: dict                  # the names its body sets or changes, and those computed from them in the function:
    #                             for each, the name of the body's it came from


def _names(node: ast.AST, ctx=ast.Load) -> set:
    """The names that ``node`` reads (ctx Load) or binds (ctx Store) outside nested functions and classes."""
    found, stack = set(), [node]
    while stack:
        n = stack.pop()
        if isinstance(n, ast.Name) and isinstance(n.ctx, ctx):
            found.add(n.id)
        if n is node or not isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda, ast.ClassDef)):
            stack.extend(ast.iter_child_nodes(n))
    return found


def _base(target: ast.AST) -> str | None:
    """The name an assignment's target changes: ``out`` of ``out``, ``out[j]``, ``out.data``, ``out[j].x``."""
    while isinstance(target, (ast.Subscript, ast.Attribute, ast.Starred)):
        target = target.value
    return target.id if isinstance(target, ast.Name) else None


def _bindings(tree: ast.AST) -> list[tuple[set, set]]:
    """(names set or changed, names read) of each assignment, loop, `with` and method call in ``tree``, outside
    nested functions: ``out[j] = v`` changes ``out`` from ``v``, ``out.append(v)`` too."""
    pairs, stack = [], list(ast.iter_child_nodes(tree))
    while stack:
        n = stack.pop()
        if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda, ast.ClassDef)):
            continue
        stack.extend(ast.iter_child_nodes(n))
        if isinstance(n, (ast.Assign, ast.AugAssign, ast.AnnAssign)) and n.value is not None:
            targets = n.targets if isinstance(n, ast.Assign) else [n.target]
            bound = {b for t in targets for b in [_base(t), *_names(t, ast.Store)] if b}
            pairs.append((bound, _names(n.value) | (bound if isinstance(n, ast.AugAssign) else set())))
        elif isinstance(n, ast.NamedExpr):
            pairs.append(({n.target.id}, _names(n.value)))
        elif isinstance(n, (ast.For, ast.AsyncFor)):
            pairs.append((_names(n.target, ast.Store), _names(n.iter)))
        elif isinstance(n, ast.withitem) and n.optional_vars is not None:
            pairs.append((_names(n.optional_vars, ast.Store), _names(n.context_expr)))
        elif isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute) and _base(n.func):
            pairs.append(({_base(n.func)}, {m for a in [*n.args, *n.keywords] for m in _names(a)}))
    return pairs


def _function_tree(code: types.CodeType):
    """The def of ``code`` (its lines numbered as in its file), or None where its source cannot be read."""
    try:
        lines, start = inspect.getsourcelines(code)
        tree = ast.parse(textwrap.dedent("".join(lines)))
    except (OSError, TypeError, SyntaxError, ValueError):
        return None
    node = tree.body[0] if tree.body else None
    if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
        return None
    ast.increment_lineno(tree, max(start, 1) - 1)
    return node


def _except_handlers(code: types.CodeType) -> tuple[list[_Handler], dict[int, set]] | None:
    """The `except` clauses of the function of ``code`` (not of the functions it defines), and the names each
    `return` reads, by its lines; None where its source cannot be read."""
    node = _function_tree(code)
    if node is None:
        return None
    handlers, returns, stack = [], {}, list(ast.iter_child_nodes(node))
    while stack:
        n = stack.pop()
        if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda, ast.ClassDef)):
            continue
        stack.extend(ast.iter_child_nodes(n))
        if isinstance(n, ast.Return):
            for line in range(n.lineno, (n.end_lineno or n.lineno) + 1):
                returns[line] = _names(n.value) if n.value is not None else set()
        if isinstance(n, ast.ExceptHandler) and n.body:
            sets = {b: b for bound, _ in _bindings(n) for b in bound}
            everywhere = _bindings(node)
            while True:         # the names computed from them anywhere in the function (the order of lines aside)
                more = {b: sets[min(read & sets.keys())] for bound, read in everywhere if read & sets.keys()
                        for b in bound if b not in sets}
                if not more:
                    break
                sets.update(more)
            handlers.append(_Handler(range(n.lineno, n.body[0].lineno),
                                     range(n.body[0].lineno, (n.end_lineno or n.body[-1].lineno) + 1), sets))
    return handlers, returns


def caught_errors(fn: Callable, args, kwargs) -> list[Caught] | None:
    """The errors that the function the check calls caught with its own ``try``/``except``, during a call of ``fn``
    on a copy of the inputs: each error raised in the learner's frames (not numpy's or torch's, nor the kit's) that
    reached that function's frame, where the call let it go no further, with the `except` whose body ran for it and
    whether that body made the result (:class:`Caught`). None where the call raised, or could not be traced (a
    tracer of another tool's, a debugger's or coverage's, is kept, and then nothing is traced).

    The tracer sees the calls of the learner's files only (a file's answer is kept), and the lines of that function
    only between an error and the `except` body it reached: a traced call takes about the time of one under a
    tracer that does nothing."""
    if sys.gettrace() is not None:
        return None
    own = learner_function(fn)
    with contextlib.suppress(ValueError, TypeError):
        own = inspect.unwrap(own)
    top_code = getattr(own, "__code__", None)
    read = _except_handlers(top_code) if top_code is not None else None
    handlers, returns = read if read is not None else ([], {})
    origin: dict = {}           # id(error) -> (error, file, line, function), where first seen
    in_top: list = []           # the errors seen in the function's frame, in order
    seen_in_top: set = set()
    ran: dict = {}              # id(error) -> the handler whose body ran for it
    pending: list = []          # errors seen in the function's frame, their handler not yet known
    state = {"top": None, "returned": None}

    def local(frame, event, arg):
        if event == "exception":
            err = arg[1]
            if isinstance(err, _EXPECTED_ERRORS):
                return local
            if id(err) not in origin:
                origin[id(err)] = (err, frame.f_code.co_filename, frame.f_lineno, frame.f_code.co_name)
            if frame is state["top"] and id(err) not in ran:
                if id(err) not in seen_in_top:
                    seen_in_top.add(id(err))
                    in_top.append(err)
                pending.append(err)
                frame.f_trace_lines = True          # which `except` body runs next
        elif frame is state["top"]:
            if event == "line" and pending:
                inside = [h for h in handlers if frame.f_lineno in h.body]
                if inside or not any(frame.f_lineno in h.clause for h in handlers):   # not yet at a clause's body
                    handler = max(inside, key=lambda h: h.body.start) if inside else None
                    for err in pending:
                        ran[id(err)] = handler
                    pending.clear()
                    frame.f_trace_lines = False
            elif event == "return":
                state["returned"] = frame.f_lineno
        return local

    def calls(frame, event, arg):
        if not _learner_file(frame.f_code.co_filename):
            return None
        if state["top"] is None and (top_code is None or frame.f_code is top_code):
            state["top"] = frame
        frame.f_trace_lines = False
        return local

    sys.settrace(calls)
    try:
        run(fn, args, kwargs)
    except Exception:
        return None
    finally:
        sys.settrace(None)
    found, back = [], state["returned"]
    for err in in_top:
        handler = ran.get(id(err))
        how = None
        if handler is not None and back is not None:
            if back in handler.body:
                how = "return"
            else:
                used = sorted(handler.sets.keys() & returns.get(back, set()))
                how = handler.sets[used[0]] if used else None
        found.append(Caught(*origin[id(err)], handler.clause.start if handler is not None else None, how,
                            back))
    return found


def swallowed_message(errors: list[Caught] | None) -> str | None:
    """A hint naming the last error the learner's function caught whose `except` made its result (returned it, or
    set a name that its return uses), or None: an `except` that only went on (``pass``, a fallback the result does
    not use) is never named."""
    made = [c for c in errors or [] if c.how is not None]
    if not made:
        return None
    import linecache
    err, filename, line, name, handler, how, back = made[-1]
    text = linecache.getline(filename, line).strip()
    code = f": `{text}`" if text else ""
    more = f" ({len(made)} errors caught in all)" if len(made) > 1 else ""
    said = f"{SWALLOWED} ({type(err).__name__}: {err}, in {name}, line {line}{code}){more}"
    if how == "return":
        return (f"{said}, and what its `except` (line {handler}) handed back is not the answer: remove the "
                "`try`/`except` (or let it `raise`) to see the error, and fix that line")
    return (f"{said}, and its `except` (line {handler}) set `{how}`, from which what the function returns (line "
            f"{back}) is computed: this may be why the result is wrong; look at the line that raised")
