"""Batch analysis (issue 38): variants analysed together give the bytes of each analysed alone.

The independent truth is the per-design analysis itself
(:func:`camcad.pipeline.analyse`, as ``camcad check`` runs it): for random
variants of every follower kind the batch's sweep rows (every summary
figure, the findings' messages, the verdicts) must be equal, as JSON text,
to the rows of the designs analysed one at a time; a sweep's CSV must be
the same bytes with batching on and off; variants of different motion
structures in one chunk fall back and still match. The stacked search's
bracket finder is checked against a plain transcription of its rule.
"""

from __future__ import annotations

import functools
import json
import math
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from camcad.errors import CamcadError
from camcad.explore.batch import BatchStats, analyse_rows, chunk_rows
from camcad.explore.measures import MEASURES, analysis_row, failed_row, parse_limit
from camcad.explore.space import design_with, grid_points, parse_variable
from camcad.explore.sweep import SweepPlan, sweep
from camcad.pipeline import analyse
from tests.explore.cases import sample_data


def _one_at_a_time(data: dict[str, Any], variables: list[Any], points: list[tuple[Any, ...]], limits=()):
    """Each point's row from its own `analyse` call (the per-design truth)."""
    rows = []
    for values in points:
        row: dict[str, Any] = {v.name: x for v, x in zip(variables, values, strict=True)}
        try:
            design = design_with(data, variables, values)
            row |= analysis_row(analyse(design, fit=False, toolpath=False, strict=False), limits)
        except CamcadError as err:
            row |= failed_row(err, limits)
        rows.append(row)
    return rows


def _text(rows: list[dict[str, Any]]) -> list[str]:
    return [json.dumps(r, sort_keys=False, default=repr) for r in rows]


def _mushroom() -> dict[str, Any]:
    data = sample_data("offset_roller")
    data["follower"] = {"type": "translating-mushroom", "face_radius": 60.0, "offset": 5.0}
    return data


# follower kind or family → (design mapping, the variables drawn, whether the batch must take the variants)
KINDS: dict[str, tuple[Any, tuple[str, ...], bool]] = {
    "translating-roller": (
        lambda: sample_data("offset_roller"),
        ("base_radius", "offset", "roller_radius", "spring_rate", "speed_rpm"),
        True,
    ),
    "translating-flat": (lambda: sample_data("hren_tappet"), ("base_radius", "speed_rpm"), True),
    "translating-mushroom": (_mushroom, ("base_radius", "offset", "follower_mass"), True),
    # an arm's pivot and initial angle move with the base radius, the pivot distance, the arm, the roller
    "oscillating-roller": (
        lambda: sample_data("packaging_rocker"),
        ("base_radius", "pivot_distance", "roller_radius", "arm_length", "speed_rpm"),
        True,
    ),
    "oscillating-flat": (
        lambda: sample_data("rocker_flat"),
        ("base_radius", "pivot_distance", "face_offset", "speed_rpm"),
        True,
    ),
    # the families: a groove is one part (its flanks' loads and stresses among the searched rows); a
    # conjugate pair has two plates and a linear cam an open profile: both analysed one by one
    "groove": (lambda: sample_data("groove_rocker"), ("base_radius", "speed_rpm", "arm_inertia"), True),
    "conjugate pair": (lambda: sample_data("indexing_conjugate"), ("speed_rpm",), False),
    "linear cam": (lambda: sample_data("linear_cam"), ("speed_rpm",), False),
}

_SCALE = st.floats(min_value=0.85, max_value=1.25, allow_nan=False)


def _value(data: dict[str, Any], name: str, scale: float) -> float:
    table = {"base_radius": "cam", "speed_rpm": "cam"}
    table |= dict.fromkeys(
        ("offset", "roller_radius", "pivot_distance", "arm_length", "face_offset"), "follower"
    )
    base = data.get(table.get(name, "dynamics"), {}).get(name)
    if base is None or base == 0:
        base = {"offset": 4.0, "spring_rate": 2.0, "follower_mass": 0.5}.get(name, 1.0)
    return float(base) * scale


@pytest.mark.parametrize("kind", list(KINDS))
@settings(max_examples=4, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scales=st.lists(st.lists(_SCALE, min_size=5, max_size=5), min_size=3, max_size=3))
def test_batch_rows_equal_one_at_a_time(kind: str, scales: list[list[float]]) -> None:
    """Random variants of each follower kind: the batch's rows are the per-design rows, every byte."""
    make, names, batched = KINDS[kind]
    data = make()
    variables = [
        parse_variable(
            f"{n}={_value(data, n, 0.85)!r}:{_value(data, n, 1.25)!r}", data, flag="--vary", counted=False
        )
        for n in names
    ]
    points = [tuple(_value(data, n, s) for n, s in zip(names, row, strict=False)) for row in scales]
    limits = (parse_limit("contact_stress<=900"),)
    stats = BatchStats()
    got = chunk_rows(data, variables, points, limits=limits, stats=stats)
    assert _text(got) == _text(_one_at_a_time(data, variables, points, limits))
    valid = sum(not isinstance(_design_or_error(data, variables, values), CamcadError) for values in points)
    if batched and valid > 1:  # (an arm too short for its pivot is refused by the loader, as alone)
        assert stats.batched == valid, stats  # the batch path ran, not the fall-back
        assert stats.served == stats.searches > 0, stats  # every search answered by the stacked one


def _design_or_error(data: dict[str, Any], variables: list[Any], values: tuple[Any, ...]) -> Any:
    try:
        return design_with(data, variables, values)
    except CamcadError as err:
        return err


def test_sweep_csv_same_bytes_with_batching_on_and_off(tmp_path) -> None:
    """A whole sweep (base radius × offset, chunks of 5, an extra limit) writes the same CSV both ways."""
    data = sample_data("offset_roller")
    variables = tuple(
        parse_variable(g, data, flag="--grid", counted=True) for g in ("base_radius=40:90:4", "offset=0:25:3")
    )
    out = {}
    for batch in (True, False):
        plan = SweepPlan(
            data=data,
            source="offset_roller.toml",
            variables=variables,
            points=tuple(grid_points(variables)),
            limits=(parse_limit("torque<=3100"),),
            pareto=(MEASURES["base_radius"], MEASURES["contact_stress"]),
            chunk_size=5,
            batch=batch,
        )
        folder = tmp_path / str(batch)
        sweep(plan, folder, fmt="csv")
        out[batch] = (folder / "sweep.csv").read_bytes()
    assert out[True] == out[False]
    assert out[True].count(b"\n") == 13  # the header and 12 designs


def test_mixed_structures_fall_back_and_match() -> None:
    """Two laws (two motion structures), a refused variant, an arm and a conjugate pair beside.

    The laws form two groups, each analysed together; the refused variant
    (offset beyond r_b + r_f) is its failed row; the rocker's base-radius
    variants (whose pivot moves) are analysed together, the conjugate pair's
    one by one. Every row is the per-design one.
    """
    data = sample_data("offset_roller")
    variables = [
        parse_variable("base_radius=30:80", data, flag="--vary", counted=False),
        parse_variable("motion[0].law=cycloidal,poly-345", data, flag="--vary", counted=False),
        parse_variable("offset=0:200", data, flag="--vary", counted=False),
    ]
    points = [
        (50.0, "cycloidal", 10.0),
        (60.0, "poly-345", 5.0),
        (70.0, "cycloidal", 0.0),
        (40.0, "poly-345", 12.0),
        (30.0, "cycloidal", 150.0),  # |e| ≥ r_b + r_f: the schema refuses it
        (80.0, "cycloidal", 20.0),
    ]
    stats = BatchStats()
    got = chunk_rows(data, variables, points, stats=stats)
    assert _text(got) == _text(_one_at_a_time(data, variables, points))
    assert got[4]["status"] == "invalid"
    assert stats.batched == 5 and stats.single == 0  # 3 cycloidal + 2 poly-345 variants, two groups

    rocker = sample_data("packaging_rocker")
    radius = [parse_variable("base_radius=50:60", rocker, flag="--vary", counted=False)]
    pts = [(50.0,), (55.0,), (60.0,)]
    stats = BatchStats()
    got = chunk_rows(rocker, radius, pts, stats=stats)
    assert _text(got) == _text(_one_at_a_time(rocker, radius, pts))
    assert stats.single == 0 and stats.batched == 3  # the pivot differs: one stacked follower all the same

    pair = sample_data("indexing_conjugate")
    radius = [parse_variable("base_radius=40:50", pair, flag="--vary", counted=False)]
    pts = [(40.0,), (45.0,)]
    stats = BatchStats()
    got = chunk_rows(pair, radius, pts, stats=stats)
    assert _text(got) == _text(_one_at_a_time(pair, radius, pts))
    assert stats.single == 2 and stats.batched == 0  # two plates: one by one


@pytest.mark.parametrize("name", ["packaging_rocker", "rocker_flat"])
def test_arm_sweep_of_base_radius_and_pivot_batches_every_variant(name: str) -> None:
    """The sweep benchmark's case for the arms: r_b × d over a grid, one chunk, every variant in the batch.

    The pivot, the initial arm angle and the arm's direction differ from
    variant to variant; the rows must still be the per-design ones, every
    byte, and every search answered by the stacked one.
    """
    data = sample_data(name)
    r, d = data["cam"]["base_radius"], data["follower"]["pivot_distance"]
    variables = [
        parse_variable(f"base_radius={r!r}:{1.25 * r!r}:3", data, flag="--grid", counted=True),
        parse_variable(f"pivot_distance={d!r}:{1.2 * d!r}:2", data, flag="--grid", counted=True),
    ]
    points = list(grid_points(variables))
    stats = BatchStats()
    got = chunk_rows(data, variables, points, stats=stats)
    assert _text(got) == _text(_one_at_a_time(data, variables, points))
    assert stats.batched == len(points) == 6 and stats.single == 0, stats
    assert stats.served == stats.searches > 0, stats
    assert len({row["pressure_angle_deg"] for row in got}) == 6  # six different cams, not one six times


_ARM = st.floats(min_value=0.8, max_value=1.3, allow_nan=False)


@settings(max_examples=25, deadline=None)
@given(params=st.lists(st.tuples(_ARM, _ARM, _ARM, _ARM), min_size=1, max_size=4))
def test_stacked_arm_followers_give_each_followers_bits(params) -> None:
    """Arms of random r_b, d, l (or face offset) stacked: element, guide, contact of each, bit for bit.

    The stacked follower runs the follower's own methods with one parameter
    value per angle; each variant's rows must equal its own follower's
    output on its angles (the per-design truth), not merely be close.
    """
    from camcad.explore.batch import _FollowerStack
    from camcad.geometry.envelope import PointElement
    from camcad.geometry.followers import OscillatingFlat, OscillatingRoller
    from camcad.motion.laws import make_law
    from camcad.motion.program import MotionProgram
    from camcad.motion.segments import SegmentKind, SegmentSpec

    program = MotionProgram.from_segments(
        (
            SegmentSpec(
                kind=SegmentKind.RISE, span=math.radians(130.0), lift=15.0, law=make_law("cycloidal")
            ),
            SegmentSpec(
                kind=SegmentKind.RETURN, span=math.radians(130.0), lift=15.0, law=make_law("poly-345")
            ),
            SegmentSpec(kind=SegmentKind.DWELL, span=math.radians(100.0)),
        )
    )
    phi = np.linspace(0.0, 2 * math.pi, 37)
    kinds = [
        [
            OscillatingRoller(  # d − l = (c − 0.3)(r_b + r_f): the arm reaches the base circle
                base_radius=50.0 * a,
                roller_radius=15.0 * b,
                pivot_distance=95.0 * e + (c - 0.3) * (50.0 * a + 15.0 * b),
                arm_length=95.0 * e,
            )
            for a, b, c, e in params
        ],
        [
            OscillatingFlat(base_radius=45.0 * a, pivot_distance=140.0 * c, face_offset=10.0 * (b - 1.05))
            for a, b, c, _ in params
        ],
    ]
    for followers in kinds:
        nv = len(followers)
        which = np.repeat(np.arange(nv), phi.size)
        motion = program.evaluate(np.tile(phi, nv))
        fol = _FollowerStack(followers).at(which)
        element = fol.element(motion)
        contact = np.column_stack((np.cos(motion.phi), np.sin(motion.phi))) * 40.0
        position = fol.contact_position(contact, motion)
        trace = fol.trace(motion)
        driven = fol.guide.driven(trace.m0)
        for v, alone in enumerate(followers):
            rows = slice(v * phi.size, (v + 1) * phi.size)
            mine = program.evaluate(phi)
            own = alone.element(mine)
            names = ("m0", "m1", "m2", "m3") if isinstance(own, PointElement) else ("normal", "theta", "p")
            for name in names:
                got, want = getattr(element, name), getattr(own, name)
                if isinstance(want, tuple):
                    for g, w in zip(got, want, strict=True):
                        assert np.array_equal(np.asarray(g)[rows], w), name
                else:
                    assert np.array_equal(got[rows], want), name
            assert np.array_equal(position[rows], alone.contact_position(contact[rows], mine))
            assert np.array_equal(trace.m0[rows], alone.trace(mine).m0)
            assert np.array_equal(driven[rows], alone.guide.driven(alone.trace(mine).m0))


def test_failed_designs_keep_their_place() -> None:
    """`analyse_rows` with a variant's error in the middle: its failed row stays there."""
    data = sample_data("offset_roller")
    variables = [parse_variable("base_radius=40:80", data, flag="--vary", counted=False)]
    designs: list[Any] = [design_with(data, variables, (r,)) for r in (40.0, 60.0, 80.0)]
    err = CamcadError("a refused variant")
    rows = analyse_rows([designs[0], err, designs[1], designs[2]])
    assert rows[1]["reason"] == "a refused variant"
    assert _text([rows[0], rows[2], rows[3]]) == _text(
        [analysis_row(analyse(d, fit=False, toolpath=False, strict=False), ()) for d in designs]
    )


def _brackets_by_rule(phi, piece, val, best):
    """Sampled strict local maxima kept by the 4·drop rule, transcribed from the docstring, row by row."""
    out = []
    m = val.shape[1]
    for r in range(val.shape[0]):
        for i in range(m):
            prev_in = i > 0 and piece[i - 1] == piece[i]
            next_in = i < m - 1 and piece[i + 1] == piece[i]
            v = val[r, i]
            if not math.isfinite(v):
                continue
            p = val[r, i - 1] if prev_in else -math.inf
            n = val[r, i + 1] if next_in else -math.inf
            if not (v >= p and v >= n):
                continue
            if (not prev_in or v == p) and (not next_in or v == n):
                continue  # flat
            lower = min(p if prev_in else math.inf, n if next_in else math.inf)
            drop = v - lower if math.isfinite(lower) else math.inf
            if v + 4.0 * drop >= best[r]:
                out.append((r, i))
    return out


@settings(max_examples=60, deadline=None)
@given(
    data=st.lists(
        st.lists(st.sampled_from([0.0, 1.0, 2.0, 2.0, 3.0, -math.inf, math.inf]), min_size=9, max_size=9),
        min_size=1,
        max_size=4,
    ),
    cuts=st.sets(st.integers(min_value=1, max_value=8), max_size=3),
)
def test_bracket_finder_follows_its_rule(data, cuts) -> None:
    """The whole-array bracket finder keeps exactly the samples its rule names (plateaus, ties, ±inf)."""
    from camcad.extremes import _brackets, _Sequence

    val = np.array(data, dtype=float)
    m = val.shape[1]
    piece = np.searchsorted(sorted(cuts), np.arange(m), side="right")
    phi = np.linspace(0.0, 6.0, m)
    best = np.max(np.where(np.isfinite(val), val, -math.inf), axis=1)
    seq = _Sequence(phi=phi, value=val, piece=piece, left=np.zeros(m, bool))
    b = _brackets(seq, val, best)
    found = set()
    for r, x1, x3 in zip(b.row, b.x1, b.x3, strict=True):
        found.add((int(r), float(x1), float(x3)))
    expected = set()
    for r, i in _brackets_by_rule(phi, piece, val, best):
        prev_in = i > 0 and piece[i - 1] == piece[i]
        next_in = i < m - 1 and piece[i + 1] == piece[i]
        if prev_in and next_in:
            expected.add((r, float(phi[i - 1]), float(phi[i + 1])))
        elif prev_in:
            expected.add((r, float(phi[i - 1]), float(phi[i])))
        elif next_in:
            expected.add((r, float(phi[i]), float(phi[i + 1])))
    assert found == expected


def test_optimize_same_result_with_batched_gradients() -> None:
    """002's problem (smallest r_b over r_b and e): the batched finite-difference stencil changes nothing.

    With ``batch`` each iterate is analysed together with its forward-difference
    neighbours; the solver must take the very same path: the same optimum, constraints
    and number of designs asked for, to the last digit.
    """
    from camcad.explore.optimize import Problem, optimize

    data = sample_data("offset_roller")
    variables = tuple(
        parse_variable(t, data, flag="--vary", counted=False) for t in ("base_radius=20:120", "offset=0:40")
    )
    got = {
        batch: optimize(
            Problem(data=data, variables=variables, objectives=(MEASURES["base_radius"],), batch=batch)
        )
        for batch in (True, False)
    }
    assert repr(got[True]) == repr(got[False])
    assert got[True].best is not None and got[True].best.values["base_radius"] == pytest.approx(
        23.42, abs=0.01
    )


@settings(max_examples=30, deadline=None)
@given(
    coef=st.lists(
        st.tuples(
            st.floats(min_value=-3, max_value=3), st.floats(min_value=0.5, max_value=4), st.floats(-3, 3)
        ),
        min_size=1,
        max_size=5,
    )
)
def test_stacked_search_equals_each_row_alone(coef) -> None:
    """Rows a·sin(b·φ + c) jumping at a joint: one stacked search gives each row's own, bit for bit."""
    from camcad.extremes import extremes_rows, extremes_stacked

    joints = [1.0, 4.0]

    def f(i: int, p: np.ndarray, side: str) -> np.ndarray:
        a, b, c = coef[i]
        jump = np.where((p > 1.0) | ((p == 1.0) & (side == "right")), 0.3 * a, 0.0)
        return a * np.sin(b * p + c) + jump

    grid = np.linspace(0.0, 2 * math.pi, 361, endpoint=False)
    kinds = ("max", "min")
    alone = [
        extremes_rows(lambda p, side, i=i: np.vstack((f(i, p, side), f(i, p, side))), grid, joints, kinds)
        for i in range(len(coef))
    ]

    def quantity(p, side):
        return np.vstack([np.vstack((f(i, p, side), f(i, p, side))) for i in range(len(coef))])

    def pick(p, rows, side):
        out = np.empty(p.size)
        for i in range(len(coef)):
            mine = rows // 2 == i
            out[mine] = f(i, p[mine], side)
        return out

    stacked = extremes_stacked(quantity, pick, grid, joints, kinds * len(coef))
    assert [repr(e) for pair in alone for e in pair] == [repr(e) for e in stacked]


def test_served_answers_only_the_same_bits() -> None:
    """A search done ahead answers the call with its very samples; a −0.0 for a 0.0 is searched anew."""
    from camcad.extremes import Extreme, extremes_rows, served

    grid = np.linspace(0.0, 2 * math.pi, 90, endpoint=False)
    values = np.vstack((np.cos(grid), np.cos(grid)))
    values[:, 10] = 0.0

    def rows(p, side):
        return np.vstack((np.cos(p), np.cos(p)))

    marker = (Extreme(value=42.0, phi=0.0), Extreme(value=-42.0, phi=0.0))
    answer = (grid, np.array([0.0]), ("max", "min"), values, (), (), marker)
    with served([answer]) as held:
        assert extremes_rows(rows, grid, [0.0], ("max", "min"), values=values) == marker
        assert held.used == 1
    flipped = values.copy()
    flipped[:, 10] = -0.0
    with served([answer]) as held:
        got = extremes_rows(rows, grid, [0.0], ("max", "min"), values=flipped)
        assert got != marker and held.used == 0
        assert got[0].value == pytest.approx(1.0) and got[1].value == pytest.approx(-1.0)


@settings(max_examples=3, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(scales=st.lists(st.lists(_SCALE, min_size=4, max_size=4), min_size=3, max_size=3))
def test_duty_searches_batched_and_equal(scales: list[list[float]]) -> None:
    """Life, film and drive ([life] with a track, [lubrication], [drive]): every summary byte as alone.

    The exact film and track searches of each variant are answered by the
    stacked one (four served searches a design: geometry, dynamics, film,
    track), and the summaries (the film's smallest ratio and its angle, the
    track's life, the laws' VDI 2143 values, the motor) are those of
    :func:`camcad.pipeline.analyse` on each design alone.
    """
    from camcad.explore.batch import analyse_many

    data = sample_data("indexing_drive")
    data["life"] |= {"track_slope": 8.0, "track_intercept": 34.0}
    keys = ("cam.base_radius", "cam.speed_rpm", "follower.roller_radius", "lubrication.viscosity_Pa_s")

    def base(key: str) -> float:
        table, name = key.split(".")
        return float(data[table][name])

    variables = [
        parse_variable(f"{k}={0.85 * base(k)!r}:{1.25 * base(k)!r}", data, flag="--vary", counted=False)
        for k in keys
    ]
    designs = [
        design_with(data, variables, tuple(base(k) * s for k, s in zip(keys, row, strict=True)))
        for row in scales
    ]
    stats = BatchStats()
    got = analyse_many(designs, stats=stats)
    alone = [analyse(d, fit=False, toolpath=False, strict=False) for d in designs]
    text = [json.dumps(a.summary(), sort_keys=True, default=repr) for a in (*got, *alone)]  # type: ignore[union-attr]
    assert text[: len(designs)] == text[len(designs) :]
    assert "film_ratio" in text[0] and "characteristic_values" in text[0]
    assert stats.batched == len(designs), stats
    assert stats.served == stats.searches == 4 * len(designs), stats


@settings(max_examples=30, deadline=None)
@given(
    pairs=st.lists(
        st.tuples(st.floats(-50, 50), st.floats(-50, 50), st.floats(0.1, 9)), min_size=2, max_size=4
    ),
    which=st.lists(st.integers(min_value=0, max_value=3), min_size=1, max_size=6),
)
def test_stacked_tuples_index_as_each_variants_own(pairs, which) -> None:
    """A differing pair (a groove's flank offsets, a guide's pivot) read at the angles is each variant's own.

    Stacked as columns, ``pair[0]`` and ``a, b = pair`` give every angle its
    variant's items (as the scalar code reads them); stacked as points (a
    follower's guide), ``np.asarray(pivot)`` is the (m, 2) of its pivots.
    """
    from dataclasses import replace

    from camcad.explore.batch import _Stacked
    from camcad.geometry.envelope import Guide

    setups = [replace(_groove_setup(), flank_offsets=(a, b), contact_length=c) for a, b, c in pairs]
    picks = np.array([w % len(pairs) for w in which])
    got = _Stacked.of(setups).at(picks)

    def each(values: list[Any]) -> np.ndarray:
        return np.array(values, dtype=float)

    def same(a: Any, b: np.ndarray) -> bool:  # a field equal in every variant stays the first's scalar
        return np.array_equal(np.broadcast_to(np.asarray(a, dtype=float), b.shape), b)

    first, second = got.flank_offsets
    assert same(got.flank_offsets[0], each([setups[w].flank_offsets[0] for w in picks]))
    assert same(first, each([setups[w].flank_offsets[0] for w in picks]))
    assert same(second, each([setups[w].flank_offsets[1] for w in picks]))
    assert same(got.contact_length, each([setups[w].contact_length for w in picks]))
    guides = [Guide(pivot=(a, b), turn=-1.0) for a, b, _ in pairs]
    pivot = _Stacked.of(guides, points=True).at(picks).pivot
    assert same(pivot, each([guides[w].pivot for w in picks]))


@functools.cache
def _groove_setup() -> Any:
    """The groove sample's dynamics setup (its flank offsets a pair)."""
    from camcad.design import load_design
    from tests.conftest import ROOT

    return load_design(ROOT / "samples" / "groove_rocker.toml").dynamics_setup()


def test_a_speed_whose_libm_square_is_off_by_an_ulp_is_still_served() -> None:
    """ω**2 by libm's pow and ω·ω differ in the last bit at this speed; the batch still serves every search.

    A found case (hypothesis): rocker_flat at 0.9197… of its speed. Were the
    dynamics to square a scalar ω with ``**`` (pow) while the batch squares
    the stacked speeds as an array (a product), the samples would differ by
    an ulp and the variant's search would be run alone.
    """
    data = sample_data("rocker_flat")
    rpm = float(data["cam"]["speed_rpm"]) * 0.9197223816057212
    omega = rpm * 2.0 * math.pi / 60.0
    assert omega**2 != omega * omega  # the premise: pow is not the correctly rounded square here
    variables = [
        parse_variable(f"speed_rpm={0.85 * rpm!r}:{1.25 * rpm!r}", data, flag="--vary", counted=False)
    ]
    points = [(float(data["cam"]["speed_rpm"]),), (rpm,), (1.1 * rpm,)]
    stats = BatchStats()
    got = chunk_rows(data, variables, points, limits=(), stats=stats)
    assert _text(got) == _text(_one_at_a_time(data, variables, points, ()))
    assert stats.batched == 3 and stats.served == stats.searches > 0, stats
