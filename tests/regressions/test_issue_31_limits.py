"""Issue 31, "size, check and optimize agree on one limit set", with every plate and flank held to it.

- conjugate pair with a smaller second roller: the second plate's Hertz stress
  binds; the optimizer's optimum sits where that stress meets the limit, found
  here by a root search on the analysis' own second-plate figure (brentq),
  and it passes ``camcad check``;
- groove driven on its outer flank: the sweep's ``contact_stress`` is the
  outer flank's 132.73 MPa the issue's independent recomputation found, its
  ``contact_force`` the largest load |F| over a dense scan of the force, and
  each row's verdict is ``check``'s;
- the curvature limit (``cam.min_curvature_radius``) by property, over base
  radii and required radii on flat and roller followers, translating and on
  arms: ``size``'s answer passes ``check``'s geometry limits, a radius just
  below it fails them, and ``optimize`` calls a design feasible exactly when
  ``check`` finds nothing broken.
"""

from __future__ import annotations

import copy
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import tomllib
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from camcad.cli import main
from camcad.design import parse_design
from camcad.design.toml_text import toml_text
from camcad.explore.measures import MEASURES, measure_values, parse_limit
from camcad.explore.optimize import Problem, _candidate, _Evaluator, design_limits, optimize
from camcad.explore.space import parse_variable
from camcad.geometry import Cam, min_base_radius
from camcad.pipeline import analyse
from tests.conftest import ROOT

# the kinds of finding the geometry limits `camcad size` sizes for raise in `camcad check`
_SIZED = {"pressure angle", "curvature", "undercut", "cusp"}


def _data(name: str, **tables: dict[str, Any]) -> dict[str, Any]:
    data = tomllib.loads((ROOT / "samples" / name).read_text())
    for key, value in tables.items():
        data.setdefault(key, {}).update(value)
    return data


def _check(data: dict[str, Any]) -> Any:
    """What `camcad check` finds (its analysis without the fit, which no limit here depends on)."""
    return analyse(parse_design(data), fit=False, toolpath=False, strict=False)


# -- conjugate pair: the second plate binds --------------------------------------------------------------

_ALLOWABLE = 101.0  # MPa: plate 1 stays near 80 MPa; plate 2 (8 mm roller) crosses 101 MPa near r_b 47 mm


def _conjugate(base_radius: float | None = None) -> dict[str, Any]:
    data = _data(
        "indexing_conjugate.toml", conjugate={"roller_radius": 8.0}, dynamics={"allowable_stress": _ALLOWABLE}
    )
    if base_radius is not None:
        data["cam"]["base_radius"] = base_radius
    return data


def test_optimum_of_a_conjugate_pair_meets_the_second_plates_stress_limit(tmp_path: Path) -> None:
    """Minimise the pressure angle over r_b: the second plate's stress stops it, where brentq says."""
    data = _conjugate()
    variables = (parse_variable("base_radius=40:62", data, flag="--vary", counted=False),)
    best = optimize(Problem(data=data, variables=variables, objectives=(MEASURES["pressure_angle"],))).best
    assert best is not None and best.feasible
    r_opt = best.values["base_radius"]

    def plate2_excess(r: float) -> float:
        return float(_check(_conjugate(r)).summary()["second_plate"]["dynamics"]["hertz_stress_max_MPa"]) - (
            _ALLOWABLE
        )

    root = brentq(plate2_excess, 42.0, 52.0, xtol=1e-6)
    assert r_opt == pytest.approx(root, abs=1e-3)
    assert "contact_stress<=101" in best.active
    # the optimum's file, typed back, passes check; its second plate carries the binding stress
    path = tmp_path / "optimum.toml"
    path.write_text(toml_text(best.data))
    assert main(["check", str(path)]) == 0
    summary = _check(best.data).summary()
    plate2 = summary["second_plate"]["dynamics"]["hertz_stress_max_MPa"]
    assert plate2 <= _ALLOWABLE and plate2 == pytest.approx(_ALLOWABLE, rel=1e-4)
    assert summary["dynamics"]["hertz_stress_max_MPa"] < 85.0  # the first plate alone would not have bound
    # the measure is the worse plate's, both plates' pressure angles held
    assert best.measures["contact_stress_MPa"] == pytest.approx(plate2, rel=1e-12)
    assert best.measures["pressure_angle_deg"] == pytest.approx(
        max(
            summary["geometry"]["pressure_angle_max_deg"],
            summary["second_plate"]["geometry"]["pressure_angle_max_deg"],
        )
    )


def test_a_conjugate_designs_stress_limit_fails_where_check_fails() -> None:
    """At r_b = 55 mm only the second plate breaks 101 MPa: the limit fails and check fails too."""
    analysis = _check(_conjugate(55.0))
    values = measure_values(analysis)
    assert not parse_limit("contact_stress<=101").holds(values)
    assert analysis.summary()["dynamics"]["hertz_stress_max_MPa"] < _ALLOWABLE  # plate 1 alone holds
    assert any(
        f.message.startswith("second plate:") and f.kind == "contact stress" for f in analysis.findings
    )


# -- groove driven on its outer flank --------------------------------------------------------------------


def _groove(preload: float, base_radius: float = 52.0) -> dict[str, Any]:
    data = _data(
        "groove_rocker.toml", dynamics={"spring_preload_torsional": preload, "allowable_stress": 100.0}
    )
    data["cam"]["base_radius"] = base_radius
    return data


@pytest.mark.parametrize("preload", [-5000.0, -2000.0, -1000.0])
def test_groove_measures_are_the_driving_flanks(preload: float) -> None:
    """contact_stress and contact_force over both flanks; each limit's verdict is check's."""
    analysis = _check(_groove(preload))
    values = measure_values(analysis)
    force = np.asarray(analysis.dynamics.contact_force)
    # the largest load on either flank: |F| on the samples, refined by the exact extremes (≥ the samples)
    assert values["contact_force_N"] >= float(np.max(np.abs(force))) - 1e-9
    assert values["contact_force_N"] == pytest.approx(float(np.max(np.abs(force))), rel=1e-4)
    assert values["contact_stress_MPa"] >= float(np.max(analysis.dynamics.hertz_stress)) - 1e-9
    stress_finding = any(f.kind == "contact stress" for f in analysis.findings)
    assert parse_limit("contact_stress<=100").holds(values) is not stress_finding
    if preload == -5000.0:
        # issue 31's independent recomputation: the outer flank's conformal contact, 132.73 MPa at 214.89°
        assert values["contact_stress_MPa"] == pytest.approx(132.73, abs=0.01)
        assert values["contact_force_N"] > 60.0 > -analysis.summary()["dynamics"]["contact_force_max_N"]


def test_groove_sweep_rows_agree_with_check(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """A sweep over the preload with a stress limit: a row is feasible exactly when check passes."""
    src = tmp_path / "groove.toml"
    src.write_text(toml_text(_groove(-5000.0)))
    out = tmp_path / "sweep"
    code = main(
        [
            "sweep",
            str(src),
            "--grid",
            "spring_preload_torsional=-5000,-1000",
            "--limit",
            "contact_stress<=100",
            "--format",
            "csv",
            "-o",
            str(out),
        ]
    )
    assert code == 0
    import csv

    rows = list(csv.DictReader((out / "sweep.csv").open()))
    for row in rows:
        passed = not _check(_groove(float(row["spring_preload_torsional"]))).findings
        assert (row["feasible"].lower() == "true") is passed
    assert [r["feasible"].lower() for r in rows] == ["false", "true"]
    capsys.readouterr()


# -- the curvature limit: one rule for size, check and optimize ------------------------------------------

# flat faces (a translating tappet, one on an arm) and rollers (translating, on an arm)
_SAMPLES = ("hren_tappet.toml", "rocker_flat.toml", "quintero_harmonic.toml", "packaging_rocker.toml")


def _with(name: str, **cam: Any) -> dict[str, Any]:
    """The sample on a 1° grid (every extreme is refined on the exact curves: the grid only seeds it),
    without its bore and keyway (the schema would refuse a small base circle for them, not a limit)."""
    data = _data(name)
    for key in ("bore", "keyway_width", "keyway_depth"):
        data["cam"].pop(key, None)
    data["cam"].update({"sample_step_deg": 1.0, **cam})
    return data


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    name=st.sampled_from(_SAMPLES),
    required=st.sampled_from([None, 0.0, 2.5, 8.0]),
    alpha=st.floats(min_value=20.0, max_value=60.0),
)
def test_size_answer_passes_check_and_just_below_fails(
    name: str, required: float | None, alpha: float
) -> None:
    extra: dict[str, Any] = {"max_pressure_angle": alpha}
    if required is not None:
        extra["min_curvature_radius"] = required
    data = _with(name, **extra)
    design = parse_design(data)
    sized = min_base_radius(
        Cam.from_design(design),
        max_pressure_angle=design.cam.max_pressure_angle,
        min_curvature_radius=design.min_curvature_radius,
    )
    assume(sized.base_radius - 1e-6 >= 0.1)  # the schema's smallest base radius
    at = _check(_with(name, base_radius=sized.base_radius, **extra))
    assert not {f.kind for f in at.findings} & _SIZED, [f.message for f in at.findings]
    below = _check(_with(name, base_radius=sized.base_radius - 1e-6, **extra))
    assert {f.kind for f in below.findings} & _SIZED


def _optimizer_verdict(data: dict[str, Any], base_radius: float) -> bool:
    """Whether camcad optimize calls the design at ``base_radius`` feasible (its evaluator, no search)."""
    variables = (parse_variable("base_radius=1:500", data, flag="--vary", counted=False),)
    problem = Problem(data=data, variables=variables, objectives=(MEASURES["base_radius"],))
    limits = design_limits(data, ())
    ev = _Evaluator(problem, (), limits)
    return _candidate(
        ev, np.zeros(1), problem.objectives, "", limits=limits, physical=(base_radius,)
    ).feasible


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    name=st.sampled_from(_SAMPLES),
    required=st.sampled_from([None, 3.0]),
    scale=st.floats(min_value=0.8, max_value=1.25),
)
def test_optimize_feasible_exactly_when_check_passes(name: str, required: float | None, scale: float) -> None:
    """Across size's answer (r_b from 0.8 to 1.25 of it): optimize's verdict is check's, both ways."""
    extra: dict[str, Any] = {} if required is None else {"min_curvature_radius": required}
    data = _with(name, **extra)
    design = parse_design(data)
    sized = min_base_radius(
        Cam.from_design(design),
        max_pressure_angle=design.cam.max_pressure_angle,
        min_curvature_radius=design.min_curvature_radius,
    )
    radius = max(sized.base_radius * scale, 0.1)
    try:
        found = _check(_with(name, base_radius=radius, **extra)).findings
    except Exception:  # an arm that cannot reach the base circle: neither may call it feasible
        found = ("invalid",)
    assert _optimizer_verdict(copy.deepcopy(data), radius) is (not found)


def test_check_enforces_the_stated_min_curvature_radius(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A flat tappet with ρ_min ≈ 1 mm against a stated 3 mm: a soft limit (check exit 3, build warns)."""
    data = _with("hren_tappet.toml", min_curvature_radius=3.0)
    design = parse_design(data)
    sized = min_base_radius(Cam.from_design(design), min_curvature_radius=3.0)
    data["cam"]["base_radius"] = sized.base_radius - 2.0  # ρ_min ≈ 1 mm: no cusp, under 3 mm
    path = tmp_path / "tappet.toml"
    path.write_text(toml_text(data))
    assert main(["check", str(path)]) == 3
    out = capsys.readouterr().out
    assert "soft limit: cam.min_curvature_radius:" in out
    assert f"base_radius ≥ {math.ceil(sized.base_radius * 100) / 100:.2f} mm" in out
    assert main(["build", str(path), "-o", str(tmp_path / "out")]) == 0
    assert (tmp_path / "out" / "summary.json").exists()
    assert main(["build", "--strict", str(path), "-o", str(tmp_path / "strict")]) == 3
