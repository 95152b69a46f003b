"""The reconstruct job's steps (recon_job), the export helpers, and notebook 11's exercises and helpers."""
import json
import os

import numpy as np
import pytest
from PIL import Image

from evinr_lite import EventDataError, read_recording
from evinr_lite.teaching import exercises
from evinr_lite.io.export import save_gif, save_mp4
from evinr_lite.apps.recon_job import choose_times, describe_recording, load_recording, run_reconstruct
from evinr_lite.io.sample_data import ENV_VAR as SHARED_ENV_VAR
from evinr_lite.teaching.recording_exercises import event_count_windows, window_table, windows_from_indices
from evinr_lite.method.contrast import estimate_contrast_threshold, frame_log_changes
from evinr_lite.sim.recordings import find_recording, write_example_recording


@pytest.fixture(scope="module")
def example(tmp_path_factory):
    return write_example_recording(tmp_path_factory.mktemp("ex") / "rec", sensor_size=(36, 48), duration=0.4,
                                   C=0.25, frame_rate=25.0, seed=1)


def test_contrast_threshold_recovered_from_frames(example):
    rec = read_recording(example)
    dL, n, mask = frame_log_changes(rec.frames, rec.events)
    assert dL.shape == n.shape == mask.shape and dL.shape[1:] == (36, 48)
    # only frame pairs with events all the way between them
    assert dL.shape[0] == np.sum((rec.frames.t[:-1] >= rec.events.t[0]) & (rec.frames.t[1:] <= rec.events.t[-1]))
    C = estimate_contrast_threshold(dL[mask], n[mask])
    assert 0.8 * 0.25 < C < 1.1 * 0.25      # crossings not yet completed bias it slightly low


def test_exercise_references_pass_and_hints_catch_mistakes(capsys):
    assert exercises.check("estimate_contrast_threshold", estimate_contrast_threshold)
    assert exercises.check("event_count_windows", event_count_windows)
    capsys.readouterr()
    ratio_of_means = lambda log_changes, net_counts: float(  # noqa: E731
        np.mean(np.asarray(log_changes)[np.asarray(net_counts) != 0] / np.asarray(net_counts)[np.asarray(net_counts) != 0]))
    assert not exercises.check("estimate_contrast_threshold", ratio_of_means)
    assert "mean of per-pixel ratios" in capsys.readouterr().out
    floor_windows = lambda n_events, max_events: (  # noqa: E731
        np.arange(max(1, n_events // max_events) + 1, dtype=np.int64) * n_events) // max(1, n_events // max_events)
    assert not exercises.check("event_count_windows", floor_windows)
    assert "ceil" in capsys.readouterr().out


@pytest.mark.parametrize("n_events,max_events", [(10, 3), (50_000, 20_000), (7, 7), (1, 5), (1001, 10)])
def test_event_count_windows_are_few_bounded_and_even(n_events, max_events):
    idx = event_count_windows(n_events, max_events)
    sizes = np.diff(idx)
    assert idx[0] == 0 and idx[-1] == n_events
    assert len(sizes) == -(-n_events // max_events)            # the fewest windows
    assert sizes.max() <= max_events and sizes.max() - sizes.min() <= 1


def test_windows_and_table(example):
    rec = read_recording(example)
    idx = event_count_windows(len(rec.events), len(rec.events) // 3 + 1)
    windows = windows_from_indices(rec.events.t, idx)
    rows = window_table(rec.events, rec.frames, windows)
    assert len(rows) == 3 and windows[-1][1] is None
    assert sum(r["events"] for r in rows) == len(rec.events)
    for (start, end), row in zip(windows, rows):
        part = load_recording(example, t_start=start, t_end=end)
        assert len(part.events) == row["events"]
        assert (0 if part.frames is None else len(part.frames)) == row["gt_frames"]
    with pytest.raises(EventDataError, match="rise strictly"):
        windows_from_indices(rec.events.t, [0, 5, 5, len(rec.events)])


def test_find_recording_order(tmp_path, monkeypatch):
    monkeypatch.delenv(SHARED_ENV_VAR, raising=False)
    shared = tmp_path / "project" / "shared" / "data" / "ijrr_slider_depth_chunk"
    shared.mkdir(parents=True)
    (shared / "events.txt").write_text("0.1 1 1 1\n")
    deep = tmp_path / "project" / "main" / "notebooks"
    deep.mkdir(parents=True)
    assert find_recording(start=deep) == (shared, "the shared IJRR slider_depth chunk")
    assert find_recording(shared.parent, start=deep) == (shared.parent, "given")
    with pytest.raises(EventDataError, match="no such recording"):
        find_recording(tmp_path / "gone", start=deep)
    # the one environment variable of shared data: a data folder without the chunk -> synthetic
    monkeypatch.setenv(SHARED_ENV_VAR, str(tmp_path / "elsewhere"))
    with pytest.raises(EventDataError, match="no recording found"):
        find_recording(start=deep)
    path, origin = find_recording(scratch=tmp_path / "scratch", start=deep)
    assert "synthetic" in origin and read_recording(path).frames is not None
    monkeypatch.setenv(SHARED_ENV_VAR, str(shared.parent))
    assert find_recording(start=tmp_path)[0] == shared


def test_choose_times(example):
    rec = load_recording(example, t_start=0.1, t_end=0.3)
    times, source = choose_times(rec)
    np.testing.assert_array_equal(times, rec.frames.t)        # default: the ground-truth frame times
    assert np.all((rec.frames.t >= 0.1) & (rec.frames.t <= 0.3)) and "ground-truth" in source
    times, _ = choose_times(rec, fps=50)
    np.testing.assert_allclose(times, 0.1 + (np.arange(10) + 0.5) / 50)
    times, _ = choose_times(rec, at="0.25, 0.15")
    np.testing.assert_array_equal(times, [0.15, 0.25])
    with pytest.raises(EventDataError, match="either fps= or at="):
        choose_times(rec, fps=10, at="0.2")
    with pytest.raises(EventDataError, match="outside the reconstructed window"):
        choose_times(rec, at=[0.05])


def test_canonical_file_supplies_C(example, tmp_path):
    from data_fetch.canonical import CanonicalWriter

    rec = read_recording(example)
    path = tmp_path / "seq.h5"
    with CanonicalWriter(path, sensor_size=rec.events.sensor_size, C=0.25, dataset="test", sequence="seq") as w:
        w.add_events(rec.events.t, rec.events.x, rec.events.y, rec.events.p)
        for img, t in zip(rec.frames.images, rec.frames.t):
            w.add_frame(img, t)
    info = describe_recording(load_recording(path))
    assert info["format"] == "canonical" and info["C"] == 0.25 and info["n_events"] == len(rec.events)
    run = run_reconstruct(path, tmp_path / "out", n_iters=3, video=False, progress=False, log=lambda *a: None)
    assert run["C"] == 0.25 and run["C_source"] == "from the file" and "scores" in run
    assert json.loads((tmp_path / "out" / "run.json").read_text())["C"] == 0.25


def test_video_writers(tmp_path):
    frames = np.random.default_rng(0).random((4, 13, 17))      # odd sizes
    save_gif(tmp_path / "a.gif", frames, fps=8)
    with Image.open(tmp_path / "a.gif") as gif:
        assert gif.n_frames == 4 and gif.size == (17, 13) and abs(gif.info["duration"] - 1000 / 8) <= 10
    save_mp4(tmp_path / "a.mp4", frames, fps=8)
    import cv2

    video = cv2.VideoCapture(str(tmp_path / "a.mp4"))
    assert int(video.get(cv2.CAP_PROP_FRAME_COUNT)) == 4 and int(video.get(cv2.CAP_PROP_FRAME_WIDTH)) == 18
    video.release()
    with pytest.raises(ValueError, match="fps must be positive"):
        save_gif(tmp_path / "b.gif", frames, fps=0)
    assert not os.path.exists(tmp_path / "b.gif")


def test_format_info_prints_a_fractional_t_origin_in_full(tmp_path):
    # a canonical file keeps the origin it was written with; ":.0f" printed 1500000000.123456 as 1500000000
    from evinr_lite.apps.recon_job import format_info
    from evinr_lite.io.canonical import CanonicalWriter
    out = tmp_path / "abs.h5"
    with CanonicalWriter(out, sensor_size=(4, 5), t_origin=1_500_000_000.123456) as w:
        w.add_events(np.array([0.01, 0.02]), np.array([1, 2]), np.array([0, 3]), np.array([1, -1]))
    text = format_info(describe_recording(read_recording(out)))
    assert "times relative to t_origin = 1500000000.123456 s" in text
    info = describe_recording(read_recording(out))
    assert "t_origin = 1500000000 s" in format_info({**info, "t_origin": 1_500_000_000.0})
    assert "t_origin = 0 s" in format_info({**info, "t_origin": 0.0})
