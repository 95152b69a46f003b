"""--display-mean (RunOptions.display_mean): the frames' level, the one thing events never give, set by the
user. Checked before any file is read, refused beside an APS anchor (whose frames give the level), taken by
both jobs and by a batch (whose resume refuses a folder made at another level or tone map)."""
from __future__ import annotations

import json

import numpy as np
import pytest
from PIL import Image

import evinr_lite.apps.recon_job as recon_job
from evinr_lite.apps.cli import build_parser, main
from evinr_lite.apps.options import RunOptions
from evinr_lite.core.events import EventDataError
from evinr_lite.sim.recordings import write_example_recording


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    return write_example_recording(tmp_path_factory.mktemp("level") / "rec", sensor_size=(30, 40), duration=0.6,
                                   C=0.25, frame_rate=20.0, seed=4)


def test_options_check_the_level_and_pass_it_to_every_recipe():
    for recipe, tonemap, own in (("kit", None, 0.4), ("kit", "reinhard", 0.5), ("paper", None, 0.5),
                                 ("v0_1", "linear", 0.4)):
        assert RunOptions(recipe=recipe, tonemap=tonemap).config(0.2).display_mean == pytest.approx(own)
        cfg = RunOptions(recipe=recipe, tonemap=tonemap, display_mean=0.25).config(0.2)
        assert cfg.display_mean == pytest.approx(0.25) and cfg.tonemap == (tonemap or cfg.tonemap)
    for bad in (0, 1, 1.5, -0.2, 0.005, 0.995, 1e-300, float("nan"), "dark", True):
        with pytest.raises(EventDataError, match="display_mean"):
            RunOptions(display_mean=bad)
    with pytest.raises(EventDataError, match="APS frames give it"):
        RunOptions(display_mean=0.3, anchor="first")


def _pngs(out):
    return np.stack([np.asarray(Image.open(p), np.float64) / 255 for p in sorted((out / "frames").glob("frame_*.png"))])


@pytest.mark.parametrize("streamed", [True, False], ids=["streamed", "in_memory"])
def test_both_jobs_show_the_frames_at_the_level_asked_for(recording, tmp_path, monkeypatch, streamed):
    means, lines = {}, {}
    for level in (None, 0.2, 0.6):
        said = []
        with monkeypatch.context() as m:
            if not streamed:
                m.setattr(recon_job, "streamable", lambda options: False)
            recon_job.run_reconstruct(recording, tmp_path / f"o{level}", C=0.25, video=False, progress=False,
                                      display_mean=level, fps=20, log=said.append)
        means[level] = _pngs(tmp_path / f"o{level}").mean()
        lines[level] = [s for s in said if "frames shown" in s]
        run = json.loads((tmp_path / f"o{level}" / "run.json").read_text())
        assert run["evinr_config"]["display_mean"] == pytest.approx(level or 0.4)
    # the level is set over the window's offset grid, the PNGs are the frames asked for: close, not equal
    assert means[None] == pytest.approx(0.4, abs=0.04)
    assert means[0.2] == pytest.approx(0.2, abs=0.03) and means[0.6] == pytest.approx(0.6, abs=0.05)
    assert len(lines[None]) == 1 and "--display-mean" in lines[None][0] and not lines[0.2] and not lines[0.6]


def test_the_command_line_takes_it_and_refuses_what_it_cannot_use(recording, tmp_path, capsys):
    assert main(["reconstruct", str(recording), "--out", str(tmp_path / "a"), "--display-mean", "0.3", "--no-video",
                 "--quiet", "--fps", "10"]) == 0
    assert json.loads((tmp_path / "a" / "run.json").read_text())["evinr_config"]["display_mean"] == pytest.approx(0.3)
    for args, says in ((["--display-mean", "1.5"], "between 0.01 and 0.99"), (["--display-mean", "0.999999"], "between 0.01"), (["--display-mean", "x"], "expected a number"),
                       (["--display-mean", "0.3", "--anchor", "first"], "APS frames give it")):
        capsys.readouterr()
        assert main(["reconstruct", str(recording), "--out", str(tmp_path / "b"), *args]) == 2
        assert says in capsys.readouterr().err
        assert not (tmp_path / "b").exists()


def test_a_batch_keeps_the_level_and_refuses_to_resume_at_another(recording, tmp_path):
    from evinr_lite.apps.batch import run_batch

    out = tmp_path / "batch"
    run_batch([recording], out, sequential=True, display_mean=0.25, C=0.25, log=lambda *a: None)
    settings = json.loads((out / "batch.json").read_text())
    assert settings["display_mean"] == pytest.approx(0.25)
    name = next(p for p in out.iterdir() if p.is_dir())
    assert json.loads((name / "run.json").read_text())["evinr_config"]["display_mean"] == pytest.approx(0.25)
    for other in (dict(display_mean=0.4), dict(display_mean=0.25, tonemap="reinhard")):
        with pytest.raises(EventDataError, match="other settings"):
            run_batch([recording], out, sequential=True, C=0.25, log=lambda *a: None, **other)


def test_the_colour_job_shows_every_channel_at_the_level(tmp_path):
    from evinr_lite.sim.colour_davis import write_colour_davis_recording

    path = write_colour_davis_recording(tmp_path / "coffee.h5", "coffee", sensor_size=(48, 64), duration=0.5, C=0.2,
                                        frame_rate=20.0, seed=0)
    assert main(["reconstruct", str(path), "--out", str(tmp_path / "c"), "--colour", "--display-mean", "0.25",
                 "--no-video", "--quiet"]) == 0
    rgb = _pngs(tmp_path / "c")
    assert rgb.ndim == 4 and np.allclose(rgb.mean(axis=(0, 1, 2)), 0.25, atol=0.02)   # grey world: each channel


def test_the_command_line_and_the_options_take_the_same_range(recording, tmp_path):
    from evinr_lite.apps.options import DISPLAY_MEAN_RANGE

    parser = build_parser()
    lo, hi = DISPLAY_MEAN_RANGE
    for value in (lo, hi):
        args = parser.parse_args(["reconstruct", str(recording), "--out", "o", "--display-mean", str(value)])
        assert RunOptions(display_mean=args.display_mean).display_mean == value
    for value in (lo * 0.99, hi + 0.001):
        with pytest.raises(EventDataError):
            RunOptions(display_mean=value)
        assert main(["reconstruct", str(recording), "--out", str(tmp_path / "x"), "--display-mean", str(value)]) == 2
