"""Synthetic scenes: ground truth at any time, finite, smooth, moving as documented."""
import numpy as np
import pytest

from evinr_lite.core.events import EventDataError
from evinr_lite.core.frames import Frames
from evinr_lite.sim.scenes import MovingBarScene, MovingImageScene, Scene, make_scene
from evinr_lite.sim.simulate import simulate_scene

SMALL = (24, 32)


@pytest.fixture(params=["camera", "astronaut", "bar", "array"])
def scene(request):
    if request.param == "array":
        image = np.random.default_rng(0).uniform(size=(64, 80, 3))
        return MovingImageScene(image, SMALL, 1.5, blur=1.5)
    return make_scene(request.param, sensor_size=SMALL, duration=1.5)


def test_shapes_finite_and_scalar_array_agree(scene):
    assert isinstance(scene, Scene) and scene.sensor_size == SMALL and scene.duration == 1.5
    t = np.array([0.0, 0.3, 1.5, 2.0])                 # 2.0 is past the end: still defined
    L = scene.log_intensity(t)
    assert L.shape == (4, *SMALL) and L.dtype == np.float64 and np.all(np.isfinite(L))
    assert scene.log_intensity(0.3).shape == SMALL
    np.testing.assert_allclose(scene.log_intensity(0.3), L[1], rtol=0, atol=1e-12)
    np.testing.assert_allclose(scene.intensity(t), np.exp(L))
    assert np.log(0.05) - 0.05 <= L.min() and L.max() <= 0.05    # intensity in [0.05, 1] (+ cubic overshoot)


def test_changes_with_time_and_continuously(scene):
    L0, L1 = scene.log_intensity(np.array([0.6, 0.9]))
    assert np.abs(L1 - L0).max() > 0.3                                    # it moves
    for dt in (1e-3, 1e-5):
        step = np.abs(scene.log_intensity(0.6 + dt) - L0).max()
        assert 0 < step < 50 * dt                  # Lipschitz in t: max speed x max gradient is bounded


def test_image_translates_at_the_stated_velocity_and_direction():
    scene = MovingImageScene("camera", (40, 50), 2.0, velocity=(20.0, -10.0), rotation=0.0, zoom=0.0)
    a, b = scene.log_intensity(np.array([0.7, 0.8]))       # in 0.1 s: 2 px right (+x), 1 px up (-y)
    np.testing.assert_allclose(b[:-1, 2:], a[1:, :-2], atol=1e-10)
    assert np.abs(b - a).max() > 0.1


def test_bar_moves_along_its_angle_and_crosses_the_sensor():
    scene = MovingBarScene((30, 40), 2.0, angle=0.0, speed=10.0, start=-5.0)
    a, b = scene.log_intensity(np.array([0.5, 0.8]))       # 3 px to the right
    np.testing.assert_allclose(b[:, 3:], a[:, :-3], atol=1e-12)
    default = MovingBarScene((30, 40), 2.0)
    first, middle, last = default.intensity(np.array([0.0, 1.0, 2.0]))
    assert np.ptp(first) < 0.01 and np.ptp(last) < 0.01 and np.ptp(middle) > 0.5   # enters and leaves


def test_zoom_and_rotation_keep_the_centre_fixed():
    H, W = 41, 51                                             # odd: a pixel sits on the centre
    scene = MovingImageScene("camera", (H, W), 2.0, velocity=(0, 0), rotation=0.5, zoom=0.3)
    L = scene.log_intensity(np.array([0.2, 1.8]))
    assert abs(L[0, 20, 25] - L[1, 20, 25]) < 1e-9
    assert np.abs(L[0] - L[1]).max() > 0.3


def test_frames_give_ground_truth_frames():
    scene = make_scene("camera", sensor_size=SMALL)
    frames = scene.frames([0.0, 0.5])
    assert isinstance(frames, Frames) and frames.size == SMALL and len(frames) == 2
    np.testing.assert_allclose(frames.images, scene.intensity(np.array([0.0, 0.5])), rtol=1e-6)


def test_default_scene_gives_tens_of_events_per_pixel():
    scene = make_scene()
    assert scene.sensor_size == (120, 160) and scene.duration == 2.0
    ev = simulate_scene(scene, C=0.2)
    per_pixel = len(ev) / (120 * 160)
    assert 5 < per_pixel < 60
    assert np.bincount(ev.y * 160 + ev.x, minlength=120 * 160).astype(bool).mean() > 0.8  # all over (camera's sky is flat)


def test_bad_scene_arguments_are_named():
    with pytest.raises(EventDataError, match="unknown scene"):
        make_scene("nope")
    with pytest.raises(EventDataError, match="sensor_size"):
        make_scene("bar", sensor_size=(0, 10))
    with pytest.raises(EventDataError, match="constant"):
        MovingImageScene(np.ones((20, 20)))
    with pytest.raises(EventDataError, match="intensity_range"):
        make_scene("camera", intensity_range=(0.0, 1.0))
    with pytest.raises(EventDataError, match="duration"):
        make_scene("camera", duration=-1)
    with pytest.raises(EventDataError, match="1-D"):
        make_scene("bar", sensor_size=SMALL).log_intensity(np.zeros((2, 2)))
