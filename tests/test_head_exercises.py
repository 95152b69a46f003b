"""Notebook 04's closed-form head exercise: the reference is the library's solve, and the check catches
the mistakes it names, on inputs that sit on every stated rule (ridge exactly 0, empty bins, a pixel
that never fired, ties)."""
import numpy as np
import torch

from evinr_lite.method.head_solve import solve_head
from evinr_lite.method.models import FrameINR
from evinr_lite.teaching import exercises, head_exercises


def test_reference_matches_the_library_solve_without_regularizer():
    H, W = 4, 5
    model = FrameINR((H, W), [[0.0, 1.0]], hidden_features=6, hidden_layers=2, first_omega_0=10.0, seed=0)
    edges = np.linspace(0.0, 1.0, 13)
    g = torch.Generator().manual_seed(0)
    E = (torch.randint(-2, 3, (1, 12, H, W), generator=g) * 0.2).float()
    A = head_exercises.bin_feature_changes(model, edges)
    S = A.T @ A
    with torch.no_grad():
        solve_head(model, torch.as_tensor(edges)[None], E, temporal_loss="difference", regularizer="none")
    mine = head_exercises.head_closed_form(A, E[0].reshape(12, -1).double().numpy(), 1e-7 * np.trace(S) / 6)
    lib = model.head_weight[0].detach().double().numpy()
    np.testing.assert_allclose(mine, lib, rtol=1e-3, atol=1e-4 * np.abs(lib).max())


def test_reference_is_the_minimum():
    rng = np.random.default_rng(1)
    A, E, ridge = rng.normal(size=(10, 3)), rng.normal(size=(10, 4)), 0.7
    W = head_exercises.head_closed_form(A, E, ridge)
    loss = lambda W: np.sum((A @ W - E) ** 2) + ridge * np.sum(W ** 2)  # noqa: E731
    for _ in range(5):
        assert loss(W) < loss(W + 1e-3 * rng.normal(size=W.shape))


def test_check_cases_sit_on_every_stated_rule():
    cases = [kw for _, kw in exercises.get("head_closed_form").cases()]
    assert any(kw["ridge"] == 0 for kw in cases)
    assert any(np.any(np.all(kw["E"] == 0, axis=1)) for kw in cases)          # an empty bin
    assert any(np.any(np.all(kw["E"] == 0, axis=0)) for kw in cases)          # a pixel that never fired
    assert any(len(np.unique(kw["A"], axis=0)) < len(kw["A"]) for kw in cases)  # a tie


def _fails_with(capsys, wrong, words):
    capsys.readouterr()
    assert not exercises.check("head_closed_form", wrong)
    out = capsys.readouterr().out
    assert words in out, out


def test_wrong_solutions_fail_with_their_hint(capsys):
    assert exercises.check("head_closed_form", head_exercises.head_closed_form)
    _fails_with(capsys, lambda A, E, ridge: np.linalg.lstsq(A, E, rcond=None)[0], "add ridge times the identity")
    _fails_with(capsys, lambda A, E, ridge: np.linalg.solve(A.T @ A + ridge * len(A) * np.eye(A.shape[1]), A.T @ E),
                "once per bin")
    def drops(A, E, ridge):
        keep = np.any(E != 0, axis=1)
        return head_exercises.head_closed_form(A[keep], E[keep], ridge)
    _fails_with(capsys, drops, "empty bin")
    _fails_with(capsys, lambda A, E, ridge: A.T @ E, "right-hand side")
    # a solution in the wrong orientation, or with the ridge on the wrong side, fails too
    assert not exercises.check("head_closed_form", lambda A, E, ridge: np.linalg.solve(
        A.T @ A + ridge * np.eye(A.shape[1]), A.T @ E).T, verbose=False)
    assert not exercises.check("head_closed_form", lambda A, E, ridge: np.linalg.solve(
        A.T @ A, A.T @ E + ridge), verbose=False)
