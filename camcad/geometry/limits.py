"""Geometry analysis of a cam: the sampled curves, limits, undercut and findings."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.angles import TWO_PI, flagged_ranges, format_ranges
from camcad.errors import UndercutError
from camcad.extremes import SIDE_WORDS, Extreme, Kind, Quantity, Side, extremes_rows, maximum
from camcad.findings import Finding, Severity
from camcad.geometry.cam import Cam, CamState
from camcad.geometry.curves import CurveSample
from camcad.geometry.envelope import LineElement, PointElement
from camcad.geometry.followers.tied import TiedRoller
from camcad.geometry.sizing import curvature_finding, min_base_radius
from camcad.knobs import Knob
from camcad.roots import brent_root

__all__ = [
    "GEOMETRY_KINDS",
    "GeometryAnalysis",
    "Undercut",
    "analyse_geometry",
    "conjugate_overlap",
    "geometry_rows",
    "undercut_error",
]

_SUGGEST_ROUND_MM = 0.01


@dataclass(frozen=True, slots=True, kw_only=True)
class Undercut:
    """Where the profile loops (roller) or has a cusp (flat face).

    ``ranges`` are cam-angle ranges [rad]; ``worst`` is the smallest convex
    pitch radius [mm] (roller) or the most negative profile radius (flat),
    at cam angle ``worst_angle`` [rad].
    """

    ranges: tuple[tuple[float, float], ...]
    worst: float
    worst_angle: float
    worst_side: Side | None = None  # the worst value is the limit just before/after a joint

    def where(self) -> str:
        """``"at 29.9°"`` or ``"at 90.0° (just before the joint)"``."""
        return Extreme(value=self.worst, phi=self.worst_angle, side=self.worst_side).where()


@dataclass(frozen=True, slots=True, kw_only=True)
class GeometryAnalysis:
    """A cam's geometry sampled over one turn, with its limits checked at true extremes.

    Arrays are (n,) over ``phi`` [rad]; ``pressure_angle`` rad; radii mm. The
    :class:`~camcad.extremes.Extreme` fields are the true extremes over the
    turn (one-sided limits at joints included, interior extrema refined on the
    exact curves), not the extremes of the samples.
    """

    cam: Cam
    phi: FloatArray
    s: FloatArray
    pitch: CurveSample
    profile: CurveSample
    pressure_angle: FloatArray
    max_pressure_angle: float  # rad, the design limit
    undercut: Undercut | None
    findings: tuple[Finding, ...]
    face_width_min: float | None  # mm, flat faces: 2 × (excursion + margin); on an arm B_max + margin
    pressure_angle_max: Extreme  # of |α| [rad]
    profile_radius_min: Extreme  # polar radius of the contact point [mm]
    profile_radius_max: Extreme
    # smallest convex profile radius [mm], signed: < 0 where the profile loops (roller) or has a
    # cusp (flat face); None if none convex
    curvature_radius_min: Extreme | None
    # smallest concave profile radius [mm] (positive), a loop or cusp not counted; None if none
    concave_radius_min: Extreme | None

    def summary(self) -> dict[str, Any]:
        """The ``geometry`` section of summary.json (angles in degrees, lengths mm).

        Every extreme is the true one; ``*_side`` says ``"before joint"`` or
        ``"after joint"`` where it is a one-sided limit at a joint, else null.
        """
        out: dict[str, Any] = {}
        _put(out, "pressure_angle_max", self.pressure_angle_max, scale=180.0 / math.pi, unit="deg")
        _put(out, "profile_radius_min", self.profile_radius_min, unit="mm")
        _put(out, "profile_radius_max", self.profile_radius_max, unit="mm")
        _put(out, "curvature_radius_min", self.curvature_radius_min, unit="mm")
        _put(out, "concave_radius_min", self.concave_radius_min, unit="mm")
        out["undercut"] = self.undercut is not None
        if self.face_width_min is not None:
            out["face_width_min_mm"] = self.face_width_min
        return out


def _put(out: dict[str, Any], key: str, ext: Extreme | None, *, unit: str, scale: float = 1.0) -> None:
    """``key_unit``, ``key_angle_deg`` and ``key_side`` of an extreme (all None when absent)."""
    out[f"{key}_{unit}"] = None if ext is None else ext.value * scale
    out[f"{key}_angle_deg"] = None if ext is None else ext.angle_deg
    out[f"{key}_side"] = None if ext is None or ext.side is None else SIDE_WORDS[ext.side]


def _concave(rho: FloatArray) -> FloatArray:
    """−ρ where concave, +inf elsewhere (for the smallest concave radius)."""
    return np.where(rho < 0.0, -rho, np.inf)


def _undercut_quantity(cam: Cam) -> tuple[Quantity, float]:
    """The quantity whose minimum decides undercut, and the value it must stay above.

    Roller: the convex pitch-curve radius must exceed r_f (else the profile
    loops). Flat face: the profile radius r_b + s + a must stay > 0 (else a cusp).
    """
    return (lambda phi, side: cam.loop_radius(cam.state(phi, side=side))), cam.roller_radius


def _bad_range(quantity: Quantity, limit: float, worst: Extreme, step: float) -> tuple[float, float]:
    """The cam-angle range [rad] around ``worst`` where ``quantity < limit``, by root finding.

    Used when the violation lies between samples or in a one-sided limit at a
    joint, so that no sample is flagged.
    """

    def g(phi: float) -> float:
        return float(quantity(np.array([phi]), "right")[0]) - limit

    def root(inside: float, outside: float) -> float:
        if g(outside) < 0.0:
            return outside
        return brent_root(g, min(inside, outside), max(inside, outside), xtol=1e-12)

    centre = worst.phi
    lo = centre if worst.side == "right" else root(centre - 1e-12, centre - 2.0 * step)
    hi = centre if worst.side == "left" else root(centre + 1e-12, centre + 2.0 * step)
    return float(np.mod(lo, TWO_PI)), float(np.mod(hi, TWO_PI)) if hi < TWO_PI else TWO_PI


def _pressure_finding(phi: FloatArray, alpha: FloatArray, worst: Extreme, limit: float) -> Finding:
    """The soft finding for a pressure angle over ``limit`` [rad], with the ranges where it is."""
    ranges = flagged_ranges(phi, np.abs(alpha) > limit)
    where = format_ranges(ranges) if ranges else worst.where()
    return Finding(
        kind="pressure angle",
        severity=Severity.SOFT,
        field=Knob.MAX_PRESSURE_ANGLE,
        message=(
            f"pressure angle reaches {math.degrees(worst.value):.2f}° > limit "
            f"{math.degrees(limit):g}° at {where}"
        ),
        angle=worst.phi,
        value=math.degrees(worst.value),
        limit=math.degrees(limit),
        unit="deg",
    )


def _arm_face_check(
    reach_min: Extreme, reach_max: Extreme, face_width: float | None, face_margin: float
) -> tuple[float, list[Finding]]:
    """A face on an arm, reaching ``face_width`` from the pivot's foot, must hold [B_min, B_max] ± margin.

    The contact's distance B along the face from the pivot's foot must stay
    ≥ ``face_margin`` (else it runs off the face's pivot end) and ≤
    ``face_width`` − ``face_margin``; the face length needed is B_max + margin.
    """
    needed = reach_max.value + face_margin
    found: list[Finding] = []
    if reach_min.value < face_margin:
        found.append(
            Finding(
                kind="face width",
                severity=Severity.HARD,
                field=Knob.PIVOT_DISTANCE,
                field_first=True,
                message=(
                    f"the contact comes within {reach_min.value:.3f} mm of the "
                    f"pivot's foot on the face {reach_min.where()}, less than face_margin = "
                    f"{face_margin:g} mm; move the pivot further from the cam or lower the lift"
                ),
                angle=reach_min.phi,
                value=reach_min.value,
                limit=face_margin,
                unit="mm",
            )
        )
    if face_width is not None and face_width < needed:
        found.append(
            Finding(
                kind="face width",
                severity=Severity.HARD,
                field=Knob.FACE_WIDTH,
                field_first=True,
                message=(
                    f"{face_width:g} mm does not cover the contact, which reaches "
                    f"{reach_max.value:.3f} mm along the face from the pivot's foot {reach_max.where()}; "
                    f"with face_margin {face_margin:g} mm use face_width ≥ {_up(needed):.2f} mm"
                ),
                angle=reach_max.phi,
                value=face_width,
                limit=needed,
                unit="mm",
            )
        )
    return needed, found


def _face_check(
    reach_min: Extreme, reach_max: Extreme, face_width: float | None, face_margin: float
) -> tuple[float, list[Finding]]:
    """The face width needed [mm] (travel + margin each side), and a hard finding if the face is narrower."""
    far = reach_max if abs(reach_max.value) >= abs(reach_min.value) else reach_min
    reach = abs(far.value)
    needed = 2.0 * (reach + face_margin)
    if face_width is None or face_width >= needed:
        return needed, []
    message = (
        f"{face_width:g} mm does not cover the contact, which travels "
        f"{reach:.3f} mm off the follower axis {far.where()}; with face_margin "
        f"{face_margin:g} mm each side use face_width ≥ {_up(needed):.2f} mm"
    )
    found = Finding(
        kind="face width",
        severity=Severity.HARD,
        field=Knob.FACE_WIDTH,
        message=message,
        field_first=True,
        angle=far.phi,
        value=face_width,
        limit=needed,
        unit="mm",
    )
    return needed, [found]


GEOMETRY_KINDS: tuple[Kind, ...] = ("max", "min", "max", "min", "min", "min", "min", "max")
"""The extreme :func:`analyse_geometry` finds of each row of :func:`geometry_rows`."""


def geometry_rows(cam: Cam, state: CamState) -> FloatArray:
    """(8, n) the quantities whose true extremes :func:`analyse_geometry` finds, at the state's angles.

    |α| [rad], profile radius (for its min and max) [mm], convex ρ, concave ρ,
    the undercut quantity (:meth:`Cam.loop_radius`) and the contact position
    (for its min and max) [mm]: one row each, kinds :data:`GEOMETRY_KINDS`.
    """
    radius = np.hypot(state.profile.point[:, 0], state.profile.point[:, 1])
    rho = state.profile.rho
    undercut = cam.loop_radius(state)
    x = state.contact_position
    # the convex side runs on into a loop or cusp with ρ < 0: its minimum is the true signed one
    convex = np.where(np.isfinite(undercut), rho, np.inf)
    concave = np.where(np.isfinite(undercut), np.inf, _concave(rho))
    out: FloatArray = np.vstack(
        (np.abs(state.pressure_angle), radius, radius, convex, concave, undercut, x, x)
    )
    return out


def analyse_geometry(
    cam: Cam,
    *,
    max_pressure_angle: float,
    face_width: float | None = None,
    face_margin: float = 1.0,
    min_curvature_radius: float = 0.0,
    step: float | None = None,
) -> GeometryAnalysis:
    """Sample the cam and check its limits at true extremes.

    Parameters
    ----------
    cam
        The cam.
    max_pressure_angle
        Design limit on |α| [rad]; exceeding it is a soft finding.
    face_width
        Flat-follower face width [mm], centred on the follower axis. It must
        cover the contact point's whole travel (r_m = |ds/dφ − e|, Hren et al.
        eq. 27) plus ``face_margin`` on each side, or it is a hard finding.
    face_margin
        Margin [mm] beyond the contact's travel at each edge of the face.
    min_curvature_radius
        Smallest convex profile radius [mm] the design requires
        (``cam.min_curvature_radius``): above 0 and below it is a soft
        finding (:func:`camcad.geometry.sizing.curvature_finding`, the rule
        ``camcad size`` and ``camcad optimize`` use too); the undercut advice
        sizes for it.
    step
        Sampling step [rad]; default the cam's (0.1°). Breakpoints are always
        samples, and every extreme is refined on the exact curves between
        samples and at both sides of every joint, so the reported extremes do
        not depend on the step.
    """
    phi = cam.sample_phi(step)
    h = float(np.max(np.diff(phi)))
    joints = [bp.phi for bp in cam.program.breakpoints]
    now = cam.state(phi)
    motion, profile, alpha = now.motion, now.profile, now.pressure_angle
    pitch = now.base if cam.has_pitch_curve else cam.pitch(phi)
    findings: list[Finding] = []

    roller = cam.has_pitch_curve  # a contact circle: undercut loops the profile (else a face's cusp)

    def rows(p: FloatArray, side: Side) -> FloatArray:
        return geometry_rows(cam, cam.state(p, side=side))

    values = geometry_rows(cam, now)  # the samples: the state above, not a second evaluation
    alpha_max, radius_min, radius_max, convex_min, concave_min, worst, reach_min, reach_max = extremes_rows(
        rows, phi, joints, GEOMETRY_KINDS, values=values, rests=cam.rests
    )

    if alpha_max.value > max_pressure_angle:
        findings.append(_pressure_finding(phi, alpha, alpha_max, max_pressure_angle))
    face_min = None
    if cam.follower_spec.kind.face:
        check = _face_check if cam.follower.guide.pivot is None else _arm_face_check
        face_min, found = check(reach_min, reach_max, face_width, face_margin)
        findings += found

    quantity, limit = _undercut_quantity(cam)
    undercut = None
    bad = values[5] < limit if roller else values[5] <= limit
    if worst.value < limit or (not roller and worst.value <= limit):
        ranges = flagged_ranges(phi, bad)
        if not ranges:
            ranges = [_bad_range(quantity, limit, worst, h)]
        undercut = Undercut(
            ranges=tuple(ranges), worst=worst.value, worst_angle=worst.phi, worst_side=worst.side
        )
    findings += _pivot_clearance(cam, radius_max)
    findings += _velocity_jumps(cam)
    findings += _reversals(cam)
    s = np.asarray(motion.s)
    readonly(phi)
    analysis = GeometryAnalysis(
        cam=cam,
        phi=phi,
        s=s,
        pitch=pitch,
        profile=profile,
        pressure_angle=alpha,
        max_pressure_angle=max_pressure_angle,
        undercut=undercut,
        findings=tuple(findings),
        face_width_min=face_min,
        pressure_angle_max=alpha_max,
        profile_radius_min=radius_min,
        profile_radius_max=radius_max,
        curvature_radius_min=convex_min if math.isfinite(convex_min.value) else None,
        concave_radius_min=concave_min if math.isfinite(concave_min.value) else None,
    )
    if undercut is None:
        # the design's own smallest radius (0 < ρ_min < required): the one rule of check, size and optimize
        rho = replace(worst, value=worst.value - limit)  # convex profile radius (a roller's: pitch ρ − r_f)
        soft = curvature_finding(cam, rho, required=min_curvature_radius)
        return analysis if soft is None else replace(analysis, findings=(*analysis.findings, soft))
    err = undercut_error(analysis, min_curvature_radius=min_curvature_radius)
    undercut_finding = Finding(
        kind="undercut" if cam.has_pitch_curve else "cusp",
        severity=Severity.HARD,
        field=Knob.BASE_RADIUS if cam.closed else Knob.STROKE_LENGTH,
        message=err.message,
        field_first=True,
        angle=undercut.worst_angle,
        value=undercut.worst,
        limit=limit,
        unit="mm",
    )
    return replace(analysis, findings=(undercut_finding, *analysis.findings))


def _pivot_clearance(cam: Cam, radius_max: Extreme) -> list[Finding]:
    """A hard finding when an arm's pivot lies inside the circle the profile sweeps (the cam would hit it).

    The profile turns with the cam, so every point of it passes through the
    circle of radius R_max = max |profile| about the cam axis; a pivot (and
    the arm's hub on it) at a distance d ≤ R_max from the axis lies in that
    swept disc. Allowed: d > R_max, a strict bound with no hub size added
    (the design states none).
    """
    pivot = cam.follower.guide.pivot
    if pivot is None or not cam.turns_about_axis:  # a developed barrel groove sweeps no disc
        return []
    if not cam.closed:
        return _pivot_above_bar(cam, pivot)
    d = math.hypot(*pivot)
    if d > radius_max.value:
        return []
    return [
        Finding(
            kind="pivot clearance",
            severity=Severity.HARD,
            field=Knob.PIVOT_DISTANCE,
            field_first=True,
            message=(
                f"{d:g} mm puts the pivot inside the circle the profile sweeps "
                f"(the profile reaches {radius_max.value:.3f} mm from the cam axis {radius_max.where()}): "
                f"the cam would hit the arm's hub; allowed: pivot_distance > {radius_max.value:.3f} mm "
                "(move the pivot out, or lower the lift or the base radius)"
            ),
            angle=radius_max.phi,
            value=d,
            limit=radius_max.value,
            unit="mm",
        )
    ]


def _pivot_above_bar(cam: Cam, pivot: tuple[float, float]) -> list[Finding]:
    """A linear cam: the whole bar slides under the pivot, which must lie above the edge's highest point."""
    top = maximum(
        lambda p, side: np.asarray(cam.profile(p, side=side).point)[:, 1],
        cam.sample_phi(),
        [bp.phi for bp in cam.program.breakpoints],
    )
    if pivot[1] > top.value:
        return []
    return [
        Finding(
            kind="pivot clearance",
            severity=Severity.HARD,
            field=Knob.PIVOT_DISTANCE,
            field_first=True,
            message=(
                f"the pivot at y = {pivot[1]:.3f} mm is not above the bar's edge, "
                f"which reaches y = {top.value:.3f} mm {top.where()}: the bar would hit the arm's hub; "
                "move the pivot up, or lower the lift or the base line"
            ),
            angle=top.phi,
            value=pivot[1],
            limit=top.value,
            unit="mm",
        )
    ]


def conjugate_overlap(partner: Cam) -> tuple[Knob, str] | None:
    """Why a conjugate pair's two rollers overlap, as (field path, message); None when they clear.

    ``partner`` is the pair's second plate (:meth:`Cam.partner`). The second
    roller is tied rigidly to the first (:class:`TiedRoller`): on a slide its
    centre is the first's shifted by a fixed Δ, on an arm it is the first's
    turned by the included angle θ about the pivot, so the distance between
    the centres is the same at every cam angle: |Δ| = √(a² + b² − 2ab cos θ)
    (a = |M1| at the top of the lift, b = r_b + r_f2; law of cosines) or
    2l·sin(θ/2) (the chord of the arm's circle of radius l). Seen along the
    shaft, the rollers overlap when that distance is below r_f + r_f2.
    """
    tied = partner.follower
    conj = partner.conjugate
    if conj is None or not isinstance(tied, TiedRoller):
        return None
    first = tied.first
    motion = partner.motion(0.0)
    m1 = _centre(first.element(motion))
    gap = float(np.hypot(*(tied.element(motion).m0[0] - m1)))
    need = first.roller_radius + tied.roller_radius
    if gap >= need:
        return None
    pivot = first.guide.pivot
    if pivot is not None:
        arm = float(np.hypot(*(m1 - np.asarray(pivot))))
        cos_max = 1.0 - need**2 / (2.0 * arm**2)  # 2l sin(θ/2) ≥ need ⇔ cos θ ≤ 1 − need²/(2l²)
        how = f"arms of length {arm:g} mm"
    else:
        breakpoints = partner.program.breakpoints
        top_phi = max((bp.phi for bp in breakpoints), key=lambda p: float(partner.motion(p).s[0]))
        a = float(np.hypot(*_centre(first.element(partner.motion(top_phi)))))
        b = partner.base_radius + tied.roller_radius
        cos_max = (a * a + b * b - need * need) / (2.0 * a * b)  # |Δ|² ≥ need² by the law of cosines
        how = f"centres {a:.4g} mm and {b:g} mm from the cam axis at the top of the lift"
    if cos_max <= -1.0:
        allowed = "no angle: use smaller rollers"
    else:
        lo = math.degrees(math.acos(min(1.0, cos_max)))
        allowed = f"{lo:.3f}° to {360.0 - lo:.3f}°"
    return (
        Knob.CONJUGATE_ANGLE,
        f"{math.degrees(conj.angle):g}° puts the two rollers' centres {gap:.4g} mm apart at every cam "
        f"angle, less than the sum of their radii {need:g} mm: the rollers overlap ({how}); "
        f"allowed: {allowed}",
    )


def _centre(element: PointElement | LineElement) -> FloatArray:
    """A roller's centre [mm] (a conjugate pair drives rollers: the element is a point path)."""
    assert isinstance(element, PointElement), "a conjugate pair needs roller followers"
    out: FloatArray = element.m0[0]
    return out


def _up(value: float) -> float:
    """Round up to the advice resolution (0.01 mm): advice always errs to the safe side."""
    return math.ceil(value / _SUGGEST_ROUND_MM) * _SUGGEST_ROUND_MM


def _velocity_jumps(cam: Cam) -> list[Finding]:
    """A hard finding for every joint where the velocity jumps (a corner in the pitch curve).

    ds/dφ jumping means an infinite follower acceleration (an impulse) and a
    profile with a corner that no follower can track; the segment whose own
    end velocity is not zero is named (a constant-velocity segment between
    rests, typically).
    """
    out = []
    unit = cam.follower_spec.kind.lift_unit  # mm on a slide, degrees of swing on an arm
    shown = "°" if unit == "deg" else unit
    for joint in cam.program.joints():
        if joint.continuity > 0:
            continue
        left = float(cam.motion(np.array([joint.phi]), side="left").v[0])
        k = (joint.index - 1) % len(cam.program.segments) if left != 0.0 else joint.index
        law = cam.program.segments[k].law
        name = law.name if law is not None else "dwell"
        out.append(
            Finding(
                kind="velocity jump",
                severity=Severity.HARD,
                field=f"motion[{k}].law",
                message=(
                    f"motion[{k}].law: {name!r} makes the follower velocity jump by "
                    f"{joint.dv:+.4g} {shown}/rad at {math.degrees(joint.phi):.1f}°, an infinite "
                    "acceleration and a corner in the profile; use a law that starts and ends at rest "
                    "('cycloidal', 'modified-trapezoid', 'modified-sine', 'poly-345')"
                ),
                angle=joint.phi,
                value=joint.dv,
                limit=0.0,
                unit=f"{unit}/rad",
            )
        )
    return out


_REVERSAL_RTOL = 1e-9  # of the segment's mean |ds/dφ|: round-off, not a reversal


def _reversals(cam: Cam) -> list[Finding]:
    """:func:`_find_reversals`, found once per motion program and lift unit (it depends on nothing else)."""
    unit = cam.follower_spec.kind.lift_unit
    return list(cam.program.kept(f"reversals {unit}", lambda: tuple(_find_reversals(cam))))


def _find_reversals(cam: Cam) -> list[Finding]:
    """A soft finding for every rise that runs backwards somewhere (or return that runs forwards).

    Fixed laws never do; a blend polynomial can, when its lift is too small
    for the end velocities its neighbours ask for (it must overshoot to meet
    them), and so can a point table. The worst backward ds/dφ is the true
    extreme: the densest sample refined by bounded minimisation (Brent) on the
    exact motion. A segment that starts (or ends) moving the other way, as a
    return out of a constant-velocity rise must, carries the follower beyond
    its own start (or end): that run is reported too, with the true extreme
    the follower reaches (where ds/dφ = 0, by Brent's method), so the stroke
    beyond the nominal lift is never silent.
    """
    out = []
    program = cam.program
    unit = cam.follower_spec.kind.lift_unit
    shown = "°" if unit == "deg" else unit
    for k, (seg, start) in enumerate(zip(program.segments, program.starts, strict=True)):
        if seg.kind.value not in ("rise", "return") or seg.lift <= 0.0:
            continue
        sense = 1.0 if seg.kind.value == "rise" else -1.0
        x = np.linspace(0.0, 1.0, 2001)
        back = -sense * cam.motion(start + x * seg.span).v  # > 0 where the follower runs backwards
        wrong = back > _REVERSAL_RTOL * seg.lift / seg.span
        # a segment that starts or ends moving the other way (a return out of a constant-velocity
        # rise) runs that way next to that end: reported as an overshoot beyond that end
        inherited = np.zeros_like(wrong)
        for edge, step in ((0, 1), (x.size - 1, -1)):
            i = edge
            while 0 <= i < x.size and wrong[edge] and wrong[i]:
                inherited[i] = True
                i += step
            if wrong[edge]:
                out.append(_overshoot(cam, k, start, seg.span, x, i - step, i, edge == 0, shown))
        back = np.where(wrong & ~inherited, back, 0.0)
        worst = int(np.argmax(back))
        if back[worst] <= 0.0:
            continue
        lo, hi = x[max(worst - 1, 0)], x[min(worst + 1, x.size - 1)]

        def forward(u: float, start: float = start, span: float = seg.span, sense: float = sense) -> float:
            return sense * float(cam.motion(np.array([start + u * span])).v[0])

        from scipy.optimize import minimize_scalar  # here: only a reversal needs it (import costs 0.3 s)

        res = minimize_scalar(forward, bounds=(lo, hi), method="bounded", options={"xatol": 1e-12})
        phi = start + float(res.x) * seg.span
        value = max(-sense * float(res.fun), float(back[worst]))
        span = np.degrees(start + x[back > 0.0] * seg.span)
        out.append(
            Finding(
                kind="motion reversal",
                severity=Severity.SOFT,
                field=f"motion[{k}].lift",
                message=(
                    f"motion[{k}].lift: the {seg.kind.value} runs backwards between {span.min():.1f}° and "
                    f"{span.max():.1f}° (ds/dφ = {-sense * value:+.4g} {shown}/rad at "
                    f"{math.degrees(phi):.1f}°): "
                    "its law must overshoot to meet the velocities of its neighbours; give it more lift or a "
                    "longer angle"
                ),
                angle=phi % TWO_PI,
                value=-sense * value,
                limit=0.0,
                unit=f"{unit}/rad",
            )
        )
    return out


def _overshoot(
    cam: Cam, k: int, start: float, span: float, x: FloatArray, last: int, first: int, head: bool, shown: str
) -> Finding:
    """The finding for segment k running the other way next to one end, out to the turning point.

    ``x[last]`` is the last sample (fraction of the span) of the run from the
    end, ``x[first]`` the first one past it (or off the segment when the run
    covers it all); the turning point, ds/dφ = 0, lies between them and is
    found by Brent's method on the exact motion.
    """
    seg = cam.program.segments[k]
    lo, hi = sorted((float(x[last]), float(x[min(max(first, 0), x.size - 1)])))

    def v(u: float) -> float:
        return float(cam.motion(np.array([start + u * span])).v[0])

    turn = brent_root(v, lo, hi, xtol=1e-13) if v(lo) * v(hi) < 0.0 else (hi if head else lo)
    edge = start if head else start + span
    side: Side = "right" if head else "left"
    s_edge = float(cam.motion(np.array([edge]), side=side).s[0])
    phi = start + turn * span
    s_turn = float(cam.motion(np.array([phi])).s[0])
    beyond = abs(s_turn - s_edge)
    way = "forwards" if seg.kind.value == "return" else "backwards"
    where = "start" if head else "end"
    first_deg, last_deg = sorted((math.degrees(edge), math.degrees(phi)))
    unit = cam.follower_spec.kind.lift_unit
    return Finding(
        kind="motion reversal",
        severity=Severity.SOFT,
        field=f"motion[{k}].lift",
        message=(
            f"motion[{k}].lift: the {seg.kind.value} runs {way} between {first_deg:.1f}° and {last_deg:.1f}° "
            f"at the {where}, carried by the speed it matches there, to {s_turn:.3f} {shown} at "
            f"{math.degrees(phi) % 360.0:.1f}°, {beyond:.3f} {shown} beyond its {where}, outside the "
            "travel its lift states; give the segment more angle or its neighbour a lower end speed"
        ),
        angle=phi % TWO_PI,
        value=beyond,
        limit=0.0,
        unit=unit,
    )


def undercut_error(analysis: GeometryAnalysis, *, min_curvature_radius: float = 0.0) -> UndercutError:
    """The error for an undercut analysis, with the smallest base radius that removes it."""
    cam, uc = analysis.cam, analysis.undercut
    assert uc is not None
    if not cam.closed:  # a linear cam: the base line's height does not change the edge's curvature
        message = (
            f"undercut at {format_ranges(list(uc.ranges))}: the pitch line's convex "
            f"radius of curvature falls to {uc.worst:.3f} mm {uc.where()}, below the "
            f"{cam.follower.words.radius} {cam.roller_radius:g} mm, so the edge loops; lengthen the "
            f"stroke (now {cam.stroke_length:g} mm), {cam.follower.words.smaller} or use a gentler law"
        )
        return UndercutError(
            message,
            phi_range=uc.ranges[0],
            worst=uc.worst,
            suggested_base_radius=None,
            field=Knob.STROKE_LENGTH,
        )
    sized = min_base_radius(cam, min_curvature_radius=min_curvature_radius)
    suggestion = math.ceil(sized.base_radius / _SUGGEST_ROUND_MM) * _SUGGEST_ROUND_MM
    where = format_ranges(list(uc.ranges))
    if cam.has_pitch_curve:
        words = cam.follower.words
        what = (
            f"undercut at {where}: the pitch curve's convex radius of curvature falls to "
            f"{uc.worst:.3f} mm {uc.where()}, below the {words.radius} "
            f"{cam.roller_radius:g} mm, so the profile loops"
        )
        way_out = f"or {words.smaller}"
    else:
        what = (
            f"cusp at {where}: the profile radius of curvature "
            f"{'r_b + s + a ' if cam.follower.guide.pivot is None else ''}falls to "
            f"{uc.worst:.3f} mm {uc.where()}"
        )
        way_out = "or use a gentler motion law"
    message = f"{what}; use base_radius ≥ {suggestion:.2f} mm (now {cam.base_radius:g} mm) {way_out}"
    return UndercutError(
        message,
        phi_range=uc.ranges[0],
        worst=uc.worst,
        suggested_base_radius=suggestion,
        field=Knob.BASE_RADIUS,
    )
