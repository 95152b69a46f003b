"""Issue 25 sections 2 and 3: every public argument is checked where it enters (core.checks), the same
plausibility rules hold in the API and the scorer, output that is not a result is an error, metrics
name the ground-truth files actually written, and a frame exactly at --end is scored for every format.
Several instances of each class go through the one mechanism."""
import csv
import json
import warnings

import numpy as np
import pytest

import evinr_lite as ev
from evinr_lite.apps.cli import main
from evinr_lite.core.checks import ResultError, check_image_values, real_number, require, whole_number
from evinr_lite.core.events import EventDataError, Events, InputError, TimeUnitWarning
from evinr_lite.core.frames import Frames
from evinr_lite.core.recording import Recording
from evinr_lite.evaluation.metrics import score_frames
from evinr_lite.evaluation.scoring import score_sequence
from evinr_lite.method.config import EvINRConfig
from evinr_lite.method.contrast import fit_contrast
from evinr_lite.method.solver import reconstruct
from evinr_lite.sim.recordings import write_example_recording
from evinr_lite.sim.scenes import make_scene
from evinr_lite.sim.simulate import simulate_scene

FAST = dict(n_iters=5, progress=False)


@pytest.fixture(scope="module")
def scene_events():
    sc = make_scene("camera", sensor_size=(24, 32), duration=0.3)
    return sc, simulate_scene(sc, 0.0, 0.3, C=0.2, seed=0)


@pytest.fixture(scope="module")
def small_rec(scene_events):
    _, events = scene_events
    return reconstruct(events, [0.1, 0.2], EvINRConfig(**FAST))


# ---- argument types: one message style, naming the argument and the fix ---------------------------------

@pytest.mark.parametrize("case", ["ndarray", "Recording", "list", "str", "config dict", "config str",
                                  "frames ndarray"])
def test_reconstruct_names_a_wrong_argument_and_the_fix(scene_events, case):
    sc, events = scene_events
    args = {"ndarray": (events.to_array(), None, None), "Recording": (Recording(events, None, {}), None, None),
            "list": (list(events.t), None, None), "str": ("events.txt", None, None),
            "config dict": (events, dict(FAST), None), "config str": (events, "paper", None),
            "frames ndarray": (events, EvINRConfig(anchor="first", **FAST), sc.frames([0.0, 0.1]).images)}[case]
    name = {"config dict": "config=", "config str": "config=", "frames ndarray": "frames="}.get(case, "events=")
    with pytest.raises(InputError, match=name) as info:
        reconstruct(args[0], [0.1], args[1], frames=args[2])
    assert "must be" in str(info.value)


@pytest.mark.parametrize("chunk", [0, -1, 1.5, "8", None, True])
def test_at_refuses_a_chunk_that_is_not_a_whole_number_of_at_least_one(small_rec, chunk):
    with pytest.raises(InputError, match="chunk= must be a whole number >= 1"):
        small_rec.at([0.1], chunk=chunk)


def test_at_accepts_whole_chunks_and_gives_the_same_frames(small_rec):
    a, b = small_rec.at([0.1, 0.2], chunk=1), small_rec.at([0.1, 0.2], chunk=np.int64(256))
    # the same frames to float32's precision of the head product: the solved head's weights are large
    # and cancel (rms 42 here), and one time at once (a matrix-vector product) sums in another order
    # than two (matrix-matrix), which moved F by 3.5e-4 on the 2-core machine of 2026-12-04 and less on
    # earlier ones (FrameINR.features);
    # a wrong chunking (times dropped, shifted or repeated) moves it by tenths
    np.testing.assert_allclose(a, b, rtol=0, atol=2e-3)
    with pytest.raises(InputError, match="times="):
        small_rec.at([0.1, np.nan])


@pytest.mark.parametrize("frames,events,name", [("ndarray", "ok", "frames="), ("ok", "ndarray", "events="),
                                                ("Recording", "ok", "frames="), ("ok", "Recording", "events=")])
def test_fit_contrast_names_a_wrong_argument(scene_events, frames, events, name):
    sc, ev_ = scene_events
    fr = Frames(sc.frames(np.linspace(0, 0.3, 4)).images, np.linspace(0, 0.3, 4))
    rec = Recording(ev_, fr, {})
    f = {"ok": fr, "ndarray": fr.images, "Recording": rec}[frames]
    e = {"ok": ev_, "ndarray": ev_.to_array(), "Recording": rec}[events]
    with pytest.raises(InputError, match=name):
        fit_contrast(f, e)


@pytest.mark.parametrize("kwargs,name", [({"block": 0}, "block="), ({"max_frames": 1.5}, "max_frames="),
                                         ({"eps": -1}, "eps="), ({"exposed": (0.9, 0.1)}, "exposed="),
                                         ({"method": "ols"}, "method")])
def test_fit_contrast_checks_its_values_before_work(scene_events, kwargs, name):
    sc, ev_ = scene_events
    fr = Frames(sc.frames(np.linspace(0, 0.3, 4)).images, np.linspace(0, 0.3, 4))
    with pytest.raises(InputError, match=name):
        fit_contrast(fr, ev_, **kwargs)


@pytest.mark.parametrize("field,value", [("gamma", 1e-9), ("gamma", 1e-300), ("gamma", 1e300), ("C", 1e300),
                                         ("C", 50.0), ("C", (0.2, 1e6))])
def test_config_values_that_cannot_give_a_result_are_refused(field, value):
    with pytest.raises(EventDataError, match=field):
        EvINRConfig(**{field: value})


def test_the_helpers_accept_what_they_should():
    assert whole_number(np.int32(3), "n", lo=1) == 3 and whole_number(4.0, "n") == 4
    assert real_number(np.float32(0.5), "x", lo=0, lo_open=True) == 0.5
    assert require(None, Events, "e", none_ok=True) is None
    for bad in (True, 2.5, "3", np.nan):
        with pytest.raises(InputError):
            whole_number(bad, "n")
    for bad in (np.inf, "1", None, -1.0):
        with pytest.raises(InputError):
            real_number(bad, "x", lo=0)


# ---- plausibility: the same rules in Events/Frames and the scorer ------------------------------------

@pytest.mark.parametrize("size", [(30.7, 40), (24, 32.5), (True, 32), ("24", 32), (24,), (24, 32, 3)])
def test_events_refuse_a_sensor_size_that_is_not_two_whole_numbers(scene_events, size):
    _, e = scene_events
    with pytest.raises(EventDataError, match="sensor_size"):
        Events(e.t, e.x, e.y, e.p, size)


def test_events_take_a_whole_float_sensor_size(scene_events):
    _, e = scene_events
    assert Events(e.t, e.x, e.y, e.p, (24.0, np.int64(32))).sensor_size == (24, 32)


@pytest.mark.parametrize("scale", [1e6, 1e9, 1e3])
def test_integer_timestamps_that_cannot_be_seconds_are_refused_with_the_fix(scene_events, scale):
    """us and ns fail the readers' span rule (refused); ms here passes it (3,214 events in 300 s), so it
    is taken as seconds with the note that names the assumption and the override."""
    _, e = scene_events
    t = np.round(e.t * scale).astype(np.int64)
    if scale >= 1e6:
        with pytest.raises(EventDataError, match="time_unit="):
            Events(t, e.x, e.y, e.p, e.sensor_size)
    else:
        with pytest.warns(TimeUnitWarning, match="time_unit='us'"):
            Events(t, e.x, e.y, e.p, e.sensor_size)
    unit = {1e6: "us", 1e9: "ns", 1e3: "ms"}[scale]
    good = Events.from_arrays(t, e.x, e.y, e.p, e.sensor_size, time_unit=unit)      # the named fix works
    np.testing.assert_allclose(good.t, e.t, atol=1.0 / scale)


def test_integer_seconds_are_taken_with_a_note(scene_events):
    n = 50
    with pytest.warns(TimeUnitWarning, match="taken as whole seconds"):
        e = Events(np.arange(n), np.zeros(n, int), np.zeros(n, int), np.ones(n), (4, 4))
    assert e.t[-1] == n - 1


def _images(kind):
    g = np.random.default_rng(0).random((3, 12, 16))
    return {"0..255": g * 255.0, "NaN": np.where(g > 0.9, np.nan, g), "inf": np.where(g > 0.9, np.inf, g),
            "negative": g - 0.5, "int16": (g * 255).astype(np.int16)}[kind]


@pytest.mark.parametrize("kind", ["0..255", "NaN", "inf", "negative", "int16"])
def test_frames_and_the_scorer_refuse_images_that_are_not_0_to_1(kind):
    good = np.random.default_rng(1).random((3, 12, 16))
    bad = _images(kind)
    with pytest.raises(InputError):
        Frames(bad, [0.0, 0.1, 0.2])
    with pytest.raises(InputError):
        score_frames(good, bad)
    with pytest.raises(InputError):
        score_sequence(good, [0.0, 0.1, 0.2], bad, [0.0, 0.1, 0.2])
    if kind in ("0..255", "NaN", "inf"):            # predictions: the same rule (small overshoot is clipped)
        with pytest.raises(InputError):
            score_frames(bad, good)


def test_the_scorer_still_takes_uint8_and_clips_a_small_overshoot():
    g = np.random.default_rng(2).random((2, 12, 16))
    a = score_frames(np.clip(g * 1.05, 0, 1.05), g)
    b = score_frames(np.clip(g * 1.05, 0, 1.0), g)
    assert a["mse"] == pytest.approx(b["mse"])
    u = (g * 255).round().astype(np.uint8)
    assert check_image_values(u) is u


# ---- output that is not a result is an error -------------------------------------------------------------

@pytest.mark.parametrize("case", ["paper lr=1e6", "anchor all, one timestamp", "anchor first, one timestamp"])
def test_output_that_is_not_finite_or_constant_is_an_error(scene_events, case):
    sc, events = scene_events
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if case == "paper lr=1e6":
            cfg, frames = EvINRConfig.paper(lr=1e6, n_iters=30, progress=False), None
        else:
            mode = case.split()[1].rstrip(",")
            cfg = EvINRConfig(anchor=mode, **FAST)
            frames = Frames(sc.frames(np.linspace(0, 0.3, 6)).images, np.full(6, 0.1))
        try:
            r = reconstruct(events, [0.05, 0.1, 0.2], cfg, frames=frames)
        except (ResultError, EventDataError) as err:     # refused: a clear message
            assert "not a result" in str(err) or "timestamp" in str(err)
            return
    # or, when the solver copes, a real result: finite and not constant
    assert np.isfinite(r.frames).all() and r.frames.max() > r.frames.min()


@pytest.mark.parametrize("C", ["1e300", "1e12", "11", "0.2,1e300"])
def test_the_command_refuses_an_implausible_C_before_training(capsys, tmp_path, C):
    rec = write_example_recording(tmp_path / "rec", sensor_size=(24, 32), duration=0.3, frame_rate=10.0)
    code = main(["reconstruct", str(rec), "--out", str(tmp_path / "out"), "--C", C, "--quiet", "--no-video"])
    err = capsys.readouterr().err
    assert code == 2 and "plausible contrast threshold" in err and "Traceback" not in err, err
    assert not (tmp_path / "out").exists()


# ---- the scored index names the ground truth written; a frame at --end is scored for every format ------

def _metrics_rows(out):
    with open(out / "metrics.csv") as f:
        return list(csv.DictReader(f))


def test_metrics_gt_index_names_the_written_ground_truth_with_anchors(tmp_path):
    rec = write_example_recording(tmp_path / "rec", sensor_size=(24, 32), duration=0.5, frame_rate=10.0)
    out = tmp_path / "out"
    code = main(["reconstruct", str(rec), "--out", str(out), "--anchor", "all", "--quiet", "--no-video"])
    assert code == 0
    run = json.loads((out / "run.json").read_text())
    gt_t = np.loadtxt(out / "gt" / "timestamps.txt", ndmin=2)[:, 1]      # "index time" per line
    anchors = set(np.round(run["anchor"]["anchor_times_s"], 9))
    rows = _metrics_rows(out)
    assert rows and len(rows) == run["anchor"]["n_scored"]
    metrics = json.loads((out / "metrics.json").read_text())
    for eq, per in metrics["per_frame"].items():
        assert per["per_frame_index"] == [int(r["gt_index"]) for r in rows]
    for r in rows:
        i = int(r["gt_index"])
        assert (out / "gt" / f"frame_{i:05d}.png").exists()
        assert gt_t[i] == pytest.approx(float(r["t_s"]), abs=1e-6)           # the row's time is that file's
        assert round(float(r["t_s"]), 9) not in anchors                      # and it is not an anchor


def _formats_with_frames(tmp_path):
    """The same events and frames as an IJRR folder, an HQF-style h5 and a canonical file."""
    import h5py

    from evinr_lite.io.canonical import CanonicalWriter
    from evinr_lite.io.readers import read_recording

    ijrr = write_example_recording(tmp_path / "ijrr", sensor_size=(24, 32), duration=0.4, frame_rate=10.0)
    rec = read_recording(ijrr)
    e, f = rec.events, rec.frames
    hqf = tmp_path / "hqf.h5"
    with h5py.File(hqf, "w") as h:
        for k, v in (("xs", e.x), ("ys", e.y), ("ts", e.t + e.t_origin), ("ps", e.p > 0)):
            h.create_dataset(f"events/{k}", data=v)
        h.attrs["sensor_resolution"] = e.sensor_size
        for i, (im, t) in enumerate(zip(f.images, f.t)):
            d = h.create_dataset(f"images/image{i:09d}", data=im)
            d.attrs["timestamp"] = t + f.t_origin
    can = tmp_path / "c.h5"
    with CanonicalWriter(can, sensor_size=e.sensor_size, t_origin=e.t_origin) as w:
        w.add_events(e.t, e.x, e.y, e.p)
        for im, t in zip(f.images, f.t):
            w.add_frame(im, float(t))
    return {"ijrr": ijrr, "h5": hqf, "canonical": can}, f


@pytest.mark.parametrize("end_frame", [2, 3])
def test_a_frame_exactly_at_end_is_scored_for_every_format(tmp_path, end_frame):
    from evinr_lite.apps.recon_job import load_recording

    paths, frames = _formats_with_frames(tmp_path)
    start, end = float(frames.t[0]), float(frames.t[end_frame])
    got = {}
    for fmt, path in paths.items():
        rec = load_recording(path, t_start=start, t_end=end)
        got[fmt] = (len(rec.events), None if rec.frames is None else rec.frames.t.tolist())
        assert rec.frames is not None and rec.frames.t[-1] == pytest.approx(end), fmt   # the frame at end is in
        assert rec.events.t[-1] < end                                                    # events: [start, end)
    assert len({str(v) for v in got.values()}) == 1, got                                # one rule for all formats
