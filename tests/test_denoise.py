"""Denoising (evinr_lite.method.denoise): exactness of the correlation filter, hot pixels, noise labels, CLI."""
import json

import numpy as np
import pytest

import importlib

from evinr_lite.core.events import EventDataError, Events
from evinr_lite.method import correlation_filter, hot_pixel_mask, remove_hot_pixels
from evinr_lite.method.denoise import denoise as denoise_fn
from evinr_lite.sim.scenes import MovingImageScene
from evinr_lite.sim.simulate import add_background_noise, add_hot_pixels, simulate_scene

D = importlib.import_module("evinr_lite.method.denoise")


# ---- the exact rule, against a brute-force loop ------------------------------------------------

def brute_force(ev: Events, dt, neighbourhood=8, min_neighbours=1, same_polarity=False, window="before"):
    """The module docstring's rule, one event at a time."""
    t, x, y, p = ev.t, ev.x.astype(int), ev.y.astype(int), ev.p
    keep = np.zeros(len(t), bool)
    for i in range(len(t)):
        support = set()
        for j in range(len(t)):
            dx, dy = abs(x[j] - x[i]), abs(y[j] - y[i])
            near = max(dx, dy) == 1 if neighbourhood == 8 else dx + dy == 1
            if not near or (same_polarity and p[i] != p[j]):
                continue
            if t[j] <= t[i] <= t[j] + dt or (window == "both" and t[j] - dt <= t[i] <= t[j]):
                support.add((x[j], y[j]))
        keep[i] = len(support) >= min_neighbours
    return keep


def tied_events(rng, n, H, W, offset=0.0):
    """Events on whole microseconds in [0, 60) us: many equal timestamps and gaps of exactly dt."""
    t = np.sort(rng.integers(0, 60, n)) * 1e-6 + offset
    return Events(t, rng.integers(0, W, n), rng.integers(0, H, n), rng.choice([-1, 1], n), (H, W))


@pytest.mark.parametrize("seed", range(2))
def test_correlation_filter_equals_brute_force_with_ties(seed, monkeypatch):
    rng = np.random.default_rng(seed)
    if seed % 2:
        monkeypatch.setattr(D, "CHUNK", 5)        # chunks cut by count too, never inside equal timestamps
    for trial in range(3):
        ev = tied_events(rng, int(rng.integers(120, 220)), int(rng.integers(2, 6)), int(rng.integers(2, 6)),
                         offset=1000.0 if trial == 2 else 0.0)
        dt = int(rng.integers(1, 12)) * 1e-6
        for kw in (dict(), dict(neighbourhood=4), dict(min_neighbours=2), dict(same_polarity=True),
                   dict(window="both"), dict(window="both", min_neighbours=3, same_polarity=True)):
            got = correlation_filter(ev, dt, **kw)
            want = brute_force(ev, dt, **kw)
            assert np.array_equal(got, want), (seed, trial, kw, np.flatnonzero(got != want)[:5])


def test_ties_exactly_at_dt_and_same_timestamp():
    # a at (0, 0); b its neighbour exactly dt later; c at the same time as a, next to it; d alone
    dt = 1e-3
    ev = Events([0.0, 0.0, dt, 0.5], [0, 1, 1, 3], [0, 0, 1, 3], [1, 1, 1, 1], (4, 4))
    keep = correlation_filter(ev, dt)
    # a and c support each other (same time, either order); b is kept by a at exactly dt; d has no neighbour
    assert keep.tolist() == [True, True, True, False]
    # a hair less than dt: b is dropped, so the end of the window is inclusive and no wider
    assert correlation_filter(ev, dt * (1 - 1e-9)).tolist() == [True, True, False, False]
    # the pixel itself never counts
    same = Events([0.0, 1e-4, 2e-4], [2, 2, 2], [2, 2, 2], [1, 1, 1], (4, 4))
    assert not correlation_filter(same, dt).any()


def test_filter_is_independent_of_the_order_of_equal_timestamps():
    rng = np.random.default_rng(5)
    ev = tied_events(rng, 400, 6, 6)
    perm = np.lexsort((rng.random(len(ev)), ev.t))          # shuffle within equal timestamps
    shuffled = ev.take(perm)
    np.testing.assert_array_equal(correlation_filter(shuffled, 3e-6), correlation_filter(ev, 3e-6)[perm])


# ---- noise labels from the simulator ---------------------------------------------------------

@pytest.fixture(scope="module")
def noisy_scene():
    """A 40x50, 1 s moving image with 2 Hz/pixel background activity and 6 hot pixels at 150 Hz, labelled."""
    scene = MovingImageScene("camera", (40, 50), 1.0, velocity=(20.0, 8.0), rotation=0.05, zoom=0.0)
    signal = simulate_scene(scene, 0.0, 1.0, C=0.2, seed=3)
    rng = np.random.default_rng(7)
    ev, bg = add_background_noise(signal, 2.0, seed=rng, t_start=0.0, t_end=1.0, return_labels=True)
    ev, hot, added = add_hot_pixels(ev, 6, 150.0, seed=rng, t_start=0.0, t_end=1.0, return_labels=True)
    labels = np.zeros(len(ev), np.int8)
    labels[~added] = bg.astype(np.int8)                     # input events keep their order
    labels[added] = 2
    return signal, ev, labels, hot


def test_noise_labels_leave_events_unchanged_and_mark_the_added(noisy_scene):
    signal, ev, labels, hot = noisy_scene
    rng = np.random.default_rng(7)
    plain = add_background_noise(signal, 2.0, seed=rng, t_start=0.0, t_end=1.0)
    plain, hot_plain = add_hot_pixels(plain, 6, 150.0, seed=rng, t_start=0.0, t_end=1.0)
    for k in "txyp":                                        # the same seed gives the same events either way
        np.testing.assert_array_equal(getattr(plain, k), getattr(ev, k))
    np.testing.assert_array_equal(hot, hot_plain)
    sig = ev.take(labels == 0)
    for k in "txyp":                                        # label 0 is exactly the simulated signal
        np.testing.assert_array_equal(getattr(sig, k), getattr(signal, k))
    W = ev.sensor_size[1]
    assert set(np.unique((ev.y * W + ev.x)[labels == 2])) <= set(hot.tolist())
    assert (labels == 1).sum() > 0.5 * 2.0 * 40 * 50


def test_zoo_simulation_with_labels_matches_the_zoo():
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from benchmarks.denoise import simulate_labeled
    from evinr_lite.sim import zoo

    # background + hot pixels; ON-only hot pixels; background that grows as light falls
    for name in ("grass_light_noisy", "unequal_onhot", "dark_falling"):
        z = zoo.quick(zoo.get(name))
        ev, labels, hot, times, gt = simulate_labeled(z)
        _, ev0, times0, gt0 = zoo.simulate(z)
        for k in "txyp":
            np.testing.assert_array_equal(getattr(ev, k), getattr(ev0, k))
        np.testing.assert_array_equal(times, times0)
        np.testing.assert_array_equal(gt, gt0)                  # the scored truth, clipped at 1 like the zoo's
        assert (labels == 1).any() and hot.size == z.hot_pixels
        assert (labels == 2).sum() > 0 or z.hot_pixels == 0
        if z.hot_on_only:
            assert np.all(ev.p[labels == 2] > 0)


# ---- hot pixels and the whole denoiser on a noisy scene ---------------------------------------

def test_hot_pixel_mask_finds_the_injected_hot_pixels(noisy_scene):
    _, ev, _, hot = noisy_scene
    H, W = ev.sensor_size
    for rule in ("mad", "median"):
        mask = hot_pixel_mask(ev, rule=rule, factor=8.0 if rule == "mad" else 5.0)
        assert sorted(np.flatnonzero(mask.ravel()).tolist()) == sorted(hot.tolist()), rule
    kept = remove_hot_pixels(ev)
    assert not np.isin(kept.y * W + kept.x, hot).any()
    assert len(kept) == len(ev) - int(np.isin(ev.y * W + ev.x, hot).sum())


def test_denoise_precision_and_recall(noisy_scene):
    _, ev, labels, hot = noisy_scene
    keep, report = D.denoise_mask(ev)
    removed = ~keep
    assert removed[labels == 2].mean() == 1.0                        # every hot-pixel event
    assert keep[labels == 0].mean() >= 0.95                          # signal kept
    bg_removed = removed[labels == 1].mean()
    assert bg_removed >= 0.25                                        # far above ...
    assert bg_removed >= 10 * removed[labels == 0].mean()            # ... the signal's loss
    assert report.n_hot == int((labels == 2).sum()) + int(np.isin((ev.y * ev.sensor_size[1] + ev.x)[labels != 2],
                                                                   hot).sum())
    assert report.n_hot + report.n_background + report.n_out == report.n_in == len(ev)
    assert sorted(y * ev.sensor_size[1] + x for x, y, _ in report.hot_pixels) == sorted(hot.tolist())
    out, report2 = denoise_fn(ev)
    assert len(out) == report.n_out and report2.to_dict() == report.to_dict()
    json.dumps(report.to_dict())                                     # JSON-ready for run.json
    assert "hot pixels" in report.summary() and "background" in report.summary()


def test_stages_can_be_switched_off_and_empty_input(noisy_scene):
    _, ev, labels, _ = noisy_scene
    out, rep = denoise_fn(ev, hot_pixels=False, background=False)
    assert len(out) == len(ev) and rep.n_hot == rep.n_background == 0 and "nothing" in rep.summary()
    empty = Events.empty((5, 6))
    out, rep = denoise_fn(empty)
    assert len(out) == 0 and rep.n_in == 0 and rep.hot_pixels == []
    assert correlation_filter(empty).shape == (0,)
    assert not hot_pixel_mask(empty).any() and hot_pixel_mask(empty).shape == (5, 6)


@pytest.mark.parametrize("call, pattern", [
    (lambda ev: correlation_filter(ev, 0.0), r"dt must be a positive number of seconds"),
    (lambda ev: correlation_filter(ev, float("nan")), r"dt must be a positive"),
    (lambda ev: correlation_filter(ev, 1e-3, neighbourhood=6), r"neighbourhood must be 8 .* or 4"),
    (lambda ev: correlation_filter(ev, 1e-3, min_neighbours=9), r"min_neighbours must be an integer in \[1, 8\]"),
    (lambda ev: correlation_filter(ev, 1e-3, window="after"), r"window must be one of"),
    (lambda ev: hot_pixel_mask(ev, rule="mean"), r"rule must be one of \('mad', 'median'\) \(the hot-pixel rule\), got 'mean'"),
    (lambda ev: hot_pixel_mask(ev, rule="median", factor=1.0), r"must exceed 1"),
    (lambda ev: hot_pixel_mask(ev, factor=-2), r"must be > 0"),
    (lambda ev: remove_hot_pixels(ev, np.zeros((3, 3), bool)), r"mask= must be a bool array of the sensor's shape"),
    (lambda ev: denoise_fn(ev.to_array()), r"expected an Events"),
    (lambda ev: correlation_filter(Events(ev.t + 1e5, ev.x, ev.y, ev.p, ev.sensor_size), 1e-9),
     r"below the resolution of these timestamps"),
])
def test_bad_arguments_name_the_fix(noisy_scene, call, pattern):
    ev = noisy_scene[1].take(slice(0, 500))
    with pytest.raises(EventDataError, match=pattern):
        call(ev)


# ---- the command line -------------------------------------------------------------------------

def test_cli_reconstruct_denoise_writes_the_report(tmp_path, capsys):
    from evinr_lite import read_recording
    from evinr_lite.apps.cli import main
    from evinr_lite.sim.recordings import write_example_recording

    folder = write_example_recording(tmp_path / "rec", sensor_size=(24, 32), duration=0.3, C=0.25, seed=0)
    ev = read_recording(folder).events
    ev, hot = add_hot_pixels(ev, 3, 400.0, seed=1)
    ev = add_background_noise(ev, 5.0, seed=2)
    np.savetxt(folder / "events.txt", np.stack([ev.t, ev.x, ev.y, (ev.p > 0).astype(np.int64)], axis=1),
               fmt=["%.9f", "%d", "%d", "%d"])
    out = tmp_path / "out"
    code = main(["reconstruct", str(folder), "--out", str(out), "--C", "0.25", "--iters", "4", "--quiet",
                 "--no-video", "--denoise"])
    printed = capsys.readouterr().out
    assert code == 0
    run = json.loads((out / "run.json").read_text())
    rep = run["denoise"]
    W = 32
    assert sorted(y * W + x for x, y, _ in rep["hot_pixels"]) == sorted(hot.tolist())
    assert rep["n_in"] == len(ev) and rep["n_out"] == rep["n_in"] - rep["n_hot"] - rep["n_background"] < len(ev)
    assert rep["settings"]["dt"] == D.DEFAULT_DT
    assert "denoise: 3 hot pixels" in printed
    # without the flag nothing is removed and run.json has no report
    out2 = tmp_path / "out2"
    assert main(["reconstruct", str(folder), "--out", str(out2), "--C", "0.25", "--iters", "4", "--quiet",
                 "--no-video"]) == 0
    assert "denoise" not in json.loads((out2 / "run.json").read_text())
