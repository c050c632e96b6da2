"""The follower's return spring: rate and preload, given directly or by the coil.

A design gives the spring either by its rate k [N/mm] and preload F0 [N] (the
force at s = 0), or by the geometry of a helical compression spring (wire
diameter, mean coil diameter, active coils, shear modulus) and its preload
deflection y1 [mm] (Hren et al., eq. 13). Either way the spring force is
F_p = k·s + F0 [N] with s the follower displacement [mm].
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly

if TYPE_CHECKING:
    from camcad.dynamics.spec import DynamicsSpec

__all__ = ["Spring", "coil_spring_rate", "spring_from_spec"]


def coil_spring_rate(
    *, wire_diameter: float, coil_diameter: float, active_coils: float, shear_modulus: float
) -> float:
    """Compute the rate of a helical compression spring from its geometry.

    Parameters
    ----------
    wire_diameter
        Wire diameter d_p [mm].
    coil_diameter
        Mean (pitch) coil diameter D_p [mm].
    active_coils
        Number of active coils n_p [1].
    shear_modulus
        Shear modulus G of the wire [MPa = N/mm²].

    Returns
    -------
    float
        Spring rate k [N/mm].

    Notes
    -----
    k = G·d_p⁴ / (8·n_p·D_p³)  (Hren et al., eq. 13), the textbook rate
    that neglects the direct-shear (Wahl) correction.

    References
    ----------
    .. [1] Hren, Hejma, Michna, Svoboda & Soukup, Analysis of torque cam
       mechanism (../shared/papers/003_738e73ff455db323.txt).

    Examples
    --------
    >>> coil_spring_rate(wire_diameter=5.0, coil_diameter=25.0, active_coils=12.5,
    ...                  shear_modulus=79000.0)
    31.6
    """
    # Hren et al., eq. 13
    return shear_modulus * wire_diameter**4 / (8.0 * active_coils * coil_diameter**3)


@dataclass(frozen=True, slots=True, kw_only=True)
class Spring:
    """A linear return spring acting on the follower.

    Attributes
    ----------
    rate
        k [N/mm].
    preload
        F0 [N]: the spring force with the follower on the base circle (s = 0).
    """

    rate: float = 0.0
    preload: float = 0.0

    def force(self, s: ArrayLike) -> FloatArray:
        """Spring force F_p = k·s + F0 [N] at displacements ``s`` [mm] (Hren et al., eq. 13)."""
        out = self.rate * np.asarray(s, dtype=float) + self.preload
        readonly(out)
        return out

    @property
    def preload_deflection(self) -> float:
        """Preload deflection y1 = F0/k [mm]; ``inf`` for a preloaded zero-rate spring, 0 if unloaded."""
        if self.rate > 0.0:
            return self.preload / self.rate
        return float("inf") if self.preload > 0.0 else 0.0


def spring_from_spec(spec: DynamicsSpec) -> Spring:
    """Build the spring a ``[dynamics]`` table describes.

    Parameters
    ----------
    spec
        Dynamics settings. With ``wire_diameter`` set (and so, by validation,
        ``coil_diameter``, ``active_coils`` and ``shear_modulus``), the rate
        comes from the coil by :func:`coil_spring_rate` and the preload is
        k·``preload_deflection``; without ``preload_deflection`` the preload
        is ``spring_preload``. Otherwise ``spring_rate`` and
        ``spring_preload`` are used as given.

    Returns
    -------
    Spring
        Rate [N/mm] and preload [N].
    """
    if not spec.uses_coil_spring:
        return Spring(rate=spec.spring_rate, preload=spec.spring_preload)
    assert spec.wire_diameter is not None and spec.coil_diameter is not None
    assert spec.active_coils is not None and spec.shear_modulus is not None
    rate = coil_spring_rate(
        wire_diameter=spec.wire_diameter,
        coil_diameter=spec.coil_diameter,
        active_coils=spec.active_coils,
        shear_modulus=spec.shear_modulus,
    )
    if spec.preload_deflection is None:
        return Spring(rate=rate, preload=spec.spring_preload)
    return Spring(rate=rate, preload=rate * spec.preload_deflection)  # Hren et al., eq. 13
