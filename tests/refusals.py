"""Helpers the bad-input rounds share (tests/test_robustness_round11.py and later): a call must be refused clearly."""
import pytest


def refused(fn, pattern, kind=ValueError):
    """fn() must raise a clear error (EventDataError is a ValueError) whose message matches pattern."""
    with pytest.raises(kind, match=pattern):
        fn()


def all_refused(calls, pattern, kind=ValueError):
    """Every call in ``calls`` must raise a clear error matching pattern (one case of several related inputs)."""
    for call in calls:
        refused(call, pattern, kind)
