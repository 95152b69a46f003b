"""Round 7 of the bad-input table (tests/test_robustness*.py): files cut off or joined, indices counted from 1,
configs changed after they were made, stacks of odd images, writers given odd paths, and data_fetch options
that did nothing.

Fixes (each test failed before its fix): a text or .csv file whose end is zero bytes (a copy cut off by a crash
or a full disk) was "found 1 columns" (or, when short, "UTF-16/32 or binary content"); a last Ctrl-Z (DOS's
end-of-file mark) was refused as a line; a names line repeated after the events began (two exports joined with
`cat`) was "the timestamp is not a number" without the cause; a `16.0 12.0` first line was told "a `W H` header
is allowed only as the first line"; coordinates counted from 1 (MATLAB) got no hint to subtract 1; a .npy of
Python objects was called damaged; ``Events.take`` with a mask of another length or float indices raised numpy's
IndexError, ``Events.concatenate(events)`` Python's "not iterable"; an EvINRConfig field set to a bad value after
construction (``cfg.tau = "x"``) was an internal error inside ``reconstruct``, and a number given as text
('0.5') got no fix; images of different sizes given to ``score_sequence`` or ``Frames`` raised numpy's
"inhomogeneous shape"; ``save_gif`` / ``save_mp4`` to a name without their suffix, into a missing folder or onto
a folder, and ``save_frames_png`` onto a file or with a prefix holding a folder, raised PIL's, OpenCV's or the
OS's bare errors (or wrote outside the folder); ``evinr-lite demo --frames 100000000`` (or ``--size
60000x60000``) allocated until memory ran out and then named --start/--end and --fps/--at, flags the demo does
not have; an ``--out`` holding a NUL character was an internal error; ``python -m data_fetch convert
--time-unit ns`` on decimal seconds wrote a file whose events all sat at t = 0 and exited 0, and
``--event-topic`` / ``--image-topic`` on a recording that is no ROS bag were silently ignored.

Guards: odd inputs next to these that already behave and must keep their outcome.
"""
import os
import re
import shutil

import numpy as np
import pytest

from evinr_lite import EventDataError, Events, EvINRConfig, Frames, read_recording
from evinr_lite.apps.cli import main

from test_robustness import H, W, _events, assert_clear_error, df, run, tree  # noqa: F401 (df: a fixture)
from test_robustness_round4 import FAST, SENSOR, _both_commands_refuse, _hqf


def _rows(fmt):
    t, x, y, p = _events()
    return "".join(fmt(a, b, c, int(d > 0)) + "\n" for a, b, c, d in zip(t, x, y, p))


TXT = f"{W} {H}\n" + _rows(lambda a, b, c, d: f"{a:.9f} {b} {c} {d}")
CSV = "t,x,y,p\n" + _rows(lambda a, b, c, d: f"{a:.9f},{b},{c},{d}")


def _same_events(path, atol=1e-9, **kwargs):
    t, x, y, p = _events()
    ev = read_recording(path, **kwargs).events
    assert ev.sensor_size == (H, W)
    np.testing.assert_allclose(ev.t + ev.t_origin, t, atol=atol)
    np.testing.assert_array_equal(ev.x, x)
    np.testing.assert_array_equal(ev.y, y)
    np.testing.assert_array_equal(ev.p, np.where(p > 0, 1, -1))


def _text_file(tmp_path, name, data: bytes):
    path = tmp_path / name
    path.write_bytes(data)
    return path, (SENSOR if name.endswith(".csv") else [])


@pytest.fixture(scope="module")
def events():
    t, x, y, p = _events()
    return Events(t, x, y, p, (H, W))


# ---- 1. fixes: text files cut off, joined or written by old tools --------------------------------------------

@pytest.mark.parametrize("name, text", [("ev.txt", TXT), ("ev.csv", CSV), ("short.txt", f"{W} {H}\n0.1 1 2 1\n")],
                         ids=["txt", "csv", "short txt"])
def test_a_text_file_ending_in_zero_bytes_is_named_as_cut_off(capsys, monkeypatch, tmp_path, name, text):
    """A copy or a recording cut off by a crash leaves its end zero-filled: the message says so and gives the
    truncate command that keeps the lines before (the short file was "UTF-16/32 or binary content")."""
    path, extra = _text_file(tmp_path, name, text.encode() + b"\0" * 700)
    size = len(text.encode())
    pattern = rf"ends in 700 zero bytes \(NUL\) after line {text.count(chr(10))}: the file was not written completely.*" \
              rf"copy it again.*truncate -s {size} "
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, extra, pattern)
    path.write_bytes(path.read_bytes()[:size])   # the command it gives reads the file
    read_recording(path, sensor_size=(H, W))


@pytest.mark.parametrize("name, text", [("ev.txt", TXT), ("ev.csv", CSV)], ids=["txt", "csv"])
def test_a_final_ctrl_z_is_read_as_the_end_of_the_file(capsys, tmp_path, name, text):
    """Old DOS and Windows tools end a text file with Ctrl-Z (0x1A); it was refused as a line of one column."""
    path, extra = _text_file(tmp_path, name, text.encode() + b"\x1a")
    _same_events(path, sensor_size=(H, W))
    code, out, err = run(capsys, "info", path, *extra)
    assert code == 0 and "error" not in err, err


@pytest.mark.parametrize("name, text", [
    ("ev.csv", CSV[:CSV.index("\n", 3000) + 1] + "t,x,y,p\n" + CSV[CSV.index("\n", 3000) + 1:]),
    ("ev.txt", TXT[:TXT.index("\n", 3000) + 1] + "t x y p\n" + TXT[TXT.index("\n", 3000) + 1:]),
    ("ev.csv", CSV + "\ntimestamp,x,y,polarity\n" + CSV.split("\n", 1)[1]),
], ids=["csv", "txt", "csv after a blank line, other names"])
def test_a_names_line_repeated_after_the_events_began_is_named(capsys, monkeypatch, tmp_path, name, text):
    """Two exports joined with `cat` repeat their names line in the middle: named, with the fix."""
    path, extra = _text_file(tmp_path, name, text.encode())
    number = next(i for i, s in enumerate(text.splitlines()) if i and s[:1].isalpha()) + 1
    pattern = rf"line {number}: the timestamp is not a number.*it names the columns again.*cat a\.csv b\.csv.*" \
              r"delete that line.*Events\.concatenate"
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, extra, pattern)


def test_a_first_line_of_decimal_width_and_height_is_named_as_the_size_line(capsys, monkeypatch, tmp_path):
    """`16.0 12.0` on top (MATLAB's dlmwrite) was told that a `W H` header is allowed only as the first line,
    which it was."""
    path, extra = _text_file(tmp_path, "ev.txt", (f"{W}.0 {H}.0\n" + TXT.split("\n", 1)[1]).encode())
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, extra,
                          r"line 1: found 2 columns.*a `W H` first line gives the sensor size as two whole numbers.*"
                          r"`640 480`")


def test_coordinates_counted_from_one_get_the_fix(capsys, monkeypatch, tmp_path):
    """x in 1..W and y in 1..H (MATLAB, Julia, R): one past the sensor at the far edge; the message now says they
    count from 1 and to subtract 1, in the readers and in Events."""
    t, x, y, p = _events()
    x[0], y[1] = W - 1, H - 1            # both reach the far edge once shifted
    path = tmp_path / "ev.txt"
    path.write_text(f"{W} {H}\n" + "".join(f"{a:.9f} {b + 1} {c + 1} {int(d > 0)}\n" for a, b, c, d in zip(t, x, y, p)))
    pattern = r"coordinates span \[1, 16\].*they count pixels from 1 \(as MATLAB.*subtract 1 from x and y"
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, [], pattern, before_training=False)
    with pytest.raises(EventDataError, match=pattern):
        Events(t, x + 1, y + 1, p, (H, W))


def test_a_npy_of_python_objects_is_named_not_called_damaged(capsys, tmp_path):
    t, x, y, p = _events()
    np.save(tmp_path / "ev.npy", np.stack([t, x, y, p], 1).astype(object), allow_pickle=True)
    err = assert_clear_error(capsys, ["info", tmp_path / "ev.npy", *SENSOR],
                             r"ev\.npy: not a readable numeric \.npy array: it holds Python objects.*allow_pickle.*"
                             r"np\.asarray\(a, dtype=np\.float64\)", root=tmp_path)
    assert "damaged" not in err


# ---- 2. fixes: the Python API -------------------------------------------------------------------------------

@pytest.mark.parametrize("index, pattern", [
    (np.ones(3, bool), r"take: a boolean mask must have one value per event, shape \(400,\), got shape \(3,\)"),
    (np.array([0.0, 2.0]), r"take: index must be .*got float64.*index\.astype\(np\.int64\)"),
    (np.array([5, 400]), r"take: indices span \[5, 400\] but there are 400 events"),
    (np.array([7, 3]), r"take: the indices put the events out of time order.*np\.sort\(index\)"),
], ids=["mask of another length", "float indices", "out of range", "unsorted"])
def test_events_take_checks_its_index(events, index, pattern):
    with pytest.raises(EventDataError, match=pattern):
        events.take(index)


def test_guard_events_take_keeps_masks_slices_and_sorted_indices(events):
    assert len(events.take(events.p > 0)) == int((events.p > 0).sum())
    assert len(events.take(slice(10, 20))) == 10
    np.testing.assert_array_equal(events.take(np.array([1, 5, 5, 9])).t, events.t[[1, 5, 5, 9]])
    assert len(events.take([])) == 0


def test_concatenate_of_one_events_says_to_pass_a_list(events):
    with pytest.raises(EventDataError, match=r"concatenate takes a list of Events, got one Events.*\[a, b\]"):
        Events.concatenate(events)
    assert len(Events.concatenate([events])) == len(events)    # guard: a list of one


@pytest.mark.parametrize("field, value, pattern", [
    ("tau", "x", r"tau must be a finite number, got 'x'"),
    ("C", -1.0, r"C must be a positive number"),
    ("n_iters", 2.5, r"n_iters must be a finite whole number"),
    ("first_omega_0", 3.0, r"first_omega_0=3\.0 is a frequency per window.*first_omega_per_s=None"),
])
def test_a_config_field_changed_after_construction_is_checked_where_it_is_set(events, field, value, pattern):
    """cfg.tau = 'x' was accepted and became numpy's UFuncTypeError deep inside reconstruct."""
    cfg = EvINRConfig(C=0.2, progress=False)
    with pytest.raises(EventDataError, match=pattern):
        setattr(cfg, field, value)
    assert getattr(cfg, field) == getattr(EvINRConfig(C=0.2, progress=False), field)   # left as it was


def test_a_config_field_changed_to_a_good_value_is_kept_and_a_late_stage_warned():
    import copy
    import pickle

    cfg = EvINRConfig(C=0.2)
    cfg.tau, cfg.seed, cfg.C = 2.0, np.int64(3), (0.22, 0.18)
    assert (cfg.tau, cfg.seed, cfg.C) == (2.0, 3, (0.22, 0.18))
    assert pickle.loads(pickle.dumps(cfg)) == cfg and copy.deepcopy(cfg) == cfg
    with pytest.warns(UserWarning, match="not inside the run"):   # the warning a new value deserves is given
        EvINRConfig.paper().n_iters = 50


@pytest.mark.parametrize("field, value, fix", [("tau", "0.5", "tau=0.5"), ("lr", "1e-4", "lr=0.0001"),
                                               ("n_iters", "300", "n_iters=300"), ("lam", "0.01", "lam=0.01")])
def test_a_number_given_as_text_gets_the_number(field, value, fix):
    extra = {"head_solve": False} if field == "n_iters" else {}
    with pytest.raises(EventDataError, match=rf"{field} must be .*got '{value}'; pass the number itself "
                                             rf"\({re.escape(fix)}\), not text"):
        EvINRConfig(**extra, **{field: value})


def test_images_of_different_sizes_are_refused_by_name():
    from evinr_lite.evaluation.scoring import score_sequence

    ragged = [np.zeros((H, W)), np.zeros((H - 4, W))]
    with pytest.raises(EventDataError, match=r"pred_frames is ragged.*images of one size \[H, W\] each"):
        score_sequence(ragged, [0.1, 0.2], np.zeros((2, H, W)), [0.1, 0.2])
    with pytest.raises(EventDataError, match=r"gt_frames is ragged"):
        score_sequence(np.zeros((2, H, W)), [0.1, 0.2], ragged, [0.1, 0.2])
    with pytest.raises(EventDataError, match=r"Frames\.images is ragged"):
        Frames(ragged, [0.1, 0.2])
    with pytest.raises(EventDataError, match=r"Frames\.t must be numbers"):
        Frames(np.zeros((2, H, W)), ["a", "b"])


def test_exports_check_their_paths_before_writing(tmp_path):
    from evinr_lite.io import export

    frames = np.random.default_rng(0).uniform(0, 1, (3, H, W))
    (tmp_path / "a_file").write_text("mine")
    cases = [
        (export.save_gif, tmp_path / "anim", r"anim does not end in \.gif.*name it .*anim\.gif"),
        (export.save_gif, tmp_path / "anim.png", r"anim\.png does not end in \.gif.*anim\.gif"),
        (export.save_gif, tmp_path / "missing" / "a.gif", r"the folder .*missing does not exist.*mkdir"),
        (export.save_gif, tmp_path, r"is a folder; pass a file name in it"),
        (export.save_mp4, tmp_path / "missing" / "a.mp4", r"the folder .*missing does not exist"),
        (export.save_mp4, tmp_path / "a.avi", r"a\.avi does not end in \.mp4"),
    ]
    before = tree(tmp_path)
    for writer, path, pattern in cases:
        with pytest.raises(EventDataError, match=pattern):
            writer(path, frames, 10)
    with pytest.raises(EventDataError, match=r"a_file is a file, not a folder"):
        export.save_frames_png(tmp_path / "a_file", frames)
    with pytest.raises(EventDataError, match=r"prefix must be the start of a file name, without a folder"):
        export.save_frames_png(tmp_path / "png", frames, prefix="../escaped_")
    assert tree(tmp_path) == before
    assert export.save_gif(tmp_path / "odd name [1] é.GIF", frames, 10).is_file()   # guard: odd but valid


# ---- 3. fixes: the commands ---------------------------------------------------------------------------------

@pytest.mark.parametrize("argv", [["--frames", "100000000", "--size", "12x16"], ["--size", "60000x60000"]])
def test_a_demo_too_large_for_memory_is_refused_before_simulating_naming_its_own_flags(capsys, monkeypatch, tmp_path,
                                                                                      argv):
    import evinr_lite.apps.demo as demo

    monkeypatch.setattr(demo, "make_scene", lambda *a, **k: pytest.fail("simulated a demo that cannot fit"))
    err = assert_clear_error(capsys, ["demo", "--out", tmp_path / "d", *argv],
                             r"the demo at .* needs about .* GiB of memory.*choose a smaller --size, fewer --frames "
                             r"or a shorter --duration", root=tmp_path)
    assert "--start" not in err and "--fps" not in err


@pytest.mark.parametrize("command", ["reconstruct", "demo", "batch"])
def test_an_out_holding_a_nul_character_is_refused(capsys, tmp_path, command):
    """Only a Python caller of main() can pass it (argv cannot hold NUL): it was an internal ValueError."""
    path = tmp_path / "ev.txt"
    path.write_text(TXT)
    out = str(tmp_path / "a\0b")
    argv = {"reconstruct": ["reconstruct", path, "--out", out, *FAST], "demo": ["demo", "--out", out],
            "batch": ["batch", path, "--out", out]}[command]
    assert_clear_error(capsys, argv, r"--out '.*a\\x00b' holds a NUL character", root=tmp_path)


@pytest.fixture(scope="module")
def ijrr_zip(tmp_path_factory):
    from evinr_lite.sim.recordings import write_example_recording

    root = tmp_path_factory.mktemp("ijrr")
    folder = write_example_recording(root / "my_sequence", sensor_size=(H, W), duration=0.2, C=0.25,
                                     frame_rate=20.0, seed=0)
    return shutil.make_archive(str(root / "my_sequence"), "zip", folder)


def test_data_fetch_convert_refuses_a_time_unit_that_puts_every_event_at_one_instant(df, tmp_path, ijrr_zip):
    """--time-unit ns on decimal seconds wrote an .h5 of 579 events all at t = 0 and exited 0."""
    code, _, err = df("convert", ijrr_zip, "--out", tmp_path / "o.h5", "--time-unit", "ns", "--quiet")
    assert code == 2 and re.search(r"all \d+ events have the same timestamp.*o\.h5 would span no time.*"
                                   r"read in the wrong unit.*--time-unit", err), err
    assert not (tmp_path / "o.h5").exists() and not list(tmp_path.glob(".o.h5*"))
    code, _, err = df("convert", ijrr_zip, "--out", tmp_path / "o.h5", "--quiet")     # guard: without it, read
    assert code == 0, err
    assert read_recording(tmp_path / "o.h5").events.duration > 0.1


@pytest.mark.parametrize("option", ["--event-topic", "--image-topic"])
def test_data_fetch_convert_refuses_bag_topics_for_a_recording_that_is_no_bag(df, tmp_path, ijrr_zip, option):
    code, _, err = df("convert", ijrr_zip, "--out", tmp_path / "o.h5", option, "/dvs/events", "--quiet")
    assert code == 2 and re.search(rf"{option} \(\w+=\) picks the topics of a ROS bag, but this is a ijrr "
                                   r"recording, which has none; leave it out", err), err
    assert not (tmp_path / "o.h5").exists()


def test_data_fetch_names_its_own_flag_for_the_sensor_size(df, tmp_path):
    path = _hqf(tmp_path / "e.h5")
    import h5py

    with h5py.File(path, "r+") as f:
        del f.attrs["sensor_resolution"]
    code, _, err = df("convert", path, "--out", tmp_path / "o.h5", "--quiet")
    assert code == 2 and "(--sensor-size H W)" in err, err


# ---- 4. guards: odd inputs that already behave ---------------------------------------------------------------

@pytest.mark.parametrize("names, order", [("timestamp,x,y,polarity", "txyp"), ("ts,x,y,pol", "txyp"),
                                          ("x,y,t,p", "xytp"), ("T,X,Y,P", "txyp"), ("t, x, y, p", "txyp"),
                                          ("t [s],x,y,p", "txyp"), ("time_us,x,y,p", "txyp"), ("t,p,x,y", "tpxy")])
def test_guard_csv_names_lines_in_other_words_and_orders_are_read(tmp_path, names, order):
    t, x, y, p = _events()
    cols = {"t": t * (1e6 if "_us" in names else 1), "x": x, "y": y, "p": (p > 0).astype(int)}
    sep = ", " if ", " in names else ","
    fmt = {"t": "{:.9f}" if "_us" not in names else "{:.0f}", "x": "{}", "y": "{}", "p": "{}"}
    path = tmp_path / "ev.csv"
    path.write_text(names + "\n" + "".join(sep.join(fmt[c].format(cols[c][i]) for c in order) + "\n"
                                           for i in range(len(t))))
    _same_events(path, atol=6e-7 if "_us" in names else 1e-9, sensor_size=(H, W))


@pytest.mark.parametrize("names, pattern", [("t,x,y,p,extra", r"names the columns \['t', 'x', 'y', 'p', 'extra'\], "
                                                              r"but an event file needs exactly four"),
                                            ("t,x,x,p", r"needs exactly four"), ("temps,x,y,polarite", r"rename")])
def test_guard_csv_names_that_do_not_give_four_columns_are_refused(capsys, monkeypatch, tmp_path, names, pattern):
    extra = ",7" if names.count(",") == 4 else ""
    path = tmp_path / "ev.csv"
    path.write_text(names + "\n" + _rows(lambda a, b, c, d: f"{a:.9f},{b},{c},{d}{extra}"))
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, SENSOR, pattern)


@pytest.mark.parametrize("encoding", ["utf-16", "utf-16-le", "utf-32"])
def test_guard_a_csv_in_utf16_or_32_is_refused_with_the_fix(capsys, monkeypatch, tmp_path, encoding):
    path = tmp_path / "ev.csv"
    path.write_bytes(CSV.encode(encoding))
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, SENSOR, r"UTF-16/32 or binary content.*plain UTF-8")


def test_guard_a_bom_and_negative_times_are_read(tmp_path):
    t, x, y, p = _events()
    path = tmp_path / "ev.txt"
    path.write_bytes(b"\xef\xbb\xbf" + (f"{W} {H}\n" + "".join(f"{a - 0.1:.9f} {b} {c} {int(d > 0)}\n"
                                                                for a, b, c, d in zip(t, x, y, p))).encode())
    ev = read_recording(path).events
    np.testing.assert_allclose(ev.t + ev.t_origin, t - 0.1, atol=1e-9)
    assert ev.t[0] < 0


def test_guard_every_x_at_the_width_names_the_sensor_size_without_the_one_based_hint(capsys, monkeypatch, tmp_path):
    t, x, y, p = _events()
    path = tmp_path / "ev.txt"
    path.write_text(f"{W} {H}\n" + "".join(f"{a:.9f} {W} {c} {int(d > 0)}\n" for a, c, d in zip(t, y, p)))
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, [], r"x \(column, width W\) coordinates span \[16, 16\]"
                          r" but sensor_size \(H, W\) = \(12, 16\) allows \[0, 15\]; check the sensor size",
                          before_training=False)
    with pytest.raises(EventDataError) as info:
        Events(t, np.full(len(t), W), y, p, (H, W))
    assert "count pixels from 1" not in str(info.value)


def test_guard_a_sensor_size_given_as_w_h_in_the_api_names_the_other_way_round():
    t, x, y, p = _events()
    with pytest.raises(EventDataError, match=r"the events fit \(12, 16\), the size given the other way round"):
        Events.from_arrays(t, x, y, p, (W, H))


@pytest.mark.parametrize("case, pattern", [
    ("ps strings", r"events/ps must be numeric, got dtype \|S1"),
    ("ts vlen strings", r"events/ts must be numeric, got dtype object"),
    ("ts shorter", r"must be 1-D with the same length, got \[\(0,\)"),
    ("ts scalar", r"must be 1-D with the same length, got \[\(\),"),
])
def test_guard_hdf5_datasets_of_text_or_other_lengths_are_refused(capsys, monkeypatch, tmp_path, case, pattern):
    import h5py

    t, x, y, p = _events()
    over = {"ps strings": {"ps": np.array([b"1" if v > 0 else b"0" for v in p])},
            "ts vlen strings": {"ts": np.array([str(v) for v in t], dtype=h5py.string_dtype())},
            "ts shorter": {"ts": np.zeros(0)}, "ts scalar": {"ts": np.float64(0.1)}}[case]
    path = _hqf(tmp_path / "e.h5", **over)
    _both_commands_refuse(capsys, monkeypatch, tmp_path, path, [], pattern)


@pytest.mark.parametrize("arrays", [dict(t="t", x="x", y="y"), dict(t="t", x="x", y="y", p="p", meta=None),
                                    dict(events=None)])
def test_guard_npz_archives_name_their_arrays_and_the_fix(capsys, tmp_path, arrays):
    t, x, y, p = _events()
    values = {"t": t, "x": x, "y": y, "p": p, "meta": np.array(5), "events": np.stack([t, x, y, p], 1)}
    np.savez(tmp_path / "ev.npz", **{k: values[k] for k in arrays})
    assert_clear_error(capsys, ["info", tmp_path / "ev.npz", *SENSOR],
                       rf"a numpy \.npz archive \(arrays {', '.join(arrays)}\), which is not read.*np\.stack",
                       root=tmp_path)


def test_guard_config_fields_take_numpy_scalars():
    cfg = EvINRConfig(C=np.float32(0.2), hidden_layers=np.int64(2), head_solve=np.bool_(True), tau=np.float64(1.0),
                      c2f_iters=np.array([100.0, 200.0]))
    assert (cfg.hidden_layers, cfg.tau, cfg.c2f_iters) == (2, 1.0, (100, 200))


def test_guard_the_scorer_reads_uint8_as_floats_and_any_order_of_ground_truth_times():
    from evinr_lite.evaluation.scoring import score_sequence

    rng = np.random.default_rng(0)
    gt = rng.uniform(0, 1, (3, H, W))
    pred = np.round(np.clip(gt + rng.normal(0, 0.05, gt.shape), 0, 1) * 255) / 255
    tt = np.array([0.1, 0.15, 0.2])
    base = score_sequence(pred, tt, gt, tt)
    as_uint8 = score_sequence(np.round(pred * 255).astype(np.uint8), tt, gt, tt)
    reordered = score_sequence(pred, tt, gt[::-1], tt[::-1])
    for other in (as_uint8, reordered):
        assert other["mse"] == pytest.approx(base["mse"], rel=1e-9) and other["ssim"] == pytest.approx(base["ssim"])


def test_guard_repeated_options_take_the_last_one(capsys, tmp_path):
    path = tmp_path / "ev.npy"
    t, x, y, p = _events()
    np.save(path, np.stack([t, x, y, p], 1))
    code, out, err = run(capsys, "info", path, "--sensor", f"{W}x{H}", "--sensor", f"{H}x{W}", "--json", "--json")
    assert code == 0 and "error" not in err, err


def test_guard_an_out_with_spaces_and_accents_is_written(capsys, tmp_path):
    path = tmp_path / "ev.txt"
    path.write_text(TXT)
    out = tmp_path / "résultats 1 [test]"
    code, _, err = run(capsys, "reconstruct", path, "--out", out, *FAST)
    assert code == 0, err
    assert (out / "run.json").is_file() and not [n for n in os.listdir(tmp_path) if n.startswith(".")]
