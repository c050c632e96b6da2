"""The outcome of the finite-element check: load cases, fields, peaks and findings.

No file I/O here: :meth:`FeaResult.summary` gives the ``fea`` section of
``summary.json``; :mod:`camcad.export.stress` writes the fields.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from camcad._typing import FloatArray
from camcad.extremes import SIDE_WORDS, Side
from camcad.fea.mesh import IntArray
from camcad.fea.solve import Field, principal_stresses, stress_at, von_mises
from camcad.fea.spec import PlaneModel
from camcad.findings import Finding

__all__ = ["FeaResult", "LoadCase", "Peak", "StressCase"]


@dataclass(frozen=True, slots=True, kw_only=True)
class LoadCase:
    """One contact load on the plate, at one cam angle (cam frame).

    Attributes
    ----------
    label
        Why this angle: ``"peak contact force"``, ``"peak input torque"``,
        ``"peak Hertz stress"`` or ``"listed"`` (``[fea] angles``); several
        joined by ``" + "`` when they fall on one angle.
    phi, side
        Cam angle [rad] and the one-sided limit at a joint (or None).
    force
        Contact force F [N] (dynamics).
    torque
        Drive torque T [N·mm] (dynamics, shaft friction included).
    friction_torque
        The shaft's bearing friction T_f [N·mm]: it acts on the shaft, so the
        key carries T − T_f.
    length
        Contact length L [mm]: the 2-D model carries F/L per mm of thickness.
    half_width, peak_pressure
        Hertz half-width b [mm] and peak pressure p0 [MPa] (Johnson 1985, eq. 4.45).
    friction
        Coefficient of the sliding friction at the contact (the guided
        tappet's f1; 0 for a roller or the energy model).
    point, normal, tangent
        Contact point [mm], outward unit normal and unit tangent (increasing φ) of the profile.
    """

    label: str
    phi: float
    side: Side | None
    force: float
    torque: float
    friction_torque: float
    length: float
    half_width: float
    peak_pressure: float
    friction: float
    point: tuple[float, float]
    normal: tuple[float, float]
    tangent: tuple[float, float]

    @property
    def angle_deg(self) -> float:
        """φ in degrees, in [0, 360)."""
        return math.degrees(self.phi) % 360.0


@dataclass(frozen=True, slots=True, kw_only=True)
class Peak:
    """The largest von Mises stress of a load case and where it is."""

    value: float  # MPa
    point: tuple[float, float]  # mm, cam frame
    where: str  # one phrase for a person
    depth: float | None = None  # mm below the contact surface, when under a contact


@dataclass(frozen=True, slots=True, kw_only=True)
class StressCase:
    """The solution of one load case."""

    case: LoadCase
    field: Field
    peak: Peak
    key_flank: str  # "+x", "-x" (the keyway flank that takes the torque) or "bore" (no keyway)
    load_scale: float  # exact resultant / quadrature resultant of the Hertz pressure (≈ 1)

    @property
    def von_mises(self) -> FloatArray:
        """(N2,) nodal von Mises stress [MPa]."""
        return self.field.von_mises

    @property
    def principal(self) -> FloatArray:
        """(N2, 3) nodal principal stresses σ1 ≥ σ2 ≥ σ3 [MPa]."""
        return principal_stresses(self.field.stress)


@dataclass(frozen=True, slots=True, kw_only=True)
class FeaResult:
    """The finite-element check of the cam plate.

    Attributes
    ----------
    nodes
        (N2, 2) P2 node coordinates [mm] (vertices, then edge middles), cam frame.
    cells
        (M, 6) quadratic triangles (VTK's node order: corners, then the
        middles of edges 01, 12, 20).
    plane
        The 2-D hypothesis used (STRESS or STRAIN).
    modulus, poisson
        The cam's E [MPa] and ν.
    cases
        One solution per load case.
    skipped
        Why an angle could not be loaded (no contact, conforming contact); each is also a NOTE finding.
    allowable_stress
        ``[fea] allowable_stress`` [MPa] or None.
    findings
        The broken limit (peak von Mises over the allowable), if any, then a note per skipped angle.
    """

    nodes: FloatArray
    cells: IntArray
    plane: PlaneModel
    modulus: float
    poisson: float
    cases: tuple[StressCase, ...]
    skipped: tuple[str, ...] = ()
    allowable_stress: float | None = None
    findings: tuple[Finding, ...] = ()
    vertices: int = 0

    def stress_at(self, case: int, points: FloatArray) -> FloatArray:
        """(n, 4) σ_xx, σ_yy, τ_xy, σ_zz [MPa] of ``cases[case]`` at points (n, 2) of the plate [mm]."""
        return stress_at(self.nodes, self.cells, self.cases[case].field.element_stress, points)

    @property
    def peak(self) -> StressCase | None:
        """The case with the largest von Mises stress (None without cases)."""
        return max(self.cases, key=lambda c: c.peak.value, default=None)

    def summary(self) -> dict[str, Any]:
        """The ``fea`` section of ``summary.json`` (plain Python values, angles in degrees)."""
        worst = self.peak
        out: dict[str, Any] = {
            "plane": self.plane.value,
            "nodes": len(self.nodes),
            "elements": len(self.cells),
            "element": "6-node triangle (P2, isoparametric)",
            "von_mises_max_MPa": None if worst is None else worst.peak.value,
            "von_mises_max_angle_deg": None if worst is None else round(worst.case.angle_deg, 6),
            "von_mises_max_where": None if worst is None else worst.peak.where,
            "allowable_stress_MPa": self.allowable_stress,
            "cases": [],
            "skipped": list(self.skipped),
        }
        for i, sc in enumerate(self.cases, start=1):
            c = sc.case
            out["cases"].append(
                {
                    "case": i,
                    "label": c.label,
                    "angle_deg": round(c.angle_deg, 6),
                    "side": None if c.side is None else SIDE_WORDS[c.side],
                    "contact_force_N": c.force,
                    "torque_Nmm": c.torque,
                    "hertz_stress_MPa": c.peak_pressure,
                    "hertz_half_width_mm": c.half_width,
                    "friction": c.friction,
                    "von_mises_max_MPa": sc.peak.value,
                    "von_mises_max_x_mm": sc.peak.point[0],
                    "von_mises_max_y_mm": sc.peak.point[1],
                    "von_mises_max_where": sc.peak.where,
                    "von_mises_max_depth_mm": sc.peak.depth,
                    "key_flank": sc.key_flank,
                    "applied_N": [
                        float(sc.field.applied[0] * c.length),
                        float(sc.field.applied[1] * c.length),
                    ],
                    "applied_moment_Nmm": float(sc.field.applied[2] * c.length),
                    "reaction_N": [
                        float(sc.field.reaction[0] * c.length),
                        float(sc.field.reaction[1] * c.length),
                    ],
                    "reaction_moment_Nmm": float(sc.field.reaction[2] * c.length),
                }
            )
        return out


def peak_of(field: Field, nodes: FloatArray, cells: IntArray) -> tuple[float, tuple[float, float]]:
    """The largest von Mises stress over every element's six nodes [MPa], and its node [mm].

    The FE stress is linear in a straight-sided triangle and von Mises is a
    convex function of the stress, so its largest value in a triangle is at
    a corner: the maximum over the element nodes is the field's maximum.
    """
    vm = von_mises(field.element_stress)  # (M, 6)
    m, k = np.unravel_index(int(np.argmax(vm)), vm.shape)
    x, y = nodes[cells[m, k]]
    return float(vm[m, k]), (float(x), float(y))
