"""Bad inputs to the Python API (``import evinr_lite as ev``): each is refused where it enters, before any long
work, with an InputError (a ValueError) whose message names the problem and the fix; never an IndexError,
AttributeError, a shape mismatch from torch, a silent NaN or a run of minutes. Whole classes of mistakes:
query times (text, 2-D, NaN), spans (NaN, reversed), configs (c2f_iters, a device that is not here, a tau
that makes thousands of networks), the simulator (seed, scene, C, sample_rate), baselines, scoring and the
writers. Small sensors and short spans: the whole file runs in seconds."""
import numpy as np
import pytest

import evinr_lite as ev
from evinr_lite.core.checks import ArgumentTypeError
from evinr_lite.core.events import EventDataError, InputError
from evinr_lite.core.frames import Frames
from evinr_lite.core.recording import Recording
from evinr_lite.evaluation import metrics, scoring
from evinr_lite.io import export, output
from evinr_lite.method import baselines, binning, tonemap
from evinr_lite.method.balance import estimate_balance
from evinr_lite.sim import simulate

FAST = dict(progress=False)


@pytest.fixture(scope="module")
def scene():
    return ev.make_scene("camera", sensor_size=(12, 16), duration=0.3)


@pytest.fixture(scope="module")
def events(scene):
    return ev.simulate_scene(scene, 0.0, 0.3, C=0.2, seed=0)


def refused(match, fn, *args, **kwargs):
    with pytest.raises(InputError, match=match) as info:
        fn(*args, **kwargs)
    return str(info.value)


# ---- Events, Frames, Recording ------------------------------------------------------------------------

T, X, Y, P = np.linspace(0, 0.1, 5), np.arange(5) % 4, np.arange(5) % 3, np.ones(5)


@pytest.mark.parametrize("t_origin", [np.nan, np.inf, "0", None, True])
def test_events_refuse_a_t_origin_that_is_not_finite_seconds(t_origin):
    refused("t_origin must be a finite number of seconds", ev.Events.from_arrays, T, X, Y, P, (3, 4), t_origin=t_origin)
    refused("t_origin must be a finite number", Frames, np.zeros((1, 3, 4)), [0.0], t_origin)


def test_events_accept_numpy_and_integer_origins():
    assert ev.Events.from_arrays(T, X, Y, P, (3, 4), t_origin=np.float64(5)).t_origin == 5.0
    assert ev.Events.from_arrays(T, X, Y, P, (3, 4), t_origin=np.array(7)).t_origin == 7.0


@pytest.mark.parametrize("bounds", [("0", "1"), (np.nan, 1.0), (0.0, np.nan), ([0.0], 1.0)])
def test_slice_time_refuses_bounds_that_are_not_seconds(bounds):
    e = ev.Events.from_arrays(T, X, Y, P, (3, 4))
    refused("slice_time: t_(start|end) must be seconds", e.slice_time, *bounds)


def test_concatenate_names_a_part_that_is_not_events():
    e = ev.Events.from_arrays(T, X, Y, P, (3, 4))
    refused(r"parts\[1\] is a ndarray, not Events", ev.Events.concatenate, [e, e.to_array()])
    other = ev.Events.from_arrays(T, X, Y, P, (4, 4))
    refused("different sensor_size.*one clock", ev.Events.concatenate, [e, other])


@pytest.mark.parametrize("args,match", [(("x", None, {}), "events= must be Events"),
                                        (("ok", np.zeros((1, 3, 4)), {}), "frames= must be Frames"),
                                        (("ok", None, None), "meta= must be a dict")])
def test_recording_checks_its_parts(args, match):
    e = ev.Events.from_arrays(T, X, Y, P, (3, 4))
    refused(match, Recording, *(e if isinstance(a, str) and a == "ok" else a for a in args))


# ---- reconstruct -----------------------------------------------------------------------------------------

@pytest.mark.parametrize("q,match", [("abc", "query_times= must be seconds"), (["0.1"], "query_times= must be seconds"),
                                     ([[0.1], [0.2]], r"1-D array .* np.ravel"), ([[0.1, 0.2]], "1-D array"),
                                     ([], "empty"), ([0.1, np.nan], r"query_times\[1\] is nan"),
                                     ([True], "must be seconds"), (None, "must be seconds")])
def test_reconstruct_refuses_bad_query_times(events, q, match):
    refused(match, ev.reconstruct, events, q, ev.EvINRConfig(**FAST))


@pytest.mark.parametrize("span,match", [(dict(t_start=np.nan), "t_start= must be a finite number"),
                                        (dict(t_start="a"), "t_start= must be a finite number"),
                                        (dict(t_end=np.inf), "t_end= must be a finite number"),
                                        (dict(t_start=0.2, t_end=0.05), "empty or reversed"),
                                        (dict(t_start=0.1, t_end=0.1), "empty or reversed")])
def test_reconstruct_refuses_a_bad_span(events, span, match):
    refused(match, ev.reconstruct, events, [0.1], ev.EvINRConfig(**FAST), **span)


def test_reconstruct_refuses_a_tau_that_leaves_networks_without_events(events, monkeypatch):
    from evinr_lite.method import solver

    monkeypatch.setattr(solver, "train_frame_inr", lambda *a, **k: pytest.fail("training started"))
    msg = refused(r"tau=0.0001 s cuts .* windows", ev.reconstruct, events, [0.1],
                  ev.EvINRConfig(tau=1e-4, overlap=0.0, **FAST))
    assert "tau=None" in msg


def test_reconstruct_keeps_odd_but_valid_queries(events):
    cfg = ev.EvINRConfig(**FAST)
    a = ev.reconstruct(events, [0.1, 0.2], cfg).frames
    b = ev.reconstruct(events, np.array([0.2, 0.1]), cfg).frames      # unsorted: the order given
    np.testing.assert_allclose(a[::-1], b, atol=1e-6)
    assert ev.reconstruct(events, 0.1, cfg).frames.shape == (1, 12, 16)   # a scalar
    assert ev.reconstruct(events, [0, 0], cfg).frames.shape == (2, 12, 16)   # ints, duplicated


@pytest.mark.parametrize("kw,match", [(dict(c2f_iters=5), "c2f_iters must be a tuple"),
                                      (dict(c2f_iters="ab"), "c2f_iters must be a tuple"),
                                      (dict(C=(0.2,)), "pair"), (dict(C=-1), "positive"), (dict(lam=-1), "lam"),
                                      (dict(hidden_features=0), "hidden_features"), (dict(tau=0), "tau"),
                                      (dict(device="gpu"), "device")])
def test_config_refuses_bad_fields(kw, match):
    refused(match, ev.EvINRConfig, **kw)


def test_a_device_that_is_not_here_is_an_input_error(events):
    import torch

    if torch.cuda.is_available():
        pytest.skip("this machine has a CUDA GPU")
    with pytest.raises(RuntimeError, match="no CUDA GPU.*device='cpu'") as info:   # still a RuntimeError
        ev.reconstruct(events, [0.1], ev.EvINRConfig(device="cuda", **FAST))
    assert isinstance(info.value, InputError)


# ---- simulator ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("kw,match", [(dict(seed=-1), "seed must be a whole number >= 0"),
                                      (dict(C=1e-9), "far below any sensor"),
                                      (dict(C=(0.2, 0.3)), "C_pos= and C_neg="), (dict(C="0.2"), "positive number"),
                                      (dict(sample_rate=1e9), "finer than the 1 us"),
                                      (dict(sample_rate="fast"), "sample_rate must be"),
                                      (dict(t_start="0"), "must be seconds"),
                                      (dict(threshold_drift="x"), "threshold_drift")])
def test_simulate_scene_refuses_bad_arguments_before_simulating(scene, kw, match):
    refused(match, ev.simulate_scene, scene, **{"t_start": 0.0, "t_end": 0.3, **kw})


def test_simulate_scene_names_a_scene_that_is_not_one():
    refused("scene= must be a Scene .* make_scene", ev.simulate_scene, "camera", 0.0, 0.3)


@pytest.mark.parametrize("kw,match", [(dict(duration="2"), "duration must be a positive number"),
                                      (dict(speed_xx=3), r"unknown parameter\(s\) \['speed_xx'\]")])
def test_make_scene_refuses_bad_arguments(kw, match):
    refused(match, ev.make_scene, "camera", sensor_size=(8, 8), **kw)
    with pytest.raises(TypeError):   # an unknown keyword is still a TypeError, as Python's own
        ev.make_scene("bar", sensor_size=(8, 8), speed_xx=3)


def test_simulate_video_refuses_camera_images_as_log_frames():
    images = np.full((3, 4, 5), 128, np.uint8)
    refused("not log intensities.*np.log", ev.simulate_video, images, np.linspace(0, 1, 3))


# ---- baselines, binning, tone map, balance -------------------------------------------------------------------

@pytest.mark.parametrize("kw,match", [(dict(method="nope"), "method must be one of"),
                                      (dict(tonemap="x"), "tonemap must be one of"),
                                      (dict(offset_solve="x"), "offset_solve must be one of"),
                                      (dict(method="hf", cutoff_hz="a"), "cutoff_hz must be a finite number"),
                                      (dict(display_mean=2), "display_mean= must be"),
                                      (dict(tonemap="reinhard", gamma=0), "gamma= must be"),
                                      (dict(t_start=np.nan), "t_start= must be"),
                                      (dict(t_start=0.3, t_end=0.1), "empty or reversed")])
def test_reconstruct_baseline_refuses_bad_arguments(events, kw, match):
    refused(match, ev.reconstruct_baseline, events, [0.1, 0.2], **kw)


@pytest.mark.parametrize("q", ["abc", [[0.1], [0.2]], [np.nan], []])
def test_baselines_refuse_bad_query_times(events, q):
    refused("query times must be", ev.reconstruct_baseline, events, q)


def test_baseline_argument_mistakes_are_input_and_type_errors(events):
    with pytest.raises(ArgumentTypeError, match="takes parameters"):
        ev.reconstruct_baseline(events, [0.1], bogus=1)
    with pytest.raises(TypeError, match="takes no frames"):
        ev.reconstruct_baseline(events, [0.1], frames=np.zeros((2, 12, 16)))
    refused("events= must be Events.*Events.from_array", ev.reconstruct_baseline, events.to_array(), [0.1])
    refused("events= must be Events", estimate_balance, events.to_array(), 0.2)


def test_binning_refuses_nan_edges_and_a_bin_count_that_cannot_be_made(events):
    refused("NaN or inf", ev.events_to_frames, events, [0.0, np.nan])
    refused("would be .* bins", ev.fixed_duration_boundaries, 0.0, 1000.0, 1e-12)
    assert len(binning.fixed_duration_boundaries(0.0, 1.0, 0.25)) == 5


@pytest.mark.parametrize("L,gamma,match", [([np.nan], 0.6, "NaN"), ("a", 0.6, "numbers"), ([0.0], 0, "gamma"),
                                           ([0.0], "0.6", "gamma")])
def test_tonemap_refuses_nan_and_bad_gamma(L, gamma, match):
    refused(match, ev.tonemap_reinhard, L, gamma)


def test_tonemap_keeps_infinite_log_intensities():
    np.testing.assert_allclose(ev.tonemap_reinhard(np.array([-np.inf, 0.0, np.inf]), 1.0), [0.0, 0.5, 1.0])


# ---- scoring ----------------------------------------------------------------------------------------------

IMG = np.random.default_rng(0).uniform(0, 1, (3, 12, 16))


@pytest.mark.parametrize("fn,args,match", [
    (metrics.mse, (np.full((4, 4), np.nan), np.zeros((4, 4))), "NaN"),
    (metrics.mse, (np.zeros((0, 0)), np.zeros((0, 0))), "empty"),
    (metrics.mse, (IMG[0], IMG[0] * 255), "0..255"),
    (metrics.mse, (IMG[0], IMG[0, :10]), "differ in shape"),
    (metrics.ssim, (np.full((12, 16), np.nan), IMG[0]), "NaN"),
    (metrics.equalize, (np.full((12, 16), np.nan), "clahe"), "NaN"),
    (metrics.equalize, (IMG[0], "x"), "equalization must be one of"),
    (metrics.score_frames, (IMG, IMG[:2]), "same shape"),
    (scoring.match_frames, ("a", [0.1]), "pred_times= must be seconds"),
    (scoring.match_frames, ([0.1], [0.1], np.nan), "tol= must be"),
    (scoring.score_sequence, (IMG, "abc", IMG, [0.1, 0.2, 0.3]), "pred_times= must be seconds"),
    (scoring.pool, ([{"a": 1}],), "row 0 has no"),
    (scoring.pool, ("abc",), "list of result rows"),
    (ev.results_table, ([{"x": 1}],), "row 0 has no"),
    (ev.results_table, ([],), "no rows"),
    (ev.results_table, ("abc",), "list of result rows"),
])
def test_scoring_refuses_bad_inputs(fn, args, match):
    refused(match, fn, *args)


def test_mse_reads_uint8_as_the_scorer_does():
    u = (IMG[0] * 255).round().astype(np.uint8)
    assert metrics.mse(u, u / 255.0) == pytest.approx(0.0, abs=1e-20)


@pytest.mark.parametrize("case,match", [
    ("methods str", r"tuple of names.*\('integration',\)"), ("methods empty", "empty"),
    ("method bad", "unknown method 'x'"), ("eq bad", "unknown equalization 'x'"),
    ("shape", "sensor_size"), ("times", "one timestamp per frame"), ("tol", "tol= must be"),
    ("params list", "baseline_params must be"), ("params key", "baseline_params names"),
    ("params bad", r"baseline_params\['hf'\] has \['zz'\]"), ("no times", "give gt_times"),
    ("nan", "NaN"), ("events", "events= must be Events"),
])
def test_evaluate_checks_everything_before_reconstructing(events, scene, monkeypatch, case, match):
    monkeypatch.setattr(scoring, "reconstruct_baseline", lambda *a, **k: pytest.fail("reconstruction started"))
    gt = scene.frames([0.1, 0.2])
    kw = dict(methods=("integration",), equalizations=("none",))
    args = {"methods str": (events, gt), "methods empty": (events, gt), "method bad": (events, gt),
            "eq bad": (events, gt), "shape": (events, gt.images[:, :5], gt.t), "times": (events, gt.images, gt.t[:1]),
            "tol": (events, gt), "params list": (events, gt), "params key": (events, gt), "params bad": (events, gt),
            "no times": (events, gt.images), "nan": (events, np.full((2, 12, 16), np.nan), gt.t),
            "events": (events.to_array(), gt)}[case]
    kw.update({"methods str": dict(methods="integration"), "methods empty": dict(methods=()),
               "method bad": dict(methods=("x",)), "eq bad": dict(equalizations=("x",)), "tol": dict(tol=-1),
               "params list": dict(baseline_params=[1]), "params key": dict(baseline_params={"x": {}}),
               "params bad": dict(baseline_params={"hf": {"zz": 1}})}.get(case, {}))
    refused(match, scoring.evaluate, *args, **kw)


# ---- writers ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("frames,match", [(IMG[:0], "no frames"), (np.full((2, 4, 4), np.nan), "NaN"),
                                          (IMG * 255, "0..255"), (IMG[0], r"image\[None\]"),
                                          (IMG.astype(np.int64), "integers")])
def test_exports_refuse_frames_that_are_not_images(tmp_path, frames, match):
    refused(match, export.save_frames_png, tmp_path / "png", frames)
    refused(match, export.save_gif, tmp_path / "a.gif", frames, 10)


@pytest.mark.parametrize("fps", [0, -5, np.nan, "10"])
def test_gif_and_mp4_refuse_a_bad_fps(tmp_path, fps):
    refused("fps must be positive", export.save_gif, tmp_path / "a.gif", IMG, fps)
    refused("fps must be positive", export.save_mp4, tmp_path / "a.mp4", IMG, fps)


def test_writers_refuse_bad_images_times_and_rows(tmp_path):
    refused("one image", output.save_png, tmp_path / "a.png", IMG)
    refused("NaN", output.save_png, tmp_path / "a.png", np.full((4, 4), np.nan))
    refused("one image", output.save_png, tmp_path / "a.png", np.zeros((0, 0)))
    refused(r"times\[0\] is nan", export.save_timestamps, tmp_path / "t.txt", [np.nan])
    refused("1-D", export.save_timestamps, tmp_path / "t.txt", [[0.1], [0.2]])
    refused("t_origin= must be", export.save_timestamps, tmp_path / "t.txt", [0.1], np.nan)
    refused(r"\[row\]", export.save_csv, tmp_path / "a.csv", {"a": 1})
    refused(r"rows\[1\] has column", export.save_csv, tmp_path / "a.csv", [{"a": 1}, {"b": 2}])
    refused(r"rows\[0\] is a int", export.save_csv, tmp_path / "a.csv", [1, 2])


def test_writers_keep_valid_frames(tmp_path):
    paths = export.save_frames_png(tmp_path / "f", Frames(IMG, [0.0, 0.1, 0.2]))   # a Frames object too
    assert len(paths) == 3 and all(p.exists() for p in paths)
    export.save_gif(tmp_path / "a.gif", (IMG * 255).astype(np.uint8), 10)
    output.save_png(tmp_path / "c.png", np.zeros((4, 4, 3)))                      # RGB
    assert (tmp_path / "a.gif").exists() and (tmp_path / "c.png").exists()
