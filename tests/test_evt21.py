"""Prophesee EVT 2.1 .raw files (io/formats/evt21.py): written here from Prophesee's format description
(64-bit words: EVT_NEG / EVT_POS with a 32-pixel mask, EVT_TIME_HIGH, EXT_TRIGGER), in both word
orders (GenX320: whole words; IMX636: upper half first), and read back event for event."""
import numpy as np
import pytest

from evinr_lite import EventDataError, read_recording
from evinr_lite.io.formats.decoding import origin_us_of
from evinr_lite.io.formats.evt21 import decode_words, header_sensor_size, is_evt21
from evinr_lite.io.load import open_recording
from evinr_lite.io.readers import detect_format

H, W = 40, 70
T0_US = 3_600_123_456_789 // 1000   # the camera's clock: 34-bit microseconds, about an hour in


def _events(n=3000, seed=0, t0=T0_US, span_us=1_500_000):
    rng = np.random.default_rng(seed)
    t = np.sort(rng.integers(t0, t0 + span_us, n)).astype(np.uint64)
    x = rng.integers(0, W, n).astype(np.uint16)
    y = rng.integers(0, H, n).astype(np.uint16)
    on = rng.random(n) < 0.45
    # bursts: some events share a time, a row, a polarity and a group of 32 columns (one word, several bits)
    t[1::3] = t[0::3][:len(t[1::3])]
    y[1::3], on[1::3] = y[0::3][:len(y[1::3])], on[0::3][:len(on[1::3])]
    x[1::3] = (x[0::3][:len(x[1::3])] // 32) * 32 + rng.integers(0, 32, len(x[1::3]))
    x = np.minimum(x, W - 1)
    keep = np.ones(n, bool)
    key = t.astype(np.int64) * 10**7 + y.astype(np.int64) * 10**4 + x.astype(np.int64) * 2 + on
    _, first = np.unique(key, return_index=True)       # one event per pixel, time and polarity
    keep[:] = False
    keep[first] = True
    return t[keep], x[keep], y[keep], on[keep]


def _words(t, x, y, on, trigger_every=0):
    """EVT 2.1 words (as the format defines them) for time-sorted events."""
    words = []
    high = None
    i = 0
    n = len(t)
    while i < n:
        if int(t[i]) >> 6 != high:
            high = int(t[i]) >> 6
            words.append((0x8 << 60) | (high << 32))
        j, mask = i, 0
        base = int(x[i]) // 32 * 32
        while j < n and t[j] == t[i] and y[j] == y[i] and on[j] == on[i] and int(x[j]) // 32 * 32 == base:
            mask |= 1 << (int(x[j]) - base)
            j += 1
        words.append((int(on[i]) << 60) | ((int(t[i]) & 0x3F) << 54) | (base << 43) | (int(y[i]) << 32) | mask)
        if trigger_every and len(words) % trigger_every == 0:
            words.append((0xA << 60) | ((int(t[i]) & 0x3F) << 54) | (1 << 32))     # an external trigger edge
        i = j
    return np.array(words, dtype=np.uint64)


def _write(path, ev, order="whole", header=None, trigger_every=0, before=()):
    order_key = np.lexsort((ev[1], ev[2], ev[3], ev[0]))       # time, then polarity, row, column
    t, x, y, on = (a[order_key] for a in ev)
    words = np.concatenate([np.array(before, np.uint64), _words(t, x, y, on, trigger_every)])
    if order == "halves":                                       # IMX636: the upper 32-bit half first
        words = (words << np.uint64(32)) | (words >> np.uint64(32))
    if header is None:
        header = f"% camera_integrator_name Prophesee\n% evt 2.1\n% format EVT21;height={H};width={W}\n% end\n"
    path.write_bytes(header.encode() + words.astype("<u8").tobytes())
    return path


def _sorted(t, x, y, p):
    k = np.lexsort((x, y, p, t))
    return t[k], x[k], y[k], p[k]


def _assert_same(events, ev):
    t, x, y, on = ev
    assert events.sensor_size == (H, W)
    us = np.round(events.t * 1e6).astype(np.int64) + int(events.t_origin) * 10**6
    got = _sorted(us, events.x.astype(np.int64), events.y.astype(np.int64), events.p.astype(np.int64))
    want = _sorted(t.astype(np.int64), x.astype(np.int64), y.astype(np.int64), np.where(on, 1, -1))
    for a, b in zip(got, want):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("order", ["whole", "halves"])
def test_both_word_orders_read_back_event_for_event(tmp_path, order):
    ev = _events()
    path = _write(tmp_path / "rec.raw", ev, order, trigger_every=50)
    assert detect_format(path) == "prophesee_raw"
    rec = read_recording(path)
    _assert_same(rec.events, ev)
    assert rec.meta["encoding"] == "evt21" and rec.meta["word_order"] == order
    assert rec.events.t_origin == origin_us_of(int(ev[0].min())) // 10**6     # a camera's clock is not absolute: 0


def test_windows_and_the_streamed_source_agree_with_the_whole_file(tmp_path):
    ev = _events(5000, seed=1)
    path = _write(tmp_path / "rec.raw", ev)
    whole = read_recording(path).events
    lo, hi = whole.t[0] + 0.5, whole.t[0] + 0.9                          # seconds of the camera's clock
    part = read_recording(path, t_start=lo, t_end=hi).events
    expected = whole.slice_time(lo, hi)
    assert 0 < len(part) < len(whole)
    np.testing.assert_array_equal(part.t, expected.t)
    src = open_recording(path)
    assert src.n_events == len(whole) and src.sensor_size == (H, W)
    np.testing.assert_array_equal(src.events(lo, hi).t, expected.t)


@pytest.mark.parametrize("header", ["% evt 2.1\n% geometry 70x40\n% end\n",
                                    "% format EVT21;height=40;width=70\n% end\n",
                                    "% evt 2.1\n% Width 70\n% Height 40\n"])
def test_header_forms_give_the_encoding_and_the_size(tmp_path, header):
    lines = [h[2:] for h in header.splitlines()]
    assert is_evt21(lines) and header_sensor_size(lines) == (H, W)
    ev = _events(500, seed=2)
    _assert_same(read_recording(_write(tmp_path / "rec.raw", ev, header=header)).events, ev)


def test_without_a_size_the_sensor_size_is_needed_and_checked(tmp_path):
    ev = _events(400, seed=3)
    path = _write(tmp_path / "bare.raw", ev, header="% evt 2.1\n% end\n")
    with pytest.raises(EventDataError, match=r"does not give the sensor size.*\(320, 320\) for a GenX320"):
        read_recording(path)
    rec = read_recording(path, sensor_size=(H, W))
    _assert_same(rec.events, ev)
    assert rec.meta["sensor_size_from"] == "sensor_size argument"
    with pytest.raises(EventDataError, match=r"fit EVT 2.1 under neither word order"):      # events beyond the given sensor
        read_recording(path, sensor_size=(H, 16))
    with pytest.raises(EventDataError, match=r"header says the sensor is \(H, W\) = \(40, 70\)"):
        read_recording(_write(tmp_path / "sized.raw", ev), sensor_size=(70, 40))


def test_a_headerless_stream_is_read_with_version_evt21(tmp_path):
    ev = _events(400, seed=4)
    path = _write(tmp_path / "plain.raw", ev, header="% geometry 70x40\n% end\n")   # no encoding named
    _assert_same(read_recording(path, version="evt21").events, ev)


def test_words_before_the_first_time_word_have_no_time_and_are_dropped(tmp_path):
    ev = _events(300, seed=5)
    stray = (1 << 60) | (32 << 43) | (3 << 32) | 0b1011                # an ON word before any time word
    rec = read_recording(_write(tmp_path / "rec.raw", ev, before=[stray]))
    _assert_same(rec.events, ev)


def test_decode_words_carries_the_time_across_chunks():
    ev = _events(800, seed=6)
    words = _words(*(a[np.lexsort((ev[1], ev[2], ev[3], ev[0]))] for a in ev))
    whole, _ = decode_words(words, None)
    parts, high = [], None
    for chunk in np.array_split(words, 7):
        packet, high = decode_words(chunk, high)
        parts.append(packet)
    np.testing.assert_array_equal(np.concatenate(parts), whole)
    assert len(whole) == len(ev[0])


def test_damaged_and_foreign_files_are_refused_with_the_fix(tmp_path):
    ev = _events(400, seed=7)
    good = _write(tmp_path / "rec.raw", ev).read_bytes()
    cut = tmp_path / "cut.raw"
    cut.write_bytes(good[:-3])                                   # not a whole number of words
    with pytest.raises(EventDataError, match=r"not a whole number of 64-bit words.*copy the file again"):
        read_recording(cut)
    evt2 = tmp_path / "evt2.raw"                                 # EVT 2.0's 32-bit words under an EVT 2.1 header
    body = np.arange(1, 2001, dtype="<u4") | np.uint32(0x1 << 28)
    evt2.write_bytes(b"% evt 2.1\n% geometry 70x40\n% end\n" + body.tobytes())
    with pytest.raises(EventDataError, match=r"evt2\.raw: its header says EVT 2.1 but .* fit EVT 2.1 under neither"):
        read_recording(evt2)
    empty = tmp_path / "empty.raw"
    empty.write_bytes(b"% evt 2.1\n% geometry 70x40\n% end\n")
    with pytest.raises(EventDataError, match=r"no event words"):
        read_recording(empty)


def test_the_command_reads_it(tmp_path, capsys):
    from evinr_lite.apps.cli import main

    path = _write(tmp_path / "rec.raw", _events(600, seed=8), "halves")
    assert main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    assert "prophesee_raw" in out and "40" in out and "70" in out
