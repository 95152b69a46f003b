"""Hints read off a wrong output: patterns any exercise can show, recognised from the output and the inputs alone.

Given the learner's output and the expected one on the failing input, each hint here returns a sentence naming a
likely mistake, or None, and runs no function: :func:`generic_hint` (a flipped sign, a constant factor or offset,
exp or log once too often, a shift by one position, a pair of outputs swapped, a scatter-add that kept one
contribution per repeated index), :func:`one_based_hint` (indices counted from 1),
:func:`swapped_pair_hint` (two to four outputs in another order) and
:func:`size_from_events_hint` (an image sized by the events, not the sensor) and :func:`aliased_rows_hint` (every row
the same: the row index not used, or, where the function's code multiplies a list of lists, a nested list made with
``[[0.0] * W] * H``). Two conditions read off the inputs
choose among hints: :func:`has_repeated_index` (a scatter-add is likely) and :func:`non_square` (an IndexError on a
sensor that is not square). The mistakes recognised by running a wrong version of the reference (the wrong image
axis among them) are in :mod:`.mistakes`; those that show only across inputs (one number off by the same factor
on every input among them) in :mod:`.across_calls`.
"""
from __future__ import annotations

import itertools

import numpy as np

from .learner_calls import multiplies_rows
from .outputs import STACK_T_ADVICE, compare_outputs, is_tensor, to_numpy
from .protocol import ExerciseLike


def generic_hint(got, expected, indexed: bool = False) -> str | None:
    """Recognise a few common patterns between a wrong and a right numeric output.

    ``indexed``: the inputs hold an index array with repeated entries (event coordinates, say),
    so a scatter-add that kept one contribution per index is a likely mistake.
    """
    try:
        g = to_numpy(got).astype(np.float64).ravel()
        e = to_numpy(expected).astype(np.float64).ravel()
    except Exception:
        return None
    if g.shape != e.shape or g.size == 0 or not np.all(np.isfinite(e)):
        return None
    if not np.all(np.isfinite(g)):
        return ("the result holds NaN or inf where every expected value is finite: a division by zero, or the log "
                "of zero or of a negative number?")
    scale = max(np.abs(e).max(), 1e-12)
    tol = 1e-6 * scale
    if to_numpy(got).dtype == bool and to_numpy(expected).dtype == bool and g.size > 1 and np.all(g != e):
        return "the mask is inverted everywhere: True where False is expected and the other way round (`~` once too often?)"
    nz = np.abs(e) > tol
    # a single non-zero entry of an array flipped may be anything else that lands on minus it: say so only when
    # several entries agree (a single number, a scalar result, may have its sign flipped on its own)
    if np.all(np.abs(g + e) <= tol) and nz.sum() >= (1 if e.size == 1 else 2):
        return "the sign is flipped everywhere"
    with np.errstate(all="ignore"):
        if np.all(np.abs(e) < 700) and np.allclose(g, np.exp(e), rtol=1e-6, atol=1e-9):
            return ("the result is np.exp of the expected values: the quantity is a log intensity (or a change of "
                    "one), so no np.exp (exp(L) is the linear intensity)")
        if np.all(e > 0) and np.allclose(g, np.log(e), rtol=1e-6, atol=1e-9):
            return "the result is np.log of the expected values: no np.log on this quantity (it is not a log yet)"
    # one number (or one non-zero entry) is always some factor of another: say so only when several agree
    if nz.sum() >= 2 and np.all(np.abs(g[~nz]) <= tol):
        ratios = g[nz] / e[nz]
        if np.ptp(ratios) <= 1e-6 * max(1.0, abs(ratios[0])) and abs(ratios[0] - 1) > 1e-6 \
                and abs(ratios[0]) > 1e-12:         # a factor 0 is a result of zeros, not a scaling
            return f"off by a constant factor: got {ratios[0]:.4g} x the expected values" + unit_note(ratios[0])
    if g.size > 1:
        d = g - e
        if np.ptp(d) <= tol and abs(d[0]) > tol:
            return f"off by a constant offset of {d[0]:.4g}"
        # a shift is recognisable only in a series of several distinct values (not in a short mask)
        if g.size >= 4 and np.unique(e).size > 2 and (np.allclose(g[1:], e[:-1], atol=tol)
                                                      or np.allclose(g[:-1], e[1:], atol=tol)):
            return "the values are shifted by one position; check the window/boundary indexing (< versus <=)"
    axes = _axes_hint(to_numpy(got), to_numpy(expected), tol)
    if axes:
        return axes
    if indexed and _one_contribution_per_entry(g, e, tol):
        return ("each entry holds at most one contribution where several are expected: with fancy indexing, "
                "`a[idx] += v` adds only once for a repeated index; accumulate with `np.add.at(a, idx, v)` "
                "(or `np.bincount(idx, weights=v)`, or `index_put_(..., accumulate=True)` in torch)")
    return None


def unit_note(ratio: float) -> str:
    """A word on a factor that is a power of 1000: a unit conversion."""
    k = np.log10(abs(ratio)) / 3 if ratio else 0.0
    if ratio > 0 and abs(k - round(k)) < 1e-6 and round(k) != 0:
        return (" (a power of 1000: a unit conversion? the kit's times are seconds throughout, rates per second: "
                "no milliseconds or microseconds)")
    return ""


def _axes_hint(g: np.ndarray, e: np.ndarray, tol: float) -> str | None:
    """A pair of outputs (x part, y part) returned in the wrong order."""
    g = np.asarray(g, dtype=np.float64)
    e = np.asarray(e, dtype=np.float64)
    if g.shape != e.shape or g.ndim < 2 or g.shape[0] != 2 or g[0].size < 2:
        return None
    if np.allclose(g[::-1], e, atol=tol) and not np.allclose(g, e, atol=tol):
        return ("the two outputs are swapped: return them in the order the docstring gives (for image "
                "differences, x is the column axis (axis -1, `np.diff(a, axis=-1)`), y the row axis (axis -2))")
    return None


def axes_order_hint(got, expected, rtol: float, atol: float) -> str | None:
    """The expected values with the axes in another order: a transposed image ([x, y] for [y, x]), a stack's axes
    reversed by ``.T`` (which reverses all of them, not only the last two), or the transposed image's entries
    read in order into the expected shape (``.reshape(H, W)`` of a [x, y] array, which never moves an entry)."""
    import itertools
    try:
        g, e = to_numpy(got), to_numpy(expected)
        if g.dtype == object or e.ndim < 2 or g.shape != e.shape or e.size < 4 or e.ndim > 5 \
                or compare_outputs(g, np.broadcast_to(e.reshape(-1)[:1], e.shape), rtol, atol) is None:
            return None                      # (anything matches a constant result)
        for perm in itertools.permutations(range(e.ndim)):
            t = np.transpose(e, perm)
            if perm == tuple(range(e.ndim)) or t.shape != g.shape or compare_outputs(g, t, rtol, atol) is not None:
                continue
            if perm == tuple(range(e.ndim - 2)) + (e.ndim - 1, e.ndim - 2):
                what = "the expected one transposed" if e.ndim == 2 else "the expected images each transposed"
                return (f"the result is {what}: rows and columns (y and x) swapped; an image is indexed [y, x], rows "
                        "first (`H, W = sensor_size`, `np.zeros((H, W))`, `frame[y, x]`), and a `.T` too many (or one "
                        "missing) transposes it, as does `.reshape(H, W)` of an image built [x, y] on a square sensor")
            return (f"the result holds the expected values with the axes in another order (the expected array "
                    f"transposed by {perm}): {STACK_T_ADVICE}, or build the array in the expected order from the "
                    "start")
        if e.shape[-1] != e.shape[-2] and \
                compare_outputs(g, np.swapaxes(e, -1, -2).reshape(e.shape), rtol, atol) is None:
            return ("the result holds the transposed result's entries, in their order, poured into the expected "
                    "shape: `.reshape(H, W)` (np.reshape, np.resize) of an image built [x, y] keeps the order of the "
                    "entries and does not transpose, so the rows come out scrambled; transpose with `.T` (np.swapaxes("
                    "a, -1, -2)), or build the image [y, x] from the start")
    except Exception:
        return None
    return None


def one_based_hint(got, expected, rtol: float, atol: float) -> str | None:
    """An image (or a stack of images) rolled by one row and/or one column towards the start: the values of row
    (column) 0 sit in the last one. That is indexing counted from 1, ``a[y - 1, x - 1]``: index -1 wraps round."""
    try:
        g, e = to_numpy(got), to_numpy(expected)
        if g.dtype == object or g.shape != e.shape or e.ndim < 2 or min(e.shape[-2:]) < 2:
            return None
        for shift, axes, what in (((-1, -1), (-2, -1), "one row and one column"), ((-1,), (-2,), "one row"),
                                  ((-1,), (-1,), "one column")):
            if compare_outputs(g, np.roll(e, shift, axis=axes), rtol, atol) is None:
                return (f"the image is shifted by {what}, and the first one's values sit in the last one: indices "
                        "counted from 1 (`a[y - 1, x - 1]`) put row (column) 0 at index -1, which wraps round to the "
                        "end; numpy counts from 0, so index with y and x as they are")
    except Exception:
        return None
    return None


def _one_contribution_per_entry(g: np.ndarray, e: np.ndarray, tol: float) -> bool:
    """True when ``g`` looks like a scatter-add that kept one contribution per repeated index.

    The sign of that mistake: the non-zero entries of ``g`` all have one magnitude (one event's
    contribution), sit where ``e`` is non-zero or where contributions cancelled, and ``e`` has at
    least one entry made of several contributions (a larger magnitude).
    """
    nzg = np.abs(g) > tol
    if nzg.sum() < 2 or g.size < 2:      # a single non-zero entry always has "one magnitude"
        return False
    mags = np.abs(g[nzg])
    unit = mags[0]
    if np.ptp(mags) > 1e-6 * max(unit, 1e-12):
        return False
    differ = np.abs(g - e) > tol
    return bool(differ.any() and np.any(np.abs(e[differ]) > unit * (1 + 1e-6)))


def _is_repeated_index(v) -> bool:
    """An integer index array (values beyond the +-1 of polarities) in which some index repeats."""
    a = to_numpy(v) if is_tensor(v) else v
    if not isinstance(a, np.ndarray) or a.ndim != 1 or a.dtype.kind not in "iu" or a.size < 2:
        return False
    return bool(np.abs(a).max() > 1 and np.unique(a).size < a.size)


def has_repeated_index(args: tuple, kwargs: dict) -> bool:
    """Any input (or an input's ``x`` / ``y`` attribute, as on Events) that is a repeated index array."""
    for v in list(args) + list(kwargs.values()):
        for item in (v, getattr(v, "x", None), getattr(v, "y", None)):
            try:
                if item is not None and _is_repeated_index(item):
                    return True
            except Exception:
                continue
    return False


def non_square(args, kwargs) -> bool:
    """True when an input names a sensor (a ``sensor_size`` argument, or events carrying one) with H != W."""
    for v in (*args, *kwargs.values()):
        size = v if isinstance(v, tuple) and len(v) == 2 and all(isinstance(a, (int, np.integer)) for a in v) \
            else getattr(v, "sensor_size", None)
        if size is not None and len(size) == 2 and int(size[0]) != int(size[1]):
            return True
    return False


def size_from_events_hint(args, kwargs, got, expected) -> str | None:
    """An image smaller than the sensor (the last rows or columns missing) where an input gives the sensor's
    size: the size was read off the largest event coordinates."""
    if not any(isinstance(v, tuple) and len(v) == 2 and all(isinstance(a, (int, np.integer)) for a in v)
               or getattr(v, "sensor_size", None) is not None for v in (*args, *kwargs.values())):
        return None
    try:
        g, e = to_numpy(got), to_numpy(expected)
    except Exception:
        return None
    if g.ndim < 2 or g.ndim != e.ndim or g.shape[:-2] != e.shape[:-2] or g.shape == e.shape:
        return None
    if all(a <= b for a, b in zip(g.shape[-2:], e.shape[-2:])):
        return ("the image is smaller than the sensor: its size is sensor_size (H, W = sensor_size), not the largest "
                "event coordinates plus one (y.max() + 1, x.max() + 1): pixels that never fired are part of it too")
    return None


SWAPPED = "the two outputs are swapped: return them in the order the docstring gives"
REORDERED = "the outputs are right, but in another order: "   # the start of a hint for three or four outputs


def swapped_pair_hint(ex: ExerciseLike, got, expected) -> str | None:
    """Outputs returned in another order: a pair swapped, or three or four outputs (esim_interval's times,
    polarities and level) in any other order, said output by output."""
    if not (isinstance(expected, (tuple, list)) and 2 <= len(expected) <= 4 and isinstance(got, (tuple, list))
            and len(got) == len(expected)):
        return None
    for order in itertools.permutations(range(len(got))):
        if order == tuple(range(len(got))):
            continue
        moved = tuple(got[j] for j in order)          # moved[i] = got[order[i]]: is it expected[i]?
        try:
            if compare_outputs(moved, expected, ex.rtol, ex.atol) is None or (
                    ex.compare is not None and ex.compare(moved, expected) is None):
                if len(got) == 2:
                    return SWAPPED
                where = ", ".join(f"output [{j}] is the expected [{i}]" for i, j in enumerate(order) if i != j)
                return REORDERED + where + ": return them in the order the docstring gives"
        except Exception:
            continue
    return None


def aliased_rows_hint(got, expected, rtol: float, atol: float, fn=None) -> str | None:
    """Every row of an image (axis -2) the same, where the expected rows differ (a sum then holds the column sums of
    the expected image in every row). Where ``fn``'s code multiplies a list that holds a list
    (:func:`.learner_calls.multiplies_rows`), a nested list made as ``[[0.0] * W] * H`` holds H references to one
    row list, so each write lands in every row; otherwise (numpy, say) the row index is not used."""
    try:
        g, e = to_numpy(got).astype(np.float64), to_numpy(expected).astype(np.float64)
    except Exception:
        return None
    if g.shape != e.shape or g.ndim < 2 or g.shape[-2] < 2 or g.shape[-1] < 1 or not np.all(np.isfinite(g)):
        return None
    same = np.broadcast_to(g[..., :1, :], g.shape)
    if not np.allclose(g, same, rtol=rtol, atol=atol) or np.allclose(e, e[..., :1, :], rtol=rtol, atol=atol) \
            or np.allclose(g, np.broadcast_to(g[..., :1, :1], g.shape), rtol=rtol, atol=atol):
        return None                         # (a result constant everywhere is some other mistake)
    summed = np.allclose(g, np.broadcast_to(e.sum(axis=-2, keepdims=True), e.shape), rtol=rtol, atol=atol)
    what = " (each holds the sums of the expected columns)" if summed else ""
    if fn is not None and multiplies_rows(fn):
        return (f"every row of the result is the same{what}, where the expected rows differ: a nested list made as "
                "`[[0.0] * W] * H` holds H references to one row, so `frame[y][x] += ...` writes column x of every "
                "row; make each row its own list (`[[0.0] * W for _ in range(H)]`), or use np.zeros((H, W)) and "
                "index `frame[y, x]`")
    return (f"every row of the result is the same{what}, where the expected rows differ: the row index is not "
            "used (a write to `frame[:, x]`, or a value that does not depend on y); index the row too, "
            "`frame[y, x]` (rows first: y is the row)")
