"""Exercise checks, round 16: ten more wrong solutions across 6 exercises, in mistake classes that rounds 2-15 did
not try, and nine correct alternatives (in 4 exercises).

Mistake classes: a function right only for the containers the check passed, where the notebook passes others
(pareto_front: notebook 07 calls `front_of(cost, quality)` with Python lists built by a list comprehension, and every
input of the check was a numpy array: `cost[:, None]`, `cost.astype(float)` and `quality * 1.0` work on arrays and
fail on lists); three outputs in another order (esim_interval's times, polarities and level); an error hidden by the
learner's own `try`/`except` (returning None, printing and returning nothing, or handing back a placeholder: zeros,
0.0, a zero tensor cut off from the graph).

Correct alternatives: np.asarray first and then vectorised, a plain Python loop over the lists, a sweep by
np.lexsort of the lists, esim_interval's outputs as a list, an optional import in a `try`/`except ImportError`, a
cache that catches its own KeyError, a 0 / 0 caught (ZeroDivisionError on Python floats) where no input reaches it,
and the references themselves.

Holes (these passed a check before this round; each now fails and its report names the mistake):
- pareto_front: pf_no_asarray, pf_argsort_method and pf_scaled_quality passed (every input an array) and raised
  TypeError or AttributeError in notebook 07, cell 47, where the learner's function runs on lists. The fourth input
  now holds Python lists (ablation_exercises._inputs_front; the count of 5 inputs that the notebook quotes stands),
  and an error raised on a list input says so and how to convert (run_check._list_inputs_hint); the stub's comment
  says "lists or arrays (the cell after the check passes lists)".

Misreported (these failed, with a report that named another mistake):
- esim_interval's outputs in another order (esim_pols_first, esim_level_first) got a dtype's or a shape's advice ("the
  values were made whole numbers: no .astype(int)"): only a pair's swap was tried. Every order of two to four
  outputs is now tried (hints.swapped_pair_hint), and the report says which output is which;
- None from an `except` of the learner's own (tm_swallow_none, ect_swallow_print) read "did you forget the `return`
  statement?": the function has one. A placeholder from such an `except` (tm_swallow_zeros, ie_swallow_index,
  tv_swallow_zero) got a bare "wrong values". The call is now run again under a tracer of the learner's own frames
  (learner_calls.caught_errors), and the report names the error that was caught, at its line.

Its review found the hint blaming an `except` that had nothing to do with the result (a `return out.sort()` told to
remove an unrelated `try: [][0] except IndexError: pass`, an off value told to remove a `try: t = t.numpy() except
AttributeError: pass`), and the traced call some 35 times slower than a plain one (each frame's file looked up
again). An error is now named only where it reached the function the check called, and that function's `except`
whose body ran for it made the result: returned from that body (then "remove the `try`/`except`"), or set a name
from which the returned value is computed (then "this may be why", with no advice to remove it); a None is first
read for an in-place method (`.sort()`). The tracer's tests are skipped where another tool's tracer runs.

Before this round's fixes all 10 wrong solutions failed the standard (3 passed the check, 7 failed with a report
that named another mistake or none), and all 9 correct alternatives passed, before and after.

Open, on purpose: a function whose parameters are only `*args` (esim_interval's notebook call passes six arguments by
position) fails with the stub's-names hint: the stub's names are the exercise's contract (round 2). An error caught
by the learner's `except KeyError` or `except ImportError` is never named (a dict filled on a miss, an optional
import); neither is one where another tool's tracer (a debugger, coverage) runs.
"""
import sys

import numpy as np
import pytest
import torch

from evinr_lite.teaching import exercises
from evinr_lite.teaching.checking import learner_calls
from exercise_reports import assert_fails_naming, assert_passes, case_ids as _id, quoted_counts, report as _report


def R(n): return exercises.reference(n)


# ---- pareto_front: right on arrays, wrong on the notebook's lists
def pf_no_asarray(cost, quality):
    c, q = cost[:, None], quality[:, None]
    dominated = (c.T <= c) & (q.T >= q) & ((c.T < c) | (q.T > q))
    return ~dominated.any(axis=1)
def pf_argsort_method(cost, quality):                         # a sweep by cost, the best quality first among ties
    order = np.lexsort((-np.asarray(quality, float), cost.astype(float)))
    keep, best, last = np.zeros(len(cost), bool), -np.inf, None
    for i in order:
        if quality[i] > best or (last is not None and cost[i] == cost[last] and quality[i] == quality[last]):
            keep[i], best, last = True, max(best, quality[i]), i
    return keep
def pf_scaled_quality(cost, quality):
    q = quality * 1.0                                         # a copy as floats: on a list, a TypeError
    c = np.asarray(cost, float)
    return R("pareto_front")(c, q)


# ---- three outputs in another order
def esim_pols_first(L_a, L_b, t_a, t_b, ref, C):
    times, pols, level = R("esim_interval")(L_a, L_b, t_a, t_b, ref, C)
    return pols, times, level
def esim_level_first(L_a, L_b, t_a, t_b, ref, C):
    times, pols, level = R("esim_interval")(L_a, L_b, t_a, t_b, ref, C)
    return level, times, pols


# ---- an error hidden by the learner's own try/except
def tm_swallow_none(L, gamma):
    try:
        I = np.exp(L)
        return (I / (I + 1)) ** gamma + offset          # a name of another cell's, never defined  # noqa: F821
    except Exception:
        return None
def ect_swallow_print(log_changes, net_counts):
    try:
        d, n = np.asarray(log_changes, float), np.asarray(net_counts, float)
        return float(np.linalg.lstsq(n, d, rcond=None)[0][0])   # n needs to be a column, n[:, None]
    except Exception as err:
        print("could not fit:", err)
def tm_swallow_zeros(L, gamma):
    try:
        I = np.exp(L)
        return (I / (I + 1)) ** gamma + offset          # noqa: F821
    except Exception:
        return np.zeros_like(L)
def ie_swallow_index(t_events, p_events, C, t_query):
    out = np.zeros(len(t_query))
    for j, tq in enumerate(t_query):
        try:
            k = np.searchsorted(t_events, tq, side="right")
            out[j] = C * np.sum(p_events[:k]) if t_events[k] > tq else 0.0    # t_events[k] past the last event
        except IndexError:
            out[j] = 0.0
    return out
def tv_swallow_zero(F):
    try:
        dx = F[..., :, 1:] - F[..., :, :-1]
        dy = F[..., 1:, :] - F[..., :-1, :]
        return (dx.abs() + dy.abs()).mean()                   # shapes [H, W-1] and [H-1, W] do not broadcast
    except RuntimeError:
        return torch.zeros((), dtype=F.dtype)


# ---- correct alternatives
def pf_asarray_vectorised(cost, quality):
    c, q = np.asarray(cost, float)[:, None], np.asarray(quality, float)[:, None]
    return ~((c.T <= c) & (q.T >= q) & ((c.T < c) | (q.T > q))).any(axis=1)
def pf_python_loops(cost, quality):                           # no numpy until the end: lists and arrays alike
    front = []
    for i in range(len(cost)):
        front.append(not any(cost[j] <= cost[i] and quality[j] >= quality[i]
                             and (cost[j] < cost[i] or quality[j] > quality[i]) for j in range(len(cost))))
    return np.array(front, dtype=bool)
def pf_lexsort_lists(cost, quality):
    c, q = np.asarray(cost, float), np.asarray(quality, float)
    keep, best, last = np.zeros(len(c), bool), -np.inf, None
    for i in np.lexsort((-q, c)):
        if q[i] > best or (last is not None and c[i] == c[last] and q[i] == q[last]):
            keep[i], best, last = True, max(best, q[i]), i
    return keep
def esim_as_list(L_a, L_b, t_a, t_b, ref, C):
    return list(R("esim_interval")(L_a, L_b, t_a, t_b, ref, C))
def tm_optional_import(L, gamma):
    try:
        from scipy.special import expit
    except ImportError:
        def expit(v): return 1.0 / (1.0 + np.exp(-v))
    return expit(np.asarray(L, float)) ** gamma
def tm_keyerror_cache(L, gamma, _curves={}):                  # a dict filled on a miss; values never kept
    try:
        curve = _curves[gamma]
    except KeyError:
        curve = _curves[gamma] = (lambda I: (I / (I + 1.0)) ** gamma)
    return curve(np.exp(np.asarray(L, float)))
def ect_zero_division_caught(log_changes, net_counts):
    d = [float(v) for v in log_changes]; n = [float(v) for v in net_counts]
    try:
        return sum(a * b for a, b in zip(d, n)) / sum(b * b for b in n)
    except ZeroDivisionError:
        return float("nan")


LISTS = "are Python lists on this input, as notebook 07_ablations, cell 47 passes them (`front_of(cost, quality)`)"
HOLES = [
    ("pareto_front", pf_no_asarray, LISTS),
    ("pareto_front", pf_argsort_method, LISTS),
    ("pareto_front", pf_scaled_quality, LISTS),
]
ORDER = "the outputs are right, but in another order: "
MISREPORTED = [
    ("esim_interval", esim_pols_first, ORDER + "output [1] is the expected [0], output [0] is the expected [1]"),
    ("esim_interval", esim_level_first, ORDER + "output [1] is the expected [0], output [2] is the expected [1], "
                                                "output [0] is the expected [2]"),
]
CAUGHT = "an error was raised inside your function and caught by its own `except` ("
SWALLOWED = [
    ("reinhard_tonemap", tm_swallow_none, "NameError: name 'offset' is not defined, in tm_swallow_none, line"),
    ("estimate_contrast_threshold", ect_swallow_print, "LinAlgError: 1-dimensional array given"),
    ("reinhard_tonemap", tm_swallow_zeros, "NameError: name 'offset' is not defined, in tm_swallow_zeros, line"),
    ("integrate_events_1d", ie_swallow_index, "IndexError: index"),
    ("total_variation", tv_swallow_zero, "RuntimeError: The size of tensor a"),
]
CORRECT = [
    ("pareto_front", pf_asarray_vectorised), ("pareto_front", pf_python_loops), ("pareto_front", pf_lexsort_lists),
    ("esim_interval", esim_as_list), ("reinhard_tonemap", tm_optional_import), ("reinhard_tonemap", tm_keyerror_cache),
    ("estimate_contrast_threshold", ect_zero_division_caught),
    ("pareto_front", R("pareto_front")), ("esim_interval", R("esim_interval")),
]


@pytest.mark.parametrize("name, wrong, words", HOLES, ids=_id(HOLES))
def test_a_function_right_only_on_arrays_fails_on_the_notebook_s_lists(name, wrong, words):
    ok, text = _report(name, wrong)
    assert not ok and "Traceback" not in text, text
    assert "on input #4 of 5 (cost=list of 5, quality=list of 5)" in text and words in text, text
    assert "`cost = np.asarray(cost, dtype=float)`" in text, text


@pytest.mark.parametrize("name, wrong, words", MISREPORTED, ids=_id(MISREPORTED))
def test_outputs_in_another_order_are_named(name, wrong, words):
    ok, text = _report(name, wrong)
    assert not ok and "Traceback" not in text, text
    assert words in text and "the outputs are in another order (wrong" in text, text
    assert "astype(int)" not in text and "whole numbers" not in text, text


# the caught errors are found by a tracer of the check's own, which another tool's (coverage, a debugger) turns off
OWN_TRACER = pytest.mark.skipif(sys.gettrace() is not None, reason="another tool's tracer runs: nothing is traced")


@OWN_TRACER
@pytest.mark.parametrize("name, wrong, words", SWALLOWED, ids=_id(SWALLOWED))
def test_an_error_the_function_caught_itself_is_named(name, wrong, words):
    ok, text = _report(name, wrong)
    assert not ok and "Traceback" not in text, text
    assert CAUGHT in text and words in text, text
    assert "did you forget the `return` statement" not in text, text
    assert sys.gettrace() is None


@pytest.mark.parametrize("name, fn", CORRECT, ids=_id(CORRECT))
def test_correct_alternatives_pass(name, fn):
    assert_passes(name, fn)


def test_the_fourth_pareto_input_holds_lists_and_the_counts_stand():
    cases = exercises.get("pareto_front").cases()
    assert [type(v) for v in cases[3][1].values()] == [list, list]
    assert all(isinstance(v, np.ndarray) for k, (_, kw) in enumerate(cases) if k != 3 for v in kw.values())
    for name, n in quoted_counts().items():
        assert len(exercises.get(name).cases()) == n, name


def test_a_forgotten_return_is_still_named_so():
    """No `except` in the function: the None is a `return` left out, as before."""
    def tm_no_return(L, gamma):
        I = np.exp(L)
        (I / (I + 1)) ** gamma
    assert_fails_naming("reinhard_tonemap", tm_no_return, "did you forget the `return` statement?")


def test_a_pair_swapped_keeps_its_words():
    def sld_swapped(h, dh_dt, weight, bias, omega):
        a, b = R("sine_layer_derivative")(h, dh_dt, weight, bias, omega)
        return b, a
    assert_fails_naming("sine_layer_derivative", sld_swapped,
                        "hint: the two outputs are swapped: return them in the order the docstring gives")


def test_caught_errors_keeps_another_tool_s_tracer():
    """Under a debugger's or coverage's tracer nothing is traced (None), and that tracer stays; with none, the
    check's own tracer finds the error and is gone after."""
    def tracer(frame, event, arg):
        return None
    old = sys.gettrace()
    sys.settrace(tracer)
    try:
        assert learner_calls.caught_errors(tm_swallow_none, (np.zeros(3), 1.0), {}) is None
        assert sys.gettrace() is tracer
    finally:
        sys.settrace(old)
    assert learner_calls.swallowed_message([]) is None and learner_calls.swallowed_message(None) is None
    if old is None:
        found = learner_calls.caught_errors(tm_swallow_none, (np.zeros(3), 1.0), {})
        assert [(type(c.error), c.how) for c in found] == [(NameError, "return")] and sys.gettrace() is None


# ---- an `except` that did not make the result is never blamed (the review of round 16)
def ie_sort_none_unrelated_except(t_events, p_events, C, t_query):
    try:
        [][0]                                                 # a check of the learner's, caught on purpose
    except IndexError:
        pass
    out = R("integrate_events_1d")(t_events, p_events, C, t_query)
    return out.sort()
def ie_tensor_or_array_off(t_events, p_events, C, t_query):
    try:
        t_query = t_query.numpy()                             # tensors accepted too
    except AttributeError:
        pass
    out = np.array(R("integrate_events_1d")(t_events, p_events, C, t_query), dtype=float)
    out[len(out) // 2] += 0.01                                # a slip no hint knows
    return out
def tm_fallback_unused(L, gamma):
    try:
        scale = float("x")
    except ValueError:
        scale = 1.0                                           # set, but the result does not use it
    I = np.exp(np.asarray(L, float))
    return (I / (I + 1)) ** gamma + 1e-3
def tm_fallback_used(L, gamma):
    I = np.exp(np.asarray(L, float))
    try:
        curve = (I / (I + 1)) ** gamma + offset               # noqa: F821
    except NameError:
        curve = np.zeros_like(I)
    result = curve * 1.0
    return result


def test_a_none_from_sort_is_named_so_whatever_the_function_caught():
    """`return out.sort()` in a function that also caught an unrelated IndexError: the `.sort()` is named."""
    ok, text = _report("integrate_events_1d", ie_sort_none_unrelated_except)
    assert not ok and "`return out.sort()`: `.sort(...)` changes its object in place" in text, text
    assert CAUGHT not in text and "IndexError" not in text, text


@pytest.mark.parametrize("wrong", [ie_tensor_or_array_off, tm_fallback_unused], ids=lambda f: f.__name__)
def test_an_except_that_did_not_make_the_result_is_not_blamed(wrong):
    name = "integrate_events_1d" if wrong is ie_tensor_or_array_off else "reinhard_tonemap"
    ok, text = _report(name, wrong)
    assert not ok and "Traceback" not in text, text
    assert CAUGHT not in text and "remove the `try`/`except`" not in text, text


@OWN_TRACER
def test_an_except_that_set_what_is_returned_is_named_softly():
    """The `except` set `curve`, from which the returned `result` is computed: named as a possible cause, without
    the advice to remove the `try`/`except` (its body has no `return`)."""
    ok, text = _report("reinhard_tonemap", tm_fallback_used)
    assert not ok and CAUGHT + "NameError: name 'offset' is not defined" in text, text
    assert "its `except` (line" in text and "set `curve`, from which what the function returns (line" in text, text
    assert "is computed: this may be why the result is wrong" in text, text
    assert "remove the `try`/`except`" not in text, text
    found = learner_calls.caught_errors(tm_fallback_unused, (np.zeros(3), 1.0), {})
    assert [(type(c.error), c.how) for c in found] == [(ValueError, None)]


def test_this_round_counts():
    wrong = HOLES + MISREPORTED + SWALLOWED
    assert (len(HOLES), len(MISREPORTED), len(SWALLOWED), len(CORRECT)) == (3, 2, 5, 9)
    assert len(wrong) == 10 and len({r[0] for r in wrong}) == 6
    assert len({r[0] for r in CORRECT}) == 4
