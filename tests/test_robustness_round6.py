"""Round 6 of the bad-input table (tests/test_robustness*.py): odd values in files, paths and arguments.

Fixes (each test failed before its fix): a window bound beyond any clock (`--end 1e308`) was an internal
OverflowError; an input that is a symbolic-link loop or a dangling link was reported as "no such file";
a text or .csv file with old Mac line ends (CR only: Excel for Mac's "CSV (Macintosh)") was refused as one
line of hundreds of columns; values that do not parse (a Unicode minus, ON / OFF or +/- polarities, a
decimal comma or a trailing comma in a `t x y p` file, `640x480` as the `W H` line, thousands separators
in a quoted .csv value) were refused without the fix; an empty or blank `--out` wrote into the current
folder (or a folder named " "); ``Events.from_arrays(..., sort=True)`` with columns of different lengths
(or a ragged t) raised numpy's IndexError / ValueError; masked arrays were read with the values under
their mask; object arrays of numbers were refused without the conversion, and an integer beyond int64
was called "not an integer"; generators and sets as event columns gave "must be a 1-D array, got shape
()"; datetime64 timestamps got no fix.

Guards: odd inputs next to these that already behave and must keep their outcome.
"""
import os
import warnings

import numpy as np
import pytest

from evinr_lite import EventDataError, Events, EvINRConfig, read_recording, reconstruct
from evinr_lite.apps.cli import main
from evinr_lite.apps.options import RunOptions

from test_robustness import H, W, _events, assert_clear_error, tree
from test_robustness_round4 import FAST, SENSOR, _both_commands_refuse


def _rows(fmt):
    t, x, y, p = _events()
    return "".join(fmt(a, b, c, int(d > 0)) + "\n" for a, b, c, d in zip(t, x, y, p))


def _same_events(path, **kwargs):
    t, x, y, p = _events()
    ev = read_recording(path, **kwargs).events
    assert ev.sensor_size == (H, W)
    np.testing.assert_allclose(ev.t + ev.t_origin, t, atol=1e-9)
    np.testing.assert_array_equal(ev.x, x)
    np.testing.assert_array_equal(ev.y, y)
    np.testing.assert_array_equal(ev.p, np.where(p > 0, 1, -1))


@pytest.fixture
def txt(tmp_path):
    path = tmp_path / "ev.txt"
    path.write_text(f"{W} {H}\n" + _rows(lambda a, b, c, d: f"{a:.9f} {b} {c} {d}"))
    return path


# ---- 1. fixes: read correctly -------------------------------------------------------------------------------

@pytest.mark.parametrize("name, text, sensor", [
    ("ev.txt", f"{W} {H}\n" + _rows(lambda a, b, c, d: f"{a:.9f} {b} {c} {d}"), False),
    ("ev.csv", "t;x;y;p\n" + _rows(lambda a, b, c, d: f"{a:.9f};{b};{c};{d}").replace(".", ","), True),
    ("ev.csv", "t,x,y,p\n" + _rows(lambda a, b, c, d: f"{a:.9f},{b},{c},{d}"), True),
], ids=["txt", "csv with semicolons and decimal commas", "csv"])
def test_old_mac_line_ends_are_read(capsys, tmp_path, name, text, sensor):
    """Lines ending in CR alone (Excel for Mac's "CSV (Macintosh)", classic Mac OS) were one line of
    hundreds of columns; now they are lines, read to the same events, by the API and the command."""
    path = tmp_path / name
    path.write_bytes(text.replace("\n", "\r").encode())
    _same_events(path, **({"sensor_size": (H, W)} if sensor else {}))
    code = main(["info", str(path), *(SENSOR if sensor else [])])
    out, err = capsys.readouterr()
    assert code == 0 and "error" not in err, (out, err)


def test_object_arrays_of_plain_numbers_are_refused_with_the_conversion():
    """np.array([...], dtype=object) of numbers stays refused (test_robustness_more's 't object'), but the
    message now gives the conversion that reads it; the converted columns are read as the same events."""
    t, x, y, p = _events()
    with pytest.raises(EventDataError, match=r"timestamps must be numbers \(seconds\), got dtype object; .*"
                                             r"np\.asarray\(t, dtype=np\.float64\)"):
        Events(t.astype(object), x, y, p, (H, W))
    with pytest.raises(EventDataError, match=r"x coordinates must be integers, got dtype object; .*"
                                             r"np\.asarray\(x, dtype=np\.int64\)"):
        Events(t, x.astype(object), y, p, (H, W))
    ev = Events(np.asarray(t.astype(object), dtype=np.float64), np.asarray(x.astype(object), dtype=np.int64), y, p,
                (H, W))
    np.testing.assert_array_equal(ev.t, t)
    np.testing.assert_array_equal(ev.x, x)


# ---- 2. fixes: refused with the problem and the fix ------------------------------------------------------

@pytest.mark.parametrize("flag, value", [("--end", "1e308"), ("--start", "-1e308"), ("--end", "1e16")])
def test_a_window_bound_beyond_any_clock_is_refused(capsys, tmp_path, txt, flag, value):
    """--end 1e308 was an internal error (OverflowError counting the frames); now status 2 naming the option."""
    assert_clear_error(capsys, ["reconstruct", txt, "--out", tmp_path / "out", f"{flag}={value}", *FAST],
                       rf"{flag} .*beyond any recording's clock.*as `evinr-lite info` prints", root=tmp_path)
    with pytest.raises(EventDataError, match=r"t_end=1e\+308 s is beyond any recording's clock"):
        RunOptions(t_end=1e308)


def test_guard_a_window_far_beyond_the_events_but_on_a_clock_is_still_taken_with_a_note():
    assert RunOptions(t_start=0.0, t_end=1e6).t_end == 1e6


@pytest.mark.parametrize("kind", ["loop", "dangling"])
def test_an_input_link_that_leads_nowhere_says_so(capsys, tmp_path, kind):
    """A loop of symbolic links and a link to a deleted file were both 'no such file or folder'."""
    link = tmp_path / "rec.txt"
    if kind == "loop":
        os.symlink(tmp_path / "other", link)
        os.symlink(link, tmp_path / "other")
        pattern = r"rec\.txt goes through a loop of symbolic links.*fix or remove the link"
    else:
        os.symlink(tmp_path / "moved.txt", link)
        pattern = r"rec\.txt is a symbolic link to .*moved\.txt, which does not exist.*point the link"
    before = sorted(os.listdir(tmp_path))
    assert_clear_error(capsys, ["info", link], pattern)
    with pytest.raises(EventDataError, match=pattern):
        read_recording(link)
    assert sorted(os.listdir(tmp_path)) == before


def test_guard_a_missing_path_is_still_no_such_file(capsys, tmp_path):
    assert_clear_error(capsys, ["info", tmp_path / "nope.txt"], r"no such file or folder: .*nope\.txt; check the path")


def _bad_text(case):
    if case == "unicode minus":
        return "ev.txt", f"{W} {H}\n" + _rows(lambda a, b, c, d: f"{a:.9f} {b} {c} {d or chr(0x2212) + '1'}"), \
            r"line \d+: p is not a number.*Unicode minus sign or dash.*replace it with '-'"
    if case == "ON/OFF":
        return "ev.txt", f"{W} {H}\n" + _rows(lambda a, b, c, d: f"{a:.9f} {b} {c} {'ON' if d else 'OFF'}"), \
            r"p is not a number.*write the polarity as a number: 1 .* for ON.*0 .* for OFF"
    if case == "+/- in csv":
        return "ev.csv", "t,x,y,p\n" + _rows(lambda a, b, c, d: f"{a:.9f},{b},{c},{'+' if d else '-'}"), \
            r"p is not a number.*write the polarity as a number"
    if case == "decimal comma in txt":
        return "ev.txt", f"{W} {H}\n" + _rows(lambda a, b, c, d: f"{a:.9f} {b} {c} {d}".replace(".", ",", 1)), \
            r"the timestamp is not a number.*decimal comma: write a decimal point.*\.csv with `;`"
    if case == "trailing comma in txt":
        return "ev.txt", f"{W} {H}\n" + _rows(lambda a, b, c, d: f"{a:.9f} {b} {c} {d},"), \
            r"p is not a number.*',' follows the value.*spaces only: remove the separators, or name the file \.csv"
    if case == "WxH size line":
        return "ev.txt", f"{W}x{H}\n" + _rows(lambda a, b, c, d: f"{a:.9f} {b} {c} {d}"), \
            r"line 1: found 1 columns.*the `W H` line is the width and the height separated by a space"
    return "ev.csv", "t_us,x,y,p\n" + _rows(lambda a, b, c, d: f'"{round(a * 1e6):,}",{b},{c},{d}'), \
        r"found 5 columns.*quoted value holds commas as thousands separators.*written plainly"


BAD_TEXT = ["unicode minus", "ON/OFF", "+/- in csv", "decimal comma in txt", "trailing comma in txt", "WxH size line",
            "thousands separators in quoted csv values"]


@pytest.mark.parametrize("case", BAD_TEXT)
def test_a_value_that_does_not_parse_gets_its_fix(capsys, monkeypatch, tmp_path, case):
    name, text, pattern = _bad_text(case)
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, SENSOR if name.endswith(".csv") else [], pattern)
    with pytest.raises(EventDataError, match=pattern):
        read_recording(path, sensor_size=(H, W))


def test_guard_a_plain_damaged_value_gets_no_hint(tmp_path):
    path = tmp_path / "ev.txt"
    path.write_text(f"{W} {H}\n" + _rows(lambda a, b, c, d: f"{a:.9f} {b} {c} {d}").replace(" 1\n", " z\n", 1))
    with pytest.raises(EventDataError, match=r"p is not a number; expected `t x y p` [^;]*\(line reads") as err:
        read_recording(path)
    assert "Unicode" not in str(err.value) and "write the polarity" not in str(err.value)


@pytest.mark.parametrize("command", ["reconstruct", "demo", "batch"])
@pytest.mark.parametrize("out", ["", "  "])
def test_an_empty_out_is_refused_not_the_current_folder(capsys, monkeypatch, tmp_path, txt, command, out):
    """--out '' was the current folder (reconstruct refused it as holding the input; in an empty folder it
    wrote there), --out ' ' wrote a folder named by a space."""
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    argv = {"reconstruct": ["reconstruct", txt, "--out", out, *FAST], "demo": ["demo", "--out", out],
            "batch": ["batch", txt, "--out", out]}[command]
    assert_clear_error(capsys, argv, r"--out '\s*' is empty or blank.*pass the folder to write, e\.g\. --out rec",
                       root=tmp_path)
    assert not any(work.iterdir())


def test_from_arrays_sort_checks_the_columns_before_sorting():
    """sort=True indexed the columns with the order of t first: numpy's IndexError for a column of another
    length or a scalar, numpy's bare ValueError for a ragged t."""
    t, x, y, p = _events()
    for bad, shape in ((x[:-1], r"'x': \(399,\)"), (3, r"'x': \(\)")):
        with pytest.raises(EventDataError, match=rf"must be 1-D arrays of the same length \[N\] to be sorted.*{shape}"):
            Events.from_arrays(t, bad, y, p, (H, W), sort=True)
    with pytest.raises(EventDataError, match=r"Events\.t is ragged"):
        Events.from_arrays([[0.1], [0.2, 0.3]], [1, 2], [1, 1], [1, 1], (H, W), sort=True)
    ev = Events.from_arrays(t[::-1], list(x[::-1]), y[::-1], p[::-1], (H, W), sort=True)   # guard: lists still sort
    np.testing.assert_array_equal(ev.t, t)


def test_masked_values_are_not_read_as_data():
    """np.asarray drops a mask: the values under it were used as timestamps, coordinates or query times."""
    t, x, y, p = _events()
    mask = np.zeros(len(t), bool)
    mask[3] = True
    with pytest.raises(EventDataError, match=r"Events\.x is a masked array with 1 of its 400 values masked.*"
                                             r"compressed\(\).*filled"):
        Events(t, np.ma.masked_array(x, mask), y, p, (H, W))
    ev = Events(np.ma.masked_array(t), x, y, p, (H, W))   # guard: nothing masked, nothing lost
    np.testing.assert_array_equal(ev.t, t)
    with pytest.raises(EventDataError, match=r"query_times= is a masked array with 1 of its 2 values masked"):
        reconstruct(ev, np.ma.masked_array([0.1, 0.15], [False, True]), EvINRConfig(C=0.2, n_iters=1, progress=False))


def test_odd_containers_and_huge_integers_are_named():
    t, x, y, p = _events()
    with pytest.raises(EventDataError, match=r"Events\.x\[1\] = 1180591620717411303424 does not fit a 64-bit "
                                             r"integer.*repair or drop it"):
        Events(t[:2], [1, 2**70], [0, 0], [1, 1], (H, W))
    with pytest.raises(EventDataError, match=r"Events\.t is a generator.*list\(\.\.\.\) of it"):
        Events((v for v in t), x, y, p, (H, W))
    with pytest.raises(EventDataError, match=r"Events\.t is a set.*has no order"):
        Events(set(t), x, y, p, (H, W))
    with pytest.raises(EventDataError, match=r"dtype datetime64\[ns\]; convert them to float64 seconds.*timedelta64"):
        Events((t * 1e9).astype("datetime64[ns]"), x, y, p, (H, W))
    with pytest.raises(EventDataError, match=r"timestamps must be numbers \(seconds\), got dtype object"):   # guard
        Events(np.array(["0.1", 0.2], dtype=object), [0, 1], [0, 0], [1, 1], (H, W))


# ---- 3. guards: odd inputs that already behave ----------------------------------------------------------------

@pytest.mark.parametrize("case", ["tabs", "mixed white space", "scientific notation", "+1/-1 polarity",
                                  "float coordinates 12.0", "float polarity 1.0", "trailing blank lines"])
def test_guard_odd_but_valid_text_is_read_to_the_same_events(tmp_path, case):
    fmt = {"tabs": lambda a, b, c, d: f"{a:.9f}\t{b}\t{c}\t{d}",
           "mixed white space": lambda a, b, c, d: f" {a:.9f} \t {b}  {c}\t{d} ",
           "scientific notation": lambda a, b, c, d: f"{a:.12e} {b} {c} {d}",
           "+1/-1 polarity": lambda a, b, c, d: f"{a:.9f} {b} {c} {'+1' if d else '-1'}",
           "float coordinates 12.0": lambda a, b, c, d: f"{a:.9f} {b}.0 {c}.0 {d}",
           "float polarity 1.0": lambda a, b, c, d: f"{a:.9f} {b} {c} {float(d)}",
           "trailing blank lines": lambda a, b, c, d: f"{a:.9f} {b} {c} {d}"}[case]
    path = tmp_path / "ev.txt"
    path.write_text(f"{W} {H}\n" + _rows(fmt) + ("\n\n  \n" if case == "trailing blank lines" else ""))
    _same_events(path)


@pytest.mark.parametrize("case, pattern", [
    ("small backwards jitter", r"line 103: the timestamp is earlier than the one before.*sort"),
    ("coordinate equal to the width", r"x \(column, width W\) coordinates span \[0, 16\].*allows \[0, 15\]"),
    ("negative coordinate", r"x \(column, width W\) coordinates span \[-1, "),
    ("NaN coordinate", r"line \d+: x must be a whole pixel index"),
    ("five columns", r"line 2: found 5 columns, expected 4"),
])
def test_guard_damaged_text_is_refused(capsys, monkeypatch, tmp_path, case, pattern):
    t, x, y, p = _events()
    t = t.copy()
    if case == "small backwards jitter":
        t[100], t[101] = t[101], t[100]
    bad = {"coordinate equal to the width": str(W), "negative coordinate": "-1", "NaN coordinate": "nan"}.get(case)
    lines = [f"{a:.9f} {bad if (bad and i == 7) else b} {c} {int(d > 0)}" + (" 0" if case == "five columns" else "")
             for i, (a, b, c, d) in enumerate(zip(t, x, y, p))]
    path = tmp_path / "ev.txt"
    path.write_text(f"{W} {H}\n" + "\n".join(lines) + "\n")
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, [], pattern, before_training=False)


def test_guard_one_event_one_pixel_one_polarity(capsys, tmp_path):
    """A single event is read and refused for reconstruction with the fix; every event at one pixel is refused
    by the background filter naming --keep-background; one polarity only is reconstructed."""
    t, x, y, p = _events()
    one = tmp_path / "one.txt"
    one.write_text(f"{W} {H}\n{t[0]:.9f} {x[0]} {y[0]} 1\n")
    assert len(read_recording(one).events) == 1
    assert_clear_error(capsys, ["reconstruct", one, "--out", tmp_path / "o1", *FAST],
                       r"holds only 1 event.*at least 2 events at different times")
    pixel = tmp_path / "pixel.txt"
    pixel.write_text(f"{W} {H}\n" + "".join(f"{a:.9f} 3 4 {int(d > 0)}\n" for a, d in zip(t, p)))
    assert_clear_error(capsys, ["reconstruct", pixel, "--out", tmp_path / "o2", *FAST],
                       r"background filter left 0 of 400 events.*--keep-background")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ev = Events(t, x, y, np.ones(len(t), int), (H, W))
    assert set(ev.p.tolist()) == {1}


@pytest.mark.parametrize("value, pattern", [
    ("12,16", r"argument --sensor: size must be HxW \(rows x columns\), e\.g\. 120x160; got '12,16'"),
    ("12.0x16", r"argument --sensor: size must be HxW"),
    (f"{W}x{H}", r"the events fit \(12, 16\), the size given the other way round \(on the command line --sensor 12x16"),
])
def test_guard_sensor_spellings(capsys, tmp_path, value, pattern):
    t, x, y, p = _events()
    path = tmp_path / "ev.npy"
    np.save(path, np.stack([t, x, y, (p > 0)], 1).astype(np.float64))
    assert_clear_error(capsys, ["info", path, "--sensor", value], pattern, root=tmp_path)


def test_guard_hdf5_dtypes_and_filters_are_read(tmp_path):
    """HQF-style files with big-endian, float or unsigned columns, gzip / lzf / shuffle / fletcher32 filters and
    resizable chunked datasets are read to the same events."""
    import h5py

    t, x, y, p = _events()
    path = tmp_path / "e.h5"
    with h5py.File(path, "w") as f:
        opts = dict(chunks=(64,), maxshape=(None,), compression="gzip", shuffle=True, fletcher32=True)
        f.create_dataset("events/xs", data=x.astype(">i2"), **opts)
        f.create_dataset("events/ys", data=y.astype(np.float32), compression="lzf")
        f.create_dataset("events/ts", data=t.astype(">f8"), **opts)
        f.create_dataset("events/ps", data=p > 0)
        f.attrs["sensor_resolution"] = np.array([H, W], dtype=np.float64)
    _same_events(path)
    assert tree(tmp_path).keys() == {"e.h5"}


def test_guard_reversed_or_empty_window_and_times_outside(capsys, tmp_path, txt):
    assert_clear_error(capsys, ["reconstruct", txt, "--out", tmp_path / "o", "--start", "0.15", "--end", "0.05",
                                *FAST], r"time window \[0\.15, 0\.05\) is empty or reversed", root=tmp_path)
    assert_clear_error(capsys, ["reconstruct", txt, "--out", tmp_path / "o", "--at", "5,6", "--iters", "3",
                                "--quiet", "--no-video"],
                       r"requested time 5\.0 s is outside the reconstructed window", root=tmp_path)
