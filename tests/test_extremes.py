"""camcad.extremes' shortcuts (rests, settled rows) against the full search, and the shared grid state.

A dwell's brackets (``rests``) and a row of constants (``settled``) are not
searched: the extremes must be the very ones the full search finds, on
synthetic quantities with round-off noise on the flat stretch and on the
shipped designs (the search run again with the shortcuts turned off).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camcad.design import parse_design
from camcad.dynamics.arm import ArmLoad
from camcad.dynamics.energy import FollowerLoad
from camcad.extremes import extremes_rows
from camcad.geometry import Cam
from camcad.pipeline import analyse

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

SAMPLES = Path(__file__).resolve().parents[1] / "samples"
GRID = np.linspace(0.0, 2.0 * math.pi, 3600, endpoint=False)


def _counting(rows):
    calls = []

    def quantity(phi, side):
        calls.append(np.size(phi))
        return rows(phi, side)

    return quantity, calls


def _bumpy(peak_at: float, rest: tuple[float, float], level: float):
    """A smooth peak of height 1 at ``peak_at`` plus ``level`` with round-off noise on ``rest``."""

    def rows(phi, side):
        phi = np.asarray(phi, dtype=float)
        bump = np.exp(-(((phi - peak_at) / 0.2) ** 2))
        noise = level * (1.0 + 1e-15 * np.sin(1e6 * phi))  # a flat stretch as the envelope computes it
        on_rest = (phi >= rest[0]) & (phi <= rest[1])
        value = np.where(on_rest, noise, level * bump)
        return np.vstack((value, -value))

    return rows


@settings(max_examples=25, deadline=None)
@given(peak_at=st.floats(3.5, 5.5), level=st.floats(0.5, 1.5))
def test_a_rest_gives_the_extremes_of_the_full_search_with_far_fewer_evaluations(peak_at, level):
    rest = (1.0, 2.5)
    rows = _bumpy(peak_at, rest, level)
    full, full_calls = _counting(rows)
    short, short_calls = _counting(rows)
    joints = list(rest)
    want = extremes_rows(full, GRID, joints, ("max", "min"))
    got = extremes_rows(short, GRID, joints, ("max", "min"), rests=[rest])
    assert got == want
    assert got[0].value == pytest.approx(level, rel=1e-12)  # the peak's closed form: level·1
    assert sum(short_calls) < sum(full_calls)


def test_a_settled_row_keeps_its_sampled_extreme_and_is_not_searched():
    """A bound that is 0 where it applies and −inf elsewhere: the full search cannot beat its samples."""

    def rows(phi, side):
        phi = np.asarray(phi, dtype=float)
        bound = np.where(np.sin(3.0 * phi) > 0.0, 0.0, -np.inf)
        return np.vstack((bound, np.sin(phi)))

    full, full_calls = _counting(rows)
    short, short_calls = _counting(rows)
    want = extremes_rows(full, GRID, [], ("max", "max"))
    got = extremes_rows(short, GRID, [], ("max", "max"), settled=[True, False])
    assert got == want
    assert got[1].value == pytest.approx(1.0, abs=1e-15) and got[1].phi == pytest.approx(
        math.pi / 2, abs=1e-8
    )
    assert len(short_calls) < len(full_calls)


@pytest.mark.parametrize("name", ["indexing_conjugate", "groove_rocker", "offset_roller", "rocker_flat"])
def test_the_shortcuts_leave_every_reported_figure_as_the_full_search_finds_it(name, monkeypatch):
    path = SAMPLES / f"{name}.toml"
    design = parse_design(tomllib.loads(path.read_text(encoding="utf-8")), source=str(path))
    fast = analyse(design, fit=False, toolpath=False, strict=False).summary()
    monkeypatch.setattr(Cam, "rests", property(lambda self: ()))
    monkeypatch.setattr(FollowerLoad, "unloaded", property(lambda self: False))
    monkeypatch.setattr(ArmLoad, "unloaded", property(lambda self: False))
    full = analyse(design, fit=False, toolpath=False, strict=False).summary()
    assert fast == full


def test_the_grid_state_is_computed_once_and_only_for_the_same_angles_and_side():
    path = SAMPLES / "indexing_conjugate.toml"
    design = parse_design(tomllib.loads(path.read_text(encoding="utf-8")), source=str(path))
    cam = Cam.from_design(design)
    grid = cam.sample_phi()
    first = cam.state(grid)
    assert cam.state(grid.copy()) is first
    fresh = Cam.from_design(design)
    for got, want in (
        (first, fresh.state(grid)),
        (cam.state(grid, side="left"), fresh.state(grid, side="left")),
    ):
        np.testing.assert_array_equal(got.profile.point, want.profile.point)
        np.testing.assert_array_equal(got.pressure_angle, want.pressure_angle)
    moved = grid.copy()
    moved[5] += 1e-3
    np.testing.assert_array_equal(cam.state(moved).profile.point, fresh.state(moved).profile.point)
    partner = cam.partner(design.conjugate)
    np.testing.assert_array_equal(partner.motion(moved).s, fresh.motion(moved).s)
    plain = Cam.from_design(design).partner(design.conjugate)  # its own motion, not the shared one
    np.testing.assert_array_equal(partner.state(moved).profile.point, plain.state(moved).profile.point)


def test_the_summary_is_the_same_on_every_call_and_each_copy_is_the_callers():
    path = SAMPLES / "offset_roller.toml"
    design = parse_design(tomllib.loads(path.read_text(encoding="utf-8")), source=str(path))
    analysis = analyse(design, fit=False, toolpath=False, strict=False)
    first = analysis.summary()
    first["motion"]["joints"].clear()
    assert analysis.summary()["motion"]["joints"]
    assert analysis.summary() == analyse(design, fit=False, toolpath=False, strict=False).summary()


def test_a_probe_that_only_ties_the_end_of_a_piece_is_not_searched():
    """s = 1 − (1 − φ)⁴ up to φ = 1 rad, then 0: flat to round-off at the top, the end's limit is the max."""

    def rows(phi, side):
        phi = np.asarray(phi, dtype=float)
        inside = (phi < 1.0) | ((phi == 1.0) & (side == "left"))
        return np.where(inside, 1.0 - (1.0 - phi) ** 4, 0.0)[None, :]

    quantity, calls = _counting(rows)
    (top,) = extremes_rows(quantity, GRID, [1.0], ("max",))
    assert (top.value, top.phi, top.side) == (1.0, 1.0, "left")  # the closed form: the limit at the joint
    assert len(calls) <= 4  # the grid, the joint's limits, the end gaps' probes: no search


def _jumpy_rows(seed: int, k: int):
    """k random smooth rows over the turn, each jumping (or not) at three joints; and the joints."""
    rng = np.random.default_rng(seed)
    joints = np.sort(rng.choice(GRID[1:], 3, replace=False))
    amp, phase = rng.normal(size=(k, 4)), rng.uniform(0, 2 * math.pi, (k, 4))
    steps = rng.normal(size=(k, 4)) * (rng.uniform(size=(k, 1)) < 0.6)  # some rows continuous

    def rows(phi, side):
        p = np.asarray(phi, dtype=float)
        piece = np.searchsorted(joints, p, side="left" if side == "left" else "right")
        waves = sum(amp[:, [j]] * np.sin((j + 1) * p + phase[:, [j]]) for j in range(4))
        return waves + np.take_along_axis(steps, np.broadcast_to(piece, (k, p.size)) % 4, axis=1)

    return rows, joints, rng


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), k=st.integers(1, 9), block=st.integers(1, 4))
def test_rows_scanned_in_blocks_give_the_extremes_of_one_scan(seed, k, block):
    """The samples' scan in blocks of rows (as a batch's many rows are) changes no bit of any extreme."""
    import camcad.extremes as ex

    rows, joints, rng = _jumpy_rows(seed, k)
    kinds = tuple(rng.choice(["min", "max"], k).tolist())
    whole = extremes_rows(rows, GRID, joints, kinds)
    kept = ex._ROW_BLOCK
    try:
        ex._ROW_BLOCK = block
        blocked = extremes_rows(rows, GRID, joints, kinds)
    finally:
        ex._ROW_BLOCK = kept
    assert blocked == whole


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), k=st.integers(1, 9))
def test_every_rows_sample_side_at_once_is_each_rows_alone(seed, k):
    """The vectorised side of each row's sample (_sample_sides) is the one-row rule (_sample_side)."""
    import camcad.extremes as ex

    rows, joints, rng = _jumpy_rows(seed, k)
    seq = ex._sequence(rows, GRID, joints, None, k)
    at_joints = np.flatnonzero(np.isin(np.mod(seq.phi, 2 * math.pi), joints) | (seq.phi == 0.0))
    top = rng.choice(np.concatenate((at_joints, rng.integers(0, seq.phi.size, 4))), k)
    assert ex._sample_sides(seq, top, {}) == [ex._sample_side(seq, r, int(top[r])) for r in range(k)]


@settings(max_examples=60, deadline=None)
@given(
    n=st.integers(min_value=2, max_value=40),
    joints=st.lists(st.floats(min_value=0.0, max_value=6.28), max_size=5),
    k=st.integers(min_value=1, max_value=5),
    lo_hi=st.tuples(st.integers(0, 4), st.integers(1, 5)),
    seed=st.integers(0, 2**32 - 1),
)
def test_layout_rows_is_the_sorted_columns(n, joints, k, lo_hi, seed) -> None:
    """A search's sequence of rows: the grid's and the extra columns taken in ``order`` (the plain gather)."""
    from camcad.extremes import _layout

    grid = np.sort(np.random.default_rng(seed).uniform(0.0, 2 * math.pi, n))
    grid = np.unique(np.concatenate((grid, [0.0])))
    rng = np.random.default_rng(seed + 1)

    def quantity(p, side):
        return rng.normal(size=(k, p.size))

    layout = _layout(quantity, grid, np.asarray(joints, dtype=float), None, k)
    lo = min(lo_hi[0], k - 1)
    hi = min(max(lo + 1, lo_hi[1]), k)
    plain = np.take(np.concatenate((layout.right[lo:hi], layout.extra[lo:hi]), axis=1), layout.order, axis=1)
    assert np.array_equal(layout.rows(lo, hi).value, plain)


@settings(max_examples=100, deadline=None)
@given(
    data=st.lists(
        st.lists(st.sampled_from([0.0, 1.0, 2.0, 2.0, 3.0, -math.inf, math.inf]), min_size=12, max_size=12),
        min_size=1,
        max_size=4,
    ),
    cuts=st.sets(st.integers(min_value=1, max_value=11), max_size=3),
    rests=st.lists(st.tuples(st.integers(0, 11), st.integers(0, 11)).map(sorted).map(tuple), max_size=3),
)
def test_brackets_outside_rests_are_the_kept_ones(data, cuts, rests) -> None:
    """Looking at the samples outside the rests only finds the brackets the rests rule keeps, in order."""
    from camcad.extremes import _brackets, _fields, _outside_rests, _Sequence, _without_rests

    val = np.array(data, dtype=float)
    m = val.shape[1]
    piece = np.searchsorted(sorted(cuts), np.arange(m), side="right")
    phi = np.linspace(0.0, 5.5, m)
    spans = [(float(phi[a]), float(phi[b])) for a, b in rests]
    best = np.max(val, axis=1) - 1.0
    seq = _Sequence(phi=phi, value=val, piece=piece, left=np.zeros(m, bool))
    everything = _without_rests(_brackets(seq, val, best), spans)
    looked = _without_rests(_brackets(seq, val, best, _outside_rests(seq, spans)), spans)
    for a, b in zip(_fields(everything), _fields(looked), strict=True):
        assert np.array_equal(a, b, equal_nan=True)
