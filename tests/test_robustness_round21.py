"""Round 21 of the bad-input table (tests/test_robustness*.py): the format readers called by name, the format
registry's and the loader's helpers, the canonical file's index helpers and the colour filter's phase check, which no
bad-input test had named (the probe of round 21 listed them from the subpackages' ``__all__``). Each bad input now ends
in the kit's error naming the argument and the fix, never a Python/numpy error from inside or a silent wrong result.

Functions: io.formats (``read_events_npy``, ``read_events_txt``, ``read_events_csv`` / ``read_csv``, ``read_txt``,
``read_npy``, ``read_h5``, ``read_aedat3`` / ``aedat3_header``, ``read_aedat4``, ``read_prophesee`` /
``prophesee_header``, ``read_mvsec``, ``read_dsec``, ``read_evreal_folder``, ``read_ijrr_folder``,
``read_frames_ijrr``, ``detect_format``, ``sniff_format``, ``get_format``), io.load (``format_info``,
``reader_options``, ``check_sensor_size_matches``), io.canonical (``repair_frame_times``, ``find_time_index``) and
core.cfa (``check_phase``).
"""
import collections
import os
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
import torch

from evinr_lite.core import cfa
from evinr_lite.core.guard import InputError
from evinr_lite.io import canonical, load
from evinr_lite.io.formats import (aedat3, aedat4, csv_events, dsec, evreal, hqf, ijrr, mvsec, npy, prophesee,
                                   registry, txt)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_fuzz_readers import _fixtures  # noqa: E402

H, W = 12, 16


@pytest.fixture(scope="module")
def fx(tmp_path_factory):
    root = tmp_path_factory.mktemp("r21")
    files = {k: v[0] / v[1] for k, v in _fixtures(root).items()}
    (root / "empty.bin").write_bytes(b"")
    (root / "afolder").mkdir()
    files.update(empty=root / "empty.bin", folder=root / "afolder", missing=root / "missing.xyz")
    return files


PATH_READERS = {"read_events_npy": npy.read_events_npy, "read_events_txt": txt.read_events_txt,
                "read_events_csv": csv_events.read_events_csv, "read_csv": csv_events.read_csv,
                "read_txt": txt.read_txt, "read_npy": npy.read_npy, "read_h5": hqf.read_h5,
                "read_aedat3": aedat3.read_aedat3, "read_aedat4": aedat4.read_aedat4,
                "read_prophesee": prophesee.read_prophesee, "read_mvsec": mvsec.read_mvsec, "read_dsec": dsec.read_dsec,
                "detect_format": registry.detect_format, "sniff_format": registry.sniff_format,
                "aedat3_header": aedat3.aedat3_header, "prophesee_header": prophesee.prophesee_header}
FOLDER_READERS = {"read_evreal_folder": evreal.read_evreal_folder, "read_ijrr_folder": ijrr.read_ijrr_folder,
                  "read_frames_ijrr": ijrr.read_frames_ijrr}
BAD_PATHS = {"None": None, "int": 5, "list": ["a"], "array": np.array(["a"])}

# (reader, fixture, keyword, value, the message's fragment)
SIZE_READERS = {"read_events_txt": (txt.read_events_txt, "txt"), "read_events_csv": (csv_events.read_events_csv, "csv"),
                "read_csv": (csv_events.read_csv, "csv"), "read_aedat3": (aedat3.read_aedat3, "aedat3"),
                "read_prophesee": (prophesee.read_prophesee, "prophesee_evt21")}
BAD_SIZES = {"5": 5, "text": "a", "0d": np.array(3), "NaN": (np.nan, 16), "fraction": (12.5, 16)}
SIZE_MATCH = r"sensor_size must be \(H, W\), two positive whole numbers"


@pytest.mark.parametrize("reader", list(PATH_READERS))
@pytest.mark.parametrize("bad", list(BAD_PATHS))
def test_a_path_that_is_no_path_is_named(reader, bad):
    with pytest.raises(InputError, match=r"path= must be the (recording's|event) (file|file or folder) \(a str or "
                                         r"Path\), got"):
        PATH_READERS[reader](BAD_PATHS[bad])


@pytest.mark.parametrize("reader", list(FOLDER_READERS))
@pytest.mark.parametrize("bad", list(BAD_PATHS))
def test_a_folder_that_is_no_path_is_named(reader, bad):
    with pytest.raises(InputError, match=r"folder= must be the recording's folder \(a str or Path\), got"):
        FOLDER_READERS[reader](BAD_PATHS[bad])


@pytest.mark.parametrize("reader", ["sniff_format", "aedat3_header", "prophesee_header"])
@pytest.mark.parametrize("where", ["folder", "missing"])
def test_a_header_helper_names_a_folder_or_a_missing_file(reader, where, fx):
    with pytest.raises(InputError, match=r"is a folder, not a file; pass the file|no such file: .*check the path"):
        PATH_READERS[reader](fx[where])


@pytest.mark.parametrize("reader", list(SIZE_READERS))
@pytest.mark.parametrize("bad", list(BAD_SIZES))
def test_a_sensor_size_that_is_no_h_w_is_named(reader, bad, fx):
    fn, key = SIZE_READERS[reader]
    with pytest.raises(InputError, match=SIZE_MATCH):
        fn(fx[key], sensor_size=BAD_SIZES[bad])


@pytest.mark.parametrize("key", ["h5", "mvsec", "ijrr"])
def test_a_fractional_sensor_size_is_refused_where_the_file_declares_one(key, fx):
    fn = {"h5": hqf.read_h5, "mvsec": mvsec.read_mvsec, "ijrr": ijrr.read_ijrr_folder}[key]
    with pytest.raises(InputError, match=SIZE_MATCH):
        fn(fx[key], sensor_size=(12.5, 16))


@pytest.mark.parametrize("reader", ["read_csv", "read_txt", "read_npy"])
def test_a_recording_reader_names_meta_as_its_own(reader, fx):
    fn, key = {"read_csv": (csv_events.read_csv, "csv"), "read_txt": (txt.read_txt, "txt"),
               "read_npy": (npy.read_npy, "npy")}[reader]
    with pytest.raises(InputError, match=rf"{reader}: meta= is not an option here; the Recording's .meta"):
        fn(fx[key], sensor_size=(H, W), meta={})


@pytest.mark.parametrize("reader", ["read_events_txt", "read_events_csv", "read_events_npy", "read_frames_ijrr"])
@pytest.mark.parametrize("meta", [5, "a", [1]])
def test_a_meta_that_is_no_dict_is_named(reader, meta, fx):
    fn, key = {"read_events_txt": (txt.read_events_txt, "txt"), "read_events_csv": (csv_events.read_events_csv, "csv"),
               "read_events_npy": (npy.read_events_npy, "npy"), "read_frames_ijrr": (ijrr.read_frames_ijrr, "ijrr")}[reader]
    kw = {} if reader == "read_frames_ijrr" else dict(sensor_size=(H, W))
    with pytest.raises(InputError, match=r"meta= must be MutableMapping, got"):
        fn(fx[key], meta=meta, **kw)


CASES = {
    "read_frames_ijrr-span-text": (lambda f: ijrr.read_frames_ijrr(f["ijrr"], events_span="a"),
                                   r"events_span= must be \(t_start, t_end\) in seconds"),
    "read_frames_ijrr-span-5": (lambda f: ijrr.read_frames_ijrr(f["ijrr"], events_span=5), r"events_span= must be"),
    "read_frames_ijrr-span-reversed": (lambda f: ijrr.read_frames_ijrr(f["ijrr"], events_span=(1.0, 0.0)),
                                       r"events_span: the span \[1.0, 0.0\] s is reversed"),
    "read_frames_ijrr-span-NaN": (lambda f: ijrr.read_frames_ijrr(f["ijrr"], events_span=(np.nan, 1.0)),
                                  r"events_span: t_start"),
    "get_format-list": (lambda f: registry.get_format(["txt"]), r"get_format: name= must be a format's name \(text\)"),
    "get_format-0d": (lambda f: registry.get_format(np.array("txt")), r"name= must be a format's name .*known: "),
    "format_info-None": (lambda f: load.format_info(None), r"format_info: info= must be the dict describe_recording"),
    "format_info-text": (lambda f: load.format_info("a"), r"info= must be the dict describe_recording"),
    "format_info-list": (lambda f: load.format_info([1]), r"info= must be the dict describe_recording"),
    "format_info-empty": (lambda f: load.format_info({}), r"it has no 'format', 'path', 'sensor_size', 'n_events'"),
    "reader_options-None": (lambda f: load.reader_options(None, f["txt"]), r"fmt= must be FileFormat, got NoneType"),
    "reader_options-name": (lambda f: load.reader_options("txt", f["txt"]), r"fmt= must be FileFormat, got str"),
    "check_sensor_size_matches-found-None": (lambda f: load.check_sensor_size_matches(f["txt"], None, (H, W)),
                                             r"found= \(the recording's sensor size\) must be \(H, W\)"),
    "check_sensor_size_matches-5": (lambda f: load.check_sensor_size_matches(f["txt"], (H, W), 5), SIZE_MATCH),
    "check_sensor_size_matches-text": (lambda f: load.check_sensor_size_matches(f["txt"], (H, W), "a"), SIZE_MATCH),
    "check_sensor_size_matches-NaN": (lambda f: load.check_sensor_size_matches(f["txt"], (H, W), (np.nan, 16)),
                                      SIZE_MATCH),
    "check_sensor_size_matches-fraction": (lambda f: load.check_sensor_size_matches(f["txt"], (H, W), (12.5, 16)),
                                           SIZE_MATCH),
    "repair_frame_times-None": (lambda f: canonical.repair_frame_times(None), r"t= must be seconds"),
    "repair_frame_times-text": (lambda f: canonical.repair_frame_times("a"), r"t= must be seconds"),
    "repair_frame_times-NaN": (lambda f: canonical.repair_frame_times([1.0, np.nan]), r"t= must be finite seconds"),
    "repair_frame_times-inf": (lambda f: canonical.repair_frame_times([1.0, np.inf]), r"t= must be finite seconds"),
    "repair_frame_times-2d": (lambda f: canonical.repair_frame_times([[1, 2], [3, 4]]), r"t= must be a 1-D array"),
    "repair_frame_times-bool": (lambda f: canonical.repair_frame_times(np.array([True, False])), r"t= must be seconds"),
    "find_time_index-None": (lambda f: canonical.find_time_index(None, 0.0), r"f= must be an open canonical file"),
    "find_time_index-5": (lambda f: canonical.find_time_index(5, 0.0), r"f= must be an open canonical file"),
    "find_time_index-text": (lambda f: _index(f, "a"), r"value= must be a time in seconds .*not NaN"),
    "find_time_index-NaN": (lambda f: _index(f, np.nan), r"value= must be a time in seconds"),
    "find_time_index-bool": (lambda f: _index(f, True), r"value= must be a time in seconds"),
    "find_time_index-list": (lambda f: _index(f, [0.0]), r"value= must be a time in seconds"),
    "find_time_index-array": (lambda f: _index(f, np.array([0.0, 1.0])), r"value= must be a time in seconds"),
    "find_time_index-side-x": (lambda f: _index(f, 0.0, "x"), r"side= must be 'left' .* or 'right'"),
    "find_time_index-side-None": (lambda f: _index(f, 0.0, None), r"side= must be 'left'"),
    "prophesee_header-limit-text": (lambda f: prophesee.prophesee_header(f["prophesee_evt21"], "a"), r"limit"),
    "prophesee_header-limit-0": (lambda f: prophesee.prophesee_header(f["prophesee_evt21"], 0), r"limit"),
    "check_phase-block-None": (lambda f: cfa.check_phase((0, 0), None), r"block must be a whole number in \[1, 8\]"),
    "check_phase-block-fraction": (lambda f: cfa.check_phase((0, 0), 2.5), r"block must be a whole number"),
    "check_phase-block-0": (lambda f: cfa.check_phase((0, 0), 0), r"block must be a whole number"),
}


def _index(f, value, side="left"):
    with h5py.File(f["canonical"], "r") as h:
        return canonical.find_time_index(h, value, side)


@pytest.mark.parametrize("case", list(CASES))
def test_a_bad_argument_is_named_with_its_fix(case, fx):
    fn, match = CASES[case]
    with pytest.raises(InputError, match=match):
        fn(fx)


# ---- guards: good inputs give what they gave -------------------------------------------------------------------

def test_the_readers_read_good_files_as_before_guard(fx):
    for fn, key in ((txt.read_events_txt, "txt"), (csv_events.read_events_csv, "csv")):
        ev = fn(fx[key])
        assert len(ev) == 60 and ev.sensor_size == (H, W)
        assert len(fn(str(fx[key]), sensor_size=torch.tensor([H, W]))) == 60   # a tensor (H, W), as before
        assert fn(fx[key], sensor_size=(12.0, 16.0)).sensor_size == (H, W)   # whole floats, as before
    meta = {}
    npy.read_events_npy(fx["npy"], sensor_size=(H, W), meta=meta)
    assert len(npy.read_npy(fx["npy"], sensor_size=(H, W)).events) == 60
    assert len(csv_events.read_csv(fx["csv"]).events) == 60 and len(txt.read_txt(fx["txt"]).events) == 60
    assert len(hqf.read_h5(fx["h5"], sensor_size=np.array([H, W])).events) == 60
    t0 = 1_468_939_993.0
    assert ijrr.read_frames_ijrr(fx["ijrr"], t0, events_span=(0.0, 0.05)).images.shape == (2, H, W)
    assert ijrr.read_frames_ijrr(fx["ijrr"], events_span=(0.0, 0.0)).images.shape == (2, H, W)   # one instant


def test_the_helpers_answer_as_before_guard(fx):
    assert registry.detect_format(fx["txt"]) == "txt" and registry.detect_format(str(fx["csv"])) == "csv"
    assert registry.detect_format(bytes(fx["txt"])) == "txt"
    assert registry.sniff_format(fx["empty"]) is None and registry.sniff_format(fx["h5"]) == "hdf5"
    assert prophesee.prophesee_header(fx["empty"]) == [] and prophesee.prophesee_header(fx["prophesee_evt21"])
    assert aedat3.aedat3_header(fx["aedat3"])[1] > 0
    assert registry.get_format("txt").name == "txt"
    assert load.reader_options(registry.get_format("txt"), fx["txt"], (H, W)) == {"sensor_size": (H, W)}
    assert load.check_sensor_size_matches(fx["txt"], (H, W), np.array([H, W])) is None
    assert load.check_sensor_size_matches(fx["txt"], (H, W), None) is None
    t, fixed = canonical.repair_frame_times([0.0, 0.1, 0.5, 0.2, 0.3])
    assert t.tolist() == [0.0, 0.1, 0.15000000000000002, 0.2, 0.3] and fixed == [2]
    assert canonical.repair_frame_times([3.0, 1.0, 2.0])[1] == [] and canonical.repair_frame_times([])[0].size == 0
    assert canonical.repair_frame_times(torch.tensor([1.0, 2.0]))[0].tolist() == [1.0, 2.0]
    with h5py.File(fx["canonical"], "r") as h:
        n = h["events/t"].shape[0]
        assert 0 < canonical.find_time_index(h, 0.01) < n and canonical.find_time_index(h, 1e9) == n
        t = h["events/t"][()]
        assert canonical.find_time_index(h, np.float32(0.01)) == np.searchsorted(t, np.float32(0.01))
        assert canonical.find_time_index(h, __import__("decimal").Decimal("0.01")) == np.searchsorted(t, 0.01)
        assert canonical.find_time_index(h, 0, "right") == np.searchsorted(t, 0.0, "right")
    assert cfa.check_phase((-1, 0), 2) == (3, 0) and cfa.check_phase((1.0, 0), 2.0) == (1, 0)
    assert cfa.check_phase((1, 1), np.array(1)) == (1, 1)


# ---- the review's findings (round 21's review): what main took is taken again, the gaps in the checks closed -------

def test_find_time_index_takes_inf_as_before_and_every_event_review(fx):
    with h5py.File(fx["canonical"], "r") as h:
        n = h["events/t"].shape[0]
        for side in ("left", "right"):
            assert canonical.find_time_index(h, -np.inf, side) == 0 and canonical.find_time_index(h, np.inf, side) == n
            assert canonical.find_time_index(h, float("-inf"), side) == 0
            assert canonical.find_time_index(h, np.float32(np.inf), side) == n


REVIEW_CASES = {
    "find_time_index-NaN-float": (lambda f: _index(f, float("nan")), r"value= must be a time in seconds .*not NaN"),
    "find_time_index-side-array": (lambda f: _index(f, 0.01, np.array(["left", "right"])), r"side= must be 'left'"),
    "find_time_index-group-events": (lambda f: _in_file(f, lambda h: canonical.find_time_index(h["events"], 0.01)),
                                     r"f= must be an open canonical file with events/t"),
    "find_time_index-hdf5-without-events": (lambda f: _in_file(f, lambda h: canonical.find_time_index(h, 0.01), "h5"),
                                            r"f= must be an open canonical file with events/t"),
    "format_info-no-rate": (lambda f: load.format_info({"format": "txt", "path": "p", "sensor_size": [H, W],
                                                        "n_events": 60, "n_frames": 0}),
                            r"describe_recording\(rec\) .*it has no 'event_rate_per_s', 't_first'"),
    "format_info-no-n_frames": (lambda f: load.format_info({"format": "txt", "path": "p", "sensor_size": [H, W],
                                                            "n_events": 0}), r"it has no 'n_frames'"),
    "format_info-no-frame_size": (lambda f: load.format_info({"format": "txt", "path": "p", "sensor_size": [H, W],
                                                              "n_events": 0, "n_frames": 2}),
                                  r"it has no 'frame_size'"),
    "check_sensor_size_matches-found-5": (lambda f: load.check_sensor_size_matches(f["txt"], 5, (H, W)),
                                          r"check_sensor_size_matches: found= .* got 5"),
    "read_frames_ijrr-span-dict": (lambda f: ijrr.read_frames_ijrr(f["ijrr"], events_span={"a": 1, "b": 2}),
                                   r"events_span= must be \(t_start, t_end\) .*not a dict or set"),
    "read_frames_ijrr-span-set": (lambda f: ijrr.read_frames_ijrr(f["ijrr"], events_span={0.0, 0.05}),
                                  r"events_span= must be \(t_start, t_end\) .*not a dict or set"),
}


def _in_file(f, fn, key="canonical"):
    with h5py.File(f[key], "r") as h:
        return fn(h)


@pytest.mark.parametrize("case", list(REVIEW_CASES))
def test_a_bad_argument_is_named_review(case, fx):
    fn, match = REVIEW_CASES[case]
    with pytest.raises(InputError, match=match):
        fn(fx)


def test_format_info_takes_what_describe_recording_returns_review(fx):
    info = load.describe_recording(txt.read_txt(fx["txt"]))
    assert load.format_info(info) == load.format_info(dict(info))
    assert "events        60" in load.format_info(collections.OrderedDict(info))


def test_check_sensor_size_matches_blames_sensor_size_when_it_is_wrong_review(fx):
    with pytest.raises(InputError, match=r"^sensor_size must be \(H, W\)"):
        load.check_sensor_size_matches(fx["txt"], (H, W), (np.nan, 16))
    with pytest.raises(InputError, match=r"the recording's sensor is \(H, W\) = \(12, 16\)"):
        load.check_sensor_size_matches(fx["txt"], [H, W], (16, 12))


@pytest.mark.skipif(not os.path.exists(os.devnull) or os.devnull != "/dev/null", reason="needs /dev/null")
def test_a_device_is_read_as_on_main_review(fx):
    assert registry.sniff_format("/dev/null") is None and registry.sniff_format(Path("/dev/null")) is None
    assert prophesee.prophesee_header("/dev/null") == []
    with pytest.raises(InputError, match=r"not an AEDAT 3.1 file"):   # as on main: no header in the device
        aedat3.aedat3_header("/dev/null")
    for fn in (registry.sniff_format, prophesee.prophesee_header, aedat3.aedat3_header):
        with pytest.raises(InputError, match=r"is a folder, not a file"):
            fn(fx["folder"])
        with pytest.raises(InputError, match=r"no such file"):
            fn(fx["missing"])


@pytest.mark.parametrize("kind", ["UserDict", "OrderedDict", "defaultdict"])
def test_meta_may_be_any_mutable_mapping_review(kind, fx):
    meta = {"UserDict": collections.UserDict, "OrderedDict": collections.OrderedDict,
            "defaultdict": lambda: collections.defaultdict(list)}[kind]()
    assert len(txt.read_events_txt(fx["txt"], meta=meta)) == 60
    assert len(csv_events.read_events_csv(fx["csv"], meta=meta)) == 60
    assert len(npy.read_events_npy(fx["npy"], sensor_size=(H, W), meta=meta)) == 60
    assert ijrr.read_frames_ijrr(fx["ijrr"], meta=meta).images.shape == (2, H, W)
