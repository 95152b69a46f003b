"""Notebook 11 (your own recording): exercise references and helpers.

Exercises (registered with :mod:`evinr_lite.teaching.exercises` at import):

- ``hot_pixel_mask``: the pixels that fire far more often than the sensor's typical firing pixel
  (count > factor x the median count of the pixels that fired; a pixel exactly at the threshold is
  not hot), the first thing to check on a recording from your own camera;
- ``event_count_windows``: cut a recording into windows of (nearly) equal event counts, so each
  reconstruction costs about the same and fits in memory;
- ``background_activity_filter``: the background-activity correlation filter (Delbruck 2008) on a
  small input, by comparing every pair of events: event i is kept when an event j at one of the 8
  neighbouring pixels (not the pixel itself) has t_j <= t_i <= t_j + dt (both ends inclusive: a
  neighbour exactly dt earlier counts, and so does one at the same timestamp wherever it sits in
  the stream). The reference is the rule of :func:`evinr_lite.method.denoise.correlation_filter`
  with ``neighbourhood=8, min_neighbours=1, same_polarity=False, window="before"`` (its defaults);
  ``tests/test_exercises_09_11.py`` pins the two together.

The contrast threshold fitted from frames (ΔL ≈ C n) is notebook 09's exercise
(:mod:`evinr_lite.teaching.realdata_exercises`); notebook 11 applies the library's
:func:`evinr_lite.method.contrast.estimate_contrast_threshold` to the reader's recording.

Helpers: :func:`windows_from_indices` and :func:`window_table`. The recording to use comes from
:func:`evinr_lite.sim.recordings.find_recording`; ΔL and n between frame pairs from
:func:`evinr_lite.method.contrast.frame_log_changes`.
"""
from __future__ import annotations

import math

import numpy as np

from ..core.events import EventDataError, Events
from ..core.frames import Frames
from . import exercises

__all__ = ["hot_pixel_mask", "event_count_windows", "background_activity_filter", "windows_from_indices",
           "window_table"]


# ---- exercise 1: a hot-pixel map from per-pixel counts ---------------------------------------

def hot_pixel_mask(x, y, sensor_size, factor: float = 10.0) -> np.ndarray:
    """Pixels that fire far more often than a typical firing pixel.

    A hot pixel (a defect, or a bias set too low for it) fires steadily whatever the scene does, often
    hundreds of times more than its neighbours. The typical rate is the median count over the pixels
    that fired at all: on a short or quiet recording most pixels never fire, so the median over all
    pixels is 0 and would call every firing pixel hot; a mean would be pulled up by the hot pixels
    themselves.

    Args:
        x, y: int [N] event columns and rows (N >= 1). sensor_size: (H, W).
        factor: how many times the median count a pixel must exceed to be hot.
    Returns:
        bool [H, W]: count > factor * median(count of the pixels with count > 0) (strictly: a pixel
        exactly at the threshold is not hot).
    """
    H, W = sensor_size
    counts = np.bincount(np.asarray(y, dtype=np.int64) * W + np.asarray(x, dtype=np.int64),
                         minlength=H * W).reshape(H, W)
    typical = np.median(counts[counts > 0])
    return counts > factor * typical


def _events_from_counts(counts, rng):
    """x, y [N] (shuffled) of a recording whose per-pixel counts are ``counts`` [H, W]."""
    y, x = np.nonzero(counts)
    reps = counts[y, x]
    order = rng.permutation(int(reps.sum()))
    return np.repeat(x, reps)[order], np.repeat(y, reps)[order]


def _inputs_hot(rng):
    cases = []
    # 16 of 25 pixels silent, so the median over all pixels is 0; the firing pixels' median is 2, so with
    # factor 5 the threshold is 10: the pixel with 10 events is exactly on it (not hot), 11 and 60 are hot;
    # the mean (10.3) would flag only the 60
    counts = np.zeros((5, 5), np.int64)
    for (r, c), n in {(0, 1): 2, (1, 0): 2, (1, 2): 2, (2, 3): 2, (4, 4): 3, (3, 0): 1,
                      (0, 3): 10, (3, 1): 11, (2, 4): 60}.items():
        counts[r, c] = n
    x, y = _events_from_counts(counts, rng)
    cases.append(dict(x=x, y=y, sensor_size=(5, 5), factor=5.0))
    # a sensor with Poisson activity, a third of it silent, and three hot pixels; one fired 260 times, past what
    # uint8 holds: counts kept in uint8 (or in the int8 of the polarities) wrap it round to 4, not hot
    counts = rng.poisson(3.0, (6, 9)) * (rng.uniform(size=(6, 9)) > 0.33)
    counts.ravel()[rng.choice(54, 3, replace=False)] = (150, 260, 31)
    x, y = _events_from_counts(counts, rng)
    cases.append(dict(x=x, y=y, sensor_size=(6, 9), factor=10.0))
    # an even number of firing pixels (8), counts 1 1 2 2 | 5 10 11 20: the median is (2 + 5) / 2 = 3.5 (np.median
    # averages the two middle values), so with factor 3 the threshold is 10.5: 11 and 20 are hot, 10 is not. The
    # upper middle value (sorted[n // 2] = 5) flags only 20, the lower one (2) flags 10 too, and so does the median
    # made a whole number (int(3.5) = 3: threshold 9). The sensor is 6 x 9 and its last row and column never fire:
    # a mask sized from the events (y.max() + 1) is too small (and counts indexed [x, y] raise: column 7 fires). It
    # is the second case's sensor, with other events: a typical count kept from one call to the next (cached per
    # sensor, as if it were the camera's) fails here
    counts = np.zeros((6, 9), np.int64)
    for (r, c), n in {(0, 0): 1, (1, 1): 2, (2, 7): 1, (3, 0): 5, (4, 1): 10, (4, 2): 2, (0, 2): 11, (2, 0): 20}.items():
        counts[r, c] = n
    x, y = _events_from_counts(counts, rng)
    cases.append(dict(x=x, y=y, sensor_size=(6, 9), factor=3.0))
    return cases


def _pixel_counts(x, y, sensor_size):
    H, W = sensor_size
    counts = np.zeros((H, W), np.int64)
    np.add.at(counts, (np.asarray(y), np.asarray(x)), 1)
    return counts


def _hot_at_threshold(x, y, sensor_size, factor=10.0):
    counts = _pixel_counts(x, y, sensor_size)
    return counts >= factor * np.median(counts[counts > 0])


def _hot_median_all_pixels(x, y, sensor_size, factor=10.0):
    counts = _pixel_counts(x, y, sensor_size)
    return counts > factor * np.median(counts)


def _hot_mean(x, y, sensor_size, factor=10.0):
    counts = _pixel_counts(x, y, sensor_size)
    return counts > factor * counts[counts > 0].mean()


def _hot_factor_ignored(x, y, sensor_size, factor=10.0):
    return hot_pixel_mask(x, y, sensor_size)


def _hot_fancy_index(x, y, sensor_size, factor=10.0):
    counts = np.zeros(sensor_size, np.int64)
    counts[np.asarray(y), np.asarray(x)] += 1
    return counts > factor * np.median(counts[counts > 0])


def _hot_upper_middle(x, y, sensor_size, factor=10.0):
    """The 'median' read as the middle element of the sorted counts, sorted[n // 2]: the upper of the two middle
    values when n is even."""
    counts = _pixel_counts(x, y, sensor_size)
    nz = np.sort(counts[counts > 0])
    return counts > factor * nz[len(nz) // 2]


def _hot_distinct_counts(x, y, sensor_size, factor=10.0):
    """The median of the distinct counts (np.unique), not of the pixels' counts."""
    counts = _pixel_counts(x, y, sensor_size)
    return counts > factor * np.median(np.unique(counts[counts > 0]))


def _hot_median_per_column(x, y, sensor_size, factor=10.0):
    counts = _pixel_counts(x, y, sensor_size)
    return counts > factor * np.median(counts, axis=0)


def _hot_rows_columns_swapped(x, y, sensor_size, factor=10.0):
    """Counts indexed [x, y]: the transposed map (on a sensor that is not square, an IndexError or this)."""
    return hot_pixel_mask(x, y, sensor_size, factor).T


def _hot_ratio_floor_division(x, y, sensor_size, factor=10.0):
    """count // median > factor: the ratio rounded down before the comparison."""
    counts = _pixel_counts(x, y, sensor_size)
    return counts // np.median(counts[counts > 0]) > factor


def _hot_whole_median(x, y, sensor_size, factor=10.0):
    """The median made a whole number (int(np.median(...))): a median of x.5 loses its half."""
    counts = _pixel_counts(x, y, sensor_size)
    return counts > factor * int(np.median(counts[counts > 0]))


def _hot_sorted_through_a_view(x, y, sensor_size, factor=10.0):
    """counts.ravel() sorted in place for the median: ravel is a view, so the counts themselves get sorted."""
    counts = _pixel_counts(x, y, sensor_size)
    flat = counts.ravel()
    flat.sort()
    return counts > factor * np.median(flat[flat > 0])


def _hot_uint8_counts(x, y, sensor_size, factor=10.0):
    """Counts kept in uint8: a pixel that fired 256 times or more wraps round to a few."""
    H, W = sensor_size
    counts = np.zeros((H, W), np.uint8)
    np.add.at(counts, (np.asarray(y), np.asarray(x)), 1)
    return counts > factor * np.median(counts[counts > 0])


def _hot_int8_counts(x, y, sensor_size, factor=10.0):
    """Counts kept in int8: a pixel that fired 128 times or more wraps round to negative counts."""
    H, W = sensor_size
    counts = np.zeros((H, W), np.int8)
    np.add.at(counts, (np.asarray(y), np.asarray(x)), 1)
    return counts > factor * np.median(counts[counts > 0])


exercises.register(
    "hot_pixel_mask", hot_pixel_mask, _inputs_hot,
    hints={
        "a pixel exactly at factor x median is not hot: use a strict `>`, not `>=`": _hot_at_threshold,
        "take the median over the pixels that fired (count > 0): with most pixels silent the median of all "
        "pixels is 0 and every firing pixel looks hot": _hot_median_all_pixels,
        "use the median, not the mean: the hot pixels pull the mean up and hide themselves": _hot_mean,
        "`counts[y, x] += 1` counts a pixel once however often it fired (fancy indexing does not accumulate "
        "repeated indices): use np.add.at(counts, (y, x), 1) or np.bincount(y * W + x, minlength=H * W)":
            _hot_fancy_index,
        "rows are y and columns are x: count into counts[y, x]": _hot_rows_columns_swapped,
        "the median of an even number of counts is the mean of the two middle values (np.median): sorted[n // 2] "
        "is only the upper one": _hot_upper_middle,
        "a pixel above the threshold is missed: compare count > factor * np.median(counts[counts > 0]), the "
        "median of one count per firing pixel; not of the distinct values (np.unique), nor of the pixels that "
        "fired more than once, and not `count // median > factor` (integer division rounds the ratio down)":
            _hot_distinct_counts,
        "use the `factor` argument, not a fixed 10 (its default)": _hot_factor_ignored,
        "one typical count for the whole sensor, np.median(counts[counts > 0]): a median along an axis (one per "
        "column) compares each pixel with its own column only":
            _hot_median_per_column,
        "`count // median > factor`: integer division rounds the ratio down, so a pixel whose ratio lies between "
        "factor and factor + 1 is missed; compare count > factor * median":
            _hot_ratio_floor_division,
        "the median of an even number of counts can end in .5: keep it as np.median gives it (no int(...), round or "
        "`//`, which move the threshold factor x median)":
            _hot_whole_median,
        "`counts.ravel()` (like counts.reshape(-1) or a slice) is a view of counts, not a copy: sorting it in place "
        "(.sort()) sorts the counts image too, so the mask marks the pixels at the end of the sensor instead of the "
        "hot ones; take the median of a copy (np.sort(...), .flatten()), or just np.median(counts[counts > 0])":
            _hot_sorted_through_a_view,
        "a hot pixel fires hundreds of times: counts in uint8 wrap past 255, so "
        "its 260 events count as 4; count in int64 (np.zeros((H, W), np.int64), np.bincount)":
            _hot_uint8_counts,
        "a hot pixel fires hundreds of times: counts in int8 wrap past 127 to negative numbers; count in int64 "
        "(np.zeros((H, W), np.int64), np.bincount)":
            _hot_int8_counts,
    })


# ---- exercise 2: windows of equal event counts -----------------------------------------------

def event_count_windows(n_events: int, max_events: int) -> np.ndarray:
    """Split N events into the fewest windows of at most ``max_events`` events, as equal as possible.

    Args:
        n_events: N >= 1. max_events: the most events a window may hold (>= 1).
    Returns:
        int64 [w + 1] event indices: window k holds events idx[k] .. idx[k + 1] - 1, with
        w = ceil(N / max_events) and idx[k] = floor(k * N / w) (so idx[0] = 0, idx[w] = N).
    """
    w = max(1, math.ceil(n_events / max_events))
    return (np.arange(w + 1, dtype=np.int64) * n_events) // w


def _inputs_windows(rng):
    # 122 events in 14 windows: k * N / w computed in floating point truncates 61 to 60 (np.linspace). A recording
    # of three million events in windows of at most 2000 (1501 windows of 1998 or 1999): k * N passes 2 ** 31, where
    # int32 wraps, and is not exact in float32
    return [dict(n_events=122, max_events=9), dict(n_events=12, max_events=4), dict(n_events=7, max_events=100),
            dict(n_events=3_000_000 + int(rng.integers(0, 400)), max_events=2000), dict(n_events=1, max_events=1)]


def _compare_windows(got, expected) -> str | None:
    if got is None:
        return "returned None; did you forget the `return` statement?"
    if not isinstance(got, np.ndarray):     # a list or a tensor: later cells use array methods
        return (f"returned a value of type {type(got).__name__}, expected a numpy array of event indices: return "
                "`np.asarray(...)` of it, or build it with numpy (np.arange ...)")
    if got.ndim != 1 or got.dtype.kind not in "iu":
        return f"expected a 1-D integer array of event indices, got {got.dtype} of shape {list(got.shape)}"
    if len(got) != len(expected):
        return (f"{len(got) - 1} windows, expected {len(expected) - 1}: the fewest windows of at most max_events "
                "events each")
    if not np.array_equal(got, expected):
        k = int(np.flatnonzero(got != expected)[0])
        return f"idx[{k}] = {got[k]}, expected {expected[k]}"
    return None


def _windows_float_positions(n_events, max_events):
    """np.linspace: k * N / w in floating point, truncated (60.999... -> 60)."""
    w = max(1, math.ceil(n_events / max_events))
    return np.linspace(0, n_events, w + 1).astype(np.int64)


def _windows_array_split(n_events, max_events):
    w = max(1, math.ceil(n_events / max_events))
    sizes = [len(a) for a in np.array_split(np.arange(n_events), w)]
    return np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)


def _windows_float_step(n_events, max_events):
    """k * (N / w) in floating point, truncated: the step N / w is rounded first, so some k * step fall short."""
    w = max(1, math.ceil(n_events / max_events))
    return (np.arange(w + 1) * (n_events / w)).astype(np.int64)


def _windows_ceil_size(n_events, max_events):
    w = max(1, math.ceil(n_events / max_events))
    return np.minimum(np.arange(w + 1) * math.ceil(n_events / w), n_events).astype(np.int64)


def _windows_ceil_positions(n_events, max_events):
    """idx[k] = ceil(k N / w), rounded up."""
    w = max(1, math.ceil(n_events / max_events))
    return -(-(np.arange(w + 1, dtype=np.int64) * n_events) // w)


def _windows_floor_step(n_events, max_events):
    """Windows of N // w events each, the remainder all in the last one."""
    w = max(1, math.ceil(n_events / max_events))
    idx = np.arange(w + 1, dtype=np.int64) * (n_events // w)
    idx[-1] = n_events
    return idx


def _windows_int32(n_events, max_events):
    """(k * N) // w in int32: k * N wraps past 2 ** 31 on a long recording."""
    w = max(1, math.ceil(n_events / max_events))
    return ((np.arange(w + 1, dtype=np.int32) * np.int32(n_events)) // np.int32(w)).astype(np.int64)


def _windows_float32(n_events, max_events):
    """floor(k * N / w) in float32: 24 bits of mantissa, not enough for k * N past 2 ** 24."""
    w = max(1, math.ceil(n_events / max_events))
    return np.floor(np.arange(w + 1, dtype=np.float32) * np.float32(n_events) / np.float32(w)).astype(np.int64)


exercises.register(
    "event_count_windows", event_count_windows, _inputs_windows, compare=_compare_windows,
    hints={
        "use ceil(N / max_events) windows: with floor, some windows hold more than max_events":
            lambda n_events, max_events: (np.arange(max(1, n_events // max_events) + 1, dtype=np.int64) * n_events)
            // max(1, n_events // max_events),
        "the windows should be as equal as possible (idx[k] = floor(k N / w)), not max_events each with a "
        "short remainder":
            lambda n_events, max_events: np.append(np.arange(0, n_events, max_events, dtype=np.int64), n_events),
        "k * N / w in floating point can land just below a whole number (60.9999... becomes 60): compute "
        "idx[k] = (k * N) // w in integers":
            _windows_float_positions,
        "idx[k] = floor(k N / w) puts the longer windows last; np.array_split puts them first: build the indices "
        "from the docstring's rule, (np.arange(w + 1) * N) // w":
            _windows_array_split,
        "idx[k] = floor(k N / w) rounds down: np.round moves some edges up by one":
            lambda n_events, max_events: np.round(np.arange(max(1, math.ceil(n_events / max_events)) + 1) * n_events
                                                  / max(1, math.ceil(n_events / max_events))).astype(np.int64),
        "k * (N / w) in floating point falls just short of a whole number for some k (N / w is rounded first): "
        "compute idx[k] = (k * N) // w in integers":
            _windows_float_step,
        "windows of ceil(N / w) events each leave a short last window: idx[k] = floor(k N / w) spreads the "
        "remainder so that the sizes differ by at most one":
            _windows_ceil_size,
        "idx[k] = floor(k N / w) rounds down, (k * N) // w: rounded up (-(-(k * N) // w), np.ceil) the longer "
        "windows come first":
            _windows_ceil_positions,
        "windows of N // w events each leave the whole remainder to the last window (which can then hold more "
        "than max_events): idx[k] = (k * N) // w spreads it, so that the sizes differ by at most one":
            _windows_floor_step,
        "k * N passes 2 ** 31 on a recording of millions of events: int32 wraps round to negative numbers; compute "
        "(k * N) // w in int64 (np.arange(w + 1, dtype=np.int64))":
            _windows_int32,
        "float32 holds whole numbers exactly only up to 2 ** 24 (16.7 million): k * N / w in float32 misses by one "
        "or more; compute (k * N) // w in int64":
            _windows_float32,
    })


# ---- exercise 3: the background-activity correlation filter ------------------------------------

def background_activity_filter(t, x, y, dt: float) -> np.ndarray:
    """Keep-mask of the background-activity filter, by comparing every pair of events (small N only).

    Args:
        t: float64 [N] seconds; x, y: int [N] columns and rows; dt: the window (s).
    Returns:
        bool [N]: True where some event j at a neighbouring pixel (max(|x_j - x_i|, |y_j - y_i|) = 1)
        has t_j <= t_i <= t_j + dt (t_j + dt in float64; equal timestamps count whatever their order).
    """
    t = np.asarray(t, np.float64)
    x, y = np.asarray(x, np.int64), np.asarray(y, np.int64)
    cheb = np.maximum(np.abs(x[:, None] - x[None, :]), np.abs(y[:, None] - y[None, :]))   # [i, j]
    in_time = (t[None, :] <= t[:, None]) & (t[:, None] <= t[None, :] + dt)
    return np.any((cheb == 1) & in_time, axis=1)


def _inputs_filter(rng):
    cases = []
    # dyadic times and dt, so t_j + dt is exact: boundary cases
    #   0: (1,1) at 1.0; 1: (2,1) at 1.25 = 1.0 + dt exactly -> kept by 0 (inclusive end)
    #   2: (6,5) at 2.0 and 3: (5,5) at 2.0, 2 stored first: equal timestamps keep each other
    #   4: (1,1) at 1.5: its own pixel fired at 1.0 (does not count); (2,1) at 1.25 is a neighbour -> kept
    #   5: (9,9) at 3.0 and 6: (9,10) at 3.375: 0.375 > dt after it -> 6 dropped, 5 has no earlier neighbour
    #   7: (3,3) at 4.0 and 8: (5,3) at 4.0: two columns apart, not neighbours -> both dropped
    #   9: (7,0) at 5.0 and 10: (7,0) at 5.125: only its own pixel fired before 10 -> dropped
    #   11: (12,12) at 6.0 and 12: (13,13) at 6.125: a diagonal neighbour -> 12 kept
    t = np.array([1.0, 1.25, 2.0, 2.0, 1.5, 3.0, 3.375, 4.0, 4.0, 5.0, 5.125, 6.0, 6.125])
    x = np.array([1, 2, 6, 5, 1, 9, 9, 3, 5, 7, 7, 12, 13])
    y = np.array([1, 1, 5, 5, 1, 9, 10, 3, 3, 0, 0, 12, 13])
    order = np.argsort(t, kind="stable")
    cases.append(dict(t=t[order], x=x[order], y=y[order], dt=0.25))
    # an event just after the window closes (1/1024 s past dt), one just inside, and a neighbour that comes later;
    # the first and the last event stored are each kept only by a neighbour with the same timestamp (a loop
    # that skips the first event, or never looks at the last one as a neighbour, fails)
    t = np.array([0.0, 0.0, 0.125 + 2 ** -10, 0.5, 0.625, 0.75, 0.875, 0.875])
    cases.append(dict(t=t, x=np.array([3, 4, 5, 0, 1, 2, 8, 9]), y=np.array([4, 4, 4, 0, 1, 2, 8, 8]), dt=0.125))
    # random small streams with whole-microsecond timestamps (ties happen)
    for n, size, span, dt in ((60, 6, 0.01, 0.002), (120, 10, 0.05, 0.004)):
        t = np.sort(np.round(rng.uniform(0, span, n), 4))
        x, y = rng.integers(0, size, n), rng.integers(0, size, n)
        if dt == 0.004:
            # two neighbours alone at pixels (20, 20) and (21, 20), exactly dt apart in decimal: 0.0197 <= 0.0157 +
            # 0.004 holds in float64, so the later one is kept; in whole microseconds made with astype(int), which
            # truncates, 0.0157 s is 15699 us (0.0157 * 1e6 = 15699.999...) and the pair falls apart
            for v, column in ((0.0157, 20), (0.0197, 21)):
                k = np.searchsorted(t, v)
                t[k], x[k], y[k] = v, column, 20
        else:
            # the last two events, two lone neighbours on a clock at 1000 s, 20 us further apart than dt: out of the
            # window in float64 (and in whole microseconds), but float32 times (spacing 61 us at 1000 s) put them
            # exactly dt apart, and the later one is kept
            t[-2:], x[-2:], y[-2:] = (1000.0, 1000.00202), (30, 31), (30, 30)
        cases.append(dict(t=t, x=x, y=y, dt=dt))
    return cases


def _filter_strict_dt(t, x, y, dt):
    t = np.asarray(t, np.float64)
    x, y = np.asarray(x, np.int64), np.asarray(y, np.int64)
    cheb = np.maximum(np.abs(x[:, None] - x[None, :]), np.abs(y[:, None] - y[None, :]))
    return np.any((cheb == 1) & (t[None, :] <= t[:, None]) & (t[:, None] - t[None, :] < dt), axis=1)


def _filter_strictly_earlier(t, x, y, dt):
    t = np.asarray(t, np.float64)
    x, y = np.asarray(x, np.int64), np.asarray(y, np.int64)
    cheb = np.maximum(np.abs(x[:, None] - x[None, :]), np.abs(y[:, None] - y[None, :]))
    return np.any((cheb == 1) & (t[None, :] < t[:, None]) & (t[:, None] <= t[None, :] + dt), axis=1)


def _filter_stream_order(t, x, y, dt):
    """Only events stored before i count (a per-pixel timestamp map updated in stream order)."""
    t = np.asarray(t, np.float64)
    x, y = np.asarray(x, np.int64), np.asarray(y, np.int64)
    n = len(t)
    cheb = np.maximum(np.abs(x[:, None] - x[None, :]), np.abs(y[:, None] - y[None, :]))
    before = np.arange(n)[None, :] < np.arange(n)[:, None]
    return np.any((cheb == 1) & before & (t[:, None] <= t[None, :] + dt), axis=1)


def _filter_own_pixel(t, x, y, dt):
    t = np.asarray(t, np.float64)
    x, y = np.asarray(x, np.int64), np.asarray(y, np.int64)
    cheb = np.maximum(np.abs(x[:, None] - x[None, :]), np.abs(y[:, None] - y[None, :]))
    others = ~np.eye(len(t), dtype=bool)
    return np.any((cheb <= 1) & others & (t[None, :] <= t[:, None]) & (t[:, None] <= t[None, :] + dt), axis=1)


def _filter_later_neighbours(t, x, y, dt):
    """A window on both sides, |t_i - t_j| <= dt: a neighbour that fires later keeps the event too."""
    t = np.asarray(t, np.float64)
    x, y = np.asarray(x, np.int64), np.asarray(y, np.int64)
    cheb = np.maximum(np.abs(x[:, None] - x[None, :]), np.abs(y[:, None] - y[None, :]))
    return np.any((cheb == 1) & (np.abs(t[:, None] - t[None, :]) <= dt), axis=1)


def _filter_four_neighbours(t, x, y, dt):
    t = np.asarray(t, np.float64)
    x, y = np.asarray(x, np.int64), np.asarray(y, np.int64)
    manhattan = np.abs(x[:, None] - x[None, :]) + np.abs(y[:, None] - y[None, :])
    return np.any((manhattan == 1) & (t[None, :] <= t[:, None]) & (t[:, None] <= t[None, :] + dt), axis=1)


def _filter_any_over_events(t, x, y, dt):
    """np.any over axis 0: whether event j supports some event, not whether event i has a supporter."""
    t = np.asarray(t, np.float64)
    x, y = np.asarray(x, np.int64), np.asarray(y, np.int64)
    cheb = np.maximum(np.abs(x[:, None] - x[None, :]), np.abs(y[:, None] - y[None, :]))
    in_time = (t[None, :] <= t[:, None]) & (t[:, None] <= t[None, :] + dt)
    return np.any((cheb == 1) & in_time, axis=0)


def _filter_manhattan_two(t, x, y, dt):
    t = np.asarray(t, np.float64)
    x, y = np.asarray(x, np.int64), np.asarray(y, np.int64)
    m = np.abs(x[:, None] - x[None, :]) + np.abs(y[:, None] - y[None, :])
    return np.any((m >= 1) & (m <= 2) & (t[None, :] <= t[:, None]) & (t[:, None] <= t[None, :] + dt), axis=1)


def _filter_unsigned_coordinates(t, x, y, dt):
    t = np.asarray(t, np.float64)
    x, y = np.asarray(x).astype(np.uint8), np.asarray(y).astype(np.uint8)
    cheb = np.maximum(np.abs(x[:, None] - x[None, :]), np.abs(y[:, None] - y[None, :]))
    return np.any((cheb == 1) & (t[None, :] <= t[:, None]) & (t[:, None] <= t[None, :] + dt), axis=1)


def _filter_dt_in_microseconds(t, x, y, dt):
    return background_activity_filter(t, x, y, dt * 1e-6)


def _filter_dt_in_milliseconds(t, x, y, dt):
    return background_activity_filter(t, x, y, dt * 1e3)


def _filter_loop_off_by_one(t, x, y, dt, first=0, last=0):
    n = len(t)
    keep = np.zeros(n, dtype=bool)
    for i in range(first, n):
        for j in range(n - last):
            if max(abs(x[j] - x[i]), abs(y[j] - y[i])) == 1 and t[j] <= t[i] <= t[j] + dt:
                keep[i] = True
    return keep


def _filter_last_event_never_a_neighbour(t, x, y, dt):
    return _filter_loop_off_by_one(t, x, y, dt, last=1)


def _filter_first_event_never_kept(t, x, y, dt):
    return _filter_loop_off_by_one(t, x, y, dt, first=1)


def _filter_time_difference(t, x, y, dt):
    """The window's end compared as a difference, t_i - t_j <= dt."""
    t = np.asarray(t, np.float64)
    x, y = np.asarray(x, np.int64), np.asarray(y, np.int64)
    cheb = np.maximum(np.abs(x[:, None] - x[None, :]), np.abs(y[:, None] - y[None, :]))
    gap = t[:, None] - t[None, :]
    return np.any((cheb == 1) & (gap >= 0) & (gap <= dt), axis=1)


def _filter_truncated_microseconds(t, x, y, dt):
    """Times made whole microseconds with astype(int), which truncates (0.0157 * 1e6 = 15699.999... -> 15699)."""
    tu = (np.asarray(t, np.float64) * 1e6).astype(np.int64)
    du = int(dt * 1e6)
    x, y = np.asarray(x, np.int64), np.asarray(y, np.int64)
    cheb = np.maximum(np.abs(x[:, None] - x[None, :]), np.abs(y[:, None] - y[None, :]))
    return np.any((cheb == 1) & (tu[None, :] <= tu[:, None]) & (tu[:, None] <= tu[None, :] + du), axis=1)


def _filter_float32_times(t, x, y, dt):
    """Times (and dt) in float32: spacing 61 us on a clock at 1000 s."""
    t32 = np.asarray(t, np.float32)
    x, y = np.asarray(x, np.int64), np.asarray(y, np.int64)
    cheb = np.maximum(np.abs(x[:, None] - x[None, :]), np.abs(y[:, None] - y[None, :]))
    return np.any((cheb == 1) & (t32[None, :] <= t32[:, None]) & (t32[:, None] <= t32[None, :] + np.float32(dt)), axis=1)


def _filter_time_slots(t, x, y, dt):
    """Times cut into slots of width dt (floor(t / dt)), a neighbour in the same slot or the one before counted."""
    k = np.floor(np.asarray(t, np.float64) / dt).astype(np.int64)
    x, y = np.asarray(x, np.int64), np.asarray(y, np.int64)
    cheb = np.maximum(np.abs(x[:, None] - x[None, :]), np.abs(y[:, None] - y[None, :]))
    return np.any((cheb == 1) & (k[None, :] <= k[:, None]) & (k[:, None] <= k[None, :] + 1), axis=1)


exercises.register(
    "background_activity_filter", background_activity_filter, _inputs_filter,
    hints={
        "a neighbour exactly dt earlier counts: t_i <= t_j + dt (inclusive), not t_i - t_j < dt": _filter_strict_dt,
        "a neighbour at the same timestamp counts: t_j <= t_i, not t_j < t_i": _filter_strictly_earlier,
        "compare times, not positions in the stream: a neighbour with the same timestamp stored after the "
        "event counts too": _filter_stream_order,
        "the pixel's own events never count (else a hot pixel keeps itself): max(|dx|, |dy|) == 1, not <= 1":
            _filter_own_pixel,
        "the 8 neighbours include the diagonals: max(|dx|, |dy|) == 1, not |dx| + |dy| == 1": _filter_four_neighbours,
        "only earlier neighbours count (t_j <= t_i): the filter decides when event i arrives, before any later "
        "event exists, so |t_i - t_j| <= dt is too wide": _filter_later_neighbours,
        "one answer per event i: np.any(..., axis=1) over the candidates j in row i (axis=0 asks whether "
        "event j supports some other event)":
            _filter_any_over_events,
        "every event can be a neighbour, the last one too: loop j over range(len(t)), not range(len(t) - 1)":
            _filter_last_event_never_a_neighbour,
        "every event gets an answer, the first one too (a neighbour with the same timestamp keeps it): loop i "
        "over range(len(t)), not range(1, len(t))":
            _filter_first_event_never_kept,
        "the 8 neighbours are the pixels with max(|dx|, |dy|) == 1: |dx| + |dy| <= 2 also takes pixels two "
        "columns (or rows) away":
            _filter_manhattan_two,
        "unsigned coordinates (uint8, uint16) wrap round when subtracted (1 - 2 = 255): convert x and y to a "
        "signed integer (np.int64) before taking |x_j - x_i|":
            _filter_unsigned_coordinates,
        "dt is in seconds, like t: use it as it is (dt * 1e-6 reads it as microseconds and shrinks the window "
        "a million times)":
            _filter_dt_in_microseconds,
        "dt is in seconds, like t: use it as it is (dt * 1e3 reads it as milliseconds and makes the window a "
        "thousand times longer)":
            _filter_dt_in_milliseconds,
        "compare t_i <= t_j + dt as written: t_i - t_j <= dt rounds differently in floating point, and an event "
        "exactly dt after its neighbour can fall out of the window": _filter_time_difference,
        "(t * 1e6).astype(int) truncates: 0.0157 s is 15699.999... us and becomes 15699, a microsecond early, so "
        "an event exactly dt after its neighbour falls out of the window; compare the seconds as they are (or "
        "np.round before astype)":
            _filter_truncated_microseconds,
        "timestamps must stay float64: in float32 a time near 1000 s is rounded to a multiple of 61 us, so two "
        "neighbours a few microseconds more than dt apart land exactly dt apart (or the other way round); keep t "
        "as it is given (np.asarray(t, dtype=np.float64))":
            _filter_float32_times,
        "slots of width dt (floor(t / dt)) are not a window of dt before each event: a neighbour in the slot "
        "before can be almost 2 dt earlier, and one just across a slot edge a moment earlier is missed when "
        "the slots are compared for equality; compare the times of each pair, t_j <= t_i <= t_j + dt":
            _filter_time_slots,
    })


def windows_from_indices(t, idx) -> list[tuple[float, float | None]]:
    """(start, end) seconds of the windows given by event indices ``idx`` [w + 1] (end None: to the
    last event), for ``load_recording(path, t_start=start, t_end=end)``."""
    t = np.asarray(t)
    idx = np.asarray(idx)
    if idx[0] != 0 or idx[-1] != len(t) or np.any(np.diff(idx) <= 0):
        raise EventDataError(f"window indices must rise strictly from 0 to {len(t)}, got {idx[:5]}...")
    return [(float(t[a]), float(t[b]) if b < len(t) else None) for a, b in zip(idx[:-1], idx[1:])]


def window_table(events: Events, frames: Frames | None, windows) -> list[dict]:
    """For each (start, end) window: duration, events, events per pixel, ground-truth frames inside."""
    H, W = events.sensor_size
    rows = []
    for k, (start, end) in enumerate(windows):
        stop = events.t[-1] if end is None else end
        n = int(np.searchsorted(events.t, stop, side="right" if end is None else "left")
                - np.searchsorted(events.t, start, side="left"))
        inside = 0 if frames is None else int(np.sum((frames.t >= start) & (frames.t <= stop)))
        rows.append({"window": k, "start_s": start, "end_s": float(stop), "duration_s": float(stop - start),
                     "events": n, "events_per_pixel": n / (H * W), "gt_frames": inside})
    return rows
