"""The closed-form output layer, the explicit per-pixel offset, and the named presets."""
import numpy as np
import pytest
import scipy.fft
import scipy.ndimage
import torch

from evinr_lite import EvINRConfig, make_scene, reconstruct, simulate_scene
from evinr_lite.method.head_solve import laplacian_eigenvalues, solve_head
from evinr_lite.method.models import FrameINR
from evinr_lite.method.offset import median_gradient_offset, poisson_integrate
from evinr_lite.method.solver import alignment_offsets
from evinr_lite.method.training import _Bins, step_losses


def _differences(n):
    D = np.zeros((n - 1, n))
    D[np.arange(n - 1), np.arange(n - 1)] = -1
    D[np.arange(n - 1), np.arange(1, n)] = 1
    return D


def test_laplacian_eigenvalues_diagonalise_the_grid_laplacian():
    H, W = 5, 7
    Dx = np.kron(np.eye(H), _differences(W))          # x differences of a row-major image
    Dy = np.kron(_differences(H), np.eye(W))
    L = 0.3 * Dx.T @ Dx + 1.7 * Dy.T @ Dy
    basis = scipy.fft.dctn(np.eye(H * W).reshape(H * W, H, W), norm="ortho", axes=(1, 2)).reshape(H * W, H * W)
    M = basis.T @ L @ basis                            # L in the orthonormal DCT-II basis (rows: DCT of e_i)
    np.testing.assert_allclose(np.diag(M), laplacian_eigenvalues((H, W), 0.3, 1.7).ravel(), atol=1e-10)
    np.testing.assert_allclose(M - np.diag(np.diag(M)), 0, atol=1e-10)


def _setup(temporal_loss, seed=0):
    scene = make_scene("camera", sensor_size=(12, 16), duration=0.6)
    events = simulate_scene(scene, 0.0, 0.6, C=0.2, seed=seed)
    windows = np.array([[0.0, 0.6]])
    model = FrameINR((12, 16), windows, hidden_features=48, hidden_layers=2, first_omega_0=10.0, seed=seed)
    bins = _Bins.build(events, [np.linspace(0.0, 0.6, 21)], 0.2, torch.device("cpu"))
    return model, bins


@pytest.mark.parametrize("temporal_loss", ["difference", "derivative"])
@pytest.mark.parametrize("lam", [0.0, 0.05])
def test_solved_head_is_a_stationary_point_of_the_training_loss(temporal_loss, lam):
    model, bins = _setup(temporal_loss)

    def loss_and_grad():
        model.zero_grad()
        temporal, reg = step_losses(model, bins, temporal_loss, "tikhonov", fused=False)
        loss = temporal + lam * reg
        loss.backward()
        return loss.item(), model.head_weight.grad.norm().item()

    _, grad_before = loss_and_grad()                  # the initial (SIREN) head
    solve_head(model, bins.boundaries, bins.frames, temporal_loss, "tikhonov", lam)
    loss, grad_after = loss_and_grad()
    assert grad_after < 1e-3 * grad_before
    temporal, reg = step_losses(model, bins, temporal_loss, "tikhonov", fused=False)
    # and Adam cannot improve on it: a few steps on the head only raise the loss or leave it
    best = float(temporal + lam * reg)
    assert best == pytest.approx(loss, rel=1e-6)
    opt = torch.optim.Adam([model.head_weight], lr=1e-4)
    for _ in range(5):
        opt.zero_grad()
        t, r = step_losses(model, bins, temporal_loss, "tikhonov", fused=False)
        (t + lam * r).backward()
        opt.step()
    t, r = step_losses(model, bins, temporal_loss, "tikhonov", fused=False)
    assert float(t + lam * r) >= best * (1 - 1e-4)


def test_without_regularizer_the_difference_loss_is_fitted_exactly_and_frames_have_zero_temporal_mean():
    model, bins = _setup("difference")
    out = solve_head(model, bins.boundaries, bins.frames, "difference", "none", 0.0)
    assert out["temporal"] < 1e-6 * float((bins.frames ** 2).mean())
    with torch.no_grad():
        F = model(bins.boundaries)
    np.testing.assert_allclose(F.mean(dim=1).numpy(), 0, atol=1e-4)


def test_head_solve_refuses_tv():
    model, bins = _setup("difference")
    with pytest.raises(ValueError, match="tikhonov"):
        solve_head(model, bins.boundaries, bins.frames, "difference", "tv", 0.05)
    with pytest.raises(ValueError, match="head_solve"):
        EvINRConfig(regularizer="tv")


def test_poisson_integrate_recovers_an_image_from_its_gradients():
    g = np.random.default_rng(0).normal(size=(9, 13))
    got = poisson_integrate(np.diff(g, axis=1), np.diff(g, axis=0))
    np.testing.assert_allclose(got, g - g.mean(), atol=1e-10)


def test_median_gradient_offset_removes_an_unknown_offset_of_a_moving_texture():
    """Frames of a translating texture plus one unknown image g0: the solve returns about -g0."""
    rng = np.random.default_rng(1)
    texture = scipy.ndimage.gaussian_filter(rng.normal(size=(40, 200)), 1.0)
    frames = np.stack([texture[:, 4 * k: 4 * k + 48] for k in range(30)])        # moving 4 px per frame
    g0 = scipy.ndimage.gaussian_filter(rng.normal(size=(40, 48)), 3.0) * 5
    g = median_gradient_offset(frames + g0)
    err_before = np.std((frames + g0) - frames - g0.mean())
    err_after = np.std((frames + g0 + g) - frames - (g0 + g).mean())
    assert err_after < 0.2 * err_before


def test_ensembles_keep_their_alignment_with_the_offset_solve():
    scene = make_scene("camera", sensor_size=(16, 20), duration=1.6)
    events = simulate_scene(scene, 0.0, 1.6, C=0.2, seed=0)
    cfg = EvINRConfig(C=0.2, hidden_features=32, hidden_layers=2, tau=0.9, overlap=0.2, progress=False)
    rec = reconstruct(events, np.linspace(0.1, 1.5, 5), cfg)
    assert len(rec.windows) == 2
    chained = alignment_offsets(rec.model, rec.windows)
    np.testing.assert_allclose(rec.offsets[1] - rec.offsets[0], chained[1] - chained[0], atol=1e-5)


def test_presets():
    paper = EvINRConfig.paper()
    assert (paper.hidden_features, paper.hidden_layers, paper.n_iters, paper.lam, paper.lr) == (512, 3, 300, 0.05, 1e-4)
    assert (paper.temporal_loss, paper.regularizer, paper.head_lr_scale, paper.first_omega_0) == (
        "derivative", "tikhonov", 1.0, None)
    assert paper.c2f_iters == (100, 200) and paper.coarse_to_fine and not paper.head_solve
    assert paper.offset_solve == "none" and paper.bin_duration == 1 / 32 and paper.tau == 5.0
    old = EvINRConfig.v0_1()
    assert (old.first_omega_0, old.head_lr_scale) == (10.0, 30.0)
    assert {k: v for k, v in vars(old).items() if k not in ("first_omega_0", "head_lr_scale")} == \
        {k: v for k, v in vars(paper).items() if k not in ("first_omega_0", "head_lr_scale")}
    kit = EvINRConfig()
    assert kit.head_solve and kit.offset_solve == "l1_gradient" and kit.n_iters == 0
    assert EvINRConfig.paper(C=0.2).C == 0.2


def test_kit_default_beats_integration_on_a_small_scene():
    """The default's job in miniature: better than direct integration under both protocols."""
    from evinr_lite import reconstruct_baseline
    from evinr_lite.evaluation import score_sequence

    scene = make_scene("camera", sensor_size=(48, 64), duration=1.0)
    events = simulate_scene(scene, 0.0, 1.0, C=0.2, seed=0)
    times = np.linspace(0.1, 0.9, 5)
    gt = scene.intensity(times)
    kit = reconstruct(events, times, EvINRConfig(C=0.2, progress=False)).frames
    base = reconstruct_baseline(events, times, "integration", C=0.2).frames
    for eq in ("none", "clahe"):
        a = score_sequence(kit, times, gt, times, eq, lpips_model=False)["ssim"]
        b = score_sequence(base, times, gt, times, eq, lpips_model=False)["ssim"]
        assert a > b, (eq, a, b)


def test_short_windows_get_at_least_min_bins():
    scene = make_scene("camera", sensor_size=(12, 16), duration=0.5)
    events = simulate_scene(scene, 0.0, 0.5, C=0.2, seed=0)
    cfg = EvINRConfig(C=0.2, hidden_features=32, hidden_layers=1, progress=False)
    assert reconstruct(events, [0.25], cfg).history["final_bins"] == cfg.min_bins == 64
    paper = EvINRConfig.paper(C=0.2, hidden_features=16, n_iters=3, c2f_iters=(1, 2), progress=False)
    assert reconstruct(events, [0.25], paper).history["final_bins"] == 16      # 0.5 s at 1/32 s


def test_the_same_numbers_on_one_thread_and_on_two(monkeypatch):
    """The solve's DCTs (scipy workers) and the offset's medians (a thread per row block) follow the
    kit's torch thread count; splitting the work must not change a single number."""
    import evinr_lite.method.offset as offset

    scene = make_scene("camera", sensor_size=(40, 56), duration=1.0)
    events = simulate_scene(scene, 0.0, 1.0, C=0.2, seed=0)
    cfg = EvINRConfig(C=0.2, hidden_features=32, progress=False)
    before = torch.get_num_threads()
    try:
        torch.set_num_threads(1)
        one = reconstruct(events, [0.2, 0.7], cfg).log_intensity
        torch.set_num_threads(2)
        # [64, 100, 1024]: 32 rows per block of about 2 M cells, so four blocks on two threads
        rows = np.random.default_rng(0).standard_normal((64, 100, 1024), dtype=np.float32)
        monkeypatch.setattr(offset, "cpu_threads", lambda: 1)
        serial = median_gradient_offset(rows)
        monkeypatch.setattr(offset, "cpu_threads", lambda: 2)
        np.testing.assert_array_equal(median_gradient_offset(rows), serial)
        two = reconstruct(events, [0.2, 0.7], cfg).log_intensity
    finally:
        torch.set_num_threads(before)
    np.testing.assert_array_equal(one, two)


def test_no_optimizer_is_built_when_nothing_is_trained(monkeypatch):
    """n_iters=0 (the kit's default) solves the head without building Adam (about 1 s of torch's lazy
    imports on first use); a recipe that trains still builds it."""
    import evinr_lite.method.training as training

    built = []
    real = training.make_adam
    monkeypatch.setattr(training, "make_adam", lambda *a, **k: built.append(1) or real(*a, **k))
    scene = make_scene("camera", sensor_size=(12, 16), duration=0.5)
    events = simulate_scene(scene, 0.0, 0.5, C=0.2, seed=0)
    reconstruct(events, [0.25], EvINRConfig(C=0.2, hidden_features=16, progress=False))
    assert built == []
    reconstruct(events, [0.25], EvINRConfig(C=0.2, hidden_features=16, n_iters=2, progress=False))
    assert built == [1]


@pytest.mark.parametrize("lam", [0.01, 0.3])
def test_the_second_order_head_is_the_optimum_of_the_laplacian_penalty(lam):
    """spatial_order=2: the solve minimises |A W - E|^2 + sum_t |M f_t|^2 / mu_ref, with M = cx Dx^T Dx + cy Dy^T Dy
    (the weighted grid Laplacian) and f_t the frames at the bin edges (their mean over time removed), written
    out here with explicit matrices on a 12 x 16 sensor: its gradient vanishes at the solved head, and order 1
    and order 2 agree at the reference frequency (penalty_spectrum)."""
    from evinr_lite.method.head_solve import ORDER_REFERENCE, _weights, penalty_spectrum

    model, bins = _setup("difference")
    H, W = 12, 16
    B = bins.frames.shape[1]
    solve_head(model, bins.boundaries, bins.frames, "difference", "tikhonov", lam, order=2)
    with torch.no_grad():
        h, _ = model.features(bins.boundaries, dtype=torch.float64)
    h = h[0].detach()
    A, hc = h[1:] - h[:-1], h - h.mean(dim=0, keepdim=True)
    cx, cy = _weights(B, B + 1, (H, W), lam)
    Dx = torch.tensor(np.kron(np.eye(H), _differences(W)))
    Dy = torch.tensor(np.kron(_differences(H), np.eye(W)))
    M = cx * Dx.T @ Dx + cy * Dy.T @ Dy
    ref = (cx + cy) * (2 - 2 * np.cos(np.pi * ORDER_REFERENCE))
    E = bins.frames[0].reshape(B, H * W).double()

    def grad(Wt):
        Wt = Wt.clone().requires_grad_(True)
        F = hc @ Wt
        J = ((A @ Wt - E) ** 2).sum() + ((F @ M.T) ** 2).sum() / ref
        J.backward()
        return Wt.grad.norm().item()

    solved = model.head_weight.detach()[0].double()
    assert grad(solved) < 1e-4 * grad(torch.zeros_like(solved))
    mu = laplacian_eigenvalues((H, W), cx, cy)
    at = np.argmin(np.abs(mu - ref))
    assert penalty_spectrum(mu, cx, cy, 2).flat[at] == pytest.approx(mu.flat[at], rel=0.2)
    with pytest.raises(ValueError, match="order must be 1"):
        penalty_spectrum(mu, cx, cy, 3)


def test_the_banded_head_is_the_optimum_of_its_spectral_penalty():
    """spatial_order="banded": the solve minimises |A W - E|^2 + sum_t f_t^T C^T diag(w) C f_t, with C the orthonormal
    2-D DCT-II written out as a matrix on a 12 x 16 sensor and w = mu up to mu_ref, mu^3 / mu_ref^2 beyond; its
    gradient vanishes at the solved head, and not at the order-2 head. The spectrum is continuous at mu_ref."""
    import scipy.fft

    from evinr_lite.method.head_solve import ORDER_REFERENCE, _weights, penalty_spectrum

    lam = 0.1
    model, bins = _setup("difference")
    H, W = 12, 16
    B = bins.frames.shape[1]
    with torch.no_grad():
        h, _ = model.features(bins.boundaries, dtype=torch.float64)
    h = h[0].detach()
    A, hc = h[1:] - h[:-1], h - h.mean(dim=0, keepdim=True)
    cx, cy = _weights(B, B + 1, (H, W), lam)
    mu = laplacian_eigenvalues((H, W), cx, cy)
    w = penalty_spectrum(mu, cx, cy, "banded").ravel()
    C = scipy.fft.dctn(np.eye(H * W).reshape(H * W, H, W), type=2, norm="ortho", axes=(1, 2)).reshape(H * W, H * W).T
    Pen = torch.tensor(C.T @ np.diag(w) @ C)
    E = bins.frames[0].reshape(B, H * W).double()

    def grad(Wt):
        Wt = Wt.clone().requires_grad_(True)
        F = hc @ Wt
        J = ((A @ Wt - E) ** 2).sum() + (F * (F @ Pen)).sum()
        J.backward()
        return Wt.grad.norm().item()

    solve_head(model, bins.boundaries, bins.frames, "difference", "tikhonov", lam, order="banded")
    banded = model.head_weight.detach()[0].double().clone()
    solve_head(model, bins.boundaries, bins.frames, "difference", "tikhonov", lam, order=2)
    second = model.head_weight.detach()[0].double().clone()
    scale = grad(torch.zeros_like(banded))
    assert grad(banded) < 1e-4 * scale
    assert grad(second) > 1e-2 * scale
    ref = (cx + cy) * (2 - 2 * np.cos(np.pi * ORDER_REFERENCE))
    below, above = mu[mu <= ref], mu[mu > ref]
    np.testing.assert_allclose(penalty_spectrum(below, cx, cy, "banded"), below)
    assert np.all(penalty_spectrum(above, cx, cy, "banded") > above)
    assert penalty_spectrum(np.array([ref * (1 + 1e-9)]), cx, cy, "banded")[0] == pytest.approx(ref, rel=1e-6)


def test_spatial_order_is_checked_and_the_papers_recipes_keep_order_one():
    from evinr_lite import EventDataError

    assert EvINRConfig().spatial_order == "banded"
    assert EvINRConfig.paper().spatial_order == EvINRConfig.v0_1().spatial_order == 1
    assert EvINRConfig(spatial_order=2).spatial_order == 2
    for bad in (0, 3, 1.5, True, "2", "band"):
        with pytest.raises(EventDataError, match="spatial_order"):
            EvINRConfig(spatial_order=bad)


@pytest.mark.parametrize("alpha", [0.25, 1.0])
def test_the_head_with_a_time_order_is_the_optimum_of_its_penalty(alpha):
    """time_order=alpha: the solve minimises |A W - E|^2 + tr(W^T P W M), with M the weighted grid Laplacian (order 1)
    and P the weighted geometric mean of the frames' Gram G = H_c^T H_c and the changes' Gram S = A^T A,
    G^1/2 (G^-1/2 S G^-1/2)^alpha G^1/2 / ref^alpha, ref = tr S / tr G, written out here with scipy's matrix powers
    (alpha = 0 would be sum_t |D f_t|^2, the frames' roughness). Its gradient vanishes at the solved head and not at
    the head of time_order 0; at alpha = 1 the head is the least-squares fit shrunk by 1 / (1 + mu / ref) at each
    spatial frequency."""
    import scipy.linalg

    from evinr_lite.method.head_solve import _weights

    lam = 0.05
    model, bins = _setup("difference")
    H, W = 12, 16
    B = bins.frames.shape[1]
    with torch.no_grad():
        h, _ = model.features(bins.boundaries, dtype=torch.float64)
    h = h[0].detach().numpy()
    A, hc = h[1:] - h[:-1], h - h.mean(axis=0, keepdims=True)
    d = A.shape[1]
    S, G = A.T @ A, hc.T @ hc
    S, G = S + 1e-7 * np.trace(S) / d * np.eye(d), G + 1e-7 * np.trace(G) / d * np.eye(d)   # the solve's ridge
    Gh = np.real(scipy.linalg.sqrtm(G))
    Gih = np.linalg.inv(Gh)
    P = Gh @ np.real(scipy.linalg.fractional_matrix_power(Gih @ S @ Gih, alpha)) @ Gh / (np.trace(S) / np.trace(G)) ** alpha
    cx, cy = _weights(B, B + 1, (H, W), lam)
    M = cx * np.kron(np.eye(H), _differences(W)).T @ np.kron(np.eye(H), _differences(W)) + \
        cy * np.kron(_differences(H), np.eye(W)).T @ np.kron(_differences(H), np.eye(W))
    E = bins.frames[0].reshape(B, H * W).double().numpy()
    At, Pt, Mt, Et = (torch.tensor(x) for x in (A, P, M, E))

    def grad(Wt):
        Wt = Wt.clone().requires_grad_(True)
        J = ((At @ Wt - Et) ** 2).sum() + (Wt * (Pt @ Wt @ Mt)).sum()
        J.backward()
        return Wt.grad.norm().item()

    solve_head(model, bins.boundaries, bins.frames, "difference", "tikhonov", lam, order=1, time_order=alpha)
    tilted = model.head_weight.detach()[0].double().clone()
    solve_head(model, bins.boundaries, bins.frames, "difference", "tikhonov", lam, order=1)
    frames_only = model.head_weight.detach()[0].double().clone()
    scale = grad(torch.zeros_like(tilted))
    assert grad(tilted) < 1e-4 * scale
    assert grad(frames_only) > 1e-2 * scale
    if alpha == 1.0:   # the per-bin changes' roughness: a uniform shrinkage of the least-squares fit per frequency
        fit = np.linalg.solve(S, A.T @ E)                                      # [d, P]
        C = scipy.fft.dctn(np.eye(H * W).reshape(H * W, H, W), norm="ortho", axes=(1, 2)).reshape(H * W, H * W).T
        mu = laplacian_eigenvalues((H, W), cx, cy).ravel()
        expected = (fit @ C.T / (1 + mu / (np.trace(S) / np.trace(G)))) @ C
        np.testing.assert_allclose(tilted.numpy(), expected, atol=1e-4 * np.abs(expected).max())


def test_prior_time_order_is_checked_and_the_papers_recipes_keep_the_frames_penalty():
    from evinr_lite import EventDataError

    assert EvINRConfig().prior_time_order == 0.25
    assert EvINRConfig.paper().prior_time_order == EvINRConfig.v0_1().prior_time_order == 0.0
    for bad in (-0.1, 1.5, float("nan"), True, "0.25"):
        with pytest.raises(EventDataError, match="prior_time_order"):
            EvINRConfig(prior_time_order=bad)
