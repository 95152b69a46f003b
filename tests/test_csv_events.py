"""The .csv event reader: Metavision's `x,y,p,t` layout and header-named column orders give the same
events as the `t x y p` text reader, and every malformed file is refused with the fix."""
import subprocess
import sys
import warnings

import numpy as np
import pytest

from evinr_lite.core.events import EventDataError
from evinr_lite.io.formats.csv_events import read_events_csv
from evinr_lite.io.formats.registry import detect_format, read_recording
from evinr_lite.io.formats.txt import read_events_txt

H, W = 30, 40


def _events(n=500, seed=0):
    rng = np.random.default_rng(seed)
    t_us = np.sort(rng.integers(1_000, 2_000_000, n))          # microseconds
    return t_us, rng.integers(0, W, n), rng.integers(0, H, n), rng.integers(0, 2, n)


@pytest.fixture
def reference(tmp_path):
    """The same events as a `t x y p` text file (seconds), read by the txt reader."""
    t_us, x, y, p = _events()
    path = tmp_path / "ref.txt"
    path.write_text(f"{W} {H}\n" + "".join(f"{a / 1e6:.6f} {b} {c} {d}\n" for a, b, c, d in zip(t_us, x, y, p)))
    return read_events_txt(path)


def _write(path, header, rows):
    path.write_text("".join(line + "\n" for line in header) + "".join(r + "\n" for r in rows))
    return path


def _same(a, b):
    np.testing.assert_allclose(a.t, b.t, atol=1e-9)
    for name in ("x", "y", "p"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert a.sensor_size == b.sensor_size


def test_metavision_layout_with_geometry_reads_microseconds(tmp_path, reference):
    t_us, x, y, p = _events()
    path = _write(tmp_path / "mv.csv", [f"%geometry:{W},{H}"], [f"{b},{c},{d},{a}" for a, b, c, d in zip(t_us, x, y, p)])
    with warnings.catch_warnings():
        warnings.simplefilter("error")          # the layout fixes the unit: no TimeUnitWarning
        ev = read_events_csv(path)
    _same(ev, reference)
    assert detect_format(path) == "csv"
    other = tmp_path / "mv.log"                 # the geometry line is recognised whatever the name
    other.write_bytes(path.read_bytes())
    assert detect_format(other) == "csv"


@pytest.mark.parametrize("names, fmt, scale", [
    ("t,x,y,p", "{t:.6f},{x},{y},{p}", 1e-6),
    ("timestamp_us,x,y,polarity", "{t},{x},{y},{p}", 1),
    ("x,y,p,t", "{x},{y},{p},{t:.6f}", 1e-6),
    ("X; Y; Time [ms]; Pol", "{x}; {y}; {t:.3f}; {p}", 1e-3),
    ('"y","x","p","ts"', "{y},{x},{p},{t:.6f}", 1e-6),
    ("t,x,y,p,", "{t:.6f},{x},{y},{p},", 1e-6),          # a trailing separator on every line
    ("t x y p", "{t:.6f} {x} {y} {p}", 1e-6),            # white space only
])
def test_named_columns_in_any_order(tmp_path, reference, names, fmt, scale):
    t_us, x, y, p = _events()
    rows = [fmt.format(t=a * scale, x=b, y=c, p=d) for a, b, c, d in zip(t_us, x, y, p)]
    ev = read_events_csv(_write(tmp_path / "named.csv", [names], rows), sensor_size=(H, W))
    _same(ev, reference)


@pytest.mark.parametrize("order", ["txyp", "xypt"])
def test_unnamed_order_is_read_off_the_rows(tmp_path, reference, order):
    t_us, x, y, p = _events()
    rows = ([f"{a / 1e6:.6f},{b},{c},{d}" for a, b, c, d in zip(t_us, x, y, p)] if order == "txyp" else
            [f"{b},{c},{d},{a}" for a, b, c, d in zip(t_us, x, y, p)])
    ev = read_events_csv(_write(tmp_path / "plain.csv", [], rows), sensor_size=(H, W))
    _same(ev, reference)


def test_absolute_microsecond_clock_is_exact(tmp_path):
    t_us, x, y, p = _events()
    rows = [f"{b},{c},{d},{a + 1_700_000_000_000_000}" for a, b, c, d in zip(t_us, x, y, p)]
    ev = read_events_csv(_write(tmp_path / "abs.csv", [f"%geometry:{W},{H}"], rows))
    np.testing.assert_allclose(ev.t, t_us / 1e6, atol=1e-9)   # whole seconds of the clock taken off exactly
    assert ev.t_origin == 1_700_000_000


@pytest.mark.parametrize("header, rows, kwargs, message", [
    (["time,col,row,pol"], ["0.1,1,2,1"], {}, r"names the columns \['time', 'col', 'row', 'pol'\].*rename them"),
    (["t,x,y"], ["0.1,1,2"], {}, r"needs exactly four"),
    ([], ["0.1,2,3,5", "0.2,1,1,7"], {}, r"cannot tell which column is which.*add a first line naming the columns"),
    (["t,x,y,p"], ["0.1,1,2,1", "0.9,,3,1"], {}, r"line 3: found 3 columns.*line reads '0\.9,,3,1'"),
    (["t,x,y,p"], ["0.5,1,2,1", "0.1,1,2,0"], {}, r"line 3: the timestamp is earlier.*sort the rows by the time column"),
    (["%geometry:0,30"], ["1,2,1,100", "1,2,0,200"], {}, r"gives a sensor of 30x0"),
    ([f"%geometry:{W},{H}"], ["1,2,1,100", "1,2,0,200"], {"sensor_size": (H + 1, W)},
     r"`%geometry:W,H` line says the sensor is \(H, W\) = \(30, 40\)"),
    (["t_us,x,y,p"], ["100,1,2,1", "200,1,2,0"], {"time_unit": "s"}, r"names the time in 'us'.*time_unit='s'"),
    (["t,x,y,p"], ["0.1,1,2,1", "0.2,1,2,0"], {}, r"no `%geometry:W,H` line\); pass sensor_size=\(H, W\)"),
    ([f"%geometry:{W},{H}"], [], {}, r"no events found after the header"),
    (["t,x,y,p"], [], {}, r"no events found; expected lines `t,x,y,p`"),
    (["t,x,y,p"], ["0.1,1,2,1", "0.2,1.5,2,0"], {"sensor_size": (H, W)}, r"line 3: x must be a whole pixel index"),
])
def test_bad_files_are_refused_with_the_fix(tmp_path, header, rows, kwargs, message):
    with pytest.raises(EventDataError, match=message):
        read_events_csv(_write(tmp_path / "bad.csv", header, rows), **kwargs)


def test_read_recording_and_the_command_line(tmp_path):
    t_us, x, y, p = _events()
    path = _write(tmp_path / "rec.csv", [f"%geometry:{W},{H}"], [f"{b},{c},{d},{a}" for a, b, c, d in zip(t_us, x, y, p)])
    rec = read_recording(path)
    assert rec.meta["format"] == "csv" and rec.events.sensor_size == (H, W) and len(rec.events.t) == len(t_us)
    run = subprocess.run([sys.executable, "-m", "evinr_lite", "info", str(path)], capture_output=True, text=True)
    assert run.returncode == 0 and "csv" in run.stdout and f"{H}x{W}" in run.stdout
    plain = _write(tmp_path / "plain.csv", ["t,x,y,p"], [f"{a / 1e6:.6f},{b},{c},{d}" for a, b, c, d in zip(t_us, x, y, p)])
    run = subprocess.run([sys.executable, "-m", "evinr_lite", "info", str(plain)], capture_output=True, text=True)
    assert run.returncode == 2 and "--sensor HxW" in run.stderr
