"""Wrong versions of a reference: mistakes recognised by making them, and confirmed on the other inputs.

An exercise's own hints map a message to a wrong version of its reference; :func:`generic_mistakes` makes a
few more from any reference, for mistakes every exercise can show (-1/+1 polarities read as 0/1, OFF events
dropped or polarities made unsigned, times made float32, an input or the result clipped to [0, 1], a result or a
float input rounded). The learner's output matching a wrong version's on the failing input is not enough:
:func:`same_mistake_elsewhere` asks that it also match on the other inputs where that mistake shows, so that one
input cannot make two different mistakes look alike. :func:`wrong_axes_hint` makes one more, the reference run on
transposed images (differences or sums along the wrong image axis), and compares it on the failing input.
"""
from __future__ import annotations

import copy
import inspect
from typing import Callable

import numpy as np

from .learner_calls import run
from .outputs import compare_outputs, is_tensor, to_numpy
from .protocol import ExerciseLike


_POLARITY_NAMES = ("p", "p_events", "polarity", "polarities")


def _is_pm1(v) -> bool:
    """An integer numpy array of polarities -1 and +1 (with at least one -1)."""
    return isinstance(v, np.ndarray) and v.dtype.kind == "i" and v.size > 0 and bool(np.all(np.abs(v) == 1)) \
        and bool(np.any(v < 0))


def has_polarities(kwargs: dict) -> bool:
    """Whether an input holds -1/+1 polarities (an argument named p or p_events, or the ``p`` of events)."""
    return _with_polarities(kwargs, lambda v: v) is not None


def _with_polarities(kwargs: dict, f: Callable) -> dict | None:
    """``kwargs`` with ``f`` applied to every -1/+1 polarity input (an argument named p or p_events, or the ``p``
    of events); None when there is none."""
    return _with_field(kwargs, _POLARITY_NAMES, "p", _is_pm1, f)


def _with_field(kwargs: dict, names: tuple, field: str, test: Callable, f: Callable) -> dict | None:
    """``kwargs`` with ``f`` applied to every input that passes ``test``: an argument named in ``names``, or the
    field ``field`` of events (a copy of them, the field set past their own check); None when there is none."""
    out, found = {}, False
    for name, v in kwargs.items():
        if name in names and test(v):
            out[name], found = f(v), True
        elif getattr(v, "sensor_size", None) is not None and test(getattr(v, field, None)):
            ev = copy.copy(v)
            object.__setattr__(ev, field, f(getattr(v, field)))    # events check their fields: set it past that
            out[name], found = ev, True
        else:
            out[name] = v
    return out if found else None


# inputs that are instants on the recording's clock (not durations such as dt or bin_s): an argument of one of these
# names, or the ``t`` of events
TIME_NAMES = ("t", "t_events", "t_query", "times", "boundaries", "t_end", "t_start", "t_a", "t_b", "windows")


def _is_float_time(v) -> bool:
    """A float numpy array with entries, or a float (not a bool)."""
    return (isinstance(v, np.ndarray) and v.dtype.kind == "f" and v.size > 0) \
        or (isinstance(v, float) and not isinstance(v, bool))


def _with_times(kwargs: dict, f: Callable) -> dict | None:
    """``kwargs`` with ``f`` applied to every time input that is a float numpy array or a float (an argument named in
    :data:`TIME_NAMES`, or the ``t`` of events); None when there is none."""
    return _with_field(kwargs, TIME_NAMES, "t", _is_float_time, f)


def _float32_time(v):
    return np.asarray(v, dtype=np.float32) if isinstance(v, np.ndarray) else float(np.float32(v))


def _outside_unit(v) -> bool:
    try:
        a = to_numpy(v)
        return a.dtype.kind == "f" and a.size > 0 and bool(np.any((a < 0) | (a > 1)))
    except Exception:
        return False


def _clip_unit(v):
    return v.clamp(0.0, 1.0) if is_tensor(v) else np.clip(v, 0.0, 1.0)


def _clipped_inputs(kwargs: dict, only: str | None = None) -> dict | None:
    """``kwargs`` with the float array (or tensor) input ``only`` (or, without it, every one) clipped to [0, 1];
    None when no such input holds values outside [0, 1]."""
    found = {name for name, v in kwargs.items() if (isinstance(v, np.ndarray) or is_tensor(v)) and _outside_unit(v)
             and only in (None, name)}
    return {name: _clip_unit(v) if name in found else v for name, v in kwargs.items()} if found else None


def _map_numbers(v, f: Callable):
    """``f`` applied to every array, tensor or float inside ``v`` (tuples, lists and dicts kept)."""
    if isinstance(v, dict):
        return {k: _map_numbers(x, f) for k, x in v.items()}
    if isinstance(v, (tuple, list)):
        return type(v)(_map_numbers(x, f) for x in v)
    if isinstance(v, (np.ndarray, float, np.floating)) or is_tensor(v):
        return f(v)
    return v


def _round_to(d: int) -> Callable:
    def f(v):
        if is_tensor(v):
            return _torch_round(v, d) if v.is_floating_point() else v
        if isinstance(v, np.ndarray) and v.dtype.kind != "f":
            return v
        r = np.round(v, d)
        return float(r) if isinstance(v, float) else r
    return f


def _torch_round(v, d):
    return (v * 10.0 ** d).round() / 10.0 ** d


def generic_mistakes(ex: ExerciseLike, cases: list | None = None) -> list[tuple[str, Callable]]:
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
        ("the polarities were made unsigned (np.uint8, or a difference of unsigned arrays such as "
         "`(p > 0).astype(np.uint8) - (p < 0).astype(np.uint8)`), where -1 wraps round to 255: keep p signed "
         "(int8, int64) or make it float",
         on_inputs(lambda kw: _with_polarities(kw, lambda p: p.astype(np.uint8)))),
        ("the times were made float32 (about 7 significant digits: `astype(np.float32)`, torch.tensor(t) or "
         "torch.Tensor of them, a float32 buffer): a time near 1000 s then moves by up to 30 us, enough to cross an "
         "edge or change an interval, and on a recording's clock (Unix time, 1.5e9 s) by a minute; keep times "
         "float64 (np.asarray(t, dtype=np.float64)), or subtract the first time in float64 before anything narrower",
         on_inputs(lambda kw: _with_times(kw, _float32_time))),
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


def same_mistake_elsewhere(ex: ExerciseLike, fn: Callable, wrong: Callable, cases: list, skip: int,
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
            w = run(wrong, args, kwargs, ex.observe)
            if compare_outputs(w, run(ex.reference, args, kwargs, ex.observe), ex.rtol, ex.atol) is None:
                continue
            g = run(fn, args, kwargs, ex.observe)
        except Exception:
            continue
        try:
            if compare_outputs(g, w, ex.rtol, ex.atol) is not None:
                return False
        except Exception:
            return False
        shown += 1
    return shown >= support


# ---- the reference run on transposed images: differences along the wrong image axis -----------------------

def _swap_last_axes(v):
    """``v`` with the last two axes of every array (or tensor) of >= 2 dimensions swapped, recursively."""
    if is_tensor(v):
        return v.transpose(-1, -2) if v.dim() >= 2 else v
    if isinstance(v, np.ndarray):
        return np.swapaxes(v, -1, -2) if v.ndim >= 2 else v
    if isinstance(v, tuple):
        return tuple(_swap_last_axes(x) for x in v)
    if isinstance(v, list):
        return [_swap_last_axes(x) for x in v]
    return v


def _has_image(v) -> bool:
    if is_tensor(v):
        return v.dim() >= 2 and v.shape[-1] > 1 and v.shape[-2] > 1
    if isinstance(v, np.ndarray):
        return v.ndim >= 2 and v.shape[-1] > 1 and v.shape[-2] > 1
    if isinstance(v, (tuple, list)):
        return any(_has_image(x) for x in v)
    return False


def wrong_axes_hint(ex: ExerciseLike, args: tuple, kwargs: dict, got, expected=None) -> str | None:
    """The learner's output equals the reference run on transposed images, transposed back.

    That is the sign of differences (or sums) taken along the wrong image axis: rows for columns.
    A candidate that equals the expected output itself (an exercise symmetric under the swap) says nothing.
    """
    if not (any(_has_image(a) for a in args) or any(_has_image(v) for v in kwargs.values())):
        return None
    try:
        w = run(ex.reference, _swap_last_axes(args), {k: _swap_last_axes(v) for k, v in kwargs.items()}, ex.observe)
        w = _swap_last_axes(w)
    except Exception:
        return None
    candidates = [w] + ([type(w)(reversed(w))] if isinstance(w, (tuple, list)) and len(w) == 2 else [])
    for c in candidates:
        try:
            if expected is not None and compare_outputs(c, expected, ex.rtol, ex.atol) is None:
                continue
            if compare_outputs(got, c, ex.rtol, ex.atol) is None:
                return ("the differences (or sums) run along the wrong image axis: x is the column "
                        "index (axis -1), y the row index (axis -2)")
        except Exception:
            continue
    return None
