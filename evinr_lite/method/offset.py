"""The per-pixel offset that events cannot fix, chosen explicitly: the ghost solved.

Events constrain only changes of log intensity, so any image g(x, y) can be added to every frame
of a reconstruction without changing a single loss term of the events. Training leaves g to the
spatial regularizer, which moves it slowly under Adam (a smooth, low-frequency ghost) and, once
converged, picks the worst image for a moving scene: with Tikhonov, sum_t |D(F_t + g)|^2 is
smallest for g = -mean_t F_t (up to a constant), which subtracts the temporal mean image from
every frame (notebook 05 shows it).

A better rule for moving scenes: natural images have sparse gradients, and a pixel that sees a
moving scene sees an edge only now and then, so the *median* over time of the true frames'
gradients at a pixel is near zero, while the reconstruction's gradient there is off by the
gradient of the unknown offset. :func:`median_gradient_offset` therefore takes as the offset's
gradient minus the temporal median of the frames' gradients, and integrates that gradient field
in the least-squares sense (a Poisson equation with Neumann borders, solved exactly with the
DCT). For a static background the median is the background's own gradient, which is removed
(events never see it; an APS frame would be needed). One convex solve on one H x W image.

On a long recording one image is not enough: what the events get wrong builds up slowly and
differently at every pixel (a threshold that drifts with temperature, per-pixel mismatch of C+
and C-, background activity's random walk), so the offset that makes the median gradient zero
over the first seconds is not the one over the last. :func:`offset_trend` therefore
solves one image per ``window`` seconds of the span (from the frames within ``window`` of its
knot) and interpolates them linearly in time (:class:`OffsetTrend`): a slow per-pixel trend,
part of the method rather than a patch applied afterwards. On spans up to about 1.5 windows it is
the single image above.

The median is taken edge by edge, and the least-squares integration then bends the per-edge
answers into one image. :func:`l1_gradient_offset` (``offset_solve="l1_gradient"``) solves the
objective behind the median jointly instead: the image g whose addition makes all frames' gradients
sparsest in total, min_g sum_k |D (F_k + g)|_1, with D the forward differences. It is convex; ADMM
splits it into an exact proximal step per edge (over that edge's K values) and the same DCT Poisson
solve per iteration, at about the median's time (1.5-2.5x before 2026-12-06; docs/scale.md).

A static camera (``EvINRConfig(camera="static")``, ``rest=`` here) breaks the sparse-gradient rule's
premise. A pixel the moving object never covers fires no event, and one it covers rests before and
after: the events see nothing of the background at rest, so the frames there show only the offset g,
and sum_k |D (F_k + g)| is smallest for a flat g: the background is removed, and while the object
covers a pixel the frame shows the object *minus* the background. Where the object passed, though,
F_k + g must show the object, a natural image with sparse gradients, and that happens only for g =
the background. So with ``rest`` (log units) each edge's term counts only the frames in which both
of its pixels lie more than ``rest`` from their own temporal medians (something moved over the
edge); an edge nothing moved over keeps every frame (a flat offset, the best guess there). Exact in
the L1 objective: a left-out frame's value is replaced by +M or -M in pairs (|z - M| + |z + M| = 2 M
is constant on [-M, M]). :func:`offset_image` takes from that solve only the structure finer than
``STATIC_COARSE_PX`` and the coarser from the plain one. On a moving camera every frame is
informative and leaving the resting ones out biases each edge towards the frames where an edge
passes (camera_translate 0.744 -> 0.613 CLAHE-SSIM), hence an option the user sets, not a default.
"""
from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
import scipy.fft

from ..core.checks import (ArgumentTypeError, choice, decimal_as_float, numbers_array, real_number, seconds_array,
                           whole_number)
from ..core.events import EventDataError
from ..core.runtime import cpu_threads
from .head_solve import laplacian_eigenvalues_unchecked

__all__ = ["median_gradient_offset", "l1_gradient_offset", "SumAbsProx", "offset_image", "poisson_integrate",
           "offset_trend", "trend_intervals", "trend_knots", "OffsetTrend", "offset_grid", "MIN_TREND_FRAMES", "OFFSET_SOLVES",
           "STATIC_REST", "STATIC_COARSE_PX", "gaussian_lowpass",
           "gaussian_lowpass_unchecked", "MAX_SIGMA_PX"]

MIN_TREND_FRAMES = 8     # a knot's median looks at least at this many grid frames (the nearest, if its window holds fewer)
OFFSET_SOLVES = ("none", "median_gradient", "l1_gradient")
L1_MAX_ITERS = 20        # ADMM iterations at most: over-relaxed, 20 are within 0.0003 of 200 on the zoo means (docs/defaults.md)
L1_TOL = 1e-3            # ... or stop once no pixel of g moves by more than this share of the mean |gradient|
L1_RHO = 10.0            # ADMM's penalty, in units of 1 / (mean |gradient|): sets the speed, not the answer
L1_RELAX = 1.6           # ADMM's over-relaxation (1.5-1.8 is the usual range): the speed again, not the answer
STATIC_REST = 0.5        # camera="static": a pixel rests within this share of C of its temporal median (the events
                         # step by C; the INR's frames stay within a small part of one C where no event came)
STATIC_COARSE_PX = 8.0   # camera="static": the rest solve sets the offset's structure finer than this (a Gaussian's
                         # sigma, px; offset_coarse_px's default), the plain solve the coarser, which the rest solve
                         # ties to the untouched background only through an object's path's rim
LEFT_OUT = 1e6           # +-M for a left-out frame's value (times the values' scale): far outside any gradient


def _numbers(value, name: str, what: str) -> np.ndarray:
    """``value`` as an array of finite numbers (any shape, its dtype kept; ``what``: what it must be, in the
    message); None, text, booleans, NaN or inf were numpy's or Python's errors, or came out as NaN without a word."""
    arr = numbers_array(value, name, what)
    if arr.dtype.kind == "f" and arr.size and not (np.isfinite(arr.min()) and np.isfinite(arr.max())):
        n_bad = int((~np.isfinite(arr)).sum())
        raise EventDataError(f"{name}= holds {n_bad:,} NaN or infinite value(s); the result would be NaN: repair "
                             f"or drop them")
    return arr


def _log_stack(frames, name: str = "frames") -> np.ndarray:
    """``frames`` as the [K, H, W] log intensities of the offset solves (at least one frame of one pixel, finite);
    its dtype kept. None or text were "got shape ()", NaN gave a NaN offset."""
    F = _numbers(frames, name, "log intensities [K, H, W]")
    if F.ndim != 3 or min(F.shape) < 1:
        raise EventDataError(f"{name}= must be [K, H, W] log intensities (at least one frame of at least one "
                             f"pixel), got shape {F.shape}" + ("; one image [H, W] is frames[None]"
                                                               if F.ndim == 2 else ""))
    return F


def poisson_integrate(gx: np.ndarray, gy: np.ndarray) -> np.ndarray:
    """The image g [H, W] whose forward differences best match (gx [H, W-1], gy [H-1, W]) in least
    squares: (Dx^T Dx + Dy^T Dy) g = Dx^T gx + Dy^T gy, solved with the DCT; mean(g) = 0.

    gx and gy are checked: finite numbers, 2-D, of the shapes of one H x W image's differences (None or text were
    AttributeErrors, shapes that disagree numpy's broadcast errors, NaN a NaN image)."""
    gx = _numbers(gx, "gx", "the x differences [H, W-1]")
    gy = _numbers(gy, "gy", "the y differences [H-1, W]")
    if gx.ndim != 2 or gy.ndim != 2 or gy.shape != (gx.shape[0] - 1, gx.shape[1] + 1):
        raise EventDataError(f"gx and gy must be the differences of one H x W image, gx [H, W-1] and gy [H-1, W], "
                             f"got shapes {gx.shape} and {gy.shape}; e.g. gx = np.diff(img, axis=1), "
                             "gy = np.diff(img, axis=0)")
    return _integrate(gx, gy)


def _integrate(gx: np.ndarray, gy: np.ndarray) -> np.ndarray:
    """:func:`poisson_integrate` without its checks (the solves' own differences)."""
    H, W = gx.shape[0], gy.shape[1]
    div = np.zeros((H, W))
    div[:, :-1] -= gx
    div[:, 1:] += gx
    div[:-1, :] -= gy
    div[1:, :] += gy
    mu = laplacian_eigenvalues_unchecked((H, W))
    mu[0, 0] = 1.0
    g = scipy.fft.dctn(div, type=2, norm="ortho", workers=cpu_threads()) / mu
    g[0, 0] = 0.0
    return scipy.fft.idctn(g, type=2, norm="ortho", workers=cpu_threads())


def gaussian_lowpass(image, sigma_px: float) -> np.ndarray:
    """``image`` [H, W] blurred by a Gaussian of ``sigma_px`` pixels, its borders mirrored: float64. In the
    DCT-II basis (the mirrored image's Fourier basis) each coefficient is multiplied by the Gaussian's
    transfer function exp(-sigma^2 (wx^2 + wy^2) / 2), w = pi k / N the frequency along each axis. From
    2 px on it is scipy.ndimage.gaussian_filter(mode="reflect") to 1e-9 (below, sampling its kernel aliases)."""
    img = _numbers(image, "image", "an image [H, W]")
    if img.ndim != 2 or img.size == 0:
        raise EventDataError(f"image= must be one image [H, W] of at least one pixel, got shape {img.shape}")
    sigma_px = real_number(sigma_px, "sigma_px", lo=0, hint="the Gaussian's standard deviation in pixels")
    return gaussian_lowpass_unchecked(img, sigma_px)


MAX_SIGMA_PX = 1e100   # a Gaussian this wide keeps only the mean (every other gain underflows to 0); sigma^2 fits


def gaussian_lowpass_unchecked(image, sigma_px: float) -> np.ndarray:
    """:func:`gaussian_lowpass` without its checks (the solves' own images, which may hold a diverged network's
    NaN: the caller's result check names that). A sigma above MAX_SIGMA_PX blurs as MAX_SIGMA_PX does (to the
    image's mean): its square overflowed (Python's OverflowError at 1e200)."""
    img = np.asarray(image, np.float64)
    sigma_px = min(sigma_px, MAX_SIGMA_PX)
    H, W = img.shape
    wy, wx = np.pi * np.arange(H) / H, np.pi * np.arange(W) / W
    gain = np.exp(-0.5 * sigma_px ** 2 * (wy[:, None] ** 2 + wx[None, :] ** 2))
    c = scipy.fft.dctn(img, type=2, norm="ortho", workers=cpu_threads())
    return scipy.fft.idctn(c * gain, type=2, norm="ortho", workers=cpu_threads())


def median_gradient_offset(frames) -> np.ndarray:
    """The offset g [H, W] (float64, mean 0) to add to every frame of ``frames`` [K, H, W] (log
    intensities over the sequence) so that the temporal median of each pixel's gradient is zero."""
    return _median_gradient(_log_stack(frames))


def _median_gradient(frames) -> np.ndarray:
    """:func:`median_gradient_offset` without its checks (:func:`offset_image`: the solver's own frames)."""
    frames = np.asarray(frames)
    if frames.ndim != 3 or frames.shape[0] < 1:
        raise EventDataError(f"frames must be [K, H, W] log intensities, got shape {frames.shape}")
    # a block of rows at a time, with time as the contiguous axis: the same float64 differences and
    # medians as on the whole stack, a few times faster, and work arrays of one block (about 2 M
    # cells) instead of three float64 copies of the stack (which matters at HD, where K is 64 or more)
    K, H, W = frames.shape
    rows = max(1, (1 << 21) // max(K * W, 1))
    gx = np.empty((H, W - 1))
    gy = np.empty((H - 1, W))

    def block_medians(r0: int) -> None:
        r1 = min(H, r0 + rows)
        block = np.asarray(frames[:, r0:min(H, r1 + 1)], dtype=np.float64)   # one extra row for dy
        dx = np.moveaxis(np.diff(block[:, :r1 - r0], axis=2), 0, -1)          # [rows, W - 1, K]
        gx[r0:r1] = -np.median(np.ascontiguousarray(dx), axis=-1)
        if r1 - r0 + (r1 < H) > 1:
            dy = np.moveaxis(np.diff(block, axis=1), 0, -1)                   # [rows (- 1 at the end), W, K]
            gy[r0:r0 + dy.shape[0]] = -np.median(np.ascontiguousarray(dy), axis=-1)

    starts = range(0, H, rows)
    # numpy's median releases the GIL: the blocks run on the kit's threads (the same numbers on any count)
    with ThreadPoolExecutor(max(1, min(len(starts), cpu_threads()))) as pool:
        list(pool.map(block_medians, starts))
    return _integrate(gx, gy)


class SumAbsProx:
    """The proximal step of f_e(z) = sum_k |z - b_ek| (one convex, piecewise-linear function per edge e)
    with penalty rho, for every edge at once: argmin_z f_e(z) + rho / 2 (z - w_e)^2.

    Between two sorted breakpoints, z = w - (2 j - K) / rho, with j the number of b_ek below z; the answer
    is that z for the smallest j with z <= b_(j+1) (the sorted values, 1-based), pushed up to b_(j) when it
    falls below it. Put c_j = b_(j+1) + (2 j - K) / rho, increasing in j: then j is the number of c_j below
    w (c_(j-1) < w <= c_j), found by bisection. Between ADMM iterations w moves little, so last iteration's
    j is checked first (against c_(j-1) and c_j, kept beside j) and only the edges whose j moved are searched
    again. Memory: float32 [E, K + 2], each row -inf, c_0 .. c_(K-1), +inf (the two ends spare every test for
    j = 0 and j = K), and 16 bytes per edge for j, c_(j-1) and c_j."""

    def __init__(self, values: np.ndarray, rho: float):
        # values: float32 [E, K + 2], each edge's K values b_ek in columns 1..K (sorted here, in place)
        E, K2 = values.shape
        self.K = K = K2 - 2
        steps = (2 * np.arange(K + 1) - K) / rho                               # (2 j - K) / rho, j = 0..K
        self.steps = steps.astype(np.float32)
        self.steps_before = np.concatenate([[0.0], steps[:-1]]).astype(np.float32)   # (2 (j - 1) - K) / rho
        self.s = values
        self.s[:, 1:K + 1].sort(axis=1)
        self.median = 0.5 * (self.s[:, 1 + (K - 1) // 2].astype(np.float64) + self.s[:, 1 + K // 2])
        self.s[:, 1:K + 1] += self.steps[:K]
        self.s[:, 0], self.s[:, K + 1] = -np.inf, np.inf
        self.flat = self.s.reshape(-1)
        self.row = np.arange(E, dtype=np.int64) * K2
        self.j = self.c_lo = self.c_hi = None          # each edge's j, c_(j-1) and c_j, from the first call on

    def _bisect(self, w: np.ndarray, row: np.ndarray) -> np.ndarray:
        # the smallest j in [0, K] with w <= c_j (c_j sits in column j + 1)
        lo, hi = np.zeros(len(w), np.int64), np.full(len(w), self.K, np.int64)
        row = row + 1
        for _ in range(int(np.ceil(np.log2(self.K + 1)))):
            mid = (lo + hi) >> 1
            below = w <= self.flat[row + mid]
            hi, lo = np.where(below, mid, hi), np.where(below, lo, mid + 1)
        return hi

    def __call__(self, w: np.ndarray) -> np.ndarray:
        w = np.asarray(w, np.float32)
        if self.j is None:
            self.j = self._bisect(w, self.row)
            idx = self.row + self.j
            self.c_lo, self.c_hi = self.flat[idx], self.flat[idx + 1]
        else:                                       # last iteration's j where it still holds: c_(j-1) < w <= c_j
            moved = np.flatnonzero((w <= self.c_lo) | (w > self.c_hi))
            if moved.size:
                self._search(w, moved)
        # z = w - (2 j - K) / rho, pushed up to b_(j) = c_(j-1) - (2 (j - 1) - K) / rho (-inf for j = 0)
        z = w - self.steps[self.j]
        return np.maximum(z, self.c_lo - self.steps_before[self.j], out=z)

    def _search(self, w: np.ndarray, moved: np.ndarray) -> None:
        """j, c_(j-1) and c_j again for the ``moved`` edges. Most moved by one since the last iteration, so
        j - 1 and j + 1 are tried first (one look-up each), and only the rest are bisected."""
        wm, base = w[moved], self.row[moved] + self.j[moved]
        down = wm <= self.c_lo[moved]                                  # w <= c_(j-1): j is smaller
        # one step down holds when c_(j-2) < w (column j - 1; -inf for j = 1), one up when w <= c_(j+1)
        # (column j + 2; +inf for j = K - 1): either way the same unique j as a bisection
        near = np.where(down, wm > self.flat[base - down], wm <= self.flat[base + 2 - 2 * down])
        j = self.j[moved] + np.where(down, -1, 1)
        far = ~near
        if far.any():
            j[far] = self._bisect(wm[far], self.row[moved[far]])
        self.j[moved] = j
        idx = self.row[moved] + j
        self.c_lo[moved], self.c_hi[moved] = self.flat[idx], self.flat[idx + 1]


class _EdgeSplit:
    """One direction's ADMM variables (z, the scaled dual u) over its edges, float32 [E]."""

    def __init__(self, prox: SumAbsProx, dg: np.ndarray):
        self.prox, self.z = prox, dg.astype(np.float32).ravel()
        self.u = np.zeros_like(self.z)

    def step(self, dg: np.ndarray) -> np.ndarray:
        """One iteration from D g (this direction's differences of the current offset): returns z - u
        (float64 [E]), what the Poisson step integrates."""
        # over-relaxed ADMM (h = a D g + (1 - a) z, a = L1_RELAX): the same fixed point, fewer iterations
        h = dg.astype(np.float32).ravel()
        h *= L1_RELAX
        h += (1 - L1_RELAX) * self.z
        self.z = self.prox(h + self.u)
        h -= self.z
        self.u += h
        return (self.z - self.u).astype(np.float64)


def _edge_values(F: np.ndarray, axis: int) -> tuple[np.ndarray, float]:
    """float32 [E, K + 2]: the K frames' -(forward differences along ``axis`` of F [K, H, W]) per edge
    (E edges, row-major) in columns 1..K, the two end columns left for :class:`SumAbsProx`; and the mean
    |difference| (float). A block of image rows at a time (no float64 copy of F, no second E x K array,
    and each block's transpose stays in cache)."""
    K, H, W = F.shape
    width = W - 1 if axis == 2 else W
    n_rows = H if axis == 2 else H - 1
    out = np.empty((n_rows * width, K + 2), np.float32)
    total = 0.0
    rows = max(1, (1 << 18) // max(K * width, 1))
    for r0 in range(0, n_rows, rows):
        r1 = min(n_rows, r0 + rows)
        block = np.asarray(F[:, r0:r1 + (axis == 1)], np.float32)
        d = np.diff(block, axis=axis)
        total += float(np.abs(d).sum(dtype=np.float64))
        out[r0 * width:r1 * width, 1:K + 1] = -d.reshape(K, -1).T
    return out, total / max(out.shape[0] * K, 1)


def _moved(F: np.ndarray, rest: float) -> np.ndarray:
    """bool [K, H, W]: where a pixel of F [K, H, W] lies more than ``rest`` from its own temporal median (a
    block of image rows at a time: float32 work arrays of about 2 M cells, whatever the sensor)."""
    if isinstance(rest, (bool, np.bool_)) or not (isinstance(rest, (int, float, np.floating)) and rest > 0
                                                   and np.isfinite(rest)):
        raise EventDataError(f"rest must be a positive number of log units or None, got {rest!r}")
    K, H, W = F.shape
    out = np.empty((K, H, W), bool)
    rows = max(1, (1 << 21) // max(K * W, 1))
    for r0 in range(0, H, rows):
        block = np.asarray(F[:, r0:r0 + rows], np.float32)
        out[:, r0:r0 + rows] = np.abs(block - np.median(block, axis=0)) > rest
    return out


def _leave_out_rest(values: np.ndarray, moved: np.ndarray, axis: int, scale: float) -> None:
    """In place: each edge's frames at rest (neither pixel ``moved``, bool [K, H, W]) in ``values``
    (:func:`_edge_values`' [E, K + 2]) become -M and +M in pairs, which add a constant to the edge's term
    on [-M, M] and move neither its median nor its proximal step. An odd one out takes the median of the
    edge's other frames, which leaves that median where it was and makes it unique. An edge that nothing
    moved over keeps all its frames: they all show the offset alone, and a flat one is the best guess there.
    A block of edge rows at a time (work arrays of about 2 M cells)."""
    K, H, W = moved.shape
    width, n_rows = (W - 1, H) if axis == 2 else (W, H - 1)
    M = np.float32(LEFT_OUT * max(scale, 1e-12))
    rows = max(1, (1 << 21) // max(K * width, 1))
    for r0 in range(0, n_rows, rows):
        r1 = min(n_rows, r0 + rows)
        if axis == 2:
            m = moved[:, r0:r1, :-1] & moved[:, r0:r1, 1:]
        else:
            m = moved[:, r0:r1, :] & moved[:, r0 + 1:r1 + 1, :]
        rest = ~m.reshape(K, -1).T                                    # [edges of these rows, K]
        rest &= ~rest.all(axis=1, keepdims=True)                      # an edge nothing moved over keeps every frame
        block = values[r0 * width:r1 * width, 1:K + 1]
        odd = np.flatnonzero(rest.sum(axis=1) % 2 == 1)               # each has a frame that moved (see above)
        if odd.size:                                                  # the median of the frames that moved
            centre = np.nanmedian(np.where(rest[odd], np.float32(np.nan), block[odd]), axis=1)
        order = np.cumsum(rest, axis=1, dtype=np.int32)               # 1, 2, ... along each edge's resting frames
        block[rest] = np.where(order[rest] % 2 == 0, M, -M)
        if odd.size:
            last = np.argmax(np.where(rest[odd], order[odd], 0), axis=1)   # each odd edge's last resting frame
            block[odd, last] = centre


def l1_gradient_offset(frames, max_iters: int = L1_MAX_ITERS, tol: float = L1_TOL, rest: float | None = None) -> np.ndarray:
    """The offset g [H, W] (float64, mean 0) that minimises sum_k |D (F_k + g)|_1 over ``frames`` [K, H, W]
    (log intensities): the frames' gradients, all of them together, as sparse as an offset can make them.

    The objective is a sum over edges e of f_e((D g)_e), f_e(z) = sum_k |z + (D F_k)_e|, whose minimiser
    edge by edge is minus the median (:func:`median_gradient_offset`'s answer before its integration).
    ADMM on z = D g, over-relaxed: h = a D g + (1 - a) z, z = prox of f / rho at h + u (exact, by a
    bisection over each edge's sorted values: :class:`SumAbsProx`), u += h - z, g = the least-squares
    integral of z - u (:func:`poisson_integrate`). It starts from the median answer and stops after
    ``max_iters`` iterations or once no pixel moves by more than ``tol`` x the mean |gradient|. rho and a
    set how fast it gets there, not where (the problem is convex). Cost: one sort of each edge's K values,
    then per iteration a few passes over the edges (x and y on two threads) and one DCT solve; about the
    median's time (0.06 s against 0.10 s at 64 x 180 x 240, 1.5 s against 1.4 s at 64 x 720 x 1280, 2 cores).
    Memory: float32 [K + 2] per edge in x and y, 12 bytes per frame and pixel at its peak (tracemalloc).

    ``rest``: None (every frame counts), or log units: each edge's term counts only the frames where one
    of its pixels lies more than ``rest`` from its temporal median (a static camera; the module's
    docstring); the frames' median image [H, W] is one more float32 image in memory."""
    F = _log_stack(frames)
    max_iters = whole_number(max_iters, "max_iters", lo=0)
    tol = real_number(tol, "tol", lo=0, hint="a share of the mean |gradient| (e.g. 1e-3)")
    return _l1_gradient(F, max_iters, tol, rest)


def _l1_gradient(frames, max_iters: int = L1_MAX_ITERS, tol: float = L1_TOL, rest: float | None = None) -> np.ndarray:
    """:func:`l1_gradient_offset` without its checks (:func:`offset_image`: the solver's own frames, which may
    hold a diverged network's NaN; the solver's result check names that, with the settings to change)."""
    F = np.asarray(frames)
    if F.ndim != 3 or F.shape[0] < 1:
        raise EventDataError(f"frames must be [K, H, W] log intensities, got shape {F.shape}")
    K, H, W = F.shape
    if H < 2 or W < 2:                              # no edges in one direction: the median answer
        return _median_gradient(F)
    # x and y edges are independent until the Poisson step: two threads (numpy releases the GIL), the
    # same numbers on any count
    with ThreadPoolExecutor(2 if cpu_threads() >= 2 else 1) as pool:
        both = lambda fx, fy: [f.result() for f in (pool.submit(fx), pool.submit(fy))]   # noqa: E731
        (bx, mx), (by, my) = both(lambda: _edge_values(F, 2), lambda: _edge_values(F, 1))
        # the mean, not the median: integrated events are flat at most pixels, so their median |gradient| is 0
        scale = (mx + my) / 2
        if rest is not None:                        # a static camera: the frames at rest leave each edge's term
            moved = _moved(F, rest)
            both(lambda: _leave_out_rest(bx, moved, 2, scale), lambda: _leave_out_rest(by, moved, 1, scale))
        rho = K * L1_RHO / scale if scale > 0 else 1.0
        px, py = both(lambda: SumAbsProx(bx, rho), lambda: SumAbsProx(by, rho))
        g = _integrate(px.median.reshape(H, W - 1), py.median.reshape(H - 1, W))   # the per-edge medians
        if not scale > 0:                           # flat frames: nothing to make sparser
            return g
        x, y = _EdgeSplit(px, np.diff(g, axis=1)), _EdgeSplit(py, np.diff(g, axis=0))
        for _ in range(max_iters):
            tx, ty = both(lambda: x.step(np.diff(g, axis=1)), lambda: y.step(np.diff(g, axis=0)))
            g_new = _integrate(tx.reshape(H, W - 1), ty.reshape(H - 1, W))
            moved = float(np.abs(g_new - g).max())
            g = g_new
            if moved <= tol * scale:
                break
    return g


def offset_image(frames, method: str, rest: float | None = None) -> np.ndarray:
    """The offset image [H, W] float64 of ``method`` ("median_gradient" or "l1_gradient") for ``frames`` [K, H, W];
    ``rest`` (log units, "l1_gradient" only): a static camera. Its structure finer than STATIC_COARSE_PX
    comes from the solve that leaves each edge's frames at rest out (:func:`l1_gradient_offset` with
    ``rest``), the coarser from the plain solve: where an object passed, the background's texture is
    seen, but its large-scale level is tied to the untouched background around it only through the
    path's rim, and a long path carries the Poisson step's error along (static_gravel_astronaut's MSE
    0.0308 -> 0.0629 with the rest solve alone, 0.0324 so; ``python benchmarks/static_camera.py``)."""
    method = choice(method, ("median_gradient", "l1_gradient"), "offset method")
    if rest is not None and method != "l1_gradient":
        raise EventDataError(f"rest= (a static camera) needs the 'l1_gradient' offset solve, got {method!r}")
    if method == "median_gradient":
        return _median_gradient(frames)
    plain = _l1_gradient(frames)
    if rest is None:
        return plain
    moved = _l1_gradient(frames, rest=rest)    # a static camera: its fine structure, the plain solve's coarse
    return moved + gaussian_lowpass_unchecked(plain - moved, STATIC_COARSE_PX)


@dataclass
class OffsetTrend:
    """A per-pixel offset that varies slowly in time: ``images`` float32 [K, H, W] at ``knots`` float64
    [K] (seconds), linear in time between knots and constant beyond the first and the last."""

    knots: np.ndarray
    images: np.ndarray

    def add_to(self, L: np.ndarray, times) -> np.ndarray:
        """L [Q, H, W] (float32 log intensities at ``times`` [Q] s) plus the offset, in place; returns L."""
        t = np.asarray(times, np.float64)
        if len(self.knots) == 1:
            L += self.images[0]
            return L
        i = np.clip(np.searchsorted(self.knots, t, side="right") - 1, 0, len(self.knots) - 2)
        w = np.clip((t - self.knots[i]) / (self.knots[i + 1] - self.knots[i]), 0.0, 1.0).astype(np.float32)
        for j in range(len(t)):          # a frame at a time: no [Q, H, W] temporary
            L[j] += (1 - w[j]) * self.images[i[j]] + w[j] * self.images[i[j] + 1]
        return L

    def at(self, times) -> np.ndarray:
        """The offset at ``times`` [Q] (s): float32 [Q, H, W]."""
        t = np.atleast_1d(np.asarray(times, np.float64))
        return self.add_to(np.zeros((len(t), *self.images.shape[1:]), np.float32), t)


MAX_TREND_INTERVALS = 10**6   # knots of an offset trend: each is an image [H, W] solved; more is a unit mix-up


def _trend_window(window):
    """``window`` (seconds between the offset trend's knots) checked: None, or a finite number > 0."""
    if window is None:
        return None
    return real_number(decimal_as_float(window), "window", lo=0, lo_open=True,
                       hint="seconds between the offset's knots (EvINRConfig.offset_window), or None for one image")


def trend_intervals(span: float, window: float | None) -> int:
    """How many intervals between knots :func:`offset_trend` puts over ``span`` seconds: 1 (one image)
    for ``window`` None or a span under 1.5 windows, else round(span / window)."""
    # a Decimal (taken before, as in the readers' windows) as its float
    span = real_number(decimal_as_float(span), "span", lo=0, hint="the span's length in seconds (t_end - t_start)")
    window = _trend_window(window)
    if window is None:
        return 1
    n = span / window
    if n > MAX_TREND_INTERVALS:   # 1e308 / 1e-308 was an OverflowError, 1e6 / 1e-6 a trend of 1e12 images
        raise EventDataError(f"a span of {span:g} s with window={window:g} s would be {n:.3g} offset images (at most "
                             f"{MAX_TREND_INTERVALS:,}); give the window in seconds (e.g. 2.0), or None for one image")
    return max(1, int(round(n)))


def trend_knots(span: float, window: float | None) -> int:
    """How many offset images :func:`offset_trend` solves over ``span`` seconds: 1, or one per knot."""
    n = trend_intervals(span, window)
    return 1 if n == 1 else n + 1


def offset_trend(times, frames, window: float | None, method: str = "l1_gradient", on_image=None,
                 rest: float | None = None) -> OffsetTrend:
    """The slowly varying offset that makes the frames' gradients sparsest locally in time
    (:func:`l1_gradient_offset`; or, with ``method="median_gradient"``, each pixel's median gradient zero).

    Args:
        times: float64 [G] increasing seconds of ``frames`` [G, H, W] (log intensities over the span).
        window: seconds between knots, and how far from its knot a frame counts; None, or a span
            shorter than 1.5 windows: one image for the whole span (:func:`offset_image`).
        method: each image's solve, "median_gradient" or "l1_gradient" (:func:`offset_image`).
        on_image: called with no argument after each image is solved (a progress bar's update), or None.
        rest: None, or log units: a static camera's solve (:func:`l1_gradient_offset`).

    Returns:
        :class:`OffsetTrend` with K = max(1, round(span / window)) + 1 knots evenly over the span
        (1 knot when one image is solved); each image float32, mean 0.
    """
    # the frames' values are not checked: the solver passes its network's frames, whose NaN its result check names
    t = seconds_array(times, "times")
    frames = numbers_array(frames, "frames", "log intensities [G, H, W]")
    if frames.ndim != 3 or len(t) != len(frames):
        raise EventDataError(f"times [G] and frames [G, H, W] must match, got shapes {t.shape} and {frames.shape}; "
                             "give one time (s) per frame")
    if np.any(np.diff(t) < 0):   # taken: the knots ran backwards, over the wrong frames
        raise EventDataError("times must be increasing seconds (one per frame, in time order); sort the frames by "
                             "time first (order = np.argsort(times); times[order], frames[order])")
    window = _trend_window(window)
    if on_image is not None and not callable(on_image):
        raise ArgumentTypeError(f"on_image= must be a function called with no argument after each image (e.g. a "
                                f"progress bar's update) or None, got {type(on_image).__name__}")
    span = float(t[-1] - t[0])
    n = trend_intervals(span, window)
    done = on_image or (lambda: None)
    if n == 1:
        image = offset_image(frames, method, rest).astype(np.float32)[None]
        done()
        return OffsetTrend(t[:1].copy(), image)
    knots = np.linspace(t[0], t[-1], n + 1)
    images = []
    for k in knots:
        near = np.flatnonzero(np.abs(t - k) <= window * (1 + 1e-9))
        if near.size < MIN_TREND_FRAMES:
            near = np.sort(np.argsort(np.abs(t - k), kind="stable")[:MIN_TREND_FRAMES])
        images.append(offset_image(frames[near], method, rest).astype(np.float32))
        done()
    return OffsetTrend(knots, np.stack(images))


def offset_grid(t_start: float, t_end: float, n_windows: int, offset_solve: str) -> np.ndarray:
    """float64 [G] times (s) at which the offset solve and the level anchor look at a span of
    ``n_windows`` network windows (the whole-sequence solve and streaming share it)."""
    offset_solve = choice(offset_solve, OFFSET_SOLVES, "offset_solve")   # a list or None was taken as a solve
    n_grid = min(64, 8 * n_windows)          # the level anchor's times (as the paper's recipe always had them)
    if offset_solve != "none":
        n_grid = max(64, 8 * n_windows)      # an offset solve wants many frames; the level anchor shares them
    return np.linspace(t_start, t_end, n_grid)
