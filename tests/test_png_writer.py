"""PngWriter (io/output.py): PNGs encoded on worker threads are the files save_png writes, errors reach the
caller, and leaving on an error or an interruption leaves no thread writing."""
import threading
import time

import numpy as np
import pytest

from evinr_lite.io.export import save_frames_png
from evinr_lite.io.output import PngWriter, save_png


def _frames(n=12, size=(48, 64)):
    rng = np.random.default_rng(0)
    return [rng.integers(0, 256, size, dtype=np.uint8) for _ in range(n)]


def _png_threads():
    return [t for t in threading.enumerate() if t.name.startswith("evinr-png") and t.is_alive()]


@pytest.mark.parametrize("threads", [1, 2, 3])
def test_the_files_are_save_png_s_byte_for_byte(tmp_path, threads):
    frames = _frames()
    for i, f in enumerate(frames):
        save_png(tmp_path / f"a{i}.png", f)
    with PngWriter(threads) as png:
        for i, f in enumerate(frames):
            png.write(tmp_path / f"b{i}.png", f)
            f[:] = 0                                  # the caller may reuse its buffer at once
    for i in range(len(frames)):
        assert (tmp_path / f"a{i}.png").read_bytes() == (tmp_path / f"b{i}.png").read_bytes()
    assert not _png_threads()
    paths = save_frames_png(tmp_path / "stack", np.stack(_frames()))
    assert [p.read_bytes() for p in paths] == [(tmp_path / f"a{i}.png").read_bytes() for i in range(len(paths))]


def test_a_failed_write_is_raised_and_the_rest_still_waited_for(tmp_path):
    frames = _frames(8)
    with pytest.raises(OSError):
        with PngWriter(2) as png:
            for i, f in enumerate(frames):
                folder = tmp_path / ("missing" if i == 3 else "")
                png.write(folder / f"{i}.png", f)
    assert not _png_threads()
    with pytest.raises(Exception, match="save_png writes one image"):     # a bad image: save_png's own error
        with PngWriter(1) as png:
            png.write(tmp_path / "x.png", np.zeros((2, 3, 5, 7)))
            time.sleep(0.05)
            png.write(tmp_path / "y.png", _frames(1)[0])


def test_leaving_on_an_interruption_cancels_what_has_not_started(tmp_path):
    frames = _frames(40, (360, 480))
    with pytest.raises(KeyboardInterrupt):
        with PngWriter(1) as png:
            for i, f in enumerate(frames):
                png.write(tmp_path / f"{i}.png", f)
                if i == 5:
                    raise KeyboardInterrupt
    assert not _png_threads()                         # nothing writes any more
    written = sorted(tmp_path.iterdir())
    time.sleep(0.1)
    assert sorted(tmp_path.iterdir()) == written and len(written) <= 6
