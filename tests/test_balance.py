"""The ON/OFF balance estimated from events alone (evinr_lite.method.balance) and its hook in reconstruct."""
import numpy as np
import pytest

from evinr_lite.core.events import EventDataError, Events
from evinr_lite.method import EvINRConfig, reconstruct
from evinr_lite.method.balance import (MAX_INTERVAL_PIXELS, PolarityCounts, balance_from_counts, estimate_balance,
                                       gradient_imbalance, interval_stride, interval_sums, minmod, polarity_counts,
                                       slice_counts, span_slices)
from evinr_lite.method.prepare import prepare_events
from evinr_lite.sim.scenes import LightingScene, MovingImageScene, OscillatingScene
from evinr_lite.sim.simulate import add_hot_pixels, simulate_scene

SIZE = (30, 40)


def _scene(duration=20.0):
    return OscillatingScene("astronaut", SIZE, duration, path=((12.0, 4.0, 4.0, 0.0), (2.0, 3.0, 1.3, 1.0)))


@pytest.fixture(scope="module")
def unequal():
    """20 s to and fro, C+ 0.25 and C- 0.20 (true imbalance (0.25 - 0.20) / 0.45 = 0.111)."""
    return simulate_scene(_scene(), C=0.225, C_pos=0.25, C_neg=0.20, seed=0)


def test_long_span_recovers_the_true_pair(unequal):
    fit = estimate_balance(unequal, 0.225)
    assert fit.applied and fit.shrink > 0.8
    assert fit.raw_imbalance == pytest.approx(0.05 / 0.45, abs=0.01)
    assert fit.C[0] == pytest.approx(0.25, abs=0.006) and fit.C[1] == pytest.approx(0.20, abs=0.006)
    assert 0.5 * (fit.C[0] + fit.C[1]) == pytest.approx(0.225)          # the nominal C stays the mean


def test_equal_thresholds_give_no_imbalance():
    ev = simulate_scene(_scene(), C=0.2, seed=1)
    assert abs(estimate_balance(ev, 0.2).imbalance) < 0.01


def test_on_only_hot_pixels_are_left_out(unequal):
    hot_ev, hot = add_hot_pixels(unequal, 8, 40.0, seed=2, on_only=True)
    on, off = polarity_counts(hot_ev)
    naive = (off.sum() - on.sum()) / (on.sum() + off.sum())
    fit = estimate_balance(hot_ev, 0.225)
    assert fit.n_hot >= 8
    assert abs(fit.raw_imbalance - 0.111) < 0.01 < abs(naive - 0.111)    # the naive pool is pulled towards ON


def test_the_counts_rule_shrinks_short_spans_towards_the_nominal_C(unequal):
    short = estimate_balance(unequal.slice_time(0.0, 0.5), 0.225, rule="counts")
    whole = estimate_balance(unequal, 0.225, rule="counts")
    assert short.rule == "counts" and np.isnan(short.interval_imbalance)
    assert short.shrink < whole.shrink and abs(short.imbalance) < abs(whole.imbalance)


def test_a_given_pair_is_kept_and_bad_counts_are_refused(unequal):
    fit = estimate_balance(unequal, (0.3, 0.1))
    assert not fit.applied and fit.C == (0.3, 0.1)
    with pytest.raises(EventDataError, match="same shape"):
        balance_from_counts(np.zeros((2, 3)), np.zeros((3, 2)), 0.2)
    few = Events.from_arrays([0.0, 1.0], [0, 1], [0, 0], [1, -1], SIZE)
    assert not estimate_balance(few, 0.2).applied                      # too few pixels fired: nominal C


def test_running_counts_match_one_span(unequal):
    counts = PolarityCounts(SIZE)
    for a in np.arange(0.0, 20.0, 3.0):
        counts.update(unequal.slice_time(a, a + 3.0, allow_empty=True))
    whole = interval_sums(unequal)
    for chunked, one in zip((*counts.intervals, *counts.last), whole):   # intervals across chunk edges count
        np.testing.assert_array_equal(chunked, one)
    assert counts.fit(0.225).C == estimate_balance(unequal, 0.225).C
    with pytest.raises(EventDataError, match="decay"):
        PolarityCounts(SIZE, decay=0.0)


def test_prepare_events_returns_a_copy_and_the_paper_recipe_keeps_C(unequal):
    cfg = EvINRConfig(C=0.225, balance="events", hot_pixels="drop", progress=False)
    ev, new = prepare_events(unequal, cfg)
    assert cfg.C == 0.225 and new.C[0] > new.C[1]
    paper = EvINRConfig.paper(C=0.225)
    assert paper.balance == "none" and paper.hot_pixels == "keep"
    assert prepare_events(unequal, paper)[1].C == 0.225
    with pytest.raises(EventDataError, match="balance"):
        EvINRConfig(balance="frames")


def test_balance_removes_the_drift_of_a_long_recording(unequal):
    """Integrated with one C, the level drifts with the event count; with the balance it does not."""
    scene = _scene()
    times = np.linspace(1.0, 19.0, 10)
    truth = scene.log_intensity(times).mean(axis=(1, 2))

    def drift(balance):
        rec = reconstruct(unequal, times, EvINRConfig(C=0.225, balance=balance, hidden_features=64, progress=False),
                          t_start=0.0, t_end=20.0)
        err = rec.log_intensity.mean(axis=(1, 2)) - truth
        return abs(err[-1] - err[0])

    assert drift("events") < 0.5 * drift("none")


def test_a_streamed_source_gets_the_same_plan_as_the_whole_span(unequal):
    from evinr_lite.io.source import MemorySource
    from evinr_lite.method.prepare import prepare_source

    hot_ev, hot = add_hot_pixels(unequal, 8, 400.0, seed=2, on_only=True)
    cfg = EvINRConfig(C=0.225, tau=5.0, progress=False)
    ev, whole = prepare_events(hot_ev, cfg)
    streamed, source = prepare_source(MemorySource(hot_ev), 0.0, float(hot_ev.t[-1]), cfg)
    assert streamed.C == whole.C
    np.testing.assert_array_equal(source.events(0.0, 30.0).t, ev.t)
    assert len(ev) < len(hot_ev)                                       # the hot pixels were dropped


def test_the_priors_spread_is_the_zoos_imbalance():
    """PRIOR is the root mean square of the imbalance simulated over the zoo (benchmarks/balance.py
    prints it with NET_CHANGE's counterpart, which needs the scenes simulated)."""
    from evinr_lite.method.balance import PRIOR
    from evinr_lite.sim.zoo import default_scenes, imbalance

    b = [imbalance(z) for z in default_scenes(long=True)]
    assert PRIOR == pytest.approx(float(np.sqrt(np.mean(np.square(b)))), abs=0.02)


def test_balance_benchmark_row_reads_a_scene():
    """benchmarks/balance.py on one quick zoo scene: both estimates find its C+ != C-."""
    from benchmarks.balance import scene_row
    from evinr_lite.sim.zoo import ZOO, quick

    z = quick(next(s for s in ZOO if s.name == "noisy_gravel"))
    row = scene_row(z)
    assert row["b_true"] == pytest.approx(0.1, abs=1e-9)
    assert abs(row["raw"] - row["b_true"]) < 0.03 and row["interval"] > 0 and 0 < row["shrink"] < 1
    assert row["applied"] == min(row["gradient"], row["interval"])       # they agree: the one nearer 0
    assert abs(row["counts_rule"]) < abs(row["raw"])


def _translation(duration=2.0):
    return MovingImageScene("camera", SIZE, duration, velocity=(8.0, 3.0))


def test_the_consensus_finds_an_imbalance_that_the_counts_rule_shrinks_away():
    """2 s of translation, C+ 0.24 and C- 0.16 given as 0.2 (b = 0.2): few events per pixel, so the
    counts rule keeps little of it; the counts and the intervals agree, and the consensus takes it."""
    ev = simulate_scene(_translation(), C=0.2, C_pos=0.24, C_neg=0.16, seed=0)
    fit, old = estimate_balance(ev, 0.2), estimate_balance(ev, 0.2, rule="counts")
    assert fit.rule == "consensus" and fit.raw_imbalance > 0 and fit.interval_imbalance > 0
    assert abs(fit.imbalance - 0.2) < 0.05 < abs(old.imbalance - 0.2)


@pytest.mark.parametrize("scene", ["translation", "oscillation"])
def test_a_change_of_light_is_not_read_as_an_imbalance(scene):
    """Equal thresholds while the light falls by e^-0.8: more OFF than ON events, which the counts read
    as C+ > C-; the slow falls of the light lengthen the OFF intervals, which the intervals read the
    other way. The two disagree, and the consensus keeps the nominal C."""
    base = _translation() if scene == "translation" else _scene(2.0)
    ev = simulate_scene(LightingScene(base, global_change=-0.8, vignette=0.0), C=0.2, seed=0)
    fit = estimate_balance(ev, 0.2)
    assert fit.raw_imbalance > 0.2 and fit.interval_imbalance < 0
    assert fit.imbalance == 0.0 and fit.C == (0.2, 0.2)
    assert estimate_balance(ev, 0.2, rule="counts").imbalance > 0.05          # the counts rule applies some


def test_interval_sums_time_the_runs_of_one_polarity():
    """Pixel (0, 0): ON at 0, 0.1, 0.3, OFF at 0.4, 0.45: ON-ON intervals 0.1 and 0.2, OFF-OFF 0.05; the
    ON -> OFF step is no interval. Pixel (0, 1): one event, no pair."""
    ev = Events.from_arrays([0.0, 0.1, 0.2, 0.3, 0.4, 0.45], [0, 0, 1, 0, 0, 0], [0, 0, 0, 0, 0, 0],
                            [1, 1, -1, 1, -1, -1], (2, 2))
    log_on, k_on, log_off, k_off, last_t, last_p = interval_sums(ev)
    assert k_on[0, 0] == 2 and k_off[0, 0] == 1 and k_on[0, 1] == k_off[0, 1] == 0
    assert log_on[0, 0] == pytest.approx(np.log(0.1) + np.log(0.2), abs=1e-4)
    assert log_off[0, 0] == pytest.approx(np.log(0.05), abs=1e-4)
    assert last_t[0, 0] == 0.45 and last_p[0, 0] == -1 and last_p[0, 1] == -1 and np.isnan(last_t[1, 1])


def test_minmod_and_bad_arguments():
    assert minmod(0.2, 0.1) == 0.1 and minmod(-0.05, -0.3) == -0.05 and minmod(0.2, -0.1) == 0.0
    assert minmod(0.2, 0.1, 0.15) == 0.1 and minmod(-0.2, -0.3, -0.25) == -0.2 and minmod(-0.1, -0.2, 0.05) == 0.0
    n = np.ones((10, 10))
    with pytest.raises(EventDataError, match="rule must be one of"):
        balance_from_counts(n, n, 0.2, rule="frames")
    with pytest.raises(EventDataError, match="intervals must be four arrays"):
        balance_from_counts(n, n, 0.2, intervals=(n, n))
    fit = balance_from_counts(n, n, 0.2)                    # counts alone: the consensus cannot be formed
    assert fit.rule == "counts"
    for bad in (-0.1, 1.0, float("nan"), "0.3"):
        with pytest.raises(EventDataError, match="max_imbalance must be a number in"):
            balance_from_counts(n, n, 0.2, max_imbalance=bad)


def test_the_configs_balance_counts_is_the_rule_before_the_intervals():
    ev = simulate_scene(_translation(), C=0.2, C_pos=0.24, C_neg=0.16, seed=0)
    for mode, rule in (("events", "consensus"), ("counts", "counts")):
        _, cfg = prepare_events(ev, EvINRConfig(C=0.2, balance=mode, background="keep", hot_pixels="keep",
                                                progress=False))
        assert cfg.C == estimate_balance(ev, 0.2, rule=rule).C


def test_large_sensors_time_a_grid_of_pixels():
    """Above MAX_INTERVAL_PIXELS the intervals come from every s-th row and column: on a 2 x 2 tiling
    of a small recording (300 x 400 pixels, stride 2) each tile's grid pixels give that tile's own
    intervals, and chunks still add up to the whole span."""
    assert interval_stride((180, 240)) == 1 and interval_stride((720, 1280)) == 4
    assert -(-720 // 4) * -(-1280 // 4) <= MAX_INTERVAL_PIXELS
    small = simulate_scene(_translation(), C=0.2, C_pos=0.24, C_neg=0.16, seed=0)      # 30 x 40
    big = Events.from_arrays(small.t, small.x * 10, small.y * 10, small.p, (300, 400))  # every 10th pixel
    assert interval_stride(big.sensor_size) == 2
    log_on, k_on, log_off, k_off, *_ = interval_sums(big)
    ref = interval_sums(small)
    np.testing.assert_array_equal(k_on[::10, ::10], ref[1])
    np.testing.assert_array_equal(log_off[::10, ::10], ref[2])
    assert k_on.sum() == ref[1].sum()                       # every event sits on the stride-2 grid
    counts = PolarityCounts(big.sensor_size)
    for a in (0.0, 0.7, 1.4):
        counts.update(big.slice_time(a, a + 0.7 if a < 1.4 else 2.1, allow_empty=True))
    for chunked, one in zip(counts.intervals, interval_sums(big)):
        np.testing.assert_array_equal(chunked, one)


def test_balance_benchmark_times_the_intervals_against_the_counts():
    from benchmarks.balance import speed

    r = speed(n_events=20_000, sensor_size=(300, 400))
    assert r["stride"] == 2 and r["interval_sums"] > 0 and r["ratio"] == r["interval_sums"] / r["polarity_counts"]


def test_off_heavy_scenes_have_C_minus_above_C_plus():
    """benchmarks/balance.py --off-heavy: a pair swapped where it differs, b = -0.15 where C+ = C-, the
    nominal C kept and another seed."""
    from benchmarks.balance import OFF_HEAVY_B, off_heavy
    from evinr_lite.sim.zoo import effective_C, get, imbalance

    for name in ("coffee_warp", "camera_translate"):
        z, o = get(name), off_heavy(get(name))
        assert o.C_neg > o.C_pos and o.seed != z.seed and effective_C(o) == pytest.approx(effective_C(z))
        assert imbalance(o) == pytest.approx(-abs(imbalance(z)) if imbalance(z) else OFF_HEAVY_B)


def _interval_arrays(shape, log_on, log_off, k=20):
    """Interval sums whose mean log ON and OFF intervals are ``log_on`` and ``log_off`` at every pixel."""
    k_arr = np.full(shape, float(k))
    return (k_arr * log_on, k_arr, k_arr * log_off, k_arr)


def _counts_with(b, n, light, C):
    """n_on, n_off [H, W] with n = n_on + n_off and n_off - n_on = b n - light / C at every pixel (the
    relation C+ n+ - C- n- = light for C+- = C (1 +- b))."""
    d = b * n - light / C
    return (n - d) / 2, (n + d) / 2


def test_busy_spans_take_the_counts_alone_unless_the_intervals_contradict_them():
    """The counts' error scale s = NET_CHANGE / (C mean n) shrinks as events accumulate; the intervals'
    bias does not. At s <= COUNTS_ALONE the counts are used alone, fitted with an intercept, so a change
    of light common to every pixel (here -0.7 log units, which pulls the pooled counts off b) is not
    read as an imbalance (b = -0.15 while the intervals read -0.01: the minmod would keep -0.01); with
    few events the minmod decides; and intervals that differ from the counts by more than MAX_IMBALANCE
    send it back to the minmod."""
    from evinr_lite.method.balance import COUNTS_ALONE, MAX_IMBALANCE, NET_CHANGE

    C, b, light = 0.2, -0.15, -0.7
    rows = np.linspace(0.5, 1.5, 20)[:, None] * np.ones((1, 20))      # event counts vary over the sensor
    small_r = 2 * np.arctanh(-0.01)                         # the intervals read b = -0.01
    for scale, expect, change in ((200.0, "counts", light), (10.0, "minmod", 0.0)):
        n = scale * rows
        n_on, n_off = _counts_with(b, n, change, C)
        fit = balance_from_counts(n_on, n_off, C, intervals=_interval_arrays(n.shape, small_r, 0.0))
        assert fit.counts_error == pytest.approx(NET_CHANGE / (C * n.mean()))
        assert (fit.counts_error <= COUNTS_ALONE) == (expect == "counts") and fit.chosen == expect
        assert fit.slope_imbalance == pytest.approx(b, abs=1e-9)
        assert (abs(fit.raw_imbalance - b) > 0.01) == (change != 0)   # the pooled counts carry the light's change
        assert fit.imbalance == pytest.approx(b if expect == "counts" else -0.01, abs=1e-9)
    n_on, n_off = _counts_with(b, 200.0 * rows, 0.0, C)
    far = 2 * np.arctanh(b + 1.2 * MAX_IMBALANCE)           # intervals far from the counts, opposite sign
    fit = balance_from_counts(n_on, n_off, C, intervals=_interval_arrays(n_on.shape, far, 0.0))
    assert fit.chosen == "nominal" and fit.imbalance == 0.0
    n_on, n_off = _counts_with(b, np.full((20, 20), 200.0), 0.0, C)    # counts that do not vary: no slope
    fit = balance_from_counts(n_on, n_off, C, intervals=_interval_arrays(n_on.shape, small_r, 0.0))
    assert np.isnan(fit.slope_imbalance) and fit.chosen == "minmod"


def test_the_counts_alone_are_bounded_by_the_three_other_estimates(monkeypatch):
    """Where the edges' estimate is there, the slope taken alone is bounded by the range of the pooled
    counts, the edges and the intervals: it stands where they bracket it, it is moved to the nearest
    where all three lie on one side of it. Without slice counts it stands alone, as before."""
    from evinr_lite.method import balance

    C, b = 0.2, -0.15
    n = 200.0 * np.linspace(0.5, 1.5, 20)[:, None] * np.ones((1, 20))
    n_on, n_off = _counts_with(b, n, -0.7, C)            # the light pulls the pooled counts to -0.1325
    ivl = _interval_arrays(n.shape, 2 * np.arctanh(-0.01), 0.0)
    sliced = (np.ones((4,) + n.shape), np.ones((4,) + n.shape))
    assert balance_from_counts(n_on, n_off, C, intervals=ivl).imbalance == pytest.approx(b, abs=1e-9)
    for grad, expect in ((-0.2, b), (-0.12, None), (-0.01, None)):
        monkeypatch.setattr(balance, "_gradient_imbalance", lambda *a, g=grad: g)   # the fit's unchecked call
        fit = balance_from_counts(n_on, n_off, C, intervals=ivl, sliced=sliced)
        assert fit.chosen == "counts" and fit.slope_imbalance == pytest.approx(b, abs=1e-9)
        nearest = min(fit.raw_imbalance, fit.gradient_imbalance, fit.interval_imbalance)   # all above b
        assert fit.imbalance == pytest.approx(expect if expect is not None else nearest, abs=1e-9)
        assert (fit.imbalance != pytest.approx(b, abs=1e-6)) == (expect is None)


def test_a_busy_shake_whose_slope_errs_gets_the_others_range():
    """fresh24_07_shake_brick (174 events per pixel, C+ 0.151 and C- 0.171: b = -0.064): the counts'
    slope reads about -0.01 (the shake stops mid-swing, so the pixels' net change goes with their
    counts), while the pooled counts, the edges and the intervals read about -0.065; the slope is
    bounded by them."""
    from evinr_lite.sim.zoo import effective_C, fresh, imbalance, simulate

    z = fresh(24)[7]
    _, events, _, _ = simulate(z)
    events, _ = prepare_events(events, EvINRConfig(C=effective_C(z), balance="none", progress=False))
    fit = estimate_balance(events, effective_C(z))
    assert fit.chosen == "counts" and abs(fit.slope_imbalance - imbalance(z)) > 0.04
    assert abs(fit.imbalance - imbalance(z)) < 0.01


def test_counts_that_show_no_change_of_light_overrule_intervals_of_the_other_sign(monkeypatch):
    """Between COUNTS_ALONE and COUNTS_OVER_INTERVALS, where the edges and the intervals disagree in sign
    (the edges -0.12, the intervals +0.08, their scene's own bias): the pooled counts read a change of
    light common to all pixels and the slope does not, so where the two agree (the span's mean log change
    C mean n |pooled - slope| at most STEADY_LIGHT) no change of light pushed the estimates apart, and the
    smallest of the edges, the slope and the pooled counts is taken. A change of light of 3 STEADY_LIGHT,
    too few events (s above COUNTS_OVER_INTERVALS) or no slice counts keep the nominal C."""
    from evinr_lite.method import balance
    from evinr_lite.method.balance import COUNTS_ALONE, COUNTS_OVER_INTERVALS, NET_CHANGE, STEADY_LIGHT

    C, b = 0.2, -0.1
    rows = np.linspace(0.5, 1.5, 20)[:, None] * np.ones((1, 20))
    ivl = _interval_arrays(rows.shape, 2 * np.arctanh(0.08), 0.0)
    sliced = (np.ones((4,) + rows.shape), np.ones((4,) + rows.shape))
    monkeypatch.setattr(balance, "_gradient_imbalance", lambda *a: -0.12)   # the fit's unchecked call
    cases = ((12.0, 0.0, "agreement"), (12.0, -0.5 * STEADY_LIGHT, "agreement"),
             (12.0, 3 * STEADY_LIGHT, "nominal"), (3.0, 0.0, "nominal"))
    for mean_n, light, expect in cases:
        n_on, n_off = _counts_with(b, mean_n * rows, light, C)
        fit = balance_from_counts(n_on, n_off, C, intervals=ivl, sliced=sliced)
        s = NET_CHANGE / (C * mean_n)
        assert fit.counts_error == pytest.approx(s) and s > COUNTS_ALONE
        assert fit.interval_imbalance == pytest.approx(0.08) and fit.gradient_imbalance == -0.12
        assert C * mean_n * abs(fit.raw_imbalance - fit.slope_imbalance) == pytest.approx(abs(light), abs=1e-9)
        assert fit.chosen == expect, (mean_n, light)
        if expect == "agreement":
            assert s <= COUNTS_OVER_INTERVALS
            assert fit.imbalance == minmod(fit.gradient_imbalance, fit.slope_imbalance, fit.raw_imbalance)
            # the slope (= b) where the light is steady, else the pooled counts, pulled towards 0 by it
            assert fit.imbalance == pytest.approx(b - light / (C * mean_n) if light < 0 else b, abs=1e-9)
        else:
            assert fit.imbalance == 0.0 and fit.C == (C, C)
    n_on, n_off = _counts_with(b, 12.0 * rows, 0.0, C)              # no slice counts: the pooled counts
    fit = balance_from_counts(n_on, n_off, C, intervals=ivl)         # and the intervals disagree, as before
    assert np.isnan(fit.gradient_imbalance) and fit.chosen == "nominal" and fit.imbalance == 0.0


def test_a_pan_whose_intervals_flip_sign_gets_the_counts_estimate():
    """fresh11_07_pan_gravel (C+ 0.269 and C- 0.331 given as 0.3: b = -0.102; 2.5 s, about 15 events per pixel): the
    intervals read about +0.1 (their scene's own bias) while the edges, the slope and the pooled counts
    read about -0.1 and agree with each other, so no change of light explains the disagreement; the
    consensus takes the counts' side instead of the nominal C."""
    from evinr_lite.sim.zoo import effective_C, fresh, imbalance, simulate

    z = fresh(11)[7]
    _, events, _, _ = simulate(z)
    events, _ = prepare_events(events, EvINRConfig(C=effective_C(z), balance="none", progress=False))
    fit = estimate_balance(events, effective_C(z))
    assert fit.interval_imbalance > 0.05 > -0.05 > fit.gradient_imbalance and fit.chosen == "agreement"
    assert abs(fit.imbalance - imbalance(z)) < 0.02 < abs(imbalance(z)) - 0.05


def test_a_long_change_of_light_is_not_read_as_an_imbalance():
    """20 s to and fro, equal thresholds, while the light falls by e^-2: more OFF than ON events, so the
    pooled counts read an imbalance; the counts fitted with an intercept do not."""
    ev = simulate_scene(LightingScene(_scene(), global_change=-2.0, vignette=0.0), C=0.225, seed=0)
    fit = estimate_balance(ev, 0.225)
    assert fit.chosen == "counts" and fit.raw_imbalance > 0.04
    assert abs(fit.imbalance) < 0.015


def test_a_long_off_heavy_recording_gets_its_pair():
    """20 s to and fro with C+ 0.20 and C- 0.25 given as 0.225 (b = -0.111): many events per pixel, so
    the counts are trusted alone, whatever the intervals read."""
    ev = simulate_scene(_scene(), C=0.225, C_pos=0.20, C_neg=0.25, seed=0)
    fit = estimate_balance(ev, 0.225)
    assert fit.chosen == "counts"
    assert fit.imbalance == pytest.approx(-0.05 / 0.45, abs=0.01)
    assert fit.C[0] == pytest.approx(0.20, abs=0.006) and fit.C[1] == pytest.approx(0.25, abs=0.006)


@pytest.fixture(scope="module")
def darkening_pan():
    """2 s of the camera image translating at (12, -5) px/s on 60 x 80 pixels, C+ 0.17 and C- 0.23 given
    as 0.2 (b = -0.15): the pan brings in brighter content, so the pooled counts read the wrong sign."""
    scene = MovingImageScene("camera", (60, 80), 2.0, velocity=(12.0, -5.0))
    return simulate_scene(scene, C=0.2, C_pos=0.17, C_neg=0.23, seed=0)


def test_the_edges_estimate_takes_the_pooled_counts_place_in_the_minmod(darkening_pan):
    fit = estimate_balance(darkening_pan, 0.2)
    assert fit.raw_imbalance > 0.1 and fit.interval_imbalance < -0.1      # the two disagree in sign ...
    assert fit.gradient_imbalance < -0.05 and fit.chosen == "minmod"       # ... the edges' estimate does not
    assert fit.imbalance == minmod(fit.gradient_imbalance, fit.interval_imbalance)
    counts = PolarityCounts((60, 80)).update(darkening_pan)               # no slice counts: the pooled counts
    old = balance_from_counts(counts.n_on, counts.n_off, 0.2, intervals=counts.intervals)
    assert np.isnan(old.gradient_imbalance) and old.imbalance == 0.0 and old.chosen == "nominal"
    assert abs(fit.imbalance + 0.15) < abs(old.imbalance + 0.15) - 0.05


def test_a_uniform_change_of_light_does_not_move_the_edges_estimate(darkening_pan):
    """Every pixel given the same extra OFF events in every slice (a fall of the light, uniform in log
    intensity): no neighbour difference changes, so neither does the edges' estimate; the pooled counts do."""
    edges = span_slices(darkening_pan.t[0], darkening_pan.t[-1])
    on, off = slice_counts(darkening_pan, edges)
    usable = (on.sum(0) + off.sum(0)) > 0
    darker = off + np.float32(3.0)
    assert gradient_imbalance(on, darker, usable) == pytest.approx(gradient_imbalance(on, off, usable), abs=1e-12)
    before = balance_from_counts(on.sum(0), off.sum(0), 0.2).raw_imbalance
    assert balance_from_counts(on.sum(0), darker.sum(0), 0.2).raw_imbalance > before + 0.1


def test_slice_counts_carried_in_chunks_match_one_span(darkening_pan):
    edges = span_slices(0.0, 2.0)
    counts = PolarityCounts((60, 80), slices=edges)
    for a in np.arange(0.0, 2.0, 0.3):
        counts.update(darkening_pan.slice_time(a, a + 0.3, allow_empty=True))
    for chunked, one in zip(counts.sliced, slice_counts(darkening_pan, edges)):
        np.testing.assert_array_equal(chunked, one)
    assert sum(a.sum() for a in counts.sliced) == len(darkening_pan)
    whole = estimate_balance(darkening_pan, 0.2)
    assert counts.fit(0.2).gradient_imbalance == pytest.approx(whole.gradient_imbalance, abs=0.02)  # slices 0-2 s vs the events' own span


def test_bad_slices_are_refused():
    with pytest.raises(EventDataError, match="increasing"):
        PolarityCounts(SIZE, slices=[0.0, 1.0, 1.0])
    with pytest.raises(EventDataError, match="sliced must be"):
        balance_from_counts(np.ones(SIZE), np.ones(SIZE), 0.2, sliced=(np.ones((4,) + SIZE), np.ones((3,) + SIZE)))


def test_the_fresh_benchmark_draws_both_signs_reproducibly():
    """benchmarks/balance.py --fresh: the same seed gives the same sensors; the draws cover C- > C+ and
    C+ > C-; the rule before is the slope where the counts were taken alone, else the pooled minmod."""
    from benchmarks.balance import fresh_scenes, pooled_minmod
    from evinr_lite.sim.zoo import imbalance

    a, b = fresh_scenes(7), fresh_scenes(7)
    assert [(z.name, z.C, z.C_pos, z.C_neg, z.seed) for z in a] == [(z.name, z.C, z.C_pos, z.C_neg, z.seed) for z in b]
    assert [z.C for z in fresh_scenes(8)] != [z.C for z in a]
    bs = [imbalance(z) for z in a]
    assert min(bs) < -0.05 and max(bs) > 0.05 and all(abs(v) < 0.2 for v in bs)
    assert all(0.5 * (z.C_pos + z.C_neg) == pytest.approx(z.C) for z in a)
    assert pooled_minmod({"chosen": "counts", "slope": -0.12, "raw": 0.3, "interval": 0.1}) == -0.12
    assert pooled_minmod({"chosen": "minmod", "slope": -0.12, "raw": 0.3, "interval": 0.1}) == pytest.approx(0.1)
    assert pooled_minmod({"chosen": "nominal", "slope": -0.12, "raw": 0.3, "interval": -0.1}) == 0.0
