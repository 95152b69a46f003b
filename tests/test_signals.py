"""Nothing lost, nothing half-written: signals during training, export and replacement; concurrent
runs into one --out; --out equal to, inside or around the input; output paths that cannot work.

Each case checks the files on disk afterwards: the folder the user had is intact (or replaced by a
complete new result), and nothing else is left (no partial folders, no lock files).
"""
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from evinr_lite.apps.cli import main
from evinr_lite.io import output
from evinr_lite.io.output import OutputDir, OutputError, check_output_path, mark_partial
from evinr_lite.sim.recordings import write_example_recording

FAST = ["--iters", "3", "--quiet", "--no-video"]
SIGNALS = [signal.SIGINT, signal.SIGTERM, signal.SIGHUP]


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    return write_example_recording(tmp_path_factory.mktemp("rec") / "example", sensor_size=(16, 20),
                                   duration=0.2, C=0.25, frame_rate=20.0, seed=0)


def tree(folder: Path) -> dict:
    """Every path under folder (hidden ones too) -> file bytes (None for folders)."""
    return {str(p.relative_to(folder)): (None if p.is_dir() else p.read_bytes())
            for p in sorted(folder.rglob("*"))}


def old_folder(where: Path) -> Path:
    old = where / "out"
    old.mkdir()
    (old / "mine.txt").write_text("the old result")
    return old


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def start(argv, cwd=None):
    """The installed command in a child process, SIGINT restored to its default (CI may start jobs
    with it ignored)."""
    env = {**os.environ, "EVINR_FAST": "1"}
    return subprocess.Popen([sys.executable, "-m", "evinr_lite", *map(str, argv)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env, cwd=cwd,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def wait_for_training(proc, timeout=120):
    deadline = time.time() + timeout
    for line in proc.stdout:
        if line.startswith("reconstructing"):
            return
        if time.time() > deadline:
            break
    raise AssertionError("training did not start: " + proc.stderr.read())


# ---- signals during training (real signals to a child process) ------------------------------------

@pytest.mark.parametrize("sig", SIGNALS, ids=lambda s: signal.Signals(s).name)
def test_signal_during_training_leaves_the_old_folder_and_nothing_else(recording, tmp_path, sig):
    old_folder(tmp_path)
    before = tree(tmp_path)
    proc = start(["reconstruct", recording, "--out", tmp_path / "out", "--overwrite", "--iters", "100000", "--quiet"])
    wait_for_training(proc)
    assert any(p.name.startswith(".out.partial-") for p in tmp_path.iterdir())   # staged before training
    assert (tmp_path / ".out.lock").exists()                                      # and locked
    time.sleep(0.3)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 128 + sig, err
    assert f"interrupted by {signal.Signals(sig).name}" in err and "Traceback" not in err
    assert "the existing" in err and "was left as it was" in err
    assert tree(tmp_path) == before


def test_sigterm_during_training_of_a_new_folder(recording, tmp_path):
    proc = start(["reconstruct", recording, "--out", tmp_path / "a" / "b" / "new", "--iters", "100000", "--quiet"])
    wait_for_training(proc)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143 and "was not written" in err, err
    assert list(tmp_path.iterdir()) == []          # the parents it created are gone too



@pytest.mark.parametrize("sig", SIGNALS, ids=lambda s: signal.Signals(s).name)
def test_signal_as_the_resume_folder_is_made_leaves_nothing(capsys, recording, tmp_path, monkeypatch, sig):
    """The instant after "reconstructing": the streamed run makes its resume folder beside the output;
    a signal then (here: as its marker is put in place) must not leave it, nor the parents made for it."""
    from evinr_lite.apps.stream_job import RESUME_MARKER

    real_replace = Path.replace
    seen = []

    def replace_with_signal(self, target):
        if Path(target).name == RESUME_MARKER:
            seen.append(Path(target).parent.name)
            os.kill(os.getpid(), sig)
        return real_replace(self, target)

    monkeypatch.setattr(Path, "replace", replace_with_signal)
    code, _, err = run(capsys, "reconstruct", recording, "--out", tmp_path / "a" / "b" / "new", *FAST)
    assert seen == [".new.resume"] and code == 128 + sig, err
    assert "was not written" in err and "Traceback" not in err
    assert list(tmp_path.iterdir()) == []          # no resume folder, and the parents it created are gone


# ---- signals during export and during replacement (in-process, the command's own handlers) ----------

@pytest.mark.parametrize("sig", SIGNALS, ids=lambda s: signal.Signals(s).name)
def test_signal_during_export(capsys, recording, tmp_path, monkeypatch, sig):
    import evinr_lite.io.export

    real = evinr_lite.io.export.save_frames_png
    calls = []

    def png_then_signal(*args, **kwargs):
        real(*args, **kwargs)
        calls.append(1)
        os.kill(os.getpid(), sig)
        time.sleep(1)      # the handler raises here

    monkeypatch.setattr(evinr_lite.io.export, "save_frames_png", png_then_signal)
    old_folder(tmp_path)
    before = tree(tmp_path)
    code, _, err = run(capsys, "reconstruct", recording, "--out", tmp_path / "out", "--overwrite", *FAST)
    assert calls and code == 128 + sig, err
    assert "was left as it was" in err and "Traceback" not in err
    assert tree(tmp_path) == before
    assert signal.getsignal(signal.SIGTERM) == signal.SIG_DFL    # handlers restored afterwards


@pytest.mark.parametrize("sig", SIGNALS, ids=lambda s: signal.Signals(s).name)
def test_signal_during_replacement_is_held_until_the_new_result_is_in_place(capsys, recording, tmp_path,
                                                                           monkeypatch, sig):
    real_rename = os.rename
    seen = []

    def rename_with_signal(src, dst):
        os.kill(os.getpid(), sig)          # arrives between the renames: held back until they are done
        seen.append((Path(src).name, Path(dst).name, sorted(p.name for p in tmp_path.iterdir())))
        real_rename(src, dst)

    monkeypatch.setattr(output.os, "rename", rename_with_signal)
    old_folder(tmp_path)
    code, _, err = run(capsys, "reconstruct", recording, "--out", tmp_path / "out", "--overwrite", *FAST)
    assert code == 128 + sig, err
    assert "was complete before that and is in place" in err
    # the old folder went aside first, then the new one came in; the old one was deleted last
    assert seen[0][0] == "out" and seen[0][1].startswith(".out.old-")
    assert seen[1][0].startswith(".out.partial-") and seen[1][1] == "out"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    assert (tmp_path / "out" / "run.json").exists() and not (tmp_path / "out" / "mine.txt").exists()


def test_a_kill_between_the_renames_is_repaired_by_the_next_run(capsys, recording, tmp_path):
    """SIGKILL cannot be handled: simulate its worst instant (old folder aside, new not yet in, a
    partial folder and a lock file left) and check that the next run restores and cleans up."""
    aside = tmp_path / ".out.old-4242-0123456789abcdef"
    aside.mkdir()
    (aside / "mine.txt").write_text("the old result")
    partial = tmp_path / ".out.partial-4242-fedcba9876543210"
    (partial / "frames").mkdir(parents=True)
    mark_partial(partial)                                               # made by evinr-lite: its marker inside
    (tmp_path / ".out.lock").write_text('{"pid": 4242}')
    code, out, err = run(capsys, "reconstruct", recording, "--out", tmp_path / "out", *FAST)
    assert code == 2 and "already exists" in err                     # the old result is back, so refused
    assert "put back" in out and "process 4242" in out                   # and both repairs are named
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    assert (tmp_path / "out" / "mine.txt").read_text() == "the old result"


# ---- two runs into one --out --------------------------------------------------------------------------

def test_a_second_run_into_the_same_out_is_refused_at_once_naming_the_first(recording, tmp_path):
    first = start(["reconstruct", recording, "--out", tmp_path / "out", "--iters", "100000", "--quiet"])
    wait_for_training(first)
    t0 = time.time()
    for extra in ([], ["--overwrite"]):
        second = subprocess.run([sys.executable, "-m", "evinr_lite", "reconstruct", str(recording), "--out",
                                 str(tmp_path / "out"), *FAST, *extra], capture_output=True, text=True,
                                env={**os.environ, "EVINR_FAST": "1"}, timeout=120)
        assert second.returncode == 2, second.stderr
        assert "is being written by another run" in second.stderr and f"process {first.pid}" in second.stderr
        assert "evinr-lite reconstruct" in second.stderr                 # the first run's command
    assert time.time() - t0 < 60                                          # refused before any training
    first.send_signal(signal.SIGTERM)
    first.communicate(timeout=60)
    assert first.returncode == 143
    assert list(tmp_path.iterdir()) == []


def test_output_dir_lock_in_process(tmp_path):
    with OutputDir(tmp_path / "out") as one:
        with pytest.raises(OutputError, match=f"process {os.getpid()}"):
            OutputDir(tmp_path / "out").open()
        (one.staging / "a.txt").write_text("x")
        one.commit()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    with pytest.raises(FileExistsError, match="already exists"):
        OutputDir(tmp_path / "out").open()


# ---- --out against the input, the current folder, and paths that cannot be written -----------------

def test_out_dot_with_overwrite_in_the_input_folder_loses_nothing(capsys, tmp_path, monkeypatch):
    folder = tmp_path / "folder"
    folder.mkdir()
    rng = np.random.default_rng(0)
    t = np.sort(rng.uniform(0, 0.2, 500))
    np.save(folder / "ev.npy", np.stack([t, rng.integers(0, 40, 500), rng.integers(0, 30, 500),
                                         rng.choice([-1, 1], 500)], axis=1))
    (folder / "notes.txt").write_text("mine")
    before = tree(tmp_path)
    monkeypatch.chdir(folder)
    code, _, err = run(capsys, "reconstruct", "ev.npy", "--sensor", "30x40", "--out", ".", "--overwrite", *FAST)
    assert code == 2 and "contains the input recording" in err, err
    code, _, err = run(capsys, "reconstruct", "ev.npy", "--sensor", "30x40", "--out", ".", *FAST)
    assert code == 2 and "contains the input recording" in err, err
    assert tree(tmp_path) == before


def test_out_is_the_current_folder(capsys, recording, tmp_path, monkeypatch):
    work = old_folder(tmp_path)
    monkeypatch.chdir(work)
    before = tree(tmp_path)
    code, _, err = run(capsys, "reconstruct", recording, "--out", ".", "--overwrite", *FAST)
    assert code == 2 and "is the current folder" in err, err
    assert tree(tmp_path) == before


@pytest.mark.parametrize("where", ["same", "inside", "around"])
def test_out_may_not_be_contain_or_lie_inside_the_input(capsys, recording, tmp_path, where):
    import shutil

    rec = tmp_path / "parent" / "rec"
    shutil.copytree(recording, rec)
    before = tree(tmp_path)
    out = {"same": rec, "inside": rec / "result", "around": tmp_path / "parent"}[where]
    code, _, err = run(capsys, "reconstruct", rec, "--out", out, "--overwrite", *FAST)
    assert code == 2, err
    assert ("lies inside the input folder" if where == "inside" else "input recording") in err
    assert tree(tmp_path) == before


def bad_paths(tmp_path):
    (tmp_path / "a_file").write_text("x")
    (tmp_path / "real").mkdir()
    os.symlink(tmp_path / "real", tmp_path / "link")
    return {
        "out is a file": (tmp_path / "a_file", "is a file, not a folder"),
        "parent is a file": (tmp_path / "a_file" / "out", "is a file, not a folder"),
        "out is a symlink": (tmp_path / "link", "symbolic link"),
        "name too long": (tmp_path / ("n" * 250), "bytes long"),
        "root": (Path("/"), "root of the file system"),
    }


@pytest.mark.parametrize("case", ["out is a file", "parent is a file", "out is a symlink", "name too long", "root"])
def test_output_problems_are_found_before_training(capsys, recording, tmp_path, case, monkeypatch):
    import evinr_lite.apps.recon_job as job

    path, pattern = bad_paths(tmp_path)[case]
    before = tree(tmp_path)
    monkeypatch.setattr(job, "load_recording", lambda *a, **k: pytest.fail("read the input before checking --out"))
    code, _, err = run(capsys, "reconstruct", recording, "--out", path, "--overwrite", *FAST)
    assert code == 2 and pattern in err and "Errno" not in err, err
    assert tree(tmp_path) == before


@pytest.mark.skipif(os.geteuid() == 0, reason="root may write in a read-only folder")
def test_read_only_parent(capsys, recording, tmp_path):
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        code, _, err = run(capsys, "reconstruct", recording, "--out", ro / "out", *FAST)
        assert code == 2 and "no permission to write" in err
    finally:
        ro.chmod(0o755)


def test_a_stale_lock_file_does_not_block(capsys, recording, tmp_path):
    (tmp_path / ".out.lock").write_text('{"pid": 999999}')       # left by a killed run
    code, _, err = run(capsys, "reconstruct", recording, "--out", tmp_path / "out", *FAST)
    assert code == 0, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    assert json.loads((tmp_path / "out" / "run.json").read_text())["n_frames_written"] >= 1


def test_check_output_path_accepts_a_new_nested_folder(tmp_path):
    assert check_output_path(tmp_path / "x" / "y") == tmp_path / "x" / "y"
    assert not (tmp_path / "x").exists()                          # checking creates nothing
