"""The ON/OFF balance from the events alone, scene by scene: what it estimates and how far it is trusted.

    python benchmarks/balance.py              # the zoo's scenes, long ones included (about 2 min on 2 cores)
    python benchmarks/balance.py --heldout    # the held-out scenes instead
    python benchmarks/balance.py --speed      # what the intervals and slice counts cost beside the counts, 1280 x 720 (about 10 s)
    python benchmarks/balance.py --off-heavy  # every scene of both sets with C- > C+, long ones included (about 8 min)
    python benchmarks/balance.py --light      # the 20 s pan under a change of light, three C pairs (about 2 min)
    python benchmarks/balance.py --fresh      # two fresh random draws of every short scene's sensor (about 5 min)

For each scene, on the events the kit trains on (hot pixels dropped, background filtered, as
:mod:`evinr_lite.method.prepare` does): the simulated imbalance b = (C+ - C-) / (C+ + C-), the two
estimates of :mod:`evinr_lite.method.balance` (the pooled counts, ``raw``, the counts fitted with an
intercept, ``slope``, and the intervals between events of one polarity, ``interval``), the default's result (``applied``: the counts alone where
their error scale is small, bounded by the range of the other three, else the minmod, or where the edges and the
intervals disagree and the counts show no change of light the smallest of the three counts' estimates; ``chosen``
says which), and the
counts rule's (``counts_rule``: ``raw`` shrunk by ``shrink``), with the mean event count per usable
pixel, the counts' error scale ``s = NET_CHANGE / (C mean n)`` (at most COUNTS_ALONE: the counts are
taken alone) and the truth's change of mean log intensity from the first to the last scored frame (what the
pooled counts cannot tell from an imbalance). The last lines give the root mean square of b and of
that change over the scenes (the counts rule's prior spreads PRIOR and NET_CHANGE are the zoo's) and
of each rule's error. Writes benchmarks/balance_results[_heldout].{json,md}.

Every simulated imbalance of the two sets is positive (C+ > C-). ``--off-heavy`` checks the other sign:
each scene of the zoo and the held-out set, the long ones (20 s and 60 s) included, again, with C+ and C- swapped
where they differ and C+ = 0.85 C, C- = 1.15 C (b = -0.15) where they are equal, another seed, the same
nominal C; it also scores the kit (CLAHE-SSIM / SSIM / MSE, and the level error per quarter on the long
ones) with the default balance, the counts rule and the true pair.
Writes benchmarks/balance_results_off_heavy.{json,md}.

``--light`` checks what a long recording's change of light does to the estimate: the zoo's 20 s pan
with the light falling by e^-0.7 (2x) and e^-2 (7.4x) over the recording, uniform over the sensor, each
with C+ = C-, C+ > C- and C- > C+ (b = 0, +-0.111), with the kit's scores and level error per quarter
under the default, b = 0 (``balance="none"``) and the true pair. Writes
benchmarks/balance_results_light.{json,md}.

``--fresh`` checks scenes built the same ways that no rule was chosen on: each short scene of the zoo
and the held-out set drawn again, twice (generators seeded 7 and 8, FRESH_SEEDS), with a new seed and a
new sensor: nominal C uniform in [0.15, 0.35], C+ / C- log-uniform in [0.7, 1.4] (either sign of b),
background activity the scene's own, 0.3 or 1 Hz, hot pixels its own or 20 (ON-only half the time),
a threshold mismatch of at least 3 %. It scores the kit under the default balance, under the rule
before the edges' estimate (``pooled_minmod``: the minmod of the pooled counts and the intervals where
the counts are not taken alone, applied as a C pair) and given the true pair. Writes
benchmarks/balance_results_fresh.{json,md}.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.common import write_json  # noqa: E402
from evinr_lite.method import EvINRConfig  # noqa: E402
from evinr_lite.method.balance import NET_CHANGE, PRIOR, estimate_balance  # noqa: E402
from evinr_lite.method.prepare import prepare_events  # noqa: E402
from evinr_lite.sim.zoo import HELDOUT, default_scenes, effective_C, imbalance, simulate  # noqa: E402


def scene_row(z, simulated=None) -> dict:
    """The balance of one zoo scene against its simulated thresholds (``simulated``: ``simulate(z)``'s
    result when the caller already has it)."""
    _, events, times, gt = simulated or simulate(z)
    C = effective_C(z)
    events, _ = prepare_events(events, EvINRConfig(C=C, balance="none", progress=False))
    fit, old = estimate_balance(events, C), estimate_balance(events, C, rule="counts")
    log_mean = np.log(np.clip(np.asarray(gt, np.float64), 1e-3, None)).mean(axis=(1, 2))
    return {"span_s": float(times[-1] - times[0]), "b_true": imbalance(z), "raw": fit.raw_imbalance,
            "interval": fit.interval_imbalance, "slope": fit.slope_imbalance, "gradient": fit.gradient_imbalance,
            "applied": fit.imbalance,
            "chosen": fit.chosen,
            "counts_error": fit.counts_error, "shrink": old.shrink,
            "counts_rule": old.imbalance, "mean_events": fit.mean_events,
            "mean_log_change": float(log_mean[-1] - log_mean[0])}


def markdown(rows: dict, rms: dict) -> str:
    lines = ["| scene | span (s) | events per pixel | counts' error scale | b simulated | counts (raw) | counts (slope) | "
             "edges | intervals | b applied (taken from) | counts rule (shrink) | truth's mean log change |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, r in rows.items():
        lines.append(f"| {name} | {r['span_s']:.1f} | {r['mean_events']:.1f} | {r['counts_error']:.3f} | {r['b_true']:+.3f} | "
                     f"{r['raw']:+.3f} | {r['slope']:+.3f} | {r['gradient']:+.3f} | {r['interval']:+.3f} | "
                     f"{r['applied']:+.3f} ({r['chosen']}) | {r['counts_rule']:+.3f} ({r['shrink']:.2f}) | "
                     f"{r['mean_log_change']:+.3f} |")
    lines += ["", f"Root mean square over these {len(rows)} scenes: simulated b {rms['b']:.3f}, mean log change "
              f"{rms['log_change']:.2f} (the counts rule's prior spreads in evinr_lite.method.balance: PRIOR {PRIOR}, "
              f"NET_CHANGE {NET_CHANGE}); error of the applied b {rms['applied_error']:.3f}, of the counts rule's "
              f"{rms['counts_rule_error']:.3f}. Written by `python benchmarks/balance.py`."]
    return "\n".join(lines) + "\n"


def speed(n_events: int = 20_000_000, sensor_size=(720, 1280), seed: int = 0) -> dict:
    """Seconds of :func:`polarity_counts` and :func:`interval_sums` on the same random events (uniform
    over the sensor and 2 s), and their ratio, measured in one run."""
    import time

    from evinr_lite.core.events import Events
    from evinr_lite.method.balance import interval_stride, interval_sums, polarity_counts, slice_counts, span_slices

    rng = np.random.default_rng(seed)
    H, W = sensor_size
    events = Events(np.sort(rng.uniform(0.0, 2.0, n_events)), rng.integers(0, W, n_events, dtype=np.int32),
                    rng.integers(0, H, n_events, dtype=np.int32), rng.choice(np.array([-1, 1], np.int8), n_events),
                    (H, W))
    seconds = {}
    edges = span_slices(0.0, 2.0)
    for name, f in (("polarity_counts", polarity_counts), ("interval_sums", interval_sums),
                    ("slice_counts", lambda ev: slice_counts(ev, edges))):
        t0 = time.perf_counter()
        f(events)
        seconds[name] = time.perf_counter() - t0
    return {"n_events": n_events, "sensor_size": [H, W], "stride": interval_stride((H, W)), **seconds,
            "ratio": seconds["interval_sums"] / seconds["polarity_counts"],
            "slice_ratio": seconds["slice_counts"] / seconds["polarity_counts"]}


OFF_HEAVY_B = -0.15     # b given to the equal-threshold scenes in --off-heavy


def off_heavy(z):
    """The scene with C- > C+: its pair swapped, or C (1 -+ 0.15) when it has one C; another seed."""
    from dataclasses import replace

    if z.C_pos is not None and z.C_pos != z.C_neg:
        c_pos, c_neg = min(z.C_pos, z.C_neg), max(z.C_pos, z.C_neg)
    else:
        c_pos, c_neg = z.C * (1 + OFF_HEAVY_B), z.C * (1 - OFF_HEAVY_B)
    return replace(z, name=z.name + "_off_heavy", C_pos=c_pos, C_neg=c_neg, seed=z.seed + 1000)


def scored_row(z, balances: dict, simulated=None, row=None) -> dict:
    """:func:`scene_row` with the kit's scores (CLAHE-SSIM, SSIM, MSE) and level error per quarter under
    each balance of ``balances`` (name -> EvINRConfig keyword arguments), the scene simulated once
    (``simulated``: ``simulate(z)``'s result, ``row``: ``scene_row(z, simulated)``, when the caller
    already has them)."""
    from benchmarks.quality_zoo import level_error, score
    from evinr_lite.method import reconstruct

    simulated = simulated or simulate(z)
    _, events, times, gt = simulated
    row = dict(row) if row is not None else scene_row(z, simulated)
    for name, kw in balances.items():
        frames = reconstruct(events, times, EvINRConfig(**{"C": effective_C(z), **kw}, progress=False)).frames
        sc = score(frames, times, gt, times)
        row[f"score_{name}"] = [sc["ssim_clahe"], sc["ssim_none"], sc["mse_none"]]
        row[f"level_{name}"] = level_error(frames, gt, times, z.duration)
    row["long"] = bool(z.long)
    return row


def off_heavy_row(z) -> dict:
    """:func:`scored_row` of the off-heavy scene under the default balance, the counts rule and the true pair."""
    return scored_row(z, {"events": {}, "counts": {"balance": "counts"}, "true_pair": {"C": (z.C_pos, z.C_neg)}})


FRESH_SEEDS = (7, 8)   # generators of the two --fresh draws


def fresh_scenes(seed: int) -> list:
    """Every short scene of the zoo and the held-out set with a new seed and a sensor drawn at random
    (the module docstring says how), by a generator seeded ``seed``."""
    from dataclasses import replace

    rng = np.random.default_rng(seed)
    out = []
    for z in default_scenes() + [h for h in HELDOUT if not h.long]:
        C = float(rng.uniform(0.15, 0.35))
        ratio = float(np.exp(rng.uniform(np.log(0.7), np.log(1.4))))        # C+ / C-
        out.append(replace(z, name=f"{z.name}_fresh{seed}", seed=z.seed + 777 + int(rng.integers(1000)), C=C,
                           C_pos=C * 2 * ratio / (1 + ratio), C_neg=C * 2 / (1 + ratio),
                           noise_hz=float(rng.choice([z.noise_hz, 0.3, 1.0])),
                           hot_pixels=int(rng.choice([z.hot_pixels, 20])), hot_on_only=bool(rng.random() < 0.5),
                           threshold_sigma=max(z.threshold_sigma, 0.03)))
    return out


def pooled_minmod(row: dict) -> float:
    """The b the rule before the edges' estimate applied: the counts' slope where they were taken alone,
    else the minmod of the pooled counts and the intervals (capped like the default)."""
    from evinr_lite.method.balance import MAX_IMBALANCE, minmod

    b = row["slope"] if row["chosen"] == "counts" else minmod(row["raw"], row["interval"])
    return float(np.clip(b, -MAX_IMBALANCE, MAX_IMBALANCE))


def fresh_row(z) -> dict:
    """:func:`scored_row` under the default balance, the rule before (:func:`pooled_minmod`) and the true pair."""
    simulated = simulate(z)
    first = scene_row(z, simulated)
    b = pooled_minmod(first)
    C = effective_C(z)
    row = scored_row(z, {"events": {}, "pooled_minmod": {"C": (C * (1 + b), C * (1 - b))},
                         "true_pair": {"C": (z.C_pos, z.C_neg)}}, simulated, first)
    row["pooled_minmod"] = b
    return row


def score_cell(v) -> str:
    """A markdown cell of one score triple (CLAHE-SSIM, SSIM, MSE)."""
    return f"{v[0]:.3f} / {v[1]:.3f} / {v[2]:.4f}"


def mean_row(label: str, rows, keys, blanks: int) -> str:
    """A markdown row: ``label``, ``blanks`` empty cells, then the mean over ``rows`` (dicts) of each
    score triple ``keys``."""
    return f"| **{label}** |" + " |" * blanks + "".join(
        f" {score_cell(np.mean([r[k] for r in rows], axis=0))} |" for k in keys)


def fresh_markdown(rows: dict, rms: dict) -> str:
    lines = ["| scene | b simulated | counts (pooled) | counts (slope) | edges | intervals | b applied (taken from) | "
             "b, rule before | kit | kit, rule before | kit given the true pair |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, r in rows.items():
        lines.append(f"| {name} | {r['b_true']:+.3f} | {r['raw']:+.3f} | {r['slope']:+.3f} | {r['gradient']:+.3f} | "
                     f"{r['interval']:+.3f} | {r['applied']:+.3f} ({r['chosen']}) | {r['pooled_minmod']:+.3f} | "
                     f"{score_cell(r['score_events'])} | {score_cell(r['score_pooled_minmod'])} | {score_cell(r['score_true_pair'])} |")
    keys = ("score_events", "score_pooled_minmod", "score_true_pair")
    lines.append(mean_row(f"mean of the {len(rows)} scenes", rows.values(), keys, 7))
    neg = [r for r in rows.values() if r["b_true"] < -0.05]
    if neg:
        lines.append(mean_row(f"mean of the {len(neg)} with b < -0.05", neg, keys, 7))
    err = lambda key: float(np.sqrt(np.mean([(r[key] - r["b_true"]) ** 2 for r in rows.values()])))      # noqa: E731
    lines += ["", f"Root mean square error of the applied b {err('applied'):.3f}, of the rule before "
              f"{err('pooled_minmod'):.3f}, of the counts rule's {rms['counts_rule_error']:.3f}. Kit cells: CLAHE-SSIM / "
              "SSIM / MSE at the zoo's scored times. Written by `python benchmarks/balance.py --fresh`."]
    return "\n".join(lines) + "\n"


LIGHT_CHANGES = (-0.7, -2.0)   # log units over the recording, --light
LIGHT_PAIRS = ((0.225, 0.225), (0.25, 0.20), (0.20, 0.25))


def light_scenes() -> list:
    """The 20 s pan (long_pan_20s) under each change of light of LIGHT_CHANGES and each C pair."""
    from dataclasses import replace

    from evinr_lite.sim.scenes import LightingScene

    base = [z for z in default_scenes(long=True) if z.name == "long_pan_20s"][0]

    def lit(change):
        return lambda size, duration: LightingScene(base.build(size, duration), global_change=change, vignette=0.0)
    return [replace(base, name=f"long_pan_20s_light{change:+.1f}_C{c_pos:.3f}_{c_neg:.3f}", build=lit(change),
                    C_pos=c_pos, C_neg=c_neg) for change in LIGHT_CHANGES for c_pos, c_neg in LIGHT_PAIRS]


def light_row(z) -> dict:
    """:func:`scored_row` under the default balance, b = 0 and the true pair."""
    return scored_row(z, {"events": {}, "none": {"balance": "none"}, "true_pair": {"C": (z.C_pos, z.C_neg)}})


def light_markdown(rows: dict, rms: dict) -> str:
    lv = lambda v: " ".join(f"{x:+.3f}" for x in v)                   # noqa: E731
    lines = ["| scene | b simulated | counts (pooled) | counts (slope) | intervals | b applied (taken from) | kit | kit, b = 0 | "
             "kit given the true pair |", "|---|---|---|---|---|---|---|---|---|"]
    for name, r in rows.items():
        lines.append(f"| {name} | {r['b_true']:+.3f} | {r['raw']:+.3f} | {r['slope']:+.3f} | {r['interval']:+.3f} | "
                     f"{r['applied']:+.3f} ({r['chosen']}) | {score_cell(r['score_events'])} | {score_cell(r['score_none'])} | "
                     f"{score_cell(r['score_true_pair'])} |")
    lines += ["", "Level error per quarter (mean prediction minus mean truth):", "",
              "| scene | kit | kit, b = 0 | kit given the true pair |", "|---|---|---|---|"]
    lines += [f"| {name} | {lv(r['level_events'])} | {lv(r['level_none'])} | {lv(r['level_true_pair'])} |"
              for name, r in rows.items()]
    lines += ["", f"Root mean square error of the applied b {rms['applied_error']:.3f}, of the counts rule's "
              f"{rms['counts_rule_error']:.3f}. Kit cells: CLAHE-SSIM / SSIM / MSE. Written by "
              "`python benchmarks/balance.py --light`."]
    return "\n".join(lines) + "\n"


def off_heavy_markdown(rows: dict, rms: dict) -> str:
    lines = ["| scene (C- > C+) | counts' error scale | b simulated | counts | counts (slope) | edges | intervals | "
             "b applied (taken from) | counts rule | kit | kit, counts rule | kit given the true pair |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, r in rows.items():
        lines.append(f"| {name} | {r['counts_error']:.3f} | {r['b_true']:+.3f} | {r['raw']:+.3f} | {r['slope']:+.3f} | "
                     f"{r['gradient']:+.3f} | {r['interval']:+.3f} | "
                     f"{r['applied']:+.3f} ({r['chosen']}) | "
                     f"{r['counts_rule']:+.3f} | {score_cell(r['score_events'])} | {score_cell(r['score_counts'])} | "
                     f"{score_cell(r['score_true_pair'])} |")
    short = [r for r in rows.values() if not r.get("long")]
    lines.append(mean_row(f"mean of the {len(short)} short scenes", short,
                          ("score_events", "score_counts", "score_true_pair"), 8))
    long = {name: r for name, r in rows.items() if r.get("long")}
    if long:
        lv = lambda v: " ".join(f"{x:+.3f}" for x in v)          # noqa: E731
        lines += ["", "Level error per quarter (mean prediction minus mean truth) on the long scenes:", "",
                  "| scene | kit | kit, counts rule | kit given the true pair |", "|---|---|---|---|"]
        lines += [f"| {name} | {lv(r['level_events'])} | {lv(r['level_counts'])} | {lv(r['level_true_pair'])} |"
                  for name, r in long.items()]
    err = lambda key: float(np.sqrt(np.mean([(r[key] - r["b_true"]) ** 2 for r in short])))      # noqa: E731
    lines += ["", f"Root mean square error over all {len(rows)} scenes: of the applied b {rms['applied_error']:.3f}, of the "
              f"counts rule's {rms['counts_rule_error']:.3f}; over the {len(short)} short ones {err('applied'):.3f} and "
              f"{err('counts_rule'):.3f}. Kit cells: CLAHE-SSIM / SSIM / MSE at the zoo's scored times. "
              "Written by `python benchmarks/balance.py --off-heavy`."]
    return "\n".join(lines) + "\n"


def mode(a) -> tuple:
    """(results suffix, scenes, the row function) of the parsed arguments ``a``."""
    if a.fresh:
        return "_fresh", [z for seed in FRESH_SEEDS for z in fresh_scenes(seed)], fresh_row
    if a.light:
        return "_light", light_scenes(), light_row
    if a.off_heavy:
        short = default_scenes() + [h for h in HELDOUT if not h.long]
        long = [z for z in default_scenes(long=True) + HELDOUT if z.long]
        return "_off_heavy", [off_heavy(z) for z in short + long], off_heavy_row
    return ("_heldout", HELDOUT, scene_row) if a.heldout else ("", default_scenes(long=True), scene_row)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--heldout", action="store_true", help="the held-out scenes instead of the zoo's")
    p.add_argument("--speed", action="store_true", help="only time the intervals against the counts (1280 x 720)")
    p.add_argument("--off-heavy", action="store_true", help="every scene of both sets with C- > C+, and the kit's scores")
    p.add_argument("--light", action="store_true", help="the 20 s pan under a change of light, three C pairs")
    p.add_argument("--fresh", action="store_true", help="two random draws of every short scene's sensor, and the kit's scores")
    a = p.parse_args(argv)
    if a.speed:
        r = speed()
        print(f"{r['n_events']:,} events at {r['sensor_size'][1]} x {r['sensor_size'][0]} (interval stride "
              f"{r['stride']}): polarity_counts {r['polarity_counts']:.2f} s, interval_sums {r['interval_sums']:.2f} s "
              f"({r['ratio']:.2f}x), slice_counts {r['slice_counts']:.2f} s ({r['slice_ratio']:.2f}x)")
        return 0
    suffix, scenes, row_of = mode(a)
    rows = {}
    for z in scenes:
        rows[z.name] = r = row_of(z)
        print(f"{z.name:20s} span {r['span_s']:5.1f} s  n {r['mean_events']:6.1f}  s {r['counts_error']:.3f}  b {r['b_true']:+.3f}  "
              f"counts {r['raw']:+.3f}  slope {r['slope']:+.3f}  edges {r['gradient']:+.3f}  intervals {r['interval']:+.3f}  applied {r['applied']:+.3f} ({r['chosen']})  "
              f"counts rule {r['counts_rule']:+.3f}  "
              f"mean log change {r['mean_log_change']:+.3f}", flush=True)

    def rms_of(f):
        return float(np.sqrt(np.mean([f(r) ** 2 for r in rows.values()])))
    rms = {"b": rms_of(lambda r: r["b_true"]), "log_change": rms_of(lambda r: r["mean_log_change"]),
           "applied_error": rms_of(lambda r: r["applied"] - r["b_true"]),
           "counts_rule_error": rms_of(lambda r: r["counts_rule"] - r["b_true"])}
    print(f"root mean square: b {rms['b']:.3f}, mean log change {rms['log_change']:.2f}; error of the applied b "
          f"{rms['applied_error']:.3f}, of the counts rule's {rms['counts_rule_error']:.3f}")
    write_json(f"benchmarks/balance_results{suffix}.json", {"heldout": a.heldout, "off_heavy": a.off_heavy, "light": a.light,
                                                             "fresh": a.fresh,
                                                             "scenes": rows, "rms": rms, "prior": PRIOR,
                                                             "net_change": NET_CHANGE})
    render = {"_fresh": fresh_markdown, "_light": light_markdown, "_off_heavy": off_heavy_markdown}.get(suffix, markdown)
    Path(f"benchmarks/balance_results{suffix}.md").write_text(render(rows, rms))
    print(f"markdown: benchmarks/balance_results{suffix}.md")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
