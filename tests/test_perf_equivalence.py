"""The optimised paths compute what the plain reference paths compute, up to float rounding.

Each fast path (binning through grouped np.bincount, chunked binning, the fused output layer +
losses, the fused Adam kernel, batched ensembles) is checked against a deliberately simple
implementation of the same thing. Speed itself is measured by benchmarks/, never here.
"""
import numpy as np
import pytest
import torch

from evinr_lite import Events
from evinr_lite.method import binning, fused as fused_kernel
from evinr_lite.method.binning import events_to_frames, events_to_frames_chunked
from evinr_lite.method.fused import head_losses
from evinr_lite.method.losses import (temporal_loss_derivative, temporal_loss_difference, tikhonov, total_variation)
from evinr_lite.method.models import FrameINR
from evinr_lite.method.solver import EvINRConfig, predict_networks, split_windows, train_frame_inr


# ---- binning --------------------------------------------------------------------------------

def reference_frames(events, b, C):
    """The definition, one event at a time through np.add.at: bin i holds b[i] < t <= b[i+1]."""
    H, W = events.sensor_size
    frames = np.zeros((len(b) - 1, H, W))
    counts = np.zeros(len(b) - 1, np.int64)
    inside = (events.t >= b[0]) & (events.t <= b[-1])
    i = np.maximum(np.searchsorted(b, events.t[inside], side="left") - 1, 0)
    np.add.at(frames, (i, events.y[inside], events.x[inside]), events.p[inside].astype(np.float64))
    np.add.at(counts, i, 1)
    return (C * frames).astype(np.float32), counts


def random_events_with_ties(rng, n, size, b):
    """Random events, a third of them exactly on bin edges, some before b[0] and after b[-1]."""
    H, W = size
    t = rng.uniform(b[0] - 0.1, b[-1] + 0.1, n)
    on_edge = rng.random(n) < 1 / 3
    t[on_edge] = rng.choice(b, on_edge.sum())
    t = np.sort(t)
    p = rng.choice(np.array([-1, 1], np.int8), n)
    return Events(t, rng.integers(0, W, n), rng.integers(0, H, n), p, size)


@pytest.mark.parametrize("size, group_cells", [((7, 9), 1 << 16), ((7, 9), 200), ((7, 9), 1), ((30, 40), 1 << 16)])
def test_events_to_frames_equals_add_at_reference(monkeypatch, size, group_cells):
    # group_cells changes how many bins one np.bincount call covers (many, a few, one)
    monkeypatch.setattr(binning, "_GROUP_CELLS", group_cells)
    rng = np.random.default_rng(1)
    b = np.sort(rng.uniform(0, 1, 12))
    b = np.concatenate([b[:4], [b[4] + 1e-12], b[5:]])       # a very short bin too
    events = random_events_with_ties(rng, 5000, size, b)
    ef = events_to_frames(events, b, C=0.3)
    frames, counts = reference_frames(events, b, 0.3)
    np.testing.assert_array_equal(ef.frames, frames)
    np.testing.assert_array_equal(ef.counts, counts)
    assert ef.frames.dtype == np.float32 and ef.frames.shape == (len(b) - 1, *size)


def test_events_to_frames_empty_bins_and_no_events_inside():
    rng = np.random.default_rng(2)
    events = random_events_with_ties(rng, 300, (4, 5), np.array([0.0, 1.0]))
    b = np.array([0.2, 0.2000001, 0.3, 5.0])
    np.testing.assert_array_equal(events_to_frames(events, b).frames, reference_frames(events, b, 1.0)[0])
    outside = events_to_frames(events, np.array([10.0, 11.0]))
    assert outside.counts.tolist() == [0] and not outside.frames.any()


@pytest.mark.parametrize("chunk", [1, 7, 250, 10_000])
def test_chunked_binning_is_bit_identical(chunk):
    rng = np.random.default_rng(3)
    b = np.linspace(0, 1, 9)
    events = random_events_with_ties(rng, 2000, (6, 8), b)
    whole = events_to_frames(events, b, C=0.2)
    chunks = [events.take(slice(i, i + chunk)) for i in range(0, len(events), chunk)]
    chunks.insert(1, events.take(slice(0, 0)))                  # an empty chunk is fine
    parts = events_to_frames_chunked(iter(chunks), b, C=0.2)
    np.testing.assert_array_equal(parts.frames, whole.frames)
    np.testing.assert_array_equal(parts.counts, whole.counts)


def test_chunked_binning_rejects_chunks_out_of_order_and_needs_a_size():
    rng = np.random.default_rng(4)
    events = random_events_with_ties(rng, 100, (3, 4), np.array([0.0, 1.0]))
    halves = [events.take(slice(50, 100)), events.take(slice(0, 50))]
    with pytest.raises(ValueError, match="time order"):
        events_to_frames_chunked(halves, [0.0, 0.5, 1.0])
    with pytest.raises(ValueError, match="sensor_size"):
        events_to_frames_chunked([], [0.0, 1.0])
    empty = events_to_frames_chunked([], [0.0, 1.0], sensor_size=(3, 4))
    assert empty.frames.shape == (1, 3, 4) and not empty.frames.any()


# ---- the network and its losses -----------------------------------------------------------------

def plain_frame_inr(model, t):
    """FrameINR written as a loop over networks with torch.nn.functional.linear (no batching)."""
    out = []
    for k in range(model.n_models):
        tau = model.normalize_time(t)[k][:, None]                               # [T, 1] in network k's window
        h = torch.sin(model.first_omega_0 * (tau * model.weights[0][k] + model.biases[0][k]))
        for w, b in zip(model.weights[1:], model.biases[1:]):
            h = torch.sin(model.omega_0 * torch.nn.functional.linear(h, w[k].T, b[k][0]))
        out.append(torch.nn.functional.linear(h, model.head_weight[k].T, model.head_bias[k][0]))
    return torch.stack(out).reshape(model.n_models, t.shape[1], *model.sensor_size)


def test_batched_frame_inr_equals_a_plain_loop_over_networks():
    model = FrameINR((5, 6), [[0.0, 1.0], [0.8, 2.0], [1.8, 3.0]], 32, 2, seed=1)
    t = torch.tensor([[0.1, 0.5, 0.9], [0.9, 1.2, 2.0], [1.8, 2.5, 3.0]], dtype=torch.float64)
    torch.testing.assert_close(model(t), plain_frame_inr(model, t), rtol=1e-5, atol=1e-6)
    F, _ = model.forward_with_derivative(t)
    torch.testing.assert_close(F, plain_frame_inr(model, t), rtol=1e-5, atol=1e-6)
    single = model.network(1)
    torch.testing.assert_close(single(t[1:2]), model(t)[1:2])


@pytest.mark.parametrize("temporal", ["derivative", "difference"])
@pytest.mark.parametrize("regularizer", ["tikhonov", "tv", "none"])
@pytest.mark.parametrize("chunk_cells", [1 << 20, 500, 130, 1])   # all at once; per network; 2 frames; 1 frame
def test_fused_head_losses_equal_the_readable_losses(monkeypatch, temporal, regularizer, chunk_cells):
    monkeypatch.setattr(fused_kernel, "_CHUNK_CELLS", chunk_cells)
    torch.manual_seed(0)
    H, W, B = 7, 9, 5
    model = FrameINR((H, W), [[0.0, 1.0], [0.8, 2.0]], 32, 2, omega_0=30.0, first_omega_0=10.0, seed=2)
    frames = torch.randn(2, B, H, W)
    durations = torch.rand(2, B) * 0.1
    n_times = B if temporal == "derivative" else B + 1
    t = torch.sort(torch.rand(2, n_times, dtype=torch.float64), dim=1).values * 0.8
    t += torch.tensor([[0.1], [1.0]], dtype=torch.float64)
    regularize = {"tikhonov": tikhonov, "tv": total_variation, "none": lambda F: F.new_zeros(())}[regularizer]

    def grads(loss):
        model.zero_grad(set_to_none=True)
        loss.backward()
        return {n: (p.grad if p.grad is not None else torch.zeros_like(p)) for n, p in model.named_parameters()}

    if temporal == "derivative":
        F, dF = model.forward_with_derivative(t)
        ref = (temporal_loss_derivative(dF, frames, durations), regularize(F))
    else:
        F = model(t)
        ref = (temporal_loss_difference(F, frames), regularize(F))
    g_ref = grads(ref[0] + 0.3 * ref[1])
    h, dh = model.features(t, with_derivative=temporal == "derivative")
    fused = head_losses(h, dh, model.head_weight, model.head_bias, frames,
                        durations if temporal == "derivative" else None, regularizer)
    g_fused = grads(fused[0] + 0.3 * fused[1])
    for a, b in zip(fused, ref):
        torch.testing.assert_close(a, b.float(), rtol=1e-5, atol=1e-7)
    for name in g_ref:   # relative to the largest gradient (some are 0 up to rounding, e.g. the bias here)
        scale = max(g_ref[name].abs().max(), 0.05 * max(g.abs().max() for g in g_ref.values()))
        torch.testing.assert_close(g_fused[name] / scale, g_ref[name] / scale, rtol=0, atol=1e-5, msg=name)
    assert g_ref["head_weight"].abs().max() > 0


def test_reused_buffers_give_the_same_losses_and_gradients():
    model = FrameINR((5, 7), [[0.0, 1.0]], 16, 1, seed=5)
    frames, durations = torch.randn(1, 4, 5, 7), torch.full((1, 4), 0.25)
    t = torch.tensor([[0.125, 0.375, 0.625, 0.875]], dtype=torch.float64)
    buffers, results = {}, []
    for use in (None, buffers, buffers, None):               # fresh, then the same buffers twice, fresh again
        model.zero_grad(set_to_none=True)
        h, dh = model.features(t, with_derivative=True)
        temporal, reg = head_losses(h, dh, model.head_weight, model.head_bias, frames, durations, "tikhonov", use)
        (temporal + reg).backward()
        results.append((temporal.item(), reg.item(), model.head_weight.grad.clone(), model.weights[1].grad.clone()))
    assert len(buffers) == 2                                   # out and g_out
    for other in results[1:]:
        assert other[:2] == results[0][:2]
        torch.testing.assert_close(other[2], results[0][2], rtol=0, atol=0)
        torch.testing.assert_close(other[3], results[0][3], rtol=0, atol=0)


def test_head_losses_reject_bad_arguments():
    h = torch.zeros(1, 2, 4)
    with pytest.raises(ValueError, match="regularizer"):
        head_losses(h, h, torch.zeros(1, 4, 6), torch.zeros(1, 1, 6), torch.zeros(1, 2, 2, 3), torch.ones(1, 2), "l1")
    with pytest.raises(ValueError, match="durations"):
        head_losses(h, h, torch.zeros(1, 4, 6), torch.zeros(1, 1, 6), torch.zeros(1, 2, 2, 3))


# ---- training: fast path versus reference path, batched versus sequential --------------------------

@pytest.fixture(scope="module")
def small_events():
    rng = np.random.default_rng(5)
    n, H, W = 6000, 6, 8
    # a bright blob sweeping right: structured enough that training moves the weights
    t = np.sort(rng.uniform(0, 2.0, n))
    x = np.clip((t / 2.0 * W + rng.normal(0, 1, n)).astype(int), 0, W - 1)
    y = rng.integers(0, H, n)
    p = np.where(rng.random(n) < 0.7, 1, -1).astype(np.int8)
    return Events(t, x, y, p, (H, W))


def _cfg(**kw):
    return EvINRConfig.v0_1(**{"C": 0.2, "hidden_features": 32, "hidden_layers": 2, "n_iters": 24, "c2f_iters": (8, 16),
                          "lr": 1e-3, "bin_duration": 0.1, "progress": False, "device": "cpu", **kw})


# TV is left to the one-step gradient test above: sign(dF/dx) of a difference that is 0 up to rounding
# flips with the rounding, and training amplifies such flips.
@pytest.mark.parametrize("kw", [{}, {"temporal_loss": "difference"}, {"regularizer": "none", "coarse_to_fine": False}])
def test_fast_training_equals_reference_training(small_events, kw):
    cfg = _cfg(**kw)
    windows = split_windows(0.0, 2.0, 1.1, 0.2)
    fast, h_fast = train_frame_inr(small_events, windows, cfg, fast=True)
    ref, h_ref = train_frame_inr(small_events, windows, cfg, fast=False)
    times = np.linspace(0.05, 1.0, 7)
    a, b = predict_networks(fast, times), predict_networks(ref, times)
    init = predict_networks(FrameINR((6, 8), windows, 32, 2, 30.0, 10.0, seed=0), times)
    assert np.abs(b - init).max() > 0.05                      # training moved the predictions ...
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-4 * np.abs(b).max())   # ... the same way both paths
    np.testing.assert_allclose(h_fast["loss"], h_ref["loss"], rtol=1e-4)


def test_batched_ensemble_equals_networks_trained_one_after_another(small_events):
    cfg = _cfg(temporal_loss="difference")
    windows = split_windows(0.0, 2.0, 0.75, 0.1)
    assert len(windows) == 3
    init = FrameINR((6, 8), windows, cfg.hidden_features, cfg.hidden_layers, cfg.omega_0, cfg.first_omega_0, seed=3)
    singles = [init.network(k) for k in range(len(windows))]           # copies of the initial weights
    before = [predict_networks(s, np.linspace(*windows[k], 5))[0] for k, s in enumerate(singles)]
    batched, _ = train_frame_inr(small_events, windows, cfg, model=init)
    for k, single in enumerate(singles):
        train_frame_inr(small_events, windows[k:k + 1], cfg, model=single)
        tk = np.linspace(*windows[k], 5)
        a, b = predict_networks(batched, tk)[k], predict_networks(single, tk)[0]
        assert np.abs(b - before[k]).max() > 0.05
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-4 * np.abs(b).max())


def test_train_frame_inr_checks_the_model_matches_the_windows(small_events):
    model = FrameINR((6, 8), [[0.0, 2.0]], 16, 1)
    with pytest.raises(ValueError, match="windows"):
        train_frame_inr(small_events, split_windows(0.0, 2.0, 1.1, 0.2), _cfg(), model=model)


def test_query_written_in_place_equals_the_plain_forward():
    model = FrameINR((9, 11), [[0.0, 1.0]], 32, 2, seed=4)
    times = np.linspace(0.0, 1.0, 300)                       # two batches of 256 and 44
    with torch.no_grad():
        plain = torch.cat([model(torch.as_tensor(times[i:i + 256])[None]) for i in (0, 256)], dim=1).numpy()
    np.testing.assert_array_equal(predict_networks(model, times), plain)
    two = FrameINR((9, 11), [[0.0, 1.0], [0.5, 1.5]], 32, 2, seed=4)          # N > 1 takes the copying path
    with torch.no_grad():
        expected = two(torch.as_tensor(times[:40]).expand(2, -1)).numpy()
    np.testing.assert_array_equal(predict_networks(two, times[:40]), expected)
