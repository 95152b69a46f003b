"""Issue 25, the rest of section 3: `data_fetch info` on a file without (or with a wrongly typed)
optional attribute describes what is there (a "?" for the missing), never an internal error; the
shared guard sorts each exception class into one exit status, for both commands."""
import shutil

import h5py
import numpy as np
import pytest

import data_fetch.__main__ as df_main
from evinr_lite.apps.cli import main as evinr_main
from evinr_lite.io.canonical import CanonicalWriter


@pytest.fixture(scope="module")
def canonical(tmp_path_factory):
    path = tmp_path_factory.mktemp("c") / "c.h5"
    with CanonicalWriter(path, sensor_size=(10, 12), dataset="ijrr", sequence="s", C=0.2) as w:
        w.add_events(np.linspace(0, 1, 200), np.zeros(200, int), np.zeros(200, int), np.ones(200, int))
    return path


def _run_df(capsys, *argv):
    code = df_main.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("attr", ["C", "t_zero", "t_origin", "n_events", "n_frames", "t_first", "t_last",
                                  "eval_window", "eval_window_published", "dataset", "sequence", "source",
                                  "meta_json"])
def test_data_fetch_info_without_an_attribute_is_no_internal_error(capsys, canonical, tmp_path, attr):
    path = tmp_path / "x.h5"
    shutil.copy(canonical, path)
    with h5py.File(path, "a") as f:
        del f.attrs[attr]
    code, out, err = _run_df(capsys, "info", path)
    assert code in (0, 2) and "internal error" not in err and "Traceback" not in err, err
    if code == 0:
        assert str(path) in out
    else:
        assert err.startswith("data_fetch: error:") and attr in err


@pytest.mark.parametrize("attr,value", [("C", "abc"), ("t_zero", "zz"), ("eval_window", "x"), ("n_events", "many"),
                                        ("sensor_size", "big"), ("meta_json", "{not json")])
def test_data_fetch_info_with_a_wrongly_typed_attribute_is_a_clear_error(capsys, canonical, tmp_path, attr, value):
    path = tmp_path / "x.h5"
    shutil.copy(canonical, path)
    with h5py.File(path, "a") as f:
        f.attrs[attr] = value
    code, out, err = _run_df(capsys, "info", path)
    assert code in (0, 2) and "internal error" not in err and "Traceback" not in err, err


@pytest.mark.parametrize("exc,code", [(lambda: OSError(28, "No space left on device", "/x"), 2),
                                      (lambda: ValueError("a bug"), 1), (lambda: KeyboardInterrupt(), 130)])
def test_both_commands_share_one_guard(capsys, monkeypatch, exc, code):
    import data_fetch
    import evinr_lite.apps.describe as describe

    def boom(*a, **k):
        raise exc()

    monkeypatch.setattr(data_fetch, "info", boom)
    monkeypatch.setattr(describe, "open_recording", boom)
    got_df, _, err_df = _run_df(capsys, "info", "x.h5")
    got_ev = evinr_main(["info", "x.h5"])
    err_ev = capsys.readouterr().err
    assert got_df == got_ev == code
    assert err_df.startswith(("data_fetch: ", "\ndata_fetch: ")) and err_ev.startswith(("evinr-lite: ", "\nevinr-lite: "))
    assert "Traceback" not in err_df + err_ev


@pytest.mark.parametrize("command", ["reconstruct", "demo", "batch"])
@pytest.mark.parametrize("out", ["loop", "loop/x", "loop/x/y"])
def test_an_out_through_a_symlink_loop_is_a_clear_error_for_every_command(capsys, tmp_path, monkeypatch, command, out):
    from evinr_lite.sim.recordings import write_example_recording

    rec = write_example_recording(tmp_path / "rec", sensor_size=(12, 16), duration=0.2, frame_rate=10.0)
    (tmp_path / "loop").symlink_to("loop")
    monkeypatch.chdir(tmp_path)
    argv = {"reconstruct": ["reconstruct", str(rec), "--out", out, "--quiet"], "demo": ["demo", "--out", out],
            "batch": ["batch", str(rec), "--out", out, "--quiet"]}[command]
    code = evinr_main(argv)
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("evinr-lite: error:") and "Traceback" not in err, err
