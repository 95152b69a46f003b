"""What the check uses of an exercise: :class:`ExerciseLike`, the one type every module of the check names.

:class:`evinr_lite.teaching.exercises.Exercise` is one (a dataclass with these fields); the check names the protocol,
not that class, so that it never imports the registry, which imports the check.
"""
from __future__ import annotations

from typing import Any, Callable, Protocol


class ExerciseLike(Protocol):
    """An exercise as the check reads it: its inputs, its reference, its own hints and how to compare."""

    reference: Callable                                       # the reference solution
    hints: dict[str, Callable]                                # {message: wrong version of the reference}
    rtol: float                                               # tolerances of the built-in comparison
    atol: float
    compare: Callable[[Any, Any], str | None] | None          # compare(got, expected) -> message, replacing it
    observe: Callable[[Any, tuple, dict], Any] | None         # observe(result, args, kwargs): what is compared
    call: Any                 # how the notebooks call it (teaching.notebook_calls.NotebookCall), or None

    def cases(self) -> list[tuple[tuple, dict]]:
        """The seeded inputs as (args, kwargs) pairs."""
        ...
