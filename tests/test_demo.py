"""The README's main job, end to end at a small size."""
import json
import subprocess
import sys

import pytest

from evinr_lite.demo import run_demo


def test_demo_writes_frames_and_scores(tmp_path):
    out = tmp_path / "demo"
    summary = run_demo(out, sensor_size=(40, 56), duration=0.5, n_frames=3, log=lambda *a: None)
    saved = json.loads((out / "metrics.json").read_text())
    assert saved["n_events"] == summary["n_events"] > 1000
    assert len(list((out / "gt").glob("*.png"))) == 3
    assert (out / "overview.png").exists()
    m = saved["methods"]
    oracle, blind = m["integration (L0 = true first frame)"], m["integration (L0 = 0)"]
    assert len(list((out / oracle["folder"]).glob("*.png"))) == 3
    # handing the integrator the first frame must beat not knowing it
    assert oracle["mse"] < blind["mse"] and oracle["ssim"] > blind["ssim"]
    assert "data_range 1.0" in saved["protocol"]


def test_demo_command_refuses_existing_output(tmp_path):
    out = tmp_path / "demo"
    out.mkdir()
    r = subprocess.run([sys.executable, "-m", "evinr_lite", "demo", "--out", str(out), "--size", "20x24",
                        "--duration", "0.2", "--frames", "2"], capture_output=True, text=True)
    assert r.returncode == 2
    assert "already exists" in r.stderr and "--overwrite" in r.stderr and "Traceback" not in r.stderr


def test_demo_command_rejects_bad_size():
    r = subprocess.run([sys.executable, "-m", "evinr_lite", "demo", "--size", "120by160"],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "HxW" in r.stderr
