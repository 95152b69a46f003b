"""Round 17 of the bad-input table (tests/test_robustness*.py): public functions no earlier round called with bad
arguments: the offset solves and their parts (evinr_lite.method.offset: ``poisson_integrate``,
``median_gradient_offset``, ``l1_gradient_offset``, ``gaussian_lowpass``), the anchor's helpers
(evinr_lite.method.anchor: ``linear_frames``, ``frame_log``, ``select_anchors``, ``smoothing_matrix``), the
frames-against-events helpers of the fit of C (evinr_lite.method.contrast: ``frame_log_changes``,
``frame_event_counts``, ``frame_trajectories``, ``estimate_contrast_threshold``), the head solve's spectrum
(evinr_lite.method.head_solve: ``laplacian_eigenvalues``, ``penalty_spectrum``) and the losses the notebooks call
(evinr_lite.method.losses: ``temporal_loss_difference``, ``temporal_loss_derivative``, ``tikhonov``,
``total_variation``, ``spatial_differences``).

217 cases, 194 of which failed before their fixes. The other 23: 17 guards (valid odd inputs that worked before and
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
Python's or numpy's errors, NaN NaN frames, -1 frames of 1 and True frames of 0 (the solver and baselines call
``linear_frames_unchecked``, as before, and check their result as before); ``frame_log`` the same for its images and
eps. ``select_anchors(mode="all")`` with every 0 was a ZeroDivisionError, -1 no anchor, 2.5, "2" and True were
taken; n_frames -3 gave no anchor. ``smoothing_matrix`` of a smoothing NaN or -1 was no smoothing, text Python's
error, times None Python's error, NaN times a NaN matrix and times out of order a matrix of 10^8.
``frame_log_changes`` / ``frame_event_counts`` / ``frame_trajectories`` compared frames of another size than the
events' sensor pixel by pixel without a word, took a negative or NaN eps (NaN logs) and a reversed exposed (no
pixel) and failed in Python or numpy on events None, eps None or text, exposed None, one number or text: they share
``fit_contrast``'s checks (``_check_pairing``); ``frame_trajectories``' max_frames 1 or 2.5 too.
``estimate_contrast_threshold`` of None gave NaN, text was numpy's error, counts of another length numpy's broadcast
error, empty inputs NaN and NaN inputs NaN. ``laplacian_eigenvalues`` of a sensor (0, 5) or (-1, 5) gave eigenvalues
of no pixel, (2.5, 3) of a made-up sensor, None and "x" unpack errors, a weight NaN, -1 or text NaN or negative
eigenvalues or numpy's error; ``penalty_spectrum`` of mu None returned None, a weight of text or NaN was taken and
order True was taken as 1. ``temporal_loss_difference`` / ``temporal_loss_derivative`` / ``tikhonov`` /
``total_variation`` of None, text or a numpy array were "not subscriptable" or torch's errors, tensors of fewer axes
"too many indices", and stacks that do not go together (5 boundaries for 5 bins, other H x W, durations of another
count) torch's "size of tensor a must match".

Valid calls are byte-identical before and after (155 calls of every function touched, compared by a scratch
script: arrays' bytes and dtypes, fits' reprs).
"""
import re

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
    g = offset.poisson_integrate(np.diff(img, axis=1), np.diff(img, axis=0).tolist() if H > 1 else np.zeros((0, W)))
    assert g.shape == (H, W) and np.isfinite(g).all()


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


@pytest.mark.parametrize("frames", [STACK.astype(np.float32), STACK.tolist(), torch.tensor(STACK),
                                    RNG.integers(0, 5, (3, 4, 4)), np.ones((2, 1, 1)), STACK[:1]],
                         ids=["float32", "list", "tensor", "int", "1x1", "one frame"])
def test_offset_solves_take_what_they_took_guard(frames):
    for solve in (offset.median_gradient_offset, offset.l1_gradient_offset):
        g = solve(frames)
        assert np.isfinite(g).all() and g.shape == np.shape(frames)[1:]


def test_l1_gradient_offset_max_iters_0_is_the_median_start_guard():
    assert np.isfinite(offset.l1_gradient_offset(STACK, max_iters=0, tol=0)).all()


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
    assert offset.gaussian_lowpass(IMG.tolist(), np.float32(2.0)).shape == IMG.shape


# ---- 4. the anchor's helpers ----------------------------------------------------------------------------------

@pytest.mark.parametrize("L", [None, "x", np.array([0.1, np.nan]), np.array([True, False]), [[0.1], [0.2, 0.3]]],
                         ids=["None", "text", "NaN", "bool", "ragged"])
def test_linear_frames_checks_L(L):
    _refused(anchor.linear_frames, L, match="L=")


@pytest.mark.parametrize("eps", [None, "x", float("nan"), -1.0, True, 1.0, float("inf")])
@pytest.mark.parametrize("fn", [anchor.linear_frames, anchor.frame_log])
def test_linear_frames_and_frame_log_check_eps(fn, eps):
    _refused(fn, np.full(3, 0.5), eps=eps, match="eps=")


@pytest.mark.parametrize("images", [None, "x", np.array([0.5, np.nan])], ids=["None", "text", "NaN"])
def test_frame_log_checks_images(images):
    _refused(anchor.frame_log, images, match="images=")


def test_linear_frames_keep_infinities_eps_0_and_tensors_guard():
    out = anchor.linear_frames(np.array([-np.inf, 0.0, np.inf]), eps=0)
    assert out.tolist() == [0.0, 1.0, 1.0]
    assert anchor.linear_frames(torch.tensor([0.1, -3.0])).dtype == np.float32
    assert anchor.frame_log(np.zeros(2, np.uint8), eps=np.float32(0.01)).shape == (2,)


@pytest.mark.parametrize("n_frames, every", [(5, 0), (5, -1), (5, 2.5), (5, "2"), (5, True), (5, None), (-3, 2),
                                             (0, 2), (None, 2), (2.5, 2)])
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
    _refused(fn, OTHER_SIZE, EVENTS, match=re.escape("frames are (4, 4) but the events' sensor is (6, 8)"))


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
    for fn in PAIRING:
        assert len(fn(f8, EVENTS, eps=np.float32(0.01), exposed=[0.0, 1.0])) in (3, 4, 5)


D = RNG.normal(size=20)
N = RNG.integers(-3, 4, 20)


@pytest.mark.parametrize("d, n, match", [
    (None, N, "log_changes="), (D, None, "net_counts="), ("x", N, "log_changes="), (D, N[:-1], "of one shape"),
    (np.zeros(0), np.zeros(0), "empty"), (_with_nan(D), N, "NaN"), (D, np.full(20, np.inf), "NaN or infinite"),
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
    assert head_solve.laplacian_eigenvalues(np.array([1, 7]), 0.0, np.float32(1.5)).shape == (1, 7)
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


@pytest.mark.parametrize("fn", [losses.tikhonov, losses.total_variation, losses.spatial_differences],
                         ids=lambda f: f.__name__)
@pytest.mark.parametrize("F", [None, "x", np.zeros((2, 4, 4)), torch.zeros(4)], ids=["None", "text", "numpy", "1-D"])
def test_spatial_terms_name_what_is_no_frame_tensor(fn, F):
    _refused(fn, F, match="F must be a torch tensor")


def test_losses_take_batches_and_2d_frames_guard():
    assert float(losses.temporal_loss_difference(torch.zeros(3, 5, 6, 8), E)) == 0.0
    assert float(losses.temporal_loss_derivative(torch.zeros(3, 4, 6, 8), E, torch.ones(4))) == 0.0
    assert float(losses.tikhonov(torch.zeros(4, 6))) == 0.0


def test_linear_frames_takes_a_tensor_that_requires_grad():
    # before: numpy's "Can't call numpy() on Tensor that requires grad"; now read through host_array, as elsewhere
    L = torch.tensor([0.1, -3.0], requires_grad=True)
    assert np.array_equal(anchor.linear_frames(L), anchor.linear_frames(L.detach().numpy()))
