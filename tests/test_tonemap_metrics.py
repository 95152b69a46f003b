import numpy as np
import pytest
import torch

from evinr_lite.metrics import mse, ssim
from evinr_lite.tonemap import tonemap_reinhard


def test_reinhard_matches_definition_and_is_stable():
    L = np.linspace(-5, 5, 11)
    I = np.exp(L)
    np.testing.assert_allclose(tonemap_reinhard(L, 0.6), (I / (I + 1)) ** 0.6, rtol=1e-12)
    extreme = tonemap_reinhard(np.array([-1e4, 1e4]))
    assert np.all(np.isfinite(extreme)) and extreme[0] == 0.0 and extreme[1] == 1.0
    t = tonemap_reinhard(torch.tensor(L), 0.6)
    np.testing.assert_allclose(t.numpy(), (I / (I + 1)) ** 0.6, rtol=1e-12)
    with pytest.raises(ValueError, match="gamma"):
        tonemap_reinhard(L, 0.0)


def test_offset_changes_brightness():
    L = np.zeros((4, 4))
    assert tonemap_reinhard(L + 1).mean() > tonemap_reinhard(L).mean()


def test_metrics_on_known_pairs():
    rng = np.random.default_rng(0)
    img = rng.uniform(0, 1, (32, 32))
    assert ssim(img, img) == pytest.approx(1.0)
    assert mse(img, img) == 0.0
    assert mse(np.zeros((4, 4)), np.full((4, 4), 0.5)) == pytest.approx(0.25)
    noisy = np.clip(img + rng.normal(0, 0.2, img.shape), 0, 1)
    assert 0.0 < ssim(noisy, img) < 0.9
    with pytest.raises(ValueError, match="differ in shape"):
        mse(img, img[:-1])


def test_ssim_uses_data_range_one():
    # with data_range 2 (scikit-image's float default) SSIM of a dim pair would be inflated
    from skimage.metrics import structural_similarity
    rng = np.random.default_rng(1)
    a = rng.uniform(0, 0.3, (32, 32))
    b = np.clip(a + rng.normal(0, 0.05, a.shape), 0, 1)
    ref = structural_similarity(a, b, gaussian_weights=True, sigma=1.5, use_sample_covariance=False, data_range=1.0)
    assert ssim(a, b) == pytest.approx(ref)


def test_equalization_and_frame_scores():
    from evinr_lite.metrics import equalize, score_frames
    rng = np.random.default_rng(2)
    img = 0.3 + 0.1 * rng.uniform(0, 1, (32, 40))   # low contrast
    for method in ("global", "clahe"):
        eq = equalize(img, method)
        assert eq.shape == img.shape and eq.std() > 2 * img.std()
    np.testing.assert_allclose(equalize(img, "none"), img)
    with pytest.raises(ValueError, match="equalization must be one of"):
        equalize(img, "hist")
    stack = np.stack([img, img])
    s = score_frames(stack, stack, "clahe")
    assert s["ssim"] == pytest.approx(1.0) and s["mse"] == 0.0 and "clahe" in s["protocol"]
    # CLAHE ignores a global brightness offset that plain SSIM punishes
    brighter = np.clip(stack + 0.2, 0, 1)
    assert score_frames(brighter, stack, "clahe")["ssim"] > score_frames(brighter, stack, "none")["ssim"]


def test_anchor_level_tone_maps_to_the_display_mean():
    from evinr_lite.tonemap import anchor_level, anchor_mean
    for gamma in (0.4, 0.6, 1.0):
        assert tonemap_reinhard(np.array(anchor_level(gamma, 0.5)), gamma) == pytest.approx(0.5)
    L = np.random.default_rng(3).normal(size=(4, 5))
    A = anchor_mean(L, 0.6, 0.3)
    assert A.mean() == pytest.approx(anchor_level(0.6, 0.3)) and np.allclose(A - L, (A - L).flat[0])
    with pytest.raises(ValueError, match="display_mean"):
        anchor_level(0.6, 1.0)
