"""The zoo benchmark's bookkeeping (benchmarks/quality_zoo.py): level error per quarter, swept baselines,
independent windows, the per-scene summary and the targets."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks import quality_zoo as qz  # noqa: E402
from evinr_lite.sim import zoo  # noqa: E402


def test_level_error_is_per_quarter():
    times = np.array([0.5, 1.5, 2.5, 3.5, 3.9])
    gt = np.full((5, 4, 4), 0.5, np.float32)
    pred = gt + np.array([0.1, 0.0, -0.1, 0.2, 0.4], np.float32)[:, None, None]
    lv = qz.level_error(pred, gt, times, 4.0)
    np.testing.assert_allclose(lv, [0.1, 0.0, -0.1, 0.3], atol=1e-6)
    assert qz.level_error(pred[:1], gt[:1], times[:1], 4.0)[1:] == [None, None, None]


@pytest.fixture(scope="module")
def small():
    z = zoo.ZooScene("t", "a small test scene for the zoo's bookkeeping", zoo.get("camera_translate").build,
                     size=(30, 40), duration=2.0, C_pos=0.24, C_neg=0.16, noise_hz=0.5, hot_pixels=3)
    return z, zoo.simulate(z)


def test_the_swept_baseline_is_the_best_of_its_sweep(small):
    z, (scene, events, times, gt) = small
    frames, sweep = qz.sweep_baseline("hf_best", events, times, 0.2, gt)
    scores = {k: v["ssim_clahe"] for k, v in sweep.items() if k != "best"}
    assert len(scores) == len(qz.SWEEP["hf_best"][2])
    best = max(scores, key=scores.get)
    assert sweep["best"] == f"cutoff_hz={best}"
    assert qz.score(frames, times, gt, times)["ssim_clahe"] == pytest.approx(scores[best])


def test_windows_answer_every_time_and_summary_has_the_targets(small):
    z, (scene, events, times, gt) = small
    f = qz.windowed(events, times, 0.2, {}, window=1.0)
    assert f.shape == gt.shape and np.all((f >= 0) & (f <= 1))
    rows = {}
    for m in ("kit", "integration_offset", "hf_best", "leaky_best", "oracle_linear", "kit_windows"):
        fr, s = qz.run_method(m, events, times, 0.2, {}, scene.log_intensity(times[0]), gt)
        rows[m] = {**qz.score(fr, times, gt, times), **qz.level_scores(fr, times, gt, 2.0), "time_s": s,
                   "level_error": qz.level_error(fr, gt, times, 2.0)}
    s = qz.summarise(rows)
    assert s["best_baseline"] in qz.BEST_OF
    best_mse = min(rows[m]["mse_none"] for m in qz.BEST_OF)
    assert s["kit_mse_over_best_baseline_mse"] == pytest.approx(rows["kit"]["mse_none"] / best_mse)
    assert "whole_minus_windows_clahe" in s and "kit_level_error_max_abs" in s
    # what each MSE is made of: the truth shown at half its level is exact once the level is the truth's
    half = {**qz.score(0.5 * np.asarray(gt), times, gt, times), **qz.level_scores(0.5 * np.asarray(gt), times, gt)}
    assert half["level_gain"] == pytest.approx(2.0, rel=1e-6) and half["mse_at_level"] < 1e-12 < half["mse_none"]
    assert half["ssim_none_at_level"] == pytest.approx(1.0) and half["ssim_clahe_at_level"] == pytest.approx(1.0)
    best_l = min(rows[m]["mse_at_level"] for m in qz.BEST_OF)
    assert s["kit_mse_at_level_over_best_baseline"] == pytest.approx(rows["kit"]["mse_at_level"] / best_l)
    results = {"t": {"rows": rows, "summary": s, "noise_free": False, "long": True}}
    names = [r["name"] for r in qz.target_rows(results)]
    assert any("level error" in n for n in names) and any("independent 2 s windows" in n for n in names)
    assert any("at the truth's level" in n and "MSE" in n for n in names)
    assert any("per quarter at the truth's level" in n for n in names)
    # at the truth's level the level error is drift alone: its mean over the quarters is about 0
    assert abs(np.mean(rows["kit"]["level_error_at_level"])) < 0.02
    assert "What each MSE is made of" in qz.markdown(results, list(rows))


def test_fresh_is_one_set_among_the_others(capsys, tmp_path):
    """--fresh SEED is another set of scenes: refused beside --heldout, and a run of one quick fresh scene
    writes the *_fresh outputs with its seed."""
    with pytest.raises(SystemExit):
        qz.zoo_main(["--fresh", "3", "--heldout"])
    assert "give one of them" in capsys.readouterr().err
    out = tmp_path / "f.json"
    results = qz.zoo_main(["--fresh", "3", "--n-fresh", "1", "--quick", "--methods", "kit,integration_offset",
                           "--json", str(out), "--md", str(tmp_path / "f.md"), "--figure", ""])
    assert list(results) == [zoo.fresh(3, 1)[0].name]
    import json
    saved = json.loads(out.read_text())
    assert saved["fresh_seed"] == 3 and saved["scenes"][zoo.fresh(3, 1)[0].name]["rows"]["kit"]["ssim_clahe"] > 0
