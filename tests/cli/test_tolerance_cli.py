"""``camcad tolerance``: the [tolerance] table, the study's files, its engines and its refusals.

Truths: the Monte-Carlo spread of the dwell error against the linear σ from
the exact sensitivities (within the sampling error); the linear bands against
the follower re-solved on a made cam (:func:`camcad.geometry.made.made_motion`,
agreement to second order); the allocation against a Monte Carlo of parts
made to the allocated tolerances; the cluster and process runs against the
serial run (identical bytes).
"""

from __future__ import annotations

import csv
import json
import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import tomllib

from camcad.cli import main
from camcad.design import load_design
from camcad.geometry.cam import Cam
from camcad.geometry.made import made_motion
from camcad.geometry.sensitivity import Tol
from camcad.inspect.tolerance import Distribution, Tolerance, monte_carlo
from tests.conftest import ROOT

SAMPLE = ROOT / "samples" / "tolerance_roller.toml"
BASE = SAMPLE.read_text(encoding="utf-8").split("\n[tolerance]\n")[0] + "\n"


def _design(tmp_path: Path, table: str, name: str = "d.toml") -> Path:
    path = tmp_path / name
    path.write_text(BASE + "[tolerance]\n" + table, encoding="utf-8")
    return path


def _rows(path: Path) -> list[dict[str, str]]:
    with path.open(newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


SMALL = "form_pm = 0.01\noffset_pm = 0.02\nroller_radius_sigma = 0.002\nphase_deg_pm = 0.05\nseed = 3\n"


@pytest.fixture(scope="module")
def serial(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, bytes]:
    """A 300-variant Monte Carlo in this process (two chunks: 250 and 50)."""
    tmp = tmp_path_factory.mktemp("serial")
    design = _design(tmp, SMALL + "samples = 300\ndwell_accuracy = 0.02\n")
    assert (
        main(["tolerance", str(design), "-o", str(tmp / "out"), "--format", "csv", "--jobs", "1", "-q"]) == 0
    )
    return tmp / "out", (tmp / "out" / "tolerance.csv").read_bytes()


def test_monte_carlo_spread_agrees_with_the_linear_sigma(serial):
    """Small tolerances: the sample σ of each dwell error within 4 standard errors of the linear σ."""
    out, _ = serial
    summary = json.loads((out / "tolerance.json").read_text(encoding="utf-8"))
    rows = _rows(out / "tolerance.csv")
    assert len(rows) == 300 and [int(r["index"]) for r in rows] == list(range(300))
    assert len(summary["dwells"]) == 2
    for k, dwell in enumerate(summary["dwells"]):
        values = np.array([float(r[f"dwell_error_{k}_mm"]) for r in rows])
        sigma = dwell["linear"]["sigma"]
        standard_error = sigma / math.sqrt(2 * (values.size - 1))  # of a sample σ (normal approximation)
        assert abs(np.std(values, ddof=1) - sigma) < 4 * standard_error
        assert abs(np.mean(values)) < 4 * sigma / math.sqrt(values.size) + 1e-4  # second-order bias only
        assert np.max(np.abs(values)) <= dwell["linear"]["worst_case"] * 1.01  # no part beyond the worst case
        assert dwell["monte_carlo"]["percentiles"] == pytest.approx(
            np.percentile(values, summary["percentiles_at"]).tolist(), rel=1e-12
        )
    drawn = np.array([float(r["form_mm"]) for r in rows])
    assert np.max(np.abs(drawn)) <= 0.01 and np.max(np.abs(drawn)) > 0.009  # ±t uniform
    sigma_r = np.std([float(r["roller_radius_mm"]) for r in rows], ddof=1)
    assert abs(sigma_r - 0.002) < 4 * 0.002 / math.sqrt(2 * 299)  # σ as given
    assert (out / "tolerance.html").read_text(encoding="utf-8").count("<figure") == 3


def test_processes_and_a_dask_cluster_give_the_serial_bytes(serial, tmp_path):
    """Two local worker processes, and --scheduler on a Dask LocalCluster on loopback."""
    from distributed import LocalCluster

    out, expected = serial
    design = _design(tmp_path, SMALL + "samples = 300\ndwell_accuracy = 0.02\n")
    assert (
        main(["tolerance", str(design), "-o", str(tmp_path / "p"), "--format", "csv", "--jobs", "2", "-q"])
        == 0
    )
    assert (tmp_path / "p" / "tolerance.csv").read_bytes() == expected
    with LocalCluster(
        n_workers=1,
        threads_per_worker=2,
        processes=False,
        protocol="tcp://",
        host="127.0.0.1",
        dashboard_address=None,
    ) as cluster:
        code = main(
            ["tolerance", str(design), "--format", "csv", "--scheduler", cluster.scheduler_address,
             "-o", str(tmp_path / "dask"), "-q"]
        )  # fmt: skip
    assert code == 0
    assert (tmp_path / "dask" / "tolerance.csv").read_bytes() == expected
    a, b = (json.loads((d / "tolerance.json").read_text(encoding="utf-8")) for d in (out, tmp_path / "dask"))
    assert {k: v for k, v in a.items() if k != "source"} == {k: v for k, v in b.items() if k != "source"}


def test_allocation_holds_in_a_monte_carlo_of_parts_made_to_it(serial):
    """RSS at 99.73 %: parts made to the allocated tolerances stay within ±E; 1.5× them do not."""
    out, _ = serial
    alloc = json.loads((out / "tolerance.json").read_text(encoding="utf-8"))["allocation"]
    assert alloc["method"] == "rss" and alloc["confidence"] == 0.9973
    largest = alloc["largest_tolerances"]
    assert largest["phase_deg_pm"] is None  # a keying error does not move a dwell's middle
    cam = Cam.from_design(load_design(SAMPLE))
    names = {"form_pm": Tol.FORM, "offset_pm": Tol.ECCENTRICITY, "roller_radius_pm": Tol.ROLLER_RADIUS}
    e = alloc["dwell_accuracy"]

    def outside(scale: float) -> float:
        tols = [
            Tolerance(tol=names[k], value=scale * largest[k], distribution=Distribution.UNIFORM)
            for k in names
        ]
        mc = monte_carlo(cam, tols, samples=20_000, seed=11, peaks=False)
        return float(np.mean(np.any(np.abs(mc.dwell_error) > e, axis=1)))

    assert outside(1.0) <= 0.0027 + 0.002  # the stated confidence, up to the sampling error
    assert outside(1.5) > 0.01  # and the allocation is not loose


def test_linear_bands_against_a_re_solved_made_cam(tmp_path):
    """method = "linear", one tolerance: the worst-case lift band is |made − nominal| to second order."""
    design = _design(tmp_path, 'form_pm = 0.01\nmethod = "linear"\n')
    assert main(["tolerance", str(design), "-o", str(tmp_path / "o"), "--format", "csv", "-q"]) == 0
    rows = _rows(tmp_path / "o" / "tolerance.csv")
    phi = np.radians([float(r["angle_deg"]) for r in rows])
    cam = Cam.from_design(load_design(design))
    made = made_motion(cam, phi, deltas={Tol.FORM: 0.01})
    error = made.lift - cam.motion(phi).s
    band = np.array([float(r["lift_mm_worst_case"]) for r in rows])
    np.testing.assert_allclose(band, np.abs(error), atol=1e-5)  # (0.01 mm)² / ρ terms
    rss = np.array([float(r["lift_mm_rss3sigma"]) for r in rows])
    np.testing.assert_allclose(rss, 3 * band / math.sqrt(3), rtol=1e-12)  # one uniform: 3σ = √3·t
    summary = json.loads((tmp_path / "o" / "tolerance.json").read_text(encoding="utf-8"))
    assert summary["method"] == "linear" and "monte_carlo" not in summary["dwells"][0]


def test_parquet_by_default_and_same_bytes_again(tmp_path):
    import pyarrow.parquet as pq

    design = _design(tmp_path, "form_pm = 0.01\nsamples = 20\n")
    args = ["tolerance", str(design), "--jobs", "1", "-q"]
    assert main([*args, "-o", str(tmp_path / "a")]) == 0
    assert main([*args, "-o", str(tmp_path / "b")]) == 0
    table = pq.read_table(tmp_path / "a" / "tolerance.parquet")
    assert table.num_rows == 20 and table.column_names[:2] == ["index", "form_mm"]
    for name in ("tolerance.parquet", "tolerance.json", "tolerance.html"):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()


BAD = [
    ("roller_radius_pm = 10.0", "tolerance.roller_radius_pm", "±10 mm is larger than the part"),
    ("roller_radius_sigma = 4.0", "tolerance.roller_radius_sigma", "3σ = 12 mm is larger than the part"),
    ("phase_deg_sigma = 35.0", "tolerance.phase_deg_sigma", "3σ = 105° is larger than the part"),
    ("form_pm = 20.0", "tolerance.form_pm", "must be ≤ 10"),
    ("phase_deg_pm = 95.0", "tolerance.phase_deg_pm", "must be"),
    ("arm_length_pm = 0.01", "tolerance.arm_length_pm", "does not apply"),
    ("form_pm = 0.01\nform_sigma = 0.01", "tolerance.form_sigma", "form_pm is given too"),
    ("samples = 1\nform_pm = 0.01", "tolerance.samples", "must be 2 to"),
    ("form_pm = -0.01", "tolerance.form_pm", "must be > 0"),
    ('form_pm = 0.01\nmethod = "exact"', "tolerance.method", "monte-carlo"),
    ("confidence = 1.0\nform_pm = 0.01", "tolerance.confidence", "must be in (0, 1)"),
    ("dwell_accuracy = 0.02", "tolerance", "names no toleranced quantity"),
    ("form_pmm = 0.01", "tolerance.form_pmm", "did you mean 'form_pm'"),
]


@pytest.mark.parametrize(("table", "field", "words"), BAD, ids=[b[1] + ":" + b[2][:12] for b in BAD])
def test_bad_tolerance_tables_exit_2_naming_the_field(tmp_path, capsys, table, field, words):
    design = _design(tmp_path, table + "\n")
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("old", encoding="utf-8")
    assert main(["tolerance", str(design), "-o", str(out), "-q"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"camcad: error: {field}: ") and words in err, err
    assert len(err.strip().splitlines()) == 1
    assert sorted(p.name for p in out.iterdir()) == ["keep.txt"]  # the folder as it was
    assert main(["check", str(design)]) == 2  # the design itself is refused too


def test_a_design_without_a_tolerance_table_and_bad_options(tmp_path, capsys):
    design = tmp_path / "plain.toml"
    design.write_text(BASE, encoding="utf-8")
    assert main(["tolerance", str(design), "-o", str(tmp_path / "o")]) == 2
    assert "has no [tolerance] table" in capsys.readouterr().err
    good = _design(tmp_path, "form_pm = 0.01\nsamples = 4\n")
    assert main(["tolerance", str(good), "-o", str(tmp_path / "o"), "--format", "xlsx"]) == 2
    assert "camcad: error: --format: 'xlsx'" in capsys.readouterr().err
    assert main(["tolerance", str(good), "-o", str(tmp_path / "o"), "--scheduler", "nonsense"]) == 2
    assert "--scheduler" in capsys.readouterr().err
    assert main(["tolerance", str(good), "-o", str(tmp_path / "o"), "--jobs", "0"]) == 2
    assert not (tmp_path / "o").exists()


def test_the_shipped_sample_through_the_installed_entry(tmp_path):
    """``python -m camcad`` in a subprocess on the sample, with fewer variants."""
    data = tomllib.loads(SAMPLE.read_text(encoding="utf-8"))
    text = SAMPLE.read_text(encoding="utf-8").replace("samples = 1000", "samples = 40")
    assert data["tolerance"]["samples"] == 1000
    design = tmp_path / "s.toml"
    design.write_text(text, encoding="utf-8")
    run = subprocess.run(
        [sys.executable, "-m", "camcad", "tolerance", str(design), "-o", str(tmp_path / "o"), "--jobs", "1"],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=ROOT,
    )
    assert run.returncode == 0, run.stderr
    assert re.search(r"dwell 0 at 150\.0°: linear σ [0-9.]+ mm", run.stdout)
    assert "allocation for ±0.02 mm (rss, confidence 0.9973)" in run.stdout
    assert {p.name for p in (tmp_path / "o").iterdir()} == {
        "tolerance.parquet",
        "tolerance.json",
        "tolerance.html",
    }


def test_quadratic_evaluation_matches_the_exact_rows_within_its_certificate(serial, tmp_path):
    """`evaluation = "quadratic"` on the same seed: every row within the bound tolerance.json reports."""
    out, _ = serial
    design = _design(tmp_path, SMALL + 'samples = 300\ndwell_accuracy = 0.02\nevaluation = "quadratic"\n')
    assert main(["tolerance", str(design), "-o", str(tmp_path / "q"), "--format", "csv", "-q"]) == 0
    exact, quad = _rows(out / "tolerance.csv"), _rows(tmp_path / "q" / "tolerance.csv")
    summary = json.loads((tmp_path / "q" / "tolerance.json").read_text(encoding="utf-8"))
    how = summary["evaluation"]
    assert how["method"] == "quadratic" and how["certified_variants"] == 200
    bound = how["max_abs_difference_from_exact"]
    assert list(quad[0]) == list(exact[0])  # the same columns
    for column, limit in bound.items():
        key = column if column.startswith("peak") else None
        names = [key] if key else [c for c in exact[0] if c.startswith("dwell_error_")]
        for name in names:
            e = np.array([float(r[name]) for r in exact if r[name]])
            q = np.array([float(r[name]) for r in quad if r[name]])
            assert e.size == q.size == 300
            assert np.max(np.abs(e - q)) <= 2.0 * limit + 1e-12, name
    for name in ("form_mm", "offset_mm", "phase_deg"):  # the same made cams
        assert [r[name] for r in quad] == [r[name] for r in exact]
