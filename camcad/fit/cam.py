"""The fit of a cam's own profile: samples, exact profile and breakpoints from the cam."""

from __future__ import annotations

import numpy as np

from camcad.fit._profile import ProfileFit, fit_profile
from camcad.geometry.cam import Cam

__all__ = ["fit_cam_profile"]


def fit_cam_profile(
    cam: Cam, *, tolerance: float = 1e-3, max_control_points: int = 500, step: float | None = None
) -> ProfileFit:
    """Certified B-spline of ``cam.profile`` over one turn.

    Samples the exact profile at the cam's sampling step (0.1° by default,
    breakpoints included), puts knots at the motion breakpoints, and certifies
    the result against ``cam.profile`` between samples too.

    Parameters
    ----------
    cam
        The cam.
    tolerance
        Largest allowed distance from the exact profile [mm].
    max_control_points
        Budget for the search; beyond it :class:`~camcad.errors.FitError`.
    step
        Sampling step [rad]; default the cam's.
    """
    phi = cam.sample_phi(step)
    return fit_profile(
        phi,
        np.asarray(cam.profile(phi).point),
        exact=lambda p: cam.profile(p).point,
        breakpoints=[(b.phi, b.continuity) for b in cam.program.breakpoints],
        tolerance=tolerance,
        max_control_points=max_control_points,
    )
