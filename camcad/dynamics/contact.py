"""Hertz line contact between the cam and a roller or a flat face.

The cam and the roller are two parallel cylinders pressed together over a
length L: the contact is a strip of half-width b with an elliptical pressure
distribution whose peak p0 is the largest contact stress σ_max. A flat face is
the limit of an infinitely large roller.

Units: force N, lengths mm, moduli and stresses MPa (N/mm²).
"""

from __future__ import annotations

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly

__all__ = [
    "contact_curvature",
    "driving_curvature",
    "effective_modulus",
    "hertz_half_width",
    "hertz_stress",
]


def effective_modulus(*, modulus_1: float, poisson_1: float, modulus_2: float, poisson_2: float) -> float:
    """Compute the contact (plane-strain) modulus E* of two elastic bodies.

    Parameters
    ----------
    modulus_1, modulus_2
        Young's moduli E1, E2 [MPa].
    poisson_1, poisson_2
        Poisson ratios ν1, ν2 [1].

    Returns
    -------
    float
        E* [MPa] with 1/E* = (1 − ν1²)/E1 + (1 − ν2²)/E2 (Johnson 1985, §4.2).

    Examples
    --------
    >>> round(effective_modulus(modulus_1=206000.0, poisson_1=0.3,
    ...                         modulus_2=206000.0, poisson_2=0.3), 1)
    113186.8
    """
    compliance = (1.0 - poisson_1**2) / modulus_1 + (1.0 - poisson_2**2) / modulus_2
    return 1.0 / compliance  # Johnson 1985, §4.2


def _is_roller(roller_radius: float | FloatArray | None) -> bool:
    """Whether r_f is a roller's: not None and not 0 (a batch's per-angle radii, all of one follower)."""
    return roller_radius is not None and bool(np.all(np.asarray(roller_radius, dtype=float) != 0.0))


def contact_curvature(profile_rho: ArrayLike, *, roller_radius: float | None) -> FloatArray:
    """Compute the relative curvature 1/R* of the cam profile and the follower [1/mm].

    Parameters
    ----------
    profile_rho
        (n,) signed radius of curvature of the cam profile at the contact [mm]:
        positive convex, negative concave, ``inf`` straight.
    roller_radius
        Roller radius r_f [mm]; ``None`` or 0 for a flat face.

    Returns
    -------
    FloatArray
        (n,) 1/R* [1/mm]:

        - convex cam and roller: 1/ρ + 1/r_f
        - concave cam and roller: 1/r_f − 1/|ρ| (the same formula with ρ < 0)
        - flat face: 1/ρ

        Values ≤ 0 (a straight flank under a flat face, or a concave pocket
        no sharper than the roller) are returned as 0: conforming contact,
        where the Hertz stress formula gives 0.

    Notes
    -----
    1/R = 1/R1 + 1/R2 with a concave surface's radius negative
    (Johnson 1985, §4.3; Norton 2009, ch. 7).
    """
    rho = np.asarray(profile_rho, dtype=float)
    with np.errstate(divide="ignore"):
        kappa = 1.0 / rho  # 0 where ρ = ±inf, inf at a cusp (ρ = 0)
    if _is_roller(roller_radius):
        kappa = kappa + 1.0 / np.asarray(roller_radius, dtype=float)  # Johnson 1985, §4.3: 1/R = 1/R1 + 1/R2
    out = np.where(kappa > 0.0, kappa, 0.0)
    readonly(out)
    return out


def driving_curvature(
    profile_rho: ArrayLike,
    force: ArrayLike,
    *,
    roller_radius: float | None,
    flank_offsets: tuple[float, float] | None = None,
) -> FloatArray:
    """The relative curvature 1/R* [1/mm] of the surface that carries the contact, every part alike.

    Parameters
    ----------
    profile_rho
        (n,) signed radius of curvature of the part's cam profile [mm] (positive convex).
    force
        (n,) the part's contact force F [N]; a groove's inner flank drives where F ≥ 0, its outer
        flank where F < 0.
    roller_radius
        r_f [mm]; None or 0 for a flat face.
    flank_offsets
        A groove's (inner, outer) flanks as offsets d of the profile [mm]
        (:func:`camcad.geometry.groove.flank_offsets`); None: the profile carries the contact.

    Returns
    -------
    FloatArray
        (n,) 1/R* (:func:`contact_curvature`). A groove's inner flank, radius ρ + d_inner, has the
        roller outside it; the outer flank, radius ρ + d_outer, has the roller inside it, so the
        roller sees it concave, radius −(ρ + d_outer): 1/R* = 1/r_f − 1/(ρ + d_outer)
        (Johnson 1985, §4.3, a concave surface's radius negative).
    """
    rho = np.asarray(profile_rho, dtype=float)
    roller = roller_radius if _is_roller(roller_radius) else None
    if flank_offsets is None:
        return contact_curvature(rho, roller_radius=roller)
    inner = contact_curvature(rho + flank_offsets[0], roller_radius=roller)
    outer = contact_curvature(-(rho + flank_offsets[1]), roller_radius=roller)  # Johnson 1985, §4.3
    out: FloatArray = np.where(np.asarray(force, dtype=float) >= 0.0, inner, outer)
    readonly(out)
    return out


def hertz_stress(force: ArrayLike, *, curvature: ArrayLike, length: float, modulus: float) -> FloatArray:
    """Compute the peak Hertz pressure σ_max of a line contact.

    Parameters
    ----------
    force
        (n,) normal contact force F [N]; F ≤ 0 (no contact) gives 0.
    curvature
        (n,) relative curvature 1/R* [1/mm] from :func:`contact_curvature`.
    length
        Contact length L [mm] (roller or cam width).
    modulus
        Contact modulus E* [MPa] from :func:`effective_modulus`.

    Returns
    -------
    FloatArray
        (n,) σ_max = p0 [MPa].

    Notes
    -----
    With the load per unit length P = F/L,
    p0 = (P·E*/(π·R*))^½ = √(F·E*/(π·L·R*))  (Johnson 1985, eq. 4.45;
    Norton 2009, ch. 7), the maximum of the elliptical pressure
    p(x) = p0·√(1 − x²/b²) over the strip of half-width b
    (:func:`hertz_half_width`); equivalently p0 = 2F/(π·b·L).

    References
    ----------
    .. [1] K. L. Johnson (1985), Contact Mechanics, Cambridge University
       Press, §4.3. doi:10.1017/CBO9781139171731
    .. [2] R. L. Norton (2009), Cam Design and Manufacturing Handbook, 2nd ed.,
       Industrial Press, ch. 7 (contact stress).
    """
    load = np.clip(np.asarray(force, dtype=float), 0.0, None)
    kappa = np.asarray(curvature, dtype=float)
    out = np.sqrt(load * modulus * kappa / (np.pi * length))  # Johnson 1985, eq. 4.45
    readonly(out)
    return out


def hertz_half_width(force: ArrayLike, *, curvature: ArrayLike, length: float, modulus: float) -> FloatArray:
    """Compute the half-width b of the Hertz contact strip [mm].

    Parameters
    ----------
    force, curvature, length, modulus
        As in :func:`hertz_stress`.

    Returns
    -------
    FloatArray
        (n,) b = √(4·F·R*/(π·L·E*)) [mm] (Johnson 1985, eq. 4.45); ``inf``
        where the curvature is 0 and F > 0 (conforming contact).
    """
    load = np.clip(np.asarray(force, dtype=float), 0.0, None)
    kappa = np.asarray(curvature, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.sqrt(4.0 * load / (np.pi * length * modulus * kappa))  # Johnson 1985, eq. 4.45
    out = np.where(load == 0.0, 0.0, out)
    readonly(out)
    return out
