"""A clock many times faster, for the learner's own reads only: a result that depends on a time budget
(``while time.perf_counter() - t0 < 0.1``) changes when each read moves an hour ahead (round 17).

The time module's clocks are captured once, here, at import (:data:`REAL_CLOCKS`), and each has one fake
(:data:`FAKE_CLOCKS`), made once. :func:`fast_clock` puts the fakes into the time module (and into the learner's
globals, for a name bound with ``from time import perf_counter``) while its block runs, and the captured real clocks
back after it (or, where another patch of the time module was in place when the first block began, a test's
frozen clock, that patch; never a fake). A fake moves only where a block is running *on the calling thread*, in
*the process that started it*, and the read comes from the learner's own code (a file neither a library's nor this
kit's); everywhere else it calls the real clock and returns its value unchanged. So a fake that outlives the block
(a reference taken during it, ``from time import perf_counter`` run by a module imported during it, a check in
another thread that put the fakes in later, a fork()ed child) reads exactly like the real clock. Overlapping blocks
in two threads compose: the fakes go in with the first block and the real clocks come back with the last (a depth
count under a lock).

The fakes live in this file, not in :mod:`.learner_calls`, whose frames :func:`.learner_calls.time_limit`'s alarm
leaves alone: a loop that spends its time reading the clock is stopped at the time limit like any other. A read is
counted per clock (a dict of at most ten counts), not stored, so an endless loop of reads uses no memory.

Not covered (such reads stay real): ``datetime.datetime.now()`` and other C-level reads, a clock bound before the
block in a default argument (``clock=time.perf_counter``) or in a module other than the function's own
(``timeit.default_timer``, a helper module's ``from time import perf_counter``), reads in threads the learner
starts, and in processes it starts (spawned, or fork()ed: the child reads the real clock).
"""
from __future__ import annotations

import contextlib
import functools
import os
import sys
import threading
import time
from typing import Callable, Iterator

from .learner_calls import KIT_ROOT, learner_function, library_file

# the time module's clocks, each read faster inside :func:`fast_clock`
CLOCKS = ("time", "perf_counter", "monotonic", "process_time", "thread_time",
          "time_ns", "perf_counter_ns", "monotonic_ns", "process_time_ns", "thread_time_ns")
CLOCK_STEP_S = 3600.0      # how far the clocks move at each of the learner's reads inside :func:`fast_clock`

# captured once, at import: what every block puts back, whatever the time module held on entry
REAL_CLOCKS = {name: getattr(time, name) for name in CLOCKS if hasattr(time, name)}


class _Block:
    """One running :func:`fast_clock` block, on one thread: the process that started it, how far its clocks are
    ahead, and the reads counted per clock."""
    __slots__ = ("pid", "ahead", "reads")

    def __init__(self):
        self.pid = os.getpid()
        self.ahead = 0.0
        self.reads: dict = {}


_local = threading.local()          # .block: the innermost running block on this thread (absent: none)
_lock = threading.Lock()
_depth = [0]                        # blocks running, all threads together: the fakes are in while it is above 0
_entry: dict = {}                   # what the time module held when the first block began (a test's frozen clock)


@functools.lru_cache(maxsize=4096)
def learner_file(filename: str) -> bool:
    """A file of the learner's code: neither a library's (Python's own, site-packages) nor this kit's (the check,
    the references, the kit's helpers a learner's function may call)."""
    if library_file(filename):
        return False
    return not os.path.realpath(filename).startswith(KIT_ROOT + os.sep)


def _fake(name: str) -> Callable:
    real = REAL_CLOCKS[name]
    in_ns = name.endswith("_ns")

    def read():
        block = getattr(_local, "block", None)
        if block is None or block.pid != os.getpid():
            return real()
        try:
            caller = sys._getframe(1).f_code.co_filename
        except ValueError:                  # called from C with no Python frame above
            return real()
        if not learner_file(caller):
            return real()
        block.reads[name] = block.reads.get(name, 0) + 1
        block.ahead += CLOCK_STEP_S
        return real() + (int(block.ahead * 1e9) if in_ns else block.ahead)

    read.__name__ = read.__qualname__ = name
    read.__doc__ = real.__doc__
    return read


# one fake per clock, made once: the same object in every block, the real clock outside one
FAKE_CLOCKS = {name: _fake(name) for name in REAL_CLOCKS}


@contextlib.contextmanager
def fast_clock(fn: Callable) -> Iterator[dict]:
    """While the block runs, each read of a time module clock (time.time, time.perf_counter, time.monotonic, ...) by
    the learner's own code on this thread moves :data:`CLOCK_STEP_S` ahead, as on a machine (or an input) that many
    times slower; names that ``fn``'s globals bind to those clocks move too. Yields {clock name: reads}, filled as
    the block runs. See the module's docstring for what stays real."""
    fn = learner_function(fn)
    block = _Block()
    outer = getattr(_local, "block", None)
    namespace = getattr(fn, "__globals__", None)
    bound: dict = {}
    with _lock:
        if _depth[0] == 0:   # put back at the end: another patch of the time module (freezegun) outlives the check
            _entry.clear()
            for name, real in REAL_CLOCKS.items():
                held = getattr(time, name, real)
                _entry[name] = real if held is FAKE_CLOCKS[name] else held
        _depth[0] += 1
        for name, fake in FAKE_CLOCKS.items():
            setattr(time, name, fake)
        if isinstance(namespace, dict):
            for key, value in list(namespace.items()):
                for name, real in REAL_CLOCKS.items():
                    if value is real:
                        namespace[key] = FAKE_CLOCKS[name]
                        bound[key] = name
    _local.block = block
    try:
        yield block.reads
    finally:
        _local.block = outer
        with _lock:
            for key, name in bound.items():
                if namespace.get(key) is FAKE_CLOCKS[name]:
                    namespace[key] = REAL_CLOCKS[name]
            _depth[0] -= 1
            if _depth[0] <= 0:
                _depth[0] = 0
                for name, real in REAL_CLOCKS.items():
                    setattr(time, name, _entry.get(name, real))
