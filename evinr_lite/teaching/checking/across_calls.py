"""Mistakes seen only across inputs or calls: state kept between calls, an argument read from elsewhere.

One input alone cannot show these: a mutable default argument or a notebook dict that fills up during the check
(:func:`mutable_default_hint`, :func:`global_cache_hint`), a second call on the same input that answers
otherwise (:func:`state_hint`) or answers otherwise on freed memory filled with zeros than with the check's pattern
(np.empty, :func:`memory_explains`), a result that is right for input #1's arguments or sizes, not this input's
(:func:`stale_argument_hint`, :func:`fixed_size_hint`), a size that is the same on every input while the expected
size changes (:func:`constant_size_hint`), one number off by the same factor on every input
(:func:`scalar_factor_hint`). And, on the second call of the last input:
:func:`shares_output` (the same array, tensor or dict handed out twice, a buffer or a cached result) and
:func:`reseed_hint` (a global generator seeded inside the function). After that, :func:`same_objects_new_values`
gives the function input #1's own objects again, refilled in place with a later input's values: a result kept by the
objects' identity (a cache keyed by id(), `t is last_t`) answers for the old values.
"""
from __future__ import annotations

import copy
import inspect
import sys
from typing import Any, Callable

import numpy as np

from .global_state import SEED_CALLS, other_rng_states, reseeded_generators, rng_states, set_rng_states
from .hints import unit_note
from .learner_calls import (copy_inputs, learner_function, poison_freed_memory, refill_in_place, run, same_array,
                            uses_uninitialised)
from .outputs import compare_outputs, is_tensor, not_finite, to_numpy
from .protocol import ExerciseLike


# ---- mistakes seen only across inputs: state kept between calls, a notebook variable for an argument ------

_MUTABLE = (list, dict, set, bytearray, np.ndarray)


def mutable_defaults(fn: Callable) -> dict[str, Any]:
    """Copies of ``fn``'s default argument values that can change in place (lists, dicts, sets, arrays)."""
    out: dict[str, Any] = {}
    try:
        params = inspect.signature(learner_function(fn)).parameters.values()
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
            return same_array(a, b)
        return bool(a == b)
    except Exception:
        return True          # cannot tell: say nothing


def mutable_default_hint(fn: Callable, before: dict[str, Any]) -> str | None:
    """A mutable default argument that changed (or holds data) during the check."""
    try:
        now = {p.name: p.default for p in inspect.signature(learner_function(fn)).parameters.values()}
    except (TypeError, ValueError):
        now = {}
    for name, old in before.items():
        value = now.get(name)
        if not _same_value(old, value) or (isinstance(value, (list, dict, set)) and len(value) > 0):
            return (f"the default value of `{name}` is created once, when the function is defined, and shared by "
                    f"every call: what one call puts in it is still there in the next (it holds data now). Use "
                    f"`{name}=None` and create a fresh one inside the function")
    return None


UNINITIALISED = (
    "your function starts an array with np.empty (np.empty_like, torch.empty), which leaves in it whatever an "
    "earlier array held in that memory, another garbage at every call: a sum, a count or a state must start from "
    "np.zeros(...) (np.empty only suits an array whose every entry is written before it is read)")


def memory_explains(fn: Callable, ex: ExerciseLike, args, kwargs, like) -> bool:
    """Whether what np.empty is handed explains ``fn``'s answers on this input: a function that calls np.empty (or
    np.empty_like, torch.empty; :func:`uses_uninitialised`) is run four times, the global generators set to one
    state before each, on freed memory (in the sizes of ``like``) filled with zeros, then the check's pattern, then
    zeros and the pattern again: the two runs on each fill agree, and the fills answer differently. A function that
    draws random numbers, keeps state between calls or counts its calls answers otherwise for its own reasons, and
    is not blamed on np.empty. The generators are set back to their state before."""
    if ex.observe is not None or not uses_uninitialised(fn):
        return False
    states = rng_states()
    try:
        outs = []
        for byte in (0x00, 0x7F, 0x00, 0x7F):
            set_rng_states(states)
            poison_freed_memory(like, byte)
            outs.append(run(fn, args, kwargs))
        zeros, pattern, zeros_again, pattern_again = outs
        return (compare_outputs(zeros_again, zeros, ex.rtol, ex.atol) is None
                and compare_outputs(pattern_again, pattern, ex.rtol, ex.atol) is None
                and compare_outputs(pattern, zeros, ex.rtol, ex.atol) is not None)
    except Exception:
        return False
    finally:
        set_rng_states(states)


def uninitialised_hint(fn: Callable, ex: ExerciseLike, args, kwargs, got) -> str | None:
    """A function that calls np.empty (or np.empty_like, torch.empty) and whose answer depends on what the freed
    memory it is handed holds (:func:`memory_explains`): it reads entries it never wrote."""
    return UNINITIALISED if memory_explains(fn, ex, args, kwargs, got) else None


STATE_BETWEEN_CALLS = (
    "called again on the same input, your function returns another result: it keeps state between calls (a "
    "notebook variable it changes, a mutable default argument), or draws random numbers from the global generator "
    "(np.random.choice, np.random.randn, torch.randn without a seed of its own); compute everything from the "
    "arguments, starting afresh in each call, with no randomness (nothing here asks for a random sample)")


def state_hint(fn: Callable, before: dict[str, Any], ex: ExerciseLike, args, kwargs, got,
                first: bool = False, memory: bool | None = None) -> str | None:
    """A mutable default argument that changed (or holds data) during the check, or a second call on the same
    input that gives another result: the function keeps state between calls, or draws unseeded random numbers
    (np.empty only where the memory it is handed explains the difference, :func:`memory_explains`).
    ``first``: the failing input is the first one, where a default cannot hold an earlier call's data yet.
    ``memory``: :func:`memory_explains`' answer on this input where the caller has it already (None: ask it here)."""
    hint = None if first else mutable_default_hint(fn, before)
    if hint is not None or ex.observe is not None:
        return hint
    try:
        if hasattr(got, "__next__") or compare_outputs(got, got, ex.rtol, ex.atol) is not None:
            return None     # no numbers to compare (a map object, an array of dtype object): a rerun says nothing
        poison_freed_memory(got)
        again = run(fn, args, kwargs, ex.observe)
        if compare_outputs(again, got, ex.rtol, ex.atol) is None:
            return None
        if memory if memory is not None else memory_explains(fn, ex, args, kwargs, got):
            return UNINITIALISED
        return STATE_BETWEEN_CALLS
    except Exception:
        return None


def global_containers(fn: Callable) -> dict[str, tuple[int, int]]:
    """The dicts, lists and sets among the notebook variables (``fn``'s globals) that ``fn``'s code names:
    {name: (id, length)}."""
    fn = learner_function(fn)          # the notebook-call wrapper's code names nothing of the learner's
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


def global_cache_hint(fn: Callable, before: dict[str, tuple[int, int]], ex: ExerciseLike | None = None,
                       case: tuple | None = None, got: Any = None, raised: bool = False) -> tuple[str | None, bool]:
    """A notebook dict, list or set named in ``fn``'s code that gained entries during the check: results (or parts
    of them) kept from one call to the next. Returns (hint, proven): with ``ex`` and ``case`` (the failing input's
    (args, kwargs), where ``fn`` returned ``got`` or ``raised``), ``proven`` says that the kept data made the
    difference: run once more with that variable empty for the call (and put back after), ``fn`` answers otherwise.
    A list the function only logs to (`log.append(len(t))`, a common habit) grows just the same and changes
    nothing: then the hint is only a fallback, for when no other hint applies."""
    now = global_containers(fn)
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


def _kept_data_matters(ex: ExerciseLike, fn: Callable, name: str, case: tuple, got: Any, raised: bool) -> bool:
    """``fn`` on ``case`` with the notebook variable ``name`` emptied for the call (a shallow copy, cleared: a
    defaultdict keeps its factory) gives another answer than ``got`` (a result where it raised, or another
    result); the variable is put back whatever happens. Cannot tell (it raises again, or otherwise): False."""
    namespace = learner_function(fn).__globals__
    kept = namespace.get(name)
    try:
        empty = copy.copy(kept)
        empty.clear()
    except Exception:
        return False
    namespace[name] = empty
    try:
        fresh = run(fn, *case, ex.observe)
    except Exception:
        return False
    finally:
        namespace[name] = kept
    if raised:
        return True
    try:
        return compare_outputs(fresh, got, ex.rtol, ex.atol) is not None
    except Exception:
        return False


def _stale_elsewhere(ex: ExerciseLike, cases: list, k: int, subset: tuple, fn_outputs) -> bool:
    """On every other input (but #1) where the learner is wrong, its output is also the reference's with the
    arguments ``subset`` taken from input #1: a coincidence on one input (a phase (0, 0) both times) says nothing."""
    kw0 = cases[0][1]
    for j, (a, kw) in enumerate(cases):
        if j in (0, k):
            continue
        try:
            g = fn_outputs(j)
            if compare_outputs(g, run(ex.reference, a, kw, ex.observe), ex.rtol, ex.atol) is None:
                continue
            if compare_outputs(g, run(ex.reference, (), dict(kw, **{name: kw0[name] for name in subset}), ex.observe),
                        ex.rtol, ex.atol) is not None:
                return False
        except Exception:
            return False
    return True


def stale_argument_hint(ex: ExerciseLike, fn: Callable, cases: list, k: int, got, expected) -> str | None:
    """The learner's output on input ``k`` equals the reference's with one or two arguments taken from input #1
    (and so on every other input where it is wrong): the function reads a notebook variable (or a value fixed in
    the code) in place of those arguments."""
    if k == 0:
        return None
    memo: dict = {}

    def fn_outputs(j):
        if j not in memo:
            memo[j] = run(fn, *cases[j], ex.observe)
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
            w = run(ex.reference, (), trial, ex.observe)
            if compare_outputs(w, expected, ex.rtol, ex.atol) is None \
                    or compare_outputs(got, w, ex.rtol, ex.atol) is not None \
                    or not_finite(w) and not not_finite(expected):   # NaN alike is no evidence: the arguments
                continue                                              # mixed (a clock at 1000 s, times near 0)
        except Exception:
            continue
        if not _stale_elsewhere(ex, cases, k, subset, fn_outputs):
            continue
        which = ", ".join(f"`{name}`" for name in subset)
        return (f"this is the right result for input #1's {which}, not for this input's: the function uses a "
                f"notebook variable (a global such as the first example's data) or a value fixed in the code in "
                f"place of its argument{'s' if len(subset) > 1 else ''} {which}; use the arguments it is given")
    return None


def fixed_size_hint(ex: ExerciseLike, cases: list, k: int, got, expected) -> str | None:
    """A result shaped like input #1's expected result (all of it, or the sizes that differ): a size fixed in the
    code, or read from a notebook variable, instead of from the arguments."""
    if k == 0:
        return None
    try:
        g, e = to_numpy(got), to_numpy(expected)
        if g.dtype == object or g.shape == e.shape or g.ndim != e.ndim or g.ndim == 0:
            return None
        e0 = to_numpy(run(ex.reference, *cases[0], ex.observe))
    except Exception:
        return None
    if e0.ndim != g.ndim or e0.shape == e.shape:
        return None
    if all(gd == ed or gd == fd for gd, ed, fd in zip(g.shape, e.shape, e0.shape)):
        return (f"the result's shape {g.shape} has input #1's sizes (its result is {e0.shape}), not this input's "
                f"{e.shape}: a size fixed in the code (np.zeros(3), `H, W = 4, 4`) or taken from a notebook "
                "variable; read the sizes from the arguments (len(...), .shape, sensor_size)")
    return None


def _leaves(v, expected) -> list | None:
    """The arrays (or tensors) of an output, in the order of ``expected``'s structure (a tuple's or list's items, a
    dict's values by ``expected``'s keys), each as (where, shape); None where ``v`` has another structure."""
    if isinstance(expected, (tuple, list)):
        if not isinstance(v, (tuple, list)) or len(v) != len(expected):
            return None
        parts = [_leaves(g, e) for g, e in zip(v, expected)]
        if any(p is None for p in parts):
            return None
        return [(f"[{k}]{w}", shape) for k, p in enumerate(parts) for w, shape in p]
    if isinstance(expected, dict):
        return None
    try:
        return [("", to_numpy(v).shape)]
    except Exception:
        return None


def constant_size_hint(ex: ExerciseLike, fn: Callable, cases: list, k: int, got, expected) -> str | None:
    """A wrong size that is the same on every input, while the expected size changes with the arguments: a size
    fixed in the code or read from a notebook variable that is not input #1's (the notebook's sensor (48, 64), its 40
    bins, its 32 frames), where :func:`fixed_size_hint` names input #1's. Asked for a wrong shape only; every input
    the learner's function and the reference both answer counts, and at least three must; the size is at least 2
    (0 or 1 everywhere is a count that collapsed) and differs from the expected one on each of them."""
    if ex.observe is not None:
        return None
    mine, want = _leaves(got, expected), _leaves(expected, expected)
    if not mine or not want or len(mine) != len(want):
        return None
    wrong = [(j, a) for j, ((where, g), (_, e)) in enumerate(zip(mine, want)) if len(g) == len(e)
             for a in range(len(g)) if g[a] != e[a]]
    if not wrong:
        return None
    seen = []                # (learner's shapes, expected shapes) per input that both answer
    for j, (args, kwargs) in enumerate(cases):
        try:
            e_j = run(ex.reference, args, kwargs) if j != k else expected
            g_j = run(fn, args, kwargs) if j != k else got
        except Exception:
            continue
        m, w = _leaves(g_j, e_j), _leaves(e_j, e_j)
        if m is None or w is None or len(m) != len(mine):
            continue
        seen.append(([shape for _, shape in m], [shape for _, shape in w]))
    if len(seen) < 3:
        return None
    fixed = []
    for j, a in wrong:
        sizes = [g[j][a] if len(g[j]) > a else None for g, _ in seen]
        wanted = [e[j][a] if len(e[j]) > a else None for _, e in seen]
        # a size of 0 or 1 everywhere is a count that collapsed (an empty range, a max(..., 1)), not a number
        # written in; and a fixed number is wrong on every input (else it may be a rule that lands alike)
        if len(set(sizes)) == 1 and len(set(wanted)) > 1 and (sizes[0] or 0) >= 2 \
                and all(w != sizes[0] for w in wanted):
            fixed.append((j, a, sizes[0], wanted))
    if not fixed:
        return None
    j = fixed[0][0]
    where, shape = mine[j]
    axes = [a for jj, a, _, _ in fixed if jj == j]
    whose = f"output {where}" if where else "the result"
    if len(axes) > 1:
        wanted = sorted({tuple(e[j]) for _, e in seen})
        said = f"{whose}'s shape is {tuple(shape)} on every input, while the expected shape changes with the arguments"
    else:
        wanted = sorted({e[j][axes[0]] for _, e in seen})
        said = (f"{whose} has {shape[axes[0]]} entries along axis {axes[0]} on every input, while the expected "
                "number changes with the arguments")
    return (f"{said} ({', '.join(str(w) for w in wanted)}): a size fixed in the code, or read from a notebook "
            "variable (the notebook's sensor, its number of bins or frames), instead of from the arguments; compute "
            "it from them (sensor_size, len(boundaries) - 1, the span over bin_s, .shape)")


def scalar_factor_hint(ex: ExerciseLike, fn: Callable, cases: list, k: int, got, expected) -> str | None:
    """One number off by the same factor on every input (a weight such as lam, a 1/2, a sum for a mean)."""
    if ex.observe is not None:
        return None
    try:
        g, e = float(to_numpy(got)), float(to_numpy(expected))
        if not (np.isfinite(g) and np.isfinite(e)) or e == 0 or g == 0:
            return None
        ratio = g / e
        seen = 0
        for j, (a, kw) in enumerate(cases):
            if j == k:
                continue
            ej = float(to_numpy(run(ex.reference, a, kw)))
            if ej == 0:
                continue
            if abs(float(to_numpy(run(fn, a, kw))) / ej - ratio) > 1e-5 * max(1.0, abs(ratio)):
                return None
            seen += 1
    except Exception:
        return None
    if seen == 0:
        return None
    return (f"off by a constant factor: got {ratio:.4g} x the expected value on every input (a weight such as "
            f"lam or 1/2 that does not belong here, a sum where a mean is expected, or the other way round?)"
            + unit_note(ratio))


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
    if is_tensor(v) and v.numel() > 0:
        return [v]
    return []


def shares_output(first, second) -> str | None:
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
                elif is_tensor(x) and is_tensor(y):
                    if x.untyped_storage().data_ptr() == y.untyped_storage().data_ptr():
                        return "tensor"
    except Exception:
        return None           # cannot tell: say nothing
    return None


def reseed_hint(ex: ExerciseLike, fn: Callable, args, kwargs) -> tuple[str | None, str | None]:
    """A function that seeds a global generator (its random numbers the same on every call, but random all the
    same): two runs from different generator states leave the generators in one state. Returns (hint, note): the
    hint when it drew from a generator after seeding it (the generator is not where a seed leaves it), which can
    explain wrong values; otherwise a note only (a seed with no draws changes no value, but resets the notebook's
    random numbers at every call)."""
    now = rng_states()
    try:
        afters = []
        for start in (now, other_rng_states(now)):
            set_rng_states(start)
            try:
                run(fn, args, kwargs, ex.observe)
            except Exception:
                return None, None
            afters.append(rng_states())
    finally:
        set_rng_states(now)
    seeded = reseeded_generators(now, other_rng_states(now), *afters)
    if not seeded:
        return None, None
    calls = ", ".join(seeded)
    keys = [key for key, call in SEED_CALLS.items() if call in seeded]
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


KEYED_BY_OBJECT = (
    "every input matched, but called on input #1's own array objects, refilled in place with input #{k}'s values "
    "(as a notebook does when it reuses a buffer, or changes an array in place and calls again), it does not "
    "answer as the reference does for those values: your function keeps results keyed by the objects (`id(t)`, "
    "`t is last_t`) or keeps the objects themselves, and an id is no fingerprint of the values (Python hands a "
    "freed array's id to the next one, and an array changed in place keeps its id); drop the cache (nothing here "
    "is slow enough to need one), or key it by the values (`t.tobytes()`) and return copies")


def same_objects_new_values(ex: ExerciseLike, fn: Callable, cases: list) -> tuple[int, bool] | None:
    """(k, state): the number (from 1) of a case k > 1 such that ``fn``, called on the first case's objects (a copy)
    and then on the same objects refilled in place with case k's values (:func:`.learner_calls.refill_in_place`),
    answers the second call otherwise than the reference on case k; else None (also where the objects cannot be
    refilled: an array the function kept a reference to, one array passed twice). ``state``: called once more on a
    fresh copy of case k, ``fn`` answers otherwise too, so the objects' identity is not what it keeps (a function
    that drifts after some number of calls, which the second call of the last input may not see: a NaN there hides
    any drift). The cases are tried from the last one back (a cache keyed by an id and a plain number is fooled only
    where that number is input #1's). Run after every input matched; the objects refilled are kept alive until it
    returns, so that none of their ids is handed to a later copy."""
    if ex.observe is not None:
        return None

    def differs(got, expected) -> bool:
        return ex.compare(got, expected) is not None if ex.compare is not None else \
            compare_outputs(got, expected, ex.rtol, ex.atol) is not None
    held = []
    for k in range(len(cases) - 1, 0, -1):
        holder = copy_inputs(cases[0])
        held.append(holder)
        try:
            expected = run(ex.reference, *cases[k])
            run(fn, holder[0], holder[1], copy_inputs=False)
            if not refill_in_place(holder, cases[k]):
                continue
        except Exception:
            continue
        try:
            wrong = differs(run(fn, holder[0], holder[1], copy_inputs=False), expected)
        except Exception:          # it answered case k from fresh objects: what it kept fails on these
            wrong = True
        if wrong:
            try:
                state = differs(run(fn, *cases[k]), expected)
            except Exception:
                state = True
            return k + 1, state
    return None
