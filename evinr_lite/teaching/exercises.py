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
inputs with ``requires_grad``), and a list or a tensor where the reference returns a numpy array. An
exception is reported at the learner's own line, even when numpy or torch raised it deeper down. The last input
is run a second time, from other states of the global random generators: a function fails that then answers
differently (state kept between calls), that hands out the same array, tensor or dict again (a buffer or a cached
result, which the next call or the caller changes), or that reseeds a global generator (np.random.seed,
torch.manual_seed, random.seed); so does one that changes torch's settings for the whole notebook (gradients
switched off, or on where the notebook had them off; the default dtype), which the check sets back after every call
(the hints' calls too) and once more at its end.

``use`` says "not finished" for a stub that still raises ``NotImplementedError`` and "does not
pass the check yet" for a finished function that gives wrong results. For a function with side
effects (one optimiser step, say), ``register(..., observe=...)`` says what to compare after the call.
"""
from __future__ import annotations

import copy
import inspect
import os
import random
import re
import site
import sys
import sysconfig
import traceback
import warnings
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

__all__ = [
    "Exercise", "ExerciseWarning", "register", "exercise", "get", "names", "reference",
    "check", "use", "solution_or_reference", "show_reference",
]

SEED = 0
NOT_DONE = "not done yet"  # the headline's start for a stub that raises NotImplementedError


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
    ex = Exercise(name, reference, make_inputs, dict(hints or {}), rtol, atol, compare, observe)
    _REGISTRY[name] = ex
    return ex


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


# ---- comparing outputs ------------------------------------------------------------

def _is_tensor(x) -> bool:
    return type(x).__module__.startswith("torch") and hasattr(x, "detach")


def _to_numpy(x):
    if _is_tensor(x):
        x = x.detach().cpu()
        return (x.float() if str(x.dtype) == "torch.bfloat16" else x).numpy()   # numpy has no bfloat16
    return np.asarray(x)


def _is_bfloat16(x) -> bool:
    return _is_tensor(x) and str(x.dtype) == "torch.bfloat16"


def _fmt(v) -> str:
    if isinstance(v, (float, np.floating)):
        return f"{float(v):.4g}"
    return str(v)


def _fmt_pair(a, b) -> tuple[str, str]:
    """Two numbers formatted so that they read differently when they differ (4 digits, more when needed)."""
    fa, fb = _fmt(a), _fmt(b)
    if fa == fb and isinstance(a, (float, np.floating)) and isinstance(b, (float, np.floating)) and a != b:
        return f"{float(a):.12g}", f"{float(b):.12g}"
    return fa, fb


def _describe_value(v) -> str:
    if not isinstance(v, (np.ndarray, np.generic, int, float, str, bool, list, tuple, dict)) and not _is_tensor(v) \
            and v is not None and ("\n" in repr(v) or len(repr(v)) > 60):
        return type(v).__name__          # a model or an optimiser: its repr would fill the report
    if _is_tensor(v):
        return f"tensor {str(v.dtype).replace('torch.', '')}{list(v.shape)}"
    if isinstance(v, np.ndarray):
        return f"{v.dtype}{list(v.shape)}" if v.size > 4 else np.array2string(v, precision=3)
    if isinstance(v, (list, tuple)) and len(v) > 4:
        return f"{type(v).__name__} of {len(v)}"
    if isinstance(v, dict) and len(repr(v)) > 60:          # a table of rows: its repr would fill the headline
        return f"dict of {len(v)} items ({', '.join(repr(k) for k in list(v)[:4])}{', ...' if len(v) > 4 else ''})"
    return _fmt(v) if isinstance(v, (int, float, np.number)) else repr(v)


def _describe_case(args: tuple, kwargs: dict) -> str:
    parts = [_describe_value(a) for a in args] + [f"{k}={_describe_value(v)}" for k, v in kwargs.items()]
    return ", ".join(parts)


def _kind(a: np.ndarray) -> str:
    return {"b": "bool", "i": "integer", "u": "integer", "f": "float", "c": "complex"}.get(a.dtype.kind, str(a.dtype))


@dataclass
class _Problem:
    message: str
    values: bool = False  # True when shapes/types agree and only the numbers differ


def _compare(got, expected, rtol: float, atol: float, where: str = "") -> _Problem | None:
    at = f" in output {where}" if where else ""
    if got is None and expected is not None:
        return _Problem(f"returned None{at}; did you forget the `return` statement?")
    if isinstance(expected, (tuple, list)):
        if not isinstance(got, (tuple, list)):
            return _Problem(f"returned a {type(got).__name__}{at}, expected a {type(expected).__name__} of {len(expected)} items")
        if len(got) != len(expected):
            return _Problem(f"returned {len(got)} items{at}, expected {len(expected)}")
        for k, (g, e) in enumerate(zip(got, expected)):
            p = _compare(g, e, rtol, atol, f"{where}[{k}]")
            if p is not None:
                return p
        return None
    if isinstance(expected, dict):
        if not isinstance(got, dict):
            return _Problem(f"returned {type(got).__name__}{at}, expected a dict with keys {sorted(expected)}")
        if set(got) != set(expected):
            missing = sorted(set(expected) - set(got), key=str)
            extra = sorted(set(got) - set(expected), key=str)
            return _Problem(f"returned a dict{at} with the wrong keys: missing {missing}, not expected {extra}; "
                            "use the input's keys unchanged (the same spelling and case)")
        for k in expected:
            p = _compare(got[k], expected[k], rtol, atol, f"{where}[{k!r}]")
            if p is not None:
                return p
        return None
    if _is_tensor(expected) and not _is_tensor(got):
        if expected.is_floating_point():
            return _Problem(f"returned a {type(got).__name__}{at}, expected a torch.Tensor: keep the computation "
                            "in torch so that it can be back-propagated")
        return _Problem(f"returned a {type(got).__name__}{at}, expected a torch.Tensor like the input: use torch "
                        "operations on the tensor (no .numpy() or Python lists)")
    if _is_tensor(expected) and expected.requires_grad and not got.requires_grad:
        return _Problem(f"the result{at} is cut off from the autograd graph (it does not require grad): keep the "
                        "computation in torch operations on the inputs, without .item(), float(), .numpy(), "
                        ".detach() or torch.tensor(...) on an intermediate value, so that it can be back-propagated")
    if isinstance(expected, np.ndarray) and _is_tensor(got):
        return _Problem(f"returned a torch.Tensor{at}, expected a numpy array: compute with numpy, or convert "
                        "with `.detach().cpu().numpy()`")
    if isinstance(expected, np.ndarray) and isinstance(got, (list, tuple)):
        return _Problem(f"returned a {type(got).__name__}{at}, expected a numpy array: return "
                        "`np.asarray(...)` of it (later cells use array methods such as .shape)")
    if isinstance(expected, (np.ndarray, np.generic, int, float, bool)) or _is_tensor(expected):
        try:
            g = _to_numpy(got)
        except Exception:
            return _Problem(f"returned a {type(got).__name__}{at}, expected numbers")
        e = _to_numpy(expected)
        if g.dtype == object or g.dtype.kind not in "biufc":
            return _Problem(f"returned {type(got).__name__} of dtype {g.dtype}{at}, expected numbers")
        if g.shape != e.shape:
            return _Problem(f"wrong shape{at}: got {g.shape}, expected {e.shape}" + _shape_note(g, e))
        if _kind(g) != _kind(e):
            return _Problem(f"wrong dtype{at}: got {_kind(g)} ({g.dtype}), expected {_kind(e)} ({e.dtype})"
                            + _dtype_note(g, e))
        close = np.isclose(g, e, rtol=rtol, atol=atol, equal_nan=True)
        if np.all(close):
            return None
        if g.dtype.kind == "u" and np.any(e < 0):
            return _Problem(f"wrong values{at}: an unsigned dtype ({g.dtype}) cannot hold the negative values "
                            "expected (-1 wraps round to the largest value): use a signed integer dtype (np.int64)")
        if _is_bfloat16(got) and not _is_bfloat16(expected):
            return _Problem(f"wrong values{at}: the result is bfloat16 (about 3 significant digits: `.bfloat16()`, "
                            "or torch.autocast), too coarse for these values: compute and return float32 like the "
                            "inputs")
        if g.dtype == np.float16 and e.dtype != np.float16:
            return _Problem(f"wrong values{at}: the result is float16 (half precision, about 3 significant "
                            "digits), too coarse for these values: compute and return float64 (or float32)")
        if g.dtype == np.float32 and e.dtype == np.float64 and np.allclose(g, e, rtol=1e-3, atol=1e-6 + atol):
            return _Problem(f"wrong values{at}: the result is float32 (about 7 significant digits) and differs from "
                            f"the expected float64 values in the last digits, beyond this exercise's tolerance "
                            f"(rtol {rtol:g}): compute in float64 (np.asarray(..., dtype=np.float64))")
        bad = np.flatnonzero(~close.ravel())
        diff = np.abs(g.astype(np.float64) - e.astype(np.float64)).ravel()
        diff = np.where(np.isnan(diff), np.inf, diff)
        worst = int(bad[np.argmax(diff[bad])])
        if e.ndim == 0:
            gs, es = _fmt_pair(g.item(), e.item())
            return _Problem(f"wrong value{at}: got {gs}, expected {es}", values=True)
        idx = np.unravel_index(worst, e.shape)
        idx_s = str(idx[0]) if len(idx) == 1 else str(tuple(int(i) for i in idx))
        gs, es = _fmt_pair(g.ravel()[worst], e.ravel()[worst])
        return _Problem(f"wrong values{at}: {bad.size} of {e.size} differ; at index {idx_s}: got {gs}, expected {es}",
                        values=True)
    # anything else: plain equality
    if got != expected:
        return _Problem(f"got {got!r}{at}, expected {expected!r}", values=True)
    return None


def _shape_note(g: np.ndarray, e: np.ndarray) -> str:
    """A word on a wrong shape that names a common cause: a transposed result, indices for a mask, an array
    holding one number where a number is expected."""
    if e.ndim >= 2 and g.ndim == e.ndim and g.shape[:-2] == e.shape[:-2] and g.shape[-2:] == e.shape[-2:][::-1]:
        return ("; the last two axes are swapped: a transposed result, or (H, W) read as (W, H) (sensor_size and "
                "images are rows first: `H, W = sensor_size`, `np.zeros((H, W))`, `a[y, x]`)")
    if e.dtype == bool and g.dtype.kind in "iu" and g.size <= e.size:
        return ("; that looks like the indices of the True entries (np.flatnonzero, np.where, np.argwhere): "
                "return the boolean mask itself, one entry per element")
    if e.ndim == 1 and g.ndim == 1 and abs(g.shape[0] - e.shape[0]) == 1:
        more = "one entry too many" if g.shape[0] > e.shape[0] else "one entry too few"
        return f"; {more}: an off-by-one (a loop's range, a slice, or a count rounded the wrong way)?"
    if e.ndim >= 3 and g.ndim == e.ndim and g.shape[1:] == e.shape[1:] and abs(g.shape[0] - e.shape[0]) == 1:
        more = "one entry too many" if g.shape[0] > e.shape[0] else "one entry too few"
        return (f"; {more} along the first axis: an off-by-one (a loop's range, a slice, np.diff's `prepend=` "
                "that keeps the length: B + 1 boundaries make B bins)?")
    if e.ndim == 0 and g.size == 1:
        return ("; that is an array holding one number where the number itself is expected: take it out "
                "(`x[0]`, `x.squeeze()`, or `float(x)` for a numpy result), e.g. np.linalg.lstsq returns an array")
    if e.ndim == 0 and g.size > 1:
        return (f"; one number is expected, not {g.size}: reduce over every entry (np.mean(x) or torch.mean(x) "
                "without `axis=` / `dim=`), and return that number alone")
    if g.size == e.size and g.size > 1 and tuple(d for d in g.shape if d != 1) == tuple(d for d in e.shape if d != 1):
        return ("; the same number of entries with an extra or missing axis of length 1 (a column (N, 1) for a "
                "1-D (N,), say): drop `[:, None]` / `reshape(-1, 1)` / `keepdims=True`, or `.ravel()` the result")
    return ""


def _dtype_note(g: np.ndarray, e: np.ndarray) -> str:
    """A word on a wrong dtype that names a common cause."""
    if e.dtype == bool and g.dtype.kind in "iuf":
        return ": return the comparison itself (a boolean mask), without .astype(int) or multiplying by 1"
    if e.dtype.kind in "iu" and g.dtype.kind == "f":
        return (": `/` (and np.trunc, np.floor, np.round) give floats: use integer division `//` "
                "(torch.div(..., rounding_mode='floor')), or convert with .astype(np.int64) after rounding; an "
                "array made without a dtype (np.zeros(n), np.full(n, p)) is float too: give dtype=")
    if e.dtype.kind == "f" and g.dtype.kind in "iu":
        return (": the values were made whole numbers: no .astype(int) or int(...) on the result, and no integer "
                "array to fill (np.zeros(..., dtype=int), or np.zeros_like of an integer input such as x or p)")
    return ""


def _generic_hint(got, expected, indexed: bool = False) -> str | None:
    """Recognise a few common patterns between a wrong and a right numeric output.

    ``indexed``: the inputs hold an index array with repeated entries (event coordinates, say),
    so a scatter-add that kept one contribution per index is a likely mistake.
    """
    try:
        g = _to_numpy(got).astype(np.float64).ravel()
        e = _to_numpy(expected).astype(np.float64).ravel()
    except Exception:
        return None
    if g.shape != e.shape or g.size == 0 or not np.all(np.isfinite(e)):
        return None
    if not np.all(np.isfinite(g)):
        return ("the result holds NaN or inf where every expected value is finite: a division by zero, or the log "
                "of zero or of a negative number?")
    scale = max(np.abs(e).max(), 1e-12)
    tol = 1e-6 * scale
    if _to_numpy(got).dtype == bool and _to_numpy(expected).dtype == bool and g.size > 1 and np.all(g != e):
        return "the mask is inverted everywhere: True where False is expected and the other way round (`~` once too often?)"
    nz = np.abs(e) > tol
    # a single non-zero entry of an array flipped may be anything else that lands on minus it: say so only when
    # several entries agree (a single number, a scalar result, may have its sign flipped on its own)
    if np.all(np.abs(g + e) <= tol) and nz.sum() >= (1 if e.size == 1 else 2):
        return "the sign is flipped everywhere"
    with np.errstate(all="ignore"):
        if np.all(np.abs(e) < 700) and np.allclose(g, np.exp(e), rtol=1e-6, atol=1e-9):
            return ("the result is np.exp of the expected values: the quantity is a log intensity (or a change of "
                    "one), so no np.exp (exp(L) is the linear intensity)")
        if np.all(e > 0) and np.allclose(g, np.log(e), rtol=1e-6, atol=1e-9):
            return "the result is np.log of the expected values: no np.log on this quantity (it is not a log yet)"
    # one number (or one non-zero entry) is always some factor of another: say so only when several agree
    if nz.sum() >= 2 and np.all(np.abs(g[~nz]) <= tol):
        ratios = g[nz] / e[nz]
        if np.ptp(ratios) <= 1e-6 * max(1.0, abs(ratios[0])) and abs(ratios[0] - 1) > 1e-6 \
                and abs(ratios[0]) > 1e-12:         # a factor 0 is a result of zeros, not a scaling
            return f"off by a constant factor: got {ratios[0]:.4g} x the expected values" + _unit_note(ratios[0])
    if g.size > 1:
        d = g - e
        if np.ptp(d) <= tol and abs(d[0]) > tol:
            return f"off by a constant offset of {d[0]:.4g}"
        # a shift is recognisable only in a series of several distinct values (not in a short mask)
        if g.size >= 4 and np.unique(e).size > 2 and (np.allclose(g[1:], e[:-1], atol=tol)
                                                      or np.allclose(g[:-1], e[1:], atol=tol)):
            return "the values are shifted by one position; check the window/boundary indexing (< versus <=)"
    axes = _axes_hint(_to_numpy(got), _to_numpy(expected), tol)
    if axes:
        return axes
    if indexed and _one_contribution_per_entry(g, e, tol):
        return ("each entry holds at most one contribution where several are expected: with fancy indexing, "
                "`a[idx] += v` adds only once for a repeated index; accumulate with `np.add.at(a, idx, v)` "
                "(or `np.bincount(idx, weights=v)`, or `index_put_(..., accumulate=True)` in torch)")
    return None


def _unit_note(ratio: float) -> str:
    """A word on a factor that is a power of 1000: a unit conversion."""
    k = np.log10(abs(ratio)) / 3 if ratio else 0.0
    if ratio > 0 and abs(k - round(k)) < 1e-6 and round(k) != 0:
        return (" (a power of 1000: a unit conversion? the kit's times are seconds throughout, rates per second: "
                "no milliseconds or microseconds)")
    return ""


def _axes_hint(g: np.ndarray, e: np.ndarray, tol: float) -> str | None:
    """A pair of outputs (x part, y part) returned in the wrong order."""
    g = np.asarray(g, dtype=np.float64)
    e = np.asarray(e, dtype=np.float64)
    if g.shape != e.shape or g.ndim < 2 or g.shape[0] != 2 or g[0].size < 2:
        return None
    if np.allclose(g[::-1], e, atol=tol) and not np.allclose(g, e, atol=tol):
        return ("the two outputs are swapped: return them in the order the docstring gives (for image "
                "differences, x is the column axis (axis -1, `np.diff(a, axis=-1)`), y the row axis (axis -2))")
    return None


def _swap_last_axes(v):
    """``v`` with the last two axes of every array (or tensor) of >= 2 dimensions swapped, recursively."""
    if _is_tensor(v):
        return v.transpose(-1, -2) if v.dim() >= 2 else v
    if isinstance(v, np.ndarray):
        return np.swapaxes(v, -1, -2) if v.ndim >= 2 else v
    if isinstance(v, tuple):
        return tuple(_swap_last_axes(x) for x in v)
    if isinstance(v, list):
        return [_swap_last_axes(x) for x in v]
    return v


def _has_image(v) -> bool:
    if _is_tensor(v):
        return v.dim() >= 2 and v.shape[-1] > 1 and v.shape[-2] > 1
    if isinstance(v, np.ndarray):
        return v.ndim >= 2 and v.shape[-1] > 1 and v.shape[-2] > 1
    if isinstance(v, (tuple, list)):
        return any(_has_image(x) for x in v)
    return False


def _wrong_axes_hint(ex: "Exercise", args: tuple, kwargs: dict, got, expected=None) -> str | None:
    """The learner's output equals the reference run on transposed images, transposed back.

    That is the sign of differences (or sums) taken along the wrong image axis: rows for columns.
    A candidate that equals the expected output itself (an exercise symmetric under the swap) says nothing.
    """
    if not (any(_has_image(a) for a in args) or any(_has_image(v) for v in kwargs.values())):
        return None
    try:
        w = _run(ex.reference, _swap_last_axes(args), {k: _swap_last_axes(v) for k, v in kwargs.items()}, ex.observe)
        w = _swap_last_axes(w)
    except Exception:
        return None
    candidates = [w] + ([type(w)(reversed(w))] if isinstance(w, (tuple, list)) and len(w) == 2 else [])
    for c in candidates:
        try:
            if expected is not None and _compare(c, expected, ex.rtol, ex.atol) is None:
                continue
            if _compare(got, c, ex.rtol, ex.atol) is None:
                return ("the differences (or sums) run along the wrong image axis: x is the column "
                        "index (axis -1), y the row index (axis -2)")
        except Exception:
            continue
    return None


def _one_based_hint(got, expected, rtol: float, atol: float) -> str | None:
    """An image (or a stack of images) rolled by one row and/or one column towards the start: the values of row
    (column) 0 sit in the last one. That is indexing counted from 1, ``a[y - 1, x - 1]``: index -1 wraps round."""
    try:
        g, e = _to_numpy(got), _to_numpy(expected)
        if g.dtype == object or g.shape != e.shape or e.ndim < 2 or min(e.shape[-2:]) < 2:
            return None
        for shift, axes, what in (((-1, -1), (-2, -1), "one row and one column"), ((-1,), (-2,), "one row"),
                                  ((-1,), (-1,), "one column")):
            if _compare(g, np.roll(e, shift, axis=axes), rtol, atol) is None:
                return (f"the image is shifted by {what}, and the first one's values sit in the last one: indices "
                        "counted from 1 (`a[y - 1, x - 1]`) put row (column) 0 at index -1, which wraps round to the "
                        "end; numpy counts from 0, so index with y and x as they are")
    except Exception:
        return None
    return None


def _one_contribution_per_entry(g: np.ndarray, e: np.ndarray, tol: float) -> bool:
    """True when ``g`` looks like a scatter-add that kept one contribution per repeated index.

    The sign of that mistake: the non-zero entries of ``g`` all have one magnitude (one event's
    contribution), sit where ``e`` is non-zero or where contributions cancelled, and ``e`` has at
    least one entry made of several contributions (a larger magnitude).
    """
    nzg = np.abs(g) > tol
    if nzg.sum() < 2 or g.size < 2:      # a single non-zero entry always has "one magnitude"
        return False
    mags = np.abs(g[nzg])
    unit = mags[0]
    if np.ptp(mags) > 1e-6 * max(unit, 1e-12):
        return False
    differ = np.abs(g - e) > tol
    return bool(differ.any() and np.any(np.abs(e[differ]) > unit * (1 + 1e-6)))


def _is_repeated_index(v) -> bool:
    """An integer index array (values beyond the +-1 of polarities) in which some index repeats."""
    a = _to_numpy(v) if _is_tensor(v) else v
    if not isinstance(a, np.ndarray) or a.ndim != 1 or a.dtype.kind not in "iu" or a.size < 2:
        return False
    return bool(np.abs(a).max() > 1 and np.unique(a).size < a.size)


def _has_repeated_index(args: tuple, kwargs: dict) -> bool:
    """Any input (or an input's ``x`` / ``y`` attribute, as on Events) that is a repeated index array."""
    for v in list(args) + list(kwargs.values()):
        for item in (v, getattr(v, "x", None), getattr(v, "y", None)):
            try:
                if item is not None and _is_repeated_index(item):
                    return True
            except Exception:
                continue
    return False


def _non_square(args, kwargs) -> bool:
    """True when an input names a sensor (a ``sensor_size`` argument, or events carrying one) with H != W."""
    for v in (*args, *kwargs.values()):
        size = v if isinstance(v, tuple) and len(v) == 2 and all(isinstance(a, (int, np.integer)) for a in v) \
            else getattr(v, "sensor_size", None)
        if size is not None and len(size) == 2 and int(size[0]) != int(size[1]):
            return True
    return False


def _library_file(filename: str) -> bool:
    """A file of an installed library or of Python itself (numpy, torch, the standard library), not the learner's
    notebook or module (nor this kit, whose frames say which of its functions the learner's call broke)."""
    path = os.path.realpath(filename)
    if path.startswith(_KIT_ROOT + os.sep):          # the kit itself, installed into site-packages or not
        return False
    return any(path.startswith(root + os.sep) for root in _LIBRARY_ROOTS)


def _site_dirs() -> list:
    """site-packages folders beyond sysconfig's: the system's (Debian's dist-packages) and the user's (some
    virtualenvs' site module lacks either function)."""
    user = getattr(site, "getusersitepackages", lambda: None)()
    return [*getattr(site, "getsitepackages", lambda: [])(), *([user] if user else [])]


_KIT_ROOT = os.path.realpath(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))   # evinr_lite/
_LIBRARY_ROOTS = tuple(sorted({os.path.realpath(p) for p in
                               [*(sysconfig.get_paths().get(k) for k in ("stdlib", "platstdlib", "purelib", "platlib")),
                                *_site_dirs()] if p}))


def _cache_raised(fn: Callable, err: BaseException) -> bool:
    """An "unhashable type" TypeError that a cache raised: ``fn`` is an lru_cache (it has ``cache_info``), the
    error came from no line of the learner's code (the cache's wrapper, in C, builds the key before the call), or
    the learner's line that raised calls a notebook function that is an lru_cache (a cached helper)."""
    if hasattr(fn, "cache_info"):
        return True
    frames = [f for f in traceback.extract_tb(err.__traceback__) if f.filename != __file__]
    own = [f for f in frames if not _library_file(f.filename)]
    if not own:
        return True
    namespace = getattr(fn, "__globals__", None)
    line = own[-1].line or ""
    if isinstance(namespace, dict) and line:
        for name in re.findall(r"[A-Za-z_][A-Za-z0-9_]*(?=\s*\()", line):
            if hasattr(namespace.get(name), "cache_info"):
                return True
    return False


def _where_raised(err: BaseException) -> list[str]:
    """The line of the learner's code that raised: the last frame outside this module and outside the libraries it
    called (an error raised deep inside numpy or torch is reported at the learner's line that called them)."""
    frames = [f for f in traceback.extract_tb(err.__traceback__) if f.filename != __file__]
    if not frames:
        return []
    own = [f for f in frames if not _library_file(f.filename)]
    f = (own or frames)[-1]
    code = f": `{f.line.strip()}`" if f.line else ""
    return [f"raised in {f.name}, line {f.lineno}{code}"]


def _deepcopy_with_grads(x):
    """``copy.deepcopy(x)``, also copying the ``.grad`` of torch parameters (which deepcopy drops),
    so that a case can hold a model with gradients left from an earlier step."""
    memo: dict = {}
    y = copy.deepcopy(x, memo)
    for orig in memo.get(id(memo), []):
        grad = getattr(orig, "grad", None) if _is_tensor(orig) else None
        new = memo.get(id(orig))
        if grad is not None and new is not None and new is not orig and getattr(new, "grad", None) is None:
            new.grad = grad.detach().clone()
    return y


def _run(fn, args, kwargs, observe=None, inputs_after: list | None = None, settings_changed: dict | None = None):
    """``fn`` on a deep copy of the inputs (one copy, so objects shared between inputs stay shared,
    e.g. a model and its optimiser); with ``observe``, what it says to compare. ``inputs_after``, a list,
    receives the copied ``(args, kwargs)`` as they are after the call.

    torch's global settings (grad mode, default dtype) are set back after every call, whether it returns or
    raises, so that a function that changes them on one input changes nothing for the calls after it (the
    reference's, the hints' wrong versions) nor for the notebook; ``settings_changed``, a dict, receives what
    the call changed ({name: (before, after)}). What the learner's function changed on any call of the check
    (the hints' calls too) is also kept for the report (see :func:`_evaluate`)."""
    args, kwargs = _deepcopy_with_grads((args, kwargs))
    settings = _torch_settings()
    try:
        result = fn(*args, **kwargs)
    finally:
        changed = _restore_torch_settings(settings)
        if settings_changed is not None:
            settings_changed.update(changed)
        if changed and _WATCH and fn is _WATCH[-1][0]:
            for name, change in changed.items():
                _WATCH[-1][1].setdefault(name, change)
    if inputs_after is not None:
        inputs_after.append((args, kwargs))
    return result if observe is None else observe(result, args, kwargs)


def _arrays_of(v) -> list[tuple[str, Any]]:
    """The arrays (or tensors) an input holds: itself, or the array fields of an object such as ``Events``."""
    if isinstance(v, np.ndarray) or _is_tensor(v):
        return [("", v)]
    fields = getattr(v, "__dict__", None)
    if isinstance(fields, dict) and not hasattr(v, "parameters"):
        return [(f".{k}", a) for k, a in fields.items() if isinstance(a, np.ndarray) or _is_tensor(a)]
    return []


def _same_array(a, b) -> bool:
    try:
        a, b = _to_numpy(a), _to_numpy(b)
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
    if isinstance(a, np.ndarray) or _is_tensor(a) or isinstance(b, np.ndarray) or _is_tensor(b):
        return _same_array(a, b)
    if isinstance(a, (bool, int, float, complex, str, bytes, np.generic, type(None))):
        try:
            return type(a) is type(b) and (bool(a == b) or bool(a != a and b != b))
        except Exception:
            return True
    return True


def _changed_inputs(before: tuple[tuple, dict], after: tuple[tuple, dict]) -> list[str]:
    """Names of the array inputs (or array fields of an input), and of the dict and list inputs (a key added,
    removed or changed, an item appended, the list sorted), that the call changed in place."""
    (args0, kwargs0), (args1, kwargs1) = before, after
    pairs = [(f"argument {k + 1}", a, b) for k, (a, b) in enumerate(zip(args0, args1))]
    pairs += [(name, kwargs0[name], kwargs1[name]) for name in kwargs0 if name in kwargs1]
    changed = []
    for name, v0, v1 in pairs:
        if isinstance(v0, (dict, list)):
            if not _same_contents(v0, v1):
                changed.append(name)
            continue
        for (field_name, a0), (_, a1) in zip(_arrays_of(v0), _arrays_of(v1)):
            if not _same_array(a0, a1):
                changed.append(f"{name}{field_name}")
    return changed


def _in_place_message(changed: list[str], containers: tuple = ()) -> str:
    names = ", ".join(f"`{n}`" for n in changed)
    if containers and set(changed) <= set(containers):
        return (f"changed its input {names} in place (a key added, changed or removed: `row[key] = ...`, "
                "`row.pop(key)`, `del row[key]`; or a list appended to or sorted): the caller's table must stay "
                "as it was, so build a new dict (`{name: ... for name, row in table.items()}`) or work on "
                "`copy.deepcopy(...)` of it")
    return (f"changed its input {names} in place (`x += ...`, `x[...] = ...`, `np.exp(x, out=x)`; "
            "`np.asarray(x, dtype=...)` is x itself when the dtype already matches): the caller's data must "
            "stay as it was, so compute a new array (`x = x + ...`) or work on a copy (`np.array(x, dtype=float)`)")


def _container_names(args: tuple, kwargs: dict) -> tuple:
    """The names `_changed_inputs` gives the dict and list inputs."""
    return tuple([f"argument {k + 1}" for k, a in enumerate(args) if isinstance(a, (dict, list))]
                 + [name for name, v in kwargs.items() if isinstance(v, (dict, list))])



# ---- mistakes seen only across inputs: state kept between calls, a notebook variable for an argument ------

_MUTABLE = (list, dict, set, bytearray, np.ndarray)


def _mutable_defaults(fn: Callable) -> dict[str, Any]:
    """Copies of ``fn``'s default argument values that can change in place (lists, dicts, sets, arrays)."""
    out: dict[str, Any] = {}
    try:
        params = inspect.signature(fn).parameters.values()
    except (TypeError, ValueError):
        return out
    for p in params:
        if isinstance(p.default, _MUTABLE):
            try:
                out[p.name] = copy.deepcopy(p.default)
            except Exception:
                continue
    return out


def _same_value(a, b) -> bool:
    try:
        if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
            return _same_array(a, b)
        return bool(a == b)
    except Exception:
        return True          # cannot tell: say nothing


def _mutable_default_hint(fn: Callable, before: dict[str, Any]) -> str | None:
    """A mutable default argument that changed (or holds data) during the check."""
    try:
        now = {p.name: p.default for p in inspect.signature(fn).parameters.values()}
    except (TypeError, ValueError):
        now = {}
    for name, old in before.items():
        value = now.get(name)
        if not _same_value(old, value) or (isinstance(value, (list, dict, set)) and len(value) > 0):
            return (f"the default value of `{name}` is created once, when the function is defined, and shared by "
                    f"every call: what one call puts in it is still there in the next (it holds data now). Use "
                    f"`{name}=None` and create a fresh one inside the function")
    return None


def _state_hint(fn: Callable, before: dict[str, Any], ex: Exercise, args, kwargs, got,
                first: bool = False) -> str | None:
    """A mutable default argument that changed (or holds data) during the check, or a second call on the same
    input that gives another result: the function keeps state between calls, or draws unseeded random numbers.
    ``first``: the failing input is the first one, where a default cannot hold an earlier call's data yet."""
    hint = None if first else _mutable_default_hint(fn, before)
    if hint is not None or ex.observe is not None:
        return hint
    try:
        again = _run(fn, args, kwargs, ex.observe)
        if _compare(again, got, ex.rtol, ex.atol) is not None:
            return ("called again on the same input, your function returns another result: it keeps state between "
                    "calls (a notebook variable it changes, a mutable default argument), or draws random numbers "
                    "from the global generator (np.random.choice, np.random.randn, torch.randn without a seed of "
                    "its own); compute everything from the arguments, starting afresh in each call, with no "
                    "randomness (nothing here asks for a random sample)")
    except Exception:
        return None
    return None


def _global_containers(fn: Callable) -> dict[str, tuple[int, int]]:
    """The dicts, lists and sets among the notebook variables (``fn``'s globals) that ``fn``'s code names:
    {name: (id, length)}."""
    code, names = getattr(fn, "__code__", None), set()
    namespace = getattr(fn, "__globals__", None)
    if code is None or not isinstance(namespace, dict):
        return {}
    stack = [code]
    while stack:                               # the function's code and the code nested in it (comprehensions)
        c = stack.pop()
        names.update(c.co_names)
        stack += [k for k in c.co_consts if inspect.iscode(k)]
    return {name: (id(v), len(v)) for name in names
            if isinstance(v := namespace.get(name), (dict, list, set))}


def _global_cache_hint(fn: Callable, before: dict[str, tuple[int, int]], ex: Exercise | None = None,
                       case: tuple | None = None, got: Any = None, raised: bool = False) -> tuple[str | None, bool]:
    """A notebook dict, list or set named in ``fn``'s code that gained entries during the check: results (or parts
    of them) kept from one call to the next. Returns (hint, proven): with ``ex`` and ``case`` (the failing input's
    (args, kwargs), where ``fn`` returned ``got`` or ``raised``), ``proven`` says that the kept data made the
    difference: run once more with that variable empty for the call (and put back after), ``fn`` answers otherwise.
    A list the function only logs to (`log.append(len(t))`, a common habit) grows just the same and changes
    nothing: then the hint is only a fallback, for when no other hint applies."""
    now = _global_containers(fn)
    for name, (ident, length) in sorted(before.items()):
        if name in now and now[name][0] == ident and now[name][1] > length:
            gained = now[name][1] - length
            hint = (f"your function keeps data in the notebook variable `{name}` (it gained {gained} "
                    f"entr{'y' if gained == 1 else 'ies'} during the check) and reads it back: an "
                    "input that shares an earlier one's key (the same settings, the same size) gets what was kept "
                    "for the earlier one; compute each result from the arguments, afresh in each call (a cache must "
                    "be keyed by everything the result depends on, the data too)")
            return hint, ex is not None and case is not None and _kept_data_matters(ex, fn, name, case, got, raised)
    return None, False


def _kept_data_matters(ex: Exercise, fn: Callable, name: str, case: tuple, got: Any, raised: bool) -> bool:
    """``fn`` on ``case`` with the notebook variable ``name`` emptied for the call (a shallow copy, cleared: a
    defaultdict keeps its factory) gives another answer than ``got`` (a result where it raised, or another
    result); the variable is put back whatever happens. Cannot tell (it raises again, or otherwise): False."""
    namespace = fn.__globals__
    kept = namespace.get(name)
    try:
        empty = copy.copy(kept)
        empty.clear()
    except Exception:
        return False
    namespace[name] = empty
    try:
        fresh = _run(fn, *case, ex.observe)
    except Exception:
        return False
    finally:
        namespace[name] = kept
    if raised:
        return True
    try:
        return _compare(fresh, got, ex.rtol, ex.atol) is not None
    except Exception:
        return False


def _stale_elsewhere(ex: Exercise, cases: list, k: int, subset: tuple, fn_outputs) -> bool:
    """On every other input (but #1) where the learner is wrong, its output is also the reference's with the
    arguments ``subset`` taken from input #1: a coincidence on one input (a phase (0, 0) both times) says nothing."""
    kw0 = cases[0][1]
    for j, (a, kw) in enumerate(cases):
        if j in (0, k):
            continue
        try:
            g = fn_outputs(j)
            if _compare(g, _run(ex.reference, a, kw, ex.observe), ex.rtol, ex.atol) is None:
                continue
            if _compare(g, _run(ex.reference, (), dict(kw, **{name: kw0[name] for name in subset}), ex.observe),
                        ex.rtol, ex.atol) is not None:
                return False
        except Exception:
            return False
    return True


def _stale_argument_hint(ex: Exercise, fn: Callable, cases: list, k: int, got, expected) -> str | None:
    """The learner's output on input ``k`` equals the reference's with one or two arguments taken from input #1
    (and so on every other input where it is wrong): the function reads a notebook variable (or a value fixed in
    the code) in place of those arguments."""
    if k == 0:
        return None
    memo: dict = {}

    def fn_outputs(j):
        if j not in memo:
            memo[j] = _run(fn, *cases[j], ex.observe)
        return memo[j]

    (args0, kw0), (args, kw) = cases[0], cases[k]
    if args or args0:
        return None
    names = [name for name in kw if name in kw0 and not _same_value(kw[name], kw0[name])]
    if ex.observe is not None:       # a model and its optimiser belong together: try the plain numbers alone
        names = [name for name in names
                 if isinstance(kw[name], (int, float, np.number)) and not isinstance(kw[name], bool)]
    subsets = [(a,) for a in names] + [(a, b) for i, a in enumerate(names) for b in names[i + 1:]]
    for subset in subsets[:45]:
        trial = dict(kw, **{name: kw0[name] for name in subset})
        try:
            w = _run(ex.reference, (), trial, ex.observe)
            if _compare(w, expected, ex.rtol, ex.atol) is None or _compare(got, w, ex.rtol, ex.atol) is not None:
                continue
        except Exception:
            continue
        if not _stale_elsewhere(ex, cases, k, subset, fn_outputs):
            continue
        which = ", ".join(f"`{name}`" for name in subset)
        return (f"this is the right result for input #1's {which}, not for this input's: the function uses a "
                f"notebook variable (a global such as the first example's data) or a value fixed in the code in "
                f"place of its argument{'s' if len(subset) > 1 else ''} {which}; use the arguments it is given")
    return None


def _fixed_size_hint(ex: Exercise, cases: list, k: int, got, expected) -> str | None:
    """A result shaped like input #1's expected result (all of it, or the sizes that differ): a size fixed in the
    code, or read from a notebook variable, instead of from the arguments."""
    if k == 0:
        return None
    try:
        g, e = _to_numpy(got), _to_numpy(expected)
        if g.dtype == object or g.shape == e.shape or g.ndim != e.ndim or g.ndim == 0:
            return None
        e0 = _to_numpy(_run(ex.reference, *cases[0], ex.observe))
    except Exception:
        return None
    if e0.ndim != g.ndim or e0.shape == e.shape:
        return None
    if all(gd == ed or gd == fd for gd, ed, fd in zip(g.shape, e.shape, e0.shape)):
        return (f"the result's shape {g.shape} has input #1's sizes (its result is {e0.shape}), not this input's "
                f"{e.shape}: a size fixed in the code (np.zeros(3), `H, W = 4, 4`) or taken from a notebook "
                "variable; read the sizes from the arguments (len(...), .shape, sensor_size)")
    return None


def _size_from_events_hint(args, kwargs, got, expected) -> str | None:
    """An image smaller than the sensor (the last rows or columns missing) where an input gives the sensor's
    size: the size was read off the largest event coordinates."""
    if not any(isinstance(v, tuple) and len(v) == 2 and all(isinstance(a, (int, np.integer)) for a in v)
               or getattr(v, "sensor_size", None) is not None for v in (*args, *kwargs.values())):
        return None
    try:
        g, e = _to_numpy(got), _to_numpy(expected)
    except Exception:
        return None
    if g.ndim < 2 or g.ndim != e.ndim or g.shape[:-2] != e.shape[:-2] or g.shape == e.shape:
        return None
    if all(a <= b for a, b in zip(g.shape[-2:], e.shape[-2:])):
        return ("the image is smaller than the sensor: its size is sensor_size (H, W = sensor_size), not the largest "
                "event coordinates plus one (y.max() + 1, x.max() + 1): pixels that never fired are part of it too")
    return None


def _swapped_pair_hint(ex: Exercise, got, expected) -> str | None:
    """A pair of outputs returned in the other order."""
    if not (isinstance(expected, (tuple, list)) and len(expected) == 2 and isinstance(got, (tuple, list))
            and len(got) == 2):
        return None
    try:
        if _compare(got[::-1], expected, ex.rtol, ex.atol) is None or (
                ex.compare is not None and ex.compare(tuple(got[::-1]), expected) is None):
            return "the two outputs are swapped: return them in the order the docstring gives"
    except Exception:
        return None
    return None


def _scalar_factor_hint(ex: Exercise, fn: Callable, cases: list, k: int, got, expected) -> str | None:
    """One number off by the same factor on every input (a weight such as lam, a 1/2, a sum for a mean)."""
    if ex.observe is not None:
        return None
    try:
        g, e = float(_to_numpy(got)), float(_to_numpy(expected))
        if not (np.isfinite(g) and np.isfinite(e)) or e == 0 or g == 0:
            return None
        ratio = g / e
        seen = 0
        for j, (a, kw) in enumerate(cases):
            if j == k:
                continue
            ej = float(_to_numpy(_run(ex.reference, a, kw)))
            if ej == 0:
                continue
            if abs(float(_to_numpy(_run(fn, a, kw))) / ej - ratio) > 1e-5 * max(1.0, abs(ratio)):
                return None
            seen += 1
    except Exception:
        return None
    if seen == 0:
        return None
    return (f"off by a constant factor: got {ratio:.4g} x the expected value on every input (a weight such as "
            f"lam or 1/2 that does not belong here, a sum where a mean is expected, or the other way round?)"
            + _unit_note(ratio))


_POLARITY_NAMES = ("p", "p_events", "polarity", "polarities")


def _is_pm1(v) -> bool:
    """An integer numpy array of polarities -1 and +1 (with at least one -1)."""
    return isinstance(v, np.ndarray) and v.dtype.kind == "i" and v.size > 0 and bool(np.all(np.abs(v) == 1)) \
        and bool(np.any(v < 0))


def _with_polarities(kwargs: dict, f: Callable) -> dict | None:
    """``kwargs`` with ``f`` applied to every -1/+1 polarity input (an argument named p or p_events, or the ``p``
    of events); None when there is none."""
    out, found = {}, False
    for name, v in kwargs.items():
        if name in _POLARITY_NAMES and _is_pm1(v):
            out[name], found = f(v), True
        elif getattr(v, "sensor_size", None) is not None and _is_pm1(getattr(v, "p", None)):
            ev = copy.copy(v)
            object.__setattr__(ev, "p", f(v.p))        # events hold -1/+1 alone: set the field past the check
            out[name], found = ev, True
        else:
            out[name] = v
    return out if found else None


def _outside_unit(v) -> bool:
    try:
        a = _to_numpy(v)
        return a.dtype.kind == "f" and a.size > 0 and bool(np.any((a < 0) | (a > 1)))
    except Exception:
        return False


def _clip_unit(v):
    return v.clamp(0.0, 1.0) if _is_tensor(v) else np.clip(v, 0.0, 1.0)


def _clipped_inputs(kwargs: dict, only: str | None = None) -> dict | None:
    """``kwargs`` with the float array (or tensor) input ``only`` (or, without it, every one) clipped to [0, 1];
    None when no such input holds values outside [0, 1]."""
    found = {name for name, v in kwargs.items() if (isinstance(v, np.ndarray) or _is_tensor(v)) and _outside_unit(v)
             and only in (None, name)}
    return {name: _clip_unit(v) if name in found else v for name, v in kwargs.items()} if found else None


def _map_numbers(v, f: Callable):
    """``f`` applied to every array, tensor or float inside ``v`` (tuples, lists and dicts kept)."""
    if isinstance(v, dict):
        return {k: _map_numbers(x, f) for k, x in v.items()}
    if isinstance(v, (tuple, list)):
        return type(v)(_map_numbers(x, f) for x in v)
    if isinstance(v, (np.ndarray, float, np.floating)) or _is_tensor(v):
        return f(v)
    return v


def _round_to(d: int) -> Callable:
    def f(v):
        if _is_tensor(v):
            return _torch_round(v, d) if v.is_floating_point() else v
        if isinstance(v, np.ndarray) and v.dtype.kind != "f":
            return v
        r = np.round(v, d)
        return float(r) if isinstance(v, float) else r
    return f


def _torch_round(v, d):
    return (v * 10.0 ** d).round() / 10.0 ** d


def _generic_mistakes(ex: Exercise, cases: list | None = None) -> list[tuple[str, Callable]]:
    """Wrong versions made from the reference, for mistakes that any exercise can show: -1/+1 polarities treated
    as 0/1 (or OFF events dropped), an input or the result clipped to [0, 1], a result rounded for display, one
    float array input rounded (made only for the arguments that are float numpy arrays in some case of
    ``cases``, the exercise's own cases by default). A wrong version made from the inputs has ``applies(args,
    kwargs)``: whether it changes them at all, asked before the inputs are copied for a run."""
    ref = ex.reference

    def on_inputs(change):
        def wrong(*args, **kwargs):
            changed = change(kwargs)
            if args or changed is None:
                raise ValueError("not applicable")
            return ref(**changed)
        wrong.applies = lambda args, kwargs: not args and change(kwargs) is not None
        return wrong

    def on_output(change):
        def wrong(*args, **kwargs):
            return change(ref(*args, **kwargs))
        return wrong

    out = [
        ("the polarities are already -1 and +1 here: `2 * p - 1` (the conversion for polarities stored as 0 and 1) "
         "turns an OFF event's -1 into -3; use p as it is (np.where(p > 0, 1, -1) works for either encoding)",
         on_inputs(lambda kw: _with_polarities(kw, lambda p: 2 * p - 1))),
        ("the OFF events count as 0: the polarities are -1 and +1 and an OFF event subtracts; weights such as "
         "`p > 0`, `p == 1` or `(p + 1) // 2` (a 0/1 encoding) drop them: use p itself",
         on_inputs(lambda kw: _with_polarities(kw, lambda p: (p > 0).astype(p.dtype)))),
    ]
    try:
        params = list(inspect.signature(ref).parameters)
    except (TypeError, ValueError):
        params = []
    for only in [None] + params:            # every array input clipped, or one of them
        what = "an input was" if only is None else f"`{only}` was"
        out.append((f"{what} clipped to [0, 1] (np.clip, torch.clamp) before use: nothing here asks for that "
                    "(only a display image lives in [0, 1]); use the values as they are",
                    on_inputs(lambda kw, only=only: _clipped_inputs(kw, only))))
    out += [
        ("the result is clipped to [0, 1] (np.clip, torch.clamp): nothing here asks for that (only a display "
         "image lives in [0, 1]); return the values unclipped",
         on_output(lambda v: _map_numbers(v, lambda a: _clip_unit(a) if _outside_unit(a) else a))),
    ]
    for d in range(7):
        out.append((f"the values are rounded to {d} decimal{'s' if d != 1 else ''}: return them as computed "
                    "(round only where you print them)", on_output(lambda v, d=d: _map_numbers(v, _round_to(d)))))
    if cases is None:
        try:
            cases = ex.cases()
        except Exception:
            cases = []
    float_arrays = [name for name in params if any(isinstance(kw.get(name), np.ndarray) and kw[name].dtype.kind == "f"
                                                   for _, kw in cases)]
    for only in float_arrays:                # one float array input rounded (times to milliseconds, say); confirmed
        for d in range(7):                   # on a second input: float32 or another rounding can land alike on one
            wrong = on_inputs(lambda kw, only=only, d=d: _rounded_input(kw, only, d))
            wrong.support = 1
            out.append((f"`{only}` was rounded to {d} decimal{'s' if d != 1 else ''} (np.round) before use: nothing "
                        "here asks for that; use the values as given (rounded times move events past one another "
                        "and past the edges of a window or a bin)", wrong))
    return out


def _rounded_input(kwargs: dict, only: str, d: int) -> dict | None:
    """``kwargs`` with the float numpy array ``only`` rounded to ``d`` decimals; None when that changes nothing."""
    v = kwargs.get(only)
    if not (isinstance(v, np.ndarray) and v.dtype.kind == "f" and v.size) or np.array_equal(np.round(v, d), v):
        return None
    return dict(kwargs, **{only: np.round(v, d)})


_WATCH: list = []   # (the learner's function, what its calls changed of torch's settings), one per running check


def _evaluate(ex: Exercise, fn: Callable) -> tuple[bool, str, list[str]]:
    """(passed, headline, detail lines) without printing.

    torch's global settings are set back after every call of a function (see :func:`_run`), and once more, to
    what they were when the check began, after all of it: a function that changes them only on an input the
    main run never reaches (a hint's search runs the others), or that raises right after, leaves the notebook as
    it was. Such a change is named in the report (`also: ...`) when the main run did not name it already."""
    settings = _torch_settings()
    _WATCH.append((fn, {}))
    try:
        ok, headline, details = _evaluate_calls(ex, fn)
        seen = _WATCH[-1][1]
        if seen and not ok and not headline.startswith("changed torch's global settings"):
            details = details + ["also: " + _settings_message(seen)]
        return ok, headline, details
    finally:
        _WATCH.pop()
        _restore_torch_settings(settings)


def _evaluate_calls(ex: Exercise, fn: Callable) -> tuple[bool, str, list[str]]:
    """:func:`_evaluate`'s work: the calls and the report."""
    if not callable(fn):
        return False, f"expected a function, got {type(fn).__name__}", []
    try:
        cases = ex.cases()
    except Exception as err:  # a bug in the exercise itself, not the learner's
        return False, f"could not build the test inputs ({type(err).__name__}: {err})", []
    n = len(cases)
    defaults = _mutable_defaults(fn)
    containers = _global_containers(fn)
    for k, (args, kwargs) in enumerate(cases):
        where = f"input #{k + 1} of {n} ({_describe_case(args, kwargs)})"
        after: list = []
        if k == n - 1:
            rng_before = _rng_states()       # the last input is run again below, from other generator states
        changed_settings: dict = {}
        try:
            got = _run(fn, args, kwargs, ex.observe, inputs_after=after, settings_changed=changed_settings)
            if k == n - 1:
                rng_after = _rng_states()
        except NotImplementedError:
            return False, f"{NOT_DONE}: the function raises NotImplementedError", [
                "Replace `raise NotImplementedError` with your code, run the cell again, then re-check."]
        except Exception as err:
            details = [f"{type(err).__name__}: {err}"] + _where_raised(err)
            if isinstance(err, TypeError) and "unhashable type" in str(err) and _cache_raised(fn, err):
                details.append("hint: a cache (functools.lru_cache, functools.cache, or a dict keyed by the "
                               "arguments) needs hashable arguments, and an array, a list or a dict is not one; "
                               "drop the cache (nothing here is slow enough to need one), or key it by "
                               "something hashable that holds all of the data (a.tobytes()) and return copies")
            elif isinstance(err, TypeError) and "unhashable type" in str(err):
                details.append("hint: an array, a list or a dict cannot be a dict key, a set's member or a "
                               "Counter's item (it is unhashable: its contents can change); use a tuple of numbers "
                               "(`tuple(row.tolist())`), one integer made of them (`y * W + x`), or numpy "
                               "itself (np.unique(..., axis=0, return_counts=True), np.add.at)")
            elif isinstance(err, TypeError) and len(details) == 1:    # the call itself failed, not a line inside
                names = ", ".join(list(kwargs)) or f"{len(args)} positional arguments"
                details.append(f"hint: the check calls your function as the stub declares it ({names}): keep the "
                               "stub's parameter names and order")
            if isinstance(err, RuntimeError) and "does not require grad" in str(err):
                details.append("hint: the loss has no autograd graph to back-propagate: it was computed under "
                               "`torch.no_grad()`, or from values taken out of the graph (.detach(), .data, "
                               ".item(), .numpy()); compute it with torch operations on the model's outputs, "
                               "with gradients on")
            if isinstance(err, IndexError) and _non_square(args, kwargs):
                details.append("hint: this input's sensor is not square; sensor_size is (H, W), rows first, and an "
                               "image is indexed [y, x] (y = row, x = column): `H, W = sensor_size`, "
                               "`np.zeros((H, W))`, `frame[y, x]`")
            state = _mutable_default_hint(fn, defaults) if k > 0 else None
            if state is None and k > 0:
                cache, proven = _global_cache_hint(fn, containers, ex, (args, kwargs), raised=True)
                if proven or not any(d.startswith("hint:") for d in details):
                    state = cache        # a list only logged to, which changes nothing, is a fallback
            if state:
                details.append(f"hint: {state}")
            return False, f"raised {type(err).__name__} on {where}", details
        if changed_settings:
            return False, f"changed torch's global settings on {where}", [_settings_message(changed_settings)]
        expected = _run(ex.reference, args, kwargs, ex.observe)
        if ex.compare is not None:
            try:
                msg = ex.compare(got, expected)
            except Exception as err:     # a return value the comparison cannot read at all
                msg = f"returned a {type(got).__name__} that cannot be compared ({type(err).__name__}: {err})"
            problem = None if msg is None else _Problem(msg, values=True)
        else:
            problem = _compare(got, expected, ex.rtol, ex.atol)
        # inputs changed in place (a function with side effects says what to compare through `observe`)
        changed = _changed_inputs((args, kwargs), after[0]) if ex.observe is None and after else []
        if problem is None and not changed:
            continue
        if problem is None:
            return False, f"changed its input on {where}", [_in_place_message(changed, _container_names(args, kwargs))]
        details = [problem.message]
        # results kept in a notebook dict (or list) that the function fills: an input that shares an earlier
        # one's key gets that input's result. Named first when the kept data made the difference (run with the
        # variable emptied, the function answers otherwise), else only when no other hint applies (below): a list
        # the function only logs to (`log.append(len(t))`, a common habit) grows just the same and explains nothing
        cache_hint, proven = _global_cache_hint(fn, containers, ex, (args, kwargs), got) if k > 0 else (None, False)
        hint = cache_hint if proven else None
        # a known mistake is recognised by its output, whatever the first difference is (a wrong
        # count of events is a wrong shape, not wrong values), and confirmed on the other inputs where
        # it shows: one input alone can make two different mistakes look alike
        for message, wrong in ex.hints.items() if hint is None else ():
            try:
                w = _run(wrong, args, kwargs, ex.observe)
                if _compare(got, w, ex.rtol, ex.atol) is None and _same_mistake_elsewhere(ex, fn, wrong, cases, k):
                    hint = message
                    break
            except Exception:
                continue
        # mistakes that show only across inputs: state kept from an earlier call, a notebook variable or a
        # fixed size in place of an argument; and a pair returned in the other order
        if hint is None:
            hint = _swapped_pair_hint(ex, got, expected)
        if hint is None:
            hint = _state_hint(fn, defaults, ex, args, kwargs, got, first=k == 0)
        if hint is None:
            hint = _stale_argument_hint(ex, fn, cases, k, got, expected)
        # mistakes any exercise can show (polarities read as 0/1, a clip to [0, 1], a rounded result), recognised
        # the same way from wrong versions made from the reference
        if hint is None and ex.observe is None:
            for message, wrong in _generic_mistakes(ex, cases):
                applies = getattr(wrong, "applies", None)
                if applies is not None and not applies(args, kwargs):
                    continue
                try:
                    w = _run(wrong, args, kwargs)
                    if _compare(w, expected, ex.rtol, ex.atol) is not None \
                            and _compare(got, w, ex.rtol, ex.atol) is None \
                            and _same_mistake_elsewhere(ex, fn, wrong, cases, k, getattr(wrong, "support", 0)):
                        hint = message
                        break
                except Exception:
                    continue
        # a global generator seeded inside: random numbers, the same at every call (after the generic mistakes: a
        # seed that draws nothing explains no value, and is only noted)
        seed_note = None
        if hint is None:
            hint, seed_note = _reseed_hint(ex, fn, args, kwargs)
        if hint is None:
            hint = _size_from_events_hint(args, kwargs, got, expected)
        if hint is None:
            hint = _fixed_size_hint(ex, cases, k, got, expected)
        if problem.values:
            if hint is None:
                hint = _one_based_hint(got, expected, ex.rtol, ex.atol)
            if hint is None:
                hint = _wrong_axes_hint(ex, args, kwargs, got, expected)
            if hint is None:
                indexed = _has_repeated_index(args, kwargs)
                hint = _generic_hint(got, expected, indexed=indexed)
                if hint is None and isinstance(expected, (tuple, list, dict)):
                    hint = _generic_hint(*_differing_leaf(got, expected, ex.rtol, ex.atol), indexed=indexed)
            if hint is None:
                hint = _scalar_factor_hint(ex, fn, cases, k, got, expected)
        if hint is None:
            hint = cache_hint
        if hint:
            details.append(f"hint: {hint}")
        if seed_note:
            details.append(f"also: {seed_note}")
        if changed:
            details.append("also: " + _in_place_message(changed, _container_names(args, kwargs)))
        return False, f"does not match the reference on {where}", details
    # the same input once more (the last one, right after its first run), from other states of the global random
    # generators: a function that keeps state between calls (a notebook variable it changes, a mutable default
    # argument) gives another result the second time; one that keeps its result (a buffer, a cache) returns the
    # same array again; one that reseeds a global generator leaves it in the same state whatever it held before
    if n:
        args, kwargs = cases[-1]
        rng_now, rng_other = _rng_states(), _other_rng_states(rng_before)
        changed_settings = {}
        try:
            _set_rng_states(rng_other)
            again = _run(fn, args, kwargs, ex.observe, settings_changed=changed_settings)
            rng_again = _rng_states()
            if ex.observe is not None:
                problem = None
            elif ex.compare is None:
                problem = _compare(again, _run(ex.reference, args, kwargs), ex.rtol, ex.atol)
            else:
                problem = None if ex.compare(again, _run(ex.reference, args, kwargs)) is None else _Problem("", True)
        except Exception as err:
            again, rng_again, problem = None, None, _Problem(f"{type(err).__name__}: {err}")
        finally:
            _set_rng_states(rng_now)
        if changed_settings:
            return False, f"changed torch's global settings on input #{n} of {n}", [_settings_message(changed_settings)]
        if problem is not None:
            return False, f"gives another result when input #{n} of {n} is run a second time", [
                "every input matched once, but a second call on the same input does not: your function keeps "
                "state between calls (a notebook variable it changes, a mutable default argument such as "
                "`state={}`, or unseeded randomness); compute everything from the arguments, afresh in each call"]
        shared = _shares_output(got, again) if ex.observe is None else None
        if shared:
            return False, f"returns the same {shared} again when input #{n} of {n} is run a second time", [
                "every input matched, but two calls return the same array (or dict) object, or views of one: a "
                "buffer or a cached result kept between calls (a notebook variable, a dict of results keyed by the "
                "shape or the arguments, a default argument) is handed out again, so each call changes what the "
                "earlier ones returned, and a caller that changes a result changes the cache (`frames = [f(...) "
                "for ...]` would hold one array many times); create the result afresh in each call (np.zeros(...) "
                "inside the function), or return a copy of a cached one (`.copy()`)"]
        reseeded = _reseeded(rng_before, rng_other, rng_after, rng_again) if rng_again is not None else []
        if reseeded:
            return False, f"reseeds the global random generator ({', '.join(reseeded)})", [
                "every input matched, but after a call the global generator is in the same state whatever it held "
                "before: your function seeds it (np.random.seed, torch.manual_seed, random.seed), which resets the "
                "random numbers of the whole notebook at every call (a later cell's random minibatches or noise "
                "repeat); nothing here asks for randomness: remove the seed, or draw from a generator of your own "
                "(rng = np.random.default_rng(seed), torch.Generator().manual_seed(seed))"]
    return True, f"matches the reference on {n} input{'s' if n != 1 else ''}", []


# ---- a second call on the last input: kept results, reseeded generators ----------------------------------------

def _mutable_leaves(v) -> list:
    """The arrays, tensors, dicts and lists inside a result that a caller could change in place."""
    if isinstance(v, dict):
        return [v] + [leaf for x in v.values() for leaf in _mutable_leaves(x)]
    if isinstance(v, list):
        return [v] + [leaf for x in v for leaf in _mutable_leaves(x)]
    if isinstance(v, tuple):
        return [leaf for x in v for leaf in _mutable_leaves(x)]
    if isinstance(v, np.ndarray) and v.size > 0 and v.flags.writeable:
        return [v]
    if _is_tensor(v) and v.numel() > 0:
        return [v]
    return []


def _shares_output(first, second) -> str | None:
    """What two results of the same call share: an array (memory), a tensor (storage), a dict or a list (the
    object); None when they share nothing."""
    try:
        a, b = _mutable_leaves(first), _mutable_leaves(second)
        for x in a:
            for y in b:
                if isinstance(x, (dict, list)) or isinstance(y, (dict, list)):
                    if x is y:
                        return type(x).__name__
                elif isinstance(x, np.ndarray) and isinstance(y, np.ndarray):
                    if np.shares_memory(x, y, max_work=10 ** 6):
                        return "array"
                elif _is_tensor(x) and _is_tensor(y):
                    if x.untyped_storage().data_ptr() == y.untyped_storage().data_ptr():
                        return "tensor"
    except Exception:
        return None           # cannot tell: say nothing
    return None


def _reseed_hint(ex: Exercise, fn: Callable, args, kwargs) -> tuple[str | None, str | None]:
    """A function that seeds a global generator (its random numbers the same on every call, but random all the
    same): two runs from different generator states leave the generators in one state. Returns (hint, note): the
    hint when it drew from a generator after seeding it (the generator is not where a seed leaves it), which can
    explain wrong values; otherwise a note only (a seed with no draws changes no value, but resets the notebook's
    random numbers at every call)."""
    now = _rng_states()
    try:
        afters = []
        for start in (now, _other_rng_states(now)):
            _set_rng_states(start)
            try:
                _run(fn, args, kwargs, ex.observe)
            except Exception:
                return None, None
            afters.append(_rng_states())
    finally:
        _set_rng_states(now)
    seeded = _reseeded(now, _other_rng_states(now), *afters)
    if not seeded:
        return None, None
    calls = ", ".join(seeded)
    keys = [key for key, call in _SEED_CALLS.items() if call in seeded]
    if any(not _fresh_seed_state(key, afters[0][key]) for key in keys):
        return (f"your function seeds the global random generator ({calls}) and draws from it: seeded, the "
                "numbers are the same at every call, but they are random numbers all the same (a random sample of "
                "the pixels, noise, a random start or tie-break), and nothing here asks for any; compute the result "
                "from all of the data, without randomness (and a seed inside a function resets the whole notebook's "
                "random numbers)"), None
    return None, (f"your function seeds the global random generator ({calls}) and draws nothing from it after: the "
                  "seed changes no value here, but it resets the whole notebook's random numbers at every call (a "
                  "later cell's random minibatches or noise repeat); remove it")


def _fresh_seed_state(key: str, state) -> bool:
    """The generator ``key`` ("numpy", "random", "torch") is in ``state`` as a seed leaves it, no number drawn
    since: Mersenne Twister's position at the end of its fresh key (numpy's and Python's), or the state that
    seeding a new generator with the state's own seed gives (torch's). Unreadable: False (say it drew)."""
    try:
        if key == "numpy":
            return int(state[2]) == 624 and int(state[3]) == 0
        if key == "random":
            return int(state[1][-1]) == 624 and state[2] is None
        torch = sys.modules.get("torch")
        if key == "torch" and torch is not None:
            g = torch.Generator()
            g.set_state(state)
            return bool(torch.equal(torch.Generator().manual_seed(g.initial_seed()).get_state(), state))
    except Exception:
        return False
    return False


def _torch_settings() -> dict | None:
    """torch's global settings a function may change for the whole notebook: gradients on or off, the default
    float dtype; None when torch is not imported."""
    torch = sys.modules.get("torch")
    if torch is None:
        return None
    return {"grad": torch.is_grad_enabled(), "dtype": torch.get_default_dtype()}


def _restore_torch_settings(before: dict | None) -> dict:
    """The settings changed since ``before`` ({name: (before, now)}), each set back to what it was."""
    torch = sys.modules.get("torch")
    if before is None or torch is None:
        return {}
    now = _torch_settings()
    changed = {k: (before[k], now[k]) for k in before if now[k] != before[k]}
    if "grad" in changed:
        torch.set_grad_enabled(before["grad"])
    if "dtype" in changed:
        torch.set_default_dtype(before["dtype"])
    return changed


def _settings_message(changed: dict) -> str:
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


def _rng_states() -> dict:
    """The states of the global random generators a learner may seed: numpy's, Python's, torch's (CPU)."""
    states = {"numpy": np.random.get_state(), "random": random.getstate()}
    torch = sys.modules.get("torch")
    if torch is not None:
        states["torch"] = torch.random.get_rng_state()
    return states


def _set_rng_states(states: dict) -> None:
    np.random.set_state(states["numpy"])
    random.setstate(states["random"])
    torch = sys.modules.get("torch")
    if torch is not None and "torch" in states:
        torch.random.set_rng_state(states["torch"])


def _other_rng_states(states: dict) -> dict:
    """States of the global generators that differ from ``states`` (built from generators of their own, so that
    nothing else is seeded: CUDA's generators stay as they are)."""
    for seed in (20240607, 7):
        other = {"numpy": np.random.RandomState(seed).get_state(), "random": random.Random(seed).getstate()}
        torch = sys.modules.get("torch")
        if torch is not None:
            other["torch"] = torch.Generator().manual_seed(seed).get_state()
        if not any(_same_rng_state(states[k], other[k]) for k in other if k in states):
            return other
    return other


def _same_rng_state(a, b) -> bool:
    if isinstance(a, tuple) and isinstance(b, tuple):
        return len(a) == len(b) and all(_same_rng_state(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return bool(np.array_equal(a, b))
    if _is_tensor(a) and _is_tensor(b):
        return a.shape == b.shape and bool((a == b).all())
    return a == b


_SEED_CALLS = {"numpy": "np.random.seed", "random": "random.seed", "torch": "torch.manual_seed"}


def _reseeded(before: dict, other: dict, after: dict, again: dict) -> list[str]:
    """The generators that two runs, started from different states (``before``, ``other``), left in one state
    (``after``, ``again``): the function seeded them."""
    out = []
    for name, call in _SEED_CALLS.items():
        if all(name in d for d in (before, other, after, again)):
            try:
                if not _same_rng_state(before[name], other[name]) and _same_rng_state(after[name], again[name]):
                    out.append(call)
            except Exception:
                continue
    return out


def _differing_leaf(got, expected, rtol: float, atol: float):
    """The (got, expected) pair, inside nested tuples, lists and dicts, where the two first differ."""
    try:
        if isinstance(expected, (tuple, list)) and isinstance(got, (tuple, list)) and len(got) == len(expected):
            for g, e in zip(got, expected):
                if _compare(g, e, rtol, atol) is not None:
                    return _differing_leaf(g, e, rtol, atol)
        if isinstance(expected, dict) and isinstance(got, dict) and set(got) == set(expected):
            for k in expected:
                if _compare(got[k], expected[k], rtol, atol) is not None:
                    return _differing_leaf(got[k], expected[k], rtol, atol)
    except Exception:
        pass
    return got, expected


def _same_mistake_elsewhere(ex: Exercise, fn: Callable, wrong: Callable, cases: list, skip: int,
                            support: int = 0) -> bool:
    """On every case but ``skip`` where the wrong version ``wrong`` shows its mistake (differs from the
    reference), ``fn`` gives the same output. Cases where either raises say nothing, and so do cases where
    the wrong version happens to be right (the learner's variant of the mistake may be broader). ``support``:
    how many other cases must show the mistake (a wrong version that changes almost any output needs none; one
    that changes only an input's last digits, where some other mistake may land alike, needs one)."""
    shown = 0
    applies = getattr(wrong, "applies", None)
    for j, (args, kwargs) in enumerate(cases):
        if j == skip or (applies is not None and not applies(args, kwargs)):
            continue
        try:
            w = _run(wrong, args, kwargs, ex.observe)
            if _compare(w, _run(ex.reference, args, kwargs, ex.observe), ex.rtol, ex.atol) is None:
                continue
            g = _run(fn, args, kwargs, ex.observe)
        except Exception:
            continue
        try:
            if _compare(g, w, ex.rtol, ex.atol) is not None:
                return False
        except Exception:
            return False
        shown += 1
    return shown >= support


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
        ok, headline, details = _evaluate(ex, fn)
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
        ok, headline, _ = _evaluate(ex, fn)
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
