"""integrate_events against a direct per-event sum."""
import numpy as np
import pytest

from evinr_lite.core.events import EventDataError, Events
from evinr_lite.method.integration import integrate_events


def random_events(n=400, size=(5, 7), seed=0):
    rng = np.random.default_rng(seed)
    t = np.sort(rng.choice(np.linspace(0, 1, 200), n))       # repeated times on purpose
    return Events(t, rng.integers(0, size[1], n), rng.integers(0, size[0], n), rng.choice([-1, 1], n), size)


def direct(ev, t_query, C_pos, C_neg, L0):
    out = np.zeros((len(t_query), *ev.sensor_size)) + L0
    for q, tq in enumerate(t_query):
        for ti, xi, yi, pi in zip(ev.t, ev.x, ev.y, ev.p):
            if ti <= tq:
                out[q, yi, xi] += C_pos if pi > 0 else -C_neg
    return out


@pytest.mark.parametrize("C", [1.0, 0.3, (0.2, 0.35)])
def test_matches_direct_sum(C):
    ev = random_events()
    rng = np.random.default_rng(1)
    t_query = np.concatenate([[-1.0, 2.0, ev.t[10], ev.t[10]], rng.uniform(0, 1, 6)])  # unsorted, repeats, at events
    L0 = rng.normal(size=ev.sensor_size)
    C_pos, C_neg = (C, C) if np.isscalar(C) else C
    got = integrate_events(ev, t_query, C=C, L0=L0)
    assert got.shape == (len(t_query), *ev.sensor_size) and got.dtype == np.float64
    np.testing.assert_allclose(got, direct(ev, t_query, C_pos, C_neg, L0), atol=1e-12)


def test_scalar_query_default_L0_and_empty_events():
    ev = random_events()
    np.testing.assert_allclose(integrate_events(ev, 0.5), direct(ev, [0.5], 1.0, 1.0, 0.0)[0])
    empty = Events.empty((2, 3))
    np.testing.assert_array_equal(integrate_events(empty, [0.0, 1.0], C=0.2, L0=0.5), np.full((2, 2, 3), 0.5))


def test_all_events_at_the_end_sum_to_net_polarity():
    ev = random_events(n=1000, seed=3)
    net = np.zeros(ev.sensor_size)
    np.add.at(net, (ev.y, ev.x), ev.p)
    np.testing.assert_allclose(integrate_events(ev, [ev.t[-1]], C=0.25)[0], 0.25 * net)


def test_bad_arguments_are_named():
    ev = random_events()
    with pytest.raises(EventDataError, match="L0"):
        integrate_events(ev, [0.5], L0=np.zeros((3, 3)))
    with pytest.raises(EventDataError, match="C must be"):
        integrate_events(ev, [0.5], C=-1.0)
    with pytest.raises(EventDataError, match="t_query"):
        integrate_events(ev, [np.nan])
