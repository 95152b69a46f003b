"""Memory at the pixel scale: the API's guard, and the estimate against a measured peak.

- ``reconstruct`` refuses a reconstruction that cannot fit before it allocates anything (issue 25
  item 5: ``EvINRConfig(bin_duration=1e-7)`` was killed by the kernel), naming the setting to change,
  and ``memory_guard=False`` skips the check;
- the streaming estimate (``estimate_memory(..., streaming=True)``) is within 25 % of the peak
  resident memory of a streamed ``evinr-lite reconstruct`` measured in a subprocess, and it does
  not grow with the recording's length while the whole-sequence estimate does.
"""
import json
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from evinr_lite import EvINRConfig, make_scene, simulate_scene
from evinr_lite.core.events import EventDataError
from evinr_lite.method import solver
from evinr_lite.method.memory import estimate_memory


@pytest.fixture(scope="module")
def events():
    return simulate_scene(make_scene("camera", sensor_size=(60, 80), duration=1.0), C=0.2, seed=0)


def test_reconstruct_refuses_what_cannot_fit_before_training(events, monkeypatch):
    def never(*a, **k):
        raise AssertionError("training started")

    monkeypatch.setattr(solver, "train_frame_inr", never)
    with pytest.raises(EventDataError, match="bin_duration") as err:
        solver.reconstruct(events, [0.5], EvINRConfig(C=0.2, bin_duration=1e-7, progress=False))
    assert "GiB" in str(err.value) and "free" in str(err.value)
    with pytest.raises(EventDataError, match="output frames"):
        solver.reconstruct(events, np.linspace(0.01, 0.99, 2_000_000), EvINRConfig(C=0.2, progress=False))
    # the override: the check is skipped (and training is reached)
    with pytest.raises(AssertionError, match="training started"):
        solver.reconstruct(events, [0.5], EvINRConfig(C=0.2, bin_duration=1e-7, progress=False), memory_guard=False)


def test_streaming_memory_is_set_by_the_window_not_the_length():
    cfg = EvINRConfig()
    short = estimate_memory((720, 1280), 0.0, 20.0, 60_000_000, 400, cfg, streaming=True)
    long = estimate_memory((720, 1280), 0.0, 600.0, 1_800_000_000, 12_000, cfg, streaming=True)
    whole = [estimate_memory((720, 1280), 0.0, s, 3_000_000 * s, 20 * s, cfg)["total"] for s in (20.0, 600.0)]
    # one window (at most tau: 4.4 s here, 5 s there) at a time; only the offset grid grows with the
    # length: 8 float32 frames per window beyond 8 windows (the whole-sequence solve's rule)
    grid = 8 * 4 * 720 * 1280 * (long["n_windows"] - max(short["n_windows"], 8))
    assert long["total"] - grid <= 1.2 * short["total"]
    assert long["parts"]["networks"] == short["parts"]["networks"]
    assert whole[1] > 10 * whole[0]
    assert short["parts"]["networks"] < 1.5e9           # one head of 257 x 921,600 float32 values


_CHILD = textwrap.dedent("""
    import json, resource, sys
    import numpy as np
    from evinr_lite import make_scene, simulate_scene
    from evinr_lite.io.canonical import CanonicalWriter
    H, W, dur, path, out = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3]), sys.argv[4], sys.argv[5]
    ev = simulate_scene(make_scene("camera", sensor_size=(H, W), duration=2.0), C=0.2, seed=0)
    with CanonicalWriter(path, sensor_size=(H, W), C=0.2) as w:
        for k in range(int(np.ceil(dur / 2.0))):
            keep = ev.t + 2.0 * k < dur
            w.add_events(ev.t[keep] + 2.0 * k, ev.x[keep], ev.y[keep], ev.p[keep])
""")


def test_estimate_is_within_a_quarter_of_the_measured_peak(tmp_path):
    path, out = tmp_path / "rec.h5", tmp_path / "out"
    subprocess.run([sys.executable, "-c", _CHILD, "180", "240", "6", str(path), str(out)], check=True)
    run = subprocess.run([sys.executable, "-c", textwrap.dedent(f"""
        import json, resource
        from evinr_lite.apps.recon_job import run_reconstruct
        run = run_reconstruct({str(path)!r}, {str(out)!r}, fps=20, video=False, progress=False, log=lambda *a: None)
        # VmHWM: this process's own peak (getrusage's ru_maxrss also counts the forked parent's image
        # before exec, which is the whole pytest process late in a suite)
        hwm = next(int(l.split()[1]) for l in open("/proc/self/status") if l.startswith("VmHWM:"))
        print(json.dumps({{"peak": hwm * 1024, "estimate": run["memory_estimate_bytes"]}}))
    """)], check=True, capture_output=True, text=True)
    got = json.loads(run.stdout.strip().splitlines()[-1])
    assert abs(got["estimate"] - got["peak"]) <= 0.25 * got["peak"], got
