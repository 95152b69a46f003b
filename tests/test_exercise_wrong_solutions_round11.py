"""Exercise checks, round 11: twenty-six more wrong solutions across 18 exercises, in mistake classes that rounds
2-10 did not try, and twenty-eight correct alternatives.

Mistake classes: integer overflow at realistic counts (a hot pixel's count in uint8, a grey pixel's or an event
frame's net count summed in int8, the polarities' own dtype, k * N in int32 on a recording of millions of events)
and whole numbers past float32's 2 ** 24; equality with a tolerance (np.isclose for ties between variants, for an
event at a query time); polarities as bool arithmetic (`(p > 0) - (p < 0)`, which numpy refuses and whose suggested
`^` is no sign; a bool polarity stored as 0; unsigned `(p > 0).astype(np.uint8) - ...`, where -1 wraps to 255);
an early return for the empty case with the wrong dtype (plain np.array([]) for int8 polarities, whole zeros for
float sums), a list, or the wrong shape; np.sort of one array where the others had to follow (pixel numbers sorted
alone, qualities sorted alone); normalising by the column's largest weight, not its sum; a mean where each entry has
its own value (the mean window length, one mean over the x and y differences together); np.fill_diagonal, which
sets the diagonal and adds nothing; exp(-alpha t) / exp(-alpha t_last), which underflows on a clock at 1000 s; the
reshape view of an input negated in place; `*` and `@` read left to right; np.median of an odd count for the cut;
whole steps N // w with the remainder left to the last window.

Correct alternatives: counts normalised by their maximum (the rule is scale-free), statistics.median, nonzero(),
int16 and int32 sums below their range, Python integers and divmod for k * N // w, np.bincount with weights,
torch's index_put_ with accumulate, exact comparisons in loops, float32 costs, a difference compared with 0, an
int64 cumsum, counts of ON minus counts of OFF (bool sums made integers), bool `|` plus `&` for the channel,
floor(|d| / C) times the sign for trunc, torch.diff on the last axes, torch.hypot, a mean of per-bin means over
equal bins, the median of negated differences, solve(M, A^T) @ E, (1 + e^-L) ** -gamma, log(s) - log1p(-s), event
times measured back from the second sample, einsum, np.lexsort, the remainder before the division.

Holes (these passed a check before this round; each now fails and its report names the mistake):
- hot_pixel_mask: counts in uint8 passed: the hot pixels fired 150, 400 and 31 times, and 400 wraps to 144, still
  hot. The second case's 400 is now 260, which wraps to 4;
- event_count_windows: (k * N) // w in int32, and floor(k * N / w) in float32, passed: N was below 9000. The fourth
  case is now three million events in windows of at most 2000 (k * N reaches 4.5e9; the windows hold 1998 or 1999
  events, so that ceil(N / w) events per window is still told from max_events each);
- grey_event_frame: net counts summed in the polarities' int8 passed: no grey pixel got more than a few dozen. The
  last case is now a flash: 1200 events, nine in ten ON, some 160 net on each grey pixel;
- events_to_frames_fixed: frames summed in the polarities' int8 passed. The first case now holds a hot pixel that
  fires 130 ON events in its second bin;
- pareto_front: ties told by np.isclose passed: every cost and quality was a small whole number or a fifth. The last
  case's costs are now counted in weights, a million and a few apart (np.isclose calls them equal).
For mistakes the check saw only as wrong values: a generic mistake for -1/+1 polarities made unsigned (-1 is 255);
a TypeError or RuntimeError for `-` on bool arrays or tensors gets a hint (numpy and torch suggest `^`, which is no
sign; since the round's review the sign's wording only where an input holds polarities, a neutral one elsewhere); a generic mistake (or an argument from input #1) whose NaN meets the learner's NaN is no longer named where
the expected values are finite (exp(-alpha t) on a clock at 1000 s was called "an input was clipped to [0, 1]" and
"the right result for input #1's t"). Registered hints: uint8 and int8 counts (hot_pixel_mask), int32, float32 and a whole
step N // w (event_count_windows), int8 sums (grey_event_frame, events_to_frames_fixed), np.isclose and qualities
sorted alone (pareto_front), np.isclose at a query (integrate_events_1d), the mean duration (temporal_loss), one
mean over both directions (total_variation), the column's maximum (crossfade_weights), pixel numbers sorted alone
(interval_imbalance), np.fill_diagonal (head_closed_form), exponentials split (highpass_per_event).

Open, on purpose: none new. Counts in int16 (32768 events on one pixel) and float32 accumulation of C over many
events were not given cases: the int16 range is past what a hot pixel fires in a test-sized recording, and round 5
already fails float32 running sums where they lose an event.
"""
import statistics

import numpy as np
import pytest
import torch

from evinr_lite.teaching import exercises
from exercise_reports import quoted_counts, report as _report, seeded_numpy


def R(n): return exercises.reference(n)


# ---- anchor, anchor_first_offset
def anchor_log1p(L, gamma, display_mean):                   # logit as log(s) - log1p(-s)
    L = np.asarray(L, float); s = display_mean ** (1 / gamma)
    return L - L.mean() + (np.log(s) - np.log1p(-s))
def afo_ravel_view(first_frame, L_t0, eps=1 / 255):         # reshape(-1) is a view: the caller's L_t0 negated in place
    a = np.asarray(first_frame); I = a / 255.0 if a.dtype == np.uint8 else np.clip(a.astype(float), 0, 1)
    l = np.asarray(L_t0, float).reshape(-1); l *= -1
    return np.log(I + eps) + l.reshape(I.shape)

# ---- bisect_equal_count
def bis_np_median(t_events, boundaries):                    # np.median of the bin's events for the cut
    t = np.asarray(t_events, float); b = np.asarray(boundaries, float); out = [b[0]]
    for i in range(len(b) - 1):
        s = t[((t > b[i]) | ((i == 0) & (t == b[i]))) & (t <= b[i + 1])]; c = 0.5 * (b[i] + b[i + 1])
        if len(s) >= 2 and b[i] < np.median(s) < b[i + 1]:
            c = np.median(s)
        out += [c, b[i + 1]]
    return np.array(out)

# ---- chain_offsets
def chain_empty_early(prev, nxt):                           # K = 0 answered before the shape is read
    prev = np.asarray(prev, float); nxt = np.asarray(nxt, float)
    if len(prev) == 0:
        return np.zeros(1)
    return np.concatenate([np.zeros((1,) + prev.shape[2:]), np.cumsum((prev - nxt).mean(axis=1), axis=0)])

# ---- crossfade_weights
def cf_over_max(windows, times):                            # each column over its largest weight, not its sum
    windows = np.asarray(windows, float); t = np.asarray(times, float)
    if len(windows) == 1:
        return np.ones((1, len(t)))
    ov = windows[0, 1] - windows[1, 0]
    fi = np.clip((t - windows[:, :1]) / ov, 0, 1); fo = np.clip((windows[:, 1:] - t) / ov, 0, 1); fi[0] = 1; fo[-1] = 1
    w = np.minimum(fi, fo)
    return w / w.max(axis=0, keepdims=True)

# ---- esim_interval
def esim_empty_float(L_a, L_b, t_a, t_b, ref, C):           # no event: plain empty arrays (float64 polarities)
    d = L_b - ref; p = 1 if d > 0 else -1; n = int(np.floor(abs(d) / C))
    if n == 0:
        return np.array([]), np.array([]), float(ref)
    lv = ref + p * C * np.arange(1, n + 1)
    return t_a + (lv - L_a) / (L_b - L_a) * (t_b - t_a), np.full(n, p, np.int8), float(ref + p * n * C)
def esim_empty_list(L_a, L_b, t_a, t_b, ref, C):            # no event: empty lists
    d = L_b - ref; p = 1 if d > 0 else -1; n = int(np.floor(abs(d) / C))
    if n == 0:
        return [], [], ref
    lv = ref + p * C * np.arange(1, n + 1)
    return t_a + (lv - L_a) / (L_b - L_a) * (t_b - t_a), np.full(n, p, np.int8), float(ref + p * n * C)
def esim_bool_polarity(L_a, L_b, t_a, t_b, ref, C):         # the polarity kept as the bool `up`: OFF stored as 0
    up = L_b > ref; p = int(up) - int(not up); n = int(np.floor(abs(L_b - ref) / C))
    lv = ref + p * C * np.arange(1, n + 1)
    times = t_a + (lv - L_a) / (L_b - L_a) * (t_b - t_a) if n else np.zeros(0)
    return times, np.full(n, up, np.int8), float(ref + p * n * C)
def esim_from_end(L_a, L_b, t_a, t_b, ref, C):              # times measured back from the second sample
    d = L_b - ref; p = 1 if d > 0 else -1; n = int(np.floor(abs(d) / C))
    lv = ref + p * C * np.arange(1, n + 1)
    t = t_b - (L_b - lv) / (L_b - L_a) * (t_b - t_a) if n else np.zeros(0)
    return np.asarray(t, np.float64), np.full(n, p, np.int8), float(ref + p * n * C)

# ---- estimate_contrast_threshold
def ct_einsum(log_changes, net_counts):
    d = np.asarray(log_changes, float); n = np.asarray(net_counts, float)
    return float(np.einsum("i,i", d, n) / np.einsum("i,i", n, n))

# ---- event_count_windows
def ecw_int32(n_events, max_events):                        # int32 indices: k * N wraps past 2 ** 31
    w = max(1, -(-n_events // max_events))
    return (np.arange(w + 1, dtype=np.int32) * np.int32(n_events) // w).astype(np.int64)
def ecw_float32(n_events, max_events):                      # floor(k * N / w) in float32
    w = max(1, -(-n_events // max_events))
    return np.floor(np.arange(w + 1, dtype=np.float32) * np.float32(n_events) / np.float32(w)).astype(np.int64)
def ecw_floor_step(n_events, max_events):                   # a whole step N // w, the remainder left to the last window
    w = max(1, -(-n_events // max_events))
    idx = np.arange(w + 1, dtype=np.int64) * (n_events // w); idx[-1] = n_events
    return idx
def ecw_python_ints(n_events, max_events):                  # Python integers do not overflow
    w = max(1, -(-n_events // max_events))
    return np.array([k * n_events // w for k in range(w + 1)], np.int64)
def ecw_divmod(n_events, max_events):                       # N = q w + r: k q + (k r) // w, each product small
    w = max(1, -(-n_events // max_events)); q, r = divmod(n_events, w); k = np.arange(w + 1, dtype=np.int32)
    return (k.astype(np.int64) * q + (k * r) // w).astype(np.int64)

# ---- event_rate_derivative
def erd_mean_duration(t_events, p_events, C, boundaries):   # every window's sum over the mean window length
    b = np.asarray(boundaries, float)
    return R("event_rate_derivative")(t_events, p_events, C, b) * np.diff(b) / np.diff(b).mean()

# ---- events_to_frames_fixed
def _frame_bins(events, b):
    i = np.searchsorted(b, events.t, side="left") - 1; i[events.t == b[0]] = 0
    return i, (i >= 0) & (i < b.size - 1)
def ef_int8_frames(events, boundaries, C):                  # per-bin sums in the polarities' dtype (int8)
    b = np.asarray(boundaries, float); H, W = events.sensor_size; i, k = _frame_bins(events, b)
    fr = np.zeros((b.size - 1, H, W), events.p.dtype); np.add.at(fr, (i[k], events.y[k], events.x[k]), events.p[k])
    return (C * fr).astype(np.float32)
def ef_int32_sums(events, boundaries, C):                   # int32 sums: far from their range
    b = np.asarray(boundaries, float); H, W = events.sensor_size; i, k = _frame_bins(events, b)
    fr = np.zeros((b.size - 1, H, W), np.int32); np.add.at(fr, (i[k], events.y[k], events.x[k]), events.p[k])
    return (C * fr).astype(np.float32)

# ---- grey_event_frame
def gf_int8_counts(x, y, p, C, raw_size):                   # net counts in the polarities' dtype (int8)
    H, W = raw_size; n = np.zeros((H // 4, W // 4), np.asarray(p).dtype)
    np.add.at(n, (np.asarray(y) // 4, np.asarray(x) // 4), np.asarray(p))
    return C * n / 16.0
def gf_bool_subtract(x, y, p, C, raw_size):                 # the sign as (p > 0) - (p < 0): numpy refuses `-` on bools
    H, W = raw_size; fr = np.zeros((H // 4, W // 4)); s = (np.asarray(p) > 0) - (np.asarray(p) < 0)
    np.add.at(fr, (np.asarray(y) // 4, np.asarray(x) // 4), C * s / 16)
    return fr
def gf_bincount(x, y, p, C, raw_size):
    H, W = raw_size; i = (np.asarray(y) // 4) * (W // 4) + np.asarray(x) // 4
    return (C / 16) * np.bincount(i, weights=np.asarray(p, float), minlength=(H // 4) * (W // 4)).reshape(H // 4, W // 4)
def gf_torch_index_put(x, y, p, C, raw_size):
    H, W = raw_size; fr = torch.zeros(H // 4, W // 4, dtype=torch.float64)
    fr.index_put_((torch.as_tensor(y) // 4, torch.as_tensor(x) // 4), torch.as_tensor(p, dtype=torch.float64) * C / 16,
                  accumulate=True)
    return fr.numpy()
def gf_int16_counts(x, y, p, C, raw_size):                  # int16 holds the flash's net counts
    H, W = raw_size; n = np.zeros((H // 4, W // 4), np.int16)
    np.add.at(n, (np.asarray(y) // 4, np.asarray(x) // 4), np.asarray(p, np.int16))
    return C * n / 16

# ---- head_closed_form
def head_fill_diagonal(A, E, ridge):                        # np.fill_diagonal sets the diagonal to ridge
    A = np.asarray(A, float); M = A.T @ A; np.fill_diagonal(M, ridge)
    return np.linalg.solve(M, A.T @ np.asarray(E, float))
def head_solve_then_E(A, E, ridge):                         # (M^-1 A^T) E: the same product, other brackets
    A = np.asarray(A, float)
    return np.linalg.solve(A.T @ A + ridge * np.eye(A.shape[1]), A.T) @ np.asarray(E, float)

# ---- highpass_per_event
def hp_split_exp(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):   # exp(-a t) / exp(-a t_last)
    H, W = sensor_size; s = np.zeros((H, W)); tl = np.full((H, W), float(t_start))
    for ti, xi, yi, pi in zip(t, x, y, p):
        s[yi, xi] = np.exp(-alpha * ti) / np.exp(-alpha * tl[yi, xi]) * s[yi, xi] + C * pi; tl[yi, xi] = ti
    return s * np.exp(-alpha * t_end) / np.exp(-alpha * tl)

# ---- hot_pixel_mask
def hpm_uint8_counts(x, y, sensor_size, factor=10.0):       # uint8 counts wrap at 256 events
    H, W = sensor_size; c = np.zeros((H, W), np.uint8); np.add.at(c, (np.asarray(y), np.asarray(x)), 1)
    return c > factor * np.median(c[c > 0])
def hpm_max_normalised(x, y, sensor_size, factor=10.0):     # counts / max: the rule is scale-free
    H, W = sensor_size; c = np.zeros((H, W)); np.add.at(c, (np.asarray(y), np.asarray(x)), 1); c = c / c.max()
    return c > factor * np.median(c[c > 0])
def hpm_statistics(x, y, sensor_size, factor=10.0):         # int32 counts, statistics.median
    H, W = sensor_size
    c = np.bincount(np.asarray(y) * W + np.asarray(x), minlength=H * W).astype(np.int32).reshape(H, W)
    return c > factor * statistics.median(c[c > 0].tolist())
def hpm_nonzero_index(x, y, sensor_size, factor=10.0):
    H, W = sensor_size; c = np.zeros((H, W), np.int64); np.add.at(c, (np.asarray(y), np.asarray(x)), 1)
    return c > factor * np.median(c[c.nonzero()])

# ---- integrate_events_1d
def ie_uint8_polarity(t_events, p_events, C, t_query):      # (p > 0) - (p < 0) in uint8: OFF wraps to 255
    p = np.asarray(p_events); s = (p > 0).astype(np.uint8) - (p < 0).astype(np.uint8)
    cs = np.concatenate([[0], np.cumsum(s)])
    return C * cs[np.searchsorted(t_events, t_query, side="right")].astype(float)
def ie_isclose_queries(t_events, p_events, C, t_query):     # "<=" as "<" or np.isclose
    t = np.asarray(t_events, float); q = np.asarray(t_query, float)
    before = (t[None, :] < q[:, None]) | np.isclose(t[None, :], q[:, None])
    return C * (before * np.asarray(p_events, float)).sum(axis=1)
def ie_empty_int_zeros(t_events, p_events, C, t_query):     # no events: "nothing happened", as whole zeros
    if len(t_events) == 0:
        return np.zeros(len(t_query), dtype=int)
    cs = np.concatenate([[0.0], np.cumsum(np.asarray(p_events, float))])
    return C * cs[np.searchsorted(t_events, t_query, side="right")]
def ie_difference_sign(t_events, p_events, C, t_query):     # t_q - t_i >= 0 is t_i <= t_q exactly
    t = np.asarray(t_events, float); q = np.asarray(t_query, float)
    return C * ((q[:, None] - t[None, :] >= 0) * np.asarray(p_events, float)).sum(axis=1)
def ie_int64_cumsum(t_events, p_events, C, t_query):
    cs = np.concatenate([[0], np.cumsum(p_events, dtype=np.int64)])
    return C * cs[np.searchsorted(t_events, t_query, side="right")]
def ie_bool_counts(t_events, p_events, C, t_query):         # ON counts minus OFF counts: bool sums are integers
    p = np.asarray(p_events); cs = np.concatenate([[0], np.cumsum(p > 0) - np.cumsum(p < 0)])
    return C * cs[np.searchsorted(t_events, t_query, side="right")]

# ---- interval_imbalance
def _imbalance(pix, t, p):
    pair = (pix[1:] == pix[:-1]) & (p[1:] == p[:-1]); ld = np.log(np.maximum(np.diff(t), 1e-6)); on = p[1:] > 0
    if not (pair & on).any() or not (pair & ~on).any():
        return float("nan")
    return float(np.tanh((ld[pair & on].mean() - ld[pair & ~on].mean()) / 2))
def ii_sort_values(events):                                 # np.sort of the pixel numbers: times no longer follow
    H, W = events.sensor_size
    return _imbalance(np.sort(events.y.astype(np.int64) * W + events.x), np.asarray(events.t, float), events.p)
def ii_lexsort(events):                                     # by pixel, then by time
    H, W = events.sensor_size; pix = events.y.astype(np.int64) * W + events.x; t = np.asarray(events.t, float)
    o = np.lexsort((t, pix))
    return _imbalance(pix[o], t[o], events.p[o])

# ---- offset_gradients
def og_median_of_negated(frames):
    F = np.asarray(frames, float)
    return np.median(-np.diff(F, axis=2), axis=0), np.median(-np.diff(F, axis=1), axis=0)

# ---- pareto_front
def pf_isclose_ties(cost, quality):                         # "equal" within np.isclose
    c = np.asarray(cost, float); q = np.asarray(quality, float); K = len(c); out = np.ones(K, bool)
    for i in range(K):
        for j in range(K):
            le = (c[j] <= c[i]) | np.isclose(c[j], c[i]); ge = (q[j] >= q[i]) | np.isclose(q[j], q[i])
            if le and ge and not (np.isclose(c[j], c[i]) and np.isclose(q[j], q[i])):
                out[i] = False
    return out
def pf_sorted_qualities(cost, quality):                     # np.sort(quality) read in argsort(cost)'s order
    c = np.asarray(cost, float); order = np.argsort(c, kind="stable")
    keep = np.zeros(len(c), bool); best = -np.inf
    for i, qq in zip(order, np.sort(np.asarray(quality, float))[::-1]):
        if qq > best:
            keep[i], best = True, qq
    return keep
def pf_exact_loops(cost, quality):
    c = [float(v) for v in cost]; q = [float(v) for v in quality]; K = len(c)
    return np.array([not any(c[j] <= c[i] and q[j] >= q[i] and (c[j] < c[i] or q[j] > q[i]) for j in range(K))
                     for i in range(K)])
def pf_float32(cost, quality):                              # a million and a few are exact in float32
    c = np.asarray(cost, np.float32)[:, None]; q = np.asarray(quality, np.float32)[:, None]
    return ~((c.T <= c) & (q.T >= q) & ((c.T < c) | (q.T > q))).any(axis=1)

# ---- quad_bayer_channel, reinhard_tonemap, render_event_counts, sine_layer_derivative, split_index
def qb_bool_arith(y, x, phase):                             # (r | c) + (r & c) is r + c for bools
    r = ((np.asarray(y) + phase[0]) % 4) >= 2; c = ((np.asarray(x) + phase[1]) % 4) >= 2
    return (r | c).astype(np.int64) + (r & c)
def tm_power_negative(L, gamma):                            # (1 + e^-L) ** -gamma
    return np.power(1.0 + np.exp(-np.asarray(L, float)), -gamma)
def rc_floor_abs_sign(L_boundaries, C):                     # trunc as floor(|d| / C) times the sign
    L = np.asarray(L_boundaries, float); ref = L[0].copy(); out = []
    for k in range(1, len(L)):
        n = np.floor(np.abs(L[k] - ref) / C) * np.sign(L[k] - ref); out.append(n); ref = ref + n * C
    return np.array(out, np.int64)
def sld_matmul_left_to_right(h, dh_dt, weight, bias, omega):   # cos(z) * omega * dh_dt @ weight: `@` last
    z = omega * (h @ weight + bias)
    return torch.sin(z), torch.cos(z) * omega * dh_dt @ weight
def split_mod_first(index, sensor_size):                    # the remainder within a frame first
    H, W = sensor_size; r = index % (H * W)
    return index // (H * W), r // W, r % W

# ---- temporal_loss, temporal_loss_boundary, tikhonov_autograd, total_variation
def tl_mean_duration(dF_dt, delta_L, durations):            # one mean window length for every window
    return torch.mean((delta_L - dF_dt * durations.mean()) ** 2)
def tlb_mean_of_means(F_boundaries, event_frames):          # a mean of per-bin means: the bins are equal in size
    return ((event_frames - torch.diff(F_boundaries, dim=0)) ** 2).mean(dim=(1, 2)).mean()
def tik_two_means(dF_dx, dF_dy):                            # the two have the same length
    return dF_dx.pow(2).mean() + dF_dy.pow(2).mean()
def tik_hypot(dF_dx, dF_dy):
    return torch.mean(torch.hypot(dF_dx, dF_dy) ** 2)
def tv_pooled_mean(F):                                      # one mean over dx and dy together, times 2
    dx = F[..., :, 1:] - F[..., :, :-1]; dy = F[..., 1:, :] - F[..., :-1, :]
    return (dx.abs().sum() + dy.abs().sum()) / (dx.numel() + dy.numel()) * 2
def tv_diff_last_dims(F):
    return torch.diff(F, dim=-1).abs().mean() + torch.diff(F, dim=-2).abs().mean()


HOLES = [
    ("event_count_windows", ecw_int32, "int32 wraps round to negative numbers"),
    ("event_count_windows", ecw_float32, "float32 holds whole numbers exactly only up to 2 ** 24"),
    ("events_to_frames_fixed", ef_int8_frames, "wrap past 127"),
    ("grey_event_frame", gf_int8_counts, "wraps past 127"),
    ("hot_pixel_mask", hpm_uint8_counts, "uint8 wrap past 255"),
    ("pareto_front", pf_isclose_ties, "np.isclose (or any tolerance)"),
]

NAMED = [
    ("anchor_first_offset", afo_ravel_view, "changed its input `L_t0` in place"),
    ("bisect_equal_count", bis_np_median, "np.median of an odd number of events"),
    ("chain_offsets", chain_empty_early, "wrong shape: got (1,), expected (1, 2, 3)"),
    ("crossfade_weights", cf_over_max, "not by its largest weight"),
    ("esim_interval", esim_empty_float, "wrong dtype in output [1]"),
    ("esim_interval", esim_empty_list, "returned a list in output [0]"),
    ("esim_interval", esim_bool_polarity, "polarity -1, not 0"),
    ("event_count_windows", ecw_floor_step, "leave the whole remainder to the last window"),
    ("event_rate_derivative", erd_mean_duration, "by its own length"),
    ("grey_event_frame", gf_bool_subtract, "`-` on two bool arrays or tensors"),
    ("head_closed_form", head_fill_diagonal, "np.fill_diagonal(M, ridge) replaces the diagonal"),
    ("highpass_per_event", hp_split_exp, "exp(-alpha t) / exp(-alpha t_last) underflows"),
    ("integrate_events_1d", ie_uint8_polarity, "the polarities were made unsigned"),
    ("integrate_events_1d", ie_isclose_queries, "a tolerance for the equal case"),
    ("integrate_events_1d", ie_empty_int_zeros, "the values were made whole numbers"),
    ("interval_imbalance", ii_sort_values, "np.sort(pix) sorts the pixel numbers alone"),
    ("pareto_front", pf_sorted_qualities, "np.sort(quality) sorts the qualities on their own"),
    ("sine_layer_derivative", sld_matmul_left_to_right, "shapes cannot be multiplied"),
    ("temporal_loss", tl_mean_duration, "not by their mean"),
    ("total_variation", tv_pooled_mean, "average each direction over its own differences"),
]

CORRECT = [
    ("anchor", anchor_log1p), ("esim_interval", esim_from_end), ("estimate_contrast_threshold", ct_einsum),
    ("event_count_windows", ecw_python_ints), ("event_count_windows", ecw_divmod),
    ("events_to_frames_fixed", ef_int32_sums), ("grey_event_frame", gf_bincount),
    ("grey_event_frame", gf_torch_index_put), ("grey_event_frame", gf_int16_counts),
    ("head_closed_form", head_solve_then_E), ("hot_pixel_mask", hpm_max_normalised), ("hot_pixel_mask", hpm_statistics),
    ("hot_pixel_mask", hpm_nonzero_index), ("integrate_events_1d", ie_difference_sign),
    ("integrate_events_1d", ie_int64_cumsum), ("integrate_events_1d", ie_bool_counts), ("interval_imbalance", ii_lexsort),
    ("offset_gradients", og_median_of_negated), ("pareto_front", pf_exact_loops), ("pareto_front", pf_float32),
    ("quad_bayer_channel", qb_bool_arith), ("reinhard_tonemap", tm_power_negative),
    ("render_event_counts", rc_floor_abs_sign), ("split_index", split_mod_first),
    ("temporal_loss_boundary", tlb_mean_of_means), ("tikhonov_autograd", tik_two_means),
    ("tikhonov_autograd", tik_hypot), ("total_variation", tv_diff_last_dims),
]


@pytest.fixture(autouse=True)
def _seeded():
    with seeded_numpy():
        yield


from exercise_reports import case_ids as _id   # noqa: E402


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


@pytest.mark.parametrize("name, fn", CORRECT, ids=_id(CORRECT))
def test_correct_alternatives_pass(name, fn):
    ok, report = _report(name, fn)
    assert ok, report


def test_this_round_covers_most_exercises_with_twenty_six_wrong_and_twenty_eight_correct():
    wrong = HOLES + NAMED
    assert len(wrong) >= 26 and len(CORRECT) >= 28
    assert len({r[0] for r in wrong}) >= 18 and len({r[0] for r in wrong + CORRECT}) >= 26


def test_the_changed_cases_hold_what_the_holes_need():
    """Counts past int8 and uint8, k * N past 2 ** 31, costs np.isclose calls equal."""
    hp = exercises.get("hot_pixel_mask").cases()[1][1]
    counts = np.bincount(hp["y"] * hp["sensor_size"][1] + hp["x"])
    median = np.median(counts[counts > 0])
    assert counts.max() >= 256 and counts.max() % 256 <= hp["factor"] * median < counts.max()
    ecw = exercises.get("event_count_windows").cases()[3][1]
    w = -(-ecw["n_events"] // ecw["max_events"])
    assert w * ecw["n_events"] > 2 ** 31 and -(-ecw["n_events"] // w) < ecw["max_events"]
    gr = exercises.get("grey_event_frame").cases()[3][1]
    net = np.zeros((gr["raw_size"][0] // 4, gr["raw_size"][1] // 4), np.int64)
    np.add.at(net, (gr["y"] // 4, gr["x"] // 4), gr["p"])
    assert gr["p"].dtype == np.int8 and np.abs(net).max() > 127
    ef = exercises.get("events_to_frames_fixed").cases()[0][1]
    ev, b = ef["events"], ef["boundaries"]
    hot = (ev.x == 3) & (ev.y == 0) & (ev.t > b[1]) & (ev.t <= b[2])
    assert ev.p.dtype == np.int8 and ev.p[hot].sum() > 127 and np.all(np.diff(ev.t) >= 0)
    pf = exercises.get("pareto_front").cases()[4][1]
    c = pf["cost"]
    assert len(set(c)) > 1 and np.isclose(c[:, None], c[None, :]).all()


def test_the_counts_the_notebooks_quote_are_unchanged():
    """Cases were changed, never added."""
    quoted = quoted_counts()
    for name in ("hot_pixel_mask", "event_count_windows", "grey_event_frame", "events_to_frames_fixed", "pareto_front"):
        if name in quoted:
            assert len(exercises.get(name).cases()) == quoted[name], name


def test_bool_subtraction_gets_a_hint_in_torch_too():
    def tl_sign(dF_dt, delta_L, durations):
        sign = (delta_L > 0) - (delta_L < 0)            # torch refuses `-` on bool tensors, as numpy does
        return torch.mean((delta_L - sign * dF_dt * durations) ** 2)
    ok, report = _report("temporal_loss", tl_sign)
    assert not ok and "`-` on two bool arrays or tensors" in report, report


def test_the_sign_hint_only_where_there_are_polarities():
    """Review: the bool-subtraction hint spoke of p and of `^` as no sign for any `-` on bools; a mask difference in
    an exercise without polarities gets the neutral hint (and `^`, right there, is not called wrong)."""
    ok, report = _report("grey_event_frame", gf_bool_subtract)
    assert not ok and "np.sign(p)" in report, report

    def hot_mask_difference(x, y, sensor_size, factor=10.0):
        H, W = sensor_size
        counts = np.zeros((H, W), np.int64)
        np.add.at(counts, (np.asarray(y), np.asarray(x)), 1)
        return (counts > factor * np.median(counts[counts > 0])) - (counts == 0)
    ok, report = _report("hot_pixel_mask", hot_mask_difference)
    assert not ok and "`-` on two bool arrays or tensors is refused" in report, report
    assert "np.sign(p)" not in report and "p itself" not in report, report


def test_int8_hot_pixel_counts_get_their_own_hint():
    def hpm_int8_counts(x, y, sensor_size, factor=10.0):
        H, W = sensor_size; c = np.zeros((H, W), np.int8); np.add.at(c, (np.asarray(y), np.asarray(x)), 1)
        return c > factor * np.median(c[c > 0])
    ok, report = _report("hot_pixel_mask", hpm_int8_counts)
    assert not ok and "int8 wrap past 127" in report, report


def test_a_nan_alike_is_no_evidence_for_a_generic_hint():
    """exp(-alpha t) on a clock at 1000 s: the reference fed input #1's times, or clipped ones, gives NaN too."""
    ok, report = _report("highpass_per_event", hp_split_exp)
    assert not ok
    assert "clipped to [0, 1]" not in report and "input #1's" not in report, report
