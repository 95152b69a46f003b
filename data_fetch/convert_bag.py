"""ROS1 bags (HQF, CED, MVSEC, IJRR .bag) -> canonical file, message by message.

The bag is read with rosbags (pure Python: no ROS installation). Image messages
(sensor_msgs/Image, a few thousand per bag) are decoded by rosbags' deserializer. Event messages
(dvs_msgs/EventArray, up to 10^8 events per bag) are decoded here with one numpy view per message:
after the header come height, width, the event count and then packed 13-byte events
(uint16 x, uint16 y, uint32 sec, uint32 nsec, uint8 polarity), which is far faster than building a
Python object per event. The numpy path is used only when the connection's message definition has
the dvs_msgs/EventArray md5; any other definition goes through rosbags' deserializer.

Prophesee cameras under ROS (``metavision_driver``) publish event_camera_msgs/EventPacket instead: each
message carries a slice of the camera's own byte stream (``encoding`` "evt3", "evt2" or "evt21"), and the
slices in order are that stream. A bag without a dvs_msgs topic is converted from such packets: their bytes
are written one after the other into a temporary Prophesee ``.raw`` file beside ``out`` (header from the
packets' encoding, width and height), which the kit's Prophesee reader decodes a window at a time, on the
sensor's clock (microseconds since the camera started). Other encodings (libcaer's) are refused by name.

Colour cameras (CED's Color DAVIS346: a 2 x 2 RGGB Bayer filter over both the events and the APS):
``cfa="RGGB"`` records the filter with the events (the canonical ``cfa`` attribute), and colour frames
are kept in colour (/frames/rgb, with their grey version in /frames/images): rgb8 / bgr8 / rgba8 /
bgra8 as they are, bayer_rggb8-style mosaics and (with ``cfa``) mono8 raw mosaics debayered
bilinearly (:func:`debayer`). ``grey=True`` stores grey frames
only, as before colour was kept.
"""
from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from evinr_lite.core.events import LARGE_T, EventDataError
from evinr_lite.io.text import NS
from evinr_lite.core.frames import to_grey_uint8 as _to_grey_uint8
from evinr_lite.core.cfa import CFA_NAMES, check_cfa

from .canonical import CanonicalWriter
from .errors import ConversionError

__all__ = ["convert_bag", "ros2_to_ros1", "decode_event_array", "decode_image", "debayer", "EVENT_DTYPE",
           "EVENT_ARRAY_MD5", "ROS2_DVS_MSGS", "EVENT_PACKET_MSGS", "EVENT_PACKET_TYPE", "packets_to_raw"]

log = logging.getLogger("data_fetch")

EVENT_DTYPE = np.dtype([("x", "<u2"), ("y", "<u2"), ("sec", "<u4"), ("nsec", "<u4"), ("p", "u1")])
EVENT_ARRAY_MD5 = "5e8beee5a6c107e504c2e78903c224b8"   # dvs_msgs/EventArray (as generated from its definition)
EVENT_ARRAY_TYPE = "dvs_msgs/msg/EventArray"
IMAGE_TYPE = "sensor_msgs/msg/Image"
# dvs_msgs as ROS2 drivers declare them, for ROS2 bags too old to carry their own message definitions
ROS2_DVS_MSGS = {"dvs_msgs/msg/Event": "uint16 x\nuint16 y\nbuiltin_interfaces/Time ts\nbool polarity\n",
                 "dvs_msgs/msg/EventArray": "std_msgs/Header header\nuint32 height\nuint32 width\n"
                                            "dvs_msgs/Event[] events\n"}
EVENT_PACKET_TYPE = "event_camera_msgs/msg/EventPacket"
# event_camera_msgs/EventPacket (ROS1 and ROS2 alike), for bags that carry no message definitions
EVENT_PACKET_MSGS = {EVENT_PACKET_TYPE: "std_msgs/Header header\nuint32 height\nuint32 width\nuint64 seq\n"
                                        "uint64 time_base\nstring encoding\nbool is_bigendian\nuint8[] events\n"}
PACKET_HEADERS = {"evt3": "evt 3.0\n% format EVT3", "evt2": "evt 2.0\n% format EVT2", "evt21": "evt 2.1\n% format EVT21"}
PREFERRED_EVENT_TOPICS = ("/dvs/events", "/davis/left/events")
PREFERRED_PACKET_TOPICS = ("/event_camera/events",)
PREFERRED_IMAGE_TOPICS = ("/dvs/image_raw", "/davis/left/image_raw", "/dvs/image_color")


def ros2_to_ros1(src, dst) -> Path:
    """A ROS2 bag (its folder: metadata.yaml with .db3 or .mcap storage) rewritten as the ROS1 bag ``dst``,
    message by message, by rosbags' converter (CDR to ROS1 serialization), so that :func:`convert_bag`
    reads it. The bag's own message definitions are used; dvs_msgs and event_camera_msgs/EventPacket are
    known here for bags that carry none (:data:`ROS2_DVS_MSGS`, :data:`EVENT_PACKET_MSGS`). ``dst`` is replaced. ConversionError names what failed."""
    from rosbags.convert import ConverterError, convert
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    src, dst = Path(src), Path(dst)
    store = get_typestore(Stores.ROS2_HUMBLE)
    types = {}
    for name, text in {**ROS2_DVS_MSGS, **EVENT_PACKET_MSGS}.items():
        types.update(get_types_from_msg(text, name))
    store.register(types)
    dst.unlink(missing_ok=True)
    log.info("data_fetch: %s: a ROS2 bag; rewriting it as a ROS1 bag first (rosbags)", src)
    try:
        convert(srcs=[src], dst=dst, dst_storage="sqlite3", dst_version=None, compress=None, compress_mode="file",
                default_typestore=store, typestore=None, exclude_topics=(), include_topics=(), exclude_msgtypes=(),
                include_msgtypes=())
    except (ConverterError, OSError, ValueError, KeyError) as err:
        dst.unlink(missing_ok=True)
        raise ConversionError(f"{src}: the ROS2 bag could not be read ({type(err).__name__}: {err}); check that the "
                              "folder holds the whole bag (metadata.yaml and its .db3 or .mcap files)") from None
    return dst


def _u32(raw, offset: int) -> int:
    return int.from_bytes(raw[offset:offset + 4], "little")


def decode_event_array(raw) -> tuple[int, int, np.ndarray]:
    """Serialized ROS1 dvs_msgs/EventArray -> (height, width, structured events [N] of EVENT_DTYPE)."""
    raw = memoryview(raw)
    off = 12 + 4 + _u32(raw, 12)              # header: seq, stamp (sec, nsec), frame_id (length + bytes)
    if off + 12 > len(raw):
        raise ConversionError("an EventArray message is cut short (header); the bag is damaged")
    height, width, n = _u32(raw, off), _u32(raw, off + 4), _u32(raw, off + 8)
    off += 12
    if off + n * EVENT_DTYPE.itemsize != len(raw):
        raise ConversionError(f"an EventArray message announces {n} events but holds "
                              f"{(len(raw) - off) / EVENT_DTYPE.itemsize:g}; the bag is damaged")
    return height, width, np.frombuffer(raw, EVENT_DTYPE, count=n, offset=off)


def _events_from_message(msg) -> tuple[int, int, np.ndarray]:
    """A deserialized EventArray (rosbags object) -> the same as decode_event_array."""
    ev = np.zeros(len(msg.events), EVENT_DTYPE)
    for i, e in enumerate(msg.events):
        ev[i] = (e.x, e.y, e.ts.sec, e.ts.nanosec, bool(e.polarity))
    return int(msg.height), int(msg.width), ev


def debayer(raw: np.ndarray, cfa: str) -> np.ndarray:
    """A raw 2 x 2 Bayer mosaic uint8 [H, W] (filter ``cfa``, e.g. "RGGB") -> colour uint8 [H, W, 3].

    Bilinear (:func:`evinr_lite.sim.quadbayer.debayer_bilinear`), rounded back to 8 bits.
    """
    from evinr_lite.sim.quadbayer import debayer_bilinear

    rgb = debayer_bilinear(raw, CFA_NAMES[cfa])
    return np.clip(np.round(rgb), 0, 255).astype(np.uint8)


def decode_image(msg, source: str = "image", *, colour: bool = False, cfa: str | None = None) -> np.ndarray:
    """sensor_msgs/Image (rosbags object) -> grey uint8 [H, W], or colour uint8 [H, W, 3] (R, G, B).

    Supports mono8/8UC1, mono16/16UC1, rgb8, bgr8, rgba8, bgra8 and the Bayer mosaics bayer_rggb8,
    bayer_grbg8, bayer_gbrg8, bayer_bggr8 (debayered bilinearly). ``colour``: colour images are
    returned in colour (else converted to grey with ITU-R 709 weights). ``cfa``: the camera's colour
    filter; mono8 images are then raw mosaics with that filter and are debayered.
    """
    h, w, step, enc = int(msg.height), int(msg.width), int(msg.step), msg.encoding.lower()
    data = np.asarray(msg.data, dtype=np.uint8)
    if data.size < h * step:
        raise ConversionError(f"{source}: image data holds {data.size} bytes, expected {h} x {step}")
    rows = data[:h * step].reshape(h, step)
    if enc.startswith("bayer_") and enc.endswith("8") and enc[6:10].upper() in CFA_NAMES:
        img = debayer(rows[:, :w], enc[6:10].upper())
    elif enc in ("mono8", "8uc1") and cfa is not None:
        img = debayer(rows[:, :w], cfa)
    elif enc in ("mono8", "8uc1"):
        img = rows[:, :w]
    elif enc in ("mono16", "16uc1"):
        img = rows[:, :2 * w].copy().view(">u2" if msg.is_bigendian else "<u2").astype(np.uint16)
    elif enc in ("rgb8", "bgr8", "rgba8", "bgra8", "8uc3"):
        c = 4 if "a" in enc[3:] else 3
        img = rows[:, :c * w].reshape(h, w, c)
        if enc.startswith("bgr"):
            img = img[..., [2, 1, 0]]
    else:
        raise ConversionError(f"{source}: image encoding {msg.encoding!r} is not supported (mono8, mono16, rgb8, "
                              "bgr8, bayer_rggb8, ...); pick another image topic with image_topic=")
    if colour and img.ndim == 3 and img.dtype == np.uint8:
        return np.ascontiguousarray(img[..., :3])
    try:
        return _to_grey_uint8(img, source)
    except EventDataError as err:
        raise ConversionError(str(err)) from None


def _pick(connections, msgtype: str, wanted, preferred, kind: str, path) -> object | None:
    found = {c.topic: c for c in connections if c.msgtype == msgtype}
    if wanted:
        for topic in ([wanted] if isinstance(wanted, str) else wanted):
            if topic in found:
                return found[topic]
        if isinstance(wanted, str):
            raise ConversionError(f"{path}: no {kind} topic {wanted!r}; its {msgtype} topics are "
                                  f"{sorted(found) or 'none'}")
    for topic in preferred:
        if topic in found:
            return found[topic]
    if len(found) == 1:
        return next(iter(found.values()))
    if len(found) > 1:
        raise ConversionError(f"{path}: several {kind} topics {sorted(found)}; choose one "
                              f"({'event_topic' if kind == 'event' else 'image_topic'}=...)")
    return None


class _Ordered:
    """Feeds event blocks to the writer in time order, merging a message that overlaps the previous one."""

    def __init__(self, writer_factory):
        self.writer_factory = writer_factory
        self.writer = None
        self.pending = None          # (t, x, y, p) not yet written
        self.merged = 0
        self.unsorted = 0

    def add(self, t, x, y, p):
        if t.size == 0:
            return
        if np.any(np.diff(t) < 0):
            order = np.argsort(t, kind="stable")
            t, x, y, p = t[order], x[order], y[order], p[order]
            self.unsorted += 1
        if self.pending is not None:
            if t[0] < self.pending[0][-1]:   # overlaps the previous message: merge the two
                cat = [np.concatenate([a, b]) for a, b in zip(self.pending, (t, x, y, p))]
                order = np.argsort(cat[0], kind="stable")
                self.pending = tuple(a[order] for a in cat)
                self.merged += 1
                return
            self.flush()
        self.pending = (t, x, y, p)

    def flush(self):
        if self.pending is not None:
            if self.writer is None:
                self.writer = self.writer_factory()
            self.writer.add_events(*self.pending, where="bag events")
            self.pending = None


def convert_bag(path, out, *, sensor_size=None, C: float = 1.0, eval_window=None, dataset: str = "",
                sequence: str | None = None, source: str = "", source_url: str = "",
                event_topic: str | None = None, image_topic=None, progress: bool = True, cfa: str | None = None,
                grey: bool = False) -> Path:
    """Convert a ROS1 bag with dvs_msgs/EventArray events (and sensor_msgs/Image frames) to ``out``.

    Args:
        path: the ``.bag`` file.
        out: canonical ``.h5`` to write (atomically).
        sensor_size: (H, W) expected; the EventArray messages' own height/width win when they
            differ (with a warning), since a few sequences (e.g. CED driving_city_3) differ.
        event_topic: topic of the events; None: /dvs/events, /davis/left/events, or the only one.
        image_topic: topic (or list of topics in order of preference) of the frames; None:
            /dvs/image_raw, /davis/left/image_raw, /dvs/image_color, or the only one.
        cfa: the colour filter of a colour camera ("RGGB" for CED's Color DAVIS346; None: mono),
            stored as the file's ``cfa`` attribute; mono8 frames are then raw mosaics, debayered.
        grey: store grey frames only (colour frames converted with ITU-R 709 weights), the
            layout from before colour was kept; False keeps colour frames in /frames/rgb.
    """
    from rosbags.rosbag1 import Reader, ReaderError
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore
    from tqdm.auto import tqdm

    path = Path(path)
    sequence = sequence or path.stem
    cfa = check_cfa(cfa, ConversionError)
    damaged = (f"the bag is damaged or incomplete (or not a ROS1 bag): delete {path} and run the command "
               "again to download it anew")
    try:
        reader = Reader(path)
        reader.open()
    except (ReaderError, OSError, ValueError) as err:
        raise ConversionError(f"{path}: cannot be opened as a ROS1 bag ({err}); {damaged}") from None
    writer_box: dict = {}
    try:
        ev_conn = _pick(reader.connections, EVENT_ARRAY_TYPE, event_topic, PREFERRED_EVENT_TOPICS, "event", path)
        if ev_conn is None:
            packets = _pick(reader.connections, EVENT_PACKET_TYPE, event_topic, PREFERRED_PACKET_TOPICS, "event", path)
            if packets is not None:
                return _convert_packets(reader, packets, path, out, sensor_size=sensor_size, C=C,
                                        eval_window=eval_window, dataset=dataset, sequence=sequence, source=source,
                                        source_url=source_url, progress=progress)
            topics = sorted(f"{c.topic} ({c.msgtype})" for c in reader.connections)
            raise ConversionError(f"{path}: no dvs_msgs/EventArray or event_camera_msgs/EventPacket topic; the bag "
                                  f"holds {topics}")
        img_conn = _pick(reader.connections, IMAGE_TYPE, image_topic, PREFERRED_IMAGE_TOPICS, "image", path)
        if img_conn is None:
            log.warning("data_fetch: %s: no sensor_msgs/Image topic, so no ground-truth frames", path)
        store = get_typestore(Stores.ROS1_NOETIC)
        fast = ev_conn.digest == EVENT_ARRAY_MD5
        if not fast:
            types = get_types_from_msg(ev_conn.msgdef.data, ev_conn.msgtype)
            store.register({k: v for k, v in types.items() if k not in store.types})
            log.info("data_fetch: %s: EventArray definition differs from dvs_msgs'; decoding with rosbags", path)

        state = {"size": None, "origin": None}
        frames: list[tuple[int, int, np.ndarray]] = []   # (sec, nsec, image) until the writer exists

        def make_writer():
            H, W = state["size"]
            w = CanonicalWriter(out, sensor_size=(H, W), t_origin=float(state["origin"]), dataset=dataset,
                                sequence=sequence, source=source, source_url=source_url, raw_file=path.name,
                                C=C, eval_window=eval_window, converter="data_fetch.convert_bag", cfa=cfa,
                                meta={"event_topic": ev_conn.topic,
                                      "image_topic": img_conn.topic if img_conn is not None else None})
            writer_box["w"] = w
            return w

        ordered = _Ordered(make_writer)

        def drain():
            w_ = writer_box.get("w")
            if w_ is None:
                return
            for sec, nsec, im in frames:
                if im.shape[:2] != tuple(state["size"]):
                    raise ConversionError(f"{path}: frames on {img_conn.topic} are {im.shape[:2]} but the events' "
                                          f"sensor is {tuple(state['size'])} (H, W); pick another image_topic")
                w_.add_frame(im, ((sec - state["origin"]) * NS + nsec) / NS)
            frames.clear()

        conns = [ev_conn] + ([img_conn] if img_conn is not None else [])
        total = sum(c.msgcount for c in conns)
        with tqdm(total=total, unit="msg", desc=f"{sequence}: bag", disable=not progress) as bar:
            for conn, _, raw in reader.messages(connections=conns):
                bar.update(1)
                if conn is ev_conn:
                    if fast:
                        h, w, ev = decode_event_array(raw)
                    else:
                        h, w, ev = _events_from_message(store.deserialize_ros1(raw, conn.msgtype))
                    if ev.size == 0:
                        continue
                    if state["size"] is None:
                        msg_size = (h, w) if h and w else None
                        given = tuple(int(v) for v in sensor_size) if sensor_size is not None else None
                        if msg_size and given and msg_size != given:
                            log.warning("data_fetch: %s: the events report a %dx%d sensor, not the expected %dx%d; "
                                        "using the events' size", path, w, h, given[1], given[0])
                        state["size"] = msg_size or given
                        if state["size"] is None:
                            raise ConversionError(f"{path}: the EventArray messages give no sensor size; pass "
                                                  "sensor_size=(H, W) (--sensor-size H W)")
                        first_sec = int(ev["sec"][0])
                        state["origin"] = first_sec if first_sec >= LARGE_T else 0
                    rel_ns = (ev["sec"].astype(np.int64) - state["origin"]) * NS + ev["nsec"].astype(np.int64)
                    ordered.add(rel_ns / NS, ev["x"], ev["y"], np.where(ev["p"] > 0, 1, -1).astype(np.int8))
                else:
                    msg = store.deserialize_ros1(raw, conn.msgtype)
                    image = decode_image(msg, f"{path}:{conn.topic}", colour=not grey, cfa=cfa)
                    frames.append((int(msg.header.stamp.sec), int(msg.header.stamp.nanosec), image))
                drain()
        ordered.flush()
        writer = writer_box.get("w")
        if writer is None:
            raise ConversionError(f"{path}: the topic {ev_conn.topic} holds no events")
        drain()
        if ordered.merged or ordered.unsorted:
            writer.meta["event_messages_reordered"] = ordered.merged + ordered.unsorted
        writer.meta["n_event_messages"] = ev_conn.msgcount
        return writer.close()
    except (ReaderError, EOFError) as err:
        raise ConversionError(f"{path}: reading failed ({err}); {damaged}") from None
    finally:
        if "w" in writer_box:
            writer_box["w"].abort()
        reader.close()


def _packet_store(conn):
    """A ROS1 typestore that knows ``conn``'s EventPacket definition (the bag's own, else the known one)."""
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC)
    text = conn.msgdef.data if conn.msgdef and conn.msgdef.data else EVENT_PACKET_MSGS[EVENT_PACKET_TYPE]
    store.register({k: v for k, v in get_types_from_msg(text, conn.msgtype).items() if k not in store.types})
    return store


def packets_to_raw(messages, raw: Path, path) -> tuple[int, int, str]:
    """Write the event bytes of EventPacket messages (deserialized, in order) after a Prophesee header into
    ``raw``: the camera's own stream, which the Prophesee reader decodes. Returns (height, width, encoding);
    ConversionError for an encoding the reader cannot decode, a big-endian stream or packets that disagree."""
    first = None
    with open(raw, "wb") as f:
        for msg in messages:
            key = (int(msg.height), int(msg.width), str(msg.encoding))
            if first is None:
                first = key
                H, W, encoding = key
                if encoding not in PACKET_HEADERS:
                    raise ConversionError(f"{path}: event packets in the {encoding!r} encoding; data_fetch decodes "
                                          f"{sorted(PACKET_HEADERS)} (Prophesee cameras); convert others with the "
                                          "camera's own tools to a format evinr-lite reads (docs/commands.md)")
                if not (H and W):
                    raise ConversionError(f"{path}: the event packets give no sensor size (height {H}, width {W})")
                f.write(f"% {PACKET_HEADERS[encoding]};height={H};width={W}\n% geometry {W}x{H}\n% end\n".encode())
            elif key != first:
                raise ConversionError(f"{path}: the event packets change from {first} to {key} (height, width, "
                                      "encoding) within the topic; a topic must hold one camera's stream")
            if msg.is_bigendian:
                raise ConversionError(f"{path}: big-endian event packets are not decoded (Prophesee cameras send "
                                      "little-endian ones)")
            f.write(np.asarray(msg.events, np.uint8).tobytes())
    if first is None:
        raise ConversionError(f"{path}: the event packet topic holds no messages")
    return first


def _open_stream(raw: Path, path: Path, encoding: str):
    """The Prophesee reader's source over the packets' stream ``raw``; ConversionError naming the bag when
    the stream cannot be decoded."""
    from evinr_lite.io.formats.prophesee import open_prophesee

    try:
        return open_prophesee(raw)
    except EventDataError as err:
        why = str(err).replace(f"{raw}: ", "")          # the temporary file is not the user's to look for
        raise ConversionError(f"{path}: the {encoding} stream in the event packets could not be decoded ({why}); "
                              "the bag is damaged or the packets are not in order") from None


def _convert_packets(reader, conn, path: Path, out, *, sensor_size, C, eval_window, dataset, sequence, source,
                     source_url, progress) -> Path:
    """:func:`convert_bag` for a topic of event_camera_msgs/EventPacket: the packets' bytes into a temporary
    ``.raw`` beside ``out``, decoded by the Prophesee reader a second at a time into the canonical file."""
    from tqdm.auto import tqdm

    store = _packet_store(conn)
    others = sorted(c.topic for c in reader.connections if c.msgtype == IMAGE_TYPE)
    if others:
        log.warning("data_fetch: %s: image topics %s are not stored: the event packets carry the camera's own "
                    "clock, not the bag's", path, others)
    raw = Path(out).parent / f".{Path(out).name}.packets.raw"
    try:
        with tqdm(total=conn.msgcount, unit="msg", desc=f"{sequence}: packets", disable=not progress) as bar:
            def messages():
                for _, _, data in reader.messages(connections=[conn]):
                    bar.update(1)
                    yield store.deserialize_ros1(data, conn.msgtype)
            H, W, encoding = packets_to_raw(messages(), raw, path)
        if sensor_size is not None and tuple(int(v) for v in sensor_size) != (H, W):
            log.warning("data_fetch: %s: the packets report a %dx%d sensor, not the expected %dx%d; using the "
                        "packets' size", path, W, H, int(sensor_size[1]), int(sensor_size[0]))
        meta = {"event_topic": conn.topic, "image_topic": None, "packet_encoding": encoding,
                "clock": "the camera's (microseconds), not the bag's"}
        with _open_stream(raw, path, encoding) as stream, \
                CanonicalWriter(out, sensor_size=(H, W), t_origin=float(stream.t_origin), dataset=dataset,
                                sequence=sequence, source=source, source_url=source_url, raw_file=path.name, C=C,
                                eval_window=eval_window, converter="data_fetch.convert_bag", meta=meta) as writer:
            t0, t1 = stream.t_span
            edges = np.append(np.arange(t0, t1, 1.0), np.nextafter(t1, np.inf))   # a second at a time, t1 included
            for a, b in zip(edges[:-1].tolist(), edges[1:].tolist()):
                ev = stream.events(a, b)
                writer.add_events(ev.t, ev.x, ev.y, ev.p, where="packet events")
            writer.meta["n_event_messages"] = conn.msgcount
        return writer.out
    finally:
        raw.unlink(missing_ok=True)
