"""Exercise checks of notebooks 09-11 catch the mistakes they name: events on a bin edge, fancy-index `+=`,
rows and columns swapped, `>=` on a stated strict threshold; and notebook 10's Jensen's-gap helper."""
import numpy as np
import pytest

from evinr_lite.teaching import aed_exercises, exercises, realdata_exercises, recording_exercises
from evinr_lite.method.contrast import estimate_contrast_threshold


def _fails_with_hint(capsys, name, wrong, words):
    capsys.readouterr()
    assert not exercises.check(name, wrong)
    out = capsys.readouterr().out
    assert words in out, out


# ---- notebook 09: event_rate, bins (b_k, b_{k+1}] (the library's rule) -----------------------------

def _rate_by_edges(t, bin_s, side):
    """Counts by ``searchsorted(edges, t, side) - 1``; side 'left' is the rule (b_k, b_{k+1}]."""
    t = np.asarray(t, dtype=np.float64)
    span = (t[-1] - t[0]) / bin_s
    n_bins = max(int(np.ceil(span)), 1) if side == "left" else int(np.floor(span)) + 1
    edges = t[0] + np.arange(n_bins + 1) * bin_s
    k = np.clip(np.searchsorted(edges, t, side=side) - 1, 0, n_bins - 1)
    return t[0] + (np.arange(n_bins) + 0.5) * bin_s, np.bincount(k, minlength=n_bins) / bin_s


def test_event_rate_check_has_events_on_bin_edges(capsys):
    assert exercises.check("event_rate", realdata_exercises.event_rate)
    assert exercises.check("event_rate", lambda t, bin_s: _rate_by_edges(t, bin_s, "left"))    # (b_k, b_{k+1}]
    _fails_with_hint(capsys, "event_rate", lambda t, bin_s: _rate_by_edges(t, bin_s, "right"), "side='left'")
    _fails_with_hint(capsys, "event_rate", realdata_exercises._rate_edges_to_later_bin, "belongs to bin k - 1")
    # the first event sits on edge b_0: a rule that drops it (no clip at 0) fails too
    def drops_first(t, bin_s):
        centers, rate = realdata_exercises.event_rate(t, bin_s)
        k = np.ceil((np.asarray(t) - t[0]) / bin_s).astype(int) - 1
        return centers, np.bincount(k[k >= 0], minlength=len(centers)) / bin_s
    assert not exercises.check("event_rate", drops_first, verbose=False)
    # the boundary cases really put events on edges, ties and empty bins (else wrong rules pass by luck)
    cases = [kw for _, kw in exercises.get("event_rate").cases()]
    on_edge = [np.any(np.isclose(((kw["t"] - kw["t"][0]) / kw["bin_s"]) % 1, 0) & (kw["t"] > kw["t"][0]))
               for kw in cases]
    assert sum(on_edge) >= 2
    assert any(np.unique(kw["t"]).size < kw["t"].size for kw in cases)                     # ties
    assert any(np.any(realdata_exercises.event_rate(**kw)[1] == 0) for kw in cases)        # an empty bin


def test_teaching_and_library_event_rate_agree_on_edges():
    """One bin-edge rule: the teaching reference and method.binning.event_rate count events exactly on
    edges in the same (earlier) bin."""
    from evinr_lite.core.events import Events
    from evinr_lite.method.binning import event_rate as library_event_rate
    t = np.array([1.0, 1.125, 1.25, 1.25, 1.3, 1.5, 1.625, 2.0])
    events = Events.from_arrays(t, np.zeros(t.size, int), np.zeros(t.size, int), np.ones(t.size, int), (1, 1))
    edges, on, off = library_event_rate(events, 0.125)
    _, rate = realdata_exercises.event_rate(t, 0.125)
    np.testing.assert_allclose(rate * 0.125, (on + off) * np.diff(edges))


def test_contrast_threshold_exercise_is_registered_by_notebook_09s_module(capsys):
    assert exercises.get("estimate_contrast_threshold").reference is estimate_contrast_threshold
    assert realdata_exercises.estimate_contrast_threshold is estimate_contrast_threshold
    assert "estimate_contrast_threshold" not in recording_exercises.__all__    # one C-fit exercise, in 09
    polyfit = lambda log_changes, net_counts: float(np.polyfit(net_counts, log_changes, 1)[0])  # noqa: E731
    _fails_with_hint(capsys, "estimate_contrast_threshold", polyfit, "through the origin")


# ---- notebook 10: grey_event_frame and Jensen's gap -------------------------------------------

def test_grey_event_frame_catches_fancy_index_and_swapped_axes(capsys):
    _fails_with_hint(capsys, "grey_event_frame", aed_exercises._grey_fancy_index, "np.add.at")

    def swapped(x, y, p, C, raw_size):
        H, W = raw_size
        frame = np.zeros((H // 4, W // 4))
        np.add.at(frame, (np.asarray(x) // 4, np.asarray(y) // 4), C * np.asarray(p, float) / 16)
        return frame

    _fails_with_hint(capsys, "grey_event_frame", swapped, "rows are y")


def test_jensen_gap_is_negative_and_second_order_where_the_spread_is_small():
    rng = np.random.default_rng(0)
    I = np.exp(rng.normal(0.0, 0.05, (3, 8, 12)))                 # small spread
    gap, second = aed_exercises.jensen_gap(I)
    assert gap.shape == second.shape == (3, 2, 3)
    direct = np.log(I[0, :4, :4]).mean() - np.log(I[0, :4, :4].mean())
    assert np.isclose(gap[0, 0, 0], direct)
    assert np.all(gap <= 0) and np.all(second <= 0)
    np.testing.assert_allclose(gap, second, rtol=0.1)             # agree to second order
    big = np.exp(rng.normal(0.0, 0.8, (8, 8)))                    # large spread: the formula drifts
    g, s = aed_exercises.jensen_gap(big)
    assert np.all(g <= 0) and np.abs(g - s).max() > 0.01
    uniform = np.full((4, 4), 0.3)
    assert np.allclose(aed_exercises.jensen_gap(uniform)[0], 0)


# ---- notebook 11: hot_pixel_mask, count > factor x median (strict) ------------------------------

def test_hot_pixel_check_catches_the_named_mistakes(capsys):
    assert exercises.check("hot_pixel_mask", recording_exercises.hot_pixel_mask)
    _fails_with_hint(capsys, "hot_pixel_mask", recording_exercises._hot_at_threshold, "strict `>`")
    _fails_with_hint(capsys, "hot_pixel_mask", recording_exercises._hot_median_all_pixels, "pixels that fired")
    _fails_with_hint(capsys, "hot_pixel_mask", recording_exercises._hot_mean, "not the mean")
    _fails_with_hint(capsys, "hot_pixel_mask", recording_exercises._hot_fancy_index, "np.add.at")

    def swapped(x, y, sensor_size, factor=10.0):
        counts = np.zeros(sensor_size, np.int64)
        np.add.at(counts, (np.asarray(x), np.asarray(y)), 1)
        return counts > factor * np.median(counts[counts > 0])

    _fails_with_hint(capsys, "hot_pixel_mask", swapped, "rows are y")


def test_hot_pixel_mask_finds_injected_hot_pixels_and_nothing_else():
    """The teaching rule on a Poisson sensor with 4 injected hot pixels (pin the library's
    evinr_lite.method.denoise hot-pixel map to this behaviour once it exists)."""
    rng = np.random.default_rng(3)
    H, W = 30, 40
    counts = rng.poisson(2.0, (H, W)) * (rng.uniform(size=(H, W)) < 0.5)
    hot = rng.choice(H * W, 4, replace=False)
    counts.ravel()[hot] = rng.integers(200, 1000, 4)
    y, x = np.nonzero(counts)
    reps = counts[y, x]
    mask = recording_exercises.hot_pixel_mask(np.repeat(x, reps), np.repeat(y, reps), (H, W))
    assert mask.dtype == bool and mask.shape == (H, W)
    assert sorted(np.flatnonzero(mask)) == sorted(hot)
    # the threshold is strict: a pixel at exactly factor x median is not hot
    m = np.median(counts[counts > 0])
    assert not recording_exercises.hot_pixel_mask(np.repeat(x, reps), np.repeat(y, reps), (H, W),
                                                  factor=counts.max() / m).any()


@pytest.mark.parametrize("name", ["event_rate", "estimate_contrast_threshold", "quad_bayer_channel",
                                  "grey_event_frame", "hot_pixel_mask", "event_count_windows",
                                  "anchor_first_offset", "background_activity_filter"])
def test_references_pass_their_own_checks(name):
    assert exercises.check(name, exercises.reference(name), verbose=False)


def test_hot_pixel_teaching_rule_is_the_librarys_median_rule():
    """Pins notebook 11's teaching reference to evinr_lite.method.denoise (its rule="median")."""
    denoise = pytest.importorskip("evinr_lite.method.denoise")
    from evinr_lite import Events
    rng = np.random.default_rng(5)
    for factor in (4.0, 10.0):
        for case in exercises.get("hot_pixel_mask").cases():
            kw = case[1]
            H, W = kw["sensor_size"]
            n = len(kw["x"])
            events = Events.from_arrays(np.sort(rng.uniform(0, 1, n)), kw["x"], kw["y"], rng.choice([-1, 1], n), (H, W))
            np.testing.assert_array_equal(recording_exercises.hot_pixel_mask(kw["x"], kw["y"], (H, W), factor),
                                          denoise.hot_pixel_mask(events, factor=factor, rule="median"))


# ---- notebook 09: anchor_first_offset, pinned to method/anchor.py -----------------------------

def test_anchor_first_offset_is_fit_anchors_first_mode():
    """The teaching reference gives the offset of method.anchor.fit_anchor(mode="first") (uint8 and float frames)."""
    from evinr_lite.core.frames import Frames
    from evinr_lite.method.anchor import fit_anchor
    rng = np.random.default_rng(7)
    for images in (rng.integers(0, 256, (3, 6, 9)).astype(np.uint8), rng.uniform(0, 1, (3, 6, 9))):
        frames = Frames(images, np.array([0.1, 0.2, 0.3]))
        L = rng.normal(-1.0, 0.7, (6, 9))
        fit = fit_anchor(lambda t: np.broadcast_to(L, (len(t), 6, 9)), frames, "first")
        np.testing.assert_allclose(realdata_exercises.anchor_first_offset(images[0], L), fit.values[0],
                                   rtol=1e-6, atol=1e-6)   # fit.values are float32
        assert np.allclose(fit.times, [0.1])


def test_anchor_first_offset_check_catches_the_named_mistakes(capsys):
    assert exercises.check("anchor_first_offset", realdata_exercises.anchor_first_offset)
    _fails_with_hint(capsys, "anchor_first_offset", realdata_exercises._offset_wrong_sign, "not L(t0) - log")
    _fails_with_hint(capsys, "anchor_first_offset", realdata_exercises._offset_no_scaling, "divide by 255")
    _fails_with_hint(capsys, "anchor_first_offset", realdata_exercises._offset_eps_outside, "inside the log")
    _fails_with_hint(capsys, "anchor_first_offset", realdata_exercises._offset_mean_only, "one offset per pixel")


# ---- notebook 11: background_activity_filter, t_j <= t_i <= t_j + dt (both ends inclusive) -----------

def test_background_activity_filter_is_the_librarys_correlation_filter():
    """Pins notebook 11's pairwise reference to method.denoise.correlation_filter (8 neighbours, one
    neighbour, any polarity, causal window), on the check's own cases and on random streams with ties."""
    from evinr_lite import Events
    from evinr_lite.method.denoise import correlation_filter
    rng = np.random.default_rng(11)
    inputs = [kw for _, kw in exercises.get("background_activity_filter").cases()]
    for n in (50, 300):
        t = np.sort(np.round(rng.uniform(0, 0.02, n), 4))             # whole 100 us: many equal timestamps
        inputs.append(dict(t=t, x=rng.integers(0, 8, n), y=rng.integers(0, 6, n), dt=0.001))
    for kw in inputs:
        H, W = int(kw["y"].max()) + 1, int(kw["x"].max()) + 1
        events = Events.from_arrays(kw["t"], kw["x"], kw["y"], rng.choice([-1, 1], len(kw["t"])), (H, W))
        lib = correlation_filter(events, kw["dt"], neighbourhood=8, min_neighbours=1, same_polarity=False,
                                 window="before")
        np.testing.assert_array_equal(recording_exercises.background_activity_filter(**kw), lib)


def test_background_activity_filter_check_has_the_boundary_cases(capsys):
    assert exercises.check("background_activity_filter", recording_exercises.background_activity_filter)
    _fails_with_hint(capsys, "background_activity_filter", recording_exercises._filter_strict_dt, "exactly dt")
    _fails_with_hint(capsys, "background_activity_filter", recording_exercises._filter_strictly_earlier,
                     "same timestamp counts")
    _fails_with_hint(capsys, "background_activity_filter", recording_exercises._filter_stream_order,
                     "not positions in the stream")
    _fails_with_hint(capsys, "background_activity_filter", recording_exercises._filter_own_pixel, "own events")
    _fails_with_hint(capsys, "background_activity_filter", recording_exercises._filter_four_neighbours, "diagonals")
    # the first case really has a neighbour exactly dt earlier and a tie (else the wrong rules could pass by luck)
    kw = exercises.get("background_activity_filter").cases()[0][1]
    d = kw["t"][:, None] - kw["t"][None, :]
    assert np.any(d == kw["dt"]) and np.any((d == 0) & ~np.eye(len(kw["t"]), dtype=bool))
