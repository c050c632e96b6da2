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


def test_size_of_a_conjugate_pair_keeps_the_second_plate_within_its_limits(
    tmp_path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The second arm at 120° makes plate 2 bind: the printed radius passes ``check``'s pressure
    angle on both plates, 1 µm less fails it on the second plate (issue 31)."""
    text = (ROOT / "samples" / "indexing_conjugate.toml").read_text(encoding="utf-8")
    text = re.sub(r"(?m)^pivot_distance = .*$", "pivot_distance = 130.0", text)
    text = re.sub(r"(?m)^angle = 80\.0 .*$", "angle = 120.0", text)
    design = tmp_path / "pair.toml"
    design.write_text(text, encoding="utf-8")
    assert main(["size", str(design)]) == 0
    said = capsys.readouterr().out
    radius = float(re.search(r"smallest base radius: ([0-9.]+) mm", said).group(1))  # type: ignore[union-attr]
    assert radius > 58.0  # plate 1 alone needs 51.281 mm here

    def check(r: float) -> str:
        trial = tmp_path / "trial.toml"
        trial.write_text(re.sub(r"(?m)^base_radius = .*$", f"base_radius = {r:.3f}", text), encoding="utf-8")
        main(["check", str(trial)])
        return capsys.readouterr().out

    # the pivot clearance (a hub the second profile sweeps into) is not a sizing limit: only the
    # pressure angle and curvature limits are compared
    held = [line for line in check(radius).splitlines() if " limit: " in line]
    assert not [line for line in held if "pressure angle" in line or "curvature" in line], held
    failed = check(radius - 0.001)
    assert "second plate: pressure angle reaches" in failed, failed
