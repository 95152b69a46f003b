"""Notebook 10's exercise references (Quad Bayer demosaicing), registered with :mod:`evinr_lite.teaching.exercises`.

- ``quad_bayer_channel``: the colour (0 R, 1 G, 2 B) of photosites on a Quad Bayer sensor with a
  given phase (see :mod:`evinr_lite.sim.quadbayer` for the convention);
- ``grey_event_frame``: demosaic events onto the reduced grey grid and sum them into one event
  frame, each event weighing C / 16 (the effective grey threshold).

Helper: :func:`jensen_gap`, the difference between the mean of a window's log intensities and the
log of its mean intensity, next to its second-order approximation (notebook 10, section 4).
"""
from __future__ import annotations

import numpy as np

from . import exercises

__all__ = ["quad_bayer_channel", "grey_event_frame", "jensen_gap"]


def quad_bayer_channel(y, x, phase):
    """Colour channel of the photosites at rows ``y``, columns ``x`` of a Quad Bayer sensor.

    The tile is R R G G / R R G G / G G B B / G G B B; ``phase = (dy, dx)`` means the photosite at
    (y, x) sees tile entry ((y + dy) % 4, (x + dx) % 4).

    Args:
        y, x: int arrays of one shape (row, column). phase: (dy, dx) ints.
    Returns:
        int64 array of that shape: 0 = R, 1 = G, 2 = B.
    """
    block_row = ((np.asarray(y) + phase[0]) % 4) // 2      # 0: the R G half of the tile, 1: the G B half
    block_col = ((np.asarray(x) + phase[1]) % 4) // 2
    return (block_row + block_col).astype(np.int64)        # R G / G B = 0 1 / 1 2


def grey_event_frame(x, y, p, C, raw_size):
    """One grey event frame at the reduced grid from Quad Bayer events.

    Each event of photosite (y, x) goes to the grey pixel (y // 4, x // 4) and adds C * p / 16
    (16 photosites per grey pixel: the grey log intensity is their mean).

    Args:
        x, y: int arrays [N] (column, row on the raw sensor). p: int [N] in {-1, +1}.
        C: the photosites' contrast threshold. raw_size: (H, W) of the raw sensor, multiples of 4.
    Returns:
        float64 [H // 4, W // 4].
    """
    H, W = raw_size
    frame = np.zeros((H // 4, W // 4))
    np.add.at(frame, (np.asarray(y) // 4, np.asarray(x) // 4), C * np.asarray(p, dtype=np.float64) / 16)
    return frame


def jensen_gap(intensity, block: int = 4):
    """Jensen's gap of each block x block window, exact and to second order.

    For the window's intensities I_k (mean m, variance v), the mean of the logs and the log of the
    mean agree to first order in the spread; their difference is the gap
    mean_k log I_k - log m = -v / (2 m^2) + O(spread^3) (Taylor expansion of log about m).

    Args:
        intensity: float [..., H, W] linear intensities > 0 (H, W multiples of ``block``).
        block: window size in photosites (4 for a Quad Bayer grey pixel).
    Returns:
        (gap, second_order): float64 [..., H // block, W // block] each: mean of logs minus log of
        mean (always <= 0), and -v / (2 m^2).
    """
    I = np.asarray(intensity, dtype=np.float64)
    *lead, H, W = I.shape
    windows = I.reshape(*lead, H // block, block, W // block, block)
    m = windows.mean(axis=(-3, -1))
    v = windows.var(axis=(-3, -1))
    gap = np.log(windows).mean(axis=(-3, -1)) - np.log(m)
    return gap, -v / (2 * m * m)


# ---- seeded inputs and known mistakes ----------------------------------------------------

def _inputs_channel(rng):
    y, x = np.mgrid[0:6, 0:7]
    cases = [dict(y=y, x=x, phase=ph) for ph in ((0, 0), (1, 0), (0, 3), (-2, -3))]   # a negative phase: a floor modulo
    cases.append(dict(y=rng.integers(0, 1000, 20), x=rng.integers(0, 1000, 20), phase=(3, 2)))
    return cases


def _channel_plain_bayer(y, x, phase):
    return (((np.asarray(y) + phase[0]) % 2) + ((np.asarray(x) + phase[1]) % 2)).astype(np.int64)


def _channel_phase_swapped(y, x, phase):
    return quad_bayer_channel(y, x, (phase[1], phase[0]))


def _channel_phase_subtracted(y, x, phase):
    return quad_bayer_channel(y, x, (-phase[0], -phase[1]))


def _channel_phase_in_blocks(y, x, phase):
    return ((np.asarray(y) // 2 + phase[0]) % 2 + (np.asarray(x) // 2 + phase[1]) % 2).astype(np.int64)


def _channel_no_block_division(y, x, phase):
    return ((((np.asarray(y) + phase[0]) % 4) + ((np.asarray(x) + phase[1]) % 4)) // 2).astype(np.int64)


def _channel_rounded_halves(y, x, phase):
    """np.round(((y + dy) % 4) / 2): 0.5 rounds to 0 but 1.5 to 2 (halves to even), not a floor."""
    return (np.round(((np.asarray(y) + phase[0]) % 4) / 2)
            + np.round(((np.asarray(x) + phase[1]) % 4) / 2)).astype(np.int64)


exercises.register(
    "quad_bayer_channel", quad_bayer_channel, _inputs_channel,
    hints={
        "np.fmod (C's remainder, like math.fmod and torch.fmod) keeps the sign of y + dy, so a negative phase gives "
        "negative tile rows: use Python's and numpy's % (a floor modulo, always in 0..3)":
            lambda y, x, phase: (np.fmod(np.asarray(y) + phase[0], 4) // 2
                                 + np.fmod(np.asarray(x) + phase[1], 4) // 2).astype(np.int64),
        "that is a plain 2x2 Bayer pattern: in Quad Bayer each colour covers a 2x2 block, so the block index "
        "is ((y + dy) % 4) // 2": _channel_plain_bayer,
        "phase is (dy, dx): the row offset first, then the column offset": _channel_phase_swapped,
        "add the phase to the coordinates: (y + dy) % 4, not (y - dy) % 4": _channel_phase_subtracted,
        "take the block row and the block column separately (each // 2) and add them": _channel_no_block_division,
        "add the phase before dividing into blocks: ((y + dy) % 4) // 2 (the phase counts photosites, not blocks)":
            _channel_phase_in_blocks,
        "the colours are 0 = R, 1 = G, 2 = B: the R G G B tile starts with R at its top-left":
            lambda y, x, phase: 2 - quad_bayer_channel(y, x, phase),
        "rows and columns count from 0: the photosite at y = 0, x = 0 sees tile entry (dy % 4, dx % 4); (y - 1 + dy) "
        "counts them from 1 and shifts the pattern by one photosite":
            lambda y, x, phase: quad_bayer_channel(y, x, (phase[0] - 1, phase[1] - 1)),
        "np.round(r / 2) is not r // 2: it rounds halves to the even neighbour (0.5 to 0, 1.5 to 2), so tile row 3 "
        "counts as block 2; the block is the integer division ((y + dy) % 4) // 2, 0 or 1":
            _channel_rounded_halves,
    })


def _inputs_grey(rng):
    # first a square sensor whose events sit in the top-right window only (3 ON events on one photosite
    # and 2 OFF on another): rows and columns swapped give wrong values (with a hint), not an IndexError,
    # and fancy-index `+=` keeps one event per pixel
    cases = [dict(x=np.array([4, 4, 4, 7, 6]), y=np.array([1, 1, 1, 3, 0]), p=np.array([1, 1, 1, -1, -1], np.int8),
                  C=0.25, raw_size=(8, 8))]
    # the last is a flash: 1200 events, nine in ten ON, some 160 net on each of its six grey pixels, past what int8
    # (the polarities' dtype) holds: net counts summed in it wrap round
    for H, W, n, C, on in ((4, 8, 12, 0.2, None), (8, 12, 60, 0.25, None), (12, 8, 1200, 0.1, 0.9)):
        p = rng.choice([-1, 1], n, p=None if on is None else [1 - on, on]).astype(np.int8)
        cases.append(dict(x=rng.integers(0, W, n), y=rng.integers(0, H, n), p=p, C=C, raw_size=(H, W)))
    return cases


def _grey_no_weight(x, y, p, C, raw_size):
    return grey_event_frame(x, y, p, C * 16, raw_size)


def _grey_quarter_weight(x, y, p, C, raw_size):
    return grey_event_frame(x, y, p, C * 4, raw_size)


def _grey_fancy_index(x, y, p, C, raw_size):
    """The mistake: ``frame[y // 4, x // 4] += ...`` keeps only one of several events on a pixel."""
    H, W = raw_size
    frame = np.zeros((H // 4, W // 4))
    frame[np.asarray(y) // 4, np.asarray(x) // 4] += C * np.asarray(p, dtype=np.float64) / 16
    return frame


def _grey_floor_division(x, y, p, C, raw_size):
    H, W = raw_size
    frame = np.zeros((H // 4, W // 4))
    np.add.at(frame, (np.asarray(y) // 4, np.asarray(x) // 4), C * np.asarray(p, dtype=np.float64) // 16)
    return frame


def _grey_histogram_bins_from_data(x, y, p, C, raw_size):
    H, W = raw_size
    f, _, _ = np.histogram2d(np.asarray(y) // 4, np.asarray(x) // 4, bins=(H // 4, W // 4),
                             weights=np.asarray(p, dtype=np.float64))
    return C * f / 16


def _grey_mean_per_pixel(x, y, p, C, raw_size):
    """Each grey pixel's events averaged instead of summed."""
    H, W = raw_size
    n = np.zeros((H // 4, W // 4))
    np.add.at(n, (np.asarray(y) // 4, np.asarray(x) // 4), 1.0)
    return grey_event_frame(x, y, p, C, raw_size) / np.maximum(n, 1)


def _grey_unsigned_polarity(x, y, p, C, raw_size):
    return grey_event_frame(x, y, np.asarray(p).astype(np.uint8).astype(np.float64), C, raw_size)


def _grey_size_from_events(x, y, p, C, raw_size):
    """The frame sized by the largest event coordinates (y.max() // 4 + 1, x.max() // 4 + 1), not by raw_size."""
    frame = np.zeros((int(np.max(y)) // 4 + 1, int(np.max(x)) // 4 + 1))
    np.add.at(frame, (np.asarray(y) // 4, np.asarray(x) // 4), C * np.asarray(p, dtype=np.float64) / 16)
    return frame


def _grey_one_per_distinct_event(x, y, p, C, raw_size):
    """The events made a set of (y, x, p): several identical events (one photosite firing again) count once."""
    events = np.unique(np.stack([np.asarray(y), np.asarray(x), np.asarray(p)]), axis=1)
    return grey_event_frame(events[1], events[0], events[2], C, raw_size)


def _grey_rows_columns_swapped(x, y, p, C, raw_size):
    """The frame indexed [x // 4, y // 4]: the transposed frame (a sensor that is not square: an IndexError or this)."""
    return grey_event_frame(x, y, p, C, raw_size).T


def _grey_int8_counts(x, y, p, C, raw_size):
    """Net counts summed in the polarities' int8 (np.zeros(..., p.dtype)): past 127 they wrap round."""
    H, W = raw_size
    n = np.zeros((H // 4, W // 4), np.int8)
    np.add.at(n, (np.asarray(y) // 4, np.asarray(x) // 4), np.asarray(p).astype(np.int8))
    return C * n / 16


exercises.register(
    "grey_event_frame", grey_event_frame, _inputs_grey,
    hints={
        "each event carries C / 16, not C: the grey log intensity is the mean over 16 photosites": _grey_no_weight,
        "a grey pixel merges 16 photosites (4 x 4), so divide by 16, not 4": _grey_quarter_weight,
        "`frame[y // 4, x // 4] += ...` adds only one of the events that share a pixel (fancy indexing "
        "does not accumulate repeated indices): use np.add.at(frame, (y // 4, x // 4), C * p / 16)":
            _grey_fancy_index,
        "rows are y and columns are x: index the frame as [y // 4, x // 4]": _grey_rows_columns_swapped,
        "did you forget the sign of the polarity? ON events add C / 16, OFF events subtract it":
            lambda x, y, p, C, raw_size: grey_event_frame(x, y, np.abs(np.asarray(p)), C, raw_size),
        "`C * p // 16` is floor division: it rounds C p / 16 down to a whole number; divide with `/`":
            _grey_floor_division,
        "np.histogram2d with a number of bins spreads them over the events' own range (min to max), not over the "
        "sensor: give the edges, bins=(np.arange(H // 4 + 1), np.arange(W // 4 + 1)), or use np.add.at":
            _grey_histogram_bins_from_data,
        "sum the events of each grey pixel (C p / 16 each), do not average them: the net count is what changes "
        "the log intensity":
            _grey_mean_per_pixel,
        "p is signed (+1 / -1): converted to an unsigned dtype (np.uint8) -1 becomes 255; keep it signed or make it "
        "float":
            _grey_unsigned_polarity,
        "the frame's size comes from raw_size, (H // 4, W // 4), not from the largest event coordinates: the "
        "last rows or columns may have no event":
            _grey_size_from_events,
        "every event counts, repeated ones too: a set (or np.unique) of the (y, x, p) triples keeps one of several "
        "identical events (a photosite that fired again); add up all of them with np.add.at":
            _grey_one_per_distinct_event,
        "a grey pixel gathers the events of 16 photosites, and a flash makes hundreds: a net count summed in int8 "
        "(the polarities' dtype, np.zeros(..., dtype=p.dtype)) wraps past 127; sum C * p / 16 in float64":
            _grey_int8_counts,
    })
