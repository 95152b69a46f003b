"""Every figure of the kit (the only subpackage that imports matplotlib) and the interact helper."""
from .events import (ON_COLOR, OFF_COLOR, EVENT_FRAME_CMAP, plot_xyt, plot_count_map, plot_polarity, polarity_image, count_map, plot_event_rate, plot_boundaries, show_event_frames, animate_events)
from .signals import plot_event_ticks, plot_signal_and_events, plot_reconstruction_1d, plot_window_errors
from .frames import show_frames, show_images, plot_histories
from .results import plot_results, plot_ablation, plot_tradeoff, plot_robustness
from .widgets import interact

__all__ = ["ON_COLOR", "OFF_COLOR", "EVENT_FRAME_CMAP", "plot_xyt", "plot_count_map", "plot_polarity",
           "polarity_image", "count_map", "plot_event_rate", "plot_boundaries",
           "show_event_frames", "animate_events", "plot_event_ticks", "plot_signal_and_events",
           "plot_reconstruction_1d", "plot_window_errors", "show_frames", "show_images",
           "plot_histories", "plot_results", "plot_ablation", "plot_tradeoff", "plot_robustness", "interact"]
