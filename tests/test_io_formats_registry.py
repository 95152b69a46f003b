"""The format registry: every format module declares itself, and detection, SUPPORTED_FORMATS, the
capability tables and batch's suffixes are derived from those declarations (nothing listed twice)."""
import importlib
import pkgutil

import pytest

import evinr_lite.io.formats as formats
from evinr_lite.core.events import EventDataError
from evinr_lite.io.formats import registry
from evinr_lite.io.formats.base import FileFormat


def _declared():
    found = {}
    for info in pkgutil.iter_modules(formats.__path__):
        module = importlib.import_module(f"evinr_lite.io.formats.{info.name}")
        declared = getattr(module, "FORMATS", None) or getattr(module, "FORMAT", None)
        if declared is not None:
            for fmt in declared if isinstance(declared, tuple) else (declared,):
                found[fmt.name] = (info.name, fmt)
    return found


def test_every_format_module_declares_a_complete_format():
    declared = _declared()
    assert set(declared) == {"ijrr", "evreal", "canonical", "h5", "aedat3", "aedat4", "prophesee_raw", "prophesee_dat",
                             "npy", "txt", "csv", "dsec", "mvsec"}
    for name, (module, fmt) in declared.items():
        assert isinstance(fmt, FileFormat) and callable(fmt.reader) and callable(fmt.sniff), name
        assert fmt.folder or fmt.suffixes, f"{module}: a file format names its suffixes"
        assert not fmt.windowed or fmt.open_source is not None, name
        assert fmt.description in registry.SUPPORTED_FORMATS
        assert ";" not in fmt.description, f"{name}: the list of formats is joined with '; '"


def test_tables_are_derived_from_the_declarations():
    declared = {name: fmt for name, (_, fmt) in _declared().items()}
    assert set(registry.SIZE_FREE_FORMATS) == {n for n, f in declared.items() if f.needs_sensor_size}
    assert set(registry.READER_WINDOW_FORMATS) == {n for n, f in declared.items() if f.windowed}
    assert set(registry.SENSOR_ARG_FORMATS) == {n for n, f in declared.items() if f.takes_sensor_size}
    assert registry.FIXED_UNITS == {n: f.time_unit for n, f in declared.items() if f.time_unit}
    assert set(registry.RECORDING_SUFFIXES) == {s for f in declared.values() for s in f.suffixes}
    # the names other layers import keep working, and are the registry's
    from evinr_lite.apps import batch, recon_job
    from evinr_lite.io import readers

    assert batch.RECORDING_SUFFIXES is registry.RECORDING_SUFFIXES
    assert recon_job.READER_WINDOW_FORMATS is registry.READER_WINDOW_FORMATS
    assert readers.SUPPORTED_FORMATS is registry.SUPPORTED_FORMATS and readers.detect_format is registry.detect_format


def test_a_declared_format_is_detected_and_read_through_the_registry(tmp_path, monkeypatch):
    """What adding a format takes: a FileFormat with a sniffer and a reader, nothing else."""
    import numpy as np

    from evinr_lite.core.events import Events
    from evinr_lite.core.recording import Recording

    def read_demo(path, **options):
        t = np.array([0.1, 0.2])
        return Recording(Events(t, [0, 1], [0, 1], [1, -1], (2, 2)), None, {"format": "demo", "path": str(path)})

    demo = FileFormat(name="demo", description="a demo file", reader=read_demo, suffixes=(".demo",),
                      sniff=lambda path, head: head is not None and head.startswith(b"DEMO"), priority=5)
    monkeypatch.setattr(registry, "FORMATS", (demo, *registry.FORMATS))
    monkeypatch.setattr(registry, "_BY_NAME", {f.name: f for f in registry.FORMATS})
    path = tmp_path / "x.demo"
    path.write_bytes(b"DEMO\n")
    assert registry.detect_format(path) == "demo"
    assert len(registry.read_recording(path).events) == 2
    from evinr_lite.io import open_recording

    with open_recording(path) as src:
        assert src.n_events == 2 and src.format == "demo"


@pytest.mark.parametrize("content,problem", [(b"#!AER-DAT2.0\r\n", "AEDAT2"), (b"#!AER-DAT3.0\r\n", "AEDAT 3.0"),
                                             (b"PK\x03\x04rest", "zip archive"),
                                             (b"\x00\x01binary", "unknown format")])
def test_unsupported_files_are_named(tmp_path, content, problem):
    path = tmp_path / "rec.bin"
    path.write_bytes(content)
    with pytest.raises(EventDataError, match=problem):
        registry.detect_format(path)


def test_folders_of_recordings_are_not_recordings(tmp_path):
    (tmp_path / "seq").mkdir()
    (tmp_path / "seq" / "events.txt").write_text("0.1 1 1 1\n")
    assert registry.is_recording_folder(tmp_path / "seq")
    assert not registry.is_recording_folder(tmp_path)
    assert not registry.is_recording_folder(tmp_path / "seq" / "events.txt")
