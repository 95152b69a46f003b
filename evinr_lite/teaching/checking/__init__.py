"""The check behind ``exercises.check`` and ``exercises.use``: run a learner's function, say what is wrong.

:mod:`evinr_lite.teaching.exercises` holds the registry and the notebook's entry points; this package is the
check itself, one job per module, lowest first:

- ``protocol``: what the check uses of an exercise (``ExerciseLike``);
- ``outputs``: compare an output with the reference's (type, shape, dtype, values, and the gradients of a
  differentiable one) and describe values;
- ``global_state``: what a call can change for the whole notebook: torch's settings, numpy's error handling, the
  warning filters, the global generators;
- ``learner_calls``: run the learner's function on copied inputs; where it raised; what it changed in place;
- ``fast_clock``: the time module's clocks an hour ahead at each of the learner's own reads, while a block runs (a
  result that depends on a time budget then changes);
- ``hints``: likely mistakes read off a wrong output (a flipped sign, a factor, indices from 1, ...);
- ``mistakes``: wrong versions made from the reference (the wrong image axis among them), confirmed on the other
  inputs;
- ``across_calls``: mistakes seen only across inputs or on a second call (kept state, a stale argument, the same
  factor on every input, a shared result, a reseeded generator);
- ``learner_source``: slips read off the learner's source once it failed, each named on evidence (`^` for a power,
  where `**` in its place matches; the None of ``b = b.sort()``, where the call on a line of its own matches), and whether a
  NotImplementedError is the stub's own raise;
- ``signature``: the function called as the notebooks call it (each exercise's call, teaching/notebook_calls.py), and
  a default other than the stub's named where the stub's default makes the input match;
- ``run_check``: the main loop tying them together, in the order the report relies on.

An exercise is named in annotations by the protocol ``ExerciseLike``, never by the registry's ``Exercise``: this
package never imports the registry (which imports it), so that the check stays below the registry, with no circle.
"""
from . import (across_calls, fast_clock, global_state, hints, learner_calls, learner_source, mistakes, outputs, protocol,
               run_check, signature)

__all__ = ["protocol", "outputs", "global_state", "learner_calls", "fast_clock", "hints", "mistakes", "across_calls",
           "learner_source", "signature", "run_check"]
