"""Event frames (Eq. 2): sums over bins, bin boundaries, and the (b_i, b_{i+1}] convention."""
import numpy as np
import pytest

from evinr_lite import EventDataError, Events, events_to_frames, fixed_duration_boundaries
from evinr_lite.method.binning import equal_count_boundaries


def random_events(n=2000, H=5, W=7, T=1.0, seed=0):
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0, T, n))
    return Events(t, rng.integers(0, W, n), rng.integers(0, H, n), rng.choice([-1, 1], n), (H, W))


def loop_reference(ev, b, C):
    """Per-event loop, the definition written out."""
    H, W = ev.sensor_size
    out = np.zeros((len(b) - 1, H, W))
    for t, x, y, p in zip(ev.t, ev.x, ev.y, ev.p):
        for i in range(len(b) - 1):
            if b[i] < t <= b[i + 1] or (i == 0 and t == b[0]):
                out[i, y, x] += p * C
                break
    return out


def test_fixed_duration_matches_per_event_loop():
    ev = random_events(500)
    b = fixed_duration_boundaries(0.0, 1.0, 1 / 32)
    assert len(b) == 33 and b[0] == 0.0 and b[-1] == 1.0
    ef = events_to_frames(ev, b, C=0.3)
    np.testing.assert_allclose(ef.frames, loop_reference(ev, b, 0.3), atol=1e-5)
    assert ef.counts.sum() == len(ev)


def test_last_bin_is_shortened_to_end():
    b = fixed_duration_boundaries(0.0, 0.1, 0.03)
    np.testing.assert_allclose(b, [0.0, 0.03, 0.06, 0.09, 0.1])


def test_boundary_convention_left_open_right_closed():
    # event exactly on an inner boundary belongs to the bin that ends there
    ev = Events([0.0, 0.5, 0.5000001, 1.0], [0, 0, 0, 0], [0, 0, 0, 0], [1, 1, -1, 1], (1, 1))
    ef = events_to_frames(ev, [0.0, 0.5, 1.0])
    np.testing.assert_array_equal(ef.counts, [2, 2])
    np.testing.assert_allclose(ef.frames[:, 0, 0], [2.0, 0.0])


def test_frames_difference_equals_events_between_boundaries():
    # sum of frames i..j equals the events in (b_i, b_{j+1}] - what F(b_{j+1}) - F(b_i) is compared with
    ev = random_events(3000, seed=1)
    b = fixed_duration_boundaries(0.0, 1.0, 0.1)
    ef = events_to_frames(ev, b)
    i, j = 2, 6
    sel = (ev.t > b[i]) & (ev.t <= b[j + 1])
    direct = np.zeros(ev.sensor_size)
    np.add.at(direct, (ev.y[sel], ev.x[sel]), ev.p[sel])
    np.testing.assert_allclose(ef.frames[i:j + 1].sum(0), direct, atol=1e-4)


def test_equal_count_bins_hold_equal_counts():
    ev = random_events(1000, seed=2)
    b = equal_count_boundaries(ev, events_per_bin=100)
    ef = events_to_frames(ev, b)
    np.testing.assert_array_equal(ef.counts, np.full(10, 100))
    assert b[0] == ev.t[0] and b[-1] == ev.t[-1]
    np.testing.assert_allclose(ef.centers, 0.5 * (b[1:] + b[:-1]))
    b7 = equal_count_boundaries(ev, n_bins=7)
    assert len(b7) == 8 and abs(events_to_frames(ev, b7).counts - 1000 / 7).max() <= 1


def test_events_outside_boundaries_are_not_counted():
    ev = random_events(1000, seed=3)
    ef = events_to_frames(ev, [0.25, 0.5, 0.75])
    inside = ((ev.t >= 0.25) & (ev.t <= 0.75)).sum()
    assert ef.counts.sum() == inside


def test_bad_bins_are_refused():
    ev = random_events(10)
    with pytest.raises(EventDataError, match="strictly increasing"):
        events_to_frames(ev, [0.0, 0.5, 0.5, 1.0])
    with pytest.raises(EventDataError, match="empty or reversed"):
        fixed_duration_boundaries(1.0, 1.0)
    with pytest.raises(EventDataError, match="exactly one"):
        equal_count_boundaries(ev)
    with pytest.raises(EventDataError, match="at least 2 events"):
        equal_count_boundaries(Events.empty((2, 2)), n_bins=2)
