"""Model A: contact force and input torque by the energy method.

Quintero & Vanegas (2016), section 4: at constant cam speed ω the power the
cam delivers equals the rate of change of the follower's kinetic and potential
energy plus the friction loss, which gives the input torque (eq. 18) and,
from the follower's equation of motion, the contact force (eq. 19).

Units: mm, N, kg, s, rad. The follower acceleration in time is
s̈ = a·ω² [mm/s²] with a = d²s/dφ² [mm/rad²], so the inertia force of a mass
m [kg] is m·a·ω²/1000 [N]. Torques are N·mm.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.dynamics.spring import Spring

if TYPE_CHECKING:
    from camcad.motion.program import Motion

__all__ = [
    "MM_PER_M",
    "STANDARD_GRAVITY",
    "FollowerLoad",
    "contact_force",
    "input_torque",
]

STANDARD_GRAVITY = 9.80665
"""g [m/s²]; m·g with m in kg is a force in N."""

MM_PER_M = 1000.0
"""m [kg]·s̈ [mm/s²] / MM_PER_M is a force in N."""


@dataclass(frozen=True, slots=True, kw_only=True)
class FollowerLoad:
    """What the cam has to push against: follower inertia, weight and spring.

    Attributes
    ----------
    mass
        Follower mass m [kg] (Quintero & Vanegas 2016: m_f; Hren et al.: m_z).
    spring
        Return spring: rate k [N/mm] and preload F0 [N] at s = 0.
    gravity
        True when the follower's weight opposes the rise (follower above the cam).

    Notes
    -----
    The force along the follower axis that the cam must supply is

    F(φ) = m·a·ω²/1000 + m·g + k·s + F0   [N]

    the bracket of Quintero & Vanegas (2016, eq. 18) with the spring deflection
    δ = s + F0/k, and F_s + F_g + F_p of Hren et al. (eqs. 13-15). It is
    linear in F0 and in ω², which the jump limits use:
    F = A·ω² + B with A = m·a/1000 [N·s²] and B = m·g + k·s + F0 [N].
    """

    mass: float = 0.0
    spring: Spring = field(default_factory=Spring)
    gravity: bool = True

    @property
    def weight(self) -> float:
        """m·g [N] if gravity acts, else 0 (Hren et al., eq. 14)."""
        return self.mass * STANDARD_GRAVITY if self.gravity else 0.0

    @property
    def unloaded(self) -> bool:
        """Whether B ≡ 0 at every angle: no weight, no spring rate, no preload."""
        return self.weight == 0.0 and self.spring.rate == 0.0 and self.spring.preload == 0.0

    def inertia_coefficient(self, motion: Motion) -> FloatArray:
        """Return A = m·a/1000 [N·s²], the inertia force per ω² (Hren et al., eqs. 15-16).

        Returns
        -------
        FloatArray
            (n,) A [N·s²/rad²]; the inertia force is A·ω² [N].
        """
        out = self.mass * np.asarray(motion.a, dtype=float) / MM_PER_M
        readonly(out)
        return out

    def static_force(self, motion: Motion) -> FloatArray:
        """Return B = m·g + k·s + F0 [N], the speed-independent part of the axial load.

        Returns
        -------
        FloatArray
            (n,) B [N].
        """
        out = self.weight + np.asarray(self.spring.force(motion.s), dtype=float)
        readonly(out)
        return out

    def axial_force(self, motion: Motion, *, omega: float) -> FloatArray:
        """Compute the force the cam must exert on the follower along its axis [N].

        Parameters
        ----------
        motion
            Uses ``s`` (n,) [mm] and ``a`` (n,) [mm/rad²].
        omega
            Cam speed ω [rad/s].

        Returns
        -------
        FloatArray
            (n,) F = m·s̈ + m·g + k·s + F0 [N], s̈ = a·ω² [mm/s²] / 1000 → m/s².

        Notes
        -----
        Quintero & Vanegas (2016), eq. 18 bracket (papers/README erratum).
        """
        inertia = self.inertia_coefficient(motion) * (omega * omega)  # m s̈, s̈ = a ω² (ω·ω: see jump.py)
        out = inertia + self.static_force(motion)  # Quintero & Vanegas 2016, eq. 18
        readonly(out)
        return out


def contact_force(axial: ArrayLike, pressure_angle: ArrayLike) -> FloatArray:
    """Compute the contact force between cam and follower along the common normal.

    Parameters
    ----------
    axial
        (n,) axial load F [N] from :meth:`FollowerLoad.axial_force`.
    pressure_angle
        (n,) pressure angle α [rad]; its sign does not matter.

    Returns
    -------
    FloatArray
        (n,) F_C = F / cos α [N]; negative where the cam would have to pull
        (the follower leaves the cam).

    Notes
    -----
    m_f s̈ = F_C cos α − m_f g − k δ, so F_C = (m_f s̈ + m_f g + k δ)/cos α
    (Quintero & Vanegas 2016, eq. 19, with the papers/README erratum). The
    side component F_C sin α goes into the follower guide, which the energy
    method takes as frictionless.

    References
    ----------
    .. [1] Quintero & Vanegas (2016), Use of the VAP function in the design of
       cam-follower mechanisms (../shared/papers/000_8f0d8937b22a3cde.txt).
    """
    alpha = np.asarray(pressure_angle, dtype=float)
    out = np.asarray(axial, dtype=float) / np.cos(alpha)  # Quintero & Vanegas 2016, eq. 19
    readonly(out)
    return out


def input_torque(axial: ArrayLike, v: ArrayLike, *, friction_torque: float = 0.0) -> FloatArray:
    """Compute the torque the cam shaft needs at constant speed, by the energy method.

    Parameters
    ----------
    axial
        (n,) axial load F [N] from :meth:`FollowerLoad.axial_force`.
    v
        (n,) pseudo velocity ds/dφ [mm/rad].
    friction_torque
        T_f [N·mm], constant, always opposing the rotation.

    Returns
    -------
    FloatArray
        (n,) T [N·mm], positive when the shaft drives the cam in its sense of
        rotation, negative where the spring (or gravity) drives the cam, as on
        much of the return.

    Notes
    -----
    T·ω − T_f·ω = d(E_C + E_P)/dt gives
    T = (m_f s̈ + m_f g + k δ)·ds/dφ + T_f  (Quintero & Vanegas 2016, eqs. 15-18,
    papers/README erratum): the axial load times the pseudo velocity.
    Without T_f its integral over a closed cycle is 0.
    """
    out = np.asarray(axial, dtype=float) * np.asarray(v, dtype=float) + friction_torque  # eq. 18
    readonly(out)
    return out
