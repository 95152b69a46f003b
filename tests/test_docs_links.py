"""The README and docs/ hold together: every relative link resolves, the README's example runs, and the
zoo figures quoted in the docs are those of the committed results (benchmarks/zoo_results.json)."""
from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")), ROOT / "benchmarks" / "README.md"]

_FENCE = re.compile(r"^(```|~~~)")
_LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
_CODE_SPAN = re.compile(r"`+[^`]*`+")


def _prose_lines(text: str):
    """(line number, line) outside fenced code blocks."""
    fenced = False
    for i, line in enumerate(text.splitlines(), 1):
        if _FENCE.match(line.strip()):
            fenced = not fenced
            continue
        if not fenced:
            yield i, line


def github_slug(heading: str) -> str:
    """GitHub's anchor for a heading: lower case, markup and punctuation dropped, spaces -> '-'."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)      # a link keeps its text
    text = text.strip().lower().replace("`", "")
    text = re.sub(r"[^\w\- ]", "", text)                           # keeps letters, digits, _ and -
    return text.replace(" ", "-")


def anchors(path: Path) -> set[str]:
    """Every heading anchor of a markdown file, numbered as GitHub numbers repeats (-1, -2, ...)."""
    seen: dict[str, int] = {}
    out = set()
    for _, line in _prose_lines(path.read_text(encoding="utf-8")):
        m = re.match(r"^(#{1,6})\s+(.*?)\s*#*\s*$", line)
        if not m:
            continue
        slug = github_slug(m.group(2))
        n = seen.get(slug, 0)
        seen[slug] = n + 1
        out.add(slug if n == 0 else f"{slug}-{n}")
    return out


def relative_links(path: Path):
    """(line number, target) of every relative link in a markdown file (code spans and blocks skipped)."""
    for i, line in _prose_lines(path.read_text(encoding="utf-8")):
        for m in _LINK.finditer(_CODE_SPAN.sub("", line)):
            target = m.group(1)
            if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):    # http:, https:, mailto:
                continue
            yield i, target


def broken_links(path: Path) -> list[str]:
    problems = []
    for line, target in relative_links(path):
        file_part, _, anchor = target.partition("#")
        dest = (path.parent / file_part).resolve() if file_part else path
        where = f"{path.relative_to(ROOT)}:{line}: [{target}]"
        if not dest.exists():
            problems.append(f"{where}: {dest.relative_to(ROOT) if dest.is_relative_to(ROOT) else dest} does not exist")
        elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
            problems.append(f"{where}: no heading '#{anchor}' in {dest.relative_to(ROOT)}")
    return problems


@pytest.mark.parametrize("path", DOCS, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_relative_link_resolves(path):
    assert path.exists()
    problems = broken_links(path)
    assert not problems, "broken links (fix the target or the heading):\n" + "\n".join(problems)


def test_the_link_checker_catches_a_missing_file_and_a_missing_anchor(tmp_path, monkeypatch):
    monkeypatch.setattr(sys.modules[__name__], "ROOT", tmp_path)
    (tmp_path / "other.md").write_text("# Other page\n\n## The `--denoise` option: what it does\n")
    page = tmp_path / "page.md"
    page.write_text("# Page\n\n## Two  words\n\n[ok](other.md#the---denoise-option-what-it-does) [ok](#page)"
                    " [ok](#two--words) [gone](missing.md) [bad](other.md#nope) [web](https://example.org/x)\n"
                    "```\n[in code](missing_too.md)\n```\n`[span](missing_span.md)`\n")
    problems = broken_links(page)
    assert len(problems) == 2, problems
    assert "missing.md does not exist" in problems[0] and "no heading '#nope'" in problems[1]


def test_github_slugs():
    assert github_slug("Set up and run: two commands") == "set-up-and-run-two-commands"
    assert github_slug("`demo`: the main job (no download)") == "demo-the-main-job-no-download"
    assert github_slug("Defaults: the kit's recipe and the paper's") == "defaults-the-kits-recipe-and-the-papers"
    assert github_slug("`--anchor`: APS frames as anchors") == "--anchor-aps-frames-as-anchors"


def test_the_readme_keeps_its_sections_and_length():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    heads = anchors(ROOT / "README.md")
    for section in ("set-up-and-run-two-commands", "run-the-tests", "how-the-data-flows", "conventions",
                    "where-next", "figures"):
        assert section in heads, f"README.md lost its section #{section}"
    assert len(text.splitlines()) <= 200, "README.md is meant to be read in five minutes: move detail to docs/"


def _doc_figures():
    import importlib.util

    spec = importlib.util.spec_from_file_location("doc_figures", ROOT / "tools" / "doc_figures.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_zoo_tables_in_the_docs_are_the_committed_results():
    """docs/defaults.md and benchmarks/README.md quote benchmarks/zoo_results.json as it is committed."""
    figures = _doc_figures()
    for name, table in figures.blocks(figures.load(), figures.load(figures.HELDOUT)).items():
        page = figures.BLOCKS[name]
        assert figures.current(page.read_text(encoding="utf-8"), name) == table, (
            f"{page.relative_to(ROOT)}: the {name} table differs from benchmarks/zoo_results[_heldout].json; "
            "run python tools/doc_figures.py")


def test_doc_figures_means_and_missing_runs():
    """The zoo mean leaves out the real chunk and the scenes a method did not run on; a gap prints '-'."""
    figures = _doc_figures()
    row = {"ssim_clahe": 0.5, "ssim_none": 0.6, "mse_none": 0.01, "time_s": 2.0}
    results = {"methods": ["kit", "paper"], "scenes": {
        "a": {"rows": {"kit": row, "paper": {**row, "ssim_clahe": 0.2}}},
        "b": {"rows": {"kit": {**row, "ssim_clahe": 0.7, "time_s": 4.0}}},                # paper skipped here
        figures.REAL: {"rows": {"kit": {**row, "ssim_clahe": 0.9}}}}}
    assert figures.zoo_mean(results, "kit", "ssim_clahe") == pytest.approx(0.6)         # (0.5 + 0.7) / 2
    assert figures.zoo_mean(results, "paper", "ssim_clahe") == pytest.approx(0.2)
    summary = figures.summary_table(results)
    assert "| kit (`EvINRConfig()`) | 0.600 | 0.600 | 0.0100 | 3.0 s | 0.900 | 0.600 |" in summary
    assert "| paper (`EvINRConfig.paper()`) | 0.200 | 0.600 | 0.0100 | 2.0 s | - | - |" in summary
    table = figures.scene_table(results)
    assert "| b | 0.700 / 0.600 | - |" in table and "| **zoo mean** | 0.600 / 0.600 | 0.200 / 0.600 |" in table


def test_the_readme_python_example_runs():
    """The six lines under 'Six lines of Python', as printed (the comments state what they give)."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    section = text.split("## Six lines of Python", 1)[1]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    assert len(code.strip().splitlines()) == 6
    scope: dict = {}
    exec(compile(code, "README.md", "exec"), scope)
    rec = scope["rec"]
    assert rec.frames.shape == (10, 120, 160) and 0 <= rec.frames.min() and rec.frames.max() <= 1
    assert rec.frames_at([0.5, 0.51]).shape == (2, 120, 160)


_DOTTED = re.compile(r"\b((?:evinr_lite|data_fetch)(?:\.[A-Za-z_]\w*)+)")
_SOURCE = re.compile(r"(?<![\w/.-])((?:[\w.-]+/)+[\w.-]+\.(?:py|ipynb))\b")


def _resolve(name: str):
    """The module or attribute a dotted name names (ImportError / AttributeError when it does not exist)."""
    import importlib

    parts = name.split(".")
    for i in range(len(parts), 0, -1):
        try:
            obj = importlib.import_module(".".join(parts[:i]))
        except ModuleNotFoundError:
            continue
        for attr in parts[i:]:
            obj = getattr(obj, attr)
        return obj
    raise ImportError(name)


@pytest.mark.parametrize("path", DOCS, ids=lambda p: str(p.relative_to(ROOT)))
def test_named_modules_functions_and_source_files_exist(path):
    """A name such as evinr_lite.method.contrast.fit_contrast, or a file such as method/head_solve.py,
    still exists after a refactor (the docs move with the code)."""
    problems = []
    for line, text in _prose_lines(path.read_text(encoding="utf-8")):
        for m in _DOTTED.finditer(text):
            name = m.group(1)
            if name.endswith((".md", ".py", ".h5", ".json")):      # a file name, checked below or not at all
                continue
            try:
                _resolve(name)
            except (ImportError, AttributeError) as err:
                problems.append(f"{path.relative_to(ROOT)}:{line}: {name} ({type(err).__name__}: {err})")
        for m in _SOURCE.finditer(text):
            rel = m.group(1)
            if re.search(r"NN|\*", rel):                             # a pattern (notebooks/NN_name.ipynb)
                continue
            if not any(p.exists() for p in (ROOT / rel, ROOT / "evinr_lite" / rel, path.parent / rel)):
                problems.append(f"{path.relative_to(ROOT)}:{line}: {rel} does not exist")
    assert not problems, "the docs name things that do not exist (update the docs):\n" + "\n".join(problems)


def test_docs_architecture_lists_every_module():
    """docs/architecture.md's 'Every module' names each module of evinr_lite under its subpackage."""
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    listed = text.split("<!-- modules -->", 1)[1].split("<!-- /modules -->", 1)[0]
    sections = {m.group(1): m.group(2) for m in re.finditer(r"^### `([\w.]+)`\n(.*?)(?=^### |\Z)", listed, re.M | re.S)}
    missing = []
    for path in sorted((ROOT / "evinr_lite").rglob("*.py")):
        if path.name in ("__init__.py", "__main__.py") or path.parent == ROOT / "evinr_lite":
            continue
        package = ".".join(path.parent.relative_to(ROOT / "evinr_lite").parts)
        if not re.search(rf"^- `{path.stem}`: \S", sections.get(package, ""), re.M):
            missing.append(f"{package}.{path.stem}")
    assert sections and not missing, ("docs/architecture.md does not list these modules (run python "
                                      "tools/doc_modules.py): " + ", ".join(missing))
