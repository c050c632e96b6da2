"""Benchmark of the certified profile fit (camcad.fit) against geomdl.

Run ``python benchmarks/fit.py``; prints Markdown tables:

1. per cam (the issue's cycloidal and harmonic roller cams, then the shipped samples):
   control points of the clamped form at 1 µm, certified max error, time of
   the whole tolerance-driven fit, time of one least-squares solve against
   ``geomdl.fitting.approximate_curve`` with the same number of control
   points (timed once: it is slow), geomdl's certified max error, and the
   control points geomdl needs for 1 µm (h^4-law scan, total geomdl time
   capped at about a minute);
2. cost against the number of samples (cycloidal cam).

geomdl's curve is measured by foot points of the samples and of exact points
midway between samples: a lower bound of its true error (camcad's own
certificate bounds the distance over the whole exact profile, by adaptive
subdivision, and so is never below it). geomdl fits an open clamped curve
through the closing point, so its seam is only C0.
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from geomdl import fitting

from camcad.fit import ProfileFit, fit_profile
from camcad.fit.bspline import chord_length_params, lsq_periodic
from camcad.fit.certify import project
from camcad.fit.curve import BSplineCurve

TOL = 1e-3  # mm
DEG = math.pi / 180
GEOMDL_BUDGET = 60.0  # s, for the geomdl control-point scans together
REPEATS = 7

Exact = Callable[[np.ndarray], np.ndarray]


def roller_cam(law: str) -> tuple[Exact, list[tuple[float, int]]]:
    """The issue's benchmark cam: base 30 mm, roller 8 mm, lift 12 mm, rise 150°, dwell 30°,
    return 150°, dwell 30°, with one law; the exact profile and its breakpoints."""
    from camcad.design import parse_design
    from camcad.geometry.cam import Cam

    design = parse_design(
        {
            "cam": {"base_radius": 30.0},
            "follower": {"type": "translating-roller", "roller_radius": 8.0},
            "motion": [
                {"kind": "rise", "angle": 150, "lift": 12.0, "law": law},
                {"kind": "dwell", "angle": 30},
                {"kind": "return", "angle": 150, "lift": 12.0, "law": law},
                {"kind": "dwell", "angle": 30},
            ],
        }
    )
    cam = Cam.from_design(design)
    breaks = [(b.phi, b.continuity) for b in cam.program.breakpoints]
    return (lambda p: np.asarray(cam.profile(p).point)), breaks


def reference_002(n_ctrl: int = 80) -> str:
    """002's worked case as a reference: the shipped offset-roller sample (r_b = 80, e = 20,
    r_f = 15) fitted with ``n_ctrl`` control points (uniform knots in chord length, one
    least-squares solve, as in 002), certified like ours; 002 reports 0.0587 mm."""
    import camcad
    from camcad.geometry.cam import Cam

    root = Path(__file__).resolve().parents[1]
    cam = Cam.from_design(camcad.load_design(root / "samples" / "offset_roller.toml"))
    phi = np.asarray(cam.sample_phi())
    points = np.asarray(cam.profile(phi).point)
    params = chord_length_params(points, closed=True)
    fit = lsq_periodic(params, points, np.arange(n_ctrl) / n_ctrl, 3)
    err = project(fit.curve, points, params).max_error
    ours = fit_profile(
        phi,
        points,
        exact=lambda p: np.asarray(cam.profile(p).point),
        breakpoints=[(b.phi, b.continuity) for b in cam.program.breakpoints],
        tolerance=TOL,
    )
    return (
        f"002 reference (offset-roller sample, {len(phi)} samples): {n_ctrl} control points, "
        f"uniform knots: max error {err * 1e3:.3f} µm (002: 58.7 µm with 90 data points); "
        f"camcad at {TOL * 1e3:g} µm: {ours.control_point_count} control points, "
        f"{ours.max_error * 1e3:.3f} µm"
    )


def shipped_cams() -> list[tuple[str, np.ndarray, Exact, list[tuple[float, int]]]]:
    """The sample designs, if camcad's geometry stage is there."""
    root = Path(__file__).resolve().parents[1]
    try:
        import camcad
        from camcad.geometry.cam import Cam
    except ImportError:
        return []
    out = []
    for path in sorted((root / "samples").glob("*.toml")):
        design = camcad.load_design(path)
        cam = Cam.from_design(design)
        phi = np.asarray(cam.sample_phi())
        breaks = [(b.phi, b.continuity) for b in cam.program.breakpoints]
        out.append((path.stem, phi, lambda p, cam=cam: np.asarray(cam.profile(p).point), breaks))
    return out


def timed(fn: Callable[[], object], repeats: int = REPEATS) -> tuple[float, float]:
    """(min, median) wall time [s] over ``repeats`` calls."""
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times), float(np.median(times))


def fit_timed(
    phi: np.ndarray, points: np.ndarray, exact: Exact, breaks: list[tuple[float, int]]
) -> tuple[ProfileFit, float, float]:
    """The fit at TOL and its (min, median) time [s]."""

    def run() -> ProfileFit:
        return fit_profile(phi, points, exact=exact, breakpoints=breaks, tolerance=TOL)

    fit = run()
    return (fit, *timed(run))


def geomdl_error(phi: np.ndarray, points: np.ndarray, exact: Exact, n_ctrl: int) -> tuple[float, float]:
    """(certified max error [mm], time [s]) of geomdl.approximate_curve with n_ctrl control points."""
    closed = np.vstack((points, points[:1]))
    t0 = time.perf_counter()
    crv = fitting.approximate_curve(closed.tolist(), 3, ctrlpts_size=n_ctrl)
    elapsed = time.perf_counter() - t0
    knots = np.asarray(crv.knotvector, dtype=float)
    curve = BSplineCurve(degree=3, knots=knots, control_points=np.asarray(crv.ctrlpts, dtype=float))
    params = chord_length_params(closed, closed=False)
    phi_mid = 0.5 * (phi + np.append(phi[1:], phi[0] + 2 * np.pi))
    at_samples = project(curve, points, params[:-1])
    between = project(curve, exact(np.mod(phi_mid, 2 * np.pi)), 0.5 * (params[1:] + params[:-1]))
    return max(at_samples.max_error, between.max_error), elapsed


def geomdl_count(phi: np.ndarray, points: np.ndarray, exact: Exact, start: int, budget: float) -> str:
    """Control points geomdl needs for TOL, by the h^4 law from ``start`` within ``budget`` s.

    Goes up until a count passes, then tries counts between the largest
    failing and the smallest passing one (law estimate from the pass).
    """
    n, spent = start, 0.0
    fail, ok = 0, None
    while spent < budget and n <= 500:
        err, elapsed = geomdl_error(phi, points, exact, n)
        spent += elapsed
        if err <= TOL:
            ok = n if ok is None else min(ok, n)
        else:
            fail = max(fail, n)
        if ok is None:
            n = max(n + 1, math.ceil(n * (err / TOL) ** 0.25))
        elif ok - fail <= 1:
            return f"{ok}"
        else:
            n = min(max(math.floor(n * (err / TOL) ** 0.25), fail + 1), ok - 1)
    if ok is None:
        return f"> {fail} (budget)"
    return f"≤ {ok} (> {fail})"


def lsq_time(phi: np.ndarray, points: np.ndarray, fit_knots: np.ndarray) -> float:
    """Min time [s] of one periodic least-squares solve with the fitted knots."""
    params = chord_length_params(points, closed=True)
    return timed(lambda: lsq_periodic(params, points, fit_knots, 3), repeats=50)[0]


def main() -> None:
    """Print the benchmark tables."""
    cams = []
    for law in ("cycloidal", "harmonic"):
        exact, breaks = roller_cam(law)
        phi = np.arange(3600) * 2 * np.pi / 3600
        cams.append((f"{law} roller cam", phi, exact, breaks))
    cams += shipped_cams()

    print(f"## camcad.fit at {TOL * 1e3:g} µm\n")
    print(
        "| cam | samples | control points | max error (µm) | fit min / median (ms) "
        "| one LSQ (ms) | geomdl LSQ (ms) | speed-up | geomdl max error, same count (µm) "
        "| geomdl count for 1 µm |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    budget = GEOMDL_BUDGET
    for name, phi, exact, breaks in cams:
        points = exact(phi)
        fit, t_min, t_med = fit_timed(phi, points, exact, breaks)
        p = fit.degree
        tau = fit.curve.knots[p : -p - 1]
        ours = lsq_time(phi, points, tau)
        g_err, g_time = geomdl_error(phi, points, exact, fit.control_point_count)
        count = "—"
        if name.endswith("roller cam") and budget > 0:
            t0 = time.perf_counter()
            count = geomdl_count(phi, points, exact, fit.control_point_count, budget / 2)
            budget -= time.perf_counter() - t0
        print(
            f"| {name} | {len(phi)} | {fit.control_point_count} | {fit.max_error * 1e3:.3f} "
            f"| {t_min * 1e3:.1f} / {t_med * 1e3:.1f} | {ours * 1e3:.2f} | {g_time * 1e3:.0f} "
            f"| {g_time / ours:.0f}× | {g_err * 1e3:.1f} | {count} |"
        )

    print(f"\n{reference_002()}")
    print("\n## Cost against samples (cycloidal roller cam)\n")
    print("| samples | control points | max error (µm) | fit min / median (ms) | µs per sample |")
    print("|---|---|---|---|---|")
    exact, breaks = roller_cam("cycloidal")
    for n in (900, 1800, 3600, 7200):
        phi = np.arange(n) * 2 * np.pi / n
        points = exact(phi)
        fit, t_min, t_med = fit_timed(phi, points, exact, breaks)
        print(
            f"| {n} | {fit.control_point_count} | {fit.max_error * 1e3:.3f} "
            f"| {t_min * 1e3:.1f} / {t_med * 1e3:.1f} | {t_min / n * 1e6:.2f} |"
        )


if __name__ == "__main__":
    from _readme import captured  # this folder is on sys.path when the script runs

    with captured("fit"):  # the printed tables become its section of benchmarks/README.md
        main()
