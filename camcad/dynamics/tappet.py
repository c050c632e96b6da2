"""Model B: a flat tappet in two guides, with Coulomb friction at three contacts.

Hren et al., section 2. The tappet carries the axial load
F = F_p + F_s + F_g (spring, inertia, weight; eqs. 13-16). It touches the cam
with normal force N1 (friction f1) and is held by two guides at distances
a_m < b_m from the cam axis with normal forces N2, N3 (friction f2, f3).
Force balance across (eq. 17) and along the axis (eq. 18) and the moment
balance about the cam axis (eq. 20) give N1 (eq. 25); the torque on the cam
shaft is eq. 29.

Conventions (the paper treats only the stroke of a clockwise cam):

- The cam-frame geometry of a counter-clockwise cam is the mirror image of the
  paper's clockwise one; every moment changes sign together, so eqs. 17-29
  hold unchanged for either sense of rotation.
- r_m is signed: the contact lies ds/dφ = v [mm] off the line through the cam
  axis parallel to the tappet (papers/README: eq. 27 reduces to |ds/dφ|; the
  sign is kept so that the return, v < 0, is right too). In eq. 29 (moments
  on the cam about its axis) the arm is v. In eq. 20 (moments on the tappet)
  the axial loads act on the tappet axis at the offset e, which adds −e·N1,
  so r_m = v − e there; for the paper's radial tappet (e = 0) both are v.
- The guide friction opposes the tappet's travel: σ = +1 on the stroke and at
  rest (as the paper, which applies its stroke equations at the ends of the
  stroke where v = 0), σ = −1 on the return (v < 0); eqs. 18 and 25 are used
  with f2, f3 replaced by σ·f2, σ·f3. The cam friction f1 keeps its sign: the
  cam surface slides across the face the same way on stroke and return.
- The torque M [N·mm] is positive when the shaft drives the cam in its sense
  of rotation; on the return it turns negative where the spring drives the cam.
- The guide forces keep the sides of Fig. 2 (N2, N3 ≥ 0 assumed by eq. 25);
  :class:`TappetForces` reports them so a caller can flag a sign change.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.errors import DesignLimitError

if TYPE_CHECKING:
    from camcad.dynamics.energy import FollowerLoad
    from camcad.motion.program import Motion

__all__ = ["GuidedTappet", "TappetForces", "tappet_forces", "travel_sign"]

# |v| below this [mm/rad] counts as rest (σ = +1, the paper's stroke equations).
_REST_PSEUDO_VELOCITY = 1e-12


@dataclass(frozen=True, slots=True, kw_only=True)
class GuidedTappet:
    """Geometry and friction of a flat tappet in two guides (Hren et al., Fig. 2).

    Attributes
    ----------
    base_radius
        r: cam base-circle radius [mm]; the face is r + s above the cam axis.
    a_m
        Distance of the near guide (force N2) from the cam axis [mm].
    b_m
        Distance of the far guide (force N3) from the cam axis [mm], > a_m.
    f1, f2, f3
        Friction coefficients cam/tappet, near guide, far guide [1].
    offset
        Follower offset e [mm] (0 in the paper).
    """

    base_radius: float
    a_m: float
    b_m: float
    f1: float = 0.0
    f2: float = 0.0
    f3: float = 0.0
    offset: float = 0.0


@dataclass(frozen=True, slots=True, kw_only=True)
class TappetForces:
    """Forces and torque of the guided tappet at each cam angle.

    Attributes
    ----------
    normal_force
        (n,) N1: normal force between cam and face [N] (eq. 25).
    guide_force_near
        (n,) N2 at the guide a_m from the cam axis [N].
    guide_force_far
        (n,) N3 at the guide b_m from the cam axis [N].
    torque
        (n,) M: drive torque on the cam shaft [N·mm] (eq. 29).
    load_ratio
        (n,) c = denominator of eq. 25 / (b_m − a_m) [1], so N1 = F/c; 1 without friction.
    """

    normal_force: FloatArray
    guide_force_near: FloatArray
    guide_force_far: FloatArray
    torque: FloatArray
    load_ratio: FloatArray


def travel_sign(v: FloatArray) -> FloatArray:
    """σ = −1 where the tappet returns (v < 0), +1 on the stroke and at rest.

    Parameters
    ----------
    v
        (n,) pseudo velocity ds/dφ [mm/rad].

    Returns
    -------
    FloatArray
        (n,) ±1.
    """
    out = np.where(np.asarray(v, dtype=float) < -_REST_PSEUDO_VELOCITY, -1.0, 1.0)
    readonly(out)
    return out


def tappet_forces(motion: Motion, *, load: FollowerLoad, omega: float, tappet: GuidedTappet) -> TappetForces:
    """Compute the normal force, guide forces and drive torque of a guided flat tappet.

    Parameters
    ----------
    motion
        Uses ``s`` [mm], ``v`` [mm/rad] and ``a`` [mm/rad²], each (n,).
    load
        Mass [kg], spring and gravity of the tappet.
    omega
        Cam speed ω [rad/s].
    tappet
        Guide distances [mm], friction coefficients, base radius [mm].

    Returns
    -------
    TappetForces
        N1, N2, N3 [N], M [N·mm] and the load ratio c [1], each (n,).

    Raises
    ------
    DesignLimitError
        If the denominator of eq. 25 is ≤ 0 somewhere: the tappet self-locks
        in its guides and no cam force can move it.

    Notes
    -----
    With F = F_p + F_s + F_g, h = r + s and the signed arms of the module
    docstring,

    - N1 = F(b_m − a_m) / [f1f3b_m + b_m − f1b_m(f3 + f2) − f1f3a_m − a_m
      + f1h(f3 + f2) + r_m(f3 + f2)]   (Hren et al., eq. 25)
    - N2 = N1(f1h + r_m − f1b_m)/(a_m − b_m)   (eq. 22)
    - N3 = N2 − f1N1   (eq. 17)
    - M = N1(v + f1h)   (eq. 29)

    References
    ----------
    .. [1] Hren, Hejma, Michna, Svoboda & Soukup, Analysis of torque cam
       mechanism (../shared/papers/003_738e73ff455db323.txt).
    """
    s = np.asarray(motion.s, dtype=float)
    v = np.asarray(motion.v, dtype=float)
    a_m, b_m = tappet.a_m, tappet.b_m
    f1 = tappet.f1
    sigma = travel_sign(v)
    f2, f3 = sigma * tappet.f2, sigma * tappet.f3  # guide friction opposes the travel
    h = tappet.base_radius + s  # arm of the cam friction f1·N1 about the cam axis
    r_m = v - tappet.offset  # eq. 20 arm of N1 (eq. 27; papers/README: r_m = ds/dφ)
    axial = load.axial_force(motion, omega=omega)  # F_p + F_s + F_g, eqs. 13-16
    denominator = (
        f1 * f3 * b_m
        + b_m
        - f1 * b_m * (f3 + f2)
        - f1 * f3 * a_m
        - a_m
        + f1 * h * (f3 + f2)
        + r_m * (f3 + f2)
    )  # Hren et al., eq. 25 (denominator)
    if np.any(denominator <= 0.0):
        k = int(np.argmin(denominator))
        raise DesignLimitError(
            f"the guided tappet self-locks at φ = {np.degrees(motion.phi[k]):.1f}°: the "
            f"denominator of Hren et al. eq. 25 is {denominator[k]:.4g} mm ≤ 0; lower the "
            "friction coefficients or move the guides apart (raise b_m − a_m)"
        )
    n1 = axial * (b_m - a_m) / denominator  # Hren et al., eq. 25
    n2 = n1 * (f1 * h + r_m - f1 * b_m) / (a_m - b_m)  # eq. 22 solved for N2
    n3 = n2 - f1 * n1  # eq. 17
    torque = n1 * (v + f1 * h)  # Hren et al., eq. 29, arm about the cam axis
    ratio = denominator / (b_m - a_m)
    out = TappetForces(
        normal_force=n1,
        guide_force_near=n2,
        guide_force_far=n3,
        torque=torque,
        load_ratio=ratio,
    )
    readonly(n1, n2, n3, torque, ratio)
    return out
