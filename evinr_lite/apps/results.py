"""A run's results: its scores against the ground-truth frames and the run folder around its frames.

Shared by the whole-sequence job (:mod:`evinr_lite.apps.recon_job`) and the streamed one
(:mod:`evinr_lite.apps.stream_job`): ``score_predictions`` / ``score_recording`` score under both
protocols (:data:`evinr_lite.evaluation.metrics.SCORE_PROTOCOLS`), ``write_results`` writes ``gt/``,
``metrics.json``, ``metrics.csv`` and ``run.json`` beside the frames the caller wrote.
"""
from __future__ import annotations

from pathlib import Path, PurePath

import numpy as np
import torch

from ..core.checks import check_path_type, require, seconds_array
from ..core.events import EventDataError
from ..core.frames import Frames
from ..core.recording import Recording
from ..evaluation.level import error_parts
from ..evaluation.metrics import SCORE_PROTOCOLS
from ..evaluation.scoring import match_frames, score_sequence
from ..method.anchor import held_out
from ..method.solver import Reconstruction

__all__ = ["score_predictions", "score_recording", "write_results", "jsonable", "EQUALIZATIONS"]

EQUALIZATIONS = SCORE_PROTOCOLS   # every result is scored without equalisation and with CLAHE (the paper's)


def _score_one(pred, pred_times, gt: Frames, equalization: str) -> dict:
    """One protocol of :func:`evinr_lite.evaluation.scoring.score_sequence`, as JSON-ready lists."""
    s = score_sequence(pred, pred_times, gt.images, gt.t, equalization=equalization)
    per = s["per_frame"]
    return {"mse": s["mse"], "ssim": s["ssim"], "lpips": s.get("lpips"), "n_frames": s["n_frames"],
            "protocol": s["protocol"], "per_frame_index": np.asarray(per["gt_index"]).tolist(),
            "per_frame_mse": np.asarray(per["mse"]).tolist(), "per_frame_ssim": np.asarray(per["ssim"]).tolist()}


def score_predictions(pred_frames, pred_times, gt: Frames) -> dict:
    """Score frames [Q, H, W] in [0, 1] at ``pred_times`` against ground truth, without equalisation
    and with CLAHE: {"none": {...}, "clahe": {...}}, each with mse, ssim, lpips (None unless its
    weights are present), n_frames, protocol (text) and per-frame lists (per_frame_t_s the GT times).

    "none" also says what its MSE is made of (:func:`evinr_lite.evaluation.error_parts`, a diagnostic):
    mse_at_level (the frames times the one gain over the scored frames that gives them the truth's
    mean: the level events never give), level_gain (that gain; above 1: shown too dark) and
    static_coarse (of mse_at_level, the part the same in every frame and coarser than 8 px)."""
    require(gt, Frames, "gt")   # None or an array was "has no attribute 'images'"
    pred_times = seconds_array(pred_times, "pred_times", allow_empty=True)   # text was numpy's ValueError
    pred_frames = np.asarray(pred_frames)
    scores = {eq: _score_one(pred_frames, pred_times, gt, eq) for eq in SCORE_PROTOCOLS}
    for s in scores.values():
        s["per_frame_t_s"] = gt.t[s["per_frame_index"]].tolist()
    p_idx, g_idx = match_frames(pred_times, gt.t)          # the pairs score_sequence scored
    if p_idx.size and pred_frames[p_idx].max() > 0:        # a black reconstruction has no level to set
        parts = error_parts(pred_frames[p_idx], gt.images[g_idx])
        scores["none"].update(mse_at_level=parts["mse_at_level"], level_gain=parts["gain"],
                              static_coarse=parts["static_coarse"])
    return scores


def score_recording(result: Reconstruction, gt: Frames | None) -> dict | None:
    """Score the reconstruction at every ground-truth frame time (see :func:`score_predictions`).

    The trained network is queried at the frames' own timestamps, so the scores do not depend on
    which times were exported. Frames used as anchors (``result.anchor_times``) are not scored.
    Returns None when no other frame lies in the reconstructed span. ``per_frame_index`` counts in
    ``gt`` as given (the frames export writes to ``gt/``), anchors included.
    """
    require(result, Reconstruction, "result")   # None was "has no attribute 'windows'"
    require(gt, Frames, "gt", none_ok=True)
    if gt is None or not len(gt):
        return None
    lo, hi = result.windows[0, 0], result.windows[-1, 1]
    keep = (gt.t >= lo) & (gt.t <= hi) & held_out(gt.t, getattr(result, "anchor_times", ()))
    if not keep.any():
        return None
    index = np.flatnonzero(keep)
    gt = Frames(gt.images[keep], gt.t[keep], gt.t_origin)
    if tuple(gt.size) != tuple(result.frames.shape[1:]):
        raise EventDataError(f"ground-truth frames are {gt.size} but the events' sensor is "
                             f"{tuple(result.frames.shape[1:])} (H, W); they cannot be compared")
    scores = score_predictions(result.frames_at(gt.t), gt.t, gt)
    for s in scores.values():   # indices into the frames given (those written to gt/), not into the scored subset
        s["per_frame_index"] = index[np.asarray(s["per_frame_index"], dtype=np.int64)].tolist()
    return scores


def write_results(tmp: Path, rec: Recording, times, history: dict, scores: dict | None, *, settings: dict | None,
                  written: list, n_events: int | None = None) -> dict:
    """Everything of a run folder but its frames (which the caller wrote: ``written`` lists them):
    ``gt/``, ``metrics.json``, ``metrics.csv`` when scored, and ``run.json``. Returns run.json's contents.
    ``n_events``: the events reconstructed (default ``len(rec.events)``; a streamed run holds none in memory)."""
    from ..io.export import save_csv, save_frames_png, save_timestamps
    from ..io.output import save_json

    check_path_type(tmp, "tmp", "the run's (temporary) folder")
    require(rec, Recording, "rec")   # None was "has no attribute 'meta'"
    if not isinstance(history, dict) or (scores is not None and not isinstance(scores, dict)) or \
            (settings is not None and not isinstance(settings, dict)):
        raise EventDataError(f"history must be a dict (the reconstruction's), scores a dict or None, settings a dict "
                             f"or None; got {type(history).__name__}, {type(scores).__name__} and "
                             f"{type(settings).__name__}")
    written = list(written)
    times = seconds_array(times, "times", allow_empty=True)
    run = {"input": rec.meta.get("path"), "format": rec.meta.get("format"),
           "sensor_size": list(rec.events.sensor_size), "t_origin": rec.events.t_origin,
           "window_s": list(rec.meta["window"]), "n_events": len(rec.events) if n_events is None else int(n_events),
           "n_frames_written": len(times), "times_s": times.tolist(),
           **(settings or {}), "evinr_config": history.get("config"),
           "train_time_s": history.get("train_time_s")}
    if scores is not None:
        gt = rec.frames
        save_frames_png(tmp / "gt", gt.images)
        save_timestamps(tmp / "gt" / "timestamps.txt", gt.t, gt.t_origin)
        summary = {eq: {k: v for k, v in s.items() if not k.startswith("per_frame")} for eq, s in scores.items()}
        save_json(tmp / "metrics.json", {"scored_at": "the ground-truth frame times in the window",
                                         "protocols": summary,
                                         "per_frame": {eq: {k: v for k, v in s.items() if k.startswith("per_frame")}
                                                       for eq, s in scores.items()}})
        first = next(iter(scores.values()))
        rows = []
        for k, gi in enumerate(first["per_frame_index"]):
            row = {"gt_index": gi, "t_s": f"{first['per_frame_t_s'][k]:.9f}"}
            for eq, s in scores.items():
                row[f"mse_{eq}"] = f"{s['per_frame_mse'][k]:.6f}"
                row[f"ssim_{eq}"] = f"{s['per_frame_ssim'][k]:.6f}"
            rows.append(row)
        save_csv(tmp / "metrics.csv", rows)
        written += ["gt/", "metrics.json", "metrics.csv"]
        run["scores"] = summary
    run["files"] = written + ["run.json"]
    save_json(tmp / "run.json", jsonable(run))
    return run


def jsonable(obj):
    """numpy scalars/arrays and tuples -> plain JSON types."""
    if isinstance(obj, dict):
        return {str(k): jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, torch.Tensor):   # kept as a tensor, json.dump's "not JSON serializable" when written
        return obj.tolist()
    if isinstance(obj, (set, frozenset)):   # a set has no order: sorted, numbers as numbers ({10, 9, 2}: [2, 9, 10])
        try:
            ordered = sorted(obj)
        except TypeError:   # mixed kinds (1 and "a"): in the order of their repr
            ordered = sorted(obj, key=repr)
        return [jsonable(v) for v in ordered]
    if isinstance(obj, PurePath):
        return str(obj)
    return obj
