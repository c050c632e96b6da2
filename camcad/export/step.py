"""STEP (AP214) solid of the cam: the certified periodic B-spline itself, extruded, with bore and keyway.

``cam.step`` holds the plate as one solid, in millimetres, named after the
design: its profile face is a linear extrusion of the fit's periodic
B-spline (the same poles and knots as :attr:`ProfileFit.curve`, not a mesh
or a polyline), and the bore with its keyway is an exact circle arc and
four lines.

The file is written here as ISO 10303-21 text, entity by entity (the B-rep
in :mod:`camcad.export._step_brep`), not through OpenCASCADE: importing
OpenCASCADE (``OCP``) costs about 0.7 s and 230 MB in every build, more
than the whole rest of a build, while the solid is a prism with pockets —
extruded B-splines, cylinders and planes, every edge and face known in
closed form — simple enough to write exactly. OpenCASCADE stays the
independent reader of the tests (``tests/export/test_step.py``), and
FreeCAD reads the file in ``tests/readers/test_freecad.py``.

The writer takes any number of :class:`Body` s, each a :class:`Prism` (a
plane region bounded by closed :data:`Outline` s, extruded along +z) minus
further prisms (pockets opened from its top face), so a groove blank with
its pocket or a conjugate pair's second plate is one more ``Body``, not a
new writer. Each body is one product (PRODUCT named after the body) whose
shape is one MANIFOLD_SOLID_BREP in an ADVANCED_BREP_SHAPE_REPRESENTATION.

A conjugate pair's plates are written as ``cam.step`` and ``cam_2.step``,
their products named "<design> plate 1" and "<design> plate 2", placed as
mounted on one shaft: plate 1 from z = 0 to t, plate 2 above it from
z = t + :data:`PAIR_GAP_MM` to 2t + :data:`PAIR_GAP_MM`, so the two files
inserted into one assembly sit side by side under their own names.

The file is the same bytes for the same bodies: the header's time stamp,
author, organisation and system are fixed, numbers are written with their
shortest round-trip digits, and entity numbers are sequential (no random
ids).
"""

from __future__ import annotations

import os
import unicodedata
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from camcad._version import __version__
from camcad.errors import ExportError
from camcad.export._bar import bar_outline
from camcad.export._step_brep import Body, Entities, Outline, Prism, real, shell
from camcad.export.atomic import atomic_write
from camcad.geometry.plate import BoreOutline

if TYPE_CHECKING:
    from camcad.fit.result import ProfileFit
    from camcad.geometry.families import Bar, Part
    from camcad.geometry.plate import Plate

__all__ = [
    "PAIR_GAP_MM",
    "STEP_TIMESTAMP",
    "Body",
    "Outline",
    "Prism",
    "bar_body",
    "groove_body",
    "plate_body",
    "step_text",
    "write_bar_step",
    "write_cam_step",
    "write_part_step",
    "write_step",
]

STEP_TIMESTAMP = "2000-01-01T00:00:00"  # FILE_NAME time stamp: fixed, like the DXF header dates
MAX_NAME_CHARS = 250
LINE_WIDTH = 80  # physical lines of the exchange structure are folded after a comma beyond this
SCHEMA = "AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }"  # AP214 IS
UNCERTAINTY_MM = 1e-7
PAIR_GAP_MM = 2.0
"""Axial gap [mm] between a conjugate pair's plates as mounted (plate 2 above plate 1 on the shaft)."""


def plate_body(fit: ProfileFit, plate: Plate, *, part: int = 0) -> Body:
    """The cam plate: the fit's periodic B-spline extruded by the plate thickness, minus bore and keyway.

    ``part`` 1 or 2 is a conjugate pair's first or second plate: named
    "<design> plate <part>" and, for plate 2, raised by the thickness plus
    :data:`PAIR_GAP_MM` (as mounted); 0 is a single plate at z = 0, named
    after the design.
    """
    if not fit.curve.periodic:
        raise ExportError("cam.step needs the periodic profile of a closed cam (ProfileFit.curve)")
    if part not in (0, 1, 2):
        raise ValueError(f"part must be 0 (a single plate), 1 or 2, got {part!r}")
    holes = (plate.bore,) if plate.bore is not None else ()
    name = f"{plate.name} plate {part}" if part else plate.name
    z0 = (plate.thickness + PAIR_GAP_MM) if part == 2 else 0.0
    return Body(name=name, prism=Prism(outer=fit.curve, holes=holes, height=plate.thickness, z0=z0))


def groove_body(
    flanks: tuple[ProfileFit, ProfileFit], plate: Plate, *, outer_radius: float, depth: float
) -> Body:
    """A groove cam: a disc of ``outer_radius`` [mm] with bore and keyway, less the groove pocket.

    The pocket lies between the outer and the inner flank's periodic
    B-splines (the fits of :func:`camcad.geometry.groove.flank_offsets`'
    curves), ``depth`` [mm] deep from the top face.
    """
    inner, outer = flanks
    if not (inner.curve.periodic and outer.curve.periodic):
        raise ExportError("cam.step needs the periodic flanks of a closed groove (ProfileFit.curve)")
    holes = (plate.bore,) if plate.bore is not None else ()
    t = plate.thickness
    return Body(
        name=plate.name,
        prism=Prism(outer=BoreOutline(radius=outer_radius), holes=holes, height=t),
        cuts=(Prism(outer=outer.curve, holes=(inner.curve,), height=depth, z0=t - depth),),
    )


def step_text(text: str) -> str:
    r"""Text made safe for a STEP string: printable ASCII, one line, at most ``MAX_NAME_CHARS``.

    Examples
    --------
    >>> step_text("Nocken Süd\n2")
    'Nocken Sud 2'
    """
    plain = unicodedata.normalize("NFKD", text)
    plain = "".join(c for c in plain if not unicodedata.combining(c))
    plain = plain.encode("ascii", "replace").decode("ascii")
    plain = " ".join("".join(c if c.isprintable() else " " for c in plain).split())
    return plain[:MAX_NAME_CHARS] or "cam"


def _string(text: str) -> str:
    """A STRING of ISO 10303-21 (§6.3.4): quoted, apostrophes doubled, backslashes escaped."""
    return "'" + step_text(text).replace("\\", "\\\\").replace("'", "''") + "'"


def _fold(record: str) -> str:
    """One instance on lines of about ``LINE_WIDTH`` characters, folded after commas outside strings."""
    if len(record) <= LINE_WIDTH:
        return record
    lines, start, width, quoted = [], 0, 0, False
    for i, char in enumerate(record):
        width += 1
        if char == "'":
            quoted = not quoted  # a doubled apostrophe toggles twice
        elif char == "," and not quoted and width >= LINE_WIDTH - 10:
            lines.append(record[start : i + 1])
            start, width = i + 1, 2
    lines.append(record[start:])
    return "\n  ".join(lines)


def _contexts(data: Entities) -> tuple[str, str, str]:
    """Application, product, product-definition and geometric contexts, shared by every body."""
    application = data.add("APPLICATION_CONTEXT('core data for automotive mechanical design processes')")
    data.add(
        f"APPLICATION_PROTOCOL_DEFINITION('international standard','automotive_design',2000,{application})"
    )
    product = data.add(f"PRODUCT_CONTEXT('',{application},'mechanical')")
    definition = data.add(f"PRODUCT_DEFINITION_CONTEXT('part definition',{application},'design')")
    length = data.add("( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) )")
    angle = data.add("( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) )")
    solid_angle = data.add("( NAMED_UNIT(*) SI_UNIT($,.STERADIAN.) SOLID_ANGLE_UNIT() )")
    uncertainty = data.add(
        f"UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE({real(UNCERTAINTY_MM)}),{length},"
        "'distance_accuracy_value','confusion accuracy')"
    )
    geometric = data.add(
        "( GEOMETRIC_REPRESENTATION_CONTEXT(3) "
        f"GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT(({uncertainty})) "
        f"GLOBAL_UNIT_ASSIGNED_CONTEXT(({length},{angle},{solid_angle})) "
        "REPRESENTATION_CONTEXT('Context #1','3D Context with UNIT and UNCERTAINTY') )"
    )
    return product, definition, geometric


def _product(data: Entities, body: Body, contexts: tuple[str, str, str]) -> str:
    """One body: its solid, its shape representation and its product; the PRODUCT's reference."""
    product_context, definition_context, geometric = contexts
    brep = data.add(f"MANIFOLD_SOLID_BREP('',{shell(data, body)})")
    origin = data.placement((0.0, 0.0, 0.0), (0.0, 0.0, 1.0), (1.0, 0.0, 0.0))
    representation = data.add(f"ADVANCED_BREP_SHAPE_REPRESENTATION('',({origin},{brep}),{geometric})")
    name = _string(body.name)
    product = data.add(f"PRODUCT({name},{name},'',({product_context}))")
    formation = data.add(f"PRODUCT_DEFINITION_FORMATION('','',{product})")
    definition = data.add(f"PRODUCT_DEFINITION('design','',{formation},{definition_context})")
    shape = data.add(f"PRODUCT_DEFINITION_SHAPE('','',{definition})")
    data.add(f"SHAPE_DEFINITION_REPRESENTATION({shape},{representation})")
    return product


def _step_file(bodies: Sequence[Body], file_name: str) -> str:
    """The whole exchange structure (ISO 10303-21) of ``bodies``, as text."""
    if not bodies:
        raise ExportError("a STEP file needs at least one body")
    data = Entities()
    contexts = _contexts(data)
    products = [_product(data, body, contexts) for body in bodies]
    data.add(f"PRODUCT_RELATED_PRODUCT_CATEGORY('part',$,({','.join(products)}))")
    system = _string(f"camcad {__version__}")
    header = [
        "ISO-10303-21;",
        "HEADER;",
        "FILE_DESCRIPTION(('camcad cam solid'),'2;1');",
        f"FILE_NAME({_string(file_name)},'{STEP_TIMESTAMP}',(''),(''),",
        f"  {system},{system},'');",
        f"FILE_SCHEMA(('{SCHEMA}'));",
        "ENDSEC;",
        "DATA;",
    ]
    body = [_fold(f"#{n} = {record};") for n, record in enumerate(data.records, 1)]
    return "\n".join([*header, *body, "ENDSEC;", "END-ISO-10303-21;", ""])


def write_step(path: str | os.PathLike[str], bodies: Sequence[Body]) -> Path:
    """Write ``bodies`` as STEP AP214 (millimetres) to ``path``, atomically.

    Raises
    ------
    ExportError
        When there is no body, or a body is not a prism with pockets the
        writer can bound exactly (a height ≤ 0, outlines that cross, a
        pocket outside the material, below the bottom or not open at the
        top); nothing is written then.
    """
    text = _step_file(bodies, Path(path).name)
    return atomic_write(path, lambda tmp: tmp.write_bytes(text.encode("ascii")))


def write_cam_step(path: str | os.PathLike[str], *, fit: ProfileFit, plate: Plate, part: int = 0) -> Path:
    """Write ``cam.step``: the plate of :func:`plate_body` as one solid (``part``: a pair's plate 1 or 2)."""
    return write_step(path, [plate_body(fit, plate, part=part)])


def write_part_step(
    folder: str | os.PathLike[str],
    part: Part,
    *,
    fit: ProfileFit,
    flank_fits: Sequence[ProfileFit] = (),
    plate: Plate,
    number: int = 0,
) -> Path:
    """``cam{suffix}.step`` of one part: its blank with the pocket, or its plate.

    ``number``: the part's place in a family that makes several (1, 2, …,
    named and placed as mounted, :func:`plate_body`), 0 for a family's only part.
    """
    path = Path(folder) / f"cam{part.suffix}.step"
    if part.bar is not None:  # a linear cam's bar (camcad.export.bar)
        return write_bar_step(folder, part, fit=fit, plate=plate)
    if part.pocket is not None:
        inner, outer = flank_fits
        body = groove_body(
            (inner, outer), plate, outer_radius=part.pocket.outer_radius, depth=part.pocket.depth
        )
        return write_step(path, [body])
    return write_cam_step(path, fit=fit, plate=plate, part=number)


def bar_body(fit: ProfileFit, bar: Bar, plate: Plate) -> Body:
    """The bar as a STEP body: its closed outline extruded by the plate thickness, named after the design."""
    return Body(name=plate.name, prism=Prism(outer=bar_outline(fit, bar), height=plate.thickness))


def write_bar_step(folder: str | os.PathLike[str], part: Part, *, fit: ProfileFit, plate: Plate) -> Path:
    """``cam{suffix}.step`` of a linear cam's bar."""
    assert part.bar is not None
    return write_step(Path(folder) / f"cam{part.suffix}.step", [bar_body(fit, part.bar, plate)])
