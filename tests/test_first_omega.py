"""The first layer's frequency per second (EvINRConfig.first_omega_per_s): each network's first_omega_0
follows its window's length, so the temporal prior is the same in a short window as in a long one."""
import math

import numpy as np
import pytest

from evinr_lite.core.events import EventDataError
from evinr_lite.method import EvINRConfig, reconstruct
from evinr_lite.method.ensemble import split_windows
from evinr_lite.method.streaming import train_window
from evinr_lite.sim.recordings import synthetic_recording


def test_the_frequency_scales_with_the_window_length():
    cfg = EvINRConfig()
    assert cfg.first_layer_omega([[0.0, 2.0]]) == pytest.approx(5.0)
    assert cfg.first_layer_omega([[3.0, 7.75]]) == pytest.approx(11.875)
    windows = split_windows(0.0, 60.0, cfg.tau, cfg.overlap)          # equal windows of 4.75 s
    assert cfg.first_layer_omega(windows) == pytest.approx(5.0 * (windows[0, 1] - windows[0, 0]) / 2)
    assert EvINRConfig(first_omega_per_s=8.0).first_layer_omega([[0.0, 0.5]]) == pytest.approx(2.0)


def test_presets_keep_a_fixed_frequency_per_window():
    assert EvINRConfig.paper().first_layer_omega([[0.0, 2.0]]) is None       # SIREN's omega_0 in every layer
    assert EvINRConfig.v0_1().first_layer_omega([[0.0, 2.0]]) == 10.0
    assert EvINRConfig.v0_1().first_layer_omega([[0.0, 5.0]]) == 10.0
    assert EvINRConfig(first_omega_per_s=None, first_omega_0=7.0).first_layer_omega([[0.0, 3.0]]) == 7.0


@pytest.mark.parametrize("bad", [0, -1.0, math.nan, math.inf, "5", True, [5.0]])
def test_a_bad_frequency_is_refused_by_name(bad):
    with pytest.raises(EventDataError, match="first_omega_per_s"):
        EvINRConfig(first_omega_per_s=bad)


def test_the_networks_get_it_in_both_solvers():
    """reconstruct (whole span) and the stream's train_window build their networks with it, and the
    first layer changes as fast per second in a 0.5 s window as in a 1 s one."""
    rec = synthetic_recording(sensor_size=(12, 16), duration=1.0, n_frames=3, C=0.2, seed=0)
    ev = rec.events
    rates = []
    for span in (0.5, 1.0):
        t0 = float(ev.t[0])
        cfg = EvINRConfig(C=0.2, progress=False)
        r = reconstruct(ev.slice_time(t0, t0 + span), np.array([t0 + span / 2]), cfg, t_start=t0, t_end=t0 + span)
        assert r.model.first_omega_0 == pytest.approx(5.0 * span / 2)
        windows = np.array([[t0, t0 + span]])
        model, _ = train_window(ev.slice_time(t0, t0 + span), windows, 0, cfg)
        assert model.first_omega_0 == pytest.approx(r.model.first_omega_0)
        # d(first-layer argument)/dt in rad/s: first_omega_0 x weight x (2 / window length)
        rates.append(model.first_omega_0 * model.weights[0].detach().numpy() * 2.0 / span)
    np.testing.assert_allclose(rates[0], rates[1], rtol=1e-5)


def test_a_frequency_per_window_that_would_be_ignored_is_refused_with_the_fix():
    with pytest.raises(EventDataError, match="first_omega_per_s=None"):
        EvINRConfig(first_omega_0=30.0)
    assert EvINRConfig(first_omega_per_s=None, first_omega_0=30.0).first_layer_omega([[0.0, 2.0]]) == 30.0
    assert EvINRConfig.v0_1(first_omega_0=30.0).first_layer_omega([[0.0, 2.0]]) == 30.0   # presets: per window
