"""Notebook 07's exercises (reference solutions registered with :mod:`evinr_lite.teaching.exercises` at import).

- ``relative_change``: the improvement of a variant over a baseline in percent, positive = better,
  for metrics where higher is better (SSIM, FPS) and where lower is better (MSE, time); the
  numbers the paper quotes ("a performance gain of over 26 %") are of this kind;
- ``pareto_front``: which variants are worth considering when both time and quality count: those
  that no other variant beats on one without losing on the other.

The references are the library's own :func:`evinr_lite.evaluation.ablation.relative_change` and
:func:`evinr_lite.evaluation.ablation.pareto_front`.
"""
from __future__ import annotations

import numpy as np

from . import exercises
from ..evaluation.ablation import pareto_front, relative_change

__all__ = ["relative_change", "pareto_front"]


# ---- exercise 1: relative change ---------------------------------------------------------------

def _inputs_change(rng):
    cases = [dict(value=0.044, baseline=0.063, higher_is_better=False),     # the paper's MSE, Base -> Base + Reg.
             dict(value=0.658, baseline=0.542, higher_is_better=True),      # its SSIM, Base -> Full
             dict(value=8.08, baseline=17.44, higher_is_better=False)]      # its time, Base + Reg. -> Full
    for _ in range(3):
        cases.append(dict(value=float(rng.uniform(0.1, 2)), baseline=float(rng.uniform(0.1, 2)),
                          higher_is_better=bool(rng.integers(2))))
    return cases


def _no_sign_flip(value, baseline, higher_is_better):
    return 100.0 * (value - baseline) / abs(baseline)


def _relative_to_value(value, baseline, higher_is_better):
    change = 100.0 * (value - baseline) / abs(value)
    return change if higher_is_better else -change


def _fraction(value, baseline, higher_is_better):
    return relative_change(value, baseline, higher_is_better) / 100.0


exercises.register(
    "relative_change", relative_change, _inputs_change, rtol=1e-6,
    hints={"for a lower-is-better metric (MSE, time) a decrease is an improvement: flip the sign when "
           "higher_is_better is False": _no_sign_flip,
           "divide by the baseline's value, not the new one: percent *of the baseline*": _relative_to_value,
           "return percent (x 100), not a fraction": _fraction})


# ---- exercise 2: Pareto front ------------------------------------------------------------------

def _inputs_front(rng):
    cases = [dict(cost=np.array([1.0, 2.0, 3.0]), quality=np.array([0.5, 0.6, 0.4])),
             dict(cost=np.array([2.0, 1.0, 1.0, 3.0]), quality=np.array([0.7, 0.5, 0.5, 0.7])),   # ties
             dict(cost=np.array([1.0, 1.0, 2.0]), quality=np.array([0.3, 0.6, 0.6]))]             # ties in one
    for k in (5, 8):
        cases.append(dict(cost=rng.integers(1, 5, k).astype(np.float64), quality=rng.integers(1, 5, k) / 5))
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


exercises.register(
    "pareto_front", pareto_front, _inputs_front,
    hints={"two variants tied in both cost and quality do not dominate each other: j dominates i only if it "
           "is also strictly better in at least one of the two": _ties_dominate,
           "a variant that is as cheap and strictly better in quality (or as good and strictly cheaper) "
           "dominates too: 'strictly better in both' is too strict": _strict_in_both,
           "lower cost is better: j dominates i when cost[j] <= cost[i]": _cost_reversed})
