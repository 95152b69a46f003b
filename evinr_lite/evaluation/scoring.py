"""One reconstruct-and-score path for EvINR and the baselines, with the protocol in every result.

    rows = evaluate(events, gt_frames, gt_times, methods=("evinr", "integration", "hf"))
    print(results_table(rows))          # markdown, the protocol(s) printed under it
    plot_results(rows)                  # bar chart

The protocol (``../shared/notes/evaluation-and-datasets.md``, EVREAL's):

- predictions are matched to ground-truth frames by timestamp (:func:`match_frames`): a GT frame is
  scored only when a prediction lies within ``tol`` (1 ms) of it, and each prediction is used once;
- both images are equalised the same way ("none", "global" or "clahe"), then MSE, SSIM and LPIPS
  (:mod:`evinr_lite.evaluation.metrics`, :mod:`evinr_lite.evaluation.lpips`) are averaged over a sequence's frames;
- over several sequences, :func:`pool` weights each by its frame count (a pooled per-frame mean).

LPIPS needs published weights (``python -m data_fetch get lpips all``). Where they are absent the
result says so (``lpips`` None, ``lpips_note`` with the command), never a silent zero.
"""
from __future__ import annotations

import time

import numpy as np

from ..core.checks import (check_image_values, image_stack, real_number, require, seconds_array, value_list,
                           whole_number)
from ..core.events import EventDataError, Events
from ..method.baselines import BASELINE_PARAMS, BASELINES, reconstruct_baseline
from .metrics import EQUALIZATIONS, SCORE_PROTOCOLS, protocol_description, score_pairs

__all__ = ["frames_to_score", "match_frames", "score_sequence", "pool", "evaluate", "results_table",
           "resolve_lpips", "measure_inference_fps", "METHODS"]

METHODS = ("evinr",) + BASELINES
_LPIPS_CACHE: dict = {}


def match_frames(pred_times, gt_times, tol: float = 1e-3) -> tuple[np.ndarray, np.ndarray]:
    """Pair ground-truth frames with predictions by timestamp.

    A GT frame is paired with a prediction at most ``tol`` seconds away; each prediction and each
    GT frame is used at most once (closest pairs first, ties to the earlier index).

    Args:
        pred_times: [P] seconds. gt_times: [G] seconds (same clock). tol: seconds (>= 0).

    Returns:
        (pred_idx, gt_idx): int64 [M] each, sorted by gt_idx; unmatched GT frames are left out.
    """
    tol = real_number(tol, "tol", lo=0, hint="seconds between a ground-truth frame and its prediction (e.g. 1e-3)")
    pt = seconds_array(np.ravel(pred_times), "pred_times", allow_empty=True)
    gt = seconds_array(np.ravel(gt_times), "gt_times", allow_empty=True)
    order = np.argsort(pt, kind="stable")
    ps = pt[order]
    lo = np.searchsorted(ps, gt - tol, side="left")
    hi = np.searchsorted(ps, gt + tol, side="right")
    g_idx = np.repeat(np.arange(gt.size), hi - lo)
    s_idx = np.concatenate([np.arange(a, b) for a, b in zip(lo, hi)]) if g_idx.size else np.zeros(0, np.int64)
    p_idx = order[s_idx]
    dist = np.abs(pt[p_idx] - gt[g_idx])
    used_p, used_g, pairs = set(), set(), []
    for k in np.lexsort((p_idx, g_idx, dist)):          # closest first
        p, g = int(p_idx[k]), int(g_idx[k])
        if p not in used_p and g not in used_g:
            used_p.add(p)
            used_g.add(g)
            pairs.append((g, p))
    pairs.sort()
    return (np.array([p for _, p in pairs], dtype=np.int64), np.array([g for g, _ in pairs], dtype=np.int64))


def resolve_lpips(lpips_model=None):
    """(model or None, note): ``None`` loads the cached weights once ("auto"), ``False`` skips LPIPS,
    a model is used as is. The note says why LPIPS is missing ("" when it is computed)."""
    if lpips_model is False:
        return None, "LPIPS not requested (lpips_model=False)"
    if isinstance(lpips_model, (str, bytes)) and lpips_model != "auto":   # a name is no model ("none" is False)
        raise EventDataError(f"lpips_model must be None or 'auto' (the cached weights), False (skip LPIPS) or an LPIPS "
                             f"model, got the text {lpips_model!r}")
    if lpips_model is not None and not isinstance(lpips_model, str):   # != "auto" of an array was numpy's "truth value"
        import torch

        if not isinstance(lpips_model, torch.nn.Module):   # True, 5 or a dict failed inside the first distance
            raise EventDataError(f"lpips_model must be None or 'auto' (the cached weights), False (skip LPIPS) or an "
                                 f"LPIPS model (a torch module, as evaluation.lpips.load_lpips() gives), got "
                                 f"{type(lpips_model).__name__} {lpips_model!r:.40}")
        return lpips_model, ""
    from ..core.runtime import default_device
    from .lpips import LPIPSUnavailable, load_lpips, lpips_paths

    key = (str(default_device()), str(lpips_paths()[0]))
    if key not in _LPIPS_CACHE:                # only successes are cached: fetching later works
        try:
            _LPIPS_CACHE[key] = load_lpips()
        except LPIPSUnavailable as err:
            return None, str(err)
    return _LPIPS_CACHE[key], ""


def _as_float_frames(frames, name: str = "frames") -> np.ndarray:
    from ..core.frames import Frames

    if isinstance(frames, Frames):
        frames = frames.images
    a = image_stack(frames, name)   # [F, H, W] or [F, H, W, 1]; torch tensors too
    if a.dtype.kind not in "uif" or a.dtype == bool:
        raise EventDataError(f"frames must be uint8 (0..255) or float in [0, 1], got dtype {a.dtype}")
    if a.dtype.kind in "iu" and a.dtype != np.uint8:
        check_image_values(a, "frames")   # refused naming the dtype and the scale, not as "floats in [0, 65535]"
    return a.astype(np.float64) / 255.0 if a.dtype == np.uint8 else a.astype(np.float64, copy=False)


def score_sequence(pred_frames, pred_times, gt_frames, gt_times, equalization: str = "none",
                   lpips_model=None, tol: float = 1e-3) -> dict:
    """Score one sequence's predictions against its ground truth.

    Args:
        pred_frames: [P, H, W] in [0, 1] (clipped). pred_times: [P] seconds.
        gt_frames: [G, H, W] uint8 (/ 255) or float in [0, 1], or a :class:`~evinr_lite.core.frames.Frames`.
        gt_times: [G] seconds on the predictions' clock.
        equalization: "none", "global" or "clahe", applied to both images before every metric.
        lpips_model: None (load the cached LPIPS weights if present), False (skip), or an LPIPS model.
        tol: seconds between a GT frame and its prediction (EVREAL: 1 ms).

    Returns:
        {"mse", "ssim": float means over matched frames; "lpips": float or None; "lpips_note": why
        None ("" otherwise); "n_frames": matched GT frames; "n_gt_frames"; "equalization";
        "protocol": text; "per_frame": {"gt_index", "mse", "ssim", "lpips"}}.

    Raises:
        ValueError: no GT frame has a prediction within ``tol`` (the message says how to fix it).
    """
    pred = _as_float_frames(pred_frames, "pred_frames")
    gt = _as_float_frames(gt_frames, "gt_frames")
    pt, gtt = seconds_array(pred_times, "pred_times"), seconds_array(gt_times, "gt_times")
    if len(pt) != len(pred) or len(gtt) != len(gt):
        raise EventDataError(f"{len(pred)} predictions with {len(pt)} times, {len(gt)} GT frames with {len(gtt)} times; "
                         "give one timestamp per frame")
    if pred.shape[1:] != gt.shape[1:]:
        raise EventDataError(f"prediction frames are {pred.shape[1:]} but GT frames are {gt.shape[1:]} (H, W)")
    p_idx, g_idx = match_frames(pt, gtt, tol)
    if p_idx.size == 0:
        raise EventDataError(f"no ground-truth frame has a prediction within {tol} s; query the reconstruction at "
                         "the ground-truth timestamps (rec.frames_at(gt_times)) on the same clock")
    P, G, m, s = score_pairs(pred[p_idx], gt[g_idx], equalization)
    model, note = resolve_lpips(lpips_model)
    lp = None
    if model is not None:
        from .lpips import lpips_distances

        lp = lpips_distances(P, G, model)
    return {"mse": float(m.mean()), "ssim": float(s.mean()), "lpips": None if lp is None else float(lp.mean()),
            "lpips_note": note, "n_frames": int(p_idx.size), "n_gt_frames": int(len(gt)),
            "equalization": equalization, "protocol": protocol_description(equalization),
            "per_frame": {"gt_index": g_idx, "mse": m, "ssim": s, "lpips": lp}}


def _result_rows(rows, keys, what: str, source: str) -> list[dict]:
    """``rows`` as a list of dicts that each hold ``keys``; else an InputError naming the function that makes them."""
    if isinstance(rows, dict):
        rows = [rows]
    if isinstance(rows, (str, bytes)) or not hasattr(rows, "__iter__"):
        raise EventDataError(f"{what} takes a list of result rows (the dicts {source} returns), got "
                             f"{type(rows).__name__}")
    rows = list(rows)
    for i, r in enumerate(rows):
        if not isinstance(r, dict):
            raise EventDataError(f"{what}: row {i} is a {type(r).__name__}, not a dict; pass the dicts {source} returns")
        missing = [k for k in keys if k not in r]
        if missing:
            raise EventDataError(f"{what}: row {i} has no {', '.join(map(repr, missing))}; pass the dicts {source} "
                                 "returns")
    return rows


def pool(rows) -> dict:
    """Frame-count-weighted means over sequences (EVREAL's pooled per-frame mean).

    Args:
        rows: results of :func:`score_sequence` (one per sequence), all with the same protocol.

    Returns:
        {"mse", "ssim", "lpips" (None unless every row has it), "lpips_note", "n_frames",
        "n_sequences", "equalization", "protocol"}.
    """
    rows = _result_rows(rows, ("protocol", "n_frames", "mse", "ssim"), "pool", "score_sequence")
    if not rows:
        raise EventDataError("pool needs at least one scored sequence")
    protocols = {r["protocol"] for r in rows}
    if len(protocols) > 1:
        raise EventDataError("cannot pool results scored with different protocols (equalisation differs); "
                         "pool each protocol separately")
    n = np.array([r["n_frames"] for r in rows], dtype=np.float64)
    if np.any(n <= 0):
        raise EventDataError("every pooled row needs n_frames > 0")
    for i, r in enumerate(rows):     # one NaN row would make the pooled mean NaN without a word
        for key in ("mse", "ssim", "lpips"):
            v = r.get(key)
            try:
                bad = (v is not None or key != "lpips") and not np.isfinite(float(v))
            except (TypeError, ValueError):
                bad = True
            if bad:
                raise EventDataError(f"pool: row {i} has {key} = {v}, not a score; pool the rows score_sequence "
                                     "returns (drop or rescore that sequence)")

    def mean(key):
        return float(np.sum(n * np.array([r[key] for r in rows], dtype=np.float64)) / n.sum())

    has_lpips = all(r.get("lpips") is not None for r in rows)
    notes = sorted({r.get("lpips_note", "") for r in rows if r.get("lpips") is None} - {""})
    return {"mse": mean("mse"), "ssim": mean("ssim"), "lpips": mean("lpips") if has_lpips else None,
            "lpips_note": "; ".join(notes) if not has_lpips else "", "n_frames": int(n.sum()),
            "n_sequences": len(rows), "equalization": rows[0].get("equalization"), "protocol": rows[0]["protocol"]}


def evaluate(events: Events, gt_frames, gt_times=None, methods=("evinr", "integration", "hf"), config=None,
             equalizations=SCORE_PROTOCOLS, lpips_model=None, baseline_params=None, *,
             tol: float = 1e-3, sequence: str = "", keep_frames: bool = False) -> list[dict]:
    """Reconstruct at the ground-truth timestamps with each method and score every equalisation.

    Args:
        events: the events (same clock as ``gt_times``).
        gt_frames: [G, H, W] uint8 or float in [0, 1], or Frames (then ``gt_times`` may be None).
        gt_times: [G] seconds.
        methods: any of "evinr", "integration", "leaky", "hf".
        config: EvINRConfig for "evinr" (default: the kit's); its C, tonemap, gamma and display_mean are
            used by the baselines too, so every method is tone-mapped and anchored alike.
        equalizations: protocols to score with ("none", "global", "clahe").
        lpips_model: None (cached weights if present, else a note), False (skip) or an LPIPS model.
        baseline_params: {method: {param: value}}, e.g. {"hf": {"cutoff_hz": 2.0}, "leaky": {"leak_hz": 1.0}}.
        tol: timestamp tolerance (s). sequence: a name stored in each row.
        keep_frames: also store each method's predicted frames [G, H, W] ("frames") and its
            reconstruction object ("reconstruction", with ``.at(times)``) in its rows.

    Returns:
        One row per (method, equalisation): the keys of :func:`score_sequence` (without per_frame)
        plus "method", "sequence", "train_time_s" (0 for baselines), "inference_time_s" (seconds
        to produce the G frames from the trained model, or to compute a baseline), "params".
    """
    from ..core.frames import Frames
    from ..method.solver import EvINRConfig, reconstruct

    # every argument checked here, before any reconstruction (EvINR trains for seconds to minutes)
    events = require(events, Events, "events")
    cfg = EvINRConfig() if config is None else require(config, EvINRConfig, "config")
    if isinstance(gt_frames, Frames) and gt_times is None:
        gt_times = gt_frames.t
    if gt_times is None:
        raise EventDataError("give gt_times (seconds), or gt_frames as a Frames object")
    gt_times = seconds_array(gt_times, "gt_times")
    gt = _as_float_frames(gt_frames)
    check_image_values(gt, "ground-truth frames")
    if len(gt) != len(gt_times):
        raise EventDataError(f"{len(gt)} ground-truth frames but {len(gt_times)} gt_times; give one timestamp per frame")
    if gt.shape[1:] != tuple(events.sensor_size):
        raise EventDataError(f"the ground-truth frames are {gt.shape[1:]} (H, W) but the events' sensor_size is "
                             f"{tuple(events.sensor_size)}; score frames of the events' sensor (crop or resize them, or "
                             "check the sensor size: it is (H, W), rows first)")
    methods, equalizations = _names(methods, METHODS, "methods"), _names(equalizations, EQUALIZATIONS, "equalizations")
    real_number(tol, "tol", lo=0, hint="seconds between a ground-truth frame and its prediction (e.g. 1e-3)")
    if baseline_params is not None:
        if not isinstance(baseline_params, dict) or not all(isinstance(v, dict) for v in baseline_params.values()):
            raise EventDataError(f"baseline_params must be {{method: {{param: value}}}}, e.g. {{'hf': {{'cutoff_hz': 2.0}}}}, "
                                 f"got {baseline_params!r}")
        stray = sorted(set(baseline_params) - set(BASELINES))
        if stray:
            raise EventDataError(f"baseline_params names {stray}, not baselines; use keys among {BASELINES}")
        for method, extra in baseline_params.items():
            allowed = BASELINE_PARAMS.get(method, ())
            if set(extra) - set(allowed):
                raise EventDataError(f"baseline_params[{method!r}] has {sorted(set(extra) - set(allowed))}; baseline "
                                     f"{method!r} takes {allowed}")
    model, note = resolve_lpips(lpips_model)
    lpips_arg = model if model is not None else False
    rows = []
    for method in methods:
        t0 = time.perf_counter()
        if method == "evinr":
            rec = reconstruct(events, gt_times, cfg)
            train = float(rec.history["train_time_s"])
            t1 = time.perf_counter()
            frames = rec.frames_at(gt_times)
            infer = time.perf_counter() - t1
            params = {"config": rec.history.get("config", {})}
        else:
            extra = dict((baseline_params or {}).get(method, {}))
            rec = reconstruct_baseline(events, gt_times, method, C=cfg.C, gamma=cfg.gamma,
                                       display_mean=cfg.display_mean, tonemap=cfg.tonemap, **extra)
            frames, train, infer = rec.frames, 0.0, time.perf_counter() - t0
            params = dict(rec.params)
        for eq in equalizations:
            r = score_sequence(frames, gt_times, gt, gt_times, eq, lpips_arg, tol)   # gt: read and checked above
            r.pop("per_frame")
            if model is None:
                r["lpips_note"] = note
            rows.append({"method": method, "sequence": sequence, **r, "train_time_s": train,
                         "inference_time_s": infer, "params": params})
            if keep_frames:
                rows[-1].update(frames=frames, reconstruction=rec)
    return rows


def _names(value, allowed, name: str) -> tuple:
    """A non-empty tuple of names, each one of ``allowed``; else an InputError (one name alone is a tuple of one)."""
    if isinstance(value, str):
        raise EventDataError(f"{name} must be a tuple of names, got the text {value!r}; pass ({value!r},)")
    # None, 5 or a 0-d array: refused by name; a dict's keys were taken as the names (as tuple() reads them): kept
    value = tuple(value) if isinstance(value, dict) else tuple(value_list(value, name, f"names among {allowed}"))
    if not value:
        raise EventDataError(f"{name} is empty: nothing would be scored; pass one or more of {allowed}")
    unknown = [v for v in value if not isinstance(v, str) or v not in allowed]
    if unknown:
        raise EventDataError(f"unknown {name[:-1]} {unknown[0]!r}; choose from {allowed}")
    return value


def _fmt(v, digits=3) -> str:
    return "n/a" if v is None else f"{v:.{digits}f}"


def results_table(rows, digits: int = 3) -> str:
    """A markdown table of result rows (from :func:`evaluate`, or any dicts with the same keys),
    with the protocol(s) and any LPIPS notes printed under it."""
    rows = _result_rows(rows, ("mse", "ssim"), "results_table", "evaluate")
    digits = whole_number(digits, "digits", lo=0)
    if not rows:
        raise EventDataError("no rows to tabulate: pass the rows evaluate() returns (it returned none)")
    has_seq = any(r.get("sequence") for r in rows)
    head = (["sequence"] if has_seq else []) + ["method", "equalisation", "MSE", "SSIM", "LPIPS", "frames",
                                                "train (s)", "inference (s)"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for r in rows:
        cells = ([r.get("sequence", "")] if has_seq else []) + [
            str(r.get("method", "")), str(r.get("equalization", "")), _fmt(r["mse"], digits), _fmt(r["ssim"], digits),
            _fmt(r.get("lpips"), digits), str(r.get("n_frames", "")), _fmt(r.get("train_time_s"), 2),
            _fmt(r.get("inference_time_s"), 3)]
        lines.append("| " + " | ".join(cells) + " |")
    out = "\n".join(lines) + "\n"
    protocols = {}
    for r in rows:
        protocols.setdefault(r.get("equalization", ""), r["protocol"])
    for eq, text in protocols.items():
        out += f"\nProtocol ({eq}): {text}"
    notes = sorted({r.get("lpips_note", "") for r in rows if r.get("lpips") is None} - {""})
    for n in notes:
        out += f"\nLPIPS: {n}"
    return out + "\n"


def measure_inference_fps(model, n_frames: int = 64, batch_size: int = 32, repeats: int = 3) -> dict:
    """Frames per second of a FrameINR answering queries (batched, torch.no_grad, on its device).

    Args:
        model: a :class:`~evinr_lite.method.models.FrameINR` (its weights' values do not change the cost).
        n_frames: query times per repeat, spread over network 0's window. batch_size: times per call.
        repeats: timed repeats after one warm-up; the best is reported (least disturbed by other load).

    Returns:
        {"fps": n_frames / best seconds, "seconds": best, "all_seconds": [...], "device": str,
        "sensor_size": (H, W), "n_frames", "batch_size"}.
    """
    import torch

    from ..method.models import FrameINR

    require(model, FrameINR, "model")
    given = {"n_frames": n_frames, "batch_size": batch_size}
    n_frames = whole_number(n_frames, "n_frames", lo=1)        # 0 timed nothing and reported 0 fps
    batch_size = whole_number(batch_size, "batch_size", lo=1)
    # an integer as given (np.int64 stays np.int64), a whole float (4.0) as the int used
    reported = {k: v if isinstance(v, (int, np.integer)) else used for (k, v), used in zip(given.items(),
                                                                                            (n_frames, batch_size))}
    repeats = whole_number(repeats, "repeats", lo=1)           # 0 or -1 timed once without a word
    device = model.head_weight.device
    lo, hi = (float(v) for v in model.windows[0])
    times = torch.linspace(lo, hi, n_frames, dtype=torch.float64, device=device)

    def run():
        with torch.no_grad():
            for i in range(0, n_frames, batch_size):
                t = times[i:i + batch_size].expand(model.n_models, -1)
                model(t)
        if device.type == "cuda":
            torch.cuda.synchronize()

    run()  # warm-up (allocations, kernels)
    seconds = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        run()
        seconds.append(time.perf_counter() - t0)
    best = min(seconds)
    return {"fps": n_frames / best, "seconds": best, "all_seconds": seconds, "device": str(device),
            "sensor_size": tuple(model.sensor_size), **reported}


def frames_to_score(frame_t, events: Events, margin: float = 0.005) -> np.ndarray:
    """Indices of the frames whose timestamps lie in [first event - margin, last event + margin] (s); a
    negative margin keeps only the frames at least |margin| inside the events' span."""
    frame_t = seconds_array(frame_t, "frame_t", allow_empty=True)   # NaN times were dropped without a word
    margin = real_number(margin, "margin", hint="seconds around the events' span (e.g. 0.005; negative: inside it)")
    require(events, Events, "events")
    if len(events) == 0:
        raise EventDataError("no events: nothing to reconstruct or score; choose a window with events")
    keep = (frame_t >= events.t[0] - margin) & (frame_t <= events.t[-1] + margin)
    if not keep.any():
        raise EventDataError(f"no frame lies within the events' span [{events.t[0]:.4f}, {events.t[-1]:.4f}] s; "
                             "pick a window that contains frames")
    return np.flatnonzero(keep)
