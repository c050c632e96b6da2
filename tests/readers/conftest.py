"""Outputs opened in real programs: shared builds, program lookup and the ``slow`` marker.

Each case (every shipped sample, plus a keyed bore) is built once per session
with the exporters alone (fit, DXF, polyline DXF, solid), so a failure here
points at the files, not at the pipeline around them.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest

from camcad.design import Design, load_design
from camcad.export.dxf import write_profile_dxf, write_profile_poly_dxf
from camcad.export.mesh import SolidResult, build_solid, write_meshes
from camcad.fit import ProfileFit, fit_cam_profile
from camcad.geometry.cam import Cam
from tests.conftest import DISC_SAMPLES, make_design

PROGRAM_TIMEOUT = 300  # s, per program run


def pytest_configure(config: pytest.Config) -> None:
    """Register the ``slow`` marker (also declared in pyproject.toml)."""
    config.addinivalue_line(
        "markers", "slow: opens outputs in real programs (LibreCAD, OpenSCAD, admesh, rs274)"
    )


@dataclass(frozen=True)
class Built:
    """One case's exported files and the numbers they must reproduce."""

    name: str
    design: Design
    cam: Cam
    fit: ProfileFit
    solid: SolidResult
    folder: Path
    dxf: Path
    poly_dxf: Path
    stl: Path


def _fit(design: Design, cam: Cam) -> ProfileFit:
    return fit_cam_profile(
        cam, tolerance=design.fit.tolerance, max_control_points=design.fit.max_control_points
    )


def _cases() -> dict[str, object]:
    cases: dict[str, object] = {p.stem: p for p in DISC_SAMPLES}
    cases["keyed-bore"] = "keyed"
    return cases


CASES = _cases()


@pytest.fixture(scope="session", params=list(CASES), ids=list(CASES))
def built(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> Built:
    """Exported files of one case, in a folder of their own."""
    source = CASES[request.param]
    if isinstance(source, Path):
        design = load_design(source)
    else:
        design = make_design(extra={"cam": {"bore": 12.0, "keyway_width": 4.0, "keyway_depth": 2.0}})
    cam = Cam.from_design(design)
    fit = _fit(design, cam)
    folder = tmp_path_factory.mktemp(request.param)
    solid = build_solid(fit, design.plate(), design.mesh, cam=cam)
    (stl,) = [p for p in write_meshes(folder, solid, ["stl"]) if p.suffix == ".stl"]
    return Built(
        name=request.param,
        design=design,
        cam=cam,
        fit=fit,
        solid=solid,
        folder=folder,
        dxf=write_profile_dxf(
            folder / "profile.dxf", cam=cam, fit=fit, plate=design.plate(), options=design.dxf
        ),
        poly_dxf=write_profile_poly_dxf(
            folder / "profile_poly.dxf", cam=cam, fit=fit, plate=design.plate(), options=design.dxf
        ),
        stl=stl,
    )


def require(program: str) -> str:
    """Path of ``program``, or skip the test saying it is not installed."""
    path = shutil.which(program)
    if path is None:
        pytest.skip(f"{program} is not installed (apt-get install {program})")
    return path


def run(args: list[str], *, cwd: Path, timeout: float = PROGRAM_TIMEOUT) -> subprocess.CompletedProcess[str]:
    """Run a program headless under ``timeout``; its config and runtime dirs go to ``cwd``.

    rs274 gets ``cwd`` as its home too: it keeps its tool table in ``$HOME/.tool.mmap``, which
    another rs274 running at the same time (another test session) would overwrite under it
    ("Requested tool 2 not found in the tool table").
    """
    env = dict(os.environ)
    env.update(
        QT_QPA_PLATFORM="offscreen",
        XDG_RUNTIME_DIR=str(cwd),
        XDG_CONFIG_HOME=str(cwd / ".config"),
    )
    if Path(args[0]).name == "rs274":
        env["HOME"] = str(cwd)
    timeout_cmd = shutil.which("timeout")
    prefix = [timeout_cmd, "--kill-after=10", str(int(timeout))] if timeout_cmd else []
    return subprocess.run(
        [*prefix, *args],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=timeout + 30,
        check=False,
    )
