"""How much the temporal scale's constant matters: the kit under FLIPS_REF 2.0, 2.5 (the kit's) and 3.0.

    python benchmarks/temporal_scale.py                          # zoo + real chunk, held out, stress, fresh 11-23
    python benchmarks/temporal_scale.py --sets zoo,stress --refs 2,2.5,3

``temporal_scale="auto"`` (:mod:`evinr_lite.method.tempo`) sets s = clip(f / FLIPS_REF, 1, 4) from f, the
median polarity reversals per pixel and second of the events the kit trains on. FLIPS_REF = 2.5 was set on
the zoo and one fresh seed; this script asks whether the result hangs on that number. For each set it
simulates every scene, reads its reversal rate f (the kit's own preparation, :func:`prepare_events`), and
trains the kit under each FLIPS_REF on the scenes whose f exceeds the smallest one (on the others every
FLIPS_REF gives s = 1: the same bytes). Scored as the zoo scores (``quality_zoo.run_zoo``; CLAHE-SSIM /
SSIM / MSE). Sets: ``zoo`` (with the real slider_depth chunk when it is beside the project), ``heldout``,
``stress``, ``large`` and fresh seeds given as numbers (``evinr_lite.sim.zoo.fresh(seed, 16)``). Writes
``temporal_scale_results.json`` and ``.md`` beside this script (``--json`` / ``--md`` to move them).
About 25 minutes for the default sets on 2 cores.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.quality_zoo import run_real, run_zoo  # noqa: E402
from evinr_lite.method import EvINRConfig  # noqa: E402
from evinr_lite.method import tempo  # noqa: E402
from evinr_lite.method.prepare import prepare_events  # noqa: E402
from evinr_lite.sim.zoo import HELDOUT, LARGE, STRESS, default_scenes, effective_C, fresh, simulate  # noqa: E402

HERE = Path(__file__).resolve().parent
DEFAULT_SETS = "zoo,heldout,stress," + ",".join(str(s) for s in range(11, 24))


@contextmanager
def flips_ref(ref: float, max_scale: float | None = None):
    """tempo.FLIPS_REF (and MAX_SCALE) set for the block, then put back: the rule reads them at each call."""
    old = tempo.FLIPS_REF, tempo.MAX_SCALE
    tempo.FLIPS_REF = ref
    tempo.MAX_SCALE = old[1] if max_scale is None else max_scale
    try:
        yield
    finally:
        tempo.FLIPS_REF, tempo.MAX_SCALE = old


def pool(name: str) -> list:
    named = {"zoo": default_scenes(False), "heldout": HELDOUT, "stress": STRESS, "large": LARGE}
    if name in named:
        return list(named[name])
    if not name.isdigit():
        raise SystemExit(f"temporal_scale.py: unknown set {name!r}: give zoo, heldout, stress, large or a fresh seed")
    return fresh(int(name), 16)


def reversal_rate(z) -> float:
    """f of a scene: its median reversals per pixel and second (at least 1: lower rates read as 1)."""
    _, events, _, _ = simulate(z)
    with flips_ref(1.0, max_scale=np.inf):
        return float(prepare_events(events, EvINRConfig(C=effective_C(z)))[1].temporal_scale)


def run(sets: list, refs: list, log=print) -> dict:
    out = {}
    for name in sets:
        scenes = pool(name)
        rates = {z.name: reversal_rate(z) for z in scenes}
        changed = [z for z in scenes if rates[z.name] > min(refs)]
        log(f"{name}: {len(changed)} of {len(scenes)} scenes above {min(refs)} reversals per pixel and second")
        per_ref = {}
        for ref in refs:
            with flips_ref(ref):
                res = run_zoo(changed, ["kit"], {}, log=lambda *a: None) if changed else {}
                if name == "zoo":
                    real = run_real(["kit"], {}, log=lambda *a: None)
                    if real is not None:
                        res["real_slider_chunk"] = real
            per_ref[ref] = {n: r["rows"]["kit"] for n, r in res.items()}
        for n in per_ref[refs[0]]:
            out[n] = {"set": name, "rate": rates.get(n), "kit": {str(ref): per_ref[ref][n] for ref in refs}}
            cells = "  ".join(f"{ref:g}: {cell(per_ref[ref][n])}" for ref in refs)
            log(f"  {n:42s} f {out[n]['rate'] if out[n]['rate'] is not None else float('nan'):5.2f}  {cells}")
    return out


def cell(k: dict) -> str:
    return f"{k['ssim_clahe']:.3f} / {k['ssim_none']:.3f} / {k['mse_none']:.4f}"


def summary(out: dict, refs: list, base: float) -> list:
    lines = []
    for ref in refs:
        if ref == base:
            continue
        d = {m: np.array([r["kit"][str(ref)][m] - r["kit"][str(base)][m] for r in out.values()])
             for m in ("ssim_clahe", "ssim_none", "mse_none")}
        c = d["ssim_clahe"]
        lines.append(f"FLIPS_REF {ref:g} against {base:g} on {len(c)} scenes: CLAHE-SSIM mean {c.mean():+.4f} "
                     f"(min {c.min():+.3f}, max {c.max():+.3f}; {int((c > 0.001).sum())} up, {int((c < -0.001).sum())} "
                     f"down by more than 0.001), SSIM mean {d['ssim_none'].mean():+.4f}, MSE mean {d['mse_none'].mean():+.5f}")
    return lines


def markdown(out: dict, refs: list, lines: list) -> str:
    head = "| set | scene | reversals / px / s | " + " | ".join(f"FLIPS_REF {r:g}" for r in refs) + " |"
    rows = [head, "|" + "---|" * (3 + len(refs))]
    for n, r in out.items():
        rate = "-" if r["rate"] is None else f"{r['rate']:.2f}"
        rows.append(f"| {r['set']} | {n} | {rate} | " + " | ".join(cell(r["kit"][str(x)]) for x in refs) + " |")
    return ("\n".join(rows) + "\n\nCells: the kit's CLAHE-SSIM / SSIM / MSE (`python benchmarks/temporal_scale.py`). "
            "Scenes at or below the smallest FLIPS_REF train at s = 1 under every value and are not listed.\n\n"
            + "\n".join(f"- {x}" for x in lines) + "\n")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--sets", default=DEFAULT_SETS, help="comma-separated: zoo, heldout, stress, large, fresh seeds")
    p.add_argument("--refs", default="2.0,2.5,3.0", help="FLIPS_REF values (reversals per pixel and second)")
    p.add_argument("--json", default=str(HERE / "temporal_scale_results.json"))
    p.add_argument("--md", default=str(HERE / "temporal_scale_results.md"))
    a = p.parse_args(argv)
    try:
        refs = sorted(float(r) for r in a.refs.split(","))
    except ValueError:
        p.error(f"--refs must be numbers separated by commas, got {a.refs!r}")
    if not refs or min(refs) <= 0:
        p.error(f"--refs must be positive numbers, got {a.refs!r}")
    base = tempo.FLIPS_REF if tempo.FLIPS_REF in refs else refs[len(refs) // 2]
    t0 = time.perf_counter()
    out = run([s for s in a.sets.split(",") if s], refs)
    lines = summary(out, refs, base)
    print("\n".join(lines) + f"\nrun: {time.perf_counter() - t0:.0f} s")
    if a.json:
        Path(a.json).write_text(json.dumps({"refs": refs, "base": base, "scenes": out, "summary": lines}, indent=1,
                                           default=float) + "\n")
    if a.md:
        Path(a.md).write_text(markdown(out, refs, lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
