"""Exercise checks, round 3: wrong solutions found by mutating the reference solutions.

Every registered exercise's reference was mutated the way learners err (a sign, x and y, a searchsorted side,
< or <=, units, a dropped factor, mean or sum, polarity, float32, integer division, a forgotten sort or line,
an index off by one, exp or log, a transposed result). The wrong solutions below passed a check, or failed it
with only a generic mismatch, before this round: bins whose closed first edge was written ``t == 0`` (right
only while every case started at 0), events before the first window counted in it, np.histogram's
[b_k, b_{k+1}) bins, a pixel number ``y * H + x``, an unstable sort, a float frame divided by 255, a t_last never
updated, a reference never moved, a bin change measured from the first boundary. Each now fails and its report
names the mistake; the references, the notebooks' own solutions and correct alternatives still pass, and the
counts of inputs that the notebooks quote ("matches the reference on N inputs") are unchanged.
"""
import json
from pathlib import Path

import numpy as np
import pytest
import torch

from evinr_lite.core.events import Events
from evinr_lite.teaching import events2d, exercises, pde1d
from evinr_lite.teaching.checking.learner_calls import run
from evinr_lite.teaching.checking.outputs import compare_outputs
from exercise_reports import quoted_counts, report as _report   # shared by rounds 3-11

ROOT = Path(__file__).resolve().parents[1]


# ---- wrong solutions -------------------------------------------------------------------------------------

def _frames(events, boundaries, C, *, first_edge="b0", clip=False):
    b = np.asarray(boundaries, dtype=np.float64)
    H, W = events.sensor_size
    B = b.size - 1
    i = np.searchsorted(b, events.t, side="left") - 1
    i[events.t == (0.0 if first_edge == "zero" else b[0])] = 0
    if clip:
        i = np.clip(i, 0, B - 1)
    keep = (i >= 0) & (i < B)
    frames = np.zeros((B, H, W))
    np.add.at(frames, (i[keep], events.y[keep], events.x[keep]), events.p[keep])
    return C * frames


def _frames_first_edge_zero(events, boundaries, C):
    return _frames(events, boundaries, C, first_edge="zero")


def _frames_clipped(events, boundaries, C):
    return _frames(events, boundaries, C, clip=True)


def _bisect(t_events, boundaries, *, zero=False):
    t, b = np.asarray(t_events, dtype=float), np.asarray(boundaries, dtype=float)
    out = [b[0]]
    for i in range(len(b) - 1):
        lo, hi = b[i], b[i + 1]
        in_bin = t[((t > lo) | ((i == 0) & (t == (0.0 if zero else lo)))) & (t <= hi)]
        n = len(in_bin)
        cut = 0.5 * (lo + hi)
        if n >= 2 and lo < 0.5 * (in_bin[n // 2 - 1] + in_bin[n // 2]) < hi:
            cut = 0.5 * (in_bin[n // 2 - 1] + in_bin[n // 2])
        out += [cut, hi]
    return np.array(out)


def _bisect_first_edge_zero(t_events, boundaries):
    return _bisect(t_events, boundaries, zero=True)


def _rate_early_events_in_first_window(t_events, p_events, C, boundaries):
    b = np.asarray(boundaries, dtype=np.float64)
    t = np.asarray(t_events, dtype=np.float64)
    inside = t <= b[-1]                               # the lower end forgotten
    idx = np.maximum(np.searchsorted(b, t[inside], side="left") - 1, 0)
    sums = C * np.bincount(idx, weights=np.asarray(p_events, dtype=np.float64)[inside], minlength=b.size - 1)
    return sums / np.diff(b)


def _rate_clipped(t_events, p_events, C, boundaries):
    b = np.asarray(boundaries, dtype=np.float64)
    i = np.clip(np.searchsorted(b, t_events, side="left") - 1, 0, b.size - 2)
    return C * np.bincount(i, weights=np.asarray(p_events, float), minlength=b.size - 1) / np.diff(b)


def _rate_histogram(t_events, p_events, C, boundaries):
    sums, _ = np.histogram(t_events, bins=boundaries, weights=np.asarray(p_events, float))
    return C * sums / np.diff(boundaries)


def _imbalance(events, *, row_length=None, kind="stable"):
    H, W = events.sensor_size
    pix = events.y.astype(np.int64) * (W if row_length is None else row_length(H, W)) + events.x
    order = np.argsort(pix, kind=kind)
    pix, t, p = pix[order], events.t[order], events.p[order]
    pair = (pix[1:] == pix[:-1]) & (p[1:] == p[:-1])
    log_dt = np.log(np.maximum(np.diff(t), events2d.MIN_INTERVAL))
    on = p[1:] > 0
    if not (pair & on).any() or not (pair & ~on).any():
        return float("nan")
    return float(np.tanh((log_dt[pair & on].mean() - log_dt[pair & ~on].mean()) / 2))


def _imbalance_y_times_h(events):
    return _imbalance(events, row_length=lambda H, W: H)


def _imbalance_default_sort(events):
    return _imbalance(events, kind="quicksort")     # np.argsort's default


def _offset_float_divided(first_frame, L_t0, eps=1 / 255):
    return np.log(np.asarray(first_frame, np.float64) / 255.0 + eps) - L_t0


def _highpass(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0, *, update=True):
    H, W = sensor_size
    state = np.zeros((H, W))
    t_last = np.full((H, W), float(t_start))
    for ti, xi, yi, pi in zip(t, x, y, p):
        state[yi, xi] = np.exp(-alpha * (ti - t_last[yi, xi])) * state[yi, xi] + C * pi
        if update:
            t_last[yi, xi] = ti
    return state * np.exp(-alpha * (t_end - t_last))


def _highpass_t_last_not_updated(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    return _highpass(t, x, y, p, sensor_size, C, alpha, t_end, t_start, update=False)


def _render_fixed_reference(L_boundaries, C):
    L = np.asarray(L_boundaries, dtype=np.float64)
    return np.trunc((L[1:] - L[0]) / C).astype(np.int64)


def _boundary_loss_from_first(F_boundaries, event_frames):
    return torch.mean((event_frames - (F_boundaries[1:] - F_boundaries[:1])) ** 2)


def _rate_strict_first_edge(t_events, p_events, C, boundaries):
    """Every window open on the left, the first one too: an event at exactly b_0 is lost."""
    sums = [p_events[(t_events > b1) & (t_events <= b2)].sum() for b1, b2 in zip(boundaries[:-1], boundaries[1:])]
    return C * np.array(sums, dtype=float) / np.diff(boundaries)


WRONG = [
    # times that do not start at 0: the closed first edge is t == b_0
    ("events_to_frames_fixed", _frames_first_edge_zero, "`t == boundaries[0]`, not `t == 0`"),
    # events outside every window or bin
    ("event_rate_derivative", _rate_early_events_in_first_window, "events before b_0 belong to no window"),
    ("event_rate_derivative", _rate_clipped, "do not clip them into the first or last window"),
    ("events_to_frames_fixed", _frames_clipped, "do not clip them into the first or last bin"),
    # an event exactly at b_0 left out of the first window (the notebook's text and the reference agree on it)
    ("event_rate_derivative", _rate_strict_first_edge, "an event exactly on the first edge b_0 opens window 0"),
    # the bin-edge rule through np.histogram
    ("event_rate_derivative", _rate_histogram, "np.histogram's bins are [b_k, b_{k+1})"),
    # H and W in the pixel number; a sort that loses the time order
    ("interval_imbalance", _imbalance_y_times_h, "y * H + x gives two pixels one number"),
    ("interval_imbalance", _imbalance_default_sort, 'kind="stable"'),
    # a dropped (here: an extra) normalisation
    ("anchor_first_offset", _offset_float_divided, "divide by 255 only a uint8 frame"),
    # a forgotten line
    ("highpass_per_event", _highpass_t_last_not_updated, "set that pixel's t_last to the event's time"),
    ("render_event_counts", _render_fixed_reference, "move the reference after each bin"),
    # an index off: every change measured from the first boundary
    ("temporal_loss_boundary", _boundary_loss_from_first, "from its own start"),
]


@pytest.mark.parametrize("name, wrong, words", WRONG, ids=[f"{n}-{w.__name__}" for n, w, _ in WRONG])
def test_wrong_solution_fails_and_names_the_problem(name, wrong, words):
    ok, report = _report(name, wrong)
    assert not ok, report
    assert words in report, report
    assert "Traceback" not in report


def test_bisect_with_the_first_edge_at_zero_fails_on_bin_0():
    """The report points at bin 0's cut (output index 1) of the case whose times start at 0.25, and names the
    mistake (a hint of its own since this session: test_accel_exercises counts five)."""
    ok, report = _report("bisect_equal_count", _bisect_first_edge_zero)
    assert not ok, report
    assert "input #4 of 4" in report and "at index 1: got 1.05, expected 0.65" in report, report
    assert "test `t == b_0`, not `t == 0`" in report, report


def test_a_hint_needs_the_same_mistake_on_every_input():
    """The new hints are confirmed on the other inputs: the b_0 = 0 version of bins matches the reference on the
    cases that start at 0, so its hint is not the 'drops the event at b_0' one."""
    ok, report = _report("events_to_frames_fixed", _frames_first_edge_zero)
    assert not ok and "an event at exactly t = b_0 belongs to bin 0 (the first bin" not in report


# ---- the cases hold what the wrong solutions trip on -------------------------------------------------------

def test_cases_start_away_from_zero_with_an_event_on_the_first_edge():
    for name in ("events_to_frames_fixed", "bisect_equal_count"):
        hits = 0
        for _, kw in exercises.get(name).cases():
            t = kw["events"].t if "events" in kw else kw["t_events"]
            b0 = kw["boundaries"][0]
            hits += b0 != 0 and np.any(t == b0) and float(np.float32(b0)) == b0   # exact in float32 too
        assert hits >= 1, name


def test_events_outside_the_windows_do_not_cancel():
    ok = False
    for _, kw in exercises.get("event_rate_derivative").cases():
        t, p, b = kw["t_events"], kw["p_events"], kw["boundaries"]
        if np.any(t < b[0]) and np.any(t > b[-1]):
            ok = p[t < b[0]].sum() != 0 and p[t > b[-1]].sum() != 0
    assert ok


def test_the_counts_the_notebooks_quote_are_unchanged():
    """Each notebook says "✓ NAME: matches the reference on N inputs"; cases were changed, never added."""
    quoted = quoted_counts()
    for name in ("events_to_frames_fixed", "bisect_equal_count", "event_rate_derivative", "interval_imbalance",
                 "anchor_first_offset", "highpass_per_event", "render_event_counts", "temporal_loss_boundary"):
        assert name in quoted, name
        assert len(exercises.get(name).cases()) == quoted[name], name


# ---- correct solutions still pass --------------------------------------------------------------------------

def _frames_bincount(events, boundaries, C):
    """A flat-index bincount, float32 throughout."""
    b = np.asarray(boundaries, dtype=np.float32)
    H, W = events.sensor_size
    B = b.size - 1
    t = events.t.astype(np.float32)
    i = np.searchsorted(b, t, side="left") - 1
    i[t == b[0]] = 0
    keep = (i >= 0) & (i < B)
    flat = (i[keep] * H + events.y[keep]) * W + events.x[keep]
    counts = np.bincount(flat, weights=events.p[keep].astype(np.float32), minlength=B * H * W)
    return (np.float32(C) * counts.astype(np.float32)).reshape(B, H, W)


def _rate_loop(t_events, p_events, C, boundaries):
    """The notebook's loop over windows (b_k, b_{k+1}], an event at exactly b_0 in the first."""
    sums = [p_events[(t_events > b1) & (t_events <= b2)].sum() for b1, b2 in zip(boundaries[:-1], boundaries[1:])]
    sums[0] += p_events[t_events == boundaries[0]].sum()
    return C * np.array(sums, dtype=float) / np.diff(boundaries)


def _imbalance_lexsort(events):
    """Sorted by (pixel x * H + y, then time) with np.lexsort: another correct numbering and sort."""
    H, W = events.sensor_size
    pix = events.x.astype(np.int64) * H + events.y
    order = np.lexsort((events.t, pix))
    pix, t, p = pix[order], events.t[order], events.p[order]
    pair = (pix[1:] == pix[:-1]) & (p[1:] == p[:-1])
    log_dt = np.log(np.maximum(np.diff(t), events2d.MIN_INTERVAL))
    on = p[1:] > 0
    if not (pair & on).any() or not (pair & ~on).any():
        return float("nan")
    return float(np.tanh((log_dt[pair & on].mean() - log_dt[pair & ~on].mean()) / 2))


def _render_loop(L_boundaries, C):
    L = np.asarray(L_boundaries, dtype=np.float64)
    ref, out = L[0].copy(), []
    for k in range(1, len(L)):
        n = np.trunc((L[k] - ref) / C)
        ref = ref + n * C
        out.append(n.astype(np.int64))
    return np.stack(out)


CORRECT = [(name, exercises.reference(name)) for name in dict.fromkeys(n for n, _, _ in WRONG)] + [
    ("bisect_equal_count", exercises.reference("bisect_equal_count")),
    ("events_to_frames_fixed", _frames_bincount),
    ("events_to_frames_fixed", lambda events, boundaries, C: _frames(events, boundaries, C)),
    ("bisect_equal_count", _bisect),
    ("bisect_equal_count", lambda t_events, boundaries: _bisect(np.asarray(t_events, np.float32),
                                                                np.asarray(boundaries, np.float32))),
    ("event_rate_derivative", _rate_loop),
    ("interval_imbalance", _imbalance_lexsort),
    ("interval_imbalance", lambda events: _imbalance(events, kind="mergesort")),
    ("highpass_per_event", _highpass),
    ("render_event_counts", _render_loop),
    ("anchor_first_offset", lambda first_frame, L_t0, eps=1 / 255: np.log(
        (first_frame / 255.0 if first_frame.dtype == np.uint8 else first_frame.astype(float)) + eps) - L_t0),
    ("temporal_loss_boundary", lambda F_boundaries, event_frames: torch.mean(
        (event_frames - torch.diff(F_boundaries, dim=0)) ** 2)),
]


@pytest.mark.parametrize("name, fn", CORRECT, ids=[f"{n}-{k}" for k, (n, _) in enumerate(CORRECT)])
def test_references_and_correct_alternatives_pass(name, fn):
    ok, report = _report(name, fn)
    assert ok, report


def test_the_wrong_versions_differ_from_the_reference():
    """Every wrong solution above really is wrong somewhere in its exercise's cases (a test that cannot
    pass by the check being lenient)."""
    for name, wrong, _ in WRONG + [("bisect_equal_count", _bisect_first_edge_zero, "")]:
        ex = exercises.get(name)
        differs = False
        for args, kwargs in ex.cases():
            got = run(wrong, args, kwargs)
            expected = run(ex.reference, args, kwargs)
            differs |= compare_outputs(got, expected, ex.rtol, ex.atol) is not None
        assert differs, name


def test_notebook_01_solution_and_text_agree_with_the_reference_on_the_first_edge():
    """Notebook 01's exercise 2 says an event exactly at b_0 opens the first window, as the reference (and the
    kit's binning) counts it; its solution passes a check that has such an event."""
    nb = json.loads((ROOT / "notebooks" / "01_event_generation_1d.ipynb").read_text())
    cells = ["".join(c["source"]) for c in nb["cells"]]
    assert any("exactly on the first edge $b_0$ opens the first window" in c for c in cells)
    assert any(np.any(kw["t_events"] == kw["boundaries"][0]) for _, kw in exercises.get("event_rate_derivative").cases())
    src = next(c for c in cells if c.startswith("def event_rate_derivative"))
    body = "\n".join(line for line in src.splitlines() if "### " not in line)
    scope = {"np": np}
    exec(body, scope)
    ok, report = _report("event_rate_derivative", scope["event_rate_derivative"])
    assert ok, report


def _event_rate_from_zero(t, bin_s):
    t = np.asarray(t, dtype=np.float64)
    n_bins = max(int(np.ceil(t[-1] / bin_s)), 1)
    k = np.clip(np.ceil(t / bin_s).astype(np.int64) - 1, 0, n_bins - 1)
    return (np.arange(n_bins) + 0.5) * bin_s, np.bincount(k, minlength=n_bins) / bin_s


def _temporal_loss_halved(dF_dt, delta_L, durations):
    return 0.5 * torch.mean((delta_L - dF_dt * durations) ** 2)


@pytest.mark.parametrize("name, wrong, words", [
    ("event_rate", _event_rate_from_zero, "count the bins from the first event t0 = t[0]"),
    ("temporal_loss", _temporal_loss_halved, "no factor 1/2 in front"),
])
def test_mistakes_that_got_only_a_generic_report_now_get_their_hint(name, wrong, words):
    """Two mistakes the mutation audit saw fail with only a generic mismatch: bins counted from time 0, and a
    loss halved (one number, so the generic 'constant factor' note cannot tell)."""
    ok, report = _report(name, wrong)
    assert not ok and words in report, report
