"""Notebooks are parameterised the papermill way: one code cell tagged "parameters" each, and a run
with overridden parameters prints the new values (the text reads its numbers from the parameters)."""
import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))


def _parameter_cells(path: Path) -> list[int]:
    cells = json.loads(path.read_text())["cells"]
    return [i for i, c in enumerate(cells)
            if c["cell_type"] == "code" and "parameters" in c.get("metadata", {}).get("tags", [])]


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_every_notebook_has_one_parameters_cell(path):
    found = _parameter_cells(path)
    assert len(found) == 1, (f"{path.name}: {len(found)} code cells tagged 'parameters' (cells {found}); "
                             "tag exactly one, the cell of settings a reader may change")


def test_notebook_01_runs_with_overridden_parameters(tmp_path):
    """papermill injects new values after the parameters cell; the notebook's printed text follows them.

    C = 0.2 instead of 0.1 (and small iteration counts, to keep the run short): the first cell prints
    the new C, and the sentence about the intensity step prints e^0.2 = 1.221, not e^0.1 = 1.105.
    """
    papermill = pytest.importorskip("papermill")
    out = tmp_path / "01_out.ipynb"
    papermill.execute_notebook(
        str(ROOT / "notebooks" / "01_event_generation_1d.ipynb"), str(out),
        parameters=dict(C=0.2, SEED=3, N_ITERS=20, LONG_ITERS=30, WANDER_ITERS=20, T_SAMPLES=500),
        kernel_name="python3", cwd=str(ROOT / "notebooks"), progress_bar=False, request_save_on_cell_execute=False)
    nb = json.loads(out.read_text())
    injected = [c for c in nb["cells"] if "injected-parameters" in c.get("metadata", {}).get("tags", [])]
    assert len(injected) == 1, "papermill found no cell tagged 'parameters' to inject after"
    text = "".join(o.get("text", "") if isinstance(o.get("text", ""), str) else "".join(o["text"])
                   for c in nb["cells"] if c["cell_type"] == "code" for o in c.get("outputs", []))
    assert "C=0.2," in text and "N_ITERS=20," in text
    assert "multiplies the intensity I by e^C = 1.221" in text
    assert "every condition is integrated and fitted with the nominal C = 0.2" in text
    assert "C_pos = 0.24, C_neg = 0.16" in text
