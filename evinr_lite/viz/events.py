"""Looking at events: x-y-t scatter, polarity images, rates, animations and event frames.

Plotting helpers for event data on a sensor (notebook 02 and later); the method modules never
import matplotlib. Conventions:

- ``plot_*`` functions draw into ``ax`` (a new figure's axes when None) and return the axes;
  ``show_event_frames`` and ``animate_events`` make their own figure.
- Colours: ON events red, OFF events blue (:data:`ON_COLOR`, :data:`OFF_COLOR`, the same as
  :mod:`evinr_lite.viz.signals`); event frames use a diverging map, red positive, blue negative,
  white zero.
- Time windows follow the binning convention of :mod:`evinr_lite.method.binning`: a window
  ``(t0, t1]`` holds the events with ``t0 < t <= t1``.
- Subsampling for scatter plots is deterministic (seeded), so a figure is the same every run.

Numbers behind the figures (:func:`count_map`, :func:`polarity_image`,
:func:`subsample_index`) are plain functions returning arrays, tested by their values.
"""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.animation import FuncAnimation
from matplotlib.colors import to_rgb
from matplotlib.transforms import blended_transform_factory

from ..core.checks import (ArgumentTypeError, checked_span, host_array, is_real_number, optional_seconds, real_number,
                           require, whole_number)
from ..core.events import EventDataError, Events
from ..method.binning import EventFrames, event_rate
from .signals import OFF_COLOR, ON_COLOR, axes_or_new
from .widgets import MAX_FIGSIZE, check_figsize

__all__ = ["ON_COLOR", "OFF_COLOR", "ON_RGB", "OFF_RGB", "subsample_index", "subsample", "count_map",
           "polarity_image", "plot_xyt", "plot_count_map", "plot_polarity", "plot_event_rate",
           "plot_boundaries", "show_event_frames", "animate_events"]

ON_RGB = to_rgb(ON_COLOR)     # (r, g, b) floats in [0, 1]
OFF_RGB = to_rgb(OFF_COLOR)
EVENT_FRAME_CMAP = "RdBu_r"   # red > 0 (more ON), blue < 0 (more OFF)
MIN_DPI = 10.0   # below 10, FreeType has no font size to draw the titles with
MAX_FRAME_PIXELS = 2**27   # an animation frame's pixels (figsize x dpi): 512 MiB of RGBA per frame; (100, 100)
#                            inches at 1000 dpi were C++'s bad_alloc, (4, 3) at 20000 dpi a minute per frame


def _axes(ax, figsize=(6, 4)):
    return axes_or_new(ax, figsize)


# ---- numbers ------------------------------------------------------------------------------

def subsample_index(n: int, max_points: int, seed: int = 0) -> np.ndarray:
    """Indices of at most ``max_points`` of ``n`` items, drawn without replacement, sorted.

    All of ``range(n)`` when ``n <= max_points`` (``max_points=np.inf``: all). The same (n, max_points, seed)
    always gives the same indices; ``seed`` is what ``np.random.default_rng`` takes (a whole number >= 0, None for
    fresh entropy, a Generator or a SeedSequence). Returns int64 [min(n, max_points)].
    """
    n = whole_number(n, "n", lo=0)
    if is_real_number(max_points) and float(host_array(max_points)) == np.inf:   # all of them
        max_points = max(n, 1)
    max_points = whole_number(max_points, "max_points")
    if max_points < 1:
        raise EventDataError(f"max_points must be at least 1, got {max_points}")
    seed = _seed(seed)
    if n <= max_points:
        return np.arange(n, dtype=np.int64)
    idx = np.random.default_rng(seed).choice(n, size=max_points, replace=False)
    return np.sort(idx).astype(np.int64)


def _seed(seed):
    """``seed`` as ``np.random.default_rng`` takes it: None, a Generator, BitGenerator or SeedSequence as given, a
    whole number >= 0 (or a list of them) checked; text, 1.5, NaN and negative numbers refused."""
    if seed is None or isinstance(seed, (np.random.Generator, np.random.BitGenerator, np.random.SeedSequence)):
        return seed
    if isinstance(seed, (list, tuple, np.ndarray)):   # entropy words, e.g. [1, 2]
        try:
            arr = np.asarray(seed)
        except (TypeError, ValueError):   # ragged
            arr = np.zeros(0)
        if arr.ndim == 1 and arr.dtype.kind in "iu" and arr.size and bool(np.all(arr >= 0)):
            return seed
    return whole_number(seed, "seed", lo=0)


def subsample(events: Events, max_points: int, seed: int = 0) -> Events:
    """At most ``max_points`` events, chosen uniformly at random (seeded), still in time order."""
    return require(events, Events, "events").take(subsample_index(len(events), max_points, seed))


def _window(events: Events, t0, t1) -> Events:
    """Events with t0 < t <= t1; None means from the first / to the last event (inf and -inf are open ends)."""
    t0, t1 = _open_end(t0, "t0"), _open_end(t1, "t1")
    lo = 0 if t0 is None else int(np.searchsorted(events.t, t0, side="right"))
    hi = len(events) if t1 is None else int(np.searchsorted(events.t, t1, side="right"))
    if t0 is not None and t1 is not None and not t1 > t0:
        raise EventDataError(f"time window ({t0}, {t1}] is empty or reversed; t1 must exceed t0")
    return events.take(slice(lo, max(lo, hi)))


def _open_end(t, name: str):
    """``t`` (seconds) as given when None or infinite (an open end, as before), else a finite float; NaN and text
    are refused naming ``name``."""
    if t is None or (is_real_number(t) and np.isinf(float(host_array(t)))):
        return t
    return optional_seconds(t, name)


def count_map(events: Events, polarity: int | None = None) -> np.ndarray:
    """Events per pixel: int64 [H, W]. ``polarity`` +1 or -1 counts only ON or only OFF events."""
    require(events, Events, "events")
    if polarity is not None and (not is_real_number(polarity) or polarity not in (1, -1)):   # True was +1
        raise EventDataError(f"polarity must be None (all), +1 (ON) or -1 (OFF), got {polarity!r}")
    H, W = events.sensor_size
    keep = slice(None) if polarity is None else events.p == polarity
    flat = events.y[keep].astype(np.int64) * W + events.x[keep]
    return np.bincount(flat, minlength=H * W).reshape(H, W)


def polarity_image(events: Events, t0: float | None = None, t1: float | None = None,
                   background=(1.0, 1.0, 1.0)) -> np.ndarray:
    """The events of a time window as a colour image: float64 [H, W, 3] in [0, 1].

    A pixel is :data:`ON_RGB` (red) when the sum of the polarities of its events with
    ``t0 < t <= t1`` is positive, :data:`OFF_RGB` (blue) when it is negative, and
    ``background`` when it had no events (or as many ON as OFF). ``t0 = None`` starts at the
    first event (included), ``t1 = None`` ends at the last.
    """
    win = _window(require(events, Events, "events"), t0, t1)
    colour = _colour(background, "background")
    net = count_map(win, 1) - count_map(win, -1)
    img = np.empty(net.shape + (3,))
    img[:] = colour
    img[net > 0] = ON_RGB
    img[net < 0] = OFF_RGB
    return img


def _colour(value, name: str) -> np.ndarray:
    """An RGB colour: 3 finite numbers in [0, 1] (one number is that grey), as float64 [3] or a 0-d grey."""
    try:
        arr = None if isinstance(value, (str, bytes)) or value is None else np.asarray(host_array(value))
    except (TypeError, ValueError):
        arr = None
    ok = (arr is not None and arr.dtype.kind in "iuf" and arr.shape in ((), (3,)) and bool(np.all(np.isfinite(arr)))
          and bool(np.all((arr >= 0) & (arr <= 1))))
    if not ok:
        raise EventDataError(f"{name}= must be a colour: (r, g, b) in [0, 1] (or one grey level), got {value!r}; "
                             "e.g. (1.0, 1.0, 1.0) for white (255 is 1.0 here)")
    return arr.astype(np.float64)


def plot_xyt(events: Events, ax=None, max_points: int = 5000, seed: int = 0, size: float = 1.0,
             title: str | None = None, view=(55, -110)):
    """The events as points in (t, x, y) space: ON red, OFF blue.

    At most ``max_points`` events are drawn, a seeded random subset (see :func:`subsample`).
    Time runs along the long horizontal axis, x (column) along the other, and y (row) is
    vertical, pointing down as in an image. ``ax`` must be a 3-D axes (``projection='3d'``)
    if given; ``view`` is the (elevation, azimuth) in degrees, or (elevation, azimuth, roll).
    """
    require(events, Events, "events")
    size = real_number(size, "size", lo=0, hint="the points' area in points^2 (e.g. 1.0)")
    if isinstance(view, (str, bytes)) or not (np.ndim(view) == 1 and np.size(view) in (2, 3) and
                                               all(is_real_number(v) and np.isfinite(float(v)) for v in view)):
        raise EventDataError(f"view= must be (elevation, azimuth) or (elevation, azimuth, roll), finite angles in "
                             f"degrees, got {view!r}")
    if len(events) == 0:   # empty 3-D axes titled "0 of 0 events"
        raise EventDataError("plot_xyt: no events to draw; pick a time window or a recording that holds some")
    sub = subsample(events, max_points, seed)
    ax = axes_or_new(ax, (7, 5), projection="3d")   # a 2-D Axes, a Figure or an array failed inside matplotlib
    for sign, color, name in ((1, ON_COLOR, "ON"), (-1, OFF_COLOR, "OFF")):
        sel = sub.p == sign
        ax.scatter(sub.t[sel], sub.x[sel], sub.y[sel], s=size, c=color, depthshade=False,
                   label=f"{name} ({int(sel.sum())} shown)")
    H, W = events.sensor_size
    ax.set(xlabel="t (s)", ylabel="x (column)", zlabel="y (row)", ylim=(0, W - 1), zlim=(H - 1, 0))
    ax.set_box_aspect((1.6, 1.0, 0.8))
    ax.view_init(*view)
    ax.set_title(title or f"{len(sub)} of {len(events)} events")
    ax.legend(loc="upper left", fontsize=9, markerscale=4)
    return ax


def plot_count_map(events: Events, ax=None, polarity: int | None = None, title: str | None = None):
    """Events per pixel as an image (with a colour bar)."""
    counts = count_map(events, polarity)   # checked before a figure is made
    ax = _axes(ax)
    im = ax.imshow(counts, cmap="magma", interpolation="nearest")
    ax.figure.colorbar(im, ax=ax, fraction=0.046, pad=0.04, label="events")
    which = {None: "", 1: "ON ", -1: "OFF "}[polarity]
    ax.set_title(title or f"{which}events per pixel (max {counts.max()})")
    ax.set_xticks([]), ax.set_yticks([])
    return ax


def plot_polarity(events: Events, t0: float | None = None, t1: float | None = None, ax=None,
                  title: str | None = None):
    """:func:`polarity_image` of the window ``(t0, t1]``, titled with the window and its event count."""
    if len(events) == 0 and title is None and (t0 is None or t1 is None):   # the title read events.t[0]
        raise EventDataError("plot_polarity: no events, so no window to title; pass t0 and t1 (seconds) for an "
                             "empty image, or events that hold some")
    ax = _axes(ax, (4, 3))
    ax.imshow(polarity_image(events, t0, t1), interpolation="nearest")
    if title is None:
        n = len(_window(events, t0, t1))
        a = events.t[0] if t0 is None else t0
        b = events.t[-1] if t1 is None else t1
        title = f"({a:.3f}, {b:.3f}] s: {n} events"
    ax.set_title(title, fontsize=9)
    ax.set_xticks([]), ax.set_yticks([])
    return ax


def plot_event_rate(events: Events, bin_s: float, ax=None, t_range=None):
    """ON and OFF event rates (events/s, whole sensor) over time, as steps; see :func:`event_rate`."""
    ax = _axes(ax, (8, 3))
    edges, on, off = event_rate(events, bin_s, t_range)
    ax.stairs(on, edges, color=ON_COLOR, label="ON")
    ax.stairs(off, edges, color=OFF_COLOR, label="OFF")
    ax.set(xlabel="time t (s)", ylabel="events / s", title=f"event rate in bins of {bin_s * 1e3:.3g} ms")
    ax.legend(fontsize=9)
    return ax


def plot_boundaries(events: Events, boundaries: dict, ax=None, max_points: int = 4000):
    """Cumulative event count over time, with sets of bin boundaries as vertical lines.

    Args:
        events: the events.
        boundaries: ``{label: edges [B + 1]}``; set k is drawn in the k-th horizontal band of
            the axes, so several sets can be compared on one figure.
        max_points: points of the cumulative curve drawn (evenly spaced in event index).

    Between two boundaries of an equal-count set the curve rises by the same amount; between
    two boundaries of a fixed-duration set the lines are evenly spaced.
    """
    if not boundaries:   # the cumulative curve alone, with an empty legend entry for the sets
        raise ValueError("boundaries is empty: pass {label: edges [B + 1]}, e.g. {'fixed': frames.boundaries}")
    if len(events) == 0:  # empty axes: no curve to compare the boundaries with
        raise EventDataError("plot_boundaries: no events, so no cumulative count to draw; pass events that hold some")
    ax = _axes(ax, (9, 3.5))
    n = len(events)
    k = np.unique(np.linspace(0, n - 1, min(n, max_points)).round().astype(np.int64))
    ax.plot(events.t[k], k + 1, color="black", lw=1.2, label="events so far")
    trans = blended_transform_factory(ax.transData, ax.transAxes)
    m = max(len(boundaries), 1)
    for j, (label, b) in enumerate(boundaries.items()):
        b = np.asarray(b)
        ax.vlines(b, j / m, (j + 1) / m, transform=trans, colors=f"C{j}", lw=1.0,
                  label=f"{label}: {b.size - 1} bins")
    ax.set(xlabel="time t (s)", ylabel="cumulative number of events")
    ax.legend(fontsize=9, loc="upper left")
    return ax


def show_event_frames(frames: EventFrames, indices=None, max_frames: int = 8, ncols: int = 4,
                      vmax: float | None = None, title: str | None = None, panel_size: float = 2.2):
    """A grid of event frames (Eq. 2), red positive, blue negative, on one shared symmetric scale.

    Args:
        frames: :class:`~evinr_lite.method.binning.EventFrames`.
        indices: which bins to show; default ``max_frames`` bins evenly spread over all of them.
        ncols: panels per row.
        vmax: colour scale limit (log units); default the largest |value| shown (0, blank frames: 1.0).
        title: figure title.

    Returns:
        The figure; each panel's title gives the bin's interval in ms and its event count.
    """
    if not isinstance(frames, EventFrames):   # None was "object of type 'NoneType' has no len()"
        raise ArgumentTypeError(f"frames must be EventFrames, got {type(frames).__name__}; make them with "
                                "events_to_frames(events, boundaries, C) (evinr_lite.method.binning) first")
    B = len(frames)
    # the counts, sizes and scale by name before the figure is made (None, text and 2.5 were Python's or numpy's
    # errors, ncols 0 a ZeroDivisionError, -1 or a NaN panel_size matplotlib's "figure size must be positive",
    # indices of a number "not iterable", 7 for 4 bins an IndexError, a NaN vmax a blank colour scale)
    max_frames = whole_number(max_frames, "max_frames", lo=1)
    ncols = whole_number(ncols, "ncols", lo=1)
    panel_size = real_number(panel_size, "panel_size", lo=0, hi=MAX_FIGSIZE, lo_open=True,
                             hint="inches per panel")
    if vmax is not None:   # 0 (the largest |value| of blank frames) falls back to 1.0, as the default does
        vmax = real_number(vmax, "vmax", lo=0, hint="the colour scale's limit in log units (None: the largest "
                                                    "|value| shown)") or 1.0
    if indices is None:
        indices = np.unique(np.linspace(0, B - 1, min(B, max_frames)).round().astype(int))
    elif isinstance(indices, (str, bytes)) or is_real_number(indices) or np.ndim(host_array(indices)) != 1:
        raise EventDataError(f"indices= must be a list of bin indices (e.g. [0, 2, 5]) or None, got "
                             f"{type(indices).__name__} {indices!r}"[:200])
    indices = [whole_number(i, "indices[]", lo=-B, hi=B - 1) for i in indices]
    if not indices:
        raise EventDataError("no event frames to show")
    shown = frames.frames[indices]
    if vmax is None:
        vmax = float(np.abs(shown).max()) or 1.0
    ncols = min(ncols, len(indices))
    nrows = -(-len(indices) // ncols)
    H, W = frames.frames.shape[1:]
    fig, axes = plt.subplots(nrows, ncols, figsize=(panel_size * ncols * max(W / H, 0.5) + 0.8,
                                                    panel_size * nrows + 0.4), squeeze=False)
    b = frames.boundaries
    for ax, i in zip(axes.flat, indices):
        im = ax.imshow(frames.frames[i], cmap=EVENT_FRAME_CMAP, vmin=-vmax, vmax=vmax, interpolation="nearest")
        ax.set_title(f"bin {i}: ({b[i] * 1e3:.1f}, {b[i + 1] * 1e3:.1f}] ms\n{frames.counts[i]} events", fontsize=9)
    for ax in axes.flat:
        ax.set_xticks([]), ax.set_yticks([])
    for ax in axes.flat[len(indices):]:
        ax.axis("off")
    fig.colorbar(im, ax=axes, fraction=0.03, pad=0.02, label="C x (sum of p)")
    if title:
        fig.suptitle(title)
    return fig


def animate_events(events: Events, n_frames: int = 20, window_s: float | None = None, t_range=None,
                   figsize=(4, 3), dpi: int = 72, interval: int = 100) -> FuncAnimation:
    """An animation of polarity images sliding through time.

    Frame k shows :func:`polarity_image` of the window ``(t_k - window_s, t_k]``, with the end
    times ``t_k`` evenly spaced so that the last frame ends at ``t_range[1]``.

    Args:
        events: the events.
        n_frames: number of frames (each is one PNG in the HTML: keep it small).
        window_s: window length (s); default ``(t1 - t0) / n_frames`` (consecutive windows).
        t_range: (t0, t1) seconds; default the first and last event times.
        figsize, dpi: size of each frame (dpi >= 10; at most 2**27 pixels a frame). interval: milliseconds
            between frames when played (> 0: ``to_jshtml`` and ``save`` play 1000 / interval frames a second).

    Returns:
        A ``FuncAnimation``; show it in a notebook with
        ``IPython.display.HTML(anim.to_jshtml())``. Its figure is already closed, so inline
        back ends show no extra static copy. ``anim.windows`` is float64 [n_frames, 2] (the
        windows) and ``anim.draw_frame(k)`` draws frame k.
    """
    # every argument by name before the figure is made (events None were "has no len()", n_frames None or 2.5
    # Python's or numpy's errors, a t_range of one number "not subscriptable", [] an IndexError, a NaN window
    # NaN frames, a dpi of 0, 2.5 or True matplotlib's or FreeType's errors when drawn, interval text too)
    require(events, Events, "events")
    n_frames = whole_number(n_frames, "n_frames", lo=1)
    if t_range is None:
        if len(events) < 2:
            raise EventDataError("animate_events needs t_range when there are fewer than 2 events")
        t0, t1 = float(events.t[0]), float(events.t[-1])
    else:
        if isinstance(t_range, (str, bytes)) or is_real_number(t_range) or np.shape(host_array(t_range)) != (2,):
            raise EventDataError(f"t_range= must be (t0, t1) seconds or None (the first and last event), got "
                                 f"{t_range!r}"[:200])
        t0, t1 = checked_span(t_range[0], t_range[1], "t_range")
    window = (t1 - t0) / n_frames if window_s is None else \
        real_number(window_s, "window_s", lo=0, lo_open=True, hint="seconds (None: consecutive windows)")
    if not window > 0:
        raise EventDataError(f"window_s must be positive seconds, got {window_s}")
    dpi = real_number(dpi, "dpi", lo=MIN_DPI, hint="dots per inch (e.g. 72)") if dpi is not None else None
    # interval > 0: matplotlib takes 0, but to_jshtml() and save() divide by it (fps = 1000 / interval)
    interval = real_number(interval, "interval", lo=0, lo_open=True, hint="milliseconds between frames") \
        if interval is not None else interval
    figsize = check_figsize(figsize)
    w, h = (plt.rcParams["figure.figsize"] if figsize is None else figsize)
    pixels = float(w) * float(h) * (plt.rcParams["figure.dpi"] if dpi is None else dpi) ** 2
    if pixels > MAX_FRAME_PIXELS:   # no cap on dpi alone: what runs out is the memory of one frame's image
        raise EventDataError(f"figsize={figsize!r} at dpi={dpi!r} makes frames of {pixels:.3g} pixels, over "
                             f"{MAX_FRAME_PIXELS:.3g} (2**27, 512 MiB of RGBA per frame); lower dpi= or figsize=")
    ends = t0 + window + (t1 - t0 - window) * np.linspace(0, 1, n_frames) if n_frames > 1 else np.array([t1])
    windows = np.stack([ends - window, ends], axis=1)

    fig, ax = plt.subplots(figsize=figsize, dpi=dpi)
    plt.close(fig)
    image = ax.imshow(polarity_image(events, *windows[0]), interpolation="nearest")
    ax.set_xticks([]), ax.set_yticks([])
    title = ax.set_title("", fontsize=9)

    def draw_frame(k):
        a, b = windows[k]
        image.set_data(polarity_image(events, a, b))
        title.set_text(f"events in ({a:.3f}, {b:.3f}] s")
        return image, title

    draw_frame(0)
    fig.tight_layout()
    anim = FuncAnimation(fig, draw_frame, frames=n_frames, interval=interval, blit=False)
    anim.windows = windows
    anim.draw_frame = draw_frame
    return anim
