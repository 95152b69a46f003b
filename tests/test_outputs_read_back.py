"""Every file a run writes, read back with an independent reader and compared with what the kit computed.

PNGs and GIFs with Pillow, MP4s with OpenCV's reader, HDF5 with h5py, JSON and CSV with the standard
library; the reference is the in-memory result (``Reconstruction.frames``, ``times``), the scorer called
directly, or the recording's own files. A non-square sensor (30 x 50, odd 31 x 51) catches H and W swapped.
"""
from __future__ import annotations

import csv
import json
from pathlib import Path

import h5py
import numpy as np
import pytest
from PIL import Image

import evinr_lite as ev
from evinr_lite.apps.recon_job import (choose_times, export_reconstruction, load_recording, reconstruct_recording,
                                       run_reconstruct, score_recording)
from evinr_lite.core.frames import to_uint8
from evinr_lite.evaluation.scoring import score_sequence
from evinr_lite.io.export import read_log_intensity, save_frames_png, save_gif, save_mp4
from evinr_lite.io.output import save_png
from evinr_lite.method.tonemap import to_display
from evinr_lite.sim.recordings import write_example_recording

ITERS = 30
QUIET = dict(progress=False, log=lambda message: None)


def _pngs(folder) -> tuple[np.ndarray, list[str]]:
    paths = sorted(Path(folder).glob("*.png"))
    return np.stack([np.asarray(Image.open(p)) for p in paths]), [p.name for p in paths]


def _timestamps(path) -> tuple[str, np.ndarray]:
    lines = Path(path).read_text().splitlines()
    return lines[0], np.array([float(line.split()[1]) for line in lines[1:]])


def _mp4(path):
    import cv2

    cap = cv2.VideoCapture(str(path))
    info = {"fps": cap.get(cv2.CAP_PROP_FPS), "w": int(cap.get(cv2.CAP_PROP_FRAME_WIDTH)),
            "h": int(cap.get(cv2.CAP_PROP_FRAME_HEIGHT))}
    frames = []
    while True:
        ok, frame = cap.read()
        if not ok:
            break
        frames.append(frame)
    cap.release()
    return np.stack(frames), info


def _gif(path) -> tuple[np.ndarray, list[int]]:
    gif = Image.open(path)
    frames, delays = [], []
    for i in range(gif.n_frames):
        gif.seek(i)
        delays.append(gif.info["duration"])
        frames.append(np.asarray(gif.convert("RGB")))
    return np.stack(frames), delays


def _absolute_clock(folder: Path, offset: float) -> None:
    """Move an IJRR folder's clock (events.txt, images.txt) by ``offset`` seconds, as a camera's absolute clock."""
    rows = np.loadtxt(folder / "events.txt")
    with open(folder / "events.txt", "w") as f:
        for t, x, y, p in rows:
            f.write(f"{t + offset:.9f} {int(x)} {int(y)} {int(p)}\n")
    lines = [line.split() for line in (folder / "images.txt").read_text().splitlines() if line.strip()]
    (folder / "images.txt").write_text("".join(f"{float(t) + offset:.9f} {name}\n" for t, name in lines))


@pytest.fixture(scope="module")
def recording(tmp_path_factory) -> Path:
    """A 30 x 50 IJRR-style recording (non-square: H and W cannot be swapped unseen), frames at 20 per second."""
    return write_example_recording(tmp_path_factory.mktemp("rb") / "rec", sensor_size=(30, 50), duration=0.5,
                                   frame_rate=20)


@pytest.fixture(scope="module")
def in_memory(recording, tmp_path_factory):
    """The in-memory job's steps (the Python path), exported with --save-log: (recording, result, scores, folder)."""
    from evinr_lite.apps.options import RunOptions

    rec = load_recording(recording)
    times, _ = choose_times(rec)
    result = reconstruct_recording(rec, times, RunOptions(n_iters=ITERS).config(1.0))
    scores = score_recording(result, rec.frames)
    out = tmp_path_factory.mktemp("rb") / "memory"
    export_reconstruction(out, rec, result, scores, save_log=True, log=QUIET["log"])
    return rec, result, scores, out


@pytest.fixture(scope="module")
def streamed(recording, tmp_path_factory) -> Path:
    """``evinr-lite reconstruct`` on the same recording (events only: the streamed job), with --save-log."""
    out = tmp_path_factory.mktemp("rb") / "streamed"
    run_reconstruct(recording, out, n_iters=ITERS, save_log=True, **QUIET)
    return out


# ---- frames/*.png, timestamps.txt ---------------------------------------------------------------

def test_png_frames_are_the_result_in_order_at_h_by_w(in_memory):
    rec, result, _, out = in_memory
    images, names = _pngs(out / "frames")
    assert names == [f"frame_{i:05d}.png" for i in range(len(result.times))]
    assert images.shape == (len(result.times), 30, 50) and images.dtype == np.uint8   # [F, H, W], not W x H
    assert Image.open(out / "frames" / names[0]).mode == "L"                              # 8-bit grey
    np.testing.assert_array_equal(images, to_uint8(result.frames))                        # round(255 x), once
    _, t = _timestamps(out / "timestamps.txt")
    np.testing.assert_allclose(t, result.times, atol=1e-9)                                 # file k <-> time k


def test_streamed_and_in_memory_runs_write_the_same_files(in_memory, streamed):
    _, _, _, memory = in_memory
    assert sorted(p.name for p in memory.iterdir()) == sorted(p.name for p in streamed.iterdir())
    np.testing.assert_array_equal(_pngs(memory / "frames")[0], _pngs(streamed / "frames")[0])
    assert (memory / "timestamps.txt").read_text() == (streamed / "timestamps.txt").read_text()
    for name in ("frames", "gt"):
        assert _pngs(memory / name)[1] == _pngs(streamed / name)[1]


def test_save_png_writes_the_levels_save_frames_png_writes(tmp_path):
    """One mapping to uint8 (round(255 x), to_uint8): save_png rounded x * 255 + 0.5 in the image's own dtype,
    which gave another level at the halves (128 of 512 here) and for some float32 values."""
    halves = (np.arange(512) / 2 / 255).reshape(16, 32)
    rng = np.random.default_rng(0).random((200, 500)).astype(np.float32)
    for image in (halves, halves.astype(np.float32), rng):
        save_png(tmp_path / "one.png", image)
        save_frames_png(tmp_path / "stack", image[None], overwrite=True)
        one = np.asarray(Image.open(tmp_path / "one.png"))
        np.testing.assert_array_equal(one, to_uint8(image))
        np.testing.assert_array_equal(one, np.asarray(Image.open(tmp_path / "stack" / "frame_00000.png")))


def test_timestamps_on_an_absolute_clock_add_up_to_the_recordings_times(tmp_path):
    """IJRR-like times near 1.5e9 s: timestamps.txt and gt/timestamps.txt are relative to the t_origin their
    header names (and run.json records); relative + t_origin is the recording's own clock to a microsecond."""
    offset = 1_500_000_000.123456
    folder = write_example_recording(tmp_path / "abs", sensor_size=(30, 50), duration=0.5, frame_rate=20)
    _absolute_clock(folder, offset)
    out = tmp_path / "out"
    run = run_reconstruct(folder, out, n_iters=ITERS, **QUIET)
    header, t = _timestamps(out / "timestamps.txt")
    origin = float(header.split("t_origin = ")[1].split()[0])
    assert origin == run["t_origin"] == json.loads((out / "run.json").read_text())["t_origin"] == 1_500_000_000.0
    clock = np.array([float(line.split()[0]) for line in (folder / "images.txt").read_text().splitlines()])
    for name in ("timestamps.txt", "gt/timestamps.txt"):
        _, t = _timestamps(out / name)
        assert all(len(line.split()[1].split(".")[1]) == 9 for line in (out / name).read_text().splitlines()[1:])
        nearest = np.abs((t + origin)[:, None] - clock[None, :]).min(axis=1)
        assert nearest.max() < 1e-6


# ---- videos ------------------------------------------------------------------------------------

def test_gif_lasts_the_frames_count_over_fps(tmp_path):
    """A GIF's delays are whole hundredths of a second: at 30 per second one rounded delay (30 ms) played
    30 frames in 0.9 s; each frame's start is rounded instead, so they last 1.0 s."""
    frames = np.random.default_rng(1).random((30, 31, 51))
    for fps, seconds in ((30.0, 1.0), (25.8, 30 / 25.8), (20.0, 1.5), (60.0, 0.6)):   # above 50: 20 ms each
        save_gif(tmp_path / "v.gif", frames, fps)
        images, delays = _gif(tmp_path / "v.gif")
        assert len(images) == 30 and images.shape[1:3] == (31, 51)
        assert abs(sum(delays) / 1000 - seconds) <= 0.01 and min(delays) >= 20
        np.testing.assert_array_equal(images[..., 0], to_uint8(frames))   # grey: lossless in a GIF


def test_run_videos_match_the_png_frames(streamed):
    run = json.loads((streamed / "run.json").read_text())
    images, _ = _pngs(streamed / "frames")
    gif, delays = _gif(streamed / "reconstruction.gif")
    np.testing.assert_array_equal(gif[..., 0], images)
    assert abs(sum(delays) / 1000 - len(images) / run["video_fps"]) <= 0.01
    mp4, info = _mp4(streamed / "reconstruction.mp4")
    assert len(mp4) == len(images) and (info["h"], info["w"]) == (30, 50)
    assert info["fps"] == pytest.approx(run["video_fps"], rel=1e-3) == pytest.approx(20.0, rel=1e-3)
    assert np.abs(mp4[[0, -1], :, :, 0].astype(int) - images[[0, -1]]).mean() < 6   # codec loss only


def test_mp4_of_an_odd_size_is_padded_by_one_black_row_and_column(tmp_path):
    frames = np.random.default_rng(2).random((5, 31, 51)) * 0.5 + 0.25
    save_mp4(tmp_path / "v.mp4", frames, 10)
    mp4, info = _mp4(tmp_path / "v.mp4")
    assert (info["h"], info["w"]) == (32, 52) and len(mp4) == 5 and info["fps"] == pytest.approx(10)
    assert np.abs(mp4[:, :31, :51, 0].astype(int) - to_uint8(frames)).mean() < 12


# ---- scores --------------------------------------------------------------------------------------

def test_metrics_are_the_scorer_on_the_result_at_the_gt_times(in_memory):
    rec, result, _, out = in_memory
    metrics = json.loads((out / "metrics.json").read_text())
    gt_images, gt_names = _pngs(out / "gt")
    _, gt_t = _timestamps(out / "gt" / "timestamps.txt")
    np.testing.assert_array_equal(gt_images, rec.frames.images)
    rows = list(csv.DictReader(open(out / "metrics.csv")))
    assert list(rows[0]) == ["gt_index", "t_s", "mse_none", "ssim_none", "mse_clahe", "ssim_clahe"]
    for eq in ("none", "clahe"):
        direct = score_sequence(result.frames_at(gt_t), gt_t, gt_images, gt_t, equalization=eq, lpips_model=False)
        assert metrics["protocols"][eq]["mse"] == pytest.approx(direct["mse"], rel=1e-9)
        assert metrics["protocols"][eq]["ssim"] == pytest.approx(direct["ssim"], rel=1e-9)
        assert metrics["protocols"][eq]["n_frames"] == direct["n_frames"] == len(rows)
        per = metrics["per_frame"][eq]
        assert per["per_frame_index"] == [int(r["gt_index"]) for r in rows] == direct["per_frame"]["gt_index"].tolist()
        np.testing.assert_allclose(per["per_frame_t_s"], gt_t[per["per_frame_index"]], atol=1e-9)
        np.testing.assert_allclose([float(r["t_s"]) for r in rows], gt_t[per["per_frame_index"]], atol=1e-9)
        np.testing.assert_allclose([float(r[f"mse_{eq}"]) for r in rows], direct["per_frame"]["mse"], atol=1e-6)
        np.testing.assert_allclose([float(r[f"ssim_{eq}"]) for r in rows], direct["per_frame"]["ssim"], atol=1e-6)
    # the frames written are the ones scored (the default times are the GT times), before their 8-bit rounding:
    # the PNGs scored again give the same scores to about 1e-5 in MSE and 1e-3 in SSIM (docs/commands.md; measured
    # 3-8e-6 and 2-6e-4), CLAHE's (on 8-bit images) the same
    png, _ = _pngs(out / "frames")
    _, t = _timestamps(out / "timestamps.txt")
    for eq, mse_tol, ssim_tol in (("none", 2e-5, 1e-3), ("clahe", 1e-9, 1e-9)):
        again = score_sequence(png / 255.0, t, gt_images, gt_t, equalization=eq, lpips_model=False)
        assert again["mse"] == pytest.approx(metrics["protocols"][eq]["mse"], abs=mse_tol)
        assert again["ssim"] == pytest.approx(metrics["protocols"][eq]["ssim"], abs=ssim_tol)


def test_batch_summary_agrees_with_each_recordings_metrics(recording, tmp_path):
    from evinr_lite.apps.batch import run_batch

    run_batch([recording], tmp_path / "b", sequential=True, n_iters=ITERS, log=QUIET["log"])
    summary = json.loads((tmp_path / "b" / "summary.json").read_text())
    metrics = json.loads((tmp_path / "b" / recording.name / "metrics.json").read_text())["protocols"]
    rows = list(csv.DictReader(open(tmp_path / "b" / "summary.csv")))
    for pooled in summary["pooled"]:
        eq = pooled["equalization"]
        assert (pooled["mse"], pooled["ssim"], pooled["n_frames"]) == \
            (metrics[eq]["mse"], metrics[eq]["ssim"], metrics[eq]["n_frames"])
        row = next(r for r in rows if r["equalization"] == eq)
        assert float(row["mse"]) == pytest.approx(metrics[eq]["mse"], rel=1e-12) and int(row["n_frames"]) == \
            metrics[eq]["n_frames"]


# ---- run.json ------------------------------------------------------------------------------------

def test_streamed_run_json_config_is_the_one_used_and_reproduces_the_frames(recording, streamed):
    """evinr_config holds what the events chose (C+ and C-, lam, temporal scale, background filter), as the
    in-memory job's does; the streamed job kept lam="auto" and temporal_scale="auto" there."""
    run = json.loads((streamed / "run.json").read_text())
    cfg = run["evinr_config"]
    assert cfg["lam"] == run["lam_used"] and cfg["temporal_scale"] == run["temporal_scale_used"]
    assert list(cfg["C"]) == run["C_used"] and cfg["background"] == run["background_used"]["background"]
    assert "auto" not in (cfg["lam"], cfg["temporal_scale"], cfg["background"])
    rec = load_recording(recording)
    config = ev.EvINRConfig(**{k: tuple(v) if isinstance(v, list) else v for k, v in cfg.items()})
    lo, hi = run["window_s"]
    again = ev.reconstruct(rec.events, np.array(run["times_s"]), config, t_start=lo, t_end=hi)
    np.testing.assert_array_equal(to_uint8(again.frames), _pngs(streamed / "frames")[0])


# ---- log_intensity.h5 ----------------------------------------------------------------------------

def test_log_intensity_file_holds_the_frames_log_intensity(in_memory, streamed):
    _, result, _, memory = in_memory
    for out in (memory, streamed):
        with h5py.File(out / "log_intensity.h5", "r") as f:
            assert f["log_intensity"].dtype == np.float32 and f["log_intensity"].shape == (len(result.times), 30, 50)
            assert f["t"].dtype == np.float64
            attrs = dict(f.attrs)
        L, t, _ = read_log_intensity(out / "log_intensity.h5")
        _, written = _timestamps(out / "timestamps.txt")
        np.testing.assert_allclose(t, written, atol=1e-9)
        assert attrs["t_origin"] == 0.0 and attrs["display"] == "frames = clip(exp(L), 0, 1)"
        assert attrs["anchor"] == "none" and attrs["tonemap"] == "linear"
        # the kit's own float32 display path (a float64 recomputation can round a pixel the other way)
        np.testing.assert_array_equal(to_uint8(to_display(L, attrs["tonemap"], attrs["gamma"])),
                                      _pngs(out / "frames")[0])
    np.testing.assert_allclose(read_log_intensity(memory / "log_intensity.h5")[0], result.log_intensity, atol=1e-6)


@pytest.mark.parametrize("recipe", ["kit", "paper"])
def test_anchored_log_intensity_names_the_display_that_drew_the_pngs(recording, tmp_path, recipe):
    """Anchored frames are the APS frames' linear intensity, clip(exp(L) - 1/255, 0, 1) (linear_frames), whatever
    the recipe's tone map; the file said clip(exp(L), 0, 1) (a level off) or, for the paper's recipe, Eq. 12. It
    records the anchor mode, since to_display(L, attrs["tonemap"]) is not the frames there."""
    from evinr_lite.method.anchor import ANCHORED_DISPLAY, FRAME_EPS

    out = tmp_path / "a"
    run_reconstruct(recording, out, n_iters=ITERS, anchor="first", recipe=recipe, save_log=True, **QUIET)
    L, _, attrs = read_log_intensity(out / "log_intensity.h5")
    assert attrs["display"] == ANCHORED_DISPLAY == "frames = clip(exp(L) - 1/255, 0, 1)"
    assert 1 / 255 == FRAME_EPS   # the formula's text states the eps the frames use
    assert attrs["tonemap"] == "linear" and attrs["anchor"] == "first"
    # the kit's own float32 path (float64 clip(exp(L) - 1/255) rounded a pixel the other way in 2 of 36 runs)
    np.testing.assert_array_equal(to_uint8(ev.method.linear_frames(L)), _pngs(out / "frames")[0])


# ---- colour --------------------------------------------------------------------------------------

def test_colour_run_writes_rgb_pngs_and_a_bgr_mp4_of_them(tmp_path):
    from evinr_lite.sim import write_colour_davis_recording

    path = write_colour_davis_recording(tmp_path / "colour.h5", sensor_size=(46, 70), duration=0.3)
    out = tmp_path / "c"
    run_reconstruct(path, out, colour=True, n_iters=10, save_log=True, **QUIET)
    images, _ = _pngs(out / "frames")
    assert images.shape[1:] == (23, 35, 3) and Image.open(sorted((out / "frames").glob("*.png"))[0]).mode == "RGB"
    L, _, attrs = read_log_intensity(out / "log_intensity.h5")
    assert L.shape == images.shape
    np.testing.assert_array_equal(to_uint8(to_display(L, attrs["tonemap"], attrs["gamma"])), images)
    mp4, info = _mp4(out / "reconstruction.mp4")   # OpenCV reads B, G, R
    assert (info["h"], info["w"]) == (24, 36)
    as_rgb = np.abs(mp4[:, :23, :35, ::-1].astype(int) - images).mean()
    assert as_rgb < 8 and as_rgb < np.abs(mp4[:, :23, :35].astype(int) - images).mean()


# ---- the canonical file ------------------------------------------------------------------------

def test_canonical_file_written_by_convert_reads_back_with_h5py(recording, tmp_path):
    import shutil

    from data_fetch.__main__ import main as data_fetch_main

    folder = tmp_path / "abs"
    shutil.copytree(recording, folder)
    offset = 1_500_000_000.123456
    _absolute_clock(folder, offset)
    assert data_fetch_main(["convert", str(folder), "--out", str(tmp_path / "c.h5"), "--sensor-size", "30", "50",
                            "--quiet"]) == 0
    raw = np.loadtxt(folder / "events.txt")
    clock = np.array([float(line.split()[0]) for line in (folder / "images.txt").read_text().splitlines()])
    with h5py.File(tmp_path / "c.h5", "r") as f:
        assert list(f.attrs["sensor_size"]) == [30, 50] and f.attrs["t_origin"] == 1_500_000_000.0
        assert {k: f["events"][k].dtype for k in "txyp"} == {"t": np.float64, "x": np.uint16, "y": np.uint16,
                                                              "p": np.int8}
        assert np.abs(f["events/t"][()] + f.attrs["t_origin"] - raw[:, 0]).max() < 1e-6
        np.testing.assert_array_equal(f["events/x"][()], raw[:, 1])
        np.testing.assert_array_equal(f["events/y"][()], raw[:, 2])
        np.testing.assert_array_equal(f["events/p"][()], np.where(raw[:, 3] > 0, 1, -1))
        assert f["frames/images"].shape == (len(clock), 30, 50) and f["frames/images"].dtype == np.uint8
        assert np.abs(f["frames/t"][()] + f.attrs["t_origin"] - clock).max() < 1e-6
