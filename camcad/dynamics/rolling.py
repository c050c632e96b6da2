"""How the contact moves: over the cam, over the follower, and how fast the surfaces slide.

The life and film analyses need three speeds at every cam angle, all along
the common tangent t of the contact:

- w, the speed at which the contact runs over the cam profile: |dS/dφ|·ω,
  S the profile's arc length (|``profile.d1``|·ω);
- the slip, the follower's material velocity relative to the cam's at the
  contact: 0 for a roller in pure rolling; for a face, (v_f − v_cam)·t with
  v_cam = σω ẑ × C the cam's and v_f the follower's material velocity
  (a slide: ṡ along its axis; an arm: ψ̇ ẑ × (C − pivot));
- the entraining speed u = |slip/2 − w| (:func:`camcad.dynamics.film.entraining_speed`).

Only the follower interface (its guide) is used, never its kind.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.dynamics.film import entraining_speed

if TYPE_CHECKING:
    from camcad.geometry.cam import Cam
    from camcad.geometry.curves import CurveSample
    from camcad.motion.program import Motion

__all__ = ["ContactMotion", "contact_motion"]


@dataclass(frozen=True, slots=True, kw_only=True)
class ContactMotion:
    """The contact's speeds over the cam turn, arrays (n,).

    Attributes
    ----------
    arc_speed
        |dS/dφ| [mm/rad]: the contact's speed along the profile per radian of cam.
    contact_speed
        w = arc_speed·ω [mm/s].
    slip
        Follower material velocity relative to the cam's at the contact, along
        the profile tangent [mm/s]; 0 for a roller (pure rolling).
    sliding_speed
        |slip| [mm/s].
    entraining_speed
        u = |slip/2 − w| [mm/s].
    rolling
        Whether the follower rolls (a roller) rather than slides (a face).
    """

    arc_speed: FloatArray
    contact_speed: FloatArray
    slip: FloatArray
    sliding_speed: FloatArray
    entraining_speed: FloatArray
    rolling: bool


def contact_motion(
    cam: Cam,
    phi: ArrayLike,
    *,
    omega: float,
    profile: CurveSample | None = None,
    motion: Motion | None = None,
) -> ContactMotion:
    """The contact's speeds at cam angles φ.

    Parameters
    ----------
    cam
        The exact cam (its follower's guide tells how the follower moves).
    phi
        (n,) cam angles [rad].
    omega
        Cam speed ω [rad/s].
    profile, motion
        ``cam.profile(phi)`` and ``cam.motion(phi)`` if already computed.

    Returns
    -------
    ContactMotion

    Notes
    -----
    A radial translating flat face gives sliding ω·(r_b + s) and entraining
    ω·(r_b + s + 2a)/2, a = d²s/dφ² (Dowson & Higginson 1977, the cam and
    flat tappet; Rothbart 2004, §9.7).
    """
    p = np.asarray(phi, dtype=float).ravel()
    prof = cam.profile(p) if profile is None else profile
    d1 = np.asarray(prof.d1, dtype=float)
    tangent = np.asarray(prof.tangent, dtype=float)
    arc = np.hypot(d1[:, 0], d1[:, 1])
    w = np.einsum("ij,ij->i", d1, tangent) * omega  # signed along t (≥ 0 but at a cusp)
    if cam.follower.rolls:
        slip = np.zeros_like(p)
    else:
        contact = cam.machine_points(p, np.asarray(prof.point, dtype=float))  # machine frame
        t_machine = cam.to_machine(p, tangent)
        guide = cam.follower.guide
        direction = guide.driven(contact)
        m = cam.motion(p) if motion is None else motion
        rate = np.asarray(m.v, dtype=float) * omega  # ṡ [mm/s] or ψ̇ [deg/s]
        if guide.pivot is not None:
            lever = np.hypot(*(contact - np.asarray(guide.pivot, dtype=float)).T)
            rate = np.radians(rate) * lever  # ψ̇ r: the arm's point at the contact [mm/s]
        follower = rate[:, None] * direction
        cam_velocity = omega * cam.surface_rate(contact)  # σω ẑ × C on a disc, (−cω, 0) on a bar
        slip = np.einsum("ij,ij->i", follower - cam_velocity, t_machine)
    u = entraining_speed(w, slip)
    sliding = np.abs(slip)
    readonly(arc, w, slip, sliding)
    return ContactMotion(
        arc_speed=arc,
        contact_speed=w,
        slip=slip,
        sliding_speed=sliding,
        entraining_speed=u,
        rolling=cam.follower.rolls,
    )
