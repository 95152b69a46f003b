"""Synthetic data with ground truth: scenes, the event simulator, Quad Bayer, recordings on disk."""
from .scenes import Scene, MovingImageScene, MovingBarScene, make_scene
from .simulate import simulate_events_1d, simulate_video, simulate_scene, pixel_events
from .quadbayer import QuadBayerScene, simulate_colour_video
from .recordings import write_example_recording, synthetic_recording, find_recording

__all__ = ["Scene", "MovingImageScene", "MovingBarScene", "make_scene", "simulate_events_1d",
           "simulate_video", "simulate_scene", "pixel_events", "QuadBayerScene",
           "simulate_colour_video", "write_example_recording", "synthetic_recording",
           "find_recording"]
