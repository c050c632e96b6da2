"""The command line's commands: each reads its arguments, runs camcad and prints the result."""

from __future__ import annotations

import argparse
import math
import os
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from camcad._version import __version__
from camcad.cli.render import (
    _barrel_rows,
    _check_rows,
    _duty_rows,
    _fea_rows,
    _fmt,
    _positive_rows,
    _vibration_rows,
)
from camcad.errors import (
    EXIT_LIMIT,
    EXIT_OK,
    DesignLimitError,
)

if TYPE_CHECKING:
    from camcad.pipeline import Progress


def _progress(quiet: bool) -> Progress | None:
    if quiet:
        return None

    def report(stage: str, seconds: float) -> None:
        print(f"  {stage:<10} {seconds * 1000:8.1f} ms", file=sys.stderr)

    return report


def _cmd_build(args: argparse.Namespace) -> int:
    from camcad.design import load_design
    from camcad.pipeline import build

    design = load_design(args.design)
    only = args.only.split(",") if args.only else None
    if not args.quiet:
        print(f"camcad {__version__}: building {design.cam.name!r} from {args.design}", file=sys.stderr)
    result = build(design, args.output, only=only, progress=_progress(args.quiet), strict=args.strict)
    if not args.quiet:
        for f in result.analysis.findings:
            if not f.hard:  # a hard one stopped the build before it wrote anything
                print(f"{'note' if f.note else 'warning'}: {f.message}", file=sys.stderr)
        print(f"wrote {len(result.files)} files to {result.outdir}", file=sys.stderr)
        for path in result.files:
            print(f"  {path}")
    if args.timings:
        timings = result.analysis.timings
        width = max(len(stage) for stage in timings)
        for stage, seconds in timings.items():
            print(f"{stage:<{width}}  {seconds:.3f} s")
        print(f"{'total':<{width}}  {sum(timings.values()):.3f} s")
    return EXIT_OK


def _cmd_check(args: argparse.Namespace) -> int:
    from camcad.design import load_design
    from camcad.pipeline import analyse

    design = load_design(args.design)
    # check does not depend on the [gcode] options: it plans no toolpath (build does)
    analysis = analyse(design, strict=False, toolpath=False, fea=args.fea or design.fea is not None)
    positive = analysis.dynamics.positive_drive  # the family holds the follower on both ways (its Drive)
    rows = _check_rows(analysis.summary(), design, positive_drive=positive)
    rows += _positive_rows(analysis.summary(), positive_drive=positive)
    rows += _barrel_rows(analysis.summary())
    rows += _duty_rows(analysis.summary())
    for later in analysis.parts[1:]:  # every further part's life and film (its own roller), the same rows
        if later.duty is not None:
            rows += _duty_rows(later.duty.summary(), f"{later.part.label} ")
    rows += _vibration_rows(analysis.summary())
    if analysis.fea is not None:
        rows += _fea_rows(analysis.summary()["fea"])
    for later in analysis.parts[1:]:  # every further plate's FE check, the same rows
        if later.fea is not None:
            rows += _fea_rows(later.fea.summary(), f"{later.part.label} ")
    width = max(len(k) for k, _ in rows)
    print(f"{design.cam.name} ({args.design})")
    for key, value in rows:
        print(f"  {key:<{width}}  {value}")
    for finding in analysis.findings:  # hard, soft, then notes
        label = "note" if finding.note else f"{finding.severity.value} limit"
        print(f"  {label}: {finding.message}")
    if analysis.violations:
        print(f"design limits violated: {', '.join(analysis.violations)}")
        return EXIT_LIMIT
    print("all design limits hold")
    return EXIT_OK


def _cmd_size(args: argparse.Namespace) -> int:
    from camcad.design import load_design
    from camcad.extremes import Extreme
    from camcad.geometry import Cam, min_base_radius, min_pivot_distance
    from camcad.geometry.families import family_of

    design = load_design(args.design)
    cam = Cam.from_design(design)
    search = min_pivot_distance if args.pivot else min_base_radius
    # a conjugate pair: both plates within both limits (the second plate follows the first's radius)
    parts = family_of(design.cam.style).parts(cam, design.family_options())
    conjugate = parts[-1].cam.conjugate  # a pair's second plate's tie to the first; None for one plate
    result = search(
        cam,
        max_pressure_angle=design.cam.max_pressure_angle,
        min_curvature_radius=design.min_curvature_radius,
        conjugate=conjugate,
    )
    if args.pivot:
        print(
            f"smallest pivot distance: {result.pivot_distance:.3f} mm "
            f"(design has {design.follower.pivot_distance:g} mm, base radius {design.cam.base_radius:g} mm)"
        )
    else:
        # rounded up to the printed µm: the printed radius, typed back, meets the limits
        shown = math.ceil(result.base_radius * 1000.0 - 1e-9) / 1000.0
        print(f"smallest base radius: {shown:.3f} mm (design has {design.cam.base_radius:g} mm)")
    where = Extreme(value=0.0, phi=result.angle, side=result.side).where()
    print(f"  limited by {result.limit} {where.replace('at ', 'at cam angle ', 1)}")
    print(
        f"  at that radius: max pressure angle {math.degrees(result.pressure_angle_max):.2f}° "
        f"(limit {math.degrees(design.cam.max_pressure_angle):g}°), "
        f"min convex curvature radius {result.curvature_radius_min:.3f} mm "
        f"(limit {design.min_curvature_radius:g} mm)"
    )
    return EXIT_OK


def _cmd_compare(args: argparse.Namespace) -> int:
    from camcad.design import load_design
    from camcad.pipeline import analyse
    from camcad.report import compare_text, write_compare

    analyses = [analyse(load_design(p), strict=False, toolpath=False) for p in args.designs]
    print(compare_text(analyses, width=100))  # names as A, B, … in a legend when they do not fit
    if args.output:
        from camcad.export.atomic import staged_folder

        with staged_folder(args.output) as staging:
            write_compare(analyses, staging.path / "compare.html")
        path = Path(args.output) / "compare.html"
        print(f"wrote {path}", file=sys.stderr)
    return EXIT_OK


def _design_mapping(path: str) -> dict[str, Any]:
    """A design file's TOML mapping, after the schema accepted the file (``optimize``, ``sweep``)."""
    import tomllib

    from camcad.design import load_design

    load_design(path)
    return tomllib.loads(Path(path).read_text(encoding="utf-8-sig"))


def _cmd_optimize(args: argparse.Namespace) -> int:
    from camcad.explore.files import write_optimize
    from camcad.explore.measures import measure, parse_limit
    from camcad.explore.optimize import Problem, optimize
    from camcad.explore.space import check_distinct, parse_variable

    data = _design_mapping(args.design)
    variables = tuple(
        parse_variable(v, data, flag="--vary", counted=False, source=args.design) for v in args.vary
    )
    check_distinct(variables, data, flag="--vary")
    problem = Problem(
        data=data,
        source=args.design,
        variables=variables,
        objectives=tuple(measure(m.strip(), "--minimize") for m in ",".join(args.minimize).split(",")),
        limits=tuple(parse_limit(text) for text in args.limit),
        method=args.method,
        starts=args.starts,
        points=args.points,
    )
    say = None if args.quiet else (lambda text: print(f"  trying {text}", file=sys.stderr))
    result = optimize(problem, progress=say)
    if len(result.tried) > 1:  # one optimum per combination of the discrete choices
        for cand in result.tried:
            objective = ", ".join(f"{k} = {_fmt(v)}" for k, v in cand.objectives.items())
            choices = ", ".join(f"{k} = {v}" for k, v in cand.values.items() if not isinstance(v, float))
            print(f"tried {choices}: {objective}{'' if cand.feasible else ' (infeasible)'}")
    shown = [result.best] if result.best is not None else list(result.front)
    for i, cand in enumerate(shown, start=1):
        head = "optimum" if result.best is not None else f"Pareto point {i}"
        objective = ", ".join(f"{k} = {_fmt(v)}" for k, v in cand.objectives.items())
        print(f"{head}{'' if cand.feasible else ' (INFEASIBLE)'}: {objective}")
        for name, value in cand.values.items():
            print(f"  {name} = {value!r}" if isinstance(value, float) else f"  {name} = {value}")  # exact
        for c in cand.constraints:
            limit = f" (limit {c.limit:g})" if math.isfinite(c.limit) else ""
            print(f"  {'*' if c.active else ' '} {c.name:<48} {_fmt(c.value)}{limit}")
        for bound in cand.bounds:
            print(f"  * {bound}")
    print(f"active constraints and bounds are marked *; {result.evaluations} analyses")
    for path in write_optimize(problem, result, args.output):
        print(f"wrote {path}", file=sys.stderr)
    if not any(c.feasible for c in shown):
        raise DesignLimitError("no design within the ranges meets every limit (see optimize.json)")
    return EXIT_OK


def _cmd_sweep(args: argparse.Namespace) -> int:
    from camcad.errors import UsageError
    from camcad.explore.measures import measure, parse_limit
    from camcad.explore.space import check_distinct, check_seed, grid_points, lhs_points, parse_variable
    from camcad.explore.sweep import SweepPlan, sweep

    check_seed(args.seed)
    data = _design_mapping(args.design)
    counted = args.samples is None
    variables = tuple(
        parse_variable(g, data, flag="--grid", counted=counted, source=args.design) for g in args.grid
    )
    if not variables:
        raise UsageError("--grid", "give at least one, e.g. --grid base_radius=30:80:51")
    check_distinct(variables, data, flag="--grid")
    names = [m.strip() for m in args.pareto.split(",")]
    if len(names) != 2:
        raise UsageError("--pareto", f"{args.pareto!r}: name two quantities, e.g. base_radius,contact_stress")
    if args.chunk_size < 1:
        raise UsageError("--chunk-size", f"{args.chunk_size} is not allowed (allowed: 1 or more)")
    points = grid_points(variables) if counted else lhs_points(variables, args.samples, seed=args.seed)
    plan = SweepPlan(
        data=data,
        source=args.design,
        variables=variables,
        points=tuple(points),
        limits=tuple(parse_limit(text) for text in args.limit),
        pareto=(measure(names[0], "--pareto"), measure(names[1], "--pareto")),
        sampling="grid" if counted else f"Latin hypercube, seed {args.seed}",
        chunk_size=args.chunk_size,
    )

    def report(done: int, total: int) -> None:  # on a terminal only: one line rewritten in place
        print(f"\r  {done}/{total} chunks", end="" if done < total else "\n", file=sys.stderr, flush=True)

    jobs = args.jobs if args.jobs is not None else (os.cpu_count() or 1)
    result = sweep(
        plan,
        args.output,
        fmt=args.format,
        jobs=jobs,
        scheduler=args.scheduler,
        progress=None if args.quiet or not sys.stderr.isatty() else report,
    )
    rows = result.rows
    counts = {s: sum(1 for r in rows if r["status"] == s) for s in ("ok", "limit", "invalid")}
    print(
        f"{len(rows)} designs: {counts['ok']} ok, {counts['limit']} breaking a limit, "
        f"{counts['invalid']} invalid; {sum(1 for r in rows if r['feasible'])} feasible, "
        f"{sum(1 for r in rows if r['pareto'])} on the Pareto front"
        + (f" ({result.resumed_chunks} chunks resumed)" if result.resumed_chunks else "")
    )
    for path in result.files:
        print(f"wrote {path}", file=sys.stderr)
    return EXIT_OK


def _toml_of(path: str) -> dict[str, Any]:
    """The TOML mapping of a design file the schema has just accepted (``tolerance``, ``inspect``)."""
    import tomllib

    data: dict[str, Any] = tomllib.loads(Path(path).read_text(encoding="utf-8-sig"))
    return data


def _cmd_tolerance(args: argparse.Namespace) -> int:
    from camcad.design import load_design
    from camcad.design.schema import parse_tolerance
    from camcad.errors import DesignError
    from camcad.explore.tolerance import tolerance_study
    from camcad.geometry.cam import Cam

    design = load_design(args.design)
    data = _toml_of(args.design)
    if "tolerance" not in data:
        raise DesignError(
            "tolerance", f"{args.design} has no [tolerance] table; see the README's [tolerance] keys"
        )
    spec = parse_tolerance(data["tolerance"], design)

    def report(done: int, total: int) -> None:
        print(f"\r  {done}/{total} chunks", end="" if done < total else "\n", file=sys.stderr, flush=True)

    jobs = args.jobs if args.jobs is not None else (os.cpu_count() or 1)
    result = tolerance_study(
        Cam.from_design(design),
        spec,
        args.output,
        name=design.cam.name,
        source=args.design,
        fmt=args.format,
        jobs=jobs,
        scheduler=args.scheduler,
        progress=None if args.quiet or not sys.stderr.isatty() else report,
        setup=design.dynamics_setup(),
    )
    summary = result.summary
    unit = summary["lift_unit"]
    for k, dwell in enumerate(summary["dwells"]):
        text = f"dwell {k} at {dwell['angle_deg']:.1f}°: linear σ {dwell['linear']['sigma']:.4g} {unit}, "
        text += f"worst case {dwell['linear']['worst_case']:.4g} {unit}"
        if "monte_carlo" in dwell:
            lo, hi = dwell["monte_carlo"]["percentiles"][0], dwell["monte_carlo"]["percentiles"][-1]
            text += f"; Monte Carlo 99.73 % within {lo:.4g} to {hi:.4g} {unit}"
        print(text)
    stress = summary["contact_stress"]
    if stress.get("percentiles") and stress["nominal"] is not None:
        lo, hi = stress["percentiles"][0], stress["percentiles"][-1]
        print(
            f"peak contact stress {stress['nominal']:.4g} MPa; "
            f"Monte Carlo 99.73 % within {lo:.4g} to {hi:.4g} MPa"
        )
    how = summary.get("evaluation", {})
    if how.get("method") == "quadratic":
        print(
            f"quadratic evaluation, checked on {how['certified_variants']} made cams re-solved exactly "
            "(the differences are in tolerance.json)"
        )
    alloc = summary["allocation"]
    if alloc is not None:
        largest = ", ".join(
            f"{k} ±{v:.4g}" if v is not None else f"{k} any" for k, v in alloc["largest_tolerances"].items()
        )
        verdict = "meet" if alloc["given_tolerances_meet_it"] else "do not meet"
        print(
            f"allocation for ±{alloc['dwell_accuracy']:g} {unit} ({alloc['method']}, confidence "
            f"{alloc['confidence']:g}): {largest}; the given tolerances {verdict} it"
        )
    for path in result.files:
        print(f"wrote {path}", file=sys.stderr)
    return EXIT_OK


def _inspect_band(args: argparse.Namespace, design_path: str, design: Any) -> float:
    """--band, or the design's [tolerance] form tolerance (±t; a σ as 3σ)."""
    from camcad.errors import UsageError

    if args.band is not None:
        if not (math.isfinite(args.band) and 0.0 < args.band <= 10.0):
            raise UsageError("--band", f"{args.band!r} mm is not allowed (allowed: over 0 up to 10 mm)")
        return float(args.band)
    data = _toml_of(design_path)
    if "tolerance" in data:
        from camcad.design.schema import parse_tolerance
        from camcad.geometry.sensitivity import Tol

        for t in parse_tolerance(data["tolerance"], design).tolerances:
            if t.tol is Tol.FORM:
                return t.value
    raise UsageError("--band", "give the tolerance band in mm (or form_pm in the design's [tolerance] table)")


def _cmd_inspect(args: argparse.Namespace) -> int:
    from camcad.design import load_design
    from camcad.design.table_file import read_table_file
    from camcad.errors import UsageError
    from camcad.explore.inspection import inspect_measured
    from camcad.inspect.measured import parse_measured

    design = load_design(args.design)
    band = _inspect_band(args, args.design, design)
    for flag, value in (("--stock", args.stock), ("--tool-diameter", args.tool_diameter)):
        if value is not None and not (math.isfinite(value) and 0.0 <= value <= 1000.0):
            raise UsageError(flag, f"{value!r} mm is not allowed (allowed: 0 to 1000 mm)")
    if args.tool_diameter is not None and args.stock is None:
        raise UsageError("--tool-diameter", "a compensated program needs --stock too")
    if args.tool_diameter == 0.0:
        raise UsageError("--tool-diameter", "0 mm is not allowed (allowed: over 0 up to 1000 mm)")
    text = read_table_file(args.measured, folder=None, where=args.measured)
    measured = parse_measured(text, where=args.measured)
    result = inspect_measured(
        design,
        measured,
        args.output,
        where=args.measured,
        band=band,
        stock=args.stock,
        tool_diameter=args.tool_diameter,
    )
    s = result.summary
    fit, dev = s["fit"], s["deviation"]
    print(f"{s['design']}: {s['points']} points ({s['layout']}) from {args.measured}")
    print(
        f"  fit: turn {fit['rotation_deg']:.4f}° ± {fit['rotation_sigma_deg']:.4f}°, cam axis at "
        f"({fit['centre_mm'][0]:.4f}, {fit['centre_mm'][1]:.4f}) mm "
        f"± {max(fit['centre_sigma_mm']) * 1000:.2f} µm"
    )
    print(
        f"  deviation {dev['min_mm'] * 1000:.2f} to {dev['max_mm'] * 1000:.2f} µm (band ±{band * 1000:g} µm, "
        f"scatter {dev['noise_mm'] * 1000:.2f} µm); {s['outside']} points outside"
    )
    for path in result.files:
        print(f"wrote {path}", file=sys.stderr)
    if not result.passed:
        lines = ", ".join(str(n) for n in s["outside_lines"][:10]) + (", …" if s["outside"] > 10 else "")
        print(f"the part is outside its band at {s['outside']} points (lines {lines})")
        return EXIT_LIMIT
    print("the part is within its band")
    return EXIT_OK


def _cmd_serve(args: argparse.Namespace) -> int:
    from camcad.errors import UsageError
    from camcad.serve import serve

    if not 0 <= args.port <= 65535:
        raise UsageError("--port", f"{args.port} is not a port (allowed: 0 for a free one, or 1 to 65535)")
    serve(args.design, port=args.port, open_browser=args.open)  # until Ctrl-C: exit 130
    return EXIT_OK


def _cmd_schema(args: argparse.Namespace) -> int:
    import json

    from camcad.design.editor_schema import design_json_schema

    print(json.dumps(design_json_schema(), indent=2, ensure_ascii=False))
    return EXIT_OK


def _cmd_laws(args: argparse.Namespace) -> int:
    from camcad.motion.laws import LAWS

    for info in LAWS.values():
        params = ", ".join(
            f"{p.name} ({p.allowed}{'' if p.default is None else f', default {p.default}'})"
            for p in info.parameters
        )
        print(f"{info.name:<20} {info.summary}" + (f"  [parameters: {params}]" if params else ""))
    return EXIT_OK
