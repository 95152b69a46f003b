"""``interact``: sliders that redraw ONE figure in a live notebook, one static figure elsewhere.

::

    def draw(fig, C=0.2, window=0.02):
        ax = fig.subplots()
        ...

    interact(draw, C=(0.05, 0.5, 0.05, 0.2), window=(0.005, 0.1, 0.005, 0.02), kind=["a", "b"])

Controls:

- ``(min, max, step)`` or ``(min, max, step, default)``: a slider (integer when all are ints);
  without a default the slider starts at the value nearest the middle of the range;
- a list of options: a dropdown starting at the first option;
- ``True`` / ``False``: a checkbox starting there.

In a live front end (an IPython kernel with a ZMQ shell, ipywidgets importable, and fast
mode off) the controls are shown and every change redraws the same figure in place (the
figure lives in an ``Output`` widget; it is cleared and redrawn, not stacked). Anywhere
else (plain Python, tests, CI, or fast mode) the figure is drawn once with the defaults
and shown as a static image. Either way ``interact`` returns an :class:`Interactive`
handle whose ``fig`` is the figure.
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field
from typing import Any, Callable

from ..core.events import EventDataError
from ..core.runtime import fast_mode

__all__ = ["Control", "parse_controls", "interact", "Interactive", "live_frontend"]


@dataclass(frozen=True)
class Control:
    """One parsed control: ``kind`` is "int", "float", "choice" or "bool"."""

    name: str
    kind: str
    default: Any
    min: float | None = None
    max: float | None = None
    step: float | None = None
    options: tuple = ()


def _is_number(v) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, bool)


def _parse_one(name: str, spec) -> Control:
    if isinstance(spec, bool):
        return Control(name, "bool", spec)
    if isinstance(spec, list):
        if not spec:
            raise ValueError(f"control {name!r}: a dropdown needs at least one option, got []")
        return Control(name, "choice", spec[0], options=tuple(spec))
    if isinstance(spec, tuple):
        if len(spec) not in (3, 4) or not all(_is_number(v) for v in spec):
            raise ValueError(f"control {name!r}: a slider is (min, max, step) or (min, max, step, default) "
                             f"with numbers, got {spec!r}")
        if not all(math.isfinite(v) for v in spec):   # inf was Python's OverflowError, or a step taken as 0
            raise ValueError(f"control {name!r}: a slider's numbers must be finite (min, max, step[, default]), "
                             f"got {spec!r}")
        lo, hi, step = spec[:3]
        if not lo < hi:
            raise ValueError(f"control {name!r}: min must be below max, got min={lo}, max={hi}")
        if not step > 0:
            raise ValueError(f"control {name!r}: step must be positive, got {step}")
        is_int = all(isinstance(v, numbers.Integral) for v in spec)
        if len(spec) == 4:
            default = spec[3]
            if not lo <= default <= hi:
                raise ValueError(f"control {name!r}: default {default} is outside [{lo}, {hi}]")
        else:
            k = round((hi - lo) / 2 / step)
            default = lo + k * step
            default = int(default) if is_int else float(default)
        return Control(name, "int" if is_int else "float", default, lo, hi, step)
    raise TypeError(f"control {name!r}: use (min, max, step[, default]) for a slider, a list of options for a "
                    f"dropdown, or True/False for a checkbox; got {type(spec).__name__} {spec!r}")


def parse_controls(**controls) -> list[Control]:
    """Parse ``name=spec`` pairs into :class:`Control` objects (ValueError/TypeError naming the bad one)."""
    return [_parse_one(name, spec) for name, spec in controls.items()]


LIVE_ENV_VAR = "EVINR_LIVE_WIDGETS"   # "1": controls even in fast mode (the browser test); "0": never


def live_frontend() -> bool:
    """True in a live Jupyter kernel with ipywidgets available and fast mode off (``EVINR_LIVE_WIDGETS=1``
    keeps the controls in fast mode, ``EVINR_LIVE_WIDGETS=0`` turns them off everywhere)."""
    import os

    forced = os.environ.get(LIVE_ENV_VAR, "").strip().lower()
    if forced in ("0", "false", "no", "off") or (fast_mode() and forced not in ("1", "true", "yes", "on")):
        return False
    try:
        from IPython import get_ipython
    except ImportError:
        return False
    shell = get_ipython()
    if shell is None or type(shell).__name__ != "ZMQInteractiveShell":
        return False
    try:
        import ipywidgets  # noqa: F401
    except ImportError:
        return False
    return True


def _in_ipython() -> bool:
    try:
        from IPython import get_ipython
    except ImportError:
        return False
    return get_ipython() is not None


@dataclass(eq=False)
class Interactive:
    """What :func:`interact` returns.

    Attributes:
        fig: the one matplotlib figure that is (re)drawn.
        values: the control values of the last drawing.
        controls: the parsed controls.
        widget: the ipywidgets container in a live front end, else None.
    """

    fig: Any
    draw: Callable
    values: dict
    controls: list[Control]
    widget: Any = None
    n_draws: int = field(default=0)

    def redraw(self, **values) -> None:
        """Clear the figure and draw it again with the current values updated by ``values``."""
        unknown = set(values) - {c.name for c in self.controls}
        if unknown:
            raise TypeError(f"unknown control(s) {sorted(unknown)}; known: {[c.name for c in self.controls]}")
        self.values.update(values)
        self.fig.clf()
        self.draw(self.fig, **self.values)
        self.n_draws += 1

    def _ipython_display_(self):
        # The figure (and the controls) were displayed by interact itself; showing the
        # handle again would stack a second copy.
        pass


def _make_widget(c: Control):
    import ipywidgets as w

    style = {"description_width": "initial"}
    if c.kind == "int":
        return w.IntSlider(value=c.default, min=c.min, max=c.max, step=c.step, description=c.name,
                           continuous_update=False, style=style)
    if c.kind == "float":
        return w.FloatSlider(value=c.default, min=c.min, max=c.max, step=c.step, description=c.name,
                             continuous_update=False, readout_format=".3g", style=style)
    if c.kind == "choice":
        return w.Dropdown(options=list(c.options), value=c.default, description=c.name, style=style)
    return w.Checkbox(value=c.default, description=c.name, style=style)


MAX_FIGSIZE = 100.0   # inches per side: wider than any screen at matplotlib's 100 dpi


def check_figsize(figsize):
    """(width, height) in inches, each a finite number in (0, MAX_FIGSIZE]; None: matplotlib's default. Else an
    EventDataError (a ValueError, as before) naming figsize= (the figures' one check of a figure size)."""
    if figsize is None:
        return None
    try:
        w, h = figsize
        ok = all(_is_number(v) and math.isfinite(v) and 0 < v <= MAX_FIGSIZE for v in (w, h))
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise EventDataError(f"figsize= must be (width, height) in inches, two numbers in (0, {MAX_FIGSIZE:g}] "
                         f"(e.g. (8, 4)), or None for matplotlib's default; got {figsize!r}")
    return figsize


def interact(draw: Callable, *, figsize=(8, 4), **controls) -> Interactive:
    """Draw ``draw(fig, **values)`` with controls; see the module docstring.

    Args:
        draw: ``draw(fig, **values)`` draws into the (cleared) figure ``fig``, e.g. with
            ``ax = fig.subplots()``. It must not create figures of its own.
        figsize: figure size in inches.
        **controls: ``name=spec``; see the module docstring for the specs.

    Returns:
        :class:`Interactive` (``.fig`` is the figure).
    """
    if not callable(draw):
        raise TypeError(f"draw must be a function draw(fig, **values), got {type(draw).__name__}")
    figsize = check_figsize(figsize)
    parsed = parse_controls(**controls)
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=figsize)
    # Closed at once: the inline backend then never shows it on its own, so the only copies
    # are the ones displayed below (the static image, or the live Output widget's content).
    plt.close(fig)
    handle = Interactive(fig, draw, {c.name: c.default for c in parsed}, parsed)

    if not live_frontend():
        handle.redraw()
        if _in_ipython():
            from IPython.display import display
            display(fig)
        return handle

    import ipywidgets as w
    from IPython.display import clear_output, display

    out = w.Output()
    widgets = {c.name: _make_widget(c) for c in parsed}

    def on_change(_change):
        with out:
            clear_output(wait=True)
            try:
                handle.redraw(**{name: wid.value for name, wid in widgets.items()})
                display(fig)
            except Exception:  # show the error where the figure was, not in a hidden log
                import traceback
                traceback.print_exc()

    for wid in widgets.values():
        wid.observe(on_change, names="value")
    handle.widget = w.VBox([w.HBox(list(widgets.values())), out]) if widgets else out
    display(handle.widget)
    handle.redraw()
    with out:
        display(fig)
    return handle
