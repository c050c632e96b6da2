"""Motion programs: ordered rise / dwell / return segments over one cam turn.

A program maps the cam angle φ [rad] to the follower displacement s [mm] and
its φ-derivatives v = ds/dφ [mm/rad], a = d²s/dφ² [mm/rad²] and
j = d³s/dφ³ [mm/rad³], exactly, from each segment's law in closed form.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, TypeVar

import numpy as np

from camcad._typing import ArrayLike, FloatArray, readonly
from camcad.angles import TWO_PI
from camcad.extremes import Side
from camcad.motion._blendlaws import InclinedSine, Polynomial
from camcad.motion.blend import resolve_blends
from camcad.motion.segments import SegmentKind, SegmentSpec

__all__ = [
    "Breakpoint",
    "Joint",
    "Motion",
    "MotionProgram",
    "Side",
    "TimeMotion",
]

T = TypeVar("T")

_SNAP = 1e-12  # a normalised x this close to a law's breakpoint is that breakpoint
# A jump smaller than this (relative to the derivative's scale) is continuity.
_JUMP_RTOL = 1e-9


@dataclass(frozen=True, slots=True, kw_only=True)
class Motion:
    """Follower motion sampled at cam angles.

    Attributes
    ----------
    phi
        (n,) cam angle φ [rad].
    s
        (n,) displacement [mm].
    v
        (n,) ds/dφ [mm/rad] (pseudo velocity).
    a
        (n,) d²s/dφ² [mm/rad²].
    j
        (n,) d³s/dφ³ [mm/rad³].
    """

    phi: FloatArray
    s: FloatArray
    v: FloatArray
    a: FloatArray
    j: FloatArray

    def in_time(self, omega: float) -> TimeMotion:
        """Time derivatives at constant cam speed ``omega`` [rad/s]."""
        out = TimeMotion(
            phi=self.phi,
            velocity=self.v * omega,
            acceleration=self.a * (omega * omega),  # ω·ω: see dynamics/jump.py
            jerk=self.j * omega**3,
        )
        readonly(out.velocity, out.acceleration, out.jerk)
        return out


@dataclass(frozen=True, slots=True, kw_only=True)
class TimeMotion:
    """Follower velocity [mm/s], acceleration [mm/s²] and jerk [mm/s³] at constant ω."""

    phi: FloatArray
    velocity: FloatArray
    acceleration: FloatArray
    jerk: FloatArray


@dataclass(frozen=True, slots=True, kw_only=True)
class Breakpoint:
    """A segment joint where the motion may lose smoothness.

    ``continuity`` k means s is C^k there: 0 when v jumps (a corner of the
    pitch curve), 1 when a jumps, 2 when j jumps, 3 when smooth to j.
    """

    phi: float  # rad
    continuity: int


@dataclass(frozen=True, slots=True, kw_only=True)
class Joint:
    """Jumps (right minus left) of v [mm/rad], a [mm/rad²], j [mm/rad³] at a joint."""

    phi: float  # rad
    index: int  # the segment that starts here
    dv: float
    da: float
    dj: float
    continuity: int
    internal: bool = False  # inside a segment, where its law switches formula

    def describe(self, unit: str = "mm") -> str:
        """One line a user reads, e.g. ``acceleration jumps by 0.85 mm/rad² at 150°``.

        ``unit`` is the lift's unit as shown: ``"mm"`` on a slide, ``"°"`` (or
        ``"deg"``) of swing on an arm.
        """
        deg = math.degrees(self.phi)
        where = " (inside the segment)" if self.internal else ""
        u = "°" if unit == "deg" else unit
        parts = []
        for name, shown, value in (
            ("velocity", f"{u}/rad", self.dv),
            ("acceleration", f"{u}/rad²", self.da),
            ("jerk", f"{u}/rad³", self.dj),
        ):
            if value != 0.0:
                parts.append(f"{name} jumps by {value:+.4g} {shown}")
        if not parts:
            return f"{deg:g}°{where}: smooth (s, v, a, j continuous)"
        return f"{deg:g}°{where}: " + ", ".join(parts)


@dataclass(frozen=True, slots=True)
class MotionProgram:
    """An ordered list of segments covering 360° of cam rotation.

    Build it with :meth:`from_segments`; the design layer has already checked
    that the spans total 2π and that the lift closes.
    """

    segments: tuple[SegmentSpec, ...]
    starts: tuple[float, ...]  # rad, start angle of each segment
    base_s: tuple[float, ...]  # mm, displacement at each segment's start
    _memo: dict[str, Any] = field(  # the joints, breakpoints, the last sample grid: found once
        default_factory=dict, init=False, compare=False, hash=False, repr=False
    )

    @classmethod
    def from_segments(cls, segments: Sequence[SegmentSpec]) -> MotionProgram:
        """Lay the segments end to end from φ = 0, solving the blend points first.

        Segments whose law adapts to its neighbours (``polynomial``,
        ``inclined-sine``) are resolved by :func:`~camcad.motion.blend.resolve_blends`;
        ``segments`` of the result holds the resolved laws.
        """
        segments = resolve_blends(segments)
        starts, base_s = [], []
        phi = s = 0.0
        for seg in segments:
            starts.append(phi)
            base_s.append(s)
            phi += seg.span
            if seg.kind is SegmentKind.RISE:
                s += seg.lift
            elif seg.kind is SegmentKind.RETURN:
                s -= seg.lift
        return cls(tuple(segments), tuple(starts), tuple(base_s))

    @property
    def lift(self) -> float:
        """Largest displacement of the program [mm]."""
        peaks = []
        for base, seg in zip(self.base_s, self.segments, strict=True):
            if seg.kind is SegmentKind.RISE:
                peaks.append(base + seg.lift)
            elif seg.kind is SegmentKind.TABLE and seg.law is not None:
                peaks.append(float(getattr(seg.law, "peak", 0.0)))
        return max([*self.base_s, *peaks])

    @property
    def segment_bounds(self) -> tuple[float, ...]:
        """Start angle of every segment [rad]; the first is 0."""
        return self.starts

    def _segment_of(self, phi: FloatArray) -> np.ndarray:
        edges = np.asarray(self.starts[1:])
        return np.searchsorted(edges, phi, side="right")

    def _evaluate_segment(
        self, index: int, x: FloatArray, side: Side = "right"
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """s, v, a, j of segment ``index`` at normalised x ∈ [0, 1].

        At a breakpoint inside the law (where it switches formula) the
        one-sided limit of ``side`` is taken: x moves one ulp to that side, so
        the formula of that side is evaluated there, exact to round-off.
        """
        seg = self.segments[index]
        base = self.base_s[index]
        if seg.kind is SegmentKind.DWELL or seg.law is None:
            zero = np.zeros_like(x)
            return zero + base, zero, zero, zero
        if seg.law.breakpoints:
            toward = 0.0 if side == "left" else 1.0
            for xb in seg.law.breakpoints:
                x = np.where(np.abs(x - xb) <= _SNAP, np.nextafter(xb, toward), x)
        y, y1, y2, y3 = seg.law.evaluate(x)
        h = seg.signed_lift  # a table's law gives s itself [mm]: h = 1
        beta = seg.span
        # chain rule: x = (φ − φ0)/β, so d^k/dφ^k = β^-k d^k/dx^k
        return base + h * y, h * y1 / beta, h * y2 / beta**2, h * y3 / beta**3

    def evaluate(self, phi: ArrayLike, *, side: Side = "right") -> Motion:
        """Displacement and its φ-derivatives at any cam angles.

        Parameters
        ----------
        phi
            Cam angles [rad], any shape; wrapped into [0, 2π).
        side
            At a joint (a segment joint or a breakpoint inside a law) the
            one-sided limit to return: ``"right"`` (the default, the motion
            just after the joint) or ``"left"`` (just before it; at 0° that is
            the end of the last segment). Elsewhere both give the same values.

        Returns
        -------
        Motion
            Flattened (n,) arrays.
        """
        phi_in = np.asarray(phi, dtype=float).ravel()
        wrapped = np.mod(phi_in, TWO_PI)
        if side == "left":
            wrapped = np.where(wrapped == 0.0, TWO_PI, wrapped)  # the end of the last segment
            edges = np.asarray(self.starts[1:])
            index = np.searchsorted(edges, wrapped, side="left")
        else:
            index = self._segment_of(wrapped)
        s = np.zeros_like(wrapped)
        v, a, j = np.zeros_like(s), np.zeros_like(s), np.zeros_like(s)
        for k, seg in enumerate(self.segments):
            mask = index == k
            if not mask.any():
                continue
            x = np.clip((wrapped[mask] - self.starts[k]) / seg.span, 0.0, 1.0)
            s[mask], v[mask], a[mask], j[mask] = self._evaluate_segment(k, x, side)
        out = Motion(phi=phi_in.copy(), s=s, v=v, a=a, j=j)
        readonly(out.phi, out.s, out.v, out.a, out.j)
        return out

    def joints(self) -> tuple[Joint, ...]:
        """Jumps of v, a and j at every segment joint (360° → 0° included).

        Points inside a segment where its law switches formula (the SCCA laws'
        phase changes, the middle of a VAP rise, where y″ jumps) are reported
        too, with ``internal=True``, since the fit needs knots there as well.
        Computed once per program (every true-extremes search asks for them).
        """
        if "joints" not in self._memo:
            self._memo["joints"] = self._find_joints()
        joints: tuple[Joint, ...] = self._memo["joints"]
        return joints

    def kept(self, key: str, compute: Callable[[], T]) -> T:
        """``compute()`` once per program and ``key``: a finding of the motion alone that every analysis asks.

        ``compute`` must depend only on this program (and on what ``key``
        names): the variants of a sweep that share one program
        (:mod:`camcad.explore.batch`) then check it once.
        """
        name = f"kept:{key}"
        if name not in self._memo:
            self._memo[name] = compute()
        out: T = self._memo[name]
        return out

    def _find_joints(self) -> tuple[Joint, ...]:
        n = len(self.segments)
        places: list[tuple[float, int, int, float, float, bool]] = []
        for k, seg in enumerate(self.segments):
            places.append((self.starts[k], (k - 1) % n, k, 1.0, 0.0, False))
            for x in seg.law.breakpoints if seg.law is not None else ():
                places.append((self.starts[k] + x * seg.span, k, k, x, x, True))
        out = []
        for phi, left_k, right_k, x_left, x_right, internal in places:
            left = self._evaluate_segment(left_k, np.array([x_left]), "left")
            right = self._evaluate_segment(right_k, np.array([x_right]), "right")
            cleaned = []
            for order, (l_, r) in enumerate(zip(left[1:], right[1:], strict=True), start=1):
                value = float(r[0] - l_[0])
                ref = max(self._derivative_scale(left_k, order), self._derivative_scale(right_k, order))
                cleaned.append(0.0 if abs(value) <= _JUMP_RTOL * ref else value)
            continuity = next((order for order, value in enumerate(cleaned) if value != 0.0), 3)
            out.append(
                Joint(
                    phi=phi,
                    index=right_k,
                    dv=cleaned[0],
                    da=cleaned[1],
                    dj=cleaned[2],
                    continuity=continuity,
                    internal=internal,
                )
            )
        return tuple(out)

    def _derivative_scale(self, index: int, order: int) -> float:
        seg = self.segments[index]
        return max(self.lift, 1.0) / seg.span**order

    @property
    def breakpoints(self) -> tuple[Breakpoint, ...]:
        """Every segment joint with its continuity order (the fit puts knots here); found once per program."""
        if "breakpoints" not in self._memo:
            self._memo["breakpoints"] = tuple(
                Breakpoint(phi=jt.phi, continuity=jt.continuity) for jt in self.joints()
            )
        out: tuple[Breakpoint, ...] = self._memo["breakpoints"]
        return out

    @property
    def blend_points(self) -> tuple[Breakpoint, ...]:
        """The joints next to a segment whose law took its boundary values from its neighbours.

        (``polynomial``, ``inclined-sine``), with their continuity: what a
        plot marks as blend points.
        """
        n = len(self.segments)
        adaptive = [isinstance(g.law, (Polynomial, InclinedSine)) for g in self.segments]
        return tuple(
            Breakpoint(phi=jt.phi, continuity=jt.continuity)
            for jt in self.joints()
            if not jt.internal and (adaptive[jt.index] or adaptive[(jt.index - 1) % n])
        )

    @property
    def smooth_knots(self) -> tuple[float, ...]:
        """Angles [rad] where a law switches formula but s, v, a, j stay continuous (``Law.knots``).

        A point table's spline knots. Not joints (nothing jumps there), but a
        quadrature over the turn converges fastest split there as well.
        """
        out = {
            start + x * seg.span
            for start, seg in zip(self.starts, self.segments, strict=True)
            for x in (seg.law.knots if seg.law is not None else ())
        }
        return tuple(sorted(out))

    @property
    def pieces(self) -> tuple[float, ...]:
        """Every angle [rad] where the formula of s(φ) changes: breakpoints and smooth knots, sorted.

        A quadrature or flattening of anything built on the motion converges
        fastest split there (Gauss-Legendre is exponential only on smooth pieces).
        """
        return tuple(sorted({bp.phi for bp in self.breakpoints} | set(self.smooth_knots)))

    def sample_phi(self, step: float) -> FloatArray:
        """Cam angles in [0, 2π): a uniform grid of ``step`` [rad] plus every breakpoint (kept)."""
        kept = self._memo.get("sample_phi")
        if kept is not None and kept[0] == step:
            got: FloatArray = kept[1]
            return got
        out = self._sample_phi(step)
        self._memo["sample_phi"] = (step, out)
        return out

    def _sample_phi(self, step: float) -> FloatArray:
        n = max(math.ceil(TWO_PI / step - 1e-9), 8)
        grid = np.linspace(0.0, TWO_PI, n, endpoint=False)
        marks = np.mod([bp.phi for bp in self.breakpoints], TWO_PI)
        phi = np.union1d(grid, marks)
        # drop grid points closer than 1e-9 rad to a breakpoint (keep the breakpoint)
        keep = np.ones(phi.size, dtype=bool)
        for b in marks:
            near = np.abs(phi - b) < 1e-9 * TWO_PI
            near[np.argmin(np.abs(phi - b))] = False
            keep &= ~near
        out = phi[keep]
        readonly(out)
        return out
