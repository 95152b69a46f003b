"""SIREN: a multilayer perceptron with sine activations (Sitzmann et al., NeurIPS 2020).

EvINR represents the log intensity as a SIREN (Sec. 3.2 of the paper): the 1-D teaching
model F(t) of notebook 01 and the frame-based model F(t) -> H*W log intensities (Eq. 11)
are both instances of :class:`Siren`.

A sine layer computes ``sin(omega_0 * (W x + b))``. The initialisation keeps every
layer's pre-activations close to a standard normal and its outputs close to the arcsine
distribution on [-1, 1], whatever the depth:

- first layer: ``W ~ U(-1/in, 1/in)`` (it sees raw coordinates, usually in [-1, 1]; its
  frequency is set by ``first_omega_0``);
- hidden layers (and the linear head): ``W ~ U(-sqrt(6/in)/omega_0, +sqrt(6/in)/omega_0)``.

Biases keep PyTorch's default ``U(-1/sqrt(in), 1/sqrt(in))``.
"""
from __future__ import annotations

import math

import torch
from torch import nn

from ..core.checks import real_number, true_or_false, whole_number
from ..core.events import EventDataError

__all__ = ["SineLayer", "Siren", "input_gradient", "check_siren_shape"]


def check_siren_shape(hidden_features, hidden_layers, omega_0, first_omega_0) -> tuple:
    """A SIREN's width (whole number >= 1), hidden layers (>= 0) and frequencies (finite, > 0; ``first_omega_0``
    None: ``omega_0``), checked by name before any weight is drawn (None and text were Python's int() / float()
    errors, 2.5 a network of width 2, 0 a ZeroDivisionError, -1 layers a model without layers, a NaN or negative
    omega_0 NaN or flipped weights, True a width of 1), for :class:`Siren` and
    :class:`~evinr_lite.method.models.FrameINR`. Returns them as (int, int, float, float)."""
    hidden_features = whole_number(hidden_features, "hidden_features", lo=1)
    hidden_layers = whole_number(hidden_layers, "hidden_layers", lo=0)
    hint = "a SIREN frequency factor (SIREN: 30)"
    omega_0 = real_number(omega_0, "omega_0", lo=0, lo_open=True, hint=hint)
    first_omega_0 = omega_0 if first_omega_0 is None else \
        real_number(first_omega_0, "first_omega_0", lo=0, lo_open=True, hint=hint + "; None: omega_0")
    return hidden_features, hidden_layers, omega_0, first_omega_0


class SineLayer(nn.Module):
    """``y = sin(omega_0 * (x @ W.T + b))``.

    Args:
        in_features, out_features: sizes of the input and output.
        omega_0: frequency factor.
        is_first: use the first-layer initialisation ``U(-1/in, 1/in)``.

    Shapes: input [..., in_features] -> output [..., out_features].
    """

    def __init__(self, in_features: int, out_features: int, omega_0: float = 30.0, is_first: bool = False):
        super().__init__()
        # checked by name (None, text and 2.5 were Python's or torch's errors, or a layer of 2; a NaN or 0 omega_0
        # and True as a size were taken): a whole number of features >= 1, a finite frequency > 0, a flag
        in_features = whole_number(in_features, "in_features", lo=1)
        out_features = whole_number(out_features, "out_features", lo=1)
        self.omega_0 = real_number(omega_0, "omega_0", lo=0, lo_open=True, hint="the sine's frequency factor (SIREN: 30)")
        self.is_first = true_or_false(is_first, "is_first")
        self.linear = nn.Linear(in_features, out_features)
        with torch.no_grad():
            bound = 1.0 / in_features if is_first else math.sqrt(6.0 / in_features) / self.omega_0
            self.linear.weight.uniform_(-bound, bound)

    def preactivation(self, x: torch.Tensor) -> torch.Tensor:
        """``omega_0 * (W x + b)``, the argument of the sine. [..., in] -> [..., out]."""
        return self.omega_0 * self.linear(x)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return torch.sin(self.preactivation(x))

    def extra_repr(self) -> str:
        return f"omega_0={self.omega_0}, is_first={self.is_first}"


class Siren(nn.Module):
    """A SIREN: ``hidden_layers + 1`` sine layers followed by a linear (or sine) output layer.

    Args:
        in_features: input size (1 for F(t), 3 for F(x, y, t)).
        out_features: output size (1 for one pixel, H*W for the frame-based model).
        hidden_features: width of every hidden layer (the paper uses 512).
        hidden_layers: number of hidden-to-hidden sine layers (the paper uses 3).
        omega_0: frequency factor of the hidden layers (SIREN's default 30).
        first_omega_0: frequency factor of the first layer; ``None`` means ``omega_0``.
            It sets the highest frequency the network represents easily along its inputs.
        outermost_linear: a linear output layer (True, for unbounded values such as log
            intensity) or one more sine layer (False, outputs in [-1, 1]).

    Shapes: input [..., in_features] -> output [..., out_features]. Inputs are expected
    roughly in [-1, 1] (map times and coordinates there before calling).

    Example::

        net = Siren(1, 1, hidden_features=64, hidden_layers=2)
        t = torch.linspace(-1, 1, 100)[:, None]      # [100, 1]
        F = net(t)                                   # [100, 1]
    """

    def __init__(self, in_features: int, out_features: int, hidden_features: int = 512,
                 hidden_layers: int = 3, omega_0: float = 30.0, first_omega_0: float | None = None,
                 outermost_linear: bool = True):
        super().__init__()
        # every argument checked by name before any layer is made (None, text, NaN and lists were Python's int() /
        # float() errors or "'>' not supported"; True was a width of 1 or torch's "must be tuple of ints"; an
        # infinite omega_0 built a network of NaN): whole numbers (>= 1, hidden_layers >= 0), finite
        # frequencies > 0, outermost_linear a flag. EventDataError is a ValueError, as the checks before were.
        in_features = whole_number(in_features, "in_features", lo=1)
        out_features = whole_number(out_features, "out_features", lo=1)
        hidden_features, hidden_layers, omega_0, first_omega_0 = check_siren_shape(
            hidden_features, hidden_layers, omega_0, first_omega_0)
        self.in_features = in_features
        self.out_features = out_features
        self.omega_0 = omega_0
        self.first_omega_0 = first_omega_0
        self.outermost_linear = true_or_false(outermost_linear, "outermost_linear")

        layers: list[nn.Module] = [SineLayer(in_features, hidden_features, self.first_omega_0, is_first=True)]
        for _ in range(hidden_layers):
            layers.append(SineLayer(hidden_features, hidden_features, self.omega_0))
        if self.outermost_linear:
            head = nn.Linear(hidden_features, out_features)
            with torch.no_grad():
                bound = math.sqrt(6.0 / hidden_features) / self.omega_0
                head.weight.uniform_(-bound, bound)
            layers.append(head)
        else:
            layers.append(SineLayer(hidden_features, out_features, self.omega_0))
        self.net = nn.Sequential(*layers)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        """[..., in_features] -> [..., out_features]."""
        if x.shape[-1] != self.in_features:
            raise ValueError(f"Siren expects inputs of shape [..., {self.in_features}], got {tuple(x.shape)}")
        return self.net(x)

    def activations(self, x: torch.Tensor) -> list[torch.Tensor]:
        """Outputs of every layer, first to last (for looking at the initialisation).

        Returns a list of ``len(self.net)`` tensors; entry k has shape [..., width of layer k].
        """
        out = []
        for layer in self.net:
            x = layer(x)
            out.append(x)
        return out

    def num_parameters(self) -> int:
        return sum(p.numel() for p in self.parameters())


def input_gradient(y: torch.Tensor, x: torch.Tensor, create_graph: bool = True) -> torch.Tensor:
    """d(sum of y)/dx by autograd; with ``create_graph=True`` a loss on it can be back-propagated
    again ("double back-propagation", Eq. 5).

    Args:
        y: output that depends on ``x`` (any shape; its entries are summed, so for a network
            applied row-wise to x [N, d] with one output per row this is the per-row gradient).
        x: input tensor with ``requires_grad=True``.

    Returns:
        tensor shaped like ``x``.
    """
    for name, v in (("y", y), ("x", x)):   # None or numpy was "has no attribute 'requires_grad'" or torch's error
        if not isinstance(v, torch.Tensor):
            raise EventDataError(f"input_gradient: {name}= must be a torch tensor, got {type(v).__name__}"
                                 + ("; make x a tensor with requires_grad=True before the forward pass" if name == "x"
                                    else "; pass the network's output computed from x"))
    if not x.requires_grad:
        raise EventDataError("input_gradient needs x.requires_grad=True before the forward pass")
    create_graph = true_or_false(create_graph, "create_graph")
    try:
        (g,) = torch.autograd.grad(y, x, grad_outputs=torch.ones_like(y), create_graph=create_graph)
    except RuntimeError as err:   # y not computed from x: torch's "does not require grad" / "not ... used in the graph"
        if "require grad" not in str(err) and "used in the graph" not in str(err):
            raise
        raise EventDataError("input_gradient: y was not computed from x (autograd finds no path from x to y); pass "
                             "y = model(x), computed after x.requires_grad_(True)") from None
    return g
