"""The output layer in closed form: the exact optimum of the loss over the head's weights.

A frame-based INR is F(t) = h(t) W + b, with h(t) [d] the last hidden layer and W [d, H*W] the
head. For fixed hidden layers the temporal loss is quadratic in W (both forms of it are linear in
F), and so is the Tikhonov regularizer: the head that Adam approaches in hundreds of steps can be
computed at once. Per network, with A [B, d] the features' change over each bin (difference
loss: h(b_{i+1}) - h(b_i); derivative loss: dh/dt(c_i) (b_{i+1} - b_i)), E [B, P] the event frames
and H_c [T, d] the features at the regularizer's times minus their mean:

    minimise  |A W - E|^2  +  lam' * sum_t |D (h_c(t) W)|^2            (D: pixel differences)

The bias b only shifts every frame by one per-pixel image, which neither term sees apart from
the regularizer's pull towards flat frames; it is set here so that F has zero mean over time at
every pixel, and the per-pixel offset is chosen afterwards (:mod:`evinr_lite.method.offset`).

D^T D is the grid Laplacian with Neumann borders, which the orthonormal 2-D DCT-II diagonalises
(eigenvalues 2 - 2 cos(pi k / W) along x, likewise along y). In that basis each spatial frequency
mu gives an independent d x d system (A^T A + lam' mu H_c^T H_c) w = A^T e. One generalised
eigendecomposition A^T A V = H_c^T H_c V Lambda (V^T H_c^T H_c V = I) solves all of them:
w = V (Lambda + lam' mu)^-1 V^T A^T e. The DCT over pixels commutes with A^T over bins, so the
right-hand side is (V^T A^T) DCT(E): B frame transforms and a d x B product instead of d transforms
and a d x d one. Cost: O(d^3 + (B + d) P log P + B d P + d^2 P).

**The prior's order in time** (``time_order``, alpha). Each eigenvector v_i is a temporal mode of the
features with Lambda_i = |A v_i|^2 / |H_c v_i|^2, its change per bin against its spread over the window:
small for slow modes, large for fast ones. The penalty above weighs every mode alike (the frames' own
roughness), so a slow change, which the per-bin differences see only as small steps, is shrunk by
Lambda_i / (Lambda_i + lam' mu) much more than a fast one of the same size. The data term treats each
bin's error as independent, so the integrated error of a slow change would grow like a random walk; the
staircase of a pixel's events never strays more than one threshold from its log intensity, which is
bounded. With alpha > 0 the penalty of mode i is weighted by (Lambda_i / Lambda_ref)^alpha, Lambda_ref =
tr(A^T A) / tr(H_c^T H_c) (the features' mean ratio, so lam keeps its scale): the spatial roughness of a
fractional time derivative of order alpha of the frames (alpha = 0, the frames, the paper's; alpha = 1,
the per-bin changes). The solve is the same, with lam' mu_p replaced by lam' mu_p (Lambda_i /
Lambda_ref)^alpha in each mode's denominator.
"""
from __future__ import annotations

import numpy as np
import scipy.fft
import scipy.linalg
import torch

from ..core.checks import choice, real_number, short_repr, whole_number
from ..core.events import EventDataError
from ..core.runtime import cpu_threads

__all__ = ["solve_head", "laplacian_eigenvalues", "laplacian_eigenvalues_unchecked", "penalty_spectrum",
           "penalty_spectrum_unchecked"]


# the spatial frequency (a fraction of Nyquist along both axes: a wavelength of 8 px) at which the second-order
# penalty equals the first-order one, so lam means the same at that scale whatever the order
ORDER_REFERENCE = 0.25


def penalty_spectrum(mu: np.ndarray, cx: float, cy: float, order: int | str = 1) -> np.ndarray:
    """The spatial penalty's weight per DCT frequency, from the weighted Laplacian's eigenvalues ``mu``
    (:func:`laplacian_eigenvalues` with ``cx``, ``cy``): order 1, mu itself (the gradient's energy,
    |D f|^2); order 2, mu^2 / mu_ref (the Laplacian's energy, |D^T D f|^2, scaled to equal order 1 at
    ``ORDER_REFERENCE`` of Nyquist): less smoothing of the coarser structure, more of the finer;
    "banded", mu up to mu_ref and mu^3 / mu_ref^2 beyond (the gradient's energy for structure coarser than
    the reference wavelength, a third-order roll-off for finer structure; continuous at mu_ref).

    Checked: ``mu`` an array of numbers, none NaN or negative (None came back as None, NaN gave NaN penalties and
    a negative mu at order 2 a positive one, as if it were smoothing), ``cx``, ``cy`` finite weights >= 0 (text or
    NaN were taken or numpy's errors), ``order`` 1, 2 or "banded" (True was taken as 1)."""
    values = None if mu is None or isinstance(mu, (str, bytes)) else np.asarray(mu)
    if values is None or values.dtype.kind not in "iuf":
        raise EventDataError(f"mu= must be the Laplacian's eigenvalues [H, W] (numbers; laplacian_eigenvalues(...)), "
                             f"got {short_repr(mu)}")
    if values.dtype.kind == "f" and np.isnan(values).any() or (values < 0).any():
        raise EventDataError(f"mu= must be the Laplacian's eigenvalues, numbers >= 0 (laplacian_eigenvalues(...)), "
                             f"got {int(np.isnan(values).sum()):,} NaN and {int((values < 0).sum()):,} negative "
                             "value(s)")
    for name, c in (("cx", cx), ("cy", cy)):
        real_number(c, name, lo=0.0, hint="the penalty's weight along that axis")
    if isinstance(order, (bool, np.bool_)) or (order != 1 and order not in (2, "banded")):
        raise EventDataError(f"order must be 1 (the gradient), 2 (the Laplacian) or 'banded', got {order!r}")
    return penalty_spectrum_unchecked(values, cx, cy, order)


def penalty_spectrum_unchecked(mu: np.ndarray, cx: float, cy: float, order: int | str = 1) -> np.ndarray:
    """:func:`penalty_spectrum` without its checks, for the head solve (whose lam, not a user's mu, gives cx and
    cy: a lam so large that they overflow is the solver's result check's to name)."""
    if order == 1:
        return mu
    ref = (cx + cy) * (2 - 2 * np.cos(np.pi * ORDER_REFERENCE))
    if ref <= 0:
        return mu
    if order == 2:
        return mu * mu / ref
    return np.where(mu <= ref, mu, mu * (mu / ref) ** 2)


def laplacian_eigenvalues(sensor_size, cx: float = 1.0, cy: float = 1.0) -> np.ndarray:
    """Eigenvalues [H, W] of cx Dx^T Dx + cy Dy^T Dy (forward differences, Neumann borders) in the
    orthonormal DCT-II basis (``scipy.fft.dctn(..., norm="ortho")``); [0, 0] is 0 (constants).

    ``sensor_size``: (H, W), whole numbers >= 1 (0 or -1 gave eigenvalues of no pixel, 2.5 of a made-up sensor,
    text such as "45" was read letter by letter); ``cx``, ``cy``: finite weights >= 0 (NaN gave NaN eigenvalues, -1
    negative ones), a number or an array of one (np.array([0.3]) is 0.3, as it was)."""
    try:
        if isinstance(sensor_size, (str, bytes)):
            raise TypeError
        H, W = sensor_size
    except (TypeError, ValueError):
        raise EventDataError(f"sensor_size= must be (H, W), two whole numbers >= 1, got {short_repr(sensor_size)}") \
            from None
    H, W = whole_number(H, "sensor_size: H", lo=1), whole_number(W, "sensor_size: W", lo=1)
    cx, cy = _one_value(cx), _one_value(cy)
    for name, c in (("cx", cx), ("cy", cy)):
        real_number(c, name, lo=0.0, hint="the weight of that axis' differences")
    return laplacian_eigenvalues_unchecked((H, W), cx, cy)


def _one_value(c):
    """A weight given as a numpy array of one element, as its 0-d array (the eigenvalues broadcast it as before)."""
    return c.reshape(()) if isinstance(c, np.ndarray) and c.size == 1 else c


def laplacian_eigenvalues_unchecked(sensor_size, cx: float = 1.0, cy: float = 1.0) -> np.ndarray:
    """:func:`laplacian_eigenvalues` without its checks (the solves' own sizes, each ADMM iteration's DCT solve)."""
    H, W = sensor_size
    ex = 2 - 2 * np.cos(np.pi * np.arange(W) / W)
    ey = 2 - 2 * np.cos(np.pi * np.arange(H) / H)
    return cy * ey[:, None] + cx * ex[None, :]


def _weights(B: int, T: int, sensor_size, lam: float) -> tuple[float, float]:
    """lam' along x and y, so that the solve minimises exactly the training loss's
    mean-over-(bins, pixels) temporal term + lam * (mean dx^2 + mean dy^2 over the T frames)."""
    H, W = sensor_size
    P = H * W
    cx = lam * B * P / (T * H * (W - 1)) if W > 1 else 0.0
    cy = lam * B * P / (T * (H - 1) * W) if H > 1 else 0.0
    return cx, cy


# Frequency columns (or weight rows) per chunk of the solve: the float64 work arrays stay a few MB
# whatever the sensor, while each BLAS call is still large enough to run at full speed.
_CHUNK_CELLS = 1 << 21


def _dct_rows(X: np.ndarray, sensor_size, inverse: bool = False) -> None:
    """Orthonormal 2-D DCT-II (or its inverse) of every row of X [d, H*W] float32, in place, a
    few rows at a time in float32 (no second d x H x W array). A third of float64's time at 1280x720; its
    rounding, 3e-7 of the largest coefficient against 4e-8 for storing a float64 transform as float32,
    moves the solved head by 2e-7 of its RMS (a session measurement, 2026-12-07)."""
    H, W = sensor_size
    transform = scipy.fft.idctn if inverse else scipy.fft.dctn
    rows = max(1, _CHUNK_CELLS // max(H * W, 1))
    for r0 in range(0, X.shape[0], rows):
        r1 = min(X.shape[0], r0 + rows)
        X[r0:r1] = transform(X[r0:r1].reshape(r1 - r0, H, W), type=2, norm="ortho", axes=(1, 2),
                             workers=cpu_threads()).reshape(r1 - r0, H * W)


def _solve_frequencies(X: np.ndarray, M: np.ndarray, E_hat: np.ndarray, V: np.ndarray, lam_: np.ndarray,
                       mu: np.ndarray, eps_s: float = 0.0, mode_weight: np.ndarray | None = None) -> float:
    """X [d, P] float32 <- V (Lambda + mu_p)^-1 M E_hat[:, p] for every spatial frequency p (with
    ``mode_weight`` w [d]: V (Lambda + w mu_p)^-1 M E_hat[:, p], the penalty of mode i weighted by w_i), with
    M = V^T A^T [d, B] and E_hat [B, P] the DCT of the event frames: the same as V (Lambda + mu)^-1 V^T
    DCT(A^T E), at B/d of the cost (the DCT over pixels commutes with A^T over bins). Float64 over
    chunks of columns (V can be large where G is ill-conditioned), stored as float32. Returns the
    temporal loss's sum |A W - E|^2 (Parseval: the same in the DCT domain), from the eigenbasis."""
    d, P = X.shape
    cols = max(1, _CHUNK_CELLS // max(d, 1))
    loss = 0.0
    for c0 in range(0, P, cols):
        c1 = min(P, c0 + cols)
        Ec = E_hat[:, c0:c1].astype(np.float64)
        m = M @ Ec
        Y = m / (lam_[:, None] + (mu[None, c0:c1] if mode_weight is None else mode_weight[:, None] * mu[None, c0:c1]))
        Xc = V @ Y
        # |A x - e|^2 per column from the eigenbasis: x = V y, V^T (S + eps_s I) V = Lambda, V^T A^T e = m:
        # x^T S x - 2 x^T A^T e + |e|^2 = sum y (lam y - 2 m) - eps_s |x|^2 + |e|^2, as row sums and dot
        # products (one pass over each array, no d x cols temporaries: a third of the time at 1280x720)
        x, e = Xc.ravel(), Ec.ravel()
        loss += float(lam_ @ np.einsum("ij,ij->i", Y, Y) - 2 * np.einsum("ij,ij->", Y, m)
                      - eps_s * np.dot(x, x) + np.dot(e, e))
        X[:, c0:c1] = Xc
    return loss


@torch.no_grad()
def solve_head(model, boundaries: torch.Tensor, event_frames: torch.Tensor, temporal_loss: str = "difference",
               regularizer: str = "tikhonov", lam: float = 0.05, ridge: float = 1e-7, order: int | str = 1,
               time_order: float = 0.0) -> dict:
    """Set ``model.head_weight`` and ``model.head_bias`` to the loss's optimum for its hidden layers.

    Args:
        model: a :class:`~evinr_lite.method.models.FrameINR` with N networks (changed in place).
        boundaries: float64 [N, B + 1] bin edges (s). event_frames: [N, B, H, W], C * sum of p per bin.
        temporal_loss: "difference" (F at the bin edges) or "derivative" (dF/dt at the bin mid-points).
        regularizer: "tikhonov" or "none" (TV has no closed form; train it with Adam instead).
        lam: the regularizer's weight, as in the training loss.
        ridge: relative ridge added to both Gram matrices (numerical safety; 1e-7 of their trace / d).
        order: the Tikhonov regularizer's order: 1, the training loss's |D F|^2 (what Adam minimises);
            2, the Laplacian's |D^T D F|^2 at the same weight at a wavelength of 8 px; "banded", order 1
            coarser than 8 px and a third-order roll-off finer (:func:`penalty_spectrum`;
            ``EvINRConfig.spatial_order``).
        time_order: alpha in [0, 1], the prior's order in time (the module's docstring): 0, the frames'
            roughness (the training loss's); 0.25, the kit's (``EvINRConfig.prior_time_order``).

    Memory: the solution is written in place in float32 (in the head's own storage on a CPU), the
    DCTs a few rows at a time in float32 and the frequencies a few columns at a time in float64 (the
    float32 DCTs move the head by 2e-7 of its RMS against float64 ones); beyond the model and the
    event frames the solve needs one float32 copy of the event frames (their DCT, B x H*W) and a few
    MB, not five float64 copies of the d x H*W head (tests/test_head_solve.py checks the optimum; at
    90x120 the RMS difference to an all-float64 solve is 3e-6 for both loss forms, against 8e-6 and
    5e-5 for the earlier float32 A^T E).

    Returns:
        {"seconds": time taken, "temporal": temporal loss after the solve (mean over bins, pixels, networks)}.
    """
    import time

    regularizer = choice(regularizer, ("tikhonov", "none"), "regularizer",
                         hint="the closed-form head's; use head_solve=False with TV")
    temporal_loss = choice(temporal_loss, ("difference", "derivative"), "temporal_loss")
    t0 = time.perf_counter()
    H, W = model.sensor_size
    P = H * W
    device, dtype = model.head_weight.device, model.head_weight.dtype
    edges = boundaries.to(device)
    if temporal_loss == "difference":
        h, _ = model.features(edges, dtype=model.exact_dtype())          # [N, B + 1, d], float64 (features())
        A = h[:, 1:] - h[:, :-1]
        reg_h = h
    else:
        centers = 0.5 * (edges[:, 1:] + edges[:, :-1])
        h, dh = model.features(centers, with_derivative=True, dtype=model.exact_dtype())
        A = dh * (edges[:, 1:] - edges[:, :-1]).to(dh.dtype)[..., None]
        reg_h = h
    N, B, d = A.shape
    T = reg_h.shape[1]
    E = event_frames.to(device).reshape(N, B, P)
    mean_h = reg_h.mean(dim=1, keepdim=True)                             # [N, 1, d]
    Hc = (reg_h - mean_h).double().cpu().numpy()
    A64 = A.double().cpu().numpy()
    # the solution goes straight into the head's storage when it lives in CPU float32 memory, else
    # into one float32 buffer that is copied to the device at the end
    in_place = device.type == "cpu" and dtype == torch.float32 and model.head_weight.is_contiguous()
    target = model.head_weight.data if in_place else torch.empty((N, d, P), dtype=torch.float32)
    weights = target.numpy()
    cx, cy = _weights(B, T, (H, W), lam if regularizer == "tikhonov" else 0.0)
    mu = penalty_spectrum_unchecked(laplacian_eigenvalues_unchecked((H, W), cx, cy), cx, cy, order).ravel()   # [P]
    total = 0.0
    for n in range(N):
        S = A64[n].T @ A64[n]
        G = Hc[n].T @ Hc[n]
        eps_s = ridge * max(np.trace(S) / d, 1e-30)
        eps_g = ridge * max(np.trace(G) / d, 1e-30)
        lam_, V = scipy.linalg.eigh(S + eps_s * np.eye(d), G + eps_g * np.eye(d))   # S V = G V diag(lam_)
        weight = None
        if time_order:   # each temporal mode's penalty weighted by (Lambda_i / Lambda_ref)^alpha
            ref = (np.trace(S) + d * eps_s) / (np.trace(G) + d * eps_g)
            weight = (np.maximum(lam_, 0.0) / ref) ** time_order
        E_hat = E[n].float().cpu().numpy().copy()                        # [B, P]: the event frames' DCT
        _dct_rows(E_hat, (H, W))
        # DCT(W) at every frequency, and the temporal loss |A W - E|^2 (= |A DCT(W) - DCT(E)|^2)
        total += _solve_frequencies(weights[n], V.T @ A64[n].T, E_hat, V, lam_, mu, eps_s, weight)
        del E_hat
        _dct_rows(weights[n], (H, W), inverse=True)                     # W
    if not in_place:
        model.head_weight.copy_(target.to(device=device, dtype=dtype))
    Wt = model.head_weight
    model.head_bias.copy_(-torch.bmm(mean_h.to(dtype), Wt))                # zero mean over time at every pixel
    return {"seconds": time.perf_counter() - t0, "temporal": total / (N * B * P)}
