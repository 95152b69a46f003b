"""Figures of whole frames for notebooks 04-05 (grids of reconstructions, image rows, loss curves).

Every function draws into ``fig`` (a new figure when None) and returns the figure, so it also
works inside :func:`evinr_lite.viz.widgets.interact`, which hands its draw function one figure to
redraw. The method modules never import this one.
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import matplotlib.pyplot as plt

from ..core.checks import ArgumentTypeError, numbers_array, real_number
from ..core.events import EventDataError
from .signals import axes_or_new
from .widgets import MAX_FIGSIZE

__all__ = ["show_frames", "show_images", "plot_histories"]


def show_frames(rows: dict, times=None, *, fig=None, cmap: str = "gray", vmin: float = 0.0, vmax: float = 1.0,
                cell_size: float = 1.6, row_titles: dict | None = None, colorbar_label: str | None = None):
    """A grid of frames: one row per entry of ``rows``, one column per frame.

    Args:
        rows: ``{label: frames [Q, H, W]}``; every entry must have the same Q.
        times: float [Q] seconds, written above the columns of the first row.
        fig: a figure to draw into (cleared first); a new one of the right size when None.
        cmap, vmin, vmax: how values map to grey (tone-mapped frames lie in [0, 1]).
        cell_size: inches per image (width), for a new figure.
        row_titles: optional ``{label: extra text}`` appended to the row's label (e.g. a score).
        colorbar_label: when given, one colour bar for the whole grid (every image shares ``vmin``,
            ``vmax`` and ``cmap``) labelled with it, unit included (e.g. "change of log intensity");
            pass one for signed or colour-mapped values, whose colours mean nothing without it.

    Returns:
        The figure.
    """
    _mapping(rows, "rows", "{label: frames [Q, H, W]}")
    if not rows:
        raise ValueError("rows is empty: pass {label: frames [Q, H, W]}")
    cell_size = _cell_size(cell_size)
    vmin, vmax = _limits(vmin, vmax)
    if row_titles is not None:
        _mapping(row_titles, "row_titles", "{label: extra text} (or None)")
    stacks = {k: np.asarray(v) for k, v in rows.items()}
    shapes = {v.shape[0] for v in stacks.values()}
    if len(shapes) != 1 or any(v.ndim != 3 for v in stacks.values()):
        raise ValueError(f"every entry of rows must be [Q, H, W] with the same Q, got "
                         f"{[v.shape for v in stacks.values()]}")
    Q = shapes.pop()
    if Q == 0:
        raise ValueError("rows hold no frames (Q = 0): pass stacks [Q, H, W] of at least one frame")
    _drawable(stacks, "rows")
    if times is not None:
        times = np.ravel(numbers_array(times, "times", "one time per frame, seconds").astype(np.float64))
        if times.size != Q:   # was an IndexError at the first missing title, or titles for the wrong frames
            raise ValueError(f"times has {times.size} value(s) for {Q} frame(s) per row; pass one time per frame")
    H, W = next(iter(stacks.values())).shape[1:]
    n = len(stacks)
    if fig is None:
        fig = plt.figure(figsize=(cell_size * Q, cell_size * H / W * n + 0.4 * n))
    else:
        fig.clf()
    axes = np.atleast_2d(fig.subplots(n, Q, squeeze=False))
    image = None
    for r, (label, frames) in enumerate(stacks.items()):
        for q in range(Q):
            ax = axes[r, q]
            image = ax.imshow(frames[q], cmap=cmap, vmin=vmin, vmax=vmax, interpolation="nearest")
            ax.set_xticks([])
            ax.set_yticks([])
            if r == 0 and times is not None:
                ax.set_title(f"t = {times[q]:.2f} s", fontsize=9)
        extra = (row_titles or {}).get(label)
        axes[r, 0].set_ylabel(label if extra is None else f"{label}\n{extra}", fontsize=9)
    fig.subplots_adjust(wspace=0.03, hspace=0.12)
    if colorbar_label is not None:
        fig.colorbar(image, ax=list(axes.ravel()), fraction=0.02, pad=0.01).set_label(colorbar_label, fontsize=9)
    return fig


def _mapping(value, name: str, what: str) -> None:
    """Refuse what is no mapping (a string, a list, a number: "has no attribute 'items'" before)."""
    if not isinstance(value, Mapping):
        raise ArgumentTypeError(f"{name}= must be a dict {what}, got {type(value).__name__}"
                                + ("; put the array in a dict: {'label': array}" if hasattr(value, "shape") else ""))


def _cell_size(cell_size) -> float:
    """Inches per image: a finite number in (0, MAX_FIGSIZE] (None or text were Python's TypeErrors, -1 or NaN
    matplotlib's "figure size must be positive finite", 0 a figure of no width)."""
    return real_number(cell_size, "cell_size", lo=0, hi=MAX_FIGSIZE, lo_open=True, hint="inches per image")


def _limits(vmin, vmax) -> tuple:
    """The grey scale's limits: each None (the image's own) or a finite number, vmin not above vmax (text failed
    inside matplotlib; NaN or a reversed range drew every pixel one grey without a word). Equal limits are taken:
    a blank frame drawn with ``vmin=-m, vmax=m`` for m = 0 is one colour, as matplotlib draws it."""
    lo = None if vmin is None else real_number(vmin, "vmin", hint="the value drawn black (None: the data's)")
    hi = None if vmax is None else real_number(vmax, "vmax", hint="the value drawn white (None: the data's)")
    if lo is not None and hi is not None and lo > hi:
        raise EventDataError(f"vmin={vmin!r} is above vmax={vmax!r}; swap them")
    return vmin, vmax


def _drawable(arrays: dict, name: str) -> None:
    """Refuse arrays holding NaN or inf: imshow draws them as blank pixels, a wrong picture without a word."""
    for k, a in arrays.items():
        a = np.asarray(a)
        if a.dtype.kind in "fc" and not np.all(np.isfinite(a)):
            raise ValueError(f"{name}[{k!r}] holds NaN or inf (drawn as blank pixels); repair or drop those frames")


def show_images(images: dict, *, fig=None, cmap: str = "gray", vmin=None, vmax=None, symmetric: bool = False,
                colorbar: bool = False, cell_size: float = 2.6, colorbar_label: str | None = None):
    """Single images side by side, each titled by its key.

    Args:
        images: ``{title: image [H, W]}``.
        vmin, vmax: shared limits (None: each image's own range, unless ``symmetric``).
        symmetric: limits +-max|value| over all images (for signed maps such as errors; use a
            diverging ``cmap``).
        colorbar: one colour bar per image.
        colorbar_label: the colour bars' label, with its unit (e.g. "log intensity", "events");
            figures should pass one whenever ``colorbar`` is on.

    Returns:
        The figure.
    """
    _mapping(images, "images", "{title: image [H, W]}")
    if not images:
        raise ValueError("images is empty: pass {title: image [H, W]}")
    cell_size = _cell_size(cell_size)
    vmin, vmax = _limits(vmin, vmax)
    arrays = {k: np.asarray(v, dtype=np.float64) for k, v in images.items()}
    bad = {k: a.shape for k, a in arrays.items() if a.ndim != 2 or a.size == 0}
    if bad:
        raise ValueError(f"every image must be [H, W] with pixels, got {bad}")
    _drawable(arrays, "images")
    if symmetric:
        m = max(float(np.abs(a).max()) for a in arrays.values()) or 1.0
        vmin, vmax = -m, m
    n = len(arrays)
    H, W = next(iter(arrays.values())).shape
    if fig is None:
        fig = plt.figure(figsize=(cell_size * n, cell_size * H / W + 0.5))
    else:
        fig.clf()
    axes = fig.subplots(1, n, squeeze=False)[0]
    for ax, (title, img) in zip(axes, arrays.items()):
        im = ax.imshow(img, cmap=cmap, vmin=vmin, vmax=vmax, interpolation="nearest")
        ax.set_title(title, fontsize=9)
        ax.set_xticks([])
        ax.set_yticks([])
        if colorbar:
            fig.colorbar(im, ax=ax, fraction=0.035, pad=0.02, label=colorbar_label)
    return fig


def plot_histories(histories: dict, key: str = "loss", *, ax=None, xlabel: str = "iteration"):
    """Training curves (log scale): ``{label: history dict or sequence of floats}``; ``key`` picks
    the curve inside a history dict. Returns the axes."""
    _mapping(histories, "histories", "{label: history dict or sequence of floats}")
    if not histories:   # an empty figure with an empty legend
        raise ValueError("histories is empty: pass {label: history dict or sequence of floats}")
    if not isinstance(key, str):   # a list was "unhashable type"
        raise ArgumentTypeError(f"key= must be the name of a curve in the histories (e.g. 'loss'), got "
                                f"{type(key).__name__} {key!r}")
    missing = [label for label, h in histories.items() if isinstance(h, dict) and key not in h]
    if missing:
        raise ValueError(f"no {key!r} in the history of {missing}; pass key= one of its curves "
                         f"(e.g. {sorted(histories[missing[0]])[:5]})")
    ax = axes_or_new(ax, (5, 3))
    for label, h in histories.items():
        values = np.asarray(h[key] if isinstance(h, dict) else h, dtype=np.float64)
        ax.semilogy(np.maximum(values, 1e-16), label=label)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(key)
    ax.legend(fontsize=9)
    return ax
