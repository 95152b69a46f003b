"""Notebook 02's exercise on the ON/OFF balance from the intervals between events
(evinr_lite.teaching.events2d.interval_imbalance): the reference passes, the package agrees with it, and
each plausible mistake fails with the hint that names it."""
import contextlib
import io
import warnings

import numpy as np
import pytest

from evinr_lite.method.balance import interval_imbalance as pooled, interval_sums
from evinr_lite.sim.scenes import OscillatingScene
from evinr_lite.sim.simulate import simulate_scene
from evinr_lite.teaching import events2d, exercises


def _report(fn):
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ok = exercises.check("interval_imbalance", fn)
    return ok, buf.getvalue()


def test_the_reference_passes_and_agrees_with_the_package():
    assert _report(events2d.interval_imbalance)[0]
    scene = OscillatingScene("astronaut", (30, 40), 4.0, path=((12.0, 4.0, 4.0, 0.0), (2.0, 3.0, 1.3, 1.0)))
    events = simulate_scene(scene, C=0.225, C_pos=0.25, C_neg=0.20, seed=0)
    mine = events2d.interval_imbalance(events)
    sums = interval_sums(events)[:4]
    assert mine == pytest.approx(pooled(sums, np.ones(events.sensor_size, bool)), abs=1e-4)   # the kit's, all pixels
    assert abs(mine - 0.05 / 0.45) < 0.05                       # near the true b of C+ 0.25 / C- 0.20


def _pairs(events, per_pixel=True, skip_other_polarity=False):
    """(ON intervals, OFF intervals) in seconds, by a plain loop: a learner's own way of pairing the events."""
    W = events.sensor_size[1]
    dts = {1: [], -1: []}
    last = {}
    for t, x, y, p in zip(events.t, events.x, events.y, events.p):
        pix = int(y) * W + int(x) if per_pixel else 0
        key = (pix, int(p)) if skip_other_polarity else pix
        if key in last and last[key][1] == int(p):
            dts[int(p)].append(t - last[key][0])
        last[key] = (t, int(p))
    return np.array(dts[1]), np.array(dts[-1])


def _b(on, off, floor=events2d.MIN_INTERVAL, of_means=False):
    if not len(on) or not len(off):
        return float("nan")
    with np.errstate(divide="ignore", invalid="ignore"):
        if of_means:
            r = np.log(np.maximum(on, floor).mean() / np.maximum(off, floor).mean())
        else:
            r = np.log(np.maximum(on, floor)).mean() - np.log(np.maximum(off, floor)).mean()
    return float(np.tanh(r / 2))


@pytest.mark.parametrize("wrong, says", [
    (lambda events: _b(*_pairs(events, per_pixel=False)), "per pixel"),
    (lambda events: _b(*_pairs(events, skip_other_polarity=True)), "consecutive events of the pixel with the same polarity"),
    (lambda events: _b(*_pairs(events), of_means=True), "average the log intervals"),
    (lambda events: 2 * np.arctanh(_b(*_pairs(events))), "tanh(r / 2)"),
    (lambda events: -_b(*_pairs(events)), "ON minus OFF"),
    (lambda events: _b(*_pairs(events), floor=0.0), "MIN_INTERVAL"),
    (lambda events: float(np.tanh(np.log(np.mean(np.diff(events.t[events.p > 0]))) / 2)), "not match"),
    (lambda events: 0.0 if np.isnan(_b(*_pairs(events))) else _b(*_pairs(events)), "not match"),   # 0 for "no estimate"
])
def test_wrong_solutions_fail_with_their_hint(wrong, says):
    ok, text = _report(wrong)
    assert not ok and says in text, text


def test_a_plain_loop_passes():
    assert _report(lambda events: _b(*_pairs(events)))[0]
