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


def test_config_overrides_parse_and_refuse():
    assert se.config_overrides("balance=none,lam=0.1", _raise) == {"balance": "none", "lam": 0.1}
    assert se.config_overrides("", _raise) == {}
    for bad, says in (("bogus=1", "bogus"), ("balance=sometimes", "balance")):
        try:
            se.config_overrides(bad, _raise)
        except SystemExit as exc:
            assert says in str(exc) and "--set" in str(exc)
        else:
            raise AssertionError(f"{bad!r} was accepted")


def _raise(message):
    raise SystemExit(message)


def test_options_reach_the_method_and_leave_the_committed_results(tmp_path, capsys):
    """--events signal, --true-thresholds and --set change what the kit is given; their run writes only
    the files it is told to (the committed results are not the default target)."""
    import json

    def run(*options):
        out = tmp_path / "r.json"
        assert se.main(["--scenes", "coffee_warp", "--events", "signal", "--set", "balance=counts", *options,
                        "--json", str(out)]) == 0
        return json.loads(out.read_text())

    counts, given = run(), run("--true-thresholds")
    assert counts["events"] == "signal" and counts["set"] == {"balance": "counts"} and not counts["true_thresholds"]
    assert given["true_thresholds"] and set(given["scenes"]) == {"coffee_warp"}
    mse = lambda got: got["scenes"]["coffee_warp"]["scores"]["kit"]["mse_none"]          # noqa: E731
    # the counts rule keeps a tenth of coffee_warp's imbalance (C+ 0.24 / C- 0.16); given the pair, the error falls
    assert mse(counts) - mse(given) > 1e-3
    committed = json.loads((Path(se.__file__).parent / "static_error_results.json").read_text())
    assert committed["set"] == {} and not committed["true_thresholds"]           # the default run, untouched
    assert "| coffee_warp |" in capsys.readouterr().out          # the table is printed, no markdown file named


def test_prior_tilt_error_of_a_plane_and_of_a_skewed_texture():
    H, W, P, s = 4, 41, 8, 0.05
    x = np.arange(W, dtype=np.float64)
    plane = np.broadcast_to(0.01 * x, (3, H, W))                   # a static plane: invisible to every prior
    err = se.prior_tilt_error(plane, C=0.2)
    for k in ("median", "mean", "hybrid"):
        np.testing.assert_allclose(err[k], [-0.01 * (W - 1), 0.0], atol=1e-12)
    # a sawtooth (slow rise s per px, one sharp drop) moving one pixel per frame over a whole period:
    # each edge's gradient is s in 7 of 8 frames, so the median says s, while the mean over time is 0
    saw = np.stack([np.broadcast_to(s * ((x - t) % P), (H, W)) for t in range(P)])
    err = se.prior_tilt_error(saw, C=0.2)
    np.testing.assert_allclose(err["median"][0], -s * (W - 1), rtol=1e-12)
    np.testing.assert_allclose(err["mean"][0], 0.0, atol=1e-12)
    np.testing.assert_allclose(err["hybrid"][0], -s * (W - 1), rtol=1e-12)   # 7 of 8 frames at the median
