"""Regenerate the README's paper figures and tables: ``python docs/make_figures.py``.

- ``docs/hren_torque.png``: the drive torque of the Hren et al. Table 1 tappet
  cam over the stroke (003 eq. 29), from ``samples/hren_tappet.toml``.
- ``docs/oscillating.png``: the oscillating followers' convention at φ = 0,
  drawn from the follower modules of the two oscillating samples.
- The Quintero & Vanegas (2016) section 5 table, printed as Markdown.
- ``docs/report.png``: the top of ``report.html`` of ``samples/quintero_vap_b01.toml``
  (the README's picture), built by ``camcad build --only report`` and shot by
  headless Chromium (skipped, saying so, when ``chromium`` is not installed).
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from camcad import load_design  # noqa: E402
from camcad.pipeline import analyse  # noqa: E402


def hren_torque() -> None:
    """Plot M(φ) over the stroke (0°–90°) and the whole turn, with the maximum marked."""
    analysis = analyse(load_design(ROOT / "samples" / "hren_tappet.toml"), fit=False, toolpath=False)
    dyn = analysis.dynamics
    deg = np.degrees(dyn.phi)
    torque = dyn.torque / 1000.0  # N·m
    stroke = deg <= 90.0
    i = int(np.argmax(np.where(stroke, torque, -np.inf)))
    fig = Figure(figsize=(7.5, 3.6), dpi=110)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    ax.plot(deg, torque, color="0.7", lw=1, label="whole turn (return: the spring drives)")
    ax.plot(deg[stroke], torque[stroke], color="#1f4e79", lw=2, label="stroke, 003 eq. 29")
    ax.plot(deg[i], torque[i], "o", color="#c0392b")
    ax.annotate(
        f"max {torque[i]:.2f} N·m at {deg[i]:.1f}°",
        (deg[i], torque[i]),
        textcoords="offset points",
        xytext=(12, -4),
        color="#c0392b",
    )
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xlim(0, 360)
    ax.set_xticks(range(0, 361, 45))
    ax.set_xlabel("cam angle φ [°]")
    ax.set_ylabel("drive torque M [N·m]")
    ax.set_title("Hren et al. Table 1: n = 9, z = 10 mm, r = 50 mm, 1425 rpm", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    fig.savefig(ROOT / "docs" / "hren_torque.png")
    print(f"003 Table 1: max torque over the stroke {torque[i] * 1000:.0f} N·mm at {deg[i]:.1f}°")


def quintero_table() -> None:
    """The four laws of 000 section 5: max pressure angle and max input torque."""
    print("| law | max pressure angle | max input torque [N·mm] (at) | min contact force [N] |")
    print("|---|---|---|---|")
    for stem, label in (
        ("quintero_poly4567", "4-5-6-7 polynomial"),
        ("quintero_harmonic", "harmonic"),
        ("quintero_vap_b02", "VAP b = 0.2"),
        ("quintero_vap_b01", "VAP b = 0.1"),
    ):
        a = analyse(load_design(ROOT / "samples" / f"{stem}.toml"), fit=False, toolpath=False)
        geo, dyn = a.geometry.summary(), a.dynamics.summary()
        print(
            f"| {label} | {geo['pressure_angle_max_deg']:.2f}° | {dyn['torque_max_Nmm']:.1f} "
            f"({dyn['torque_max_angle_deg']:.1f}°) | {dyn['contact_force_min_N']:.3f} |"
        )


def oscillating_convention() -> None:
    """Roller and flat face on an arm at φ = 0: base circle, roller or face, pivot, d, l, β0, rise's sense."""
    from camcad.geometry import Cam

    fig = Figure(figsize=(10.0, 4.8), dpi=110)
    FigureCanvasAgg(fig)
    for k, stem in enumerate(("packaging_rocker", "rocker_flat")):
        cam = Cam.from_design(load_design(ROOT / "samples" / f"{stem}.toml"))
        follower = cam.follower
        ax = fig.add_subplot(1, 2, k + 1)
        t = np.linspace(0, 2 * np.pi, 200)
        rb = cam.base_radius
        ax.plot(rb * np.cos(t), rb * np.sin(t), color="0.5", ls=":", lw=1)
        ax.plot(0, 0, "k+", ms=10)
        sketch = follower.sketch(cam.motion(np.array([0.0])), size=rb)[0]
        for part in sketch.body:
            ax.plot(*part.T, color="#1f4e79", lw=2)
        for part in sketch.links:
            ax.plot(*part.T, color="#c0392b", lw=2)
        px, py = follower.guide.pivot
        ax.plot(px, py, "o", color="#c0392b", ms=6)
        ax.plot([0, px], [0, py], color="0.3", lw=0.8, ls="--")
        ax.annotate("pivot", (px, py), textcoords="offset points", xytext=(6, 6))
        ax.annotate(
            f"d = {cam.follower_spec.pivot_distance:g}",
            (px / 2, py / 2),
            textcoords="offset points",
            xytext=(4, -14),
        )
        if cam.has_pitch_curve:
            centre = follower.element(cam.motion(np.array([0.0]))).m0[0]
            ax.annotate(
                f"l = {cam.follower_spec.arm_length:g}",
                (centre + np.array([px, py])) / 2,
                textcoords="offset points",
                xytext=(-10, -18),
            )
            ax.annotate(
                "roller centre on +y\nat r_b + r_f", centre, textcoords="offset points", xytext=(-110, 10)
            )
            title = "oscillating-roller: β = β0 + ψ, a rise swings the roller outward"
        else:
            ax.annotate(
                "face tangent to the base circle at (0, r_b)",
                (0, rb),
                textcoords="offset points",
                xytext=(-90, -28),
            )
            below = cam.follower_spec.face_offset
            title = f"oscillating-flat: face {below:g} mm below the pivot, a rise lifts it"
        # the sense of a rise: the arm turns clockwise about the pivot
        ax.annotate(
            "",
            xy=(px - 18, py + 12),
            xytext=(px - 22, py - 6),
            arrowprops={"arrowstyle": "->", "color": "#c0392b", "connectionstyle": "arc3,rad=-0.4"},
        )
        ax.text(px - 30, py + 16, "rise", color="#c0392b", fontsize=8)
        ax.margins(0.15)
        ax.set_title(title, fontsize=9)
        ax.set_aspect("equal")
        ax.grid(alpha=0.3)
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
    fig.tight_layout()
    fig.savefig(ROOT / "docs" / "oscillating.png")


def report_page() -> None:
    """Build the VAP sample's report and save a screenshot of its first screen (cam and key numbers)."""
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if browser is None:
        print("docs/report.png not redrawn: no chromium on PATH", file=sys.stderr)
        return
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "out"
        sample = "samples/quintero_vap_b01.toml"  # relative: the report shows this path
        build = [sys.executable, "-m", "camcad", "build", sample, "-o", str(out), "--only", "report", "-q"]
        subprocess.run(build, check=True, cwd=ROOT, env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
        shot = [browser, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars"]
        shot += ["--window-size=1100,830", f"--screenshot={ROOT / 'docs' / 'report.png'}"]
        subprocess.run([*shot, (out / "report.html").as_uri()], check=True, capture_output=True, timeout=120)


if __name__ == "__main__":
    report_page()
    oscillating_convention()
    hren_torque()
    quintero_table()
