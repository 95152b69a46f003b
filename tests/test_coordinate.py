"""The coordinate-based EvINR F(x, y, t): derivatives, units, losses, training, anchoring, errors."""
import math

import numpy as np
import pytest
import torch
from torch import nn

from evinr_lite.teaching import exercises
from evinr_lite import make_scene, simulate_scene
from evinr_lite.method.coordinate import (CoordinateConfig, CoordinateINR, bin_events, predict_anchored, reconstruct_coordinate, split_index, temporal_loss, tikhonov_autograd, train_coordinate_inr)
from evinr_lite.method.tonemap import anchor_level
from evinr_lite.core.events import EventDataError, Events

SMALL = dict(hidden_features=32, hidden_layers=2)


@pytest.fixture(autouse=True, scope="module")
def one_thread():
    """These networks are tiny: one thread is as fast, and is not slowed tenfold when other
    processes keep the cores busy (thread oversubscription)."""
    n = torch.get_num_threads()
    torch.set_num_threads(1)
    yield
    torch.set_num_threads(n)


def _points(M=40, size=(16, 20), t_range=(0.0, 1.0), seed=0):
    g = torch.Generator().manual_seed(seed)
    H, W = size
    x = torch.rand(M, generator=g, dtype=torch.float64) * (W - 1)
    y = torch.rand(M, generator=g, dtype=torch.float64) * (H - 1)
    t = t_range[0] + torch.rand(M, generator=g, dtype=torch.float64) * (t_range[1] - t_range[0])
    return x, y, t


# ---- derivatives and units ---------------------------------------------------------------

def test_autograd_derivatives_match_finite_differences():
    model = CoordinateINR((16, 20), (0.3, 0.8), **SMALL, seed=1).double()
    x, y, t = _points(t_range=(0.3, 0.8))
    F, dF_dt, dF_dx, dF_dy = model.derivatives(x, y, t, create_graph=False)
    assert F.shape == dF_dt.shape == dF_dx.shape == dF_dy.shape == (40,)
    with torch.no_grad():
        assert torch.allclose(F, model(x, y, t))
        hx, ht = 1e-5, 1e-7          # one hundred-thousandth of a pixel, a tenth of a microsecond
        fd_x = (model(x + hx, y, t) - model(x - hx, y, t)) / (2 * hx)
        fd_y = (model(x, y + hx, t) - model(x, y - hx, t)) / (2 * hx)
        fd_t = (model(x, y, t + ht) - model(x, y, t - ht)) / (2 * ht)
    for got, fd in ((dF_dx, fd_x), (dF_dy, fd_y), (dF_dt, fd_t)):
        assert torch.allclose(got, fd, rtol=1e-5, atol=1e-6 * fd.abs().max().item())
    # the per-second derivative is large for a half-second window: the units are not normalised ones
    assert dF_dt.abs().max() > 1.0


def test_units_follow_the_window_and_the_sensor_size():
    """Same weights, window and sensor twice as long: F_B(x, y, t) = F_A(x/2, y/2, t/2), so every
    derivative per pixel / per second must halve (a normalised-unit derivative would not change)."""
    a = CoordinateINR((16, 20), (0.0, 1.0), **SMALL, seed=3)
    b = CoordinateINR((31, 39), (0.0, 2.0), **SMALL, seed=99)
    b.load_state_dict(a.state_dict())
    x, y, t = _points()
    Fa, dta, dxa, dya = a.derivatives(x, y, t, create_graph=False)
    Fb, dtb, dxb, dyb = b.derivatives(2 * x, 2 * y, 2 * t, create_graph=False)
    assert torch.allclose(Fb, Fa, atol=1e-5)
    for da, db in ((dta, dtb), (dxa, dxb), (dya, dyb)):
        assert torch.allclose(db, 0.5 * da, rtol=1e-4, atol=1e-5)
    assert a.scales == pytest.approx((2 / 19, 2 / 15, 2.0))


class _Analytic(nn.Module):
    """Stands in for the SIREN: evaluates a known L(x, y, t) given in pixels and seconds."""

    def __init__(self, model, L):
        super().__init__()
        self.sx, self.sy, self.st = model.scales
        self.tc = 0.5 * sum(model.t_range)
        self.L = L
        self.net = nn.ModuleList([nn.Module()])
        self.net[0].linear = nn.Linear(1, 1).double()   # normalize() reads dtype and device here

    def forward(self, c):
        x, y, t = (c[:, 0] + 1) / self.sx, (c[:, 1] + 1) / self.sy, c[:, 2] / self.st + self.tc
        return self.L(x, y, t)[:, None]


def _analytic_model(L, size=(8, 10), t_range=(0.0, 1.0)):
    model = CoordinateINR(size, t_range, **SMALL)
    model.siren = _Analytic(model, L)
    return model


def _bins_of(L, size, t_range, n_bins):
    """Exact event frames of L: E_i = L(b_{i+1}) - L(b_i) at every pixel (what ideal events sum to, up to C)."""
    H, W = size
    b = torch.linspace(*t_range, n_bins + 1, dtype=torch.float64)
    y, x = torch.meshgrid(torch.arange(H, dtype=torch.float64), torch.arange(W, dtype=torch.float64), indexing="ij")
    Lb = torch.stack([L(x.ravel(), y.ravel(), torch.full((H * W,), float(v), dtype=torch.float64)) for v in b])
    return b, (Lb[1:] - Lb[:-1]).reshape(n_bins, H, W)


def _temporal_at_centres(model, b, E):
    B, H, W = E.shape
    k = torch.arange(B * H * W)
    bi, y, x = split_index(k, (H, W))
    centres, durations = 0.5 * (b[1:] + b[:-1]), b[1:] - b[:-1]
    _, dF_dt, dF_dx, dF_dy = model.derivatives(x, y, centres[bi], create_graph=False)
    return temporal_loss(dF_dt, E[bi, y, x], durations[bi]), dF_dt, dF_dx, dF_dy


def test_temporal_loss_on_a_known_log_intensity():
    size, t_range = (8, 10), (0.0, 1.0)
    linear = lambda x, y, t: 0.05 * x - 0.02 * y ** 2 + 3.0 * t                # dL/dt = 3 per second
    model = _analytic_model(linear, size, t_range)
    b, E = _bins_of(linear, size, t_range, 32)
    loss, dF_dt, dF_dx, dF_dy = _temporal_at_centres(model, b, E)
    _, y, _ = split_index(torch.arange(E.numel()), size)
    assert torch.allclose(dF_dt, torch.full_like(dF_dt, 3.0))
    assert torch.allclose(dF_dx, torch.full_like(dF_dx, 0.05))
    assert torch.allclose(dF_dy, -0.04 * y.double())
    assert loss.item() < 1e-20                                 # L linear in t: Eq. 5 is exact
    # a constant offset is invisible to the loss; a wrong slope costs (slope error * bin length)^2
    model.siren.L = lambda x, y, t: linear(x, y, t) + 0.7
    assert _temporal_at_centres(model, b, E)[0].item() < 1e-20
    model.siren.L = lambda x, y, t: linear(x, y, t) + 0.5 * t
    assert _temporal_at_centres(model, b, E)[0].item() == pytest.approx((0.5 / 32) ** 2, rel=1e-9)
    # curved in time: the mid-point rule errs by dur^3 / 24 * d3L/dt3 per bin (Eq. 3's Taylor error)
    w = 2 * math.pi * 3
    curved = lambda x, y, t: torch.sin(w * t) + 0 * x
    model.siren.L = curved
    b, E = _bins_of(curved, size, t_range, 32)
    loss = _temporal_at_centres(model, b, E)[0].item()
    bound = ((1 / 32) ** 3 / 24 * w ** 3) ** 2
    assert 0.05 * bound < loss < bound


def test_tikhonov_is_the_mean_squared_gradient():
    gx, gy = torch.tensor([1.0, -2.0, 0.0]), torch.tensor([0.0, 1.0, 3.0])
    assert tikhonov_autograd(gx, gy).item() == pytest.approx((1 + 4 + 0 + 0 + 1 + 9) / 3)


def test_split_index_inverts_row_major_order():
    B, H, W = 3, 4, 5
    b, y, x = split_index(torch.arange(B * H * W), (H, W))
    grid = torch.arange(B * H * W).reshape(B, H, W)
    assert torch.equal(grid[b, y, x], torch.arange(B * H * W))
    assert x.max() == W - 1 and y.max() == H - 1 and b.max() == B - 1


# ---- training on a synthetic scene -------------------------------------------------------

@pytest.fixture(scope="module")
def bar_events():
    scene = make_scene("bar", sensor_size=(16, 20), duration=1.0)
    return scene, simulate_scene(scene, C=0.1)


FAST = dict(C=0.1, n_iters=300, batch_size=1024, lr=1e-3, progress=False, device="cpu", **SMALL)


def test_training_reduces_the_loss_and_recovers_the_bar(bar_events):
    scene, events = bar_events
    model, history = train_coordinate_inr(events, CoordinateConfig(**FAST), (0.0, 1.0))
    loss = np.asarray(history["loss"])
    assert len(loss) == 300 and history["n_coordinates"] == 32 * 16 * 20
    assert np.mean(loss[-20:]) < 0.2 * np.mean(loss[:20])
    assert history["train_time_s"] > 0 and np.all(np.diff(history["time_s"]) > 0)
    # the loss is Eq. 6 + lam * Eq. 9 (both terms logged)
    assert np.allclose(loss, np.add(history["temporal"], 0.05 * np.asarray(history["regularizer"])), rtol=1e-5)
    q = np.linspace(0.1, 0.9, 9)
    truth, L = scene.log_intensity(q), model.render(q)
    centred = lambda a: a - a.mean()          # events fix L only up to a constant
    rmse = np.sqrt(np.mean((centred(L) - centred(truth)) ** 2))
    constant = np.sqrt(np.mean(centred(truth) ** 2))                          # predict the mean everywhere
    shuffled = np.random.default_rng(0).permutation(truth.ravel()).reshape(truth.shape)
    chance = np.sqrt(np.mean((centred(shuffled) - centred(truth)) ** 2))      # right values, wrong places
    assert rmse < 0.25 * constant and rmse < 0.25 * chance, (rmse, constant, chance)


def test_seeded_training_is_deterministic(bar_events):
    _, events = bar_events
    cfg = dict(FAST, n_iters=20)
    m1, h1 = train_coordinate_inr(events, CoordinateConfig(**cfg), (0.0, 1.0))
    m2, h2 = train_coordinate_inr(events, CoordinateConfig(**cfg), (0.0, 1.0))
    m3, h3 = train_coordinate_inr(events, CoordinateConfig(**dict(cfg, seed=1)), (0.0, 1.0))
    assert h1["loss"] == h2["loss"]
    assert np.array_equal(m1.render(0.5), m2.render(0.5))
    assert h1["loss"] != h3["loss"]


def test_reconstruction_anchors_the_offset(bar_events):
    scene, events = bar_events
    q = np.array([0.25, 0.5, 0.75])
    rec = reconstruct_coordinate(events, q, CoordinateConfig(**dict(FAST, n_iters=30)), t_start=0.0, t_end=1.0)
    assert rec.frames.shape == rec.log_intensity.shape == (3, 16, 20)
    assert rec.frames.min() >= 0 and rec.frames.max() <= 1
    # the mean over 16 evenly spaced times of the span sits at logit(0.5 ** (1 / 0.6))
    s = 0.5 ** (1 / 0.6)
    assert rec.at(np.linspace(0, 1, 16)).mean() == pytest.approx(math.log(s / (1 - s)), abs=1e-5)
    assert np.allclose(rec.at(q), rec.log_intensity) and np.allclose(rec.frames_at(q), rec.frames)
    # a constant added to the network changes nothing after anchoring
    with torch.no_grad():
        rec.model.siren.net[-1].bias += 2.5
    L2, offset2 = predict_anchored(rec.model, q)
    assert np.allclose(L2, rec.log_intensity, atol=1e-5) and offset2 == pytest.approx(rec.offset - 2.5, abs=1e-5)
    grid = np.linspace(*rec.model.t_range, 16)    # the offset anchors the mean over the whole range
    assert float((rec.model.render(grid) + offset2).mean()) == pytest.approx(anchor_level(0.6, 0.5), abs=1e-5)


def test_render_matches_forward_and_chunks():
    model = CoordinateINR((5, 7), (0.0, 2.0), **SMALL)
    full = model.render(np.array([0.5, 1.5]))
    assert full.shape == (2, 5, 7) and full.dtype == np.float32
    assert np.allclose(model.render(np.array([0.5, 1.5]), chunk=6), full, atol=1e-6)   # same values, other chunks
    assert model.render(1.5).shape == (5, 7)
    with torch.no_grad():
        v = model(torch.tensor([3]), torch.tensor([4]), torch.tensor([1.5], dtype=torch.float64))
    assert full[1, 4, 3] == pytest.approx(v.item())


def test_bins_hold_the_event_sums(bar_events):
    _, events = bar_events
    bins = bin_events(events, (0.0, 1.0), C=0.1, bin_duration=1 / 32, device="cpu")
    assert bins.frames.shape == (32, 16, 20) and len(bins) == 32 * 16 * 20
    assert bins.frames.sum().item() == pytest.approx(0.1 * events.p.sum(), abs=1e-3)
    assert torch.allclose(bins.durations, torch.full((32,), 1 / 32))
    assert np.allclose(bins.centers.numpy(), (np.arange(32) + 0.5) / 32)      # Eq. 4 evaluates at mid-points


def test_exercise_references_pass_and_hints_fire(capsys):
    assert exercises.check("split_index", split_index)
    assert exercises.check("tikhonov_autograd", tikhonov_autograd)
    assert not exercises.check("split_index", lambda index, sensor_size: (
        index // (sensor_size[0] * sensor_size[1]), index % sensor_size[1], (index // sensor_size[1]) % sensor_size[0]))
    assert "swapped" in capsys.readouterr().out
    assert not exercises.check("tikhonov_autograd", lambda dF_dx, dF_dy: torch.mean(dF_dx.abs() + dF_dy.abs()))
    assert "total variation" in capsys.readouterr().out


# ---- bad input ---------------------------------------------------------------------------

@pytest.mark.parametrize("kwargs, match", [
    (dict(batch_size=0), "batch_size"), (dict(n_iters=0), "n_iters"), (dict(lam=-1.0), "lam"),
    (dict(C=0.0), "C= must be a finite number > 0"), (dict(lr_decay=1.5), "lr_decay"), (dict(display_mean=1.0), "display_mean"),
    (dict(lr_decay_every=0), "lr_decay_every"),
])
def test_bad_config(kwargs, match):
    with pytest.raises(ValueError, match=match):
        CoordinateConfig(**kwargs)


def test_bad_model_inputs():
    with pytest.raises(EventDataError, match="sensor_size"):
        CoordinateINR((0, 5), (0.0, 1.0))
    with pytest.raises(EventDataError, match="reversed"):
        CoordinateINR((4, 5), (1.0, 1.0))
    model = CoordinateINR((4, 5), (0.0, 1.0), **SMALL)
    with pytest.raises(ValueError, match="same length"):
        model(torch.zeros(3), torch.zeros(3), torch.zeros(2))
    with pytest.raises(TypeError, match="torch tensor"):
        model(np.zeros(3), torch.zeros(3), torch.zeros(3))
    with pytest.raises(EventDataError, match="1-D array"):
        model.render(np.zeros((2, 2)))


def test_bad_training_inputs(bar_events):
    _, events = bar_events
    cfg = CoordinateConfig(**dict(FAST, n_iters=1))
    with pytest.raises(TypeError, match="Events"):
        train_coordinate_inr(events.to_array(), cfg)
    with pytest.raises(EventDataError, match="at least 2 events"):
        train_coordinate_inr(Events.empty((16, 20)), cfg)
    with pytest.raises(EventDataError, match="reversed"):
        train_coordinate_inr(events, cfg, (1.0, 0.0))
    with pytest.raises(EventDataError, match="outside"):
        reconstruct_coordinate(events, [0.5, 2.0], cfg, t_start=0.0, t_end=1.0)
    with pytest.raises(EventDataError, match="query_times"):
        reconstruct_coordinate(events, [], cfg)
