"""Teaching: the exercise registry (checks that say what is wrong) and the modules behind each notebook.

    from evinr_lite import teaching
    teaching.exercises.check("integrate_events_1d", my_function)

Each ``*_exercises`` module (and ``pde1d``, ``events2d``) registers its notebook's exercises when
imported; ``notebook_calls`` records how the notebooks call each exercise's function. This face imports every one of
them explicitly, so importing the subpackage (or any module
in it) fills the registry, and the imports are plain ones that import-linter and the circle test see.
Only this subpackage knows the registry; the library never registers anything. The check behind
``exercises.check`` lives in ``checking`` (one job per module), which never imports the registry.
"""
from . import exercises
from . import (ablation_exercises, accel_exercises, aed_exercises, coordinate_exercises, discussion_exercises,
               events2d, frame_exercises, head_exercises, notebook_calls, pde1d, poisson_exercises, realdata_exercises, recording_exercises, training_exercises)

__all__ = ["exercises", "pde1d", "events2d", "coordinate_exercises", "frame_exercises", "training_exercises",
           "head_exercises", "poisson_exercises", "accel_exercises", "ablation_exercises", "discussion_exercises", "realdata_exercises", "aed_exercises",
           "recording_exercises", "notebook_calls"]
