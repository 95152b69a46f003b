"""Round 5 of the bad-input table (tests/test_robustness*.py): how real exports and clumsy hands write files.

Text and .csv as other tools write them: a polarity column of True / False (pandas' bool column), a
spreadsheet's .csv in a locale whose decimal mark is the comma (`0,0125;12;7;1`), every value quoted
(csv.QUOTE_ALL), comment lines (`# t x y p`) on top of a `t x y p` file, a line of column names on top of
one, pandas' unnamed index column; files compressed with gzip, bzip2 or xz; numpy's .npz archives,
structured (record) arrays and [4, N] (transposed) arrays; an HQF-style .h5 without its
'sensor_resolution' attribute (with and without --sensor); and ``python -m evinr_lite.apps.cli``, which did
nothing. Valid files are read to the right events (checked value by value against the same events written
plainly); bad ones give exit status 2 with ``evinr-lite: error:`` naming the problem and the fix, never an
internal error or a traceback, and leave no file behind; reconstruct is refused before training. Guards:
odd inputs next to these that must keep their outcome.
"""
import bz2
import gzip
import lzma
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from evinr_lite import EventDataError, read_recording
from evinr_lite.apps.cli import main

from test_robustness import H, W, _events, tree
from test_robustness_round4 import FAST, SENSOR, _both_commands_refuse, _hqf

ROOT = Path(__file__).resolve().parents[1]


def _reference():
    """The events every file below holds: t seconds, x, y and polarity as 0 / 1."""
    t, x, y, p = _events()
    return t, x, y, (p > 0).astype(int)


def _same_events(path, **kwargs):
    t, x, y, on = _reference()
    ev = read_recording(path, **kwargs).events
    assert ev.sensor_size == (H, W)
    np.testing.assert_allclose(ev.t + ev.t_origin, t, atol=1e-9)
    np.testing.assert_array_equal(ev.x, x)
    np.testing.assert_array_equal(ev.y, y)
    np.testing.assert_array_equal(ev.p, np.where(on > 0, 1, -1))


def _rows(fmt, sep=","):
    t, x, y, on = _reference()
    return "".join(fmt.format(t=a, x=b, y=c, p=d, tf=("True" if d else "False"), s=sep) + "\n"
                   for a, b, c, d in zip(t, x, y, on))


def _info_ok(capsys, path, *extra):
    code = main(["info", str(path), *extra])
    out, err = capsys.readouterr()
    assert code == 0 and "error" not in err and "Traceback" not in err, (code, out, err)


# ---- 1. files that are valid and were refused: read to the right events ---------------------------------------

def _valid(tmp_path, case):
    if case == "csv polarity True/False, names line":            # pandas: df.to_csv(path, index=False)
        text = "t,x,y,p\n" + _rows("{t:.9f},{x},{y},{tf}")
    elif case == "csv polarity true/false, no names line":
        text = _rows("{t:.9f},{x},{y},{tf}").lower()
    elif case == "txt polarity True/False":
        text = f"{W} {H}\n" + _rows("{t:.9f} {x} {y} {tf}")
    elif case == "csv semicolons and decimal commas, names line":  # a spreadsheet in a German or French locale
        text = "\ufefft;x;y;p\r\n" + _rows("{t:.9f};{x};{y};{p}").replace(".", ",").replace("\n", "\r\n")
    elif case == "csv semicolons and decimal commas, no names line":
        text = _rows("{t:.9f};{x};{y};{p}").replace(".", ",")
    elif case == "csv every value quoted":                           # csv.QUOTE_ALL
        text = '"t","x","y","p"\n' + _rows('"{t:.9f}","{x}","{y}","{p}"')
    elif case == "txt comment lines on top":
        text = "# recorded with a DAVIS346\n# t x y p\n" + f"{W} {H}\n" + _rows("{t:.9f} {x} {y} {p}")
    else:                                                             # % comments, as Metavision writes them
        text = "% date 2024-05-01\n" + f"{W} {H}\n% t x y p\n" + _rows("{t:.9f} {x} {y} {p}")
    path = tmp_path / ("ev.csv" if case.startswith("csv") else "ev.txt")
    path.write_bytes(text.encode("utf-8"))
    return path, ({"sensor_size": (H, W)} if case.startswith("csv") else {})


VALID = ["csv polarity True/False, names line", "csv polarity true/false, no names line", "txt polarity True/False",
         "csv semicolons and decimal commas, names line", "csv semicolons and decimal commas, no names line",
         "csv every value quoted", "txt comment lines on top", "txt % comment lines around the W H line"]


@pytest.mark.parametrize("case", VALID)
def test_valid_exports_are_read_to_the_right_events(capsys, tmp_path, case):
    path, kwargs = _valid(tmp_path, case)
    _same_events(path, **kwargs)
    _info_ok(capsys, path, *(SENSOR if kwargs else ()))


def test_an_hqf_file_without_sensor_resolution_is_read_with_the_sensor_given(capsys, tmp_path):
    import h5py

    path = _hqf(tmp_path / "e.h5")
    with h5py.File(path, "r+") as f:
        del f.attrs["sensor_resolution"]
    t, x, y, p = _events()
    ev = read_recording(path, sensor_size=(H, W)).events
    assert ev.sensor_size == (H, W) and len(ev.t) == len(t)
    np.testing.assert_array_equal(ev.x, x)
    np.testing.assert_array_equal(ev.y, y)
    _info_ok(capsys, path, *SENSOR)
    code = main(["reconstruct", str(path), "--out", str(tmp_path / "out"), *SENSOR, *FAST])
    out, err = capsys.readouterr()
    assert code == 0 and (tmp_path / "out" / "run.json").is_file(), (code, out, err)


# ---- 2. bad input whose message did not name the problem or the fix --------------------------------------------

def _bad(tmp_path, case):
    t, x, y, p = _events()
    if case == "csv pandas index column":                              # df.to_csv(path) keeps the index
        path = tmp_path / "ev.csv"
        path.write_text(",t,x,y,p\n" + "".join(f"{i},{r}" for i, r in enumerate(_rows("{t:.9f},{x},{y},{p}")
                                                                                 .splitlines(keepends=True))))
        return path, SENSOR, r"index column, as pandas writes.*index=False"
    if case == "txt line of column names":
        path = tmp_path / "ev.txt"
        path.write_text("t x y p\n" + _rows("{t:.9f} {x} {y} {p}"))
        return path, SENSOR, r"line 1: .*it names the columns.*start that line with `#`.*\.csv"
    if case == "txt line of comma-separated names":
        path = tmp_path / "ev.txt"
        path.write_text("timestamp,x,y,polarity\n" + _rows("{t:.9f} {x} {y} {p}"))
        return path, SENSOR, r"line 1: found 1 columns.*it names the columns.*start that line with `#`"
    if case in ("gzip", "bzip2", "xz"):
        compress, tool, suffix = {"gzip": (gzip.compress, "gunzip", "gz"), "bzip2": (bz2.compress, "bunzip2", "bz2"),
                                  "xz": (lzma.compress, "unxz", "xz")}[case]
        path = tmp_path / f"ev.txt.{suffix}"
        path.write_bytes(compress((f"{W} {H}\n" + _rows("{t:.9f} {x} {y} {p}")).encode()))
        return path, [], rf"{case}-compressed file; decompress it first \({tool} "
    if case == "npz of t, x, y, p":
        np.savez(tmp_path / "ev.npz", t=t, x=x, y=y, p=p)
        return tmp_path / "ev.npz", SENSOR, r"ev\.npz: a numpy \.npz archive \(arrays t, x, y, p\).*np\.stack"
    if case == "npy structured (Metavision EventCD)":
        a = np.zeros(len(t), dtype=[("x", "<u2"), ("y", "<u2"), ("p", "<i2"), ("t", "<i8")])
        a["x"], a["y"], a["p"], a["t"] = x, y, p > 0, np.round(t * 1e6)
        np.save(tmp_path / "ev.npy", a)
        return tmp_path / "ev.npy", SENSOR, r"structured array with fields \['x', 'y', 'p', 't'\].*np\.stack"
    if case == "npy [4, N]":
        np.save(tmp_path / "ev.npy", np.stack([t, x, y, p]))
        return tmp_path / "ev.npy", SENSOR, r"shape \(4, 400\).*transposed.*np\.load\(path\)\.T"
    path = _hqf(tmp_path / "e.h5")
    import h5py

    with h5py.File(path, "r+") as f:
        del f.attrs["sensor_resolution"]
    return path, [], r"no root attribute 'sensor_resolution'.*pass it \(--sensor HxW\)"


BAD = ["csv pandas index column", "txt line of column names", "txt line of comma-separated names", "gzip", "bzip2",
       "xz", "npz of t, x, y, p", "npy structured (Metavision EventCD)", "npy [4, N]",
       "hqf without sensor_resolution"]


@pytest.mark.parametrize("case", BAD)
def test_bad_input_names_the_problem_and_the_fix(capsys, monkeypatch, tmp_path, case):
    path, extra, pattern = _bad(tmp_path, case)
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, extra, pattern)


def test_python_m_evinr_lite_apps_cli_runs_the_command(tmp_path):
    before = tree(tmp_path)
    run = subprocess.run([sys.executable, "-m", "evinr_lite.apps.cli", "info", str(tmp_path / "nope.txt")],
                         capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert run.returncode == 2 and "evinr-lite: error: no such file or folder" in run.stderr, run
    assert "RuntimeWarning" not in run.stderr, run.stderr   # the package does not import cli before runpy runs it
    assert tree(tmp_path) == before


# ---- 3. guards: odd inputs next to these keep their outcome ------------------------------------------------------

def test_guard_csv_with_semicolons_and_decimal_points_is_read_as_before(tmp_path):
    path = tmp_path / "ev.csv"
    path.write_text("t;x;y;p\n" + _rows("{t:.9f};{x};{y};{p}"))
    _same_events(path, sensor_size=(H, W))


def test_guard_a_polarity_word_other_than_true_or_false_is_refused(tmp_path):
    path = tmp_path / "ev.csv"
    path.write_text("t,x,y,p\n" + _rows("{t:.9f},{x},{y},{tf}").replace("False", "off"))
    with pytest.raises(EventDataError, match=r"ev\.csv, line \d+: p is not a number"):
        read_recording(path, sensor_size=(H, W))


def test_guard_a_damaged_line_after_the_first_gets_no_names_hint(capsys, monkeypatch, tmp_path):
    path = tmp_path / "ev.txt"
    path.write_text(f"{W} {H}\n" + _rows("{t:.9f} {x} {y} {p}") + "end of x y\n")
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, [],
                          r"line 402: the timestamp is not a number.*end of x y", before_training=False)
    with pytest.raises(EventDataError) as err:
        read_recording(path)
    assert "names the columns" not in str(err.value)


def test_guard_a_comment_after_the_first_event_is_still_refused(tmp_path):
    path = tmp_path / "ev.txt"
    rows = _rows("{t:.9f} {x} {y} {p}").splitlines(keepends=True)
    path.write_text(f"{W} {H}\n" + "".join(rows[:5]) + "# a note\n" + "".join(rows[5:]))
    with pytest.raises(EventDataError, match=r"ev\.txt, line 7: "):
        read_recording(path)


def test_guard_a_zip_that_is_no_npz_keeps_the_zip_message(capsys, tmp_path):
    import zipfile

    with zipfile.ZipFile(tmp_path / "seq.zip", "w") as archive:
        archive.writestr("events.txt", "0.1 1 1 1\n")
    code = main(["info", str(tmp_path / "seq.zip")])
    err = capsys.readouterr().err
    assert code == 2 and "a zip archive; unzip it first" in err, err


def test_guard_an_hqf_sensor_given_that_differs_from_sensor_resolution_is_refused(capsys, monkeypatch, tmp_path):
    path = _hqf(tmp_path / "e.h5")
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, ["--sensor", f"{H + 2}x{W}"],
                          rf"sensor is \(H, W\) = \({H}, {W}\).*but sensor size \({H + 2}, {W}\) was given")


def test_an_option_the_format_does_not_take_is_refused_naming_the_ones_it_takes(tmp_path):
    """ev.read_recording(ijrr_folder, camera="right") raised a bare TypeError from the reader's call; now the
    refusal names the option, MVSEC as the format that takes camera=, and the reader's own options. A misspelt
    option is refused the same way, and the options a format takes still work."""
    folder = tmp_path / "seq"
    folder.mkdir()
    t, x, y, on = _reference()
    (folder / "events.txt").write_text("".join(f"{a:.6f} {b} {c} {d}\n" for a, b, c, d in zip(t, x, y, on)))
    with pytest.raises(EventDataError, match=r"takes no option 'camera' \(camera= is for MVSEC.*takes t_origin, "
                                             r"sensor_size, time_unit"):
        read_recording(folder, camera="right", sensor_size=(H, W))
    with pytest.raises(EventDataError, match="takes no option 'sensor_sise'"):
        read_recording(folder, sensor_sise=(H, W))
    assert len(read_recording(folder, sensor_size=(H, W)).events) == len(t)
