"""Streaming reconstruction (method/streaming.py) against the whole-sequence solve (method/solver.py).

What streaming must keep: one window gives the identical result; over several windows the networks,
their alignment, the cross-fade, the offset image and the level are the same (offset_from="span"),
or differ by exactly one offset image taken from the first window (offset_from="first_window");
each window reads only its own events; a run stopped after any window resumes to the same frames.
"""
import numpy as np
import pytest
import torch

from evinr_lite import EvINRConfig, make_scene, simulate_scene
from evinr_lite.core.events import EventDataError
from evinr_lite.evaluation.scoring import score_sequence
from evinr_lite.io.source import MemorySource
from evinr_lite.method.prepare import prepare_source, reach
from evinr_lite.method.models import FrameINR
from evinr_lite.method.solver import reconstruct
from evinr_lite.method.streaming import StreamState, stream_reconstruct
from evinr_lite.method.tonemap import tonemap_reinhard

SIZE = (24, 32)


@pytest.fixture(scope="module")
def scene_events():
    scene = make_scene("camera", sensor_size=SIZE, duration=3.0)
    return scene, simulate_scene(scene, 0.0, 3.0, C=0.2, seed=0)


def _config(**kw):
    return EvINRConfig(C=0.2, hidden_features=64, progress=False, **kw)


def _collect(parts):
    parts = list(parts)
    idx = np.concatenate([p.indices for p in parts])
    return (idx, np.concatenate([p.log_intensity for p in parts]), np.concatenate([p.frames for p in parts]), parts)


class _CountingSource(MemorySource):
    """A source that records every window it is asked for."""

    def __init__(self, events):
        super().__init__(events)
        self.asked = []

    def _read_window(self, t0, t1):
        self.asked.append((t0, t1))
        return super()._read_window(t0, t1)


@pytest.mark.parametrize("offset_from", ["span", "first_window"])
def test_one_window_is_identical_to_the_whole_sequence_solve(scene_events, offset_from):
    _, events = scene_events
    q = np.linspace(0.05, 2.95, 12)
    cfg = _config()                                   # tau 5 s: the 3 s span is one window
    whole = reconstruct(events, q, cfg, t_start=0.0, t_end=3.0)
    idx, L, frames, parts = _collect(stream_reconstruct(events, q, cfg, t_start=0.0, t_end=3.0,
                                                        offset_from=offset_from))
    assert np.array_equal(idx, np.arange(len(q)))
    np.testing.assert_array_equal(L, whole.log_intensity)
    np.testing.assert_array_equal(frames, whole.frames)


def test_many_windows_give_the_whole_sequence_result(scene_events, tmp_path):
    _, events = scene_events
    q = np.linspace(0.05, 2.95, 40)                   # some inside the overlaps, where networks are cross-faded
    cfg = _config(tau=1.0, overlap=0.25)              # 4 windows
    whole = reconstruct(events, q, cfg, t_start=0.0, t_end=3.0)
    assert len(whole.windows) == 4
    source = _CountingSource(events)
    idx, L, frames, parts = _collect(stream_reconstruct(source, q, cfg, t_start=0.0, t_end=3.0, workdir=tmp_path))
    assert np.array_equal(idx, np.arange(len(q)))
    # same networks, alignment, cross-fade, offset image and level: equal up to float32 rounding
    np.testing.assert_allclose(L, whole.log_intensity, rtol=0, atol=1e-4 * np.abs(whole.log_intensity).max())
    np.testing.assert_allclose(frames, whole.frames, rtol=0, atol=1e-4)
    # each window read only its own events and the background filter's reach (never the whole
    # recording); before them, the two counting passes of method/prepare.prepare_source (raw counts for
    # the hot pixels, filtered ones for the ON/OFF balance and lam) read the span in chunks of tau, with the
    # span read once in between for the filter's window (background="auto", method/background.py: a span of
    # at most 8 s is measured whole), and after them, on a span of at most 3 s, the static image's coarse
    # part (method/coarse.py) reads it once more
    assert len(source.asked) == 4 + 3 + 1 + 3 + 3
    used = prepare_source(MemorySource(events), 0.0, 3.0, cfg)[0]
    r = reach(used.background_dt) if used.background == "filter" else 0.0
    assert [t1 - t0 > cfg.tau + 2 * r + 1e-6 for t0, t1 in source.asked] == [False] * 3 + [True] + [False] * 10
    assert (tmp_path / "log_intensity.f32").stat().st_size == len(q) * SIZE[0] * SIZE[1] * 4   # the spill


def test_every_long_phase_shows_progress_and_quiet_shows_none(scene_events, tmp_path, capsys):
    """A long recording spends much of its time outside training (at 1280x720 for 20 s: 29 s counting and
    filtering before the first window, 24 s on the offset and the frames after the last): each phase has
    its own bar, each runs to its end, and progress=False prints none of them."""
    _, events = scene_events
    q = np.linspace(0.05, 2.95, 12)
    cfg = _config(tau=1.0, overlap=0.25)                 # 4 windows: the counting passes read in chunks
    ends = {"counting events": "3.0/3.0 s", "filtering background activity": "3.0/3.0 s",
            "EvINR windows": "4/4", "EvINR offset": "2/2",   # one offset image, then the coarse part (3 s span)
            "EvINR frames": "12/12"}
    for progress in (True, False):
        list(stream_reconstruct(MemorySource(events), q, cfg, t_start=0.0, t_end=3.0, workdir=tmp_path / str(progress),
                                progress=progress))
        lines = capsys.readouterr().err.replace("\r", "\n").splitlines()
        for bar, end in ends.items():
            shown = [line for line in lines if line.startswith(bar)]
            assert bool(shown) == progress, (bar, progress, lines[-20:])
            assert not progress or any(end in line for line in shown), (bar, end, shown[-3:])


def test_first_window_offset_differs_from_the_whole_sequence_solve_by_one_image(scene_events):
    scene, events = scene_events
    q = np.linspace(0.05, 2.95, 40)
    cfg = _config(tau=1.0, overlap=0.25)
    whole = reconstruct(events, q, cfg, t_start=0.0, t_end=3.0)
    parts = []
    for part in stream_reconstruct(events, q, cfg, t_start=0.0, t_end=3.0, offset_from="first_window"):
        parts.append(part)                            # each window's frames are final as it finishes
        assert part.window[0] == len(parts) - 1
    idx, L, frames, _ = _collect(parts)
    assert np.array_equal(idx, np.arange(len(q)))
    diff = L - whole.log_intensity
    spread = np.abs(diff - diff.mean(axis=0)).max()
    assert spread < 1e-3 * np.abs(whole.log_intensity).max(), spread
    # quality against the truth: within 0.02 CLAHE-SSIM of the whole-sequence solve
    gt = tonemap_reinhard(np.stack([scene.log_intensity(t) for t in q])).astype(np.float32)
    s_whole = score_sequence(whole.frames, q, gt, q, "clahe", lpips_model=False)["ssim"]
    s_stream = score_sequence(frames, q, gt, q, "clahe", lpips_model=False)["ssim"]
    assert s_stream > s_whole - 0.02, (s_stream, s_whole)


@pytest.mark.parametrize("offset_from", ["span", "first_window"])
def test_a_stopped_run_resumes_to_the_same_frames(scene_events, tmp_path, offset_from):
    _, events = scene_events
    q = np.linspace(0.05, 2.95, 25)
    cfg = _config(tau=1.0, overlap=0.25)
    run = dict(t_start=0.0, t_end=3.0, offset_from=offset_from)
    _, L_full, _, _ = _collect(stream_reconstruct(events, q, cfg, **run))
    states = []
    stream = stream_reconstruct(events, q, cfg, **run, workdir=tmp_path / "work",
                                on_state=lambda s: (s.save(tmp_path / "state.npz"), states.append(s.next_window)))
    handed = []
    if offset_from == "span":                         # nothing is handed out before the last window: stop in between
        stream = iter(stream_reconstruct(events, q, cfg, **run, workdir=tmp_path / "work",
                                         on_state=lambda s: (s.save(tmp_path / "state.npz"),
                                                             states.append(s.next_window),
                                                             _stop_after(s, 2))))
        with pytest.raises(_Stop):
            next(stream)
    else:
        handed += [next(stream), next(stream), next(stream)]
        stream.close()                                # "killed" after handing out three windows
    state = StreamState.load(tmp_path / "state.npz")
    assert state.next_window == 2 and states[-1] == 2
    idx, L, _, _ = _collect(stream_reconstruct(events, q, cfg, **run, workdir=tmp_path / "work", state=state))
    if offset_from == "span":
        np.testing.assert_array_equal(idx, np.arange(len(q)))
        np.testing.assert_array_equal(L, L_full)
    else:                                             # the windows after the saved state come again, the same
        np.testing.assert_array_equal(L, L_full[idx])
        assert idx[0] == handed[2].indices[0] and idx[-1] == len(q) - 1
    # a state from another plan of windows is refused, not silently mixed in
    with pytest.raises(EventDataError, match="another plan"):
        next(stream_reconstruct(events, q, _config(tau=1.5, overlap=0.25), **run, state=state))


class _Stop(Exception):
    pass


def _stop_after(state, k):
    if state.next_window == k:
        raise _Stop


def test_network_k_alone_is_network_k_of_the_ensemble():
    windows = [[0.0, 1.0], [0.75, 2.0], [1.75, 3.0]]
    ensemble = FrameINR(SIZE, windows, 32, 2, 30.0, 10.0, seed=5)
    alone = FrameINR(SIZE, windows[2:], 32, 2, 30.0, 10.0, seed=5, first_index=2)
    for name, value in alone.state_dict().items():
        assert torch.equal(value, ensemble.state_dict()[name][2:3]), name
    first = FrameINR(SIZE, windows[:1], 32, 2, 30.0, 10.0, seed=5)      # network 0 keeps the old seeding
    assert torch.equal(first.weights[1], ensemble.weights[1][:1])
    assert not torch.equal(ensemble.weights[1][0], ensemble.weights[1][1])


def test_bad_requests_are_refused_before_any_training(scene_events):
    _, events = scene_events
    with pytest.raises(EventDataError, match="anchored"):
        next(stream_reconstruct(events, [0.5], _config(anchor="first")))
    with pytest.raises(EventDataError, match="offset_from"):
        next(stream_reconstruct(events, [0.5], _config(), offset_from="middle"))
    with pytest.raises(EventDataError, match="sorted"):
        next(stream_reconstruct(events, [0.6, 0.5], _config()))
    with pytest.raises(EventDataError, match="outside"):
        next(stream_reconstruct(events, [5.0], _config(), t_start=0.0, t_end=3.0))


def recording_file(path, seconds=10.0, size=SIZE):
    """A canonical file of a 2 s scene repeated (as benchmarks/scale.py builds long recordings)."""
    from evinr_lite.io.canonical import CanonicalWriter

    ev = simulate_scene(make_scene("camera", sensor_size=size, duration=2.0), C=0.2, seed=0)
    with CanonicalWriter(path, sensor_size=size, C=0.2) as w:
        for k in range(int(np.ceil(seconds / 2.0))):
            keep = ev.t + 2.0 * k < seconds
            w.add_events(ev.t[keep] + 2.0 * k, ev.x[keep], ev.y[keep], ev.p[keep])
    return path


def stop_command_after(monkeypatch, k: int):
    """StreamState.save patched so that a streamed command stops (KeyboardInterrupt) once the state after
    window k is saved, as a killed process would; returns the original save (to set back)."""
    save = StreamState.save

    def killed(self, file):
        save(self, file)
        if self.next_window == k:
            raise KeyboardInterrupt

    monkeypatch.setattr(StreamState, "save", killed)
    return save


def test_a_killed_command_resumes_without_recomputing_finished_windows(tmp_path, monkeypatch):
    from PIL import Image

    from evinr_lite.apps.recon_job import run_reconstruct
    from evinr_lite.method import streaming

    path = recording_file(tmp_path / "rec.h5")
    quiet = dict(fps=5, video=False, progress=False, log=lambda *a: None)
    whole = run_reconstruct(path, tmp_path / "whole", **quiet)
    assert len(whole["times_s"]) >= 45
    trained = []
    train = streaming.train_window
    monkeypatch.setattr(streaming, "train_window", lambda ev, w, k, cfg: (trained.append(k), train(ev, w, k, cfg))[1])
    save = stop_command_after(monkeypatch, 2)
    with pytest.raises(KeyboardInterrupt):
        run_reconstruct(path, tmp_path / "out", **quiet)
    assert trained == [0, 1]
    assert not (tmp_path / "out").exists() and (tmp_path / ".out.resume" / "state.npz").is_file()
    assert not list(tmp_path.glob(".out.partial-*"))           # the staging folder is gone, the lock too
    assert not (tmp_path / ".out.lock").exists()
    monkeypatch.setattr(StreamState, "save", save)
    with pytest.raises(EventDataError, match="another input or other settings"):   # not these settings' state
        run_reconstruct(path, tmp_path / "out", **{**quiet, "fps": 4}, resume=True)
    assert (tmp_path / ".out.resume").is_dir()                 # refused, nothing removed
    run = run_reconstruct(path, tmp_path / "out", **quiet, resume=True)
    assert trained == [0, 1, 2]                                # only the third window was trained again
    assert not (tmp_path / ".out.resume").exists()             # committed: the state is removed
    assert run["times_s"] == whole["times_s"]
    for name in ("frame_00000.png", "frame_00024.png", "frame_00044.png"):
        a = np.asarray(Image.open(tmp_path / "whole" / "frames" / name))
        b = np.asarray(Image.open(tmp_path / "out" / "frames" / name))
        np.testing.assert_array_equal(a, b)


def test_the_command_saves_the_state_after_every_window_but_the_last(tmp_path, monkeypatch):
    # the last window's state would spare a resume only that window's training, and writing it (the offset
    # grid) cost a third of that at 1280x720: the command skips it
    from evinr_lite.apps.recon_job import run_reconstruct

    path = recording_file(tmp_path / "rec.h5")
    saved = []
    save = StreamState.save
    monkeypatch.setattr(StreamState, "save", lambda self, file: (saved.append((self.next_window, len(self.windows))),
                                                                 save(self, file))[1])
    run_reconstruct(path, tmp_path / "out", fps=5, video=False, progress=False, log=lambda *a: None)
    n = saved[0][1]
    assert n >= 3 and [k for k, _ in saved] == list(range(1, n))
