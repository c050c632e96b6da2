"""``camcad tolerance``: a design's ``[tolerance]`` study on local processes or a Dask cluster.

The numbers are :mod:`camcad.inspect.tolerance`'s: the errors of every made
cam are drawn at once in this process (same seed, same variants), cut into
chunks of :data:`CHUNK` variants in a fixed order, and each chunk is
re-solved together (:func:`~camcad.inspect.tolerance.variant_figures`) in
this process, in local worker processes or on a Dask cluster, using the
sweep's engines (:mod:`camcad.explore.sweep`: the forkserver pool whose
workers end with the command, the scheduler address and the cluster
client). A chunk's figures depend only on its variants, so every engine and
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
import os
import sys
from collections.abc import Callable, Iterator, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from camcad._typing import FloatArray
from camcad.errors import CamcadError, UsageError
from camcad.geometry.cam import Cam
from camcad.geometry.sensitivity import Tol
from camcad.inspect.spec import StudyMethod, ToleranceSpec
from camcad.inspect.tolerance import (
    PERCENTILES,
    Distribution,
    LinearDwell,
    Method,
    allocate,
    draw,
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
    """One unit of work: the cam, the first variant's index, and the chunk's drawn errors (mm; PHASE rad)."""

    cam: Cam
    start: int
    deltas: tuple[tuple[Tol, FloatArray], ...]
    columns: tuple[str, ...]


def evaluate_tolerance_chunk(chunk: ToleranceChunk) -> list[dict[str, Any]]:
    """The rows of one chunk (what a worker runs)."""
    deltas = dict(chunk.deltas)
    dwell_err, acc, alpha = variant_figures(chunk.cam, deltas, step=STEP)
    unit = _unit(chunk.cam)
    rows = []
    for i in range(dwell_err.shape[0]):
        row: dict[str, Any] = {"index": chunk.start + i}
        for (tol, values), column in zip(chunk.deltas, chunk.columns, strict=True):
            row[column] = math.degrees(float(values[i])) if tol is Tol.PHASE else float(values[i])
        for k in range(dwell_err.shape[1]):
            row[f"dwell_error_{k}_{unit}"] = float(dwell_err[i, k])
        row[f"peak_acceleration_{unit}_per_rad2"] = None if math.isnan(acc[i]) else float(acc[i])
        row["peak_pressure_angle_deg"] = math.degrees(float(alpha[i]))
        rows.append(row)
    return rows


def _chunks(cam: Cam, spec: ToleranceSpec) -> list[ToleranceChunk]:
    drawn = draw(spec.tolerances, samples=spec.samples, seed=spec.seed)
    columns = tuple(_column(k) for k in spec.keys)
    return [
        ToleranceChunk(
            cam=cam,
            start=lo,
            deltas=tuple((t.tol, np.array(drawn[t.tol][lo : lo + CHUNK])) for t in spec.tolerances),
            columns=columns,
        )
        for lo in range(0, spec.samples, CHUNK)
    ]


# -- engines (the sweep's: its worker lifetime and its cluster client) ---------------------------


def _serial(chunks: Sequence[ToleranceChunk]) -> Iterator[tuple[int, list[dict[str, Any]]]]:
    for k, chunk in enumerate(chunks):
        yield k, evaluate_tolerance_chunk(chunk)


def _processes(chunks: Sequence[ToleranceChunk], jobs: int) -> Iterator[tuple[int, list[dict[str, Any]]]]:
    import multiprocessing

    from camcad.explore.sweep import _die_with

    method = "forkserver" if sys.platform != "win32" else "spawn"
    with ProcessPoolExecutor(
        max_workers=jobs,
        mp_context=multiprocessing.get_context(method),
        initializer=_die_with,
        initargs=(os.getpid(),),
    ) as pool:
        futures = {pool.submit(evaluate_tolerance_chunk, chunk): k for k, chunk in enumerate(chunks)}
        try:
            for future in as_completed(futures):
                try:
                    rows = future.result()
                except BrokenProcessPool as err:
                    raise CamcadError("a tolerance worker process died (killed, or out of memory)") from err
                yield futures[future], rows
        finally:
            for future in futures:
                future.cancel()


def _dask(chunks: Sequence[ToleranceChunk], scheduler: str) -> Iterator[tuple[int, list[dict[str, Any]]]]:
    try:
        from distributed import as_completed as dask_completed
    except ImportError:
        raise UsageError("--scheduler", "needs dask.distributed: pip install 'camcad[cluster]'") from None
    from camcad.explore.sweep import _connect, _quiet_distributed

    with _quiet_distributed():
        client = _connect(scheduler)
        try:
            futures = client.map(evaluate_tolerance_chunk, list(chunks), pure=False)
            index = {future.key: k for k, future in enumerate(futures)}
            try:
                with client.as_current():
                    for future, rows in dask_completed(futures, with_results=True):
                        yield index[future.key], rows
            finally:
                client.cancel(futures)
        finally:
            client.close()


def run_variants(
    cam: Cam,
    spec: ToleranceSpec,
    *,
    jobs: int = 1,
    scheduler: str | None = None,
    progress: Progress | None = None,
) -> list[dict[str, Any]]:
    """Every made cam's row, in variant order, on the engine chosen (see the module notes)."""
    if jobs < 1:
        raise UsageError("--jobs", f"{jobs} is not allowed (allowed: 1 or more worker processes)")
    chunks = _chunks(cam, spec)
    if scheduler is not None:
        results = _dask(chunks, scheduler)
    elif jobs == 1 or len(chunks) == 1:
        results = _serial(chunks)
    else:
        results = _processes(chunks, min(jobs, len(chunks)))
    done: dict[int, list[dict[str, Any]]] = {}
    for k, rows in results:
        done[k] = rows
        if progress is not None:
            progress(len(done), len(chunks))
    return [row for k in range(len(chunks)) for row in done[k]]


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


def _band_rows(bands: Bands, unit: str) -> list[dict[str, Any]]:
    names = {
        "lift": f"lift_{unit}",
        "velocity": f"velocity_{unit}_per_rad",
        "pressure_angle": "pressure_angle_deg",
    }
    rows = []
    for i, phi in enumerate(bands.phi):
        row: dict[str, Any] = {"angle_deg": math.degrees(float(phi))}
        for key, name in names.items():
            row[name] = float(bands.nominal[key][i])
            row[f"{name}_rss3sigma"] = float(bands.rss[key][i])
            row[f"{name}_worst_case"] = float(bands.worst[key][i])
        rows.append(row)
    return rows


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


def _nominal_peaks(cam: Cam) -> tuple[float, float]:
    """Peak |a| [lift unit/rad²] and |α| [rad] of the design, found as for a made cam with no error."""
    _, acc, alpha = variant_figures(cam, {Tol.FORM: np.zeros(1)}, step=STEP)
    return float(acc[0]), float(alpha[0])


def tolerance_summary(
    cam: Cam, spec: ToleranceSpec, rows: Sequence[Mapping[str, Any]] | None, *, name: str, source: str
) -> dict[str, Any]:
    """The figures of ``tolerance.json`` (rows: the Monte-Carlo table, or None for the linear method)."""
    unit = _unit(cam)
    lin = linear_dwell(cam, spec.tolerances)
    acc0, alpha0 = _nominal_peaks(cam)
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
        if rows is not None:
            values = np.array([r[f"dwell_error_{k}_{unit}"] for r in rows], dtype=float)
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
    acc_key = f"peak_acceleration_{unit}_per_rad2"
    out["peak_acceleration"] = {"unit": f"{unit}/rad^2", "nominal": None if math.isnan(acc0) else acc0}
    out["peak_pressure_angle"] = {"unit": "deg", "nominal": math.degrees(alpha0)}
    if rows is not None:
        out["samples"], out["seed"] = spec.samples, spec.seed
        acc = np.array([math.nan if r[acc_key] is None else r[acc_key] for r in rows], dtype=float)
        out["peak_acceleration"]["percentiles"] = _pct(acc)
        alpha = np.array([r["peak_pressure_angle_deg"] for r in rows], dtype=float)
        out["peak_pressure_angle"]["percentiles"] = _pct(alpha)
    out["contact_stress"] = None
    out["contact_stress_note"] = (
        "not computed: a made cam's contact force needs the dynamics re-run per variant, which the batch "
        "re-solve of the motion does not do"
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
    from camcad._plots._base import figure, svg

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
    """The files written, the table's rows and the summary of ``tolerance.json``."""

    files: tuple[Path, ...]
    rows: tuple[dict[str, Any], ...]
    summary: dict[str, Any]


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
    from camcad.explore.sweep import scheduler_address
    from camcad.explore.table import csv_text, parquet_bytes
    from camcad.export.atomic import atomic_write_bytes, atomic_write_text, staged_folder

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
        rows = run_variants(cam, spec, jobs=jobs, scheduler=scheduler, progress=progress)
        summary = tolerance_summary(cam, spec, rows, name=name, source=source)
    else:
        rows = _band_rows(linear_bands(cam, spec, cam.sample_phi(STEP)), _unit(cam))
        summary = tolerance_summary(cam, spec, None, name=name, source=source)
    table = f"tolerance.{fmt}"
    page = tolerance_page(cam, spec, summary, table=table)
    text = json.dumps(summary, indent=2, ensure_ascii=False, allow_nan=False) + "\n"
    outdir = Path(outdir)
    with staged_folder(outdir) as staging:
        if fmt == "parquet":
            atomic_write_bytes(staging.path / table, parquet_bytes(rows))
        else:
            atomic_write_text(staging.path / table, csv_text(rows))
        atomic_write_text(staging.path / "tolerance.json", text)
        atomic_write_text(staging.path / "tolerance.html", page)
    names = (table, "tolerance.json", "tolerance.html")
    return ToleranceResult(files=tuple(outdir / n for n in names), rows=tuple(rows), summary=summary)
