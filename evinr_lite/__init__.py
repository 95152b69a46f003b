"""evinr-lite: event-camera video reconstruction with EvINR, as a small readable package.

    import evinr_lite as ev
    scene = ev.make_scene("camera", sensor_size=(120, 160), duration=2.0)
    events = ev.simulate_scene(scene, 0.0, 2.0, C=0.2, seed=0)
    rec = ev.reconstruct(events, [0.5, 1.0, 1.5], ev.EvINRConfig(C=0.2))

Subpackages, in layers (a module imports only its own layer or lower ones; the tests check it):

    core        Events, Frames, Recording; runtime (device, fast mode, cache folder)
    io          format detection and readers, the text parser, AEDAT4/Prophesee, the canonical HDF5
                format (reader and writer), export (PNG, GIF, MP4), sample data
    sim         synthetic scenes, the event simulator, Quad Bayer, synthetic recordings
    method      binning, SIREN, frame and coordinate INRs, losses and their fused kernel, the solver,
                tone mapping, colour, integration and baselines, C from frames
    evaluation  metrics, LPIPS, the one scoring path, ablations, event enhancement
    viz         every figure and the interact helper (the only matplotlib importer)
    teaching    the exercise registry and the modules behind each notebook
    apps        the command line, the demo, the reconstruct job

Data flow: file -> Events -> event frames -> solver -> log intensity -> tone map -> metrics / export.

Every subpackage's face is reachable from here (``ev.method.FrameINR``, ``ev.viz.show_frames``), each
imported on first use like every name here: the notebooks import only ``evinr_lite as ev`` (and one
teaching import), and ``import evinr_lite`` itself stays light.
"""
# Names are imported when first used (PEP 562), so that `import evinr_lite` and the command's
# start-up stay light (no numpy or torch): the command handles Ctrl-C from its first line, and
# `evinr-lite info` never imports torch.
_LAZY = {"core": ("EventDataError", "Events", "Frames", "Recording", "default_device", "fast_mode", "pick"),
         "evaluation": ("evaluate", "results_table"),
         "io": ("read_recording",),
         "method": ("EvINRConfig", "Reconstruction", "events_to_frames", "fixed_duration_boundaries",
                    "integrate_events", "reconstruct", "reconstruct_baseline", "tonemap_reinhard"),
         "sim": ("make_scene", "simulate_events_1d", "simulate_scene", "simulate_video")}
_HOME = {name: sub for sub, names in _LAZY.items() for name in names}


def __getattr__(name):
    import importlib

    if name in _HOME:
        value = getattr(importlib.import_module(f".{_HOME[name]}", __name__), name)
        globals()[name] = value
        return value
    if name in ("core", "io", "sim", "method", "evaluation", "viz", "teaching", "apps"):
        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_HOME))

__all__ = ["Events", "EventDataError", "Frames", "Recording", "read_recording", "make_scene", "simulate_scene",
           "simulate_video", "simulate_events_1d", "EvINRConfig", "reconstruct", "Reconstruction",
           "events_to_frames", "fixed_duration_boundaries", "integrate_events", "reconstruct_baseline",
           "tonemap_reinhard", "evaluate", "results_table", "fast_mode", "pick", "default_device"]

__version__ = "0.1.0"

