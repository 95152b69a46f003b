"""Notebook 10's exercise references (Quad Bayer demosaicing), registered with :mod:`evinr_lite.teaching.exercises`.

- ``quad_bayer_channel``: the colour (0 R, 1 G, 2 B) of photosites on a Quad Bayer sensor with a
  given phase (see :mod:`evinr_lite.sim.quadbayer` for the convention);
- ``grey_event_frame``: demosaic events onto the reduced grey grid and sum them into one event
  frame, each event weighing C / 16 (the effective grey threshold).
"""
from __future__ import annotations

import numpy as np

from . import exercises

__all__ = ["quad_bayer_channel", "grey_event_frame"]


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


# ---- seeded inputs and known mistakes ----------------------------------------------------

def _inputs_channel(rng):
    y, x = np.mgrid[0:6, 0:7]
    cases = [dict(y=y, x=x, phase=ph) for ph in ((0, 0), (1, 0), (0, 3), (2, 1))]
    cases.append(dict(y=rng.integers(0, 1000, 20), x=rng.integers(0, 1000, 20), phase=(3, 2)))
    return cases


def _channel_plain_bayer(y, x, phase):
    return (((np.asarray(y) + phase[0]) % 2) + ((np.asarray(x) + phase[1]) % 2)).astype(np.int64)


def _channel_phase_swapped(y, x, phase):
    return quad_bayer_channel(y, x, (phase[1], phase[0]))


def _channel_phase_subtracted(y, x, phase):
    return quad_bayer_channel(y, x, (-phase[0], -phase[1]))


def _channel_no_block_division(y, x, phase):
    return ((((np.asarray(y) + phase[0]) % 4) + ((np.asarray(x) + phase[1]) % 4)) // 2).astype(np.int64)


exercises.register(
    "quad_bayer_channel", quad_bayer_channel, _inputs_channel,
    hints={
        "that is a plain 2x2 Bayer pattern: in Quad Bayer each colour covers a 2x2 block, so the block index "
        "is ((y + dy) % 4) // 2": _channel_plain_bayer,
        "phase is (dy, dx): the row offset first, then the column offset": _channel_phase_swapped,
        "add the phase to the coordinates: (y + dy) % 4, not (y - dy) % 4": _channel_phase_subtracted,
        "take the block row and the block column separately (each // 2) and add them": _channel_no_block_division,
    })


def _inputs_grey(rng):
    cases = []
    for H, W, n, C in ((4, 8, 12, 0.2), (8, 12, 60, 0.25), (12, 8, 200, 0.1)):
        cases.append(dict(x=rng.integers(0, W, n), y=rng.integers(0, H, n), p=rng.choice([-1, 1], n).astype(np.int8),
                          C=C, raw_size=(H, W)))
    return cases


def _grey_no_weight(x, y, p, C, raw_size):
    return grey_event_frame(x, y, p, C * 16, raw_size)


def _grey_quarter_weight(x, y, p, C, raw_size):
    return grey_event_frame(x, y, p, C * 4, raw_size)


exercises.register(
    "grey_event_frame", grey_event_frame, _inputs_grey,
    hints={
        "each event carries C / 16, not C: the grey log intensity is the mean over 16 photosites": _grey_no_weight,
        "a grey pixel merges 16 photosites (4 x 4), so divide by 16, not 4": _grey_quarter_weight,
    })
