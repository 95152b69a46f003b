"""Fast mode, device choice, atomic output folders and the notebook stripping tool."""
import json
import subprocess
import sys
from pathlib import Path

import pytest
import torch

from evinr_lite import default_device, fast_mode, pick
from evinr_lite.io.output import atomic_output_dir

ROOT = Path(__file__).resolve().parents[1]


def test_fast_mode_follows_environment(monkeypatch):
    monkeypatch.setenv("EVINR_FAST", "0")
    assert not fast_mode() and pick(1, 2) == 2
    monkeypatch.setenv("EVINR_FAST", "1")
    assert fast_mode() and pick(1, 2) == 1


def test_default_device_is_cpu_without_gpu(monkeypatch):
    monkeypatch.delenv("EVINR_DEVICE", raising=False)
    dev = default_device()
    assert dev.type == ("cuda" if torch.cuda.is_available() else dev.type)
    assert default_device("cpu") == torch.device("cpu")
    if not torch.cuda.is_available():
        with pytest.raises(RuntimeError, match="no CUDA GPU"):
            default_device("cuda")


def test_atomic_output_dir_refuses_existing_and_cleans_up(tmp_path):
    out = tmp_path / "out"
    with atomic_output_dir(out) as tmp:
        (tmp / "a.txt").write_text("x")
    assert (out / "a.txt").read_text() == "x"
    with pytest.raises(FileExistsError, match="overwrite=True"):
        with atomic_output_dir(out):
            pass
    with pytest.raises(KeyboardInterrupt):
        with atomic_output_dir(out, overwrite=True) as tmp:
            (tmp / "b.txt").write_text("half")
            raise KeyboardInterrupt
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]  # no partial folder left
    assert not (out / "b.txt").exists() and (out / "a.txt").exists()


def test_strip_tool_removes_outputs_but_keeps_checked_cells(tmp_path):
    nb = {"cells": [
        {"cell_type": "code", "source": ["x = 1"], "metadata": {}, "execution_count": 3,
         "outputs": [{"output_type": "stream", "name": "stdout", "text": ["1\n"]}]},
        {"cell_type": "code", "source": ["# NBVAL_CHECK_OUTPUT\n", "print(1)"], "metadata": {}, "execution_count": 4,
         "outputs": [{"output_type": "stream", "name": "stdout", "text": ["1\n"]}]},
    ], "metadata": {}, "nbformat": 4, "nbformat_minor": 5}
    path = tmp_path / "n.ipynb"
    path.write_text(json.dumps(nb))
    tool = [sys.executable, str(ROOT / "tools" / "strip_notebooks.py")]
    assert subprocess.run(tool + ["--check", str(path)], capture_output=True).returncode == 1
    subprocess.run(tool + [str(path)], check=True, capture_output=True)
    cells = json.loads(path.read_text())["cells"]
    assert cells[0]["outputs"] == [] and cells[0]["execution_count"] is None
    assert cells[1]["outputs"][0]["text"] == ["1\n"]
    assert subprocess.run(tool + ["--check", str(path)], capture_output=True).returncode == 0
