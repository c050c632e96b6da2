"""The Python API (issue 39), through public names only, against the command line and the loader.

The figures of ``camcad.analyse`` must be those ``camcad check`` prints, on
every shipped sample (the check's table parsed from its output); a variant
from ``Design.replace`` must be refused with the loader's own message for a
file with that value; ``Result.build`` must write the bytes ``camcad build``
writes; the Jupyter renderings must parse as XML.
"""

from __future__ import annotations

import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from lxml import etree

import camcad
from camcad.cli import main
from tests.conftest import ROOT, SAMPLES

OFFSET = ROOT / "samples" / "offset_roller.toml"
ROW = re.compile(r"^  (\S.*?)\s{2,}(\S.*)$")
AT = re.compile(r" at (−?-?[\d.]+)°(?: \(just (before|after) the joint\))?")


def cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run(
        [sys.executable, "-m", "camcad", *args], capture_output=True, text=True, env=env, cwd=cwd, timeout=600
    )


def check_table(path: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, dict[str, str], list[str]]:
    """``camcad check``'s exit code, its rows (label → text) and its limit lines."""
    code = main(["check", str(path)])
    out = capsys.readouterr().out.splitlines()
    rows, limits = {}, []
    for line in out[1:]:
        if line.startswith(("  hard limit: ", "  soft limit: ")):
            limits.append(line.split(": ", 1)[1])
        elif (m := ROW.match(line)) is not None:
            rows[m.group(1)] = m.group(2)
    return code, rows, limits


def shown(q: camcad.Quantity, digits: int, unit: str) -> str:
    """A quantity as ``camcad check`` prints it (value, unit, where)."""
    if q.value is None:
        return "—"
    text = f"{q.value:.{digits}f}{unit}"
    if q.angle_deg is not None:
        text += f" at {q.angle_deg:.1f}°"
        if q.side:
            text += f" (just {q.side.replace(' joint', ' the joint')})"
    return text


@pytest.fixture(scope="module")
def offset() -> camcad.Result:
    """The offset roller sample, analysed once for the tests that only read it."""
    return camcad.analyse(camcad.load(OFFSET), toolpath=False)


def yes_no(value: bool | None) -> str:
    return "—" if value is None else ("yes" if value else "no")


@pytest.mark.parametrize("path", SAMPLES, ids=[p.stem for p in SAMPLES])
def test_figures_equal_those_camcad_check_prints(path, capsys):
    result = camcad.analyse(camcad.load(path), toolpath=False)
    code, rows, limits = check_table(path, capsys)
    lift = rows["lift"] if "lift" in rows else rows["arm swing"]
    unit = " mm" if result.lift_unit == "mm" else "°"
    expected = shown(result.lift, 3, unit)
    if round(result.stroke.value, 3) != round(result.lift.value, 3):  # the true travel beside the lift
        low, high = (round(q.value, 3) + 0.0 for q in (result.travel_min, result.travel_max))
        expected += (
            f" (true stroke {result.stroke.value:.3f}{unit}: {low:.3f}{unit} to {high:.3f}{unit}"
            f" at {result.travel_max.angle_deg:.1f}°)"
        )
    assert lift == expected
    assert math.isclose(result.stroke.value, result.travel_max.value - result.travel_min.value, abs_tol=1e-9)
    limit = f" (limit {result.pressure_angle_limit.value:g}°"
    limit += f"; {result.pressure_angle_flank} flank drives)" if result.pressure_angle_flank else ")"
    assert rows["max pressure angle"] == shown(result.max_pressure_angle, 2, "°") + limit
    assert rows["min curvature radius"] == shown(result.min_curvature_radius, 3, " mm")
    assert rows["min concave radius"] == shown(result.min_concave_radius, 3, " mm")
    assert rows["undercut"] == yes_no(result.undercut)
    assert rows["max torque"] == shown(result.max_torque, 1, " N·mm")
    assert rows["max contact force"] == shown(result.max_contact_force, 2, " N")
    assert rows["min contact force"] == shown(result.min_contact_force, 2, " N")
    flank = f" ({result.contact_stress_flank} flank)" if result.contact_stress_flank else ""
    assert rows["max contact stress"] == shown(result.max_contact_stress, 1, " MPa") + flank
    jump = "none (positive drive)" if result.follower_jump is None else yes_no(result.follower_jump)
    assert rows["follower jump"] == jump
    fit = rows["fit control points"]
    assert fit == f"{result.fit_control_points} (max error {result.fit_max_error.value * 1000:.3f} µm)"
    # every limit the API finds, the check finds too (the check also plans the toolpath: gouge)
    # (a note is no limit)
    assert {f.message for f in result.findings if f.severity.value != "note"} <= set(limits)
    assert (code == 0) == (not limits)


def test_a_full_analysis_has_the_checks_findings_and_verdict(capsys):
    path = ROOT / "samples" / "quintero_harmonic.toml"
    result = camcad.load(path).analyse()
    code, _, limits = check_table(path, capsys)
    assert [f.message for f in result.findings] == limits
    assert result.ok == (code == 0)


def test_extremes_are_at_least_the_sampled_curves(offset):
    """The figures are true extremes: never below the largest sample of the curves (independent arrays)."""
    result = offset
    tol = 1e-9
    assert result.max_pressure_angle.value >= math.degrees(np.abs(result.pressure_angle).max()) - tol
    assert result.max_contact_force.value >= result.contact_force.max() - tol
    assert result.min_contact_force.value <= result.contact_force.min() + tol
    assert result.max_contact_stress.value >= result.contact_stress.max() - tol
    assert result.max_torque.value >= result.torque.max() - tol
    convex = result.rho[result.rho > 0]
    assert result.min_curvature_radius.value <= convex.min() + tol


def test_curves_are_read_only_and_the_profile_is_the_offset_pitch_curve(offset):
    result = offset
    n = result.phi.shape
    for name in ("angle_deg", "s", "v", "a", "j", "x", "y", "pitch_x", "pitch_y", "pressure_angle", "rho"):
        values = getattr(result, name)
        assert values.shape == n and values.dtype == np.float64 and not values.flags.writeable, name
    for name in ("contact_force", "torque", "contact_stress"):
        assert getattr(result, name).shape == n
    # a roller's profile lies one roller radius from the pitch curve, everywhere
    gap = np.hypot(result.x - result.pitch_x, result.y - result.pitch_y)
    np.testing.assert_allclose(gap, 15.0, atol=1e-9)
    # the lift is the largest s (a rise from the base circle)
    assert math.isclose(result.s.max(), result.lift.value, rel_tol=1e-9)


def test_load_takes_toml_text_as_well_as_a_path():
    text = OFFSET.read_text(encoding="utf-8")
    from_text, from_path = camcad.load(text), camcad.load(OFFSET)
    assert from_text.source == "" and from_path.source == str(OFFSET)
    assert from_text.data == from_path.data
    assert from_text.spec.cam == from_path.spec.cam and from_text.spec.motion == from_path.spec.motion
    with pytest.raises(camcad.DesignError, match="not valid TOML"):
        camcad.load("[cam\nbase_radius = 3\n")


@pytest.mark.parametrize(
    ("key", "value", "old", "new"),
    [
        ("cam.base_radius", -5, "base_radius = 80.0", "base_radius = -5"),
        ("cam.base_radus", 40, "base_radius = 80.0", "base_radius = 80.0\nbase_radus = 40"),
        ("motion[1].angle", 0, "angle = 60.0", "angle = 0"),
        ("follower.type", "sliding", 'type = "translating-roller"', 'type = "sliding"'),
    ],
    ids=["bound", "unknown-key", "motion", "enum"],
)
def test_replace_refuses_a_bad_value_with_the_loaders_message(tmp_path, key, value, old, new):
    design = camcad.load(OFFSET)
    with pytest.raises(camcad.DesignError) as from_api:
        design.replace(**{key: value})
    edited = tmp_path / "edited.toml"
    edited.write_text(OFFSET.read_text(encoding="utf-8").replace(old, new, 1), encoding="utf-8")
    with pytest.raises(camcad.DesignError) as from_file:
        camcad.load_design(edited)
    assert str(from_api.value) == str(from_file.value)
    assert str(from_api.value).startswith(key.split(".")[0])


def test_replace_gives_the_design_the_edited_file_gives(tmp_path):
    design = camcad.load(OFFSET)
    variant = design.replace(**{"cam.base_radius": 95.5, "dynamics.spring_rate": 3.0})
    edited = tmp_path / "edited.toml"
    text = OFFSET.read_text(encoding="utf-8").replace("base_radius = 80.0", "base_radius = 95.5", 1)
    edited.write_text(text.replace("spring_rate = 2.0", "spring_rate = 3.0", 1), encoding="utf-8")
    spec = camcad.load_design(edited)
    assert variant.spec.cam == spec.cam and variant.spec.dynamics == spec.dynamics
    assert design.spec.cam.base_radius == 80.0  # the original is unchanged
    assert design.replace(**{"cam.bore": None}).spec.cam.bore == 0.0  # None: back to the default


def test_result_build_writes_the_bytes_camcad_build_writes(tmp_path, offset):
    api_out, cli_out = tmp_path / "api", tmp_path / "cli"
    built = offset.build(api_out, only=["tables", "dxf", "step"])
    run = cli("build", str(OFFSET), "-o", str(cli_out), "--only", "tables,dxf,step", "-q")
    assert run.returncode == 0, run.stderr
    names = sorted(p.name for p in cli_out.iterdir())
    assert sorted(p.name for p in api_out.iterdir()) == names == sorted(p.name for p in built.files)
    assert "cam.step" in names and "profile.dxf" in names
    for name in names:
        assert (api_out / name).read_bytes() == (cli_out / name).read_bytes(), name


def test_sweep_writes_the_table_camcad_sweep_writes(tmp_path):
    grid = "base_radius=70:90:3"
    table = camcad.sweep(camcad.load(OFFSET), tmp_path / "api", grid=[grid], fmt="csv")
    out = str(tmp_path / "c")
    run = cli("sweep", str(OFFSET), "--grid", grid, "--format", "csv", "--jobs", "1", "-q", "-o", out)
    assert run.returncode == 0, run.stderr
    assert (tmp_path / "api" / "sweep.csv").read_bytes() == (tmp_path / "c" / "sweep.csv").read_bytes()
    assert [row["base_radius"] for row in table.rows] == [70.0, 80.0, 90.0]


def test_optimize_finds_the_smallest_base_radius_camcad_size_finds():
    """One variable, one limit: the optimum is where the pressure angle meets its limit (``camcad size``)."""
    design = camcad.load(OFFSET)
    found = camcad.optimize(design, minimize="base_radius", vary=["base_radius=40:120"])
    run = cli("size", str(OFFSET))
    assert run.returncode == 0, run.stderr
    sized = float(re.search(r"smallest base radius: ([\d.]+) mm", run.stdout).group(1))
    assert found.best is not None and found.best.feasible
    assert math.isclose(found.best.values["base_radius"], sized, abs_tol=2e-3)


def test_the_jupyter_renderings_are_well_formed(offset):
    design, result = offset.design, offset
    card = etree.fromstring(result._repr_html_())
    text = "".join(card.itertext())
    assert f"{result.max_pressure_angle.value:.2f}°" in text and "all design limits hold" in text
    page = etree.fromstring(design._repr_html_())
    assert design.name in "".join(page.itertext())
    for svg in (result._repr_svg_(), design._repr_svg_()):
        root = etree.fromstring(svg.encode("utf-8"))
        assert root.tag == "{http://www.w3.org/2000/svg}svg"


def test_plot_draws_each_kind_and_refuses_others(offset):
    result = offset
    for kind, panels in (("motion", 4), ("profile", 1), ("pressure", 1), ("dynamics", 3)):
        figure = result.plot(kind)
        assert len(figure.axes) == panels, kind
    line = result.plot("profile").axes[0].lines[0]
    np.testing.assert_array_equal(line.get_xdata()[:-1], result.x)
    with pytest.raises(camcad.UsageError, match="allowed: motion, profile"):
        result.plot("torque")
