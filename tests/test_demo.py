"""The README's main job, end to end at a small size."""
import json
import subprocess
import sys

import pytest


from evinr_lite.apps.demo import run_demo
from evinr_lite.method.solver import EvINRConfig


def test_demo_writes_frames_and_scores(tmp_path):
    out = tmp_path / "demo"
    cfg = EvINRConfig.v0_1(C=0.2, n_iters=60, c2f_iters=(20, 40), hidden_features=64, hidden_layers=2, progress=False)
    summary = run_demo(out, sensor_size=(40, 56), duration=0.5, n_frames=3, config=cfg, log=lambda *a: None)
    saved = json.loads((out / "metrics.json").read_text())
    assert saved["n_events"] == summary["n_events"] > 1000
    assert len(list((out / "gt").glob("*.png"))) == 3
    assert (out / "overview.png").exists()
    m = saved["methods"]
    assert set(m) == {"EvINR", "integration (L0 = 0)", "integration (L0 = true first frame, oracle)"}
    for r in m.values():
        assert len(list((out / r["folder"]).glob("*.png"))) == 3
        assert 0 <= r["mse_none"] < 1 and -1 <= r["ssim_clahe"] <= 1
    oracle, blind = m["integration (L0 = true first frame, oracle)"], m["integration (L0 = 0)"]
    # handing the integrator the first frame must beat not knowing it
    assert oracle["mse_none"] < blind["mse_none"] and oracle["ssim_none"] > blind["ssim_none"]
    assert "data_range 1" in saved["protocol"] and saved["evinr_config"]["n_iters"] == 60
    assert saved["overview"]["rows"] == ["ground truth", "EvINR", "integration", "oracle (true L0)"]
    assert saved["overview"]["columns"] == [f"t = {t:.2f} s" for t in saved["query_times_s"]]


def test_demo_command_refuses_existing_output(tmp_path):
    out = tmp_path / "demo"
    out.mkdir()
    r = subprocess.run([sys.executable, "-m", "evinr_lite", "demo", "--out", str(out), "--size", "20x24",
                        "--duration", "0.2", "--frames", "2", "--iters", "3"], capture_output=True, text=True)
    assert r.returncode == 2
    assert "already exists" in r.stderr and "--overwrite" in r.stderr and "Traceback" not in r.stderr


def test_demo_command_rejects_bad_size():
    r = subprocess.run([sys.executable, "-m", "evinr_lite", "demo", "--size", "120by160"],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "HxW" in r.stderr


def test_overview_labels_rows_and_columns():
    import numpy as np
    from evinr_lite.apps.demo import labelled_grid

    rows = [np.full((3, 20, 30), v) for v in (0.2, 0.5, 0.8)]
    img = labelled_grid(rows, ["ground truth", "EvINR", "integration"], ["t = 0.10 s", "t = 0.20 s", "t = 0.30 s"])
    left = img.shape[1] - 3 * 32          # the label column left of the frames
    top = img.shape[0] - 3 * 22           # the time labels above them
    assert left > 20 and top > 5
    assert (img[top:, :left] < 128).any() and (img[:top, left:] < 128).any()   # text was drawn in both strips
    np.testing.assert_array_equal(img[top:top + 20, left:left + 30], round(0.2 * 255))  # frames pasted unscaled
    with pytest.raises(ValueError, match="one label per row"):
        labelled_grid(rows, ["only one"], ["a", "b", "c"])


def test_overview_frames_hold_the_levels_the_pngs_hold():
    """The overview maps [0, 1] to 8 bits as the frames' PNGs do (to_uint8, round(255 x)); it rounded
    x * 255 + 0.5 down, another level at the halves."""
    import numpy as np
    from evinr_lite.apps.demo import labelled_grid
    from evinr_lite.core.frames import to_uint8

    halves = (np.arange(600) / 2 / 255).reshape(20, 30)   # every half level, 0 .. 299.5 / 255 (clipped above 1)
    rows = [np.stack([halves, halves[::-1], 1 - halves])]
    img = labelled_grid(rows, ["EvINR"], ["a", "b", "c"])
    left, top = img.shape[1] - 3 * 32, img.shape[0] - 22
    for j in range(3):
        x = left + j * 32
        np.testing.assert_array_equal(img[top:top + 20, x:x + 30], to_uint8(rows[0][j]))
