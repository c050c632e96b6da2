"""Write a planned toolpath as G-code text, and summarise it.

Output is deterministic: fixed 4-decimal coordinates, words in a fixed
order, axis words only when they change, the feed only when it changes.
"""

from __future__ import annotations

import math
import re
import unicodedata
from dataclasses import asdict, dataclass
from typing import TYPE_CHECKING, Any

from camcad.export.gcode.dialects import DialectRules, dialect_rules
from camcad.toolpath.moves import MoveKind
from camcad.toolpath.spec import Dialect, GcodeSpec

if TYPE_CHECKING:
    from camcad.toolpath.plan import Toolpath

__all__ = [
    "GcodeProgram",
    "GcodeSummary",
    "comment_text",
    "count_blocks",
    "render_gcode",
    "render_program",
    "summarize",
]


def _num(v: float) -> str:
    text = f"{v:.4f}"
    return "0.0000" if text == "-0.0000" else text


def _feed(v: float) -> str:
    return f"{v:.3f}".rstrip("0").rstrip(".")


MAX_COMMENT_CHARS = 200  # LinuxCNC reads lines of up to 255 characters
# LinuxCNC acts on comments that start with these words and a comma: (MSG, …), (DEBUG, …), …
_ACTIVE_COMMENT = re.compile(r"\s*(msg|debug|print|log\w*|probe\w*|abort)\s*,", re.IGNORECASE)


def comment_text(text: str) -> str:
    """Text made safe for the inside of one G-code comment.

    Every text that reaches a comment (the cam name, notes) goes through
    here: ASCII only (accents dropped), every control character (newline,
    carriage return, tab, …) a space, no parentheses (they would close the
    comment early) nor semicolons (a line comment in GRBL and others), at
    most ``MAX_COMMENT_CHARS`` characters, and never a LinuxCNC active
    comment such as ``MSG,`` at the start.
    """
    plain = unicodedata.normalize("NFKD", text).encode("ascii", "ignore").decode("ascii")
    plain = "".join(" " if ord(c) < 32 or ord(c) == 127 else c for c in plain)
    plain = plain.replace("(", "[").replace(")", "]").replace(";", ",")
    plain = " ".join(plain.split())
    if len(plain) > MAX_COMMENT_CHARS:
        plain = plain[: MAX_COMMENT_CHARS - 3] + "..."
    if _ACTIVE_COMMENT.match(plain):
        plain = "- " + plain
    return plain


def _comment(text: str) -> str:
    """One whole-line comment block around :func:`comment_text`."""
    return f"({comment_text(text)})"


def _header(tp: Toolpath, dialect: str) -> list[str]:
    s = tp.spec
    depth = -tp.final_depth
    passes = len(tp.levels)
    lines = [
        f"camcad G-code: {tp.name}",
        f"dialect: {dialect}",
        "units: millimetres [G21], feeds mm/min",
        "origin: G54 X0 Y0 on the cam axis, Z0 on top of the stock",
        f"tool: T{s.tool_number} flat end mill D{s.tool_diameter:.3f} (radius {s.tool_radius:.3f})"
        + (", chosen by camcad to fit the groove" if s.choose_tool and tp.operation == "groove" else ""),
        *(
            [
                f"stock: blank {tp.thickness:.3f} thick, groove cut to Z{-depth:.4f} from the top face",
                f"tolerance: {s.tolerance:.4f}, measured flank deviation {tp.max_deviation:.4f}",
                f"passes: slot ramp in {passes} laps + 1 flat lap, "
                + (f"{tp.clearing_laps} clearing laps, " if tp.clearing_laps else "")
                + f"2 flank finishing, {s.direction.value}",
            ]
            if tp.operation == "groove"
            else [
                f"stock: plate {tp.thickness:.3f} thick, cut to Z{-depth:.4f} "
                f"[breakthrough {s.breakthrough:.3f}]",
                f"tolerance: {s.tolerance:.4f}, measured contour deviation {tp.max_deviation:.4f}",
                f"passes: {passes} roughing at offset {tp.rough_offset:.4f}, 1 finishing, "
                f"{s.direction.value}",
            ]
        ),
        f"heights: clearance Z{s.clearance_height:.3f}, safe Z{s.safe_height:.3f}",
    ]
    if tp.tab_top is not None:
        lines.append(f"tabs: {s.tab_count} x {s.tab_width:.3f} wide, top at Z{tp.tab_top:.4f}")
    lines.extend(tp.notes)
    return [_comment(t) for t in lines]


def program_start(s: GcodeSpec, rules: DialectRules) -> list[str]:
    """The blocks after the header: modal state, blending, tool, length offset, clearance, spindle, coolant.

    Shared by the XY and the rotary writer, so both start a program the same way.
    """
    out = [rules.modal]
    if rules.blend:
        out.append(f"G64 P{_num(s.tolerance)}")
    if rules.tool_change:
        out.append(f"T{s.tool_number} M6")
    else:
        out.append(
            _comment(f"load tool T{s.tool_number}: end mill D{s.tool_diameter:.3f}, set Z0 on the stock top")
        )
    if rules.length_offset:
        out.append(f"G43 H{s.tool_number}")
    out.append(f"G0 Z{_num(s.clearance_height)}")
    out.append(f"S{_feed(s.spindle_rpm)} M3")
    if rules.spindle_dwell:
        out.append(rules.spindle_dwell)
    if s.coolant:
        out.append("M8")
    return out


def render_gcode(toolpath: Toolpath, dialect: Dialect | str | None = None) -> str:
    """The G-code program for a toolpath, as text with a final newline.

    Parameters
    ----------
    toolpath
        The planned moves.
    dialect
        ``linuxcnc``, ``grbl`` or ``generic`` (default: the toolpath's spec).

    Returns
    -------
    str
        The program. Arcs are G2/G3 with incremental I/J from the written
        start point; every coordinate has 4 decimals.
    """
    rules = dialect_rules(toolpath.spec.dialect if dialect is None else dialect)
    s: GcodeSpec = toolpath.spec
    out = _header(toolpath, rules.name) + program_start(s, rules)
    pos: list[float | None] = [None, None, s.clearance_height]
    feed: float | None = None
    for m in toolpath.moves:
        if m.note:
            out.extend(_comment(t) for t in m.note.split("\n"))
        words = [m.kind.value]
        for axis, k in (("X", 0), ("Y", 1), ("Z", 2)):
            if pos[k] is None or _num(m.end[k]) != _num(pos[k]) or (m.kind.is_arc and k < 2):  # type: ignore[arg-type]
                words.append(f"{axis}{_num(m.end[k])}")
        if m.kind.is_arc:
            assert m.center is not None
            words.append(f"I{_num(m.center[0] - m.start[0])}")
            words.append(f"J{_num(m.center[1] - m.start[1])}")
            if m.turns:
                raise ValueError("multi-turn arcs (P word) are not written; plan one turn per block")
        if m.kind is not MoveKind.RAPID and m.feed != feed:
            words.append(f"F{_feed(m.feed)}")
            feed = m.feed
        out.append(" ".join(words))
        pos = list(m.end)
    if s.coolant:
        out.append("M9")
    out.append("M5")
    out.append(rules.end)
    return "\n".join(out) + "\n"


def count_blocks(text: str) -> int:
    """Blocks that do something: lines other than blanks and whole-line comments."""
    n = 0
    for line in text.splitlines():
        stripped = line.strip()
        if stripped and not (stripped.startswith("(") and stripped.endswith(")")) and stripped != "%":
            n += 1
    return n


@dataclass(frozen=True, slots=True, kw_only=True)
class GcodeSummary:
    """Figures for summary.json.

    Attributes
    ----------
    blocks
        Program blocks (lines other than comments).
    arcs
        G2/G3 blocks.
    cutting_length_mm
        Length of all feed moves [mm].
    cycle_time_s
        Estimated run time from feeds and rapids [s].
    max_deviation_mm
        Measured two-way deviation of the finishing contour from the exact offset curve [mm].
    tool_diameter_mm
        The cutter's diameter [mm].
    tool_chosen
        True when camcad chose the cutter (no ``gcode.tool_diameter`` stated, a groove cam).
    """

    blocks: int
    arcs: int
    cutting_length_mm: float
    cycle_time_s: float
    max_deviation_mm: float
    tool_diameter_mm: float = 0.0
    tool_chosen: bool = False

    def as_dict(self) -> dict[str, Any]:
        """Plain dict, values rounded for a stable file."""
        d = asdict(self)
        d["cutting_length_mm"] = round(d["cutting_length_mm"], 3)
        d["cycle_time_s"] = round(d["cycle_time_s"], 1)
        d["max_deviation_mm"] = round(d["max_deviation_mm"], 6)
        return d


def summarize(toolpath: Toolpath, text: str) -> GcodeSummary:
    """Summarise a toolpath and its rendered program."""
    arcs = sum(1 for m in toolpath.moves if m.kind.is_arc)
    time = toolpath.cycle_time()
    return GcodeSummary(
        blocks=count_blocks(text),
        arcs=arcs,
        cutting_length_mm=toolpath.cutting_length(),
        cycle_time_s=time if math.isfinite(time) else 0.0,
        max_deviation_mm=toolpath.max_deviation,
        tool_diameter_mm=toolpath.spec.tool_diameter,
        tool_chosen=toolpath.spec.choose_tool and toolpath.operation == "groove",
    )


@dataclass(frozen=True, slots=True, kw_only=True)
class GcodeProgram:
    """A toolpath rendered once: the program text and its figures for summary.json.

    Attributes
    ----------
    text
        The G-code program (what ``cam.ngc`` holds).
    figures
        Blocks, arcs, cutting length, cycle time and deviation, counted on ``text``.
    """

    text: str
    figures: GcodeSummary

    def summary(self) -> dict[str, Any]:
        """The ``gcode`` entry of summary.json."""
        return self.figures.as_dict()


def render_program(toolpath: Toolpath, dialect: Dialect | str | None = None) -> GcodeProgram:
    """Render a toolpath (see :func:`render_gcode`) and summarise what was rendered."""
    text = render_gcode(toolpath, dialect)
    return GcodeProgram(text=text, figures=summarize(toolpath, text))
