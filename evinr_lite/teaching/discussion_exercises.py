"""Notebook 08 (discussion experiments): exercise registrations.

- ``highpass_per_event``: the high-pass filter of Scheerlinck et al. event by event; the reference
  is the library's :func:`evinr_lite.method.baselines.highpass_per_event`, which the tests pin to
  the vectorised :func:`~evinr_lite.method.baselines.highpass_filter`;
- ``render_event_counts``: events re-rendered from a model's log intensity at bin boundaries; the
  reference is :func:`evinr_lite.evaluation.enhance.render_event_counts`.

Each hint is a deliberately wrong version (same signature) that makes one common mistake.
"""
from __future__ import annotations

import math

import numpy as np

from ..evaluation.enhance import render_counts, render_event_counts
from ..method.baselines import highpass_per_event
from . import exercises

__all__: list[str] = []


def _inputs_highpass(rng):
    cases = []
    # C and t_end differ between cases too: a version that fixes either to one value fails. The first sensor is
    # one row and one column larger than the events reach (pixels that never fired): a state sized from the
    # events (y.max() + 1, x.max() + 1) comes out too small. The second recording's clock reads 1000 s (t_start =
    # 1000): times held in float32 (spacing 61 us there) change every decay by about alpha x 30 us
    for n, (H, W), alpha, C, t_end, extra, t0 in ((12, (2, 3), 2 * math.pi, 0.2, 1.2, 1, 0.0),
                                                  (40, (3, 4), 5.0, 0.35, 1.5, 0, 1000.0),
                                                  (25, (1, 5), 0.0, 0.15, 1.0, 0, 0.0)):
        t = t0 + np.sort(rng.uniform(0.0, 1.0, n))
        cases.append(dict(t=t, x=rng.integers(0, W, n), y=rng.integers(0, H, n), p=rng.choice([-1, 1], n),
                          sensor_size=(H + extra, W + extra), C=C, alpha=alpha, t_end=t0 + t_end)
                     | ({"t_start": t0} if t0 else {}))
    return cases


def _no_final_decay(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    H, W = sensor_size
    state = np.zeros((H, W))
    t_last = np.full((H, W), float(t_start))
    for ti, xi, yi, pi in zip(t, x, y, p):
        state[yi, xi] = np.exp(-alpha * (ti - t_last[yi, xi])) * state[yi, xi] + C * pi
        t_last[yi, xi] = ti
    return state


def _global_last_time(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    H, W = sensor_size
    state = np.zeros((H, W))
    t_prev = float(t_start)
    for ti, xi, yi, pi in zip(t, x, y, p):
        state[yi, xi] = np.exp(-alpha * (ti - t_prev)) * state[yi, xi] + C * pi
        t_prev = ti
    return state * np.exp(-alpha * (t_end - t_prev))


def _last_time_not_updated(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    """The mistake of never updating t_last: every event decays the state from t_start, not from the pixel's
    previous event."""
    H, W = sensor_size
    state = np.zeros((H, W))
    t_last = np.full((H, W), float(t_start))
    for ti, xi, yi, pi in zip(t, x, y, p):
        state[yi, xi] = np.exp(-alpha * (ti - t_last[yi, xi])) * state[yi, xi] + C * pi
    return state * np.exp(-alpha * (t_end - t_last))


def _decay_after_adding(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    H, W = sensor_size
    state = np.zeros((H, W))
    t_last = np.full((H, W), float(t_start))
    for ti, xi, yi, pi in zip(t, x, y, p):
        state[yi, xi] = np.exp(-alpha * (ti - t_last[yi, xi])) * (state[yi, xi] + C * pi)
        t_last[yi, xi] = ti
    return state * np.exp(-alpha * (t_end - t_last))


def _state_transposed(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    """The state indexed [x, y] (shape (W, H)) instead of [y, x]."""
    return highpass_per_event(t, x, y, p, sensor_size, C, alpha, t_end, t_start).T


def _final_decay_from_last_event(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    """Every pixel decayed to t_end from the stream's last event, not from its own."""
    state = _no_final_decay(t, x, y, p, sensor_size, C, alpha, t_end, t_start)
    return state * np.exp(-alpha * (t_end - (t[-1] if len(t) else t_start)))


def _growth(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    """exp(+alpha dt): the state grows between events instead of decaying."""
    return highpass_per_event(t, x, y, p, sensor_size, C, -alpha, t_end, t_start)


def _fancy_index_sum(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    """The closed form sum of C p exp(-alpha (t_end - t)) per pixel, written with ``state[y, x] += ...``."""
    state = np.zeros(sensor_size)
    state[np.asarray(y), np.asarray(x)] += C * np.asarray(p) * np.exp(-alpha * (t_end - np.asarray(t, np.float64)))
    return state


def _integer_state(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    """The state array made with an integer dtype (np.zeros_like(x), np.zeros(..., dtype=int)): every decayed
    value is truncated toward 0 when stored."""
    H, W = sensor_size
    state = np.zeros((H, W), dtype=np.int64)
    t_last = np.full((H, W), float(t_start))
    for ti, xi, yi, pi in zip(t, x, y, p):
        state[yi, xi] = np.exp(-alpha * (ti - t_last[yi, xi])) * state[yi, xi] + C * pi
        t_last[yi, xi] = ti
    return state * np.exp(-alpha * (t_end - t_last))


def _alpha_times_two_pi(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    return highpass_per_event(t, x, y, p, sensor_size, C, 2 * math.pi * alpha, t_end, t_start)


def _alpha_over_two_pi(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    return highpass_per_event(t, x, y, p, sensor_size, C, alpha / (2 * math.pi), t_end, t_start)


def _alpha_in_degrees(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    return highpass_per_event(t, x, y, p, sensor_size, C, np.deg2rad(alpha), t_end, t_start)


def _t_last_set_first(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    """t_last set to the event's time before the decay, which is then exp(0) = 1: no decay between events."""
    H, W = sensor_size
    state = np.zeros((H, W))
    t_last = np.full((H, W), float(t_start))
    for ti, xi, yi, pi in zip(t, x, y, p):
        t_last[yi, xi] = ti
        state[yi, xi] = np.exp(-alpha * (ti - t_last[yi, xi])) * state[yi, xi] + C * pi
    return state * np.exp(-alpha * (t_end - t_last))


def _highpass_split_exponentials(t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0):
    """A wrong version (for the hint): exp(-alpha t) / exp(-alpha t_last), each factor from the clock's zero:
    both underflow to 0 on a clock at 1000 s (0 / 0 is NaN)."""
    H, W = sensor_size
    state = np.zeros((H, W))
    t_last = np.full((H, W), float(t_start))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
        for ti, xi, yi, pi in zip(t, x, y, p):
            state[yi, xi] = np.exp(-alpha * ti) / np.exp(-alpha * t_last[yi, xi]) * state[yi, xi] + C * pi
            t_last[yi, xi] = ti
        return state * np.exp(-alpha * t_end) / np.exp(-alpha * t_last)


exercises.register(
    "highpass_per_event", highpass_per_event, _inputs_highpass, rtol=1e-6, atol=1e-10,
    hints={
        "exp(-alpha t) / exp(-alpha t_last) underflows: on a clock at 1000 s both factors are 0 (and 0 / 0 is "
        "NaN); decay by the time since the pixel's last event, np.exp(-alpha * (t - t_last))":
            _highpass_split_exponentials,
        "images are indexed [y, x] (row, column): the state is np.zeros((H, W)) with H, W = sensor_size, "
        "updated at state[y, x]": _state_transposed,
        "after the last event, decay every pixel to t_end (exp(-alpha (t_end - t_last)))": _no_final_decay,
        "each pixel decays since its own last event: keep one t_last per pixel, not one for the stream":
            _global_last_time,
        "decay the old state first, then add C * p (the new event has not decayed yet)": _decay_after_adding,
        "after each event, set that pixel's t_last to the event's time: the next decay runs from the pixel's "
        "previous event, not from t_start": _last_time_not_updated,
        "decay each pixel to t_end from its own last event, exp(-alpha (t_end - t_last[y, x])), not from the "
        "stream's last event t[-1]":
            _final_decay_from_last_event,
        "alpha is already in rad/s: decay by exp(-alpha dt), without another factor 2 pi":
            _alpha_times_two_pi,
        "alpha is already in rad/s: decay by exp(-alpha dt), without dividing by 2 pi (that would make it a "
        "frequency in Hz)":
            _alpha_over_two_pi,
        "alpha is an angular frequency in radians per second already, not degrees: decay by exp(-alpha dt) "
        "as it is, without np.deg2rad / math.radians (a factor pi / 180)":
            _alpha_in_degrees,
        "the state decays: exp(-alpha * (t - t_last)), with the minus sign (exp(+alpha dt) grows without bound)":
            _growth,
        "`state[y, x] += ...` adds only one of the events that share a pixel (fancy indexing does not accumulate "
        "repeated indices): loop over the events, or accumulate with np.add.at(state, (y, x), ...)":
            _fancy_index_sum,
        "the state array has an integer dtype, so every stored value is truncated: make it float "
        "(np.zeros((H, W)), not np.zeros_like(x) or dtype=int)":
            _integer_state,
        "set the pixel's t_last = t after its decay, not before: updated first, the decay exp(-alpha (t - t_last)) "
        "is exp(0) = 1 and the state never decays between events (only at the end, to t_end)":
            _t_last_set_first,
        "timestamps must stay float64: in float32 a time near 1000 s is rounded to a multiple of 61 us, which "
        "changes every decay exp(-alpha (t - t_last)); keep t as it is given (np.asarray(t, dtype=np.float64))":
            lambda t, x, y, p, sensor_size, C, alpha, t_end, t_start=0.0: highpass_per_event(
                np.asarray(t, np.float32), x, y, p, sensor_size, C, alpha, t_end, t_start),
    })


def _inputs_render(rng):
    cases = []
    # [B + 1, H, W], as notebook 08 states it (a [B + 1, P] case would refuse its `B1, H, W = L.shape`)
    for B, shape, C in ((4, (2, 3), 0.2), (6, (3, 4), 0.25), (5, (1, 6), 0.5)):
        steps = rng.normal(0.0, 2.5 * C, (B,) + shape)
        L = np.concatenate([rng.normal(0.0, 1.0, (1,) + shape), steps]).cumsum(axis=0)
        cases.append(dict(L_boundaries=L, C=C))
    # the threshold rule: a change of exactly C fires one event (n = trunc(change / C)). Steps of whole
    # quarters with C = 0.25 are exact in binary floating point, so a strict "> C" test fails here
    steps = np.array([[0.25, -0.25], [0.5, 0.0], [-0.75, 0.25], [0.25, 1.0]])
    cases.append(dict(L_boundaries=np.concatenate([np.zeros((1, 2)), steps]).cumsum(axis=0)[:, None, :], C=0.25))
    return cases


def _reference_fixed(L_boundaries, C):
    """The mistake of never moving the reference: every bin counts from L(b_0), so a change is counted
    again in every later bin."""
    L = np.asarray(L_boundaries, dtype=np.float64)
    return np.trunc((L[1:] - L[0]) / C).astype(np.int64)


def _no_carry(L_boundaries, C):
    L = np.asarray(L_boundaries, dtype=np.float64)
    return np.trunc(np.diff(L, axis=0) / C).astype(np.int64)


def _round_nearest(L_boundaries, C):
    return render_counts(L_boundaries, C, np.round)


def _reference_to_level(L_boundaries, C):
    L = np.asarray(L_boundaries, dtype=np.float64)
    ref = L[0].copy()
    out = np.empty((L.shape[0] - 1,) + L.shape[1:], dtype=np.int64)
    for k in range(1, L.shape[0]):
        n = np.trunc((L[k] - ref) / C)
        ref = np.where(n != 0, L[k], ref)
        out[k - 1] = n
    return out


def _floor_not_trunc(L_boundaries, C):
    return render_counts(L_boundaries, C, np.floor)


def _levels_on_a_grid(L_boundaries, C):
    """Counts as differences of trunc((L - L(b_0)) / C): levels fixed at L(b_0) + k C, no moving reference."""
    L = np.asarray(L_boundaries, dtype=np.float64)
    return np.diff(np.trunc((L - L[0]) / C), axis=0).astype(np.int64)


def _strict_threshold(L_boundaries, C):
    """The mistake of firing only once the change *exceeds* C (``> C`` instead of ``>= C``)."""
    def strict(x):
        return np.sign(x) * np.maximum(np.ceil(np.abs(x)) - 1, 0)
    return render_counts(L_boundaries, C, strict)


def _reference_by_modulo(L_boundaries, C):
    """The reference moved to L - (L - ref) % C: numpy's % is a floor modulo, so after a fall the reference lands a
    whole C below the last level crossed."""
    L = np.asarray(L_boundaries, dtype=np.float64)
    ref = L[0].copy()
    out = np.empty((L.shape[0] - 1,) + L.shape[1:], dtype=np.int64)
    for k in range(1, L.shape[0]):
        out[k - 1] = np.trunc((L[k] - ref) / C)
        ref = L[k] - (L[k] - ref) % C
    return out


exercises.register(
    "render_event_counts", render_event_counts, _inputs_render,
    hints={
        "a change of exactly C fires one event: the rule is |change| >= C (n = trunc(change / C)), not > C":
            _strict_threshold,
        "OFF events round toward zero too: np.trunc(-1.5) = -1, np.floor(-1.5) = -2": _floor_not_trunc,
        "carry the remainder: compare with a reference level that moves by whole steps n * C, "
        "not with the previous boundary": _no_carry,
        "a camera fires only once the change reaches C: round toward zero (np.trunc), not to the nearest": _round_nearest,
        "move the reference by n * C, not to the current level (the part below C must carry over)":
            _reference_to_level,
        "move the reference after each bin (ref += n * C): a reference that stays at L(b_0) counts the same "
        "change again in every later bin": _reference_fixed,
        "the reference moves with the events (ref += n * C after each bin), not on a fixed grid of levels L(b_0) + "
        "k C: after a rise and a partial fall the grid fires an OFF event that the camera does not":
            _levels_on_a_grid,
        "move the reference by the whole steps fired, ref += n * C: L - (L - ref) % C is not the same after a fall, "
        "since numpy's % is a floor modulo (-0.3 % 0.25 is 0.2, not -0.05)":
            _reference_by_modulo,
    })
