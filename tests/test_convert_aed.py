"""The AED converter on small fake sequence folders (Quad Bayer events 48 x 64, frames 96 x 128)."""
import json

import h5py
import numpy as np
import pytest
from PIL import Image

import data_fetch
from data_fetch.__main__ import main as cli
from data_fetch.convert_aed import convert_aed
from data_fetch.errors import ConversionError
from evinr_lite import simulate_scene
from evinr_lite.io.canonical import read_canonical
from evinr_lite.sim.quadbayer import QuadBayerScene

RAW = (48, 64)              # (H, W) event photosites -> grey event grid 12 x 16
FRAME = (96, 128)           # frame pixels -> 24 x 32 grey (the "816 x 612"), -> 12 x 16 at the event grid
T0_US = 1_600_000_123_456_789 // 1000     # an absolute clock in microseconds
FRAME_T_US = [T0_US + 20_000, T0_US + 150_000, T0_US + 280_000]


@pytest.fixture(scope="module")
def fake():
    """Events (int64 us, p 0/1) from a simulated Quad Bayer scene, and RGB frames of the same image."""
    scene = QuadBayerScene("coffee", RAW, 0.3, phase=(1, 2), velocity=(40.0, 15.0), rotation=0.0, zoom=0.0)
    ev = simulate_scene(scene, 0.0, 0.3, C=0.25, seed=1)
    t_us = T0_US + np.round(ev.t * 1e6).astype(np.int64)
    cols = np.stack([t_us, ev.x, ev.y, (ev.p > 0).astype(np.int64)], axis=1)
    big = QuadBayerScene("coffee", FRAME, 0.3, velocity=(80.0, 30.0), rotation=0.0, zoom=0.0)
    times = (np.array(FRAME_T_US) - T0_US) / 1e6
    rgb = np.exp(big.rgb_log_intensity(times))
    frames = np.clip(np.round(rgb * 255), 0, 255).astype(np.uint8)
    return cols, frames


def _write(folder, cols, frames, *, events="npy", meta=None, frame_times=FRAME_T_US, names=None):
    folder.mkdir(parents=True, exist_ok=True)
    if events == "npy":
        np.save(folder / "events.npy", cols)
    elif events == "h5":
        with h5py.File(folder / "events.h5", "w") as f:
            for k, name in enumerate("txyp"):
                f.create_dataset(f"events/{name}", data=cols[:, k])
    elif events == "txt":
        lines = [f"{(t - T0_US) / 1e6:.6f} {x} {y} {p}" for t, x, y, p in cols]
        (folder / "events.txt").write_text("# t x y p\n" + "\n".join(lines) + "\n")
    if frames is not None:
        (folder / "frames").mkdir(exist_ok=True)
        names = names or [f"frame_{k:04d}.png" for k in range(len(frames))]
        for name, img in zip(names, frames):
            Image.fromarray(img).save(folder / "frames" / name)
        (folder / "frames.txt").write_text("".join(f"{t} {n}\n" for t, n in zip(frame_times, names)))
    if meta is not None:
        (folder / "meta.json").write_text(meta if isinstance(meta, str) else json.dumps(meta))
    return folder


def _expected_grey(frames):
    """Independent reference: (R + 2G + B) / 4, 4x4 tile means, then 2x2 means; uint8."""
    v = frames.astype(np.float64) / 255.0
    grey = (v[..., 0] + 2 * v[..., 1] + v[..., 2]) / 4
    F, H, W = grey.shape
    full = grey.reshape(F, H // 4, 4, W // 4, 4).mean(axis=(2, 4))
    small = full.reshape(F, H // 8, 2, W // 8, 2).mean(axis=(2, 4))
    u8 = lambda a: np.clip(np.round(a * 255), 0, 255).astype(np.uint8)    # noqa: E731
    return u8(full), u8(small)


def _check_file(path, cols, frames, *, t_atol=0.0):
    rec = read_canonical(path)
    ev = rec.events
    assert ev.sensor_size == (12, 16)
    assert rec.meta["C"] == 0.25 and rec.meta["raw_event_sensor_size"] == [48, 64]
    assert ev.t_origin == T0_US // 10**6
    np.testing.assert_allclose(ev.t, (cols[:, 0] - (T0_US // 10**6) * 10**6) / 1e6, rtol=0, atol=t_atol)
    assert np.array_equal(ev.x, cols[:, 1] // 4) and np.array_equal(ev.y, cols[:, 2] // 4)
    assert np.array_equal(ev.p, np.where(cols[:, 3] > 0, 1, -1))
    full, small = _expected_grey(frames)
    assert np.array_equal(rec.frames.images, small)
    np.testing.assert_allclose(rec.frames.t, (np.array(FRAME_T_US) - (T0_US // 10**6) * 10**6) / 1e6, atol=1e-9)
    with h5py.File(path, "r") as f:
        assert np.array_equal(f["frames_full/images"][()], full)
        assert np.array_equal(f["frames_full/t"][()], rec.frames.t)
    return rec


@pytest.mark.parametrize("kind", ["npy", "h5"])
def test_converts_value_by_value(fake, tmp_path, kind):
    cols, frames = fake
    folder = _write(tmp_path / "street", cols, frames, events=kind, meta={"event_sensor_size": list(RAW),
                                                                          "phase": [1, 2]})
    rec = _check_file(convert_aed(folder, tmp_path / "out.h5", progress=False), cols, frames)
    assert rec.meta["sequence"] == "street" and rec.meta["time_unit"] == "us" and rec.meta["phase"] == [1, 2]
    assert rec.meta["frame_kind"] == "rgb" and rec.meta["frames_full_size"] == [24, 32]


def test_text_events_in_seconds(fake, tmp_path):
    cols, frames = fake
    frame_s = [f"{(t - T0_US) / 1e6:.6f}" for t in FRAME_T_US]
    folder = _write(tmp_path / "txt", cols, frames, events="txt", meta={"event_sensor_size": list(RAW)},
                    frame_times=frame_s)
    rec = read_canonical(convert_aed(folder, tmp_path / "out.h5", progress=False))
    assert rec.meta["time_unit"] == "s" and rec.events.t_origin == 0
    np.testing.assert_allclose(rec.events.t, (cols[:, 0] - T0_US) / 1e6, atol=1e-9)
    assert np.array_equal(rec.events.x, cols[:, 1] // 4)
    assert np.array_equal(rec.frames.images, _expected_grey(frames)[1])


def test_mosaic_frames_16_bit(fake, tmp_path):
    cols, _ = fake
    rng = np.random.default_rng(0)
    mosaics = rng.integers(0, 65536, size=(3,) + FRAME, dtype=np.uint16)
    folder = _write(tmp_path / "mosaic", cols, mosaics, meta={"event_sensor_size": list(RAW)})
    rec = read_canonical(convert_aed(folder, tmp_path / "out.h5", progress=False))
    full = (mosaics / 65535.0).reshape(3, 24, 4, 32, 4).mean(axis=(2, 4))
    small = full.reshape(3, 12, 2, 16, 2).mean(axis=(2, 4))
    assert np.array_equal(rec.frames.images, np.round(small * 255).astype(np.uint8))
    assert rec.meta["frame_kind"] == "mosaic"


def test_convert_and_command_line_use_the_aed_converter(fake, tmp_path):
    cols, frames = fake
    folder = _write(tmp_path / "seq1", cols, frames, meta={"event_sensor_size": list(RAW)})
    path = data_fetch.convert(folder, tmp_path / "a.h5", dataset="aed", progress=False)
    _check_file(path, cols, frames)
    assert data_fetch.info(path)["dataset"] == "aed"
    assert cli(["convert", str(folder), "--dataset", "aed", "--out", str(tmp_path / "b.h5"), "--quiet"]) == 0
    _check_file(tmp_path / "b.h5", cols, frames)
    # --sensor-size is the raw event sensor for AED
    assert cli(["convert", str(folder), "--dataset", "aed", "--out", str(tmp_path / "c.h5"), "--quiet",
                "--sensor-size", "48", "64"]) == 0


def test_events_only_folder(fake, tmp_path):
    cols, _ = fake
    folder = _write(tmp_path / "ev", cols, None, meta={"event_sensor_size": list(RAW)})
    rec = read_canonical(convert_aed(folder, tmp_path / "out.h5", progress=False))
    assert rec.frames is None and len(rec.events) == len(cols)


# ---- bad layouts ---------------------------------------------------------------------------

def _bad(fake, tmp_path, match, **kwargs):
    cols, frames = fake
    edit = kwargs.pop("edit", None)
    kwargs.setdefault("meta", {"event_sensor_size": list(RAW)})
    folder = _write(tmp_path / "bad", kwargs.pop("cols", cols), kwargs.pop("frames", frames), **kwargs)
    if edit:
        edit(folder)
    out = tmp_path / "out.h5"
    with pytest.raises(ConversionError, match=match):
        convert_aed(folder, out, progress=False)
    assert not out.exists() and not list(tmp_path.glob(".*partial"))


def test_not_a_folder(tmp_path):
    (tmp_path / "x.npy").write_text("")
    with pytest.raises(ConversionError, match="is a folder"):
        convert_aed(tmp_path / "x.npy", tmp_path / "out.h5")


def test_no_events_file(fake, tmp_path):
    _bad(fake, tmp_path, "no events file.*events.npy", edit=lambda f: (f / "events.npy").unlink())


def test_two_events_files(fake, tmp_path):
    _bad(fake, tmp_path, "several events files", edit=lambda f: (f / "events.txt").write_text("0 0 0 1\n"))


def test_npy_of_wrong_shape(fake, tmp_path):
    _bad(fake, tmp_path, r"\[N, 4\]", cols=fake[0][:, :3])


def test_h5_without_polarity(fake, tmp_path):
    def drop_p(folder):
        with h5py.File(folder / "events.h5", "a") as f:
            del f["events/p"]
    _bad(fake, tmp_path, r"missing datasets \['p'\]", events="h5", edit=drop_p)


def test_events_outside_the_sensor(fake, tmp_path):
    _bad(fake, tmp_path, "set event_sensor_size in meta.json", meta={"event_sensor_size": [48, 32]})


def test_sensor_not_a_multiple_of_the_tile(fake, tmp_path):
    _bad(fake, tmp_path, "multiples of the Quad Bayer tile", meta={"event_sensor_size": [50, 64]})


def test_meta_json_errors(fake, tmp_path):
    _bad(fake, tmp_path, "unknown keys", meta={"time_units": "us"})
    _bad(fake, tmp_path / "2", "not valid JSON", meta="{time_unit: us")
    _bad(fake, tmp_path / "3", "time_unit", meta={"time_unit": "minutes"})


def test_frames_without_listing(fake, tmp_path):
    _bad(fake, tmp_path, "frames.txt is missing", edit=lambda f: (f / "frames.txt").unlink())


def test_listing_names_a_missing_frame(fake, tmp_path):
    _bad(fake, tmp_path, "names frame_0001.png, which is not in",
         edit=lambda f: (f / "frames" / "frame_0001.png").unlink())


def test_listing_with_a_bad_line(fake, tmp_path):
    _bad(fake, tmp_path, "line 2 has 3 columns",
         edit=lambda f: (f / "frames.txt").write_text(f"{FRAME_T_US[0]} frame_0000.png\n1 2 3\n"))


def test_frames_that_do_not_fit_the_event_grid(fake, tmp_path):
    cols, frames = fake
    _bad(fake, tmp_path, "do not fit the events", frames=frames[:, :88])       # 88 rows: 22 != 2 x 12


def test_frames_of_different_sizes(fake, tmp_path):
    def shrink(folder):
        Image.fromarray(fake[1][1, :48, :64]).save(folder / "frames" / "frame_0001.png")
    _bad(fake, tmp_path, "all frames of a sequence must match", edit=shrink)


def test_frame_times_in_another_unit(fake, tmp_path):
    _bad(fake, tmp_path, "events' clock and time unit", frame_times=[1.0, 2.0, 3.0])


def test_unsorted_events(fake, tmp_path):
    cols = fake[0].copy()
    cols[[10, 11]] = cols[[11, 10]]
    cols[10, 0] += 5                                        # strictly out of order
    _bad(fake, tmp_path, "go back in time", cols=cols)


def test_microseconds_stored_as_floats_need_a_unit(fake, tmp_path):
    cols = fake[0].astype(np.float64)
    cols[:, 0] -= T0_US                                     # relative us, read as seconds by default
    _bad(fake, tmp_path, '"time_unit": "us"', cols=cols,
         frame_times=[t - T0_US for t in FRAME_T_US], meta={"event_sensor_size": list(RAW)})


def test_write_aed_folder_round_trip(tmp_path):
    from data_fetch.convert_aed import write_aed_folder
    from evinr_lite.sim.quadbayer import demosaic_events

    scene = QuadBayerScene("chelsea", (16, 24), 0.2, phase=(3, 1), velocity=(30.0, 0.0), rotation=0.0, zoom=0.0)
    ev = simulate_scene(scene, 0.0, 0.2, C=0.3, seed=0)
    frames = np.full((2, 32, 48, 3), 128, np.uint8)
    folder = write_aed_folder(tmp_path / "seq", ev, frames, [0.05, 0.15], phase=(3, 1))
    rec = read_canonical(convert_aed(folder, tmp_path / "seq.h5", progress=False))
    grey = demosaic_events(ev)
    assert rec.meta["phase"] == [3, 1] and rec.events.sensor_size == grey.sensor_size
    assert np.array_equal(rec.events.x, grey.x) and np.array_equal(rec.events.p, grey.p)
    np.testing.assert_allclose(rec.events.t, np.round(ev.t * 1e6) / 1e6, atol=1e-12)
    np.testing.assert_allclose(rec.frames.t, [0.05, 0.15], atol=1e-12)
    assert np.all(rec.frames.images == 128)
    with pytest.raises(FileExistsError):
        write_aed_folder(tmp_path / "seq", ev)


def test_get_converts_a_folder_placed_in_the_cache(fake, tmp_path, monkeypatch):
    monkeypatch.setenv("EVINR_DATA", str(tmp_path / "cache"))
    with pytest.raises(data_fetch.NotDownloadable, match="place the files"):
        data_fetch.get("aed", "seq1", progress=False)
    cols, frames = fake
    _write(data_fetch.raw_path("aed", "seq1"), cols, frames, meta={"event_sensor_size": list(RAW)})
    path = data_fetch.get("aed", "seq1", progress=False)
    assert path == data_fetch.canonical_path("aed", "seq1")
    _check_file(path, cols, frames)
