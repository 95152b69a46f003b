"""The event simulator against the physics it claims (Sec. 3.1 / Eq. 2 of the paper)."""
import numpy as np
import pytest

from evinr_lite.core.events import EventDataError, Events
from evinr_lite.method.integration import integrate_events
from evinr_lite.sim.scenes import make_scene
from evinr_lite.sim.simulate import sample_thresholds, simulate_events_1d, simulate_scene, simulate_video

ASYMMETRIC = [(0.2, 0.2), (0.15, 0.3)]


def smooth_signals(n_pixels=6, seed=1):
    """A callable L(s) -> [M, P]: sums of sinusoids, a few log units of swing per second."""
    rng = np.random.default_rng(seed)
    freq = rng.uniform(0.5, 3.0, size=(3, n_pixels))
    amp = rng.uniform(0.3, 1.0, size=(3, n_pixels))
    phase = rng.uniform(0, 2 * np.pi, size=(3, n_pixels))

    def L(s):
        s = np.asarray(s, dtype=np.float64)[:, None, None]
        return (amp * np.sin(2 * np.pi * freq * s + phase)).sum(axis=1) - 1.0
    return L


def reference_crossings(t, L, C_pos, C_neg):
    """Plain-loop ESIM, one pixel at a time: (time, pixel, polarity) of every crossing."""
    out = []
    for i in range(L.shape[1]):
        ref = L[0, i]
        for k in range(1, len(t)):
            a, b = L[k - 1, i], L[k, i]
            while b - ref >= C_pos:
                ref += C_pos
                out.append((t[k - 1] + (ref - a) / (b - a) * (t[k] - t[k - 1]), i, 1))
            while ref - b >= C_neg:
                ref -= C_neg
                out.append((t[k - 1] + (ref - a) / (b - a) * (t[k] - t[k - 1]), i, -1))
    return out


def event_levels(ev, L_start, C_pos, C_neg):
    """The level each event crossed: L(t0) + C_pos * #ON - C_neg * #OFF so far at its pixel (inclusive)."""
    levels = np.empty(len(ev))
    n_pix = ev.sensor_size[1]
    for i in range(n_pix):
        idx = np.flatnonzero(ev.x == i)
        steps = np.where(ev.p[idx] > 0, C_pos, -C_neg)
        levels[idx] = L_start[i] + np.cumsum(steps)
    return levels


# ---- integration reproduces L (Eq. 2) ---------------------------------------------------

@pytest.mark.parametrize("C_pos,C_neg", ASYMMETRIC)
@pytest.mark.parametrize("as_callable", [True, False])
def test_1d_events_integrate_back_to_L_within_one_threshold(C_pos, C_neg, as_callable):
    L = smooth_signals()
    t = np.linspace(0.0, 2.0, 400)
    samples = L(t)
    ev = simulate_events_1d(L if as_callable else samples, t, C_pos=C_pos, C_neg=C_neg)
    assert len(ev) > 100
    diff = (samples - samples[0]) - integrate_events(ev, t, C=(C_pos, C_neg))[:, 0, :]
    assert diff.min() > -C_neg - 1e-9 and diff.max() < C_pos + 1e-9
    # and tight: the residual uses most of the band (the test would catch a C off by a factor)
    assert diff.max() > 0.5 * C_pos and diff.min() < -0.5 * C_neg


@pytest.mark.parametrize("C_pos,C_neg", ASYMMETRIC)
def test_2d_scene_events_integrate_back_to_L_within_one_threshold(C_pos, C_neg):
    scene = make_scene("camera", sensor_size=(30, 40), duration=1.0, velocity=(12.0, 6.0))
    t = np.linspace(0.0, 1.0, 60)
    frames = scene.log_intensity(t)
    ev = simulate_video(frames, t, C_pos=C_pos, C_neg=C_neg)
    assert ev.sensor_size == (30, 40)
    diff = (frames - frames[0]) - integrate_events(ev, t, C=(C_pos, C_neg))
    assert diff.min() > -C_neg - 1e-9 and diff.max() < C_pos + 1e-9
    assert diff.max() > 0.5 * C_pos and diff.min() < -0.5 * C_neg


def test_simulate_scene_is_simulate_video_on_its_samples():
    scene = make_scene("bar", sensor_size=(20, 30), duration=1.0)
    ev = simulate_scene(scene, sample_rate=100, C=0.25, seed=3)
    t = np.linspace(0.0, 1.0, 101)
    ref = simulate_video(scene.log_intensity(t), t, C=0.25, seed=3)
    assert len(ev) == len(ref) > 0
    for k in "txyp":
        np.testing.assert_array_equal(getattr(ev, k), getattr(ref, k))


# ---- exact crossings --------------------------------------------------------------------

@pytest.mark.parametrize("C_pos,C_neg", ASYMMETRIC)
def test_events_match_a_loop_reference_including_several_per_interval(C_pos, C_neg):
    rng = np.random.default_rng(0)
    t = np.sort(rng.uniform(0, 1, 40))
    L = np.cumsum(rng.normal(0, 0.5, size=(40, 4)), axis=0)   # big steps: often several crossings per interval
    ev = simulate_events_1d(L, t, C_pos=C_pos, C_neg=C_neg)
    ref = reference_crossings(t, L, C_pos, C_neg)
    assert len(ev) == len(ref) > 4 * 40
    assert np.bincount(ev.x, minlength=4).tolist() == np.bincount([r[1] for r in ref], minlength=4).tolist()
    for i in range(4):
        mine = ev.take(ev.x == i)
        theirs = sorted(r for r in ref if r[1] == i)
        np.testing.assert_allclose(mine.t, [r[0] for r in theirs], atol=1e-12)
        assert mine.p.tolist() == [r[2] for r in theirs]


def test_times_sorted_inside_the_samples_and_exact_for_a_callable():
    L = smooth_signals(n_pixels=4, seed=5)
    t = np.linspace(0.1, 1.1, 80)
    C_pos, C_neg = 0.15, 0.25
    ev = simulate_events_1d(L, t, C_pos=C_pos, C_neg=C_neg, refine=True)
    assert np.all(np.diff(ev.t) >= 0)
    assert ev.t.min() >= t[0] and ev.t.max() <= t[-1]
    assert ev.sensor_size == (1, 4) and np.all(ev.y == 0) and set(np.unique(ev.p)) == {-1, 1}
    levels = event_levels(ev, L(t[:1])[0], C_pos, C_neg)
    at_event = L(ev.t)[np.arange(len(ev)), ev.x]
    assert np.abs(at_event - levels).max() < 1e-9
    # linear interpolation alone is visibly off on these coarse samples, so refine does the work
    rough = simulate_events_1d(L, t, C_pos=C_pos, C_neg=C_neg, refine=False)
    for i in range(4):                       # same events per pixel, only the times move
        np.testing.assert_array_equal(rough.p[rough.x == i], ev.p[ev.x == i])
    rough_levels = event_levels(rough, L(t[:1])[0], C_pos, C_neg)
    assert np.abs(L(rough.t)[np.arange(len(rough)), rough.x] - rough_levels).max() > 1e-4


def test_constant_signal_gives_no_events_and_one_pixel_input_works():
    t = np.linspace(0, 1, 50)
    assert len(simulate_events_1d(np.zeros((50, 3)), t)) == 0
    ev = simulate_events_1d(lambda s: 3.1 * s, t, C=0.2)         # one pixel, [T] output
    assert ev.sensor_size == (1, 1) and len(ev) == 15 and np.all(ev.p == 1)   # floor(3.1 / 0.2)
    np.testing.assert_allclose(ev.t, 0.2 * np.arange(1, 16) / 3.1, atol=1e-14)


# ---- noise, mismatch, refractory, determinism ------------------------------------------

def test_same_seed_same_events_other_seed_other_noise():
    L = smooth_signals()
    t = np.linspace(0, 1, 200)
    kw = dict(threshold_sigma=0.1, noise_rate=5.0, refractory=1e-3)
    a, b = simulate_events_1d(L, t, seed=7, **kw), simulate_events_1d(L, t, seed=7, **kw)
    c = simulate_events_1d(L, t, seed=np.random.default_rng(8), **kw)
    for k in "txyp":
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k))
    assert len(a) != len(c) or not np.array_equal(a.t, c.t)


def test_noise_rate_matches_poisson_expectation():
    P, duration, rate = 200, 2.0, 50.0
    t = np.linspace(0, duration, 3)
    ev = simulate_events_1d(np.zeros((3, P)), t, noise_rate=rate, seed=1)
    expected = rate * P * duration
    assert abs(len(ev) - expected) < 5 * np.sqrt(expected)
    assert abs((ev.p > 0).mean() - 0.5) < 5 * 0.5 / np.sqrt(expected)
    assert ev.t.min() >= 0 and ev.t.max() <= duration and np.all(np.diff(ev.t) >= 0)
    counts = np.bincount(ev.x, minlength=P)
    assert 0.7 < counts.var() / counts.mean() < 1.3                # Poisson: variance = mean


def test_threshold_mismatch_sets_per_pixel_counts():
    P, rise, fall = 300, 3.0, 2.0
    t = np.array([0.0, 1.0, 2.0])
    L = np.array([np.zeros(P), np.full(P, rise), np.full(P, rise - fall)])   # up 3, then down 2
    ev = simulate_events_1d(L, t, C_pos=0.2, C_neg=0.25, threshold_sigma=0.1, seed=11)
    C_pos_pix, C_neg_pix = sample_thresholds(P, 0.2, 0.25, 0.1, np.random.default_rng(11))
    on = np.bincount(ev.x[ev.p > 0], minlength=P)
    off = np.bincount(ev.x[ev.p < 0], minlength=P)
    np.testing.assert_array_equal(on, np.floor(rise / C_pos_pix))
    np.testing.assert_array_equal(off, np.floor((on * C_pos_pix - (rise - fall)) / C_neg_pix))
    assert on.std() > 0.5                                         # thresholds really differ per pixel
    big_pos, big_neg = sample_thresholds(20000, 0.2, 0.3, 0.1, np.random.default_rng(0))
    assert abs(big_pos.mean() - 0.2) < 1e-3 and abs(big_pos.std() - 0.02) < 1e-3      # relative sigma
    assert abs(big_neg.mean() - 0.3) < 1e-3 and abs(big_neg.std() - 0.03) < 1e-3
    clipped, _ = sample_thresholds(1000, 0.2, 0.2, 2.0, np.random.default_rng(0))
    assert clipped.min() == pytest.approx(0.02)                     # clipped at 0.1 x nominal
    nominal = simulate_events_1d(L, t, C_pos=0.2, C_neg=0.25)
    assert np.all(np.bincount(nominal.x[nominal.p > 0], minlength=P) == 15)


def test_refractory_period_drops_close_events_esim_style():
    L = smooth_signals(n_pixels=5, seed=2)
    t = np.linspace(0, 2, 500)
    R = 0.01
    free = simulate_events_1d(L, t, C=0.1)
    ev = simulate_events_1d(L, t, C=0.1, refractory=R)
    assert 0 < len(ev) < len(free)
    for i in range(5):
        ti = ev.t[ev.x == i]
        assert np.diff(ti).min() >= R - 1e-12
        # ESIM convention: dropping does not hold the reference, so the kept events are exactly
        # the greedy selection from the refractory-free stream
        kept, last = [], -np.inf
        for s in free.t[free.x == i]:
            if s - last >= R:
                kept.append(s)
                last = s
        np.testing.assert_array_equal(ti, kept)


def test_refractory_applies_to_noise_too():
    ev = simulate_events_1d(np.zeros((2, 50)), [0.0, 1.0], noise_rate=200.0, refractory=0.02, seed=4)
    for i in range(50):
        ti = ev.t[ev.x == i]
        assert ti.size < 60 and (ti.size < 2 or np.diff(ti).min() >= 0.02)


# ---- bad arguments ----------------------------------------------------------------------

@pytest.mark.parametrize("kwargs,match", [
    (dict(C=0.0), "positive"),
    (dict(C_neg=-0.1), "C_neg"),
    (dict(noise_rate=-1.0), "noise_rate"),
    (dict(refractory=np.nan), "refractory"),
    (dict(threshold_sigma=-0.1), "threshold_sigma"),
    (dict(seed="x"), "seed"),
])
def test_bad_arguments_are_named(kwargs, match):
    with pytest.raises(EventDataError, match=match):
        simulate_events_1d(np.zeros((3, 2)), [0.0, 0.5, 1.0], **kwargs)


def test_bad_samples_are_named():
    with pytest.raises(EventDataError, match="strictly increasing"):
        simulate_events_1d(np.zeros(3), [0.0, 1.0, 1.0])
    with pytest.raises(EventDataError, match=r"\[T, P\]"):
        simulate_events_1d(np.zeros((4, 2)), [0.0, 0.5, 1.0])
    with pytest.raises(EventDataError, match="NaN"):
        simulate_events_1d(np.array([0.0, np.nan, 1.0]), [0.0, 0.5, 1.0])
    with pytest.raises(EventDataError, match=r"\[T, H, W\]"):
        simulate_video(np.zeros((3, 4)), [0.0, 0.5, 1.0])
    with pytest.raises(TypeError, match="unexpected"):
        simulate_scene(make_scene("bar", sensor_size=(4, 4)), refine=True)


def test_result_is_an_events_container():
    ev = simulate_video(np.random.default_rng(0).normal(size=(5, 3, 4)), np.arange(5.0), C=0.3)
    assert isinstance(ev, Events) and ev.sensor_size == (3, 4)
    assert ev.x.max() < 4 and ev.y.max() < 3


def test_threshold_drift_scales_steps_and_zero_drift_changes_nothing():
    from evinr_lite.sim.scenes import MovingImageScene

    sc = MovingImageScene("camera", (30, 40), 2.0)
    base = simulate_scene(sc, C=0.2, seed=0)
    same = simulate_scene(sc, C=0.2, seed=0, threshold_drift=0.0)
    np.testing.assert_array_equal(base.t, same.t)
    ev = simulate_scene(sc, C=0.2, seed=0, threshold_drift=0.5)
    # each event moved the reference by the threshold in force (0.75x at the start .. 1.25x at the end):
    # summed per pixel, the steps reproduce the change of L to within one (largest) step
    scale = 1 + 0.5 * (ev.t / 2.0 - 0.5)
    steps = np.bincount(ev.y * 40 + ev.x, weights=ev.p * 0.2 * scale, minlength=1200).reshape(30, 40)
    err = sc.log_intensity(2.0) - sc.log_intensity(0.0) - steps
    assert np.abs(err).max() < 0.2 * 1.25 + 0.02
    # and the nominal threshold alone would be off: later events are bigger steps
    nominal = np.bincount(ev.y * 40 + ev.x, weights=ev.p * 0.2, minlength=1200).reshape(30, 40)
    assert np.abs(sc.log_intensity(2.0) - sc.log_intensity(0.0) - nominal).max() > np.abs(err).max()
    with pytest.raises(EventDataError, match="threshold_drift"):
        simulate_scene(sc, C=0.2, threshold_drift=2.5)
