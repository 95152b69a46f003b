"""One RunOptions for the command line, run_reconstruct and run_batch; one --at parser; recipes and the
memory estimate in method (issue 23 items 1 and 3, issue 25's "parsing differs by entry point")."""
import json

import numpy as np
import pytest

from evinr_lite import EventDataError
from evinr_lite.apps.cli import build_parser, main
from evinr_lite.apps.options import BATCH_FIELDS, RunOptions, parse_times
from evinr_lite.io.export import save_timestamps
from evinr_lite.method.config import EvINRConfig
from evinr_lite.method.ensemble import split_windows
from evinr_lite.method.memory import check_memory, estimate_memory
from evinr_lite.method.recipes import DEFAULT_C, contrast_option, recipe_config
from evinr_lite.sim.recordings import write_example_recording

FAST = ["--no-video", "--quiet"]


@pytest.fixture(scope="module")
def example(tmp_path_factory):
    return write_example_recording(tmp_path_factory.mktemp("opt") / "rec", sensor_size=(24, 32), duration=0.3,
                                   C=0.25, frame_rate=20.0, seed=0)


# ---- one parser of time lists ----------------------------------------------------------------------

def test_a_list_on_one_line_of_a_file_gives_the_same_times_as_the_text(tmp_path):
    text = "0.1, 0.2, 0.3, 0.4"
    path = tmp_path / "times.txt"
    path.write_text(text + "\n")
    from_file, from_text = parse_times(str(path)), parse_times(text)
    assert from_file.tolist() == from_text.tolist() == [0.1, 0.2, 0.3, 0.4]
    assert parse_times(path).tolist() == from_file.tolist()            # a Path, too
    # one time per line, comments and a CRLF file: the same times
    path.write_bytes(b"# times\r\n0.4\r\n0.1\r\n\r\n0.3, 0.2\r\n")
    assert parse_times(str(path)).tolist() == from_text.tolist()


def test_a_long_list_is_never_taken_for_a_file_name():
    times = np.round(np.linspace(0.001, 0.299, 60), 6)
    text = ",".join(f"{t:.6f}" for t in times)
    assert len(text) > 255
    assert parse_times(text).tolist() == times.tolist()
    assert RunOptions(at=text).at.tolist() == times.tolist()


def test_timestamps_txt_written_by_the_kit_reads_back_as_its_times(tmp_path):
    times = np.array([0.05, 0.1, 0.15])
    save_timestamps(tmp_path / "timestamps.txt", times)
    assert parse_times(str(tmp_path / "timestamps.txt")).tolist() == pytest.approx(times.tolist())
    one = tmp_path / "one.txt"
    save_timestamps(one, times[:1])                  # one frame: the header says it is index + time
    assert parse_times(str(one)).tolist() == pytest.approx([0.05])
    # the same `index time` text from the command line gives the same times
    assert parse_times((tmp_path / "timestamps.txt").read_text()).tolist() == pytest.approx(times.tolist())


@pytest.mark.parametrize("bad,pattern", [("", "at least one"), ("  ", "at least one"), ("0.1;0.2", "could not read"),
                                         ("nan", "finite"), ([[0.1, 0.2]], "flat list")])
def test_bad_time_lists_are_refused_with_the_fix(bad, pattern):
    with pytest.raises(EventDataError, match=pattern):
        parse_times(bad)


def test_a_folder_is_not_a_file_of_times(tmp_path):
    with pytest.raises(EventDataError, match="folder"):
        parse_times(str(tmp_path))
    with pytest.raises(EventDataError, match="no such file"):
        parse_times(tmp_path / "missing.txt")


def test_the_command_line_reads_a_file_and_a_list_alike(capsys, example, tmp_path):
    path = tmp_path / "times.txt"
    path.write_text("0.1, 0.15, 0.2, 0.25\n")
    runs = {}
    for name, at in (("file", str(path)), ("list", "0.1,0.15,0.2,0.25")):
        assert main(["reconstruct", str(example), "--out", str(tmp_path / name), "--at", at, *FAST]) == 0
        runs[name] = json.loads((tmp_path / name / "run.json").read_text())
    capsys.readouterr()
    assert runs["file"]["times_s"] == runs["list"]["times_s"] == [0.1, 0.15, 0.2, 0.25]
    assert runs["file"]["n_frames_written"] == 4


# ---- RunOptions ---------------------------------------------------------------------------------------

def test_options_are_normalised_once():
    o = RunOptions(C=[0.22, 0.18], fps=30, sensor_size=np.array([24, 32]), n_iters=np.int64(5), seed=np.int32(3))
    assert o.C == (0.22, 0.18) and o.fps == 30.0 and o.sensor_size == (24, 32)
    assert type(o.n_iters) is int and type(o.seed) is int
    assert RunOptions(at="0.3,0.1").at.tolist() == [0.1, 0.3]
    with pytest.raises(ValueError):
        RunOptions(at="0.1").at[0] = 5.0                    # the parsed times are read-only
    with pytest.raises(AttributeError):
        o.fps = 1.0                                         # frozen: checked values stay checked


@pytest.mark.parametrize("fields,name", [
    ({"C": 0}, "C"), ({"C": "0.2"}, "C="), ({"C": (0.2, -1)}, "C"), ({"fps": 0}, "fps="), ({"fps": np.nan}, "fps="),
    ({"fps": 2, "at": "0.1"}, "fps= or at="), ({"t_start": 1.0, "t_end": 1.0}, "t_end="), ({"t_start": np.inf}, "t_start="),
    ({"n_iters": 0}, "n_iters="), ({"n_iters": 2.5}, "n_iters="), ({"recipe": "Paper"}, "recipe="),
    ({"seed": -1}, "seed"), ({"seed": True}, "seed"), ({"time_unit": "sec"}, "time_unit="), ({"anchor": "some"}, "anchor="),
    ({"sensor_size": (0, 5)}, "sensor_size="), ({"sensor_size": (2.5, 4)}, "sensor_size="), ({"video": "yes"}, "video="),
    ({"colour": True, "anchor": "all"}, "colour"), ({"device": 0}, "device="), ({"tonemap": "gamma"}, "tonemap="),
])
def test_every_bad_option_is_refused_naming_it(fields, name):
    with pytest.raises(EventDataError, match=name.replace("(", r"\(")):
        RunOptions(**fields)


def test_of_replaces_fields_and_checks_them_again():
    base = RunOptions(C=0.2, fps=10)
    assert RunOptions.of(base) is base
    assert RunOptions.of(base, seed=4).seed == 4 and RunOptions.of(base, seed=4).C == 0.2
    with pytest.raises(EventDataError, match="fps="):
        RunOptions.of(base, fps=-1)
    with pytest.raises(EventDataError, match="RunOptions"):
        RunOptions.of({"C": 0.2})


def test_batch_settings_round_trip_and_batch_only_options():
    o = RunOptions(C=(0.22, 0.18), sensor_size=(24, 32), recipe="paper", n_iters=6, seed=2, denoise=True, video=False)
    settings = json.loads(json.dumps({**o.to_dict(BATCH_FIELDS), "torch_threads": 1}))   # as batch.json holds it
    back = RunOptions.from_settings(settings, t_start=0.1)
    assert back.to_dict(BATCH_FIELDS) == o.to_dict(BATCH_FIELDS) and back.t_start == 0.1
    assert o.check_batch() is o
    for fields in ({"at": "0.1"}, {"t_end": 1.0}, {"time_unit": "us"}, {"colour": True}):
        with pytest.raises(EventDataError, match="batch"):
            RunOptions(**fields).check_batch()


def test_options_give_the_recipes_config():
    cfg = RunOptions(recipe="paper", n_iters=90, seed=5, progress=False, anchor="first").config(0.3)
    assert cfg.C == 0.3 and cfg.n_iters == 90 and cfg.c2f_iters == (30, 60) and cfg.seed == 5
    assert cfg.anchor == "first" and not cfg.progress and cfg.first_omega_0 is None   # the paper's recipe
    assert recipe_config("kit", C=0.2) == EvINRConfig(C=0.2)
    # the display: the recipe's own unless asked, each tone map at its own level
    assert (RunOptions().config(0.2).tonemap, RunOptions(recipe="paper").config(0.2).tonemap) == ("linear", "reinhard")
    paper_shown_linear = RunOptions(recipe="paper", tonemap="linear").config(0.2)
    kit_shown_reinhard = RunOptions(tonemap="reinhard").config(0.2)
    assert (paper_shown_linear.tonemap, paper_shown_linear.display_mean) == ("linear", EvINRConfig().display_mean)
    assert (kit_shown_reinhard.tonemap, kit_shown_reinhard.display_mean) == ("reinhard", EvINRConfig.paper().display_mean)
    assert kit_shown_reinhard.head_solve and not paper_shown_linear.head_solve   # only the display changed


def test_the_command_line_maps_each_flag_to_its_option(monkeypatch, tmp_path):
    import evinr_lite.apps.recon_job as job

    seen = {}
    monkeypatch.setattr(job, "run_reconstruct", lambda path, out, options, **kw: seen.update(options=options, **kw))
    argv = ["reconstruct", "rec", "--out", str(tmp_path / "o"), "--sensor", "24x32", "--C", "0.22,0.18", "--at", "0.2,0.1",
            "--start", "0.05", "--end", "0.3", "--time-unit", "us", "--device", "cpu", "--recipe", "v0_1", "--iters", "7",
            "--seed", "9", "--anchor", "first", "--denoise", "--no-video", "--quiet", "--overwrite", "--tonemap", "reinhard"]
    assert main(argv) == 0
    o = seen["options"]
    assert (o.sensor_size, o.C, o.at.tolist(), o.t_start, o.t_end, o.time_unit, o.device, o.recipe, o.n_iters, o.seed,
            o.anchor, o.denoise, o.colour, o.video, o.progress) == \
        ((24, 32), (0.22, 0.18), [0.1, 0.2], 0.05, 0.3, "us", "cpu", "v0_1", 7, 9, "first", True, False, False, False)
    assert seen["overwrite"] is True and o.tonemap == "reinhard"
    defaults = build_parser().parse_args(["reconstruct", "rec", "--out", "o"])
    assert defaults.recipe == RunOptions().recipe and defaults.seed == RunOptions().seed


def test_keep_background_turns_off_the_kit_filter_from_the_command_line(monkeypatch, tmp_path):
    """--keep-background (reconstruct and batch) gives EvINRConfig(background="keep"); the method's error when
    the filter leaves too few events names the flag on the command line."""
    import evinr_lite.apps.recon_job as job
    from evinr_lite.apps.cli import _message
    from evinr_lite.method.prepare import _check_left

    seen = {}
    monkeypatch.setattr(job, "run_reconstruct", lambda path, out, options, **kw: seen.update(options=options))
    assert main(["reconstruct", "rec", "--out", str(tmp_path / "o"), "--keep-background", "--quiet"]) == 0
    o = seen["options"]
    assert o.keep_background and o.config(0.2).background == "keep"
    assert RunOptions().config(0.2).background == "auto" and not RunOptions().keep_background
    assert build_parser().parse_args(["batch", "a", "--out", "o", "--keep-background"]).keep_background
    settings = json.loads(json.dumps(o.to_dict(BATCH_FIELDS)))
    assert RunOptions.from_settings(settings).keep_background is True   # a batch's settings carry it
    with pytest.raises(EventDataError) as err:
        _check_left(0, 2)
    assert "--keep-background" in _message(err.value) and "EvINRConfig" not in _message(err.value)
    with pytest.raises(EventDataError, match="keep_background"):
        RunOptions(keep_background="yes")


def test_static_camera_reaches_the_config_from_reconstruct_and_batch(monkeypatch, tmp_path):
    """--static-camera (reconstruct and batch) gives EvINRConfig(camera="static"); a batch's settings carry it,
    and a batch.json written before the option reads as a moving camera."""
    import evinr_lite.apps.recon_job as job
    from evinr_lite.apps.batch import result_settings

    seen = {}
    monkeypatch.setattr(job, "run_reconstruct", lambda path, out, options, **kw: seen.update(options=options))
    assert main(["reconstruct", "rec", "--out", str(tmp_path / "o"), "--static-camera", "--quiet"]) == 0
    o = seen["options"]
    assert o.static_camera and o.config(0.2).camera == "static" and RunOptions().config(0.2).camera == "moving"
    assert build_parser().parse_args(["batch", "a", "--out", "o", "--static-camera"]).static_camera
    settings = json.loads(json.dumps(o.to_dict(BATCH_FIELDS)))
    assert RunOptions.from_settings(settings).static_camera is True
    assert result_settings({})["static_camera"] is False
    assert main(["reconstruct", "rec", "--out", str(tmp_path / "p"), "--static-camera", "--recipe", "paper", "--quiet"]) != 0
    from evinr_lite.apps.cli import _message

    with pytest.raises(EventDataError) as err:
        RunOptions(static_camera=True, recipe="v0_1")
    text = _message(err.value)                   # the command line names its flags, not the Python fields
    assert "--static-camera" in text and "--recipe kit" in text and "static_camera" not in text.replace("--static-camera", "")


# ---- method: the default C and the memory estimate -------------------------------------------------

def test_default_C_is_the_configs():
    assert DEFAULT_C == EvINRConfig().C
    assert contrast_option(None) is None and contrast_option("auto") == "auto" and contrast_option(1) == 1.0


@pytest.mark.parametrize("span", [0.2, 4.9, 5.0, 5.1, 9.6, 23.0, 101.0])
def test_the_estimate_counts_the_solvers_own_windows(span):
    cfg = EvINRConfig(progress=False)
    est = estimate_memory((24, 32), 1.0, 1.0 + span, 1000, 10, cfg)
    assert est["n_windows"] == len(split_windows(1.0, 1.0 + span, cfg.tau, cfg.overlap))
    assert est["total"] == sum(est["parts"].values())


def test_the_estimate_grows_with_what_it_counts():
    cfg = EvINRConfig(progress=False)
    base = estimate_memory((24, 32), 0.0, 1.0, 1000, 10, cfg)["total"]
    assert estimate_memory((48, 64), 0.0, 1.0, 1000, 10, cfg)["total"] > base
    assert estimate_memory((24, 32), 0.0, 1.0, 1000, 100, cfg)["total"] > base
    assert estimate_memory((24, 32), 0.0, 20.0, 1000, 10, cfg)["total"] > base
    eq = EvINRConfig(binning="equal_count", progress=False)
    assert estimate_memory((24, 32), 0.0, 1.0, 10**7, 10, eq)["n_bins"] > estimate_memory((24, 32), 0.0, 1.0, 10**4, 10, eq)["n_bins"]
    with pytest.raises(EventDataError, match="output frames"):
        check_memory((24, 32), 0.0, 1.0, 1000, 10**12, cfg)


def test_batch_task_estimate_takes_plain_arguments():
    from evinr_lite.apps.batch import PROCESS_MIB, estimate_task_memory_mb

    cfg = EvINRConfig(binning="equal_count", progress=False)
    mb = estimate_task_memory_mb((24, 32), 2.0, 10**6, n_frames=5, config=cfg)
    est = estimate_memory((24, 32), 0.0, 2.0, 10**6, 5, cfg)
    # the estimate's own process and events parts are the worker's and the read events' (not counted twice)
    assert mb == pytest.approx(PROCESS_MIB + (2 * 17 * 10**6 + est["total"] - est["parts"]["process"]
                                              - est["parts"]["events"]) / 2**20)
    streamed = estimate_task_memory_mb((24, 32), 60.0, 10**8, n_frames=5, config=cfg, streaming=True)
    assert streamed < estimate_task_memory_mb((24, 32), 60.0, 10**8, n_frames=5, config=cfg) / 4


def test_the_command_lines_choices_are_the_librarys():
    """The command line spells its choices itself (it starts without importing torch): they must stay the library's."""
    from evinr_lite.apps.cli import RECIPE_CHOICES, TIME_UNIT_CHOICES, TONEMAP_CHOICES
    from evinr_lite.core.events import TIME_UNITS
    from evinr_lite.method.anchor import ANCHOR_MODES
    from evinr_lite.method.recipes import RECIPES

    assert set(RECIPE_CHOICES) == set(RECIPES) and set(TIME_UNIT_CHOICES) == set(TIME_UNITS)
    actions = {a.dest: a for a in build_parser()._subparsers._group_actions[0].choices["reconstruct"]._actions}
    assert set(actions["anchor"].choices) == set(ANCHOR_MODES)
    from evinr_lite.method.tonemap import TONEMAPS
    assert set(TONEMAP_CHOICES) == set(TONEMAPS) and set(actions["tonemap"].choices) == set(TONEMAPS)


# ---- --lam: the regularizer's weight, set or chosen from the events -----------------------------------------

@pytest.mark.parametrize("bad", [-0.1, float("nan"), float("inf"), "x", True, [0.1]])
def test_a_bad_lam_is_refused_with_the_fix(bad):
    with pytest.raises(EventDataError, match="lam= must be 'auto'.*or a number >= 0"):
        RunOptions(lam=bad)


def test_lam_reaches_the_recipes_config():
    assert RunOptions().config(0.2).lam == "auto"                         # the kit's own
    assert RunOptions(recipe="paper").config(0.2).lam == EvINRConfig.paper().lam
    assert RunOptions(lam=0.1).config(0.2).lam == 0.1
    assert RunOptions(recipe="paper", lam="AUTO").config(0.2).lam == "auto"
    assert RunOptions(lam=0).config(0.2).lam == 0.0
    assert "lam" in BATCH_FIELDS


@pytest.mark.parametrize("text, message", [("-1", "must be auto or a number >= 0"), ("x", "expected auto or a number")])
def test_the_lam_flag_refuses_bad_text(text, message, capsys):
    with pytest.raises(SystemExit):
        build_parser().parse_args(["reconstruct", "rec", "--out", "o", "--lam", text])
    assert message in capsys.readouterr().err


def test_reconstruct_says_which_lam_it_chose_and_uses_a_given_one(tmp_path, capsys):
    """Without --lam the kit's recipe logs the lam it chose from the events and keeps it in run.json (lam_used,
    within the rule's range); with --lam the run trains with that value and logs no choice."""
    from evinr_lite.method.smoothing import LAM_MAX, LAM_MIN
    from evinr_lite.sim.recordings import write_example_recording

    rec = write_example_recording(tmp_path / "rec", scene="camera", sensor_size=(30, 40), duration=0.4, frame_rate=10.0)
    main(["reconstruct", str(rec), "--out", str(tmp_path / "a"), "--no-video", "--quiet"])
    log = capsys.readouterr().out
    run = json.loads((tmp_path / "a" / "run.json").read_text())
    assert LAM_MIN <= run["lam_used"] <= LAM_MAX and f"lam = {run['lam_used']:.4g}" in log
    main(["reconstruct", str(rec), "--out", str(tmp_path / "b"), "--no-video", "--quiet", "--lam", "0.2"])
    log = capsys.readouterr().out
    run = json.loads((tmp_path / "b" / "run.json").read_text())
    assert run["evinr_config"]["lam"] == 0.2 and "lam_used" not in run and "chosen from the events' activity" not in log


def test_a_times_file_with_a_header_line_is_refused_naming_the_file_and_the_word(tmp_path):
    f = tmp_path / "times.csv"
    f.write_text("time\n0.1\n0.5\n")
    with pytest.raises(EventDataError, match=r"times\.csv.*'time' is not a number of seconds; a header line"):
        parse_times(str(f))
    f.write_text("# time\n0.1\n0.5\n")                              # the fix the message gives
    assert parse_times(str(f)).tolist() == [0.1, 0.5]
    with pytest.raises(EventDataError, match=r"'x' is not a number of seconds\)"):
        parse_times("0.1,x")
