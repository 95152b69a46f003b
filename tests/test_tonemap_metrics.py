import numpy as np
import pytest
import torch

from evinr_lite.evaluation.metrics import mse, ssim
from evinr_lite.method.tonemap import anchor_level, anchor_mean, tonemap_reinhard


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
    from evinr_lite.evaluation.metrics import equalize, score_frames
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
    from evinr_lite.method.tonemap import anchor_level, anchor_mean
    for gamma in (0.4, 0.6, 1.0):
        assert tonemap_reinhard(np.array(anchor_level(gamma, 0.5)), gamma) == pytest.approx(0.5)
    L = np.random.default_rng(3).normal(size=(4, 5))
    A = anchor_mean(L, 0.6, 0.3)
    assert A.mean() == pytest.approx(anchor_level(0.6, 0.3)) and np.allclose(A - L, (A - L).flat[0])
    with pytest.raises(ValueError, match="display_mean"):
        anchor_level(0.6, 1.0)


# ---- the protocol, checked against independent computations ----------------------------------

def reference_ssim(a, b, sigma=1.5, truncate=3.5, K1=0.01, K2=0.03, L=1.0):
    """SSIM after Wang et al. (2004), written out with scipy: gaussian-weighted local means,
    population (co)variances, the map averaged over pixels at least radius px from the border."""
    from scipy.ndimage import gaussian_filter

    def blur(img):
        return gaussian_filter(img, sigma, truncate=truncate)

    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    mu_a, mu_b = blur(a), blur(b)
    var_a = blur(a * a) - mu_a ** 2
    var_b = blur(b * b) - mu_b ** 2
    cov = blur(a * b) - mu_a * mu_b
    C1, C2 = (K1 * L) ** 2, (K2 * L) ** 2
    s = ((2 * mu_a * mu_b + C1) * (2 * cov + C2)) / ((mu_a ** 2 + mu_b ** 2 + C1) * (var_a + var_b + C2))
    r = int(truncate * sigma + 0.5)
    return float(s[r:-r, r:-r].mean())


@pytest.mark.parametrize("seed, noise", [(0, 0.05), (1, 0.2), (2, 0.5)])
def test_ssim_and_mse_match_an_independent_computation_on_noisy_pairs(seed, noise):
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:48, 0:64]
    img = 0.5 + 0.4 * np.sin(x / 5.0) * np.cos(y / 7.0)              # structure, values in [0.1, 0.9]
    noisy = np.clip(img + rng.normal(0, noise, img.shape), 0, 1)
    assert ssim(noisy, img) == pytest.approx(reference_ssim(noisy, img), abs=1e-10)
    assert ssim(img, noisy) == pytest.approx(reference_ssim(img, noisy), abs=1e-10)
    assert ssim(noisy, img) < 1.0
    assert mse(noisy, img) == pytest.approx(((noisy - img) ** 2).sum() / img.size, rel=1e-12)
    # the prediction (first argument) is clipped to [0, 1] before scoring (an overshoot beyond [-1, 2], the 0..255
    # scale, is refused as score_pairs refuses it: tests/test_robustness_round10.py)
    assert mse(img + 0.5, img) == pytest.approx(np.mean((np.minimum(img + 0.5, 1.0) - img) ** 2))


def test_ssim_of_an_image_with_itself_is_one_for_any_content():
    rng = np.random.default_rng(4)
    for img in (rng.uniform(0, 1, (20, 30)), np.full((16, 16), 0.3), np.zeros((12, 40))):
        assert ssim(img, img) == pytest.approx(1.0, abs=1e-12)
    with pytest.raises(ValueError, match="at least 11"):
        ssim(np.zeros((8, 8)), np.zeros((8, 8)))


def test_clahe_and_global_equal_opencv_on_uint8():
    import cv2

    from evinr_lite.evaluation.metrics import equalize
    from evinr_lite.core.frames import to_uint8
    rng = np.random.default_rng(5)
    img = np.clip(0.35 + 0.1 * rng.standard_normal((60, 80)), 0, 1)
    u = np.round(img * 255).astype(np.uint8)
    np.testing.assert_array_equal(to_uint8(img), u)
    clahe = cv2.createCLAHE(clipLimit=2.0, tileGridSize=(8, 8)).apply(u)
    np.testing.assert_array_equal(equalize(img, "clahe"), clahe / 255.0)
    np.testing.assert_array_equal(equalize(img, "global"), cv2.equalizeHist(u) / 255.0)
    np.testing.assert_array_equal(equalize(u, "clahe"), clahe / 255.0)      # uint8 input directly
    np.testing.assert_array_equal(equalize(u, "none"), u / 255.0)           # uint8 scaled, not clipped
    with pytest.raises(ValueError, match=r"\[H, W\]"):
        equalize(np.zeros((2, 8, 8)), "clahe")


def test_protocol_text_names_every_parameter():
    from evinr_lite.evaluation.metrics import PROTOCOLS, protocol_description, score_frames
    for eq in ("none", "global", "clahe"):
        text = protocol_description(eq)
        assert text == PROTOCOLS[eq]
        for part in ("sigma 1.5", "data_range 1.0", "K1 0.01", "v0.1", "[-1, 1]"):
            assert part in text
    assert "clipLimit=2.0" in protocol_description("clahe") and "(8, 8)" in protocol_description("clahe")
    assert "equalizeHist" in protocol_description("global")
    stack = np.random.default_rng(6).uniform(0, 1, (2, 16, 16))
    assert protocol_description("clahe") in score_frames(stack, stack, "clahe")["protocol"]
    with pytest.raises(ValueError, match="equalization must be one of"):
        protocol_description("local")


def test_anchor_mean_with_reference():
    rng = np.random.default_rng(0)
    L = rng.normal(-1.0, 0.7, (4, 6, 8))
    for gamma, mean in ((0.6, 0.5), (1.0, 0.3), (2.2, 0.7)):
        A = anchor_mean(L, gamma, mean)
        assert tonemap_reinhard(A.mean(), gamma) == pytest.approx(mean, rel=1e-12)
        np.testing.assert_allclose(np.diff(A, axis=0), np.diff(L, axis=0), atol=1e-12)   # one constant only
    ref = L[:2]
    A = anchor_mean(L[3], 0.6, 0.5, reference=ref)
    assert tonemap_reinhard(np.mean(ref + (A - L[3]).mean()), 0.6) == pytest.approx(0.5)
    with pytest.raises(ValueError, match="display_mean"):
        anchor_mean(L, 0.6, 1.0)


def test_the_linear_display_is_the_intensity_and_its_level_sets_the_frames_mean():
    from evinr_lite.method.tonemap import display_shift, to_display, tonemap_linear

    rng = np.random.default_rng(3)
    L = rng.normal(-1.0, 0.8, (6, 20, 30)).astype(np.float32)
    np.testing.assert_allclose(tonemap_linear(L), np.minimum(np.exp(L.astype(np.float64)), 1.0))
    np.testing.assert_allclose(tonemap_linear(torch.from_numpy(L)).numpy(), tonemap_linear(L), rtol=1e-6)
    for mean in (0.2, 0.45, 0.8):
        c = display_shift(L, "linear", display_mean=mean)
        assert to_display(L + c, "linear").mean() == pytest.approx(mean, abs=1e-9)   # clipped pixels count as 1
    # a few hot pixels far above the scene move the level of the rest very little
    hot = L.copy()
    hot[0, 0, :4] = 40.0
    assert display_shift(hot) == pytest.approx(display_shift(L), abs=0.01)
    # the paper's anchor is unchanged: the mean log intensity sits at Reinhard's grey level
    assert (L + display_shift(L, "reinhard", 0.6, 0.5)).mean() == pytest.approx(anchor_level(0.6, 0.5), abs=1e-6)
    with pytest.raises(ValueError, match="tonemap"):
        to_display(L, "gamma")
    with pytest.raises(ValueError, match="display_mean"):
        display_shift(L, "linear", display_mean=1.0)


def test_the_kit_shows_linear_frames_and_the_paper_its_reinhard_curve():
    from evinr_lite import make_scene, simulate_scene
    from evinr_lite.method import EvINRConfig, reconstruct
    from evinr_lite.method.tonemap import to_display

    sc = make_scene("camera", sensor_size=(24, 32), duration=0.5)
    ev = simulate_scene(sc, 0.0, 0.5, C=0.2, seed=0)
    q = np.linspace(0.1, 0.4, 3)
    kit = EvINRConfig(C=0.2, progress=False)
    assert (kit.tonemap, EvINRConfig.paper().tonemap, EvINRConfig.paper().display_mean) == ("linear", "reinhard", 0.5)
    rec = reconstruct(ev, q, kit)
    np.testing.assert_allclose(rec.frames, to_display(rec.log_intensity, "linear"), atol=1e-6)
    np.testing.assert_allclose(rec.frames_at(q), rec.frames, atol=1e-6)
    paper_display = reconstruct(ev, q, EvINRConfig(C=0.2, progress=False, tonemap="reinhard", display_mean=0.5))
    np.testing.assert_allclose(paper_display.frames, tonemap_reinhard(paper_display.log_intensity, 0.6), atol=1e-6)
    # the same reconstruction, only shown otherwise: the log intensities differ by one constant
    d = rec.log_intensity - paper_display.log_intensity
    assert np.ptp(d) < 1e-4
    with pytest.raises(Exception, match="tonemap"):
        EvINRConfig(tonemap="srgb")
