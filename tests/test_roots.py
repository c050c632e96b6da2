"""camcad.roots.brent_root against scipy.optimize.brentq and closed-form roots."""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from camcad.roots import brent_root


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
