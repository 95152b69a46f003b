"""FrameINR (batched SIRENs, forward-mode dF/dt) and the losses: they compute what they claim."""
import numpy as np
import pytest
import torch

from evinr_lite import Events
from evinr_lite.method.binning import bisect_boundaries, events_to_frames
from evinr_lite.method.losses import (temporal_loss_derivative, temporal_loss_difference, tikhonov, total_variation)
from evinr_lite.method.models import FrameINR


def small_model(N=2, size=(3, 4), **kw):
    windows = [[0.0, 1.0], [0.8, 2.0]][:N]
    return FrameINR(size, windows, hidden_features=16, hidden_layers=2, seed=3, **kw)


def test_shapes_and_seed():
    m = small_model()
    t = torch.tensor([[0.1, 0.5, 0.9], [1.0, 1.5, 1.9]], dtype=torch.float64)
    assert m(t).shape == (2, 3, 3, 4)
    torch.testing.assert_close(m(t), small_model()(t))
    assert not torch.equal(m(t), FrameINR((3, 4), [[0, 1], [0.8, 2]], 16, 2, seed=4)(t))


def test_forward_mode_derivative_matches_autograd():
    m = small_model(omega_0=10.0)
    t = torch.tensor([[0.1, 0.5, 0.9], [1.0, 1.5, 1.9]], dtype=torch.float64, requires_grad=True)
    F, dF = m.forward_with_derivative(t)
    torch.testing.assert_close(F, m(t))
    for y in range(3):
        for x in range(4):
            (g,) = torch.autograd.grad(m(t)[:, :, y, x].sum(), t)
            torch.testing.assert_close(dF[:, :, y, x].double(), g, rtol=1e-4, atol=1e-5)


def test_derivative_is_per_second_and_differentiable():
    m = small_model(N=1)
    t = torch.tensor([[0.3, 0.6]], dtype=torch.float64)
    _, dF = m.forward_with_derivative(t)
    h = 1e-4
    fd = (m(t + h) - m(t - h)).double() / (2 * h)
    torch.testing.assert_close(dF.double(), fd, rtol=2e-2, atol=2e-3)
    dF.pow(2).sum().backward()  # a loss on dF/dt reaches every weight (double back-propagation)
    for name, p in m.named_parameters():  # ... except the head's bias: a constant has no derivative
        assert (p.grad is None) == (name == "head_bias"), name
        assert name == "head_bias" or p.grad.abs().sum() > 0, name


def test_networks_are_independent():
    m = small_model()
    t = torch.tensor([[0.2, 0.4], [1.2, 1.4]], dtype=torch.float64)
    m(t)[0].sum().backward()
    assert all(p.grad[1].abs().sum() == 0 for p in m.parameters())
    assert all(p.grad[0].abs().sum() > 0 for p in m.parameters())


def test_difference_loss_is_exact_and_derivative_loss_has_taylor_error():
    # L(t) = a t^3 per pixel: boundary differences are exact; the mid-point derivative is off by
    # a * d^3 / 4 per bin (Taylor remainder of the mid-point rule for a cubic).
    a = torch.tensor([1.0, -2.0]).reshape(1, 1, 2)
    b = torch.linspace(0, 1, 5, dtype=torch.float64)
    L = lambda t: (t[:, None, None] ** 3) * a
    frames = (L(b[1:]) - L(b[:-1])).float()
    assert temporal_loss_difference(L(b).float(), frames).item() == pytest.approx(0.0, abs=1e-12)
    c, d = 0.5 * (b[1:] + b[:-1]), b[1:] - b[:-1]
    dL = (3 * c[:, None, None] ** 2 * a).float()
    expected = torch.mean((a * d[:, None, None] ** 3 / 4).float() ** 2)
    assert temporal_loss_derivative(dL, frames, d.float()).item() == pytest.approx(expected.item(), rel=1e-4)
    # and it is exact for a quadratic
    Lq = lambda t: (t[:, None, None] ** 2) * a
    fq = (Lq(b[1:]) - Lq(b[:-1])).float()
    assert temporal_loss_derivative((2 * c[:, None, None] * a).float(), fq, d.float()).item() < 1e-12


def test_regularizers_against_numpy():
    rng = np.random.default_rng(0)
    F = rng.normal(size=(2, 5, 6))
    dx, dy = np.diff(F, axis=2), np.diff(F, axis=1)
    t = torch.tensor(F)
    assert tikhonov(t).item() == pytest.approx((dx ** 2).mean() + (dy ** 2).mean())
    assert total_variation(t).item() == pytest.approx(np.abs(dx).mean() + np.abs(dy).mean())
    assert tikhonov(t + 3.0).item() == pytest.approx(tikhonov(t).item())  # blind to the offset


def test_bisection_gives_equal_count_halves():
    rng = np.random.default_rng(1)
    t = np.sort(np.concatenate([rng.uniform(0, 0.2, 300), rng.uniform(0.2, 1.0, 100)]))
    ev = Events(t, np.zeros(400, int), np.zeros(400, int), np.ones(400, int), (1, 1))
    b = np.array([0.0, 0.5, 1.0])
    b2 = bisect_boundaries(ev, b)
    assert len(b2) == 5 and np.all(np.diff(b2) > 0) and np.all(b2[::2] == b)
    counts = events_to_frames(ev, b2).counts
    assert abs(counts[0] - counts[1]) <= 1 and abs(counts[2] - counts[3]) <= 1
    assert b2[1] < 0.25  # the dense first half is cut early, not at the time mid-point
    empty = Events(np.array([0.9, 0.95]), [0, 0], [0, 0], [1, 1], (1, 1))
    np.testing.assert_allclose(bisect_boundaries(empty, [0.0, 0.5]), [0.0, 0.25, 0.5])


def test_one_times_frame_is_the_same_alone_as_in_a_batch():
    """A prediction of one time is computed as two equal rows: a matrix-vector product may be summed in another
    order than a product of several rows (MKL on AVX-512: 5e-3 apart where the closed-form head's weights, here
    scaled to thousands, cancel), and a frame must not depend on which other times were asked for; the in-place
    ``out`` path too."""
    m = FrameINR((6, 7), [[0.0, 1.0], [0.8, 2.0]], hidden_features=128, hidden_layers=2, seed=3)
    with torch.no_grad():
        m.head_weight.mul_(2000.0)
        t = torch.tensor([[0.1, 0.35, 0.6, 0.9], [1.0, 1.2, 1.5, 1.9]], dtype=torch.float64)
        batch = m(t)
        for i in range(t.shape[1]):
            assert torch.equal(m(t[:, i:i + 1]), batch[:, i:i + 1])
            out = torch.empty((2, 1, 6, 7))
            assert m(t[:, i:i + 1], out=out) is out and torch.equal(out, batch[:, i:i + 1])
