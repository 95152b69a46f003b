"""The static image's coarse part from the integrated events (method/coarse.py,
EvINRConfig.offset_coarse_px): its pieces, its gate on the span, and what it is for."""
import numpy as np
import pytest
from scipy.ndimage import gaussian_filter

from evinr_lite import EvINRConfig, make_scene, simulate_scene
from evinr_lite.core.events import EventDataError
from evinr_lite.method import integrate_events
from evinr_lite.method.coarse import (MAX_SPAN_S, coarse_applies, coarse_correction, gaussian_lowpass,
                                      integrated_frames)
from evinr_lite.method.memory import estimate_memory
from evinr_lite.method.solver import reconstruct


@pytest.fixture(scope="module")
def translating():
    """A clean 2 s pan at 48 x 64 (the case the correction is for) and its events."""
    scene = make_scene("camera", sensor_size=(48, 64), duration=2.0, velocity=(14.0, 6.0))
    return scene, simulate_scene(scene, 0.0, 2.0, C=0.2, seed=0)


def test_the_lowpass_is_a_gaussian_with_mirrored_borders():
    img = np.random.default_rng(0).normal(size=(120, 161))
    for sigma in (2.0, 4.0, 8.0):        # scipy's sampled kernel, cut at 8 sigma inside the image (below 2 px
        # the sampled kernel and the transfer function part by aliasing)
        want = gaussian_filter(img, sigma, mode="reflect", truncate=8.0)
        np.testing.assert_allclose(gaussian_lowpass(img, sigma), want, rtol=0, atol=1e-9)


def test_integrated_frames_are_the_integrated_events_in_any_chunks(translating):
    _, events = translating
    t = np.linspace(0.0, 2.0, 17)
    for C in (0.2, (0.25, 0.15)):
        whole = integrated_frames([events], t, C, (48, 64))
        assert whole.dtype == np.float32 and whole.shape == (17, 48, 64)
        want = integrate_events(events, t, C=C)
        np.testing.assert_allclose(whole - whole[0], want - want[0], rtol=0, atol=1e-4)
        chunks = [events.slice_time(a, b, allow_empty=True) for a, b in ((0.0, 0.7), (0.7, 0.71), (0.71, 2.1))]
        np.testing.assert_allclose(integrated_frames(chunks, t, C, (48, 64)), whole, rtol=0, atol=1e-4)
    assert integrated_frames([events.slice_time(5.0, 6.0, allow_empty=True)], t, 0.2, (48, 64)) is None


def test_the_correction_is_smooth_has_mean_zero_and_is_zero_without_events(translating):
    _, events = translating
    t = np.linspace(0.0, 2.0, 64)
    frames = integrated_frames([events], t, 0.2, (48, 64)) * 0.5          # a static image with too little contrast
    corr = coarse_correction([events], 0.2, t, frames, 8.0, "l1_gradient")
    assert corr.dtype == np.float32 and corr.shape == (48, 64)
    assert abs(float(corr.mean())) < 1e-6 and float(np.abs(corr).max()) > 0.01
    np.testing.assert_allclose(gaussian_lowpass(corr, 2.0), corr, rtol=0, atol=0.1 * float(np.abs(corr).max()))
    empty = coarse_correction([events.slice_time(5.0, 6.0, allow_empty=True)], 0.2, t, frames, 8.0, "l1_gradient")
    assert not empty.any()


def test_it_brings_the_static_image_closer_to_the_truth_at_coarse_scales(translating):
    scene, events = translating
    q = np.linspace(0.1, 1.9, 10)
    truth = np.stack([scene.log_intensity(x) for x in q]).astype(np.float64)

    def coarse_static_error(px):
        L = reconstruct(events, q, EvINRConfig(C=0.2, progress=False, offset_coarse_px=px)).log_intensity
        e = (L - truth).mean(axis=0)
        return float(np.sqrt((gaussian_lowpass(e - e.mean(), 8.0) ** 2).mean()))

    without, with_ = coarse_static_error(None), coarse_static_error(8.0)
    assert with_ < 0.9 * without, (with_, without)


def test_spans_longer_than_the_limit_keep_the_inr_static_image():
    scene = make_scene("camera", sensor_size=(24, 32), duration=3.5)
    events = simulate_scene(scene, 0.0, 3.5, C=0.2, seed=1)
    q = np.linspace(0.1, 3.4, 6)
    cfg = EvINRConfig(C=0.2, progress=False, hidden_features=64)
    assert not coarse_applies(cfg, 0.0, 3.5) and coarse_applies(cfg, 0.0, MAX_SPAN_S)
    a = reconstruct(events, q, cfg, t_start=0.0, t_end=3.5).log_intensity
    b = reconstruct(events, q, EvINRConfig(C=0.2, progress=False, hidden_features=64, offset_coarse_px=None),
                    t_start=0.0, t_end=3.5).log_intensity
    np.testing.assert_array_equal(a, b)
    short = reconstruct(events, q[:3], cfg, t_start=0.0, t_end=1.5).log_intensity
    plain = reconstruct(events, q[:3], EvINRConfig(C=0.2, progress=False, hidden_features=64, offset_coarse_px=None),
                        t_start=0.0, t_end=1.5).log_intensity
    assert not np.array_equal(short, plain)


def test_the_setting_is_checked_and_the_paper_recipes_leave_it_out():
    assert EvINRConfig().offset_coarse_px == 8.0
    for preset in (EvINRConfig.paper(), EvINRConfig.v0_1(), EvINRConfig.base()):
        assert preset.offset_coarse_px is None and not coarse_applies(preset, 0.0, 1.0)
    assert not coarse_applies(EvINRConfig(offset_solve="none"), 0.0, 1.0)
    for bad in (0, -2.0, float("nan"), "8", True):
        with pytest.raises(EventDataError, match="offset_coarse_px"):
            EvINRConfig(offset_coarse_px=bad)


def test_the_memory_estimate_counts_what_the_coarse_part_allocates(translating):
    """estimate_memory's coarse_bytes against coarse_correction's own peak (tracemalloc sees numpy's
    buffers), for a pair of thresholds (ON and OFF sums apart) on a 64-frame grid; and nothing on
    spans over MAX_SPAN_S, where it does not run."""
    import tracemalloc

    _, events = translating
    grid = np.linspace(0.0, 2.0, 64)
    frames = np.zeros((64, 48, 64), np.float32)
    est = estimate_memory((48, 64), 0.0, 2.0, len(events), 10, EvINRConfig())["coarse_bytes"]
    coarse_correction([events], (0.22, 0.18), grid, frames, 8.0, "l1_gradient")      # imports and caches first
    peaks = []
    for _ in range(3):       # tracemalloc also counts other threads' allocations (a worker's leftovers): the least of 3
        tracemalloc.start()
        coarse_correction([events], (0.22, 0.18), grid, frames, 8.0, "l1_gradient")
        peaks.append(tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
    peak = min(peaks)
    assert 0.75 * peak <= est <= 1.25 * peak, (est, peaks)
    for streaming in (False, True):
        long = [estimate_memory((720, 1280), 0.0, MAX_SPAN_S + 1, 20_000_000, 10, c, streaming=streaming)
                for c in (EvINRConfig(), EvINRConfig(offset_coarse_px=None))]
        assert long[0]["coarse_bytes"] == 0 and long[0]["total"] == long[1]["total"]
        short = estimate_memory((720, 1280), 0.0, 2.0, 10_000_000, 10, EvINRConfig(), streaming=streaming)
        assert 0 < short["coarse_bytes"] < short["offset_solve_bytes"]   # half the grid: within the grid's solve


