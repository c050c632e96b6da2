"""A closed triangle mesh as a small value, its checks, and its files: STL, PLY, OBJ, OFF and 3MF.

:class:`TriangleMesh` holds manifold3d's mesh (vertices and faces, nothing
else); its volume, area, Euler number and the closed-solid check are a few
lines of numpy each. The writers are hand-written too: importing trimesh
(which loads networkx, meshio and SciPy submodules) took 0.3-0.6 s, more
than building, checking and writing the solid, and each of these formats is
a header and the two arrays (STL and PLY: one structured array, one
``tobytes``). Every writer is deterministic: no timestamps or random ids, a fixed
zip date in 3MF, so the same mesh gives the same bytes.

Conventions: units are mm; faces are counter-clockwise seen from outside (the
right-hand normal points out of the solid); text formats write every
coordinate with Python's shortest round-trip ``repr``, so OBJ, OFF and 3MF
read back to the same float64; PLY stores float64 (``property double``);
binary STL is float32 by its definition.
"""

from __future__ import annotations

import io
import struct
import zipfile
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from camcad._typing import FloatArray

if TYPE_CHECKING:
    import manifold3d

__all__ = [
    "STL_HEADER",
    "TriangleMesh",
    "obj_bytes",
    "off_bytes",
    "ply_bytes",
    "stl_bytes",
    "threemf_bytes",
]

IntArray = NDArray[np.int64]

# 80-byte binary STL header: says the unit, and must not begin with "solid" (ASCII STL)
STL_HEADER = b"camcad cam plate, binary STL, units mm".ljust(80, b"\0")
# one binary STL facet: normal, three vertices (float32, little-endian), attribute byte count 0
_STL_FACET = np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attribute", "<u2")])
# one PLY face: the vertex count (3) as uchar, then three int32 indices
_PLY_FACE = np.dtype([("count", "u1"), ("index", "<i4", (3,))])
_ZIP_DATE = (1980, 1, 1, 0, 0, 0)  # the earliest date a zip entry can carry: no build time in the file


@dataclass(frozen=True, slots=True, kw_only=True)
class TriangleMesh:
    """A triangle mesh: shared vertices and the faces that index them.

    Attributes
    ----------
    vertices
        (n, 3) float64 vertex positions [mm], read-only.
    faces
        (m, 3) int64 vertex indices per triangle, counter-clockwise seen from
        outside for a solid, read-only.
    """

    vertices: FloatArray
    faces: IntArray

    def __post_init__(self) -> None:
        vertices = np.array(self.vertices, dtype=np.float64)
        faces = np.array(self.faces, dtype=np.int64)
        if vertices.ndim != 2 or vertices.shape[1] != 3:
            raise ValueError(f"vertices must be (n, 3), got shape {vertices.shape}")
        if faces.ndim != 2 or faces.shape[1] != 3:
            raise ValueError(f"faces must be (m, 3), got shape {faces.shape}")
        if faces.size and (faces.min() < 0 or faces.max() >= len(vertices)):
            raise ValueError(f"face indices must lie in [0, {len(vertices)})")
        vertices.flags.writeable = False
        faces.flags.writeable = False
        object.__setattr__(self, "vertices", vertices)
        object.__setattr__(self, "faces", faces)

    @classmethod
    def from_manifold(cls, solid: manifold3d.Manifold) -> TriangleMesh:
        """The mesh of a manifold3d solid, in double precision (``to_mesh64``: no float32 rounding)."""
        raw = solid.to_mesh64()
        return cls(
            vertices=np.asarray(raw.vert_properties, dtype=np.float64)[:, :3],
            faces=np.asarray(raw.tri_verts, dtype=np.int64),
        )

    @property
    def triangles(self) -> FloatArray:
        """(m, 3, 3) corner positions of every face [mm]."""
        return self.vertices[self.faces]

    @property
    def bounds(self) -> FloatArray:
        """(2, 3) lowest and highest x, y, z of the vertices [mm]."""
        return np.array([self.vertices.min(axis=0), self.vertices.max(axis=0)])

    def _edge_cross(self) -> FloatArray:
        tri = self.triangles
        return np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])

    @property
    def face_normals(self) -> FloatArray:
        """(m, 3) unit normals by the right-hand rule; (0, 0, 0) for a face of zero area."""
        cross = self._edge_cross()
        length = np.linalg.norm(cross, axis=1)[:, None]
        normals: FloatArray = np.divide(cross, length, out=np.zeros_like(cross), where=length > 0.0)
        return normals

    @property
    def area(self) -> float:
        """Surface area [mm²]: half the sum of the faces' edge cross products' lengths."""
        return 0.5 * float(np.linalg.norm(self._edge_cross(), axis=1).sum())

    @property
    def volume(self) -> float:
        """Enclosed volume [mm³] by the divergence theorem: Σ a·(b × c)/6 over faces (a, b, c).

        Exact for a closed mesh, positive when the faces wind outward. The
        vertices are first moved by the centre of their bounds, which keeps
        the terms small and the sum free of cancellation.
        """
        centre = 0.5 * (self.vertices.min(axis=0) + self.vertices.max(axis=0)) if len(self.vertices) else 0.0
        tri = self.vertices[self.faces] - centre
        return float(np.einsum("ij,ij->", tri[:, 0], np.cross(tri[:, 1], tri[:, 2]))) / 6.0

    @property
    def euler_number(self) -> int:
        """χ = V − E + F: vertices the faces use, undirected edges, faces (2 − 2g when closed)."""
        used = np.unique(self.faces).size
        edges = np.sort(self._directed_edges(), axis=1)
        unique = np.unique(edges[:, 0] * max(len(self.vertices), 1) + edges[:, 1]).size
        return int(used - unique + len(self.faces))

    def _directed_edges(self) -> IntArray:
        """(3m, 2) the faces' edges a→b, b→c, c→a."""
        f = self.faces
        return np.concatenate((f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]))

    def closed_defect(self) -> str | None:
        """Why the mesh is not a closed, consistently wound surface, or None when it is.

        Closed and consistent means: no face repeats a vertex, and every
        undirected edge is used by exactly two faces, in opposite directions.
        With no face repeating a vertex, that holds exactly when no directed
        edge a→b occurs twice and every a→b has its b→a: a directed edge
        used twice is a non-manifold edge or a face wound against its
        neighbour, one without its reverse lies on an open boundary.
        """
        f = self.faces
        if len(f) == 0:
            return "the mesh has no faces"
        repeats = (f[:, 0] == f[:, 1]) | (f[:, 1] == f[:, 2]) | (f[:, 2] == f[:, 0])
        if repeats.any():
            return f"face {int(np.flatnonzero(repeats)[0])} repeats a vertex"
        n = len(self.vertices)
        edges = self._directed_edges()
        keys = np.sort(edges[:, 0] * n + edges[:, 1])
        twice = np.flatnonzero(keys[1:] == keys[:-1])
        if twice.size:
            a, b = divmod(int(keys[twice[0]]), n)
            return f"edge {a}→{b} is used twice in the same direction (a face wound against its neighbour)"
        reverse = np.sort(edges[:, 1] * n + edges[:, 0])
        if not np.array_equal(keys, reverse):
            lone = np.setdiff1d(keys, reverse, assume_unique=True)
            a, b = divmod(int(lone[0]), n)
            return f"edge {a}→{b} has no opposite edge (an open boundary)"
        return None


# ---------------------------------------------------------------------------
# file encodings


def stl_bytes(mesh: TriangleMesh) -> bytes:
    """Binary STL: the 80-byte header, the facet count, then per facet its unit normal and corners (float32).

    One structured array and one ``tobytes``: 84 + 50 m bytes for m faces.
    """
    facets = np.zeros(len(mesh.faces), dtype=_STL_FACET)
    facets["normal"] = mesh.face_normals
    facets["vertices"] = mesh.triangles
    return STL_HEADER + struct.pack("<I", len(facets)) + facets.tobytes()


def ply_bytes(mesh: TriangleMesh) -> bytes:
    """Binary little-endian PLY: float64 vertices, faces as (uchar 3, three int32 indices)."""
    header = (
        "ply\nformat binary_little_endian 1.0\ncomment camcad cam plate, units mm\n"
        f"element vertex {len(mesh.vertices)}\n"
        "property double x\nproperty double y\nproperty double z\n"
        f"element face {len(mesh.faces)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    faces = np.zeros(len(mesh.faces), dtype=_PLY_FACE)
    faces["count"] = 3
    faces["index"] = mesh.faces
    return header.encode("ascii") + mesh.vertices.astype("<f8").tobytes() + faces.tobytes()


def _vertex_lines(mesh: TriangleMesh, prefix: str) -> str:
    return "".join(f"{prefix}{x!r} {y!r} {z!r}\n" for x, y, z in mesh.vertices.tolist())


def obj_bytes(mesh: TriangleMesh) -> bytes:
    """Wavefront OBJ: ``v x y z`` lines, then ``f a b c`` with 1-based indices; no normals or texture."""
    faces = "".join(f"f {a} {b} {c}\n" for a, b, c in (mesh.faces + 1).tolist())
    return ("# camcad cam plate, units mm\n" + _vertex_lines(mesh, "v ") + faces).encode("ascii")


def off_bytes(mesh: TriangleMesh) -> bytes:
    """OFF (Object File Format): ``OFF``, the counts, the vertices, then ``3 a b c`` per face (0-based)."""
    faces = "".join(f"3 {a} {b} {c}\n" for a, b, c in mesh.faces.tolist())
    head = f"OFF\n{len(mesh.vertices)} {len(mesh.faces)} 0\n"
    return (head + _vertex_lines(mesh, "") + faces).encode("ascii")


_CONTENT_TYPES = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">'
    '<Default Extension="rels" '
    'ContentType="application/vnd.openxmlformats-package.relationships+xml"/>'
    '<Default Extension="model" '
    'ContentType="application/vnd.ms-package.3dmanufacturing-3dmodel+xml"/>'
    "</Types>\n"
)
_RELS = (
    '<?xml version="1.0" encoding="UTF-8"?>\n'
    '<Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">'
    '<Relationship Target="/3D/3dmodel.model" Id="rel0" '
    'Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/>'
    "</Relationships>\n"
)


def threemf_bytes(mesh: TriangleMesh, *, name: str = "cam") -> bytes:
    """Encode a 3MF package (core spec 1.x, unit millimetre) holding one mesh object named ``name``.

    Written with the standard library (zipfile), so it needs no XML package;
    entries carry a fixed timestamp and fixed attributes, so equal meshes
    give equal bytes. Characters other than letters, digits, ``-_ .`` are
    dropped from the name.
    """
    vertices = "".join(f'<vertex x="{x!r}" y="{y!r}" z="{z!r}"/>' for x, y, z in mesh.vertices.tolist())
    triangles = "".join(f'<triangle v1="{a}" v2="{b}" v3="{c}"/>' for a, b, c in mesh.faces.tolist())
    safe = "".join(ch for ch in name if ch.isalnum() or ch in "-_ .") or "cam"
    model = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<model unit="millimeter" xml:lang="en-US" '
        'xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02">'
        f'<resources><object id="1" type="model" name="{safe}"><mesh>'
        f"<vertices>{vertices}</vertices><triangles>{triangles}</triangles>"
        '</mesh></object></resources><build><item objectid="1"/></build></model>\n'
    )
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for entry, text in (
            ("[Content_Types].xml", _CONTENT_TYPES),
            ("_rels/.rels", _RELS),
            ("3D/3dmodel.model", model),
        ):
            info = zipfile.ZipInfo(entry, date_time=_ZIP_DATE)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.create_system = 3  # "Unix" on every platform (zipfile's default depends on the OS)
            info.external_attr = 0o644 << 16  # rw-r--r--
            archive.writestr(info, text.encode("utf-8"))
    return buffer.getvalue()
