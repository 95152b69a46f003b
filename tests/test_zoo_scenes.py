"""The zoo's scenes and sensor models (evinr_lite.sim.scenes, simulate.add_hot_pixels, sim.zoo)."""
import numpy as np
import pytest

from evinr_lite.core.events import EventDataError, Events
from evinr_lite.sim import zoo
from evinr_lite.sim.scenes import (LightingScene, MovingImageScene, ObjectOverBackgroundScene, VaryingSpeedScene,
                                   WarpedImageScene)
from evinr_lite.sim.simulate import add_hot_pixels

T = np.array([0.0, 0.7, 1.3, 2.0])


def test_warped_scene_without_warp_is_the_moving_image():
    a = WarpedImageScene("camera", (24, 32), 2.0, shear=(0.0, 0.0), tilt=(0.0, 0.0))
    b = MovingImageScene("camera", (24, 32), 2.0)
    np.testing.assert_allclose(a.log_intensity(T), b.log_intensity(T), atol=1e-12)
    warped = WarpedImageScene("camera", (24, 32), 2.0, shear=(0.3, 0.0), tilt=(0.2, 0.0))
    assert np.abs(warped.log_intensity(T[-1:]) - b.log_intensity(T[-1:])).max() > 0.05
    np.testing.assert_allclose(warped.log_intensity(1.0), b.log_intensity(1.0), atol=1e-12)   # tau = 0: no warp
    with pytest.raises(EventDataError, match="folds"):
        WarpedImageScene("camera", (24, 32), 2.0, tilt=(0.6, 0.0))


def test_object_over_static_background():
    s = ObjectOverBackgroundScene("brick", "coffee", (40, 60), 2.0, radius=6.0)
    L = s.log_intensity(np.linspace(0, 2, 9))
    changes = np.abs(np.diff(L, axis=0)).max(axis=0)
    assert changes[0, 0] < 1e-3 and changes[-1, 0] < 1e-3        # corners far from the path (soft edge: tanh tail)
    assert changes.max() > 0.3                                    # the object's path does
    assert s.max_speed == pytest.approx(np.hypot(*(s.end - s.start)) / 2.0)


def test_lighting_adds_global_change_and_vignette():
    base = MovingImageScene("chelsea", (20, 30), 2.0)
    lit = LightingScene(base, global_change=0.4, vignette=-0.5)
    d = lit.log_intensity(T) - base.log_intensity(T)
    s = T / 2.0 - 0.5
    np.testing.assert_allclose(d[:, 10, 15] / s[:, None][:, 0], 0.4, atol=0.01)   # near the centre: global only
    assert d[-1, 0, 0] - d[0, 0, 0] == pytest.approx(0.4 - 0.5, abs=1e-9)         # a corner: global + vignette


def test_varying_speed_scene_moved_to_sim():
    from evinr_lite.teaching import accel_exercises

    assert accel_exercises.VaryingSpeedScene is VaryingSpeedScene


def test_hot_pixels():
    ev = Events.from_arrays([0.0, 2.0], [0, 1], [0, 0], [1, -1], (8, 10))
    out, hot = add_hot_pixels(ev, 5, 100.0, seed=3)
    again, hot2 = add_hot_pixels(ev, 5, 100.0, seed=3)
    np.testing.assert_array_equal(out.t, again.t) and np.testing.assert_array_equal(hot, hot2)
    flat = out.y.astype(np.int64) * 10 + out.x
    counts = np.bincount(flat, minlength=80)
    assert set(np.flatnonzero(counts > 20)) == set(hot.tolist())
    assert np.all(np.abs(counts[hot] - 200) < 5 * np.sqrt(200))   # Poisson(rate x span)
    for h in hot:
        p = out.p[flat == h]
        assert max(np.mean(p > 0), np.mean(p < 0)) > 0.75            # mostly one polarity
    with pytest.raises(EventDataError, match="n_pixels"):
        add_hot_pixels(ev, 81, 1.0)


def test_zoo_is_documented_and_simulates():
    names = [z.name for z in zoo.ZOO]
    assert len(names) == len(set(names)) >= 8 and all(len(z.doc) > 20 for z in zoo.ZOO)
    assert {z.noise_free for z in zoo.ZOO} == {True, False}
    z = zoo.quick(zoo.get("noisy_gravel"))
    scene, events, times, gt = zoo.simulate(z)
    assert gt.shape == (zoo.N_SCORED, *z.size) and len(events) > 1000 and events.sensor_size == z.size
    assert zoo.effective_C(z) == pytest.approx(0.2)
    with pytest.raises(EventDataError, match="no zoo scene"):
        zoo.get("nope")


def test_heldout_scenes_are_new_and_simulate():
    """The held-out set (no default chosen on it): its own names, images and seeds, documented, and
    every scene simulates (quick sizes) with events and frames in range."""
    names = [z.name for z in zoo.HELDOUT]
    assert len(names) == len(set(names)) >= 6 and not set(names) & {z.name for z in zoo.ZOO}
    assert all(len(z.doc) > 20 for z in zoo.HELDOUT)
    assert not {z.seed for z in zoo.HELDOUT} & {z.seed for z in zoo.ZOO}
    assert {z.noise_free for z in zoo.HELDOUT} == {True, False}
    assert zoo.get(names[0]) is zoo.HELDOUT[0]
    z = zoo.quick(zoo.get("coins_unequal_onhot"))
    scene, events, times, gt = zoo.simulate(z)
    assert gt.shape == (z.n_scored, *z.size) and len(events) > 1000 and 0 < gt.min() and gt.max() <= 1

def test_stress_scenes_are_new_outside_the_ranges_and_simulate():
    """The stress set: its own names and seeds, documented, with settings outside the zoo's and the
    held-out set's ranges (threshold, sensor size, noise, an OFF-heavy pair, mismatch), and its scenes
    simulate (quick sizes) with events and frames in range."""
    names = [z.name for z in zoo.STRESS]
    others = zoo.ZOO + zoo.HELDOUT
    assert len(names) == len(set(names)) >= 8 and not set(names) & {z.name for z in others}
    assert all(len(z.doc) > 20 for z in zoo.STRESS)
    assert not {z.seed for z in zoo.STRESS} & {z.seed for z in others}
    assert zoo.get(names[-1]) is zoo.STRESS[-1]
    C = [zoo.effective_C(z) for z in others]
    assert min(zoo.effective_C(z) for z in zoo.STRESS) < min(C) and max(zoo.effective_C(z) for z in zoo.STRESS) > max(C)
    pixels = [z.size[0] * z.size[1] for z in others]
    assert min(z.size[0] * z.size[1] for z in zoo.STRESS) < min(pixels)
    assert max(z.size[1] / z.size[0] for z in zoo.STRESS) > max(z.size[1] / z.size[0] for z in others)
    assert max(z.noise_hz for z in zoo.STRESS) > max(z.noise_hz for z in others)
    assert min(zoo.imbalance(z) for z in zoo.STRESS) < 0 <= min(zoo.imbalance(z) for z in others)
    assert max(z.threshold_sigma for z in zoo.STRESS) > max(z.threshold_sigma for z in others)
    for name in ("chelsea_off_heavy", "bar_sweep"):
        z = zoo.quick(zoo.get(name))
        scene, events, times, gt = zoo.simulate(z)
        assert gt.shape == (z.n_scored, *z.size) and len(events) > 1000 and 0 < gt.min() and gt.max() <= 1


# ---- issue 21: the zoo grows (long scenes, ON-only hot pixels, drifting thresholds, light-dependent noise)

def test_oscillating_scene_is_bounded_and_periodic():
    from evinr_lite.sim.scenes import OscillatingScene

    s = OscillatingScene("camera", (24, 32), 8.0, path=((10.0, 4.0, 2.0, 0.0),), rotation=(0.05, 4.0))
    np.testing.assert_allclose(s.log_intensity(0.0), s.log_intensity(4.0), atol=1e-9)    # both periods divide 4 s
    assert np.abs(s.log_intensity(1.0) - s.log_intensity(0.0)).max() > 0.3                # it does move
    o = s.offset(np.linspace(0, 8, 401))
    assert np.abs(o[:, 0]).max() <= 10.0 + 1e-9 and np.abs(o[:, 1]).max() <= 4.0 + 1e-9
    # the fastest pixel never outruns max_speed (it sets the simulator's sampling)
    t = np.linspace(0, 8, 2001)
    speed = np.hypot(*np.diff(s.offset(t), axis=0).T) / np.diff(t)
    assert speed.max() <= s.max_speed
    with pytest.raises(EventDataError, match="path"):
        OscillatingScene("camera", (24, 32), 2.0, path=((1.0, 1.0, 0.0, 0.0),))


def test_on_only_hot_pixels_keep_pixels_and_times():
    ev = Events.from_arrays([0.0, 2.0], [0, 1], [0, 0], [1, -1], (8, 10))
    mixed, hot = add_hot_pixels(ev, 5, 100.0, seed=3)
    on, hot_on = add_hot_pixels(ev, 5, 100.0, seed=3, on_only=True)
    np.testing.assert_array_equal(hot, hot_on)
    np.testing.assert_array_equal(mixed.t, on.t)
    flat = on.y.astype(np.int64) * 10 + on.x
    assert np.all(on.p[np.isin(flat, hot)] == 1) and np.any(mixed.p[np.isin(flat, hot)] == -1)


def test_light_noise_grows_where_it_is_dark():
    from evinr_lite.sim.simulate import add_light_noise

    class HalfDark:                        # left half at full scale, right half at 1/10 of it
        sensor_size = (20, 40)

        def log_intensity(self, t):
            L = np.zeros((20, 40))
            L[:, 20:] = np.log(0.1)
            return L

    ev = Events.from_arrays([0.0, 10.0], [0, 1], [0, 0], [1, -1], (20, 40))
    out, added = add_light_noise(ev, HalfDark(), 2.0, seed=1, return_labels=True)
    x = out.x[added]
    n_bright, n_dark = np.sum(x < 20), np.sum(x >= 20)
    assert n_bright == pytest.approx(20 * 20 * 2.0 * 10, rel=0.1)          # Poisson(rate x area x span)
    assert n_dark / n_bright == pytest.approx(10.0, rel=0.1)              # x 1 / intensity
    again = add_light_noise(ev, HalfDark(), 2.0, seed=1)
    np.testing.assert_array_equal(again.t, out.t)
    with pytest.raises(EventDataError, match="sensor_size"):
        add_light_noise(Events.from_arrays([0.0, 1.0], [0, 1], [0, 0], [1, -1], (8, 10)), HalfDark(), 1.0)


def test_zoo_long_scenes_are_marked_and_new_faults_are_there():
    long = [z for z in zoo.ZOO if z.long]
    assert {z.name for z in long} >= {"long_pan_20s", "long_ijrr_60s"}
    assert max(z.duration for z in long) >= 60 and min(z.duration for z in long) >= 20
    assert all(not z.long for z in zoo.default_scenes()) and len(zoo.default_scenes(long=True)) == len(zoo.ZOO)
    assert any(z.hot_on_only for z in zoo.ZOO) and any(z.threshold_drift for z in zoo.ZOO)
    assert any(z.dark_noise_hz for z in zoo.ZOO)
    assert zoo.get("long_pan_20s").n_scored == 40 and zoo.get("camera_translate").n_scored == zoo.N_SCORED


def test_zoo_dark_scene_gets_noisier_as_light_falls():
    z = zoo.quick(zoo.get("dark_falling"))
    scene, events, times, gt = zoo.simulate(z)
    assert gt[-1].mean() < gt[0].mean() / 4                               # the light falls
    from dataclasses import replace

    clean = zoo.simulate(replace(z, dark_noise_hz=0.0))[1]
    noise = len(events) - len(clean)
    assert noise > 0


def test_large_scenes_are_new_larger_than_every_other_set_and_simulate():
    """The 360x480 set: its own names and seeds, documented, larger than every scene of the other sets, and
    its scenes simulate (quick sizes) with events and frames in range."""
    names = [z.name for z in zoo.LARGE]
    others = zoo.ZOO + zoo.HELDOUT + zoo.STRESS
    assert len(names) == len(set(names)) >= 3 and not set(names) & {z.name for z in others}
    assert all(len(z.doc) > 20 for z in zoo.LARGE)
    assert not {z.seed for z in zoo.LARGE} & {z.seed for z in others}
    assert zoo.get(names[0]) is zoo.LARGE[0]
    assert min(z.size[0] * z.size[1] for z in zoo.LARGE) > max(z.size[0] * z.size[1] for z in others)
    z = zoo.quick(zoo.LARGE[1])
    _, events, _, gt = zoo.simulate(z)
    assert gt.shape == (z.n_scored, *z.size) and len(events) > 1000 and 0 < gt.min() and gt.max() <= 1


def test_fresh_scenes_are_seeded_varied_documented_and_simulate():
    """zoo.fresh: the same scenes for the same seed, others for another; every scene class and both a clean
    and a noisy sensor among 40 draws; unequal thresholds given as their mean; names and docs say what was
    drawn; the builders pickle (Dask); a few simulate (quick sizes) with events and frames in range."""
    import pickle

    a, b, c = zoo.fresh(5, 40), zoo.fresh(5, 40), zoo.fresh(6, 40)
    assert [z.doc for z in a] == [z.doc for z in b] and [z.seed for z in a] == [z.seed for z in b]
    assert [z.doc for z in a] != [z.doc for z in c]
    assert len({z.name for z in a}) == 40 and not {z.name for z in a} & {z.name for z in zoo.ZOO + zoo.HELDOUT}
    assert {z.tags[1] for z in a} == set(zoo.FRESH_KINDS) and {z.noise_free for z in a} == {True, False}
    for z in a:
        assert z.name.split("_")[2] in zoo.FRESH_KINDS and "given as" in z.doc
        assert abs(zoo.effective_C(z) - z.C) < 1e-9 and 0.74 < z.C_pos / z.C_neg < 1.34
        assert not z.long and 2.0 <= z.duration <= 3.0
    pickle.loads(pickle.dumps(a[0]))
    for z in [next(z for z in a if z.tags[1] == kind) for kind in ("static", "light")]:
        z = zoo.quick(z)
        scene, events, times, gt = zoo.simulate(z)
        assert gt.shape == (z.n_scored, *z.size) and len(events) > 100 and 0 < gt.min() and gt.max() <= 1
    assert zoo.fresh(5, 0) == []
