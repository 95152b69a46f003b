"""Notebook 03 (the coordinate network): exercise registrations.

- ``split_index``: a flat index over (bin, row, column) back to (bin, y, x);
- ``tikhonov_autograd``: Eq. 9 on autograd derivatives.

The references are the library's :func:`evinr_lite.method.coordinate.split_index` and
:func:`~evinr_lite.method.coordinate.tikhonov_autograd`; each hint is a deliberately wrong version.
"""
from __future__ import annotations

import torch

from ..method.coordinate import split_index, tikhonov_autograd
from . import exercises

__all__: list[str] = []


def _inputs_split(rng):
    cases = []
    for H, W, B in ((2, 3, 4), (5, 7, 3), (16, 20, 32)):
        index = torch.as_tensor(rng.integers(0, B * H * W, 12), dtype=torch.int64)
        cases.append(dict(index=index, sensor_size=(H, W)))
    return cases


def _inputs_tikhonov(rng):
    cases = []
    for M in (5, 64):
        # leaves that require grad, as autograd's derivatives do in training: the result must stay differentiable
        gx = torch.as_tensor(rng.normal(0, 0.3, M), dtype=torch.float32).requires_grad_(True)
        gy = torch.as_tensor(rng.normal(0, 0.5, M), dtype=torch.float32).requires_grad_(True)
        cases.append(dict(dF_dx=gx, dF_dy=gy))
    return cases


def _split_swapped(index, sensor_size):
    H, W = sensor_size
    return index // (H * W), index % W, (index // W) % H


def _split_by_height(index, sensor_size):
    H, W = sensor_size
    return index // (H * W), index % H, (index // H) % W


def _split_size_unpacked_wh(index, sensor_size):
    W, H = sensor_size
    return index // (H * W), (index // W) % H, index % W


def _split_x_first(index, sensor_size):
    b, y, x = split_index(index, sensor_size)
    return x, y, b


def _split_row_without_modulo(index, sensor_size):
    H, W = sensor_size
    return index // (H * W), index // W, index % W


def _split_bin_without_brackets(index, sensor_size):
    """index // H * W, which Python reads as (index // H) * W."""
    H, W = sensor_size
    return index // H * W, (index // W) % H, index % W


exercises.register(
    "split_index", split_index, _inputs_split,
    hints={
        "x and y are swapped: y is the row (index // W) % H, x the column index % W":
            _split_swapped,
        "rows are W pixels long: the column is index % W (not % H), the row (index // W) % H":
            _split_by_height,
        "sensor_size is (H, W), height first: unpack it as `H, W = sensor_size`":
            _split_size_unpacked_wh,
        "return (b, y, x), in that order: the bin first, the column last":
            _split_x_first,
        "the row is (index // W) % H: without `% H`, index // W also counts the rows of the earlier bins":
            _split_row_without_modulo,
        "brackets: `index // H * W` is (index // H) * W, from left to right; the bin is index // (H * W)":
            _split_bin_without_brackets,
    })

def _tikhonov_magnitude(dF_dx, dF_dy):
    return torch.mean(torch.sqrt(dF_dx ** 2 + dF_dy ** 2))


def _tikhonov_stacked_mean(dF_dx, dF_dy):
    return torch.mean(torch.stack([dF_dx, dF_dy]) ** 2)


exercises.register(
    "tikhonov_autograd", tikhonov_autograd, _inputs_tikhonov, rtol=1e-5, atol=1e-7,
    hints={
        "use the mean over the minibatch, not the sum":
            lambda dF_dx, dF_dy: torch.sum(dF_dx ** 2 + dF_dy ** 2),
        "Eq. 9 squares the gradients (|dF/dx| + |dF/dy| is total variation, another regularizer)":
            lambda dF_dx, dF_dy: torch.mean(dF_dx.abs() + dF_dy.abs()),
        "Eq. 9 uses both directions: (dF/dx)^2 + (dF/dy)^2":
            lambda dF_dx, dF_dy: torch.mean(dF_dx ** 2),
        "square each gradient, not their sum: (dF/dx)^2 + (dF/dy)^2":
            lambda dF_dx, dF_dy: torch.mean((dF_dx + dF_dy) ** 2),
        "Eq. 9 is the squared gradient, dF/dx^2 + dF/dy^2, without a square root (that is the gradient's "
        "magnitude)":
            _tikhonov_magnitude,
        "half the expected value: the mean over the stacked [2, M] tensor divides by 2M (and Eq. 9 has no factor "
        "1/2): average dF/dx^2 + dF/dy^2 over the M pixels":
            _tikhonov_stacked_mean,
        "Eq. 9 is the mean of the squares, without a square root over the mean (that is an RMS)":
            lambda dF_dx, dF_dy: torch.sqrt(torch.mean(dF_dx ** 2 + dF_dy ** 2)),
        "torch.var subtracts the mean (and divides by M - 1): Eq. 9 is the mean of the squares themselves, "
        "torch.mean(dF_dx ** 2 + dF_dy ** 2)":
            lambda dF_dx, dF_dy: torch.var(dF_dx) + torch.var(dF_dy),
        "`//` is floor division, also on float tensors: the sum // M rounds the mean down to a whole number (0 for "
        "small gradients); divide with `/`, or use torch.mean":
            lambda dF_dx, dF_dy: torch.sum(dF_dx ** 2 + dF_dy ** 2) // dF_dx.numel(),
    })
