"""Real-data helpers of notebook 09: event rate, contrast-threshold fit, frames to score, the shared data folder."""
import numpy as np
import pytest

from evinr_lite.teaching import exercises
from evinr_lite.core.events import EventDataError, Events
from evinr_lite.teaching.realdata_exercises import event_rate
from evinr_lite.evaluation.scoring import frames_to_score
from evinr_lite.method.binning import event_rate as library_event_rate
from evinr_lite.method.contrast import estimate_contrast_threshold, frame_log_changes
from evinr_lite.io.sample_data import find_shared_data, sample_recording_path
from evinr_lite.sim.recordings import synthetic_recording


def test_event_rate_counts_every_event_once():
    t = np.sort(np.random.default_rng(0).uniform(2.0, 3.0, 1000))
    centers, rate = event_rate(t, 0.1)
    assert np.isclose((rate * 0.1).sum(), len(t))
    assert np.isclose(centers[0], t[0] + 0.05) and np.all(np.diff(centers) > 0)
    assert centers[-1] - 0.05 <= t[-1] < centers[-1] + 0.05


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_teaching_event_rate_agrees_with_the_library(seed):
    """The exercise's reference re-implements method.binning.event_rate on purpose; pin the two."""
    rng = np.random.default_rng(seed)
    bin_s = 0.05
    t = np.sort(rng.uniform(1.0, 1.0 + rng.uniform(0.3, 0.9), 500))
    t = t[np.abs((t - t[0]) / bin_s - np.round((t - t[0]) / bin_s)) > 1e-6]   # no event on a bin edge
    t = np.concatenate([[1.0 - 0.01], t])
    p = rng.choice(np.array([-1, 1]), t.size)
    events = Events.from_arrays(t, np.zeros(t.size, int), np.zeros(t.size, int), p, (1, 1))
    centers, rate = event_rate(t, bin_s)
    edges, on, off = library_event_rate(events, bin_s)
    np.testing.assert_allclose(rate * bin_s, (on + off) * np.diff(edges), atol=1e-9)   # the same counts
    np.testing.assert_allclose(centers[:-1], 0.5 * (edges[:-2] + edges[1:-1]))        # full bins: same centres


def test_exercise_reference_passes_its_check():
    assert exercises.check("event_rate", event_rate, verbose=False)
    assert not exercises.check("event_rate", lambda t, bin_s: (event_rate(t, bin_s)[0], event_rate(t, bin_s)[1] * bin_s),
                               verbose=False)


def test_frames_to_score_and_span():
    ev = Events.from_arrays(t=np.array([0.1, 0.2, 0.3]), x=np.zeros(3, int), y=np.zeros(3, int),
                            p=np.array([1, -1, 1]), sensor_size=(2, 2))
    assert list(frames_to_score([0.0, 0.098, 0.2, 0.31, 0.5], ev)) == [1, 2]
    assert list(frames_to_score([0.0, 0.098, 0.2, 0.301, 0.5], ev, margin=0.005)) == [1, 2, 3]
    with pytest.raises(EventDataError, match="no frame lies within"):
        frames_to_score([0.5, 0.6], ev)


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
    from evinr_lite.io.readers import read_recording
    rec = read_recording(slider_depth_dir)
    idx = frames_to_score(rec.frames.t, rec.events)
    assert np.all(rec.frames.t[idx] >= rec.events.t[0] - 0.005) and np.all(rec.frames.t[idx] <= rec.events.t[-1] + 0.005)
    dL, n, mask = frame_log_changes(rec.frames, rec.events)
    assert dL.shape == n.shape == mask.shape and dL.shape[1:] == (180, 240)
    # events and brightness changes agree in sign on most active, well-exposed pixels of a real recording
    active = mask & (np.abs(n) >= 2)
    assert np.mean(np.sign(dL[active]) == np.sign(n[active])) > 0.7
    assert estimate_contrast_threshold(dL[mask], n[mask]) > 0
