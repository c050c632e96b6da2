"""Regenerate the README's paper figures and tables: ``python docs/make_figures.py``.

- ``docs/hren_torque.png``: the drive torque of the Hren et al. Table 1 tappet
  cam over the stroke (003 eq. 29), from ``samples/hren_tappet.toml``.
- The Quintero & Vanegas (2016) section 5 table, printed as Markdown.
"""

from __future__ import annotations

import sys
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


if __name__ == "__main__":
    hren_torque()
    quintero_table()
