"""A static camera (EvINRConfig(camera="static"), method/offset.py: l1_gradient_offset(rest=...)): each edge's
offset term counts only the frames where something moved over it, so the background an object passed over
is recovered instead of being flattened."""
import numpy as np
import pytest
from scipy.ndimage import binary_erosion, gaussian_filter

from evinr_lite import EvINRConfig
from evinr_lite.apps.options import RunOptions
from evinr_lite.core.events import EventDataError
from evinr_lite.evaluation.scoring import score_sequence
from evinr_lite.method.offset import STATIC_COARSE_PX, gaussian_lowpass, l1_gradient_offset, offset_image
from evinr_lite.method.solver import reconstruct
from evinr_lite.method.streaming import stream_reconstruct
from evinr_lite.sim.scenes import ObjectOverBackgroundScene
from evinr_lite.sim.simulate import simulate_scene

C = 0.2


def _object_over_background(K=48, H=40, W=56, seed=0):
    """(frames [K, H, W], background [H, W], swath bool [H, W]): what the events carry of a disc moving over a
    static background, the change of log intensity since rest (0 where nothing covers a pixel, object minus
    background where the disc does), and the background nobody sees."""
    rng = np.random.default_rng(seed)
    bg = gaussian_filter(rng.normal(size=(H, W)), 1.5)
    bg *= 0.6 / bg.std()
    obj = gaussian_filter(rng.normal(size=(H, W + 60)), 3.0)
    obj *= 0.6 / obj.std()
    y, x = np.mgrid[:H, :W]
    frames, swath = np.zeros((K, H, W)), np.zeros((H, W), bool)
    for k in range(K):
        cx = 8 + (W - 16) * k / (K - 1)
        disc = np.hypot(x - cx, y - H / 2) < 10
        swath |= disc
        start = int(round(60 - cx))
        shifted = obj[:, start:start + W]                             # the object's texture travels with it
        frames[k][disc] = (shifted - bg)[disc]
    return frames, bg, swath


def _corr(a, b):
    a, b = a - a.mean(), b - b.mean()
    return float((a * b).sum() / np.sqrt((a * a).sum() * (b * b).sum()))


def test_the_static_solve_recovers_the_background_an_object_passed_over():
    frames, bg, swath = _object_over_background()
    inner = binary_erosion(swath, iterations=3)                        # away from the swath's rim
    moving = l1_gradient_offset(frames)
    static = l1_gradient_offset(frames, rest=0.5 * C)
    assert _corr(static[inner], bg[inner]) > 0.85                      # the background is back
    assert _corr(moving[inner], bg[inner]) < 0.5                       # the default flattens it
    outside = ~swath                                                   # where nothing moved: nearly flat
    assert np.std(static[outside]) < 0.5 * np.std(static[inner])
    # what the solver uses: the structure finer than STATIC_COARSE_PX from that solve, the coarser from the plain one
    used = offset_image(frames, "l1_gradient", rest=0.5 * C)
    fine = lambda img: img - gaussian_lowpass(img, STATIC_COARSE_PX)          # noqa: E731
    assert _corr(fine(used)[inner], fine(bg)[inner]) > 0.85
    assert _corr(fine(offset_image(frames, "l1_gradient"))[inner], fine(bg)[inner]) < 0.5


def test_frames_at_rest_leave_each_edge_term_exactly():
    # every pixel moves in the first 10 frames and rests at one value in the other 20: the static solve over
    # all 30 is the plain solve over the 10 that moved
    rng = np.random.default_rng(1)
    moved = gaussian_filter(rng.normal(size=(10, 16, 20)), (0, 1, 1))
    moved = moved / moved.std() * 0.3
    rest_value = rng.normal(size=(16, 20))
    moved = rest_value + np.sign(moved) * (0.3 + np.abs(moved))          # at least 0.3 from rest everywhere
    frames = np.concatenate([moved, np.repeat(rest_value[None], 20, axis=0)])
    static = l1_gradient_offset(frames, rest=0.1, max_iters=300, tol=1e-7)
    plain = l1_gradient_offset(frames[:10], max_iters=300, tol=1e-7)
    scale = np.abs(np.diff(moved, axis=2)).mean()
    assert np.abs(static - plain).max() < 0.02 * scale
    assert np.abs(l1_gradient_offset(frames) - plain).max() > 0.1 * scale   # all 30 frames: another answer


def test_bad_rest_and_a_median_solve_are_refused():
    frames = np.zeros((4, 5, 6))
    frames[1, 2, 3] = 1.0
    for bad in (0.0, -1.0, np.nan, "0.1"):
        with pytest.raises(ValueError, match="rest"):
            l1_gradient_offset(frames, rest=bad)
    with pytest.raises(ValueError, match="l1_gradient"):
        offset_image(frames, "median_gradient", rest=0.1)


@pytest.fixture(scope="module")
def static_scene():
    scene = ObjectOverBackgroundScene("brick", "coffee", (48, 64), 1.5)
    events = simulate_scene(scene, 0.0, 1.5, C=C, seed=0)
    times = np.linspace(0.15, 1.4, 6)
    return events, times, np.clip(scene.intensity(times), 0, 1).astype(np.float32)


def test_reconstruct_with_a_static_camera_beats_the_default_on_a_static_scene(static_scene, tmp_path):
    events, times, gt = static_scene
    base = dict(C=C, hidden_features=64, progress=False)
    moving = reconstruct(events, times, EvINRConfig(**base), t_start=0.0, t_end=1.5)
    static = reconstruct(events, times, EvINRConfig(**base, camera="static"), t_start=0.0, t_end=1.5)
    s_moving = score_sequence(moving.frames, times, gt, times, "none", lpips_model=False)["ssim"]
    s_static = score_sequence(static.frames, times, gt, times, "none", lpips_model=False)["ssim"]
    assert s_static > s_moving + 0.03
    parts = list(stream_reconstruct(events, times, EvINRConfig(**base, camera="static"), t_start=0.0, t_end=1.5,
                                    workdir=tmp_path))                 # the stream solves the same offset
    L = np.concatenate([p.log_intensity for p in parts])
    np.testing.assert_allclose(L, static.log_intensity, rtol=0, atol=1e-3 * np.abs(static.log_intensity).max())


def test_the_camera_setting_is_checked_and_reaches_the_config():
    with pytest.raises(EventDataError, match="camera must be one of"):
        EvINRConfig(camera="tripod")
    with pytest.raises(EventDataError, match="l1_gradient"):
        EvINRConfig(camera="static", offset_solve="median_gradient")
    assert EvINRConfig().offset_rest() is None
    assert EvINRConfig(C=(0.3, 0.2), camera="static").offset_rest() == pytest.approx(0.1)
    assert RunOptions(static_camera=True).config(0.2).camera == "static"
    assert RunOptions().config(0.2).camera == "moving"
    with pytest.raises(EventDataError, match="static_camera"):
        RunOptions(static_camera=True, recipe="paper")
    with pytest.raises(EventDataError, match="static_camera"):
        RunOptions(static_camera=True, anchor="first")
    with pytest.raises(EventDataError, match="static_camera"):
        RunOptions(static_camera="yes")
