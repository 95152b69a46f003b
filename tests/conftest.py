from pathlib import Path

import pytest

SHARED_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"


@pytest.fixture
def slider_depth_dir():
    """The small real IJRR recording beside the project, or a skip saying why."""
    path = SHARED_DATA / "ijrr_slider_depth_chunk"
    if not (path / "events.txt").exists():
        pytest.skip(f"real recording not present at {path} (it ships only in ../shared beside the project)")
    return path
