"""The solver's settings: :class:`EvINRConfig`, every field checked on construction, and its named recipes.

    cfg = EvINRConfig()                 # the kit's default (chosen on the scene zoo and the real chunk)
    cfg = EvINRConfig.paper()           # the paper's recipe exactly (Sec. 3-4)
    cfg = EvINRConfig(C=0.2, tau=2.0)   # any field overridden; a bad value raises EventDataError

Times are seconds; C is in log units per event.
"""
from __future__ import annotations

import functools

import math
import re
from dataclasses import dataclass, fields, replace

import numpy as np

from ..core.checks import choice
from ..core.events import EventDataError
from .anchor import ANCHOR_MODES
from .balance import BALANCE_MODES, HOT_PIXEL_MODES
from .binning import as_thresholds
from .denoise import DEFAULT_DT
from .offset import OFFSET_SOLVES, STATIC_REST
from .prepare import BACKGROUND_MODES
from .tempo import MIN_SCALE, SCALE_RANGE, scale_floor_message
from .tonemap import DEFAULT_DISPLAY_MEAN, DEFAULT_TONEMAP, DISPLAY_MEANS, TONEMAPS

__all__ = ["EvINRConfig", "CAMERAS"]

CAMERAS = ("moving", "static")   # what the user knows of the camera (EvINRConfig.camera)


FIRST_OMEGA_0 = 10.0   # first_omega_0's default; used only where first_omega_per_s is None


@dataclass
class EvINRConfig:
    """Every setting of the frame-based solver.

    Three named recipes (``benchmarks/quality_zoo.py`` compares them in one run):

    - ``EvINRConfig()``: the kit's default, chosen on the mean of the scene zoo (seeded scenes,
      ``evinr_lite.sim.zoo``) and the real slider_depth chunk, never on one scene;
    - ``EvINRConfig.paper()``: the paper's recipe exactly (Sec. 3-4);
    - ``EvINRConfig.v0_1()``: the kit's earlier default (the paper's plus first_omega_0 = 10 and
      head_lr_scale = 30, tuned on the demo scene alone); notebooks 03-11 train it.

    The kit's default departs from the paper in these fields. Zoo means (CLAHE-SSIM / SSIM / MSE; wall
    time per scene; every method shown by the kit's display):
    ``python benchmarks/quality_zoo.py`` (13 short scenes, 2 cores): kit 0.643 / 0.703 / 0.0344 in
    0.8 s, paper 0.392 / 0.481 / 0.0578, v0.1 0.571 / 0.624 / 0.0482 (about 25 s each on quiet cores),
    integration 0.415 / 0.453 / 0.0641, high-pass filter 0.489 / 0.556 / 0.0557. The figures in the
    bullets before ``tonemap`` were measured with the paper's Eq. 12 display, the kit's until then.

    - head_solve=True, n_iters=0, coarse_to_fine=False: the output layer is solved in closed form
      for the SIREN's initial hidden layers. Training the hidden layers first (60 Adam steps) changed
      the zoo means by less than 0.002 at 4x the time, so no Adam step is taken.
    - temporal_loss="difference": the closed form fits the exact integral form; the mid-point
      derivative is a first-order approximation.
    - first_omega_per_s=5.0: the first layer's frequency per second of the events' clock
      (first_omega_0 = 5 x the window's length / 2), the closed-form model's only temporal prior.
      The fixed 10 per window before (v0_1's) was 10 per second on the zoo's 2 s scenes and 4.2 on a
      60 s recording's 4.75 s windows; the sweep (docs/defaults.md) wants 4-7 per window on the short
      scenes and 10-15 on the long ones, and 4-6 per second on both. Zoo mean 0.637 / 0.697 / 0.0354
      -> 0.641 / 0.699 / 0.0355, held-out 0.526 / 0.574 / 0.0665 -> 0.530 / 0.576 / 0.0661, real
      chunk 0.357 / 0.426 / 0.0649 -> 0.365 / 0.442 / 0.0568, the 20 s and 60 s recordings within 0.001.
    - temporal_scale="auto": under fast motion (the pixels reverse polarity more than 2.5 times a second,
      as under a shake) the bins are up to 4x shorter and the first layer up to 4x faster, by the
      reversals' rate (:mod:`~evinr_lite.method.tempo`); every other scene is trained exactly as before.
      On the 38 of 209 short scenes where it applies, the 11 shakes gain 0.028-0.146 CLAHE-SSIM (mean
      0.074), the 27 others -0.005 to +0.020 (docs/defaults.md, "The temporal scale").
    - offset_solve="l1_gradient": the per-pixel offset that events never fix is solved explicitly
      instead of drifting under the regularizer (the ghost): the one image that makes all frames'
      gradients sparsest together, by ADMM from the per-edge medians ("median_gradient", the default
      before). Same run of ``python benchmarks/quality_zoo.py`` against the committed median run
      (CLAHE-SSIM / SSIM / MSE): zoo mean 0.634 / 0.692 / 0.0366 -> 0.637 / 0.697 / 0.0354, real
      chunk 0.360 / 0.429 / 0.0690 -> 0.357 / 0.426 / 0.0649; held-out and long recordings in
      docs/defaults.md. 0.12 s against the median's 0.08 s for a 64 x 180 x 240 grid.
    - offset_coarse_px=8.0: on spans of at most 3 s the static image's spatial frequencies below 8 px
      (a Gaussian's sigma) come from the integrated events' own offset solve, the finer ones and every
      change in time from the INR (:mod:`~evinr_lite.method.coarse`). The offset solve reads the
      static image better from the events' staircase than from the INR's smooth frames, whose static
      image it shrinks (camera_translate: 0.89 against 0.71 of the truth's contrast). Zoo mean
      0.641 / 0.699 / 0.0355 -> 0.643 / 0.703 / 0.0344 (camera_translate's MSE 0.0119 -> 0.0090),
      held-out mean 0.530 / 0.576 / 0.0661 -> 0.536 / 0.583 / 0.0629, real chunk 0.365 / 0.442 /
      0.0568 -> 0.377 / 0.461 / 0.0696 (both SSIMs gain, MSE rises: the chunk's C = 1 is too large, so
      more static contrast is too much there). It costs grass_light_noisy 4 % MSE (0.0281 -> 0.0292,
      v0_1's 0.02900 against the kit's 0.02916 now: the noisy target falls from 4 to 3 of 6 scenes),
      while MSE meets the best baseline's on 9 of 13 zoo scenes (7 before). On longer spans integration drifts and the INR's static
      image was the better one on every recording measured (drift_clock 8 s: 0.791 -> 0.784;
      long_pan_20s 0.646 -> 0.632, also when each 3 s segment gets its own correction), hence the
      3 s limit. 4 and 16 px give the zoo 0.641 and 0.643, the real chunk 0.385 and 0.372
      (docs/defaults.md). About 0.3 s more for a 2 s 180x240 scene (0.9 -> 1.2 s in one run).
    - offset_window=5.0 (issue 21): on spans longer than 7.5 s the offset is a slow per-pixel trend
      (one offset image per 5 s, linear between; measured below with the median solve, the default
      then), which follows what builds up at every pixel over a long recording; shorter spans keep
      the single image. ``python
      benchmarks/quality_zoo.py --long --scenes drift_clock,long_pan_20s,long_ijrr_60s --methods
      kit,one_image --variant one_image=offset_window=None``: long_pan_20s 0.514 / 0.576 / 0.0349 ->
      0.545 / 0.591 / 0.0343, long_ijrr_60s 0.489 / 0.471 / 0.0161 -> 0.516 / 0.483 / 0.0157,
      drift_clock 0.747 -> 0.752; windows of 1-2 s lost on every short scene (0.602 -> 0.582 at 1 s
      on astronaut_rotzoom).
    - spatial_order=2 (2026-12-06): the closed-form head's Tikhonov term is the Laplacian's energy
      |D^T D F|^2, equal to the paper's gradient energy |D F|^2 at a wavelength of 8 px: coarser
      structure is smoothed less, finer more. Kit-only means, order 1 -> 2 (CLAHE-SSIM / SSIM / MSE): zoo
      0.648 / 0.710 / 0.0339 -> 0.657 / 0.716 / 0.0339, held out 0.540 -> 0.555, stress 0.596 -> 0.613,
      fresh seeds 11 / 12 / 13 0.576 / 0.594 / 0.615 -> 0.590 / 0.603 / 0.630, long_pan_20s 0.647 -> 0.676,
      long_ijrr_60s 0.697 -> 0.722, real chunk 0.372 / 0.451 / 0.0656 -> 0.376 / 0.453 / 0.0671; the same
      time (docs/defaults.md, "The spatial prior's order").
    - spatial_order="banded" (2026-12-06, ninth session): the gradient's energy (order 1, the paper's) for
      structure coarser than 8 px and a third-order roll-off, mu^3 / mu_ref^2, for finer structure:
      coarse structure is treated as the paper does, fine texture and quantization noise are damped
      more than order 2 does. Kit-only CLAHE-SSIM means, order 2 -> banded: zoo 0.657 -> 0.665, real
      chunk 0.376 -> 0.376 (SSIM 0.453 -> 0.458, MSE 0.0671 -> 0.0655), held out 0.555 -> 0.559, stress
      0.613 -> 0.619, fresh seeds 11-15 +0.002 / +0.006 / +0.002 / +0.010 / +0.007, long_pan_20s 0.676 ->
      0.683, long_ijrr_60s 0.722 -> 0.719; the same time (docs/defaults.md, "The spatial prior's order").
    - prior_time_order=0.25 (2026-12-07, tenth session): the spatial prior weighs each temporal mode of the
      features by (Lambda_i / Lambda_ref)^0.25, Lambda_i the mode's change per bin against its spread:
      slow changes are shrunk less, fast ones (the changes' quantization noise) more. Kit-only means,
      0 -> 0.25 (CLAHE-SSIM / SSIM / MSE): zoo 0.665 / 0.720 / 0.0338 -> 0.669 / 0.722 / 0.0339, real chunk
      0.376 / 0.458 / 0.0655 -> 0.378 / 0.460 / 0.0654, held out 0.559 -> 0.565, stress 0.619 -> 0.624,
      fresh seeds 11 and 16 (16 drawn this session) 0.592 -> 0.597 and 0.667 -> 0.672,
      long_pan_20s 0.683 -> 0.686, long_ijrr_60s 0.719 -> 0.733; the same time (docs/defaults.md, "The spatial
      prior's order in time").
    - lam="auto" instead of 0.05 (0.01 before issue 21): with the exact head, less smoothing wins where
      much texture passes each pixel, and more where little does (quick zoo, fixed lam, CLAHE-SSIM
      mean: 0.293 at lam 1, 0.403 at 0.2, 0.482 at 0.05, 0.528 at 0.01). The Tikhonov term damps the
      changes' quantization noise and the texture alike, and pulls each frame towards the window's
      mean frame (on long_ijrr_60s the texture's amplitude fell to 0.3 at a pan's turning points, 0.67
      for integration). :mod:`~evinr_lite.method.smoothing` sets lam = 0.3 / m^2 within [0.002, 0.01],
      m the events per pixel per window that came and went. ``python benchmarks/lam_rule.py --long``
      (sweep and rule per scene): 13 short zoo scenes 0.566 / 0.602 / 0.0409 -> 0.574 / 0.611 /
      0.0406 (best gains grass_light_noisy 0.555 -> 0.597, noisy_gravel 0.523 -> 0.546; worst loss
      dark_falling 0.420 -> 0.413, whose events are mostly a global dimming); real chunk unchanged
      (0.350 / 0.416 / 0.0889, lam 0.01); long_ijrr_60s 0.516 -> 0.570 (hf_best 0.552, leaky_best
      0.559); long_pan_20s 0.545 -> 0.539. The scenes that want more than 0.01 (unequal_onhot: 0.723
      at 0.1; object_static_cam) and less than 0.002 stay at the bounds: beyond them the rule
      would trade the real chunk (0.311 at 0.1) and long_pan_20s (0.523 at 0.001). Rerun with the
      linear display (``python benchmarks/lam_rule.py --long`` and ``--heldout``): zoo mean 0.621
      against 0.618 for the best fixed lam (0.01), real chunk 0.354 (0.360 at 0.005), held-out 0.513
      against 0.519 (0.01), long_pan_20s 0.567 against 0.594 (0.01), long_ijrr_60s 0.698 against 0.663
      (0.01): the rule stays. Again with the zoo's balance prior: zoo 0.619 against 0.617 (0.01), real
      chunk 0.354 (0.359 at 0.005), held-out 0.516 against 0.521 (0.01), long_pan_20s 0.569 against
      0.595 (0.01), long_ijrr_60s 0.699 against 0.664 (0.01). Again with the background filter (the
      rule counts what it leaves): zoo 0.634 against 0.631 (0.005, 0.01), real chunk 0.360 (0.366 at
      0.005), held-out 0.523 against 0.527 (0.005, 0.01), long_pan_20s 0.643 against 0.651 (0.005),
      long_ijrr_60s 0.698 against 0.663 (0.01; 0.700 at 0.001). Again with the L1 offset solve: zoo
      0.637 against 0.634 (0.005, 0.01), real chunk 0.357 (0.361 at 0.005), held-out 0.526 against
      0.530 (0.005, 0.01), long_pan_20s 0.647 against 0.655 (0.005), long_ijrr_60s 0.698 (0.700 at 0.001).
    - hidden_features=128 (issue 21; 256 before, 512 in the paper): the same scores as 256 at about half
      the time. Seven full-size zoo scenes (noisy_gravel, unequal_onhot, camera_240x180,
      astronaut_rotzoom, lowtex_light, text_shake, drift_clock), mean CLAHE-SSIM / SSIM / MSE 0.6401 /
      0.6931 / 0.0337 in 11.3 s against 0.6396 / 0.6930 / 0.0336 in 23.8 s (camera_240x180: 2.1 s
      against 3.1 s); quick zoo, eight scenes: 0.5485 against 0.5492; real chunk 0.350 / 0.416 / 0.0889
      both. (256 had matched 512 within 0.002 at a quarter of the solve's d^2 work.) Longer bins
      (1/16 s, min_bins 32) won on the quick zoo (0.562 against 0.549) but lost on the full-size scenes
      (0.624 against 0.640: text_shake 0.453 against 0.511, fast shake needs short bins): not taken.
    - balance="events", hot_pixels="drop" (issue 21): C+ and C- from the events' ON/OFF counts when
      one C is given (:mod:`evinr_lite.method.balance`: pooled counts, hot pixels left out, shrunk
      towards the nominal C as far as the span carries evidence), and hot pixels' events left out.
      long_pan_20s (20 s, C+ 0.25 / C- 0.20 given as 0.225, ON-only hot pixels): CLAHE-SSIM / SSIM /
      MSE 0.494 / 0.554 / 0.0462 -> 0.514 / 0.576 / 0.0349, level error per quarter +0.144 +0.062
      -0.032 -0.101 -> +0.023 +0.018 +0.010 +0.009, better than the same recording cut into
      independent 2 s windows (0.500 / 0.551 / 0.0452). On 2-3 s scenes the shrinkage leaves C nearly
      as given (quick zoo mean 0.5302 -> 0.5319; unequal_onhot 0.577 -> 0.605 from the hot pixels);
      real chunk 0.349 -> 0.350. Measured with ``python benchmarks/quality_zoo.py --quick --variant
      "bal=balance='events',hot_pixels='drop'"`` and ``--long --scenes long_pan_20s``.
      The shrinkage's two prior spreads are the zoo's root mean squares (``python benchmarks/balance.py``:
      imbalance 0.084, change of the mean log brightness over a span 0.50; NET_CHANGE was 1.0 before):
      zoo mean 0.621 / 0.688 / 0.0373 -> 0.619 / 0.687 / 0.0364, real chunk 0.354 / 0.424 / 0.0732 ->
      0.354 / 0.423 / 0.0694, held-out 0.513 / 0.560 / 0.0696 -> 0.516 / 0.564 / 0.0680, long_pan_20s
      0.567 / 0.664 / 0.0379 -> 0.569 / 0.669 / 0.0352 (level error per quarter -0.027 ... -0.153 ->
      -0.070 ... -0.116, the display level near -0.09 aside), cat_slider_20s 0.488 -> 0.494 (MSE 0.0552 ->
      0.0503).
      Then the balance became the consensus (minmod) of the counts' estimate and the intervals'
      (C+ / C- from the mean log interval within runs of ON and of OFF events), unshrunk. A change of
      light biases the two in opposite directions, and a real imbalance moves both alike
      (:mod:`evinr_lite.method.balance`, ``python benchmarks/balance.py [--heldout]``: within 0.05 of
      the simulated b on 24 of the zoo's and held-out's 25 scenes; root mean square error 0.027 and
      0.019 against the counts rule's 0.087 and 0.100). Zoo mean 0.643 / 0.703 / 0.0344 ->
      0.648 / 0.710 / 0.0337, real chunk 0.377 / 0.461 / 0.0696 -> 0.377 / 0.457 / 0.0668, held-out
      0.536 / 0.583 / 0.0629 -> 0.541 / 0.590 / 0.0608 (``python benchmarks/quality_zoo.py
      [--heldout]``; docs/defaults.md, "The ON/OFF balance as a consensus"). ``balance="counts"`` keeps the rule before.
      Then the counts alone, fitted with an intercept so that a change of light common to all pixels
      is not read as an imbalance, where their error scale NET_CHANGE / (C events per pixel) is at
      most 0.1 (the intervals' bias does not shrink with the recording; the counts' error does). With
      C- > C+ (``python benchmarks/balance.py --off-heavy``) the short scenes' mean 0.583 / 0.637 /
      0.0486 -> 0.592 / 0.647 / 0.0468, and the long ones no longer drift (long_ijrr_60s 0.294 ->
      0.696 CLAHE-SSIM); under a change of light over the 20 s pan (``--light``) the kit is within
      0.004 of the true pair. The zoo and held-out scenes: docs/defaults.md.
      Then the edges' estimate (b that keeps each edge's change from following its pixels' count
      difference) took the pooled counts' place in the minmod: off-heavy short mean -> 0.598 / 0.654 /
      0.0452, fresh random sensors (``--fresh``) 0.528 / 0.608 / 0.0478 -> 0.529 / 0.609 / 0.0473,
      zoo 0.648 / 0.710 / 0.0337 -> 0.648 / 0.710 / 0.0339, real chunk 0.377 / 0.457 / 0.0668 ->
      0.372 / 0.451 / 0.0656 (docs/defaults.md, "The edges' estimate").

    - tonemap="linear", display_mean=0.4 (issue 21; the paper's Eq. 12 with the mean of F at 0.5
      before): frames are clip(exp(F), 0, 1), the intensity whose log changes fired the events, with
      the frames' mean over the sequence at 0.4 (:mod:`~evinr_lite.method.tonemap`). Eq. 12 halved
      the frames' contrast against linear ground truth. One run, the same reconstructions shown four
      ways (docs/defaults.md, "The display"): zoo mean 0.574 / 0.611 / 0.0406 (Eq. 12) -> 0.621 /
      0.688 / 0.0373, real chunk 0.350 / 0.416 / 0.0889 -> 0.354 / 0.424 / 0.0732; display_mean 0.35
      loses the zoo's MSE (0.0450), 0.45 loses all three on the real chunk (0.344 / 0.404 / 0.0961).
      Per scene MSE rises on bright and noisy scenes (noisy_gravel 0.0205 -> 0.0559).

    - background="filter" (issue 21): after the hot pixels, events without an event of the same
      polarity at a neighbouring pixel within 50 ms before or after them are left out, and the ON/OFF
      balance and lam are estimated on the rest (:mod:`evinr_lite.method.prepare`). One run with
      ``background="keep"`` beside it (``python benchmarks/quality_zoo.py --methods
      kit,kit_unfiltered,...``): zoo mean 0.619 / 0.687 / 0.0364 -> 0.634 / 0.692 / 0.0366, real chunk
      0.354 / 0.423 / 0.0694 -> 0.360 / 0.429 / 0.0690, held-out mean 0.516 / 0.564 / 0.0680 -> 0.523 /
      0.569 / 0.0682, long_pan_20s 0.569 / 0.669 / 0.0352 -> 0.643 / 0.732 / 0.0307, unequal_onhot
      0.637 -> 0.784; costs chelsea_speed 0.552 -> 0.536 and ihc_warp 0.436 -> 0.412 (fast motion and
      sparse fine texture, where some signal events have no neighbour).
    - background="auto" instead of "filter" (2026-12-07, eleventh session): the filter's window, 50 ms to
      0.4 s or no filter, chosen from the events' own share of noise (:mod:`~evinr_lite.method.background`:
      the share read against random probes, the window that keeps the most signal net of twice the
      noise). A slow or sparse clean recording keeps its events (a 50 ms window dropped 10 % of a slow
      pan's); a noisy one keeps 50 ms. Figures in docs/defaults.md, "The background filter's window".

    With these, on the 13 short zoo scenes at full size (``benchmarks/zoo_results.md``, 2 cores):
    kit 0.643 / 0.703 / 0.0344, integration + the same L1 offset 0.559 / 0.635 / 0.0364 (the INR:
    1.15x in CLAHE-SSIM), HF with its cutoff swept per scene 0.532 / 0.586 / 0.0535, leaky
    integration swept 0.518 / 0.576 / 0.0543; real chunk 0.377 / 0.461 / 0.0696 (1.16x integration +
    offset); camera_240x180 (2 s at 180x240) in 1.15 s (one run with and without offset_coarse_px,
    ``--variant``: 1.2 s against 0.9 s; the committed run before it, on a quieter day: 0.61 s).
    - min_bins=64: short windows get shorter bins (at least 64 per window). The zoo's windows are
      2-3 s, so at 1/32 s they hold 64-96 bins and nothing changes there; on the 0.17 s real chunk
      (5 bins at 1/32 s) CLAHE-SSIM / SSIM go from 0.272 / 0.339 to 0.349 / 0.415. The cost: on the
      quick zoo (1.5-2.25 s scenes) the mean CLAHE-SSIM drops from 0.528 to 0.522.

    Events and bins:
        C: contrast threshold (log units per event; paper: 1 for IJRR/HQF, 0.25 for AED), or a pair
            (c_pos, c_neg): ON events weigh +c_pos, OFF events -c_neg (real sensors differ; fit both
            from APS frames with :func:`evinr_lite.method.contrast.fit_contrast`).
        bin_duration: final event-frame length in seconds (paper: 1/32 s), before ``temporal_scale``.
        temporal_scale: "auto" (the kit's) or a number s >= 1/64: the bins are bin_duration / s and the
            first layer's frequency (first_omega_per_s, or first_omega_0) s times higher. "auto" reads s
            from the events (:mod:`~evinr_lite.method.tempo`: 1 unless the pixels reverse polarity more
            than 2.5 times a second, as under a fast shake; at most 4); 1 keeps bin_duration and the
            prior as given (the paper's and v0_1's recipes). :meth:`final_bin_duration` gives the bins.
        min_bins: at least this many final fixed-duration bins per network window (shorter bins
            in short windows; 0: bin_duration alone decides, as in the paper).
        binning: "fixed" (paper: fixed-duration bins) or "equal_count" (the reference code).
        events_per_bin: final events per bin for "equal_count". The reference code fixes the number
            of bins instead (50, then 100 after one bisection at n_iters / 2, over the whole window):
            emulate it with events_per_bin = n_events // 100 and c2f_iters = (n_iters // 2,)
            (``ablation.recipe_variants`` does).
    Losses:
        temporal_loss: "derivative" (paper, Eq. 5-6: dF/dt at bin mid-points times bin length) or
            "difference" (F(b_{i+1}) - F(b_i) at bin boundaries: exact integral form).
        regularizer: "tikhonov" (paper, Eq. 9), "tv" (reference code) or "none".
        lam: weight lambda of the regularizer (paper: 0.05; finite differences in pixel units), or
            "auto": chosen from the events' activity per network window, LAM_SCALE / m^2 within
            [0.002, 0.01] (:mod:`~evinr_lite.method.smoothing`; m: events per pixel that came and went).
        spatial_order: the Tikhonov regularizer's order in the closed-form head (``head_solve``): 1, the
            gradient's energy |D F|^2 (the paper's Eq. 9, what Adam's loss uses); 2, the
            Laplacian's energy |D^T D F|^2, equal to order 1 at a wavelength of 8 px, so lam keeps its
            meaning there: coarser structure is smoothed less, finer more; "banded" (the kit's): order 1
            for structure coarser than 8 px and a third-order roll-off (mu^3 / mu_ref^2) for finer,
            continuous at 8 px (:func:`~evinr_lite.method.head_solve.penalty_spectrum`; measured in
            docs/defaults.md, "The spatial prior's order"). Adam's loss stays first-order.
        prior_time_order: alpha in [0, 1], the closed-form head's spatial prior's order in time: the
            penalty of each temporal mode of the features is weighted by (its change per bin against its
            spread, relative to the features' mean)^alpha. 0 penalises the frames' roughness (the paper's,
            what Adam's loss uses), 1 the per-bin changes'; the kit's 0.25 shrinks slow changes less and
            fast ones (quantization noise) more (:mod:`~evinr_lite.method.head_solve`; docs/defaults.md,
            "The spatial prior's order in time").
    Network (SIREN):
        hidden_features, hidden_layers: width and depth (paper: 512, 3).
        omega_0: frequency factor of the hidden layers (SIREN's default 30).
        first_omega_0: frequency factor of the first layer, which sets how fast F can vary in time
            (not in the paper; the reference code uses 10 everywhere). With 30, the network fits
            dF/dt at the bin mid-points while wandering between them, so integrated changes are
            wrong (notebook 01 shows the same in 1-D); 10 keeps F smooth at the scale of a bin.
            Each network maps its own window to [-1, 1], so shorter ensemble windows allow faster
            wiggles per second: with short windows prefer temporal_loss="difference" (notebook 06).
            Used as given when ``first_omega_per_s`` is None (the paper's recipe, v0_1); another value
            while first_omega_per_s is set is refused, since it would be ignored.
        first_omega_per_s: the first layer's frequency factor per second of the events' clock (the
            kit's default 5.0; None: ``first_omega_0`` as given). Each network's first_omega_0 is then
            first_omega_per_s x its window's length / 2 (:meth:`first_layer_omega`), so F may vary as
            fast per second in a 2 s window as in a 4.75 s one. With the closed-form head the hidden
            layers are never trained, so this frequency is the model's only temporal prior: lower is
            smoother in time. Chosen on the zoo, the held-out scenes, the long recordings and the real
            chunk: the figures are in the list of departures above and in docs/defaults.md.
    Optimisation:
        n_iters: iterations (paper: 300). lr, lr_decay, lr_decay_every: Adam with lr x lr_decay
            every lr_decay_every iterations (paper: 1e-4, 0.95, 10).
        head_lr_scale: learning-rate factor for the H*W output layer. Not in the paper: the public
            reference code multiplies the head's output by omega_0, which under Adam makes the head
            learn omega_0 times faster. We keep SIREN's small initial output and scale the head's
            learning rate instead (default 30 = omega_0); with 1, 300 iterations at lr 1e-4 leave
            the frames far from converged (see benchmarks/solver_quality.py).
        coarse_to_fine: bisect the bins at ``c2f_iters`` (paper: 3 stages, at 100 and 200).
    Ensembling:
        tau: longest window per network in seconds (paper: 5); None for one network.
        overlap: seconds shared by neighbouring windows (used to align and cross-fade them).
    Beyond the paper:
        head_solve: after the Adam iterations (if any), set the H*W output layer to the exact optimum
            of the loss for the hidden layers (a linear least-squares problem solved in closed form,
            :mod:`evinr_lite.method.head_solve`; needs regularizer "tikhonov" or "none").
        offset_solve: how the per-pixel offset that events cannot fix is chosen: "none" (left to the
            regularizer, as in the paper), "median_gradient" (:mod:`evinr_lite.method.offset`:
            the offset that makes the temporal median of each pixel's gradient zero) or "l1_gradient"
            (the offset that makes all frames' gradients sparsest together, their L1 norm summed over
            the frames: :func:`~evinr_lite.method.offset.l1_gradient_offset`, ADMM started from the
            median answer; the default).
        offset_window: with an offset solve, the seconds over which one offset image
            is solved: on spans longer than 1.5 windows the offset becomes a slow per-pixel trend,
            one image per ``offset_window`` seconds, linear in time between them
            (:func:`~evinr_lite.method.offset.offset_trend`); None: one image for any span.
        offset_coarse_px: with an offset solve, on spans of at most 3 s, the static image's spatial
            frequencies below this scale (a Gaussian's sigma, pixels) come from the integrated
            events' own offset solve, the finer ones and every change in time from the INR
            (:mod:`evinr_lite.method.coarse`); None: the static image from the INR's frames alone.
        camera: "moving" (the default) or "static" (the camera stood still, e.g. on a tripod, and
            things moved in front of it). Events never see a background at rest, so with "static"
            each edge's offset is solved from the frames in which something moved over it (a pixel
            more than STATIC_REST x C from its temporal median; :func:`~evinr_lite.method.offset.l1_gradient_offset`
            with ``rest``): where an object passed, the background it covered is recovered instead of
            being flattened; that solve sets the offset's structure finer than STATIC_COARSE_PX (8 px),
            the plain one the coarser (:func:`~evinr_lite.method.offset.offset_image`). Needs
            offset_solve "l1_gradient". Not for a moving camera: there every
            frame is informative and leaving the resting ones out loses (``python benchmarks/static_camera.py``).
        balance: "none" (ON and OFF events weigh C as given), "events" or "counts": when C is one number,
            C+ and C- are estimated from the events, their mean kept at C
            (:mod:`evinr_lite.method.balance`). "events": the consensus (minmod) of two estimates with
            different assumptions, the edges' (b that keeps each edge's change over time from
            following its two pixels' count difference) and the intervals between events of one
            polarity, and the counts alone (fitted with an intercept, so a change of light shared by all pixels
            does not count, and kept within the range of the other three estimates) where the span holds
            enough events that their error scale NET_CHANGE / (C events per pixel) is at most COUNTS_ALONE
            (long or busy recordings); where the edges and the intervals disagree in sign and the counts
            show no change of light, the smallest of the edges, the slope and the pooled counts;
            "counts": the counts' estimate alone, shrunk towards C as far as the span carries little
            evidence (the rule before the intervals). A given pair is used as it is.
        hot_pixels: "keep" or "drop": the events of pixels firing far above the sensor's robust rate
            (:func:`evinr_lite.method.denoise.hot_pixel_mask`) are left out before training.
        background: "keep", "filter" or "auto": background activity (isolated events with no event of the
            same polarity at a neighbouring pixel within ``background_dt`` before or after) is left out
            before training, after the hot pixels and before the ON/OFF balance and lam are estimated
            (:func:`evinr_lite.method.denoise.correlation_filter`, two-sided, same polarity; streamed
            windows are read with the filter's reach beyond their edges, so they see the same events).
            "auto" (the kit's) chooses the window, or no filter, from the events' own share of noise
            (:mod:`evinr_lite.method.background`); the returned config says which ("filter" with its
            ``background_dt``, or "keep").
        background_dt: seconds, the filter's window with ``background="filter"`` (50 ms: the fixed
            default before "auto"; a slow or sparse scene loses signal events below about 1 / speed).
            With "auto", which chooses it, another value is refused (it would not be used).
        anchor: APS frames as anchors (:mod:`evinr_lite.method.anchor`; pass ``frames=`` to
            :func:`reconstruct`): "none" (events only, the default), "first" (the first frame in the
            window sets the per-pixel offset) or "all" (every ``anchor_every``-th frame is a soft
            constraint on a slowly varying per-pixel offset; the others are held out for scoring).
            Anchored output is the frames' linear intensity, clip(exp(L) - 1/255, 0, 1), instead of
            the tone map; offset_solve and display_mean are then unused.
        anchor_every: with anchor "all", frames 0, k, 2k, ... of the window are anchors (k >= 1;
            default 2: every other frame is held out for scoring).
        anchor_smoothing: with anchor "all", the time scale s (seconds, >= 0) over which the offset
            may drift between anchors: 0 passes through every anchor frame, large s fits one
            least-squares offset per pixel.
    Output:
        tonemap: "linear" (clip(exp(F), 0, 1): the intensity whose log changes fired the events) or
            "reinhard" (the paper's Eq. 12, (I / (I + 1))^gamma), :mod:`evinr_lite.method.tonemap`.
        gamma: Reinhard's exponent (paper: 0.6; unused by "linear"). display_mean: the level events
            never fix: linear, the mean of the displayed frames over the sequence (0.4, a little below
            mid-grey); reinhard, the display value of the mean log intensity (the
            paper's 0.5). A user who knows the scene is dark or bright sets it (``evinr-lite
            reconstruct --display-mean``; on dark_falling 0.18, its truth's level, takes MSE 0.0623 -> 0.0049).
    Runtime:
        seed: seeds the initialisation. device: "cpu", "cuda" or None (GPU when present).
        progress: show a progress bar (terminal or notebook).
    """

    C: float | tuple = 1.0
    bin_duration: float = 1 / 32
    temporal_scale: float | str = "auto"
    min_bins: int = 64
    binning: str = "fixed"
    events_per_bin: int = 100
    temporal_loss: str = "difference"
    regularizer: str = "tikhonov"
    lam: float | str = "auto"
    spatial_order: int | str = "banded"
    prior_time_order: float = 0.25
    hidden_features: int = 128
    hidden_layers: int = 3
    omega_0: float = 30.0
    first_omega_0: float | None = FIRST_OMEGA_0
    first_omega_per_s: float | None = 5.0
    n_iters: int = 0
    lr: float = 1e-4
    lr_decay: float = 0.95
    lr_decay_every: int = 10
    head_lr_scale: float = 30.0
    coarse_to_fine: bool = False
    c2f_iters: tuple = (100, 200)
    tau: float | None = 5.0
    overlap: float = 0.5
    tonemap: str = DEFAULT_TONEMAP
    gamma: float = 0.6
    display_mean: float = DEFAULT_DISPLAY_MEAN
    head_solve: bool = True
    offset_solve: str = "l1_gradient"
    offset_window: float | None = 5.0
    offset_coarse_px: float | None = 8.0
    camera: str = "moving"
    balance: str = "events"
    hot_pixels: str = "drop"
    background: str = "auto"
    background_dt: float = DEFAULT_DT
    anchor: str = "none"
    anchor_every: int = 2
    anchor_smoothing: float = 0.03
    seed: int = 0
    device: str | None = None
    progress: bool = True

    def __post_init__(self):
        # Every field checked here (EventDataError, a ValueError): a bad value never reaches training.
        choices = {"binning": ("fixed", "equal_count"), "temporal_loss": ("derivative", "difference"),
                   "regularizer": ("tikhonov", "tv", "none"), "offset_solve": OFFSET_SOLVES,
                   "balance": BALANCE_MODES, "hot_pixels": HOT_PIXEL_MODES,
                   "background": BACKGROUND_MODES, "tonemap": TONEMAPS, "camera": CAMERAS}
        for name, allowed in choices.items():   # an array was numpy's "truth value ... is ambiguous"
            choice(getattr(self, name), allowed, name)
        self.spatial_order = choice(self.spatial_order, (1, 2, "banded"), "spatial_order", hint="1: the gradient's energy, 2: the "
               "Laplacian's, 'banded': order 1 coarser than 8 px, a third-order roll-off finer")   # a tensor was taken
        if self.head_solve and self.regularizer == "tv":
            raise EventDataError("head_solve=True needs regularizer 'tikhonov' or 'none' (TV has no closed form); "
                                 "pass head_solve=False to train the head with Adam")
        if self.camera == "static" and self.offset_solve != "l1_gradient":
            raise EventDataError(f"camera='static' solves the offset from the frames where something moved, which "
                                 f"needs offset_solve='l1_gradient', got {self.offset_solve!r}; pass "
                                 "offset_solve='l1_gradient' or camera='moving'")
        choice(self.anchor, ANCHOR_MODES, "anchor")
        if isinstance(self.anchor_every, bool) or not isinstance(self.anchor_every, (int, np.integer)) or \
                self.anchor_every < 1:
            raise EventDataError(f"anchor_every must be a whole number >= 1, got {self.anchor_every!r}")
        self.anchor_every = int(self.anchor_every)
        if isinstance(self.anchor_smoothing, bool) or not isinstance(self.anchor_smoothing, (int, float, np.integer, np.floating)) \
                or not (math.isfinite(self.anchor_smoothing) and self.anchor_smoothing >= 0):
            raise EventDataError(f"anchor_smoothing must be a finite number of seconds >= 0, got {self.anchor_smoothing!r}")
        self.anchor_smoothing = float(self.anchor_smoothing)

        def number(name, value, *, integer=False):
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) or (
                    integer and not float(value).is_integer()) or not math.isfinite(value):
                hint = ""
                if isinstance(value, str):   # '0.5' read from a file, a form or the command line
                    try:
                        number_ = float(value)
                        number_ = int(number_) if integer and number_.is_integer() else number_
                        hint = f"; pass the number itself ({name}={number_!r}), not text"
                    except ValueError:
                        pass
                raise EventDataError(f"{name} must be a finite {'whole ' if integer else ''}number, got {value!r}{hint}")
            return int(value) if integer else float(value)

        if isinstance(self.C, (tuple, list, np.ndarray)):   # (c_pos, c_neg), checked by the one parser of C
            self.C = as_thresholds(self.C, "C")
        else:                                               # one number, kept as given
            as_thresholds(self.C, "C")
        for name in ("bin_duration", "lr", "gamma", "omega_0", "head_lr_scale"):
            if not number(name, getattr(self, name)) > 0:
                raise EventDataError(f"{name} must be positive, got {getattr(self, name)}")
        if self.first_omega_0 is not None and not number("first_omega_0", self.first_omega_0) > 0:
            raise EventDataError(f"first_omega_0 must be positive (or None), got {self.first_omega_0}")
        if self.first_omega_per_s is not None and not number("first_omega_per_s", self.first_omega_per_s) > 0:
            raise EventDataError(f"first_omega_per_s must be positive (or None), got {self.first_omega_per_s}")
        if self.first_omega_per_s is not None and self.first_omega_0 != FIRST_OMEGA_0:   # it would be ignored
            raise EventDataError(f"first_omega_0={self.first_omega_0!r} is a frequency per window, but first_omega_per_s="
                                 f"{self.first_omega_per_s!r} (per second) sets the first layer; pass first_omega_per_s=None "
                                 "to use first_omega_0, or change first_omega_per_s instead")
        for name, low in (("n_iters", 0 if self.head_solve else 1), ("min_bins", 0), ("hidden_features", 1), ("hidden_layers", 0), ("lr_decay_every", 1),
                          ("events_per_bin", 1)):
            if number(name, getattr(self, name), integer=True) < low:
                raise EventDataError(f"{name} must be at least {low}, got {getattr(self, name)}")
            setattr(self, name, int(getattr(self, name)))
        if isinstance(self.temporal_scale, str):
            if self.temporal_scale != "auto":
                raise EventDataError(f"temporal_scale must be 'auto' (read from the events) or {SCALE_RANGE} (1: "
                                     f"bin_duration and the temporal prior as given), got {self.temporal_scale!r}")
        else:
            if not number("temporal_scale", self.temporal_scale) > 0:
                raise EventDataError(f"temporal_scale must be {SCALE_RANGE}, or 'auto', got {self.temporal_scale!r}")
            if float(self.temporal_scale) < MIN_SCALE:
                raise EventDataError(scale_floor_message("temporal_scale", self.temporal_scale))
            self.temporal_scale = float(self.temporal_scale)
        if isinstance(self.lam, str):
            if self.lam != "auto":
                try:
                    hint = f"; pass the number itself (lam={float(self.lam)!r}), not text"
                except ValueError:
                    hint = ""
                raise EventDataError(f"lam must be a number >= 0 or 'auto' (chosen from the events), got "
                                     f"{self.lam!r}{hint}")
        elif not number("lam", self.lam) >= 0:
            raise EventDataError(f"lam must be zero or positive (or 'auto'), got {self.lam}")
        if not number("background_dt", self.background_dt) > 0:
            raise EventDataError(f"background_dt must be a positive number of seconds (the filter's window, e.g. 0.05), "
                                 f"got {self.background_dt!r}")
        self.background_dt = float(self.background_dt)
        if self.background == "auto":                 # "auto" would set it without a word
            if not math.isclose(self.background_dt, DEFAULT_DT, rel_tol=1e-6):   # 0.05 through float32 is 0.05
                raise EventDataError(
                    f"background_dt={self.background_dt!r} is the filter's window with background='filter', but "
                    f"background='auto' (the kit's default) chooses the window itself from the events and would not "
                    f"use it; pass background='filter' with background_dt={self.background_dt!r} (both at once: "
                    f"dataclasses.replace(cfg, background='filter', background_dt=...), or set cfg.background = "
                    f"'filter' first), or leave background_dt at {DEFAULT_DT} with 'auto'")
            self.background_dt = DEFAULT_DT
        if not 0 <= number("prior_time_order", self.prior_time_order) <= 1:
            raise EventDataError(f"prior_time_order must be within [0, 1] (0: the frames' roughness, the paper's; 1: the "
                                 f"per-bin changes'; the kit's 0.25), got {self.prior_time_order!r}")
        self.prior_time_order = float(self.prior_time_order)
        if not 0 < number("lr_decay", self.lr_decay) <= 1:
            raise EventDataError(f"lr_decay must be in (0, 1], got {self.lr_decay}")
        if not 0 < number("display_mean", self.display_mean) < 1:
            raise EventDataError(f"display_mean must be in (0, 1), got {self.display_mean}")
        level = self.display_mean ** (1.0 / self.gamma)   # Reinhard's grey level: it must exist in floats (checked
        if not 0.0 < level < 1.0 or not math.isfinite(math.log(level / (1.0 - level))):   # for "linear" too)
            raise EventDataError(f"gamma={self.gamma!r} with display_mean={self.display_mean!r} leaves Reinhard's tone map no "
                                 f"grey level (display_mean ** (1 / gamma) = {level!r}); use a gamma of about 0.01 "
                                 "to 100 (the paper's 0.6)")
        if self.offset_window is not None and not number("offset_window", self.offset_window) > 0:
            raise EventDataError(f"offset_window must be positive seconds or None (one offset image for the whole "
                                 f"span), got {self.offset_window!r}")
        self.offset_window = None if self.offset_window is None else float(self.offset_window)
        if self.offset_coarse_px is not None and not number("offset_coarse_px", self.offset_coarse_px) > 0:
            raise EventDataError(f"offset_coarse_px must be a positive number of pixels or None (the static image "
                                 f"from the INR's frames alone), got {self.offset_coarse_px!r}")
        self.offset_coarse_px = None if self.offset_coarse_px is None else float(self.offset_coarse_px)
        if self.tau is not None and not number("tau", self.tau) > number("overlap", self.overlap) >= 0:
            raise EventDataError(f"need tau > overlap >= 0 seconds, got tau={self.tau}, overlap={self.overlap}")
        for name in ("head_solve", "coarse_to_fine", "progress"):
            if not isinstance(getattr(self, name), (bool, np.bool_)):
                raise EventDataError(f"{name} must be True or False, got {getattr(self, name)!r}")
        if isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) or not 0 <= self.seed < 2**63:
            raise EventDataError(f"seed must be a whole number in [0, 2**63), got {self.seed!r}")
        if self.device is not None and not (isinstance(self.device, str) and
                                            re.fullmatch(r"cpu|mps|cuda(:\d+)?", self.device)):
            raise EventDataError(f"device must be 'cpu', 'cuda', 'cuda:N', 'mps' or None (a GPU when present), "
                                 f"got {self.device!r}")
        if not isinstance(self.c2f_iters, (tuple, list, np.ndarray)):
            raise EventDataError(f"c2f_iters must be a tuple of iterations (e.g. (100, 200), or () for none), got "
                                 f"{self.c2f_iters!r}")
        self.c2f_iters = tuple(number("c2f_iters", i, integer=True) for i in self.c2f_iters)
        if self.coarse_to_fine:
            if any(i < 1 for i in self.c2f_iters) or list(self.c2f_iters) != sorted(set(self.c2f_iters)):
                raise EventDataError(f"c2f_iters must be increasing iterations >= 1, got {self.c2f_iters}")
            late = [i for i in self.c2f_iters if i >= self.n_iters]
            if late:   # a warning, not an error: fast-mode notebooks shorten n_iters under the default stages
                import warnings

                fix = (f"c2f_iters=({self.n_iters // 3}, {2 * self.n_iters // 3})" if self.n_iters >= 3
                       else "coarse_to_fine=False")
                warnings.warn(f"c2f_iters {late} are not inside the run of n_iters={self.n_iters} iterations: those "
                              f"bisections never happen, so the final bins are coarser than bin_duration; pass {fix}",
                              stacklevel=3)

    def __setattr__(self, name, value):
        """A field changed after construction (``cfg.tau = 2.0``) is checked as on construction: the whole
        config is built again with the new value (the same checks, the same messages), so a bad value is
        refused where it is set, not deep inside a run."""
        if name not in _FIELDS and not name.startswith("_"):   # a misspelt field set after construction was kept
            raise unknown_field(name, f"cfg.{name} = ... would set a new attribute that no step reads")
        if name in _FIELDS and id(self) not in _BUILDING:
            import warnings

            with warnings.catch_warnings():
                if name not in ("n_iters", "c2f_iters", "coarse_to_fine"):   # their warning concerns this change
                    warnings.simplefilter("ignore")
                value = getattr(replace(self, **{name: value}), name)
        object.__setattr__(self, name, value)

    @classmethod
    def paper(cls, **overrides) -> "EvINRConfig":
        """The paper's recipe exactly (Sec. 3-4): SIREN 3 x 512 with omega_0 = 30 in every layer, the
        derivative loss (Eq. 5-6) on 1/32 s bins, Tikhonov with lambda 0.05, Adam lr 1e-4 x 0.95 every
        10 iterations for 300 iterations, coarse-to-fine at 100 and 200, 5 s sub-sequences; one
        learning rate for every layer; no head or offset solve."""
        return cls(**{"C": 1.0, "bin_duration": 1 / 32, "binning": "fixed", "temporal_loss": "derivative",
                      "min_bins": 0, "regularizer": "tikhonov", "lam": 0.05, "hidden_features": 512, "hidden_layers": 3,
                      "omega_0": 30.0, "first_omega_0": None, "first_omega_per_s": None, "n_iters": 300, "lr": 1e-4, "lr_decay": 0.95,
                      "lr_decay_every": 10, "head_lr_scale": 1.0, "coarse_to_fine": True, "c2f_iters": (100, 200),
                      "tau": 5.0, "overlap": 0.5, "tonemap": "reinhard", "gamma": 0.6, "display_mean": DISPLAY_MEANS["reinhard"], "head_solve": False, "offset_solve": "none", "offset_coarse_px": None,
                      "balance": "none", "hot_pixels": "keep", "background": "keep", "spatial_order": 1,
                      "prior_time_order": 0.0, "temporal_scale": 1.0, **overrides})

    @classmethod
    def v0_1(cls, **overrides) -> "EvINRConfig":
        """The kit's default of version 0.1 (before the scene zoo): the paper's recipe with
        first_omega_0 = 10 and head_lr_scale = 30, tuned on the demo scene alone. Kept so that
        benchmarks compare today's default with it in the same run."""
        return cls.paper(**{"first_omega_0": 10.0, "head_lr_scale": 30.0, **overrides})

    @classmethod
    def base(cls, **overrides) -> "EvINRConfig":
        """The paper's ablation 'Base': no spatial regularization, no coarse-to-fine."""
        return cls.v0_1(**{"regularizer": "none", "coarse_to_fine": False, **overrides})

    @classmethod
    def reference_code(cls, **overrides) -> "EvINRConfig":
        """The public reference code's choices where they differ from the paper (as far as this
        solver expresses them): anisotropic TV, equal-count bins, a boundary-difference temporal
        term (evaluated at the boundaries, without the code's half-bin shift), omega_0 = 10.

        Its bin count depends on the data (the code uses 100 bins over the window, 50 before one
        bisection at n_iters / 2): pass ``events_per_bin=n_events // 100, c2f_iters=(n_iters // 2,)``.
        Not expressible here: AdamW at a fixed lr 3e-4 for 1000 steps, the extra regularizer terms,
        the sigmoid tone mapping."""
        return cls.paper(**{"regularizer": "tv", "binning": "equal_count", "temporal_loss": "difference",
                            "omega_0": 10.0, "first_omega_0": 10.0, "head_lr_scale": 10.0, **overrides})

    def first_layer_omega(self, windows) -> float | None:
        """The first layer's frequency factor for networks on ``windows`` [N, 2] (seconds; equal lengths,
        as :func:`~evinr_lite.method.ensemble.split_windows` makes them): first_omega_per_s x the
        longest window's length / 2, or first_omega_0 when first_omega_per_s is None; either times the
        temporal scale (:meth:`scale`)."""
        s = self.scale()
        if self.first_omega_per_s is None:
            return self.first_omega_0 if self.first_omega_0 is None or s == 1 else float(self.first_omega_0 * s)
        w = np.asarray(windows, np.float64).reshape(-1, 2)
        return float(self.first_omega_per_s * s * float(np.max(w[:, 1] - w[:, 0])) / 2.0)

    def scale(self) -> float:
        """The temporal scale s as a number: ``temporal_scale``, or 1 while it is "auto" (before the
        solver has read it from the events, :func:`~evinr_lite.method.prepare.plan_from_counts`)."""
        return 1.0 if self.temporal_scale == "auto" else float(self.temporal_scale)

    def final_bin_duration(self) -> float:
        """The final bins' length in seconds: bin_duration / the temporal scale (:meth:`scale`)."""
        s = self.scale()
        return self.bin_duration if s == 1 else self.bin_duration / s

    def offset_rest(self) -> float | None:
        """The offset solve's ``rest`` (log units): None for a moving camera; for a static one STATIC_REST x
        the smaller threshold (a pixel that moved less since its median has seen no event)."""
        if self.camera != "static":
            return None
        return float(STATIC_REST * np.min(as_thresholds(self.C)))

    @property
    def n_bisections(self) -> int:
        """How many times the bins are halved during training."""
        return len(self.c2f_iters) if self.coarse_to_fine else 0


_FIELDS = frozenset(f.name for f in fields(EvINRConfig))
# configs being constructed (by id, while their __init__ and __post_init__ run): their fields are set freely there,
# and checked by __post_init__; kept outside the instance so that cfg.__dict__ holds the fields alone
_BUILDING: set = set()


class UnknownFieldError(EventDataError, TypeError, AttributeError):
    """A name that is no field of EvINRConfig (a misspelt keyword or attribute): an EventDataError, and the
    TypeError / AttributeError Python would have raised, so that code catching those still does."""


def unknown_field(name: str, how: str) -> UnknownFieldError:
    """The error for ``name``, no field of EvINRConfig, with the closest field names."""
    import difflib

    close = difflib.get_close_matches(name, sorted(_FIELDS), n=3, cutoff=0.6)
    return UnknownFieldError(f"EvINRConfig has no field {name!r} ({how})"
                             + (f"; did you mean {' or '.join(map(repr, close))}?" if close else
                                "; see help(EvINRConfig) for its fields"))


def _marking_construction(init):
    @functools.wraps(init)
    def wrapped(self, *args, **kwargs):
        unknown = [k for k in kwargs if k not in _FIELDS]
        if unknown:   # Python's TypeError named the word but not the field meant
            raise unknown_field(unknown[0], "a keyword given to EvINRConfig(...)")
        _BUILDING.add(id(self))
        try:
            init(self, *args, **kwargs)
        finally:
            _BUILDING.discard(id(self))
    return wrapped


EvINRConfig.__init__ = _marking_construction(EvINRConfig.__init__)
