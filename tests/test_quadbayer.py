"""Quad Bayer CFA, mosaicing, demosaicing of frames and events, colour reconstruction."""
import numpy as np
import pytest

from evinr_lite import EvINRConfig, Events, EventDataError, integrate_events, simulate_scene
from evinr_lite.teaching import aed_exercises, exercises
from evinr_lite.method.colour import channel_offsets_from, chroma_correlation, reconstruct_colour
from evinr_lite.sim.quadbayer import (BAYER, QuadBayerScene, cfa_channel, cfa_pattern, cfa_tile, demosaic_events, demosaic_events_rgb, demosaic_grey, demosaic_rgb, demosaic_rgb_full, checker_amplitude, effective_thresholds, mosaic, mosaic_display, photosites_per_window, reduce_mean, simulate_colour_video)

PHASES = [(0, 0), (1, 0), (0, 1), (1, 3), (3, 2), (2, 2)]


@pytest.fixture(scope="module")
def colour_events():
    """Events of a moving colour image on a 32 x 48 Quad Bayer sensor with an odd phase."""
    scene = QuadBayerScene("coffee", (32, 48), 0.5, phase=(1, 3), velocity=(30.0, 10.0), rotation=0.0, zoom=0.0)
    return scene, simulate_scene(scene, 0.0, 0.5, C=0.2, seed=0)


# ---- the filter ----------------------------------------------------------------------------

def test_tile_at_phase_zero_is_the_quad_bayer_layout():
    R, G, B = 0, 1, 2
    assert cfa_tile().tolist() == [[R, R, G, G], [R, R, G, G], [G, G, B, B], [G, G, B, B]]
    assert cfa_tile(BAYER).tolist() == [[R, G], [G, B]]


@pytest.mark.parametrize("phase", PHASES)
def test_phase_shifts_the_pattern_and_every_window_holds_one_period(phase):
    H, W = 12, 20
    base = cfa_pattern((H, W))
    shifted = cfa_pattern((H, W), phase)
    dy, dx = phase
    # photosite (y, x) at phase (dy, dx) sees what photosite (y + dy, x + dx) sees at phase 0
    assert np.array_equal(shifted[:H - 4, :W - 4], base[dy:dy + H - 4, dx:dx + W - 4])
    counts = np.stack([reduce_mean((shifted == c).astype(float), 4) * 16 for c in range(3)])
    assert np.array_equal(counts, np.broadcast_to(np.array([4, 8, 4])[:, None, None], counts.shape))


def test_exercise_reference_agrees_with_the_package():
    y, x = np.mgrid[0:9, 0:11]
    for phase in PHASES:
        assert np.array_equal(aed_exercises.quad_bayer_channel(y, x, phase), cfa_channel(y, x, phase))
    assert exercises.check("quad_bayer_channel", lambda y, x, phase: cfa_channel(y, x, phase), verbose=False)


def test_bad_cfa_arguments_are_named():
    with pytest.raises(EventDataError, match="phase"):
        cfa_pattern((8, 8), phase=(0.5, 0))
    with pytest.raises(EventDataError, match="block"):
        cfa_tile(block=0)
    with pytest.raises(EventDataError, match=r"\[\.\.\., H, W, 3\]"):
        mosaic(np.zeros((4, 4)))
    with pytest.raises(EventDataError, match="multiples of the tile period 4"):
        demosaic_grey(np.ones((6, 8)))


# ---- frames --------------------------------------------------------------------------------

def _smooth_rgb(H, W):
    y, x = np.mgrid[0:H, 0:W].astype(float)
    rgb = np.stack([0.5 + 0.3 * np.sin(2 * np.pi * x / 64 + 0.3), 0.5 + 0.3 * np.cos(2 * np.pi * y / 48),
                    0.5 + 0.2 * np.sin(2 * np.pi * (x + y) / 80)], axis=-1)
    return rgb


@pytest.mark.parametrize("phase", [(0, 0), (1, 3), (2, 1)])
def test_mosaic_then_demosaic_of_a_smooth_image_returns_it(phase):
    rgb = _smooth_rgb(48, 64)
    raw = mosaic(rgb, phase)
    # a channel's photosites in a 4x4 window sit at most 1 px (per axis) from the window centre on
    # average, so the reduced colour is off by at most max|d/dx| + max|d/dy| (first order)
    gy, gx = np.gradient(rgb, axis=(0, 1))
    bound = np.abs(gx).max() + np.abs(gy).max()
    truth = np.stack([reduce_mean(rgb[..., c], 4) for c in range(3)], axis=-1)
    err = np.abs(demosaic_rgb(raw, phase) - truth)
    assert err.max() <= 1.1 * bound
    grey_truth = reduce_mean(rgb @ np.array([0.25, 0.5, 0.25]), 4)
    assert np.abs(demosaic_grey(raw) - grey_truth).max() <= 1.1 * bound
    full = demosaic_rgb_full(raw, phase)
    assert full.shape == rgb.shape
    assert np.abs(full - rgb)[3:-3, 3:-3].max() <= 2.5 * bound     # neighbours up to 2 px away


@pytest.mark.parametrize("phase", [(0, 0), (3, 1)])
def test_constant_colour_is_recovered_exactly(phase):
    colour = np.array([0.7, 0.4, 0.1])
    raw = mosaic(np.broadcast_to(colour, (2, 8, 12, 3)), phase)     # a video of 2 frames
    assert raw.shape == (2, 8, 12)
    assert np.allclose(demosaic_rgb(raw, phase), colour)
    assert np.allclose(demosaic_grey(raw), (colour[0] + 2 * colour[1] + colour[2]) / 4)
    assert np.allclose(demosaic_rgb_full(raw[0], phase), colour)


def test_orientation_of_one_bright_photosite_for_an_odd_phase():
    raw = np.zeros((12, 16))
    raw[5, 9] = 1.0                                      # row 5, column 9
    phase = (1, 3)
    c = int(cfa_channel(5, 9, phase))
    rgb = demosaic_rgb(raw, phase)
    assert rgb.shape == (3, 4, 3)
    hot = np.argwhere(rgb > 0)
    assert hot.tolist() == [[1, 2, c]]                    # row 5 // 4, column 9 // 4, its own channel


# ---- events --------------------------------------------------------------------------------

def test_one_event_lands_on_its_window_and_channel_for_an_odd_phase():
    phase = (1, 3)
    ev = Events(np.array([0.1, 0.2]), np.array([9, 2]), np.array([5, 10]), np.array([1, -1]), (12, 16))
    grey = demosaic_events(ev)
    assert grey.sensor_size == (3, 4)
    assert grey.x.tolist() == [2, 0] and grey.y.tolist() == [1, 2]
    streams = demosaic_events_rgb(ev, phase)
    for c, s in enumerate(streams):
        assert s.sensor_size == (3, 4)
        expect = [i for i in range(2) if cfa_channel(ev.y[i], ev.x[i], phase) == c]
        assert s.t.tolist() == ev.t[expect].tolist()


def test_event_demosaicing_conserves_counts_and_polarity_sums(colour_events):
    scene, ev = colour_events
    grey = demosaic_events(ev)
    assert len(grey) == len(ev) > 1000
    assert np.array_equal(grey.t, ev.t) and np.array_equal(grey.p, ev.p)
    H, W = ev.sensor_size
    raw_sums = np.zeros((H, W))
    np.add.at(raw_sums, (ev.y, ev.x), ev.p)
    grey_sums = np.zeros(grey.sensor_size)
    np.add.at(grey_sums, (grey.y, grey.x), grey.p)
    assert np.array_equal(grey_sums, reduce_mean(raw_sums, 4) * 16)
    streams = demosaic_events_rgb(ev, scene.phase)
    assert sum(len(s) for s in streams) == len(ev)
    pattern = cfa_pattern((H, W), scene.phase)
    for c, s in enumerate(streams):
        sums = np.zeros(s.sensor_size)
        np.add.at(sums, (s.y, s.x), s.p)
        assert np.array_equal(sums, reduce_mean(np.where(pattern == c, raw_sums, 0), 4) * 16)
        assert np.all(np.diff(s.t) >= 0)


def test_grey_event_frame_is_the_weighted_mean_of_the_channel_frames(colour_events):
    scene, ev = colour_events
    C = 0.2
    eff = effective_thresholds(C)
    assert eff == {"R": C / 4, "G": C / 8, "B": C / 4, "grey": C / 16}
    n = photosites_per_window()
    t = np.array([0.25, 0.5])
    grey = integrate_events(demosaic_events(ev), t, eff["grey"])
    chans = [integrate_events(s, t, eff[name]) for s, name in zip(demosaic_events_rgb(ev, scene.phase), "RGB")]
    assert np.allclose(grey, sum(n[name] / n["grey"] * L for L, name in zip(chans, "RGB")))
    frame = aed_exercises.grey_event_frame(ev.x, ev.y, ev.p, C, ev.sensor_size)
    assert np.allclose(frame, grey[-1])


def test_integrated_grey_events_track_the_mean_log_within_one_threshold(colour_events):
    scene, ev = colour_events
    C = 0.2
    t = np.linspace(0.05, 0.5, 6)
    mean_log = demosaic_grey(scene.log_intensity(np.r_[0.0, t]))         # mean of the photosites' logs
    change = mean_log[1:] - mean_log[0]
    grey = demosaic_events(ev)
    err = integrate_events(grey, t, effective_thresholds(C)["grey"]) - change
    # each photosite is within one threshold of its own change, so their mean is too
    assert np.abs(err).max() < C
    assert np.abs(err).mean() < 0.25 * np.abs(change).mean()
    wrong = integrate_events(grey, t, C) - change                        # forgetting the 1/16
    assert np.abs(wrong).mean() > 5 * np.abs(err).mean()


def test_scene_log_intensity_is_the_mosaic_of_its_channels():
    scene = QuadBayerScene("astronaut", (8, 12), 1.0, phase=(2, 1))
    L = scene.log_intensity([0.0, 0.5])
    assert L.shape == (2, 8, 12)
    assert np.array_equal(L, mosaic(scene.rgb_log_intensity([0.0, 0.5]), (2, 1)))
    assert scene.rgb(0.5).shape == (2, 3, 3) and scene.grey([0.5]).shape == (1, 2, 3)
    with pytest.raises(EventDataError, match="multiples of the tile period"):
        QuadBayerScene("coffee", (10, 12))


def test_simulate_colour_video_matches_the_mosaic_of_the_channels():
    t = np.linspace(0, 1, 5)
    rgb = np.exp(np.linspace(0, 1, 5)[:, None, None, None] * np.array([1.05, -0.55, 0.27]))
    rgb = np.broadcast_to(rgb, (5, 4, 8, 3))
    ev = simulate_colour_video(rgb, t, C=0.1, phase=(0, 0))
    R, G, B = (len(s) for s in demosaic_events_rgb(ev))
    # per photosite: R rises by 1.05 (10 events of C = 0.1), G falls by 0.55 (5), B rises by 0.27 (2)
    assert (R, G, B) == (10 * 8, 5 * 16, 2 * 8)
    with pytest.raises(EventDataError, match="positive"):
        simulate_colour_video(np.zeros((2, 4, 4, 3)), [0, 1])


def test_bad_event_sensor_is_named():
    ev = Events(np.array([0.0]), np.array([0]), np.array([0]), np.array([1]), (6, 8))
    with pytest.raises(EventDataError, match="multiples of the tile period 4"):
        demosaic_events(ev)


# ---- colour reconstruction ------------------------------------------------------------------

def test_channel_offsets_from_a_uniform_colour():
    off = channel_offsets_from(np.broadcast_to([0.6, 0.3, 0.15], (4, 4, 3)))
    assert np.allclose(off, np.log([0.6, 0.3, 0.15]) - np.log([0.6, 0.3, 0.15]).mean())
    with pytest.raises(EventDataError):
        channel_offsets_from(np.zeros((2, 2, 3)))


def test_reconstruct_colour_shapes_thresholds_and_offsets(colour_events):
    scene, ev = colour_events
    streams = demosaic_events_rgb(ev, scene.phase)
    cfg = EvINRConfig.v0_1(hidden_features=16, n_iters=6, c2f_iters=(2, 4), progress=False)
    q = [0.1, 0.3]
    rec = reconstruct_colour(streams, q, cfg, C=0.2, t_start=0.0, t_end=0.5)
    assert rec.frames.shape == (2, 8, 12, 3) and rec.frames.min() >= 0 and rec.frames.max() <= 1
    assert rec.thresholds == (0.05, 0.025, 0.05)
    assert [r.config.C for r in rec.channels] == list(rec.thresholds)
    off = np.array([0.3, 0.0, -0.3])
    shifted = reconstruct_colour(streams, q, cfg, C=0.2, channel_offsets=off, t_start=0.0, t_end=0.5)
    assert np.allclose(shifted.log_intensity - rec.log_intensity, off.astype(np.float32), atol=1e-5)
    with pytest.raises(EventDataError, match="three"):
        reconstruct_colour(streams[:2], q, cfg, C=0.2)
    with pytest.raises(EventDataError, match="pass C"):
        reconstruct_colour(streams, q, cfg)


def test_mosaic_display_and_checker_amplitude():
    raw = np.full((4, 8), 0.5)
    shown = mosaic_display(raw, (1, 0))
    pattern = cfa_pattern((4, 8), (1, 0))
    assert shown.shape == (4, 8, 3)
    assert np.array_equal(shown.argmax(axis=-1), pattern) and np.allclose(shown.sum(axis=-1), 0.5)
    board = np.indices((6, 8)).sum(axis=0) % 2 * 1.0          # 0/1 checkerboard
    assert checker_amplitude(board) == pytest.approx(0.5)
    assert checker_amplitude(np.full((6, 8), 3.0)) == 0.0
    ramp = np.tile(np.arange(8.0) * 0.1, (6, 1))               # slope 0.1 per pixel along x
    assert checker_amplitude(ramp) == pytest.approx(0.05)


def test_chroma_correlation():
    rng = np.random.default_rng(0)
    L = rng.normal(size=(2, 4, 5, 3))
    assert chroma_correlation(L, L) == pytest.approx({"R-G": 1.0, "B-G": 1.0})
    grey = np.repeat(L[..., :1], 3, axis=-1)                    # no colour at all
    shifted = L + np.array([0.7, -0.2, 0.4])                     # a colour cast changes nothing
    assert chroma_correlation(shifted, L) == pytest.approx({"R-G": 1.0, "B-G": 1.0})
    assert chroma_correlation(grey, L) == {"R-G": 0.0, "B-G": 0.0}
