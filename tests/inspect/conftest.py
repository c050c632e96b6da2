"""Cams of every follower kind for the tolerance and inspection tests."""

from __future__ import annotations

import pytest

from camcad.design import load_design
from camcad.geometry.cam import Cam
from tests.conftest import ROOT, make_design


def sample_cam(name: str) -> Cam:
    """The cam of a shipped sample design."""
    return Cam.from_design(load_design(ROOT / "samples" / f"{name}.toml"))


CAMS = {
    "offset-roller-ccw": lambda: Cam.from_design(make_design(offset=8.0)),
    "offset-roller-cw": lambda: Cam.from_design(make_design(offset=8.0, rotation="cw", law="poly-345")),
    "translating-flat": lambda: Cam.from_design(
        make_design(follower="translating-flat", offset=5.0, base_radius=50.0)
    ),
    "oscillating-roller": lambda: sample_cam("packaging_rocker"),
    "oscillating-flat-cw": lambda: sample_cam("rocker_flat"),
}


@pytest.fixture(params=sorted(CAMS), scope="module")
def any_cam(request: pytest.FixtureRequest) -> Cam:
    """One cam of each follower kind and both rotations."""
    return CAMS[request.param]()
