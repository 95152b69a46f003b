"""Notebooks 04-05: exercise references and checks (evinr_lite.teaching.frame_exercises), teaching helpers, figures."""

import matplotlib
import numpy as np
import pytest
import torch

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from evinr_lite.teaching import exercises, frame_exercises as fe  # noqa: E402
from evinr_lite import tonemap_reinhard  # noqa: E402
from evinr_lite.teaching.exercises import ExerciseWarning  # noqa: E402
from evinr_lite.method.losses import temporal_loss_difference, tikhonov, total_variation  # noqa: E402
from evinr_lite.method.models import FrameINR  # noqa: E402
from evinr_lite.viz.frames import plot_histories, show_frames, show_images  # noqa: E402

NAMES = ["sine_layer_derivative", "temporal_loss_boundary", "reinhard_tonemap", "total_variation"]


def _stub(*args, **kwargs):
    raise NotImplementedError


# ---- registration, checks, fallbacks -------------------------------------------------------

def test_exercises_are_registered():
    assert set(NAMES) <= set(exercises.names())


@pytest.mark.parametrize("name", NAMES)
def test_reference_passes_and_stub_falls_back(name, capsys):
    ref = exercises.reference(name)
    assert exercises.check(name, ref)
    assert "✓" in capsys.readouterr().out
    with pytest.warns(ExerciseWarning, match="not finished"):  # a stub raising NotImplementedError
        assert exercises.use(name, _stub) is ref
    assert "not finished" in capsys.readouterr().out


@pytest.mark.parametrize("name", NAMES)
def test_every_hint_is_shown_for_its_mistake(name, capsys):
    ex = exercises.get(name)
    assert ex.hints
    for message, wrong in ex.hints.items():
        assert exercises.check(name, wrong) is False
        assert message in capsys.readouterr().out, f"{name}: hint not shown: {message}"


def test_numpy_answer_to_a_torch_exercise_is_named(capsys):
    def as_numpy(F_boundaries, event_frames):
        return float(fe.temporal_loss_boundary(F_boundaries, event_frames))
    assert not exercises.check("temporal_loss_boundary", as_numpy)
    assert "torch.Tensor" in capsys.readouterr().out


# ---- the references are right ---------------------------------------------------------------

def test_sine_layer_derivative_matches_autograd():
    g = torch.Generator().manual_seed(3)
    h0 = torch.randn(5, 3, generator=g, dtype=torch.float64)
    v = torch.randn(5, 3, generator=g, dtype=torch.float64)       # direction = dh/dt
    w = torch.randn(3, 4, generator=g, dtype=torch.float64) / 3
    b = torch.randn(4, generator=g, dtype=torch.float64)
    h, dh = fe.sine_layer_derivative(h0, v, w, b, 7.0)
    _, jvp = torch.func.jvp(lambda x: torch.sin(7.0 * (x @ w + b)), (h0,), (v,))
    torch.testing.assert_close(h, torch.sin(7.0 * (h0 @ w + b)))
    torch.testing.assert_close(dh, jvp)


def test_sine_layers_chained_reproduce_frame_inr_derivative():
    model = FrameINR((3, 4), [[0.5, 2.5]], hidden_features=16, hidden_layers=2, omega_0=30.0, first_omega_0=10.0, seed=1)
    t = torch.tensor([0.6, 1.3, 2.4], dtype=torch.float64)
    lo, hi = model.windows[0]
    tau = (2 * (t - lo) / (hi - lo) - 1).float()[:, None]
    h, dh = fe.sine_layer_derivative(tau, torch.full_like(tau, float(2 / (hi - lo))), model.weights[0][0],
                                     model.biases[0][0, 0], model.first_omega_0)
    for w, b in zip(model.weights[1:], model.biases[1:]):
        h, dh = fe.sine_layer_derivative(h, dh, w[0], b[0, 0], model.omega_0)
    with torch.no_grad():
        F, dF = model.forward_with_derivative(t[None])
    torch.testing.assert_close((h @ model.head_weight[0] + model.head_bias[0, 0]).reshape(3, 3, 4), F[0])
    torch.testing.assert_close((dh @ model.head_weight[0]).reshape(3, 3, 4), dF[0], rtol=1e-4, atol=1e-5)


def test_references_agree_with_the_package():
    g = torch.Generator().manual_seed(4)
    F = torch.randn(6, 5, 7, generator=g)
    E = torch.randn(5, 5, 7, generator=g)
    torch.testing.assert_close(fe.temporal_loss_boundary(F, E), temporal_loss_difference(F, E))
    torch.testing.assert_close(fe.total_variation(F), total_variation(F))
    L = np.linspace(-8, 5, 50).reshape(5, 10)
    np.testing.assert_allclose(fe.reinhard_tonemap(L, 0.6), tonemap_reinhard(L, 0.6), rtol=1e-12)


def test_tonemap_hint_does_not_warn():
    with np.errstate(all="raise"):
        exercises.check("reinhard_tonemap", fe.reinhard_tonemap, verbose=False)
        for wrong in exercises.get("reinhard_tonemap").hints.values():
            exercises.check("reinhard_tonemap", wrong, verbose=False)


# ---- helpers ---------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def moving_edge():
    """A soft vertical edge sweeping right: [T, H, W] log intensities."""
    T, H, W = 12, 6, 20
    x = np.arange(W)[None, None, :]
    centre = np.linspace(4, 15, T)[:, None, None]
    return np.broadcast_to(np.tanh((x - centre) / 1.5), (T, H, W)).copy() - 1.0


def test_tikhonov_offsets_are_minus_the_temporal_mean_and_optimal(moving_edge):
    L = moving_edge
    g = fe.best_offsets(L, "tikhonov")
    m = L.mean(axis=0)
    np.testing.assert_allclose(g, -(m - m.mean()), atol=1e-12)
    assert abs(g.mean()) < 1e-12
    best = tikhonov(torch.as_tensor(L + g)).item()
    rng = np.random.default_rng(1)
    for _ in range(5):   # any perturbation of the offsets is worse
        assert tikhonov(torch.as_tensor(L + g + 0.05 * rng.normal(size=g.shape))).item() > best
    assert best < tikhonov(torch.as_tensor(L)).item()      # ... and it beats the truth: the ghost


def test_tv_offsets_beat_truth_and_ghost(moving_edge):
    L = moving_edge
    g_tv = fe.best_offsets(L, "tv", n_iters=300)
    tv = lambda g: total_variation(torch.as_tensor(L + g)).item()  # noqa: E731
    assert tv(g_tv) <= tv(0.0) + 1e-9
    assert tv(0.0) < tv(fe.best_offsets(L, "tikhonov"))     # TV rates the truth above the ghost
    assert fe.ghost_strength(L + g_tv, L) < 0.5
    with pytest.raises(ValueError, match="tikhonov"):
        fe.best_offsets(L, "l2")


def test_ghost_strength(moving_edge):
    L = moving_edge
    ghost = L - L.mean(axis=0)
    assert fe.ghost_strength(ghost, L) == pytest.approx(1.0)
    assert fe.ghost_strength(L + 3.0, L) == pytest.approx(0.0, abs=1e-12)
    assert fe.ghost_strength(L - 0.5 * L.mean(axis=0) + 2.0, L) == pytest.approx(0.5)
    r = fe.static_residual(ghost + 1.0, L)
    assert r.shape == L.shape[1:] and abs(r.mean()) < 1e-12


# ---- figures ---------------------------------------------------------------------------------

def test_show_frames_grid_and_errors():
    rows = {"a": np.zeros((3, 4, 5)), "b": np.ones((3, 4, 5))}
    fig = show_frames(rows, times=[0.1, 0.2, 0.3], row_titles={"b": "x"})
    assert len(fig.axes) == 6
    assert fig.axes[0].get_title() == "t = 0.10 s" and fig.axes[3].get_ylabel() == "b\nx"
    again = show_frames(rows, fig=fig)                  # redraws into the same figure
    assert again is fig and len(fig.axes) == 6
    plt.close(fig)
    with pytest.raises(ValueError, match="same Q"):
        show_frames({"a": np.zeros((3, 4, 5)), "b": np.zeros((2, 4, 5))})
    with pytest.raises(ValueError, match="empty"):
        show_frames({})


def test_show_images_symmetric_limits_and_histories():
    fig = show_images({"p": np.array([[0.0, 2.0]]), "n": np.array([[-3.0, 1.0]])}, symmetric=True, colorbar=True)
    im = fig.axes[0].images[0]
    assert im.get_clim() == (-3.0, 3.0)
    plt.close(fig)
    ax = plot_histories({"a": {"loss": [1.0, 0.5]}, "b": [2.0, 1.0, 0.0]})
    assert len(ax.get_lines()) == 2 and ax.get_yscale() == "log"
    plt.close(ax.figure)
