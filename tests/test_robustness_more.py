"""More rows of the bad-input table of tests/test_robustness.py: every option of every command with
each class of bad value, each reader against each class of damage, and misuse of the Python API.

Each case asserts its outcome: a clear ``error: ...`` naming the problem (exit status 2 from the
command, an EventDataError from the library), or, for an odd but valid input, the correct result;
and that no file is left behind. None trains a network. ``python tests/robustness_table.py``
prints the table of case classes (tests/test_robustness*.py and tests/test_signals.py).
"""
import json
import math
import os
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from evinr_lite import EventDataError, Events, EvINRConfig, read_recording, reconstruct
from evinr_lite.apps.cli import main
from evinr_lite.sim.recordings import write_example_recording

from test_robustness import H, W, _events, _evreal, assert_clear_error, run, tree

NUMBER_JUNK = ["nan", "-nan", "+inf", "Infinity", "-Infinity", "1e400", "-1e400", "abc", "", " ", "1,2", "0x10",
               "0.1.2", "1e", "--", "½"]


@pytest.fixture(scope="module")
def rec_dir(tmp_path_factory):
    return write_example_recording(tmp_path_factory.mktemp("rec") / "example", sensor_size=(H, W), duration=0.2,
                                   C=0.25, frame_rate=20.0, seed=0)


@pytest.fixture(scope="module")
def npy_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("npy") / "ev.npy"
    t, x, y, p = _events()
    np.save(path, np.stack([t, x, y, p], axis=1))
    return path


def _no_training(monkeypatch):
    import evinr_lite.apps.recon_job as job

    monkeypatch.setattr(job, "reconstruct_recording", lambda *a, **k: pytest.fail("trained on a bad input"))


# ---- 1. option values: reconstruct, info, demo, batch ----------------------------------------------------

RECONSTRUCT_OPTION_CASES = (
    [(opt, v) for opt in ("--C", "--fps") for v in NUMBER_JUNK + ["-0", "1e-400", "-1e-9", "-inf"]
     if (opt, v) != ("--C", "1,2")]                       # --C 1,2 is a valid pair C+,C- (issue 15)
    + [("--C", v) for v in ("1,0", "1,2,3", "1,", "auto,1", "Auto1")]
    + [(opt, v) for opt in ("--start", "--end") for v in NUMBER_JUNK]
    + [(opt, v) for opt in ("--iters", "--seed") for v in ["+inf", "-inf", "1,2", "0x10", " ", "1e9", "--", "3.0"]]
    + [("--iters", "-0"), ("--seed", str(2**63)), ("--seed", "-0.5")]
    + [("--sensor", v) for v in ("0x0", "-5x5", "5x-5", "1e9x1e9", "1.5x2", "12x16x", "x16", "12x", "12X0",
                                 "65537x1", "1x65537", "nanxnan", "infx5", "12,16", "12*16", "12\u00d716", " ",
                                 "0x10", "10x0", "-0x5")]
    + [("--time-unit", v) for v in ("seconds", "\u00b5s", "S", "1", "us ", "ms,us")]
    + [("--device", v) for v in ("CPU", "cuda:0", "mps", "0", "cpu ")]
    + [("--recipe", v) for v in ("", "Paper", "v0.1", "kit,paper", "none", "../kit")]
)


@pytest.mark.parametrize("option,value", RECONSTRUCT_OPTION_CASES)
def test_reconstruct_option_values(capsys, rec_dir, tmp_path, option, value):
    assert_clear_error(capsys, ["reconstruct", rec_dir, "--out", tmp_path / "o", f"{option}={value}", "--quiet"],
                       r"argument|must|expected|invalid", root=tmp_path)


AT_CASES = [("nan,0.1", r"finite time"), ("-inf", r"finite time"), ("1e400", r"finite time"),
            ("0.1;0.12", r"could not read times"), ("0.1 0.12 x", r"could not read times"),
            ("0x10", r"could not read times"), (",", r"could not read times|at least one"),
            ("abc", r"could not read times|no such"), ("1e6", r"outside the reconstructed window"),
            ("0.1,5", r"outside the reconstructed window")]


@pytest.mark.parametrize("value,pattern", AT_CASES)
def test_at_values(capsys, rec_dir, tmp_path, monkeypatch, value, pattern):
    _no_training(monkeypatch)
    assert_clear_error(capsys, ["reconstruct", rec_dir, "--out", tmp_path / "o", f"--at={value}", "--quiet"],
                       pattern, root=tmp_path)


AT_FILE_CASES = {"empty file": (b"", r"at least one|empty"), "text": (b"hello\nworld\n", r"could not read times"),
                 "nan line": (b"0.1\nnan\n", r"finite time"), "latin-1": (b"0.1\n\xe9\n", r"could not read|UTF|text"),
                 "utf-16": ("0.1\n0.12\n".encode("utf-16"), r"could not read|UTF|text"),
                 "a folder": (None, r"folder|could not read|is a directory")}


@pytest.mark.parametrize("case", AT_FILE_CASES)
def test_at_files(capsys, rec_dir, tmp_path, monkeypatch, case):
    _no_training(monkeypatch)
    data, pattern = AT_FILE_CASES[case]
    work = tmp_path / "work"
    work.mkdir()
    path = work / "times.txt"
    if data is None:
        path.mkdir()
    else:
        path.write_bytes(data)
    assert_clear_error(capsys, ["reconstruct", rec_dir, "--out", tmp_path / "o", "--at", path, "--quiet"], pattern,
                       root=tmp_path)


@pytest.mark.parametrize("text,expected", [("0.1 0.12", [0.1, 0.12]), (" 0.12 , 0.1 ", [0.1, 0.12]),
                                           ("0.1,0.1", [0.1, 0.1]), ("1e-1", [0.1])])
def test_at_text_forms_are_read_correctly(text, expected):
    from evinr_lite.apps.options import parse_times as _parse_times

    np.testing.assert_allclose(_parse_times(text), expected)


def test_at_file_with_crlf_is_read_correctly(rec_dir, tmp_path):
    from evinr_lite.apps.options import parse_times as _parse_times

    (tmp_path / "t.txt").write_bytes(b"0.05\r\n0.1\r\n\r\n0.15\r\n")
    np.testing.assert_allclose(_parse_times(str(tmp_path / "t.txt")), [0.05, 0.1, 0.15])


@pytest.mark.parametrize("argv,pattern", [
    (["--out", ""], r"out|empty|current folder|exists"),
    (["--out"], r"expected one argument"),
    ([], r"--out"),
    (["--out", "o", "--out"], r"expected one argument"),
    (["--fps", "10", "--at", "0.1", "--out", "o"], r"not allowed with"),
    (["--out", "o", "--start", "0.2", "--end", "0.1"], r"empty or reversed"),
    (["--out", "o", "--bogus"], r"unrecognized"),
    (["--out", "o", "extra_positional"], r"unrecognized"),
    (["--out", "o", "--C"], r"expected one argument"),
    (["--out", "o", "--sensor", "16x12"], r"sensor|header|size"),
])
def test_reconstruct_argument_shapes(capsys, rec_dir, tmp_path, monkeypatch, argv, pattern):
    _no_training(monkeypatch)
    monkeypatch.chdir(tmp_path)
    (tmp_path / "keep").write_text("x")
    err = assert_clear_error(capsys, ["reconstruct", rec_dir, *argv, "--quiet"], pattern, root=tmp_path)
    assert "Traceback" not in err


@pytest.mark.parametrize("option,value", [("--sensor", v) for v in ("0x0", "-5x5", "1e9x1e9", "10x0", "abc", "",
                                                                    "12,16", "99999999x2")]
                         + [("--time-unit", v) for v in ("", "sec", "hours", "US")])
def test_info_option_values(capsys, npy_file, option, value):
    assert_clear_error(capsys, ["info", npy_file, f"{option}={value}"], r"argument")


@pytest.mark.parametrize("argv,pattern", [
    (["info", ""], r"path is empty"),
    (["info", "/no/such/recording.h5"], r"no such file"),
    (["info", "a", "b"], r"unrecognized"),
    (["info", "--json"], r"required|recording"),
    (["info", "/"], r"folder of unknown format"),
])
def test_info_arguments(capsys, argv, pattern):
    assert_clear_error(capsys, argv, pattern)


DEMO_CASES = ([("--duration", v) for v in ("nan", "-inf", "abc", "", "1e400", "-0.5", "0x10")]
              + [("--C", v) for v in ("inf", "0", "-0.2", "abc", "", "nan")]
              + [("--frames", v) for v in ("-1", "abc", "1.5", "", "nan", "1e3")]
              + [("--iters", v) for v in ("-1", "abc", "2.5", "")]
              + [("--seed", v) for v in ("abc", "1.5", str(2**63), "-1")]
              + [("--size", v) for v in ("0x0", "-5x5", "10x0", "1e9x1e9", "abc", "", "70000x10", "12,16")]
              + [("--recipe", v) for v in ("", "fast", "PAPER")])


@pytest.mark.parametrize("option,value", DEMO_CASES)
def test_demo_option_values_more(capsys, tmp_path, option, value):
    assert_clear_error(capsys, ["demo", "--out", tmp_path / "d", f"{option}={value}"], r"argument", root=tmp_path)


@pytest.mark.parametrize("scene", ["no_such_scene", "", "../camera", "CAMERA "])
def test_demo_unknown_scene_before_training(capsys, tmp_path, monkeypatch, scene):
    import evinr_lite.apps.demo as demo

    monkeypatch.setattr(demo, "reconstruct", lambda *a, **k: pytest.fail("trained on an unknown scene"), raising=False)
    assert_clear_error(capsys, ["demo", "--out", tmp_path / "d", "--scene", scene, "--size", "12x16",
                                "--frames", "2", "--duration", "0.1"], r"scene", root=tmp_path)


def test_demo_refuses_an_existing_out_before_training(capsys, tmp_path):
    (tmp_path / "d").mkdir()
    (tmp_path / "d" / "mine.txt").write_text("precious")
    assert_clear_error(capsys, ["demo", "--out", tmp_path / "d"], r"exists.*--overwrite", root=tmp_path)


BATCH_CASES = ([("--C", v) for v in ("nan", "inf", "0", "-1", "abc", "")]
               + [("--fps", v) for v in ("nan", "inf", "0", "-3", "abc")]
               + [("--workers", v) for v in ("0", "-1", "abc", "1.5")]
               + [("--torch-threads", v) for v in ("0", "-1", "abc", "1.5")]
               + [("--seed", v) for v in ("-1", "abc", str(2**63))]
               + [("--iters", v) for v in ("0", "-3", "x")]
               + [("--sensor", v) for v in ("0x10", "-5x5", "1e9x1e9")]
               + [("--recipe", "nope"), ("--device", "gpu")])


@pytest.mark.parametrize("option,value", BATCH_CASES)
def test_batch_option_values(capsys, rec_dir, tmp_path, option, value):
    assert_clear_error(capsys, ["batch", rec_dir, "--out", tmp_path / "b", f"{option}={value}", "--quiet"],
                       r"argument|must", root=tmp_path)


@pytest.mark.parametrize("case", ["missing input", "empty folder", "unknown dataset", "unknown sequence",
                                  "scheduler and workers", "no inputs"])
def test_batch_inputs(capsys, tmp_path, monkeypatch, case):
    monkeypatch.setenv("EVINR_DATA", str(tmp_path / "cache"))
    (tmp_path / "cache").mkdir()
    argv = ["batch"]
    if case == "missing input":
        argv += [tmp_path / "nope"]
        pattern = r"nope"
    elif case == "empty folder":
        (tmp_path / "empty").mkdir()
        argv += [tmp_path / "empty"]
        pattern = r"empty|no recording"
    elif case == "unknown dataset":
        argv += ["nodataset:seq"]
        pattern = r"nodataset"
    elif case == "unknown sequence":
        argv += ["ijrr:no_such_sequence"]
        pattern = r"no_such_sequence"
    elif case == "scheduler and workers":
        argv += [tmp_path, "--scheduler", "tcp://localhost:1", "--workers", "2"]
        pattern = r"not allowed with"
    elif case == "no inputs":
        pattern = r"required|INPUT"
    assert_clear_error(capsys, [*argv, "--out", tmp_path / "b", "--quiet"], pattern, root=tmp_path)


# ---- 2. EvINRConfig fields: wrong types and values ---------------------------------------------------------

TRAINED = dict(head_solve=False, coarse_to_fine=True, n_iters=300, c2f_iters=(100, 200))
CONFIG_CASES = [("n_iters", "300"), ("n_iters", None), ("n_iters", -math.inf), ("lr", None), ("lr", "1e-4"),
                ("lr", True), ("omega_0", [30]), ("omega_0", -30.0), ("omega_0", math.nan), ("first_omega_0", 0),
                ("first_omega_0", math.inf), ("hidden_features", "256"), ("hidden_features", -8),
                ("hidden_layers", -1), ("hidden_layers", 2.5), ("lam", "tikhonov"),
                ("lam", math.inf), ("lam", None), ("lr_decay", -0.5), ("lr_decay", "0.9"), ("lr_decay_every", -10),
                ("lr_decay_every", 2.5), ("events_per_bin", -100), ("events_per_bin", 10.5), ("c2f_iters", (0,)),
                ("c2f_iters", (100, 100)), ("c2f_iters", "100,200"), ("c2f_iters", (-1, 200)),
                ("c2f_iters", (100.5, 200)), ("C", 0), ("C", -0.2), ("C", math.nan), ("C", None), ("C", [0.2]),
                ("bin_duration", -0.01), ("bin_duration", math.inf), ("bin_duration", "0.03"), ("gamma", 0),
                ("gamma", math.nan), ("gamma", math.inf), ("tau", 0), ("tau", -1.0), ("tau", math.inf),
                ("overlap", math.nan), ("overlap", 5.0), ("overlap", 6.0), ("overlap", -0.5), ("head_lr_scale", 0),
                ("head_lr_scale", -1), ("display_mean", 0.0), ("display_mean", -0.5), ("display_mean", math.nan),
                ("binning", "nope"), ("binning", ""), ("temporal_loss", "l2"), ("regularizer", "l1"),
                ("regularizer", None), ("offset_solve", "magic"), ("seed", -1), ("seed", 1.5), ("seed", "0"),
                ("device", "gpu"), ("device", 0), ("head_solve", "yes"), ("coarse_to_fine", "no"),
                ("progress", "quiet")]


@pytest.mark.parametrize("field,value", CONFIG_CASES)
def test_config_fields_more(field, value):
    with pytest.raises(EventDataError, match=field):
        EvINRConfig(**{**TRAINED, field: value})


@pytest.mark.parametrize("field,value", [("hidden_layers", 0), ("c2f_iters", (100,)), ("overlap", 2.0),
                                          ("device", "cuda:1"), ("seed", np.int64(7)), ("first_omega_0", None)])
def test_config_edge_values_are_accepted(field, value):
    per_window = {"first_omega_per_s": None} if field == "first_omega_0" else {}   # else first_omega_0 is unused
    assert getattr(EvINRConfig(**{**TRAINED, **per_window, field: value}), field) == value


def test_config_stages_after_the_run_warn_not_fail():
    with pytest.warns(UserWarning, match="not inside the run"):
        EvINRConfig(**{**TRAINED, "c2f_iters": (100, 400)})


def test_config_unknown_field():
    with pytest.raises(TypeError, match="n_iter"):
        EvINRConfig(n_iter=3)


# ---- 3. Python API misuse: Events, reconstruct, read_recording -------------------------------------------

def _ok():
    t, x, y, p = _events(50)
    return dict(t=t, x=x, y=y, p=p)


EVENTS_CASES = {
    "t shorter": (lambda a: {**a, "t": a["t"][:-1]}, r"same length"),
    "p longer": (lambda a: {**a, "p": np.r_[a["p"], 1]}, r"same length"),
    "t 2-D": (lambda a: {**a, "t": a["t"][:, None]}, r"1-D"),
    "t strings": (lambda a: {**a, "t": a["t"].astype(str)}, r"numbers"),
    "t float32": (lambda a: {**a, "t": a["t"].astype(np.float32)}, r"float32"),
    "t nan": (lambda a: {**a, "t": np.r_[a["t"][:-1], np.nan]}, r"non-finite"),
    "t inf": (lambda a: {**a, "t": np.r_[a["t"][:-1], np.inf]}, r"non-finite"),
    "t -inf first": (lambda a: {**a, "t": np.r_[-np.inf, a["t"][1:]]}, r"non-finite"),
    "t unsorted": (lambda a: {**a, "t": a["t"][::-1]}, r"not sorted"),
    "t complex": (lambda a: {**a, "t": a["t"].astype(complex)}, r"numbers"),
    "t object": (lambda a: {**a, "t": a["t"].astype(object)}, r"numbers"),
    "x negative": (lambda a: {**a, "x": np.r_[-1, a["x"][1:]]}, r"x .*coordinates"),
    "x = W": (lambda a: {**a, "x": np.r_[W, a["x"][1:]]}, r"x .*coordinates"),
    "y = H": (lambda a: {**a, "y": np.r_[H, a["y"][1:]]}, r"y .*coordinates"),
    "y negative": (lambda a: {**a, "y": np.r_[-3, a["y"][1:]]}, r"y .*coordinates"),
    "x fractional": (lambda a: {**a, "x": a["x"] + 0.5}, r"whole pixel"),
    "x nan": (lambda a: {**a, "x": np.r_[np.nan, a["x"][1:].astype(float)]}, r"whole pixel"),
    "x strings": (lambda a: {**a, "x": a["x"].astype(str)}, r"integers"),
    "y bool": (lambda a: {**a, "y": a["y"] > 3}, r"integers|y"),
    "p = 2": (lambda a: {**a, "p": np.r_[2, a["p"][1:]]}, r"polarit"),
    "p nan": (lambda a: {**a, "p": np.r_[np.nan, a["p"][1:].astype(float)]}, r"polarit"),
    "p 0.5": (lambda a: {**a, "p": np.r_[0.5, a["p"][1:].astype(float)]}, r"polarit"),
    "p strings": (lambda a: {**a, "p": np.where(a["p"] > 0, "on", "off")}, r"polarit"),
    "p mixed 0 and -1": (lambda a: {**a, "p": np.r_[0, -1, 1, a["p"][3:]]}, r"polarit"),
    "p all 3": (lambda a: {**a, "p": np.full(len(a["p"]), 3)}, r"polarit"),
}


@pytest.mark.parametrize("case", EVENTS_CASES)
def test_events_from_arrays_misuse(case):
    change, pattern = EVENTS_CASES[case]
    a = change(_ok())
    with pytest.raises(EventDataError, match=pattern):
        Events.from_arrays(a["t"], a["x"], a["y"], a["p"], (H, W))


@pytest.mark.parametrize("size", [(0, 5), (5, 0), (-1, 5), (5,), (1, 2, 3), "12x16", None, 12, (np.nan, 5),
                                  ("a", "b")])
def test_events_sensor_size_misuse(size):
    a = _ok()
    with pytest.raises(EventDataError, match=r"sensor_size"):
        Events.from_arrays(a["t"], a["x"], a["y"], a["p"], size)


@pytest.mark.parametrize("call,pattern", [
    (lambda a: Events.from_arrays(a["t"], a["x"], a["y"], a["p"], (H, W), time_unit="h"), r"time_unit"),
    (lambda a: Events.from_arrays(a["t"], a["x"], a["y"], a["p"], (H, W), polarity="maybe"), r"polarity|encoding"),
    (lambda a: Events.from_array(np.stack([a["t"], a["x"], a["y"]], 1), (H, W)), r"\[N, 4\]"),
    (lambda a: Events.from_array(a["t"], (H, W)), r"\[N, 4\]"),
    (lambda a: Events.from_array(np.stack([a["t"], a["x"], a["y"], a["p"]], 1), (H, W), columns="txyy"),
     r"permutation"),
    (lambda a: Events.concatenate([]), r"at least one"),
    (lambda a: Events.concatenate([Events.empty((H, W)), Events.empty((H + 1, W))]), r"different sensor_size"),
])
def test_events_constructor_misuse(call, pattern):
    with pytest.raises(EventDataError, match=pattern):
        call(_ok())


def test_events_from_arrays_sort_gives_the_sorted_stream():
    a = _ok()
    order = np.random.default_rng(0).permutation(len(a["t"]))
    ev = Events.from_arrays(a["t"][order], a["x"][order], a["y"][order], a["p"][order], (H, W), sort=True)
    np.testing.assert_array_equal(ev.t, a["t"])


@pytest.fixture(scope="module")
def few_events():
    t, x, y, p = _events(200)
    return Events.from_arrays(t, x, y, p, (H, W))


@pytest.mark.parametrize("times,pattern", [([], r"non-empty"), ([np.nan], r"finite"), ([0.1, np.inf], r"finite"),
                                           ([-np.inf], r"finite"), (np.zeros((0, 3)), r"non-empty"),
                                           (["a"], r"finite|could not convert|number")])
def test_reconstruct_query_times(few_events, times, pattern):
    with pytest.raises((EventDataError, ValueError), match=pattern):
        reconstruct(few_events, times, EvINRConfig(C=0.25))


@pytest.mark.parametrize("call,pattern", [
    (lambda ev: reconstruct(ev, [0.1], t_start=0.5, t_end=0.6), r"outside"),
    (lambda ev: reconstruct(ev.take(slice(0, 1)), [0.1]), r"at least 2 events"),
    (lambda ev: reconstruct(Events.empty((H, W)), [0.1]), r"at least 2 events"),
    (lambda ev: reconstruct(ev, [0.1], t_start=5.0, t_end=6.0), r"outside"),
])
def test_reconstruct_spans(few_events, call, pattern):
    with pytest.raises(EventDataError, match=pattern):
        call(few_events)


@pytest.mark.parametrize("path,pattern", [("", r"path is empty"), (" ", r"path is empty"),
                                          ("/no/such/file.npy", r"no such"), ("/dev/zero", r"not a regular"),
                                          ("/proc/self", r"folder of unknown format|no permission|cannot be read")])
def test_read_recording_odd_paths(path, pattern):
    with pytest.raises(EventDataError, match=pattern):
        read_recording(path)


def test_read_recording_unknown_keyword(npy_file):
    with pytest.raises(TypeError, match="sensor"):
        read_recording(npy_file, sensor=(H, W))


# ---- 4. memory and sizes --------------------------------------------------------------------------------

@pytest.mark.parametrize("argv,pattern", [
    (["--sensor", "65536x65536"], r"needs about"),
    (["--sensor", "20000x30000", "--at", "0.1"], r"needs about"),
    (["--sensor", f"{H}x{W}", "--start=-1e9", "--end=1e9"], r"needs about|no events|outside|implausible"),
])
def test_memory_more(capsys, npy_file, tmp_path, monkeypatch, argv, pattern):
    _no_training(monkeypatch)
    err = assert_clear_error(capsys, ["reconstruct", npy_file, "--out", tmp_path / "o", *argv, "--quiet"], pattern,
                             root=tmp_path)
    # the command line's advice names flags, never a Python keyword it has no flag for
    assert not re.search(r"\b[a-z]+_[a-z_]+\b", err), err


@pytest.mark.parametrize("size", ["8x16", "12x8", "1x1"])
def test_sensor_smaller_than_the_events(capsys, npy_file, size):
    assert_clear_error(capsys, ["info", npy_file, "--sensor", size], r"coordinates span.*sensor")


def test_sensor_disagreeing_with_a_header(capsys, tmp_path):
    t, x, y, p = _events()
    (tmp_path / "ev.txt").write_text(f"{W} {H}\n" + "".join(f"{a:.9f} {b} {c} {d}\n" for a, b, c, d in zip(t, x, y, p)))
    assert_clear_error(capsys, ["info", tmp_path / "ev.txt", "--sensor", f"{W}x{H}"], r"header")


def test_sensor_larger_than_the_events_is_kept(capsys, npy_file):
    code, out, err = run(capsys, "info", npy_file, "--sensor", "480x640", "--json")
    assert code == 0 and json.loads(out)["sensor_size"] == [480, 640], (out, err)


# ---- 5. time units ----------------------------------------------------------------------------------------

@pytest.mark.parametrize("unit,scale", [("s", 1.0), ("ms", 1e3), ("us", 1e6), ("ns", 1e9)])
def test_each_time_unit_gives_the_same_duration(capsys, tmp_path, unit, scale):
    t, x, y, p = _events()
    col = np.round(t * scale).astype(np.int64) if unit != "s" else t
    np.save(tmp_path / "ev.npy", np.stack([col, x, y, p], axis=1))
    code, out, err = run(capsys, "info", tmp_path / "ev.npy", "--sensor", f"{H}x{W}", "--json", "--time-unit", unit)
    assert code == 0, err
    assert json.loads(out)["duration_s"] == pytest.approx(t[-1] - t[0], abs=2 / scale + 1e-12)


@pytest.mark.parametrize("unit", ["us", "ns"])
def test_a_wrong_time_unit_on_seconds_is_refused(capsys, tmp_path, unit):
    rng = np.random.default_rng(2)
    n = 20000
    t = np.sort(rng.uniform(0, 0.5, n))
    np.save(tmp_path / "ev.npy", np.stack([t, rng.integers(0, W, n), rng.integers(0, H, n), rng.choice([-1, 1], n)], 1))
    assert_clear_error(capsys, ["info", tmp_path / "ev.npy", "--sensor", f"{H}x{W}", "--time-unit", unit],
                       r"implausible|span")


@pytest.mark.parametrize("fmt", ["raw", "dat"])
def test_time_unit_refused_for_prophesee(capsys, tmp_path, fmt):
    faery = pytest.importorskip("faery")
    t, x, y, p = _events()
    packet = np.zeros(len(t), dtype=faery.EVENTS_DTYPE)
    packet["t"], packet["x"], packet["y"], packet["on"] = np.round(t * 1e6).astype(np.uint64), x, y, p > 0
    path = tmp_path / f"r.{fmt}"
    faery.events_stream_from_array(packet, dimensions=(W, H)).to_file(path, version="evt3" if fmt == "raw" else None)
    assert_clear_error(capsys, ["info", path, "--time-unit", "ns"], r"cannot apply.*leave --time-unit out")
    code, out, err = run(capsys, "info", path, "--time-unit", "us", "--json")   # the format's own unit: accepted
    assert code == 0 and json.loads(out)["n_events"] == len(t), err


# ---- 6. damaged files: each reader against each class of damage ------------------------------------------

def _write_npy(path, t, x, y, p):
    np.save(path, np.stack([t, x, y, p], axis=1))


def _txt_lines(t, x, y, p):
    return "".join(f"{a:.9f} {b} {c} {(d + 1) // 2}\n" for a, b, c, d in zip(t, x, y, p))


NPY_CASES = {
    "3 columns": (lambda t, x, y, p: np.stack([t, x, y], 1), r"\[N, 4\]|shape"),
    "5 columns": (lambda t, x, y, p: np.stack([t, x, y, p, p], 1), r"\[N, 4\]|shape"),
    "1-D": (lambda t, x, y, p: t, r"\[N, 4\]|shape"),
    "3-D": (lambda t, x, y, p: np.stack([t, x, y, p], 1)[None], r"\[N, 4\]|shape"),
    "strings": (lambda t, x, y, p: np.stack([t, x, y, p], 1).astype(str), r"numbers|numeric|dtype"),
    "complex": (lambda t, x, y, p: np.stack([t, x, y, p], 1).astype(complex), r"numbers|numeric|dtype|complex"),
    "structured": (lambda t, x, y, p: np.zeros(4, dtype=[("t", "f8"), ("x", "i4")]), r"shape|structured|\[N, 4\]"),
    "float32": (lambda t, x, y, p: np.stack([t, x, y, p], 1).astype(np.float32), r"float32"),
    "nan time": (lambda t, x, y, p: np.stack([np.r_[t[:-1], np.nan], x, y, p], 1), r"non-finite"),
    "inf time": (lambda t, x, y, p: np.stack([np.r_[np.inf, t[1:]], x, y, p], 1), r"non-finite"),
    "unsorted": (lambda t, x, y, p: np.stack([t[::-1], x, y, p], 1), r"not sorted"),
    "negative x": (lambda t, x, y, p: np.stack([t, np.r_[-1, x[1:]], y, p], 1), r"x .*coordinates"),
    "x beyond sensor": (lambda t, x, y, p: np.stack([t, np.r_[W + 5, x[1:]], y, p], 1), r"x .*coordinates"),
    "y beyond sensor": (lambda t, x, y, p: np.stack([t, x, np.r_[H, y[1:]], p], 1), r"y .*coordinates"),
    "fractional x": (lambda t, x, y, p: np.stack([t, x + 0.25, y, p], 1), r"whole pixel"),
    "polarity 2": (lambda t, x, y, p: np.stack([t, x, y, np.r_[2, p[1:]]], 1), r"polarit"),
    "polarity nan": (lambda t, x, y, p: np.stack([t, x, y, np.r_[np.nan, p[1:]]], 1), r"polarit"),
    "polarity 0,1,-1 mixed": (lambda t, x, y, p: np.stack([t, x, y, np.r_[0, p[1:]]], 1), r"polarit"),
}


@pytest.mark.parametrize("case", NPY_CASES)
def test_damaged_npy(capsys, tmp_path, case):
    make, pattern = NPY_CASES[case]
    np.save(tmp_path / "ev.npy", make(*_events()))
    err = assert_clear_error(capsys, ["info", tmp_path / "ev.npy", "--sensor", f"{H}x{W}"], pattern, root=tmp_path)
    assert "ev.npy" in err


@pytest.mark.parametrize("fmt", ["npy", "txt"])
def test_a_file_with_no_events_is_described_and_not_reconstructed(capsys, tmp_path, monkeypatch, fmt):
    _no_training(monkeypatch)
    path = tmp_path / f"ev.{fmt}"
    if fmt == "npy":
        np.save(path, np.zeros((0, 4)))
    else:
        path.write_text(HEADER)
    code, out, err = run(capsys, "info", path, "--sensor", f"{H}x{W}", "--json")
    if code == 0:
        assert json.loads(out)["n_events"] == 0, out
    else:
        assert code == 2 and re.search(r"no events|empty", err) and "Traceback" not in err, err
    assert_clear_error(capsys, ["reconstruct", path, "--sensor", f"{H}x{W}", "--out", tmp_path / "o", "--quiet"],
                       r"event", root=tmp_path)


def test_npy_object_array_is_not_unpickled(capsys, tmp_path):
    np.save(tmp_path / "ev.npy", np.array([{"t": 1}, None], dtype=object), allow_pickle=True)
    assert_clear_error(capsys, ["info", tmp_path / "ev.npy", "--sensor", f"{H}x{W}"], r"ev\.npy.*not a readable",
                       root=tmp_path)


def test_npz_is_named(capsys, tmp_path):
    t, x, y, p = _events()
    np.savez(tmp_path / "ev.npz", events=np.stack([t, x, y, p], 1))
    assert_clear_error(capsys, ["info", tmp_path / "ev.npz", "--sensor", f"{H}x{W}"], r"ev\.npz")


HEADER = f"{W} {H}\n"
TXT_CASES = {
    "3 columns": (HEADER + "0.1 1 2\n0.2 3 4\n", r"line|columns|values"),
    "5 columns": (HEADER + "0.1 1 2 1 7\n0.2 3 4 0 7\n", r"line|columns|values"),
    "letters in a row": (HEADER + "0.1 1 2 1\n0.2 a 4 0\n", r"line 3|line"),
    "trailing garbage line": (None, r"line"),
    "nan time": (HEADER + "0.1 1 2 1\nnan 3 4 0\n", r"non-finite|nan|line"),
    "inf time": (HEADER + "0.1 1 2 1\ninf 3 4 0\n", r"non-finite|inf|line"),
    "unsorted": (HEADER + "0.2 1 2 1\n0.1 3 4 0\n", r"not sorted"),
    "negative x": (HEADER + "0.1 -1 2 1\n0.2 3 4 0\n", r"x .*coordinates|negative|line"),
    "x beyond sensor": (HEADER + f"0.1 {W} 2 1\n0.2 3 4 0\n", r"x .*coordinates"),
    "y beyond sensor": (HEADER + f"0.1 1 {H + 3} 1\n0.2 3 4 0\n", r"y .*coordinates"),
    "fractional x": (HEADER + "0.1 1.5 2 1\n0.2 3 4 0\n", r"whole|integer|line"),
    "polarity 2": (HEADER + "0.1 1 2 2\n0.2 3 4 0\n", r"polarit"),
    "polarity 0, 1 and -1 mixed": (HEADER + "0.1 1 2 0\n0.2 3 4 -1\n0.3 3 4 1\n", r"polarit"),
    "header 0 0": ("0 0\n0.1 1 2 1\n0.2 3 4 0\n", r"sensor|header|size"),
    "header not numbers": ("W H\n0.1 1 2 1\n0.2 3 4 0\n", r"line 1|header|line"),
    "header 3 values": (f"{W} {H} 3\n0.1 1 2 1\n0.2 3 4 0\n", r"line 1|header|line|columns"),
    "latin-1 byte": (HEADER + "0.1 1 2 1\n0.2 3 \xe9 0\n", r"UTF-8|text|line|byte"),
    "NUL bytes": (HEADER + "0.1 1 2 1\n\0\0\0\0\n", r"line|text|byte|NUL|binary"),
    "only blank lines": ("\n\n\n", r"no events|empty"),
    "only a comment": ("# t x y p\n", r"line 1"),
}


@pytest.mark.parametrize("case", TXT_CASES)
def test_damaged_txt(capsys, tmp_path, case):
    text, pattern = TXT_CASES[case]
    path = tmp_path / "ev.txt"
    if case == "trailing garbage line":
        path.write_text(HEADER + _txt_lines(*_events()) + "end of file, written by hand\n")
    elif case in ("latin-1 byte",):
        path.write_bytes(text.encode("latin-1"))
    else:
        path.write_text(text)
    err = assert_clear_error(capsys, ["info", path], pattern, root=tmp_path)
    assert "ev.txt" in err


TXT_OK_CASES = ["crlf", "tabs", "several spaces", "no final newline", "blank lines between", "comment lines",
                "leading spaces", "utf-8 bom", "cr only", "+1 polarity sign"]


@pytest.mark.parametrize("case", TXT_OK_CASES)
def test_odd_but_valid_txt_is_read_correctly(tmp_path, case):
    t, x, y, p = _events(60)
    rows = [f"{a:.9f} {b} {c} {(d + 1) // 2}" for a, b, c, d in zip(t, x, y, p)]
    header = f"{W} {H}"
    if case == "crlf":
        data = "\r\n".join([header, *rows]) + "\r\n"
    elif case == "tabs":
        data = "\n".join([header, *(r.replace(" ", "\t") for r in rows)]) + "\n"
    elif case == "several spaces":
        data = "\n".join([header, *(r.replace(" ", "   ") for r in rows)]) + "\n"
    elif case == "no final newline":
        data = "\n".join([header, *rows])
    elif case == "blank lines between":
        data = "\n\n".join([header, *rows]) + "\n"
    elif case == "comment lines":
        data = "\n".join(["# recorded by hand", header, "# t x y p", *rows]) + "\n"
    elif case == "leading spaces":
        data = "\n".join([header, *("  " + r for r in rows)]) + "\n"
    elif case == "utf-8 bom":
        data = "\ufeff" + "\n".join([header, *rows]) + "\n"
    elif case == "cr only":
        data = "\r".join([header, *rows]) + "\r"
    else:
        data = "\n".join([header, *(f"{a:.9f} {b} {c} {'+1' if d > 0 else '-1'}" for a, b, c, d in zip(t, x, y, p))])
    (tmp_path / "ev.txt").write_bytes(data.encode("utf-8"))
    try:
        ev = read_recording(tmp_path / "ev.txt").events
    except EventDataError as err:       # refusing is also fine, if the message names the file and the line ending
        assert "ev.txt" in str(err) and case in ("cr only", "comment lines") and "line" in str(err), err
        return
    assert ev.sensor_size == (H, W)
    np.testing.assert_allclose(ev.t + ev.t_origin, t, atol=1e-9)
    np.testing.assert_array_equal(ev.x, x)
    np.testing.assert_array_equal(ev.y, y)
    np.testing.assert_array_equal(ev.p, p)


IJRR_CASES = ["events unsorted", "events crlf", "events beyond the image size", "images.txt nan time",
              "images.txt unsorted", "missing image file", "images of two sizes", "calib.txt empty",
              "events latin-1", "events 3 columns", "images folder missing", "events polarity 5"]


@pytest.mark.parametrize("case", IJRR_CASES)
def test_damaged_ijrr_more(capsys, tmp_path, rec_dir, case):
    folder = tmp_path / "seq"
    shutil.copytree(rec_dir, folder)
    ev_text = (folder / "events.txt").read_text()
    lines = ev_text.splitlines()
    img_lines = (folder / "images.txt").read_text().splitlines()
    expect = None
    if case == "events unsorted":
        (folder / "events.txt").write_text("\n".join([lines[0], lines[2], lines[1], *lines[3:]]) + "\n")
        expect = r"not sorted"
    elif case == "events crlf":
        (folder / "events.txt").write_bytes(ev_text.replace("\n", "\r\n").encode())
    elif case == "events beyond the image size":
        t0 = lines[-1].split()[0]
        (folder / "events.txt").write_text(ev_text + f"{t0} {W + 10} 0 1\n")
        expect = r"coordinates"
    elif case == "images.txt nan time":
        first = img_lines[0].split()
        (folder / "images.txt").write_text("\n".join([f"nan {first[1]}", *img_lines[1:]]) + "\n")
        expect = r"images\.txt"
    elif case == "images.txt unsorted":     # read back in time order, each image with its own time
        (folder / "images.txt").write_text("\n".join([img_lines[1], img_lines[0], *img_lines[2:]]) + "\n")
    elif case == "missing image file":
        (folder / img_lines[0].split()[1]).unlink()
        expect = r"does not exist"
    elif case == "images of two sizes":
        from PIL import Image

        Image.fromarray(np.zeros((H + 2, W), np.uint8)).save(folder / img_lines[1].split()[1])
        expect = r"size|shape"
    elif case == "calib.txt empty":
        (folder / "calib.txt").write_text("")
    elif case == "events latin-1":
        (folder / "events.txt").write_bytes(ev_text.encode() + b"0.5 1 1 \xe9\n")
        expect = r"events\.txt"
    elif case == "events 3 columns":
        (folder / "events.txt").write_text("\n".join(" ".join(r.split()[:3]) for r in lines) + "\n")
        expect = r"events\.txt"
    elif case == "images folder missing":
        shutil.rmtree(folder / "images")
        expect = r"does not exist"
    elif case == "events polarity 5":
        (folder / "events.txt").write_text(ev_text.replace(lines[1], " ".join(lines[1].split()[:3] + ["5"]), 1))
        expect = r"polarit"
    if expect is None:
        ref = read_recording(rec_dir)
        got = read_recording(folder)
        np.testing.assert_array_equal(got.events.t, ref.events.t)
        np.testing.assert_array_equal(got.events.p, ref.events.p)
        np.testing.assert_array_equal(got.frames.t, ref.frames.t)
        np.testing.assert_array_equal(got.frames.images, ref.frames.images)
    else:
        assert_clear_error(capsys, ["info", folder], expect)


EVREAL_CASES = ["p longer", "xy shorter", "p = 2", "nan ts", "unsorted ts", "negative xy", "xy beyond sensor",
                "no events_p.npy", "no events_xy.npy", "events_p.npy a folder", "float xy", "no sensor_resolution",
                "sensor_resolution 0 0", "sensor_resolution negative", "images_ts shorter", "images 2-D",
                "events_xy 3 columns", "metadata.json empty", "events_ts 2-D", "events_ts float32"]


@pytest.mark.parametrize("case", EVREAL_CASES)
def test_damaged_evreal_more(capsys, tmp_path, case):
    p = np.random.default_rng(0).integers(0, 2, 400).astype(np.uint8)
    folder = _evreal(tmp_path / "seq", p)
    ts = np.load(folder / "events_ts.npy")
    xy = np.load(folder / "events_xy.npy")
    meta = folder / "metadata.json"
    if case == "p longer":
        np.save(folder / "events_p.npy", np.r_[p, 1])
    elif case == "xy shorter":
        np.save(folder / "events_xy.npy", xy[:-5])
    elif case == "p = 2":
        np.save(folder / "events_p.npy", np.r_[2, p[1:]].astype(np.uint8))
    elif case == "nan ts":
        np.save(folder / "events_ts.npy", np.r_[ts[:-1], np.nan])
    elif case == "unsorted ts":
        np.save(folder / "events_ts.npy", ts[::-1].copy())
    elif case == "negative xy":
        xy[0, 0] = -1
        np.save(folder / "events_xy.npy", xy)
    elif case == "xy beyond sensor":
        xy[0, 1] = H
        np.save(folder / "events_xy.npy", xy)
    elif case == "no events_p.npy":
        (folder / "events_p.npy").unlink()
    elif case == "no events_xy.npy":
        (folder / "events_xy.npy").unlink()
    elif case == "events_p.npy a folder":
        (folder / "events_p.npy").unlink()
        (folder / "events_p.npy").mkdir()
    elif case == "float xy":
        np.save(folder / "events_xy.npy", xy + 0.5)
    elif case == "no sensor_resolution":
        meta.write_text("{}")
    elif case == "sensor_resolution 0 0":
        meta.write_text('{"sensor_resolution": [0, 0]}')
    elif case == "sensor_resolution negative":
        meta.write_text(f'{{"sensor_resolution": [-{H}, {W}]}}')
    elif case == "images_ts shorter":
        np.save(folder / "images.npy", np.zeros((3, H, W), np.uint8))
        np.save(folder / "images_ts.npy", np.array([0.05, 0.1]))
    elif case == "images 2-D":
        np.save(folder / "images.npy", np.zeros((H, W), np.uint8))
        np.save(folder / "images_ts.npy", np.array([0.05]))
    elif case == "events_xy 3 columns":
        np.save(folder / "events_xy.npy", np.c_[xy, xy[:, :1]])
    elif case == "metadata.json empty":
        meta.write_text("")
    elif case == "events_ts 2-D":
        np.save(folder / "events_ts.npy", ts[:, None])
    elif case == "events_ts float32":
        np.save(folder / "events_ts.npy", ts.astype(np.float32))
    assert_clear_error(capsys, ["info", folder], r"seq", root=tmp_path)


def _hqf(path, **over):
    import h5py

    t, x, y, p = _events()
    data = {"xs": x, "ys": y, "ts": t, "ps": (p > 0).astype(np.uint8)}
    with h5py.File(path, "w") as f:
        for k, v in data.items():
            v = over.get(k, v)
            if v is not None:
                f.create_dataset(f"events/{k}", data=v)
        res = over.get("sensor_resolution", (H, W))
        if res is not None:
            f.attrs["sensor_resolution"] = res
        if "images" in over:
            f.create_dataset("images/image000000000", data=over["images"])
            f["images/image000000000"].attrs["timestamp"] = over.get("image_ts", 0.1)
    return path


_T, _X, _Y, _P = _events()
HQF_CASES = {
    "no events/ts": dict(ts=None),
    "no events/xs": dict(xs=None),
    "ps longer": dict(ps=np.r_[_P > 0, True].astype(np.uint8)),
    "ts shorter": dict(ts=_T[:-3]),
    "nan ts": dict(ts=np.r_[_T[:-1], np.nan]),
    "unsorted ts": dict(ts=_T[::-1].copy()),
    "xs beyond sensor": dict(xs=np.r_[W + 1, _X[1:]]),
    "negative ys": dict(ys=np.r_[-1, _Y[1:]]),
    "ps = 3": dict(ps=np.r_[3, (_P[1:] > 0)].astype(np.uint8)),
    "ts strings": dict(ts=np.array([b"a"] * len(_T))),
    "ts 2-D": dict(ts=_T[:, None]),
    "sensor_resolution 0 5": dict(sensor_resolution=(0, 5)),
    "sensor_resolution 3 values": dict(sensor_resolution=(H, W, 3)),
    "sensor_resolution text": dict(sensor_resolution="12x16"),
    "image with nan timestamp": dict(images=np.zeros((H, W), np.uint8), image_ts=np.nan),
    "image of the wrong size": dict(images=np.zeros((H + 4, W), np.uint8)),
    "xs fractional": dict(xs=_X + 0.5),
    "ts float32 on an absolute clock": dict(ts=(_T + 1.6e9).astype(np.float32)),
    "ts float16": dict(ts=(_T * 1e3 + 100).astype(np.float16)),
}


@pytest.mark.parametrize("case", HQF_CASES)
def test_damaged_hqf(capsys, tmp_path, case):
    path = _hqf(tmp_path / "hqf.h5", **HQF_CASES[case])
    assert_clear_error(capsys, ["info", path], r"hqf\.h5", root=tmp_path)


def test_hqf_float32_relative_seconds_are_read_correctly(tmp_path):
    ev = read_recording(_hqf(tmp_path / "hqf.h5", ts=_T.astype(np.float32))).events
    np.testing.assert_allclose(ev.t + ev.t_origin, _T, atol=1e-7)


def test_hqf_events_group_is_a_dataset(capsys, tmp_path):
    import h5py

    with h5py.File(tmp_path / "hqf.h5", "w") as f:
        f.create_dataset("events", data=np.zeros((4, 4)))
    assert_clear_error(capsys, ["info", tmp_path / "hqf.h5"], r"hqf\.h5", root=tmp_path)


def test_h5_with_no_events_at_all(capsys, tmp_path):
    import h5py

    with h5py.File(tmp_path / "x.h5", "w") as f:
        f.create_dataset("something", data=np.zeros(3))
    assert_clear_error(capsys, ["info", tmp_path / "x.h5"], r"x\.h5", root=tmp_path)


def _canonical(path):
    from evinr_lite.io.canonical import CanonicalWriter

    t, x, y, p = _events()
    with CanonicalWriter(path, sensor_size=(H, W)) as w:
        w.add_events(t, x, y, p)
    return path


@pytest.mark.parametrize("case", ["drop a member", "drop t_index", "sensor_size attribute removed", "sensor_size 0 0",
                                  "times reversed", "a member truncated", "x beyond sensor"])
def test_damaged_canonical(capsys, tmp_path, case):
    import h5py

    path = _canonical(tmp_path / "c.h5")
    with h5py.File(path, "r+") as f:
        groups = []
        f.visititems(lambda name, obj: groups.append(name) if isinstance(obj, h5py.Dataset) else None)
        assert {"events/t", "events/x"} <= set(groups), groups
        tname, xname = "events/t", "events/x"
        if case == "drop a member":
            del f[xname]
        elif case == "drop t_index":
            del f["events/t_index"]
        elif case == "sensor_size attribute removed":
            key = next(k for k in f.attrs if "sensor" in k)
            del f.attrs[key]
        elif case == "sensor_size 0 0":
            key = next(k for k in f.attrs if "sensor" in k)
            f.attrs[key] = (0, 0)
        elif case == "times reversed":
            f[tname][...] = f[tname][...][::-1]
        elif case == "a member truncated":
            data = f[xname][:-5]
            del f[xname]
            f.create_dataset(xname, data=data)
        else:
            data = f[xname][...]
            data[0] = W + 3
            f[xname][...] = data
    if case == "drop t_index":   # an index the reader rebuilds: the events read back the same
        ev = read_recording(path).events
        np.testing.assert_array_equal(ev.t, _events()[0])
        return
    assert_clear_error(capsys, ["info", path], r"c\.h5", root=tmp_path)


def _faery_file(path, version=None, dims=(W, H), t=None, x=None):
    faery = pytest.importorskip("faery")
    t0, x0, y0, p0 = _events()
    packet = np.zeros(len(t0), dtype=faery.EVENTS_DTYPE)
    packet["t"] = np.round((t0 if t is None else t) * 1e6).astype(np.uint64)
    packet["x"], packet["y"], packet["on"] = (x0 if x is None else x), y0, p0 > 0
    faery.events_stream_from_array(packet, dimensions=dims).to_file(path, version=version)
    return path


@pytest.mark.parametrize("fmt,cut", [("aedat4", "header only"), ("raw", "header only"), ("dat", "header only"),
                                     ("aedat4", "a folder"), ("raw", "a folder"), ("dat", "a folder"),
                                     ("aedat4", "text renamed"), ("raw", "text renamed"), ("dat", "text renamed")])
def test_event_camera_files_header_only_or_not_files(capfd, tmp_path, fmt, cut):
    name = {"aedat4": "r.aedat4", "raw": "r.raw", "dat": "r.dat"}[fmt]
    path = tmp_path / name
    if cut == "a folder":
        path.mkdir()
        pattern = r"folder"
    elif cut == "text renamed":
        path.write_text(HEADER + "0.1 1 2 1\nhello\n")
        pattern = name.replace(".", r"\.")
    else:
        _faery_file(path, version="evt3" if fmt == "raw" else None)
        data = path.read_bytes()
        if fmt == "aedat4":
            keep = data.index(b"</dv:Tree>") + len(b"</dv:Tree>") if b"</dv:Tree>" in data else 200
        elif fmt == "raw":
            keep = data.index(b"% end\n") + len(b"% end\n") if b"% end\n" in data else data.rindex(b"\n%", 0, 2000)
        else:
            keep = data.rindex(b"\n", 0, data.index(b"\n", data.rindex(b"% ")) + 1) + 1 + 2
        path.write_bytes(data[:keep])
        pattern = name.replace(".", r"\.") + r"|no events"
    capfd.readouterr()
    code = main(["info", str(path), "--json"])
    out, err = capfd.readouterr()
    assert "panicked" not in err and "Traceback" not in err, err
    if code == 0:    # a Prophesee header with no events is a valid, empty recording (the format records no count)
        assert cut == "header only" and fmt in ("raw", "dat") and json.loads(out)["n_events"] == 0, (code, out, err)
        code = main(["reconstruct", str(path), "--out", str(tmp_path / "o"), "--quiet"])
        out, err = capfd.readouterr()
        assert not (tmp_path / "o").exists() and re.search(r"event", err)
    assert code == 2 and re.search(pattern, err) and "Traceback" not in err, (code, out, err)


def test_raw_without_size_needs_sensor_and_a_too_small_sensor_is_refused(capsys, tmp_path):
    path = _faery_file(tmp_path / "r.raw", version="evt3")
    data = path.read_bytes()
    lines = data.split(b"\n")
    stripped = b"\n".join(l for l in lines if not (l.startswith(b"%") and (b"geometry" in l or b"format" in l and b"width" in l)))
    if stripped == data:
        pytest.skip("faery's header holds no size line to strip")
    path.write_bytes(stripped)
    code, out, err = run(capsys, "info", path)
    if code == 2:
        assert "--sensor" in err
    assert_clear_error(capsys, ["info", path, "--sensor", "4x4"], r"coordinates|sensor|size")


@pytest.mark.parametrize("fmt", ["aedat4", "raw", "dat"])
def test_event_camera_files_with_a_smaller_sensor_than_declared(capsys, tmp_path, fmt):
    path = _faery_file(tmp_path / f"r.{fmt}", version="evt3" if fmt == "raw" else None)
    assert_clear_error(capsys, ["info", path, "--sensor", f"{H - 4}x{W}"], r"sensor|size|header")


# ---- 7. polarity -------------------------------------------------------------------------------------------

@pytest.mark.parametrize("values,pattern", [([0, 2], r"polarit"), ([-1, 0, 1], r"polarit"), ([-2, 2], r"polarit"),
                                            ([0.0, 0.5], r"polarit"), ([np.nan, 1.0], r"polarit"),
                                            ([np.inf, 1.0], r"polarit"), ([255, 0], r"polarit"), ([-1, 2], r"polarit")])
def test_polarity_values_outside_the_encodings(values, pattern):
    from evinr_lite.core.events import normalize_polarity

    p = np.array(values * 10)
    with pytest.raises(EventDataError, match=pattern):
        normalize_polarity(p)


@pytest.mark.parametrize("values,encoding,expected", [
    ([0, 1], "auto", [-1, 1]), ([-1, 1], "auto", [-1, 1]), ([1, 1], "auto", [1, 1]), ([0, 0], "auto", [-1, -1]),
    ([False, True], "auto", [-1, 1]), ([0.0, 1.0], "auto", [-1, 1]), ([-1.0, 1.0], "auto", [-1, 1]),
])
def test_polarity_encodings_give_the_right_signs(values, encoding, expected):
    from evinr_lite.core.events import normalize_polarity

    np.testing.assert_array_equal(normalize_polarity(np.array(values), encoding), expected)


@pytest.mark.parametrize("values,encoding", [([-1, 1], "01"), ([0, 1, 2], "01"), ([0, 1], "pm1"), ([0, 1], "nope")])
def test_polarity_explicit_encoding_is_checked(values, encoding):
    from evinr_lite.core.events import normalize_polarity

    with pytest.raises(EventDataError, match=r"polarit|encoding"):
        normalize_polarity(np.array(values), encoding)


# ---- 8. the guard and argparse ---------------------------------------------------------------------------

@pytest.mark.parametrize("argv", [["--help"], ["info", "--help"], ["reconstruct", "--help"], ["demo", "--help"],
                                  ["batch", "--help"]])
def test_help_exits_0(capsys, argv):
    code, out, err = run(capsys, *argv)
    assert code == 0 and "usage" in out and not err


@pytest.mark.parametrize("argv,pattern", [
    (["--debug"], r"required|command"), (["--version-nope"], r"unrecognized|required"),
    (["info", "--sensor"], r"expected one argument"), (["demo", "--out"], r"expected one argument"),
    (["batch", "--out", "x"], r"required|INPUT"), (["reconstruct", "--out", "x"], r"required|recording"),
    (["INFO", "x"], r"invalid choice"), (["recon", "x"], r"invalid choice|ambiguous"),
])
def test_argparse_errors_in_the_commands_style(capsys, tmp_path, monkeypatch, argv, pattern):
    monkeypatch.chdir(tmp_path)
    assert_clear_error(capsys, argv, pattern, root=tmp_path)


@pytest.mark.parametrize("exc,code,text", [
    (lambda: MemoryError(), 2, "ran out of memory"), (lambda: RuntimeError("CUDA out of memory."), 2, "ran out of memory"),
    (lambda: KeyError("x"), 1, "internal error: KeyError"), (lambda: AssertionError("no"), 1, "internal error"),
    (lambda: PermissionError(13, "Permission denied", "/x/y"), 2, "/x/y: Permission denied"),
    (lambda: FileNotFoundError(2, "No such file or directory", "/x/z"), 2, "/x/z: No such file"),
    (lambda: EventDataError("sensor_size=(H, W) is wrong"), 2, "--sensor HxW is wrong"),
])
def test_the_guard_sorts_exceptions(capsys, rec_dir, monkeypatch, exc, code, text):
    import evinr_lite.apps.describe as job   # what `info` runs (no torch)

    def boom(rec):
        raise exc()
    monkeypatch.setattr(job, "describe_recording", boom)
    got, out, err = run(capsys, "info", rec_dir)
    assert got == code and text in err and "Traceback" not in err, err


# ---- 9. data_fetch ----------------------------------------------------------------------------------------

@pytest.fixture
def df(capsys, tmp_path, monkeypatch):
    from data_fetch.__main__ import main as df_main
    from test_robustness import _no_network

    monkeypatch.setenv("EVINR_DATA", str(tmp_path / "cache"))
    _no_network(monkeypatch)

    def call(*argv):
        code = df_main([str(a) for a in argv])
        out, err = capsys.readouterr()
        return code, out, err
    return call


def _df_clear(df, argv, pattern, root=None):
    before = tree(root) if root else None
    code, out, err = df(*argv)
    assert code == 2 and err.startswith("data_fetch: error:") and "Traceback" not in err, (code, out, err)
    assert re.search(pattern, err), err
    if root:
        assert tree(root) == before, "a bad input changed or left files"


@pytest.fixture
def ijrr_zip(tmp_path, rec_dir):
    base = tmp_path / "src" / "my_sequence"
    shutil.copytree(rec_dir, base)
    return Path(shutil.make_archive(str(tmp_path / "src" / "my_sequence"), "zip", base))


DF_CONVERT_CASES = ([("--C", v) for v in ("abc", "", "-inf", "1,2")]
                    + [("--sensor-size", v) for v in (["a", "b"], ["5"], ["-5", "5"], ["5", "0"], ["1e9", "1e9"],
                                                      ["99999999", "99999999"], ["1.5", "2"])]
                    + [("--time-unit", v) for v in ("", "sec", "US")])


@pytest.mark.parametrize("option,value", DF_CONVERT_CASES)
def test_data_fetch_convert_option_values(df, tmp_path, ijrr_zip, option, value):
    values = value if isinstance(value, list) else [value]
    if len(values) == 1 and option != "--sensor-size":
        argv = ["convert", ijrr_zip, "--out", tmp_path / "o.h5", f"{option}={values[0]}", "--quiet"]
    else:
        argv = ["convert", ijrr_zip, "--out", tmp_path / "o.h5", option, *values, "--quiet"]
    _df_clear(df, argv, r"argument|C must|sensor size|invalid|expected", root=tmp_path)


@pytest.mark.parametrize("case", ["missing raw", "raw is a folder of nothing", "raw is empty", "unknown extension",
                                  "unknown dataset", "out parent is a file", "zip of nothing", "damaged zip"])
def test_data_fetch_convert_inputs(df, tmp_path, case):
    out = tmp_path / "o.h5"
    if case == "missing raw":
        raw = tmp_path / "nope.zip"
    elif case == "raw is a folder of nothing":
        raw = tmp_path / "empty"
        raw.mkdir()
    elif case == "raw is empty":
        raw = tmp_path / "r.zip"
        raw.write_bytes(b"")
    elif case == "unknown extension":
        raw = tmp_path / "r.xyz"
        raw.write_bytes(b"hello")
    elif case == "unknown dataset":
        raw = tmp_path / "r.txt"
        raw.write_text(HEADER + "0.1 1 2 1\n0.2 2 3 0\n")
        out = tmp_path / "o.h5"
        _df_clear(df, ["convert", raw, "--out", out, "--dataset", "nodataset", "--quiet"], r"nodataset", root=tmp_path)
        return
    elif case == "out parent is a file":
        raw = tmp_path / "r.zip"
        raw.write_bytes(b"PK\x05\x06" + b"\0" * 18)
        (tmp_path / "afile").write_text("x")
        out = tmp_path / "afile" / "o.h5"
    elif case == "zip of nothing":
        raw = tmp_path / "r.zip"
        raw.write_bytes(b"PK\x05\x06" + b"\0" * 18)
    else:
        raw = tmp_path / "r.zip"
        raw.write_bytes(b"PK\x03\x04" + os.urandom(200))
    _df_clear(df, ["convert", raw, "--out", out, "--quiet"], r"\S", root=tmp_path)


@pytest.mark.parametrize("argv,pattern", [
    (["list", "nodataset"], r"nodataset"), (["list", ""], r"unknown|dataset"), (["list", "ijrr", "extra"], r"unrecognized"),
    (["get"], r"required|dataset"), (["get", "ijrr"], r"required|sequence"), (["get", "", "x"], r"unknown|dataset"),
    (["get", "ijrr", "all", "--url", "http://example.invalid/x.zip"], r"--url names one file"),
    (["get", "ijrr", "slider_depth/../../x"], r"unknown|sequence"), (["get", "ijrr", ""], r"unknown|sequence"),
    (["info"], r"required|file"), (["info", "/no/such.h5"], r"no such|not a file|does not exist"),
    (["info", ""], r"no such|not a file|does not exist|empty"), (["info", "/dev/null"], r"not a|regular|readable"),
    (["convert"], r"required|raw"), (["--bogus"], r"unrecognized|required"), (["LIST"], r"invalid choice"),
])
def test_data_fetch_argument_errors(df, tmp_path, monkeypatch, argv, pattern):
    monkeypatch.chdir(tmp_path)
    _df_clear(df, argv, pattern, root=tmp_path)


@pytest.mark.parametrize("argv", [["list"], ["list", "ijrr"], ["list", "hqf", "--all"], ["--help"]])
def test_data_fetch_list_works_offline(df, argv):
    code, out, err = df(*argv)
    assert code == 0 and "Traceback" not in err and out


@pytest.mark.parametrize("case", ["symlink loop", "fifo", "canonical with a member removed", "a zip"])
def test_data_fetch_info_odd_files(df, tmp_path, case):
    import h5py

    path = tmp_path / "f.h5"
    if case == "symlink loop":
        os.symlink(path, path)
    elif case == "fifo":
        os.mkfifo(path)
    elif case == "canonical with a member removed":
        _canonical(path)
        with h5py.File(path, "r+") as f:
            names = []
            f.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
            del f[names[0]]
    else:
        path.write_bytes(b"PK\x05\x06" + b"\0" * 18)
    _df_clear(df, ["info", path], r"f\.h5", root=None if case in ("symlink loop", "fifo") else tmp_path)
