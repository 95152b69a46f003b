"""Helpers the rounds of wrong exercise solutions share (tests/test_exercise_wrong_solutions_round3.py and later)."""
import contextlib
import io
import json
import re
import warnings
from pathlib import Path

from evinr_lite.teaching import exercises

ROOT = Path(__file__).resolve().parents[1]


def report(name, fn):
    """(the check's verdict, the report it prints) for ``fn`` as exercise ``name``; warnings silenced."""
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ok = exercises.check(name, fn)
    return ok, buf.getvalue()


def assert_fails_naming(name, wrong, words):
    """``wrong`` fails exercise ``name`` with a report that holds ``words`` and no traceback."""
    ok, text = report(name, wrong)
    assert not ok, text
    assert words in text, text
    assert "Traceback" not in text


def assert_passes(name, fn):
    """``fn`` passes exercise ``name``."""
    ok, text = report(name, fn)
    assert ok, text


def quoted_counts() -> dict:
    """{check name: N} from every notebook's "✓ NAME: matches the reference on N inputs"."""
    quoted = {}
    for path in sorted((ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb")):
        text = "".join("".join(c["source"]) for c in json.loads(path.read_text())["cells"])
        for name, n in re.findall(r"✓ (\w+): matches the reference on (\d+) input", text):
            quoted[name] = int(n)
    return quoted


def case_ids(rows):
    """pytest ids "exercise-k-function" for rows (exercise name, function, ...); a callable without a name (a
    functools.partial, an object with __call__) by its type's."""
    return [f"{r[0]}-{k}-{getattr(r[1], '__name__', type(r[1]).__name__)}" for k, r in enumerate(rows)]


@contextlib.contextmanager
def seeded_numpy(seed: int = 7):
    """numpy's global generator seeded for one check (the reports compare calls) and set back afterwards."""
    import numpy as np

    state = np.random.get_state()
    np.random.seed(seed)
    try:
        yield
    finally:
        np.random.set_state(state)
