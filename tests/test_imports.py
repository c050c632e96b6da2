"""What loads when: heavy libraries only for the outputs that need them (issue 18).

Checked in a fresh interpreter against its own ``sys.modules`` (the truth of
what was imported), so the law holds whatever the test session loaded before.
Speed itself is measured in ``benchmarks/pipeline.py``, not here.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from tests.conftest import ROOT

REPORT_ONLY = ("matplotlib",)  # drawn only for report.html (and the compare and explore plots)
MESH_ONLY = ("trimesh", "meshio", "manifold3d")  # only for the mesh outputs
# SciPy only for designs that need it: blend points (linalg), point tables (interpolate), a motion
# reversal (optimize), the FE check; the fit, toolpath, STEP, meshes and crossovers do without it
SCIPY = ("scipy",)


def loaded_after(code: str) -> set[str]:
    """Top-level packages present in ``sys.modules`` after running ``code`` in a fresh interpreter."""
    probe = f"{code}\nimport json, sys\nprint(json.dumps(sorted({{m.split('.')[0] for m in sys.modules}})))"
    out = subprocess.run(
        [sys.executable, "-c", probe], cwd=ROOT, capture_output=True, text=True, check=True, timeout=300
    )
    return set(json.loads(out.stdout.splitlines()[-1]))


@pytest.mark.parametrize("module", ["camcad", "camcad.pipeline", "camcad.cli"])
def test_importing_the_pipeline_or_the_cli_loads_no_plotting_or_mesh_library(module):
    loaded = loaded_after(f"import {module}")
    assert f"{module}".split(".")[0] in loaded  # the probe did import it
    assert not loaded & {*REPORT_ONLY, *MESH_ONLY}


def test_camcad_check_analyses_fit_and_toolpath_without_matplotlib_or_meshes():
    sample = ROOT / "samples" / "quintero_vap_b01.toml"
    code = (
        "from camcad.cli import main\n"
        "import contextlib, io\n"
        "with contextlib.redirect_stdout(io.StringIO()) as text:\n"
        f"    code = main(['check', {str(sample)!r}])\n"
        "assert code == 0 and 'fit control points' in text.getvalue(), text.getvalue()"
    )
    loaded = loaded_after(code)
    assert "camcad" in loaded
    assert not loaded & {*REPORT_ONLY, *MESH_ONLY, *SCIPY}


def test_a_whole_build_writes_its_meshes_without_trimesh_or_networkx(tmp_path):
    """Every default output of a plate and a groove cam, in one fresh interpreter: the STL is written
    (manifold3d loaded) by camcad's own writers, so trimesh, networkx and mapbox_earcut never load."""
    builds = {name: tmp_path / name for name in ("quintero_vap_b01", "groove_rocker")}
    code = "from camcad.cli import main\n" + "".join(
        f"assert main(['build', {str(ROOT / 'samples' / f'{name}.toml')!r}, '-o', {str(out)!r}, '-q']) == 0\n"
        for name, out in builds.items()
    )
    loaded = loaded_after(code)
    for out in builds.values():
        assert (out / "cam.stl").stat().st_size > 84 and (out / "report.html").is_file()
    assert "manifold3d" in loaded
    assert not loaded & {"trimesh", "networkx", "mapbox_earcut", "OCP", *SCIPY}
