"""interact (static and live paths) and the plotting helpers."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from evinr_lite.viz import signals as plotting, widgets  # noqa: E402
from evinr_lite.viz.frames import plot_histories  # noqa: E402
from evinr_lite.viz.widgets import Control, interact, parse_controls  # noqa: E402


def test_parse_controls():
    c = {x.name: x for x in parse_controls(C=(0.05, 0.5, 0.05, 0.2), n=(1, 9, 2), kind=["a", "b"], on=True,
                                           w=(0.0, 1.0, 0.1))}
    assert c["C"] == Control("C", "float", 0.2, 0.05, 0.5, 0.05)
    assert c["n"].kind == "int" and c["n"].default == 5  # middle of the range, on the step grid
    assert c["kind"].kind == "choice" and c["kind"].default == "a" and c["kind"].options == ("a", "b")
    assert c["on"].kind == "bool" and c["on"].default is True
    assert c["w"].default == pytest.approx(0.5)


@pytest.mark.parametrize("spec, error, match", [
    ((1.0, 0.0, 0.1), ValueError, "min must be below max"),
    ((0.0, 1.0, 0.0), ValueError, "step must be positive"),
    ((0.0, 1.0, 0.1, 2.0), ValueError, "outside"),
    ((0.0, 1.0), ValueError, "min, max, step"),
    (("a", "b", "c"), ValueError, "min, max, step"),
    ([], ValueError, "at least one option"),
    ("text", TypeError, "slider"),
    (3.0, TypeError, "slider"),
])
def test_bad_controls_are_named(spec, error, match):
    with pytest.raises(error, match=match) as info:
        parse_controls(C=spec)
    assert "'C'" in str(info.value)


def test_headless_draws_once_with_defaults_and_returns_the_figure():
    calls = []

    def draw(fig, C, kind):
        calls.append((C, kind))
        ax = fig.subplots()
        ax.plot([0, 1], [0, C])

    before = plt.get_fignums()
    h = interact(draw, C=(0.1, 1.0, 0.1, 0.3), kind=["x", "y"])
    assert calls == [(0.3, "x")]
    assert isinstance(h.fig, matplotlib.figure.Figure) and len(h.fig.axes) == 1
    assert h.widget is None and h.values == {"C": 0.3, "kind": "x"} and h.n_draws == 1
    assert plt.get_fignums() == before  # no extra open figure for inline backends to show again
    h.redraw(C=0.5)  # redraws the same figure, cleared
    assert calls[-1] == (0.5, "x") and len(h.fig.axes) == 1
    with pytest.raises(TypeError, match="unknown control"):
        h.redraw(D=1)


def test_headless_in_fast_mode_even_when_a_frontend_exists(monkeypatch):
    monkeypatch.setenv("EVINR_FAST", "1")
    assert widgets.live_frontend() is False


def test_bad_draw_argument():
    with pytest.raises(TypeError, match="draw"):
        interact("not a function", C=(0, 1, 1))


def test_live_path_redraws_one_figure(monkeypatch):
    pytest.importorskip("ipywidgets")
    monkeypatch.setattr(widgets, "live_frontend", lambda: True)
    calls = []
    before = plt.get_fignums()                   # figures an earlier test in this process left open are not ours

    def draw(fig, C, show):
        calls.append((C, show))
        fig.subplots().plot([0, 1], [0, C])

    h = interact(draw, C=(0.1, 1.0, 0.1, 0.3), show=True)
    assert calls == [(0.3, True)] and h.widget is not None
    slider = h.widget.children[0].children[0]
    fig = h.fig
    slider.value = 0.7
    assert calls[-1] == (pytest.approx(0.7), True)
    assert h.fig is fig and len(fig.axes) == 1 and h.n_draws == 2
    assert plt.get_fignums() == before           # the live figure is not a pyplot one: nothing new to close


# ---- plotting ------------------------------------------------------------------------

def test_plot_signal_and_events_draws_signal_levels_and_ticks():
    t = np.linspace(0, 1, 101)
    L = np.sin(2 * np.pi * t)
    te = np.array([0.1, 0.2, 0.6, 0.7])
    pe = np.array([1, 1, -1, -1])
    ax = plotting.plot_signal_and_events(t, L, (te, pe), C=0.5)
    assert np.allclose(ax.lines[0].get_ydata(), L)
    ticks = ax.collections
    assert len(ticks) == 2 and all(len(c.get_segments()) == 2 for c in ticks)
    assert any(line.get_marker() == "^" for line in ax.lines)
    plt.close(ax.figure)


def test_plot_reconstruction_and_loss():
    t = np.linspace(0, 1, 11)
    ax = plotting.plot_reconstruction_1d(t, {"a": t, "b": 2 * t}, truth=t)
    assert [line.get_label() for line in ax.lines] == ["true L(t)", "a", "b"]
    plt.close(ax.figure)
    hist = {"loss": [1.0, 0.1, 0.0], "temporal": [1.0, 0.1, 0.0]}
    ax = plot_histories({"loss": hist, "temporal": hist["temporal"]})
    assert len(ax.lines) == 2 and ax.get_yscale() == "log"
    plt.close(ax.figure)
    res = {"window": np.array([0.01, 0.1]), "taylor": np.array([1e-3, 1e-1]), "events": np.array([1.0, 0.1])}
    ax = plotting.plot_window_errors(res, C=0.1)
    assert len(ax.lines) == 3
    plt.close(ax.figure)
