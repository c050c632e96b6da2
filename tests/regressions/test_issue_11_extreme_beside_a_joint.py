"""A maximum between a joint and the first (or last) sample of its piece is found.

Hypothesis found it (modified trapezoid, 60° rise, 274 rpm): the contact force
rises from the joint at 22.5°, peaks at 22.545° and falls below the joint's
value before the next sample at 22.6°, so no sample showed the peak and the
report gave the joint's value, 3e-5 short. Here the truth is a closed form: a
parabola with its vertex a fraction of a sample step from the joint.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from camcad.extremes import maximum, minimum

JOINT = 1.0  # rad
STEP = 0.01  # rad, the sample step
PEAK = 4e-4  # rad, the vertex's distance from the joint
CURVE = 1000.0  # the parabola's curvature; q(joint) beats the neighbouring sample


def _parabola_beside_the_joint(after: bool):
    vertex = JOINT + PEAK if after else JOINT - PEAK

    def quantity(phi, side):
        phi = np.asarray(phi, dtype=float)
        if after:
            on_peak_side = (phi > JOINT) | ((phi == JOINT) & (side == "right"))
        else:
            on_peak_side = (phi < JOINT) | ((phi == JOINT) & (side == "left"))
        return np.where(on_peak_side, 2.0 - CURVE * (phi - vertex) ** 2, 0.5)

    return quantity, vertex


@pytest.mark.parametrize("after", [True, False], ids=["first-gap-of-a-piece", "last-gap-of-a-piece"])
@pytest.mark.parametrize("kind", ["max", "min"])
def test_peak_hidden_between_a_joint_and_its_neighbour_sample(after, kind):
    quantity, vertex = _parabola_beside_the_joint(after)
    sign = 1.0 if kind == "max" else -1.0
    grid = np.arange(0.0, 2 * math.pi, STEP)
    grid = np.union1d(grid[np.abs(grid - JOINT) > STEP / 2], [JOINT])
    # the premise: the joint's value beats its neighbour sample and every sample misses the peak
    joint_value = quantity(np.array([JOINT]), "right" if after else "left")[0]
    neighbour = quantity(np.array([JOINT + STEP if after else JOINT - STEP]), "right")[0]
    assert joint_value > neighbour and quantity(grid, "right").max() < 2.0 - 1e-4

    find = maximum if kind == "max" else minimum  # the minimum of −q is −(the maximum of q)
    found = find(lambda phi, side: sign * quantity(phi, side), grid, [JOINT])
    assert found.value == pytest.approx(sign * 2.0, abs=1e-12)
    assert found.phi == pytest.approx(vertex, abs=1e-7)
    assert found.side is None
