"""Round 9 of the bad-input table (tests/test_robustness*.py): the background filter whose window is chosen from the
events (``EvINRConfig(background="auto")``, the default; evinr_lite/method/background.py and prepare.py), in memory
and streamed, on recordings and arguments a user or a careless caller brings.

Fixes (each test failed before its fix): a scene off the centre of a sensor larger than the 256 x 256 square that is
measured (a corner of a 1280 x 720 sensor) was measured on no event and got the fixed 50 ms window without a word,
where the same events on their own sensor keep 0.4 s; a span longer than 8 s whose events lie at its start and end
(or query times far past the events) had evenly spread 2 s slices holding no event, and the same silent fall-back;
a sensor of one pixel (no neighbouring pixels) got auto's 50 ms filter, which drops every event, and an error
blaming noise; every event at one instant with "auto" was refused as an empty "time window [t, t)" nobody gave
(read inside the chooser), not as the empty span that "keep" and "filter" name; the filter's error spoke of "a 50
ms neighbourhood" whatever the window (0.2 s given, or chosen); ``EvINRConfig(background_dt=0.2)`` with the default
"auto" was accepted and the 0.2 s silently replaced by the chosen window; the module functions took bad arguments
without a word or failed deep inside numpy: ``sample_spans`` of an infinite, NaN or reversed span gave slices at
inf / NaN, ``fit_background(events)`` was Python's TypeError, ``seed=None`` drew unseeded (not deterministic),
``neighbour_gaps`` with queries of different lengths an IndexError, and queries off the sensor, at NaN times or
between pixels were answered, a single number as a query was numpy's IndexError, ``reach(0)`` / ``reach(nan)`` gave
0 / nan (and ``reach("0.1")`` 0.2), and ``prepare_events`` / ``prepare_source`` / ``choose_background`` with a NaN,
infinite or reversed span named an inner ``slice_time`` or a "window [0.5, 5e-324)" instead of their argument.

Guards: odd inputs next to these that already behave and must keep their outcome (fewer than MIN_EVENTS events,
every event at one pixel or at isolated pixels, thin sensors, one polarity, spans either side of the 8 s limit,
duplicate events, hot pixels, bad background_dt and background values, a huge window, the returned config fed
back, determinism, the streamed path choosing as the in-memory one).
"""
import decimal

import numpy as np
import pytest

from evinr_lite import EventDataError, Events, EvINRConfig, reconstruct
from evinr_lite.io.source import MemorySource
from evinr_lite.method.background import GRID, MIN_EVENTS, SLICE_S, fit_background, neighbour_gaps, sample_spans
from evinr_lite.method.denoise import DEFAULT_DT
from evinr_lite.method.prepare import choose_background, filter_background, prepare_events, prepare_source, reach
from evinr_lite.method.streaming import stream_reconstruct

from test_robustness import H, W, _events, run

FASTCFG = dict(n_iters=0, progress=False)       # the head solved, no training: the preparation is what is tested
BIG = (720, 1280)                               # larger than the 256 x 256 square measured


def _random(n, size=(H, W), span=0.5, seed=0, p=None):
    rng = np.random.default_rng(seed)
    pol = rng.choice([-1, 1], n) if p is None else np.full(n, p)
    return Events.from_arrays(np.sort(rng.uniform(0, span, n)), rng.integers(0, size[1], n),
                              rng.integers(0, size[0], n), pol, size)


def _moved(ev, dy=0, dx=0, size=None, dt=0.0):
    return Events.from_arrays(ev.t + dt, ev.x + dx, ev.y + dy, ev.p, size or ev.sensor_size)


def _joined(a, b):
    return Events.from_arrays(np.concatenate([a.t, b.t]), np.concatenate([a.x, b.x]), np.concatenate([a.y, b.y]),
                              np.concatenate([a.p, b.p]), a.sensor_size)


@pytest.fixture(scope="module")
def pan():
    """A slow clean pan (3 px/s, 2 s, 30 x 40): its edges take 0.3 s to reach the next pixel, so "auto" keeps a long
    window (0.4 s); a 50 ms one would drop real events."""
    from evinr_lite.sim.scenes import MovingImageScene
    from evinr_lite.sim.simulate import simulate_scene

    scene = MovingImageScene("camera", (30, 40), 2.0, velocity=(3.0, 1.0), rotation=0.0, zoom=0.0)
    return simulate_scene(scene, 0.0, 2.0, C=0.2, seed=0)


@pytest.fixture(scope="module")
def burst():
    """1 s of a faster pan (20 x 24): the recording's activity, repeated later in the long spans below."""
    from evinr_lite.sim.scenes import MovingImageScene
    from evinr_lite.sim.simulate import simulate_scene

    scene = MovingImageScene("camera", (20, 24), 1.0, velocity=(8.0, 3.0), rotation=0.0, zoom=0.0)
    return simulate_scene(scene, 0.0, 1.0, C=0.25, seed=0)


def _chosen(cfg):
    return cfg.background, (cfg.background_dt if cfg.background == "filter" else None)


def _both(ev, span=None, **over):
    """(in memory, streamed in two counting passes): what "auto" chose on ``ev`` over ``span``."""
    t0, t1 = (float(ev.t[0]), float(ev.t[-1])) if span is None else span
    cfg = EvINRConfig(progress=False, **over)
    memory = prepare_events(ev, cfg, (t0, t1))[1]
    chunk = max((t1 - t0) / 3, 1e-3)                       # a span of several chunks: the two-pass path
    streamed = prepare_source(MemorySource(ev), t0, t1, cfg, chunk_s=chunk)[0]
    return _chosen(memory), _chosen(streamed)


# ---- 1. fixes: measured where the events are ------------------------------------------------------------------

@pytest.mark.parametrize("corner", [(0, 0), (BIG[0] - 30, BIG[1] - 40)], ids=["top left", "bottom right"])
def test_a_scene_off_the_centre_of_a_large_sensor_is_measured_where_it_is(pan, corner):
    """The centre's 256 x 256 square held none of the events: the fixed 50 ms window, where on its own sensor the
    same scene keeps 0.4 s."""
    alone = fit_background([(pan, (0.0, 2.0))])
    big = _moved(pan, *corner, size=BIG)
    fit = fit_background([(big, (0.0, 2.0))])
    assert fit.n_events == alone.n_events == len(pan)
    assert fit.dt == alone.dt and fit.dt in (max(GRID), None)
    assert abs(fit.noise_share - alone.noise_share) < 0.01


def test_a_scene_off_the_centre_is_chosen_for_alike_in_memory_and_streamed(pan):
    big = _moved(pan, 0, BIG[1] - 40, size=BIG)
    memory, streamed = _both(big)
    assert memory == streamed and memory[1] != DEFAULT_DT


@pytest.mark.parametrize("gap", [12.0, 30.0])
def test_a_long_span_with_events_only_at_its_ends_is_measured_on_them(burst, gap):
    """Evenly spread 2 s slices of a 13 or 31 s span fell between the two bursts: no event measured, 50 ms."""
    from evinr_lite.method.background import busy_spans, tile_counts

    ev = _joined(burst, _moved(burst, dt=gap))
    near = _joined(burst, _moved(burst, dt=6.5))           # the same bursts within 8 s: measured whole
    memory, streamed = _both(ev)
    assert memory == streamed == _both(near)[0]
    assert memory[1] != DEFAULT_DT
    tiles = tile_counts(ev.t, float(ev.t[0]), float(ev.t[-1]))
    spans = busy_spans(float(ev.t[0]), float(ev.t[-1]), tiles)
    assert len(spans) == 2 and tiles.sum() == len(ev)
    assert all(((ev.t >= qa) & (ev.t <= qb)).sum() >= len(burst) - 5 for _, _, qa, qb in spans)


def test_query_times_far_past_the_events_still_measure_them(burst):
    """reconstruct's span widened to query times at 40 s: the slices of [0, 40] missed the 1 s of events."""
    memory, streamed = _both(burst, span=(0.0, 40.0))
    assert memory == streamed == _both(burst)[0]


def test_a_sensor_of_one_pixel_keeps_its_events_with_auto():
    """No pixel has a neighbour: "auto" chose 50 ms, which drops every event, and blamed noise."""
    ev = _random(400, size=(1, 1))
    times = np.linspace(0.0, 0.5, 5)
    result = reconstruct(ev, times, EvINRConfig(**FASTCFG))
    assert result.config.background == "keep" and np.all(np.isfinite(result.frames))
    parts = list(stream_reconstruct(ev, times, EvINRConfig(**FASTCFG)))
    assert sum(len(p.times) for p in parts) == 5
    with pytest.raises(EventDataError, match=r"background filter left 0 of 400 events.*a sensor of one pixel has no "
                                             r"neighbouring pixels.*background='keep'"):
        reconstruct(ev, times, EvINRConfig(background="filter", **FASTCFG))


def test_a_sensor_of_one_pixel_is_reconstructed_by_the_command(capsys, tmp_path):
    t = np.sort(np.random.default_rng(0).uniform(0, 0.5, 300))
    path = tmp_path / "one_pixel.txt"
    path.write_text("1 1\n" + "".join(f"{a:.9f} 0 0 {i % 2}\n" for i, a in enumerate(t)))
    code, out, err = run(capsys, "reconstruct", path, "--out", tmp_path / "o", "--fps", "10", "--iters", "3",
                         "--quiet", "--no-video")
    assert code == 0, err
    assert (tmp_path / "o" / "run.json").is_file()


@pytest.mark.parametrize("entry", ["reconstruct", "stream", "prepare_source"])
def test_every_event_at_one_instant_is_refused_as_an_empty_span_with_auto(entry):
    """With "auto" the chooser read [t, t) and the error named a "time window" the caller never gave; "keep" and
    "filter" name the empty span."""
    ev = _moved(_random(400), dt=0.0)
    ev = Events.from_arrays(np.full(len(ev), 0.1), ev.x, ev.y, ev.p, ev.sensor_size)
    for background in ("auto", "keep", "filter"):
        cfg = EvINRConfig(background=background, **FASTCFG)
        with pytest.raises(EventDataError, match=r"^time span \[0\.1, 0\.1\] is empty; t_end must exceed t_start"):
            if entry == "reconstruct":
                reconstruct(ev, [0.1], cfg)
            elif entry == "stream":
                next(stream_reconstruct(ev, [0.1], cfg))
            else:
                prepare_source(MemorySource(ev), 0.1, 0.1, cfg)
                from evinr_lite.method.ensemble import split_windows   # "keep": the plan of windows refuses it
                split_windows(0.1, 0.1, cfg.tau, cfg.overlap)


@pytest.mark.parametrize("dt", [0.2, 1e-6])
def test_the_filter_error_names_the_window_it_used(dt):
    """Events 0.3 s apart at pixels 3 apart: no neighbour within the window; the message said "50 ms"."""
    n = 12
    ev = Events.from_arrays(np.arange(n) * 0.3, (np.arange(n) * 3) % W, (np.arange(n) * 5) % H, np.ones(n), (H, W))
    with pytest.raises(EventDataError, match=rf"background filter left 0 of 12 events .*background_dt = {dt:g} s.*"
                                             rf"too sparse for a {dt:g} s neighbourhood.*background='keep'") as info:
        reconstruct(ev, [1.0], EvINRConfig(background="filter", background_dt=dt, **FASTCFG))
    assert "50 ms" not in str(info.value)


def test_a_background_dt_with_auto_is_refused_not_replaced():
    """EvINRConfig(background_dt=0.2) kept "auto" (the default), which replaced the 0.2 s by its own window."""
    pattern = r"background_dt=0\.2 is the filter's window with background='filter', but background='auto'.*would not " \
              r"use it; pass background='filter' with background_dt=0\.2"
    with pytest.raises(EventDataError, match=pattern):
        EvINRConfig(background_dt=0.2)
    cfg = EvINRConfig()
    with pytest.raises(EventDataError, match=pattern):
        cfg.background_dt = 0.2
    assert cfg.background_dt == DEFAULT_DT
    assert EvINRConfig(background="filter", background_dt=0.2).background_dt == 0.2          # guard: filter takes it
    assert EvINRConfig(background_dt=DEFAULT_DT).background == "auto"


# ---- 2. fixes: the module functions' arguments ----------------------------------------------------------------

@pytest.mark.parametrize("span, pattern", [((0.0, np.inf), r"t_end= must be a finite number, got inf"),
                                           ((np.nan, 1.0), r"t_start= must be a finite number, got nan"),
                                           ((1.0, 0.0), r"the span \[1\.0, 0\.0\] s is reversed"),
                                           ((None, 1.0), r"t_start= must be a finite number, got None")],
                         ids=["inf", "nan", "reversed", "None"])
def test_sample_spans_refuses_a_span_that_is_not_finite_seconds(span, pattern):
    with pytest.raises(EventDataError, match=r"^sample_spans: " + pattern):
        sample_spans(*span)
    assert sample_spans(2.0, 2.0) == [(2.0, 2.0, 2.0, 2.0)]                # guard: a span of no length is one span


@pytest.mark.parametrize("samples, pattern", [
    (lambda e: e, r"samples must be a list \[\(events, \(query_from, query_to\)\), \.\.\.\].*got Events"),
    (lambda e: [e], r"samples\[0\] must be \(events, \(query_from, query_to\)\)"),
    (lambda e: [(e, 0.5)], r"samples\[0\] must be \(events, \(query_from, query_to\)\)"),
    (lambda e: [(e, (np.nan, 0.5))], r"samples\[0\]: t_start= must be a finite number, got nan"),
    (lambda e: [(e, (0.5, 0.0))], r"samples\[0\]: the span \[0\.5, 0\.0\] s is reversed"),
    (lambda e: [(e, (0.0, 0.5)), (_random(50, size=(6, 6)), (0.0, 0.5))], r"samples\[1\] is of sensor \(6, 6\)"),
], ids=["events alone", "no interval", "one number", "nan interval", "reversed interval", "two sensors"])
def test_fit_background_names_the_form_of_its_samples(samples, pattern):
    with pytest.raises(EventDataError, match=r"^fit_background: " + pattern):
        fit_background(samples(_random(400)))


@pytest.mark.parametrize("seed", [None, -1, 0.5, "1", True])
def test_fit_background_refuses_a_seed_that_is_not_a_whole_number(seed):
    """seed=None drew unseeded probes: another window from one call to the next on a borderline recording."""
    with pytest.raises(EventDataError, match=r"fit_background: seed= must be a whole number >= 0"):
        fit_background([(_random(400), (0.0, 0.5))], seed=seed)


@pytest.mark.parametrize("query, pattern", [
    (([0.1, 0.2], [1, 2, 3], [1, 2], [1, 1]), r"t, x, y and p must have one length .*got 2, 3, 2 and 2"),
    (([0.1], [-1], [3], [1]), r"x must hold whole pixel coordinates in \[0, 15\] \(the sensor is 12 x 16\)"),
    (([0.1], [3], [12], [1]), r"y must hold whole pixel coordinates in \[0, 11\]"),
    (([0.1], [1.5], [3], [1]), r"x must hold whole pixel coordinates"),
    (([np.nan], [1], [3], [1]), r"t\[0\] is nan"),
    (([0.1], [1], [3], [2]), r"p must hold polarities -1, 0 or \+1"),
    (([0.1], [[1]], [3], [1]), r"x must be a whole number or a 1-D array"),
    ((["0.1"], [1], [3], [1]), r"t= must be seconds"),
], ids=["lengths", "x negative", "y past the sensor", "x between pixels", "nan time", "polarity 2", "2-D x", "text"])
def test_neighbour_gaps_checks_its_queries(query, pattern):
    with pytest.raises(EventDataError, match=r"^neighbour_gaps: .*" + pattern):
        neighbour_gaps(_random(400), *query)


def test_neighbour_gaps_takes_single_numbers_for_every_query():
    """A single number for a query was numpy's IndexError (a 0-d array indexed)."""
    ev = _random(400)
    one = neighbour_gaps(ev, 0.25, 5, 5, 1)
    many = neighbour_gaps(ev, [0.1, 0.25], 5, 5, [1, 1])
    assert one.shape == (1,) and many[1] == one[0]
    with pytest.raises(EventDataError, match=r"events must be Events, got tuple"):
        neighbour_gaps((ev.t, ev.x, ev.y, ev.p), 0.25, 5, 5, 1)


@pytest.mark.parametrize("dt", [0, -0.05, np.nan, np.inf, None, "0.1"])
def test_reach_refuses_a_window_that_is_not_positive_seconds(dt):
    """reach(0) was 0 and reach(nan) nan: a streamed window read with no reach, or at NaN times."""
    with pytest.raises(EventDataError, match=r"^reach: dt= must be a finite number > 0"):
        reach(dt)
    assert reach(0.05) == 0.1


@pytest.mark.parametrize("call, pattern", [
    (lambda e, c: prepare_events(e, c, (np.nan, 0.5)), r"^prepare_events: t_start= must be a finite number, got nan"),
    (lambda e, c: prepare_events(e, c, (0.5, 0.0)), r"^prepare_events: the span \[0\.5, 0\.0\] s is reversed"),
    (lambda e, c: prepare_events(e, c, 0.5), r"^prepare_events: span must be \(t_start, t_end\) in seconds"),
    (lambda e, c: prepare_source(MemorySource(e), 0.5, 0.0, c), r"^prepare_source: the span \[0\.5, 0\.0\] s"),
    (lambda e, c: choose_background(c, lambda a, b: e.slice_time(a, b, allow_empty=True), 0.0, np.inf),
     r"^choose_background: t_end= must be a finite number, got inf"),
], ids=["nan span", "reversed span", "one number", "streamed reversed", "chooser inf"])
def test_the_preparation_names_a_span_that_is_not_seconds(call, pattern):
    with pytest.raises(EventDataError, match=pattern):
        call(_random(400), EvINRConfig(progress=False))


# ---- 3. guards: odd recordings that already behave ------------------------------------------------------------

@pytest.mark.parametrize("n", [50, MIN_EVENTS - 1])
def test_guard_fewer_than_min_events_keep_the_fixed_window(n):
    ev = _random(n, span=0.5)
    assert fit_background([(ev, (0.0, 0.5))]).dt == DEFAULT_DT
    result = reconstruct(ev, [0.25], EvINRConfig(**FASTCFG))
    assert _chosen(result.config) == ("filter", DEFAULT_DT) and np.all(np.isfinite(result.frames))


def test_guard_a_few_isolated_events_are_refused_naming_keep_and_kept_with_it():
    ev = _random(3, span=0.5)
    with pytest.raises(EventDataError, match=r"background filter left 0 of 3 events.*background='keep'"):
        reconstruct(ev, [0.25], EvINRConfig(**FASTCFG))
    assert np.all(np.isfinite(reconstruct(ev, [0.25], EvINRConfig(background="keep", **FASTCFG)).frames))


@pytest.mark.parametrize("pixels", [1, 3], ids=["one pixel", "three apart"])
def test_guard_every_event_at_isolated_pixels_is_refused_naming_keep(pixels):
    t, _, _, p = _events()
    k = np.arange(len(t)) % pixels
    ev = Events.from_arrays(t, np.array([3, 8, 13])[k], np.array([4, 9, 1])[k], p, (H, W))
    with pytest.raises(EventDataError, match=r"background filter left 0 of 400 events.*isolated events.*"
                                             r"background='keep'"):
        reconstruct(ev, [0.1], EvINRConfig(**FASTCFG))
    with pytest.raises(EventDataError, match=r"background filter left 0 of 400 events"):
        next(stream_reconstruct(ev, [0.1], EvINRConfig(tau=0.05, overlap=0.01, **FASTCFG)))
    assert np.all(np.isfinite(reconstruct(ev, [0.1], EvINRConfig(background="keep", **FASTCFG)).frames))


def _hot_and_sparse():
    """Three pixels firing 1000 times each and 60 scattered events: the hot pixels are dropped first."""
    rng = np.random.default_rng(0)
    t = rng.uniform(0, 1, 3060)
    x = np.concatenate([rng.choice([3, 10, 14], 3000), rng.integers(0, W, 60)])
    y = np.concatenate([rng.choice([2, 8], 3000), rng.integers(0, H, 60)])
    o = np.argsort(t)
    return Events.from_arrays(t[o], x[o], y[o], rng.choice([-1, 1], 3060), (H, W))


ODD = {
    "1 x 40 sensor": lambda: _random(800, size=(1, 40)),
    "40 x 1 sensor": lambda: _random(800, size=(40, 1)),
    "10 x 400 sensor": lambda: _random(4000, size=(10, 400)),
    "300 x 6 sensor": lambda: _random(4000, size=(300, 6)),
    "ON only": lambda: _random(2000, p=1),
    "OFF only": lambda: _random(2000, p=-1),
    "hot pixels and sparse events": _hot_and_sparse,
    "ms timestamps (ties)": lambda: Events.from_arrays(np.round(_random(2000).t, 3), _random(2000).x,
                                                       _random(2000).y, _random(2000).p, (H, W)),
}


@pytest.mark.parametrize("name", list(ODD))
def test_guard_odd_recordings_are_chosen_for_alike_and_reconstructed(name):
    ev = ODD[name]()
    memory, streamed = _both(ev)
    assert memory == streamed
    again = _both(ev)                                         # determinism: the same choice twice
    assert again == (memory, streamed)
    result = reconstruct(ev, [float(ev.t[len(ev) // 2])], EvINRConfig(**FASTCFG))
    assert _chosen(result.config) == memory and np.all(np.isfinite(result.frames))


@pytest.mark.parametrize("over", [-0.3, -0.01, 0.01, 0.5], ids=["7.7 s", "just under 8 s", "just over 8 s", "8.5 s"])
def test_guard_spans_either_side_of_the_whole_span_limit(burst, over):
    """Measured whole up to 8 s, on four slices beyond: the same window either side, in memory and streamed."""
    gap = 8.0 + over - float(burst.t[-1] - burst.t[0])
    ev = _joined(burst, _moved(burst, dt=gap))
    span = float(ev.t[-1] - ev.t[0])
    assert span == pytest.approx(8.0 + over) and (len(sample_spans(ev.t[0], ev.t[-1])) == 1) == (over < 0)
    memory, streamed = _both(ev)
    assert memory == streamed == _both(_joined(burst, _moved(burst, dt=6.5)))[0]


def test_guard_duplicated_events_measure_as_the_originals():
    ev = _random(1500)
    twice = Events.from_arrays(np.repeat(ev.t, 2), np.repeat(ev.x, 2), np.repeat(ev.y, 2), np.repeat(ev.p, 2), (H, W))
    a, b = fit_background([(ev, (0.0, 0.5))]), fit_background([(twice, (0.0, 0.5))])
    assert (a.dt, a.noise_share, a.kept) == (b.dt, b.noise_share, b.kept) and b.n_events == 2 * a.n_events


@pytest.mark.parametrize("value, pattern", [
    (0, r"background_dt must be a positive number of seconds"), (-0.1, r"must be a positive number"),
    (np.nan, r"background_dt must be a finite number, got nan"), (np.inf, r"finite number, got inf"),
    ("0.1", r"pass the number itself \(background_dt=0\.1\), not text"), ("abc", r"finite number, got 'abc'"),
    (True, r"finite number, got True"), (None, r"finite number, got None"), ([0.1], r"finite number, got \[0\.1\]"),
    (decimal.Decimal("0.1"), r"finite number, got Decimal"),
], ids=["0", "negative", "nan", "inf", "text", "word", "bool", "None", "list", "Decimal"])
def test_guard_background_dt_values_that_are_no_window(value, pattern):
    with pytest.raises(EventDataError, match=pattern):
        EvINRConfig(background="filter", background_dt=value)


def test_guard_background_dt_of_numpy_types_is_read():
    assert EvINRConfig(background="filter", background_dt=np.float32(0.1)).background_dt == pytest.approx(0.1)
    assert EvINRConfig(background="filter", background_dt=np.int64(1)).background_dt == 1.0


@pytest.mark.parametrize("value", ["Auto", "AUTO", "filtre", "none", "", None, True, "keep ", "off"])
def test_guard_background_values_misspelt_or_of_another_case(value):
    with pytest.raises(EventDataError, match=r"background must be one of \('keep', 'filter', 'auto'\), got "):
        EvINRConfig(background=value)


@pytest.mark.parametrize("dt", [0, -1, np.nan, "0.1", None])
def test_guard_filter_background_refuses_a_window_that_is_no_number(dt):
    with pytest.raises(EventDataError, match=r"dt must be a positive number of seconds"):
        filter_background(_random(400), dt)


def test_guard_a_window_longer_than_the_span_keeps_every_event_with_a_neighbour():
    ev = _random(400)
    span = float(ev.t[-1] - ev.t[0])
    whole = filter_background(ev, span)
    assert len(filter_background(ev, 1e9)) == len(whole) > 0
    cfg = EvINRConfig(background="filter", background_dt=1e9, progress=False)
    memory = prepare_events(ev, cfg, (float(ev.t[0]), float(ev.t[-1])))[0]
    _, source = prepare_source(MemorySource(ev), float(ev.t[0]), float(ev.t[-1]), cfg, chunk_s=0.1)
    streamed = sum(len(source.events(a, b)) for a, b in zip(np.arange(0, 0.5, 0.1), np.arange(0.1, 0.6, 0.1)))
    assert len(memory) == streamed == len(whole)


def test_guard_the_returned_config_fed_back_gives_the_same_frames(pan):
    times = [0.5, 1.0, 1.5]
    first = reconstruct(pan, times, EvINRConfig(C=0.2, **FASTCFG))
    assert first.config.background in ("filter", "keep")
    again = reconstruct(pan, times, EvINRConfig(C=0.2, **FASTCFG))          # determinism
    fed = reconstruct(pan, times, first.config)                          # what "auto" chose, fed back in
    np.testing.assert_array_equal(first.frames, again.frames)
    np.testing.assert_array_equal(first.frames, fed.frames)
    assert _chosen(fed.config) == _chosen(first.config)


def test_the_tile_counts_of_chunks_add_up_to_the_whole(burst):
    """The streamed first pass counts the tiles chunk by chunk: the same counts as all the events at once."""
    from evinr_lite.method.background import tile_counts

    ev = _joined(burst, _moved(burst, dt=20.0))
    t0, t1 = float(ev.t[0]), float(ev.t[-1])
    whole = tile_counts(ev.t, t0, t1)
    edges = np.append(np.arange(t0, t1, 0.7), t1)
    parts = sum(tile_counts(ev.t[(ev.t >= a) & ((ev.t < b) | (b == t1))], t0, t1) for a, b in zip(edges[:-1], edges[1:]))
    np.testing.assert_array_equal(whole, parts)
    assert len(whole) == int(np.ceil((t1 - t0) / SLICE_S)) and whole.sum() == len(ev)
