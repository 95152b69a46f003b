"""EvINR's solver: train frame-based INRs on events and query them at any time.

    rec = reconstruct(events, query_times, EvINRConfig(C=0.2))
    rec.frames          # [Q, H, W] displayed (config.tonemap), in [0, 1]
    rec.log_intensity   # [Q, H, W] log intensity
    rec.at(t)           # log intensity at other times

The recipe (paper Sec. 3-4; defaults in :class:`EvINRConfig`):

1. Cut [t_start, t_end] into N overlapping windows of at most ``tau`` seconds (ensembling), one
   network each, all trained together in one batched computation (:class:`~evinr_lite.method.models.FrameINR`).
2. Stack each window's events into event frames. With coarse-to-fine, training starts with bins
   4x longer than ``bin_duration`` and bisects every bin into halves of equal event count at
   iterations 100 and 200, ending at ``bin_duration`` on average (with "fixed" binning the final
   bins are equal-count halves, so their lengths vary with the event rate); without it, training
   uses fixed bins of ``bin_duration`` throughout (the paper's Base).
3. Minimise temporal loss + lambda * spatial regularizer with Adam (lr 1e-4, x0.95 every 10 steps).
4. Align the networks: each network's per-pixel offset is matched to its predecessor's over their
   overlap, and predictions are cross-faded linearly across the overlap, so no seam shows.
5. Anchor the brightness. Events only constrain changes of log intensity: adding any constant to
   F leaves every loss unchanged, and a per-pixel constant is only set by the regularizer. The
   global level is therefore a choice, not a measurement: by default F is shifted so that the
   frames' mean over the sequence is ``display_mean`` (0.4; the paper's recipe: the mean of F
   tone-maps to 0.5). Metrics with histogram equalisation (CLAHE) are nearly insensitive to it;
   others should say how the level was set.
6. Display: clip(exp(F), 0, 1) by default, or the paper's Reinhard curve with ``gamma``
   (``config.tonemap``, :mod:`~evinr_lite.method.tonemap`); with APS frames as anchors
   (``config.anchor``), the frames set the offset and the level and their linear intensity is returned.

The kit's default (:class:`EvINRConfig`) replaces the Adam iterations of step 3 by the output
layer's closed-form optimum and solves the per-pixel offset of step 5 explicitly
(:mod:`~evinr_lite.method.offset`); on spans up to 3 s that offset's coarse part comes from the
integrated events (:mod:`~evinr_lite.method.coarse`).

Where each part lives: the settings in :mod:`~evinr_lite.method.config`; windows, predictions,
blending and alignment in :mod:`~evinr_lite.method.ensemble`; bins, Adam and the closed-form head
in :mod:`~evinr_lite.method.training`; this module holds :func:`reconstruct`, which calls them in
order, and the :class:`Reconstruction` it returns. The names above stay importable from here.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, field

import numpy as np

from ..core.checks import (check_reach, check_result_frames, host_array, optional_seconds,
                           require, seconds_array, whole_number)
from ..core.events import EventDataError, Events
from ..core.frames import Frames
from .anchor import fit_anchor, frames_in_window, linear_frames_unchecked
from .prepare import prepare_events
from .config import EvINRConfig
from .memory import check_memory
from .ensemble import alignment_offsets, blend_networks, blend_weights, predict_networks, split_windows
from .models import FrameINR
from .coarse import coarse_applies, coarse_correction
from .offset import offset_trend, offset_grid
from .tonemap import display_shift, to_display
from .training import train_frame_inr

__all__ = ["EvINRConfig", "Reconstruction", "reconstruct", "split_windows", "train_frame_inr",
           "predict_networks", "blend_weights", "blend_networks", "alignment_offsets"]


@dataclass(eq=False)
class Reconstruction:
    """A trained EvINR and its predictions.

    Attributes:
        times: float64 [Q] query times (seconds, the events' clock).
        log_intensity: float32 [Q, H, W] anchored log intensity at ``times``.
        frames: float32 [Q, H, W] tone-mapped frames in [0, 1].
        model: the trained FrameINR (N networks). windows: [N, 2] their time windows (s).
        offsets: float32 [N, H, W] per-network offsets added by the alignment and the anchor.
        config: the EvINRConfig used. history: training curves and time (see train_frame_inr).
        anchor: the :class:`~evinr_lite.method.anchor.AnchorFit` of an anchored reconstruction
            (``config.anchor`` "first" or "all"), else None; ``anchor_times`` the frames it used.
        trend: the :class:`~evinr_lite.method.offset.OffsetTrend` added on top of ``offsets`` when the
            offset varies over a long span (``config.offset_window``), else None (the offset is in ``offsets``).
    """

    times: np.ndarray
    log_intensity: np.ndarray
    frames: np.ndarray
    model: FrameINR
    windows: np.ndarray
    offsets: np.ndarray
    config: EvINRConfig
    history: dict = field(repr=False)
    anchor: object = field(default=None, repr=False)
    trend: object = field(default=None, repr=False)

    @property
    def anchor_times(self) -> np.ndarray:
        """float64 [K] times (s) of the APS frames used as anchors (empty when events only): not to be scored."""
        return np.zeros(0) if self.anchor is None else self.anchor.times.copy()

    def at(self, times, chunk: int = 256) -> np.ndarray:
        """Anchored log intensity at any times (seconds) inside the windows: float32 [Q, H, W].
        ``chunk``: frames computed at once (a whole number >= 1)."""
        return self._at(times, chunk, "at")

    def _at(self, times, chunk: int, caller: str) -> np.ndarray:
        """:meth:`at`, its memory message naming ``caller`` (the method the user called)."""
        chunk = whole_number(chunk, "chunk", lo=1)
        self._check_count(times, caller)
        t = seconds_array(times, "times", allow_empty=True)   # text, None, booleans, NaN, 2-D refused; [] stays empty
        L = blend_networks(self.model, self.windows, t, self.offsets, chunk)
        if self.trend is not None:
            self.trend.add_to(L, t)
        return L if self.anchor is None else L + self.anchor.offset_at(t)

    def _check_count(self, times, caller: str = "at") -> None:
        """Refuse, before any time is converted, more query times than the frames of :meth:`at` can fit in 80 % of
        the free memory (10^9 times of a view cost nothing to pass). Per time, float32 H x W frames:
        :func:`~evinr_lite.method.ensemble.blend_networks` holds every network's frame (N, the offsets added in
        place), the float64 blend (2) and its float32 copy (1): N + 3 frames, plus the blend's weights (16 bytes per
        network) and 64 bytes (measured peaks: 3.99, 5.00, 7.02 and 10.99 frames for N = 1, 2, 4, 8 at 24x32).
        :meth:`frames_at` then tone-maps in float64 (a copy, a clip, an exp): 7 frames at its peak (tracemalloc), so
        it needs max(N + 3, 7)."""
        from .memory import gib, available_bytes

        try:
            n = int(np.size(host_array(times))) if not isinstance(times, (str, bytes)) else 1
        except (TypeError, ValueError):   # a ragged list: seconds_array names it
            return
        H, W = self.log_intensity.shape[1:]
        N = len(self.windows)
        frames = N + 3 if caller == "at" else max(N + 3, 7)
        need, free = n * (64.0 + 16.0 * N + 4.0 * H * W * frames), available_bytes("cpu")
        if need > 0.8 * free:
            raise EventDataError(f"times= holds {n:,} query times: their frames of {H}x{W} pixels need about "
                                 f"{gib(need)} of memory but about {gib(free)} is free; ask for fewer times (or "
                                 f"call {caller}() on parts of them and keep what you need)")

    def frames_at(self, times) -> np.ndarray:
        """Frames in [0, 1] at any times: float32 [Q, H, W]; tone-mapped, or the APS frames' linear
        intensity when anchored (:func:`evinr_lite.method.anchor.linear_frames`)."""
        if self.anchor is not None:
            return linear_frames_unchecked(self._at(times, 256, "frames_at"))
        return to_display(self._at(times, 256, "frames_at"), self.config.tonemap, self.config.gamma).astype(np.float32)


def reconstruct(events: Events, query_times, config: EvINRConfig | None = None, *,
                t_start: float | None = None, t_end: float | None = None, frames=None,
                memory_guard: bool = True) -> Reconstruction:
    """Reconstruct log intensity and tone-mapped frames at ``query_times`` from events alone.

    Args:
        events: the events (their sensor_size gives H, W).
        query_times: [Q] seconds on the events' clock, inside [t_start, t_end].
        config: EvINRConfig (the kit's default when None).
        t_start, t_end: span to reconstruct (seconds); default: from the first to the last event,
            widened to include the query times.
        frames: the APS frames (:class:`~evinr_lite.core.frames.Frames`, on the events' clock) for
            ``config.anchor`` "first" or "all" (:mod:`evinr_lite.method.anchor`); frames outside
            [t_start, t_end] are ignored. Needed by an anchored config, refused by an events-only one.
        memory_guard: refuse (EventDataError, before training) a reconstruction whose memory estimate
            (:func:`~evinr_lite.method.memory.estimate_memory`: N networks, their bins, every network
            at every query time) exceeds 80 % of the free memory, naming the setting to change, as
            the command line does; False skips the check. Long recordings: stream them
            (:func:`~evinr_lite.method.streaming.stream_reconstruct`).

    Returns:
        Reconstruction with frames [Q, H, W] in [0, 1] and log intensities [Q, H, W].
    """
    events = require(events, Events, "events")                                 # every argument where it enters
    cfg = EvINRConfig() if config is None else require(config, EvINRConfig, "config")
    require(frames, Frames, "frames", none_ok=True)
    _check_device(cfg)                                                          # before any work: a GPU that is not here
    q, events, t_start, t_end = _checked_span(events, query_times, t_start, t_end)
    events, cfg = prepare_events(events, cfg, (t_start, t_end))                 # 0. hot pixels, background, ON/OFF balance, lam
    windows = split_windows(t_start, t_end, cfg.tau, cfg.overlap)               # 1. windows
    _check_events_per_network(len(events), windows, cfg)
    frames = _checked_anchor_frames(frames, events.sensor_size, t_start, t_end, cfg)   # before training
    if memory_guard:                                                            # before anything large is allocated
        check_memory(events.sensor_size, t_start, t_end, len(events), len(q), cfg, _device_name(cfg),
                     events_span=(float(events.t[0]), float(events.t[-1])))
    model, history = train_frame_inr(events, windows, cfg, model=_initial_model(events.sensor_size, windows, cfg))
    model.eval()
    offsets = alignment_offsets(model, windows)                                 # 3. align the networks
    history["config"] = asdict(cfg)
    if cfg.anchor != "none":   # the APS frames fix the per-pixel offset and the level: no solve, no mean anchor
        fit = fit_anchor(lambda t: blend_networks(model, windows, t, offsets), frames, cfg.anchor,
                         every=cfg.anchor_every, smoothing=cfg.anchor_smoothing)
        history["anchor"] = fit.summary()
        L = blend_networks(model, windows, q, offsets) + fit.offset_at(q)       # = Reconstruction.at(q)
        return _checked_result(Reconstruction(q, L, linear_frames_unchecked(L), model, windows, offsets, cfg, history, fit))
    grid = offset_grid(t_start, t_end, len(windows), cfg.offset_solve)
    trend = None
    if cfg.offset_solve != "none":                                              # 4. offset solve
        trend = offset_trend(grid, blend_networks(model, windows, grid, offsets), cfg.offset_window, cfg.offset_solve,
                             rest=cfg.offset_rest())
        if len(trend.knots) == 1:   # one offset image for all networks: the alignment stays
            offsets += trend.images[0]
            trend = None
    L_grid = blend_networks(model, windows, grid, offsets)
    if trend is not None:           # a slow per-pixel trend over a long span (offset.offset_trend)
        trend.add_to(L_grid, grid)
        history["offset_knots_s"] = trend.knots.tolist()
    if coarse_applies(cfg, t_start, t_end):      # 4b. the static image's coarse part from the integrated events
        coarse = coarse_correction([events], cfg.C, grid, L_grid, cfg.offset_coarse_px, cfg.offset_solve,
                                   cfg.offset_rest())
        offsets += coarse
        L_grid += coarse
    offsets += _level_shift(L_grid, cfg)                                        # 5. level anchor
    del L_grid
    L = blend_networks(model, windows, q, offsets)
    if trend is not None:
        trend.add_to(L, q)
    frames = to_display(L, cfg.tonemap, cfg.gamma).astype(np.float32)           # 6. tone map
    return _checked_result(Reconstruction(q, L, frames, model, windows, offsets, cfg, history, trend=trend))


RESULT_FIX = ("the settings do not fit these events: check C (the log-intensity change per event, 0.05 to 1.5 for "
              "event cameras; or fit it: --C auto), keep the recipe's learning rate (a smaller lr=), and for anchors "
              "use APS frames with distinct timestamps")


def _checked_result(rec: Reconstruction) -> Reconstruction:
    """The reconstruction, unless its output is not a result: NaN or infinite values, or every frame
    one constant although events were given (at least 2, see :func:`_checked_span`) -> ResultError."""
    check_result_frames(rec.log_intensity, what="EvINR's log intensity", input_varies=False, fix=RESULT_FIX)
    check_result_frames(rec.frames, what="EvINR's frames", input_varies=True, fix=RESULT_FIX)
    return rec


def _device_name(cfg: EvINRConfig) -> str:
    """The device the config trains on, as the memory check names it ("cpu" when none can be chosen)."""
    from ..core.runtime import default_device

    try:
        return str(default_device(cfg.device))
    except RuntimeError:   # no such device: train_frame_inr says so with its own message
        return "cpu"


MIN_EVENTS_PER_NETWORK = 2   # on average over the windows: as for the whole span (_checked_span), a network needs 2


def _check_events_per_network(n_events: int, windows: np.ndarray, cfg: EvINRConfig) -> None:
    """Refuse, before training, windows (``windows`` [N, 2] s, one network each) that hold fewer than
    :data:`MIN_EVENTS_PER_NETWORK` events on average: a tau far below the span (tau=1e-4 over 0.3 s makes
    about 3,000 networks) leaves the networks nothing to learn from and trains for minutes."""
    n = len(windows)
    if n > 1 and n_events < MIN_EVENTS_PER_NETWORK * n:
        span = float(windows[-1, 1] - windows[0, 0])
        raise EventDataError(f"tau={cfg.tau!r} s cuts the span of {span:.6g} s into {n:,} windows (one network each) "
                             f"but only {n_events:,} events are there ({n_events / n:.2g} per network; each needs at "
                             f"least {MIN_EVENTS_PER_NETWORK}); use a longer tau (the default is 5.0 s) or tau=None (one "
                             "network for the whole span), or a shorter span (t_start=/t_end=, and query times near the "
                             "events)")


def _check_device(cfg: EvINRConfig) -> None:
    """Refuse (DeviceUnavailable, an InputError) a ``cfg.device`` this machine does not have, before any work."""
    from ..core.runtime import default_device

    if cfg.device is not None:
        default_device(cfg.device)


def _initial_model(sensor_size, windows: np.ndarray, cfg: EvINRConfig) -> FrameINR:
    """The N networks to train, on the config's device; a head that is only solved in closed form
    (head_solve with no Adam step) is not drawn (saves d x H*W random numbers per network)."""
    from ..core.runtime import default_device

    solve_only = cfg.head_solve and cfg.n_iters == 0
    return FrameINR(sensor_size, windows, cfg.hidden_features, cfg.hidden_layers, cfg.omega_0,
                    cfg.first_layer_omega(windows), seed=cfg.seed, init_head=not solve_only).to(default_device(cfg.device))


def _checked_span(events: Events, query_times, t_start, t_end):
    """(query times float64 [Q], the events inside the span, t_start, t_end): every input checked
    before any work; the span defaults to the events' widened to include the query times."""
    q = seconds_array(query_times, "query_times")   # float64 [Q]: a number or a 1-D array, finite, not empty
    t_start, t_end = optional_seconds(t_start, "t_start"), optional_seconds(t_end, "t_end")
    if t_start is not None and t_end is not None and not t_end > t_start:
        raise EventDataError(f"the span [t_start, t_end] = [{t_start}, {t_end}] s is empty or reversed; t_end must "
                             "exceed t_start (or leave both out: the events' span, widened to the query times)")
    if len(events) < 2:
        raise EventDataError(f"need at least 2 events to reconstruct, got {len(events)}; choose a longer window")
    t_start = min(events.t[0], q.min()) if t_start is None else t_start
    t_end = max(events.t[-1], q.max()) if t_end is None else t_end
    check_reach(t_start, t_end, events.t, events.t_origin, "query_times= (or t_start, t_end)")
    if q.min() < t_start or q.max() > t_end:
        raise EventDataError(f"query times span [{q.min()}, {q.max()}] s, outside [t_start, t_end] = "
                             f"[{t_start}, {t_end}] s; widen the span or drop those times")
    events = events.slice_time(t_start, np.nextafter(t_end, np.inf), allow_empty=True)
    if len(events) < 2:
        raise EventDataError(f"fewer than 2 events in [{t_start}, {t_end}] s; choose a window with events")
    return q, events, t_start, t_end


def _checked_anchor_frames(frames, sensor_size, t_start: float, t_end: float, cfg: EvINRConfig):
    """The APS frames inside [t_start, t_end] for an anchored config (None for events only); an
    anchored config without frames, or frames without an anchored config, is refused here."""
    if cfg.anchor != "none":
        return frames_in_window(frames, sensor_size, t_start, t_end, cfg.anchor)
    if frames is not None:
        raise EventDataError("frames= were given but config.anchor is 'none' (events only): pass "
                             "EvINRConfig(anchor='first') or anchor='all' to use them, or leave frames= out")
    return None


def _level_shift(L_grid: np.ndarray, cfg: EvINRConfig) -> np.float32:
    """The constant added to every offset so that the sequence (``L_grid`` [G, H, W]) displays at
    ``cfg.display_mean`` (:func:`~evinr_lite.method.tonemap.display_shift`): the level events never fix. A grid
    that is not finite (a diverged run) is a ResultError here, as the frames would be, not display_shift's refusal."""
    check_result_frames(L_grid, what="EvINR's log intensity", input_varies=False, fix=RESULT_FIX)
    return np.float32(display_shift(L_grid, cfg.tonemap, cfg.gamma, cfg.display_mean))
