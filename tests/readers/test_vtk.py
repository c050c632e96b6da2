"""stress.vtu opened by VTK itself (Debian's python3-vtk9, the reader ParaView is built on).

A second reader besides meshio: VTK's own XML reader loads the quadratic
triangles and every array with the expected number of components, and its
values agree with what camcad computed (the peak von Mises of the nodes).
Skipped, saying why, when the system Python has no VTK.
"""

from __future__ import annotations

import json
import subprocess
import textwrap
from pathlib import Path

import pytest

from camcad.cli import main

pytest.importorskip("gmsh")
pytest.importorskip("skfem")

SYSTEM_PYTHON = Path("/usr/bin/python3")

READ = textwrap.dedent(
    """
    import json, sys
    from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader
    from vtkmodules.util.numpy_support import vtk_to_numpy
    reader = vtkXMLUnstructuredGridReader()
    reader.SetFileName(sys.argv[1])
    reader.Update()
    grid = reader.GetOutput()
    data = grid.GetPointData()
    arrays = {}
    for i in range(data.GetNumberOfArrays()):
        values = vtk_to_numpy(data.GetArray(i))
        arrays[data.GetArrayName(i)] = [data.GetArray(i).GetNumberOfComponents(), float(abs(values).max())]
    types = sorted({grid.GetCellType(i) for i in range(grid.GetNumberOfCells())})
    print(json.dumps({"points": grid.GetNumberOfPoints(), "cells": grid.GetNumberOfCells(),
                      "types": types, "arrays": arrays}))
    """
)

DESIGN = """
[cam]
base_radius = 30.0
thickness = 8.0
bore = 12.0
keyway_width = 4.0
keyway_depth = 2.0
[follower]
type = "translating-roller"
roller_radius = 8.0
[[motion]]
kind = "rise"
angle = 180.0
lift = 10.0
law = "poly-345"
[[motion]]
kind = "return"
angle = 180.0
lift = 10.0
law = "poly-345"
[dynamics]
spring_preload = 100.0
[fea]
contact_divisions = 4
"""


@pytest.mark.slow
def test_vtk_reads_stress_vtu(tmp_path: Path):
    if (
        not SYSTEM_PYTHON.exists()
        or subprocess.run(
            [str(SYSTEM_PYTHON), "-c", "import vtkmodules.vtkIOXML"], capture_output=True, check=False
        ).returncode
    ):
        pytest.skip("VTK's Python is not installed (apt-get install python3-vtk9)")
    design = tmp_path / "cam.toml"
    design.write_text(DESIGN)
    assert main(["build", str(design), "-o", str(tmp_path / "out"), "-q", "--only", "fea"]) == 0
    proc = subprocess.run(
        [str(SYSTEM_PYTHON), "-c", READ, str(tmp_path / "out" / "stress.vtu")],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    seen = json.loads(proc.stdout)
    fea = json.loads((tmp_path / "out" / "summary.json").read_text())["fea"]
    assert seen["points"] == fea["nodes"] and seen["cells"] == fea["elements"]
    assert seen["types"] == [22]  # VTK_QUADRATIC_TRIANGLE
    for i, case in enumerate(fea["cases"], start=1):
        parts = {name: seen["arrays"][f"case{i}_{name}"] for name in ("displacement_mm", "stress_MPa")}
        assert parts["displacement_mm"][0] == 3 and parts["stress_MPa"][0] == 6
        assert seen["arrays"][f"case{i}_principal_stress_MPa"][0] == 3
        components, peak = seen["arrays"][f"case{i}_von_mises_MPa"]
        assert components == 1 and 0.5 * case["von_mises_max_MPa"] < peak <= case["von_mises_max_MPa"] * (
            1 + 1e-9
        )
