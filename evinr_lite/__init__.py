"""evinr-lite: event-camera video reconstruction with EvINR, as a small readable package.

Modules, one job each:
    events      the `Events` container (t seconds float64, x column, y row, p +-1, (H, W))
    frames      `Frames`: ground-truth frames with timestamps
    readers     npy, IJRR text/folders, EVREAL folders, HQF-style h5 -> Recording(events, frames, meta)
    formats     AEDAT4 (DV/DAVIS, with frames) and Prophesee .raw/.dat readers (faery)
    binning     event frames over fixed-duration or equal-count bins (Eq. 2)
    simulate    ESIM-style event simulation (1-D signals, videos, scenes)
    scenes      synthetic scenes with ground truth at any time
    integration direct event integration
    models      FrameINR: N frame-based SIRENs F(t) -> [H, W] with stacked weights (Eq. 11)
    losses      temporal losses (derivative Eq. 5-6, boundary difference), Tikhonov (Eq. 9), TV
    solver      EvINRConfig and reconstruct(): training, coarse-to-fine, ensembles, anchoring
    coordinate  the paper's basic coordinate network F(x, y, t) with autograd derivatives
    tonemap     Reinhard tone mapping (Eq. 12)
    metrics     MSE, SSIM, equalisation (none/global/CLAHE) and the protocol text
    lpips       LPIPS (AlexNet, v0.1) without torchvision
    baselines   integration, leaky integration, the high-pass filter (Scheerlinck et al.)
    evaluation  match by timestamp, score, pool, evaluate(), tables and bar charts
    enhance     events re-rendered from a trained model, scored against clean events
    ablation    named EvINRConfig variants run and scored side by side (notebook 07)
    quadbayer   Quad Bayer colour filter, colour event simulation, demosaicing of frames and events
    colour      per-channel colour EvINR
    realdata    event rate, contrast threshold fitted from frames, frames to score (notebook 09)
    sample_data the shared real recording beside the project, or a synthetic stand-in
    siren       SIREN networks (sine activations, SIREN initialisation)
    pde1d       the 1-D pieces of notebook 01 (window sums, Eq. 4, a 1-D SIREN fit)
    events2d    notebook 02's exercise references (one pixel's ESIM step, event frames)
    frame_exercises, accel_exercises   exercise references and helpers of notebooks 04-06
    ablation_exercises, aed_exercises, recording_exercises   exercise references of notebooks 07, 10, 11
    plot_frames frame grids and loss curves for the notebooks
    viz         looking at events: x-y-t scatter, polarity images, rates, animations
    exercises   exercise checks that say what is wrong, with fallback to the reference
    widgets     `interact`: sliders in a live front end, one static figure otherwise
    plotting    figures for the notebooks (the method modules never import matplotlib)
    demo, cli   the `evinr-lite` command and the README's demo
    recon_job   the reconstruct job: load -> window -> reconstruct -> score -> export
    export      PNG frames, GIF, MP4
    fastmode    small sizes for tests and CI (EVINR_FAST)
    device      CPU by default, a GPU when present
"""
from .binning import (EventFrames, equal_count_boundaries, events_to_frames, events_to_frames_chunked,
                      fixed_duration_boundaries)
from .device import default_device
from .events import EventDataError, Events, normalize_polarity
from .fastmode import fast_mode, pick
from .frames import Frames
from .readers import Recording, read_events, read_recording
from .integration import integrate_events
from .scenes import MovingBarScene, MovingImageScene, make_scene
from .simulate import simulate_events_1d, simulate_scene, simulate_video
from .solver import EvINRConfig, Reconstruction, reconstruct
from .tonemap import tonemap_reinhard
from .baselines import reconstruct_baseline
from .evaluation import evaluate, results_table, score_sequence

__version__ = "0.1.0"
