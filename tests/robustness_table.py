"""The bad-input case table of issue 13: each case class with its count and its outcomes.

    python tests/robustness_table.py            runs tests/test_robustness*.py and tests/test_signals.py

One pytest case is one row of the table. A passing case ended as it must (a clear error naming the
problem, or the correct result, and nothing left behind); a failing one is counted by what its
failure says: a traceback or internal error, files left behind, the input or an existing output
changed (data loss), else a silent wrong result. Exit status 1 if any case failed.
"""
import re
import sys
from collections import Counter, defaultdict
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
FILES = ["test_robustness.py", "test_robustness_more.py", "test_signals.py"]

# test function (prefix) -> case class; the first match wins
CLASSES = [
    ("output path / data loss", r"test_out_|test_output_|test_read_only_parent|test_check_output_path|"
                                r"test_demo_refuses_an_existing_out|test_data_fetch_convert_refuses"),
    ("signals", r"test_signal_|test_sigterm_|test_a_kill_"),
    ("concurrent runs", r"test_a_second_run|test_output_dir_lock|test_a_stale_lock"),
    ("option values", r"test_option_values|test_demo_option|test_window_and_time|test_reconstruct_option|"
                      r"test_at_|test_reconstruct_argument|test_info_option|test_info_arguments|test_demo_|"
                      r"test_batch_"),
    ("EvINRConfig fields", r"test_config_"),
    ("Python API misuse", r"test_events_|test_reconstruct_query|test_reconstruct_spans|test_read_recording_"),
    ("memory / sizes", r"test_memory_|test_a_tiny_bin|test_sensor_"),
    ("time units", r"test_integer_|test_implausible|test_time_unit|test_each_time_unit|test_a_wrong_time_unit"),
    ("damaged files", r"test_damaged_(files|npy|txt|ijrr|evreal|hqf|canonical)|test_odd_|test_npy_|test_npz_|"
                      r"test_hqf_|test_h5_|test_event_camera_|test_raw_|test_a_file_with_no_events"),
    ("polarity", r"test_both_polarity|test_polarity_"),
    ("guard / --debug / argparse", r"test_an_internal_error|test_unknown_subcommand|test_help_|test_argparse_|"
                                   r"test_the_guard"),
    ("data_fetch", r"test_data_fetch_"),
]
COLUMNS = ["cases", "clear error / correct", "tracebacks", "silent wrong results", "leftovers", "data loss",
           "skipped"]


def case_class(nodeid: str) -> str:
    name = nodeid.split("::")[-1]
    for label, pattern in CLASSES:
        if re.match(pattern, name):
            return label
    return "other"


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
            text = str(report.longrepr)
            if re.search(r"Traceback|internal error|panicked", text):
                row["tracebacks"] += 1
            elif "left files" in text or "leftover" in text:
                row["leftovers"] += 1
            elif re.search(r"changed or left|data loss|was lost", text):
                row["data loss"] += 1
            else:
                row["silent wrong results"] += 1
        if report.when == "call" or report.failed or report.skipped:
            row["cases"] += 1


def main() -> int:
    tally = Tally()
    code = pytest.main([*(str(HERE / f) for f in FILES), "-q", "-p", "no:cacheprovider"], plugins=[tally])
    order = [label for label, _ in CLASSES] + ["other"]
    total = Counter()
    print(f"\n| class | {' | '.join(COLUMNS)} |\n|---|{'---|' * len(COLUMNS)}")
    for label in order:
        row = tally.rows.get(label)
        if row:
            total.update(row)
            print(f"| {label} | {' | '.join(str(row[c]) for c in COLUMNS)} |")
    print(f"| **total** | {' | '.join(str(total[c]) for c in COLUMNS)} |")
    return int(code != 0)


if __name__ == "__main__":
    sys.exit(main())
