"""Lubricant film between the cam and its follower: Dowson–Higginson line contact, every angle.

The cam and the roller (or face) meet in an elastohydrodynamic line contact.
Its minimum film thickness follows Dowson & Higginson (1977):

    H_min = h_min / R = 2.65 · U^0.70 · G^0.54 · W′^−0.13

with U = η₀·u/(E′·R), G = α·E′, W′ = w/(E′·R): η₀ the viscosity at the
operating temperature, α the pressure–viscosity coefficient, u the
entraining speed (the mean of the two surfaces' speeds relative to the
contact), R the reduced radius of curvature, w the load per unit length of
the line, and E′ the reduced modulus of Dowson & Higginson,

    2/E′ = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂,  so E′ = 2·E*,

twice the contact modulus E* of :func:`~camcad.dynamics.contact.effective_modulus`
(Johnson's convention, used by the Hertz stress). The film ratio
λ = h_min/√(Rq₁² + Rq₂²) with the surfaces' rms roughnesses Rq says whether
the film separates them (λ ≳ 1: mostly; λ > 3: fully).

Units inside: mm, N, s, MPa; the viscosity [Pa·s] and α [1/Pa] are converted
here (1 Pa·s = 10⁻⁶ N·s/mm², 1/Pa = 10⁶/MPa); films and roughness in µm.

References
----------
.. [1] D. Dowson & G. R. Higginson (1977), Elasto-Hydrodynamic Lubrication,
   SI ed., Pergamon, ch. 7: the minimum film thickness of a line contact
   (formula above, E′ by 2/E′ = Σ(1 − ν²)/E, u = (u₁ + u₂)/2).
.. [2] H. A. Rothbart (ed.) (2004), Cam Design Handbook, McGraw-Hill, §9.7:
   the same formula and the film parameter Λ = h_min/√(t₁² + t₂²) with t the
   rms roughnesses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.errors import DesignError
from camcad.findings import Finding, Severity
from camcad.knobs import Knob, TableKey

__all__ = [
    "FilmResult",
    "LubricationSpec",
    "analyse_film",
    "entraining_speed",
    "film_findings",
    "film_ratio",
    "minimum_film_thickness",
    "reduced_modulus",
]

_PA_S = 1e-6  # 1 Pa·s in N·s/mm²
_PER_PA = 1e6  # 1/Pa in 1/MPa
_UM = 1e3  # µm per mm


@dataclass(frozen=True, slots=True, kw_only=True)
class LubricationSpec:
    """The ``[lubrication]`` table.

    Attributes
    ----------
    viscosity_Pa_s
        η₀ [Pa·s], the dynamic viscosity at the operating temperature and
        atmospheric pressure (ISO VG 100 mineral oil at 40 °C: ≈ 0.09 Pa·s).
    pressure_viscosity_coefficient
        α [1/Pa] (mineral oils ≈ 2·10⁻⁸ 1/Pa).
    roughness_cam_um, roughness_follower_um
        Rq [µm], the root-mean-square roughness of each surface (not Ra; for
        a ground surface Rq ≈ 1.25·Ra).
    min_film_ratio
        λ below which a soft finding is raised (default 1).
    """

    viscosity_Pa_s: float
    pressure_viscosity_coefficient: float
    roughness_cam_um: float
    roughness_follower_um: float
    min_film_ratio: float = 1.0

    def __post_init__(self) -> None:
        """Check every value: one-line errors naming the field."""
        for name, unit in (
            ("viscosity_Pa_s", "Pa·s"),
            ("pressure_viscosity_coefficient", "1/Pa"),
            ("roughness_cam_um", "µm"),
            ("roughness_follower_um", "µm"),
            ("min_film_ratio", "1"),
        ):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0.0):
                raise DesignError(
                    TableKey(Knob.LUBRICATION_TABLE, name),
                    f"must be a positive number [{unit}], got {value!r}",
                )

    @property
    def composite_roughness_um(self) -> float:
        """√(Rq₁² + Rq₂²) [µm]."""
        return math.hypot(self.roughness_cam_um, self.roughness_follower_um)


def reduced_modulus(contact_modulus: float) -> float:
    """E′ = 2·E* [MPa]: Dowson & Higginson's reduced modulus from Johnson's contact modulus E*.

    2/E′ = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂ (Dowson & Higginson 1977) and
    1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂ (Johnson 1985, §4.2).

    Examples
    --------
    >>> round(reduced_modulus(113186.8), 1)
    226373.6
    """
    return 2.0 * contact_modulus


def entraining_speed(contact_speed: ArrayLike, slip: ArrayLike | float = 0.0) -> FloatArray:
    """Entraining (rolling) speed u of the lubricant into the contact [mm/s].

    Parameters
    ----------
    contact_speed
        (n,) w [mm/s]: the speed at which the contact runs over the cam
        profile (|dS/dφ|·ω), along the profile's tangent t.
    slip
        (n,) the follower's material velocity relative to the cam's at the
        contact, along the same t [mm/s]: 0 for a roller in pure rolling.

    Returns
    -------
    FloatArray
        (n,) u = |slip/2 − w| ≥ 0: the mean of the surfaces' velocities
        relative to the contact, −w (cam) and slip − w (follower)
        (Dowson & Higginson 1977: u = (u₁ + u₂)/2). A roller in pure rolling
        gives u = w; a radial flat face gives ω(r_b + s + 2a)/2, a the
        pseudo-acceleration d²s/dφ².
    """
    w = np.asarray(contact_speed, dtype=float)
    out: FloatArray = np.abs(
        0.5 * np.asarray(slip, dtype=float) - w
    )  # Dowson & Higginson 1977: u = (u1 + u2)/2
    readonly(out)
    return out


def minimum_film_thickness(
    *,
    load_per_length: ArrayLike,
    speed: ArrayLike,
    curvature: ArrayLike,
    modulus: float,
    viscosity_Pa_s: float,
    pressure_viscosity_coefficient: float,
) -> FloatArray:
    """Dowson–Higginson minimum film thickness of a line contact [mm].

    Parameters
    ----------
    load_per_length
        (n,) w = F/L [N/mm]; w ≤ 0 (no contact) gives ``inf`` (no film needed).
    speed
        (n,) entraining speed u ≥ 0 [mm/s].
    curvature
        (n,) 1/R [1/mm], the relative curvature (convex and concave flanks
        alike, :func:`~camcad.dynamics.contact.contact_curvature`); 0 (a
        conforming contact) gives ``inf``.
    modulus
        E′ [MPa] (:func:`reduced_modulus`).
    viscosity_Pa_s
        η₀ [Pa·s].
    pressure_viscosity_coefficient
        α [1/Pa].

    Returns
    -------
    FloatArray
        (n,) h_min = R·2.65·U^0.70·G^0.54·W′^−0.13 [mm] (Dowson & Higginson 1977,
        ch. 7; Rothbart 2004, §9.7); 0 where u = 0.
    """
    w = np.asarray(load_per_length, dtype=float)
    u = np.asarray(speed, dtype=float)
    kappa = np.asarray(curvature, dtype=float)
    eta = viscosity_Pa_s * _PA_S  # N·s/mm²
    g = pressure_viscosity_coefficient * _PER_PA * modulus  # G = α E′ [1]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        u_dimless = eta * u * kappa / modulus  # U = η0 u / (E′ R)
        w_dimless = w * kappa / modulus  # W′ = w / (E′ R)
        h = 2.65 * u_dimless**0.70 * g**0.54 * w_dimless**-0.13 / kappa  # Dowson & Higginson 1977
    out: FloatArray = np.where((w <= 0.0) | (kappa <= 0.0), np.inf, np.where(u <= 0.0, 0.0, h))
    readonly(out)
    return out


def film_ratio(
    thickness_um: ArrayLike, *, roughness_cam_um: float, roughness_follower_um: float
) -> FloatArray:
    """λ = h_min/√(Rq₁² + Rq₂²) (Rothbart 2004, §9.7: film parameter Λ), h and Rq in µm."""
    out = np.asarray(thickness_um, dtype=float) / math.hypot(roughness_cam_um, roughness_follower_um)
    readonly(out)
    return out


@dataclass(frozen=True, slots=True, kw_only=True)
class FilmResult:
    """The lubricant film over the cam turn.

    Attributes
    ----------
    phi
        (n,) cam angle [rad].
    thickness_um
        (n,) minimum film thickness h_min [µm]; ``inf`` where there is no
        contact or the contact conforms.
    ratio
        (n,) film ratio λ [1].
    speed
        (n,) entraining speed u [mm/s].
    min_ratio, angle
        The smallest λ and the cam angle [rad] where it occurs.
    min_thickness_um
        h_min there [µm].
    flank
        A groove's flank that carries the contact there (``"inner"``/``"outer"``), else None.
    limit
        ``min_film_ratio``.
    findings
        A soft finding when ``min_ratio < limit``.
    """

    phi: FloatArray
    thickness_um: FloatArray
    ratio: FloatArray
    speed: FloatArray
    min_ratio: float
    angle: float
    min_thickness_um: float
    limit: float
    findings: tuple[Finding, ...] = ()
    flank: str | None = None

    def summary(self) -> dict[str, Any]:
        """The ``lubrication`` section of ``summary.json`` (``min_film_ratio_flank`` on a groove)."""
        out: dict[str, Any] = {
            "min_film_ratio": self.min_ratio if math.isfinite(self.min_ratio) else None,
            "min_film_ratio_angle_deg": round(math.degrees(self.angle) % 360.0, 6),
        }
        if self.flank is not None:
            out["min_film_ratio_flank"] = self.flank
        out["min_film_thickness_um"] = self.min_thickness_um if math.isfinite(self.min_thickness_um) else None
        out["film_ratio_limit"] = self.limit
        return out


def analyse_film(
    phi: ArrayLike,
    force: ArrayLike,
    *,
    curvature: ArrayLike,
    length: float,
    speed: ArrayLike,
    contact_modulus: float,
    spec: LubricationSpec,
) -> FilmResult:
    """Film thickness and film ratio at every cam angle, their minimum and a finding below the limit.

    Parameters
    ----------
    phi
        (n,) cam angles [rad].
    force
        (n,) contact force F [N].
    curvature
        (n,) relative curvature 1/R [1/mm].
    length
        Contact length L [mm].
    speed
        (n,) entraining speed u [mm/s] (:func:`entraining_speed`).
    contact_modulus
        E* [MPa] (Johnson's; E′ = 2E* is formed here).
    spec
        The ``[lubrication]`` table.

    Returns
    -------
    FilmResult
    """
    p = np.array(phi, dtype=float).ravel()
    h = (
        minimum_film_thickness(
            load_per_length=np.asarray(force, dtype=float) / length,
            speed=speed,
            curvature=curvature,
            modulus=reduced_modulus(contact_modulus),
            viscosity_Pa_s=spec.viscosity_Pa_s,
            pressure_viscosity_coefficient=spec.pressure_viscosity_coefficient,
        )
        * _UM
    )
    lam = film_ratio(
        h, roughness_cam_um=spec.roughness_cam_um, roughness_follower_um=spec.roughness_follower_um
    )
    i = int(np.argmin(lam))
    u = np.array(speed, dtype=float)
    readonly(p, h, u)
    result = FilmResult(
        phi=p,
        thickness_um=h,
        ratio=lam,
        speed=u,
        min_ratio=float(lam[i]),
        angle=float(p[i]),
        min_thickness_um=float(h[i]),
        limit=spec.min_film_ratio,
    )
    return replace(result, findings=film_findings(result))


def film_findings(result: FilmResult) -> tuple[Finding, ...]:
    """A soft finding when λ falls below ``min_film_ratio`` somewhere."""
    if not result.min_ratio < result.limit:
        return ()
    flank = "" if result.flank is None else f" ({result.flank} flank)"
    return (
        Finding(
            kind="film ratio",
            severity=Severity.SOFT,
            field=Knob.MIN_FILM_RATIO,
            message=(
                f"lubricant film ratio λ falls to {result.min_ratio:.3g} at "
                f"{math.degrees(result.angle):.1f}°{flank} (h_min {result.min_thickness_um:.3g} µm), below "
                f"{result.limit:g}: the surfaces touch through the film; use a more viscous oil, smoother "
                "surfaces, or a larger radius of curvature there"
            ),
            angle=result.angle,
            value=result.min_ratio,
            limit=result.limit,
            unit="1",
        ),
    )
