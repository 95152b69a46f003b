"""Frame-based EvINR in the notebooks: exercise references (04, 05) and small teaching helpers.

Exercises (reference solutions, registered with :mod:`evinr_lite.teaching.exercises` at import):

- notebook 04, ``sine_layer_derivative``: one sine layer with its forward-mode time derivative,
  the step that :meth:`evinr_lite.method.models.FrameINR.forward_with_derivative` repeats layer by layer;
- notebook 04, ``temporal_loss_boundary``: the boundary-difference temporal loss
  (F(b_{i+1}) - F(b_i) against the events of bin i);
- notebook 05, ``reinhard_tonemap``: Eq. 12, (e^L / (e^L + 1))^gamma;
- notebook 05, ``total_variation``: anisotropic total variation by finite differences.
- notebook 05, ``anchor``: the brightness anchor, L shifted so that its mean tone-maps to a chosen
  display value (pinned by a test to :func:`evinr_lite.method.tonemap.anchor_mean`);
- notebook 05, ``offset_gradients``: the gradient field of the per-pixel offset that the kit's default
  solves for, minus the temporal median of the frames' forward differences (pinned by a test to
  :func:`evinr_lite.method.offset.median_gradient_offset` through ``poisson_integrate``).

Helpers used by both notebooks:

- :func:`best_offsets`: with *exact* changes of L, the only freedom left is a per-pixel offset
  g(x, y); this finds the g that a regularizer prefers (closed form for Tikhonov, Adam for TV);
- :func:`static_residual`, :func:`ghost_strength`: measure how much of the temporal-mean
  image a reconstruction subtracts (the Tikhonov "ghost").
"""
from __future__ import annotations


import numpy as np
import torch

from . import exercises
from ..method.losses import spatial_differences

__all__ = ["sine_layer_derivative", "temporal_loss_boundary", "reinhard_tonemap", "total_variation",
           "anchor", "offset_gradients", "best_offsets", "static_residual", "ghost_strength"]


# ---- notebook 04 ---------------------------------------------------------------------------

def sine_layer_derivative(h, dh_dt, weight, bias, omega):
    """One sine layer and its time derivative (forward mode, the chain rule by hand).

    z = omega * (h @ weight + bias), h_out = sin(z), dh_out/dt = cos(z) * omega * (dh_dt @ weight).

    Args:
        h: torch [T, d_in], the layer's input at T times.
        dh_dt: torch [T, d_in], its derivative with respect to time.
        weight: torch [d_in, d_out]. bias: torch [d_out]. omega: float frequency factor.

    Returns:
        (h_out, dh_out_dt): two torch tensors [T, d_out].
    """
    z = omega * (h @ weight + bias)
    return torch.sin(z), torch.cos(z) * (omega * (dh_dt @ weight))


def temporal_loss_boundary(F_boundaries, event_frames):
    """The boundary-difference temporal loss: mean of (E_i - (F(b_{i+1}) - F(b_i)))^2.

    Args:
        F_boundaries: torch [B + 1, H, W], the model at the bin boundaries b_0 .. b_B.
        event_frames: torch [B, H, W], E_i = C * (sum of p over the events in (b_i, b_{i+1}]).

    Returns:
        torch scalar (mean over bins and pixels).
    """
    predicted = F_boundaries[1:] - F_boundaries[:-1]
    return torch.mean((event_frames - predicted) ** 2)


def _inputs_sine(rng):
    g = torch.Generator().manual_seed(0)
    cases = []
    for T, d_in, d_out, omega in ((3, 1, 4, 10.0), (5, 6, 3, 30.0), (4, 8, 8, 1.0)):
        cases.append(dict(h=torch.rand(T, d_in, generator=g) * 2 - 1, dh_dt=torch.randn(T, d_in, generator=g),
                          weight=(torch.rand(d_in, d_out, generator=g) * 2 - 1) / d_in,
                          bias=torch.rand(d_out, generator=g) - 0.5, omega=omega))
    # the layer is trained through its derivative (Eq. 5 uses dF/dt): both outputs must stay differentiable
    # with respect to the weights, so a detached or rebuilt derivative fails
    cases[-1]["weight"].requires_grad_(True)
    cases[-1]["bias"].requires_grad_(True)
    return cases


def _inputs_boundary(rng):
    g = torch.Generator().manual_seed(1)
    cases = []
    for B, H, W in ((3, 2, 2), (6, 4, 5)):
        F = torch.randn(B + 1, H, W, generator=g).requires_grad_(True)   # the loss must stay differentiable
        E = torch.randint(-3, 4, (B, H, W), generator=g).float() * 0.2
        cases.append(dict(F_boundaries=F, event_frames=E))
    return cases


def _sine_derivative_of_h(h, dh_dt, weight, bias, omega):
    z = omega * (h @ weight + bias)
    return torch.sin(z), torch.cos(z) * (omega * (h @ weight))


exercises.register(
    "sine_layer_derivative", sine_layer_derivative, _inputs_sine, rtol=1e-4, atol=1e-6,
    hints={
        "the derivative of sin(z) is cos(z) times dz/dt: multiply by cos(z)":
            lambda h, dh_dt, weight, bias, omega: (torch.sin(omega * (h @ weight + bias)), omega * (dh_dt @ weight)),
        "dz/dt = omega * (dh/dt @ W): keep the factor omega (the bias has no derivative)":
            lambda h, dh_dt, weight, bias, omega: (torch.sin(omega * (h @ weight + bias)),
                                                   torch.cos(omega * (h @ weight + bias)) * (dh_dt @ weight)),
        "the derivative of sin(z) is cos(z), not sin(z)":
            lambda h, dh_dt, weight, bias, omega: (torch.sin(omega * (h @ weight + bias)),
                                                   torch.sin(omega * (h @ weight + bias)) * omega * (dh_dt @ weight)),
        "omega multiplies the bias too: z = omega * (h @ W + b)":
            lambda h, dh_dt, weight, bias, omega: (torch.sin(omega * (h @ weight) + bias),
                                                   torch.cos(omega * (h @ weight) + bias) * omega * (dh_dt @ weight)),
        "the chain rule: dz/dt = omega * (dh/dt @ W) uses dh_dt, not h":
            _sine_derivative_of_h,
        "the bias is a constant: it has no time derivative, so dz/dt = omega * (dh/dt @ W), without + b":
            lambda h, dh_dt, weight, bias, omega: (torch.sin(omega * (h @ weight + bias)),
                                                   torch.cos(omega * (h @ weight + bias)) * omega * (dh_dt @ weight + bias)),
        "omega appears once in dz/dt = omega * (dh/dt @ W): the derivative of sin(z) is cos(z), with no second omega":
            lambda h, dh_dt, weight, bias, omega: (torch.sin(omega * (h @ weight + bias)),
                                                   torch.cos(omega * (h @ weight + bias)) * omega ** 2 * (dh_dt @ weight)),
        "torch.sin and torch.cos take radians, and z is in radians already: no torch.deg2rad (or math.radians), "
        "which multiplies z by pi / 180":
            lambda h, dh_dt, weight, bias, omega: (
                torch.sin(torch.deg2rad(omega * (h @ weight + bias))),
                torch.cos(torch.deg2rad(omega * (h @ weight + bias))) * omega * (dh_dt @ weight)),
    })

def _boundary_loss_sum_of_bin_means(F_boundaries, event_frames):
    return torch.mean((event_frames - (F_boundaries[1:] - F_boundaries[:-1])) ** 2, dim=(-2, -1)).sum()


def _boundary_loss_last_bin_dropped(F_boundaries, event_frames):
    return torch.mean((event_frames[:-1] - (F_boundaries[1:-1] - F_boundaries[:-2])) ** 2)


def _boundary_loss_where_fired(F_boundaries, event_frames):
    """The mean over the (bin, pixel) entries where events fired (E != 0) only."""
    r = (event_frames - (F_boundaries[1:] - F_boundaries[:-1])) ** 2
    return r[event_frames != 0].mean()


exercises.register(
    "temporal_loss_boundary", temporal_loss_boundary, _inputs_boundary,
    hints={
        "use the mean over bins and pixels, not the sum":
            lambda F_boundaries, event_frames: torch.sum((event_frames - (F_boundaries[1:] - F_boundaries[:-1])) ** 2),
        "the change over bin i is F(b_{i+1}) - F(b_i), later minus earlier":
            lambda F_boundaries, event_frames: torch.mean((event_frames - (F_boundaries[:-1] - F_boundaries[1:])) ** 2),
        "square the difference (an absolute value gives another loss)":
            lambda F_boundaries, event_frames: torch.mean(torch.abs(event_frames - (F_boundaries[1:] - F_boundaries[:-1]))),
        "bin i's change is F(b_{i+1}) - F(b_i), from its own start (F_boundaries[1:] - F_boundaries[:-1]), "
        "not from the first boundary F(b_0)":
            lambda F_boundaries, event_frames: torch.mean((event_frames - (F_boundaries[1:] - F_boundaries[:1])) ** 2),
        "one mean over bins and pixels together (torch.mean of all the squares), not a sum of per-bin means":
            _boundary_loss_sum_of_bin_means,
        "use all B bins: F_boundaries[1:] - F_boundaries[:-1] has B changes, one per event frame (the last "
        "bin is left out)":
            _boundary_loss_last_bin_dropped,
        "compare each event frame with the model's change over its bin, F(b_{i+1}) - F(b_i), not with the value "
        "F(b_{i+1}) itself":
            lambda F_boundaries, event_frames: torch.mean((event_frames - F_boundaries[1:]) ** 2),
        "the mean is over bins and pixels, B * H * W squares: dividing the sum by B alone leaves a sum over pixels":
            lambda F_boundaries, event_frames: torch.sum((event_frames - (F_boundaries[1:] - F_boundaries[:-1])) ** 2)
            / event_frames.shape[0],
        "a pixel with no events in a bin (E = 0) is a measurement too: it says the model should not change there; "
        "average over every bin and pixel, not only where events fired (E != 0)":
            _boundary_loss_where_fired,
    })


# ---- notebook 05 ---------------------------------------------------------------------------

def reinhard_tonemap(L, gamma):
    """Eq. 12 on log intensities: I = exp(L), Gamma = (I / (I + 1))^gamma.

    Args:
        L: numpy float array, any shape (log intensity). gamma: positive float.

    Returns:
        numpy float64 array of the same shape, values in (0, 1).
    """
    I = np.exp(np.asarray(L, dtype=np.float64))
    return (I / (I + 1.0)) ** gamma


def total_variation(F):
    """Anisotropic total variation by forward differences: mean |dF/dx| + mean |dF/dy|.

    Args:
        F: torch [..., H, W] (any leading dimensions, e.g. [T, H, W]).

    Returns:
        torch scalar: the mean of |F[..., :, 1:] - F[..., :, :-1]| plus the mean of
        |F[..., 1:, :] - F[..., :-1, :]| (each averaged over its own differences).
    """
    dx = F[..., :, 1:] - F[..., :, :-1]
    dy = F[..., 1:, :] - F[..., :-1, :]
    return dx.abs().mean() + dy.abs().mean()


def _inputs_tonemap(rng):
    return [dict(L=rng.uniform(-4.0, 2.0, 7), gamma=0.6), dict(L=rng.normal(-1.0, 1.0, (3, 4)), gamma=1.0),
            dict(L=rng.normal(0.0, 2.0, (2, 5)), gamma=2.2)]


def _tonemap_without_exp(L, gamma):
    L = np.asarray(L, dtype=np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        return (L / (L + 1.0)) ** gamma


def _inputs_tv(rng):
    g = torch.Generator().manual_seed(2)
    # F requires grad (as a network's output does): the result must stay differentiable. The last F is float64, as
    # notebook 05 passes it (cell 11, `tv(F)` of a float64 stack): a difference matrix or a kernel made float32
    # inside the function (torch.eye, torch.tensor([-1.0, 1.0])) fails there (round 17)
    return [dict(F=torch.randn(3, 4, generator=g).requires_grad_(True)),
            dict(F=torch.randn(2, 5, 3, generator=g).requires_grad_(True)),
            dict(F=torch.randn(1, 6, 9, generator=g).double().requires_grad_(True))]


def _tv_pooled(F):
    dx, dy = spatial_differences(F)
    return torch.cat([dx.abs().flatten(), dy.abs().flatten()]).mean()


def _tonemap_power_of_denominator(L, gamma):
    I = np.exp(np.asarray(L, dtype=np.float64))
    return I / (I + 1.0) ** gamma


def _tonemap_exp_minus(L, gamma):
    return reinhard_tonemap(-np.asarray(L, dtype=np.float64), gamma)


def _tonemap_in_float16(L, gamma):
    I = np.exp(np.asarray(L, dtype=np.float16))
    return ((I / (I + 1)) ** gamma).astype(np.float64)


def _tonemap_min_max(L, gamma):
    g = reinhard_tonemap(L, gamma)
    return (g - g.min()) / (g.max() - g.min())


exercises.register(
    "reinhard_tonemap", reinhard_tonemap, _inputs_tonemap,
    hints={
        "the exponent is gamma, not 1 / gamma (1 / gamma is the public reference code's convention)":
            lambda L, gamma: reinhard_tonemap(L, 1.0 / gamma),
        "L is a log intensity: take I = exp(L) first":
            _tonemap_without_exp,
        "do not forget the exponent gamma":
            lambda L, gamma: reinhard_tonemap(L, 1.0),
        "brackets: (I / (I + 1)) ** gamma; I / (I + 1) ** gamma raises only the denominator":
            _tonemap_power_of_denominator,
        "I = exp(L), not exp(-L): a brighter pixel (larger L) must display brighter":
            _tonemap_exp_minus,
        "L is a natural log: I = exp(L) (np.exp), not 10 ** L":
            lambda L, gamma: reinhard_tonemap(np.asarray(L, dtype=np.float64) * np.log(10.0), gamma),
        "apply gamma to the ratio, (I / (I + 1)) ** gamma, not to I inside it (I ** gamma / (I ** gamma + 1))":
            lambda L, gamma: reinhard_tonemap(gamma * np.asarray(L, dtype=np.float64), 1.0),
        "do not stretch the result to [0, 1] (min-max normalising): Eq. 12 already maps into (0, 1), and a "
        "stretch makes each image's display depend on its own darkest and brightest pixels":
            _tonemap_min_max,
        "L is a natural log: I = exp(L) (np.exp), not 2 ** L (np.exp2)":
            lambda L, gamma: reinhard_tonemap(np.asarray(L, dtype=np.float64) * np.log(2.0), gamma),
        "the curve was computed in float16 (half precision, about 3 significant digits) and only then made "
        "float64: the digits lost on the way do not come back; compute in float64 (np.asarray(L, np.float64))":
            _tonemap_in_float16,
    })

def _tv_first_axes(F):
    """F[:, 1:] and F[1:]: the first two axes, right only for a single image [H, W]."""
    return (F[:, 1:] - F[:, :-1]).abs().mean() + (F[1:] - F[:-1]).abs().mean()


def _tv_over_pixels(F):
    dx, dy = F[..., :, 1:] - F[..., :, :-1], F[..., 1:, :] - F[..., :-1, :]
    return (dx.abs().sum() + dy.abs().sum()) / F.numel()


def _tv_rolled(F):
    return (F - torch.roll(F, 1, -1)).abs().mean() + (F - torch.roll(F, 1, -2)).abs().mean()


def _tv_joint_crop(F):
    dx = F[..., :-1, 1:] - F[..., :-1, :-1]
    dy = F[..., 1:, :-1] - F[..., :-1, :-1]
    return (dx.abs() + dy.abs()).mean()


def _tv_sum_over_images(F):
    """Each image's total variation, summed over the leading dimensions instead of averaged."""
    dx = (F[..., :, 1:] - F[..., :, :-1]).abs().mean(dim=(-2, -1))
    dy = (F[..., 1:, :] - F[..., :-1, :]).abs().mean(dim=(-2, -1))
    return (dx + dy).sum()


def _tv_root_mean_square(F):
    dx, dy = F[..., :, 1:] - F[..., :, :-1], F[..., 1:, :] - F[..., :-1, :]
    return torch.sqrt((dx ** 2).mean()) + torch.sqrt((dy ** 2).mean())


def _tv_isotropic(F):
    dx = F[..., :-1, 1:] - F[..., :-1, :-1]
    dy = F[..., 1:, :-1] - F[..., :-1, :-1]
    return torch.sqrt(dx ** 2 + dy ** 2).mean()


def _tv_central_differences(F):
    """torch.gradient's central differences ((F[x+1] - F[x-1]) / 2 inside, one-sided at the borders)."""
    return torch.gradient(F, dim=-1)[0].abs().mean() + torch.gradient(F, dim=-2)[0].abs().mean()


def _tv_pooled_mean(F):
    """A wrong version (for the hint): one mean over the x and y differences together (times 2)."""
    dx, dy = F[..., :, 1:] - F[..., :, :-1], F[..., 1:, :] - F[..., :-1, :]
    return 2 * (dx.abs().sum() + dy.abs().sum()) / (dx.numel() + dy.numel())


exercises.register(
    "total_variation", total_variation, _inputs_tv, rtol=1e-5, atol=1e-7,
    hints={
        "average each direction over its own differences (H (W - 1) along x, (H - 1) W along y), then add the two "
        "means: one mean over both together weighs the longer direction more":
            _tv_pooled_mean,
        "total variation takes absolute values; squares give Tikhonov (Eq. 9)":
            lambda F: torch.mean((F[..., :, 1:] - F[..., :, :-1]) ** 2) + torch.mean((F[..., 1:, :] - F[..., :-1, :]) ** 2),
        "use means, not sums":
            lambda F: (F[..., :, 1:] - F[..., :, :-1]).abs().sum() + (F[..., 1:, :] - F[..., :-1, :]).abs().sum(),
        "use both directions: |dF/dx| (along a row) and |dF/dy| (along a column)":
            lambda F: (F[..., :, 1:] - F[..., :, :-1]).abs().mean(),
        "average each direction over its own differences and add the two means":
            _tv_pooled,
        "F may have leading dimensions ([T, H, W]): index the last two axes, F[..., :, 1:] and F[..., 1:, :] "
        "(F[:, 1:] differences along axis 1, which is H there)":
            _tv_first_axes,
        "the anisotropic total variation averages |dF/dx| and |dF/dy| separately, not sqrt(dF/dx^2 + dF/dy^2)":
            _tv_isotropic,
        "average each direction over its own differences (H (W - 1) of them along x, (H - 1) W along y), not "
        "over the H W pixels of F":
            _tv_over_pixels,
        "torch.roll wraps round: it also takes the difference between the last and the first column (row); use "
        "F[..., :, 1:] - F[..., :, :-1], which has one column fewer":
            _tv_rolled,
        "|dF/dx| and |dF/dy| are averaged separately, each over all its differences: cropping both to "
        "[..., :-1, :-1] leaves out the last row of dF/dx and the last column of dF/dy":
            _tv_joint_crop,
        "average over the leading dimensions too (every image of [T, H, W]): the mean of all differences, not the "
        "sum of the images' total variations":
            _tv_sum_over_images,
        "the mean of |d| (absolute values), not the square root of the mean of d ** 2 (an RMS, the root of "
        "Tikhonov)":
            _tv_root_mean_square,
        "torch.gradient (np.gradient) takes central differences, (F[x+1] - F[x-1]) / 2 inside and one-sided ones at "
        "the borders: total variation uses the forward differences F[..., :, 1:] - F[..., :, :-1] (and along y)":
            _tv_central_differences,
    })


# ---- notebook 05: the brightness anchor and the offset's gradients -------------------------

def anchor(L, gamma, display_mean):
    """``L`` shifted by one constant so that its mean tone-maps to ``display_mean``.

    The display value of a log intensity F is sigmoid(F) ** gamma (Eq. 12), so the level that shows
    as ``display_mean`` is F* = logit(display_mean ** (1 / gamma)) = log(s / (1 - s)) with
    s = display_mean ** (1 / gamma); the result is L + (F* - mean(L)).

    Args:
        L: numpy float array of log intensities, any shape. gamma: positive float.
        display_mean: float in (0, 1), the display value the mean should get (0.5: mid-grey).

    Returns:
        numpy float64 array, the shape of ``L``.
    """
    L = np.asarray(L, dtype=np.float64)
    s = display_mean ** (1.0 / gamma)
    return L + (np.log(s / (1.0 - s)) - L.mean())


def _inputs_anchor(rng):
    # the first and the last case share gamma and display_mean (not L): a shift kept from one call to the next
    # (cached per gamma and display_mean, as if it did not depend on L's mean) fails on the last
    return [dict(L=rng.normal(-1.0, 1.0, (3, 4)), gamma=0.6, display_mean=0.5),
            dict(L=rng.normal(0.5, 2.0, (2, 3, 5)), gamma=2.2, display_mean=0.3),
            dict(L=rng.uniform(-4.0, 1.0, 9), gamma=0.6, display_mean=0.8),
            dict(L=np.full((2, 2), 3.0), gamma=0.6, display_mean=0.5)]


def _anchor_level_wrong(level):
    def wrong(L, gamma, display_mean):
        L = np.asarray(L, dtype=np.float64)
        return L + (level(gamma, display_mean) - L.mean())
    return wrong


def _logit(s):
    return np.log(s / (1.0 - s))


def _anchor_mean_along_axis(L, gamma, display_mean):
    """The mean along the first axis (one per column) where the mean of all of L is one number."""
    L = np.asarray(L, dtype=np.float64)
    s = display_mean ** (1.0 / gamma)
    return L + (np.log(s / (1.0 - s)) - L.mean(axis=0))


def _anchor_per_frame(L, gamma, display_mean):
    """Each image of L shifted by its own mean (the mean over the last two axes) instead of one shift for all."""
    L = np.asarray(L, dtype=np.float64)
    s = display_mean ** (1.0 / gamma)
    return L + (np.log(s / (1.0 - s)) - (L.mean(axis=(-2, -1), keepdims=True) if L.ndim >= 2 else L.mean()))


def _anchor_last_axis(L, gamma, display_mean):
    L = np.asarray(L, dtype=np.float64)
    s = display_mean ** (1.0 / gamma)
    return L + (np.log(s / (1.0 - s)) - L.mean(axis=-1, keepdims=True))


def _anchor_standardised(L, gamma, display_mean):
    L = np.asarray(L, dtype=np.float64)
    s = display_mean ** (1.0 / gamma)
    sd = L.std()
    return (L - L.mean()) / (sd if sd > 0 else 1.0) + np.log(s / (1.0 - s))


def _anchor_builtin_sum(L, gamma, display_mean):
    """Python's built-in sum, which adds the rows of a 2-D array (one total per column), divided by L.size."""
    L = np.asarray(L, dtype=np.float64)
    s = display_mean ** (1.0 / gamma)
    return L + (np.log(s / (1.0 - s)) - sum(L) / L.size)


def _anchor_len_divisor(L, gamma, display_mean):
    """The sum divided by len(L), the number of rows (the first axis), not the number of entries."""
    L = np.asarray(L, dtype=np.float64)
    s = display_mean ** (1.0 / gamma)
    return L + (np.log(s / (1.0 - s)) - L.sum() / len(L))


def _anchor_median(L, gamma, display_mean):
    L = np.asarray(L, dtype=np.float64)
    s = display_mean ** (1.0 / gamma)
    return L + (np.log(s / (1.0 - s)) - np.median(L))


exercises.register(
    "anchor", anchor, _inputs_anchor, rtol=1e-6, atol=1e-9,
    hints={
        "undo the exponent first: sigmoid(F) ** gamma = display_mean means sigmoid(F) = display_mean ** (1 / gamma)":
            _anchor_level_wrong(lambda gamma, m: _logit(m)),
        "the exponent to undo is 1 / gamma, not gamma":
            _anchor_level_wrong(lambda gamma, m: _logit(m ** gamma)),
        "I / (I + 1) = s gives I = s / (1 - s): the level is log(s / (1 - s)), not log(s)":
            _anchor_level_wrong(lambda gamma, m: np.log(m ** (1.0 / gamma))),
        "shift so that the *mean* lands on the level: add (level - mean(L)), not the level alone":
            lambda L, gamma, display_mean: np.asarray(L, dtype=np.float64) + _logit(display_mean ** (1.0 / gamma)),
        "the mean is over all of L, one number (L.mean()): a mean along an axis (L.mean(axis=0)) shifts every "
        "column by its own amount":
            _anchor_mean_along_axis,
        "shift so that the *mean* of L lands on the level (L.mean()), not the median":
            _anchor_median,
        "log intensities are natural logs: the level is np.log(s / (1 - s)), not np.log10":
            _anchor_level_wrong(lambda gamma, m: np.log10(m ** (1.0 / gamma) / (1.0 - m ** (1.0 / gamma)))),
        "the level is log(s / (1 - s)) (the logit), not log((1 - s) / s): a brighter display value needs a larger F":
            _anchor_level_wrong(lambda gamma, m: -_logit(m ** (1.0 / gamma))),
        "one shift for all of L, the mean over every entry: a mean per image (over the last two axes) shifts each "
        "frame by its own amount and removes the brightness changes between frames":
            _anchor_per_frame,
        "the mean is over all of L, one number (L.mean()): a mean along the last axis (L.mean(axis=-1)) shifts "
        "every row by its own amount":
            _anchor_last_axis,
        "only shift L (add one constant); do not rescale it: dividing by its standard deviation changes the "
        "contrast the events measured":
            _anchor_standardised,
        "Python's built-in sum(L) adds the rows of a 2-D array (along the first axis) and gives one total per "
        "column, so every column is shifted by its own amount: use L.mean() (or np.sum(L) / L.size), one number":
            _anchor_builtin_sum,
        "len(L) is the number of rows of L (its first axis), not the number of entries: divide the sum by L.size, "
        "or use L.mean()":
            _anchor_len_divisor,
    })


def offset_gradients(frames):
    """The gradient field (gx, gy) of the per-pixel offset that makes each pixel's median gradient zero.

    gx = -median over time of F[k, :, x+1] - F[k, :, x] (x: the column, axis -1), and
    gy = -median over time of F[k, y+1, :] - F[k, y, :] (y: the row, axis -2).
    ``evinr_lite.method.offset.poisson_integrate(gx, gy)`` turns them into the offset image.

    Args:
        frames: numpy float [K, H, W], log intensities of a reconstruction over the sequence.

    Returns:
        (gx float64 [H, W - 1], gy float64 [H - 1, W]).
    """
    F = np.asarray(frames, dtype=np.float64)
    return -np.median(np.diff(F, axis=2), axis=0), -np.median(np.diff(F, axis=1), axis=0)


def _inputs_offset_gradients(rng):
    return [dict(frames=rng.normal(0.0, 1.0, (5, 4, 4))), dict(frames=rng.normal(0.0, 1.0, (4, 3, 6))),
            dict(frames=rng.normal(0.0, 1.0, (7, 5, 2)).cumsum(axis=0))]


def _offset_gradients_mean(frames):
    F = np.asarray(frames, dtype=np.float64)
    return -np.mean(np.diff(F, axis=2), axis=0), -np.mean(np.diff(F, axis=1), axis=0)


def _offset_gradients_swapped_axes(frames):
    F = np.asarray(frames, dtype=np.float64)
    return -np.median(np.diff(F, axis=1), axis=0), -np.median(np.diff(F, axis=2), axis=0)


def _offset_gradients_of_median_frame(frames):
    m = np.median(np.asarray(frames, dtype=np.float64), axis=0)
    return -np.diff(m, axis=1), -np.diff(m, axis=0)


def _offset_gradients_upper_middle(frames):
    """The median read as the middle entry of the sorted differences, sorted[K // 2]."""
    F = np.asarray(frames, dtype=np.float64)
    K = F.shape[0]
    return -np.sort(np.diff(F, axis=2), axis=0)[K // 2], -np.sort(np.diff(F, axis=1), axis=0)[K // 2]


def _offset_gradients_prepended(frames):
    F = np.asarray(frames, dtype=np.float64)
    return (-np.median(np.diff(F, axis=2, prepend=F[:, :, :1]), axis=0),
            -np.median(np.diff(F, axis=1, prepend=F[:, :1, :]), axis=0))


def _offset_gradients_no_sign(frames):
    gx, gy = offset_gradients(frames)
    return -gx, -gy


def _offset_gradients_central(frames):
    """np.gradient's central differences (shape [H, W]) in place of the forward differences np.diff."""
    F = np.asarray(frames, dtype=np.float64)
    return -np.median(np.gradient(F, axis=2), axis=0), -np.median(np.gradient(F, axis=1), axis=0)


AXES_HINT = ("gx is the difference along x, the column axis (axis 2 of [K, H, W], shape [H, W - 1]); gy along y, "
             "the rows (axis 1, shape [H - 1, W])")


def _compare_offset_gradients(got, expected):
    """None when ``got`` is (gx, gy) equal to ``expected``; otherwise what is wrong. Reported as a values
    problem even for a wrong shape, so that the hints run (differences along the wrong axes change the shapes)."""
    if got is None:
        return "returned None; did you forget the `return` statement?"
    if not isinstance(got, (tuple, list)) or len(got) != 2:
        return f"return a pair (gx, gy), got {type(got).__name__}"
    for name, g, e in zip(("gx", "gy"), got, expected):
        if not isinstance(g, np.ndarray):
            return f"{name} is a {type(g).__name__}, expected a numpy array"
        if g.dtype.kind not in "biuf":
            return f"{name} has dtype {g.dtype}, expected numbers"
        if g.shape != e.shape:   # a hint then says whether the axes are swapped
            return f"{name} has shape {g.shape}, expected {e.shape}"
        if not np.allclose(g, e, rtol=1e-6, atol=1e-9):   # float32 arithmetic passes; the hints differ by far more
            with np.errstate(invalid="ignore"):
                return f"{name}: wrong values, largest difference {np.abs(g - e).max():.3g}"
    return None


def _offset_gradients_lower(frames):
    """The lower of the two middle values for an even K."""
    F = np.asarray(frames, dtype=np.float64)
    return (-np.quantile(np.diff(F, axis=2), 0.5, axis=0, method="lower"),
            -np.quantile(np.diff(F, axis=1), 0.5, axis=0, method="lower"))


exercises.register(
    "offset_gradients", offset_gradients, _inputs_offset_gradients, compare=_compare_offset_gradients,
    hints={
        "take the median over time, not the mean: the mean keeps every moving edge's trail (the ghost)":
            _offset_gradients_mean,
        AXES_HINT: _offset_gradients_swapped_axes,
        "the offset cancels the median gradient: return minus the median": _offset_gradients_no_sign,
        "take the median of the frames' differences (np.median(np.diff(F, axis=2), axis=0)), not the differences "
        "of the median frame: the two differ wherever an edge moves":
            _offset_gradients_of_median_frame,
        "the median of an even number of frames is the mean of the two middle values (np.median): sorted[K // 2] "
        "is only the upper one":
            _offset_gradients_upper_middle,
        "gx has W - 1 columns (one per pair of neighbours), gy H - 1 rows: np.diff without `prepend=`, which adds "
        "a difference of 0 at the border":
            _offset_gradients_prepended,
        "the median of an even number K of differences is the mean of the two middle ones: np.median, not the "
        "lower middle value (sorted[(K - 1) // 2], np.quantile(..., method='lower'))": _offset_gradients_lower,
        "np.gradient takes central differences, (F[x+1] - F[x-1]) / 2, and keeps the shape [H, W]: the gradient "
        "field is the forward differences np.diff(F, axis=2) (shape [H, W - 1]) and np.diff(F, axis=1) ([H - 1, W])":
            _offset_gradients_central,
    })


# ---- helpers for notebooks 04 and 05 -------------------------------------------------------

def best_offsets(L, regularizer: str = "tikhonov", n_iters: int = 400, lr: float = 0.05, seed: int = 0):
    """The per-pixel offset g [H, W] a regularizer picks when the temporal loss is exact.

    With exact changes, every F(t) = L(t) + g(x, y) has zero temporal loss, so the total loss is
    lam * mean_t R(L(t) + g) and the optimum is the g minimising mean_t R(L(t) + g), whatever lam.

    - "tikhonov": setting the gradient to zero gives D^T D (g + mean_t L) = 0, so
      g = -mean_t L(t) + const (closed form; D are the finite differences).
    - "tv": no closed form; minimised by Adam on the subgradient (lr decaying to 1 % over
      ``n_iters``), starting from g = 0, in numpy.

    Args:
        L: float [T, H, W] true log intensities. Returns float64 [H, W] with zero mean.
    """
    L = np.asarray(L, dtype=np.float64)
    if regularizer == "tikhonov":
        g = -L.mean(axis=0)
        return g - g.mean()
    if regularizer != "tv":
        raise ValueError(f"regularizer must be 'tikhonov' or 'tv', got {regularizer!r}")
    # Adam on mean_t TV(L(t) + g) in numpy (subgradient sign(.) of |.|); cheap and thread-free
    T, H, W = L.shape
    Lx, Ly = np.diff(L, axis=2), np.diff(L, axis=1)
    g = np.zeros((H, W))
    m = np.zeros_like(g)
    v = np.zeros_like(g)
    beta1, beta2, eps = 0.9, 0.999, 1e-8
    for k in range(1, int(n_iters) + 1):
        sx = np.sign(Lx + np.diff(g, axis=1)).sum(axis=0) / (T * H * (W - 1))   # d mean|dx| / d(dg_x)
        sy = np.sign(Ly + np.diff(g, axis=0)).sum(axis=0) / (T * (H - 1) * W)
        grad = np.zeros_like(g)
        grad[:, 1:] += sx
        grad[:, :-1] -= sx
        grad[1:, :] += sy
        grad[:-1, :] -= sy
        m = beta1 * m + (1 - beta1) * grad
        v = beta2 * v + (1 - beta2) * grad ** 2
        step = lr * 0.01 ** ((k - 1) / max(n_iters, 1))
        g -= step * (m / (1 - beta1 ** k)) / (np.sqrt(v / (1 - beta2 ** k)) + eps)
    return g - g.mean()


def static_residual(L_rec, L_true) -> np.ndarray:
    """The part of the error that is the same in every frame: mean_t of (L_rec - L_true), each frame
    mean-subtracted first (the global offset is not an error here). float64 [H, W]."""
    r = np.asarray(L_rec, np.float64) - np.asarray(L_true, np.float64)
    r = r - r.mean(axis=(1, 2), keepdims=True)
    return r.mean(axis=0)


def ghost_strength(L_rec, L_true) -> float:
    """How much of the temporal-mean image is missing from every frame of a reconstruction.

    The least-squares coefficient a in ``static_residual(L_rec, L_true) ~ -a * (mean_t L_true - its
    mean)``: 1 for Tikhonov's exact optimum L(t) - mean_t L(t) (and for frames that lost all their
    static content, e.g. flat ones), 0 when the static error has no component along the mean image
    (e.g. the truth itself, or the truth plus a constant).
    """
    r = static_residual(L_rec, L_true).ravel()
    m = np.asarray(L_true, np.float64).mean(axis=0).ravel()
    b = -(m - m.mean())
    return float((r - r.mean()) @ b / max(b @ b, 1e-300))
