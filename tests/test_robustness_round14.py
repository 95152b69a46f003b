"""Round 14 of the bad-input table (tests/test_robustness*.py): the batch's entries (evinr_lite.apps.batch:
``resolve_inputs``, ``summarize``, ``run_batch``, always sequential or refused before any cluster), the
``Reconstruction`` a run returns (``at``, ``frames_at``), the event figures' helpers (evinr_lite.viz.events), the
signed counts (evinr_lite.evaluation.enhance), the scoring protocol's text and the inference timing
(evinr_lite.evaluation.metrics / scoring).

Fixes (each test failed before its fix): ``resolve_inputs`` of None or 5 was Python's "not iterable", an input of
None, 5 or bytes Python's TypeError, "" (or [""]) ran the current folder as a folder of recordings, cache=5 was
Python's TypeError; ``summarize`` of None, a text, [None] or a row without its dataset was Python's TypeError or
KeyError and settings=5 was stored as the settings; ``run_batch`` with sequential="yes" ran, log=5 failed after the
batch had run (leaving its out_dir), client=5 was an AttributeError and out_dir None or 5 Python's TypeError.
``Reconstruction.at`` / ``frames_at`` read text ("0.1", ["0.1"]) as seconds and True as 1 s (then "outside the
span"), None was "got shape (1,)", and 10^9 query times (a view costing nothing) went on to allocate frames for
each. ``subsample_index`` of max_points 1.5, "5", NaN, None or True, of n "10", NaN or None and of a seed 1.5,
"0", NaN or -1 were numpy's or Python's errors, n=1.5 gave two indices and n=-1 none; ``subsample`` /
``count_map`` of None were AttributeErrors; ``polarity_image`` with t0 "0" was Python's TypeError, t1 "a" (with
t0 None) was ignored, NaN was "empty or reversed", and a background of two values, of text, of NaN or None (NaN
pixels) or of 255 was numpy's error or an image outside [0, 1]; ``plot_xyt`` with view=5 was Python's error and a
size NaN or -1 drew nothing without a word. ``signed_to_polarity_counts`` cast NaN to integers and truncated 0.5,
and text or None were numpy's errors. ``protocol_description(["none"])`` was "unhashable type".
``measure_inference_fps`` of None was an AttributeError, n_frames -1, 1.5 or "4", batch_size 0 or 1.5 and
repeats 1.5 were torch's or Python's errors, and repeats 0 or -1 timed once without a word.

Review fixes (section 5; each test failed before its fix): ``run_batch`` checked its out_dir against the raw inputs,
so a generator of inputs (used up by resolve_inputs) let a batch write into its input folder and a single str input
(read char by char, "/" an input folder) was always refused; ``run_batch(sequential=0 / 1)`` (np.int64 too) was
refused, and out_dir as bytes passed the check and was Python's TypeError; ``summarize(settings=MappingProxyType)``
was refused (any Mapping is taken, stored as a dict); " " as an input was said to read the current folder (a blank
name now). ``Reconstruction.at`` / ``frames_at`` estimated N + 2 frames per query time while blend_networks held 2N
(the networks' frames and their sum with the offsets) or N + 3 (the float64 blend and its float32 copy): the offsets
are now added in place (the same values, bit for bit) and the estimate is N + 3 frames plus the weights (measured
peaks 3.99, 5.00, 7.02, 10.99 frames for N = 1, 2, 4, 8); the memory message of ``frames_at`` told its caller to
call at(). ``subsample_index`` / ``subsample`` / ``plot_xyt`` refused seed=None, a Generator, a SeedSequence and a
list of seed words (default_rng takes them), max_points=np.inf (all events) and ``plot_xyt(view=(elev, azim,
roll))``. ``signed_to_polarity_counts`` of a tensor requiring grad was torch's RuntimeError; ``measure_inference_fps
(n_frames=4.0)`` reported 4.0, not the int it used. ``LogIntensityWriter`` took any tonemap, gamma and display
(tonemap np.str_ was h5py's TypeError) and wrote NaN frames, which read as never written; ``save_log_intensity``
now checks every frame (finite as float32, the first bad index named) before any file is made, and ``write``
refuses a non-finite frame. ``BaselineReconstruction.at`` / ``CoordinateReconstruction.at`` read "0.1" and True
as seconds: they take times through the same seconds_array check as ``Reconstruction.at`` (57 valid calls give the
same bytes); the colour result's ``at`` already did, through its channels' ``Reconstruction.at``.

Refused on purpose where they were taken before: ``measure_inference_fps(n_frames=0)`` (an fps of 0 from no frame)
and repeats < 1, a background outside [0, 1] (255 drew as white), ``plot_xyt(size=-1)``, ``resolve_inputs("")``, and,
kept refused after the review, a background that only broadcasts to a colour (np.array([[1, 1, 1]])),
``resolve_inputs`` of a dict and times as Fraction or Decimal (section 5's last test).

Left as they are: the file writers (save_frames_png, save_gif, save_mp4, save_timestamps, save_csv: rounds 4 to 8
already refuse their frames, fps and paths; save_log_intensity's values and display are section 5's), the other figures (plot_results,
show_frames, show_images, plot_event_rate, the scorer: rounds 10 and 13), ``render_event_counts`` of a 1-D signal
(one pixel's boundaries: valid) and ``run_batch``'s unknown keywords (Python's TypeError names the keyword).
Left after the review: ``BaselineReconstruction.at`` of no time ([]) is still integrate_events' "non-empty 1-D
array" refusal, as before.

Guards: odd inputs next to these that already behave and must keep their outcome (np.int64 and 0-d tensor times,
float32 times, an empty list of times, numpy / float counts and seeds, a whole float n, a grey background given as
one number, inputs as Paths, tuples or iterators, rows as a tuple, an empty list of rows, the existing refusals).
"""
import os

import numpy as np
import pytest
import torch

from evinr_lite import EvINRConfig, reconstruct
from evinr_lite.apps import batch
from evinr_lite.evaluation import enhance, metrics, scoring
from evinr_lite.method.models import FrameINR
from evinr_lite.sim import make_scene, simulate_scene

os.environ.setdefault("MPLBACKEND", "Agg")
import matplotlib.pyplot as plt  # noqa: E402

from evinr_lite.viz import events as ve  # noqa: E402

EV = simulate_scene(make_scene("bar", sensor_size=(8, 10), duration=0.2), C=0.2)
REC = reconstruct(EV, [0.05, 0.1], EvINRConfig(progress=False, n_iters=0))
MODEL = FrameINR((4, 4), np.array([[0.0, 1.0]]), 8, 1, 30.0, 30.0, seed=0)
QUIET = lambda *a: None   # noqa: E731


from refusals import all_refused as _none_of, refused as _no   # noqa: E402  (shared by rounds 11-14)


@pytest.fixture
def npy(tmp_path):
    path = tmp_path / "ev.npy"
    np.save(path, np.stack([EV.t, EV.x, EV.y, EV.p], 1))
    return path


# ---- 1. the batch's entries ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("inputs", [None, 5, [None], [5], [b"x"], "", [""], ["  "]])
def test_resolve_inputs_refuses_what_names_no_recording(inputs):
    _no(lambda: batch.resolve_inputs(inputs, log=QUIET), r"inputs")


def test_resolve_inputs_refuses_a_cache_that_is_no_folder(npy):
    _no(lambda: batch.resolve_inputs([str(npy)], cache=5, log=QUIET), r"cache= must be a folder")


@pytest.mark.parametrize("rows,pattern", [(None, r"rows= must be"), ("abc", r"rows= must be"), (5, r"rows= must be"),
                                          ([None], r"rows\[0\] must be a dict"),
                                          ([{"name": "a"}], r"rows\[0\] has no 'dataset'"),
                                          ([{"name": "a", "dataset": "d"}], r"rows\[0\] has no 'status'")])
def test_summarize_refuses_rows_that_are_no_batch_rows(rows, pattern):
    _no(lambda: batch.summarize(rows), pattern)


@pytest.mark.parametrize("settings", [5, [1], "C=0.2"])
def test_summarize_refuses_settings_that_are_no_dict(settings):
    _no(lambda: batch.summarize([], settings), r"settings= must be a dict")


@pytest.mark.parametrize("kw,pattern", [(dict(sequential="yes"), r"sequential= must be True or False"),
                                        (dict(sequential=2), r"sequential= must be True or False"),
                                        (dict(log=5), r"log= must be a function"),
                                        (dict(client=5, sequential=False), r"client= must be a distributed.Client"),
                                        (dict(cache=5), r"cache= must be a folder")])
def test_run_batch_refuses_settings_before_any_folder(npy, kw, pattern):
    out = npy.parent / "out"
    _no(lambda: batch.run_batch([str(npy)], out, **{"sequential": True, "log": QUIET, **kw}), pattern)
    assert not out.exists()


@pytest.mark.parametrize("out", [None, 5])
def test_run_batch_refuses_an_out_dir_that_is_no_path(npy, out):
    _no(lambda: batch.run_batch([str(npy)], out, sequential=True, log=QUIET), r"out_dir= must be a folder")


def test_run_batch_refuses_inputs_that_are_none(tmp_path):
    _no(lambda: batch.run_batch(None, tmp_path / "out", sequential=True, log=QUIET), r"inputs")
    assert not (tmp_path / "out").exists()


def test_batch_as_before(npy, tmp_path):
    one = batch.resolve_inputs(str(npy), log=QUIET)
    assert batch.resolve_inputs((npy,), log=QUIET) == one == batch.resolve_inputs(iter([npy]), log=QUIET)
    assert batch.resolve_inputs([npy, str(npy)], cache=str(tmp_path), log=QUIET) == one
    _no(lambda: batch.resolve_inputs([], log=QUIET), r"no recordings given")
    _no(lambda: batch.resolve_inputs(["nosuch:thing"], cache=tmp_path, log=QUIET), r"no converted sequence")
    assert batch.summarize([])["pooled"] == [] and batch.summarize((), None)["settings"] == {}
    rows = ({"name": "b", "dataset": "x", "status": "failed", "input": "j", "error": "boom"},)
    assert batch.summarize(iter(rows), {"C": 0.2})["failed"] == [{"name": "b", "input": "j", "error": "boom"}]
    _no(lambda: batch.run_batch([str(npy)], tmp_path / "o", sequential=True, workers=2, log=QUIET), r"at most one")
    _no(lambda: batch.run_batch([str(npy)], tmp_path / "o", sequential=True, workers=0, log=QUIET), r"workers=")
    assert not (tmp_path / "o").exists()


# ---- 2. the Reconstruction -------------------------------------------------------------------------------------------

@pytest.mark.parametrize("times,pattern", [("0.1", r"times= must be seconds"), (["0.1"], r"times= must be seconds"),
                                           ([True], r"times= must be seconds"), (None, r"times= must be seconds"),
                                           ([0.1, np.nan], r"times= must be finite seconds, but times\[1\] is nan")])
def test_at_refuses_times_that_are_no_seconds(times, pattern):
    _none_of([lambda: REC.at(times), lambda: REC.frames_at(times)], pattern)


def test_at_refuses_a_billion_times_before_allocating_them():
    many = np.broadcast_to(0.1, (10**9,))    # a view: costs nothing until frames are made for each
    _none_of([lambda: REC.at(many), lambda: REC.frames_at(many)], r"times= holds 1,000,000,000 query times")


def test_at_as_before():
    ref = REC.at([0.05, 0.1])
    assert np.array_equal(REC.at(np.array([0.05, 0.1])), ref)
    assert np.array_equal(REC.at(torch.tensor([0.05, 0.1], dtype=torch.float64)), ref)
    assert np.array_equal(REC.at(np.float64(0.1))[0], ref[1]) and np.array_equal(REC.at(torch.tensor(0.1, dtype=torch.float64))[0], ref[1])
    assert REC.at([]).shape == (0, 8, 10) and REC.frames_at(np.zeros(0)).shape == (0, 8, 10)
    assert REC.at(np.array([0.05, 0.1], np.float32)).shape == (2, 8, 10)
    _none_of([lambda: REC.at([5.0]), lambda: REC.at([[0.1], [0.05]]), lambda: REC.at([0.1], chunk=1.5)],
             r"outside the reconstructed span|1-D array|chunk=")


# ---- 3. the event figures' helpers ----------------------------------------------------------------------------------

@pytest.mark.parametrize("max_points", [1.5, "5", np.nan, None, True])
def test_subsample_index_refuses_a_count_that_is_no_count(max_points):
    _no(lambda: ve.subsample_index(10, max_points), r"max_points= must be a whole number, got")


@pytest.mark.parametrize("n", [-1, 1.5, "10", np.nan, None])
def test_subsample_index_refuses_an_n_that_is_no_count(n):
    _no(lambda: ve.subsample_index(n, 5), r"n= must be a whole number >= 0")


@pytest.mark.parametrize("seed", [1.5, "0", np.nan, -1])
def test_subsample_index_refuses_a_seed_that_is_no_seed(seed):
    _no(lambda: ve.subsample_index(10, 5, seed), r"seed= must be a whole number >= 0")


def test_the_event_helpers_refuse_what_is_no_events():
    _none_of([lambda: ve.subsample(None, 5), lambda: ve.count_map(None), lambda: ve.plot_count_map(None)],
             r"events= must be Events, got NoneType")


@pytest.mark.parametrize("t0,t1", [("0", 0.1), (None, "a"), (np.nan, 0.1), (0.05, np.nan)])
def test_polarity_image_refuses_a_window_that_is_no_seconds(t0, t1):
    _no(lambda: ve.polarity_image(EV, t0, t1), r"t[01]= must be a finite number")


@pytest.mark.parametrize("bg", [(1, 1), "white", (np.nan, 1, 1), None, (255, 255, 255), (2, 1, 1)])
def test_polarity_image_refuses_a_background_that_is_no_colour(bg):
    _no(lambda: ve.polarity_image(EV, background=bg), r"background= must be a colour")


@pytest.mark.parametrize("kw,pattern", [(dict(view=5), r"view= must be \(elevation, azimuth\)"),
                                        (dict(view=(np.nan, 3)), r"view= must be \(elevation, azimuth\)"),
                                        (dict(size=np.nan), r"size= must be a finite number >= 0"),
                                        (dict(size=-1), r"size= must be a finite number >= 0"),
                                        (dict(max_points="5"), r"max_points= must be a whole number")])
def test_plot_xyt_refuses_settings_that_draw_nothing(kw, pattern):
    _no(lambda: ve.plot_xyt(EV, **kw), pattern)
    plt.close("all")


def test_subsample_index_takes_whole_floats():
    assert ve.subsample_index(10.0, 5.0).tolist() == ve.subsample_index(10, 5).tolist()   # numpy's error before


def test_event_helpers_as_before():
    assert ve.subsample_index(10, 5).tolist() == ve.subsample_index(np.int64(10), np.int64(5), np.int64(0)).tolist()
    assert ve.subsample_index(0, 3).tolist() == [] and ve.subsample_index(3, 10**12).tolist() == [0, 1, 2]
    _no(lambda: ve.subsample_index(10, 0), r"max_points")
    assert np.array_equal(ve.count_map(EV, 1.0), ve.count_map(EV, 1))
    assert np.array_equal(ve.polarity_image(EV, np.float32(0.05), torch.tensor(0.1)), ve.polarity_image(EV, 0.05, 0.1))
    assert np.array_equal(ve.polarity_image(EV, 0, np.inf), ve.polarity_image(EV))       # an open end, as before
    assert np.array_equal(ve.polarity_image(EV, background=0.5)[0, 0], [0.5, 0.5, 0.5])
    assert np.array_equal(ve.polarity_image(EV, background=np.array([1.0, 0.9, 0.8]))[0, 0], [1.0, 0.9, 0.8])
    _no(lambda: ve.polarity_image(EV, 0.2, 0.1), r"empty or reversed")
    ax = ve.plot_xyt(EV, max_points=np.int64(50), size=np.float32(2), view=[10, 10])
    assert ax.get_title() == f"50 of {len(EV)} events"
    plt.close("all")


# ---- 4. counts, the protocol's text, the inference timing ------------------------------------------------------------

@pytest.mark.parametrize("signed", [np.full((2, 2), np.nan), np.array([0.5, -1.0]), np.full((2, 2), "a"), None])
def test_signed_counts_refuse_what_is_no_whole_count(signed):
    _no(lambda: enhance.signed_to_polarity_counts(signed), r"signed: counts must be whole numbers")


def test_signed_counts_as_before():
    assert enhance.signed_to_polarity_counts([[1, -2]]).tolist() == [[[1, 0]], [[0, 2]]]
    assert enhance.signed_to_polarity_counts(np.array([2.0, -1.0])).tolist() == [[2, 0], [0, 1]]
    assert enhance.signed_to_polarity_counts(np.zeros((0, 2))).shape == (2, 0, 2)
    assert enhance.signed_to_polarity_counts(np.array([1, -1], np.int8)).dtype == np.int64


@pytest.mark.parametrize("eq", [["none"], {"clahe"}])
def test_protocol_description_names_the_equalisations(eq):
    _no(lambda: metrics.protocol_description(eq), r"equalization must be one of \('none', 'global', 'clahe'\)")


@pytest.mark.parametrize("kw,pattern", [(dict(n_frames=-1), r"n_frames= must be a whole number >= 1"),
                                        (dict(n_frames=1.5), r"n_frames= must be a whole number >= 1"),
                                        (dict(n_frames="4"), r"n_frames= must be a whole number >= 1"),
                                        (dict(n_frames=0), r"n_frames= must be a whole number >= 1"),
                                        (dict(batch_size=0), r"batch_size= must be a whole number >= 1"),
                                        (dict(batch_size=1.5), r"batch_size= must be a whole number >= 1"),
                                        (dict(repeats=1.5), r"repeats= must be a whole number >= 1"),
                                        (dict(repeats=0), r"repeats= must be a whole number >= 1"),
                                        (dict(repeats=-1), r"repeats= must be a whole number >= 1")])
def test_measure_inference_fps_refuses_counts_that_are_no_counts(kw, pattern):
    _no(lambda: scoring.measure_inference_fps(MODEL, **kw), pattern)


def test_measure_inference_fps_refuses_what_is_no_model():
    _no(lambda: scoring.measure_inference_fps(None), r"model= must be FrameINR, got NoneType")


def test_measure_inference_fps_takes_whole_floats():
    assert scoring.measure_inference_fps(MODEL, n_frames=4.0, batch_size=2.0, repeats=1.0)["n_frames"] == 4


def test_scoring_helpers_as_before():
    assert metrics.protocol_description() == metrics.protocol_description(np.str_("none"))
    _none_of([lambda: metrics.protocol_description(eq) for eq in (None, "CLAHE", ("none",))], r"equalization must be")
    r = scoring.measure_inference_fps(MODEL, n_frames=np.int64(4), batch_size=np.int64(4), repeats=np.int64(2))
    assert r["n_frames"] == 4 and len(r["all_seconds"]) == 2 and r["sensor_size"] == (4, 4)
    assert scoring.measure_inference_fps(MODEL, n_frames=5, batch_size=100, repeats=1)["batch_size"] == 100


# ---- 5. the review's fixes -------------------------------------------------------------------------------------------

@pytest.fixture
def recs(tmp_path):
    """A folder holding one tiny recording (as tests/test_batch.py writes them)."""
    from evinr_lite.sim.recordings import write_example_recording

    folder = tmp_path / "recs"
    folder.mkdir()
    write_example_recording(folder / "rec_camera", scene="camera", sensor_size=(12, 16), duration=0.2,
                            frame_rate=10.0, seed=0)
    return folder


def test_run_batch_refuses_a_generator_of_inputs_around_its_out_dir(recs):
    out = recs / "out_gen"   # inside the input folder: the generator was used up before the ownership rule looked
    _no(lambda: batch.run_batch((p for p in [recs]), out, sequential=True, n_iters=2, progress=False, log=QUIET),
        r"is, or lies inside, the input folder")
    assert not out.exists() and sorted(p.name for p in recs.iterdir()) == ["rec_camera"]


def test_run_batch_takes_one_str_or_path_as_its_inputs(recs, tmp_path):
    out = tmp_path / "out"   # a str was read char by char: "/" counted as an input folder, so always refused
    summary = batch.run_batch(str(recs), out, sequential=1, n_iters=2, progress=False, log=QUIET)
    assert [r["name"] for r in summary["recordings"]] == ["rec_camera"] and not summary["failed"]
    again = batch.run_batch(recs, out, sequential=np.int64(1), n_iters=2, progress=False, log=QUIET)   # resumes
    assert [r["name"] for r in again["recordings"]] == ["rec_camera"]


def test_run_batch_takes_sequential_as_0_or_1(npy, tmp_path):
    out = tmp_path / "out"   # 0 is False: refused for the client, not for sequential=
    _no(lambda: batch.run_batch([str(npy)], out, sequential=np.int64(0), client=5, log=QUIET), r"client= must be")
    _no(lambda: batch.run_batch([str(npy)], out, sequential=0, client=5, log=QUIET), r"client= must be")
    assert not out.exists()


def test_run_batch_refuses_an_out_dir_of_bytes_by_name(npy, tmp_path):
    _no(lambda: batch.run_batch([str(npy)], os.fsencode(tmp_path / "o"), sequential=True, log=QUIET),
        r"out_dir= must be a folder \(a str or Path\), got bytes")
    assert not (tmp_path / "o").exists()


def test_summarize_takes_any_mapping_as_settings():
    from types import MappingProxyType

    s = batch.summarize([], MappingProxyType({"C": 0.2}))
    assert s["settings"] == {"C": 0.2} and type(s["settings"]) is dict


def test_resolve_inputs_names_a_blank_input_as_blank():
    _no(lambda: batch.resolve_inputs([" "], log=QUIET), r"inputs\[0\] is ' ', a blank name")


def _tight_memory(monkeypatch, n_times):
    """Free memory just under what n_times query times of REC need at max(2N, N + 3) frames each (N + 3 measured
    after the in-place offsets; 2N before them), and above the old estimate of N + 2 frames."""
    from evinr_lite.method import memory

    N, (H, W) = len(REC.windows), REC.log_intensity.shape[1:]
    need = n_times * (64.0 + 16.0 * N + 4.0 * H * W * (N + 3))
    assert n_times * (40.0 + 4.0 * H * W * (N + 2)) < 0.8 * (need / 0.8 - 1.0)   # the old estimate let them through
    monkeypatch.setattr(memory, "available_bytes", lambda device="cpu": need / 0.8 - 1.0)


def test_at_counts_every_frame_the_blend_holds(monkeypatch):
    times = np.full(50_000, 0.1)
    _tight_memory(monkeypatch, times.size)
    _no(lambda: REC.at(times), r"times= holds 50,000 query times.*call at\(\) on parts")


def test_frames_at_names_itself_in_the_memory_message(monkeypatch):
    times = np.full(50_000, 0.1)
    _tight_memory(monkeypatch, times.size)
    _no(lambda: REC.frames_at(times), r"call frames_at\(\) on parts")


def test_frames_at_counts_the_display_frames_too(monkeypatch):
    """Final review: frames_at tone-maps in float64 (7 frames at its peak), more than the blend's N + 3 when N < 4;
    memory that fits at()'s frames but not frames_at()'s refuses frames_at() alone."""
    from evinr_lite.method import memory

    N, (H, W) = len(REC.windows), REC.log_intensity.shape[1:]
    assert N + 3 < 7
    n = 50_000
    between = n * (64.0 + 16.0 * N + 4.0 * H * W * (N + 3 + 7) / 2)   # above at()'s need, below frames_at()'s
    monkeypatch.setattr(memory, "available_bytes", lambda device="cpu": between / 0.8)
    times = np.full(n, 0.1)
    assert REC.at(times).shape == (n, H, W)
    _no(lambda: REC.frames_at(times), r"call frames_at\(\) on parts")


def test_blend_networks_as_before():
    from evinr_lite.method.ensemble import blend_networks, blend_weights, predict_networks

    t = np.linspace(0.03, 0.19, 7)
    F = predict_networks(REC.model, t) + REC.offsets[:, None]    # the earlier formula, two arrays
    ref = np.einsum("nq,nqhw->qhw", blend_weights(REC.windows, t), F).astype(np.float32)
    assert np.array_equal(blend_networks(REC.model, REC.windows, t, REC.offsets), ref)


@pytest.mark.parametrize("seed", [None, "generator", "seedsequence", [1, 2]])
def test_subsample_index_takes_what_default_rng_takes(seed):
    seed = {"generator": np.random.default_rng(3), "seedsequence": np.random.SeedSequence(3)}.get(
        seed if isinstance(seed, str) else "", seed)
    idx = ve.subsample_index(100, 10, seed)
    assert idx.shape == (10,) and np.all(np.diff(idx) > 0)
    if isinstance(seed, (np.random.Generator, np.random.SeedSequence)):
        assert idx.tolist() == ve.subsample_index(100, 10, 3).tolist()   # default_rng(3)'s draw, as before


def test_plot_xyt_takes_seed_none_all_points_and_a_roll():
    ax = ve.plot_xyt(EV, seed=None, max_points=np.inf, view=(20, -60, 10))
    assert ax.get_title() == f"{len(EV)} of {len(EV)} events" and ax.roll == 10
    plt.close("all")
    assert ve.subsample_index(10, np.inf).tolist() == list(range(10)) and ve.subsample(EV, float("inf")).t.size == len(EV)
    _no(lambda: ve.subsample_index(10, -np.inf), r"max_points")


def test_signed_counts_take_a_tensor_that_requires_grad():
    t = torch.tensor([1.0, -2.0], requires_grad=True)
    assert enhance.signed_to_polarity_counts(t).tolist() == [[1, 0], [0, 2]]


def test_measure_inference_fps_reports_the_count_it_used():
    r = scoring.measure_inference_fps(MODEL, n_frames=4.0, batch_size=2.0, repeats=1)
    assert type(r["n_frames"]) is int and type(r["batch_size"]) is int and r["n_frames"] == 4


@pytest.mark.parametrize("kw,pattern", [(dict(tonemap="nope"), r"tonemap must be one of \('linear', 'reinhard'\)"),
                                        (dict(tonemap=None), r"tonemap must be one of"),
                                        (dict(gamma=0), r"gamma= must be a finite number > 0"),
                                        (dict(gamma=np.nan), r"gamma= must be a finite number > 0"),
                                        (dict(gamma="0.6"), r"gamma= must be a finite number > 0"),
                                        (dict(display=5), r"display= must be a str")])
def test_log_intensity_writer_refuses_a_display_that_is_none(tmp_path, kw, pattern):
    from evinr_lite.io.export import LogIntensityWriter, save_log_intensity

    _no(lambda: LogIntensityWriter(tmp_path / "w.h5", [0.0], (2, 2), **kw), pattern)
    _no(lambda: save_log_intensity(tmp_path / "s.h5", np.zeros((1, 2, 2)), [0.0], **kw), pattern)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("bad", [np.nan, np.inf, 1e39])   # 1e39 is inf as float32
def test_save_log_intensity_refuses_non_finite_frames_before_the_file(tmp_path, bad):
    from evinr_lite.io.export import save_log_intensity

    L = np.zeros((4, 2, 3))
    L[2, 1, 0] = bad
    _no(lambda: save_log_intensity(tmp_path / "l.h5", L, [0.0, 0.1, 0.2, 0.3]), r"log_intensity\[2\] holds NaN or inf")
    assert list(tmp_path.iterdir()) == []   # no file, no partial beside it


def test_log_intensity_writer_refuses_a_nan_frame(tmp_path):
    from evinr_lite.io.export import LogIntensityWriter

    w = LogIntensityWriter(tmp_path / "w.h5", [0.0, 0.1], (2, 2))
    _no(lambda: w.write(1, np.full((2, 2), np.nan)), r"frame 1 holds NaN or infinite")
    w.abort()


def test_log_intensity_export_stores_a_numpy_str_tonemap(tmp_path):
    from evinr_lite.io import export
    from evinr_lite.method.tonemap import TONEMAPS

    assert export.TONEMAPS == TONEMAPS   # io sits below method: the list is kept twice
    L = np.random.default_rng(0).normal(size=(2, 3, 4)).astype(np.float32)
    p = export.save_log_intensity(tmp_path / "a.h5", L, [0.1, 0.2], tonemap=np.str_("reinhard"), gamma=np.float32(0.5),
                                  display="sigmoid")
    back, t, attrs = export.read_log_intensity(p)
    assert np.array_equal(back, L) and attrs["tonemap"] == "reinhard" and attrs["gamma"] == 0.5
    assert export.save_log_intensity(tmp_path / "i.h5", np.ones((1, 2, 2), np.int64), [0.0]).exists()


def test_baseline_and_coordinate_at_take_times_as_reconstruction_at_does():
    from evinr_lite.method.baselines import reconstruct_baseline
    from evinr_lite.method.coordinate import CoordinateConfig, reconstruct_coordinate

    base = reconstruct_baseline(EV, [0.05, 0.1])
    coord = reconstruct_coordinate(EV, [0.05, 0.1], CoordinateConfig(n_iters=2, hidden_features=8, hidden_layers=1,
                                                                     progress=False, device="cpu"))
    for rec in (base, coord):
        _none_of([lambda: rec.at("0.1"), lambda: rec.at(["0.1"]), lambda: rec.at([True]), lambda: rec.frames_at(None)],
                 r"times= must be seconds")
        assert np.array_equal(rec.at(np.float32(0.1)), rec.at([np.float32(0.1)]))
    assert coord.at([]).shape == (0, 8, 10)


def test_refused_on_purpose_stay_refused(tmp_path):
    from decimal import Decimal
    from fractions import Fraction

    _no(lambda: ve.polarity_image(EV, background=np.array([[1, 1, 1]])), r"background= must be a colour")
    _no(lambda: batch.resolve_inputs({"a": 1}, log=QUIET), r"inputs= must be")
    _none_of([lambda: REC.at([Fraction(1, 10)]), lambda: REC.frames_at([Decimal("0.1")])], r"times= must be seconds")
