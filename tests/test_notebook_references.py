"""Every reference in the notebooks' text resolves (issue 24, section 3).

A notebook's text points at its own sections ("section 6", "sections 2, 3 and 9"), at its exercises
("Exercise 3"), at another notebook's section or exercise ("notebook 04, section 7"), announces how
many exercises and *predict before you run* questions it has ("two exercises and three predict ...")
and lists its plan (a table of sections, or "(1) ..., (2) ..."). Each must match what is there:

- sections are the ``## N. Title`` headings;
- exercises are the ``### Exercise N`` / ``**Exercise N.**`` labels, numbered 1..k with k the number of
  solution blocks (``### BEGIN SOLUTION``) in the notebook;
- predict questions are the cells holding ``**Predict before you run.**``;
- the plan lists exactly the section numbers.

It also keeps the bin-edge rule single: the kit's bins are (b_k, b_{k+1}]; no notebook teaches a
half-open [b_k, b_{k+1}) bin.
"""
import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))
WORDS = {"no": 0, "one": 1, "two": 2, "three": 3, "four": 4, "five": 5, "six": 6, "seven": 7, "eight": 8,
         "nine": 9, "ten": 10}
NUMBER_LIST = r"\d+(?:(?:\s*,\s*|\s+and\s+|\s+or\s+|\s*-\s*|\s+to\s+)\d+)*"
REFERENCE = re.compile(r"(?i)\b(?:notebook\s+(?P<nb>\d\d)\s*(?:'s|,)?\s+)?(?P<kind>sections?|exercises?)\s+"
                       r"(?P<nums>" + NUMBER_LIST + r")\b")
HEADING = re.compile(r"^##\s+(\d+)\.\s", re.M)
EXERCISE_LABEL = re.compile(r"^###\s+Exercise\s+(\d+)\b|\*\*Exercise\s+(\d+)\b", re.M)
COUNT = re.compile(r"(?i)\b(?P<n>" + "|".join(WORDS) + r"|\d+)\s+(?:\*)?(?P<what>exercises?|predict\b)")
PLAN_ROW = re.compile(r"^\|\s*(\d+)\s*\|", re.M)
PLAN_ITEM = re.compile(r"\((\d+)\)\s")
HALF_OPEN_LEFT = re.compile(r"\[\s*(?:b_|t_0|t0)[^\]\n]{0,40}?\)")


def _cells(path):
    return json.loads(path.read_text())["cells"]


def _text(cell):
    return "".join(cell["source"])


def _markdown(path):
    return [(i, _text(c)) for i, c in enumerate(_cells(path)) if c["cell_type"] == "markdown"]


def _numbers(text):
    """'2, 3 and 9' -> [2, 3, 9]; '2-4' or '2 to 4' -> [2, 3, 4]."""
    out = []
    for part in re.split(r"\s*,\s*|\s+and\s+|\s+or\s+", text.strip()):
        span = re.split(r"\s*-\s*|\s+to\s+", part)
        out += list(range(int(span[0]), int(span[-1]) + 1))
    return out


def structure(path):
    """What a notebook holds: section numbers, exercise labels, solution blocks, predict questions."""
    md = _markdown(path)
    labels = [int(m.group(1) or m.group(2)) for _, s in md for m in EXERCISE_LABEL.finditer(s)]
    return {
        "sections": {int(n) for _, s in md for n in HEADING.findall(s)},
        "exercises": labels,
        "solutions": sum("### BEGIN SOLUTION" in _text(c) for c in _cells(path) if c["cell_type"] == "code"),
        "predicts": sum("**Predict before you run.**" in s for _, s in md),
    }


STRUCTURE = {p.name[:2]: structure(p) for p in NOTEBOOKS}


def broken_references(path, structures=STRUCTURE):
    """Every reference in ``path``'s text (markdown, and code: comments and printed strings) that does
    not resolve, as readable lines."""
    own = path.name[:2]
    found = []
    for i, text in [(i, _text(c)) for i, c in enumerate(_cells(path))]:
        # the closing "Exercises (open)" list numbers its own items; a heading is not a reference
        body = text.split("## Exercises (open)")[0]
        for m in REFERENCE.finditer(body):
            nb = m.group("nb") or own
            if nb not in structures:
                found.append(f"[{i}] '{m.group(0)}': there is no notebook {nb}")
                continue
            target = structures[nb]
            for n in _numbers(m.group("nums")):
                if m.group("kind").lower().startswith("section") and n not in target["sections"]:
                    found.append(f"[{i}] '{m.group(0)}': notebook {nb} has no section {n} "
                                 f"(sections {sorted(target['sections'])})")
                if m.group("kind").lower().startswith("exercise") and n not in target["exercises"]:
                    found.append(f"[{i}] '{m.group(0)}': notebook {nb} has no Exercise {n} "
                                 f"(labelled: {target['exercises']})")
    return found


def count_problems(path, s=None):
    """The intro's promised counts, the exercise labels and the plan against what the notebook holds."""
    s = s or structure(path)
    found = []
    intro = _markdown(path)[0][1]
    for m in COUNT.finditer(intro):
        n = WORDS.get(m.group("n").lower(), None)
        n = int(m.group("n")) if n is None else n
        what = m.group("what").lower()
        have = s["predicts"] if what.startswith("predict") else s["solutions"]
        if n != have:
            found.append(f"the introduction promises {m.group(0)!r}, the notebook has {have}")
    if s["exercises"] and s["exercises"] != list(range(1, len(s["exercises"]) + 1)):
        found.append(f"exercise labels {s['exercises']} are not 1..{len(s['exercises'])} in order")
    if s["solutions"] > 1 and len(s["exercises"]) != s["solutions"]:
        found.append(f"{s['solutions']} exercises (solution blocks) but labels {s['exercises']}")
    plan = [int(n) for n in PLAN_ROW.findall(intro)] or [int(n) for n in PLAN_ITEM.findall(intro)]
    if plan and sorted(set(plan)) != sorted(s["sections"]):
        found.append(f"the plan lists sections {sorted(set(plan))}, the headings are {sorted(s['sections'])}")
    return found


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_every_reference_resolves(path):
    found = broken_references(path)
    assert not found, f"{path.name}:\n  " + "\n  ".join(found)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_counts_labels_and_plan_match(path):
    found = count_problems(path)
    assert not found, f"{path.name}:\n  " + "\n  ".join(found)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_one_bin_edge_rule(path):
    """Bins are (b_k, b_{k+1}] everywhere (as method.binning); a [b_k, ...) interval in text is a second rule."""
    bad = [f"[{i}] {m.group(0)}" for i, s in _markdown(path) for m in HALF_OPEN_LEFT.finditer(s)]
    assert not bad, f"{path.name} states a half-open [b_k, b_k+1) bin: {bad}"


# ---- the finder itself finds what it should ---------------------------------------------------------

def _fake(tmp_path, name, *markdown, code=()):
    cells = [{"cell_type": "markdown", "metadata": {}, "source": [m]} for m in markdown]
    cells += [{"cell_type": "code", "metadata": {}, "source": [c], "outputs": [], "execution_count": None}
              for c in code]
    p = tmp_path / name
    p.write_text(json.dumps({"cells": cells}))
    return p


def test_the_finder_catches_each_kind_of_broken_reference(tmp_path):
    p = _fake(tmp_path, "05_x.ipynb",
              "# 05\n\nTwo exercises and three *predict before you run* questions.\n\n| 1 | a |\n| 2 | b |\n| 3 | c |",
              "## 1. A\n\n### Exercise 1\n\n**Predict before you run.** ?",
              "## 2. B\n\nAs section 4 shows, and Exercise 3 (see sections 1, 2 and 7; notebook 99, section 1).",
              code=["### BEGIN SOLUTION\nx = 1\n### END SOLUTION\n", "### BEGIN SOLUTION\ny = 1\n### END SOLUTION\n"])
    s = structure(p)
    assert s == {"sections": {1, 2}, "exercises": [1], "solutions": 2, "predicts": 1}
    broken = "\n".join(broken_references(p, {"05": s}))
    for words in ("no section 4", "no Exercise 3", "no section 7", "no notebook 99"):
        assert words in broken, broken
    assert "no section 1" not in broken and "no section 2 " not in broken
    counts = "\n".join(count_problems(p, s))
    assert "'three *predict'" in counts and "has 1" in counts           # three promised, one there
    assert "2 exercises (solution blocks) but labels [1]" in counts
    assert "plan lists sections [1, 2, 3]" in counts


def test_the_finder_resolves_cross_notebook_references(tmp_path):
    p = _fake(tmp_path, "06_y.ipynb", "# 06\n\nSee notebook 04, section 7, and notebook 04's Exercise 2.")
    structures = {"06": structure(p), "04": {"sections": {7}, "exercises": [1, 2], "solutions": 2, "predicts": 0}}
    assert broken_references(p, structures) == []
    structures["04"]["sections"] = {1}
    assert broken_references(p, structures)


def test_the_bin_rule_check_sees_a_half_open_bin():
    assert HALF_OPEN_LEFT.search(r"bins are $[b_k, b_{k+1})$") and HALF_OPEN_LEFT.search(r"$[t_0 + k\,b,\ t_0 + (k+1)\,b)$")
    assert not HALF_OPEN_LEFT.search(r"bins are $(b_k, b_{k+1}]$")


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_ends_with_a_questionnaire_and_open_exercises(path):
    """Issue 24 section 5: 5-10 review questions and a numbered list of open exercises at the end."""
    md = [s for _, s in _markdown(path)]
    quiz = [s for s in md if s.startswith("## Questionnaire")]
    open_ = [s for s in md if s.startswith("## Exercises (open)")]
    assert len(quiz) == 1 and len(open_) == 1, f"{path.name}: one questionnaire and one open-exercise list"
    questions = re.findall(r"^(\d+)\. ", quiz[0], re.M)
    assert 5 <= len(questions) <= 10 and questions == [str(k) for k in range(1, len(questions) + 1)], questions
    items = re.findall(r"^(\d+)\. ", open_[0], re.M)
    assert items and items == [str(k) for k in range(1, len(items) + 1)], items
    assert md.index(open_[0]) == len(md) - 1, f"{path.name}: the open exercises are the last cell"
