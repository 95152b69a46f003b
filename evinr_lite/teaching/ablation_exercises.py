"""Notebook 07's exercises (reference solutions registered with :mod:`evinr_lite.teaching.exercises` at import).

- ``time_fps_products``: Time x FPS for every row of one of the paper's tables. The product is the
  number of frames the FPS column counts; that it is (nearly) constant within a table shows that
  the paper's FPS is training throughput, frames delivered per second of optimisation, not an
  inference speed;
- ``pareto_front``: which variants are worth considering when both time and quality count: those
  that no other variant beats on one without losing on the other.

The references are the library's own :func:`evinr_lite.evaluation.ablation.paper_frame_counts` and
:func:`evinr_lite.evaluation.ablation.pareto_front`.
"""
from __future__ import annotations

import numpy as np

from . import exercises
from ..evaluation.ablation import PAPER_TABLE2, PAPER_TABLE3, paper_frame_counts, pareto_front

__all__ = ["time_fps_products", "pareto_front"]

time_fps_products = paper_frame_counts


# ---- exercise 1: Time x FPS of the paper's tables -------------------------------------------------

def _inputs_products(rng):
    cases = [dict(table=PAPER_TABLE2), dict(table=PAPER_TABLE3)]
    rows = {f"row {k}": {"time_s": float(rng.uniform(1, 30)), "fps": float(rng.uniform(5, 80)),
                         "ssim": float(rng.uniform(0.3, 0.7))} for k in range(4)}
    cases.append(dict(table=rows))
    return cases


def _time_over_fps(table):
    return {name: row["time_s"] / row["fps"] for name, row in table.items()}


def _fps_over_time(table):
    return {name: row["fps"] / row["time_s"] for name, row in table.items()}


def _time_times_ssim(table):
    return {name: row["time_s"] * row["ssim"] for name, row in table.items()}


def _products_sorted_names(table):
    """The names sorted, the products in the table's order: zipped, each product goes to another row's name."""
    return dict(zip(sorted(table), [row["time_s"] * row["fps"] for row in table.values()]))


exercises.register(
    "time_fps_products", time_fps_products, _inputs_products, rtol=1e-6,
    hints={"FPS is frames per second: frames = seconds x (frames / second), multiply time_s by fps": _time_over_fps,
           "fps / time_s has units frames per second squared; the frame count is time_s * fps": _fps_over_time,
           "use the row's 'fps' entry (the FPS column), not its quality": _time_times_ssim,
           "the names and the products are out of step: zip(sorted(table), products) pairs each product (in the "
           "table's order) with another row's name; build {name: row['time_s'] * row['fps'] for name, row in "
           "table.items()}": _products_sorted_names})


# ---- exercise 2: Pareto front ------------------------------------------------------------------

def _inputs_front(rng):
    cases = [dict(cost=np.array([1.0, 2.0, 3.0]), quality=np.array([0.5, 0.6, 0.4])),
             dict(cost=np.array([2.0, 1.0, 1.0, 3.0]), quality=np.array([0.7, 0.5, 0.5, 0.7])),   # ties
             dict(cost=np.array([1.0, 1.0, 2.0]), quality=np.array([0.3, 0.6, 0.6]))]             # ties in one
    for k in (5, 8):
        cases.append(dict(cost=rng.integers(1, 5, k).astype(np.float64), quality=rng.integers(1, 5, k) / 5))
    # costs counted in weights (a million, a few apart): unequal, though np.isclose (rtol 1e-5) calls them equal
    cases[4]["cost"] += 1e6
    # Python lists, as notebook 07 passes them (`cost = [r["train_time_s"] for r in all_rows]`): a function that
    # indexes them as arrays (cost[:, None], cost.astype(float)) would pass arrays here and fail in the notebook
    cases[3] = {key: value.tolist() for key, value in cases[3].items()}
    return cases


def _ties_dominate(cost, quality):
    c, q = np.asarray(cost, float)[:, None], np.asarray(quality, float)[:, None]
    dominated = (c.T <= c) & (q.T >= q) & ~np.eye(len(c), dtype=bool)
    return ~dominated.any(axis=1)


def _strict_in_both(cost, quality):
    c, q = np.asarray(cost, float)[:, None], np.asarray(quality, float)[:, None]
    return ~((c.T < c) & (q.T > q)).any(axis=1)


def _cost_reversed(cost, quality):
    return pareto_front(-np.asarray(cost, float), quality)


def _dominated_any_over_rows(cost, quality):
    c = np.asarray(cost, dtype=np.float64)[:, None]
    q = np.asarray(quality, dtype=np.float64)[:, None]
    dominated = (c.T <= c) & (q.T >= q) & ((c.T < c) | (q.T > q))
    return ~dominated.any(axis=0)


def _running_best_kept(cost, quality):
    """In order of cost (a stable sort), keep q >= np.maximum.accumulate(q): a variant that costs more for only the
    same quality as the best so far is kept."""
    c, q = np.asarray(cost, dtype=np.float64), np.asarray(quality, dtype=np.float64)
    order = np.argsort(c, kind="stable")
    keep = np.zeros(len(c), dtype=bool)
    keep[order] = q[order] >= np.maximum.accumulate(q[order])
    return keep


def _sweep_by_cost_alone(cost, quality):
    """A sweep in order of cost alone (equal costs in the order given): a worse variant that comes before a better
    one of the same cost is kept."""
    c, q = np.asarray(cost, dtype=np.float64), np.asarray(quality, dtype=np.float64)
    keep, best = np.zeros(len(c), dtype=bool), -np.inf
    for i in np.argsort(c, kind="stable"):
        if q[i] > best:
            keep[i], best = True, q[i]
    return keep


def _best_quality_only(cost, quality):
    q = np.asarray(quality, dtype=np.float64)
    return q == q.max()


def _sweep(cost, quality, keep_equal):
    c, q = np.asarray(cost, dtype=np.float64), np.asarray(quality, dtype=np.float64)
    keep, best = np.zeros(len(c), dtype=bool), -np.inf
    for i in np.lexsort((-q, c)):                  # by cost, the best quality first among equal costs
        if q[i] > best or (keep_equal and q[i] >= best):
            keep[i], best = True, q[i]
    return keep


def _sweep_strict(cost, quality):
    return _sweep(cost, quality, False)


def _sweep_ties_kept(cost, quality):
    return _sweep(cost, quality, True)


def _qualities_sorted_alone(cost, quality):
    """A sweep in order of cost over np.sort(quality), best first: the qualities sorted on their own, so each
    variant is paired with another one's quality."""
    c = np.asarray(cost, dtype=np.float64)
    keep, best = np.zeros(len(c), dtype=bool), -np.inf
    for i, q in zip(np.argsort(c, kind="stable"), np.sort(np.asarray(quality, dtype=np.float64))[::-1]):
        if q > best:
            keep[i], best = True, q
    return keep


def _ties_within_tolerance(cost, quality):
    """Equal costs and qualities told by np.isclose (rtol 1e-5): a million weights and a million and three tie."""
    c, q = np.asarray(cost, float), np.asarray(quality, float)
    same_c, same_q = np.isclose(c[None, :], c[:, None]), np.isclose(q[None, :], q[:, None])
    no_more = (c[None, :] <= c[:, None]) | same_c
    no_worse = (q[None, :] >= q[:, None]) | same_q
    return ~(no_more & no_worse & ~(same_c & same_q)).any(axis=1)


exercises.register(
    "pareto_front", pareto_front, _inputs_front,
    hints={"two variants tied in both cost and quality do not dominate each other: j dominates i only if it "
           "is also strictly better in at least one of the two": _ties_dominate,
           "a variant that is as cheap and strictly better in quality (or as good and strictly cheaper) "
           "dominates too: 'strictly better in both' is too strict": _strict_in_both,
           "lower cost is better: j dominates i when cost[j] <= cost[i]": _cost_reversed,
           "dominated[i, j] says j dominates i: variant i is on the front when no j does, any over axis 1 "
           "(axis 0 asks whether i dominates some other variant; so does calling it with cost and quality swapped: "
           "cost comes first, and lower cost is better)": _dominated_any_over_rows,
           "a sweep in order of cost that keeps a variant only when its quality beats the best so far drops a "
           "variant tied with a kept one in both cost and quality: ties in both are on the front": _sweep_strict,
           "a sweep that keeps a variant whenever its quality is >= the best so far keeps one that costs more for "
           "the same quality (it is dominated): keep it only when it is strictly better, or tied in both with the "
           "last kept one": _sweep_ties_kept,
           "the front holds every variant that no other one dominates (cheaper ones with lower quality too), not "
           "only the best quality": _best_quality_only,
           "q >= np.maximum.accumulate(q) in order of cost keeps a variant that costs more for only the same quality "
           "as a cheaper one (that one dominates it), and among equal costs keeps a worse one sorted before a better "
           "one: compare with the best quality of the strictly cheaper variants, and ties only in both":
           _running_best_kept,
           "sorted by cost alone, variants of equal cost stay in the order given, and a worse one met before a "
           "better one of the same cost is kept (that one dominates it): sort by cost and then by quality, best "
           "first (np.lexsort((-quality, cost))), or compare every pair":
           _sweep_by_cost_alone,
           "np.sort(quality) sorts the qualities on their own, so they no longer belong to the variants that "
           "np.argsort(cost) lists: take both in one order (order = np.argsort(cost), then quality[order])":
           _qualities_sorted_alone,
           "compare costs and qualities exactly (<=, >=, <, >): np.isclose (or any tolerance) calls costs of "
           "1000003 and 1000004 weights equal, so a variant that costs more for the same quality stays on the "
           "front": _ties_within_tolerance})
