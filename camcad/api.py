"""The Python API: load a design, analyse it, read its figures and curves, build its files.

Everything ``camcad check`` and ``camcad build`` do, typed, for scripts and
notebooks::

    import camcad

    design = camcad.load("samples/offset_roller.toml")   # a path, or TOML text
    result = camcad.analyse(design)                       # what `camcad check` computes
    result.max_pressure_angle.value                       # degrees, the true extreme
    result.phi, result.s, result.x, result.y               # numpy arrays of the curves
    bigger = design.replace(**{"cam.base_radius": 45})    # a variant, validated by the loader
    camcad.analyse(bigger).build("out/", only=["dxf"])     # the same bytes as `camcad build`

``Design`` keeps the TOML mapping it was read from: a variant is that
mapping with keys changed, read again by the loader
(``camcad.design.parse_design``), so every rule of the design file
applies to it and a bad value is refused with the loader's message.
``Result`` holds the figures of ``camcad check`` as ``Quantity``
attributes (value, unit, and the cam angle where an extreme occurs), the
findings, and read-only arrays of every curve. In Jupyter both render
themselves: the report's key-number cards (``_repr_html_``) and the cam
drawing (``_repr_svg_``).
"""

from __future__ import annotations

import copy
import html
import math
import os
import re
import sys
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from camcad._typing import FloatArray
from camcad.design import Design as DesignSpec
from camcad.design import load_design, parse_design
from camcad.errors import DesignError
from camcad.findings import Finding

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib  # type: ignore[import-not-found, unused-ignore]

if TYPE_CHECKING:
    from matplotlib.figure import Figure

    from camcad.analysis import Analysis
    from camcad.explore.optimize import OptimizeResult
    from camcad.explore.sweep import SweepResult
    from camcad.pipeline import BuildResult

__all__ = ["PLOTS", "Design", "Quantity", "Result", "analyse", "load", "optimize", "sweep"]

PLOTS = ("motion", "profile", "pressure", "dynamics")
"""What ``Result.plot`` draws: s, v, a, j; the cam outline; the pressure angle; force, torque, stress."""

_PATH_PART = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)(?:\[(\d+)\])?$")


class Design:
    """A validated design file, with the TOML mapping it was read from.

    Make one with ``load``. It is immutable: ``replace`` gives a new
    design. ``spec`` is the validated, typed design (mm and radians) the
    pipeline runs on; ``data`` a copy of the TOML mapping (file units: mm,
    degrees, rpm).
    """

    __slots__ = ("_cache", "_data", "_spec")

    def __init__(self, data: Mapping[str, Any], *, source: str = "") -> None:
        """Validate ``data`` (a design file's TOML mapping) with the loader.

        Raises
        ------
        DesignError
            Naming the field path, the value and what is allowed.
        """
        self._data: dict[str, Any] = copy.deepcopy(dict(data))
        self._spec: DesignSpec = parse_design(self._data, source=source)
        self._cache: dict[str, Any] = {}

    @property
    def spec(self) -> DesignSpec:
        """The validated design the pipeline runs on (``camcad.design.Design``, mm and radians)."""
        return self._spec

    @property
    def data(self) -> dict[str, Any]:
        """A deep copy of the design's TOML mapping (file units: mm, degrees, rpm)."""
        return copy.deepcopy(self._data)

    @property
    def name(self) -> str:
        """The cam's name (``[cam] name``)."""
        return self._spec.cam.name

    @property
    def source(self) -> str:
        """The design file's path, or ``""`` for a design given as text."""
        return self._spec.source

    def replace(self, **changes: Any) -> Design:
        """A variant with design-file keys changed, validated by the loader.

        Parameters
        ----------
        **changes
            Dotted keys of the design file and their new values in the
            file's units: ``cam.base_radius`` [mm], ``follower.offset``
            [mm], ``motion[1].angle`` [degrees], ``dynamics.spring_rate``
            [N/mm]. Pass them unpacked from a dict, since dots are not
            allowed in Python keywords:
            ``design.replace(**{"cam.base_radius": 45})``. ``None`` removes
            a key (its default applies).

        Returns
        -------
        Design
            The new design; this one is unchanged.

        Raises
        ------
        DesignError
            The loader's message, naming the field, the value and what is
            allowed (the same as for a design file with that value).
        """
        data = copy.deepcopy(self._data)
        for dotted, value in changes.items():
            holder, key = _holder(data, dotted)
            if value is None:
                holder.pop(key, None)
            else:
                holder[key] = value
        return Design(data, source=self.source)

    def analyse(self, *, toolpath: bool = True, fea: bool | None = None) -> Result:
        """Analyse this design; see ``analyse``."""
        return analyse(self, toolpath=toolpath, fea=fea)

    def build(self, outdir: str | os.PathLike[str], *, only: Iterable[str] | None = None) -> BuildResult:
        """Write the design's files into ``outdir``, as ``camcad build`` does; see ``Result.build``."""
        from camcad.pipeline import build

        return build(self._spec, Path(outdir), only=only)

    def _preview(self) -> Analysis:
        """The geometry and dynamics without fit or toolpath (for the drawing), computed once."""
        if "preview" not in self._cache:
            from camcad.pipeline import analyse as run

            self._cache["preview"] = run(self._spec, fit=False, toolpath=False, strict=False)
        return self._cache["preview"]  # type: ignore[no-any-return]

    def __repr__(self) -> str:
        """``Design('name', source='path')``."""
        return f"Design({self.name!r}, source={self.source!r})"

    def __eq__(self, other: object) -> bool:
        """Designs are equal when their validated specs are."""
        return isinstance(other, Design) and self._spec == other._spec

    __hash__ = None  # type: ignore[assignment]  # holds a mutable mapping

    def _repr_html_(self) -> str:
        """A table of the design's main inputs and its motion program (Jupyter)."""
        spec = self._spec
        unit = spec.follower.kind.lift.short
        rows = [
            ("follower", spec.follower.kind.word),
            ("base radius", f"{spec.cam.base_radius:g} mm"),
            ("speed", f"{spec.cam.speed_rpm:g} rpm"),
            ("max pressure angle", f"{math.degrees(spec.cam.max_pressure_angle):g}°"),
        ]
        motion = [
            (
                seg.kind.value,
                f"{math.degrees(seg.span):g}°",
                f"{seg.lift:g} {unit}",
                "" if seg.law is None else seg.law.describe(),
            )
            for seg in _segments(self)
        ]
        body = "".join(f"<tr><th>{_e(k)}</th><td>{_e(v)}</td></tr>" for k, v in rows)
        program = "".join("<tr>" + "".join(f"<td>{_e(c)}</td>" for c in row) + "</tr>" for row in motion)
        return (
            f'<div class="camcad-design"><strong>{_e(self.name)}</strong>'
            f"<table>{body}</table>"
            f"<table><tr><th>segment</th><th>angle</th><th>lift</th><th>law</th></tr>{program}</table></div>"
        )

    def _repr_svg_(self) -> str:
        """The cam drawn to scale with its follower, as in the report (Jupyter)."""
        return _cam_svg(self._preview())


def _segments(design: Design) -> tuple[Any, ...]:
    """The motion program's segments, resolved (laws and lifts)."""
    from camcad.geometry.cam import Cam

    return tuple(Cam.from_design(design.spec).program.segments)


def _holder(data: dict[str, Any], dotted: str) -> tuple[dict[str, Any], str]:
    """The table in ``data`` that holds the key ``dotted`` names (created if missing) and the key."""
    parts = dotted.split(".")
    holder: Any = data
    for i, part in enumerate(parts):
        match = _PATH_PART.match(part)
        if match is None:
            raise DesignError(dotted, "not a design-file key; write table.key or motion[i].key")
        name, index = match.group(1), match.group(2)
        last = i == len(parts) - 1
        if last and index is None:
            return holder, name
        if index is not None:
            items = holder.get(name)
            if not isinstance(items, list) or int(index) >= len(items):
                count = len(items) if isinstance(items, list) else 0
                raise DesignError(dotted, f"no {name}[{index}]; the design has {count} (indices from 0)")
            holder = items[int(index)]
            if last:
                raise DesignError(dotted, f"name a key of {name}[{index}], e.g. {name}[{index}].angle")
        else:
            nxt = holder.setdefault(name, {})
            if not isinstance(nxt, dict):
                raise DesignError(dotted, f"{name} is not a table")
            holder = nxt
    raise DesignError(dotted, "empty key")  # pragma: no cover - split gives at least one part


def load(source: str | os.PathLike[str]) -> Design:
    """Read and validate a design: a path to a TOML file, or the TOML text itself.

    Parameters
    ----------
    source
        A ``pathlib.Path`` or a string naming a file, or a string of
        TOML text (any string with a line break is read as text). Point
        tables (``kind = "table"``) in text are read relative to the
        current folder.

    Raises
    ------
    DesignError
        When the file is missing or unreadable, is not TOML, or is invalid:
        naming the field path, the value and what is allowed.
    """
    if isinstance(source, str) and "\n" in source:
        try:
            data = tomllib.loads(source)
        except tomllib.TOMLDecodeError as err:
            raise DesignError("", f"the design text is not valid TOML: {err}") from None
        return Design(data)
    path = Path(source)
    spec = load_design(path)  # the loader's own messages for a missing, unreadable or invalid file
    design = Design.__new__(Design)
    design._data = tomllib.loads(path.read_text(encoding="utf-8-sig"))
    design._spec = spec
    design._cache = {}
    return design


@dataclass(frozen=True, slots=True, kw_only=True)
class Quantity:
    """One figure of ``camcad check``: its value, unit and, for an extreme, where on the turn it occurs.

    Attributes
    ----------
    value
        The number in ``unit``; None when the design has none (no concave
        part, no fit).
    unit
        ``"mm"``, ``"°"``, ``"N"``, ``"N·mm"``, ``"MPa"`` or ``""``.
    angle_deg
        Cam angle of the extreme [degrees], or None.
    side
        ``"before joint"`` or ``"after joint"`` when the extreme is a
        one-sided limit at a motion joint, else None.
    """

    value: float | None
    unit: str
    angle_deg: float | None = None
    side: str | None = None

    def __float__(self) -> float:
        """The value (NaN when None)."""
        return math.nan if self.value is None else float(self.value)

    def __str__(self) -> str:
        """``22.146° at 246.3°`` (3 decimals)."""
        if self.value is None:
            return "—"
        text = f"{self.value:.3f}{'' if self.unit in ('°', '') else ' '}{self.unit}"
        if self.angle_deg is not None:
            text += f" at {self.angle_deg:.1f}°"
        if self.side:
            text += f" (just {self.side})"
        return text


def _quantity(section: Mapping[str, Any], key: str, unit: str) -> Quantity:
    """The entry ``<key>_<unit suffix>`` of a summary section with its angle and side."""
    suffix = {"°": "deg", "mm": "mm", "N": "N", "N·mm": "Nmm", "MPa": "MPa"}[unit]
    value = section.get(f"{key}_{suffix}")
    return Quantity(
        value=None if value is None else float(value),
        unit=unit,
        angle_deg=section.get(f"{key}_angle_deg"),
        side=section.get(f"{key}_side"),
    )


def _readonly(values: Any) -> FloatArray:
    out = np.array(values, dtype=np.float64)
    out.flags.writeable = False
    return out


class Result:
    """What ``analyse`` computed: the figures of ``camcad check``, the findings and every curve.

    The figures are ``Quantity`` objects in the units ``camcad check``
    prints, true extremes over the turn with the cam angle where they occur.
    The curves are read-only float64 arrays of shape (n,) over the same
    angles ``phi``.

    Attributes
    ----------
    design : Design
        The design analysed.
    lift : Quantity
        The nominal lift the program states [mm], or swing [°] for an arm (``lift_unit``).
    stroke, travel_min, travel_max : Quantity
        The follower's true travel over the turn, max − min of s, and its two ends
        (true extremes, with their cam angles): larger than ``lift`` where a
        segment overshoots (a return carried forwards by a constant-velocity rise).
    max_pressure_angle, pressure_angle_limit : Quantity
        The largest pressure angle |α| and the design's limit [°].
    pressure_angle_flank : str or None
        A groove cam's flank that drives where |α| is largest ("inner" or "outer"); None for other cams.
    contact_stress_flank : str or None
        A groove cam's flank that carries ``max_contact_stress`` ("inner" or "outer"); None for other cams.
    min_curvature_radius, min_concave_radius : Quantity
        The smallest convex and concave radius of curvature of the profile [mm].
    max_torque : Quantity
        The largest input torque on the cam shaft [N·mm].
    max_contact_force, min_contact_force : Quantity
        The contact force's extremes [N].
    max_contact_stress : Quantity
        The largest Hertz contact stress [MPa].
    max_von_mises : Quantity
        The finite-element check's largest von Mises stress [MPa]; None without it.
    fit_control_points : int or None
        Control points of the certified NURBS fit.
    fit_max_error : Quantity
        The fit's certified largest error [mm].
    undercut : bool
        Whether the profile is undercut (a hard limit).
    follower_jump : bool or None
        Whether the follower leaves the cam; None for a positive drive.
    phi, angle_deg : numpy.ndarray
        Cam angle φ [rad] and [°].
    s, v, a, j : numpy.ndarray
        Lift and its derivatives in φ (mm, or ° of swing; per rad, rad², rad³).
    x, y, pitch_x, pitch_y : numpy.ndarray
        Profile and pitch curve [mm], cam frame at φ = 0.
    pressure_angle : numpy.ndarray
        Signed pressure angle [rad].
    rho : numpy.ndarray
        Signed radius of curvature of the profile [mm], positive where convex.
    contact_force, torque, contact_stress : numpy.ndarray
        Contact force [N], input torque [N·mm], Hertz stress [MPa].
    summary : dict
        The content of ``summary.json``.
    analysis : camcad.analysis.Analysis
        Everything the pipeline computed.
    """

    def __init__(self, design: Design, analysis: Analysis) -> None:
        """Wrap an analysis of ``design``; use ``analyse`` to make one."""
        self.design = design
        self.analysis = analysis
        summary = analysis.summary()
        self.summary: dict[str, Any] = summary
        motion, geo, dyn = summary["motion"], summary["geometry"], summary["dynamics"]
        fit = summary.get("fit")
        arm = "lift_deg" in motion
        self.lift_unit = "°" if arm else "mm"
        self.lift = Quantity(value=float(motion["lift_deg" if arm else "lift_mm"]), unit=self.lift_unit)
        u = "deg" if arm else "mm"
        self.stroke = Quantity(
            value=float(motion[f"stroke_{u}"]),
            unit=self.lift_unit,
            angle_deg=motion.get("travel_max_angle_deg"),
        )
        self.travel_min = Quantity(
            value=float(motion[f"travel_min_{u}"]),
            unit=self.lift_unit,
            angle_deg=motion.get("travel_min_angle_deg"),
        )
        self.travel_max = Quantity(
            value=float(motion[f"travel_max_{u}"]),
            unit=self.lift_unit,
            angle_deg=motion.get("travel_max_angle_deg"),
        )
        self.max_pressure_angle = _quantity(geo, "pressure_angle_max", "°")
        self.pressure_angle_limit = Quantity(value=math.degrees(design.spec.cam.max_pressure_angle), unit="°")
        groove = summary.get("groove") or {}
        self.pressure_angle_flank: str | None = groove.get("pressure_angle_max_flank")
        self.min_curvature_radius = _quantity(geo, "curvature_radius_min", "mm")
        self.min_concave_radius = _quantity(geo, "concave_radius_min", "mm")
        self.undercut: bool = bool(geo["undercut"])
        self.max_torque = _quantity(dyn, "torque_max", "N·mm")
        self.max_contact_force = _quantity(dyn, "contact_force_max", "N")
        self.min_contact_force = _quantity(dyn, "contact_force_min", "N")
        self.max_contact_stress = _quantity(dyn, "hertz_stress_max", "MPa")
        self.contact_stress_flank: str | None = dyn.get("hertz_stress_max_flank")
        positive = analysis.dynamics.positive_drive  # no spring holds it on: no jump check
        self.follower_jump: bool | None = None if positive else dyn.get("jump")
        self.fit_control_points: int | None = None if fit is None else int(fit["control_points"])
        self.fit_max_error = Quantity(value=None if fit is None else float(fit["max_error_mm"]), unit="mm")
        fea = summary.get("fea") or {}
        self.max_von_mises = Quantity(
            value=fea.get("von_mises_max_MPa"), unit="MPa", angle_deg=fea.get("von_mises_max_angle_deg")
        )
        geometry, dynamics, m = analysis.geometry, analysis.dynamics, analysis.motion
        self.phi = _readonly(geometry.phi)
        self.angle_deg = _readonly(np.degrees(geometry.phi))
        self.s, self.v, self.a, self.j = (_readonly(q) for q in (m.s, m.v, m.a, m.j))
        self.x, self.y = _readonly(geometry.profile.point[:, 0]), _readonly(geometry.profile.point[:, 1])
        self.pitch_x, self.pitch_y = (_readonly(geometry.pitch.point[:, k]) for k in (0, 1))
        self.pressure_angle = _readonly(geometry.pressure_angle)
        self.rho = _readonly(geometry.profile.rho)
        self.contact_force = _readonly(dynamics.contact_force)
        self.torque = _readonly(dynamics.torque)
        self.contact_stress = _readonly(dynamics.hertz_stress)

    @property
    def findings(self) -> tuple[Finding, ...]:
        """Every broken limit of every stage, hard ones first, then notes (``camcad.findings.Finding``)."""
        return self.analysis.findings

    @property
    def violations(self) -> list[str]:
        """The kinds of the broken limits; ``camcad check`` exits 3 when there is any."""
        return self.analysis.violations

    @property
    def ok(self) -> bool:
        """True when every design limit holds (``camcad check`` exits 0)."""
        return not self.violations

    def build(self, outdir: str | os.PathLike[str], *, only: Iterable[str] | None = None) -> BuildResult:
        """Write the design's files into ``outdir`` exactly as ``camcad build`` does.

        The build runs the pipeline's ``camcad.pipeline.build`` on the
        design (the same bytes as the command line), all or nothing: a
        failed build leaves ``outdir`` as it was.

        Parameters
        ----------
        outdir
            The output folder (created; files in it replaced).
        only
            Output groups: ``tables``, ``dxf``, ``stl``, ``step``, ``gcode``,
            ``fea``, ``report`` (``summary.json`` always); None: all.

        Raises
        ------
        UsageError
            An unknown output group.
        OutputError
            ``outdir`` cannot be written.
        DesignLimitError
            A hard limit (undercut, gouge, fit tolerance) makes the files unusable.
        """
        return self.design.build(outdir, only=only)

    def plot(self, kind: str = "motion") -> Figure:
        """A matplotlib figure of one of ``PLOTS``.

        Parameters
        ----------
        kind
            ``"motion"`` (s, v, a, j against the cam angle), ``"profile"``
            (the cam outline and pitch curve to scale), ``"pressure"`` (the
            pressure angle with its limit) or ``"dynamics"`` (contact force,
            torque, contact stress).

        Returns
        -------
        matplotlib.figure.Figure
            A new figure, not registered with pyplot (save it with
            ``fig.savefig``; in Jupyter it shows as the cell's value).

        Raises
        ------
        UsageError
            ``kind`` is not one of ``PLOTS``.
        """
        from matplotlib.figure import Figure

        from camcad.errors import UsageError

        if kind not in PLOTS:
            raise UsageError("kind", f"{kind!r} is not allowed (allowed: {', '.join(PLOTS)})")
        deg, u = self.angle_deg, self.lift_unit
        if kind == "profile":
            fig = Figure(figsize=(5.0, 5.0))
            ax = fig.add_subplot()
            ax.plot(np.append(self.x, self.x[0]), np.append(self.y, self.y[0]), color="k", label="profile")
            ax.plot(self.pitch_x, self.pitch_y, "--", color="tab:blue", lw=0.8, label="pitch curve")
            ax.set_aspect("equal")
            ax.set(xlabel="x [mm]", ylabel="y [mm]", title=self.design.name)
            ax.legend(loc="upper right", fontsize="small")
            return fig
        panels: list[tuple[FloatArray, str]] = {
            "motion": [
                (self.s, f"s [{u}]"),
                (self.v, f"v [{u}/rad]"),
                (self.a, f"a [{u}/rad²]"),
                (self.j, f"j [{u}/rad³]"),
            ],
            "pressure": [(np.degrees(self.pressure_angle), "pressure angle [°]")],
            "dynamics": [
                (self.contact_force, "contact force [N]"),
                (self.torque, "torque [N·mm]"),
                (self.contact_stress, "contact stress [MPa]"),
            ],
        }[kind]
        fig = Figure(figsize=(7.0, 1.8 * len(panels) + 0.6))
        axes = fig.subplots(len(panels), 1, sharex=True, squeeze=False)[:, 0]
        for ax, (values, label) in zip(axes, panels, strict=True):
            ax.plot(deg, values, lw=1.2)
            ax.set_ylabel(label)
            ax.grid(True, lw=0.3)
        if kind == "pressure":
            limit = float(self.pressure_angle_limit)
            for sign in (1.0, -1.0):
                axes[0].axhline(sign * limit, color="tab:red", lw=0.8, ls="--")
        axes[-1].set_xlabel("cam angle φ [°]")
        axes[0].set_title(self.design.name)
        fig.tight_layout()
        return fig

    def __repr__(self) -> str:
        """``Result('name': all design limits hold)`` or the broken limits."""
        state = "all design limits hold" if self.ok else "limits violated: " + ", ".join(self.violations)
        return f"Result({self.design.name!r}: {state})"

    def _repr_html_(self) -> str:
        """The report's key-number cards and the broken limits (Jupyter)."""
        from camcad.report import key_numbers_html

        items = "".join(
            f"<li>{'note' if f.note else f.severity.value + ' limit'}: {_e(f.message)}</li>"
            for f in self.findings
        )
        verdict = (
            f'<p class="camcad-ok">{_e(self.design.name)}: all design limits hold</p>'
            if self.ok
            else f'<p class="camcad-bad">{_e(self.design.name)}: design limits violated</p><ul>{items}</ul>'
        )
        cards = key_numbers_html(self.analysis)
        return f'<div class="camcad-result"><style>{_CARD_CSS}</style>{verdict}{cards}</div>'

    def _repr_svg_(self) -> str:
        """The cam drawn to scale with its follower, as in the report (Jupyter)."""
        return _cam_svg(self.analysis)


_CARD_CSS = (
    ".camcad-result .cards{display:grid;grid-template-columns:repeat(auto-fill,minmax(11em,1fr));gap:.5em}"
    ".camcad-result .card{border:1px solid #d8dee6;border-radius:6px;padding:.4em .6em}"
    ".camcad-result .card.over{background:#fde2e1;border-color:#c0392b}"
    ".camcad-result .label,.camcad-result .note{color:#5b6877;font-size:.85em}"
    ".camcad-result .value{font-size:1.2em;font-weight:600}"
    ".camcad-bad{color:#c0392b}.camcad-ok{color:#2e8b57}"
)


def _e(text: object) -> str:
    return html.escape(str(text), quote=True)


def _cam_svg(analysis: Analysis) -> str:
    """The report's drawing of the cam (``profile`` figure) as SVG text."""
    from camcad._plots.design import profile_plot

    plot = profile_plot(analysis)
    assert plot.svg is not None  # the profile figure is always drawn as SVG
    text = plot.svg.decode("utf-8")
    return text[text.index("<svg") :]  # without the XML prologue and doctype, for inline HTML


def analyse(design: Design, *, toolpath: bool = True, fea: bool | None = None) -> Result:
    """Analyse a design as ``camcad check`` does: every stage, limits recorded as findings.

    Parameters
    ----------
    design
        From ``load`` or ``Design.replace``.
    toolpath
        Plan the G-code toolpath too (it finds a gouge; it is most of the
        time of an analysis). The figures do not depend on it.
    fea
        Run the finite-element check; None (default): when the design has
        an ``[fea]`` table, as ``camcad check`` does.

    Returns
    -------
    Result
        Figures, findings and curves. A hard limit (undercut, gouge) is a
        finding here, not an error: ``result.ok`` tells.
    """
    from camcad.pipeline import analyse as run

    spec = design.spec
    with_fea = spec.fea is not None if fea is None else fea
    return Result(design, run(spec, strict=False, toolpath=toolpath, fea=with_fea))


def optimize(
    design: Design,
    *,
    minimize: str | Sequence[str],
    vary: Sequence[str],
    limits: Sequence[str] = (),
    method: str = "slsqp",
    starts: int = 1,
    points: int = 7,
    progress: Callable[[str], None] | None = None,
) -> OptimizeResult:
    """Constrained optimization over design-file keys, as ``camcad optimize`` does.

    Parameters
    ----------
    design
        The starting design; its own limits (pressure angle, allowable
        stress, no undercut) always apply.
    minimize
        One quantity (``"base_radius"``, ``"pressure_angle"``,
        ``"contact_stress"``, ``"torque"``, …), or two for a Pareto front.
    vary
        Variables as on the command line: ``"base_radius=30:80"`` (a range)
        or ``"law=cycloidal,poly345"`` (choices tried one by one).
    limits
        Extra limits: ``"contact_stress<=600"``.
    method, starts, points
        ``slsqp`` or ``trust-constr``; local searches; points of a front.
    progress
        Called with a description of each design tried.

    Returns
    -------
    camcad.explore.optimize.OptimizeResult
        ``best`` (one objective) or ``front`` (two), each a candidate with
        its values, objectives, constraints and ``data`` (the TOML mapping,
        ready for ``Design``).
    """
    from camcad.explore.measures import measure, parse_limit
    from camcad.explore.optimize import Problem
    from camcad.explore.optimize import optimize as run
    from camcad.explore.space import parse_variable

    data, source = design.data, design.source
    names = [minimize] if isinstance(minimize, str) else list(minimize)
    problem = Problem(
        data=data,
        source=source,
        variables=tuple(parse_variable(v, data, flag="vary", counted=False, source=source) for v in vary),
        objectives=tuple(measure(m.strip(), "minimize") for name in names for m in name.split(",")),
        limits=tuple(parse_limit(text) for text in limits),
        method=method,
        starts=starts,
        points=points,
    )
    return run(problem, progress=progress)


def sweep(
    design: Design,
    outdir: str | os.PathLike[str],
    *,
    grid: Sequence[str],
    samples: int | None = None,
    seed: int = 0,
    limits: Sequence[str] = (),
    pareto: tuple[str, str] = ("base_radius", "contact_stress"),
    fmt: str = "parquet",
    jobs: int = 1,
    scheduler: str | None = None,
    chunk_size: int = 16,
) -> SweepResult:
    """Analyse a grid or a Latin-hypercube sample of variants, as ``camcad sweep`` does.

    Parameters
    ----------
    design
        The base design.
    outdir
        Folder for ``sweep.parquet`` (or ``sweep.csv``) and ``sweep.html``.
    grid
        Variables: ``"base_radius=30:80:11"`` (11 values, ends included),
        ``"law=cycloidal,poly345"``; with ``samples`` ranges ``"30:80"``.
    samples, seed
        Latin-hypercube sampling of this many designs instead of a grid.
    limits
        Extra limits judged in the ``feasible`` column: ``"contact_stress<=600"``.
    pareto
        The two minimised quantities of the front.
    fmt
        ``"parquet"`` or ``"csv"``.
    jobs, scheduler
        Local worker processes (1: this process), or a Dask scheduler
        address (``tcp://host:8786``) that overrides ``jobs``.
    chunk_size
        Designs per unit of work; finished chunks survive an interruption.

    Returns
    -------
    camcad.explore.sweep.SweepResult
        ``rows`` (one dict per design, in order) and the ``files`` written.
    """
    from camcad.errors import UsageError
    from camcad.explore.measures import measure, parse_limit
    from camcad.explore.plan import SweepPlan
    from camcad.explore.space import grid_points, lhs_points, parse_variable
    from camcad.explore.sweep import sweep as run

    data, source = design.data, design.source
    counted = samples is None
    variables = tuple(parse_variable(g, data, flag="grid", counted=counted, source=source) for g in grid)
    if not variables:
        raise UsageError("grid", "give at least one, e.g. grid=['base_radius=30:80:51']")
    if chunk_size < 1:
        raise UsageError("chunk_size", f"{chunk_size} is not allowed (allowed: 1 or more)")
    points = grid_points(variables) if samples is None else lhs_points(variables, samples, seed=seed)
    plan = SweepPlan(
        data=data,
        source=source,
        variables=variables,
        points=tuple(points),
        limits=tuple(parse_limit(text) for text in limits),
        pareto=(measure(pareto[0], "pareto"), measure(pareto[1], "pareto")),
        sampling="grid" if counted else f"Latin hypercube, seed {seed}",
        chunk_size=chunk_size,
    )
    return run(plan, Path(outdir), fmt=fmt, jobs=jobs, scheduler=scheduler)
