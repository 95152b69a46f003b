"""One writable-folder check (io.output.check_writable) for run folders and data_fetch's cache and outputs."""
from __future__ import annotations

import os

import pytest

from data_fetch.conversion import check_writable_folder
from data_fetch.errors import DataFetchError
from evinr_lite.io.output import OutputError, check_output_path, check_writable


def test_a_folder_under_a_file_is_refused_by_both_callers(tmp_path):
    (tmp_path / "a_file").write_text("x")
    with pytest.raises(OutputError, match="cannot create the output folder .*a_file is a file, not a folder; choose"):
        check_output_path(tmp_path / "a_file" / "out")
    with pytest.raises(DataFetchError, match="cannot create the cache folder .*is a file, not a folder; set EVINR_DATA"):
        check_writable_folder(tmp_path / "a_file" / "cache", "cache folder")


def test_no_permission_is_refused_by_both_callers(tmp_path, monkeypatch):
    monkeypatch.setattr(os, "access", lambda path, mode: False)    # as a read-only parent (root may write anyway)
    with pytest.raises(OutputError, match=f"no permission to write in {tmp_path}; choose another out_dir="):
        check_output_path(tmp_path / "out")
    with pytest.raises(DataFetchError, match=f"no permission to write in {tmp_path}; set EVINR_DATA"):
        check_writable_folder(tmp_path / "new" / "cache", "cache folder")


def test_a_writable_place_returns_its_nearest_existing_folder(tmp_path):
    assert check_writable(tmp_path / "a" / "b", "the folder", "fix") == tmp_path
    assert check_writable(tmp_path, "the folder", "fix") == tmp_path
    check_writable_folder(tmp_path / "cache", "cache folder")          # no error
