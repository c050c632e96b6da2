"""A cam whose profile is the design corrected by a measured form error, for the fit, tool path and DXF.

:class:`CompensatedCam` is the design's :class:`~camcad.geometry.cam.Cam`
with :meth:`offset_curve` (and so :meth:`profile`) replaced: the base curve B (a
roller's pitch curve, a face's profile) moved along its normal N by
w + c(u), with c = −e(u) the correction (:func:`~camcad.inspect.actual.compensate`)
and w the distance asked for less the roller radius, exact to the second
derivative (:func:`camcad.geometry.made.made_curve`'s formulas, with the
one-sided limits at joints). The tool path, the certified fit and the
drawings of camcad then take it like any cam.

The offset of the corrected profile is taken along the design's normal N,
not the corrected profile's own N_c: the two differ by the angle
θ ≈ c′/|B′|, which moves the path d·(1 − cos θ) ≈ d·θ²/2 off the exact
offset of the corrected profile at distance d (the path's direction is
unchanged to first order). :func:`offset_error` measures that bound;
``camcad inspect`` refuses a correction where it exceeds a tenth of the
G-code tolerance.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from camcad._typing import ArrayLike, readonly
from camcad.geometry.cam import Cam
from camcad.geometry.curves import CurveSample
from camcad.geometry.made import FormError
from camcad.motion.program import Side

__all__ = ["CompensatedCam", "offset_error"]


@dataclass(frozen=True, slots=True, kw_only=True)
class CompensatedCam(Cam):
    """The design (its program, follower and rotation) with the profile moved by ``correction`` [mm].

    ``correction(u)`` gives c, dc/du, d²c/du² (mm per radᵏ) at cam angles u:
    + moves the profile outward (adds material).
    """

    correction: FormError

    @classmethod
    def of(cls, cam: Cam, correction: FormError) -> CompensatedCam:
        """The cam ``cam`` corrected by ``correction``."""
        return cls(
            program=cam.program,
            base_radius=cam.base_radius,
            follower_spec=cam.follower_spec,
            rotation=cam.rotation,
            sample_step=cam.sample_step,
            conjugate=cam.conjugate,
            correction=correction,
        )

    def offset_curve(self, phi: ArrayLike, distance: float, *, side: Side = "right") -> CurveSample:
        """The corrected profile offset outward by ``distance`` [mm] along the design's normal."""
        base, drho, profile_at = self._base_curve(phi, side)
        u = np.asarray(base.phi, dtype=float)
        c0, c1, c2 = self.correction(u)
        off = distance + profile_at + c0
        with np.errstate(divide="ignore", invalid="ignore"):
            k = np.where(np.isinf(base.rho), 0.0, 1.0 / base.rho)  # 1/ρ
            dk = np.where(np.isinf(base.rho), 0.0, -drho / base.rho**2)  # d(1/ρ)/dφ
        n = base.normal
        stretch = 1.0 + off * k
        # X = B + off·N with N′ = −k·B′ (k = 1/ρ): X′ = B′(1 + off·k) + c′N, and its derivative
        d1 = base.d1 * stretch[:, None] + c1[:, None] * n
        d2 = base.d2 * stretch[:, None] + base.d1 * (2.0 * c1 * k + off * dk)[:, None] + c2[:, None] * n
        point = base.point + off[:, None] * n
        speed = np.hypot(d1[:, 0], d1[:, 1])
        tangent = d1 / speed[:, None]
        left = np.column_stack((-tangent[:, 1], tangent[:, 0]))
        outward = np.sign(
            np.einsum("ij,ij->i", n, np.column_stack((-base.tangent[:, 1], base.tangent[:, 0])))
        )
        normal = outward[:, None] * left
        cross = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
        with np.errstate(divide="ignore"):
            rho = np.where(cross == 0.0, np.inf, -outward * speed**3 / cross)  # convex > 0
        out = CurveSample(phi=u, point=point, d1=d1, d2=d2, tangent=tangent, normal=normal, rho=rho)
        readonly(out.point, out.d1, out.d2, out.tangent, out.normal, out.rho)
        return out


def offset_error(cam: CompensatedCam, distance: float, phi: ArrayLike | None = None) -> float:
    """Largest distance·(1 − cos θ) [mm]: how far the path may lie off the exact offset (module notes)."""
    ph = cam.sample_phi() if phi is None else np.asarray(phi, dtype=float)
    design = Cam.offset_curve(cam, ph, 0.0)  # the uncorrected profile and its normal
    corrected = cam.offset_curve(ph, 0.0)
    cos = np.clip(np.einsum("ij,ij->i", design.normal, corrected.normal), -1.0, 1.0)
    return float(abs(distance) * np.max(1.0 - cos)) if ph.size else 0.0
