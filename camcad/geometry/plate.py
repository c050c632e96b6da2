"""The cam plate around the profile: its thickness, bore and keyway, as exact geometry.

The writers (DXF, mesh, and later STEP) take a :class:`Plate` and the fitted
profile, never the whole design.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from camcad._typing import FloatArray, readonly

__all__ = ["BoreOutline", "Plate", "circle_segments"]


def circle_segments(radius: float, chord_tolerance: float, sweep: float = 2.0 * math.pi) -> int:
    """Chords needed for an arc of ``radius`` [mm] and ``sweep`` [rad] within ``chord_tolerance`` [mm].

    Notes
    -----
    A chord spanning the angle Δ deviates from its arc by the sagitta
    r(1 − cos(Δ/2)); Δ is chosen so that this is at most the tolerance.

    Examples
    --------
    >>> circle_segments(10.0, 0.01)
    71
    """
    ratio = min(chord_tolerance / radius, 1.0)
    max_step = 2.0 * math.acos(1.0 - ratio)
    return max(3, math.ceil(sweep / max_step - 1e-9))


@dataclass(frozen=True, slots=True, kw_only=True)
class BoreOutline:
    """The bore, with an optional keyway on its +y side, as exact geometry.

    Attributes
    ----------
    radius
        Bore radius r [mm] (half the design's bore diameter).
    keyway_width
        Keyway width w [mm]; 0 for a plain bore.
    keyway_depth
        Keyway depth d [mm], from the bore surface; the keyway's flat end is
        at y = r + d.
    """

    radius: float
    keyway_width: float = 0.0
    keyway_depth: float = 0.0

    @classmethod
    def from_cam_spec(cls, bore: float, keyway_width: float, keyway_depth: float) -> BoreOutline | None:
        """Build the outline for a bore *diameter* [mm] and keyway size; None without a bore."""
        if bore <= 0.0:
            return None
        if keyway_width > 0.0 and keyway_depth > 0.0:
            return cls(radius=bore / 2.0, keyway_width=keyway_width, keyway_depth=keyway_depth)
        return cls(radius=bore / 2.0)

    @property
    def has_keyway(self) -> bool:
        """Whether the outline includes a keyway."""
        return self.keyway_width > 0.0 and self.keyway_depth > 0.0

    @property
    def _half_angle(self) -> float:
        """Half the angle δ the keyway cuts out of the bore circle [rad]: sin δ = w / 2r."""
        return math.asin(self.keyway_width / (2.0 * self.radius))

    @property
    def _corner_y(self) -> float:
        """Height y₀ = r cos δ where the keyway sides meet the bore circle [mm]."""
        return self.radius * math.cos(self._half_angle)

    @property
    def area(self) -> float:
        """Exact area of the hole [mm²].

        Notes
        -----
        Disc plus keyway rectangle above the chord y = y₀, minus the circular
        cap they share: πr² + w(r + d − y₀) − (r²δ − (w/2)y₀).
        """
        r, w, d = self.radius, self.keyway_width, self.keyway_depth
        disc = math.pi * r * r
        if not self.has_keyway:
            return disc
        y0, delta = self._corner_y, self._half_angle
        cap = r * r * delta - 0.5 * w * y0
        return disc + w * (r + d - y0) - cap

    @property
    def perimeter(self) -> float:
        """Exact length of the outline [mm]."""
        r, w, d = self.radius, self.keyway_width, self.keyway_depth
        if not self.has_keyway:
            return 2.0 * math.pi * r
        return r * (2.0 * math.pi - 2.0 * self._half_angle) + 2.0 * (r + d - self._corner_y) + w

    @property
    def reach(self) -> float:
        """Largest distance of the outline from the cam axis [mm]."""
        if not self.has_keyway:
            return self.radius
        return math.hypot(self.radius + self.keyway_depth, 0.5 * self.keyway_width)

    def bulge_vertices(self) -> list[tuple[float, float, float]]:
        """Counter-clockwise ``(x, y, bulge)`` vertices of the keyed outline for an LWPOLYLINE.

        The four keyway corners are exact; the bore arc from the last corner
        back to the first is one bulge, tan(θ/4) for its included angle θ.
        Only for a bore with a keyway (a plain bore is a CIRCLE).
        """
        if not self.has_keyway:
            raise ValueError("a plain bore is written as a circle")
        r, w, d = self.radius, self.keyway_width, self.keyway_depth
        y0, delta = self._corner_y, self._half_angle
        sweep = 2.0 * math.pi - 2.0 * delta
        half = 0.5 * w
        return [
            (half, y0, 0.0),
            (half, r + d, 0.0),
            (-half, r + d, 0.0),
            (-half, y0, math.tan(sweep / 4.0)),
        ]

    def polygon(self, chord_tolerance: float) -> FloatArray:
        """Counter-clockwise polygon of the outline within ``chord_tolerance`` [mm].

        Returns
        -------
        FloatArray
            (n, 2) vertices [mm], inscribed in the arc, keyway corners exact;
            read-only.
        """
        r = self.radius
        if not self.has_keyway:
            n = circle_segments(r, chord_tolerance)
            t = 2.0 * math.pi * np.arange(n) / n
            points = np.column_stack((r * np.cos(t), r * np.sin(t)))
        else:
            corners = np.array([(x, y) for x, y, _ in self.bulge_vertices()])
            delta = self._half_angle
            sweep = 2.0 * math.pi - 2.0 * delta
            n = circle_segments(r, chord_tolerance, sweep)
            t = 0.5 * math.pi + delta + sweep * np.arange(1, n) / n
            arc = np.column_stack((r * np.cos(t), r * np.sin(t)))
            points = np.vstack((corners, arc))
        points = np.ascontiguousarray(points, dtype=float)
        readonly(points)
        return points


@dataclass(frozen=True, slots=True, kw_only=True)
class Plate:
    """The plate the profile is cut from.

    Attributes
    ----------
    name
        The cam's name (for titles and annotations; writers clean it for their format).
    thickness
        Plate thickness [mm].
    bore
        The bore with its keyway, or ``None`` for a plate without a bore.
    """

    name: str
    thickness: float
    bore: BoreOutline | None = None
