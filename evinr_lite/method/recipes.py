"""Named recipes of the solver and the contrast threshold C of a run: checked, resolved, printed.

    config = recipe_config("paper", n_iters=90, C=0.2)     # the paper's recipe, c2f at 30 and 60
    C = contrast_option(C)                                 # None, "auto", a number or (c_pos, c_neg)
    C, source, fit = resolve_contrast(rec, C)              # "auto" -> fitted from the APS frames

C is in log units per event; times are seconds on the recording's clock.
"""
from __future__ import annotations

import numpy as np

from ..core.checks import whole_number
from ..core.events import EventDataError
from ..core.recording import Recording
from .binning import as_thresholds
from .config import EvINRConfig
from .contrast import fit_contrast
from .tonemap import DISPLAY_MEANS

__all__ = ["RECIPES", "recipe_config", "DEFAULT_C", "contrast_option", "format_contrast", "resolve_contrast"]

RECIPES = {"kit": EvINRConfig, "paper": EvINRConfig.paper, "v0_1": EvINRConfig.v0_1}
DEFAULT_C = EvINRConfig.C   # the paper's threshold for DAVIS recordings (IJRR, HQF): EvINRConfig's own default


def recipe_config(recipe: str = "kit", n_iters: int | None = None, tonemap: str | None = None,
                  **fields) -> EvINRConfig:
    """The EvINRConfig of a named recipe: "kit" (``EvINRConfig()``, the default), "paper" (the paper's
    recipe exactly) or "v0_1" (the kit's default before the scene zoo).

    ``n_iters`` None keeps the recipe's own (kit: no Adam iteration, the output layer solved in closed
    form; paper: 300). Given, it sets the Adam iterations; for the recipes with coarse-to-fine the two
    bisections move to n_iters / 3 and 2 n_iters / 3 (the paper's 100 and 200 of 300).
    ``tonemap`` None keeps the recipe's own display; "linear" or "reinhard" shows it that way, at that
    tone map's own level (:data:`~evinr_lite.method.tonemap.DISPLAY_MEANS`) unless ``display_mean`` is
    among ``fields``.
    """
    if not isinstance(recipe, str) or recipe not in RECIPES:
        raise EventDataError(f"recipe= must be one of {tuple(RECIPES)}, got {recipe!r}")
    make = RECIPES[recipe]
    if n_iters is not None:
        n_iters = whole_number(n_iters, "n_iters", lo=0)   # 2.5 ran 2, "90" and True were taken
        fields["n_iters"] = n_iters
        if make().coarse_to_fine:
            c2f = (n_iters // 3, 2 * n_iters // 3) if n_iters >= 3 else ()
            fields.update(c2f_iters=c2f, coarse_to_fine=bool(c2f))
    if tonemap is not None:
        if not isinstance(tonemap, str) or tonemap not in DISPLAY_MEANS:
            raise EventDataError(f"tonemap= must be one of {tuple(DISPLAY_MEANS)} (or None: the recipe's own), "
                                 f"got {tonemap!r}")
        fields["tonemap"] = tonemap
        fields.setdefault("display_mean", DISPLAY_MEANS[tonemap])   # a display_mean given stays
    return make(**fields)


def contrast_option(C):
    """A run's ``C=`` checked: None (the file's, else DEFAULT_C), a positive number, a pair
    (c_pos, c_neg) of positive numbers, or "auto" (fitted from the APS frames: :func:`resolve_contrast`).
    Returns None, "auto", a float or a (c_pos, c_neg) tuple; EventDataError naming C= otherwise.
    The one check of a run's C (the command line only turns its text into numbers)."""
    if C is None or (isinstance(C, str) and C == "auto"):
        return C
    if isinstance(C, (str, bytes)):
        raise EventDataError(f"C= must be a positive number, a pair (c_pos, c_neg) or 'auto', got {C!r}")
    pair = as_thresholds(C, "C")   # the one rule of a threshold's value (EvINRConfig applies it too)
    return pair if isinstance(C, (tuple, list, np.ndarray)) and np.ndim(C) == 1 else pair[0]


def format_contrast(C) -> str:
    """'0.2' for one threshold, 'C+ 0.22 / C- 0.18' for a pair (a resolved C: not None, not 'auto', and one
    that EvINRConfig accepts: each threshold in (0, MAX_C])."""
    as_thresholds(C, "C")   # None, 'auto', text, NaN or one value as a pair were Python's format errors or 'nan'
    return f"{C:g}" if np.ndim(C) == 0 else f"C+ {C[0]:.4g} / C- {C[1]:.4g}"


def resolve_contrast(rec: Recording, C, path=None, log=print, *, colour: bool = False):
    """(C for EvINRConfig, where it came from, the ContrastFit or None) for a checked ``C=`` option.

    "auto" fits C+ and C- from the recording's APS frames in the window ``rec.meta["window"]``
    (seconds; default: the events' span) with :func:`evinr_lite.method.contrast.fit_contrast` and
    logs the fit with its uncertainty; None takes the file's C (``rec.meta["C"]``), else DEFAULT_C.
    Raises EventDataError when "auto" finds no frames or too few usable ones (the message says to
    pass a number instead), or when ``colour`` is given a pair or "auto".
    """
    fit = None
    if C == "auto":
        lo, hi = rec.meta.get("window") or (float(rec.events.t[0]), float(rec.events.t[-1]))
        if rec.frames is None or len(rec.frames) < 2:
            n = 0 if rec.frames is None else len(rec.frames)
            raise EventDataError(f"{path}: C='auto' fits C from the recording's APS frames, but the window "
                                 f"[{lo:.6f}, {hi:.6f}] s holds {n} frame(s) (2 or more needed); pass a number instead "
                                 "(e.g. C=0.2), or widen the window with t_start=/t_end=")
        try:
            fit = fit_contrast(rec.frames, rec.events)
        except EventDataError as err:
            raise EventDataError(f"{path}: C='auto' could not fit C from the frames in [{lo:.6f}, {hi:.6f}] s: "
                                 f"{err}") from None
        log(f"C from the APS frames: {fit}")
        C, source = fit.C, "fitted from the APS frames (auto)"
    elif C is not None:
        source = "given"
    else:
        source = ("from the file" if rec.meta.get("C") else
                  "default, the paper's (set it with --C, or C= in Python; --C auto fits it from APS frames)")
        C = float(rec.meta.get("C") or DEFAULT_C)
    if colour and np.ndim(C) != 0:
        raise EventDataError("colour reconstruction takes one C (the photosites' threshold), not a pair or 'auto'; "
                             "pass a number (e.g. C=0.2)")
    return C, source, fit
