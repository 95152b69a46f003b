"""Exercise checks, round 4: wrong solutions written the way learners err, that earlier rounds did not try.

Each exercise was given plausible wrong solutions (an off-by-one loop, a mean or an `any` along the wrong axis, a
transposed result, (H, W) read as (W, H), indices where a mask belongs, an array of one number where a number
belongs, a float16, unsigned or float dtype, `/` for `//`, a hard-coded constant or the module's default for an
argument, np.median or np.histogram(dd) where the rule differs, np.linspace's floating-point positions, a derivative
cut off from the autograd graph, a formula with the wrong brackets or sign). Before this round these passed a check,
or failed it with a bare "wrong values" / "wrong shape" / "wrong dtype" (or a misleading "constant factor"):

- now caught (they passed): a background-activity loop that never takes the last event as a neighbour, or never
  decides the first event (the cases now hold such events); window indices from np.linspace (k * N / w in floating
  point truncates 61 to 60 for 122 events in 14 windows); a sine layer's derivative detached or rebuilt with
  torch.tensor (a case's weights now require grad);
- now named: a transposed result or (H, W) unpacked as (W, H) (a shape with the last two axes swapped), the indices of
  a mask, an int mask, one number in an array, float16, an unsigned dtype holding negative counts, floats where
  integers belong, a dict with renamed keys, an OFF polarity written 0 (it read "constant factor -0"), and one hint per
  exercise-specific mistake listed in WRONG below.

Each now fails and its report names the mistake; the references, the notebooks' own solutions and correct
alternatives still pass, and the counts of inputs that the notebooks quote are unchanged.
"""
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
import torch

from evinr_lite.teaching import exercises
from evinr_lite.teaching.checking.learner_calls import run
from evinr_lite.teaching.checking.outputs import compare_outputs

from exercise_reports import report as _report   # the check's verdict and its printed report

ROOT = Path(__file__).resolve().parents[1]




def _ref(name):
    return exercises.reference(name)


# ---- wrong solutions: how the result is packaged ----------------------------------------------------------

def _crossfade_transposed(windows, times):
    return _ref("crossfade_weights")(windows, times).T             # [Q, N]


def _head_transposed(A, E, ridge):
    A = np.asarray(A, dtype=np.float64)
    return np.linalg.solve(A.T @ A + ridge * np.eye(A.shape[1]), A.T @ E).T


def _hot_w_h(x, y, sensor_size, factor=10.0):
    W, H = sensor_size                                              # (H, W) read as (W, H)
    counts = np.bincount(np.asarray(y) * W + np.asarray(x), minlength=H * W).reshape(H, W)
    return counts > factor * np.median(counts[counts > 0])


def _hot_argwhere(x, y, sensor_size, factor=10.0):
    return np.argwhere(_ref("hot_pixel_mask")(x, y, sensor_size, factor))


def _filter_indices(t, x, y, dt):
    return np.flatnonzero(_ref("background_activity_filter")(t, x, y, dt))


def _filter_int(t, x, y, dt):
    return _ref("background_activity_filter")(t, x, y, dt).astype(int)


def _front_indices(cost, quality):
    return np.flatnonzero(_ref("pareto_front")(cost, quality))


def _front_int(cost, quality):
    return _ref("pareto_front")(cost, quality) * 1


def _threshold_lstsq(log_changes, net_counts):
    n = np.asarray(net_counts, dtype=np.float64)[:, None]
    return np.linalg.lstsq(n, log_changes, rcond=None)[0]           # an array [1]


def _loss_shape_one(dF_dt, delta_L, durations):
    return torch.mean((delta_L - dF_dt * durations) ** 2, dim=0, keepdim=True)


def _split_true_division(index, sensor_size):
    H, W = sensor_size
    return torch.div(index, H * W, rounding_mode="floor"), torch.floor(index / W) % H, index % W


def _render_float(L_boundaries, C):
    L = np.asarray(L_boundaries, dtype=np.float64)
    ref, out = L[0].copy(), []
    for k in range(1, len(L)):
        n = np.trunc((L[k] - ref) / C)                               # floats
        ref = ref + n * C
        out.append(n)
    return np.stack(out)


def _render_uint8(L_boundaries, C):
    return _render_float(L_boundaries, C).astype(np.uint8)


def _frames_float16(events, boundaries, C):
    return _ref("events_to_frames_fixed")(events, boundaries, C).astype(np.float16)


def _anchor_float16(L, gamma, display_mean):
    L = np.asarray(L, dtype=np.float16)
    s = np.float16(display_mean) ** np.float16(1.0 / gamma)
    return L + (np.log(s / (np.float16(1.0) - s)) - L.mean())


def _integrate_float16(t_events, p_events, C, t_query):
    return _ref("integrate_events_1d")(t_events, p_events, C, t_query).astype(np.float16)


def _products_lower_keys(table):
    return {name.lower(): row["time_s"] * row["fps"] for name, row in table.items()}


def _esim_off_zero(L_a, L_b, t_a, t_b, ref, C):
    d = L_b - ref
    p = 1 if d > 0 else -1
    n = int(np.floor(abs(d) / C))
    levels = ref + p * C * np.arange(1, n + 1)
    times = t_a + (levels - L_a) / (L_b - L_a) * (t_b - t_a) if n else np.zeros(0)
    return times, np.full(n, 1 if p > 0 else 0, dtype=np.int8), float(ref + p * n * C)


# ---- wrong solutions that passed: loops, floating point, autograd ------------------------------------------

def _filter_loop(t, x, y, dt, first=0, last=0):
    keep = np.zeros(len(t), dtype=bool)
    for i in range(first, len(t)):
        for j in range(len(t) - last):
            if max(abs(x[j] - x[i]), abs(y[j] - y[i])) == 1 and t[j] <= t[i] <= t[j] + dt:
                keep[i] = True
    return keep


def _filter_j_misses_last(t, x, y, dt):
    return _filter_loop(t, x, y, dt, last=1)


def _filter_i_skips_first(t, x, y, dt):
    return _filter_loop(t, x, y, dt, first=1)


def _windows_linspace(n_events, max_events):
    w = math.ceil(n_events / max_events)
    return np.linspace(0, n_events, w + 1).astype(np.int64)


def _sine_detached(h, dh_dt, weight, bias, omega):
    z = omega * (h @ weight + bias)
    return torch.sin(z), (torch.cos(z) * omega * (dh_dt @ weight)).detach()


def _sine_rebuilt(h, dh_dt, weight, bias, omega):
    z = omega * (h @ weight + bias)
    return torch.sin(z), torch.tensor((torch.cos(z) * omega * (dh_dt @ weight)).tolist())


# ---- wrong solutions: one mistake of the exercise ------------------------------------------------------------

def _anchor_axis0(L, gamma, display_mean):
    L = np.asarray(L, dtype=np.float64)
    s = display_mean ** (1.0 / gamma)
    return L + (np.log(s / (1.0 - s)) - L.mean(axis=0))


def _anchor_median(L, gamma, display_mean):
    L = np.asarray(L, dtype=np.float64)
    s = display_mean ** (1.0 / gamma)
    return L - np.median(L) + np.log(s / (1.0 - s))


def _offset(first_frame, L_t0, eps, *, scale=255.0, log=np.log):
    a = np.asarray(first_frame)
    intensity = a / scale if a.dtype == np.uint8 else a
    return log(intensity + eps) - L_t0


def _offset_module_eps(first_frame, L_t0, eps=1 / 255):
    return _offset(first_frame, L_t0, 1 / 255)


def _offset_256(first_frame, L_t0, eps=1 / 255):
    return _offset(first_frame, L_t0, eps, scale=256.0)


def _offset_log10(first_frame, L_t0, eps=1 / 255):
    return _offset(first_frame, L_t0, eps, log=np.log10)


def _filter_any_axis0(t, x, y, dt):
    t, x, y = np.asarray(t, float), np.asarray(x), np.asarray(y)
    near = np.maximum(abs(x[:, None] - x[None, :]), abs(y[:, None] - y[None, :])) == 1
    return np.any(near & (t[None, :] <= t[:, None]) & (t[:, None] <= t[None, :] + dt), axis=0)


def _bisect(t_events, boundaries, median=None, cuts_only=False):
    t, b = np.asarray(t_events, float), np.asarray(boundaries, float)
    out = [b[0]]
    for i in range(len(b) - 1):
        lo, hi = b[i], b[i + 1]
        m = t[((t > lo) | ((i == 0) & (t == lo))) & (t <= hi)]
        cut = 0.5 * (lo + hi)
        if len(m) >= 2:
            c = np.median(m) if median else 0.5 * (m[len(m) // 2 - 1] + m[len(m) // 2])
            cut = c if lo < c < hi else cut
        out += [cut, hi]
    return np.array(out[1::2] if cuts_only else out)


def _chain(prev, nxt, axis=1, flat=False):
    steps = (np.asarray(prev, float) - np.asarray(nxt, float)).mean(axis=axis)
    acc = np.cumsum(steps).reshape(steps.shape) if flat else np.cumsum(steps, axis=0)
    return np.concatenate([np.zeros((1,) + np.shape(prev)[2:]), acc])


def _esim(L_a, L_b, t_a, t_b, ref, C, *, sort=False, from_ref=False):
    d = L_b - ref
    p = 1 if d > 0 else -1
    n = int(np.floor(abs(d) / C))
    levels = ref + p * C * np.arange(1, n + 1)
    if sort:
        levels = np.sort(levels)
    start = ref if from_ref else L_a
    times = t_a + (levels - start) / (L_b - start) * (t_b - t_a) if n else np.zeros(0)
    return times, np.full(n, p, dtype=np.int8), float(ref + p * n * C)


def _threshold_sums(log_changes, net_counts):
    return float(np.sum(log_changes) / np.sum(net_counts))


def _rate_int_bins(t, bin_s):
    t = np.asarray(t, dtype=np.float64)
    B = max(int((t[-1] - t[0]) / bin_s), 1)
    k = np.clip(np.ceil((t - t[0]) / bin_s).astype(int) - 1, 0, B - 1)
    return t[0] + (np.arange(B) + 0.5) * bin_s, np.bincount(k, minlength=B) / bin_s


def _derivative_first_length(t_events, p_events, C, boundaries):
    b = np.asarray(boundaries, dtype=np.float64)
    sums = [p_events[(t_events > lo) & (t_events <= hi)].sum() for lo, hi in zip(b[:-1], b[1:])]
    sums[0] += p_events[t_events == b[0]].sum()
    return C * np.array(sums, dtype=float) / (b[1] - b[0])


def _frames_histogramdd(events, boundaries, C):
    H, W = events.sensor_size
    h, _ = np.histogramdd((events.t, events.y, events.x), bins=(boundaries, np.arange(H + 1), np.arange(W + 1)),
                          weights=events.p)
    return (C * h).astype(np.float32)


def _head_ridge_added(A, E, ridge):
    return np.linalg.solve(A.T @ A + ridge, A.T @ E)


def _highpass(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0, *, end_from_stream=False, hz=False):
    H, W = sensor_size
    a = 2 * np.pi * alpha if hz else alpha
    state, t_last = np.zeros((H, W)), np.full((H, W), float(t_start))
    for ti, xi, yi, pi in zip(t, x, y, p):
        state[yi, xi] = np.exp(-a * (ti - t_last[yi, xi])) * state[yi, xi] + C * pi
        t_last[yi, xi] = ti
    return state * np.exp(-a * (t_end - (t[-1] if end_from_stream else t_last)))


def _integrate_no_zero(t_events, p_events, C, t_query):
    csum = np.cumsum(p_events)
    return C * csum[np.searchsorted(t_events, t_query, side="right") - 1]


def _front_axis0(cost, quality):
    c, q = np.asarray(cost, float)[:, None], np.asarray(quality, float)[:, None]
    return ~((c.T <= c) & (q.T >= q) & ((c.T < c) | (q.T > q))).any(axis=0)


def _tonemap_brackets(L, gamma):
    I = np.exp(L)
    return I / (I + 1) ** gamma


def _tonemap_exp_minus(L, gamma):
    I = np.exp(-np.asarray(L, float))
    return (I / (I + 1)) ** gamma


def _sine_h_for_dh(h, dh_dt, weight, bias, omega):
    z = omega * (h @ weight + bias)
    return torch.sin(z), torch.cos(z) * omega * (h @ weight)


def _split_x_y_b(index, sensor_size):
    H, W = sensor_size
    return index % W, (index // W) % H, index // (H * W)


TL = [
    ("rates", lambda dF_dt, delta_L, durations: torch.mean((delta_L / durations - dF_dt) ** 2)),
    ("rms", lambda dF_dt, delta_L, durations: torch.sqrt(torch.mean((delta_L - dF_dt * durations) ** 2))),
    ("mse_loss", lambda dF_dt, delta_L, durations: torch.nn.functional.mse_loss(dF_dt, delta_L * durations)),
]


def _boundary_bin_means_summed(F_boundaries, event_frames):
    return ((event_frames - (F_boundaries[1:] - F_boundaries[:-1])) ** 2).mean(dim=(1, 2)).sum()


def _boundary_last_bin_dropped(F_boundaries, event_frames):
    B = event_frames.shape[0]
    return torch.mean(torch.stack([((event_frames[i] - (F_boundaries[i + 1] - F_boundaries[i])) ** 2)
                                   for i in range(B - 1)]))


def _tv_first_axes(F):
    return torch.mean(torch.abs(F[:, 1:] - F[:, :-1])) + torch.mean(torch.abs(F[1:] - F[:-1]))


def _tv_diff_dims_0_1(F):
    return torch.diff(F, dim=1).abs().mean() + torch.diff(F, dim=0).abs().mean()


def _tv_isotropic(F):
    dx = F[..., :-1, 1:] - F[..., :-1, :-1]
    dy = F[..., 1:, :-1] - F[..., :-1, :-1]
    return torch.sqrt(dx ** 2 + dy ** 2).mean()


WRONG = [
    # packaging: shapes, dtypes, containers
    ("crossfade_weights", _crossfade_transposed, "the last two axes are swapped"),
    ("head_closed_form", _head_transposed, "a transposed result"),
    ("hot_pixel_mask", _hot_w_h, "(H, W) read as (W, H)"),
    ("hot_pixel_mask", _hot_argwhere, "indices of the True entries"),
    ("background_activity_filter", _filter_indices, "indices of the True entries"),
    ("pareto_front", _front_indices, "return the boolean mask itself"),
    ("background_activity_filter", _filter_int, "return the comparison itself (a boolean mask)"),
    ("pareto_front", _front_int, "return the comparison itself (a boolean mask)"),
    ("estimate_contrast_threshold", _threshold_lstsq, "an array holding one number"),
    ("temporal_loss", _loss_shape_one, "an array holding one number"),
    ("split_index", _split_true_division, "integer division `//`"),
    ("render_event_counts", _render_float, "np.trunc"),
    ("render_event_counts", _render_uint8, "unsigned dtype (uint8) cannot hold the negative values"),
    ("events_to_frames_fixed", _frames_float16, "float16 (half precision"),
    ("anchor", _anchor_float16, "float16 (half precision"),
    ("integrate_events_1d", _integrate_float16, "float16 (half precision"),
    ("time_fps_products", _products_lower_keys, "same spelling and case"),
    ("esim_interval", _esim_off_zero, "polarity -1, not 0"),
    # used to pass
    ("background_activity_filter", _filter_j_misses_last, "range(len(t) - 1)"),
    ("background_activity_filter", _filter_i_skips_first, "range(1, len(t))"),
    ("event_count_windows", _windows_linspace, "(k * N) // w in integers"),
    ("sine_layer_derivative", _sine_detached, "cut off from the autograd graph"),
    ("sine_layer_derivative", _sine_rebuilt, "cut off from the autograd graph"),
    # one mistake of the exercise, now named
    ("anchor", _anchor_axis0, "a mean along an axis"),
    ("anchor", _anchor_median, "not the median"),
    ("anchor_first_offset", _offset_module_eps, "use the `eps` argument"),
    ("anchor_first_offset", _offset_256, "divide by 255, not 256"),
    ("anchor_first_offset", _offset_log10, "not base 10"),
    ("background_activity_filter", _filter_any_axis0, "np.any(..., axis=1)"),
    ("bisect_equal_count", lambda t_events, boundaries: _bisect(t_events, boundaries, median=True),
     "np.median of an odd number of events"),
    ("bisect_equal_count", lambda t_events, boundaries: _bisect(t_events, boundaries, cuts_only=True),
     "return the old edges too"),
    ("chain_offsets", lambda prev, nxt: _chain(prev, nxt, axis=0), "not over the K overlaps"),
    ("chain_offsets", lambda prev, nxt: _chain(prev, nxt, flat=True), "np.cumsum without axis="),
    ("esim_interval", lambda L_a, L_b, t_a, t_b, ref, C: _esim(L_a, L_b, t_a, t_b, ref, C, sort=True),
     "return the events in time order"),
    ("esim_interval", lambda L_a, L_b, t_a, t_b, ref, C: _esim(L_a, L_b, t_a, t_b, ref, C, from_ref=True),
     "measured from L_a, not from ref"),
    ("estimate_contrast_threshold", _threshold_sums, "sum(ΔL) / sum(n)"),
    ("event_rate", _rate_int_bins, "int() rounds down"),
    ("event_rate_derivative", _derivative_first_length, "not the first window's length"),
    ("events_to_frames_fixed", _frames_histogramdd, "np.histogramdd"),
    ("head_closed_form", _head_ridge_added, "adds ridge to every entry"),
    ("highpass_per_event", lambda *a, **k: _highpass(*a, **k, end_from_stream=True), "not from the stream's last"),
    ("highpass_per_event", lambda *a, **k: _highpass(*a, **k, hz=True), "already in rad/s"),
    ("integrate_events_1d", _integrate_no_zero, "prepend a 0"),
    ("pareto_front", _front_axis0, "any over axis 1"),
    ("reinhard_tonemap", _tonemap_brackets, "raises only the denominator"),
    ("reinhard_tonemap", _tonemap_exp_minus, "not exp(-L)"),
    ("sine_layer_derivative", _sine_h_for_dh, "uses dh_dt, not h"),
    ("split_index", _split_x_y_b, "return (b, y, x), in that order"),
    ("temporal_loss", TL[0][1], "dividing delta_L by it compares rates"),
    ("temporal_loss", TL[1][1], "without a square root"),
    ("temporal_loss", TL[2][1], "not delta_L"),
    ("temporal_loss_boundary", _boundary_bin_means_summed, "not a sum of per-bin means"),
    ("temporal_loss_boundary", _boundary_last_bin_dropped, "use all B bins"),
    ("tikhonov_autograd", lambda dF_dx, dF_dy: torch.mean(torch.sqrt(dF_dx ** 2 + dF_dy ** 2)),
     "without a square root"),
    ("tikhonov_autograd", lambda dF_dx, dF_dy: torch.mean(torch.stack([dF_dx, dF_dy]) ** 2), "divides by 2M"),
    ("total_variation", _tv_first_axes, "index the last two axes"),
    ("total_variation", _tv_diff_dims_0_1, "index the last two axes"),
    ("total_variation", _tv_isotropic, "not sqrt(dF/dx^2 + dF/dy^2)"),
]


def _id(n, fn, k):
    return f"{n}-{k}-{getattr(fn, '__name__', 'fn').strip('<>_')}"


@pytest.mark.parametrize("name, wrong, words", WRONG, ids=[_id(n, w, k) for k, (n, w, _) in enumerate(WRONG)])
def test_wrong_solution_fails_and_names_the_problem(name, wrong, words):
    ok, report = _report(name, wrong)
    assert not ok, report
    assert words in report, report
    assert "Traceback" not in report


def test_a_zero_result_is_not_called_a_constant_factor():
    """OFF polarities written 0: the generic note used to read "off by a constant factor: got -0 x"."""
    ok, report = _report("esim_interval", _esim_off_zero)
    assert not ok and "constant factor" not in report, report


def test_float16_is_named_instead_of_a_constant_factor():
    ok, report = _report("events_to_frames_fixed", _frames_float16)
    assert not ok and "constant factor" not in report, report


def test_the_wrong_versions_differ_from_the_reference():
    """Every wrong solution above really is wrong somewhere in its exercise's cases."""
    for name, wrong, _ in WRONG:
        ex = exercises.get(name)
        differs = False
        for args, kwargs in ex.cases():
            try:
                got = run(wrong, args, kwargs)
            except Exception:
                differs = True
                continue
            expected = run(ex.reference, args, kwargs)
            differs |= compare_outputs(got, expected, ex.rtol, ex.atol) is not None
        differs |= name == "sine_layer_derivative"          # right values, cut off from the graph
        assert differs, name


# ---- guards: mistakes that already failed with a clear message, and correct solutions -------------------------

def _filter_stream_order(t, x, y, dt):
    """Guard: only events stored before i count (equal timestamps stored later are missed)."""
    keep = np.zeros(len(t), dtype=bool)
    for i in range(len(t)):
        for j in range(i):
            if max(abs(x[j] - x[i]), abs(y[j] - y[i])) == 1 and t[i] - t[j] <= dt:
                keep[i] = True
    return keep


def _hot_histogram2d(x, y, sensor_size, factor=10.0):
    """Guard: np.histogram2d(x, y) counts into [x, y]."""
    H, W = sensor_size
    c, _, _ = np.histogram2d(x, y, bins=(np.arange(W + 1), np.arange(H + 1)))
    return c > factor * np.median(c[c > 0])


GUARDS = [
    ("background_activity_filter", _filter_stream_order, "compare times, not positions in the stream"),
    ("hot_pixel_mask", _hot_histogram2d, "rows are y and columns are x"),
    ("total_variation", lambda F: float((F[..., :, 1:] - F[..., :, :-1]).abs().mean()
                                        + (F[..., 1:, :] - F[..., :-1, :]).abs().mean()), "expected a torch.Tensor"),
]


@pytest.mark.parametrize("name, wrong, words", GUARDS, ids=[n for n, _, _ in GUARDS])
def test_guard_mistakes_that_already_failed_clearly(name, wrong, words):
    ok, report = _report(name, wrong)
    assert not ok and words in report, report


def _crossfade_product(windows, times):
    """fade_in * fade_out instead of their minimum: the same weights (one of the two is 1 in every overlap)."""
    windows, t = np.asarray(windows, float), np.asarray(times, float)
    if len(windows) == 1:
        return np.ones((1, len(t)))
    overlap = windows[0, 1] - windows[1, 0]
    fi = np.clip((t - windows[:, :1]) / overlap, 0, 1)
    fo = np.clip((windows[:, 1:] - t) / overlap, 0, 1)
    fi[0], fo[-1] = 1.0, 1.0
    w = fi * fo
    return w / w.sum(axis=0, keepdims=True)


def _hot_unique(x, y, sensor_size, factor=10.0):
    H, W = sensor_size
    pix, counts = np.unique(np.asarray(y) * W + np.asarray(x), return_counts=True)
    full = np.zeros(H * W, dtype=np.int64)
    full[pix] = counts
    return (full > factor * np.median(counts)).reshape(H, W)


def _windows_integers(n_events, max_events):
    w = -(-n_events // max_events)
    return np.array([k * n_events // w for k in range(w + 1)], dtype=np.int64)


def _render_astype(L_boundaries, C):
    L = np.asarray(L_boundaries, dtype=np.float64)
    ref, out = L[0].copy(), []
    for k in range(1, len(L)):
        n = ((L[k] - ref) / C).astype(np.int64)                     # truncates toward zero, as np.trunc
        ref = ref + n * C
        out.append(n)
    return np.stack(out)


def _filter_loop_all(t, x, y, dt):
    return _filter_loop(t, x, y, dt)


CORRECT = [(name, exercises.reference(name)) for name in dict.fromkeys(n for n, _, _ in WRONG)] + [
    ("crossfade_weights", _crossfade_product),
    ("hot_pixel_mask", _hot_unique),
    ("event_count_windows", _windows_integers),
    ("render_event_counts", _render_astype),
    ("background_activity_filter", _filter_loop_all),
    # (np.where(n > 0, csum[max(n - 1, 0)], 0) was here: round 5 gave the check a pixel with no events, where it
    # raises IndexError; tests/test_exercise_wrong_solutions_round5.py holds it as a hole)
    ("integrate_gradients", lambda gx, gy: exercises.reference("integrate_gradients")(gy.T, gx.T).T),
    ("anchor", lambda L, gamma, display_mean: np.asarray(L, np.float32) - np.float32(np.mean(L)) + np.float32(
        np.log(display_mean ** (1 / gamma)) - np.log1p(-display_mean ** (1 / gamma)))),
    ("sine_layer_derivative", lambda h, dh_dt, weight, bias, omega: (
        torch.sin(omega * (h @ weight + bias)),
        omega * torch.cos(omega * (h @ weight + bias)) * torch.matmul(dh_dt, weight))),
    ("pareto_front", lambda cost, quality: np.array([
        not any(cj <= ci and qj >= qi and (cj < ci or qj > qi) for cj, qj in zip(cost, quality))
        for ci, qi in zip(cost, quality)])),
]


@pytest.mark.parametrize("name, fn", CORRECT, ids=[f"{n}-{k}" for k, (n, _) in enumerate(CORRECT)])
def test_guard_references_and_correct_alternatives_pass(name, fn):
    ok, report = _report(name, fn)
    assert ok, report


def test_guard_the_counts_the_notebooks_quote_are_unchanged():
    """Each notebook says "✓ NAME: matches the reference on N inputs"; cases were changed, never added."""
    quoted = {}
    for path in sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb")):
        text = "".join("".join(c["source"]) for c in json.loads(path.read_text())["cells"])
        for name, n in re.findall(r"✓ (\w+): matches the reference on (\d+) input", text):
            quoted[name] = int(n)
    for name in ("background_activity_filter", "event_count_windows", "sine_layer_derivative"):
        if name in quoted:
            assert len(exercises.get(name).cases()) == quoted[name], name
