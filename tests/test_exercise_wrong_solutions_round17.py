"""Exercise checks, round 17: ten more wrong solutions across 9 exercises, in mistake classes that rounds 2-16 did
not try, and ten correct alternatives (in 8 exercises).

How the notebooks call the functions was read off a run of every notebook with ``exercises.use`` wrapped to log its
arguments (fast mode): where the notebooks pass other dtypes than the check, and what sizes they use.

Mistake classes: a function right only for the dtype the check passed, where the notebook passes another (notebook
05 calls `tv(F)` on a float64 stack, every input of total_variation was float32: a difference matrix made with
torch.eye, or a convolution kernel made with torch.tensor([[-1.0, 1.0]]), is float32 and torch refuses to mix it
with float64); a result that depends on the clock (an iterative solver stopped after a time budget, `while
time.perf_counter() - t0 < 0.2`: converged on the check's small inputs, stopped early on the notebook's 48 x 64 image
or on a busy machine); a size fixed in the code that is not input #1's (the notebook's 40 bins for event_rate, its
sensor (48, 64) or RAW (64, 96) read from notebook variables, its 32 frames).

Correct alternatives: the difference matrix and the kernel made like the input (dtype=F.dtype, F.new_tensor), the
clock read only to print how long a solve took, an iterative solver stopped on a tolerance, a RuntimeWarning left
unsilenced (0 / 0 gives the documented NaN), a 0-d array for a float, a list of outputs for a tuple, bins counted
from the arguments, and a size read from sensor_size.

Holes (these passed a check before this round; each now fails and its report names the mistake):
- total_variation: tv_eye_matrices, tv_conv_kernel passed (every F was float32) and raised RuntimeError in notebook
  05, cell 11. The third input is now float64 (its values unchanged: float32 draws made float64; the count of 3
  stands), and torch's refusal to mix float32 and float64 (`expected m1 and m2 to have the same dtype`, `expected
  scalar type Double but found Float`) now names the input's width and how to make a tensor like it
  (run_check._float_widths_hint);
- integrate_gradients, head_closed_form, estimate_contrast_threshold: ig_time_budget, hcf_time_budget and
  ect_time_budget converged within their time budget on every input. The second call of the last input now runs on
  a clock 3600 s faster at every read (learner_calls.fast_clock: the time module's clocks, and names a notebook bound
  to them with `from time import ...`; the check's own reads, a library's and another thread's stay real); where the function read the clock and
  matched there, every other input is run on it too (the last input of integrate_gradients is a constant image,
  which a solver's zero start already is); a result that differs there and matches on the real clock is named
  (run_check._clock_elsewhere, _clock_message).

Misreported (these failed with a bare "wrong shape", naming nothing):
- er_forty_bins, hpm_notebook_sensor, gef_notebook_raw, ef_fixed_32_bins, rec_fixed_16_bins: a size the same on every input while the
  expected size changes is now named, with the sizes expected (across_calls.constant_size_hint; round 6's
  fixed_size_hint names only input #1's sizes).

Before this round's fixes all 10 wrong solutions failed the standard (5 passed the check, 5 failed with a bare
"wrong shape"), and all 10 correct alternatives passed, before and after.

Tried, and already named before this round (no test here): Events' fields sorted in place (named as a changed
input), event_rate's left edges for centres (its own hint), a stacked array or a generator for a tuple of outputs
("returned a ndarray, expected a tuple of 2 items").

Open, on purpose: dtypes the notebooks pass that no mistake tried here tells apart (offset_gradients and
chain_offsets get float32 frames, highpass_per_event int8 polarities and int32 coordinates, anchor_first_offset a
float32 L_t0; the references convert, and a learner's function that does not returns float32, which round 9 left
open); a torch 0-d tensor where a Python float is expected passes (notebook 09's later cells run with it).
"""
import math
import threading
import time

import numpy as np
import pytest
import torch

from evinr_lite.teaching import exercises
from evinr_lite.teaching.checking import learner_calls
from exercise_reports import assert_passes, case_ids as _id, quoted_counts, report as _report


def R(n): return exercises.reference(n)


# ---- total_variation: right on float32 only (notebook 05 passes float64)
def tv_eye_matrices(F):
    H, W = F.shape[-2:]
    Dx = torch.eye(W)[1:] - torch.eye(W)[:-1]                # [W - 1, W] forward differences, float32
    Dy = torch.eye(H)[1:] - torch.eye(H)[:-1]
    return (F @ Dx.T).abs().mean() + (Dy @ F).abs().mean()
def tv_conv_kernel(F):
    H, W = F.shape[-2:]
    x = F.reshape(-1, 1, H, W)
    dx = torch.nn.functional.conv2d(x, torch.tensor([[[[-1.0, 1.0]]]]))
    dy = torch.nn.functional.conv2d(x, torch.tensor([[[[-1.0], [1.0]]]]))
    return dx.abs().mean() + dy.abs().mean()


# ---- a time budget for an iterative solver
def ig_time_budget(gx, gy):
    gx, gy = np.asarray(gx, float), np.asarray(gy, float)
    L = np.zeros((gx.shape[0], gy.shape[1]))
    t0 = time.perf_counter()
    while time.perf_counter() - t0 < 0.2:                     # gradient descent for 0.2 s
        rx, ry = np.diff(L, axis=1) - gx, np.diff(L, axis=0) - gy
        g = np.zeros_like(L)
        g[:, 1:] += rx; g[:, :-1] -= rx; g[1:, :] += ry; g[:-1, :] -= ry
        L -= 0.2 * g
    return L - L.mean()
def hcf_time_budget(A, E, ridge):
    A, E = np.asarray(A, float), np.asarray(E, float)
    G, b = A.T @ A + ridge * np.eye(A.shape[1]), A.T @ E
    W, step = np.zeros((A.shape[1], E.shape[1])), 1.0 / np.linalg.norm(A.T @ A + ridge * np.eye(A.shape[1]), 2)
    t0 = time.time()
    while time.time() - t0 < 0.1:
        W -= step * (G @ W - b)
    return W
def ect_time_budget(log_changes, net_counts):
    d, n = np.asarray(log_changes, float), np.asarray(net_counts, float)
    if not np.any(n):
        return float("nan")
    C, step, t0 = 0.0, 1.0 / np.sum(n * n), time.monotonic()
    while time.monotonic() - t0 < 0.02:                       # gradient descent on sum (d - C n)^2
        C -= step * np.sum((C * n - d) * n)
    return float(C)


# ---- a size fixed in the code (not input #1's)
def er_forty_bins(t, bin_s):                                  # notebook 09 asks for span / 40
    counts, edges = np.histogram(np.asarray(t, float), bins=40)
    return (edges[:-1] + edges[1:]) / 2, counts / bin_s
SENSOR = (48, 64)                                             # a notebook's own sensor
def hpm_notebook_sensor(x, y, sensor_size, factor=10.0):
    counts = np.zeros(SENSOR, np.int64)
    np.add.at(counts, (y, x), 1)
    return counts > factor * np.median(counts[counts > 0])
RAW = (64, 96)                                                # notebook 10's raw size
def gef_notebook_raw(x, y, p, C, raw_size):
    return R("grey_event_frame")(x, y, p, C, RAW)
def ef_fixed_32_bins(events, boundaries, C):                  # notebook 02's b_fixed has 33 edges
    b = np.asarray(boundaries, float)
    H, W = events.sensor_size
    frames = np.zeros((32, H, W))
    i = np.searchsorted(b, events.t, side="left") - 1
    i[events.t == b[0]] = 0
    keep = (i >= 0) & (i < len(b) - 1)
    np.add.at(frames, (i[keep], events.y[keep], events.x[keep]), events.p[keep])
    return (C * frames).astype(np.float32)
def rec_fixed_16_bins(L_boundaries, C):                       # notebook 08 renders 17 boundaries, 16 bins
    L = np.asarray(L_boundaries, float)
    counts = np.zeros((16,) + L.shape[1:], np.int64)
    ref = L[0].copy()
    for k in range(min(16, len(L) - 1)):
        counts[k] = np.trunc((L[k + 1] - ref) / C)
        ref = ref + counts[k] * C
    return counts


# ---- correct alternatives
def tv_eye_like_input(F):
    H, W = F.shape[-2:]
    Dx = torch.eye(W, dtype=F.dtype)[1:] - torch.eye(W, dtype=F.dtype)[:-1]
    Dy = torch.eye(H, dtype=F.dtype)[1:] - torch.eye(H, dtype=F.dtype)[:-1]
    return (F @ Dx.T).abs().mean() + (Dy @ F).abs().mean()
def tv_kernel_like_input(F):
    H, W = F.shape[-2:]
    x = F.reshape(-1, 1, H, W)
    dx = torch.nn.functional.conv2d(x, F.new_tensor([[[[-1.0, 1.0]]]]))
    dy = torch.nn.functional.conv2d(x, F.new_tensor([[[[-1.0], [1.0]]]]))
    return dx.abs().mean() + dy.abs().mean()
def ig_timed_print(gx, gy):
    t0 = time.perf_counter()
    L = R("integrate_gradients")(gx, gy)
    print(f"solved in {1000 * (time.perf_counter() - t0):.1f} ms")
    return L
def hcf_tolerance(A, E, ridge):                               # conjugate gradients per column, stopped on a tolerance
    A, E = np.asarray(A, float), np.asarray(E, float)
    G, B = A.T @ A + ridge * np.eye(A.shape[1]), A.T @ E
    W = np.zeros_like(B)
    for j in range(B.shape[1]):
        w, r = np.zeros(G.shape[0]), B[:, j].copy()
        d = r.copy()
        for _ in range(10 * G.shape[0]):
            if np.linalg.norm(r) <= 1e-13 * max(np.linalg.norm(B[:, j]), 1e-300):
                break
            a = (r @ r) / (d @ G @ d)
            w, r_new = w + a * d, r - a * (G @ d)
            d, r = r_new + (r_new @ r_new) / (r @ r) * d, r_new
        W[:, j] = w
    return W
def ect_warns(log_changes, net_counts):                       # 0 / 0 warns and gives the documented NaN
    d, n = np.asarray(log_changes, float), np.asarray(net_counts, float)
    return float(np.sum(d * n) / np.sum(n * n))
def ii_zero_d(events):
    return np.array(R("interval_imbalance")(events))
def split_as_list(index, sensor_size):
    return list(R("split_index")(index, sensor_size))
def er_bins_from_arguments(t, bin_s):
    t = np.asarray(t, float)
    B = max(math.ceil((t[-1] - t[0]) / bin_s), 1)
    edges = t[0] + bin_s * np.arange(B + 1)
    k = np.clip(np.searchsorted(edges, t, side="left") - 1, 0, B - 1)
    return (edges[:-1] + edges[1:]) / 2, np.bincount(k, minlength=B) / bin_s
def hpm_bincount(x, y, sensor_size, factor=10.0):
    H, W = sensor_size
    counts = np.bincount(np.asarray(y) * W + np.asarray(x), minlength=H * W).reshape(H, W)
    return counts > factor * np.median(counts[counts > 0])


DTYPE_HOLES = [
    ("total_variation", tv_eye_matrices, "expected m1 and m2 to have the same dtype"),
    ("total_variation", tv_conv_kernel, "expected scalar type Double but found Float"),
]
CLOCK_HOLES = [
    ("integrate_gradients", ig_time_budget, "time.perf_counter()"),
    ("head_closed_form", hcf_time_budget, "time.time()"),
    ("estimate_contrast_threshold", ect_time_budget, "time.monotonic()"),
]
SIZES = " on every input, while the expected "
FIXED_SIZES = [
    ("event_rate", er_forty_bins, "output [0] has 40 entries along axis 0" + SIZES + "number changes with the "
                                  "arguments (1, 4, 8, 10)"),
    ("hot_pixel_mask", hpm_notebook_sensor, "the result's shape is (48, 64)" + SIZES + "shape changes"),
    ("grey_event_frame", gef_notebook_raw, "the result's shape is (16, 24)" + SIZES + "shape changes"),
    ("events_to_frames_fixed", ef_fixed_32_bins, "the result has 32 entries along axis 0" + SIZES + "number changes "
                                                 "with the arguments (2, 4, 5)"),
    ("render_event_counts", rec_fixed_16_bins, "the result has 16 entries along axis 0" + SIZES + "number changes "
                                               "with the arguments (4, 5, 6)"),
]
CORRECT = [
    ("total_variation", tv_eye_like_input), ("total_variation", tv_kernel_like_input),
    ("integrate_gradients", ig_timed_print), ("head_closed_form", hcf_tolerance),
    ("estimate_contrast_threshold", ect_warns), ("interval_imbalance", ii_zero_d), ("split_index", split_as_list),
    ("event_rate", er_bins_from_arguments), ("hot_pixel_mask", hpm_bincount), ("total_variation", R("total_variation")),
]


@pytest.mark.parametrize("name, wrong, words", DTYPE_HOLES, ids=_id(DTYPE_HOLES))
def test_a_tensor_made_float32_inside_fails_on_the_notebook_s_float64(name, wrong, words):
    ok, text = _report(name, wrong)
    assert not ok and "Traceback" not in text, text
    assert "raised RuntimeError on input #3 of 3 (F=tensor float64[1, 6, 9])" in text and words in text, text
    assert "hint: torch does not mix float32 and float64 tensors in one operation" in text, text
    assert "`F` is a float64 tensor on this input" in text and "`torch.eye(n, dtype=F.dtype)`" in text, text


@pytest.mark.parametrize("name, wrong, words", CLOCK_HOLES, ids=_id(CLOCK_HOLES))
def test_a_result_that_depends_on_the_clock_is_named(name, wrong, words):
    ok, text = _report(name, wrong)
    assert not ok and "Traceback" not in text, text
    assert "gives another result when the clock runs faster (input #" in text, text
    assert f"its result depends on the time it reads ({words})" in text, text
    assert "keeps state between calls" not in text, text
    assert time.perf_counter.__module__ == "time" and time.time.__module__ == "time"      # the clocks put back


@pytest.mark.parametrize("name, wrong, words", FIXED_SIZES, ids=_id(FIXED_SIZES))
def test_a_size_fixed_in_the_code_is_named(name, wrong, words):
    ok, text = _report(name, wrong)
    assert not ok and "Traceback" not in text, text
    assert "wrong shape" in text and "hint: " + words in text, text
    assert "a size fixed in the code, or read from a notebook variable" in text, text


@pytest.mark.parametrize("name, fn", CORRECT, ids=_id(CORRECT))
def test_correct_alternatives_pass(name, fn):
    assert_passes(name, fn)


def test_the_third_total_variation_input_is_float64_and_the_counts_stand():
    cases = exercises.get("total_variation").cases()
    assert [kw["F"].dtype for _, kw in cases] == [torch.float32, torch.float32, torch.float64]
    assert all(kw["F"].requires_grad for _, kw in cases)
    F = cases[2][1]["F"]
    assert torch.equal(F.detach(), F.detach().float().double())          # float32 values, made float64
    for name, n in quoted_counts().items():
        assert len(exercises.get(name).cases()) == n, name


def test_the_fast_clock_moves_only_the_learner_s_reads_and_is_put_back():
    """Inside the block a read from this file (the learner's side) moves an hour ahead each time; a name bound
    with `from time import perf_counter` moves too; another thread's read (a notebook kernel's output thread) stays
    real; after it, every clock is the time module's own again."""
    originals = {name: getattr(time, name) for name in ("time", "perf_counter", "monotonic")}

    def fn():
        return None
    fn.__globals__["_r17_bound_clock"] = time.perf_counter
    try:
        with learner_calls.fast_clock(fn) as reads:
            a = time.perf_counter()
            b = time.perf_counter()
            c = fn.__globals__["_r17_bound_clock"]()
            seen = []
            other = threading.Thread(target=lambda: seen.append(time.monotonic()))   # another thread: real
            other.start(); other.join()
        assert b - a >= learner_calls.CLOCK_STEP_S and c - b >= learner_calls.CLOCK_STEP_S
        assert reads == ["perf_counter"] * 3 and abs(seen[0] - time.monotonic()) < 60
        assert fn.__globals__["_r17_bound_clock"] is originals["perf_counter"]
        assert all(getattr(time, name) is clock for name, clock in originals.items())
    finally:
        del fn.__globals__["_r17_bound_clock"]


def test_a_clock_read_only_for_a_print_is_not_blamed(capsys):
    assert_passes("integrate_gradients", ig_timed_print)


def test_this_round_counts():
    wrong = DTYPE_HOLES + CLOCK_HOLES + FIXED_SIZES
    assert (len(DTYPE_HOLES), len(CLOCK_HOLES), len(FIXED_SIZES), len(CORRECT)) == (2, 3, 5, 10)
    assert len(wrong) == 10 and len({r[0] for r in wrong}) == 9
    assert len({r[0] for r in CORRECT}) == 8
