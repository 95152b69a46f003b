"""Round 17 of the bad-input table (tests/test_robustness*.py): public functions no earlier round called with bad
arguments: the offset solves and their parts (evinr_lite.method.offset: ``poisson_integrate``,
``median_gradient_offset``, ``l1_gradient_offset``, ``gaussian_lowpass``), the anchor's helpers
(evinr_lite.method.anchor: ``linear_frames``, ``frame_log``, ``select_anchors``, ``smoothing_matrix``), the
frames-against-events helpers of the fit of C (evinr_lite.method.contrast: ``frame_log_changes``,
``frame_event_counts``, ``frame_trajectories``, ``estimate_contrast_threshold``), the head solve's spectrum
(evinr_lite.method.head_solve: ``laplacian_eigenvalues``, ``penalty_spectrum``) and the losses the notebooks call
(evinr_lite.method.losses: ``temporal_loss_difference``, ``temporal_loss_derivative``, ``tikhonov``,
``total_variation``, ``spatial_differences``).

283 cases. Sections 1 to 7: 211, 188 of which failed before their fixes (six cases the review found to refuse
what worked before are gone: bool L, an eps of 1 for ``linear_frames`` and ``frame_log``, ``select_anchors(0,
"all")``, empty values in the threshold, a numpy array for ``spatial_differences``). The other 23: 17 guards (valid odd inputs that worked before and
must keep their outcome: float32, int, list and tensor frames, one frame, 1 x 1 and 1 x N images, max_iters 0, sigma
0, infinite L and eps 0, whole-float and numpy counts, one anchor time, uint8 frames and a whole exposed range,
lists, tensors and 2-D values in the threshold, zero weights, batched and 2-D losses) and 6 refusals that stood
before (the frame helpers' frames None or an array: ``_in_order``'s ``require``). Two guard cases failed before: a
``gy`` given as a list (``poisson_integrate`` read ``gy.shape``: an AttributeError), now taken as the array it is.

Fixes (each test failed before its fix): ``poisson_integrate`` of None or text was an AttributeError, differences of
shapes that are no image's (1-D, [H, W] for both, one row too many) numpy's broadcast error and NaN a NaN image: gx
and gy are finite numbers of shapes [H, W-1] and [H-1, W] (the solves call an unchecked ``_integrate``).
``median_gradient_offset`` / ``l1_gradient_offset`` of None or text were "got shape ()", NaN or inf frames a NaN
offset without a word, [K, 0, W] frames numpy's errors: one check, ``_log_stack``, names frames= (an EventDataError,
still a ValueError); ``l1_gradient_offset``'s ``max_iters`` of 2.5, "5" or True were Python's errors or 1 iteration,
-1 ran none without a word, a ``tol`` of NaN, -1 or text ran on or was Python's error. ``gaussian_lowpass`` of a
sigma None or text was Python's TypeError, NaN or inf a NaN image, -1 a blur by 1, True by 1; an image None, 1-D,
3-D or empty numpy's unpack errors, NaN a NaN image. ``linear_frames`` of None was a NaN "frame" of no shape, NaN L
NaN frames, text numpy's error, a tensor that requires grad numpy's "Can't call numpy()", an eps of None or text
Python's or numpy's errors, NaN NaN frames, -1 frames of 1 and True frames of 0 (an eps is a finite number >= 0:
``anchor.check_frame_eps``) (the solver and baselines call
``linear_frames_unchecked``, as before, and check their result as before); ``frame_log`` the same for its images and
eps. ``select_anchors(mode="all")`` with every 0 was a ZeroDivisionError, -1 no anchor, 2.5, "2" and True were
taken; n_frames -3 gave no anchor. ``smoothing_matrix`` of a smoothing NaN or -1 was no smoothing, text Python's
error, times None Python's error, NaN times a NaN matrix and times out of order a matrix of 10^8.
``frame_log_changes`` / ``frame_event_counts`` / ``frame_trajectories`` compared frames of another size than the
events' sensor pixel by pixel without a word, took a negative or NaN eps (NaN logs) and a reversed exposed (no
pixel) and failed in Python or numpy on events None, eps None or text, exposed None, one number or text: they share
``fit_contrast``'s checks (``_check_pairing``); ``frame_trajectories``' max_frames 1 or 2.5 too.
``estimate_contrast_threshold`` of None gave NaN, text was numpy's error, counts of another length numpy's broadcast
error and NaN inputs NaN. ``laplacian_eigenvalues`` of a sensor (0, 5) or (-1, 5) gave eigenvalues
of no pixel, (2.5, 3) of a made-up sensor, None and "x" unpack errors, a weight NaN, -1 or text NaN or negative
eigenvalues or numpy's error; ``penalty_spectrum`` of mu None returned None, a weight of text or NaN was taken and
order True was taken as 1. ``temporal_loss_difference`` / ``temporal_loss_derivative`` / ``tikhonov`` /
``total_variation`` of None, text or a numpy array (``spatial_differences`` slices one) were "not subscriptable" or torch's errors, tensors of fewer axes
"too many indices", and stacks that do not go together (5 boundaries for 5 bins, other H x W, durations of another
count) torch's "size of tensor a must match".

Review fixes (section 8: 59 cases, 52 of which failed on this branch before them; the other 7 are guards: an eps of
0 and the message for -0.5 in the anchor's helpers, durations of [1, B] and [B, 2], and the scalar count's refusal
kept). A diverged run (``EvINRConfig(lr=1e6, head_solve=False)``) was told the offset solve's "frames= holds ... NaN
... repair or drop them", about frames the user never gave, instead of the solver's ResultError with the settings to
change: ``offset_image`` (the solver's, the baselines' and streaming's entry) calls the unchecked inner solves
(``_median_gradient``, ``_l1_gradient``) and ``coarse_correction`` and the static camera's blend
``gaussian_lowpass_unchecked``, so the network's NaN reaches the result check again. The round narrowed what worked:
``estimate_contrast_threshold`` of no pixel is NaN again, as for all-zero counts (notebook 11's
``estimate_C(dL[off], n[off])`` of an ON-only recording); eps had two ranges, [0, 1) in anchor.py and (0, 1] in
contrast.py, refusing eps 0 for ``frame_log_changes`` and 1 for ``frame_log`` / ``linear_frames`` that worked: one
check, ``anchor.check_frame_eps``, a finite number >= 0, for all five (``fit_contrast`` takes eps 0 too: its exposed
mask leaves black pixels out); ``temporal_loss_derivative`` took only durations [..., B] of dF_dt's leading axes and
refused a 0-d tensor and [1], which broadcast, while durations of other leading axes were still torch's
RuntimeError: they are checked with ``torch.broadcast_shapes`` (a last axis of B or 1, or a 0-d tensor), and the
temporal losses' stacks broadcast over H x W as torch does (F of [B + 1, 1, 1]); ``spatial_differences`` of a numpy
array is its slices again (``tikhonov`` / ``total_variation`` still need torch's mean); bool frames and logs are 0
and 1 again in ``frame_log`` / ``linear_frames``; ``select_anchors(0, ...)`` is no anchor in both modes ("all" gave
[], refused by the round; "first" gave [0], an index into no frame) and "first" checks n_frames (-3, None, 2.5 gave
[0]); ``laplacian_eigenvalues`` takes a weight of one element (np.array([0.3])) as its number, as it did. Siblings:
``penalty_spectrum`` refuses NaN or negative mu (mu -1 at order 2 gave +0.85, a penalty as if it smoothed),
``smoothing_matrix`` repeated times (a gap of 0 floored at 1e-9 s: a condition number of 6e7; ``fit_anchor``'s frames
are distinct, ``frames_in_window`` refuses repeated timestamps), ``gaussian_lowpass`` blurs a sigma above
``MAX_SIGMA_PX`` (1e100) as that one, to the mean (1e200 was Python's OverflowError) and ``laplacian_eigenvalues``
refuses text as a sensor ("45" was read as H "4", W "5"). Messages: ``smoothing_matrix`` names
``EvINRConfig.anchor_smoothing`` (it said ``anchor_smoothing_s``, the summary's key) and ``penalty_spectrum``'s
order (True, 3, None) is an EventDataError (still a ValueError). The ADMM iterations call
``head_solve.laplacian_eigenvalues_unchecked``. The guards compare float32, list, tensor and uint8 inputs with the
float64 answer (``np.array_equal``, or ``np.allclose`` for float32's rounding) instead of their shape or finiteness.
Refused on purpose where it was taken before: one count for every pixel in the threshold
(``estimate_contrast_threshold(dL, 1)`` summed dL * n over the pixels but n^2 once: C was sum(dL)), a 2-D dF_dt in
``temporal_loss_derivative`` (its durations broadcast into a third axis) and -inf frames in the offset solves. Left:
the loss checks' cost (about 20 us a call, on the readable fast=False training path only).

Valid calls are byte-identical before and after (155 calls of every function touched, compared by a scratch
script: arrays' bytes and dtypes, fits' reprs; after the review, the reviewer's 109 calls against the tree before the
round: of those that worked there, all give the same bytes except the ones changed on purpose above: -inf frames,
an infinite image (a NaN image), repeated anchor times, one count for all pixels, a 2-D dF_dt and
``select_anchors(0, "first")``).

The session's final review (section 9: 13 cases, 10 of which failed before their fixes; the other 3, an eps of
np.float32, guards): the head solve still called the checked ``laplacian_eigenvalues`` and ``penalty_spectrum`` with
the cx, cy its lam gives, so ``lam=1e308`` was told "cx= must be a finite number >= 0, got inf" (an argument the
user never passed) instead of the solver's ResultError: it calls ``laplacian_eigenvalues_unchecked`` and
``penalty_spectrum_unchecked``. ``frame_log_changes``, ``frame_event_counts`` and ``frame_trajectories`` checked eps
and then used the raw value (a Fraction was numpy's "no callable log method", a 0-d tensor "Concatenation operation
is not implemented"): they use the float the check returns, as ``fit_contrast`` did. ``penalty_spectrum`` checked
np.asarray(mu) and computed with mu (a list was Python's "can't multiply sequence", or came back as the list).
"""
import re
from fractions import Fraction

import numpy as np
import pytest
import torch

from evinr_lite import EventDataError, Events
from evinr_lite.core.frames import Frames
from evinr_lite.method import anchor, contrast, head_solve, losses, offset

RNG = np.random.default_rng(17)
IMG = RNG.uniform(0.1, 0.9, (6, 8))
STACK = RNG.normal(size=(5, 6, 8))
GX, GY = np.diff(IMG, axis=1), np.diff(IMG, axis=0)


def _refused(fn, *args, match=None, **kw):
    with pytest.raises(EventDataError, match=match):
        fn(*args, **kw)


def _with_nan(a, index=(0,)):
    a = np.array(a, np.float64)
    a[index] = np.nan
    return a


# ---- 1. poisson_integrate -------------------------------------------------------------------------------------

@pytest.mark.parametrize("gx, gy", [
    (None, GY), ("x", GY), (GX, None), (GX, b"x"), (np.zeros(5), GY), (IMG, IMG),
    (GX, np.diff(STACK[:, :, :7], axis=1)),
    (GX, GY[:-1]), (GX[:, :-1], GY), (_with_nan(GX), GY), (GX, _with_nan(GY)), (np.full_like(GX, np.inf), GY),
    (GX.astype(bool), GY), (np.zeros((0, 0)), GY),
], ids=lambda v: type(v).__name__ if not hasattr(v, "shape") else str(v.shape))
def test_poisson_integrate_refuses_what_is_no_image_gradient(gx, gy):
    _refused(offset.poisson_integrate, gx, gy, match=r"gx|gy")


@pytest.mark.parametrize("H, W", [(6, 8), (1, 5), (5, 1), (1, 1)])
def test_poisson_integrate_takes_any_image_size_guard(H, W):
    img = RNG.normal(size=(H, W))
    gx, gy = np.diff(img, axis=1), np.diff(img, axis=0)
    g = offset.poisson_integrate(gx, gy.tolist() if H > 1 else np.zeros((0, W)))
    assert np.array_equal(g, offset.poisson_integrate(gx, gy))       # the list is the array it holds
    assert np.allclose(g, img - img.mean(), atol=1e-12)               # exact differences integrate back


# ---- 2. the offset solves' frames, max_iters and tol ---------------------------------------------------------

BAD_FRAMES = [None, "frames", b"x", IMG, np.zeros(5), np.zeros((0, 6, 8)), np.zeros((3, 0, 8)), _with_nan(STACK),
              np.where(STACK > 1.5, np.inf, STACK), STACK > 0, np.array([["a"]] * 2)]


@pytest.mark.parametrize("solve", [offset.median_gradient_offset, offset.l1_gradient_offset])
@pytest.mark.parametrize("frames", BAD_FRAMES, ids=range(len(BAD_FRAMES)))
def test_offset_solves_name_frames_they_cannot_use(solve, frames):
    _refused(solve, frames, match="frames=")


@pytest.mark.parametrize("kw, name", [({"max_iters": 2.5}, "max_iters"), ({"max_iters": "5"}, "max_iters"),
                                      ({"max_iters": True}, "max_iters"), ({"max_iters": -1}, "max_iters"),
                                      ({"max_iters": None}, "max_iters"), ({"tol": float("nan")}, "tol"),
                                      ({"tol": -1.0}, "tol"), ({"tol": "x"}, "tol"), ({"tol": None}, "tol")])
def test_l1_gradient_offset_checks_its_iterations_and_tolerance(kw, name):
    _refused(offset.l1_gradient_offset, STACK, match=f"{name}=", **kw)


INTS = RNG.integers(0, 5, (3, 4, 4))


@pytest.mark.parametrize("frames, same_as", [(STACK.astype(np.float32), None), (STACK.tolist(), STACK),
                                             (torch.tensor(STACK), STACK), (INTS, INTS.astype(np.float64)),
                                             (np.ones((2, 1, 1)), np.ones((2, 1, 1))), (STACK[:1], STACK[:1])],
                         ids=["float32", "list", "tensor", "int", "1x1", "one frame"])
def test_offset_solves_take_what_they_took_guard(frames, same_as):
    for solve in (offset.median_gradient_offset, offset.l1_gradient_offset):
        g = solve(frames)
        if same_as is None:     # float32 frames: the float64 answer to float32's rounding
            assert g.dtype == np.float64 and np.allclose(g, solve(STACK), atol=1e-5)
        else:
            assert np.array_equal(g, solve(same_as))


def test_l1_gradient_offset_max_iters_0_is_the_median_start_guard():
    assert np.allclose(offset.l1_gradient_offset(STACK, max_iters=0, tol=0), offset.median_gradient_offset(STACK),
                       atol=1e-6)


# ---- 3. gaussian_lowpass ------------------------------------------------------------------------------------

@pytest.mark.parametrize("sigma", [None, "2", float("nan"), float("inf"), -1.0, True])
def test_gaussian_lowpass_checks_sigma(sigma):
    _refused(offset.gaussian_lowpass, IMG, sigma, match="sigma_px=")


@pytest.mark.parametrize("image", [None, "x", np.zeros(5), STACK, np.zeros((0, 0)), _with_nan(IMG)],
                         ids=["None", "text", "1-D", "3-D", "empty", "NaN"])
def test_gaussian_lowpass_checks_the_image(image):
    _refused(offset.gaussian_lowpass, image, 2.0, match="image=")


def test_gaussian_lowpass_takes_sigma_0_lists_and_float32_guard():
    assert np.allclose(offset.gaussian_lowpass(IMG, 0), IMG)
    assert np.array_equal(offset.gaussian_lowpass(IMG.tolist(), np.float32(2.0)), offset.gaussian_lowpass(IMG, 2.0))


# ---- 4. the anchor's helpers ----------------------------------------------------------------------------------

@pytest.mark.parametrize("L", [None, "x", np.array([0.1, np.nan]), [[0.1], [0.2, 0.3]]],
                         ids=["None", "text", "NaN", "ragged"])
def test_linear_frames_checks_L(L):
    _refused(anchor.linear_frames, L, match="L=")


@pytest.mark.parametrize("eps", [None, "x", float("nan"), -1.0, True, float("inf")])
@pytest.mark.parametrize("fn", [anchor.linear_frames, anchor.frame_log])
def test_linear_frames_and_frame_log_check_eps(fn, eps):
    _refused(fn, np.full(3, 0.5), eps=eps, match="eps=")


@pytest.mark.parametrize("images", [None, "x", np.array([0.5, np.nan])], ids=["None", "text", "NaN"])
def test_frame_log_checks_images(images):
    _refused(anchor.frame_log, images, match="images=")


def test_linear_frames_keep_infinities_eps_0_and_tensors_guard():
    out = anchor.linear_frames(np.array([-np.inf, 0.0, np.inf]), eps=0)
    assert out.tolist() == [0.0, 1.0, 1.0]
    assert np.array_equal(anchor.linear_frames(torch.tensor([0.1, -3.0])),
                          anchor.linear_frames(np.array([0.1, -3.0], np.float32)))
    assert np.array_equal(anchor.frame_log(np.zeros(2, np.uint8), eps=np.float32(0.01)),
                          np.log(np.zeros(2) + np.float32(0.01)))


@pytest.mark.parametrize("n_frames, every", [(5, 0), (5, -1), (5, 2.5), (5, "2"), (5, True), (5, None), (-3, 2),
                                             (None, 2), (2.5, 2)])
def test_select_anchors_all_checks_every_and_n_frames(n_frames, every):
    _refused(anchor.select_anchors, n_frames, "all", every, match=r"every=|n_frames=")


def test_select_anchors_whole_floats_and_numpy_ints_guard():
    assert anchor.select_anchors(np.int64(5), "all", 2.0).tolist() == [0, 2, 4]
    assert anchor.select_anchors(5, "first", 0).tolist() == [0]


@pytest.mark.parametrize("times, smoothing, name", [
    (np.array([0.0, 1.0]), float("nan"), "smoothing="), (np.array([0.0, 1.0]), -1.0, "smoothing="),
    (np.array([0.0, 1.0]), "x", "smoothing="), (None, 0.1, "times="), (np.array([1.0, 0.0]), 0.1, "times="),
    (np.array([0.0, np.nan]), 0.1, "times="), (np.array([[0.0, 1.0]]), 0.1, "times="), ("x", 0.1, "times=")])
def test_smoothing_matrix_checks_its_times_and_smoothing(times, smoothing, name):
    _refused(anchor.smoothing_matrix, times, smoothing, match=name)


def test_smoothing_matrix_one_time_and_no_smoothing_guard():
    assert anchor.smoothing_matrix(np.array([0.2]), 0.03).tolist() == [[1.0]]
    assert np.array_equal(anchor.smoothing_matrix([0.0, 0.1], 0), np.eye(2))


# ---- 5. frames against events (the fit of C's helpers) -------------------------------------------------------

N_EV = 4000
_t = np.sort(RNG.uniform(0, 1, N_EV))
EVENTS = Events(_t, RNG.integers(0, 8, N_EV), RNG.integers(0, 6, N_EV), RNG.choice([-1, 1], N_EV), (6, 8))
FRAMES = Frames(RNG.uniform(0, 1, (5, 6, 8)), np.array([0.05, 0.3, 0.5, 0.7, 0.95]))
OTHER_SIZE = Frames(RNG.uniform(0, 1, (5, 4, 4)), np.array([0.05, 0.3, 0.5, 0.7, 0.95]))
PAIRING = [contrast.frame_log_changes, contrast.frame_event_counts, contrast.frame_trajectories]


@pytest.mark.parametrize("fn", PAIRING, ids=lambda f: f.__name__)
@pytest.mark.parametrize("kw, match", [
    ({"eps": -1.0}, "eps="), ({"eps": float("nan")}, "eps="), ({"eps": None}, "eps="), ({"eps": "x"}, "eps="),
    ({"exposed": (0.9, 0.1)}, "exposed="), ({"exposed": None}, "exposed="), ({"exposed": (0.1,)}, "exposed="),
    ({"exposed": ("a", "b")}, "exposed="), ({"exposed": 0.5}, "exposed=")])
def test_frame_helpers_check_eps_and_exposed(fn, kw, match):
    _refused(fn, FRAMES, EVENTS, match=match, **kw)


@pytest.mark.parametrize("fn", PAIRING, ids=lambda f: f.__name__)
def test_frame_helpers_refuse_frames_of_another_sensor(fn):
    _refused(fn, OTHER_SIZE, EVENTS, match=r"frames are \(4, 4\).*\(6, 8\)")


@pytest.mark.parametrize("fn", PAIRING, ids=lambda f: f.__name__)
@pytest.mark.parametrize("frames, events", [(FRAMES, None), (FRAMES, "events.h5"), (None, EVENTS), (IMG, EVENTS)],
                         ids=["events None", "events text", "frames None", "frames array"])
def test_frame_helpers_name_what_is_no_frames_or_events(fn, frames, events):
    _refused(fn, frames, events, match=r"frames=|events=")


@pytest.mark.parametrize("max_frames", [1, 2.5, "8", None])
def test_frame_trajectories_checks_max_frames(max_frames):
    _refused(contrast.frame_trajectories, FRAMES, EVENTS, max_frames=max_frames, match="max_frames=")


def test_frame_helpers_take_uint8_frames_and_a_whole_range_guard():
    f8 = Frames((FRAMES.images * 255).astype(np.uint8), FRAMES.t)
    as_float = Frames(f8.as_float(), FRAMES.t)      # the uint8 frames are read as these
    for fn, n_out in zip(PAIRING, (3, 4, 5)):
        got = fn(f8, EVENTS, eps=np.float32(0.01), exposed=[0.0, 1.0])
        want = fn(as_float, EVENTS, eps=float(np.float32(0.01)), exposed=(0.0, 1.0))
        assert len(got) == n_out and all(np.array_equal(a, b) for a, b in zip(got, want))


D = RNG.normal(size=20)
N = RNG.integers(-3, 4, 20)


@pytest.mark.parametrize("d, n, match", [
    (None, N, "log_changes="), (D, None, "net_counts="), ("x", N, "log_changes="), (D, N[:-1], "log_changes and net_counts"),
    (_with_nan(D), N, "NaN"), (D, np.full(20, np.inf), "NaN or infinite"),
    (D, N.astype(bool), "net_counts="), ([[0.1], [0.2, 0.3]], N, "ragged")])
def test_estimate_contrast_threshold_checks_its_values(d, n, match):
    _refused(contrast.estimate_contrast_threshold, d, n, match=match)


def test_estimate_contrast_threshold_takes_lists_tensors_and_2d_guard():
    c = contrast.estimate_contrast_threshold(D, N)
    assert contrast.estimate_contrast_threshold(D.tolist(), N.tolist()) == c
    assert contrast.estimate_contrast_threshold(torch.tensor(D), torch.tensor(N)) == c
    assert contrast.estimate_contrast_threshold(D.reshape(4, 5), N.reshape(4, 5)) == c


# ---- 6. the head solve's spectrum -----------------------------------------------------------------------------

@pytest.mark.parametrize("args, match", [
    (((0, 5),), "sensor_size"), (((-1, 5),), "sensor_size"), (((2.5, 3),), "sensor_size"), ((None,), "sensor_size"),
    (("x",), "sensor_size"), (((4, 4, 4),), "sensor_size"), (((True, 4),), "sensor_size"),
    (((4, 4), -1.0), "cx="), (((4, 4), float("nan")), "cx="), (((4, 4), "x"), "cx="), (((4, 4), 1.0, None), "cy="),
    (((4, 4), 1.0, float("inf")), "cy=")])
def test_laplacian_eigenvalues_checks_the_sensor_and_weights(args, match):
    _refused(head_solve.laplacian_eigenvalues, *args, match=match)


MU = head_solve.laplacian_eigenvalues((4, 4))


@pytest.mark.parametrize("args, match", [
    ((None, 1.0, 1.0), "mu="), (("x", 1.0, 1.0), "mu="), ((MU, "x", 1.0, 2), "cx="),
    ((MU, float("nan"), 1.0, 2), "cx="),
    ((MU, 1.0, -1.0, 2), "cy="), ((MU, 1.0, 1.0, True), "order must be")])
def test_penalty_spectrum_checks_its_arguments(args, match):
    with pytest.raises(ValueError, match=match):
        head_solve.penalty_spectrum(*args)


def test_spectrum_takes_arrays_numpy_numbers_and_zero_weights_guard():
    assert np.array_equal(head_solve.laplacian_eigenvalues(np.array([1, 7]), 0.0, np.float32(1.5)),
                          head_solve.laplacian_eigenvalues((1, 7), 0.0, 1.5))
    assert np.array_equal(head_solve.penalty_spectrum(MU, 0.0, 0.0, 2), MU)


# ---- 7. the losses ------------------------------------------------------------------------------------------

E = torch.zeros(4, 6, 8)


@pytest.mark.parametrize("F, ev, match", [
    (None, E, "F_boundaries"), ("x", E, "F_boundaries"), (np.zeros((5, 6, 8)), E, "torch.from_numpy"),
    (torch.zeros(0), E, "at least 3 axes"), (torch.zeros(5, 6, 8), None, "event_frames"),
    (torch.zeros(4, 6, 8), E, "one more bin"), (torch.zeros(5, 6, 7), E, "one more bin"),
    (torch.zeros(3, 5, 6, 8), torch.zeros(2, 4, 6, 8), "do not go together")])
def test_temporal_loss_difference_names_stacks_that_do_not_go_together(F, ev, match):
    _refused(losses.temporal_loss_difference, F, ev, match=match)


@pytest.mark.parametrize("dF, ev, dur, match", [
    (None, E, torch.ones(4), "dF_dt"), (torch.zeros(4, 6, 8), np.zeros((4, 6, 8)), torch.ones(4), "event_frames"),
    (torch.zeros(3, 6, 8), E, torch.ones(4), "do not go together"),
    (torch.zeros(4, 6, 8), E, torch.ones(3), "durations"),
    (torch.zeros(4, 6, 8), E, None, "durations"), (torch.zeros(4, 6, 8), E, [1.0] * 4, "durations"),
    (torch.zeros(4, 6), torch.zeros(4, 6), torch.ones(4), "at least 3 axes")])
def test_temporal_loss_derivative_checks_its_stacks(dF, ev, dur, match):
    _refused(losses.temporal_loss_derivative, dF, ev, dur, match=match)


@pytest.mark.parametrize("fn, F", [(fn, F) for fn in (losses.tikhonov, losses.total_variation, losses.spatial_differences)
                                   for F in (None, "x", np.zeros((2, 4, 4)), torch.zeros(4))
                                   if not (fn is losses.spatial_differences and isinstance(F, np.ndarray))],
                         ids=lambda v: getattr(v, "__name__", None) or type(v).__name__)
def test_spatial_terms_name_what_is_no_frame_tensor(fn, F):
    _refused(fn, F, match="F must be a torch tensor")


def test_losses_take_batches_and_2d_frames_guard():
    torch.manual_seed(17)
    F, ev, dF = torch.randn(3, 5, 6, 8), torch.randn(4, 6, 8), torch.randn(3, 4, 6, 8)
    batched = losses.temporal_loss_difference(F, ev)      # a batch of 3: the mean of the 3 equal-sized losses
    assert torch.allclose(batched, torch.stack([losses.temporal_loss_difference(f, ev) for f in F]).mean())
    batched = losses.temporal_loss_derivative(dF, ev, torch.full((4,), 0.5))
    assert torch.allclose(batched, torch.stack([losses.temporal_loss_derivative(d, ev, torch.full((4,), 0.5))
                                                for d in dF]).mean())
    img = torch.randn(4, 6)
    assert torch.equal(losses.tikhonov(img), torch.mean(img.diff(dim=1) ** 2) + torch.mean(img.diff(dim=0) ** 2))


def test_linear_frames_takes_a_tensor_that_requires_grad():
    # before: numpy's "Can't call numpy() on Tensor that requires grad"; now read through host_array, as elsewhere
    L = torch.tensor([0.1, -3.0], requires_grad=True)
    assert np.array_equal(anchor.linear_frames(L), anchor.linear_frames(L.detach().numpy()))


# ---- 8. review fixes ------------------------------------------------------------------------------------------
# Each case failed on this branch before the review's fixes, unless it says "guard" (kept outcomes).

def test_a_diverged_run_is_the_solvers_result_error_with_its_advice():
    # the offset solve got the network's NaN through the now-checked public solves: "frames= holds ... NaN ...
    # repair or drop them" (about frames the user never gave); the solver calls unchecked inner solves again
    from evinr_lite import EvINRConfig, reconstruct
    from evinr_lite.core.checks import ResultError
    from evinr_lite.sim.scenes import make_scene
    from evinr_lite.sim.simulate import simulate_scene

    scene = make_scene("camera", sensor_size=(16, 20), duration=0.2)
    events = simulate_scene(scene, 0.0, 0.2, C=0.2, seed=0)
    with pytest.raises(ResultError, match=r"NaN or infinite.*the settings do not fit these events.*learning rate"):
        reconstruct(events, [0.05, 0.1], EvINRConfig(lr=1e6, n_iters=10, progress=False, head_solve=False))


@pytest.mark.parametrize("method, rest", [("median_gradient", None), ("l1_gradient", None), ("l1_gradient", 0.1)])
def test_offset_image_leaves_nan_to_its_callers_result_check(method, rest):
    # offset_image is the solver's, baselines' and streaming's entry: their own frames, checked with their result
    assert offset.offset_image(_with_nan(STACK), method, rest).shape == (6, 8)


def test_coarse_correction_leaves_nan_to_the_result_check():
    from evinr_lite.method.coarse import coarse_correction

    L = np.full((4, 6, 8), np.nan, np.float32)
    out = coarse_correction([EVENTS], 0.2, np.linspace(0.1, 0.9, 4), L, 8.0, "l1_gradient")
    assert out.shape == (6, 8) and np.isnan(out).all()


@pytest.mark.parametrize("d, n", [(np.zeros(0), np.zeros(0)), ([], []), (D[N > 99], N[N > 99])],
                         ids=["empty", "lists", "empty mask"])
def test_estimate_contrast_threshold_of_no_pixel_is_nan(d, n):
    # notebook 11: estimate_C(dL[off], n[off]) of an ON-only recording (no OFF pixel); NaN as for all-zero counts
    assert np.isnan(contrast.estimate_contrast_threshold(d, n))


def test_estimate_contrast_threshold_refuses_one_count_for_all_pixels_guard():
    # refused on purpose: a scalar count broadcast summed dL * n over the pixels but n^2 once (C was sum(dL))
    _refused(contrast.estimate_contrast_threshold, D, 1, match="log_changes and net_counts")


@pytest.mark.parametrize("fn", [anchor.frame_log, anchor.linear_frames])
@pytest.mark.parametrize("eps", [0, 1.0, 2.0], ids=["0", "1", "2"])
def test_frame_log_and_linear_frames_take_any_eps_from_0(fn, eps):
    x = np.array([0.0, 0.2, 1.0])
    with np.errstate(divide="ignore"):
        want = np.log(x + eps) if fn is anchor.frame_log else \
            np.clip(np.exp(np.minimum(x, 1.0)) - eps, 0.0, 1.0).astype(np.float32)
        assert np.array_equal(fn(x, eps=eps), want)


@pytest.mark.parametrize("fn", PAIRING, ids=lambda f: f.__name__)
def test_frame_helpers_take_eps_0(fn):
    with np.errstate(divide="ignore"):
        got = fn(FRAMES, EVENTS, eps=0)
        dL, mask = got[1 if fn is contrast.frame_trajectories else 0], got[-1]
        assert np.isfinite(dL[mask]).all() and mask.any()


@pytest.mark.parametrize("fn", [anchor.frame_log, anchor.linear_frames,
                                lambda eps: contrast.frame_log_changes(FRAMES, EVENTS, eps=eps),
                                lambda eps: contrast.fit_contrast(FRAMES, EVENTS, eps=eps)],
                         ids=["frame_log", "linear_frames", "frame_log_changes", "fit_contrast"])
def test_eps_has_one_range_everywhere(fn):
    # anchor.py said [0, 1), contrast.py (0, 1]: one check, anchor.check_frame_eps, "a finite number >= 0"
    call = (lambda e: fn(np.full(3, 0.5), eps=e)) if fn in (anchor.frame_log, anchor.linear_frames) else fn
    with pytest.raises(EventDataError, match=r"eps= must be a finite number >= 0"):
        call(-0.5)


DF = torch.randn(3, 4, 6, 8)
EV3 = torch.randn(3, 4, 6, 8)


@pytest.mark.parametrize("dur, full", [(torch.tensor(0.5), torch.full((4,), 0.5)),
                                       (torch.tensor([0.5]), torch.full((4,), 0.5)),
                                       (torch.full((3, 1), 0.5), torch.full((3, 4), 0.5)),
                                       (torch.full((1, 4), 0.5), torch.full((3, 4), 0.5))],
                         ids=["0-d", "[1]", "[3, 1]", "[1, 4]"])
def test_temporal_loss_derivative_takes_broadcastable_durations(dur, full):
    assert torch.equal(losses.temporal_loss_derivative(DF, EV3, dur), losses.temporal_loss_derivative(DF, EV3, full))


@pytest.mark.parametrize("dur", [torch.ones(2, 4), torch.ones(3, 2), torch.ones(4, 4)],
                         ids=["[2, 4]", "[3, 2]", "[4, 4]"])
def test_temporal_loss_derivative_names_durations_of_other_leading_axes(dur):
    # [2, 4] for a batch of 3 was torch's "size of tensor a (3) must match"
    _refused(losses.temporal_loss_derivative, DF, EV3, dur, match="durations")


def test_temporal_loss_difference_broadcasts_one_value_per_frame():
    F = torch.randn(5, 1, 1)
    assert torch.equal(losses.temporal_loss_difference(F, E), losses.temporal_loss_difference(F.expand(5, 6, 8), E))


def test_spatial_differences_of_a_numpy_array_are_its_slices():
    a = RNG.normal(size=(2, 4, 5))
    dx, dy = losses.spatial_differences(a)
    assert np.array_equal(dx, np.diff(a, axis=2)) and np.array_equal(dy, np.diff(a, axis=1))


def test_bool_frames_and_logs_are_0_and_1():
    b = np.array([True, False])
    assert np.array_equal(anchor.linear_frames(b), anchor.linear_frames(b.astype(np.float64)))
    assert np.array_equal(anchor.frame_log(b), anchor.frame_log(b.astype(np.float64)))


@pytest.mark.parametrize("mode", ["first", "all"])
def test_select_anchors_of_no_frame_is_no_anchor(mode):
    assert anchor.select_anchors(0, mode, 2).tolist() == []


@pytest.mark.parametrize("n_frames", [-3, None, 2.5, "3"])
def test_select_anchors_first_checks_n_frames(n_frames):
    _refused(anchor.select_anchors, n_frames, "first", match="n_frames=")


@pytest.mark.parametrize("w", [np.array([0.3]), np.array([[0.3]])], ids=["[1]", "[1, 1]"])
def test_laplacian_eigenvalues_take_a_weight_of_one_element(w):
    assert np.array_equal(head_solve.laplacian_eigenvalues((6, 8), w, 0.7),
                          head_solve.laplacian_eigenvalues((6, 8), 0.3, 0.7))


@pytest.mark.parametrize("mu", [np.full((4, 4), np.nan), -MU, [[0.0, -1.0]]], ids=["NaN", "negative", "list"])
@pytest.mark.parametrize("order", [1, 2, "banded"])
def test_penalty_spectrum_refuses_nan_or_negative_mu(mu, order):
    # mu=-1 at order 2 gave +0.85, a penalty as if it smoothed; NaN came back as NaN
    _refused(head_solve.penalty_spectrum, mu, 1.0, 1.0, order, match="mu=")


@pytest.mark.parametrize("times", [[0.0, 0.1, 0.1], [0.2, 0.2]], ids=["repeated", "two equal"])
def test_smoothing_matrix_refuses_repeated_times(times):
    # a gap of 0 was floored at 1e-9 s: a matrix of condition 6e7 (fit_anchor's frames are distinct)
    _refused(anchor.smoothing_matrix, np.array(times), 0.03, match="times= must be increasing")


@pytest.mark.parametrize("sigma", [1e200, 1e300, float(np.finfo(np.float64).max)])
def test_gaussian_lowpass_of_a_huge_sigma_is_the_mean(sigma):
    # sigma ** 2 was Python's OverflowError
    assert np.allclose(offset.gaussian_lowpass(IMG, sigma), IMG.mean(), atol=1e-12)


@pytest.mark.parametrize("size", ["45", b"45"])
def test_laplacian_eigenvalues_refuse_text_as_a_sensor(size):
    _refused(head_solve.laplacian_eigenvalues, size, match=r"sensor_size= must be \(H, W\)")


def test_smoothing_matrix_names_the_config_field():
    _refused(anchor.smoothing_matrix, np.array([0.0, 1.0]), -1.0, match=r"EvINRConfig\.anchor_smoothing\b")


def test_penalty_spectrum_order_true_is_an_event_data_error():
    _refused(head_solve.penalty_spectrum, MU, 1.0, 1.0, True, match="order must be")


def test_the_admm_iterations_call_no_checked_eigenvalues(monkeypatch):
    def checked(*args, **kw):
        raise AssertionError("the checked laplacian_eigenvalues ran inside the solve")

    monkeypatch.setattr(head_solve, "laplacian_eigenvalues", checked)
    monkeypatch.setattr(offset, "laplacian_eigenvalues", checked, raising=False)
    g = offset.l1_gradient_offset(STACK)
    monkeypatch.undo()
    assert np.array_equal(g, offset.l1_gradient_offset(STACK))


# ---- 9. the session's final review ----------------------------------------------------------------------------
# Each case failed before its fix (the round's code after its first review).

@pytest.mark.parametrize("order", [1, 2, "banded"])
def test_a_lam_so_large_that_the_head_solve_overflows_is_the_solvers_result_error(order):
    # the head solve called the checked laplacian_eigenvalues / penalty_spectrum with the cx, cy its lam gave:
    # "cx= must be a finite number >= 0, got inf" named an argument the user never passed
    from evinr_lite import EvINRConfig, reconstruct
    from evinr_lite.core.checks import ResultError
    from evinr_lite.sim.scenes import make_scene
    from evinr_lite.sim.simulate import simulate_scene

    events = simulate_scene(make_scene("camera", sensor_size=(12, 16), duration=0.3), 0.0, 0.3, C=0.2, seed=0)
    with pytest.raises(ResultError, match=r"NaN or infinite.*the settings do not fit these events"):
        reconstruct(events, [0.1, 0.2], EvINRConfig(C=0.2, lam=1e308, spatial_order=order, progress=False))


@pytest.mark.parametrize("fn", ["frame_log_changes", "frame_event_counts", "frame_trajectories"])
@pytest.mark.parametrize("eps", [Fraction(1, 255), torch.tensor(1 / 255), np.float32(1 / 255)])   # float32: guard
def test_the_frame_helpers_use_the_eps_their_check_read(fn, eps):
    # the check read eps as a float and the helper used the raw value: a Fraction was numpy's "no callable log
    # method", a 0-d tensor "Concatenation operation is not implemented"
    got = getattr(contrast, fn)(FRAMES, EVENTS, eps=eps)
    want = getattr(contrast, fn)(FRAMES, EVENTS, eps=float(eps))
    for a, b in zip(got if isinstance(got, tuple) else (got,), want if isinstance(want, tuple) else (want,)):
        assert np.array_equal(np.asarray(a), np.asarray(b))


def test_penalty_spectrum_computes_with_the_array_it_checked():
    # a list of eigenvalues passed the check and then met Python's list arithmetic: "can't multiply sequence by
    # non-int of type 'list'" (order 2), or came back as the list itself (order 1)
    mu = [[0.0, 1.0], [2.0, 3.0]]
    for order in (1, 2, "banded"):
        got = head_solve.penalty_spectrum(mu, 1.0, 1.0, order)
        assert isinstance(got, np.ndarray)
        assert np.array_equal(got, head_solve.penalty_spectrum(np.asarray(mu), 1.0, 1.0, order))
