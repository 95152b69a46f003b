"""Synthetic scenes: log intensity known exactly at any time, for simulation and ground truth.

A scene is a function of time: ``scene.log_intensity(t)`` gives float64 [H, W] for a scalar
``t`` (seconds) and [T, H, W] for an array ``t`` [T]; ``scene.intensity(t)`` is its exp.
Feed a scene to :func:`evinr_lite.sim.simulate.simulate_scene` for events, and query it at any
timestamps for ground-truth frames (:meth:`Scene.frames`).

Two kinds:

- :class:`MovingImageScene`: a grey natural image (scikit-image's sample images, or your array)
  translating, rotating and zooming about the sensor centre, sampled with cubic splines.
- :class:`MovingBarScene`: a bright bar with smooth (tanh) edges sweeping across a dark background.

Intensities stay in a range like [0.05, 1] so that the log is finite (about [-3, 0]).
Coordinates: x is the column, y the row (pointing down); sizes are (H, W).
"""
from __future__ import annotations

import inspect

import numpy as np
from scipy import ndimage

from ..core.checks import ArgumentTypeError, host_array, is_real_number, real_number
from ..core.events import EventDataError, check_sensor_size
from ..core.frames import Frames
from ..core.guard import dense_array

__all__ = ["Scene", "MovingImageScene", "OscillatingScene", "MovingBarScene", "VaryingSpeedScene", "WarpedImageScene",
           "ObjectOverBackgroundScene", "LightingScene", "make_scene", "IMAGE_NAMES", "SCENE_NAMES",
           "MOTION_PARAMETERS", "check_intensity_range", "real_image"]

# scikit-image sample images that ship with the package (no download needed).
IMAGE_NAMES = ("camera", "astronaut", "coffee", "chelsea", "cat", "coins", "moon", "rocket", "brick",
               "grass", "gravel", "text", "page", "clock", "hubble_deep_field", "immunohistochemistry")
SCENE_NAMES = IMAGE_NAMES + ("bar",)
MOTION_PARAMETERS = ("velocity", "rotation", "zoom", "scale", "blur", "order")   # MovingImageScene's motion keywords
_RENDER_CHUNK = 1 << 20     # pixels x times computed at once inside log_intensity


def _pair(value, name: str, what: str) -> tuple[float, float]:
    """``value`` as two finite floats; else an EventDataError saying ``name`` must be ``what`` (one number for a
    pair was Python's "not iterable", three numbers numpy's broadcast error, NaN NaN frames)."""
    try:
        items = tuple(host_array(value)) if not isinstance(value, (str, bytes)) else ()
    except TypeError:
        items = ()
    if len(items) != 2 or not all(is_real_number(v) and np.isfinite(host_array(v)) for v in items):
        raise EventDataError(f"{name} must be {what}, got {value!r}")
    return float(host_array(items[0])), float(host_array(items[1]))


def check_intensity_range(intensity_range) -> tuple[float, float]:
    """(low, high) intensities with 0 < low < high, finite; else an EventDataError (low > 0 keeps the log finite)."""
    what = "(low, high) with 0 < low < high (low > 0 keeps log intensity finite)"
    lo, hi = _pair(intensity_range, "intensity_range", what)
    if not 0 < lo < hi:
        raise EventDataError(f"intensity_range must be {what}, got {intensity_range!r}")
    return lo, hi



def real_image(image) -> np.ndarray:
    """``image`` (an array, a list or a tensor) as a numpy array of real numbers (bool and integers too); complex
    and non-numeric images are refused by name (a cast to float dropped the imaginary part without a word)."""
    img = dense_array(image, "image", error=EventDataError, want="an image of one size [h, w] or [h, w, 3]")
    if img.dtype.kind == "c":
        raise EventDataError("image is complex; pass a real image (np.abs(image) or np.real(image), whichever you mean)")
    if img.dtype.kind not in "biuf":
        raise EventDataError(f"image must be numbers (intensities), got dtype {img.dtype}")
    return img


def _check_base(base, name: str = "base"):
    """``base`` when it is a scene (sensor_size, duration, log_intensity, max_speed); else an EventDataError."""
    missing = [a for a in ("sensor_size", "duration", "log_intensity", "max_speed") if not hasattr(base, a)]
    if missing:
        raise EventDataError(f"{name}= must be a Scene (it has no {', '.join(missing)}), got {type(base).__name__}; "
                             "build one with make_scene(name, sensor_size=(H, W), duration=seconds)")
    return base


class Scene:
    """Base class: a video defined at every time.

    Attributes:
        sensor_size: (H, W) pixels.
        duration: seconds; the scene is designed for t in [0, duration] (defined at any t).
        max_speed: upper bound on the image motion, pixels per second (sets simulation sampling).

    Subclasses implement :meth:`_log_intensity` for times [T] -> [T, H, W].
    """

    sensor_size: tuple[int, int]
    duration: float
    max_speed: float

    def __init__(self, sensor_size=(120, 160), duration: float = 2.0):
        self.sensor_size = check_sensor_size(sensor_size)
        if not (is_real_number(duration) and np.isfinite(duration) and duration > 0):
            raise EventDataError(f"duration must be a positive number of seconds, got {duration!r}")
        self.duration = float(duration)

    def log_intensity(self, t) -> np.ndarray:
        """Log intensity: float64 [H, W] for a scalar t (s), [T, H, W] for t of shape [T]."""
        try:
            arr = np.asarray(host_array(t)) if not isinstance(t, (str, bytes)) else None
        except (TypeError, ValueError):
            arr = None
        if arr is None or arr.dtype.kind not in "iuf":   # "0.1" was read as 0.1 s, a complex time Python's error
            raise EventDataError(f"t must be seconds (a number or a 1-D array of numbers), got {t!r:.60}")
        t = arr.astype(np.float64)
        if t.ndim > 1:
            raise EventDataError(f"t must be a scalar or a 1-D array of seconds, got shape {t.shape}")
        if not np.all(np.isfinite(t)):
            raise EventDataError("t contains NaN or inf; pass finite seconds")
        times = np.atleast_1d(t)
        H, W = self.sensor_size
        L = np.empty((times.size, H, W))
        chunk = max(1, _RENDER_CHUNK // (H * W))      # bounds the intermediates of _log_intensity
        for i in range(0, times.size, chunk):
            L[i:i + chunk] = self._log_intensity(times[i:i + chunk])
        return L[0] if t.ndim == 0 else L

    def intensity(self, t) -> np.ndarray:
        """exp(log_intensity(t)): float64 [H, W] or [T, H, W], values in (0, 1] for the defaults."""
        return np.exp(self.log_intensity(t))

    def frames(self, t) -> Frames:
        """Ground-truth :class:`Frames` (float32 intensities) at the times t [F] (s)."""
        t = np.atleast_1d(np.asarray(t, dtype=np.float64))
        return Frames(self.intensity(t).astype(np.float32), t)

    def _log_intensity(self, t: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def _grid(self) -> tuple[np.ndarray, np.ndarray]:
        """Pixel coordinates relative to the sensor centre, float64 [H, W] each: (x, y)."""
        H, W = self.sensor_size
        y, x = np.mgrid[0:H, 0:W].astype(np.float64)
        return x - (W - 1) / 2, y - (H - 1) / 2

    def __repr__(self) -> str:
        return f"{type(self).__name__}(sensor_size={self.sensor_size}, duration={self.duration})"


def load_image(image="camera") -> np.ndarray:
    """A grey image as float64 [h, w] in [0, 1] (min-max normalised).

    Args:
        image: a name from ``IMAGE_NAMES`` (scikit-image sample data; colour is converted to
            grey) or an array [h, w], [h, w, 3] or [h, w, 4] of any numeric range.
    """
    if isinstance(image, str):
        if image not in IMAGE_NAMES:
            raise EventDataError(f"unknown image {image!r}; use one of {IMAGE_NAMES} or pass an array")
        import skimage.data
        img = np.asarray(getattr(skimage.data, image)())
    else:
        img = real_image(image)
    if img.ndim == 3 and img.shape[-1] in (3, 4):
        from skimage.color import rgb2gray
        img = rgb2gray(img[..., :3])
    if img.ndim != 2 or min(img.shape) < 4:
        raise EventDataError(f"image must be grey [h, w] or colour [h, w, 3], at least 4x4; got shape {img.shape}")
    img = img.astype(np.float64)
    if not np.all(np.isfinite(img)):
        raise EventDataError("image contains NaN or inf")
    lo, hi = img.min(), img.max()
    if hi <= lo:
        raise EventDataError("image is constant; a moving constant image produces no events, use a textured one")
    return (img - lo) / (hi - lo)


class MovingImageScene(Scene):
    """A natural image moving in front of the sensor.

    At time t, with tau = t - duration / 2 (the image is centred at mid-sequence), the content
    seen at sensor position q (pixels from the sensor centre, (x, y)) is the image point

        q0 = R(-omega * tau) (q - v * tau) / exp(zoom * tau)

    i.e. the image translates at ``velocity`` v = (vx, vy) px/s, rotates at ``rotation`` omega
    rad/s (positive turns clockwise on screen, y pointing down) and scales by exp(zoom * tau)
    (``zoom`` > 0 grows), all about the sensor centre. Image point q0 maps to the source pixel
    ``source_centre + scale * q0``; outside the image, it is mirrored.

    Intensity: the image (blurred by ``blur`` sensor pixels, then min-max normalised) is mapped
    linearly to ``intensity_range`` (default [0.05, 1]), so log intensity lies in
    [log 0.05, 0] ~ [-3.0, 0] and is finite. The *log* image is sampled with cubic splines
    (``order=3``; 1 is bilinear), so L is smooth in space and time; cubic sampling can overshoot
    that range by a few hundredths near sharp edges (never to a non-finite value).

    Args:
        image: name from ``IMAGE_NAMES`` or an array (see :func:`load_image`).
        sensor_size: (H, W). duration: seconds.
        velocity: (vx, vy) px/s. rotation: rad/s. zoom: relative scale rate, 1/s.
        scale: source pixels per sensor pixel; default fits the sensor inside the central
            ~70 % of the image (``min(h / H, w / W) / 1.4``).
        blur: Gaussian blur sigma in sensor pixels (anti-aliasing and smoothness; 0 = none).
        intensity_range: (low, high) intensities, 0 < low < high.
        order: spline order for sampling, 1 (bilinear) or 3 (cubic).
    """

    def __init__(self, image="camera", sensor_size=(120, 160), duration=2.0, *, velocity=(24.0, 12.0),
                 rotation=0.15, zoom=0.1, scale=None, blur=0.75, intensity_range=(0.05, 1.0), order=3):
        super().__init__(sensor_size, duration)
        img = load_image(image)
        H, W = self.sensor_size
        self.velocity = _pair(velocity, "velocity", "(vx, vy) in px/s")
        self.rotation = real_number(rotation, "rotation", hint="rad/s")
        self.zoom = real_number(zoom, "zoom", hint="relative scale rate, 1/s")
        self.scale = (float(min(img.shape[0] / H, img.shape[1] / W) / 1.4) if scale is None else
                      real_number(scale, "scale", lo=0, lo_open=True, hint="source pixels per sensor pixel"))
        blur = real_number(blur, "blur", lo=0, hint="a Gaussian sigma in sensor pixels (0: none)")
        if order not in (1, 3):
            raise EventDataError(f"order must be 1 (bilinear) or 3 (cubic), got {order!r}")
        self.order = order
        self.blur = float(blur)
        self.intensity_range = check_intensity_range(intensity_range)
        if blur > 0:
            img = ndimage.gaussian_filter(img, sigma=blur * self.scale, mode="mirror")
        img = (img - img.min()) / max(img.max() - img.min(), 1e-12)
        lo, hi = self.intensity_range
        log_img = np.log(lo + (hi - lo) * img)
        # spline coefficients once, so each query is a plain (prefilter=False) evaluation
        self._coeffs = ndimage.spline_filter(log_img, order=order, mode="mirror") if order > 1 else log_img
        self._centre = ((img.shape[0] - 1) / 2, (img.shape[1] - 1) / 2)
        self._x, self._y = self._grid()
        self.image = img

    @property
    def max_speed(self) -> float:
        """Bound on image motion (px/s) over [0, duration]: |v| + (|omega| + |zoom|) * radius."""
        radius = np.hypot(*self.sensor_size) / 2 + np.hypot(*self.velocity) * self.duration / 2
        return float(np.hypot(*self.velocity) + (abs(self.rotation) + abs(self.zoom)) * radius)

    def _log_intensity(self, t: np.ndarray) -> np.ndarray:
        tau = t - self.duration / 2
        vx, vy = self.velocity
        c, s = np.cos(self.rotation * tau), np.sin(self.rotation * tau)
        k = (self.scale * np.exp(-self.zoom * tau))[:, None, None]
        dx = self._x[None] - vx * tau[:, None, None]
        dy = self._y[None] - vy * tau[:, None, None]
        c, s = c[:, None, None], s[:, None, None]
        cols = self._centre[1] + k * (c * dx + s * dy)       # R(-theta) applied to (dx, dy)
        rows = self._centre[0] + k * (-s * dx + c * dy)
        L = ndimage.map_coordinates(self._coeffs, [rows.ravel(), cols.ravel()], order=self.order,
                                    mode="mirror", prefilter=False)
        return L.reshape(t.size, *self.sensor_size)


class OscillatingScene(MovingImageScene):
    """A natural image swinging back and forth: bounded motion that can last minutes.

    The image offset (x, y) in sensor pixels is a sum of sinusoids,
    ``o(t) = sum_i a_i sin(2 pi t / T_i + phi_i)`` over ``path`` = ((ax, ay, T, phi), ...), and the
    image turns by ``rotation[0] sin(2 pi t / rotation[1])`` rad about the sensor centre. One slow
    component is a slider or a panning camera going to and fro (long recordings stay on the image);
    several fast ones are a hand-held camera's shake. Intensity and sampling as
    :class:`MovingImageScene`.

    Args:
        image, sensor_size, duration, scale, blur, intensity_range, order: as :class:`MovingImageScene`.
        path: ((ax px, ay px, period s, phase rad), ...), at least one component, periods > 0.
        rotation: (amplitude rad, period s); (0, 1) for none.
    """

    def __init__(self, image="camera", sensor_size=(120, 160), duration=2.0, *, path=((30.0, 10.0, 4.0, 0.0),),
                 rotation=(0.0, 1.0), scale=None, blur=0.75, intensity_range=(0.05, 1.0), order=3):
        super().__init__(image, sensor_size, duration, velocity=(0.0, 0.0), rotation=0.0, zoom=0.0, scale=scale,
                         blur=blur, intensity_range=intensity_range, order=order)
        path_what = "((ax, ay, period > 0, phase), ...) in px, s, rad"
        arr = dense_array(path, "path", error=EventDataError, want=path_what)
        if arr.dtype.kind not in "iuf" or arr.size == 0 or arr.size % 4:   # 3 numbers were numpy's reshape error
            raise EventDataError(f"path must be {path_what}; got {path!r}")
        self.path = arr.astype(np.float64).reshape(-1, 4)
        self.rot_amp, self.rot_period = _pair(rotation, "rotation", "(amplitude rad, period s > 0)")
        if not np.all(np.isfinite(self.path)) or np.any(self.path[:, 2] <= 0):
            raise EventDataError(f"path must be {path_what}; got {path!r}")
        if not self.rot_period > 0:
            raise EventDataError(f"rotation must be (amplitude rad, period s > 0), got {rotation!r}")

    def offset(self, t) -> np.ndarray:
        """Image offset (x, y) in sensor pixels at times t [T]: float64 [T, 2]."""
        t = np.atleast_1d(np.asarray(t, dtype=np.float64))
        a, T, phi = self.path[:, :2], self.path[:, 2], self.path[:, 3]
        return np.sin(2 * np.pi * t[:, None] / T[None] + phi[None]) @ a

    @property
    def max_speed(self) -> float:
        radius = np.hypot(*self.sensor_size) / 2 + np.abs(self.path[:, :2]).sum()
        v = np.sum(2 * np.pi * np.hypot(self.path[:, 0], self.path[:, 1]) / self.path[:, 2])
        return float(v + 2 * np.pi * abs(self.rot_amp) / self.rot_period * radius)

    def _log_intensity(self, t: np.ndarray) -> np.ndarray:
        o = self.offset(t)
        theta = self.rot_amp * np.sin(2 * np.pi * t / self.rot_period)
        c, s = np.cos(theta)[:, None, None], np.sin(theta)[:, None, None]
        dx = self._x[None] - o[:, 0, None, None]
        dy = self._y[None] - o[:, 1, None, None]
        cols = self._centre[1] + self.scale * (c * dx + s * dy)
        rows = self._centre[0] + self.scale * (-s * dx + c * dy)
        L = ndimage.map_coordinates(self._coeffs, [rows.ravel(), cols.ravel()], order=self.order,
                                    mode="mirror", prefilter=False)
        return L.reshape(t.size, *self.sensor_size)


class MovingBarScene(Scene):
    """A bright bar with soft tanh edges sweeping across a darker background.

    The bar is perpendicular to the direction ``angle`` (rad; 0 moves right along +x, pi/2
    moves down along +y) and its centre line is at signed distance ``d(t) = start + speed * t``
    from the sensor centre along that direction. With u the distance of a pixel along the
    direction, the intensity is

        I = background + (bar - background) * 0.5 * (tanh((u - d + width/2) / edge)
                                                      - tanh((u - d - width/2) / edge))

    Defaults: the bar enters just outside the sensor at t = 0 and leaves at t = duration.

    Args:
        sensor_size: (H, W). duration: seconds.
        speed: px/s (default: crosses the sensor in ``duration``). angle: rad.
        width: bar width, px. edge: edge softness, px (tanh scale; larger is smoother).
        intensities: (background, bar), both > 0.
        start: d at t = 0, px (default: the bar just outside the sensor).
    """

    def __init__(self, sensor_size=(120, 160), duration=2.0, *, speed=None, angle=0.3, width=12.0, edge=2.0,
                 intensities=(0.15, 0.9), start=None):
        super().__init__(sensor_size, duration)
        # each checked by name: a NaN angle or an infinite width or edge blamed "speed ... got None" (not given)
        self.angle = real_number(angle, "angle", hint="rad (0 moves right along +x)")
        self.width = real_number(width, "width", lo=0, lo_open=True, hint="the bar's width in pixels")
        self.edge = real_number(edge, "edge", lo=0, lo_open=True, hint="the edges' softness in pixels")
        what = "(background, bar), two finite intensities > 0"
        self.intensities = _pair(intensities, "intensities", what)
        if min(self.intensities) <= 0:
            raise EventDataError(f"intensities must be {what}, got {intensities!r}")
        x, y = self._grid()
        self._u = x * np.cos(self.angle) + y * np.sin(self.angle)
        reach = np.abs(self._u).max() + self.width / 2 + 3 * self.edge   # the bar is off-sensor beyond this
        self.start = -reach if start is None else real_number(start, "start", hint="px from the sensor centre at t = 0")
        self.speed = 2 * reach / self.duration if speed is None else real_number(speed, "speed", hint="px/s")

    @property
    def max_speed(self) -> float:
        return abs(self.speed)

    def _log_intensity(self, t: np.ndarray) -> np.ndarray:
        d = (self.start + self.speed * t)[:, None, None]
        u = self._u[None]
        half = self.width / 2
        profile = 0.5 * (np.tanh((u - d + half) / self.edge) - np.tanh((u - d - half) / self.edge))
        bg, bar = self.intensities
        return np.log(bg + (bar - bg) * profile)


class VaryingSpeedScene(Scene):
    """``base`` played at a varying speed: L(t) = base.L(s(t)), s(t) = t + depth sin(w t) / w, w = 2 pi / period.

    The playback speed s'(t) = 1 + depth cos(2 pi t / period) swings between 1 - depth and 1 + depth,
    so the event rate rises and falls with it (0 <= depth < 1).
    """

    def __init__(self, base: Scene, depth: float = 0.8, period: float = 2.0):
        super().__init__(_check_base(base).sensor_size, base.duration)
        if not (is_real_number(depth) and 0 <= float(host_array(depth)) < 1):
            raise EventDataError(f"depth= must be a finite number in [0, 1) so that time keeps running forward, got "
                                 f"{depth!r}")
        depth = float(host_array(depth))
        period = real_number(period, "period", lo=0, lo_open=True, hint="seconds (an infinite one gave NaN frames)")
        self.base, self.depth, self.period = base, depth, period

    def warp(self, t) -> np.ndarray:
        """s(t): the base scene's time shown at time t (seconds)."""
        w = 2 * np.pi / self.period
        return np.asarray(t, dtype=np.float64) + self.depth * np.sin(w * np.asarray(t, dtype=np.float64)) / w

    def speed(self, t) -> np.ndarray:
        """s'(t): playback speed relative to the base scene."""
        return 1 + self.depth * np.cos(2 * np.pi * np.asarray(t, dtype=np.float64) / self.period)

    @property
    def max_speed(self) -> float:
        return float(self.base.max_speed) * (1 + self.depth)

    def _log_intensity(self, t: np.ndarray) -> np.ndarray:
        return self.base.log_intensity(self.warp(t))


class WarpedImageScene(MovingImageScene):
    """A :class:`MovingImageScene` seen through a shear and a perspective tilt that grow over time.

    Before the moving image's own mapping, sensor position q = (x, y) (pixels from the centre) is
    mapped by the homography with tau = t - duration / 2 (r: half the sensor diagonal):

        x' = (x + shear[0] tau y) / w,   y' = (y + shear[1] tau x) / w,   w = 1 + (tilt[0] x + tilt[1] y) tau / r

    so straight lines stay straight while the view shears (1/s) and tilts (1/s) like a camera
    turning towards a plane. All other arguments are :class:`MovingImageScene`'s.
    """

    def __init__(self, image="camera", sensor_size=(120, 160), duration=2.0, *, shear=(0.15, 0.0),
                 tilt=(0.2, 0.0), **kwargs):
        super().__init__(image, sensor_size, duration, **kwargs)
        what = "(x, y) pairs of finite rates (1/s)"
        try:
            self.shear, self.tilt = _pair(shear, "shear", what), _pair(tilt, "tilt", what)
        except EventDataError:
            raise EventDataError(f"shear and tilt must be {what}, got {shear!r}, {tilt!r}") from None
        self._r = float(np.hypot(*self.sensor_size) / 2)
        if max(abs(v) for v in self.tilt) * self.duration / 2 >= 0.5:
            raise EventDataError(f"tilt {tilt} over {duration} s folds the view; keep |tilt| * duration / 2 below 0.5")

    @property
    def max_speed(self) -> float:
        extra = (abs(self.shear[0]) + abs(self.shear[1]) + 2 * (abs(self.tilt[0]) + abs(self.tilt[1]))) * self._r
        return super().max_speed + float(extra)

    def _log_intensity(self, t: np.ndarray) -> np.ndarray:
        tau = (t - self.duration / 2)[:, None, None]
        x, y = self._x[None], self._y[None]
        w = 1 + (self.tilt[0] * x + self.tilt[1] * y) * tau / self._r
        xw, yw = (x + self.shear[0] * tau * y) / w, (y + self.shear[1] * tau * x) / w
        gx, gy = self._x, self._y
        out = np.empty((t.size, *self.sensor_size))
        try:                                    # the parent's mapping, on the warped grid
            for k in range(t.size):
                self._x, self._y = xw[k], yw[k]
                out[k] = super()._log_intensity(t[k:k + 1])[0]
        finally:
            self._x, self._y = gx, gy
        return out


class ObjectOverBackgroundScene(Scene):
    """A static camera: a textured object moving over a static textured background.

    The background is ``background`` (an image name or array) at rest; the object is a disc of
    ``radius`` pixels cut from ``object_image``, with a soft edge of ``edge`` pixels, whose centre
    moves from ``start`` to ``end`` (pixels from the sensor centre) over the duration. Where the
    object is, L = log of the object's texture; elsewhere the background's. Events come only from the
    object and the background it uncovers: the background's static structure is invisible to events.
    """

    def __init__(self, background="brick", object_image="coffee", sensor_size=(120, 160), duration=2.0, *,
                 radius=None, edge=2.0, start=None, end=None, blur=0.75, intensity_range=(0.05, 1.0)):
        super().__init__(sensor_size, duration)
        H, W = self.sensor_size
        # finite pixels > 0 by name (None and text were Python's float() errors, an infinite radius or edge made
        # start/end of inf and a NaN scene, True a disc of 1 pixel)
        self.radius = float(min(H, W) / 4) if radius is None else \
            real_number(radius, "radius", lo=0, lo_open=True, hint="the disc's radius in pixels (None: a quarter of the sensor)")
        self.edge = real_number(edge, "edge", lo=0, lo_open=True, hint="the disc's soft edge in pixels")
        what = "(x, y): finite pixels from the sensor centre"
        try:   # 3 numbers were numpy's broadcast error, NaN gave NaN frames
            self.start = np.asarray((-W / 2 + self.radius, -H / 6) if start is None else _pair(start, "start", what))
            self.end = np.asarray((W / 2 - self.radius, H / 6) if end is None else _pair(end, "end", what))
        except EventDataError:
            raise EventDataError(f"start and end must be {what}, got {start!r}, {end!r}") from None
        still = dict(velocity=(0.0, 0.0), rotation=0.0, zoom=0.0, blur=blur, intensity_range=intensity_range)
        self._background = MovingImageScene(background, sensor_size, duration, **still).log_intensity(0.0)
        self._object = MovingImageScene(object_image, sensor_size, duration, **still)
        self._x, self._y = self._grid()

    @property
    def max_speed(self) -> float:
        return float(np.hypot(*(self.end - self.start)) / self.duration)

    def _log_intensity(self, t: np.ndarray) -> np.ndarray:
        frac = (t / self.duration)[:, None]
        centre = self.start[None] + frac * (self.end - self.start)[None]             # [T, 2] (x, y)
        dx = self._x[None] - centre[:, 0, None, None]
        dy = self._y[None] - centre[:, 1, None, None]
        mask = 0.5 * (1 - np.tanh((np.hypot(dx, dy) - self.radius) / self.edge))       # 1 inside the disc
        out = np.empty((t.size, *self.sensor_size))
        obj = self._object
        for k in range(t.size):                 # the object's texture travels with it
            gx, gy = obj._x, obj._y
            try:
                obj._x, obj._y = self._x - centre[k, 0], self._y - centre[k, 1]
                L_obj = obj._log_intensity(np.array([obj.duration / 2]))[0]
            finally:
                obj._x, obj._y = gx, gy
            out[k] = (1 - mask[k]) * self._background + mask[k] * L_obj
        return out


class LightingScene(Scene):
    """``base`` under changing light: L(t) = base.L(t) + s (global + vignette * r^2 / r_max^2),
    with s = t / duration - 1/2, r the distance from the sensor centre.

    ``global_change``: the log intensity added over the whole duration everywhere (e.g. 0.5: the
    light grows by a factor e^0.5); ``vignette``: the log intensity added at the corners over the
    duration (negative: the corners darken). A change of light is a change of log intensity that
    events record like any other.
    """

    def __init__(self, base: Scene, global_change: float = 0.4, vignette: float = -0.5):
        super().__init__(_check_base(base).sensor_size, base.duration)
        self.base = base
        # finite numbers by name (None, text and lists were Python's float() errors; True was a change of 1)
        self.global_change = real_number(global_change, "global_change", hint="a log intensity added over the duration")
        self.vignette = real_number(vignette, "vignette", hint="a log intensity added at the corners over the duration")
        x, y = self._grid()
        self._shape = self.global_change + self.vignette * (x ** 2 + y ** 2) / (x ** 2 + y ** 2).max()

    @property
    def max_speed(self) -> float:
        return float(self.base.max_speed)

    def _log_intensity(self, t: np.ndarray) -> np.ndarray:
        s = (t / self.duration - 0.5)[:, None, None]
        return self.base.log_intensity(t) + s * self._shape[None]


def make_scene(name="camera", sensor_size=(120, 160), duration=2.0, **kwargs) -> Scene:
    """A named synthetic scene with pleasant smooth defaults.

    Args:
        name: one of ``IMAGE_NAMES`` (a :class:`MovingImageScene` of that image) or ``'bar'``
            (a :class:`MovingBarScene`).
        sensor_size: (H, W). duration: seconds.
        **kwargs: passed to the scene class (e.g. velocity, rotation, zoom, blur for images;
            speed, angle, width for the bar).
    """
    if not isinstance(name, str) or (name != "bar" and name not in IMAGE_NAMES):
        raise EventDataError(f"unknown scene {name!r}; use one of {SCENE_NAMES}")
    cls = MovingBarScene if name == "bar" else MovingImageScene
    signature = inspect.signature(cls.__init__).parameters
    params = [k for k, v in signature.items() if k not in ("self", "image", "sensor_size", "duration")
              and v.kind is inspect.Parameter.KEYWORD_ONLY]
    unknown = sorted(set(kwargs) - set(params))
    if unknown:
        raise ArgumentTypeError(f"make_scene({name!r}) got unknown parameter(s) {unknown}; a {cls.__name__} takes "
                                f"{', '.join(params)} (and sensor_size, duration)")
    if name == "bar":
        return MovingBarScene(sensor_size, duration, **kwargs)
    return MovingImageScene(name, sensor_size, duration, **kwargs)
