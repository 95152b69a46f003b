"""viz (event-data figures) by their properties, and notebook 02's reference solutions (events2d)."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.colors import to_rgb  # noqa: E402
from matplotlib.image import AxesImage  # noqa: E402

from evinr_lite.teaching import events2d, exercises  # noqa: E402
from evinr_lite.viz import signals as plotting, events as viz  # noqa: E402
from evinr_lite.method.binning import events_to_frames  # noqa: E402
from evinr_lite.core.events import EventDataError, Events  # noqa: E402
from evinr_lite.sim.simulate import simulate_video  # noqa: E402

WHITE = (1.0, 1.0, 1.0)


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def make_events(t, x, y, p, size=(3, 4)):
    return Events(np.asarray(t, float), np.asarray(x), np.asarray(y), np.asarray(p), size)


def random_events(n=500, size=(6, 8), seed=0, t1=1.0):
    rng = np.random.default_rng(seed)
    H, W = size
    return Events(np.sort(rng.uniform(0, t1, n)), rng.integers(0, W, n), rng.integers(0, H, n),
                  rng.choice([-1, 1], n), size)


# ---- colours and numbers ---------------------------------------------------------------

def test_colours_are_the_packages_on_red_off_blue():
    assert viz.ON_COLOR == plotting.ON_COLOR and viz.OFF_COLOR == plotting.OFF_COLOR
    assert viz.ON_RGB == to_rgb(plotting.ON_COLOR) and viz.OFF_RGB == to_rgb(plotting.OFF_COLOR)
    r, g, b = viz.ON_RGB
    assert r > g and r > b                      # red
    r, g, b = viz.OFF_RGB
    assert b > r and b > g                      # blue


def test_subsample_index_is_seeded_sorted_and_bounded():
    a = viz.subsample_index(1000, 50, seed=3)
    assert a.shape == (50,) and a.dtype == np.int64
    assert np.all(np.diff(a) > 0) and a.min() >= 0 and a.max() < 1000     # sorted, unique, in range
    assert np.array_equal(a, viz.subsample_index(1000, 50, seed=3))       # deterministic
    assert not np.array_equal(a, viz.subsample_index(1000, 50, seed=4))
    assert np.array_equal(viz.subsample_index(7, 50), np.arange(7))       # small: everything
    with pytest.raises(EventDataError, match="max_points"):
        viz.subsample_index(10, 0)


def test_subsample_keeps_time_order_and_values():
    ev = random_events(300)
    sub = viz.subsample(ev, 40, seed=1)
    idx = viz.subsample_index(len(ev), 40, seed=1)
    assert len(sub) == 40 and np.all(np.diff(sub.t) >= 0)
    assert np.array_equal(sub.t, ev.t[idx]) and np.array_equal(sub.p, ev.p[idx])


def test_count_map_counts_every_event_at_its_pixel():
    ev = make_events([0.1, 0.2, 0.3, 0.4, 0.5], [0, 0, 3, 3, 3], [0, 0, 2, 2, 1], [1, -1, 1, 1, -1])
    c = viz.count_map(ev)
    assert c.shape == (3, 4) and c.dtype == np.int64 and c.sum() == 5
    assert c[0, 0] == 2 and c[2, 3] == 2 and c[1, 3] == 1                  # [y, x]
    assert viz.count_map(ev, 1)[2, 3] == 2 and viz.count_map(ev, -1)[2, 3] == 0
    assert viz.count_map(ev, 1).sum() + viz.count_map(ev, -1).sum() == 5
    with pytest.raises(EventDataError, match="polarity"):
        viz.count_map(ev, 0)


def test_polarity_image_colours_on_off_and_empty_pixels():
    # pixel (x=0, y=0): ON only; (x=1, y=0): OFF only; (x=2, y=0): one of each; (x=3, y=2): ON twice, OFF once
    ev = make_events([0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7], [0, 1, 2, 2, 3, 3, 3], [0, 0, 0, 0, 2, 2, 2],
                     [1, -1, 1, -1, 1, -1, 1])
    img = viz.polarity_image(ev)
    assert img.shape == (3, 4, 3) and img.dtype == np.float64 and img.min() >= 0 and img.max() <= 1
    assert tuple(img[0, 0]) == viz.ON_RGB
    assert tuple(img[0, 1]) == viz.OFF_RGB
    assert tuple(img[0, 2]) == WHITE                  # balanced
    assert tuple(img[2, 3]) == viz.ON_RGB             # net +1
    assert tuple(img[1, 1]) == WHITE                  # no events
    grey = viz.polarity_image(ev, background=(0.5, 0.5, 0.5))
    assert tuple(grey[1, 1]) == (0.5, 0.5, 0.5) and tuple(grey[0, 0]) == viz.ON_RGB


def test_polarity_image_window_is_open_left_closed_right():
    ev = make_events([0.1, 0.2, 0.3], [0, 1, 2], [0, 0, 0], [1, 1, -1])
    img = viz.polarity_image(ev, 0.1, 0.3)            # (0.1, 0.3]: drops t = 0.1, keeps t = 0.3
    assert tuple(img[0, 0]) == WHITE
    assert tuple(img[0, 1]) == viz.ON_RGB
    assert tuple(img[0, 2]) == viz.OFF_RGB
    with pytest.raises(EventDataError, match="reversed"):
        viz.polarity_image(ev, 0.3, 0.1)


def test_event_rate_counts_match_and_edges_use_the_bin_convention():
    ev = random_events(400)
    edges, on, off = viz.event_rate(ev, 0.1, (0.0, 1.0))
    assert edges.shape == (11,) and on.shape == off.shape == (10,)
    dur = np.diff(edges)
    assert np.allclose((on + off) * dur, np.round((on + off) * dur))        # whole counts
    assert round(np.sum(on * dur)) == np.sum(ev.p > 0) and round(np.sum(off * dur)) == np.sum(ev.p < 0)
    # an event exactly on an inner edge belongs to the bin that ends there
    e = make_events([0.0, 0.5, 0.75], [0, 0, 0], [0, 0, 0], [1, 1, -1])
    edges, on, off = viz.event_rate(e, 0.5, (0.0, 1.0))
    assert np.allclose(on * np.diff(edges), [2, 0]) and np.allclose(off * np.diff(edges), [0, 1])
    assert np.allclose(on, [4.0, 0.0])                                      # events per second


# ---- figures ----------------------------------------------------------------------------

def _n_points(coll):
    return len(coll.get_offsets())


def test_plot_xyt_draws_a_seeded_subset_in_on_off_colours():
    ev = random_events(2000)
    ax = viz.plot_xyt(ev, max_points=300, seed=0)
    assert ax.name == "3d"
    on_coll, off_coll = ax.collections
    sub = viz.subsample(ev, 300, seed=0)
    assert _n_points(on_coll) == np.sum(sub.p > 0) and _n_points(off_coll) == np.sum(sub.p < 0)
    assert _n_points(on_coll) + _n_points(off_coll) == 300
    assert np.allclose(on_coll.get_facecolor()[0, :3], viz.ON_RGB)
    assert np.allclose(off_coll.get_facecolor()[0, :3], viz.OFF_RGB)
    small = random_events(50)
    ax = viz.plot_xyt(small, max_points=300)
    assert sum(_n_points(c) for c in ax.collections) == 50


def test_plot_count_map_and_polarity_show_the_numbers():
    ev = random_events(200)
    ax = viz.plot_count_map(ev)
    (im,) = [a for a in ax.get_children() if isinstance(a, AxesImage)]
    assert np.array_equal(im.get_array(), viz.count_map(ev))
    ax = viz.plot_polarity(ev, 0.2, 0.6)
    (im,) = [a for a in ax.get_children() if isinstance(a, AxesImage)]
    assert np.array_equal(im.get_array(), viz.polarity_image(ev, 0.2, 0.6))
    n = np.sum((ev.t > 0.2) & (ev.t <= 0.6))
    assert f"{n} events" in ax.get_title()


def test_plot_event_rate_and_boundaries_draw_one_artist_per_thing():
    ev = random_events(300)
    ax = viz.plot_event_rate(ev, 0.25, t_range=(0.0, 1.0))
    assert len(ax.patches) == 2                                   # ON and OFF steps
    b1, b2 = np.linspace(0, 1, 5), np.array([0.0, 0.3, 1.0])
    ax = viz.plot_boundaries(ev, {"a": b1, "b": b2})
    segments = [len(c.get_segments()) for c in ax.collections]
    assert segments == [5, 3]                                     # one line per edge, per set
    (curve,) = ax.lines
    assert curve.get_ydata()[-1] == len(ev)                       # the cumulative count ends at N


def test_show_event_frames_panels_share_a_symmetric_scale():
    ev = random_events(600)
    fr = events_to_frames(ev, np.linspace(0, 1, 11), C=0.25)
    fig = viz.show_event_frames(fr, indices=[0, 3, 9], ncols=2)
    images = [a for ax in fig.axes for a in ax.get_children() if isinstance(a, AxesImage)]
    assert len(images) == 3
    vmax = np.abs(fr.frames[[0, 3, 9]]).max()
    for im, i in zip(images, [0, 3, 9]):
        assert im.get_clim() == (-vmax, vmax)
        assert np.array_equal(im.get_array(), fr.frames[i])
    titles = [ax.get_title() for ax in fig.axes if ax.get_title()]
    assert any(f"{fr.counts[3]} events" in t for t in titles)
    fig = viz.show_event_frames(fr, max_frames=4)                 # evenly spread default
    assert len([a for ax in fig.axes for a in ax.get_children() if isinstance(a, AxesImage)]) == 4
    with pytest.raises(EventDataError):
        viz.show_event_frames(fr, indices=[])


def test_animate_events_frames_are_polarity_images_of_consecutive_windows():
    ev = random_events(400)
    anim = viz.animate_events(ev, n_frames=5, t_range=(0.0, 1.0))
    assert anim.windows.shape == (5, 2)
    assert np.allclose(anim.windows[:, 1] - anim.windows[:, 0], 0.2)
    assert np.allclose(anim.windows[1:, 0], anim.windows[:-1, 1])      # consecutive, no gaps
    assert anim.windows[-1, 1] == pytest.approx(1.0) and anim.windows[0, 0] == pytest.approx(0.0)
    for k in (0, 3):
        image, title = anim.draw_frame(k)
        assert np.array_equal(image.get_array(), viz.polarity_image(ev, *anim.windows[k]))
    sliding = viz.animate_events(ev, n_frames=4, window_s=0.05, t_range=(0.0, 1.0))
    assert np.allclose(np.diff(sliding.windows, axis=1), 0.05) and sliding.windows[-1, 1] == pytest.approx(1.0)
    assert plt.get_fignums() == []                                       # closed: no stray static copy
    html = anim.to_jshtml()
    assert html.count("data:image/png;base64") == 5                      # one picture per frame
    sliding.to_jshtml()
    with pytest.raises(EventDataError):
        viz.animate_events(ev, n_frames=0)


# ---- notebook 02's reference solutions ---------------------------------------------------

@pytest.mark.parametrize("seed", [0, 1, 2])
def test_events_to_frames_fixed_equals_the_package(seed):
    ev = random_events(800, size=(5, 7), seed=seed)
    rng = np.random.default_rng(seed)
    b = np.concatenate([[0.05], np.sort(rng.uniform(0.1, 0.9, 6)), [0.95]])
    b[3] = ev.t[100]                                         # an event exactly on an inner edge
    b[0] = ev.t[10]                                          # ... and on the first edge
    b = np.sort(b)
    mine = events2d.events_to_frames_fixed(ev, b, 0.3)
    assert mine.dtype == np.float32
    assert np.array_equal(mine, events_to_frames(ev, b, 0.3).frames)


def test_esim_interval_run_over_a_video_equals_simulate_video():
    rng = np.random.default_rng(0)
    t = np.linspace(0, 1, 41)
    L = np.cumsum(rng.normal(0, 0.15, (41, 3, 4)), axis=0)   # a random-walk video
    C = 0.1
    ev = simulate_video(L, t, C)
    for y in range(3):
        for x in range(4):
            ref, times, pols = L[0, y, x], [], []
            for k in range(1, t.size):
                tk, pk, ref = events2d.esim_interval(L[k - 1, y, x], L[k, y, x], t[k - 1], t[k], ref, C)
                assert np.all(np.diff(tk) > 0) and np.all((tk >= t[k - 1]) & (tk <= t[k]))
                times.extend(tk), pols.extend(pk)
            t_px, p_px = events2d.pixel_trace(ev, x, y)
            assert len(times) == len(t_px)
            assert np.allclose(times, t_px, rtol=0, atol=1e-12) and np.array_equal(pols, p_px)


def test_esim_interval_several_events_and_remainder():
    times, p, ref = events2d.esim_interval(0.0, 0.55, 1.0, 2.0, 0.0, 0.25)
    assert np.allclose(times, [1 + 0.25 / 0.55, 1 + 0.5 / 0.55]) and list(p) == [1, 1] and ref == pytest.approx(0.5)
    times, p, ref = events2d.esim_interval(0.0, 0.1, 1.0, 2.0, 0.0, 0.25)
    assert times.size == 0 and p.size == 0 and ref == 0.0


def test_busiest_pixel():
    ev = make_events([0.1, 0.2, 0.3], [2, 2, 1], [1, 1, 0], [1, -1, 1])
    assert events2d.busiest_pixel(ev) == (2, 1)


@pytest.mark.parametrize("name", ["esim_interval", "events_to_frames_fixed"])
def test_exercise_checks_pass_the_reference_and_name_each_known_mistake(name, capsys):
    ex = exercises.get(name)
    assert exercises.check(name, ex.reference)
    for message, wrong in ex.hints.items():
        assert not exercises.check(name, wrong)
        assert message in capsys.readouterr().out, f"the hint {message!r} is never shown"


def test_show_frames_colour_bar_is_one_shared_labelled_bar():
    from evinr_lite.viz import show_frames

    frames = np.random.default_rng(0).normal(size=(3, 4, 5))
    fig = show_frames({"a": frames, "b": -frames}, [0.1, 0.2, 0.3], cmap="RdBu_r", vmin=-2, vmax=2,
                      colorbar_label="change of log intensity")
    bars = [ax for ax in fig.axes if ax.get_label() == "<colorbar>"]
    assert len(bars) == 1 and bars[0].get_ylabel() == "change of log intensity"
    assert bars[0].get_ylim() == (-2.0, 2.0)
    plain = show_frames({"a": frames})
    assert not [ax for ax in plain.axes if ax.get_label() == "<colorbar>"]
    plt.close("all")
