"""Shared fixtures: designs built in code and the shipped samples."""

from __future__ import annotations

import shutil
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.spatial import cKDTree

from camcad.design import Design, parse_design

ROOT = Path(__file__).resolve().parent.parent
SAMPLES = sorted((ROOT / "samples").glob("*.toml"))
# the samples of disc cams (plate, groove, conjugate): the tests of a disc's outline, its DXF
# polylines and its XY tool path run on these; a barrel cam's files are tested in test_barrel_family
DISC_SAMPLES = [p for p in SAMPLES if not p.stem.startswith("barrel_")]


def make_design(
    *,
    law: str = "cycloidal",
    base_radius: float = 40.0,
    roller_radius: float = 10.0,
    offset: float = 0.0,
    follower: str = "translating-roller",
    rotation: str = "ccw",
    lift: float = 20.0,
    spans: tuple[float, float, float, float] = (150.0, 30.0, 150.0, 30.0),
    params: dict[str, Any] | None = None,
    extra: dict[str, Any] | None = None,
) -> Design:
    """A rise–dwell–return–dwell design with one law."""
    p = params or {}
    data: dict[str, Any] = {
        "cam": {"name": f"test {law}", "base_radius": base_radius, "rotation": rotation, "thickness": 8.0},
        "follower": {"type": follower, "offset": offset}
        | ({"roller_radius": roller_radius} if follower == "translating-roller" else {}),
        "motion": [
            {"kind": "rise", "angle": spans[0], "lift": lift, "law": law, **p},
            {"kind": "dwell", "angle": spans[1]},
            {"kind": "return", "angle": spans[2], "lift": lift, "law": law, **p},
            {"kind": "dwell", "angle": spans[3]},
        ],
    }
    for key, value in (extra or {}).items():
        data.setdefault(key, {}).update(value)
    return parse_design(data)


@pytest.fixture(params=SAMPLES, ids=[p.stem for p in SAMPLES])
def sample_path(request: pytest.FixtureRequest) -> Path:
    """Each shipped sample design file."""
    return request.param


def distance_to_polygon(
    points: np.ndarray, polygon: np.ndarray, *, beyond: float | None = None
) -> np.ndarray:
    """Distance of each point to a closed polygon (first vertex not repeated), near its nearest vertex.

    With ``beyond``, a point whose nearest vertex lies farther than ``beyond`` gets +inf without the slow
    far search: its true distance exceeds ``beyond`` minus half the longest edge (every point of an edge
    lies within half its length of a vertex), so a check ``gap <= tol`` or ``median < c`` with
    ``tol, c`` below that gives the same verdict.
    """
    n = len(polygon)
    # leaves of 128 vertices: the same nearest vertices as the default 16, found faster on dense curves
    d, nearest = cKDTree(polygon, leafsize=128).query(
        points, distance_upper_bound=np.inf if beyond is None else beyond
    )
    near = np.isfinite(d)
    points, nearest = points[near], nearest[near]
    dist = np.full(len(points), np.inf)
    for shift in (-1, 0):
        i = (nearest + shift) % n
        p, q = polygon[i], polygon[(i + 1) % n]
        t = np.clip(np.einsum("ij,ij->i", points - p, q - p) / np.einsum("ij,ij->i", q - p, q - p), 0, 1)
        dist = np.minimum(dist, np.linalg.norm(points - (p + t[:, None] * (q - p)), axis=1))
    out = np.full(len(near), np.inf)
    out[near] = dist
    return out


@contextmanager
def serving(folder: Path, **options: Any) -> Iterator[tuple[Any, str, Path]]:
    """``camcad serve`` on a free loopback port, in a thread, editing a copy of a shipped sample.

    The copy of quintero_vap_b01 is ``folder``/cam.toml. Yields the server, its URL (with the token)
    and the design file; shuts the server down afterwards. ``options`` go to
    :class:`camcad.serve.DesignerServer` (workers, analyses, max_pending, timeout).
    """
    from camcad.serve import make_server

    design = folder / "cam.toml"
    shutil.copy(ROOT / "samples" / "quintero_vap_b01.toml", design)
    srv, url = make_server(design, port=0, **options)
    threading.Thread(target=srv.serve_forever, daemon=True).start()
    try:
        yield srv, url, design
    finally:
        srv.shutdown()
        srv.server_close()


# Files run on one pytest-xdist worker together (``--dist loadgroup``, pyproject.toml); every other
# file is a group of its own, so its module-scoped builds run once. Runs of LinuxCNC's rs274 at once
# clash (its tool table is shared through /tmp); two Chromiums at once would crowd the two cores.
_SERIAL_GROUPS = {
    "rs274": (
        "tests/readers/test_rs274.py",
        "tests/readers/test_rs274_conjugate.py",
        "tests/readers/test_rs274_groove.py",
        "tests/readers/test_rs274_linear.py",
        "tests/readers/test_rs274_rotary.py",
        "tests/readers/test_barrel_readers.py",
        "tests/test_barrel_family.py",
        "tests/cli/test_inspect_cli.py",
    ),
    "chromium": (
        "tests/readers/test_chromium_report.py",
        "tests/readers/test_chromium_serve.py",
        "tests/readers/test_chromium_sweep.py",
    ),
}
_GROUP_OF = {path: group for group, paths in _SERIAL_GROUPS.items() for path in paths}


@pytest.hookimpl(tryfirst=True)  # before pytest-xdist reads the marks
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Give each test one ``xdist_group``: its file's, or the shared group of its file."""
    for item in items:
        try:
            name = item.path.resolve().relative_to(ROOT).as_posix()
        except ValueError:
            name = str(item.path)
        item.add_marker(pytest.mark.xdist_group(_GROUP_OF.get(name, name)))


@pytest.fixture(autouse=True)
def _sigpipe_ignored() -> Iterator[None]:
    """Python's own SIGPIPE setting (ignored) around every test.

    A library a test loads in-process may set SIGPIPE back to its default; a
    server thread writing to a socket the browser closed then kills the whole
    test run with exit 141 (seen in the full suite after the Chromium tests).
    """
    import signal

    signal.signal(signal.SIGPIPE, signal.SIG_IGN)
    yield
    signal.signal(signal.SIGPIPE, signal.SIG_IGN)
