"""lam="auto" (method/smoothing.py): the regularizer's weight from the events' activity per window."""
import numpy as np
import pytest

from evinr_lite import EvINRConfig, make_scene, simulate_scene
from evinr_lite.core.events import EventDataError
from evinr_lite.method.balance import polarity_counts
from evinr_lite.method.prepare import plan_from_counts
from evinr_lite.method.ensemble import split_windows
from evinr_lite.method.smoothing import LAM_MAX, LAM_MIN, LAM_SCALE, activity, auto_lam, window_fraction
from evinr_lite.method.solver import reconstruct
from evinr_lite.method.training import train_frame_inr


def test_a_global_change_of_light_is_no_activity():
    n = np.full((4, 5), 12)
    assert activity(n, np.zeros_like(n)) == 0.0          # every pixel fired OFF only: light fell, no texture
    assert activity(n, n) == 24.0                         # came and went: all of them count
    assert activity([[3, 0]], [[1, 5]]) == 1.0            # 2 min(3, 1) = 2 and 0, mean 1


def test_lam_falls_as_activity_grows_within_its_bounds():
    ms = [0.0, 1.0, 4.0, 6.0, 8.0, 12.0, 20.0, 50.0]
    lams = [auto_lam(np.full((3, 3), m / 2), np.full((3, 3), m / 2)) for m in ms]
    assert lams[0] == LAM_MAX and lams[-1] == LAM_MIN
    assert all(a >= b for a, b in zip(lams, lams[1:]))
    assert all(LAM_MIN <= v <= LAM_MAX for v in lams)
    assert auto_lam(np.full((3, 3), 5.0), np.full((3, 3), 5.0)) == pytest.approx(LAM_SCALE / 100)   # m = 10
    # the same counts over a span twice as long as one window: half the activity per window, 4x the lam
    half = auto_lam(np.full((3, 3), 6.0), np.full((3, 3), 6.0), fraction=0.5)
    assert half == pytest.approx(4 * auto_lam(np.full((3, 3), 6.0), np.full((3, 3), 6.0)))


def test_window_fraction_follows_the_windows():
    assert window_fraction(0.0, 3.0, 5.0, 0.5) == 1.0
    w = split_windows(0.0, 20.0, 5.0, 0.5)
    assert window_fraction(0.0, 20.0, 5.0, 0.5) == pytest.approx((w[0, 1] - w[0, 0]) / 20.0)
    assert window_fraction(0.0, 20.0, None, 0.5) == 1.0


@pytest.mark.parametrize("bad", ["tikhonov", "AUTO", None, -0.1, float("nan")])
def test_lam_is_a_number_or_auto(bad):
    with pytest.raises(EventDataError, match="lam"):
        EvINRConfig(lam=bad)
    assert EvINRConfig().lam == "auto" and EvINRConfig(lam=0.05).lam == 0.05


@pytest.fixture(scope="module")
def events():
    scene = make_scene("camera", sensor_size=(30, 40), duration=2.0)
    return simulate_scene(scene, 0.0, 2.0, C=0.2, seed=0)


def test_reconstruct_resolves_auto_from_the_span_and_says_which(events):
    q = np.linspace(0.1, 1.9, 5)
    rec = reconstruct(events, q, EvINRConfig(C=0.2, hidden_features=32, progress=False))
    want, _ = plan_from_counts(*polarity_counts(events), EvINRConfig(C=0.2), 1.0)
    assert isinstance(rec.config.lam, float) and LAM_MIN <= rec.config.lam <= LAM_MAX
    assert rec.config.lam == pytest.approx(want.lam) and rec.history["lam"] == pytest.approx(want.lam)
    fixed = reconstruct(events, q, EvINRConfig(C=0.2, hidden_features=32, lam=rec.config.lam, progress=False))
    np.testing.assert_array_equal(fixed.frames, rec.frames)              # auto is that number, nothing else


def test_a_direct_training_call_resolves_auto_too(events):
    windows = split_windows(0.0, 2.0, 5.0, 0.5)
    _, history = train_frame_inr(events, windows, EvINRConfig(C=0.2, hidden_features=16, progress=False))
    assert history["lam"] == pytest.approx(auto_lam(*polarity_counts(events)))
