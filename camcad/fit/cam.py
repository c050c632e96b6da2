"""The fit of a cam's own profile: samples, exact profile and breakpoints from the cam."""

from __future__ import annotations

import math

import numpy as np

from camcad.fit._limits import Names, SamplesTooFewError
from camcad.fit._profile import _fit_closed, fit_open_profile
from camcad.fit.result import ProfileFit
from camcad.geometry.cam import Cam
from camcad.knobs import Knob, Namer

__all__ = ["FIT_STEP", "fit_cam_profile"]

FIT_STEP = math.radians(0.1)  # rad, the coarsest sampling the fit uses
REFINEMENTS = 3  # halvings of the step when the samples are too few for the tolerance


def fit_cam_profile(
    cam: Cam,
    *,
    tolerance: float = 1e-3,
    max_control_points: int | None = None,
    step: float | None = None,
    offset: float = 0.0,
    name_of: Namer | None = None,
) -> ProfileFit:
    """Certified B-spline of ``cam.profile`` (or of its offset ``cam.offset_curve(φ, offset)``) over one turn.

    A disc cam's closed profile gives a periodic B-spline; a linear cam's
    open edge (``cam.closed`` false) a clamped one from φ = 0 to 2π.

    Samples the exact profile (breakpoints included), puts knots at the
    motion breakpoints, and certifies the result against ``cam.profile``
    over the whole turn (:func:`camcad.fit.certify.certify_exact`), so the
    certified error bounds the true distance whatever the sampling.

    Parameters
    ----------
    cam
        The cam.
    tolerance
        Largest allowed distance from the exact profile [mm]
        (``fit.tolerance``).
    max_control_points
        Budget for the search (``fit.max_control_points``); None (default):
        automatic, as many as the samples leave room for, up to a memory
        bound (:data:`camcad.fit._profile.AUTO_MAX_CONTROL_POINTS`).
    step
        Sampling step of the fit's data [rad]. Default: the finer of the
        cam's ``sample_step`` and ``FIT_STEP`` (0.1°): a coarse sample step
        chosen for tables does not starve the least squares. With the
        default, a tolerance that needs more control points than the
        samples leave room for halves the step (up to ``REFINEMENTS``
        times) before giving up.

    offset
        Fit the profile offset outward by this distance [mm] instead of the
        profile itself (a groove's flanks,
        :func:`camcad.geometry.groove.groove_flanks`); the certificate is then
        against ``cam.offset_curve(φ, offset)``.
    name_of
        How the error names the fit's settings (the design layer: their TOML
        paths); None: as :class:`~camcad.knobs.Knob` s.

    Raises
    ------
    FitError
        The tolerance cannot be met; the message names the knob that binds
        (``fit.max_control_points`` when the budget stops the search,
        ``fit.tolerance`` when the automatic budget or the finest sampling
        does, ``step`` when the caller's step does), its value and the
        control points reached. ``cam.sample_step_deg`` is never the cause:
        the fit does not use a step coarser than 0.1°.
    """
    names = Names(
        tolerance=Knob.FIT_TOLERANCE if name_of is None else name_of(Knob.FIT_TOLERANCE),
        max_control_points=(
            Knob.FIT_MAX_CONTROL_POINTS if name_of is None else name_of(Knob.FIT_MAX_CONTROL_POINTS)
        ),
        samples=None if step is None else "step",
    )
    h = min(cam.sample_step, FIT_STEP) if step is None else step
    for attempt in range(REFINEMENTS + 1):
        phi = cam.curve_phi(h)  # a linear cam's open edge: from φ = 0 to 2π, both ends
        fit = _fit_closed if cam.closed else fit_open_profile
        try:
            return fit(
                phi,
                np.asarray(cam.offset_curve(phi, offset).point),
                exact=lambda p: cam.offset_curve(p, offset).point,
                breakpoints=[(b.phi, b.continuity) for b in cam.program.breakpoints],
                tolerance=tolerance,
                max_control_points=max_control_points,
                degree=3,
                names=names,
            )
        except SamplesTooFewError:
            if step is not None or attempt == REFINEMENTS:
                raise
            h *= 0.5
    raise AssertionError("unreachable")  # pragma: no cover
