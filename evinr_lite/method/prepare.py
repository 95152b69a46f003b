"""The solver's step 0: what is done to the events, and to the config, before any training.

In this order, each judged on what the step before left (``EvINRConfig`` fields in brackets):

1. hot pixels dropped (``hot_pixels="drop"``): pixels whose count is far above the sensor's robust
   count (:func:`~evinr_lite.method.denoise.hot_pixel_mask`);
2. background activity filtered (``background="filter"``): events without an event of the same
   polarity at a neighbouring pixel within ``background_dt`` (50 ms by default) before or after them
   (:func:`~evinr_lite.method.denoise.correlation_filter`, two-sided and same polarity as
   :func:`~evinr_lite.method.denoise.denoise`'s defaults). ``background="auto"`` (the kit's) first chooses
   that window, or no filter, from the events' own share of noise
   (:func:`~evinr_lite.method.background.fit_background`, measured on the spans of
   :func:`~evinr_lite.method.background.sample_spans`) and the config says what it chose. Hot pixels go
   first: their events would otherwise keep their neighbours' noise;
3. the ON/OFF balance (``balance="events"``: C+ and C- from one nominal C,
   :mod:`~evinr_lite.method.balance`) and ``lam="auto"`` (:mod:`~evinr_lite.method.smoothing`),
   both from the per-pixel ON / OFF counts (and, for the balance, the intervals between events of one
   polarity) of the events that are left; pixels still hot on those counts are dropped too.

:func:`prepare_events` does this for events in memory (:func:`~evinr_lite.method.solver.reconstruct`),
:func:`prepare_source` for a recording read window by window
(:func:`~evinr_lite.method.streaming.stream_reconstruct`). The two see the same events: the stream
counts the span in chunks first (two reading passes when the background is filtered: the hot
pixels come from the raw counts, the balance from the filtered ones; with "auto" the sampled spans are
read in between), and reads each window with the filter's reach (:func:`reach`, clipped to the span)
beyond its edges, so an event near an edge is judged on the same neighbours as in the whole span. A
span no longer than one counting chunk (``cfg.tau``) is read once and prepared in memory, as
:func:`prepare_events` does, and its windows are slices of it.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..core.checks import ArgumentTypeError, checked_span, pixel_mask, real_number, require
from ..core.events import EventDataError, Events
from .balance import PolarityCounts, balance_from_counts, span_slices
from .background import MIN_EVENTS, WHOLE_SPAN, busy_spans, fit_background, sample_spans, tile_counts
from .denoise import DEFAULT_DT, check_count_pair, check_counts, denoise_mask, hot_pixel_mask, hot_threshold
from .smoothing import auto_lam, window_fraction
from .tempo import temporal_scale

__all__ = ["prepare_events", "prepare_source", "plan_from_counts", "drop_pixels", "filter_background",
           "choose_background", "reach", "BACKGROUND_MODES"]

BACKGROUND_MODES = ("keep", "filter", "auto")


def reach(dt: float) -> float:
    """Seconds read beyond a streamed window's edges for a filter of window ``dt`` (s, a positive finite
    number): twice it, so rounding never matters."""
    return 2 * real_number(dt, "reach: dt", lo=0, lo_open=True, hint="the background filter's window in seconds")


def choose_background(cfg, read, t_start: float, t_end: float, hot=None, tiles=None):
    """``cfg`` with ``background="auto"`` resolved (else unchanged): ``background="filter"`` with the
    ``background_dt`` that :func:`~evinr_lite.method.background.fit_background` chooses, or ``"keep"``.
    ``read(a, b)``: the events over [a, b) (s); ``hot``: bool [H, W] pixels to drop first, or None.
    ``tiles``: the span's :func:`~evinr_lite.method.background.tile_counts` (or a function giving them),
    for a long span whose evenly spread slices hold fewer than MIN_EVENTS events: then its busiest tiles
    are measured (:func:`~evinr_lite.method.background.busy_spans`). The span [t_start, t_end] must not be
    empty (every event at one instant): refused as the windows' plan refuses it."""
    if cfg.background != "auto":
        return cfg
    t_start, t_end = checked_span(t_start, t_end, "choose_background")
    if not t_end > t_start:   # read(t, t) would be refused as an empty window, blaming a window nobody gave
        raise EventDataError(f"time span [{t_start}, {t_end}] is empty; t_end must exceed t_start")

    def measure(spans):
        return fit_background([(drop_pixels(read(a, b), hot), (qa, qb)) for a, b, qa, qb in spans], cfg.seed)

    spans = sample_spans(t_start, t_end)
    fit = measure(spans)
    if fit.n_events < MIN_EVENTS and len(spans) > 1 and tiles is not None:   # the slices missed the events
        busy = busy_spans(t_start, t_end, tiles() if callable(tiles) else tiles)
        if busy and busy != spans:
            fit = measure(busy)
    return replace(cfg, background="keep") if fit.dt is None else replace(cfg, background="filter", background_dt=fit.dt)


def plan_from_counts(n_on, n_off, cfg, fraction: float = 1.0, intervals=None, sliced=None, flips=None,
                     span_s: float | None = None):
    """(cfg, hot): the config with C replaced by the estimated pair when ``cfg.balance`` is not "none" and
    C is one number (``intervals``: the span's :attr:`~evinr_lite.method.balance.PolarityCounts.intervals`,
    which the "events" rule needs; without them it falls back to the "counts" rule; ``sliced``: its
    :attr:`~evinr_lite.method.balance.PolarityCounts.sliced`, for the edges' estimate), ``lam="auto"``
    replaced by its value (:func:`~evinr_lite.method.smoothing.auto_lam`
    for windows covering ``fraction`` of the span), ``temporal_scale="auto"`` by its value
    (:func:`~evinr_lite.method.tempo.temporal_scale`, from ``flips``, the span's
    :attr:`~evinr_lite.method.balance.PolarityCounts.flips`, over ``span_s`` seconds; without them it stays
    "auto", which trains as 1), and the hot pixels to drop (bool [H, W], all False
    unless ``cfg.hot_pixels == "drop"``), from the span's per-pixel counts. The caller's config is not
    changed (a copy)."""
    # the config's fields, by name: method.config imports this module (None, a dict or a recipe's name was an
    # AttributeError on cfg.hot_pixels)
    if not all(hasattr(cfg, a) for a in ("hot_pixels", "balance", "C", "lam", "temporal_scale")):
        raise ArgumentTypeError(f"plan_from_counts: cfg= must be EvINRConfig, got {type(cfg).__name__}; e.g. "
                                "EvINRConfig() or EvINRConfig.paper()")
    n_on, n_off = check_count_pair(n_on, n_off, "plan_from_counts: ")   # the span's ON and OFF events per pixel
    if intervals is not None and (isinstance(intervals, (str, bytes)) or len(intervals) != 4):
        raise EventDataError("plan_from_counts: intervals must be four [H, W] arrays (log_on, k_on, log_off, k_off, "
                             "as interval_sums returns), or None")
    named = [("flips", flips)] + [(f"intervals[{i}]", a) for i, a in enumerate(() if intervals is None else intervals)]
    for name, a in named:
        if a is not None and np.shape(a) != n_on.shape:
            raise EventDataError(f"plan_from_counts: {name} has shape {np.shape(a)}, not the counts' {n_on.shape}")
    if flips is not None:
        flips = check_counts(flips, "plan_from_counts: flips")
    if span_s is not None:
        span_s = real_number(span_s, "plan_from_counts: span_s", lo=0, hint="the span's length in seconds")
    n = n_on + n_off
    hot = np.zeros(n.shape, bool)
    if cfg.hot_pixels == "drop":
        hot = _hot_mask(n)
    if cfg.balance != "none" and np.ndim(cfg.C) == 0:
        fit = balance_from_counts(np.where(hot, 0, n_on), np.where(hot, 0, n_off), cfg.C,
                                  intervals=None if intervals is None else [np.where(hot, 0, a) for a in intervals],
                                  sliced=sliced, rule="counts" if cfg.balance == "counts" else "consensus")
        if fit.applied:
            cfg = replace(cfg, C=fit.C)
    if cfg.lam == "auto":
        cfg = replace(cfg, lam=auto_lam(np.where(hot, 0, n_on), np.where(hot, 0, n_off), fraction))
    if cfg.temporal_scale == "auto" and flips is not None and span_s is not None and span_s > 0:
        cfg = replace(cfg, temporal_scale=temporal_scale(np.where(hot, 0, flips), np.where(hot, 0, n), span_s))
    return cfg, hot


def drop_pixels(events: Events, mask) -> Events:
    """The events without those of the pixels in ``mask`` (bool [H, W]; None or all False: unchanged)."""
    require(events, Events, "drop_pixels: events")
    if mask is None:
        return events
    # numbers were taken as event indices, another shape numpy's IndexError, a tensor numpy's any() error
    mask = pixel_mask(mask, events.sensor_size, "drop_pixels: mask", "build it with hot_pixel_mask(events)")
    if not mask.any():
        return events
    return events.take(~mask[events.y, events.x])


def filter_background(events: Events, dt: float) -> Events:
    """The events that :func:`~evinr_lite.method.denoise.denoise` keeps with its hot-pixel stage off and a
    window of ``dt`` seconds (the correlation filter: two-sided, same polarity)."""
    if len(events) == 0:
        return events
    return events.take(denoise_mask(events, hot_pixels=False, dt=dt)[0])


def _hot_mask(n: np.ndarray) -> np.ndarray:
    """Bool [H, W]: :func:`~evinr_lite.method.denoise.hot_pixel_mask`'s rule on per-pixel counts ``n``."""
    return n > hot_threshold(np.rint(n))


def _check_left(n_left: int, n_in: int, dt: float = DEFAULT_DT, sensor_size=None):
    """Refuse what the background filter (window ``dt`` s) left of ``n_in`` events when under 2."""
    if n_left < 2:
        why = ("a sensor of one pixel has no neighbouring pixels, so the filter drops every event" if
               sensor_size is not None and tuple(sensor_size) == (1, 1) else
               f"the recording is mostly isolated events (noise, or a scene too sparse for a {dt:g} s neighbourhood)")
        raise EventDataError(f"the background filter left {n_left} of {n_in:,} events (an event is kept when a "
                             f"neighbouring pixel fired one of its polarity within background_dt = {dt:g} s of it); "
                             f"{why}. Pass EvINRConfig(background='keep') to train on every event")


def prepare_events(events: Events, cfg, span: tuple | None = None):
    """Step 0 of :func:`~evinr_lite.method.solver.reconstruct` (see the module's docstring): ``(events,
    cfg)`` with hot pixels and background activity removed as ``cfg`` says, C replaced by the pair
    estimated from these events (``cfg.balance == "events"``, one C given) and ``lam="auto"`` by its
    value. ``span``: (t_start, t_end) seconds reconstructed (default: the events' first and last
    time), which sets how much of it one window covers."""
    if span is not None:
        if not (isinstance(span, (tuple, list, np.ndarray)) and len(span) == 2):
            raise EventDataError(f"prepare_events: span must be (t_start, t_end) in seconds, or None, got {span!r}")
        span = checked_span(*span, "prepare_events")
    if not len(events):
        return events, cfg
    t0, t1 = (float(events.t[0]), float(events.t[-1])) if span is None else span
    if cfg.background != "keep":                    # hot pixels first, then the filter (its window chosen first)
        n_in, raw = len(events), events
        first = hot_pixel_mask(events) if cfg.hot_pixels == "drop" else None
        events = drop_pixels(events, first)
        cfg = choose_background(cfg, lambda a, b: events.slice_time(a, b, allow_empty=True), t0, t1,
                                tiles=lambda: tile_counts(raw.t, t0, t1))
        if cfg.background == "filter":
            events = filter_background(events, cfg.background_dt)
            _check_left(len(events), n_in, cfg.background_dt, events.sensor_size)
    counts = PolarityCounts(tuple(events.sensor_size), slices=span_slices(t0, t1)).update(events)
    cfg, hot = plan_from_counts(counts.n_on, counts.n_off, cfg, window_fraction(t0, t1, cfg.tau, cfg.overlap),
                                counts.intervals, counts.sliced, counts.flips, t1 - t0)
    return drop_pixels(events, hot), cfg


class _Prepared:
    """A recording source whose windows are prepared as in the whole span: hot pixels (``first``)
    dropped, background filtered with a window of ``dt`` seconds (None: not filtered) on the window read
    :func:`reach` beyond its edges (within the span), then the pixels of ``then`` dropped. Everything else
    is the source's."""

    def __init__(self, source, span, first=None, dt=None, then=None, held=None):
        self._source, self._span = source, span
        self._first, self._dt, self._then, self._held = first, dt, then, held

    def __getattr__(self, name):
        return getattr(self._source, name)

    def events(self, t0, t1):
        if self._held is not None:                   # a span of one counting chunk, prepared once
            return self._held.slice_time(t0, t1, allow_empty=True)
        if self._dt is None:                         # hot pixels only
            return drop_pixels(drop_pixels(self._source.events(t0, t1), self._first), self._then)
        lo, hi = self._span
        r = reach(self._dt)
        a, b = max(t0 - r, lo), min(t1 + r, np.nextafter(hi, np.inf))   # the span's end is inclusive
        wide = filter_background(drop_pixels(self._source.events(a, max(a, b)), self._first), self._dt)
        inside = (wide.t >= t0) & (wide.t < t1)
        return drop_pixels(wide.take(inside), self._then)


def read_chunks(source, t_start: float, t_end: float, chunk_s: float):
    """The source's events over [t_start, t_end] in time-ordered chunks of ``chunk_s`` seconds, read one
    at a time (a generator of Events); the span's end is inclusive, as in reconstruct."""
    return (events for _, events in _read_spans(source, t_start, t_end, chunk_s))


def _read_spans(source, t_start: float, t_end: float, chunk_s: float):
    """:func:`read_chunks` with each chunk's [a, b] (s): a generator of ((a, b), Events)."""
    edges = np.append(np.arange(t_start, t_end, chunk_s), t_end)
    for i, (a, b) in enumerate(zip(edges[:-1].tolist(), edges[1:].tolist())):
        yield (a, b), source.events(a, np.nextafter(b, np.inf) if i == len(edges) - 2 else b)


def _counts(source, t_start: float, t_end: float, chunk_s: float, progress: str | None = None,
            counts_only: bool = False, tiles=None) -> PolarityCounts:
    """The per-pixel ON / OFF counts over the span, read a chunk at a time (``counts_only``: those alone,
    without the balance's intervals and slices); ``progress``: a bar's title (seconds of the recording
    read), or None for none. ``tiles``: an int64 array of the span's
    :func:`~evinr_lite.method.background.tile_counts` to add the events to, or None."""
    from tqdm.auto import tqdm

    counts = PolarityCounts(tuple(source.sensor_size), slices=None if counts_only else span_slices(t_start, t_end),
                            counts_only=counts_only)
    with tqdm(total=round(t_end - t_start, 3), desc=progress, unit="s", disable=progress is None,
              bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.1f}/{total:.1f} s of events [{elapsed}<{remaining}]") as bar:
        for (a, b), events in _read_spans(source, t_start, t_end, chunk_s):
            counts.update(events)
            if tiles is not None:
                tiles += tile_counts(events.t, t_start, t_end)
            bar.update(round(b - a, 3))
    return counts


def prepare_source(source, t_start: float, t_end: float, cfg, chunk_s: float | None = None, progress: bool = False):
    """:func:`prepare_events` for a streamed recording (a hook in
    :func:`~evinr_lite.method.streaming.stream_reconstruct`): ``(cfg, source)``. The counts are read
    over [t_start, t_end] in chunks of ``chunk_s`` seconds (default ``cfg.tau``, so memory stays that
    of one window): once, or twice when the background may be filtered (``cfg.background`` "filter" or
    "auto"; raw counts for the hot pixels, then the filtered events' counts, with "auto" the sampled spans
    read in between to choose the window). So every window is trained with the same C pair, lam
    and events as the whole-span solve. ``progress``: a bar for each pass over the recording."""
    t_start, t_end = checked_span(t_start, t_end, "prepare_source")
    if (cfg.balance == "none" and cfg.hot_pixels == "keep" and cfg.lam != "auto" and cfg.background == "keep"
            and cfg.temporal_scale != "auto"):
        return cfg, source
    chunk_s = chunk_s or cfg.tau or (t_end - t_start)
    span, first, filtered = (t_start, t_end), None, cfg.background != "keep"
    if filtered and t_end - t_start <= chunk_s:
        # the span is one chunk (no more than one window's events): read it once, prepare it as the
        # whole-span solve does, and hand the windows slices of it instead of reading and filtering again
        held, cfg = prepare_events(source.events(t_start, np.nextafter(t_end, np.inf)), cfg, span)
        return cfg, _Prepared(source, span, held=held)
    # with the filter, this first pass only finds the hot pixels (the balance reads the second one's counts)
    # and, with "auto", counts the events on the span's tiles (where they are, for the window's statistics)
    # (a span measured whole, up to WHOLE_SPAN, never looks at them)
    tiles = (tile_counts([], t_start, t_end) if cfg.background == "auto" and t_end - t_start > WHOLE_SPAN
             else None)                                                                  # zeros, one per tile
    counts = _counts(source, t_start, t_end, chunk_s, "counting events" if progress else None, counts_only=filtered,
                     tiles=tiles)
    if filtered:
        if cfg.hot_pixels == "drop":
            first = _hot_mask(counts.n_on + counts.n_off)
        n_in = int((counts.n_on + counts.n_off).sum())
        cfg = choose_background(cfg, source.events, t_start, t_end, first, tiles=tiles)
        dt = cfg.background_dt if cfg.background == "filter" else None
        counts = _counts(_Prepared(source, span, first, dt=dt), t_start, t_end, chunk_s,
                         ("filtering background activity" if dt else "counting events again") if progress else None)
        if dt:
            _check_left(int((counts.n_on + counts.n_off).sum()), n_in, dt, source.sensor_size)
    cfg, hot = plan_from_counts(counts.n_on, counts.n_off, cfg, window_fraction(t_start, t_end, cfg.tau, cfg.overlap),
                                counts.intervals, counts.sliced, counts.flips, t_end - t_start)
    if cfg.background == "keep" and first is None and not hot.any():
        return cfg, source
    return cfg, _Prepared(source, span, first, dt=cfg.background_dt if cfg.background == "filter" else None, then=hot)
