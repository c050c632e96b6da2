"""``camcad check`` on positive-drive cams (issue 15): the rows it adds, against closed forms."""

from __future__ import annotations

import re

import pytest

from camcad.cli import main
from tests.conftest import ROOT


def _rows(capsys: pytest.CaptureFixture[str], sample: str) -> dict[str, str]:
    assert main(["check", str(ROOT / "samples" / sample)]) == 0
    out = capsys.readouterr().out.splitlines()[1:]
    pairs = [re.split(r"\s{2,}", line.strip(), maxsplit=1) for line in out if line.startswith("  ")]
    return {p[0]: p[1] for p in pairs if len(p) == 2}


def test_groove_check_lists_crossovers_at_the_laws_inflections(
    capsys: pytest.CaptureFixture[str],
) -> None:
    rows = _rows(capsys, "groove_rocker.toml")
    # an arm with inertia only: the driving flank changes where ψ″ = 0, which for a
    # symmetric law is the middle of its segment: the 140° rise from 0°, the 140° return from 180°
    assert rows["crossovers"] == "70.0°, 250.0°"
    assert rows["follower jump"] == "none (positive drive)"
    assert rows["groove width"] == "24.030 mm"  # 2 r_f + clearance = 24 + 0.03
    assert float(rows["max impact speed"].split()[0]) > 0.0


def test_conjugate_check_lists_the_second_plate(capsys: pytest.CaptureFixture[str]) -> None:
    rows = _rows(capsys, "indexing_conjugate.toml")
    assert rows["crossovers"] == "60.0°, 240.0°"  # mid-rise of the 120° rise, mid-return from 180°
    assert "2nd plate pressure angle" in rows and "2nd plate min curvature" in rows
