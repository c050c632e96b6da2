"""The energy method for an oscillating follower: moments about the arm's pivot.

Quintero & Vanegas (2016, eqs. 15-19) balance the power the cam delivers
against the follower's kinetic and potential energy; for an arm swinging by
ψ(φ) about its pivot the same balance (Norton 2009, §8.9; Rothbart 2004,
ch. 10) reads

    T·ω = d/dt(½·I·ψ̇² + V(ψ)) + T_f·ω,   T = M·ψ′ + T_f,
    M(φ) = I·ψ″·ω²/1000 + M_s(ψ) + M_g(ψ)   [N·mm]

with ψ′ = dψ/dφ, I [kg·mm²] the arm's moment of inertia about the pivot
(kg·mm²·rad/s² / 1000 = N·mm), M_s the spring's moment and M_g gravity's.
The contact force F_C along the common normal does the same virtual work as
M: F_C·c = M with c = r·cos α [mm], r the distance from the pivot to the
driven point (roller centre, or the contact on a face) and α the pressure
angle. M is linear in the preload and in ω², as for a slide (A·ω² + B), so
the jump limits of :mod:`camcad.dynamics.jump` apply with c in place of cos α.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.dynamics.energy import MM_PER_M, STANDARD_GRAVITY

if TYPE_CHECKING:
    from camcad.motion.program import Motion

__all__ = ["ArmLoad", "arm_speed"]

_RAD_PER_DEG = math.pi / 180.0


def arm_speed(motion: Motion) -> FloatArray:
    """ψ′ = dψ/dφ [rad/rad] from the motion (whose lift is in degrees of swing)."""
    out = np.asarray(motion.v, dtype=float) * _RAD_PER_DEG
    readonly(out)
    return out


@dataclass(frozen=True, slots=True, kw_only=True)
class ArmLoad:
    """What the cam has to turn against on an oscillating arm: inertia, spring and weight.

    Attributes
    ----------
    inertia
        I [kg·mm²], the arm with its roller about the pivot.
    spring_rate
        Rate of the spring's moment about the pivot [N·mm/rad]: a torsion
        spring's, or k·r_s² for a linear spring of rate k [N/mm] acting
        perpendicular to the arm at lever r_s [mm] (arc deflection r_s·ψ).
    preload
        The spring's moment at ψ = 0 [N·mm] (F0·r_s for a linear spring).
    mass
        The arm's mass [kg], for its weight.
    cg_distance
        Distance of its centre of mass from the pivot [mm], along the arm.
    arm_angle
        The arm's direction at ψ = 0, machine frame [rad]; the arm turns
        clockwise by ψ on a rise (the machine's gravity points along −y).
    """

    inertia: float = 0.0
    spring_rate: float = 0.0
    preload: float = 0.0
    mass: float = 0.0
    cg_distance: float = 0.0
    arm_angle: float = 0.0

    def _psi(self, motion: Motion) -> FloatArray:
        return np.asarray(motion.s, dtype=float) * _RAD_PER_DEG

    @property
    def unloaded(self) -> bool:
        """Whether B ≡ 0 at every arm angle: no spring moment, no preload, no weight's moment."""
        return self.spring_rate == 0.0 and self.preload == 0.0 and self.mass * self.cg_distance == 0.0

    def inertia_coefficient(self, motion: Motion) -> FloatArray:
        """A = I·ψ″/1000 [N·mm·s²]: the inertia moment per ω²."""
        out = self.inertia * np.asarray(motion.a, dtype=float) * _RAD_PER_DEG / MM_PER_M
        readonly(out)
        return out

    def static_force(self, motion: Motion) -> FloatArray:
        """B = M_s + M_g [N·mm]: spring moment k_t·ψ + M0 and the weight's moment against a rise.

        The weight m·g at G = pivot + c_g·(cos(θ0 − ψ), sin(θ0 − ψ)) does virtual
        work −m·g·δy_G, so the moment the cam must supply is
        M_g = −m·g·c_g·cos(θ0 − ψ) (positive when the rise lifts G).
        """
        psi = self._psi(motion)
        weight = -self.mass * STANDARD_GRAVITY * self.cg_distance * np.cos(self.arm_angle - psi)
        out = self.spring_rate * psi + self.preload + weight
        readonly(out)
        return out

    def axial_force(self, motion: Motion, *, omega: float) -> FloatArray:
        """M = A·ω² + B [N·mm]: the moment about the pivot the cam must supply."""
        out = self.inertia_coefficient(motion) * (omega * omega) + self.static_force(
            motion
        )  # ω·ω: see jump.py
        readonly(out)
        return out
