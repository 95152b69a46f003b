"""Exercise checks, round 2: whole classes of wrong solutions that the first tests did not feed them.

Each wrong solution below is a plausible learner's mistake (an input changed in place, a loss cut off from
the autograd graph, a list or a tensor where a numpy array belongs, events outside every window, query times
out of order, ties on a bin edge, (H, W) unpacked as (W, H), a symmetric time window, ...): the check fails it
and its report names the problem. The correct alternatives (float32 arithmetic, a copy, a different algorithm)
pass, and garbage (None, a string, NaN, an exception, an object) fails every check without a traceback.
"""
import contextlib
import copy
import inspect
import io
import math
import warnings

import numpy as np
import pytest
import torch

from evinr_lite.evaluation.ablation import pareto_front
from evinr_lite.teaching import accel_exercises as ae
from evinr_lite.teaching import aed_exercises as aed
from evinr_lite.teaching import exercises
from evinr_lite.teaching import frame_exercises as fe
from evinr_lite.teaching import pde1d, poisson_exercises as pe, realdata_exercises as rd
from evinr_lite.teaching import recording_exercises as rec
from evinr_lite.teaching import training_exercises as te
from evinr_lite.teaching.checking import learner_calls
from evinr_lite.method.coordinate import split_index
from evinr_lite.method.baselines import highpass_per_event


def _report(name, fn):
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ok = exercises.check(name, fn)
    return ok, buf.getvalue()


# ---- inputs changed in place -----------------------------------------------------------------------

def _anchor_in_place(L, gamma, display_mean):
    L = np.asarray(L, dtype=np.float64)          # no copy: L is the caller's float64 array
    s = display_mean ** (1.0 / gamma)
    L += np.log(s / (1.0 - s)) - L.mean()
    return L


def _tonemap_in_place(L, gamma):
    L = np.asarray(L, dtype=np.float64)
    np.exp(L, out=L)
    L /= L + 1.0
    L **= gamma
    return L


def _offset_in_place(first_frame, L_t0, eps=rd.FRAME_EPS):
    L_t0 *= -1
    L_t0 += np.log((first_frame / 255.0 if first_frame.dtype == np.uint8 else first_frame) + eps)
    return L_t0


def _frames_mutating_events(events, boundaries, C):
    out = exercises.reference("events_to_frames_fixed")(events, boundaries, C)
    events.p[:] = np.abs(events.p)               # leaves the caller's events all ON
    return out


def _sorts_queries(t_events, p_events, C, t_query):
    out = pde1d.integrate_events_1d(t_events, p_events, C, t_query)
    t_query.sort()
    return out


def _hot_zeroes_x(x, y, sensor_size, factor=10.0):
    mask = rec.hot_pixel_mask(x, y, sensor_size, factor)
    x[:] = 0
    return mask


IN_PLACE = [
    ("anchor", _anchor_in_place, "`L` in place"),
    ("reinhard_tonemap", _tonemap_in_place, "`L` in place"),
    ("anchor_first_offset", _offset_in_place, "`L_t0` in place"),
    ("events_to_frames_fixed", _frames_mutating_events, "`events.p` in place"),
    ("integrate_events_1d", _sorts_queries, "`t_query` in place"),
    ("hot_pixel_mask", _hot_zeroes_x, "`x` in place"),
]


@pytest.mark.parametrize("name, wrong, words", IN_PLACE, ids=[f"{n}-{w.__name__}" for n, w, _ in IN_PLACE])
def test_an_input_changed_in_place_fails_even_with_the_right_values(name, wrong, words):
    ok, out = _report(name, wrong)
    assert ok is False, out
    assert words in out and "copy" in out, out


def test_a_copy_then_in_place_arithmetic_passes():
    def on_a_copy(L, gamma, display_mean):
        L = np.array(L, dtype=np.float64)                  # a copy: += on it is fine
        s = display_mean ** (1.0 / gamma)
        L += np.log(s / (1.0 - s)) - L.mean()
        return L
    assert _report("anchor", on_a_copy)[0]


# ---- losses cut off from the autograd graph -------------------------------------------------------

DETACHED = [
    ("temporal_loss", lambda dF_dt, delta_L, durations:
        torch.tensor(float(torch.mean((delta_L - dF_dt * durations) ** 2)))),
    ("tikhonov_autograd", lambda dF_dx, dF_dy: torch.tensor(float(torch.mean(dF_dx ** 2 + dF_dy ** 2)))),
    ("temporal_loss_boundary", lambda F_boundaries, event_frames:
        torch.as_tensor(fe.temporal_loss_boundary(F_boundaries, event_frames).item())),
    ("total_variation", lambda F: fe.total_variation(F).detach()),
]


@pytest.mark.parametrize("name, wrong", DETACHED, ids=[n for n, _ in DETACHED])
def test_a_loss_cut_off_from_the_graph_fails(name, wrong):
    ok, out = _report(name, wrong)
    assert ok is False and "autograd graph" in out, out


# ---- the wrong container: a list where a numpy array belongs, a tensor for an array, numpy for a tensor --

CONTAINERS = [
    ("integrate_events_1d", lambda t_events, p_events, C, t_query:
        pde1d.integrate_events_1d(t_events, p_events, C, t_query).tolist(), "expected a numpy array"),
    ("pareto_front", lambda cost, quality: list(pareto_front(cost, quality)), "expected a numpy array"),
    ("crossfade_weights", lambda windows, times: torch.as_tensor(ae.crossfade_weights(windows, times)),
     "expected a numpy array"),
    ("esim_interval", lambda L_a, L_b, t_a, t_b, ref, C: (
        lambda times, p, r: (list(times), p, r))(*exercises.reference("esim_interval")(L_a, L_b, t_a, t_b, ref, C)),
     "expected a numpy array"),
    ("event_count_windows", lambda n_events, max_events: rec.event_count_windows(n_events, max_events).tolist(),
     "expected a numpy array"),
    ("split_index", lambda index, sensor_size: tuple(v.numpy() for v in split_index(index, sensor_size)),
     "expected a torch.Tensor like the input"),
]


@pytest.mark.parametrize("name, wrong, words", CONTAINERS, ids=[n for n, _, _ in CONTAINERS])
def test_the_wrong_container_is_named(name, wrong, words):
    ok, out = _report(name, wrong)
    assert ok is False and words in out, out


# ---- mistakes the check cases now sit on ---------------------------------------------------------

def _sweep_assumes_sorted_queries(t_events, p_events, C, t_query):
    out, j, acc = [], 0, 0.0
    for q in t_query:
        while j < len(t_events) and t_events[j] <= q:
            acc += p_events[j]
            j += 1
        out.append(C * acc)
    return np.array(out)


def _rate_clips_outside_events(t_events, p_events, C, boundaries):
    b = np.asarray(boundaries, dtype=np.float64)
    i = np.clip(np.searchsorted(b, t_events, side="left") - 1, 0, len(b) - 2)
    return C * np.bincount(i, weights=np.asarray(p_events, float), minlength=len(b) - 1) / np.diff(b)


def _rate_without_minlength(t_events, p_events, C, boundaries):
    b = np.asarray(boundaries, dtype=np.float64)
    i = np.searchsorted(b, t_events, side="left") - 1
    keep = (i >= 0) & (i < len(b) - 1)
    sums = np.bincount(i[keep], weights=np.asarray(p_events, float)[keep])
    return C * sums / np.diff(b)[:len(sums)]


def _bisect_keeps_a_cut_on_the_edge(t_events, boundaries):
    t, b = np.asarray(t_events, dtype=np.float64), np.asarray(boundaries, dtype=np.float64)
    out = np.empty(2 * len(b) - 1)
    out[0::2] = b
    for i, (lo, hi) in enumerate(zip(b[:-1], b[1:])):
        in_bin = t[((t > lo) | ((i == 0) & (t == lo))) & (t <= hi)]
        n = len(in_bin)
        out[2 * i + 1] = 0.5 * (in_bin[n // 2 - 1] + in_bin[n // 2]) if n >= 2 else 0.5 * (lo + hi)
    return out


def _contrast_on_magnitudes(log_changes, net_counts):
    d, n = np.abs(np.asarray(log_changes, float)), np.abs(np.asarray(net_counts, float))
    return float(np.sum(d * n) / np.sum(n * n))


def _filter_symmetric_window(t, x, y, dt):
    t = np.asarray(t, np.float64)
    x, y = np.asarray(x, np.int64), np.asarray(y, np.int64)
    cheb = np.maximum(np.abs(x[:, None] - x[None, :]), np.abs(y[:, None] - y[None, :]))
    return np.any((cheb == 1) & (np.abs(t[:, None] - t[None, :]) <= dt), axis=1)


def _split_w_first(index, sensor_size):
    W, H = sensor_size
    return index // (H * W), (index // W) % H, index % W


def _grey_indexed_x_y(x, y, p, C, raw_size):
    H, W = raw_size
    frame = np.zeros((H // 4, W // 4))
    np.add.at(frame, (np.asarray(x) // 4, np.asarray(y) // 4), C * np.asarray(p, float) / 16)
    return frame


WRONG = [
    ("integrate_events_1d", _sweep_assumes_sorted_queries, "does not match"),
    ("event_rate_derivative", _rate_clips_outside_events, "does not match"),
    ("event_rate_derivative", _rate_without_minlength, "wrong shape"),
    ("event_rate_derivative", lambda t_events, p_events, C, boundaries:
        pde1d.window_sums(t_events, p_events, C, boundaries) / np.diff(boundaries).mean(), "its own length"),
    ("bisect_equal_count", _bisect_keeps_a_cut_on_the_edge, "does not match"),
    ("estimate_contrast_threshold", _contrast_on_magnitudes, "wrong value"),
    ("background_activity_filter", _filter_symmetric_window, "only earlier neighbours count"),
    ("split_index", _split_w_first, "H, W = sensor_size"),
    ("hot_pixel_mask", lambda x, y, sensor_size, factor=10.0: rec.hot_pixel_mask(x, y, sensor_size),
     "use the `factor` argument"),
    ("highpass_per_event", lambda t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0:
        highpass_per_event(t, x, y, p, sensor_size, C, alpha, t_end, t_start).T, "indexed [y, x]"),
    ("grey_event_frame", _grey_indexed_x_y, "rows are y"),
    ("events_to_frames_fixed", lambda events, boundaries, C:
        exercises.reference("events_to_frames_fixed")(events, boundaries, C).transpose(0, 2, 1), "indexed [y, x]"),
    ("sine_layer_derivative", lambda h, dh_dt, weight, bias, omega:
        fe.sine_layer_derivative(h, dh_dt, weight, bias, omega)[::-1], "two outputs are swapped"),
    ("esim_interval", lambda L_a, L_b, t_a, t_b, ref, C: (
        lambda times, p, r: (times, -p, r))(*exercises.reference("esim_interval")(L_a, L_b, t_a, t_b, ref, C)),
     "sign is flipped"),
    ("esim_interval", lambda L_a, L_b, t_a, t_b, ref, C: (
        lambda times, p, r: (times, p, float(L_b)))(*exercises.reference("esim_interval")(L_a, L_b, t_a, t_b, ref, C)),
     "not to L_b"),
    ("integrate_events_1d", lambda t, p, C, tq: pde1d.integrate_events_1d(t, p, C, tq), "parameter names"),
]


@pytest.mark.parametrize("name, wrong, words", WRONG, ids=[f"{n}-{k}" for k, (n, _, _) in enumerate(WRONG)])
def test_wrong_solution_fails_and_names_the_problem(name, wrong, words):
    ok, out = _report(name, wrong)
    assert ok is False, out
    assert words in out, out


# ---- hints that must not name another mistake -------------------------------------------------------

def test_a_hint_is_confirmed_on_the_other_inputs():
    """Ignoring `factor` looks like the mean rule on the first input alone; the other inputs tell them apart."""
    ok, out = _report("hot_pixel_mask", lambda x, y, sensor_size, factor=10.0: rec.hot_pixel_mask(x, y, sensor_size))
    assert not ok and "not the mean" not in out and "`factor`" in out, out


@pytest.mark.parametrize("name, wrong, not_words", [
    # a single number is always "some factor" of another, and a 3-entry mask is not a shifted series
    ("temporal_loss", lambda dF_dt, delta_L, durations: torch.mean((delta_L / durations - dF_dt) ** 2),
     "constant factor"),
    ("pareto_front", lambda cost, quality: pareto_front(cost, -np.asarray(quality, float)), "shifted by one"),
    # one grey pixel with one value is not "one contribution per entry" of a fancy-index `+=`
    ("grey_event_frame", lambda x, y, p, C, raw_size: aed.grey_event_frame(x, y, np.clip(p, 0, 1), C, raw_size),
     "np.add.at"),
    # float32 differences are not "the wrong image axis"
    ("offset_gradients", lambda frames: tuple(g.astype(np.float32) + np.float32(1e-3)
                                              for g in fe.offset_gradients(frames)), "wrong image axis"),
])
def test_generic_hints_do_not_misname_the_problem(name, wrong, not_words):
    ok, out = _report(name, wrong)
    assert ok is False and not_words not in out, out


def test_nan_results_get_a_nan_hint():
    ok, out = _report("reinhard_tonemap", lambda L, gamma: np.full(np.shape(L), np.nan))
    assert not ok and "NaN" in out, out


# ---- correct alternatives pass -------------------------------------------------------------------------

def _head_augmented_lstsq(A, E, ridge):
    d = A.shape[1]
    return np.linalg.lstsq(np.vstack([A, math.sqrt(ridge) * np.eye(d)]), np.vstack([E, np.zeros((d, E.shape[1]))]),
                           rcond=None)[0]


def _frame_step_not_detached(model, optimizer, event_frames, centers, durations, lam):
    from evinr_lite.method.losses import temporal_loss_derivative, tikhonov
    F, dF = model.forward_with_derivative(centers)
    temporal = temporal_loss_derivative(dF, event_frames, durations)
    reg = tikhonov(F)
    loss = temporal + lam * reg
    optimizer.zero_grad()
    loss.backward()
    optimizer.step()
    return loss, temporal, reg


ALTERNATIVES = [
    ("anchor", lambda L, gamma, display_mean: fe.anchor(L, gamma, display_mean).astype(np.float32)),
    ("offset_gradients", lambda frames: tuple(g.astype(np.float32) for g in fe.offset_gradients(frames))),
    ("offset_gradients", lambda frames: (np.median(frames[:, :, :-1] - frames[:, :, 1:], axis=0),
                                         np.median(frames[:, :-1] - frames[:, 1:], axis=0))),
    ("time_fps_products", lambda table: {k: np.float32(r["time_s"] * r["fps"]) for k, r in table.items()}),
    ("highpass_per_event", lambda *a, **k: highpass_per_event(*a, **k).astype(np.float32)),
    ("integrate_gradients", lambda gx, gy: pe.integrate_gradients(gy.T, gx.T).T),
    ("integrate_events_1d", lambda t_events, p_events, C, t_query:
        np.array([C * np.sum(p_events[t_events <= q]) for q in t_query], dtype=np.float32)),
    ("temporal_loss", lambda dF_dt, delta_L, durations: torch.nn.functional.mse_loss(dF_dt * durations, delta_L)),
    ("tikhonov_autograd", lambda dF_dx, dF_dy: (dF_dx ** 2).mean() + (dF_dy ** 2).mean()),
    ("total_variation", lambda F: torch.diff(F, dim=-2).abs().mean() + torch.diff(F, dim=-1).abs().mean()),
    ("sine_layer_derivative", lambda h, dh_dt, weight, bias, omega:
        torch.func.jvp(lambda v: torch.sin(omega * (v @ weight + bias)), (h,), (dh_dt,))),
    ("head_closed_form", _head_augmented_lstsq),
    ("frame_train_step", _frame_step_not_detached),
    ("estimate_contrast_threshold", lambda log_changes, net_counts: float(np.linalg.lstsq(
        np.asarray(net_counts, float)[:, None], log_changes, rcond=None)[0][0])),
    ("hot_pixel_mask", lambda x, y, sensor_size, factor=10.0: (lambda c: c > factor * np.median(c[c > 0]))(
        np.bincount(np.ravel_multi_index((y, x), sensor_size), minlength=sensor_size[0] * sensor_size[1])
        .reshape(sensor_size))),
    ("split_index", lambda index, sensor_size: (index // (sensor_size[0] * sensor_size[1]),
                                                (index % (sensor_size[0] * sensor_size[1])) // sensor_size[1],
                                                index % sensor_size[1])),
]


@pytest.mark.parametrize("name, fn", ALTERNATIVES, ids=[f"{n}-{k}" for k, (n, _) in enumerate(ALTERNATIVES)])
def test_correct_alternatives_pass(name, fn):
    ok, out = _report(name, fn)
    assert ok is True, out


# ---- garbage never crashes a check -----------------------------------------------------------------

def _raises(*args, **kwargs):
    raise ValueError("boom")


def _nan_like(v):
    if isinstance(v, tuple):
        return tuple(_nan_like(x) for x in v)
    if isinstance(v, dict):
        return {k: _nan_like(x) for k, x in v.items()}
    if torch.is_tensor(v):
        return torch.full(v.shape, float("nan"))
    return np.full(np.shape(v), np.nan)


def _nan_of_reference(name):
    ref = exercises.reference(name)
    return lambda *a, **k: _nan_like(ref(*a, **k))


GARBAGE = {"None": lambda name: (lambda *a, **k: None), "raises": lambda name: _raises,
           "string": lambda name: (lambda *a, **k: "abc"), "object": lambda name: (lambda *a, **k: object()),
           "NaN": _nan_of_reference, "ragged": lambda name: (lambda *a, **k: ([1.0], [1.0, 2.0])),
           "no_arguments": lambda name: (lambda: None)}     # the stub's signature changed: the call itself fails


@pytest.mark.parametrize("kind", list(GARBAGE))
@pytest.mark.parametrize("name", [n for n in exercises.names() if n != "frame_train_step"] + ["frame_train_step"])
def test_garbage_fails_every_check_without_a_traceback(name, kind):
    if name == "frame_train_step" and kind == "NaN":
        fn = lambda *a, **k: (float("nan"),) * 3   # noqa: E731 - the step returns three floats
    else:
        fn = GARBAGE[kind](name)
    ok, out = _report(name, fn)
    assert ok is False, out
    assert "check itself failed" not in out and "Traceback" not in out, out
    assert "exercises.py" not in out and "_observe_step" not in out, out
    # a report names a function and a line, never the check's own: its loop and `run` stand between the report
    # and the learner's code (learner_calls._check_file skips their frames)
    for own in ("run", "_run_inputs", "_raised_report", "run_check"):
        assert f"raised in {own}," not in out, out
    if kind == "None":
        assert "None" in out, out
    if kind == "raises":
        assert "raised ValueError" in out, out
    if kind == "no_arguments":      # no line of the learner's raised: no "raised in", and the hint on the stub
        assert "raised TypeError" in out and "raised in " not in out, out
        assert "keep the stub's parameter names and order" in out, out


def _raised_through_run(fn, *args):
    """The error ``fn`` raised when called through the check's ``run``, its traceback starting at ``run``'s frame,
    as the check's loop (in checking/ too) catches it."""
    try:
        learner_calls.run(fn, args, {})
    except Exception as err:
        return err.with_traceback(err.__traceback__.tb_next)
    raise AssertionError(f"{fn.__name__} raised nothing")


def test_where_raised_names_the_learners_line_never_the_checks_nor_the_registrys():
    def no_arguments():                  # the stub's signature changed: the call fails before any learner line
        return 0

    def asks_the_registry(t):            # a learner's code may call the registry: the error is the learner's
        return exercises.get("typo")

    assert learner_calls.where_raised(_raised_through_run(no_arguments, 1.0)) == []
    line = asks_the_registry.__code__.co_firstlineno + 1
    assert learner_calls.where_raised(_raised_through_run(asks_the_registry, 1.0)) == [
        f'raised in asks_the_registry, line {line}: `return exercises.get("typo")`']


def test_a_step_returning_a_tensor_or_none_is_named_not_blamed_on_the_check():
    def returns_F(model, optimizer, event_frames, centers, durations, lam):
        loss = te.frame_train_step(model, optimizer, event_frames, centers, durations, lam)[0]
        return loss, model(centers), None
    ok, out = _report("frame_train_step", returns_F)
    assert ok is False and "wrong shape in output ['losses'][1]" in out and "_observe_step" not in out, out


# ---- the cases behind the new failures stay in place ------------------------------------------------

def test_check_cases_sit_on_the_new_rules():
    queries = [kw["t_query"] for _, kw in exercises.get("integrate_events_1d").cases()]
    assert any(np.any(np.diff(q) < 0) for q in queries)                                   # unsorted queries
    rate = [kw for _, kw in exercises.get("event_rate_derivative").cases()]
    assert any(np.any(kw["t_events"] < kw["boundaries"][0]) and np.any(kw["t_events"] > kw["boundaries"][-1])
               for kw in rate)                                                            # events outside
    assert any(not np.any(kw["t_events"] > kw["boundaries"][-2]) for kw in rate)          # an empty last window
    bis = [kw for _, kw in exercises.get("bisect_equal_count").cases()]
    assert any(np.sum(kw["t_events"] == kw["boundaries"][2]) >= 2 for kw in bis)           # ties on an edge
    for name in ("temporal_loss", "tikhonov_autograd", "temporal_loss_boundary", "total_variation"):
        assert all(any(torch.is_tensor(v) and v.requires_grad for v in kw.values())
                   for _, kw in exercises.get(name).cases()), name
    # the success lines the notebooks quote keep their counts
    counts = {"integrate_events_1d": 4, "event_rate_derivative": 4, "bisect_equal_count": 4,
              "estimate_contrast_threshold": 3, "temporal_loss": 2, "tikhonov_autograd": 2}
    for name, n in counts.items():
        assert len(exercises.get(name).cases()) == n, name


@pytest.mark.parametrize("wrong, words", [
    (lambda frames: ([[1.0], [1.0, 2.0]], [1]), "gx is a list"),
    (lambda frames: tuple(torch.as_tensor(g).requires_grad_(True) for g in fe.offset_gradients(frames)),
     "gx is a Tensor"),
    (lambda frames: (np.array(["a"]), np.array(["b"])), "dtype"),
])
def test_a_custom_comparison_names_what_it_cannot_read(wrong, words):
    ok, out = _report("offset_gradients", wrong)
    assert ok is False and words in out and "check itself failed" not in out, out


# ---- (W, H) unpacked where the sensor size is (H, W) ------------------------------------------------

def _frames_w_h(events, boundaries, C):
    W, H = events.sensor_size                     # the mistake: sensor_size is (H, W)
    B = len(boundaries) - 1
    out = np.zeros((B, H, W))
    k = np.clip(np.searchsorted(boundaries, events.t, side="right") - 1, 0, B - 1)
    np.add.at(out, (k, events.y, events.x), C * events.p)
    return out


def test_an_index_error_on_a_non_square_sensor_names_the_axis_order():
    ok, out = _report("events_to_frames_fixed", _frames_w_h)
    assert ok is False and "IndexError" in out, out
    assert "sensor_size is (H, W)" in out and "[y, x]" in out, out


# ---- an argument ignored ---------------------------------------------------------------------------

def _arguments(ex):
    """(label, freeze) for every argument of every case: freeze(args, kwargs) puts the first case's value
    of that argument in place of the given one (a version that hard-codes it, or ignores it)."""
    cases = ex.cases()
    (a0, k0), out = cases[0], []
    for key in (k for k in k0 if all(k in kw for _, kw in cases)):
        out.append((repr(key), lambda a, kw, _k=key: (a, {**kw, _k: copy.deepcopy(k0[_k])})))
    if all(len(a) == len(a0) for a, _ in cases):
        for i in range(len(a0)):
            out.append((f"positional {i}", lambda a, kw, _i=i: (
                tuple(copy.deepcopy(a0[_i]) if j == _i else v for j, v in enumerate(a)), kw)))
    return out


@pytest.mark.parametrize("name", exercises.names())
def test_a_version_that_ignores_an_argument_fails(name):
    """Each check's cases vary every argument in a way the result shows: a learner's version that uses
    one fixed value (the first case's) for any argument fails. (highpass_per_event's cases once all had
    C = 0.2 and t_end = 1.2, so a version with C fixed at 0.2 passed.)"""
    ex = exercises.get(name)
    passed = []
    for label, freeze in _arguments(ex):
        def fixed(*args, _freeze=freeze, **kwargs):
            a, kw = _freeze(args, kwargs)
            return ex.reference(*a, **kw)
        fixed.__signature__ = inspect.signature(ex.reference)
        ok, _ = _report(name, fixed)
        if ok:
            passed.append(label)
    assert not passed, f"{name}: a version that ignores {passed} passes the check"
