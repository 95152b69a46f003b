"""The Events container: conversions and every bad-input error, checked by message."""
import numpy as np
import pytest

from evinr_lite import EventDataError, Events
from evinr_lite.core.events import normalize_polarity


def make(n=5, H=4, W=6, p=None):
    t = np.linspace(0.0, 1.0, n)
    x = np.arange(n) % W
    y = np.arange(n) % H
    p = np.array([1, -1] * n)[:n] if p is None else p
    return t, x, y, p


def test_valid_events_keep_values_and_types():
    t, x, y, p = make()
    ev = Events(t, x, y, p, (4, 6))
    assert ev.t.dtype == np.float64 and ev.x.dtype == np.int32 and ev.p.dtype == np.int8
    np.testing.assert_array_equal(ev.x, x)
    np.testing.assert_array_equal(ev.y, y)
    np.testing.assert_array_equal(ev.p, p)
    assert ev.sensor_size == (4, 6) and len(ev) == 5


@pytest.mark.parametrize("p01, expected", [
    (np.array([0, 1, 1, 0]), [-1, 1, 1, -1]),
    (np.array([False, True, True, False]), [-1, 1, 1, -1]),
    (np.array([0.0, 1.0, 1.0, 0.0]), [-1, 1, 1, -1]),
])
def test_01_and_bool_polarity_become_minus_plus_one(p01, expected):
    ev = Events(np.arange(4.0), [0, 1, 2, 3], [0, 0, 0, 0], p01, (1, 4))
    np.testing.assert_array_equal(ev.p, expected)
    assert (ev.p == -1).sum() == 2  # OFF events kept, not counted as zero


def test_explicit_01_encoding_converts_all_ones():
    ev = Events.from_arrays(np.arange(3.0), [0, 0, 0], [0, 0, 0], [1, 1, 1], (1, 1), polarity="01")
    np.testing.assert_array_equal(ev.p, [1, 1, 1])


@pytest.mark.parametrize("p, match", [
    ([2, 1, -1], "neither -1/\\+1 nor 0/1"),
    ([0, 1, -1], "neither -1/\\+1 nor 0/1"),
])
def test_bad_polarity_is_refused(p, match):
    with pytest.raises(EventDataError, match=match):
        Events(np.arange(3.0), [0, 0, 0], [0, 0, 0], p, (1, 1))


def test_pm1_encoding_refuses_zeros_and_says_how():
    with pytest.raises(EventDataError, match="polarity='01'"):
        normalize_polarity(np.array([0, 1]), "pm1")


def test_unsorted_timestamps_name_index_and_fix():
    with pytest.raises(EventDataError, match=r"not sorted: t\[1\] = 0.5 > t\[2\] = 0.2.*sort=True"):
        Events([0.0, 0.5, 0.2], [0, 0, 0], [0, 0, 0], [1, 1, 1], (1, 1))


def test_sort_flag_sorts_stably():
    ev = Events.from_arrays([0.0, 0.5, 0.2], [0, 1, 2], [0, 0, 0], [1, -1, 1], (1, 3), sort=True)
    np.testing.assert_array_equal(ev.t, [0.0, 0.2, 0.5])
    np.testing.assert_array_equal(ev.x, [0, 2, 1])


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_non_finite_timestamps(bad):
    with pytest.raises(EventDataError, match="timestamp 1 is .*non-finite"):
        Events([0.0, bad, 1.0], [0, 0, 0], [0, 0, 0], [1, 1, 1], (1, 1))


def test_float32_timestamps_refused_with_reason():
    with pytest.raises(EventDataError, match="float32"):
        Events(np.array([0.0, 1.0], np.float32), [0, 0], [0, 0], [1, 1], (1, 1))


def test_coordinates_outside_sensor_mention_h_w_order():
    with pytest.raises(EventDataError, match=r"x \(column, width W\) coordinates span \[0, 6\].*\(H, W\)"):
        Events(np.arange(2.0), [0, 6], [0, 0], [1, 1], (4, 6))
    with pytest.raises(EventDataError, match=r"y \(row, height H\)"):
        Events(np.arange(2.0), [0, 0], [0, 4], [1, 1], (4, 6))
    with pytest.raises(EventDataError, match="coordinates span"):
        Events(np.arange(2.0), [-1, 0], [0, 0], [1, 1], (4, 6))


def test_non_integer_coordinates_refused():
    with pytest.raises(EventDataError, match="whole pixel indices"):
        Events(np.arange(2.0), [0.5, 1.0], [0, 0], [1, 1], (4, 6))


def test_length_mismatch_and_shape_errors():
    with pytest.raises(EventDataError, match="same length"):
        Events(np.arange(3.0), [0, 0], [0, 0, 0], [1, 1, 1], (1, 1))
    with pytest.raises(EventDataError, match="1-D"):
        Events(np.zeros((2, 2)), [0, 0], [0, 0], [1, 1], (1, 1))
    with pytest.raises(EventDataError, match=r"sensor_size must be \(H, W\)"):
        Events(np.arange(2.0), [0, 0], [0, 0], [1, 1], (0, 4))


def test_from_array_checks_columns():
    with pytest.raises(EventDataError, match=r"shape \[N, 4\]"):
        Events.from_array(np.zeros((3, 3)), (2, 2))
    a = np.array([[0.1, 2, 1, 0], [0.2, 3, 0, 1]])
    ev = Events.from_array(a, (2, 4))
    np.testing.assert_array_equal(ev.x, [2, 3])
    np.testing.assert_array_equal(ev.y, [1, 0])
    np.testing.assert_array_equal(ev.p, [-1, 1])
    ev2 = Events.from_array(a[:, [1, 2, 0, 3]], (2, 4), columns="xytp")
    np.testing.assert_array_equal(ev2.t, ev.t)


def test_time_units_convert_to_seconds():
    ev = Events.from_arrays(np.array([0, 1500, 2_000_000]), [0, 0, 0], [0, 0, 0], [1, 1, 1], (1, 1), time_unit="us")
    np.testing.assert_allclose(ev.t, [0.0, 1.5e-3, 2.0])


def test_absolute_clock_keeps_precision_through_origin():
    # A 1.47e9 s clock would lose sub-microsecond steps in float64; relative t + origin keeps them.
    origin = 1468939802.0
    ev = Events([0.123456789, 0.123456790], [0, 0], [0, 0], [1, 1], (1, 1), t_origin=origin)
    assert ev.t[1] - ev.t[0] == pytest.approx(1e-9, abs=1e-15)
    assert ev.t_origin == origin


def test_slice_time_half_open_and_empty_window_error():
    ev = Events(np.array([0.0, 0.1, 0.2, 0.3]), [0] * 4, [0] * 4, [1] * 4, (1, 1))
    np.testing.assert_array_equal(ev.slice_time(0.1, 0.3).t, [0.1, 0.2])
    with pytest.raises(EventDataError, match=r"no events in the window \[0.5, 0.7\).*cover \[0.000000, 0.300000\]"):
        ev.slice_time(0.5, 0.7)
    with pytest.raises(EventDataError, match="reversed"):
        ev.slice_time(0.3, 0.1)
    assert len(ev.slice_time(0.5, 0.7, allow_empty=True)) == 0


def test_concatenate_merges_in_time_order():
    a = Events([0.0, 0.2], [0, 0], [0, 0], [1, 1], (1, 2))
    b = Events([0.1, 0.3], [1, 1], [0, 0], [-1, -1], (1, 2))
    ev = Events.concatenate([a, b])
    np.testing.assert_array_equal(ev.t, [0.0, 0.1, 0.2, 0.3])
    np.testing.assert_array_equal(ev.p, [1, -1, 1, -1])
    with pytest.raises(EventDataError, match="different sensor_size"):
        Events.concatenate([a, Events.empty((3, 3))])


def test_integer_absolute_clock_in_ns_is_split_exactly():
    t_ns = np.array([1468939802_123456789, 1468939802_123456790], dtype=np.int64)
    ev = Events.from_arrays(t_ns, [0, 0], [0, 0], [1, 1], (1, 1), time_unit="ns")
    assert ev.t_origin == 1468939802.0
    assert ev.t[0] == 0.123456789 and ev.t[1] - ev.t[0] == pytest.approx(1e-9, abs=1e-15)


def test_us_conversion_is_correctly_rounded():
    t_us = np.arange(0, 100_000, 7)
    ev = Events.from_arrays(t_us, np.zeros_like(t_us), np.zeros_like(t_us), np.ones_like(t_us), (1, 1), time_unit="us")
    np.testing.assert_array_equal(ev.t, t_us / 1e6)


def test_a_sensor_size_given_the_wrong_way_round_is_named():
    x, y = np.array([0, 39]), np.array([0, 29])
    with pytest.raises(EventDataError, match=r"the events fit \(30, 40\), the size given the other way round "
                                             r"\(on the command line --sensor 30x40, or correct"):
        Events(np.array([0.0, 1.0]), x, y, np.array([1, -1]), (40, 30))
    with pytest.raises(EventDataError) as err:                    # too small both ways: no such suggestion
        Events(np.array([0.0, 1.0]), np.array([0, 50]), y, np.array([1, -1]), (40, 30))
    assert "other way round" not in str(err.value)
