"""Every notebook's figures and printed results are visible without running it (issue 24, section 2):
docs/executed/ holds a fast-mode executed copy of each notebook, and this test keeps them current.

A copy is current when its cells (type and source) are exactly its notebook's, every code cell ran and
none raised. After changing a notebook, regenerate its copy:
``nice python tools/render_notebooks.py --executed --only NN`` (docs/notebooks.md says why this design).
"""
import base64
import importlib.util
import io
import json
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("render_notebooks", ROOT / "tools" / "render_notebooks.py")
rn = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(rn)


def test_committed_executed_copies_are_current():
    found = rn.executed_problems()
    assert not found, ("executed copies differ from the notebooks:\n  " + "\n  ".join(found)
                       + "\nregenerate with `nice python tools/render_notebooks.py --executed --only NN`")


@pytest.mark.parametrize("path", sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb")), ids=lambda p: p.name)
def test_every_figure_of_a_notebook_is_in_its_copy(path):
    """Each cell that draws (plt.show, a show_* or plot_* helper, interact) has an image in the copy, and
    the copy stays small (figures re-encoded)."""
    copy = ROOT / "docs" / "executed" / path.name
    if not copy.exists():
        pytest.fail(f"no executed copy docs/executed/{path.name}")
    cells = json.loads(copy.read_text())["cells"]
    images = sum("image/png" in o.get("data", {}) for c in cells if c["cell_type"] == "code" for o in c["outputs"])
    draws = sum("plt.show()" in "".join(c["source"]) for c in cells if c["cell_type"] == "code")
    assert images >= draws, f"{path.name}: {draws} cells call plt.show() but the copy holds {images} images"
    assert copy.stat().st_size < 3_000_000, f"{path.name}: executed copy is {copy.stat().st_size / 1e6:.1f} MB"


def _nb(*sources, outputs=None, count=1):
    cells = [{"cell_type": "code", "id": f"c{i}", "metadata": {}, "source": s, "execution_count": count,
              "outputs": outputs if outputs is not None else []} for i, s in enumerate(sources)]
    return {"cells": cells, "metadata": {}, "nbformat": 4, "nbformat_minor": 5}


def test_problems_finds_missing_stale_broken_and_extra(tmp_path):
    src, out = tmp_path / "notebooks", tmp_path / "executed"
    src.mkdir()
    out.mkdir()
    for name in ("01_a.ipynb", "02_b.ipynb", "03_c.ipynb", "04_d.ipynb"):
        (src / name).write_text(json.dumps(_nb("x = 1\n", "print(x)\n", count=None)))
    (out / "01_a.ipynb").write_text(json.dumps(_nb("x = 1\n", "print(x)\n")))                 # current
    (out / "02_b.ipynb").write_text(json.dumps(_nb("x = 2\n", "print(x)\n")))                 # stale
    (out / "03_c.ipynb").write_text(json.dumps(_nb("x = 1\n", "print(x)\n", count=None)))     # never ran
    (out / "05_e.ipynb").write_text(json.dumps(_nb("x = 1\n")))                               # extra
    found = "\n".join(rn.executed_problems(src, out))
    assert "01_a" not in found
    assert "stale: executed/02_b.ipynb (cell 0" in found
    assert "broken: executed/03_c.ipynb cell 0 did not run" in found
    assert "missing: executed/04_d.ipynb" in found and "extra: executed/05_e.ipynb" in found
    (out / "03_c.ipynb").write_text(json.dumps(_nb("x = 1\n", "print(x)\n", outputs=[
        {"output_type": "error", "ename": "NameError", "evalue": "x", "traceback": []}])))
    assert "broken: executed/03_c.ipynb cell 0 has an error output" in "\n".join(rn.executed_problems(src, out))


def test_small_png_is_narrow_and_smaller():
    from PIL import Image

    rng = np.random.default_rng(0)
    img = Image.fromarray((rng.random((600, 1500, 3)) * 255).astype(np.uint8))
    raw = io.BytesIO()
    img.save(raw, format="PNG")
    small = rn.small_png(raw.getvalue())
    assert len(small) < len(raw.getvalue())
    out = Image.open(io.BytesIO(small))
    assert out.width == rn.EXECUTED_WIDTH and out.height == round(600 * rn.EXECUTED_WIDTH / 1500)
    assert base64.b64encode(small)
