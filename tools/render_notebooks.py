"""Render the notebooks as a static HTML gallery: executed, with their figures.

    python tools/render_notebooks.py                 # fast mode (the tests' sizes), into site/
    python tools/render_notebooks.py --full          # the notebooks' full sizes (much longer)
    python tools/render_notebooks.py --out /tmp/site --only 01 05
    python -m http.server -d site 8000               # then open http://127.0.0.1:8000/ (or open site/index.html)

Each notebook in ``notebooks/`` is executed top to bottom in a fresh kernel (nbclient, the same
executor nbval uses; ``EVINR_FAST=1`` unless ``--full``; interactive figures drawn once, statically,
``EVINR_LIVE_WIDGETS=0``) and written by nbconvert's HTML exporter (the JupyterLab template) as
``site/NN_name.html`` with its figures as PNG files in ``site/NN_name_files/``. ``site/index.html``
lists the notebooks in reading order: each one's question (the notebook's **Question.**
paragraph), its first figure as a thumbnail, its run time (seconds) and the mode it ran in.

Why nbconvert and not jupyter-book / myst-nb: the site is a flat list of executed notebooks, which
nbconvert (already installed with JupyterLab) writes in one call per notebook; jupyter-book would
add a Sphinx build, a table of contents and a configuration file for the same pages.

**Executed copies** (``--executed``): the same fast-mode execution, saved as notebooks in
``docs/executed/NN_name.ipynb`` with every output, figures re-encoded small (at most
``EXECUTED_WIDTH`` pixels wide, 64-colour PNG), so that a reader sees every figure and printed
result in the repository's web view without running anything. ``--check-executed`` (and
``tests/test_executed_notebooks.py``) says which copies are missing, extra, stale (a cell's source
differs from its notebook's) or broken (a cell that did not run, or an error output). Regenerate
after changing a notebook: ``nice python tools/render_notebooks.py --executed --only 04``.

The site is written into a temporary folder beside ``--out`` and renamed into place when every
notebook has run (a failing notebook stops the build, names the cell, and leaves ``--out`` as it
was). Exit status: 0 done, 1 a notebook failed, 2 bad arguments.
"""
from __future__ import annotations

import argparse
import base64
import html
import io
import json
import os
import re
import shutil
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"
THUMB_WIDTH = 360   # pixels
EXECUTED = ROOT / "docs" / "executed"
EXECUTED_WIDTH = 640   # pixels: the widest figure in an executed copy
EXECUTED_COLOURS = 64  # palette size of its PNGs (figures are line plots and grey images)

INDEX_CSS = """
body { font-family: system-ui, sans-serif; max-width: 1100px; margin: 2em auto; padding: 0 1em; color: #222; }
.card { display: flex; gap: 1.2em; border-bottom: 1px solid #ddd; padding: 1em 0; }
.card img { width: %dpx; height: auto; border: 1px solid #ccc; flex-shrink: 0; }
.card .none { width: %dpx; flex-shrink: 0; color: #888; }
.card h2 { margin: 0 0 .3em 0; font-size: 1.15em; }
.meta { color: #666; font-size: .9em; }
""" % (THUMB_WIDTH, THUMB_WIDTH)


def notebook_paths(folder: Path = NOTEBOOKS, only=None) -> list[Path]:
    """The notebooks in reading order (their NN_ prefix); ``only``: prefixes or names to keep."""
    paths = sorted(folder.glob("[0-9][0-9]_*.ipynb"))
    if only:
        keep = [p for p in paths if any(p.stem == o or p.stem.startswith(f"{o}_") or p.name == o for o in only)]
        missing = [o for o in only if not any(p.stem == o or p.stem.startswith(f"{o}_") or p.name == o for p in paths)]
        if missing:
            raise SystemExit(f"render_notebooks: no notebook {', '.join(missing)} in {folder} "
                             f"(known: {', '.join(p.stem for p in paths)})")
        paths = keep
    if not paths:
        raise SystemExit(f"render_notebooks: no NN_*.ipynb notebooks in {folder}")
    return paths


LATEX = {"Theta": "Θ", "theta": "θ", "times": "×", "lambda": "λ", "gamma": "γ", "tau": "τ", "partial": "∂",
         "Delta": "Δ", "mu": "µ", "sigma": "σ", "approx": "≈", "le": "≤", "ge": "≥", "cdot": "·"}


def _markdown_text(md: str) -> str:
    """Markdown to plain text, enough for a one-paragraph summary (inline maths as Unicode)."""
    md = re.sub(r"\$([^$]+)\$", lambda m: re.sub(r"\\([A-Za-z]+)", lambda c: LATEX.get(c.group(1), c.group(1)),
                                                 m.group(1)), md)
    md = re.sub(r"[*_`]+", "", md)
    md = re.sub(r"\[([^\]]+)\]\([^)]+\)", r"\1", md)
    return " ".join(md.split())


def describe(nb) -> dict:
    """The notebook's title (first heading) and question (its **Question.** paragraph, else the
    first paragraph after the title)."""
    title, question = None, None
    for cell in nb.cells:
        if cell.cell_type != "markdown":
            continue
        paragraphs = [p.strip() for p in cell.source.split("\n\n") if p.strip()]
        for p in paragraphs:
            if title is None and p.startswith("#"):
                title = p.lstrip("#").strip()
            elif question is None and p.startswith("**Question"):
                question = _markdown_text(re.sub(r"^\*\*Question\.?\*\*\.?", "", p))
        if title is not None and question is None:
            rest = [p for p in paragraphs if not p.startswith("#")]
            if rest:
                question = _markdown_text(rest[0])
        if title is not None and question is not None:
            break
    return {"title": title or "(untitled)", "question": question or ""}


def first_figure(nb) -> bytes | None:
    """The PNG bytes of the first figure in the executed notebook's outputs."""
    for cell in nb.cells:
        for out in cell.get("outputs", []):
            data = out.get("data", {})
            if "image/png" in data:
                return base64.b64decode(data["image/png"])
    return None


def thumbnail(png: bytes, path: Path, width: int = THUMB_WIDTH) -> None:
    from PIL import Image

    img = Image.open(io.BytesIO(png))
    if img.width > width:
        img = img.resize((width, round(img.height * width / img.width)), Image.LANCZOS)
    img.save(path)


def execute(path: Path, *, full: bool, timeout: int) -> tuple:
    """Run the notebook in a fresh kernel in its own folder; returns (notebook, seconds)."""
    import nbformat
    from nbclient import NotebookClient

    nb = nbformat.read(path, as_version=4)
    scratch = tempfile.TemporaryDirectory(prefix="evinr_render_")   # a notebook's mkdtemp lands here, then goes
    env = {"EVINR_FAST": "0" if full else "1", "EVINR_LIVE_WIDGETS": "0", "TMPDIR": scratch.name,
           "MPLBACKEND": "module://matplotlib_inline.backend_inline"}   # figures as PNG outputs, even under Agg
    saved = {k: os.environ.get(k) for k in env}
    os.environ.update(env)   # the kernel inherits this process's environment
    try:
        client = NotebookClient(nb, timeout=timeout, kernel_name="python3",
                                resources={"metadata": {"path": str(path.parent)}})
        t0 = time.perf_counter()
        client.execute()
        return nb, time.perf_counter() - t0
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
        scratch.cleanup()


def write_page(nb, stem: str, site: Path) -> int:
    """nbconvert's HTML (JupyterLab template), figures extracted to ``<stem>_files/``; returns the count."""
    from nbconvert import HTMLExporter
    from traitlets.config import Config

    config = Config()
    config.HTMLExporter.preprocessors = ["nbconvert.preprocessors.ExtractOutputPreprocessor"]
    config.ExtractOutputPreprocessor.output_filename_template = "{unique_key}_{cell_index}_{index}{extension}"
    exporter = HTMLExporter(config=config, template_name="lab")
    body, resources = exporter.from_notebook_node(nb, resources={"output_files_dir": f"{stem}_files",
                                                                 "unique_key": stem})
    outputs = resources.get("outputs", {})
    for name, data in outputs.items():
        target = site / name
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(data)
    (site / f"{stem}.html").write_text(body, encoding="utf-8")
    return sum(name.endswith(".png") for name in outputs)


def write_index(entries: list[dict], site: Path, *, full: bool) -> None:
    mode = "full size" if full else "fast mode (the tests' small sizes; --full for the notebooks' full sizes)"
    cards = []
    for e in entries:
        thumb = (f'<img src="{html.escape(e["thumbnail"])}" alt="first figure of {html.escape(e["stem"])}">'
                 if e["thumbnail"] else '<div class="none">(no figure)</div>')
        cards.append(f"""<div class="card"><a href="{html.escape(e['page'])}">{thumb}</a><div>
<h2><a href="{html.escape(e['page'])}">{html.escape(e['title'])}</a></h2>
<p>{html.escape(e['question'])}</p>
<p class="meta">{e['n_figures']} figure(s); ran in {e['seconds']:.1f} s</p></div></div>""")
    total = sum(e["seconds"] for e in entries)
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>evinr-lite notebooks</title>
<style>{INDEX_CSS}</style></head><body>
<h1>evinr-lite: the notebooks, rendered</h1>
<p>Event-camera video reconstruction with EvINR, step by step. Executed in {mode}: {len(entries)} notebook(s)
in {total:.0f} s, built {time.strftime('%Y-%m-%d %H:%M')}. Run them yourself: <code>jupyter lab notebooks/</code>.</p>
{''.join(cards)}
</body></html>
"""
    (site / "index.html").write_text(page, encoding="utf-8")


def build(out="site", *, full: bool = False, only=None, notebooks_dir: Path = NOTEBOOKS, timeout: int = 1200,
          log=print) -> dict:
    """Execute the notebooks and write the site into ``out``; returns {"entries", "seconds", "out"}."""
    from nbclient.exceptions import CellExecutionError

    out = Path(out)
    paths = notebook_paths(Path(notebooks_dir), only)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.partial-", dir=out.parent))
    t0 = time.perf_counter()
    entries = []
    try:
        (tmp / "thumbs").mkdir()
        for path in paths:
            log(f"render_notebooks: {path.name} ...", end=" ", flush=True)
            try:
                nb, seconds = execute(path, full=full, timeout=timeout)
            except CellExecutionError as err:
                raise RuntimeError(f"{path.name} failed while executing; {out} was left as it was.\n{err}") from None
            n_figures = write_page(nb, path.stem, tmp)
            png = first_figure(nb)
            thumb = None
            if png is not None:
                thumb = f"thumbs/{path.stem}.png"
                thumbnail(png, tmp / thumb)
            entries.append({"stem": path.stem, "page": f"{path.stem}.html", "thumbnail": thumb, "seconds": seconds,
                            "n_figures": n_figures, **describe(nb)})
            log(f"{seconds:.1f} s, {n_figures} figure(s)")
        write_index(entries, tmp, full=full)
        (tmp / "gallery.json").write_text(json.dumps({"full": full, "entries": entries}, indent=2) + "\n")
        if out.exists():
            shutil.rmtree(out)
        os.replace(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    seconds = time.perf_counter() - t0
    log(f"render_notebooks: wrote {out}/index.html ({len(entries)} notebook(s)) in {seconds:.1f} s")
    return {"entries": entries, "seconds": seconds, "out": str(out)}


# ---- executed copies ------------------------------------------------------------------------------

def small_png(png: bytes, width: int = EXECUTED_WIDTH, colours: int = EXECUTED_COLOURS) -> bytes:
    """A figure re-encoded small: at most ``width`` pixels wide, a ``colours``-colour palette PNG."""
    from PIL import Image

    img = Image.open(io.BytesIO(png)).convert("RGB")
    if img.width > width:
        img = img.resize((width, round(img.height * width / img.width)), Image.LANCZOS)
    out = io.BytesIO()
    img.quantize(colours, method=Image.Quantize.MEDIANCUT).save(out, format="PNG", optimize=True)
    return out.getvalue()


def _cell_key(cell) -> tuple:
    return cell["cell_type"], "".join(cell["source"]) if isinstance(cell["source"], list) else cell["source"]


def executed_copy(nb, seconds: float, source_name: str):
    """The executed notebook made small and stable: small figures, no widget state, no timestamps."""
    for cell in nb.cells:
        cell.get("metadata", {}).pop("execution", None)
        for out in cell.get("outputs", []):
            data = out.get("data", {})
            if "image/png" in data:
                data["image/png"] = base64.b64encode(small_png(base64.b64decode(data["image/png"]))).decode()
                out.get("metadata", {}).pop("image/png", None)
            data.pop("application/vnd.jupyter.widget-view+json", None)
    nb.metadata.pop("widgets", None)
    nb.metadata["evinr_executed"] = {"source": f"notebooks/{source_name}", "mode": "fast (EVINR_FAST=1)",
                                     "seconds": round(seconds, 1),
                                     "regenerate": f"python tools/render_notebooks.py --executed --only {source_name[:2]}"}
    return nb


def executed_problems(notebooks_dir: Path = NOTEBOOKS, executed_dir: Path = EXECUTED) -> list[str]:
    """What is wrong with the executed copies: missing, extra, stale or broken (empty when all is well)."""
    sources = {p.name: p for p in notebook_paths(notebooks_dir)}
    copies = {p.name: p for p in sorted(Path(executed_dir).glob("[0-9][0-9]_*.ipynb"))}
    found = [f"missing: {executed_dir.name}/{n}" for n in sources if n not in copies]
    found += [f"extra: {executed_dir.name}/{n} (no notebooks/{n})" for n in copies if n not in sources]
    for name in sorted(set(sources) & set(copies)):
        src_cells = json.loads(sources[name].read_text())["cells"]
        copy_cells = json.loads(copies[name].read_text())["cells"]
        if [_cell_key(c) for c in src_cells] != [_cell_key(c) for c in copy_cells]:
            diff = next((i for i, (a, b) in enumerate(zip(src_cells, copy_cells)) if _cell_key(a) != _cell_key(b)),
                        min(len(src_cells), len(copy_cells)))
            found.append(f"stale: {executed_dir.name}/{name} (cell {diff} differs from notebooks/{name})")
            continue
        for i, cell in enumerate(copy_cells):
            if cell["cell_type"] != "code" or not "".join(cell["source"]).strip():
                continue
            if cell.get("execution_count") is None:
                found.append(f"broken: {executed_dir.name}/{name} cell {i} did not run")
                break
            if any(o.get("output_type") == "error" for o in cell.get("outputs", [])):
                found.append(f"broken: {executed_dir.name}/{name} cell {i} has an error output")
                break
    return found


def write_executed(only=None, *, notebooks_dir: Path = NOTEBOOKS, out: Path = EXECUTED, timeout: int = 1200,
                   log=print) -> list[Path]:
    """Execute (fast mode) and write the executed copy of each notebook, atomically; returns the paths."""
    import nbformat

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for path in notebook_paths(Path(notebooks_dir), only):
        log(f"render_notebooks: executing {path.name} ...", end=" ", flush=True)
        nb, seconds = execute(path, full=False, timeout=timeout)
        nb = executed_copy(nb, seconds, path.name)
        fd, tmp = tempfile.mkstemp(dir=out, prefix=f".{path.name}.", suffix=".tmp")
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            nbformat.write(nb, f)
        os.chmod(tmp, 0o644)                    # mkstemp makes it private; a repository file is readable
        os.replace(tmp, out / path.name)
        written.append(out / path.name)
        log(f"{seconds:.1f} s, {(out / path.name).stat().st_size / 1e3:.0f} kB")
    return written


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--full", action="store_true", help="execute at the notebooks' full sizes (default: fast mode)")
    p.add_argument("--out", default=str(ROOT / "site"), help="output folder (default: site/ in the repository)")
    p.add_argument("--only", nargs="+", metavar="NN", help="only these notebooks (prefixes such as 01 05, or names)")
    p.add_argument("--timeout", type=int, default=1200, help="seconds allowed per cell (default: 1200)")
    p.add_argument("--executed", action="store_true",
                   help="write the executed copies docs/executed/NN_*.ipynb (fast mode) instead of the site")
    p.add_argument("--check-executed", action="store_true",
                   help="only report missing, extra, stale or broken executed copies (exit 1)")
    args = p.parse_args(argv)
    if args.check_executed:
        found = executed_problems()
        for line in found:
            print(line)
        if found:
            print("regenerate with `nice python tools/render_notebooks.py --executed --only NN`", file=sys.stderr)
            return 1
        print("docs/executed/: every executed copy is current")
        return 0
    if args.executed:
        from nbclient.exceptions import CellExecutionError
        try:
            write_executed(args.only, timeout=args.timeout)
        except CellExecutionError as err:
            print(f"\nrender_notebooks: error: {err}", file=sys.stderr)
            return 1
        return 0
    try:
        build(args.out, full=args.full, only=args.only, timeout=args.timeout)
    except RuntimeError as err:
        print(f"\nrender_notebooks: error: {err}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
