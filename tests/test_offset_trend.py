"""The slowly varying per-pixel offset (method/offset.py: offset_trend, OffsetTrend) and its
use by the solver and streaming (EvINRConfig.offset_window)."""
import numpy as np
import pytest
from scipy.ndimage import gaussian_filter, shift

from evinr_lite import EvINRConfig, make_scene, simulate_scene
from evinr_lite.core.events import EventDataError
from evinr_lite.method.offset import OffsetTrend, median_gradient_offset, offset_trend
from evinr_lite.method.solver import reconstruct
from evinr_lite.method.streaming import stream_reconstruct


def _panned_texture(n_frames=60, size=(40, 50), seed=0):
    """float64 [G, H, W] log intensities of a random texture moving in circles of 20 px radius (a
    moving scene: each pixel sees an edge only now and then, along x and y)."""
    rng = np.random.default_rng(seed)
    tex = gaussian_filter(rng.normal(size=(size[0] + 50, size[1] + 50)), 1.0)
    tex = 1.5 * np.sign(tex) * np.abs(tex / tex.std()) ** 0.5       # patches with sharp edges
    a = np.linspace(0, 6 * np.pi, n_frames)
    return np.stack([shift(tex, (20 * np.sin(x), 20 * np.cos(x)), order=1, mode="nearest")[25:25 + size[0], 25:25 + size[1]]
                     for x in a])


def _centred(img):
    return img - img.mean()


def test_one_knot_is_the_single_image():
    frames = _panned_texture()
    t = np.linspace(0.0, 3.0, len(frames))
    ref = median_gradient_offset(frames).astype(np.float32)
    for window in (None, 5.0, 2.5):            # 3 s span: under 1.5 windows of 2.5 s or more, one image
        trend = offset_trend(t, frames, window, "median_gradient")
        assert trend.knots.shape == (1,)
        np.testing.assert_array_equal(trend.images[0], ref)


def test_a_per_pixel_drift_is_followed_where_one_image_cannot():
    rng = np.random.default_rng(1)
    frames = _panned_texture(n_frames=120, seed=1)
    t = np.linspace(0.0, 20.0, len(frames))
    drift = gaussian_filter(rng.normal(size=frames.shape[1:]), 2.0)
    drift *= 1.0 / drift.std()                         # a per-pixel offset going from 0 to `drift` over the span
    observed = frames + (t / t[-1])[:, None, None] * drift
    truth_offset = -(t / t[-1])[:, None, None] * drift  # what must be added back (up to one image)
    one = offset_trend(t, observed, None).at(t)
    trend = offset_trend(t, observed, 4.0)
    assert len(trend.knots) == 6
    many = trend.at(t)

    def err(est):   # the offset's error, each frame up to the image a single offset solve also leaves
        e = est - truth_offset
        return float(np.sqrt(np.mean([(_centred(e[k]) - _centred(e[0])) ** 2 for k in range(len(t))])))

    assert err(many) < 0.5 * err(one), (err(many), err(one))


def test_the_trend_is_linear_between_knots_and_flat_beyond():
    rng = np.random.default_rng(2)
    images = rng.normal(size=(3, 4, 5)).astype(np.float32)
    trend = OffsetTrend(np.array([0.0, 2.0, 6.0]), images)
    got = trend.at([-1.0, 0.0, 1.0, 2.0, 4.0, 6.0, 9.0])
    want = [images[0], images[0], 0.5 * (images[0] + images[1]), images[1], 0.5 * (images[1] + images[2]),
            images[2], images[2]]
    np.testing.assert_allclose(got, np.stack(want), atol=1e-6)
    L = np.ones((2, 4, 5), np.float32)
    assert trend.add_to(L, [0.0, 6.0]) is L                     # in place
    np.testing.assert_allclose(L, 1 + images[[0, 2]], atol=1e-6)


@pytest.mark.parametrize("bad", [0, -1.0, float("nan"), "5", True])
def test_a_bad_offset_window_is_refused(bad):
    with pytest.raises(EventDataError, match="offset_window"):
        EvINRConfig(offset_window=bad)
    assert EvINRConfig(offset_window=None).offset_window is None
    assert EvINRConfig(offset_window=3).offset_window == 3.0


@pytest.fixture(scope="module")
def events_3s():
    scene = make_scene("camera", sensor_size=(24, 32), duration=3.0)
    return simulate_scene(scene, 0.0, 3.0, C=0.2, seed=0)


def test_the_solver_and_streaming_apply_the_same_trend(events_3s, tmp_path):
    q = np.linspace(0.05, 2.95, 30)
    cfg = EvINRConfig(C=0.2, hidden_features=64, tau=1.0, overlap=0.25, offset_window=1.0, progress=False)
    rec = reconstruct(events_3s, q, cfg, t_start=0.0, t_end=3.0)
    assert rec.trend is not None and len(rec.trend.knots) == 4      # 3 s in windows of 1 s: 4 knots
    np.testing.assert_allclose(rec.at(q), rec.log_intensity, atol=1e-5)   # at() adds the same trend
    one = reconstruct(events_3s, q, EvINRConfig(**{**cfg.__dict__, "offset_window": None}), t_start=0.0, t_end=3.0)
    assert one.trend is None
    assert np.abs(rec.log_intensity - one.log_intensity).max() > 1e-3   # the trend changed something
    parts = list(stream_reconstruct(events_3s, q, cfg, t_start=0.0, t_end=3.0, workdir=tmp_path))
    L = np.concatenate([p.log_intensity for p in parts])
    # the same up to float32 rounding, which the per-knot medians can pick up (measured: 3e-4 of 2.3)
    np.testing.assert_allclose(L, rec.log_intensity, rtol=0, atol=1e-3 * np.abs(rec.log_intensity).max())
