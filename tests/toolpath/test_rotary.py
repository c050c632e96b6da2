"""Rotary-axis programs (X + A/C, G93) and polar tables, against independent measurements.

Every check here rebuilds what a controller would do from the written words
alone (X and the rotary word, linear between blocks) and measures it in the
cam frame against a dense sampling of the exact offset curve, with a
distance computation that shares nothing with the planner (the planner
bounds a radial gap; the tests measure Euclidean distances to a polygon).
"""

from __future__ import annotations

import math
import re
from dataclasses import replace
from functools import cache

import numpy as np
import pytest
from hypothesis import HealthCheck, given, reject, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from camcad.design import parse_design
from camcad.design.paths import named_error, path_of
from camcad.errors import DesignError, GougeError, NotStarShapedError
from camcad.export.gcode.rotary import inverse_feed_text, render_rotary, render_rotary_program
from camcad.export.tables import polar_table_text
from camcad.geometry.cam import Cam
from camcad.toolpath import rotary as rotary_module
from camcad.toolpath.rotary import RotaryToolpath, plan_rotary, rotary_levels
from tests.conftest import distance_to_polygon, make_design

DENSE = 60_000  # samples of the exact curves the path is measured against (chord sag < 2e-7 mm)


def rotary(design, **gcode):
    """The design with ``machine = "rotary"`` and the given [gcode] values (TOML spellings)."""
    spec = parse_design({**_toml(design), "gcode": {"machine": "rotary", **gcode}}).gcode
    return replace(design, gcode=spec)


def _toml(design):
    """The minimal TOML mapping the test designs are made from (cam, follower, motion are reused)."""
    return {
        "cam": {"base_radius": design.cam.base_radius, "thickness": design.cam.thickness},
        "follower": {"type": "translating-roller", "roller_radius": 10.0},
        "motion": [{"kind": "dwell", "angle": 360.0}],
    }


CASES = {
    "poly345-offset-ccw": {"law": "poly-345", "offset": 4.0},
    "cycloidal-cw": {"law": "cycloidal", "rotation": "cw", "offset": -3.0},
    "flat-face": {"law": "cycloidal", "follower": "translating-flat", "base_radius": 50.0},
    "concave": {"base_radius": 20.0, "lift": 15.0, "roller_radius": 5.0, "spans": (90.0, 90.0, 90.0, 90.0)},
}
SETTINGS = {
    "climb-A-ccw": {},
    "conventional-C-cw": {"direction": "conventional", "rotary_axis": "C", "rotary_direction": "cw"},
    "wheel-fine": {"cutter": "wheel", "tool_diameter": 16.0, "tolerance": 0.001, "start_angle": 200.0},
}


@cache
def planned(case: str, setting: str) -> tuple[Cam, RotaryToolpath]:
    design = rotary(make_design(**CASES[case]), **SETTINGS[setting])
    cam = Cam.from_design(design)
    return cam, plan_rotary(cam, design.gcode, name=case, thickness=design.cam.thickness)


def cam_frame_path(x: np.ndarray, words: np.ndarray, *, sign: float, spacing: float = 0.01) -> np.ndarray:
    """The tool centre in the cam frame as the controller moves X and the rotary word linearly.

    Points at most ``spacing`` mm apart, so the polygon's chord sag (≈ spacing²/8r) is below 1e-6 mm.
    """
    xs, ws = [], []
    for k in range(x.size - 1):
        n = max(8, math.ceil(abs(math.radians(words[k + 1] - words[k])) * max(x[k], x[k + 1]) / spacing))
        t = np.arange(n) / n
        xs.append(x[k] + (x[k + 1] - x[k]) * t)
        ws.append(words[k] + (words[k + 1] - words[k]) * t)
    xs, ws = np.concatenate(xs), np.concatenate(ws)
    theta = np.radians(sign * ws)  # the cam's ccw turn; the tool at (X, 0) is at R(−θ)(X, 0) on the cam
    return np.column_stack((xs * np.cos(-theta), xs * np.sin(-theta)))


def exact_polygon(cam: Cam, distance: float, n: int = DENSE) -> np.ndarray:
    phi = np.linspace(0.0, 2.0 * math.pi, n, endpoint=False)
    return cam.offset_curve(phi, distance).point


def hausdorff(path: np.ndarray, exact: np.ndarray) -> float:
    """Two-way distance between a closed path and a closed exact polygon [mm]."""
    return max(float(distance_to_polygon(path, exact).max()), float(distance_to_polygon(exact, path).max()))


def sign_of(tp: RotaryToolpath) -> float:
    return 1.0 if tp.spec.rotary_direction.value == "ccw" else -1.0


@pytest.mark.parametrize("setting", list(SETTINGS))
@pytest.mark.parametrize("case", list(CASES))
def test_written_words_follow_the_exact_offset_curve_within_tolerance(case, setting):
    """Against a dense exact offset polygon: two-way Euclidean distance ≤ tolerance, and no gouge."""
    cam, tp = planned(case, setting)
    spec = tp.spec
    path = cam_frame_path(tp.x, tp.rotary_words, sign=sign_of(tp))
    exact = exact_polygon(cam, spec.tool_radius)
    measured = hausdorff(path, exact)
    assert measured <= spec.tolerance
    assert measured <= tp.max_deviation + 1e-6  # the planner's radial gap bounds the true distance
    assert tp.max_deviation <= spec.tolerance
    clearance = distance_to_polygon(path, exact_polygon(cam, 0.0)) - spec.tool_radius
    assert clearance.min() >= -spec.tolerance  # the tool never cuts more than the tolerance into the part
    # one whole revolution, in the sense the direction asks for: climb turns the cam ccw seen from +Z
    turn = sign_of(tp) * (tp.rotary_words[-1] - tp.rotary_words[0])
    assert turn == pytest.approx(360.0 if spec.direction.value == "climb" else -360.0, abs=1e-9)
    assert 0.0 <= tp.rotary_words[0] < 360.0


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    law=st.sampled_from(["cycloidal", "poly-345", "modified-sine", "harmonic"]),
    base_radius=st.floats(25.0, 60.0),
    lift=st.floats(3.0, 20.0),
    offset=st.floats(-6.0, 6.0),
    rotation=st.sampled_from(["ccw", "cw"]),
    tool_diameter=st.floats(1.0, 16.0),
    tolerance=st.floats(0.001, 0.01),
    start=st.floats(0.0, 359.0),
    climb=st.booleans(),
    axis_cw=st.booleans(),
)
def test_any_design_is_cut_within_tolerance(
    law, base_radius, lift, offset, rotation, tool_diameter, tolerance, start, climb, axis_cw
):
    """For all designs: the rebuilt written path stays within tolerance of the exact offset curve."""
    try:
        design = rotary(
            make_design(law=law, base_radius=base_radius, lift=lift, offset=offset, rotation=rotation),
            tool_diameter=tool_diameter,
            tolerance=tolerance,
            start_angle=start,
            direction="climb" if climb else "conventional",
            rotary_direction="cw" if axis_cw else "ccw",
        )
        cam = Cam.from_design(design)
        tp = plan_rotary(cam, design.gcode, name="h", thickness=8.0)
    except (DesignError, GougeError, NotStarShapedError):
        reject()
    path = cam_frame_path(tp.x, tp.rotary_words, sign=sign_of(tp))
    assert hausdorff(path, exact_polygon(cam, design.gcode.tool_radius)) <= tolerance
    assert tp.x[0] == pytest.approx(
        float(np.hypot(*cam.offset_curve(np.radians([start]), tool_diameter / 2).point[0])), abs=6e-5
    )


class _Loop:
    """A stand-in cam whose tool-centre path is a circle beside the axis: rays meet it twice."""

    sample_step = math.radians(1.0)

    def sample_phi(self, step: float) -> np.ndarray:
        return np.arange(0.0, 2.0 * math.pi, step)

    def offset_curve(self, phi, distance, side="right"):
        phi = np.asarray(phi, dtype=float)

        class _Points:
            point = np.column_stack((30.0 + 5.0 * np.cos(phi), 5.0 * np.sin(phi)))

        return _Points()


def test_a_path_that_is_not_star_shaped_is_refused(monkeypatch):
    """A ray from the axis meeting the path twice would need the cam to turn back: refused, field named."""
    monkeypatch.setattr(rotary_module, "_check_cutter", lambda cam, spec: math.inf)
    spec = rotary(make_design()).gcode
    with pytest.raises(NotStarShapedError) as err:
        plan_rotary(_Loop(), spec, name="loop", thickness=8.0)
    assert re.match(r"^gcode\.machine: the tool-centre path is not star-shaped", str(named_error(err.value)))


def test_the_measurement_is_not_vacuous():
    """Dropping every other block breaks the tolerance, so the measurement can fail."""
    cam, tp = planned("poly345-offset-ccw", "climb-A-ccw")
    keep = np.r_[0 : tp.x.size - 1 : 2, tp.x.size - 1]
    path = cam_frame_path(tp.x[keep], tp.rotary_words[keep], sign=1.0)
    assert hausdorff(path, exact_polygon(cam, tp.spec.tool_radius)) > tp.spec.tolerance


def test_start_block_is_the_exact_tool_centre_at_the_start_angle():
    """Closed form: the first words are |Q(φ0)| and −atan2(Q) of the exact offset point at start_angle."""
    cam, tp = planned("concave", "wheel-fine")
    q = cam.offset_curve(np.array([math.radians(200.0)]), tp.spec.tool_radius).point[0]
    assert tp.x[0] == pytest.approx(math.hypot(*q), abs=5e-5)
    expected = math.degrees(-math.atan2(q[1], q[0])) % 360.0
    assert tp.rotary_words[0] == pytest.approx(expected, abs=1e-6)


def test_a_circular_cam_is_a_constant_x_rotation():
    """A dwell-only program: the profile is the base circle, so X = r_b + r_tool on every block."""
    design = rotary(parse_design(_toml(make_design())), tool_diameter=8.0)
    cam = Cam.from_design(design)
    tp = plan_rotary(cam, design.gcode, name="circle", thickness=8.0)
    assert np.all(tp.x == round(40.0 + 4.0, 4))
    assert tp.max_deviation <= 1e-9
    assert abs(tp.rotary_words[-1] - tp.rotary_words[0]) == pytest.approx(360.0)
    assert tp.blocks_per_revolution == 4  # only the 90° cap on a block's turn splits it
    text = render_rotary(tp)
    cuts = [line for line in text.splitlines() if line.startswith("G1 ") and " A" in line]
    assert {w for line in cuts for w in line.split() if w.startswith("X")} == {"X44.0000"}


@pytest.mark.parametrize("case", ["poly345-offset-ccw", "flat-face"])
def test_inverse_time_feeds_give_the_contact_path_at_the_surface_speed(case):
    """Against an independent contact length: a dense polyline of the exact profile per block."""
    cam, tp = planned(case, "climb-A-ccw")
    for i in range(tp.blocks_per_revolution):
        phi = np.linspace(tp.phi[i], tp.phi[i + 1], 4001)
        pts = cam.profile(phi).point
        length = float(np.sum(np.hypot(*np.diff(pts, axis=0).T)))
        minutes = 1.0 / float(inverse_feed_text(tp.inverse_feed[i]))  # as written: F = 1/T
        assert minutes * tp.spec.feed == pytest.approx(length, rel=2e-5)
    # the whole revolution covers the profile's perimeter once
    perimeter = exact_polygon(cam, 0.0)
    closed = np.vstack((perimeter, perimeter[:1]))
    assert float(tp.contact_length.sum()) == pytest.approx(
        np.sum(np.hypot(*np.diff(closed, axis=0).T)), rel=1e-7
    )


@pytest.mark.parametrize("setting", list(SETTINGS))
@pytest.mark.parametrize("case", list(CASES))
def test_no_block_falls_below_linuxcnc_slowest_inverse_time_rate(case, setting):
    """LinuxCNC runs a G93 block at max(0.1, |ΔX|·F) (its X length, when X moves): never the 0.1 clamp."""
    _, tp = planned(case, setting)
    dx = np.abs(np.diff(tp.x))
    rate = dx * np.array([float(inverse_feed_text(f)) for f in tp.inverse_feed])
    assert np.all((dx == 0.0) | (rate >= 0.1))


def test_cw_words_mirror_ccw_words():
    """rotary_direction = "cw" writes −θ: the same cut with every word negated (up to whole turns)."""
    base = make_design(law="poly-345", offset=4.0)
    ccw = plan_rotary(Cam.from_design(base), rotary(base).gcode, name="a", thickness=8.0)
    cw_design = rotary(base, rotary_direction="cw")
    cw = plan_rotary(Cam.from_design(cw_design), cw_design.gcode, name="a", thickness=8.0)
    shift = cw.rotary_words[0] + ccw.rotary_words[0]
    assert shift % 360.0 == pytest.approx(0.0, abs=1e-6) or shift % 360.0 == pytest.approx(360.0, abs=1e-6)
    assert np.allclose(cw.rotary_words, shift - ccw.rotary_words, atol=2e-6)
    assert np.array_equal(cw.x, ccw.x)


def test_largest_wheel_is_the_smallest_concave_radius():
    """Against a brute force over 10⁶ exact curvatures: the largest wheel, refused just above it."""
    design = make_design(**CASES["concave"])
    cam = Cam.from_design(design)
    rho = cam.profile(np.linspace(0.0, 2.0 * math.pi, 1_000_000, endpoint=False)).rho
    brute = float(np.min(-rho[rho < 0.0]))
    _, tp = planned("concave", "wheel-fine")
    assert tp.concave_radius_min <= brute + 1e-9
    assert tp.concave_radius_min == pytest.approx(brute, abs=1e-6)
    fits = rotary(design, cutter="wheel", tool_diameter=2.0 * brute - 0.02)
    plan_rotary(cam, fits.gcode, name="c", thickness=8.0)
    too_big = rotary(design, cutter="wheel", tool_diameter=2.0 * brute + 0.02)
    with pytest.raises(GougeError) as err:
        plan_rotary(cam, too_big.gcode, name="c", thickness=8.0)
    assert re.match(r"^gcode\.tool_diameter: a wheel .* the largest wheel is Ø", str(named_error(err.value)))
    assert err.value.max_tool_radius == pytest.approx(brute, abs=1e-6)


def test_levels_wheel_one_pass_end_mill_step_downs():
    """Depth = thickness + breakthrough: one level for a wheel, ⌈depth / step_down⌉ equal ones for a mill."""
    design = make_design()
    mill = rotary(design, step_down=3.0).gcode
    assert rotary_levels(mill, 8.0) == (-2.8333, -5.6667, -8.5)
    assert rotary_levels(rotary(design, cutter="wheel").gcode, 8.0) == (-8.5,)


def test_program_has_f_on_every_g93_block_and_ends_in_g94():
    """Read back: every G93 feed block carries F; the cut ends in G94; the header names the tool."""
    _, tp = planned("poly345-offset-ccw", "climb-A-ccw")
    text = render_rotary(tp)
    assert text == render_rotary(tp)  # deterministic
    mode, g93_blocks, last_mode = "G94", 0, None
    for line in text.splitlines():
        words = line.split()
        if "G93" in words or "G94" in words:
            mode = "G93" if "G93" in words else "G94"
            last_mode = mode
        if words and words[0] == "G1" and mode == "G93":
            g93_blocks += 1
            assert any(w.startswith("F") for w in words), line
            assert any(w.startswith("A") for w in words), line
    assert g93_blocks == tp.blocks_per_revolution * len(tp.levels)
    assert last_mode == "G94"
    assert "(depth: end mill, 5 step-downs along the cam axis [Z] to Z-8.5000)" in text
    _, wheel = planned("concave", "wheel-fine")
    assert "grinding wheel D16.000" in render_rotary(wheel)
    figures = render_rotary_program(tp).summary()
    assert figures["machine"] == "rotary" and figures["blocks_per_revolution"] == tp.blocks_per_revolution


def test_grbl_cannot_run_a_rotary_program():
    with pytest.raises(DesignError, match=r"gcode\.dialect.*grbl.*linuxcnc, generic"):
        rotary(make_design(), dialect="grbl")
    _, tp = planned("poly345-offset-ccw", "climb-A-ccw")
    with pytest.raises(DesignError) as err:
        render_rotary(tp, "grbl")
    assert str(named_error(err.value)).startswith("gcode.dialect: ")
    assert "M30" in render_rotary(tp, "generic")


@pytest.mark.parametrize(
    ("gcode", "field"),
    [
        ({"cutter": "wheel"}, "gcode.cutter"),
        ({"machine": "rotary", "rotary_axis": "B"}, "gcode.rotary_axis"),
        ({"machine": "rotary", "tab_count": 2}, "gcode.tab_count"),
        ({"machine": "rotary", "mill_bore": True}, "gcode.mill_bore"),
        ({"machine": "rotary", "fewest_arcs": True}, "gcode.fewest_arcs"),
        ({"machine": "lathe"}, "gcode.machine"),
        ({"machine": "rotary", "dialect": "grbl"}, "gcode.dialect"),
    ],
)
def test_bad_rotary_settings_name_their_field(gcode, field):
    data = {**_toml(make_design()), "gcode": gcode}
    with pytest.raises(DesignError) as err:
        parse_design(data)
    assert path_of(err.value.path) == field


# --- polar tables ---------------------------------------------------------------------------


def _rows(text: str) -> np.ndarray:
    return np.array(
        [[float(v) for v in line.split()] for line in text.splitlines() if not line.startswith("#")]
    )


def _ray_crossing(cam: Cam, distance: float, theta: float, sign: float, dense: np.ndarray) -> float:
    """Independent: the ray u = (sign·sin θ, cos θ) against the exact offset curve, by Brent's method."""
    u = np.array([sign * math.sin(theta), math.cos(theta)])
    phi = np.linspace(0.0, 2.0 * math.pi, dense.shape[0] + 1)
    pts = np.vstack((dense, dense[:1]))
    cross = u[0] * pts[:, 1] - u[1] * pts[:, 0]
    ahead = pts @ u > 0.0
    k = np.flatnonzero((np.sign(cross[:-1]) != np.sign(cross[1:])) & ahead[:-1])[0]

    def f(p: float) -> float:
        q = cam.offset_curve(np.array([p]), distance).point[0]
        return float(u[0] * q[1] - u[1] * q[0])

    root = brentq(f, phi[k], phi[k + 1], xtol=1e-14)
    return float(np.hypot(*cam.offset_curve(np.array([root]), distance).point[0]))


@pytest.mark.parametrize("case", ["poly345-offset-ccw", "cycloidal-cw", "concave"])
def test_polar_table_radii_equal_the_ray_crossing_to_the_printed_precision(case):
    design = make_design(**CASES[case])
    cam = Cam.from_design(design)
    wheel = 12.5 if case != "concave" else 60.0
    options = replace(design.tables, wheel_radius=wheel, polar_step=math.radians(0.5), polar_decimals=4)
    rows = _rows(polar_table_text(cam, options, name=case))
    assert rows.shape == (720, 2)
    assert np.allclose(rows[:, 0], np.arange(720) * 0.5)
    dense = exact_polygon(cam, wheel, 20_000)
    sign = cam.sigma
    for angle, radius in rows[::37]:
        exact = _ray_crossing(cam, wheel, math.radians(angle), sign, dense)
        assert abs(radius - exact) <= 0.5e-4 + 1e-9


def test_polar_table_of_a_circular_cam_is_base_plus_wheel():
    """Closed form: a dwell-only cam's wheel centre stays at r_b + R_w at every angle."""
    design = parse_design({**_toml(make_design()), "tables": {"wheel_radius": 7.25, "polar_decimals": 6}})
    rows = _rows(polar_table_text(Cam.from_design(design), design.tables))
    assert rows.shape == (360, 2)
    assert np.all(rows[:, 1] == 47.25)


def test_polar_table_header_and_a_wheel_too_large_for_the_profile():
    design = make_design(**CASES["concave"])
    cam = Cam.from_design(design)
    text = polar_table_text(cam, replace(design.tables, wheel_radius=10.0), name="bad\nname (x)")
    head = [line for line in text.splitlines() if line.startswith("#")]
    assert head[0] == "# camcad polar table: bad name (x)"
    assert "columns: angle_deg radius_mm; 360 rows, step 1 deg, radius 4 decimals" in head[-1]
    with pytest.raises(GougeError) as err:
        polar_table_text(cam, replace(design.tables, wheel_radius=110.0))
    assert re.match(r"^tables\.wheel_radius: .* allowed: wheel_radius ≤ 105\.6", str(named_error(err.value)))


# --- through the pipeline -------------------------------------------------------------------


def test_build_writes_the_rotary_program_and_the_polar_table(tmp_path):
    """End to end: cam.ngc is the rotary program, polar.txt is written, summary.json says so."""
    from camcad.pipeline import build

    design = parse_design({
        **_toml(make_design()),
        "motion": [
            {"kind": "rise", "angle": 180.0, "lift": 10.0, "law": "cycloidal"},
            {"kind": "return", "angle": 180.0, "lift": 10.0, "law": "cycloidal"},
        ],
        "gcode": {"machine": "rotary", "rotary_axis": "C", "cutter": "wheel", "tool_diameter": 20.0},
        "tables": {"wheel_radius": 10.0, "polar_step_deg": 2.0},
    })  # fmt: skip
    result = build(design, tmp_path / "out", only=["gcode", "tables"])
    text = (tmp_path / "out" / "cam.ngc").read_text(encoding="ascii")
    assert "G93" in text and " C" in text and "grinding wheel D20.000" in text
    polar = _rows((tmp_path / "out" / "polar.txt").read_text(encoding="ascii"))
    assert polar.shape == (180, 2)
    summary = result.analysis.summary()["gcode"]
    assert summary["machine"] == "rotary" and summary["cutter"] == "wheel"
    assert summary["max_deviation_mm"] <= design.gcode.tolerance


def test_a_wheel_too_large_is_a_hard_finding_naming_the_tool_diameter():
    from camcad.pipeline import analyse

    design = rotary(make_design(**CASES["concave"]), cutter="wheel", tool_diameter=220.0)
    analysis = analyse(design, strict=False, fit=False)
    (finding,) = [f for f in analysis.findings if f.hard]
    assert path_of(finding.field) == "gcode.tool_diameter" and "largest wheel" in finding.message
    with pytest.raises(GougeError):
        analyse(design, fit=False)


def test_a_groove_cam_is_not_cut_on_the_rotary_machine():
    data = {**_toml(make_design()), "gcode": {"machine": "rotary"}}
    data["cam"] = {**data["cam"], "style": "groove", "outer_radius": 80.0, "thickness": 20.0}
    with pytest.raises(DesignError) as err:
        parse_design(data)
    assert path_of(err.value.path) == "gcode.machine"
