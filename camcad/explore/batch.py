"""Batch analysis: many variants of one design as arrays, the same bytes as analysing them one by one.

A sweep's chunk (or an optimiser's finite-difference stencil) holds designs
that differ only in a few keys: the base radius, the roller radius, the
offset, the spring, the speed. Analysed one by one (:func:`camcad.pipeline.analyse`)
each costs tens of milliseconds, most of it spent by the true-extreme
searches (:mod:`camcad.extremes`) calling the exact cam a few dozen times on
a handful of angles each. Here the variants that share one motion structure
(one motion program, rotation, sample step, follower kind and cam family)
are analysed together:

- the motion on the sample grid is evaluated once for all of them;
- the cam's state (envelope, profile, pressure angle, contact) on the grid
  is evaluated on the (variants × angles) stack, the follower's
  parameters as one value per stacked angle (:class:`_FollowerStack`), a
  block of :data:`_GRID_BLOCK` variants at a time (arrays that stay in the
  processor's cache);
- the geometry's and the dynamics' true extremes of all variants are found
  by one search (:func:`camcad.extremes.extremes_stacked`) whose rows are
  the variants' rows, each refinement step one call of the stacked cam;
  the lubricant film's smallest ratio and the track's largest load-stress
  factor (``[lubrication]``, ``[life]``) by a second one (:func:`_duty_answers`);
- the laws' VDI 2143 values (``[drive]``), which depend on the motion
  program alone, are computed once for the group;
- then each variant is analysed by the ordinary stages, its grid state
  handed to its cam (:meth:`camcad.geometry.cam.Cam.keep_state`) and its
  searches answered from the batch (:func:`camcad.extremes.served`).

Why the bytes are the same: every step of the search is elementwise per
row and per bracket, the quantities are the same functions evaluated
elementwise on the same angles (a parameter as one value per angle instead
of one scalar gives the same IEEE products and sums; what a follower derives
from its parameters with scalar library math, such as an arm's pivot and
initial angle, is each variant's own property, read on its follower), and an
analysis takes a batch answer only when the samples it computed itself are
bit-for-bit the ones the batch searched from; any other search runs as usual.
Variants of another structure, other families (groove, conjugate pair,
linear cam), a ``[vibration]`` table, or a follower whose non-numeric
parameters differ are analysed one by one (:func:`analyse_one`).
"""

from __future__ import annotations

import copy
import types
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, fields, is_dataclass, replace
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from camcad._typing import FloatArray, readonly
from camcad.errors import CamcadError
from camcad.explore.measures import Limit, analysis_row, failed_row
from camcad.explore.space import Variable, design_with

if TYPE_CHECKING:
    from camcad.analysis import Analysis
    from camcad.design import Design
    from camcad.extremes import Extreme, Kind, Side
    from camcad.geometry.cam import Cam, CamState
    from camcad.geometry.curves import CurveSample
    from camcad.motion.program import Motion

__all__ = ["BatchStats", "analyse_many", "analyse_one", "analyse_rows", "chunk_rows", "structure_key"]


@dataclass(slots=True)
class BatchStats:
    """How a batch went: variants analysed in batches, one by one, and searches answered by a batch."""

    batched: int = 0
    single: int = 0
    served: int = 0
    searches: int = 0


def analyse_one(design: Design) -> Analysis:
    """The per-design analysis a sweep row is made from (as ``camcad check``: no fit, toolpath, strict)."""
    from camcad.pipeline import analyse

    return analyse(design, fit=False, toolpath=False, strict=False)


def structure_key(design: Design) -> str | None:
    """What variants must share to be analysed together; None for a design analysed one by one.

    The motion program's segments, the rotation, the sample step, the
    follower kind and the cam style; a design with ``[vibration]`` (whose
    compensated lift would change the program) is analysed alone. A family
    of more than one part (a conjugate pair) or an open profile (a linear
    cam) is found out when the group is built, and analysed one by one.
    """
    if design.vibration is not None:
        return None
    cam = design.cam
    return repr((design.motion, cam.rotation, cam.sample_step, cam.style, design.follower.kind))


class _Unsupported(Exception):
    """A group the stacked cam cannot evaluate: its variants are analysed one by one."""


def _equal(values: Sequence[Any]) -> bool:
    first = values[0]
    try:
        return all(bool(v == first) for v in values[1:])
    except (TypeError, ValueError):  # arrays: not one value
        return False


def _number(value: Any) -> bool:
    return isinstance(value, (float, int)) and not isinstance(value, bool)


def _numbers(values: Sequence[Any]) -> bool:
    """Whether the values are all numbers: one array element each."""
    return all(_number(v) for v in values)


def _tuples(values: Sequence[Any]) -> bool:
    """Whether the values are all tuples of as many numbers (a point, two offsets): one array row each."""
    first = values[0]
    return (
        isinstance(first, tuple)
        and bool(first)
        and all(isinstance(v, tuple) and len(v) == len(first) and all(_number(x) for x in v) for v in values)
    )


class _FollowerStack:
    """Many followers of one class as one: each numeric parameter an array, one value per stacked angle.

    The follower's own methods (its element, its contact position) run on
    it unchanged; a property is read on every variant's follower (so a
    derived value such as k = √((r_b + r_f)² − e²), or an arm's pivot and
    initial angle, is each variant's own scalar, computed as in a single
    analysis) and stacked: a number as (V,) values, a point such as the
    pivot as (V, 2), a dataclass such as the guide as :class:`_Stacked`.
    Any other attribute that differs between the variants is
    :class:`_Unsupported`.
    """

    def __init__(self, followers: Sequence[Any]) -> None:
        cls = type(followers[0])
        if any(type(f) is not cls for f in followers):
            raise _Unsupported("mixed follower kinds")
        methods: dict[str, Any] = {}
        self.constant: dict[str, Any] = {}
        self.varying: dict[str, FloatArray] = {}
        self.nested: dict[str, _Stacked] = {}
        for klass in reversed(cls.__mro__[:-1]):
            for name, obj in vars(klass).items():
                if name.startswith("__"):
                    continue
                if isinstance(obj, (property, types.MemberDescriptorType)):
                    try:
                        values = [getattr(f, name) for f in followers]
                    except Exception:  # a property this kind does not have: left out
                        continue
                    if _equal(values):
                        self.constant[name] = values[0]
                    elif _numbers(values) or _tuples(values):  # the pivot: (V, 2), an (m, 2) array at angles
                        self.varying[name] = np.array(values, dtype=float)
                    elif is_dataclass(values[0]):
                        self.nested[name] = _Stacked.of(values, points=True)
                    else:
                        raise _Unsupported(f"the follower's {name} differs between the variants")
                elif isinstance(obj, (types.FunctionType, staticmethod, classmethod)):
                    methods[name] = obj
        self.view_class = type(f"_{cls.__name__}Stack", (), methods)

    def at(self, which: np.ndarray) -> Any:
        """The stacked follower for angles of the variants ``which`` (one index per angle)."""
        view: Any = object.__new__(self.view_class)
        view.__dict__.update(self.constant)
        for name, values in self.varying.items():
            setattr(view, name, values[which])
        for name, inner in self.nested.items():
            setattr(view, name, inner.at(which))
        return view


@dataclass(frozen=True, slots=True)
class _Stacked:
    """Many frozen dataclasses of one type as one: a differing number becomes one value per stacked angle.

    ``varying`` holds each differing numeric field's values over the variants
    (V,), ``tuples`` each differing tuple-of-numbers field's (V, k), ``nested``
    the differing dataclass fields; equal fields are the first object's. At
    the angles a tuple becomes a tuple of k arrays, one value per angle each,
    so that its items (a groove's flank offsets) index and unpack as the
    scalar code does; with ``points`` (a follower's guide, whose code reads its
    pivot as an array) it becomes one (m, k) array. A differing field of
    another type is :class:`_Unsupported`.
    """

    first: Any
    varying: Mapping[str, FloatArray]
    tuples: Mapping[str, FloatArray]
    nested: Mapping[str, _Stacked]
    points: bool

    @staticmethod
    def of(objects: Sequence[Any], *, points: bool = False) -> _Stacked:
        first = objects[0]
        if not is_dataclass(first) or any(type(o) is not type(first) for o in objects):
            raise _Unsupported("not one dataclass")
        varying: dict[str, FloatArray] = {}
        tuples: dict[str, FloatArray] = {}
        nested: dict[str, _Stacked] = {}
        for f in fields(first):
            values = [getattr(o, f.name) for o in objects]
            if _equal(values):
                continue
            if _numbers(values):
                varying[f.name] = np.array(values, dtype=float)
            elif _tuples(values):
                tuples[f.name] = np.array(values, dtype=float)
            elif is_dataclass(values[0]):
                nested[f.name] = _Stacked.of(values, points=points)
            else:
                raise _Unsupported(f"{f.name} differs between the variants")
        return _Stacked(first=first, varying=varying, tuples=tuples, nested=nested, points=points)

    def at(self, which: np.ndarray) -> Any:
        """The object with each differing number the value of variant ``which[i]`` at stacked angle i."""
        out = copy.copy(self.first)
        for name, values in self.varying.items():
            object.__setattr__(out, name, values[which])  # frozen: set as its own constructor would
        for name, rows in self.tuples.items():
            picked = rows[which]
            value = picked if self.points else tuple(picked[:, j] for j in range(picked.shape[1]))
            object.__setattr__(out, name, value)
        for name, inner in self.nested.items():
            object.__setattr__(out, name, inner.at(which))
        return out


def _offset(base: CurveSample, drho: FloatArray, delta: float | FloatArray) -> CurveSample:
    """:func:`camcad.geometry.envelope.offset_curve` with one offset per angle (the same operations)."""
    from camcad.geometry.curves import CurveSample
    from camcad.geometry.envelope import offset_curve

    if np.ndim(delta) == 0:
        return offset_curve(base, drho, float(delta))
    d = np.asarray(delta, dtype=float)
    rho = base.rho
    with np.errstate(divide="ignore", invalid="ignore"):
        stretch = np.where(np.isinf(rho), 1.0, 1.0 + d / rho)
        bend = np.where(np.isinf(rho), 0.0, d * drho / rho**2)
    return CurveSample(
        phi=base.phi,
        point=base.point + d[:, None] * base.normal,
        d1=base.d1 * stretch[:, None],
        d2=base.d2 * stretch[:, None] - base.d1 * bend[:, None],
        tangent=base.tangent,
        normal=base.normal,
        rho=rho + d,
    )


class _Loop:
    """The one thing :func:`~camcad.geometry.limits.geometry_rows` asks the cam: its undercut quantity."""

    def __init__(self, has_pitch_curve: bool) -> None:
        self.has_pitch_curve = has_pitch_curve

    def loop_radius(self, state: CamState) -> FloatArray:
        from camcad.geometry.cam import Cam

        return Cam.loop_radius(cast(Cam, self), state)


def _take(motion: Motion, index: np.ndarray | slice) -> Motion:
    return replace(motion, **{f.name: getattr(motion, f.name)[index] for f in fields(motion)})


def _tile(motion: Motion, times: int) -> Motion:
    out = replace(motion, **{f.name: np.tile(getattr(motion, f.name), times) for f in fields(motion)})
    readonly(*(getattr(out, f.name) for f in fields(out)))
    return out


@dataclass(slots=True)
class _Group:
    """Variants of one structure: their designs and cams, the stacked follower, the shared grid."""

    designs: list[Design]
    cams: list[Cam]
    stack: _FollowerStack
    sigma: float
    pitch: bool
    phi: FloatArray
    grid_motion: Motion
    drive_signs: list[float]

    @property
    def size(self) -> int:
        return len(self.cams)

    def motion(self, phi: FloatArray, side: Side) -> Motion:
        return self.cams[0].program.evaluate(phi, side=side)

    def state(self, motion: Motion, which: np.ndarray) -> CamState:
        """The cam's state of variant ``which[i]`` at ``motion.phi[i]``, as :meth:`Cam.state` computes it."""
        from camcad.geometry.cam import CamState
        from camcad.geometry.envelope import (
            PointElement,
            line_envelope,
            point_envelope,
            pressure_angle,
            to_cam,
        )

        fol = self.stack.at(which)
        element = fol.element(motion)
        if isinstance(element, PointElement):
            base, drho = point_envelope(motion.phi, element, self.sigma)
            profile = _offset(base, drho, -fol.roller_radius)
            driven = base.point
        else:
            base, drho = line_envelope(motion.phi, element, self.sigma)
            profile = base
            driven = profile.point
        guide = fol.guide
        turned = np.asarray(motion.phi, dtype=float)
        driven_machine = to_cam(turned, np.asarray(driven, dtype=float), -self.sigma)
        alpha = pressure_angle(turned, profile.normal, driven_machine, guide, self.sigma)
        contact = to_cam(turned, np.asarray(profile.point, dtype=float), -self.sigma)
        lever = None
        if guide.pivot is not None:
            arm = driven_machine - np.asarray(guide.pivot)
            lever = np.hypot(arm[:, 0], arm[:, 1])
        position = fol.contact_position(contact, motion)
        return CamState(
            lever=lever,
            motion=motion,
            base=base,
            profile=profile,
            pressure_angle=alpha,
            contact_position=position,
        )


def _group(designs: list[Design]) -> _Group:
    from camcad.geometry.cam import Cam, follower_from_spec
    from camcad.geometry.families import family_of

    # the followers first: a group whose followers cannot be stacked (a non-numeric parameter that
    # differs) is refused before anything else is built
    _FollowerStack([follower_from_spec(d.follower, d.cam.base_radius) for d in designs])
    first = Cam.from_design(designs[0])
    cams = [first] + [replace(Cam.from_design(d), program=first.program) for d in designs[1:]]
    signs = []
    for d, c in zip(designs, cams, strict=True):
        parts = family_of(d.cam.style).parts(c, d.family_options())
        if len(parts) != 1 or parts[0].cam is not c:
            raise _Unsupported("a family of more than one part")
        signs.append(parts[0].drive_sign)
    stack = _FollowerStack([c.follower for c in cams])
    pitch = {c.has_pitch_curve for c in cams}
    if len(pitch) != 1 or any(not c.closed for c in cams):
        raise _Unsupported("mixed contact kinds")
    phi = cams[0].sample_phi()
    return _Group(
        designs=designs,
        cams=cams,
        stack=stack,
        sigma=cams[0].sigma,
        pitch=pitch.pop(),
        phi=phi,
        grid_motion=cams[0].motion(phi),
        drive_signs=signs,
    )


def _state_slice(state: CamState, lo: int, hi: int) -> CamState:
    """The rows lo … hi − 1 of a stacked state (one variant's grid)."""
    return _state_take(state, slice(lo, hi))


def _state_take(state: CamState, index: np.ndarray | slice) -> CamState:
    """The rows ``index`` of a stacked state."""

    def curve(c: CurveSample) -> CurveSample:
        return replace(c, **{f.name: getattr(c, f.name)[index] for f in fields(c)})

    return replace(
        state,
        motion=_take(state.motion, index),
        base=curve(state.base),
        profile=curve(state.profile),
        pressure_angle=state.pressure_angle[index],
        contact_position=state.contact_position[index],
        lever=None if state.lever is None else state.lever[index],
    )


_GRID_BLOCK = 8
"""Variants whose grid state and rows are evaluated together (in blocks: their arrays stay in cache)."""


@dataclass(frozen=True, slots=True)
class _Block:
    """Variants first … first + count − 1 on their stacked grid: its angles, their variant, the state."""

    first: int
    count: int
    phi: FloatArray
    which: np.ndarray
    state: CamState


def _by_variant(values: FloatArray, k: int, nv: int, m: int) -> FloatArray:
    """(k, V·m) k rows at the angles of V variants in turn → (V·k, m), variant after variant."""
    out: FloatArray = values.reshape(k, nv, m).transpose(1, 0, 2).reshape(nv * k, m)
    return out


def _block_rows(blocks: Sequence[_Block], rows: Any, k: int, nv: int, n: int) -> FloatArray:
    """(V·k, n) the k grid rows of every variant, variant after variant, ``rows(block)`` (k, count·n) each."""
    out = np.empty((nv, k, n))
    for b in blocks:
        out[b.first : b.first + b.count] = np.reshape(rows(b), (k, b.count, n)).transpose(1, 0, 2)
    return out.reshape(nv * k, n)


Answer = tuple[
    FloatArray,
    FloatArray,
    tuple["Kind", ...],
    FloatArray,
    tuple[tuple[float, float], ...],
    tuple[bool, ...],
    tuple["Extreme", ...],
]
"""A search done ahead: grid, joints, kinds, sampled values, rests, settled rows, the extremes found."""


def _searches(group: _Group) -> tuple[list[CamState], list[list[Answer]]]:
    """Every variant's grid state and the answers of its geometry and dynamics searches."""
    from camcad.dynamics.model import dynamics_rows, extreme_rows
    from camcad.extremes import extremes_stacked
    from camcad.geometry.cam import Cam
    from camcad.geometry.envelope import keep_turn
    from camcad.geometry.limits import GEOMETRY_KINDS, geometry_rows

    nv, n = group.size, group.phi.size
    loop = cast(Cam, _Loop(group.pitch))
    joints = np.array([bp.phi for bp in group.cams[0].program.breakpoints], dtype=float)
    rests = group.cams[0].rests
    # the grid state of _GRID_BLOCK variants at a time (arrays that stay in the processor's cache), each
    # block's stacked grid one tiled motion, turned by the grid's own cos and sin
    turn = {
        sigma: (np.cos(sigma * group.phi), np.sin(sigma * group.phi)) for sigma in (group.sigma, -group.sigma)
    }
    tiles: dict[int, Motion] = {}
    blocks: list[_Block] = []
    for v0 in range(0, nv, _GRID_BLOCK):
        count = min(_GRID_BLOCK, nv - v0)
        tiled = tiles.setdefault(count, _tile(group.grid_motion, count))
        for sigma, (cos, sin) in turn.items():
            keep_turn(tiled.phi, sigma, np.tile(cos, count), np.tile(sin, count))
        which = np.repeat(np.arange(v0, v0 + count), n)
        blocks.append(
            _Block(first=v0, count=count, phi=tiled.phi, which=which, state=group.state(tiled, which))
        )
    states = [_state_slice(b.state, i * n, (i + 1) * n) for b in blocks for i in range(b.count)]

    def stacked_at(p: FloatArray, which: np.ndarray, side: Side) -> CamState:
        return group.state(group.motion(p, side), which)

    # dynamics: variants with equal setups share one model; different ones, one model of stacked parameters
    setups = [
        replace(d.dynamics_setup(), drive_sign=sign, roller_radius=c.roller_radius)
        for d, c, sign in zip(group.designs, group.cams, group.drive_signs, strict=True)
    ]
    models: list[tuple[Any, list[int]]] = []
    for v, s in enumerate(setups):
        for held in models:
            if held[0][0] == s:
                held[1].append(v)
                break
        else:
            models.append(((s, extreme_rows(s)), [v]))
    kinds = models[0][0][1][0]
    if any(m[0][1][0] != kinds for m in models):
        raise _Unsupported("mixed dynamics rows")
    kd = len(kinds)
    owner = np.empty(nv, dtype=int)
    for g, (_, members) in enumerate(models):
        owner[members] = g
    stacked_setup = _Stacked.of(setups) if len(models) > 1 else None

    def drows(st: CamState, which: np.ndarray) -> FloatArray:
        """(kd, m) each angle's rows of its own variant's model."""
        nonlocal stacked_setup
        if stacked_setup is not None:
            try:  # one model, each parameter one value per angle
                rows = dynamics_rows(stacked_setup.at(which))
                return np.asarray(rows(st.motion, st.pressure_angle, st.profile.rho, st.lever), dtype=float)
            except (TypeError, ValueError, AttributeError):  # the model takes a parameter as a scalar
                stacked_setup = None
        out = np.empty((kd, which.size))
        for g, ((_, (_, _, rows)), _) in enumerate(models):
            mine = np.flatnonzero(owner[which] == g)
            if mine.size == which.size:
                return np.asarray(rows(st.motion, st.pressure_angle, st.profile.rho, st.lever), dtype=float)
            if mine.size:
                lever = None if st.lever is None else st.lever[mine]
                out[:, mine] = rows(
                    _take(st.motion, mine), st.pressure_angle[mine], st.profile.rho[mine], lever
                )
        return out

    # one search for both stages: variant v's rows are v·k … v·k + k − 1, its geometry's 8 then its
    # dynamics' (each row's search is its own, so stacking them changes nothing but the number of calls)
    kg = len(GEOMETRY_KINDS)
    k = kg + kd

    def both(st: CamState, which: np.ndarray) -> FloatArray:
        """(k, m) every row at each angle, of the angle's own variant."""
        return np.vstack((geometry_rows(loop, st), drows(st, which)))

    def by_variant(values: FloatArray, m: int) -> FloatArray:
        """(k, V·m) rows of the variants' angles in turn → (V·k, m), variant after variant."""
        return _by_variant(values, k, nv, m)

    values = _block_rows(blocks, lambda b: both(b.state, b.which), k, nv, n)

    def quantity(p: FloatArray, side: Side) -> FloatArray:
        m = p.size
        which = np.repeat(np.arange(nv), m)
        return by_variant(both(stacked_at(np.tile(p, nv), which, side), which), m)

    def pick(p: FloatArray, rows: np.ndarray, side: Side) -> FloatArray:
        which = rows // k
        out: FloatArray = both(stacked_at(p, which, side), which)[rows % k, np.arange(p.size)]
        return out

    settled: list[bool] = []
    for v in range(nv):
        settled += [False] * kg + list(models[owner[v]][0][1][1])
    found = extremes_stacked(
        quantity,
        pick,
        group.phi,
        joints,
        (GEOMETRY_KINDS + kinds) * nv,
        values=values,
        rests=rests,
        settled=settled,
    )
    answers: list[list[Answer]] = []
    for v in range(nv):
        lo, mid, hi = v * k, v * k + kg, (v + 1) * k
        answers.append(
            [
                (group.phi, joints, GEOMETRY_KINDS, values[lo:mid], rests, (), found[lo:mid]),
                (group.phi, joints, kinds, values[mid:hi], rests, models[owner[v]][0][1][1], found[mid:hi]),
            ]
        )
    for mine, more in zip(answers, _duty_answers(group, setups, blocks, joints), strict=True):
        mine += more
    return states, answers


def _duty_answers(
    group: _Group, setups: Sequence[Any], blocks: Sequence[_Block], joints: FloatArray
) -> list[list[Answer]]:
    """The answers of each variant's film and track searches (:func:`~camcad.dynamics.duty.analyse_duty`).

    The lubricant film's smallest ratio λ and the track's largest load-stress
    factor are searched on the exact cam as the geometry's and the dynamics'
    extremes are: one stacked search for all the variants, its quantity
    :func:`~camcad.dynamics.duty.film_ratio_of` and
    :func:`~camcad.dynamics.duty.track_factor_of` of
    :func:`~camcad.dynamics.duty.carried_in_state` with the stacked cam and
    setup. Empty where the designs have neither (or not all of them the same).
    """
    from camcad.dynamics.contact import effective_modulus
    from camcad.dynamics.duty import carried_in_state, film_ratio_of, track_factor_of
    from camcad.extremes import extremes_stacked

    nv, n = group.size, group.phi.size
    designs = group.designs
    film = all(d.lubrication is not None for d in designs)
    track = all(d.life is not None and d.life.track is not None for d in designs)
    if not (film or track):
        return [[] for _ in designs]
    kinds: tuple[Kind, ...] = ()
    if film:
        kinds += ("min",)
    if track:
        kinds += ("max",)
    kq = len(kinds)
    lubrications = [d.lubrication for d in designs]
    moduli = [
        effective_modulus(
            modulus_1=s.spec.cam_modulus,
            poisson_1=s.spec.cam_poisson,
            modulus_2=s.spec.follower_modulus,
            poisson_2=s.spec.follower_poisson,
        )
        for s in setups
    ]
    # variants with equal setups, lubricants and moduli share one evaluation; different ones, one of
    # stacked parameters (each one value per angle), or, where a function takes a parameter as a
    # scalar, one evaluation per kind of variant on its own angles
    keys: list[tuple[Any, Any, float]] = []
    owner = np.empty(nv, dtype=int)
    for v, key in enumerate(zip(setups, lubrications, moduli, strict=True)):
        for g, held in enumerate(keys):
            if held == key:
                owner[v] = g
                break
        else:
            owner[v] = len(keys)
            keys.append(key)
    stacked: list[Any] = [None]
    if len(keys) > 1:
        stacked[0] = (
            _Stacked.of(setups).at,
            _Stacked.of(lubrications).at if film else None,
            np.array(moduli, dtype=float).__getitem__,
        )

    def evaluate(p: FloatArray, st: CamState, which: np.ndarray, side: Side, at: Any) -> FloatArray:
        setup_at, lubrication_at, modulus_at = at
        view = replace(group.cams[0])  # the cam, its follower the stacked one
        view._memo["follower"] = group.stack.at(which)
        setup = setup_at(which)
        carried = carried_in_state(view, p, st, setup=setup, side=side)
        out = []
        if film:
            out.append(
                film_ratio_of(carried, setup=setup, spec=lubrication_at(which), modulus=modulus_at(which))
            )
        if track:
            out.append(track_factor_of(carried, setup=setup))
        return np.vstack(out)

    def rows(p: FloatArray, st: CamState, which: np.ndarray, side: Side) -> FloatArray:
        """(kq, m) the film ratio and/or track factor at each angle, of the angle's own variant."""
        if stacked[0] is not None:
            try:
                return evaluate(p, st, which, side, stacked[0])
            except (TypeError, ValueError, AttributeError):  # a function takes a parameter as a scalar
                stacked[0] = None
        out = np.empty((kq, p.size))
        for g, (setup, lubrication, modulus) in enumerate(keys):
            mine = np.flatnonzero(owner[which] == g)
            at = (lambda w, s=setup: s, lambda w, lub=lubrication: lub, lambda w, e=modulus: e)
            if mine.size == p.size:
                return evaluate(p, st, which, side, at)
            if mine.size:
                out[:, mine] = evaluate(p[mine], _state_take(st, mine), which[mine], side, at)
        return out

    values = _block_rows(blocks, lambda b: rows(b.phi, b.state, b.which, "right"), kq, nv, n)

    def quantity(p: FloatArray, side: Side) -> FloatArray:
        m = p.size
        which = np.repeat(np.arange(nv), m)
        tiled = np.tile(p, nv)
        return _by_variant(rows(tiled, group.state(group.motion(tiled, side), which), which, side), kq, nv, m)

    def pick(p: FloatArray, which_rows: np.ndarray, side: Side) -> FloatArray:
        which = which_rows // kq
        got = rows(p, group.state(group.motion(p, side), which), which, side)
        out: FloatArray = got[which_rows % kq, np.arange(p.size)]
        return out

    found = extremes_stacked(quantity, pick, group.phi, joints, kinds * nv, values=values)
    return [
        [
            (
                group.phi,
                joints,
                (kind,),
                values[v * kq + q : v * kq + q + 1],
                (),
                (),
                found[v * kq + q : v * kq + q + 1],
            )
            for q, kind in enumerate(kinds)
        ]
        for v in range(nv)
    ]


def _assemble(design: Design, cam: Cam, characteristics: Any = None) -> Analysis:
    """:func:`analyse_one` for a plate cam whose grid state and searches are at hand (the same stages)."""
    from camcad.analysis import Analysis, PartResult
    from camcad.dynamics import analyse_dynamics
    from camcad.geometry import analyse_geometry
    from camcad.geometry.families import family_of

    family = family_of(design.cam.style)
    parts = family.parts(cam, design.family_options())
    geometries = [
        analyse_geometry(
            part.cam,
            max_pressure_angle=design.cam.max_pressure_angle,
            face_width=design.follower.face_width,
            face_margin=design.follower.face_margin,
            min_curvature_radius=design.min_curvature_radius,
        )
        for part in parts
    ]
    motion = cam.motion(geometries[0].phi)
    setup = design.dynamics_setup()
    dynamics = [
        analyse_dynamics(
            part.cam.motion(g.phi),
            pressure_angle=g.pressure_angle,
            profile_rho=g.profile.rho,
            setup=replace(setup, drive_sign=part.drive_sign, roller_radius=part.cam.roller_radius),
            cam=part.cam,
        )
        for part, g in zip(parts, geometries, strict=True)
    ]
    results = [
        PartResult(part=part, geometry=g, dynamics=d)
        for part, g, d in zip(parts, geometries, dynamics, strict=True)
    ]
    drive = None
    if design.life is not None or design.lubrication is not None or design.drive is not None:
        from camcad.pipeline import part_duties  # the same per-part life, film and train drive

        results, drive = part_duties(design, cam, results, characteristics=characteristics)
    return Analysis(
        design=design, family=family, parts=tuple(results), motion=motion, toolpath=None, drive=drive
    )


Row = dict[str, Any]


def analyse_many(
    designs: Sequence[Design],
    *,
    batch: bool = True,
    stats: BatchStats | None = None,
) -> list[Analysis | CamcadError]:
    """Each design's analysis (as :func:`analyse_one`), or the error it raised, in order.

    With ``batch`` the designs of one structure (:func:`structure_key`) are
    analysed together (see the module notes), the others one by one; every
    analysis is the same either way, to the bit.
    """
    stats = stats if stats is not None else BatchStats()
    out: list[Analysis | CamcadError | None] = [None] * len(designs)
    groups: dict[str, list[int]] = {}
    for i, d in enumerate(designs):
        key = structure_key(d) if batch else None
        if key is None:
            out[i] = _single(d)
            stats.single += 1
        else:
            groups.setdefault(key, []).append(i)
    for members in groups.values():
        done = _batched([designs[i] for i in members], stats) if len(members) > 1 else None
        if done is None:
            for i in members:
                out[i] = _single(designs[i])
            stats.single += len(members)
            continue
        for i, got in zip(members, done, strict=True):
            out[i] = got
        stats.batched += len(members)
    return [a for a in out if a is not None]


def analyse_rows(
    designs: Sequence[Design | CamcadError],
    limits: Sequence[Limit] = (),
    *,
    batch: bool = True,
    stats: BatchStats | None = None,
) -> list[Row]:
    """The sweep row (:func:`~camcad.explore.measures.analysis_row`) of each design, in order.

    A design given as the error its variant raised becomes its failed row;
    the rows are the same bytes with ``batch`` on or off.
    """
    from camcad.analysis import Analysis

    valid = [d for d in designs if not isinstance(d, CamcadError)]
    analysed = iter(analyse_many(valid, batch=batch, stats=stats))
    rows: list[Row] = []
    for d in designs:
        got = d if isinstance(d, CamcadError) else next(analysed)
        rows.append(analysis_row(got, limits) if isinstance(got, Analysis) else failed_row(got, limits))
    return rows


def _single(design: Design) -> Analysis | CamcadError:
    try:
        return analyse_one(design)
    except CamcadError as err:
        return err


def _batched(designs: list[Design], stats: BatchStats) -> list[Analysis | CamcadError] | None:
    """One structure's designs analysed together; None where the stacked cam cannot."""
    from camcad.analysis import motion_summary
    from camcad.extremes import served

    try:
        with np.errstate(all="ignore"):
            group = _group(designs)
            states, answers = _searches(group)
    except (_Unsupported, CamcadError, ValueError, TypeError, AttributeError, IndexError):
        return None
    out: list[Analysis | CamcadError] = []
    shared: Any = None
    characteristics = None
    if any(d.drive is not None for d in designs):  # the laws' VDI 2143 values: of the one motion program
        from camcad.dynamics.drive import segment_characteristics

        characteristics = segment_characteristics(group.cams[0].program)
    for design, cam, state, mine in zip(designs, group.cams, states, answers, strict=True):
        cam.keep_state(group.phi, replace(state, motion=group.grid_motion))
        with served(mine) as held:
            try:
                analysis = _assemble(design, cam, characteristics)
            except CamcadError as err:
                out.append(err)
                continue
        stats.served += held.used
        stats.searches += len(mine)
        if shared is None:  # one program and lift unit: one motion summary (summary() hands out copies)
            shared = motion_summary(analysis.cam, analysis.motion)
        analysis._memo["motion"] = shared
        out.append(analysis)
    return out


def chunk_rows(
    data: Mapping[str, Any],
    variables: Sequence[Variable],
    points: Sequence[Sequence[Any]],
    *,
    limits: Sequence[Limit] = (),
    source: str = "",
    batch: bool = True,
    stats: BatchStats | None = None,
) -> list[Row]:
    """Each point's sweep row: its inputs, then its analysis row (a refused variant: its reason)."""
    designs: list[Design | CamcadError] = []
    for values in points:
        try:
            designs.append(design_with(data, variables, values, source=source))
        except CamcadError as err:
            designs.append(err)
    out = analyse_rows(designs, limits, batch=batch, stats=stats)
    return [
        {v.name: value for v, value in zip(variables, values, strict=True)} | row
        for values, row in zip(points, out, strict=True)
    ]
