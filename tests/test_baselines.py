"""Baselines: direct, leaky and high-pass-filtered integration, and their frames."""
import math

import numpy as np
import pytest

from evinr_lite import Events, integrate_events
from evinr_lite.teaching import exercises
from evinr_lite.method.baselines import (highpass_filter, highpass_per_event, leaky_integration, reconstruct_baseline)
from evinr_lite.method import EvINRConfig
from evinr_lite.method.tonemap import anchor_level, to_display, tonemap_reinhard


def random_events(n=400, H=5, W=7, seed=0, t_span=(0.1, 1.0)):
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(*t_span, n))
    return Events(t, rng.integers(0, W, n), rng.integers(0, H, n), rng.choice([-1, 1], n), (H, W))


def query_times(ev):
    # unsorted, a repeat, exactly at event times, before the first event and after the last
    return np.array([0.7, ev.t[10], 0.05, ev.t[-1], 0.3, 0.7, 1.4, ev.t[200]])


@pytest.mark.parametrize("cutoff_hz", [0.3, 2.0, 15.0])
def test_hf_vectorised_equals_the_per_event_loop(cutoff_hz):
    ev = random_events()
    q = query_times(ev)
    L0 = np.random.default_rng(1).normal(size=ev.sensor_size)
    a = highpass_filter(ev, q, 0.2, cutoff_hz, L0=L0)
    b = highpass_filter(ev, q, 0.2, cutoff_hz, L0=L0, method="per_event")
    assert a.shape == (len(q),) + ev.sensor_size
    np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-12)
    assert highpass_filter(ev, 0.7, 0.2, cutoff_hz).shape == ev.sensor_size
    with pytest.raises(ValueError, match="vectorised"):
        highpass_filter(ev, q, 0.2, cutoff_hz, method="loop")


def test_hf_with_cutoff_zero_and_leak_zero_are_integration():
    ev = random_events(seed=2)
    q = query_times(ev)
    ref = integrate_events(ev, q, C=0.3, L0=0.5)
    np.testing.assert_allclose(highpass_filter(ev, q, 0.3, 0.0, L0=0.5), ref, atol=1e-12)
    np.testing.assert_allclose(highpass_filter(ev, q, 0.3, 0.0, L0=0.5, method="per_event"), ref, atol=1e-12)
    np.testing.assert_allclose(leaky_integration(ev, q, 0.3, 0.0, L0=0.5), ref, atol=1e-12)
    pair = integrate_events(ev, q, C=(0.2, 0.4))
    np.testing.assert_allclose(leaky_integration(ev, q, (0.2, 0.4)), pair, atol=1e-12)


def test_leak_decays_as_exp_of_minus_leak_times_age():
    ev = Events(np.array([0.2, 0.5]), np.array([1, 1]), np.array([0, 0]), np.array([1, -1]), (2, 3))
    leak, C, L0 = 3.0, 0.25, 0.7
    q = np.array([0.2, 0.3, 0.5, 0.9])
    L = leaky_integration(ev, q, C, leak, L0=L0)
    expected = [C, C * math.exp(-leak * 0.1), C * math.exp(-leak * 0.3) - C,
                C * math.exp(-leak * 0.7) - C * math.exp(-leak * 0.4)]
    np.testing.assert_allclose(L[:, 0, 1] - L0, expected, rtol=1e-12)
    np.testing.assert_allclose(np.delete(L.reshape(4, -1), 1, axis=1), L0)     # other pixels keep L0
    # the high-pass filter lets L0 decay too, at alpha = 2 pi cutoff
    hf = highpass_filter(Events.empty((2, 3)), [0.0, 0.4], 0.2, cutoff_hz=0.5, L0=L0, t_start=0.0)
    np.testing.assert_allclose(hf[:, 0, 0], [L0, L0 * math.exp(-2 * math.pi * 0.5 * 0.4)], rtol=1e-12)


def test_exercise_reference_is_the_filter():
    ev = random_events(n=120, seed=3)
    alpha = 2 * math.pi * 1.5
    direct = highpass_per_event(ev.t, ev.x, ev.y, ev.p, ev.sensor_size, 0.2, alpha, t_end=1.1, t_start=0.0)
    np.testing.assert_allclose(direct, highpass_filter(ev, 1.1, 0.2, 1.5, t_start=0.0), rtol=1e-10, atol=1e-12)
    assert exercises.check("highpass_per_event", highpass_per_event, verbose=False)
    wrong = lambda t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0: highpass_per_event(
        t, x, y, p, sensor_size, C, alpha, t_end=t[-1], t_start=t_start)      # forgets the final decay
    assert not exercises.check("highpass_per_event", wrong, verbose=False)


def test_bad_arguments_are_named():
    ev = random_events(n=20)
    with pytest.raises(ValueError, match="cutoff_hz"):
        highpass_filter(ev, [0.5], 0.2, cutoff_hz=-1.0)
    with pytest.raises(ValueError, match="leak_hz"):
        leaky_integration(ev, [0.5], 0.2, leak_hz=float("nan"))
    with pytest.raises(ValueError, match="L0"):
        leaky_integration(ev, [0.5], 0.2, L0=np.zeros((3, 3)))
    with pytest.raises(ValueError, match="before t_start"):
        highpass_filter(ev, [0.05], 0.2, t_start=0.5)


@pytest.mark.parametrize("method, params", [("integration", {}), ("leaky", {"leak_hz": 2.0}), ("hf", {"cutoff_hz": 1.0})])
def test_reconstruct_baseline_makes_frames_like_the_solver(method, params):
    ev = random_events(n=600, H=6, W=8, seed=4)
    q = np.array([0.3, 0.6, 0.9])
    rec = reconstruct_baseline(ev, q, method, C=0.2, gamma=0.6, **params)
    assert rec.frames.shape == (3, 6, 8) and rec.frames.dtype == np.float32
    assert np.all((rec.frames >= 0) & (rec.frames <= 1))
    np.testing.assert_array_equal(rec.times, q)
    assert rec.history["train_time_s"] == 0.0 and rec.method == method
    # anchored like the solver: over 64 times spread over the span the frames' mean is display_mean
    grid = np.linspace(ev.t[0], ev.t[-1], 64)
    assert rec.params["tonemap"] == "linear" == EvINRConfig().tonemap
    assert to_display(rec.at(grid)).mean() == pytest.approx(EvINRConfig().display_mean, abs=1e-9)
    # the paper's display: the mean log intensity sits at Reinhard's grey level
    paper = reconstruct_baseline(ev, q, method, C=0.2, gamma=0.6, display_mean=0.5, tonemap="reinhard", **params)
    assert paper.at(grid).mean() == pytest.approx(anchor_level(0.6, 0.5), abs=1e-9)
    np.testing.assert_allclose(paper.frames, tonemap_reinhard(paper.log_intensity, 0.6), atol=1e-6)
    np.testing.assert_allclose(rec.at(q), rec.log_intensity, atol=1e-12)
    np.testing.assert_allclose(rec.frames_at(q), rec.frames, atol=1e-6)
    # changes between frames are the method's own, whatever the anchor
    raw = {"integration": lambda t: integrate_events(ev, t, 0.2),
           "leaky": lambda t: leaky_integration(ev, t, 0.2, 2.0, t_start=ev.t[0]),
           "hf": lambda t: highpass_filter(ev, t, 0.2, 1.0, t_start=ev.t[0])}[method](q)
    np.testing.assert_allclose(np.diff(rec.log_intensity, axis=0), np.diff(raw, axis=0), atol=1e-12)


def test_reconstruct_baseline_rejects_unknown_methods_and_parameters():
    ev = random_events(n=50)
    with pytest.raises(ValueError, match="method must be one of"):
        reconstruct_baseline(ev, [0.5], "e2vid")
    with pytest.raises(TypeError, match="cutoff_hz"):
        reconstruct_baseline(ev, [0.5], "leaky", cutoff_hz=1.0)


def test_baseline_with_the_offset_solve_removes_integration_ghost():
    from evinr_lite import make_scene, simulate_scene
    from evinr_lite.evaluation import score_sequence

    scene = make_scene("camera", sensor_size=(48, 64), duration=1.0)
    events = simulate_scene(scene, 0.0, 1.0, C=0.2, seed=0)
    times = np.linspace(0.1, 0.9, 5)
    gt = scene.intensity(times)
    plain = reconstruct_baseline(events, times, "integration", C=0.2)
    solved = reconstruct_baseline(events, times, "integration", C=0.2, offset_solve="median_gradient")
    assert np.shape(solved.offset) == (48, 64) and solved.params["offset_solve"] == "median_gradient"
    a = score_sequence(solved.frames, times, gt, times, "clahe", lpips_model=False)["ssim"]
    b = score_sequence(plain.frames, times, gt, times, "clahe", lpips_model=False)["ssim"]
    assert a > b
    with pytest.raises(ValueError, match="offset_solve"):
        reconstruct_baseline(events, times, "integration", C=0.2, offset_solve="median")
