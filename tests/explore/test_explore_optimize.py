"""camcad optimize against brute force: 002's problem, `camcad size`, closed forms, a grid of analyses."""

from __future__ import annotations

import json
import math
import re
import time

import numpy as np
import pytest
import tomllib

from camcad.cli import main
from camcad.design import load_design
from camcad.design.toml_text import toml_text
from camcad.errors import UsageError
from camcad.explore.measures import MEASURES, parse_limit
from camcad.explore.optimize import Problem, optimize
from camcad.explore.space import parse_variable
from camcad.geometry import Cam, min_base_radius
from camcad.motion.program import MotionProgram
from camcad.pipeline import analyse
from tests.conftest import ROOT
from tests.explore.cases import (
    motion_sv,
    peak_pressure_angle_002,
    peak_pressure_angles_002,
    sample_data,
    smallest_base_radius_002,
)

R_F = 15.0  # 002: roller radius [mm]
ALPHA = 25.0  # 002: permitted pressure angle [deg]


def _vary(data, *texts):
    return tuple(parse_variable(t, data, flag="--vary", counted=False) for t in texts)


@pytest.fixture(scope="module")
def case_002():
    """002's problem on the shipped sample: smallest r_b over (r_b, e) under 25° and 1500 MPa."""
    data = sample_data("offset_roller")
    problem = Problem(
        data=data,
        variables=_vary(data, "base_radius=20:120", "offset=0:40"),  # 002 constraint 3: e ≥ 0
        objectives=(MEASURES["base_radius"],),
    )
    return optimize(problem)


def test_002_optimum_equals_brute_force_grid(case_002):
    """The optimum against a brute-force grid over the offset (step 0.01 mm), r_b from 002 eq. 4 at each e."""
    s, v = motion_sv("offset_roller")
    step = 0.01
    grid = np.arange(0.0, 40.0 + step / 2, step)
    radii = np.array([smallest_base_radius_002(s, v, e=e, r_f=R_F, alpha_deg=ALPHA) for e in grid])
    i = int(np.argmin(radii))
    best = case_002.best
    assert best is not None and best.feasible
    r_b, e = best.values["base_radius"], best.values["offset"]
    # the grid's best is an upper bound of the true optimum; within one grid step of e it cannot be beaten by
    # more than the slope of r_b(e) times the step (< 3 mm/mm here)
    assert radii[i] - 3.0 * step <= r_b <= radii[i] + 1e-5
    assert abs(e - grid[i]) <= step
    assert r_b == pytest.approx(23.42, abs=0.01)  # the number docs/guides/optimization.md quotes


def test_002_optimum_is_limited_by_both_sides_of_the_pressure_angle(case_002):
    """At the smallest cam rise and return both reach 25° (002 eq. 4 on 72 001 angles); stress is slack."""
    best = case_002.best
    s, v = motion_sv("offset_roller")
    k = math.sqrt((best.values["base_radius"] + R_F) ** 2 - best.values["offset"] ** 2)
    alpha = np.degrees(np.arctan2(v - best.values["offset"], s + k))
    assert alpha.max() == pytest.approx(ALPHA, abs=1e-4)
    assert -alpha.min() == pytest.approx(ALPHA, abs=1e-4)
    assert set(best.active) == {"pressure_angle<=25 (max α)", "pressure_angle<=25 (−min α)"}
    stress = next(c for c in best.constraints if c.name.startswith("contact_stress"))
    assert stress.limit == 1500.0 and not stress.active and stress.value < 1500.0


def test_trust_constr_finds_the_same_optimum(case_002):
    """A second method (scipy's trust-constr) agrees with SLSQP."""
    data = sample_data("offset_roller")
    problem = Problem(
        data=data,
        variables=_vary(data, "base_radius=20:120", "offset=0:40"),
        objectives=(MEASURES["base_radius"],),
        method="trust-constr",
    )
    other = optimize(problem).best
    assert other.feasible
    assert other.values["base_radius"] == pytest.approx(case_002.best.values["base_radius"], abs=5e-3)
    assert other.values["offset"] == pytest.approx(case_002.best.values["offset"], abs=5e-2)


@pytest.mark.parametrize("name", ["offset_roller", "quintero_vap_b01", "hren_tappet"])
def test_base_radius_alone_equals_camcad_size(name):
    """Against `camcad size` (bracket + regula falsi): pressure-angle, undercut and cusp limited samples."""
    data = sample_data(name)
    problem = Problem(
        data=data,
        variables=_vary(data, "base_radius=5:150"),
        objectives=(MEASURES["base_radius"],),
        limits=(parse_limit("contact_stress<=1e7"),),  # size knows no stress limit
    )
    best = optimize(problem).best
    design = load_design(ROOT / "samples" / f"{name}.toml")
    sized = min_base_radius(
        Cam.from_design(design),
        max_pressure_angle=design.cam.max_pressure_angle,
        min_curvature_radius=design.min_curvature_radius,
    )
    assert best.feasible
    assert best.values["base_radius"] == pytest.approx(sized.base_radius, abs=2e-3)


def test_offset_roller_base_radius_equals_002_closed_form():
    """The offset sample (e = 20 fixed): r_b = √(k_min² + e²) − r_f with k_min from 002 eq. 4."""
    data = sample_data("offset_roller")
    best = optimize(
        Problem(data=data, variables=_vary(data, "base_radius=20:150"), objectives=(MEASURES["base_radius"],))
    ).best
    s, v = motion_sv("offset_roller")
    assert best.values["base_radius"] == pytest.approx(
        smallest_base_radius_002(s, v, e=20.0, r_f=R_F, alpha_deg=ALPHA), abs=1e-3
    )


def test_flat_tappet_base_radius_equals_cusp_closed_form():
    """hren_tappet (flat face): r_b = ρ_min − min(s + a) on 10⁵ angles, ρ_min = 1 mm (flat-face default)."""
    data = sample_data("hren_tappet")
    best = optimize(
        Problem(data=data, variables=_vary(data, "base_radius=5:150"), objectives=(MEASURES["base_radius"],))
    ).best
    design = load_design(ROOT / "samples" / "hren_tappet.toml")
    program = MotionProgram.from_segments(design.motion)
    phi = np.linspace(0.0, 2 * math.pi, 100_001)
    joints = np.array([bp.phi for bp in program.breakpoints])
    left, right = program.evaluate(joints, side="left"), program.evaluate(joints, side="right")
    m = program.evaluate(phi)
    lowest = min(np.min(m.s + m.a), np.min(left.s + left.a), np.min(right.s + right.a))
    assert best.values["base_radius"] == pytest.approx(1.0 - lowest, abs=2e-3)


def test_stress_limit_against_a_grid_of_analyses():
    """A binding stress limit: the optimum against the smallest r_b of a 0.5 mm grid of full analyses."""
    data = sample_data("offset_roller")
    best = optimize(
        Problem(
            data=data,
            variables=_vary(data, "base_radius=60:100"),
            objectives=(MEASURES["base_radius"],),
            limits=(parse_limit("contact_stress<=172"),),
        )
    ).best
    design = load_design(ROOT / "samples" / "offset_roller.toml")
    grid = np.arange(70.0, 80.01, 0.5)
    stress = [
        analyse(design.with_base_radius(r), fit=False, toolpath=False, strict=False).dynamics.summary()[
            "hertz_stress_max_MPa"
        ]
        for r in grid
    ]
    first_ok = grid[int(np.argmax(np.array(stress) <= 172.0))]
    assert first_ok - 0.5 < best.values["base_radius"] <= first_ok
    assert any(c.active and c.name == "contact_stress<=172" for c in best.constraints)


def test_discrete_law_by_enumeration_against_closed_form():
    """The law (rise and return) chosen among three: each optimum and the best against 002 eq. 4 (e = 20)."""
    data = sample_data("offset_roller")
    result = optimize(
        Problem(
            data=data,
            variables=_vary(data, "law=cycloidal,poly-345,modified-sine", "base_radius=20:150"),
            objectives=(MEASURES["base_radius"],),
        )
    )
    expected = {}
    for law in ("cycloidal", "poly-345", "modified-sine"):
        variant = dict(data, motion=[dict(s, law=law) if "law" in s else s for s in data["motion"]])
        from camcad.design import parse_design

        program = MotionProgram.from_segments(parse_design(variant).motion)
        m = program.evaluate(np.linspace(0.0, 2 * math.pi, 72_001))
        expected[law] = smallest_base_radius_002(
            np.asarray(m.s), np.asarray(m.v), e=20.0, r_f=R_F, alpha_deg=ALPHA
        )
    found = {c.values["law"]: c.values["base_radius"] for c in result.tried}
    assert found == pytest.approx(expected, abs=1e-3)
    assert len({round(r, 1) for r in expected.values()}) == 3  # the laws differ: the choice means something
    assert result.best.values["law"] == min(expected, key=expected.get)


def test_pareto_front_against_brute_force():
    """Cam size vs peak pressure angle over (r_b, e): each front point against 002 eq. 4 on a grid of offsets,
    and no point of a brute-force (r_b, e) grid dominates a front point."""
    data = sample_data("offset_roller")
    result = optimize(
        Problem(
            data=data,
            variables=_vary(data, "base_radius=20:60", "offset=0:20"),
            objectives=(MEASURES["base_radius"], MEASURES["pressure_angle"]),
            points=4,
        )
    )
    s, v = motion_sv("offset_roller", n=36_001)
    offsets = np.arange(0.0, 20.0 + 1e-9, 0.01)
    front = [(c.values["base_radius"], c.objectives["pressure_angle"]) for c in result.front]
    assert len(front) == 4
    assert front[0][0] == pytest.approx(23.423, abs=2e-3) and front[0][1] == pytest.approx(25.0, abs=1e-4)
    assert front[-1][0] == pytest.approx(60.0)
    for r_b, alpha in front:  # at its own r_b no offset gives a smaller peak pressure angle
        peaks = peak_pressure_angles_002(s, v, r_b=r_b, offsets=offsets, r_f=R_F)
        # the vectorised form is 002 eq. 4 itself (its docstring's identity): spot-check it per sample
        for j in (0, 777, len(offsets) - 1, int(np.argmin(peaks))):
            assert peaks[j] == pytest.approx(peak_pressure_angle_002(s, v, r_b=r_b, e=offsets[j], r_f=R_F))
        best = float(peaks.min())
        assert best - 0.01 <= alpha <= best + 1e-4
    coarse = np.arange(0.0, 20.01, 0.5)
    for r_b in np.arange(20.0, 60.01, 0.5):
        for e, alpha in zip(
            coarse, peak_pressure_angles_002(s, v, r_b=r_b, offsets=coarse, r_f=R_F), strict=True
        ):
            assert not any(r_b < p[0] - 1e-6 and alpha < p[1] - 1e-4 for p in front), (r_b, e)


def test_cli_writes_a_design_file_that_passes_check(tmp_path, capsys):
    """The optimum's design file reads back, keeps every other key, and `camcad check` accepts it (exit 0)."""
    out = tmp_path / "opt"
    sample = str(ROOT / "samples" / "offset_roller.toml")
    code = main(
        [
            "optimize",
            sample,
            "--minimize",
            "base_radius",
            "--vary",
            "base_radius=20:120",
            "-o",
            str(out),
            "-q",
        ]
    )
    printed = capsys.readouterr().out
    assert code == 0
    assert "* pressure_angle<=25 (−min α)" in printed
    optimum = tomllib.loads((out / "optimum.toml").read_text(encoding="utf-8"))
    original = sample_data("offset_roller")
    assert optimum["cam"]["base_radius"] != original["cam"]["base_radius"]
    assert {k: v for k, v in optimum["cam"].items() if k != "base_radius"} == {
        k: v for k, v in original["cam"].items() if k != "base_radius"
    }
    assert optimum["motion"] == original["motion"] and optimum["dynamics"] == original["dynamics"]
    assert main(["check", str(out / "optimum.toml")]) == 0
    record = json.loads((out / "optimize.json").read_text(encoding="utf-8"))
    assert record["optimum"]["values"]["base_radius"] == optimum["cam"]["base_radius"]
    assert main(["size", str(out / "optimum.toml")]) == 0
    assert f"{optimum['cam']['base_radius']:.3f}" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("args", "flag"),
    [
        (["--vary", "base_radus=20:120"], "--vary"),
        (["--vary", "base_radius=-5:120"], "--vary"),
        (["--vary", "base_radius=80:20"], "--vary"),
        (["--vary", "base_radius=20:120:5"], "--vary"),
        (["--vary", "motion[9].law=cycloidal"], "--vary"),
        (["--vary", "law=cycloidal,warp-drive"], "--vary"),
        (["--vary", "base_radius=20:120", "--limit", "stress<=5"], "--limit"),
        (["--vary", "base_radius=20:120", "--method", "newton"], "--method"),
        (["--vary", "base_radius=20:120", "--starts", "100000000"], "--starts"),
        (["--vary", "base_radius=20:120", "--points", "100000000"], "--points"),
        (["--vary", "base_radius=20:120", "--vary", "cam.base_radius=30:40"], "--vary"),
        (["--vary", "base_radius=20:120", "--vary", "base_radius=30:40"], "--vary"),
        (["--vary", "law=cycloidal", "--vary", "motion[0].law=harmonic"], "--vary"),
        (["--vary", "base_radius=" + ",".join(f"{20 + i / 1000}" for i in range(10_000))], "--vary"),
        (
            ["--vary", "law=cycloidal,harmonic", "--vary", "offset=" + ",".join(map(str, range(600)))],
            "--vary",
        ),
    ],
    ids=[
        "unknown-key",
        "negative",
        "reversed",
        "count",
        "no-segment",
        "unknown-law",
        "limit",
        "method",
        "starts-cap",
        "points-cap",
        "same-key-alias",
        "same-key-twice",
        "same-segment-law",
        "10000-choices",
        "1200-combinations",
    ],
)
def test_bad_options_exit_2_naming_the_flag(args, flag, tmp_path, capsys):
    sample = str(ROOT / "samples" / "offset_roller.toml")
    start = time.monotonic()
    code = main(["optimize", sample, "--minimize", "base_radius", *args, "-o", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert time.monotonic() - start < 30  # refused up front, not after a run
    assert code == 2
    assert err.startswith(f"camcad: error: {flag}:"), err
    assert not (tmp_path / "o").exists()


def test_infeasible_ranges_exit_3(tmp_path, capsys):
    """No base radius in 20–30 mm meets 25° at e = 20 (002 eq. 4 needs 67.3): exit 3, the record written."""
    sample = str(ROOT / "samples" / "offset_roller.toml")
    code = main(
        ["optimize", sample, "--minimize", "base_radius", "--vary", "base_radius=20:30", "-o", str(tmp_path)]
    )
    assert code == 3
    assert "INFEASIBLE" in capsys.readouterr().out
    assert (tmp_path / "optimize.json").exists()
    optimum = (tmp_path / "optimum.toml").read_text(encoding="utf-8")
    assert optimum.startswith(
        "# INFEASIBLE: no design within the ranges meets every limit; this one breaks: "
    )
    assert "pressure_angle<=25" in optimum.splitlines()[0]
    assert main(["check", str(tmp_path / "optimum.toml")]) == 3  # check agrees: a limit is broken


def test_an_arm_optimum_typed_back_from_the_screen_passes_check_and_size(tmp_path, capsys):
    """Issue 31: packaging_rocker over (r_b, d). The printed digits, typed back, give a design that
    `camcad check` passes; so does optimum.toml; `camcad size` on it finds a radius, and that radius
    (an independent bracketing search at the optimum's pivot) equals the optimum's r_b: it is minimal."""
    sample = ROOT / "samples" / "packaging_rocker.toml"
    vary = ["--vary", "base_radius=20:80", "--vary", "pivot_distance=90:160"]
    code = main(
        ["optimize", str(sample), "--minimize", "base_radius", *vary, "-o", str(tmp_path / "o"), "-q"]
    )
    printed = capsys.readouterr().out
    assert code == 0, printed
    shown = {
        m["name"]: float(m["value"])
        for m in re.finditer(r"^  (?P<name>base_radius|pivot_distance) = (?P<value>\S+)$", printed, re.M)
    }
    assert set(shown) == {"base_radius", "pivot_distance"}
    assert "* pressure_angle<=30 (max α)" in printed and "* pressure_angle<=30 (−min α)" in printed

    typed = tomllib.loads(sample.read_text(encoding="utf-8"))
    typed["cam"]["base_radius"] = shown["base_radius"]
    typed["follower"]["pivot_distance"] = shown["pivot_distance"]
    (tmp_path / "typed.toml").write_text(toml_text(typed), encoding="utf-8")
    assert main(["check", str(tmp_path / "typed.toml")]) == 0
    assert "all design limits hold" in capsys.readouterr().out

    written = tomllib.loads((tmp_path / "o" / "optimum.toml").read_text(encoding="utf-8"))
    assert written["cam"]["base_radius"] == shown["base_radius"]
    assert written["follower"]["pivot_distance"] == shown["pivot_distance"]
    assert main(["check", str(tmp_path / "o" / "optimum.toml")]) == 0
    capsys.readouterr()
    assert main(["size", str(tmp_path / "o" / "optimum.toml")]) == 0
    assert capsys.readouterr().out.startswith("smallest base radius: ")

    design = load_design(tmp_path / "o" / "optimum.toml")
    smallest = min_base_radius(
        Cam.from_design(design),
        max_pressure_angle=design.cam.max_pressure_angle,
        min_curvature_radius=design.min_curvature_radius,
    ).base_radius
    assert smallest <= shown["base_radius"] + 1e-7
    assert smallest >= shown["base_radius"] - 1e-3  # no smaller cam at that pivot: the optimum is minimal


def test_problem_needs_a_variable():
    with pytest.raises(UsageError, match="--vary"):
        optimize(
            Problem(data=sample_data("offset_roller"), variables=(), objectives=(MEASURES["base_radius"],))
        )


def test_the_edge_of_the_valid_designs_is_reported():
    """quintero_vap_b02 could be 2.7 mm (`camcad size`), but its keyway must stay inside the base circle:
    r_b > bore/2 + keyway_depth = 10 + 2.8 mm (the schema's rule, from the file's numbers)."""
    data = sample_data("quintero_vap_b02")
    best = optimize(
        Problem(data=data, variables=_vary(data, "base_radius=0.5:60"), objectives=(MEASURES["base_radius"],))
    ).best
    edge = data["cam"]["bore"] / 2 + data["cam"]["keyway_depth"]
    assert best.feasible
    assert edge < best.values["base_radius"] <= edge + 1e-3
    assert any(b.startswith("base_radius cannot go lower: cam.keyway_depth:") for b in best.bounds)


def test_same_problem_same_files(tmp_path):
    """Two runs write byte-identical files (no timestamps, a deterministic solver)."""
    sample = str(ROOT / "samples" / "offset_roller.toml")
    args = ["optimize", sample, "--minimize", "base_radius", "--vary", "base_radius=20:120", "-q"]
    assert main([*args, "-o", str(tmp_path / "a")]) == main([*args, "-o", str(tmp_path / "b")]) == 0
    for name in ("optimum.toml", "optimize.json"):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()


@pytest.mark.skipif(not (ROOT / "samples" / "measured_table.toml").exists(), reason="no point-table sample")
def test_point_table_file_is_found_from_the_output_folder(tmp_path, capsys):
    """A design naming its lift table relative to itself: the optimum, written elsewhere, still reads it."""
    out = tmp_path / "deep" / "er"
    sample = str(ROOT / "samples" / "measured_table.toml")
    code = main(
        ["optimize", sample, "--minimize", "base_radius", "--vary", "base_radius=30:60", "-o", str(out), "-q"]
    )
    assert code == 0
    assert main(["check", str(out / "optimum.toml")]) == 0
    assert "all design limits hold" in capsys.readouterr().out
