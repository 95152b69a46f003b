"""What an MSE is made of (evinr_lite.evaluation.level): the level events never give, and the static
large-scale error."""
import numpy as np
import pytest

import evinr_lite as ev
from evinr_lite.core.events import EventDataError
from evinr_lite.evaluation import error_parts, match_level


def textured(seed=0, shape=(4, 64, 96), mean=0.2, spread=0.1):
    rng = np.random.default_rng(seed)
    return np.clip(mean + spread * (rng.random(shape) - 0.5) * 2, 0.0, 1.0)


def test_match_level_recovers_one_gain_over_the_sequence():
    gt = textured()
    matched, gain = match_level(2.25 * gt, gt)
    assert gain == pytest.approx(1 / 2.25, rel=1e-9)
    np.testing.assert_allclose(matched, gt, atol=1e-9)
    assert ev.evaluation.match_level is match_level


def test_the_right_contrast_at_the_wrong_level_loses_mse_but_not_at_the_truths_level():
    gt = textured(mean=0.2, spread=0.17)
    right = 2.25 * gt                               # the truth's relative contrast, shown 2.25x too bright
    flat = np.full_like(gt, right.mean())           # the same level, no structure at all
    r, f = error_parts(right, gt), error_parts(flat, gt)
    assert r["mse"] > f["mse"]                      # MSE charges the gain twice: the flat frame wins
    assert r["mse_at_level"] < 1e-12 < f["mse_at_level"]
    assert f["mse_at_level"] == pytest.approx(gt.var(), rel=1e-6)


def test_a_static_ramp_is_static_and_coarse_and_noise_is_neither():
    gt = textured(seed=1, mean=0.4)
    K, H, W = gt.shape
    ramp = np.linspace(-0.1, 0.1, W)[None, None, :] * np.ones((K, H, 1))
    noise = 0.05 * np.random.default_rng(2).standard_normal(gt.shape)
    pr, pn = error_parts(np.clip(gt + ramp, 0, 1), gt), error_parts(np.clip(gt + noise, 0, 1), gt)
    assert pr["static_coarse"] > 0.8 * pr["mse_at_level"]
    assert pn["static_coarse"] < 0.05 * pn["mse_at_level"]


def test_clipped_highlights_still_reach_the_truths_mean():
    gt = textured(seed=3, mean=0.6, spread=0.3)
    pred = np.clip(0.5 * gt, 0, 1)
    pred[:, :8, :8] = 1.0                           # a saturated patch that no gain can brighten
    matched, gain = match_level(pred, gt)
    assert matched.mean() == pytest.approx(gt.mean(), abs=1e-9) and gain > 1
    assert matched.max() <= 1.0


def test_uint8_truth_is_read_as_a_fraction_of_255():
    gt = textured(seed=4)
    u8 = np.round(gt * 255).astype(np.uint8)
    assert error_parts(gt, u8)["gain"] == pytest.approx(1.0, abs=0.01)


@pytest.mark.parametrize("pred,gt,words", [
    (np.ones((2, 8, 8)), np.ones((3, 8, 8)), "match_frames"),
    (np.ones((8, 8)), np.ones((8, 8)), r"image\[None\]"),
    (np.full((2, 8, 8), np.nan), np.ones((2, 8, 8)), "NaN"),
    (np.zeros((2, 8, 8)), np.ones((2, 8, 8)), "black"),
    (np.array([[["a"]]]), np.ones((1, 1, 1)), "uint8"),
    (np.ones((1, 8, 8)), np.full((1, 8, 8), 128.0), "divide by 255"),
    (np.ones((1, 8, 8)), np.full((1, 8, 8), 128, np.int32), "pass uint8"),
])
def test_bad_frames_say_what_is_wrong(pred, gt, words):
    with pytest.raises(EventDataError, match=words):
        error_parts(pred, gt)


@pytest.mark.parametrize("bad", [0, -1.0, float("nan"), "8"])
def test_coarse_px_must_be_a_positive_number(bad):
    with pytest.raises(EventDataError, match="coarse_px"):
        error_parts(np.ones((1, 8, 8)) * 0.5, np.ones((1, 8, 8)) * 0.5, coarse_px=bad)
