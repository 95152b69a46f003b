"""Exercise checks, round 14: twenty-five more wrong solutions across 20 exercises (two left open on purpose), in
mistake classes that rounds 2-13 did not try, and thirteen correct alternatives (in 8 exercises); and the review's
section (below): 7 wrong solutions whose own mistake is now named, 8 reports that no longer name an unproven slip, 4
signatures that the notebooks' calls accept and that now pass, and 4 single tests.

Mistake classes: a signature other than the stub's (parameters in another order: `(t_events, p_events, t_query,
C)`, `(x, y, phase)` for `(y, x, phase)`, `(nxt, prev)`, `(quality, cost)`, `(gamma, L)`, omega moved first; a
keyword-only `*` before an argument the notebook's cells pass by position; a default other than the stub's,
`factor=5.0` for 10.0, `eps=1e-6` for 1/255, or none); `^` written for a power (`n ^ 2` on integers is XOR, and on
float arrays and tensors numpy and torch refuse it); the value of a method that works in place and returns None
(`b = b.sort()`, `order = order.sort()` of a list, `return out.sort()`, `out = out.update(...)` of a dict); an
optimiser's gradients clipped (open, below); the global generator drawn where the answer does not depend on it
(open, below).

Correct alternatives: an extra keyword parameter at the end (`verbose=False`), a keyword-only `eps` that notebook 09
leaves out (afo_kwonly_eps), `factor=5.0` where notebook 11 always passes HOT_FACTOR (hpm_default_changed), `*args, **kwargs` handed on, a default
written another way (`eps=1 / 255`, `factor=10` for 10.0) or as None resolved inside, `model.zero_grad()` for
`optimizer.zero_grad()`, `^ True` on a bool mask (bits, not a power), an array sorted in place on a line of its own,
torch.square, a permutation from a generator of one's own.

Holes (these passed a check before this round; each now fails and its report names the mistake):
- a function whose parameters are in another order than the stub's, or keyword-only, passed: the check passes every
  argument by name, while the notebook's later cell calls the function by position (`hot_mask(rec.events.x,
  rec.events.y, (H, W), HOT_FACTOR)` in notebook 11, `tonemap(L_frame, g)` in notebook 05) and gets another answer or
  an error: ie_reordered, tm_reordered, esim_reordered, chain_reordered, pf_reordered, sld_reordered, gef_reordered,
  er_reordered, anchor_reordered, qb_x_first (x and y are symmetric under input #1's phase: every input is tried),
  hpm_factor_kwonly.
  After every input matched, and only where the function's signature differs from the stub's, the check now calls it
  as the notebook's call does (teaching/notebook_calls.py, read off the notebooks): each input with the arguments
  the call passes by position by position, and, where the call leaves an optional argument out, each input that
  passes it without it, each compared with the reference called the same way (checking/signature.called_as_notebook,
  run_check.py). An unchanged stub costs no call.
No case was changed or added: the counts the notebooks quote stand.

The review's fixes (section "review" at the end; each of its tests failed before them): the round first replayed
"the stub's order, optional arguments left out" on every signature that differed, and so failed solutions that work
in the notebooks (`anchor_first_offset(first_frame, L_t0, *, eps=1/255)`, which notebook 09 calls as
`anchor_first_offset(scored.images[0], L_t0)`; factor=5.0 where notebook 11 always passes HOT_FACTOR; a keyword-only
t_end that notebook 08 passes by name; a parameter positional-only where the notebook passes it by position), and
its report claimed calls the notebooks do not make. A parameter renamed stays a mistake, as round 2 has it (the
stub's names are the exercise's contract), although the notebook's positional call would take it. Each exercise's real call is now recorded
(teaching/notebook_calls.py, kept in step with the notebooks by a test) and the check calls the function that way;
a function that cannot take the inputs by name is called so throughout (signature.notebook_caller), and the
report quotes the notebook's cell. Every slip read off the source is now named only on evidence: another default
only where passing the stub's makes the failing input match (a `t_start=None` resolved inside, or `eps=None`, beside
another mistake got the default's hint in place of that mistake's); `^` only where the function, `^` rewritten to
`**` and compiled again with its globals and closure, matches (a correct `dominated ^ 1` beside another mistake was
blamed), or where numpy's or torch's error refuses `^` on floats; the None of `.sort()` only where the error names a
None or a traced call sees the name hold one (torch's Tensor.sort() returns values and indices), and after the
exercise's own and the generic wrong versions. A NotImplementedError is the stub's only where the learner's own
frame executed a raise (the word `raise` in `raised = x ^ 2` made torch's refusal "not done yet", and so did torch's
Module without a `forward`). A functools.wraps wrapper is read by its own signature, not the wrapped function's. For
an exercise with no recorded call, a positional-only `/` gets its own hint, not "keep the names and order".

Named (these failed before, with a report that named nothing or the wrong thing):
- `^` for a power on a float tensor (tl_xor, tik_xor, tlb_xor) raises torch's NotImplementedError
  (`"bitwise_xor_cpu" not implemented for 'Float'`), and the report said "not done yet: the function raises
  NotImplementedError ... Replace `raise NotImplementedError`": a NotImplementedError is now the stub's only where a
  `raise` statement raised it (learner_source.stub_raised); otherwise it is reported as the error it is. On a float
  array (tm_xor) numpy's "ufunc 'bitwise_xor'" got the hint about `&` and `|` binding before comparisons; on integers
  (ect_xor) a bare "wrong value". Each now gets "`^` is exclusive or (of the bits) in Python, not a power", from the
  error's words or, for a wrong value, from `^` beside a number in the function's source (learner_source.py);
- a None from a method that works in place (ie_sort_returns_none: a bare "wrong shape: got ()"; bis_sort_none and
  tfp_update_none: an error and no hint; ii_sort_none: a bare "wrong value"; ie_return_sort: "did you forget the
  `return` statement?", and it has one) now gets "`.sort(...)` changes its object in place and returns None", with the
  learner's line (learner_source.none_from_in_place_hint: read off the source, asked only once the function failed);
- a default other than the stub's where an input leaves the argument out (afo_default_1e6, a bare "wrong values") or
  a default dropped (afo_default_dropped, "keep the stub's parameter names and order", which it did) now name the
  argument and both defaults (signature.signature_default_hint).

The final review's fixes (section "final review" at the end; each of its tests failed before them): the None of an
in-place method was named on weak evidence (any "None" in the error's words, a traced local that held None at any
time): it is now named only where the function, rewritten with the method on a line of its own and the name kept
holding the object, matches the reference (or, where it raised or returned None or another shape, no longer fails
but in its numbers), and a torch `.sort()` beside a helper returning None, or `s = None` before it, is not blamed
(the constant factor of tl_sort_init_none is named instead); ii_sort_none now sorts the pixel order by key, its
earlier sort of argsort's indices being a second mistake no rewrite could prove. A positional-only function (called
through the check's notebook-call wrapper) keeps the hints read off its code and globals (a notebook cache, np.empty,
`^`), and a decorated one (`@torch.no_grad()`) is read and recompiled as its own function; `^` with 0, 1, True or
False after it is never taken for a power; a global whose property raises, or any hint that raises, no longer makes
"the check itself failed"; every notebook call of each exercise's function, not only the first, is kept in step
with teaching/notebook_calls.py. learner_source and signature are one layer of the checking package's contract.

The session's last review (section "the session's last review"; each test failed before its fix): the `^` proof
ran the learner's `^` as `**` whatever the operands, so a correct hash-combine tag on whole numbers (`seed ^= s +
0x9e3779b9 + ...`) became a power no check finishes (the check hung): the proof's power is
``learner_source.guarded_power``, bound as a closure variable of the recompiled function (the learner's globals are
not touched), which refuses a power of whole numbers above 2^31; and with two uses of an in-place method's value the
report quoted the first (a harmless `note = log.append(...)`), while the None of the second made the failure: each
use is proven alone first, and the one whose rewrite matches is named. The reference runs once for both of the `^`
proof's calls.

Open, on purpose: gradients clipped before the step (step_clip_grad) pass: the exercise's optimiser is Adam, whose
step divides the gradient by its own running size, so one clipped step moves the parameters as far as an unclipped
one (within the tolerance); a probe with SGD would be a new case, and the notebooks quote the counts. A function that
draws from the global generator where its answer does not depend on the draw (pf_shuffled: a random permutation and
its inverse) passes: the answer is right, and the reseed check names only a generator left in a fixed state; a
notebook's later random numbers change, but no exercise asks for the generator's state. No probe for a result that
shares memory with an input (no reference returns a view of an input, and no wrong solution tried here did
without also changing the input in place, which is named already), nor for a tensor on another device (no
accelerator on the machines that run the checks).
"""
import inspect
import math

import numpy as np
import pytest
import torch

from evinr_lite.teaching import exercises
from exercise_reports import assert_fails_naming, assert_passes, case_ids as _id, report as _report, seeded_numpy


def R(n): return exercises.reference(n)


# ---- parameters in another order than the stub's, keyword-only, other defaults
def ie_reordered(t_events, p_events, t_query, C):
    return R("integrate_events_1d")(t_events, p_events, C, t_query)
def tm_reordered(gamma, L):
    return R("reinhard_tonemap")(L, gamma)
def esim_reordered(L_a, L_b, ref, C, t_a, t_b):
    return R("esim_interval")(L_a, L_b, t_a, t_b, ref, C)
def chain_reordered(nxt, prev):
    return R("chain_offsets")(prev, nxt)
def pf_reordered(quality, cost):
    return R("pareto_front")(cost, quality)
def sld_reordered(h, dh_dt, omega, weight, bias):
    return R("sine_layer_derivative")(h, dh_dt, weight, bias, omega)
def gef_reordered(x, y, p, raw_size, C):
    return R("grey_event_frame")(x, y, p, C, raw_size)
def er_reordered(bin_s, t):
    return R("event_rate")(t, bin_s)
def anchor_reordered(L, display_mean, gamma):
    return R("anchor")(L, gamma, display_mean)
def qb_x_first(x, y, phase):                                # x before y, by habit
    return R("quad_bayer_channel")(y, x, phase)
def afo_kwonly_eps(first_frame, L_t0, *, eps=1 / 255):      # notebook 09 leaves eps out: it works there
    return R("anchor_first_offset")(first_frame, L_t0, eps)
def hpm_factor_kwonly(x, y, sensor_size, *, factor=10.0):
    return R("hot_pixel_mask")(x, y, sensor_size, factor)
def hpm_default_changed(x, y, sensor_size, factor=5.0):    # notebook 11 always passes HOT_FACTOR
    return R("hot_pixel_mask")(x, y, sensor_size, factor)
def afo_default_1e6(first_frame, L_t0, eps=1e-6):
    return R("anchor_first_offset")(first_frame, L_t0, eps)
def afo_default_dropped(first_frame, L_t0, eps):
    return R("anchor_first_offset")(first_frame, L_t0, eps)


# ---- `^` for a power
def tl_xor(dF_dt, delta_L, durations):
    return torch.mean((delta_L - dF_dt * durations) ^ 2)
def tik_xor(dF_dx, dF_dy):
    return (dF_dx ^ 2).mean() + (dF_dy ^ 2).mean()
def tlb_xor(F_boundaries, event_frames):
    return torch.mean((event_frames - (F_boundaries[1:] - F_boundaries[:-1])) ^ 2)
def tm_xor(L, gamma):
    I = np.exp(np.asarray(L, float))
    return (I / (I + 1.0)) ^ gamma
def ect_xor(log_changes, net_counts):                       # net counts are integers: n ^ 2 is n XOR 2
    d = np.asarray(log_changes, float); n = np.asarray(net_counts)
    return float(np.sum(d * n) / np.sum(n ^ 2))


# ---- the value of a method that works in place and returns None
def ie_sort_returns_none(t_events, p_events, C, t_query):
    tq = np.array(t_query, float)
    tq = tq.sort()
    return R("integrate_events_1d")(t_events, p_events, C, tq)
def bis_sort_none(t_events, boundaries):
    b = list(boundaries)
    b = b.sort()
    return R("bisect_equal_count")(t_events, b)
def ie_return_sort(t_events, p_events, C, t_query):
    out = R("integrate_events_1d")(t_events, p_events, C, t_query)
    return out.sort()
def ii_sort_none(events):
    from evinr_lite.teaching.events2d import MIN_INTERVAL
    H, W = events.sensor_size
    pix = events.y.astype(np.int64) * W + events.x
    order = list(range(len(pix)))
    order = order.sort(key=pix.__getitem__)          # a stable sort by pixel, as np.argsort(pix, kind="stable")
    pix, t, p = pix[order], np.asarray(events.t, np.float64)[order], events.p[order]
    pair = (pix[1:] == pix[:-1]) & (p[1:] == p[:-1])
    log_dt = np.log(np.maximum(np.diff(t), MIN_INTERVAL)); on = p[1:] > 0
    if not (pair & on).any() or not (pair & ~on).any():
        return float("nan")
    return float(np.tanh((log_dt[pair & on].mean() - log_dt[pair & ~on].mean()) / 2))
def tfp_update_none(table):
    out = {}
    for name, row in table.items():
        out = out.update({name: row["time_s"] * row["fps"]})
    return out


# ---- left open (see the docstring)
def _step_parts(model, event_frames, centers, durations, lam):
    from evinr_lite.method.losses import temporal_loss_derivative, tikhonov
    F, dF_dt = model.forward_with_derivative(centers)
    temporal = temporal_loss_derivative(dF_dt, event_frames, durations); reg = tikhonov(F)
    return temporal + lam * reg, temporal, reg
def step_clip_grad(model, optimizer, event_frames, centers, durations, lam):
    loss, temporal, reg = _step_parts(model, event_frames, centers, durations, lam)
    optimizer.zero_grad(); loss.backward()
    torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
    optimizer.step()
    return loss.detach(), temporal.detach(), reg.detach()
def pf_shuffled(cost, quality):                             # the global generator, drawn for nothing
    c = np.asarray(cost, float); q = np.asarray(quality, float); o = np.random.permutation(c.size)
    m = R("pareto_front")(c[o], q[o]); out = np.empty_like(m); out[o] = m
    return out


# ---- correct alternatives
def hpm_extra_kw(x, y, sensor_size, factor=10.0, verbose=False):
    return R("hot_pixel_mask")(x, y, sensor_size, factor)
def tm_star_args(*args, **kwargs):
    return R("reinhard_tonemap")(*args, **kwargs)
def afo_default_expr(first_frame, L_t0, eps=1 / 255):
    return R("anchor_first_offset")(first_frame, L_t0, eps)
def afo_eps_none(first_frame, L_t0, eps=None):
    return R("anchor_first_offset")(first_frame, L_t0, 1 / 255 if eps is None else eps)
def hpm_int_default(x, y, sensor_size, factor=10):
    return R("hot_pixel_mask")(x, y, sensor_size, factor)
def step_model_zero_grad(model, optimizer, event_frames, centers, durations, lam):
    loss, temporal, reg = _step_parts(model, event_frames, centers, durations, lam)
    model.zero_grad(); loss.backward(); optimizer.step()
    return loss.detach(), temporal.detach(), reg.detach()
def pf_xor_true(cost, quality):                             # `^ True` on a bool mask: bits, not a power
    c = np.asarray(cost, float)[:, None]; q = np.asarray(quality, float)[:, None]
    return ((c.T <= c) & (q.T >= q) & ((c.T < c) | (q.T > q))).any(axis=1) ^ True
def bis_sort_in_place(t_events, boundaries):                # sorted in place on a line of its own
    b = np.array(boundaries, float)
    b.sort()
    return R("bisect_equal_count")(t_events, b)
def tl_square(dF_dt, delta_L, durations):
    return torch.mean(torch.square(delta_L - dF_dt * durations))
def pf_shuffled_own_rng(cost, quality):
    c = np.asarray(cost, float); q = np.asarray(quality, float); o = np.random.default_rng(0).permutation(c.size)
    m = R("pareto_front")(c[o], q[o]); out = np.empty_like(m); out[o] = m
    return out
def ecw_math_ceil(n_events, max_events):
    w = max(1, math.ceil(n_events / max_events))
    return np.array([k * n_events // w for k in range(w + 1)], dtype=np.int64)


IN_ORDER = "is passed as the notebook passes it (its values)"
HOLES = [
    ("integrate_events_1d", ie_reordered, IN_ORDER),
    ("reinhard_tonemap", tm_reordered, IN_ORDER),
    ("esim_interval", esim_reordered, IN_ORDER),
    ("chain_offsets", chain_reordered, IN_ORDER),
    ("pareto_front", pf_reordered, IN_ORDER),
    ("sine_layer_derivative", sld_reordered, IN_ORDER),
    ("grey_event_frame", gef_reordered, IN_ORDER),
    ("event_rate", er_reordered, IN_ORDER),
    ("anchor", anchor_reordered, IN_ORDER),
    ("quad_bayer_channel", qb_x_first, "your parameters are (x, y, phase), the stub's (y, x, phase)"),
    ("hot_pixel_mask", hpm_factor_kwonly,
     "calls it as `hot_mask(rec.events.x, rec.events.y, (H, W), HOT_FACTOR)` (x, y, sensor_size, factor by position)"),
]

XOR = "`^` is exclusive or (of the bits) in Python, not a power"
NONE = "changes its object in place and returns None"
NAMED = [
    ("temporal_loss", tl_xor, XOR),
    ("tikhonov_autograd", tik_xor, XOR),
    ("temporal_loss_boundary", tlb_xor, XOR),
    ("reinhard_tonemap", tm_xor, XOR),
    ("estimate_contrast_threshold", ect_xor, XOR),
    ("integrate_events_1d", ie_sort_returns_none, "`tq = tq.sort()`: `.sort(...)` " + NONE),
    ("bisect_equal_count", bis_sort_none, "`b = b.sort()`"),
    ("integrate_events_1d", ie_return_sort, "so the function returns None"),
    ("interval_imbalance", ii_sort_none, "`order = order.sort(key=pix.__getitem__)`"),
    ("time_fps_products", tfp_update_none, "`.update(...)` " + NONE),
    ("anchor_first_offset", afo_default_1e6, "so your default `eps=1e-06` is used; with the stub's"),
    ("anchor_first_offset", afo_default_dropped, "your function has no default for it"),
]

OPEN = [("frame_train_step", step_clip_grad), ("pareto_front", pf_shuffled)]

CORRECT = [
    ("hot_pixel_mask", hpm_extra_kw), ("reinhard_tonemap", tm_star_args), ("anchor_first_offset", afo_default_expr),
    ("anchor_first_offset", afo_eps_none), ("hot_pixel_mask", hpm_int_default),
    ("frame_train_step", step_model_zero_grad), ("pareto_front", pf_xor_true),
    ("bisect_equal_count", bis_sort_in_place), ("temporal_loss", tl_square), ("pareto_front", pf_shuffled_own_rng),
    ("event_count_windows", ecw_math_ceil),
    ("anchor_first_offset", afo_kwonly_eps), ("hot_pixel_mask", hpm_default_changed),    # moved here by the review
]


@pytest.fixture(autouse=True)
def _fresh():
    with seeded_numpy():
        yield


@pytest.mark.parametrize("name, wrong, words", HOLES, ids=_id(HOLES))
def test_hole_now_fails_and_names_the_mistake(name, wrong, words):
    assert_fails_naming(name, wrong, words)


@pytest.mark.parametrize("name, wrong, words", NAMED, ids=_id(NAMED))
def test_wrong_solution_fails_and_names_the_mistake(name, wrong, words):
    assert_fails_naming(name, wrong, words)


@pytest.mark.parametrize("name, fn", CORRECT, ids=_id(CORRECT))
def test_correct_alternatives_pass(name, fn):
    assert_passes(name, fn)


@pytest.mark.parametrize("name, fn", OPEN, ids=_id(OPEN))
def test_holes_left_open_on_purpose_still_pass(name, fn):
    """Documented in the module docstring: closing one of these is a decision, to be recorded there."""
    assert_passes(name, fn)


def test_this_round_counts():
    wrong = HOLES + NAMED + OPEN
    assert (len(HOLES), len(NAMED), len(OPEN), len(CORRECT)) == (11, 12, 2, 13)
    assert len({r[0] for r in wrong}) == 20
    assert len({r[0] for r in CORRECT}) == 8


def test_the_notebooks_own_cases_are_unchanged():
    """No case was changed this round: the holes were closed in checking/, so the counts the notebooks quote stand."""
    from exercise_reports import quoted_counts
    for name, n in quoted_counts().items():
        assert len(exercises.get(name).cases()) == n, name


def test_torch_s_not_implemented_is_no_unfinished_stub():
    """torch raises NotImplementedError for an operation it has no kernel for; the stub's own still reads "not done"."""
    ok, text = _report("temporal_loss", tl_xor)
    assert not ok and "not done yet" not in text and "raised NotImplementedError" in text, text

    def stub(dF_dt, delta_L, durations):
        raise NotImplementedError

    def helper():
        raise NotImplementedError("write me")

    def calls_a_stub(dF_dt, delta_L, durations):
        return helper()
    for fn in (stub, calls_a_stub):
        ok, text = _report("temporal_loss", fn)
        assert not ok and "not done yet" in text, text


def test_source_hints_do_not_blame_module_functions_or_bits():
    """np.sort and torch.sort return values; `^` on bools, or with no number beside it, is left alone; a function
    without source (a builtin) gets no hint."""
    from evinr_lite.teaching.checking.learner_source import none_from_in_place_hint, xor_power_hint

    def module_sorts(a, t):
        a = np.sort(a)
        v, i = t.sort()
        t2 = torch.sort(t)
        return a, v, i, t2

    def bits(m, n):
        return (m ^ True) ^ n
    assert none_from_in_place_hint(module_sorts) is None and xor_power_hint(bits) is None
    assert none_from_in_place_hint(len) is None and xor_power_hint(len) is None

    def shuffled(b):
        b = np.random.shuffle(b)
        return b
    from types import SimpleNamespace
    same_values = SimpleNamespace(reference=lambda b: b, observe=None, rtol=0, atol=0,
                                  compare=lambda g, e: None if np.array_equal(np.sort(g), np.sort(e)) else "differs")
    assert "`b = np.random.shuffle(b)`" in none_from_in_place_hint(shuffled, same_values, ((np.arange(3.0),), {}))


def test_an_unchanged_signature_costs_no_call():
    """Where the function's signature is the reference's, called_as_notebook calls nothing."""
    from evinr_lite.teaching.checking.signature import called_as_notebook
    calls = []

    def hot_pixel_mask(x, y, sensor_size, factor: float = 10.0):
        calls.append(1)
        return R("hot_pixel_mask")(x, y, sensor_size, factor)
    ex = exercises.get("hot_pixel_mask")
    assert called_as_notebook(ex, hot_pixel_mask, ex.cases()) is None and not calls


# ---- review: each failed before the review's fixes
def _no_final_decay(*a, **k):
    from evinr_lite.teaching.discussion_exercises import _no_final_decay as wrong
    return wrong(*a, **k)
def hp_none_no_decay(t, x, y, p, sensor_size, C, alpha, t_end, t_start=None):    # None resolved + another bug
    return _no_final_decay(t, x, y, p, sensor_size, C, alpha, t_end, 0.0 if t_start is None else t_start)
def hp_int_no_decay(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0):
    return _no_final_decay(t, x, y, p, sensor_size, C, alpha, t_end, t_start)
def afo_none_divides(first_frame, L_t0, eps=None):
    eps = 1 / 255 if eps is None else eps
    return np.log(np.asarray(first_frame, np.float64) / 255.0 + eps) - np.asarray(L_t0, np.float64)
def afo_none_if_array(first_frame, L_t0, eps=None):
    eps = 1 / 255 if eps is None else eps
    a = np.asarray(first_frame)
    if a > 1:
        a = a / 255.0
    return np.log(a + eps) - L_t0
def tl_torch_sort(dF_dt, delta_L, durations):                  # Tensor.sort() returns (values, indices)
    s = (delta_L - dF_dt * durations).flatten().sort()
    return torch.mean(s.values ** 2) * 2
def pf_xor_bits_reversed(cost, quality):                       # a correct `^ 1` on 0/1 ints, and the order reversed
    c = np.asarray(cost, float)[:, None]; q = np.asarray(quality, float)[:, None]
    dominated = ((c.T <= c) & (q.T >= q) & ((c.T < c) | (q.T > q))).any(axis=1).astype(int)
    return (dominated ^ 1).astype(bool)[::-1]
def tl_raised_name(dF_dt, delta_L, durations):                 # the word `raise` on a line that raises no stub
    raised = (delta_L - dF_dt * durations) ^ 2
    return torch.mean(raised)
class _Squared(torch.nn.Module):
    def foward(self, x):                                       # misspelt: torch's Module raises NotImplementedError
        return x ** 2
def tl_module_foward(dF_dt, delta_L, durations):
    return torch.mean(_Squared()(delta_L - dF_dt * durations))
def _keyword_only(f):
    import functools

    @functools.wraps(f)
    def wrapper(**kw):
        return f(**kw)
    return wrapper
@_keyword_only
def tm_wrapped_keyword_only(L, gamma):
    return R("reinhard_tonemap")(L, gamma)
def hpm_positional_only(x, y, sensor_size, /, factor=10.0):
    return R("hot_pixel_mask")(x, y, sensor_size, factor)
def tm_renamed(L, g):
    return R("reinhard_tonemap")(L, g)
def afo_renamed_none(frame, L_t0, eps=None):
    return R("anchor_first_offset")(frame, L_t0, 1 / 255 if eps is None else eps)
def hp_t_end_keyword_only(t, x, y, p, sensor_size, C, alpha, *, t_end, t_start=0.0):
    return R("highpass_per_event")(t, x, y, p, sensor_size, C, alpha, t_end, t_start)


DEFAULT = "your default"
REVIEW_NAMED = [         # another mistake beside a default written otherwise: that mistake's hint, not the default's
    ("highpass_per_event", hp_none_no_decay, "decay every pixel to t_end"),
    ("highpass_per_event", hp_int_no_decay, "decay every pixel to t_end"),
    ("anchor_first_offset", afo_none_divides, "divide by 255 only a uint8 frame"),
    ("anchor_first_offset", afo_none_if_array, "each need one True or False"),
    ("temporal_loss", tl_raised_name, XOR),
    ("temporal_loss", tl_module_foward, 'missing the required "forward" function'),
    ("reinhard_tonemap", tm_wrapped_keyword_only, "your parameters are (**kw), the stub's (L, gamma)"),
    # a parameter renamed stays a mistake (round 2's class: the stub's names are the exercise's contract), though
    # the notebook's positional call would take it
    ("reinhard_tonemap", tm_renamed, "keep the stub's parameter names"),
    ("anchor_first_offset", afo_renamed_none, "keep the stub's parameter names"),
]
REVIEW_NOT_BLAMED = [    # (exercise, function, words the report must not hold)
    ("highpass_per_event", hp_none_no_decay, DEFAULT), ("highpass_per_event", hp_int_no_decay, DEFAULT),
    ("anchor_first_offset", afo_none_divides, DEFAULT), ("anchor_first_offset", afo_none_if_array, DEFAULT),
    ("temporal_loss", tl_torch_sort, NONE), ("pareto_front", pf_xor_bits_reversed, XOR),
    ("temporal_loss", tl_raised_name, "not done yet"), ("temporal_loss", tl_module_foward, "not done yet"),
]
REVIEW_CORRECT = [       # the notebooks' calls work: positional-only, keyword-only where passed by name
    ("hot_pixel_mask", hpm_positional_only), ("highpass_per_event", hp_t_end_keyword_only),
]


@pytest.mark.parametrize("name, wrong, words", REVIEW_NAMED, ids=_id(REVIEW_NAMED))
def test_review_the_other_mistake_is_named(name, wrong, words):
    assert_fails_naming(name, wrong, words)


@pytest.mark.parametrize("name, wrong, words", REVIEW_NOT_BLAMED, ids=_id(REVIEW_NOT_BLAMED))
def test_review_an_unproven_slip_is_not_named(name, wrong, words):
    ok, text = _report(name, wrong)
    assert not ok and words not in text, text


@pytest.mark.parametrize("name, fn", REVIEW_CORRECT, ids=_id(REVIEW_CORRECT))
def test_review_what_works_in_the_notebook_passes(name, fn):
    assert_passes(name, fn)


def test_review_counts():
    assert (len(REVIEW_NAMED), len(REVIEW_NOT_BLAMED), len(REVIEW_CORRECT)) == (9, 8, 2)


def test_review_a_stub_raise_over_several_lines_is_still_not_done():
    ns = {}
    exec(compile("def stub(dF_dt, delta_L, durations):\n    raise NotImplementedError(\n        'write me'\n    )\n",
                 "<cell>", "exec"), ns)
    ok, text = _report("temporal_loss", ns["stub"])
    assert not ok and "not done yet" in text, text


def test_review_the_positional_only_hint_names_the_slash():
    """An exercise with no recorded notebook call passes its inputs by name: `/` is named, not the names."""
    exercises.register("_toy_posonly", lambda a, b: a + b, lambda rng: [{"a": 1.0, "b": 2.0}])
    try:
        def f(a, b, /):
            return a + b
        ok, text = _report("_toy_posonly", f)
    finally:
        exercises.unregister("_toy_posonly")
    assert not ok and "remove the `/`" in text and "parameter names and order" not in text, text


def test_review_the_recorded_notebook_calls_are_the_notebooks():
    """teaching/notebook_calls.py holds each exercise's first call in the notebooks (after `x = exercises.use(...)`),
    and every later call of the same function has its form: as many arguments by position, the same ones by name
    (the final review: each call, not only the first). A call that unpacks a tuple (`chain(*pairs)`) cannot say
    how many arguments it passes: its keywords are checked, and the recorded count must fill the stub's parameters
    without a default."""
    import ast
    import inspect as _inspect
    import json
    from exercise_reports import ROOT
    from evinr_lite.teaching.notebook_calls import NOTEBOOK_CALLS
    found: dict = {}
    for path in sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb")):
        aliases = {}
        for i, cell in enumerate(json.loads(path.read_text())["cells"]):
            if cell["cell_type"] != "code":
                continue
            tree = ast.parse("\n".join(line for line in "".join(cell["source"]).splitlines()
                                       if not line.lstrip().startswith(("%", "!"))))
            for node in ast.walk(tree):
                if isinstance(node, ast.Assign) and isinstance(node.value, ast.Call) \
                        and getattr(node.value.func, "attr", None) == "use":
                    aliases.update({t.id: node.value.args[0].value for t in node.targets})
            for node in ast.walk(tree):
                if isinstance(node, ast.Call) and getattr(node.func, "id", None) in aliases:
                    star = any(isinstance(a, ast.Starred) for a in node.args)
                    found.setdefault(aliases[node.func.id], []).append(
                        (path.stem, i + 1, None if star else len(node.args), tuple(k.arg for k in node.keywords),
                         ast.unparse(node)))
    assert set(found) == set(NOTEBOOK_CALLS) and set(NOTEBOOK_CALLS) <= set(exercises.names())
    assert sum(len(c) for c in found.values()) > len(found)          # later calls are seen too
    for name, calls in found.items():
        call = NOTEBOOK_CALLS[name]
        nb, cell, _, _, text = calls[0]
        assert (call.notebook, call.cell, call.text) == (nb, cell, text), name
        assert exercises.get(name).call is call
        required = [p for p in _inspect.signature(exercises.reference(name)).parameters.values()
                    if p.default is _inspect.Parameter.empty and p.kind is not p.KEYWORD_ONLY]
        for nb, cell, positional, keywords, text in calls:
            assert keywords == call.keywords, (name, nb, cell, text)
            if positional is None:          # `*` unpacks a tuple whose length the notebook's text does not show
                assert call.positional >= len(required), (name, nb, cell, text)
            else:
                assert positional == call.positional, (name, nb, cell, text)


# ---- final review: each failed before the final review's fixes
class _Unloaded:
    @property
    def data(self):
        raise RuntimeError("not loaded")
unloaded = _Unloaded()
def tm_property_raises(L, gamma):                              # a global whose property raises, read by the hint
    x = unloaded.data.sort()
    return R("reinhard_tonemap")(L, gamma)


def test_final_a_property_that_raises_does_not_crash_the_check():
    ok, text = _report("reinhard_tonemap", tm_property_raises)
    assert not ok and "the check itself failed" not in text and "RuntimeError: not loaded" in text, text


def test_final_a_hint_that_raises_does_not_crash_the_check(monkeypatch):
    from evinr_lite.teaching.checking import run_check as rc

    def boom(*a, **k):
        raise ValueError("hint broke")
    for name in ("xor_power_hint", "signature_default_hint", "none_from_in_place_hint"):
        monkeypatch.setattr(rc, name, boom)
    for exercise, fn in (("reinhard_tonemap", tm_xor), ("bisect_equal_count", bis_sort_none),
                         ("estimate_contrast_threshold", ect_xor)):
        ok, text = _report(exercise, fn)
        assert not ok and "the check itself failed" not in text, text


def test_final_learner_source_and_signature_are_a_layer_and_share_learner_function():
    from exercise_reports import ROOT
    from evinr_lite.teaching.checking import learner_calls, learner_source, signature
    assert '"learner_source | signature",' in (ROOT / "pyproject.toml").read_text()
    assert "_learner_function" not in inspect.getsource(learner_source)
    assert signature.learner_function is learner_calls.learner_function


def _weights_forget_return(durations):
    w = durations / durations.sum()                            # forgot `return w`
def tl_sort_and_helper_none(dF_dt, delta_L, durations):        # a correct torch sort, and a helper returning None
    s = (delta_L - dF_dt * durations).flatten().sort()
    return torch.mean(s.values ** 2 * _weights_forget_return(durations))
def tl_sort_init_none(dF_dt, delta_L, durations):              # None held before a correct torch sort; the mistake: * 2
    s = None
    s = (delta_L - dF_dt * durations).flatten().sort()
    return torch.mean(s.values ** 2) * 2
_HPM_CACHE = {}
def hpm_cache_positional_only(x, y, sensor_size, /, factor=10.0):
    key = tuple(sensor_size)
    if key not in _HPM_CACHE:
        _HPM_CACHE[key] = R("hot_pixel_mask")(x, y, sensor_size, factor)
    return _HPM_CACHE[key]
def hpm_empty_positional_only(x, y, sensor_size, /, factor=10.0):
    H, W = sensor_size
    counts = np.empty((H, W))
    np.add.at(counts, (np.asarray(y), np.asarray(x)), 1)
    return counts > factor * np.median(counts[counts > 0])
def ect_xor_positional_only(log_changes, net_counts, /):
    d = np.asarray(log_changes, float); n = np.asarray(net_counts)
    return float(np.sum(d * n) / np.sum(n ^ 2))
@torch.no_grad()
def ect_xor_no_grad(log_changes, net_counts):                  # a decorator whose wrapper lives in torch
    d = np.asarray(log_changes, float); n = np.asarray(net_counts)
    return float(np.sum(d * n) / np.sum(n ^ 2))
def ecw_parity_flip(n_events, max_events):                     # `^ 1` flips a bit: x ** 1 == x proves nothing
    w = max(1, math.ceil(n_events / max_events))
    idx = (np.arange(w + 1, dtype=np.int64) * n_events) // w
    return idx ^ 1 if n_events > 100 else idx


FINAL_NAMED = [          # the learner's own code read behind the notebook-call wrapper and behind a decorator
    ("temporal_loss", tl_sort_init_none, "off by a constant factor"),
    ("hot_pixel_mask", hpm_cache_positional_only, "notebook variable `_HPM_CACHE`"),
    ("hot_pixel_mask", hpm_empty_positional_only, "starts an array with np.empty"),
    ("estimate_contrast_threshold", ect_xor_positional_only, XOR),
    ("estimate_contrast_threshold", ect_xor_no_grad, XOR),
]
FINAL_NOT_BLAMED = [     # the None of an in-place method, or `^`, named without proof
    ("temporal_loss", tl_sort_and_helper_none, NONE), ("temporal_loss", tl_sort_init_none, NONE),
    ("event_count_windows", ecw_parity_flip, XOR),
]


@pytest.mark.parametrize("name, wrong, words", FINAL_NAMED, ids=_id(FINAL_NAMED))
def test_final_the_mistake_is_named(name, wrong, words):
    _HPM_CACHE.clear()
    assert_fails_naming(name, wrong, words)


@pytest.mark.parametrize("name, wrong, words", FINAL_NOT_BLAMED, ids=_id(FINAL_NOT_BLAMED))
def test_final_an_unproven_slip_is_not_named(name, wrong, words):
    ok, text = _report(name, wrong)
    assert not ok and words not in text, text


def test_final_counts():
    assert (len(FINAL_NAMED), len(FINAL_NOT_BLAMED)) == (5, 3)


# ---- the session's last review -------------------------------------------------------------------------------
# Each test failed before its fix (the code after the final review's fixes).

_NOTES = []


def tm_hash_tag(L, gamma):          # a correct `^=` on whole numbers (a hash-combine tag), and a wrong exponent
    seed = 17
    for s in np.shape(L):
        seed ^= s + 0x9e3779b9 + (seed << 6) + (seed >> 2)
    I = np.exp(np.asarray(L, float))
    return (I / (I + 1.0)) ** (gamma * 1.01)


def bis_note_then_sort(t_events, boundaries):
    note = _NOTES.append(len(boundaries))       # harmless: `note` is never used  # noqa: F841
    b = list(boundaries)
    b = b.sort()
    return R("bisect_equal_count")(t_events, b)


def test_last_a_hash_tag_on_whole_numbers_does_not_hang_the_power_proof():
    """The `^` proof ran `seed ** (s + 0x9e3779b9 + ...)`, a power of whole numbers no check finishes: the proof's
    power refuses one of more than 2^31 (``learner_source.guarded_power``), and the wrong exponent is named."""
    import time

    start = time.perf_counter()
    ok, text = _report("reinhard_tonemap", tm_hash_tag)
    assert not ok and XOR not in text and "wrong value" in text, text
    assert time.perf_counter() - start < 30


def test_last_the_in_place_use_named_is_the_one_whose_none_made_the_failure():
    """Two uses of an in-place method's value: the harmless `note = _NOTES.append(...)` came first and was quoted;
    each use is now proven alone, and `b = b.sort()` is named."""
    ok, text = _report("bisect_equal_count", bis_note_then_sort)
    assert not ok and "`b = b.sort()`" in text and "note = " not in text, text


def test_last_the_guarded_power_is_a_power_where_it_is_small():
    from evinr_lite.teaching.checking.learner_source import guarded_power

    assert guarded_power(3, 4) == 81 and guarded_power(2.0, 0.5) == 2.0 ** 0.5 and guarded_power(2, -1) == 0.5
    assert np.array_equal(guarded_power(np.arange(4), 2), np.arange(4) ** 2)
    with pytest.raises(OverflowError):
        guarded_power(17, 0x9e3779b9)
    with pytest.raises(OverflowError):
        guarded_power(np.int64(1 << 20), 2)
