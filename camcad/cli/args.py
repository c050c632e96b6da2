"""The command line's argument parser: every subcommand, its arguments and its handler."""

from __future__ import annotations

import argparse

from camcad._version import __version__
from camcad.cli.commands import (
    _cmd_build,
    _cmd_check,
    _cmd_compare,
    _cmd_inspect,
    _cmd_laws,
    _cmd_optimize,
    _cmd_schema,
    _cmd_serve,
    _cmd_size,
    _cmd_sweep,
    _cmd_tolerance,
)
from camcad.errors import (
    EXIT_INVALID,
    printable,
)


class _Parser(argparse.ArgumentParser):
    """An argument parser that exits 2 with one clear line (argparse's own code for usage errors)."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(EXIT_INVALID, f"camcad: error: {printable(message)} (see '{self.prog} --help')\n")


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

    p = sub.add_parser("optimize", help="constrained optimization over design-file keys, or a Pareto front")
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
