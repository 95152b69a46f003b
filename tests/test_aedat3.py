"""AEDAT 3.1 files (io/formats/aedat3.py): written here from libcaer's event definitions (28-byte packet
headers, 8-byte polarity events, frame events with their exposure times and 16-bit pixels) and read back
event for event and frame for frame."""
import numpy as np
import pytest

from evinr_lite import EventDataError, read_recording
from evinr_lite.io.formats.aedat3 import DEVICE_SIZES
from evinr_lite.io.load import open_recording
from evinr_lite.io.readers import detect_format

H, W = 180, 240                      # a DAVIS240
T0_US = (1 << 31) - 400_000          # 0.4 s before the 32-bit timestamp's first overflow


def _events(n=4000, seed=0, t0=T0_US, span_us=900_000, size=(H, W)):
    rng = np.random.default_rng(seed)
    t = np.sort(rng.integers(t0, t0 + span_us, n)).astype(np.int64)
    x = rng.integers(0, size[1], n)
    y = rng.integers(0, size[0], n)
    on = rng.random(n) < 0.45
    return t, x, y, on


def _header(kind, source, size, overflow, capacity, number, valid=None):
    """libcaer's 28-byte packet header: int16 eventType, eventSource; int32 eventSize, eventTSOffset,
    eventTSOverflow, eventCapacity, eventNumber, eventValid."""
    return (np.array([kind, source], "<i2").tobytes()
            + np.array([size, 4, overflow, capacity, number, number if valid is None else valid], "<i4").tobytes())


def _polarity_packets(t, x, y, on, per_packet=700, source=1, invalid=(), spare=0, store="capacity"):
    """Packets of polarity events, split where a packet fills or the 31-bit timestamp overflows. ``spare``
    unused slots per packet (capacity > number), stored (``store='capacity'``) or not ('number')."""
    out = []
    overflow = t >> 31
    i = 0
    while i < len(t):
        j = min(i + per_packet, len(t))
        j = i + int(np.searchsorted(overflow[i:j], overflow[i], side="right"))
        data = (x[i:j].astype(np.uint32) << 17) | (y[i:j].astype(np.uint32) << 2) | (on[i:j].astype(np.uint32) << 1) | 1
        for k in invalid:                     # events marked invalid (valid bit 0)
            if i <= k < j:
                data[k - i] &= ~np.uint32(1)
        ev = np.zeros(j - i, [("data", "<u4"), ("ts", "<i4")])
        ev["data"], ev["ts"] = data, t[i:j] & 0x7FFFFFFF
        n = j - i
        body = ev.tobytes()
        if store == "capacity":
            body += np.random.default_rng(i).integers(0, 255, 8 * spare, dtype=np.uint8).tobytes()
        out.append(_header(1, source, 8, int(overflow[i]), n + spare, n, n - sum(i <= k < j for k in invalid)) + body)
        i = j
    return out


def _frame_packet(images, start_exposure, end_exposure, source=1, overflow=0, info_extra=0, position=(0, 0)):
    """One frame packet of grey 16-bit frames ``images`` [K, h, w] with their exposure times (us, < 2^31)."""
    K, h, w = images.shape
    size = 36 + 2 * h * w
    body = b""
    for k in range(K):
        fields = np.array([1 | (1 << 1) | info_extra, start_exposure[k] - 100, end_exposure[k] + 100,
                           start_exposure[k], end_exposure[k], w, h, *position], "<i4")
        body += fields.tobytes() + images[k].astype("<u2").tobytes()
    return _header(2, source, size, overflow, K, K) + body


def _file(path, packets, device="DAVIS240C", extra_lines=(), fmt="RAW", version=b"3.1"):
    lines = [b"#!AER-DAT" + version, f"#Format: {fmt}".encode()]
    if device:
        lines.append(f"#Source 1: {device}".encode())
    lines += [line.encode() for line in extra_lines]
    lines += [b"#Start-Time: 2026-12-06 10:00:00 (TZ+0000)", b"#!END-HEADER"]
    path.write_bytes(b"\r\n".join(lines) + b"\r\n" + b"".join(packets))
    return path


def _check_events(events, t, x, y, on):
    assert events.sensor_size == (H, W) and len(events) == len(t)
    t_us = np.round((events.t + events.t_origin) * 1e6).astype(np.int64)
    np.testing.assert_array_equal(t_us, t)
    np.testing.assert_array_equal(events.x, x)
    np.testing.assert_array_equal(events.y, y)
    np.testing.assert_array_equal(events.p > 0, on)


@pytest.mark.parametrize("store,spare", [("capacity", 0), ("capacity", 5), ("number", 5)])
def test_events_read_back_event_for_event_across_the_timestamp_overflow(tmp_path, store, spare):
    t, x, y, on = _events()
    assert (t >> 31).min() == 0 and (t >> 31).max() == 1        # the file crosses the overflow
    path = _file(tmp_path / "rec.aedat", _polarity_packets(t, x, y, on, spare=spare, store=store))
    assert detect_format(path) == "aedat3"
    rec = read_recording(path)
    _check_events(rec.events, t, x, y, on)
    assert rec.frames is None
    assert rec.meta["format"] == "aedat3" and rec.meta["device"] == "DAVIS240C"
    assert rec.meta["sensor_size_from"] == "device name"


def test_frames_are_read_at_the_middle_of_their_exposure(tmp_path):
    t, x, y, on = _events(t0=5_000_000)
    rng = np.random.default_rng(1)
    grey = rng.integers(0, 256, (3, H, W))
    start = np.array([5_100_000, 5_400_000, 5_700_000])
    end = start + 20_000
    packets = _polarity_packets(t, x, y, on)
    packets.insert(2, _frame_packet(grey * 257, start, end))
    path = _file(tmp_path / "davis.aedat", packets)
    rec = read_recording(path)
    _check_events(rec.events, t, x, y, on)
    assert len(rec.frames) == 3
    np.testing.assert_array_equal(rec.frames.images, grey.astype(np.uint8))
    np.testing.assert_allclose(rec.frames.t + rec.frames.t_origin, (start + 10_000) / 1e6, atol=1e-9)


def test_invalid_events_other_sources_and_other_types_are_skipped(tmp_path):
    t, x, y, on = _events(n=1500, t0=1_000_000)
    packets = _polarity_packets(t, x, y, on, invalid=(3, 700, 1400))
    imu = _header(3, 1, 36, 0, 2, 2) + bytes(72)                 # IMU6 samples of the same source
    other = _polarity_packets(t[:50], x[:50], y[:50], on[:50], source=2)   # a second camera, after the first
    roi = _frame_packet(np.zeros((1, 10, 12)), [1_200_000], [1_210_000], position=(4, 5))
    colour = _frame_packet(np.zeros((1, H, W)), [1_300_000], [1_310_000], info_extra=1 << 4)   # a Bayer filter
    path = _file(tmp_path / "mixed.aedat", [imu, packets[0], *other[:1], roi, *packets[1:], colour],
                 extra_lines=["Source 2: DVS128"])
    rec = read_recording(path)
    keep = np.ones(len(t), bool)
    keep[[3, 700, 1400]] = False
    _check_events(rec.events, t[keep], x[keep], y[keep], on[keep])
    assert rec.frames is None and rec.meta["frames_skipped"] == 2
    assert rec.meta["source"] == 1 and rec.meta["sources"] == {"1": "DAVIS240C", "2": "DVS128"}


def test_windows_and_the_streamed_source_agree_with_the_whole_file(tmp_path):
    t, x, y, on = _events(n=20000, t0=2_000_000, span_us=2_000_000)
    path = _file(tmp_path / "rec.aedat", _polarity_packets(t, x, y, on, per_packet=900))
    whole = read_recording(path).events
    part = read_recording(path, t_start=2.5, t_end=3.25).events        # seconds on the file's clock
    np.testing.assert_array_equal(part.t, whole.t[(whole.t >= 2.5) & (whole.t < 3.25)])
    with open_recording(path) as source:
        assert source.format == "aedat3" and source.n_events == len(whole)
        assert source.t_span == (whole.t[0], whole.t[-1])
        for lo, hi in [(2.1, 2.3), (2.3, 2.8), (2.8, 4.1), (2.2, 2.4)]:    # in order, then back
            got = source.events(lo, hi)
            np.testing.assert_array_equal(got.t, whole.t[(whole.t >= lo) & (whole.t < hi)])


@pytest.mark.parametrize("device,size", [("DVS128", (128, 128)), ("DAVIS346B", (260, 346)), ("DAVIS 240 C", (180, 240))])
def test_the_device_name_gives_the_sensor_size(tmp_path, device, size):
    t, x, y, on = _events(n=200, size=size)
    rec = read_recording(_file(tmp_path / "rec.aedat", _polarity_packets(t, x, y, on), device=device))
    assert rec.events.sensor_size == size
    assert set(DEVICE_SIZES) >= {"DVS128", "DAVIS240", "DAVIS346"}


def test_without_a_known_device_the_size_comes_from_the_header_or_is_needed(tmp_path):
    t, x, y, on = _events(n=200)
    packets = _polarity_packets(t, x, y, on)
    xml = ['-Source 1: <attr key="dvsSizeX" type="short">240</attr><attr key="dvsSizeY" type="short">180</attr>']
    rec = read_recording(_file(tmp_path / "xml.aedat", packets, device="", extra_lines=xml))
    assert rec.events.sensor_size == (H, W) and rec.meta["sensor_size_from"] == "header"
    bare = _file(tmp_path / "bare.aedat", packets, device="PROTOTYPE7")
    with pytest.raises(EventDataError, match=r"does not give the sensor size.*PROTOTYPE7.*sensor_size=\(H, W\)"):
        read_recording(bare)
    assert read_recording(bare, sensor_size=(H, W)).events.sensor_size == (H, W)
    with pytest.raises(EventDataError, match=r"header says the sensor is .*\(180, 240\).*\(100, 100\) was given"):
        read_recording(tmp_path / "xml.aedat", sensor_size=(100, 100))
    with pytest.raises(EventDataError, match=r"outside|sensor"):
        read_recording(bare, sensor_size=(50, 50))
    huge = ['-Source 1: <attr key="dvsSizeX" type="short">999999</attr><attr key="dvsSizeY" type="short">9</attr>']
    with pytest.raises(EventDataError, match=r"larger than any event camera"):
        read_recording(_file(tmp_path / "huge.aedat", packets, device="", extra_lines=huge))


def test_damaged_compressed_and_older_files_are_refused_with_the_fix(tmp_path):
    t, x, y, on = _events(n=500)
    good = _file(tmp_path / "good.aedat", _polarity_packets(t, x, y, on)).read_bytes()
    cut = tmp_path / "cut.aedat"
    cut.write_bytes(good[:-13])
    with pytest.raises(EventDataError, match=r"cut\.aedat: .*(truncated|damaged).*copy"):
        read_recording(cut)
    noise = tmp_path / "noise.aedat"
    noise.write_bytes(good[:good.find(b"#!END-HEADER") + 14] + np.full(200, 255, np.uint8).tobytes())
    with pytest.raises(EventDataError, match=r"noise\.aedat: .*not an AEDAT 3\.1 packet header.*damaged"):
        read_recording(noise)
    with pytest.raises(EventDataError, match=r"'Compressed' format.*only RAW.*DV"):
        read_recording(_file(tmp_path / "zip.aedat", _polarity_packets(t, x, y, on), fmt="Compressed"))
    with pytest.raises(EventDataError, match=r"AEDAT 3\.0 file \(not 3\.1\).*DV"):
        read_recording(_file(tmp_path / "old.aedat", _polarity_packets(t, x, y, on), version=b"3.0"))
    headless = tmp_path / "headless.aedat"
    headless.write_bytes(b"#!AER-DAT3.1\r\n" + bytes(64))
    with pytest.raises(EventDataError, match=r"no `#!END-HEADER`"):
        read_recording(headless)
    tiny = _header(2, 1, 20, 0, 1, 1) + bytes(20)                  # a frame event shorter than its own fields
    with pytest.raises(EventDataError, match=r"frame packet with 20-byte events.*damaged"):
        read_recording(_file(tmp_path / "tiny.aedat", _polarity_packets(t, x, y, on) + [tiny]))
    reversed_exposure = _frame_packet(np.zeros((1, H, W)), [5000], [4000])
    with pytest.raises(EventDataError, match=r"reversed exposure.*damaged"):
        read_recording(_file(tmp_path / "rev.aedat", _polarity_packets(t, x, y, on) + [reversed_exposure]))
    frames_only = _file(tmp_path / "frames.aedat", [_frame_packet(np.zeros((1, H, W)), [10], [20])])
    with pytest.raises(EventDataError, match=r"no polarity \(DVS\) events"):
        read_recording(frames_only)


def test_the_command_reads_it(tmp_path, capsys):
    from evinr_lite.apps.cli import main

    t, x, y, on = _events(n=3000)
    path = _file(tmp_path / "rec.aedat", _polarity_packets(t, x, y, on))
    assert main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert "aedat3" in out and "180x240" in out.replace(" ", "") and "3,000" in out and "DAVIS240C" in out
