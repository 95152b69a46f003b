"""How long the background filter's window should be, chosen from the events' own share of noise.

The background-activity filter (:func:`~evinr_lite.method.denoise.correlation_filter`, two-sided, same
polarity) keeps an event when one of its 8 neighbouring pixels fired an event of the same polarity within
``dt`` of it. A short ``dt`` removes more noise and more signal: a texture moving at v px/s takes about
1 / v seconds to reach the next pixel, so on a slow or sparse recording a 50 ms window drops real events
(10 % of a slow pan's, fresh17_08_pan_gravel), and a recording without background activity only loses by
it. Which ``dt`` is right depends on how much of the recording is noise, and the events say that.

**The noise share.** Background activity fires at random pixels and times, so a noise event is kept
exactly as often as a *probe*, a random (pixel, time, polarity), would be: with probability P(dt), the
share of random probes that find a same-polarity neighbour within dt among the real events (computed, not
assumed). A signal event has a neighbour within a long enough window (an edge reaches the next pixel).
So with K(dt) the share of the events kept, and n the noise share,

    K(dt) = (1 - n) S(dt) + n P(dt),   S(dt) -> 1 for long dt,   so   n <= (1 - K(dt)) / (1 - P(dt)),

with equality once S(dt) = 1. ``n`` is the smallest of these bounds over the windows of :data:`GRID` that
leave the probes room (1 - P >= :data:`MIN_ROOM`, so the ratio is not a small difference over a small
difference). On the zoo's, the held-out, stress and fresh scenes it reads the injected noise share to
within a few per cent of the events (fresh17_15_shake_moon 0.439 for 0.445, fresh17_01 0.176 for 0.170,
noisy_gravel 0.072 for 0.066, clean scenes 0.000-0.015).

**The window.** Each ``dt`` keeps (1 - n) S(dt) signal events and n P(dt) noise events (shares of all
events): the choice keeps the most signal net of the noise it lets through, a kept noise event costing
as much as :data:`NOISE_COST` lost signal events,

    dt = argmax over GRID and "keep" of   (1 - n) S(dt) - NOISE_COST n P(dt)
       = argmax                            K(dt) - (1 + NOISE_COST) n P(dt)      ("keep": K = P = 1).

A noisy recording keeps 50 ms; a clean one keeps (nearly) everything. NOISE_COST from 1 to 3 ties on the
zoo's short scenes, the held-out and the stress sets; 2 keeps 50 ms on the 20 s noisy pan, where the
noise share read is 0.13 (the slow pan's signal is not all kept even at 0.4 s, so the bound is loose)
and 0.1 s loses to 50 ms (docs/defaults.md, "The background filter's window", has the sweep and its
command).

**What is measured.** Spans up to :data:`WHOLE_SPAN` seconds are measured whole; a longer one on
:data:`SLICES` slices of :data:`SLICE_S` seconds spread over it (queries only inside each slice's
interior, :data:`MARGIN` from its edges, so every neighbour within the longest window is read). At most
:data:`N_QUERY` events and as many probes, drawn with ``seed``, on the sensor's centre (at most
:data:`CROP_PX` pixels along each side): the result is deterministic and costs one sort of the sampled
spans' events there, whatever the recording's length and size. :func:`~evinr_lite.method.prepare.prepare_events`
and :func:`~evinr_lite.method.prepare.prepare_source` read the same slices, so a recording gets the same
window in memory and streamed.

**Where the events are.** The centre and the evenly spread slices stand for the whole recording when they
hold events; where they hold fewer than :data:`MIN_EVENTS` (a scene off the centre of a large sensor, a
long span whose activity is at its start and end) the statistics move to the events: the
:data:`CROP_PX`-square window holding the most of the sampled events (:func:`fit_background`), and the
:data:`SLICES` :data:`SLICE_S`-second tiles of the span holding the most events (:func:`tile_counts`,
:func:`busy_spans`; both paths count them on the same tiles). Only with fewer than :data:`MIN_EVENTS`
events there too is the fixed window kept. A sensor of one pixel has no neighbours: no filter.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.checks import checked_span, seconds_array, whole_number
from ..core.events import EventDataError, Events
from .denoise import DEFAULT_DT

__all__ = ["GRID", "MIN_ROOM", "N_QUERY", "WHOLE_SPAN", "SLICES", "SLICE_S", "MARGIN", "MIN_EVENTS", "CROP_PX", "NOISE_COST",
           "MAX_TILES", "BackgroundFit", "neighbour_gaps", "sample_spans", "tile_counts", "busy_spans",
           "fit_background"]

GRID = (0.05, 0.1, 0.2, 0.4)   # s: the filter's windows tried (50 ms: the fixed default before; 0.4 s keeps ~all signal)
MIN_ROOM = 0.1                 # a window estimates the noise share only where >= 10 % of the probes find no neighbour
N_QUERY = 100_000              # events (and probes) sampled for the statistics: +-0.3 % on each share
WHOLE_SPAN = 8.0               # s: spans up to this are measured whole
SLICES = 4                     # a longer span: this many slices, spread evenly over it
SLICE_S = 2.0                  # s: each slice's interior (queries); read MARGIN beyond on both sides
MARGIN = max(GRID)             # s: so a query's neighbours within the longest window are all read
MIN_EVENTS = 200               # fewer events measured: too few to tell noise from signal; the fixed DEFAULT_DT
NOISE_COST = 2.0               # a noise event kept costs as much as this many signal events lost (1-3 tie on the short sets)
CROP_PX = 256                  # px: a larger sensor is measured on its centre (the sort's cost; noise is everywhere alike)
MAX_TILES = 1 << 16            # tiles of a span counted at most (longer tiles beyond 36 hours of SLICE_S ones)


@dataclass(frozen=True)
class BackgroundFit:
    """What :func:`fit_background` measured and chose.

    Attributes:
        dt: the filter's window (s), or None: keep every event.
        noise_share: the estimated share of the events that are background activity, in [0, 1].
        grid: the windows tried (s). kept: [len(grid)] the share of the sampled events that the filter keeps
        at each. probe_kept: [len(grid)] the share of random probes that it would keep (a noise event's chance).
        n_events: the events the statistics were measured on (all of them in the sampled spans).
    """
    dt: float | None
    noise_share: float
    grid: tuple
    kept: tuple
    probe_kept: tuple
    n_events: int


class _Neighbours:
    """The events sorted by (pixel, polarity) and, within each, by time (they arrive time-sorted): built once,
    searched for any number of queries (:func:`neighbour_gaps`)."""

    def __init__(self, events: Events):
        self.H, self.W = events.sensor_size
        key = ((events.y.astype(np.int64) * self.W + events.x) * 2 + (events.p > 0)).astype(np.int32)
        order = np.argsort(key, kind="stable")        # int32 keys: numpy's fastest stable sort
        self.key, self.t = key[order].astype(np.int64), events.t[order]
        self.t0 = float(self.t.min()) if len(self.t) else 0.0
        self.span = (float(self.t.max()) - self.t0 + 1.0) if len(self.t) else 1.0
        self.flat = self.key * self.span + (self.t - self.t0)   # (key, t) as one sorted float

    def gaps(self, t, x, y, p) -> np.ndarray:
        t = np.asarray(t, np.float64)
        x, y = np.asarray(x, np.int64), np.asarray(y, np.int64)
        on = (np.asarray(p) > 0).astype(np.int64)
        best = np.full(t.shape, np.inf)
        last = len(self.t) - 1
        if last < 0 or not t.size:
            return best
        # the queries in (pixel, time) order, so each search walks the sorted events forwards (cache-friendly)
        order = np.lexsort((t, y * self.W + x))
        t, x, y, on = t[order], x[order], y[order], on[order]
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                if dx == 0 and dy == 0:
                    continue
                nx, ny = x + dx, y + dy
                inside = (nx >= 0) & (nx < self.W) & (ny >= 0) & (ny < self.H)
                nkey = (ny * self.W + nx) * 2 + on
                pos = np.searchsorted(self.flat, nkey * self.span + (t - self.t0))
                for c in (pos - 1, pos):          # the neighbour's events just before and just after t
                    cc = np.clip(c, 0, last)
                    ok = inside & (c >= 0) & (c <= last) & (self.key[cc] == nkey)
                    best = np.minimum(best, np.where(ok, np.abs(self.t[cc] - t), np.inf))
        out = np.empty_like(best)
        out[order] = best
        return out


def neighbour_gaps(events: Events, t, x, y, p) -> np.ndarray:
    """For each query (time t (s), column x, row y, polarity p), float64 [Q]: the smallest |t_j - t| over
    the events j of the same polarity (p > 0 is ON) at one of the query's 8 neighbouring pixels (not its own
    pixel); inf where there is none. The filter of :func:`~evinr_lite.method.denoise.correlation_filter`
    with ``window="both"``, ``same_polarity=True`` keeps an event exactly when its gap is <= dt (up to the
    rounding of t_j + dt).

    t, x, y, p: numbers or 1-D arrays of one length (a single number stands for every query): finite
    seconds, whole pixel coordinates on the events' sensor, polarities -1/0/+1. Anything else is refused
    (EventDataError) naming the argument."""
    if not isinstance(events, Events):
        raise EventDataError(f"neighbour_gaps: events must be Events, got {type(events).__name__}")
    return _Neighbours(events).gaps(*_queries(events.sensor_size, t, x, y, p))


def _queries(sensor_size, t, x, y, p) -> tuple:
    """(t, x, y, p) of :func:`neighbour_gaps` checked and broadcast to one length."""
    H, W = sensor_size
    try:
        t = seconds_array(t, "t", allow_empty=True)   # no queries: no gaps (a mask that selects nothing)
    except EventDataError as e:
        raise EventDataError(f"neighbour_gaps: {e}") from None
    cols = {}
    for name, value, hi in (("x", x, W - 1), ("y", y, H - 1), ("p", p, 1)):
        a = np.atleast_1d(np.asarray(value))
        if a.dtype == bool or a.dtype.kind not in "iuf" or a.ndim != 1:
            raise EventDataError(f"neighbour_gaps: {name} must be a whole number or a 1-D array of them, got "
                                 f"{a.dtype} of shape {a.shape}")
        lo = -1 if name == "p" else 0
        if a.size and not (np.all(np.isfinite(a)) and np.all(a == np.round(a)) and a.min() >= lo and a.max() <= hi):
            what = ("polarities -1, 0 or +1" if name == "p" else
                    f"whole pixel coordinates in [0, {hi}] (the sensor is {H} x {W})")
            raise EventDataError(f"neighbour_gaps: {name} must hold {what}, got values in [{a.min()}, {a.max()}]")
        cols[name] = a.astype(np.int64)
    sizes = {len(a) for a in (t, *cols.values())} - {1}
    if len(sizes) > 1:
        raise EventDataError(f"neighbour_gaps: t, x, y and p must have one length (or be single numbers), got "
                             f"{len(t)}, {len(cols['x'])}, {len(cols['y'])} and {len(cols['p'])}")
    return tuple(np.broadcast_arrays(t, cols["x"], cols["y"], cols["p"]))


def _crop(sensor_size) -> tuple:
    """(y0, y1, x0, x1): the sensor's centre, at most :data:`CROP_PX` pixels along each side, where the
    statistics are measured (the whole sensor up to that size)."""
    H, W = sensor_size
    h, w = min(H, CROP_PX), min(W, CROP_PX)
    y0, x0 = (H - h) // 2, (W - w) // 2
    return y0, y0 + h, x0, x0 + w


def _busiest_crop(samples, sensor_size) -> tuple:
    """(y0, y1, x0, x1): the window of :func:`_crop`'s size holding the most of the samples' measured events
    (the first such, row by row: deterministic)."""
    H, W = sensor_size
    y0, y1, x0, x1 = _crop(sensor_size)
    h, w = y1 - y0, x1 - x0
    n = np.zeros(H * W, np.int64)
    for ev, (a, b) in samples:
        q = (ev.t >= a) & (ev.t <= b)
        n += np.bincount(ev.y[q].astype(np.int64) * W + ev.x[q], minlength=H * W)
    s = np.zeros((H + 1, W + 1), np.int64)
    s[1:, 1:] = n.reshape(H, W).cumsum(0).cumsum(1)
    sums = s[h:, w:] - s[:-h, w:] - s[h:, :-w] + s[:-h, :-w]      # [H - h + 1, W - w + 1]: by top-left corner
    i, j = np.unravel_index(int(np.argmax(sums)), sums.shape)
    return int(i), int(i) + h, int(j), int(j) + w


def sample_spans(t_start: float, t_end: float) -> list:
    """The spans the statistics are measured on: [(read_from, read_to, query_from, query_to)] (s). The whole
    span when it is at most :data:`WHOLE_SPAN` long; else :data:`SLICES` slices with a :data:`SLICE_S`
    interior, centred at (i + 1/2) / SLICES of it, read :data:`MARGIN` beyond the interior. ``t_start`` and
    ``t_end``: finite seconds, t_end >= t_start."""
    t_start, t_end = checked_span(t_start, t_end, "sample_spans")
    if t_end - t_start <= WHOLE_SPAN:
        return [(t_start, t_end, t_start, t_end)]
    out = []
    for i in range(SLICES):
        c = t_start + (i + 0.5) * (t_end - t_start) / SLICES
        a, b = c - SLICE_S / 2, c + SLICE_S / 2
        out.append((max(t_start, a - MARGIN), min(t_end, b + MARGIN), a, b))
    return out


def _tile(t_start: float, t_end: float) -> tuple:
    """(tile length (s), number of tiles) of the span: :data:`SLICE_S`, or longer beyond :data:`MAX_TILES`."""
    length = max(SLICE_S, (t_end - t_start) / MAX_TILES)
    return length, max(1, int(np.ceil((t_end - t_start) / length)))


def tile_counts(t, t_start: float, t_end: float) -> np.ndarray:
    """int64 [K]: how many of the times ``t`` (s) fall in each tile of [t_start, t_end], tiles of
    :data:`SLICE_S` seconds from t_start (the last one shorter, holding the span's end; longer tiles when the
    span would need more than :data:`MAX_TILES`). Times outside the span are not counted. Counts of the
    span's events in chunks add up to those of all of them at once (the streamed and in-memory paths)."""
    t_start, t_end = checked_span(t_start, t_end, "tile_counts")
    length, k = _tile(t_start, t_end)
    t = np.asarray(t, np.float64)
    t = t[(t >= t_start) & (t <= t_end)]
    return np.bincount(np.minimum(((t - t_start) / length).astype(np.int64), k - 1), minlength=k)


def busy_spans(t_start: float, t_end: float, tiles) -> list:
    """:func:`sample_spans`' form for the :data:`SLICES` tiles (of :func:`tile_counts`) that hold the most
    events, in time order (ties: the earlier tile), tiles without events left out; read :data:`MARGIN`
    beyond each. Where the evenly spread slices of a long span miss its events."""
    t_start, t_end = checked_span(t_start, t_end, "busy_spans")
    length, k = _tile(t_start, t_end)
    tiles = np.asarray(tiles)
    if tiles.shape != (k,):
        raise EventDataError(f"busy_spans: tiles must be tile_counts(t, {t_start}, {t_end}) ({k} counts), got shape "
                             f"{tiles.shape}")
    best = np.argsort(-tiles, kind="stable")[:SLICES]
    out = []
    for i in sorted(int(i) for i in best if tiles[i] > 0):
        a, b = t_start + i * length, min(t_end, t_start + (i + 1) * length)
        out.append((max(t_start, a - MARGIN), min(t_end, b + MARGIN), a, b))
    return out


def _samples(samples) -> list:
    """``samples`` of :func:`fit_background` checked: [(Events, (a, b))], one sensor, finite a <= b."""
    form = ("[(events, (query_from, query_to)), ...]: the events read over each span of sample_spans and the "
            "interval measured, e.g. fit_background([(events, (events.t[0], events.t[-1]))])")
    if isinstance(samples, Events) or not isinstance(samples, (list, tuple)):
        raise EventDataError(f"fit_background: samples must be a list {form}; got {type(samples).__name__}")
    out = []
    for i, item in enumerate(samples):
        if not (isinstance(item, (list, tuple)) and len(item) == 2 and isinstance(item[0], Events)
                and isinstance(item[1], (list, tuple, np.ndarray)) and len(item[1]) == 2):
            raise EventDataError(f"fit_background: samples[{i}] must be (events, (query_from, query_to)); samples is "
                                 f"a list {form}")
        a, b = checked_span(*item[1], f"fit_background: samples[{i}]")
        if out and tuple(item[0].sensor_size) != tuple(out[0][0].sensor_size):
            raise EventDataError(f"fit_background: samples[{i}] is of sensor {tuple(item[0].sensor_size)}, samples[0] "
                                 f"of {tuple(out[0][0].sensor_size)}: the spans of one recording share its sensor")
        out.append((item[0], (a, b)))
    return out


def _measured(samples, crop) -> tuple:
    """([(events in the crop and a ring of one pixel around it, (a, b), crop)], [indices of the measured
    events: those inside the crop and the interval]) for each sample."""
    cropped, inner = [], []
    for ev, (a, b) in samples:
        y0, y1, x0, x1 = crop
        # the crop's events with a ring of one pixel around it (the neighbours of its edge pixels)
        ring = (ev.y >= y0 - 1) & (ev.y <= y1) & (ev.x >= x0 - 1) & (ev.x <= x1)
        ev = ev.take(np.flatnonzero(ring))
        q = (ev.t >= a) & (ev.t <= b) & (ev.y >= y0) & (ev.y < y1) & (ev.x >= x0) & (ev.x < x1)
        cropped.append((ev, (float(a), float(b)), (y0, y1, x0, x1)))
        inner.append(np.flatnonzero(q))
    return cropped, inner


def fit_background(samples, seed: int = 0) -> BackgroundFit:
    """The filter's window for a recording, from ``samples``: [(events, (query_from, query_to))], the
    events read over each span of :func:`sample_spans` (hot pixels already dropped) and the interval (s)
    whose events and probes are measured. See the module's docstring for the rule.

    The centre's :data:`CROP_PX` square is measured; where it holds fewer than :data:`MIN_EVENTS` of the
    events to measure, the square holding the most of them. With fewer than :data:`MIN_EVENTS` there too, the
    fixed ``DEFAULT_DT`` (the filter as before); on a sensor of one pixel (no neighbours), no filter.
    ``seed``: the sampling of events and probes (deterministic), a whole number >= 0."""
    samples = _samples(samples)
    rng = np.random.default_rng(whole_number(seed, "fit_background: seed", lo=0))
    nothing = (float("nan"),) * len(GRID)
    size = tuple(samples[0][0].sensor_size) if samples else None
    if size == (1, 1):                                # one pixel: no neighbours to find, nothing to filter by
        return BackgroundFit(None, nothing[0], GRID, nothing, nothing, 0)
    cropped, inner = _measured(samples, _crop(size) if samples else None)
    n_events = int(sum(len(i) for i in inner))
    if samples and n_events < MIN_EVENTS and _crop(size) != (0, size[0], 0, size[1]):
        # the centre of a larger sensor holds (almost) none of the events: measure where they are
        cropped, inner = _measured(samples, _busiest_crop(samples, size))
        n_events = int(sum(len(i) for i in inner))
    if n_events < MIN_EVENTS:
        return BackgroundFit(DEFAULT_DT, nothing[0], GRID, nothing, nothing, n_events)
    per = max(1, N_QUERY // len(samples))
    gaps_ev, gaps_pr = [], []
    for (ev, (a, b), (y0, y1, x0, x1)), idx in zip(cropped, inner):
        if len(idx) > per:
            idx = np.sort(rng.choice(idx, per, replace=False))
        near = _Neighbours(ev)
        gaps_ev.append(near.gaps(ev.t[idx], ev.x[idx], ev.y[idx], ev.p[idx]))
        gaps_pr.append(near.gaps(rng.uniform(a, b, per), rng.integers(x0, x1, per), rng.integers(y0, y1, per),
                                 rng.integers(0, 2, per)))
    g_ev, g_pr = np.concatenate(gaps_ev), np.concatenate(gaps_pr)
    kept = np.array([np.mean(g_ev <= d) for d in GRID])
    probe = np.array([np.mean(g_pr <= d) for d in GRID])
    room = 1.0 - probe
    bounds = (1.0 - kept) / np.maximum(room, 1e-12)
    usable = room >= MIN_ROOM
    n = float(np.clip(bounds[usable].min() if usable.any() else bounds[0], 0.0, 1.0))
    # signal kept minus NOISE_COST x noise kept (shares of all events); "keep": all of both
    score = np.append(kept - (1 + NOISE_COST) * n * probe, 1.0 - (1 + NOISE_COST) * n)
    best = int(np.argmax(score))
    return BackgroundFit(GRID[best] if best < len(GRID) else None, n, GRID, tuple(kept.tolist()),
                         tuple(probe.tolist()), n_events)
