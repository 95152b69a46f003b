"""Round 6 of the Python API audit: inputs researchers pass from a notebook (``import evinr_lite as ev``).

Classes covered, each failing before its fix:

- torch tensors that require grad (or sit on a GPU) where arrays are taken: Events, the simulator (frames,
  sample times, a callable L), query times (reconstruct, Reconstruction.at, baselines, integrate_events) and the
  scorer (score_sequence, score_frames, mse): taken as their values (``core.checks.host_array``), same result as
  numpy, never torch's "Can't call numpy() on Tensor that requires grad".
- 0-d arrays and tensors as numbers (``t.max()``, ``np.array(0.2)``): C, t_start / t_end, duration, tol; same
  result as the plain float.
- float32 times coarser than the events' microsecond (from 16 s on: query times, sample times): refused naming
  float64, not silently moved.
- query times (or a span) in microseconds or on the absolute clock: refused naming the unit and t_origin, not a
  "use a longer tau" refusal or a silent 200,000 s baseline.
- simulator sample times in microseconds (integers taken as seconds): refused.
- a sensor_size larger than any camera: refused before anything is allocated.
- image stacks [F, H, W, 1] (and one image [H, W, 1]) score as grey [F, H, W]; colour [F, H, W, 3] is refused
  with the fix; uint16 frames are named as uint16 with their scale, not as "floats in [19, 65535]".

Tiny sensors and short spans: the file runs in seconds.
"""
import numpy as np
import pytest
import torch

import evinr_lite as ev
from evinr_lite.core.checks import real_number
from evinr_lite.core.events import InputError
from evinr_lite.evaluation import metrics, scoring

FAST = dict(n_iters=3, progress=False)


@pytest.fixture(scope="module")
def scene():
    return ev.make_scene("camera", sensor_size=(12, 16), duration=0.3)


@pytest.fixture(scope="module")
def events(scene):
    return ev.simulate_scene(scene, 0.0, 0.3, C=0.2, seed=0)


def grad(a):
    return torch.tensor(np.asarray(a, dtype=np.float64), requires_grad=True)


def same_events(a, b):
    return all(np.array_equal(getattr(a, k), getattr(b, k)) for k in "txyp") and a.sensor_size == b.sensor_size


@pytest.fixture(scope="module")
def stacks():
    rng = np.random.default_rng(0)
    gt = rng.uniform(0, 1, (3, 12, 16))
    return np.clip(gt + rng.normal(0, 0.05, gt.shape), 0, 1), gt, np.array([0.1, 0.15, 0.2])


# ---- torch tensors that require grad ------------------------------------------------------------------

def test_events_take_tensors_that_require_grad():
    t, x, y, p = np.linspace(0, 0.1, 6), np.arange(6) % 4, np.arange(6) % 3, np.array([1, -1] * 3)
    plain = ev.Events(t, x, y, p, (3, 4))
    assert same_events(ev.Events(grad(t), torch.tensor(x), torch.tensor(y), torch.tensor(p), (3, 4)), plain)
    assert same_events(ev.Events.from_arrays(grad(t[::-1].copy()), x[::-1], y[::-1], p[::-1], (3, 4), sort=True),
                       ev.Events.from_arrays(t[::-1].copy(), x[::-1], y[::-1], p[::-1], (3, 4), sort=True))
    assert same_events(ev.Events.from_array(grad(plain.to_array()), (3, 4)), plain)


def test_the_simulator_takes_tensors_that_require_grad():
    t = np.linspace(0, 0.1, 5)
    logf = np.log(np.random.default_rng(0).uniform(0.1, 1, (5, 3, 4)))
    assert same_events(ev.simulate_video(grad(logf), grad(t), C=0.1, seed=0), ev.simulate_video(logf, t, C=0.1, seed=0))
    plain = ev.simulate_events_1d(lambda s: np.sin(np.asarray(s) * 30), t, C=0.1)
    as_tensor = ev.simulate_events_1d(lambda s: torch.sin(grad(s) * 30), t, C=0.1)
    assert same_events(as_tensor, plain)


def test_query_times_that_require_grad(events):
    q = np.array([0.1, 0.2])
    np.testing.assert_array_equal(ev.integrate_events(events, grad(q), C=0.2), ev.integrate_events(events, q, C=0.2))
    np.testing.assert_array_equal(ev.reconstruct_baseline(events, grad(q), "hf", C=0.2).frames,
                                  ev.reconstruct_baseline(events, q, "hf", C=0.2).frames)
    rec = ev.reconstruct(events, grad(q), ev.EvINRConfig(**FAST))
    np.testing.assert_array_equal(rec.times, q)
    np.testing.assert_array_equal(rec.at(grad([0.15])), rec.at([0.15]))


def test_the_scorer_takes_tensors_that_require_grad(stacks):
    pred, gt, t = stacks
    a = scoring.score_sequence(grad(pred), grad(t), grad(gt), t, lpips_model=False)
    b = scoring.score_sequence(pred, t, gt, t, lpips_model=False)
    assert (a["mse"], a["ssim"]) == (b["mse"], b["ssim"])
    assert metrics.score_frames(grad(pred), gt)["mse"] == metrics.score_frames(pred, gt)["mse"]
    assert metrics.mse(grad(pred[0]), gt[0]) == metrics.mse(pred[0], gt[0])


# ---- 0-d arrays and tensors are numbers ---------------------------------------------------------------------

def test_zero_d_arrays_and_tensors_are_numbers(scene, events, stacks):
    plain = ev.simulate_scene(scene, 0.0, 0.3, C=0.2, seed=0)
    assert same_events(ev.simulate_scene(scene, np.array(0.0), np.array(0.3), C=np.array(0.2), seed=0), plain)
    assert same_events(ev.simulate_scene(scene, 0.0, torch.tensor(0.3, dtype=torch.float64),
                                         C=torch.tensor(0.2, dtype=torch.float64), seed=0), plain)
    assert ev.make_scene("camera", sensor_size=(12, 16), duration=np.array(0.3)).duration == 0.3
    q = [0.1, 0.2]
    np.testing.assert_array_equal(ev.integrate_events(events, q, C=np.array(0.2)), ev.integrate_events(events, q, C=0.2))
    np.testing.assert_array_equal(ev.reconstruct_baseline(events, q, C=np.array(0.2)).frames,
                                  ev.reconstruct_baseline(events, q, C=0.2).frames)
    pred, gt, t = stacks
    assert scoring.score_sequence(pred, t, gt, t, lpips_model=False, tol=np.array(1e-3))["mse"] == \
        scoring.score_sequence(pred, t, gt, t, lpips_model=False, tol=1e-3)["mse"]
    assert real_number(torch.tensor(2.0), "x") == 2.0
    with pytest.raises(InputError, match="must be a finite number"):
        real_number(np.array([2.0, 3.0]), "x")   # several values are not one number


# ---- float32 times, times in other units ---------------------------------------------------------------------

def test_float32_times_coarser_than_a_microsecond_are_refused_naming_float64(events):
    late = ev.Events(events.t + 20.0, events.x, events.y, events.p, events.sensor_size)
    q32 = np.array([20.1, 20.2], np.float32)
    for fn in (lambda: ev.reconstruct(late, q32, ev.EvINRConfig(**FAST)),
               lambda: ev.reconstruct(late, torch.tensor([20.1, 20.2]), ev.EvINRConfig(**FAST)),
               lambda: ev.reconstruct_baseline(late, q32, C=0.2),
               lambda: ev.integrate_events(late, q32, C=0.2),
               lambda: ev.simulate_video(np.zeros((3, 2, 2)), np.array([20.0, 20.05, 20.1], np.float32))):
        with pytest.raises(InputError, match="float32 seconds.*make them float64"):
            fn()
    # short spans: float32 keeps the microsecond, taken as the float64 of the same values
    q = np.array([0.1, 0.2], np.float32)
    np.testing.assert_array_equal(ev.integrate_events(events, q, C=0.2),
                                  ev.integrate_events(events, q.astype(np.float64), C=0.2))


def test_query_times_in_microseconds_or_on_the_absolute_clock_are_refused(events):
    with pytest.raises(InputError, match="divide microseconds by 1e6"):
        ev.reconstruct(events, [100_000, 200_000], ev.EvINRConfig(**FAST))
    with pytest.raises(InputError, match="divide microseconds by 1e6"):
        ev.reconstruct_baseline(events, [100_000, 200_000], C=0.2)
    us = np.round((events.t + 1.6e9) * 1e6).astype(np.int64)
    absolute = ev.Events.from_arrays(us, events.x, events.y, events.p, events.sensor_size, time_unit="us")
    assert absolute.t_origin > 1e9
    with pytest.raises(InputError, match="subtract events.t_origin"):
        ev.reconstruct(absolute, [absolute.t_origin + 0.1], ev.EvINRConfig(**FAST))
    with pytest.raises(InputError, match="subtract events.t_origin"):
        ev.reconstruct_baseline(absolute, absolute.t_origin + 0.1, C=0.2, t_start=0.0)


def test_simulator_sample_times_in_microseconds_are_refused():
    t_us = np.arange(0, 1_000_001, 250_000)          # 1 s at 4 Hz, in microseconds
    with pytest.raises(InputError, match="sample times t span .*divide microseconds by 1e6"):
        ev.simulate_video(np.zeros((5, 2, 2)), t_us, C=0.1)


def test_a_sensor_larger_than_any_camera_is_refused():
    with pytest.raises(InputError, match="larger than any event camera"):
        ev.Events(np.zeros(1), [0], [0], [1], (480, 640_000))


# ---- image stacks -------------------------------------------------------------------------------------------

def test_a_trailing_channel_of_one_scores_as_grey(stacks):
    pred, gt, t = stacks
    plain = scoring.score_sequence(pred, t, gt, t, lpips_model=False)
    for p_, g_ in ((pred[..., None], gt), (pred, gt[..., None]), (pred[..., None], gt[..., None])):
        got = scoring.score_sequence(p_, t, g_, t, lpips_model=False)
        assert (got["mse"], got["ssim"]) == (plain["mse"], plain["ssim"])
    assert metrics.score_frames(pred[..., None], gt[..., None]) == metrics.score_frames(pred, gt)
    assert metrics.ssim(pred[0][..., None], gt[0]) == metrics.ssim(pred[0], gt[0])


def test_colour_and_16_bit_stacks_are_refused_naming_the_fix(stacks):
    pred, gt, t = stacks
    with pytest.raises(InputError, match=r"\(3, 12, 16, 3\); colour images: make them grey first"):
        scoring.score_sequence(pred, t, np.repeat(gt[..., None], 3, -1), t, lpips_model=False)
    with pytest.raises(InputError, match=r"uint16 integers .*frames / 65535\.0"):
        scoring.score_sequence(pred, t, (gt * 65535).astype(np.uint16), t, lpips_model=False)


def test_ragged_query_times_are_refused_as_not_seconds(events):
    """A ragged list of times is no array: Reconstruction.at and reconstruct refuse it as not seconds, never with
    numpy's "inhomogeneous shape" ValueError (the float32 check added in this round must not call np.asarray first)."""
    rec = ev.reconstruct(events, [0.1], ev.EvINRConfig(C=0.2, **FAST))
    with pytest.raises(InputError, match="must be seconds"):
        rec.at([[0.1], [0.2, 0.3]])
    with pytest.raises(InputError, match="must be seconds"):
        ev.reconstruct(events, [[0.1], [0.2, 0.3]], ev.EvINRConfig(C=0.2, **FAST))
