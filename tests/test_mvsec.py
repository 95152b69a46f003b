"""The MVSEC HDF5 reader: davis/<camera>/events rows (x, y, t, p) on the ROS clock and the APS frames
read exactly, windows read from disk equal the slices of the whole file, bad files refused with the fix."""
import h5py
import numpy as np
import pytest

from evinr_lite.core.events import EventDataError
from evinr_lite.io import load_recording, open_recording
from evinr_lite.io.formats.mvsec import read_mvsec
from evinr_lite.io.formats.registry import detect_format

H, W = 26, 34
T0 = 1_504_643_000.25            # seconds on the ROS clock, as MVSEC's


def _write(path, n=5000, frames=12, camera="left", seed=0, sorted_t=True):
    rng = np.random.default_rng(seed)
    t = T0 + (np.sort(rng.uniform(0, 3, n)) if sorted_t else rng.uniform(0, 3, n))
    rows = np.stack([rng.integers(0, W, n), rng.integers(0, H, n), t, rng.choice([-1.0, 1.0], n)], 1)
    with h5py.File(path, "w") as f:
        f.create_dataset(f"davis/{camera}/events", data=rows, chunks=(min(n, 1024), 4), compression="gzip")
        if frames:
            f.create_dataset(f"davis/{camera}/image_raw", data=rng.integers(0, 255, (frames, H, W)).astype(np.uint8))
            f.create_dataset(f"davis/{camera}/image_raw_ts", data=T0 + np.linspace(0.1, 2.9, frames))
    return path, rows


def test_events_and_frames_read_exactly(tmp_path):
    path, rows = _write(tmp_path / "seq_data.hdf5")
    assert detect_format(path) == "mvsec"
    rec = read_mvsec(path)
    ev = rec.events
    assert ev.sensor_size == (H, W) and ev.t_origin == np.floor(T0)
    np.testing.assert_allclose(ev.t + ev.t_origin, rows[:, 2], rtol=0, atol=1e-6)
    np.testing.assert_array_equal(ev.x, rows[:, 0])
    np.testing.assert_array_equal(ev.p, rows[:, 3].astype(np.int8))
    with h5py.File(path) as f:
        np.testing.assert_array_equal(rec.frames.images, f["davis/left/image_raw"][()])
    np.testing.assert_allclose(rec.frames.t + ev.t_origin, T0 + np.linspace(0.1, 2.9, 12), atol=1e-6)


def test_windows_from_disk_equal_slices_of_the_whole(tmp_path):
    path, _ = _write(tmp_path / "seq_data.hdf5")
    whole = read_mvsec(path)
    t0 = whole.events.t[0] + 0.7
    part = load_recording(path, t_start=t0, t_end=t0 + 1.2)
    keep = (whole.events.t >= t0) & (whole.events.t < t0 + 1.2)
    np.testing.assert_array_equal(part.events.t, whole.events.t[keep])
    in_window = (whole.frames.t >= t0) & (whole.frames.t <= t0 + 1.2)
    np.testing.assert_array_equal(part.frames.t, whole.frames.t[in_window])
    with open_recording(path) as source:
        np.testing.assert_array_equal(source.events(t0, t0 + 1.2).t, whole.events.t[keep])


def test_the_right_camera_alone_is_found(tmp_path):
    path, rows = _write(tmp_path / "right.hdf5", camera="right")
    assert detect_format(path) == "mvsec"
    assert len(read_mvsec(path).events.t) == len(rows)
    with pytest.raises(EventDataError, match=r"no davis/left/events.*pass camera='right'"):
        read_mvsec(path, camera="left")


def test_sensor_size_comes_from_the_frames_or_is_asked_for(tmp_path):
    path, _ = _write(tmp_path / "seq.hdf5")
    with pytest.raises(EventDataError, match=r"image_raw's frame size says the sensor is \(H, W\) = \(26, 34\)"):
        read_mvsec(path, (H + 1, W))
    bare, _ = _write(tmp_path / "bare.hdf5", frames=0)
    with pytest.raises(EventDataError, match=r"no davis/left/image_raw frames.*\(260, 346\)"):
        read_mvsec(bare)
    assert read_mvsec(bare, (H, W)).frames is None


@pytest.mark.parametrize("edit, message", [
    (lambda f: f.__delitem__("davis/left/image_raw_ts") or f.create_dataset("davis/left/image_raw_ts", data=[T0]),
     r"holds 12 frames but image_raw_ts 1 times"),
    (lambda f: f.__delitem__("davis/left/events") or f.create_dataset("davis/left/events", data=np.zeros((5, 3))),
     r"no davis/left/events dataset of rows \(x, y, t, p\)"),
])
def test_damaged_files_are_refused(tmp_path, edit, message):
    path, _ = _write(tmp_path / "bad.hdf5")
    with h5py.File(path, "r+") as f:
        edit(f)
    with pytest.raises(EventDataError, match=message):
        read_mvsec(path, (H, W))


def test_unsorted_times_are_refused_for_a_window(tmp_path):
    path, _ = _write(tmp_path / "unsorted.hdf5", sorted_t=False)
    with pytest.raises(EventDataError, match=r"not sorted"):
        read_mvsec(path, t_start=0.5, t_end=1.0)


def test_reconstruct_scores_against_the_aps_frames(tmp_path):
    """The command end to end: a window of an MVSEC file, scored against its APS frames (metrics.json)."""
    import json
    import subprocess
    import sys

    path, _ = _write(tmp_path / "seq_data.hdf5")
    out = tmp_path / "rec"
    run = subprocess.run([sys.executable, "-m", "evinr_lite", "reconstruct", str(path), "--start", "0.5", "--end",
                          "2.5", "--out", str(out), "--quiet", "--no-video"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    metrics = json.loads(next(out.glob("**/metrics.json")).read_text())
    stamps = T0 + np.linspace(0.1, 2.9, 12) - np.floor(T0)          # the APS frames on the returned clock
    inside = stamps[(stamps >= 0.5) & (stamps <= 2.5)]
    np.testing.assert_allclose(metrics["per_frame"]["none"]["per_frame_t_s"], inside, atol=1e-6)


def _write_stereo(path):
    """Both cameras of a stereo file, each at its own sensor size and frame count, so that a reader of the
    wrong one is seen at once."""
    rng = np.random.default_rng(3)
    with h5py.File(path, "w") as f:
        for camera, (h, w), n_frames in (("left", (H, W), 12), ("right", (H + 4, W - 6), 7)):
            n = 4000
            t = T0 + np.sort(rng.uniform(0, 3, n))
            rows = np.stack([rng.integers(0, w, n), rng.integers(0, h, n), t, rng.choice([-1.0, 1.0], n)], 1)
            f.create_dataset(f"davis/{camera}/events", data=rows)
            f.create_dataset(f"davis/{camera}/image_raw", data=rng.integers(0, 255, (n_frames, h, w)).astype(np.uint8))
            f.create_dataset(f"davis/{camera}/image_raw_ts", data=T0 + np.linspace(0.1, 2.9, n_frames))
    return path


def _cli(*args):
    import subprocess
    import sys

    return subprocess.run([sys.executable, "-m", "evinr_lite", *map(str, args)], capture_output=True, text=True)


def test_the_camera_flag_picks_a_stereo_files_camera(tmp_path):
    """--camera right reads davis/right (its own sensor size and APS frames) in info and reconstruct; the default
    stays the left camera; load_recording and open_recording take the same camera=."""
    import json

    path = _write_stereo(tmp_path / "stereo_data.hdf5")
    assert load_recording(path).events.sensor_size == (H, W)
    assert load_recording(path, camera="right").events.sensor_size == (H + 4, W - 6)
    with open_recording(path, camera="right") as source:
        assert source.sensor_size == (H + 4, W - 6)
    info = _cli("info", path, "--camera", "right", "--json")
    assert info.returncode == 0, info.stderr
    assert json.loads(info.stdout)["sensor_size"] == [H + 4, W - 6]
    out = tmp_path / "right"
    run = _cli("reconstruct", path, "--camera", "right", "--out", out, "--quiet", "--no-video")
    assert run.returncode == 0, run.stderr
    metrics = json.loads(next(out.glob("**/metrics.json")).read_text())
    assert len(metrics["per_frame"]["none"]["per_frame_t_s"]) == 7            # the right camera's frames
    assert json.loads((out / "run.json").read_text())["sensor_size"] == [H + 4, W - 6]


def test_the_camera_flag_is_refused_where_it_cannot_apply(tmp_path):
    """A one-camera format refuses --camera with the fix, a stereo-less MVSEC file names the camera it has, a
    camera that MVSEC does not have is refused by the parser and by RunOptions, and a batch refuses it."""
    from evinr_lite.apps.options import RunOptions

    npy = tmp_path / "ev.npy"
    np.save(npy, np.stack([np.linspace(0, 1, 50), np.arange(50) % 8, np.arange(50) % 6, np.ones(50)], 1))
    run = _cli("info", npy, "--sensor", "6x8", "--camera", "right")
    assert run.returncode == 2 and "--camera right cannot apply" in run.stderr and "leave --camera out" in run.stderr, run.stderr
    path, _ = _write(tmp_path / "left_only.hdf5")
    run = _cli("reconstruct", path, "--camera", "right", "--out", tmp_path / "o", "--quiet")
    assert run.returncode == 2 and "--camera left" in run.stderr, run.stderr
    assert not (tmp_path / "o").exists()
    run = _cli("info", path, "--camera", "middle")
    assert run.returncode == 2 and "invalid choice" in run.stderr
    with pytest.raises(EventDataError, match="camera= must be one of"):
        RunOptions(camera="middle")
    with pytest.raises(EventDataError, match="camera="):
        RunOptions(camera="right").check_batch()
