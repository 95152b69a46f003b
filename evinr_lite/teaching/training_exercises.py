"""One training step of the frame INR (notebook 04): the method itself, as an exercise.

Exercise (reference solution registered with :mod:`evinr_lite.teaching.exercises` at import):

- ``frame_train_step``: F and dF/dt at the bin mid-points (Eq. 11 and 5, forward mode), the temporal
  loss (Eq. 6) plus lambda times Tikhonov (Eq. 9), then one optimiser step. The check runs it on
  tiny seeded :class:`~evinr_lite.method.models.FrameINR` models (one network, then two: the inputs
  are [N, B, ...]) with an Adam optimiser whose gradients hold stale values (as after an earlier step),
  and compares the returned losses *and* every parameter after the step with the reference's, so a
  forgotten ``zero_grad`` or ``step`` is caught even where the loss value alone looks right.

The loop in notebook 04 calls this step ``N_ITERS`` times; the learning-rate schedule stays outside it.
"""
from __future__ import annotations

import numpy as np
import torch

from . import exercises
from ..method.losses import temporal_loss_derivative, tikhonov
from ..method.models import FrameINR

__all__ = ["frame_train_step"]


def frame_train_step(model, optimizer, event_frames, centers, durations, lam):
    """One step of the paper's basic objective for a frame INR.

    Args:
        model: a :class:`FrameINR` with N networks (N = 1 in notebook 04).
        optimizer: a torch optimiser over ``model``'s parameters (Adam in the notebook).
        event_frames: float32 [N, B, H, W], C times the summed polarities of each bin (Eq. 2).
        centers: float64 [N, B] bin mid-points (s).
        durations: float32 [N, B] bin lengths (s).
        lam: weight of the Tikhonov term (Eq. 9).

    Returns:
        (loss, temporal, regularizer): three detached torch scalars, the values *before* the step
        (loss = temporal + lam * regularizer).
    """
    F, dF_dt = model.forward_with_derivative(centers)             # Eq. 11 and Eq. 5: [N, B, H, W] each
    temporal = temporal_loss_derivative(dF_dt, event_frames, durations)   # Eq. 6, mean over bins and pixels
    reg = tikhonov(F)                                             # Eq. 9, finite differences
    loss = temporal + lam * reg
    optimizer.zero_grad()                                         # gradients accumulate otherwise
    loss.backward()                                               # double back-propagation through dF/dt
    optimizer.step()
    return loss.detach(), temporal.detach(), reg.detach()


def _inputs_step(rng):
    """Tiny seeded cases: a 3 x 4 sensor, 5 bins, an 8-wide SIREN; stale gradients in place. The first model has
    one network (as in notebook 04), the second two (N = 2, overlapping windows): the step is written for [N, B]
    inputs, so a version that assumes N = 1 (durations.view(-1, 1, 1), centers[0]) fails there."""
    cases = []
    for seed, lam, lr, windows in ((0, 0.05, 1e-3, [[0.0, 1.0]]), (1, 0.5, 3e-3, [[0.0, 0.6], [0.4, 1.0]])):
        model = FrameINR((3, 4), windows, hidden_features=8, hidden_layers=1, omega_0=30.0,
                         first_omega_0=10.0, seed=seed)
        g = torch.Generator().manual_seed(seed)
        for p in model.parameters():                              # stale gradients, as after an earlier step
            p.grad = torch.randn(p.shape, generator=g, dtype=p.dtype)
        opt = torch.optim.Adam(model.parameters(), lr=lr)
        edges = []
        for lo, hi in windows:                                    # 5 bins of unequal lengths in each window
            e = np.sort(rng.uniform(lo, hi, 6))
            e[0], e[-1] = lo, hi
            edges.append(e)
        edges = np.stack(edges)
        centers = torch.as_tensor(0.5 * (edges[:, 1:] + edges[:, :-1]))
        durations = torch.as_tensor(np.diff(edges, axis=1), dtype=torch.float32)
        E = (torch.randint(-2, 3, (len(windows), 5, 3, 4), generator=g) * 0.2).float()
        cases.append(dict(model=model, optimizer=opt, event_frames=E, centers=centers, durations=durations, lam=lam))
    return cases


def _as_float(value):
    """A returned loss as a float; anything that is not one number stays as it is (the comparison names it)."""
    try:
        return float(value)
    except (TypeError, ValueError, RuntimeError):
        return value


def _observe_step(result, args, kwargs):
    """The step's three losses (as floats), the model's parameters after the step, and the optimiser's learning
    rates after it (a step that changes them, a decay inside the step, changes every later step of the loop)."""
    model = kwargs["model"] if "model" in kwargs else args[0]
    optimizer = kwargs["optimizer"] if "optimizer" in kwargs else args[1]
    if isinstance(result, (tuple, list)):
        result = tuple(_as_float(r) for r in result)
    params = {name: p.detach().clone() for name, p in model.named_parameters()}
    lrs = tuple(float(group["lr"]) for group in optimizer.param_groups)
    return {"losses": result, "parameters after the step": params, "optimizer's learning rates after the step": lrs}


def _no_zero_grad(model, optimizer, event_frames, centers, durations, lam):
    F, dF_dt = model.forward_with_derivative(centers)
    temporal = temporal_loss_derivative(dF_dt, event_frames, durations)
    reg = tikhonov(F)
    loss = temporal + lam * reg
    loss.backward()
    optimizer.step()
    return loss.detach(), temporal.detach(), reg.detach()


def _no_step(model, optimizer, event_frames, centers, durations, lam):
    F, dF_dt = model.forward_with_derivative(centers)
    temporal = temporal_loss_derivative(dF_dt, event_frames, durations)
    reg = tikhonov(F)
    loss = temporal + lam * reg
    optimizer.zero_grad()
    loss.backward()
    return loss.detach(), temporal.detach(), reg.detach()


def _no_lam(model, optimizer, event_frames, centers, durations, lam):
    return frame_train_step(model, optimizer, event_frames, centers, durations, 1.0)


def _no_durations(model, optimizer, event_frames, centers, durations, lam):
    return frame_train_step(model, optimizer, event_frames, centers, torch.ones_like(durations), lam)


def _lam_on_temporal(model, optimizer, event_frames, centers, durations, lam):
    F, dF_dt = model.forward_with_derivative(centers)
    temporal = temporal_loss_derivative(dF_dt, event_frames, durations)
    reg = tikhonov(F)
    optimizer.zero_grad()
    (lam * temporal + reg).backward()
    optimizer.step()
    return (lam * temporal + reg).detach(), temporal.detach(), reg.detach()


def _losses_after_step(model, optimizer, event_frames, centers, durations, lam):
    frame_train_step(model, optimizer, event_frames, centers, durations, lam)
    with torch.enable_grad():
        F, dF_dt = model.forward_with_derivative(centers)
    temporal = temporal_loss_derivative(dF_dt, event_frames, durations)
    reg = tikhonov(F)
    return (temporal + lam * reg).detach(), temporal.detach(), reg.detach()


def _regularizer_on_derivative(model, optimizer, event_frames, centers, durations, lam):
    F, dF_dt = model.forward_with_derivative(centers)
    temporal = temporal_loss_derivative(dF_dt, event_frames, durations)
    reg = tikhonov(dF_dt)
    loss = temporal + lam * reg
    optimizer.zero_grad()
    loss.backward()
    optimizer.step()
    return loss.detach(), temporal.detach(), reg.detach()


def _minus_regularizer(model, optimizer, event_frames, centers, durations, lam):
    return frame_train_step(model, optimizer, event_frames, centers, durations, -lam)


def _two_steps(model, optimizer, event_frames, centers, durations, lam):
    out = frame_train_step(model, optimizer, event_frames, centers, durations, lam)
    optimizer.step()
    return out


def _own_optimizer(model, optimizer, event_frames, centers, durations, lam):
    """A new Adam made inside the step at the paper's learning rate: the optimiser passed in is not used."""
    return frame_train_step(model, torch.optim.Adam(model.parameters(), lr=1e-4), event_frames, centers, durations, lam)


def _lr_changed(model, optimizer, event_frames, centers, durations, lam):
    out = frame_train_step(model, optimizer, event_frames, centers, durations, lam)
    for group in optimizer.param_groups:
        group["lr"] *= 0.99
    return out


def _only_temporal(model, optimizer, event_frames, centers, durations, lam):
    return frame_train_step(model, optimizer, event_frames, centers, durations, 0.0)


exercises.register(
    "frame_train_step", frame_train_step, _inputs_step, observe=_observe_step, rtol=1e-4, atol=1e-6,
    hints={
        "call optimizer.zero_grad() before loss.backward(): otherwise the new gradients are added to the "
        "ones left from the previous step":
            _no_zero_grad,
        "the parameters did not change: call optimizer.step() after loss.backward(), and no "
        "optimizer.zero_grad() between the two (it wipes the gradients the step needs)":
            _no_step,
        "weight the Tikhonov term by lam (loss = temporal + lam * regularizer)":
            _no_lam,
        "Eq. 5 multiplies dF/dt by the bin length before comparing with the event frame (pass `durations`)":
            _no_durations,
        "the loss is temporal + lam * Tikhonov: the regularizer is missing":
            _only_temporal,
        "lam weights the regularizer, not the temporal term: loss = temporal + lam * tikhonov(F)":
            _lam_on_temporal,
        "return the losses computed for this step, before optimizer.step(): evaluating them again after the "
        "step reports the next step's losses":
            _losses_after_step,
        "Tikhonov (Eq. 9) regularizes the spatial differences of F, the log intensity, not of dF/dt":
            _regularizer_on_derivative,
        "the regularizer is added: loss = temporal + lam * regularizer (a minus rewards rough frames)":
            _minus_regularizer,
        "one call makes one optimizer.step(): a second step moves the parameters again with the same gradients":
            _two_steps,
        "the step changed the optimiser's learning rate (`group['lr'] *= ...`, a scheduler's step): one call is "
        "one step of the loss at the learning rate it is given; the schedule belongs to the loop outside it "
        "(notebook 04), so leave optimizer.param_groups as they are":
            _lr_changed,
        "use the optimiser passed in: a new one made inside the step (torch.optim.Adam(model.parameters(), ...)) "
        "has its own learning rate and forgets what Adam keeps from one step to the next (its running means)":
            _own_optimizer,
    })
