"""Round 8 of the bad-input table (tests/test_robustness*.py): numbers stored in types too small for them, paths
as people type them, writers asked to overwrite or to play at impossible rates, windows between two events, and
misspelt config fields.

Fixes (each test failed before its fix): x or y stored as uint8 on a sensor wider or taller than 256 (a DAVIS346)
wrapped to 0..255 and was read without a word (int8 ones were refused without the cause); timestamps of a 32-bit
counter that wrapped around (uint32 microseconds every 71.6 minutes, int32 ones) were told to be sorted, which
interleaves the laps, in Events, the windowed readers and text / .csv; polarities stored as 0/255 or 1/2 got no
conversion; a recording path starting with ``~`` (quoted, or from Python) was "no such file" although --out
expanded it, and ``--out ~nouser/x`` was an internal RuntimeError; a web address and a folder holding recordings
were "no such file" / "folder of unknown format" without the fix; ``save_timestamps``, ``save_csv`` and
``save_log_intensity`` into a missing folder or onto a folder raised the OS's bare errors; the file writers wrote in
place (a failed write left half a file); ``save_frames_png`` left an empty folder behind on bad frames and mixed its
frames silently with older ones of a longer run; ``save_mp4`` at fps over 65535 raised OpenCV's misleading
RuntimeError and under about 0.003 aborted the interpreter (libavcodec), ``save_gif`` under 0.0016 Pillow's
OverflowError; ``reconstruct --start/--end`` around no event was an internal ValueError ('auto') with the kit
recipe, a "constant frames" error blaming the settings with --keep-background, and a frame of untrained noise with
exit 0 with --recipe paper (``stream_reconstruct`` had no check of its span); ``EvINRConfig(tua=2)`` was
Python's TypeError without the field meant, and ``cfg.tua = 2`` was kept silently as an attribute no step reads;
``--at`` times in ms / us got no hint of the unit.

Guards: odd inputs next to these that already behave and must keep their outcome.
"""
import os
import re

import numpy as np
import pytest

from evinr_lite import EventDataError, Events, EvINRConfig, read_recording
from evinr_lite.io import export

from test_robustness import H, W, _events, assert_clear_error, run, tree
from test_robustness_round4 import FAST, SENSOR, _both_commands_refuse, _hqf

LAP = 2 ** 32


def _wrapped_us(n=400, seed=0, signed=False):
    """Integer microseconds of a 32-bit counter that wraps once in the middle of ``n`` events (steps up to 20 ms)."""
    rng = np.random.default_rng(seed)
    start = (2 ** 31 if signed else LAP) - 2_000_000
    t = start + np.cumsum(rng.integers(1, 20_000, n))
    t = (t + 2 ** 31) % LAP - 2 ** 31 if signed else t % LAP
    return t.astype(np.int32 if signed else np.uint32), rng.integers(0, W, n), rng.integers(0, H, n), \
        rng.choice([-1, 1], n)


UNWRAP = r"32-bit counter of microseconds wrapped around \(every 71\.6 minutes\).*a sort would interleave.*" \
         r"2\*\*32 \* np\.cumsum"


def _npy(path, *cols, dtype=np.float64):
    np.save(path, np.stack(cols, 1).astype(dtype))
    return path


# ---- 1. fixes: numbers in types too small for them ------------------------------------------------------------

@pytest.mark.parametrize("axis", ["x", "y"])
def test_uint8_coordinates_on_a_larger_sensor_are_refused_as_wrapped(axis):
    """A DAVIS346 (260 x 346) saved with uint8 coordinates: the columns past 255 became 0..89, all in range."""
    t, x, y, p = _events()
    size = (260, 346)
    col = (np.arange(len(t)) * 7 % (size[1] if axis == "x" else size[0])) % 256
    x, y = (col.astype(np.uint8), y) if axis == "x" else (x, col.astype(np.uint8))
    with pytest.raises(EventDataError, match=rf"{axis} is stored as uint8, which holds only 0 \.\. 255, but the sensor "
                                             rf"is \d+ \w+ \w+ and {axis} reaches 255: .* wrapped around .*uint16"):
        Events(t, x, y, p, size)


def test_uint8_coordinates_in_an_hdf5_file_are_refused(capsys, monkeypatch, tmp_path):
    t, x, y, p = _events()
    xs = (np.arange(len(t)) * 7 % 346 % 256).astype(np.uint8)
    path = _hqf(tmp_path / "e.h5", xs=xs, sensor_resolution=(260, 346))
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, [], r"x is stored as uint8.*wrapped around",
                          before_training=False)


def test_int8_coordinates_that_went_negative_name_the_type():
    t, x, y, p = _events()
    x = (np.arange(len(t)) * 7 % 346).astype(np.int8)
    with pytest.raises(EventDataError, match=r"coordinates span \[-128, 127\].*x is stored as int8, which holds only "
                                             r"-128 \.\. 127: the values past 127 wrapped around to negative"):
        Events(t, x, y, p, (260, 346))


@pytest.mark.parametrize("signed", [False, True], ids=["uint32", "int32"])
def test_a_wrapped_32_bit_clock_in_events_is_named_not_sorted(signed):
    t, x, y, p = _wrapped_us(signed=signed)
    pattern = (r"across 2\*\*31 to -2\*\*31: a signed " if signed else r"across 2\*\*32: a ") + UNWRAP
    with pytest.raises(EventDataError, match=pattern):
        Events.from_arrays(t, x, y, p, (H, W), time_unit="us")


@pytest.mark.parametrize("fmt", ["npy", "txt", "csv"])
def test_a_wrapped_32_bit_clock_in_a_file_is_named(capsys, monkeypatch, tmp_path, fmt):
    t, x, y, p = _wrapped_us()
    on = (p > 0).astype(int)
    if fmt == "npy":
        path, extra, pattern = _npy(tmp_path / "ev.npy", t, x, y, on, dtype=np.int64), SENSOR, "32-bit counter of ticks"
        extra = [*extra, "--time-unit", "us"]
    else:
        path = tmp_path / f"ev.{fmt}"
        head, sep = (f"{W} {H}\n", " ") if fmt == "txt" else ("t_us,x,y,p\n", ",")
        path.write_text(head + "".join(sep.join(map(str, row)) + "\n" for row in zip(t, x, y, on)))
        extra, pattern = (["--time-unit", "us"] if fmt == "txt" else SENSOR), UNWRAP
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, extra,
                          rf"not sorted.*they fall from 4294\d+ to \d+, across 2\*\*32.*{pattern}")


@pytest.mark.parametrize("values, hint", [((0, 255), r"0/255 are an 8-bit image's black and white: if 255 is ON and "
                                                     r"0 OFF, convert them with p = np\.where\(p == 255, 1, -1\)"),
                                          ((1, 2), r"1/2 count from 1 \(as MATLAB indexes\).*np\.where\(p == 2, 1, -1\)"),
                                          ((-1, 2), r"if 2 is ON and -1 OFF, convert them")],
                         ids=["0/255", "1/2", "other pair"])
def test_two_valued_polarities_get_their_conversion(capsys, monkeypatch, tmp_path, values, hint):
    t, x, y, p = _events()
    stored = np.where(p > 0, values[1], values[0])
    with pytest.raises(EventDataError, match=hint):
        Events(t, x, y, stored, (H, W))
    path = _npy(tmp_path / "ev.npy", t, x, y, stored)
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, SENSOR, r"neither -1/\+1 nor 0/1.*" + hint,
                          before_training=False)


# ---- 2. fixes: paths as people type them ---------------------------------------------------------------------

@pytest.fixture
def home(tmp_path, monkeypatch):
    monkeypatch.setenv("HOME", str(tmp_path))
    t, x, y, p = _events()
    _npy(tmp_path / "ev.npy", t, x, y, p)
    return tmp_path


def test_a_recording_path_with_a_tilde_is_read_as_out_is_written(capsys, home):
    """``--out ~/x`` was expanded and the recording's ``~/ev.npy`` was "no such file" (a quoted argument, a
    notebook's read_recording("~/data/ev.npy"))."""
    from evinr_lite.io import open_recording

    assert read_recording("~/ev.npy", sensor_size=(H, W)).meta["path"] == str(home / "ev.npy")
    with open_recording("~/ev.npy", sensor_size=(H, W)) as source:
        assert source.path == home / "ev.npy"
    code, out, err = run(capsys, "info", "~/ev.npy", *SENSOR)
    assert code == 0 and "error" not in err, err


def test_batch_reads_a_recording_path_with_a_tilde(home):
    from evinr_lite.apps.batch import resolve_inputs

    assert resolve_inputs(["~/ev.npy"], log=lambda *a: None)[0]["path"] == str((home / "ev.npy").resolve())


def test_a_tilde_of_no_user_is_named_on_input_and_output(capsys, home):
    assert_clear_error(capsys, ["info", "~nosuchuser8/ev.npy", *SENSOR],
                       r"~nosuchuser8 names no user's home folder on this machine; write the folder's full path",
                       root=home)
    assert_clear_error(capsys, ["reconstruct", home / "ev.npy", *SENSOR, "--out", "~nosuchuser8/out", *FAST],
                       r"--out '~nosuchuser8/out' starts with ~nosuchuser8, which names no user's home folder",
                       root=home)


def test_a_web_address_is_named(capsys, tmp_path):
    assert_clear_error(capsys, ["info", "https://example.com/data/ev.h5"],
                       r"https://example\.com/data/ev\.h5 is a web address, not a file on this machine; download it "
                       r"first.*data_fetch get", root=tmp_path)


def test_a_folder_holding_recordings_names_them_and_batch(capsys, tmp_path):
    t, x, y, p = _events()
    folder = tmp_path / "session"
    folder.mkdir()
    for name in ("a.npy", "b.npy"):
        _npy(folder / name, t, x, y, p)
    (folder / "notes.md").write_text("not a recording")
    assert_clear_error(capsys, ["info", folder, *SENSOR],
                       r"a folder holding 2 recording\(s\) \(a\.npy, b\.npy\), not one recording.*pass one of them, "
                       r"e\.g\. .*session/a\.npy, or give the folder to `evinr-lite batch .*session --out DIR`",
                       root=tmp_path)


# ---- 3. fixes: the export writers ----------------------------------------------------------------------------

FRAMES = np.random.default_rng(0).uniform(0, 1, (3, H, W))


@pytest.mark.parametrize("writer, args, name", [
    (export.save_timestamps, ([0.1, 0.2],), "save_timestamps"),
    (export.save_csv, ([{"a": 1}],), "save_csv"),
    (export.save_log_intensity, (FRAMES, [0.1, 0.2, 0.3]), "save_log_intensity"),
], ids=["timestamps", "csv", "log intensity"])
def test_file_writers_check_their_path(tmp_path, writer, args, name):
    before = tree(tmp_path)
    with pytest.raises(EventDataError, match=rf"{name}: the folder .*missing does not exist.*mkdir"):
        writer(tmp_path / "missing" / "f.out", *args)
    with pytest.raises(EventDataError, match=rf"{name}: .* is a folder; pass a file name in it"):
        writer(tmp_path, *args)
    assert tree(tmp_path) == before


@pytest.mark.parametrize("writer, name, args", [
    (export.save_gif, "a.gif", (FRAMES, 10)), (export.save_mp4, "a.mp4", (FRAMES, 10)),
    (export.save_timestamps, "t.txt", ([0.1, 0.2],)), (export.save_csv, "m.csv", ([{"a": 1}],)),
    (export.save_log_intensity, "l.h5", (FRAMES, [0.1, 0.2, 0.3])),
], ids=["gif", "mp4", "timestamps", "csv", "log intensity"])
def test_a_failed_write_leaves_the_file_that_was_there(tmp_path, monkeypatch, writer, name, args):
    """Each writer wrote in place: an error or an interruption mid-write left half a file over the old one."""
    path = tmp_path / name
    path.write_bytes(b"the user's earlier file")
    real_replace = os.replace

    def fail_at_rename(src, dst):
        assert Path(src).exists() and Path(src).parent == tmp_path     # the whole new file was written beside
        raise KeyboardInterrupt

    from pathlib import Path
    monkeypatch.setattr(os, "replace", fail_at_rename)
    with pytest.raises(KeyboardInterrupt):
        writer(path, *args)
    monkeypatch.setattr(os, "replace", real_replace)
    assert sorted(os.listdir(tmp_path)) == [name] and path.read_bytes() == b"the user's earlier file"
    assert writer(path, *args) == path and path.read_bytes() != b"the user's earlier file"   # then it is replaced


def test_png_frames_that_are_refused_leave_no_folder(tmp_path):
    bad = FRAMES.copy()
    bad[1, 2, 3] = np.nan
    with pytest.raises(EventDataError, match=r"NaN or inf"):
        export.save_frames_png(tmp_path / "pngs", bad)
    assert os.listdir(tmp_path) == []


def test_png_frames_are_not_mixed_with_older_ones(tmp_path):
    """Three new frames into a folder of six older ones left 0-2 new and 3-5 old, passing for one run."""
    export.save_frames_png(tmp_path / "pngs", np.random.default_rng(1).uniform(0, 1, (6, H, W)))
    before = tree(tmp_path)
    with pytest.raises(EventDataError, match=r"already holds 6 frame\(s\) named frame_NNNNN\.png.*would mix with them.*"
                                             r"overwrite=True"):
        export.save_frames_png(tmp_path / "pngs", FRAMES)
    assert tree(tmp_path) == before
    export.save_frames_png(tmp_path / "pngs", FRAMES, overwrite=True)
    assert sorted(os.listdir(tmp_path / "pngs")) == [f"frame_{i:05d}.png" for i in range(3)]
    export.save_frames_png(tmp_path / "pngs", FRAMES, prefix="other_")     # guard: another prefix may share it
    assert len(os.listdir(tmp_path / "pngs")) == 6


def test_a_failed_png_write_into_a_new_folder_leaves_nothing(tmp_path, monkeypatch):
    from evinr_lite.io import output

    calls = []

    def write_two_then_fail(self, path, image):
        calls.append(path)
        if len(calls) == 2:
            raise OSError(28, "No space left on device")
        real(self, path, image)

    real = output.PngWriter.write
    monkeypatch.setattr(output.PngWriter, "write", write_two_then_fail)
    with pytest.raises(OSError):
        export.save_frames_png(tmp_path / "new" / "pngs", FRAMES)
    assert [p.name for p in (tmp_path / "new").iterdir()] == []


@pytest.mark.parametrize("writer, fps", [(export.save_mp4, 1e5), (export.save_mp4, 65536), (export.save_mp4, 0.001),
                                         (export.save_gif, 0.001)])
def test_a_video_rate_no_file_can_state_is_refused(tmp_path, writer, fps):
    """Over 65535 OpenCV could not open its writer (and said the GIF was written); under about 0.003 libavcodec
    aborted the interpreter; Pillow overflowed on a GIF delay past 655 s."""
    suffix = ".mp4" if writer is export.save_mp4 else ".gif"
    with pytest.raises(EventDataError, match=r"beyond what a video file can state \(0\.01 to 65535 frames per second\)"
                                             r".*the playback rate"):
        writer(tmp_path / f"a{suffix}", FRAMES, fps)
    assert os.listdir(tmp_path) == []


# ---- 4. fixes: a window around no event, misspelt fields, times in other units -------------------------------

@pytest.fixture(scope="module")
def txt(tmp_path_factory):
    t, x, y, p = _events()
    path = tmp_path_factory.mktemp("txt") / "ev.txt"
    path.write_text(f"{W} {H}\n" + "".join(f"{a:.9f} {b} {c} {int(d > 0)}\n" for a, b, c, d in zip(t, x, y, p)))
    return path


@pytest.mark.parametrize("extra", [[], ["--recipe", "paper"], ["--keep-background"]],
                         ids=["kit", "paper", "keep background"])
def test_a_window_between_two_events_is_refused(capsys, tmp_path, txt, extra):
    t = _events()[0]
    gap = int(np.argmax(np.diff(t)))
    lo, hi = t[gap] + 1e-7, t[gap + 1] - 1e-7     # no event inside
    assert_clear_error(capsys, ["reconstruct", txt, "--out", tmp_path / "o", "--start", f"{lo:.9f}", "--end",
                                f"{hi:.9f}", *extra, "--iters", "3", "--quiet", "--no-video"],
                       r"fewer than 2 events in \[.*\] s; choose a window with events \(the recording's events cover",
                       root=tmp_path)


def test_stream_reconstruct_refuses_a_span_without_two_events():
    from evinr_lite.method.streaming import stream_reconstruct

    t, x, y, p = _events()
    events = Events(t, x, y, p, (H, W))
    gap = int(np.argmax(np.diff(t)))
    with pytest.raises(EventDataError, match=r"fewer than 2 events"):
        next(stream_reconstruct(events, [t[gap] + 1e-7], EvINRConfig.paper(n_iters=3, c2f_iters=(1, 2), progress=False),
                                t_start=t[gap] + 1e-8, t_end=t[gap + 1] - 1e-8))


@pytest.mark.parametrize("make, pattern", [
    (lambda: EvINRConfig(tua=2.0), r"no field 'tua' \(a keyword given to EvINRConfig\(\.\.\.\)\); did you mean 'tau'"),
    (lambda: EvINRConfig.paper(n_iter=10), r"no field 'n_iter'.*did you mean 'n_iters'"),
    (lambda: EvINRConfig(zzz=1), r"no field 'zzz'.*see help\(EvINRConfig\)"),
], ids=["tua", "paper n_iter", "no close name"])
def test_a_misspelt_config_keyword_names_the_field_meant(make, pattern):
    with pytest.raises(EventDataError, match=pattern):
        make()
    with pytest.raises(TypeError):      # what code written for Python's own error catches
        make()


def test_a_misspelt_config_attribute_is_refused_not_kept():
    """cfg.tua = 2.0 was kept as a new attribute, and the run used the default tau."""
    cfg = EvINRConfig(C=0.2)
    with pytest.raises(EventDataError, match=r"no field 'tua' \(cfg\.tua = \.\.\. would set a new attribute that no "
                                             r"step reads\); did you mean 'tau'"):
        cfg.tua = 2.0
    assert not hasattr(cfg, "tua") and "tua" not in vars(cfg)
    cfg.tau = 2.0                       # guard: a real field is still set
    assert cfg.tau == 2.0


@pytest.mark.parametrize("at, unit", [("100000,150000", "microseconds"), ("100,150", "milliseconds")])
def test_at_times_in_another_unit_are_named(capsys, tmp_path, txt, at, unit):
    assert_clear_error(capsys, ["reconstruct", txt, "--out", tmp_path / "o", "--at", at, *FAST[2:]],
                       rf"outside the reconstructed window.*they look like {unit}: the times are seconds, e\.g\. "
                       r"0\.1,0\.15", root=tmp_path)


# ---- 5. guards: odd inputs that already behave ---------------------------------------------------------------

def test_guard_uint8_coordinates_on_a_small_sensor_and_uint16_on_a_large_one_are_read():
    t, x, y, p = _events()
    assert Events(t, x.astype(np.uint8), y.astype(np.uint8), p, (H, W)).x.dtype == np.int32
    big = (np.arange(len(t)) * 7 % 346).astype(np.uint16)
    assert Events(t, big, y, p, (260, 346)).x.max() == 345


def test_guard_a_fall_that_is_no_wrap_keeps_the_joined_hint():
    t, x, y, p = _events()
    joined = np.concatenate([t[200:], t[:200]])
    with pytest.raises(EventDataError) as info:
        Events(joined, x, y, p, (H, W))
    assert "fall back only once" in str(info.value) and "32-bit" not in str(info.value)


def test_the_unwrap_the_message_gives_sorts_a_wrapped_clock():
    t, x, y, p = _wrapped_us()
    with pytest.raises(EventDataError) as info:
        Events.from_arrays(t, x, y, p, (H, W), time_unit="us")
    fix = re.search(r"(t = t\.astype.*< 0\))", str(info.value)).group(1)
    scope = {"t": t, "np": np}
    exec(fix, scope)                     # the message's own code, as a user would paste it
    ev = Events.from_arrays(scope["t"], x, y, p, (H, W), time_unit="us")
    assert len(ev) == 400 and np.all(np.diff(ev.t) > 0) and ev.duration == pytest.approx(
        (int(scope["t"][-1]) - int(scope["t"][0])) * 1e-6)


@pytest.mark.parametrize("values, pattern", [((-1, 0, 1), r"neither -1/\+1 nor 0/1"), ((0, 1, 2), r"neither")])
def test_guard_three_valued_polarities_get_no_pair_conversion(values, pattern):
    t, x, y, _ = _events()
    p = np.array(values)[np.arange(len(t)) % len(values)]
    with pytest.raises(EventDataError, match=pattern) as info:
        Events(t, x, y, p, (H, W))
    assert "np.where" not in str(info.value)


def test_guard_big_endian_npy_and_tab_separated_text_are_read(tmp_path):
    t, x, y, p = _events()
    ev = read_recording(_npy(tmp_path / "be.npy", t, x, y, p, dtype=">f8"), sensor_size=(H, W)).events
    np.testing.assert_allclose(ev.t, t)
    path = tmp_path / "tab.txt"
    path.write_text(f"{W}\t{H}\n" + "".join(f"{a:.9f}\t{b}\t{c}\t{d}\n" for a, b, c, d in zip(t, x, y, p)))
    np.testing.assert_array_equal(read_recording(path).events.p, p)


@pytest.mark.parametrize("argv, pattern", [
    (["--start", "100ms"], r"argument --start: expected a number, got '100ms'"),
    (["--fps", "30fps"], r"argument --fps: expected a number, got '30fps'"),
    (["--sensor", "12,16"], r"argument --sensor: size must be HxW"),
    (["--display-mean", "40"], r"must lie between 0\.01 and 0\.99"),
    (["--at", "0.1;0.15"], r"could not read times from --at"),
    (["--device", "cuda:0"], r"invalid choice: 'cuda:0'"),
    (["--start", "1e5"], r"no events in the window"),
], ids=["start with unit", "fps with unit", "sensor with comma", "display mean in percent", "at with semicolons",
        "device with index", "start on another clock"])
def test_guard_flags_with_units_or_other_spellings_are_refused(capsys, tmp_path, txt, argv, pattern):
    assert_clear_error(capsys, ["reconstruct", txt, "--out", tmp_path / "o", *argv, "--iters", "3", "--quiet",
                                "--no-video"], pattern, root=tmp_path)


def test_guard_a_window_holding_events_still_streams_and_a_whole_recording_reads_nothing_more(capsys, tmp_path, txt):
    code, _, err = run(capsys, "reconstruct", txt, "--out", tmp_path / "o", "--start", "0.05", "--end", "0.15",
                       "--recipe", "paper", *FAST)
    assert code == 0, err
    assert (tmp_path / "o" / "run.json").is_file()


def test_guard_export_writers_still_write_odd_but_valid_names(tmp_path):
    assert export.save_timestamps(tmp_path / "times", [0.1]).read_text().startswith("# frame index")
    assert export.save_csv(tmp_path / "m.tsv", [{"a": 1}]).read_text() == "a\n1\n"
    assert export.save_gif(tmp_path / "slow.gif", FRAMES, 0.01).is_file()        # 100 s a frame: the slowest
    assert not [n for n in os.listdir(tmp_path) if n.startswith(".")]


def test_guard_config_fields_and_private_attributes_are_still_set():
    cfg = EvINRConfig(C=0.2)
    cfg._scratch = 1            # a private name is left alone
    assert cfg._scratch == 1
    assert EvINRConfig.paper(n_iters=30, c2f_iters=(10, 20)).n_iters == 30
