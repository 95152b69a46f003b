"""data_fetch, offline: a loopback HTTP server serves fixture files that the tests generate.

Covered: download + conversion (IJRR zip, ROS1 bags for MVSEC and CED, MVSEC hdf5, HQF h5, HQF via a
stand-in for gdown), a dropped connection resumed within a call and across calls, a wrong checksum
(nothing left in the cache), a corrupt archive, a 404, an unreachable server, the canonical reader's
windowed and chunked reads, and the command line. Events and frames are checked value by value.
"""
from __future__ import annotations

import hashlib
import io
import json
import os
import socket
import subprocess
import sys
import threading
import zipfile
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import h5py
import numpy as np
import pytest

from evinr_lite.core.events import EventDataError
from PIL import Image

import data_fetch
from data_fetch import ChecksumError, ConversionError, DataFetchError, DownloadError, NotDownloadable
from data_fetch.__main__ import main as cli
from evinr_lite.io.canonical import find_time_index, iter_canonical_events, read_canonical
from evinr_lite.core.frames import to_grey_uint8 as _to_grey_uint8

NS = 10**9
ORIGIN = 1468941032          # whole seconds of an absolute DAVIS clock (IJRR-like)


# ---- loopback HTTP server -----------------------------------------------------------------

class Server:
    """Serves ``files`` {path: bytes} on 127.0.0.1 with Range support; can drop a transfer once."""

    def __init__(self):
        self.files: dict[str, bytes] = {}
        self.drop_once: set[str] = set()
        self.log: list[tuple[str, str | None]] = []
        server = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, *args):
                pass

            def do_GET(self):
                rng = self.headers.get("Range")
                server.log.append((self.path, rng))
                data = server.files.get(self.path)
                if data is None:
                    self.send_error(404, "Not Found")
                    return
                start = 0
                if rng:
                    start = int(rng.split("=")[1].split("-")[0])
                    if start >= len(data):
                        self.send_response(416)
                        self.send_header("Content-Range", f"bytes */{len(data)}")
                        self.send_header("Content-Length", "0")
                        self.end_headers()
                        return
                    self.send_response(206)
                    self.send_header("Content-Range", f"bytes {start}-{len(data) - 1}/{len(data)}")
                else:
                    self.send_response(200)
                body = data[start:]
                self.send_header("Content-Length", str(len(body)))
                self.end_headers()
                if self.path in server.drop_once:
                    server.drop_once.discard(self.path)
                    self.wfile.write(body[: len(body) // 2])
                    self.wfile.flush()
                    self.connection.shutdown(socket.SHUT_RDWR)
                    self.close_connection = True
                    return
                self.wfile.write(body)

        self.httpd = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.httpd.daemon_threads = True
        self.url = f"http://127.0.0.1:{self.httpd.server_address[1]}"
        self.thread = threading.Thread(target=self.httpd.serve_forever, kwargs={"poll_interval": 0.02}, daemon=True)
        self.thread.start()

    def close(self):
        self.httpd.shutdown()
        self.httpd.server_close()


@pytest.fixture
def server():
    s = Server()
    yield s
    s.close()


@pytest.fixture
def cache(tmp_path, monkeypatch):
    root = tmp_path / "cache"
    monkeypatch.setenv("EVINR_DATA", str(root))
    monkeypatch.setattr("data_fetch.download.BACKOFF_S", 0.0)
    return root


def free_port() -> int:
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


# ---- fixture recordings -------------------------------------------------------------------

def make_events(n=1000, H=18, W=24, seed=0):
    """Integer nanosecond times on an absolute clock, sorted, with a few ties; x, y, p (0/1)."""
    rng = np.random.default_rng(seed)
    ns = ORIGIN * NS + 3_811_000 + np.cumsum(rng.integers(0, 40_000, n))   # ties where the step is 0
    return dict(ns=ns.astype(np.int64), x=rng.integers(0, W, n), y=rng.integers(0, H, n),
                p=rng.integers(0, 2, n), H=H, W=W)


def make_frames(k=4, H=18, W=24, seed=1):
    rng = np.random.default_rng(seed)
    images = rng.integers(0, 256, (k, H, W), dtype=np.uint8)
    ns = ORIGIN * NS + np.arange(k, dtype=np.int64) * 9_000_000 + 1_000     # first frame before the first event
    return images, ns


def ns_text(v) -> str:
    return f"{v // NS}.{v % NS:09d}"


def png_bytes(image) -> bytes:
    buf = io.BytesIO()
    Image.fromarray(image).save(buf, format="PNG")
    return buf.getvalue()


def make_ijrr_zip(path, ev, frames, nested=False, bad_line=None, notes=()):
    images, fns = frames
    pre = "seq/" if nested else ""
    lines = list(notes) + [f"{ns_text(t)} {x} {y} {p}" for t, x, y, p in zip(ev["ns"], ev["x"], ev["y"], ev["p"])]
    if bad_line is not None:
        lines[bad_line] = "1468941032.5 12 oops 1"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr(pre + "events.txt", "\n".join(lines) + "\n")
        z.writestr(pre + "images.txt", "".join(f"{ns_text(t)} images/frame_{i:08d}.png\n" for i, t in enumerate(fns)))
        for i, im in enumerate(images):
            z.writestr(pre + f"images/frame_{i:08d}.png", png_bytes(im))
        z.writestr(pre + "calib.txt", "335.4 335.3 129.9 99.2 -0.13 0.09 -0.0003 0.0001 0.0\n")
        z.writestr(pre + "imu.txt", "")
    return Path(path)


def check_events(rec, ev, origin=ORIGIN):
    e = rec.events
    assert e.t_origin == origin
    np.testing.assert_array_equal(e.t, (ev["ns"] - origin * NS) / NS)   # exact: integer ns, then one division
    np.testing.assert_array_equal(e.x, ev["x"])
    np.testing.assert_array_equal(e.y, ev["y"])
    np.testing.assert_array_equal(e.p, np.where(ev["p"] > 0, 1, -1))
    assert e.sensor_size == (ev["H"], ev["W"])


def check_frames(rec, frames, origin=ORIGIN, grey=None):
    images, fns = frames
    np.testing.assert_array_equal(rec.frames.images, images if grey is None else grey)
    np.testing.assert_array_equal(rec.frames.t, (fns - origin * NS) / NS)


# ROS1 bags written with rosbags' writer; dvs_msgs registered from their message definitions.
EVENT_MSG = "uint16 x\nuint16 y\ntime ts\nbool polarity\n"
EVENT_ARRAY_MSG = "std_msgs/Header header\nuint32 height\nuint32 width\ndvs_msgs/Event[] events\n"


def typestore():
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC)
    types = {}
    types.update(get_types_from_msg(EVENT_MSG, "dvs_msgs/msg/Event"))
    types.update(get_types_from_msg(EVENT_ARRAY_MSG, "dvs_msgs/msg/EventArray"))
    store.register(types)
    return store


def make_bag(path, ev, frames, *, event_topics=("/dvs/events",), image_topic="/dvs/image_raw",
             encoding="mono8", per_msg=97, overlap=False, other_events=None):
    """Events in messages of `per_msg` on event_topics[0] (other_events on the other topics), frames as
    sensor_msgs/Image. overlap: one event of message 3 travels in message 2 (messages overlap in time)."""
    from rosbags.rosbag1 import Writer

    store = typestore()
    T = store.types
    Time, Header = T["builtin_interfaces/msg/Time"], T["std_msgs/msg/Header"]
    Event, EventArray, Img = T["dvs_msgs/msg/Event"], T["dvs_msgs/msg/EventArray"], T["sensor_msgs/msg/Image"]
    images, fns = frames
    path = Path(path)
    msgs = []   # (bag time ns, topic, message, type)
    for j, topic in enumerate(event_topics):
        e = ev if j == 0 else other_events
        n = len(e["ns"])
        cuts = list(range(0, n, per_msg)) + [n]
        blocks = [list(range(a, b)) for a, b in zip(cuts[:-1], cuts[1:])]
        if overlap and j == 0:
            blocks[1].append(blocks[2].pop(5))
        for k, idx in enumerate(blocks):
            events = [Event(x=int(e["x"][i]), y=int(e["y"][i]),
                            ts=Time(sec=int(e["ns"][i] // NS), nanosec=int(e["ns"][i] % NS)),
                            polarity=bool(e["p"][i])) for i in idx]
            stamp = int(max(e["ns"][i] for i in idx))
            head = Header(seq=k, stamp=Time(sec=stamp // NS, nanosec=stamp % NS), frame_id="")
            msgs.append((stamp, topic, EventArray(header=head, height=e["H"], width=e["W"], events=events),
                         "dvs_msgs/msg/EventArray"))
    for k, (im, t) in enumerate(zip(images, fns)):
        if encoding == "rgb8":
            data = np.ascontiguousarray(im).reshape(-1)
            h, w, step = im.shape[0], im.shape[1], im.shape[1] * 3
        else:
            data, h, w, step = im.reshape(-1), im.shape[0], im.shape[1], im.shape[1]
        head = Header(seq=k, stamp=Time(sec=int(t // NS), nanosec=int(t % NS)), frame_id="")
        msgs.append((int(t), image_topic, Img(header=head, height=h, width=w, encoding=encoding, is_bigendian=0,
                                              step=step, data=data.astype(np.uint8)), "sensor_msgs/msg/Image"))
    msgs.sort(key=lambda m: m[0])   # (stable: the overlapping message keeps its place)
    with Writer(path) as writer:
        conns = {}
        for _, topic, _, msgtype in msgs:
            if topic not in conns:
                conns[topic] = writer.add_connection(topic, msgtype, typestore=store)
        for t, topic, msg, msgtype in msgs:
            writer.write(conns[topic], t, store.serialize_ros1(msg, msgtype))
    return path


# ---- IJRR: download + convert -------------------------------------------------------------

@pytest.fixture
def ijrr(tmp_path):
    ev, frames = make_events(), make_frames()
    ev["H"], ev["W"] = 18, 24
    z = make_ijrr_zip(tmp_path / "slider_depth.zip", ev, frames)
    return ev, frames, z.read_bytes()


@pytest.fixture
def small_sensor(monkeypatch):
    """Registry sensor sizes shrunk to the fixtures' 18 x 24 (and 26 x 34 for DAVIS346 datasets)."""
    from dataclasses import replace

    from data_fetch import registry

    for name, size in (("ijrr", (18, 24)), ("hqf", (18, 24)), ("mvsec", (18, 24)), ("ced", (18, 24))):
        monkeypatch.setitem(registry.DATASETS, name, replace(registry.DATASETS[name], sensor_size=size))


def test_get_ijrr_downloads_converts_and_caches(server, cache, ijrr, small_sensor, monkeypatch):
    ev, frames, data = ijrr
    server.files["/davis/slider_depth.zip"] = data
    # small parse blocks and HDF5 chunks, so that the streaming paths run many times
    monkeypatch.setattr("data_fetch.convert_ijrr.BLOCK_BYTES", 300)
    monkeypatch.setattr("evinr_lite.io.canonical.CHUNK_EVENTS", 64)
    path = data_fetch.get("ijrr", "slider_depth", url=server.url + "/davis/slider_depth.zip", progress=False)
    assert path == cache / "ijrr" / "slider_depth.h5"
    assert (cache / "raw" / "ijrr" / "slider_depth.zip").read_bytes() == data
    assert not list((cache / "raw" / "ijrr").glob("*.part")) and not list((cache / "ijrr").glob(".*partial"))
    rec = data_fetch.read(path)
    check_events(rec, ev)
    check_frames(rec, frames)
    m = rec.meta
    assert (m["dataset"], m["sequence"], m["C"]) == ("ijrr", "slider_depth", 1.0)
    assert m["calib"]["fx"] == 335.4
    t_zero = (frames[1][0] - ORIGIN * NS) / NS               # the first frame precedes the first event
    assert m["t_zero"] == t_zero
    assert m["eval_window"] == (t_zero + 1.0, t_zero + 2.5)
    assert m["eval_window_published"] == (1.0, 2.5)
    with h5py.File(path) as f:                                # chunked, compressed, indexed
        assert f["events/t"].chunks == (64,) and f["events/t"].compression == "gzip"
        np.testing.assert_array_equal(f["events/t_index"][()], f["events/t"][::64])
        assert f["events/x"].dtype == np.uint16 and f["events/p"].dtype == np.int8
    requests_before = len(server.log)
    assert data_fetch.get("ijrr", "slider_depth", url=server.url + "/davis/slider_depth.zip", progress=False) == path
    assert len(server.log) == requests_before                 # cached: no new request


def test_ijrr_events_txt_with_comment_lines_on_top_converts_as_evinr_lite_reads_it(tmp_path, cache, small_sensor,
                                                                                   monkeypatch):
    """`#` / `%` notes above the events: evinr-lite's reader skips them, so the converter does too (it refused them
    as "found 5 columns"), also when the first parse block holds only part of the events."""
    monkeypatch.setattr("data_fetch.convert_ijrr.BLOCK_BYTES", 300)
    ev, frames = make_events(300, seed=4), make_frames(2)
    z = make_ijrr_zip(tmp_path / "slider_depth.zip", ev, frames, notes=("# recorded 2016-07-19", "% t x y p"))
    rec = read_canonical(data_fetch.convert(z, tmp_path / "a.h5", progress=False))
    check_events(rec, ev)
    check_frames(rec, frames)


def test_ijrr_nested_zip_and_folder_give_the_same_file(tmp_path, cache, small_sensor):
    ev, frames = make_events(300, seed=3), make_frames(2)
    nested = make_ijrr_zip(tmp_path / "boxes_6dof.zip", ev, frames, nested=True)
    a = read_canonical(data_fetch.convert(nested, tmp_path / "a.h5", progress=False))
    folder = tmp_path / "unzipped"
    zipfile.ZipFile(nested).extractall(folder)
    b = read_canonical(data_fetch.convert(folder / "seq", tmp_path / "b.h5", dataset="ijrr",
                                          sequence="boxes_6dof", progress=False))
    for rec in (a, b):
        check_events(rec, ev)
        check_frames(rec, frames)
        assert rec.meta["eval_window_published"] == (5.0, 20.0)


def test_interrupted_download_is_resumed_with_a_range_request(server, cache, ijrr, small_sensor, monkeypatch):
    ev, frames, data = ijrr
    monkeypatch.setattr("data_fetch.download.BLOCK", 256)   # bytes per read (the last partial read is lost)
    server.files["/slider_depth.zip"] = data
    server.drop_once.add("/slider_depth.zip")
    path = data_fetch.get("ijrr", "slider_depth", url=server.url + "/slider_depth.zip", progress=False)
    gets = [rng for p, rng in server.log if p == "/slider_depth.zip"]
    assert len(gets) == 2 and gets[0] is None
    resumed_at = int(gets[1].removeprefix("bytes=").removesuffix("-"))   # continues where the first stopped
    assert len(data) // 2 - 256 <= resumed_at <= len(data) // 2
    assert (cache / "raw" / "ijrr" / "slider_depth.zip").read_bytes() == data
    check_events(read_canonical(path), ev)


def test_interrupted_download_resumes_on_the_next_call(server, cache, ijrr, small_sensor, monkeypatch):
    ev, frames, data = ijrr
    monkeypatch.setattr("data_fetch.download.BLOCK", 1)       # keep every byte received
    url = server.url + "/slider_depth.zip"
    server.files["/slider_depth.zip"] = data
    server.drop_once.add("/slider_depth.zip")
    with pytest.raises(DownloadError) as err:
        data_fetch.get("ijrr", "slider_depth", url=url, progress=False, retries=0)
    part = cache / "raw" / "ijrr" / "slider_depth.zip.part"
    assert str(part) in str(err.value) and "again" in str(err.value)
    assert part.read_bytes() == data[: len(data) // 2]
    assert not (cache / "raw" / "ijrr" / "slider_depth.zip").exists()
    path = data_fetch.get("ijrr", "slider_depth", url=url, progress=False)
    assert server.log[-1] == ("/slider_depth.zip", f"bytes={len(data) // 2}-")
    assert not part.exists()
    check_events(read_canonical(path), ev)


def test_checksums_pinned_right_and_wrong(server, cache, ijrr, small_sensor):
    ev, frames, data = ijrr
    url = server.url + "/slider_depth.zip"
    server.files["/slider_depth.zip"] = data
    with pytest.raises(ChecksumError) as err:
        data_fetch.get("ijrr", "slider_depth", url=url, known_hash="sha256:" + "0" * 64, progress=False)
    assert "does not match" in str(err.value) and "deleted" in str(err.value)
    raw_dir = cache / "raw" / "ijrr"
    assert [p.name for p in raw_dir.iterdir() if not p.name.startswith(".locks")] == []   # nothing left
    assert not (cache / "ijrr" / "slider_depth.h5").exists()
    good = hashlib.sha256(data).hexdigest()
    path = data_fetch.get("ijrr", "slider_depth", url=url, known_hash="sha256:" + good, progress=False)
    check_events(read_canonical(path), ev)
    # a file placed by hand that does not match the pinned checksum is refused, not silently replaced
    (cache / "ijrr" / "slider_depth.h5").unlink()
    (raw_dir / "slider_depth.zip").write_bytes(data[:-1] + b"x")
    with pytest.raises(ChecksumError, match="Delete it"):
        data_fetch.get("ijrr", "slider_depth", url=url, known_hash="sha256:" + good, progress=False)


def test_404_names_the_url_and_where_to_place_the_file(server, cache):
    with pytest.raises(DownloadError) as err:
        data_fetch.get("ijrr", "slider_depth", url=server.url + "/missing.zip", progress=False)
    msg = str(err.value)
    assert "404" in msg and "/missing.zip" in msg
    assert str(cache / "raw" / "ijrr" / "slider_depth.zip") in msg and "EVINR_DATA" in msg
    assert not (cache / "raw" / "ijrr" / "slider_depth.zip").exists()


def test_unreachable_server_says_so_and_where_to_place_the_file(cache):
    url = f"http://127.0.0.1:{free_port()}/slider_depth.zip"
    with pytest.raises(DownloadError) as err:
        data_fetch.get("ijrr", "slider_depth", url=url, progress=False)
    msg = str(err.value)
    assert "could not reach" in msg and url in msg and "offline" in msg
    assert str(cache / "raw" / "ijrr" / "slider_depth.zip") in msg


def test_corrupt_archives_are_reported_with_the_fix(server, cache, ijrr, small_sensor, tmp_path):
    ev, frames, data = ijrr
    cases = {
        "/garbage.zip": b"<html>not a zip</html>" * 50,          # e.g. an error page saved as the file
        "/truncated.zip": data[: len(data) // 2],                 # cut off (server without Content-Length)
    }
    # a zip whose events.txt data is damaged (CRC / deflate error while streaming)
    broken = bytearray(data)
    info = zipfile.ZipFile(io.BytesIO(data)).getinfo("events.txt")
    start = info.header_offset + 30 + len(info.filename) + len(info.extra)
    for i in range(start + 100, start + 400):
        broken[i] ^= 0x5A
    cases["/crc.zip"] = bytes(broken)
    for name, blob in cases.items():
        server.files[name] = blob
        with pytest.raises(ConversionError) as err:
            data_fetch.get("ijrr", "slider_depth", url=server.url + name, progress=False, force=True)
        msg = str(err.value)
        assert "delete" in msg.lower() and "again" in msg, msg
        assert not (cache / "ijrr" / "slider_depth.h5").exists()
        assert not list((cache / "ijrr").glob(".*partial")) if (cache / "ijrr").exists() else True
        (cache / "raw" / "ijrr" / "slider_depth.zip").unlink()


def test_a_bad_line_is_named_and_leaves_no_output(tmp_path, small_sensor):
    ev, frames = make_events(200), make_frames(2)
    z = make_ijrr_zip(tmp_path / "slider_depth.zip", ev, frames, bad_line=150)
    out = tmp_path / "out.h5"
    with pytest.raises(ConversionError, match="line 151: y is not a number"):
        data_fetch.convert(z, out, progress=False)
    assert not out.exists() and not list(tmp_path.glob(".*partial"))


# ---- bags ---------------------------------------------------------------------------------

def test_bag_event_decoder_matches_rosbags_deserializer(tmp_path):
    from rosbags.rosbag1 import Reader

    from data_fetch.convert_bag import EVENT_ARRAY_MD5, decode_event_array

    ev, frames = make_events(250, seed=5), make_frames(1)
    bag = make_bag(tmp_path / "a.bag", ev, frames)
    store = typestore()
    with Reader(bag) as reader:
        conn = next(c for c in reader.connections if c.topic == "/dvs/events")
        assert conn.digest == EVENT_ARRAY_MD5
        for _, _, raw in reader.messages(connections=[conn]):
            h, w, fast = decode_event_array(raw)
            msg = store.deserialize_ros1(raw, conn.msgtype)
            assert (h, w) == (msg.height, msg.width)
            assert fast["x"].tolist() == [e.x for e in msg.events]
            assert fast["y"].tolist() == [e.y for e in msg.events]
            assert fast["sec"].tolist() == [e.ts.sec for e in msg.events]
            assert fast["nsec"].tolist() == [e.ts.nanosec for e in msg.events]
            assert fast["p"].astype(bool).tolist() == [bool(e.polarity) for e in msg.events]
    with pytest.raises(ConversionError, match="damaged"):
        decode_event_array(bytes(raw)[:-5])


def test_get_mvsec_bag_left_camera_with_pinned_md5(server, cache, small_sensor, tmp_path, monkeypatch):
    monkeypatch.setattr("evinr_lite.io.canonical.CHUNK_EVENTS", 128)
    ev, frames = make_events(1500, seed=7), make_frames(5)
    right = make_events(1500, seed=8)
    bag = make_bag(tmp_path / "indoor_flying4_data.bag", ev, frames,
                   event_topics=("/davis/left/events", "/davis/right/events"), image_topic="/davis/left/image_raw",
                   overlap=True, other_events=right)
    data = bag.read_bytes()
    server.files["/mvsec/indoor_flying4_data.bag"] = data
    path = data_fetch.get("mvsec", "indoor_flying4", url=server.url + "/mvsec/indoor_flying4_data.bag",
                          known_hash="md5:" + hashlib.md5(data).hexdigest(), progress=False)
    assert right["ns"][0] != ev["ns"][0]
    rec = read_canonical(path)
    check_events(rec, ev)
    check_frames(rec, frames)
    t_zero = (frames[1][0] - ORIGIN * NS) / NS
    assert rec.meta["eval_window"] == (t_zero + 10.0, t_zero + 19.8)
    assert rec.meta["event_topic"] == "/davis/left/events"
    assert rec.meta["event_messages_reordered"] == 1             # the overlapping message was merged in order


def test_ced_zip_of_bags_colour_frames_to_grey(server, cache, small_sensor, tmp_path):
    ev = make_events(400, seed=9)
    rng = np.random.default_rng(2)
    colour = rng.integers(0, 256, (3, 18, 24, 3), dtype=np.uint8)
    fns = make_frames(3)[1]
    bag = make_bag(tmp_path / "simple_carpet.bag", ev, (colour, fns), image_topic="/dvs/image_color",
                   encoding="rgb8")
    other = make_bag(tmp_path / "simple_fruit.bag", make_events(50, seed=10), make_frames(1))
    archive = tmp_path / "CED_simple.zip"
    with zipfile.ZipFile(archive, "w") as z:
        z.write(bag, "CED_simple/simple_carpet.bag")
        z.write(other, "CED_simple/simple_fruit.bag")
    server.files["/CED_simple.zip"] = archive.read_bytes()
    path = data_fetch.get("ced", "simple_carpet", url=server.url + "/CED_simple.zip", progress=False)
    rec = read_canonical(path)
    check_events(rec, ev)
    grey = np.stack([_to_grey_uint8(c, "test") for c in colour])
    check_frames(rec, (colour, fns), grey=grey)
    assert rec.meta["image_topic"] == "/dvs/image_color" and rec.meta["eval_window"] is None
    assert not list((cache / "ced").glob(".*.bag"))          # the extracted bag copy is gone
    with pytest.raises(ConversionError, match="holds no simple_jenga_1.bag"):
        data_fetch.get("ced", "simple_jenga_1", progress=False)   # same archive, already in the cache


def test_a_damaged_bag_is_reported(tmp_path):
    ev, frames = make_events(300), make_frames(2)
    bag = make_bag(tmp_path / "desk.bag", ev, frames)
    cut = tmp_path / "cut.bag"
    cut.write_bytes(bag.read_bytes()[:2000])
    for bad in (cut, tmp_path / "junk.bag"):
        if bad.name == "junk.bag":
            bad.write_bytes(b"#ROSBAG V2.0\n" + b"\0" * 100)
        with pytest.raises(ConversionError, match="delete"):
            data_fetch.convert(bad, tmp_path / "out.h5", dataset="hqf", sequence="desk", progress=False)
        assert not (tmp_path / "out.h5").exists()


def test_hqf_through_gdown_stand_in(cache, small_sensor, tmp_path, monkeypatch):
    import gdown

    ev, frames = make_events(500, seed=11), make_frames(3)
    bag = make_bag(tmp_path / "still_life.bag", ev, frames)
    calls = []

    class Entry:
        def __init__(self, id, path):
            self.id, self.path = id, path

    def download_folder(url=None, skip_download=False, quiet=False, **kw):
        calls.append(("list", url, skip_download))
        return [Entry("ID_STILL", "HQF/still_life.bag"), Entry("ID_DESK", "HQF/desk.bag")]

    def download(id=None, output=None, quiet=False, resume=False, retries=0, **kw):
        calls.append(("get", id, resume))
        Path(output).write_bytes(bag.read_bytes())
        return output

    monkeypatch.setattr(gdown, "download_folder", download_folder)
    monkeypatch.setattr(gdown, "download", download)
    path = data_fetch.get("hqf", "still_life", progress=False)
    assert calls == [("list", data_fetch.registry.HQF_FOLDER, True), ("get", "ID_STILL", True)]
    rec = read_canonical(path)
    check_events(rec, ev)
    check_frames(rec, frames)
    assert rec.meta["eval_window"] is None and rec.meta["C"] == 1.0
    listing = json.loads((cache / "raw" / "hqf" / ".drive_listing.json").read_text())
    assert listing == {"still_life.bag": "ID_STILL", "desk.bag": "ID_DESK"}
    assert [c[0] for c in calls].count("list") == 1
    with pytest.raises(DownloadError, match="boxes.bag is not in the Google Drive folder"):
        data_fetch.get("hqf", "boxes", progress=False)          # missing from the cached listing: listed anew
    assert [c[0] for c in calls].count("list") == 2

    def offline(**kw):
        raise ConnectionError("Failed to resolve 'drive.google.com'")

    (cache / "raw" / "hqf" / ".drive_listing.json").unlink()
    monkeypatch.setattr(gdown, "download_folder", offline)
    with pytest.raises(DownloadError) as err:
        data_fetch.get("hqf", "desk", progress=False)
    assert "could not list" in str(err.value) and str(cache / "raw" / "hqf" / "desk.bag") in str(err.value)


# ---- h5 releases --------------------------------------------------------------------------

def test_mvsec_hdf5_conversion(tmp_path, small_sensor, monkeypatch):
    monkeypatch.setattr("data_fetch.convert_h5.ROWS", 100)
    ev, frames = make_events(700, seed=12), make_frames(3)
    t_abs = ev["ns"] / NS            # MVSEC stores float64 absolute seconds
    raw = tmp_path / "outdoor_day1_data.hdf5"
    with h5py.File(raw, "w") as f:
        f["davis/left/events"] = np.stack([ev["x"], ev["y"], t_abs, np.where(ev["p"] > 0, 1, -1)], 1).astype(np.float64)
        f["davis/left/image_raw"] = frames[0]
        f["davis/left/image_raw_ts"] = frames[1] / NS
        f["davis/right/events"] = np.zeros((5, 4))
    rec = read_canonical(data_fetch.convert(raw, tmp_path / "out", progress=False))
    assert rec.meta["sequence"] == "outdoor_day1" and rec.meta["eval_window_published"] == (0.0, 60.0)
    np.testing.assert_array_equal(rec.events.t, t_abs - ORIGIN)
    np.testing.assert_array_equal(rec.events.x, ev["x"])
    np.testing.assert_array_equal(rec.events.y, ev["y"])
    np.testing.assert_array_equal(rec.events.p, np.where(ev["p"] > 0, 1, -1))
    np.testing.assert_array_equal(rec.frames.images, frames[0])
    np.testing.assert_array_equal(rec.frames.t, frames[1] / NS - ORIGIN)


def test_hqf_h5_conversion_repairs_an_out_of_order_frame_time(tmp_path, small_sensor):
    ev, frames = make_events(400, seed=13), make_frames(5)
    t = (ev["ns"] - ORIGIN * NS) / NS        # small times: t_origin stays 0
    stamps = (frames[1] - ORIGIN * NS) / NS
    wrong = stamps.copy()
    wrong[2] = stamps[4] + 0.5             # one timestamp too late, as in HQF engineering_posters
    raw = tmp_path / "engineering_posters.h5"
    with h5py.File(raw, "w") as f:
        f["events/xs"], f["events/ys"], f["events/ts"] = ev["x"].astype(np.int16), ev["y"].astype(np.int16), t
        f["events/ps"] = ev["p"].astype(bool)
        f.attrs["sensor_resolution"] = (18, 24)
        for i, (im, s) in enumerate(zip(frames[0], wrong)):
            f[f"images/image{i:09d}"] = im
            f[f"images/image{i:09d}"].attrs["timestamp"] = s
    rec = read_canonical(data_fetch.convert(raw, tmp_path / "o.h5", progress=False))
    assert rec.events.t_origin == 0 and rec.meta["sequence"] == "engineering_posters"
    np.testing.assert_array_equal(rec.events.t, t)
    np.testing.assert_array_equal(rec.events.x, ev["x"])
    np.testing.assert_array_equal(rec.events.y, ev["y"])
    np.testing.assert_array_equal(rec.events.p, np.where(ev["p"] > 0, 1, -1))
    repaired = stamps.copy()
    repaired[2] = 0.5 * (stamps[1] + stamps[3])
    np.testing.assert_array_equal(rec.frames.t, repaired)
    np.testing.assert_array_equal(rec.frames.images, frames[0])
    assert rec.meta["frame_times_repaired"] == [2]


# ---- canonical reader ---------------------------------------------------------------------

def test_canonical_windows_and_chunks_read_only_what_is_asked(tmp_path, monkeypatch):
    from data_fetch.canonical import CanonicalWriter

    monkeypatch.setattr("evinr_lite.io.canonical.CHUNK_EVENTS", 50)
    rng = np.random.default_rng(4)
    n = 5000
    t = np.sort(rng.integers(0, 2000, n)) * 1e-3         # many ties
    x, y = rng.integers(0, 24, n), rng.integers(0, 18, n)
    p = rng.choice([-1, 1], n).astype(np.int8)
    out = tmp_path / "c.h5"
    with CanonicalWriter(out, sensor_size=(18, 24), t_origin=ORIGIN, dataset="test", eval_window=(0.5, 1.5)) as w:
        for a in range(0, n, 333):
            w.add_events(t[a:a + 333], x[a:a + 333], y[a:a + 333], p[a:a + 333])
        for k in range(4):
            w.add_frame(np.full((18, 24), k, np.uint8), 0.5 * k)
    with h5py.File(out) as f:
        for v in np.concatenate([t[::97], [-1.0, 0.0, 2.5, 1.0005]]):
            for side in ("left", "right"):
                assert find_time_index(f, v, side) == np.searchsorted(t, v, side=side)
    whole = read_canonical(out)
    np.testing.assert_array_equal(whole.events.t, t)
    assert whole.events.t_origin == ORIGIN
    part = read_canonical(out, 0.5, 1.0)
    lo, hi = np.searchsorted(t, 0.5), np.searchsorted(t, 1.0)
    np.testing.assert_array_equal(part.events.t, t[lo:hi])
    np.testing.assert_array_equal(part.events.x, x[lo:hi])
    np.testing.assert_array_equal(part.frames.t, [0.5])
    assert part.meta["event_slice"] == (lo, hi)
    chunks = list(iter_canonical_events(out, 0.25, None, chunk_events=700))
    assert max(len(c) for c in chunks) == 700
    np.testing.assert_array_equal(np.concatenate([c.t for c in chunks]), t[np.searchsorted(t, 0.25):])
    with pytest.raises(Exception, match="no events in the window"):
        read_canonical(out, 5.0, 6.0)
    with pytest.raises(ConversionError, match="go back in time"):
        with CanonicalWriter(tmp_path / "bad.h5", sensor_size=(18, 24)) as w:
            w.add_events(np.array([1.0, 0.5]), np.zeros(2), np.zeros(2), np.ones(2))
    assert not (tmp_path / "bad.h5").exists() and not list(tmp_path.glob(".*partial"))


# ---- AED, registry, command line ----------------------------------------------------------

def test_aed_is_place_by_hand(cache):
    with pytest.raises(NotDownloadable) as err:
        data_fetch.get("aed", "some_sequence")
    msg = str(err.value)
    assert "not publicly downloadable" in msg and str(cache / "raw" / "aed" / "some_sequence") in msg
    with pytest.raises(DataFetchError, match="known datasets"):
        data_fetch.get("nope", "x")
    with pytest.raises(DataFetchError, match="known sequences"):
        data_fetch.get("hqf", "no_such_sequence")


def test_registry_facts():
    from data_fetch.registry import DATASETS

    ijrr, hqf, mvsec = DATASETS["ijrr"], DATASETS["hqf"], DATASETS["mvsec"]
    assert [s for s, q in ijrr.sequences.items() if q.evaluation] == [
        "calibration", "boxes_6dof", "dynamic_6dof", "office_zigzag", "poster_6dof", "shapes_6dof", "slider_depth"]
    assert ijrr.sequences["slider_depth"].url == "https://rpg.ifi.uzh.ch/datasets/davis/slider_depth.zip"
    assert ijrr.sequences["office_zigzag"].eval_window == (5.0, 12.0)
    assert len(hqf.sequences) == 14 and all(q.eval_window is None for q in hqf.sequences.values())
    assert mvsec.sequences["outdoor_day2"].eval_window == (100.0, 160.0)
    assert mvsec.sequences["indoor_flying1"].url.endswith("/mvsec/indoor_flying/indoor_flying1_data.bag")
    assert all(q.known_hash is None for q in ijrr.sequences.values())      # none published: not invented
    assert (ijrr.sensor_size, mvsec.sensor_size, DATASETS["aed"].C) == ((180, 240), (260, 346), 0.25)


def test_command_line(tmp_path, cache, small_sensor, capsys):
    ev, frames = make_events(300, seed=14), make_frames(2)
    z = make_ijrr_zip(tmp_path / "shapes_6dof.zip", ev, frames)
    assert cli(["list"]) == 0
    out = capsys.readouterr().out
    assert str(cache) in out and "NOT downloadable" in out and "Google Drive" in out
    assert cli(["list", "ijrr"]) == 0
    out = capsys.readouterr().out
    assert "[1, 2.5] s" in out and "shapes_rotation" not in out and "sequences outside the evaluation protocol" in out
    assert cli(["list", "ijrr", "--all"]) == 0   # the ECD names `get` also takes (from the URL pattern) are listed
    assert "shapes_rotation" in capsys.readouterr().out
    assert cli(["convert", str(z), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    written = Path(capsys.readouterr().out.strip())
    assert written == tmp_path / "o" / "shapes_6dof.h5"
    check_events(read_canonical(written), ev)
    assert cli(["info", str(written)]) == 0
    assert "300 events" in capsys.readouterr().out
    assert cli(["get", "aed", "seq1"]) == 2
    assert "error: " in capsys.readouterr().err
    assert cli(["convert", str(tmp_path / "missing.zip")]) == 2


def test_import_is_light():
    code = ("import sys, data_fetch; heavy = ('pooch', 'requests', 'gdown', 'rosbags', 'h5py', 'torch'); "
            "print([m for m in heavy if m in sys.modules])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=Path(__file__).resolve().parents[1], env={**os.environ, "PYTHONPATH": "."})
    assert out.stdout.strip() == "[]"


# ---- ROS2 bags: rewritten as ROS1 by rosbags, then converted as any bag ---------------------------------------

def make_ros2_bag(folder, ev, frames, per_msg=97, storage="sqlite3"):
    """A ROS2 bag folder (rosbag2 version 9, its message definitions stored) with dvs_msgs/EventArray on
    /dvs/events and sensor_msgs/Image on /dvs/image_raw, as a ROS2 driver records them."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    from data_fetch.convert_bag import ROS2_DVS_MSGS

    store = get_typestore(Stores.ROS2_HUMBLE)
    types = {}
    for name, text in ROS2_DVS_MSGS.items():
        types.update(get_types_from_msg(text, name))
    store.register(types)
    T = store.types
    Time, Header = T["builtin_interfaces/msg/Time"], T["std_msgs/msg/Header"]
    Event, EventArray, Img = T["dvs_msgs/msg/Event"], T["dvs_msgs/msg/EventArray"], T["sensor_msgs/msg/Image"]
    images, fns = frames
    msgs = []
    n = len(ev["ns"])
    for a in range(0, n, per_msg):
        idx = range(a, min(n, a + per_msg))
        events = [Event(x=int(ev["x"][i]), y=int(ev["y"][i]), ts=Time(sec=int(ev["ns"][i] // NS),
                        nanosec=int(ev["ns"][i] % NS)), polarity=bool(ev["p"][i])) for i in idx]
        stamp = int(ev["ns"][idx[-1]])
        msgs.append((stamp, "/dvs/events", EventArray(header=Header(stamp=Time(sec=stamp // NS, nanosec=stamp % NS),
                                                                    frame_id=""), height=ev["H"], width=ev["W"],
                                                      events=events), "dvs_msgs/msg/EventArray"))
    for im, t in zip(images, fns):
        head = Header(stamp=Time(sec=int(t // NS), nanosec=int(t % NS)), frame_id="")
        msgs.append((int(t), "/dvs/image_raw", Img(header=head, height=im.shape[0], width=im.shape[1], encoding="mono8",
                                                   is_bigendian=0, step=im.shape[1], data=im.reshape(-1)),
                     "sensor_msgs/msg/Image"))
    msgs.sort(key=lambda m: m[0])
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    with Writer(Path(folder), version=9, storage_plugin=plugin) as writer:
        conns = {}
        for t, topic, msg, msgtype in msgs:
            if topic not in conns:
                conns[topic] = writer.add_connection(topic, msgtype, typestore=store)
            writer.write(conns[topic], t, store.serialize_cdr(msg, msgtype))
    return Path(folder)


@pytest.mark.parametrize("storage", ["sqlite3", "mcap"])
def test_a_ros2_bag_converts_exactly(tmp_path, storage):
    """python -m data_fetch convert FOLDER on a ROS2 bag: the events and APS frames come out exactly as
    written (integer nanoseconds), through rosbags' rewrite as a ROS1 bag, whose copy does not stay."""
    from data_fetch import convert
    from evinr_lite.io import load_recording

    ev, frames = make_events(), make_frames()
    bag = make_ros2_bag(tmp_path / "drive_ros2", ev, frames, storage=storage)
    out = convert(bag, tmp_path / "out", progress=False)
    rec = load_recording(out)
    check_events(rec, ev)
    keep = (frames[1] >= ev["ns"][0]) & (frames[1] <= ev["ns"][-1])     # the frames within the events' span
    np.testing.assert_array_equal(rec.frames.images, frames[0][keep])
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [out.name]


def test_a_ros2_bag_is_refused_by_the_kit_with_the_conversion(tmp_path):
    """evinr-lite on a ROS2 bag's folder, or on one of its storage files, names `python -m data_fetch convert`;
    data_fetch given a storage file asks for the folder."""
    from data_fetch import convert
    from data_fetch.errors import DataFetchError
    from evinr_lite.io.formats.registry import detect_format, sniff_format

    bag = make_ros2_bag(tmp_path / "rec", make_events(200), make_frames(2))
    with pytest.raises(EventDataError, match=r"a ROS2 bag.*python -m data_fetch convert"):
        detect_format(bag)
    db3 = next(bag.glob("*.db3"))
    assert sniff_format(db3) == "sqlite"
    with pytest.raises(EventDataError, match=r"ROS2 bag's \.db3 storage.*data_fetch convert FOLDER"):
        detect_format(db3)
    with pytest.raises(DataFetchError, match="pass the bag's folder"):
        convert(db3, tmp_path / "o.h5", progress=False)


def test_a_ros2_bag_without_message_definitions_converts_with_the_known_dvs_msgs(tmp_path, monkeypatch):
    """Bags recorded before rosbag2 stored message definitions carry none: the ROS2 dvs_msgs definitions
    supplied to the converter stand in (without them rosbags does not know dvs_msgs/msg/EventArray)."""
    import sqlite3

    import data_fetch.convert_bag as cb
    from data_fetch import convert
    from evinr_lite.io import load_recording

    ev = make_events(300)
    bag = make_ros2_bag(tmp_path / "old", ev, make_frames(2))
    with sqlite3.connect(next(bag.glob("*.db3"))) as con:
        con.execute("delete from message_definitions")
    check_events(load_recording(convert(bag, tmp_path / "a.h5", progress=False)), ev)
    monkeypatch.setattr(cb, "ROS2_DVS_MSGS", {})
    with pytest.raises(DataFetchError, match=r"ROS2 bag could not be read.*dvs_msgs/msg/EventArray"):
        convert(bag, tmp_path / "b.h5", progress=False)


# ---- event_camera_msgs/EventPacket (Prophesee cameras under ROS: metavision_driver) --------------------------------

def _packet_stream(n=3000, H=30, W=40, seed=3, encoding="evt3"):
    """Events on a camera clock (integer microseconds), and the camera's own byte stream for them (faery's
    EVT 2 / 3 writer, its header taken off)."""
    faery = pytest.importorskip("faery")
    rng = np.random.default_rng(seed)
    ev = np.zeros(n, dtype=faery.EVENTS_DTYPE)
    ev["t"] = np.sort(1_200_000 + rng.integers(0, 2_500_000, n)).astype(np.uint64)
    ev["x"], ev["y"], ev["on"] = rng.integers(0, W, n), rng.integers(0, H, n), rng.random(n) < 0.5
    with __import__("tempfile").TemporaryDirectory() as folder:     # nothing left behind in /tmp
        path = Path(folder) / "s.raw"
        faery.events_stream_from_array(ev, dimensions=(W, H)).to_file(path, version=encoding)
        data = path.read_bytes()
    pos, t0 = 0, 0
    while data[pos:pos + 1] == b"%":
        end = data.index(b"\n", pos)
        if data[pos:end].startswith(b"% t0 "):       # faery's stream counts from this time: so does the camera's
            t0 = int(data[pos + 5:end])
        pos = end + 1
    ev["t"] -= np.uint64(t0)
    return ev, data[pos:]


def make_packet_bag(folder, stream, H, W, encoding="evt3", per_msg=501, ros2=True, image=False):
    """A bag of event_camera_msgs/EventPacket on /event_camera/events: the stream cut into messages of
    per_msg bytes (anywhere, even inside a word: the messages in order are the stream), as metavision_driver
    records them; image: also a sensor_msgs/Image topic."""
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    from data_fetch.convert_bag import EVENT_PACKET_MSGS, EVENT_PACKET_TYPE

    store = get_typestore(Stores.ROS2_HUMBLE if ros2 else Stores.ROS1_NOETIC)
    store.register(get_types_from_msg(EVENT_PACKET_MSGS[EVENT_PACKET_TYPE], EVENT_PACKET_TYPE))
    T = store.types
    Time, Header, Packet = T["builtin_interfaces/msg/Time"], T["std_msgs/msg/Header"], T[EVENT_PACKET_TYPE]
    msgs = []
    for k, a in enumerate(range(0, len(stream), per_msg)):
        stamp = ORIGIN * NS + k * 1_000_000
        head = Header(stamp=Time(sec=stamp // NS, nanosec=stamp % NS), frame_id="cam") if ros2 else \
            Header(seq=k, stamp=Time(sec=stamp // NS, nanosec=stamp % NS), frame_id="cam")
        msgs.append((stamp, "/event_camera/events", Packet(header=head, height=H, width=W, seq=k, time_base=0,
                     encoding=encoding, is_bigendian=False, events=np.frombuffer(stream[a:a + per_msg], np.uint8)),
                     EVENT_PACKET_TYPE))
    if image:
        Img = T["sensor_msgs/msg/Image"]
        im = np.zeros((H, W), np.uint8)
        head = Header(stamp=Time(sec=ORIGIN, nanosec=5), frame_id="") if ros2 else \
            Header(seq=0, stamp=Time(sec=ORIGIN, nanosec=5), frame_id="")
        msgs.append((ORIGIN * NS + 5, "/image", Img(header=head, height=H, width=W, encoding="mono8", is_bigendian=0,
                                                     step=W, data=im.reshape(-1)), "sensor_msgs/msg/Image"))
    msgs.sort(key=lambda m: m[0])
    if ros2:
        from rosbags.rosbag2 import Writer
        ctx, serialize = Writer(Path(folder), version=9), store.serialize_cdr
    else:
        from rosbags.rosbag1 import Writer
        ctx, serialize = Writer(Path(folder)), store.serialize_ros1
    with ctx as writer:
        conns = {}
        for t, topic, msg, msgtype in msgs:
            if topic not in conns:
                conns[topic] = writer.add_connection(topic, msgtype, typestore=store)
            writer.write(conns[topic], t, serialize(msg, msgtype))
    return Path(folder)


@pytest.mark.parametrize("encoding, ros2", [("evt3", True), ("evt3", False), ("evt2", True)])
def test_event_packets_of_a_prophesee_camera_convert_exactly(tmp_path, encoding, ros2):
    """A ROS2 (or ROS1) bag of event_camera_msgs/EventPacket: the packets' bytes in order are the camera's
    stream; the canonical file holds its events exactly, on the camera's clock (microseconds)."""
    from data_fetch import convert
    from evinr_lite.io import load_recording

    ev, stream = _packet_stream(encoding=encoding)
    bag = make_packet_bag(tmp_path / ("rec" if ros2 else "rec.bag"), stream, 30, 40, encoding, ros2=ros2)
    out = convert(bag, tmp_path / "out.h5", progress=False)
    rec = load_recording(out)
    e = rec.events
    assert e.sensor_size == (30, 40) and rec.frames is None
    us = np.round((e.t + e.t_origin) * 1e6).astype(np.int64)
    np.testing.assert_array_equal(us, ev["t"].astype(np.int64))
    np.testing.assert_array_equal(e.x, ev["x"])
    np.testing.assert_array_equal(e.y, ev["y"])
    np.testing.assert_array_equal(e.p, np.where(ev["on"], 1, -1))
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(["out.h5", bag.name])    # no temporary left


def test_event_packets_refused_with_the_reason(tmp_path):
    from data_fetch import convert

    ev, stream = _packet_stream(500)
    bag = make_packet_bag(tmp_path / "cmp", stream, 30, 40, encoding="libcaer_cmp")
    with pytest.raises(ConversionError, match=r"'libcaer_cmp' encoding; data_fetch decodes \['evt2', 'evt21', 'evt3'\]"):
        convert(bag, tmp_path / "a.h5", progress=False)
    garbage = np.random.default_rng(0).integers(0, 256, 4000, dtype=np.uint8).tobytes()
    bag = make_packet_bag(tmp_path / "junk", garbage, 30, 40)
    with pytest.raises(ConversionError, match=r"junk: the evt3 stream in the event packets could not be decoded "
                                              r"\((?!.*packets\.raw).*the bag is damaged"):
        convert(bag, tmp_path / "b.h5", progress=False)
    assert not list(tmp_path.glob(".*packets.raw")) and not (tmp_path / "b.h5").exists()
    import logging

    seen = []
    handler = logging.Handler(logging.WARNING)
    handler.emit = lambda record: seen.append(record.getMessage())
    logger = logging.getLogger("data_fetch")     # its own handler: the command line may stop its propagation
    logger.addHandler(handler)
    try:
        convert(make_packet_bag(tmp_path / "with_image", stream, 30, 40, image=True), tmp_path / "c.h5", progress=False)
    finally:
        logger.removeHandler(handler)
    assert any("image topics ['/image'] are not stored" in m for m in seen)


def test_event_packets_of_a_ros2_bag_without_message_definitions(tmp_path):
    """Bags recorded before rosbag2 stored message definitions: the known EventPacket definition stands in."""
    import sqlite3

    from data_fetch import convert
    from evinr_lite.io import load_recording

    ev, stream = _packet_stream(800)
    bag = make_packet_bag(tmp_path / "old", stream, 30, 40)
    with sqlite3.connect(next(bag.glob("*.db3"))) as con:
        con.execute("delete from message_definitions")
    e = load_recording(convert(bag, tmp_path / "a.h5", progress=False)).events
    np.testing.assert_array_equal(np.round((e.t + e.t_origin) * 1e6).astype(np.int64), ev["t"].astype(np.int64))
