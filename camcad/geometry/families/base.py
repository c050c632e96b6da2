"""What a cam family is: the parts it makes, and what each part needs from the later stages.

A cam family (plate, groove, conjugate pair; a barrel later) turns the one
designed :class:`~camcad.geometry.cam.Cam` into the :class:`Part` s to make.
Every later stage maps over the parts with the same code: the geometry and
the rigid dynamics of each part's own cam (its own roller sets its Hertz
contact, its ``drive_sign`` says which way it pushes), the certified fit of
its outline and of its further curves (:class:`Flank`), its tool path and its
files (``cam{suffix}.*``). What only one family knows (a groove's flank
checks, a pair's ``second_plate`` summary section, the drawing's caption)
stays in that family's module.

The shape of a part is data the writers read, not a family name: a part
with no :attr:`Part.pocket` is a plate cut along its outline; one with a
:class:`Pocket` is a blank with a pocket between two flanks; one with a
:class:`Barrel` is a cylinder with a groove round it, whose walls the later
stages take from its exact envelope (:mod:`camcad.geometry.barrel`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol, TypedDict

from camcad.findings import Finding
from camcad.geometry.barrel import BarrelFollower, BarrelOptions, RollerShape
from camcad.geometry.barrel_limits import BarrelLimits
from camcad.geometry.cam import Cam
from camcad.geometry.spec import ConjugateSpec, GrooveSpec, LinearSpec
from camcad.motion.program import MotionProgram

__all__ = [
    "Bar",
    "Barrel",
    "BarrelSpec",
    "CamFamily",
    "Drive",
    "FamilyOptions",
    "Flank",
    "Part",
    "PartCheck",
    "PartResults",
    "Pocket",
]


@dataclass(frozen=True, slots=True, kw_only=True)
class BarrelSpec:
    """What the design states of a barrel cam beyond the ``[groove]`` table (issue 36).

    ``barrel_radius`` R [mm] (outer) and ``length`` [mm] along its axis
    (``[cam]``); ``axial_position`` z0 [mm], the roller's axis at φ = 0,
    ``roller`` its shape and ``roller_length`` ℓ [mm] (``[follower]``);
    ``rib_width`` w [mm] (``[cam]``): a rib's width along the axis at the
    pitch station, None for a groove (``cam.style = "barrel-rib"`` requires it).
    """

    barrel_radius: float
    length: float
    axial_position: float
    roller_length: float
    roller: RollerShape = RollerShape.CYLINDRICAL
    rib_width: float | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class FamilyOptions:
    """What the families read from the design: the ``[groove]`` and ``[conjugate]`` tables, the blank.

    ``outer_radius`` [mm]: a groove cam's blank (None: no blank);
    ``hole_radius`` [mm]: the bore's farthest reach, keyway included (0 without a bore);
    ``barrel``: a barrel cam's :class:`BarrelSpec`; ``bore`` [mm]: the bore's diameter.
    """

    groove: GrooveSpec = field(default_factory=GrooveSpec)
    conjugate: ConjugateSpec = field(default_factory=ConjugateSpec)
    linear: LinearSpec = field(default_factory=LinearSpec)
    outer_radius: float | None = None
    hole_radius: float = 0.0
    barrel: BarrelSpec | None = None  # a barrel cam's own values; None for every other style
    bore: float = 0.0  # the bore's diameter [mm] (a barrel's; a plate's is in hole_radius)


class Drive(TypedDict):
    """How a family holds the follower on (the fields of :class:`camcad.dynamics.spec.DynamicsSetup`).

    ``positive_drive``: no spring holds it, the cam drives it both ways;
    ``clearance`` [mm]: a groove's radial play; ``flank_offsets`` [mm]: a
    groove's flanks as offsets of the profile, None for any other family.
    """

    positive_drive: bool
    clearance: float
    flank_offsets: tuple[float, float] | None


class PartCheck(Protocol):
    """A family's own check of a part (a groove's flanks): findings, radius margin, summary figures."""

    @property
    def findings(self) -> tuple[Finding, ...]:
        """The check's broken limits."""
        ...

    @property
    def radius_margin(self) -> float:
        """The smallest radius [mm] of the part's further curves that must stay positive (a flank's)."""
        ...

    def summary(self) -> dict[str, Any]:
        """The check's figures for ``summary.json``."""
        ...


@dataclass(frozen=True, slots=True, kw_only=True)
class Flank:
    """A further curve of a part, fitted and drawn beside its outline: an offset of its cam's profile.

    ``name`` keys its fit in ``summary.json``; ``layer`` is its DXF layer;
    ``offset`` [mm] the distance from the profile (``Cam.offset_curve(φ, offset)``).
    """

    name: str
    layer: str
    offset: float


@dataclass(frozen=True, slots=True, kw_only=True)
class Pocket:
    """A blank of ``outer_radius`` [mm] with a pocket ``depth`` [mm] deep between ``flanks`` (inner, outer).

    ``clearance`` [mm]: the radial play of the roller in the pocket;
    ``width`` [mm]: the pocket's width, flank to flank.
    """

    outer_radius: float
    depth: float
    clearance: float
    width: float
    flanks: tuple[Flank, Flank]


@dataclass(frozen=True, slots=True, kw_only=True)
class Bar:
    """A bar cut along its cam's open edge (a linear cam), in the cam's frame [mm].

    The bar runs from x = ``x0`` (the edge's start, φ = 0) to ``x0 + length``
    (its end, φ = 2π); its bottom edge is the line y = ``bottom``. Its
    outline is the edge, the end at x0 + length down to the bottom, the
    bottom back and the end at x0 up to the edge's start.
    """

    x0: float
    length: float
    bottom: float


@dataclass(frozen=True, slots=True, kw_only=True)
class Barrel:
    """A cylinder with a groove round it: the exact walls' data (:mod:`camcad.geometry.barrel`).

    ``program`` the motion, ``follower`` where it holds the roller's axis,
    ``options`` the barrel, groove and roller [mm], ``limits`` its checked
    figures over the turn (:func:`~camcad.geometry.barrel_limits.barrel_limits`).
    """

    program: MotionProgram
    follower: BarrelFollower
    options: BarrelOptions
    limits: BarrelLimits


@dataclass(frozen=True, slots=True, kw_only=True)
class Part:
    """One part a cam family makes, and what every later stage needs of it.

    Attributes
    ----------
    cam
        The part's exact cam (its follower, its roller): geometry, dynamics,
        fit and tool path all run on it.
    suffix
        Its files' name suffix: ``cam{suffix}.stl``, ``profile{suffix}.dxf``.
    label
        Empty for the family's first part; else its name ("second plate"),
        which prefixes its findings and names its G-code program.
    drive_sign
        +1 where the part's roller pushes the follower forwards, −1 where it
        pushes it back (a conjugate pair's second plate): the sign that turns
        the generalised force into the part's contact force.
    made
        False for a part analysed but not made on its own (the second roller
        of a constant-breadth pair runs on the first plate).
    pocket
        None: a plate, cut along its outline. Else the blank and the pocket
        between two flanks (a groove cam).
    bar
        None: a disc. Else the bar whose top edge is the cam's open profile
        (a linear cam).
    barrel
        None, or the cylinder and its groove (a barrel cam): its fit, files
        and tool path are taken from the walls, its ``cam`` is the groove
        developed at the roller's pitch station.
    checks
        The family's own checks of the part (a groove's flank checks).
    program
        False for a part made without a G-code program: no ``cam.ngc`` is
        planned; its checks carry a note saying why (no family needs it now).
    """

    cam: Cam
    suffix: str = ""
    label: str = ""
    drive_sign: float = 1.0
    made: bool = True
    pocket: Pocket | None = None
    bar: Bar | None = None
    barrel: Barrel | None = None
    checks: tuple[PartCheck, ...] = ()
    program: bool = True

    @property
    def flanks(self) -> tuple[Flank, ...]:
        """The further curves fitted and drawn beside the outline (a pocket's flanks), else none."""
        return () if self.pocket is None else self.pocket.flanks

    @property
    def findings(self) -> tuple[Finding, ...]:
        """The findings of the family's own checks of this part."""
        return tuple(f for check in self.checks for f in check.findings)

    def title(self, name: str) -> str:
        """The part's name for a program or a drawing: ``name``, with its label in brackets."""
        return f"{name} ({self.label})" if self.label else name


class PartResults(Protocol):
    """What the later stages computed for one part (:class:`camcad.analysis.PartResult` is one)."""

    @property
    def part(self) -> Part:
        """The part."""
        ...

    @property
    def geometry(self) -> Any:
        """Its :class:`~camcad.geometry.GeometryAnalysis`."""
        ...

    @property
    def dynamics(self) -> Any:
        """Its :class:`~camcad.dynamics.DynamicsResult` (``phi``, ``contact_force``, ``summary()``)."""
        ...

    @property
    def fit(self) -> Any:
        """Its outline's :class:`~camcad.fit.ProfileFit`, or None."""
        ...

    @property
    def flank_fits(self) -> tuple[Any, ...]:
        """A :class:`~camcad.fit.ProfileFit` per flank (``part.flanks``), or none."""
        ...

    @property
    def fea(self) -> Any:
        """Its plate's :class:`~camcad.fea.results.FeaResult` (``summary()``), or None."""
        ...

    @property
    def duty(self) -> Any:
        """Its :class:`~camcad.dynamics.duty.DutyResult` (life and film: ``summary()``), or None."""
        ...

    @property
    def wall_fit(self) -> Any:
        """A barrel's :class:`~camcad.fit.surface.BarrelWallFit`, or None."""
        ...


class CamFamily(Protocol):
    """A cam family: the parts it makes of a cam, its own ``summary.json`` section and caption."""

    @property
    def name(self) -> str:
        """The TOML ``cam.style`` of the family."""
        ...

    @property
    def table(self) -> str | None:
        """The TOML table only this family reads (``[groove]``, ``[conjugate]``), or None."""
        ...

    @property
    def own_keys(self) -> frozenset[str]:
        """The design keys only this family reads (``cam.barrel_radius``); refused on other styles."""
        ...

    @property
    def needs_roller(self) -> bool:
        """Whether the family drives its follower through a roller (positive drive does)."""
        ...

    @property
    def one_plate(self) -> bool:
        """Whether the family makes one plate cut along its outline (the rotary machine)."""
        ...

    @property
    def plates(self) -> bool:
        """Whether each part made is a plate cut along its outline (the FE check holds each by its bore)."""
        ...

    def check(
        self, options: FamilyOptions, *, base_radius: float, roller_radius: float, thickness: float
    ) -> None:
        """Raise :class:`~camcad.errors.DesignError` (naming its field) where the design cannot be made.

        ``base_radius``, ``roller_radius`` (the designed follower's) and ``thickness`` in mm.
        """
        ...

    def check_cam(self, cam: Callable[[], Cam], options: FamilyOptions) -> None:
        """Raise :class:`~camcad.errors.DesignError` where the designed cam cannot make the family's parts.

        ``cam`` builds the designed cam (called only by a family that needs it).
        """
        ...

    def parts(self, cam: Cam, options: FamilyOptions) -> tuple[Part, ...]:
        """The parts to make of ``cam``, the designed one first."""
        ...

    def drive(self, roller_radius: float, options: FamilyOptions) -> Drive:
        """How the family holds the follower on: :class:`Drive`, fields of the dynamics setup.

        ``roller_radius`` [mm]: the designed follower's (0 for a flat face).
        """
        ...

    def summary(self, results: Sequence[PartResults]) -> dict[str, Any]:
        """The family's own sections of ``summary.json`` (none for a plate)."""
        ...

    def caption(self, parts: Sequence[Part]) -> str:
        """What the cam drawing adds for this family, as a sentence (or nothing)."""
        ...
