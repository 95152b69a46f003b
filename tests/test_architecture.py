"""The package's architecture, checked: layers, import rules, no circles, no private names across modules.

The import rules are import-linter contracts in pyproject.toml ([tool.importlinter]); this test runs
them, so CI enforces them. ``test_a_broken_rule_fails`` proves the check can fail: it copies the
package, adds one forbidden import, and expects import-linter to report it.
"""
import ast
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("evinr_lite", "data_fetch")
SUBPACKAGES = {"core", "io", "sim", "method", "evaluation", "viz", "teaching", "apps"}

pytest.importorskip("importlinter", reason="pip install import-linter (pinned in environment.txt)")


def lint_imports(root: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", "import sys; from importlinter.cli import lint_imports_command; "
                           "sys.exit(lint_imports_command())", "--config", str(root / "pyproject.toml"), "--no-cache"],
                          cwd=root, env={"PYTHONPATH": str(root), "PATH": "/usr/bin:/bin"},
                          capture_output=True, text=True, timeout=120)


def test_import_contracts_are_kept():
    result = lint_imports(ROOT)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "0 broken" in result.stdout


def test_a_broken_rule_fails(tmp_path):
    for name in PACKAGES:
        shutil.copytree(ROOT / name, tmp_path / name, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(ROOT / "pyproject.toml", tmp_path)
    events = tmp_path / "evinr_lite" / "core" / "events.py"
    events.write_text(events.read_text() + "\nfrom ..method import solver  # a lower layer importing a higher one\n")
    result = lint_imports(tmp_path)
    assert result.returncode != 0 and "BROKEN" in result.stdout
    assert "evinr_lite.core.events -> evinr_lite.method" in result.stdout


def _modules(package: str):
    for path in sorted((ROOT / package).rglob("*.py")):
        rel = path.relative_to(ROOT).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        yield ".".join(parts), path


def _imports(name: str, path: Path):
    """(imported module, [names]) for each import in the file, relative imports resolved."""
    tree = ast.parse(path.read_text())
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module
            yield target, [a.name for a in node.names]
        elif isinstance(node, ast.Import):
            for a in node.names:
                yield a.name, []


def test_top_of_the_package_holds_only_subpackages():
    top = {p.name for p in (ROOT / "evinr_lite").iterdir() if p.name != "__pycache__"}
    assert top == {"__init__.py", "__main__.py"} | SUBPACKAGES


def test_no_private_name_crosses_a_module():
    crossings = []
    for package in PACKAGES:
        for name, path in _modules(package):
            for target, names in _imports(name, path):
                if target and target.split(".")[0] in PACKAGES:
                    crossings += [f"{name} imports {target}.{n}" for n in names if n.startswith("_")]
    assert not crossings, crossings


def test_no_import_circle():
    graph = {}
    known = {name for package in PACKAGES for name, _ in _modules(package)}
    for package in PACKAGES:
        for name, path in _modules(package):
            deps = set()
            for target, names in _imports(name, path):
                if not target or target.split(".")[0] not in PACKAGES:
                    continue
                for n in names or [""]:            # `from pkg import module` depends on pkg.module
                    deps.add(f"{target}.{n}" if f"{target}.{n}" in known else target)
            graph[name] = {d for d in deps if d in known and d != name}
    # a module importing its own package's face (``from . import exercises`` resolves to the module)
    # is the package's business, not a circle between modules
    edges = {m: {d for d in ds if not m.startswith(d + ".")} for m, ds in graph.items()}
    index, low, stack, on, circles, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            scc = []
            while True:
                w = stack.pop()
                on.discard(w)
                scc.append(w)
                if w == v:
                    break
            if len(scc) > 1:
                circles.append(sorted(scc))

    sys.setrecursionlimit(10_000)
    for v in sorted(edges):
        if v not in index:
            visit(v)
    assert not circles, circles


# the exercise registry's plain imports are checked in tests/test_exercises.py
# (test_registry_is_filled_by_the_teaching_face_with_plain_imports)


def test_public_face():
    import evinr_lite as ev

    assert 15 <= len(ev.__all__) <= 30
    for name in ev.__all__:
        assert hasattr(ev, name), name
    for sub in SUBPACKAGES:
        module = __import__(f"evinr_lite.{sub}", fromlist=["__all__"])
        assert module.__all__ and all(hasattr(module, n) or (ROOT / "evinr_lite" / sub / f"{n}.py").exists()
                                      for n in module.__all__), sub


def test_the_check_may_import_no_other_teaching_module():
    """The contract that keeps teaching.checking below the registry names every other module of teaching, so that
    a teaching module added later is not left out of it."""
    import tomllib
    contracts = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"]
    source = ["evinr_lite.teaching.checking"]
    forbidden = {m for c in contracts if c.get("source_modules") == source for m in c["forbidden_modules"]}
    teaching = ROOT / "evinr_lite" / "teaching"
    others = {f"evinr_lite.teaching.{p.stem}" for p in teaching.glob("*.py") if p.name != "__init__.py"}
    others |= {f"evinr_lite.teaching.{p.name}" for p in teaching.iterdir()
               if (p / "__init__.py").exists() and p.name != "checking"}
    assert forbidden == others
