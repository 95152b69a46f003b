"""The reconstruct-and-score path: matching by timestamp, scoring, pooling, tables; event enhancement."""
import numpy as np
import pytest
import torch

from evinr_lite import EvINRConfig, make_scene, simulate_scene, simulate_video
from evinr_lite.teaching import exercises
from evinr_lite.evaluation.enhance import (add_background_noise, count_scores, event_counts, model_event_counts, render_event_counts, signed_to_polarity_counts)
from evinr_lite.evaluation.scoring import (evaluate, match_frames, measure_inference_fps, pool, results_table, score_sequence)
from evinr_lite.viz.results import plot_results
from evinr_lite.evaluation.lpips import ALEXNET_FILE, LINEAR_FILE, load_lpips
from evinr_lite.method.tonemap import tonemap_reinhard


@pytest.fixture(autouse=True)
def empty_cache(tmp_path, monkeypatch):
    """No LPIPS weights anywhere: the 'unavailable' path, whatever the machine's cache holds."""
    monkeypatch.setenv("EVINR_DATA", str(tmp_path / "cache"))
    monkeypatch.setattr("evinr_lite.evaluation.scoring._LPIPS_CACHE", {})


# ---- matching ------------------------------------------------------------------------------

def test_match_frames_within_tolerance_each_prediction_once():
    gt = np.array([0.0, 0.1, 0.2, 0.3])
    pred = np.array([0.3004, 0.0, 0.1015, 0.2009, 0.2002])     # unsorted; two candidates for 0.2
    p, g = match_frames(pred, gt, tol=1e-3)
    np.testing.assert_array_equal(g, [0, 2, 3])                # 0.1 has none within 1 ms
    np.testing.assert_array_equal(p, [1, 4, 0])                # the closer of 0.2009 / 0.2002
    p, g = match_frames(pred, gt, tol=2e-3)
    np.testing.assert_array_equal(g, [0, 1, 2, 3])
    # one prediction between two GT frames serves only the closer one
    p, g = match_frames([0.1003], [0.1, 0.1008], tol=1e-3)
    np.testing.assert_array_equal(g, [0])
    np.testing.assert_array_equal(p, [0])
    p, g = match_frames([5.0], gt)
    assert p.size == 0 and g.size == 0
    with pytest.raises(ValueError, match="tol"):
        match_frames(pred, gt, tol=-1)


# ---- scoring and pooling -------------------------------------------------------------------

def smooth_images(n=3, H=32, W=40, seed=0):
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:H, 0:W]
    return np.stack([0.5 + 0.35 * np.sin(x / (4 + k) + rng.uniform(0, 3)) * np.cos(y / 6) for k in range(n)])


def test_score_sequence_matches_uint8_ground_truth_and_reports_missing_lpips():
    gt = np.round(smooth_images() * 255).astype(np.uint8)
    t = np.array([0.1, 0.2, 0.3])
    perfect = gt / 255.0
    r = score_sequence(perfect[::-1], t[::-1] + 2e-4, gt, t, "none")
    assert r["mse"] == pytest.approx(0.0, abs=1e-15) and r["ssim"] == pytest.approx(1.0)
    assert r["n_frames"] == 3 and r["equalization"] == "none" and "sigma 1.5" in r["protocol"]
    assert r["lpips"] is None and "python -m data_fetch get lpips all" in r["lpips_note"]
    noisy = np.clip(perfect + np.random.default_rng(1).normal(0, 0.1, perfect.shape), 0, 1)
    r2 = score_sequence(noisy[:2], t[:2], gt, t, "clahe", lpips_model=False)
    assert r2["n_frames"] == 2 and r2["n_gt_frames"] == 3 and r2["ssim"] < 1 and r2["mse"] > 0
    np.testing.assert_allclose(r2["per_frame"]["mse"].mean(), r2["mse"])
    assert "not requested" in r2["lpips_note"] and "CLAHE" in r2["protocol"]
    with pytest.raises(ValueError, match="no ground-truth frame has a prediction"):
        score_sequence(perfect, t + 0.05, gt, t)


def test_score_sequence_with_an_lpips_model(tmp_path):
    g = torch.Generator().manual_seed(0)
    shapes = {"features.0.weight": (64, 3, 11, 11), "features.3.weight": (192, 64, 5, 5),
              "features.6.weight": (384, 192, 3, 3), "features.8.weight": (256, 384, 3, 3),
              "features.10.weight": (256, 256, 3, 3)}
    alex = {k: torch.randn(s, generator=g) * 0.1 for k, s in shapes.items()}
    alex.update({k.replace("weight", "bias"): torch.zeros(s[0]) for k, s in shapes.items()})
    lin = {f"lin{k}.model.1.weight": torch.rand(1, c, 1, 1, generator=g) for k, c in enumerate((64, 192, 384, 256, 256))}
    torch.save(alex, tmp_path / ALEXNET_FILE)
    torch.save(lin, tmp_path / LINEAR_FILE)
    model = load_lpips(tmp_path, device="cpu")
    imgs = smooth_images()
    t = np.arange(3.0)
    same = score_sequence(imgs, t, imgs, t, "none", lpips_model=model)
    assert same["lpips"] == pytest.approx(0.0, abs=1e-6) and same["lpips_note"] == ""
    other = score_sequence(imgs[::-1], t, imgs, t, "none", lpips_model=model)
    assert other["lpips"] > 0


def test_pool_weights_sequences_by_frame_count():
    a = {"mse": 0.1, "ssim": 0.5, "lpips": 0.2, "n_frames": 1, "protocol": "P", "equalization": "none"}
    b = {"mse": 0.3, "ssim": 0.9, "lpips": 0.4, "n_frames": 3, "protocol": "P", "equalization": "none"}
    p = pool([a, b])
    assert p["mse"] == pytest.approx((0.1 + 3 * 0.3) / 4) and p["ssim"] == pytest.approx((0.5 + 2.7) / 4)
    assert p["lpips"] == pytest.approx((0.2 + 1.2) / 4) and p["n_frames"] == 4 and p["n_sequences"] == 2
    assert p["mse"] != pytest.approx((0.1 + 0.3) / 2)                 # not the mean of sequence means
    no_lpips = pool([a, {**b, "lpips": None, "lpips_note": "weights absent"}])
    assert no_lpips["lpips"] is None and no_lpips["lpips_note"] == "weights absent"
    with pytest.raises(ValueError, match="different protocols"):
        pool([a, {**b, "protocol": "Q"}])


# ---- the whole path on a tiny synthetic scene ----------------------------------------------

def test_evaluate_scores_evinr_and_baselines_through_one_path():
    scene = make_scene("camera", sensor_size=(32, 40), duration=0.4)
    events = simulate_scene(scene, 0.0, 0.4, C=0.2, seed=0)
    gt_t = np.array([0.1, 0.2, 0.3])
    gt = tonemap_reinhard(scene.log_intensity(gt_t))
    cfg = EvINRConfig.v0_1(C=0.2, n_iters=6, hidden_features=16, c2f_iters=(2, 4), progress=False)
    rows = evaluate(events, gt, gt_t, methods=("evinr", "integration", "leaky", "hf"), config=cfg,
                    baseline_params={"leaky": {"leak_hz": 1.0}, "hf": {"cutoff_hz": 2.0}})
    assert [(r["method"], r["equalization"]) for r in rows] == [
        (m, e) for m in ("evinr", "integration", "leaky", "hf") for e in ("none", "clahe")]
    for r in rows:
        assert {"mse", "ssim", "lpips", "lpips_note", "n_frames", "protocol", "train_time_s",
                "inference_time_s", "params"} <= set(r)
        assert r["n_frames"] == 3 and 0 <= r["mse"] < 1 and -1 < r["ssim"] <= 1
        assert r["lpips"] is None and "data_fetch get lpips all" in r["lpips_note"]
    assert rows[0]["train_time_s"] > 0 and rows[2]["train_time_s"] == 0.0
    assert rows[-1]["params"]["cutoff_hz"] == 2.0 and rows[0]["params"]["config"]["n_iters"] == 6
    table = results_table(rows)
    assert table.count("\n| ") == len(rows) and "n/a" in table and "Protocol (clahe)" in table
    assert "clipLimit=2.0" in table and "python -m data_fetch get lpips all" in table
    fig = plot_results(rows)
    assert len(fig.axes) == 2                                           # MSE and SSIM; no LPIPS values
    import matplotlib.pyplot as plt
    plt.close(fig)                                                      # no figure left for the next test file
    kept = evaluate(events, gt, gt_t, methods=("hf",), equalizations=("none",), keep_frames=True, lpips_model=False)
    assert kept[0]["frames"].shape == (3, 32, 40) and kept[0]["reconstruction"].method == "hf"
    with pytest.raises(ValueError, match="unknown method"):
        evaluate(events, gt, gt_t, methods=("e2vid",))


def test_measure_inference_fps_reports_its_setting():
    from evinr_lite.method.models import FrameINR
    model = FrameINR((6, 8), [[0.0, 1.0]], hidden_features=16, hidden_layers=1)
    r = measure_inference_fps(model, n_frames=8, batch_size=4, repeats=2)
    assert r["fps"] > 0 and len(r["all_seconds"]) == 2 and r["sensor_size"] == (6, 8) and r["device"] == "cpu"


# ---- event enhancement ---------------------------------------------------------------------

def test_rendered_counts_equal_the_simulator_on_the_same_samples():
    rng = np.random.default_rng(0)
    t = np.linspace(0.0, 1.0, 9)
    L = np.cumsum(rng.normal(0, 0.3, (9, 4, 5)), axis=0)
    ev = simulate_video(L, t, C=0.2)
    counts = event_counts(ev, t)
    np.testing.assert_array_equal(signed_to_polarity_counts(render_event_counts(L, 0.2)), counts)
    assert counts.sum() == len(ev)
    assert exercises.check("render_event_counts", render_event_counts, verbose=False)
    no_carry = lambda L_boundaries, C: np.trunc(np.diff(L_boundaries, axis=0) / C).astype(np.int64)
    assert not exercises.check("render_event_counts", no_carry, verbose=False)


def test_count_scores_and_noise():
    scene = make_scene("bar", sensor_size=(16, 20), duration=0.5)
    clean = simulate_scene(scene, 0.0, 0.5, C=0.2, seed=0)
    noisy = add_background_noise(clean, rate_hz=4.0, seed=1, t_start=0.0, t_end=0.5)
    again = add_background_noise(clean, rate_hz=4.0, seed=1, t_start=0.0, t_end=0.5)
    np.testing.assert_array_equal(noisy.t, again.t)
    n_noise = len(noisy) - len(clean)
    expected = 4.0 * 0.5 * 16 * 20
    assert abs(n_noise - expected) < 5 * np.sqrt(expected)
    b = np.linspace(0.0, 0.5, 17)
    c = event_counts(clean, b)
    perfect = count_scores(c, c, C=0.2)
    assert perfect["precision"] == perfect["recall"] == perfect["f1"] == 1.0 and perfect["frame_rmse"] == 0.0
    s = count_scores(event_counts(noisy, b), c, C=0.2)
    assert s["recall"] == 1.0 and s["precision"] == pytest.approx(len(clean) / len(noisy))
    assert s["frame_rmse"] > 0 and s["n_events"] == len(noisy)

    class Oracle:                       # a perfect model: the scene's own log intensity
        def at(self, times):
            return scene.log_intensity(times)

    rendered = model_event_counts(Oracle(), b, 0.2)
    assert count_scores(rendered, c, 0.2)["f1"] > 0.9
