"""APS frames as anchors (EvINRConfig(anchor=...), method/anchor.py) and the complementary filter baseline."""
import json
import math
import shutil

import numpy as np
import pytest

from evinr_lite import EventDataError, Events, integrate_events
from evinr_lite.apps.cli import main
from evinr_lite.apps.recon_job import score_recording
from evinr_lite.core.frames import Frames, to_uint8
from evinr_lite.evaluation.scoring import score_sequence
from evinr_lite.method import EvINRConfig, reconstruct, reconstruct_baseline
from evinr_lite.method.anchor import frame_log, held_out, linear_frames
from evinr_lite.method.baselines import complementary_filter
from evinr_lite.sim.recordings import write_example_recording
from evinr_lite.sim.scenes import ObjectOverBackgroundScene
from evinr_lite.sim.simulate import simulate_scene

FAST = dict(C=0.2, progress=False, hidden_features=64)


@pytest.fixture(scope="module")
def static_cam():
    """A small static-camera scene: a disc crossing a static brick wall; frames at 10 per second."""
    scene = ObjectOverBackgroundScene("brick", "coffee", (40, 56), 1.0)
    events = simulate_scene(scene, 0.0, 1.0, C=0.2, seed=0)
    ft = np.arange(0.0, 1.0 + 1e-9, 0.1)
    gt = scene.intensity(ft).astype(np.float32)
    return events, Frames(to_uint8(gt), ft), gt


def plain_ssim(frames, times, gt, sel):
    return score_sequence(frames[sel], times[sel], gt[sel], times[sel], "none", lpips_model=False)["ssim"]


# ---- anchored reconstruction -------------------------------------------------------------------

def test_first_recovers_the_static_background(static_cam):
    events, frames, gt = static_cam
    ft = frames.t
    rec = reconstruct(events, ft, EvINRConfig(anchor="first", **FAST), frames=frames)
    np.testing.assert_array_equal(rec.anchor_times, ft[:1])
    held = np.flatnonzero(held_out(ft, rec.anchor_times))
    np.testing.assert_array_equal(held, np.arange(1, len(ft)))
    anchored = plain_ssim(rec.frames, ft, gt, held)
    events_only = plain_ssim(reconstruct(events, ft, EvINRConfig(**FAST)).frames, ft, gt, held)
    assert anchored > 0.8 and anchored > events_only + 0.3, (anchored, events_only)
    # at the anchor the output is the frame itself (to rounding of uint8 and eps)
    np.testing.assert_allclose(rec.log_intensity[0], frame_log(frames.images[0]), atol=1e-3)
    # querying a subset of the times gives the same frames up to float32 rounding: the hidden features
    # differ by ~1e-6 with the batch's shape, and the closed-form head's weights (|w| ~ 100) carry that
    # to ~1e-4 (measured 2.2e-4 on this machine's oneDNN kernels)
    np.testing.assert_allclose(rec.frames_at(ft[3:5]), rec.frames[3:5], atol=1e-3)
    assert rec.history["anchor"]["n_held_out"] == len(ft) - 1
    # events-only records no anchors
    assert reconstruct(events, ft, EvINRConfig(**FAST)).anchor_times.size == 0


def test_all_holds_out_every_other_frame_and_smoothing_interpolates(static_cam):
    events, frames, gt = static_cam
    ft = frames.t
    hard = reconstruct(events, ft, EvINRConfig(anchor="all", anchor_smoothing=0.0, **FAST), frames=frames)
    np.testing.assert_array_equal(hard.anchor_times, ft[::2])
    np.testing.assert_array_equal(np.flatnonzero(held_out(ft, hard.anchor_times)), np.arange(1, len(ft), 2))
    # smoothing 0: the output passes through every anchor frame
    np.testing.assert_allclose(hard.at(ft[::2]), frame_log(frames.images[::2]), atol=1e-3)
    # large smoothing: one offset per pixel, nearly the same at every anchor time
    stiff = reconstruct(events, ft, EvINRConfig(anchor="all", anchor_smoothing=1e6, **FAST), frames=frames)
    v = stiff.anchor.values
    assert np.abs(v - v.mean(axis=0)).max() < 1e-3 < np.abs(hard.anchor.values - hard.anchor.values.mean(0)).max()
    every3 = reconstruct(events, ft, EvINRConfig(anchor="all", anchor_every=3, **FAST), frames=frames)
    np.testing.assert_array_equal(every3.anchor_times, ft[::3])
    odd = np.arange(1, len(ft), 2)
    assert plain_ssim(hard.frames, ft, gt, odd) > 0.8


def test_anchor_frames_are_not_scored(static_cam):
    events, frames, gt = static_cam
    ft = frames.t
    for mode, n_scored in (("first", len(ft) - 1), ("all", len(ft) // 2)):
        rec = reconstruct(events, ft, EvINRConfig(anchor=mode, **FAST), frames=frames)
        scores = score_recording(rec, frames)
        assert scores["none"]["n_frames"] == scores["clahe"]["n_frames"] == n_scored
        scored_t = np.asarray(scores["none"]["per_frame_t_s"])
        assert not np.isin(scored_t, rec.anchor_times).any()
    rec = reconstruct(events, ft, EvINRConfig(**FAST))
    assert score_recording(rec, frames)["none"]["n_frames"] == len(ft)


def test_errors_name_the_fix(static_cam):
    events, frames, _ = static_cam
    ft = frames.t
    with pytest.raises(EventDataError, match=r"needs the APS frames: pass frames="):
        reconstruct(events, ft, EvINRConfig(anchor="first", **FAST))
    late = Frames(frames.images[:2], np.array([5.0, 6.0]))
    with pytest.raises(EventDataError, match=r"no APS frame lies inside .* choose a window"):
        reconstruct(events, ft, EvINRConfig(anchor="first", **FAST), frames=late)
    small = Frames(frames.images[:, :20], ft)
    with pytest.raises(EventDataError, match=r"same H x W as the events"):
        reconstruct(events, ft, EvINRConfig(anchor="first", **FAST), frames=small)
    with pytest.raises(EventDataError, match=r"anchor is 'none'.*anchor='first'"):
        reconstruct(events, ft, EvINRConfig(**FAST), frames=frames)
    with pytest.raises(EventDataError, match=r"Frames\(images, t\)"):
        reconstruct(events, ft, EvINRConfig(anchor="first", **FAST), frames=frames.images)
    for bad in ({"anchor": "last"}, {"anchor_every": 0}, {"anchor_smoothing": -1.0}, {"anchor_every": 1.5}):
        with pytest.raises(EventDataError, match="anchor"):
            EvINRConfig(**bad)


# ---- the complementary filter ------------------------------------------------------------------

def tiny(seed=0, n=40, H=3, W=4):
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0.02, 0.3, n))
    ev = Events(t, rng.integers(0, W, n), rng.integers(0, H, n), rng.choice([-1, 1], n), (H, W))
    frames = Frames(rng.uniform(0.1, 0.9, (3, H, W)).astype(np.float32), np.array([0.0, 0.11, 0.23]))
    return ev, frames


def euler_reference(ev, frames, times, C, alpha, dt=2e-6):
    """dL/dt = E - alpha (L - L_F) stepped with a tiny dt: independent of the exact solution."""
    LF = frame_log(frames.images)
    L = LF[0].copy()
    out, t, i, q = [], frames.t[0], 0, 0
    times = np.sort(times)
    while q < len(times):
        while i < len(ev) and ev.t[i] <= t:
            L[ev.y[i], ev.x[i]] += C * ev.p[i]
            i += 1
        if t >= times[q] - dt / 2:
            out.append(L.copy())
            q += 1
            continue
        cur = LF[np.searchsorted(frames.t, t, side="right") - 1]
        L += -alpha * (L - cur) * dt
        t += dt
    return np.array(out)


def test_cf_matches_the_per_event_loop_and_a_brute_force_ode():
    ev, frames = tiny()
    q = np.array([0.05, 0.11, 0.17, 0.29, 0.0, ev.t[7]])
    a = complementary_filter(ev, frames, q, C=0.2, gain=6.0)
    b = complementary_filter(ev, frames, q, C=0.2, gain=6.0, method="per_event")
    np.testing.assert_allclose(a, b, rtol=1e-10, atol=1e-12)
    order = np.argsort(q)
    ref = euler_reference(ev, frames, q[order], 0.2, 6.0)
    np.testing.assert_allclose(a[order], ref, atol=2e-3)


def test_cf_with_gain_zero_is_integration_from_the_first_frame():
    ev, frames = tiny(seed=1)
    q = np.linspace(0.0, 0.3, 7)
    L = complementary_filter(ev, frames, q, C=0.2, gain=0.0)
    np.testing.assert_allclose(L, frame_log(frames.images[0]) + integrate_events(ev, q, C=0.2), atol=1e-12)


def test_cf_without_events_relaxes_to_the_frames_at_rate_gain():
    _, frames = tiny(seed=2)
    none = Events(np.zeros(0), np.zeros(0, int), np.zeros(0, int), np.zeros(0, int), frames.size)
    alpha = 2 * math.pi
    t = np.array([0.05, 0.12, 0.17, 0.22])                    # between frame 1 (0.11 s) and frame 2 (0.23 s)
    L = complementary_filter(none, frames, t, gain=alpha)
    LF = frame_log(frames.images)
    np.testing.assert_allclose(L[0], LF[0])                    # still on frame 0
    ratio = (L[1:] - LF[1]) / (LF[0] - LF[1])
    np.testing.assert_allclose(ratio, np.exp(-alpha * (t[1:] - 0.11))[:, None, None] * np.ones_like(ratio), rtol=1e-9)


def test_cf_as_a_baseline_and_its_errors():
    ev, frames = tiny(seed=3)
    q = np.array([0.05, 0.2])
    b = reconstruct_baseline(ev, q, "complementary", C=0.2, frames=frames, gain=3.0)
    np.testing.assert_allclose(b.frames, linear_frames(complementary_filter(ev, frames, q, 0.2, 3.0)))
    np.testing.assert_allclose(b.frames_at(q), b.frames, atol=1e-6)
    assert b.method == "complementary" and b.params["gain"] == 3.0
    with pytest.raises(EventDataError, match="needs APS frames"):
        reconstruct_baseline(ev, q, "complementary", C=0.2)
    with pytest.raises(TypeError, match="takes no frames"):
        reconstruct_baseline(ev, q, "hf", C=0.2, frames=frames)
    with pytest.raises(EventDataError, match="before the filter's start"):
        complementary_filter(ev, Frames(frames.images, frames.t + 0.1), q)
    with pytest.raises(EventDataError, match="same camera"):
        complementary_filter(ev, Frames(frames.images[:, :2], frames.t), q)


# ---- the command line --------------------------------------------------------------------------

@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    return write_example_recording(tmp_path_factory.mktemp("anchor") / "rec", sensor_size=(24, 32), duration=0.3,
                                   C=0.25, frame_rate=20.0, seed=0)


def test_cli_anchor_first_writes_the_anchors_into_run_json(recording, tmp_path, capsys):
    out = tmp_path / "out"
    code = main(["reconstruct", str(recording), "--out", str(out), "--anchor", "first", "--C", "0.25", "--quiet", "--no-video"])
    text = capsys.readouterr()
    assert code == 0, text
    run = json.loads((out / "run.json").read_text())
    a = run["anchor"]
    window_frames = np.array(a["frame_times_s"])
    assert a["mode"] == "first" and a["anchor_times_s"] == [window_frames[0]]
    assert a["n_scored"] == run["scores"]["none"]["n_frames"] == len(window_frames) - 1
    assert "anchored (first) on 1 APS frame(s)" in text.out
    assert main(["reconstruct", "--help"]) == 0 and "--anchor" in capsys.readouterr().out


def test_cli_anchor_without_frames_names_the_fix(recording, tmp_path, capsys):
    bare = tmp_path / "bare"
    shutil.copytree(recording, bare)
    (bare / "images.txt").unlink()
    shutil.rmtree(bare / "images")
    code = main(["reconstruct", str(bare), "--out", str(tmp_path / "o"), "--anchor", "first", "--sensor", "24x32", "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and "needs APS frames" in err and "--anchor none" in err, err
    assert not (tmp_path / "o").exists()
