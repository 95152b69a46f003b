"""Issue 25 section 4: signals from the command's first instruction, pipes, a deleted current folder,
`info` without torch, and no leftovers (locks, partial folders) after signals or a full disk. Each
class goes through the one guard (evinr_lite.core.guard.run_guarded) with several instances."""
import errno
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from evinr_lite.core.guard import Interrupted, run_guarded, termination_signals
from evinr_lite.sim.recordings import write_example_recording

ENV = {**os.environ, "EVINR_FAST": "1", "PYTHONUNBUFFERED": "1"}
COMMANDS = {"evinr-lite": [sys.executable, "-m", "evinr_lite"], "data_fetch": [sys.executable, "-m", "data_fetch"]}


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    return write_example_recording(tmp_path_factory.mktemp("sig") / "rec", sensor_size=(24, 32), duration=0.3,
                                   frame_rate=10.0)


def _guard_installed(pid: int) -> bool:
    """The guard handles SIGTERM and SIGHUP (Python alone handles neither): both seen in the kernel's
    caught-signal mask. It installs its handlers one after another (SIGINT, SIGTERM, SIGHUP), so
    seeing SIGTERM's alone left a moment in which a SIGHUP still met the default action (CI saw it:
    exit -1 instead of 129)."""
    try:
        with open(f"/proc/{pid}/status") as f:
            mask = next(int(line.split()[1], 16) for line in f if line.startswith("SigCgt"))
    except (OSError, StopIteration):
        return False
    return all(mask & (1 << (sig - 1)) for sig in (signal.SIGTERM, signal.SIGHUP))


def _start(argv, cwd=None, **kw):
    return subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=ENV, cwd=cwd, **kw)


def _signal_at_first_instruction(argv, sig, cwd=None):
    proc = _start(argv, cwd=cwd)
    deadline = time.time() + 60
    while not _guard_installed(proc.pid) and proc.poll() is None and time.time() < deadline:
        time.sleep(0.0005)
    assert proc.poll() is None, "the command ended before its guard was seen"
    proc.send_signal(sig)
    out, err = proc.communicate(timeout=120)
    return proc.returncode, out, err


needs_proc = pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="reads /proc/<pid>/status")


@needs_proc
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
@pytest.mark.parametrize("command", ["reconstruct", "info", "data_fetch info"])
def test_signal_at_start_up_ends_cleanly(recording, tmp_path, sig, command):
    """The signal arrives as soon as the guard exists: while numpy/torch are still being imported."""
    argv = {"reconstruct": COMMANDS["evinr-lite"] + ["reconstruct", str(recording), "--out", str(tmp_path / "out"),
                                                     "--quiet"],
            "info": COMMANDS["evinr-lite"] + ["info", str(recording)],
            "data_fetch info": COMMANDS["data_fetch"] + ["info", str(tmp_path / "missing.h5")]}[command]
    code, out, err = _signal_at_first_instruction(argv, sig)
    assert code == 128 + sig, (code, err)
    assert "Traceback" not in err and f"interrupted by {signal.Signals(sig).name}" in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == []               # nothing left behind


@needs_proc
def test_three_quick_sigints_while_writing_end_once_without_leftovers(recording, tmp_path):
    """Three SIGINTs while the frames are being written: one message, status 130, no traceback (none
    from atexit either), no partial folder and no lock file."""
    script = textwrap.dedent(f"""
        import os, signal, sys
        import evinr_lite.io.export as export
        write = export.save_frames_png
        def write_then_interrupt(*a, **k):
            write(*a, **k)
            for _ in range(3):
                os.kill(os.getpid(), signal.SIGINT)
        export.save_frames_png = write_then_interrupt
        from evinr_lite.apps.cli import main
        sys.argv = ["evinr-lite", "reconstruct", {str(recording)!r}, "--out", {str(tmp_path / 'out')!r}, "--quiet"]
        sys.exit(main())
    """)
    r = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=ENV, timeout=300)
    assert r.returncode == 130 and "Traceback" not in r.stderr and "Exception ignored" not in r.stderr, r.stderr
    assert r.stderr.count("interrupted by SIGINT") == 1
    left = sorted(p.name for p in tmp_path.iterdir())
    # no partial folder, no lock (a --resume state, .out.resume, is kept on purpose: it is not a result)
    assert not [n for n in left if ".partial-" in n or n.endswith(".lock") or n == "out"], left


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_an_interrupt_that_a_library_swallowed_never_exits_0(capsys, signum):
    def body():
        try:
            os.kill(os.getpid(), signum)
            time.sleep(0.5)                  # the handler raises here
        except KeyboardInterrupt:            # ... and a careless library swallows it
            pass
        return 0

    assert run_guarded("prog", body, []) == 128 + signum
    assert f"interrupted by {signal.Signals(signum).name}" in capsys.readouterr().err


@pytest.mark.parametrize("chained", ["from", "during"])
def test_a_signal_that_a_library_turned_into_its_own_error_is_an_interruption(capsys, chained):
    """numpy's import catches any exception raised inside it and raises an ImportError ("IMPORTANT: PLEASE READ
    THIS ...") from it: a SIGHUP at start-up, while numpy loads, was reported as an internal error (status 1, one
    CI run of 2026-12-07); the signal behind it is what ended the command."""
    def body():
        try:
            raise Interrupted(signal.SIGHUP)
        except Interrupted as exc:
            if chained == "from":
                raise ImportError("numpy: IMPORTANT: PLEASE READ THIS") from exc
            raise ImportError("numpy: IMPORTANT: PLEASE READ THIS")   # only __context__

    assert run_guarded("prog", body, []) == 128 + signal.SIGHUP
    err = capsys.readouterr().err
    assert "interrupted by SIGHUP" in err and "internal error" not in err


def test_an_error_without_a_signal_behind_it_is_still_internal(capsys):
    def body():
        try:
            raise ValueError("a bug's own cause")
        except ValueError:
            raise ImportError("not an interruption")

    assert run_guarded("prog", body, []) == 1
    assert "internal error: ImportError" in capsys.readouterr().err


def test_a_second_signal_during_cleanup_is_noted_not_raised():
    cleaned = []
    with pytest.raises(Interrupted):
        with termination_signals():
            try:
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.5)
            finally:
                os.kill(os.getpid(), signal.SIGTERM)     # arrives during the cleanup
                time.sleep(0.05)
                cleaned.append(True)
    assert cleaned == [True]


# ---- pipes -----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("reader", ["head -1", "true", "closed before start"])
@pytest.mark.parametrize("command", ["info", "reconstruct"])
def test_a_reader_that_closes_stdout_does_not_change_the_result(recording, tmp_path, reader, command):
    out_dir = tmp_path / "out"
    argv = COMMANDS["evinr-lite"] + (["info", str(recording)] if command == "info" else
                                     ["reconstruct", str(recording), "--out", str(out_dir), "--no-video"])
    read_fd, write_fd = os.pipe()
    proc = subprocess.Popen(argv, stdout=write_fd, stderr=subprocess.PIPE, text=True, env=ENV)
    os.close(write_fd)
    with os.fdopen(read_fd) as pipe:
        if reader == "head -1":
            pipe.readline()
        # "true" and "closed before start": read nothing; the with-block closes the pipe now
    _, err = proc.communicate(timeout=300)
    assert proc.returncode == 0, err
    assert "Traceback" not in err and "BrokenPipe" not in err and "Exception ignored" not in err, err
    if command == "reconstruct":
        assert (out_dir / "run.json").exists()                    # the whole result, as without the pipe


# ---- the current folder, info without torch ---------------------------------------------------------------

@pytest.mark.parametrize("argv", [["info", "REC"], ["reconstruct", "REC", "--out", "ABS/out"], ["demo", "--out", "x"]])
def test_a_deleted_current_folder_is_a_clear_error(recording, tmp_path, argv):
    gone = tmp_path / "gone"
    gone.mkdir()
    argv = [a.replace("REC", str(recording)).replace("ABS", str(tmp_path)) for a in argv]
    script = f"cd {gone} && rmdir {gone} && exec {sys.executable} -m evinr_lite " + " ".join(argv)
    r = subprocess.run(["bash", "-c", script], capture_output=True, text=True, env=ENV, timeout=120)
    assert r.returncode == 2 and "current folder was deleted" in r.stderr, r.stderr
    assert "Traceback" not in r.stderr and "oneMKL" not in r.stderr


@pytest.mark.parametrize("argv", [["info", "REC"], ["info", "REC", "--json"], ["--help"], ["info", "--help"]])
def test_info_and_help_import_no_torch(recording, argv):
    argv = [a.replace("REC", str(recording)) for a in argv]
    script = (f"import sys\nfrom evinr_lite.apps.cli import main\ncode = main({argv!r})\n"
              "assert 'torch' not in sys.modules, 'torch was imported'\nsys.exit(code)")
    r = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=ENV, timeout=120)
    assert r.returncode == 0, r.stderr


# ---- a full disk while locking leaves no empty lock ---------------------------------------------------------

def test_enospc_while_writing_the_lock_leaves_no_lock(tmp_path, monkeypatch):
    from evinr_lite.io import output
    from evinr_lite.io.output import OutputDir, OutputError

    real_write = os.write

    def full(fd, data):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(output.os, "write", full)
    with pytest.raises(OutputError, match="No space left"):
        OutputDir(tmp_path / "a" / "out").open()
    monkeypatch.setattr(output.os, "write", real_write)
    assert sorted(p.name for p in tmp_path.iterdir()) == []          # no lock, no parent folder


def test_enospc_while_locking_a_batch_leaves_nothing(tmp_path, monkeypatch, recording):
    import filelock

    from evinr_lite.apps.batch import run_batch
    from evinr_lite.core.events import EventDataError

    def full(self, *a, **k):
        open(self.lock_file, "a").close()                                # the file was made, then the disk filled
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(filelock.FileLock, "acquire", full)
    with pytest.raises(EventDataError, match="No space left"):
        run_batch([recording], tmp_path / "out", sequential=True, progress=False, log=lambda *a: None)
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_an_interrupt_raised_where_python_ignores_exceptions_is_not_lost(capsys):
    """A signal whose Interrupted is raised inside a weakref callback (as when an import releases its
    module lock) is only printed by Python ("Exception ignored in ..."): the guard delivers it again,
    so it still stops the command at its next line, and nothing is printed."""
    import signal
    import time
    import weakref

    from evinr_lite.core.guard import Interrupted, termination_signals

    class Thing:
        pass

    def callback(ref):   # runs when the object goes away; exceptions raised here are unraisable
        signal.raise_signal(signal.SIGINT)
        for _ in range(1000):   # the handler runs here, inside the callback
            pass

    reached = []
    with pytest.raises(Interrupted):
        with termination_signals():
            thing = Thing()
            ref = weakref.ref(thing, callback)
            del thing
            deadline = time.monotonic() + 10
            while time.monotonic() < deadline:   # the command's next lines: the interrupt must arrive here
                reached.append(1)
    assert ref() is None and time.monotonic() < deadline
    err = capsys.readouterr().err
    assert "Exception ignored" not in err and "Traceback" not in err, err


def _signal_once_installed(monkeypatch, sig):
    """signal.signal that sends ``sig`` to this process as soon as the guard's last handler is in place
    (the moment the start-up test hits at random: the guard's loop has not finished yet)."""
    from evinr_lite.core.guard import TERMINATION_SIGNALS

    real, sent = signal.signal, []

    def install(signum, handler):
        previous = real(signum, handler)
        if signum == TERMINATION_SIGNALS[-1] and getattr(handler, "__name__", "") == "handler" and not sent:
            sent.append(signum)
            os.kill(os.getpid(), sig)
            for _ in range(1000):   # the handler runs here, before the guard's loop goes on
                pass
        return previous

    monkeypatch.setattr(signal, "signal", install)
    return sent


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_a_signal_as_the_guard_installs_its_handlers_is_caught(monkeypatch, capsys, sig):
    """CI once saw `reconstruct` end with a traceback (status 1) when SIGINT came right after the guard's
    handlers were seen in /proc: the handlers were installed before the guard's `try`. The signal now
    arrives at exactly that moment: the guard reports it (128 + n) and leaves the handlers as they were."""
    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    ran = []
    sent = _signal_once_installed(monkeypatch, sig)
    assert run_guarded("prog", lambda: ran.append(1), []) == 128 + sig
    assert sent and ran == []
    assert f"interrupted by {signal.Signals(sig).name}" in capsys.readouterr().err
    monkeypatch.undo()
    assert {s: signal.getsignal(s) for s in before} == before


def test_a_signal_as_termination_signals_installs_its_handlers_restores_them(monkeypatch):
    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    ran = []
    _signal_once_installed(monkeypatch, signal.SIGTERM)
    with pytest.raises(Interrupted):
        with termination_signals():
            ran.append(1)
    monkeypatch.undo()
    assert ran == [] and {s: signal.getsignal(s) for s in before} == before
