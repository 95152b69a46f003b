"""Teaching: the exercise registry (checks that say what is wrong) and the modules behind each notebook.

    from evinr_lite.teaching import exercises, pde1d
    exercises.check("integrate_events_1d", my_function)

Each ``*_exercises`` module (and ``pde1d``, ``events2d``) registers its notebook's exercises when
imported; :mod:`~evinr_lite.teaching.exercises` imports them on the first lookup of an unknown name.
Only this subpackage knows the registry; the library never registers anything.
"""
from . import exercises

__all__ = ["exercises", "pde1d", "events2d", "coordinate_exercises", "frame_exercises", "training_exercises",
           "accel_exercises",
           "ablation_exercises", "discussion_exercises", "realdata_exercises", "aed_exercises",
           "recording_exercises"]
