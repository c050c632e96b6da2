"""The cam plate's FE check against independent truths.

- Hertz's half-plane under an elliptical pressure (Johnson 1985, §4.2, eq. 4.49):
  on the axis below a line contact σ_x = −p0[(1 + 2ζ²)/√(1 + ζ²) − 2ζ],
  σ_z = −p0/√(1 + ζ²) with ζ = z/b, so the in-plane shear τ1 = (σ_x − σ_z)/2
  peaks at 0.300 p0 at z = 0.786 b; a disc of radius 100 mm under a roller
  (b ≈ 0.14 mm) is a half-plane to 1e-3.
- Equilibrium: the supports' reactions balance the applied load, and the
  applied load is the dynamics stage's contact force along the profile's
  normal, whose moment about the cam axis is the drive torque less the
  shaft's friction torque (the energy method, Quintero & Vanegas 2016 eq. 17,
  and Hren et al. eq. 29 with the cam friction f1): an independent route to
  the same torque.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from camcad.design import Design, load_design, parse_design
from camcad.fea import FeaResult, FeaSpec, PlaneModel, analyse_fea
from camcad.geometry import Cam
from camcad.pipeline import analyse
from tests.conftest import ROOT, make_design

pytest.importorskip("gmsh")
pytest.importorskip("skfem")

NU = 0.3


def _disc(plane: str) -> Design:
    return parse_design(
        {
            "cam": {"name": "disc", "base_radius": 100.0, "thickness": 10.0, "bore": 20.0},
            "follower": {"type": "translating-roller", "roller_radius": 20.0},
            "motion": [{"kind": "dwell", "angle": 360.0}],
            "dynamics": {"spring_preload": 1000.0, "gravity": False},
            "fea": {"plane": plane},
        }
    )


def _run(design: Design, spec: FeaSpec | None = None) -> FeaResult:
    analysis = analyse(design, fit=False, toolpath=False)
    return analyse_fea(
        analysis.cam,
        design.plate(),
        setup=design.dynamics_setup(),
        dynamics=analysis.dynamics,
        spec=spec or design.fea or FeaSpec(),
    )


def _hertz_axis(zeta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """σ_x/p0 and σ_z/p0 on the axis of a 2-D Hertz contact (Johnson 1985, §4.2, eq. 4.49)."""
    root = np.sqrt(1.0 + zeta**2)
    return -((1.0 + 2.0 * zeta**2) / root - 2.0 * zeta), -1.0 / root


@pytest.fixture(scope="module")
def strain_disc() -> FeaResult:
    return _run(_disc("strain"))


def test_closed_form_as_transcribed():
    zeta = np.linspace(0.0, 3.0, 300001)
    sx, sz = _hertz_axis(zeta)
    tau = 0.5 * (sx - sz)
    k = int(np.argmax(tau))
    assert tau[k] == pytest.approx(0.300, abs=0.001) and zeta[k] == pytest.approx(0.786, abs=0.002)


def test_subsurface_field_under_a_hertz_load(strain_disc: FeaResult):
    (case,) = strain_disc.cases
    c = case.case
    assert c.force == pytest.approx(1000.0) and len(strain_disc.cases) == 1  # all three angles coincide
    b, p0 = c.half_width, c.peak_pressure
    assert p0 == pytest.approx(2.0 * c.force / (math.pi * b * c.length), rel=1e-12)  # Johnson eq. 4.45
    zeta = np.linspace(0.02, 3.0, 150)
    point, normal, tangent = np.array(c.point), np.array(c.normal), np.array(c.tangent)
    xy = point[None, :] - np.outer(zeta * b, normal)
    sx, sy, txy, _ = strain_disc.stress_at(0, xy).T
    tensor = np.array([[sx, txy], [txy, sy]])  # (2, 2, n)
    along = np.einsum("i,ijn,j->n", tangent, tensor, tangent)
    across = np.einsum("i,ijn,j->n", normal, tensor, normal)
    exact_x, exact_z = _hertz_axis(zeta)
    np.testing.assert_allclose(along / p0, exact_x, atol=0.02)
    np.testing.assert_allclose(across / p0, exact_z, atol=0.02)
    tau = 0.5 * np.hypot(along - across, 2.0 * np.einsum("i,ijn,j->n", tangent, tensor, normal))
    k = int(np.argmax(tau))
    assert tau[k] / p0 == pytest.approx(0.300, rel=0.03)
    assert zeta[k] == pytest.approx(0.786, rel=0.06)


def test_peak_von_mises_plane_strain(strain_disc: FeaResult):
    (case,) = strain_disc.cases
    zeta = np.linspace(0.0, 3.0, 30001)
    sx, sz = _hertz_axis(zeta)
    vm = np.sqrt(0.5 * ((sx - sz) ** 2 + (sz - NU * (sx + sz)) ** 2 + (NU * (sx + sz) - sx) ** 2))
    k = int(np.argmax(vm))  # 0.557 p0 at 0.70 b for ν = 0.3
    assert vm[k] == pytest.approx(0.557, abs=0.001) and zeta[k] == pytest.approx(0.70, abs=0.01)
    assert case.peak.value / case.case.peak_pressure == pytest.approx(vm[k], rel=0.02)
    assert case.peak.where.startswith("under the contact")
    assert case.peak.depth / case.case.half_width == pytest.approx(zeta[k], abs=0.12)
    assert strain_disc.plane is PlaneModel.STRAIN


def test_peak_von_mises_plane_stress_is_the_surface_pressure():
    """Plane stress: σ_zz = 0, so at the surface (σ_x = σ_z = −p0) von Mises is p0, its largest value."""
    result = _run(_disc("stress"))
    (case,) = result.cases
    assert result.plane is PlaneModel.STRESS
    assert case.peak.value == pytest.approx(case.case.peak_pressure, rel=0.02)
    assert case.peak.depth is not None and case.peak.depth < 0.05 * case.case.half_width


def _keyed(path: str, **cam: float) -> Design:
    design = load_design(ROOT / "samples" / path)
    return dataclasses.replace(
        design,
        cam=dataclasses.replace(design.cam, bore=20.0, keyway_width=6.0, keyway_depth=2.8, **cam),
        # coarse: the balance holds on any mesh
        fea=FeaSpec(angles=(math.radians(200.0),), contact_divisions=4, growth=0.6),
    )


@pytest.mark.parametrize(
    ("path", "cam", "rtol"),
    [
        ("offset_roller.toml", {}, 1e-6),
        ("offset_roller.toml", {"bore": 0.0}, 1e-6),  # replaced below by a plain bore
        ("hren_tappet.toml", {}, 2e-5),  # cam friction f1 = 0.1: the friction's arm varies across the strip
        ("packaging_rocker.toml", {}, 1e-6),
    ],
    ids=["offset-roller-keyed", "offset-roller-plain", "hren-tappet-friction", "rocker"],
)
def test_equilibrium_and_torque(path: str, cam: dict[str, float], rtol: float):
    design = _keyed(path)
    if cam.get("bore") == 0.0:  # a plain bore (no keyway): held in both directions
        design = dataclasses.replace(
            design, cam=dataclasses.replace(design.cam, keyway_width=0.0, keyway_depth=0.0)
        )
    analysis = analyse(design, fit=False, toolpath=False)
    result = analyse_fea(
        analysis.cam,
        design.plate(),
        setup=design.dynamics_setup(),
        dynamics=analysis.dynamics,
        spec=design.fea,
    )
    assert len(result.cases) >= 2
    sigma = analysis.cam.sigma
    for sc in result.cases:
        c, field = sc.case, sc.field
        applied, reaction = field.applied * c.length, field.reaction * c.length
        radius = math.hypot(*c.point)
        np.testing.assert_allclose(reaction[:2], -applied[:2], rtol=0, atol=1e-6 * c.force)
        assert reaction[2] == pytest.approx(-applied[2], rel=0, abs=1e-6 * c.force * radius)
        # the contact force along the inward normal, and its friction along the tangent
        normal, tangent = np.array(c.normal), np.array(c.tangent)
        np.testing.assert_allclose(applied[:2] @ normal, -c.force, rtol=1e-6)
        # (the pressure follows the curved surface over ±b, the friction keeps the tangent at C: (b/ρ)²)
        assert abs(applied[:2] @ tangent) == pytest.approx(c.friction * c.force, abs=1e-4 * c.force)
        # its moment about the cam axis: the key carries the drive torque less the bearings' friction
        scale = c.force * math.hypot(*c.point)  # the moment's size: the force at the contact's radius
        assert abs(applied[2] + sigma * (c.torque - c.friction_torque)) <= rtol * scale
        assert sc.load_scale == pytest.approx(1.0, abs=1e-3)  # ∫ p ds = π b p0 / 2 by quadrature
        if design.cam.keyway_width > 0.0:
            # the key pushes on the flank against the load's moment: +x flank for a positive moment
            assert sc.key_flank == ("+x" if applied[2] > 0 else "-x")
            assert reaction[2] * applied[2] < 0.0
    labels = [sc.case.label for sc in result.cases]
    assert any("peak contact force" in s for s in labels) and any("peak input torque" in s for s in labels)
    assert any(
        s == "listed" and sc.case.angle_deg == pytest.approx(200.0)
        for s, sc in zip(labels, result.cases, strict=True)
    )


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    offset=st.floats(-12.0, 12.0),
    rotation=st.sampled_from(["ccw", "cw"]),
    law=st.sampled_from(["cycloidal", "poly-345", "harmonic"]),
    roller=st.floats(6.0, 15.0),
    angle=st.floats(0.0, 360.0),
)
# a contact 1e-9 rad from the profile's first node once made an edge of 5e-8 mm (skfem's inverse map failed)
@example(offset=3.25, rotation="ccw", law="cycloidal", roller=6.0, angle=5.960464477539063e-08)
def test_the_key_carries_the_drive_torque_for_any_offset_roller(
    offset: float, rotation: str, law: str, roller: float, angle: float
):
    """For all offset rollers: the load's moment about the axis = −σ(T − T_f), and the supports balance it."""
    design = make_design(
        law=law,
        base_radius=45.0,
        roller_radius=roller,
        offset=offset,
        rotation=rotation,
        lift=12.0,
        extra={
            "cam": {"bore": 16.0, "keyway_width": 5.0, "keyway_depth": 2.3},
            "dynamics": {
                "follower_mass": 0.5,
                "spring_rate": 3.0,
                "spring_preload": 80.0,
                "friction_torque": 20.0,
            },
            "fea": {"angles": [angle], "contact_divisions": 2, "growth": 1.0, "mesh_size": 20.0},
        },
    )
    result = _run(design)
    sigma = 1.0 if rotation == "ccw" else -1.0
    joints = [bp.phi for bp in Cam.from_design(design).program.breakpoints]
    for sc in result.cases:
        c = sc.case
        applied, reaction = sc.field.applied * c.length, sc.field.reaction * c.length
        scale = c.force * math.hypot(*c.point)
        # a strip lying across a joint where the curvature jumps (the harmonic law's acceleration
        # step) has its own moment, of order F·b·(jump in the lever arm over b): 2e-5 of F·r here
        at_joint = any(abs((c.phi - j + math.pi) % (2 * math.pi) - math.pi) < 1e-3 for j in joints)
        assert (
            abs(applied[2] + sigma * (c.torque - c.friction_torque)) <= (1e-4 if at_joint else 1e-6) * scale
        )
        np.testing.assert_allclose(reaction, -applied, rtol=0, atol=1e-6 * scale)
        assert sc.key_flank == ("+x" if applied[2] > 0 else "-x")
