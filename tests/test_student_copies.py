"""tools/make_student_copies.py: solutions removed, stubs and checks kept, deterministic, and the
committed students/ folder is what the generator makes from notebooks/ (not stale)."""
import importlib.util
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TOOL = ROOT / "tools" / "make_student_copies.py"
_spec = importlib.util.spec_from_file_location("make_student_copies", TOOL)
msc = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(msc)


def _nb(*cells):
    return {"cells": list(cells), "metadata": {"kernelspec": {"name": "python3"}}, "nbformat": 4, "nbformat_minor": 5}


def _code(source, outputs=(), count=None, cell_id="c"):
    return {"cell_type": "code", "id": cell_id, "metadata": {}, "source": source.splitlines(keepends=True),
            "outputs": list(outputs), "execution_count": count}


INSTRUCTOR = _nb(
    {"cell_type": "markdown", "id": "m", "metadata": {}, "source": ["# Title\n"]},
    _code("def f(x):\n    \"\"\"Doc.\"\"\"\n    ### BEGIN SOLUTION\n    y = x + 1\n    return y\n    ### END SOLUTION\n",
          cell_id="ex1"),
    _code("exercises.check('f', f)\n", outputs=[{"output_type": "stream", "name": "stdout", "text": ["ok\n"]}],
          count=3, cell_id="chk"),
    _code("# NBVAL_CHECK_OUTPUT\nprint(round(1.234, 2))\n",
          outputs=[{"output_type": "stream", "name": "stdout", "text": ["1.23\n"]}], count=4, cell_id="num"),
    _code("### BEGIN SOLUTION\nz = 2\n### END SOLUTION\nprint(z)\n", cell_id="ex2"),
)


def test_solutions_become_stubs_and_checks_stay():
    student = msc.student_copy(INSTRUCTOR, "01_x.ipynb")
    sources = ["".join(c["source"]) for c in student["cells"]]
    assert student["cells"][0]["cell_type"] == "markdown" and "generated" in sources[0]
    assert "make_student_copies" in sources[0] and "notebooks/01_x.ipynb" in sources[0]
    assert sources[2] == 'def f(x):\n    """Doc."""\n    raise NotImplementedError\n'   # indentation kept
    assert sources[3] == "exercises.check('f', f)\n"                                  # the check is kept
    assert sources[4] == "print(round(1.234, 2))\n"                                   # no output comparison
    assert sources[5] == "raise NotImplementedError\nprint(z)\n"                      # code after the block kept
    assert all(c.get("outputs", []) == [] and c.get("execution_count") is None
               for c in student["cells"] if c["cell_type"] == "code")
    assert "BEGIN SOLUTION" in "".join(INSTRUCTOR["cells"][1]["source"]), "the instructor copy is not modified"


def test_generation_is_deterministic_and_idempotent(tmp_path):
    src, out = tmp_path / "notebooks", tmp_path / "students"
    src.mkdir()
    (src / "01_x.ipynb").write_text(json.dumps(INSTRUCTOR))
    assert msc.generate(src, out) == ["wrote students/01_x.ipynb"]
    first = (out / "01_x.ipynb").read_text()
    assert msc.generate(src, out) == [] and (out / "01_x.ipynb").read_text() == first
    assert msc.problems(src, out) == []
    # a copy of the copy does not gain a second header
    again = msc.student_copy(json.loads(first), "01_x.ipynb")
    assert sum(c.get("id") == msc.HEADER_ID for c in again["cells"]) == 1


def test_check_reports_stale_missing_and_extra(tmp_path):
    src, out = tmp_path / "notebooks", tmp_path / "students"
    src.mkdir()
    (src / "01_x.ipynb").write_text(json.dumps(INSTRUCTOR))
    (src / "02_y.ipynb").write_text(json.dumps(INSTRUCTOR))
    msc.generate(src, out)
    changed = json.loads(json.dumps(INSTRUCTOR))
    changed["cells"][0]["source"] = ["# A new title\n"]
    (src / "01_x.ipynb").write_text(json.dumps(changed))
    (out / "02_y.ipynb").unlink()
    (out / "03_z.ipynb").write_text("{}")
    found = msc.problems(src, out)
    assert any(p.startswith("stale: students/01_x.ipynb") for p in found)
    assert "missing: students/02_y.ipynb" in found
    assert any(p.startswith("extra: students/03_z.ipynb") for p in found)
    run = subprocess.run([sys.executable, str(TOOL), "--check", "--source", str(src), "--out", str(out)],
                         capture_output=True, text=True)
    assert run.returncode == 1 and "python tools/make_student_copies.py" in run.stderr
    msc.generate(src, out)
    assert msc.problems(src, out) == [] and not (out / "03_z.ipynb").exists()


def test_committed_student_copies_are_up_to_date():
    found = msc.problems()
    assert not found, ("student copies differ from what the instructor notebooks generate:\n  "
                       + "\n  ".join(found) + "\nrun `python tools/make_student_copies.py` and commit students/")


def test_student_lines_appear_and_instructor_cells_are_left_out():
    nb = {"cells": [
        _code("def f(x):\n    ### STUDENT: # TODO: return twice x\n    ### STUDENT: result = ...\n"
              "    ### BEGIN SOLUTION\n    result = 2 * x\n    ### END SOLUTION\n    return result\n", cell_id="ex"),
        {"cell_type": "markdown", "id": "q", "metadata": {"tags": ["predict"]}, "source": ["**Predict.** f(2)?\n"]},
        {"cell_type": "markdown", "id": "ans", "metadata": {"tags": ["instructor"]}, "source": ["**Answer.** 4, twice 2.\n"]},
        {"cell_type": "markdown", "id": "note", "metadata": {"tags": ["instructor"]}, "source": ["Note: go slowly.\n"]},
    ], "metadata": {}, "nbformat": 4, "nbformat_minor": 5}
    student = msc.student_copy(nb, "01_x.ipynb")
    sources = ["".join(c["source"]) for c in student["cells"]]
    assert sources[1] == ("def f(x):\n    # TODO: return twice x\n    result = ...\n"
                          "    raise NotImplementedError\n    return result\n")
    assert [c["id"] for c in student["cells"][1:]] == ["ex", "q", "ans"]   # the note is instructor-only
    answer = student["cells"][3]
    assert answer["metadata"]["jupyter"]["source_hidden"] is True          # collapsed in Jupyter
    assert answer["metadata"]["tags"] == ["answer"]
    text = "".join(answer["source"])
    assert text.startswith("<details>") and "4, twice 2." in text and "</details>" in text   # closed elsewhere
    assert "**Answer.**" not in text
    ns = {}
    exec("".join(nb["cells"][0]["source"]), ns)                           # instructor copy: STUDENT lines are comments
    assert ns["f"](2) == 4


def test_every_answer_in_the_notebooks_reaches_the_student_copy_hidden():
    """Issue 24 section 4: explanations are kept for students, behind a collapsed cell."""
    for path in sorted(msc.SOURCE_DIR.glob(msc.PATTERN)):
        nb = json.loads(path.read_text())
        answers = [c["id"] for c in nb["cells"] if msc.is_answer(c)]
        student = msc.student_copy(nb, path.name)
        kept = {c["id"]: c for c in student["cells"] if "answer" in c["metadata"].get("tags", [])}
        assert list(kept) == answers, path.name
        assert all(c["metadata"]["jupyter"]["source_hidden"] for c in kept.values())
