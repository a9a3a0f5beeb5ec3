"""The world's plane as geodetic coordinates and headings as quaternions.

The world is a flat plane in metres with x east and y north (REP 103's ENU), heading 0
along +x, counter-clockwise. A ``sensor_msgs/NavSatFix`` needs a latitude and a longitude,
so the plane is laid on the WGS 84 ellipsoid at an origin: the local tangent plane,
linearised (meridian and prime-vertical radii of curvature at the origin). The map is
linear, so :func:`geodetic_to_enu` inverts :func:`enu_to_geodetic` to rounding; against the
exact ellipsoid it is off by ~d²/(2R), 8 cm at 1 km from the origin, far below a GPS's
noise. A map panel (Foxglove) draws the tracks where the origin is.
"""

from __future__ import annotations

import math

#: Where the world's (0, 0) lies by default: Toulouse (43.5616 N, 1.4683 E), on land, so a
#: map panel shows streets under the tracks rather than the sea at (0, 0).
DEFAULT_ORIGIN = (43.5616, 1.4683)

_A = 6378137.0  # WGS 84 semi-major axis, m
_F = 1 / 298.257223563
_E2 = _F * (2 - _F)


def _radii(lat0_deg: float) -> tuple[float, float]:
    """Meridian (north) and prime-vertical-times-cos (east) metres per radian at ``lat0``."""
    phi = math.radians(lat0_deg)
    s2 = math.sin(phi) ** 2
    m = _A * (1 - _E2) / (1 - _E2 * s2) ** 1.5
    n = _A / math.sqrt(1 - _E2 * s2)
    return m, n * math.cos(phi)


def enu_to_geodetic(x: float, y: float, origin: tuple[float, float]) -> tuple[float, float]:
    """Latitude and longitude in degrees of the plane's point (x east, y north) in metres."""
    m, n_cos = _radii(origin[0])
    return origin[0] + math.degrees(y / m), origin[1] + math.degrees(x / n_cos)


def geodetic_to_enu(lat: float, lon: float, origin: tuple[float, float]) -> tuple[float, float]:
    """The plane's (x, y) in metres of a latitude and longitude in degrees (the inverse)."""
    m, n_cos = _radii(origin[0])
    return math.radians(lon - origin[1]) * n_cos, math.radians(lat - origin[0]) * m


def yaw_quaternion(yaw: float) -> dict[str, float]:
    """The rotation by ``yaw`` radians about z, as a ``geometry_msgs/Quaternion``."""
    return {"x": 0.0, "y": 0.0, "z": math.sin(yaw / 2), "w": math.cos(yaw / 2)}


def quaternion_yaw(q: dict[str, float] | object) -> float:
    """The yaw of a rotation about z (a dict or an object with ``z`` and ``w``)."""
    z = q["z"] if isinstance(q, dict) else q.z  # type: ignore[attr-defined]
    w = q["w"] if isinstance(q, dict) else q.w  # type: ignore[attr-defined]
    return 2 * math.atan2(z, w)
