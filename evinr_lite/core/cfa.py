"""Colour filter arrays (CFA): the one home of what a colour event sensor's filter is.

Used by io (the canonical file's ``cfa`` attribute), sim (Quad Bayer and colour DAVIS scenes), method
(per-channel thresholds) and apps (``reconstruct --colour``); :mod:`evinr_lite.sim.quadbayer` explains
mosaicing and demosaicing with it.

The tile
    A Quad Bayer sensor repeats a 4 x 4 tile of 2 x 2 same-colour blocks (``block = 2``)::

        R R G G
        R R G G
        G G B B
        G G B B

    A plain Bayer sensor is the same with ``block = 1`` (the 2 x 2 tile R G / G B). The period is
    ``P = 2 * block``. ``phase = (dy, dx)`` says where the sensor's photosite (row 0, column 0)
    sits in the tile: the photosite at row y, column x has colour
    ``TILE[(y + dy) % P, (x + dx) % P]``. Channels are numbered 0 = R, 1 = G, 2 = B.

Names
    A 2 x 2 Bayer filter is named by the colours of its photosites (0, 0), (0, 1), (1, 0), (1, 1):
    "RGGB", "GRBG", "GBRG", "BGGR" (:data:`CFA_NAMES`); the name gives the phase with ``block = 1``
    (:func:`cfa_phase`): "GRBG" is RGGB shifted by one column, phase (0, 1).

Thresholds
    A demosaiced event of channel c stands for a log-intensity step of C / n_c, n_c the photosites of
    colour c per P x P window (:func:`effective_thresholds`; the argument is in
    :mod:`evinr_lite.sim.quadbayer`).
"""
from __future__ import annotations

import numpy as np

from .checks import host_array, is_real_number, real_number, short_repr, whole_number
from .events import EventDataError, check_sensor_size

__all__ = ["CHANNELS", "QUAD_BAYER", "BAYER", "TILE_COLOURS", "CFA_NAMES", "check_cfa", "cfa_phase",
           "check_block", "check_phase", "period", "photosites_per_window", "cfa_tile", "cfa_channel",
           "cfa_pattern", "effective_thresholds"]

CHANNELS = ("R", "G", "B")
QUAD_BAYER = 2          # block size: 2 x 2 same-colour photosites
BAYER = 1               # plain Bayer: every photosite its own block
TILE_COLOURS = np.array([[0, 1], [1, 2]], dtype=np.int8)   # R G / G B, one entry per block
# 2 x 2 Bayer filters by the colours of photosites (0, 0), (0, 1), (1, 0), (1, 1) -> phase (dy, dx) of
# the RGGB tile (block = 1)
CFA_NAMES = {"RGGB": (0, 0), "GRBG": (0, 1), "GBRG": (1, 0), "BGGR": (1, 1)}
MAX_BLOCK = 8   # photosites per side of one colour block: Quad Bayer 2, "nona" 3, "hexadeca" 4; none larger exists


def check_cfa(cfa, error=EventDataError) -> str | None:
    """A colour filter name checked (None = mono): one of :data:`CFA_NAMES`, upper-cased.
    ``error`` is the exception class raised (io and data_fetch pass their own)."""
    if cfa is None:
        return None
    name = str(cfa).upper() if isinstance(cfa, str) else None
    if name not in CFA_NAMES:
        raise error(f"cfa must be one of {', '.join(CFA_NAMES)} (the colours of the photosites (0, 0), (0, 1), "
                    f"(1, 0), (1, 1)) or None for a mono sensor; got {cfa!r}")
    return name


def cfa_phase(cfa) -> tuple[int, int]:
    """(dy, dx) of a 2 x 2 Bayer filter name in the RGGB tile: "RGGB" (0, 0), "GRBG" (0, 1), "GBRG"
    (1, 0), "BGGR" (1, 1); the ``phase`` of :func:`cfa_channel` with ``block=1``."""
    name = check_cfa(cfa)
    if name is None:
        raise EventDataError("cfa_phase needs a colour filter name (RGGB, GRBG, GBRG, BGGR), got None (mono)")
    return CFA_NAMES[name]


def check_block(block) -> int:
    """``block`` checked: a whole number in [1, MAX_BLOCK] (2 = Quad Bayer, 1 = plain Bayer); a 0-d array or
    tensor holding one is that number (a block of 10^9 was a tile of 4 * 10^18 photosites)."""
    try:
        return whole_number(block, "block", lo=1, hi=MAX_BLOCK)
    except EventDataError:
        raise EventDataError(f"block must be a whole number in [1, {MAX_BLOCK}] (2 = Quad Bayer, 1 = plain Bayer), "
                             f"got {block!r}") from None


def check_phase(phase, block: int) -> tuple[int, int]:
    """``phase = (dy, dx)`` checked (whole numbers, not text) and reduced modulo the period P = 2 * block (``block``
    checked as :func:`check_block` does: None was Python's TypeError, 2.5 gave float phases)."""
    block = check_block(block)
    try:
        dy, dx = phase
        ok = is_real_number(dy) and is_real_number(dx)
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise EventDataError(f"phase must be (dy, dx), two whole numbers (row, column offset in the tile), got "
                             f"{phase!r}")
    try:
        dy, dx = whole_number(dy, "phase: dy"), whole_number(dx, "phase: dx")
    except EventDataError:
        raise EventDataError(f"phase must hold whole numbers (row, column offset in the tile), got {phase!r}") from None
    P = 2 * block
    return dy % P, dx % P


def period(block: int = QUAD_BAYER) -> int:
    """P = 2 * block: the side of the CFA tile and of one reduced (grey) pixel, in photosites."""
    return 2 * check_block(block)


def photosites_per_window(block: int = QUAD_BAYER) -> dict:
    """Photosites of each colour in one P x P window: {"R": b^2, "G": 2 b^2, "B": b^2, "grey": 4 b^2}."""
    b2 = check_block(block) ** 2
    return {"R": b2, "G": 2 * b2, "B": b2, "grey": 4 * b2}


def cfa_tile(block: int = QUAD_BAYER, phase=(0, 0)) -> np.ndarray:
    """The tile as the sensor sees it from its photosite (0, 0): int8 [P, P] of channel indices."""
    block = check_block(block)
    dy, dx = check_phase(phase, block)
    P = 2 * block
    y, x = np.mgrid[0:P, 0:P]
    return cfa_channel(y, x, (dy, dx), block).astype(np.int8)


def cfa_channel(y, x, phase=(0, 0), block: int = QUAD_BAYER) -> np.ndarray:
    """Colour channel (0 R, 1 G, 2 B) of the photosites at rows ``y`` and columns ``x``.

    ``TILE[(y + dy) % P, (x + dx) % P]``: the block row is ``((y + dy) % P) // block``, the block
    column likewise, and the block colour is R G / G B. ``y`` and ``x`` are int arrays of one shape
    (broadcast); returns int64 of that shape. Whole numbers given as floats are taken; fractions, NaN and
    text are refused (a photosite has whole coordinates), and so are shapes that do not broadcast.
    """
    block = check_block(block)
    dy, dx = check_phase(phase, block)
    P = 2 * block
    y = _photosites(y, "y", "rows")
    x = _photosites(x, "x", "columns")
    try:
        np.broadcast_shapes(y.shape, x.shape)
    except ValueError:
        raise EventDataError(f"y= (shape {y.shape}) and x= (shape {x.shape}) must have one shape (or broadcast): "
                             "one row and one column per photosite") from None
    return TILE_COLOURS[((y + dy) % P) // block, ((x + dx) % P) // block].astype(np.int64)


def _photosites(a, name: str, what: str) -> np.ndarray:
    """Photosite coordinates as int64; EventDataError naming ``name`` when they are not whole numbers."""
    try:
        arr = np.asarray(host_array(a))
    except (TypeError, ValueError):
        arr = np.asarray([None])
    if arr.dtype.kind in "iu":
        return arr.astype(np.int64)
    if arr.dtype.kind != "f" or not np.all(np.isfinite(arr)) or not np.all(arr == np.round(arr)):
        raise EventDataError(f"{name}= must be whole photosite {what} (integers), got {short_repr(a)}")
    return arr.astype(np.int64)


def cfa_pattern(sensor_size, phase=(0, 0), block: int = QUAD_BAYER) -> np.ndarray:
    """Channel of every photosite of a sensor (H, W): int8 [H, W] (indexed [y, x])."""
    H, W = check_sensor_size(sensor_size)
    y, x = np.mgrid[0:H, 0:W]
    return cfa_channel(y, x, phase, block).astype(np.int8)


def effective_thresholds(C: float, block: int = QUAD_BAYER) -> dict:
    """Log-intensity step carried by one demosaiced event: C / (photosites per window).

    Returns {"grey": C / n, "R": C / n_R, "G": C / n_G, "B": C / n_B}; for Quad Bayer
    C/16, C/4, C/8, C/4 (:mod:`evinr_lite.sim.quadbayer` explains why).
    """
    C = real_number(C, "C", lo=0.0, lo_open=True, hint="a positive contrast threshold in log units (e.g. 0.2)")
    return {name: C / n for name, n in photosites_per_window(block).items()}
