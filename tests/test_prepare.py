"""The solver's step 0 (evinr_lite.method.prepare): hot pixels, the background filter, the ON/OFF
balance and lam, the same for events in memory and for a recording read window by window."""
import numpy as np
import pytest

from evinr_lite.core.events import EventDataError, Events
from evinr_lite.io.source import MemorySource
from evinr_lite.method import EvINRConfig
from evinr_lite.method.denoise import denoise
from evinr_lite.method.prepare import filter_background, prepare_events, prepare_source
from evinr_lite.sim.scenes import OscillatingScene
from evinr_lite.sim.simulate import add_background_noise, add_hot_pixels, simulate_scene

SIZE = (30, 40)


@pytest.fixture(scope="module")
def noisy():
    """6 s to and fro with background activity (1 Hz per pixel) and ON-only hot pixels; the labels
    say which events are background (True)."""
    scene = OscillatingScene("astronaut", SIZE, 6.0, path=((12.0, 4.0, 4.0, 0.0), (2.0, 3.0, 1.3, 1.0)))
    ev = simulate_scene(scene, C=0.225, C_pos=0.25, C_neg=0.20, seed=0)
    ev, added = add_background_noise(ev, 1.0, seed=1, t_start=0.0, t_end=6.0, return_labels=True)
    ev, _ = add_hot_pixels(ev, 4, 200.0, seed=2, on_only=True)
    return ev, added


def _key(ev: Events):
    return np.stack([ev.t, ev.x, ev.y, ev.p])


def test_the_default_filters_background_and_the_paper_keeps_it(noisy):
    ev, _ = noisy
    kept, used = prepare_events(ev, EvINRConfig(C=0.225, background="filter"))
    # the same events as denoise() with its defaults (hot pixels, then the two-sided same-polarity filter)
    reference, _ = denoise(ev)
    assert set(map(tuple, _key(kept).T)) <= set(map(tuple, _key(reference).T))
    assert len(kept) >= 0.99 * len(reference)       # only pixels still hot on the filtered counts may go
    assert used.background == "filter" and used.background_dt == 0.05
    # the kit's default chooses the window from the events: this recording's background activity keeps 50 ms
    assert EvINRConfig().background == "auto"
    assert prepare_events(ev, EvINRConfig(C=0.225))[1].background_dt == 0.05
    assert EvINRConfig.paper().background == EvINRConfig.v0_1().background == "keep"   # the paper's recipe exactly
    assert len(prepare_events(ev, EvINRConfig.paper(C=0.225))[0]) == len(ev)


def test_a_run_that_denoised_first_does_not_filter_again():
    from evinr_lite.apps.options import RunOptions

    assert RunOptions(denoise=True).config(0.2).background == "keep"      # --denoise filtered and reported already
    assert RunOptions().config(0.2).background == "auto"


def test_the_filter_removes_background_and_keeps_signal():
    scene = OscillatingScene("astronaut", SIZE, 6.0, path=((12.0, 4.0, 4.0, 0.0), (2.0, 3.0, 1.3, 1.0)))
    clean = simulate_scene(scene, C=0.2, seed=0)
    ev, added = add_background_noise(clean, 1.0, seed=1, t_start=0.0, t_end=6.0, return_labels=True)
    kept, _ = prepare_events(ev, EvINRConfig(C=0.2, hot_pixels="keep", background="filter"))
    kept_keys = set(map(tuple, _key(kept).T))
    is_kept = np.array([k in kept_keys for k in map(tuple, _key(ev).T)])
    assert is_kept[~added].mean() > 0.95             # signal events stay
    assert is_kept[added].mean() < 0.9               # a share of the background goes
    assert is_kept[added].mean() < is_kept[~added].mean() - 0.1


@pytest.mark.parametrize("tau", [1.5, 2.5])
def test_a_streamed_recording_sees_the_same_events_as_the_whole_span(noisy, tau):
    """Windows read with the filter's reach beyond their edges: the events near an edge are judged on
    the same neighbours, so the windows together are exactly the whole span's prepared events."""
    ev, _ = noisy
    cfg = EvINRConfig(C=0.225, tau=tau, progress=False)
    t0, t1 = 0.0, float(ev.t[-1])
    whole_ev, whole = prepare_events(ev, cfg, (t0, t1))
    streamed, source = prepare_source(MemorySource(ev), t0, t1, cfg)
    assert streamed.C == whole.C and streamed.lam == whole.lam
    edges = np.append(np.arange(t0, t1, tau / 3), np.nextafter(t1, np.inf))
    parts = [source.events(a, b) for a, b in zip(edges[:-1], edges[1:])]
    np.testing.assert_array_equal(np.concatenate([_key(p) for p in parts], axis=1), _key(whole_ev))
    # the reach matters: filtered alone, a window loses edge events whose neighbours lie beyond it
    only_filter = EvINRConfig(C=0.225, tau=tau, hot_pixels="keep", balance="none", lam=0.01, background="filter",
                              progress=False)
    _, plain = prepare_source(MemorySource(ev), t0, t1, only_filter)
    a, b = 1.0, 1.0 + tau
    alone, wide = filter_background(ev.slice_time(a, b, allow_empty=True), only_filter.background_dt), plain.events(a, b)
    assert set(map(tuple, _key(alone).T)) < set(map(tuple, _key(wide).T))


def test_a_recording_of_isolated_events_is_refused_with_the_fix():
    rng = np.random.default_rng(0)
    n = 200
    t = np.sort(rng.uniform(0.0, 20.0, n))           # one event per 0.1 s on a 30x40 sensor: no neighbour
    ev = Events.from_arrays(t, rng.integers(0, 40, n), rng.integers(0, 30, n), rng.choice([-1, 1], n), SIZE)
    with pytest.raises(EventDataError, match="background='keep'"):
        prepare_events(ev, EvINRConfig(C=0.2))
    with pytest.raises(EventDataError, match="background='keep'"):
        prepare_source(MemorySource(ev), 0.0, 20.0, EvINRConfig(C=0.2))
    kept, _ = prepare_events(ev, EvINRConfig(C=0.2, background="keep"))
    assert len(kept) == n


def test_an_unknown_background_mode_is_refused():
    with pytest.raises(EventDataError, match="background must be one of"):
        EvINRConfig(background="median")


def test_a_span_of_one_chunk_is_read_once_and_prepared_as_the_whole_span(noisy):
    ev, _ = noisy

    class Counting(MemorySource):
        def __init__(self, events):
            super().__init__(events)
            self.reads = 0

        def _read_window(self, t0, t1):
            self.reads += 1
            return super()._read_window(t0, t1)

    cfg = EvINRConfig(C=0.225, tau=10.0, progress=False)            # the 6 s span is one counting chunk
    t0, t1 = 0.0, float(ev.t[-1])
    whole_ev, whole = prepare_events(ev, cfg, (t0, t1))
    counting = Counting(ev)
    streamed, source = prepare_source(counting, t0, t1, cfg)
    assert counting.reads == 1 and streamed.C == whole.C and streamed.lam == whole.lam
    parts = [source.events(a, b) for a, b in ((0.0, 2.0), (2.0, 4.5), (4.5, np.nextafter(t1, np.inf)))]
    np.testing.assert_array_equal(np.concatenate([_key(p) for p in parts], axis=1), _key(whole_ev))
    assert counting.reads == 1                                        # the windows are slices, not reads
