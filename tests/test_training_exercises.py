"""Notebook 04's method-carrying exercise: one training step of the frame INR (evinr_lite.teaching.training_exercises)."""
import numpy as np
import pytest
import torch

from evinr_lite.teaching import exercises, training_exercises as te
from evinr_lite.teaching.exercises import ExerciseWarning
from evinr_lite.method.losses import temporal_loss_derivative, tikhonov
from evinr_lite.method.models import FrameINR


def test_reference_passes_and_a_stub_falls_back(capsys):
    assert exercises.check("frame_train_step", te.frame_train_step)
    assert "✓ frame_train_step: matches the reference on 2 inputs" in capsys.readouterr().out

    def stub(*args, **kwargs):
        raise NotImplementedError

    with pytest.warns(ExerciseWarning, match="not finished"):
        assert exercises.use("frame_train_step", stub) is te.frame_train_step


@pytest.mark.parametrize("message", list(exercises.get("frame_train_step").hints))
def test_every_mistake_fails_the_check_and_gets_its_hint(message, capsys):
    wrong = exercises.get("frame_train_step").hints[message]
    assert exercises.check("frame_train_step", wrong) is False
    assert message in capsys.readouterr().out


def test_a_forgotten_zero_grad_is_caught_by_the_parameters_not_the_loss(capsys):
    """The losses of the no-zero_grad version are right; only the parameter update shows the mistake
    (the check's cases carry stale gradients through its deep copy)."""
    wrong = exercises.get("frame_train_step").hints[next(m for m in exercises.get("frame_train_step").hints
                                                          if "zero_grad" in m)]
    assert not exercises.check("frame_train_step", wrong)
    out = capsys.readouterr().out
    assert "parameters after the step" in out and "zero_grad" in out


def test_the_step_is_the_loop_body_of_notebook_04():
    """frame_train_step = the loss of the library's losses and one Adam step, as written in the notebook."""
    model = FrameINR((4, 5), [[0.0, 1.0]], hidden_features=16, hidden_layers=2, seed=3)
    twin = FrameINR((4, 5), [[0.0, 1.0]], hidden_features=16, hidden_layers=2, seed=3)
    opt, opt_twin = torch.optim.Adam(model.parameters(), lr=1e-3), torch.optim.Adam(twin.parameters(), lr=1e-3)
    E = torch.randn(1, 6, 4, 5, generator=torch.Generator().manual_seed(0)) * 0.2
    centers = torch.linspace(0.05, 0.95, 6, dtype=torch.float64)[None]
    durations = torch.full((1, 6), 1 / 6, dtype=torch.float32)
    for _ in range(3):
        loss, temporal, reg = te.frame_train_step(model, opt, E, centers, durations, 0.05)
        F, dF = twin.forward_with_derivative(centers)
        t2 = temporal_loss_derivative(dF, E, durations)
        l2 = t2 + 0.05 * tikhonov(F)
        opt_twin.zero_grad(); l2.backward(); opt_twin.step()
        assert torch.allclose(loss, l2.detach()) and torch.allclose(temporal, t2.detach())
    for p, q in zip(model.parameters(), twin.parameters()):
        assert torch.equal(p, q)
    assert not loss.requires_grad and np.isclose(float(loss), float(temporal) + 0.05 * float(reg), rtol=1e-5)
