"""Round 4 of the bad-input table (tests/test_robustness*.py): classes of damage the earlier rounds miss.

Every event at one instant (any format), frames sharing a timestamp (any format with frames), a file
holding 0 or 1 event, absurd sensor sizes stored in a file, numbers too large for any clock or sensor in
a text file, frame files that are no images, NaN in stored frames or frame stamps, a canonical file
with 0/1 polarities; and, as guards, representative odd inputs that already gave a clear error or that
are valid and must keep working. Each bad input gives exit status 2 with ``evinr-lite: error:`` naming
the problem, never an internal error or a traceback, and leaves no file behind; reconstruct is refused
before training.
"""
import re
import shutil

import numpy as np
import pytest

from evinr_lite.apps.cli import main

from test_robustness import H, W, _events, tree

FAST = ["--fps", "5", "--iters", "3", "--quiet", "--no-video"]
SENSOR = ["--sensor", f"{H}x{W}"]


@pytest.fixture(scope="module")
def rec_dir(tmp_path_factory):
    from evinr_lite.sim.recordings import write_example_recording

    return write_example_recording(tmp_path_factory.mktemp("rec") / "example", sensor_size=(H, W), duration=0.2,
                                   C=0.25, frame_rate=20.0, seed=0)


def _no_training(monkeypatch):
    import evinr_lite.apps.recon_job as job
    import evinr_lite.method.streaming as streaming

    monkeypatch.setattr(job, "reconstruct_recording", lambda *a, **k: pytest.fail("trained on a bad input"))
    monkeypatch.setattr(streaming, "stream_reconstruct", lambda *a, **k: pytest.fail("trained on a bad input"))


def _both_commands_refuse(capsys, monkeypatch, root, path, extra, pattern, commands=("info", "reconstruct"),
                          before_training=True):
    """info and reconstruct each end with status 2 and an error matching ``pattern``; nothing under root changes.
    ``before_training``: reconstruct refuses before any training (damage inside the events' payload, such as one
    bad coordinate, is found by a streamed run when it reads that window: then only the outcome is checked)."""
    if before_training:
        _no_training(monkeypatch)
    before = tree(root)
    for command in commands:
        argv = (["info", path, *extra] if command == "info"
                else ["reconstruct", path, "--out", root / "out", *extra, *FAST])
        code = main([str(a) for a in argv])
        out, err = capsys.readouterr()
        assert code == 2, (command, code, out, err)
        assert err.startswith("evinr-lite: error: ") and "Traceback" not in err and "internal error" not in err, err
        assert re.search(pattern, err), (command, err)
        assert tree(root) == before, f"{command} left or changed files"


def _txt(path, t, x, y, p, header=f"{W} {H}\n"):
    path.write_text(header + "".join(f"{a:.9f} {b} {c} {(d + 1) // 2}\n" for a, b, c, d in zip(t, x, y, p)))
    return path


def _hqf(path, frames=None, **over):
    import h5py

    t, x, y, p = _events()
    with h5py.File(path, "w") as f:
        for k, v in (("xs", x), ("ys", y), ("ts", t), ("ps", (p > 0).astype(np.uint8))):
            f.create_dataset(f"events/{k}", data=over.get(k, v))
        f.attrs["sensor_resolution"] = over.get("sensor_resolution", (H, W))
        for i, (stamp, image) in enumerate(frames or ()):
            f.create_dataset(f"images/image{i:09d}", data=image)
            f[f"images/image{i:09d}"].attrs["timestamp"] = stamp
    return path


def _canonical(path, t=None, p=None, frames=()):
    from evinr_lite.io.canonical import CanonicalWriter

    t0, x, y, p0 = _events()
    with CanonicalWriter(path, sensor_size=(H, W)) as w:
        w.add_events(t0 if t is None else t, x, y, p0)
        for stamp in frames:
            w.add_frame(np.full((H, W), 100, np.uint8), stamp)
    if p is not None:
        import h5py

        with h5py.File(path, "r+") as f:
            f["events/p"][...] = p(f["events/p"][...])
    return path


def _evreal(folder, ts=None, images_ts=None, images=None, meta=None):
    t, x, y, p = _events()
    folder.mkdir()
    np.save(folder / "events_ts.npy", t if ts is None else ts)
    np.save(folder / "events_xy.npy", np.stack([x, y], axis=1).astype(np.int16))
    np.save(folder / "events_p.npy", (p > 0).astype(np.uint8))
    (folder / "metadata.json").write_text(meta or f'{{"sensor_resolution": [{H}, {W}]}}')
    if images_ts is not None:
        np.save(folder / "images.npy", np.full((len(images_ts), H, W), 100, np.uint8) if images is None else images)
        np.save(folder / "images_ts.npy", np.asarray(images_ts))
    return folder


def _faery(path, t_us=None):
    faery = pytest.importorskip("faery")
    t, x, y, p = _events()
    packet = np.zeros(len(t), dtype=faery.EVENTS_DTYPE)
    packet["t"] = np.round(t * 1e6).astype(np.uint64) if t_us is None else t_us
    packet["x"], packet["y"], packet["on"] = x, y, p > 0
    faery.events_stream_from_array(packet, dimensions=(W, H)).to_file(path)
    return path


def _ijrr(tmp_path, rec_dir):
    folder = tmp_path / "seq"
    shutil.copytree(rec_dir, folder)
    return folder


# ---- 1. every event at one instant: a damaged time column, not a time-unit problem -------------------------

def _same_time(tmp_path, rec_dir, fmt):
    t, x, y, p = _events()
    same = np.full(len(t), 0.1)
    if fmt == "txt":
        return _txt(tmp_path / "ev.txt", same, x, y, p), []
    if fmt == "txt, 2 events":
        return _txt(tmp_path / "ev.txt", same[:2], x[:2], y[:2], p[:2]), []
    if fmt == "txt, 1500 events":   # enough events for the span check, whose advice (another unit) would not help
        n = 1500
        return _txt(tmp_path / "ev.txt", np.full(n, 0.1), np.resize(x, n), np.resize(y, n), np.resize(p, n)), []
    if fmt == "npy":
        np.save(tmp_path / "ev.npy", np.stack([same, x, y, p], axis=1))
        return tmp_path / "ev.npy", SENSOR
    if fmt == "h5":
        return _hqf(tmp_path / "e.h5", ts=same), []
    if fmt == "canonical":
        return _canonical(tmp_path / "c.h5", t=same), []
    if fmt == "evreal":
        return _evreal(tmp_path / "seq", ts=same), []
    if fmt == "aedat4":
        return _faery(tmp_path / "r.aedat4", t_us=np.full(len(t), 100_000, np.uint64)), []
    folder = _ijrr(tmp_path, rec_dir)
    lines = (folder / "events.txt").read_text().splitlines()
    (folder / "events.txt").write_text("".join("0.1 " + " ".join(line.split()[1:]) + "\n" for line in lines))
    return folder, []


@pytest.mark.parametrize("fmt", ["txt", "txt, 2 events", "txt, 1500 events", "npy", "h5", "canonical", "evreal",
                                 "aedat4", "ijrr"])
def test_every_event_at_one_instant(capsys, monkeypatch, tmp_path, rec_dir, fmt):
    path, extra = _same_time(tmp_path, rec_dir, fmt)
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, extra, r"events have the same timestamp")


# ---- 2. frames that share a timestamp (reconstruct scored them: an internal error) -----------------------

def _duplicate_frames(tmp_path, rec_dir, fmt):
    if fmt in ("ijrr, all equal", "ijrr, two equal"):
        folder = _ijrr(tmp_path, rec_dir)
        lines = (folder / "images.txt").read_text().splitlines()
        if fmt == "ijrr, all equal":
            lines = [f"0.1 {line.split()[1]}" for line in lines]
        else:
            lines[2] = f"{lines[1].split()[0]} {lines[2].split()[1]}"
        (folder / "images.txt").write_text("\n".join(lines) + "\n")
        return folder
    image = np.full((H, W), 100, np.uint8)
    if fmt == "h5":
        return _hqf(tmp_path / "e.h5", frames=[(0.1, image), (0.1, image), (0.15, image)])
    if fmt == "canonical":
        return _canonical(tmp_path / "c.h5", frames=(0.1, 0.1, 0.15))
    return _evreal(tmp_path / "seq", images_ts=[0.1, 0.1, 0.1])


@pytest.mark.parametrize("fmt", ["ijrr, all equal", "ijrr, two equal", "h5", "canonical", "evreal"])
def test_frames_sharing_a_timestamp(capsys, monkeypatch, tmp_path, rec_dir, fmt):
    path = _duplicate_frames(tmp_path, rec_dir, fmt)
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, [], r"repeats? the timestamp of another frame")


# ---- 3. a recording of 0 or 1 event: described by info, refused by reconstruct for what it is -------------

@pytest.mark.parametrize("fmt,n", [("npy", 0), ("npy", 1), ("txt", 1), ("h5", 0), ("h5", 1), ("canonical", 1)])
def test_a_recording_of_too_few_events(capsys, monkeypatch, tmp_path, fmt, n):
    t, x, y, p = (a[:n] for a in _events())
    extra = []
    if fmt == "npy":
        np.save(tmp_path / "ev.npy", np.stack([t, x, y, p], axis=1).reshape(n, 4))
        path, extra = tmp_path / "ev.npy", SENSOR
    elif fmt == "txt":
        path = _txt(tmp_path / "ev.txt", t, x, y, p)
    elif fmt == "h5":
        path = _hqf(tmp_path / "e.h5", ts=t, xs=x, ys=y, ps=(p > 0).astype(np.uint8))
    else:
        from evinr_lite.io.canonical import CanonicalWriter

        path = tmp_path / "c.h5"
        with CanonicalWriter(path, sensor_size=(H, W)) as w:
            w.add_events(t, x, y, p)
    code = main(["info", str(path), *extra])
    out, err = capsys.readouterr()
    assert code == 0 and "Traceback" not in err, (out, err)
    held = "no events" if n == 0 else "only 1 event"
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, extra, rf"holds {held}.*at least 2 events",
                          commands=("reconstruct",))


# ---- 4. sizes and numbers no sensor or clock has ------------------------------------------------------------

def _absurd(tmp_path, case):
    t, x, y, p = _events()
    if case == "txt header 99999999x99999999":
        return _txt(tmp_path / "ev.txt", t, x, y, p, header="99999999 99999999\n"), r"header line .*no event camera"
    if case == "txt header 70000x12":
        return _txt(tmp_path / "ev.txt", t, x, y, p, header=f"70000 {H}\n"), r"header line .*no event camera"
    if case == "h5 sensor_resolution 1e6":
        return _hqf(tmp_path / "e.h5", sensor_resolution=(10**6, 10**6)), r"sensor_resolution .*larger than any"
    if case == "evreal sensor_resolution 1e6":
        return (_evreal(tmp_path / "seq", meta='{"sensor_resolution": [1000000, 1000000]}'),
                r"sensor_resolution .*larger than any")
    if case == "canonical sensor_size 1e9":
        import h5py

        path = _canonical(tmp_path / "c.h5")
        with h5py.File(path, "r+") as f:
            f.attrs["sensor_size"] = (10**9, 10**9)
        return path, r"sensor_size must be .*at most 65536"
    if case == "canonical sensor_size 12.5":
        import h5py

        path = _canonical(tmp_path / "c.h5")
        with h5py.File(path, "r+") as f:
            f.attrs["sensor_size"] = (H + 0.5, W)
        return path, r"sensor_size must be .*whole numbers"
    if case == "txt x with 20 digits":
        (tmp_path / "ev.txt").write_text(f"{W} {H}\n0.1 99999999999999999999 1 1\n0.2 1 1 0\n")
        return tmp_path / "ev.txt", r"line 2: x = 1e\+20 is no pixel index"
    if case == "txt y 1e12":
        (tmp_path / "ev.txt").write_text(f"{W} {H}\n0.1 1 2 1\n0.2 1 1e12 0\n")
        return tmp_path / "ev.txt", r"line 3: y = 1e\+12 is no pixel index"
    (tmp_path / "ev.txt").write_text(f"{W} {H}\n" + "".join(f"{10**25 + k} 1 1 1\n" for k in range(5)))
    return tmp_path / "ev.txt", r"line 2: the timestamp is beyond any clock"


@pytest.mark.parametrize("case", ["txt header 99999999x99999999", "txt header 70000x12", "h5 sensor_resolution 1e6",
                                  "evreal sensor_resolution 1e6", "canonical sensor_size 1e9",
                                  "canonical sensor_size 12.5", "txt x with 20 digits", "txt y 1e12",
                                  "txt timestamps of 26 digits"])
def test_sizes_and_numbers_no_sensor_or_clock_has(capsys, monkeypatch, tmp_path, case):
    path, pattern = _absurd(tmp_path, case)
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, [], pattern)


# ---- 5. frames: not images, NaN pixels or stamps; a canonical file's polarity --------------------------------

def _damaged_frames(tmp_path, rec_dir, case):
    if case.startswith("ijrr"):
        folder = _ijrr(tmp_path, rec_dir)
        listed = folder / (folder / "images.txt").read_text().splitlines()[1].split()[1]
        if case == "ijrr frame is a text file":
            listed.write_text("hello\n")
            return folder, r"frame_00000001\.png: not an image file"
        if case == "ijrr frame is empty":
            listed.write_bytes(b"")
            return folder, r"frame_00000001\.png: the image file is empty"
        (folder / "images.txt").write_text("0.05 /etc/hostname\n")   # a listed path outside the folder
        return folder, r"hostname: not an image file"
    if case == "h5 frame with NaN pixels":
        return (_hqf(tmp_path / "e.h5", frames=[(0.1, np.full((H, W), np.nan))]),
                r"image000000000: the frame holds NaN")
    if case == "evreal NaN frame stamp":
        return _evreal(tmp_path / "seq", images_ts=[0.05, np.nan]), r"images_ts\.npy: frame 1's timestamp is nan"
    if case == "evreal frames with NaN pixels":
        return (_evreal(tmp_path / "seq", images_ts=[0.05, 0.1], images=np.full((2, H, W), np.nan)),
                r"images\.npy: the frame holds NaN")
    if case == "canonical p 0/1":
        p = lambda a: (a > 0).astype(a.dtype)  # noqa: E731
    else:
        p = lambda a: np.r_[0, a[1:]].astype(a.dtype)  # noqa: E731
    return _canonical(tmp_path / "c.h5", p=p), r"events/p must hold -1/\+1 .*convert it again"


@pytest.mark.parametrize("case", ["ijrr frame is a text file", "ijrr frame is empty", "ijrr frame outside the folder",
                                  "h5 frame with NaN pixels", "evreal NaN frame stamp", "evreal frames with NaN pixels",
                                  "canonical p 0/1", "canonical one p = 0"])
def test_damaged_frames_and_stored_polarity(capsys, monkeypatch, tmp_path, rec_dir, case):
    import os

    if case == "ijrr frame outside the folder" and not os.path.isfile("/etc/hostname"):
        pytest.skip("no /etc/hostname here")
    path, pattern = _damaged_frames(tmp_path, rec_dir, case)
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, [], pattern, before_training="canonical" not in case)


def test_an_empty_calib_txt_gives_no_note(capsys, tmp_path, rec_dir):
    folder = _ijrr(tmp_path, rec_dir)
    (folder / "calib.txt").write_text("")
    code = main(["info", str(folder)])
    out, err = capsys.readouterr()
    assert code == 0 and "note" not in err and "loadtxt" not in err, err


# ---- 6. guards: damage that already gave a clear error ------------------------------------------------------

def _guard(tmp_path, rec_dir, case):
    t, x, y, p = _events()
    path = tmp_path / "ev.txt"
    if case == "txt comma separated":
        path.write_text(f"{W} {H}\n" + "".join(f"{a:.9f},{b},{c},{(d + 1) // 2}\n" for a, b, c, d in zip(t, x, y, p)))
        return path, [], r"line 2: found 1 columns"
    if case == "txt csv header line":
        path.write_text("t,x,y,p\n" + "".join(f"{a:.9f} {b} {c} {(d + 1) // 2}\n" for a, b, c, d in zip(t, x, y, p)))
        return path, SENSOR, r"line 1: found 1 columns"
    if case == "txt cut inside a line":
        data = _txt(path, t, x, y, p).read_bytes()
        path.write_bytes(data[: data.index(b"\n", len(data) // 2) + 8])
        return path, [], r"line \d+: found [123] columns"
    if case == "txt polarities -1 and 0":
        path.write_text(f"{W} {H}\n" + "".join(f"{a:.9f} {b} {c} {(d - 1) // 2}\n" for a, b, c, d in zip(t, x, y, p)))
        return path, [], r"polarity values \{-1, 0\}"
    if case == "txt decimal comma":
        path.write_text(f"{W} {H}\n0,1 1 1 1\n0,2 1 1 0\n")
        return path, [], r"line 2: the timestamp is not a number"
    if case == "npy NaN time mid-file":
        t = t.copy()
        t[200] = np.nan
        np.save(tmp_path / "ev.npy", np.stack([t, x, y, p], axis=1))
        return tmp_path / "ev.npy", SENSOR, r"timestamp 200 is nan"
    if case == "h5 NaN time mid-file":   # a window search stopped at it and skipped the events after it
        t = t.copy()
        t[200] = np.nan
        return _hqf(tmp_path / "e.h5", ts=t), [], r"e\.h5: timestamp 200 is nan"
    if case == "npy x beyond the sensor mid-file":
        x = x.copy()
        x[300] = W + 7
        np.save(tmp_path / "ev.npy", np.stack([t, x, y, p], axis=1))
        return tmp_path / "ev.npy", SENSOR, r"x \(column.*coordinates span"
    if case == "h5 cut at 90 %":
        data = _hqf(tmp_path / "e.h5").read_bytes()
        (tmp_path / "e.h5").write_bytes(data[: int(0.9 * len(data))])
        return tmp_path / "e.h5", [], r"e\.h5: the HDF5 file is damaged or incomplete"
    if case == "aedat4 cut at 30 %":
        data = _faery(tmp_path / "r.aedat4").read_bytes()
        (tmp_path / "r.aedat4").write_bytes(data[: int(0.3 * len(data))])
        return tmp_path / "r.aedat4", [], r"r\.aedat4: .*damaged"
    if case == "png named .txt":
        path.write_bytes((rec_dir / "images" / "frame_00000000.png").read_bytes())
        return path, [], r"ev\.txt: UTF-16/32 or binary content"
    folder = _ijrr(tmp_path, rec_dir)
    (folder / "events.txt").unlink()
    return folder, [], r"folder of unknown format"


@pytest.mark.parametrize("case", ["txt comma separated", "txt csv header line", "txt cut inside a line",
                                  "txt polarities -1 and 0", "txt decimal comma", "npy NaN time mid-file",
                                  "h5 NaN time mid-file",
                                  "npy x beyond the sensor mid-file", "h5 cut at 90 %", "aedat4 cut at 30 %",
                                  "png named .txt", "ijrr folder without events.txt"])
def test_guards_damage_already_refused(capsys, monkeypatch, tmp_path, rec_dir, case):
    path, extra, pattern = _guard(tmp_path, rec_dir, case)
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, extra, pattern, before_training="mid-file" not in case)


# ---- 7. guards: unusual but valid recordings keep working ------------------------------------------------------

def _valid(tmp_path, rec_dir, case):
    t, x, y, p = _events()
    if case == "txt negative timestamps":
        return _txt(tmp_path / "ev.txt", t - 0.1, x, y, p), []
    if case == "txt BOM, CRLF and tabs":
        text = f"{W} {H}\n" + "".join(f"{a:.9f}\t{b}\t{c}\t{(d + 1) // 2}\n" for a, b, c, d in zip(t, x, y, p))
        (tmp_path / "ev.txt").write_bytes(b"\xef\xbb\xbf" + text.replace("\n", "\r\n").encode())
        return tmp_path / "ev.txt", []
    if case == "txt two events at different times":
        return _txt(tmp_path / "ev.txt", t[[0, -1]], x[:2], y[:2], p[:2]), []
    if case == "npy big-endian, Fortran order":
        np.save(tmp_path / "ev.npy", np.asfortranarray(np.stack([t, x, y, p], axis=1).astype(">f8")))
        return tmp_path / "ev.npy", SENSOR
    if case == "h5 renamed .npy":
        return _hqf(tmp_path / "e.npy"), []
    if case == "h5 sensor_resolution as floats":
        return _hqf(tmp_path / "e.h5", sensor_resolution=(float(H), float(W))), []
    if case == "ijrr 16-bit frame":
        from PIL import Image

        folder = _ijrr(tmp_path, rec_dir)
        Image.fromarray((np.arange(H * W).reshape(H, W) * 200).astype(np.uint16)).save(
            folder / "images" / "frame_00000001.png")
        return folder, []
    folder = tmp_path / "my séquence ü"
    shutil.copytree(rec_dir, folder)
    return folder, []


@pytest.mark.parametrize("case", ["txt negative timestamps", "txt BOM, CRLF and tabs",
                                  "txt two events at different times",
                                  "npy big-endian, Fortran order", "h5 renamed .npy", "h5 sensor_resolution as floats",
                                  "ijrr 16-bit frame", "a path with spaces and unicode"])
def test_guards_unusual_but_valid(capsys, tmp_path, rec_dir, case):
    path, extra = _valid(tmp_path, rec_dir, case)
    code = main(["info", str(path), *extra, "--json"])
    out, err = capsys.readouterr()
    assert code == 0 and "Traceback" not in err and '"n_events"' in out, (code, out, err)
    assert "error" not in err, err
