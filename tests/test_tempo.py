"""The temporal scale (evinr_lite.method.tempo): polarity reversals per pixel and second, the scale they give,
and the bins and first-layer frequency it sets, the same for events in memory and read window by window."""
import numpy as np
import pytest

from evinr_lite.core.events import EventDataError, Events
from evinr_lite.io.source import MemorySource
from evinr_lite.method import EvINRConfig
from evinr_lite.method.balance import PolarityCounts, interval_sums
from evinr_lite.method.prepare import prepare_events, prepare_source
from evinr_lite.method.tempo import FLIPS_REF, MAX_SCALE, MIN_EVENTS, flip_rate, scale_from_rate, temporal_scale
from evinr_lite.sim.scenes import OscillatingScene
from evinr_lite.sim.simulate import simulate_scene

SIZE = (30, 40)


def _pixel_train(polarities, x=0, y=0, dt=0.1, size=(2, 3)):
    """One pixel's events, ``dt`` s apart, with the given polarities (-1 / +1)."""
    p = np.asarray(polarities, np.int8)
    t = dt * np.arange(1, len(p) + 1)
    return Events.from_arrays(t, np.full(len(p), x), np.full(len(p), y), p, size)


def test_a_reversal_is_an_event_of_the_other_polarity_than_the_pixels_one_before():
    ev = _pixel_train([1, 1, -1, -1, 1, -1, -1, 1])             # reversals at events 3, 5, 6, 8: four
    flips = interval_sums(ev, with_flips=True)[-1]
    assert flips[0, 0] == 4 and flips.sum() == 4
    assert len(interval_sums(ev)) == 6                           # without the flag: what callers unpack, as before


def test_chunks_count_the_reversals_of_the_whole_span():
    scene = OscillatingScene("camera", SIZE, 2.0, path=((3.0, 1.0, 0.25, 0.0),))
    ev = simulate_scene(scene, C=0.2, seed=0)
    whole = PolarityCounts(SIZE).update(ev).flips
    chunked = PolarityCounts(SIZE)
    for a, b in ((0.0, 0.3), (0.3, 1.1), (1.1, 2.1)):
        chunked.update(ev.slice_time(a, b, allow_empty=True))
    np.testing.assert_array_equal(chunked.flips, whole)          # a reversal across a chunk's edge counts once
    assert whole.sum() > 0


def test_the_rate_is_the_median_over_pixels_that_fired_enough():
    flips = np.array([[10.0, 20.0, 30.0], [1000.0, 0.0, 0.0]])
    n = np.array([[50.0, 50.0, 50.0], [MIN_EVENTS - 1, 0.0, 0.0]])   # the busy pixel fired too few times to count
    assert flip_rate(flips, n, 2.0) == 10.0                           # median 20 reversals over 2 s
    assert np.isnan(flip_rate(flips, np.zeros_like(n), 2.0))
    assert scale_from_rate(float("nan")) == 1.0
    assert scale_from_rate(FLIPS_REF / 2) == 1.0 and scale_from_rate(FLIPS_REF) == 1.0
    assert scale_from_rate(2 * FLIPS_REF) == 2.0 and scale_from_rate(100 * FLIPS_REF) == MAX_SCALE
    assert temporal_scale(flips, n, 2.0) == 10.0 / FLIPS_REF


@pytest.mark.parametrize("call, pattern", [
    (lambda: flip_rate(np.zeros((2, 3)), np.zeros((3, 2)), 1.0), "one shape"),
    (lambda: flip_rate(np.zeros(6), np.zeros(6), 1.0), r"\[H, W\]"),
    (lambda: flip_rate(np.zeros((2, 3)), np.zeros((2, 3)), 0.0), "positive number of seconds"),
    (lambda: flip_rate(np.zeros((2, 3)), np.zeros((2, 3)), float("nan")), "positive number of seconds"),
])
def test_bad_counts_are_refused(call, pattern):
    with pytest.raises(EventDataError, match=pattern):
        call()


@pytest.mark.parametrize("value, pattern", [("fast", "'auto'"), ("2", "'auto'"), (0, "from 1/64"), (-1.0, "from 1/64"),
                                            (float("nan"), "finite"), (None, "finite"), (True, "finite")])
def test_the_config_refuses_a_scale_it_cannot_use(value, pattern):
    with pytest.raises(EventDataError, match=pattern):
        EvINRConfig(temporal_scale=value)


def test_the_scale_shortens_the_bins_and_speeds_the_first_layer():
    windows = np.array([[0.0, 2.0]])
    base = EvINRConfig(temporal_scale=1)
    fast = EvINRConfig(temporal_scale=2.5)
    assert base.temporal_scale == 1.0 and isinstance(base.temporal_scale, float)
    assert base.final_bin_duration() == base.bin_duration == 1 / 32
    assert fast.final_bin_duration() == pytest.approx(1 / 80)
    assert fast.first_layer_omega(windows) == pytest.approx(2.5 * base.first_layer_omega(windows))
    assert EvINRConfig().scale() == 1.0                               # "auto", not yet read from events
    # the paper's recipe and v0_1 keep their bins and first layer exactly; a scale there scales first_omega_0
    assert EvINRConfig.paper().temporal_scale == EvINRConfig.v0_1().temporal_scale == 1.0
    assert EvINRConfig.v0_1().first_layer_omega(windows) == 10.0
    assert EvINRConfig.v0_1(temporal_scale=2.0).first_layer_omega(windows) == 20.0


@pytest.fixture(scope="module")
def shaken():
    """A fast shake (periods 0.2 and 0.13 s): every pixel turns several times a second."""
    scene = OscillatingScene("camera", SIZE, 2.0, path=((4.0, 2.0, 0.2, 0.0), (2.0, 3.0, 0.13, 1.0)))
    return simulate_scene(scene, C=0.2, seed=0)


@pytest.fixture(scope="module")
def slow():
    scene = OscillatingScene("camera", SIZE, 2.0, path=((4.0, 2.0, 4.0, 0.0),))
    return simulate_scene(scene, C=0.2, seed=0)


def test_prepare_reads_the_scale_from_the_events(shaken, slow):
    _, fast_cfg = prepare_events(shaken, EvINRConfig(C=0.2, progress=False))
    _, slow_cfg = prepare_events(slow, EvINRConfig(C=0.2, progress=False))
    assert 1.0 < fast_cfg.temporal_scale <= MAX_SCALE
    assert slow_cfg.temporal_scale == 1.0                          # a slow pan trains exactly as before
    assert prepare_events(shaken, EvINRConfig(C=0.2, temporal_scale=1.5))[1].temporal_scale == 1.5   # given: kept
    assert prepare_events(shaken, EvINRConfig.paper(C=0.2))[1].temporal_scale == 1.0


def test_streamed_and_in_memory_read_the_same_scale(shaken):
    cfg = EvINRConfig(C=0.2, tau=1.2, overlap=0.2, progress=False)
    _, whole = prepare_events(shaken, cfg, (0.0, 2.0))
    streamed, _ = prepare_source(MemorySource(shaken), 0.0, 2.0, cfg, chunk_s=0.5)
    assert streamed.temporal_scale == whole.temporal_scale > 1.0
    # background kept and nothing else to count: the stream still counts, for the scale alone
    plain = EvINRConfig(C=0.2, tau=1.2, overlap=0.2, balance="none", hot_pixels="keep", lam=0.01, background="keep", progress=False)
    assert prepare_source(MemorySource(shaken), 0.0, 2.0, plain, chunk_s=0.5)[0].temporal_scale == whole.temporal_scale


def test_reconstruct_trains_the_scaled_bins(shaken):
    from evinr_lite.method.solver import reconstruct

    rec = reconstruct(shaken, np.linspace(0.1, 1.9, 4), EvINRConfig(C=0.2, progress=False))
    s = rec.history["config"]["temporal_scale"]
    assert s > 1.0
    assert rec.history["final_bins"] == max(64, round(2.0 / (1 / 32 / s)))


def test_a_stream_checks_its_memory_again_when_the_events_shorten_its_bins(shaken, monkeypatch):
    """The command checks memory before the stream has read the scale (as 1); the stream checks again once the
    events have set it above 1, before any window is trained."""
    from evinr_lite.method import memory
    from evinr_lite.method.streaming import stream_reconstruct

    q = np.linspace(0.1, 1.9, 4)
    monkeypatch.setattr(memory, "available_bytes", lambda device="cpu": 1.0)   # nothing fits
    with pytest.raises(EventDataError, match="needs about"):
        next(iter(stream_reconstruct(MemorySource(shaken), q, EvINRConfig(C=0.2, progress=False))))
    # a scale given as 1 (and a slow scene's "auto") adds no check: the caller's stands
    parts = list(stream_reconstruct(MemorySource(shaken), q, EvINRConfig(C=0.2, temporal_scale=1, progress=False)))
    assert sum(len(p.times) for p in parts) == len(q)


def test_the_command_line_takes_the_scale():
    from evinr_lite.apps.cli import build_parser, _message
    from evinr_lite.apps.options import BATCH_FIELDS, RunOptions

    assert RunOptions().config(0.2).temporal_scale == "auto"
    assert RunOptions(temporal_scale=2).config(0.2).temporal_scale == 2.0
    assert RunOptions(temporal_scale=" AUTO ").config(0.2).temporal_scale == "auto"
    assert RunOptions(recipe="v0_1").config(0.2).temporal_scale == 1.0      # the recipe's own
    assert "temporal_scale" in BATCH_FIELDS
    for bad in ("fast", 0, -1.0, float("nan"), True, [2]):
        with pytest.raises(EventDataError, match="temporal_scale= must be 'auto'"):
            RunOptions(temporal_scale=bad)
    parser = build_parser()
    assert parser.parse_args(["reconstruct", "x.h5", "--out", "o", "--temporal-scale", "2.5"]).temporal_scale == 2.5
    assert parser.parse_args(["batch", "x.h5", "--out", "o", "--temporal-scale", "auto"]).temporal_scale == "auto"
    for bad in ("0", "-1", "nan", "fast"):
        with pytest.raises(SystemExit):
            parser.parse_args(["reconstruct", "x.h5", "--out", "o", "--temporal-scale", bad])
    # the memory check's advice, as the command line words it
    message = _message(EventDataError("... or use a longer bin_duration; or temporal_scale=1 (the events' fast "
                                      "changes set 4)"))
    assert "--temporal-scale 1" in message and "bin_duration" not in message


def test_too_little_memory_for_the_scaled_bins_names_the_scale(shaken, monkeypatch):
    from evinr_lite.method import memory
    from evinr_lite.method.solver import reconstruct

    est = memory.estimate_memory(SIZE, 0.0, 2.0, len(shaken), 4, EvINRConfig(C=0.2, temporal_scale=4.0))
    monkeypatch.setattr(memory, "available_bytes", lambda device="cpu": est["total"] / 0.8 / 1.5)
    monkeypatch.setattr(memory, "estimate_memory", lambda *a, **k: {**est, "parts": {"bins": 1.0}})
    with pytest.raises(EventDataError, match=r"temporal_scale=1 \(the events' fast changes set"):
        reconstruct(shaken, np.linspace(0.1, 1.9, 4), EvINRConfig(C=0.2, progress=False))


def test_under_a_fast_shake_the_scale_buys_quality(shaken):
    """What the rule is for: a shake of 0.2 and 0.13 s periods, frames scored against the truth with and without it."""
    from evinr_lite.evaluation import score_frames
    from evinr_lite.method.solver import reconstruct

    scene = OscillatingScene("camera", SIZE, 2.0, path=((4.0, 2.0, 0.2, 0.0), (2.0, 3.0, 0.13, 1.0)))
    q = np.linspace(0.1, 1.9, 10)
    truth = np.stack([np.exp(scene.log_intensity(t)) for t in q]).clip(0, 1)
    ssim = {}
    for s in ("auto", 1.0):
        frames = reconstruct(shaken, q, EvINRConfig(C=0.2, temporal_scale=s, progress=False)).frames
        ssim[s] = {eq: score_frames(frames, truth, eq)["ssim"] for eq in ("none", "clahe")}
    for eq in ("none", "clahe"):
        assert ssim["auto"][eq] > ssim[1.0][eq] + 0.1, ssim        # measured 0.714 against 0.445, 0.592 against 0.306


def test_the_jobs_record_the_scale_and_say_when_it_shortened_the_bins():
    from evinr_lite.apps.stream_job import report_temporal_scale

    for given, used, logged in (("auto", 2.0, True), ("auto", 1.0, False), (1.0, 1.0, None), ("auto", None, None)):
        settings, lines = {}, []
        report_temporal_scale(given, used, 1 / 32, settings, lines.append)
        if logged is None:       # a scale given by hand, or none read: nothing to report
            assert settings == {} and lines == []
            continue
        assert settings == {"temporal_scale_used": used}
        assert bool(lines) == logged
    settings, lines = {}, []
    report_temporal_scale("auto", 2.0, 1 / 32, settings, lines.append)
    assert "2x shorter (at most 15.6 ms, not 31.2)" in lines[0] and "--temporal-scale 1" in lines[0]


def test_the_constant_benchmark_sets_the_rule_for_a_block_and_puts_it_back():
    from benchmarks import temporal_scale as bench
    from evinr_lite.method import tempo

    with pytest.raises(RuntimeError):
        with bench.flips_ref(1.0, max_scale=np.inf):
            assert scale_from_rate(10.0) == 10.0           # the rule reads the constants at each call
            raise RuntimeError("a failure inside the block")
    assert (tempo.FLIPS_REF, tempo.MAX_SCALE) == (FLIPS_REF, MAX_SCALE)
    assert scale_from_rate(10.0) == min(10.0 / FLIPS_REF, MAX_SCALE)
    row = {"ssim_clahe": 0.5, "ssim_none": 0.6, "mse_none": 0.01}
    out = {"a": {"set": "zoo", "rate": 3.0, "kit": {"2.0": {**row, "ssim_clahe": 0.52}, "2.5": row, "3.0": row}}}
    lines = bench.summary(out, [2.0, 2.5, 3.0], 2.5)
    assert len(lines) == 2 and "+0.0200" in lines[0] and "1 up, 0 down" in lines[0] and "+0.0000" in lines[1]
    assert "| zoo | a | 3.00 | 0.520 / 0.600 / 0.0100 | 0.500" in bench.markdown(out, [2.0, 2.5, 3.0], lines)
