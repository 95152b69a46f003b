"""Round 12 of the bad-input table (tests/test_robustness*.py): the reader-facing helpers of the teaching modules that
notebooks 01 and 02 call and readers re-call with their own values (evinr_lite.teaching.pde1d: the window sums, the
Taylor error, the SIREN of one pixel, its fit, loss and residuals; evinr_lite.teaching.events2d: one pixel's events
and the busiest pixel).

Fixes (each test failed before its fix): ``window_sums`` with C NaN gave NaN sums and with C as text numpy's ufunc
error, no boundaries was numpy's IndexError, one edge, decreasing or repeated edges gave no windows or zero sums (and
``event_rate_derivative`` NaN or -0 rates), a NaN edge dropped events, a 2-D array of edges numpy's broadcast error,
polarities of another length numpy's boolean-index error and polarities as text numpy's conversion error;
``taylor_error`` with window 0 or NaN gave NaN, with a negative window a value, with text Python's TypeError, a
t_mid as text was read as a time and a NaN one gave NaN, L not a function Python's "not callable";
``eq4_error_vs_window`` with a window of 0 was Python's OverflowError, NaN "cannot convert float NaN", a negative one
blamed t_range, 1e-12 s a 7 TiB MemoryError, one number "iteration over a 0-d array", a t_range of three values or
one Python's unpack errors, of text was taken, of NaN "cannot convert float NaN", C NaN a NaN error, and p_events
without t_events was silently ignored; ``TimeSiren1D`` took an infinite or text t_range and one number was Python's
"not iterable"; ``predict`` / ``derivative`` of one time were IndexErrors, of text a torch TypeError, of NaN NaN, of
a 2-D array the Siren's shape error; ``shifted(nan)`` gave NaN and ``shifted("1")`` Python's TypeError;
``time_derivative`` of a numpy array was torch's TypeError; ``evaluate_temporal_loss`` with C NaN gave NaN, window 0
a ZeroDivisionError, NaN Python's conversion error, a negative window was taken, 1e-12 s a MemoryError, a reversed
t_range taken and model None an AttributeError; ``bin_residuals`` with delta_L of another length was numpy's
broadcast error, NaN delta_L or one edge NaN residuals, model None an AttributeError; ``fit_siren_1d`` with C 0 or
NaN trained on nothing or NaN, C as text numpy's error, n_iters 2.5 ran 2 steps and "2" or NaN were Python's errors,
window NaN or text Python's errors, seed None torch's TypeError and 1.5 ran seed 1, lr 0 trained nothing, lr_decay
NaN or 0 NaN or a stopped fit, an anchor or prior_mean of NaN gave a NaN loss and of text was read as a number, one
number or three as anchor Python's unpack errors, anchor_weight NaN or negative a NaN or rewarded loss, a wrong form
with n_iters=0 was accepted and a NaN t_range Python's conversion error; ``pixel_trace`` of None was an
AttributeError, a pixel outside the sensor, 1.5 or "1" matched no event without a word and a pair numpy's broadcast
error; ``busiest_pixel`` of no events said (0, 0) and of None or a (t, p) pair was an AttributeError.

Left as they are: the exercises' reference solutions (integrate_events_1d, event_rate_derivative's own lines,
temporal_loss, esim_interval, events_to_frames_fixed, interval_imbalance): notebooks show their source
(exercises.show_reference) and tools/mutate_exercises.py mutates every line of them, so checks there would be shown
to readers as part of the solution and mutated as if they were (event_rate_derivative gets window_sums' checks).

Guards: odd inputs next to these that already behave and must keep their outcome (the notebooks' calls, one time
as a number in taylor_error, an empty list of windows, 0-d tensors as C and c, a list of times for predict, a
negative torch seed, a window longer than the range, the existing refusals next to the new ones).
"""
import numpy as np
import pytest
import torch

from evinr_lite import Events
from evinr_lite.sim import make_scene, simulate_scene
from evinr_lite.teaching import events2d, pde1d

RNG = np.random.default_rng(0)
T = np.sort(RNG.uniform(0.0, 1.0, 50))
P = np.where(RNG.uniform(size=50) > 0.5, 1, -1).astype(np.int8)
B = np.linspace(0.0, 1.0, 5)
PAIR = (T, P)
MODEL = pde1d.TimeSiren1D((0.0, 1.0), hidden_features=8, hidden_layers=1)
EV2 = simulate_scene(make_scene("bar", sensor_size=(8, 10), duration=0.2), C=0.2)
EMPTY = Events.from_arrays(np.zeros(0), np.zeros(0, int), np.zeros(0, int), np.zeros(0, int), (8, 10))
FIT = dict(n_iters=1, hidden_features=8, hidden_layers=1, device="cpu")


from refusals import all_refused as _none_of, refused as _no   # noqa: E402  (shared by rounds 11-14)


# ---- 1. window sums and the rate of events ------------------------------------------------------------------------

@pytest.mark.parametrize("C", [np.nan, "0.2", 0.0, -0.2, np.inf])
def test_window_sums_refuse_a_contrast_that_is_no_threshold(C):
    _no(lambda: pde1d.window_sums(T, P, C, B), r"C= must be a finite number > 0")


@pytest.mark.parametrize("b,pattern", [([], r"boundaries= is empty"), ([0.5], r"at least 2 edges"),
                                       (B[::-1], r"must increase"),
                                       ([0.0, np.nan, 1.0], r"finite"), (B[None], r"1-D array"),
                                       ])
def test_window_sums_and_rates_refuse_edges_that_are_no_windows(b, pattern):
    _none_of([lambda: pde1d.window_sums(T, P, 0.2, b), lambda: pde1d.event_rate_derivative(T, P, 0.2, b)], pattern)


def test_window_sums_refuse_polarities_that_do_not_fit_the_times():
    _no(lambda: pde1d.window_sums(T, P[:3], 0.2, B), r"50 event time\(s\) in t_events but 3 polarities")
    _no(lambda: pde1d.window_sums(T, ["a"] * 50, 0.2, B), r"p_events= must be a 1-D array of polarities")
    _no(lambda: pde1d.window_sums(T, P, 0.2, "0 1"), r"boundaries= must be seconds")
    _no(lambda: pde1d.window_sums(np.r_[T[:-1], np.nan], P, 0.2, B), r"t_events= must be finite")


def test_window_sums_values_as_before():
    t, p = np.array([0.0, 0.1, 0.25, 0.3, 1.0]), np.array([1, 1, -1, 1, 1])
    assert pde1d.window_sums(t, p, 0.5, [0.0, 0.25, 0.5, 1.0]).tolist() == [0.5, 0.5, 0.5]
    assert pde1d.window_sums(list(t), list(p), np.float32(0.5), (0.0, 1.0)).tolist() == [1.5]
    assert pde1d.window_sums([], [], 0.2, B).tolist() == [0.0] * 4
    assert pde1d.window_sums(t, p, torch.tensor(0.5), B[:2]).tolist() == [0.5]
    assert np.allclose(pde1d.event_rate_derivative(t, p, 0.5, [0.0, 0.25, 1.0]), [2.0, 4.0 / 3.0])


# ---- 2. the Taylor error and its table ----------------------------------------------------------------------------

@pytest.mark.parametrize("w", [0.0, np.nan, -0.1, "0.1"])
def test_taylor_error_refuses_a_window_that_is_no_length(w):
    _no(lambda: pde1d.taylor_error(np.sin, [0.5], w), r"window= must be a finite number > 0")


def test_taylor_error_refuses_bad_times_and_no_function():
    _none_of([lambda: pde1d.taylor_error(np.sin, "0.5", 0.1), lambda: pde1d.taylor_error(np.sin, [np.nan], 0.1)],
             r"t_mid= must be")
    _none_of([lambda: pde1d.taylor_error(None, [0.5], 0.1), lambda: pde1d.taylor_error(np.ones(3), [0.5], 0.1)],
             r"L= must be a function of time", TypeError)
    _no(lambda: pde1d.taylor_error(np.sin, [0.5], 0.1, dLdt=1.0), r"dLdt= must be a function", TypeError)


def test_taylor_error_values_as_before():
    assert pde1d.taylor_error(np.sin, 0.5, 0.1) == pytest.approx(pde1d.taylor_error(np.sin, [0.5], 0.1)[0])
    assert np.ndim(pde1d.taylor_error(np.sin, 0.5, 0.1)) == 0
    assert pde1d.taylor_error(np.sin, [0.0], 0.02, np.cos)[0] == pytest.approx(1 - np.sin(0.01) / 0.01, abs=1e-12)


@pytest.mark.parametrize("windows,pattern", [([0.0], r"window lengths > 0"), ([-0.1], r"window lengths > 0"),
                                             ([np.nan], r"windows= must be finite"), ([1e-12], r"10,000,000"),
                                             ("0.1", r"windows= must be seconds")])
def test_eq4_table_refuses_windows_that_are_no_lengths(windows, pattern):
    _no(lambda: pde1d.eq4_error_vs_window(np.sin, windows, (0, 1)), pattern)


@pytest.mark.parametrize("span,pattern", [((1, 0), r"t_range= must be increasing"), ((0, np.nan), r"t1= must be a fin"),
                                          ((0, 1, 2), r"pair \(t0, t1\)"), (1.0, r"pair \(t0, t1\)"),
                                          (("0", "1"), r"t0= must be a finite number")])
def test_eq4_table_refuses_a_range_that_is_no_span(span, pattern):
    _no(lambda: pde1d.eq4_error_vs_window(np.sin, [0.1], span), pattern)


def test_eq4_table_needs_all_three_of_the_events_or_none():
    _no(lambda: pde1d.eq4_error_vs_window(np.sin, [0.1], (0, 1), p_events=P, C=0.2), r"t_events, p_events and C")
    _no(lambda: pde1d.eq4_error_vs_window(np.sin, [0.1], (0, 1), t_events=T, p_events=P, C=np.nan), r"C= must be")
    _no(lambda: pde1d.eq4_error_vs_window(np.sin, [0.1], (0, 1), t_events=T, p_events=P[:5], C=0.2), r"polarities")


def test_eq4_table_as_before():
    res = pde1d.eq4_error_vs_window(np.sin, 0.1, (0, 1))
    assert res["window"].tolist() == [0.1] and res["taylor"].shape == (1,)
    assert pde1d.eq4_error_vs_window(np.sin, [], (0, 1))["taylor"].size == 0
    _no(lambda: pde1d.eq4_error_vs_window(np.sin, [2.0], (0, 1)), r"longer than t_range")
    res = pde1d.eq4_error_vs_window(np.sin, [0.1, 0.25], (0, 1), t_events=T, p_events=P, C=0.2, dLdt=np.cos)
    assert np.isfinite(res["events"]).all()


# ---- 3. the SIREN of one pixel -------------------------------------------------------------------------------------

@pytest.mark.parametrize("span,pattern", [((0, np.inf), r"t1= must be a finite"), (("0", "1"), r"t0= must be a fin"),
                                          (1.0, r"pair \(t0, t1\)"), ((1, 0), r"t_range= must be increasing")])
def test_time_siren_refuses_a_range_that_is_no_span(span, pattern):
    _no(lambda: pde1d.TimeSiren1D(span), pattern)


@pytest.mark.parametrize("t,pattern", [("0.5", r"t= must be seconds"), ([np.nan], r"t= must be finite"),
                                       (np.ones((2, 2)), r"t= must be a 1-D array")])
def test_time_siren_predict_and_derivative_refuse_bad_times(t, pattern):
    _none_of([lambda: MODEL.predict(t), lambda: MODEL.derivative(t)], pattern)


def test_time_siren_takes_one_time_and_lists():
    assert MODEL.predict(0.5).shape == (1,)
    assert MODEL.predict(0.5)[0] == pytest.approx(MODEL.predict([0.5, 0.6])[0], abs=1e-6)
    assert MODEL.derivative(0.5)[0] == pytest.approx(MODEL.derivative(np.array([0.5]))[0])


def test_time_siren_shift_must_be_a_number():
    _none_of([lambda: MODEL.shifted(np.nan), lambda: MODEL.shifted("1")], r"c= must be a finite number")
    assert float(MODEL.shifted(torch.tensor(1.0)).offset) == 1.0


def test_time_derivative_refuses_numpy_times():
    _no(lambda: pde1d.time_derivative(MODEL, np.ones(3)), r"t must be a torch tensor", TypeError)
    _no(lambda: pde1d.time_derivative(MODEL, torch.ones(3)), r"requires_grad")


# ---- 4. the loss, the residuals and the fit ------------------------------------------------------------------------

@pytest.mark.parametrize("kw,pattern", [(dict(C=np.nan), r"C= must be"), (dict(window=0.0), r"window= must be"),
                                        (dict(window=np.nan), r"window= must be"), (dict(window=-0.1), r"window="),
                                        (dict(window=1e-12), r"windows \(at most"),
                                        (dict(t_range=(1, 0)), r"t_range= must be increasing"),
                                        (dict(form="diff"), r"form must be")])
def test_evaluate_temporal_loss_refuses_bad_settings(kw, pattern):
    args = dict(C=0.2, window=0.1) | kw
    _no(lambda: pde1d.evaluate_temporal_loss(MODEL, PAIR, **args), pattern)


def test_loss_and_residuals_refuse_no_model():
    _no(lambda: pde1d.evaluate_temporal_loss(None, PAIR, 0.2, 0.1), r"model= must be a fitted TimeSiren1D")
    _no(lambda: pde1d.bin_residuals(None, B, np.ones(4)), r"model= must be a fitted TimeSiren1D")


def test_bin_residuals_refuse_sums_that_do_not_fit_the_windows():
    _no(lambda: pde1d.bin_residuals(MODEL, B, np.ones(3)), r"delta_L= holds 3 value\(s\) but boundaries= make 4")
    _no(lambda: pde1d.bin_residuals(MODEL, B, [np.nan] * 4), r"delta_L= must be a 1-D array of finite numbers")
    _no(lambda: pde1d.bin_residuals(MODEL, [0.5], []), r"at least 2 edges")


def test_loss_and_residuals_as_before():
    a = pde1d.evaluate_temporal_loss(MODEL, PAIR, 0.2, 0.1)
    assert a == pytest.approx(pde1d.evaluate_temporal_loss(MODEL.shifted(0.5), PAIR, 0.2, 0.1), rel=1e-6)
    assert np.isfinite(pde1d.evaluate_temporal_loss(MODEL, PAIR, 0.2, 5.0))     # longer than the range: one window
    r = pde1d.bin_residuals(MODEL, B, pde1d.window_sums(T, P, 0.2, B))
    assert set(r) == {"slope", "change"} and np.isfinite(list(r.values())).all()


@pytest.mark.parametrize("kw,pattern", [
    (dict(C=0.0), r"C= must be a finite number > 0"), (dict(C=np.nan), r"C= must be"), (dict(C="0.2"), r"C= must be"),
    (dict(n_iters=2.5), r"n_iters= must be a whole number >= 0"), (dict(n_iters=np.nan), r"n_iters="),
    (dict(window=np.nan), r"window= must be"), (dict(seed=None), r"seed= must be a whole number"),
    (dict(seed=1.5), r"seed= must be a whole number"), (dict(lr=0.0), r"lr= must be a finite number > 0"),
    (dict(lr_decay=np.nan), r"lr_decay= must be"), (dict(anchor=(0.0, np.nan)), r"anchor: L_a= must be"),
    (dict(anchor=("0", "1")), r"anchor: t_a= must be"), (dict(anchor=0.5), r"anchor= must be a pair"),
    (dict(prior_mean=np.nan), r"prior_mean= must be"),
    (dict(anchor=(0, 0), anchor_weight=np.nan), r"anchor_weight="),
    (dict(anchor=(0, 0), anchor_weight=-1.0), r"anchor_weight= must be a finite number >= 0"),
    (dict(form="diff", n_iters=0), r"form must be"), (dict(t_range=(0, np.nan)), r"t1= must be a finite")])
def test_fit_siren_refuses_settings_that_train_nothing_or_garbage(kw, pattern):
    args = dict(t_range=(0.0, 1.0), C=0.2) | FIT | kw
    _no(lambda: pde1d.fit_siren_1d(PAIR, **args), pattern)


def test_fit_siren_as_before():
    m1, h1 = pde1d.fit_siren_1d(PAIR, (0.0, 1.0), 0.2, **(FIT | dict(n_iters=2.0)), seed=3)
    m2, h2 = pde1d.fit_siren_1d(PAIR, (0.0, 1.0), 0.2, **(FIT | dict(n_iters=2)), seed=3, anchor=(0.0, 0.0),
                                anchor_weight=0.0)
    assert len(h1["loss"]) == 2 and h1["temporal"] == h2["temporal"]
    assert len(pde1d.fit_siren_1d(PAIR, (0.0, 1.0), 0.2, seed=-1, **FIT)[1]["loss"]) == 1   # torch takes it
    _no(lambda: pde1d.fit_siren_1d(PAIR, (0.0, 1.0), 0.2, window=0.0), r"window")
    _no(lambda: pde1d.fit_siren_1d(PAIR, (0.0, 1.0), 0.2, form="integral", **FIT), r"form")


# ---- 5. one pixel of many -----------------------------------------------------------------------------------------

@pytest.mark.parametrize("x,y,pattern", [(100, 0, r"x= must be a whole number in \[0, 9\]"), (-1, 0, r"x= must"),
                                         (1.5, 0, r"x= must"), ("1", 0, r"x= must"), ((1, 2), 0, r"x= must"),
                                         (0, 8, r"y= must be a whole number in \[0, 7\]")])
def test_pixel_trace_refuses_a_pixel_off_the_sensor(x, y, pattern):
    _no(lambda: events2d.pixel_trace(EV2, x, y), pattern)


def test_pixel_trace_and_busiest_pixel_refuse_what_is_not_events():
    _none_of([lambda: events2d.pixel_trace(None, 0, 0), lambda: events2d.pixel_trace(PAIR, 0, 0),
              lambda: events2d.busiest_pixel(None), lambda: events2d.busiest_pixel(PAIR)], r"events= must be Events")


def test_busiest_pixel_of_no_events_is_refused():
    _no(lambda: events2d.busiest_pixel(EMPTY), r"no event")


def test_pixel_trace_and_busiest_pixel_as_before():
    x, y = events2d.busiest_pixel(EV2)
    t, p = events2d.pixel_trace(EV2, x, y)
    keep = (EV2.x == x) & (EV2.y == y)
    assert len(t) and np.array_equal(t, EV2.t[keep]) and np.array_equal(p, EV2.p[keep])
    assert np.array_equal(events2d.pixel_trace(EV2, np.int64(x), float(y))[0], t)


# ---- from the review of this round ----------------------------------------------------------------

def test_window_sums_take_a_repeated_edge_as_an_empty_window():
    """The review: refusing repeated edges cost the exercise check of event_rate_derivative its hint for an input
    clipped to [0, 1] (the reference answers the clipped input through window_sums). A repeated edge is an empty
    window again; decreasing edges stay refused."""
    sums = pde1d.window_sums(T, P, 0.2, [0.0, 0.5, 0.5, 1.0])
    assert sums.shape == (3,) and sums[1] == 0.0
    assert np.isclose(sums.sum(), pde1d.window_sums(T, P, 0.2, [0.0, 0.5, 1.0]).sum())


def test_no_query_times_give_no_answers():
    """The review: a zoom range no mid-point falls in (notebook 01) asked predict / derivative / taylor_error for no
    times, which now was an error; an empty query has the empty answer, as before this round."""
    assert MODEL.predict(np.zeros(0)).shape == (0,) and MODEL.derivative([]).shape == (0,)
    assert pde1d.taylor_error(np.sin, [], 0.1, np.cos).shape == (0,)


def test_whole_numbers_take_zero_d_arrays_and_tensors():
    """The review: pixel_trace(E, torch.tensor(2), torch.tensor(1)) said "x= must be a whole number in [0, 2], got
    tensor(2)"; a 0-d array or tensor holding a whole number is that number (core.checks.whole_number)."""
    from evinr_lite.core.checks import whole_number
    assert whole_number(torch.tensor(2), "x") == 2 and whole_number(np.array(3), "x") == 3
    _no(lambda: whole_number(torch.tensor(2.5), "x"), r"whole number")


def test_a_readers_own_model_with_the_same_methods_is_taken():
    """The review: evaluate_temporal_loss and bin_residuals refused any model but a TimeSiren1D by type."""
    class Wrap:
        def __init__(self, m):
            self.m, self.t_range = m, m.t_range

        def predict(self, t):
            return self.m.predict(t)

        def derivative(self, t):
            return self.m.derivative(t)
    assert np.isclose(pde1d.bin_residuals(Wrap(MODEL), B, np.ones(4))["slope"],
                      pde1d.bin_residuals(MODEL, B, np.ones(4))["slope"])
