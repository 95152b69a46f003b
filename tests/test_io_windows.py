"""Reading only a window: for every format, the windows a source hands out (and a reader's t_start /
t_end) hold exactly the events of the whole read, sliced; a large file is read in bounded memory."""
import json
import subprocess
import sys
import textwrap
import warnings

import numpy as np
import pytest

from evinr_lite.core.events import EventDataError, Events
from evinr_lite.io import describe_recording, open_recording, read_recording
from evinr_lite.io.canonical import CanonicalWriter

H, W = 30, 40
T0_US = 1_600_000_123_456_789   # an absolute clock (2020) in microseconds, not on a whole second


def _events(n=6000, seed=0, span=2.0):
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0.0, span, n))
    return t, rng.integers(0, W, n), rng.integers(0, H, n), rng.choice([-1, 1], n)


def _write_npy(path, seed):
    t, x, y, p = _events(seed=seed)
    path = path.with_suffix(".npy")
    np.save(path, np.stack([t + 1.6e9, x, y, (p > 0)], 1))   # absolute clock in float64 seconds
    return path, dict(sensor_size=(H, W))


def _write_npy_us(path, seed):
    t, x, y, p = _events(seed=seed)
    path = path.with_suffix(".npy")
    np.save(path, np.stack([(t * 1e6).astype(np.int64) + T0_US, x, y, p], 1))
    return path, dict(sensor_size=(H, W), time_unit="us")


def _write_hqf(path, seed):
    import h5py

    t, x, y, p = _events(seed=seed)
    path = path.with_suffix(".h5")
    with h5py.File(path, "w") as f:
        f["events/ts"], f["events/xs"], f["events/ys"], f["events/ps"] = t + 100.0, x, y, p > 0
        f.attrs["sensor_resolution"] = (H, W)
        for k, stamp in enumerate((100.1, 100.9, 101.5)):
            f[f"images/image{k:09d}"] = np.full((H, W), 10 * k, np.uint8)
            f[f"images/image{k:09d}"].attrs["timestamp"] = stamp
    return path, {}


def _write_canonical(path, seed):
    t, x, y, p = _events(seed=seed)
    path = path.with_suffix(".h5")
    with CanonicalWriter(path, sensor_size=(H, W), t_origin=1.6e9, dataset="test", sequence="seq") as w:
        for lo in range(0, len(t), 1000):
            w.add_events(t[lo:lo + 1000], x[lo:lo + 1000], y[lo:lo + 1000], p[lo:lo + 1000])
        for k, stamp in enumerate((0.2, 1.0, 1.7)):
            w.add_frame(np.full((H, W), 10 * k, np.uint8), stamp)
    return path, {}


def _write_txt(path, seed):
    t, x, y, p = _events(seed=seed, n=3000)
    path = path.with_suffix(".txt")
    path.write_text(f"{W} {H}\n" + "".join(f"{a:.9f} {b} {c} {int(d > 0)}\n" for a, b, c, d in zip(t, x, y, p)))
    return path, {}


def _faery_packet(seed):
    faery = pytest.importorskip("faery")
    t, x, y, p = _events(seed=seed)
    ev = np.zeros(len(t), dtype=faery.EVENTS_DTYPE)
    ev["t"] = (np.round(t * 1e6).astype(np.int64) + T0_US).astype(np.uint64)
    ev["x"], ev["y"], ev["on"] = x, y, p > 0
    return faery, ev


def _write_faery(suffix, version=None):
    def write(path, seed):
        faery, ev = _faery_packet(seed)
        path = path.with_suffix(suffix)
        faery.events_stream_from_array(ev, dimensions=(W, H)).to_file(path, version=version)
        return path, {}
    return write


WRITERS = {"npy": _write_npy, "npy_us": _write_npy_us, "h5": _write_hqf, "canonical": _write_canonical,
           "txt": _write_txt, "aedat4": _write_faery(".aedat4"), "raw_evt3": _write_faery(".raw", "evt3"),
           "raw_evt2": _write_faery(".raw", "evt2"), "dat": _write_faery(".dat")}


def _same(a: Events, b: Events):
    assert len(a) == len(b)
    for k in "txyp":
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k))
    assert a.sensor_size == b.sensor_size and a.t_origin == b.t_origin


@pytest.fixture(params=sorted(WRITERS))
def written(request, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        path, options = WRITERS[request.param](tmp_path / f"rec_{request.param}", seed=len(request.param))
    return request.param, path, options


@pytest.fixture
def whole(written):
    _, path, options = written
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return read_recording(path, **options)


def test_source_knows_span_count_and_frames(written, whole):
    _, path, options = written
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        src = open_recording(path, **options)
    with src:
        assert src.sensor_size == whole.events.sensor_size and src.t_origin == whole.events.t_origin
        assert src.t_span == (whole.events.t[0], whole.events.t[-1])
        assert src.n_events == len(whole.events)
        assert (src.frames is None) == (whole.frames is None)
        if src.frames is not None:
            np.testing.assert_array_equal(src.frames.t, whole.frames.t)


@pytest.mark.parametrize("n_windows", [1, 7, 40])
def test_windows_in_order_tile_the_whole_read(written, whole, n_windows):
    _, path, options = written
    ev = whole.events
    edges = np.linspace(ev.t[0] - 0.01, ev.t[-1] + 0.01, n_windows + 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        src = open_recording(path, **options)
    with src:
        parts = [src.events(a, b) for a, b in zip(edges[:-1], edges[1:])]
    for part, a, b in zip(parts, edges[:-1], edges[1:]):
        _same(part, ev.slice_time(a, b, allow_empty=True))


def test_overlapping_backward_and_empty_windows(written, whole):
    _, path, options = written
    ev = whole.events
    t0, t1 = ev.t[0], ev.t[-1]
    span = t1 - t0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        src = open_recording(path, **options)
    windows = [(t0 + 0.1 * span, t0 + 0.4 * span), (t0 + 0.3 * span, t0 + 0.6 * span),   # overlap
               (t0 + 0.05 * span, t0 + 0.2 * span),                                         # backwards
               (t1 + 5.0, t1 + 6.0), (t0 - 3.0, t0 - 2.0),                                  # outside: empty
               (t0 + 0.5 * span, t1 + 1.0)]
    with src:
        for a, b in windows:
            _same(src.events(a, b), ev.slice_time(a, b, allow_empty=True))
        with pytest.raises(EventDataError, match="empty or reversed"):
            src.events(t0 + 0.5, t0 + 0.4)


def test_reader_window_and_load_match_the_slice(written, whole):
    name, path, options = written
    ev = whole.events
    a, b = ev.t[0] + 0.3, ev.t[0] + 1.1
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rec = open_recording(path, **options).load(a, b)
    _same(rec.events, ev.slice_time(a, b))
    if whole.frames is not None:
        expected = whole.frames.slice_time(a, b)
        got = rec.frames.t if rec.frames is not None else np.zeros(0)
        np.testing.assert_array_equal(got, expected.t)
    with pytest.raises(EventDataError, match="no events in the window"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            open_recording(path, **options).load(ev.t[-1] + 10, ev.t[-1] + 11)


def test_info_from_a_source_agrees_with_the_whole_read(written, whole):
    _, path, options = written
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fast = describe_recording(open_recording(path, **options))
    full = describe_recording(whole)
    for key in ("format", "sensor_size", "n_events", "t_first", "t_last", "duration_s", "on_fraction", "n_frames"):
        assert fast[key] == full[key], key


def test_info_samples_the_polarity_of_a_long_recording(tmp_path, monkeypatch):
    import evinr_lite.io.load as load

    path, options = _write_npy(tmp_path / "rec.npy", seed=3)
    monkeypatch.setattr(load, "INFO_SAMPLE_EVENTS", 800)
    info = describe_recording(open_recording(path, **options))
    full = describe_recording(read_recording(path, **options))
    assert info["n_events"] == full["n_events"] and 0 < info["on_fraction_events"] < full["n_events"]
    assert abs(info["on_fraction"] - full["on_fraction"]) < 0.1


def test_npy_window_refuses_unsorted_times(tmp_path):
    t, x, y, p = _events()
    t = t[::-1].copy()
    np.save(tmp_path / "rev.npy", np.stack([t, x, y, p], 1))
    with pytest.raises(EventDataError, match="not sorted"):
        read_recording(tmp_path / "rev.npy", sensor_size=(H, W), t_start=0.1, t_end=0.5)
    with pytest.raises(EventDataError, match="not sorted") as err:
        open_recording(tmp_path / "rev.npy", sensor_size=(H, W))
    # the fix a command-line user can run (the CLI has no sort option), and plain numbers, not np.float64(...)
    assert "np.argsort(a[:, 0]" in str(err.value) and "sort=True" in str(err.value) and "np.float" not in str(err.value)
    fixed = np.load(tmp_path / "rev.npy")
    np.save(tmp_path / "rev.npy", fixed[np.argsort(fixed[:, 0], kind="stable")])   # the message's own fix
    assert len(open_recording(tmp_path / "rev.npy", sensor_size=(H, W)).events(0.1, 0.5)) > 0
    ev = read_recording(tmp_path / "rev.npy", sensor_size=(H, W), sort=True, t_start=0.1, t_end=0.5).events
    assert np.all(np.diff(ev.t) >= 0) and ev.t[0] >= 0.1 and ev.t[-1] < 0.5


BOUNDED = textwrap.dedent("""
    import json, resource, sys
    import numpy as np
    from evinr_lite.io import describe_recording, open_recording, read_recording

    def peak_mb():   # this process image's peak (VmHWM); ru_maxrss also counts the parent's peak before exec
        try:
            for line in open("/proc/self/status"):
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024
        except OSError:
            pass
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024

    path = sys.argv[1]
    n_read = 0
    with open_recording(path, sensor_size=(480, 640)) as src:
        t0, t1 = src.t_span
        for a in np.linspace(t0, t1, 12)[:-1]:
            n_read += len(src.events(a, a + 0.02 * (t1 - t0)))
        info = describe_recording(src)
    n_read += len(read_recording(path, sensor_size=(480, 640), t_start=t0 + 1.0, t_end=t0 + 1.5).events)
    print(json.dumps({"peak_mb": peak_mb(), "n_read": n_read, "n_events": info["n_events"]}))
""")


def test_large_npy_is_read_in_bounded_memory(tmp_path):
    """40 M events (1.2 GB on disk, as much in memory): windows, a reader window and info stay far below."""
    n, block = 40_000_000, 4_000_000
    path = tmp_path / "large.npy"
    rng = np.random.default_rng(0)
    with open(path, "wb") as f:   # written a block at a time (20 s at 2 M events per second)
        np.lib.format.write_array_header_1_0(f, {"descr": "<f8", "fortran_order": False, "shape": (n, 4)})
        for lo in range(0, n, block):
            rows = np.empty((block, 4))
            rows[:, 0] = (lo + np.arange(block)) / 2e6
            rows[:, 1], rows[:, 2] = rng.integers(0, 640, block), rng.integers(0, 480, block)
            rows[:, 3] = rng.integers(0, 2, block)
            f.write(rows.tobytes())
    size_mb = path.stat().st_size / 2**20
    run = subprocess.run([sys.executable, "-c", BOUNDED, str(path)], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    result = json.loads(run.stdout.strip().splitlines()[-1])
    assert result["n_events"] == n
    assert result["n_read"] > 8_000_000   # 11 windows of 2 % and 0.5 s: the windows were really read
    assert result["peak_mb"] < size_mb / 4, (result, size_mb)


def test_times_that_fall_back_once_are_named_as_joined_recordings(tmp_path):
    """Two takes joined (or a clock that restarted) fall back once: sorting would interleave them, and the
    refusal says so; a shuffled file falls back many times and gets the sort alone."""
    from evinr_lite.core.events import Events

    t, x, y, p = _events()
    half = len(t) // 2
    joined = np.concatenate([t[half:], t[:half]])                       # the second part's clock starts again
    np.save(tmp_path / "joined.npy", np.stack([joined, x, y, p], 1))
    for refuse in (lambda: open_recording(tmp_path / "joined.npy", sensor_size=(H, W)),
                   lambda: Events(joined, x, y, p, (H, W))):
        with pytest.raises(EventDataError, match="not sorted.*fall back only once.*interleave") as err:
            refuse()
        assert "split the file" in str(err.value)
    shuffled = np.random.default_rng(0).permutation(t)
    np.save(tmp_path / "shuffled.npy", np.stack([shuffled, x, y, p], 1))
    with pytest.raises(EventDataError, match="not sorted") as err:
        open_recording(tmp_path / "shuffled.npy", sensor_size=(H, W))
    assert "fall back only once" not in str(err.value)
