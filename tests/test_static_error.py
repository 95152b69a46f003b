"""The error decomposition of benchmarks/static_error.py: its parts add up to the error, and each
kind of error lands in its own part."""
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks import static_error as se  # noqa: E402


def _error(parts):
    return parts["level"] + parts["tilt"] + parts["coarse"] + parts["fine"] + parts["changes"]


def test_parts_add_up_to_the_error():
    rng = np.random.default_rng(0)
    L, L_true = rng.normal(size=(6, 20, 30)), rng.normal(size=(6, 20, 30))
    parts = se.decompose(L, L_true)
    np.testing.assert_allclose(_error(parts), L - L_true, atol=1e-12)
    assert abs(parts["changes"].mean(axis=0)).max() < 1e-12          # the changes share no static part


def test_each_error_lands_in_its_part():
    H, W = 40, 60
    y, x = np.mgrid[0:H, 0:W].astype(np.float64)
    rng = np.random.default_rng(1)
    L_true = rng.normal(size=(5, H, W))
    ramp = 0.02 * (x - x.mean()) - 0.01 * (y - y.mean())             # rises 1.18 across x, falls 0.39 down y
    noise = rng.normal(scale=0.3, size=(H, W))
    noise -= se.plane(noise)[0] + noise.mean()
    cases = {"level": 0.7 + 0 * x, "tilt": ramp, "fine": noise, "changes": rng.normal(size=(5, H, W))}
    for part, err in cases.items():
        if part == "changes":
            err = err - err.mean(axis=0)
        parts = se.decompose(L_true + err, L_true)
        sizes = {k: (abs(v) if k == "level" else se.rms(v)) for k, v in parts.items()}
        assert sizes[part] > 0.1, (part, sizes)
        others = {k: v for k, v in sizes.items() if k != part and not (part == "fine" and k == "coarse")}
        assert max(others.values()) < 1e-9 * max(sizes[part], 1), (part, sizes)
    _, ax, ay = se.plane(ramp)
    np.testing.assert_allclose([ax, ay], [0.02 * (W - 1), -0.01 * (H - 1)], rtol=1e-12)


def test_fine_noise_is_mostly_fine():
    rng = np.random.default_rng(2)
    noise = rng.normal(scale=0.3, size=(64, 64))
    parts = se.decompose(noise[None], np.zeros((1, 64, 64)))
    assert se.rms(parts["fine"]) > 10 * se.rms(parts["coarse"])
