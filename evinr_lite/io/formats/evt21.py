"""Prophesee EVT 2.1 ``.raw`` files, decoded here with numpy (faery 0.7.1 does not decode EVT 2.1).

EVT 2.1 is the default output of Prophesee's GenX320 sensor and one of the IMX636's. It is a stream of
64-bit words after the file's ``%`` header; the 4 top bits of a word are its type (Prophesee's
"EVT 2.1 Format" page):

    EVT_NEG 0x0, EVT_POS 0x1   [59:54] the timestamp's 6 low bits, [53:43] x (a multiple of 32),
                               [42:32] y, [31:0] a mask: bit n set is one event at (x + n, y)
    EVT_TIME_HIGH 0x8          [59:32] the timestamp's bits 6..33 (microseconds), [31:0] zero
    EXT_TRIGGER 0xA, OTHERS 0xE, CONTINUED 0xF: no change-detection events; skipped

Timestamps are 34-bit microseconds (they wrap after 4 h 46 min, which is not undone here); words before
the first EVT_TIME_HIGH have no time and are dropped, as Prophesee's own decoder does. The bytes are
little-endian, but the two sensors order a word's halves differently: the GenX320 writes the 64-bit
word at once, the IMX636 its upper 32-bit half first. A file does not say which, so the order is read
off the data (:func:`word_order`): under the wrong one, time words turn into events and events into
words of reserved types.
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ...core.events import EventDataError

__all__ = ["is_evt21", "header_sensor_size", "word_order", "decode_words", "evt21_packets",
           "EVENT_DTYPE", "ORDERS"]

EVENT_DTYPE = np.dtype([("t", "<u8"), ("x", "<u2"), ("y", "<u2"), ("on", "?")])
ORDERS = ("whole", "halves")      # GenX320: the 64-bit word at once; IMX636: its upper 32-bit half first
KNOWN_TYPES = (0x0, 0x1, 0x8, 0xA, 0xE, 0xF)
SAMPLE_WORDS = 1 << 16            # words read to tell the order
CHUNK_WORDS = 1 << 20             # words decoded at a time (8 MB)


def is_evt21(header: list[str]) -> bool:
    """Whether a ``%`` header (lines without the '% ') names EVT 2.1 (``evt 2.1`` or ``format EVT21...``)."""
    for line in (h.strip().lower() for h in header):
        if line == "evt 2.1" or line.startswith("evt 2.1 ") or re.match(r"format\s+evt\s*2\.?1\b", line):
            return True
    return False


def header_sensor_size(header: list[str]):
    """(H, W) from a ``%`` header (``format ...;width=W;height=H``, ``geometry WxH`` or ``Width W`` /
    ``Height H`` lines), or None when it gives none."""
    width = height = None
    for line in header:
        low = line.strip().lower()
        m = re.match(r"geometry\s+([0-9]+)\s*x\s*([0-9]+)", low)
        if m:
            return int(m.group(2)), int(m.group(1))
        if low.startswith("format"):
            fields = dict(f.split("=", 1) for f in low.split(";")[1:] if "=" in f)
            w, h = (re.fullmatch(r"\s*([0-9]+)\s*", fields.get(k, "")) for k in ("width", "height"))
            if w and h:
                return int(h.group(1)), int(w.group(1))
        m = re.match(r"(width|height)\s+([0-9]+)$", low)
        if m:
            width, height = (int(m.group(2)), height) if m.group(1) == "width" else (width, int(m.group(2)))
    return (height, width) if width and height else None


def _as_words(raw: np.ndarray, order: str) -> np.ndarray:
    """uint64 words as the format defines them, from little-endian uint64 values read in ``order``."""
    return raw if order == "whole" else (raw << np.uint64(32)) | (raw >> np.uint64(32))


def _plausible(words: np.ndarray, sensor_size) -> tuple[float, int, bool]:
    """(share of words that fit the format, time words, whether the times never go back)."""
    kind = words >> np.uint64(60)
    ok = np.isin(kind, KNOWN_TYPES)
    time = kind == 0x8
    ok[time] &= (words[time] & np.uint64(0xFFFFFFFF)) == 0          # a time word's low half is zero
    cd = kind <= 0x1
    x = (words[cd] >> np.uint64(43)) & np.uint64(0x7FF)
    y = (words[cd] >> np.uint64(32)) & np.uint64(0x7FF)
    fits = (x % np.uint64(32) == 0) & ((words[cd] & np.uint64(0xFFFFFFFF)) != 0)
    if sensor_size is not None:
        fits &= (y < np.uint64(sensor_size[0])) & (x < np.uint64(sensor_size[1]))
    ok[cd] &= fits
    high = (words[time] >> np.uint64(32)) & np.uint64(0xFFFFFFF)
    return float(ok.mean()) if len(ok) else 0.0, int(time.sum()), bool(np.all(np.diff(high.astype(np.int64)) >= 0))


def word_order(path: Path, offset: int, sensor_size=None) -> str:
    """"whole" (GenX320) or "halves" (IMX636): the order under which the file's first words are EVT 2.1
    (every word of a known type, time words with a zero low half and times that never go back, event
    words with x a multiple of 32 inside the sensor and at least one event); an error when neither or
    both fit."""
    raw = np.fromfile(path, dtype="<u8", count=SAMPLE_WORDS, offset=offset)
    if len(raw) == 0:
        raise EventDataError(f"{path}: an EVT 2.1 file with no event words after its header: the recording "
                             "stopped before any event, or the file was cut short; record or copy it again")
    fits = []
    for order in ORDERS:
        share, n_time, forward = _plausible(_as_words(raw, order), sensor_size)
        if share >= 0.999 and n_time > 0 and forward:
            fits.append(order)
    if len(fits) != 1:
        why = "under neither word order" if not fits else "under both word orders alike, so the order is unknown"
        raise EventDataError(f"{path}: its header says EVT 2.1 but its first {len(raw)} words fit EVT 2.1 {why} "
                             "(GenX320: whole 64-bit words; IMX636: upper half first); if it was written in "
                             "another encoding, convert it with Metavision's metavision_file_to_dat, or check that "
                             "the file is complete")
    return fits[0]


def decode_words(words: np.ndarray, time_high: int | None) -> tuple[np.ndarray, int | None]:
    """The change-detection events of ``words`` (uint64, already in the format's order) as a packet
    (EVENT_DTYPE: t in microseconds, x, y, on), in word order and within a word by x; and the last time
    word's value, carried into the next call (None: none seen yet, so events before it are dropped)."""
    kind = words >> np.uint64(60)
    is_time = kind == 0x8
    idx = np.where(is_time, np.arange(len(words)), -1)
    np.maximum.accumulate(idx, out=idx)                              # each word's last time word
    values = (words >> np.uint64(32)) & np.uint64(0xFFFFFFF)
    start = np.uint64(time_high if time_high is not None else 0)
    high = np.where(idx >= 0, values[np.maximum(idx, 0)], start)
    cd = (kind <= 0x1) & ((idx >= 0) | (time_high is not None))
    w, high = words[cd], high[cd]
    row, n = _set_bits(w & np.uint64(0xFFFFFFFF))
    out = np.empty(len(row), EVENT_DTYPE)
    out["t"] = (high[row] << np.uint64(6)) | ((w[row] >> np.uint64(54)) & np.uint64(0x3F))
    out["x"] = ((w[row] >> np.uint64(43)) & np.uint64(0x7FF)).astype(np.uint16) + n
    out["y"] = ((w[row] >> np.uint64(32)) & np.uint64(0x7FF)).astype(np.uint16)
    out["on"] = (w[row] >> np.uint64(60)) == 1
    last = int(values[idx[-1]]) if len(idx) and idx[-1] >= 0 else time_high
    return out, last


def _set_bits(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(row, bit) of every set bit of ``mask`` (uint64 [N]), by row and within a row by bit: the lowest set
    bit of every word still holding one, taken off in turn (a pass per bit of the fullest word; most words
    of a recording hold one or two)."""
    counts = np.bitwise_count(mask).astype(np.int64)
    first = np.cumsum(counts) - counts                    # each row's first place in the output
    row = np.empty(int(counts.sum()), np.int64)
    bit = np.empty(len(row), np.uint16)
    left = mask.copy()
    active = np.flatnonzero(left)
    k = 0
    while active.size:
        m = left[active]
        low = m & (~m + np.uint64(1))                      # the lowest set bit
        row[first[active] + k] = active
        bit[first[active] + k] = np.bitwise_count(low - np.uint64(1))
        left[active] = m ^ low
        active = active[left[active] != 0]
        k += 1
    return row, bit


def evt21_packets(path: Path, offset: int, order: str, chunk_words: int = CHUNK_WORDS):
    """Yield the file's events a chunk of words at a time (packets as :func:`decode_words` gives them)."""
    size = Path(path).stat().st_size - offset
    if size % 8:
        raise EventDataError(f"{path}: the EVT 2.1 data is {size} bytes, not a whole number of 64-bit words (a "
                             "truncated copy?); copy the file again")
    time_high = None
    for start in range(0, size // 8, chunk_words):
        raw = np.fromfile(path, dtype="<u8", count=chunk_words, offset=offset + 8 * start)
        packet, time_high = decode_words(_as_words(raw, order), time_high)
        if len(packet):
            yield packet
