"""The check behind ``exercises.check`` and ``exercises.use``: run a learner's function, say what is wrong.

:mod:`evinr_lite.teaching.exercises` holds the registry and the notebook's entry points; this package is the
check itself, one job per module, lowest first:

- ``compare``: compare an output with the reference's (type, shape, dtype, values) and describe values;
- ``global_state``: what a call can change for the whole notebook: torch's settings, the global generators;
- ``calls``: run the learner's function on copied inputs; where it raised; what it changed in place;
- ``hints``: likely mistakes read off a wrong output (a flipped sign, a factor, indices from 1, ...);
- ``mistakes``: wrong versions made from the reference, confirmed on the other inputs;
- ``across_calls``: mistakes seen only across inputs or on a second call (kept state, a stale argument, a
  shared result, a reseeded generator);
- ``evaluate``: the main loop tying them together, in the order the report relies on.

An ``Exercise`` is named in annotations only, as a string: this package never imports the registry (which imports
it), so that the check stays below the registry, with no circle.
"""
from . import across_calls, calls, compare, evaluate, global_state, hints, mistakes

__all__ = ["compare", "global_state", "calls", "hints", "mistakes", "across_calls", "evaluate"]
