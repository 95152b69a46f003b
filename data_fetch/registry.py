"""What data_fetch knows about each dataset: sequences, where the raw files live, sensor sizes, C,
evaluation windows and checksums.

Evaluation windows are in seconds after the sequence's zero, which is (as in EVREAL's conversion)
the earliest event or frame timestamp; the converter turns them into times on the canonical file's
clock. ``None`` means the whole sequence is scored.

Checksums: a checksum is pinned only where a published one is known (MVSEC bags: the md5 sums
that the Tonic library's MVSEC loader publishes for the same files). For IJRR zips, HQF bags and
CED archives no published checksum is known, so ``known_hash`` is None: the download is not
verified, and pooch logs the file's sha256 so a user can pin it.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

__all__ = ["Dataset", "Sequence", "DATASETS", "get_dataset", "get_sequence", "sequence_name", "WeightFile", "WEIGHTS",
           "get_weight_set"]

IJRR_BASE = "https://rpg.ifi.uzh.ch/datasets/davis/"
HQF_FOLDER = "https://drive.google.com/drive/folders/18Xdr6pxJX0ZXTrXW9tK0hC3ZpmKDIt6_"
MVSEC_BASE = "http://visiondata.cis.upenn.edu/mvsec/"
CED_BASE = "http://rpg.ifi.uzh.ch/CED/datasets/"

DAVIS240 = (180, 240)   # (H, W)
DAVIS346 = (260, 346)


@dataclass(frozen=True)
class Sequence:
    """One sequence of a dataset.

    Attributes:
        name: the sequence name used on the command line.
        raw_file: file name of the raw download in ``<cache>/raw/<dataset>/``.
        url: where to download it (None: the dataset's method decides, e.g. a Drive folder).
        known_hash: pooch-style checksum ("sha256:...", "md5:...") or None when none is published.
        eval_window: (start, end) seconds after the sequence's zero, or None for the whole sequence.
        archive_member: for files inside an archive (CED), the member's base name.
        evaluation: True for the sequences of the published evaluation protocol.
    """

    name: str
    raw_file: str
    url: str | None = None
    known_hash: str | None = None
    eval_window: tuple[float, float] | None = None
    archive_member: str | None = None
    evaluation: bool = True


@dataclass(frozen=True)
class Dataset:
    """A dataset: how its files are obtained and what every sequence shares."""

    name: str
    title: str
    method: str                  # "http" (one URL per file), "gdrive" (public Drive folder), "manual"
    sensor_size: tuple[int, int]  # (H, W) of the events
    C: float                     # contrast threshold the paper uses for it
    raw_format: str              # "ijrr-zip", "rosbag", "ced-zip", "manual"
    homepage: str
    sequences: dict[str, Sequence] = field(default_factory=dict)
    event_topic: str | None = None
    image_topics: tuple[str, ...] = ()
    note: str = ""
    url_pattern: str | None = None   # for names not in `sequences` (IJRR): "{name}" is replaced
    citation: str = ""
    cfa: str | None = None           # colour filter of a colour sensor (2 x 2 Bayer, e.g. "RGGB"); None: mono

    def sequence(self, name: str) -> Sequence:
        return get_sequence(self.name, name)


def _ijrr() -> Dataset:
    windows = {
        "calibration": (5.0, 20.0), "boxes_6dof": (5.0, 20.0), "dynamic_6dof": (5.0, 20.0),
        "office_zigzag": (5.0, 12.0), "poster_6dof": (5.0, 20.0), "shapes_6dof": (5.0, 20.0),
        "slider_depth": (1.0, 2.5),
    }
    seqs = {n: Sequence(n, f"{n}.zip", IJRR_BASE + f"{n}.zip", None, w) for n, w in windows.items()}
    return Dataset(
        "ijrr", "IJRR / Event Camera Dataset (ECD), DAVIS240C", "http", DAVIS240, 1.0, "ijrr-zip",
        "https://rpg.ifi.uzh.ch/davis_data.html", seqs,
        note="text zips (events.txt, images.txt, images/, calib.txt); the same sequences exist as "
             ".bag files at the same address, which `convert` also reads",
        url_pattern=IJRR_BASE + "{name}.zip",
        citation="Mueggler et al., The event-camera dataset and simulator, IJRR 2017",
    )


# Every sequence of the Event Camera Dataset's text release (https://rpg.ifi.uzh.ch/davis_data.html); names
# outside this list are refused before any download.
ECD_NAMES = ("shapes_rotation", "shapes_translation", "shapes_6dof", "poster_rotation", "poster_translation",
             "poster_6dof", "boxes_rotation", "boxes_translation", "boxes_6dof", "hdr_poster", "hdr_boxes",
             "outdoors_walking", "outdoors_running", "dynamic_rotation", "dynamic_translation", "dynamic_6dof",
             "calibration", "office_zigzag", "office_spiral", "slider_close", "slider_far", "slider_hdr_close",
             "slider_hdr_far", "slider_depth", "urban")

HQF_NAMES = ("bike_bay_hdr", "boxes", "desk", "desk_fast", "desk_hand_only", "desk_slow",
             "engineering_posters", "high_texture_plants", "poster_pillar_1", "poster_pillar_2",
             "reflective_materials", "slow_and_fast_desk", "slow_hand", "still_life")


def _hqf() -> Dataset:
    seqs = {n: Sequence(n, f"{n}.bag") for n in HQF_NAMES}
    return Dataset(
        "hqf", "High Quality Frames (HQF), DAVIS240C", "gdrive", DAVIS240, 1.0, "rosbag",
        HQF_FOLDER, seqs, event_topic="/dvs/events", image_topics=("/dvs/image_raw",),
        note="rosbags in a public Google Drive folder (fetched with gdown); whole sequences are scored; "
             "one frame timestamp of engineering_posters is out of order and is repaired",
        citation="Stoffregen et al., Reducing the sim-to-real gap for event cameras, ECCV 2020",
    )


MVSEC_WINDOWS = {
    "indoor_flying1": (10.0, 70.0), "indoor_flying2": (10.0, 70.0), "indoor_flying3": (10.0, 70.0),
    "indoor_flying4": (10.0, 19.8), "outdoor_day1": (0.0, 60.0), "outdoor_day2": (100.0, 160.0),
}
# md5 of the <sequence>_data.bag files as published by the Tonic library's MVSEC loader.
MVSEC_MD5 = {
    "indoor_flying1": "fd01f35eb52a754e8195d478ed2a00a2",
    "indoor_flying2": "015ac75086b248167e9602b72485e0eb",
    "indoor_flying3": "fda3408d3c72b2d7445540e5bdbd6396",
    "indoor_flying4": "30ba3a744dcd4408fc4102e88c636acc",
    "outdoor_day1": "7438c34b71d08ff38f52cef68834e9be",
    "outdoor_day2": "536d20bc59720b995df49f925f96b74d",
    "outdoor_night1": "534bea503649eeb2801316704d6ab041",
    "outdoor_night2": "371ff73324ba94ecb368b4c220dc8e54",
    "outdoor_night3": "fc40889a48de7b28e6e2506125b229ac",
}


def _mvsec() -> Dataset:
    seqs = {}
    for name, md5 in MVSEC_MD5.items():
        group = re.sub(r"\d+$", "", name)
        seqs[name] = Sequence(name, f"{name}_data.bag", f"{MVSEC_BASE}{group}/{name}_data.bag", f"md5:{md5}",
                              MVSEC_WINDOWS.get(name), evaluation=name in MVSEC_WINDOWS)
    return Dataset(
        "mvsec", "Multi Vehicle Stereo Event Camera (MVSEC), DAVIS346 left camera", "http", DAVIS346, 1.0,
        "rosbag", "https://daniilidis-group.github.io/mvsec/", seqs,
        event_topic="/davis/left/events", image_topics=("/davis/left/image_raw",),
        note="the <sequence>_data.bag files (md5 pinned); `convert` also reads the <sequence>_data.hdf5 "
             "release (davis/left/events as N x 4 columns x, y, t, p)",
        citation="Zhu et al., The multivehicle stereo event camera dataset, RA-L 2018",
    )


CED_NAMES = (
    "calib_fluorescent", "calib_fluorescent_density", "calib_fluorescent_density_infrared",
    "calib_fluorescent_dynamic", "calib_fluorescent_infrared", "calib_low", "calib_low_density",
    "calib_outdoor", "calib_outdoor_density", "calib_outdoor_dynamic", "calib_outdoor_hdr_infrared",
    "calib_outdoor_infrared", "driving_city_1", "driving_city_2", "driving_city_3", "driving_city_4",
    "driving_city_5", "driving_city_sun_1", "driving_city_sun_2", "driving_country",
    "driving_country_sun_1", "driving_country_sun_2", "driving_tunnel", "driving_tunnel_sun",
    "indoors_corridor", "indoors_dark_100ms", "indoors_dark_25ms", "indoors_flying_room",
    "indoors_foosball_1", "indoors_foosball_2", "indoors_foosball_3", "indoors_kitchen_1",
    "indoors_kitchen_2", "indoors_kitchen_fast", "indoors_office", "indoors_very_dark_250ms",
    "indoors_very_dark_25ms", "indoors_window", "indoors_window_autoexposure",
    "outdoor_jumping_1_infrared", "outdoor_jumping_infrared_2", "outdoor_shadow_1_infrared",
    "outdoor_shadow_density_infrared", "people_dynamic_air_guitar", "people_dynamic_armroll",
    "people_dynamic_clap", "people_dynamic_dancing", "people_dynamic_dancing_multiple",
    "people_dynamic_jogging", "people_dynamic_jumping", "people_dynamic_selfie", "people_dynamic_sitting",
    "people_dynamic_wave", "people_dynamic_wave_clockwise", "people_dynamic_wave_counterclockwise",
    "people_static_air_guitar", "people_static_arm_roll", "people_static_clap", "people_static_dancing",
    "people_static_dancing_multiple_1", "people_static_dancing_multiple_2",
    "people_static_dancing_multiple_3", "people_static_jogging", "people_static_jumping",
    "people_static_sitting", "people_static_wave", "people_static_wave_clockwise",
    "people_static_wave_counterclockwise", "simple_carpet", "simple_carpet_fast",
    "simple_color_keyboard_1", "simple_color_keyboard_2", "simple_color_keyboard_3",
    "simple_flowers_infrared", "simple_fruit", "simple_fruit_fast", "simple_jenga_1", "simple_jenga_2",
    "simple_jenga_destroy", "simple_objects", "simple_objects_dynamic", "simple_rabbits",
    "simple_wires_1", "simple_wires_2",
)
# The CED page distributes one zip of bags per category; only CED_simple.zip's address is confirmed
# from a published link, the others follow the same naming and are checked when downloaded.
CED_CONFIRMED_ARCHIVES = ("simple",)


def ced_category(name: str) -> str:
    return name.split("_", 1)[0]


def _ced() -> Dataset:
    seqs = {n: Sequence(n, f"CED_{ced_category(n)}.zip", f"{CED_BASE}CED_{ced_category(n)}.zip", None, None,
                        archive_member=f"{n}.bag") for n in CED_NAMES}
    return Dataset(
        "ced", "Color Event Camera Dataset (CED), Color DAVIS346", "http", DAVIS346, 1.0, "ced-zip",
        "https://rpg.ifi.uzh.ch/CED.html", seqs,
        event_topic="/dvs/events", image_topics=("/dvs/image_color", "/dvs/image_raw"),
        note="one zip of rosbags per category (simple, people, indoors, ...); the bag is taken out of the "
             "zip; events keep their RGGB colour filter (cfa attribute) and frames stay colour (image_color; "
             "image_raw mosaics are debayered); convert --grey for grey frames; a bag placed by hand is used as is",
        citation="Scheerlinck et al., CED: Color event camera dataset, CVPRW 2019",
        cfa="RGGB",   # Color DAVIS346: photosite (0, 0) red, as rpg_e2vid's colour split assumes
    )


def _aed() -> Dataset:
    return Dataset(
        "aed", "ALPIX Event Dataset (AED), ALPIX-Eiger", "manual", (306, 408), 0.25, "manual",
        "(distributed by the EvINR authors on request)", {},
        note="not publicly downloadable: request it from the authors and place the files by hand; events "
             "1632x1224 Quad Bayer, demosaiced to 408x306; frames 816x612 grey; about 10 s per sequence; "
             "convert a placed folder with `python -m data_fetch convert <folder> --dataset aed` "
             "(expected layout: data_fetch/convert_aed.py)",
        citation="Wang et al., EvINR, ECCV 2024",
    )


DATASETS: dict[str, Dataset] = {d.name: d for d in (_ijrr(), _hqf(), _ced(), _mvsec(), _aed())}


def _name(value, what: str) -> str:
    """A registry name given as text; anything else is a DataFetchError (None or 5 were "has no attribute 'lower'")."""
    from .errors import DataFetchError

    if not isinstance(value, str):
        raise DataFetchError(f"{what} must be a name (text), got {value!r}; run `python -m data_fetch list` for the "
                             "names")
    return value


def sequence_name(name) -> str:
    """``name`` when it can name a sequence: text that is a file name (no folder part, not "." or ".."); the
    sequence's files are <cache>/<dataset>/<name>.h5 and <cache>/raw/<dataset>/<name>, so "../x" or "a/b" would
    lie elsewhere. Anything else is a DataFetchError."""
    from .errors import DataFetchError

    _name(name, "the sequence")
    if not name.strip() or name.strip() in (".", "..") or "/" in name or "\\" in name or "\0" in name:
        raise DataFetchError(f"the sequence must be a sequence's name (no folder, no '/', not '.' or '..'), got "
                             f"{name!r}; run `python -m data_fetch list` for the names")
    return name


def get_dataset(name: str) -> Dataset:
    from .errors import DataFetchError

    key = _name(name, "the dataset").lower()
    if key == "ecd":
        key = "ijrr"
    if key not in DATASETS:
        raise DataFetchError(f"unknown dataset {name!r}; known datasets: {', '.join(DATASETS)} "
                             "(run `python -m data_fetch list`)")
    return DATASETS[key]


def get_sequence(dataset: str, name: str) -> Sequence:
    """The registered sequence, or for IJRR a non-evaluation sequence built from the URL pattern."""
    from .errors import DataFetchError

    ds = get_dataset(dataset)
    sequence_name(name)
    if name in ds.sequences:
        return ds.sequences[name]
    if ds.url_pattern and re.fullmatch(r"[A-Za-z0-9_]+", name) and (ds.name != "ijrr" or name in ECD_NAMES):
        return Sequence(name, f"{name}.zip", ds.url_pattern.format(name=name), None, None, evaluation=False)
    if ds.method == "manual":
        return Sequence(name, name, None, None, None, evaluation=False)
    known = ", ".join(ECD_NAMES if ds.name == "ijrr" else ds.sequences)
    raise DataFetchError(f"{ds.name} has no sequence {name!r} (nothing was downloaded); known sequences: {known}")


# ---- model weights (not datasets): fetched with `python -m data_fetch get <name> all` ----------

@dataclass(frozen=True)
class WeightFile:
    """One published weight file, stored as ``<cache>/weights/<set>/<file>``.

    Attributes:
        name: its name on the command line. file: the file name (kept as published).
        url: where to download it. known_hash: pinned checksum ("sha256:..."), or None.
        note: where the checksum comes from.
    """

    name: str
    file: str
    url: str
    known_hash: str | None
    note: str = ""


# LPIPS (AlexNet, v0.1) for evinr_lite.evaluation.lpips. Checksums: torchvision names its file after the first
# 8 hex digits of the sha256 (7be5be79); the full digest is the one other public projects pin for
# the same file. The v0.1 heads are byte-identical to lpips/weights/v0.1/alex.pth in the `lpips`
# 0.1.4 wheel on PyPI, whose sha256 was computed from that wheel.
WEIGHTS: dict[str, dict[str, WeightFile]] = {
    "lpips": {
        "alexnet": WeightFile(
            "alexnet", "alexnet-owt-7be5be79.pth", "https://download.pytorch.org/models/alexnet-owt-7be5be79.pth",
            "sha256:7be5be791159472b1fbf3c69796f7cb30dca7ad8466c2df70058c37116cdee02",
            "torchvision ImageNet AlexNet (IMAGENET1K_V1), 233 MB; only its `features` are used"),
        "alex_v0.1": WeightFile(
            "alex_v0.1", "alex.pth",
            "https://github.com/richzhang/PerceptualSimilarity/raw/master/lpips/weights/v0.1/alex.pth",
            "sha256:df73285e35b22355a2df87cdb6b70b343713b667eddbda73e1977e0c860835c0",
            "LPIPS v0.1 linear heads for AlexNet, 6 kB"),
    },
}


def get_weight_set(name: str) -> dict[str, WeightFile]:
    from .errors import DataFetchError

    key = _name(name, "the weight set").lower()
    if key not in WEIGHTS:
        raise DataFetchError(f"unknown weight set {name!r}; known: {', '.join(WEIGHTS)}")
    return WEIGHTS[key]
