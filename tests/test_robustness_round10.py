"""Round 10 of the bad-input table (tests/test_robustness*.py): the public entry points earlier rounds touched least,
the scorer (evinr_lite.evaluation), the APS frames as anchors and as the data of the contrast fit
(``reconstruct(..., frames=...)`` with ``EvINRConfig(anchor=...)``, ``--anchor``, ``--C auto``), the colour path
(evinr_lite/method/colour.py, apps/colour_job.py, ``--colour``) and the figures of evinr_lite.viz.

Fixes (each test failed before its fix): APS frames sharing a timestamp were anchors without a word (which of the two
holds at that time is unknown; with ``anchor_every=1`` the offset between them was 0 / 0: NaN frames at the
repeated time), and the contrast fit refused them, and frames merely out of order, as "boundaries must be strictly
increasing" (span "pairs": numpy's IndexError) where sorting them gives the fit; ``mse`` / ``ssim`` took a
prediction on the 0..255 scale and clipped it to white (a score of a white image); ``equalize`` turned 0..255 floats
and uint16 images white and an empty image into OpenCV's AttributeError; ``error_parts`` of frames with no pixel was
numpy's "zero-size array" error; ``score_sequence(lpips_model="none")`` an AttributeError deep in the LPIPS code;
``pool`` of a row with a NaN score a NaN pooled mean; ``frames_to_score`` dropped NaN frame times silently and took a
column of times; ``reconstruct_colour`` took ``config={}`` as the default config, a generator of streams was Python's
TypeError, no query time numpy's "zero-size array" error, a threshold given as text Python's float error, and NaN
channel offsets made every frame NaN; ``channel_offsets_from`` of an infinite intensity and ``chroma_correlation`` of
NaN gave NaN; ``--colour`` on a sensor one photosite high was refused as a (0, W) sensor nobody gave; the figures:
``plot_polarity`` of no events was numpy's IndexError, ``show_frames`` with one time too few an IndexError (and with
no frames matplotlib's error), ``show_frames`` / ``show_images`` drew NaN as blank pixels, ``show_images`` of a 1-D
array failed unpacking its shape, ``plot_histories`` of nothing drew an empty figure and of a history without the
curve a KeyError, ``plot_results`` of no rows was matplotlib's error and of a NaN score drew no bar without a word,
``plot_event_ticks`` with fewer polarities than times numpy's boolean-index error. Closed after (round 10b, each
test failed before its fix too): ``mse`` / ``ssim`` of a 1-D array, a number, a stack [F, H, W] or a colour image
(the docstrings say [H, W]; no caller in the kit passes other shapes) were the mean over all of it, an SSIM along a
line or over a volume, or "SSIM needs images of at least 11 x 11 pixels"; ``plot_signal_and_events`` of None, ``[]``
or an [N, 2] array said only "events must be an Events or a (t, p) pair", of fewer polarities than times was numpy's
boolean-index error, of no sample times an IndexError and of an L shorter than t matplotlib's error;
``plot_window_errors({})`` was a KeyError (and of no windows empty axes); ``show_event_frames(None)`` "object of type
'NoneType' has no len()"; ``plot_tradeoff([])``, ``plot_xyt`` of no events and ``plot_boundaries`` with no
boundaries or of no events drew empty axes without a word.

Guards: odd inputs next to these that already behave and must keep their outcome (uint8 truth against float
predictions, 0..255 floats, NaN or inf pixels, constant and black frames, transposed frames, one image given as
[H, W], times that match no frame, no frames, colour and uint16 truth; black, saturated, constant, uint16, transposed,
out-of-span, missing and single anchor frames, and frames out of order; the fit of C on black, saturated or constant
frames, one frame or frames outside the events; odd-sized colour sensors, a recording without a colour filter, a
channel with no events, bad thresholds and C; the viz functions' existing refusals; the command line's --anchor,
--C auto and --colour on such recordings; one image with a trailing channel of one in mse / ssim; a 1-D signal with
no events, as ``([], [])`` or as an empty Events).
"""
import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
import pytest

from evinr_lite import EventDataError, Events, EvINRConfig, reconstruct
from evinr_lite.core.frames import Frames
from evinr_lite.core.recording import Recording
from evinr_lite.evaluation import (equalize, error_parts, frames_to_score, match_level, mse, pool, score_frames,
                                   score_sequence, ssim)
from evinr_lite.method.colour import channel_offsets_from, chroma_correlation, reconstruct_colour
from evinr_lite.method.contrast import fit_contrast

from test_robustness import H, W, assert_clear_error, run

FAST = dict(n_iters=0, progress=False)      # the head solved, no training: the inputs are what is tested
RNG = np.random.default_rng(0)
GT = RNG.uniform(0.05, 0.95, (3, 16, 20))
T = np.array([0.1, 0.2, 0.3])


def _events(size=(H, W), n=600, span=0.4, seed=0, keep=None):
    rng = np.random.default_rng(seed)
    t, x, y = np.sort(rng.uniform(0, span, n)), rng.integers(0, size[1], n), rng.integers(0, size[0], n)
    p = rng.choice([-1, 1], n)
    if keep is not None:
        k = keep(x, y)
        t, x, y, p = t[k], x[k], y[k], p[k]
    return Events.from_arrays(t, x, y, p, size)


@pytest.fixture(scope="module")
def ev():
    return _events()


IMG = np.random.default_rng(1).uniform(0.2, 0.8, (4, H, W))
FT = np.array([0.05, 0.15, 0.25, 0.35])
Q = np.array([0.1, 0.2, 0.3])


def _no(fn, pattern):
    """fn() must raise a clear error (EventDataError, a ValueError) whose message matches pattern."""
    with pytest.raises(ValueError, match=pattern):
        fn()


# ---- 1. the scorer: fixes ----------------------------------------------------------------------------------------

def test_scoring_refuses_a_prediction_on_the_0_255_scale_in_mse_and_ssim():
    _no(lambda: mse(GT[0] * 255, GT[0]), r"0\.\.255")
    _no(lambda: ssim(GT[0] * 255, GT[0]), r"0\.\.255")
    assert mse(GT[0] * 1.02, GT[0]) < 1e-3       # a small overshoot is clipped, as the protocol says


@pytest.mark.parametrize("image,pattern", [(GT[0] * 255, r"0\.\.255"), ((GT[0] * 65535).astype(np.uint16), "uint16"),
                                           (np.zeros((0, 0)), "empty")])
@pytest.mark.parametrize("method", ["global", "clahe"])
def test_scoring_equalize_refuses_images_it_would_turn_white(image, pattern, method):
    _no(lambda: equalize(image, method), pattern)


def test_scoring_error_parts_of_frames_without_pixels():
    _no(lambda: error_parts(np.zeros((1, 0, 0)), np.zeros((1, 0, 0))), r"no frame or no pixel")


def test_scoring_an_lpips_model_given_as_text():
    _no(lambda: score_sequence(GT, T, GT, T, lpips_model="none"), r"lpips_model .*False")


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), "n/a", None])
def test_scoring_pool_refuses_a_row_without_a_score(bad):
    row = score_sequence(GT, T, GT, T, lpips_model=False)
    _no(lambda: pool([row, {**row, "mse": bad}]), r"row 1 has mse")
    assert pool([row, row])["mse"] == 0.0


def test_scoring_frames_to_score_refuses_nan_and_column_times(ev):
    _no(lambda: frames_to_score([np.nan, 0.1], ev), r"frame_t\[0\] is nan")
    _no(lambda: frames_to_score([[0.1], [0.2]], ev), r"1-D")
    assert frames_to_score([0.1, 5.0], ev).tolist() == [0]
    # guard (review of this round): a negative margin keeps the frames well inside the span, as it always did
    first, last = float(ev.t[0]), float(ev.t[-1])
    inside = frames_to_score([first, (first + last) / 2, last], ev, margin=-1e-6).tolist()
    assert inside == [1]


@pytest.mark.parametrize("shape,pattern", [((320,), r"1-D .* reshape it to \[H, W\]"), ((), r"1-D .*\[H, W\]"),
                                           ((3, 16, 20), r"\(3, 16, 20\); for a stack .*score_frames"),
                                           ((12, 16, 20), r"score_frames"), ((16, 20, 3), r"grey first")])
@pytest.mark.parametrize("metric", [mse, ssim])
def test_scoring_mse_and_ssim_refuse_what_is_not_one_image(metric, shape, pattern):
    """Before: mse of a 1-D array, a number, a stack or a colour image was the mean over all of it, ssim of a 1-D
    array an SSIM along a line and of a stack of 11 or more frames one 3-D SSIM over the volume (of fewer frames, or
    colour, "SSIM needs images of at least 11 x 11 pixels"); no caller in the kit passes them."""
    a = np.random.default_rng(2).uniform(0.1, 0.9, shape)
    _no(lambda: metric(a, a), pattern)


# ---- 2. the scorer: guards ---------------------------------------------------------------------------------------

def test_scoring_mse_and_ssim_take_one_image_with_a_trailing_channel_of_one():
    assert mse(GT[0][..., None], GT[1]) == mse(GT[0], GT[1]) and ssim(GT[0], GT[1][..., None]) == ssim(GT[0], GT[1])
    assert score_frames(GT, GT * 0.9)["mse"] == pytest.approx(np.mean([mse(a, a * 0.9) for a in GT]))


def test_scoring_uint8_truth_matches_float_truth():
    u8 = np.round(GT * 255).astype(np.uint8)
    a = score_sequence(GT, T, u8, T, lpips_model=False)
    b = score_sequence(GT, T, u8 / 255.0, T, lpips_model=False)
    assert a["mse"] == pytest.approx(b["mse"]) and a["ssim"] == pytest.approx(b["ssim"]) and a["n_frames"] == 3


@pytest.mark.parametrize("which", ["pred", "gt"])
@pytest.mark.parametrize("bad", ["255", "nan", "inf", "uint16", "bool", "rgb"])
def test_scoring_bad_pixels_are_refused(which, bad):
    images = {"255": GT * 255, "nan": np.where(GT > 0.9, np.nan, GT), "inf": np.where(GT > 0.9, np.inf, GT),
              "uint16": (GT * 65535).astype(np.uint16), "bool": GT > 0.5, "rgb": np.stack([GT] * 3, -1)}[bad]
    pred, gt = (images, GT) if which == "pred" else (GT, images)
    pattern = {"255": r"0\.\.255", "nan": "NaN", "inf": "NaN or inf", "uint16": "uint16", "bool": "bool",
               "rgb": "grey"}[bad]
    _no(lambda: score_sequence(pred, T, gt, T, lpips_model=False), pattern)
    if bad not in ("rgb",):
        _no(lambda: error_parts(pred, gt), pattern)


def test_scoring_constant_and_black_frames():
    flat = np.full_like(GT, 0.5)
    assert score_sequence(flat, T, flat, T, lpips_model=False)["ssim"] == pytest.approx(1.0)
    assert score_sequence(np.zeros_like(GT), T, np.zeros_like(GT), T, lpips_model=False)["mse"] == 0.0
    r = score_sequence(flat, T, GT, T, lpips_model=False)
    assert np.isfinite(r["mse"]) and np.isfinite(r["ssim"]) and r["ssim"] < 0.2
    _no(lambda: error_parts(np.zeros_like(GT), GT), r"0 everywhere")
    parts = error_parts(GT, np.zeros_like(GT))
    assert parts["gain"] == 0.0 and parts["mse_at_level"] == 0.0
    matched, gain = match_level(np.ones_like(GT), GT)          # saturated: the gain gives the truth's mean
    assert matched.mean() == pytest.approx(GT.mean()) and 0 < gain < 1


def test_scoring_transposed_frames_are_refused_naming_both_shapes():
    _no(lambda: score_sequence(GT, T, GT.transpose(0, 2, 1), T, lpips_model=False), r"\(16, 20\).*\(20, 16\)")
    _no(lambda: error_parts(GT, GT.transpose(0, 2, 1)), r"\(3, 16, 20\).*\(3, 20, 16\)")
    _no(lambda: score_frames(GT, GT.transpose(0, 2, 1)), r"same shape")


def test_scoring_one_image_given_as_2d_names_the_fix():
    _no(lambda: score_sequence(GT[0], 0.1, GT[0], 0.1, lpips_model=False), r"image\[None\]")
    _no(lambda: error_parts(GT[0], GT[0]), r"image\[None\]")
    _no(lambda: score_frames(GT[0], GT[0]), r"image\[None\]")


def test_scoring_times_that_match_no_frame_or_differ_in_count():
    _no(lambda: score_sequence(GT, T, GT, T + 1.0, lpips_model=False), r"no ground-truth frame has a prediction")
    _no(lambda: score_sequence(GT, T[:2], GT, T, lpips_model=False), r"one timestamp per frame")
    r = score_sequence(GT, [0.1, 0.1, 0.1], GT, T, lpips_model=False)   # one prediction is used once
    assert r["n_frames"] == 1 and r["n_gt_frames"] == 3


def test_scoring_empty_sequences():
    empty = np.zeros((0, 16, 20))
    _no(lambda: score_sequence(empty, [], empty, [], lpips_model=False), r"empty")
    _no(lambda: score_frames(empty, empty), r"one or more matched frame pairs")
    _no(lambda: error_parts(empty, empty), r"stack")
    _no(lambda: pool([]), r"at least one")


# ---- 3. APS anchors and the contrast fit: fixes --------------------------------------------------------------------

@pytest.mark.parametrize("mode", ["first", "all"])
@pytest.mark.parametrize("times", [[0.05, 0.05, 0.25, 0.25], [0.05, 0.15, 0.05, 0.15]])
def test_anchor_frames_sharing_a_timestamp_are_refused(ev, mode, times):
    cfg = EvINRConfig(anchor=mode, **FAST)
    _no(lambda: reconstruct(ev, Q, cfg, frames=Frames(IMG, times)), r"share a timestamp.*distinct times")


def test_anchor_every_frame_with_duplicates_gave_nan_at_the_repeated_time(ev):
    """Before: rec.frames_at([0.25]) was NaN (the offset between two anchors at 0.25 s, 0 / 0)."""
    cfg = EvINRConfig(anchor="all", anchor_every=1, **FAST)
    _no(lambda: reconstruct(ev, Q, cfg, frames=Frames(IMG, [0.05, 0.05, 0.25, 0.25])), r"share a timestamp")


@pytest.mark.parametrize("span", ["trajectory", "pairs"])
def test_contrast_fit_of_frames_out_of_order_is_the_fit_of_them_sorted(span):
    from evinr_lite.sim.scenes import MovingImageScene
    from evinr_lite.sim.simulate import simulate_scene

    scene = MovingImageScene("camera", (24, 32), 0.5, velocity=(20.0, 8.0), rotation=0.0, zoom=0.0)
    events = simulate_scene(scene, 0.0, 0.5, C=0.2, seed=0)
    ft = np.linspace(0.02, 0.48, 8)
    frames = Frames(np.stack([np.clip(scene.intensity(t), 0, 1) for t in ft]).astype(np.float32), ft)
    want = fit_contrast(frames, events, span=span, n_bootstrap=0)
    order = np.random.default_rng(3).permutation(8)
    got = fit_contrast(Frames(frames.images[order], ft[order]), events, span=span, n_bootstrap=0)
    assert got.C == pytest.approx(want.C)


@pytest.mark.parametrize("span", ["trajectory", "pairs"])
def test_contrast_fit_of_frames_sharing_a_timestamp_is_refused(ev, span):
    _no(lambda: fit_contrast(Frames(IMG, [0.05, 0.05, 0.25, 0.25]), ev, span=span), r"fitting C: .*share a timestamp")


# ---- 4. APS anchors and the contrast fit: guards -------------------------------------------------------------------

@pytest.mark.parametrize("mode", ["first", "all"])
@pytest.mark.parametrize("kind", ["black", "saturated", "saturated uint8", "constant", "one", "unsorted"])
def test_anchor_odd_frames_give_finite_frames_in_range(ev, mode, kind):
    images, times = {"black": (np.zeros_like(IMG), FT), "saturated": (np.ones_like(IMG), FT),
                     "saturated uint8": (np.full(IMG.shape, 255, np.uint8), FT),
                     "constant": (np.full_like(IMG, 0.5), FT), "one": (IMG[:1], FT[:1]),
                     "unsorted": (IMG[::-1], FT[::-1])}[kind]
    rec = reconstruct(ev, Q, EvINRConfig(anchor=mode, **FAST), frames=Frames(images, times))
    assert np.all(np.isfinite(rec.frames)) and rec.frames.min() >= 0 and rec.frames.max() <= 1
    assert np.all(np.isfinite(rec.frames_at([0.001, 0.39])))
    assert rec.anchor_times[0] == pytest.approx(0.05)     # the earliest frame, whatever the given order


@pytest.mark.parametrize("mode", ["first", "all"])
def test_anchor_bad_frames_are_refused(ev, mode):
    cfg = EvINRConfig(anchor=mode, **FAST)
    _no(lambda: reconstruct(ev, Q, cfg, frames=Frames(IMG, FT + 5)), r"no APS frame lies inside")
    _no(lambda: reconstruct(ev, Q, cfg, frames=Frames(np.zeros((0, H, W)), [])), r"no frames")
    _no(lambda: reconstruct(ev, Q, cfg, frames=Frames(IMG.transpose(0, 2, 1), FT)), r"same H x W")
    _no(lambda: reconstruct(ev, Q, cfg), r"needs the APS frames")
    _no(lambda: Frames((IMG * 65535).astype(np.uint16), FT), r"uint16")
    _no(lambda: Frames(np.where(IMG > 0.7, np.nan, IMG), FT), r"NaN")


@pytest.mark.parametrize("kind,pattern", [("black", "too few usable samples"), ("saturated", "too few usable samples"),
                                          ("constant", "not positive"), ("one", "at least two"),
                                          ("outside", "at least two"), ("all one time", "share a timestamp")])
def test_contrast_fit_of_odd_frames_is_refused(ev, kind, pattern):
    images, times = {"black": (np.zeros_like(IMG), FT), "saturated": (np.ones_like(IMG), FT),
                     "constant": (np.full_like(IMG, 0.5), FT), "one": (IMG[:1], FT[:1]),
                     "outside": (IMG, FT + 5), "all one time": (IMG, [0.05] * 4)}[kind]
    _no(lambda: fit_contrast(Frames(images, times), ev), pattern)


def _canonical_with_frames(path, frames, cfa=None, size=(H, W)):
    from evinr_lite.io.canonical import CanonicalWriter

    ev = _events(size, n=800, span=0.3)
    with CanonicalWriter(path, sensor_size=size, cfa=cfa) as w:
        w.add_events(ev.t, ev.x, ev.y, ev.p)
        for stamp, image in frames:
            w.add_frame(image, stamp)
    return path


CLI_FAST = ["--fps", "5", "--iters", "1", "--quiet", "--no-video"]


@pytest.mark.parametrize("case,option,pattern", [
    ("black", ["--C", "auto"], r"too few usable samples.*give C"),
    ("one frame", ["--C", "auto"], r"1 frame\(s\) \(2 or more needed\)"),
    ("outside", ["--anchor", "first"], r"has none in the window"),
    ("none", ["--anchor", "all"], r"frames"),
])
def test_anchor_and_C_auto_on_the_command_line(capsys, tmp_path, case, option, pattern):
    grey = np.full((H, W), 100, np.uint8)
    frames = {"black": [(t, np.zeros((H, W), np.uint8)) for t in (0.05, 0.15, 0.25)], "one frame": [(0.1, grey)],
              "outside": [(0.5, grey), (0.6, grey)], "none": []}[case]
    path = _canonical_with_frames(tmp_path / "c.h5", frames)
    assert_clear_error(capsys, ["reconstruct", path, "--out", tmp_path / "out", *option, *CLI_FAST], pattern)
    assert not (tmp_path / "out").exists()


def test_anchor_first_with_one_frame_on_the_command_line(capsys, tmp_path):
    path = _canonical_with_frames(tmp_path / "c.h5", [(0.1, np.full((H, W), 100, np.uint8))])
    code, out, err = run(capsys, "reconstruct", path, "--out", tmp_path / "out", "--anchor", "first", *CLI_FAST)
    assert code == 0, err
    assert (tmp_path / "out" / "run.json").exists()


# ---- 5. colour: fixes --------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def small():
    return _events((12, 16))


def test_colour_a_config_given_as_an_empty_dict_is_refused(small):
    _no(lambda: reconstruct_colour((small, small, small), Q, {}, C=0.2), r"config= must be EvINRConfig")


def test_colour_streams_as_a_generator_are_read(small):
    rec = reconstruct_colour(iter((small, small, small)), Q, EvINRConfig(**FAST), C=0.2)
    assert rec.frames.shape == (3, 12, 16, 3) and np.all(np.isfinite(rec.frames))


def test_colour_streams_in_any_container_are_read(small):
    """Guard (review of this round): a dict's values or a deque were read before the generator fix and still are."""
    from collections import deque

    for streams in ({"R": small, "G": small, "B": small}.values(), deque((small,) * 3)):
        rec = reconstruct_colour(streams, Q, EvINRConfig(**FAST), C=0.2)
        assert rec.frames.shape == (3, 12, 16, 3)


@pytest.mark.parametrize("q,pattern", [([], "empty"), ([np.nan], "finite")])
def test_colour_query_times_are_checked(small, q, pattern):
    _no(lambda: reconstruct_colour((small,) * 3, q, EvINRConfig(**FAST), C=0.2), r"query_times= .*" + pattern)


def test_colour_thresholds_given_as_text(small):
    _no(lambda: reconstruct_colour((small,) * 3, Q, EvINRConfig(**FAST), thresholds=("a", 1, 1)),
        r"thresholds must be three positive numbers")


@pytest.mark.parametrize("offsets", [[np.nan, 0, 0], [np.inf, 0, 0], [0, 0]])
def test_colour_offsets_must_be_finite(small, offsets):
    _no(lambda: reconstruct_colour((small,) * 3, Q, EvINRConfig(**FAST), C=0.2, channel_offsets=offsets),
        r"channel_offsets must be 3 finite numbers")


def test_colour_reference_and_chroma_refuse_non_finite_values():
    _no(lambda: channel_offsets_from(np.array([[1.0, np.inf, 1.0]])), r"positive finite")
    _no(lambda: chroma_correlation(np.full((1, 4, 4, 3), np.nan), np.ones((1, 4, 4, 3))), r"NaN or inf")
    assert chroma_correlation(np.ones((1, 4, 4, 3)), np.ones((1, 4, 4, 3))) == {"R-G": 0.0, "B-G": 0.0}


def test_colour_a_sensor_one_photosite_high(capsys, tmp_path):
    from evinr_lite.apps.colour_job import reconstruct_colour_recording

    rec = Recording(_events((1, 32)), None, {"format": "canonical", "path": "thin.h5", "cfa": "RGGB"})
    _no(lambda: reconstruct_colour_recording(rec, Q, EvINRConfig(**FAST)), r"1 x 32 sensor holds no full 2 x 2")


# ---- 6. colour: guards -------------------------------------------------------------------------------------------

@pytest.mark.parametrize("size", [(24, 32), (25, 33), (24, 33), (3, 3)])
def test_colour_odd_sensors_drop_the_last_row_or_column(size):
    from evinr_lite.apps.colour_job import reconstruct_colour_recording

    rec = Recording(_events(size, n=3000), None, {"format": "canonical", "path": "c.h5", "cfa": "RGGB"})
    res = reconstruct_colour_recording(rec, Q, EvINRConfig(**FAST))
    assert res.frames.shape == (3, size[0] // 2, size[1] // 2, 3) and np.all(np.isfinite(res.frames))


@pytest.mark.parametrize("cfa,pattern", [(None, "no colour filter"), ("RGBW", "must be one of RGGB")])
def test_colour_a_recording_without_a_usable_filter(cfa, pattern):
    from evinr_lite.apps.colour_job import reconstruct_colour_recording

    meta = {"format": "canonical", "path": "c.h5", **({} if cfa is None else {"cfa": cfa})}
    _no(lambda: reconstruct_colour_recording(Recording(_events((24, 32)), None, meta), Q, EvINRConfig(**FAST)),
        pattern)


def test_colour_a_channel_with_no_events():
    from evinr_lite.apps.colour_job import reconstruct_colour_recording

    no_red = _events((24, 32), n=3000, keep=lambda x, y: ~((x % 2 == 0) & (y % 2 == 0)))   # RGGB: R at (even, even)
    rec = Recording(no_red, None, {"format": "canonical", "path": "c.h5", "cfa": "RGGB"})
    _no(lambda: reconstruct_colour_recording(rec, Q, EvINRConfig(**FAST)), r"fewer than 2 R events")
    empty = Events.from_arrays(np.zeros(0), np.zeros(0, int), np.zeros(0, int), np.zeros(0, int), (12, 16))
    small = _events((12, 16))
    _no(lambda: reconstruct_colour((small, small, empty), Q, EvINRConfig(**FAST), C=0.2), r"at least 2 events")


@pytest.mark.parametrize("kw,pattern", [(dict(thresholds=(np.nan, 1, 1)), "three positive"),
                                        (dict(thresholds=(1, 1)), "three positive"), (dict(C=-1), "positive"),
                                        (dict(C=np.nan), "positive"), (dict(), "pass C")])
def test_colour_bad_thresholds(small, kw, pattern):
    _no(lambda: reconstruct_colour((small,) * 3, Q, EvINRConfig(**FAST), **kw), pattern)


def test_colour_on_the_command_line_without_a_filter(capsys, tmp_path):
    path = _canonical_with_frames(tmp_path / "c.h5", [])
    assert_clear_error(capsys, ["reconstruct", path, "--out", tmp_path / "out", "--colour", *CLI_FAST],
                       r"no colour filter")


# ---- 7. the figures: fixes ---------------------------------------------------------------------------------------

EMPTY = Events.from_arrays(np.zeros(0), np.zeros(0, int), np.zeros(0, int), np.zeros(0, int), (4, 5))


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def test_viz_polarity_of_no_events():
    from evinr_lite.viz import plot_polarity

    _no(lambda: plot_polarity(EMPTY), r"no events.*t0 and t1")
    assert plot_polarity(EMPTY, 0.0, 1.0).get_title().endswith("0 events")


@pytest.mark.parametrize("rows,times,pattern", [
    ({"a": np.zeros((0, 4, 5))}, None, r"no frames"),
    ({"a": np.zeros((2, 4, 5))}, [0.1], r"1 value\(s\) for 2 frame"),
    ({"a": np.full((2, 4, 5), np.nan)}, None, r"NaN"),
])
def test_viz_show_frames_odd_rows(rows, times, pattern):
    from evinr_lite.viz import show_frames

    _no(lambda: show_frames(rows, times), pattern)


@pytest.mark.parametrize("image,pattern", [(np.zeros(5), r"\[H, W\]"), (np.zeros((0, 3)), r"\[H, W\]"),
                                           (np.full((4, 5), np.inf), "NaN or inf")])
def test_viz_show_images_odd_images(image, pattern):
    from evinr_lite.viz import show_images

    _no(lambda: show_images({"a": image}), pattern)


def test_viz_plot_histories_of_nothing_or_a_missing_curve():
    from evinr_lite.viz import plot_histories

    _no(lambda: plot_histories({}), r"empty")
    _no(lambda: plot_histories({"a": {"psnr": [1.0]}}), r"no 'loss' .*psnr")


def test_viz_plot_results_of_no_rows_or_a_nan_score():
    from evinr_lite.viz import plot_results

    _no(lambda: plot_results([]), r"result rows")
    _no(lambda: plot_results([{"method": "a", "mse": np.nan, "ssim": 0.5, "lpips": None}]), r"mse = nan")


def test_viz_event_ticks_with_fewer_polarities():
    from evinr_lite.viz import plot_event_ticks

    _no(lambda: plot_event_ticks(plt.gca(), [0.1, 0.2], [1]), r"2 event times but 1 polarities")


SIG_T = np.linspace(0.0, 1.0, 50)


@pytest.mark.parametrize("t,L,events,pattern", [
    (SIG_T, np.sin(SIG_T), None, r"events is None.*\(\[\], \[\]\) for no events"),
    (SIG_T, np.sin(SIG_T), [], r"got an empty list"),
    (SIG_T, np.sin(SIG_T), np.zeros((5, 2)), r"columns \[N, 2\] are \(events\[:, 0\], events\[:, 1\]\)"),
    (SIG_T, np.sin(SIG_T), ([0.1, 0.2], [1]), r"2 event time\(s\) but 1 polarities"),
    ([], [], ([0.1], [1]), r"t must be the sample times"),
    (SIG_T, np.sin(SIG_T)[:10], ([0.1], [1]), r"L has shape \(10,\) for 50 sample times"),
])
def test_viz_signal_and_events_of_empty_or_mismatched_inputs(t, L, events, pattern):
    """Before: None, [] and an [N, 2] array were a TypeError saying only "an Events or a (t, p) pair", fewer
    polarities than times numpy's boolean-index error, no sample times an IndexError and L shorter than t
    matplotlib's "x and y must have same first dimension"."""
    from evinr_lite.viz import plot_signal_and_events

    _no(lambda: plot_signal_and_events(t, L, events, 0.2), pattern)


@pytest.mark.parametrize("result,pattern", [({}, r"'window' and 'taylor'.*got keys \[\]"),
                                            ({"window": [0.1, 0.2]}, r"got keys \['window'\]"),
                                            ({"window": [], "taylor": []}, r"no window lengths"),
                                            ({"window": [0.1, 0.2], "taylor": [1.0]}, r"2 window length\(s\)")])
def test_viz_window_errors_of_an_odd_result(result, pattern):
    """Before: a KeyError ('window'), empty axes, or matplotlib's "x and y must have same first dimension"."""
    from evinr_lite.viz import plot_window_errors

    _no(lambda: plot_window_errors(result, C=0.1), pattern)


@pytest.mark.parametrize("frames,pattern", [(None, r"EventFrames, got NoneType.*events_to_frames"),
                                            (np.zeros((3, 4, 5)), r"EventFrames, got ndarray")])
def test_viz_show_event_frames_of_what_is_not_event_frames(frames, pattern):
    """Before: "object of type 'NoneType' has no len()" (a TypeError) and, of an array, an AttributeError."""
    from evinr_lite.viz import show_event_frames

    _no(lambda: show_event_frames(frames), pattern)


@pytest.mark.parametrize("case,pattern", [("tradeoff", r"no rows to plot"), ("xyt", r"no events to draw"),
                                          ("no boundaries", r"boundaries is empty.*\{label: edges"),
                                          ("boundaries of no events", r"no events")])
def test_viz_empty_axes_without_a_word(case, pattern):
    """Before: plot_tradeoff([]), plot_xyt of no events and plot_boundaries with no boundaries (or of no events)
    drew empty axes (a legend of nothing, "0 of 0 events") and returned them."""
    from evinr_lite import viz

    e = _events((4, 5), n=50, span=1.0)
    draw = {"tradeoff": lambda: viz.plot_tradeoff([]), "xyt": lambda: viz.plot_xyt(EMPTY),
            "no boundaries": lambda: viz.plot_boundaries(e, {}),
            "boundaries of no events": lambda: viz.plot_boundaries(EMPTY, {"a": [0.0, 1.0]})}[case]
    _no(draw, pattern)
    assert not plt.get_fignums()          # refused before a figure was made


# ---- 8. the figures: guards --------------------------------------------------------------------------------------

def test_viz_existing_refusals_keep_their_outcome():
    from evinr_lite import viz

    e = _events((4, 5), n=50, span=1.0)
    _no(lambda: viz.plot_event_rate(EMPTY, 0.1), r"t_range")
    _no(lambda: viz.plot_event_rate(e, 0), r"positive")
    _no(lambda: viz.plot_polarity(e, 0.8, 0.2), r"empty or reversed")
    _no(lambda: viz.count_map(e, 2), r"polarity must be")
    _no(lambda: viz.plot_xyt(e, max_points=0), r"at least 1")
    _no(lambda: viz.animate_events(EMPTY), r"t_range")
    _no(lambda: viz.show_frames({}), r"empty")
    _no(lambda: viz.show_frames({"a": np.zeros((2, 4, 5)), "b": np.zeros((3, 4, 5))}), r"same Q")
    _no(lambda: viz.show_images({}), r"empty")
    _no(lambda: viz.plot_ablation([]), r"no rows")
    _no(lambda: viz.plot_robustness({}), r"no sweeps")
    assert viz.count_map(EMPTY).sum() == 0 and viz.plot_event_ticks(plt.gca(), [], []) is not None
    assert viz.show_frames({"a": np.zeros((2, 4, 5))}, [0.1, 0.2]) is not None


def test_viz_signal_with_no_events_draws_the_signal_alone():
    from evinr_lite.viz import plot_signal_and_events

    for no_events in (([], []), Events.from_arrays(np.zeros(0), np.zeros(0, int), np.zeros(0, int), np.zeros(0, int),
                                                   (1, 3))):
        ax = plot_signal_and_events(SIG_T, np.sin(SIG_T), no_events, 0.2)
        assert ax.get_legend_handles_labels()[1] == ["L(t) = log I(t)", "ON events (0)", "OFF events (0)"]


def test_review_mends_plot_polarity_with_a_title_and_integer_and_overshooting_images():
    """Review of this round: plot_polarity of no events with a title of its own draws as before (the refusal is for
    a title read from the events); mse / ssim name the fix for uint16 and int64 images as score_pairs does (they
    were cast to float first and told to divide by 255); a prediction a little above 2 (an unclipped exp) is not
    told it looks like 0..255."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from evinr_lite.core.events import Events
    from evinr_lite.viz import plot_polarity

    empty = Events(np.zeros(0), np.zeros(0, int), np.zeros(0, int), np.zeros(0, int), (4, 5))
    ax = plot_polarity(empty, title="an empty slice")
    assert ax.get_title() == "an empty slice"
    plt.close("all")
    gt = np.full((8, 8), 0.5)
    _no(lambda: mse(np.full((8, 8), 40000, np.uint16), gt), r"uint16 integers .*65535")
    _no(lambda: mse(np.ones((8, 8), np.int64), gt), r"int64 integers")
    _no(lambda: mse(np.full((8, 8), 3.3), gt), r"clip them to \[0, 1\]")
    _no(lambda: mse(np.full((8, 8), 200.0), gt), r"look like 0\.\.255")
