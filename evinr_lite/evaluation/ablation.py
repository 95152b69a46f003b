"""Ablations of EvINR (paper Sec. 4.3, Tables 2-3): run named variants, score them, tabulate, plot.

    variants = table2_variants(C=0.2, n_iters=100)          # Base, Base + Reg., Base + C2F, Full
    rows = run_variants(events, gt_frames, gt_times, variants)
    print(ablation_table(rows))                              # markdown, with the protocol under it
    viz.plot_ablation(rows)                                  # from evinr_lite import viz

A *variant* is an :class:`~evinr_lite.method.solver.EvINRConfig` (trained with :func:`reconstruct`) or a
plain function ``method(events, times) -> frames [Q, H, W] in [0, 1]`` (a baseline such as
:func:`integration_baseline`). A *row* is a dict (one per variant) holding:

    name                      the variant's name
    mse_<eq>, ssim_<eq>       mean MSE / SSIM over the scored frames after equalisation <eq> of both
                              images (default "none" and "clahe"; evaluation.score_sequence)
    train_time_s              wall-clock seconds of training (EvINR: the training loop; a baseline:
                              the whole call); the fastest of ``repeats`` runs
    inference_fps             frames per second of querying the trained model (measure_inference_fps)
    fps                       end-to-end: scored frames / (train time + their inference time); the
                              paper's Tables 2-3 report this (their Time x FPS is the same in every row)
    n_frames                  frames scored
    n_networks, n_params      networks in the ensemble and their parameters (0 for a baseline)
    final_bins, bins_processed  event bins per network at the last iteration, and summed over all
                              iterations and networks (the work, free of timing noise)
    config                    the EvINRConfig (None for a baseline)
    frames                    the predicted frames [Q, H, W] (float32)
    protocol                  one paragraph saying how all of the above was measured

The variant builders start from :meth:`EvINRConfig.v0_1` (the paper's training recipe as the kit ran
it before the scene zoo), because they reproduce the paper's Tables 2-3, which are about training.
The paper's numbers are in :data:`PAPER_TABLE2` and :data:`PAPER_TABLE3`;
:func:`compare_with_paper` sets our relative changes next to theirs.
"""
from __future__ import annotations

import hashlib
import time
from collections.abc import Mapping
from dataclasses import asdict, replace

import numpy as np

from ..core.checks import ArgumentTypeError, check_image_values, real_number, require, value_list, whole_number
from ..core.events import EventDataError, Events
from ..core.guard import dense_array
from ..core.runtime import default_device
from ..method.binning import as_thresholds
from ..method.integration import integrate_events
from ..method.solver import EvINRConfig, reconstruct
from ..method.tonemap import anchor_mean, reinhard_unchecked
from .metrics import SCORE_PROTOCOLS
from .scoring import measure_inference_fps, score_sequence

__all__ = ["PAPER_TABLE2", "PAPER_TABLE3", "COLUMN_LABELS",
           "table2_variants", "tau_for_networks", "ensemble_variants", "lambda_variants",
           "temporal_loss_variants", "recipe_variants", "integration_baseline", "run_variants",
           "rows_by_name", "ablation_table", "pareto_front",
           "relative_change", "compare_with_paper", "comparison_table", "paper_frame_counts"]

# Paper, Table 2 (IJRR, RTX 3090): MSE, SSIM, LPIPS (after CLAHE), training time (s), FPS.
PAPER_TABLE2 = {
    "Base":        {"mse": 0.063, "ssim": 0.542, "lpips": 0.357, "time_s": 17.29, "fps": 13.77},
    "Base + Reg.": {"mse": 0.044, "ssim": 0.612, "lpips": 0.275, "time_s": 17.44, "fps": 13.64},
    "Base + C2F":  {"mse": 0.061, "ssim": 0.566, "lpips": 0.343, "time_s": 7.94, "fps": 31.33},
    "Full":        {"mse": 0.047, "ssim": 0.658, "lpips": 0.251, "time_s": 8.08, "fps": 29.45},
}

# Paper, Table 3 (IJRR calibration, 50 s): N networks of tau seconds each.
PAPER_TABLE3 = {
    "N = 1":  {"N": 1, "tau_s": 50, "mse": 0.084, "ssim": 0.460, "lpips": 0.380, "time_s": 15.71, "fps": 75.66},
    "N = 5":  {"N": 5, "tau_s": 10, "mse": 0.0688, "ssim": 0.600, "lpips": 0.253, "time_s": 16.91, "fps": 70.31},
    "N = 10": {"N": 10, "tau_s": 5, "mse": 0.0625, "ssim": 0.612, "lpips": 0.244, "time_s": 18.32, "fps": 64.90},
    "N = 50": {"N": 50, "tau_s": 1, "mse": 0.0875, "ssim": 0.488, "lpips": 0.343, "time_s": 29.43, "fps": 40.39},
}

HIGHER_IS_BETTER = {"mse": False, "ssim": True, "lpips": False, "time_s": False, "train_time_s": False,
                    "fps": True, "inference_fps": True}


# ---- the variants -----------------------------------------------------------------------------

def table2_variants(**common) -> dict[str, EvINRConfig]:
    """The paper's Table 2: Base (no regularizer, no coarse-to-fine), Base + Reg. (Tikhonov, lambda
    0.05), Base + C2F, Full. ``common``: EvINRConfig fields shared by all four (C, n_iters, ...)."""
    return {"Base": EvINRConfig.base(**common),
            "Base + Reg.": EvINRConfig.v0_1(**{**common, "coarse_to_fine": False}),
            "Base + C2F": EvINRConfig.v0_1(**{**common, "regularizer": "none"}),
            "Full": EvINRConfig.v0_1(**common)}


def tau_for_networks(n_networks: int, duration: float, overlap: float) -> float | None:
    """The window length tau (s) for which :func:`~evinr_lite.method.solver.split_windows` cuts ``duration``
    seconds into exactly ``n_networks`` windows sharing ``overlap`` s; None for one network."""
    n_networks = whole_number(n_networks, "n_networks", lo=1)   # 2.5 gave a tau for 2.5 windows, "2" a TypeError
    duration = real_number(duration, "duration", lo=0, lo_open=True, hint="the span in seconds")
    overlap = real_number(overlap, "overlap", lo=0, hint="seconds shared by neighbouring windows")
    if n_networks == 1:
        return None
    tau = (duration - overlap) / n_networks + overlap
    if not tau >= 2 * overlap:
        raise ValueError(f"{n_networks} windows over {duration} s would be {tau:.3g} s long, shorter than twice the "
                         f"overlap ({overlap} s); use fewer networks or a smaller overlap")
    return tau * (1 + 1e-9)  # ceil((T - o) / (tau - o)) must not round up to N + 1


def ensemble_variants(duration: float, n_networks=(1, 2, 4), *, overlap: float = 0.1, **common) -> dict[str, EvINRConfig]:
    """Table 3: the Full recipe with N networks over ``duration`` seconds, one variant per N."""
    return {f"N = {n}": EvINRConfig.v0_1(**{**common, "tau": tau_for_networks(n, duration, overlap), "overlap": overlap})
            for n in n_networks}


def _check_common(common: dict, own, name: str) -> None:
    """Refuse a keyword in ``common`` that the variants set themselves: it was overwritten in some rows (or in
    all) without a word, so a table labelled one way was run another."""
    clash = [k for k in own if k in common]
    if clash:
        raise EventDataError(f"{name} sets {clash[0]}= in its rows itself; drop {clash[0]}= from the shared settings "
                             f"(it would be overwritten, and the rows' labels would not say what ran)")


def lambda_variants(lams, regularizers=("tikhonov",), **common) -> dict[str, EvINRConfig]:
    """The Full recipe with each regularizer weight in ``lams``, for each regularizer ("tikhonov", "tv")."""
    _check_common(common, ("regularizer", "lam"), "lambda_variants")
    lams = [real_number(lam, f"lams[{k}]", lo=0, hint="a regularizer weight (e.g. 0.05)")   # True was lambda = 1
            for k, lam in enumerate(value_list(lams, "lams", "weights, e.g. [0.01, 0.05, 0.2]"))]
    regularizers = value_list(regularizers, "regularizers", "names, e.g. ('tikhonov', 'tv')", text=True)
    return {f"{reg}, lambda = {lam:g}": EvINRConfig.v0_1(**{**common, "regularizer": reg, "lam": float(lam)})
            for reg in regularizers for lam in lams}


def temporal_loss_variants(**common) -> dict[str, EvINRConfig]:
    """Derivative (Eq. 5-6, dF/dt at bin mid-points) versus boundary difference (F(b_{i+1}) - F(b_i)),
    each on Base and on Full."""
    _check_common(common, ("temporal_loss",), "temporal_loss_variants")
    out = {}
    for recipe, make in (("Base", EvINRConfig.base), ("Full", EvINRConfig.v0_1)):
        for loss in ("derivative", "difference"):
            out[f"{recipe}, {loss}"] = make(**{**common, "temporal_loss": loss})
    return out


def recipe_variants(n_events: int, span_s: float, **common) -> dict[str, EvINRConfig]:
    """From ``EvINRConfig.v0_1()`` (the paper's recipe with two changes) to the public reference code's, one
    change at a time (each row adds one).

    1. "Full (v0_1)": EvINRConfig.v0_1(): Tikhonov, fixed 1/32 s bins, derivative loss, first layer omega 10.
    2. "+ TV": anisotropic TV instead of Tikhonov (the code's main regularizer term).
    3. "+ equal-count bins": bins of equal event counts, as many as the fixed bins (the binning rule alone).
    4. "+ boundary difference": F(b_{i+1}) - F(b_i) against each bin's events.
    5. "+ omega_0 = 10": omega 10 in every layer, head learning rate x10 (the code's network).
    6. "+ its bin count (= reference code)": the code's number of bins: 100 over the whole window at the
       end, 50 before one bisection at n_iters / 2 (its ``train_resolution``; a number of bins, not of
       events per bin).

    The last row equals :meth:`EvINRConfig.reference_code` with those bins. Not expressible here, and left
    out: the code's AdamW at a fixed lr 3e-4 for 1000 steps, the L1 on temporal increments and the
    variance-of-mean term of its regularizer, its sigmoid tone mapping.

    Args:
        n_events: events in the reconstructed span. span_s: its length in seconds (sets the fixed bins).
        common: EvINRConfig fields shared by every row (C, n_iters, sizes, ...); tau must be None or
            at least span_s (one network), since equal-count bins are counted per network.
    """
    n_events = whole_number(n_events, "n_events", lo=1)   # -5 or 1.5 were taken, NaN "cannot convert float NaN"
    span_s = real_number(span_s, "span_s", lo=0, lo_open=True, hint="the span's length in seconds")
    # the fields a step's label names (c2f_iters and events_per_bin of the rows before the last are the caller's)
    _check_common(common, ("regularizer", "binning", "temporal_loss", "omega_0", "head_lr_scale"), "recipe_variants")
    base = EvINRConfig.v0_1(**common)
    if base.tau is not None and base.tau < span_s:
        raise EventDataError(f"recipe_variants counts bins over one window: use tau=None or tau >= span_s ({span_s} s)")
    n_fixed = max(1, int(round(span_s / base.bin_duration)))
    code_bins = {"events_per_bin": max(1, int(round(n_events / 100))), "c2f_iters": (base.n_iters // 2,)}
    steps = [("Full (v0_1)", {}),
             ("+ TV instead of Tikhonov", {"regularizer": "tv"}),
             ("+ equal-count bins", {"binning": "equal_count", "events_per_bin": max(1, int(round(n_events / n_fixed)))}),
             ("+ boundary difference", {"temporal_loss": "difference"}),
             ("+ omega_0 = 10", {"omega_0": 10.0, "head_lr_scale": 10.0}),
             ("+ its bin count (= reference code)", code_bins)]
    out, changes = {}, {}
    for name, change in steps:
        changes = {**changes, **change}
        out[name] = EvINRConfig.v0_1(**{**common, **changes})
    reference = EvINRConfig.reference_code(**{**common, **code_bins})
    if asdict(reference) != asdict(out[steps[-1][0]]):  # the preset changed: say so rather than mislabel
        raise RuntimeError("EvINRConfig.reference_code() no longer matches the last step of recipe_variants; update both")
    return out


def integration_baseline(C: float, gamma: float = 0.6):
    """Direct event integration from L0 = 0, anchored and tone-mapped as the solver's output is:
    a variant ``method(events, times) -> frames [Q, H, W]`` in [0, 1]. ``C``: one threshold or a pair (c_pos, c_neg)."""
    c_pos, c_neg = as_thresholds(C)   # checked when made: text was a format error, gamma 0 failed only when called
    gamma = real_number(gamma, "gamma", lo=0, lo_open=True, hint="Reinhard's exponent (the paper's 0.6)")

    def method(events: Events, times: np.ndarray) -> np.ndarray:
        return reinhard_unchecked(anchor_mean(integrate_events(events, times, C=C), gamma), gamma).astype(np.float32)
    method.__name__ = f"integration (C = {c_pos:g})" if c_pos == c_neg else f"integration (C = ({c_pos:g}, {c_neg:g}))"
    return method


# ---- running them -------------------------------------------------------------------------------

def _config_key(cfg: EvINRConfig) -> tuple:
    d = asdict(cfg)
    d.pop("progress", None)
    return tuple(sorted((k, repr(v)) for k, v in d.items()))


def _fingerprint(events: Events, gt: np.ndarray, times: np.ndarray, *extra) -> str:
    """A digest of everything besides the config that a cached row depends on."""
    h = hashlib.sha1()
    for a in (events.t, events.x, events.y, events.p, gt, times):
        h.update(np.ascontiguousarray(a).tobytes())
    h.update(repr((events.sensor_size, *extra)).encode())
    return h.hexdigest()


def _protocol(n_frames: int, equalizations, repeats: int, n_inference: int, device: str) -> str:
    eqs = " and ".join(f"'{e}'" for e in equalizations)
    return (f"Protocol: {n_frames} frames scored at the ground-truth timestamps; each prediction keeps its own "
            f"brightness anchor (mean tone-mapped level 0.5). MSE and SSIM (gaussian sigma 1.5, data_range 1) are "
            f"means over frames after equalisation {eqs} of both images ('clahe' is the paper's protocol). "
            f"Train (s): wall-clock training time on {device}, fastest of {repeats} run(s), on a machine that may be "
            f"shared. Infer FPS: frames per second of the trained model answering {n_inference} batched queries "
            f"(evaluation.measure_inference_fps). "
            f"FPS: scored frames / (train time + their inference time), the paper's end-to-end definition "
            f"(in its Tables 2-3, Time x FPS is the same in every row).")


def run_variants(events: Events, gt_frames, gt_times, variants: dict, *, t_start: float | None = None,
                 t_end: float | None = None, equalizations=SCORE_PROTOCOLS, repeats: int = 1,
                 n_inference: int = 64, cache: dict | None = None, log=None) -> list[dict]:
    """Reconstruct at ``gt_times`` with every variant and score against ``gt_frames``.

    Args:
        events: the events.
        gt_frames: [Q, H, W] ground truth in [0, 1] (uint8 is divided by 255).
        gt_times: [Q] their timestamps (seconds, the events' clock).
        variants: ``{name: EvINRConfig or method(events, times) -> frames [Q, H, W]}``.
        t_start, t_end: span to reconstruct (seconds; see :func:`reconstruct`).
        equalizations: the scoring protocols (default metrics.SCORE_PROTOCOLS; any of metrics.EQUALIZATIONS).
        repeats: runs per variant; the fastest training time is kept (results are identical: seeded).
        n_inference: query times for the inference-FPS measurement.
        cache: a dict shared between calls: a config already run on the same events, ground truth,
            times and span is not trained again (its row is copied, with ``reused_from`` naming the
            first run; its time is that run's).
        log: ``log(str)`` per finished row (e.g. print); None for silence.

    Returns:
        One row (dict, see the module docstring) per variant, in order.
    """
    events = require(events, Events, "events")
    if not isinstance(variants, dict):   # a list was "'list' object has no attribute 'items'"
        raise ArgumentTypeError(f"variants must be a dict {{name: EvINRConfig or method(events, times)}}, got "
                                f"{type(variants).__name__}" + ("; name each: {name: variant for ...}"
                                                               if isinstance(variants, (list, tuple)) else ""))
    repeats = whole_number(repeats, "repeats", lo=1)
    n_inference = whole_number(n_inference, "n_inference", lo=1)   # 0 was a ZeroDivisionError
    if isinstance(equalizations, str):   # one protocol by name: "clahe" was scored letter by letter
        equalizations = (equalizations,)
    gt = np.asarray(gt_frames)
    if gt.dtype.kind in "iu" and gt.dtype != np.uint8:   # uint16 was cast to float and called 0..255
        check_image_values(gt, "gt_frames")
    gt = gt.astype(np.float32) / 255.0 if gt.dtype == np.uint8 else gt.astype(np.float32)
    times = np.asarray(gt_times, dtype=np.float64)
    if gt.ndim != 3 or times.shape != (gt.shape[0],):
        raise EventDataError(f"gt_frames must be [Q, H, W] with Q = len(gt_times); got {gt.shape} and {times.shape}")
    if gt.shape[1:] != tuple(events.sensor_size):
        raise EventDataError(f"ground-truth frames are {gt.shape[1:]} but the sensor is {events.sensor_size}; "
                             "crop or resize them to the sensor size")
    if not variants:
        raise ValueError("variants is empty: pass {name: EvINRConfig or method(events, times)}")
    device = str(default_device(None))
    protocol = _protocol(len(times), equalizations, repeats, n_inference, device)
    rows = []
    data_key = _fingerprint(events, gt, times, t_start, t_end, tuple(equalizations)) if cache is not None else None
    for name, variant in variants.items():
        key = None
        if isinstance(variant, EvINRConfig):
            key = (data_key, _config_key(variant))
        if cache is not None and key in cache:
            row = {**cache[key], "name": name, "reused_from": cache[key]["name"]}
        else:
            row = _run_one(name, variant, events, times, t_start, t_end, repeats, n_inference)
            for eq in equalizations:   # the one scoring path (evaluation.scoring), LPIPS left out
                s = score_sequence(row["frames"], times, gt, times, eq, lpips_model=False)
                row[f"mse_{eq}"], row[f"ssim_{eq}"] = s["mse"], s["ssim"]
            row["protocol"] = protocol
            if cache is not None and key is not None:
                cache[key] = row
        rows.append(row)
        if log is not None:
            scores = "  ".join(f"SSIM[{eq}] {row[f'ssim_{eq}']:.3f}" for eq in equalizations)
            log(f"{name:<36s} {scores}  train {row['train_time_s']:6.2f} s")
    return rows


def _run_one(name, variant, events, times, t_start, t_end, repeats, n_inference) -> dict:
    n = len(times)
    if isinstance(variant, EvINRConfig):
        cfg = replace(variant, progress=False)
        best, rec = np.inf, None
        for _ in range(repeats):
            r = reconstruct(events, times, cfg, t_start=t_start, t_end=t_end)
            if r.history["train_time_s"] < best:
                best, rec = r.history["train_time_s"], r
        infer_fps = measure_inference_fps(rec.model, n_frames=n_inference, repeats=2)["fps"]
        return {"name": name, "train_time_s": float(best), "inference_fps": float(infer_fps),
                "fps": n / (best + n / infer_fps), "n_frames": n,
                "n_networks": len(rec.windows), "n_params": rec.model.num_parameters(),
                "final_bins": rec.history["final_bins"], "bins_processed": len(rec.windows) * sum(rec.history["n_bins"]),
                "config": variant, "frames": rec.frames}
    if not callable(variant):
        raise TypeError(f"variant {name!r} must be an EvINRConfig or a function (events, times) -> frames, "
                        f"got {type(variant).__name__}")
    best, frames = np.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = variant(events, times)
        if time.perf_counter() - t0 < best:
            best, frames = time.perf_counter() - t0, out
    frames = np.asarray(frames, dtype=np.float32)
    if frames.shape != (n, *events.sensor_size):
        raise EventDataError(f"variant {name!r} returned frames of shape {frames.shape}, expected {(n, *events.sensor_size)}")
    best = max(best, 1e-9)
    return {"name": name, "train_time_s": float(best), "inference_fps": n / best, "fps": n / best, "n_frames": n,
            "n_networks": 0, "n_params": 0, "final_bins": 0, "bins_processed": 0, "config": None, "frames": frames}


def rows_by_name(rows: list[dict]) -> dict[str, dict]:
    """``{row["name"]: row}``."""
    out = {}
    for k, r in enumerate(value_list(rows, "rows", "rows (dicts with a 'name'), as run_variants returns them")):
        if not isinstance(r, Mapping) or "name" not in r:   # a Mapping row (a mappingproxy) was taken before: taken
            raise EventDataError(f"rows[{k}] must be a dict with a 'name' (a row of run_variants), got {r!r:.60}")
        if r["name"] in out:   # the first was dropped without a word
            raise EventDataError(f"rows hold the name {r['name']!r} twice (rows {list(out).index(r['name'])} and {k}); "
                                 "give each variant its own name")
        out[r["name"]] = r
    return out


# ---- tables ---------------------------------------------------------------------------------------

COLUMN_LABELS = {"mse_none": ("MSE", "{:.4f}"), "ssim_none": ("SSIM", "{:.3f}"),
            "mse_clahe": ("CLAHE MSE", "{:.4f}"), "ssim_clahe": ("CLAHE SSIM", "{:.3f}"),
            "mse_global": ("global-eq. MSE", "{:.4f}"), "ssim_global": ("global-eq. SSIM", "{:.3f}"),
            "train_time_s": ("Train (s)", "{:.2f}"), "inference_fps": ("Infer FPS", "{:.0f}"),
            "fps": ("FPS", "{:.2f}"), "n_networks": ("N", "{:d}"), "n_params": ("params", "{:,d}"),
            "final_bins": ("bins", "{:d}"), "bins_processed": ("bins processed", "{:,d}"),
            "lam": ("lambda", "{:g}"), "tau_s": ("tau (s)", "{:.2f}")}

DEFAULT_COLUMNS = ("mse_none", "ssim_none", "mse_clahe", "ssim_clahe", "train_time_s", "inference_fps", "fps")


def ablation_table(rows: list[dict], columns=DEFAULT_COLUMNS, *, title: str | None = None,
                   protocol: str | None = None, best: bool = True) -> str:
    """A markdown table of ``rows`` (one line per variant), with the protocol paragraph under it.

    Args:
        rows: from :func:`run_variants` (rows missing a column show "-").
        columns: row keys to show, in order (see ``COLUMN_LABELS`` for their headers; others show raw).
        title: a line above the table.
        protocol: the text under the table (default: the rows' own ``protocol``).
        best: mark the best value of each quality column in bold.

    Returns:
        The markdown text (print it, or display it with IPython.display.Markdown).
    """
    if rows is None:
        raise ValueError("no rows to tabulate: pass run_variants' rows (a list of dicts)")
    if isinstance(rows, dict) or not all(isinstance(r, dict) for r in rows):   # one row was Python's TypeError
        raise EventDataError(f"rows must be a list of dicts (run_variants' rows), got {type(rows).__name__}"
                             + ("; one row: pass [row]" if isinstance(rows, dict) else ""))
    if isinstance(columns, str):   # one name made a column per letter
        raise EventDataError(f"columns must be a list of row keys, got the text {columns!r}; one column: "
                             f"columns=({columns!r},)")
    if not rows:
        raise ValueError("no rows to tabulate")
    headers = ["variant"] + [COLUMN_LABELS.get(c, (c, "{}"))[0] for c in columns]
    best_of = {}
    if best and len(rows) > 1:
        for c in columns:
            metric = c.split("_")[0]
            values = [r[c] for r in rows if isinstance(r.get(c), (int, float))]
            if metric in ("mse", "ssim") and values:
                best_of[c] = min(values) if metric == "mse" else max(values)
    lines = [] if title is None else [f"**{title}**", ""]
    lines += ["| " + " | ".join(headers) + " |", "|" + "|".join(["---"] + ["---:"] * len(columns)) + "|"]
    for r in rows:
        cells = [str(r["name"]) + (f" (= {r['reused_from']})" if r.get("reused_from") else "")]
        for c in columns:
            v = r.get(c)
            if v is None or (isinstance(v, float) and not np.isfinite(v)):
                cells.append("-")
                continue
            fmt = COLUMN_LABELS.get(c, (c, "{}"))[1]
            text = fmt.format(int(v) if fmt.endswith("d}") else v)
            cells.append(f"**{text}**" if c in best_of and v == best_of[c] else text)
        lines.append("| " + " | ".join(cells) + " |")
    text = protocol if protocol is not None else rows[0].get("protocol")
    if text:
        lines += ["", text]
    return "\n".join(lines)


# ---- next to the paper ------------------------------------------------------------------------------

def relative_change(value: float, baseline: float, higher_is_better: bool) -> float:
    """Improvement of ``value`` over ``baseline`` in percent of the baseline; positive = better."""
    value, baseline = real_number(value, "value"), real_number(baseline, "baseline")   # NaN gave NaN
    if baseline == 0:   # was a ZeroDivisionError
        raise EventDataError(f"no relative change from a baseline of 0 (value {value:g}): the baseline is 0; compare "
                             "the values themselves")
    change = 100.0 * (value - baseline) / abs(baseline)
    return change if higher_is_better else -change


def pareto_front(cost, quality) -> np.ndarray:
    """bool [K]: the variants no other variant dominates. Variant j dominates i when it costs no more
    (cost[j] <= cost[i]) and is no worse (quality[j] >= quality[i]), and is strictly better in at
    least one of the two. Ties in both are kept on the front.

    Args:
        cost: [K] lower is better (e.g. training seconds). quality: [K] higher is better (e.g. SSIM).
    """
    c, q = _scores(cost, "cost"), _scores(quality, "quality")
    if c.size != q.size:   # was numpy's broadcast error
        raise EventDataError(f"{c.size} costs but {q.size} qualities; pass one of each per variant")
    c, q = c[:, None], q[:, None]
    # dominated[i, j]: j dominates i
    dominated = (c.T <= c) & (q.T >= q) & ((c.T < c) | (q.T > q))
    return ~dominated.any(axis=1)


def _scores(value, name: str) -> np.ndarray:
    """One finite number per variant, float64 [K]: a NaN variant was on the front (nothing dominates NaN), a 2-D
    array was taken as a matrix of variants."""
    arr = None if isinstance(value, (str, bytes)) else dense_array(value, name, error=EventDataError)
    if arr is None or arr.dtype.kind not in "iuf" or arr.ndim != 1:
        raise EventDataError(f"{name} must be a 1-D list of numbers, one per variant, got "
                             + (f"shape {arr.shape} dtype {arr.dtype}" if arr is not None else repr(value)[:60]))
    arr = arr.astype(np.float64)
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise EventDataError(f"{name}[{bad[0]}] is {arr[bad[0]]}; every variant needs a finite {name} (drop that one)")
    return arr


def paper_frame_counts(table: dict) -> dict[str, float]:
    """Time x FPS of each row of a paper table: the frames the FPS column counts (constant per table
    when FPS = frames / training time)."""
    return {name: row["time_s"] * row["fps"] for name, row in _checked_paper_table(table).items()}


def _checked_paper_table(table) -> dict:
    """paper_frame_counts' table with its numbers checked as floats: text was repeated ("1" * 2 = "11"), True
    taken as 1 s, a negative time counted negative frames."""
    if not isinstance(table, Mapping):   # a Mapping (a mappingproxy) was taken before: taken
        raise EventDataError(f"table= must be a dict {{name: {{'time_s': ..., 'fps': ...}}}} (e.g. PAPER_TABLE2), got "
                             f"{type(table).__name__}")
    out = {}
    for name, row in table.items():
        if not isinstance(row, Mapping) or not {"time_s", "fps"} <= set(row):
            raise EventDataError(f"table[{name!r}] must be a dict with 'time_s' and 'fps' (a paper table's row), got "
                                 f"{row!r:.60}")
        out[name] = {key: real_number(row[key], f"table[{name!r}][{key!r}]", lo=0) for key in ("time_s", "fps")}
    return out


def compare_with_paper(ours: dict[str, dict], paper: dict[str, dict], pairs, metrics=(("mse", "mse_clahe"),
                       ("ssim", "ssim_clahe"), ("time_s", "train_time_s")), *, change=None,
                       small_pct: float = 2.0) -> list[dict]:
    """Relative changes of variant against baseline, ours next to the paper's.

    Args:
        ours: ``{name: row}`` (see :func:`rows_by_name`).
        paper: ``{name: {metric: value}}`` (e.g. :data:`PAPER_TABLE2`), with the same names.
        pairs: ``[(variant, baseline), ...]`` names present in both.
        metrics: ``[(paper_key, our_key), ...]``: the paper's SSIM/MSE are after CLAHE.
        change: ``change(value, baseline, higher_is_better) -> percent`` (default :func:`relative_change`).
        small_pct: changes smaller than this (percent) count as no change.

    Returns:
        One dict per (pair, metric): variant, baseline, metric, paper_pct, ours_pct (improvement in
        percent, positive = better) and agree: "yes" (same direction), "no" (opposite, or one side
        changed and the other did not) or "both small" (both within ``small_pct``).
    """
    change = relative_change if change is None else change
    if not callable(change):
        raise ArgumentTypeError(f"change= must be a function change(value, baseline, higher_is_better) -> percent, or "
                                f"None for relative_change, got {type(change).__name__}")
    small_pct = real_number(small_pct, "small_pct", lo=0, hint="percent: smaller changes count as no change")
    for name, table in (("ours", ours), ("paper", paper)):
        if not isinstance(table, Mapping):   # a mappingproxy or other Mapping was taken before: taken
            raise EventDataError(f"{name}= must be a dict {{name: row}} (rows_by_name(rows) for ours, e.g. PAPER_TABLE2 "
                                 f"for the paper), got {type(table).__name__}")
    pairs = value_list(pairs, "pairs", "(variant, baseline) name pairs, e.g. [('Full', 'Base')]")
    metrics = value_list(metrics, "metrics", "(paper_key, our_key) pairs, e.g. [('ssim', 'ssim_clahe')]")
    for k, pair in enumerate(pairs):
        if isinstance(pair, (str, bytes)) or not hasattr(pair, "__len__") or len(pair) != 2:
            raise EventDataError(f"pairs[{k}] must be (variant, baseline), two names, got {pair!r:.60}")
        for name in pair:
            for side, table in (("ours", ours), ("paper", paper)):
                if not _holds(table, name):
                    raise EventDataError(f"pairs[{k}] names {name!r}, which {side} has no row of (it has "
                                         f"{sorted(map(str, table))[:6]}); pass names present in both")
    for k, metric in enumerate(metrics):
        if isinstance(metric, (str, bytes)) or not hasattr(metric, "__len__") or len(metric) != 2:
            raise EventDataError(f"metrics[{k}] must be (paper_key, our_key), got {metric!r:.60}")
        if metric[0] not in HIGHER_IS_BETTER:
            raise EventDataError(f"metrics[{k}]: {metric[0]!r} is no metric with a known direction; use one of "
                                 f"{sorted(HIGHER_IS_BETTER)}")
        for variant, baseline in pairs:
            for side, table, key in (("ours", ours, metric[1]), ("paper", paper, metric[0])):
                for name in (variant, baseline):
                    if not isinstance(table[name], Mapping):   # was "has no 'mse_clahe'" for a row that held it
                        raise EventDataError(f"{side}[{name!r}] must be a dict of metrics ({{metric: value}}), got "
                                             f"{type(table[name]).__name__}")
                    if not _holds(table[name], key):
                        raise EventDataError(f"{side}[{name!r}] has no {key!r} (metrics[{k}]); pass rows that hold it, "
                                             "or leave that metric out")
    out = []
    for variant, baseline in pairs:
        for p_key, o_key in metrics:
            better = HIGHER_IS_BETTER[p_key]
            p = float(change(paper[variant][p_key], paper[baseline][p_key], better))
            o = float(change(ours[variant][o_key], ours[baseline][o_key], better))
            small_p, small_o = abs(p) < small_pct, abs(o) < small_pct
            if small_p and small_o:
                agree = "both small"
            elif small_p != small_o:
                agree = "no"
            else:
                agree = "yes" if np.sign(p) == np.sign(o) else "no"
            out.append({"variant": variant, "baseline": baseline, "metric": p_key, "paper_pct": p,
                        "ours_pct": o, "agree": agree, "small_pct": small_pct})
    return out


def _holds(table, key) -> bool:
    """Whether the Mapping ``table`` has ``key`` (an unhashable key, a list, is in none: Python's TypeError)."""
    try:
        return key in table
    except TypeError:
        return False


def comparison_table(comparisons: list[dict]) -> str:
    """Markdown table of :func:`compare_with_paper`'s output, with a line counting the disagreements."""
    comparisons = value_list(comparisons, "comparisons", "compare_with_paper's dicts")
    if not comparisons:
        raise EventDataError("no comparisons to tabulate: pass compare_with_paper's output (one dict per pair and "
                             "metric)")
    keys = ("variant", "baseline", "metric", "paper_pct", "ours_pct", "agree", "small_pct")
    for k, c in enumerate(comparisons):
        missing = [key for key in keys if not isinstance(c, Mapping) or key not in c]
        if missing:
            raise EventDataError(f"comparisons[{k}] must be a dict of compare_with_paper's (it has no {missing[0]!r}), "
                                 f"got {c!r:.60}")
        for key in ("paper_pct", "ours_pct", "small_pct"):
            real_number(c[key], f"comparisons[{k}][{key!r}]", hint="percent, as compare_with_paper gives")
    lines = ["| change | metric | paper | ours | same direction |", "|---|---|---:|---:|---|"]
    for c in comparisons:
        lines.append(f"| {c['baseline']} → {c['variant']} | {c['metric']} | {c['paper_pct']:+.0f} % | "
                     f"{c['ours_pct']:+.0f} % | {c['agree']} |")
    differ = [f"{c['baseline']} → {c['variant']} ({c['metric']})" for c in comparisons if c["agree"] == "no"]
    lines += ["", "Improvement in percent of the baseline's value, positive = better (lower MSE or time, higher SSIM); "
              f"MSE and SSIM after CLAHE on both sides; 'both small': both changes under {comparisons[0]['small_pct']:g} %. "
              f"Not in the paper's direction: {len(differ)} of {len(comparisons)}"
              + (f" ({', '.join(differ)})." if differ else ".")]
    return "\n".join(lines)
