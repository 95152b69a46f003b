"""The commands the docs show can be typed as written: every ``evinr-lite`` / ``python -m evinr_lite`` and
``python -m data_fetch`` command in the README, docs/*.md and benchmarks/README.md names a real subcommand
and only options it has (checked against the parsers, nothing run); every ``python benchmarks/X.py`` /
``python tools/X.py`` script exists and defines the flags shown; batch.md's list of suffixes is the one
batch uses, and reliability.md's the settings a batch's resume compares. Reads text and builds two
argparse parsers: about a second."""
from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")), ROOT / "benchmarks" / "README.md"]

_FENCED = re.compile(r"```[^\n]*\n(.*?)```", re.S)
_SPAN = re.compile(r"`([^`]+)`")
_COMMAND = re.compile(r"(evinr-lite|python -m evinr_lite|python -m data_fetch|python (?:benchmarks|tools)/\w+\.py)"
                      r"((?:[ \t]+[^\s#`]+)*)")
_FLAG = re.compile(r"(?<![\w-])(--[a-z][\w-]*)")


def _commands():
    """(doc, program, the words after it) for every command in a code span or a fenced block."""
    found = []
    for doc in DOCS:
        text = doc.read_text(encoding="utf-8")
        blocks = _FENCED.findall(text)
        spans = [s.replace("\n", " ") for s in _SPAN.findall(_FENCED.sub("", text))]
        for piece in [line for block in blocks for line in block.splitlines()] + spans:
            piece = re.split(r"\s#\s", piece)[0]          # a shell comment ends the command
            for m in _COMMAND.finditer(piece):
                found.append((doc.relative_to(ROOT).as_posix(), m.group(1), m.group(2).split()))
    return found


COMMANDS = _commands()


def _subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(action.choices)


def _check_subcommand(parser, doc, words, program):
    subs = _subcommands(parser)
    top = set(parser._option_string_actions)
    if not words or words[0].startswith("-") or not re.fullmatch(r"[a-z]+", words[0]):
        return                                          # `evinr-lite --help`, `evinr-lite ...`, a placeholder
    assert words[0] in subs, f"{doc}: `{program} {' '.join(words)}`: no subcommand {words[0]!r} (has {sorted(subs)})"
    options = set(subs[words[0]]._option_string_actions) | top
    unknown = [f for f in _FLAG.findall(" ".join(words[1:])) if f not in options]
    assert not unknown, f"{doc}: `{program} {' '.join(words)}`: {words[0]} has no {unknown}"


def test_the_docs_show_commands():
    programs = {p for _, p, _ in COMMANDS}
    assert {"evinr-lite", "python -m evinr_lite", "python -m data_fetch"} <= programs
    assert any(p.startswith("python benchmarks/") for p in programs)


def test_evinr_lite_commands_exist_with_their_options():
    from evinr_lite.apps.cli import build_parser
    parser = build_parser()
    for doc, program, words in COMMANDS:
        if program in ("evinr-lite", "python -m evinr_lite"):
            _check_subcommand(parser, doc, words, program)


def test_data_fetch_commands_exist_with_their_options():
    from data_fetch.__main__ import build_parser
    parser = build_parser()
    for doc, program, words in COMMANDS:
        if program == "python -m data_fetch":
            _check_subcommand(parser, doc, words, program)


@pytest.mark.parametrize("script", sorted({p.split()[1] for _, p, _ in COMMANDS if p.endswith(".py")}))
def test_scripts_exist_and_define_the_flags_shown(script):
    path = ROOT / script
    assert path.is_file(), f"the docs run {script}, which does not exist"
    source = path.read_text(encoding="utf-8")
    for doc, program, words in COMMANDS:
        if program.endswith(script):
            for flag in _FLAG.findall(" ".join(words)):
                assert f'"{flag}"' in source, f"{doc}: `{program} {' '.join(words)}`: {script} defines no {flag}"


def test_batch_md_lists_the_suffixes_batch_reads():
    from evinr_lite.io.formats import RECORDING_SUFFIXES
    text = (ROOT / "docs" / "batch.md").read_text(encoding="utf-8")
    listed = re.search(r"files ending\s+in `([^`]+)`", text)
    assert listed, "docs/batch.md no longer lists the suffixes of a folder's recordings"
    assert sorted(listed.group(1).split()) == sorted(RECORDING_SUFFIXES)


def test_reliability_md_lists_the_settings_a_batch_resume_compares():
    from evinr_lite.apps.batch import RESULT_SETTINGS
    text = (ROOT / "docs" / "reliability.md").read_text(encoding="utf-8")
    listed = re.search(r"the result settings \(((?:`\w+`,?\s*)+)\)", text)
    assert listed, "docs/reliability.md no longer lists the result settings a rerun compares"
    assert re.findall(r"`(\w+)`", listed.group(1)) == list(RESULT_SETTINGS)


def test_the_checker_catches_a_wrong_option():
    from evinr_lite.apps.cli import build_parser
    with pytest.raises(AssertionError, match="no \\['--frames'\\]"):
        _check_subcommand(build_parser(), "x.md", ["reconstruct", "R", "--out", "D", "--frames", "3"], "evinr-lite")
    with pytest.raises(AssertionError, match="no subcommand"):
        _check_subcommand(build_parser(), "x.md", ["recon", "R"], "evinr-lite")
