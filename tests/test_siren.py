"""SIREN initialisation, shapes and input gradients; the 1-D event fit built on it."""
import numpy as np
import pytest
import torch

from evinr_lite.teaching import pde1d
from evinr_lite.method.siren import Siren, SineLayer, input_gradient


def test_output_shape_and_batch_dims():
    net = Siren(3, 7, hidden_features=32, hidden_layers=2)
    assert net(torch.zeros(5, 3)).shape == (5, 7)
    assert net(torch.zeros(2, 4, 3)).shape == (2, 4, 7)
    assert len(net.activations(torch.zeros(5, 3))) == 4  # first + 2 hidden + head
    with pytest.raises(ValueError, match=r"\[\.\.\., 3\]"):
        net(torch.zeros(5, 2))


def test_first_and_hidden_layer_init_bounds():
    torch.manual_seed(0)
    net = Siren(2, 1, hidden_features=256, hidden_layers=2, omega_0=30.0)
    first, hidden = net.net[0].linear.weight, net.net[1].linear.weight
    assert first.abs().max() <= 1 / 2 and first.abs().max() > 0.45  # U(-1/in, 1/in), in = 2
    bound = np.sqrt(6 / 256) / 30
    assert hidden.abs().max() <= bound and hidden.abs().max() > 0.95 * bound
    # uniform: variance bound^2 / 3
    assert hidden.var().item() == pytest.approx(bound ** 2 / 3, rel=0.05)
    head = net.net[-1]
    assert isinstance(head, torch.nn.Linear) and head.weight.abs().max() <= bound


def test_activation_statistics_stay_order_one_in_depth():
    """SIREN's init keeps pre-activations ~ N(0, 1) and sine outputs ~ arcsine (std 1/sqrt(2))
    through many layers on uniform inputs, instead of exploding or vanishing."""
    torch.manual_seed(0)
    net = Siren(1, 1, hidden_features=512, hidden_layers=8, omega_0=30.0)
    x = torch.rand(4096, 1) * 2 - 1
    with torch.no_grad():
        h = x
        stds, pre_stds = [], []
        for layer in net.net[:-1]:
            pre_stds.append(layer.preactivation(h).std().item())
            h = layer(h)
            stds.append(h.std().item())
        # arcsine distribution on [-1, 1]: about half the mass beyond |0.7| (a normal would put ~1/3 there)
        frac_outer = (h.abs() > np.sqrt(0.5)).float().mean().item()
    assert all(0.55 < s < 0.8 for s in stds), stds
    assert all(0.7 < s < 1.5 for s in pre_stds[1:]), pre_stds
    assert 0.4 < frac_outer < 0.6


def test_outermost_sine_bounds_output():
    net = Siren(1, 4, hidden_features=16, hidden_layers=1, outermost_linear=False)
    y = net(torch.linspace(-1, 1, 50)[:, None])
    assert y.abs().max() <= 1.0 and isinstance(net.net[-1], SineLayer)


def test_first_omega_defaults_to_omega():
    assert Siren(1, 1, 8, 1, omega_0=10.0).net[0].omega_0 == 10.0
    assert Siren(1, 1, 8, 1, omega_0=10.0, first_omega_0=3.0).net[0].omega_0 == 3.0


@pytest.mark.parametrize("kwargs", [dict(hidden_features=0), dict(hidden_layers=-1), dict(omega_0=0.0)])
def test_bad_arguments(kwargs):
    with pytest.raises(ValueError):
        Siren(1, 1, **kwargs)


def test_input_gradient_matches_finite_differences():
    torch.manual_seed(1)
    net = Siren(2, 1, hidden_features=32, hidden_layers=2).double()
    x = (torch.rand(6, 2, dtype=torch.float64) * 2 - 1).requires_grad_(True)
    g = input_gradient(net(x), x)
    h = 1e-6
    for d in range(2):
        e = torch.zeros(1, 2, dtype=torch.float64)
        e[0, d] = h
        with torch.no_grad():
            fd = (net(x + e) - net(x - e))[:, 0] / (2 * h)
        assert torch.allclose(g[:, d], fd, rtol=1e-5, atol=1e-6)
    # double back-propagation: a loss on the gradient reaches the weights
    g.pow(2).sum().backward()
    assert net.net[0].linear.weight.grad is not None and net.net[0].linear.weight.grad.abs().sum() > 0
    with pytest.raises(ValueError, match="requires_grad"):
        input_gradient(net(x.detach()), x.detach())


def test_time_siren_derivative_is_in_seconds():
    torch.manual_seed(0)
    model = pde1d.TimeSiren1D((2.0, 4.0), hidden_features=16, hidden_layers=1).double()
    t = np.linspace(2.1, 3.9, 7)
    h = 1e-6
    fd = (model.predict(t + h) - model.predict(t - h)) / (2 * h)
    assert np.allclose(model.derivative(t), fd, rtol=1e-5, atol=1e-6)
    shifted = model.shifted(0.7)
    assert np.allclose(shifted.predict(t) - model.predict(t), 0.7)
    assert np.allclose(shifted.derivative(t), model.derivative(t))


# ---- the 1-D fit -------------------------------------------------------------------

def _signal(t):
    return -1.0 + 0.8 * np.sin(2 * np.pi * 1.5 * t) + 0.3 * t


def _events(C=0.1):
    # ideal level crossings of _signal, found on a fine grid (independent of the simulator)
    t = np.linspace(0, 1, 200001)
    v = _signal(t)
    ref, te, pe = v[0], [], []
    for ti, vi in zip(t, v):
        while vi >= ref + C:
            ref += C
            te.append(ti)
            pe.append(1)
        while vi <= ref - C:
            ref -= C
            te.append(ti)
            pe.append(-1)
    return np.array(te), np.array(pe, dtype=np.int8)


@pytest.fixture(scope="module")
def events():
    return _events()


def test_fit_siren_1d_recovers_signal_with_anchor(events):
    torch.manual_seed(123)  # the fit seeds itself; this must not matter
    model, hist = pde1d.fit_siren_1d(events, (0.0, 1.0), 0.1, n_iters=300, anchor=(0.0, _signal(0.0)), seed=0)
    t = np.linspace(0, 1, 501)
    rmse = np.sqrt(np.mean((model.predict(t) - _signal(t)) ** 2))
    assert rmse < 0.15
    assert hist["loss"][-1] < 0.1 * hist["loss"][0]
    assert len(hist["loss"]) == len(hist["temporal"]) == len(hist["anchor"]) == 300
    model2, hist2 = pde1d.fit_siren_1d(events, (0.0, 1.0), 0.1, n_iters=300, anchor=(0.0, _signal(0.0)), seed=0)
    assert np.array_equal(model.predict(t), model2.predict(t))  # deterministic


def test_offset_is_not_determined_by_the_events(events):
    model, _ = pde1d.fit_siren_1d(events, (0.0, 1.0), 0.1, n_iters=50, seed=0)
    loss = pde1d.evaluate_temporal_loss(model, events, 0.1, 0.025)
    assert pde1d.evaluate_temporal_loss(model.shifted(1.5), events, 0.1, 0.025) == pytest.approx(loss, rel=1e-6)


def test_prior_mean_and_anchor_set_the_offset(events):
    m, _ = pde1d.fit_siren_1d(events, (0.0, 1.0), 0.1, n_iters=200, prior_mean=-0.5, seed=0)
    mid = np.linspace(0.0125, 0.9875, 40)
    assert m.predict(mid).mean() == pytest.approx(-0.5, abs=0.02)
    m, _ = pde1d.fit_siren_1d(events, (0.0, 1.0), 0.1, n_iters=200, anchor=(0.5, 2.0), seed=0)
    assert m.predict([0.5])[0] == pytest.approx(2.0, abs=0.02)


def test_fit_siren_difference_form_and_errors(events):
    m, _ = pde1d.fit_siren_1d(events, (0.0, 1.0), 0.1, n_iters=300, anchor=(0.0, _signal(0.0)), form="difference")
    t = np.linspace(0, 1, 201)
    assert np.sqrt(np.mean((m.predict(t) - _signal(t)) ** 2)) < 0.15
    with pytest.raises(ValueError, match="form"):
        pde1d.fit_siren_1d(events, (0.0, 1.0), 0.1, n_iters=1, form="integral")
    with pytest.raises(ValueError, match="window"):
        pde1d.fit_siren_1d(events, (0.0, 1.0), 0.1, window=0.0)
