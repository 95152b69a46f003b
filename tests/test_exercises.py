"""Exercise checks and fallbacks, and the reference solutions of notebook 01 (evinr_lite.teaching.pde1d)."""
import warnings

import numpy as np
import pytest
import torch

from evinr_lite.teaching import exercises, pde1d
from evinr_lite.method.binning import events_to_frames
from evinr_lite.core.events import Events
from evinr_lite.teaching.exercises import ExerciseWarning


def _ref_scaled_cumsum(x, C):
    return C * np.cumsum(x)


def _inputs(rng):
    return [dict(x=rng.choice([-1.0, 1.0], 6), C=0.2), dict(x=rng.choice([-1.0, 1.0], 9), C=0.5)]


@pytest.fixture
def toy():
    exercises.register("toy_cumsum", _ref_scaled_cumsum, _inputs,
                       hints={"did you forget the sign of the polarity?": lambda x, C: C * np.cumsum(np.abs(x))})
    yield "toy_cumsum"
    exercises.unregister("toy_cumsum")


def _solution_with_markers(x, C):
    ### BEGIN SOLUTION
    return C * np.cumsum(x)
    ### END SOLUTION


def _student_stub(x, C):
    raise NotImplementedError


def test_correct_function_passes(toy, capsys):
    assert exercises.check(toy, _solution_with_markers) is True
    out = capsys.readouterr().out
    assert out.startswith("✓ toy_cumsum") and "2 inputs" in out
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert exercises.use(toy, _solution_with_markers) is _solution_with_markers


def test_stub_is_not_done_and_falls_back_with_a_warning(toy, capsys):
    assert exercises.check(toy, _student_stub) is False
    assert "not done yet" in capsys.readouterr().out
    with pytest.warns(ExerciseWarning, match="toy_cumsum.*not done yet.*reference solution"):
        fn = exercises.use(toy, _student_stub)
    assert fn is _ref_scaled_cumsum
    out = capsys.readouterr().out
    assert "⚠ Exercise 'toy_cumsum' is not finished" in out and "reference solution" in out
    assert "does not pass" not in out


def test_a_finished_but_wrong_function_does_not_pass_yet_rather_than_unfinished(toy, capsys):
    wrong = lambda x, C: C * np.cumsum(np.abs(x))  # noqa: E731 - finished, but wrong
    with pytest.warns(ExerciseWarning, match="toy_cumsum' does not pass the check yet.*reference solution"):
        fn = exercises.use(toy, wrong)
    assert fn is _ref_scaled_cumsum
    out = capsys.readouterr().out
    assert "⚠ Exercise 'toy_cumsum' does not pass the check yet" in out and "not finished" not in out


def test_fancy_index_plus_equals_gets_the_add_at_hint(capsys):
    def ref(idx, w, n):
        out = np.zeros(n)
        np.add.at(out, idx, w)
        return out

    def fancy(idx, w, n):
        out = np.zeros(n)
        out[idx] += w  # a repeated index is added once
        return out

    exercises.register("toy_scatter", ref, lambda rng: [dict(idx=np.array([0, 2, 2, 3, 3, 3]), w=np.full(6, 0.2), n=5)])
    exercises.register("toy_sum", lambda x, C: C * np.cumsum(x), lambda rng: [dict(x=np.array([1.0, 1.0, -1.0]), C=0.2)])
    try:
        assert not exercises.check("toy_scatter", fancy)
        assert "np.add.at" in capsys.readouterr().out
        # no index array among the inputs: the same pattern of values gets no scatter-add hint
        assert not exercises.check("toy_sum", lambda x, C: C * x)
        assert "np.add.at" not in capsys.readouterr().out
    finally:
        exercises.unregister("toy_scatter")
        exercises.unregister("toy_sum")


def test_differences_along_the_wrong_axes_get_an_axis_hint(capsys):
    img = np.random.default_rng(1).normal(size=(4, 5))
    ref = lambda a: (np.diff(a, axis=-1)[:-1], np.diff(a, axis=-2)[:, :-1])  # noqa: E731 - (dx, dy), 3 x 4 each
    swapped = lambda a: ref(a)[::-1]  # noqa: E731
    wrong_axis = lambda a: np.diff(a, axis=-2)[:, :-1]  # noqa: E731 - rows instead of columns
    exercises.register("toy_grad", ref, lambda rng: [dict(a=img)])
    exercises.register("toy_dx", lambda a: ref(a)[0], lambda rng: [dict(a=np.random.default_rng(2).normal(size=(4, 4)))])
    try:
        assert not exercises.check("toy_grad", swapped)
        out = capsys.readouterr().out
        assert "swapped" in out or "wrong image axis" in out
        assert not exercises.check("toy_dx", wrong_axis)
        assert "wrong image axis" in capsys.readouterr().out
    finally:
        exercises.unregister("toy_grad")
        exercises.unregister("toy_dx")


def test_wrong_values_name_the_input_the_index_and_the_hint(toy, capsys):
    assert not exercises.check(toy, lambda x, C: C * np.cumsum(np.abs(x)))
    out = capsys.readouterr().out
    assert "✗ toy_cumsum" in out and "input #1 of 2" in out
    assert "at index" in out and "got" in out and "expected" in out
    assert "did you forget the sign of the polarity?" in out


def test_generic_hints(toy, capsys):
    exercises.check(toy, lambda x, C: np.cumsum(x))  # forgot C: a constant factor
    assert "constant factor" in capsys.readouterr().out
    exercises.check(toy, lambda x, C: -C * np.cumsum(x))
    assert "sign is flipped" in capsys.readouterr().out
    exercises.check(toy, lambda x, C: C * np.cumsum(x) + 1.0)
    assert "constant offset of 1" in capsys.readouterr().out


@pytest.mark.parametrize("fn, message", [
    (lambda x, C: C * np.cumsum(x)[:-1], "wrong shape"),
    (lambda x, C: np.cumsum(x).astype(int), "wrong dtype: got integer"),
    (lambda x, C: None, "returned None"),
    (lambda x, C: x[100], "raised IndexError"),
    (lambda x, C: "text", "expected numbers"),
    (42, "expected a function"),
])
def test_structural_problems_are_named(toy, capsys, fn, message):
    assert exercises.check(toy, fn) is False  # never raises
    assert message in capsys.readouterr().out


def test_inputs_are_copied_so_mutation_does_not_leak(toy):
    def mutating(x, C):
        x *= 0
        return C * np.cumsum(x)
    assert not exercises.check(toy, mutating, verbose=False)
    assert exercises.check(toy, _solution_with_markers, verbose=False)


def test_unknown_exercise(capsys):
    assert exercises.check("no_such_exercise", _student_stub) is False
    assert "no exercise named 'no_such_exercise'" in capsys.readouterr().out
    with pytest.raises(KeyError):
        exercises.use("no_such_exercise", _student_stub)


def test_decorator_registers(capsys):
    @exercises.exercise("toy_square", lambda rng: [(np.arange(3.0),)])
    def square(a):
        return a ** 2
    try:
        assert exercises.reference("toy_square") is square
        assert exercises.check("toy_square", lambda a: a * a)
    finally:
        exercises.unregister("toy_square")


# ---- notebook 01's exercises --------------------------------------------------------

NB01 = ["integrate_events_1d", "event_rate_derivative", "temporal_loss"]


def test_notebook01_exercises_are_registered():
    assert set(NB01) <= set(exercises.names())


@pytest.mark.parametrize("name", NB01)
def test_references_pass_and_stubs_fall_back(name, capsys):
    ref = exercises.reference(name)
    assert exercises.check(name, ref)
    with pytest.warns(ExerciseWarning):
        assert exercises.use(name, _stub_like(ref)) is ref


def _stub_like(ref):
    def stub(*args, **kwargs):
        raise NotImplementedError
    return stub


@pytest.mark.parametrize("name, wrong, hint", [
    ("integrate_events_1d", lambda t_events, p_events, C, t_query: pde1d.integrate_events_1d(t_events, np.abs(p_events), C, t_query),
     "sign of the polarity"),
    ("integrate_events_1d", lambda t_events, p_events, C, t_query: pde1d.integrate_events_1d(t_events, p_events, 1.0, t_query),
     "multiply by the contrast threshold C"),
    ("event_rate_derivative", lambda t_events, p_events, C, boundaries: pde1d.window_sums(t_events, p_events, C, boundaries),
     "divide by the window length"),
    ("temporal_loss", lambda dF_dt, delta_L, durations: torch.sum((delta_L - dF_dt * durations) ** 2), "mean over windows"),
    ("temporal_loss", lambda dF_dt, delta_L, durations: torch.mean((delta_L - dF_dt) ** 2), "window length"),
    ("temporal_loss", lambda dF_dt, delta_L, durations: float(torch.mean((delta_L - dF_dt * durations) ** 2)), "torch.Tensor"),
])
def test_typical_mistakes_get_their_hint(name, wrong, hint, capsys):
    assert not exercises.check(name, wrong)
    assert hint in capsys.readouterr().out


def test_integrate_events_1d_agrees_with_the_library():
    """pde1d.integrate_events_1d re-implements method.integration.integrate_events for one pixel; pin them."""
    from evinr_lite import Events, integrate_events

    rng = np.random.default_rng(3)
    t = np.sort(rng.uniform(0.0, 1.0, 200))
    p = rng.choice(np.array([-1, 1]), t.size)
    q = np.concatenate([rng.uniform(0.0, 1.0, 20), t[::17]])           # queries on event times too (t <= t_q)
    events = Events.from_arrays(t, np.zeros(t.size, int), np.zeros(t.size, int), p, (1, 1))
    np.testing.assert_allclose(pde1d.integrate_events_1d(t, p, 0.2, q), integrate_events(events, q, C=0.2)[:, 0, 0],
                               atol=1e-12)


def test_integrate_events_1d_values():
    t = np.array([0.1, 0.2, 0.3, 0.5])
    p = np.array([1, 1, -1, 1], dtype=np.int8)
    got = pde1d.integrate_events_1d(t, p, 0.25, [0.0, 0.1, 0.25, 0.3, 1.0])
    assert np.allclose(got, [0.0, 0.25, 0.5, 0.25, 0.5]) and got.dtype == np.float64


def test_event_rate_derivative_agrees_with_binning():
    rng = np.random.default_rng(3)
    t = np.sort(rng.uniform(0, 1, 200))
    p = rng.choice([-1, 1], 200)
    b = np.linspace(0, 1, 9)
    ev = Events(t, np.zeros(200, int), np.zeros(200, int), p, (1, 1))
    frames = events_to_frames(ev, b, C=0.2)
    assert np.allclose(pde1d.event_rate_derivative(t, p, 0.2, b), frames.frames[:, 0, 0] / frames.durations)
    assert np.allclose(pde1d.window_sums(t, p, 0.2, b), frames.frames[:, 0, 0])


def test_taylor_error_shrinks_like_window_squared():
    # L = sin(2 pi t): slope over a window of length w about m is L'(m) * sinc-like factor,
    # error = 2 pi |cos(2 pi m)| (1 - sin(pi w) / (pi w)) ~ 2 pi (pi w)^2 / 6 at m = 0
    L, dL = (lambda t: np.sin(2 * np.pi * t)), (lambda t: 2 * np.pi * np.cos(2 * np.pi * t))
    e1 = pde1d.taylor_error(L, [0.0], 0.01, dL)[0]
    e2 = pde1d.taylor_error(L, [0.0], 0.02, dL)[0]
    assert e1 == pytest.approx(2 * np.pi * (np.pi * 0.01) ** 2 / 6, rel=1e-3)
    assert e2 / e1 == pytest.approx(4.0, rel=1e-2)
    assert pde1d.taylor_error(L, [0.0], 0.02)[0] == pytest.approx(e2, rel=1e-3)  # numerical derivative


def test_eq4_error_vs_window_has_both_regimes():
    L, dL = (lambda t: 2 * np.sin(2 * np.pi * t)), (lambda t: 4 * np.pi * np.cos(2 * np.pi * t))
    # ideal events of L with C = 0.05 (level crossings on a fine grid)
    t = np.linspace(0, 1, 100001)
    k = np.floor((L(t) - L(0)) / 0.05 + 0.5)
    steps = np.diff(k)
    idx = np.flatnonzero(steps)
    te, pe = t[idx + 1], np.sign(steps[idx]).astype(np.int8)
    res = pde1d.eq4_error_vs_window(L, [0.005, 0.05, 0.25], (0, 1), t_events=te, p_events=pe, C=0.05, dLdt=dL)
    assert res["taylor"][0] < res["taylor"][1] < res["taylor"][2]
    assert res["events"][0] > res["events"][1]  # quantisation dominates short windows
    with pytest.raises(ValueError):
        pde1d.eq4_error_vs_window(L, [2.0], (0, 1))


def _strict_integrate(t_events, p_events, C, t_query):  # t_i < t_q: an event at the query time left out
    return np.array([C * np.sum(p_events[t_events < q]) for q in t_query])


def _strict_rate(t_events, p_events, C, boundaries):  # (b_k, b_{k+1}): an event on the end edge left out
    return C * np.array([p_events[(t_events > b1) & (t_events < b2)].sum()
                         for b1, b2 in zip(boundaries[:-1], boundaries[1:])], float) / np.diff(boundaries)


def _left_rate(t_events, p_events, C, boundaries):  # [b_k, b_{k+1}) in place of (b_k, b_{k+1}]
    i = np.searchsorted(boundaries, t_events, side="right") - 1
    keep = (i >= 0) & (i < len(boundaries) - 1)
    return C * np.bincount(i[keep], weights=p_events[keep].astype(float), minlength=len(boundaries) - 1) / np.diff(boundaries)


@pytest.mark.parametrize("name, wrong, hint", [
    ("integrate_events_1d", _strict_integrate, "t_i <= t_q"),
    ("integrate_events_1d", lambda t_events, p_events, C, t_query:
        C * np.concatenate([[0.0], np.cumsum(p_events)])[np.searchsorted(t_events, t_query, side="left")], "side=\"right\""),
    ("event_rate_derivative", _strict_rate, "not a strict `<`"),
    ("event_rate_derivative", _left_rate, "(b_k, b_{k+1}]"),
])
def test_boundary_rules_are_checked(name, wrong, hint, capsys):
    """The text's boundary rules (t_i <= t_q; windows (b_k, b_{k+1}]) have check cases on the boundary,
    so the off-by-one variants fail the check and get the hint that names the rule."""
    assert exercises.check(name, wrong) is False
    assert hint in capsys.readouterr().out


def test_notebook_02_boundary_rule_and_scatter_add_mistakes_fail_with_their_hint(capsys):
    """esim_interval: a level reached exactly fires (floor, not ceil - 1); events_to_frames_fixed:
    `frames[i, y, x] += p` drops repeated indices. Both fail the check and name the rule."""
    from evinr_lite.teaching import events2d

    def strict_esim(L_a, L_b, t_a, t_b, ref, C):   # counts only levels strictly passed
        times, p, new_ref = events2d.esim_interval(L_a, L_b, t_a, t_b, ref, C)
        if times.size and np.isclose(abs(L_b - ref) / C, round(abs(L_b - ref) / C)):
            return times[:-1], p[:-1], new_ref - (1 if L_b > ref else -1) * C
        return times, p, new_ref

    assert exercises.check("esim_interval", strict_esim) is False
    assert "reaches exactly fires too" in capsys.readouterr().out

    def fancy_frames(events, boundaries, C):
        H, W = events.sensor_size
        i = np.clip(np.searchsorted(boundaries, events.t, side="left") - 1, 0, None)
        keep = i < len(boundaries) - 1
        frames = np.zeros((len(boundaries) - 1, H, W))
        frames[i[keep], events.y[keep], events.x[keep]] += events.p[keep]
        return (C * frames).astype(np.float32)

    assert exercises.check("events_to_frames_fixed", fancy_frames) is False
    assert "np.add.at" in capsys.readouterr().out


@pytest.mark.parametrize("notebook", ["01_event_generation_1d", "02_events_from_video", "03_coordinate_inr", "04_frame_inr"])
def test_stub_banners_quote_what_the_check_prints(notebook, capsys):
    """Each stub's banner says which line the check prints on success; that line must be the real one."""
    import json
    import re
    from pathlib import Path

    nb = json.loads((Path(__file__).resolve().parents[1] / "notebooks" / f"{notebook}.ipynb").read_text())
    quoted = re.findall(r'### STUDENT: # The check below prints "(✓ ([a-z0-9_]+): [^"]+)"',
                        "".join("".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "code"))
    assert len(quoted) >= 2, f"{notebook}: every exercise stub needs a banner quoting the check's success line"
    for line, name in quoted:
        assert exercises.check(name, exercises.reference(name))
        assert capsys.readouterr().out.strip() == line


def test_registry_is_filled_by_the_teaching_face_with_plain_imports():
    """Issue 23 item 4: no registry of module-name strings; the face imports every registering module,
    and ``teaching.__all__`` lists only names it holds."""
    import ast
    from pathlib import Path

    import evinr_lite.teaching as teaching

    assert all(hasattr(teaching, n) for n in teaching.__all__)
    source = Path(exercises.__file__).read_text()
    assert "import_module" not in source and "REFERENCE_MODULES" not in source
    folder = Path(teaching.__file__).parent
    registering = {p.stem for p in folder.glob("*.py")
                   if p.stem not in ("__init__", "exercises") and "exercises." in p.read_text()}
    imported = {a.name for node in ast.walk(ast.parse((folder / "__init__.py").read_text()))
                if isinstance(node, ast.ImportFrom) for a in node.names}
    assert registering and registering <= imported, registering - imported
    # every notebook's exercise is known without importing its module by hand
    assert {"integrate_events_1d", "crossfade_weights"} <= set(exercises.names())
