"""Rewrite the scene-zoo tables of the docs from the committed results (benchmarks/zoo_results.json,
and benchmarks/zoo_results_heldout.json for the held-out scenes).

    python tools/doc_figures.py            # after `python benchmarks/quality_zoo.py [--heldout]` rewrote the JSON

Three tables, each between HTML comment markers, so the prose around them stays hand-written:

- docs/defaults.md, ``<!-- zoo-summary -->``: one row per method: the zoo mean (every scene but the
  real chunk on which the method ran) of CLAHE-SSIM, SSIM, MSE and wall time, and the real chunk's
  CLAHE-SSIM and SSIM;
- benchmarks/README.md, ``<!-- zoo-table -->``: CLAHE-SSIM / SSIM per scene and method, and the mean row;
- benchmarks/README.md, ``<!-- heldout-table -->``: per held-out scene, CLAHE-SSIM / SSIM / MSE of the
  kit, v0_1, integration + offset and the best baseline (best of hf_best, leaky_best, integration_offset
  by CLAHE-SSIM), the kit's ratio to that baseline, and the mean row.

tests/test_docs_links.py fails when the docs differ from what this writes.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from textfile import write_beside  # noqa: E402  (tools/textfile.py)

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "zoo_results.json"
HELDOUT = ROOT / "benchmarks" / "zoo_results_heldout.json"
REAL = "real_slider_chunk"
LABELS = {"kit": "kit (`EvINRConfig()`)", "kit_unfiltered": "kit_unfiltered (`EvINRConfig(background=\"keep\")`)", "paper": "paper (`EvINRConfig.paper()`)",
          "v0_1": "v0_1 (`EvINRConfig.v0_1()`)", "hf": "hf (high-pass filter)"}
BLOCKS = {"zoo-summary": ROOT / "docs" / "defaults.md", "zoo-table": ROOT / "benchmarks" / "README.md",
          "heldout-table": ROOT / "benchmarks" / "README.md"}


def load(path: Path = RESULTS) -> dict:
    return json.loads(Path(path).read_text(encoding="utf-8"))


def zoo_mean(results: dict, method: str, key: str) -> float | None:
    """Mean of ``key`` over the synthetic scenes where ``method`` ran (None when it ran on none)."""
    values = [s["rows"][method][key] for name, s in results["scenes"].items()
              if name != REAL and key in s["rows"].get(method, {})]
    return float(np.mean(values)) if values else None


def _f(v, digits: int = 3) -> str:
    return "-" if v is None else f"{v:.{digits}f}"


def _ran(results: dict) -> list:
    """The run's methods that scored at least one scene (kit_windows runs on long scenes only)."""
    return [m for m in results["methods"] if any(m in s["rows"] for s in results["scenes"].values())]


def summary_table(results: dict) -> str:
    """docs/defaults.md's table: one row per method."""
    real = results["scenes"].get(REAL, {}).get("rows", {})
    lines = ["| method | zoo mean CLAHE-SSIM | SSIM | MSE | time | real chunk CLAHE-SSIM | SSIM |",
             "|---|---|---|---|---|---|---|"]
    for m in _ran(results):
        t = zoo_mean(results, m, "time_s")
        cells = [_f(zoo_mean(results, m, "ssim_clahe")), _f(zoo_mean(results, m, "ssim_none")),
                 _f(zoo_mean(results, m, "mse_none"), 4), "-" if t is None else f"{t:.1f} s",
                 _f(real.get(m, {}).get("ssim_clahe")), _f(real.get(m, {}).get("ssim_none"))]
        lines.append(f"| {LABELS.get(m, m)} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def scene_table(results: dict) -> str:
    """benchmarks/README.md's table: CLAHE-SSIM / SSIM per scene and method, then the zoo mean."""
    methods = _ran(results)

    def pair(row):
        if row is None or "ssim_clahe" not in row:
            return "-"
        return f"{row['ssim_clahe']:.3f} / {row['ssim_none']:.3f}"

    lines = ["| scene (CLAHE-SSIM / SSIM) | " + " | ".join(methods) + " |", "|---|" + "---|" * len(methods)]
    for name, scene in results["scenes"].items():
        lines.append(f"| {name} | " + " | ".join(pair(scene["rows"].get(m)) for m in methods) + " |")
    means = [pair({"ssim_clahe": zoo_mean(results, m, "ssim_clahe"), "ssim_none": zoo_mean(results, m, "ssim_none")})
             if zoo_mean(results, m, "ssim_clahe") is not None else "-" for m in methods]
    lines.append("| **zoo mean** | " + " | ".join(means) + " |")
    return "\n".join(lines) + "\n"


def heldout_table(results: dict) -> str:
    """benchmarks/README.md's held-out table: kit, v0_1, integration + offset and the best baseline."""
    def cell(row):
        return "-" if row is None else f"{row['ssim_clahe']:.3f} / {row['ssim_none']:.3f} / {row['mse_none']:.4f}"

    lines = ["| held-out scene (CLAHE-SSIM / SSIM / MSE) | kit | v0_1 | integration_offset | best baseline | "
             "kit / best baseline (CLAHE) |", "|---|---|---|---|---|---|"]
    for name, scene in results["scenes"].items():
        rows, best = scene["rows"], scene["summary"].get("best_baseline")   # picked by quality_zoo.summarise
        lines.append(f"| {name} | {cell(rows.get('kit'))} | {cell(rows.get('v0_1'))} | "
                     f"{cell(rows.get('integration_offset'))} | {best or '-'}: {cell(rows.get(best))} | "
                     f"{_f(scene['summary'].get('kit_over_best_baseline_clahe'))} |")
    short = {"methods": results["methods"],
             "scenes": {n: s for n, s in results["scenes"].items() if not s.get("long")}}
    mean = {m: {k: zoo_mean(short, m, k) for k in ("ssim_clahe", "ssim_none", "mse_none")}
            for m in ("kit", "v0_1", "integration_offset")}
    ratios = [s["summary"]["kit_over_best_baseline_clahe"] for s in short["scenes"].values()
              if "kit_over_best_baseline_clahe" in s["summary"]]
    lines.append("| **mean, short scenes** | " + " | ".join("-" if mean[m]["ssim_clahe"] is None else cell(mean[m])
                                                           for m in ("kit", "v0_1", "integration_offset"))
                 + f" | | {_f(float(np.mean(ratios)) if ratios else None)} |")
    return "\n".join(lines) + "\n"


def blocks(results: dict, heldout: dict | None = None) -> dict:
    out = {"zoo-summary": summary_table(results), "zoo-table": scene_table(results)}
    if heldout is not None:
        out["heldout-table"] = heldout_table(heldout)
    return out


def current(text: str, name: str) -> str:
    """The text between ``<!-- name -->`` and ``<!-- /name -->`` (blank lines around it dropped)."""
    inner = text.split(f"<!-- {name} -->", 1)[1].split(f"<!-- /{name} -->", 1)[0]
    return inner.strip("\n") + "\n"


def replace(text: str, name: str, table: str) -> str:
    head, rest = text.split(f"<!-- {name} -->", 1)
    _, tail = rest.split(f"<!-- /{name} -->", 1)
    return f"{head}<!-- {name} -->\n{table}<!-- /{name} -->{tail}"


def main() -> None:
    for name, table in blocks(load(), load(HELDOUT) if HELDOUT.exists() else None).items():
        page = BLOCKS[name]
        new = replace(page.read_text(encoding="utf-8"), name, table)
        write_beside(page, new)
        print(f"wrote {page.relative_to(ROOT)} ({name})")


if __name__ == "__main__":
    main()
