"""``camcad tolerance``: a design's ``[tolerance]`` study on local processes or a Dask cluster.

The numbers are :mod:`camcad.inspect.tolerance`'s: the errors of every made
cam are drawn at once in this process (same seed, same variants), cut into
chunks of :data:`CHUNK` variants in a fixed order, and each chunk is
re-solved together (:func:`~camcad.inspect.tolerance.variant_figures`) in
this process, in local worker processes or on a Dask cluster, using the
engines it shares with the sweep (:mod:`camcad.explore.cluster`: the
forkserver pool whose workers end with the command, the scheduler address
and the cluster client). A chunk's figures depend only on its variants, so every engine and
any number of workers give the same rows, byte for byte.

Files, written all or nothing (:func:`camcad.export.atomic.staged_folder`):

- ``tolerance.parquet`` (or ``.csv``): Monte Carlo, one row per made cam
  (``index``, the drawn error of each quantity, the dwell errors, the peak
  |acceleration| and |pressure angle|); ``method = "linear"``, one row per
  cam angle (the nominal lift, velocity and pressure angle with their RSS
  σ and worst-case bands from the exact sensitivities).
- ``tolerance.json``: percentiles, the linear dwell figures, the allocation.
- ``tolerance.html``: the error bands around the nominal curves.
"""

from __future__ import annotations

import base64
import html
import json
import math
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from camcad._typing import FloatArray
from camcad.errors import DesignError, UsageError
from camcad.explore.cluster import dask_map, process_map, scheduler_address, serial_map
from camcad.geometry.cam import Cam
from camcad.geometry.sensitivity import Tol

if TYPE_CHECKING:
    from camcad.dynamics.spec import DynamicsSetup
from camcad.inspect.batch import BATCH, TRUST, certify, response, untrusted
from camcad.inspect.spec import Evaluation, StudyMethod, ToleranceSpec
from camcad.inspect.tolerance import (
    PERCENTILES,
    Distribution,
    LinearDwell,
    Method,
    allocate,
    draw,
    dwell_angles,
    linear_dwell,
    variant_figures,
)

__all__ = [
    "CHUNK",
    "FORMATS",
    "ToleranceChunk",
    "ToleranceResult",
    "evaluate_tolerance_chunk",
    "tolerance_study",
]

CHUNK = 250
"""Made cams per unit of work (and per batch re-solved together)."""
FORMATS = ("parquet", "csv")
STEP = math.radians(1.0)
"""Grid the peaks are found on before refining, and the bands are drawn on [rad]."""
ENVELOPE_VARIANTS = 100
"""Made cams re-solved along the whole turn for the page's Monte-Carlo envelope."""
_Z = 3.0  # the RSS band: ±3σ (99.73 % of a normal spread)

Progress = Callable[[int, int], None]


def _unit(cam: Cam) -> str:
    """The lift's unit: ``mm`` on a slide, ``deg`` of swing on an arm."""
    return cam.follower_spec.kind.lift_unit


def _column(key: str) -> str:
    """The table column of a toleranced quantity's drawn error: ``tolerance.form_pm`` → ``form_mm``."""
    name = key.removeprefix("tolerance.").rsplit("_", 1)[0]
    return name if name.endswith("_deg") else f"{name}_mm"


@dataclass(frozen=True, slots=True, kw_only=True)
class ToleranceChunk:
    """One unit of work: the cam, its dynamics, and the chunk's drawn errors (mm; PHASE rad)."""

    cam: Cam
    start: int
    deltas: tuple[tuple[Tol, FloatArray], ...]
    setup: DynamicsSetup | None = None


Figures = tuple[FloatArray, FloatArray, FloatArray, FloatArray]
"""Dwell errors (V, D), peak |a| (V,), peak |α| [rad] (V,), peak contact stress [MPa] (V,)."""


def evaluate_tolerance_chunk(chunk: ToleranceChunk) -> Figures:
    """The figures of one chunk's made cams, each re-solved (what a worker runs)."""
    return variant_figures(chunk.cam, dict(chunk.deltas), step=STEP, setup=chunk.setup)


def _chunks(
    cam: Cam, spec: ToleranceSpec, drawn: Mapping[Tol, FloatArray], setup: DynamicsSetup | None
) -> list[ToleranceChunk]:
    return [
        ToleranceChunk(
            cam=cam,
            start=lo,
            deltas=tuple((t.tol, np.array(drawn[t.tol][lo : lo + CHUNK])) for t in spec.tolerances),
            setup=setup,
        )
        for lo in range(0, spec.samples, CHUNK)
    ]


def _exact(
    cam: Cam,
    spec: ToleranceSpec,
    drawn: Mapping[Tol, FloatArray],
    setup: DynamicsSetup | None,
    *,
    jobs: int,
    scheduler: str | None,
    progress: Progress | None,
) -> Figures:
    chunks = _chunks(cam, spec, drawn, setup)
    if scheduler is not None:
        results = dask_map(evaluate_tolerance_chunk, chunks, scheduler)
    elif jobs == 1 or len(chunks) == 1:
        results = serial_map(evaluate_tolerance_chunk, chunks)
    else:
        results = process_map(
            evaluate_tolerance_chunk,
            chunks,
            min(jobs, len(chunks)),
            died="a tolerance worker process died (killed, or out of memory)",
        )
    done: dict[int, Figures] = {}
    for k, figures in results:
        done[k] = figures
        if progress is not None:
            progress(len(done), len(chunks))
    parts = [done[k] for k in range(len(chunks))]
    d = len(dwell_angles(cam))
    return (
        np.vstack([p[0] for p in parts]) if parts else np.zeros((0, d)),
        *(np.concatenate([p[i] for p in parts]) for i in (1, 2, 3)),
    )  # type: ignore[return-value]


def run_variants(
    cam: Cam,
    spec: ToleranceSpec,
    *,
    setup: DynamicsSetup | None = None,
    jobs: int = 1,
    scheduler: str | None = None,
    progress: Progress | None = None,
    batch: int = BATCH,
) -> tuple[dict[str, FloatArray], dict[str, Any]]:
    """Every made cam's figures as table columns in variant order, and how they were evaluated.

    ``spec.evaluation`` EXACT: each made cam re-solved on the engine chosen
    (see the module notes); QUADRATIC: the certified quadratics
    (:mod:`camcad.inspect.batch`) in this process, ``batch`` variants at a
    time (the engines are not needed: 10⁶ variants take seconds).
    """
    if jobs < 1:
        raise UsageError("--jobs", f"{jobs} is not allowed (allowed: 1 or more worker processes)")
    drawn = draw(spec.tolerances, samples=spec.samples, seed=spec.seed)
    how: dict[str, Any] = {"method": spec.evaluation.value}
    if spec.evaluation is Evaluation.QUADRATIC:
        fitted = response(cam, spec.tolerances, setup=setup, step=STEP)
        figures = fitted.figures(drawn, batch=batch)
        cert = certify(cam, fitted, drawn, setup=setup, step=STEP)
        bad = untrusted(cert, figures, lift=float(np.max(np.abs(cam.motion(cam.sample_phi(STEP)).s))))
        if bad:
            raise DesignError(
                "tolerance.evaluation",
                f'"quadratic" does not hold for these tolerances ({", ".join(bad)}: the made cams '
                f're-solved exactly differ by more than {TRUST:g} of the spread); allowed: "exact"',
            )
        if progress is not None:
            progress(1, 1)
        how |= {
            "stencil_variants": fitted.stencil_variants,
            "certified_variants": len(cert.indices),
            "max_abs_difference_from_exact": {
                f"dwell_error_{_unit(cam)}": _finite(cert.dwell),
                f"peak_acceleration_{_unit(cam)}_per_rad2": _finite(cert.acceleration),
                "peak_pressure_angle_deg": _finite(math.degrees(cert.pressure_angle)),
                "peak_contact_stress_mpa": _finite(cert.stress),
            },
        }
    else:
        figures = _exact(cam, spec, drawn, setup, jobs=jobs, scheduler=scheduler, progress=progress)
    return _columns(cam, spec, drawn, figures), how


def _finite(value: float) -> float | None:
    return None if math.isnan(value) else value


def _columns(
    cam: Cam, spec: ToleranceSpec, drawn: Mapping[Tol, FloatArray], figures: Figures
) -> dict[str, FloatArray]:
    """The table: ``index``, the drawn errors (phase in degrees), the dwell errors and the peaks."""
    unit = _unit(cam)
    dwell_err, acc, alpha, stress = figures
    out: dict[str, FloatArray] = {"index": np.arange(spec.samples, dtype=np.int64)}
    for key, t in zip(spec.keys, spec.tolerances, strict=True):
        values = np.asarray(drawn[t.tol], dtype=float)
        out[_column(key)] = np.degrees(values) if t.tol is Tol.PHASE else values
    for k in range(dwell_err.shape[1]):
        out[f"dwell_error_{k}_{unit}"] = np.ascontiguousarray(dwell_err[:, k])
    out[f"peak_acceleration_{unit}_per_rad2"] = acc
    out["peak_pressure_angle_deg"] = np.degrees(alpha)
    out["peak_contact_stress_mpa"] = stress
    return out


CSV_ROWS = 20_000
"""Rows formatted at once when the CSV is written (its memory does not grow with the study)."""


def _csv_lines(columns: Mapping[str, FloatArray]) -> Iterator[str]:
    """The table as CSV text pieces: floats by ``repr`` (read back bit for bit), NaN as an empty cell."""
    names = list(columns)
    yield ",".join(names) + "\n"
    count = len(next(iter(columns.values()))) if names else 0
    for lo in range(0, count, CSV_ROWS):
        cells = []
        for name in names:
            values = columns[name][lo : lo + CSV_ROWS]
            if values.dtype.kind == "i":
                cells.append([str(v) for v in values.tolist()])
            else:
                cells.append(["" if v != v else repr(v) for v in values.tolist()])
        yield "".join(",".join(row) + "\n" for row in zip(*cells, strict=True))


def _write_csv(path: Path, columns: Mapping[str, FloatArray]) -> None:
    with path.open("w", encoding="utf-8", newline="") as out:
        out.writelines(_csv_lines(columns))


def _parquet(columns: Mapping[str, FloatArray]) -> bytes:
    """The table as Parquet (zstd), NaN as null."""
    import io

    import pyarrow as pa
    import pyarrow.parquet as pq

    arrays = {
        name: pa.array(v) if v.dtype.kind == "i" else pa.array(v, mask=np.isnan(v))
        for name, v in columns.items()
    }
    buf = io.BytesIO()
    pq.write_table(pa.table(arrays), buf, compression="zstd")
    return buf.getvalue()


# -- the linear figures, the bands, the summary ---------------------------------------------------


@dataclass(frozen=True, slots=True, kw_only=True)
class Bands:
    """Nominal curves at ``phi`` (n,) [rad] and their first-order error bands (±3σ RSS and worst case).

    Lift and velocity in the lift unit (per rad); pressure angle in degrees.
    """

    phi: FloatArray
    nominal: Mapping[str, FloatArray]
    rss: Mapping[str, FloatArray]
    worst: Mapping[str, FloatArray]


def linear_bands(cam: Cam, spec: ToleranceSpec, phi: FloatArray) -> Bands:
    """The bands from the exact sensitivities (:func:`camcad.geometry.sensitivity.sensitivities`)."""
    from camcad.geometry.sensitivity import sensitivities

    sens = sensitivities(cam, phi)
    motion = cam.motion(phi)
    nominal = {
        "lift": np.asarray(motion.s, dtype=float),
        "velocity": np.asarray(motion.v, dtype=float),
        "pressure_angle": np.degrees(np.asarray(cam.pressure_angle(phi), dtype=float)),
    }
    rss: dict[str, FloatArray] = {}
    worst: dict[str, FloatArray] = {}
    for name, table, scale in (
        ("lift", sens.lift, 1.0),
        ("velocity", sens.velocity, 1.0),
        ("pressure_angle", sens.pressure_angle, math.degrees(1.0)),
    ):
        rows = np.array([table[sens.row(t.tol)] for t in spec.tolerances])  # (K, n)
        sig = np.array([t.value * t.distribution.sigma_per_tolerance for t in spec.tolerances])
        tv = np.array([t.value for t in spec.tolerances])
        rss[name] = _Z * np.sqrt(np.sum((rows * sig[:, None]) ** 2, axis=0)) * scale
        worst[name] = np.sum(np.abs(rows) * tv[:, None], axis=0) * scale
    return Bands(phi=phi, nominal=nominal, rss=rss, worst=worst)


def _band_columns(bands: Bands, unit: str) -> dict[str, FloatArray]:
    names = {
        "lift": f"lift_{unit}",
        "velocity": f"velocity_{unit}_per_rad",
        "pressure_angle": "pressure_angle_deg",
    }
    out: dict[str, FloatArray] = {"angle_deg": np.degrees(bands.phi)}
    for key, name in names.items():
        out[name] = np.asarray(bands.nominal[key], dtype=float)
        out[f"{name}_rss3sigma"] = np.asarray(bands.rss[key], dtype=float)
        out[f"{name}_worst_case"] = np.asarray(bands.worst[key], dtype=float)
    return out


def _pct(values: FloatArray) -> list[float] | None:
    finite = values[np.isfinite(values)]
    return None if finite.size == 0 else [float(v) for v in np.percentile(finite, PERCENTILES)]


def _allocation(spec: ToleranceSpec, lin: LinearDwell, unit: str) -> dict[str, Any] | None:
    if spec.dwell_accuracy is None:
        return None
    dists = {t.distribution for t in spec.tolerances}
    distribution = dists.pop() if len(dists) == 1 else Distribution.UNIFORM  # mixed: the wider spread
    alloc = allocate(
        lin.coefficients,
        lin.parameters,
        required=spec.dwell_accuracy,
        method=spec.allocation,
        confidence=spec.confidence,
        distribution=distribution,
    )
    if spec.allocation is Method.WORST_CASE:
        now = lin.worst_case
    else:
        from scipy.stats import norm

        now = float(norm.ppf(0.5 + 0.5 * spec.confidence)) * lin.sigma
    largest = {}
    for key, t in zip(spec.keys, spec.tolerances, strict=True):
        v = alloc.tolerances[t.tol]
        shown = math.degrees(v) if t.tol is Tol.PHASE else v
        largest[key.removeprefix("tolerance.").rsplit("_", 1)[0] + "_pm"] = (
            None if math.isinf(shown) else shown
        )
    return {
        "dwell_accuracy": spec.dwell_accuracy,
        "unit": unit,
        "method": spec.allocation.value,
        "confidence": alloc.confidence,
        "distribution": distribution.value,
        "largest_tolerances": largest,
        "predicted_dwell_error": [float(v) for v in alloc.predicted],
        "given_tolerances_dwell_error": [float(v) for v in now],
        "given_tolerances_meet_it": bool(np.all(now <= spec.dwell_accuracy)),
    }


def _nominal_peaks(cam: Cam, setup: DynamicsSetup | None) -> tuple[float, float, float]:
    """Peak |a| [lift unit/rad²], |α| [rad] and contact stress [MPa] of the design, as for a made cam."""
    _, acc, alpha, stress = variant_figures(cam, {Tol.FORM: np.zeros(1)}, step=STEP, setup=setup)
    return float(acc[0]), float(alpha[0]), float(stress[0])


def tolerance_summary(
    cam: Cam,
    spec: ToleranceSpec,
    columns: Mapping[str, FloatArray] | None,
    *,
    name: str,
    source: str,
    setup: DynamicsSetup | None = None,
    evaluation: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """The figures of ``tolerance.json`` (columns: the Monte-Carlo table, or None for the linear method)."""
    unit = _unit(cam)
    lin = linear_dwell(cam, spec.tolerances)
    acc0, alpha0, stress0 = _nominal_peaks(cam, setup)
    dwells = []
    for k, phi in enumerate(lin.dwell_phi):
        entry: dict[str, Any] = {
            "angle_deg": math.degrees(float(phi)),
            "linear": {
                "sigma": float(lin.sigma[k]),
                "worst_case": float(lin.worst_case[k]),
                "per_unit_error": {
                    key: float(lin.coefficients[k, j]) * (math.radians(1.0) if t.tol is Tol.PHASE else 1.0)
                    for j, (key, t) in enumerate(zip(spec.keys, spec.tolerances, strict=True))
                },
            },
        }
        if columns is not None:
            values = np.asarray(columns[f"dwell_error_{k}_{unit}"], dtype=float)
            entry["monte_carlo"] = {
                "mean": float(np.mean(values)),
                "std": float(np.std(values, ddof=1)),
                "percentiles": _pct(values),
            }
        dwells.append(entry)
    out: dict[str, Any] = {
        "design": name,
        "source": source,
        "method": spec.method.value,
        "lift_unit": unit,
        "tolerances": [
            {
                "key": key,
                "quantity": t.tol.value,
                "tolerance": math.degrees(t.value) if t.tol is Tol.PHASE else t.value,
                "unit": "deg" if t.tol is Tol.PHASE else "mm",
                "distribution": t.distribution.value,
            }
            for key, t in zip(spec.keys, spec.tolerances, strict=True)
        ],
        "percentiles_at": list(PERCENTILES),
        "dwells": dwells,
    }
    out["peak_acceleration"] = {"unit": f"{unit}/rad^2", "nominal": _finite(acc0)}
    out["peak_pressure_angle"] = {"unit": "deg", "nominal": math.degrees(alpha0)}
    out["contact_stress"] = {"unit": "MPa", "nominal": _finite(stress0)}
    if columns is not None:
        out["samples"], out["seed"] = spec.samples, spec.seed
        out["evaluation"] = dict(evaluation or {"method": spec.evaluation.value})
        out["peak_acceleration"]["percentiles"] = _pct(columns[f"peak_acceleration_{unit}_per_rad2"])
        out["peak_pressure_angle"]["percentiles"] = _pct(columns["peak_pressure_angle_deg"])
        out["contact_stress"]["percentiles"] = _pct(columns["peak_contact_stress_mpa"])
    if math.isnan(stress0):
        out["contact_stress_note"] = (
            "not computed: no dynamics setup given"
            if setup is None
            else "not computed: a groove's flanks, or a face on an arm (its made acceleration is not found)"
        )
    out["allocation"] = _allocation(spec, lin, unit)
    return out


# -- the page -------------------------------------------------------------------------------------

_CSS = (
    "body{font-family:system-ui,sans-serif;margin:2em;color:#222}"
    "table{border-collapse:collapse;font-size:0.85em}td,th{border:1px solid #ccc;padding:2px 6px}"
    "td.n{text-align:right;font-variant-numeric:tabular-nums}figure{margin:1em 0}"
    "img{max-width:100%;height:auto}"
)


def _e(text: object) -> str:
    plain = "".join("\ufffd" if ord(c) < 32 or ord(c) == 127 else c for c in str(text))
    return html.escape(plain, quote=True)


def _envelope(cam: Cam, spec: ToleranceSpec, phi: FloatArray) -> dict[str, tuple[FloatArray, FloatArray]]:
    """Min and max of the errors of the first :data:`ENVELOPE_VARIANTS` made cams, re-solved at ``phi``."""
    from camcad.geometry.made import made_motion

    drawn = draw(spec.tolerances, samples=spec.samples, seed=spec.seed)
    part = {k: v[:ENVELOPE_VARIANTS] for k, v in drawn.items()}
    made = made_motion(cam, phi, deltas=part)
    motion = cam.motion(phi)
    errors = {
        "lift": made.lift - motion.s,
        "velocity": made.velocity - motion.v,
        "pressure_angle": np.degrees(made.pressure_angle - cam.pressure_angle(phi)),
    }
    return {k: (np.min(v, axis=0), np.max(v, axis=0)) for k, v in errors.items()}


def _band_figure(bands: Bands, key: str, label: str, envelope: tuple[FloatArray, FloatArray] | None) -> str:
    from camcad._plots import figure, svg

    fig = figure((7.0, 3.0))
    ax = fig.add_subplot()
    x = np.degrees(bands.phi)
    ax.fill_between(x, -bands.worst[key], bands.worst[key], color="#dbe6f2", lw=0, label="worst case")
    ax.fill_between(x, -bands.rss[key], bands.rss[key], color="#7f9fbf", lw=0, label="±3σ (RSS)")
    if envelope is not None:
        ax.plot(x, envelope[0], color="#c0392b", lw=0.8, label=f"Monte Carlo, {ENVELOPE_VARIANTS} cams")
        ax.plot(x, envelope[1], color="#c0392b", lw=0.8)
    ax.axhline(0.0, color="#222222", lw=0.8)
    ax.set_xlim(0.0, 360.0)
    ax.set_xlabel("cam angle [°]", fontsize=9)
    ax.set_ylabel(label, fontsize=9)
    ax.tick_params(labelsize=8)
    ax.grid(True, color="#eeeeee", linewidth=0.6)
    ax.legend(fontsize=7, loc="upper right")
    return base64.b64encode(svg(fig)).decode("ascii")


def _peaks_table(summary: Mapping[str, Any], unit: str, pct_head: str) -> list[str]:
    """The peaks' section: each figure's design value and its Monte-Carlo percentiles."""
    rows = []
    for key, label in (
        ("peak_acceleration", f"peak |acceleration| [{unit}/rad²]"),
        ("peak_pressure_angle", "peak |pressure angle| [°]"),
        ("contact_stress", "peak contact stress [MPa]"),
    ):
        fig = summary.get(key) or {}
        nominal = fig.get("nominal")
        cells = "".join(f'<td class="n">{v:.5g}</td>' for v in (fig.get("percentiles") or []) if pct_head)
        shown = "—" if nominal is None else f"{nominal:.5g}"
        rows.append(f'<tr><td>{_e(label)}</td><td class="n">{shown}</td>{cells}</tr>')
    out = [
        "<h2>Peaks of the made cams</h2>",
        f"<table><tr><th>figure</th><th>design</th>{pct_head}</tr>" + "".join(rows) + "</table>",
    ]
    note = summary.get("contact_stress_note")
    if note:
        out.append(f"<p>Contact stress {_e(note)}.</p>")
    how = summary.get("evaluation") or {}
    if how.get("method") == "quadratic":
        worst = "; ".join(
            f"{_e(k)} {'—' if v is None else f'{v:.2g}'}"
            for k, v in how["max_abs_difference_from_exact"].items()
        )
        out.append(
            f"<p>Evaluated by quadratics fitted on {how['stencil_variants']} re-solved made cams; on "
            f"{how['certified_variants']} of these made cams re-solved exactly the largest differences were: "
            f"{worst}.</p>"
        )
    return out


def tolerance_page(cam: Cam, spec: ToleranceSpec, summary: Mapping[str, Any], *, table: str) -> str:
    """The HTML text of ``tolerance.html``."""
    unit = summary["lift_unit"]
    phi = cam.sample_phi(STEP)
    bands = linear_bands(cam, spec, phi)
    env = _envelope(cam, spec, phi) if spec.method is StudyMethod.MONTE_CARLO else {}
    tol_rows = "".join(
        f'<tr><td><code>{_e(t["key"])}</code></td><td class="n">±{t["tolerance"]:.6g} {_e(t["unit"])}</td>'
        f"<td>{_e(t['distribution'])}</td></tr>"
        for t in summary["tolerances"]
    )
    pct_head = "".join(f"<th>{p:g} %</th>" for p in summary["percentiles_at"])
    dwell_rows = []
    for k, d in enumerate(summary["dwells"]):
        mc = d.get("monte_carlo")
        cells = "".join(f'<td class="n">{v:.4g}</td>' for v in (mc["percentiles"] if mc else []))
        dwell_rows.append(
            f"<tr><td>dwell {k} at {d['angle_deg']:.1f}°</td>"
            f'<td class="n">{d["linear"]["sigma"]:.4g}</td><td class="n">{d["linear"]["worst_case"]:.4g}</td>'
            f"{cells}</tr>"
        )
    body = [
        f"<h1>Tolerances of {_e(summary['design'])}</h1>",
        f"<p>From {_e(summary['source'])}; method {_e(summary['method'])}"
        + (f", {summary['samples']} made cams, seed {summary['seed']}" if "samples" in summary else "")
        + f". Every figure is in <code>tolerance.json</code>, every row in <code>{_e(table)}</code>.</p>",
        "<h2>Tolerances</h2><table><tr><th>key</th><th>tolerance</th><th>drawn</th></tr>"
        + tol_rows
        + "</table>",
        f"<h2>Dwell position error [{_e(unit)}]</h2>",
        f"<table><tr><th>dwell</th><th>σ (linear)</th><th>worst case</th>{pct_head if env else ''}</tr>"
        + "".join(dwell_rows)
        + "</table>",
    ]
    body += _peaks_table(summary, unit, pct_head if env else "")
    alloc = summary.get("allocation")
    if alloc is not None:
        items = "".join(
            f'<tr><td><code>{_e(k)}</code></td><td class="n">{"any" if v is None else f"±{v:.4g}"}</td></tr>'
            for k, v in alloc["largest_tolerances"].items()
        )
        verdict = "meet" if alloc["given_tolerances_meet_it"] else "do NOT meet"
        body += [
            "<h2>Allocation</h2>",
            f"<p>Largest symmetric tolerances keeping every dwell within ±{alloc['dwell_accuracy']:g} "
            f"{_e(unit)} ({_e(alloc['method'])}, confidence {alloc['confidence']:g}); the given tolerances "
            f"{verdict} it.</p><table><tr><th>key</th><th>largest</th></tr>{items}</table>",
        ]
    body.append(
        "<h2>Error bands along the turn</h2><p>Made minus nominal: the first-order bands from the exact "
        "sensitivities (±3σ RSS and the worst case)"
        + (", and the range of the first made cams re-solved" if env else "")
        + ".</p>"
    )
    for key, label in (
        ("lift", f"lift error [{unit}]"),
        ("velocity", f"velocity error [{unit}/rad]"),
        ("pressure_angle", "pressure angle error [°]"),
    ):
        png = _band_figure(bands, key, label, env.get(key))
        body.append(
            f'<figure id="{key}"><img alt="{_e(label)}" src="data:image/svg+xml;base64,{png}"></figure>'
        )
    return (
        '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        f"<title>Tolerances of {_e(summary['design'])}</title>\n<style>{_CSS}</style>\n</head>\n<body>\n"
        + "\n".join(body)
        + "\n</body>\n</html>\n"
    )


# -- the command ----------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True, kw_only=True)
class ToleranceResult:
    """The files written, the table's columns and the summary of ``tolerance.json``."""

    files: tuple[Path, ...]
    columns: Mapping[str, FloatArray]
    summary: dict[str, Any]

    @property
    def rows(self) -> list[dict[str, Any]]:
        """The table as one mapping per row (NaN as None): for small studies."""
        names = list(self.columns)
        lists = [self.columns[n].tolist() for n in names]
        return [
            {n: (None if isinstance(v, float) and v != v else v) for n, v in zip(names, row, strict=True)}
            for row in zip(*lists, strict=True)
        ]


def tolerance_study(
    cam: Cam,
    spec: ToleranceSpec,
    outdir: str | Path,
    *,
    name: str,
    source: str,
    fmt: str = "parquet",
    jobs: int = 1,
    scheduler: str | None = None,
    progress: Progress | None = None,
    setup: DynamicsSetup | None = None,
) -> ToleranceResult:
    """Run the study and write ``tolerance.{parquet,csv}``, ``tolerance.json`` and ``tolerance.html``.

    Raises
    ------
    UsageError
        ``--format`` not parquet or csv, Parquet without pyarrow, a bad
        ``--jobs`` or an unreachable ``--scheduler``.
    OutputError
        When ``outdir`` cannot be written.
    """
    from camcad.export.atomic import atomic_write, atomic_write_bytes, atomic_write_text, staged_folder

    if fmt not in FORMATS:
        raise UsageError("--format", f"{fmt!r} is not allowed (allowed: {', '.join(FORMATS)})")
    if scheduler is not None:
        scheduler_address(scheduler)
    if fmt == "parquet":
        try:
            import pyarrow.parquet  # noqa: F401
        except ImportError:
            raise UsageError(
                "--format", "parquet needs pyarrow: pip install 'camcad[cluster]', or use --format csv"
            ) from None
    if jobs < 1:
        raise UsageError("--jobs", f"{jobs} is not allowed (allowed: 1 or more worker processes)")
    linear_dwell(cam, spec.tolerances)  # refused before any work: a tolerance that does not apply
    if spec.method is StudyMethod.MONTE_CARLO:
        columns, how = run_variants(cam, spec, setup=setup, jobs=jobs, scheduler=scheduler, progress=progress)
        summary = tolerance_summary(cam, spec, columns, name=name, source=source, setup=setup, evaluation=how)
    else:
        columns = _band_columns(linear_bands(cam, spec, cam.sample_phi(STEP)), _unit(cam))
        summary = tolerance_summary(cam, spec, None, name=name, source=source, setup=setup)
    table = f"tolerance.{fmt}"
    page = tolerance_page(cam, spec, summary, table=table)
    text = json.dumps(summary, indent=2, ensure_ascii=False, allow_nan=False) + "\n"
    outdir = Path(outdir)
    with staged_folder(outdir) as staging:
        if fmt == "parquet":
            atomic_write_bytes(staging.path / table, _parquet(columns))
        else:
            atomic_write(staging.path / table, lambda path: _write_csv(path, columns))
        atomic_write_text(staging.path / "tolerance.json", text)
        atomic_write_text(staging.path / "tolerance.html", page)
    names = (table, "tolerance.json", "tolerance.html")
    return ToleranceResult(files=tuple(outdir / n for n in names), columns=columns, summary=summary)
