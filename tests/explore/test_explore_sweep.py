"""camcad sweep: rows against single `camcad check` runs, engines giving the same bytes, resuming, files."""

from __future__ import annotations

import contextlib
import csv
import io
import math
import os
import re
import signal
import subprocess
import sys
import threading
import time
from html.parser import HTMLParser

import pytest

from camcad.cli import main
from camcad.design import load_design
from camcad.design.toml_text import toml_text
from camcad.explore.measures import MEASURES, parse_limit
from camcad.explore.pareto import pareto_mask
from camcad.explore.space import apply_values, grid_points, parse_variable
from camcad.explore.sweep import SweepPlan, sweep
from camcad.pipeline import analyse
from tests.conftest import ROOT
from tests.explore.cases import sample_data

SAMPLE = str(ROOT / "samples" / "offset_roller.toml")


def _plan(data, *grids, limits=(), chunk_size=3):
    variables = tuple(parse_variable(g, data, flag="--grid", counted=True) for g in grids)
    return SweepPlan(
        data=data,
        source="offset_roller.toml",
        variables=variables,
        points=tuple(grid_points(variables)),
        limits=tuple(parse_limit(t) for t in limits),
        pareto=(MEASURES["base_radius"], MEASURES["contact_stress"]),
        chunk_size=chunk_size,
    )


@pytest.fixture(scope="module")
def small_plan():
    """8 designs: base radius 20–80 mm × two rise laws, one extra limit, chunks of 3."""
    data = sample_data("offset_roller")
    return _plan(data, "base_radius=20:80:4", "motion[0].law=cycloidal,poly-345", limits=["torque<=3100"])


@pytest.fixture(scope="module")
def serial_csv(small_plan, tmp_path_factory):
    out = tmp_path_factory.mktemp("serial")
    result = sweep(small_plan, out, fmt="csv")
    return result, (out / "sweep.csv").read_bytes()


def _read_csv(text):
    return list(csv.DictReader(io.StringIO(text)))


def test_rows_equal_single_camcad_check_runs(small_plan, serial_csv, tmp_path, capsys):
    """Rows against `camcad check` of the same design written as a file: verdict (exit code) and figures."""
    result, _ = serial_csv
    statuses = [r["status"] for r in result.rows]
    assert statuses.count("ok") >= 2 and "limit" in statuses
    # `camcad check` fits and plans the toolpath too (seconds each): one row of each kind, and the largest cam
    chosen = {statuses.index("ok"), statuses.index("limit"), len(statuses) - 1}
    for row in (result.rows[i] for i in sorted(chosen)):
        values = [row[v.name] for v in small_plan.variables]
        path = tmp_path / f"design-{row['index']}.toml"
        path.write_text(
            toml_text(apply_values(small_plan.data, small_plan.variables, values)), encoding="utf-8"
        )
        code = main(["check", str(path)])
        printed = capsys.readouterr().out
        assert code == (0 if row["status"] == "ok" else 3)
        angle = re.search(r"max pressure angle\s+([\d.]+)°", printed)[1]
        stress = re.search(r"max contact stress\s+([\d.]+) MPa", printed)[1]
        assert angle == f"{row['geometry.pressure_angle_max_deg']:.2f}"
        assert stress == f"{row['dynamics.hertz_stress_max_MPa']:.1f}"
        # and every figure exactly, from the file read back
        summary = analyse(load_design(path), fit=False, toolpath=False, strict=False).summary()
        assert row["geometry.pressure_angle_max_deg"] == summary["geometry"]["pressure_angle_max_deg"]
        assert row["dynamics.torque_max_Nmm"] == summary["dynamics"]["torque_max_Nmm"]
        assert row["geometry.curvature_radius_min_mm"] == summary["geometry"]["curvature_radius_min_mm"]
        torque = max(abs(summary["dynamics"]["torque_max_Nmm"]), abs(summary["dynamics"]["torque_min_Nmm"]))
        assert row["limit:torque<=3100"] == (torque <= 3100)
        assert row["feasible"] == (code == 0 and torque <= 3100)


def test_invalid_designs_are_rows_with_their_reason(tmp_path):
    """An offset beyond r_b + r_f is refused by the schema: a row saying so, never a failed sweep."""
    data = sample_data("offset_roller")
    result = sweep(_plan(data, "offset=0:200:3"), tmp_path, fmt="csv")
    statuses = [r["status"] for r in result.rows]
    assert statuses[0] == "ok" and statuses[2] == "invalid"
    assert result.rows[2]["reason"].startswith("follower.offset:")
    text = (tmp_path / "sweep.csv").read_text(encoding="utf-8")
    assert _read_csv(text)[2]["status"] == "invalid"


def test_same_input_same_bytes(small_plan, serial_csv, tmp_path):
    _, first = serial_csv
    sweep(small_plan, tmp_path / "again", fmt="csv")
    assert (tmp_path / "again" / "sweep.csv").read_bytes() == first
    sweep(small_plan, tmp_path / "p1", fmt="parquet")
    sweep(small_plan, tmp_path / "p2", fmt="parquet")
    assert (tmp_path / "p1" / "sweep.parquet").read_bytes() == (
        tmp_path / "p2" / "sweep.parquet"
    ).read_bytes()
    assert (tmp_path / "p1" / "sweep.html").read_bytes() == (tmp_path / "p2" / "sweep.html").read_bytes()


def test_parquet_and_csv_hold_the_same_table(small_plan, serial_csv, tmp_path):
    """pyarrow reading the Parquet file and csv reading the CSV file give the same columns and values."""
    import pyarrow.parquet as pq

    _, text = serial_csv
    sweep(small_plan, tmp_path, fmt="parquet")
    table = pq.read_table(tmp_path / "sweep.parquet").to_pylist()
    rows = _read_csv(text.decode("utf-8"))
    assert len(table) == len(rows) == 8
    assert list(table[0]) == list(rows[0])
    for a, b in zip(table, rows, strict=True):
        for key, value in a.items():
            cell = b[key]
            if value is None:
                assert cell == ""
            elif isinstance(value, bool):
                assert cell == ("true" if value else "false")
            elif isinstance(value, float):
                assert float(cell) == value or (math.isnan(value) and math.isnan(float(cell)))
            else:
                assert cell == str(value)


def test_processes_and_dask_give_the_same_bytes(small_plan, serial_csv, tmp_path):
    """Two local worker processes, and `camcad sweep --scheduler` on a Dask LocalCluster on loopback, against
    the serial run."""
    from distributed import LocalCluster

    _, serial = serial_csv
    sweep(small_plan, tmp_path / "procs", fmt="csv", jobs=2)
    assert (tmp_path / "procs" / "sweep.csv").read_bytes() == serial
    with LocalCluster(
        n_workers=1,
        threads_per_worker=2,
        processes=False,
        protocol="tcp://",
        host="127.0.0.1",
        dashboard_address=None,
    ) as cluster:  # a real TCP scheduler on loopback, its worker threads in this process
        code = main(
            [
                "sweep", SAMPLE, "--grid", "base_radius=20:80:4",
                "--grid", "motion[0].law=cycloidal,poly-345",
                "--limit", "torque<=3100", "--chunk-size", "3", "--format", "csv",
                "--scheduler", cluster.scheduler_address, "-o", str(tmp_path / "dask"), "-q",
            ]
        )  # fmt: skip
    assert code == 0
    assert (tmp_path / "dask" / "sweep.csv").read_bytes() == serial


def test_unreachable_scheduler_is_a_usage_error(tmp_path, capsys, monkeypatch):
    import camcad.explore.cluster as engine

    monkeypatch.setattr(engine, "SCHEDULER_TIMEOUT_S", 1)
    args = ["sweep", SAMPLE, "--grid", "base_radius=40:80:2", "--scheduler", "tcp://127.0.0.1:1"]
    assert main([*args, "--format", "csv", "-o", str(tmp_path / "new" / "out")]) == 2
    assert capsys.readouterr().err.startswith("camcad: error: --scheduler: cannot reach the Dask scheduler")
    assert not (tmp_path / "new").exists()  # nothing computed, nothing left behind


def test_interrupted_sweep_resumes_from_what_it_wrote(small_plan, serial_csv, tmp_path):
    """Stop after the first chunk; the next run computes only the other chunks and writes the same bytes."""
    _, serial = serial_csv

    def stop(k, rows):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sweep(small_plan, tmp_path, fmt="csv", on_chunk=stop)
    assert not (tmp_path / "sweep.csv").exists()
    assert len(list(tmp_path.glob(".camcad-sweep-*/chunk-*.json"))) == 1
    computed = []
    result = sweep(small_plan, tmp_path, fmt="csv", on_chunk=lambda k, rows: computed.append(k))
    chunks = math.ceil(8 / small_plan.chunk_size)
    assert result.resumed_chunks == 1 and len(computed) == chunks - 1
    assert (tmp_path / "sweep.csv").read_bytes() == serial
    assert not list(tmp_path.glob(".camcad-sweep-*"))  # the records go once the table is written


def test_pareto_column_is_the_dominance_filter_of_feasible_rows(serial_csv):
    """The `pareto` column against the definition: feasible, and no feasible row at least as good in both
    objectives and better in one (base radius, contact stress)."""
    rows = serial_csv[0].rows
    ok = [r for r in rows if r["feasible"]]
    for r in rows:
        dominated = any(
            o["base_radius_mm"] <= r["base_radius_mm"]
            and o["contact_stress_MPa"] <= r["contact_stress_MPa"]
            and (
                o["base_radius_mm"] < r["base_radius_mm"] or o["contact_stress_MPa"] < r["contact_stress_MPa"]
            )
            for o in ok
        )
        assert r["pareto"] == (r["feasible"] and not dominated)
    assert any(r["pareto"] for r in rows)
    assert pareto_mask([r["base_radius_mm"] for r in ok], [r["contact_stress_MPa"] for r in ok]).any()


class _Page(HTMLParser):
    def __init__(self):
        super().__init__()
        self.images, self.rows, self.stack = 0, 0, []

    def handle_starttag(self, tag, attrs):
        self.images += tag == "img" and dict(attrs)["src"].startswith("data:image/png;base64,")
        self.rows += tag == "tr"


def test_page_has_the_front_and_the_feasible_region(serial_csv, tmp_path, small_plan):
    sweep(small_plan, tmp_path, fmt="csv")
    text = (tmp_path / "sweep.html").read_text(encoding="utf-8")
    page = _Page()
    page.feed(text)
    assert page.images == 2  # the front and the feasible region
    assert page.rows == 1 + sum(r["pareto"] for r in serial_csv[0].rows)  # header + one per front design
    assert 'id="front"' in text and 'id="region"' in text and "sweep.csv" in text


def test_cli_sweep_grid_and_latin_hypercube(tmp_path, capsys):
    code = main(
        [
            "sweep",
            SAMPLE,
            "--grid",
            "base_radius=40:80:3",
            "--format",
            "csv",
            "--jobs",
            "1",
            "-o",
            str(tmp_path / "g"),
            "-q",
        ]
    )
    assert code == 0
    assert capsys.readouterr().out.startswith("3 designs:")
    rows = _read_csv((tmp_path / "g" / "sweep.csv").read_text(encoding="utf-8"))
    assert [float(r["base_radius"]) for r in rows] == [40.0, 60.0, 80.0]
    code = main(
        [
            "sweep", SAMPLE, "--grid", "base_radius=40:80", "--grid", "offset=0:20", "--samples", "4",
            "--format", "csv", "--jobs", "1", "-o", str(tmp_path / "l"), "-q",
        ]
    )  # fmt: skip
    assert code == 0
    rows = _read_csv((tmp_path / "l" / "sweep.csv").read_text(encoding="utf-8"))
    # one design in each quarter of each range (Latin hypercube)
    assert sorted(int((float(r["base_radius"]) - 40.0) / 10.0) for r in rows) == [0, 1, 2, 3]
    assert sorted(int(float(r["offset"]) / 5.0) for r in rows) == [0, 1, 2, 3]


@pytest.mark.parametrize(
    ("args", "flag"),
    [
        (["--grid", "base_radius=40:80"], "--grid"),
        (["--grid", "cam.base_radus=40:80:3"], "--grid"),
        (["--grid", "base_radius=0:80:3"], "--grid"),
        (["--grid", "base_radius=40:80:3", "--format", "xlsx"], "--format"),
        (["--grid", "base_radius=40:80:3", "--pareto", "base_radius"], "--pareto"),
        (["--grid", "base_radius=40:80:3", "--jobs", "0"], "--jobs"),
        (["--grid", "base_radius=40:80:3", "--limit", "torque<3000"], "--limit"),
        ([], "--grid"),
        (["--grid", "base_radius=40:80:3", "--seed", "-1"], "--seed"),
        (["--grid", "base_radius=40:80", "--samples", "3", "--seed", str(2**32)], "--seed"),
        (["--grid", "base_radius=40:80:3", "--grid", "cam.base_radius=50:60:2"], "--grid"),
        (["--grid", "offset=0:5:2", "--grid", "offset=1,2"], "--grid"),
        (["--grid", "base_radius=" + ",".join(f"{40 + i / 1000}" for i in range(10_000))], "--grid"),
    ],
    ids=[
        "no-count",
        "unknown-key",
        "bad-range",
        "format",
        "pareto",
        "jobs",
        "limit",
        "no-grid",
        "negative-seed",
        "seed-beyond-32-bits",
        "same-key-alias",
        "same-key-twice",
        "10000-choices",
    ],
)
def test_bad_options_exit_2_naming_the_flag(args, flag, tmp_path, capsys):
    code = main(["sweep", SAMPLE, *args, "-o", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith(f"camcad: error: {flag}:"), err


def _timed_cli(*args: str) -> tuple[float, subprocess.CompletedProcess[str]]:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    start = time.monotonic()
    done = subprocess.run(
        [sys.executable, "-m", "camcad", *args],
        capture_output=True,
        text=True,
        env=env,
        timeout=120,
        check=False,
    )
    return time.monotonic() - start, done


def test_a_bad_scheduler_fails_fast_with_one_line_and_no_traceback(tmp_path):
    """Issue 32: one line, exit 2, within seconds of a run that fails at once on another option; and
    nothing later (Dask's client finaliser used to print a traceback 40 s on). A subprocess: what is
    printed at the interpreter's exit counts. The refused port goes the furthest (a parsed address,
    a connection tried); a malformed address stops earlier on the same path (next test, in process)."""
    grid = ["--grid", "base_radius=40:80:2", "--format"]
    baseline, _ = _timed_cli("sweep", SAMPLE, *grid, "xlsx", "-o", str(tmp_path / "b"))  # imports, load
    seconds, done = _timed_cli(
        "sweep", SAMPLE, *grid, "csv", "--scheduler", "tcp://127.0.0.1:1", "-o", str(tmp_path / "o")
    )
    assert done.returncode == 2, done.stderr
    assert done.stdout == ""
    lines = done.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("camcad: error: --scheduler: "), lines
    assert "cannot reach the Dask scheduler" in lines[0]
    assert "Traceback" not in done.stderr
    assert seconds < max(10.0, baseline + 5.0), (seconds, baseline)
    assert not (tmp_path / "o").exists()


def test_a_malformed_scheduler_address_is_refused_at_once_in_one_line(tmp_path, capsys):
    """Issue 32: "not a url" is refused by the address parser before any connection or Dask client
    (camcad.explore.cluster.scheduler_address), in one line, exit 2, within seconds, nothing written."""
    start = time.monotonic()
    code = main(
        ["sweep", SAMPLE, "--grid", "base_radius=40:80:2", "--format", "csv", "--scheduler", "not a url",
         "-o", str(tmp_path / "o")]
    )  # fmt: skip
    captured = capsys.readouterr()
    assert code == 2 and captured.out == ""
    lines = captured.err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("camcad: error: --scheduler: "), lines
    assert "is not a scheduler address" in lines[0]
    assert time.monotonic() - start < 10.0
    assert not (tmp_path / "o").exists()


def _group(pgid: int) -> list[tuple[int, str]]:
    """(pid, state) of every process of the process group ``pgid``, read from /proc."""
    found = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat", "rb") as stat:
                    fields = stat.read().rpartition(b")")[2].split()
            except OSError:
                continue
            if int(fields[2]) == pgid:
                found.append((int(entry), fields[0].decode()))
    return found


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads the process table from /proc")
def test_a_killed_sweep_takes_its_workers_fork_server_and_tracker_with_it(tmp_path):
    """Issue 32: SIGKILL of `camcad sweep --jobs 2`: within seconds no process of its group is left
    running (workers, fork server, resource tracker) and the caller's stdout pipe reaches EOF."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    args = ["--grid", "base_radius=40:80:60", "--chunk-size", "1", "--jobs", "2", "--format", "csv"]
    proc = subprocess.Popen(
        [sys.executable, "-m", "camcad", "sweep", SAMPLE, *args, "-o", str(tmp_path / "o"), "-q"],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        env=env,
        start_new_session=True,  # its own process group: everything it starts is found by its id
    )
    try:
        deadline = time.monotonic() + 120
        while len(_group(proc.pid)) < 5:  # the sweep, the tracker, the fork server and two workers
            assert proc.poll() is None and time.monotonic() < deadline, _group(proc.pid)
            time.sleep(0.05)
        proc.kill()
        eof = threading.Event()
        threading.Thread(target=lambda: (proc.stdout.read(), eof.set()), daemon=True).start()
        assert eof.wait(15), "a process still holds the caller's stdout"
        deadline = time.monotonic() + 15
        while [p for p, state in _group(proc.pid) if p != proc.pid and state not in "ZX"]:
            assert time.monotonic() < deadline, _group(proc.pid)
            time.sleep(0.1)
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)
        proc.wait(timeout=60)
