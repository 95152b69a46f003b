"""Readers: every format round-trips known values; bad input fails with a message naming the fix."""
import json

import h5py
import numpy as np
import pytest
from skimage.io import imsave

from evinr_lite.core.events import EventDataError, Events
from evinr_lite.core.recording import Recording
from evinr_lite.io.readers import (read_events, read_events_npy, read_events_txt, read_evreal_folder, read_frames_ijrr, read_h5, read_ijrr_folder, read_recording)

# Five events on a 3 x 5 sensor (H = 3 rows, W = 5 columns); p written as 0/1.
T = ["0.000100000", "0.000250000", "0.000250000", "0.001000001", "0.002500000"]
X = [0, 4, 2, 1, 3]
Y = [0, 2, 1, 2, 0]
P01 = [1, 0, 0, 1, 1]
PM1 = [1, -1, -1, 1, 1]


def write_txt(path, rows, header=None):
    lines = ([header] if header else []) + [" ".join(str(v) for v in row) for row in rows]
    path.write_text("\n".join(lines) + "\n")
    return path


def write_png(path, image):
    path.parent.mkdir(parents=True, exist_ok=True)
    imsave(path, image, check_contrast=False)


def check_small_events(ev, t_origin=0.0):
    np.testing.assert_array_equal(ev.t, [float(s) for s in T])
    np.testing.assert_array_equal(ev.x, X)
    np.testing.assert_array_equal(ev.y, Y)
    np.testing.assert_array_equal(ev.p, PM1)
    assert ev.p.dtype == np.int8
    assert ev.sensor_size == (3, 5)
    assert ev.t_origin == t_origin


@pytest.fixture
def small_txt(tmp_path):
    return write_txt(tmp_path / "events.txt", zip(T, X, Y, P01))


# ---- text ---------------------------------------------------------------------------------

def test_txt_round_trip(small_txt):
    check_small_events(read_events_txt(small_txt, (3, 5)))


def test_txt_header_gives_sensor_size_width_first(tmp_path):
    path = write_txt(tmp_path / "e2vid.txt", zip(T, X, Y, P01), header="5 3")
    check_small_events(read_events_txt(path))
    check_small_events(read_events_txt(path, sensor_size=(3, 5)))  # agreeing argument is fine


def test_txt_header_disagreeing_with_argument(tmp_path):
    path = write_txt(tmp_path / "e2vid.txt", zip(T, X, Y, P01), header="5 3")
    with pytest.raises(EventDataError, match=r"header line `5 3`.*\(3, 5\).*sensor_size=\(5, 3\) was passed"):
        read_events_txt(path, sensor_size=(5, 3))


def test_txt_without_sensor_size(small_txt):
    with pytest.raises(EventDataError, match=r"pass sensor_size=\(H, W\).*smallest sensor that fits is \(3, 5\)"):
        read_events_txt(small_txt)


def test_txt_wrong_column_count(tmp_path):
    path = tmp_path / "events.txt"
    path.write_text("0.1 1 2 0\n0.2 1 2 1\n0.3 1 2\n0.4 1 2 1\n")
    with pytest.raises(EventDataError, match=r"line 3: found 3 columns, expected 4: `t x y p`"):
        read_events_txt(path, (3, 5))
    path.write_text("0.1 1 2 0\n5 3\n")
    with pytest.raises(EventDataError, match=r"line 2: .*header is allowed only as the first line"):
        read_events_txt(path, (3, 5))


def test_txt_blank_lines_and_crlf(tmp_path):
    path = tmp_path / "events.txt"
    path.write_bytes(b"\r\n".join(" ".join(map(str, row)).encode() for row in zip(T, X, Y, P01)) + b"\r\n\r\n")
    check_small_events(read_events_txt(path, (3, 5)))


def test_absolute_timestamps_keep_nanoseconds(tmp_path):
    a, b = "1468939802.123456789", "1468939802.123457789"
    # float64 cannot tell these apart at 1e-12: the naive parse is off by ~1e-7.
    assert abs((float(b) - float(a)) - 1e-6) > 1e-12
    path = write_txt(tmp_path / "events.txt", [(a, 1, 2, 0), (b, 3, 1, 1)])
    ev = read_events_txt(path, (3, 5))
    assert ev.t_origin == 1468939802.0
    assert abs((ev.t[1] - ev.t[0]) - 1e-6) < 1e-12
    assert abs(ev.t[0] - 0.123456789) < 1e-15
    # an explicit origin is honoured, still exactly
    ev = read_events_txt(path, (3, 5), t_origin=1468939800)
    assert ev.t_origin == 1468939800.0
    assert abs(ev.t[0] - 2.123456789) < 1e-14
    assert abs((ev.t[1] - ev.t[0]) - 1e-6) < 1e-12


def test_small_timestamps_have_zero_origin(small_txt):
    assert read_events_txt(small_txt, (3, 5)).t_origin == 0.0


@pytest.mark.parametrize("lines, message", [
    (["0.2 1 1 1", "0.1 1 1 0"], r"line 2: the timestamp is earlier .* not sorted by time"),
    (["0.1 1 1 1", "nan 1 1 0"], r"line 2: the timestamp is not finite"),
    (["0.1 1 1 1", "0.2 5 1 0"], r"x \(column, width W\) coordinates span \[1, 5\].*\(3, 5\)"),
    (["0.1 1 1 1", "0.2 1 3 0"], r"y \(row, height H\) coordinates span \[1, 3\]"),
    (["0.1 1 1 1", "0.2 1 1 2"], r"polarity values \{1, 2\} are neither -1/\+1 nor 0/1"),
    (["0.1 1 1 -1", "0.2 1 1 0", "0.3 1 1 1"], r"polarity values \{-1, 0, 1\} are neither"),
    (["0.1 1 1 1", "0.2 1.5 1 0"], r"line 2: x must be a whole pixel index"),
    (["0.1 1 1 1", "0.2s 1 1 0"], r"line 2: the timestamp is not a number; expected `t x y p`"),
    (["0.1 1 1 1", "0.2 1 one 0"], r"line 2: y is not a number"),
])
def test_txt_bad_input(tmp_path, lines, message):
    path = write_txt(tmp_path / "bad.txt", [line.split() for line in lines])
    with pytest.raises(EventDataError, match=message):
        read_events_txt(path, (3, 5))


def test_txt_empty(tmp_path):
    path = tmp_path / "events.txt"
    path.write_text("\n")
    with pytest.raises(EventDataError, match="is empty"):
        read_events_txt(path, (3, 5))


def test_txt_many_chunks(tmp_path, monkeypatch):
    """Chunked parsing: line numbers and sortedness are tracked across chunk boundaries."""
    import evinr_lite.io.text as readers

    monkeypatch.setattr(readers, "CHUNK_BYTES", 64)
    n = 200
    t_ns = 1468939802_000000000 + np.arange(n) * 1234
    rows = [(f"{v // 10**9}.{v % 10**9:09d}", i % 5, i % 3, i % 2) for i, v in enumerate(t_ns)]
    path = write_txt(tmp_path / "events.txt", rows)
    ev = read_events_txt(path, (3, 5))
    np.testing.assert_array_equal(ev.t, np.arange(n) * 1234 / 1e9)
    np.testing.assert_array_equal(ev.x, np.arange(n) % 5)
    for i in (150, 151):  # 27-byte lines, two per chunk: inside a chunk, then across a boundary
        swapped = rows[:i] + [rows[i + 1], rows[i]] + rows[i + 2:]
        write_txt(path, swapped)
        with pytest.raises(EventDataError, match=f"line {i + 2}: the timestamp is earlier"):
            read_events_txt(path, (3, 5))


# ---- IJRR folders -------------------------------------------------------------------------

def make_ijrr_folder(folder, event_times, frame_times, rgb=False):
    folder.mkdir()
    write_txt(folder / "events.txt", [(t, i % 5, i % 3, i % 2) for i, t in enumerate(event_times)])
    lines = []
    for i, t in enumerate(frame_times):
        image = np.full((3, 5), 40 * i, np.uint8)
        image[1, 2] = 255
        write_png(folder / "images" / f"frame_{i:08d}.png", np.stack([image] * 3, -1) if rgb else image)
        lines.append(f"{t} images/frame_{i:08d}.png")
    (folder / "images.txt").write_text("\n".join(lines) + "\n")
    (folder / "calib.txt").write_text("335.4 335.3 129.9 99.2 -0.1 0.09 -0.0003 0.0002 0.0\n")
    return folder


def test_ijrr_folder_frames_share_the_origin(tmp_path):
    folder = make_ijrr_folder(tmp_path / "seq", ["1468939802.123456789", "1468939802.123457789"],
                              ["1468939802.100000001", "1468939802.200000000"])
    rec = read_ijrr_folder(folder)
    assert isinstance(rec, Recording)
    assert rec.events.t_origin == rec.frames.t_origin == 1468939802.0
    assert abs(rec.frames.t[0] - 0.100000001) < 1e-15
    assert abs((rec.events.t[0] - rec.frames.t[0]) - 0.023456788) < 1e-12
    assert rec.events.sensor_size == rec.frames.size == (3, 5)
    np.testing.assert_array_equal(rec.events.p, [-1, 1])
    assert rec.frames.images.dtype == np.uint8
    assert rec.frames.images[1, 0, 0] == 40 and rec.frames.images[1, 1, 2] == 255
    assert rec.meta["format"] == "ijrr" and rec.meta["path"] == str(folder)
    assert rec.meta["calib"]["fx"] == 335.4 and rec.meta["calib"]["k3"] == 0.0
    # the frames alone, on the same origin
    frames = read_frames_ijrr(folder, t_origin=rec.events.t_origin)
    np.testing.assert_array_equal(frames.t, rec.frames.t)


def test_ijrr_rgb_frames_become_grey(tmp_path):
    folder = make_ijrr_folder(tmp_path / "seq", ["0.1", "0.2"], ["0.0", "0.15"], rgb=True)
    frames = read_ijrr_folder(folder).frames
    assert frames.images.shape == (2, 3, 5) and frames.images.dtype == np.uint8
    assert frames.images[1, 0, 0] == 40 and frames.images[1, 1, 2] == 255


def test_ijrr_missing_frame_file(tmp_path):
    folder = make_ijrr_folder(tmp_path / "seq", ["0.1", "0.2"], ["0.0", "0.15"])
    (folder / "images" / "frame_00000001.png").unlink()
    with pytest.raises(EventDataError, match="lists frame_00000001.png, but .* does not exist"):
        read_ijrr_folder(folder)


def test_real_slider_depth(slider_depth_dir):
    rec = read_ijrr_folder(slider_depth_dir)
    ev, frames = rec.events, rec.frames
    assert len(ev) == 50000
    assert ev.sensor_size == (180, 240)
    assert ev.t_origin == 0.0
    assert abs(ev.t[0] - 0.003811) < 1e-12 and abs(ev.t[-1] - 0.174156) < 1e-12
    assert np.all(np.diff(ev.t) >= 0)
    assert set(np.unique(ev.p).tolist()) == {-1, 1}
    assert len(frames) == 6 and frames.size == (180, 240) and frames.images.dtype == np.uint8
    assert frames.t[0] == 0.0 and abs(frames.t[-1] - 0.193827) < 1e-12
    assert abs(rec.meta["calib"]["fx"] - 335.419462958) < 1e-9
    # read_recording detects the folder
    assert len(read_events(slider_depth_dir)) == 50000


# ---- npy ----------------------------------------------------------------------------------

def test_npy_round_trip(tmp_path):
    path = tmp_path / "events.npy"
    np.save(path, np.stack([[float(s) for s in T], X, Y, P01], axis=1))
    check_small_events(read_events_npy(path, (3, 5)))


def test_npy_columns_and_integer_microseconds(tmp_path):
    t_us = np.array([1468939802_123456, 1468939802_123457, 1468939803_000000], dtype=np.int64)
    path = tmp_path / "events.npy"
    np.save(path, np.stack([[1, 2, 3], [0, 1, 2], t_us, [-1, 1, 1]], axis=1))  # columns x y t p
    ev = read_events_npy(path, (3, 5), columns="xytp", time_unit="us")
    assert ev.t_origin == 1468939802.0
    np.testing.assert_array_equal(ev.t, [0.123456, 0.123457, 1.0])
    np.testing.assert_array_equal(ev.x, [1, 2, 3])
    np.testing.assert_array_equal(ev.y, [0, 1, 2])
    np.testing.assert_array_equal(ev.p, [-1, 1, 1])


def test_npy_sort(tmp_path):
    path = tmp_path / "events.npy"
    np.save(path, np.array([[0.2, 1, 1, 1], [0.1, 2, 2, 0]]))
    with pytest.raises(EventDataError, match="not sorted.*sort=True"):
        read_events_npy(path, (3, 5))
    ev = read_events_npy(path, (3, 5), sort=True)
    np.testing.assert_array_equal(ev.t, [0.1, 0.2])
    np.testing.assert_array_equal(ev.x, [2, 1])


def test_npy_wrong_shape(tmp_path):
    path = tmp_path / "events.npy"
    np.save(path, np.zeros((5, 3)))
    with pytest.raises(EventDataError, match=r"shape \[N, 4\] with columns t x y p.*got shape \(5, 3\)"):
        read_events_npy(path, (3, 5))


def test_npy_without_sensor_size(tmp_path):
    path = tmp_path / "events.npy"
    np.save(path, np.stack([[float(s) for s in T], X, Y, P01], axis=1))
    with pytest.raises(EventDataError, match=r"pass sensor_size=\(H, W\).*fits is \(3, 5\)"):
        read_events_npy(path)


# ---- EVREAL -------------------------------------------------------------------------------

def make_evreal_folder(folder):
    folder.mkdir()
    np.save(folder / "events_ts.npy", np.array([float(s) for s in T]))
    np.save(folder / "events_xy.npy", np.stack([X, Y], axis=1).astype(np.int16))
    np.save(folder / "events_p.npy", np.array(P01, dtype=np.uint8))
    images = np.arange(2 * 3 * 5, dtype=np.uint8).reshape(2, 3, 5, 1)
    np.save(folder / "images.npy", images)
    np.save(folder / "images_ts.npy", np.array([0.0, 0.002]))
    np.save(folder / "image_event_indices.npy", np.array([0, 4]))
    (folder / "metadata.json").write_text(json.dumps({"sensor_resolution": [3, 5]}))
    return folder, images


def test_evreal_round_trip(tmp_path):
    folder, images = make_evreal_folder(tmp_path / "seq")
    rec = read_evreal_folder(folder)
    check_small_events(rec.events)
    np.testing.assert_array_equal(rec.frames.images, images[..., 0])
    np.testing.assert_array_equal(rec.frames.t, [0.0, 0.002])
    np.testing.assert_array_equal(rec.meta["image_event_indices"], [0, 4])
    assert rec.meta["format"] == "evreal"


def test_evreal_missing_file(tmp_path):
    folder, _ = make_evreal_folder(tmp_path / "seq")
    (folder / "metadata.json").unlink()
    with pytest.raises(EventDataError, match="missing metadata.json"):
        read_evreal_folder(folder)


# ---- HQF-style h5 -------------------------------------------------------------------------

def make_h5(path, ts, frame_times, t_offset=0.0):
    rng = np.random.default_rng(0)
    n = len(ts)
    chunks = (min(64, n),)  # small chunks: a window read touches only a few
    xs, ys = rng.integers(0, 5, n).astype(np.int16), rng.integers(0, 3, n).astype(np.int16)
    ps = rng.integers(0, 2, n).astype(bool)
    with h5py.File(path, "w") as f:
        f.attrs["sensor_resolution"] = (3, 5)
        f.create_dataset("events/xs", data=xs, chunks=chunks)
        f.create_dataset("events/ys", data=ys, chunks=chunks)
        f.create_dataset("events/ts", data=np.asarray(ts) + t_offset, chunks=chunks)
        f.create_dataset("events/ps", data=ps, chunks=chunks)
        for i, t in enumerate(frame_times):
            d = f.create_dataset(f"images/image{i:09d}", data=np.full((3, 5), i, np.uint8))
            d.attrs["timestamp"] = t + t_offset
            d.attrs["event_idx"] = i
    return xs, ys, ps


def test_h5_round_trip_with_frames_out_of_order(tmp_path):
    path = tmp_path / "seq.h5"
    ts = np.sort(np.random.default_rng(1).integers(0, 1000, 500)) / 1000
    xs, ys, ps = make_h5(path, ts, frame_times=[0.3, 0.1, 0.2])
    rec = read_h5(path)
    np.testing.assert_array_equal(rec.events.t, ts)
    np.testing.assert_array_equal(rec.events.x, xs)
    np.testing.assert_array_equal(rec.events.y, ys)
    np.testing.assert_array_equal(rec.events.p, np.where(ps, 1, -1))
    assert rec.events.sensor_size == (3, 5) and rec.events.t_origin == 0.0
    np.testing.assert_array_equal(rec.frames.t, [0.1, 0.2, 0.3])
    np.testing.assert_array_equal(rec.frames.images[:, 0, 0], [1, 2, 0])
    np.testing.assert_array_equal(rec.meta["frame_event_idx"], [1, 2, 0])
    assert rec.meta["format"] == "h5"


@pytest.mark.parametrize("t_offset", [0.0, 1500000000.0])
def test_h5_window_reads_only_the_slice(tmp_path, monkeypatch, t_offset):
    path = tmp_path / "seq.h5"
    ts = np.sort(np.random.default_rng(2).integers(0, 1000, 500)) / 1000  # many duplicate times
    xs, ys, ps = make_h5(path, ts, frame_times=[0.3, 0.1, 0.2, 0.6], t_offset=t_offset)
    reads = []
    getitem = h5py.Dataset.__getitem__

    def spy(self, args, *rest, **kwargs):
        out = getitem(self, args, *rest, **kwargs)
        if self.name.startswith("/events/"):
            reads.append(np.size(out))
        return out

    monkeypatch.setattr(h5py.Dataset, "__getitem__", spy)
    rel = (ts + t_offset) - t_offset  # the stored float64 times on the returned clock
    dup = np.flatnonzero(np.diff(rel) == 0)  # window edges on duplicated timestamps
    t_start, t_end = rel[dup[dup >= 100][0]], rel[dup[dup >= 300][0]]
    rec = read_h5(path, t_start=t_start, t_end=t_end)
    keep = (rel >= t_start) & (rel < t_end)
    assert rec.events.t_origin == t_offset
    np.testing.assert_array_equal(rec.events.t, rel[keep])
    np.testing.assert_array_equal(rec.events.x, xs[keep])
    np.testing.assert_array_equal(rec.events.y, ys[keep])
    np.testing.assert_array_equal(rec.events.p, np.where(ps[keep], 1, -1))
    assert max(reads) == keep.sum() < len(ts)  # never read the whole dataset
    frame_rel = np.sort((np.array([0.3, 0.1, 0.2, 0.6]) + t_offset) - t_offset)
    np.testing.assert_array_equal(rec.frames.t, frame_rel[(frame_rel >= t_start) & (frame_rel < t_end)])


def test_h5_empty_window(tmp_path):
    path = tmp_path / "seq.h5"
    make_h5(path, np.linspace(0, 1, 50), frame_times=[0.5])
    with pytest.raises(EventDataError, match=r"no events in the window \[2.0, 3.0\).*choose a window"):
        read_h5(path, t_start=2.0, t_end=3.0)


# ---- read_recording -----------------------------------------------------------------------

def test_read_recording_detects_formats(tmp_path, small_txt):
    assert read_recording(small_txt, sensor_size=(3, 5)).meta == {"format": "txt", "path": str(small_txt)}
    npy = tmp_path / "events.npy"
    np.save(npy, np.stack([[float(s) for s in T], X, Y, P01], axis=1))
    rec = read_recording(npy, sensor_size=(3, 5))
    assert rec.meta["format"] == "npy" and rec.frames is None
    check_small_events(rec.events)
    folder, _ = make_evreal_folder(tmp_path / "evreal")
    assert read_recording(folder).meta["format"] == "evreal"
    h5 = tmp_path / "seq.hdf5"
    make_h5(h5, np.linspace(0, 1, 50), frame_times=[0.5])
    assert read_recording(h5).meta["format"] == "h5"
    ijrr = make_ijrr_folder(tmp_path / "ijrr", ["0.1", "0.2"], ["0.0", "0.15"])
    assert read_recording(ijrr).meta["format"] == "ijrr"
    assert isinstance(read_events(ijrr), Events)


def test_read_recording_unknown_format(tmp_path):
    path = tmp_path / "events.xyz"
    path.write_text("0.1,1,1,1\n")
    with pytest.raises(EventDataError, match=r"unknown format '.xyz'.*supported formats: an IJRR folder"):
        read_recording(path)
    with pytest.raises(EventDataError, match=r"folder of unknown format.*supported formats"):
        read_recording(tmp_path)


def test_read_recording_missing_path(tmp_path):
    with pytest.raises(EventDataError, match=r"no such file or folder: .*nothing\.h5"):
        read_recording(tmp_path / "nothing.h5")
    with pytest.raises(EventDataError, match=r"no such file: .*nothing\.txt"):
        read_events_txt(tmp_path / "nothing.txt", (3, 5))


def test_a_metavision_hdf5_file_names_the_conversion(tmp_path):
    """Metavision SDK 4+ writes CD/events (a compound dataset, ECF-compressed), which the kit does not
    decode: the error names the format and the conversion, not the HQF datasets it lacks."""
    import h5py

    path = tmp_path / "recording.hdf5"
    dtype = np.dtype([("x", "<u2"), ("y", "<u2"), ("p", "<i2"), ("t", "<i8")])
    with h5py.File(path, "w") as f:
        f.create_dataset("CD/events", data=np.zeros(4, dtype))
    with pytest.raises(EventDataError, match=r"Prophesee Metavision HDF5 file.*metavision_file_to_dat"):
        read_recording(path)


def test_a_ros_bag_names_the_conversion(tmp_path):
    from evinr_lite.io.formats import sniff_format

    path = tmp_path / "recording.bag"
    path.write_bytes(b"#ROSBAG V2.0\n" + bytes(64))
    assert sniff_format(path) == "rosbag"
    with pytest.raises(EventDataError, match=r"a ROS1 bag.*python -m data_fetch convert"):
        read_recording(path)


def test_an_ijrr_folder_missing_its_images_says_how_many_and_the_fixes(tmp_path):
    import shutil

    from evinr_lite.io import read_recording
    from evinr_lite.io.sample_data import find_shared_data

    data = find_shared_data()
    src = None if data is None else data / "ijrr_slider_depth_chunk"
    if src is None or not src.is_dir():
        pytest.skip("the shared slider_depth chunk is not here")
    folder = tmp_path / "chunk"
    shutil.copytree(src, folder)
    (folder / "images" / "frame_00000003.png").unlink()
    with pytest.raises(EventDataError, match=r"frame_00000003\.png does not exist.*copy the images back.*--sensor"):
        read_recording(folder)
    shutil.rmtree(folder / "images")
    with pytest.raises(EventDataError, match=r"6 of its 6 frames are missing"):
        read_recording(folder)
    (folder / "images.txt").rename(tmp_path / "images.txt")        # the last fix the message gives
    assert read_recording(folder, sensor_size=(180, 240)).frames is None
