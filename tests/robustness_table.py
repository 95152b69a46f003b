"""The bad-input case table (issues 13 and 25, and the later rounds): each case class with its count and outcomes.

    python tests/robustness_table.py            every file below; exit status 1 unless the four counts are 0
    python tests/robustness_table.py --round3   only issue 25's classes (its test files)
    python tests/robustness_table.py --later    only the later rounds (bad files 4 to 11, API arguments, fuzzed readers)

One pytest case is one row of the table. A passing case ended as it must (a clear error naming the
problem, or the correct result, and nothing left behind). A failing one is counted by what its failure
says, in this order: a traceback shown to the user; an internal error on bad input (the command's
"internal error", or an exception other than an assertion escaping the library); files left behind;
the input, an existing output or a user's file changed (data loss); else a silent wrong result.

The verdict line asks for 0 data loss, 0 tracebacks, 0 internal errors on bad input and 0 silent wrong
results (leftovers and skips are shown too).
"""
import argparse
import re
import sys
from collections import Counter, defaultdict
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
ROUND2 = ["test_robustness.py", "test_robustness_more.py", "test_signals.py"]
ROUND3 = ["test_batch_ownership.py", "test_api_checks.py", "test_signals_edges.py", "test_robustness_round3.py",
          "test_io_reliability.py", "test_options.py"]
LATER = ["test_robustness_round4.py", "test_robustness_round5.py", "test_robustness_round6.py", "test_api_bad_inputs.py",
         "test_api_round6.py", "test_ragged_inputs.py", "test_fuzz_readers.py", "test_robustness_round7.py",
         "test_robustness_round8.py", "test_robustness_round9.py", "test_robustness_round10.py",
         "test_robustness_round11.py", "test_robustness_round12.py", "test_robustness_round13.py",
         "test_robustness_round14.py", "test_robustness_round15.py", "test_robustness_round16.py",
         "test_robustness_round17.py", "test_robustness_round18.py",
         "test_robustness_round19.py", "test_robustness_round20.py", "test_robustness_round21.py"]

# (file, test function pattern) -> case class; the first match wins. Issue 25's classes come first.
CLASSES = [
    # ---- later rounds: one class per file -------------------------------------------------------
    ("bad files, round 4 (one instant, 0/1 events, absurd sizes, NaN frames)", "test_robustness_round4.py", r"test_"),
    ("exports and odd files, round 5 (spreadsheets, compressed, npz, options)", "test_robustness_round5.py", r"test_"),
    ("text quirks, links, clocks and containers, round 6", "test_robustness_round6.py", r"test_"),
    ("Python API arguments (bad inputs)", "test_api_bad_inputs.py", r"test_"),
    ("Python API arguments, round 6 (tensors, 0-d, float32 and us times)", "test_api_round6.py", r"test_"),
    ("ragged nests as times, samples, frames or columns", "test_ragged_inputs.py", r"test_"),
    ("fuzzed readers (every format, damaged bytes)", "test_fuzz_readers.py", r"test_"),
    ("cut-off and joined files, changed configs, odd stacks and paths, round 7", "test_robustness_round7.py",
     r"test_"),
    ("wrapped types and clocks, typed paths, writers, empty windows, misspelt fields, round 8",
     "test_robustness_round8.py", r"test_"),
    ("the background filter's chosen window: off-centre scenes, empty slices, one pixel, one instant, its "
     "arguments, round 9", "test_robustness_round9.py", r"test_"),
    ("the scorer, APS anchors and the fit of C, the colour path and the figures: odd pixels, shapes, times, sensors "
     "and empty inputs, round 10", "test_robustness_round10.py", r"test_"),
    ("the simulator (seeds, noise rates and spans, scenes, colour, recordings) and the method's helpers beside "
     "reconstruct (baselines, bins, lam, windows, tone maps, denoiser, enhancement, ablation), round 11",
     "test_robustness_round11.py", r"test_"),
    ("the teaching helpers readers re-call (pde1d's window sums, Taylor error, one-pixel SIREN, its fit, loss and "
     "residuals; events2d's pixel trace and busiest pixel): contrasts, edges, windows, spans, seeds, pixels, round 12",
     "test_robustness_round12.py", r"test_"),
    ("public functions no round had called with bad arguments (the colour filter array and Quad Bayer's "
     "demosaicing, the memory estimate, recipes and the printed C, the streaming solver's entry, a source's window, "
     "the level match, the notebooks' controls): types, NaN, sizes, shapes, spans, round 13",
     "test_robustness_round13.py", r"test_"),
    ("the batch's entries (inputs, rows, settings, out_dir, hooks), a Reconstruction's query times, the event "
     "figures' helpers, signed counts, the protocol's text and the inference timing: types, NaN, counts, colours, "
     "10^9 times, round 14", "test_robustness_round14.py", r"test_"),
    ("data_fetch's names and settings, the canonical file's writer and reader, the readers' keyword options, every "
     "job's output folder and the demo and reconstruct jobs from Python: names, paths, flags, counts, windows, "
     "round 15", "test_robustness_round15.py", r"test_"),
    ("the temporal scale set by hand (a floor) and the tone map's overflow, the tempo helpers, the solver's plan from "
     "counts and the balance's sums, the simulator's thresholds, the zoo, the colour recording's writer, the scorer's "
     "LPIPS model, the figures' axes and one-pixel curves, degenerate recordings: counts, shapes, spans, flags, "
     "round 16", "test_robustness_round16.py", r"test_"),
    ("the offset solves and their parts (Poisson integration, the low-pass), the anchor's helpers, the frames-against-"
     "events helpers of the fit of C and its threshold, the head solve's spectrum and the notebooks' losses: NaN "
     "frames, shapes that do not go together, eps, exposed, sensors, weights, counts of iterations and anchors, "
     "round 17", "test_robustness_round17.py", r"test_"),
    ("the networks' constructors (Siren, SineLayer, FrameINR), the coordinate method's config, the chunked event "
     "frames, the colour helpers, two scenes, the device choice and the figures notebooks call (event frames, "
     "animations, frame grids, histories, score charts, event ticks): sizes, frequencies, seeds, flags, windows, "
     "round 18", "test_robustness_round18.py", r"test_"),
    ("enumerated options (equalisation, tone maps, the denoiser's rule and window, the config's and run options' option "
     "fields, anchors, baselines' loops, offset solves, polarity encodings, figure options) given arrays, lists, dicts, "
     "tensors, None or numbers: one shared check, round 19", "test_robustness_round19.py", r"test_"),
    ("public functions that take data and no round had named (the balance's estimates, the offset trend, the coarse "
     "correction's helpers, pixel masks, the per-event filter, the coordinate method's pieces, the ablation helpers, "
     "LPIPS, the apps' scorers and writers, the text parsers, JSON and paths): None, text, NaN, shapes, masks, "
     "counts, keywords a helper sets itself, half-written files, round 20 and its review (uint and bool counts, 0-d "
     "lists, Mapping rows, NaN and bool polarities, restored buffers, scalars, generators, bytes paths and Decimal)",
     "test_robustness_round20.py", r"test_"),
    ("the format readers called by name, the registry's and the loader's helpers, the canonical file's index "
     "helpers and the colour filter's phase: paths that are no path, folders and missing files, sensor sizes, meta, "
     "events_span, format names, info dicts, index queries, frame times, blocks, round 21",
     "test_robustness_round21.py", r"test_"),
    # ---- issue 25 -------------------------------------------------------------------------------
    ("batch ownership", "test_batch_ownership.py",
     r"test_an_out_among|test_a_user_folder|test_a_damaged_batch_json|test_a_foreign_partial|test_an_out_through|"
     r"test_the_command_refuses_out"),
    ("input identity in resume", "test_batch_ownership.py",
     r"test_a_different_input|test_a_changed_file|test_one_recording_reached|test_labels_do_not_depend"),
    ("batch leftovers", "test_batch_ownership.py", r"test_no_lock_file|test_a_scheduler_address"),
    ("one clock for frames and events", "test_io_reliability.py", r"test_(ijrr|hqf|evreal)_frame"),
    ("plausibility of units and ranges", "test_io_reliability.py", r"test_decimal_milliseconds|test_fast_decimal"),
    ("plausibility of units and ranges", "test_api_checks.py",
     r"test_events_refuse_a_sensor|test_events_take|test_integer_|test_frames_and_the_scorer|test_the_scorer_still|"
     r"test_config_values|test_the_command_refuses_an_implausible_C"),
    ("checked indexes", "test_io_reliability.py", r"test_a_damaged_time_index|test_find_time_index|test_unsorted_frame"),
    ("typed metadata", "test_io_reliability.py", r"test_wrongly_typed_meta|test_a_canonical_dataset|test_an_hqf_dataset"),
    ("typed metadata", "test_robustness_round3.py", r"test_data_fetch_info_"),
    ("one time-list parser", "test_options.py",
     r"test_a_list_on_one_line|test_a_long_list|test_timestamps_txt|test_bad_time_lists|test_a_folder_is_not|"
     r"test_the_command_line_reads"),
    ("API arguments", "test_api_checks.py", r"test_reconstruct_names|test_at_|test_fit_contrast|test_the_helpers"),
    ("non-finite or constant output refused", "test_api_checks.py", r"test_output_that_is_not"),
    ("scored index = written ground truth", "test_api_checks.py", r"test_metrics_gt_index|test_a_frame_exactly_at_end"),
    ("signals from the first instruction", "test_signals_edges.py",
     r"test_signal_at_start_up|test_three_quick|test_an_interrupt_that|test_a_second_signal"),
    ("pipes", "test_signals_edges.py", r"test_a_reader_that_closes"),
    ("deleted cwd / info without torch", "test_signals_edges.py", r"test_a_deleted_current|test_info_and_help"),
    ("leftovers (locks, partials, ENOSPC)", "test_signals_edges.py", r"test_enospc"),
    ("guard / --debug / argparse", "test_robustness_round3.py", r"test_both_commands_share"),
    ("output path / data loss", "test_robustness_round3.py", r"test_an_out_through"),
    # ---- issue 13 -------------------------------------------------------------------------------
    ("output path / data loss", None, r"test_out_|test_output_|test_read_only_parent|test_check_output_path|"
                                      r"test_demo_refuses_an_existing_out|test_data_fetch_convert_refuses"),
    ("signals", None, r"test_signal_|test_sigterm_|test_a_kill_"),
    ("concurrent runs", None, r"test_a_second_run|test_output_dir_lock|test_a_stale_lock"),
    ("option values", None, r"test_option_values|test_demo_option|test_window_and_time|test_reconstruct_option|"
                            r"test_at_|test_reconstruct_argument|test_info_option|test_info_arguments|test_demo_|"
                            r"test_batch_"),
    ("EvINRConfig fields", None, r"test_config_"),
    ("Python API misuse", None, r"test_events_|test_reconstruct_query|test_reconstruct_spans|test_read_recording_"),
    ("memory / sizes", None, r"test_memory_|test_a_tiny_bin|test_sensor_"),
    ("time units", None, r"test_integer_|test_implausible|test_time_unit|test_each_time_unit|test_a_wrong_time_unit"),
    ("damaged files", None, r"test_damaged_(files|npy|txt|ijrr|evreal|hqf|canonical)|test_odd_|test_npy_|test_npz_|"
                            r"test_hqf_|test_h5_|test_event_camera_|test_raw_|test_a_file_with_no_events"),
    ("polarity", None, r"test_both_polarity|test_polarity_"),
    ("guard / --debug / argparse", None, r"test_an_internal_error|test_unknown_subcommand|test_help_|test_argparse_|"
                                         r"test_the_guard"),
    ("data_fetch", None, r"test_data_fetch_"),
]
COLUMNS = ["cases", "clear error / correct", "data loss", "tracebacks", "internal errors on bad input",
           "silent wrong results", "leftovers", "skipped"]
MUST_BE_ZERO = ["data loss", "tracebacks", "internal errors on bad input", "silent wrong results"]


def case_class(nodeid: str) -> str:
    path, _, name = nodeid.partition("::")
    name = name.split("::")[-1]
    file = Path(path).name
    for label, in_file, pattern in CLASSES:
        if (in_file is None or in_file == file) and re.match(pattern, name):
            return label
    return "other"


def outcome(report) -> str:
    """The column of one failed case, from what its failure says."""
    text = str(report.longrepr)
    crash = getattr(getattr(report.longrepr, "reprcrash", None), "message", "") or ""
    if re.search(r"Traceback \(most recent|panicked|Exception ignored", text):
        return "tracebacks"
    if "internal error" in text or (crash and not re.match(r"(AssertionError|Failed|assert )", crash)):
        return "internal errors on bad input"      # an exception other than an assertion escaped
    if re.search(r"left files|leftover|\.partial-|\.lock\b|\.batch\.lock", text):
        return "leftovers"
    if re.search(r"snapshot|changed or left|data loss|was lost|user's own|keep me|read_text\(\) == ", text):
        return "data loss"
    return "silent wrong results"


class Tally:
    def __init__(self):
        self.rows = defaultdict(Counter)

    def pytest_runtest_logreport(self, report):
        if report.when != "call" and not (report.failed or report.skipped):
            return
        row = self.rows[case_class(report.nodeid)]
        if report.skipped:
            row["skipped"] += 1
        elif report.passed:
            row["clear error / correct"] += 1
        else:
            row[outcome(report)] += 1
        row["cases"] += 1


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    which = p.add_mutually_exclusive_group()
    which.add_argument("--round3", action="store_true", help="only issue 25's test files")
    which.add_argument("--later", action="store_true", help="only the later rounds' test files")
    args = p.parse_args(sys.argv[1:] if argv is None else argv)
    files = ROUND3 if args.round3 else LATER if args.later else ROUND2 + ROUND3 + LATER
    files = [f for f in files if (HERE / f).exists()]
    tally = Tally()
    # -n 0: in this process, so the tally plugin sees every report (the suite itself runs on workers)
    code = pytest.main([*(str(HERE / f) for f in files), "-q", "-p", "no:cacheprovider", "-n", "0"], plugins=[tally])
    order = list(dict.fromkeys(label for label, _, _ in CLASSES)) + ["other"]
    total = Counter()
    print(f"\n| class | {' | '.join(COLUMNS)} |\n|---|{'---|' * len(COLUMNS)}")
    for label in order:
        row = tally.rows.get(label)
        if row:
            total.update(row)
            print(f"| {label} | {' | '.join(str(row[c]) for c in COLUMNS)} |")
    print(f"| **total** | {' | '.join(str(total[c]) for c in COLUMNS)} |")
    verdict = ", ".join(f"{total[c]} {c}" for c in MUST_BE_ZERO)
    ok = not any(total[c] for c in MUST_BE_ZERO) and code == 0
    print(f"\n{'PASS' if ok else 'FAIL'}: {verdict} ({len(files)} files: {', '.join(files)})")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
