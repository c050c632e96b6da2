"""Whether a milling tool fits the cam profile: its radius against the smallest concave radius.

A flat end mill of radius r running along the outside of the profile can
only follow a concave stretch whose radius of curvature is at least r;
where the profile bends tighter, the tool cuts into the part (a gouge).
"""

from __future__ import annotations

import numpy as np

from camcad._typing import FloatArray
from camcad.angles import flagged_ranges, format_ranges
from camcad.errors import GougeError
from camcad.extremes import minimum
from camcad.geometry.cam import Cam
from camcad.knobs import Knob

__all__ = ["check_tool"]


def _concave_radius(rho: FloatArray) -> FloatArray:
    """−ρ where the profile is concave, +inf elsewhere [mm]."""
    return np.where(rho < 0.0, -rho, np.inf)


def check_tool(cam: Cam, tool_radius: float) -> float:
    """Smallest concave profile radius [mm] (inf if none); raise if the tool does not fit.

    Parameters
    ----------
    cam
        The cam; its exact profile curvature ``cam.profile(phi).rho`` is used.
    tool_radius
        Radius of the milling tool [mm].

    Returns
    -------
    float
        The true smallest concave radius of the profile [mm]: sampled on
        ``cam.sample_phi()`` and refined on the exact curvature, with both
        one-sided limits at every joint (:func:`camcad.extremes.minimum`);
        ``inf`` for a profile without a concave stretch.

    Raises
    ------
    GougeError
        Where a concave radius of the profile is smaller than ``tool_radius``:
        the message names the cam-angle ranges in degrees and the largest tool
        diameter that fits (twice the smallest concave radius).
    """
    phi = cam.sample_phi()
    rho = cam.profile(phi).rho
    joints = [bp.phi for bp in cam.program.breakpoints]
    worst = minimum(
        lambda p, side: _concave_radius(cam.profile(p, side=side).rho),
        phi,
        joints,
        values=_concave_radius(rho),
    )
    smallest = float(worst.value)
    if smallest >= tool_radius:
        return smallest
    bad = (rho < 0.0) & (-rho < tool_radius)
    # a stretch narrower than the sample step is named by where its extreme is
    ranges = flagged_ranges(phi, bad) if bad.any() else [(worst.phi, worst.phi)]
    raise GougeError(
        f"tool Ø{2 * tool_radius:g} mm gouges the profile at φ = {format_ranges(ranges)}: "
        f"its concave radius is down to {smallest:.3f} mm, below the tool radius "
        f"{tool_radius:g} mm; the largest tool that fits is Ø{2 * smallest:.3f} mm "
        "(set the tool diameter below it)",
        phi_range=ranges[0],
        max_tool_radius=smallest,
        field=Knob.TOOL_DIAMETER,
    )
