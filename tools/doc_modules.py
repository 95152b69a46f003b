"""Rewrite the 'Every module' list of docs/architecture.md from the modules' own docstrings.

    python tools/doc_modules.py          # rewrites the part between <!-- modules --> and <!-- /modules -->

Each module gets one line: its docstring's first paragraph, reST roles turned into code spans.
tests/test_docs_links.py fails when a module is missing from the list.
"""
from __future__ import annotations

import ast
import re
import textwrap
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from textfile import write_beside  # noqa: E402  (tools/textfile.py)

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("core", "io", "io/formats", "sim", "method", "evaluation", "viz", "teaching", "teaching/checking",
            "apps")   # by layer


def summary(path: Path) -> str:
    """The module docstring's first paragraph on one line, reST roles as plain code spans."""
    doc = ast.get_docstring(ast.parse(path.read_text(encoding="utf-8"))) or ""
    para = " ".join(doc.split("\n\n")[0].split())
    para = re.sub(r":\w+:`~?([^`]+)`", r"`\1`", para)
    return para.replace("``", "`")


def module_list() -> str:
    out = []
    for pkg in PACKAGES:
        out.append(f"### `{pkg.replace('/', '.')}`\n")
        for path in sorted((ROOT / "evinr_lite" / pkg).glob("*.py")):
            if path.name in ("__init__.py", "__main__.py"):
                continue
            out.append(textwrap.fill(f"- `{path.stem}`: {summary(path)}", 110, subsequent_indent="  ",
                                     break_on_hyphens=False, break_long_words=False))
        out.append("")
    return "\n".join(out)


def main() -> None:
    page = ROOT / "docs" / "architecture.md"
    text = page.read_text(encoding="utf-8")
    head, rest = text.split("<!-- modules -->\n", 1)
    _, tail = rest.split("<!-- /modules -->", 1)
    new = head + "<!-- modules -->\n\n" + module_list() + "<!-- /modules -->" + tail
    write_beside(page, new)
    print(f"wrote {page.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
