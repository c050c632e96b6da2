"""The cam as a function of the cam angle: pitch curve, profile and offsets, for any follower.

Everything here is exact: points and their first and second φ-derivatives
follow from the motion's s, v, a, j in closed form, through the follower's
contact element (:mod:`camcad.geometry.followers`) and the generic envelope
(:mod:`camcad.geometry.envelope`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any, ClassVar, Protocol

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.angles import TWO_PI
from camcad.errors import DesignError
from camcad.geometry.curves import CurveSample
from camcad.geometry.envelope import (
    LineElement,
    PointElement,
    line_envelope,
    offset_curve,
    point_envelope,
    pressure_angle,
    to_cam,
    translation_envelope,
)
from camcad.geometry.followers import Follower
from camcad.geometry.followers.tied import TiedRoller
from camcad.geometry.spec import ConjugateSpec, FollowerSpec, Rotation
from camcad.knobs import Knob
from camcad.motion.program import Motion, MotionProgram, Side
from camcad.motion.segments import SegmentKind, SegmentSpec

__all__ = ["Cam", "CamState", "follower_from_spec"]


class _CamTable(Protocol):
    """What a cam is built from of the design's ``[cam]`` table."""

    @property
    def base_radius(self) -> float:
        """r_b [mm]."""
        ...

    @property
    def rotation(self) -> Rotation:
        """The sense the cam turns."""
        ...

    @property
    def sample_step(self) -> float:
        """Sampling step [rad]."""
        ...


class _CamDesign(Protocol):
    """The shape of a design that :meth:`Cam.from_design` reads (the schema sits above this stage)."""

    @property
    def cam(self) -> _CamTable:
        """The ``[cam]`` table."""
        ...

    @property
    def follower(self) -> FollowerSpec:
        """The ``[follower]`` table."""
        ...

    @property
    def motion(self) -> Sequence[SegmentSpec]:
        """The ``[[motion]]`` segments."""
        ...


def follower_from_spec(spec: FollowerSpec, base_radius: float) -> Follower:
    """The follower module a design's ``[follower]`` table describes, at r_b [mm]: its kind builds it."""
    return spec.kind.build(spec, base_radius)


@dataclass(frozen=True, slots=True, kw_only=True)
class CamState:
    """The cam at some angles, from one evaluation (see :meth:`Cam.state`); arrays (n,) or (n, 2).

    ``base`` is the curve offsets are taken from: the pitch curve of a roller,
    the profile of a face. ``contact_position`` is where the contact sits on
    the follower [mm] (see :meth:`Cam.contact_offset`). ``lever`` is an
    oscillating follower's distance from its pivot to the driven point (roller
    centre, or the contact on a face) [mm]; None for a slide.
    """

    motion: Motion
    base: CurveSample
    profile: CurveSample
    pressure_angle: FloatArray
    contact_position: FloatArray
    lever: FloatArray | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class Cam:
    """A disc cam, or a linear cam (a plate translating along x), driving a follower.

    Attributes
    ----------
    program
        The motion program s(φ).
    base_radius
        r_b [mm]: the smallest radius of the cam profile.
    follower_spec
        The design's ``[follower]`` table (kind, roller radius r_f [mm],
        offset e [mm]); the follower it builds is :attr:`follower`.
    rotation
        ``CCW`` (default) or ``CW``.
    stroke_length
        None: a disc cam turning about its axis. Else a linear cam: the plate
        moves by ``stroke_length`` L [mm] towards −x per cycle of the motion
        (φ from 0 to 2π), so a machine point M(φ) is at M(φ) + (Lφ/2π, 0) in
        the plate's frame (:func:`camcad.geometry.envelope.translation_envelope`;
        :mod:`camcad.geometry.linear`); ``base_radius`` is then the base line's
        height above y = 0 and the profile is open, from x = 0 to x = L.

    Notes
    -----
    Cam frame: origin on the cam axis, x right, y up; at φ = 0 the follower
    stands on +y where the machine puts it (a translating follower's axis is
    the line x = e whatever the rotation). The cam turns by +φ (ccw) or −φ
    (cw) while the machine stays put, so a machine point M(φ) is seen at
    R(∓φ)·M(φ) in the cam frame: for an offset roller P = R(−φ)·(e, k + s)
    with k = √((r_b + r_f)² − e²) (Quang & Hung 2015, eq. 2 with the erratum
    y_p = (k + s) cos φ − e sin φ), and P = R(+φ)·(e, k + s) for a cw cam.
    """

    program: MotionProgram
    base_radius: float
    follower_spec: FollowerSpec
    rotation: Rotation = Rotation.CCW
    sample_step: float = math.radians(0.1)
    conjugate: ConjugateSpec | None = None  # set: this is the pair's second plate, driving the tied roller
    stroke_length: float | None = None  # set: a linear cam, L [mm] of plate travel per cycle
    turns_about_axis: ClassVar[bool] = True  # its profile turns about the cam axis (a developed groove: no)
    _memo: dict[str, Any] = field(  # the follower module, and the last sample grid's motion and state
        default_factory=dict, init=False, compare=False, hash=False, repr=False
    )

    @classmethod
    def from_design(cls, design: _CamDesign) -> Cam:
        """The cam a validated design describes."""
        return cls(
            program=MotionProgram.from_segments(design.motion),
            base_radius=design.cam.base_radius,
            follower_spec=design.follower,
            rotation=design.cam.rotation,
            sample_step=design.cam.sample_step,
        )

    # -- basic quantities -------------------------------------------------

    @property
    def follower(self) -> Follower:
        """The follower module at this cam's base radius (the tied roller on a pair's second plate).

        Built once per cam: every evaluation of the cam's curves asks for it.
        """
        if "follower" not in self._memo:
            self._memo["follower"] = self._follower()
        out: Follower = self._memo["follower"]
        return out

    def _follower(self) -> Follower:
        first = follower_from_spec(self.follower_spec, self.base_radius)
        if self.conjugate is None:
            return first
        top_phi = max((bp.phi for bp in self.program.breakpoints), key=lambda p: float(self.motion(p).s[0]))
        return TiedRoller.on(
            first,
            roller_radius=self.conjugate.roller_radius or first.roller_radius,
            angle=self.conjugate.angle,
            top=first.element(self.motion(top_phi)),  # type: ignore[arg-type]
            base_radius=self.base_radius,
        )

    def partner(self, conjugate: ConjugateSpec) -> Cam:
        """The conjugate pair's second plate, on the same shaft, driving the tied second roller.

        Both plates follow one motion program: the second starts with the
        first one's motion of the sample grid, if computed, instead of
        evaluating it again.
        """
        out = replace(self, conjugate=conjugate)
        if "motion" in self._memo:
            out._memo["motion"] = self._memo["motion"]
        return out

    @property
    def has_pitch_curve(self) -> bool:
        """Whether the contact element is a circle (a roller, a curved face): its centre traces a pitch curve.

        Then the profile is that path offset inward by :attr:`roller_radius` and
        undercut makes it loop; a flat face's envelope is the profile itself,
        and undercut makes a cusp.
        """
        return self.follower.roller_radius > 0.0

    @property
    def roller_radius(self) -> float:
        """The contact circle's radius [mm] (a roller's r_f, a curved face's radius); 0 for a flat face."""
        return self.follower.roller_radius

    @property
    def eccentricity(self) -> float:
        """Follower eccentricity e [mm] (the design file's ``offset``): its axis is the line x = e."""
        return self.follower_spec.eccentricity

    @property
    def closed(self) -> bool:
        """Whether the profile is a closed curve (a disc cam); a linear cam's runs open from x = 0 to L."""
        return self.stroke_length is None

    @property
    def travel_rate(self) -> float | None:
        """A linear cam's plate travel per radian of the motion, c = L/2π [mm/rad]; None for a disc cam."""
        return None if self.stroke_length is None else self.stroke_length / TWO_PI

    @property
    def straight_spans(self) -> tuple[tuple[float, float], ...]:
        """φ-intervals [rad] over which the profile and its offsets are straight lines; () on a disc cam.

        On a linear cam the follower stands still through each dwell of the
        motion while the bar slides under it, so the contact element's path
        relative to the bar, and with it the profile and every offset of it,
        is a line parallel to the travel over the dwell's span. Taken from the
        motion's dwell segments, not from samples. (A disc cam's dwell is a
        circle about the cam's axis.)
        """
        if self.stroke_length is None:
            return ()
        return tuple(
            (start, start + seg.span)
            for start, seg in zip(self.program.starts, self.program.segments, strict=True)
            if seg.kind is SegmentKind.DWELL and seg.span > 0.0
        )

    def frame_angle(self, phi: ArrayLike) -> FloatArray:
        """The angle [rad] the cam frame is turned by at motion angles φ: φ on a disc, 0 on a linear cam.

        ``to_cam(cam.frame_angle(φ), v, -cam.sigma)`` turns cam-frame vectors into the machine frame.
        """
        angle = np.asarray(phi, dtype=float)
        out: FloatArray = angle if self.stroke_length is None else np.zeros_like(angle)
        return out

    def machine_points(self, phi: ArrayLike, points: FloatArray) -> FloatArray:
        """(n, 2) cam-frame points at motion angles φ (n,) [rad] in the machine frame [mm].

        A disc turns them by +σφ; a linear cam's bar, moved by −cφ along x, shifts them by −cφ.
        """
        angle = np.asarray(phi, dtype=float)
        out: FloatArray = to_cam(self.frame_angle(angle), np.asarray(points, dtype=float), -self.sigma)
        if self.stroke_length is not None:
            out = out - np.column_stack((self.stroke_length / TWO_PI * angle, np.zeros_like(angle)))
        return out

    def to_machine(self, phi: ArrayLike, vectors: FloatArray) -> FloatArray:
        """(n, 2) cam-frame vectors at motion angles φ (n,) [rad] seen in the machine frame."""
        return to_cam(self.frame_angle(phi), vectors, -self.sigma)

    def seen_from_cam(self, phi: ArrayLike, points: FloatArray) -> FloatArray:
        """(n, 2) machine-frame points at motion angles φ (n,) [rad] in the cam's frame [mm].

        A disc turns them by −σφ; a linear cam's bar, moved by −cφ along x, shifts them by +cφ.
        """
        angle = np.asarray(phi, dtype=float)
        out: FloatArray = to_cam(self.frame_angle(angle), np.asarray(points, dtype=float), self.sigma)
        if self.stroke_length is not None:
            out = out + np.column_stack((self.stroke_length / TWO_PI * angle, np.zeros_like(angle)))
        return out

    def surface_rate(self, points: FloatArray) -> FloatArray:
        """(n, 2) velocity of the cam's material at machine points (n, 2) [mm], per radian of motion [mm/rad].

        A disc turning at σ: σ ẑ × P; a linear cam's plate: (−c, 0) everywhere, c = L/2π.
        """
        pts = np.asarray(points, dtype=float)
        if self.stroke_length is None:
            out: FloatArray = self.sigma * np.column_stack((-pts[:, 1], pts[:, 0]))
            return out
        return np.column_stack((np.full(len(pts), -self.stroke_length / TWO_PI), np.zeros(len(pts))))

    def _point_envelope(self, m: Motion, element: PointElement) -> tuple[CurveSample, FloatArray]:
        """The path of a roller centre in the cam frame and its dρ/dφ: turned by a disc, shifted by a bar."""
        if self.stroke_length is None:
            return point_envelope(m.phi, element, self.sigma)
        return translation_envelope(m.phi, element, self.stroke_length / TWO_PI)

    def _line_envelope(self, m: Motion, element: LineElement) -> tuple[CurveSample, FloatArray]:
        if self.stroke_length is not None:  # the design check refuses it (geometry.linear)
            raise DesignError(
                Knob.FOLLOWER_TYPE,
                "a flat face has no envelope on a linear cam (it does not turn relative to it)",
            )
        return line_envelope(m.phi, element, self.sigma)

    @property
    def sigma(self) -> float:
        """+1 for a counter-clockwise cam, −1 for a clockwise one."""
        return 1.0 if self.rotation is Rotation.CCW else -1.0

    def motion(self, phi: ArrayLike, *, side: Side = "right") -> Motion:
        """The follower motion at cam angles φ [rad]; ``side`` picks the one-sided limit at joints.

        The motion of the last sample grid asked for (:data:`_GRID_MIN` angles
        or more) is kept and given again for the same angles and side: every
        stage of an analysis samples the cam on one grid.
        """
        key = _grid_key(phi, side)
        if key is not None:
            kept = self._memo.get("motion")
            if kept is not None and kept[0] == key:
                out: Motion = kept[1]
                return out
        m = self.program.evaluate(phi, side=side)
        if key is not None:
            self._memo["motion"] = (key, m)
        return m

    @property
    def rests(self) -> tuple[tuple[float, float], ...]:
        """The dwells, each as [start, end] [rad]: the follower stands still, every quantity is constant.

        On a dwell the profile is an arc about the cam axis and the follower's
        state does not change (s constant, v = a = j = 0 exactly): the true
        extremes searches (:func:`camcad.extremes.extremes_rows`) need not
        refine there.
        """
        program = self.program
        ends = (*program.starts[1:], TWO_PI)
        return tuple(
            (start, end)
            for start, end, seg in zip(program.starts, ends, program.segments, strict=True)
            if seg.kind is SegmentKind.DWELL or seg.law is None
        )

    def sample_phi(self, step: float | None = None) -> FloatArray:
        """Cam angles in [0, 2π) at ``step`` [rad] (default: the design's) plus every breakpoint."""
        return self.program.sample_phi(self.sample_step if step is None else step)

    def curve_phi(self, step: float | None = None) -> FloatArray:
        """:meth:`sample_phi`, and for an open profile (a linear cam's edge) its end φ = 2π too."""
        phi = self.sample_phi(step)
        if self.closed:
            return phi
        out: FloatArray = np.append(phi, TWO_PI)
        readonly(out)
        return out

    # -- curves -------------------------------------------------------------

    def _element(self, phi: ArrayLike, side: Side) -> tuple[Motion, PointElement | LineElement]:
        m = self.motion(phi, side=side)
        return m, self.follower.element(m)

    def pitch(self, phi: ArrayLike, *, side: Side = "right") -> CurveSample:
        """The pitch curve at cam angles φ [rad].

        For a roller follower it is the path of the roller centre; for a flat
        follower, the path of the face centre (the point of the face on the
        follower axis). ``side`` picks the one-sided limit at joints.
        """
        m = self.motion(phi, side=side)
        return self._point_envelope(m, self.follower.trace(m))[0]

    def _base_curve(self, phi: ArrayLike, side: Side) -> tuple[CurveSample, FloatArray, float]:
        """The curve offsets are taken from, its dρ/dφ, and the profile's distance from it [mm].

        Roller: the pitch curve (the profile is its offset by −r_f).
        Flat: the profile itself.
        """
        m, element = self._element(phi, side)
        if isinstance(element, PointElement):
            base, drho = self._point_envelope(m, element)
            return base, drho, -self.roller_radius
        base, drho = self._line_envelope(m, element)
        return base, drho, 0.0

    def offset_curve(self, phi: ArrayLike, distance: float, *, side: Side = "right") -> CurveSample:
        """The profile offset outward by ``distance`` [mm] at cam angles φ [rad].

        ``distance = r`` is the centre path of a milling tool (or a roller) of
        radius r rolling on the profile; ``distance = 0`` is the profile. See
        :func:`camcad.geometry.envelope.offset_curve`; ``side`` picks the
        one-sided limit at joints.
        """
        base, drho, profile_at = self._base_curve(phi, side)
        return offset_curve(base, drho, distance + profile_at)

    def profile(self, phi: ArrayLike, *, side: Side = "right") -> CurveSample:
        """The cam profile (contact point C) at cam angles φ [rad]; ``side`` as in :meth:`offset_curve`."""
        return self.offset_curve(phi, 0.0, side=side)

    def _driven_point(self, phi: ArrayLike, side: Side) -> tuple[CurveSample, FloatArray]:
        """The profile, and the follower point that is driven (roller centre or contact), machine frame."""
        base, drho, profile_at = self._base_curve(phi, side)
        profile = offset_curve(base, drho, profile_at)
        driven = base.point if self.has_pitch_curve else profile.point
        return profile, self.machine_points(profile.phi, driven)

    def state(self, phi: ArrayLike, *, side: Side = "right") -> CamState:
        """Everything at cam angles φ [rad] from one evaluation: motion, base curve, profile, α, contact.

        The analyses refine many quantities at once on the same angles; this
        computes the contact element and its envelope once for all of them.
        The state of the last sample grid asked for is kept, as in :meth:`motion`.
        """
        key = _grid_key(phi, side)
        if key is not None:
            kept = self._memo.get("state")
            if kept is not None and kept[0] == key:
                got: CamState = kept[1]
                return got
        out = self._state(phi, side)
        if key is not None:
            self._memo["state"] = (key, out)
        return out

    def keep_state(self, phi: FloatArray, state: CamState) -> None:
        """Keep ``state`` (and its motion) as this cam's right-side state at the sample grid ``phi`` [rad].

        For a batch analysis (:mod:`camcad.explore.batch`) that evaluated the
        grid of many variants of one design at once: :meth:`state` and
        :meth:`motion` then give these for the grid, as if computed here.
        """
        key = _grid_key(phi, "right")
        if key is not None:
            self._memo["motion"] = (key, state.motion)
            self._memo["state"] = (key, state)

    def _state(self, phi: ArrayLike, side: Side) -> CamState:
        m, element = self._element(phi, side)
        if isinstance(element, PointElement):
            base, drho = self._point_envelope(m, element)
            profile = offset_curve(base, drho, -self.roller_radius)
            driven = base.point
        else:
            base, drho = self._line_envelope(m, element)
            profile = base
            driven = profile.point
        guide = self.follower.guide
        turned = self.frame_angle(m.phi)
        driven_machine = self.machine_points(m.phi, driven)
        alpha = pressure_angle(turned, profile.normal, driven_machine, guide, self.sigma)
        contact = self.machine_points(m.phi, profile.point)
        lever = None
        if guide.pivot is not None:
            arm = driven_machine - np.asarray(guide.pivot)
            lever = np.hypot(arm[:, 0], arm[:, 1])
            readonly(lever)
        position = self.follower.contact_position(contact, m)
        readonly(position)
        return CamState(
            lever=lever,
            motion=m,
            base=base,
            profile=profile,
            pressure_angle=alpha,
            contact_position=position,
        )

    def loop_radius(self, state: CamState) -> FloatArray:
        """(n,) the radius that decides undercut [mm]: it must stay above :attr:`roller_radius`.

        Roller: the convex pitch-curve radius (the profile loops where it falls
        below r_f; +inf where the pitch curve is concave). Flat face: the
        profile radius r_b + s + a (a cusp where it reaches 0).
        """
        if self.has_pitch_curve:
            out: FloatArray = np.where(state.base.rho > 0.0, state.base.rho, np.inf)
            return out
        return state.profile.rho

    def pressure_angle(self, phi: ArrayLike, *, side: Side = "right") -> FloatArray:
        """Signed pressure angle α [rad] at cam angles φ [rad].

        See :func:`camcad.geometry.envelope.pressure_angle`: |α| is the angle
        between the common normal and the direction the follower is driven
        in; for an offset roller tan α = (v − e)/(s + k) on a ccw cam
        (Quang & Hung 2015, eq. 4) and (v + e)/(s + k) on a cw cam; its
        magnitude is arccos(R·n/|R|) for a radial follower (Quintero &
        Vanegas 2016, eq. 14); a translating flat face has α ≡ 0. ``side``
        picks the one-sided limit at joints.
        """
        profile, driven = self._driven_point(phi, side)
        turned = self.frame_angle(profile.phi)
        return pressure_angle(turned, profile.normal, driven, self.follower.guide, self.sigma)

    def contact_offset(self, phi: ArrayLike, *, side: Side = "right") -> FloatArray:
        """Where the contact sits on the follower [mm] (:meth:`Follower.contact_position`).

        Translating followers: its distance from the follower axis along the
        machine's +x; for a flat face it is σ·v − e (Hren et al., eq. 27 with
        the papers/README reading r_m = |ds/dφ|), for a roller the roller
        radius times sin α, in the same sense. Oscillating flat face: its
        distance B along the face from the pivot's foot.
        """
        m = self.motion(phi, side=side)
        profile = self.profile(phi, side=side)
        contact = self.machine_points(profile.phi, profile.point)
        out = self.follower.contact_position(contact, m)
        readonly(out)
        return out


_GRID_MIN = 256
"""The fewest angles a sample grid has: smaller requests (a refinement's few points) are not kept."""


def _grid_key(phi: ArrayLike, side: Side) -> tuple[Side, int, bytes] | None:
    """What identifies a sample grid of :data:`_GRID_MIN` or more angles [rad]; None for fewer."""
    if not isinstance(phi, np.ndarray) or phi.size < _GRID_MIN:
        return None
    return side, phi.size, np.ascontiguousarray(phi, dtype=float).tobytes()
