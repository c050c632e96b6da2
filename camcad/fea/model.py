"""The finite-element check of the cam plate: the load cases, the model and its solution.

A 2-D model of the plate (plane stress for a thin plate, plane strain for a
thick one) in the cam frame, meshed from the exact profile, bore and keyway
(:mod:`camcad.fea.mesh`), solved with quadratic triangles
(:mod:`camcad.fea.solve`):

- **Load**: at each cam angle that matters, the contact force F of the
  dynamics stage as the Hertz pressure p(s) = p0·√(1 − s²/b²) over the
  contact strip |s| ≤ b along the profile (Johnson 1985, eq. 4.45; p0 and b
  as in :mod:`camcad.dynamics.contact`), with the sliding friction μ·p
  against the cam surface's slip where the dynamics model has friction (the
  guided tappet's f1). The 2-D model carries F/L per mm of thickness, L the
  contact length: the plate's stresses are those under the contact line.
- **Support**: the shaft holds the bore in its normal direction (a
  frictionless pin, like a CAD package's cylindrical support) and the key
  holds the keyway flank that takes the torque in its normal direction; a
  bore without a keyway is held in both directions (the torque by friction).
  The supports are stiff elastic layers, so the reactions are their forces.
- **Keyway**: its two inner corners are rounded by ``keyway_fillet`` (a sharp
  re-entrant corner has infinite stress in linear elasticity).
- **Angles**: peak contact force, peak |input torque| and peak Hertz stress
  (true extremes from the dynamics stage, one-sided at joints), and every
  angle in ``[fea] angles``.

References
----------
.. [1] Quang & Hung (2015), Computer aided cam design of roller-follower cam
   mechanism (../shared/papers/002_3938fa916e46e710.txt): the FE check of the
   plate beside the pressure-angle and contact-stress limits.
.. [2] K. L. Johnson (1985), Contact Mechanics, Cambridge University Press,
   §4.2 (line contact: pressure, half-width, subsurface stresses).
   doi:10.1017/CBO9781139171731
.. [3] S. Timoshenko & J. N. Goodier (1970), Theory of Elasticity, 3rd ed.,
   McGraw-Hill: plane stress and plane strain (§16), Lamé's thick ring (§28).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray
from camcad.angles import TWO_PI
from camcad.dynamics import DynamicsResult, analyse_dynamics
from camcad.dynamics.contact import contact_curvature, effective_modulus, hertz_half_width
from camcad.dynamics.spec import DynamicsModel, DynamicsSetup
from camcad.errors import DesignError
from camcad.extremes import Extreme, Side
from camcad.fea.mesh import (
    MAX_ELEMENTS,
    Curve,
    Loop,
    Piece,
    PlateMesh,
    Spot,
    estimated_triangles,
    mesh_region,
    smallest_mesh_size,
)
from camcad.fea.results import FeaResult, LoadCase, Peak, StressCase, peak_of
from camcad.fea.solve import ElasticPlate, Material, Support
from camcad.fea.spec import PLANE_STRAIN_RATIO, FeaSpec, PlaneModel
from camcad.findings import Finding, Severity
from camcad.geometry.cam import Cam
from camcad.geometry.plate import BoreOutline, Plate
from camcad.knobs import Knob

__all__ = [
    "EDGE_NAMES",
    "analyse_fea",
    "keyway_fillet",
    "load_cases",
    "mesh_plate",
    "plane_model",
    "plate_loops",
]

PROFILE, BORE, FLANK_POS, FLANK_NEG, KEYWAY_END, KEYWAY_FILLET = 1, 2, 3, 4, 5, 6
EDGE_NAMES = {
    PROFILE: "the profile",
    BORE: "the bore",
    FLANK_POS: "the keyway flank at +x",
    FLANK_NEG: "the keyway flank at −x",
    KEYWAY_END: "the keyway's end",
    KEYWAY_FILLET: "a keyway fillet",
}
"""What each boundary-edge tag of the plate mesh lies on."""

SUPPORT_LAYER = 1e-5
"""The supports' elastic layer is this × the bore radius thick (stiffness k = E / thickness)."""

_SAME_ANGLE = 1e-9  # rad: load cases closer than this are one case
_NEAR_CONTACT = 20.0  # half-widths: a peak this close to a contact is "under the contact"


def plane_model(spec: FeaSpec, *, thickness: float, outer_radius: float) -> PlaneModel:
    """STRESS or STRAIN: the stated one, or by thickness / outer diameter (``PLANE_STRAIN_RATIO``)."""
    if spec.plane is not PlaneModel.AUTO:
        return spec.plane
    return PlaneModel.STRAIN if thickness >= PLANE_STRAIN_RATIO * 2.0 * outer_radius else PlaneModel.STRESS


def keyway_fillet(spec: FeaSpec, bore: BoreOutline) -> float:
    """The keyway fillet radius [mm] (stated, or 5 % of the keyway width), checked to fit the keyway.

    Raises
    ------
    DesignError
        Naming ``fea.keyway_fillet`` when it is not below half the width and the flank's length.
    """
    radius = spec.keyway_fillet if spec.keyway_fillet is not None else 0.05 * bore.keyway_width
    half = 0.5 * bore.keyway_width
    flank = bore.radius + bore.keyway_depth - bore.radius * math.cos(math.asin(half / bore.radius))
    if not 0.0 < radius < min(half, flank):
        raise DesignError(
            Knob.KEYWAY_FILLET,
            f"{radius:g} mm does not fit the keyway; allowed: > 0 and < {min(half, flank):.4g} mm "
            "(half the keyway width, and the flank's length beyond the bore)",
        )
    return radius


def _line(a: tuple[float, float], b: tuple[float, float]) -> Curve:
    ax, ay = a
    dx, dy = b[0] - ax, b[1] - ay
    length = math.hypot(dx, dy)
    return lambda t: np.column_stack((ax + dx * t / length, ay + dy * t / length))


def _arc(cx: float, cy: float, r: float) -> Curve:
    return lambda t: np.column_stack((cx + r * np.cos(t), cy + r * np.sin(t)))


def plate_loops(
    cam: Cam, bore: BoreOutline, *, fillet: float, fixed: Sequence[float] = ()
) -> tuple[Loop, Loop]:
    """The plate's outline as exact curves: the profile (by φ) and the bore with its keyway.

    ``fixed`` are cam angles [rad] that must be boundary nodes (the contact strips).
    The keyway lies on +y (as :class:`~camcad.geometry.plate.BoreOutline`); its
    flank at x = +w/2 is tagged ``FLANK_POS``, the other ``FLANK_NEG``.
    """

    def profile(phi: FloatArray) -> FloatArray:
        return np.asarray(cam.profile(np.asarray(phi, dtype=float)).point, dtype=float)

    def speed(phi: FloatArray) -> FloatArray:
        d1 = cam.profile(np.asarray(phi, dtype=float)).d1
        return np.asarray(np.hypot(d1[:, 0], d1[:, 1]), dtype=float)

    outer = Loop(
        pieces=(
            Piece(
                curve=profile,
                start=0.0,
                stop=TWO_PI,
                tag=PROFILE,
                fixed=tuple(sorted({float(p) % TWO_PI for p in fixed})),
                speed=speed,
            ),
        )
    )
    r = bore.radius
    if not bore.has_keyway:
        return outer, Loop(pieces=(Piece(curve=_arc(0.0, 0.0, r), start=0.0, stop=TWO_PI, tag=BORE),))
    half, top = 0.5 * bore.keyway_width, bore.radius + bore.keyway_depth
    delta = math.asin(half / r)
    y0 = r * math.cos(delta)
    f = fillet
    pieces = [
        Piece(curve=_line((half, y0), (half, top - f)), start=0.0, stop=top - f - y0, tag=FLANK_POS),
        Piece(curve=_arc(half - f, top - f, f), start=0.0, stop=0.5 * math.pi, tag=KEYWAY_FILLET),
    ]
    if half - f > 0.0:
        pieces.append(
            Piece(
                curve=_line((half - f, top), (f - half, top)),
                start=0.0,
                stop=2.0 * (half - f),
                tag=KEYWAY_END,
            )
        )
    pieces += [
        Piece(curve=_arc(f - half, top - f, f), start=0.5 * math.pi, stop=math.pi, tag=KEYWAY_FILLET),
        Piece(curve=_line((-half, top - f), (-half, y0)), start=0.0, stop=top - f - y0, tag=FLANK_NEG),
        Piece(curve=_arc(0.0, 0.0, r), start=0.5 * math.pi + delta, stop=2.5 * math.pi - delta, tag=BORE),
    ]
    return outer, Loop(pieces=tuple(pieces))


def _strip(cam: Cam, phi: float, half_width: float, divisions: int) -> FloatArray:
    """Cam angles of the contact strip's nodes: arc length −b … +b from the contact at φ, evenly."""
    nodes_s = np.linspace(-half_width, half_width, divisions + 1)
    g, w = np.polynomial.legendre.leggauss(8)

    def arc(to: FloatArray) -> FloatArray:
        mid, half = 0.5 * (to + phi), 0.5 * (to - phi)
        d1 = cam.profile((mid[:, None] + half[:, None] * g[None, :]).ravel()).d1
        speed = np.hypot(d1[:, 0], d1[:, 1]).reshape(len(to), len(g))
        return np.asarray(half * (speed @ w), dtype=float)

    d1 = cam.profile(np.array([phi])).d1
    out = phi + nodes_s / float(np.hypot(*d1[0]))
    for _ in range(3):  # Newton on the arc length ∫|C'| dφ
        d1 = cam.profile(out).d1
        out = out - (arc(out) - nodes_s) / np.hypot(d1[:, 0], d1[:, 1])
    return out


@dataclass(frozen=True, slots=True, kw_only=True)
class _Wanted:
    label: str
    phi: float
    side: Side | None


def _wanted_angles(dynamics: DynamicsResult, spec: FeaSpec) -> list[_Wanted]:
    """The angles that matter: peak force, peak |torque|, peak Hertz stress, then the listed ones."""

    def sampled(values: FloatArray) -> Extreme:
        i = int(np.argmax(values))
        return Extreme(value=float(values[i]), phi=float(dynamics.phi[i]))

    force = dynamics.contact_force_max or sampled(dynamics.contact_force)
    tmax = dynamics.torque_max or sampled(dynamics.torque)
    tmin = dynamics.torque_min or Extreme(
        value=-sampled(-dynamics.torque).value, phi=sampled(-dynamics.torque).phi
    )
    torque = tmax if abs(tmax.value) >= abs(tmin.value) else tmin
    stress = dynamics.hertz_stress_max or sampled(dynamics.hertz_stress)
    out = [
        _Wanted(label="peak contact force", phi=force.phi, side=force.side),
        _Wanted(label="peak input torque", phi=torque.phi, side=torque.side),
        _Wanted(label="peak Hertz stress", phi=stress.phi, side=stress.side),
    ]
    out += [_Wanted(label="listed", phi=float(p) % TWO_PI, side=None) for p in spec.angles]
    merged: list[_Wanted] = []
    for w in out:
        for i, m in enumerate(merged):
            gap = abs((w.phi - m.phi + math.pi) % TWO_PI - math.pi)
            if gap < _SAME_ANGLE and w.side == m.side:
                merged[i] = _Wanted(label=f"{m.label} + {w.label}", phi=m.phi, side=m.side)
                break
        else:
            merged.append(w)
    return merged


def load_cases(
    cam: Cam, dynamics: DynamicsResult, setup: DynamicsSetup, spec: FeaSpec
) -> tuple[list[LoadCase], list[str]]:
    """The contact loads at the angles that matter, and a note for each angle that cannot be loaded.

    The force, torque and Hertz stress at each angle come from the dynamics
    stage's own model (:func:`camcad.dynamics.analyse_dynamics` at that angle,
    on the side of the joint the extreme was found on).
    """
    dyn = setup.spec
    modulus = effective_modulus(
        modulus_1=dyn.cam_modulus,
        poisson_1=dyn.cam_poisson,
        modulus_2=dyn.follower_modulus,
        poisson_2=dyn.follower_poisson,
    )
    friction = dyn.f1 if dyn.model is DynamicsModel.GUIDED_TAPPET else 0.0
    cases: list[LoadCase] = []
    skipped: list[str] = []
    for want in _wanted_angles(dynamics, spec):
        side: Side = want.side or "right"
        state = cam.state(np.array([want.phi]), side=side)
        at = analyse_dynamics(
            state.motion,
            pressure_angle=state.pressure_angle,
            profile_rho=state.profile.rho,
            setup=setup,
            cam=cam if setup.arm_angle is not None else None,
        )
        force = float(at.contact_force[0])
        where = f"{want.label} at {math.degrees(want.phi) % 360.0:.2f}°"
        if not force > 0.0:
            skipped.append(
                f"FE check: no load case for the {where}: the contact force is {force:.3g} N (no contact)"
            )
            continue
        kappa = contact_curvature(state.profile.rho, roller_radius=setup.roller_radius or None)
        b = float(hertz_half_width([force], curvature=kappa, length=setup.contact_length, modulus=modulus)[0])
        if not math.isfinite(b) or b <= 0.0:
            skipped.append(f"FE check: no load case for the {where}: conforming contact (no Hertz strip)")
            continue
        profile = state.profile
        cases.append(
            LoadCase(
                label=want.label,
                phi=want.phi,
                side=want.side,
                force=force,
                torque=float(at.torque[0]),
                friction_torque=dyn.friction_torque,
                length=setup.contact_length,
                half_width=b,
                peak_pressure=float(at.hertz_stress[0]),
                friction=friction,
                point=(float(profile.point[0, 0]), float(profile.point[0, 1])),
                normal=(float(profile.normal[0, 0]), float(profile.normal[0, 1])),
                tangent=(float(profile.tangent[0, 0]), float(profile.tangent[0, 1])),
            )
        )
    return cases, skipped


def mesh_plate(cam: Cam, plate: Plate, cases: Sequence[LoadCase], spec: FeaSpec) -> tuple[PlateMesh, float]:
    """Mesh the plate, refined under the contact strips and at the keyway; also the outer radius [mm]."""
    bore = plate.bore
    if bore is None:
        raise DesignError(
            Knob.BORE, "the finite-element check holds the plate at its bore: give the cam a bore > 0"
        )
    fillet = keyway_fillet(spec, bore) if bore.has_keyway else 0.0
    outer_radius = float(np.max(np.hypot(*cam.profile(cam.sample_phi(math.radians(1.0))).point.T)))
    h_max = spec.mesh_size if spec.mesh_size is not None else outer_radius / 10.0
    outline = cam.profile(cam.sample_phi(math.radians(1.0))).point
    x, y = outline[:, 0], outline[:, 1]
    area = 0.5 * abs(float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))) - math.pi * bore.radius**2
    if estimated_triangles(area, h_max) > MAX_ELEMENTS:
        raise DesignError(
            Knob.FEA_MESH_SIZE,
            f"{h_max:g} mm would fill the plate's {area:.0f} mm² with about "
            f"{estimated_triangles(area, h_max):.3g} triangles; allowed: at most {MAX_ELEMENTS} "
            f"(mesh_size ≥ {smallest_mesh_size(area):.3g} mm for this plate)",
        )
    fixed: list[float] = []
    spots = [Spot(centre=(0.0, 0.0), size=min(h_max, TWO_PI * bore.radius / 36.0), radius=bore.radius)]
    for c in cases:
        fixed.extend(_strip(cam, c.phi, c.half_width, spec.contact_divisions).tolist())
        spots.append(
            Spot(centre=c.point, size=2.0 * c.half_width / spec.contact_divisions, radius=c.half_width)
        )
    if bore.has_keyway:
        half, top = 0.5 * bore.keyway_width, bore.radius + bore.keyway_depth
        size = min(h_max, 0.25 * fillet)
        spots += [
            Spot(centre=(sx * (half - fillet), top - fillet), size=size, radius=fillet) for sx in (1.0, -1.0)
        ]
        y0 = math.sqrt(bore.radius**2 - half**2)
        edge = min(h_max, bore.keyway_width / 12.0)
        spots += [Spot(centre=(sx * half, y0), size=edge) for sx in (1.0, -1.0)]
    outer, hole = plate_loops(cam, bore, fillet=fillet, fixed=fixed)
    mesh = mesh_region(outer, [hole], spots, h_max=h_max, growth=spec.growth)
    return mesh, outer_radius


def _slip_sign(case: LoadCase, sigma: float) -> float:
    """+1 or −1: the friction on the cam acts along ∓ this × tangent (against the surface's slip).

    The cam surface at C moves with σω ẑ × C; a translating face moves along
    its normal, so the slip along the tangent t is σ(ẑ × C)·t.
    """
    cx, cy = case.point
    tx, ty = case.tangent
    slip = sigma * (-cy * tx + cx * ty)
    return 1.0 if slip >= 0.0 else -1.0


def _describe(mesh: PlateMesh, case: LoadCase, point: tuple[float, float], outer_radius: float) -> str:
    """Where a peak is, in words: under the contact (with its depth), at a boundary feature, or inside."""
    px, py = point
    cx, cy = case.point
    if math.hypot(px - cx, py - cy) <= _NEAR_CONTACT * case.half_width:
        depth = (cx - px) * case.normal[0] + (cy - py) * case.normal[1]
        if depth <= 1e-9 * case.half_width:
            return "under the contact, at the surface"
        return f"under the contact, {depth:.4g} mm deep ({depth / case.half_width:.2f} b)"
    ends = mesh.points[mesh.edges]  # (B, 2, 2)
    mids = 0.5 * (ends[:, 0] + ends[:, 1])
    length = np.hypot(*(ends[:, 1] - ends[:, 0]).T)
    d = np.hypot(mids[:, 0] - px, mids[:, 1] - py)
    k = int(np.argmin(d))
    if d[k] <= max(1.5 * length[k], 1e-9 * outer_radius):
        name = EDGE_NAMES[int(mesh.edge_tags[k])]
        polar = math.degrees(math.atan2(py, px)) % 360.0
        return f"at {name} (x = {px:.3f} mm, y = {py:.3f} mm; {polar:.1f}° from +x)"
    return f"inside the plate (x = {px:.3f} mm, y = {py:.3f} mm, r = {math.hypot(px, py):.3f} mm)"


def analyse_fea(
    cam: Cam, plate: Plate, *, setup: DynamicsSetup, dynamics: DynamicsResult, spec: FeaSpec
) -> FeaResult:
    """Solve the plate at every load case; the peak von Mises stress of each and the limit.

    Parameters
    ----------
    cam
        The exact cam (profile, normals, curvature at any φ).
    plate
        Thickness, bore and keyway (a bore is required).
    setup
        The dynamics stage's options (materials, contact length, friction).
    dynamics
        The dynamics stage's result (its true extremes pick the angles).
    spec
        The ``[fea]`` table.

    Raises
    ------
    DesignError
        Without a bore (``cam.bore``), or a keyway fillet that does not fit
        (``fea.keyway_fillet``).
    UsageError
        When gmsh or scikit-fem is not installed (the extra ``camcad[fea]``).
    """
    cases, skipped = load_cases(cam, dynamics, setup, spec)
    mesh, outer_radius = mesh_plate(cam, plate, cases, spec)
    plane = plane_model(spec, thickness=plate.thickness, outer_radius=outer_radius)
    dyn = setup.spec
    material = Material(modulus=dyn.cam_modulus, poisson=dyn.cam_poisson, plane=plane)
    model = ElasticPlate(mesh, material)
    assert plate.bore is not None  # mesh_plate checked it
    stiffness = material.modulus / (SUPPORT_LAYER * plate.bore.radius)
    ends = mesh.points[mesh.edges]
    mids = 0.5 * (ends[:, 0] + ends[:, 1])
    solved: list[StressCase] = []
    for case in cases:
        line_load = case.force / case.length  # N per mm of thickness
        c = np.asarray(case.point)
        t0 = np.asarray(case.tangent)
        near = np.flatnonzero(
            (mesh.edge_tags == PROFILE)
            & (np.hypot(mids[:, 0] - c[0], mids[:, 1] - c[1]) <= 2.0 * case.half_width)
        )
        b = case.half_width

        def pressure(x: FloatArray, c: FloatArray = c, t0: FloatArray = t0, b: float = b) -> FloatArray:
            """Hertz pressure per unit p0: √(1 − s²/b²), s the arc length from C (Johnson 1985, §4.2)."""
            s = (x[0] - c[0]) * t0[0] + (x[1] - c[1]) * t0[1]  # along the tangent: b ≪ ρ
            return np.asarray(np.sqrt(np.clip(1.0 - (s / b) ** 2, 0.0, None)), dtype=float)

        slip = _slip_sign(case, cam.sigma)
        mu = case.friction

        def traction(
            x: FloatArray, n: FloatArray, t0: FloatArray = t0, slip: float = slip, mu: float = mu
        ) -> FloatArray:
            p = pressure(x)
            return np.asarray(-p * n - mu * slip * p * t0[:, None, None], dtype=float)

        shape = model.load(near, lambda x, n: -pressure(x) * n)
        # the elliptical pressure has total P = π·b·p0/2 (Johnson 1985, §4.2); quadrature gets it to ~1e-5
        scale = line_load / float(np.hypot(*model.resultant(shape)[:2]))
        load = model.load(near, traction) * scale
        moment = float(model.resultant(load)[2])
        if plate.bore.has_keyway:
            flank = FLANK_POS if moment > 0.0 else FLANK_NEG  # the key pushes back against the load's moment
            key = material.modulus / (0.5 * plate.bore.keyway_width)  # the key: a layer half its width thick
            supports: tuple[Support, ...] = (
                Support(tags=(BORE,), stiffness=stiffness, normal_only=True),
                Support(tags=(flank,), stiffness=key, normal_only=True),
            )
            key_flank = "+x" if flank == FLANK_POS else "-x"
        else:
            supports = (Support(tags=(BORE,), stiffness=stiffness, normal_only=False),)
            key_flank = "bore"
        field = model.solve(supports, load)
        value, point = peak_of(field, model.nodes, model.cells)
        where = _describe(mesh, case, point, outer_radius)
        depth = None
        if where.startswith("under the contact"):
            depth = max(0.0, (c[0] - point[0]) * case.normal[0] + (c[1] - point[1]) * case.normal[1])
        solved.append(
            StressCase(
                case=case,
                field=field,
                peak=Peak(value=value, point=point, where=where, depth=depth),
                key_flank=key_flank,
                load_scale=0.5 * math.pi * case.half_width * scale / line_load,
            )
        )
    findings: list[Finding] = []
    worst = max(solved, key=lambda s: s.peak.value, default=None)
    if spec.allowable_stress is not None and worst is not None and worst.peak.value > spec.allowable_stress:
        findings.append(
            Finding(
                kind="von Mises stress",
                severity=Severity.SOFT,
                field=Knob.FEA_ALLOWABLE_STRESS,
                angle=worst.case.phi,
                value=worst.peak.value,
                limit=spec.allowable_stress,
                unit="MPa",
                message=(
                    f"FE von Mises stress {worst.peak.value:.1f} MPa exceeds the allowable "
                    f"{spec.allowable_stress:g} MPa at the {worst.case.label} ({worst.case.angle_deg:.1f}°), "
                    f"{worst.peak.where}; use a larger base radius or roller, a wider contact or a "
                    "stronger material"
                ),
            )
        )
    # an angle with no load case is worth knowing but breaks no limit
    findings += [
        Finding(kind="FE load case", severity=Severity.NOTE, field=Knob.FEA_ANGLES, message=t)
        for t in skipped
    ]
    return FeaResult(
        nodes=model.nodes,
        cells=model.cells,
        plane=plane,
        modulus=material.modulus,
        poisson=material.poisson,
        cases=tuple(solved),
        skipped=tuple(skipped),
        allowable_stress=spec.allowable_stress,
        findings=tuple(findings),
        vertices=len(mesh.points),
    )
