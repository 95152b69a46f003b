"""The background filter's window chosen from the events (evinr_lite.method.background): the neighbour gaps
are the filter's own rule, the noise share is read from the events, and the window follows it."""
import numpy as np
import pytest

from evinr_lite.core.events import EventDataError, Events
from evinr_lite.io.source import MemorySource
from evinr_lite.method import EvINRConfig
from evinr_lite.method.background import GRID, fit_background, neighbour_gaps, sample_spans
from evinr_lite.method.denoise import correlation_filter
from evinr_lite.method.prepare import prepare_events, prepare_source
from evinr_lite.sim.scenes import MovingImageScene, OscillatingScene
from evinr_lite.sim.simulate import add_background_noise, simulate_scene

SIZE = (30, 40)


def _random_events(n, seed, span=2.0, size=(6, 7)):
    rng = np.random.default_rng(seed)
    t = np.sort(np.round(rng.uniform(0, span, n), 3))          # whole ms: ties at the same time occur
    return Events.from_arrays(t, rng.integers(0, size[1], n), rng.integers(0, size[0], n), rng.choice([-1, 1], n), size)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_gaps_are_a_brute_force_search_and_the_filter_keeps_what_is_within_dt(seed):
    ev = _random_events(300, seed)
    gaps = neighbour_gaps(ev, ev.t, ev.x, ev.y, ev.p)
    for i in range(len(ev)):
        near = (np.maximum(np.abs(ev.x - ev.x[i]), np.abs(ev.y - ev.y[i])) == 1) & (ev.p == ev.p[i])
        expected = np.abs(ev.t[near] - ev.t[i]).min() if near.any() else np.inf
        assert gaps[i] == expected
    for dt in (0.0045, 0.0205, 0.1005):          # off the ms grid: the filter's t_j + dt rounds, |t_j - t_i| too
        kept = correlation_filter(ev, dt, window="both", same_polarity=True)
        np.testing.assert_array_equal(kept, gaps <= dt)


def test_a_query_at_a_corner_or_without_neighbours_has_no_gap():
    ev = Events.from_arrays(np.array([0.0, 0.5]), np.array([0, 5]), np.array([0, 5]), np.array([1, 1]), (6, 7))
    g = neighbour_gaps(ev, [0.1, 0.1, 0.1], [1, 0, 4], [1, 0, 4], [1, 1, -1])
    assert g[0] == pytest.approx(0.1) and g[1] == np.inf and g[2] == np.inf   # own pixel never counts; OFF != ON


def test_long_spans_are_measured_on_slices_that_read_beyond_their_interior():
    assert sample_spans(0.0, 8.0) == [(0.0, 8.0, 0.0, 8.0)]
    spans = sample_spans(0.0, 60.0)
    assert len(spans) == 4
    for read_a, read_b, qa, qb in spans:
        assert qb - qa == pytest.approx(2.0) and read_a == pytest.approx(qa - max(GRID)) and read_b == pytest.approx(qb + max(GRID))


def _pan(speed, seed=0):
    scene = MovingImageScene("camera", SIZE, 2.0, velocity=(speed, speed / 3), rotation=0.0, zoom=0.0)
    return simulate_scene(scene, 0.0, 2.0, C=0.2, seed=seed)


@pytest.mark.parametrize("hz", [0.5, 2.0])
def test_the_noise_share_is_read_from_the_events(hz):
    clean = _pan(8.0)
    ev, added = add_background_noise(clean, hz, seed=3, t_start=0.0, t_end=2.0, return_labels=True)
    fit = fit_background([(ev, (0.0, 2.0))])
    assert abs(fit.noise_share - added.mean()) < 0.05 + 0.2 * added.mean()
    assert fit.dt == min(GRID)                    # background activity: the shortest window
    assert fit_background([(clean, (0.0, 2.0))]).noise_share < 0.03


def test_a_slow_clean_pan_keeps_its_events_and_a_noisy_one_is_filtered():
    """At 3 px/s an edge takes 0.3 s to reach the next pixel: a 50 ms window would drop real events."""
    clean = _pan(3.0)
    used = prepare_events(clean, EvINRConfig(C=0.2))[1]
    assert used.background == "keep" or used.background_dt > min(GRID)
    noisy = add_background_noise(clean, 2.0, seed=4, t_start=0.0, t_end=2.0)
    used = prepare_events(noisy, EvINRConfig(C=0.2))[1]
    assert used.background == "filter" and used.background_dt == min(GRID)


def test_too_few_events_keep_the_fixed_window_and_the_choice_is_deterministic():
    ev = _random_events(50, 0)
    assert fit_background([(ev, (0.0, 2.0))]).dt == 0.05
    clean = _pan(3.0)
    a, b = fit_background([(clean, (0.0, 2.0))], seed=5), fit_background([(clean, (0.0, 2.0))], seed=5)
    assert a == b


def test_a_streamed_recording_chooses_the_same_window_as_in_memory():
    scene = OscillatingScene("astronaut", SIZE, 12.0, path=((6.0, 2.0, 4.0, 0.0), (2.0, 1.0, 1.3, 1.0)))
    ev = add_background_noise(simulate_scene(scene, C=0.2, seed=0), 0.3, seed=1, t_start=0.0, t_end=12.0)
    cfg = EvINRConfig(C=0.2, tau=3.0, progress=False)
    t1 = float(ev.t[-1])
    whole = prepare_events(ev, cfg, (0.0, t1))[1]
    streamed = prepare_source(MemorySource(ev), 0.0, t1, cfg)[0]
    assert whole.background == streamed.background and whole.background_dt == streamed.background_dt
    assert whole.C == streamed.C and whole.lam == streamed.lam


def test_background_dt_must_be_positive_seconds():
    from evinr_lite.core.events import EventDataError

    with pytest.raises(EventDataError, match="background_dt must be a positive number of seconds"):
        EvINRConfig(background_dt=0)
    with pytest.raises(EventDataError, match="pass the number itself"):
        EvINRConfig(background_dt="0.1")


def test_no_queries_get_no_gaps_and_a_float32_default_window_is_the_default():
    """A mask that selects no query is answered with no gaps (not refused as empty input), and 0.05 s that
    went through float32 is the default window, not a value "auto" would ignore."""
    rng = np.random.default_rng(0)
    ev = Events(np.sort(rng.uniform(0, 1, 400)), rng.integers(0, 40, 400), rng.integers(0, 30, 400),
                rng.choice([-1, 1], 400), (30, 40))
    assert neighbour_gaps(ev, [], [], [], []).shape == (0,)
    cfg = EvINRConfig(background_dt=np.float32(0.05))
    assert cfg.background == "auto" and cfg.background_dt == 0.05
    with pytest.raises(EventDataError, match="background='filter'"):
        EvINRConfig(background_dt=0.2)
