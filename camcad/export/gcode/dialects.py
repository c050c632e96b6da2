"""What each G-code dialect accepts: preamble, tool change, blending, dwell, end.

``linuxcnc`` writes the full modal preamble, path blending ``G64 P<tol>``
and a tool change with tool-length offset. ``grbl`` has no tool-length
offsets, no canned cycles, no G64 and no M6, so the tool change becomes a
comment. ``generic`` is a Fanuc-like subset: no G64, no G91.1 (incremental
I/J is the usual default there), no spindle dwell.
"""

from __future__ import annotations

from dataclasses import dataclass

from camcad.knobs import Knob
from camcad.toolpath.spec import Dialect

__all__ = ["DIALECTS", "DialectRules", "dialect_rules"]


@dataclass(frozen=True, slots=True, kw_only=True)
class DialectRules:
    """Words a dialect writes; empty strings are left out."""

    name: str
    modal: str  # the modal preamble
    blend: bool  # write G64 P<tolerance>
    tool_change: bool  # T… M6 (else a comment)
    length_offset: bool  # G43 H… after the tool change
    spindle_dwell: str  # dwell block after spindle start, "" for none
    end: str


DIALECTS: dict[Dialect, DialectRules] = {
    Dialect.LINUXCNC: DialectRules(
        name="linuxcnc",
        modal="G17 G21 G40 G49 G54 G80 G90 G91.1 G94",
        blend=True,
        tool_change=True,
        length_offset=True,
        spindle_dwell="G4 P2",
        end="M2",
    ),
    Dialect.GRBL: DialectRules(
        name="grbl",
        modal="G17 G21 G40 G54 G90 G91.1 G94",
        blend=False,
        tool_change=False,
        length_offset=False,
        spindle_dwell="G4 P2",
        end="M2",
    ),
    Dialect.GENERIC: DialectRules(
        name="generic",
        modal="G17 G21 G40 G49 G54 G80 G90 G94",
        blend=False,
        tool_change=True,
        length_offset=True,
        spindle_dwell="",
        end="M30",
    ),
}


def dialect_rules(dialect: Dialect | str) -> DialectRules:
    """The rules of a dialect given as an enum or its name.

    Raises
    ------
    DesignError
        For an unknown name, listing the valid ones.
    """
    if isinstance(dialect, Dialect):
        return DIALECTS[dialect]
    try:
        return DIALECTS[Dialect(dialect)]
    except ValueError:
        from camcad.errors import DesignError

        allowed = ", ".join(d.value for d in Dialect)
        raise DesignError(Knob.DIALECT, f"{dialect!r} is not allowed (allowed: {allowed})") from None
