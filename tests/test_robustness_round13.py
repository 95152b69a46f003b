"""Round 13 of the bad-input table (tests/test_robustness*.py): public functions no earlier round called with bad
arguments: the colour filter array (evinr_lite.core.cfa) and Quad Bayer's mosaicing and demosaicing
(evinr_lite.sim.quadbayer), the memory estimate (evinr_lite.method.memory), the named recipes and the printed C
(evinr_lite.method.recipes), the streaming solver's entry (evinr_lite.method.streaming.stream_reconstruct), the
window of a recording source (evinr_lite.io.source), the level match (evinr_lite.evaluation.level) and the
notebooks' controls (evinr_lite.viz.widgets).

Fixes (each test failed before its fix; the two with times of 10^9 s ran for hours before, so they were deselected
in the run before the fixes): ``period`` / ``cfa_tile`` took a block of 9 or 10^9 (a tile of 4 * 10^18 photosites),
and refused a 0-d array or tensor holding 2; a phase of (inf, 0) was Python's OverflowError and one of text was read
as numbers; ``effective_thresholds("0.2")`` was numpy's ufunc error (and a 0-d tensor was refused);
``cfa_channel`` truncated photosite 1.5 and read "1" as 1 without a word, NaN was "cannot convert float NaN", None
Python's TypeError and positions of two lengths numpy's IndexError. ``demosaic_grey`` / ``demosaic_rgb`` /
``demosaic_rgb_full`` / ``mosaic_display`` / ``debayer_bilinear`` / ``checker_amplitude`` of text were numpy's
conversion errors and of NaN gave NaN images; ``mosaic_display`` and ``debayer_bilinear`` of one row or None, and
``debayer_bilinear`` of a stack, blamed a sensor_size nobody passed, and ``checker_amplitude`` of one row or None was
Python's unpack error; a mosaic of no photosite gave an empty result, one of 1 x 1 NaN colours (debayer) and
``checker_amplitude`` of one row NaN; ``mosaic`` kept complex numbers and text without a word; ``reduce_mean`` with a
factor of 0 was a ZeroDivisionError, -2 numpy's reshape error, "2" and 2.0 Python's TypeErrors, 1.5 or NaN blamed
the image, and one row was Python's unpack error. ``estimate_memory`` of sensor_size None was Python's unpack
error, of (10, 10.5), (0, 10) or (-5, 10) an estimate; NaN or infinite times were "cannot convert float NaN" /
OverflowError, times as text were taken and a reversed span estimated as one instant; n_events or n_frames negative,
as text or 2.5 were taken (truncated), NaN gave a NaN estimate or Python's error; config None, a dict or a name an
AttributeError; n_kept -1, NaN or 1.5 an estimate (NaN). ``check_memory`` with a fraction of 0, -1 or NaN refused every
run blaming "the libraries alone", "0.8" was a MemoryError and 1.5 allowed more than is free;
``check_times_memory`` took -1, NaN or 2.5 times and "5" was Python's TypeError. ``recipe_config`` ran n_iters 2.5 as
2, took "90" and True, NaN was Python's error, and a recipe or tonemap given as a list was "unhashable type";
``format_contrast`` of None, "auto", text or one value in a tuple was Python's format or index error, of NaN 'nan'
and of a negative pair its text. ``stream_reconstruct`` took query times [True], and text, ragged or complex
ones were numpy's or Python's errors; a query time or t_end of 10^9 s (ms or us given as seconds) counted events for
hours before any window, a t_start of -1e300 was numpy's "Maximum allowed size exceeded"; t_start NaN blamed "fewer
than 2 events in [nan, ...]", "0" was taken and t_end "a" Python's error; config={} ran the default config,
progress="no" showed the bar, on_state=5 failed after the first window had trained, state=5 was an AttributeError
and workdir=5 Python's TypeError. A source's window (``check_window``, ``RecordingSource.events``) read text ("0")
and True as seconds. ``match_level`` / ``error_parts`` of a ragged list of frames were numpy's error. A slider with
an infinite bound was Python's OverflowError and with an infinite step took default 0; ``interact`` drew a figure
0 inches wide, one of 10^6 inches, and a figsize of 8 or ("8", 4) were Python's or matplotlib's errors.

Left as they are: the ensemble's internals (``blend_weights``, ``predict_networks``, ``alignment_offsets``: the
solver and streaming pass them checked windows and models; readers do not call them), ``reduce_mean`` of NaN
(a generic mean: its demosaicing callers refuse NaN first), ``simulate_colour_video`` on a sensor that is no
multiple of the tile (the mosaic is defined on any sensor; ``demosaic_events`` names the crop), LPIPS (its entry
needs the 233 MB weights this machine lacks; ``lpips_distances`` already refuses mismatched shapes) and the
command's numeric flags (every flag of ``reconstruct`` and ``demo`` given 0, -1, nan, inf, text, 2.5 or 1e12 already
ended with status 2 and one line, or ran where the value is valid).

Guards: odd inputs next to these that already behave and must keep their outcome (np.int64 blocks and phases, a
phase as an array, negative photosites (the tile repeats), whole photosites as floats, float32 C, plain Bayer on
odd sizes, float32 / uint8 / list mosaics, a factor of np.int64(2), np.int64 and float32 sizes and times, an
instant's estimate, spans of an hour, n_frames 10.0, np.int64 / 90.0 / tensor n_iters, a pair of C as an array,
query times as a tensor and a 0-d tensor t_end, 0-d tensor windows, lists of frames, float32 slider bounds,
figsize=None, and the existing refusals next to the new ones).
"""
import numpy as np
import pytest
import torch

from evinr_lite import EvINRConfig, Events
from evinr_lite.core import cfa
from evinr_lite.evaluation import level
from evinr_lite.io.source import as_source, check_window
from evinr_lite.method import memory, recipes
from evinr_lite.method.streaming import stream_reconstruct
from evinr_lite.sim import make_scene, quadbayer as qb, simulate_scene
from evinr_lite.viz import widgets

RNG = np.random.default_rng(0)
RGB = RNG.uniform(0.1, 1.0, (8, 8, 3))
RAW = RNG.uniform(0.1, 1.0, (8, 8))
CFG = EvINRConfig(progress=False)
EV = simulate_scene(make_scene("bar", sensor_size=(8, 10), duration=0.2), C=0.2)
SRC = as_source(EV)
A = RNG.uniform(0.1, 0.9, (2, 8, 8))
B = RNG.uniform(0.1, 0.9, (2, 8, 8))


from refusals import all_refused as _none_of, refused as _no   # noqa: E402  (shared by rounds 11-14)


# ---- 1. the colour filter array ------------------------------------------------------------------------------------

@pytest.mark.parametrize("block", [10**9, 9])
def test_cfa_refuses_a_block_no_sensor_has(block):
    _none_of([lambda: cfa.period(block), lambda: cfa.cfa_tile(block)], r"block must be a whole number in \[1, 8\]")


@pytest.mark.parametrize("phase", [(np.inf, 0), ("1", "0"), (1, "0")])
def test_cfa_refuses_a_phase_that_is_no_offset(phase):
    _none_of([lambda: cfa.cfa_tile(2, phase), lambda: cfa.cfa_channel(0, 0, phase)],
             r"phase must (be \(dy, dx\), two|hold) whole numbers")


def test_effective_thresholds_refuse_a_contrast_given_as_text():
    _no(lambda: cfa.effective_thresholds("0.2"), r"C= must be a finite number > 0")


def test_cfa_keeps_its_earlier_refusals():
    _none_of([lambda: cfa.period(b) for b in (0, -1, "2", np.nan, None, 1.5)], r"block must be")
    _none_of([lambda: cfa.cfa_tile(2, ph) for ph in ((0, "a"), (np.nan, 0), (0.5, 0), (0,), None, 1)],
             r"phase must")
    _none_of([lambda: cfa.effective_thresholds(C) for C in (np.nan, 0.0, -0.2, np.inf, [0.2], None)], r"C=? must be")


@pytest.mark.parametrize("y,x,pattern", [(1.5, 0, r"y= must be whole photosite rows"),
                                         ("1", 0, r"y= must be whole photosite rows"),
                                         (np.nan, 0, r"y= must be whole photosite rows"),
                                         (None, 0, r"y= must be whole photosite rows"),
                                         (0, [0.5, 1], r"x= must be whole photosite columns"),
                                         ([1, 2], [1, 2, 3], r"y= \(shape \(2,\)\) and x= \(shape \(3,\)\)")])
def test_cfa_channel_refuses_positions_that_are_no_photosites(y, x, pattern):
    _no(lambda: cfa.cfa_channel(y, x), pattern)


def test_cfa_as_before():
    assert cfa.cfa_tile(2).tolist() == [[0, 0, 1, 1], [0, 0, 1, 1], [1, 1, 2, 2], [1, 1, 2, 2]]
    assert np.array_equal(cfa.cfa_tile(np.int64(1), (np.int64(0), 1)), cfa.cfa_tile(1, (0, 1)))
    assert np.array_equal(cfa.cfa_tile(2, np.array([1, 1])), cfa.cfa_tile(2, (1, 1)))
    assert cfa.cfa_channel(-1, -1) == cfa.cfa_channel(3, 3)            # the tile repeats beyond the sensor's edge
    assert np.array_equal(cfa.cfa_channel(np.array([2.0, 3.0]), 1), cfa.cfa_channel([2, 3], 1))
    assert cfa.cfa_channel(np.arange(4)[:, None], np.arange(4)).shape == (4, 4)
    assert cfa.effective_thresholds(0.2) == {"R": 0.05, "G": 0.025, "B": 0.05, "grey": 0.0125}
    assert cfa.effective_thresholds(np.float32(0.2))["grey"] == float(np.float32(0.2)) / 16


def test_cfa_takes_whole_numbers_in_any_form():
    """0-d arrays and tensors are the numbers they hold (core.checks.whole_number, real_number), and 2.0 is 2."""
    assert cfa.period(torch.tensor(2)) == cfa.period(np.array(2)) == cfa.period(2.0) == 4
    assert cfa.effective_thresholds(torch.tensor(0.5))["grey"] == pytest.approx(0.5 / 16)


# ---- 2. mosaicing and demosaicing -----------------------------------------------------------------------------------

@pytest.mark.parametrize("fn", [qb.demosaic_grey, qb.demosaic_rgb, qb.demosaic_rgb_full, qb.mosaic_display,
                                qb.debayer_bilinear, qb.checker_amplitude])
@pytest.mark.parametrize("raw,pattern", [(np.full((4, 4), "a"), r"{}= must be numbers"),
                                         (np.full((4, 4), np.nan), r"{}= holds 16 NaN or infinite")])
def test_demosaicing_refuses_a_mosaic_that_is_no_numbers(fn, raw, pattern):
    _no(lambda: fn(raw), pattern.format("images" if fn is qb.checker_amplitude else "raw"))


@pytest.mark.parametrize("fn", [qb.mosaic_display, qb.debayer_bilinear, qb.checker_amplitude])
@pytest.mark.parametrize("raw", [np.ones(4), None])
def test_display_and_checks_of_a_mosaic_name_it_not_a_sensor_size(fn, raw):
    name = "images" if fn is qb.checker_amplitude else "raw"
    _no(lambda: fn(raw), rf"{name}= must be (a mosaic|images) \[(\.\.\., )?H, W\]")


def test_demosaicing_keeps_its_earlier_refusals():
    _none_of([lambda: fn(raw) for fn in (qb.demosaic_grey, qb.demosaic_rgb, qb.demosaic_rgb_full)
              for raw in (np.ones(4), None)], r"raw=? must be a mosaic")
    _no(lambda: qb.demosaic_grey(RAW[:7]), r"multiples of the tile period 4")


def test_demosaicing_refuses_no_photosites_and_too_few():
    _none_of([lambda: qb.demosaic_grey(np.zeros((0, 0))), lambda: qb.demosaic_rgb(np.zeros((2, 0, 4)))],
             r"raw= has no photosite")
    _no(lambda: qb.debayer_bilinear(np.ones((1, 1))), r"at least 2 x 2 photosites")
    _no(lambda: qb.checker_amplitude(np.ones((1, 5))), r"at least 2 x 2")
    _no(lambda: qb.debayer_bilinear(np.ones((2, 4, 4))), r"raw= must be one mosaic \[H, W\], got shape \(2, 4, 4\)")


def test_mosaic_refuses_colours_that_are_no_intensities():
    _no(lambda: qb.mosaic(RGB + 1j), r"rgb= must be numbers")
    _no(lambda: qb.mosaic(np.full((4, 4, 3), "a")), r"rgb= must be numbers")


@pytest.mark.parametrize("factor", [0, -2, "2", np.nan, 1.5, None])
def test_reduce_mean_refuses_a_factor_that_is_no_window(factor):
    _no(lambda: qb.reduce_mean(RAW, factor), r"factor= must be a whole number >= 1")


def test_reduce_mean_takes_a_whole_float_factor():
    assert np.array_equal(qb.reduce_mean(RAW, 2.0), qb.reduce_mean(RAW, 2))   # 2.0 was numpy's error before


def test_demosaicing_an_empty_video_gives_an_empty_video():
    # a stack of no frames [0, H, W] (times that select none) is valid; the round first refused it (review)
    assert qb.demosaic_grey(np.zeros((0, 16, 24))).shape == (0, 4, 6)
    assert qb.demosaic_rgb(np.zeros((0, 16, 24))).shape == (0, 4, 6, 3)
    assert qb.demosaic_rgb_full(np.zeros((0, 16, 24))).shape[0] == 0


def test_reduce_mean_refuses_what_is_no_image():
    _no(lambda: qb.reduce_mean(np.ones(4), 2), r"image= must be an image \[\.\.\., H, W\]")


def test_demosaicing_as_before():
    assert qb.demosaic_grey(RAW).shape == (2, 2) and qb.demosaic_rgb(RAW).shape == (2, 2, 3)
    assert qb.demosaic_grey(RAW)[0, 0] == RAW[:4, :4].mean()
    assert np.array_equal(qb.reduce_mean(RAW, np.int64(2)), qb.reduce_mean(RAW, 2))
    assert qb.checker_amplitude(np.array([[0.0, 1.0], [1.0, 0.0]])) == 0.5
    assert qb.checker_amplitude(np.ones((3, 5))) == 0.0                  # odd sizes: the even part
    assert qb.debayer_bilinear(np.ones((5, 5))).shape == (5, 5, 3)        # plain Bayer needs no multiple of the tile
    assert qb.mosaic(RGB.astype(np.float32)).dtype == np.float32 and qb.mosaic(RGB.tolist()).shape == (8, 8)
    assert qb.demosaic_grey(RAW.astype(np.uint8)).dtype == np.float64
    assert qb.mosaic_display(RAW).shape == (8, 8, 3)


# ---- 3. the memory estimate -----------------------------------------------------------------------------------------

@pytest.mark.parametrize("args,pattern", [
    (((10, 10.5), 0, 1, 1000, 10), r"sensor_size must be \(H, W\)"), ((None, 0, 1, 1000, 10), r"sensor_size"),
    (((0, 10), 0, 1, 1000, 10), r"sensor_size"), (((-5, 10), 0, 1, 1000, 10), r"sensor_size"),
    (((10, 10), np.nan, 1, 1000, 10), r"t_start= must be a finite number"),
    (((10, 10), 0, np.inf, 1000, 10), r"t_end= must be a finite number"),
    (((10, 10), "0", "1", 1000, 10), r"t_start= must be a finite number"),
    (((10, 10), 1, 0, 1000, 10), r"the span \[1.0, 0.0\] s is reversed"),
    (((10, 10), 0, 1, -5, 10), r"n_events= must be a whole number >= 0"),
    (((10, 10), 0, 1, np.nan, 10), r"n_events= must be a whole number >= 0"),
    (((10, 10), 0, 1, "1000", 10), r"n_events= must be a whole number >= 0"),
    (((10, 10), 0, 1, 1000, -3), r"n_frames= must be a whole number >= 0"),
    (((10, 10), 0, 1, 1000, 2.5), r"n_frames= must be a whole number >= 0"),
    (((10, 10), 0, 1, 1000, np.nan), r"n_frames= must be a whole number >= 0"),
    (((10, 10), 0, 1, 1000, "10"), r"n_frames= must be a whole number >= 0")])
def test_estimate_memory_refuses_sizes_that_are_no_run(args, pattern):
    _no(lambda: memory.estimate_memory(*args, CFG), pattern)


@pytest.mark.parametrize("config", [None, {}, "kit"])
def test_estimate_memory_refuses_what_is_no_config(config):
    _no(lambda: memory.estimate_memory((10, 10), 0, 1, 1000, 10, config), r"config= must be EvINRConfig")


def test_estimate_memory_refuses_kept_frames_that_are_no_count():
    _none_of([lambda: memory.estimate_memory((10, 10), 0, 1, 1000, 10, CFG, streaming=True, n_kept=k)
              for k in (-1, np.nan, 1.5)], r"n_kept= must be a whole number >= 0")


@pytest.mark.parametrize("fraction", [0, -1, np.nan, "0.8", 1.5])
def test_check_memory_refuses_a_fraction_that_is_no_share(fraction):
    _no(lambda: memory.check_memory((10, 10), 0, 1, 1000, 10, CFG, fraction=fraction),
        r"fraction= must be a finite number in \(0, 1\]")


@pytest.mark.parametrize("n", [-1, np.nan, "5", 2.5])
def test_check_times_memory_refuses_a_count_that_is_no_count(n):
    _no(lambda: memory.check_times_memory(n, (10, 10), "x"), r"n_times= must be a whole number >= 0")


def test_memory_estimate_as_before():
    est = memory.estimate_memory((10, 10), 0, 1, 1000, 10, CFG)
    assert est["total"] == memory.estimate_memory((np.int64(10), 10), np.float32(0.0), 1, np.int64(1000),
                                                  np.int64(10), CFG)["total"]
    assert memory.estimate_memory((10, 10), 1.0, 1.0, 0, 0, CFG)["n_windows"] == 1      # one instant
    assert memory.estimate_memory((10, 10), 0, 1, 1000, 10.0, CFG)["n_frames"] == 10
    assert memory.estimate_memory((720, 1280), 0.0, 3600.0, 20_000_000, 10, CFG)["total"] > est["total"]
    assert memory.check_memory((10, 10), 0, 1, 1000, 10, CFG, fraction=1)["total"] == est["total"]
    assert memory.check_times_memory(np.int64(5), (10, 10), "x") is None
    _no(lambda: memory.check_memory((10, 10), 0, 1, 1000, 10**12, CFG), r"output frames")


# ---- 4. recipes and the printed C ------------------------------------------------------------------------------------

@pytest.mark.parametrize("n_iters", [2.5, "90", np.nan, True])
def test_recipe_config_refuses_iterations_that_are_no_count(n_iters):
    _none_of([lambda: recipes.recipe_config("kit", n_iters=n_iters), lambda: recipes.recipe_config("paper", n_iters)],
             r"n_iters= must be a whole number >= 0")


def test_recipe_config_refuses_a_list_as_a_name():
    _no(lambda: recipes.recipe_config(["kit"]), r"recipe= must be one of \('kit', 'paper', 'v0_1'\), got \['kit'\]")
    _no(lambda: recipes.recipe_config(tonemap=["linear"]), r"tonemap= must be one of \('linear', 'reinhard'\)")


@pytest.mark.parametrize("C", [None, "auto", "x", (0.1,), np.nan, (0.2, -0.1)])
def test_format_contrast_refuses_what_is_no_threshold(C):
    _no(lambda: recipes.format_contrast(C), r"C must be a positive number or a pair")


def test_recipes_as_before():
    assert recipes.recipe_config("paper", n_iters=90).c2f_iters == (30, 60)
    assert recipes.recipe_config("paper", n_iters=np.int64(90)) == recipes.recipe_config("paper", n_iters=90)
    assert recipes.recipe_config("paper", n_iters=90.0) == recipes.recipe_config("paper", n_iters=90)
    assert recipes.recipe_config("kit", n_iters=torch.tensor(3)).n_iters == 3
    assert recipes.format_contrast(0.2) == "0.2" and recipes.format_contrast(np.float32(0.25)) == "0.25"
    assert recipes.format_contrast((0.22, 0.18)) == "C+ 0.22 / C- 0.18"
    assert recipes.format_contrast(np.array([0.22, 0.18])) == "C+ 0.22 / C- 0.18"


# ---- 5. the streaming solver's entry -------------------------------------------------------------------------------

def _stream(q=(0.05, 0.1), **kw):
    return list(stream_reconstruct(EV, q, kw.pop("config", CFG), **kw))


@pytest.mark.parametrize("q,pattern", [([True], r"query_times= must be seconds"), (["a"], r"query_times= must be sec"),
                                       ([[0.1], [0.05, 0.2]], r"query_times= must be seconds"),
                                       ([0.1 + 1j], r"query_times= must be seconds"),
                                       ([1e9], r"reach \[0.0172689, 1e\+09\] s")])
def test_stream_refuses_query_times_that_are_no_seconds(q, pattern):
    _no(lambda: _stream(q), pattern)


@pytest.mark.parametrize("kw,pattern", [(dict(t_start=np.nan), r"t_start= must be a finite number"),
                                        (dict(t_start="0"), r"t_start= must be a finite number"),
                                        (dict(t_end="a"), r"t_end= must be a finite number"),
                                        (dict(t_start=-1e300), r"reach \[-1e\+300"),
                                        (dict(t_end=1e9), r"reach \[0.0172689, 1e\+09\] s"),
                                        (dict(config={}), r"config= must be EvINRConfig, got dict; pass EvINRConfig"),
                                        (dict(progress="no"), r"progress= must be True, False or None"),
                                        (dict(on_state=5), r"on_state= must be a function on_state\(state\)"),
                                        (dict(state=5), r"state= must be StreamState"),
                                        (dict(workdir=5), r"workdir= must be a folder")])
def test_stream_refuses_settings_before_any_window(kw, pattern):
    _no(lambda: _stream(**kw), pattern)


def test_stream_as_before():
    parts = _stream(np.array([0.05, 0.1]))
    assert sum(len(p.times) for p in parts) == 2
    one = _stream(torch.tensor([0.1], dtype=torch.float64), t_start=np.float64(0.0), t_end=torch.tensor(0.2))
    assert [p.times.tolist() for p in one] == [[0.1]]
    _no(lambda: _stream([0.1, 0.05]), r"sorted")
    _none_of([lambda: _stream(q) for q in ([], [np.nan], np.full((2, 2), 0.1))], r"query_times=? (must|is)")
    _no(lambda: _stream(config=EvINRConfig(anchor="first", progress=False)), r"anchored")


# ---- 6. a source's window, the level match, the notebooks' controls -----------------------------------------------

@pytest.mark.parametrize("w", [("0", "1"), (True, 2), (0, "1")])
def test_a_source_window_must_be_two_numbers(w):
    _none_of([lambda: check_window(*w), lambda: SRC.events(*w)], r"must be two numbers of seconds")


def test_a_source_window_as_before():
    assert check_window(np.int64(0), torch.tensor(1.5)) == (0.0, 1.5)
    assert len(SRC.events(0, 1e300)) == len(EV) and len(SRC.load(np.float32(0.0), None).events) == len(EV)
    _no(lambda: SRC.events(1, 0), r"reversed")


def test_level_refuses_a_ragged_stack():
    _none_of([lambda: level.match_level([np.ones((2, 2)), np.ones((3, 3))], B[:, :2, :2]),
              lambda: level.error_parts(A, [np.ones((8, 8)), np.ones((4, 4))])], r"one size")


def test_level_as_before():
    assert level.match_level(A.tolist(), B)[1] == level.match_level(A, B)[1]
    assert level.error_parts(A, B, np.int64(8))["static_coarse"] == level.error_parts(A, B)["static_coarse"]


@pytest.mark.parametrize("spec", [(0, np.inf, 0.1), (-np.inf, 1, 0.1), (0, 1, np.inf)])
def test_a_slider_refuses_bounds_that_are_not_finite(spec):
    _no(lambda: widgets.parse_controls(a=spec), r"control 'a': a slider's numbers must be finite")


@pytest.mark.parametrize("figsize", [(0, 4), 8, ("8", 4), (1e6, 1e6)])
def test_interact_refuses_a_figure_size_that_is_no_size(figsize):
    _no(lambda: widgets.interact(lambda fig: None, figsize=figsize), r"figsize= must be \(width, height\)")


def test_widgets_as_before():
    c, = widgets.parse_controls(a=(np.float32(0), 1, 0.1))
    assert c.kind == "float" and c.default == 0.5
    assert widgets.parse_controls(a=(0, 10, 1))[0].default == 5
    assert widgets.interact(lambda fig: None, figsize=(np.int64(4), 3.5)).fig.get_size_inches().tolist() == [4, 3.5]
    _no(lambda: widgets.parse_controls(a=(1, 0, 0.1)), r"min must be below max")
    _none_of([lambda: widgets.parse_controls(a=spec) for spec in ((np.nan, 1, 0.1), (0, 1, np.nan), (0, 1, 0.1, np.nan))],
             r"control 'a': ")
    _none_of([lambda: widgets.interact(lambda fig: None, figsize=f) for f in ((-1, 4), (np.nan, 4))],
             r"figsize= must be|figure size must be positive")
    assert widgets.interact(lambda fig: None, figsize=None).fig.get_size_inches().tolist() == [6.4, 4.8]
