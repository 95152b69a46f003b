"""Exercise checks, round 5: about a hundred more wrong solutions written the way learners err.

Per registered exercise: an off-by-one at a window or bin edge or in a loop's range, a wrong sign or polarity
convention, log10 or 10 ** L or log1p for the natural log, C twice, x and y or H and W swapped, float32 or an int8
running sum where precision matters, an input changed in place, integer or floor division, the wrong reduction or
normalising count (B - 1, the events, the pixels, sum |n|), a median read as sorted[n // 2], a sweep where ties
matter, windows rebuilt as if the sequence started at 0, a torch tensor for a numpy array (and back), and edge cases
(no events, a single window, one network).

Holes (these passed a check before this round; each now fails and its report names the mistake):
- integrate_events_1d: a pixel with no events at all (csum[n - 1] on an empty sum); a Python loop `s = 0; s +=
  p[i]`, which stays int8 in NumPy 2 and wraps past 127, and an int8 buffer; float32 timestamps on an absolute clock
  (the cases now hold no events, 150 ON events at t ~ 1000 s and queries 10 us before an event);
- hot_pixel_mask: the median read as sorted[n // 2] (the third case now has an even number of firing pixels whose
  two middle counts differ);
- crossfade_weights: windows rebuilt from 0 (k * step), and the caller's windows shifted in place to start at 0
  (the first case now starts at 1.5 s).

Named: about sixty mistakes that failed with a bare "wrong values" (or a misleading note: a mean polarity called
fancy indexing, a median over distinct counts called a fixed factor) now get a hint; a float32 result that misses a
tight tolerance and a 1-D result one entry short or long get a generic note. Guards: wrong solutions that already
failed clearly, and correct alternatives (a loop with a float sum, np.digitize, floor division of floats, a dense
least-squares solve, the high-pass filter's closed form by np.add.at, sigmoid by tanh, the push-through inverse,
np.percentile) that must pass.
"""

import math

import numpy as np
import pytest
import torch

from evinr_lite.core.events import Events
from evinr_lite.method.losses import temporal_loss_derivative, tikhonov
from evinr_lite.teaching import exercises
from evinr_lite.teaching.checking.learner_calls import changed_inputs, run
from evinr_lite.teaching.checking.outputs import compare_outputs
from exercise_reports import quoted_counts, report as _report   # the check's verdict and its report; the notebooks' counts


def R(n): return exercises.reference(n)

# ---- integrate_events_1d
def integ_C_twice(t_events, p_events, C, t_query):
    return C * R("integrate_events_1d")(t_events, p_events, C, t_query)
def integ_on_only(t_events, p_events, C, t_query):
    p = np.asarray(p_events)
    return R("integrate_events_1d")(t_events, (p > 0).astype(float), C, t_query)
def integ_empty_breaks(t_events, p_events, C, t_query):
    csum = np.cumsum(np.asarray(p_events, float))
    n = np.searchsorted(t_events, t_query, side="right")
    return C * np.where(n > 0, csum[np.maximum(n - 1, 0)], 0.0)
def integ_drops_first(t_events, p_events, C, t_query):
    csum = np.concatenate([[0.0], [0.0], np.cumsum(np.asarray(p_events, float)[1:])])
    return C * csum[np.searchsorted(t_events, t_query, side="right")]
def integ_list(t_events, p_events, C, t_query):
    return [C * float(np.sum(p_events[t_events <= q])) for q in t_query]
def integ_loop_break(t_events, p_events, C, t_query):
    out = np.zeros(len(t_query))
    for k, q in enumerate(t_query):
        s = 0
        for ti, pi in zip(t_events, p_events):
            if ti > q: break
            s += pi
        out[k] = C * s
    return out
def integ_int8_acc(t_events, p_events, C, t_query):
    p = np.asarray(p_events)
    csum = np.zeros(len(p) + 1, dtype=p.dtype)
    csum[1:] = np.cumsum(p)
    return C * csum[np.searchsorted(t_events, t_query, side="right")]

# ---- event_rate_derivative
def rate_by_count(t_events, p_events, C, boundaries):
    b = np.asarray(boundaries, float); t = np.asarray(t_events, float)
    i = np.searchsorted(b, t, side="left") - 1; i[t == b[0]] = 0
    keep = (i >= 0) & (i < b.size - 1)
    s = np.bincount(i[keep], weights=np.asarray(p_events, float)[keep], minlength=b.size - 1)
    n = np.bincount(i[keep], minlength=b.size - 1)
    return C * s / np.maximum(n, 1)
def rate_total_duration(t_events, p_events, C, boundaries):
    b = np.asarray(boundaries, float)
    return R("event_rate_derivative")(t_events, p_events, C, b) * np.diff(b) / (b[-1] - b[0])
def rate_times_length(t_events, p_events, C, boundaries):
    b = np.asarray(boundaries, float)
    return R("event_rate_derivative")(t_events, p_events, C, b) * np.diff(b) ** 2
def rate_loop_one_short(t_events, p_events, C, boundaries):
    b = boundaries
    out = []
    for k in range(len(b) - 2):
        m = (t_events > b[k]) & (t_events <= b[k + 1]) | ((k == 0) & (t_events == b[0]))
        out.append(C * p_events[m].sum() / (b[k + 1] - b[k]))
    return np.array(out)
def rate_digitize_right(t_events, p_events, C, boundaries):
    b = np.asarray(boundaries, float)
    i = np.digitize(t_events, b, right=True) - 1
    keep = (i >= 0) & (i < b.size - 1)
    return C * np.bincount(i[keep], weights=np.asarray(p_events, float)[keep], minlength=b.size - 1) / np.diff(b)
def rate_closed_both(t_events, p_events, C, boundaries):
    b = boundaries
    return np.array([C * p_events[(t_events >= lo) & (t_events <= hi)].sum() / (hi - lo) for lo, hi in zip(b[:-1], b[1:])])

# ---- temporal_loss
def tl_b_minus_1(dF_dt, delta_L, durations):
    return ((delta_L - dF_dt * durations) ** 2).sum() / (len(delta_L) - 1)
def tl_square_of_mean(dF_dt, delta_L, durations):
    return torch.mean(delta_L - dF_dt * durations) ** 2
def tl_numpy(dF_dt, delta_L, durations):
    return np.mean((delta_L.numpy() - dF_dt.detach().numpy() * durations.numpy()) ** 2)
def tl_durations_squared(dF_dt, delta_L, durations):
    return torch.mean((delta_L - dF_dt * durations) ** 2 * durations)

# ---- esim_interval
def esim_round(L_a, L_b, t_a, t_b, ref, C, how=np.round, refsign=True, dfrom=None):
    d = L_b - (ref if dfrom is None else L_a)
    p = 1 if d > 0 else -1
    n = int(how(abs(d) / C))
    levels = ref + p * C * np.arange(1, n + 1)
    times = t_a + (levels - L_a) / (L_b - L_a) * (t_b - t_a) if n else np.zeros(0)
    return np.asarray(times, float), np.full(n, p, dtype=np.int8), float(ref + (p if refsign else 1) * n * C)
def esim_rounds(L_a, L_b, t_a, t_b, ref, C): return esim_round(L_a, L_b, t_a, t_b, ref, C)
def esim_ceil(L_a, L_b, t_a, t_b, ref, C): return esim_round(L_a, L_b, t_a, t_b, ref, C, how=np.ceil)
def esim_ref_unsigned(L_a, L_b, t_a, t_b, ref, C): return esim_round(L_a, L_b, t_a, t_b, ref, C, how=np.floor, refsign=False)
def esim_count_from_La(L_a, L_b, t_a, t_b, ref, C): return esim_round(L_a, L_b, t_a, t_b, ref, C, how=np.floor, dfrom="a")
def esim_empty_list(L_a, L_b, t_a, t_b, ref, C):
    times, p, r = R("esim_interval")(L_a, L_b, t_a, t_b, ref, C)
    return (list(times), list(p), r) if len(p) == 0 else (times, p, r)
def esim_float_int_division(L_a, L_b, t_a, t_b, ref, C):
    d = L_b - ref
    p = 1 if d > 0 else -1
    n = int(abs(d) // C)
    levels = ref + p * C * np.arange(1, n + 1)
    times = t_a + (levels - L_a) / (L_b - L_a) * (t_b - t_a) if n else np.zeros(0)
    return times.astype(np.float64), np.full(n, p, dtype=np.int8), float(ref + p * n * C)

# ---- events_to_frames_fixed
def frames_C_twice(events, boundaries, C):
    return C * R("events_to_frames_fixed")(events, boundaries, C)
def frames_mean_polarity(events, boundaries, C):
    f = R("events_to_frames_fixed")(events, boundaries, 1.0)
    ones = Events(events.t, events.x, events.y, np.ones(len(events), np.int8), events.sensor_size)
    n = R("events_to_frames_fixed")(ones, boundaries, 1.0)
    return (C * f / np.maximum(n, 1)).astype(np.float32)
def frames_nudges_b0(events, boundaries, C):
    b = boundaries
    b[0] -= 1e-9
    H, W = events.sensor_size
    i = np.searchsorted(b, events.t, side="left") - 1
    keep = (i >= 0) & (i < b.size - 1)
    f = np.zeros((b.size - 1, H, W)); np.add.at(f, (i[keep], events.y[keep], events.x[keep]), events.p[keep])
    return (C * f).astype(np.float32)
def frames_one_bin_too_many(events, boundaries, C):
    b = np.asarray(boundaries, float); H, W = events.sensor_size
    i = np.searchsorted(b, events.t, side="left") - 1; i[events.t == b[0]] = 0
    keep = (i >= 0) & (i < b.size - 1)
    f = np.zeros((b.size, H, W)); np.add.at(f, (i[keep], events.y[keep], events.x[keep]), events.p[keep])
    return (C * f).astype(np.float32)
def frames_float32_times(events, boundaries, C):
    ev = Events(events.t.astype(np.float32).astype(np.float64), events.x, events.y, events.p, events.sensor_size)
    return R("events_to_frames_fixed")(ev, boundaries, C)

# ---- interval_imbalance
from evinr_lite.teaching import events2d
def _imb(events, logf=np.log, stat=np.mean, out=lambda r: float(np.tanh(r / 2)), nan=float("nan")):
    H, W = events.sensor_size
    pix = events.y.astype(np.int64) * W + events.x
    order = np.argsort(pix, kind="stable")
    pix, t, p = pix[order], np.asarray(events.t, float)[order], events.p[order]
    pair = (pix[1:] == pix[:-1]) & (p[1:] == p[:-1])
    ld = logf(np.maximum(np.diff(t), events2d.MIN_INTERVAL))
    on = p[1:] > 0
    if not (pair & on).any() or not (pair & ~on).any():
        return nan
    return out(stat(ld[pair & on]) - stat(ld[pair & ~on]))
def imb_log10(events): return _imb(events, logf=np.log10)
def imb_tanh_r(events): return _imb(events, out=lambda r: float(np.tanh(r)))
def imb_median(events): return _imb(events, stat=np.median)
def imb_zero_not_nan(events): return _imb(events, nan=0.0)
def imb_raw_ratio(events):
    return _imb(events, logf=lambda d: d, out=lambda r: r) if False else _imb_raw(events)
def _imb_raw(events):
    H, W = events.sensor_size
    pix = events.y.astype(np.int64) * W + events.x
    order = np.argsort(pix, kind="stable")
    pix, t, p = pix[order], np.asarray(events.t, float)[order], events.p[order]
    pair = (pix[1:] == pix[:-1]) & (p[1:] == p[:-1])
    d = np.maximum(np.diff(t), events2d.MIN_INTERVAL); on = p[1:] > 0
    if not (pair & on).any() or not (pair & ~on).any():
        return float("nan")
    a, b = d[pair & on].mean(), d[pair & ~on].mean()
    return float((a - b) / (a + b))

# ---- split_index
def split_no_mod(index, sensor_size):
    H, W = sensor_size
    return index // (H * W), index // W, index % W
def split_stacked(index, sensor_size):
    H, W = sensor_size
    return torch.stack([index // (H * W), (index // W) % H, index % W])
def split_numpy(index, sensor_size):
    H, W = sensor_size
    i = index.numpy()
    return i // (H * W), (i // W) % H, i % W

# ---- tikhonov_autograd
def tik_half(dF_dx, dF_dy): return 0.5 * torch.mean(dF_dx ** 2 + dF_dy ** 2)
def tik_rms(dF_dx, dF_dy): return torch.sqrt(torch.mean(dF_dx ** 2 + dF_dy ** 2))
def tik_norm_sq(dF_dx, dF_dy): return (torch.norm(dF_dx) ** 2 + torch.norm(dF_dy) ** 2)

# ---- sine_layer_derivative
def sine_precedence(h, dh_dt, weight, bias, omega):
    z = omega * (h @ weight + bias)
    return torch.sin(z), torch.cos(z) * omega * dh_dt @ weight
def sine_bias_in_derivative(h, dh_dt, weight, bias, omega):
    z = omega * (h @ weight + bias)
    return torch.sin(z), torch.cos(z) * omega * (dh_dt @ weight + bias)
def sine_weight_T(h, dh_dt, weight, bias, omega):
    z = omega * (h @ weight + bias)
    return torch.sin(z), torch.cos(z) * omega * (dh_dt @ weight.T)
def sine_omega_squared(h, dh_dt, weight, bias, omega):
    z = omega * (h @ weight + bias)
    return torch.sin(z), torch.cos(z) * omega ** 2 * (dh_dt @ weight)

# ---- temporal_loss_boundary
def tlb_F_not_diff(F_boundaries, event_frames): return torch.mean((event_frames - F_boundaries[1:]) ** 2)
def tlb_over_B(F_boundaries, event_frames):
    return ((event_frames - (F_boundaries[1:] - F_boundaries[:-1])) ** 2).sum() / event_frames.shape[0]
def tlb_diff_wrong_dim(F_boundaries, event_frames):
    return torch.mean((event_frames - torch.diff(F_boundaries, dim=-1)) ** 2)
def tlb_shifted(F_boundaries, event_frames):
    return torch.mean((event_frames[1:] - (F_boundaries[1:-1] - F_boundaries[:-2])) ** 2)

# ---- total_variation
def tv_over_numel(F):
    dx = F[..., :, 1:] - F[..., :, :-1]; dy = F[..., 1:, :] - F[..., :-1, :]
    return (dx.abs().sum() + dy.abs().sum()) / F.numel()
def tv_roll(F):
    return (F - torch.roll(F, 1, -1)).abs().mean() + (F - torch.roll(F, 1, -2)).abs().mean()
def tv_joint_crop(F):
    dx = F[..., :-1, 1:] - F[..., :-1, :-1]; dy = F[..., 1:, :-1] - F[..., :-1, :-1]
    return (dx.abs() + dy.abs()).mean()
def tv_hardcoded_2d(F):
    return (F[:, :, 1:] - F[:, :, :-1]).abs().mean() + (F[:, 1:, :] - F[:, :-1, :]).abs().mean()

# ---- reinhard_tonemap
def tm_pow10(L, gamma):
    I = 10.0 ** np.asarray(L, float); return (I / (I + 1)) ** gamma
def tm_gamma_inside(L, gamma):
    I = np.exp(np.asarray(L, float)) ** gamma; return I / (I + 1)
def tm_minus_one(L, gamma):
    I = np.expm1(np.asarray(L, float)); return (I / (I + 1)) ** gamma

# ---- anchor
def anchor_log10(L, gamma, display_mean):
    L = np.asarray(L, float); s = display_mean ** (1 / gamma)
    return L + (np.log10(s / (1 - s)) - L.mean())
def anchor_inverse_logit(L, gamma, display_mean):
    L = np.asarray(L, float); s = display_mean ** (1 / gamma)
    return L + (np.log((1 - s) / s) - L.mean())
def anchor_int_exponent(L, gamma, display_mean):
    L = np.asarray(L, float); s = display_mean ** (1 // gamma) if gamma >= 1 else display_mean ** (1 / gamma)
    return L + (np.log(s / (1 - s)) - L.mean())

# ---- offset_gradients
def og_median_image(frames):
    m = np.median(np.asarray(frames, float), axis=0)
    return -np.diff(m, axis=1), -np.diff(m, axis=0)
def og_last_minus_first(frames):
    F = np.asarray(frames, float)
    return -np.median(F[:, :, 1:] - F[:, :, :1], axis=0), -np.median(F[:, 1:, :] - F[:, :1, :], axis=0)
def og_torch(frames):
    F = torch.as_tensor(frames)
    return -torch.diff(F, dim=2).median(dim=0).values, -torch.diff(F, dim=1).median(dim=0).values

# ---- integrate_gradients
def ig_hw_from_gx(gx, gy):
    gx, gy = np.asarray(gx, float), np.asarray(gy, float)
    H, W = gx.shape[0], gx.shape[1] + 1
    from evinr_lite.teaching.poisson_exercises import _differences
    D = _differences(H, W).toarray()
    g = np.linalg.lstsq(D, np.concatenate([gx.ravel(), gy.ravel()]), rcond=None)[0]
    return (g - g.mean()).reshape(H, W)
def ig_rows_only(gx, gy):
    gx = np.asarray(gx, float); H = gx.shape[0]; W = np.asarray(gy).shape[1]
    g = np.zeros((H, W)); g[:, 1:] = np.cumsum(gx, axis=1)
    return g - g.mean()

# ---- bisect_equal_count
def _bis(t_events, boundaries, empty=lambda lo, hi: 0.5 * (lo + hi), member=None):
    t, b = np.asarray(t_events, float), np.asarray(boundaries, float)
    out = [b[0]]
    for i in range(len(b) - 1):
        lo, hi = b[i], b[i + 1]
        m = t[member(t, i, lo, hi)] if member else t[((t > lo) | ((i == 0) & (t == lo))) & (t <= hi)]
        n = len(m); cut = empty(lo, hi)
        if n >= 2 and lo < 0.5 * (m[n // 2 - 1] + m[n // 2]) < hi:
            cut = 0.5 * (m[n // 2 - 1] + m[n // 2])
        elif n >= 2: cut = 0.5 * (lo + hi)
        out += [cut, hi]
    return np.array(out)
def bis_empty_at_lo(t_events, boundaries): return _bis(t_events, boundaries, empty=lambda lo, hi: lo)
def bis_closed_both(t_events, boundaries): return _bis(t_events, boundaries, member=lambda t, i, lo, hi: (t >= lo) & (t <= hi))
def bis_mean_of_halves(t_events, boundaries):
    t, b = np.asarray(t_events, float), np.asarray(boundaries, float)
    out = [b[0]]
    for i in range(len(b) - 1):
        lo, hi = b[i], b[i + 1]
        m = t[((t > lo) | ((i == 0) & (t == lo))) & (t <= hi)]
        n = len(m); cut = 0.5 * (lo + hi)
        if n >= 2:
            c = 0.5 * (m[(n - 1) // 2] + m[n // 2])
            cut = c if lo < c < hi else cut
        out += [cut, hi]
    return np.array(out)

# ---- crossfade_weights
def cf_no_single(windows, times):
    windows, t = np.asarray(windows, float), np.asarray(times, float)
    lo, hi = windows[:, :1], windows[:, 1:]
    ov = windows[0, 1] - windows[1, 0]
    fi = np.clip((t - lo) / ov, 0, 1); fo = np.clip((hi - t) / ov, 0, 1); fi[0] = 1; fo[-1] = 1
    w = np.minimum(fi, fo); return w / w.sum(axis=0, keepdims=True)
def cf_overlap_from_tau(windows, times):
    windows, t = np.asarray(windows, float), np.asarray(times, float)
    if len(windows) == 1: return np.ones((1, len(t)))
    ov = 0.25 * (windows[0, 1] - windows[0, 0])
    lo, hi = windows[:, :1], windows[:, 1:]
    fi = np.clip((t - lo) / ov, 0, 1); fo = np.clip((hi - t) / ov, 0, 1); fi[0] = 1; fo[-1] = 1
    w = np.minimum(fi, fo); return w / w.sum(axis=0, keepdims=True)
def cf_smoothstep(windows, times):
    w = R("crossfade_weights")(windows, times)
    s = w * w * (3 - 2 * w); return s / s.sum(axis=0, keepdims=True)

# ---- chain_offsets
def chain_median(prev, nxt):
    steps = np.median(np.asarray(prev, float) - np.asarray(nxt, float), axis=1)
    return np.concatenate([np.zeros((1,) + np.shape(prev)[2:]), np.cumsum(steps, axis=0)])
def chain_empty_breaks(prev, nxt):
    steps = (np.asarray(prev, float) - np.asarray(nxt, float)).mean(axis=1)
    return np.concatenate([np.zeros_like(steps[:1]), np.cumsum(steps, axis=0)])
def chain_loop_range(prev, nxt):
    prev, nxt = np.asarray(prev, float), np.asarray(nxt, float)
    K = len(prev); out = np.zeros((K + 1,) + prev.shape[2:])
    for k in range(1, K):
        out[k] = out[k - 1] + (prev[k - 1] - nxt[k - 1]).mean(axis=0)
    return out
def chain_first_sample(prev, nxt):
    steps = np.asarray(prev, float)[:, 0] - np.asarray(nxt, float)[:, 0]
    return np.concatenate([np.zeros((1,) + np.shape(prev)[2:]), np.cumsum(steps, axis=0)])

# ---- time_fps_products
def tfp_list(table): return [r["time_s"] * r["fps"] for r in table.values()]
def tfp_round(table): return {k: round(r["time_s"] * r["fps"]) for k, r in table.items()}
def tfp_minutes(table): return {k: r["time_s"] / 60 * r["fps"] for k, r in table.items()}

# ---- pareto_front
def pf_sweep(cost, quality, ge=False):
    c, q = np.asarray(cost, float), np.asarray(quality, float)
    order = np.lexsort((-q, c)); keep = np.zeros(len(c), bool); best = -np.inf
    for i in order:
        if q[i] > best or (ge and q[i] >= best):
            keep[i] = True; best = q[i]
    return keep
def pf_sweep_strict(cost, quality): return pf_sweep(cost, quality)
def pf_sweep_ge(cost, quality): return pf_sweep(cost, quality, ge=True)
def pf_quality_lower(cost, quality): return R("pareto_front")(cost, -np.asarray(quality, float))

# ---- highpass_per_event
def hp_ignores_t_start(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    return R("highpass_per_event")(t, x, y, p, sensor_size, C, alpha, t_end, 0.0)
def hp_growth(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    return R("highpass_per_event")(t, x, y, p, sensor_size, C, -alpha, t_end, t_start)
def hp_fancy(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    s = np.zeros(sensor_size); s[np.asarray(y), np.asarray(x)] += C * np.asarray(p) * np.exp(-alpha * (t_end - np.asarray(t)))
    return s
def hp_float_state_int(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    H, W = sensor_size
    state = np.zeros((H, W), dtype=int); t_last = np.full((H, W), float(t_start))
    for ti, xi, yi, pi in zip(t, x, y, p):
        state[yi, xi] = np.exp(-alpha * (ti - t_last[yi, xi])) * state[yi, xi] + C * pi
        t_last[yi, xi] = ti
    return state * np.exp(-alpha * (t_end - t_last))

# ---- render_event_counts
def rc_grid(L_boundaries, C):
    L = np.asarray(L_boundaries, float); m = np.trunc((L - L[0]) / C)
    return np.diff(m, axis=0).astype(np.int64)
def rc_counts_times_C(L_boundaries, C): return R("render_event_counts")(L_boundaries, C) * C
def rc_with_first(L_boundaries, C):
    r = R("render_event_counts")(L_boundaries, C); return np.concatenate([np.zeros_like(r[:1]), r])

# ---- event_rate
def er_fraction(t, bin_s):
    c, r = R("event_rate")(t, bin_s); return c, r * bin_s / len(t)
def er_no_min_one(t, bin_s):
    t = np.asarray(t, float); n = int(np.ceil((t[-1] - t[0]) / bin_s))
    k = np.clip(np.ceil((t - t[0]) / bin_s).astype(np.int64) - 1, 0, n - 1)
    return t[0] + (np.arange(n) + 0.5) * bin_s, np.bincount(k, minlength=n) / bin_s
def er_arange_edges(t, bin_s):
    t = np.asarray(t, float); edges = np.arange(t[0], t[-1] + bin_s, bin_s)
    k = np.clip(np.searchsorted(edges, t, side="left") - 1, 0, len(edges) - 2)
    return edges[:-1] + bin_s / 2, np.bincount(k, minlength=len(edges) - 1) / bin_s

# ---- estimate_contrast_threshold
def ct_abs_norm(log_changes, net_counts):
    d, n = np.asarray(log_changes, float), np.asarray(net_counts, float); return float(np.sum(d * n) / np.sum(np.abs(n)))
def ct_over_M(log_changes, net_counts):
    d, n = np.asarray(log_changes, float), np.asarray(net_counts, float); return float(np.sum(d * n) / len(n))
def ct_nonzero_only_mean(log_changes, net_counts):
    d, n = np.asarray(log_changes, float), np.asarray(net_counts, float); k = n != 0
    return float(np.sum(d[k]) / np.sum(n[k]))

# ---- anchor_first_offset
def af_log1p(first_frame, L_t0, eps=1 / 255):
    a = np.asarray(first_frame); I = a / 255.0 if a.dtype == np.uint8 else np.clip(a, 0, 1)
    return np.log1p(I) - L_t0
def af_floor_div(first_frame, L_t0, eps=1 / 255):
    a = np.asarray(first_frame); I = a // 255 if a.dtype == np.uint8 else a
    return np.log(I + eps) - L_t0
def af_uint8_wrap(first_frame, L_t0, eps=1 / 255):
    a = np.asarray(first_frame)
    I = (a + 1) / 256.0 if a.dtype == np.uint8 else a
    return np.log(I) - L_t0

# ---- quad_bayer_channel
def qb_args_swapped(y, x, phase): return R("quad_bayer_channel")(x, y, phase)
def qb_phase_after_block(y, x, phase):
    return (((np.asarray(y) // 2 + phase[0]) % 2) + ((np.asarray(x) // 2 + phase[1]) % 2)).astype(np.int64)
def qb_rb_swapped(y, x, phase): return 2 - R("quad_bayer_channel")(y, x, phase)

# ---- grey_event_frame
def gf_abs(x, y, p, C, raw_size): return R("grey_event_frame")(x, y, np.abs(p), C, raw_size)
def gf_floor_div(x, y, p, C, raw_size):
    H, W = raw_size; f = np.zeros((H // 4, W // 4))
    np.add.at(f, (np.asarray(y) // 4, np.asarray(x) // 4), C * np.asarray(p, float) // 16); return f
def gf_hist2d(x, y, p, C, raw_size):
    H, W = raw_size
    f, _, _ = np.histogram2d(np.asarray(y) // 4, np.asarray(x) // 4, bins=(H // 4, W // 4), weights=np.asarray(p, float))
    return C * f / 16
def gf_div2(x, y, p, C, raw_size):
    H, W = raw_size; f = np.zeros((H // 4, W // 4))
    np.add.at(f, (np.asarray(y) // 2 // 2, np.asarray(x) // 2), C * np.asarray(p, float) / 16)
    return f

# ---- head_closed_form
def head_eye_B(A, E, ridge):
    A = np.asarray(A, float); return np.linalg.solve(A.T @ A + ridge * np.eye(A.shape[0]), A.T @ E)
def head_dual(A, E, ridge):
    A = np.asarray(A, float); return A.T @ np.linalg.solve(A @ A.T + ridge * np.eye(A.shape[0]), E)
def head_float32(A, E, ridge):
    A = np.asarray(A, np.float32); E = np.asarray(E, np.float32)
    return np.linalg.solve(A.T @ A + np.float32(ridge) * np.eye(A.shape[1], dtype=np.float32), A.T @ E)
def head_sqrt_ridge(A, E, ridge):
    A = np.asarray(A, float); return np.linalg.solve(A.T @ A + ridge ** 2 * np.eye(A.shape[1]), A.T @ E)

# ---- hot_pixel_mask
def hot_unique_median(x, y, sensor_size, factor=10.0):
    H, W = sensor_size; c = np.bincount(np.asarray(y) * W + np.asarray(x), minlength=H * W).reshape(H, W)
    return c > factor * np.median(np.unique(c[c > 0]))
def hot_exclude_single(x, y, sensor_size, factor=10.0):
    H, W = sensor_size; c = np.bincount(np.asarray(y) * W + np.asarray(x), minlength=H * W).reshape(H, W)
    return c > factor * np.median(c[c > 1])
def hot_ratio_int(x, y, sensor_size, factor=10.0):
    H, W = sensor_size; c = np.bincount(np.asarray(y) * W + np.asarray(x), minlength=H * W).reshape(H, W)
    return c // np.median(c[c > 0]) > factor

# ---- event_count_windows
def ecw_plus_one(n_events, max_events):
    w = n_events // max_events + 1; return (np.arange(w + 1) * n_events) // w
def ecw_array_split(n_events, max_events):
    w = math.ceil(n_events / max_events)
    return np.concatenate([[0], np.cumsum([len(a) for a in np.array_split(np.arange(n_events), w)])]).astype(np.int64)
def ecw_round(n_events, max_events):
    w = math.ceil(n_events / max_events); return np.round(np.arange(w + 1) * n_events / w).astype(np.int64)

# ---- background_activity_filter
def baf_manhattan2(t, x, y, dt):
    t = np.asarray(t, float); x, y = np.asarray(x), np.asarray(y)
    m = np.abs(x[:, None] - x[None, :]) + np.abs(y[:, None] - y[None, :])
    return np.any((m >= 1) & (m <= 2) & (t[None, :] <= t[:, None]) & (t[:, None] <= t[None, :] + dt), axis=1)
def baf_time_map(t, x, y, dt):
    H, W = int(np.max(y)) + 3, int(np.max(x)) + 3
    last = np.full((H, W), -np.inf); keep = np.zeros(len(t), bool)
    for i in range(len(t)):
        yi, xi = y[i] + 1, x[i] + 1
        nb = last[yi - 1:yi + 2, xi - 1:xi + 2].copy(); nb[1, 1] = -np.inf
        keep[i] = t[i] - nb.max() <= dt
        last[yi, xi] = t[i]
    return keep
def baf_uint_x(t, x, y, dt):
    t = np.asarray(t, float); x, y = np.asarray(x, np.uint8), np.asarray(y, np.uint8)
    cheb = np.maximum(np.abs(x[:, None] - x[None, :]), np.abs(y[:, None] - y[None, :]))
    return np.any((cheb == 1) & (t[None, :] <= t[:, None]) & (t[:, None] <= t[None, :] + dt), axis=1)


def integ_accumulate(t_events, p_events, C, t_query):
    csum = np.concatenate([[0], np.add.accumulate(np.asarray(p_events))])
    return C * csum[np.searchsorted(t_events, t_query, side="right")]
def integ_f32(t_events, p_events, C, t_query):
    return R("integrate_events_1d")(np.float32(t_events), p_events, C, np.float32(t_query))
def rate_f32(t_events, p_events, C, boundaries):
    return R("event_rate_derivative")(np.float32(t_events), p_events, C, np.float32(boundaries)).astype(float)
def imb_f32(events):
    return R("interval_imbalance")(Events(events.t.astype(np.float32), events.x, events.y, events.p, events.sensor_size))
def er_f32(t, bin_s):
    c, r = R("event_rate")(np.float32(t), np.float32(bin_s)); return c.astype(float), r.astype(float)
def baf_f32(t, x, y, dt):
    return R("background_activity_filter")(np.float32(t), x, y, np.float32(dt))
def rate_addat_int8(t_events, p_events, C, boundaries):
    b = np.asarray(boundaries, float); t = np.asarray(t_events, float)
    i = np.searchsorted(b, t, side="left") - 1; i[t == b[0]] = 0
    keep = (i >= 0) & (i < b.size - 1)
    s = np.zeros(b.size - 1, dtype=np.asarray(p_events).dtype); np.add.at(s, i[keep], np.asarray(p_events)[keep])
    return C * s / np.diff(b)
def chain_inplace(prev, nxt):
    prev -= nxt
    steps = prev.mean(axis=1)
    return np.concatenate([np.zeros((1,) + prev.shape[2:]), np.cumsum(steps, axis=0)])
def cf_inplace(windows, times):
    windows -= 0.0 * windows  # no-op in value
    w0 = windows[0, 0]; windows -= w0; t = np.asarray(times) - w0
    return R("crossfade_weights")(windows, t)
def _step(model, optimizer, event_frames, centers, durations, lam, mode):
    F, dF = model.forward_with_derivative(centers)
    temporal = temporal_loss_derivative(dF, event_frames, durations)
    reg = tikhonov(dF if mode == "reg_on_dF" else F)
    loss = (lam * temporal + reg) if mode == "lam_on_temporal" else temporal + lam * reg
    optimizer.zero_grad(); loss.backward()
    if mode == "zero_after_backward": optimizer.zero_grad()
    optimizer.step()
    if mode == "after":
        F, dF = model.forward_with_derivative(centers)
        temporal = temporal_loss_derivative(dF, event_frames, durations); reg = tikhonov(F); loss = temporal + lam * reg
    return loss.detach(), temporal.detach(), reg.detach()
def step_zero_after_backward(model, optimizer, event_frames, centers, durations, lam): return _step(model, optimizer, event_frames, centers, durations, lam, "zero_after_backward")
def step_lam_on_temporal(model, optimizer, event_frames, centers, durations, lam): return _step(model, optimizer, event_frames, centers, durations, lam, "lam_on_temporal")
def step_reg_on_dF(model, optimizer, event_frames, centers, durations, lam): return _step(model, optimizer, event_frames, centers, durations, lam, "reg_on_dF")
def step_losses_after(model, optimizer, event_frames, centers, durations, lam): return _step(model, optimizer, event_frames, centers, durations, lam, "after")
def bisect_empty_input_breaks(t_events, boundaries):
    t = np.asarray(t_events, float); b = np.asarray(boundaries, float)
    idx = np.searchsorted(t, b, side="right"); idx[0] = np.searchsorted(t, b[0], side="left")
    out = np.empty(2 * len(b) - 1); out[0::2] = b
    for i in range(len(b) - 1):
        m = t[idx[i]:idx[i + 1]]; n = len(m); cut = 0.5 * (b[i] + b[i + 1])
        if n >= 2 and b[i] < 0.5 * (m[n // 2 - 1] + m[n // 2]) < b[i + 1]: cut = 0.5 * (m[n // 2 - 1] + m[n // 2])
        out[2 * i + 1] = cut
    return out
def hot_first_pixel_median(x, y, sensor_size, factor=10.0):
    H, W = sensor_size; c = np.bincount(np.asarray(y) * W + np.asarray(x), minlength=H * W).reshape(H, W)
    nz = np.sort(c[c > 0]); return c > factor * nz[len(nz) // 2]
def pf_tie_first(cost, quality):
    c, q = np.asarray(cost, float), np.asarray(quality, float)
    keep = np.ones(len(c), bool)
    for i in range(len(c)):
        for j in range(len(c)):
            if j != i and c[j] <= c[i] and q[j] >= q[i] and (c[j] < c[i] or q[j] > q[i] or j < i): keep[i] = False
    return keep
def er_from_hist(t, bin_s):
    t = np.asarray(t, float); n = max(int(np.ceil((t[-1] - t[0]) / bin_s)), 1)
    counts, edges = np.histogram(t, bins=n, range=(t[0], t[0] + n * bin_s))
    return 0.5 * (edges[1:] + edges[:-1]), counts / bin_s

def cf_windows_from_zero(windows, times):
    windows = np.asarray(windows, float)
    if len(windows) == 1: return np.ones((1, len(times)))
    tau, step = windows[0, 1] - windows[0, 0], windows[1, 0] - windows[0, 0]
    lo = step * np.arange(len(windows))
    return R("crossfade_weights")(np.stack([lo, lo + tau], 1), times)

def hp_vectorised(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    """Guard (correct): the filter is linear, so its state is the sum of C p exp(-alpha (t_end - t)) per pixel."""
    s = np.zeros(sensor_size)
    np.add.at(s, (np.asarray(y), np.asarray(x)), C * np.asarray(p) * np.exp(-alpha * (t_end - np.asarray(t))))
    return s


def integ_loop_float(t_events, p_events, C, t_query):
    """Guard (correct): the loop with a float accumulator, so int8 polarities cannot overflow."""
    out = np.zeros(len(t_query))
    for k, q in enumerate(t_query):
        s = 0.0
        for ti, pi in zip(t_events, p_events):
            if ti > q:
                break
            s += float(pi)
        out[k] = C * s
    return out


# ---- holes: each of these passed its check before this round ----------------------------------------------

HOLES = [
    ("integrate_events_1d", integ_empty_breaks, "IndexError"),                       # no events at all
    ("integrate_events_1d", integ_loop_break, "the running sum overflowed"),        # s = 0; s += p[i] stays int8
    ("integrate_events_1d", integ_int8_acc, "the running sum overflowed"),          # an int8 buffer
    ("integrate_events_1d", integ_f32, "timestamps must stay float64"),              # 10 us apart at t ~ 1000 s
    ("hot_pixel_mask", hot_first_pixel_median, "the mean of the two middle values"),  # sorted[n // 2]
    ("crossfade_weights", cf_windows_from_zero, "need not start at 0"),             # windows rebuilt from 0
    ("crossfade_weights", cf_inplace, "changed its input `windows` in place"),       # shifted to start at 0
]

# ---- wrong solutions that failed before, now (or already) with a message that names the mistake ------------

NAMED = [
    ("integrate_events_1d", integ_C_twice, "multiply by C once"),
    ("integrate_events_1d", integ_on_only, "OFF events count too"),
    ("integrate_events_1d", integ_drops_first, "the first event is lost"),
    ("event_rate_derivative", rate_by_count, "not by the number of events in it"),
    ("event_rate_derivative", rate_total_duration, "not by the whole span"),
    ("event_rate_derivative", rate_times_length, "do not multiply by it"),
    ("event_rate_derivative", rate_closed_both, "counts in two windows"),
    ("event_rate_derivative", rate_loop_one_short, "one entry too few"),
    ("event_rate_derivative", rate_digitize_right, "exactly on the first edge b_0 opens window 0"),
    ("temporal_loss", tl_b_minus_1, "not B - 1"),
    ("temporal_loss", tl_square_of_mean, "not torch.mean(d) ** 2"),
    ("esim_interval", esim_rounds, "not round"),
    ("esim_interval", esim_ceil, "not ceil"),
    ("esim_interval", esim_ref_unsigned, "down for OFF events"),
    ("esim_interval", esim_count_from_La, "one entry too few"),
    ("events_to_frames_fixed", frames_C_twice, "multiply by C once"),
    ("events_to_frames_fixed", frames_mean_polarity, "do not average them"),
    ("events_to_frames_fixed", frames_one_bin_too_many, "wrong shape"),
    ("interval_imbalance", imb_log10, "natural logs"),
    ("interval_imbalance", imb_tanh_r, "with the half"),
    ("interval_imbalance", imb_median, "not the median"),
    ("interval_imbalance", imb_zero_not_nan, "return NaN"),
    ("interval_imbalance", imb_raw_ratio, "average the log intervals"),
    ("split_index", split_no_mod, "without `% H`"),
    ("tikhonov_autograd", tik_half, "half the expected value"),
    ("tikhonov_autograd", tik_rms, "that is an RMS"),
    ("tikhonov_autograd", tik_norm_sq, "not the sum"),
    ("sine_layer_derivative", sine_bias_in_derivative, "the bias is a constant"),
    ("sine_layer_derivative", sine_omega_squared, "omega appears once"),
    ("frame_train_step", step_zero_after_backward, "no optimizer.zero_grad() between the two"),
    ("frame_train_step", step_lam_on_temporal, "lam weights the regularizer"),
    ("frame_train_step", step_reg_on_dF, "not of dF/dt"),
    ("frame_train_step", step_losses_after, "before optimizer.step()"),
    ("temporal_loss_boundary", tlb_F_not_diff, "not with the value F(b_{i+1}) itself"),
    ("temporal_loss_boundary", tlb_over_B, "B * H * W squares"),
    ("temporal_loss_boundary", tlb_shifted, "wrong value"),
    ("total_variation", tv_over_numel, "not over the H W pixels"),
    ("total_variation", tv_roll, "torch.roll wraps round"),
    ("total_variation", tv_joint_crop, "cropping both"),
    ("reinhard_tonemap", tm_pow10, "not 10 ** L"),
    ("reinhard_tonemap", tm_gamma_inside, "not to I inside it"),
    ("reinhard_tonemap", tm_minus_one, "NaN or inf"),
    ("anchor", anchor_log10, "not np.log10"),
    ("anchor", anchor_inverse_logit, "not log((1 - s) / s)"),
    ("offset_gradients", og_median_image, "not the differences of the median frame"),
    ("offset_gradients", og_last_minus_first, "gx: wrong values"),
    ("integrate_gradients", ig_rows_only, "wrong values"),
    ("bisect_equal_count", bis_empty_at_lo, "not at its first edge"),
    ("bisect_equal_count", bis_closed_both, "counts in two bins"),
    ("bisect_equal_count", bis_mean_of_halves, "np.median of an odd number of events"),
    ("crossfade_weights", cf_overlap_from_tau, "wrong values"),
    ("crossfade_weights", cf_smoothstep, "wrong values"),
    ("chain_offsets", chain_median, "not the median"),
    ("chain_offsets", chain_loop_range, "not range(1, K)"),
    ("chain_offsets", chain_first_sample, "not only the first one"),
    ("time_fps_products", tfp_minutes, "wrong value"),
    ("pareto_front", pf_sweep_strict, "ties in both are on the front"),
    ("pareto_front", pf_sweep_ge, "keeps one that costs more"),
    ("pareto_front", pf_quality_lower, "wrong values"),
    ("pareto_front", pf_tie_first, "wrong values"),
    ("highpass_per_event", hp_growth, "with the minus sign"),
    ("highpass_per_event", hp_fancy, "fancy indexing does not accumulate"),
    ("highpass_per_event", hp_float_state_int, "integer dtype"),
    ("render_event_counts", rc_grid, "not on a fixed grid of levels"),
    ("event_rate", er_fraction, "not by the number of events"),
    ("event_rate", er_from_hist, "wrong values"),
    ("estimate_contrast_threshold", ct_abs_norm, "not sum(|n|)"),
    ("estimate_contrast_threshold", ct_over_M, "not by the number of pixels"),
    ("estimate_contrast_threshold", ct_nonzero_only_mean, "wrong value"),
    ("anchor_first_offset", af_log1p, "np.log1p(I) is log(1 + I)"),
    ("anchor_first_offset", af_floor_div, "integer division"),
    ("anchor_first_offset", af_uint8_wrap, "NaN or inf"),
    ("quad_bayer_channel", qb_args_swapped, "phase is (dy, dx)"),
    ("quad_bayer_channel", qb_phase_after_block, "add the phase before dividing into blocks"),
    ("quad_bayer_channel", qb_rb_swapped, "0 = R, 1 = G, 2 = B"),
    ("grey_event_frame", gf_abs, "the sign of the polarity"),
    ("grey_event_frame", gf_floor_div, "floor division"),
    ("grey_event_frame", gf_hist2d, "np.histogram2d with a number of bins"),
    ("head_closed_form", head_float32, "the result is float32"),
    ("head_closed_form", head_dual, "wrong values"),
    ("head_closed_form", head_sqrt_ridge, "wrong values"),
    ("hot_pixel_mask", hot_unique_median, "not of the distinct values (np.unique)"),
    ("hot_pixel_mask", hot_exclude_single, "nor of the pixels that fired more than once"),
    ("hot_pixel_mask", hot_ratio_int, "integer division rounds the ratio down"),
    ("event_count_windows", ecw_plus_one, "the fewest windows"),
    ("event_count_windows", ecw_array_split, "np.array_split puts them first"),
    ("event_count_windows", ecw_round, "np.round moves some edges"),
    ("background_activity_filter", baf_manhattan2, "|dx| + |dy| <= 2"),
    ("background_activity_filter", baf_uint_x, "unsigned coordinates"),
    ("background_activity_filter", baf_time_map, "compare times, not positions in the stream"),
    ("background_activity_filter", baf_f32, "wrong values"),
]

# ---- guards: wrong solutions that already failed with a clear message (an exception on an edge case, the wrong
# container, an input changed in place) --------------------------------------------------------------------

GUARDS = [
    ("integrate_events_1d", integ_list, "expected a numpy array"),
    ("temporal_loss", tl_numpy, "expected a torch.Tensor"),
    ("temporal_loss", tl_durations_squared, "wrong value"),
    ("esim_interval", esim_empty_list, "expected a numpy array"),
    ("events_to_frames_fixed", frames_nudges_b0, "changed its input `boundaries` in place"),
    ("interval_imbalance", imb_f32, "float32"),
    ("split_index", split_stacked, "expected a tuple of 3 items"),
    ("split_index", split_numpy, "expected a torch.Tensor like the input"),
    ("sine_layer_derivative", sine_precedence, "RuntimeError"),
    ("sine_layer_derivative", sine_weight_T, "RuntimeError"),
    ("temporal_loss_boundary", tlb_diff_wrong_dim, "RuntimeError"),
    ("total_variation", tv_hardcoded_2d, "IndexError"),
    ("anchor", anchor_int_exponent, "ZeroDivisionError"),
    ("offset_gradients", og_torch, "expected a numpy array"),
    ("crossfade_weights", cf_no_single, "IndexError"),
    ("chain_offsets", chain_empty_breaks, "wrong shape"),
    ("chain_offsets", chain_inplace, "changed its input `prev` in place"),
    ("time_fps_products", tfp_list, "expected a dict"),
    ("time_fps_products", tfp_round, "wrong dtype"),
    ("render_event_counts", rc_counts_times_C, "wrong dtype"),
    ("render_event_counts", rc_with_first, "wrong shape"),
    ("event_rate", er_no_min_one, "ValueError"),
    ("event_rate", er_arange_edges, "ValueError"),
    ("grey_event_frame", gf_div2, "IndexError"),
    ("head_closed_form", head_eye_B, "ValueError"),
]

CORRECT = [
    ("integrate_events_1d", integ_loop_float),
    ("integrate_events_1d", lambda t_events, p_events, C, t_query: C * np.concatenate(
        [[0.0], np.cumsum(p_events)])[np.digitize(t_query, t_events)]),
    ("esim_interval", esim_float_int_division),                    # abs(d) // C: floor division of floats
    ("esim_interval", lambda L_a, L_b, t_a, t_b, ref, C: (lambda r: (r[0], r[1].astype(np.int64), r[2]))(
        R("esim_interval")(L_a, L_b, t_a, t_b, ref, C))),          # int64 polarities
    ("integrate_gradients", ig_hw_from_gx),                        # a dense least-squares solve
    ("bisect_equal_count", bisect_empty_input_breaks),             # searchsorted slices
    ("highpass_per_event", hp_ignores_t_start),                    # the state starts at 0: t_start cannot show
    ("highpass_per_event", hp_vectorised),                         # sum of C p exp(-alpha (t_end - t)) by np.add.at
    ("reinhard_tonemap", lambda L, gamma: 1 / (1 + np.exp(-np.asarray(L, float))) ** gamma),
    ("reinhard_tonemap", lambda L, gamma: (0.5 * (1 + np.tanh(np.asarray(L, float) / 2))) ** gamma),
    ("head_closed_form", lambda A, E, ridge: np.linalg.inv(A.T @ A + ridge * np.eye(A.shape[1])) @ A.T @ E),
    ("quad_bayer_channel", lambda y, x, phase: ((np.asarray(y) + phase[0]) // 2 % 2 + (np.asarray(x) + phase[1]) // 2 % 2)),
    ("temporal_loss", lambda dF_dt, delta_L, durations: torch.mean((dF_dt * durations - delta_L) ** 2, dim=0)),
    ("tikhonov_autograd", lambda dF_dx, dF_dy: (torch.cat([dF_dx, dF_dy]) ** 2).sum() / dF_dx.numel()),
    ("anchor_first_offset", lambda first_frame, L_t0, eps=1 / 255: (
        np.log((first_frame.astype(float) + eps * 255) / 255) - L_t0 if first_frame.dtype == np.uint8
        else np.log(np.clip(first_frame, 0, 1) + eps) - L_t0)),
    ("split_index", lambda index, sensor_size: (
        index // (sensor_size[0] * sensor_size[1]),
        torch.div(index % (sensor_size[0] * sensor_size[1]), sensor_size[1], rounding_mode="floor"),
        torch.remainder(index, sensor_size[1]))),
    ("hot_pixel_mask", lambda x, y, sensor_size, factor=10.0: (lambda c: c > factor * np.percentile(c[c > 0], 50))(
        np.bincount(np.asarray(y) * sensor_size[1] + np.asarray(x), minlength=sensor_size[0] * sensor_size[1])
        .reshape(sensor_size))),
    ("crossfade_weights", lambda windows, times: R("crossfade_weights")(np.array(windows) - windows[0, 0],
                                                                        np.asarray(times) - windows[0, 0])),
] + [(name, exercises.reference(name)) for name in exercises.names()]


def _id(rows):
    return [f"{r[0]}-{k}-{getattr(r[1], '__name__', 'fn').strip('<>_')}" for k, r in enumerate(rows)]


@pytest.mark.parametrize("name, wrong, words", HOLES, ids=_id(HOLES))
def test_hole_now_fails_and_names_the_mistake(name, wrong, words):
    ok, report = _report(name, wrong)
    assert not ok, report
    assert words in report, report
    assert "Traceback" not in report


@pytest.mark.parametrize("name, wrong, words", NAMED, ids=_id(NAMED))
def test_wrong_solution_fails_and_names_the_mistake(name, wrong, words):
    ok, report = _report(name, wrong)
    assert not ok, report
    assert words in report, report
    assert "Traceback" not in report


@pytest.mark.parametrize("name, wrong, words", GUARDS, ids=_id(GUARDS))
def test_guard_wrong_solution_already_failed_clearly(name, wrong, words):
    ok, report = _report(name, wrong)
    assert not ok and words in report, report


@pytest.mark.parametrize("name, fn", CORRECT, ids=_id(CORRECT))
def test_guard_correct_alternatives_and_references_pass(name, fn):
    ok, report = _report(name, fn)
    assert ok, report


def test_hot_pixel_mistakes_are_not_blamed_on_the_factor_argument():
    """Before this round a median over the distinct counts (or over the pixels that fired twice) was reported as
    "use the `factor` argument, not a fixed 10": the cases could not tell them apart."""
    for wrong in (hot_unique_median, hot_exclude_single, hot_ratio_int):
        ok, report = _report("hot_pixel_mask", wrong)
        assert not ok and "use the `factor` argument" not in report, report


def test_a_mean_polarity_is_not_called_fancy_indexing():
    """Averaged polarities have one magnitude per entry, which the generic scatter-add note used to take for
    `a[idx] += v`."""
    ok, report = _report("events_to_frames_fixed", frames_mean_polarity)
    assert not ok and "fancy indexing" not in report, report


def test_every_hint_fires_on_its_own_wrong_version():
    """Each registered hint (the new ones too) is reached by the mistake it names: no earlier hint shadows it."""
    for name in exercises.names():
        for message, wrong in exercises.get(name).hints.items():
            ok, report = _report(name, wrong)
            assert not ok and message in report, (name, message, report)


def test_the_cases_hold_the_edge_cases_the_holes_need():
    integ = [kw for _, kw in exercises.get("integrate_events_1d").cases()]
    assert any(len(kw["t_events"]) == 0 for kw in integ)                                    # no events
    assert any(np.cumsum(kw["p_events"], dtype=np.int64).max(initial=0) > 127 for kw in integ)  # past int8
    assert any(kw["t_events"].size and kw["t_events"][0] > 100 for kw in integ)             # absolute clock
    hot = [kw for _, kw in exercises.get("hot_pixel_mask").cases()]
    counts = [np.bincount(kw["y"] * kw["sensor_size"][1] + kw["x"]) for kw in hot]
    assert any((c > 0).sum() % 2 == 0 and len(set(np.sort(c[c > 0])[[(c > 0).sum() // 2 - 1, (c > 0).sum() // 2]])) == 2
               for c in counts)                                                              # two middle values differ
    assert any(kw["windows"][0, 0] != 0 for _, kw in exercises.get("crossfade_weights").cases())


def test_the_counts_the_notebooks_quote_are_unchanged():
    """Each notebook says "✓ NAME: matches the reference on N inputs"; cases were changed, never added."""
    quoted = quoted_counts()
    for name in ("integrate_events_1d", "hot_pixel_mask", "crossfade_weights"):
        assert len(exercises.get(name).cases()) == quoted[name], name


def test_the_wrong_versions_differ_from_the_reference():
    """Every wrong solution above is wrong on some case of its exercise (none passes by the check being lenient)."""
    for name, wrong, _ in HOLES + NAMED + GUARDS:
        ex = exercises.get(name)
        differs = False
        for args, kwargs in ex.cases():
            after = []
            try:
                got = run(wrong, args, kwargs, ex.observe, inputs_after=after)
            except Exception:
                differs = True
                continue
            expected = run(ex.reference, args, kwargs, ex.observe)
            differs |= compare_outputs(got, expected, ex.rtol, ex.atol) is not None
            differs |= bool(changed_inputs((args, kwargs), after[0])) if ex.observe is None else False
        assert differs, (name, wrong.__name__)
