"""Where the kit's error lives: the display level, the static image (its tilt, coarse and fine parts)
and the changes in time, per zoo scene, in log units.

    python benchmarks/static_error.py              # the 13 short zoo scenes (about 1 min on 2 cores)
    python benchmarks/static_error.py --heldout    # the held-out scenes (zoo.HELDOUT, short ones)
    python benchmarks/static_error.py --scenes noisy_gravel,camera_translate
    python benchmarks/static_error.py --events signal --set balance=none    # what the tilt is not caused by
    python benchmarks/static_error.py --true-thresholds                     # given the simulated C+ / C-

Events fix log intensity only up to one image that every frame shares (the static image, which the
kit's offset solve chooses: :mod:`evinr_lite.method.offset`), and up to one constant (the display
level). So the kit's log error e_k = L_k - L_true_k at the scored times splits exactly into

    level    the mean of e over pixels and times (a choice of display, :mod:`evinr_lite.method.tonemap`);
    tilt     the least-squares plane a x + b y of the static error mean_k e_k - level;
    coarse   what is left of the static error below ``SIGMA`` px (a Gaussian's sigma);
    fine     the rest of the static error;
    changes  e_k - mean_k e_k: what differs between the frames.

Each is reported as a root mean square (log units), beside the truth's own tilt (the plane of its
mean log image), and the tilts as log units across the sensor (x: left to right, y: top to bottom).
Two re-displays of the same reconstruction show what the tilt costs in the zoo's metrics (CLAHE-SSIM
/ SSIM / MSE, the same display and level rule as the kit's): its tilt removed, and its tilt replaced
by the truth's (an oracle: the truth is not known to any method). Writes
benchmarks/static_error_results[_heldout].{json,md}.

Three options give the kit what events cannot tell it, or take a part of the method away, to find
what causes a part of the error: ``--events signal`` keeps only the events of the scene's brightness
changes (the zoo's labels: no background activity, no hot pixels), ``--true-thresholds`` gives the
method the simulated C+ / C- instead of the nominal C, and ``--set FIELD=VALUE,...`` changes fields of
``EvINRConfig`` (e.g. ``balance=none``). With any of them the table is printed and the committed
results are left alone, unless ``--json`` / ``--md`` name the files.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from scipy.ndimage import gaussian_filter

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.common import write_json  # noqa: E402
from benchmarks.quality_zoo import parse_variant, score  # noqa: E402
from evinr_lite.method.config import EvINRConfig  # noqa: E402
from evinr_lite.method.solver import reconstruct  # noqa: E402
from evinr_lite.method.tonemap import anchor_mean, to_display  # noqa: E402
from evinr_lite.sim.zoo import SIGNAL, HELDOUT, default_scenes, effective_C, get, simulate  # noqa: E402

SIGMA = 8.0      # px: the scale of the kit's coarse part (EvINRConfig().offset_coarse_px)
PARTS = ("level", "tilt", "coarse", "fine", "changes")
PRIOR_TIMES = 64  # true frames over the span for prior_tilt_error (the offset grid's size)


def plane(image: np.ndarray) -> tuple[np.ndarray, float, float]:
    """(the least-squares plane a x + b y through ``image`` [H, W] with its mean removed, float64 [H, W];
    its rise across the sensor along x (columns, left to right) and along y (rows, top to bottom)).
    x and y are centred, so the plane has mean 0 and the two slopes are independent."""
    H, W = image.shape
    y, x = np.mgrid[0:H, 0:W].astype(np.float64)
    x -= x.mean()
    y -= y.mean()
    a = float((image * x).sum() / max((x * x).sum(), 1e-30))
    b = float((image * y).sum() / max((y * y).sum(), 1e-30))
    return a * x + b * y, a * max(W - 1, 0), b * max(H - 1, 0)


def decompose(L: np.ndarray, L_true: np.ndarray, sigma: float = SIGMA) -> dict:
    """The error of log intensities ``L`` [K, H, W] against ``L_true`` [K, H, W], split into
    :data:`PARTS` (arrays: level a float, tilt / coarse / fine [H, W], changes [K, H, W]) that add up
    to it exactly: e = level + tilt + coarse + fine + changes."""
    e = np.asarray(L, np.float64) - np.asarray(L_true, np.float64)
    level = float(e.mean())
    static = e.mean(axis=0) - level
    tilt, _, _ = plane(static)
    coarse = gaussian_filter(static - tilt, sigma, mode="nearest")
    return {"level": level, "tilt": tilt, "coarse": coarse, "fine": static - tilt - coarse,
            "changes": e - e.mean(axis=0)}


def prior_tilt_error(L_true: np.ndarray, C: float) -> dict:
    """The tilt error (log units across x, y) that a gradient prior makes on the true frames ``L_true``
    [T, H, W] (log, many times over the span), edge by edge, before any noise or threshold error.

    A static image solved from the changes alone gives each edge (a pair of neighbouring pixels) the
    gradient that makes the frames' gradients there zero in the prior's sense, i.e. the true static
    gradient minus a location of the edge's gradients over time. Summed over the sensor, that
    location's mean is a tilt error: ``median`` for the L1 solve (:mod:`evinr_lite.method.offset`),
    ``mean`` for a least-squares one, and ``hybrid`` the median where the edge's gradient stays within
    C / 2 of it in 3 of 4 frames and the mean elsewhere. The joint solve's integrability is ignored,
    so these are what the priors assume, not what the solver returns."""
    out = {"median": [], "mean": [], "hybrid": []}
    for axis in (2, 1):                                   # x (along a row), then y (down a column)
        g = np.diff(L_true, axis=axis)                    # [T, ...] each edge's gradient at each time
        med, mean = np.median(g, axis=0), g.mean(axis=0)
        hybrid = np.where((np.abs(g - med) < C / 2).mean(axis=0) >= 0.75, med, mean)
        across = L_true.shape[axis] - 1
        for name, loc in (("median", med), ("mean", mean), ("hybrid", hybrid)):
            out[name].append(float(-loc.mean() * across))
    return out


def tilt_error(row: dict) -> np.ndarray:
    """The kit's tilt error, kit minus truth, across x and y (log units) of one scene's row."""
    return np.subtract(row["kit_tilt_across"], row["true_tilt_across"])


def rms(x) -> float:
    return float(np.sqrt(np.mean(np.square(x))))


def redisplay(L: np.ndarray, cfg: EvINRConfig) -> np.ndarray:
    """Frames [K, H, W] in [0, 1] from log intensities ``L`` by ``cfg``'s display, the level set by the
    kit's one brightness anchor on these frames (:func:`~evinr_lite.method.tonemap.anchor_mean`)."""
    L = anchor_mean(L, cfg.gamma, cfg.display_mean, tonemap=cfg.tonemap)
    return to_display(L, cfg.tonemap, cfg.gamma).astype(np.float32)


def scene_row(name, scene, events, times, gt, C, log=print, overrides=None) -> dict:
    """One scene's parts, tilts and re-displayed scores (the module's docstring); ``overrides``: fields
    of EvINRConfig set on top of the default (``C`` and ``progress=False``)."""
    cfg = EvINRConfig(**{"C": C, "progress": False, **(overrides or {})})
    rec = reconstruct(events, times, cfg)
    L = rec.log_intensity.astype(np.float64)
    L_true = np.stack([scene.log_intensity(t) for t in times]).astype(np.float64)
    parts = decompose(L, L_true)
    kit_tilt, kx, ky = plane(L.mean(axis=0))
    true_tilt, tx, ty = plane(L_true.mean(axis=0))
    span = np.linspace(0.0, float(scene.duration), PRIOR_TIMES)
    prior = prior_tilt_error(np.stack([scene.log_intensity(t) for t in span]).astype(np.float64),
                             float(np.mean(C)))
    pick = ("ssim_clahe", "ssim_none", "mse_none")
    shown = {"kit": score(rec.frames, times, gt, times),
             "tilt_removed": score(redisplay(L - kit_tilt, cfg), times, gt, times),
             "truth_tilt": score(redisplay(L - kit_tilt + true_tilt, cfg), times, gt, times)}
    row = {"rms": {k: (abs(v) if k == "level" else rms(v)) for k, v in parts.items()},
           "kit_tilt_across": [kx, ky], "true_tilt_across": [tx, ty],
           "true_tilt_rms": rms(true_tilt), "prior_tilt_error_across": prior, "scores": {k: {m: v[m] for m in pick} for k, v in shown.items()}}
    r, s = row["rms"], row["scores"]
    log(f"{name:20s} " + "  ".join(f"{k} {r[k]:.3f}" for k in PARTS)
        + f"  | tilt x/y kit {kx:+.2f} {ky:+.2f} truth {tx:+.2f} {ty:+.2f}"
        + f" median prior's error {prior['median'][0]:+.2f} {prior['median'][1]:+.2f}"
        + "  | MSE " + " ".join(f"{k} {v['mse_none']:.4f}" for k, v in s.items()))
    return row


def markdown(rows: dict) -> str:
    lines = ["| scene | level | tilt | coarse | fine | changes | tilt across x / y: kit | truth | kit's error "
             "| median prior's error | mean prior's error | kit | tilt removed | truth's tilt |", "|" + "---|" * 14]
    for name, r in rows.items():
        cells = [f"{r['rms'][k]:.3f}" for k in PARTS]
        shown = [" / ".join(f"{r['scores'][k][m]:.{4 if m == 'mse_none' else 3}f}"
                            for m in ("ssim_clahe", "ssim_none", "mse_none"))
                 for k in ("kit", "tilt_removed", "truth_tilt")]
        lines.append(f"| {name} | " + " | ".join(cells)
                     + f" | {r['kit_tilt_across'][0]:+.2f} / {r['kit_tilt_across'][1]:+.2f}"
                     + f" | {r['true_tilt_across'][0]:+.2f} / {r['true_tilt_across'][1]:+.2f}"
                     + " | {:+.2f} / {:+.2f}".format(*tilt_error(r))
                     + "".join(f" | {r['prior_tilt_error_across'][k][0]:+.2f} / {r['prior_tilt_error_across'][k][1]:+.2f}"
                               for k in ("median", "mean"))
                     + " | " + " | ".join(shown) + " |")
    if rows:
        means = {k: np.mean([r["scores"][k]["ssim_clahe"] for r in rows.values()])
                 for k in ("kit", "tilt_removed", "truth_tilt")}
        lines.append(f"| **mean CLAHE-SSIM** | | | | | | | | | | | {means['kit']:.3f} | {means['tilt_removed']:.3f} | "
                     f"{means['truth_tilt']:.3f} |")
    lines += ["", "Level ... changes: the kit's log-intensity error split into its parts (root mean square, log "
              f"units; level: its absolute value; coarse: below a Gaussian sigma of {SIGMA:g} px after the tilt). "
              "Tilt across: the rise of the static image's least-squares plane from the first to the last column "
              "(x) and row (y), log units, for the kit and for the truth, and the kit's error (kit minus truth). "
              "Median / mean prior's error: the tilt error that the L1 solve's prior (each edge's median gradient "
              "over time is zero) and a least-squares prior (its mean is zero) make on the true frames themselves, "
              "edge by edge, before any noise or threshold error (`prior_tilt_error`). The last three columns: CLAHE-SSIM / "
              "SSIM / MSE of the kit as it is, re-displayed with its tilt removed, and with its tilt replaced by "
              "the truth's (an oracle). Written by `python benchmarks/static_error.py`."]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--heldout", action="store_true", help="the held-out scenes instead (short ones)")
    p.add_argument("--scenes", default=None, help="comma-separated scene names (default: every short scene)")
    p.add_argument("--events", choices=("all", "signal"), default="all",
                   help="signal: only the events of brightness changes (no background activity, no hot pixels)")
    p.add_argument("--true-thresholds", action="store_true",
                   help="give the method the simulated C+ / C- (where they differ) instead of the nominal C")
    p.add_argument("--set", default="", metavar="FIELD=VALUE,...", help="EvINRConfig fields to change, e.g. balance=none")
    p.add_argument("--json", default=None, help="default benchmarks/static_error_results[_heldout].json")
    p.add_argument("--md", default=None, help="default benchmarks/static_error_results[_heldout].md")
    a = p.parse_args(argv)
    overrides = config_overrides(a.set, p.error)
    scenes = ([get(n) for n in a.scenes.split(",")] if a.scenes else
              [z for z in (HELDOUT if a.heldout else default_scenes()) if not z.long])
    rows = {}
    for z in scenes:
        scene, events, times, gt, labels, _ = simulate(z, labels=True)
        if a.events == "signal":
            events = events.take(np.flatnonzero(labels == SIGNAL))
        C = (z.C_pos, z.C_neg) if a.true_thresholds and z.C_pos is not None else effective_C(z)
        rows[z.name] = scene_row(z.name, scene, events, times, gt, C, overrides=overrides)
    agreement = prior_agreement(rows, {z.name for z in scenes if z.C_pos is not None})
    summary = "".join(
        f"\nC+ {'=' if group == 'equal' else '!='} C- ({a_['scenes']} scenes): the kit's tilt error against the median "
        f"prior's on the true frames: correlation {a_['correlation']:.2f}, rms difference {a_['rms_difference']:.2f} "
        f"(the error's own rms {a_['rms_kit_error']:.2f} log units; x and y tilts of every scene).\n"
        for group, a_ in agreement.items())
    setup = {"heldout": a.heldout, "sigma_px": SIGMA, "events": a.events, "true_thresholds": a.true_thresholds,
             "set": overrides}
    changed = a.events != "all" or a.true_thresholds or overrides
    suffix = "_heldout" if a.heldout else ""
    if not changed:
        a.json = a.json or f"benchmarks/static_error_results{suffix}.json"
        a.md = a.md or f"benchmarks/static_error_results{suffix}.md"
    if a.json:
        write_json(a.json, {**setup, "prior_agreement": agreement, "scenes": rows})
        print(f"json: {a.json}")
    if a.md:
        Path(a.md).write_text(markdown(rows) + summary)
        print(f"markdown: {a.md}")
    print(markdown(rows) + summary if changed and not a.md else summary)
    return 0


def prior_agreement(rows: dict, unequal: set) -> dict:
    """How well the median prior's error on the true frames explains the kit's tilt error: per group of
    scenes ("equal": C+ = C-, "unequal"), the correlation of the two over the scenes' x and y tilts, the
    root mean square of their difference and of the kit's error (log units across)."""
    out = {}
    for group in ("equal", "unequal"):
        names = [n for n in rows if (n in unequal) == (group == "unequal")]
        if len(names) < 2:
            continue
        e = np.concatenate([tilt_error(rows[n]) for n in names])
        m = np.concatenate([rows[n]["prior_tilt_error_across"]["median"] for n in names])
        out[group] = {"scenes": len(names), "correlation": float(np.corrcoef(e, m)[0, 1]),
                      "rms_difference": rms(e - m), "rms_kit_error": rms(e)}
    return out


def config_overrides(text: str, error) -> dict:
    """'FIELD=VALUE,...' -> {field: value} for EvINRConfig (values as Python literals); ``error(message)``
    is called for a field EvINRConfig does not have or a value it refuses."""
    _, fields = parse_variant("set=" + text)
    try:
        EvINRConfig(**fields)
    except TypeError as exc:
        error(f"--set {text!r}: {exc} (the fields are EvINRConfig's, e.g. balance=none, lam=0.1)")
    except ValueError as exc:
        error(f"--set {text!r}: {exc}")
    return fields


if __name__ == "__main__":
    raise SystemExit(main())
