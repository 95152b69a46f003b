"""The scene zoo: seeded synthetic scenes nobody tuned to, with their sensor models.

    from evinr_lite.sim import zoo
    for z in zoo.ZOO:                                   # one line of documentation each: z.doc
        scene, events, times, gt = zoo.simulate(z)      # ground-truth intensities at 10 scored times
        C = zoo.effective_C(z)                          # the one threshold every method is given

Together the scenes vary texture (five natural images and one low-texture scene), motion
(translation, rotation + zoom, shear and perspective, non-uniform speed, a static camera with an
object moving over a static background), light (a global change and vignetting), the sensor
(background activity, hot pixels, C+ != C-, threshold mismatch, a refractory period), size
(120x160 to 180x240) and length (2-3 s; 8 s for the drifting thresholds; 20 s and 60 s for the two
``long`` recordings, which only the zoo's ``--long`` mode runs). Sensor faults that users' recordings
bring: C+ != C- with one nominal C given, ON-only hot pixels, thresholds drifting over the recording,
background activity growing as light falls. Motion also includes bounded to-and-fro pans (a slider)
and hand-held shake (:class:`~evinr_lite.sim.scenes.OscillatingScene`). ``benchmarks/quality_zoo.py`` scores every method on
them; the kit's defaults were chosen on their mean, never on one scene. ``HELDOUT`` holds ten more
scenes built the same ways (other images, motions, sizes and seeds; one of 20 s) on which no default
was chosen: ``quality_zoo.py --heldout`` checks that the defaults carry over to them. ``STRESS`` holds
eleven built the same ways with settings outside both sets' ranges (``quality_zoo.py --stress``), and
``LARGE`` three at 360x480, twice the zoo's largest sensor along each side (``quality_zoo.py --large``).
:func:`fresh` draws any number more at random from a seed, the same ways (``quality_zoo.py --fresh SEED``).
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, field
from functools import partial

import numpy as np

from ..core.checks import require, true_or_false, whole_number
from ..core.events import EventDataError
from . import scenes as sc
from .simulate import add_background_noise, add_hot_pixels, add_light_noise, simulate_scene

__all__ = ["ZooScene", "ZOO", "HELDOUT", "STRESS", "LARGE", "N_SCORED", "fresh", "FRESH_KINDS", "quick", "simulate", "effective_C", "imbalance", "get", "default_scenes",
           "SIGNAL", "BACKGROUND", "HOT"]

N_SCORED = 10   # ground-truth times scored per scene, evenly spread over [0.1, 0.95] of the duration


@dataclass
class ZooScene:
    """One seeded scene: how to build it, the sensor's model, and one line saying what it tests."""

    name: str
    doc: str
    build: object                        # (sensor_size, duration) -> Scene
    size: tuple = (120, 160)
    duration: float = 2.0
    C: float = 0.2                       # nominal threshold; C_pos / C_neg below when asymmetric
    C_pos: float | None = None
    C_neg: float | None = None
    threshold_sigma: float = 0.0         # relative mismatch between pixels
    refractory: float = 0.0              # seconds
    noise_hz: float = 0.0                # background activity per pixel
    hot_pixels: int = 0                  # stuck pixels firing hot_hz each
    hot_hz: float = 50.0
    hot_on_only: bool = False            # hot pixels fire ON events only (they integrate into a climb)
    threshold_drift: float = 0.0         # relative change of the thresholds over the recording (nominal mid-way)
    dark_noise_hz: float = 0.0           # background activity x 1/intensity (grows as light falls)
    long: bool = False                   # a long recording: only in the zoo's --long mode
    seed: int = 0
    tags: tuple = field(default_factory=tuple)

    @property
    def noise_free(self) -> bool:
        return (self.noise_hz == 0 and self.hot_pixels == 0 and self.threshold_sigma == 0
                and self.dark_noise_hz == 0 and self.threshold_drift == 0)

    @property
    def n_scored(self) -> int:
        """Ground-truth times scored: N_SCORED, or 2 per second on long scenes (so each quarter holds many)."""
        return max(N_SCORED, int(round(2 * self.duration)))


ZOO = [
    ZooScene("camera_translate", "camera image, translation with a slight rotation and zoom; clean sensor",
             lambda s, d: sc.MovingImageScene("camera", s, d, velocity=(20.0, 8.0), rotation=0.08, zoom=0.05)),
    ZooScene("astronaut_rotzoom", "astronaut, rotation 0.35 rad/s and zoom 0.25/s about the centre; clean sensor",
             lambda s, d: sc.MovingImageScene("astronaut", s, d, velocity=(4.0, -3.0), rotation=0.35, zoom=0.25),
             size=(150, 200), duration=2.5),
    ZooScene("coffee_warp", "coffee, shear and perspective tilt growing over time; C+ 0.24 != C- 0.16",
             lambda s, d: sc.WarpedImageScene("coffee", s, d, velocity=(10.0, 5.0), rotation=0.0, zoom=0.0,
                                              shear=(0.25, 0.1), tilt=(0.3, 0.15)),
             C_pos=0.24, C_neg=0.16),
    ZooScene("chelsea_speed", "chelsea, speed swinging 0.2x-1.8x; 4 % threshold mismatch, 1 ms refractory",
             lambda s, d: sc.VaryingSpeedScene(sc.MovingImageScene("chelsea", s, d, velocity=(-22.0, 6.0),
                                                                   rotation=0.05, zoom=0.0), depth=0.8, period=d),
             duration=3.0, threshold_sigma=0.04, refractory=1e-3),
    ZooScene("object_static_cam", "static camera: a coffee-textured disc crossing a static brick wall; clean",
             lambda s, d: sc.ObjectOverBackgroundScene("brick", "coffee", s, d)),
    ZooScene("lowtex_light", "low texture (moon, blurred) under a global light change and vignetting; clean",
             lambda s, d: sc.LightingScene(sc.MovingImageScene("moon", s, d, velocity=(15.0, 10.0), rotation=0.1,
                                                               zoom=0.0, blur=2.5), global_change=0.5,
                                           vignette=-0.6)),
    ZooScene("noisy_gravel", "gravel at 180x240: 0.5 Hz background activity, 20 hot pixels, C+ != C-, 5 % mismatch",
             lambda s, d: sc.MovingImageScene("gravel", s, d, velocity=(18.0, -10.0), rotation=0.05, zoom=0.05),
             size=(180, 240), C_pos=0.22, C_neg=0.18, threshold_sigma=0.05, refractory=5e-4, noise_hz=0.5,
             hot_pixels=20, seed=1),
    ZooScene("grass_light_noisy", "grass under vignetting light, 0.2 Hz background activity, 10 hot pixels, 3 s",
             lambda s, d: sc.LightingScene(sc.MovingImageScene("grass", s, d, velocity=(12.0, 12.0), rotation=-0.1,
                                                               zoom=0.08), global_change=-0.3, vignette=-0.4),
             duration=3.0, threshold_sigma=0.03, noise_hz=0.2, hot_pixels=10, seed=2),
    ZooScene("camera_240x180", "camera at 180x240 (the paper's DAVIS240 size), 2 s: the timing target; clean",
             lambda s, d: sc.MovingImageScene("camera", s, d, velocity=(25.0, 10.0), rotation=0.1, zoom=0.1),
             size=(180, 240)),
    ZooScene("unequal_onhot", "rocket, pan + zoom at 150x200, 3 s: C+ 0.26, C- 0.18 given as C 0.22, 30 ON-only hot pixels",
             lambda s, d: sc.MovingImageScene("rocket", s, d, velocity=(-16.0, 6.0), rotation=-0.06, zoom=0.08),
             size=(150, 200), duration=3.0, C=0.22, C_pos=0.26, C_neg=0.18, threshold_sigma=0.03, noise_hz=0.2,
             hot_pixels=30, hot_hz=40.0, hot_on_only=True, seed=3),
    ZooScene("drift_clock", "clock panned to and fro (slider), 8 s: thresholds drift from 0.8x to 1.2x, 3 % mismatch",
             lambda s, d: sc.OscillatingScene("clock", s, d, path=((28.0, 6.0, 5.0, 0.0),), rotation=(0.04, 7.0)),
             duration=8.0, threshold_sigma=0.03, threshold_drift=0.4, seed=4),
    ZooScene("dark_falling", "coins while the light falls 7x over 3 s; background activity grows as 1/intensity",
             lambda s, d: sc.LightingScene(sc.MovingImageScene("coins", s, d, velocity=(14.0, -9.0), rotation=0.12,
                                                               zoom=0.0, blur=1.0, intensity_range=(0.02, 0.35)),
                                           global_change=-2.0, vignette=-0.3),
             duration=3.0, threshold_sigma=0.04, dark_noise_hz=0.05, seed=5),
    ZooScene("text_shake", "printed text (binary strokes) under hand-held shake: three fast sinusoids; clean sensor",
             lambda s, d: sc.OscillatingScene("text", s, d, path=((6.0, 3.0, 0.9, 0.0), (3.0, 5.0, 0.55, 1.0),
                                                                  (2.0, 2.0, 0.23, 2.0)), rotation=(0.03, 0.7))),
    ZooScene("long_pan_20s", "astronaut on a slider going to and fro, 20 s at 180x240: C+ 0.25, C- 0.20 given as "
             "0.225, 20 ON-only hot pixels, 0.3 Hz background",
             lambda s, d: sc.OscillatingScene("astronaut", s, d, path=((40.0, 8.0, 10.0, 0.0), (5.0, 4.0, 3.3, 1.0)),
                                              rotation=(0.05, 13.0)),
             size=(180, 240), duration=20.0, C=0.225, C_pos=0.25, C_neg=0.20, threshold_sigma=0.03, noise_hz=0.3,
             hot_pixels=20, hot_hz=30.0, hot_on_only=True, long=True, seed=6),
    ZooScene("long_ijrr_60s", "gravel panned for 60 s at 180x240, ~IJRR event rate: C+ 0.22, C- 0.18, drift 0.3, "
             "ON-only hot pixels, 0.1 Hz background, 0.5 ms refractory",
             lambda s, d: sc.OscillatingScene("gravel", s, d, path=((50.0, 10.0, 12.0, 0.0), (6.0, 8.0, 4.1, 2.0)),
                                              rotation=(0.06, 17.0)),
             size=(180, 240), duration=60.0, C=0.2, C_pos=0.22, C_neg=0.18, threshold_sigma=0.05, refractory=5e-4,
             threshold_drift=0.3, noise_hz=0.1, hot_pixels=20, hot_hz=30.0, hot_on_only=True, long=True, seed=7),
]

# Held out: built the same ways as ZOO (the same scene classes and sensor faults) with other images,
# motions, sizes and seeds. No default was chosen on them; they check that the defaults chosen on
# ZOO carry over to scenes nobody looked at (``python benchmarks/quality_zoo.py --heldout``).
HELDOUT = [
    ZooScene("cat_pan_noisy", "cat, pan + rotation at 150x200, 2.5 s: 0.4 Hz background, 15 hot pixels, "
             "C+ 0.23 != C- 0.17, 4 % mismatch",
             lambda s, d: sc.MovingImageScene("cat", s, d, velocity=(15.0, -9.0), rotation=0.07, zoom=0.04),
             size=(150, 200), duration=2.5, C_pos=0.23, C_neg=0.17, threshold_sigma=0.04, refractory=5e-4,
             noise_hz=0.4, hot_pixels=15, seed=11),
    ZooScene("page_shake", "a printed page under hand-held shake (two sinusoids and a slow turn); clean sensor",
             lambda s, d: sc.OscillatingScene("page", s, d, path=((5.0, 4.0, 0.8, 0.3), (3.0, 2.0, 0.4, 1.2)),
                                              rotation=(0.02, 0.9)), seed=12),
    ZooScene("hubble_rotzoom", "Hubble deep field (sparse bright points), rotation 0.3 rad/s and zoom 0.2/s; clean",
             lambda s, d: sc.MovingImageScene("hubble_deep_field", s, d, velocity=(3.0, 2.0), rotation=0.3, zoom=0.2),
             size=(150, 200), duration=2.5, seed=13),
    ZooScene("ihc_warp", "immunohistochemistry slide, shear and perspective tilt: C+ 0.25 != C- 0.17",
             lambda s, d: sc.WarpedImageScene("immunohistochemistry", s, d, velocity=(-8.0, 6.0), rotation=0.0,
                                              zoom=0.0, shear=(0.2, 0.15), tilt=(0.2, 0.25)),
             C_pos=0.25, C_neg=0.17, seed=14),
    ZooScene("cat_over_page", "static camera: a cat-textured disc crossing a static printed page; clean",
             lambda s, d: sc.ObjectOverBackgroundScene("page", "cat", s, d), seed=15),
    ZooScene("ihc_dark", "immunohistochemistry while the light falls 5x over 3 s; background activity grows "
             "as 1/intensity",
             lambda s, d: sc.LightingScene(sc.MovingImageScene("immunohistochemistry", s, d, velocity=(-12.0, 7.0),
                                                               rotation=-0.08, zoom=0.0, blur=1.0,
                                                               intensity_range=(0.03, 0.4)),
                                           global_change=-1.6, vignette=-0.2),
             duration=3.0, threshold_sigma=0.03, dark_noise_hz=0.04, seed=16),
    ZooScene("cat_slider_drift", "cat on a slider going to and fro, 6 s: thresholds drift 0.825x to 1.175x, "
             "3 % mismatch",
             lambda s, d: sc.OscillatingScene("cat", s, d, path=((24.0, 5.0, 4.0, 0.5),), rotation=(0.03, 5.0)),
             duration=6.0, threshold_sigma=0.03, threshold_drift=0.35, seed=17),
    ZooScene("coins_unequal_onhot", "coins, pan + rotation at 150x200, 3 s: C+ 0.28, C- 0.18 given as 0.23, "
             "25 ON-only hot pixels",
             lambda s, d: sc.MovingImageScene("coins", s, d, velocity=(13.0, 9.0), rotation=0.09, zoom=-0.05),
             size=(150, 200), duration=3.0, C=0.23, C_pos=0.28, C_neg=0.18, threshold_sigma=0.03, noise_hz=0.25,
             hot_pixels=25, hot_hz=35.0, hot_on_only=True, seed=18),
    ZooScene("brick_speed_noisy", "brick wall, speed swinging 0.3x-1.7x at 180x240: 0.2 Hz background, "
             "1 ms refractory",
             lambda s, d: sc.VaryingSpeedScene(sc.MovingImageScene("brick", s, d, velocity=(16.0, -12.0),
                                                                   rotation=-0.04, zoom=0.06), depth=0.7, period=d),
             size=(180, 240), duration=3.0, threshold_sigma=0.03, refractory=1e-3, noise_hz=0.2, seed=19),
    ZooScene("cat_slider_20s", "cat on a slider going to and fro with shake, 20 s at 150x200: C+ 0.24, C- 0.19 given "
             "as 0.215, drift 0.25, 15 ON-only hot pixels, 0.2 Hz background",
             lambda s, d: sc.OscillatingScene("cat", s, d, path=((30.0, 12.0, 9.0, 0.7), (4.0, 3.0, 2.7, 0.2)),
                                              rotation=(0.04, 11.0)),
             size=(150, 200), duration=20.0, C=0.215, C_pos=0.24, C_neg=0.19, threshold_sigma=0.03,
             threshold_drift=0.25, noise_hz=0.2, hot_pixels=15, hot_hz=30.0, hot_on_only=True, long=True, seed=20),
]


# Stress: built the same ways again, with settings outside the ranges of ZOO and HELDOUT (a threshold of
# 0.1 or 0.45, a 64x64 or a 90x320 sensor, a speed that nearly stops, 2 Hz of background activity, an
# OFF-heavy pair, 15 % mismatch, a flat background under a sweeping bar). No default was chosen on them
# either; ``quality_zoo.py --stress`` says where the defaults stop carrying over (docs/defaults.md).
STRESS = [
    ZooScene("camera_coarse_C", "camera panned with C 0.45: a few events per pixel; clean sensor",
             lambda s, d: sc.MovingImageScene("camera", s, d, velocity=(18.0, 7.0), rotation=0.06, zoom=0.04),
             C=0.45, seed=31),
    ZooScene("coffee_fine_C_noisy", "coffee at C 0.1 (dense events): 0.5 Hz background, 10 hot pixels, 5 % mismatch",
             lambda s, d: sc.MovingImageScene("coffee", s, d, velocity=(-10.0, 6.0), rotation=0.05, zoom=0.03),
             C=0.1, threshold_sigma=0.05, noise_hz=0.5, hot_pixels=10, seed=32),
    ZooScene("astronaut_near_stop", "astronaut whose speed swings 0.05x-1.95x (it nearly stops), 3 s; clean",
             lambda s, d: sc.VaryingSpeedScene(sc.MovingImageScene("astronaut", s, d, velocity=(15.0, -8.0),
                                                                   rotation=0.05, zoom=0.0), depth=0.95, period=d),
             duration=3.0, seed=33),
    ZooScene("cat_64x64", "cat on a 64x64 sensor, pan + rotation + zoom; clean",
             lambda s, d: sc.MovingImageScene("cat", s, d, velocity=(8.0, 5.0), rotation=0.1, zoom=0.05),
             size=(64, 64), seed=34),
    ZooScene("brick_90x320", "brick wall panned along a 90x320 strip; clean",
             lambda s, d: sc.MovingImageScene("brick", s, d, velocity=(25.0, 3.0), rotation=0.02, zoom=0.0),
             size=(90, 320), seed=35),
    ZooScene("rocket_very_noisy", "rocket under 2 Hz background activity and 60 hot pixels, C+ 0.22 != C- 0.18",
             lambda s, d: sc.MovingImageScene("rocket", s, d, velocity=(12.0, 9.0), rotation=0.05, zoom=0.05),
             C_pos=0.22, C_neg=0.18, noise_hz=2.0, hot_pixels=60, seed=36),
    ZooScene("chelsea_off_heavy", "chelsea at 150x200, 3 s: C+ 0.17, C- 0.27 given as 0.22 (OFF-heavy), "
             "20 ON-only hot pixels, 0.2 Hz background",
             lambda s, d: sc.MovingImageScene("chelsea", s, d, velocity=(-14.0, -7.0), rotation=0.07, zoom=-0.05),
             size=(150, 200), duration=3.0, C=0.22, C_pos=0.17, C_neg=0.27, noise_hz=0.2, hot_pixels=20,
             hot_on_only=True, seed=37),
    ZooScene("gravel_mismatch", "gravel with 15 % threshold mismatch between pixels",
             lambda s, d: sc.MovingImageScene("gravel", s, d, velocity=(16.0, 10.0), rotation=0.03, zoom=0.03),
             threshold_sigma=0.15, seed=38),
    ZooScene("bar_sweep", "a bright bar sweeping across a flat dark background (no texture); clean",
             lambda s, d: sc.MovingBarScene(s, d), seed=39),
    ZooScene("ihc_rotate_5s", "immunohistochemistry turning in place at 0.25 rad/s for 5 s; clean",
             lambda s, d: sc.MovingImageScene("immunohistochemistry", s, d, velocity=(0.0, 0.0), rotation=0.25,
                                              zoom=0.0),
             duration=5.0, seed=40),
    ZooScene("page_shake_noisy", "a printed page under fast hand-held shake: 0.3 Hz background, 10 hot pixels",
             lambda s, d: sc.OscillatingScene("page", s, d, path=((5.0, 3.0, 0.5, 0.0), (2.0, 4.0, 0.3, 1.0)),
                                              rotation=(0.02, 0.6)),
             noise_hz=0.3, hot_pixels=10, seed=41),
]

# Twice the zoo's largest sensor along each side (360x480: 4x its pixels), the motions scaled with it in
# pixels per second and the hot pixels with the pixel count; no default was chosen on them.
LARGE = [
    ZooScene("camera_360x480", "camera at 360x480, translation with a slight rotation and zoom; clean sensor",
             lambda s, d: sc.MovingImageScene("camera", s, d, velocity=(40.0, 16.0), rotation=0.08, zoom=0.05),
             size=(360, 480), seed=51),
    ZooScene("gravel_360x480_noisy", "gravel at 360x480: 0.5 Hz background activity, 80 hot pixels, C+ 0.22 != "
             "C- 0.18, 5 % mismatch",
             lambda s, d: sc.MovingImageScene("gravel", s, d, velocity=(36.0, -20.0), rotation=0.05, zoom=0.05),
             size=(360, 480), C_pos=0.22, C_neg=0.18, threshold_sigma=0.05, refractory=5e-4, noise_hz=0.5,
             hot_pixels=80, seed=52),
    ZooScene("astronaut_360x480_unequal", "astronaut at 360x480 turning and zooming: C+ 0.24 != C- 0.16 given as "
             "0.2, 0.2 Hz background activity, 2.5 s",
             lambda s, d: sc.MovingImageScene("astronaut", s, d, velocity=(8.0, -6.0), rotation=0.3, zoom=0.2),
             size=(360, 480), duration=2.5, C_pos=0.24, C_neg=0.16, noise_hz=0.2, seed=53),
]


FRESH_KINDS = ("pan", "shake", "warp", "speed", "light", "static")   # the zoo's scene classes
FRESH_SIZES = ((90, 120), (120, 160), (150, 200), (180, 240))


def _fresh_seed(seed) -> tuple:
    """(seed, label): :func:`fresh`'s seed as ``np.random.default_rng`` takes it, and its label in the scenes' names.
    Taken: a whole number >= 0 (the label is the number, as always), a list, tuple or 1-D array of them (joined by
    "-"; a list of one is the number's own generator) or a ``np.random.SeedSequence`` (its entropy, then "s" and its
    spawn key when it has one). Refused (numpy takes them): None, a Generator or BitGenerator (scenes nobody could
    draw again from their names) and an empty list (a name with no seed)."""
    if isinstance(seed, np.random.SeedSequence):
        entropy = seed.entropy if np.ndim(seed.entropy) else [seed.entropy]
        key = f"s{'-'.join(str(int(k)) for k in seed.spawn_key)}" if seed.spawn_key else ""
        return seed, "-".join(str(int(e)) for e in entropy) + key
    if isinstance(seed, (list, tuple, np.ndarray)) and np.ndim(seed) == 1:
        if len(seed) == 0:
            raise EventDataError("fresh: seed= is an empty list; give a whole number >= 0 (e.g. 23) or a list of them")
        whole = [whole_number(v, "fresh: seed", lo=0) for v in seed]
        return whole, "-".join(map(str, whole))
    if seed is None or isinstance(seed, (np.random.Generator, np.random.BitGenerator)):
        raise EventDataError(f"fresh: seed= must be a whole number >= 0, a list of them or a np.random.SeedSequence, "
                             f"got {type(seed).__name__}: the scenes are named by their seed, so that they can be "
                             "drawn again (e.g. fresh(23))")
    seed = whole_number(seed, "fresh: seed", lo=0)
    return seed, str(seed)


def fresh(seed: int, n: int = 16) -> list:
    """``n`` scenes drawn at random (a generator seeded ``seed``) the ways the zoo's are built, for a check
    no default was chosen on: one of the zoo's scene classes (a pan with rotation and zoom, a hand-held
    shake, a warp, a speed that swings, a change of light over a pan, an object crossing a static
    background), any of the images, a sensor size, a duration and motion in the zoo's ranges, and a
    sensor: C 0.15-0.3 with C+ / C- 0.75-1.33 (given as their mean), 0-5 % mismatch, a refractory
    period, and on half the scenes background activity and hot pixels (ON-only on half of those). Each
    scene's ``doc`` says what was drawn (``python benchmarks/quality_zoo.py --fresh SEED``). ``seed``: a whole
    number >= 0, a list of them or a ``np.random.SeedSequence`` (see :func:`_fresh_seed`)."""
    seed, label = _fresh_seed(seed)                  # NaN and "0" were numpy's SeedSequence error
    n = whole_number(n, "fresh: n", lo=0)            # -1 gave no scene, 2.5 two and "3" three without a word
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n):
        img = str(rng.choice(sc.IMAGE_NAMES))
        size = FRESH_SIZES[int(rng.integers(len(FRESH_SIZES)))]
        duration = float(rng.choice([2.0, 2.5, 3.0]))
        v = (round(float(rng.uniform(-30, 30)), 1), round(float(rng.uniform(-20, 20)), 1))
        rot, zoom = round(float(rng.uniform(-0.3, 0.3)), 3), round(float(rng.uniform(-0.2, 0.2)), 3)
        kind = str(rng.choice(FRESH_KINDS, p=[0.3, 0.15, 0.15, 0.1, 0.2, 0.1]))
        if kind == "pan":
            what = f"{img} panned at {v} px/s, rotation {rot} rad/s, zoom {zoom}/s"
            build = partial(_pan, img, v, rot, zoom)
        elif kind == "shake":
            A, P, ph = round(float(rng.uniform(5, 30)), 1), round(float(rng.uniform(0.5, 3)), 2), round(float(rng.uniform(0, 3)), 2)
            what = f"{img} shaken {A} x {round(A / 3, 1)} px with a {P} s period"
            build = partial(_shake, img, A, P, ph)
        elif kind == "warp":
            shear = (round(float(rng.uniform(0, 0.3)), 3), round(float(rng.uniform(0, 0.2)), 3))
            tilt = (round(float(rng.uniform(0, 0.3)), 3), round(float(rng.uniform(0, 0.3)), 3))
            what = f"{img} sheared {shear} and tilted {tilt}, drifting at {(v[0] / 2, v[1] / 2)} px/s"
            build = partial(_warp, img, (v[0] / 2, v[1] / 2), shear, tilt)
        elif kind == "speed":
            what = f"{img} panned at {v} px/s with a speed swinging 0.2x-1.8x"
            build = partial(_speed, img, v, round(rot / 3, 3))
        elif kind == "light":
            g, vg = round(float(rng.uniform(-1.5, 1.0)), 2), round(float(rng.uniform(-0.6, 0.2)), 2)
            what = f"{img} panned at {v} px/s while the light changes by {g} (log) and the corners by {vg}"
            build = partial(_light, img, v, round(rot / 2, 3), g, vg)
        else:
            obj = str(rng.choice(sc.IMAGE_NAMES))
            what = f"static camera: a {obj}-textured disc crossing a static {img}"
            build = partial(_static, img, obj)
        C = round(float(rng.uniform(0.15, 0.3)), 3)
        ratio = float(np.exp(rng.uniform(np.log(0.75), np.log(1.33))))
        sigma, refractory = round(float(rng.uniform(0, 0.05)), 3), float(rng.choice([0.0, 5e-4, 1e-3]))
        noisy = bool(rng.random() < 0.5)
        noise_hz = round(float(rng.uniform(0.05, 0.6)), 2) if noisy else 0.0
        hot = int(rng.integers(5, 30)) if noisy else 0
        on_only = bool(rng.random() < 0.5)
        c_pos, c_neg = C * 2 * ratio / (1 + ratio), C * 2 / (1 + ratio)
        sensor = (f"C+ {c_pos:.3f}, C- {c_neg:.3f} given as {C}, {100 * sigma:.1f} % mismatch"
                  + (f", {noise_hz} Hz background, {hot} {'ON-only ' if on_only else ''}hot pixels" if noisy
                     else ", no noise"))
        out.append(ZooScene(f"fresh{label}_{k:02d}_{kind}_{img}", f"{what}; {sensor}", build, size=size,
                            duration=duration, C=C, C_pos=c_pos, C_neg=c_neg, threshold_sigma=sigma,
                            refractory=refractory, noise_hz=noise_hz, hot_pixels=hot, hot_on_only=on_only,
                            seed=int(rng.integers(1000, 9999)), tags=("fresh", kind)))
    return out


# the fresh scenes' builders: module functions (with functools.partial) so a scene pickles for Dask
def _pan(img, v, rot, zoom, s, d):
    return sc.MovingImageScene(img, s, d, velocity=v, rotation=rot, zoom=zoom)


def _shake(img, A, P, ph, s, d):
    return sc.OscillatingScene(img, s, d, path=((A, A / 3, P, ph),), rotation=(0.03, 2 * P))


def _warp(img, v, shear, tilt, s, d):
    return sc.WarpedImageScene(img, s, d, velocity=v, rotation=0.0, zoom=0.0, shear=shear, tilt=tilt)


def _speed(img, v, rot, s, d):
    return sc.VaryingSpeedScene(sc.MovingImageScene(img, s, d, velocity=v, rotation=rot, zoom=0.0), depth=0.8, period=d)


def _light(img, v, rot, g, vg, s, d):
    return sc.LightingScene(sc.MovingImageScene(img, s, d, velocity=v, rotation=rot, zoom=0.0), global_change=g,
                            vignette=vg)


def _static(img, obj, s, d):
    return sc.ObjectOverBackgroundScene(img, obj, s, d)


def quick(z: ZooScene) -> ZooScene:
    """A smaller, shorter version (--quick): 3/5 of the size, 3/4 of the length."""
    require(z, ZooScene, "quick: z")   # a name was an AttributeError; get(name) gives its scene
    H, W = z.size
    return ZooScene(**{**asdict(z), "build": z.build, "size": (int(H * 0.6) // 2 * 2, int(W * 0.6) // 2 * 2),
                       "duration": round(z.duration * 0.75, 3)})


SIGNAL, BACKGROUND, HOT = 0, 1, 2     # the labels of simulate(..., labels=True)


def simulate(z: ZooScene, labels: bool = False):
    """(scene, events, gt times [n_scored], gt intensity frames [n_scored, H, W] in (0, 1], clipped at 1).

    ``labels=True`` appends (labels int8 [N]: SIGNAL 0, BACKGROUND 1 (background activity, also the
    dark noise), HOT 2; the hot pixels' flat indices int64 [K]): the same seeds, draws and events.
    """
    require(z, ZooScene, "simulate: z")   # a name was an AttributeError; get(name) gives its scene
    scene = z.build(z.size, z.duration)
    kw = {} if z.C_pos is None else {"C_pos": z.C_pos, "C_neg": z.C_neg}
    if z.threshold_drift:
        kw["threshold_drift"] = z.threshold_drift
    events = simulate_scene(scene, 0.0, z.duration, C=z.C, threshold_sigma=z.threshold_sigma,
                            refractory=z.refractory, seed=z.seed, **kw)
    rng = np.random.default_rng(z.seed + 100)
    kind = np.zeros(len(events), np.int8)
    hot = np.zeros(0, np.int64)
    if z.noise_hz > 0:
        events, added = add_background_noise(events, z.noise_hz, seed=rng, t_start=0.0, t_end=z.duration,
                                             return_labels=True)
        kind = _relabelled(kind, added, BACKGROUND)
    if z.hot_pixels:
        events, hot, added = add_hot_pixels(events, z.hot_pixels, z.hot_hz, seed=rng, t_start=0.0, t_end=z.duration,
                                            on_only=z.hot_on_only, return_labels=True)
        kind = _relabelled(kind, added, HOT)
    if z.dark_noise_hz > 0:
        events, added = add_light_noise(events, scene, z.dark_noise_hz, seed=rng, t_start=0.0, t_end=z.duration,
                                        return_labels=True)
        kind = _relabelled(kind, added, BACKGROUND)
    times = np.linspace(0.1 * z.duration, 0.95 * z.duration, z.n_scored)
    # a frame camera saturates: light above full scale (a brightening scene, cubic overshoot at edges) reads 1
    out = (scene, events, times, np.clip(scene.intensity(times), 0.0, 1.0).astype(np.float32))
    return out + (kind, np.asarray(hot, np.int64)) if labels else out


def _relabelled(kind: np.ndarray, added: np.ndarray, label: int) -> np.ndarray:
    """The labels after a stable merge: the ``added`` events (bool [N_out]) get ``label``, the others
    keep theirs (``kind`` [N_in], in order)."""
    new = np.full(added.shape, label, np.int8)
    new[~added] = kind
    return new


def imbalance(z: ZooScene) -> float:
    """The scene's simulated ON/OFF imbalance (C+ - C-) / (C+ + C-) (0 when C+ = C-)."""
    require(z, ZooScene, "imbalance: z")   # a name was an AttributeError; get(name) gives its scene
    return 0.0 if z.C_pos is None else (z.C_pos - z.C_neg) / (z.C_pos + z.C_neg)


def effective_C(z: ZooScene) -> float:
    """The one threshold every method is given: the mean of C+ and C- (the solvers take one C)."""
    require(z, ZooScene, "effective_C: z")   # a name was an AttributeError; get(name) gives its scene
    return z.C if z.C_pos is None else 0.5 * (z.C_pos + z.C_neg)




def default_scenes(long: bool = False) -> list:
    """The scenes a zoo run scores: every scene, or (``long=False``) all but the long recordings."""
    long = true_or_false(long, "default_scenes: long")   # "no" was true
    return [z for z in ZOO if long or not z.long]


def get(name: str) -> ZooScene:
    """The zoo scene (or held-out or stress scene) called ``name``."""
    for z in ZOO + HELDOUT + STRESS + LARGE:
        if z.name == name:
            return z
    raise EventDataError(f"no zoo scene {name!r}; the zoo holds {[z.name for z in ZOO + HELDOUT + STRESS + LARGE]}")
