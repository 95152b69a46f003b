"""The colour filter has one home (evinr_lite.core.cfa); io, sim, method, apps and data_fetch use it and the
old import paths (io.canonical, sim.quadbayer) still give the same objects."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from evinr_lite.core import cfa
from evinr_lite.core.events import EventDataError

ROOT = Path(__file__).resolve().parents[1]
NAMES = ("CFA_NAMES", "check_cfa", "cfa_phase", "CHANNELS", "QUAD_BAYER", "BAYER", "TILE_COLOURS", "period",
         "photosites_per_window", "cfa_tile", "cfa_channel", "cfa_pattern", "effective_thresholds")


def test_old_import_paths_give_the_same_objects():
    from evinr_lite.io import canonical
    from evinr_lite.sim import quadbayer

    for name in ("CFA_NAMES", "check_cfa", "cfa_phase"):
        assert getattr(canonical, name) is getattr(cfa, name), name
    for name in NAMES[3:]:
        assert getattr(quadbayer, name) is getattr(cfa, name), name


def test_no_other_module_defines_the_filter():
    pattern = re.compile(r"^(CFA_NAMES\s*=|TILE_COLOURS\s*=|def (check_cfa|cfa_phase|cfa_channel|cfa_pattern|cfa_tile|"
                         r"effective_thresholds|photosites_per_window)\()", re.M)
    found = [str(p.relative_to(ROOT)) for pkg in ("evinr_lite", "data_fetch") for p in (ROOT / pkg).rglob("*.py")
             if pattern.search(p.read_text(encoding="utf-8"))]
    assert found == ["evinr_lite/core/cfa.py"], found


def test_names_phases_and_thresholds():
    assert [cfa.cfa_phase(n) for n in ("rggb", "GRBG", "GBRG", "BGGR")] == [(0, 0), (0, 1), (1, 0), (1, 1)]
    for name, phase in cfa.CFA_NAMES.items():   # the name spells the tile as the sensor sees it
        assert "".join(cfa.CHANNELS[c] for c in cfa.cfa_tile(cfa.BAYER, phase).ravel()) == name
    assert cfa.check_cfa(None) is None
    with pytest.raises(ValueError, match="cfa must be one of RGGB"):
        cfa.check_cfa("RGBG", ValueError)
    with pytest.raises(EventDataError, match="mono"):
        cfa.cfa_phase(None)
    assert cfa.effective_thresholds(0.32, cfa.QUAD_BAYER) == {"R": 0.08, "G": 0.04, "B": 0.08, "grey": 0.02}
