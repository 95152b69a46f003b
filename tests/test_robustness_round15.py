"""Round 15 of the bad-input table (tests/test_robustness*.py): public functions no earlier round called with bad
arguments: data_fetch's Python API (its registry's names, the weights' files, a conversion's settings), the
canonical HDF5 file's writer and reader (evinr_lite.io.canonical), the readers' keyword options through
``read_recording``, the output folder of every job (evinr_lite.io.output.OutputDir) and the demo and reconstruct
jobs called from Python (evinr_lite.apps.demo.run_demo, evinr_lite.apps.recon_job.run_reconstruct).

177 cases, 167 of which failed before their fixes (the other 10 are the guards; 33 cases of section 8, the review's,
31 of which failed before its fixes).

Fixes (each test failed before its fix): data_fetch's ``list_datasets`` / ``canonical_path`` / ``raw_path`` /
``get`` / ``get_all`` of a dataset None, 5 or a list and ``weights_dir`` / ``get_weights`` of such a weight set were
"has no attribute 'lower'"; a sequence of None or 5 was Python's error or a file named "None.h5", and "", ".", "..",
"../x" or "a/b" made paths outside the dataset's folders (an AED folder placed by hand at <cache>/raw/aed itself);
``get_weights(files="nope")`` was read letter by letter ("no file 'n'") and files None or 5 were Python's errors.
``check_settings`` (so ``convert``) stored a sensor size of (2.5, 3) as (2, 3), (True, 3) as (1, 3) and took sizes
as text; a time unit given as a list was "unhashable type". ``CanonicalWriter`` took a sensor of 2.5 rows (written
as 2), a NaN or negative C, a NaN t_origin, a reversed or NaN eval_window and a dataset of 5, failed at close (after
every event was written) on meta that JSON cannot hold and on a sequence of None, and its other bad settings were
Python's errors; ``add_events`` wrote x = 1.5 as 1 and NaN as 0, and text times were numpy's error; ``add_frame`` of
a time "a", None or [0.1] was Python's "must be real number" and True was 1 s. ``read_canonical``,
``canonical_info``, ``CanonicalSource``, ``iter_canonical_events``, ``is_canonical``, ``data_fetch.read`` /
``info`` of a path None or 5 were Python's "expected str, bytes or os.PathLike object"; a window of text or a list
was blamed on the file ("damaged or incomplete") and True was read as 1 s; ``iter_canonical_events`` gave no chunk
for a NaN window, took "0" as seconds, and a chunk_events of 2.5, "5", None or NaN was Python's error (True one event
a chunk); ``frames="no"`` read the frames. Through ``read_recording``: the .npy, .txt and .csv readers (which pass
``**options`` on) raised Python's bare "unexpected keyword argument" for an option they do not take; a time_unit
given as a list or dict was "unhashable type" (``Events.from_arrays`` too); a t_origin of text or a list was
Python's "must be real number" and True was 1 s; an IJRR folder took sensor_size=(12.5, 12) as (12, 12); a window
bound of True was 1 s. ``OutputDir`` (every job's output folder) of None, 5 or 1.5 was Python's TypeError,
``overwrite="no"`` replaced an existing folder, and a log of 5 or a command of 5 were taken (the command written in
the lock). ``run_demo`` took n_frames=True (one frame), 2.5 and "4" were Python's errors and 0 blamed query_times
nobody passed, ``config={}`` ran the default recipe, log=5 failed after the simulation, an out_dir of None, 5 or
bytes failed after the training, an existing folder was refused after the training and a sensor under 11 x 11
pixels was refused by SSIM after the training. ``run_reconstruct`` took ``resume="yes"`` and 5, and a path of None,
5 or 1.5 was Python's TypeError.

Review fixes (section 8; each test failed before its fix, on this branch before the review): round 15's window check
took only int and float, so a window of a 0-d array, a tensor, a Fraction or a Decimal, which ``read_canonical``,
``iter_canonical_events`` and ``data_fetch.read`` took before, was refused: the check is now
``core.checks.check_reader_window``, built on ``optional_seconds`` (every windowed reader uses it; a Decimal is taken
as its float). A t_origin, C or frame time of Fraction or Decimal (``float()`` took them) was refused as "no finite
number": ``check_t_origin`` takes any real number and Decimal (the text readers' nanoseconds stay exact, through
Fraction), the writer's C and frame time take Decimal too; ``origin_to_ns`` of np.float32 or a 0-d array (which its
check took) was Python's TypeError (now their ``.item()``). ``get_weights`` showed the tuple made of what was passed
((5,), (None,), the bytes' numbers) and ``get("lpips", 5)`` blamed files=: the message shows the value, get checks
its sequence first. The demo command's small-sensor message named --sensor (the command line's spelling of
sensor_size=); the demo's flag is --size. ``convert(sequence="../evil")`` and "a/b" (and ``convert --sequence``)
still wrote outside the cache: the name is checked first. ``run_reconstruct`` let a path of bytes through to
Python's TypeError: it is read as ``read_recording`` reads it (os.fsdecode). The output folder's refusals are tested
on a fresh folder (an existing one was refused for being there). One check each: SSIM's 11 pixels
(``evaluation.metrics.SSIM_MIN_SIDE``), a flag (``true_or_false``, ``run_batch``'s sequential too), a log
(``check_log``) and a path (``check_path_type``; ``run_batch``'s log=5 and out_dir=None are now TypeErrors as the
other jobs'); the demo command checked its folder twice; io/text.py imported math unused.

Refused on purpose where they were taken before: a sensor size as text in ``convert`` (("180", "240")), a canonical
file's text attributes that are no text (dataset=5 was written as a number), frames= of None or 0.5 for the
canonical reader (None skipped the frames), ``overwrite`` / ``resume`` of None (read as False) or of a number other
than 0 and 1 (1.0 was true), a demo sensor under 11 x 11 (it failed after the training), a sequence given as a Path
(``canonical_path("ijrr", Path("slider_depth"))``), x / y of bools or Python objects in ``add_events``, and False as a
time (a t_origin, a window bound, a frame time: it was 0 s), as True is (it was 1 s): a flag given where a time
belongs.

Left as they are: the other readers' declared-or-given sensor sizes (``sensor_from_header`` / ``check_declared_size``
compare int() of the given size with the file's: a 12.5 is refused there only when the file's size differs),
data_fetch's converters' own keywords (``convert_bag`` / ``convert_h5`` / ``convert_ijrr``: ``convert`` checks them
first), ``guess_sequence`` / ``ced_category`` (internal helpers taking a Path / a registered name) and the
downloads' ``retries`` (the loopback tests of test_data_fetch.py cover them); data_fetch raises its DataFetchError
(a RuntimeError, which its command line prints) rather than a ValueError, as the rest of data_fetch does.

Guards: odd inputs next to these that already behave and must keep their outcome (np.str_ names, a dataset's
alias and capitals, an AED name with dots and dashes, numpy and whole-float sizes, float32 C and times, an eval
window as an array, whole float and int32 coordinates, float32 polarities, frames of another size than the events,
np.int64 / np.float32 windows, chunk_events as np.int64, frames as np.bool_ or 1, Paths as text, an IJRR size of
(12.0, np.int64(12)), time_unit as np.str_, overwrite as np.bool_ / 0 / 1, log=None, n_frames as np.int64, and the
existing refusals next to the new ones).
"""
import json
import warnings
from decimal import Decimal
from fractions import Fraction

import numpy as np
import pytest

import data_fetch
from data_fetch import DataFetchError
from data_fetch.conversion import check_settings
from evinr_lite import EvINRConfig, EventDataError, Events, read_recording
from evinr_lite.apps.demo import run_demo
from evinr_lite.apps.recon_job import run_reconstruct
from evinr_lite.io.canonical import (CanonicalSource, CanonicalWriter, canonical_info, is_canonical,
                                     iter_canonical_events, read_canonical)
from evinr_lite.io.output import OutputDir, atomic_output_dir
from evinr_lite.sim import make_scene, simulate_scene, write_example_recording

from refusals import all_refused as _none_of, refused as _no   # noqa: E402  (shared by rounds 11-15)

EV = simulate_scene(make_scene("bar", sensor_size=(12, 12), duration=0.2), C=0.2)
P = np.where(EV.p > 0, 1, -1)
QUIET = lambda *a: None   # noqa: E731
FAST = EvINRConfig(n_iters=0, progress=False)


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("EVINR_DATA", str(tmp_path / "cache"))
    return tmp_path / "cache"


def _canonical(path, **kw):
    with CanonicalWriter(path, **{"sensor_size": (12, 12), **kw}) as w:
        w.add_events(EV.t, EV.x, EV.y, P)
        w.add_frame(np.zeros((12, 12), np.uint8), 0.1)
    return path


@pytest.fixture
def h5(tmp_path):
    return _canonical(tmp_path / "c.h5")


@pytest.fixture
def files(tmp_path):
    """The same events as .npy, .txt (0/1 polarities) and .csv (integer microseconds), and an IJRR folder."""
    np.save(tmp_path / "e.npy", np.stack([EV.t, EV.x, EV.y, EV.p], 1))
    rows = zip(EV.t, EV.x, EV.y, (EV.p > 0).astype(int))
    (tmp_path / "e.txt").write_text("".join(f"{t:.6f} {x} {y} {p}\n" for t, x, y, p in rows))
    rows = zip(np.round(EV.t * 1e6).astype(int), EV.x, EV.y, (EV.p > 0).astype(int))
    (tmp_path / "e.csv").write_text("t,x,y,p\n" + "".join(f"{t},{x},{y},{p}\n" for t, x, y, p in rows))
    write_example_recording(tmp_path / "ijrr", sensor_size=(12, 12), duration=0.2)
    return tmp_path


def _read(path, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return read_recording(path, **kw)


# ---- 1. data_fetch's names -----------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", [None, 5, ["ijrr"], b"ijrr"])
def test_data_fetch_refuses_a_dataset_name_that_is_no_text(cache, name):
    """None, 5 or a list were "has no attribute 'lower'", bytes an unknown dataset (list_datasets(None) lists all)."""
    calls = [lambda: data_fetch.canonical_path(name, "slider_depth"), lambda: data_fetch.raw_path(name, "slider_depth"),
             lambda: data_fetch.get(name, "slider_depth"), lambda: data_fetch.get_all(name)]
    _none_of(calls + ([lambda: data_fetch.list_datasets(name)] if name is not None else []), r"dataset must be a name",
             DataFetchError)


@pytest.mark.parametrize("name", [None, 5, ["lpips"]])
def test_data_fetch_refuses_a_weight_set_name_that_is_no_text(cache, name):
    _none_of([lambda: data_fetch.weights_dir(name), lambda: data_fetch.get_weights(name)],
             r"weight set must be a name", DataFetchError)


@pytest.mark.parametrize("dataset", ["ijrr", "aed"])
@pytest.mark.parametrize("sequence", [None, 5, "", " ", ".", "..", "../x", "a/b", "a\\b"])
def test_data_fetch_refuses_a_sequence_name_that_is_no_name(cache, dataset, sequence):
    _none_of([lambda: data_fetch.canonical_path(dataset, sequence), lambda: data_fetch.raw_path(dataset, sequence),
              lambda: data_fetch.get(dataset, sequence, progress=False)], r"sequence must be", DataFetchError)
    assert not cache.exists()


@pytest.mark.parametrize("files", [None, 5, [None]])
def test_get_weights_refuses_files_that_are_no_names(cache, files):
    _no(lambda: data_fetch.get_weights("lpips", files, progress=False), r"files= must be", DataFetchError)


def test_get_weights_reads_one_name_as_one_file(cache):
    """files="nope" was read letter by letter: "has no file 'n'"."""
    _no(lambda: data_fetch.get_weights("lpips", "nope", progress=False), r"no file 'nope'", DataFetchError)


def test_data_fetch_names_as_before(cache):
    rows = data_fetch.list_datasets()
    assert data_fetch.list_datasets("IJRR") == [r for r in rows if r["dataset"] == "ijrr"]
    assert data_fetch.list_datasets("ecd") == data_fetch.list_datasets(np.str_("ijrr"))
    assert data_fetch.canonical_path("ijrr", "slider_depth") == cache / "ijrr" / "slider_depth.h5"
    assert data_fetch.canonical_path("ijrr", np.str_("slider_depth")) == cache / "ijrr" / "slider_depth.h5"
    assert data_fetch.raw_path("ijrr", "slider_depth") == cache / "raw" / "ijrr" / "slider_depth.zip"
    assert data_fetch.raw_path("aed", "my_take-2.v1") == cache / "raw" / "aed" / "my_take-2.v1"
    assert data_fetch.weights_dir("LPIPS") == cache / "weights" / "lpips"
    _no(lambda: data_fetch.get("nope", "x"), r"unknown dataset 'nope'", DataFetchError)
    _no(lambda: data_fetch.raw_path("ijrr", "nope"), r"ijrr has no sequence 'nope'", DataFetchError)
    _no(lambda: data_fetch.get_weights("lpips", ["alexnet", "nope"]), r"no file 'nope'", DataFetchError)
    assert not cache.exists()


# ---- 2. a conversion's settings (data_fetch.convert) ---------------------------------------------------------------

@pytest.mark.parametrize("size", [(2.5, 3), (True, 3), ("180", "240")])
def test_check_settings_refuses_a_sensor_size_that_is_no_two_whole_numbers(size):
    """(2.5, 3) was stored as (2, 3) without a word, (True, 3) as (1, 3)."""
    _no(lambda: check_settings(sensor_size=size), r"sensor.size must be \(H, W\)", DataFetchError)


@pytest.mark.parametrize("unit", [["s"], {"s": 1}])
def test_convert_refuses_a_time_unit_that_is_no_name(tmp_path, unit):
    """A list was Python's "unhashable type"."""
    _no(lambda: data_fetch.convert(tmp_path, tmp_path / "out.h5", time_unit=unit), r"time unit must be one of",
        DataFetchError)


def test_check_settings_as_before():
    check_settings(C=0.2, sensor_size=(np.int64(180), 240.0), eval_window=(0, 1), time_unit="us")
    check_settings(sensor_size=[180, 240], time_unit="auto")
    _no(lambda: check_settings(sensor_size=(0, 240)), r"sensor.size must be \(H, W\)", DataFetchError)
    _no(lambda: check_settings(sensor_size=(180, np.nan)), r"sensor.size must be \(H, W\)", DataFetchError)
    _no(lambda: check_settings(time_unit="h"), r"time unit must be one of", DataFetchError)


# ---- 3. the canonical file's writer --------------------------------------------------------------------------------

@pytest.mark.parametrize("kw,pattern", [
    (dict(sensor_size=(2.5, 12)), r"sensor_size must be \(H, W\)"), (dict(sensor_size=None), r"sensor_size must be"),
    (dict(sensor_size=(0, 12)), r"sensor_size must be \(H, W\) with positive"),
    (dict(C=float("nan")), r"C= must be a finite number > 0"), (dict(C=-1), r"C= must be"), (dict(C="a"), r"C= must be"),
    (dict(C=None), r"C= must be"),
    (dict(t_origin=float("nan")), r"t_origin must be a finite number"), (dict(t_origin="a"), r"t_origin must be"),
    (dict(eval_window=(1, 0)), r"eval_window .* reversed"), (dict(eval_window=(0, float("nan"))), r"eval_window"),
    (dict(eval_window=5), r"eval_window must be \(start, end\)"),
    (dict(meta={"a": object()}), r"meta= must be a dict of JSON"), (dict(meta={"a": np.float32(1)}), r"meta= must be"),
    (dict(meta=5), r"meta= must be a dict"), (dict(meta=[1]), r"meta= must be a dict"),
    (dict(dataset=5), r"dataset= must be text"), (dict(sequence=None), r"sequence= must be text")])
def test_canonical_writer_refuses_settings_before_any_file(tmp_path, kw, pattern):
    """Each was taken (a NaN C, a reversed window, 2.5 rows as 2, a dataset of 5) or failed after the events were
    written (meta that JSON cannot hold, a sequence of None: h5py's TypeError at close) or was Python's error."""
    _no(lambda: CanonicalWriter(tmp_path / "c.h5", **{"sensor_size": (12, 12), **kw}), pattern)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("cols,pattern", [
    (([0.0], [1.5], [0], [1]), r"x must be whole"), (([0.0], [np.nan], [0], [1]), r"x must be whole"),
    (([0.0], [1], [0.5], [1]), r"y must be whole"), (([0.0], ["1"], [0], [1]), r"x must be whole"),
    ((["a"], [1], [0], [1]), r"t must be numbers")])
def test_canonical_writer_refuses_events_that_are_no_numbers(tmp_path, cols, pattern):
    """x = 1.5 was written as 1, NaN as 0 (numpy's cast); text was numpy's error."""
    with CanonicalWriter(tmp_path / "c.h5", sensor_size=(12, 12)) as w:
        _no(lambda: w.add_events(*cols), pattern)
        w.add_events([0.0, 0.1], [1, 2], [3, 4], [1, -1])
    assert len(read_canonical(tmp_path / "c.h5").events) == 2


@pytest.mark.parametrize("t", ["a", None, [0.1], True])
def test_canonical_writer_refuses_a_frame_time_that_is_no_number(tmp_path, t):
    with CanonicalWriter(tmp_path / "c.h5", sensor_size=(12, 12)) as w:
        w.add_events([0.0, 0.1], [1, 2], [3, 4], [1, -1])
        _no(lambda: w.add_frame(np.zeros((12, 12), np.uint8), t), r"frame time must be a finite number")


def test_canonical_writer_as_before(tmp_path):
    """Whole floats, numpy numbers, float32 times and frames of another size (AED) keep working."""
    meta = {"calib": [1.0, 2.0], "note": "x", "n": 3, "nested": {"a": None}}
    with CanonicalWriter(tmp_path / "a.h5", sensor_size=(np.int64(12), 12.0), C=np.float32(0.25), t_origin=np.int64(5),
                         eval_window=np.array([0.0, 0.1]), meta=meta, dataset="d") as w:
        w.add_events(EV.t, EV.x.astype(np.float64), EV.y.astype(np.int32), P.astype(np.float32))
        w.add_frame(np.zeros((6, 6), np.uint8), np.float32(0.1))
        w.add_frame(np.zeros((6, 6), np.uint8), np.int64(0))
    info = canonical_info(tmp_path / "a.h5")
    assert info["sensor_size"] == (12, 12) and info["meta"]["calib"] == [1.0, 2.0] and info["dataset"] == "d"
    assert np.array_equal(read_canonical(tmp_path / "a.h5").events.x, EV.x)


# ---- 4. the canonical file's reader --------------------------------------------------------------------------------

@pytest.mark.parametrize("path", [None, 5, [b"c.h5"]])
def test_canonical_reader_refuses_a_path_that_is_no_path(path):
    _none_of([lambda: read_canonical(path), lambda: canonical_info(path), lambda: CanonicalSource(path),
              lambda: list(iter_canonical_events(path)), lambda: is_canonical(path), lambda: data_fetch.read(path),
              lambda: data_fetch.info(path)], r"path= must be a file", TypeError)


@pytest.mark.parametrize("window", [("0", None), (None, "0.1"), ([0.0], None), (True, None), (None, np.bool_(True))])
def test_canonical_reader_refuses_a_window_that_is_no_seconds(h5, window):
    """Text and lists were blamed on the file ("damaged or incomplete"), True read as 1 s."""
    _none_of([lambda: read_canonical(h5, *window), lambda: list(iter_canonical_events(h5, *window))],
             r"must be a finite number of seconds")


def test_iter_canonical_events_refuses_a_nan_window(h5):
    """NaN gave no chunk without a word (read_canonical refused it)."""
    _none_of([lambda: list(iter_canonical_events(h5, np.nan)), lambda: list(iter_canonical_events(h5, None, np.inf))],
             r"must be a finite number of seconds")


@pytest.mark.parametrize("chunk", [2.5, "5", None, True, np.nan])
def test_iter_canonical_events_refuses_a_chunk_that_is_no_count(h5, chunk):
    _no(lambda: list(iter_canonical_events(h5, chunk_events=chunk)), r"chunk_events= must be a whole number >= 1")


@pytest.mark.parametrize("frames", ["no", None, 0.5])
def test_canonical_reader_refuses_frames_that_is_no_flag(h5, frames):
    """"no" read the frames (a true value), None did not."""
    _none_of([lambda: read_canonical(h5, frames=frames), lambda: CanonicalSource(h5, frames=frames)],
             r"frames= must be True or False")


def test_canonical_reader_as_before(h5):
    whole = read_canonical(h5)
    assert len(read_canonical(h5, np.int64(0), np.float32(0.1)).events) == int(np.sum(EV.t < np.float32(0.1)))
    assert read_canonical(h5, frames=np.bool_(False)).frames is None and read_canonical(h5, frames=1).frames is not None
    sizes = [len(c) for c in iter_canonical_events(h5, chunk_events=np.int64(500))]
    assert sum(sizes) == len(whole.events) and sizes[0] == 500
    assert is_canonical(str(h5)) and not is_canonical(h5.parent / "none.h5")
    with CanonicalSource(str(h5), frames=False) as src:
        assert src.frames is None and src.n_events == len(whole.events)
    _no(lambda: read_canonical(h5, 0.1, 0.05), r"empty or reversed")
    _none_of([lambda: list(iter_canonical_events(h5, chunk_events=0)),
              lambda: list(iter_canonical_events(h5, chunk_events=-1))], r"chunk_events")


# ---- 5. the readers' keyword options -------------------------------------------------------------------------------

@pytest.mark.parametrize("name,kw,pattern", [
    ("e.npy", dict(t_origin=0.0), r"takes no option 't_origin'.*its reader takes .*columns"),
    ("e.npy", dict(frames=False), r"takes no option 'frames'"),
    ("e.txt", dict(t_start=0.0), r"takes no option 't_start'.*its reader takes .*t_origin"),
    ("e.csv", dict(columns="txyp"), r"takes no option 'columns'")])
def test_readers_with_options_refuse_an_option_they_do_not_take(files, name, kw, pattern):
    """The .npy, .txt and .csv readers (which pass **options on) raised Python's bare "unexpected keyword"."""
    _no(lambda: _read(files / name, sensor_size=(12, 12), **kw), pattern, EventDataError)


@pytest.mark.parametrize("name", ["e.npy", "e.txt", "e.csv", "ijrr"])
@pytest.mark.parametrize("unit", [["s"], {"us": 1}])
def test_readers_refuse_a_time_unit_that_is_no_name(files, name, unit):
    """Python's "unhashable type"."""
    kw = {} if name == "ijrr" else dict(sensor_size=(12, 12))
    _no(lambda: _read(files / name, time_unit=unit, **kw), r"time_unit")


def test_events_from_arrays_refuses_a_time_unit_that_is_no_name():
    _no(lambda: Events.from_arrays([0, 1], [0, 1], [0, 1], [1, 0], (2, 2), time_unit=["us"]), r"unknown time_unit")


@pytest.mark.parametrize("name", ["e.txt", "e.csv", "ijrr"])
@pytest.mark.parametrize("origin", ["0", [0], True])
def test_text_readers_refuse_a_t_origin_that_is_no_seconds(files, name, origin):
    """Text and lists were Python's "must be real number", True was taken as 1 s."""
    kw = {} if name == "ijrr" else dict(sensor_size=(12, 12))
    _no(lambda: _read(files / name, t_origin=origin, **kw), r"t_origin must be a finite number")


@pytest.mark.parametrize("size", [(12.5, 12), (12, 12.5), (True, 12)])
def test_ijrr_refuses_a_sensor_size_that_is_no_two_whole_numbers(files, size):
    """An IJRR folder's frames give its size: a given (12.5, 12) was compared as (12, 12) and taken."""
    _no(lambda: _read(files / "ijrr", sensor_size=size), r"sensor_size must be \(H, W\), two positive whole")


@pytest.mark.parametrize("window", [dict(t_start=True), dict(t_end=np.bool_(True))])
def test_windowed_readers_refuse_a_window_of_true(files, h5, window):
    """True was read as 1 s ("no events in the window [True, None)")."""
    _none_of([lambda: _read(files / "e.npy", sensor_size=(12, 12), **window), lambda: _read(h5, **window)],
             r"must be a finite number of seconds")


def test_readers_options_as_before(files, h5):
    base = _read(files / "e.npy", sensor_size=(12, 12))
    assert len(_read(files / "e.npy", sensor_size=(np.int64(12), 12.0), time_unit=np.str_("s"), t_start=np.int64(0),
                     t_end=np.float64(0.1)).events) == int(np.sum(base.events.t < 0.1))
    txt = _read(files / "e.txt", sensor_size=[12, 12], t_origin=np.int64(0), polarity="01", time_unit="auto")
    assert np.array_equal(txt.events.x, base.events.x)
    assert len(_read(files / "e.csv", sensor_size=(12, 12), t_origin=0.0).events) == len(base.events)
    assert _read(files / "ijrr", sensor_size=(12.0, np.int64(12)), t_origin=0).events.sensor_size == (12, 12)
    _no(lambda: _read(files / "ijrr", sensor_size=(10, 12)), r"the frames \(or header\) say")
    _no(lambda: _read(files / "ijrr", camera="left"), r"takes no option 'camera'")
    _no(lambda: _read(files / "e.npy", sensor_size=(12, 12), time_unit="h"), r"unknown time_unit")
    assert len(_read(h5, frames=False).events) == len(base.events)


# ---- 6. the output folder of every job -----------------------------------------------------------------------------

@pytest.mark.parametrize("out", [None, 5, 1.5, [b"x"]])
def test_output_dir_refuses_an_out_dir_that_is_no_path(out):
    """Python's "expected str, bytes or os.PathLike object"."""
    _no(lambda: OutputDir(out), r"out_dir= must be a folder", TypeError)


@pytest.mark.parametrize("kw,pattern", [(dict(overwrite="no"), r"overwrite= must be True or False"),
                                        (dict(overwrite=None), r"overwrite= must be True or False"),
                                        (dict(overwrite=2), r"overwrite= must be True or False"),
                                        (dict(log=5), r"log= must be a function"),
                                        (dict(command=5), r"command= must be text")])
def test_output_dir_refuses_settings_before_any_folder(tmp_path, kw, pattern):
    """overwrite="no" replaced an existing folder (a true value); a log of 5 and a command of 5 were taken (the
    command written in the lock). A fresh folder (an existing one was refused for being there, whatever the
    settings) with overwrite=True where overwrite is not the case: nothing may be made, no folder, no lock."""
    kw = kw if "overwrite" in kw else {"overwrite": True, **kw}

    def use():
        with OutputDir(tmp_path / "out", **kw) as target:
            (target.staging / "new.txt").write_text("y")
            target.commit()
    _no(use, pattern)
    assert list(tmp_path.iterdir()) == []   # no out/, no .out.lock, no staging folder


def test_output_dir_as_before(tmp_path):
    for i, overwrite in enumerate([np.bool_(True), 1, 0, False]):
        with atomic_output_dir(tmp_path / f"o{i}", overwrite=overwrite, log=None) as stage:
            (stage / "a.txt").write_text("a")
        assert (tmp_path / f"o{i}" / "a.txt").exists()
    with OutputDir(str(tmp_path / "o0"), overwrite=True, log=QUIET, command=np.str_("evinr-lite x")) as target:
        target.commit()
    _no(lambda: OutputDir(""), r"empty or blank")


# ---- 7. the demo and reconstruct jobs from Python ------------------------------------------------------------------

@pytest.mark.parametrize("kw,pattern", [
    (dict(n_frames=2.5), r"n_frames= must be a whole number >= 1"), (dict(n_frames="4"), r"n_frames= must be"),
    (dict(n_frames=True), r"n_frames= must be"), (dict(n_frames=0), r"n_frames= must be a whole number >= 1"),
    (dict(config={}), r"config= must be EvINRConfig"), (dict(log=5), r"log= must be a function"),
    (dict(overwrite="no"), r"overwrite= must be True or False"),
    (dict(sensor_size=(8, 10)), r"at least 11 x 11")])
def test_run_demo_refuses_settings_before_any_work(tmp_path, monkeypatch, kw, pattern):
    """n_frames 2.5 / "4" were Python's errors, True ran one frame and 0 blamed query_times nobody passed; config={}
    ran the default recipe; log=5 failed after the simulation; overwrite="no" replaced; a sensor under 11 x 11 was
    refused by SSIM after the training."""
    import evinr_lite.apps.demo as demo

    monkeypatch.setattr(demo, "simulate_scene", lambda *a, **k: pytest.fail("simulated before the check"))
    out = tmp_path / "demo"
    _no(lambda: run_demo(out, **{"sensor_size": (16, 16), "duration": 0.2, "n_frames": 2, "config": FAST,
                                 "log": QUIET, **kw}), pattern)
    assert not out.exists()


@pytest.mark.parametrize("out", [None, 5, b"demo"])
def test_run_demo_refuses_an_out_dir_that_is_no_path_before_any_work(monkeypatch, out):
    """Python's TypeError, after the training."""
    import evinr_lite.apps.demo as demo

    monkeypatch.setattr(demo, "simulate_scene", lambda *a, **k: pytest.fail("simulated before the check"))
    _no(lambda: run_demo(out, sensor_size=(16, 16), duration=0.2, n_frames=2, config=FAST, log=QUIET),
        r"out_dir= must be a folder", TypeError)


def test_run_demo_refuses_an_existing_folder_before_any_work(tmp_path, monkeypatch):
    """The existing folder was refused after the training."""
    import evinr_lite.apps.demo as demo

    (tmp_path / "demo").mkdir()
    monkeypatch.setattr(demo, "simulate_scene", lambda *a, **k: pytest.fail("simulated before the check"))
    _no(lambda: run_demo(tmp_path / "demo", sensor_size=(16, 16), duration=0.2, n_frames=2, config=FAST, log=QUIET),
        r"already exists")


def test_run_demo_as_before(tmp_path):
    summary = run_demo(tmp_path / "demo", sensor_size=(np.int64(16), 16.0), duration=0.2, n_frames=np.int64(2),
                       config=FAST, log=QUIET, overwrite=np.bool_(False))
    assert len(summary["query_times_s"]) == 2 and json.loads((tmp_path / "demo" / "metrics.json").read_text())
    assert len(run_demo(str(tmp_path / "demo"), sensor_size=(16, 16), duration=0.2, n_frames=3, config=FAST,
                        log=QUIET, overwrite=True)["query_times_s"]) == 3


@pytest.fixture
def npy(tmp_path):
    np.save(tmp_path / "e.npy", np.stack([EV.t, EV.x, EV.y, EV.p], 1))
    return tmp_path / "e.npy"


@pytest.mark.parametrize("kw,pattern", [(dict(resume="yes"), r"resume= must be True or False"),
                                        (dict(resume=5), r"resume= must be True or False"),
                                        (dict(overwrite="no"), r"overwrite= must be True or False"),
                                        (dict(command=5), r"command= must be text"),
                                        (dict(log=5), r"log= must be a function")])
def test_run_reconstruct_refuses_settings_before_any_folder(npy, kw, pattern):
    out = npy.parent / "out"
    _no(lambda: run_reconstruct(npy, out, **{"sensor_size": (12, 12), "n_iters": 1, "log": QUIET, **kw}), pattern)
    assert not out.exists()


def test_run_reconstruct_as_before(npy):
    out = npy.parent / "out"
    run = run_reconstruct(str(npy), out, sensor_size=(12, 12), n_iters=1, fps=10, log=QUIET, resume=np.bool_(False),
                          overwrite=0, command=np.str_("evinr-lite reconstruct"), progress=False)
    assert run["n_frames_written"] >= 1 and (out / "run.json").exists()
    _no(lambda: run_reconstruct(npy, out, sensor_size=(12, 12), n_iters=1, log=QUIET), r"already exists")


@pytest.mark.parametrize("path", [None, 5, 1.5])
def test_run_reconstruct_refuses_a_path_that_is_no_path(tmp_path, path):
    """Python's "expected str, bytes or os.PathLike object"."""
    _no(lambda: run_reconstruct(path, tmp_path / "out", sensor_size=(12, 12), n_iters=1, log=QUIET),
        r"path= must be a recording", TypeError)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("out", [None, 5])
def test_run_reconstruct_refuses_an_out_dir_that_is_no_path(npy, out):
    _no(lambda: run_reconstruct(npy, out, sensor_size=(12, 12), n_iters=1, log=QUIET), r"out_dir= must be a folder",
        TypeError)


# ---- 8. the review's fixes -----------------------------------------------------------------------------------------

def _torch_seconds(value):
    import torch

    return torch.tensor(value, dtype=torch.float64)


@pytest.mark.parametrize("make", [np.array, _torch_seconds, lambda v: Fraction(v).limit_denominator(1000),
                                  lambda v: Decimal(str(v))], ids=["0-d", "tensor", "Fraction", "Decimal"])
def test_review_windows_of_0d_arrays_tensors_fractions_and_decimals_are_read(files, h5, make):
    """Round 15's window check took only int and float (numpy's too): a 0-d array (t.max()), a tensor, a Fraction or
    a Decimal, which read_canonical / iter_canonical_events / data_fetch.read took before, were refused."""
    lo, hi = make(0.05), make(0.15)
    want = read_canonical(h5, 0.05, 0.15).events.t
    assert np.array_equal(read_canonical(h5, lo, hi).events.t, want)
    assert np.array_equal(data_fetch.read(h5, lo, hi).events.t, want)
    assert np.array_equal(np.concatenate([c.t for c in iter_canonical_events(h5, lo, hi)]), want)
    npy = _read(files / "e.npy", sensor_size=(12, 12), t_start=0.05, t_end=0.15).events.t
    assert np.array_equal(_read(files / "e.npy", sensor_size=(12, 12), t_start=lo, t_end=hi).events.t, npy)
    _none_of([lambda: read_canonical(h5, False), lambda: read_canonical(h5, np.array([0.05])),
              lambda: read_canonical(h5, Decimal("NaN"))], r"t_start= must be a finite number of seconds")


@pytest.mark.parametrize("value", [Fraction(3, 2), Decimal("1.5")], ids=["Fraction", "Decimal"])
def test_review_canonical_writer_takes_fractions_and_decimals(tmp_path, value):
    """float() took them before round 15; its checks refused them as "no finite number"."""
    with CanonicalWriter(tmp_path / "c.h5", sensor_size=(12, 12), t_origin=value, C=value / 6) as w:
        w.add_events(EV.t, EV.x, EV.y, P)
        w.add_frame(np.zeros((12, 12), np.uint8), value / 15)
    info = canonical_info(tmp_path / "c.h5")
    assert info["t_origin"] == 1.5 and info["C"] == 0.25
    assert read_canonical(tmp_path / "c.h5").frames.t[0] == 0.1


@pytest.mark.parametrize("name", ["e.txt", "e.csv", "ijrr"])
@pytest.mark.parametrize("origin", [Fraction(0), Decimal("0"), np.float32(0), np.array(0.0)],
                         ids=["Fraction", "Decimal", "float32", "0-d"])
def test_review_text_readers_take_a_t_origin_of_any_number(files, name, origin):
    """Fraction and Decimal were refused by round 15's check (taken before); np.float32 and a 0-d array passed the
    check and were Python's "argument should be a string or a Rational instance" in origin_to_ns."""
    kw = {} if name == "ijrr" else dict(sensor_size=(12, 12))
    want = _read(files / name, t_origin=0, **kw).events
    got = _read(files / name, t_origin=origin, **kw).events
    assert np.array_equal(got.t, want.t) and got.t_origin == want.t_origin


def test_review_origin_to_ns_of_numpy_numbers_and_decimals():
    from evinr_lite.io.text import origin_to_ns

    assert origin_to_ns(np.float32(1.5)) == origin_to_ns(np.array(1.5)) == origin_to_ns(_torch_seconds(1.5)) == \
        1_500_000_000
    assert origin_to_ns(Decimal("1468939993.067416")) == 1_468_939_993_067_416_000   # exact, not the float's
    assert origin_to_ns(1468939993.067416) == round(Fraction(1468939993.067416) * 10**9)


@pytest.mark.parametrize("false", [False, np.bool_(False)])
def test_review_false_is_refused_where_true_is(tmp_path, files, h5, false):
    """True was 1 s and is refused; False (0 s before round 15) is refused alike: a flag is no time."""
    _no(lambda: _read(files / "e.txt", sensor_size=(12, 12), t_origin=false), r"t_origin must be a finite number")
    _no(lambda: CanonicalWriter(tmp_path / "f.h5", sensor_size=(12, 12), t_origin=false), r"t_origin must be")
    _no(lambda: read_canonical(h5, None, false), r"t_end= must be a finite number of seconds")
    with CanonicalWriter(tmp_path / "g.h5", sensor_size=(12, 12)) as w:
        w.add_events([0.0, 0.1], [1, 2], [3, 4], [1, -1])
        _no(lambda: w.add_frame(np.zeros((12, 12), np.uint8), false), r"frame time must be a finite number")
    assert not (tmp_path / "f.h5").exists()


@pytest.mark.parametrize("files,shown", [(5, "got 5$"), (b"alexnet", r"got b'alexnet'$"), (None, "got None$")])
def test_review_get_weights_names_what_was_passed(cache, files, shown):
    """The message showed the tuple made of it: (5,), (None,) or the bytes' numbers (97, 108, ...)."""
    _no(lambda: data_fetch.get_weights("lpips", files, progress=False), r"files= must be .*" + shown, DataFetchError)


def test_review_get_of_a_weight_set_checks_the_file_name(cache):
    """get("lpips", 5) blamed files=(5,), an argument of get_weights that get's caller never passed."""
    for bad in (5, None):
        with pytest.raises(DataFetchError, match=r"sequence must be a name") as err:
            data_fetch.get("lpips", bad, progress=False)
        assert "files=" not in str(err.value)
    assert not cache.exists()


def test_review_demo_command_names_its_own_size_flag(tmp_path, capsys):
    """The message said sensor_size=(8, 10), which the command line rewrote as --sensor 8x10: the demo's flag is
    --size."""
    from evinr_lite.apps.cli import main

    assert main(["demo", "--size", "8x10", "--out", str(tmp_path / "d")]) == 2
    err = capsys.readouterr().err
    assert "--size 11x11" in err and "8 x 10" in err and "--sensor" not in err, err
    assert not (tmp_path / "d").exists()


@pytest.mark.parametrize("sequence", ["../evil", "a/b", "..", 5])
def test_review_convert_refuses_a_sequence_that_is_no_name(cache, files, sequence):
    """convert(sequence="../evil") wrote <cache>/evil.h5, "a/b" <cache>/converted/a/b.h5; the command line too."""
    from data_fetch.__main__ import main

    _no(lambda: data_fetch.convert(files / "ijrr", progress=False, sequence=sequence), r"sequence must be",
        DataFetchError)
    if isinstance(sequence, str):
        assert main(["convert", str(files / "ijrr"), "--sequence", sequence]) == 2
    assert not cache.exists() and not list(files.rglob("*.h5"))


def test_review_run_reconstruct_reads_a_path_given_as_bytes(npy):
    """bytes passed the check and were Python's TypeError later; read_recording takes them (os.fsdecode)."""
    import os

    kw = dict(sensor_size=(12, 12), n_iters=1, fps=10, log=QUIET, progress=False, seed=0)
    a = run_reconstruct(os.fsencode(npy), npy.parent / "a", **kw)
    b = run_reconstruct(str(npy), npy.parent / "b", **kw)
    assert a["n_frames_written"] == b["n_frames_written"] >= 1


def test_review_jobs_share_their_checks(tmp_path, monkeypatch, capsys):
    """One rule each: the demo's smallest side is evaluation.metrics' SSIM_MIN_SIDE; a log of 5 and an out_dir of
    None are the same TypeError, with the same words, for every job (run_batch's were plain ValueErrors); the demo
    command checks its output folder once (cli.py checked it before run_demo did again)."""
    import evinr_lite.apps.demo as demo
    import evinr_lite.io.output as output
    from evinr_lite.apps.batch import run_batch
    from evinr_lite.apps.cli import main
    from evinr_lite.evaluation.metrics import SSIM_MIN_SIDE, ssim

    assert demo.SSIM_MIN_SIDE is SSIM_MIN_SIDE == 11
    _no(lambda: ssim(np.zeros((10, 12)), np.zeros((10, 12))), r"at least 11 x 11")
    npy = tmp_path / "e.npy"
    np.save(npy, np.stack([EV.t, EV.x, EV.y, EV.p], 1))
    jobs = [lambda out, log: OutputDir(out, log=log),
            lambda out, log: run_demo(out, sensor_size=(16, 16), duration=0.2, n_frames=2, config=FAST, log=log),
            lambda out, log: run_batch([str(npy)], out, sequential=True, log=log),
            lambda out, log: run_reconstruct(npy, out, sensor_size=(12, 12), n_iters=1, log=log)]
    for job in jobs:
        _no(lambda: job(tmp_path / "out", 5), r"^log= must be a function log\(text\) \(e\.g\. print\)", TypeError)
        _no(lambda: job(None, QUIET), r"^out_dir= must be a folder \(a str or Path\), got NoneType$", TypeError)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["e.npy"]
    calls = []
    checked = output.check_output_path

    def counted(*a, **k):
        calls.append(a)
        return checked(*a, **k)
    monkeypatch.setattr(output, "check_output_path", counted)
    monkeypatch.setattr(demo, "check_output_path", counted)
    assert main(["demo", "--size", "8x10", "--out", str(tmp_path / "d")]) == 2
    capsys.readouterr()
    assert len(calls) == 1


def test_review_io_text_imports_what_it_uses():
    """io/text.py imported math and used none of it."""
    import ast
    from pathlib import Path

    import evinr_lite.io.text as text

    tree = ast.parse(Path(text.__file__).read_text())
    imported = {a.asname or a.name for n in tree.body if isinstance(n, ast.Import) for a in n.names}
    used = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
    assert imported <= used, imported - used
