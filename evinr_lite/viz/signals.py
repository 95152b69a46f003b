"""Small matplotlib helpers for the notebooks (method modules never import matplotlib).

Every function draws into ``ax`` (a new figure's axes when ``ax`` is None) and returns the axes.
Colours: ON events red, OFF events blue. No named styles (they change between versions).
"""
from __future__ import annotations

import numpy as np
import matplotlib.pyplot as plt
from matplotlib.transforms import blended_transform_factory

from matplotlib.axes import Axes
from matplotlib.figure import FigureBase

from ..core.checks import ArgumentTypeError, host_array, numbers_array, real_number, short_repr, true_or_false
from ..core.events import EventDataError
from ..sim.simulate import pixel_events

__all__ = ["ON_COLOR", "OFF_COLOR", "axes_or_new",
           "plot_event_ticks", "plot_signal_and_events", "plot_reconstruction_1d",
           "plot_window_errors"]

ON_COLOR = "tab:red"
OFF_COLOR = "tab:blue"


def axes_or_new(ax, figsize=(8, 3.5), *, projection: str | None = None):
    """``ax`` when it is a matplotlib Axes, a new figure's (of ``figsize`` inches) when None; else an
    ArgumentTypeError (a Figure, a number or an array of axes failed inside the first drawing call).
    ``projection="3d"``: the axes must be 3-D (a new one is made so; a 2-D one failed inside the drawing)."""
    kw = {} if projection is None else {"projection": projection}
    if ax is None:
        return plt.figure(figsize=figsize).add_subplot(**kw)
    new = f"fig.add_subplot({', '.join(f'{k}={v!r}' for k, v in kw.items())})"
    if not isinstance(ax, Axes):
        if isinstance(ax, FigureBase):   # a Figure or a SubFigure
            fits = [i for i, a in enumerate(ax.axes) if projection is None or a.name == projection]
            fix = (f" (a {type(ax).__name__}: pass one of its axes, e.g. fig.axes[{fits[0]}], or {new})" if fits
                   else f" (a {type(ax).__name__} without {'' if projection is None else '3-D '}axes: pass {new})")
        else:
            fix = (" (an array of axes from plt.subplots: pass one of them, e.g. axes[0])"
                   if isinstance(ax, np.ndarray) else "")
        kind = "a 3-D matplotlib Axes" if projection == "3d" else "a matplotlib Axes"
        raise ArgumentTypeError(f"ax= must be {kind} or None (a new figure), got {type(ax).__name__}{fix}")
    if projection is not None and ax.name != projection:
        raise ArgumentTypeError(f"ax= must be an Axes of projection={projection!r}, got one of projection="
                                f"{ax.name!r}; make it with {new}")
    return ax


def _curve(values, name: str, n: int) -> np.ndarray:
    """A curve to draw against n times: numbers whose first axis has length n."""
    arr = None if isinstance(values, (str, bytes)) or values is None else np.asarray(host_array(values))
    if arr is None or arr.dtype.kind not in "biuf" or arr.ndim == 0:
        raise EventDataError(f"{name} must be numbers, one per time ([T] = [{n}]), got {short_repr(values)}")
    if len(arr) != n:
        raise EventDataError(f"{name} holds {len(arr)} values but t holds {n} times; pass one value per time")
    return arr


def _times(t) -> np.ndarray:
    """A figure's times as float64 [T]: numbers on one axis, NaN allowed (matplotlib leaves a gap there), any float
    type (float32 or float16 times are drawn as they are: no event timestamps, whose precision matters)."""
    try:
        arr = None if isinstance(t, (str, bytes)) or t is None else np.asarray(host_array(t))
    except (TypeError, ValueError):   # a ragged list
        arr = None
    if arr is None or arr.dtype.kind not in "iuf" or arr.ndim != 1:
        raise EventDataError(f"t= must be seconds, a 1-D array of numbers [T], got "
                             f"{short_repr(t) if arr is None or arr.ndim == 1 else f'shape {arr.shape}'}")
    return arr.astype(np.float64)


def plot_event_ticks(ax, t_events, p_events, height: float = 0.08, legend: bool = True):
    """Short vertical ticks at the bottom of ``ax`` (axes fraction ``height``), one per event,
    red for ON and blue for OFF."""
    # checked by name before any tick is drawn (None was "1 event times", text numpy's conversion error, a height
    # of None or text drew no tick without a word, a list of 3 numpy's broadcast error inside matplotlib)
    ax = axes_or_new(ax)
    t_events = np.ravel(numbers_array(t_events, "t_events", "event times in seconds").astype(np.float64))
    p_events = np.ravel(numbers_array(p_events, "p_events", "polarities (+1 ON, -1 OFF; or 1 / 0)", flags=True))
    height = real_number(height, "height", lo=0, hi=1, lo_open=True, hint="the ticks' height, a fraction of the axes")
    legend = true_or_false(legend, "legend")
    if t_events.shape != p_events.shape:   # numpy's boolean-index error before
        raise ValueError(f"{t_events.size} event times but {p_events.size} polarities; pass one polarity per event")
    trans = blended_transform_factory(ax.transData, ax.transAxes)
    for sign, color, name in ((1, ON_COLOR, "ON event"), (-1, OFF_COLOR, "OFF event")):
        sel = t_events[p_events * sign > 0]
        ax.vlines(sel, 0.0, height, colors=color, lw=1.0, transform=trans,
                  label=f"{name}s ({sel.size})" if legend else None)
    return ax


def plot_signal_and_events(t, L, events, C: float | None = None, *, ax=None, pixel: int = 0, L0=None,
                           show_levels: bool = True, show_crossings: bool = True, label: str = "L(t) = log I(t)"):
    """A 1-D log-intensity signal, its threshold levels and its events (Eq. 1).

    Args:
        t: float [T] sample times (s).
        L: float [T] log intensity at ``t``, or a callable of t.
        events: ``Events`` with sensor_size (1, P) (``pixel`` picks one) or a (t, p) pair (``([], [])``:
            no events, the signal and its levels only).
        C: contrast threshold; draws the levels L0 + k*C and the level each event reached.
        L0: the reference level at the start (default ``L[0]``).
    """
    t = np.asarray(t, dtype=np.float64)
    if t.ndim != 1 or t.size == 0:   # L[0] was numpy's IndexError
        raise ValueError(f"t must be the sample times [T] (1-D, at least one), got shape {t.shape}")
    L = np.asarray(L(t) if callable(L) else L, dtype=np.float64)
    if L.shape != t.shape:           # matplotlib's "x and y must have same first dimension"
        raise ValueError(f"L has shape {L.shape} for {t.size} sample times; pass one log intensity per time in t")
    te, pe = pixel_events(events, pixel)   # refuses None, [] and t / p of different lengths, naming the fix
    ax = axes_or_new(ax)
    L0 = L[0] if L0 is None else float(L0)
    ax.plot(t, L, color="black", lw=1.5, label=label)
    if C is not None and show_levels:
        k = np.arange(np.floor((L.min() - L0) / C), np.ceil((L.max() - L0) / C) + 1)
        for level in L0 + C * k:
            ax.axhline(level, color="0.85", lw=0.7, zorder=0)
    if C is not None and show_crossings and te.size:
        level = L0 + C * np.cumsum(pe)
        ax.plot(te[pe > 0], level[pe > 0], "^", color=ON_COLOR, ms=4, ls="none")
        ax.plot(te[pe < 0], level[pe < 0], "v", color=OFF_COLOR, ms=4, ls="none")
    plot_event_ticks(ax, te, pe)
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("log intensity")
    ax.legend(loc="upper right", fontsize=9)
    return ax


def plot_reconstruction_1d(t, curves: dict, truth=None, *, events=None, ax=None, pixel: int = 0, title=None):
    """Reconstructions of one pixel against the true signal.

    Args:
        t: float [T] times (s).
        curves: ``{label: values [T]}``; drawn in order.
        truth: float [T] true log intensity (thick black), optional.
        events: optional events drawn as ticks at the bottom.
    """
    t = _times(t)
    if not isinstance(curves, dict):   # a list or None was an AttributeError
        raise ArgumentTypeError(f"curves= must be a dict {{label: values [T]}}, got {type(curves).__name__}; e.g. "
                                "{'EvINR': L_hat}")
    curves = {label: _curve(values, f"curves[{label!r}]", len(t)) for label, values in curves.items()}
    truth = None if truth is None else _curve(truth, "truth", len(t))
    ax = axes_or_new(ax)
    if truth is not None:
        ax.plot(t, truth, color="black", lw=2.5, alpha=0.35, label="true L(t)")
    for label, values in curves.items():
        ax.plot(t, values, lw=1.3, label=label)
    if events is not None:
        plot_event_ticks(ax, *pixel_events(events, pixel), legend=False)
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("log intensity")
    if title:
        ax.set_title(title)
    ax.legend(loc="best", fontsize=9)
    return ax


def plot_window_errors(result: dict, *, ax=None, C: float | None = None):
    """Error of the dL/dt estimate versus window length (from :func:`evinr_lite.teaching.pde1d.eq4_error_vs_window`):
    ``result`` holds ``"window"`` and ``"taylor"`` [K] (and optionally ``"events"`` [K])."""
    if not isinstance(result, dict) or not {"window", "taylor"} <= result.keys():   # a KeyError before
        got = f"keys {sorted(result)}" if isinstance(result, dict) else type(result).__name__
        raise ValueError(f"result must be the dict eq4_error_vs_window returns, with 'window' and 'taylor' "
                         f"(and 'events'), got {got}")
    w = np.ravel(np.asarray(result["window"], dtype=np.float64))
    bad = {k: np.shape(result[k]) for k in ("taylor", "events") if k in result and np.size(result[k]) != w.size}
    if w.size == 0:
        raise ValueError("result holds no window lengths; pass eq4_error_vs_window at least one window")
    if bad:
        raise ValueError(f"result holds {w.size} window length(s) but errors of shape {bad}; pass one error per window")
    ax = axes_or_new(ax, (5, 3.5))
    ax.loglog(w, result["taylor"], "o-", label="Eq. 3 with the exact ΔL (Taylor error)")
    if "events" in result:
        ax.loglog(w, result["events"], "s-", label="Eq. 4 with events")
    if C is not None:
        ax.loglog(w, C / w, ":", color="0.5", label="C / window: the rate of one event")
    ax.set_xlabel("window length t2 - t1 (s)")
    ax.set_ylabel("mean |error of dL/dt| (1/s)")
    ax.legend(fontsize=9)
    return ax
