"""The training step's fast path: the H x W output layer and the losses in one autograd node.

:func:`head_losses` computes what :mod:`evinr_lite.method.losses` states (temporal loss plus
regularizer on the frames F = h @ W + b) without materialising the autograd graph of F: it writes
the gradients in place, a few frames at a time, and reuses its buffers between steps. The
equivalence tests (``tests/test_perf_equivalence.py``) pin it to the readable losses.
"""
from __future__ import annotations

import torch

from ..core.checks import choice
from .losses import spatial_differences

__all__ = ["head_losses"]

REGULARIZERS = ("tikhonov", "tv", "none")

_CHUNK_CELLS = 1 << 20   # frames x pixels per elementwise chunk on a CPU: a few MB, so each chunk stays in cache


def head_losses(h: torch.Tensor, dh: torch.Tensor | None, weight: torch.Tensor, bias: torch.Tensor,
                event_frames: torch.Tensor, durations: torch.Tensor | None = None,
                regularizer: str = "tikhonov", buffers: dict | None = None):
    """The temporal loss and the regularizer of a FrameINR's output layer, as one autograd node.

    Same values and gradients as the readable path, up to float rounding
    (tests/test_perf_equivalence.py): with F = h @ weight + bias and dF = dh @ weight,

    - derivative form (``dh`` given, h and dh at the B bin centres):
      ``temporal_loss_derivative(dF, event_frames, durations)`` and ``regularizer(F)``;
    - difference form (``dh`` None, h at the B + 1 bin boundaries):
      ``temporal_loss_difference(F, event_frames)`` and ``regularizer(F)``.

    Why: the H*W-wide tensors ([N, B, H, W], tens of MB at 240x180) dominate the memory traffic of
    a training step. Autograd through the readable path sweeps them about 40 times (slices,
    squares, their backward, zero-filled slice gradients); here the elementwise work is done a few
    frames at a time while they are in cache (on a CPU), gradients are written in place, and the
    matmul gradients come from two bmm calls.

    Args:
        h: [N, R, d] last hidden layer; dh: [N, B, d] its time derivative (per second) or None.
        weight: [N, d, H*W]; bias: [N, 1, H*W]. event_frames: [N, B, H, W].
        durations: [N, B] seconds (derivative form only).
        regularizer: "tikhonov", "tv" or "none".
        buffers: a dict in which the large work arrays are kept and reused from call to call
            (fresh memory costs page faults on every step). Only for loops in which each step's
            backward runs before the next step's forward, as in a training loop; None: fresh arrays.

    Returns:
        (temporal, regularizer) scalars; the regularizer is 0 for "none".
    """
    if type(regularizer) is not str or regularizer not in REGULARIZERS:   # each training step: the shared check
        regularizer = choice(regularizer, REGULARIZERS, "regularizer")    # only when it is no plain str option
    if dh is not None and durations is None:
        raise ValueError("the derivative form needs the bin durations [N, B] (seconds)")
    return _HeadLosses.apply(h, dh, weight, bias, event_frames, durations, regularizer, buffers)


def _buffer(buffers: dict | None, name: str, shape, like: torch.Tensor) -> torch.Tensor:
    """An uninitialised tensor of this shape, reused from ``buffers`` when it holds a matching one."""
    if buffers is None:
        return like.new_empty(shape)
    key = (name, tuple(shape), like.dtype, like.device)
    if key not in buffers:
        for old in [k for k in buffers if k[0] == name]:   # a new shape (coarse-to-fine): drop the old one
            del buffers[old]
        buffers[key] = like.new_empty(shape)
    return buffers[key]


def _chunks(N: int, R: int, P: int, device: torch.device):
    """(n0, n1, f0, f1): networks n0:n1, frames f0:f1, about _CHUNK_CELLS cells each on a CPU.

    Small problems are one chunk (no Python loop over networks); on a GPU everything is one chunk.
    """
    if device.type != "cpu" or N * R * P <= _CHUNK_CELLS:
        yield 0, N, 0, R
        return
    if R * P <= _CHUNK_CELLS:
        n_step = _CHUNK_CELLS // (R * P)
        for n0 in range(0, N, n_step):
            yield n0, min(N, n0 + n_step), 0, R
        return
    step = max(1, _CHUNK_CELLS // P)
    for n in range(N):
        for f0 in range(0, R, step):
            yield n, n + 1, f0, min(R, f0 + step)


def _differences(F4: torch.Tensor, regularizer: str):
    """Forward differences of frames [c, H, W] along x and y (their signs for TV)."""
    dx, dy = spatial_differences(F4)
    return (dx.sign_(), dy.sign_()) if regularizer == "tv" else (dx, dy)


def _regularizer_sums(F4: torch.Tensor, regularizer: str):
    """(sum over dF/dx, sum over dF/dy) of squares (Tikhonov) or absolute values (TV) for frames [..., H, W]."""
    dx, dy = spatial_differences(F4)
    order = 2 if regularizer == "tikhonov" else 1
    return torch.linalg.vector_norm(dx, order) ** order, torch.linalg.vector_norm(dy, order) ** order


def _add_difference_adjoint(g4: torch.Tensor, dx: torch.Tensor, dy: torch.Tensor, cx: float, cy: float):
    """g4 [..., H, W] = gradient of cx * sum(dx * D_x F) + cy * sum(dy * D_y F) with respect to F (overwritten)."""
    torch.mul(dx, -cx, out=g4[..., :, :-1])
    g4[..., :, -1].zero_()
    g4[..., :, 1:].add_(dx, alpha=cx)
    g4[..., :-1, :].add_(dy, alpha=-cy)
    g4[..., 1:, :].add_(dy, alpha=cy)


class _HeadLosses(torch.autograd.Function):
    @staticmethod
    def forward(ctx, h, dh, weight, bias, event_frames, durations, regularizer, buffers):
        N, R, _ = h.shape
        B, H, W = event_frames.shape[1:]
        P = H * W
        X = h if dh is None else torch.cat([h, dh], dim=1)
        out = torch.bmm(X, weight, out=_buffer(buffers, "out", (N, X.shape[1], P), X))   # [N, R (+ B), P]
        F = out[:, :R]
        E = event_frames.reshape(N, B, P)
        acc = torch.zeros(3, dtype=torch.float64, device=X.device)    # temporal, reg x, reg y (sums)
        if dh is None:                                              # F at boundaries: r = F[1:] - F[:-1] - E
            F += bias
            r = torch.sub(F[:, 1:], F[:, :-1], out=_buffer(buffers, "r", (N, B, P), X))
            r -= E
            acc[0] = torch.linalg.vector_norm(r).double() ** 2
        else:                                                       # dF at centres: r = dF * duration - E
            r = out[:, R:]
        for n0, n1, f0, f1 in _chunks(N, R, P, X.device):
            Fc = F[n0:n1, f0:f1]
            if dh is not None:
                Fc += bias[n0:n1]
                rc = r[n0:n1, f0:f1]
                rc *= durations[n0:n1, f0:f1, None]
                rc -= E[n0:n1, f0:f1]
                acc[0] += torch.linalg.vector_norm(rc) ** 2
            if regularizer != "none":
                sx, sy = _regularizer_sums(Fc.view(n1 - n0, f1 - f0, H, W), regularizer)
                acc[1] += sx
                acc[2] += sy
        temporal = (acc[0] / r.numel()).to(X.dtype)
        n_x, n_y = N * R * H * (W - 1), N * R * (H - 1) * W
        reg = (acc[1] / max(n_x, 1) + acc[2] / max(n_y, 1)).to(X.dtype) if regularizer != "none" else X.new_zeros(())
        ctx.regularizer, ctx.shape, ctx.derivative, ctx.buffers = regularizer, (N, R, B, H, W), dh is not None, buffers
        ctx.save_for_backward(X, weight, out, r, durations)
        return temporal, reg

    @staticmethod
    def backward(ctx, g_temporal, g_reg):
        X, weight, out, r, durations = ctx.saved_tensors
        N, R, B, H, W = ctx.shape
        P = H * W
        c = 2 * float(g_temporal) / r.numel()
        g_out = _buffer(ctx.buffers, "g_out", (N, X.shape[1], P), X)   # d loss / d out, every element written
        gF = g_out[:, :R]
        g_bias = X.new_zeros(N, 1, P)
        k = 2 if ctx.regularizer == "tikhonov" else 1
        cx, cy = k * float(g_reg) / max(H * (W - 1) * N * R, 1), k * float(g_reg) / max((H - 1) * W * N * R, 1)
        for n0, n1, f0, f1 in _chunks(N, R, P, X.device):
            g4 = gF[n0:n1, f0:f1].view(n1 - n0, f1 - f0, H, W)
            if ctx.regularizer != "none":
                dx, dy = _differences(out[n0:n1, f0:f1].view(n1 - n0, f1 - f0, H, W), ctx.regularizer)
                _add_difference_adjoint(g4, dx, dy, cx, cy)
            else:
                g4.zero_()
            if ctx.derivative:
                g_bias[n0:n1] += gF[n0:n1, f0:f1].sum(dim=1, keepdim=True)
                torch.mul(r[n0:n1, f0:f1], durations[n0:n1, f0:f1, None] * c, out=g_out[n0:n1, R + f0:R + f1])
        if not ctx.derivative:                                      # adjoint of F[1:] - F[:-1]
            gF[:, 1:].add_(r, alpha=c)
            gF[:, :-1].add_(r, alpha=-c)
            g_bias = gF.sum(dim=1, keepdim=True)
        g_weight = torch.bmm(X.transpose(1, 2), g_out)
        g_X = torch.bmm(g_out, weight.transpose(1, 2))
        g_h, g_dh = (g_X, None) if not ctx.derivative else g_X.split(R, dim=1)
        return g_h, g_dh, g_weight, g_bias, None, None, None, None
