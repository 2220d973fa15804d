"""Worlds: a rectangular workspace with obstacles, and exact, vectorized geometry on them.

Conventions: coordinates in metres; a square is given by its centre and *half side*; a point or a
segment collides with a shape only when it reaches the shape's interior (touching the boundary is
allowed). See ``docs/world.md``.
"""

from __future__ import annotations

from audere.world._geometry import (
    bounding_box,
    contains,
    describe_shape,
    inflate,
    segment_distance,
    segments_intersect,
    signed_distance,
)
from audere.world._shapes import Circle, Obstacle, Polygon, Rectangle, Square, Workspace
from audere.world._world import Collision, World

__all__ = [
    "Circle",
    "Collision",
    "Obstacle",
    "Polygon",
    "Rectangle",
    "Square",
    "Workspace",
    "World",
    "bounding_box",
    "contains",
    "describe_shape",
    "inflate",
    "segment_distance",
    "segments_intersect",
    "signed_distance",
]
