"""Colour event cameras end to end (issue 15 item 5, CED in colour): the canonical file's cfa attribute
and colour frames, the bag converter keeping colour, a simulated colour DAVIS, `reconstruct --colour`."""
from __future__ import annotations

import json
from types import SimpleNamespace

import h5py
import numpy as np
import pytest
from PIL import Image

from evinr_lite.apps.cli import main
from evinr_lite.apps.colour_job import reconstruct_colour_recording, score_colour_recording
from evinr_lite.apps.recon_job import load_recording, score_predictions
from evinr_lite.core.events import EventDataError
from evinr_lite.core.frames import to_grey_uint8
from evinr_lite.core.recording import Recording
from evinr_lite.io.canonical import CanonicalWriter, canonical_info, cfa_phase, read_canonical
from evinr_lite.method.colour import chroma_correlation
from evinr_lite.method.solver import EvINRConfig
from evinr_lite.sim.colour_davis import colour_davis_recording, write_colour_davis_recording
from evinr_lite.sim.quadbayer import cfa_pattern
from evinr_lite.sim.recordings import write_example_recording

SCENE = dict(sensor_size=(48, 64), duration=0.5, C=0.2, frame_rate=20.0, seed=0)
CHROMA_MIN = 0.3          # mean of R-G and B-G: a colourless (grey) reconstruction scores 0


@pytest.fixture(scope="module")
def colour_h5(tmp_path_factory):
    return write_colour_davis_recording(tmp_path_factory.mktemp("colour") / "coffee.h5", "coffee", **SCENE)


@pytest.fixture(scope="module")
def cli_run(colour_h5, tmp_path_factory):
    out = tmp_path_factory.mktemp("cli") / "out"
    code = main(["reconstruct", str(colour_h5), "--out", str(out), "--colour", "--no-video", "--quiet"])
    return code, out


# ---- the canonical file -------------------------------------------------------------------

def test_canonical_round_trip_keeps_cfa_and_colour_frames(colour_h5):
    sim = colour_davis_recording("coffee", **SCENE)
    rec = read_canonical(colour_h5)
    assert rec.meta["cfa"] == "RGGB" and canonical_info(colour_h5)["cfa"] == "RGGB"
    np.testing.assert_array_equal(rec.meta["frames_rgb"], sim.meta["frames_rgb"])
    np.testing.assert_array_equal(rec.meta["frames_rgb_t"], rec.frames.t)
    grey = np.stack([to_grey_uint8(im, "t") for im in sim.meta["frames_rgb"]])
    np.testing.assert_array_equal(rec.frames.images, grey)          # grey frames stay the default view
    np.testing.assert_array_equal(rec.events.x, sim.events.x)
    part = read_canonical(colour_h5, t_start=0.12, t_end=0.33)      # a window reads its colour frames only
    assert len(part.frames) == 4 and part.meta["frames_rgb"].shape == (4, 48, 64, 3)
    np.testing.assert_array_equal(part.meta["frames_rgb"], sim.meta["frames_rgb"][3:7])


def test_old_grey_files_read_as_before(tmp_path):
    out = tmp_path / "grey.h5"
    with CanonicalWriter(out, sensor_size=(6, 8)) as w:       # a mono file: the layout before colour
        w.add_events(np.array([0.1, 0.2]), np.array([1, 2]), np.array([0, 3]), np.array([1, -1]))
        w.add_frame(np.full((6, 8), 7, np.uint8), 0.15)
    with h5py.File(out) as f:
        assert "cfa" not in f.attrs and "frames/rgb" not in f
    rec = read_canonical(out)
    assert rec.meta["cfa"] is None and rec.meta["frames_rgb"] is None
    assert rec.frames.images.shape == (1, 6, 8) and rec.frames.images[0, 0, 0] == 7


def test_writer_and_reader_refuse_bad_colour_input(tmp_path):
    with pytest.raises(EventDataError, match="cfa must be one of"):
        CanonicalWriter(tmp_path / "a.h5", sensor_size=(6, 8), cfa="RGBG")
    with pytest.raises(EventDataError, match="of one kind"):
        with CanonicalWriter(tmp_path / "c.h5", sensor_size=(6, 8)) as w:
            w.add_frame(np.zeros((6, 8, 3), np.uint8), 0.0)
            w.add_frame(np.zeros((6, 8), np.uint8), 0.1)
    assert not list(tmp_path.glob("*c.h5*"))                      # nothing half-written
    out = tmp_path / "d.h5"
    with CanonicalWriter(out, sensor_size=(6, 8), cfa="GRBG") as w:
        w.add_events(np.array([0.1, 0.2]), np.array([1, 2]), np.array([0, 3]), np.array([1, -1]))
    with h5py.File(out, "a") as f:
        f.attrs["cfa"] = "XYZW"
    with pytest.raises(EventDataError, match="attribute cfa must be one of.*convert the file again"):
        read_canonical(out)


def test_an_odd_sensor_loses_only_its_last_row_and_column():
    from evinr_lite.apps.colour_job import split_colour_events
    from evinr_lite.core.events import Events

    rng = np.random.default_rng(0)
    n = 500
    ev = Events(np.sort(rng.uniform(0, 1, n)), rng.integers(0, 9, n), rng.integers(0, 7, n),
                rng.choice([-1, 1], n), (7, 9))
    streams = split_colour_events(Recording(ev, None, {"cfa": "RGGB"}))
    assert {s.sensor_size for s in streams} == {(3, 4)}
    assert sum(len(s) for s in streams) == int(np.sum((ev.x < 8) & (ev.y < 6)))
    red = streams[0]                                                 # RGGB: red photosites at even (y, x)
    inside = (ev.x < 8) & (ev.y < 6) & (ev.x % 2 == 0) & (ev.y % 2 == 0)
    np.testing.assert_array_equal(red.t, ev.t[inside])


# ---- data_fetch: the CED converter keeps colour -------------------------------------------

def bag_events(n=400, H=18, W=24, seed=9):
    from test_data_fetch import make_events

    return make_events(n, H=H, W=W, seed=seed)


def test_converter_keeps_colour_from_a_ced_bag(tmp_path):
    import data_fetch
    from test_data_fetch import make_bag, make_frames

    ev = bag_events()
    colour = np.random.default_rng(2).integers(0, 256, (3, 18, 24, 3), dtype=np.uint8)
    fns = make_frames(3)[1]
    bag = make_bag(tmp_path / "simple_carpet.bag", ev, (colour, fns), image_topic="/dvs/image_color", encoding="rgb8")
    path = data_fetch.convert(bag, tmp_path / "colour.h5", dataset="ced", sequence="simple_carpet", progress=False)
    rec = read_canonical(path)
    assert rec.meta["cfa"] == "RGGB"                                 # the registry's filter, with the events
    np.testing.assert_array_equal(rec.meta["frames_rgb"], colour)
    np.testing.assert_array_equal(rec.frames.images, np.stack([to_grey_uint8(c, "t") for c in colour]))
    grey = data_fetch.convert(bag, tmp_path / "grey.h5", dataset="ced", sequence="simple_carpet", progress=False,
                              grey=True)                             # the escape: grey frames only
    g = read_canonical(grey)
    assert g.meta["frames_rgb"] is None and g.meta["cfa"] == "RGGB"
    np.testing.assert_array_equal(g.frames.images, rec.frames.images)
    mono = data_fetch.convert(bag, tmp_path / "mono.h5", dataset="ced", sequence="simple_carpet", progress=False,
                              cfa=None)
    assert read_canonical(mono).meta["cfa"] is None


def test_converter_debayers_raw_mosaic_frames(tmp_path):
    from data_fetch.convert_bag import convert_bag
    from test_data_fetch import make_bag, make_frames

    raw, fns = make_frames(2)
    bag = make_bag(tmp_path / "raw.bag", bag_events(), (raw, fns), image_topic="/dvs/image_raw", encoding="mono8")
    rec = read_canonical(convert_bag(bag, tmp_path / "raw.h5", cfa="GBRG", progress=False))
    rgb = rec.meta["frames_rgb"]
    pattern = cfa_pattern((18, 24), cfa_phase("GBRG"), block=1)
    for c in range(3):   # every photosite keeps its own measurement in its own channel
        np.testing.assert_array_equal(rgb[..., c][:, pattern == c], raw[:, pattern == c])
    assert rec.meta["cfa"] == "GBRG"


def test_decode_image_colour_encodings():
    from data_fetch.convert_bag import decode_image

    rgb = np.random.default_rng(0).integers(0, 256, (4, 6, 3), dtype=np.uint8)

    def msg(data, enc, step):
        return SimpleNamespace(height=4, width=6, step=step, encoding=enc, is_bigendian=0, data=data.reshape(-1))

    np.testing.assert_array_equal(decode_image(msg(rgb[..., ::-1].copy(), "bgr8", 18), colour=True), rgb)
    np.testing.assert_array_equal(decode_image(msg(rgb, "rgb8", 18)), to_grey_uint8(rgb, "t"))   # grey by default
    mosaic = np.take_along_axis(rgb, cfa_pattern((4, 6), cfa_phase("GRBG"), 1)[..., None].astype(np.intp), -1)[..., 0]
    out = decode_image(msg(mosaic, "bayer_grbg8", 6), colour=True)
    assert out.shape == (4, 6, 3) and out[0, 1, 0] == mosaic[0, 1]   # photosite (0, 1) of GRBG is red


# ---- reconstruction in colour ------------------------------------------------------------

def test_cli_colour_writes_colour_pngs_and_scores_chroma(cli_run):
    code, out = cli_run
    assert code == 0
    png = Image.open(out / "frames" / "frame_00000.png")
    assert png.mode == "RGB" and png.size == (32, 24)               # (W/2, H/2): one pixel per 2 x 2 window
    run = json.loads((out / "run.json").read_text())
    assert run["colour"]["cfa"] == "RGGB" and run["colour"]["thresholds"] == [0.2, 0.1, 0.2]
    assert run["colour"]["chroma_correlation_mean"] > CHROMA_MIN
    assert set(run["scores"]) == {"none", "clahe"} and run["scores"]["none"]["n_frames"] == run["colour"]["n_frames"]


def test_a_wrong_colour_filter_phase_loses_the_colours(colour_h5, cli_run):
    right = json.loads((cli_run[1] / "run.json").read_text())["colour"]["chroma_correlation_mean"]
    rec = load_recording(colour_h5)
    swapped = Recording(rec.events, rec.frames, {**rec.meta, "cfa": "BGGR"})   # red and blue exchanged
    times = rec.frames.t
    result = reconstruct_colour_recording(swapped, times, EvINRConfig(C=0.2, progress=False))
    _, colour = score_colour_recording(result, swapped, score_predictions)
    assert colour["chroma_correlation_mean"] < right - 0.3, (colour, right)
    L = result.at(times)
    grey = np.repeat(L[..., 1:2], 3, axis=-1)                      # a colourless reconstruction scores 0
    assert max(chroma_correlation(grey, L).values()) == 0.0 < CHROMA_MIN


def test_colour_on_a_mono_recording_names_the_fix(capsys, tmp_path):
    folder = write_example_recording(tmp_path / "mono", sensor_size=(20, 24), duration=0.2)
    code = main(["reconstruct", str(folder), "--out", str(tmp_path / "out"), "--colour", "--quiet"])
    err = capsys.readouterr().err
    assert code == 2 and "no colour filter" in err and "drop --colour" in err and "data_fetch" in err
    assert not (tmp_path / "out").exists()


def test_colour_davis_scene_checks_its_inputs():
    with pytest.raises(EventDataError, match="cfa must be one of"):
        colour_davis_recording(cfa="RGB")
    with pytest.raises(EventDataError, match="multiples"):
        colour_davis_recording(sensor_size=(47, 64))


def test_export_writes_colour_gif_and_mp4(tmp_path):
    import cv2

    from evinr_lite.io.export import save_frames_png, save_gif, save_mp4

    frames = np.zeros((3, 8, 10, 3), np.float32)
    frames[..., 0] = 1.0                                            # pure red
    save_gif(tmp_path / "a.gif", frames, 10.0)
    gif = np.asarray(Image.open(tmp_path / "a.gif").convert("RGB")).astype(int)
    assert gif.shape == (8, 10, 3) and gif[..., 0].min() > 200 and gif[..., 2].max() < 50
    save_mp4(tmp_path / "a.mp4", frames, 10.0)
    ok, first = cv2.VideoCapture(str(tmp_path / "a.mp4")).read()   # BGR
    assert ok and first.shape == (8, 10, 3) and first[..., 2].mean() > 200 > 50 > first[..., 0].mean()
    assert Image.open(save_frames_png(tmp_path / "p", frames)[0]).mode == "RGB"
    with pytest.raises(ValueError, match=r"\[F, H, W, 3\] \(colour\)"):
        save_frames_png(tmp_path / "q", np.zeros((2, 4, 4, 2)))
