"""The files of ``camcad optimize``: the design file of the optimum, the front and a JSON record.

Written all at once into the output folder (:func:`camcad.export.atomic.staged_folder`):

- ``optimum.toml``: the base design file with the optimum's values written in
  (one objective), ready for ``camcad build``;
- ``front.csv`` and ``front-01.toml`` … (two objectives): the Pareto front,
  one row and one design file per point, in order of the first objective;
- ``optimize.json``: every candidate with its values, objectives,
  constraints (value, limit, relative margin, active) and the solver's message.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from camcad.design.toml_text import toml_text
from camcad.explore.optimize import Candidate, OptimizeResult, Problem
from camcad.explore.table import csv_text

__all__ = ["optimize_files", "write_optimize"]


def _header(problem: Problem, cand: Candidate, what: str) -> str:
    values = ", ".join(f"{k} = {v!r}" for k, v in cand.values.items())
    objectives = ", ".join(f"{k} = {v:.6g}" for k, v in cand.objectives.items() if v is not None)
    active = ", ".join(cand.active) or "none"
    text = (
        f"{what} of {problem.source or 'the design'} found by camcad optimize\n"
        f"variables: {values}\nobjectives: {objectives}\nactive constraints: {active}"
    )
    if not cand.feasible:
        broken = ", ".join([c.name for c in cand.constraints if c.margin < 0.0] + list(cand.findings)) or (
            "the design cannot be analysed"
        )
        text = (
            f"INFEASIBLE: no design within the ranges meets every limit; this one breaks: {broken}\n" + text
        )
    return text


def _rebased(data: dict[str, Any], source: str, outdir: Path) -> dict[str, Any]:
    """The mapping with each point-table ``file`` made relative to ``outdir``, where it is read from.

    A design file names its table relative to its own folder; the design file
    of the optimum lives in the output folder, so the name is rewritten to
    reach the same file from there.
    """
    segments = data.get("motion")
    if not source or not isinstance(segments, list):
        return data
    here = Path(source).resolve().parent
    out = dict(data)
    out["motion"] = [
        s | {"file": os.path.relpath(here / s["file"], outdir.resolve())}
        if isinstance(s, dict) and isinstance(s.get("file"), str) and not Path(s["file"]).is_absolute()
        else s
        for s in segments
    ]
    return out


def optimize_files(problem: Problem, result: OptimizeResult, *, outdir: str | Path = ".") -> dict[str, str]:
    """File name → text of every file ``camcad optimize`` writes into ``outdir``."""
    outdir = Path(outdir)
    files: dict[str, str] = {}
    record: dict[str, Any] = {
        "design": problem.source,
        "objectives": [m.name for m in problem.objectives],
        "variables": {v.name: {"path": v.path, "values": v.spec()} for v in problem.variables},
        "method": problem.method,
        **result.summary(),
    }
    if result.best is not None:
        data = _rebased(result.best.data, problem.source, outdir)
        files["optimum.toml"] = toml_text(data, header=_header(problem, result.best, "The optimum"))
    rows = []
    for i, cand in enumerate(result.front, start=1):
        name = f"front-{i:02d}.toml"
        data = _rebased(cand.data, problem.source, outdir)
        files[name] = toml_text(data, header=_header(problem, cand, f"Pareto point {i}"))
        rows.append(
            {
                "point": i,
                "file": name,
                **cand.values,
                **{m.column: cand.objectives[m.name] for m in problem.objectives},
            }
            | {"active": "; ".join(cand.active)}
        )
    if rows:
        files["front.csv"] = csv_text(rows)
    files["optimize.json"] = json.dumps(record, indent=2, ensure_ascii=False, default=repr) + "\n"
    return files


def write_optimize(problem: Problem, result: OptimizeResult, outdir: str | Path) -> list[Path]:
    """Write :func:`optimize_files` into ``outdir`` all at once; return the paths."""
    from camcad.export.atomic import atomic_write_text, staged_folder

    files = optimize_files(problem, result, outdir=outdir)
    with staged_folder(outdir) as staging:
        for name, text in files.items():
            atomic_write_text(staging.path / name, text)
    return [Path(outdir) / name for name in files]
