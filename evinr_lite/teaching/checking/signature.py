"""The learner's function called as the notebooks call it: arguments in order, optional ones left out.

The check passes every argument by name, so a function whose parameters are in another order than the stub's
(``def tonemap(gamma, L)``), keyword-only (``*, eps=...``), or whose default differs from the stub's
(``factor=5.0`` for 10.0) matches every input; the notebook's later cells call it positionally and leave the
optional arguments out (``anchor_first_offset(first_frame, L_t0)``), and get another answer or an error.
:func:`called_as_notebook` runs, after every input matched, each input with its arguments in the stub's order,
and, for each optional argument, each input that passes it with that argument left out, each compared with the
reference called the same way. Only where the function's signature differs from the reference's (another order,
another default): an unchanged stub costs nothing. :func:`signature_default_hint` names a default that differs
where an input itself leaves the argument out.
"""
from __future__ import annotations

import inspect
from typing import Callable

from .learner_calls import run
from .outputs import compare_outputs
from .protocol import ExerciseLike

_ORDERED = (inspect.Parameter.POSITIONAL_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD)


def _signature(fn: Callable) -> inspect.Signature | None:
    try:
        return inspect.signature(fn)
    except (TypeError, ValueError):
        return None


def _same(a, b) -> bool:
    try:
        return type(a) is type(b) and bool(a == b)
    except Exception:
        return a is b


def _shown(params) -> str:
    """The parameters' names as a def line lists them (`*` before keyword-only ones), without annotations."""
    out, star = [], False
    for p in params:
        if p.kind is inspect.Parameter.VAR_POSITIONAL:
            out.append(f"*{p.name}"); star = True
        elif p.kind is inspect.Parameter.VAR_KEYWORD:
            out.append(f"**{p.name}")
        else:
            if p.kind is inspect.Parameter.KEYWORD_ONLY and not star:
                out.append("*"); star = True
            out.append(p.name)
    return ", ".join(out)


def signature_default_hint(ex: ExerciseLike, fn: Callable, kwargs: dict) -> str | None:
    """A hint where an input leaves out an optional argument whose default in ``fn`` is not the stub's (or that
    ``fn`` requires); else None."""
    ref, own = _signature(ex.reference), _signature(fn)
    if ref is None or own is None:
        return None
    for name, p in ref.parameters.items():
        if p.default is inspect.Parameter.empty or name in kwargs or name not in own.parameters:
            continue
        mine = own.parameters[name].default
        if mine is inspect.Parameter.empty:
            return (f"this input leaves `{name}` out, and your function has no default for it: keep the stub's "
                    f"`{name}={p.default!r}` (the notebook's cells leave it out too)")
        if not _same(mine, p.default):
            return (f"this input leaves `{name}` out, so your default `{name}={mine!r}` is used; the stub's is "
                    f"`{name}={p.default!r}`: keep the stub's defaults (the notebook's cells leave it out too)")
    return None


def called_as_notebook(ex: ExerciseLike, fn: Callable, cases: list) -> tuple[str, list[str]] | None:
    """(headline, details) where ``fn``, called as the notebooks call it, answers otherwise than the reference
    called the same way (or raises); else None. See the module docstring."""
    ref, own = _signature(ex.reference), _signature(fn)
    if ref is None or own is None or not cases:
        return None
    ref_order = [p.name for p in ref.parameters.values() if p.kind in _ORDERED]
    own_order = [p.name for p in own.parameters.values() if p.kind in _ORDERED]
    stub = f"({_shown(ref.parameters.values())})"
    mine = f"({_shown(own.parameters.values())})"
    if own_order[:len(ref_order)] != ref_order:
        # every input, its arguments moved into the stub's order as far as it passes them (an optional one left out
        # stops the order): one input alone may not show it (x and y swapped under a phase that is the same for both)
        for k, (args, kwargs) in enumerate(cases):
            moved = ref_order[len(args):_in_order(ref_order, args, kwargs)]
            if not moved:
                continue
            wrong = _differs(ex, fn, tuple(args) + tuple(kwargs[m] for m in moved),
                             {m: v for m, v in kwargs.items() if m not in moved})
            if wrong:
                return (f"{_verb(wrong)} when input #{k + 1}'s arguments are passed in order, as the notebook's "
                        f"cells pass them", [f"{wrong}; your parameters are {mine}, the stub's {stub}: the check "
                                             "passes each argument by name, the notebook's cells by position; keep "
                                             "the stub's parameter order (and no `*` before an argument the cells "
                                             "pass by position)"])
    for name, p in ref.parameters.items():
        if p.default is inspect.Parameter.empty:
            continue
        q = own.parameters.get(name)
        if q is not None and _same(q.default, p.default):
            continue
        for k, (args, kwargs) in enumerate(cases):
            if name not in kwargs:
                continue
            wrong = _differs(ex, fn, args, {n: v for n, v in kwargs.items() if n != name})
            if wrong:
                yours = "no default" if q is None or q.default is inspect.Parameter.empty \
                    else f"`{name}={q.default!r}`"
                return (f"{_verb(wrong)} when `{name}` is left out of input #{k + 1}, as the notebook's cells "
                        f"leave it out", [f"{wrong}; your function has {yours}, the stub `{name}={p.default!r}`: "
                                          "keep the stub's defaults"])
    return None


def _verb(wrong: str) -> str:
    return "raises" if "raised" in wrong else "answers otherwise"


def _in_order(order: list, args: tuple, kwargs: dict) -> int:
    """How many of the parameters ``order`` the call ``(args, kwargs)`` can pass by position, from the first."""
    n = len(args)
    while n < len(order) and order[n] in kwargs:
        n += 1
    return n


def _differs(ex: ExerciseLike, fn: Callable, args: tuple, kwargs: dict) -> str | None:
    """What goes wrong when ``fn`` is called on ``(args, kwargs)``: its error, or "it answers otherwise" where its
    result is not the reference's on the same call; None where it matches (or the reference itself fails)."""
    try:
        expected = run(ex.reference, args, kwargs, ex.observe)
    except Exception:
        return None
    try:
        got = run(fn, args, kwargs, ex.observe)
    except Exception as err:
        return f"called so, your function raised {type(err).__name__}: {err}"
    if ex.compare is not None and ex.observe is None:
        try:
            same = ex.compare(got, expected) is None
        except Exception:
            same = False
    else:
        same = compare_outputs(got, expected, ex.rtol, ex.atol) is None
    return None if same else "called so, your function answers otherwise than the reference"
