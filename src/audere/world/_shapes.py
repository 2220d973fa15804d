"""Obstacle and region shapes, and the rectangular workspace.

Conventions (stated in every description a model sees):

- coordinates are metres in the plane, ``(x, y)``;
- a **square** is axis-aligned and given by its centre and its *half side* (the distance from the
  centre to each edge); its side length is ``2 * half_side``;
- a **rectangle** is axis-aligned and given by its bounds ``xmin, xmax, ymin, ymax``;
- a **polygon** is a simple polygon given by its vertices in order (either orientation);
- a point *collides* with a shape when it lies strictly inside it: touching the boundary is allowed.
"""

from __future__ import annotations

from typing import Annotated, Literal

import shapely
from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

__all__ = ["Circle", "Obstacle", "Polygon", "Rectangle", "Square", "Workspace"]

Point = tuple[float, float]


class _Frozen(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)


class Workspace(_Frozen):
    """The axis-aligned box the robot must stay in (boundary included)."""

    xmin: float = 0.0
    xmax: float = 10.0
    ymin: float = 0.0
    ymax: float = 10.0

    @model_validator(mode="after")
    def _ordered(self) -> Workspace:
        if not self.xmin < self.xmax:
            raise ValueError(f"workspace needs xmin < xmax, got xmin={self.xmin}, xmax={self.xmax}")
        if not self.ymin < self.ymax:
            raise ValueError(f"workspace needs ymin < ymax, got ymin={self.ymin}, ymax={self.ymax}")
        return self


class Circle(_Frozen):
    """A disc of the given centre and radius.

    Attributes
    ----------
    center
        ``(x, y)``, metres.
    radius
        Metres, > 0.
    """

    kind: Literal["circle"] = "circle"
    center: Point
    radius: float = Field(gt=0)


class Square(_Frozen):
    """An axis-aligned square given by its centre and half side (side length ``2 * half_side``).

    Attributes
    ----------
    center
        ``(x, y)``, metres.
    half_side
        Distance from the centre to each edge, metres, > 0; the side length is ``2 * half_side``.
    """

    kind: Literal["square"] = "square"
    center: Point
    half_side: float = Field(gt=0)


class Rectangle(_Frozen):
    """An axis-aligned rectangle given by its bounds (``xmin < xmax``, ``ymin < ymax``, metres)."""

    kind: Literal["rectangle"] = "rectangle"
    xmin: float
    xmax: float
    ymin: float
    ymax: float

    @model_validator(mode="after")
    def _ordered(self) -> Rectangle:
        if not self.xmin < self.xmax:
            raise ValueError(f"rectangle needs xmin < xmax, got xmin={self.xmin}, xmax={self.xmax}")
        if not self.ymin < self.ymax:
            raise ValueError(f"rectangle needs ymin < ymax, got ymin={self.ymin}, ymax={self.ymax}")
        return self

    @classmethod
    def from_center(cls, cx: float, cy: float, width: float, height: float) -> Rectangle:
        """Build a rectangle from its centre, width (along x) and height (along y).

        Parameters
        ----------
        cx
            Centre x, metres.
        cy
            Centre y, metres.
        width
            Extent along x, metres, > 0.
        height
            Extent along y, metres, > 0.

        Returns
        -------
        Rectangle
            ``xmin = cx - width / 2``, ``xmax = cx + width / 2``, likewise in y.
        """
        return cls(xmin=cx - width / 2, xmax=cx + width / 2, ymin=cy - height / 2, ymax=cy + height / 2)


class Polygon(_Frozen):
    """A simple polygon (at least three vertices, non-zero area, no self-intersection).

    Attributes
    ----------
    vertices
        ``((x0, y0), (x1, y1), ...)`` in order around the boundary, either orientation, metres; the
        closing edge from the last vertex back to the first is implied (repeating the first vertex at
        the end is allowed).
    """

    kind: Literal["polygon"] = "polygon"
    vertices: tuple[Point, ...] = Field(min_length=3)

    @field_validator("vertices")
    @classmethod
    def _simple(cls, vertices: tuple[Point, ...]) -> tuple[Point, ...]:
        ring = shapely.Polygon(vertices)
        if ring.convex_hull.area <= 0:
            raise ValueError(
                f"polygon vertices must enclose a non-zero area, got {len(vertices)} collinear vertices "
                f"{_short_points(vertices)}"
            )
        if not ring.is_valid:
            raise ValueError(
                "polygon vertices must form a simple polygon (edges may not cross or touch), got "
                f"{shapely.is_valid_reason(ring)} for vertices {_short_points(vertices)}"
            )
        return vertices


def _short_points(vertices: tuple[Point, ...], limit: int = 6) -> str:
    text = ", ".join(f"({x:g}, {y:g})" for x, y in vertices[:limit])
    return "[" + text + (", ...]" if len(vertices) > limit else "]")


Obstacle = Annotated[Circle | Square | Rectangle | Polygon, Field(discriminator="kind")]
"""Any shape; the ``kind`` field says which (``circle``, ``square``, ``rectangle``, ``polygon``)."""
