"""The follower train as a linear lumped model: masses, springs and dampers in one coordinate.

Sign conventions (Rothbart 2004, ch. 13; Norton 2009, §15.3): s(φ) is the
cam's lift at the contact, q₀ the mass at the contact, q_out the output (the
same mass in the single-mass model), every coordinate positive along the rise.
A spring of rate k_f and a damper c_f join the contact to q₀; the two-mass
model adds k₂, c₂ between q₀ and q₁ = q_out. The return spring (rate k_s,
preload F₀) and the weight act on the output::

    single mass:  m ẍ + c (ẋ − ṡ) + k_f (x − s) + k_s x + F₀ = 0
    two masses:   m₁ ẍ₁ + c_f (ẋ₁ − ṡ) + k_f (x₁ − s) + c₂ (ẋ₁ − ẋ₂) + k₂ (x₁ − x₂) = −m₁ g
                  m₂ ẍ₂ + c₂ (ẋ₂ − ẋ₁) + k₂ (x₂ − x₁) + k_s x₂ + F₀ = −m₂ g

The contact force is F = k_f (s − q₀) + c_f (ṡ − q̇₀) [N]. An oscillating
follower uses the same form in ψ [rad] with the arm's inertia [kg·mm²] and
torsional rates [N·mm/rad]; F is then a moment about the pivot [N·mm].
Units: mm (rad), s, N; a mass m [kg] enters as m/1000 [N·s²/mm].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.dynamics.energy import MM_PER_M, STANDARD_GRAVITY
from camcad.dynamics.spec import DynamicsSpec
from camcad.dynamics.spring import spring_from_spec
from camcad.dynamics.vibration.spec import TrainModel, VibrationSpec
from camcad.errors import DesignError
from camcad.knobs import Knob

__all__ = ["Train", "train_from_specs"]

_RAD_PER_DEG = math.pi / 180.0


@dataclass(frozen=True, slots=True, kw_only=True)
class Train:
    """A linear follower train (see the module docstring for the equations).

    Attributes
    ----------
    mass
        (dof,) masses [N·s²/mm] (kg/1000), or inertias [N·mm·s²/rad] for an arm.
    contact_rate, contact_damping
        k_f [N/mm] and c_f [N·s/mm] between the cam contact and mass 0.
    coupling_rate, coupling_damping
        k₂, c₂ between mass 0 and mass 1 (two-mass model; else 0).
    spring_rate, preload
        The return spring on the output: k_s [N/mm] and F₀ [N] at q = 0.
    weight
        (dof,) constant load on each mass against the rise [N] (m_i·g, or 0).
    unit
        Generalised units per unit of the motion's lift: 1 (mm) or π/180
        (an arm's lift is in degrees of swing, its coordinate in rad).
    """

    mass: tuple[float, ...]
    contact_rate: float
    contact_damping: float = 0.0
    coupling_rate: float = 0.0
    coupling_damping: float = 0.0
    spring_rate: float = 0.0
    preload: float = 0.0
    weight: tuple[float, ...] = (0.0,)
    unit: float = 1.0

    @property
    def dof(self) -> int:
        """Number of masses (1 or 2)."""
        return len(self.mass)

    def matrices(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Mass, damping and stiffness matrices M, C, K (dof, dof) of M q̈ + C q̇ + K q = inputs."""
        n = self.dof
        m = np.diag(np.asarray(self.mass, dtype=float))
        c = np.zeros((n, n))
        k = np.zeros((n, n))
        c[0, 0] += self.contact_damping
        k[0, 0] += self.contact_rate
        if n == 2:
            c[:, :] += self.coupling_damping * np.array([[1.0, -1.0], [-1.0, 1.0]])
            k[:, :] += self.coupling_rate * np.array([[1.0, -1.0], [-1.0, 1.0]])
        k[-1, -1] += self.spring_rate
        return m, c, k

    def state_space(self) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """First-order form ż = A z + b_s s + b_v ṡ + f of the state z = (q, q̇).

        Returns
        -------
        tuple
            A (2·dof, 2·dof) [1/s, 1/s²], b_s and b_v (2·dof,) (the input s,
            ṡ in generalised units), f (2·dof,) the constant load's part.
        """
        n = self.dof
        m, c, k = self.matrices()
        minv = np.linalg.inv(m)
        a = np.zeros((2 * n, 2 * n))
        a[:n, n:] = np.eye(n)
        a[n:, :n] = -minv @ k
        a[n:, n:] = -minv @ c
        bs = np.zeros(2 * n)
        bv = np.zeros(2 * n)
        bs[n:] = minv[:, 0] * self.contact_rate
        bv[n:] = minv[:, 0] * self.contact_damping
        load = np.asarray(self.weight, dtype=float).copy()
        load[-1] += self.preload
        f = np.zeros(2 * n)
        f[n:] = -minv @ load
        return a, bs, bv, f

    def natural_frequencies(self) -> FloatArray:
        """Undamped natural frequencies ω_n [rad/s], ascending (dof,)."""
        m, _, k = self.matrices()
        w2 = np.linalg.eigvals(np.linalg.solve(m, k)).real
        out = np.asarray(np.sqrt(np.sort(np.maximum(w2, 0.0))), dtype=float)
        readonly(out)
        return out


def train_from_specs(vib: VibrationSpec, dyn: DynamicsSpec, *, arm_angle: float | None = None) -> Train:
    """Build the train a ``[vibration]`` and a ``[dynamics]`` table describe.

    Parameters
    ----------
    vib
        The ``[vibration]`` table (validated here).
    dyn
        The ``[dynamics]`` table: ``follower_mass`` [kg], the return spring,
        ``gravity``; for an arm ``arm_inertia`` [kg·mm²], the torsional or
        lever spring and ``cg_distance``.
    arm_angle
        An oscillating follower's arm direction at ψ = 0 [rad]; ``None`` for a
        translating follower.

    Returns
    -------
    Train
        With c = 2ζ√(k·m) for each spring of the train (Rothbart 2004, ch. 13).

    Notes
    -----
    On an arm the weight's moment −m·g·c_g·cos(θ₀ − ψ) (:mod:`camcad.dynamics.arm`)
    is linearised about ψ = 0 (its rate −m·g·c_g·sin θ₀ joins k_s): the train
    model is linear.
    """
    arm = arm_angle is not None
    vib.validate(arm=arm)
    zeta = vib.damping_ratio
    g = STANDARD_GRAVITY if dyn.gravity else 0.0
    if arm:
        assert arm_angle is not None and vib.stiffness_torsional is not None
        inertia = dyn.arm_inertia / MM_PER_M
        if inertia <= 0.0:
            raise DesignError(Knob.ARM_INERTIA, f"{dyn.arm_inertia!r} must be > 0 for [vibration]")
        if dyn.spring_arm is not None:
            rate, preload = dyn.spring_rate * dyn.spring_arm**2, dyn.spring_preload * dyn.spring_arm
        else:
            rate, preload = dyn.spring_rate_torsional, dyn.spring_preload_torsional
        wr = dyn.follower_mass * g * dyn.cg_distance
        rate -= wr * math.sin(arm_angle)  # d/dψ of −m g c_g cos(θ₀ − ψ) at ψ = 0
        preload -= wr * math.cos(arm_angle)
        kf = vib.stiffness_torsional
        return Train(
            mass=(inertia,),
            contact_rate=kf,
            contact_damping=2.0 * zeta * math.sqrt(kf * inertia),
            spring_rate=rate,
            preload=preload,
            weight=(0.0,),
            unit=_RAD_PER_DEG,
        )
    assert vib.stiffness is not None
    spring = spring_from_spec(dyn)
    kf = vib.stiffness
    if vib.model is TrainModel.TWO_MASS:
        assert vib.mass_1 is not None and vib.mass_2 is not None and vib.stiffness_2 is not None
        m1, m2 = vib.mass_1 / MM_PER_M, vib.mass_2 / MM_PER_M
        k2 = vib.stiffness_2
        return Train(
            mass=(m1, m2),
            contact_rate=kf,
            contact_damping=2.0 * zeta * math.sqrt(kf * m1),
            coupling_rate=k2,
            coupling_damping=2.0 * zeta * math.sqrt(k2 * m2),
            spring_rate=spring.rate,
            preload=spring.preload,
            weight=(vib.mass_1 * g, vib.mass_2 * g),
        )
    if dyn.follower_mass <= 0.0:
        raise DesignError(Knob.FOLLOWER_MASS, f"{dyn.follower_mass!r} must be > 0 for [vibration]")
    m = dyn.follower_mass / MM_PER_M
    return Train(
        mass=(m,),
        contact_rate=kf,
        contact_damping=2.0 * zeta * math.sqrt(kf * m),
        spring_rate=spring.rate,
        preload=spring.preload,
        weight=(dyn.follower_mass * g,),
    )
