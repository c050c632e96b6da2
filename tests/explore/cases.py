"""Shared helpers of the exploration tests: the samples' design mappings and 002's closed forms."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import tomllib

from camcad.design import load_design
from camcad.motion.program import MotionProgram
from tests.conftest import ROOT


def sample_data(name: str) -> dict[str, Any]:
    """A shipped sample's TOML mapping."""
    return tomllib.loads((ROOT / "samples" / f"{name}.toml").read_text(encoding="utf-8"))


def motion_sv(design_path: str, n: int = 72_001) -> tuple[np.ndarray, np.ndarray]:
    """s [mm] and v = ds/dφ [mm/rad] of a sample's motion program on n angles over the turn."""
    design = load_design(ROOT / "samples" / f"{design_path}.toml")
    program = MotionProgram.from_segments(design.motion)
    phi = np.linspace(0.0, 2.0 * math.pi, n)
    m = program.evaluate(phi)
    return np.asarray(m.s), np.asarray(m.v)


def smallest_base_radius_002(
    s: np.ndarray, v: np.ndarray, *, e: float, r_f: float, alpha_deg: float
) -> float:
    """Smallest base radius of an offset roller (ccw) with |α| ≤ alpha at offset e, by 002 eq. 4 alone.

    tan α = (v − e)/(s + k), k = √((r_b + r_f)² − e²): |α| ≤ A at every angle ⇔
    k ≥ |v − e|/tan A − s at every angle, so k_min = max(|v − e|/tan A − s) and
    r_b = √(k_min² + e²) − r_f (Quang & Hung 2015, eqs. 2 and 4).
    """
    k = float(np.max(np.abs(v - e) / math.tan(math.radians(alpha_deg)) - s))
    return math.sqrt(k * k + e * e) - r_f


def peak_pressure_angle_002(s: np.ndarray, v: np.ndarray, *, r_b: float, e: float, r_f: float) -> float:
    """max |α| [deg] over the samples by 002 eq. 4."""
    k = math.sqrt((r_b + r_f) ** 2 - e * e)
    return float(np.degrees(np.max(np.abs(np.arctan2(v - e, s + k)))))


def peak_pressure_angles_002(
    s: np.ndarray, v: np.ndarray, *, r_b: float, offsets: np.ndarray, r_f: float
) -> np.ndarray:
    """max |α| [deg] over the samples by 002 eq. 4 at each of many offsets (one r_b).

    The value of :func:`peak_pressure_angle_002` at each offset, with one arctan per offset instead of one
    per sample: where s + k > 0, α = arctan((v − e)/(s + k)), and arctan is odd and increasing, so
    max |α| = arctan(max |v − e|/(s + k)).
    """
    offsets = np.asarray(offsets, dtype=float)
    ratio = np.empty(offsets.shape)
    num, den = np.empty_like(s), np.empty_like(s)
    for i, e in enumerate(offsets):
        np.add(s, math.sqrt((r_b + r_f) ** 2 - e * e), out=den)
        assert den.min() > 0.0  # the identity above needs the follower outside the base circle
        np.abs(np.subtract(v, e, out=num), out=num)
        ratio[i] = np.max(np.divide(num, den, out=num))
    return np.degrees(np.arctan(ratio))
