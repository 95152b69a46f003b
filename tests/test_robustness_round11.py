"""Round 11 of the bad-input table (tests/test_robustness*.py): the public entry points earlier rounds touched least,
the simulator (evinr_lite.sim: the event simulators, the noise it adds, the scenes, Quad Bayer and the synthetic
recordings) and the method's helpers beside the main reconstruct path (the baselines, the binning, the smoothing rule,
the ensemble's windows, the tone maps, the denoiser) and evinr_lite.evaluation's enhancement and ablation helpers.

Fixes (each test failed before its fix): the noise functions drew unseeded noise for ``seed=None`` (the same call
gave other events each time) and passed a negative or text seed to numpy ("expected non-negative integer"); a noise
rate given as text was numpy's ufunc error, one given as a 0-d array or tensor was refused (C takes them); an
infinite span was numpy's "lam value too large", a reversed or NaN span of hot pixels "lam < 0", a start given as
text was taken; events with no event and no span were numpy's IndexError, a (t, p) pair or None an AttributeError,
a rate that adds 10^15 events a MemoryError; ``add_hot_pixels`` took 2.5 pixels as 2 and "2" as 2 (NaN: Python's
"cannot convert float NaN"); ``add_light_noise`` with no scene was an AttributeError, ``n_frames_per_s`` of 0 or
-5 was taken and of NaN Python's error, a ``max_gain`` given as text numpy's; complex sample times, samples or
colour frames lost their imaginary part without a word; ``simulate_events_1d(refine="no")`` refined;
``pixel_events`` took pixel 1.5 (no events), pixel "0" was Python's TypeError, a pair of text numpy's, a pair with
NaN times passed them on, and a pair with ``pixel=3`` ignored the pixel. The scenes: ``MovingBarScene`` with a NaN
angle or an infinite width or edge blamed "speed ... got None" (not given), NaN or infinite intensities and a NaN
start gave NaN or inf log intensity, one intensity was Python's "not iterable"; ``MovingImageScene`` with one
number as velocity or intensity_range, blur or rotation as text, and a complex image failed in Python or numpy or
dropped the imaginary part; ``OscillatingScene`` with a path of 3 numbers or a rotation of one was numpy's reshape
or Python's unpack error; ``VaryingSpeedScene`` and ``LightingScene`` of None or of a name were AttributeErrors, an
infinite period NaN frames and a period or depth as text Python's TypeError; ``ObjectOverBackgroundScene`` with a
start of 3 numbers was numpy's broadcast error and with a NaN start NaN frames; ``WarpedImageScene(shear=0.1)``
"not iterable"; ``Scene.log_intensity("0.1")`` read text as a time (and a complex time was Python's error);
``QuadBayerScene`` with one number as intensity_range was "not subscriptable", with a complex image silent, and
with an unknown motion argument named MovingImageScene.__init__; ``simulate_colour_video`` with infinite frames
named ``log_frames`` (not its argument), with NaN frames called them not positive, and with text numpy's error;
``write_example_recording`` with frame_rate 0 was a ZeroDivisionError, -1 a recording without frames and NaN
numpy's arange error; ``synthetic_recording(n_frames=1)`` a ZeroDivisionError, 0 a complaint about a temporary
images.txt and 2.5 two frames; ``colour_davis_recording(frame_rate="20")`` numpy's ufunc error. The method:
``leaky_integration`` / ``highpass_filter`` of a (t, p) pair or None were AttributeErrors, L0 of NaN gave NaN frames
and as text or complex Python's errors, a NaN t_start NaN frames, "0" was taken and an infinite one used; their
rates as a 0-d array or tensor were refused; ``complementary_filter(t_start=nan)`` said t_start was before the first
frame; ``fixed_duration_boundaries`` with times or a bin length as text or None, ``equal_count_boundaries`` of None,
with a NaN events_per_bin, 2.5 or "3" bins, ``events_to_frames`` of None or a pair, or boundaries as text, failed in
Python or numpy; ``bisect_boundaries`` took NaN and decreasing boundaries (NaN or reversed edges) and one edge was an
IndexError; ``event_rate`` took a t_range of three values and one of one value was an IndexError; ``auto_lam`` of
NaN or negative counts or a NaN, zero, negative or > 1 fraction gave a lam without a word, and counts of two shapes
numpy's broadcast error; ``covered_fraction`` of no windows or a flat pair was numpy's IndexError;
``window_fraction`` of a NaN span was 1; ``split_windows`` with tau equal to the overlap or 0 was a
ZeroDivisionError, with NaN tau or overlap or an infinite span Python's conversion errors, a negative overlap left
gaps between the windows, tau as text was Python's TypeError and 0-d tensors numpy's; ``tonemap_linear`` of NaN
gave NaN frames and of text numpy's error, ``tonemap_reinhard`` of a NaN tensor NaN; ``display_shift`` (reinhard)
of NaN was NaN and of nothing numpy's "mean of empty slice", a display_mean as text Python's TypeError, gamma 0 or
-1 a ZeroDivisionError or "math domain error" (``anchor_level`` too, and NaN gave NaN), ``anchor_mean`` of text
numpy's error and of NaN NaN; ``denoise(hot_pixels="no")`` ran the stage; ``hot_threshold`` of a list was Python's
TypeError and NaN or negative counts were dropped without a word. The evaluation: ``render_event_counts`` with C 0,
NaN or negative gave garbage counts (or none of the sign), with C as text numpy's error, of NaN log intensities
garbage, of none an IndexError and of complex ones the real part; ``event_counts`` took NaN and infinite boundaries
and of None was an AttributeError, ``model_event_counts(None, ...)`` too; ``count_scores`` of NaN, fractional or
negative counts cast them, with C NaN gave a NaN RMSE and with C as text numpy's error; ``integration_baseline`` with
C as text or a pair was a format error and gamma 0 or -1 failed when called; ``tau_for_networks`` took 2.5 networks
and a negative overlap, "2" was Python's TypeError and a NaN duration blamed the overlap; ``pareto_front`` put a NaN
variant on the front, took 2-D arrays and of two lengths was numpy's broadcast error; ``relative_change`` from 0 was
a ZeroDivisionError and of NaN NaN; ``ablation_table`` with one column name as text made a column per letter and of
one row (a dict) was Python's TypeError; ``run_variants`` with repeats 1.5 or "2", n_inference 0, events as a pair
or variants as a list failed in Python, one equalisation given as text was taken letter by letter ("got 'c'") and
uint16 truth was called 0..255.

Guards: odd inputs next to these that already behave and must keep their outcome (seeded noise is repeatable and a
Generator is taken, a span given for no events, 0 hot pixels, float16 / int8 / list / tensor log frames, a 1 x 1
sensor, uint8 / bool / list / tensor images in a scene, uint8 and odd-sized colour frames, the 1-D events' pixel as
np.int64, ([], []) as no events, the baselines on no events, 0-d tensors as bin limits, the valid lam rule, a single
window, the tone maps of +-inf, the denoiser on no events, one boundary's counts, the empty Pareto front, and the
existing refusals next to the new ones).
"""
import math

import numpy as np
import pytest
import torch

from evinr_lite import Events
from evinr_lite.evaluation.ablation import (ablation_table, integration_baseline, pareto_front, relative_change,
                                            run_variants, tau_for_networks)
from evinr_lite.evaluation.enhance import count_scores, event_counts, model_event_counts, render_event_counts
from evinr_lite.method.baselines import complementary_filter, highpass_filter, leaky_integration, reconstruct_baseline
from evinr_lite.method.binning import (bisect_boundaries, equal_count_boundaries, event_rate, events_to_frames,
                                       fixed_duration_boundaries)
from evinr_lite.method.denoise import denoise, hot_threshold
from evinr_lite.method.ensemble import split_windows
from evinr_lite.method.smoothing import LAM_MAX, LAM_MIN, LAM_SCALE, auto_lam, covered_fraction, window_fraction
from evinr_lite.method.tonemap import anchor_level, anchor_mean, display_shift, tonemap_linear, tonemap_reinhard
from evinr_lite.core.frames import Frames
from evinr_lite.sim import (LightingScene, MovingBarScene, MovingImageScene, ObjectOverBackgroundScene,
                            OscillatingScene, QuadBayerScene, VaryingSpeedScene, WarpedImageScene, add_background_noise,
                            add_hot_pixels, add_light_noise, colour_davis_recording, make_scene, simulate_colour_video,
                            simulate_events_1d, simulate_scene, simulate_video, synthetic_recording,
                            write_example_recording)
from evinr_lite.sim.simulate import pixel_events

SIZE = (8, 10)
BAR = make_scene("bar", sensor_size=SIZE, duration=0.2)
EV = simulate_scene(BAR, C=0.2)
EMPTY = Events.from_arrays(np.zeros(0), np.zeros(0, int), np.zeros(0, int), np.zeros(0, int), SIZE)
T5 = np.linspace(0.0, 1.0, 5)
LV = np.log(np.random.default_rng(0).uniform(0.1, 1.0, (5, 4, 6)))          # log frames [T, H, W]
Q = np.array([0.05, 0.1, 0.15])
B = np.linspace(0.0, 0.2, 5)
IMG = np.random.default_rng(1).uniform(0.0, 1.0, (16, 16))
RGB = np.random.default_rng(2).uniform(0.1, 1.0, (4, 8, 8, 3))
T4 = np.linspace(0.0, 0.1, 4)


from refusals import all_refused as _none_of, refused as _no   # noqa: E402  (shared by rounds 11-14)


def _same(a: Events, b: Events) -> bool:
    return len(a) == len(b) and all(np.array_equal(getattr(a, k), getattr(b, k)) for k in "txyp")


NOISE = {"background": lambda ev, **kw: add_background_noise(ev, 10.0, **kw),
         "hot": lambda ev, **kw: add_hot_pixels(ev, 2, 50.0, **kw)[0],
         "light": lambda ev, **kw: add_light_noise(ev, BAR, 1.0, **kw)}


# ---- 1. the simulator's noise: seeds, rates, spans, events --------------------------------------------------------

@pytest.mark.parametrize("fn", ["background", "hot", "light"])
def test_sim_noise_refuses_an_unseeded_or_bad_seed(fn):
    """Before: background and hot-pixel noise drew unseeded for None (other events each call), and numpy refused -1
    ("expected non-negative integer") and "a" (SeedSequence's TypeError). add_light_noise already refused them."""
    _none_of([lambda s=s: NOISE[fn](EV, seed=s) for s in (None, -1, "a")],
             r"seed must be a whole number >= 0 or a np\.random\.Generator")


def test_sim_noise_is_repeatable_and_takes_a_generator():
    for fn in NOISE:
        assert _same(NOISE[fn](EV, seed=3), NOISE[fn](EV, seed=3)) and not _same(NOISE[fn](EV, seed=3),
                                                                                 NOISE[fn](EV, seed=4))
        assert _same(NOISE[fn](EV, seed=np.random.default_rng(3)), NOISE[fn](EV, seed=3))


def test_sim_noise_rates_as_text_are_refused_and_0d_rates_taken():
    _no(lambda: add_background_noise(EV, "10"), r"rate_hz must be a finite number >= 0")
    _no(lambda: add_hot_pixels(EV, 2, "10"), r"rate_hz must be a finite number >= 0")
    _no(lambda: add_light_noise(EV, BAR, 1.0, max_gain="3"), r"max_gain must be a number >= 1")
    a = add_background_noise(EV, 10.0, seed=1)
    assert _same(add_background_noise(EV, np.array(10.0), seed=1), a)
    assert _same(add_background_noise(EV, torch.tensor(10.0), seed=1), a)


@pytest.mark.parametrize("span,pattern", [((None, np.inf), r"t_end= must be a finite number"),
                                          ((np.nan, None), r"t_start= must be a finite number"),
                                          (("0", None), r"t_start= must be a finite number"),
                                          ((1.0, 0.0), r"noise span \[1\.0, 0\.0\] s is empty")])
def test_sim_noise_refuses_a_bad_span(span, pattern):
    """Before: an infinite end was numpy's "lam value too large", hot pixels over a reversed or NaN span numpy's
    "lam < 0 or lam is NaN", and a start given as text was read as a number."""
    _none_of([lambda fn=fn: NOISE[fn](EV, t_start=span[0], t_end=span[1]) for fn in NOISE], pattern)


@pytest.mark.parametrize("fn", ["background", "hot", "light"])
def test_sim_noise_on_no_events_needs_a_span(fn):
    """Before: numpy's IndexError (events.t[0] of no events)."""
    _no(lambda: NOISE[fn](EMPTY), r"no events.*t_start= and t_end=")
    assert len(NOISE[fn](EMPTY, t_start=0.0, t_end=1.0)) > 0


@pytest.mark.parametrize("fn", ["background", "hot", "light"])
def test_sim_noise_refuses_what_is_not_events(fn):
    _none_of([lambda: NOISE[fn]((EV.t, EV.p)), lambda: NOISE[fn](None)], r"events= must be Events")


def test_sim_noise_refuses_a_rate_that_adds_more_events_than_memory_holds():
    _no(lambda: add_background_noise(EV, 1e15), r"would add about .* events")
    _no(lambda: add_hot_pixels(EV, 2, 1e18), r"would add about .* events")
    _no(lambda: add_light_noise(EV, BAR, 1e15), r"would add about .* events")


def test_sim_hot_pixels_count_must_be_whole():
    """Before: 2.5 and "2" were taken as 2, NaN was Python's "cannot convert float NaN to integer"."""
    _none_of([lambda n=n: add_hot_pixels(EV, n, 10.0) for n in (2.5, "2", np.nan)],
             r"n_pixels= must be a whole number in \[0, 80\]")


def test_sim_hot_pixels_whole_counts_as_before():
    assert add_hot_pixels(EV, 2.0, 10.0, seed=1)[1].tolist() == add_hot_pixels(EV, 2, 10.0, seed=1)[1].tolist()
    out, hot = add_hot_pixels(EV, 0, 10.0)
    assert hot.size == 0 and _same(out, EV)
    _no(lambda: add_hot_pixels(EV, 81, 1.0), r"n_pixels")


def test_sim_light_noise_refuses_no_scene():
    _no(lambda: add_light_noise(EV, None, 1.0), r"scene= must be a Scene")


def test_sim_light_noise_refuses_a_frame_rate_that_is_no_rate():
    """Before: 0 and -5 were taken (two frames), NaN was Python's "cannot convert float NaN to integer"."""
    _none_of([lambda r=r: add_light_noise(EV, BAR, 1.0, n_frames_per_s=r) for r in (0, -5, np.nan)],
             r"n_frames_per_s= must be a finite number > 0")


# ---- 2. the simulators: complex input, refine, pixel_events ----------------------------------------------------------

def test_sim_complex_samples_or_times_are_refused_in_1d():
    """Before: numpy's ComplexWarning, and the events of the real part."""
    s = np.sin(5 * T5)
    _none_of([lambda: simulate_events_1d(s.astype(complex), T5), lambda: simulate_events_1d(s, T5.astype(complex))],
             r"complex")


def test_sim_complex_times_or_colour_frames_are_refused_in_video():
    _none_of([lambda: simulate_video(LV, T5.astype(complex)), lambda: simulate_colour_video(RGB.astype(complex), T4)],
             r"complex")


def test_sim_refine_must_be_true_or_false():
    _no(lambda: simulate_events_1d(np.sin, T5, refine="no"), r"refine must be True or False")
    assert len(simulate_events_1d(lambda s: np.sin(5 * s), T5, refine=False)) > 0


def test_sim_video_guards_float16_int8_list_tensor_and_one_pixel():
    n = len(simulate_video(LV, T5))
    assert len(simulate_video(LV.tolist(), list(T5))) == n == len(simulate_video(torch.tensor(LV), torch.tensor(T5)))
    assert len(simulate_video(LV.astype(np.float16), T5)) > 0 and len(simulate_video(LV.astype(np.int8), T5)) >= 0
    assert simulate_video(LV[:, :1, :1], T5).sensor_size == (1, 1)
    _no(lambda: simulate_video(LV[:1], T5[:1]), r"at least 2 times")
    _no(lambda: simulate_video(LV > -1, T5), r"got dtype bool")


EV1D = simulate_events_1d(np.stack([np.sin(5 * T5), np.cos(5 * T5)], 1), T5)


def test_sim_pixel_events_refuses_a_pixel_that_is_no_index():
    """Before: pixel 1.5 gave no events without a word, "0" was Python's TypeError."""
    _none_of([lambda: pixel_events(EV1D, 1.5), lambda: pixel_events(EV1D, "0")], r"pixel= must be a whole number")


def test_sim_pixel_events_refuses_a_pair_of_text_or_nan_times():
    _no(lambda: pixel_events((["a"], ["b"])), r"events: t and p must be numbers")
    _no(lambda: pixel_events(([np.nan, 0.1], [1, -1])), r"events: t\[0\] is nan")


def test_sim_pixel_events_refuses_a_pixel_of_a_pair():
    """Before: the pixel was ignored (a (t, p) pair is one pixel already)."""
    _no(lambda: pixel_events(([0.1], [1]), 3), r"pixel=3 picks a pixel of an Events")


def test_sim_pixel_events_guards():
    t, p = pixel_events(EV1D, np.int64(1))
    assert t.size and np.array_equal(t, EV1D.t[EV1D.x == 1])
    assert pixel_events(([], []))[0].size == 0 and pixel_events(([0.1], [1]), 0)[0].tolist() == [0.1]


# ---- 3. the scenes ------------------------------------------------------------------------------------------------

def test_scene_bar_refuses_non_finite_geometry():
    """Before: a NaN angle or an infinite width or edge blamed "speed must be finite px/s, got None" (not given), a
    NaN start gave NaN log intensity."""
    for kw, pattern in [(dict(angle=np.nan), r"angle= must be a finite number"),
                        (dict(width=np.inf), r"width= must be a finite number > 0"),
                        (dict(edge=np.inf), r"edge= must be a finite number > 0"),
                        (dict(start=np.nan), r"start= must be a finite number")]:
        _no(lambda: MovingBarScene(SIZE, **kw), pattern)


def test_scene_bar_refuses_intensities_that_are_no_pair_of_positive_numbers():
    """Before: NaN or inf gave NaN or inf log intensity, one number "'float' object is not iterable"."""
    _none_of([lambda i=i: MovingBarScene(SIZE, intensities=i) for i in ((np.nan, 0.9), (0.1, np.inf), 0.5)],
             r"intensities must be \(background, bar\)")


def test_scene_image_refuses_one_number_for_a_pair():
    _no(lambda: MovingImageScene("camera", SIZE, velocity=5), r"velocity must be \(vx, vy\)")
    _no(lambda: MovingImageScene("camera", SIZE, intensity_range=0.5), r"intensity_range must be \(low, high\)")


def test_scene_image_refuses_text_for_numbers():
    _no(lambda: MovingImageScene("camera", SIZE, blur="1"), r"blur= must be a finite number >= 0")
    _no(lambda: MovingImageScene("camera", SIZE, rotation="x"), r"rotation= must be a finite number")


def test_scene_image_refuses_a_complex_image():
    _no(lambda: MovingImageScene(IMG.astype(complex), SIZE), r"complex")


def test_scene_image_takes_uint8_bool_list_and_tensor_images():
    ref = MovingImageScene(IMG, SIZE).log_intensity(0.1)
    assert np.allclose(MovingImageScene(IMG.tolist(), SIZE).log_intensity(0.1), ref)
    assert np.allclose(MovingImageScene(torch.tensor(IMG), SIZE).log_intensity(0.1), ref)
    for img in ((IMG * 255).astype(np.uint8), IMG > 0.5):
        assert np.isfinite(MovingImageScene(img, SIZE).log_intensity(0.1)).all()
    assert np.isfinite(make_scene("camera", sensor_size=(1, 1)).log_intensity(0.1)).all()


def test_scene_oscillating_refuses_short_tuples():
    _no(lambda: OscillatingScene("camera", SIZE, path=(1.0, 2.0, 3.0)), r"path must be \(\(ax, ay, period")
    _no(lambda: OscillatingScene("camera", SIZE, rotation=(0.1,)), r"rotation must be \(amplitude rad, period s")


def test_scene_wrappers_refuse_no_base():
    _none_of([lambda: VaryingSpeedScene(None), lambda: LightingScene(None), lambda: LightingScene("camera")],
             r"base= must be a Scene.*make_scene")


def test_scene_wrappers_refuse_odd_numbers():
    """Before: an infinite period gave NaN frames, a period or depth as text Python's TypeError."""
    _no(lambda: VaryingSpeedScene(BAR, period=np.inf), r"period= must be a finite number > 0")
    _no(lambda: VaryingSpeedScene(BAR, period="2"), r"period= must be a finite number > 0")
    _no(lambda: VaryingSpeedScene(BAR, depth="0.5"), r"depth= must be a finite number in \[0, 1\)")


def test_scene_wrappers_take_a_quad_bayer_scene_as_base():
    qb = QuadBayerScene(sensor_size=(8, 8), duration=0.2)
    assert VaryingSpeedScene(qb).log_intensity(0.1).shape == (8, 8)


def test_scene_object_refuses_odd_start():
    _none_of([lambda s=s: ObjectOverBackgroundScene(sensor_size=(16, 16), start=s) for s in ((1.0, 2.0, 3.0),
                                                                                             (np.nan, 2.0))],
             r"start and end must be \(x, y\)")


def test_scene_warped_refuses_one_number_as_shear():
    _no(lambda: WarpedImageScene(sensor_size=(16, 16), shear=0.1), r"shear and tilt must be \(x, y\) pairs")


def test_scene_log_intensity_refuses_times_that_are_no_seconds():
    """Before: "0.1" was read as 0.1 s, a complex time was Python's float() error."""
    _none_of([lambda t=t: BAR.log_intensity(t) for t in ("0.1", 0.1 + 1j, [0.1, None])], r"t must be seconds")
    assert np.array_equal(BAR.log_intensity(torch.tensor(0.1, dtype=torch.float64)), BAR.log_intensity(0.1))


# ---- 4. Quad Bayer, colour and recordings on disk ---------------------------------------------------------------

@pytest.mark.parametrize("kw,pattern", [(dict(intensity_range=0.5), r"intensity_range must be \(low, high\)"),
                                        (dict(image=RGB[0].astype(complex)), r"complex"),
                                        (dict(speed=3), r"unknown parameter\(s\) \['speed'\].*velocity")])
def test_quadbayer_scene_refuses_odd_arguments(kw, pattern):
    _no(lambda: QuadBayerScene(sensor_size=(8, 8), **kw), pattern, (ValueError, TypeError))


def test_quadbayer_colour_video_names_its_own_argument_for_nan_and_inf():
    """Before: inf was "log_frames contain NaN or inf" (not its argument), NaN "must be positive intensities"."""
    _no(lambda: simulate_colour_video(np.where(RGB > 0.9, np.inf, RGB), T4), r"rgb_frames contain .* inf")
    _no(lambda: simulate_colour_video(np.where(RGB > 0.9, np.nan, RGB), T4), r"rgb_frames contain .* NaN")


def test_quadbayer_colour_video_refuses_text():
    _no(lambda: simulate_colour_video("abc", T4), r"rgb_frames must be numbers")


def test_quadbayer_colour_video_takes_uint8_lists_and_odd_sizes():
    assert len(simulate_colour_video((RGB * 255).astype(np.uint8), T4)) > 0
    assert len(simulate_colour_video(RGB.tolist(), T4)) == len(simulate_colour_video(RGB, T4))
    assert simulate_colour_video(RGB[:, :7, :5], T4).sensor_size == (7, 5)


def test_recording_example_refuses_a_bad_frame_rate_and_leaves_nothing(tmp_path):
    """Before: 0 was a ZeroDivisionError, -1 a recording without frames (readers then refuse it), NaN numpy's
    "arange: cannot compute length"."""
    _none_of([lambda r=r: write_example_recording(tmp_path / "r", sensor_size=SIZE, duration=0.1, frame_rate=r)
              for r in (0, -1, np.nan)], r"frame_rate= must be a finite number > 0")
    assert not list(tmp_path.iterdir())


def test_recording_synthetic_needs_two_frames_or_more():
    """Before: 1 was a ZeroDivisionError, 0 a complaint about a temporary images.txt, 2.5 two frames."""
    _none_of([lambda n=n: synthetic_recording(SIZE, 0.1, n_frames=n) for n in (1, 0, 2.5)],
             r"n_frames= must be a whole number >= 2")


def test_recording_synthetic_guard_two_frames():
    rec = synthetic_recording(SIZE, 0.1, n_frames=2)
    assert len(rec.frames) == 2 and rec.frames.t[-1] == pytest.approx(0.1)


def test_recording_colour_davis_frame_rate_as_text():
    _no(lambda: colour_davis_recording(sensor_size=(8, 8), duration=0.1, frame_rate="20"),
        r"frame_rate= must be a finite number > 0")


# ---- 5. the baselines --------------------------------------------------------------------------------------------

BASE = [leaky_integration, highpass_filter]


@pytest.mark.parametrize("fn", BASE, ids=["leaky", "hf"])
def test_baseline_refuses_what_is_not_events(fn):
    _none_of([lambda: fn((EV.t, EV.p), Q), lambda: fn(None, Q)], r"events= must be Events")


@pytest.mark.parametrize("L0", [np.nan, "a", 1j, np.full(SIZE, np.inf)], ids=["nan", "text", "complex", "inf"])
def test_baseline_refuses_an_L0_that_is_no_finite_log_intensity(L0):
    _none_of([lambda fn=fn: fn(EV, Q, L0=L0) for fn in BASE], r"L0 must be")


@pytest.mark.parametrize("t_start", [np.nan, "0", -np.inf])
def test_baseline_refuses_a_t_start_that_is_no_finite_time(t_start):
    """Before: NaN gave NaN frames, "0" was read as a number, -inf was used."""
    _none_of([lambda fn=fn: fn(EV, Q, t_start=t_start) for fn in BASE], r"t_start= must be a finite number")


def test_baseline_rates_take_0d_arrays_and_tensors_as_C_does():
    ref = leaky_integration(EV, Q, leak_hz=1.0)
    assert np.array_equal(leaky_integration(EV, Q, leak_hz=np.array(1.0)), ref)
    assert np.array_equal(highpass_filter(EV, Q, cutoff_hz=torch.tensor(1.0)), highpass_filter(EV, Q, cutoff_hz=1.0))
    _no(lambda: leaky_integration(EV, Q, leak_hz="1"), r"leak_hz must be a finite number >= 0")


def test_baseline_complementary_names_a_nan_t_start():
    frames = Frames(np.full((2, *SIZE), 0.5), np.array([0.0, 0.1]))
    _no(lambda: complementary_filter(EV, frames, Q, t_start=np.nan), r"t_start= must be a finite number")


def test_baseline_guards_no_events_and_the_existing_refusals():
    assert leaky_integration(EMPTY, Q).shape == (3, *SIZE) and np.all(highpass_filter(EMPTY, Q) == 0)
    assert np.isfinite(reconstruct_baseline(EMPTY, Q).frames).all()
    _no(lambda: leaky_integration(EV, Q, L0=np.zeros((3, 3))), r"L0 must be a scalar or an \[H, W\]")
    _no(lambda: highpass_filter(EV, Q, method="fast"), r"vectorised")


# ---- 6. binning -------------------------------------------------------------------------------------------------

def test_binning_fixed_duration_refuses_text_and_none():
    _none_of([lambda: fixed_duration_boundaries("0", 1, 0.1), lambda: fixed_duration_boundaries(None, 1, 0.1)],
             r"t_start= must be a finite number")
    _no(lambda: fixed_duration_boundaries(0, 1, "0.1"), r"bin_duration= must be a finite number > 0")


def test_binning_fixed_duration_takes_0d_tensors():
    assert np.array_equal(fixed_duration_boundaries(torch.tensor(0.0), torch.tensor(1.0), np.array(0.5)),
                          [0.0, 0.5, 1.0])


def test_binning_equal_count_refuses_no_events():
    _no(lambda: equal_count_boundaries(None, n_bins=3), r"events= must be Events")


def test_binning_equal_count_refuses_odd_counts():
    _no(lambda: equal_count_boundaries(EV, events_per_bin=np.nan), r"events_per_bin= must be a finite number >= 1")
    _none_of([lambda n=n: equal_count_boundaries(EV, n_bins=n) for n in (2.5, "3")], r"n_bins= must be a whole number")


def test_binning_events_to_frames_refuses_what_is_not_events():
    _none_of([lambda: events_to_frames(None, B), lambda: events_to_frames((EV.t, EV.p), B)], r"events= must be Events")


def test_binning_events_to_frames_refuses_text_boundaries():
    _no(lambda: events_to_frames(EV, "abc"), r"boundaries must be numbers")


@pytest.mark.parametrize("b,pattern", [([0.0, np.nan, 0.2], r"NaN or inf"), ([0.2, 0.1, 0.0], r"strictly increasing"),
                                       ([0.1], r"at least 2 edges")])
def test_binning_bisect_checks_its_boundaries(b, pattern):
    """Before: NaN edges came back NaN, decreasing ones reversed, one edge was numpy's IndexError."""
    _no(lambda: bisect_boundaries(EV, b), pattern)


def test_binning_event_rate_refuses_a_range_that_is_no_pair():
    """Before: (0, 0.1, 0.2) used (0, 0.1) without a word, (0,) was Python's IndexError."""
    _none_of([lambda r=r: event_rate(EV, 0.05, r) for r in ((0.0,), (0.0, 0.1, 0.2))], r"t_range must be \(t0, t1\)")


def test_binning_event_rate_refuses_no_events():
    _no(lambda: event_rate(None, 0.05), r"events= must be Events")


# ---- 7. the lam rule, the ensemble's windows ---------------------------------------------------------------------

ONES = np.ones((3, 3))


def test_smoothing_auto_lam_refuses_what_is_no_count():
    """Before: NaN and negative counts gave lam = LAM_MAX without a word."""
    _no(lambda: auto_lam(np.full((3, 3), np.nan), ONES), r"n_on must be finite (event )?counts")   # denoise's check
    _no(lambda: auto_lam(-20 * ONES, -20 * ONES), r"n_on must be finite (event )?counts >= 0")


def test_smoothing_auto_lam_refuses_counts_of_two_shapes():
    _no(lambda: auto_lam(ONES, np.ones((2, 2))), r"n_on and n_off .* one shape")


def test_smoothing_auto_lam_refuses_a_fraction_that_is_no_share():
    """Before: NaN, 0 and -1 gave LAM_MAX, 2 a lam for twice the activity, without a word."""
    _none_of([lambda f=f: auto_lam(20 * ONES, 20 * ONES, f) for f in (np.nan, 0.0, -1.0, 2.0)],
             r"fraction= must be a finite number in \(0, 1\]")


def test_smoothing_auto_lam_guard_values():
    assert auto_lam(20 * ONES, 20 * ONES) == LAM_MIN and auto_lam(ONES, 0 * ONES) == LAM_MAX
    assert auto_lam(3 * ONES, 3 * ONES, 0.5) == pytest.approx(min(LAM_MAX, max(LAM_MIN, LAM_SCALE / 9.0)))
    assert auto_lam(np.zeros((0, 0)), np.zeros((0, 0))) == LAM_MAX


def test_smoothing_covered_fraction_refuses_what_is_no_windows():
    _none_of([lambda: covered_fraction([]), lambda: covered_fraction([0.0, 1.0])], r"windows must be \[N, 2\]")


def test_smoothing_window_fraction_refuses_a_nan_span():
    _no(lambda: window_fraction(np.nan, 1.0, 0.5, 0.1), r"t_start= must be a finite number")


def test_ensemble_split_windows_refuses_tau_at_most_the_overlap():
    """Before: a ZeroDivisionError for both."""
    _no(lambda: split_windows(0, 1, 0.1, 0.1), r"tau .* must exceed the overlap")
    _no(lambda: split_windows(0, 1, 0, 0), r"tau= must be a finite number > 0")


def test_ensemble_split_windows_refuses_nan_tau_or_overlap():
    _no(lambda: split_windows(0, 1, np.nan, 0.1), r"tau= must be a finite number > 0")
    _no(lambda: split_windows(0, 1, 0.3, np.nan), r"overlap= must be a finite number >= 0")


def test_ensemble_split_windows_refuses_a_negative_overlap():
    """Before: windows with gaps between them, where no network is trained."""
    _no(lambda: split_windows(0, 1, 0.3, -0.1), r"overlap= must be a finite number >= 0")


def test_ensemble_split_windows_refuses_text_and_an_endless_span():
    _no(lambda: split_windows(0, 1, "0.3", 0.1), r"tau= must be a finite number > 0")
    _no(lambda: split_windows(0, np.inf, 0.3, 0.1), r"t_end= must be a finite number")


def test_ensemble_split_windows_guards():
    w = split_windows(torch.tensor(0.0), torch.tensor(1.0), 0.3, 0.1)
    assert np.array_equal(w, split_windows(0.0, 1.0, 0.3, 0.1)) and w.shape == (5, 2)
    assert split_windows(0.0, 1.0, None, 0.1).tolist() == [[0.0, 1.0]]
    assert split_windows(0.0, 1.0, 2.0, 0.1).tolist() == [[0.0, 1.0]]
    _no(lambda: split_windows(0, 1, 0.15, 0.1), r"overlap three at a time")
    _no(lambda: split_windows(1, 1, 0.3, 0.1), r"is empty")


# ---- 8. the tone maps and the level ------------------------------------------------------------------------------

def test_tonemap_linear_refuses_nan_and_text():
    """Before: NaN frames, and numpy's "could not convert string to float"."""
    _no(lambda: tonemap_linear(np.array([0.0, np.nan])), r"L contains 1 NaN")
    _no(lambda: tonemap_linear("a"), r"L must be log intensities \(numbers\)")


def test_tonemap_reinhard_refuses_a_nan_tensor_as_it_does_a_nan_array():
    _no(lambda: tonemap_reinhard(torch.tensor([0.0, float("nan")])), r"L contains 1 NaN")


def test_tonemap_display_shift_refuses_nan_or_no_log_intensity_with_reinhard():
    """Before: NaN came back as the shift, no values numpy's "Mean of empty slice" and NaN."""
    _none_of([lambda: display_shift(np.array([0.0, np.nan]), "reinhard"),
              lambda: display_shift(np.zeros(0), "reinhard")],
             r"finite log intensities")


def test_tonemap_display_mean_as_text():
    _no(lambda: display_shift(np.zeros(3), display_mean="0.4"), r"display_mean= must be a finite number in \(0, 1\)")


def test_tonemap_gamma_that_is_no_exponent():
    """Before: gamma 0 was a ZeroDivisionError, -1 "math domain error", NaN gave NaN."""
    _none_of([lambda: display_shift(np.zeros(3), "reinhard", gamma=0),
              lambda: display_shift(np.zeros(3), "reinhard", gamma=-1), lambda: anchor_level(0),
              lambda: anchor_level(np.nan)], r"gamma= must be a finite number > 0")


def test_tonemap_anchor_mean_refuses_text_and_nan():
    _no(lambda: anchor_mean("a"), r"L must be log intensities \(numbers\)")
    _no(lambda: anchor_mean(np.array([0.0, np.nan])), r"L contains 1 NaN")


def test_tonemap_guards_infinities_and_tensors():
    assert tonemap_linear(np.array([np.inf, -np.inf])).tolist() == [1.0, 0.0]
    assert tonemap_reinhard(np.array([np.inf, -np.inf])).tolist() == [1.0, 0.0]
    t = torch.zeros(3, requires_grad=True)
    assert torch.allclose(tonemap_reinhard(t, 0.6), torch.full((3,), 0.5 ** 0.6))
    assert anchor_level(0.6, 0.5) == pytest.approx(math.log(0.5 ** (1 / 0.6) / (1 - 0.5 ** (1 / 0.6))))


# ---- 9. the denoiser --------------------------------------------------------------------------------------------

def test_denoise_switches_must_be_true_or_false():
    """Before: "no" (truthy) ran the stage, and the report said hot_pixels=True."""
    _none_of([lambda kw=kw: denoise(EV, **kw) for kw in (dict(hot_pixels="no"), dict(background="yes"),
                                                          dict(same_polarity=1))], r"must be True or False")


def test_denoise_hot_threshold_refuses_nan_and_negative_counts():
    _no(lambda: hot_threshold(np.array([[1.0, np.nan], [3, 4]])), r"counts must be finite")
    _no(lambda: hot_threshold(np.array([[-1, 2], [3, 4]])), r"counts must be finite .* >= 0")


def test_denoise_hot_threshold_takes_a_list_and_refuses_text():
    assert hot_threshold([[1, 2], [3, 4]]) == hot_threshold(np.array([[1, 2], [3, 4]]))
    _no(lambda: hot_threshold("abc"), r"counts must be")


def test_denoise_guards_no_events_and_switches():
    assert len(denoise(EMPTY)[0]) == 0
    kept, report = denoise(EV, hot_pixels=False, background=np.bool_(False))
    assert len(kept) == len(EV) and report.settings["hot_pixels"] is False


# ---- 10. enhancement: rendered and counted events ------------------------------------------------------------------

LB = np.log(np.random.default_rng(3).uniform(0.1, 1.0, (5, 4, 6)))


def test_enhance_render_refuses_a_threshold_that_is_no_step():
    """Before: C 0 or NaN gave garbage counts (inf or NaN cast to int64), -0.2 counts of the wrong sign, "0.2"
    numpy's ufunc error."""
    _none_of([lambda c=c: render_event_counts(LB, c) for c in (0, -0.2, np.nan, "0.2")],
             r"C= must be a finite number > 0")


def test_enhance_render_refuses_nan_complex_or_no_log_intensities():
    """Before: NaN became garbage counts, complex the counts of the real part, none numpy's IndexError."""
    _no(lambda: render_event_counts(np.where(LB > -1, np.nan, LB), 0.2), r"L_boundaries contain .* NaN")
    _no(lambda: render_event_counts(LB.astype(complex), 0.2), r"L_boundaries must be numbers")
    _no(lambda: render_event_counts(LB[:0], 0.2), r"at least one boundary")


def test_enhance_render_guards():
    assert render_event_counts(LB[:1], 0.2).shape == (0, 4, 6)
    assert render_event_counts(np.array([0.0, 0.5, 1.0]), 0.2).tolist() == [2, 2]


def test_enhance_event_counts_refuses_non_finite_boundaries():
    """Before: counted as if the NaN or inf edge were not there."""
    _none_of([lambda b=b: event_counts(EV, b) for b in ([0.0, np.nan, 0.2], [0.0, 0.1, np.inf])], r"NaN or inf")


def test_enhance_event_counts_refuses_no_events():
    _no(lambda: event_counts(None, B), r"events= must be Events")


def test_enhance_model_counts_need_a_reconstruction():
    _no(lambda: model_event_counts(None, B, 0.2), r"rec must be a reconstruction .*\.at\(times\)")


CNT = event_counts(EV, B)


def test_enhance_count_scores_refuse_what_is_no_count():
    """Before: NaN, 0.5 and negative counts were cast to int64 and scored."""
    _none_of([lambda a=a: count_scores(a, CNT) for a in (np.full(CNT.shape, np.nan), CNT + 0.5, -CNT)],
             r"counts must be whole numbers >= 0")


def test_enhance_count_scores_refuse_a_threshold_that_is_no_step():
    _none_of([lambda c=c: count_scores(CNT, CNT, c) for c in (np.nan, "1")], r"C= must be a finite number > 0")


def test_enhance_count_scores_guard_whole_floats():
    assert count_scores(CNT.astype(float), CNT)["f1"] == 1.0
    _no(lambda: count_scores(CNT[0], CNT[0]), r"\[2, B, H, W\]")


# ---- 11. ablation helpers ---------------------------------------------------------------------------------------

def test_ablation_integration_baseline_checks_C_when_made():
    """Before: "Unknown format code 'g' for object of type 'str'"."""
    _no(lambda: integration_baseline("0.2"), r"C must be a positive number")


def test_ablation_integration_baseline_checks_gamma_when_made():
    """Before: a ZeroDivisionError (0) or "math domain error" (-1) when called."""
    _none_of([lambda g=g: integration_baseline(0.2, g) for g in (0, -1)], r"gamma= must be a finite number > 0")


def test_ablation_integration_baseline_takes_a_pair_of_thresholds():
    fn = integration_baseline((0.22, 0.18))
    assert "0.22" in fn.__name__ and fn(EV, Q).shape == (3, *SIZE)


def test_ablation_tau_for_networks_refuses_a_count_that_is_no_count():
    _none_of([lambda n=n: tau_for_networks(n, 1.0, 0.1) for n in (2.5, "2")],
             r"n_networks= must be a whole number >= 1")


def test_ablation_tau_for_networks_refuses_odd_spans():
    _no(lambda: tau_for_networks(2, np.nan, 0.1), r"duration= must be a finite number > 0")
    _no(lambda: tau_for_networks(2, 1.0, -0.1), r"overlap= must be a finite number >= 0")


def test_ablation_pareto_front_refuses_nan():
    """Before: a NaN variant was on the front (nothing dominates NaN)."""
    _no(lambda: pareto_front([1, np.nan, 3], [0.5, 0.9, 0.7]), r"cost\[1\] is nan")


def test_ablation_pareto_front_refuses_odd_shapes():
    _no(lambda: pareto_front([1, 2, 3], [0.5, 0.9]), r"3 costs but 2 qualities")
    _no(lambda: pareto_front([[1, 2]], [[0.5, 0.9]]), r"1-D")


def test_ablation_pareto_front_guards():
    assert pareto_front([], []).tolist() == []
    assert pareto_front([1, 2, 3], [0.5, 0.9, 0.7]).tolist() == [True, True, False]


def test_ablation_relative_change_refuses_zero_and_nan():
    _no(lambda: relative_change(1.0, 0.0, True), r"baseline is 0")
    _no(lambda: relative_change(np.nan, 1.0, True), r"value= must")


def test_ablation_table_refuses_a_name_for_columns_and_a_row_for_rows():
    row = {"name": "a", "mse_none": 0.1, "ssim_none": 0.5}
    _no(lambda: ablation_table([row], columns="mse_none"), r"columns must be a list")
    _no(lambda: ablation_table(row), r"rows must be a list of dicts")


GT = np.random.default_rng(4).uniform(0.1, 0.9, (2, 12, 12))
GTT = np.array([0.05, 0.15])
EV12 = simulate_scene(make_scene("bar", sensor_size=(12, 12), duration=0.2), C=0.2)
VAR = {"int": integration_baseline(0.2)}


def test_ablation_run_variants_refuses_counts_that_are_no_counts():
    _none_of([lambda: run_variants(EV12, GT, GTT, VAR, repeats=1.5),
              lambda: run_variants(EV12, GT, GTT, VAR, repeats="2")],
             r"repeats= must be a whole number >= 1")
    _no(lambda: run_variants(EV12, GT, GTT, VAR, n_inference=0), r"n_inference= must be a whole number >= 1")


def test_ablation_run_variants_refuses_what_is_not_events():
    _no(lambda: run_variants((EV12.t, EV12.p), GT, GTT, VAR), r"events= must be Events")


def test_ablation_run_variants_refuses_a_list_of_variants():
    _no(lambda: run_variants(EV12, GT, GTT, [integration_baseline(0.2)]), r"variants must be a dict")


def test_ablation_run_variants_names_uint16_truth():
    """Before: uint16 truth was cast to float and called 0..255 ("divide by 255, or pass uint8")."""
    _no(lambda: run_variants(EV12, (GT * 65535).astype(np.uint16), GTT, VAR), r"uint16 .* 65535")


def test_ablation_run_variants_takes_one_equalization_by_name():
    """Before: "clahe" was scored letter by letter ("equalization must be one of ..., got 'c'")."""
    row = run_variants(EV12, GT, GTT, VAR, equalizations="clahe")[0]
    assert "ssim_clahe" in row and "ssim_none" not in row
    assert row["ssim_clahe"] == run_variants(EV12, GT, GTT, VAR, equalizations=("clahe",))[0]["ssim_clahe"]


# ---- from the review of this round ----------------------------------------------------------------

@pytest.mark.parametrize("duration", [-1, 0, math.nan])
def test_synthetic_recording_names_its_duration(duration):
    """After the frame_rate check: a bad duration was blamed on a frame_rate the caller never passed (0: a
    ZeroDivisionError)."""
    from evinr_lite.sim import synthetic_recording
    _no(lambda: synthetic_recording((20, 20), duration, n_frames=3), r"duration=")


def test_ablation_table_of_none_says_no_rows():
    """After the row check: None was Python's TypeError ("'NoneType' object is not iterable")."""
    _no(lambda: ablation_table(None, ["ssim_none"]), r"no rows")


@pytest.mark.parametrize("t_range,bin_s,pattern", [((0, math.inf), 0.1, r"t_range\[1\]"), ((0, 1), -1, r"bin_s"),
                                                   ((1, 0), 0.1, r"t_range\[1\]")])
def test_event_rate_names_its_own_arguments(t_range, bin_s, pattern):
    """Before: fixed_duration_boundaries' names (t_end=, bin_duration=) for the caller's t_range and bin_s."""
    _no(lambda: event_rate(EV12, bin_s, t_range), pattern)
