"""Batch ownership and input identity (issue 25, sections 1 and 2): batch writes only into folders it
created and can prove its own, refuses an --out among its inputs, keys resumed results by the input's
identity and settings, pools one recording reached by two names once, and leaves nothing behind when
it did nothing. Several instances of each class go through the same mechanism."""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from evinr_lite.apps.batch import OWNER_MARKER, check_scheduler_address, resolve_inputs, run_batch
from evinr_lite.core.events import EventDataError
from evinr_lite.sim.recordings import write_example_recording

ITERS = 20


def _quiet(*args, **kwargs):
    pass


def snapshot(folder: Path) -> dict:
    return {str(p.relative_to(folder)): (None if p.is_dir() else p.read_bytes()) for p in sorted(folder.rglob("*"))}


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    """data/ with two small recordings and a user folder (calib/) that is not a recording."""
    root = tmp_path_factory.mktemp("own") / "data"
    root.mkdir()
    for i, scene in enumerate(("camera", "coffee")):
        write_example_recording(root / f"rec_{scene}", scene=scene, sensor_size=(24, 32), duration=0.3,
                                frame_rate=10.0, seed=i)
    (root / "calib").mkdir()
    (root / "calib" / "notes.txt").write_text("my calibration")
    return root


def batch(inputs, out, **kw):
    return run_batch(inputs, out, sequential=True, n_iters=ITERS, progress=False, log=_quiet, **kw)


# ---- 1. --out among the inputs, or holding what batch did not write: refused, nothing touched -----------

@pytest.mark.parametrize("where", ["the input folder", "inside the input folder", "inside a recording folder",
                                   "the parent of an input"])
def test_an_out_among_the_inputs_is_refused_and_nothing_changes(data, tmp_path, where):
    before = snapshot(data)
    out = {"the input folder": data, "inside the input folder": data / "results",
           "inside a recording folder": data / "rec_camera" / "out", "the parent of an input": data}[where]
    inputs = [data / "rec_camera"] if where == "the parent of an input" else [data]
    with pytest.raises(EventDataError, match="input"):
        batch(inputs, out)
    assert snapshot(data) == before


@pytest.mark.parametrize("content", ["summary.md", "calib/notes.txt", "rec_camera/mine.txt", ".hidden"])
def test_a_user_folder_or_file_in_out_is_never_replaced(data, tmp_path, content):
    out = tmp_path / "out"
    (out / content).parent.mkdir(parents=True, exist_ok=True)
    (out / content).write_text("the user's own")
    before = snapshot(out)
    with pytest.raises(EventDataError, match="did not write|not written by this batch"):
        batch([data], out)
    assert snapshot(out) == before


def test_a_user_folder_named_like_a_recording_in_an_owned_out_is_refused(data, tmp_path):
    out = tmp_path / "out"
    batch([data / "rec_camera"], out)
    (out / "rec_coffee").mkdir()                               # the user's, inside a folder batch owns
    (out / "rec_coffee" / "mine.txt").write_text("keep me")
    before = snapshot(out)
    with pytest.raises(EventDataError, match="rec_coffee.*not written by this batch"):
        batch([data], out)
    assert snapshot(out) == before


@pytest.mark.parametrize("damage", [b"{not json", b"[1, 2]", b'{"recordings": 3}', b"\xff\xfe"])
def test_a_damaged_batch_json_is_a_clear_error_and_nothing_is_touched(data, tmp_path, damage):
    out = tmp_path / "out"
    batch([data / "rec_camera"], out)
    (out / "batch.json").write_bytes(damage)
    before = snapshot(out)
    with pytest.raises(EventDataError, match="batch.json is damaged"):
        batch([data / "rec_camera"], out)
    assert snapshot(out) == before


# ---- 2. identity: a resume is keyed by the input, not its name ------------------------------------------

def test_a_different_input_under_the_same_name_is_reconstructed_again(data, tmp_path):
    a, b = tmp_path / "a" / "rec", tmp_path / "b" / "rec"
    shutil.copytree(data / "rec_camera", a)
    shutil.copytree(data / "rec_coffee", b)
    out = tmp_path / "out"
    first = batch([a], out)
    second = batch([b], out)                                   # same name "rec", another recording
    (r1,), (r2,) = first["recordings"], second["recordings"]
    assert r1["status"] == "done" and r2["status"] == "done", r2
    assert r2["scores"] != r1["scores"]
    assert json.loads((out / "rec" / "run.json").read_text())["input"] == str(b.resolve())
    again = batch([b], out)                                    # the same input: resumed
    assert again["recordings"][0]["status"] == "skipped" and again["recordings"][0]["scores"] == r2["scores"]
    marker = json.loads((out / "rec" / OWNER_MARKER).read_text())
    assert marker["input"]["path"] == str(b.resolve())


def test_a_changed_file_is_reconstructed_again(data, tmp_path):
    src = tmp_path / "rec"
    shutil.copytree(data / "rec_camera", src)
    out = tmp_path / "out"
    batch([src], out)
    lines = (src / "events.txt").read_text().splitlines()
    (src / "events.txt").write_text("\n".join(lines[: len(lines) // 2]) + "\n")   # the same name, other content
    again = batch([src], out)
    assert again["recordings"][0]["status"] == "done"


def test_one_recording_reached_by_several_names_is_pooled_once(data, tmp_path, monkeypatch):
    cache = tmp_path / "cache"
    (cache / "ijrr").mkdir(parents=True)
    (cache / "ijrr" / "seq.h5").write_bytes(b"")
    os.symlink(cache / "ijrr" / "seq.h5", tmp_path / "link.h5")
    monkeypatch.chdir(tmp_path)
    names = [cache / "ijrr" / "seq.h5", "ijrr:seq", "ijrr", tmp_path / "link.h5", Path("cache/ijrr/seq.h5")]
    items = resolve_inputs(names, cache=Path("cache"), log=_quiet)             # a relative cache folder too
    assert len(items) == 1 and items[0]["path"] == str((cache / "ijrr" / "seq.h5").resolve())


def test_labels_do_not_depend_on_the_order_of_the_inputs(tmp_path):
    for parent in ("a/x", "b/x", "c/x"):
        (tmp_path / parent).mkdir(parents=True)
        (tmp_path / parent / "rec.npy").write_bytes(b"")
    paths = [tmp_path / p / "rec.npy" for p in ("a/x", "b/x", "c/x")]
    forward = {i["path"]: i["name"] for i in resolve_inputs(paths, log=_quiet)}
    backward = {i["path"]: i["name"] for i in resolve_inputs(paths[::-1], log=_quiet)}
    middle = {i["path"]: i["name"] for i in resolve_inputs([paths[1], paths[2], paths[0]], log=_quiet)}
    assert forward == backward == middle and len(set(forward.values())) == 3


# ---- 4. leftovers: a batch leaves only its results ------------------------------------------------------

def test_no_lock_file_stays_and_a_batch_that_could_not_start_leaves_nothing(data, tmp_path, monkeypatch):
    import evinr_lite.apps.batch as batch_module

    monkeypatch.setattr(batch_module, "SCHEDULER_TIMEOUT", "2s")   # nothing listens: no need to wait 20 s
    out = tmp_path / "out"
    batch([data / "rec_camera"], out)
    assert not (out / ".batch.lock").exists()
    assert {p.name for p in out.iterdir()} == {"rec_camera", "batch.json", "summary.json", "summary.csv", "summary.md"}
    for address in ("tcp://127.0.0.1:1", "localhost:1"):            # nothing listens there
        fresh = tmp_path / f"fresh{address[-1]}{len(address)}"
        with pytest.raises(EventDataError, match="cannot reach the Dask scheduler"):
            run_batch([data / "rec_camera"], fresh, scheduler=address, n_iters=ITERS, progress=False, log=_quiet)
        assert not fresh.exists()                                    # so a plain rerun is not blocked
    shutil.rmtree(out / "rec_camera")
    with pytest.raises(EventDataError, match="cannot reach"):
        run_batch([data / "rec_camera"], out, scheduler="tcp://127.0.0.1:1", n_iters=ITERS, progress=False, log=_quiet)
    assert (out / "batch.json").exists() and not (out / ".batch.lock").exists()   # an existing batch.json stays


@pytest.mark.parametrize("address", ["not a url", "http//x", "tcp://", "tcp://host:port", "", "a b:1"])
def test_a_scheduler_address_that_is_not_one_is_refused_before_any_work(address, tmp_path, data):
    with pytest.raises(EventDataError, match="not a Dask scheduler address"):
        check_scheduler_address(address)
    with pytest.raises(EventDataError, match="not a Dask scheduler address"):
        run_batch([data / "rec_camera"], tmp_path / "out", scheduler=address, progress=False, log=_quiet)
    assert not (tmp_path / "out").exists()


def test_a_foreign_partial_folder_is_left_and_a_marked_one_removed(data, tmp_path):
    from evinr_lite.io.output import mark_partial

    out = tmp_path / "out"
    batch([data / "rec_camera"], out)
    mine, theirs = out / ".rec_camera.partial-1-00", out / ".rec_camera.partial-2-user"
    mine.mkdir()
    mark_partial(mine)
    theirs.mkdir()
    (theirs / "thesis.tex").write_text("not evinr's")
    batch([data / "rec_camera"], out)
    assert not mine.exists() and (theirs / "thesis.tex").read_text() == "not evinr's"


@pytest.mark.parametrize("out", ["loop/x", "loop"])
def test_an_out_through_a_symlink_loop_is_a_clear_error(tmp_path, data, capsys, out):
    from evinr_lite.apps.cli import main

    os.symlink(tmp_path / "loop", tmp_path / "loop")
    code = main(["batch", str(data / "rec_camera"), "--out", str(tmp_path / out), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and "internal error" not in err and "Traceback" not in err, err


def test_the_command_refuses_out_equal_to_the_input_folder(data):
    before = snapshot(data)
    r = subprocess.run([sys.executable, "-m", "evinr_lite", "batch", str(data), "--out", str(data), "--workers", "1"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "Traceback" not in r.stderr and "input folder" in r.stderr, r.stderr
    assert snapshot(data) == before
