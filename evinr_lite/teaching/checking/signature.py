"""The learner's function called as the notebooks call it (the exercise's ``call``: teaching/notebook_calls.py).

The check's inputs pass every argument by name, so a function whose parameters are in another order than the stub's
(``def tonemap(gamma, L)``) or keyword-only matches every input, while the notebook's later cell calls it by position
and gets another answer or an error; one that renamed a parameter (``def tonemap(L, g)``) or made it positional-only
(``/``) fails on the names, while the notebook's positional call works. :func:`notebook_caller` hands the main loop a
function that takes the inputs by name and calls the learner's as the notebook does, where some input cannot be
passed to it by name. After every input matched, :func:`called_as_notebook` calls it on each input as the notebook
does (its arguments by position and by name as the notebook's call passes them; the ones the notebook leaves out by
name, and, where optional, left out), each compared with the reference called the same way: only where the
function's signature differs from the stub's (an unchanged stub costs nothing), and only for an exercise whose call
is recorded. A signature that departs from the stub's where the notebook's call still works passes (a keyword-only
``eps`` the notebook leaves out, another default for a ``factor`` it always passes). :func:`signature_default_hint`
names a default other than the stub's, only where passing the stub's default makes the failing input match.
"""
from __future__ import annotations

import inspect
from typing import Callable

from .learner_calls import learner_function, run
from .outputs import first_difference
from .protocol import ExerciseLike

_ORDERED = (inspect.Parameter.POSITIONAL_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD)


def _signature(fn: Callable) -> inspect.Signature | None:
    """The signature Python binds a call to: a functools.wraps wrapper's own, not the wrapped function's."""
    try:
        return inspect.signature(learner_function(fn), follow_wrapped=False)
    except (TypeError, ValueError):
        return None


def _same(a, b) -> bool:
    try:
        return type(a) is type(b) and bool(a == b)
    except Exception:
        return a is b


def _same_signature(ref: inspect.Signature, own: inspect.Signature) -> bool:
    """The same names, kinds and defaults in the same order (annotations aside)."""
    a, b = list(ref.parameters.values()), list(own.parameters.values())
    return len(a) == len(b) and all(p.name == q.name and p.kind == q.kind and _same(p.default, q.default)
                                    for p, q in zip(a, b))


def _shown(params) -> str:
    """The parameters' names as a def line lists them (`/` after positional-only ones, `*` before keyword-only ones),
    without annotations."""
    out, star, params = [], False, list(params)
    for k, p in enumerate(params):
        if p.kind is inspect.Parameter.VAR_POSITIONAL:
            out.append(f"*{p.name}"); star = True
        elif p.kind is inspect.Parameter.VAR_KEYWORD:
            out.append(f"**{p.name}")
        else:
            if p.kind is inspect.Parameter.KEYWORD_ONLY and not star:
                out.append("*"); star = True
            out.append(p.name)
        if p.kind is inspect.Parameter.POSITIONAL_ONLY and (k + 1 == len(params)
                                                              or params[k + 1].kind is not p.kind):
            out.append("/")
    return ", ".join(out)


def _left_out(call, ref: inspect.Signature) -> list[str]:
    """The stub's parameters that the notebook's ``call`` does not pass."""
    order = [p.name for p in ref.parameters.values() if p.kind in _ORDERED][:call.positional]
    return [n for n in ref.parameters if n not in order and n not in call.keywords]


def notebook_args(ex: ExerciseLike, args: tuple, kwargs: dict, leave_out: bool = False) -> tuple[tuple, dict] | None:
    """An input ``(args, kwargs)`` as the notebook's call passes its arguments: the first ones by position, then the
    ones it names by keyword; the input's others (which the notebook leaves out) by keyword, or, with
    ``leave_out``, the optional ones among them left out. None where the exercise has no recorded call."""
    call, ref = getattr(ex, "call", None), _signature(ex.reference)
    if call is None or ref is None:
        return None
    try:
        values = dict(ref.bind(*args, **kwargs).arguments)
    except TypeError:
        return None
    order = [p.name for p in ref.parameters.values() if p.kind in _ORDERED]
    pos = []
    for name in order[:call.positional]:
        if name not in values:
            break
        pos.append(values.pop(name))
    if leave_out:
        dropped = set(_left_out(call, ref))
        values = {n: v for n, v in values.items()
                  if n not in dropped or ref.parameters[n].default is inspect.Parameter.empty}
    return tuple(pos), values


def _how(call, ref: inspect.Signature) -> str:
    """How the notebook's call passes the stub's arguments, in words."""
    order = [p.name for p in ref.parameters.values() if p.kind in _ORDERED][:call.positional]
    parts = [f"{', '.join(order)} by position" if order else "no argument by position"]
    if call.keywords:
        parts.append(f"{', '.join(call.keywords)} by name")
    out = _left_out(call, ref)
    if out:
        parts.append(f"{', '.join(out)} left out")
    return "; ".join(parts)


def notebook_caller(ex: ExerciseLike, fn: Callable) -> Callable:
    """``fn``, or, where some input cannot be passed to it by name (a positional-only parameter of the stub's name)
    but every input can be passed as the notebook's call passes it, a function that takes the inputs by name and
    calls ``fn`` that way (:func:`learner_function` gives ``fn`` back). A parameter renamed is not: the stub's
    names are the exercise's contract (round 2), and the report says so."""
    call, ref, own = getattr(ex, "call", None), _signature(ex.reference), _signature(fn)
    if call is None or ref is None or own is None or _same_signature(ref, own):
        return fn
    if list(own.parameters) != list(ref.parameters):
        return fn       # a parameter renamed, added or dropped: the stub's names are the exercise's contract
    try:
        cases = ex.cases()
    except Exception:
        return fn

    def binds(a, k) -> bool:
        try:
            own.bind(*a, **k)
            return True
        except TypeError:
            return False
    if all(binds(a, k) for a, k in cases):
        return fn
    forms = [notebook_args(ex, a, k) for a, k in cases]
    if any(f is None or not binds(*f) for f in forms):
        return fn

    return _as_notebook_calls(ex, fn)


def _as_notebook_calls(ex: ExerciseLike, fn: Callable) -> Callable:
    def called_as_in_the_notebook(*args, **kwargs):
        pos, named = notebook_args(ex, args, kwargs)
        return fn(*pos, **named)
    called_as_in_the_notebook.wraps_learner_function = fn
    called_as_in_the_notebook.notebook_exercise = ex
    return called_as_in_the_notebook


def called_the_same_way(fn: Callable, other: Callable) -> Callable:
    """``other`` (the learner's function recompiled by a hint's proof) called as the check calls ``fn``: through
    :func:`notebook_caller`'s wrapper where ``fn`` is one, else ``other`` itself."""
    ex = getattr(fn, "notebook_exercise", None)
    return other if ex is None or learner_function(fn) is fn else _as_notebook_calls(ex, other)


def _matches(ex: ExerciseLike, got, expected) -> bool:
    return first_difference(ex, got, expected) is None


def signature_default_hint(ex: ExerciseLike, fn: Callable, args: tuple, kwargs: dict) -> str | None:
    """A hint where input ``(args, kwargs)`` leaves out an optional argument whose default in ``fn`` is not the
    stub's (or that ``fn`` requires), and ``fn`` matches the reference once the stub's defaults are passed; else
    None (the default did not make the failure: another mistake did, or the call fails for another reason)."""
    ref, own = _signature(ex.reference), _signature(fn)
    if ref is None or own is None:
        return None
    try:
        given = ref.bind(*args, **kwargs).arguments
    except TypeError:
        return None
    other = []                          # (name, the learner's default or empty, the stub's)
    for name, p in ref.parameters.items():
        if p.default is inspect.Parameter.empty or name in given or name not in own.parameters:
            continue
        mine = own.parameters[name].default
        if mine is inspect.Parameter.empty or not _same(mine, p.default):
            other.append((name, mine, p.default))
    if not other:
        return None
    try:
        expected = run(ex.reference, args, kwargs, ex.observe)
        got = run(fn, args, {**kwargs, **{name: stub for name, _, stub in other}}, ex.observe)
        if not _matches(ex, got, expected):
            return None
    except Exception:
        return None
    name, mine, stub = other[0]
    call = getattr(ex, "call", None)
    also = f" ({call.where()} leaves it out too: `{call.text}`)" if call is not None \
        and name in _left_out(call, ref) else ""
    if mine is inspect.Parameter.empty:
        return (f"this input leaves `{name}` out, and your function has no default for it; with the stub's "
                f"`{name}={stub!r}` passed it matches: keep the stub's default{also}")
    return (f"this input leaves `{name}` out, so your default `{name}={mine!r}` is used; with the stub's "
            f"`{name}={stub!r}` passed your function matches: keep the stub's defaults{also}")


def called_as_notebook(ex: ExerciseLike, fn: Callable, cases: list) -> tuple[str, list[str]] | None:
    """(headline, details) where ``fn``, called on an input as the notebook's call passes its arguments, answers
    otherwise than the reference called the same way (or raises); else None. See the module docstring."""
    call, ref, own = getattr(ex, "call", None), _signature(ex.reference), _signature(fn)
    if call is None or ref is None or own is None or not cases or _same_signature(ref, own):
        return None
    detail = (f"keep the stub's signature: {call.where()} calls it as `{call.text}` ({_how(call, ref)}); your "
              f"parameters are ({_shown(own.parameters.values())}), the stub's ({_shown(ref.parameters.values())})")
    for k, (args, kwargs) in enumerate(cases):
        full = notebook_args(ex, args, kwargs)
        for leave_out in (False, True):
            form = notebook_args(ex, args, kwargs, leave_out) if leave_out else full
            if form is None or (leave_out and set(form[1]) == set(full[1])):
                continue
            wrong = _differs(ex, fn, *form)
            if not wrong:
                continue
            dropped = [n for n in full[1] if n not in form[1]]
            what = f"`{'`, `'.join(dropped)}` left out, as the notebook leaves it out" if leave_out else "its values"
            defaults = "".join(f"; your function has {_default(own, n)}, the stub `{n}={ref.parameters[n].default!r}`"
                               for n in dropped if not (n in own.parameters and _same(
                                   own.parameters[n].default, ref.parameters[n].default)))
            return (f"{_verb(wrong)} when input #{k + 1} is passed as the notebook passes it ({what})",
                    [f"{wrong}{defaults}; {detail}"])
    return None


def _default(own: inspect.Signature, name: str) -> str:
    q = own.parameters.get(name)
    return "no default" if q is None or q.default is inspect.Parameter.empty else f"`{name}={q.default!r}`"


def _verb(wrong: str) -> str:
    return "raises" if "raised" in wrong else "answers otherwise"


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
    return None if _matches(ex, got, expected) else "called so, your function answers otherwise than the reference"
