"""Simulation: the 2-D event simulator on a 240x180 video of 1000 frames.

    python benchmarks/simulate_speed.py            # 1000 frames (target: under 30 s)
    python benchmarks/simulate_speed.py --quick    # 250 frames

Protocol: the built-in "camera" scene (a natural image drifting, rotating and zooming) rendered
at 1000 evenly spaced times over 5 s on 240x180 (about 0.4 px of motion per frame), as log
intensities [1000, 180, 240] float64; ``simulate_video`` with C = 0.2 and the default noise-free
model is timed on that array (the fastest of ``--repeats``). Rendering the video is a property
of the scene, not of the simulator: it is timed and reported separately, as is the whole
``simulate_scene`` call (rendering in chunks + simulation) on the same times.
"""
from __future__ import annotations

import sys
import time

import numpy as np

try:
    from benchmarks.common import best_time, parser, report, row
except ImportError:  # run as a script
    from common import best_time, parser, report, row

from evinr_lite import make_scene, simulate_scene, simulate_video  # noqa: E402


def run(quick: bool = False, repeats: int | None = None, n_frames: int | None = None, log=print) -> list[dict]:
    repeats = repeats or (1 if quick else 3)
    n_frames = n_frames or (250 if quick else 1000)
    duration = 5.0 * n_frames / 1000
    scene = make_scene("camera", sensor_size=(180, 240), duration=duration)
    t = np.linspace(0.0, duration, n_frames)
    t0 = time.perf_counter()
    video = np.concatenate([scene.log_intensity(t[i:i + 100]) for i in range(0, n_frames, 100)])
    render_s = time.perf_counter() - t0
    result = {}
    seconds = best_time(lambda: result.setdefault("ev", simulate_video(video, t, C=0.2, seed=0)), repeats)
    n_events = len(result["ev"])
    sample_rate = (n_frames - 1) / duration
    scene_s = best_time(lambda: simulate_scene(scene, 0.0, duration, sample_rate=sample_rate, C=0.2, seed=0), 1)
    log(f"simulate_video: {n_frames} frames of 240x180 -> {n_events:,} events in {seconds:.2f} s "
        f"({n_frames / seconds:.0f} frames/s); rendering the video took {render_s:.1f} s; "
        f"simulate_scene (render + simulate) {scene_s:.1f} s")
    # the target is for 1000 frames; a quick run scales its time linearly to 1000 frames
    per_1000 = seconds * 1000 / n_frames
    return [row("simulation: simulate_video, 1000 frames of 240x180", per_1000, "s", target=30.0,
                higher_is_better=False,
                note=(f"{n_frames} frames simulated in {seconds:.2f} s" + (" (scaled to 1000)" if n_frames != 1000 else "")
                      + f", {n_events:,} events; rendering the scene {render_s:.1f} s; simulate_scene "
                        f"(render + simulate) {scene_s:.1f} s"),
                n_frames=n_frames, seconds=seconds, n_events=n_events, render_s=render_s, simulate_scene_s=scene_s)]


def main(argv=None) -> int:
    p = parser(__doc__, "250 frames, one repeat", device=False)
    p.add_argument("--frames", type=int, default=None)
    a = p.parse_args(argv)
    rows = run(a.quick, a.repeats, a.frames)
    report(rows, a.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
