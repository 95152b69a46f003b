"""The DSEC-style HDF5 reader: Blosc-compressed events/x, y, t (microseconds since t_offset), p read
exactly, windows read from disk equal the slices of the whole file, and bad files refused with the fix."""
import subprocess
import sys

import h5py
import hdf5plugin
import numpy as np
import pytest

from evinr_lite.core.events import EventDataError
from evinr_lite.io import load_recording, open_recording
from evinr_lite.io.formats import dsec as dsec_module
from evinr_lite.io.formats.dsec import read_dsec
from evinr_lite.io.formats.registry import detect_format

H, W = 48, 64
OFFSET = 49_599_300_523            # microseconds, as in DSEC's files (about 13.8 hours)


def _events(n=20_000, seed=0):
    rng = np.random.default_rng(seed)
    return (np.sort(rng.integers(0, 3_000_000, n)).astype(np.uint32), rng.integers(0, W, n).astype(np.uint16),
            rng.integers(0, H, n).astype(np.uint16), rng.integers(0, 2, n).astype(np.uint8))


def _write(path, t, x, y, p, *, offset=OFFSET, compress=True):
    kw = dict(chunks=(min(4096, len(t)),), **hdf5plugin.Blosc(cname="zstd", clevel=5)) if compress else {}
    with h5py.File(path, "w") as f:
        for name, v in (("x", x), ("y", y), ("t", t), ("p", p)):
            f.create_dataset(f"events/{name}", data=v, **kw)
        if offset is not None:
            f["t_offset"] = np.int64(offset)
        f["ms_to_idx"] = np.searchsorted(t, np.arange(0, int(t[-1]) // 1000 + 2) * 1000).astype(np.uint64)
    return path


def test_compressed_file_reads_exactly(tmp_path):
    t, x, y, p = _events()
    path = _write(tmp_path / "events.h5", t, x, y, p)
    assert detect_format(path) == "dsec"
    rec = read_dsec(path, (H, W))
    np.testing.assert_allclose(rec.events.t + rec.events.t_origin, (t.astype(np.int64) + OFFSET) / 1e6, rtol=0,
                               atol=1e-9)
    np.testing.assert_array_equal(rec.events.x, x)
    np.testing.assert_array_equal(rec.events.y, y)
    np.testing.assert_array_equal(rec.events.p > 0, p == 1)
    assert rec.events.sensor_size == (H, W) and rec.frames is None and rec.meta["t_offset_us"] == OFFSET


def test_windows_from_disk_equal_slices_of_the_whole(tmp_path):
    t, x, y, p = _events()
    path = _write(tmp_path / "events.h5", t, x, y, p)
    whole = read_dsec(path, (H, W)).events
    t0 = whole.t[0] + 0.8
    part = load_recording(path, sensor_size=(H, W), t_start=t0, t_end=t0 + 1.1).events
    keep = (whole.t >= t0) & (whole.t < t0 + 1.1)
    np.testing.assert_array_equal(part.t, whole.t[keep])
    np.testing.assert_array_equal(part.x, whole.x[keep])
    with open_recording(path, sensor_size=(H, W)) as source:
        ev = source.events(t0, t0 + 1.1)
    np.testing.assert_array_equal(ev.t, whole.t[keep])


def test_without_offset_and_uncompressed(tmp_path):
    t, x, y, p = _events(500)
    rec = read_dsec(_write(tmp_path / "plain.h5", t, x, y, p, offset=None, compress=False), (H, W))
    np.testing.assert_allclose(rec.events.t + rec.events.t_origin, t / 1e6, atol=1e-12)


def test_an_hqf_file_is_still_hqf(tmp_path):
    path = tmp_path / "hqf.h5"
    with h5py.File(path, "w") as f:
        for name, v in (("xs", [1, 2]), ("ys", [1, 2]), ("ts", [0.1, 0.2]), ("ps", [0, 1])):
            f[f"events/{name}"] = np.asarray(v)
        f.attrs["sensor_resolution"] = (H, W)
    assert detect_format(path) == "h5"


def _bad(tmp_path, edit):
    t, x, y, p = _events(300)
    path = _write(tmp_path / "bad.h5", t, x, y, p, compress=False)
    with h5py.File(path, "r+") as f:
        edit(f)
    return path


@pytest.mark.parametrize("edit, message", [
    (lambda f: f.__delitem__("events/p") or f.create_dataset("events/p", data=np.zeros(5, np.uint8)),
     r"must be 1-D with the same length"),
    (lambda f: f.__delitem__("events/t") or f.create_dataset("events/t", data=np.linspace(0, 1, 300)),
     r"events/t must be integers \(t in microseconds\)"),
    (lambda f: f.__delitem__("t_offset") or f.create_dataset("t_offset", data=[1, 2]),
     r"t_offset must be one integer"),
])
def test_damaged_layouts_are_refused(tmp_path, edit, message):
    with pytest.raises(EventDataError, match=message):
        read_dsec(_bad(tmp_path, edit), (H, W))


def test_sensor_size_is_asked_for_with_dsecs_own(tmp_path):
    t, x, y, p = _events(300)
    path = _write(tmp_path / "events.h5", t, x, y, p)
    with pytest.raises(EventDataError, match=r"does not record the sensor size; pass sensor_size=\(H, W\).*\(480, 640\)"):
        read_dsec(path)
    run = subprocess.run([sys.executable, "-m", "evinr_lite", "info", str(path)], capture_output=True, text=True)
    assert run.returncode == 2 and "--sensor HxW" in run.stderr
    run = subprocess.run([sys.executable, "-m", "evinr_lite", "info", str(path), "--sensor", f"{H}x{W}"],
                         capture_output=True, text=True)
    assert run.returncode == 0 and "dsec" in run.stdout


def test_a_filter_this_python_lacks_names_the_fix(tmp_path, monkeypatch):
    t, x, y, p = _events(300)
    path = _write(tmp_path / "events.h5", t, x, y, p)
    monkeypatch.setattr(h5py.h5z, "filter_avail", lambda fid: False)
    with pytest.raises(EventDataError, match=r"compressed with HDF5 filter 32001 \(Blosc\).*pip install hdf5plugin"):
        read_dsec(path, (H, W))
    assert dsec_module.FILTERS[32001] == "Blosc"


def test_unsorted_times_are_refused_for_a_window(tmp_path):
    t, x, y, p = _events(3000)
    path = _write(tmp_path / "events.h5", t[::-1].copy(), x, y, p)
    with pytest.raises(EventDataError, match=r"not sorted"):
        read_dsec(path, (H, W), t_start=49600.0, t_end=49601.0)


def test_reconstruct_reads_a_window_of_a_dsec_file(tmp_path):
    """The command end to end on a window: frames written for the window only, from the file's events."""
    t, x, y, p = _events()
    path = _write(tmp_path / "events.h5", t, x, y, p)
    start = (OFFSET + int(t[0])) / 1e6 + 0.5
    out = tmp_path / "rec"
    run = subprocess.run([sys.executable, "-m", "evinr_lite", "reconstruct", str(path), "--sensor", f"{H}x{W}",
                          "--start", f"{start:.6f}", "--end", f"{start + 1.0:.6f}", "--fps", "4", "--out", str(out),
                          "--quiet", "--no-video"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert len(sorted(out.glob("**/*.png"))) == 4
