"""tools/render_notebooks.py: executed notebooks as a static site, index in reading order with each
notebook's question, first figure as thumbnail and run time; a failing notebook leaves --out alone.

Small made-up notebooks keep this fast; tests/test_browser.py opens a real notebook's page."""
import importlib.util
import json
from pathlib import Path

import nbformat
import pytest
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook

ROOT = Path(__file__).resolve().parents[1]


def _tool():
    spec = importlib.util.spec_from_file_location("render_notebooks", ROOT / "tools" / "render_notebooks.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _write(folder, name, cells):
    nbformat.write(new_notebook(cells=cells, metadata={"kernelspec": {"name": "python3", "language": "python",
                                                                       "display_name": "Python 3"}}),
                   folder / name)


def figure():
    return new_code_cell("import matplotlib.pyplot as plt\nfig, ax = plt.subplots(figsize=(3, 2))\n"
                           "ax.plot([0, 1], [0, 1])\nplt.show()")


@pytest.fixture
def notebooks(tmp_path):
    folder = tmp_path / "nbs"
    folder.mkdir()
    _write(folder, "02_second.ipynb", [new_markdown_cell("# 02 · Second\n\nNo question line here, a first paragraph."),
                                       new_code_cell("print(1 + 1)")])
    _write(folder, "01_first.ipynb", [new_markdown_cell("# 01 · First\n\n**Question.** Does the *gallery* show $C$?"),
                                      new_code_cell("import os\nprint(os.environ['EVINR_FAST'])"), figure(), figure()])
    (folder / "notes.ipynb").write_text("{}")   # not NN_*: not part of the reading order
    return folder


def test_site_in_reading_order_with_questions_thumbnails_and_times(notebooks, tmp_path):
    tool = _tool()
    result = tool.build(tmp_path / "site", notebooks_dir=notebooks, log=lambda *a, **k: None)
    site = Path(result["out"])
    entries = json.loads((site / "gallery.json").read_text())["entries"]
    assert [e["stem"] for e in entries] == ["01_first", "02_second"]
    first, second = entries
    assert first["title"] == "01 · First" and first["question"] == "Does the gallery show C?"
    assert second["question"] == "No question line here, a first paragraph."
    assert first["n_figures"] == 2 and second["n_figures"] == 0 and second["thumbnail"] is None
    assert (site / first["thumbnail"]).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert all(e["seconds"] > 0 for e in entries)
    index = (site / "index.html").read_text()
    assert index.index("01 · First") < index.index("02 · Second") and 'href="01_first.html"' in index
    assert f"ran in {first['seconds']:.1f} s" in index and "fast mode" in index
    page = (site / "01_first.html").read_text()
    images = [src for src in page.split('src="')[1:] if src.startswith("01_first_files/")]
    assert len(images) == 2 and all((site / src.split('"')[0]).exists() for src in images)
    assert "<pre>1\n</pre>" in page   # executed in fast mode: EVINR_FAST=1 printed


def test_failing_notebook_names_the_cell_and_leaves_the_site(notebooks, tmp_path):
    tool = _tool()
    site = tmp_path / "site"
    site.mkdir()
    (site / "keep.txt").write_text("an earlier build")
    _write(notebooks, "03_broken.ipynb", [new_markdown_cell("# 03"), new_code_cell("raise ValueError('broken on purpose')")])
    with pytest.raises(RuntimeError, match="(?s)03_broken.ipynb failed.*broken on purpose"):
        tool.build(site, notebooks_dir=notebooks, log=lambda *a, **k: None)
    assert (site / "keep.txt").exists() and not (site / "index.html").exists()
    assert not list(tmp_path.glob(".site.partial-*"))


def test_unknown_notebook_is_refused(notebooks):
    with pytest.raises(SystemExit, match="no notebook 07"):
        _tool().notebook_paths(notebooks, only=["07"])
