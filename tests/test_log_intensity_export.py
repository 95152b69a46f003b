"""`--save-log` / `save_log=True`: the frames' log intensity, unclipped, as float32 in log_intensity.h5
(evinr_lite.io.export), from the streamed job, the in-memory job and the colour job."""
from __future__ import annotations

import json

import h5py
import numpy as np
import pytest
from PIL import Image

from evinr_lite.apps.cli import main
from evinr_lite.apps.options import BATCH_FIELDS, RunOptions
from evinr_lite.apps.recon_job import run_reconstruct
from evinr_lite.apps.stream_job import check_disk, streamable
from evinr_lite.core.events import EventDataError
from evinr_lite.io.export import (LOG_INTENSITY_FILE, LogIntensityWriter, read_log_intensity, save_log_intensity)
from evinr_lite.method.tonemap import display_formula, to_display
from evinr_lite.sim.colour_davis import write_colour_davis_recording
from evinr_lite.sim.recordings import write_example_recording


@pytest.fixture(scope="module")
def example(tmp_path_factory):
    return write_example_recording(tmp_path_factory.mktemp("ex") / "rec", sensor_size=(36, 48), duration=0.4,
                                   C=0.25, frame_rate=25.0, seed=3)


def _pngs(folder) -> np.ndarray:
    return np.stack([np.asarray(Image.open(p)) for p in sorted((folder / "frames").glob("frame_*.png"))])


def _check_run(out, tonemap="linear", gamma=0.6):
    """The file holds one float32 frame per PNG, at timestamps.txt's times, and the PNGs are its display."""
    L, t, attrs = read_log_intensity(out / LOG_INTENSITY_FILE)
    png = _pngs(out)
    stamps = np.loadtxt(out / "timestamps.txt")[:, 1]
    assert L.dtype == np.float32 and L.shape[:3] == png.shape[:3] and np.all(np.isfinite(L))
    np.testing.assert_allclose(t, stamps, atol=1e-9)
    # the 8-bit frames are exactly the display of these values (the same rounding as to_uint8)
    shown = np.round(np.clip(to_display(L.astype(np.float64), tonemap, gamma), 0, 1) * 255)
    assert np.abs(shown - png).max() <= 1
    assert attrs["tonemap"] == tonemap and attrs["display"] == display_formula(tonemap, gamma)
    assert attrs["anchor"] == "none"
    assert LOG_INTENSITY_FILE in json.loads((out / "run.json").read_text())["files"]
    return L


def test_round_trip_keeps_every_value_and_says_what_they_are(tmp_path):
    rng = np.random.default_rng(0)
    L = rng.normal(0, 2, size=(4, 5, 6)).astype(np.float32)       # values far beyond the display's white
    path = save_log_intensity(tmp_path / "L.h5", L, [0.1, 0.2, 0.3, 0.4], t_origin=12.0, tonemap="reinhard",
                              gamma=0.5, display=display_formula("reinhard", 0.5))
    back, t, attrs = read_log_intensity(path)
    assert np.array_equal(back, L) and t.dtype == np.float64 and list(t) == [0.1, 0.2, 0.3, 0.4]
    assert attrs["t_origin"] == 12.0 and attrs["tonemap"] == "reinhard" and attrs["gamma"] == 0.5
    assert "natural log" in attrs["units"] and attrs["display"] == "frames = sigmoid(L) ** 0.5"
    with h5py.File(path, "r") as f:                                  # one chunk per frame: streamed writes
        assert f["log_intensity"].chunks == (1, 5, 6)
    colour = rng.normal(size=(2, 3, 4, 3)).astype(np.float32)
    assert np.array_equal(read_log_intensity(save_log_intensity(tmp_path / "c.h5", colour, [0.0, 1.0]))[0], colour)


def test_anchor_attribute_says_which_display_applies_and_old_files_still_read(tmp_path):
    """An anchored run's frames are linear_frames(L), not to_display(L, "linear") (a grey level off), so the file
    names the anchor mode; a file from before the attribute reads with anchor None, and bad modes are refused."""
    from evinr_lite.io.export import ANCHORS
    from evinr_lite.method.anchor import ANCHOR_MODES

    assert ANCHORS == ANCHOR_MODES   # io sits below method: the list is kept twice
    L = np.zeros((2, 3, 4), np.float32)
    assert read_log_intensity(save_log_intensity(tmp_path / "n.h5", L, [0.0, 1.0]))[2]["anchor"] == "none"
    path = save_log_intensity(tmp_path / "a.h5", L, [0.0, 1.0], anchor="first")
    assert read_log_intensity(path)[2]["anchor"] == "first"
    with h5py.File(path, "a") as f:   # as written before the attribute existed
        del f.attrs["anchor"]
    back, t, attrs = read_log_intensity(path)
    assert attrs["anchor"] is None and back.shape == (2, 3, 4) and attrs["tonemap"] == "linear"
    with pytest.raises(EventDataError, match="anchor"):
        save_log_intensity(tmp_path / "b.h5", L, [0.0, 1.0], anchor="some")


def test_writer_refuses_an_incomplete_file_and_bad_frames(tmp_path):
    w = LogIntensityWriter(tmp_path / "a.h5", [0.1, 0.2, 0.3], (4, 5))
    w.write(2, np.zeros((4, 5)))
    with pytest.raises(EventDataError, match=r"2 of 3 frames were never written \(first: 0\)"):
        w.close()
    L, _, _ = read_log_intensity(tmp_path / "a.h5")
    assert np.isnan(L[0]).all() and np.isnan(L[1]).all() and (L[2] == 0).all()   # unwritten rows read as NaN
    with LogIntensityWriter(tmp_path / "b.h5", [0.1], (4, 5)) as w:
        with pytest.raises(EventDataError, match=r"shape \(5, 4\), expected \(4, 5\)"):
            w.write(0, np.zeros((5, 4)))
        w.write(0, np.ones((4, 5)))
    # an error inside the block aborts: the file is closed and the incompleteness is not what is raised
    with pytest.raises(RuntimeError, match="stopped"):
        with LogIntensityWriter(tmp_path / "c.h5", [0.1, 0.2], (4, 5)) as w:
            raise RuntimeError("stopped")
    assert not w.file.id.valid
    for bad in [(4,), (4, 5, 2), (0, 5)]:
        with pytest.raises(EventDataError, match="frame_shape"):
            LogIntensityWriter(tmp_path / "d.h5", [0.1], bad)
    with pytest.raises(EventDataError, match="one frame per time"):
        save_log_intensity(tmp_path / "e.h5", np.zeros((2, 4, 5)), [0.1])


def test_reading_something_else_names_the_fix(tmp_path):
    (tmp_path / "x.h5").write_bytes(b"not hdf5 at all")
    with pytest.raises(EventDataError, match="cannot be read as HDF5"):
        read_log_intensity(tmp_path / "x.h5")
    with h5py.File(tmp_path / "events.h5", "w") as f:
        f.create_dataset("events/t", data=np.zeros(3))
    with pytest.raises(EventDataError, match="--save-log"):
        read_log_intensity(tmp_path / "events.h5")


def test_streamed_run_writes_the_unclipped_log_intensity(example, tmp_path):
    out = tmp_path / "s"
    run_reconstruct(example, out, C=0.25, fps=20, save_log=True, video=False, progress=False, log=lambda *a: None)
    assert streamable(RunOptions(C=0.25, fps=20, save_log=True))      # this run went through the stream
    L = _check_run(out)
    assert L.shape[0] == len(json.loads((out / "run.json").read_text())["times_s"]) >= 5
    # without the flag there is no file (and nothing else changes)
    plain = tmp_path / "p"
    run_reconstruct(example, plain, C=0.25, fps=20, video=False, progress=False, log=lambda *a: None)
    assert not (plain / LOG_INTENSITY_FILE).exists()
    assert np.array_equal(_pngs(plain), _pngs(out))


def test_in_memory_run_writes_it_too(example, tmp_path):
    out = tmp_path / "m"
    run_reconstruct(example, out, C=0.25, save_log=True, denoise=True, tonemap="reinhard", progress=False,
                    log=lambda *a: None)                              # denoise: the in-memory job
    assert not streamable(RunOptions(denoise=True))
    L = _check_run(out, tonemap="reinhard")
    assert (out / "reconstruction.mp4").exists() and L.shape[0] == len(np.loadtxt(out / "timestamps.txt"))


def test_colour_run_keeps_three_channels(tmp_path):
    h5 = write_colour_davis_recording(tmp_path / "coffee.h5", "coffee", sensor_size=(24, 32), duration=0.3, C=0.2,
                                      frame_rate=20.0, seed=0)
    out = tmp_path / "c"
    assert main(["reconstruct", str(h5), "--out", str(out), "--colour", "--no-video", "--quiet", "--save-log"]) == 0
    L = _check_run(out)
    assert L.shape[1:] == (12, 16, 3)


def test_a_failing_write_leaves_no_output(example, tmp_path, monkeypatch):
    def broken(self, i, image):
        raise OSError("disk full")

    monkeypatch.setattr(LogIntensityWriter, "write", broken)
    out = tmp_path / "f"
    with pytest.raises(OSError, match="disk full"):
        run_reconstruct(example, out, C=0.25, fps=20, save_log=True, video=False, progress=False, log=lambda *a: None)
    assert not out.exists() and list(tmp_path.iterdir()) == []


def test_disk_check_counts_the_log_frames(tmp_path):
    base = check_disk(10, (100, 200), tmp_path)["total"]
    assert check_disk(10, (100, 200), tmp_path, log_frames=10)["total"] == base + 10 * 4 * 100 * 200
    with pytest.raises(EventDataError, match="GiB of disk"):
        check_disk(1, (100, 200), tmp_path, log_frames=10 ** 9)


def test_the_option_is_checked_and_reaches_batch():
    assert RunOptions(save_log=True).save_log is True and RunOptions().save_log is False
    with pytest.raises(EventDataError, match="save_log"):
        RunOptions(save_log="yes")
    assert "save_log" in BATCH_FIELDS
    assert RunOptions.from_settings({"save_log": True}).save_log is True


def test_batch_writes_one_file_per_recording(tmp_path):
    from evinr_lite.apps.batch import run_batch

    folder = tmp_path / "in"
    folder.mkdir()
    for i, scene in enumerate(("camera", "moon")):
        write_example_recording(folder / f"rec_{scene}", scene=scene, sensor_size=(24, 32), duration=0.3,
                                frame_rate=10.0, seed=i)
    run_batch([folder], tmp_path / "out", sequential=True, save_log=True, progress=False, log=lambda *a, **k: None)
    for scene in ("camera", "moon"):
        _check_run(tmp_path / "out" / f"rec_{scene}")


def test_given_as_a_recording_it_is_named_for_what_it_is(tmp_path, capsys):
    path = save_log_intensity(tmp_path / LOG_INTENSITY_FILE, np.zeros((2, 4, 5)), [0.1, 0.2])
    for command in (["info", str(path)], ["reconstruct", str(path), "--out", str(tmp_path / "o")]):
        assert main(command) == 2
        err = capsys.readouterr().err
        assert "a reconstruction's log intensity" in err and "the recording it came from" in err
    assert not (tmp_path / "o").exists()


def test_a_time_asked_for_twice_is_written_twice_by_both_jobs(example, tmp_path):
    """--at with a repeated time: every frame of timestamps.txt has its PNG and its row in log_intensity.h5, in
    the streamed job (which once wrote only the last of them) as in the in-memory one."""
    at = [0.1, 0.1, 0.2]
    for name, extra in (("streamed", {}), ("in_memory", {"denoise": True})):
        out = tmp_path / name
        run_reconstruct(example, out, C=0.25, at=at, save_log=True, video=False, progress=False,
                        log=lambda *a: None, **extra)
        png = _pngs(out)
        assert png.shape[0] == 3 and np.array_equal(png[0], png[1])
        L = _check_run(out)
        assert np.array_equal(L[0], L[1])


def test_a_part_is_read_without_the_rest(tmp_path):
    L = np.arange(5 * 2 * 3, dtype=np.float32).reshape(5, 2, 3)
    path = save_log_intensity(tmp_path / "L.h5", L, [0.1, 0.2, 0.3, 0.4, 0.5])
    part, t, _ = read_log_intensity(path, frames=slice(1, 3))
    assert np.array_equal(part, L[1:3]) and list(t) == [0.2, 0.3]
    one, t1, _ = read_log_intensity(path, frames=-1)
    assert np.array_equal(one, L[-1]) and t1 == 0.5
    for bad, match in ((7, "does not exist; the file holds 5"), ([0, 1], "a slice or an index"), (True, "slice")):
        with pytest.raises(EventDataError, match=match):
            read_log_intensity(path, frames=bad)


def test_a_resumed_run_writes_the_whole_file(tmp_path, monkeypatch):
    """Stopped after two windows and resumed with --resume, a streamed run's log_intensity.h5 holds every frame,
    the same as a run never stopped (the finished windows' frames come back from the resume folder's spill)."""
    from evinr_lite.method.streaming import StreamState
    from test_streaming import recording_file, stop_command_after

    path = recording_file(tmp_path / "rec.h5")                            # 10 s: several windows
    quiet = dict(fps=5, video=False, progress=False, save_log=True, log=lambda *a: None)
    run_reconstruct(path, tmp_path / "whole", **quiet)
    save = stop_command_after(monkeypatch, 2)
    with pytest.raises(KeyboardInterrupt):
        run_reconstruct(path, tmp_path / "out", **quiet)
    monkeypatch.setattr(StreamState, "save", save)
    run_reconstruct(path, tmp_path / "out", **quiet, resume=True)
    whole, t_whole, _ = read_log_intensity(tmp_path / "whole" / LOG_INTENSITY_FILE)
    resumed, t_resumed, _ = read_log_intensity(tmp_path / "out" / LOG_INTENSITY_FILE)
    assert whole.shape[0] >= 45 and np.array_equal(t_whole, t_resumed)
    np.testing.assert_allclose(resumed, whole, atol=1e-5)
