"""Round 19 of the bad-input table (tests/test_robustness*.py): enumerated options (text chosen from a few) across the
kit, left open by round 18. They were compared with ``x not in (...)`` / ``x == "..."``, so an array (np.zeros(0),
np.array(["a", "b"])) was numpy's "truth value of an array is ambiguous", a list or a dict against a dict of recipes
Python's "unhashable type", a tensor for ``spatial_order`` taken as 1, and ``offset_grid`` took any value that was not
"none" as a solve. Every such option now goes through one check, ``core.checks.choice``: text matched as text
(``np.str_`` too), whole numbers as whole numbers, never ``==`` across kinds; the message lists the allowed values
and, for an array, list or tensor, the fix (the option itself, as text).

Functions: evaluation (``equalize``, ``protocol_description``, ``resolve_lpips``), method (``EvINRConfig``'s option
fields, ``hot_threshold``, ``hot_pixel_mask``, ``correlation_filter``, ``display_shift``, ``anchor_mean``,
``to_display``, ``display_formula``, ``fit_contrast``, ``fit_contrast_arrays``, ``balance_from_counts``,
``select_anchors``, ``highpass_filter``, ``complementary_filter``, ``reconstruct_baseline``, ``stream_reconstruct``,
``solve_head``, ``head_losses``, ``offset_image``, ``offset_grid``), core (``normalize_polarity``), apps
(``RunOptions``' option fields) and viz (``plot_ablation``'s xscale, ``plot_tradeoff``'s labels).
"""
import numpy as np
import pytest
import torch

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt   # noqa: E402

from evinr_lite import EventDataError, Events, Frames   # noqa: E402
from evinr_lite.apps import RunOptions   # noqa: E402
from evinr_lite.core import normalize_polarity   # noqa: E402
from evinr_lite.core.checks import choice   # noqa: E402
from evinr_lite.evaluation import equalize, protocol_description, resolve_lpips   # noqa: E402
from evinr_lite.method import EvINRConfig   # noqa: E402
from evinr_lite.method import (anchor, balance, baselines, contrast, denoise, fused, head_solve, offset,   # noqa: E402
                               streaming, tonemap)
from evinr_lite.viz import plot_ablation, plot_tradeoff   # noqa: E402

RNG = np.random.default_rng(19)
N = 2000
EV = Events(np.sort(RNG.uniform(0, 1, N)), RNG.integers(0, 16, N), RNG.integers(0, 12, N), RNG.choice([-1, 1], N),
            (12, 16))
IMG = RNG.uniform(0.1, 0.9, (12, 16))
LOG = np.log(RNG.uniform(0.1, 0.9, (3, 12, 16)))
FR = Frames(RNG.uniform(0.1, 0.9, (4, 12, 16)), np.linspace(0, 1, 4))


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


# The values that reached numpy's or Python's errors (or a branch) through `x in (...)`: empty and two-element text
# arrays, a one-element list, a dict and a 0-d tensor.
BAD = [np.zeros(0), np.array(["a", "b"]), ["x"], {"a": 1}, torch.tensor(1)]
BAD_IDS = ["zeros0", "text_array", "list", "dict", "tensor"]


def _stream(v):
    next(iter(streaming.stream_reconstruct(EV, [0.5], offset_from=v)))


CALLS = {
    "equalize": (lambda v: equalize(IMG, method=v), "equalization"),
    "protocol_description": (lambda v: protocol_description(v), "equalization"),
    "EvINRConfig.tonemap": (lambda v: EvINRConfig(tonemap=v), "tonemap"),
    "EvINRConfig.binning": (lambda v: EvINRConfig(binning=v), "binning"),
    "EvINRConfig.temporal_loss": (lambda v: EvINRConfig(temporal_loss=v), "temporal_loss"),
    "EvINRConfig.regularizer": (lambda v: EvINRConfig(regularizer=v), "regularizer"),
    "EvINRConfig.offset_solve": (lambda v: EvINRConfig(offset_solve=v), "offset_solve"),
    "EvINRConfig.balance": (lambda v: EvINRConfig(balance=v), "balance"),
    "EvINRConfig.hot_pixels": (lambda v: EvINRConfig(hot_pixels=v), "hot_pixels"),
    "EvINRConfig.background": (lambda v: EvINRConfig(background=v), "background"),
    "EvINRConfig.camera": (lambda v: EvINRConfig(camera=v), "camera"),
    "EvINRConfig.anchor": (lambda v: EvINRConfig(anchor=v), "anchor"),
    "EvINRConfig.spatial_order": (lambda v: EvINRConfig(spatial_order=v), "spatial_order"),
    "hot_threshold": (lambda v: denoise.hot_threshold(np.arange(10.0), rule=v), "rule"),
    "hot_pixel_mask": (lambda v: denoise.hot_pixel_mask(EV, rule=v), "rule"),
    "correlation_filter": (lambda v: denoise.correlation_filter(EV, window=v), "window"),
    "display_shift": (lambda v: tonemap.display_shift(LOG, v), "tonemap"),
    "anchor_mean": (lambda v: tonemap.anchor_mean(LOG, tonemap=v), "tonemap"),
    "to_display": (lambda v: tonemap.to_display(LOG, v), "tonemap"),
    "display_formula": (lambda v: tonemap.display_formula(v), "tonemap"),
    "fit_contrast.method": (lambda v: contrast.fit_contrast(FR, EV, method=v), "method"),
    "fit_contrast.span": (lambda v: contrast.fit_contrast(FR, EV, span=v), "span"),
    "fit_contrast_arrays": (lambda v: contrast.fit_contrast_arrays(np.ones(5), np.ones(5), np.ones(5), method=v),
                            "method"),
    "balance_from_counts": (lambda v: balance.balance_from_counts(np.ones(5), np.ones(5), 0.2, rule=v), "rule"),
    "select_anchors": (lambda v: anchor.select_anchors(5, v), "anchor"),
    "highpass_filter": (lambda v: baselines.highpass_filter(EV, [0.5], method=v), "method"),
    "complementary_filter": (lambda v: baselines.complementary_filter(EV, FR, [0.5], method=v), "method"),
    "reconstruct_baseline": (lambda v: baselines.reconstruct_baseline(EV, [0.5], method=v), "method"),
    "stream_reconstruct": (_stream, "offset_from"),
    "solve_head.regularizer": (lambda v: head_solve.solve_head(None, torch.zeros(3), torch.zeros(2, 12, 16),
                                                               regularizer=v), "regularizer"),
    "solve_head.temporal_loss": (lambda v: head_solve.solve_head(None, torch.zeros(3), torch.zeros(2, 12, 16),
                                                                 temporal_loss=v), "temporal_loss"),
    "head_losses": (lambda v: fused.head_losses(torch.zeros(2, 3), None, torch.zeros(3), torch.zeros(1),
                                                torch.zeros(2, 1), regularizer=v), "regularizer"),
    "offset_image": (lambda v: offset.offset_image(LOG, v), "offset method"),
    "offset_grid": (lambda v: offset.offset_grid(0.0, 1.0, 3, v), "offset_solve"),
    "normalize_polarity": (lambda v: normalize_polarity(np.array([0, 1]), v), "polarity"),
    "RunOptions.tonemap": (lambda v: RunOptions(tonemap=v), "tonemap="),
    "RunOptions.anchor": (lambda v: RunOptions(anchor=v), "anchor="),
    "RunOptions.recipe": (lambda v: RunOptions(recipe=v), "recipe="),
    "RunOptions.camera": (lambda v: RunOptions(camera=v), "camera="),
    "RunOptions.time_unit": (lambda v: RunOptions(time_unit=v), "time_unit="),
    "plot_ablation": (lambda v: plot_ablation([{"name": "a", "x": 1, "ssim_none": 0.5, "ssim_clahe": 0.5}], x="x",
                                              xscale=v), "xscale="),
    "plot_tradeoff": (lambda v: plot_tradeoff([{"name": "a", "ssim_clahe": 0.5, "train_time_s": 1.0}], labels=v),
                      "labels"),
}


@pytest.mark.parametrize("value", BAD, ids=BAD_IDS)
@pytest.mark.parametrize("call", list(CALLS))
def test_an_option_given_as_an_array_list_dict_or_tensor_is_named_with_the_allowed_values(call, value):
    fn, name = CALLS[call]
    with pytest.raises(EventDataError, match=rf"^{name} must be one of \(.*\).*, got .*; pass "):
        fn(value)


# None is RunOptions' own time unit (the recipe's), not refused
OTHER = [(c, v) for c in ["offset_grid", "EvINRConfig.spatial_order", "select_anchors", "head_losses",
                          "RunOptions.recipe", "RunOptions.time_unit", "equalize"] for v in (None, 5, "nope")
         if not (v is None and c == "RunOptions.time_unit")]


@pytest.mark.parametrize("call, value", OTHER, ids=[f"{c}-{v!r}" for c, v in OTHER])
def test_an_option_that_is_none_a_number_or_unknown_text_is_named(call, value):
    fn, name = CALLS[call]
    with pytest.raises(EventDataError, match=rf"^{name} must be one of \("):
        fn(value)


@pytest.mark.parametrize("value", [torch.tensor(1), True, 1.5, "Banded"], ids=repr)
def test_spatial_order_is_1_2_or_banded_itself(value):
    with pytest.raises(EventDataError, match=r"spatial_order must be one of \(1, 2, 'banded'\)"):
        EvINRConfig(spatial_order=value)


@pytest.mark.parametrize("value, fix", [(np.array("clahe"), r"pass the option itself \(equalization='clahe'\), "
                                                           r"not a ndarray"),
                                        (["global"], r"pass the option itself \(equalization='global'\), not a list"),
                                        ("CLAHE", r"did you mean 'clahe'\?")], ids=repr)
def test_the_message_names_the_fix(value, fix):
    with pytest.raises(EventDataError, match=fix):
        equalize(IMG, method=value)


def test_resolve_lpips_of_an_array_is_named():
    with pytest.raises(EventDataError, match="lpips_model must be None or 'auto'"):
        resolve_lpips(np.zeros(0))


# ---- guards: valid calls keep working ----------------------------------------------------------------------------

def test_numpy_text_scalars_are_text_guard():
    assert np.array_equal(equalize(IMG, method=np.str_("clahe")), equalize(IMG, method="clahe"))
    assert protocol_description(np.str_("none")) == protocol_description("none")
    assert EvINRConfig(tonemap=np.str_("reinhard"), anchor=np.str_("first")).tonemap == "reinhard"
    assert np.array_equal(denoise.hot_pixel_mask(EV, rule=np.str_("median")), denoise.hot_pixel_mask(EV, rule="median"))
    assert tonemap.display_shift(LOG, np.str_("linear")) == tonemap.display_shift(LOG, "linear")
    assert RunOptions(recipe=np.str_("paper"), time_unit=np.str_("us")).recipe == "paper"
    assert np.array_equal(anchor.select_anchors(5, np.str_("all")), anchor.select_anchors(5, "all"))


def test_numpy_whole_numbers_are_spatial_orders_guard():
    assert EvINRConfig(spatial_order=np.int64(2)).spatial_order == 2
    for whole in (2.0, np.float64(1.0)):   # a whole float is that order, stored as the int (as sizes are)
        got = EvINRConfig(spatial_order=whole).spatial_order
        assert got == int(whole) and type(got) is int
    assert EvINRConfig(spatial_order="banded").spatial_order == "banded"


def test_offset_grid_and_head_losses_keep_their_results_guard():
    assert offset.offset_grid(0.0, 1.0, 3, "none").size == 24 and offset.offset_grid(0.0, 1.0, 3, "l1_gradient").size == 64
    gen = torch.Generator().manual_seed(19)
    h, w, b = torch.randn(2, 3, 8, generator=gen), torch.randn(2, 8, 20, generator=gen), torch.randn(2, 1, 20, generator=gen)
    frames = torch.randn(2, 2, 4, 5, generator=gen)
    for reg in ("tikhonov", "tv", "none"):
        a = fused.head_losses(h, None, w, b, frames, regularizer=reg)
        c = fused.head_losses(h, None, w, b, frames, regularizer=np.str_(reg))
        assert all(torch.equal(x, y) for x, y in zip(a, c))


def test_choice_returns_the_allowed_entry_guard():
    assert type(choice(np.str_("a"), ("a", "b"), "x")) is str
    assert choice(np.int64(2), (1, 2, "banded"), "x") == 2
    assert choice(None, (None, "a"), "x") is None
