"""The frame-based INR (Eq. 11): F(t) -> all H x W log intensities, for N networks at once.

``FrameINR`` holds N independent SIRENs with stacked weights, so an ensemble of N sub-sequence
networks (Sec. 3.3, "network ensembling") trains in one batched computation (``torch.baddbmm``),
never a Python loop over networks. N = 1 is the plain frame-based model.

Each network maps a time t (seconds) in its own window [t_lo, t_hi] to [-1, 1] and then:

    h_0 = sin(first_omega_0 * (W_0 tau + b_0))            width `hidden_features`
    h_k = sin(omega_0 * (W_k h_{k-1} + b_k))                `hidden_layers` times
    F   = W_out h_L + b_out                                 H * W log intensities

The time derivative dF/dt (Eq. 5) is propagated alongside the values (forward mode): with
z_k the pre-activation, dh_k/dt = cos(z_k) * omega * W_k dh_{k-1}/dt, and dF/dt = W_out dh_L/dt.
This is exactly what double back-propagation computes, at the cost of one extra pass; the
tests check it against autograd.
"""
from __future__ import annotations

import math

import torch
from torch import nn

from ..core.checks import check_seed, numbers_array, true_or_false, whole_number
from ..core.events import EventDataError, check_sensor_size
from .siren import check_siren_shape

__all__ = ["FrameINR", "network_seed"]


def _uniform(shape, bound, generator, out=None):
    """U(-bound, bound) of ``shape``, drawn into ``out`` when given (in place: no temporaries, which
    matters for the d x H*W head at HD sizes); the same values either way."""
    out = torch.empty(shape) if out is None else out
    torch.rand(shape, generator=generator, out=out)
    return out.mul_(2).sub_(1).mul_(bound)


def network_seed(seed: int, k: int) -> int:
    """The seed of network k of an ensemble seeded with ``seed``: ``seed`` itself for k = 0, so a
    one-network model is initialised as before; each network's own seed makes network k the same
    whether it is built alone (streaming, one window at a time) or inside an N-network model."""
    return (int(seed) + int(k) * 0x9E3779B97F4A7C15) % 2**63


def _check_windows(windows) -> torch.Tensor:
    """The networks' windows as float64 [N, 2] seconds: finite numbers, two per network (a flat [2 * N] is N
    windows, as before), at least one, each with t_hi > t_lo; else an EventDataError naming windows=."""
    arr = numbers_array(windows, "windows", "time windows [N, 2] in seconds (t_lo, t_hi) per network")
    if arr.size == 0 or arr.size % 2 or (arr.ndim > 1 and arr.shape[-1] != 2):
        raise EventDataError(f"windows= must be time windows [N, 2] in seconds, one (t_lo, t_hi) per network and at "
                             f"least one, got shape {arr.shape}")
    windows = torch.as_tensor(windows, dtype=torch.float64).reshape(-1, 2)
    if not torch.isfinite(windows).all():
        raise EventDataError("windows= holds NaN or infinite seconds; every network window [t_lo, t_hi] needs "
                             "finite times")
    if torch.any(windows[:, 1] <= windows[:, 0]):
        raise EventDataError("every network window [t_lo, t_hi] needs t_hi > t_lo (seconds)")
    return windows


class FrameINR(nn.Module):
    """N frame-based SIRENs F_n(t) -> [H, W] with stacked weights.

    Args:
        sensor_size: (H, W).
        windows: [N, 2] seconds, the time window [t_lo, t_hi] of each network (mapped to [-1, 1]).
        hidden_features: width (paper: 512).
        hidden_layers: hidden-to-hidden sine layers (paper: 3).
        omega_0: frequency factor of the hidden layers (SIREN: 30; the reference code uses 10).
        first_omega_0: frequency factor of the first layer (None: omega_0).
        seed: seeds the initialisation (SIREN's, per network: network k draws from
            :func:`network_seed` (seed, first_index + k)).
        first_index: the ensemble index of the first network held here, so that a model of one
            window (streaming) is initialised exactly as that window's network of the whole ensemble.
        init_head: False leaves the H*W output layer at zero instead of drawing it (for a head that
            will be solved in closed form before use: saves d x H*W random draws, ~1 GB at 1280x720).

    Shapes: ``forward(t)`` with t [N, T] seconds -> F [N, T, H, W].
    """

    def __init__(self, sensor_size, windows, hidden_features: int = 512, hidden_layers: int = 3,
                 omega_0: float = 30.0, first_omega_0: float | None = None, seed: int = 0, *,
                 first_index: int = 0, init_head: bool = True):
        super().__init__()
        H, W = check_sensor_size(sensor_size)
        windows = _check_windows(windows)
        # the sizes, frequencies, seed and flag by name before any weight is drawn
        d, hidden_layers, omega_0, first_omega_0 = check_siren_shape(hidden_features, hidden_layers, omega_0,
                                                                     first_omega_0)
        seed = check_seed(seed)   # [0, 2**63), EvINRConfig's: network_seed works modulo 2**63
        first_index = whole_number(first_index, "first_index", lo=0)
        init_head = true_or_false(init_head, "init_head")
        self.sensor_size = (H, W)
        self.n_models = N = windows.shape[0]
        self.omega_0 = omega_0
        self.first_omega_0 = first_omega_0
        self.register_buffer("windows", windows)
        hidden_bound = math.sqrt(6 / d) / self.omega_0
        # (name, shape per network, bound) in SIREN's drawing order; biases as PyTorch's Linear
        layout = [("w0", (1, d), 1.0), ("b0", (1, d), 1.0)]   # first layer: U(-1/in, 1/in), in = 1
        for i in range(1, int(hidden_layers) + 1):
            layout += [(f"w{i}", (d, d), hidden_bound), (f"b{i}", (1, d), 1 / math.sqrt(d))]
        layout += [("head_w", (d, H * W), hidden_bound), ("head_b", (1, H * W), 1 / math.sqrt(d))]
        values = {name: torch.empty((N, *shape)) for name, shape, _ in layout}
        for k in range(N):   # network k from its own generator (network_seed), drawn straight into place
            g = torch.Generator().manual_seed(network_seed(seed, int(first_index) + k))
            for name, shape, bound in layout:
                if name.startswith("head") and not init_head:
                    continue
                _uniform((1, *shape), bound, g, out=values[name][k:k + 1])
        if not init_head:   # to be solved in closed form: zeros (never read before the solve)
            values["head_w"].zero_()
            values["head_b"].zero_()
        self.weights = nn.ParameterList([nn.Parameter(values[f"w{i}"]) for i in range(int(hidden_layers) + 1)])
        self.biases = nn.ParameterList([nn.Parameter(values[f"b{i}"]) for i in range(int(hidden_layers) + 1)])
        self.head_weight = nn.Parameter(values["head_w"])
        self.head_bias = nn.Parameter(values["head_b"])

    # ---- time mapping -------------------------------------------------------------------
    def normalize_time(self, t: torch.Tensor, dtype: torch.dtype | None = None) -> torch.Tensor:
        """Seconds [N, T] -> [-1, 1] within each network's window (computed in float64; returned in
        ``dtype``, default the model's: float32)."""
        lo, hi = self.windows[:, :1], self.windows[:, 1:]
        return (2 * (t.double() - lo) / (hi - lo) - 1).to(self.head_weight.dtype if dtype is None else dtype)

    def _time_scale(self, dtype: torch.dtype | None = None) -> torch.Tensor:
        """d tau / d t per network, [N, 1, 1] (1/seconds), in ``dtype`` (default the model's)."""
        return (2 / (self.windows[:, 1] - self.windows[:, 0])).to(self.head_weight.dtype if dtype is None
                                                                   else dtype)[:, None, None]

    # ---- forward ------------------------------------------------------------------------
    def features(self, t: torch.Tensor, with_derivative: bool = False, dtype: torch.dtype | None = None):
        """Last hidden layer h [N, T, d] (and dh/dt [N, T, d] per second if asked), in ``dtype`` (default:
        the model's). :meth:`forward` without gradients and the closed-form head ask for
        :meth:`exact_dtype`: the solved head's weights are large and cancel (rms 31 at 180x240 with the
        kit's default), so a float32 rounding of h (1e-6, and different for 1 and 2 BLAS threads)
        moved F by up to 1e-3 (about 2e-4 now; the rest is the float32 head product's own rounding).
        The hidden layers are d x d, so float64 costs nothing next to the head."""
        dtype = self.head_weight.dtype if dtype is None else dtype
        cast = (lambda x: x) if dtype == self.head_weight.dtype else (lambda x: x.to(dtype))
        tau = self.normalize_time(t, dtype)[..., None]                           # [N, T, 1]
        w0, b0 = cast(self.weights[0]), cast(self.biases[0])
        z = self.first_omega_0 * (tau * w0 + b0)                                 # [N, T, d]
        h = torch.sin(z)
        dh = torch.cos(z) * (self.first_omega_0 * w0 * self._time_scale(dtype)) if with_derivative else None
        for w, b in zip(self.weights[1:], self.biases[1:]):
            w, b = cast(w), cast(b)
            z = self.omega_0 * torch.baddbmm(b, h, w)
            h = torch.sin(z)
            if with_derivative:
                dh = torch.cos(z) * (self.omega_0 * torch.bmm(dh, w))
        return h, dh

    def exact_dtype(self) -> torch.dtype:
        """float64 for the hidden features where the model's device has it (not Apple's MPS), else the model's."""
        return self.head_weight.dtype if self.head_weight.device.type == "mps" else torch.float64

    def forward(self, t: torch.Tensor, out: torch.Tensor | None = None) -> torch.Tensor:
        """Log intensity F at times t [N, T] (seconds) -> [N, T, H, W].

        ``out``: optional float32 tensor [N, T, H, W] to write into (no gradient), so that a long
        query fills one preallocated result instead of allocating and copying every batch.
        """
        if torch.is_grad_enabled():       # training: float32 through autograd
            h, _ = self.features(t)
        else:                             # a prediction: exact features, rounded once for the head (features())
            h, _ = self.features(t, dtype=self.exact_dtype())
            h = h.to(self.head_weight.dtype)
            if h.shape[1] == 1:
                # one time is a matrix-vector product, which BLAS may sum in another order than a product
                # of two or more rows (MKL on AVX-512 does: 5e-3 apart where the head's weights cancel);
                # computed as two equal rows, one time's frame is the same as in any batch of times
                # (in out's dtype, so that a wrong one is refused as it is for many times)
                two = torch.empty((h.shape[0], 2, self.head_weight.shape[-1]), device=h.device,
                                  dtype=self.head_weight.dtype if out is None else out.dtype)
                torch.baddbmm(self.head_bias, torch.cat([h, h], dim=1), self.head_weight, out=two)
                if out is None:
                    return two[:, :1].reshape(h.shape[0], 1, *self.sensor_size)
                out.view(*out.shape[:2], -1).copy_(two[:, :1])
                return out
        if out is not None:
            torch.baddbmm(self.head_bias, h, self.head_weight, out=out.view(*out.shape[:2], -1))
            return out
        F = torch.baddbmm(self.head_bias, h, self.head_weight)
        return F.reshape(*F.shape[:2], *self.sensor_size)

    def forward_with_derivative(self, t: torch.Tensor):
        """(F, dF/dt) at times t [N, T] (seconds): two tensors [N, T, H, W], dF/dt per second."""
        h, dh = self.features(t, with_derivative=True)
        T = h.shape[1]
        out = torch.bmm(torch.cat([h, dh], dim=1), self.head_weight)             # one matmul for both
        F = (out[:, :T] + self.head_bias).reshape(-1, T, *self.sensor_size)
        dF = out[:, T:].reshape(-1, T, *self.sensor_size)
        return F, dF

    def network(self, k: int) -> "FrameINR":
        """A one-network FrameINR holding a copy of network k's weights (same device and window)."""
        if not -self.n_models <= k < self.n_models:
            raise IndexError(f"network {k} does not exist; this FrameINR holds {self.n_models}")
        k = k % self.n_models
        d = self.weights[0].shape[-1]
        single = FrameINR(self.sensor_size, self.windows[k:k + 1].cpu(), d, len(self.weights) - 1,
                          self.omega_0, self.first_omega_0, init_head=False)
        single.load_state_dict({name: v[k:k + 1].clone() for name, v in self.state_dict().items()})
        return single.to(self.head_weight.device)

    def num_parameters(self) -> int:
        return sum(p.numel() for p in self.parameters())
