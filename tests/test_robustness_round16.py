"""Round 16 of the bad-input table (tests/test_robustness*.py): public functions and flags no earlier round called
with bad arguments: the temporal scale set by hand (``EvINRConfig(temporal_scale=)``, ``RunOptions``, ``reconstruct`` /
``batch --temporal-scale``), its helpers (evinr_lite.method.tempo), the solver's plan from per-pixel counts
(evinr_lite.method.prepare.plan_from_counts) and the balance's counts and sums (evinr_lite.method.balance:
``polarity_counts``, ``interval_sums``, ``slice_counts``, ``span_slices``, ``interval_stride``, ``PolarityCounts``,
``balance_from_counts``), the simulator's thresholds (``sample_thresholds``), the zoo's helpers
(evinr_lite.sim.zoo), the colour recording's writer (``write_colour_davis_recording``), the scorer's LPIPS model, the
figures' ``ax`` and one pixel's curves (``plot_reconstruction_1d``), and recordings that are valid files but
degenerate for the method (one polarity, one pixel, one timestamp, a ten-hour gap, time going back 0.1 ms, sensors of
1 x N, N x 1 and 1 x 1).

234 cases. Sections 1 to 8: 195, 157 of which failed before their fixes (the other 38: 25 guards and 13 refusals that
stood before, kept beside the new ones with their old message allowed); section 9, the review's: 39, 31 of which
failed before its fixes (2 of them, a per-pixel C of the wrong length or holding NaN, only by their message: this
branch refused any array there as no number), and 8 guards.

Fixes (each test failed before its fix): a temporal scale set by hand had no floor: 1e-9 (bins of 3 * 10^7 s and a
prior of 5 * 10^-9 rad/s) diverged and overflowed the linear tone map's shift (``display_shift``: math.exp of more
than 700, the command's "internal error"; reconstruct and batch alike), 1e-6 or 5e-324 gave frames of 0 and 1 at a
"gain" of 10^26 without a word: ``EvINRConfig`` and ``RunOptions`` now refuse a scale below ``tempo.MIN_SCALE``
(1/64: bins 64x longer, a prior 64x slower), the command naming --temporal-scale (status 2, nothing written); and
``display_shift`` sums exp(v + c) directly where exp(top + c) overflows, so a valid but very slow first layer
(``first_omega_per_s=1e-9``) gives finite frames (a spread of e^2000 is matched to its mean exactly).
``tempo.flip_rate`` of a span "1" or None was numpy's ufunc error and True was 1 s; text counts were numpy's
conversion error, negative or NaN counts gave a negative or NaN rate; ``scale_from_rate`` of text or None was
numpy's error and a list or True were taken. ``plan_from_counts`` of a config None, a dict or a text was an
AttributeError, counts of two shapes, text, None or 1-D were numpy's broadcast or conversion errors or a plan for no
sensor, flips or intervals of another shape numpy's broadcast error, span_s "1" Python's TypeError, and NaN or -1
were taken (the scale left "auto"). ``polarity_counts`` / ``interval_sums`` / ``slice_counts`` of None, a path or an
array were AttributeErrors; ``interval_sums``' ``last`` of 5, text or one array were Python's errors, of another
shape numpy's IndexError, a polarity of NaN or 3 was cast to int8 and a time given where no polarity is (or NaN
where one is) was taken; ``slice_counts`` with no edges was numpy's "negative dimensions", one edge gave no slice,
NaN or reversed edges counted without a word; ``span_slices`` of k 0 or -1 gave one or no boundary, 2.5 and "8" were
numpy's errors, NaN spans gave NaN boundaries and a reversed span slices one microsecond; ``interval_stride`` /
``PolarityCounts`` of None, 5, text, (0, 5), (-5, 5) or (2.5, 3) were Python's or numpy's errors or a stride and
counts for no pixel; ``PolarityCounts(decay="0.5")`` was taken and None was Python's TypeError;
``balance_from_counts`` of negative counts and a min_events of -1 or NaN gave a fit without a word, text counts were
numpy's error. Whole floats (a count of 8.0 slices, 4.0 pixels, a sensor 12.0 wide) were Python's "cannot be
interpreted as an integer". ``sample_thresholds`` of n_pixels -1, 2.5, "3" or None were numpy's errors, a NaN,
negative or text C and a NaN, negative or text sigma were taken (thresholds of NaN or -0.2), rng=5 an
AttributeError. ``zoo.fresh`` of a seed "0" or NaN was numpy's SeedSequence error and -1 its ValueError, n -1 gave
no scene and 2.5 or "3" scenes without a word; ``quick`` / ``simulate`` / ``imbalance`` / ``effective_C`` of a name
or None were AttributeErrors; ``default_scenes("no")`` counted the long scenes. ``write_colour_davis_recording`` of
a path None, 5, bytes or a list was Python's TypeError, and ``overwrite="no"`` (or 2, "False") replaced the user's
file. ``score_sequence`` / ``evaluate`` with ``lpips_model`` True, 5, 1.5, {} or [1] failed inside the first LPIPS
distance (AttributeError): a model must be a torch module. ``plot_reconstruction_1d`` with curves None, a list or
text was an AttributeError, curves or a truth of another length, t None and text values were matplotlib's errors; every
figure taking ``ax=`` (``plot_count_map``, ``plot_polarity``, ``plot_event_rate``,
``plot_boundaries``, ``plot_signal_and_events``, ``plot_reconstruction_1d``, ``plot_window_errors``) failed inside
matplotlib on a Figure, a number or an array of axes: the one check is ``viz.signals.axes_or_new``, naming
fig.axes[0] / axes[0]. A 1 x 1 sensor reconstructed at one time was refused as "constant frames although the input
varies; check C": one value cannot vary (``check_result_frames`` asks for more than one).

Review fixes (section 9; each test failed before its fix, on this branch before the review): the round's checks
refused what worked before it, and copied checks that existed. ``plot_reconstruction_1d`` sent its times through
``seconds_array``, the event timestamps' check, which refused float32 times at 20 s (torch.linspace's default),
float16 times and NaN (matplotlib's gap in the line): a figure's times are float64 1-D numbers of the curves'
length, NaN allowed, as ``plot_signal_and_events`` takes them (section 7's case of NaN times is gone).
``balance_from_counts`` asked every call for [H, W] counts and refused 1-D counts that fitted before (section 4's
case of them is gone): only ``sliced=`` (the edges' estimate, which needs a sensor's neighbours) asks for them.
``sample_thresholds`` took only a np.random.Generator and one number per threshold: any generator with
``standard_normal`` (np.random.RandomState) and per-pixel arrays of C (n_pixels of them, or one) are taken again, a
Decimal C too, and the thresholds are checked by the simulators' own ``_check_thresholds`` (one rule: a C below
MIN_C, 10^-3, which it took and ``simulate_events_1d`` refuses, is refused; section 5's four threshold cases match
that message now). ``zoo.fresh`` took whole numbers only: a np.random.SeedSequence and a list of whole numbers, which
numpy's default_rng takes, draw again (named by their numbers; [3] and SeedSequence(3) draw fresh(3)'s scenes).
``span_slices`` and ``balance_from_counts(min_events=)`` refused a Decimal: it is taken as its float
(``core.checks.decimal_as_float``). ``plot_histories``, ``plot_tradeoff`` and ``plot_xyt`` kept their own ``if ax
is None`` and failed inside matplotlib on a Figure or an array of axes: they go through ``axes_or_new``, whose
``projection="3d"`` makes ``plot_xyt``'s new axes and names a 2-D one; a Figure without axes was told "e.g.
fig.axes[0]" (an IndexError) and a SubFigure got no hint: both are told fig.add_subplot(). Copies: ``PolarityCounts``
checked its slices by a second rule that took an infinite edge (refused at the first update, as slice_counts'
edges): it calls ``_slice_edges``; smoothing's copy of ``check_counts`` is gone, and the four checks of "two counts
of one [H, W] shape" (smoothing, tempo, prepare, balance) are one, ``denoise.check_count_pair``. A temporal scale of
0 was told "must be positive" (``EvINRConfig``) or "a number > 0" (``RunOptions``, --temporal-scale), and then 0.001
was refused by the floor: the first message says the range, "a number from 1/64 (tempo.MIN_SCALE) up, or 'auto'"
(--temporal-scale: "from 1/64 up"), as the command's help does.

Refused on purpose where they were taken before: a hand-set temporal scale in (0, 1/64) (0.01 gave frames; below
the floor the network hardly changes over a window), a rate of -1 in ``scale_from_rate`` (it was 1), an
``interval_sums`` ``last`` whose times and polarities disagree, ``plan_from_counts(span_s=-1)``, the zoo's
``default_scenes(None)`` / ``(2)``; from the review: ``sample_thresholds``' C below MIN_C (10^-3, as the
simulators), ``zoo.fresh``'s seed None, a np.random.Generator or BitGenerator (numpy takes them, but the scenes are
named by their seed, to be drawn again) and an empty list, and ``plot_reconstruction_1d``'s times of datetime64 or
any other non-number (its axis is seconds).

Left as they are: ``flip_rate`` of counts of zero size (no pixel: NaN, as before), ``span_slices`` / ``zoo.fresh``
of 10^12 slices or scenes (a MemoryError or hours: a count, not a type), ``estimate_balance``'s unknown keywords
(Python's TypeError names the keyword), ``write_colour_davis_recording`` to a path whose suffix is not .h5 (the
canonical writer takes any name) or a missing folder (made, as the writer makes it), a first_omega_per_s of 1e-9
(a valid setting whose frames are now finite, however poor) and the degenerate recordings of section 8, which
already reconstruct (one polarity, 1 x N, N x 1, 1 x 1 at several times) or are refused by name (one timestamp:
"time span is empty"; a ten-hour gap: the windows' count; one pixel: the background filter's share; time going
back 0.1 ms: "timestamps are not sorted").

Guards: odd inputs next to these that already behave and must keep their outcome (scales from 1/64 up, float32 and
"auto"; an ordinary display shift; NaN and np.int64 rates, int64 counts, a float32 span; plans with int64 / float32
counts, no span, a 0 x 0 sensor and interval sums; np.int64 sizes, float32 decays, one-instant spans, chained
interval sums, int64 edges; np.int64 counts and float32 C in sample_thresholds; np.int64 seeds; np.bool_ / 0 / 1
flags; overwrite=np.bool_(True); LPIPS skipped or any torch module; given and new axes, lists and 2-D curves; the
degenerate recordings of section 8; section 9's: a 2-D or text t, 1-D counts with slices, the seeds that name no
scene, and the other figures on given and new axes).
"""
import math
import re
from decimal import Decimal

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
import pytest
import torch

from evinr_lite import EvINRConfig, EventDataError, Events, reconstruct
from evinr_lite.apps import cli
from evinr_lite.apps.options import RunOptions, temporal_scale_option
from evinr_lite.evaluation import evaluate, score_sequence
from evinr_lite.method import balance, tempo
from evinr_lite.method.prepare import plan_from_counts
from evinr_lite.method.smoothing import auto_lam
from evinr_lite.method.tonemap import display_shift
from evinr_lite.sim import make_scene, simulate_scene, write_example_recording, zoo
from evinr_lite.sim.colour_davis import write_colour_davis_recording
from evinr_lite.sim.simulate import sample_thresholds
from evinr_lite.viz import (plot_boundaries, plot_count_map, plot_event_rate, plot_histories, plot_polarity,
                            plot_reconstruction_1d, plot_signal_and_events, plot_tradeoff, plot_window_errors, plot_xyt)

from refusals import all_refused as _none_of, refused as _no   # noqa: E402  (shared by rounds 11-16)

matplotlib.use("Agg")
EV = simulate_scene(make_scene("bar", sensor_size=(12, 12), duration=0.3), C=0.2)
Z = np.zeros((12, 12))
FIVE = np.full((12, 12), 5.0)
CFG = EvINRConfig()
GT = np.random.default_rng(0).uniform(0, 1, (3, 16, 16))
TIMES = [0.1, 0.2, 0.3]


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


# ---- 1. the temporal scale set by hand: a floor, and the tone map's overflow -------------------------------------

@pytest.mark.parametrize("scale", [1e-9, 1e-6, 1e-3, 5e-324, 0.01])
def test_config_refuses_a_temporal_scale_below_the_floor(scale):
    _no(lambda: EvINRConfig(temporal_scale=scale), r"temporal_scale=.* is below 0\.015625.*'auto'")


@pytest.mark.parametrize("scale", [1e-9, 0.001])
def test_run_options_refuse_a_temporal_scale_below_the_floor(scale):
    _no(lambda: RunOptions(temporal_scale=scale), r"temporal_scale=.* is below 0\.015625")


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    return write_example_recording(tmp_path_factory.mktemp("rec") / "rec", sensor_size=(12, 12), duration=0.3)


@pytest.mark.parametrize("command", ["reconstruct", "batch"])
def test_the_command_refuses_a_temporal_scale_below_the_floor(command, recording, tmp_path, capsys):
    status = cli.main([command, str(recording), "--out", str(tmp_path / "out"), "--temporal-scale", "1e-9",
                       "--iters", "2"])
    err = capsys.readouterr().err
    assert status == 2, err
    assert "--temporal-scale 1e-09 is below 0.015625" in err and "internal error" not in err
    assert not (tmp_path / "out").exists()


def test_a_very_slow_first_layer_no_longer_overflows_the_tone_map():
    # first_omega_per_s=1e-9: a valid setting whose log intensity spans more than e^700; display_shift's
    # exp(top + c) was an OverflowError (the command's "internal error")
    rec = reconstruct(EV, [0.1, 0.15, 0.2], EvINRConfig(n_iters=20, progress=False, first_omega_per_s=1e-9))
    assert np.isfinite(rec.frames).all()


def test_display_shift_of_values_spread_over_e_to_the_700():
    ref = np.array([-2000.0] * 9 + [0.0])   # the bright pixel shows 1; the others must rise by about 2000
    c = display_shift(ref, "linear", display_mean=0.4)
    assert abs(c - (2000 - math.log(3))) < 1e-6    # 9 exp(c - 2000) / 10 + 1 / 10 = 0.4


@pytest.mark.parametrize("scale", [1 / 64, 0.25, 0.5, 1, 2.5, np.float32(2.0), "auto"])
def test_guard_scales_from_the_floor_up_are_taken(scale):
    assert EvINRConfig(temporal_scale=scale).temporal_scale == (scale if scale == "auto" else float(scale))
    assert RunOptions(temporal_scale=scale).config(0.2).temporal_scale == (scale if scale == "auto" else float(scale))


def test_guard_a_display_shift_of_ordinary_values_is_unchanged():
    ref = np.linspace(-2, 1, 50)
    c = display_shift(ref, "linear", display_mean=0.4)
    assert abs(np.minimum(np.exp(ref + c), 1).mean() - 0.4) < 1e-9


# ---- 2. the temporal scale's helpers (evinr_lite.method.tempo) --------------------------------------------------

@pytest.mark.parametrize("span", ["1", None, True, 0, -1.0, float("nan"), float("inf")])
def test_flip_rate_refuses_a_span_that_is_no_positive_number(span):
    _no(lambda: tempo.flip_rate(Z, FIVE, span), r"span_s(= must be a finite number > 0| must be a positive number)")


@pytest.mark.parametrize("flips, events, name", [
    ("a", FIVE, "flips"), (None, FIVE, "flips"), (-FIVE, FIVE, "flips"), (np.full((12, 12), np.nan), FIVE, "flips"),
    (Z, np.full((12, 12), np.nan), "n_events"), (Z, -FIVE, "n_events"), (Z, None, "n_events")])
def test_flip_rate_refuses_counts_that_are_no_counts(flips, events, name):
    _no(lambda: tempo.flip_rate(flips, events, 1.0), rf"flip_rate: ({name} must be|flips and n_events must be)")


@pytest.mark.parametrize("rate", ["5", None, -1.0, [5.0], True])
def test_scale_from_rate_refuses_a_rate_that_is_no_number(rate):
    _no(lambda: tempo.scale_from_rate(rate), r"rate must be polarity reversals per pixel and second")


def test_temporal_scale_refuses_text_counts_and_a_text_span():
    _none_of([lambda: tempo.temporal_scale("abc", FIVE, 1.0), lambda: tempo.temporal_scale(Z, FIVE, "2")],
             r"flip_rate: (flips must be|span_s= must be)")


def test_guard_the_tempo_helpers_keep_their_results():
    assert math.isnan(tempo.flip_rate(Z, Z, 1.0))                           # no pixel fired often enough
    assert math.isnan(tempo.flip_rate(np.zeros((0, 0)), np.zeros((0, 0)), 1.0))
    assert tempo.flip_rate(FIVE, FIVE, np.float32(2.0)) == 2.5
    assert tempo.flip_rate(FIVE.astype(np.int64), FIVE.astype(np.int64), 1) == 5.0
    assert tempo.scale_from_rate(float("nan")) == 1.0 and tempo.scale_from_rate(np.float64(25.0)) == tempo.MAX_SCALE
    assert tempo.scale_from_rate(np.int64(5)) == 2.0 and tempo.scale_from_rate(float("inf")) == 1.0


# ---- 3. the solver's plan from per-pixel counts (evinr_lite.method.prepare.plan_from_counts) ---------------------

@pytest.mark.parametrize("cfg", [None, {}, "kit", EvINRConfig.__name__])
def test_plan_from_counts_refuses_a_config_that_is_no_evinr_config(cfg):
    _no(lambda: plan_from_counts(FIVE, FIVE, cfg), r"plan_from_counts: cfg= must be EvINRConfig")


OLD_COUNTS = r"|^counts must be finite event counts >= 0, but 144|^n_on must be finite counts"   # refused before too


@pytest.mark.parametrize("n_on, n_off, old", [
    (FIVE, np.ones((5, 5)), ""), (np.ones(5), np.ones(5), ""), ("a", "b", ""), (None, None, ""),
    (-FIVE, FIVE, OLD_COUNTS), (np.full((12, 12), np.nan), FIVE, OLD_COUNTS),
    (FIVE, np.full((12, 12), np.inf), OLD_COUNTS)])
def test_plan_from_counts_refuses_counts_that_are_no_counts_of_one_sensor(n_on, n_off, old):
    _no(lambda: plan_from_counts(n_on, n_off, CFG), r"plan_from_counts: n_o(n|ff)" + old)


@pytest.mark.parametrize("kw, pattern", [
    ({"flips": np.ones((3, 3)), "span_s": 1.0}, r"flips has shape \(3, 3\)"),
    ({"flips": -FIVE, "span_s": 1.0}, r"flips must be finite event counts"),
    ({"flips": FIVE, "span_s": "1"}, r"span_s= must be a finite number"),
    ({"flips": FIVE, "span_s": float("nan")}, r"span_s= must be a finite number"),
    ({"flips": FIVE, "span_s": -1.0}, r"span_s= must be a finite number >= 0"),
    ({"intervals": [np.ones((3, 3))] * 4}, r"intervals\[0\] has shape")])
def test_plan_from_counts_refuses_flips_spans_and_intervals_that_do_not_fit(kw, pattern):
    _no(lambda: plan_from_counts(FIVE, FIVE, CFG, **kw), pattern)


def test_guard_plan_from_counts_keeps_its_plans():
    cfg, hot = plan_from_counts(FIVE, FIVE, CFG, flips=FIVE, span_s=1.0)
    assert hot.shape == (12, 12) and cfg.temporal_scale == 2.0
    assert plan_from_counts(FIVE, FIVE, CFG, flips=FIVE, span_s=0.0)[0].temporal_scale == "auto"   # no span: stays
    assert plan_from_counts(FIVE.astype(np.int64), FIVE.astype(np.float32), CFG)[1].shape == (12, 12)
    assert plan_from_counts(np.zeros((0, 0)), np.zeros((0, 0)), CFG)[1].shape == (0, 0)
    *sums, _, _ = balance.interval_sums(EV)
    assert plan_from_counts(*balance.polarity_counts(EV), CFG, intervals=tuple(sums))[1].shape == (12, 12)


# ---- 4. the balance's counts and sums (evinr_lite.method.balance) -----------------------------------------------

@pytest.mark.parametrize("fn", [balance.polarity_counts, balance.interval_sums,
                                lambda e: balance.slice_counts(e, [0.0, 0.1, 0.3])])
@pytest.mark.parametrize("events", [None, "events.txt", np.zeros((10, 4))])
def test_the_counts_refuse_what_is_no_events(fn, events):
    _no(lambda: fn(events), r"events= must be Events")


@pytest.mark.parametrize("last, pattern", [
    (5, "last must be"), ("ab", "last must be"), ((Z,), "last must be"),
    ((np.zeros((3, 3)), np.zeros((3, 3))), r"shapes \(3, 3\)"),
    ((np.full((12, 12), np.nan), np.full((12, 12), np.nan)), "other values than -1, 0 and"),
    ((np.full((12, 12), np.nan), np.full((12, 12), 3)), "other values than -1, 0 and"),
    ((np.zeros((12, 12)), np.zeros((12, 12))), "NaN exactly where last_p is 0"),
    ((np.full((12, 12), np.nan), np.ones((12, 12))), "NaN exactly where last_p is 0")])
def test_interval_sums_refuses_a_last_event_that_is_not_one(last, pattern):
    _no(lambda: balance.interval_sums(EV, last=last), pattern)


@pytest.mark.parametrize("edges", [[], [0.1], None, "ab", [0.0, np.nan, 0.3], [0.3, 0.2, 0.1], [[0.0, 0.3]]])
def test_slice_counts_refuses_edges_that_are_no_slices(edges):
    _no(lambda: balance.slice_counts(EV, edges), r"slice_counts: edges must be")


@pytest.mark.parametrize("args, pattern", [
    ((0.0, 1.0, 0), r"k= must be a whole number >= 1"), ((0.0, 1.0, -1), r"k= must be a whole number >= 1"),
    ((0.0, 1.0, 2.5), r"k= must be a whole number"), ((0.0, 1.0, "8"), r"k= must be a whole number"),
    ((np.nan, 1.0), r"t_start= must be a finite number"), ((0.0, "1"), r"t_end= must be a finite number"),
    ((1.0, 0.0), r"reversed")])
def test_span_slices_refuses_counts_and_spans_that_are_no_slices(args, pattern):
    _no(lambda: balance.span_slices(*args), pattern)


@pytest.mark.parametrize("size", [None, 5, (0, 5), (-5, 5), (2.5, 3), "ab"])
def test_the_stride_and_the_running_counts_refuse_a_size_that_is_no_sensor(size):
    _none_of([lambda: balance.interval_stride(size), lambda: balance.PolarityCounts(size)], r"sensor_size must be")


@pytest.mark.parametrize("decay", [0, 2, np.nan, "0.5", None])
def test_running_counts_refuse_a_decay_outside_0_1(decay):
    _no(lambda: balance.PolarityCounts((12, 12), decay=decay), r"decay=? must be (a finite number )?in \(0, 1\]")


@pytest.mark.parametrize("n_on, n_off, kw, pattern", [
    (-FIVE, FIVE, {}, r"n_on must be finite event counts"),
    (np.full((12, 12), np.nan), FIVE, {}, r"n_on must be" + OLD_COUNTS),
    (FIVE, "abc", {}, r"n_off must be event counts"),
    (FIVE, FIVE, {"min_events": -1}, r"min_events= must be a finite number >= 0"),
    (FIVE, FIVE, {"min_events": np.nan}, r"min_events= must be a finite number >= 0")])
def test_balance_from_counts_refuses_counts_that_are_no_counts(n_on, n_off, kw, pattern):
    _no(lambda: balance.balance_from_counts(n_on, n_off, 0.2, **kw), pattern)


def test_guard_the_balance_keeps_its_counts_and_fits():
    counts = balance.PolarityCounts((np.int64(12), 12), decay=np.float32(0.5)).update(EV)
    assert counts.sensor_size == (12, 12) and counts.decay == 0.5
    assert balance.interval_stride((1280, 720)) == 4 and balance.interval_stride([12, 12]) == 1
    assert balance.span_slices(0.0, 0.0, np.int64(2)).shape == (3,)                   # one instant: 1 us apart
    assert balance.span_slices(np.float32(0.0), 1, np.int64(8)).shape == (9,)
    *sums, last_t, last_p = balance.interval_sums(EV.take(slice(0, len(EV) // 2)))
    again = balance.interval_sums(EV.take(slice(len(EV) // 2, None)), last=(last_t, last_p))
    assert np.isfinite(again[0]).all()
    fit = balance.balance_from_counts(FIVE.astype(np.int64), FIVE.astype(np.float32), 0.2, min_events=np.int64(2))
    assert fit.C == (0.2, 0.2)
    assert balance.slice_counts(EV, np.array([0, 1], np.int64))[0].shape == (1, 12, 12)


@pytest.mark.parametrize("call, size", [(lambda: balance.span_slices(0.0, 1.0, 8.0), 9),
                                        (lambda: sample_thresholds(4.0, 0.2, 0.2)[0], 4),
                                        (lambda: balance.PolarityCounts((12, 12.0)).update(EV).n_on, 144)],
                         ids=["span_slices k=8.0", "sample_thresholds n_pixels=4.0", "PolarityCounts W=12.0"])
def test_a_whole_float_count_is_taken(call, size):
    # Python's "'float' object cannot be interpreted as an integer" before: a count given as 8.0 is 8
    assert np.size(call()) == size


# ---- 5. the simulator's thresholds, the zoo and the colour recording's writer (evinr_lite.sim) ---------------------

@pytest.mark.parametrize("args, kw, pattern", [
    ((-1, 0.2, 0.2), {}, r"n_pixels= must be a whole number >= 0"), ((2.5, 0.2, 0.2), {}, r"n_pixels= must be a whole"),
    (("3", 0.2, 0.2), {}, r"n_pixels= must be a whole"), ((None, 0.2, 0.2), {}, r"n_pixels= must be a whole"),
    ((3, np.nan, 0.2), {}, r"threshold C_pos must be a positive number"), ((3, -0.2, 0.2), {}, r"C_pos must be"),
    ((3, "0.2", 0.2), {}, r"C_pos must be"), ((3, 0.2, 0.0), {}, r"threshold C_neg must be a positive number"),
    ((3, 0.2, 0.2, np.nan), {}, r"threshold_sigma= must be a finite number >= 0"),
    ((3, 0.2, 0.2, -1), {}, r"threshold_sigma= must be"), ((3, 0.2, 0.2, "0.1"), {}, r"threshold_sigma= must be"),
    ((3, 0.2, 0.2, 0.1), {"rng": 5}, r"rng= must be Generator")])
def test_sample_thresholds_refuses_what_is_no_threshold_or_count(args, kw, pattern):
    _no(lambda: sample_thresholds(*args, **kw), pattern)


def test_guard_sample_thresholds_keeps_its_draws():
    pos, neg = sample_thresholds(np.int64(3), np.float32(0.2), 0.3)
    assert np.allclose(pos, 0.2) and np.allclose(neg, 0.3) and sample_thresholds(0, 0.2, 0.2)[0].shape == (0,)
    a = sample_thresholds(4, 0.2, 0.2, 0.05, rng=np.random.default_rng(1))
    b = sample_thresholds(np.int64(4), 0.2, 0.2, np.float64(0.05), rng=np.random.default_rng(1))
    assert np.array_equal(a[0], b[0])
    _no(lambda: sample_thresholds(3, 0.2, 0.2, 0.1), r"needs a generator")                  # as before


@pytest.mark.parametrize("seed, n, pattern", [("0", 2, r"seed= must be a whole number"),
                                              (np.nan, 2, r"seed= must be a whole number"),
                                              (-1, 2, r"seed= must be a whole number >= 0"),
                                              (0, -1, r"n= must be a whole number >= 0"),
                                              (0, 2.5, r"n= must be a whole number"),
                                              (0, "3", r"n= must be a whole number")])
def test_fresh_scenes_refuse_a_seed_or_count_that_is_no_whole_number(seed, n, pattern):
    _no(lambda: zoo.fresh(seed, n), pattern)


@pytest.mark.parametrize("fn", [zoo.quick, zoo.simulate, zoo.imbalance, zoo.effective_C])
@pytest.mark.parametrize("z", ["bar_pan", None])
def test_the_zoo_helpers_refuse_a_name_where_a_scene_belongs(fn, z):
    _no(lambda: fn(z), r"z= must be ZooScene")


@pytest.mark.parametrize("long", ["no", None, 2])
def test_default_scenes_refuse_a_flag_that_is_no_flag(long):
    _no(lambda: zoo.default_scenes(long), r"long= must be True or False")


def test_guard_the_zoo_keeps_its_scenes():
    assert len(zoo.fresh(np.int64(3), 2.0)) == 2 and zoo.fresh(0, 0) == []
    z = zoo.ZOO[0]
    assert zoo.quick(z).duration <= z.duration and zoo.imbalance(z) == zoo.imbalance(z)
    assert zoo.default_scenes(np.bool_(True)) == zoo.default_scenes(1) and len(zoo.default_scenes(0)) <= len(zoo.ZOO)


@pytest.mark.parametrize("out", [None, 5, b"x.h5", ["x.h5"]])
def test_the_colour_recording_writer_refuses_a_path_that_is_no_path(out):
    _no(lambda: write_colour_davis_recording(out, sensor_size=(8, 8), duration=0.1), r"out= must be", TypeError)


@pytest.mark.parametrize("overwrite", ["no", 2, "False"])
def test_the_colour_recording_writer_keeps_a_users_file_on_an_overwrite_that_is_no_flag(overwrite, tmp_path):
    mine = tmp_path / "mine.h5"
    mine.write_text("keep me")
    _no(lambda: write_colour_davis_recording(mine, sensor_size=(8, 8), duration=0.1, overwrite=overwrite),
        r"overwrite= must be True or False")
    assert mine.read_text() == "keep me"


def test_guard_the_colour_recording_writer_still_writes_and_replaces(tmp_path):
    out = write_colour_davis_recording(tmp_path / "c.h5", sensor_size=(8, 8), duration=0.1)
    assert out.exists()
    _no(lambda: write_colour_davis_recording(str(out), sensor_size=(8, 8), duration=0.1), r"already exists")
    assert write_colour_davis_recording(out, sensor_size=(8, 8), duration=0.1, overwrite=np.bool_(True)) == out


# ---- 6. the scorer's LPIPS model ----------------------------------------------------------------------------------

@pytest.mark.parametrize("model", [True, 5, 1.5, {}, [1]])
def test_scoring_refuses_an_lpips_model_that_is_no_model(model):
    _no(lambda: score_sequence(GT, TIMES, GT, TIMES, lpips_model=model), r"lpips_model must be .*an LPIPS model")


def test_evaluate_refuses_an_lpips_model_that_is_no_model():
    _no(lambda: evaluate(EV, GT[:, :12, :12], [0.05, 0.1, 0.15], methods=["hf"], lpips_model=True),
        r"lpips_model must be")


def test_guard_scoring_without_lpips_and_with_a_module():
    import torch

    class Zero(torch.nn.Module):   # any torch module is taken as the model, as before
        def forward(self, a, b):
            return torch.zeros(len(a), 1, 1, 1) + self.w

        def __init__(self):
            super().__init__()
            self.w = torch.nn.Parameter(torch.zeros(()))

    assert score_sequence(GT, TIMES, GT, TIMES, lpips_model=False)["lpips"] is None
    assert score_sequence(GT, TIMES, GT, TIMES, lpips_model=Zero())["lpips"] == 0.0


# ---- 7. the figures: a reconstruction of one pixel, and an ax that is no Axes --------------------------------------

T10 = np.linspace(0, 1, 10)


@pytest.mark.parametrize("curves", [None, [np.ones(10)], "abc"])
def test_plot_reconstruction_1d_refuses_curves_that_are_no_dict(curves):
    _no(lambda: plot_reconstruction_1d(T10, curves), r"curves= must be a dict", TypeError)


@pytest.mark.parametrize("t, curves, truth, pattern", [
    (T10, {"a": np.ones(5)}, None, r"curves\['a'\] holds 5 values but t holds 10"),
    (T10, {"a": np.ones(10)}, np.ones(3), r"truth holds 3 values"),
    (None, {"a": np.ones(10)}, None, r"t= must be seconds"),
    (T10, {"a": "abcdefghij"}, None, r"curves\['a'\] must be numbers"),
    (T10, {"a": None}, None, r"curves\['a'\] must be numbers")])
def test_plot_reconstruction_1d_refuses_curves_that_do_not_fit_the_times(t, curves, truth, pattern):
    _no(lambda: plot_reconstruction_1d(t, curves, truth), pattern)


def _figure_calls(ax):
    return [lambda: plot_count_map(EV, ax=ax), lambda: plot_polarity(EV, ax=ax),
            lambda: plot_event_rate(EV, 0.01, ax=ax), lambda: plot_boundaries(EV, {"a": [0.0, 0.1, 0.3]}, ax=ax),
            lambda: plot_signal_and_events(T10, np.sin(T10), ([], []), ax=ax),
            lambda: plot_reconstruction_1d(T10, {"a": np.ones(10)}, ax=ax),
            lambda: plot_window_errors({"window": [0.1, 0.2], "taylor": [1.0, 2.0]}, ax=ax)]


@pytest.mark.parametrize("which", range(7))
@pytest.mark.parametrize("ax", ["figure", 5, "axes array"])
def test_the_figures_refuse_an_ax_that_is_no_axes(which, ax):
    if ax == "figure":
        ax = plt.figure()
    elif ax == "axes array":
        ax = plt.subplots(1, 2)[1]
    _no(_figure_calls(ax)[which], r"ax= must be a matplotlib Axes", TypeError)


def test_guard_the_figures_draw_on_given_axes_or_a_new_one():
    fig, axes = plt.subplots(1, 2)
    for call in _figure_calls(axes[0]) + _figure_calls(None):
        assert call() is not None
    assert plot_reconstruction_1d([0, 1, 2], {"a": [1, 2, 3], "b": np.ones((3, 2))}, truth=(0, 1, 2)) is not None


# ---- 8. recordings that are valid files but degenerate for the method ---------------------------------------------

def _events(t, x, y, p, size):
    return Events.from_arrays(np.asarray(t, float), np.asarray(x), np.asarray(y), np.asarray(p), sensor_size=size)


RNG = np.random.default_rng(0)
N = 2000
TT = np.sort(RNG.uniform(0, 1, N))
PP = RNG.integers(0, 2, N) * 2 - 1
FAST = EvINRConfig(n_iters=2, progress=False)


def test_a_one_pixel_sensor_at_one_time_is_a_result_not_a_failed_setting():
    # one value cannot vary: it was refused as "constant frames although the input varies; check C"
    rec = reconstruct(_events(TT, np.zeros(N, int), np.zeros(N, int), PP, (1, 1)), [0.5], FAST)
    assert rec.frames.shape == (1, 1, 1) and np.isfinite(rec.frames).all()


@pytest.mark.parametrize("case", ["all ON", "all OFF", "1 x N", "N x 1", "1 x 1 at several times"])
def test_guard_degenerate_recordings_that_reconstruct(case):
    x, y = RNG.integers(0, 20, N), RNG.integers(0, 16, N)
    events = {"all ON": lambda: _events(TT, x, y, np.ones(N), (16, 20)),
              "all OFF": lambda: _events(TT, x, y, -np.ones(N), (16, 20)),
              "1 x N": lambda: _events(TT, RNG.integers(0, 50, N), np.zeros(N, int), PP, (1, 50)),
              "N x 1": lambda: _events(TT, np.zeros(N, int), RNG.integers(0, 50, N), PP, (50, 1)),
              "1 x 1 at several times": lambda: _events(TT, np.zeros(N, int), np.zeros(N, int), PP, (1, 1))}[case]()
    rec = reconstruct(events, [0.2, 0.5, 0.8], FAST)
    assert np.isfinite(rec.frames).all() and rec.frames.shape[1:] == tuple(events.sensor_size)


@pytest.mark.parametrize("case, pattern", [
    ("one timestamp", r"time span \[0.5, 0.5\] is empty"),
    ("ten-hour gap", r"cuts the span of 36001 s into 8,001 windows"),
    ("one pixel", r"background filter left 0 of 2,000 events"),
    ("backwards by 0.1 ms", r"timestamps are not sorted")])
def test_guard_degenerate_recordings_that_are_refused_clearly(case, pattern):
    x, y = RNG.integers(0, 20, N), RNG.integers(0, 16, N)

    def make():
        if case == "one timestamp":
            return _events(np.full(N, 0.5), x, y, PP, (16, 20)), [0.5]
        if case == "ten-hour gap":
            return _events(np.concatenate([TT[:N // 2], TT[N // 2:] + 36000]), x, y, PP, (16, 20)), [0.5]
        if case == "one pixel":
            return _events(TT, np.zeros(N, int), np.zeros(N, int), PP, (16, 20)), [0.5]
        back = TT.copy()
        back[500] = back[499] - 1e-4
        return _events(back, x, y, PP, (16, 20)), [0.5]

    def run():
        events, times = make()
        return reconstruct(events, times, FAST)

    _no(run, pattern)


# ---- 9. the review's fixes: what the round's checks refused that worked before, and its copies ----------------------

def _message(fn):
    with pytest.raises(ValueError) as info:
        fn()
    return str(info.value)


@pytest.mark.parametrize("t, curve", [
    (torch.linspace(0, 20, 500), torch.sin(torch.linspace(0, 20, 500))),     # float32 at 20 s: a plot, no timestamps
    (np.r_[0.0, 0.5, np.nan, 1.0], [1, 2, 3, 4]),                            # NaN: matplotlib's gap in the line
    (np.linspace(0, 1, 10).astype(np.float16), np.ones(10))],
    ids=["float32 at 20 s", "NaN gap", "float16"])
def test_plot_reconstruction_1d_draws_the_times_it_drew_before(t, curve):
    # seconds_array (event timestamps' float32 precision check, no NaN) refused them
    assert plot_reconstruction_1d(t, {"fit": curve}, curve).get_lines()


def test_guard_plot_reconstruction_1d_still_refuses_times_that_are_no_1d_numbers():
    _none_of([lambda: plot_reconstruction_1d(np.zeros((10, 1)), {"a": np.ones(10)}),
              lambda: plot_reconstruction_1d(["a"] * 10, {"a": np.ones(10)})], r"t= must be (a 1-D array of )?seconds")


N600 = np.random.default_rng(0).integers(5, 50, 600).astype(float)


@pytest.mark.parametrize("shape", [(600,), (2, 10, 30)])
def test_balance_from_counts_takes_counts_of_any_one_shape_without_slices(shape):
    # 1-D counts fitted before the round ([H, W] was asked of every call); only the slices' edges need a sensor
    n_on, n_off = N600.reshape(shape), 1.1 * N600.reshape(shape)
    fit = balance.balance_from_counts(n_on, n_off, 0.2)
    assert fit.applied and fit.raw_imbalance == pytest.approx(balance.balance_from_counts(
        n_on.reshape(20, 30), n_off.reshape(20, 30), 0.2, rule="counts").raw_imbalance)


def test_guard_balance_from_counts_with_slices_still_asks_for_one_sensor():
    sliced = (np.ones((2, 600)), np.ones((2, 600)))
    _no(lambda: balance.balance_from_counts(N600, N600, 0.2, sliced=sliced), r"\[H, W\]")


def test_sample_thresholds_takes_a_random_state_and_per_pixel_thresholds():
    # a RandomState (np.random's legacy generator) drew before: only Generator was taken
    pos, neg = sample_thresholds(4, 0.2, 0.2, 0.05, np.random.RandomState(0))
    draw = np.random.RandomState(0).standard_normal(8)
    assert np.allclose(pos, 0.2 * (1 + 0.05 * draw[:4])) and np.allclose(neg, 0.2 * (1 + 0.05 * draw[4:]))
    pos, neg = sample_thresholds(3, np.array([0.2, 0.3, 0.4]), np.float32(0.2))   # one C per pixel, as before
    assert np.allclose(pos, [0.2, 0.3, 0.4]) and np.allclose(neg, 0.2)
    assert np.allclose(sample_thresholds(3, Decimal("0.25"), 0.2)[0], 0.25)        # float() took it


@pytest.mark.parametrize("c, pattern", [(1e-4, "far below any sensor"), (np.array([0.2, 1e-4, 0.2]), "far below any"),
                                        (np.array([0.2, 0.2]), r"one per pixel: a 1-D array of 3"),
                                        (np.array([0.2, np.nan, 0.2]), r"C_pos must be a positive number")])
def test_sample_thresholds_checks_its_thresholds_by_the_simulators_rule(c, pattern):
    # the simulators' one rule, MIN_C included (1e-4 was taken here and refused by simulate_events_1d)
    _no(lambda: sample_thresholds(3, c, 0.2), pattern)


@pytest.mark.parametrize("seed, same_as", [(np.random.SeedSequence(3), 3), ([3], 3), (np.array([3]), 3)])
def test_fresh_takes_the_seeds_numpy_takes(seed, same_as):
    # a SeedSequence or a list of ints seeded numpy's generator before; the same seed draws the same scenes
    assert [z.name for z in zoo.fresh(seed, 2)] == [z.name for z in zoo.fresh(same_as, 2)]


def test_fresh_names_a_list_seed_by_its_numbers():
    scenes = zoo.fresh([1, 2], 1)
    assert scenes[0].name.startswith("fresh1-2_00_")
    assert zoo.fresh(np.random.SeedSequence(5, spawn_key=(1,)), 1)[0].name.startswith("fresh5s1_00_")


@pytest.mark.parametrize("seed", [None, np.random.default_rng(0), [], [-1], ["0"]],
                         ids=["None", "Generator", "empty list", "[-1]", "['0']"])
def test_guard_fresh_refuses_seeds_that_name_no_scene(seed):
    _no(lambda: zoo.fresh(seed, 1), r"seed= (must be a whole number|is an empty list)")


def test_span_slices_and_min_events_take_a_decimal():
    # float() took a Decimal before the round's number checks
    assert np.allclose(balance.span_slices(Decimal("0"), Decimal("1"), 4), [0, 0.25, 0.5, 0.75, 1])
    assert balance.balance_from_counts(FIVE, FIVE, 0.2, min_events=Decimal("4")).C == (0.2, 0.2)


def _more_figure_calls(ax):
    row = {"ssim_clahe": 0.5, "train_time_s": 1.0, "name": "x"}
    return [lambda: plot_histories({"a": [1.0, 0.5]}, ax=ax), lambda: plot_tradeoff([row], ax=ax),
            lambda: plot_xyt(EV, ax=ax)]


@pytest.mark.parametrize("which", range(3), ids=["plot_histories", "plot_tradeoff", "plot_xyt"])
@pytest.mark.parametrize("ax", ["figure", "axes array"])
def test_the_other_figures_refuse_an_ax_that_is_no_axes(which, ax):
    ax = plt.figure() if ax == "figure" else plt.subplots(1, 2)[1]
    _no(_more_figure_calls(ax)[which], r"ax= must be a (3-D )?matplotlib Axes", TypeError)


def test_plot_xyt_refuses_2d_axes_by_name():
    _no(lambda: plot_xyt(EV, ax=plt.subplots()[1]), r"projection='3d'.*fig\.add_subplot\(projection='3d'\)", TypeError)


def test_guard_the_other_figures_draw_on_given_axes_or_a_new_one():
    axes = [plt.subplots()[1], plt.subplots()[1], plt.figure().add_subplot(projection="3d")]
    for call in _more_figure_calls(None) + [_more_figure_calls(ax)[i] for i, ax in enumerate(axes)]:
        assert call() is not None


@pytest.mark.parametrize("fig", ["figure", "subfigure"])
def test_an_empty_figure_is_told_to_add_axes_not_to_index_them(fig):
    # "e.g. fig.axes[0]" was an IndexError on a figure without axes; a SubFigure got no hint at all
    fig = plt.figure() if fig == "figure" else plt.figure().subfigures(1, 2)[0]
    text = _message(lambda: plot_count_map(EV, ax=fig))
    assert "add_subplot()" in text and "axes[0]" not in text


def test_polarity_counts_refuse_an_infinite_slice_edge_when_made():
    # taken at construction and refused at the first update as slice_counts' edges
    _no(lambda: balance.PolarityCounts((12, 12), slices=[0.0, np.inf]), r"^slices must be finite")


def test_the_count_pairs_are_checked_by_one_rule():
    # four copies of "two counts of one [H, W] shape" (and smoothing's copy of check_counts) said it four ways
    shapes = [_message(lambda: fn(FIVE, np.ones((5, 5)))) for fn in
              (tempo_pair, plan_pair, balance_pair, smoothing_pair)]
    assert all(re.search(r"must be (\[H, W\] )?counts of one shape .*got shapes \(12, 12\) and \(5, 5\)", m)
               for m in shapes), shapes
    nans = [_message(lambda: fn(np.full((12, 12), np.nan), FIVE)) for fn in (plan_pair, balance_pair, smoothing_pair)]
    assert len({m.split("n_on ", 1)[1] for m in nans}) == 1, nans


def tempo_pair(a, b):
    return tempo.flip_rate(a, b, 1.0)


def plan_pair(a, b):
    return plan_from_counts(a, b, CFG)


def balance_pair(a, b):
    return balance.balance_from_counts(a, b, 0.2, sliced=(np.ones((2, *np.shape(a))),) * 2)


def smoothing_pair(a, b):
    return auto_lam(a, b)


@pytest.mark.parametrize("call", [lambda: EvINRConfig(temporal_scale=0), lambda: EvINRConfig(temporal_scale=-1.0),
                                  lambda: RunOptions(temporal_scale=0.0), lambda: temporal_scale_option(-2)],
                         ids=["config 0", "config -1", "RunOptions 0", "option -2"])
def test_a_scale_of_zero_is_told_the_range_not_positive(call):
    # "must be positive" / "a number > 0", and then 0.001 was refused by the floor
    _no(call, r"a number from 1/64 \(tempo\.MIN_SCALE\) up")


def test_the_command_tells_the_range_of_a_zero_scale(capsys):
    with pytest.raises(SystemExit):
        cli.build_parser().parse_args(["reconstruct", "x.h5", "--out", "o", "--temporal-scale", "0"])
    assert "a number from 1/64 up" in capsys.readouterr().err
