"""A barrel build's cost against a plate build of the same motion (issue 36: at most 3×).

Run ``python benchmarks/barrel.py``. Each build runs in a fresh process
(imports included, as ``camcad build`` pays them), median of 3, the two
kinds interleaved so that the machine's load hits both alike:

- barrel: the indexer of ``tests/barrel_cases.py`` (translating roller,
  dwell – 40 mm modified-sine index over 100° – dwell – return): limits,
  certified wall surfaces, the STEP solid through OpenCASCADE, the STL,
  the developed DXF and the 4-axis G-code, written into a temporary folder;
- plate: ``camcad.pipeline.build`` (serial) of a plate cam with the same
  motion and roller (base radius 60 mm), once with every output (report
  included) and once with the barrel's outputs only (``--only
  dxf,stl,step,gcode``).

It prints the seconds of each and the ratio, plus the barrel's stages
measured in one process (OpenCASCADE's import apart).
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
REPEATS = 3

_BARREL = """
import json, sys, tempfile, time
from pathlib import Path
mark = [time.perf_counter()]
stages = {}
def tick(name):
    now = time.perf_counter(); stages[name] = now - mark[0]; mark[0] = now
from tests.barrel_cases import INDEXER as c
from camcad.geometry.barrel_limits import barrel_limits
from camcad.fit.surface import fit_barrel_walls
from camcad.export.barrel_mesh import barrel_mesh, barrel_stl_bytes
from camcad.export.barrel_dxf import developed_groove, write_developed_dxf
from camcad.toolpath.barrel import BarrelToolpathOptions, plan_barrel
from camcad.export.gcode.barrel import render_barrel_program
tick("import camcad")
import OCP.BRepAlgoAPI, OCP.STEPControl
tick("import OCP")
out = Path(tempfile.mkdtemp())
barrel_limits(c.program, c.follower, c.options); tick("geometry")
fit = fit_barrel_walls(c.program, c.follower, c.options); tick("fit")
from camcad.export.barrel_step import barrel_shape, barrel_step_bytes
solid = barrel_shape(fit, c.options)
(out / "cam.step").write_bytes(barrel_step_bytes(solid, name="indexer")); tick("step")
(out / "cam.stl").write_bytes(barrel_stl_bytes(barrel_mesh(c.program, c.follower, c.options))); tick("mesh")
groove = developed_groove(c.program, c.follower, c.options)
write_developed_dxf(groove, out / "profile.dxf", length=c.options.length)
tick("dxf")
tp = plan_barrel(c.program, c.follower, c.options, BarrelToolpathOptions())
(out / "cam.ngc").write_text(render_barrel_program(tp, name="indexer")); tick("gcode")
print("RESULT " + json.dumps(stages))
"""

_PLATE = """
import json, tempfile, time
from pathlib import Path
t0 = time.perf_counter()
from camcad.pipeline import build
from tests.conftest import make_design
design = make_design(law="modified-sine", lift=40.0, base_radius=60.0, roller_radius=8.0,
                     spans=(100.0, 80.0, 100.0, 80.0))
only = None if ONLY == "all" else ONLY.split(",")
build(design, Path(tempfile.mkdtemp()) / "out", only=only, parallel=False)
print("RESULT " + json.dumps({"total": time.perf_counter() - t0}))
"""


def _run(code: str) -> tuple[float, dict[str, float]]:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    start = time.perf_counter()
    proc = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True, check=True
    )
    wall = time.perf_counter() - start
    (line,) = [s for s in proc.stdout.splitlines() if s.startswith("RESULT ")]
    return wall, json.loads(line[len("RESULT ") :])


def main() -> None:
    """Print the table."""
    barrel, plate, same, stages = [], [], [], []
    for _ in range(REPEATS):
        wall, st = _run(_BARREL)
        barrel.append(wall)
        stages.append(st)
        plate.append(_run(_PLATE.replace("ONLY", repr("all")))[0])
        same.append(_run(_PLATE.replace("ONLY", repr("dxf,stl,step,gcode")))[0])
    b, p, q = statistics.median(barrel), statistics.median(plate), statistics.median(same)
    print("| build | seconds (median of 3, fresh process) | barrel / this |")
    print("| --- | --- | --- |")
    print(f"| barrel (indexer): STEP, STL, DXF, G-code | {b:.2f} | 1 |")
    print(f"| plate, same motion, every output | {p:.2f} | {b / p:.2f} |")
    print(f"| plate, same motion, --only dxf,stl,step,gcode | {q:.2f} | {b / q:.2f} |")
    print()
    print("| barrel stage | seconds (median) |")
    print("| --- | --- |")
    for name in stages[0]:
        print(f"| {name} | {statistics.median(s[name] for s in stages):.2f} |")


if __name__ == "__main__":
    from _readme import captured  # this folder is on sys.path when the script runs

    with captured("barrel"):  # the printed tables become its section of benchmarks/README.md
        main()
