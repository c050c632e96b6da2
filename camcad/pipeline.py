"""Design → analysis → files, with an all-or-nothing output folder.

:func:`analyse` runs the stages motion → geometry → dynamics → fit (and the
toolpath plan, which checks for gouge) and returns an :class:`Analysis`;
:func:`build` writes the files into a temporary folder and moves them into
the output folder only when every stage has succeeded.
"""

from __future__ import annotations

import os
import pickle
import signal
import sys
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, replace
from functools import lru_cache, partial
from pathlib import Path
from typing import Any, cast

from camcad.analysis import Analysis, PartResult, motion_summary
from camcad.design import Design, load_design
from camcad.design.paths import named_error, named_finding, named_findings, names_its_errors, path_of
from camcad.dynamics import DynamicsResult, analyse_dynamics
from camcad.dynamics.spec import DynamicsSetup
from camcad.errors import DesignLimitError, ExportError, FitError, GougeError, UsageError
from camcad.export.atomic import staged_folder
from camcad.export.records import write_json, write_text
from camcad.findings import Finding, Severity
from camcad.fit import ProfileFit, fit_cam_profile
from camcad.geometry import Cam, GeometryAnalysis, analyse_geometry, undercut_error
from camcad.geometry.families import CamFamily, Part, family_of
from camcad.toolpath.spec import Machine

__all__ = [
    "OUTPUT_GROUPS",
    "Analysis",
    "BuildResult",
    "Progress",
    "Project",
    "analyse",
    "build",
    "load",
    "motion_summary",
]

Progress = Callable[[str, float], None]
"""Called after each stage with its name and its duration [s]."""

OUTPUT_GROUPS: dict[str, tuple[str, ...]] = {
    "tables": (
        "motion.csv",
        "profile.csv",
        "dynamics.csv",
        "points.csv",
        "lift.csv",
        "polar.txt",
        "cam_table.csv",
        "vibration.csv",  # with [vibration] (issue 34)
        "speed_map.csv",
    ),
    "dxf": ("profile.dxf", "profile_poly.dxf", "profile_arcs.dxf"),
    "stl": ("cam.stl",),
    "step": ("cam.step",),
    "gcode": ("cam.ngc",),
    "fea": ("stress.vtu",),  # the FE check (extra camcad[fea]); by default only when [fea] is present
    "report": ("report.html",),
}
"""What ``build --only`` selects; ``summary.json`` is always written."""


@names_its_errors
def load(path: str | Path) -> Project:
    """Read and validate a design file; ``camcad.load(path).analyse()`` runs it."""
    return Project(design=load_design(path))


@dataclass(frozen=True, slots=True, kw_only=True)
class BuildResult:
    """What :func:`build` wrote: the analysis, the output folder and the files."""

    analysis: Analysis
    outdir: Path
    files: tuple[Path, ...]


@dataclass(frozen=True, slots=True, kw_only=True)
class Project:
    """A loaded design with the Python API of ``camcad.load``."""

    design: Design

    def analyse(self, *, fit: bool = True, toolpath: bool = True) -> Analysis:
        """Run every analysis stage; see :func:`analyse`."""
        return analyse(self.design, fit=fit, toolpath=toolpath)

    def build(self, outdir: str | Path, *, only: Iterable[str] | None = None) -> BuildResult:
        """Write the shop files into ``outdir``; see :func:`build`."""
        return build(self.design, outdir, only=only)


def _timed(timings: dict[str, float], progress: Progress | None, name: str, fn: Callable[[], Any]) -> Any:
    start = time.perf_counter()
    result = fn()
    timings[name] = time.perf_counter() - start
    if progress is not None:
        progress(name, timings[name])
    return result


@names_its_errors
def analyse(
    design: Design,
    *,
    fit: bool = True,
    toolpath: bool = True,
    strict: bool = True,
    progress: Progress | None = None,
    fea: bool = False,
) -> Analysis:
    """Run motion → geometry → dynamics → fit → toolpath plan.

    Parameters
    ----------
    design
        A validated design.
    fit, toolpath
        Whether to run the NURBS fit and plan the G-code toolpath.
    strict
        Raise on hard limits (undercut, face width, velocity jump, gouge, fit
        tolerance unreachable). With ``strict=False`` they are recorded as
        hard :class:`~camcad.findings.Finding` s instead (``camcad check``),
        and the stages that need a usable profile (fit, toolpath) are skipped
        when geometry already found one.
    progress
        Called after each stage with its name and duration.
    fea
        Run the finite-element check of the plate (:mod:`camcad.fea`) with the
        design's ``[fea]`` table, or its defaults. Off by default: it is the
        slowest stage (``build`` and ``check`` turn it on for a design with ``[fea]``).

    Raises
    ------
    DesignLimitError
        When ``strict`` and the design breaks a hard limit (``UndercutError``,
        ``GougeError``, ``FitError`` among them).
    """
    timings: dict[str, float] = {}
    cam = Cam.from_design(design)
    vibration = None
    if design.vibration is not None:  # issue 34: the elastic train; a polydyne cam is cut from its lift c
        vibration = _timed(timings, progress, "vibration", lambda: _vibration(design, cam))
        stop = [named_finding(f) for f in vibration.findings if f.hard]  # the follower leaves the cam
        if stop and strict:
            raise DesignLimitError(stop[0].message, field=stop[0].field)
        if vibration.compensated is not None:
            from camcad.dynamics.vibration import compensated_program

            cam = replace(cam, program=compensated_program(vibration.compensated))
    family = family_of(design.cam.style)
    parts = family.parts(cam, design.family_options())  # plate; a groove's blank; a pair's two plates

    def geometry_of(part: Part) -> GeometryAnalysis:
        return analyse_geometry(
            part.cam,
            max_pressure_angle=design.cam.max_pressure_angle,
            face_width=design.follower.face_width,
            face_margin=design.follower.face_margin,
            min_curvature_radius=design.min_curvature_radius,
        )

    geometries = _timed(timings, progress, "geometry", lambda: [geometry_of(part) for part in parts])
    motion = cam.motion(geometries[0].phi)
    hard = [
        f
        for part, geometry in zip(parts, geometries, strict=True)
        for f in _labelled(part, (*geometry.findings, *part.findings))
        if f.hard
    ]
    if hard and strict:
        if geometries[0].undercut is not None:
            raise named_error(undercut_error(geometries[0], min_curvature_radius=design.min_curvature_radius))
        raise DesignLimitError(hard[0].message, field=hard[0].field)
    setup = design.dynamics_setup()

    def setup_of(part: Part) -> DynamicsSetup:
        # each part's own roller sets its Hertz contact (Johnson 1985, §4.3), its drive sign its force
        return replace(setup, drive_sign=part.drive_sign, roller_radius=part.cam.roller_radius)

    def dynamics_of(part: Part, geometry: GeometryAnalysis) -> DynamicsResult:
        try:
            return analyse_dynamics(
                part.cam.motion(geometry.phi),
                pressure_angle=geometry.pressure_angle,
                profile_rho=geometry.profile.rho,
                setup=setup_of(part),
                cam=part.cam,
            )
        except DesignLimitError as err:  # the guided tappet self-locks (Hren et al. eq. 25)
            err.with_field("dynamics.b_m")  # spread its guides
            raise

    dynamics = _timed(
        timings,
        progress,
        "dynamics",
        lambda: [dynamics_of(part, g) for part, g in zip(parts, geometries, strict=True)],
    )
    results = [
        PartResult(part=part, geometry=g, dynamics=d)
        for part, g, d in zip(parts, geometries, dynamics, strict=True)
    ]
    drive = None
    if design.life is not None or design.lubrication is not None or design.drive is not None:
        results, drive = _timed(timings, progress, "duty", lambda: part_duties(design, cam, results))
    later: list[Finding] = []  # hard limits found by the fit and the toolpath plan
    if fit and not hard:
        fit_curve = partial(
            fit_cam_profile,
            tolerance=design.fit.tolerance,
            max_control_points=design.fit.max_control_points,
            name_of=path_of,
        )

        def fit_part(result: PartResult) -> PartResult:  # its outline, then its further curves (flanks)
            if not result.part.made:
                return result
            part = result.part
            if part.barrel is not None:  # a barrel's groove walls: certified surfaces
                from camcad.fit.surface import WallFitOptions, fit_barrel_walls

                b, options = part.barrel, WallFitOptions(tolerance=design.fit.tolerance)
                return replace(result, wall_fit=fit_barrel_walls(b.program, b.follower, b.options, options))
            flanks = tuple(fit_curve(part.cam, offset=f.offset) for f in part.flanks)
            return replace(result, fit=fit_curve(part.cam), flank_fits=flanks)

        results = (
            _limited(
                lambda: [fit_part(r) for r in results],
                timings=timings,
                progress=progress,
                stage="fit",
                strict=strict,
                found=later,
            )
            or results
        )
    planned = None
    if toolpath and not hard:
        from camcad.export.gcode import render_program
        from camcad.export.gcode.rotary import render_rotary_program
        from camcad.toolpath.parts import plan_part

        rotary = design.gcode.machine is Machine.ROTARY  # X + A/C in inverse time (camcad.toolpath.rotary)
        render = render_rotary_program if rotary else render_program
        spent = 0.0
        for index, result in enumerate(results):
            if not (result.part.made and result.part.program):  # a part without a program: its note says why
                continue
            timings.pop("toolpath", None)
            plan = _limited(
                partial(
                    plan_part,
                    result.part,
                    design.gcode,
                    name=design.cam.name,
                    thickness=design.cam.thickness,
                    bore=design.cam.bore,
                ),
                timings=timings,
                progress=progress,
                stage="toolpath",
                strict=strict,
                found=later,
            )
            spent += timings.pop("toolpath", 0.0)
            if plan is None:
                break
            if result.part.barrel is not None:  # the 4-axis program of a barrel's groove (scipy: here only)
                from camcad.export.gcode.barrel_program import barrel_program
                from camcad.toolpath.barrel import BarrelToolpath

                program = barrel_program(cast(BarrelToolpath, plan), name=design.cam.name)  # plan_part's
                results[index] = replace(result, gcode=program)
                continue
            if index == 0:
                planned = None if rotary else plan  # the rotary plan lives in its program (G93 text, figures)
            results[index] = replace(result, gcode=render(plan, design.gcode.dialect))
        if spent:
            timings["toolpath"] = spent  # every part's plan
    if fea and not hard:
        fea_setups = [setup_of(r.part) for r in results]
        results = _timed(timings, progress, "fea", lambda: _fea_check(design, family, results, fea_setups))
    return Analysis(
        design=design,
        family=family,
        parts=tuple(results),
        motion=motion,
        toolpath=planned,
        timings=timings,
        stage_findings=tuple(later),
        drive=drive,
        vibration=vibration,
    )


def _vibration(design: Design, cam: Cam) -> Any:
    """The ``[vibration]`` analysis of the design's motion program at its speed (issue 34).

    The last few results are kept by their inputs (:func:`_vibration_of`): the
    speed map takes seconds and most edits in ``camcad serve`` (the cam's size,
    its follower's radius, a limit) leave every input of it as it was.
    """
    assert design.vibration is not None
    setup = design.dynamics_setup()
    args = (cam.program, design.vibration, design.dynamics, design.cam.speed_rpm, setup.arm_angle)
    spring_loaded = not setup.positive_drive
    try:
        hash(args)
    except TypeError:  # an input holding arrays (a point table's): computed, not kept
        return _vibration_of.__wrapped__(*args, spring_loaded)
    return _vibration_of(*args, spring_loaded)


@lru_cache(maxsize=4)
def _vibration_of(
    program: Any, spec: Any, dynamics: Any, speed_rpm: float, arm_angle: float | None, spring_loaded: bool
) -> Any:
    """:func:`camcad.dynamics.vibration.analyse_vibration` of these frozen inputs (same in, same out)."""
    from camcad.dynamics.vibration import analyse_vibration

    return analyse_vibration(
        program, spec, dynamics, speed_rpm=speed_rpm, arm_angle=arm_angle, spring_loaded=spring_loaded
    )


def _labelled(part: Part, findings: Iterable[Finding]) -> list[Finding]:
    """``findings`` of ``part``, their messages named by its label when it has one ("second plate: …")."""
    named = named_findings(findings)  # the path leads the message, then the label leads both
    if not part.label:
        return list(named)
    return [replace(f, message=f"{part.label}: {f.message}") for f in named]


def _fea_check(
    design: Design, family: CamFamily, results: Sequence[PartResult], setups: Sequence[DynamicsSetup]
) -> list[PartResult]:
    """The FE check of every made plate with the design's ``[fea]`` table (its defaults when absent).

    Each plate is loaded by its own roller's contact (its dynamics, its setup),
    by the same code; a part that is not a plate cut along its outline (a
    groove's blank) or not made is not checked.
    """
    from camcad.fea import FeaSpec, analyse_fea

    if not family.plates:  # the FE model is a plate cut along its outline, held at its bore
        raise UsageError("fea", f"the finite-element check applies to plate cams only, not {family.name}")
    spec = design.fea if design.fea is not None else FeaSpec()
    plate = design.plate()
    return [
        replace(r, fea=analyse_fea(r.part.cam, plate, setup=s, dynamics=r.dynamics, spec=spec))
        if r.part.made and r.part.pocket is None
        else r
        for r, s in zip(results, setups, strict=True)
    ]


_STAGE_LIMITS: dict[str, tuple[type[DesignLimitError], str, str]] = {
    "fit": (FitError, "fit tolerance", "fit.tolerance"),
    "toolpath": (GougeError, "gouge", "gcode.tool_diameter"),
}
"""The hard limit each later stage can break: its error, the finding's kind, the field when it names none."""


def _limited(
    run: Callable[[], Any],
    *,
    timings: dict[str, float],
    progress: Progress | None,
    stage: str,
    strict: bool,
    found: list[Finding],
) -> Any:
    """Run a stage that can break a hard limit: raise it when strict, else record a finding and give None."""
    error, kind, field = _STAGE_LIMITS[stage]
    try:
        return _timed(timings, progress, stage, run)
    except error as err:
        named_error(err.with_field(field))  # the stage's own field when it named none
        if strict:
            raise
        found.append(Finding(kind=kind, severity=Severity.HARD, field=err.field, message=str(err)))
        return None


def _groups(only: Iterable[str] | None) -> set[str]:
    if only is None:
        return set(OUTPUT_GROUPS)
    chosen = {g.strip().lower() for g in only if g.strip()}
    aliases = {"mesh": "stl", "ngc": "gcode", "csv": "tables", "html": "report"}
    chosen = {aliases.get(g, g) for g in chosen}
    unknown = sorted(chosen - set(OUTPUT_GROUPS))
    if unknown:
        raise UsageError("--only", f"unknown output {unknown[0]!r} (allowed: {', '.join(OUTPUT_GROUPS)})")
    return chosen


@names_its_errors
def build(
    design: Design,
    outdir: str | Path,
    *,
    only: Iterable[str] | None = None,
    progress: Progress | None = None,
    strict: bool = False,
    parallel: bool = True,
) -> BuildResult:
    """Analyse the design and write its files into ``outdir`` all at once.

    Everything is written into a hidden folder beside ``outdir`` first; the
    files are moved into ``outdir`` only when every stage has succeeded, so a
    failed build leaves ``outdir`` exactly as it was and nothing beside it
    (see :func:`camcad.export.atomic.staged_folder`).

    With ``parallel`` (the default) on Linux with two or more CPUs, the
    report is drawn in a forked child process while this one writes the
    other files (:class:`_Background`): its libraries' import and its
    drawing take about as long as all the other outputs together. The files
    are the same bytes either way.

    Raises
    ------
    UsageError
        When ``only`` names an unknown output (path ``--only``).
    OutputError
        When ``outdir`` or a file in it cannot be written (path ``--output``).
    DesignLimitError
        When the design breaks a hard limit (undercut, face width, velocity
        jump, gouge, fit, a table the profile cannot give), or with ``strict``
        a soft one (pressure angle, contact stress, follower jump).
    """
    groups = _groups(only)
    if only is None and design.fea is None:
        groups.discard("fea")  # slower than everything else: by default only when the design asks for it
    outdir = Path(outdir)
    with staged_folder(outdir) as staging:
        analysis = analyse(
            design, fit=True, toolpath="gcode" in groups, progress=progress, fea="fea" in groups
        )
        soft = [f for f in analysis.findings if f.severity is Severity.SOFT]
        if strict and soft:
            listed = "; ".join(f"{f.field}: {f.message}" for f in soft)
            raise DesignLimitError(f"--strict: {len(soft)} soft limit(s) broken: {listed}")
        written = _write_outputs(
            analysis, staging.path, groups=groups, progress=progress, parallel=parallel and _can_fork()
        )
        written.append(write_json(staging.path / "summary.json", analysis.summary()))
    return BuildResult(analysis=analysis, outdir=outdir, files=tuple(outdir / Path(p).name for p in written))


def _write_outputs(
    analysis: Analysis, folder: Path, *, groups: set[str], progress: Progress | None, parallel: bool = False
) -> list[Path]:
    """Write the selected output groups into ``folder``; return the paths written.

    With ``parallel`` the report is drawn by a forked child meanwhile (see :func:`build`).
    """
    report = None
    if "report" in groups and parallel:
        report = _Background(partial(_write_report, analysis, folder))
    try:
        written = _write_files(analysis, folder, groups=groups - {"report"}, progress=progress)
        if report is not None:
            path, seconds = report.join()
            analysis.timings["report"] = seconds
            if progress is not None:
                progress("report", seconds)
            written.append(path)
        elif "report" in groups:
            draw = partial(_write_report, analysis, folder)
            written.append(_timed(analysis.timings, progress, "report", draw))
    except BaseException:
        if report is not None:
            report.cancel()
        raise
    return written


def _write_report(analysis: Analysis, folder: Path) -> Path:
    from camcad.report import write_report  # here: it loads matplotlib

    return write_report(analysis, folder / "report.html")


def _can_fork() -> bool:
    """Whether a forked child can draw the report beside this process: Linux, two or more CPUs."""
    return sys.platform.startswith("linux") and hasattr(os, "fork") and len(os.sched_getaffinity(0)) > 1


class _Background:
    """One output stage run in a forked child process; :meth:`join` returns its result or raises its error.

    The child inherits the analysis as it is (fork copies the process), runs
    the stage, sends back a pickled ``(result, seconds)`` or the exception
    through a pipe and leaves with :func:`os._exit`, so none of the parent's
    clean-up (the staged output folder) runs twice.
    """

    def __init__(self, fn: Callable[[], Any]) -> None:
        self._read, write = os.pipe()
        self._pid = os.fork()  # 0 in the child; in the parent 0 again once reaped
        if self._pid == 0:  # pragma: no cover - the child (coverage does not follow it)
            os.close(self._read)
            status = 1
            try:
                start = time.perf_counter()
                result = fn()
                payload = pickle.dumps(("ok", result, time.perf_counter() - start))
                status = 0
            except BaseException as err:  # every failure goes back to the parent
                payload = pickle.dumps(("error", (type(err).__name__, str(err)), _picklable(err)))
            try:
                with os.fdopen(write, "wb") as pipe:
                    pipe.write(payload)
            finally:
                os._exit(status)
        os.close(write)

    def join(self) -> tuple[Any, float]:
        """Wait for the child; its result and its duration [s], or raise the exception it raised."""
        with os.fdopen(self._read, "rb") as pipe:
            data = pipe.read()
        os.waitpid(self._pid, 0)
        self._pid = 0  # reaped: nothing left to cancel
        if not data:
            raise ExportError("the report process ended without a result (killed?)")
        kind, value, extra = pickle.loads(data)
        if kind == "ok":
            return value, float(extra)
        if extra is not None:
            raise _unpickled(extra)
        name, message = value
        raise ExportError(f"report: {name}: {message}")

    def cancel(self) -> None:
        """Stop the child and reap it, unless :meth:`join` did (this process failed or was interrupted)."""
        if self._pid == 0:
            return
        os.kill(self._pid, signal.SIGKILL)  # a child not yet reaped still exists, if only as a zombie
        os.waitpid(self._pid, 0)
        self._pid = 0
        os.close(self._read)


def _picklable(err: BaseException) -> Any:
    """What brings ``err`` back across the pipe: the exception itself, a recipe for it, or None.

    Most exceptions survive a pickle round trip. Those whose ``__init__``
    takes other arguments than their ``args`` (``OutputError(path, problem,
    advice)``, ``DesignError(path, message)``) do not; they travel as a recipe
    (class, ``args``, attributes, and ``errno``, ``strerror``, ``filename`` of an
    ``OSError``) that :func:`_unpickled` rebuilds without calling ``__init__``,
    so a full disk while the report is written is the same ``OutputError`` as
    anywhere else. None when neither travels (its name and text go instead).
    """
    try:
        pickle.loads(pickle.dumps(err))
        return err
    except Exception:  # any exception that cannot travel as it is
        pass
    fields = (err.errno, err.strerror, err.filename) if isinstance(err, OSError) else None
    recipe = ("recipe", type(err), err.args, dict(getattr(err, "__dict__", {})), fields)
    try:
        _unpickled(pickle.loads(pickle.dumps(recipe)))
    except Exception:  # a local class, an attribute that cannot travel
        return None
    return recipe


def _unpickled(extra: Any) -> BaseException:
    """The exception :func:`_picklable` sent: itself, or rebuilt from its recipe."""
    if not isinstance(extra, tuple):
        return extra  # type: ignore[no-any-return]
    _, cls, args, attributes, fields = extra
    err: BaseException = cls.__new__(cls, *args)
    err.args = args
    err.__dict__.update(attributes)
    if fields is not None:
        err.errno, err.strerror, err.filename = fields  # type: ignore[attr-defined]
    return err


def _write_files(
    analysis: Analysis, folder: Path, *, groups: set[str], progress: Progress | None
) -> list[Path]:
    """Write every selected output group but the report into ``folder``; return the paths written."""
    design, timings = analysis.design, analysis.timings
    plate = design.plate()
    written: list[Path] = []

    def stage(name: str, fn: Callable[[], Any]) -> None:
        result = _timed(timings, progress, name, fn)
        written.extend(result if isinstance(result, list) else [result])

    if "tables" in groups:
        stage("tables", lambda: write_tables(analysis, folder))
    made = [r for r in analysis.parts if r.part.made]  # a constant-breadth pair's second roller: no files
    barrels = [r for r in made if r.part.barrel is not None]  # a barrel's files come from its walls
    made = [r for r in made if r.part.barrel is None]
    numbers = (
        range(1, len(made) + 1) if len(made) > 1 else (0,) * len(made)
    )  # several parts: named 1, 2, … as mounted
    if barrels:
        stage("barrel", lambda: _write_barrel_files(analysis, barrels, folder, groups=groups))
    if "dxf" in groups and made:
        from camcad.export.dxf import write_part_dxfs

        stage(
            "dxf",
            lambda: [
                path
                for r in made
                for path in write_part_dxfs(
                    folder, r.part, fit=_fitted(r), flank_fits=r.flank_fits, plate=plate, options=design.dxf
                )
            ],
        )
    if "stl" in groups and made:
        from camcad.export.mesh import write_part_meshes

        mesh = design.mesh
        stage(
            "mesh",
            lambda: [
                path
                for r in made
                for path in write_part_meshes(
                    folder,
                    r.part,
                    fit=_fitted(r),
                    flank_fits=r.flank_fits,
                    plate=plate,
                    options=mesh,
                    formats=mesh.formats,
                )
            ],
        )
    if "step" in groups and made:
        from camcad.export.step import write_part_step

        stage(
            "step",
            lambda: [
                write_part_step(
                    folder, r.part, fit=_fitted(r), flank_fits=r.flank_fits, plate=plate, number=n
                )
                for r, n in zip(made, numbers, strict=True)
            ],
        )
    if "gcode" in groups:
        # analysed with the toolpath when G-code is asked for (a part without a program has a note)
        assert analysis.gcode is not None or not analysis.parts[0].part.program
        programs = [
            (f"cam{r.part.suffix}.ngc", r.gcode.text) for r in (*barrels, *made) if r.gcode is not None
        ]
        stage("gcode", lambda: [write_text(folder / name, text) for name, text in programs])
    if "fea" in groups and analysis.fea is not None:
        from camcad.export.stress import write_stress_vtu

        checked = [(r.part.suffix, r.fea) for r in made if r.fea is not None]  # every made plate's
        stage("stress", lambda: [write_stress_vtu(folder / f"stress{sfx}.vtu", f) for sfx, f in checked])
    return written


def _write_barrel_files(
    analysis: Analysis, results: Sequence[PartResult], folder: Path, *, groups: set[str]
) -> list[Path]:
    """A barrel's developed groove (``profile.dxf``), ``cam.stl`` and ``cam.step``, as selected."""
    from camcad.export.barrel_files import write_barrel_dxf, write_barrel_step, write_barrel_stl

    design = analysis.design
    written: list[Path] = []
    for r in results:
        if "dxf" in groups:
            written.append(write_barrel_dxf(folder, r.part, tolerance=design.fit.tolerance))
        if "stl" in groups:
            written.append(write_barrel_stl(folder, r.part, chord=design.mesh.chord_tolerance))
        if "step" in groups:
            assert r.wall_fit is not None  # build always fits, and fails on walls it cannot certify
            written.append(write_barrel_step(folder, r.part, fit=r.wall_fit, name=design.cam.name))
    return written


def part_duties(
    design: Design, cam: Cam, results: Sequence[PartResult], *, characteristics: Any = None
) -> tuple[list[PartResult], Any]:
    """Every part's life and film by the same code, and the train's drive ([life], [lubrication], [drive]).

    Each part is loaded through its own roller and drive sign (Johnson 1985,
    §4.3); the motor turns the camshaft, so the drive is a figure of the
    follower train, computed once from the first part's dynamics.
    ``characteristics`` are the laws' VDI 2143 values if already computed
    (:func:`camcad.dynamics.duty.analyse_train_drive`).
    """
    from camcad.dynamics.duty import analyse_duty, analyse_train_drive

    setup = design.dynamics_setup()

    def duty_of(result: PartResult) -> PartResult:
        if design.life is None and design.lubrication is None:
            return result
        part = result.part
        duty = analyse_duty(
            part.cam,
            result.dynamics,
            setup=replace(setup, drive_sign=part.drive_sign, roller_radius=part.cam.roller_radius),
            profile=result.geometry.profile,
            life=design.life,
            lubrication=design.lubrication,
        )
        return replace(result, duty=duty)

    train = None
    if design.drive is not None:
        train = analyse_train_drive(
            cam, results[0].dynamics, setup=setup, spec=design.drive, characteristics=characteristics
        )
    return [duty_of(r) for r in results], train


def _fitted(result: PartResult) -> ProfileFit:
    """The certified fit of a made part's outline (build always fits)."""
    assert result.fit is not None  # build analyses with the fit, and fails on a fit it cannot certify
    return result.fit


@names_its_errors
def write_tables(analysis: Analysis, folder: Path) -> list[Path]:
    """motion.csv, profile.csv, dynamics.csv, points.csv, lift.csv and the optional tables into ``folder``."""
    from camcad.export.tables import (
        write_dynamics_csv,
        write_lift_csv,
        write_motion_csv,
        write_points_csv,
        write_profile_csv,
    )

    cam, design = analysis.cam, analysis.design
    unit = cam.follower_spec.kind.lift_unit  # mm on a slide, degrees of swing on an arm
    duty = analysis.duty.csv_columns() if analysis.duty is not None else {}  # the first part's film
    duty |= analysis.drive.csv_columns() if analysis.drive is not None else {}  # the train's motor torque
    motion_csv = write_motion_csv(folder / "motion.csv", cam, unit=unit)
    profile_csv = write_profile_csv(folder / "profile.csv", analysis.geometry)
    later = [  # every further part with files of its own (a pair's second plate): its columns too
        (r.part.suffix, r.dynamics, r.duty.csv_columns() if r.duty is not None else {})
        for r in analysis.parts[1:]
        if r.part.suffix
    ]
    dynamics_csv = write_dynamics_csv(
        folder / "dynamics.csv", analysis.dynamics, extra=duty or None, later_parts=later
    )
    return [
        motion_csv,
        profile_csv,
        dynamics_csv,
        write_points_csv(folder / "points.csv", cam, design.tables),
        write_lift_csv(folder / "lift.csv", cam, design.tables),
        *_polar_table(analysis, folder),
        *_drive_table(analysis, folder),
        *_vibration_tables(analysis, folder),
    ]


def _vibration_tables(analysis: Analysis, folder: Path) -> list[Path]:
    """vibration.csv (the response at the design speed) and speed_map.csv, with ``[vibration]``."""
    vib = analysis.vibration
    if vib is None:
        return []

    def text(rows: list[tuple[str, ...]]) -> str:
        cells = (("0" + c[2:] if c.startswith("-0") and float(c) == 0.0 else c for c in r) for r in rows)
        return "\n".join(",".join(r) for r in cells) + "\n"  # no "-0": the same table everywhere

    return [
        write_text(folder / "vibration.csv", text(vib.response_rows())),
        write_text(folder / "speed_map.csv", text(vib.speed_map_rows())),
    ]


def _drive_table(analysis: Analysis, folder: Path) -> list[Path]:
    """cam_table.csv (the electronic cam for a servo drive) when ``[tables] cam_table_points`` is given."""
    from camcad.export.drive import write_drive_table

    options = analysis.design.tables
    if options.cam_table_points is None:
        return []
    unit = analysis.cam.follower_spec.kind.lift_unit
    return [
        write_drive_table(
            folder / "cam_table.csv",
            analysis.cam.program,
            options.cam_table_points,
            layout=options.cam_table_layout,
            unit=unit,
        )
    ]


def _polar_table(analysis: Analysis, folder: Path) -> list[Path]:
    """polar.txt (wheel-centre radius per angle) when ``[tables] wheel_radius`` is given."""
    from camcad.export.tables import write_polar_table

    design = analysis.design
    if design.tables.wheel_radius is None:
        return []
    return [write_polar_table(folder / "polar.txt", analysis.cam, design.tables, name=design.cam.name)]
