"""A student copy (solutions removed by tools/make_student_copies.py) runs top to bottom, and every
unfinished exercise shows a visible "not finished" warning (the cells below use the reference).

The student copies' stubs raise NotImplementedError, so they say "not finished"; a finished but
wrong function would say "does not pass the check yet" instead (tests/test_exercises.py)."""
import importlib.util
import json
from pathlib import Path

import nbformat
import pytest
from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("make_student_copies", ROOT / "tools" / "make_student_copies.py")
make_student_copies = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(make_student_copies)

NOTEBOOKS = sorted(p for p in (ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb") if "BEGIN SOLUTION" in p.read_text())


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_student_copy_runs_and_warns(path, tmp_path, monkeypatch):
    # the kernel inherits TMPDIR: a notebook's tempfile.mkdtemp scratch (notebook 11's) lands in tmp_path,
    # which pytest removes, instead of one more folder left in /tmp by every run of the suite
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    instructor = json.loads(path.read_text())
    n_exercises = make_student_copies.count_exercises(instructor)
    assert n_exercises >= 2, f"{path.name}: a notebook with exercises needs at least 2"
    student = make_student_copies.student_copy(instructor, path.name)
    text = json.dumps(student)
    assert "BEGIN SOLUTION" not in text and text.count("raise NotImplementedError") >= n_exercises
    nb = nbformat.reads(json.dumps(student), as_version=4)
    NotebookClient(nb, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}).execute()
    outputs = json.dumps([c.get("outputs", []) for c in nb.cells])
    assert outputs.count("not finished") >= n_exercises, "each unfinished exercise must show a visible warning"
