"""Notebook 05's gradient-integration exercise: the reference equals the library's DCT solve, and the
check catches the mistakes it names, on cases that sit on every stated rule."""
import numpy as np

from evinr_lite.method.offset import poisson_integrate
from evinr_lite.teaching import exercises, poisson_exercises


def test_reference_is_the_librarys_dct_solve():
    rng = np.random.default_rng(0)
    for H, W in ((4, 5), (7, 3), (1, 6), (5, 1)):
        gx, gy = rng.normal(size=(H, W - 1)), rng.normal(size=(H - 1, W))
        np.testing.assert_allclose(poisson_exercises.integrate_gradients(gx, gy), poisson_integrate(gx, gy),
                                   atol=1e-9)


def test_exact_gradients_are_recovered_with_mean_zero():
    img = np.random.default_rng(1).normal(size=(6, 7))
    g = poisson_exercises.integrate_gradients(np.diff(img, axis=1), np.diff(img, axis=0))
    np.testing.assert_allclose(g, img - img.mean(), atol=1e-9)


def test_check_cases_sit_on_every_stated_rule():
    cases = [kw for _, kw in exercises.get("integrate_gradients").cases()]
    shapes = [(kw["gx"].shape[0], kw["gy"].shape[1]) for kw in cases]
    assert any(h == 1 for h, _ in shapes) and any(w == 1 for _, w in shapes) and (1, 1) in shapes
    assert any(not np.any(kw["gx"]) and not np.any(kw["gy"]) for kw in cases)          # a zero field


def test_wrong_solutions_fail_with_their_hint(capsys):
    assert exercises.check("integrate_gradients", poisson_exercises.integrate_gradients)
    for wrong, words in ((poisson_exercises._anchored_at_first_pixel, "mean 0"),
                         (poisson_exercises._path_integral, "path integral")):
        capsys.readouterr()
        assert not exercises.check("integrate_gradients", wrong)
        assert words in capsys.readouterr().out
    # differences taken the other way round (g[:, :-1] - g[:, 1:]) give the negated image
    assert not exercises.check("integrate_gradients",
                               lambda gx, gy: -poisson_exercises.integrate_gradients(gx, gy), verbose=False)
    # only the x differences used (the rows integrated independently) fails
    assert not exercises.check("integrate_gradients",
                               lambda gx, gy: poisson_exercises.integrate_gradients(gx, np.zeros_like(gy)), verbose=False)
    # np.linalg.lstsq's minimum-norm solution has mean 0 too: a right answer passes
    def lstsq(gx, gy):
        H, W = gx.shape[0], gy.shape[1]
        D = poisson_exercises._differences(H, W).toarray()
        return np.linalg.lstsq(D, np.concatenate([gx.ravel(), gy.ravel()]), rcond=None)[0].reshape(H, W)
    assert exercises.check("integrate_gradients", lstsq, verbose=False)
