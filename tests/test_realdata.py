"""Real-data helpers of notebook 09: event rate, contrast-threshold fit, frames to score, the shared data folder."""
import numpy as np
import pytest

from evinr_lite import exercises
from evinr_lite.events import EventDataError, Events
from evinr_lite.realdata import (event_rate, fit_contrast_threshold, frame_pair_changes, frames_to_score,
                                 scored_span)
from evinr_lite.sample_data import find_shared_data, sample_recording_path, synthetic_recording
from evinr_lite.scenes import make_scene
from evinr_lite.simulate import simulate_scene


def test_event_rate_counts_every_event_once():
    t = np.sort(np.random.default_rng(0).uniform(2.0, 3.0, 1000))
    centers, rate = event_rate(t, 0.1)
    assert np.isclose((rate * 0.1).sum(), len(t))
    assert np.isclose(centers[0], t[0] + 0.05) and np.all(np.diff(centers) > 0)
    assert centers[-1] - 0.05 <= t[-1] < centers[-1] + 0.05


def test_fit_recovers_the_simulated_threshold():
    C = 0.3
    scene = make_scene("camera", sensor_size=(40, 50), duration=0.5)
    events = simulate_scene(scene, 0.0, 0.5, C=C, seed=0)
    t = np.linspace(0.0, 0.5, 6)
    dL = np.diff(scene.log_intensity(t), axis=0)
    from evinr_lite.binning import events_to_frames
    n = events_to_frames(events, t, C=1.0).frames
    # |dL - C n| < C per pixel, so the least-squares slope lands near C
    assert abs(fit_contrast_threshold(dL, n) - C) < 0.1 * C
    assert exercises.check("fit_contrast_threshold", fit_contrast_threshold, verbose=False)
    assert exercises.check("event_rate", event_rate, verbose=False)
    assert not exercises.check("fit_contrast_threshold", lambda dL, n: 2 * fit_contrast_threshold(dL, n), verbose=False)


def test_frames_to_score_and_span():
    ev = Events.from_arrays(t=np.array([0.1, 0.2, 0.3]), x=np.zeros(3, int), y=np.zeros(3, int),
                            p=np.array([1, -1, 1]), sensor_size=(2, 2))
    assert list(frames_to_score([0.0, 0.098, 0.2, 0.31, 0.5], ev)) == [1, 2]
    assert list(frames_to_score([0.0, 0.098, 0.2, 0.301, 0.5], ev, margin=0.005)) == [1, 2, 3]
    with pytest.raises(EventDataError, match="no frame lies within"):
        frames_to_score([0.5, 0.6], ev)
    assert scored_span([0.0], ev, eval_window=(0.15, 0.25)) == (0.15, 0.25)
    assert scored_span([0.0], ev, eval_window=(1.0, 2.5)) == (0.1, 0.3)     # recording shorter than the window


def test_find_shared_data_follows_the_env_var(tmp_path, monkeypatch):
    (tmp_path / "mine").mkdir()
    monkeypatch.setenv("EVINR_SHARED_DATA", str(tmp_path))
    assert find_shared_data() == tmp_path
    assert sample_recording_path("mine") == tmp_path / "mine"
    assert sample_recording_path("absent") is None
    monkeypatch.setenv("EVINR_SHARED_DATA", str(tmp_path / "nowhere"))
    assert find_shared_data() is None


def test_synthetic_recording_is_deterministic():
    a, b = synthetic_recording(sensor_size=(20, 30), duration=0.2, seed=3), synthetic_recording(sensor_size=(20, 30), duration=0.2, seed=3)
    assert np.array_equal(a.events.t, b.events.t) and np.array_equal(a.frames.images, b.frames.images)
    assert a.frames.images.shape == (6, 20, 30) and a.events.sensor_size == (20, 30)


def test_slider_depth_frames_and_threshold(slider_depth_dir):
    from evinr_lite.readers import read_recording
    rec = read_recording(slider_depth_dir)
    idx = frames_to_score(rec.frames.t, rec.events)
    assert np.all(rec.frames.t[idx] >= rec.events.t[0] - 0.005) and np.all(rec.frames.t[idx] <= rec.events.t[-1] + 0.005)
    dL, n = frame_pair_changes(rec.events, rec.frames.t[idx], rec.frames.images[idx])
    assert dL.shape == n.shape == (len(idx) - 1, 180, 240)
    # events and brightness changes agree in sign on most active pixels of a real recording
    active = np.abs(n) >= 2
    assert np.mean(np.sign(dL[active]) == np.sign(n[active])) > 0.7
    assert fit_contrast_threshold(dL, n) > 0
