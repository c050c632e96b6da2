"""Linear cams as a cam family (issue 36): cam.style = "linear", checked against closed forms.

The bar translates by L per cycle, so a follower point M(φ) is at
M(φ) + (Lφ/2π, 0) in the bar's frame: a translating roller's pitch line is
(x, r_b + r_f + s) with x = Lφ/2π, its pressure angle tan α = ds/dx, and the
curvature of the edge is compared with a numerical curvature of the exact
curve sampled densely (an independent second method).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose

from camcad.cli import main
from camcad.design import parse_design
from camcad.design.paths import path_of
from camcad.errors import DesignError
from camcad.geometry.cam import Cam
from camcad.geometry.families import family_of
from camcad.pipeline import analyse

L = 240.0  # mm per cycle
RB, RF = 30.0, 8.0
LIFT = 20.0


def linear_data(
    *, follower: dict[str, Any] | None = None, linear: dict[str, Any] | None = None, **cam: Any
) -> dict[str, Any]:
    return {
        "cam": {"name": "bar", "style": "linear", "base_radius": RB, "thickness": 10.0, **cam},
        "linear": {"stroke_length": L, "bar_height": 25.0, **(linear or {})},
        "follower": follower or {"type": "translating-roller", "roller_radius": RF},
        "motion": [
            {"kind": "rise", "angle": 120.0, "lift": LIFT, "law": "cycloidal"},
            {"kind": "dwell", "angle": 60.0},
            {"kind": "return", "angle": 120.0, "lift": LIFT, "law": "poly-345"},
            {"kind": "dwell", "angle": 60.0},
        ],
    }


def bar_cam(data: dict[str, Any]) -> Cam:
    design = parse_design(data)
    (part,) = family_of(design.cam.style).parts(Cam.from_design(design), design.family_options())
    return part.cam


def cycloid(phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """s and ds/dφ of the cycloidal rise over 120° (closed form, Norton 2009, eq. 8.12)."""
    beta = math.radians(120.0)
    u = phi / beta
    s = LIFT * (u - np.sin(2 * np.pi * u) / (2 * np.pi))
    v = LIFT / beta * (1 - np.cos(2 * np.pi * u))
    return s, v


def test_pitch_line_of_a_translating_roller_is_x_and_base_plus_lift():
    cam = bar_cam(linear_data())
    phi = np.linspace(0.0, math.radians(120.0), 241)
    s, _ = cycloid(phi)
    x = L * phi / (2 * np.pi)
    assert_allclose(cam.pitch(phi).point, np.column_stack((x, RB + RF + s)), atol=1e-9)


def test_pressure_angle_of_a_translating_roller_is_the_slope_ds_dx():
    cam = bar_cam(linear_data())
    phi = np.linspace(0.0, math.radians(120.0), 241)
    _, v = cycloid(phi)
    slope = v / (L / (2 * np.pi))  # ds/dx = (ds/dφ)/(dx/dφ)
    assert_allclose(np.tan(cam.state(phi).pressure_angle), slope, atol=1e-12)


def test_reported_pressure_angle_is_the_true_maximum():
    """Cycloidal rise 20 mm over 120° = 80 mm: ds/dx peaks at 2h/80 mm = 0.5 at mid-rise."""
    design = parse_design(linear_data())
    result = analyse(design, fit=False, toolpath=False)
    ext = result.geometry.pressure_angle_max
    assert ext.value == pytest.approx(math.atan(2 * LIFT / 80.0), abs=1e-12)
    assert ext.phi == pytest.approx(math.radians(60.0), abs=1e-6)


@pytest.mark.parametrize(
    "follower",
    [
        {"type": "translating-roller", "roller_radius": RF, "offset": 3.0},
        {"type": "translating-mushroom", "face_radius": 40.0},
        {"type": "oscillating-roller", "roller_radius": RF, "pivot_distance": 90.0, "arm_length": 70.0},
    ],
    ids=["roller-offset", "mushroom", "oscillating-roller"],
)
def test_curvature_of_the_edge_matches_a_numerical_curvature(follower):
    cam = bar_cam(linear_data(follower=follower))
    for lo, hi in ((0.02, 2.07), (3.16, 5.22)):  # inside the rise and the return (no joints)
        phi = np.linspace(lo, hi, 20001)
        p = np.asarray(cam.profile(phi).point)
        d1 = np.gradient(p, phi, axis=0, edge_order=2)
        d2 = np.gradient(d1, phi, axis=0, edge_order=2)
        cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
        rho_num = np.hypot(d1[:, 0], d1[:, 1]) ** 3 / cross
        # camcad's sign: positive where convex seen from the follower (the curve runs +x, the follower
        # above it), i.e. where the curve turns clockwise
        rho = np.asarray(cam.profile(phi).rho)
        inner = slice(10, -10)
        kappa, kappa_num = 1 / rho[inner], -1 / rho_num[inner]
        assert_allclose(kappa, kappa_num, atol=1e-6)


def test_undercut_is_found_and_named_at_the_pitch_lines_sharpest_convex_point():
    """A 40 mm stroke: the rise's crest is sharper than a 8 mm roller; brute force agrees."""
    data = linear_data(linear={"stroke_length": 40.0})
    design = parse_design(data)
    result = analyse(design, fit=False, toolpath=False, strict=False)
    under = [f for f in result.findings if f.kind == "undercut"]
    assert under and under[0].hard
    cam = bar_cam(data)
    phi = np.linspace(0.0, 2 * np.pi, 200001)
    pitch = np.asarray(cam.pitch(phi).point)
    d1 = np.gradient(pitch, phi, axis=0)
    d2 = np.gradient(d1, phi, axis=0)
    cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    with np.errstate(divide="ignore"):  # straight on the dwells
        convex = np.hypot(d1[:, 0], d1[:, 1]) ** 3 / -cross  # > 0 where the pitch line turns clockwise
    brute = float(np.min(np.where(convex > 0, convex, np.inf)))
    assert brute < RF
    assert result.geometry.undercut is not None
    assert path_of(under[0].field) == "linear.stroke_length"
    assert under[0].value == pytest.approx(brute, rel=1e-3)


def test_no_undercut_on_the_long_stroke():
    result = analyse(parse_design(linear_data()), fit=False, toolpath=False, strict=False)
    assert not [f for f in result.findings if f.kind == "undercut"]


def test_speed_mm_s_sets_the_cycle_rate():
    design = parse_design(linear_data(linear={"speed_mm_s": 120.0}))
    assert design.cam.speed_rpm == pytest.approx(60.0 * 120.0 / L)  # 2 s per 240 mm cycle


BAD = {
    "stroke-zero": (lambda d: d["linear"].update(stroke_length=0.0), "linear.stroke_length"),
    "stroke-negative": (lambda d: d["linear"].update(stroke_length=-5.0), "linear.stroke_length"),
    "stroke-missing": (lambda d: d["linear"].pop("stroke_length"), "linear.stroke_length"),
    "groove-key": (lambda d: d["cam"].update(outer_radius=90.0), "cam.outer_radius"),
    "groove-table": (lambda d: d.update(groove={"depth": 5.0}), "groove"),
    "bore": (lambda d: d["cam"].update(bore=10.0), "cam.bore"),
    "cw": (lambda d: d["cam"].update(rotation="cw"), "cam.rotation"),
    "flat-face": (lambda d: d.update(follower={"type": "translating-flat"}), "follower.type"),
    "bar-too-low": (lambda d: d["linear"].update(bar_height=-1.0), "linear.bar_height"),
    "speed-twice": (
        lambda d: d["cam"].update(speed_rpm=30.0) or d["linear"].update(speed_mm_s=100.0),
        "linear.speed_mm_s",
    ),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_linear_input_names_its_field(case):
    data = linear_data()
    change, field = BAD[case]
    change(data)
    with pytest.raises(DesignError) as err:
        parse_design(data)
    assert path_of(err.value.path) == field


def test_a_plate_refuses_the_linear_table():
    data = linear_data()
    data["cam"].pop("style")
    with pytest.raises(DesignError) as err:
        parse_design(data)
    assert path_of(err.value.path) == "linear"


def test_cli_exit_2_names_the_field(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(
        '[cam]\nstyle = "linear"\nbase_radius = 30.0\n[linear]\nstroke_length = -1.0\n'
        '[follower]\ntype = "translating-roller"\nroller_radius = 5.0\n'
        '[[motion]]\nkind = "rise"\nangle = 180.0\nlift = 5.0\nlaw = "cycloidal"\n'
        '[[motion]]\nkind = "return"\nangle = 180.0\nlift = 5.0\nlaw = "cycloidal"\n',
        encoding="utf-8",
    )
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert "linear.stroke_length" in err and "-1" in err
    assert "Traceback" not in err


ARM = {"type": "oscillating-roller", "roller_radius": RF, "pivot_distance": 90.0, "arm_length": 70.0}


def test_oscillating_rollers_pressure_angle_from_the_pitch_lines_numerical_normal():
    """|α| is the angle between the pitch line's normal and the arm's perpendicular at the roller centre."""
    cam = bar_cam(linear_data(follower=ARM))
    pivot = np.asarray(cam.follower.guide.pivot)
    phi = np.linspace(0.05, 2.05, 4001)  # inside the rise
    pitch = np.asarray(cam.pitch(phi).point)
    tangent = np.gradient(pitch, phi, axis=0, edge_order=2)
    normal = np.column_stack((-tangent[:, 1], tangent[:, 0]))
    centre = np.asarray(cam.follower.element(cam.motion(phi)).m0)  # machine frame (the arm does not move x)
    arm = centre - pivot
    across = np.column_stack((-arm[:, 1], arm[:, 0]))
    cos = np.abs(np.einsum("ij,ij->i", normal, across)) / (np.hypot(*normal.T) * np.hypot(*across.T))
    assert_allclose(np.abs(cam.state(phi).pressure_angle)[5:-5], np.arccos(cos)[5:-5], atol=1e-6)


def test_a_pivot_below_the_bars_edge_is_a_hard_finding():
    low = dict(ARM, pivot_distance=50.0)
    result = analyse(parse_design(linear_data(follower=low)), fit=False, toolpath=False, strict=False)
    (hit,) = [f for f in result.findings if f.kind == "pivot clearance"]
    assert hit.hard and path_of(hit.field) == "follower.pivot_distance"
    top = float(
        np.max(
            np.asarray(bar_cam(linear_data(follower=low)).profile(np.linspace(0, 2 * np.pi, 72001)).point)[
                :, 1
            ]
        )
    )
    assert hit.limit == pytest.approx(top, abs=1e-6)
    high = analyse(parse_design(linear_data(follower=ARM)), fit=False, toolpath=False, strict=False)
    assert not [f for f in high.findings if f.kind == "pivot clearance"]


@pytest.mark.parametrize(
    "follower",
    [
        {"type": "translating-roller", "roller_radius": RF, "offset": 6.0},
        {"type": "oscillating-roller", "roller_radius": RF, "pivot_distance": 70.0, "arm_length": 60.0},
    ],
)
def test_straight_spans_are_the_dwells_and_the_edge_is_a_line_there(follower):
    """The follower stands still in a dwell: every offset of the edge is a line along x over its span."""
    cam = bar_cam(linear_data(follower=follower))
    spans = cam.straight_spans
    want = [(math.radians(120.0), math.radians(180.0)), (math.radians(300.0), 2 * math.pi)]
    assert_allclose(np.array(spans), np.array(want), atol=1e-12)
    for a, b in spans:
        for d in (0.0, 5.0):
            o = cam.offset_curve(np.linspace(a, b, 101), d)
            pts = np.asarray(o.point)
            # a line along x travelled at the bar's rate: y constant, x = x(a) + L(φ − a)/2π
            assert np.ptp(pts[:, 1]) <= 1e-9
            assert_allclose(
                pts[:, 0] - pts[0, 0], L * (np.linspace(a, b, 101) - a) / (2 * math.pi), atol=1e-9
            )
        # just outside, it is not (the curve leaves the line: not every stretch is straight)
        if a > 0.0:
            near = np.asarray(cam.offset_curve(np.array([a - 0.05, a]), 0.0).point)
            assert abs(near[0, 1] - near[1, 1]) > 1e-6
    # a disc cam of the same motion has no straight stretch: its dwells are circles
    disc_data = linear_data(follower=follower)
    del disc_data["linear"]
    disc_data["cam"] = {"name": "disc", "base_radius": RB, "thickness": 10.0}
    assert Cam.from_design(parse_design(disc_data)).straight_spans == ()
