"""Exercises that keep a notebook runnable, finished or not.

An exercise has three parts:

- a **stub** in the notebook: the function's signature and docstring. The instructor copy
  holds the solution between ``### BEGIN SOLUTION`` and ``### END SOLUTION`` lines; the
  student copy (generated from it) has ``raise NotImplementedError`` instead;
- a **reference solution** in the package, registered here under the exercise's name;
- a **check** that runs the learner's function and the reference on small seeded inputs
  and says what is wrong: not done yet, an exception, a wrong type, shape or dtype, or
  wrong values (where, by how much, and a hint when the mistake is a known one).

Typical notebook cells::

    from evinr_lite.teaching import exercises

    def integrate_events_1d(t_events, p_events, C, t_query):
        ### BEGIN SOLUTION
        ...
        ### END SOLUTION

    exercises.check("integrate_events_1d", integrate_events_1d)      # prints a report

    # later cells: the learner's version if it passes, otherwise the reference + a warning
    integrate = exercises.use("integrate_events_1d", integrate_events_1d)

Registering an exercise (done in a module of :mod:`evinr_lite.teaching`, at import; the reference
may be a library function or a teaching version pinned to one by a test)::

    exercises.register("integrate_events_1d", reference, make_inputs,
                       hints={"did you forget the sign of the polarity?": wrong_version})

``make_inputs(rng)`` gets a seeded ``numpy.random.Generator`` and returns a list of cases;
a case is a dict of keyword arguments (preferred: the names appear in the report) or a
tuple of positional arguments. A hint maps a message to a *wrong version* of the
reference (same signature) that makes the mistake: when the learner's output matches the
wrong version's output, the message is shown. Without a matching hint, a few generic ones are
tried: a flipped sign, a constant factor or offset, a shift by one position (``<`` versus ``<=``),
differences along the wrong image axis (the reference run on transposed images), a
scatter-add that kept one contribution per repeated index (fancy-index ``+=`` for ``np.add.at``), and
an image shifted by one row or column towards its start (indices counted from 1, ``a[y - 1, x - 1]``).

A hint is shown only when the learner's output also matches the wrong version on the other inputs
where that mistake shows, so that one input cannot make two different mistakes look alike. Beyond the
values, a check fails a function that changes an input array in place (even when its result is right),
a tensor result cut off from the autograd graph where the reference's is differentiable (cases mark such
inputs with ``requires_grad``), or whose gradients with respect to those inputs differ from the reference's (a new
leaf made with ``requires_grad=True``, a term taken out of the graph, ``.backward()`` called inside), and a list or
a tensor where the reference returns a numpy array. Memory freed in the sizes of the reference's result is filled
with a pattern before each call (blocks of up to 1 MiB; a larger result's memory is not filled), so that an array
started with np.empty does not pass by holding zeros. An
exception is reported at the learner's own line, even when numpy or torch raised it deeper down. The last input
is run a second time, from other states of the global random generators: a function fails that then answers
differently (state kept between calls), that hands out the same array, tensor or dict again (a buffer or a cached
result, which the next call or the caller changes), or that reseeds a global generator (np.random.seed,
torch.manual_seed, random.seed); so does one that changes torch's settings for the whole notebook (gradients
switched off, or on where the notebook had them off; the default dtype), numpy's error handling (np.seterr) or the
warning filters (warnings.filterwarnings), which the check sets back after every call (the hints' calls too) and
once more at its end.

``use`` says "not finished" for a stub that still raises ``NotImplementedError`` and "does not
pass the check yet" for a finished function that gives wrong results. For a function with side
effects (one optimiser step, say), ``register(..., observe=...)`` says what to compare after the call.

This module holds the registry and the entry points (``check``, ``use``); the check itself (comparing outputs,
running the learner's function, the hints, the mistakes seen across calls, the main loop and its order) lives in
:mod:`evinr_lite.teaching.checking`, one job per module, whose docstring lists them.
"""
from __future__ import annotations

import inspect
import warnings
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

from .checking.run_check import NOT_DONE, run_check
from .notebook_calls import NOTEBOOK_CALLS, NotebookCall

__all__ = [
    "Exercise", "ExerciseWarning", "register", "unregister", "exercise", "get", "names", "reference",
    "check", "use", "solution_or_reference", "show_reference",
]

SEED = 0


class ExerciseWarning(UserWarning):
    """An exercise is unfinished or wrong, and the reference solution is used instead."""


@dataclass
class Exercise:
    """One registered exercise (see the module docstring)."""

    name: str
    reference: Callable
    make_inputs: Callable[[np.random.Generator], list]
    hints: dict[str, Callable] = field(default_factory=dict)
    rtol: float = 1e-5
    atol: float = 1e-8
    compare: Callable[[Any, Any], str | None] | None = None
    observe: Callable[[Any, tuple, dict], Any] | None = None
    call: NotebookCall | None = None     # how the notebooks call it (notebook_calls.py); None for an exercise of none

    def cases(self) -> list[tuple[tuple, dict]]:
        """The seeded inputs as (args, kwargs) pairs."""
        out = []
        for case in self.make_inputs(np.random.default_rng(SEED)):
            if isinstance(case, dict):
                out.append(((), dict(case)))
            elif isinstance(case, tuple):
                out.append((case, {}))
            else:
                raise TypeError(f"exercise {self.name!r}: make_inputs must return dicts or tuples, got {type(case)}")
        return out


_REGISTRY: dict[str, Exercise] = {}


def register(name: str, reference: Callable, make_inputs: Callable, *, hints: dict | None = None,
             rtol: float = 1e-5, atol: float = 1e-8,
             compare: Callable[[Any, Any], str | None] | None = None,
             observe: Callable[[Any, tuple, dict], Any] | None = None) -> Exercise:
    """Register (or replace) an exercise.

    Args:
        name: the exercise's name, used in ``check(name, fn)``.
        reference: the reference solution.
        make_inputs: ``make_inputs(rng) -> list of cases`` (dicts of keyword arguments or
            tuples of positional arguments); keep them small.
        hints: ``{message: wrong_version}``; the message is shown when the learner's output
            matches ``wrong_version``'s output on the failing input.
        rtol, atol: tolerances for comparing numbers (``numpy.isclose``).
        compare: optional ``compare(got, expected) -> message or None`` replacing the
            built-in comparison.
        observe: optional ``observe(result, args, kwargs) -> value``: what is compared, for a
            function with side effects. It gets the function's result and the (copied) inputs
            *after* the call, e.g. a model's parameters after one optimiser step.
    """
    if not callable(reference) or not callable(make_inputs):
        raise TypeError("register needs a callable reference and a callable make_inputs(rng)")
    ex = Exercise(name, reference, make_inputs, dict(hints or {}), rtol, atol, compare, observe,
                  NOTEBOOK_CALLS.get(name))
    _REGISTRY[name] = ex
    return ex


def unregister(name: str) -> None:
    """Forget exercise ``name`` (a toy exercise a test registered); an unknown name is ignored."""
    _REGISTRY.pop(name, None)


def exercise(name: str, make_inputs: Callable, **kwargs) -> Callable:
    """Decorator form of :func:`register`: ``@exercise("name", make_inputs)`` above the reference."""
    def wrap(reference):
        register(name, reference, make_inputs, **kwargs)
        return reference
    return wrap


def get(name: str) -> Exercise:
    """The registered exercise ``name`` (KeyError listing the known names otherwise).

    The registry is filled when :mod:`evinr_lite.teaching` is imported (its face imports every
    module that registers exercises), which any import of this module does first.
    """
    if name not in _REGISTRY:
        raise KeyError(f"no exercise named {name!r}; known exercises: {', '.join(names()) or 'none'}")
    return _REGISTRY[name]


def names() -> list[str]:
    return sorted(_REGISTRY)


def reference(name: str) -> Callable:
    """The reference solution of exercise ``name``."""
    return get(name).reference


def show_reference(name: str) -> None:
    """Print the reference solution's source (to compare after trying)."""
    print(inspect.getsource(get(name).reference))


def check(name: str, fn: Callable, *, verbose: bool = True) -> bool:
    """Run ``fn`` against exercise ``name``'s reference and print a ✓/✗ report. Never raises.

    Returns:
        True when ``fn`` matches the reference on every seeded input.
    """
    try:
        ex = get(name)
    except KeyError as err:
        if verbose:
            print(f"✗ {err.args[0]}")
        return False
    try:
        ok, headline, details = run_check(ex, fn)
    except Exception as err:  # never raise from a check
        ok, headline, details = False, f"the check itself failed ({type(err).__name__}: {err})", []
    if verbose:
        print(f"{'✓' if ok else '✗'} {name}: {headline}")
        for line in details:
            print(f"    {line}")
    return ok


def use(name: str, fn: Callable, *, verbose: bool = True) -> Callable:
    """``fn`` when it passes exercise ``name``'s check, otherwise the reference solution.

    When the reference is used, a warning (:class:`ExerciseWarning`) and a printed banner
    say so, so that the cells below still run and the reader knows whose code they run.
    """
    ex = get(name)  # an unknown name is a mistake in the notebook itself: raise
    try:
        ok, headline, _ = run_check(ex, fn)
    except Exception as err:
        ok, headline = False, f"the check itself failed ({type(err).__name__}: {err})"
    if ok:
        if verbose:
            print(f"✓ Using your {name}.")
        return fn
    # "not finished" only for a stub that still raises NotImplementedError; a finished function
    # that gives wrong values "does not pass the check yet" (its author did finish it).
    state = "is not finished" if headline.startswith(NOT_DONE) else "does not pass the check yet"
    banner = f"⚠ Exercise '{name}' {state}: the cells below use the reference solution."
    if verbose:
        rule = "=" * 88
        print(f"{rule}\n{banner}\n  Why: {headline}.\n"
              f"  Run exercises.check({name!r}, your_function) for details.\n{rule}")
    warnings.warn(f"Exercise '{name}' {state} ({headline}); the cells below use the reference solution.",
                  ExerciseWarning, stacklevel=2)
    return ex.reference


solution_or_reference = use
