"""The evinr-lite command end to end on generated recordings, including every bad-input case."""
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from evinr_lite import read_recording
from evinr_lite.apps.cli import main
from evinr_lite.evaluation import error_parts
from evinr_lite.sim.recordings import write_example_recording

ROOT = Path(__file__).resolve().parents[1]
FAST = ["--iters", "4", "--quiet"]


@pytest.fixture(scope="module")
def ijrr_folder(tmp_path_factory):
    """A small synthetic recording with frames (IJRR layout), 24x32, 0.3 s, frames every 50 ms."""
    return write_example_recording(tmp_path_factory.mktemp("rec") / "example", sensor_size=(24, 32),
                                   duration=0.3, C=0.25, frame_rate=20.0, seed=0)


@pytest.fixture(scope="module")
def aedat4_file(ijrr_folder, tmp_path_factory):
    """The same events as an AEDAT4 file written by faery (no frames), on an absolute clock."""
    faery = pytest.importorskip("faery")
    ev = read_recording(ijrr_folder).events
    packet = np.zeros(len(ev), dtype=faery.EVENTS_DTYPE)
    packet["t"] = np.round(ev.t * 1e6).astype(np.uint64) + 1_650_000_000_000_000
    packet["x"], packet["y"], packet["on"] = ev.x, ev.y, ev.p > 0
    path = tmp_path_factory.mktemp("aedat") / "example.aedat4"
    faery.events_stream_from_array(packet, dimensions=(32, 24)).to_file(path)
    return path


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def assert_error(capsys, argv, pattern):
    import re

    code, out, err = run(capsys, *argv)
    assert code == 2, (code, out, err)
    assert err.startswith("evinr-lite: error: ") and "Traceback" not in err, err
    assert re.search(pattern, err), err
    return err


# ---- info --------------------------------------------------------------------------------------

def test_info_text_and_json(capsys, ijrr_folder):
    rec = read_recording(ijrr_folder)
    code, out, _ = run(capsys, "info", ijrr_folder)
    assert code == 0
    assert "format        ijrr" in out and "sensor        24x32 (H x W)" in out
    assert f"events        {len(rec.events):,}" in out and f"frames        {len(rec.frames)} of 24x32" in out
    code, out, _ = run(capsys, "info", ijrr_folder, "--json")
    info = json.loads(out)
    assert info["n_events"] == len(rec.events) and info["n_frames"] == len(rec.frames)
    assert info["on_fraction"] == pytest.approx(np.mean(rec.events.p > 0))
    assert info["event_rate_per_s"] == pytest.approx(len(rec.events) / rec.events.duration)
    assert info["duration_s"] == pytest.approx(rec.events.t[-1] - rec.events.t[0])


def test_info_vendor_file_and_npy(capsys, aedat4_file, tmp_path):
    code, out, _ = run(capsys, "info", aedat4_file)
    assert code == 0 and "format        aedat4" in out and "t_origin = 1650000000 s" in out and "frames        none" in out
    npy = tmp_path / "events.npy"
    np.save(npy, np.array([[0.1, 1, 2, 1], [0.2, 3, 4, -1]]))
    assert_error(capsys, ["info", npy], r"does not record the sensor size.*--sensor HxW")
    code, out, _ = run(capsys, "info", npy, "--sensor", "10x10")
    assert code == 0 and "sensor        10x10" in out and "events        2" in out


# ---- reconstruct -------------------------------------------------------------------------------

def test_reconstruct_with_ground_truth(capsys, ijrr_folder, tmp_path):
    out_dir = tmp_path / "out"
    code, out, _ = run(capsys, "reconstruct", ijrr_folder, "--out", out_dir, "--C", "0.25", *FAST)
    assert code == 0
    rec = read_recording(ijrr_folder)
    lo, hi = rec.events.t[0], rec.events.t[-1]
    gt_t = rec.frames.t[(rec.frames.t >= lo) & (rec.frames.t <= hi)]
    pngs = sorted((out_dir / "frames").glob("frame_*.png"))
    assert len(pngs) == len(gt_t) >= 3                     # default: the ground-truth frame times
    stamps = np.loadtxt(out_dir / "timestamps.txt")[:, 1]
    np.testing.assert_allclose(stamps, gt_t, atol=1e-9)
    assert Image.open(out_dir / "reconstruction.gif").n_frames == len(gt_t)
    assert (out_dir / "reconstruction.mp4").stat().st_size > 0
    metrics = json.loads((out_dir / "metrics.json").read_text())
    assert set(metrics["protocols"]) == {"none", "clahe"}
    assert "clahe" in metrics["protocols"]["clahe"]["protocol"].lower()
    assert metrics["protocols"]["none"]["n_frames"] == len(gt_t)
    # the scores describe the written images: recompute MSE (no equalisation) from the PNGs
    pred = np.stack([np.asarray(Image.open(p), np.float64) / 255 for p in pngs])
    gt = np.stack([np.asarray(Image.open(p), np.float64) / 255 for p in sorted((out_dir / "gt").glob("frame_*.png"))])
    assert np.mean((pred - gt) ** 2) == pytest.approx(metrics["protocols"]["none"]["mse"], abs=2e-3)
    # and what that MSE is made of: the same images with the level set from the truth (evaluation.error_parts)
    none = metrics["protocols"]["none"]
    parts = error_parts(pred, gt)
    assert none["mse_at_level"] == pytest.approx(parts["mse_at_level"], abs=2e-3)
    assert none["level_gain"] == pytest.approx(parts["gain"], rel=0.02) and 0 <= none["static_coarse"] <= none["mse_at_level"]
    assert "at the truth's level, gain" in out
    rows = (out_dir / "metrics.csv").read_text().splitlines()
    assert rows[0].startswith("gt_index,t_s,mse_none,ssim_none,mse_clahe,ssim_clahe") and len(rows) == len(gt_t) + 1
    run_json = json.loads((out_dir / "run.json").read_text())
    assert run_json["C"] == 0.25 and run_json["format"] == "ijrr" and run_json["n_frames_written"] == len(gt_t)
    summary = out.strip().splitlines()[-1]
    assert summary.startswith(f"wrote {len(gt_t)} frames to {out_dir}/") and "MSE" in summary and "clahe" in summary
    assert not list(tmp_path.glob(".out.partial-*"))


def test_reconstruct_vendor_file_at_fps_in_a_window(capsys, aedat4_file, tmp_path):
    out_dir = tmp_path / "fps"
    code, out, _ = run(capsys, "reconstruct", aedat4_file, "--out", out_dir, "--fps", "40", "--start", "0.05",
                       "--end", "0.25", "--no-video", *FAST)
    assert code == 0
    stamps = np.loadtxt(out_dir / "timestamps.txt")[:, 1]
    assert len(stamps) == 8 and np.all((stamps > 0.05) & (stamps < 0.25))     # 0.2 s x 40 per second
    np.testing.assert_allclose(np.diff(stamps), 1 / 40)
    assert not (out_dir / "metrics.json").exists() and not (out_dir / "reconstruction.gif").exists()
    assert "not scored" in out.strip().splitlines()[-1]
    code, out, _ = run(capsys, "reconstruct", aedat4_file, "--out", tmp_path / "at", "--at", "0.1,0.2,0.15",
                       "--no-video", *FAST)
    assert code == 0
    np.testing.assert_allclose(np.loadtxt(tmp_path / "at" / "timestamps.txt")[:, 1], [0.1, 0.15, 0.2])


# ---- bad input ---------------------------------------------------------------------------------

def test_bad_input_errors(capsys, ijrr_folder, tmp_path):
    out = ["--out", tmp_path / "never", *FAST]
    assert_error(capsys, ["info", tmp_path / "missing.aedat4"], r"no such file or folder: .*missing\.aedat4")
    junk = tmp_path / "junk.xyz"
    junk.write_bytes(bytes(range(256)))
    assert_error(capsys, ["reconstruct", junk, *out], r"unknown format '.xyz'.*supported formats: .*AEDAT4")
    assert_error(capsys, ["reconstruct", ijrr_folder, "--sensor", "10x10", *out],
                 r"sensor is \(H, W\) = \(24, 32\).*--sensor 10x10 was given.*pass --sensor 24x32")
    assert_error(capsys, ["reconstruct", ijrr_folder, "--start", "5", "--end", "6", *out],
                 r"no events in the window \[5\.0, 6\.0\).*choose a window inside")
    assert_error(capsys, ["reconstruct", ijrr_folder, "--start", "0.2", "--end", "0.1", *out], r"empty or reversed")
    assert_error(capsys, ["reconstruct", ijrr_folder, "--at", "0.1,7", *out], r"7\.0 s is outside the reconstructed window")
    assert_error(capsys, ["reconstruct", ijrr_folder, "--at", "soon", *out], r"could not read times")
    assert_error(capsys, ["reconstruct", ijrr_folder, "--fps", "-3", *out], r"argument --fps: must be positive")
    assert_error(capsys, ["reconstruct", ijrr_folder, "--C", "0", *out], r"argument --C: must be positive")
    assert not (tmp_path / "never").exists()


def test_cuda_requested_without_a_gpu(capsys, ijrr_folder, tmp_path):
    import torch

    if torch.cuda.is_available():
        pytest.skip("this machine has a GPU")
    assert_error(capsys, ["reconstruct", ijrr_folder, "--device", "cuda", "--out", tmp_path / "o", *FAST],
                 r"no CUDA GPU.*--device cpu")


def test_existing_output_folder_is_refused_unless_overwrite(capsys, ijrr_folder, tmp_path):
    out_dir = tmp_path / "taken"
    out_dir.mkdir()
    (out_dir / "mine.txt").write_text("keep me")
    assert_error(capsys, ["reconstruct", ijrr_folder, "--out", out_dir, *FAST], r"taken already exists.*--overwrite")
    assert (out_dir / "mine.txt").read_text() == "keep me"
    code, _, _ = run(capsys, "reconstruct", ijrr_folder, "--out", out_dir, "--overwrite", "--no-video", *FAST)
    assert code == 0 and not (out_dir / "mine.txt").exists() and (out_dir / "run.json").exists()


def test_interrupted_export_leaves_nothing_that_looks_complete(capsys, ijrr_folder, tmp_path, monkeypatch):
    import evinr_lite.io.export

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(evinr_lite.io.export, "save_gif", interrupted)   # after the PNGs, before run.json
    code, _, err = run(capsys, "reconstruct", ijrr_folder, "--out", tmp_path / "new", *FAST)
    assert code == 130 and "interrupted" in err and "Traceback" not in err
    assert not (tmp_path / "new").exists()
    old = tmp_path / "old"
    old.mkdir()
    (old / "mine.txt").write_text("keep me")
    code, _, _ = run(capsys, "reconstruct", ijrr_folder, "--out", old, "--overwrite", *FAST)
    assert code == 130 and sorted(p.name for p in old.iterdir()) == ["mine.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["old"]       # no partial folders left


# ---- the installed command, as a user runs it --------------------------------------------------

def test_module_entry_point_errors_without_traceback(tmp_path):
    run_ = subprocess.run([sys.executable, "-m", "evinr_lite", "info", str(tmp_path / "nope.raw")],
                          capture_output=True, text=True, cwd=tmp_path)
    assert run_.returncode == 2 and "Traceback" not in run_.stderr
    assert run_.stderr.startswith("evinr-lite: error: no such file or folder")


def test_ctrl_c_during_training(ijrr_folder, tmp_path):
    """A real SIGINT while training: exit status 130 and no output folder."""
    env = {**os.environ, "EVINR_FAST": "1", "PYTHONFAULTHANDLER": "1"}   # SIGABRT prints every thread's stack
    proc = subprocess.Popen([sys.executable, "-m", "evinr_lite", "reconstruct", str(ijrr_folder), "--out",
                             str(tmp_path / "out"), "--iters", "100000", "--quiet"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                            # a job started in the background by a non-interactive shell (as CI may be)
                            # inherits SIGINT ignored; a terminal's Ctrl-C is what this test imitates
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.time() + 60
    for line in proc.stdout:          # wait until training has started
        if line.startswith("reconstructing") or time.time() > deadline:
            break
    time.sleep(0.5)
    proc.send_signal(signal.SIGINT)
    try:
        _, err = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:   # seen once in a CI run under load (docs/setup.md): say where it stood
        proc.send_signal(signal.SIGABRT)
        _, err = proc.communicate(timeout=30)
        pytest.fail(f"reconstruct still ran 60 s after SIGINT; its threads when aborted:\n{err[-8000:]}")
    assert proc.returncode == 130, err
    assert "interrupted" in err and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []
