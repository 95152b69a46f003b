"""AEDAT4 and Prophesee readers, on files written by maintained writers (faery; dv-processing for
AEDAT4 frame tracks), compared value by value; and format detection by content."""
import numpy as np
import pytest

faery = pytest.importorskip("faery")

from evinr_lite import EventDataError, read_recording  # noqa: E402
from evinr_lite.io.formats import read_aedat4, read_prophesee, sniff_format  # noqa: E402
from evinr_lite.io.readers import SUPPORTED_FORMATS, detect_format  # noqa: E402

H, W = 30, 40
T0_US = 1_600_000_123_456_789   # an absolute clock in microseconds (2020), not on a whole second


def _packet(n=2000, seed=0, t0_us=T0_US, span_us=2_000_000):
    rng = np.random.default_rng(seed)
    ev = np.zeros(n, dtype=faery.EVENTS_DTYPE)
    ev["t"] = np.sort(rng.integers(t0_us, t0_us + span_us, n)).astype(np.uint64)
    ev["x"] = rng.integers(0, W, n)
    ev["y"] = rng.integers(0, H, n)
    ev["on"] = rng.random(n) < 0.4
    return ev


def _write(path, ev, version=None):
    faery.events_stream_from_array(ev, dimensions=(W, H)).to_file(path, version=version)
    return path


def _assert_same(events, ev):
    """Events (seconds since a whole-second t_origin) hold exactly the microsecond packet ev."""
    assert events.sensor_size == (H, W)
    assert events.t_origin == float(int(ev["t"][0]) // 10**6)          # whole seconds
    us = np.round(events.t * 1e6).astype(np.int64) + int(events.t_origin) * 10**6
    np.testing.assert_array_equal(us, ev["t"].astype(np.int64))
    np.testing.assert_array_equal(events.x, ev["x"])
    np.testing.assert_array_equal(events.y, ev["y"])
    np.testing.assert_array_equal(events.p, np.where(ev["on"], 1, -1))


@pytest.mark.parametrize("name,version", [("rec.aedat4", None), ("rec.raw", "evt3"), ("rec.raw", "evt2"),
                                          ("rec.dat", None)])
def test_round_trip_through_maintained_writer(tmp_path, name, version):
    ev = _packet()
    path = _write(tmp_path / name, ev, version)
    rec = read_recording(path)
    _assert_same(rec.events, ev)
    assert rec.frames is None
    assert rec.meta["format"] == detect_format(path) == {"aedat4": "aedat4", "raw": "prophesee_raw",
                                                         "dat": "prophesee_dat"}[name.split(".")[1]]
    if version:
        assert rec.meta["encoding"] == version


def test_window_reads_only_the_window(tmp_path):
    ev = _packet()
    full = read_aedat4(_write(tmp_path / "rec.aedat4", ev)).events
    lo, hi = 0.6, 1.3
    part = read_aedat4(tmp_path / "rec.aedat4", t_start=lo, t_end=hi).events
    expected = full.slice_time(lo, hi)
    assert 0 < len(part) < len(full)
    np.testing.assert_array_equal(part.t, expected.t)
    np.testing.assert_array_equal(part.x, expected.x)
    raw = read_prophesee(_write(tmp_path / "rec.raw", ev, "evt3"), t_start=lo, t_end=hi).events
    np.testing.assert_array_equal(raw.t, expected.t)
    with pytest.raises(EventDataError, match=r"no events in the window \[50, 60\).*cover \[0\.\d+, 2\.\d+\] s"):
        read_aedat4(tmp_path / "rec.aedat4", t_start=50, t_end=60)
    with pytest.raises(EventDataError, match=r"empty or reversed"):
        read_prophesee(tmp_path / "rec.raw", t_start=1.0, t_end=0.5)


def test_aedat4_frames_from_dv_processing(tmp_path):
    dv = pytest.importorskip("dv_processing")
    ev = _packet(500)
    path = tmp_path / "davis.aedat4"
    config = dv.io.MonoCameraWriter.Config("DAVIS346")
    config.addEventStream((W, H))
    config.addFrameStream((W, H))
    writer = dv.io.MonoCameraWriter(str(path), config)
    store = dv.EventStore()
    for t, x, y, on in ev:
        store.push_back(int(t), int(x), int(y), bool(on))
    writer.writeEvents(store)
    rng = np.random.default_rng(1)
    frame_us = [T0_US + 100_000, T0_US + 900_000, T0_US + 1_700_000]
    images = [rng.integers(0, 256, (H, W), dtype=np.uint8) for _ in frame_us]
    for t, img in zip(frame_us, images):
        writer.writeFrame(dv.Frame(t, img))
    del writer  # closes the file
    rec = read_recording(path)
    _assert_same(rec.events, ev)
    assert rec.frames is not None and len(rec.frames) == 3
    assert rec.frames.t_origin == rec.events.t_origin
    np.testing.assert_array_equal(np.round(rec.frames.t * 1e6).astype(np.int64) + int(rec.frames.t_origin) * 10**6,
                                  frame_us)
    np.testing.assert_array_equal(rec.frames.images, np.stack(images))
    windowed = read_aedat4(path, t_start=0.8, t_end=1.5)   # frames at 0.557, 1.357, 2.157 s
    assert len(windowed.frames) == 1 and np.array_equal(windowed.frames.images[0], images[1])
    from evinr_lite.io import open_recording

    with open_recording(path) as src:   # the streaming source: the same frames, on the same clock
        np.testing.assert_array_equal(src.frames.t, rec.frames.t)
        np.testing.assert_array_equal(src.frames.images, rec.frames.images)
        assert src.n_events == len(rec.events) and src.t_origin == rec.events.t_origin
        loaded = src.load(0.8, 1.5)
        assert len(loaded.frames) == 1 and np.array_equal(loaded.frames.images[0], images[1])
        np.testing.assert_array_equal(loaded.events.t, windowed.events.t)


def test_raw_without_size_needs_sensor_size(tmp_path):
    ev = _packet(300, t0_us=0)
    data = _write(tmp_path / "with.raw", ev, "evt2").read_bytes()
    body = data[data.index(b"% t0"):]
    body = body[body.index(b"\n") + 1:]
    bare = tmp_path / "bare.raw"
    bare.write_bytes(b"% evt 2.0\n" + body)    # the header names the encoding but not the size
    with pytest.raises(EventDataError, match=r"does not give the sensor size.*sensor_size=\(H, W\)"):
        read_recording(bare)
    rec = read_recording(bare, sensor_size=(H, W))
    assert rec.events.sensor_size == (H, W) and rec.meta["sensor_size_from"] == "sensor_size argument"
    np.testing.assert_array_equal(rec.events.x, ev["x"])
    evt21 = tmp_path / "evt21.raw"   # EVT 2.0 words under an EVT 2.1 header (io/formats/evt21.py): a clear error
    evt21.write_bytes(b"% evt 2.1\n% geometry 40x30\n" + body)
    with pytest.raises(EventDataError, match=r"evt21\.raw: its header says EVT 2.1 but .* fit EVT 2.1 under neither"):
        read_recording(evt21)
    with pytest.raises(EventDataError, match=r"events lie outside the sensor size \(30, 10\).*real sensor size"):
        read_recording(bare, sensor_size=(H, 10))


def test_sensor_size_that_disagrees_with_the_file(tmp_path):
    path = _write(tmp_path / "rec.aedat4", _packet(50))
    with pytest.raises(EventDataError, match=r"sensor is \(H, W\) = \(30, 40\).*\(40, 30\) was given"):
        read_aedat4(path, sensor_size=(W, H))
    with pytest.raises(EventDataError, match=r"header says the sensor is \(H, W\) = \(30, 40\)"):
        read_prophesee(_write(tmp_path / "rec.raw", _packet(50)), sensor_size=(10, 10))


def test_detection_by_content_not_name(tmp_path):
    ev = _packet(100)
    odd = tmp_path / "recording.bin"
    _write(tmp_path / "rec.aedat4", ev)
    odd.write_bytes((tmp_path / "rec.aedat4").read_bytes())
    assert sniff_format(odd) == "aedat4" and detect_format(odd) == "aedat4"
    _assert_same(read_recording(odd).events, ev)
    raw = tmp_path / "rec.raw"
    _write(raw, ev, "evt3")
    renamed = tmp_path / "rec.events"
    renamed.write_bytes(raw.read_bytes())
    assert detect_format(renamed) == "prophesee_raw"
    text = tmp_path / "events.data"
    text.write_text("0.1 1 2 1\n0.2 3 4 0\n")
    assert detect_format(text) == "txt"


def test_unsupported_and_damaged_files(tmp_path):
    old = tmp_path / "old.aedat"
    old.write_bytes(b"#!AER-DAT3.0\r\n" + bytes(64))
    with pytest.raises(EventDataError, match=r"AEDAT 3.0 file \(not 3.1\); AEDAT 3.1 and AEDAT4 are read.*DV"):
        read_recording(old)
    junk = tmp_path / "junk.xyz"
    junk.write_bytes(bytes(range(256)))
    with pytest.raises(EventDataError, match=r"unknown format '.xyz'.*AEDAT4.*Prophesee"):
        read_recording(junk)
    assert "AEDAT4" in SUPPORTED_FORMATS and ".raw" in SUPPORTED_FORMATS
    good = _write(tmp_path / "rec.aedat4", _packet(5000)).read_bytes()
    cut = tmp_path / "cut.aedat4"
    cut.write_bytes(good[: len(good) // 2])
    with pytest.raises(EventDataError, match=r"cut\.aedat4: .*(damaged|truncated)"):
        read_recording(cut)
