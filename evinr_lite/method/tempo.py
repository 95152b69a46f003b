"""The temporal scale: shorter bins and a faster temporal prior where the scene changes fast at a pixel.

The kit's bins (``bin_duration`` 1/32 s) and its temporal prior (``first_omega_per_s`` 5) were chosen
on scenes whose pixels turn around (a run of ON events followed by OFF, or back) once or twice a
second. A scene shaken fast turns every pixel around several times a second: a pixel then rises and
falls within a few bins, and the network, smooth on the scale of a second, averages the swing away.
The events say how fast: a **polarity reversal** at a pixel (an event whose polarity differs from the
pixel's event before it) is a turn of its log intensity, so reversals per second are twice the
pixel's temporal frequency, whatever the contrast or the threshold. The rule:

    f = the median, over the pixels that fired at least MIN_EVENTS times, of their reversals per second
    s = clip(f / FLIPS_REF, 1, MAX_SCALE)
    bins: bin_duration / s;   first layer: first_omega_per_s x s (or first_omega_0 x s)

so a scene at up to FLIPS_REF reversals per pixel and second (every scene of the zoo but its fast
shake) is trained exactly as before, and one at 10 gets 4x shorter bins and a 4x faster prior.
The counts are those of the events the solver trains on (hot pixels and background activity
removed, :mod:`~evinr_lite.method.prepare`): noise flips polarity at random. ``EvINRConfig(temporal_scale=s)``
sets s by hand; 1 keeps the base bins and prior (the paper's and v0_1's recipes).
"""
from __future__ import annotations

import numpy as np

from ..core.checks import host_array, is_real_number, real_number
from ..core.events import EventDataError
from .balance import interval_stride
from .denoise import check_count_pair

__all__ = ["FLIPS_REF", "MAX_SCALE", "MIN_EVENTS", "MIN_SCALE", "SCALE_RANGE", "scale_floor_message",
           "flip_rate", "scale_from_rate", "temporal_scale"]

FLIPS_REF = 2.5    # reversals per pixel and second up to which the base bins and prior stand
MAX_SCALE = 4.0    # at most 4x shorter bins (1/128 s from 1/32) and a 4x faster prior: bins cost memory and time
MIN_EVENTS = 4     # a pixel's events for its reversals to count (one or two events cannot reverse often)
# the least scale set by hand: 64x longer bins and a 64x slower prior (5/64 rad per second). Below, the first layer
# hardly changes over a window, the network's time derivative cannot follow the events and its log intensity
# diverges (a scale of 1e-9 gave frames of 0 and 1 at a "gain" of 10^26, or an overflow in the tone map)
MIN_SCALE = 1.0 / 64
SCALE_RANGE = "a number from 1/64 (tempo.MIN_SCALE) up"   # a hand-set scale, in messages (as the CLI's help)


def scale_floor_message(name: str, value) -> str:
    """The refusal of a hand-set temporal scale below MIN_SCALE (``name``: the field or the flag)."""
    return (f"{name}={value!r} is below {MIN_SCALE:g} (1/64: bins 64x longer and a temporal prior 64x slower than the "
            f"recipe's); the network could not follow the events in time and its log intensity diverges: use 1 (the "
            f"recipe's bins and prior), a number from {MIN_SCALE:g} up, or 'auto'")


def flip_rate(flips, n_events, span_s: float) -> float:
    """The median reversals per second over the pixels with at least MIN_EVENTS events, or NaN when none.

    Args:
        flips: float [H, W] polarity reversals per pixel (:attr:`~evinr_lite.method.balance.PolarityCounts.flips`),
            counted on :func:`~evinr_lite.method.balance.interval_stride`'s grid (large sensors: every s-th
            row and column; the others hold 0 and are left out).
        n_events: float [H, W] events per pixel over the same span (ON + OFF).
        span_s: the span's length in seconds (> 0).
    """
    flips, n_events = check_count_pair(flips, n_events, "flip_rate: ", names=("flips", "n_events"))
    span_s = real_number(span_s, "flip_rate: span_s", lo=0, lo_open=True, hint="the span's length, a positive number of seconds")
    if flips.size == 0:
        return float("nan")
    s = interval_stride(flips.shape)
    f, n = flips[::s, ::s], n_events[::s, ::s]
    active = n >= MIN_EVENTS
    return float(np.median(f[active]) / span_s) if active.any() else float("nan")


def scale_from_rate(rate: float) -> float:
    """s = clip(rate / FLIPS_REF, 1, MAX_SCALE); 1 for NaN (no pixel fired often enough to tell)."""
    value = float(host_array(rate)) if is_real_number(rate) else None
    if value is None or value < 0:
        raise EventDataError(f"scale_from_rate: rate must be polarity reversals per pixel and second (a number >= 0, "
                             f"or NaN where no pixel fired often enough), got {rate!r}")
    rate = value
    return 1.0 if not np.isfinite(rate) else float(np.clip(rate / FLIPS_REF, 1.0, MAX_SCALE))


def temporal_scale(flips, n_events, span_s: float) -> float:
    """The scale s for ``temporal_scale="auto"`` from a span's per-pixel reversals and counts."""
    return scale_from_rate(flip_rate(flips, n_events, span_s))
