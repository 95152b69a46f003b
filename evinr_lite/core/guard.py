"""The one ``main()`` guard of every command (``evinr-lite`` and ``python -m data_fetch``).

Standard library only, so that it can be in force from a command's first instruction, before numpy
or torch are imported (importing them takes a second or more, and a Ctrl-C then must not print a
traceback). What it guarantees:

- **exit status**: 0 done; 2 a bad input (``PROG: error: ...``, the errors the command names as
  expected, and OSError); 1 an internal error (a bug: ``--debug`` shows the traceback); 128 + n
  after signal n (130 SIGINT, 143 SIGTERM, 129 SIGHUP).
- **signals**: SIGINT, SIGTERM and SIGHUP raise :class:`Interrupted` once, wherever the command is
  (importing, reading, training, writing); further signals during the cleanup that follows are
  noted, not raised, so cleanup completes and no second traceback appears. An interruption that
  some library swallowed still ends the command with 128 + n, never 0.
- **pipes**: a reader that closed stdout or stderr (``| head -1``, ``| true``) does not change the
  result: what cannot be shown is dropped and the command goes on; the exit status is the command's.
- **the current folder**: a deleted current folder is refused with the fix before anything else
  runs (native libraries abort the process on it).
- **shutdown**: when the guard owns the process (a command, not a call from Python), signals that
  arrive after the command finished no longer raise (no traceback from ``atexit`` handlers).
"""
from __future__ import annotations

import os
import signal
import sys
import threading
from contextlib import contextmanager

__all__ = ["InputError", "host_array", "dense_array", "check_unmasked", "Interrupted", "TERMINATION_SIGNALS", "termination_signals", "signals_deferred",
           "run_guarded", "protect_streams", "check_cwd", "EXIT_OK", "EXIT_ERROR", "EXIT_INTERNAL"]


def host_array(value):
    """``value`` with a torch tensor (on any device, requiring grad or not) made a numpy array of the same values
    (``tensor.detach().cpu().numpy()``); anything else as it is. Called where arrays enter the API, so that
    ``np.asarray`` never meets a tensor that requires grad ("Can't call numpy() on Tensor that requires grad")
    or sits on a GPU; torch is not imported here."""
    if type(value).__module__.startswith("torch") and hasattr(value, "detach") and hasattr(value, "cpu"):
        return value.detach().cpu().numpy()
    return value


def dense_array(value, name: str, dtype=None, error: type[Exception] | None = None,
                want: str = "one flat list or 1-D array (np.concatenate the pieces)"):
    """``np.asarray(host_array(value), dtype)``, with a ragged nest (``[[0.1], [0.2, 0.3]]``: rows of
    different lengths, which numpy refuses with "setting an array element with a sequence") or values that
    are not numbers where ``dtype`` asks for them refused as ``error`` (default :class:`InputError`) naming
    ``name`` and the fix (``want``: what to give instead), instead of numpy's bare ValueError. Also refused
    by name: a generator, iterator or set (numpy makes a 0-d object array of it), a masked array with masked
    entries (:func:`check_unmasked`) and a Python integer beyond int64 (numpy keeps it as an object). numpy is
    imported on first use."""
    import numpy as np

    error = InputError if error is None else error
    value = host_array(value)
    if isinstance(value, (set, frozenset)) or (hasattr(value, "__next__") and hasattr(value, "__iter__")):
        raise error(f"{name} is a {type(value).__name__}, which numpy takes as one object, not as values"
                    + ("; a set has no order either" if isinstance(value, (set, frozenset)) else "")
                    + f": give {want} (list(...) of it)")
    check_unmasked(value, name, error)
    try:
        arr = np.asarray(value, dtype=dtype)
    except (TypeError, ValueError) as err:
        text = " ".join(repr(value).split())
        text = text if len(text) <= 60 else f"{type(value).__name__} {text[:50]}..."
        if "inhomogeneous" in str(err) or "sequence" in str(err):
            raise error(f"{name} is ragged (its parts have different lengths or shapes: {text}), so it is no "
                        f"array; give {want}") from None
        raise error(f"{name} must be numbers, got {text} ({err})") from None
    return _object_integers(arr, name, error) if arr.dtype == object and arr.ndim else arr


def check_unmasked(value, name: str, error: type[Exception] | None = None) -> None:
    """Refuse (``error``, default :class:`InputError`) a numpy masked array with masked entries: ``np.asarray``
    drops the mask and would use the values under it as if they were data (netCDF4, ``np.genfromtxt(...,
    usemask=True)`` and ``np.ma`` give such arrays). A masked array with nothing masked passes."""
    import numpy as np

    if isinstance(value, np.ma.MaskedArray) and np.ma.is_masked(value):
        masked = int(np.ma.count_masked(value))
        raise (error or InputError)(
            f"{name} is a masked array with {masked} of its {np.size(value)} values masked; the values under the "
            f"mask are no data: drop those entries (a.compressed(), with the same entries of the other columns) or "
            f"fill them (a.filled(value)) first")


def _object_integers(arr, name: str, error):
    """``arr`` (an object array [...]) as it is, after refusing (``error``) by name and index a Python integer
    beyond int64 among plain numbers: numpy keeps such a list as objects, which callers would call "not
    numbers" or "not integers" when the value is an integer, only too large for any clock or sensor."""
    import numbers

    flat = arr.ravel().tolist()
    if all(isinstance(v, (numbers.Integral, float)) and not isinstance(v, bool) for v in flat):
        for i, v in enumerate(flat):
            if isinstance(v, numbers.Integral) and not -2**63 <= v < 2**63:
                raise error(f"{name}[{i}] = {v} does not fit a 64-bit integer: no timestamp, pixel index or "
                            "polarity is that large, so the value is damaged; repair or drop it")
    return arr


EXIT_OK, EXIT_ERROR, EXIT_INTERNAL = 0, 2, 1
TERMINATION_SIGNALS = tuple(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name))


class InputError(ValueError):
    """A bad input the user can fix (a file, a path, a setting); the message names the problem and the fix.

    The command line prints it as ``evinr-lite: error: ...`` and exits with status 2. (Defined here,
    with the guard that maps it to its exit status; :mod:`evinr_lite.core.events` exports it.)"""


class EventDataError(InputError):
    """Event data that cannot be used as given. The message names the problem and the fix. (Defined here, beside
    :class:`InputError`, so that :mod:`evinr_lite.core.options` can raise it below :mod:`evinr_lite.core.events`,
    which exports it.)"""


class Interrupted(KeyboardInterrupt):
    """SIGINT, SIGTERM or SIGHUP arrived; ``signum`` says which (the exit status is 128 + signum)."""

    def __init__(self, signum: int = signal.SIGINT):
        super().__init__(signal.Signals(signum).name)
        self.signum = int(signum)


class _SignalState:
    """The signals seen since :func:`termination_signals` was entered; the first one raises, the rest are noted."""

    def __init__(self):
        self.seen: list[int] = []
        self.armed = True          # False once the command's work is over: signals are only noted
        self.swallowed = False     # the first Interrupted was raised where Python ignores exceptions

    def handler(self, signum, frame):
        self.seen.append(int(signum))
        if self.armed and (len(self.seen) == 1 or self.swallowed):
            self.swallowed = False
            raise Interrupted(signum)

    def unraisable(self, unraisable, previous):
        """sys.unraisablehook: an Interrupted raised inside a weakref callback, a __del__ or another place
        whose exceptions Python only prints (e.g. while an import releases its module lock) would be
        lost and the command would go on; deliver the signal once more instead, to be raised at the
        next ordinary line of the command."""
        exc = unraisable.exc_value
        if isinstance(exc, Interrupted) and self.armed:
            import _thread

            self.swallowed = True
            # from another thread, a moment later: a signal raised here would run its handler inside this hook
            timer = threading.Timer(0.05, _thread.interrupt_main, args=(exc.signum,))
            timer.daemon = True
            timer.start()
            return
        previous(unraisable)

    def note(self, signum, frame):
        self.seen.append(int(signum))


_state = _SignalState()


def _main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


@contextmanager
def termination_signals():
    """Inside the block SIGINT, SIGTERM and SIGHUP raise :class:`Interrupted` (once: later ones are
    noted while the cleanup runs), so cleanup runs for all three. SIGINT is left alone when it is
    ignored (a background job). Outside the main thread the block runs unprotected."""
    global _state
    if not _main_thread():
        yield
        return
    outer, _state = _state, _SignalState()
    previous = {}
    state, hook = _state, sys.unraisablehook
    try:   # handlers are installed inside the try: a signal right after the first one still restores them all
        for sig in TERMINATION_SIGNALS:
            current = signal.getsignal(sig)
            if sig == signal.SIGINT and current in (signal.SIG_IGN, None):
                continue
            previous[sig] = current
            signal.signal(sig, state.handler)
        sys.unraisablehook = lambda unraisable: state.unraisable(unraisable, hook)
        yield
    finally:
        sys.unraisablehook = hook
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        seen, _state = _state.seen, outer
        outer.seen.extend(seen)


@contextmanager
def signals_deferred():
    """Hold back SIGINT, SIGTERM and SIGHUP inside the block; one that arrives is acted on when the
    block ends (its handler runs then, or its default action). Only the main thread can do this
    (Python runs signal handlers there); elsewhere the block runs unprotected."""
    if not _main_thread():
        yield
        return
    pending, previous = [], {}
    try:   # inside the try: a signal between two installations still gets every handler restored
        for sig in TERMINATION_SIGNALS:
            handler = signal.getsignal(sig)
            if handler in (signal.SIG_IGN, None):
                continue
            previous[sig] = handler
            signal.signal(sig, lambda signum, frame: pending.append(signum))
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        if pending:
            handler = previous[pending[0]]
            if callable(handler):
                handler(pending[0], None)        # e.g. raises KeyboardInterrupt / Interrupted
            elif handler == signal.SIG_DFL:
                os.kill(os.getpid(), pending[0])  # the default action, now that the block is done


class _PipeSafe:
    """A text stream whose reader may go away: a broken pipe drops what follows instead of raising."""

    def __init__(self, stream):
        self._stream = stream
        self.closed_by_reader = False

    def _drop(self):
        self.closed_by_reader = True
        try:   # the descriptor now points at /dev/null, so the interpreter's final flush succeeds too
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, self._stream.fileno())
            os.close(devnull)
        except (OSError, ValueError, AttributeError):
            pass

    def write(self, text):
        if self.closed_by_reader:
            return len(text)
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            self._drop()
            return len(text)

    def flush(self):
        if self.closed_by_reader:
            return
        try:
            self._stream.flush()
        except BrokenPipeError:
            self._drop()

    def __getattr__(self, name):
        return getattr(self._stream, name)


def protect_streams() -> None:
    """Make sys.stdout and sys.stderr safe against a reader that closed the pipe (idempotent)."""
    for name in ("stdout", "stderr"):
        stream = getattr(sys, name)
        if stream is not None and not isinstance(stream, _PipeSafe):
            setattr(sys, name, _PipeSafe(stream))


class CwdMissing(OSError):
    """The current folder no longer exists."""


def check_cwd() -> None:
    """Raise :class:`CwdMissing` (an OSError: exit status 2) when the current folder was deleted."""
    try:
        os.getcwd()
    except FileNotFoundError:
        raise CwdMissing("the current folder was deleted (by another program); change to an existing folder "
                         "(cd) and run the command again") from None


def _signal_name(signum: int) -> str:
    return signal.Signals(signum).name


def _interrupted(prog: str, exc: KeyboardInterrupt, state, interrupted_note) -> int:
    """Say that ``exc`` (a signal's :class:`Interrupted`, or Python's KeyboardInterrupt) ended the command; its status."""
    state.armed = False
    signum = exc.signum if isinstance(exc, Interrupted) else signal.SIGINT
    note = interrupted_note(exc) if interrupted_note is not None else None
    where = f"; {note}" if note else ""
    print(f"\n{prog}: interrupted by {_signal_name(signum)}{where} (partial results are deleted)", file=sys.stderr)
    return 128 + int(signum)


def _interruption_behind(exc: BaseException, depth: int = 16):
    """The KeyboardInterrupt (or :class:`Interrupted`) that ``exc`` was raised from or while handling, if any: a
    library that catches a signal's exception and raises its own (numpy's import turns it into an ImportError)."""
    seen = set()
    while exc is not None and depth > 0 and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return exc
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
        depth -= 1
    return None


def run_guarded(prog: str, body, argv, *, expected=(), describe=str, interrupted_note=None, out_of_memory=None,
                debug=lambda: False, owns_process: bool = False) -> int:
    """Run ``body()`` (which parses ``argv`` and does the work; returns an exit status) under the guard.

    Args:
        prog: the name in messages (``PROG: error: ...``).
        body: a callable; it may import heavy modules: signals are handled from before its first line.
        argv: the arguments, for the ``--debug`` rerun line of an internal error.
        expected: exception classes that are bad input (status 2); InputError and OSError always are.
        describe: exception -> message text (e.g. parameter names turned into flags).
        interrupted_note: exception -> a note on what happened to the output, or None.
        out_of_memory: exception -> a message when the exception means memory ran out (status 2), else None.
        debug: -> True when the traceback of an internal error should be shown.
        owns_process: the command is the process (not a call from Python): at the end, later signals
            are ignored so that the interpreter's shutdown is not interrupted.
    """
    import traceback

    global _state
    code = None
    outer, state = _state, _SignalState()
    previous = {}
    try:
        # The handlers are installed inside the try: a signal that arrives as soon as one is in place
        # (the loop has not finished yet) is still an Interrupted that this function catches.
        if _main_thread():
            _state = state
            for sig in TERMINATION_SIGNALS:
                current = signal.getsignal(sig)
                if sig == signal.SIGINT and current in (signal.SIG_IGN, None):
                    continue                  # a background job ignores Ctrl-C: so do we
                previous[sig] = current
                signal.signal(sig, state.handler)
        protect_streams()
        check_cwd()
        code = body()
        code = EXIT_OK if code is None else int(code)
    except SystemExit as exc:   # argparse: --help (0) or a bad option (2, already printed)
        code = exc.code if isinstance(exc.code, int) else EXIT_ERROR
    except KeyboardInterrupt as exc:
        code = _interrupted(prog, exc, state, interrupted_note)
    except (InputError, OSError, *expected) as exc:
        print(f"{prog}: error: {describe(exc)}", file=sys.stderr)
        code = EXIT_ERROR
    except Exception as exc:
        message = out_of_memory(exc) if out_of_memory is not None else None
        cause = _interruption_behind(exc)
        if cause is not None:   # a library turned the signal into its own error (numpy's ImportError mid-import)
            code = _interrupted(prog, cause, state, interrupted_note)
        elif message:
            print(f"{prog}: error: {message}", file=sys.stderr)
            code = EXIT_ERROR
        elif debug():
            traceback.print_exc()
            code = EXIT_INTERNAL
        else:
            print(f"{prog}: internal error: {type(exc).__name__}: {exc}\n  This is a bug in {prog}, not a "
                  f"problem with your input. Rerun with --debug to see the traceback and include it in a "
                  f"report:\n  {prog} --debug {' '.join(str(a) for a in argv)}", file=sys.stderr)
            code = EXIT_INTERNAL
    finally:
        state.armed = False      # from here on a signal is noted, not raised
        if owns_process:         # the process only exits now: no traceback from atexit handlers
            for sig in previous:
                signal.signal(sig, state.note)
        else:
            for sig, handler in previous.items():
                signal.signal(sig, handler)
            _state = outer
    if state.seen and code == EXIT_OK:   # an interruption some library swallowed: never a success
        print(f"\n{prog}: interrupted by {_signal_name(state.seen[0])}", file=sys.stderr)
        code = 128 + state.seen[0]
    try:
        sys.stdout.flush()
    except (OSError, ValueError):
        pass
    return code
