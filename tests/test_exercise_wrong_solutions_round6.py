"""Exercise checks, round 6: about a hundred more wrong solutions written the way learners err, across all 32 exercises.

Mistake classes: a list, tuple or nested dict for an array; a column (N, 1) for (N,); a transposed (W, H) result;
the right values in an integer (or float for int) dtype; a float for a tensor, a detached tensor, a tensor for an
array; a shape taken from the check's first input (np.zeros(3), `H, W = 4, 4`) or the first input's data kept in a
notebook global; a mutable default argument (`idx=[]`, `_cache={}`, `state={}`) and a notebook dict that carries
state between calls; an image sized from the events (y.max() + 1) instead of sensor_size / raw_size; a mean along
one axis (per column, per frame, the last axis) for one over everything; a rescaling (per-frame max, min-max,
standardising) where only a shift or nothing is allowed; seconds read as milliseconds or microseconds (a factor
1e-3 / 1e-6, dt * 1e-6, alpha / 2 pi); the sign of the temporal derivative, of the regulariser, an inverted mask;
a sum of per-image losses for a mean, an RMS for a mean |d|, a root in a least-squares slope; np.diff's prepend
kept, a running sum without its leading 0, cuts appended after the edges; exp for log (and log for exp); a clip
before scaling; nearest bin centres and half-way levels (off by half a bin); a sorted[K // 2] median; two optimiser
steps; solutions that print and return None, raise (AssertionError, ZeroDivisionError, TypeError, LinAlgError) or
give NaN; and correct alternatives (torch.func.jvp, mse_loss, np.percentile, pinv and minimum-norm lstsq, an
augmented least-squares head, loops, bincount and reshape-sum frames, times in microseconds throughout).

Holes (these passed a check before this round; each now fails and its report names the mistake):
- events_to_frames_fixed, highpass_per_event, hot_pixel_mask: an image sized from the largest event coordinates
  (every case's events reached the last row and column); one case each now has a sensor whose last row and column
  never fire (a 6 x 8 sensor for the 300 random events drawn on 5 x 7, a 3 x 4 high-pass sensor for 2 x 3
  events, the 6 x 4 even-median hot-pixel case), and a generic hint names it;
- highpass_per_event: a notebook dict of per-sensor states that is never reset (every case had its own sensor
  and C); the check now runs its last input a second time and fails a function that answers differently.

Hints added: generic ones (in checking/) for state kept between calls (a mutable default argument that holds
data, a second call that differs), a notebook variable or fixed value used in place of an argument (the result is
the reference's with input #1's argument, confirmed on every other failing input), a shape with input #1's sizes,
an image smaller than the sensor, two outputs swapped, an inverted mask, np.exp / np.log of the expected values, a
scalar off by the same factor on every input, a power of 1000 (a unit conversion); shape notes for an extra or
missing axis of length 1, one number expected but several returned, one entry too many along the first axis; a
dtype note for floats made whole numbers. Registered hints for about thirty named mistakes (see NAMED). A dict
argument is described by its size and first keys, not its whole repr, in the report's headline.

Guards: wrong solutions that already failed with a clear message, and correct alternatives that must pass.
"""
import math
import warnings

import numpy as np
import pytest
import torch

from evinr_lite.core.events import Events
from evinr_lite.method.losses import temporal_loss_derivative, tikhonov
from evinr_lite.teaching import events2d, exercises
from evinr_lite.teaching.checking.learner_calls import changed_inputs, run
from evinr_lite.teaching.checking.outputs import compare_outputs
from evinr_lite.teaching.poisson_exercises import _differences, _path_integral
from exercise_reports import quoted_counts, report as _report


def R(n): return exercises.reference(n)

# ---- shared: the notebooks' first inputs, as a learner's globals would hold them
def _first(name):
    return exercises.get(name).cases()[0][1]

# ---- integrate_events_1d
def integ_column(t_events, p_events, C, t_query):
    return R("integrate_events_1d")(t_events, p_events, C, t_query)[:, None]
def integ_int(t_events, p_events, C, t_query):
    return R("integrate_events_1d")(t_events, p_events, C, t_query).astype(np.int64)
_NB_INTEG = _first("integrate_events_1d")
def integ_globals(t_events, p_events, C, t_query):
    t, p = _NB_INTEG["t_events"], _NB_INTEG["p_events"]           # the notebook's t, p, not the arguments
    return C * np.concatenate([[0.0], np.cumsum(p, dtype=float)])[np.searchsorted(t, t_query, side="right")]
def integ_exp(t_events, p_events, C, t_query):
    return np.exp(R("integrate_events_1d")(t_events, p_events, C, t_query))
def integ_cached(t_events, p_events, C, t_query, _cache={}):
    if "csum" not in _cache:
        _cache["csum"] = np.concatenate([[0.0], np.cumsum(np.asarray(p_events, float))])
    n = np.minimum(np.searchsorted(t_events, t_query, side="right"), len(_cache["csum"]) - 1)
    return C * _cache["csum"][n]
def integ_print(t_events, p_events, C, t_query):
    print(C * np.concatenate([[0.0], np.cumsum(np.asarray(p_events, float))])[np.searchsorted(t_events, t_query, side="right")])
def integ_assert(t_events, p_events, C, t_query):
    assert len(t_events) > 0, "no events"
    return R("integrate_events_1d")(t_events, p_events, C, t_query)
def integ_loop_quadratic(t_events, p_events, C, t_query):
    return np.array([C * float(np.sum(np.asarray(p_events, float)[np.asarray(t_events) <= q])) for q in t_query])

# ---- event_rate_derivative
def rate_hardcoded_B(t_events, p_events, C, boundaries):
    out = np.zeros(3)                                            # the first input's 3 windows
    b = np.asarray(boundaries, float)
    r = R("event_rate_derivative")(t_events, p_events, C, b)
    out[:min(3, len(r))] = r[:3]
    return out
def rate_us(t_events, p_events, C, boundaries):
    return R("event_rate_derivative")(t_events, p_events, C, boundaries) / 1e6       # "per microsecond"
def rate_column(t_events, p_events, C, boundaries):
    return R("event_rate_derivative")(t_events, p_events, C, boundaries).reshape(-1, 1)
def rate_cumsum_missing_zero(t_events, p_events, C, boundaries):
    b = np.asarray(boundaries, float); t = np.asarray(t_events, float)
    csum = np.cumsum(np.asarray(p_events, float))                 # no leading 0: csum[-1] is the total
    n = np.searchsorted(t, b, side="right") - 1; n[0] = np.searchsorted(t, b[0], side="left") - 1
    return C * np.diff(csum[n]) / np.diff(b)
def rate_cumsum_guarded(t_events, p_events, C, boundaries):
    b = np.asarray(boundaries, float); t = np.asarray(t_events, float)
    csum = np.cumsum(np.asarray(p_events, float))                 # no leading 0
    n = np.searchsorted(t, b, side="right") - 1; n[0] = np.searchsorted(t, b[0], side="left") - 1
    at = np.where(n >= 0, csum[np.maximum(n, 0)], 0.0)
    return C * np.diff(at) / np.diff(b)
def rate_centres_half_bin(t_events, p_events, C, boundaries):
    b = np.asarray(boundaries, float); t = np.asarray(t_events, float)
    c = 0.5 * (b[1:] + b[:-1])                                     # nearest bin centre
    keep = (t >= b[0]) & (t <= b[-1])
    i = np.argmin(np.abs(t[keep, None] - c[None, :]), axis=1)
    return C * np.bincount(i, weights=np.asarray(p_events, float)[keep], minlength=len(c)) / np.diff(b)

# ---- temporal_loss
def tl_sign(dF_dt, delta_L, durations): return torch.mean((delta_L + dF_dt * durations) ** 2)
def tl_keepdim(dF_dt, delta_L, durations): return torch.mean((delta_L - dF_dt * durations) ** 2, dim=0, keepdim=True)
def tl_item(dF_dt, delta_L, durations): return torch.mean((delta_L - dF_dt * durations) ** 2).item()
def tl_per_window(dF_dt, delta_L, durations): return (delta_L - dF_dt * durations) ** 2
def tl_mse(dF_dt, delta_L, durations): return torch.nn.functional.mse_loss(dF_dt * durations, delta_L)
def tl_sum_over_len(dF_dt, delta_L, durations): return ((delta_L - dF_dt * durations) ** 2).sum() / len(delta_L)

# ---- esim_interval
def esim_p_float(L_a, L_b, t_a, t_b, ref, C):
    times, p, r = R("esim_interval")(L_a, L_b, t_a, t_b, ref, C)
    return times, p.astype(np.float64), r
def esim_slope_first(L_a, L_b, t_a, t_b, ref, C):
    slope = (t_b - t_a) / (L_b - L_a)                            # before knowing whether any level is crossed
    d = L_b - ref; p = 1 if d > 0 else -1; n = int(np.floor(abs(d) / C))
    levels = ref + p * C * np.arange(1, n + 1)
    return t_a + (levels - L_a) * slope, np.full(n, p, np.int8), float(ref + p * n * C)
def esim_half_level(L_a, L_b, t_a, t_b, ref, C):
    d = L_b - ref; p = 1 if d > 0 else -1; n = int(np.floor(abs(d) / C))
    levels = ref + p * C * (np.arange(1, n + 1) - 0.5)           # half-way between levels
    times = t_a + (levels - L_a) / (L_b - L_a) * (t_b - t_a) if n else np.zeros(0)
    return np.asarray(times, float), np.full(n, p, np.int8), float(ref + p * n * C)
def esim_while_loop(L_a, L_b, t_a, t_b, ref, C):
    times, pol, level = [], [], ref
    p = 1 if L_b > ref else -1
    while p * (L_b - (level + p * C)) >= -1e-12:
        level += p * C
        times.append(t_a + (level - L_a) / (L_b - L_a) * (t_b - t_a)); pol.append(p)
    return np.array(times, dtype=np.float64), np.array(pol, dtype=np.int8), float(level)
def esim_ref_array(L_a, L_b, t_a, t_b, ref, C):
    times, p, r = R("esim_interval")(L_a, L_b, t_a, t_b, ref, C)
    return times, p, np.array([r])

# ---- events_to_frames_fixed
def frames_sensor_from_data(events, boundaries, C):
    b = np.asarray(boundaries, float)
    H, W = int(events.y.max()) + 1, int(events.x.max()) + 1     # the size read off the events
    i = np.searchsorted(b, events.t, side="left") - 1; i[events.t == b[0]] = 0
    keep = (i >= 0) & (i < b.size - 1)
    f = np.zeros((b.size - 1, H, W)); np.add.at(f, (i[keep], events.y[keep], events.x[keep]), events.p[keep])
    return (C * f).astype(np.float32)
def frames_per_frame_norm(events, boundaries, C):
    f = R("events_to_frames_fixed")(events, boundaries, C)
    m = np.abs(f).max(axis=(1, 2), keepdims=True)
    return (f / np.where(m > 0, m, 1)).astype(np.float32)
def frames_int(events, boundaries, C):
    return R("events_to_frames_fixed")(events, boundaries, C).astype(np.int64)
_NB_FRAMES = _first("events_to_frames_fixed")
def frames_global_size(events, boundaries, C):
    H, W = _NB_FRAMES["events"].sensor_size                      # the notebook's sensor
    b = np.asarray(boundaries, float)
    i = np.searchsorted(b, events.t, side="left") - 1; i[events.t == b[0]] = 0
    keep = (i >= 0) & (i < b.size - 1)
    f = np.zeros((b.size - 1, H, W)); np.add.at(f, (i[keep], events.y[keep], events.x[keep]), events.p[keep])
    return (C * f).astype(np.float32)
def frames_float64(events, boundaries, C):
    return R("events_to_frames_fixed")(events, boundaries, C).astype(np.float64)
def frames_bincount(events, boundaries, C):
    b = np.asarray(boundaries, float); H, W = events.sensor_size; B = b.size - 1
    i = np.searchsorted(b, events.t, side="left") - 1; i[events.t == b[0]] = 0
    keep = (i >= 0) & (i < B)
    flat = (i[keep] * H + events.y[keep]) * W + events.x[keep]
    return (C * np.bincount(flat, weights=events.p[keep], minlength=B * H * W)).reshape(B, H, W).astype(np.float32)

# ---- interval_imbalance
def imb_nan_by_mean_of_empty(events):
    H, W = events.sensor_size
    pix = events.y.astype(np.int64) * W + events.x
    order = np.argsort(pix, kind="stable")
    pix, t, p = pix[order], np.asarray(events.t, float)[order], events.p[order]
    pair = (pix[1:] == pix[:-1]) & (p[1:] == p[:-1])
    ld = np.log(np.maximum(np.diff(t), events2d.MIN_INTERVAL)); on = p[1:] > 0
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return float(np.tanh((np.mean(ld[pair & on]) - np.mean(ld[pair & ~on])) / 2))
def imb_per_pixel_means(events):
    H, W = events.sensor_size
    pix = events.y.astype(np.int64) * W + events.x
    order = np.argsort(pix, kind="stable")
    pix, t, p = pix[order], np.asarray(events.t, float)[order], events.p[order]
    pair = (pix[1:] == pix[:-1]) & (p[1:] == p[:-1])
    ld = np.log(np.maximum(np.diff(t), events2d.MIN_INTERVAL)); on = p[1:] > 0; px = pix[1:]
    def m(sel):
        vals = [ld[sel & (px == k)].mean() for k in np.unique(px[sel])]
        return np.mean(vals) if vals else np.nan
    a, b = m(pair & on), m(pair & ~on)
    return float("nan") if np.isnan(a) or np.isnan(b) else float(np.tanh((a - b) / 2))
def imb_array(events): return np.array(R("interval_imbalance")(events))
# ---- split_index
_NB_SPLIT = _first("split_index")
def split_global_size(index, sensor_size):
    H, W = _NB_SPLIT["sensor_size"]
    return index // (H * W), (index // W) % H, index % W
def split_true_div(index, sensor_size):
    H, W = sensor_size
    return index / (H * W), (index / W) % H, index % W
def split_list(index, sensor_size):
    H, W = sensor_size
    return [index // (H * W), (index // W) % H, index % W]
def split_divmod(index, sensor_size):
    H, W = sensor_size
    rest, x = divmod(index, W); b, y = divmod(rest, H)
    return b, y, x

# ---- tikhonov_autograd
def tik_lam(dF_dx, dF_dy, lam=0.05): return lam * torch.mean(dF_dx ** 2 + dF_dy ** 2)
def tik_double(dF_dx, dF_dy): return torch.mean(dF_dx.double() ** 2 + dF_dy.double() ** 2)
def tik_pow(dF_dx, dF_dy): return dF_dx.pow(2).mean() + dF_dy.pow(2).mean()
def tik_vector_norm(dF_dx, dF_dy):
    return torch.linalg.vector_norm(torch.cat([dF_dx, dF_dy])) ** 2 / dF_dx.numel()
def tik_float(dF_dx, dF_dy): return float(torch.mean(dF_dx ** 2 + dF_dy ** 2))

# ---- sine_layer_derivative
def sine_swapped_outputs(h, dh_dt, weight, bias, omega):
    z = omega * (h @ weight + bias)
    return torch.cos(z) * omega * (dh_dt @ weight), torch.sin(z)
def sine_minus_cos(h, dh_dt, weight, bias, omega):
    z = omega * (h @ weight + bias)
    return torch.sin(z), -torch.cos(z) * omega * (dh_dt @ weight)
def sine_detached(h, dh_dt, weight, bias, omega):
    z = omega * (h @ weight + bias)
    return torch.sin(z), (torch.cos(z) * omega * (dh_dt @ weight)).detach()
def sine_addmm(h, dh_dt, weight, bias, omega):
    z = omega * torch.addmm(bias, h, weight)
    return torch.sin(z), torch.cos(z) * omega * torch.matmul(dh_dt, weight)
def sine_jvp(h, dh_dt, weight, bias, omega):
    out, tangent = torch.func.jvp(lambda u: torch.sin(omega * (u @ weight + bias)), (h,), (dh_dt,))
    return out, tangent

# ---- frame_train_step
def _step6(model, optimizer, event_frames, centers, durations, lam, mode):
    F, dF = model.forward_with_derivative(centers)
    temporal = temporal_loss_derivative(dF, event_frames, durations)
    reg = tikhonov(F)
    loss = temporal - lam * reg if mode == "minus" else temporal + lam * reg
    optimizer.zero_grad(); loss.backward(); optimizer.step()
    if mode == "twice": optimizer.step()
    if mode == "floats": return loss.item(), temporal.item(), reg.item()
    return loss.detach(), temporal.detach(), reg.detach()
def step_minus_reg(model, optimizer, event_frames, centers, durations, lam): return _step6(model, optimizer, event_frames, centers, durations, lam, "minus")
def step_twice(model, optimizer, event_frames, centers, durations, lam): return _step6(model, optimizer, event_frames, centers, durations, lam, "twice")
def step_floats(model, optimizer, event_frames, centers, durations, lam): return _step6(model, optimizer, event_frames, centers, durations, lam, "floats")
def step_no_return(model, optimizer, event_frames, centers, durations, lam):
    _step6(model, optimizer, event_frames, centers, durations, lam, "plain")

# ---- temporal_loss_boundary
def tlb_per_bin(F_boundaries, event_frames):
    return torch.mean((event_frames - (F_boundaries[1:] - F_boundaries[:-1])) ** 2, dim=(1, 2))
def tlb_diff(F_boundaries, event_frames):
    return torch.mean((event_frames - torch.diff(F_boundaries, dim=0)) ** 2)
def tlb_sign(F_boundaries, event_frames):
    return torch.mean((event_frames + (F_boundaries[1:] - F_boundaries[:-1])) ** 2)
def tlb_item(F_boundaries, event_frames):
    return torch.tensor(torch.mean((event_frames - (F_boundaries[1:] - F_boundaries[:-1])) ** 2).item())

# ---- total_variation
def tv_prepend(F):
    return (torch.diff(F, dim=-1, prepend=F[..., :1])).abs().mean() + torch.diff(F, dim=-2, prepend=F[..., :1, :]).abs().mean()
def tv_per_image(F):
    dx = (F[..., :, 1:] - F[..., :, :-1]).abs().mean(dim=(-2, -1)); dy = (F[..., 1:, :] - F[..., :-1, :]).abs().mean(dim=(-2, -1))
    return (dx + dy).mean()
def tv_sqrt_square(F):
    return torch.sqrt((F[..., :, 1:] - F[..., :, :-1]) ** 2).mean() + torch.sqrt((F[..., 1:, :] - F[..., :-1, :]) ** 2).mean()
def tv_per_image_sum(F):
    dx = (F[..., :, 1:] - F[..., :, :-1]).abs().mean(dim=(-2, -1)); dy = (F[..., 1:, :] - F[..., :-1, :]).abs().mean(dim=(-2, -1))
    return (dx + dy).reshape(-1).sum()
def tv_square_root_of_sum(F):
    dx = F[..., :, 1:] - F[..., :, :-1]; dy = F[..., 1:, :] - F[..., :-1, :]
    return torch.sqrt((dx ** 2).mean()) + torch.sqrt((dy ** 2).mean())

# ---- reinhard_tonemap
def tm_normalised(L, gamma):
    g = R("reinhard_tonemap")(L, gamma); return (g - g.min()) / (g.max() - g.min())
def tm_log(L, gamma):
    with np.errstate(all="ignore"):
        I = np.log(np.asarray(L, float)); return (I / (I + 1)) ** gamma
def tm_torch(L, gamma):
    I = torch.exp(torch.as_tensor(L)); return (I / (I + 1)) ** gamma
def tm_clipped(L, gamma):
    I = np.exp(np.asarray(L, float)); return np.clip(I / (I + 1), 0, 1) ** gamma

# ---- anchor
def anchor_per_frame(L, gamma, display_mean):
    L = np.asarray(L, float); s = display_mean ** (1 / gamma)
    m = L.mean(axis=(-2, -1), keepdims=True) if L.ndim >= 2 else L.mean()
    return L + (np.log(s / (1 - s)) - m)
def anchor_standardised(L, gamma, display_mean):
    L = np.asarray(L, float); s = display_mean ** (1 / gamma); sd = L.std()
    return (L - L.mean()) / (sd if sd > 0 else 1.0) + np.log(s / (1 - s))
def anchor_last_axis(L, gamma, display_mean):
    L = np.asarray(L, float); s = display_mean ** (1 / gamma)
    return L + (np.log(s / (1 - s)) - L.mean(axis=-1, keepdims=True))
def anchor_in_place(L, gamma, display_mean):
    s = display_mean ** (1 / gamma)
    L -= L.mean(); L += np.log(s / (1 - s)); return L

# ---- offset_gradients
def og_prepend(frames):
    F = np.asarray(frames, float)
    return -np.median(np.diff(F, axis=2, prepend=F[:, :, :1]), axis=0), -np.median(np.diff(F, axis=1, prepend=F[:, :1]), axis=0)
def og_sorted_middle(frames):
    F = np.asarray(frames, float); K = len(F)
    return -np.sort(np.diff(F, axis=2), axis=0)[K // 2], -np.sort(np.diff(F, axis=1), axis=0)[K // 2]
def og_swapped_outputs(frames):
    gx, gy = R("offset_gradients")(frames); return gy, gx
def og_list(frames): return list(R("offset_gradients")(frames))
def og_percentile(frames):
    F = np.asarray(frames, float)
    return -np.percentile(np.diff(F, axis=2), 50, axis=0), -np.percentile(np.diff(F, axis=1), 50, axis=0)

# ---- integrate_gradients
def ig_row_first_path(gx, gy):
    gx, gy = np.asarray(gx, float), np.asarray(gy, float); H, W = gx.shape[0], gy.shape[1]
    g = np.zeros((H, W)); g[0, 1:] = np.cumsum(gx[0]); g[1:, :] = g[:1, :] + np.cumsum(gy, axis=0)
    return g - g.mean()
def ig_lstsq_min_norm(gx, gy):
    gx, gy = np.asarray(gx, float), np.asarray(gy, float); H, W = gx.shape[0], gy.shape[1]
    D = _differences(H, W).toarray()
    return np.linalg.lstsq(D, np.concatenate([gx.ravel(), gy.ravel()]), rcond=None)[0].reshape(H, W)
def ig_pinv(gx, gy):
    gx, gy = np.asarray(gx, float), np.asarray(gy, float); H, W = gx.shape[0], gy.shape[1]
    g = np.linalg.pinv(_differences(H, W).toarray()) @ np.concatenate([gx.ravel(), gy.ravel()])
    return g.reshape(H, W) - g.mean()
def ig_hardcoded(gx, gy):
    H, W = 4, 5                                                      # the first input's image
    D = _differences(H, W).toarray()
    g = np.linalg.lstsq(D, np.concatenate([np.ravel(gx), np.ravel(gy)]), rcond=None)[0]
    return g.reshape(H, W) - g.mean()
def ig_transposed(gx, gy):
    return R("integrate_gradients")(gx, gy).T
def ig_float32(gx, gy):
    return R("integrate_gradients")(gx, gy).astype(np.float32)
# ---- bisect_equal_count
def bis_concatenated(t_events, boundaries):
    out = R("bisect_equal_count")(t_events, boundaries)
    return np.concatenate([out[0::2], out[1::2]])
def bis_sorted_concat(t_events, boundaries):
    out = R("bisect_equal_count")(t_events, boundaries)
    return np.sort(np.concatenate([out[0::2], out[1::2]]))
def bis_list(t_events, boundaries): return list(R("bisect_equal_count")(t_events, boundaries))
# ---- crossfade_weights
_NB_CF = _first("crossfade_weights")
def cf_global_windows(windows, times): return R("crossfade_weights")(_NB_CF["windows"], times)
def cf_transposed(windows, times): return R("crossfade_weights")(windows, times).T
def cf_loop(windows, times):
    windows = np.asarray(windows, float); t = np.asarray(times, float); N = len(windows)
    w = np.zeros((N, len(t)))
    for q, tq in enumerate(t):
        for k in range(N):
            lo, hi = windows[k]
            up = 1.0 if k == 0 else min(max((tq - lo) / (windows[k - 1, 1] - lo), 0.0), 1.0)
            down = 1.0 if k == N - 1 else min(max((hi - tq) / (hi - windows[k + 1, 0]), 0.0), 1.0)
            w[k, q] = min(up, down)
        w[:, q] /= w[:, q].sum()
    return w
def cf_overlap_sign(windows, times):
    windows, t = np.asarray(windows, float), np.asarray(times, float)
    if len(windows) == 1: return np.ones((1, len(t)))
    ov = windows[1, 0] - windows[0, 1]                              # start minus end: negative
    fi = np.clip((t - windows[:, :1]) / abs(ov), 0, 1); fo = np.clip((windows[:, 1:] - t) / ov, 0, 1)
    fi[0] = 1; fo[-1] = 1
    w = np.minimum(fi, fo)
    with np.errstate(all="ignore"): return w / w.sum(axis=0, keepdims=True)

# ---- chain_offsets
def chain_sum_samples(prev, nxt):
    steps = (np.asarray(prev, float) - np.asarray(nxt, float)).sum(axis=1)
    return np.concatenate([np.zeros((1,) + np.shape(prev)[2:]), np.cumsum(steps, axis=0)])
def chain_loop(prev, nxt):
    prev, nxt = np.asarray(prev, float), np.asarray(nxt, float)
    out = [np.zeros(prev.shape[2:])]
    for k in range(len(prev)):
        out.append(out[-1] + (prev[k] - nxt[k]).mean(axis=0))
    return np.array(out)
def chain_float32(prev, nxt):
    return R("chain_offsets")(np.float32(prev), np.float32(nxt)).astype(np.float32)
def chain_list(prev, nxt): return list(R("chain_offsets")(prev, nxt))

# ---- time_fps_products
_NB_TABLE = _first("time_fps_products")["table"]
def tfp_global(table): return {k: r["time_s"] * r["fps"] for k, r in _NB_TABLE.items()}
def tfp_nested(table): return {k: {"frames": r["time_s"] * r["fps"]} for k, r in table.items()}
def tfp_total(table): return sum(r["time_s"] * r["fps"] for r in table.values())
def tfp_numpy(table): return {k: np.float64(r["time_s"]) * np.float64(r["fps"]) for k, r in table.items()}
def tfp_int(table): return {k: int(r["time_s"] * r["fps"]) for k, r in table.items()}

# ---- pareto_front
def pf_args_swapped(cost, quality): return R("pareto_front")(quality, cost)
def pf_best_only(cost, quality): q = np.asarray(quality, float); return q == q.max()
def pf_loop(cost, quality):
    c, q = np.asarray(cost, float), np.asarray(quality, float); K = len(c)
    keep = np.ones(K, bool)
    for i in range(K):
        for j in range(K):
            if c[j] <= c[i] and q[j] >= q[i] and (c[j] < c[i] or q[j] > q[i]): keep[i] = False
    return keep
def pf_list(cost, quality): return [bool(v) for v in R("pareto_front")(cost, quality)]
def pf_int(cost, quality): return R("pareto_front")(cost, quality).astype(int)

# ---- highpass_per_event
def hp_sensor_from_data(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    H, W = int(np.max(y)) + 1, int(np.max(x)) + 1
    return R("highpass_per_event")(t, x, y, p, (H, W), C, alpha, t_end, t_start)
def hp_state_default(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0, state={}):
    H, W = sensor_size
    s = state.setdefault("s", np.zeros((H, W))); t_last = np.full((H, W), float(t_start))
    if s.shape != (H, W): s = state["s"] = np.zeros((H, W))
    for ti, xi, yi, pi in zip(t, x, y, p):
        s[yi, xi] = np.exp(-alpha * (ti - t_last[yi, xi])) * s[yi, xi] + C * pi; t_last[yi, xi] = ti
    return s * np.exp(-alpha * (t_end - t_last))
_HP_STATE = {}                                                       # a notebook-level dict of per-sensor states
def hp_global_state(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    H, W = sensor_size
    s = _HP_STATE.setdefault((H, W, C), np.zeros((H, W))); t_last = np.full((H, W), float(t_start))
    for ti, xi, yi, pi in zip(t, x, y, p):
        s[yi, xi] = np.exp(-alpha * (ti - t_last[yi, xi])) * s[yi, xi] + C * pi; t_last[yi, xi] = ti
    return s * np.exp(-alpha * (t_end - t_last))
def hp_time_us(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    return R("highpass_per_event")(np.asarray(t) * 1e6, x, y, p, sensor_size, C, alpha * 1e-6, t_end * 1e6, t_start * 1e6)
def hp_alpha_hz(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    return R("highpass_per_event")(t, x, y, p, sensor_size, C, alpha / (2 * math.pi), t_end, t_start)
def hp_list_state(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    return R("highpass_per_event")(t, x, y, p, sensor_size, C, alpha, t_end, t_start).tolist()

# ---- render_event_counts
def rc_prepend(L_boundaries, C):
    L = np.asarray(L_boundaries, float); ref = L[0].copy(); out = []
    for k in range(L.shape[0]):
        n = np.trunc((L[k] - ref) / C); ref = ref + n * C; out.append(n)
    return np.array(out, dtype=np.int64)                         # B + 1 entries: the first one is 0
def rc_float(L_boundaries, C): return R("render_event_counts")(L_boundaries, C).astype(float)
def rc_loop_pixels(L_boundaries, C):
    L = np.asarray(L_boundaries, float); flat = L.reshape(L.shape[0], -1)
    out = np.zeros((L.shape[0] - 1, flat.shape[1]), np.int64)
    for j in range(flat.shape[1]):
        ref = flat[0, j]
        for k in range(1, L.shape[0]):
            n = int((flat[k, j] - ref) / C); out[k - 1, j] = n; ref += n * C
    return out.reshape((L.shape[0] - 1,) + L.shape[1:])
# ---- event_rate
def er_right_edges(t, bin_s):
    c, r = R("event_rate")(t, bin_s); return c + bin_s / 2, r
def er_us(t, bin_s):
    c, r = R("event_rate")(np.asarray(t) * 1e6, bin_s * 1e6); return c, r     # centres in microseconds
def er_rate_per_ms(t, bin_s):
    c, r = R("event_rate")(t, bin_s); return c, r / 1000
def er_list(t, bin_s):
    c, r = R("event_rate")(t, bin_s); return c.tolist(), r.tolist()
def er_swapped(t, bin_s):
    c, r = R("event_rate")(t, bin_s); return r, c
_NB_RATE = _first("event_rate")
# ---- estimate_contrast_threshold
def ct_sqrt(log_changes, net_counts):
    d, n = np.asarray(log_changes, float), np.asarray(net_counts, float); return float(np.sqrt(np.sum(d * d) / np.sum(n * n)))
def ct_lstsq_array(log_changes, net_counts):
    return np.linalg.lstsq(np.asarray(net_counts, float)[:, None], np.asarray(log_changes, float), rcond=None)[0]
def ct_lstsq(log_changes, net_counts):
    return float(np.linalg.lstsq(np.asarray(net_counts, float)[:, None], np.asarray(log_changes, float), rcond=None)[0][0])
def ct_tuple(log_changes, net_counts):
    d, n = np.asarray(log_changes, float), np.asarray(net_counts, float); return float(d @ n / (n @ n)), float(np.sum((d - d @ n / (n @ n) * n) ** 2))
def ct_means(log_changes, net_counts):
    d, n = np.asarray(log_changes, float), np.asarray(net_counts, float); return float(np.mean(d * n) / np.mean(n * n))
def ct_abs(log_changes, net_counts):
    d, n = np.abs(np.asarray(log_changes, float)), np.abs(np.asarray(net_counts, float)); return float(np.sum(d * n) / np.sum(n * n))

# ---- anchor_first_offset
def af_clip_uint8(first_frame, L_t0, eps=1 / 255):
    a = np.clip(np.asarray(first_frame), 0, 1)                   # clipped before scaling
    I = a / 255.0 if np.asarray(first_frame).dtype == np.uint8 else a
    return np.log(I + eps) - np.asarray(L_t0, float)
def af_transposed(first_frame, L_t0, eps=1 / 255):
    return R("anchor_first_offset")(first_frame.T, np.asarray(L_t0).T, eps)
def af_exp(first_frame, L_t0, eps=1 / 255):
    a = np.asarray(first_frame); I = a / 255.0 if a.dtype == np.uint8 else a
    return np.log(I + eps) - np.exp(np.asarray(L_t0, float))       # L(t0) taken for an intensity
def af_uint8_sum(first_frame, L_t0, eps=1 / 255):
    a = np.asarray(first_frame)
    I = (a + 1) / 255.0 if a.dtype == np.uint8 else a                # uint8 + 1 wraps 255 to 0
    return np.log(I + eps - 1 / 255.0) - L_t0

# ---- quad_bayer_channel
def qb_float(y, x, phase): return R("quad_bayer_channel")(y, x, phase) / 1
def qb_lookup(y, x, phase):
    tile = np.array([[0, 0, 1, 1], [0, 0, 1, 1], [1, 1, 2, 2], [1, 1, 2, 2]], dtype=np.int64)
    return tile[(np.asarray(y) + phase[0]) % 4, (np.asarray(x) + phase[1]) % 4]
_NB_QB = _first("quad_bayer_channel")
def qb_global_grid(y, x, phase):
    yy, xx = _NB_QB["y"], _NB_QB["x"]                            # the notebook's np.mgrid[0:6, 0:7]
    return ((((yy + phase[0]) % 4) // 2) + (((xx + phase[1]) % 4) // 2)).astype(np.int64)
def gf_mean(x, y, p, C, raw_size):
    H, W = raw_size; f = np.zeros((H // 4, W // 4)); n = np.zeros_like(f)
    np.add.at(f, (np.asarray(y) // 4, np.asarray(x) // 4), C * np.asarray(p, float) / 16)
    np.add.at(n, (np.asarray(y) // 4, np.asarray(x) // 4), 1)
    return f / np.maximum(n, 1)
def gf_bincount(x, y, p, C, raw_size):
    H, W = raw_size
    i = (np.asarray(y) // 4) * (W // 4) + np.asarray(x) // 4
    return (C / 16 * np.bincount(i, weights=np.asarray(p, float), minlength=(H // 4) * (W // 4))).reshape(H // 4, W // 4)
def gf_size_from_data(x, y, p, C, raw_size):
    f = np.zeros((int(np.max(y)) // 4 + 1, int(np.max(x)) // 4 + 1))
    np.add.at(f, (np.asarray(y) // 4, np.asarray(x) // 4), C * np.asarray(p, float) / 16)
    return f
def gf_int_frame(x, y, p, C, raw_size):
    H, W = raw_size; f = np.zeros((H // 4, W // 4), dtype=int)
    np.add.at(f, (np.asarray(y) // 4, np.asarray(x) // 4), C * np.asarray(p, float) / 16)
    return f
def gf_p_uint8(x, y, p, C, raw_size):
    H, W = raw_size; f = np.zeros((H // 4, W // 4))
    np.add.at(f, (np.asarray(y) // 4, np.asarray(x) // 4), C * np.asarray(p).astype(np.uint8) / 16)
    return f
def gf_reshape_sum(x, y, p, C, raw_size):
    H, W = raw_size; raw = np.zeros((H, W)); np.add.at(raw, (np.asarray(y), np.asarray(x)), np.asarray(p, float))
    return C / 16 * raw.reshape(H // 4, 4, W // 4, 4).sum(axis=(1, 3))

# ---- head_closed_form
def head_augmented(A, E, ridge):
    A, E = np.asarray(A, float), np.asarray(E, float); d = A.shape[1]
    return np.linalg.lstsq(np.vstack([A, np.sqrt(ridge) * np.eye(d)]), np.vstack([E, np.zeros((d, E.shape[1]))]), rcond=None)[0]
def head_transposed(A, E, ridge): return R("head_closed_form")(A, E, ridge).T
def head_per_pixel_loop(A, E, ridge):
    A, E = np.asarray(A, float), np.asarray(E, float); M = A.T @ A + ridge * np.eye(A.shape[1])
    return np.stack([np.linalg.solve(M, A.T @ E[:, j]) for j in range(E.shape[1])], axis=1)
def head_ridge_B(A, E, ridge):
    A = np.asarray(A, float); return np.linalg.solve(A.T @ A + ridge * np.eye(A.shape[1]) / A.shape[0], A.T @ E)
def head_E_first(A, E, ridge):
    A = np.asarray(A, float); return np.linalg.solve(A.T @ A + ridge * np.eye(A.shape[1]), E.T @ A)
def head_pinv(A, E, ridge):
    return np.linalg.pinv(np.asarray(A, float)) @ np.asarray(E, float)

# ---- hot_pixel_mask
def hot_sensor_from_data(x, y, sensor_size, factor=10.0):
    H, W = int(np.max(y)) + 1, int(np.max(x)) + 1
    return R("hot_pixel_mask")(x, y, (H, W), factor)
def hot_counts_returned(x, y, sensor_size, factor=10.0):
    H, W = sensor_size; c = np.bincount(np.asarray(y) * W + np.asarray(x), minlength=H * W).reshape(H, W)
    return np.where(c > factor * np.median(c[c > 0]), c, 0)
def hot_histogram2d(x, y, sensor_size, factor=10.0):
    H, W = sensor_size
    c, _, _ = np.histogram2d(y, x, bins=(np.arange(H + 1), np.arange(W + 1)))
    return c > factor * np.median(c[c > 0])
def hot_mean_rows(x, y, sensor_size, factor=10.0):
    H, W = sensor_size; c = np.bincount(np.asarray(y) * W + np.asarray(x), minlength=H * W).reshape(H, W)
    return c > factor * np.median(c, axis=0)
def hot_list_mask(x, y, sensor_size, factor=10.0): return R("hot_pixel_mask")(x, y, sensor_size, factor).tolist()

# ---- event_count_windows
def ecw_accumulate(n_events, max_events, idx=[]):
    w = math.ceil(n_events / max_events)
    for k in range(w + 1): idx.append(k * n_events // w)
    return np.array(idx, dtype=np.int64)
def ecw_float_step(n_events, max_events):
    w = math.ceil(n_events / max_events); return (np.arange(w + 1) * (n_events / w)).astype(np.int64)
def ecw_ceil_size(n_events, max_events):
    w = math.ceil(n_events / max_events); size = math.ceil(n_events / w)
    return np.minimum(np.arange(w + 1) * size, n_events).astype(np.int64)
def ecw_list_comp(n_events, max_events):
    w = -(-n_events // max_events); return np.array([k * n_events // w for k in range(w + 1)])
def ecw_tuple(n_events, max_events):
    w = math.ceil(n_events / max_events); return tuple(int(k * n_events // w) for k in range(w + 1))

# ---- background_activity_filter
def baf_dt_us(t, x, y, dt): return R("background_activity_filter")(t, x, y, dt * 1e-6)
def baf_dt_ms(t, x, y, dt): return R("background_activity_filter")(t, x, y, dt * 1e3)
def baf_loop(t, x, y, dt):
    n = len(t); keep = np.zeros(n, bool)
    for i in range(n):
        for j in range(n):
            if max(abs(int(x[j]) - int(x[i])), abs(int(y[j]) - int(y[i]))) == 1 and t[j] <= t[i] <= t[j] + dt:
                keep[i] = True; break
    return keep
def baf_indices(t, x, y, dt): return np.flatnonzero(R("background_activity_filter")(t, x, y, dt))
def baf_dropped_events(t, x, y, dt): return ~R("background_activity_filter")(t, x, y, dt)
def baf_sorted_window(t, x, y, dt):
    t = np.asarray(t, float); x, y = np.asarray(x, np.int64), np.asarray(y, np.int64); keep = np.zeros(len(t), bool)
    for i in range(len(t)):
        lo = np.searchsorted(t, t[i] - dt, side="left"); hi = np.searchsorted(t, t[i], side="right")
        j = np.arange(lo, hi)
        keep[i] = np.any(np.maximum(np.abs(x[j] - x[i]), np.abs(y[j] - y[i])) == 1)
    return keep


# ---- holes: each of these passed its check before this round ----------------------------------------------

HOLES = [
    ("events_to_frames_fixed", frames_sensor_from_data, "the image is smaller than the sensor"),
    ("highpass_per_event", hp_sensor_from_data, "the image is smaller than the sensor"),
    ("hot_pixel_mask", hot_sensor_from_data, "the image is smaller than the sensor"),
    ("highpass_per_event", hp_global_state, "keeps state between calls"),
]

# ---- wrong solutions whose report names the mistake (a registered hint, or a generic one) -------------------

NAMED = [
    ("integrate_events_1d", integ_column, "extra or missing axis of length 1"),
    ("integrate_events_1d", integ_int, "the values were made whole numbers"),
    ("integrate_events_1d", integ_globals, "input #1's `t_events`, `p_events`"),
    ("integrate_events_1d", integ_exp, "np.exp of the expected values"),
    ("integrate_events_1d", integ_cached, "the default value of `_cache`"),
    ("event_rate_derivative", rate_hardcoded_B, "has input #1's sizes"),
    ("event_rate_derivative", rate_us, "a unit conversion"),
    ("event_rate_derivative", rate_column, "extra or missing axis of length 1"),
    ("event_rate_derivative", rate_cumsum_missing_zero, "prepend a 0"),
    ("event_rate_derivative", rate_centres_half_bin, "not to the window whose centre is nearest"),
    ("temporal_loss", tl_sign, "not delta_L + dF_dt * durations"),
    ("temporal_loss", tl_per_window, "one number is expected, not 4"),
    ("esim_interval", esim_half_level, "not half-way between two levels"),
    ("events_to_frames_fixed", frames_per_frame_norm, "do not normalise the frames"),
    ("events_to_frames_fixed", frames_int, "the values were made whole numbers"),
    ("events_to_frames_fixed", frames_global_size, "has input #1's sizes"),
    ("interval_imbalance", imb_per_pixel_means, "not a mean of per-pixel means"),
    ("split_index", split_global_size, "input #1's `sensor_size`"),
    ("tikhonov_autograd", tik_lam, "got 0.05 x the expected value on every input"),
    ("sine_layer_derivative", sine_swapped_outputs, "the two outputs are swapped"),
    ("sine_layer_derivative", sine_minus_cos, "the sign is flipped everywhere"),
    ("frame_train_step", step_minus_reg, "the regularizer is added"),
    ("frame_train_step", step_twice, "one call makes one optimizer.step()"),
    ("temporal_loss_boundary", tlb_per_bin, "one number is expected, not 3"),
    ("temporal_loss_boundary", tlb_sign, "later minus earlier"),
    ("total_variation", tv_prepend, "not over the H W pixels"),
    ("total_variation", tv_per_image_sum, "not the sum of the images' total variations"),
    ("total_variation", tv_square_root_of_sum, "not the square root of the mean of d ** 2"),
    ("reinhard_tonemap", tm_normalised, "min-max normalising"),
    ("reinhard_tonemap", tm_log, "the log of zero or of a negative number"),
    ("anchor", anchor_per_frame, "a mean per image"),
    ("anchor", anchor_standardised, "do not rescale it"),
    ("anchor", anchor_last_axis, "a mean along the last axis"),
    ("offset_gradients", og_prepend, "np.diff without `prepend=`"),
    ("offset_gradients", og_sorted_middle, "sorted[K // 2] is only the upper one"),
    ("offset_gradients", og_swapped_outputs, "gx is the difference along x"),
    ("integrate_gradients", ig_row_first_path, "along the first row and then down the columns"),
    ("bisect_equal_count", bis_concatenated, "interleave the edges and the cuts"),
    ("crossfade_weights", cf_global_windows, "input #1's `windows`"),
    ("crossfade_weights", cf_overlap_sign, "NaN or inf"),
    ("chain_offsets", chain_sum_samples, "off by a constant factor: got 4 x"),
    ("time_fps_products", tfp_global, "input #1's `table`"),
    ("time_fps_products", tfp_int, "the values were made whole numbers"),
    ("pareto_front", pf_args_swapped, "cost and quality swapped"),
    ("pareto_front", pf_best_only, "not only the best quality"),
    ("highpass_per_event", hp_state_default, "the default value of `state`"),
    ("highpass_per_event", hp_alpha_hz, "without dividing by 2 pi"),
    ("render_event_counts", rc_prepend, "one entry too many along the first axis"),
    ("event_rate", er_right_edges, "not the right edges"),
    ("event_rate", er_us, "a unit conversion"),
    ("event_rate", er_rate_per_ms, "a unit conversion"),
    ("event_rate", er_swapped, "the two outputs are swapped"),
    ("estimate_contrast_threshold", ct_sqrt, "not sqrt(sum(ΔL^2) / sum(n^2))"),
    ("estimate_contrast_threshold", ct_abs, "keep the signs"),
    ("estimate_contrast_threshold", ct_tuple, "one number is expected, not 2"),
    ("anchor_first_offset", af_clip_uint8, "clip to [0, 1] after dividing"),
    ("anchor_first_offset", af_exp, "L_t0 is already a log intensity"),
    ("anchor_first_offset", af_uint8_sum, "NaN or inf"),
    ("quad_bayer_channel", qb_global_grid, "input #1's `y`, `x`"),
    ("grey_event_frame", gf_mean, "do not average them"),
    ("grey_event_frame", gf_size_from_data, "not from the largest event coordinates"),
    ("grey_event_frame", gf_int_frame, "the values were made whole numbers"),
    ("grey_event_frame", gf_p_uint8, "-1 becomes 255"),
    ("head_closed_form", head_ridge_B, "not ridge / B"),
    ("head_closed_form", head_pinv, "add ridge times the identity"),
    ("hot_pixel_mask", hot_mean_rows, "a median along an axis (one per column)"),
    ("event_count_windows", ecw_accumulate, "the default value of `idx`"),
    ("event_count_windows", ecw_float_step, "(k * N) // w in integers"),
    ("event_count_windows", ecw_ceil_size, "leave a short last window"),
    ("background_activity_filter", baf_dt_us, "reads it as microseconds"),
    ("background_activity_filter", baf_dt_ms, "reads it as milliseconds"),
    ("background_activity_filter", baf_dropped_events, "the mask is inverted everywhere"),
]

# ---- guards: wrong solutions that already failed with a clear message ---------------------------------------

GUARDS = [
    ("integrate_events_1d", integ_print, "did you forget the `return` statement?"),
    ("integrate_events_1d", integ_assert, "AssertionError: no events"),
    ("temporal_loss", tl_keepdim, "an array holding one number"),
    ("temporal_loss", tl_item, "expected a torch.Tensor"),
    ("esim_interval", esim_p_float, "wrong dtype in output [1]"),
    ("esim_interval", esim_slope_first, "ZeroDivisionError"),
    ("esim_interval", esim_ref_array, "an array holding one number"),
    ("split_index", split_true_div, "use integer division `//`"),
    ("split_index", split_divmod, "TypeError"),
    ("tikhonov_autograd", tik_float, "expected a torch.Tensor"),
    ("sine_layer_derivative", sine_detached, "cut off from the autograd graph"),
    ("frame_train_step", step_no_return, "did you forget the `return` statement?"),
    ("temporal_loss_boundary", tlb_item, "cut off from the autograd graph"),
    ("reinhard_tonemap", tm_torch, "expected a numpy array"),
    ("anchor", anchor_in_place, "changed its input `L` in place"),
    ("integrate_gradients", ig_hardcoded, "LinAlgError"),
    ("integrate_gradients", ig_transposed, "the last two axes are swapped"),
    ("bisect_equal_count", bis_list, "expected a numpy array"),
    ("crossfade_weights", cf_transposed, "the last two axes are swapped"),
    ("chain_offsets", chain_list, "expected a numpy array"),
    ("time_fps_products", tfp_nested, "expected numbers"),
    ("time_fps_products", tfp_total, "expected a dict"),
    ("pareto_front", pf_list, "expected a numpy array"),
    ("pareto_front", pf_int, "return the comparison itself"),
    ("highpass_per_event", hp_list_state, "expected a numpy array"),
    ("render_event_counts", rc_float, "wrong dtype"),
    ("event_rate", er_list, "expected a numpy array"),
    ("estimate_contrast_threshold", ct_lstsq_array, "an array holding one number"),
    ("anchor_first_offset", af_transposed, "the last two axes are swapped"),
    ("quad_bayer_channel", qb_float, "wrong dtype"),
    ("head_closed_form", head_transposed, "the last two axes are swapped"),
    ("head_closed_form", head_E_first, "ValueError"),
    ("hot_pixel_mask", hot_counts_returned, "return the comparison itself"),
    ("hot_pixel_mask", hot_list_mask, "expected a numpy array"),
    ("event_count_windows", ecw_tuple, "expected a numpy array"),
    ("background_activity_filter", baf_indices, "the indices of the True entries"),
]

CORRECT = [
    ("integrate_events_1d", integ_loop_quadratic),
    ("event_rate_derivative", rate_cumsum_guarded),
    ("temporal_loss", tl_mse),
    ("temporal_loss", tl_sum_over_len),
    ("esim_interval", esim_while_loop),
    ("events_to_frames_fixed", frames_float64),
    ("events_to_frames_fixed", frames_bincount),
    ("interval_imbalance", imb_nan_by_mean_of_empty),       # np.mean of no pairs is NaN by itself
    ("interval_imbalance", imb_array),                      # a 0-d array holding b
    ("split_index", split_list),
    ("tikhonov_autograd", tik_double),
    ("tikhonov_autograd", tik_pow),
    ("tikhonov_autograd", tik_vector_norm),
    ("sine_layer_derivative", sine_addmm),
    ("sine_layer_derivative", sine_jvp),                    # forward-mode autograd gives the same derivative
    ("frame_train_step", step_floats),                      # the losses as Python floats
    ("temporal_loss_boundary", tlb_diff),
    ("total_variation", tv_per_image),                      # equal-sized images: the mean of means is the mean
    ("total_variation", tv_sqrt_square),
    ("reinhard_tonemap", tm_clipped),
    ("offset_gradients", og_list),
    ("offset_gradients", og_percentile),
    ("integrate_gradients", ig_lstsq_min_norm),             # the minimum-norm solution already has mean 0
    ("integrate_gradients", ig_pinv),
    ("integrate_gradients", ig_float32),
    ("bisect_equal_count", bis_sorted_concat),
    ("crossfade_weights", cf_loop),
    ("chain_offsets", chain_loop),
    ("chain_offsets", chain_float32),
    ("time_fps_products", tfp_numpy),
    ("pareto_front", pf_loop),
    ("highpass_per_event", hp_time_us),                     # microseconds throughout (alpha per microsecond)
    ("render_event_counts", rc_loop_pixels),
    ("estimate_contrast_threshold", ct_lstsq),
    ("estimate_contrast_threshold", ct_means),
    ("quad_bayer_channel", qb_lookup),
    ("grey_event_frame", gf_bincount),
    ("grey_event_frame", gf_reshape_sum),
    ("head_closed_form", head_augmented),                   # lstsq on [A; sqrt(ridge) I], [E; 0]
    ("head_closed_form", head_per_pixel_loop),
    ("hot_pixel_mask", hot_histogram2d),                    # histogram2d with the sensor's edges
    ("event_count_windows", ecw_list_comp),
    ("background_activity_filter", baf_loop),
    ("background_activity_filter", baf_sorted_window),
]


def _id(rows):
    return [f"{r[0]}-{k}-{getattr(r[1], '__name__', 'fn').strip('<>_')}" for k, r in enumerate(rows)]


@pytest.mark.parametrize("name, wrong, words", HOLES, ids=_id(HOLES))
def test_hole_now_fails_and_names_the_mistake(name, wrong, words):
    _HP_STATE.clear()
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
def test_guard_correct_alternatives_pass(name, fn):
    ok, report = _report(name, fn)
    assert ok, report


def test_a_coincidence_on_one_input_is_not_called_a_notebook_variable():
    """A column phase alone equals input #1's phase (0, 0) on input #2 by chance; the other inputs show it is not
    the first input's phase that was used, so the report must not say so."""
    def qb_phase_x_only(y, x, phase):
        return R("quad_bayer_channel")(y, x, (0, phase[1]))
    ok, report = _report("quad_bayer_channel", qb_phase_x_only)
    assert not ok and "input #1's `phase`" not in report, report


def test_a_memo_cache_keyed_by_its_input_still_passes():
    """State kept between calls is fine when it cannot change a result (a cache keyed by the input itself)."""
    def integ_memo(t_events, p_events, C, t_query, _memo={}):
        key = (np.asarray(t_events).tobytes(), np.asarray(p_events).tobytes(), C, np.asarray(t_query).tobytes())
        if key not in _memo:
            _memo[key] = R("integrate_events_1d")(t_events, p_events, C, t_query)
        return _memo[key].copy()
    ok, report = _report("integrate_events_1d", integ_memo)
    assert ok, report


def test_a_table_argument_is_described_briefly():
    ok, report = _report("time_fps_products", tfp_total)
    headline = report.splitlines()[0]
    assert not ok and "dict of 4 items" in headline and "'mse'" not in headline, headline


def test_the_cases_hold_a_sensor_larger_than_its_events():
    for name in ("events_to_frames_fixed", "highpass_per_event", "hot_pixel_mask"):
        found = False
        for _, kw in exercises.get(name).cases():
            ev = kw.get("events")
            x, y, (H, W) = (ev.x, ev.y, ev.sensor_size) if ev is not None else (kw["x"], kw["y"], kw["sensor_size"])
            found |= int(np.max(y)) + 1 < H and int(np.max(x)) + 1 < W
        assert found, name


def test_the_counts_the_notebooks_quote_are_unchanged():
    """Each notebook says "✓ NAME: matches the reference on N inputs"; cases were changed, never added."""
    quoted = quoted_counts()
    for name in ("events_to_frames_fixed", "highpass_per_event", "hot_pixel_mask"):
        assert len(exercises.get(name).cases()) == quoted[name], name


def test_every_hint_fires_on_its_own_wrong_version():
    for name in exercises.names():
        for message, wrong in exercises.get(name).hints.items():
            ok, report = _report(name, wrong)
            assert not ok and message in report, (name, message, report)


def test_the_wrong_versions_differ_from_the_reference():
    """Every wrong solution above is wrong on some case of its exercise, or changes its state between calls."""
    for name, wrong, _ in HOLES + NAMED + GUARDS:
        _HP_STATE.clear()
        ex = exercises.get(name)
        differs = False
        for args, kwargs in ex.cases() + ex.cases()[-1:]:
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
