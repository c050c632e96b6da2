"""The cam drawing of positive-drive cams (issue 15): what is drawn touches what it should.

The drawn rollers of a conjugate pair's second follower touch the second
plate's exact profile (dense polygon, not the drawing's); a groove cam's
drawn rollers sit on the groove's centre line, half a groove width less the
clearance from both exact flanks.
"""

from __future__ import annotations

import math
from functools import cache

import numpy as np

import camcad
from camcad._plots.design import follower_drawings, profile_plot
from camcad.analysis import Analysis
from camcad.geometry.groove import groove_flanks
from camcad.pipeline import analyse
from tests.conftest import ROOT, distance_to_polygon

DENSE = np.linspace(0.0, 2.0 * math.pi, 200_000, endpoint=False)


@cache
def analysed(sample: str) -> Analysis:
    return analyse(camcad.load_design(ROOT / "samples" / sample), fit=False, toolpath=False)


def _centres(drawings) -> np.ndarray:
    return np.array([d.body[0][:-1].mean(axis=0) for d in drawings])  # a roller is a closed circle polygon


def test_second_rollers_are_drawn_on_the_second_plate() -> None:
    analysis = analysed("indexing_conjugate.toml")
    partner = analysis.parts[1].part.cam
    drawings = follower_drawings(analysis, 100.0, cam=partner)
    plate = partner.profile(DENSE).point
    gap = distance_to_polygon(_centres(drawings), plate)
    assert np.abs(gap - analysis.design.conjugate.roller_radius).max() < 1e-3
    # each second roller hangs on its own arm from the pivot (seen from the turning cam)
    pivot = np.asarray(analysis.cam.follower.guide.pivot)
    for drawing, phi in zip(drawings, np.radians([d.phi_deg for d in drawings]), strict=True):
        c, s = math.cos(phi), math.sin(phi)
        seen = np.array([c * pivot[0] + s * pivot[1], -s * pivot[0] + c * pivot[1]])  # R(−φ): a ccw cam
        assert np.allclose(drawing.links[0][0], seen, atol=1e-9)
    assert b"second plate" in profile_plot(analysis).svg


def test_groove_rollers_are_drawn_in_the_groove() -> None:
    analysis = analysed("groove_rocker.toml")
    design = analysis.design
    inner, outer = groove_flanks(analysis.cam, DENSE, design.groove.clearance)
    centres = _centres(follower_drawings(analysis, 100.0))
    half = design.follower.roller_radius + 0.5 * design.groove.clearance
    for flank in (inner, outer):
        assert np.abs(distance_to_polygon(centres, flank.point) - half).max() < 1e-3
    assert b"groove flanks" in profile_plot(analysis).svg


def test_dynamics_plot_draws_the_second_plate_force_and_stress() -> None:
    """Issue 31: a conjugate pair's dynamics figure carries plate 2's own force and stress series."""
    from camcad._plots.design import dynamics_plot

    pair = dynamics_plot(analysed("indexing_conjugate.toml")).svg
    single = dynamics_plot(analysed("offset_roller.toml")).svg
    assert pair.count(b"plate 2") >= 2 and pair.count(b"plate 1") >= 2  # legend of force and of stress
    assert b"plate 2" not in single
