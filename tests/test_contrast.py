"""C+ and C- from APS frames (method/contrast.py), C pairs in the binning and the solver, `--C auto`."""
import json
import math
import shutil

import numpy as np
import pytest

from evinr_lite.apps.cli import build_parser, main
from evinr_lite.apps.recon_job import check_run_options, contrast_option
from evinr_lite.core.events import EventDataError, Events
from evinr_lite.core.frames import Frames
from evinr_lite.method.binning import as_thresholds, events_to_frames, events_to_frames_chunked
from evinr_lite.method.contrast import (ContrastFit, estimate_contrast_threshold, fit_contrast, frame_event_counts,
                                        frame_log_changes)
from evinr_lite.method.integration import integrate_events
from evinr_lite.method.solver import EvINRConfig, reconstruct
from evinr_lite.sim.recordings import write_example_recording
from evinr_lite.sim.scenes import MovingImageScene
from evinr_lite.sim.simulate import add_background_noise, simulate_scene


def _scene_and_frames(C_pos, C_neg, *, size=(48, 64), duration=1.0, rate=25.0, seed=0):
    """A moving image's events with thresholds C_pos / C_neg and its APS frames (intensity as uint8)."""
    scene = MovingImageScene("camera", size, duration, velocity=(18.0, 7.0), rotation=0.05, zoom=0.03)
    events = simulate_scene(scene, 0.0, duration, C=0.5 * (C_pos + C_neg), C_pos=C_pos, C_neg=C_neg, seed=seed)
    t = np.arange(0.0, duration + 1e-9, 1.0 / rate)
    frames = Frames(np.clip(np.rint(255 * scene.intensity(t)), 0, 255).astype(np.uint8), t)
    return events, frames


@pytest.fixture(scope="module")
def asymmetric():
    return _scene_and_frames(0.24, 0.16)


@pytest.fixture(scope="module")
def symmetric():
    return _scene_and_frames(0.2, 0.2)


# ---- the fit ------------------------------------------------------------------------------------

def test_fit_recovers_asymmetric_thresholds(asymmetric):
    events, frames = asymmetric
    fit = fit_contrast(frames, events)
    assert isinstance(fit, ContrastFit)
    assert abs(fit.c_pos / 0.24 - 1) < 0.10 and abs(fit.c_neg / 0.16 - 1) < 0.10, fit
    assert fit.c_pos > fit.c_neg                      # the asymmetry itself, not only its size
    for c, se, (lo, hi) in ((fit.c_pos, fit.c_pos_se, fit.c_pos_interval), (fit.c_neg, fit.c_neg_se, fit.c_neg_interval)):
        assert 0 < se < 0.1 * c and lo < c < hi
    inside = np.count_nonzero((frames.t >= events.t[0]) & (frames.t <= events.t[-1]))
    assert fit.C == (fit.c_pos, fit.c_neg) and fit.n_used > 1000 and fit.n_frames == inside
    text = str(fit)
    assert text.startswith(f"C+ = {fit.c_pos:.3f} ± {fit.c_pos_se:.3f}, C- = {fit.c_neg:.3f}") and f"{fit.n_used:,}" in text
    assert json.loads(json.dumps(fit.as_dict()))["c_pos"] == fit.c_pos


def test_fit_is_deterministic_and_seeded(asymmetric):
    events, frames = asymmetric
    a, b = fit_contrast(frames, events, seed=3, span="pairs"), fit_contrast(frames, events, seed=3, span="pairs")
    assert a == b
    c = fit_contrast(frames, events, seed=4, span="pairs")
    assert c.c_pos == a.c_pos and c.c_pos_se != a.c_pos_se    # only the bootstrap depends on the seed


def test_symmetric_case_agrees_with_the_single_C_fit(symmetric):
    events, frames = symmetric
    fit = fit_contrast(frames, events)
    assert abs(fit.c_pos - fit.c_neg) < 0.05 * 0.2
    assert abs(fit.c_single / 0.2 - 1) < 0.10 and min(fit.c_pos, fit.c_neg) <= fit.c_single * 1.02
    # least squares over consecutive pairs: the single C is estimate_contrast_threshold's, to rounding
    pairs = fit_contrast(frames, events, method="lsq", span="pairs", min_events=1)
    dL, n, mask = frame_log_changes(frames, events)
    assert math.isclose(pairs.c_single, estimate_contrast_threshold(dL[mask], n[mask]), rel_tol=1e-9)


def test_event_counts_split_the_net_count(asymmetric):
    events, frames = asymmetric
    dL, n, mask = frame_log_changes(frames, events)
    dL2, n_on, n_off, mask2 = frame_event_counts(frames, events)
    assert np.array_equal(dL, dL2) and np.array_equal(mask, mask2) and np.array_equal(n_on - n_off, n)
    assert n_on.min() >= 0 and n_off.min() >= 0 and n_on.sum() > 0 and n_off.sum() > 0


def test_instruments_remove_the_background_activity_bias(asymmetric):
    events, frames = asymmetric
    noisy = add_background_noise(events, 1.0, seed=5, t_start=0.0, t_end=1.0)
    plain = fit_contrast(frames, noisy, method="huber")
    iv = fit_contrast(frames, noisy, method="iv")
    # noise in the counts pulls least-squares fits towards 0; the neighbours' counts do not share it
    assert plain.c_pos < iv.c_pos and plain.c_neg < iv.c_neg
    assert abs(iv.c_pos / 0.24 - 1) < 0.10 and abs(iv.c_neg / 0.16 - 1) < 0.10, iv


def test_fit_refuses_what_it_cannot_fit(asymmetric):
    events, frames = asymmetric
    with pytest.raises(EventDataError, match="at least two"):
        fit_contrast(Frames(frames.images[:1], frames.t[:1]), events)
    with pytest.raises(EventDataError, match="sensor"):
        fit_contrast(Frames(frames.images[:, :10], frames.t), events)
    still = Frames(np.repeat(frames.images[:1], len(frames), axis=0), frames.t)
    few = events.take(np.arange(len(events)) % 1000 == 0)   # 25 events over the second
    with pytest.raises(EventDataError, match="too few|give C"):
        fit_contrast(still, few)
    with pytest.raises(EventDataError, match="method"):
        fit_contrast(frames, events, method="ransac")


# ---- C pairs in binning, integration and the solver -------------------------------------------------

def _events(n=3000, size=(6, 8), seed=0):
    rng = np.random.default_rng(seed)
    return Events(np.sort(rng.uniform(0, 1, n)), rng.integers(0, size[1], n), rng.integers(0, size[0], n),
                  rng.choice([-1, 1], n), size)


def test_binning_with_equal_pair_is_binning_with_one_C():
    ev, b = _events(), np.linspace(0, 1, 9)
    for c in (0.2, 0.3, 1.0, 1 / 3):
        assert np.array_equal(events_to_frames(ev, b, (c, c)).frames, events_to_frames(ev, b, c).frames)
        chunks = [ev.slice_time(0, 0.4), ev.slice_time(0.4, None)]
        assert np.array_equal(events_to_frames_chunked(iter(chunks), b, (c, c)).frames,
                              events_to_frames(ev, b, c).frames)


def test_binning_weighs_on_by_c_pos_and_off_by_c_neg():
    ev, b = _events(), np.linspace(0, 1, 5)
    on = events_to_frames(ev.take(ev.p > 0), b, 1.0).frames
    off = -events_to_frames(ev.take(ev.p < 0), b, 1.0).frames
    want = (0.25 * on.astype(np.float64) - 0.15 * off).astype(np.float32)
    np.testing.assert_allclose(events_to_frames(ev, b, (0.25, 0.15)).frames, want, rtol=1e-6, atol=1e-7)
    chunks = [ev.slice_time(0, 0.3), ev.slice_time(0.3, 0.7), ev.slice_time(0.7, None)]
    np.testing.assert_allclose(events_to_frames_chunked(iter(chunks), b, (0.25, 0.15)).frames, want, rtol=1e-6,
                               atol=1e-7)
    # integration of the same events agrees with the binned sums
    L = integrate_events(ev, b[1:], C=(0.25, 0.15))
    np.testing.assert_allclose(np.diff(L, axis=0, prepend=0.0), want, rtol=1e-5, atol=1e-6)


@pytest.mark.parametrize("bad", [0, -0.2, math.nan, math.inf, "0.2", (0.2,), (0.2, 0.0), (0.2, -1), (0.2, math.nan),
                                 (0.2, 0.3, 0.4), True, (True, 0.2), None, ("0.2", "0.1")])
def test_bad_C_refused_with_its_name(bad):
    with pytest.raises(EventDataError, match="C"):
        EvINRConfig(C=bad)
    if bad is not None:
        with pytest.raises(EventDataError, match="C"):
            as_thresholds(bad)
        with pytest.raises(EventDataError, match="C="):
            check_run_options(C=bad)


def test_config_with_a_C_pair_reconstructs(asymmetric):
    events, frames = asymmetric
    cfg = EvINRConfig(C=[0.24, 0.16], progress=False, hidden_features=64, min_bins=16)
    assert cfg.C == (0.24, 0.16)
    rec = reconstruct(events, frames.t[2:5], cfg)
    assert rec.frames.shape == (3, *events.sensor_size) and np.all(np.isfinite(rec.log_intensity))
    assert rec.history["config"]["C"] == (0.24, 0.16)
    # the pair changes the event frames the solver fits: not the same reconstruction as one C
    one = reconstruct(events, frames.t[2:5], EvINRConfig(C=0.2, progress=False, hidden_features=64, min_bins=16))
    assert not np.allclose(one.log_intensity, rec.log_intensity)


# ---- the command line ---------------------------------------------------------------------------

@pytest.fixture(scope="module")
def example(tmp_path_factory):
    return write_example_recording(tmp_path_factory.mktemp("c") / "rec", sensor_size=(36, 48), duration=0.4,
                                   C=0.25, frame_rate=25.0, seed=1)


def test_C_option_forms():
    parse = build_parser().parse_args
    base = ["reconstruct", "r", "--out", "o"]
    assert parse(base + ["--C", "auto"]).C == "auto"
    assert parse(base + ["--C", "0.22,0.18"]).C == (0.22, 0.18)
    assert parse(base + ["--C", "0.3"]).C == 0.3
    assert contrast_option("auto") == "auto" and contrast_option([0.2, 0.1]) == (0.2, 0.1)
    with pytest.raises(EventDataError, match="C="):
        contrast_option("AUTO")


@pytest.mark.parametrize("value", ["0.2,0", "a,b", "0.2,0.1,0.3", "0.2,", ",0.2", "0.2,inf", "autos"])
def test_bad_C_option_refused_before_reading(capsys, tmp_path, value):
    code = main(["reconstruct", str(tmp_path / "missing"), "--out", str(tmp_path / "o"), f"--C={value}", "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and "argument --C" in err and "missing" not in err.split("argument --C")[0]


def test_cli_C_auto_records_the_fit(capsys, example, tmp_path):
    out = tmp_path / "out"
    code = main(["reconstruct", str(example), "--out", str(out), "--C", "auto", "--no-video"])
    text = capsys.readouterr().out
    assert code == 0
    run = json.loads((out / "run.json").read_text())
    fit = run["C_fit"]
    assert run["C"] == [fit["c_pos"], fit["c_neg"]] and run["evinr_config"]["C"] == run["C"]
    assert run["C_source"].startswith("fitted") and fit["c_pos_se"] > 0 and fit["c_neg_se"] > 0
    assert abs(fit["c_pos"] / 0.25 - 1) < 0.15 and abs(fit["c_neg"] / 0.25 - 1) < 0.15    # simulated with C = 0.25
    assert f"C+ = {fit['c_pos']:.3f} ± {fit['c_pos_se']:.3f}" in text


def test_cli_reports_the_on_off_balance_it_applied(capsys, example, tmp_path):
    """One C given: the run says which C+ / C- the events gave (their mean the given C) and records it;
    a pair given is used as it is, with nothing to report."""
    code = main(["reconstruct", str(example), "--out", str(tmp_path / "one"), "--C", "0.25", "--no-video", "--quiet"])
    text = capsys.readouterr().out
    run = json.loads((tmp_path / "one" / "run.json").read_text())
    assert code == 0 and run["C"] == 0.25 and run["evinr_config"]["C"] == run["C_used"]
    assert np.mean(run["C_used"]) == pytest.approx(0.25)
    assert f"C+ = {run['C_used'][0]:.4f}, C- = {run['C_used'][1]:.4f}" in text and "--C 0.25,0.25" in text
    code = main(["reconstruct", str(example), "--out", str(tmp_path / "pair"), "--C", "0.25,0.25", "--no-video",
                 "--quiet"])
    assert code == 0 and "ON/OFF balance" not in capsys.readouterr().out
    assert "C_used" not in json.loads((tmp_path / "pair" / "run.json").read_text())
    # the in-memory job (denoise: every event of the window at once) reports it the same way
    code = main(["reconstruct", str(example), "--out", str(tmp_path / "mem"), "--C", "0.25", "--denoise",
                 "--no-video", "--quiet"])
    text = capsys.readouterr().out
    run = json.loads((tmp_path / "mem" / "run.json").read_text())
    assert code == 0 and run["evinr_config"]["C"] == run["C_used"] and "denoise" in run
    assert f"C+ = {run['C_used'][0]:.4f}" in text


def test_cli_C_auto_without_frames_says_what_to_do(capsys, example, tmp_path):
    folder = tmp_path / "events_only"
    shutil.copytree(example, folder)
    (folder / "images.txt").unlink()
    shutil.rmtree(folder / "images")
    code = main(["reconstruct", str(folder), "--out", str(tmp_path / "o"), "--sensor", "36x48", "--C", "auto",
                 "--quiet", "--no-video"])
    err = capsys.readouterr().err
    assert code == 2 and "auto" in err and "frame" in err and "--C 0.2" in err
    assert not (tmp_path / "o").exists()


# ---- the real chunk -----------------------------------------------------------------------------

def test_real_chunk_C_pos_and_C_neg(slider_depth_dir):
    from evinr_lite.io.readers import read_recording

    rec = read_recording(slider_depth_dir)
    fit = fit_contrast(rec.frames, rec.events)
    print(f"slider_depth chunk: {fit}")
    for c, se in ((fit.c_pos, fit.c_pos_se), (fit.c_neg, fit.c_neg_se)):
        assert math.isfinite(c) and c > 0 and math.isfinite(se) and 0 < se < c
    assert fit.n_pixels > 100 and fit.n_frames >= 2
