"""Generate the student notebooks from the instructor notebooks (one source of truth).

    python tools/make_student_copies.py            # write students/NN_*.ipynb (and delete stale extras)
    python tools/make_student_copies.py --check    # exit 1 if any copy is missing, stale or extra

For every numbered notebook in notebooks/, the student copy in students/ has:

- each solution between ``### BEGIN SOLUTION`` and ``### END SOLUTION`` lines replaced by
  ``raise NotImplementedError`` (same indentation); stubs, docstrings and checks are kept, so an
  unfinished exercise falls back to the reference with a "does not pass the check yet" warning;
- each ``### STUDENT: text`` line (a comment in the instructor copy, so it never runs there) turned
  into ``text`` at the same indentation: the TODO banner and the skeleton (``result = ...``) that
  only the student sees, e.g. ``### STUDENT: # TODO: sum the events with t_i <= t_q``;
- every answer to a predict-then-run question (a cell tagged ``instructor`` whose text starts with
  ``**Answer.**`` or ``*Answer.*``) kept, but hidden until the student opens it: its source is marked
  ``jupyter.source_hidden`` (JupyterLab and Notebook 7 show a collapsed bar) and wrapped in an HTML
  ``<details>`` block (GitHub's and nbviewer's rendering show a closed "Answer" line), tagged ``answer``;
  every other ``instructor`` cell (notes for the instructor) left out;
- all outputs and execution counts removed, and ``# NBVAL_CHECK_OUTPUT`` markers dropped (a student
  copy is only checked to run top to bottom);
- a first markdown cell saying that it is generated, from which file, and how to regenerate it.

Files are written atomically (temporary file, then rename); the output is deterministic, so
regenerating an up-to-date copy changes nothing.
"""
from __future__ import annotations

import argparse
import copy
import json
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from textfile import write_beside  # noqa: E402  (tools/textfile.py)

ROOT = Path(__file__).resolve().parents[1]
SOURCE_DIR = ROOT / "notebooks"
STUDENT_DIR = ROOT / "students"
PATTERN = "[0-9][0-9]_*.ipynb"
SOLUTION = re.compile(r"^(?P<indent>[ \t]*)### BEGIN SOLUTION[^\n]*\n.*?^[ \t]*### END SOLUTION[^\n]*(\n|\Z)", re.S | re.M)
STUDENT_LINE = re.compile(r"^(?P<indent>[ \t]*)### STUDENT: ?(?P<text>[^\n]*)$", re.M)
INSTRUCTOR_TAG = "instructor"
ANSWER_TAG = "answer"
ANSWER = re.compile(r"^\s*(\*\*Answer\.\*\*|\*Answer\.\*)\s*")
ANSWER_SUMMARY = "Answer (open it after you have written your prediction)"
CHECK_MARK = re.compile(r"^# NBVAL_CHECK_OUTPUT[^\n]*\n?")
HEADER_ID = "student-copy-header"


def without_solutions(source: str) -> str:
    """Replace every solution block by ``raise NotImplementedError`` at the block's indentation."""
    return SOLUTION.sub(lambda m: f"{m.group('indent')}raise NotImplementedError\n", source)


def student_lines(source: str) -> str:
    """Uncomment every ``### STUDENT: text`` line: the banner and skeleton only the student copy runs."""
    return STUDENT_LINE.sub(lambda m: f"{m.group('indent')}{m.group('text')}", source)


def count_exercises(nb: dict) -> int:
    """Code cells holding a solution block."""
    return sum(1 for c in nb["cells"] if c["cell_type"] == "code" and "### BEGIN SOLUTION" in _text(c["source"]))


def _text(source) -> str:
    return source if isinstance(source, str) else "".join(source)


def _lines(text: str) -> list[str]:
    """Notebook JSON stores sources as lists of lines, each keeping its newline."""
    return text.splitlines(keepends=True)


def is_answer(cell: dict) -> bool:
    """An instructor cell holding the answer to a predict-then-run question."""
    return (cell["cell_type"] == "markdown" and INSTRUCTOR_TAG in cell.get("metadata", {}).get("tags", [])
            and bool(ANSWER.match(_text(cell["source"]))))


def hidden_answer(cell: dict) -> dict:
    """The student's version of an answer cell: collapsed in Jupyter, a closed <details> block elsewhere."""
    text = ANSWER.sub("", _text(cell["source"]), count=1).strip("\n")
    meta = dict(cell.get("metadata", {}))
    meta["tags"] = [t for t in meta.get("tags", []) if t != INSTRUCTOR_TAG] + [ANSWER_TAG]
    meta["jupyter"] = {**meta.get("jupyter", {}), "source_hidden": True}
    source = f"<details>\n<summary><b>{ANSWER_SUMMARY}</b></summary>\n\n{text}\n\n</details>\n"
    return {**cell, "metadata": meta, "source": _lines(source)}


def header_cell(name: str, n_exercises: int) -> dict:
    what = (f"Its {n_exercises} exercise{'s' if n_exercises != 1 else ''} are stubs that raise "
            "`NotImplementedError`: fill them in where it says so. Until you do, the cells after each "
            "exercise use the reference solution and say so with a warning, so the notebook always runs "
            "top to bottom. `exercises.check(...)` tells you what is still wrong."
            if n_exercises else "It has no exercises.")
    text = (f"> **Student copy** of `notebooks/{name}`, generated by `python tools/make_student_copies.py`. "
            f"Do not edit it in the repository: edit the instructor notebook and regenerate.\n>\n> {what}\n>\n"
            "> After each *predict before you run* question, the answer is a collapsed cell: open it once you "
            "have written your guess and run the cell.")
    return {"cell_type": "markdown", "id": HEADER_ID, "metadata": {}, "source": _lines(text)}


def student_copy(nb: dict, name: str) -> dict:
    """The student version of instructor notebook ``nb`` (a new dict; ``nb`` is not modified)."""
    nb = copy.deepcopy(nb)
    n_exercises = count_exercises(nb)
    cells = []
    for cell in nb["cells"]:
        if cell.get("id") == HEADER_ID:
            continue
        if is_answer(cell):
            cells.append(hidden_answer(cell))
            continue
        if INSTRUCTOR_TAG in cell.get("metadata", {}).get("tags", []):
            continue
        cell.get("metadata", {}).pop("execution", None)
        if cell["cell_type"] == "code":
            source = CHECK_MARK.sub("", student_lines(without_solutions(_text(cell["source"]))))
            cell["source"] = _lines(source)
            cell["outputs"] = []
            cell["execution_count"] = None
        cells.append(cell)
    nb["cells"] = [header_cell(name, n_exercises)] + cells
    nb.get("metadata", {}).pop("widgets", None)
    return nb


def dumps(nb: dict) -> str:
    return json.dumps(nb, indent=1, ensure_ascii=False) + "\n"


def expected_copies(source_dir: Path = SOURCE_DIR) -> dict[str, str]:
    """{file name: text of its student copy} for every numbered notebook in ``source_dir``."""
    out = {}
    for path in sorted(source_dir.glob(PATTERN)):
        nb = json.loads(path.read_text())
        out[path.name] = dumps(student_copy(nb, path.name))
    return out


def problems(source_dir: Path = SOURCE_DIR, student_dir: Path = STUDENT_DIR) -> list[str]:
    """What differs between ``student_dir`` and freshly generated copies (empty when up to date)."""
    expected = expected_copies(source_dir)
    present = {p.name: p for p in sorted(student_dir.glob(PATTERN))} if student_dir.exists() else {}
    found = []
    for name, text in expected.items():
        if name not in present:
            found.append(f"missing: {student_dir.name}/{name}")
        elif present[name].read_text() != text:
            found.append(f"stale: {student_dir.name}/{name} (notebooks/{name} changed since it was generated)")
    found += [f"extra: {student_dir.name}/{name} (no notebooks/{name})" for name in present if name not in expected]
    return found


def generate(source_dir: Path = SOURCE_DIR, student_dir: Path = STUDENT_DIR) -> list[str]:
    """Write every student copy that is missing or stale and delete extras; returns what changed."""
    student_dir.mkdir(parents=True, exist_ok=True)
    changed = []
    expected = expected_copies(source_dir)
    for name, text in expected.items():
        path = student_dir / name
        if not path.exists() or path.read_text() != text:
            write_beside(path, text)
            changed.append(f"wrote {student_dir.name}/{name}")
    for path in sorted(student_dir.glob(PATTERN)):
        if path.name not in expected:
            path.unlink()
            changed.append(f"deleted {student_dir.name}/{path.name} (no notebooks/{path.name})")
    return changed


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--check", action="store_true", help="only report missing, stale or extra copies (exit 1)")
    parser.add_argument("--source", type=Path, default=SOURCE_DIR, help="instructor notebooks (default: notebooks/)")
    parser.add_argument("--out", type=Path, default=STUDENT_DIR, help="student copies (default: students/)")
    args = parser.parse_args(argv)
    if not any(args.source.glob(PATTERN)):
        print(f"no numbered notebooks ({PATTERN}) in {args.source}", file=sys.stderr)
        return 1
    if args.check:
        found = problems(args.source, args.out)
        for line in found:
            print(line)
        if found:
            print("run `python tools/make_student_copies.py` to regenerate the student copies", file=sys.stderr)
            return 1
        print(f"{args.out.name}/: {len(expected_copies(args.source))} student copies up to date")
        return 0
    changed = generate(args.source, args.out)
    for line in changed:
        print(line)
    print(f"{args.out.name}/: {len(expected_copies(args.source))} student copies, {len(changed)} changed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
