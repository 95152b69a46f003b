"""The check's main loop: every input in turn, the first problem reported with the hint that explains it.

:func:`run_check` runs the learner's function and the reference on each of the exercise's inputs
(:mod:`.learner_calls`; the reference first, and memory of its result's sizes filled with a pattern before the
learner's call), compares the outputs (:mod:`.outputs`; where the values match, the gradients of a differentiable
result too), and at the first difference looks for a hint (:func:`_hint_for`), in a fixed order: data kept in a
notebook variable (when it made the difference), np.empty (a rerun on zeroed memory answers otherwise), the
exercise's own wrong versions, outputs in another order, state kept between calls, an argument taken from input #1, the
generic wrong versions (:mod:`.mistakes`), a reseeded generator, a size taken from the events or from input #1 (or the
same on every input), the
patterns read off the values (:mod:`.hints`: axes in another order, indices from 1, rows aliased by one list, then
the rest), and last a notebook variable that only grew. A None that no in-place method explains
(``return out.sort()``), or a wrong value no hint explains, that an `except` of the learner's own made (returned, or
set a name the return uses) names the error it caught (:func:`.learner_calls.caught_errors`); an error raised on a
Python list among the inputs (where the notebook passes lists) says how to convert. A model among the inputs left
in another mode, or with other
parameters requiring grad, than the reference leaves it is named after each call, and so is an input tensor whose
requires_grad the call changed. A call stopped at the time limit (:class:`.learner_calls.TooSlow`: an endless loop) or
ended by sys.exit() or exit() (in a notebook too) is reported at once, at the learner's line, with no hint's search
(which would run it again). After every input matched, the last one is run a second time from other states of the
global generators and on a clock running faster (:func:`_second_call`, :mod:`.across_calls`, :mod:`.global_state`,
:func:`.fast_clock.fast_clock`: where the clock was read, every input on it), and input #1's own objects are
refilled in place with a later input's values and given again (:func:`.across_calls.same_objects_new_values`: a cache
keyed by id()), and last the function is called as the
notebooks call it (:func:`.signature.called_as_notebook`, each exercise's recorded call, only where its signature
differs from the stub's); a function that cannot take the inputs by name (a parameter renamed, or positional-only) is
called so throughout (:func:`.signature.notebook_caller`). Slips read off the learner's source and proven by a call
come first among the hints, and in a raised error's report before the guesses from the error's words: `^` for a
power (the function with `**` in its place matches, or numpy's or torch's error refuses `^` on floats) and a default
other than the stub's where an input leaves it out (with the stub's default passed, the input matches); the None of
``b = b.sort()`` (:mod:`.learner_source`), named only where the function with the method on a line of its own
matches, comes after the exercise's own and the generic wrong versions and a reseeded generator, before the guesses
read off the values. A hint read off the source never crashes the check (:func:`_safely`). The order is the report's:
change it and other hints win. Returns (passed, headline, detail lines); printing is
:func:`evinr_lite.teaching.exercises.check`'s.
"""
from __future__ import annotations

import contextlib
import functools
import io
import re
import threading
from typing import Callable

from .across_calls import (KEYED_BY_OBJECT, STATE_BETWEEN_CALLS, UNINITIALISED, constant_size_hint, fixed_size_hint,
                           global_cache_hint,
                           global_containers, mutable_default_hint, memory_explains, mutable_defaults, reseed_hint,
                           same_objects_new_values, scalar_factor_hint, shares_output, stale_argument_hint, state_hint)
from .global_state import (global_settings, imports_watched, other_rng_states, reseeded_generators, restore_settings,
                           rng_states, set_rng_states, settings_message)
from .hints import (REORDERED, aliased_rows_hint, axes_order_hint, generic_hint, has_repeated_index, non_square,
                    one_based_hint, size_from_events_hint, swapped_pair_hint)
from .fast_clock import fast_clock
from .learner_calls import (SWALLOWED, ExitCalled, TooSlow, cache_raised, caught_errors, changed_inputs,
                            container_names, in_place_message, module_flags, module_flags_message, poison_freed_memory,
                            run, swallowed_message, tensor_flags, tensor_flags_message, watching, where_raised)
from .learner_source import none_from_in_place_hint, stub_raised, xor_power_hint
from .mistakes import generic_mistakes, has_polarities, same_mistake_elsewhere, wrong_axes_hint
from .outputs import (BACKWARD_CALLED, Problem, compare_gradients, compare_outputs, describe_case, differing_leaf,
                      first_difference, is_tensor, named_inputs, not_finite)
from .protocol import ExerciseLike
from .signature import (called_as_notebook, called_the_same_way, learner_function, notebook_caller,
                        signature_default_hint)

NOT_DONE = "not done yet"  # the headline's start for a stub that raises NotImplementedError

Report = tuple[bool, str, list[str]]   # (passed, headline, detail lines)


def run_check(ex: ExerciseLike, fn: Callable) -> Report:
    """(passed, headline, detail lines) without printing.

    The global settings (torch's, numpy's error handling, the warning filters) are set back after every call of a
    function (see :func:`run`), and once more, to
    what they were when the check began, after all of it: a function that changes them only on an input the
    main run never reaches (a hint's search runs the others), or that raises right after, leaves the notebook as
    it was. Such a change is named in the report (`also: ...`) when the main run did not name it already."""
    settings = global_settings()
    fn = notebook_caller(ex, fn)       # a parameter renamed or positional-only: called as the notebook calls it
    with imports_watched() as imported:
        try:
            with watching(fn) as seen:
                ok, headline, details = _run_inputs(ex, fn)
            if seen and not ok and not headline.startswith("changed the notebook's global settings"):
                details = details + ["also: " + settings_message(seen)]
            return ok, headline, details
        finally:
            restore_settings(settings, imported)


def _run_inputs(ex: ExerciseLike, fn: Callable) -> Report:
    """:func:`run_check`'s work: every input in turn until one fails, then the last input a second time."""
    if not callable(fn):
        return False, f"expected a function, got {type(fn).__name__}", []
    try:
        cases = ex.cases()
    except Exception as err:  # a bug in the exercise itself, not the learner's
        return False, f"could not build the test inputs ({type(err).__name__}: {err})", []
    n = len(cases)
    defaults = mutable_defaults(fn)
    containers = global_containers(fn)
    for k, (args, kwargs) in enumerate(cases):
        where = f"input #{k + 1} of {n} ({describe_case(args, kwargs)})"
        after: list = []
        if k == n - 1:
            rng_before = rng_states()       # the last input is run again below, from other generator states
        changed_settings: dict = {}
        # the reference first, so that memory freed in the sizes of its result can be filled with a pattern before
        # the learner's call: an array started with np.empty then holds that pattern, not zeros by chance
        ref_after: list = []
        ref_seconds: list = []              # the reference's call alone (not the inputs' copy, nor the poisoning)
        try:
            expected = run(ex.reference, args, kwargs, ex.observe, inputs_after=ref_after, seconds=ref_seconds)
            poison_freed_memory(expected)
        except Exception:                   # run again below, where its error stops the check as it did before
            ref_after = []
        try:
            got = run(fn, args, kwargs, ex.observe, inputs_after=after, settings_changed=changed_settings)
            if k == n - 1:
                rng_after = rng_states()
        except NotImplementedError as err:
            if not stub_raised(err):      # torch's own (an operation it has no kernel for), not the stub's
                return _raised_report(ex, fn, err, cases, k, where, defaults, containers)
            return False, f"{NOT_DONE}: the function raises NotImplementedError", [
                "Replace `raise NotImplementedError` with your code, run the cell again, then re-check."]
        except TooSlow as err:              # no hint's search: each would run the endless call again
            return False, f"did not return within {err.seconds:g} s on {where}", _too_slow_details(
                err, ref_seconds[-1] if ref_seconds else None)
        except ExitCalled as err:
            return False, f"called {err.how} on {where}", _exit_details(err)
        except Exception as err:
            return _raised_report(ex, fn, err, cases, k, where, defaults, containers)
        if changed_settings:
            return False, f"changed the notebook's global settings on {where}", [settings_message(changed_settings)]
        if not ref_after:
            expected = run(ex.reference, args, kwargs, ex.observe, inputs_after=ref_after)
        model_changed = module_flags_message(module_flags(after[0]), module_flags(ref_after[0])) \
            if after and ref_after else None
        if model_changed:
            return False, f"changed the model's settings on {where}", [model_changed]
        problem = first_difference(ex, got, expected)
        # an input tensor's requires_grad changed, where the reference's call leaves it (a flag, not a value)
        flags = tensor_flags_message(tensor_flags(after[0]), tensor_flags(ref_after[0])) \
            if after and ref_after else None
        # inputs changed in place (a function with side effects says what to compare through `observe`)
        changed = changed_inputs((args, kwargs), after[0]) if ex.observe is None and after else []
        # the right values, but not what back-propagation from them reaches (a differentiable result)
        grads = compare_gradients(got, after[0], expected, ref_after[0]) \
            if problem is None and ex.observe is None and ex.compare is None and after and ref_after else None
        if grads is not None:
            extra = ["also: " + in_place_message(changed, container_names(args, kwargs))] if changed else []
            what = "back-propagates inside the function" if grads.message == BACKWARD_CALLED \
                else "gives the right values, but not the reference's gradients,"
            return False, f"{what} on {where}", [grads.message] + extra
        if problem is None and not changed and not flags:
            continue
        if problem is None and not changed:
            return False, f"changed its input's requires_grad on {where}", [flags]
        if problem is None:
            return False, f"changed its input on {where}", [in_place_message(changed, container_names(args, kwargs))] \
                + (["also: " + flags] if flags else [])
        details = [problem.message]
        hint, seed_note = _hint_for(ex, fn, cases, k, got, expected, problem, defaults, containers)
        if hint is None:            # a placeholder an `except` of the learner's own handed back (zeros, 0.0)
            hint = _safely(_swallowed_hint, fn, args, kwargs)
        if hint and hint.startswith(SWALLOWED) and got is None:
            details = ["returned None"]           # not a `return` forgotten: the function has one
        if hint and hint.startswith(REORDERED) and not problem.values:
            # a dtype's or a shape's own advice ("no .astype(int)") would name a slip the function did not make
            details = [f"the outputs are in another order ({problem.message.split(':')[0]})"]
        if hint:
            details.append(f"hint: {hint}")
        if seed_note:
            details.append(f"also: {seed_note}")
        if changed:
            details.append("also: " + in_place_message(changed, container_names(args, kwargs)))
        if flags:
            details.append("also: " + flags)
        return False, f"does not match the reference on {where}", details
    if n:
        clocks: dict = {}
        failed = _second_call(ex, fn, cases[-1], n, got, rng_before, rng_after, clocks)
        if failed is None and clocks:       # the clock was read: the other inputs on the faster clock too
            failed = _clock_elsewhere(ex, fn, cases)
        if failed is not None:
            return failed
        refilled = same_objects_new_values(ex, fn, cases)
        if refilled is not None:
            k, state = refilled
            if state:              # a fresh copy of input #k fails too: the calls, not the objects, made it
                return False, f"answers otherwise when called again on input #{k}", [STATE_BETWEEN_CALLS]
            return False, f"answers otherwise when input #1's objects are refilled with input #{k}'s values", [
                KEYED_BY_OBJECT.format(k=k)]
        as_called = called_as_notebook(ex, learner_function(fn), cases)
        if as_called is not None:
            return False, as_called[0], as_called[1]
    return True, f"matches the reference on {n} input{'s' if n != 1 else ''}", []


def _too_slow_details(err: TooSlow, ref_s: float | None) -> list[str]:
    """What a report says of a call stopped after the time limit: the learner's line it was on, and the likely
    causes (the reference's time on the same input for scale)."""
    line = [w.replace("raised in", "stopped in", 1) for w in where_raised(err)]
    return line + [
        f"hint: {_reference_time(ref_s)}every input here is small: your function "
        "is too slow, most likely an endless loop: a `while` whose condition never changes (its counter or level "
        "not moved toward the end, `i += 1` outside the loop's body, `level += C` where the level goes down, a "
        "time step of 0), a loop that appends to the list it walks over, or a call that waits (input(), "
        "time.sleep); run it on a small input with a print inside the loop to see which values stop changing"]


def _reference_time(seconds: float | None) -> str:
    """"the reference takes 12 ms on this input, and " (whole milliseconds from 10 ms, two digits below), or nothing
    where the reference's call was not timed (it raised)."""
    if seconds is None:
        return ""
    ms = 1000 * seconds
    return f"the reference takes {ms:.0f} ms on this input, and " if ms >= 10 else \
        f"the reference takes {ms:.2g} ms on this input, and "


_EXIT_FIX = ("to refuse an input raise an error (`raise ValueError(\"...\")`), and for a case the docstring gives a "
             "value for (no events, no pairs) return that value")


def _exit_details(err: ExitCalled) -> list[str]:
    """What a report says of a call that ended with sys.exit(), exit() or quit(): in plain Python a SystemExit; in a
    notebook (IPython's exit()) a request to shut the kernel down, which the check refused."""
    if err.notebook:
        return where_raised(err) + [
            "hint: exit() (quit()) in a notebook does not end the function: it asks Jupyter to shut the kernel down "
            "once the cell has run, and every variable of the notebook is lost (the check undid that here); "
            + _EXIT_FIX]
    return [f"SystemExit: {err.code!r}"] + where_raised(err) + [
        "hint: sys.exit() (exit(), quit()) ends the whole program, not the function: in a notebook it stops the "
        "cell (and the check) with no result; " + _EXIT_FIX]


def _raised_report(ex: ExerciseLike, fn: Callable, err: Exception, cases: list, k: int, where: str, defaults: dict,
                   containers: dict) -> Report:
    """The report for a call of ``fn`` that raised ``err`` on input ``k``: the error, the learner's line that
    raised it, and a hint where the error names a likely cause (an unhashable argument to a cache or a dict key,
    the stub's signature changed, `-` on bool arrays, a loss without a graph, a sensor that is not square, state
    kept between calls)."""
    args, kwargs = cases[k]
    details = [f"{type(err).__name__}: {err}"] + where_raised(err)
    same = functools.partial(called_the_same_way, fn)      # a proof's recompiled function, called as fn is
    written = _safely(xor_power_hint, fn, err, ex, (args, kwargs), None, same) \
        or _safely(signature_default_hint, ex, fn, args, kwargs) \
        or _safely(none_from_in_place_hint, fn, ex, (args, kwargs), None, same)
    if written:                 # read off the learner's source: what the error's words would only guess at
        details.append(f"hint: {written}")
    elif isinstance(err, TypeError) and "unhashable type" in str(err) and cache_raised(fn, err):
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
        if "positional-only arguments passed as keyword" in str(err):
            details.append(f"hint: the check passes the arguments by name ({names}), and your `/` makes the ones "
                           "before it positional-only: remove the `/` (the stub has none)")
        else:
            details.append(f"hint: the check calls your function as the stub declares it ({names}): keep the "
                           "stub's parameter names and order")
    if ("boolean subtract" in str(err) or "with two bool tensors" in str(err)) and has_polarities(kwargs):
        # numpy's and torch's words; with polarities at hand the likely aim is a sign, which `^` is not
        details.append("hint: `-` on two bool arrays or tensors (a sign as `(p > 0) - (p < 0)`) is refused, and "
                       "the `^` suggested is no sign (it is True for ON and OFF alike): make them integers first, "
                       "`(p > 0).astype(int) - (p < 0).astype(int)` (`.long()` for tensors), or use np.sign(p), "
                       "or p itself")
    elif "boolean subtract" in str(err) or "with two bool tensors" in str(err):
        details.append("hint: `-` on two bool arrays or tensors is refused: make them integers first "
                       "(`.astype(int)`, `.long()` for tensors) for a difference of counts or a sign; for masks "
                       "use `&`, `|`, `~` (a and not b: `a & ~b`)")
    if not written:
        details += _python_on_arrays_hints(err, " ".join(details[1:]))
    if isinstance(err, RuntimeError) and "does not require grad" in str(err):
        details.append("hint: the loss has no autograd graph to back-propagate: it was computed under "
                       "`torch.no_grad()`, or from values taken out of the graph (.detach(), .data, "
                       ".item(), .numpy()); compute it with torch operations on the model's outputs, "
                       "with gradients on")
    widths = _float_widths_hint(err, args, kwargs)
    if widths:
        details.append(f"hint: {widths}")
    if isinstance(err, IndexError) and non_square(args, kwargs):
        details.append("hint: this input's sensor is not square; sensor_size is (H, W), rows first, and an "
                       "image is indexed [y, x] (y = row, x = column): `H, W = sensor_size`, "
                       "`np.zeros((H, W))`, `frame[y, x]`")
    listed = _list_inputs_hint(ex, err, args, kwargs)
    if listed and not any(d.startswith("hint:") for d in details):
        details.append(f"hint: {listed}")
    state = mutable_default_hint(fn, defaults) if k > 0 else None
    if state is None and k > 0:
        cache, proven = global_cache_hint(fn, containers, ex, (args, kwargs), raised=True)
        if proven and cache:
            # the kept data made the error (with the variable emptied the call answers): a guess read off the
            # error's words (a sensor that is not square, say) explains nothing more; the cache's hint comes first
            details = [d for d in details if not d.startswith("hint:")]
        if proven or not any(d.startswith("hint:") for d in details):
            state = cache        # a list only logged to, which changes nothing, is a fallback
    if state:
        details.append(f"hint: {state}")
    return False, f"raised {type(err).__name__} on {where}", details


def _list_inputs_hint(ex: ExerciseLike, err: Exception, args, kwargs) -> str | None:
    """An error that an array method or array indexing raised on a Python list among the inputs (``cost[:, None]``,
    ``cost.astype(float)``, ``quality * 2.0``): where the notebook passes lists too, name them and how to convert.
    The check passes every input by name (no exercise's case has a positional one), so only keywords are read."""
    if not isinstance(err, (TypeError, AttributeError)) or ("list" not in str(err) and "sequence" not in str(err)):
        return None
    names = [name for name, value in kwargs.items() if isinstance(value, list)]
    if not names:
        return None
    call = getattr(ex, "call", None)
    where = f" as {call.where()} passes them (`{call.text}`)" if call is not None else ""
    first = names[0]
    return (f"{', '.join(f'`{name}`' for name in names)} {'is a Python list' if len(names) == 1 else 'are Python lists'} on this input,"
            f"{where}: a list has no array methods, no [:, None] indexing and no element-wise arithmetic; convert "
            f"first, `{first} = np.asarray({first}, dtype=float)`")


def _float_widths_hint(err: Exception, args, kwargs) -> str | None:
    """torch's refusal to mix float32 and float64 in one operation (a matrix product, a convolution, index_put),
    where an input tensor has one of the two widths: name it, and how to make a tensor of one's own like it. A
    difference matrix or a kernel made inside (torch.eye, torch.tensor([-1.0, 1.0])) is float32 whatever the input,
    so the function works on float32 inputs only (notebook 05 passes total_variation a float64 stack)."""
    msg = str(err)
    # "Double" and "Float" (scalar types, CUDA's DoubleTensor and FloatTensor), or "same dtype" (matmul's, tensordot's)
    widths = bool(re.search(r"\b[Dd]ouble", msg) and re.search(r"\b[Ff]loat", msg))
    if not isinstance(err, RuntimeError) or not (widths or "same dtype" in msg):
        return None
    named = [(name, str(v.dtype).replace("torch.", "")) for name, v in named_inputs(args, kwargs)
             if is_tensor(v) and str(v.dtype) in ("torch.float32", "torch.float64")]
    if not named or not (widths or any(w == "float64" for _, w in named)):
        return None
    name, width = next(((n, w) for n, w in named if w == "float64"), named[0])
    return (f"torch does not mix float32 and float64 tensors in one operation (a matrix product, a convolution, "
            f"index_put), and `{name}` is a {width} tensor on this input: a tensor made inside the function is "
            f"float32 by default (torch.eye, torch.zeros, torch.tensor([-1.0, 1.0])) and float64 when made from "
            f"numpy floats (torch.from_numpy, torch.tensor of an array); make it like the input "
            f"(`torch.eye(n, dtype={name}.dtype)`, `{name}.new_tensor([...])`, `torch.zeros_like({name})`), "
            f"which works for either width")


def _swallowed_hint(fn: Callable, args, kwargs) -> str | None:
    """The error the learner's own `except` caught on this input (:func:`.learner_calls.caught_errors`), named."""
    return swallowed_message(caught_errors(fn, args, kwargs))


def _safely(hint: Callable, *args) -> str | None:
    """``hint(*args)``, or None where it raises: a hint read off the learner's source (its globals' properties, a
    module's ``__getattr__``) must never crash the check."""
    try:
        return hint(*args)
    except Exception:
        return None


def _python_on_arrays_hints(err: Exception, line: str) -> list[str]:
    """Hints for Python's one-value tools used on whole arrays or tensors, from the error numpy or torch raised:
    `and` / `or` / `if` / a chained comparison (one truth value), `&` read before a comparison, the math module (one
    number), numpy on a tensor that requires grad (whose error suggests .detach(), which cuts the graph). ``line``:
    the learner's line that raised, as the report quotes it."""
    msg = str(err)
    if isinstance(err, (ValueError, RuntimeError)) and "ambiguous" in msg and ("truth value" in msg
                                                                            or "Boolean value" in msg):
        return ["hint: `and`, `or`, `not`, `if` and a chained comparison such as `a < t <= b` (which Python reads "
                "as `a < t and t <= b`) each need one True or False, and an array holds many: combine element-wise "
                "comparisons with `&`, `|` and `~`, each comparison in its own brackets: `(a < t) & (t <= b)`"]
    if isinstance(err, TypeError) and "ufunc 'bitwise_" in msg and "bitwise_xor" not in msg:
        return ["hint: `&` and `|` bind more tightly than comparisons: `t > a & t <= b` reads `t > (a & t) <= b`, "
                "and `&` of floats is refused; put each comparison in brackets: `(t > a) & (t <= b)`"]
    if isinstance(err, TypeError) and "converted to Python scalars" in msg and "math." in line:
        return ["hint: the math module works on one number at a time (math.exp, math.log, math.sqrt, math.floor): "
                "on an array use numpy's element-wise functions (np.exp, np.log, ...), on a tensor torch's"]
    if isinstance(err, RuntimeError) and "numpy() on Tensor that requires grad" in msg:
        return ["hint: a numpy function (np.mean, np.square, np.exp, ...) on a tensor that requires grad turns it "
                "into a numpy array, which torch refuses; the error's own suggestion, .detach().numpy(), would cut "
                "the result off from the autograd graph, so nothing could be trained through it: use torch's "
                "functions (torch.mean, torch.square, torch.exp) or the tensor's own methods (x.pow(2).mean())"]
    return []


def _hint_for(ex: ExerciseLike, fn: Callable, cases: list, k: int, got, expected, problem: Problem, defaults: dict,
              containers: dict) -> tuple[str | None, str | None]:
    """(hint, seed note) for a wrong output ``got`` on input ``k``: the first hint that applies, in the report's
    order. Each step may run the learner's function again (with its side effects), so a step runs only when the
    ones before it found nothing."""
    args, kwargs = cases[k]
    same = functools.partial(called_the_same_way, fn)      # a proof's recompiled function, called as fn is
    if got is None and expected is not None:
        # the None of `return out.sort()`, read off the source and proven, else the None that an `except` of the
        # learner's own handed back (the function has a `return`): an `except` that only went on explains nothing
        hint = _safely(none_from_in_place_hint, fn, ex, (args, kwargs), expected, same, got) \
            or _safely(_swallowed_hint, fn, args, kwargs)
        if hint:
            return hint, None
    # results kept in a notebook dict (or list) that the function fills: an input that shares an earlier
    # one's key gets that input's result. Named first when the kept data made the difference (run with the
    # variable emptied, the function answers otherwise), else only when no other hint applies (below): a list
    # the function only logs to (`log.append(len(t))`, a common habit) grows just the same and explains nothing
    cache_hint, proven = global_cache_hint(fn, containers, ex, (args, kwargs), got) if k > 0 else (None, False)
    hint = cache_hint if proven else None
    if hint is None:            # slips read off the source, each proven: `^` for `**`, another default
        hint = _safely(xor_power_hint, fn, None, ex, (args, kwargs), expected, same) \
            or _safely(signature_default_hint, ex, fn, args, kwargs)
    memory = None       # memory_explains' answer on this input, asked once (it runs the function four times)
    if hint is None:
        memory = memory_explains(fn, ex, args, kwargs, got)
        hint = UNINITIALISED if memory else None
    if hint is None:
        hint = _own_hint(ex, fn, cases, k, got)
    # mistakes that show only across inputs: state kept from an earlier call, a notebook variable or a
    # fixed size in place of an argument; and a pair returned in the other order
    if hint is None:
        hint = swapped_pair_hint(ex, got, expected)
    if hint is None:
        hint = state_hint(fn, defaults, ex, args, kwargs, got, first=k == 0, memory=memory)
    if hint is None:
        hint = stale_argument_hint(ex, fn, cases, k, got, expected)
    if hint is None and ex.observe is None:
        hint = _generic_mistake_hint(ex, fn, cases, k, got, expected)
    # a global generator seeded inside: random numbers, the same at every call (after the generic mistakes: a
    # seed that draws nothing explains no value, and is only noted)
    seed_note = None
    if hint is None:
        hint, seed_note = reseed_hint(ex, fn, args, kwargs)
    if hint is None:            # the None of `b = b.sort()`, proven: the method on a line of its own, the function
        # matches (or no longer fails but in its numbers); before the guesses read off the values (a NaN's)
        hint = _safely(none_from_in_place_hint, fn, ex, (args, kwargs), expected, same, got)
    if hint is None:
        hint = size_from_events_hint(args, kwargs, got, expected)
    if hint is None:
        hint = fixed_size_hint(ex, cases, k, got, expected)
    if hint is None and not problem.values:
        hint = constant_size_hint(ex, fn, cases, k, got, expected)
    if problem.values:
        if hint is None:
            hint = axes_order_hint(got, expected, ex.rtol, ex.atol)
        if hint is None:
            hint = one_based_hint(got, expected, ex.rtol, ex.atol)
        if hint is None:
            hint = aliased_rows_hint(got, expected, ex.rtol, ex.atol, fn)
        if hint is None:
            hint = wrong_axes_hint(ex, args, kwargs, got, expected)
        if hint is None:
            indexed = has_repeated_index(args, kwargs)
            hint = generic_hint(got, expected, indexed=indexed)
            if hint is None and isinstance(expected, (tuple, list, dict)):
                hint = generic_hint(*differing_leaf(got, expected, ex.rtol, ex.atol), indexed=indexed)
        if hint is None:
            hint = scalar_factor_hint(ex, fn, cases, k, got, expected)
    if hint is None:
        hint = cache_hint
    return hint, seed_note


def _own_hint(ex: ExerciseLike, fn: Callable, cases: list, k: int, got) -> str | None:
    """The message of the exercise's own wrong version that ``got`` matches on input ``k``.

    A known mistake is recognised by its output, whatever the first difference is (a wrong count of events is a
    wrong shape, not wrong values), and confirmed on the other inputs where it shows: one input alone can make two
    different mistakes look alike."""
    args, kwargs = cases[k]
    for message, wrong in ex.hints.items():
        try:
            w = run(wrong, args, kwargs, ex.observe)
            if compare_outputs(got, w, ex.rtol, ex.atol) is None and same_mistake_elsewhere(ex, fn, wrong, cases, k):
                return message
        except Exception:
            continue
    return None


def _generic_mistake_hint(ex: ExerciseLike, fn: Callable, cases: list, k: int, got, expected) -> str | None:
    """The message of a generic wrong version (:func:`generic_mistakes`) that ``got`` matches on input ``k``.

    Mistakes any exercise can show (polarities read as 0/1, a clip to [0, 1], a rounded result), recognised the
    same way as the exercise's own, from wrong versions made from the reference."""
    args, kwargs = cases[k]
    for message, wrong in generic_mistakes(ex, cases):
        applies = getattr(wrong, "applies", None)
        if applies is not None and not applies(args, kwargs):
            continue
        try:
            w = run(wrong, args, kwargs)
            if compare_outputs(w, expected, ex.rtol, ex.atol) is not None \
                    and not (not_finite(w) and not not_finite(expected)) \
                    and compare_outputs(got, w, ex.rtol, ex.atol) is None \
                    and same_mistake_elsewhere(ex, fn, wrong, cases, k, getattr(wrong, "support", 0)):
                return message
        except Exception:
            continue
    return None


def _second_call(ex: ExerciseLike, fn: Callable, case: tuple, n: int, got, rng_before: dict,
                 rng_after: dict, clocks_read: dict | None = None) -> Report | None:
    """The failure seen when the last input, ``case``, is run once more, from other states of the global random
    generators, or None. From the loop's last pass: ``got``, what the first run returned, and ``rng_before`` and
    ``rng_after``, the generators' states around it.

    A function that keeps state between calls (a notebook variable it changes, a mutable default argument) gives
    another result the second time; one that keeps its result (a buffer, a cache) returns the same array again;
    one that reseeds a global generator leaves it in the same state whatever it held before. The second call runs on
    a clock many times faster (:func:`.fast_clock.fast_clock`): a result that then differs (or an error), and not on
    the real clock, depends on the time read (a loop stopped after a time budget); what it prints is not shown.
    ``clocks_read``, a dict, receives the clocks the call read ({name: reads})."""
    args, kwargs = case
    rng_now, rng_other = rng_states(), other_rng_states(rng_before)
    changed_settings: dict = {}
    clocks: dict = {}
    raised = None
    try:
        set_rng_states(rng_other)
        poison_freed_memory(got)
        # the clock many times faster: a loop stopped after a time budget shows
        with _quiet(), fast_clock(fn) as clocks:
            try:
                again = run(fn, args, kwargs, ex.observe, settings_changed=changed_settings)
            except Exception as err:
                raised = err
                raise
        rng_again = rng_states()
        if ex.observe is not None:
            problem = None
        elif ex.compare is None:
            problem = compare_outputs(again, run(ex.reference, args, kwargs), ex.rtol, ex.atol)
        else:
            problem = None if ex.compare(again, run(ex.reference, args, kwargs)) is None else Problem("", True)
    except Exception as err:
        again, rng_again, problem = None, None, Problem(f"{type(err).__name__}: {err}")
    finally:
        set_rng_states(rng_now)
    if clocks_read is not None:
        clocks_read.update(clocks)
    if changed_settings:
        return False, f"changed the notebook's global settings on input #{n} of {n}", [settings_message(changed_settings)]
    if isinstance(raised, TooSlow) and clocks:      # no rerun on the real clock: it could hang as long again
        return _clock_too_slow(raised, clocks, n, n)
    if problem is not None and clocks and _right_on_real_clock(ex, fn, case, rng_other):
        return _clock_report(clocks, raised, n, n)
    if problem is not None and memory_explains(fn, ex, args, kwargs, got):
        return False, f"gives another result when input #{n} of {n} is run a second time", [UNINITIALISED]
    if problem is not None:
        return False, f"gives another result when input #{n} of {n} is run a second time", [
            "every input matched once, but a second call on the same input does not: your function keeps "
            "state between calls (a notebook variable it changes, a mutable default argument such as "
            "`state={}`, or unseeded randomness); compute everything from the arguments, afresh in each call"]
    shared = shares_output(got, again) if ex.observe is None else None
    if shared:
        return False, f"returns the same {shared} again when input #{n} of {n} is run a second time", [
            "every input matched, but two calls return the same array (or dict) object, or views of one: a "
            "buffer or a cached result kept between calls (a notebook variable, a dict of results keyed by the "
            "shape or the arguments, a default argument) is handed out again, so each call changes what the "
            "earlier ones returned, and a caller that changes a result changes the cache (`frames = [f(...) "
            "for ...]` would hold one array many times); create the result afresh in each call (np.zeros(...) "
            "inside the function), or return a copy of a cached one (`.copy()`)"]
    reseeded = reseeded_generators(rng_before, rng_other, rng_after, rng_again) if rng_again is not None else []
    if reseeded:
        return False, f"reseeds the global random generator ({', '.join(reseeded)})", [
            "every input matched, but after a call the global generator is in the same state whatever it held "
            "before: your function seeds it (np.random.seed, torch.manual_seed, random.seed), which resets the "
            "random numbers of the whole notebook at every call (a later cell's random minibatches or noise "
            "repeat); nothing here asks for randomness: remove the seed, or draw from a generator of your own "
            "(rng = np.random.default_rng(seed), torch.Generator().manual_seed(seed))"]
    return None


def _clock_elsewhere(ex: ExerciseLike, fn: Callable, cases: list) -> Report | None:
    """For a function that read the clock in the second call and still matched there: each other input run on the
    faster clock (:func:`.learner_calls.fast_clock`); the first that then differs, and matches on the real clock,
    is reported (a time budget that the last input's result does not show: a solver's start that is the answer);
    what the function prints there is not shown."""
    n = len(cases)
    for j, (args, kwargs) in enumerate(cases[:-1]):
        clocks: dict = {}
        raised = None
        try:
            with _quiet(), fast_clock(fn) as clocks:
                try:
                    got = run(fn, args, kwargs, ex.observe)
                except Exception as err:
                    raised = err
                    raise
            if ex.observe is not None or not clocks:
                continue
            expected = run(ex.reference, args, kwargs)
            differs = (compare_outputs(got, expected, ex.rtol, ex.atol) if ex.compare is None
                       else ex.compare(got, expected)) is not None
        except Exception:
            differs = True
        if isinstance(raised, TooSlow) and clocks:
            return _clock_too_slow(raised, clocks, j + 1, n)
        if differs and clocks and _right_on_real_clock(ex, fn, cases[j], rng_states()):
            return _clock_report(clocks, raised, j + 1, n)
    return None


@contextlib.contextmanager
def _quiet():
    """What the block prints (to sys.stdout or sys.stderr) is kept from the notebook: the check's own reruns of the
    learner's function, whose prints (a progress line, a time taken an hour long) the learner did not ask for. On
    the main thread only: sys.stdout is the whole process's, and two checks in two threads that each put back what
    they found would leave one's buffer in place for good (a check run from another thread prints as before)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        yield


def _clock_report(clocks: dict, raised: Exception | None, k: int, n: int) -> Report:
    """The report of input #k whose result changed on the faster clock (``raised``: the error it raised there,
    if any) and matches on the real clock."""
    if raised is None:
        return False, f"gives another result when the clock runs faster (input #{k} of {n})", [_clock_message(clocks)]
    return False, f"raised {type(raised).__name__} when the clock ran faster (input #{k} of {n})", [
        f"{type(raised).__name__}: {raised}", *where_raised(raised), _clock_message(clocks, raised)]


def _clock_too_slow(err: TooSlow, clocks: dict, k: int, n: int) -> Report:
    """The report of input #k stopped at the time limit on the faster clock (it returned on the real clock)."""
    read = ", ".join(f"time.{name}()" for name in clocks)
    return False, f"did not return within {err.seconds:g} s when the clock ran faster (input #{k} of {n})", [
        *[w.replace("raised in", "stopped in", 1) for w in where_raised(err)],
        f"every input matched, but run again with the clock many times faster ({read} an hour ahead at each read) "
        "it did not return: its running time may depend on the time it reads (a wait until a time, a `time.sleep` "
        "of a time read), or on state kept between calls; stop a loop on a tolerance and an iteration count, and "
        "read the clock only to print how long it took"]


def _right_on_real_clock(ex: ExerciseLike, fn: Callable, case: tuple, rng_other: dict) -> bool:
    """Whether ``fn`` matches the reference on ``case`` when run again from the same generator states as the second
    call, on the real clock: then the faster clock alone made the second call's difference. What it prints is not
    shown (a rerun of the check's own)."""
    args, kwargs = case
    rng_now = rng_states()
    try:
        set_rng_states(rng_other)
        with _quiet():
            again = run(fn, args, kwargs, ex.observe)
        if ex.observe is not None:
            return False
        expected = run(ex.reference, args, kwargs)
        return (compare_outputs(again, expected, ex.rtol, ex.atol) if ex.compare is None
                else ex.compare(again, expected)) is None
    except Exception:
        return False
    finally:
        set_rng_states(rng_now)


def _clock_message(clocks: dict, raised: Exception | None = None) -> str:
    """What a report says of a result that changed when the clock ran faster (``clocks``: the clocks read;
    ``raised``: the error the function raised there instead of answering, if any)."""
    read = ", ".join(f"time.{name}()" for name in clocks)
    if raised is not None:
        return (f"every input matched, but run again with the clock many times faster the function raised "
                f"{type(raised).__name__} instead of answering: it depends on the time it reads ({read}); a time "
                "limit used as a safeguard (`if time.perf_counter() - t0 > 30: raise ...`) fires on a slower or busier "
                "machine: cap the number of iterations instead, stop on a tolerance, and read the clock only to print "
                "how long it took")
    return (f"every input matched, but run again with the clock many times faster the function answers otherwise: "
            f"its result depends on the time it reads ({read}), as a loop stopped after a time budget does (`while "
            "time.perf_counter() - t0 < 0.1`); on the notebook's larger inputs, or a slower or busier machine, it "
            "stops earlier with another answer; stop an iterative loop on a tolerance and an iteration count, or "
            "solve directly (np.linalg.solve, np.linalg.lstsq), and read the clock only to print how long it took")
