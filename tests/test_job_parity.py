"""The streamed job and the in-memory job give the same run folder for the same options: the same
timestamps, the same frames (to one grey level: float rounding of two equal solves), the same log
intensities and scores, and the same refusals. A difference between the two found a streamed run that
lost a frame asked for twice (tests/test_log_intensity_export.py)."""
from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image

import evinr_lite.apps.recon_job as recon_job
from evinr_lite.core.events import EventDataError
from evinr_lite.io.export import LOG_INTENSITY_FILE, read_log_intensity
from evinr_lite.sim.recordings import write_example_recording

CASES = [dict(fps=33.3), dict(at=[0.1, 0.1, 0.3]), dict(t_start=0.2, t_end=0.5, fps=7), dict(at=[0.25]),
         dict(t_end=0.31, at=[0.3, 0.31]), dict(t_start=0.05)]


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    return write_example_recording(tmp_path_factory.mktemp("parity") / "rec", sensor_size=(30, 40), duration=0.6,
                                   C=0.25, frame_rate=20.0, seed=4)


def _run(recording, out, streamed: bool, monkeypatch, **opts):
    with monkeypatch.context() as m:
        if not streamed:
            m.setattr(recon_job, "streamable", lambda options: False)
        run = recon_job.run_reconstruct(recording, out, C=0.25, video=False, progress=False, save_log=True,
                                        log=lambda *a: None, **opts)
    pngs = np.stack([np.asarray(Image.open(p)) for p in sorted((out / "frames").glob("frame_*.png"))])
    return run, pngs, (out / "timestamps.txt").read_text(), read_log_intensity(out / LOG_INTENSITY_FILE)[0]


@pytest.mark.parametrize("opts", CASES, ids=lambda o: ",".join(f"{k}={v}" for k, v in o.items()) or "defaults")
def test_streamed_and_in_memory_runs_agree(recording, tmp_path, monkeypatch, opts):
    s_run, s_png, s_t, s_L = _run(recording, tmp_path / "s", True, monkeypatch, **opts)
    m_run, m_png, m_t, m_L = _run(recording, tmp_path / "m", False, monkeypatch, **opts)
    assert s_t == m_t and s_run["n_frames_written"] == m_run["n_frames_written"] == len(s_png) == len(m_png)
    assert np.abs(s_png.astype(int) - m_png.astype(int)).max() <= 1
    np.testing.assert_allclose(s_L, m_L, atol=1e-3)
    assert set(s_run["files"]) == set(m_run["files"])
    if "scores" in m_run:
        # the scored frames are the same solve's up to float rounding (the in-memory job queries the network at
        # the frames' times, the streamed one takes them from its batches); CLAHE equalises 8-bit images, where a
        # rounding that crosses a grey level moves its SSIM by about 1e-4 (1.3e-4 seen with fps=33.3)
        for eq, tol in (("none", 1e-4), ("clahe", 5e-4)):
            assert s_run["scores"][eq]["ssim"] == pytest.approx(m_run["scores"][eq]["ssim"], abs=tol)
    assert json.loads((tmp_path / "s" / "run.json").read_text())["times_s"] == m_run["times_s"]


def test_both_jobs_refuse_a_time_outside_the_events(recording, tmp_path, monkeypatch):
    for streamed in (True, False):
        with pytest.raises(EventDataError, match="outside the reconstructed window"):
            _run(recording, tmp_path / f"o{streamed}", streamed, monkeypatch, at=[0.0, 0.3])
        assert not (tmp_path / f"o{streamed}").exists()


def test_a_pause_without_events_is_reconstructed_by_both_jobs(tmp_path, monkeypatch):
    """A recording that pauses longer than a network's window (the sensor covered, two takes in one file):
    the streamed job refused the empty window, the in-memory one took it. Now both do, alike, and the
    frames stay put while nothing fires (the event model: no event, no change) once the INR's temporal
    smoothness (a few seconds at the first layer's 5 per second) has let go of the takes."""
    from evinr_lite import make_scene, simulate_scene

    ev = simulate_scene(make_scene("camera", sensor_size=(30, 40), duration=1.0), C=0.25, seed=2)
    take = np.stack([ev.t, ev.x, ev.y, ev.p], axis=1)
    path = tmp_path / "two_takes.npy"
    np.save(path, np.concatenate([take, take + [20.0, 0, 0, 0]]))        # nothing between 1 s and 20 s
    opts = dict(sensor_size=(30, 40), fps=2.0)
    s_run, s_png, s_t, s_L = _run(path, tmp_path / "s", True, monkeypatch, **opts)
    m_run, m_png, m_t, m_L = _run(path, tmp_path / "m", False, monkeypatch, **opts)
    assert s_t == m_t and len(s_png) == len(m_png) == s_run["n_frames_written"]
    assert np.abs(s_png.astype(int) - m_png.astype(int)).max() <= 1
    np.testing.assert_allclose(s_L, m_L, atol=1e-3)
    times = np.asarray(s_run["times_s"])
    pause = (times > 7.0) & (times < 14.0)                                # 6 s from either take
    assert pause.sum() >= 10
    assert np.abs(np.diff(s_L[pause], axis=0)).max() < 1e-3          # no event, no change
    assert np.abs(s_L[0] - s_L[pause][0]).max() > 0.05 and np.abs(s_L[-1] - s_L[pause][-1]).max() > 0.05


def test_a_window_past_the_events_is_noted_by_both_jobs(recording, tmp_path, monkeypatch):
    """--end (or --start) seconds beyond the recording is taken (the frames there hold still) and noted,
    so a typo in the window does not pass unseen."""
    for streamed in (True, False):
        said = []
        with monkeypatch.context() as m:
            if not streamed:
                m.setattr(recon_job, "streamable", lambda options: False)
            recon_job.run_reconstruct(recording, tmp_path / f"o{streamed}", C=0.25, video=False, progress=False,
                                      t_end=5.0, fps=2, log=said.append)
        notes = [s for s in said if s.startswith("note: the window")]
        assert len(notes) == 1 and "s after the last" in notes[0] and "before" not in notes[0], said
        said.clear()
        with monkeypatch.context() as m:
            if not streamed:
                m.setattr(recon_job, "streamable", lambda options: False)
            recon_job.run_reconstruct(recording, tmp_path / f"p{streamed}", C=0.25, video=False, progress=False,
                                      t_end=0.5, fps=5, log=said.append)
        assert not [s for s in said if s.startswith("note: the window")], said


def test_both_jobs_record_and_report_the_background_window_auto_chose(recording, tmp_path, monkeypatch):
    """run.json says which background filter ran (what background="auto" chose), in its settings and in the
    config it records, the same for both jobs, and the log says it once; a streamed run recorded the
    config as given ("auto") before, so its run.json could not reproduce the filter."""
    got = {}
    for streamed in (True, False):
        lines = []
        with monkeypatch.context() as m:
            if not streamed:
                m.setattr(recon_job, "streamable", lambda options: False)
            run = recon_job.run_reconstruct(recording, tmp_path / f"b{streamed}", C=0.25, video=False, progress=False,
                                            log=lines.append, fps=10)
        saved = json.loads((tmp_path / f"b{streamed}" / "run.json").read_text())
        used = saved["background_used"]
        assert used["background"] in ("filter", "keep")
        assert (used["background_dt"] is None) == (used["background"] == "keep")
        assert saved["evinr_config"]["background"] == used["background"]
        if used["background"] == "filter":
            assert saved["evinr_config"]["background_dt"] == used["background_dt"]
        assert sum(("background filter" in ln or "background activity filtered" in ln) for ln in lines) == 1
        got[streamed] = used
        assert run["background_used"] == used
    assert got[True] == got[False]
