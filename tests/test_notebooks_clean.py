"""Notebooks are committed without outputs (except checked cells) and show their sizes up front."""
import json
from pathlib import Path

import pytest

NOTEBOOKS = sorted((Path(__file__).resolve().parents[1] / "notebooks").glob("[0-9][0-9]_*.ipynb"))


def test_there_are_notebooks():
    assert NOTEBOOKS, "no numbered notebooks found in notebooks/"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_committed_without_outputs(path):
    nb = json.loads(path.read_text())
    for i, cell in enumerate(nb["cells"]):
        if cell["cell_type"] != "code":
            continue
        src = "".join(cell["source"])
        if src.startswith("# NBVAL_CHECK_OUTPUT"):
            assert cell["outputs"], f"{path.name} cell {i} is a checked cell but has no stored output"
            assert cell["execution_count"], f"{path.name} cell {i}: nbval needs an execution count on checked cells"
            continue
        assert not cell["outputs"], (f"{path.name} cell {i} has stored outputs; "
                                     "run `python tools/strip_notebooks.py notebooks/*.ipynb`")
        assert cell.get("execution_count") is None, f"{path.name} cell {i} has an execution count"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_parameters_cell_uses_fast_mode(path):
    nb = json.loads(path.read_text())
    code = ["".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "code"][:3]
    assert any("pick(" in c or "fast_mode" in c for c in code), (
        f"{path.name}: one of the first code cells should set sizes with evinr_lite.pick(fast, full)")
