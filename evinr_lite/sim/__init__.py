"""Synthetic data with ground truth: scenes, the event simulator, Quad Bayer, recordings on disk."""
from .scenes import (Scene, MovingImageScene, OscillatingScene, MovingBarScene, VaryingSpeedScene, WarpedImageScene,
                     ObjectOverBackgroundScene, LightingScene, make_scene)
from .simulate import (simulate_events_1d, simulate_video, simulate_scene, pixel_events, add_background_noise,
                       add_hot_pixels, add_light_noise)
from .quadbayer import QuadBayerScene, simulate_colour_video
from .colour_davis import colour_davis_recording, write_colour_davis_recording
from .recordings import write_example_recording, synthetic_recording, find_recording
from . import zoo

__all__ = ["Scene", "MovingImageScene", "OscillatingScene", "MovingBarScene", "VaryingSpeedScene", "WarpedImageScene",
           "ObjectOverBackgroundScene", "LightingScene", "make_scene", "simulate_events_1d",
           "simulate_video", "simulate_scene", "pixel_events", "add_background_noise", "add_hot_pixels", "add_light_noise", "QuadBayerScene",
           "simulate_colour_video", "colour_davis_recording", "write_colour_davis_recording",
           "write_example_recording", "synthetic_recording",
           "find_recording", "zoo"]
