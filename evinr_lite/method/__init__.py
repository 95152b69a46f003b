"""EvINR and its baselines: binning, networks, losses, the solver, tone mapping, colour, C from frames, the ON/OFF
balance from events, denoising."""
from .binning import (EventFrames, events_to_frames, events_to_frames_chunked, fixed_duration_boundaries, equal_count_boundaries, bisect_boundaries, event_rate, as_thresholds)
from .siren import Siren, SineLayer
from .models import FrameINR
from .config import EvINRConfig
from .ensemble import split_windows
from .solver import Reconstruction, reconstruct
from .tonemap import tonemap_reinhard, anchor_level, anchor_mean
from .integration import integrate_events
from .baselines import reconstruct_baseline, leaky_integration, highpass_filter, complementary_filter
from .coordinate import CoordinateConfig, reconstruct_coordinate, predict_anchored
from .colour import reconstruct_colour, channel_offsets_from, chroma_correlation
from .contrast import frame_log_changes, estimate_contrast_threshold, fit_contrast, ContrastFit
from .balance import BalanceFit, estimate_balance
from .denoise import DenoiseReport, correlation_filter, hot_pixel_mask, remove_hot_pixels, denoise_mask
from .losses import temporal_loss_derivative, temporal_loss_difference, tikhonov   # the notebooks call these
from .offset import median_gradient_offset, l1_gradient_offset, poisson_integrate
from .anchor import linear_frames
# `method.denoise` stays the module (call method.denoise.denoise(events)): re-exporting the function under the
# module's own name would hide the module from attribute access.

__all__ = ["EventFrames", "events_to_frames", "events_to_frames_chunked",
           "fixed_duration_boundaries", "equal_count_boundaries", "bisect_boundaries",
           "event_rate", "Siren", "SineLayer", "FrameINR", "EvINRConfig", "Reconstruction",
           "reconstruct", "split_windows", "tonemap_reinhard", "anchor_level", "anchor_mean",
           "integrate_events", "reconstruct_baseline", "leaky_integration", "highpass_filter",
           "complementary_filter",
           "CoordinateConfig", "reconstruct_coordinate", "reconstruct_colour", "frame_log_changes",
           "estimate_contrast_threshold", "denoise", "DenoiseReport", "hot_pixel_mask",
           "remove_hot_pixels", "correlation_filter", "fit_contrast", "ContrastFit", "as_thresholds",
           "predict_anchored", "channel_offsets_from", "chroma_correlation", "denoise_mask", "temporal_loss_derivative",
           "temporal_loss_difference", "tikhonov", "median_gradient_offset", "l1_gradient_offset", "poisson_integrate",
           "linear_frames", "estimate_balance", "BalanceFit"]
