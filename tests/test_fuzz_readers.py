"""Property-based test of every reader on damaged input (hypothesis).

Valid files of every format are mutated (truncated at random offsets, bytes flipped, inserted and
deleted, junk lines inserted; for HDF5 also datasets retyped and attributes removed or retyped) and
read with :func:`evinr_lite.io.load.read_any` (``read_recording`` with the sensor size passed only to
the formats that take it, as the command line reads). Each read must either return valid events (sorted finite
float64 seconds, coordinates inside the sensor, polarity -1/+1) or raise the package's input error
(:class:`evinr_lite.core.events.InputError`, e.g. EventDataError). Any other exception, a hang or
a Rust panic is a failure.

Normal run: 2,000 cases per format (deterministic: ``derandomize=True``), a few seconds each.
``EVINR_FUZZ_LONG=1`` runs 20,000 per format (``EVINR_FUZZ_EXAMPLES=N`` sets any number).
The counts of each outcome are printed at the end (``pytest -s``) and kept in ``OUTCOMES``.
"""
import collections
import os
import shutil
import tempfile
import warnings
from pathlib import Path

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings, strategies as st  # noqa: E402

from evinr_lite.io.load import read_any  # noqa: E402
from evinr_lite.core.events import InputError  # noqa: E402

EXAMPLES = int(os.environ.get("EVINR_FUZZ_EXAMPLES") or (20_000 if os.environ.get("EVINR_FUZZ_LONG") == "1" else 2_000))
FUZZ = settings(max_examples=EXAMPLES, deadline=None, derandomize=True, database=None,
                suppress_health_check=list(HealthCheck), print_blob=True)
OUTCOMES = collections.defaultdict(collections.Counter)   # format -> {"events": n, "input error": n}
H, W = 12, 16


def _events(n=60, seed=0, t0=0.0):
    rng = np.random.default_rng(seed)
    t = np.sort(t0 + rng.uniform(0, 0.05, n))
    return t, rng.integers(0, W, n), rng.integers(0, H, n), rng.integers(0, 2, n)


# ---- one valid fixture per format: {relative file name: bytes} (files to mutate) + the path to read ---

def _fixtures(root: Path) -> dict:
    from PIL import Image

    t, x, y, p = _events()
    out = {}

    d = root / "npy"
    d.mkdir()
    np.save(d / "ev.npy", np.stack([t, x, y, p * 2 - 1], axis=1))
    out["npy"] = (d, "ev.npy", ["ev.npy"], dict(sensor_size=(H, W)))

    d = root / "txt"
    d.mkdir()
    (d / "ev.txt").write_text(f"{W} {H}\n" + "".join(f"{a:.9f} {b} {c} {e}\n" for a, b, c, e in zip(t, x, y, p)))
    out["txt"] = (d, "ev.txt", ["ev.txt"], {})

    d = root / "csv"   # Metavision's layout: a geometry line, then x,y,p,t in microseconds
    d.mkdir()
    (d / "ev.csv").write_text(f"%geometry:{W},{H}\n" + "".join(f"{b},{c},{e},{int(round(a * 1e6))}\n"
                                                              for a, b, c, e in zip(t, x, y, p)))
    out["csv"] = (d, "ev.csv", ["ev.csv"], {})

    d = root / "ijrr" / "seq"
    (d / "images").mkdir(parents=True)
    t_abs = t + 1_468_939_993.0
    (d / "events.txt").write_text("".join(f"{a:.9f} {b} {c} {e}\n" for a, b, c, e in zip(t_abs, x, y, p)))
    for k in range(2):
        Image.fromarray(np.full((H, W), 40 * k + 20, np.uint8)).save(d / "images" / f"frame_{k:08d}.png")
    (d / "images.txt").write_text(f"{t_abs[0]:.9f} images/frame_00000000.png\n{t_abs[-1]:.9f} images/frame_00000001.png\n")
    (d / "calib.txt").write_text("200 200 8 6 0 0 0 0 0\n")
    out["ijrr"] = (d, ".", ["events.txt", "images.txt", "calib.txt", "images/frame_00000000.png"], {})

    d = root / "evreal" / "seq"
    d.mkdir(parents=True)
    np.save(d / "events_ts.npy", t)
    np.save(d / "events_xy.npy", np.stack([x, y], axis=1).astype(np.int16))
    np.save(d / "events_p.npy", p.astype(np.uint8))
    np.save(d / "images.npy", np.full((2, H, W, 1), 100, np.uint8))
    np.save(d / "images_ts.npy", np.array([t[0], t[-1]]))
    (d / "metadata.json").write_text(f'{{"sensor_resolution": [{H}, {W}]}}')
    out["evreal"] = (d, ".", ["events_ts.npy", "events_xy.npy", "events_p.npy", "images.npy", "images_ts.npy",
                              "metadata.json"], {})

    import h5py

    d = root / "h5"
    d.mkdir()
    with h5py.File(d / "hqf.h5", "w") as f:
        f.create_dataset("events/xs", data=x.astype(np.int16))
        f.create_dataset("events/ys", data=y.astype(np.int16))
        f.create_dataset("events/ts", data=t)
        f.create_dataset("events/ps", data=p.astype(bool))
        f.attrs["sensor_resolution"] = (H, W)
        for k, stamp in enumerate((t[0], t[-1])):
            im = f.create_dataset(f"images/image{k:09d}", data=np.full((H, W), 90, np.uint8))
            im.attrs["timestamp"] = stamp
    out["h5"] = (d, "hqf.h5", ["hqf.h5"], {})

    d = root / "dsec"   # uncompressed: a damaged Blosc stream is the codec's to survive, not the reader's
    d.mkdir()
    with h5py.File(d / "events.h5", "w") as f:
        f.create_dataset("events/x", data=x.astype(np.uint16))
        f.create_dataset("events/y", data=y.astype(np.uint16))
        f.create_dataset("events/t", data=np.round(t * 1e6).astype(np.uint32))
        f.create_dataset("events/p", data=p.astype(np.uint8))
        f["t_offset"] = np.int64(47_000_000)
    out["dsec"] = (d, "events.h5", ["events.h5"], dict(sensor_size=(H, W)))

    d = root / "mvsec"
    d.mkdir()
    with h5py.File(d / "seq_data.hdf5", "w") as f:
        f.create_dataset("davis/left/events", data=np.stack([x, y, t + 1_504_643_000.0, p * 2.0 - 1], axis=1))
        f.create_dataset("davis/left/image_raw", data=np.full((2, H, W), 80, np.uint8))
        f.create_dataset("davis/left/image_raw_ts", data=np.array([t[0], t[-1]]) + 1_504_643_000.0)
    out["mvsec"] = (d, "seq_data.hdf5", ["seq_data.hdf5"], {})

    from evinr_lite.io.canonical import CanonicalWriter

    d = root / "canonical"
    d.mkdir()
    with CanonicalWriter(d / "seq.h5", sensor_size=(H, W), dataset="test", sequence="seq", C=0.5,
                         eval_window=(0.0, 0.04)) as writer:
        writer.add_events(t, x, y, p * 2 - 1)
        writer.add_frame(np.full((H, W), 70, np.uint8), float(t[0]))
    out["canonical"] = (d, "seq.h5", ["seq.h5"], {})

    faery = pytest.importorskip("faery")
    packet = np.zeros(len(t), dtype=faery.EVENTS_DTYPE)
    packet["t"] = (np.round(t * 1e6) + 1_650_000_000_000_000).astype(np.uint64)
    packet["x"], packet["y"], packet["on"] = x, y, p > 0
    for name, fname, version in (("aedat4", "rec.aedat4", None), ("prophesee_raw", "rec.raw", "evt3"),
                                 ("prophesee_dat", "rec.dat", None)):
        d = root / name
        d.mkdir()
        faery.events_stream_from_array(packet, dimensions=(W, H)).to_file(d / fname, version=version)
        out[name] = (d, fname, [fname], {})
    d = root / "prophesee_evt21"        # decoded by the kit (io/formats/evt21.py), the IMX636's word order
    d.mkdir()
    t_us = np.round(t * 1e6).astype(np.uint64) + np.uint64(7_000_000)
    words = []
    for i in range(len(t)):
        if i == 0 or t_us[i] >> 6 != t_us[i - 1] >> 6:
            words.append((0x8 << 60) | (int(t_us[i] >> 6) << 32))
        words.append((int(p[i] > 0) << 60) | ((int(t_us[i]) & 0x3F) << 54) | (int(y[i]) << 32) | (1 << int(x[i])))
    words = np.array(words, np.uint64)
    words = (words << np.uint64(32)) | (words >> np.uint64(32))
    (d / "rec.raw").write_bytes(f"% evt 2.1\n% format EVT21;height={H};width={W}\n% end\n".encode()
                                + words.astype("<u8").tobytes())
    out["prophesee_evt21"] = (d, "rec.raw", ["rec.raw"], {})
    d = root / "aedat3"                 # decoded by the kit (io/formats/aedat3.py): libcaer's packets
    d.mkdir()
    t_us = np.round(t * 1e6).astype(np.int64) + ((1 << 31) - 25_000)      # across the 31-bit timestamp's overflow
    packets = []
    for lo, hi in ((0, 20), (20, 45), (45, len(t))):
        ev = np.zeros(hi - lo, [("data", "<u4"), ("ts", "<i4")])
        ev["data"] = (x[lo:hi] << 17) | (y[lo:hi] << 2) | ((p[lo:hi] > 0) << 1) | 1
        ev["ts"] = t_us[lo:hi] & 0x7FFFFFFF
        n, ovf = hi - lo, int(t_us[lo] >> 31)
        packets.append(np.array([1, 1], "<i2").tobytes() + np.array([8, 4, ovf, n, n, n], "<i4").tobytes()
                       + ev.tobytes())                 # type 1 (polarity), source 1; size, offset, overflow, counts
    frame = np.array([3, 100, 200, 110, 190, W, H, 0, 0], "<i4").tobytes() + np.arange(H * W, dtype="<u2").tobytes()
    packets.insert(1, np.array([2, 1], "<i2").tobytes() + np.array([len(frame), 4, 0, 1, 1, 1], "<i4").tobytes() + frame)
    header = (f'#!AER-DAT3.1\r\n#Format: RAW\r\n#Source 1: PROTO\r\n#-Source 1: <attr key="dvsSizeX" type="short">{W}'
              f'</attr><attr key="dvsSizeY" type="short">{H}</attr>\r\n#!END-HEADER\r\n')
    (d / "rec.aedat").write_bytes(header.encode() + b"".join(packets))
    out["aedat3"] = (d, "rec.aedat", ["rec.aedat"], {})
    return out


@pytest.fixture(scope="module")
def fixtures():
    root = Path(tempfile.mkdtemp(prefix="evinr-fuzz-"))
    try:
        yield _fixtures(root)
    finally:
        shutil.rmtree(root, ignore_errors=True)


# ---- mutations -------------------------------------------------------------------------------------

JUNK_LINES = [b"\n", b"nan 1 2 1\n", b"0.1 1 2\n", b"1e400 1 1 1\n", b"-5 -1 -1 7\n", b"0.2 99999 3 1\n",
              b"\xff\xfe\x00junk\n", b"0.1 1.5 2 1\n", b"inf inf inf inf\n", b"1 2\n", b"# comment\n"]
mutation = st.one_of(
    st.tuples(st.just("truncate"), st.integers(0, 1 << 20)),
    st.tuples(st.just("flip"), st.integers(0, 1 << 20), st.integers(1, 255)),
    st.tuples(st.just("insert"), st.integers(0, 1 << 20), st.binary(min_size=1, max_size=16)),
    st.tuples(st.just("delete"), st.integers(0, 1 << 20), st.integers(1, 64)),
    st.tuples(st.just("junk_line"), st.integers(0, 1 << 20), st.sampled_from(JUNK_LINES)),
)


def mutate(data: bytes, ops) -> bytes:
    b = bytearray(data)
    for op in ops:
        at = op[1] % (len(b) + 1)
        if op[0] == "truncate":
            del b[at:]
        elif op[0] == "flip" and b:
            b[at % len(b)] ^= op[2]
        elif op[0] == "insert":
            b[at:at] = op[2]
        elif op[0] == "delete":
            del b[at:at + op[2]]
        elif op[0] == "junk_line":
            nl = b.find(b"\n", at)
            at = len(b) if nl < 0 else nl + 1
            b[at:at] = op[2]
    return bytes(b)


def check_events(events):
    H_, W_ = events.sensor_size
    assert events.t.dtype == np.float64 and np.all(np.isfinite(events.t))
    assert np.all(np.diff(events.t) >= 0)
    assert np.all((events.x >= 0) & (events.x < W_)) and np.all((events.y >= 0) & (events.y < H_))
    assert set(np.unique(events.p).tolist()) <= {-1, 1}


def read_and_classify(kind, path, kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            rec = read_any(path, **kwargs)
        except InputError as err:
            assert str(err), "an input error needs a message"
            OUTCOMES[kind]["input error"] += 1
            return
    check_events(rec.events)
    OUTCOMES[kind]["events"] += 1


FORMATS = ["npy", "txt", "csv", "ijrr", "evreal", "h5", "dsec", "mvsec", "canonical", "aedat4", "prophesee_raw", "prophesee_dat",
           "prophesee_evt21", "aedat3"]


@pytest.mark.parametrize("kind", FORMATS)
def test_mutated_files_give_events_or_an_input_error(fixtures, kind):
    folder, target, files, kwargs = fixtures[kind]
    work = Path(tempfile.mkdtemp(prefix=f"evinr-fuzz-{kind}-"))
    originals = {name: (folder / name).read_bytes() for name in files}

    @FUZZ
    @given(which=st.sampled_from(files), ops=st.lists(mutation, min_size=1, max_size=4))
    def case(which, ops):
        case_dir = work / "case"
        if case_dir.exists():
            shutil.rmtree(case_dir)
        shutil.copytree(folder, case_dir)
        (case_dir / which).write_bytes(mutate(originals[which], ops))
        read_and_classify(kind, case_dir / target, kwargs)

    try:
        case()
    finally:
        shutil.rmtree(work, ignore_errors=True)
    assert sum(OUTCOMES[kind].values()) >= EXAMPLES
    assert OUTCOMES[kind]["input error"] > 0          # the mutations do damage files


H5_EDITS = ["drop_dataset", "retype_dataset", "drop_attr", "attr_to_text", "attr_to_nan", "shorten_dataset"]


@pytest.mark.parametrize("kind", ["h5", "dsec", "mvsec", "canonical"])
def test_hdf5_structure_edits_give_events_or_an_input_error(fixtures, kind):
    import h5py

    folder, target, _, kwargs = fixtures[kind]
    work = Path(tempfile.mkdtemp(prefix=f"evinr-fuzz-{kind}-edit-"))

    def names(f):
        found = []
        f.visit(lambda n: found.append(n) if isinstance(f[n], h5py.Dataset) else None)
        return sorted(found)

    with h5py.File(folder / target, "r") as f:
        datasets, attrs = names(f), sorted(f.attrs)

    @FUZZ
    @given(edits=st.lists(st.tuples(st.sampled_from(H5_EDITS), st.integers(0, 1000),
                                    st.sampled_from(["S8", "f4", "i1", "u8", "f8"])), min_size=1, max_size=3))
    def case(edits):
        path = work / target
        shutil.copy(folder / target, path)
        with h5py.File(path, "r+") as f:
            for edit, k, dtype in edits:
                ds = datasets[k % len(datasets)]
                if edit == "drop_dataset" and ds in f:
                    del f[ds]
                elif edit == "retype_dataset" and ds in f:
                    data = f[ds][()]
                    del f[ds]
                    f.create_dataset(ds, data=np.zeros(np.shape(data), dtype) if dtype != "S8"
                                     else np.full(np.shape(data), b"x", "S8"))
                elif edit == "shorten_dataset" and ds in f:
                    data = f[ds][()]
                    del f[ds]
                    f.create_dataset(ds, data=data[: max(0, len(data) // 2)] if np.ndim(data) else data)
                elif attrs:
                    name = attrs[k % len(attrs)]
                    if edit == "drop_attr" and name in f.attrs:
                        del f.attrs[name]
                    elif edit == "attr_to_text":
                        f.attrs[name] = "not a number"
                    elif edit == "attr_to_nan":
                        f.attrs[name] = np.nan
        read_and_classify(f"{kind} (structure)", path, kwargs)

    try:
        case()
    finally:
        shutil.rmtree(work, ignore_errors=True)
    assert sum(OUTCOMES[f"{kind} (structure)"].values()) >= EXAMPLES


def teardown_module(module):
    print("\nfuzz outcomes (cases per format):")
    for kind, counts in sorted(OUTCOMES.items()):
        print(f"  {kind:26s} {sum(counts.values()):6d} cases: {counts['events']:6d} valid events, "
              f"{counts['input error']:6d} input errors, 0 other exceptions")
