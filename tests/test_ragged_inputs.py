"""Ragged nests ([[0.1], [0.2, 0.3]]: parts of different lengths, which numpy refuses with a bare
"setting an array element with a sequence") are refused by name, with what to give instead, wherever
times, events, samples or frames enter the API (core.guard.dense_array)."""
import numpy as np
import pytest

import evinr_lite as ev
from evinr_lite import EventDataError
from evinr_lite.core.guard import InputError, dense_array

RAGGED = [[0.1], [0.2, 0.3]]


@pytest.fixture(scope="module")
def events():
    rng = np.random.default_rng(0)
    n = 200
    return ev.Events(t=np.sort(rng.uniform(0, 1, n)), x=rng.integers(0, 16, n), y=rng.integers(0, 12, n),
                     p=rng.choice([-1, 1], n), sensor_size=(12, 16))


CASES = {
    "integrate_events": (lambda e: ev.integrate_events(e, RAGGED), "t_query"),
    "reconstruct_baseline": (lambda e: ev.reconstruct_baseline(e, RAGGED), "query times"),
    "reconstruct_baseline hf": (lambda e: ev.reconstruct_baseline(e, RAGGED, method="hf"), "query times"),
    "simulate_events_1d times": (lambda e: ev.simulate_events_1d(np.zeros(2), RAGGED), "sample times"),
    "simulate_events_1d samples": (lambda e: ev.simulate_events_1d(RAGGED, [0.0, 1.0]), "L"),
    "simulate_video times": (lambda e: ev.simulate_video(np.zeros((2, 4, 4)), RAGGED), "sample times"),
    "simulate_video frames": (lambda e: ev.simulate_video([np.zeros((2, 2)), np.zeros((3, 3))], [0.0, 1.0]),
                              "log_frames"),
    "Events t": (lambda e: ev.Events(t=RAGGED, x=[0, 1], y=[0, 1], p=[1, 1], sensor_size=(2, 2)), "Events.t"),
    "Events p": (lambda e: ev.Events(t=[0.1, 0.2], x=[0, 1], y=[0, 1], p=[[1], [1, -1]], sensor_size=(2, 2)),
                 "Events.p"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_a_ragged_input_is_refused_by_name(events, case):
    call, name = CASES[case]
    with pytest.raises(EventDataError, match="ragged") as info:
        call(events)
    assert name in str(info.value)
    assert "\n" not in str(info.value)


def test_dense_array_passes_arrays_and_names_what_is_no_number():
    np.testing.assert_array_equal(dense_array([[1, 2], [3, 4]], "a", np.float64), [[1.0, 2.0], [3.0, 4.0]])
    with pytest.raises(InputError, match=r"a must be numbers, got \['x', 'y'\]"):
        dense_array(["x", "y"], "a", np.float64)
    with pytest.raises(InputError, match="give rows of one length") as info:
        dense_array(RAGGED, "a", want="rows of one length")
    assert type(info.value) is InputError
