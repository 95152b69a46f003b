"""Notebook 06's exercises and helpers (evinr_lite.teaching.accel_exercises): references agree with the solver,
the checks recognise the common mistakes, and batched and sequential training give the same networks."""
import warnings

import numpy as np
import pytest
import torch

from evinr_lite.teaching import accel_exercises as accel
from evinr_lite.teaching import exercises
from evinr_lite import make_scene, simulate_scene
from evinr_lite.method.binning import bisect_boundaries
from evinr_lite.core.events import EventDataError, Events
from evinr_lite.teaching.exercises import ExerciseWarning
from evinr_lite.method.models import FrameINR
from evinr_lite.method.solver import EvINRConfig, blend_weights, reconstruct, split_windows

TINY = dict(hidden_features=16, hidden_layers=1, progress=False, lr=3e-4)


def _events(t):
    t = np.asarray(t, dtype=np.float64)
    return Events(t, np.zeros(len(t), int), np.zeros(len(t), int), np.ones(len(t), int), (1, 1))


# ---- exercise 1: bisection ------------------------------------------------------------------

@pytest.mark.parametrize("seed", range(6))
def test_bisect_reference_matches_the_solver(seed):
    rng = np.random.default_rng(seed)
    t = np.sort(np.concatenate([rng.uniform(0, 1, rng.integers(0, 60)), rng.uniform(0.2, 0.3, 20)]))
    b = np.concatenate([[0.0], np.sort(rng.uniform(0.05, 0.95, rng.integers(1, 8))), [1.0]])
    t = np.concatenate([[0.0], t, [b[1]]]) if seed % 2 else t       # events on edges, too
    t = np.sort(t)
    np.testing.assert_array_equal(accel.bisect_equal_count(t, b), bisect_boundaries(_events(t), b))


def test_bisect_halves_hold_equal_counts_and_fall_back_to_midpoints():
    t = np.array([0.1, 0.12, 0.14, 0.16, 0.9, 1.4, 1.45])
    out = accel.bisect_equal_count(t, [0.0, 1.0, 2.0, 3.0])
    np.testing.assert_allclose(out, [0.0, 0.13, 1.0, 1.425, 2.0, 2.5, 3.0])   # bin 3 is empty: time mid-point
    ties = accel.bisect_equal_count([0.5, 0.5, 0.5, 0.5], [0.0, 1.0])          # the cut cannot split equal times
    assert 0 < ties[1] < 1
    counts = np.histogram(t[t <= 1.0], out[:3])[0]
    assert counts.tolist() == [2, 3]                    # 5 events: n // 2 before the cut, the rest after


def test_bisect_exercise_passes_the_reference_and_names_the_mistakes(capsys):
    assert exercises.check("bisect_equal_count", accel.bisect_equal_count)
    ex = exercises.get("bisect_equal_count")
    assert len(ex.hints) == 13         # mid-points, mean, event n//2, the boundary rule [b_i, b_{i+1}), t == 0 for b_0,
                                       # a cut on the first edge (lo <= median: tools/mutate_exercises.py found it),
                                       # np.median of an odd count, the cuts without the edges (round 4), a sparse
                                       # bin cut at its first edge, bins closed at both ends (round 5), the edges
                                       # and the cuts concatenated, not interleaved (round 6), the last bin open
                                       # at its end, t < b_B (round 7), round(n / 2) for n // 2 (round 10)
    for message, wrong in ex.hints.items():
        capsys.readouterr()
        assert not exercises.check("bisect_equal_count", wrong)
        assert message in capsys.readouterr().out


# ---- exercise 2: cross-fade -----------------------------------------------------------------

@pytest.mark.parametrize("span,tau,overlap", [(3.0, 1.2, 0.3), (6.0, 1.25, 0.25), (2.0, 0.6, 0.1), (1.0, 5.0, 0.5)])
def test_crossfade_reference_matches_the_solver(span, tau, overlap):
    w = split_windows(0.0, span, tau, overlap)
    t = np.sort(np.concatenate([np.linspace(0, span, 301), w.ravel()]))
    ours = accel.crossfade_weights(w, t)
    np.testing.assert_allclose(ours, blend_weights(w, t), atol=1e-5)
    np.testing.assert_allclose(ours.sum(axis=0), 1.0)
    for k in range(1, len(w)):                                   # linear ramps over each overlap
        inside = (t > w[k, 0]) & (t < w[k - 1, 1])
        np.testing.assert_allclose(ours[k, inside], (t[inside] - w[k, 0]) / overlap, atol=1e-12)


def test_crossfade_exercise_passes_the_reference_and_names_the_mistakes(capsys):
    assert exercises.check("crossfade_weights", accel.crossfade_weights)
    for message, wrong in exercises.get("crossfade_weights").hints.items():
        capsys.readouterr()
        assert not exercises.check("crossfade_weights", wrong)
        assert message in capsys.readouterr().out


@pytest.mark.parametrize("name", ["bisect_equal_count", "crossfade_weights"])
def test_unfinished_exercise_falls_back_to_the_reference(name):
    def stub(*args, **kwargs):
        raise NotImplementedError

    with pytest.warns(ExerciseWarning, match=name):
        assert exercises.use(name, stub, verbose=False) is exercises.reference(name)


# ---- the varying-speed scene ------------------------------------------------------------------

def test_varying_speed_scene_is_the_base_scene_at_warped_times():
    base = make_scene("camera", sensor_size=(8, 10), duration=2.0)
    scene = accel.VaryingSpeedScene(base, depth=0.8, period=2.0)
    t = np.array([0.0, 0.3, 1.0, 1.7])
    np.testing.assert_allclose(scene.log_intensity(t), base.log_intensity(scene.warp(t)))
    h = 1e-6
    np.testing.assert_allclose(scene.speed(t), (scene.warp(t + h) - scene.warp(t - h)) / (2 * h), rtol=1e-6)
    assert scene.speed(0.0) == pytest.approx(1.8) and scene.speed(1.0) == pytest.approx(0.2)
    assert scene.max_speed == pytest.approx(1.8 * base.max_speed)
    with pytest.raises(EventDataError, match="depth"):
        accel.VaryingSpeedScene(base, depth=1.0)


# ---- seams ------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def ensemble():
    scene = accel.VaryingSpeedScene(make_scene("camera", sensor_size=(12, 16), duration=2.0))
    events = simulate_scene(scene, 0.0, 2.0, C=0.2, seed=0)
    cfg = EvINRConfig.v0_1(C=0.2, n_iters=6, c2f_iters=(2, 4), tau=0.8, overlap=0.2, **TINY)
    return reconstruct(events, [0.5, 1.5], cfg, t_start=0.0, t_end=2.0)


def test_ensemble_predictions_cover_the_four_mixes(ensemble):
    rec = ensemble
    assert len(rec.windows) == 3
    t = np.linspace(0.0, 2.0, 41)
    np.testing.assert_allclose(accel.ensemble_predictions(rec, t), rec.at(t), atol=1e-6)
    hard = accel.ensemble_predictions(rec, t, crossfade=False)
    raw_hard = accel.ensemble_predictions(rec, t, align=False, crossfade=False)
    outside = ~accel.overlap_mask(rec.windows, t)
    np.testing.assert_allclose(hard[outside], rec.at(t)[outside], atol=1e-6)   # only the overlaps differ
    # the raw networks differ from the aligned ones by exactly the alignment offsets
    centres = 0.5 * (rec.windows[1:, 0] + rec.windows[:-1, 1])
    k = np.searchsorted(centres, t)
    np.testing.assert_allclose(hard - raw_hard, rec.offsets[k] - rec.offsets[0], atol=1e-5)
    change = accel.frame_change(hard, t)
    assert change.shape == (40,) and np.all(change >= 0)


def test_overlap_mask():
    w = np.array([[0.0, 1.2], [1.0, 2.2], [2.0, 3.0]])
    np.testing.assert_array_equal(accel.overlap_mask(w, [0.5, 1.1, 1.5, 2.1, 2.9]), [False, True, False, True, False])


# ---- batched versus sequential ----------------------------------------------------------------

def test_single_copies_hold_the_batched_networks():
    windows = np.array([[0.0, 1.0], [0.8, 1.8], [1.6, 2.6]])
    model = FrameINR((5, 6), windows, 16, 2, 30.0, 10.0, seed=3)
    singles = accel.single_copies(model)
    t = torch.as_tensor(np.linspace(windows[:, 0], windows[:, 1], 7).T)
    with torch.no_grad():
        F = model(t)
        for k, m in enumerate(singles):
            assert m.n_models == 1
            np.testing.assert_allclose(m(t[k:k + 1])[0].numpy(), F[k].numpy(), atol=1e-6)


def test_per_network_loss_gives_each_network_its_own_gradient():
    scene = make_scene("camera", sensor_size=(6, 8), duration=1.0)
    events = simulate_scene(scene, 0.0, 1.0, C=0.2, seed=0)
    windows = split_windows(0.0, 1.0, 0.6, 0.2)
    bins = accel.window_bins(events, windows, 1 / 32, 0.2, "cpu")
    model = FrameINR((6, 8), windows, 16, 1, 30.0, 10.0, seed=0)
    singles = accel.single_copies(model)
    accel.per_network_loss(model, bins).sum().backward()
    for k, m in enumerate(singles):
        accel.per_network_loss(m, {n: v[k:k + 1] for n, v in bins.items()}).sum().backward()
        np.testing.assert_allclose(m.head_weight.grad[0].numpy(), model.head_weight.grad[k].numpy(),
                                   rtol=1e-4, atol=1e-7)


def test_batched_and_sequential_training_agree():
    scene = make_scene("camera", sensor_size=(8, 10), duration=1.5)
    events = simulate_scene(scene, 0.0, 1.5, C=0.2, seed=0)
    windows = split_windows(0.0, 1.5, 0.6, 0.1)
    r = accel.batched_vs_sequential(events, windows, hidden_features=16, hidden_layers=1, n_iters=5, repeats=1,
                                    device="cpu")
    assert r["n_models"] == len(windows) == 3
    assert r["batched_s"] > 0 and r["sequential_s"] > 0
    assert r["ratio"] == pytest.approx(r["sequential_s"] / r["batched_s"])
    assert r["max_abs_diff"] < 1e-4 * max(r["pred_scale"], 1.0)


def test_benchmark_script_runs_small():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "ensemble_batching.py"
    spec = importlib.util.spec_from_file_location("ensemble_batching", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    lines = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = module.run((1, 3), size=(6, 8), duration=1.0, hidden=8, layers=1, iters=2, repeats=1,
                            device="cpu", log=lines.append)
    assert [r["n_models"] for r in result["rows"]] == [1, 3] and result["same_predictions"]
    assert "seq./batched" in lines[1] and len(lines) == 5


# ---- ensemble alignment (chain_offsets) -------------------------------------------------------------

def test_chain_offsets_is_the_solvers_alignment():
    """The exercise's reference, fed by overlap_predictions, equals method.ensemble.alignment_offsets."""
    from evinr_lite.method.models import FrameINR
    from evinr_lite.method.solver import split_windows

    windows = split_windows(0.0, 3.0, 1.2, 0.3)
    model = FrameINR((3, 4), windows, hidden_features=8, hidden_layers=1, first_omega_0=10.0, seed=0)
    mine = accel.chain_offsets(*accel.overlap_predictions(model, windows))
    np.testing.assert_allclose(mine, accel.alignment_offsets(model, windows), atol=1e-5)
    one = accel.chain_offsets(*accel.overlap_predictions(model, windows[:1]))
    assert one.shape == (1, 3, 4) and not one.any()


def test_chain_offsets_check_catches_the_named_mistakes(capsys):
    assert exercises.check("chain_offsets", accel.chain_offsets)
    cases = [kw for _, kw in exercises.get("chain_offsets").cases()]
    assert any(kw["prev"].shape[0] == 0 for kw in cases)      # a single network: the boundary K = 0
    assert any(kw["prev"].shape[1] == 1 for kw in cases)      # one sample per overlap
    for wrong, words in ((accel._not_chained, "np.cumsum"), (accel._next_minus_prev, "not F_k - F_{k-1}"),
                         (accel._no_leading_zero, "first one zero")):
        capsys.readouterr()
        assert not exercises.check("chain_offsets", wrong)
        assert words in capsys.readouterr().out
    # one sample's difference, or the median over the samples, instead of the mean fails too
    first = lambda prev, nxt: accel.chain_offsets(np.asarray(prev)[:, :1], np.asarray(nxt)[:, :1])  # noqa: E731
    median = lambda prev, nxt: np.concatenate([np.zeros((1,) + np.shape(prev)[2:]),  # noqa: E731
                                               np.cumsum(np.median(np.subtract(prev, nxt), axis=1), axis=0)])
    assert not exercises.check("chain_offsets", first, verbose=False)
    assert not exercises.check("chain_offsets", median, verbose=False)
