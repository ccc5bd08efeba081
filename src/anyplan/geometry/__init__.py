"""Exact planar geometry: shapes, static clearance and moving-disc contact."""

from anyplan.geometry.collision import COLLISION_EPS, ObstacleSet
from anyplan.geometry.moving import (
    closest_approach,
    closest_approach_straight,
    first_contact,
    first_contact_straight,
)
from anyplan.geometry.se2 import wrap_angle
from anyplan.geometry.shapes import Circle, Polygon, Shape, rectangle, regular_polygon, square

__all__ = [
    "COLLISION_EPS",
    "Circle",
    "ObstacleSet",
    "Polygon",
    "Shape",
    "closest_approach",
    "closest_approach_straight",
    "first_contact",
    "first_contact_straight",
    "rectangle",
    "regular_polygon",
    "square",
    "wrap_angle",
]
