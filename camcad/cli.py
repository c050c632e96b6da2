"""The camcad command line: build, check, size, compare, laws.

Exit codes (defined in :mod:`camcad.errors`): 0 success, 2 invalid input
(usage, unreadable or invalid design, unwritable output), 3 a design limit
violated (undercut, gouge, jump, pressure angle or stress limit), 1 anything
unexpected, 130 interrupted (SIGINT, SIGTERM, SIGHUP), 141 stdout closed by
its reader (``camcad check … | head``).
"""

from __future__ import annotations

import argparse
import logging
import math
import os
import signal
import sys
import threading
import warnings
from collections.abc import Iterator, Sequence
from contextlib import contextmanager, suppress
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING, Any

from camcad import _exit_interrupted
from camcad._version import __version__
from camcad.errors import (
    EXIT_INTERRUPTED,
    EXIT_INVALID,
    EXIT_LIMIT,
    EXIT_OK,
    EXIT_PIPE_CLOSED,
    EXIT_UNEXPECTED,
    CamcadError,
    DesignLimitError,
    exit_code,
    printable,
)

if TYPE_CHECKING:
    from camcad.pipeline import Progress

__all__ = ["build_parser", "main"]


class _Parser(argparse.ArgumentParser):
    """An argument parser that exits 2 with one clear line (argparse's own code for usage errors)."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(EXIT_INVALID, f"camcad: error: {printable(message)} (see '{self.prog} --help')\n")


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
    warnings = result.analysis.warnings
    if not args.quiet:
        for w in warnings:
            print(f"warning: {w}", file=sys.stderr)
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


def _fmt(value: Any, unit: str = "", digits: int = 3) -> str:
    if value is None:
        return "—"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return f"{value}{unit}"
    return f"{value:.{digits}f}{unit}"


def _at(section: dict[str, Any], key: str) -> str:
    """`` at 90.0° (just before the joint)`` for an extreme of ``section``, or ``""``."""
    angle = section.get(f"{key}_angle_deg")
    if angle is None:
        return ""
    side = section.get(f"{key}_side")
    return f" at {angle:.1f}°" + (f" (just {side.replace(' joint', ' the joint')})" if side else "")


def _lift_row(motion: dict[str, Any]) -> tuple[str, str]:
    """The nominal lift (or swing), with the true stroke beside it where the travel exceeds it."""
    name, u, shown = ("lift", "mm", " mm") if "lift_mm" in motion else ("arm swing", "deg", "°")
    text = _fmt(motion[f"lift_{u}"], shown)
    stroke = motion.get(f"stroke_{u}")
    if stroke is not None and round(stroke, 3) != round(motion[f"lift_{u}"], 3):
        low, high = (round(motion[f"travel_{e}_{u}"], 3) + 0.0 for e in ("min", "max"))  # no "-0.000"
        top = f"{_fmt(low, shown)} to {_fmt(high, shown)}"
        text += f" (true stroke {_fmt(stroke, shown)}: {top} at {motion['travel_max_angle_deg']:.1f}°)"
    return name, text


def _check_rows(summary: dict[str, Any], design: Any) -> list[tuple[str, str]]:
    geo, dyn = summary["geometry"], summary["dynamics"]
    fit = summary.get("fit") or {}
    limit = math.degrees(design.cam.max_pressure_angle)
    return [
        _lift_row(summary["motion"]),
        (
            "max pressure angle",
            _fmt(geo["pressure_angle_max_deg"], "°", 2)
            + _at(geo, "pressure_angle_max")
            + f" (limit {limit:g}°"
            + (
                f"; {flank} flank drives)"
                if (flank := summary.get("groove", {}).get("pressure_angle_max_flank"))
                else ")"
            ),
        ),
        (
            "min curvature radius",
            _fmt(geo["curvature_radius_min_mm"], " mm") + _at(geo, "curvature_radius_min"),
        ),
        ("min concave radius", _fmt(geo["concave_radius_min_mm"], " mm") + _at(geo, "concave_radius_min")),
        ("undercut", _fmt(geo["undercut"])),
        ("max torque", _fmt(dyn.get("torque_max_Nmm"), " N·mm", 1) + _at(dyn, "torque_max")),
        ("max contact force", _fmt(dyn.get("contact_force_max_N"), " N", 2) + _at(dyn, "contact_force_max")),
        ("min contact force", _fmt(dyn.get("contact_force_min_N"), " N", 2) + _at(dyn, "contact_force_min")),
        (
            "max contact stress",
            _fmt(dyn.get("hertz_stress_max_MPa"), " MPa", 1)
            + _at(dyn, "hertz_stress_max")
            + (f" ({dyn['hertz_stress_max_flank']} flank)" if dyn.get("hertz_stress_max_flank") else ""),
        ),
        (
            "follower jump",
            "none (positive drive)"
            if {"groove", "second_plate", "barrel"} & set(summary)
            else _fmt(dyn.get("jump")),
        ),
        (
            "fit control points",
            f"{fit['control_points']} (max error {fit['max_error_mm'] * 1000:.3f} µm)" if fit else "—",
        ),
    ]


def _duty_rows(summary: dict[str, Any]) -> list[tuple[str, str]]:
    """The rows ``[life]``, ``[lubrication]`` and ``[drive]`` add to ``camcad check`` (issue 35)."""
    rows: list[tuple[str, str]] = []
    life, film, drive = summary.get("life"), summary.get("lubrication"), summary.get("drive")
    if life is not None and "sliding_speed_max_mm_per_s" in life:
        rows.append(
            ("rolling life", f"n/a: the face slides (max {life['sliding_speed_max_mm_per_s']:.1f} mm/s)")
        )
    if life is not None and "roller_life_h" in life:
        hours = life["roller_life_h"]
        rows.append(
            (
                "roller L10 life",
                ("unloaded" if hours is None else f"{hours:.4g} h")
                + f" (P {life['roller_equivalent_load_N']:.1f} N,"
                + f" {life['roller_turns_per_cam_turn']:.3f} roller turns a turn)",
            )
        )
    if life is not None and "track_life_h" in life:
        hours = life["track_life_h"]
        rows.append(("track life", "unloaded" if hours is None else f"{hours:.4g} h"))
    if film is not None:
        rows.append(
            (
                "min film ratio λ",
                _fmt(film["min_film_ratio"], "", 2)
                + _at(film, "min_film_ratio")
                + f" (limit {film['film_ratio_limit']:g})",
            )
        )
    if drive is not None:
        for line in drive["checks"]:
            verdict = "" if line["ok"] is None else (" ok" if line["ok"] else " FAILS")
            limit = "" if line["limit"] is None else f" (limit {line['limit']:g})"
            unit = "" if line["unit"] == "1" else f" {line['unit']}"
            rows.append((f"motor {line['name']}", f"{line['value']:.4g}{unit}{limit}{verdict}"))
    return rows


def _vibration_rows(summary: dict[str, Any]) -> list[tuple[str, str]]:
    """The rows ``[vibration]`` adds to ``camcad check`` (issue 34): the elastic train at the design speed."""
    vib = summary.get("vibration")
    if vib is None:
        return []
    unit = "mm" if "error_peak_mm" in vib else "deg"
    shown = " mm" if unit == "mm" else "°"
    force = " N" if unit == "mm" else " N·mm"
    at = f" at {vib['speed_rpm']:g} rpm"
    rows = [
        ("natural frequency", ", ".join(f"{f:.4g} Hz" for f in vib["natural_frequencies_hz"])),
        (
            "peak dynamic error",
            f"{vib[f'error_peak_{unit}']:.4g}{shown} at {vib['error_peak_angle_deg']:.1f}°{at}",
        ),
        (
            "min dynamic contact force",
            f"{vib['contact_force_min']:.4g}{force} at {vib['contact_force_min_angle_deg']:.1f}°{at}",
        ),
    ]
    for k, value in enumerate(vib[f"residual_{unit}"], start=1):
        rows.append((f"residual in dwell {k}", f"{value:.4g}{shown}"))
    flights = vib["flights"]
    leaves = "no"
    if vib["leaves_cam"]:
        leaves = "yes" + (f", at {flights[0]['leave_deg']:.1f}°" if flights else "")
    rows.append(("leaves the cam", leaves))
    if "compensate_rpm" in vib:
        rows.append(
            (
                "polydyne lift correction",
                f"max |c − s| {vib[f'lift_correction_max_{unit}']:.4g}{shown}"
                f" (tuned for {vib['compensate_rpm']:g} rpm)",
            )
        )
    return rows


def _barrel_rows(summary: dict[str, Any]) -> list[tuple[str, str]]:
    """The rows a barrel cam adds to ``camcad check`` (issue 36): pressure angles, groove, slip, walls."""
    barrel = summary.get("barrel")
    if barrel is None:
        return []
    rows: list[tuple[str, str]] = []
    for where in ("bottom", "pitch", "top"):
        ext = barrel["pressure_angle_max"][where]
        radius = barrel["stations_mm"][where]
        rows.append(
            (
                f"pressure angle at {where}",
                f"{ext['value_deg']:.2f}° at {ext['angle_deg']:.1f}° (radius {radius:g} mm)",
            )
        )
    z = barrel["groove_z_mm"]
    rows.append(
        ("groove along the axis", f"{z['lowest']:.3f} to {z['highest']:.3f} mm (of {barrel['length_mm']:g})")
    )
    slip = barrel["slip"]
    rows.append(
        (
            "roller slip",
            f"{slip['across_max']['value_mm_per_rad']:.3f} mm/rad round it, "
            f"{slip['along_max']['value_mm_per_rad']:.3f} mm/rad along it (× ω for mm/s)",
        )
    )
    return rows


def _positive_rows(summary: dict[str, Any]) -> list[tuple[str, str]]:
    """The rows a groove or a conjugate pair adds to ``camcad check``: flanks, second plate, crossovers."""
    rows: list[tuple[str, str]] = []
    groove, second = summary.get("groove"), summary.get("second_plate")
    if groove is not None:
        rows += [
            ("groove width", _fmt(groove["width_mm"], " mm")),
            ("largest cutter radius", _fmt(groove["tool_radius_max_mm"], " mm")),
            ("outer flank reach", _fmt(groove["outer_flank_reach_mm"], " mm")),
        ]
        for name, flank in summary["dynamics"].get("flanks", {}).items():  # where each flank drives
            load = "does not drive"
            if flank["contact_force_max_N"] is not None:
                load = (
                    _fmt(flank["contact_force_max_N"], " N", 2)
                    + _at(flank, "contact_force_max")
                    + ", stress "
                    + _fmt(flank["hertz_stress_max_MPa"], " MPa", 1)
                    + _at(flank, "hertz_stress_max")
                )
            rows.append((f"{name} flank max load", load))
    if second is not None:
        geo = second["geometry"]
        rows += [
            (
                "2nd plate pressure angle",
                _fmt(geo["pressure_angle_max_deg"], "°", 2) + _at(geo, "pressure_angle_max"),
            ),
            (
                "2nd plate min curvature",
                _fmt(geo["curvature_radius_min_mm"], " mm") + _at(geo, "curvature_radius_min"),
            ),
        ]
        dyn2 = second["dynamics"]  # the second plate's own roller and contact
        rows += [
            (
                "2nd plate max force",
                _fmt(dyn2.get("contact_force_max_N"), " N", 2) + _at(dyn2, "contact_force_max"),
            ),
            (
                "2nd plate max stress",
                _fmt(dyn2.get("hertz_stress_max_MPa"), " MPa", 1) + _at(dyn2, "hertz_stress_max"),
            ),
        ]
    if groove is not None or second is not None:
        dyn = summary["dynamics"]
        crossings = ", ".join(f"{a:.1f}°" for a in dyn.get("crossover_angles_deg", [])) or "none"
        rows.append(("crossovers", crossings))
        if dyn.get("impact_speed_max_mm_per_s") is not None:
            rows.append(("max impact speed", _fmt(dyn["impact_speed_max_mm_per_s"], " mm/s", 1)))
    return rows


def _fea_rows(fea: dict[str, Any]) -> list[tuple[str, str]]:
    """The finite-element check's rows of ``camcad check``: the peak von Mises stress, then each case."""
    limit = fea.get("allowable_stress_MPa")
    peak = _fmt(fea.get("von_mises_max_MPa"), " MPa", 1)
    if fea.get("von_mises_max_angle_deg") is not None:
        peak += f" at {fea['von_mises_max_angle_deg']:.1f}°, {fea['von_mises_max_where']}"
    rows = [("FE max von Mises", peak + (f" (limit {limit:g} MPa)" if limit is not None else ""))]
    for case in fea.get("cases", []):
        rows.append(
            (
                f"  FE case {case['case']}",
                f"{case['label']} at {case['angle_deg']:.1f}°: von Mises {case['von_mises_max_MPa']:.1f} MPa "
                f"(Hertz {case['hertz_stress_MPa']:.1f} MPa)",
            )
        )
    return rows


def _cmd_check(args: argparse.Namespace) -> int:
    from camcad.design import load_design
    from camcad.pipeline import analyse

    design = load_design(args.design)
    # check does not depend on the [gcode] options: it plans no toolpath (build does)
    analysis = analyse(design, strict=False, toolpath=False, fea=args.fea or design.fea is not None)
    rows = _check_rows(analysis.summary(), design) + _positive_rows(analysis.summary())
    rows += _barrel_rows(analysis.summary())
    rows += _duty_rows(analysis.summary())
    rows += _vibration_rows(analysis.summary())
    if analysis.fea is not None:
        rows += _fea_rows(analysis.summary()["fea"])
    width = max(len(k) for k, _ in rows)
    print(f"{design.cam.name} ({args.design})")
    for key, value in rows:
        print(f"  {key:<{width}}  {value}")
    limits = {f.message for f in analysis.findings}
    for finding in analysis.findings:
        print(f"  {'hard' if finding.hard else 'soft'} limit: {finding.message}")
    for w in analysis.warnings:
        if w not in limits:
            print(f"  note: {w}")
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


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every subcommand."""
    parser = _Parser(
        prog="camcad",
        description="Disc cams from a motion specification to DXF, STL, G-code and a report.",
        epilog="Exit codes: 0 ok, 1 unexpected failure, 2 invalid input, 3 design limit violated.",
    )
    parser.add_argument("--version", action="version", version=f"camcad {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True

    p = sub.add_parser("build", help="analyse a design and write every shop file and the report")
    p.add_argument("design", help="design file (TOML)")
    p.add_argument("-o", "--output", required=True, help="output folder (created; files replaced)")
    p.add_argument(
        "--only",
        help="comma-separated outputs to write: tables, dxf, stl, step, gcode, fea, report (summary.json "
        "always; fea = stress.vtu, by default only with a [fea] table)",
    )
    p.add_argument("-q", "--quiet", action="store_true", help="no progress output")
    p.add_argument("--timings", action="store_true", help="print the seconds each stage took (stdout)")
    p.add_argument(
        "--strict",
        action="store_true",
        help="treat soft limits (pressure angle, contact stress, follower jump) as errors: exit 3, no files",
    )
    p.set_defaults(handler=_cmd_build)

    p = sub.add_parser("check", help="validate and analyse without writing; exit 3 if a limit is violated")
    p.add_argument("design", help="design file (TOML)")
    p.add_argument("--fea", action="store_true", help="run the finite-element check (default: with [fea])")
    p.set_defaults(handler=_cmd_check)

    p = sub.add_parser("size", help="smallest base radius meeting the pressure-angle and curvature limits")
    p.add_argument("design", help="design file (TOML)")
    p.add_argument(
        "--pivot",
        action="store_true",
        help="oscillating followers: the smallest pivot distance at the design's base radius instead",
    )
    p.set_defaults(handler=_cmd_size)

    p = sub.add_parser("compare", help="compare designs side by side (table, and overlay plots with -o)")
    p.add_argument("designs", nargs="+", help="design files (TOML)")
    p.add_argument("-o", "--output", help="folder for compare.html")
    p.set_defaults(handler=_cmd_compare)

    p = sub.add_parser("laws", help="list the motion laws and their parameters")
    p.set_defaults(handler=_cmd_laws)

    p = sub.add_parser("schema", help="print the JSON Schema of the design file (for editors)")
    p.set_defaults(handler=_cmd_schema)

    p = sub.add_parser("serve", help="edit a design live in the browser (local web page on 127.0.0.1)")
    p.add_argument("design", help="design file (TOML)")
    p.add_argument("--port", type=int, default=0, help="port on 127.0.0.1 (default: a free one)")
    p.add_argument("--open", action="store_true", help="open the page in the default browser")
    p.set_defaults(handler=_cmd_serve)

    p = sub.add_parser("optimize", help="constrained optimisation over design-file keys, or a Pareto front")
    p.add_argument("design", help="design file (TOML)")
    p.add_argument(
        "--minimize",
        action="append",
        required=True,
        metavar="QUANTITY",
        help="base_radius, pressure_angle, contact_stress, torque, …; two (comma or repeated) for a front",
    )
    p.add_argument(
        "--vary",
        action="append",
        default=[],
        metavar="NAME=LOW:HIGH|A,B,…",
        help="a variable: a range, or choices tried one by one (repeat)",
    )
    p.add_argument(
        "--limit",
        action="append",
        default=[],
        metavar="QUANTITY<=VALUE",
        help="a limit besides the design's own (pressure angle, allowable stress, no undercut)",
    )
    p.add_argument("--method", default="slsqp", help="slsqp (default) or trust-constr")
    p.add_argument("--starts", type=int, default=1, help="local searches: the design's values, then LHS")
    p.add_argument("--points", type=int, default=7, help="points of a two-objective front (default 7)")
    p.add_argument("-o", "--output", required=True, help="folder for the result files")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress output")
    p.set_defaults(handler=_cmd_optimize)

    p = sub.add_parser("sweep", help="analyse a grid or sample of design variants")
    p.add_argument("design", help="design file (TOML)")
    p.add_argument(
        "--grid",
        action="append",
        default=[],
        metavar="NAME=START:STOP:COUNT|A,B,…",
        help="a variable and its values (repeat); with --samples a range START:STOP",
    )
    p.add_argument("--samples", type=int, help="Latin-hypercube sampling of this many designs, not a grid")
    p.add_argument("--seed", type=int, default=0, help="seed of the Latin hypercube (default 0)")
    p.add_argument(
        "--limit",
        action="append",
        default=[],
        metavar="QUANTITY<=VALUE",
        help="a limit judged in the feasible column besides the design's own",
    )
    p.add_argument(
        "--pareto",
        default="base_radius,contact_stress",
        help="the two minimised quantities of the front (default base_radius,contact_stress)",
    )
    p.add_argument("--format", default="parquet", help="table format: parquet (default) or csv")
    p.add_argument("--jobs", type=int, help="local worker processes (default: every core; 1: this process)")
    p.add_argument("--scheduler", help="a Dask scheduler address, e.g. tcp://host:8786 (instead of --jobs)")
    p.add_argument("--chunk-size", type=int, default=16, help="designs per unit of work (default 16)")
    p.add_argument("-o", "--output", required=True, help="folder for sweep.parquet (or .csv) and sweep.html")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress output")
    p.set_defaults(handler=_cmd_sweep)

    p = sub.add_parser(
        "tolerance", help="tolerance study of a design's [tolerance] table (Monte Carlo or linear)"
    )
    p.add_argument("design", help="design file (TOML) with a [tolerance] table")
    p.add_argument("--format", default="parquet", help="table format: parquet (default) or csv")
    p.add_argument("--jobs", type=int, help="local worker processes (default: every core; 1: this process)")
    p.add_argument("--scheduler", help="a Dask scheduler address, e.g. tcp://host:8786 (instead of --jobs)")
    p.add_argument("-o", "--output", required=True, help="folder for tolerance.parquet, .json and .html")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress output")
    p.set_defaults(handler=_cmd_tolerance)

    p = sub.add_parser(
        "inspect", help="a measured cam (CMM points) against its design; exit 3 outside the band"
    )
    p.add_argument("design", help="design file (TOML)")
    p.add_argument(
        "measured", help="measured points: CSV with a header x, y (mm) or angle (deg), radius (mm)"
    )
    p.add_argument("--band", type=float, help="tolerance band ± mm (default: the design's tolerance.form_pm)")
    p.add_argument(
        "--stock", type=float, help="write a compensated cam.ngc and profile.dxf; the most it may cut, mm"
    )
    p.add_argument(
        "--tool-diameter", type=float, help="tool of the compensated program, mm (default [gcode])"
    )
    p.add_argument(
        "-o", "--output", required=True, help="folder for inspection.csv, .json, .html, actual_motion.csv"
    )
    p.set_defaults(handler=_cmd_inspect)
    return parser


def _interrupt(signum: int, frame: FrameType | None) -> None:
    """SIGTERM and SIGHUP end a run like Ctrl-C: clean up, exit 130."""
    raise KeyboardInterrupt


@contextmanager
def _terminate_like_interrupt() -> Iterator[None]:
    """Map SIGTERM and SIGHUP to KeyboardInterrupt while the block runs (main thread only)."""
    names = ("SIGTERM", "SIGHUP")
    signums = [getattr(signal, n) for n in names if hasattr(signal, n)]
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {s: signal.signal(s, _interrupt) for s in signums}
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def _silence_stdout() -> None:
    """Point stdout at the null device, so the flush at exit does not fail on a closed pipe again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):  # stdout is not a real file (e.g. captured by a test)
        pass


@contextmanager
def _no_library_logging() -> Iterator[None]:
    """Keep log records of the libraries camcad uses off stderr while the block runs.

    Without a handler Python prints warnings to stderr, e.g. matplotlib's
    when the home folder is not writable; camcad's own messages are its errors.
    """
    root = logging.getLogger()
    handler = logging.NullHandler()
    root.addHandler(handler)
    try:
        yield
    finally:
        root.removeHandler(handler)


@contextmanager
def _no_library_warnings() -> Iterator[None]:
    """Keep Python warnings of the libraries camcad uses (a SciPy ``RuntimeWarning``) off stderr.

    camcad reports what matters as findings, notes and errors of its own;
    a library's warning is a line the user cannot act on.
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line and return the exit code.

    Ctrl-C (SIGINT, and SIGTERM, SIGHUP) at any moment gives one line,
    ``camcad: interrupted``, and exit 130: while a command runs it raises
    ``KeyboardInterrupt``, which cleans up (a staged output folder is
    removed); when this function is the process's entry point (the
    ``camcad`` command, ``python -m camcad``), a signal after it returns ends
    the process the same way. The heavy modules are imported by the command
    after the handling is in place.
    """
    entry = _is_entry_point()
    previous: Any = None
    code = EXIT_INTERRUPTED
    try:
        if threading.current_thread() is threading.main_thread():
            previous = signal.signal(signal.SIGINT, signal.default_int_handler)
        try:
            code = _run(argv)
        except KeyboardInterrupt:  # a signal while an error line was printed
            print("camcad: interrupted", file=sys.stderr)
    except KeyboardInterrupt:  # the moment the handling was put in place
        print("camcad: interrupted", file=sys.stderr)
    finally:
        if previous is not None:
            signal.signal(signal.SIGINT, _exit_interrupted if entry else previous)
    if entry and code == EXIT_INTERRUPTED:
        # CPython 3.11 remembers an interrupt that went through exec() of a string (dataclasses,
        # namedtuple) and then ends the process by SIGINT at exit, though camcad handled it; the
        # clean-up has run, so leave now with the documented code
        with suppress(OSError, ValueError):
            sys.stdout.flush()
        with suppress(OSError, ValueError):
            sys.stderr.flush()
        os._exit(EXIT_INTERRUPTED)
    return code


def _is_entry_point() -> bool:
    """Whether :func:`main` runs as the process's command (so a later SIGINT may end the process at once)."""
    main_module = sys.modules.get("__main__")
    spec = getattr(main_module, "__spec__", None)
    if spec is not None and spec.name == "camcad.__main__":  # python -m camcad
        return True
    return os.path.basename(sys.argv[0] if sys.argv else "") in ("camcad", "camcad.exe")  # the command


def _run(argv: Sequence[str] | None) -> int:
    """Parse, run the command, and map its errors to one line and an exit code."""
    try:
        args = build_parser().parse_args(argv)
        with _terminate_like_interrupt(), _no_library_logging(), _no_library_warnings():
            code = int(args.handler(args))
            sys.stdout.flush()
        return code
    except KeyboardInterrupt:
        print("camcad: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        _silence_stdout()
        return EXIT_PIPE_CLOSED
    except DesignLimitError as err:
        _say("design limit", str(err))
        return exit_code(err)
    except CamcadError as err:
        _say("error", str(err))
        return exit_code(err)
    except OSError as err:
        where = f": {os.fsdecode(err.filename)}" if err.filename else ""
        _say("error", f"{err.strerror or err}{where}")
        return exit_code(err)
    except Exception as err:  # the one place that maps surprises to exit 1
        _say("unexpected error", f"{type(err).__name__}: {err}")
        print("camcad: please report this with your design file", file=sys.stderr)
        return EXIT_UNEXPECTED


def _say(kind: str, message: str) -> None:
    """Print ``camcad: <kind>: <message>`` as one line on stderr: every user string in it escaped."""
    print(f"camcad: {kind}: {printable(message)}", file=sys.stderr)
