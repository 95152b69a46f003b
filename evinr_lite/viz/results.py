"""Figures of scores: results bar charts, ablation panels, the time/quality trade-off, robustness sweeps."""
from __future__ import annotations

from collections.abc import Iterable, Mapping

import matplotlib.pyplot as plt
import numpy as np

from ..core.checks import ArgumentTypeError, choice, host_array, is_real_number, numbers_array, short_repr
from ..core.events import EventDataError
from ..evaluation.ablation import COLUMN_LABELS, pareto_front
from .signals import axes_or_new

__all__ = ["plot_results", "plot_ablation", "plot_tradeoff", "plot_robustness"]


def _rows(rows, what: str) -> list:
    """The rows as a list, each a dict (a Mapping); else an ArgumentTypeError naming rows= and ``what`` they are
    (None or a number were "not iterable", a string was read letter by letter, a tuple of numbers "'int' object
    is not subscriptable")."""
    if isinstance(rows, (str, bytes, Mapping)) or not isinstance(rows, Iterable):
        raise ArgumentTypeError(f"rows= must be a list of result rows ({what}), got {type(rows).__name__}"
                                + ("; pass [row]" if isinstance(rows, Mapping) else ""))
    rows = list(rows)
    bad = next((r for r in rows if not isinstance(r, Mapping)), None)
    if bad is not None:
        raise ArgumentTypeError(f"rows= must be a list of result rows ({what}), but one is a {type(bad).__name__}: "
                                f"{bad!r}"[:200])
    return rows


def _keys(keys, name: str) -> list:
    """Row keys as a list of str: one str, or any iterable of str that is no mapping (a list, a tuple, a numpy
    array of text, a generator, dict keys, a set: drawn in the order it gives them); None or a number were "not
    iterable", a list of lists "unhashable"."""
    if isinstance(keys, str):
        return [keys]
    given = keys
    keys = None if isinstance(keys, (bytes, Mapping)) or not isinstance(keys, Iterable) else list(keys)
    if keys is None or not all(isinstance(k, str) for k in keys):
        raise ArgumentTypeError(f"{name}= must be the names of row keys (e.g. ('ssim_none', 'ssim_clahe')), got "
                                f"{given!r}"[:200])
    return [str(k) for k in keys]   # numpy's str_ as str


def _score(value, key: str, where: str, *, finite: bool) -> float:
    """One row's ``key`` as a float: None is NaN (a missing score, drawn as a gap); text, a bool or anything else
    that is no number is refused (text was parsed, or drawn as categories), and so is NaN or inf when ``finite`` (a
    broken score, drawn as a gap without a word before)."""
    if value is None:
        return np.nan
    if not is_real_number(value):
        kind = "text" if isinstance(value, (str, bytes)) else type(value).__name__
        raise EventDataError(f"rows' {key!r} must be numbers, one per row (None: missing); {where} has "
                             f"{short_repr(value)} ({kind})" + (": convert with float()" if kind == "text" else ""))
    v = float(host_array(value))
    if finite and not np.isfinite(v):
        raise EventDataError(f"{where}: {key} = {v}, not a score; rescore it (or drop the row); None marks a "
                             "missing score, drawn as a gap")
    return v


def _column(rows: list, key, name: str, fix: str, *, finite: bool = False) -> np.ndarray:
    """``row[key]`` of every row as float64 numbers (None: NaN, a missing score; ``finite``: NaN or inf given is
    refused, see :func:`_score`); a key no row holds is named with ``fix`` (a KeyError before), and so is a value
    that is no number."""
    if not isinstance(key, str):
        raise ArgumentTypeError(f"{name}= must be the name of a row key (e.g. 'ssim_clahe'), got {key!r}"[:200])
    missing = [i for i, r in enumerate(rows) if key not in r]
    if missing:
        raise EventDataError(f"row {missing[0]} has no {key!r} (its keys: {sorted(map(str, rows[missing[0]]))[:8]}); "
                             f"{fix}")
    return np.array([_score(r[key], key, _where(r, i), finite=finite) for i, r in enumerate(rows)], np.float64)


def _where(row, i: int) -> str:
    """A row as the message names it: its index and, when it has one, its name or method."""
    label = row.get("name", row.get("method"))
    return f"row {i}" + ("" if label is None else f" ({label})")


def plot_results(rows, *, metrics=("mse", "ssim", "lpips"), fig=None):
    """Bar charts, one panel per metric: methods along x, one bar per equalisation. Returns the figure."""
    rows = _rows(rows, "dicts with 'method', as evaluate() returns")
    metrics = _keys(metrics, "metrics")
    if not rows or not all(isinstance(r, dict) and "method" in r for r in rows):
        raise ValueError("plot_results needs the result rows evaluate() returns (dicts with 'method'), got "
                         + ("none" if not rows else repr(rows[0])[:80]))
    metrics = [m for m in metrics if any(r.get(m) is not None for r in rows)]
    if not metrics:
        raise ValueError("no row holds any of the metrics asked for; pass metrics= among the rows' keys")
    # None (or no key) is a missing score, drawn as a gap; a NaN score drew no bar: read as a missing method, not
    # as a broken score, so it is refused (as plot_ablation does); text was drawn as categories
    scores = {m: [_score(r.get(m), m, _where(r, i), finite=True) for i, r in enumerate(rows)] for m in metrics}
    methods = list(dict.fromkeys(r["method"] for r in rows))
    eqs = list(dict.fromkeys(r.get("equalization", "") for r in rows))
    fig = fig or plt.figure(figsize=(3.6 * len(metrics), 3.0))
    axes = fig.subplots(1, len(metrics), squeeze=False)[0]
    width = 0.8 / len(eqs)
    better = {"mse": "lower is better", "ssim": "higher is better", "lpips": "lower is better"}
    for ax, metric in zip(axes, metrics):
        for k, eq in enumerate(eqs):
            vals = []
            for m in methods:
                hit = [v for r, v in zip(rows, scores[metric]) if r["method"] == m and r.get("equalization", "") == eq]
                vals.append(hit[0] if hit else np.nan)
            ax.bar(np.arange(len(methods)) + (k - (len(eqs) - 1) / 2) * width, vals, width, label=eq)
        ax.set_xticks(np.arange(len(methods)), methods)
        ax.set_title(f"{metric.upper()} ({better.get(metric, '')})")
    axes[0].legend(title="equalisation", fontsize=9)
    fig.tight_layout()
    return fig


def plot_ablation(rows: list[dict], metrics=("ssim_none", "ssim_clahe"), *, x=None, xlabel: str | None = None,
                  xscale: str = "linear", title: str | None = None, fig=None):
    """Quality (left) and training time (right) of each variant.

    Args:
        rows: from :func:`evinr_lite.evaluation.ablation.run_variants`.
        metrics: quality keys drawn on the left panel (one bar or line each).
        x: None for bars, one group per variant; or numbers [len(rows)] (e.g. the lambdas of a sweep)
            for lines against x.
        xlabel, xscale: the x axis when ``x`` is given ("linear", "log", "symlog").
        title: figure title. fig: a figure to draw into (cleared); a new one when None.

    Returns:
        The matplotlib figure.
    """
    rows = _rows(rows, "dicts with 'name', 'train_time_s' and the metrics, as run_variants returns")
    if not rows:
        raise ValueError("no rows to plot")
    metrics = _keys(metrics, "metrics")
    if not metrics:
        raise ValueError("metrics= is empty: pass the quality keys to draw (e.g. ('ssim_none', 'ssim_clahe'))")
    xscale = choice(xscale, ("linear", "log", "symlog"), "xscale=")
    fix = "pass the rows of run_variants (dicts with 'name', 'train_time_s' and the metrics)"
    missing = [i for i, r in enumerate(rows) if "name" not in r]
    if missing:   # a KeyError before
        raise EventDataError(f"row {missing[0]} has no 'name'; {fix}")
    # None is a missing score (or time), drawn as a gap; NaN or inf is refused, as plot_results refuses it (a None
    # metric was a TypeError when drawn, a NaN one a bar missing without a word)
    times = _column(rows, "train_time_s", "rows", fix, finite=True)
    scores = {m: _column(rows, m, "metrics", "pass metrics= among the rows' keys", finite=True) for m in metrics}
    names = [r["name"] for r in rows]
    if fig is None:
        fig = plt.figure(figsize=(max(9.0, 1.3 * len(rows) + 4), 3.4))
    else:
        fig.clf()
    ax_q, ax_t = fig.subplots(1, 2, gridspec_kw={"width_ratios": [3, 2]})
    if x is None:
        pos = np.arange(len(rows))
        width = 0.8 / len(metrics)
        for k, m in enumerate(metrics):
            ax_q.bar(pos + (k - (len(metrics) - 1) / 2) * width, scores[m], width,
                     label=COLUMN_LABELS.get(m, (m,))[0])
        ax_t.bar(pos, times, 0.6, color="0.5")
        for ax in (ax_q, ax_t):
            ax.set_xticks(pos, names, rotation=30, ha="right", fontsize=9)
    else:
        x = np.asarray(x, dtype=np.float64)
        if x.shape != (len(rows),):
            raise ValueError(f"x must hold one number per row ({len(rows)}), got shape {x.shape}")
        for m in metrics:
            ax_q.plot(x, scores[m], "o-", label=COLUMN_LABELS.get(m, (m,))[0])
        ax_t.plot(x, times, "o-", color="0.4")
        for ax in (ax_q, ax_t):
            ax.set_xscale(xscale)
            ax.set_xticks(x, [f"{v:g}" for v in x])
            ax.minorticks_off()
            ax.set_xlabel(xlabel or "")
    ax_q.set(ylabel="score", title="quality (higher SSIM, lower MSE is better)")
    ax_q.legend(fontsize=9)
    ax_t.set(ylabel="training time (s)", title="time on this machine")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_tradeoff(rows: list[dict], quality: str = "ssim_clahe", *, cost: str = "train_time_s", front=None,
                  labels: str = "front", ax=None, title: str | None = None):
    """Scatter of cost (x) against quality (y), one labelled point per row, the Pareto front joined.

    Args:
        rows: from :func:`evinr_lite.evaluation.ablation.run_variants` (all of them, from several tables).
        quality, cost: row keys (higher quality and lower cost are better).
        front: bool [len(rows)] marking the front (default: :func:`pareto_front`).
        labels: "front" names the points on the front only (readable with many rows), "all" every point.
        ax: axes to draw into (a new figure when None). title: axes title.

    Returns:
        The axes.
    """
    rows = _rows(rows, "dicts with 'name', the quality and the cost keys, as run_variants returns")
    if not rows:   # empty axes titled "time against quality"
        raise ValueError("no rows to plot: pass the rows of run_variants (dicts with 'name', the quality and the "
                         "cost keys)")
    # the keys, the front and the labels before anything is drawn (a key no row holds was a KeyError, a front of
    # one number "iteration over a 0-d array", one of another length numpy's IndexError; labels were checked
    # after the points were drawn)
    c = _column(rows, cost, "cost", "pass cost= one of the rows' keys (e.g. 'train_time_s')")
    q = _column(rows, quality, "quality", "pass quality= one of the rows' keys (e.g. 'ssim_clahe')")
    for key in (cost, quality):   # a point has no gap to draw: None (a missing score) was "quality[1] is nan"
        gap = next((i for i, r in enumerate(rows) if r[key] is None), None)
        if gap is not None:
            raise EventDataError(f"{_where(rows[gap], gap)} has no {key} (None); every point needs its cost and its "
                                 "quality: drop that row")
    missing = [i for i, r in enumerate(rows) if "name" not in r]
    if missing:
        raise EventDataError(f"row {missing[0]} has no 'name' (each point is labelled with it); pass the rows of "
                             "run_variants")
    if front is None:
        front = pareto_front(c, q)
    else:
        given = numbers_array(front, "front", "flags, one per row (True: on the front)", flags=True)
        if given.shape != (len(rows),) or not np.isin(given, (0, 1)).all():
            raise EventDataError(f"front= must be {len(rows)} flags (one per row, True on the front), got "
                                 f"{given.dtype} of shape {given.shape}")
        front = given.astype(bool)
    labels = choice(labels, ("front", "all"), "labels")
    ax = axes_or_new(ax, (8, 4.5))
    ax.scatter(c[~front], q[~front], color="0.6", s=18, label="dominated")
    ax.scatter(c[front], q[front], color="tab:red", s=30, label="Pareto front")
    order = np.flatnonzero(front)[np.argsort(c[front])]
    ax.step(c[order], q[order], where="post", color="tab:red", lw=1)
    for r, ci, qi, on in zip(rows, c, q, front):
        if on or labels == "all":
            ax.annotate(r["name"], (ci, qi), fontsize=9, xytext=(4, -3), textcoords="offset points")
    ax.set(xlabel=COLUMN_LABELS.get(cost, (cost,))[0], ylabel=COLUMN_LABELS.get(quality, (quality,))[0],
           title=title or "time against quality")
    ax.legend(fontsize=9)
    return ax


def plot_robustness(results: dict, metrics=("ssim_clahe", "ssim_none"), *, fontsize: float = 9, fig=None):
    """Robustness sweeps: one column of panels per sweep, one row per metric, one line per method.

    Args:
        results: {"methods": [names], "sweeps": {name: {"label": x-axis label with units, "levels": [L],
            "clean": the unperturbed level, "means": {method: {metric: [L values, None where not run]}}}}}
            (what ``benchmarks/robustness.py`` writes). A sweep named "C_scale" gets a log x axis.
        metrics: one row of panels each (default CLAHE-SSIM over plain SSIM).
        fontsize: points, for every label, tick and legend (>= 9 for print).
        fig: a figure to draw into (cleared); a new one when None.

    Returns:
        The figure: len(metrics) x len(sweeps) axes, each with one line per method that has values,
        and a dotted vertical line at the clean level.
    """
    sweeps = results.get("sweeps") or {}
    if not sweeps:
        raise ValueError("results hold no sweeps; pass what benchmarks/robustness.py writes (results['sweeps'])")
    methods = list(results.get("methods") or next(iter(sweeps.values()))["means"])
    names = {"ssim_clahe": "CLAHE-SSIM", "ssim_none": "SSIM (no equalisation)", "mse_none": "MSE (no equalisation)"}
    if fig is None:
        fig = plt.figure(figsize=(3.6 * len(sweeps), 2.7 * len(metrics) + 0.5))
    else:
        fig.clf()
    axes = fig.subplots(len(metrics), len(sweeps), squeeze=False)
    colours = {m: f"C{i}" for i, m in enumerate(methods)}
    for j, (s, sw) in enumerate(sweeps.items()):
        x = np.asarray(sw["levels"], dtype=np.float64)
        for i, metric in enumerate(metrics):
            ax = axes[i, j]
            for m in methods:
                vals = sw["means"].get(m, {}).get(metric)
                if vals is None:
                    continue
                y = np.array([np.nan if v is None else v for v in vals], dtype=np.float64)
                ok = np.isfinite(y)
                if ok.any():
                    ax.plot(x[ok], y[ok], "o-", color=colours[m], label=m, ms=4, lw=1.5)
            ax.axvline(sw["clean"], color="0.6", ls=":", lw=1)
            if s == "C_scale":
                ax.set_xscale("log")
                ax.set_xticks(x, [f"{v:g}" for v in x])
                ax.minorticks_off()
            ax.set_xlabel(sw.get("label", s), fontsize=fontsize)
            ax.set_ylabel(names.get(metric, metric), fontsize=fontsize)
            ax.tick_params(labelsize=fontsize)
            if i == 0:
                ax.set_title(s, fontsize=fontsize + 1)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=max(1, len(labels)), fontsize=fontsize, frameon=False)
    fig.suptitle("Robustness: mean over scenes (dotted: the clean condition)", fontsize=fontsize + 1)
    fig.tight_layout(rect=(0, 0.4 / fig.get_figheight(), 1, 1))
    return fig
