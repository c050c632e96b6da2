"""Issue 31, "Wrong figures": each figure against a computation of its own.

- groove: the Hertz stress where the outer flank drives, from the flank's own
  curvature (the groove geometry) and a force from the arm's equation of
  motion, with Johnson's line-contact formula written out here;
- conjugate pair: the second plate's stress with the second roller's radius;
- cusp: the signed smallest radius against a dense sampling of the profile;
- stroke: max − min of s on 10⁶ angles, refined where ds/dφ = 0 (brentq);
- units: an arm's joint texts in degrees;
- positive drive: no jump figures in its summary.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import tomllib
from scipy.optimize import brentq, minimize_scalar

from camcad.cli import main
from camcad.design import parse_design
from camcad.geometry.groove import groove_flanks
from camcad.pipeline import analyse
from camcad.report import key_numbers_html
from tests.conftest import ROOT


def _sample(name: str, **tables: dict[str, Any]) -> tuple[Any, dict[str, Any]]:
    data = tomllib.loads((ROOT / "samples" / name).read_text())
    for key, value in tables.items():
        data.setdefault(key, {}).update(value)
    return parse_design(data, source=name), data


def _contact_modulus(e1: float, nu1: float, e2: float, nu2: float) -> float:
    return 1.0 / ((1.0 - nu1**2) / e1 + (1.0 - nu2**2) / e2)


def _line_contact(force: float, inv_radius: float, length: float, modulus: float) -> float:
    """p0 = √(F·E*/(π·L·R*)), Johnson 1985 eq. 4.45, with 1/R* given."""
    return math.sqrt(force * modulus * inv_radius / (math.pi * length))  # Johnson 1985, eq. 4.45


def test_groove_outer_flank_stress_where_it_drives() -> None:
    design, _ = _sample(
        "groove_rocker.toml", dynamics={"spring_preload_torsional": -5000.0, "allowable_stress": 100.0}
    )
    result = analyse(design, fit=False, toolpath=False)
    cam, c, r_f = result.cam, design.groove.clearance, design.follower.roller_radius
    omega, inertia, m0 = design.cam.omega, 8000.0, -5000.0
    e_star = _contact_modulus(206000.0, 0.3, 206000.0, 0.3)

    def stress(phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(σ on the driving flank, signed force): M = I·ψ″·ω²/1000 + M0 about the pivot, F = M/(r cos α)."""
        st = cam.state(phi)
        moment = inertia * np.radians(st.motion.a) * omega**2 / 1000.0 + m0
        force = moment / (st.lever * np.cos(st.pressure_angle))
        inner, outer = groove_flanks(cam, phi, c)
        # the roller outside the inner flank, or inside the outer flank (conformal)
        inv = np.where(force >= 0.0, 1.0 / r_f + 1.0 / inner.rho, 1.0 / r_f - 1.0 / outer.rho)
        return np.sqrt(np.abs(force) * e_star * inv / (math.pi * 10.0)), force  # Johnson 1985 eq. 4.45

    dyn = result.summary()["dynamics"]
    at = np.radians([dyn["hertz_stress_max_angle_deg"]])
    sigma, f = stress(at)
    expected, force = float(sigma[0]), float(f[0])
    assert force < 0.0 and dyn["hertz_stress_max_flank"] == "outer"
    assert dyn["hertz_stress_max_MPa"] == pytest.approx(expected, rel=1e-9)
    assert dyn["hertz_stress_max_MPa"] == pytest.approx(132.73, abs=0.005)
    # the true maximum: a dense scan refined by bounded minimisation
    grid = np.radians(np.arange(0.0, 360.0, 0.05))
    i = int(np.argmax(stress(grid)[0]))
    best = minimize_scalar(
        lambda p: -float(stress(np.array([p]))[0][0]),
        bounds=(grid[i - 1], grid[i + 1]),
        method="bounded",
        options={"xatol": 1e-12},
    )
    assert dyn["hertz_stress_max_MPa"] == pytest.approx(-best.fun, rel=1e-8)
    assert dyn["flanks"]["inner"]["contact_force_max_N"] is None  # it never drives here
    assert dyn["flanks"]["outer"]["contact_force_max_N"] == pytest.approx(
        -dyn["contact_force_min_N"], rel=1e-12
    )
    (found,) = [f for f in result.findings if f.kind == "contact stress"]
    assert "outer flank" in found.message and found.value == pytest.approx(expected, rel=1e-9)
    cards = key_numbers_html(result)  # the report's and the designer's cards
    assert "on the outer flank" in cards and f"{dyn['flanks']['outer']['contact_force_max_N']:.3f} N" in cards


def test_groove_pressure_angle_names_the_flank_that_drives() -> None:
    # no spring: the arm's moment I·ψ″·ω² has the sign of ψ″; positive: the inner flank pushes
    design, _ = _sample("groove_rocker.toml")
    result = analyse(design, fit=False, toolpath=False)
    summary = result.summary()
    at = math.radians(summary["geometry"]["pressure_angle_max_angle_deg"])
    a = float(result.cam.motion(np.array([at])).a[0])
    assert summary["groove"]["pressure_angle_max_flank"] == ("inner" if a > 0.0 else "outer")


def test_groove_check_names_the_flank(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    text = (ROOT / "samples" / "groove_rocker.toml").read_text()
    text = text.replace(
        "[dynamics]\n", "[dynamics]\nspring_preload_torsional = -5000.0\nallowable_stress = 100.0\n"
    )
    path = tmp_path / "g.toml"
    path.write_text(text)
    assert main(["check", str(path)]) == 3
    out = capsys.readouterr().out
    assert "132.7 MPa at 214.9° (outer flank)" in out
    assert "inner flank max load   does not drive" in out


@pytest.mark.parametrize("r2", [14.0, 8.0])
def test_conjugate_second_plate_stress_uses_its_own_roller(r2: float) -> None:
    design, _ = _sample("indexing_conjugate.toml", conjugate={"roller_radius": r2})
    result = analyse(design, fit=False, toolpath=False)
    second = result.parts[1]  # the pair's second plate, with its own roller
    dyn = second.dynamics
    e_star = _contact_modulus(206000.0, 0.3, 206000.0, 0.3)
    ext = dyn.hertz_stress_max
    assert ext is not None
    st = second.part.cam.state(np.array([ext.phi]))
    force = float(np.interp(ext.phi, dyn.phi, dyn.contact_force))
    inv = 1.0 / r2 + 1.0 / float(st.profile.rho[0])  # the second roller on the second plate
    assert ext.value == pytest.approx(_line_contact(force, inv, 12.0, e_star), rel=1e-4)
    summary = result.summary()["second_plate"]["dynamics"]
    assert summary["hertz_stress_max_MPa"] == ext.value


def test_a_smaller_second_roller_raises_the_second_plate_stress() -> None:
    big, small = (
        analyse(
            _sample("indexing_conjugate.toml", conjugate={"roller_radius": r})[0], fit=False, toolpath=False
        )
        for r in (14.0, 8.0)
    )
    ratio = (
        small.summary()["second_plate"]["dynamics"]["hertz_stress_max_MPa"]
        / (big.summary()["second_plate"]["dynamics"]["hertz_stress_max_MPa"])
    )
    assert 1.2 < ratio < 1.4  # about a third more, as σ ∝ √(1/R*)
    # the first plate does not change
    assert small.dynamics.hertz_stress_max.value == pytest.approx(
        big.dynamics.hertz_stress_max.value, rel=1e-12
    )


def test_cusp_prints_the_true_signed_radius(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    design, _ = _sample("rocker_flat.toml", cam={"base_radius": 20.0})
    result = analyse(design, fit=False, toolpath=False, strict=False)
    geo = result.summary()["geometry"]
    cam = result.cam
    grid = np.radians(np.arange(0.0, 360.0, 0.01))
    rho = cam.state(grid).profile.rho
    i = int(np.argmin(rho))
    best = minimize_scalar(
        lambda p: float(cam.state(np.array([p])).profile.rho[0]),
        bounds=(grid[i - 1], grid[i + 1]),
        method="bounded",
    )
    assert best.fun < -13.0
    assert geo["curvature_radius_min_mm"] == pytest.approx(best.fun, abs=1e-8)
    assert geo["concave_radius_min_mm"] is None  # a flat face has no concave part: that is the cusp
    (cusp,) = [f for f in result.findings if f.kind == "cusp"]
    assert cusp.value == pytest.approx(geo["curvature_radius_min_mm"], abs=1e-12)
    assert f"{best.fun:.3f} mm" in key_numbers_html(result)  # the designer's and the report's card
    text = (
        (ROOT / "samples" / "rocker_flat.toml")
        .read_text()
        .replace("base_radius = 45.0", "base_radius = 20.0")
    )
    path = tmp_path / "cusp.toml"
    path.write_text(text)
    main(["check", str(path)])
    assert f"min curvature radius  {best.fun:.3f} mm" in capsys.readouterr().out


def test_true_stroke_of_the_web_cutter(capsys: pytest.CaptureFixture[str]) -> None:
    design, _ = _sample("web_cutter.toml")
    result = analyse(design, fit=False, toolpath=False)
    motion = result.summary()["motion"]
    cam = result.cam
    phi = np.linspace(0.0, 2.0 * math.pi, 1_000_001)
    s = cam.motion(phi).s

    def v(p: float) -> float:
        return float(cam.motion(np.array([p])).v[0])

    def refined(k: int) -> float:  # the extreme between the neighbours of sample k, where ds/dφ = 0
        lo, hi = phi[max(k - 1, 0)], phi[min(k + 1, phi.size - 1)]
        if v(lo) * v(hi) >= 0.0:  # a dwell: the sample is the extreme
            return float(s[k])
        return float(cam.motion(np.array([brentq(v, lo, hi, xtol=1e-14)])).s[0])

    top, bottom = refined(int(np.argmax(s))), refined(int(np.argmin(s)))
    assert motion["lift_mm"] == pytest.approx(53.333, abs=1e-3)
    assert motion["travel_max_mm"] == pytest.approx(top, abs=1e-9)
    assert motion["stroke_mm"] == pytest.approx(top - bottom, abs=1e-9)
    assert motion["stroke_mm"] == pytest.approx(63.71, abs=0.005)
    assert motion["travel_max_angle_deg"] == pytest.approx(206.5, abs=0.05)
    (found,) = [f for f in result.findings if f.field == "motion[3].lift"]
    assert not found.hard and "runs forwards" in found.message
    assert main(["check", str(ROOT / "samples" / "web_cutter.toml")]) == 3
    out = capsys.readouterr().out
    assert "53.333 mm (true stroke 63.707 mm" in out


def test_an_arms_texts_are_in_degrees() -> None:
    for name in (
        "groove_rocker.toml",
        "packaging_rocker.toml",
        "rocker_flat.toml",
        "indexing_conjugate.toml",
    ):
        design, _ = _sample(name)
        summary = analyse(design, fit=False, toolpath=False, strict=False).summary()
        texts = [j["text"] for j in summary["motion"]["joints"]] + [f["message"] for f in summary["findings"]]
        assert not [t for t in texts if "mm/rad" in t], name
        jumps = [t for t in texts if "jerk jumps by" in t]
        assert jumps and all(t.endswith("°/rad³") for t in jumps), name


def test_positive_drive_carries_no_jump_figures() -> None:
    for name in ("groove_rocker.toml", "indexing_conjugate.toml"):
        design, _ = _sample(name)
        summary = analyse(design, fit=False, toolpath=False).summary()
        for section in (summary["dynamics"], summary.get("second_plate", {}).get("dynamics", {})):
            assert not {"min_preload_N", "min_preload_N_mm", "speed_range_rpm"} & set(section), name
    design, _ = _sample("offset_roller.toml")
    assert {"min_preload_N", "speed_range_rpm"} <= set(
        analyse(design, fit=False, toolpath=False).summary()["dynamics"]
    )


def test_a_massless_follower_has_no_impact_figure() -> None:
    # M = k_t·ψ + M0 changes sign at ψ = 10°: crossovers, but no free flight without inertia
    design, _ = _sample(
        "groove_rocker.toml",
        dynamics={"arm_inertia": 0.0, "spring_rate_torsional": 1000.0, "spring_preload_torsional": -174.5},
    )
    result = analyse(design, fit=False, toolpath=False)
    dyn = result.summary()["dynamics"]
    assert len(dyn["crossover_angles_deg"]) == 2
    assert dyn["impact_speed_max_mm_per_s"] is None


def test_comparing_arms_labels_degrees() -> None:
    from camcad._plots.compare import compare_plots
    from camcad.report import compare_table

    arms = [
        analyse(_sample(n)[0], fit=False, toolpath=False) for n in ("groove_rocker.toml", "rocker_flat.toml")
    ]
    rows = {r[0] for r in compare_table(arms)}
    assert {"lift [°]", "max |v| [°/rad]", "max |a| [°/rad²]"} <= rows
    assert not [r for r in rows if r.startswith(("lift", "max |v|", "max |a|")) and "mm" in r]
    plots = compare_plots(arms, ["A", "B"])
    labels = " ".join(str(p.svg, "utf-8") for p in plots if p.key in ("compare-s", "compare-v"))
    assert "[°/rad]" in labels and "[mm/rad]" not in labels
