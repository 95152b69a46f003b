"""RecordingSource: windows of a recording, from memory or from any file format, match the whole read."""
import numpy as np
import pytest

from evinr_lite.core.events import EventDataError, Events, InputError
from evinr_lite.core.frames import Frames
from evinr_lite.core.recording import Recording
from evinr_lite.io import as_source, open_recording, read_recording, sample_recording_path


def _events(n=5000, seed=0, size=(30, 40), t_origin=0.0):
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0.0, 1.0, n))
    return Events(t, rng.integers(0, size[1], n), rng.integers(0, size[0], n), rng.choice([-1, 1], n), size,
                  t_origin=t_origin)


def _same(a: Events, b: Events):
    assert len(a) == len(b)
    for k in "txyp":
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k))
    assert a.sensor_size == b.sensor_size and a.t_origin == b.t_origin


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_memory_windows_tile_the_events(seed):
    ev = _events(seed=seed, t_origin=1.5e9)
    src = as_source(ev)
    assert src.n_events == len(ev) and src.sensor_size == ev.sensor_size and src.t_origin == 1.5e9
    assert src.t_span == (ev.t[0], ev.t[-1])
    edges = np.linspace(src.t_span[0], src.t_span[1] + 1e-9, 8)
    parts = [src.events(a, b) for a, b in zip(edges[:-1], edges[1:])]
    for part, a, b in zip(parts, edges[:-1], edges[1:]):
        assert np.all((part.t >= a) & (part.t < b))
    _same(Events.concatenate(parts), ev)


def test_memory_window_outside_is_empty_and_bad_windows_refused():
    src = as_source(_events())
    assert len(src.events(5.0, 6.0)) == 0
    for t0, t1 in ((0.5, 0.5), (0.6, 0.5), (float("nan"), 1.0), ("a", 1.0)):
        with pytest.raises(EventDataError):
            src.events(t0, t1)
    with pytest.raises(EventDataError, match="no events in the window"):
        src.load(5.0, 6.0)


def test_as_source_recording_keeps_frames_and_load_slices_them():
    ev = _events()
    frames = Frames(np.zeros((4, 30, 40), np.uint8), np.array([0.1, 0.3, 0.5, 0.7]))
    src = as_source(Recording(ev, frames, {"format": "x", "path": "p"}))
    assert src.frames is frames and src.format == "x"
    rec = src.load(0.2, 0.6)
    np.testing.assert_array_equal(rec.frames.t, [0.3, 0.5])
    _same(rec.events, ev.slice_time(0.2, 0.6))
    assert src.load().events is ev
    assert as_source(src) is src


@pytest.mark.parametrize("bad", [np.zeros((10, 4)), "some/path.h5", {"t": 1}, None])
def test_as_source_refuses_what_is_not_in_memory(bad):
    with pytest.raises(InputError):
        as_source(bad)


def test_open_recording_real_chunk_matches_read_recording():
    path = sample_recording_path()
    if path is None:
        pytest.skip("shared data not present")
    whole = read_recording(path)
    with open_recording(path) as src:
        assert src.sensor_size == whole.events.sensor_size and src.format == "ijrr"
        assert src.n_events in (None, len(whole.events))
        assert src.t_span == (whole.events.t[0], whole.events.t[-1])
        mid = 0.5 * (src.t_span[0] + src.t_span[1])
        _same(src.events(src.t_span[0], mid), whole.events.slice_time(None, mid))
        assert len(src.frames) == len(whole.frames)
