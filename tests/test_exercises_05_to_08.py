"""Notebooks 05-08: the exercises that carry the method are pinned to the library, their checks name the
common mistakes, and boundary rules are checked with events exactly on the boundary."""
import numpy as np
import pytest

from evinr_lite.teaching import ablation_exercises, accel_exercises as accel, exercises, frame_exercises as fe
from evinr_lite.teaching import discussion_exercises  # noqa: F401  (registers notebook 08's exercises)
from evinr_lite.core.events import Events
from evinr_lite.evaluation import ablation as ab
from evinr_lite.method import anchor_level, anchor_mean, bisect_boundaries, tonemap_reinhard
from evinr_lite.method.offset import median_gradient_offset, poisson_integrate

NAMES = ["anchor", "offset_gradients", "time_fps_products", "bisect_equal_count", "render_event_counts",
         "highpass_per_event"]


def _stub(*args, **kwargs):
    raise NotImplementedError


@pytest.mark.parametrize("name", NAMES)
def test_reference_passes_and_every_hint_is_shown(name, capsys):
    assert exercises.check(name, exercises.reference(name))
    ex = exercises.get(name)
    assert ex.hints
    for message, wrong in ex.hints.items():
        capsys.readouterr()
        assert exercises.check(name, wrong) is False
        assert message in capsys.readouterr().out, f"{name}: hint not shown: {message}"
    assert exercises.check(name, _stub) is False


@pytest.mark.parametrize("seed", range(4))
def test_anchor_is_the_librarys_anchor(seed):
    rng = np.random.default_rng(seed)
    L = rng.normal(rng.uniform(-3, 3), rng.uniform(0.1, 2), (3, 5, 4))
    gamma, m = float(rng.uniform(0.3, 2.5)), float(rng.uniform(0.05, 0.95))
    out = fe.anchor(L, gamma, m)
    np.testing.assert_allclose(out, anchor_mean(L, gamma, m), rtol=0, atol=1e-12)
    assert out.mean() == pytest.approx(anchor_level(gamma, m), abs=1e-12)
    assert float(tonemap_reinhard(out.mean(), gamma)) == pytest.approx(m, abs=1e-12)
    np.testing.assert_allclose(out - L, out.flat[0] - L.flat[0])          # one constant shift


@pytest.mark.parametrize("seed", range(4))
def test_offset_gradients_integrate_to_the_librarys_offset(seed):
    rng = np.random.default_rng(seed)
    frames = rng.normal(0, 1, (int(rng.integers(1, 9)), int(rng.integers(2, 7)), int(rng.integers(2, 7))))
    gx, gy = fe.offset_gradients(frames)
    assert gx.shape == (frames.shape[1], frames.shape[2] - 1) and gy.shape == (frames.shape[1] - 1, frames.shape[2])
    np.testing.assert_allclose(poisson_integrate(gx, gy), median_gradient_offset(frames), atol=1e-10)


def test_offset_gradients_check_names_swapped_axes_on_a_non_square_image(capsys):
    def swapped(frames):
        F = np.asarray(frames, dtype=np.float64)
        return -np.median(np.diff(F, axis=1), axis=0), -np.median(np.diff(F, axis=2), axis=0)
    assert not exercises.check("offset_gradients", swapped)
    assert "column axis" in capsys.readouterr().out


def test_time_fps_products_is_the_librarys_and_constant_in_the_paper_tables():
    assert ablation_exercises.time_fps_products is ab.paper_frame_counts
    for table in (ab.PAPER_TABLE2, ab.PAPER_TABLE3):
        p = np.array(list(ablation_exercises.time_fps_products(table).values()))
        times = np.array([row["time_s"] for row in table.values()])
        assert np.ptp(p) / np.median(p) < 0.05 < np.ptp(times) / np.median(times)   # products fixed, times not


# ---- boundary rules: bins (b_i, b_{i+1}], bin 0 closed on the left ------------------------------

def _left_closed(t_events, boundaries):
    """bins [b_i, b_{i+1}): what searchsorted(side='left') at both ends gives."""
    t, b = np.asarray(t_events, float), np.asarray(boundaries, float)
    out = np.empty(2 * len(b) - 1)
    out[0::2] = b
    for i, (lo, hi) in enumerate(zip(b[:-1], b[1:])):
        in_bin = t[(t >= lo) & (t < hi)]
        n = len(in_bin)
        cut = 0.5 * (in_bin[n // 2 - 1] + in_bin[n // 2]) if n >= 2 else 0.5 * (lo + hi)
        out[2 * i + 1] = cut if lo < cut < hi else 0.5 * (lo + hi)
    return out


def _strict_upper(t_events, boundaries):
    """bins (b_i, b_{i+1}) with a strict t < b_{i+1}: events on an inner edge fall out."""
    t, b = np.asarray(t_events, float), np.asarray(boundaries, float)
    out = np.empty(2 * len(b) - 1)
    out[0::2] = b
    for i, (lo, hi) in enumerate(zip(b[:-1], b[1:])):
        in_bin = t[((t > lo) | ((i == 0) & (t == lo))) & (t < hi)]
        n = len(in_bin)
        cut = 0.5 * (in_bin[n // 2 - 1] + in_bin[n // 2]) if n >= 2 else 0.5 * (lo + hi)
        out[2 * i + 1] = cut if lo < cut < hi else 0.5 * (lo + hi)
    return out


def _bin0_open(t_events, boundaries):
    """every bin (b_i, b_{i+1}], bin 0 included: an event at exactly b_0 is lost."""
    t, b = np.asarray(t_events, float), np.asarray(boundaries, float)
    out = np.empty(2 * len(b) - 1)
    out[0::2] = b
    for i, (lo, hi) in enumerate(zip(b[:-1], b[1:])):
        in_bin = t[(t > lo) & (t <= hi)]
        n = len(in_bin)
        cut = 0.5 * (in_bin[n // 2 - 1] + in_bin[n // 2]) if n >= 2 else 0.5 * (lo + hi)
        out[2 * i + 1] = cut if lo < cut < hi else 0.5 * (lo + hi)
    return out


@pytest.mark.parametrize("wrong", [_left_closed, _strict_upper, _bin0_open])
def test_bisect_check_fails_the_wrong_boundary_rules(wrong, capsys):
    assert exercises.check("bisect_equal_count", wrong) is False
    assert "does not match" in capsys.readouterr().out


def test_bisect_boundary_case_agrees_with_the_solver():
    cases = [kw for _, kw in exercises.get("bisect_equal_count").cases()]
    on_edges = [kw for kw in cases if np.isin(kw["boundaries"], kw["t_events"]).sum() >= 3]
    assert on_edges, "no check case has events exactly on the bin edges"
    for kw in on_edges:
        t = kw["t_events"]
        ev = Events(t, np.zeros(len(t), int), np.zeros(len(t), int), np.ones(len(t), int), (1, 1))
        np.testing.assert_array_equal(accel.bisect_equal_count(t, kw["boundaries"]), bisect_boundaries(ev, kw["boundaries"]))


def test_within_bin_detail_is_zero_for_a_steady_rate_and_refuses_unrelated_edges():
    t = np.linspace(0.0, 1.0, 401)[1:]                                  # one event every 2.5 ms, one pixel
    ev = Events(t, np.zeros(len(t), int), np.zeros(len(t), int), np.ones(len(t), int), (1, 1))
    coarse = np.linspace(0.0, 1.0, 5)
    fine = accel.bisect_equal_count(t, coarse)
    assert accel.within_bin_detail(ev, coarse, fine, 0.2) == pytest.approx(0.0, abs=1e-12)
    skewed = np.sort(np.concatenate([np.linspace(0.0, 0.1, 50, endpoint=False)[1:], [0.9]]))
    ev2 = Events(skewed, np.zeros(len(skewed), int), np.zeros(len(skewed), int), np.ones(len(skewed), int), (1, 1))
    by_time = np.linspace(0.0, 1.0, 3)
    assert accel.within_bin_detail(ev2, coarse[[0, 4]], by_time, 0.2) > 0.1    # halves by time: unequal halves
    with pytest.raises(ValueError, match="bisection of coarse"):
        accel.within_bin_detail(ev, coarse, np.linspace(0.0, 1.0, 7), 0.2)


# ---- the threshold rule of rendered events: a change of exactly C fires (|change| >= C) -----------

def test_render_check_fails_a_strict_threshold(capsys):
    from evinr_lite.evaluation.enhance import render_counts

    def strict(L_boundaries, C):          # a loop that fires only while the change exceeds C
        L = np.asarray(L_boundaries, dtype=np.float64)
        ref, out = L[0].copy(), np.zeros((L.shape[0] - 1,) + L.shape[1:], dtype=np.int64)
        for k in range(1, L.shape[0]):
            d = L[k] - ref
            n = np.where(np.abs(d) > C, np.sign(d) * np.floor(np.abs(d) / C), 0)
            n = np.where((np.abs(d) > C) & (np.abs(d) == np.abs(n) * C), n - np.sign(d), n)
            ref += n * C
            out[k - 1] = n
        return out
    assert exercises.check("render_event_counts", strict) is False
    assert "exactly C" in capsys.readouterr().out
    exact = [kw for _, kw in exercises.get("render_event_counts").cases() if kw["C"] == 0.25]
    assert exact and np.any(render_counts(exact[0]["L_boundaries"], 0.25) != 0)
