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
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING, Any

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
)

if TYPE_CHECKING:
    from camcad.pipeline import Progress

__all__ = ["build_parser", "main"]


class _Parser(argparse.ArgumentParser):
    """An argument parser that exits 2 with one clear line (argparse's own code for usage errors)."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(EXIT_INVALID, f"camcad: error: {message} (see '{self.prog} --help')\n")


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


def _check_rows(summary: dict[str, Any], design: Any) -> list[tuple[str, str]]:
    geo, dyn = summary["geometry"], summary["dynamics"]
    fit = summary.get("fit") or {}
    limit = math.degrees(design.cam.max_pressure_angle)
    return [
        (
            ("lift", _fmt(summary["motion"]["lift_mm"], " mm"))
            if "lift_mm" in summary["motion"]
            else ("arm swing", _fmt(summary["motion"]["lift_deg"], "°"))
        ),
        (
            "max pressure angle",
            _fmt(geo["pressure_angle_max_deg"], "°", 2)
            + _at(geo, "pressure_angle_max")
            + f" (limit {limit:g}°)",
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
            _fmt(dyn.get("hertz_stress_max_MPa"), " MPa", 1) + _at(dyn, "hertz_stress_max"),
        ),
        ("follower jump", _fmt(dyn.get("jump"))),
        (
            "fit control points",
            f"{fit['control_points']} (max error {fit['max_error_mm'] * 1000:.3f} µm)" if fit else "—",
        ),
    ]


def _cmd_check(args: argparse.Namespace) -> int:
    from camcad.design import load_design
    from camcad.pipeline import analyse

    design = load_design(args.design)
    analysis = analyse(design, strict=False, toolpath=True)
    rows = _check_rows(analysis.summary(), design)
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

    design = load_design(args.design)
    cam = Cam.from_design(design)
    search = min_pivot_distance if args.pivot else min_base_radius
    result = search(
        cam,
        max_pressure_angle=design.cam.max_pressure_angle,
        min_curvature_radius=design.min_curvature_radius,
    )
    if args.pivot:
        print(
            f"smallest pivot distance: {result.pivot_distance:.3f} mm "
            f"(design has {design.follower.pivot_distance:g} mm, base radius {design.cam.base_radius:g} mm)"
        )
    else:
        print(f"smallest base radius: {result.base_radius:.3f} mm (design has {design.cam.base_radius:g} mm)")
    where = Extreme(value=0.0, phi=result.angle, side=result.side).where()
    print(f"  limited by {result.limit} {where.replace('at ', 'at cam angle ', 1)}")
    print(
        f"  at that radius: max pressure angle {math.degrees(result.pressure_angle_max):.2f}° "
        f"(limit {math.degrees(design.cam.max_pressure_angle):g}°), "
        f"min convex curvature radius {result.curvature_radius_min:.3f} mm "
        f"(limit {design.min_curvature_radius:g} mm)"
    )
    return EXIT_OK


def _terminal_text(text: str) -> str:
    """One line of printable text: control characters (a newline in a cam name) become spaces."""
    return " ".join("".join(c if c.isprintable() else " " for c in text).split())


def _cmd_compare(args: argparse.Namespace) -> int:
    from camcad.design import load_design
    from camcad.pipeline import analyse
    from camcad.report import compare_table, write_compare

    analyses = [analyse(load_design(p), strict=False, toolpath=False) for p in args.designs]
    table = [[_terminal_text(cell) for cell in row] for row in compare_table(analyses)]
    widths = [max(len(row[i]) for row in table) for i in range(len(table[0]))]
    for row in table:
        print("  ".join(cell.ljust(w) for cell, w in zip(row, widths, strict=True)).rstrip())
    if args.output:
        from camcad.export.atomic import staged_folder

        with staged_folder(args.output) as staging:
            write_compare(analyses, staging.path / "compare.html")
        path = Path(args.output) / "compare.html"
        print(f"wrote {path}", file=sys.stderr)
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
        help="comma-separated outputs to write: tables, dxf, stl, gcode, report (summary.json always)",
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


def main(argv: Sequence[str] | None = None) -> int:
    """Run the camcad command line and return the exit code."""
    args = build_parser().parse_args(argv)
    try:
        with _terminate_like_interrupt(), _no_library_logging():
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
        print(f"camcad: design limit: {err}", file=sys.stderr)
        return exit_code(err)
    except CamcadError as err:
        print(f"camcad: error: {err}", file=sys.stderr)
        return exit_code(err)
    except OSError as err:
        where = f": {err.filename}" if err.filename else ""
        print(f"camcad: error: {err.strerror or err}{where}", file=sys.stderr)
        return exit_code(err)
    except Exception as err:  # the one place that maps surprises to exit 1
        print(f"camcad: unexpected error: {type(err).__name__}: {err}", file=sys.stderr)
        print("camcad: please report this with your design file", file=sys.stderr)
        return EXIT_UNEXPECTED
