"""Mutation testing of the exercise checks (tools/mutate_exercises.py): every reference solution is changed in
one place at a time, the ways learners err (operators, numbers off by one, left/right, x/y, sum/mean, a line left
out), and each check must reject every mutant except the ones a person judged equivalent to the reference on
every input the exercise's contract allows (tests/exercise_mutants_judged.json, each with the reason). A new
survivor is a wrong solution a check misses: make the exercise's inputs catch it (and add a hint naming it), or,
when it is truly equivalent, judge it in the file."""
import json
from pathlib import Path

from evinr_lite.teaching import exercises
from tools import mutate_exercises

ROOT = Path(__file__).resolve().parents[1]


def _tool():
    return mutate_exercises


def test_every_surviving_mutant_was_judged_equivalent():
    results = _tool().run(exercises.names(), limit=20.0, log=lambda *a: None)
    judged = json.loads((ROOT / "tests" / "exercise_mutants_judged.json").read_text())
    unjudged = [f"{name}: {s['change']} @ {s['code']}" for name, r in results.items() for s in r["survivors"]
                if f"{s['change']} @ {s['code']}" not in judged.get(name, {})]
    assert not unjudged, "wrong solutions the checks accept:\n" + "\n".join(unjudged)
    total = sum(r["mutants"] for r in results.values())
    assert total > 500                                   # the tool still mutates every reference
    assert all(r["mutants"] > 0 for name, r in results.items() if name != "render_event_counts")


def test_the_two_gaps_it_found_stay_closed(capsys):
    tool = _tool()
    from evinr_lite.teaching import accel_exercises, poisson_exercises

    for name, ref, change in (("bisect_equal_count", accel_exercises.bisect_equal_count, "lo <= median < hi"),
                              ("integrate_gradients", poisson_exercises.integrate_gradients, "H / W")):
        found = [fn for _, what, fn in tool.mutants(ref) if change in what.split("->")[-1]]
        assert found, f"the mutation {change!r} of {name} is no longer generated"
        assert not any(tool.passes(name, fn, 20.0) for fn in found)
