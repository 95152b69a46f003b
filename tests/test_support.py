"""Fast mode, device choice, atomic output folders and the notebook stripping tool."""
import json
import os
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


_PAGE_PROBE = """
import os, sys
sys.argv = ["evinr-lite", "info", sys.argv[1]]
from evinr_lite.apps.cli import main
code = main()
import numpy
print(code, os.environ.get("NUMPY_MADVISE_HUGEPAGE"), numpy._core.multiarray._get_madvise_hugepage())
"""


@pytest.mark.parametrize("preset, expected", [(None, "0 False"), ("1", "1 True"), ("0", "0 False")])
def test_the_command_asks_numpy_for_ordinary_pages_unless_the_user_chose(tmp_path, preset, expected):
    # the command (main() as the process) sets NUMPY_MADVISE_HUGEPAGE=0 before numpy is imported, so numpy's own
    # switch is off (huge pages cost 10 of 22 s of a 1280x720 run on lazily backed VMs: core/runtime.py); a
    # value the user set is kept
    from evinr_lite.sim.recordings import write_example_recording
    path = write_example_recording(tmp_path / "rec", duration=0.2, sensor_size=(20, 30))
    env = {k: v for k, v in os.environ.items() if k != "NUMPY_MADVISE_HUGEPAGE"}
    if preset is not None:
        env["NUMPY_MADVISE_HUGEPAGE"] = preset
    out = subprocess.run([sys.executable, "-c", _PAGE_PROBE, str(path)], capture_output=True, text=True, env=env,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == f"0 {expected}"


def test_page_policy_leaves_an_imported_numpy_and_library_calls_alone(monkeypatch):
    import numpy  # noqa: F401  (already imported in the test process)
    from evinr_lite.core.runtime import command_page_policy
    monkeypatch.delenv("NUMPY_MADVISE_HUGEPAGE", raising=False)
    assert command_page_policy() is False and "NUMPY_MADVISE_HUGEPAGE" not in os.environ
