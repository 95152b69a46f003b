"""Reader-side reliability (issue 25, sections 2 and 3): one clock for frames and events, plausible
units, checked internal indexes, typed metadata; several instances of each class."""
import json
import warnings

import h5py
import numpy as np
import pytest

from evinr_lite.core.events import EventDataError
from evinr_lite.io import open_recording, read_recording
from evinr_lite.io.canonical import CanonicalWriter, find_time_index
from evinr_lite.io.notes import ReadNote

H, W = 12, 16


def _events(n=4000, span=2.0, seed=0):
    rng = np.random.default_rng(seed)
    return (np.sort(rng.uniform(0.0, span, n)), rng.integers(0, W, n), rng.integers(0, H, n),
            rng.integers(0, 2, n))


def _read(path, **options):
    """(recording, notes) with every ReadNote caught."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rec = read_recording(path, **options)
    notes = [str(w.message) for w in caught if issubclass(w.category, ReadNote)]
    assert notes == rec.meta.get("read_notes", [])
    return rec, notes


# ---- one clock for frames and events --------------------------------------------------------

def _ijrr(folder, frame_tokens, event_t=None):
    from skimage.io import imsave

    t, x, y, p = _events() if event_t is None else event_t
    folder.mkdir()
    (folder / "images").mkdir()
    (folder / "events.txt").write_text("".join(f"{a:.9f} {b} {c} {d}\n" for a, b, c, d in zip(t, x, y, p)))
    lines = []
    for k, token in enumerate(frame_tokens):
        imsave(folder / "images" / f"frame_{k:08d}.png", np.full((H, W), 20 * k, np.uint8), check_contrast=False)
        lines.append(f"{token} images/frame_{k:08d}.png")
    (folder / "images.txt").write_text("\n".join(lines) + "\n")
    return folder


@pytest.mark.parametrize("unit,scale", [("ns", 10**9), ("ms", 10**3), ("us", 10**6)])
def test_ijrr_frames_in_another_unit_are_converted_with_a_note(tmp_path, unit, scale):
    stamps = [0.25, 0.75, 1.5]
    folder = _ijrr(tmp_path / "seq", [str(int(round(s * scale))) for s in stamps])
    rec, notes = _read(folder)
    np.testing.assert_allclose(rec.frames.t, stamps, atol=1e-9)
    assert len(notes) == 1 and f"taken as {unit}" in notes[0]


def test_ijrr_frames_on_the_same_clock_give_no_note(tmp_path):
    rec, notes = _read(_ijrr(tmp_path / "seq", ["0.250000000", "0.750000000"]))
    np.testing.assert_allclose(rec.frames.t, [0.25, 0.75])
    assert notes == []


@pytest.mark.parametrize("tokens", [["1468939802.25", "1468939802.75"],          # absolute frames, relative events
                                    ["-500.0", "-499.5"],                          # another zero
                                    ["25000.0", "25000.5"]])                       # an offset of hours
def test_ijrr_frames_on_another_clock_are_refused_naming_both_spans(tmp_path, tokens):
    folder = _ijrr(tmp_path / "seq", tokens)
    with pytest.raises(EventDataError, match=r"not on one clock: .*frame timestamps span .* events span .*same zero"):
        read_recording(folder)


def _hqf(path, stamps, events=None):
    t, x, y, p = _events() if events is None else events
    with h5py.File(path, "w") as f:
        f["events/ts"] = t
        f["events/xs"], f["events/ys"], f["events/ps"] = x, y, p
        f.attrs["sensor_resolution"] = (H, W)
        for k, stamp in enumerate(stamps):
            f[f"images/image{k:09d}"] = np.full((H, W), k, np.uint8)
            f[f"images/image{k:09d}"].attrs["timestamp"] = stamp
    return path


@pytest.mark.parametrize("unit,scale", [("us", 1e6), ("ns", 1e9), ("ms", 1e3)])
def test_hqf_frame_stamps_in_another_unit_are_converted(tmp_path, unit, scale):
    rec, notes = _read(_hqf(tmp_path / "a.h5", [0.2 * scale, 1.1 * scale, 1.9 * scale]))
    np.testing.assert_allclose(rec.frames.t, [0.2, 1.1, 1.9], atol=1e-9)
    assert len(notes) == 1 and f"taken as {unit}" in notes[0]


@pytest.mark.parametrize("stamps", [[1.6e9 + 0.2, 1.6e9 + 1.1], [-3600.0, -3599.0], [7200.0, 7201.0]])
def test_hqf_frame_stamps_on_another_clock_are_refused(tmp_path, stamps):
    with pytest.raises(EventDataError, match="not on one clock"):
        read_recording(_hqf(tmp_path / "a.h5", stamps))
    with pytest.raises(EventDataError, match="not on one clock"):
        open_recording(tmp_path / "a.h5")


def _evreal(folder, images_ts, ts, events=None):
    t, x, y, p = _events() if events is None else events
    folder.mkdir()
    np.save(folder / "events_ts.npy", ts)
    np.save(folder / "events_xy.npy", np.stack([x, y], 1))
    np.save(folder / "events_p.npy", p)
    np.save(folder / "images.npy", np.zeros((len(images_ts), H, W, 1), np.uint8))
    np.save(folder / "images_ts.npy", np.asarray(images_ts))
    (folder / "metadata.json").write_text(json.dumps({"sensor_resolution": [H, W]}))
    return folder


@pytest.mark.parametrize("events_scale,events_unit,frame_scale,frame_unit", [
    (1e6, "us", 1.0, "s"),       # integer microseconds for the events, seconds for the frames
    (1e9, "ns", 1.0, "s"),       # (the events' unit given)
    (1.0, "s", 1e3, "ms"),       # events in seconds, frames in milliseconds
])
def test_evreal_frames_on_another_unit_are_converted(tmp_path, events_scale, events_unit, frame_scale, frame_unit):
    t = _events()[0]
    ts = np.round(t * events_scale).astype(np.int64) if events_scale > 1 else t
    folder = _evreal(tmp_path / "seq", [0.5 * frame_scale, 1.5 * frame_scale], ts)
    rec, notes = _read(folder, time_unit=events_unit)
    np.testing.assert_allclose(rec.frames.t, [0.5, 1.5], atol=1e-6)
    assert len(notes) == 1 and f"taken as {frame_unit}" in notes[0]


def test_evreal_frames_nowhere_near_the_events_are_refused(tmp_path):
    folder = _evreal(tmp_path / "seq", [1e12, 1e12 + 5], _events()[0])
    with pytest.raises(EventDataError, match="not on one clock"):
        read_recording(folder)


# ---- plausible units ------------------------------------------------------------------------

def _ms_events(n=100_000, span_s=2.0):
    t, x, y, p = _events(n=n, span=span_s)
    return t * 1e3, x, y, p   # milliseconds, written with decimals


@pytest.mark.parametrize("fmt", ["txt", "npy", "h5", "evreal"])
def test_decimal_milliseconds_get_a_note_naming_the_override(tmp_path, fmt):
    t, x, y, p = events = _ms_events()   # 50 events per second if read as seconds: a note, not an error
    if fmt == "txt":
        path = tmp_path / "e.txt"
        path.write_text(f"{W} {H}\n" + "".join(f"{a:.6f} {b} {c} {d}\n" for a, b, c, d in zip(t, x, y, p)))
        options = {}
    elif fmt == "npy":
        path = tmp_path / "e.npy"
        np.save(path, np.stack([t, x, y, p], 1))
        options = dict(sensor_size=(H, W))
    elif fmt == "h5":
        path = _hqf(tmp_path / "e.h5", [], events=events)
        options = {}
    else:
        path = _evreal(tmp_path / "seq", [], t, events=events)
        (path / "images.npy").unlink()
        (path / "images_ts.npy").unlink()
        options = {}
    rec, notes = _read(path, **options)
    assert len(notes) == 1 and "time_unit='ms'" in notes[0] and "seconds" in notes[0]
    rec, notes = _read(path, **options, time_unit="ms")
    assert notes == [] and rec.events.duration == pytest.approx((t[-1] - t[0]) / 1e3)
    rec, notes = _read(path, **options, time_unit="s")   # said explicitly: taken as said
    assert notes == []


def test_fast_decimal_seconds_get_no_note(tmp_path):
    t, x, y, p = _events(n=20000, span=0.5)
    path = tmp_path / "e.npy"
    np.save(path, np.stack([t, x, y, p], 1))
    assert _read(path, sensor_size=(H, W))[1] == []


# ---- checked internal indexes ----------------------------------------------------------------

def _canonical(path, monkeypatch, n=5000, frames=(0.3, 0.9, 1.6), **meta):
    monkeypatch.setattr("evinr_lite.io.canonical.CHUNK_EVENTS", 64)
    t, x, y, p = _events(n=n)
    with CanonicalWriter(path, sensor_size=(H, W), meta=meta or None) as w:
        w.add_events(t, x, y, 2 * p - 1)
        for k, stamp in enumerate(frames):
            w.add_frame(np.full((H, W), 40 * k, np.uint8), stamp)
    return path, t


@pytest.mark.parametrize("damage", ["shifted", "scaled", "one entry", "too short", "nan", "stride"])
def test_a_damaged_time_index_is_detected_and_windows_stay_right(tmp_path, monkeypatch, damage):
    path, t = _canonical(tmp_path / "c.h5", monkeypatch)
    with h5py.File(path, "r+") as f:
        index = f["events/t_index"][()]
        del f["events/t_index"]
        if damage == "shifted":
            index = index + 0.05
        elif damage == "scaled":
            index = index * 0.5
        elif damage == "one entry":
            index[len(index) // 2] += 0.01
        elif damage == "too short":
            index = index[: len(index) // 2]
        elif damage == "nan":
            index[3] = np.nan
        f["events/t_index"] = index
        f["events/t_index"].attrs["stride"] = 64 if damage != "stride" else 100
    for a, b in ((0.1, 0.7), (0.95, 1.05), (1.5, 2.5)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ev = read_recording(path, t_start=a, t_end=b).events
            with open_recording(path) as src:
                ev2 = src.events(a, b)
        expected = t[(t >= a) & (t < b)]
        np.testing.assert_array_equal(ev.t, expected)
        np.testing.assert_array_equal(ev2.t, expected)


def test_find_time_index_agrees_with_searchsorted_on_a_sound_index(tmp_path, monkeypatch):
    path, t = _canonical(tmp_path / "c.h5", monkeypatch)
    with h5py.File(path, "r") as f:
        for value in np.concatenate([t[::97], [-1.0, 0.0, 5.0], t[64::64]]):
            for side in ("left", "right"):
                assert find_time_index(f, value, side) == np.searchsorted(t, value, side)


def test_unsorted_frame_times_are_sorted_with_a_note(tmp_path, monkeypatch):
    path, _ = _canonical(tmp_path / "c.h5", monkeypatch)
    with h5py.File(path, "r+") as f:
        ft = f["frames/t"][()]
        f["frames/t"][...] = ft[[2, 0, 1]]   # frame 0 (value 0) now says 1.6 s, and so on
    rec, notes = _read(path)
    np.testing.assert_array_equal(rec.frames.t, np.sort(ft))
    np.testing.assert_array_equal(rec.frames.images[:, 0, 0], [40, 80, 0])   # images follow their times
    assert len(notes) == 1 and "not in time order" in notes[0]
    rec, _ = _read(path, t_start=0.5, t_end=1.7)
    np.testing.assert_array_equal(rec.frames.images[:, 0, 0], [80, 0])


# ---- typed metadata, datasets where groups are -----------------------------------------------

@pytest.mark.parametrize("key,value", [("C", "abc"), ("C", -1), ("C", True), ("eval_window", "all"),
                                       ("eval_window", [2.0, 1.0]), ("calib", 3), ("cfa", "XYZW"),
                                       ("frames_sorted", "yes")])
def test_wrongly_typed_meta_json_names_the_field(tmp_path, monkeypatch, key, value):
    path, _ = _canonical(tmp_path / "c.h5", monkeypatch)
    with h5py.File(path, "r+") as f:
        meta = json.loads(f.attrs["meta_json"])
        meta[key] = value
        f.attrs["meta_json"] = json.dumps(meta)
    for read in (read_recording, open_recording):
        with pytest.raises(EventDataError, match=rf"meta_json\[{key!r}\] is .* must be"):
            read(path)


@pytest.mark.parametrize("name", ["events/x", "events/t", "events/t_index", "frames/t", "frames/images"])
def test_a_canonical_dataset_stored_as_a_group_is_refused(tmp_path, monkeypatch, name):
    path, _ = _canonical(tmp_path / "c.h5", monkeypatch)
    with h5py.File(path, "r+") as f:
        del f[name]
        f.create_group(name)
    with pytest.raises(EventDataError, match=rf"{name} is a group, not a dataset"):
        read_recording(path)


@pytest.mark.parametrize("name", ["events/ts", "events/xs", "images/image000000001"])
def test_an_hqf_dataset_stored_as_a_group_is_refused(tmp_path, name):
    path = _hqf(tmp_path / "a.h5", [0.2, 1.1, 1.9])
    with h5py.File(path, "r+") as f:
        del f[name]
        f.create_group(name)
    with pytest.raises(EventDataError, match="group"):
        read_recording(path)


def test_hqf_frames_of_another_size_than_sensor_resolution_give_the_fix_that_works(tmp_path):
    path = _hqf(tmp_path / "a.h5", [0.2, 1.1])
    with h5py.File(path, "r+") as f:
        f.attrs["sensor_resolution"] = (H + 2, W)                          # the camera's size, written wrong
    with pytest.raises(EventDataError, match=r"frames are .* but sensor_resolution is .*set the attribute") as err:
        read_recording(path)
    fix = str(err.value).split("e.g. ")[1]                                 # run the message's own fix
    assert fix.startswith("h5py.File(path, 'r+').attrs['sensor_resolution'] = ")
    with h5py.File(path, "r+") as f:
        f.attrs["sensor_resolution"] = eval(fix.split(" = ")[1])
    assert read_recording(path).frames.size == (H, W)
