"""camcad.roots.brent_root against scipy.optimize.brentq and closed-form roots; brent_roots against it."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from camcad.roots import brent_root, brent_roots


@settings(max_examples=200, deadline=None)
@given(
    root=st.floats(-50.0, 50.0),
    left=st.floats(1e-6, 40.0),
    right=st.floats(1e-6, 40.0),
    slope=st.floats(0.01, 100.0),
    wiggle=st.floats(0.0, 1.0),
    power=st.sampled_from([1, 3, 5]),
)
def test_the_root_of_an_increasing_function_is_found_to_xtol(root, left, right, slope, wiggle, power):
    """f(x) = slope·(d^power + d/2 + 0.4·wiggle·sin d), d = x − r: f' > 0.1·slope, the only root is r."""

    def f(x: float) -> float:
        d = x - root
        return slope * (d**power + 0.5 * d + 0.4 * wiggle * math.sin(d))

    a, b = root - left, root + right
    ours = brent_root(f, a, b, xtol=1e-12)
    assert abs(ours - root) <= 1e-11 + 1e-14 * abs(root)
    assert abs(ours - brentq(f, a, b, xtol=1e-12)) <= 2e-11 + 1e-14 * abs(root)


@pytest.mark.parametrize(
    ("f", "a", "b", "truth"),
    [
        (math.cos, 0.0, 3.0, math.pi / 2),
        (lambda x: x**3 - 2.0, 0.0, 2.0, 2.0 ** (1 / 3)),
        (lambda x: math.exp(x) - 10.0, -5.0, 5.0, math.log(10.0)),
        (lambda x: x - 1.0, 1.0, 2.0, 1.0),  # the root at an end
        (lambda x: math.copysign(1.0, x - 0.3), 0.0, 1.0, 0.3),  # a jump: bisection only
    ],
)
def test_closed_form_roots(f, a, b, truth):
    assert brent_root(f, a, b, xtol=1e-13) == pytest.approx(truth, abs=1e-12)


def test_no_bracket_is_refused():
    with pytest.raises(ValueError, match="do not bracket"):
        brent_root(lambda x: x * x + 1.0, -1.0, 1.0)


@settings(max_examples=100, deadline=None)
@given(
    root=st.floats(-50.0, 50.0),
    ends=st.lists(st.tuples(st.floats(1e-6, 40.0), st.floats(1e-6, 40.0)), min_size=1, max_size=5),
    slope=st.floats(0.01, 100.0),
    wiggle=st.floats(0.0, 1.0),
    power=st.sampled_from([1, 3, 5]),
)
def test_the_brackets_searched_together_give_each_root_of_the_search_alone_to_the_bit(
    root, ends, slope, wiggle, power
):
    """brent_roots runs brent_root's steps on every bracket in lockstep: the same roots, bit for bit."""

    def f(x):
        d = np.asarray(x, dtype=float) - root
        return slope * (d**power + 0.5 * d + 0.4 * wiggle * np.sin(d))

    a = [root - left for left, _ in ends]
    b = [root + right for _, right in ends]
    together = brent_roots(f, a, b, xtol=1e-12)
    for i, (lo, hi) in enumerate(zip(a, b, strict=True)):
        alone = brent_root(lambda x: float(f(np.array([x]))[0]), lo, hi, xtol=1e-12)
        assert together[i] == alone
        assert abs(
            together[i] - brentq(lambda x: float(f(np.array([x]))[0]), lo, hi, xtol=1e-12)
        ) <= 2e-11 + 1e-14 * abs(root)


def test_brackets_with_a_root_at_an_end_a_jump_or_none():
    step = lambda x: np.copysign(1.0, np.asarray(x) - 0.3)  # noqa: E731 - bisection only
    assert brent_roots(step, [0.0], [1.0], xtol=1e-13)[0] == brent_root(
        lambda x: float(step(x)), 0.0, 1.0, xtol=1e-13
    )
    np.testing.assert_array_equal(
        brent_roots(lambda x: np.asarray(x) - 1.0, [1.0, 0.0], [2.0, 1.0]), [1.0, 1.0]
    )
    with pytest.raises(ValueError, match="do not bracket"):
        brent_roots(lambda x: np.asarray(x) ** 2 + 1.0, [-1.0, 0.5], [1.0, 2.0])
