"""APS frames as anchors: the per-pixel offset that events never fix, read off the camera's frames.

Beyond the paper (events-only stays the default, ``EvINRConfig(anchor="none")``). Events constrain
only changes of log intensity, so a pixel that never fires (a static background under a static
camera) keeps whatever offset the solver guessed: the background never appears. One APS frame
fixes it. With ``L(t)`` the INR's log intensity (after the networks are aligned) and
``A_k = log(I_k + eps)`` the log of anchor frame k at time t_k (``I_k`` in [0, 1], eps = 1/255):

- ``anchor="first"``: the first frame inside the window sets the offset, g = A_0 - L(t_0), added
  at every time: L(t) + g = A_0 + (L(t) - L(t_0)), the frame carried forward by the INR's changes.
- ``anchor="all"``: every ``anchor_every``-th frame inside the window (0, k, 2k, ...) is an anchor,
  the others are held out for scoring. Each anchor is a soft constraint on a slowly varying
  per-pixel offset g(t), linear between anchor times and constant outside them. Its values g_k at
  the anchor times minimise, per pixel,

      sum_k (g_k - r_k)^2 + sum_k (s / (t_{k+1} - t_k)) (g_{k+1} - g_k)^2,   r_k = A_k - L(t_k),

  with s = ``anchor_smoothing`` seconds: s = 0 passes through every anchor frame, s -> infinity
  gives one least-squares offset per pixel (the mean residual); in between, the correction drifts
  on the time scale s (it absorbs event drift, e.g. a C mis-specified or noise, without following
  each frame's noise). One K x K system shared by all pixels.

Output space: the anchored log intensity is the frames' own, so the frames are
``clip(exp(L) - eps, 0, 1)`` (the APS frames' linear intensity; plain SSIM against the frames is
meaningful). The paper's display tone map (Reinhard after the mean anchor; the kit's display until
issue 21's linear one, :mod:`~evinr_lite.method.tonemap`) is measured beside it in
``benchmarks/anchors.py`` (the tone-mapped numbers there): it scores lower on every scene but the
low-texture lowtex_light (``first``: 0.876 / 0.709 linear, 0.934 / 0.803 tone-mapped), so the linear
output is the one produced. Frames used as anchors are excluded from scoring
(``Reconstruction.anchor_times``; :func:`held_out`).

Measured (``nice -n 10 python benchmarks/anchors.py``, 320 s on 2 shared cores; writes
benchmarks/anchors_results.md|json). Zoo scenes with APS frames simulated at 20 frames/s (uint8, scored
against the true intensity), the real slider chunk with its own 5 frames (C = 1). SSIM without
equalisation / CLAHE-SSIM, on the frames not used as anchors (``first``: all but frame 0; ``all``: the
odd frames). CF: the complementary filter (Scheerlinck et al. 2018, gain 2 pi rad/s) fed frame 0
(like for like with ``first``), the even frames (like for like with ``all``), or every frame as it
arrives (its design: a frame every 50 ms); CF gain 0 is direct integration from frame 0. Events only
is the kit default of that run, shown by Eq. 12 (it has no level of its own)::

    scene               events only  first        CF frame 0   CF gain 0    all          CF even      CF every
    object_static_cam   0.242/0.226  0.897/0.894  0.789/0.782  0.958/0.938  0.985/0.977  0.967/0.953  0.975/0.963
    zoo mean (9)        0.583/0.554  0.754/0.660  0.533/0.455  0.756/0.671  0.924/0.886  0.859/0.790  0.869/0.804
    real slider chunk   0.414/0.346  0.658/0.587  0.606/0.583  0.582/0.571  0.748/0.679  0.650/0.633  0.623/0.603

``first`` beats the filter fed the same frame (gain 2 pi) on all ten scenes under both protocols, and
``all`` beats the filter fed the same anchors on all ten. Not met: with a frame every 50 ms the filter
beats ``first`` on every zoo scene (it sees 40 frames, ``first`` one), and on the real chunk it wins
under CLAHE (0.603 vs 0.587); direct integration from frame 0 (CF gain 0) beats ``first`` under
both protocols on five zoo scenes (object_static_cam 0.958 vs 0.897: the INR smooths the changes it
integrates) and loses on the real chunk (0.582 / 0.571 vs 0.658 / 0.587) and, in the linear output,
on the scenes with threshold mismatch and noise (chelsea_speed, noisy_gravel 0.552 vs 0.639,
grass_light_noisy).

``anchor_smoothing`` (default 0.03 s) was chosen on the zoo mean, the real chunk and noisy frames:
``all`` scores 0.928 / 0.894 (zoo mean) and 0.751 / 0.688 (real) at s = 0, 0.924 / 0.886 and 0.748 /
0.679 at 0.03 s, 0.916 / 0.870 and 0.736 / 0.663 at 0.1 s; with noisy APS frames the soft constraint
pays (``--frame-noise 0.03``, see benchmarks/anchors.py): object_static_cam 0.903 / 0.810 at s = 0,
0.924 / 0.840 at 0.03 s, 0.938 / 0.865 at 0.1 s; camera_translate 0.779 / 0.605, 0.815 / 0.643,
0.839 / 0.672. (``first`` carries its one frame's noise everywhere: object_static_cam 0.781 there.)
"""
from __future__ import annotations

import numpy as np

from ..core.checks import choice, numbers_array, real_number, short_repr, whole_number
from ..core.events import EventDataError
from ..core.frames import Frames

__all__ = ["FRAME_EPS", "ANCHOR_MODES", "AnchorFit", "frames_in_window", "select_anchors", "fit_anchor",
           "frame_log", "linear_frames", "linear_frames_unchecked", "check_frame_eps", "held_out", "ANCHORED_DISPLAY"]

FRAME_EPS = 1.0 / 255.0     # added to frame intensities in [0, 1] before the log (black pixels stay finite)
ANCHOR_MODES = ("none", "first", "all")
# an anchored reconstruction's frames from its log intensity (linear_frames, whatever the config's tone map), in
# words: the display attribute of its log_intensity.h5; built from FRAME_EPS ("1/255"), so the two cannot drift
_EPS_TEXT = f"1/{round(1 / FRAME_EPS)}" if 1 / round(1 / FRAME_EPS) == FRAME_EPS else repr(FRAME_EPS)
ANCHORED_DISPLAY = f"frames = clip(exp(L) - {_EPS_TEXT}, 0, 1)"


def check_frame_eps(eps) -> float:
    """The intensity added to frames in [0, 1] before the log (FRAME_EPS, 1/255, by default), checked: a finite
    number >= 0, as a float. The one check of :func:`frame_log`, :func:`linear_frames` and the fit of C's frame
    helpers (:mod:`evinr_lite.method.contrast`). None or text were numpy's errors, NaN gave NaN frames and a
    negative one the log of negative intensities; 0 (black pixels' log is -inf, which the fit of C masks and
    :func:`linear_frames` maps to 0) and 1 or more (a flatter log) are numbers that worked and still do."""
    return real_number(eps, "eps", lo=0.0, hint="the intensity added to frames in [0, 1] before the log "
                                                 "(FRAME_EPS = 1/255)")


def frame_log(images, eps: float = FRAME_EPS) -> np.ndarray:
    """log(I + eps) of frames given as uint8 (0..255) or float in [0, 1]: float64, same shape (booleans are 0 and 1,
    a black and white image). NaN images and an eps that is no finite number >= 0 are refused (they gave NaN logs):
    :func:`check_frame_eps`."""
    eps_value = check_frame_eps(eps)
    a = numbers_array(images, "images", "frames, uint8 or floats in [0, 1]", flags=True)
    if a.dtype.kind == "f" and np.isnan(a).any():
        raise EventDataError(f"images= holds {int(np.isnan(a).sum()):,} NaN value(s); a frame's intensity must be "
                             "a number: repair or drop those frames")
    a = a.astype(np.float64) / 255.0 if a.dtype == np.uint8 else np.clip(a.astype(np.float64), 0.0, 1.0)
    return np.log(a + (eps if isinstance(eps, (int, float, np.integer, np.floating)) else eps_value))


def linear_frames(L, eps: float = FRAME_EPS) -> np.ndarray:
    """Anchored log intensity -> the frames' linear intensity, clip(exp(L) - eps, 0, 1): float32.

    ``L``: numbers (a NaN was a NaN frame, None a NaN "frame" of no shape); +-inf are the logs of saturation and 0;
    booleans are 0 and 1, as numpy reads them (they were taken before). ``eps``: :func:`check_frame_eps`."""
    eps_value = check_frame_eps(eps)
    values = numbers_array(L, "L", "log intensities", flags=True)
    if values.dtype.kind == "f" and np.isnan(values).any():
        raise EventDataError(f"L= holds {int(np.isnan(values).sum()):,} NaN value(s); a log intensity must be a "
                             "number (NaN frames would come out)")
    return linear_frames_unchecked(values, eps if isinstance(eps, (int, float, np.integer, np.floating)) else eps_value)


def linear_frames_unchecked(L, eps: float = FRAME_EPS) -> np.ndarray:
    """:func:`linear_frames` without its checks (the solver's own values, checked with its result)."""
    return np.clip(np.exp(np.minimum(np.asarray(L, np.float64), 1.0)) - eps, 0.0, 1.0).astype(np.float32)


def frames_in_window(frames, sensor_size, t_start: float, t_end: float, mode: str = "first") -> Frames:
    """The frames with t_start <= t <= t_end, checked: a Frames object, the events' sensor size,
    at least one frame inside the window. Raises EventDataError naming the fix."""
    if frames is None:
        raise EventDataError(f"anchor={mode!r} needs the APS frames: pass frames= (e.g. frames=recording.frames, "
                             "from a recording that has frames), or use anchor='none' (events only)")
    if not isinstance(frames, Frames):
        raise EventDataError(f"frames= must be an evinr_lite.core.frames.Frames (images [F, H, W] and times t [F] "
                             f"on the events' clock), got {type(frames).__name__}; build one with Frames(images, t)")
    if tuple(frames.size) != tuple(sensor_size):
        raise EventDataError(f"the APS frames are {frames.size} (H, W) but the events' sensor is {tuple(sensor_size)}; "
                             "pass the frames of the same camera (same H x W as the events)")
    keep = (frames.t >= t_start) & (frames.t <= t_end)
    if not keep.any():
        span = f"[{frames.t.min():.6f}, {frames.t.max():.6f}] s" if len(frames) else "nothing (no frames)"
        raise EventDataError(f"no APS frame lies inside the reconstructed window [{t_start:.6f}, {t_end:.6f}] s "
                             f"(the frames cover {span}); choose a window (t_start=/t_end=) that contains a frame, "
                             "or use anchor='none'")
    inside = Frames(frames.images[keep], frames.t[keep], frames.t_origin)
    return inside.sorted_distinct(f"anchor={mode!r}")


def select_anchors(n_frames: int, mode: str, every: int = 2) -> np.ndarray:
    """Indices (into the window's frames, in time order) of the anchor frames: [0] for "first",
    [0, every, 2 every, ...] for "all" (every = 1: all of them, nothing left to score). ``n_frames``: a whole
    number >= 0 in both modes (-3 or None gave [0] for "first" and no anchor or Python's error for "all"); of no
    frame there is no anchor ([] in both modes: "first" gave [0], the index of a frame that is not there)."""
    mode = choice(mode, ANCHOR_MODES, "anchor")   # an array was numpy's "truth value ... is ambiguous"
    if mode in ("first", "all"):
        n_frames = whole_number(n_frames, "n_frames", lo=0)
    if mode == "first":
        return np.zeros(min(n_frames, 1), np.int64)
    if mode == "all":
        every = whole_number(every, "every", lo=1)   # 0 was a ZeroDivisionError, -1 no anchor, 2.5 and "2" taken
        return np.arange(0, n_frames, every, dtype=np.int64)
    raise EventDataError(f"anchor must be one of {ANCHOR_MODES}, got {mode!r}")


def held_out(frame_t, anchor_times, tol: float = 1e-9) -> np.ndarray:
    """bool [F]: which frames (times [F], seconds) are not anchors, i.e. may be scored."""
    ft = np.asarray(frame_t, np.float64)
    at = np.asarray(anchor_times, np.float64).ravel()
    if at.size == 0:
        return np.ones(ft.shape, bool)
    return ~np.any(np.abs(ft[:, None] - at[None, :]) <= tol, axis=1)


def smoothing_matrix(times: np.ndarray, smoothing: float) -> np.ndarray:
    """The K x K matrix I + s D^T diag(1 / dt) D of the soft-anchor problem (symmetric positive definite).
    ``times``: finite seconds [K], increasing (anchors are distinct frames: :func:`frames_in_window` refuses APS
    frames of one timestamp); ``smoothing``: seconds >= 0 (NaN or -1 were no smoothing, times out of order a matrix
    of 10^8, two equal times one of 10^7 from the 1e-9 s floor of a gap)."""
    smoothing = real_number(smoothing, "smoothing", lo=0.0,
                            hint="seconds (EvINRConfig.anchor_smoothing, e.g. 0.03)")
    times = numbers_array(times, "times", "anchor times in seconds [K]")
    if times.ndim != 1 or (times.dtype.kind == "f" and not np.isfinite(times).all()):
        raise EventDataError(f"times= must be finite seconds [K], increasing, got {short_repr(times)}")
    if (np.diff(times) <= 0).any():
        i = int(np.flatnonzero(np.diff(times) <= 0)[0])
        raise EventDataError(f"times= must be increasing (distinct anchor times, in order), got {times[i]!r} then "
                             f"{times[i + 1]!r} at {i}, {i + 1}; drop repeated frames")
    K = len(times)
    A = np.eye(K)
    if K > 1 and smoothing > 0:
        w = smoothing / np.maximum(np.diff(times), 1e-9)
        D = np.zeros((K - 1, K))
        D[np.arange(K - 1), np.arange(K - 1)] = -1.0
        D[np.arange(K - 1), np.arange(1, K)] = 1.0
        A += D.T @ (w[:, None] * D)
    return A


class AnchorFit:
    """A fitted anchor: per-pixel offsets ``values`` [K, H, W] at anchor ``times`` [K] (seconds),
    linear between them, constant outside. :meth:`offset_at` evaluates it; ``frame_times`` are the
    window's frame times and ``anchor_index`` which of them are anchors."""

    def __init__(self, mode: str, times, values, frame_times, anchor_index, every: int, smoothing: float):
        self.mode = mode
        self.times = np.asarray(times, np.float64)
        self.values = np.asarray(values, np.float32)
        self.frame_times = np.asarray(frame_times, np.float64)
        self.anchor_index = np.asarray(anchor_index, np.int64)
        self.every, self.smoothing = int(every), float(smoothing)

    def offset_at(self, times) -> np.ndarray:
        """float32 [Q, H, W]: the offset at times [Q] (s)."""
        t = np.atleast_1d(np.asarray(times, np.float64))
        if len(self.times) == 1:
            return np.broadcast_to(self.values[0], (len(t), *self.values.shape[1:]))
        j = np.clip(np.searchsorted(self.times, t, side="right") - 1, 0, len(self.times) - 2)
        w = np.clip((t - self.times[j]) / (self.times[j + 1] - self.times[j]), 0.0, 1.0).astype(np.float32)
        return (1 - w)[:, None, None] * self.values[j] + w[:, None, None] * self.values[j + 1]

    def summary(self) -> dict:
        """JSON-ready description: mode, anchor times, the window's frame times, how many are held out."""
        held = np.ones(len(self.frame_times), bool)
        held[self.anchor_index] = False
        return {"mode": self.mode, "anchor_times_s": self.times.tolist(), "n_anchors": int(len(self.times)),
                "frame_times_s": self.frame_times.tolist(), "n_held_out": int(held.sum()),
                "anchor_every": self.every if self.mode == "all" else None,
                "anchor_smoothing_s": self.smoothing if self.mode == "all" else None,
                "eps": FRAME_EPS, "output": "clip(exp(L) - eps, 0, 1), the frames' linear intensity"}


def fit_anchor(L_at, frames: Frames, mode: str, *, every: int = 2, smoothing: float = 0.03) -> AnchorFit:
    """Fit the anchor offset.

    Args:
        L_at: function times [K] (s) -> the model's log intensity [K, H, W] before anchoring.
        frames: the window's frames (:func:`frames_in_window`), in time order.
        mode: "first" or "all". every, smoothing: the "all" parameters (see the module docstring).

    Returns:
        AnchorFit whose :meth:`AnchorFit.offset_at` added to ``L_at`` gives the anchored log intensity.
    """
    idx = select_anchors(len(frames), mode, every)
    t = frames.t[idx]
    r = frame_log(frames.images[idx]) - np.asarray(L_at(t), np.float64)       # [K, H, W] residuals
    K, H, W = r.shape
    if K > 1:
        r = np.linalg.solve(smoothing_matrix(t, smoothing), r.reshape(K, -1)).reshape(K, H, W)
    return AnchorFit(mode, t, r, frames.t, idx, every, smoothing)
