"""The follower interface of the generic envelope."""

from __future__ import annotations

import enum
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy as np

from camcad._typing import FloatArray
from camcad.geometry.envelope import Guide, LineElement, PointElement
from camcad.motion.program import Motion

if TYPE_CHECKING:
    from camcad.geometry.spec import FollowerSpec

__all__ = [
    "ARM_LIFT",
    "FACE_MARGIN",
    "FACE_WIDTH",
    "OFFSET",
    "PIVOT_DISTANCE",
    "ROLLER_RADIUS",
    "ROLLER_WORDS",
    "SLIDE_LIFT",
    "Follower",
    "FollowerKey",
    "FollowerSketch",
    "FollowerType",
    "KeyRange",
    "Lift",
    "Words",
    "no_problem",
    "slide_point",
    "slide_sketch",
]


class KeyRange(enum.Enum):
    """The range of a follower key's value, as the loader states it (its bounds are the loader's).

    ``LENGTH`` a size > 0, ``LENGTH_OR_ZERO`` 0 or a size, ``NONNEGATIVE``
    0 or more, ``SIGNED`` a signed length; all in mm and capped at the
    loader's largest part.
    """

    LENGTH = "length"
    LENGTH_OR_ZERO = "length-or-zero"
    NONNEGATIVE = "nonnegative"
    SIGNED = "signed"


@dataclass(frozen=True, slots=True, kw_only=True)
class FollowerKey:
    """One key of the ``[follower]`` table as a follower kind declares it: an entry of the loader's rules.

    ``attr`` is the :class:`~camcad.geometry.spec.FollowerSpec` attribute it
    sets (None: the key itself, or a kind's own value in ``FollowerSpec.params``).
    Whether the key is required is the kind's (:attr:`FollowerType.required`).
    """

    name: str
    description: str
    range: KeyRange = KeyRange.LENGTH
    unit: str = "mm"
    attr: str | None = None


ROLLER_RADIUS = FollowerKey(
    name="roller_radius", range=KeyRange.LENGTH_OR_ZERO, description="roller radius r_f (mm)"
)
OFFSET = FollowerKey(
    name="offset",
    range=KeyRange.SIGNED,
    attr="eccentricity",
    description="eccentricity e (mm): the follower's axis is the line x = e",
)
FACE_WIDTH = FollowerKey(
    name="face_width", description="the face's width (mm); checked against the contact's travel"
)
FACE_MARGIN = FollowerKey(
    name="face_margin",
    range=KeyRange.NONNEGATIVE,
    description="face left beyond the contact's travel at each edge (mm, default 1)",
)
PIVOT_DISTANCE = FollowerKey(name="pivot_distance", description="pivot distance d from the cam axis (mm)")


@dataclass(frozen=True, slots=True, kw_only=True)
class Lift:
    """What the motion program's lift is for a follower: a slide's travel (mm) or an arm's swing (degrees).

    ``unit`` is the unit word of summary keys and tables (``"mm"`` or
    ``"deg"``), ``symbol`` how a value is shown after its number (``" mm"``,
    ``"°"``), ``short`` the unit in a column header (``mm``, ``°``),
    ``variable`` its symbol (s or ψ), ``name`` and ``title`` its names in a
    card and over a chart, ``labels`` the axis labels of s, v, a, j.
    ``angular`` is true when the follower's generalised coordinate is an angle
    about a pivot: its dynamics then take torsion springs, arm inertia and a
    spring lever, and a servo drives it on a rotary axis (no screw lead).
    ``followers`` names the followers that move so, in messages.
    """

    unit: str
    symbol: str
    short: str
    variable: str
    name: str
    title: str
    labels: tuple[str, str, str, str]
    angular: bool
    followers: str


SLIDE_LIFT = Lift(
    unit="mm",
    symbol=" mm",
    short="mm",
    variable="s",
    name="Lift",
    title="Displacement",
    labels=("s [mm]", "v = ds/dφ\n[mm/rad]", "a = d²s/dφ²\n[mm/rad²]", "j = d³s/dφ³\n[mm/rad³]"),
    angular=False,
    followers="translating",
)
ARM_LIFT = Lift(
    unit="deg",
    symbol="°",
    short="°",
    variable="ψ",
    name="Arm swing",
    title="Arm angle",
    labels=("arm angle ψ [°]", "ψ′ = dψ/dφ\n[°/rad]", "ψ″ = d²ψ/dφ²\n[°/rad²]", "ψ‴ = d³ψ/dφ³\n[°/rad³]"),
    angular=True,
    followers="oscillating",
)

Problem = tuple[str, str] | None
"""(field path, message) of why a design cannot be built, or None."""


@dataclass(frozen=True, slots=True, kw_only=True)
class FollowerType:
    """Everything a ``follower.type`` means, declared once by its module; the registry maps ``word`` to it.

    Attributes
    ----------
    word
        The TOML ``follower.type``.
    order
        Its place in lists of kinds (the loader's allowed words, the union of keys).
    keys
        Its ``[follower]`` keys (besides ``type``), entries of the loader's rules.
    required
        The names of the keys it cannot do without; a required length is > 0.
    lift
        What its motion program's lift is (:data:`SLIDE_LIFT` or :data:`ARM_LIFT`).
    face
        Whether the contact slides over a face whose width must cover its travel
        (``face_width``, ``face_margin``; see ``Follower.contact_position``).
    two_sided
        Whether its contact element can be driven from both sides: run in a
        groove, or be one of a conjugate pair's tied rollers.
    radial_slide
        Whether it can be the yoke of a constant-breadth cam (a slide through the
        cam axis when its eccentricity is 0).
    guided_tappet
        Whether Hren et al.'s guided-tappet dynamics model applies to it.
    min_curvature_radius
        The default smallest convex profile radius [mm] (``cam.min_curvature_radius``).
    default
        Whether a ``[follower]`` table without ``type`` means this kind (one kind says so).
    build
        ``build(spec, base_radius)``: the follower module at base radius r_b [mm].
    check
        ``check(spec, base_radius, swing)``: why the design's follower cannot be
        built, ``swing`` the largest lift (program units), or None.
    """

    word: str
    order: int
    keys: tuple[FollowerKey, ...]
    required: tuple[str, ...]
    lift: Lift
    face: bool
    two_sided: bool
    radial_slide: bool = False
    guided_tappet: bool = False
    min_curvature_radius: float = 0.0
    default: bool = False
    build: Callable[[FollowerSpec, float], Follower]
    check: Callable[[FollowerSpec, float, float], Problem]

    @property
    def lift_unit(self) -> str:
        """``"mm"`` for a slide, ``"deg"`` of arm swing for an arm (summary keys, tables)."""
        return self.lift.unit


def no_problem(spec: FollowerSpec, base_radius: float, swing: float) -> Problem:
    """A follower that any valid key values can build."""
    return None


_CIRCLE = np.linspace(0.0, 2.0 * np.pi, 73)


@dataclass(frozen=True, slots=True, kw_only=True)
class FollowerSketch:
    """A drawing of the follower at one cam angle, machine frame [mm].

    ``body`` are the parts that touch or carry the cam load (roller, face),
    ``links`` what holds them (stem, arm), ``axes`` construction lines (the
    slide's axis); each a (k, 2) polyline. ``marks`` (m, 2) are points to mark
    (roller centre, pivot); the label goes at ``tip``, leaning ``heading``.
    """

    body: tuple[FloatArray, ...]
    links: tuple[FloatArray, ...]
    axes: tuple[FloatArray, ...]
    marks: FloatArray
    tip: FloatArray
    heading: FloatArray


def circle_points(centre: FloatArray, radius: float) -> FloatArray:
    """(73, 2) points of a closed circle [mm]."""
    return np.column_stack((centre[0] + radius * np.cos(_CIRCLE), centre[1] + radius * np.sin(_CIRCLE)))


def slide_sketch(
    centre: FloatArray, axis: FloatArray, *, radius: float, half_face: float, size: float
) -> FollowerSketch:
    """A translating follower at ``centre`` driven along unit ``axis``: roller (radius > 0) or face.

    The stem is ``size``/4 long beyond the roller or face; the slide's axis runs
    from its foot nearest the cam centre to the stem's tip.
    """
    across = np.array([axis[1], -axis[0]])
    if radius > 0.0:
        body: tuple[FloatArray, ...] = (circle_points(centre, radius),)
        foot = centre + radius * axis
        marks = centre[None, :]
    else:
        body = (np.array([centre - half_face * across, centre + half_face * across]),)
        foot = centre
        marks = np.empty((0, 2))
    tip = foot + 0.25 * size * axis
    back = centre - float(np.dot(centre, axis)) * axis
    return FollowerSketch(
        body=body,
        links=(np.array([foot, tip]),),
        axes=(np.array([back, tip]),),
        marks=marks,
        tip=tip,
        heading=axis,
    )


def slide_point(x: float, height: float, motion: Motion) -> PointElement:
    """A point on a slide along the machine's +y at x [mm]: (x, height + s) and its φ-derivatives.

    M = (x, h + s), M′ = (0, v), M″ = (0, a), M‴ = (0, j): the roller centre of
    a translating roller (h = k) or the face centre of a translating face (h = r_b).
    """
    zero = np.zeros_like(motion.s)
    return PointElement(
        m0=np.column_stack((zero + x, height + motion.s)),
        m1=np.column_stack((zero, motion.v)),
        m2=np.column_stack((zero, motion.a)),
        m3=np.column_stack((zero, motion.j)),
    )


class Follower(Protocol):
    """What a follower tells the envelope.

    Attributes
    ----------
    roller_radius
        r_f [mm] of a roller follower (the profile is the element's path
        offset inward by it); 0 for a face.
    guide
        How the follower is guided in the machine frame.
    """

    @property
    def roller_radius(self) -> float:
        """r_f [mm]; 0 for a face."""
        ...

    @property
    def guide(self) -> Guide:
        """Translation axis or pivot, machine frame."""
        ...

    def element(self, motion: Motion) -> PointElement | LineElement:
        """The contact element at the motion's cam angles, machine frame, with three φ-derivatives."""
        ...

    def trace(self, motion: Motion) -> PointElement:
        """The follower's reference point (roller centre, face centre), machine frame, for drawings."""
        ...

    def describe(self) -> str:
        """A short label for reports, e.g. ``"translating roller r_f = 15 mm, e = 20 mm"``."""
        ...

    def contact_position(self, contact: FloatArray, motion: Motion) -> FloatArray:
        """(n,) where the contact sits on the follower [mm], from the machine-frame contact points (n, 2).

        Slides: its distance from the slide's axis along +x. Oscillating flat
        face: its distance along the face from the pivot's foot. Oscillating
        roller: its distance from the arm's line (r_f·sin of the angle off it).
        """
        ...

    def sketch(self, motion: Motion, *, size: float) -> list[FollowerSketch]:
        """The follower drawn at each of the motion's angles, machine frame; ``size`` [mm] scales stems."""
        ...

    @property
    def contact_radius(self) -> float:
        """The follower's radius of curvature at the contact [mm], which sets the contact stress; 0: flat."""
        ...

    @property
    def rolls(self) -> bool:
        """Whether the contact element is a roller turning on its bearing (rolling contact, roller life)."""
        ...

    @property
    def arm_direction(self) -> float | None:
        """An arm's direction pivot → follower at ψ = 0, machine frame [rad]; None on a slide."""
        ...

    @property
    def words(self) -> Words:
        """How reports, plots and drawings name the follower's curves and sizes."""
        ...

    def rows(self) -> tuple[tuple[str, float | None], ...]:
        """The report's design-table rows of the follower: (label with unit, value or None for "—")."""
        ...


@dataclass(frozen=True, slots=True, kw_only=True)
class Words:
    """How a follower's curves and sizes are named in reports, plots, the designer and drawings.

    ``trace`` names its reference curve (:meth:`Follower.trace`'s path);
    ``path`` the element path whose convex radius of curvature limits the
    profile ("" for a face, whose profile is the envelope itself); ``radius``
    the element's radius (``roller_radius``; "" for a face) and ``smaller``
    the way out of an undercut it offers ("" for a face); ``why_rho`` why the
    curvature matters.
    """

    trace: str
    path: str = ""
    radius: str = ""
    smaller: str = ""
    why_rho: str = "a flat face needs ρ > 0 everywhere (a convex profile) or the face cannot follow it"


ROLLER_WORDS = Words(
    trace="pitch curve (roller-centre path)",
    path="roller-centre path",
    radius="roller radius",
    smaller="use a smaller roller",
    why_rho="the roller-centre path's convex ρ must stay above the roller radius or the profile loops",
)
