"""The README's main job on a built-in synthetic scene (no download).

Simulate events from a moving natural image, reconstruct frames at a few timestamps with EvINR
(the kit's default, ``EvINRConfig()``; pass ``config=EvINRConfig.paper(...)`` for the paper's
recipe) and with direct event integration, write them as PNGs with the ground truth beside them,
and score them against the ground truth (the scene shown by the config's display: with the kit's,
its intensity clipped at 1; with the paper's, Eq. 12):

- ``EvINR``: the frame-based INR fitted to the events alone; its brightness level is anchored
  (the kit's display: the frames' mean is 0.4), since events only see changes.
- ``integration (L0 = 0)``: Eq. 2 from an unknown start, anchored the same way.
- ``integration (L0 = true first frame)``: an oracle that is handed the first frame.
"""
from __future__ import annotations

import time

import numpy as np

from ..method.integration import integrate_events
from ..evaluation.metrics import SCORE_PROTOCOLS, SSIM_MIN_SIDE, score_frames
from ..core.checks import check_log, require, true_or_false, whole_number
from ..core.events import EventDataError, check_sensor_size
from ..core.frames import to_uint8
from ..io.output import atomic_output_dir, check_output_path, save_json, save_png
from ..sim.scenes import make_scene
from ..sim.simulate import simulate_scene
from ..method.solver import EvINRConfig, reconstruct
from ..method.tonemap import anchor_mean, to_display

__all__ = ["run_demo", "labelled_grid"]

ROW_LABELS = {"evinr": "EvINR", "integration": "integration", "integration_oracle": "oracle (true L0)"}


def labelled_grid(rows, row_labels, column_labels, *, title: str = "") -> np.ndarray:
    """Frames in rows with a label left of each row and above each column: a uint8 [H, W] image.

    Args:
        rows: one [N, h, w] array in [0, 1] per row (all the same shape).
        row_labels: one text per row (e.g. the method); column_labels: one per column (e.g. the time).
        title: an optional line above the column labels.
    Drawn with Pillow (apps never import matplotlib), black text on white.
    """
    from PIL import Image, ImageDraw, ImageFont

    rows = [np.clip(np.asarray(r, np.float64), 0.0, 1.0) for r in rows]
    n, h, w = rows[0].shape
    if len(row_labels) != len(rows) or len(column_labels) != n:
        raise ValueError(f"need one label per row ({len(rows)}) and per column ({n}); "
                         f"got {len(row_labels)} and {len(column_labels)}")
    size = max(10, min(16, h // 6))
    font = ImageFont.load_default(size=size)
    measure = ImageDraw.Draw(Image.new("L", (1, 1)))
    left, line, gap = int(max(measure.textlength(t, font=font) for t in row_labels)) + 12, size + 6, 2
    top = line * (2 if title else 1)
    width = max(left + n * (w + gap), int(measure.textlength(title, font=font)) + 8)
    canvas = Image.new("L", (width, top + len(rows) * (h + gap)), 255)
    draw = ImageDraw.Draw(canvas)
    if title:
        draw.text((4, 2), title, fill=0, font=font)
    for j, label in enumerate(column_labels):
        x = left + j * (w + gap) + w / 2
        draw.text((x, top - line / 2), label, fill=0, font=font, anchor="mm")
    for i, (frames, label) in enumerate(zip(rows, row_labels)):
        y = top + i * (h + gap)
        draw.text((4, y + h / 2), label, fill=0, font=font, anchor="lm")
        for j, img in enumerate(frames):
            canvas.paste(Image.fromarray(to_uint8(img)), (left + j * (w + gap), y))   # the levels the PNGs hold
    return np.asarray(canvas)


def _check_demo_memory(sensor_size, duration, n_frames, cfg, *, fraction: float = 0.8) -> None:
    """Refuse (EventDataError, before anything is simulated) a demo whose reconstruction (the solver's estimate,
    :func:`~evinr_lite.method.memory.estimate_memory`) and ground-truth frames would not fit in ``fraction`` of
    the free memory, naming the demo's own settings (its command has no --start/--end or --fps/--at)."""
    from ..method.memory import available_bytes, estimate_memory

    H, W = check_sensor_size(sensor_size)
    n_frames = int(n_frames)
    est = estimate_memory((H, W), 0.0, float(duration), 0, n_frames, cfg)["total"]
    est += 4.0 * n_frames * H * W * 8   # the scene's true frames, shown and scored (float64 copies)
    free = available_bytes("cpu")
    if est > fraction * free:
        raise EventDataError(f"the demo at {H}x{W} pixels with {n_frames:,} frames over {duration:g} s needs about "
                             f"{est / 2**30:,.1f} GiB of memory but about {free / 2**30:,.1f} GiB is free; choose a "
                             "smaller --size, fewer --frames or a shorter --duration (run_demo's sensor_size, n_frames "
                             "and duration; the defaults: --size 120x160 --frames 8 --duration 2)")


def run_demo(out_dir="evinr_demo", *, scene: str = "camera", sensor_size=(120, 160), duration: float = 2.0,
             C: float = 0.2, n_frames: int = 8, seed: int = 0, overwrite: bool = False,
             config: EvINRConfig | None = None, log=print) -> dict:
    """Run the demo and write ``out_dir``/<method>/frame_XXXX.png, gt/, overview.png, metrics.json.

    Args:
        config: EvINR settings (default: the paper's recipe with ``C``; progress bar on).
    Returns:
        the contents of metrics.json: {"methods": {name: {"mse_none", "ssim_none", "mse_clahe",
        "ssim_clahe", "time_s", "folder"}}, "n_events": int, ...}.
    """
    t0 = time.perf_counter()
    # before any work (the simulation and the training): the output folder was checked after the training
    overwrite = true_or_false(overwrite, "overwrite")
    check_output_path(out_dir, overwrite=overwrite)
    n_frames = whole_number(n_frames, "n_frames", lo=1)   # 2.5 was numpy's error, True one frame, 0 no query time
    require(config, EvINRConfig, "config", none_ok=True)   # {} ran the default recipe
    check_log(log)
    H, W = check_sensor_size(sensor_size)
    if min(H, W) < SSIM_MIN_SIDE:   # the scores' SSIM refused it after the training
        # no "sensor_size=" here: the command line would name it --sensor, and the demo's flag is --size
        side = SSIM_MIN_SIDE
        raise EventDataError(f"the demo's sensor of {H} x {W} pixels is smaller than the {side} x {side} window of "
                             f"SSIM, which scores its frames: choose at least {side} x {side} (sensor_size "
                             f"({side}, {side}), --size {side}x{side}; the default is 120 x 160)")
    cfg = config or EvINRConfig(C=C, seed=seed)
    _check_demo_memory(sensor_size, duration, n_frames, cfg)   # before the scene and its frames are allocated
    sc = make_scene(scene, sensor_size=sensor_size, duration=duration)
    events = simulate_scene(sc, 0.0, duration, C=C, seed=seed)
    H, W = sc.sensor_size
    log(f"simulated {len(events):,} events on {H}x{W} over {duration:g} s "
        f"({len(events) / (H * W):.1f} per pixel, C = {C:g}) in {time.perf_counter() - t0:.1f} s")

    t_query = np.linspace(0.0, duration, n_frames + 2)[1:-1]
    gt = to_display(sc.log_intensity(t_query), cfg.tonemap, cfg.gamma)   # the scene, shown as the frames are
    t1 = time.perf_counter()
    rec = reconstruct(events, t_query, cfg, t_start=0.0, t_end=duration)
    steps = f"{cfg.n_iters} Adam iterations" + (" + the closed-form output layer" if cfg.head_solve else "")
    log(f"EvINR fitted in {rec.history['train_time_s']:.1f} s ({steps}, "
        f"{len(rec.windows)} network(s), {rec.model.num_parameters():,} parameters in all)")
    t2 = time.perf_counter()
    L_int = integrate_events(events, t_query, C=C)
    L_oracle = L_int + sc.log_intensity(0.0)  # the same events, handed the true first frame
    t3 = time.perf_counter()
    methods = {
        ("EvINR", "evinr"): (rec.frames, t2 - t1),
        ("integration (L0 = 0)", "integration"):
            (to_display(anchor_mean(L_int, cfg.gamma, cfg.display_mean, tonemap=cfg.tonemap), cfg.tonemap, cfg.gamma),
             t3 - t2),
        ("integration (L0 = true first frame, oracle)", "integration_oracle"):
            (to_display(L_oracle, cfg.tonemap, cfg.gamma), t3 - t2),
    }
    results = {}
    with atomic_output_dir(out_dir, overwrite=overwrite) as tmp:
        (tmp / "gt").mkdir()
        for i, img in enumerate(gt):
            save_png(tmp / "gt" / f"frame_{i:04d}.png", img)
        rows, row_labels = [gt], ["ground truth"]
        for (name, folder), (frames, seconds) in methods.items():
            (tmp / folder).mkdir()
            for i, img in enumerate(frames):
                save_png(tmp / folder / f"frame_{i:04d}.png", img)
            rows.append(frames)
            row_labels.append(ROW_LABELS[folder])
            results[name] = {"folder": folder, "time_s": seconds}
            for eq in SCORE_PROTOCOLS:
                s = score_frames(frames, gt, eq)
                results[name].update({f"mse_{eq}": s["mse"], f"ssim_{eq}": s["ssim"]})
        column_labels = [f"t = {t:.2f} s" for t in t_query]
        save_png(tmp / "overview.png", labelled_grid(rows, row_labels, column_labels,
                                                      title=f"{scene}, {H}x{W}, C = {C:g}: rows = method, "
                                                            "columns = time"))
        summary = {
            "scene": scene, "sensor_size": [H, W], "duration_s": duration, "C": C, "seed": seed,
            "n_events": len(events), "query_times_s": t_query.tolist(),
            "protocol": f"ground truth = to_display(true log intensity, {cfg.tonemap!r}, gamma={cfg.gamma}) "
                        "(linear: the scene's intensity clipped at 1); "
                        "MSE on [0, 1]; SSIM gaussian sigma 1.5, data_range 1; equalisation of both "
                        "images: none, and CLAHE (the EvINR paper's protocol)",
            "evinr_config": rec.history["config"],
            "methods": results,
            "overview": {"rows": row_labels, "columns": column_labels},
        }
        save_json(tmp / "metrics.json", summary)
    log(f"\n{'method':<46} {'MSE':>7} {'SSIM':>6} | {'CLAHE MSE':>9} {'SSIM':>6} | {'time':>6}")
    for name, r in results.items():
        log(f"{name:<46} {r['mse_none']:>7.4f} {r['ssim_none']:>6.3f} | {r['mse_clahe']:>9.4f} "
            f"{r['ssim_clahe']:>6.3f} | {r['time_s']:>5.1f}s")
    log(f"\n(MSE, SSIM: gaussian sigma 1.5, data_range 1; CLAHE on both images for the right-hand "
        f"columns; {n_frames} frames)")
    log(f"wrote {out_dir}/ (overview.png: rows ground truth, EvINR, integration, oracle; columns the times) "
        f"in {time.perf_counter() - t0:.1f} s")
    return summary
