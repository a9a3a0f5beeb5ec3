"""Standard ROS messages (as plain dicts of their fields) from a Leaf's Data and parameters.

Covariances come from the sensor's declared noise model (``engine/noise.py``'s Gazebo
parameters: ``stddev``, ``bias_mean``, ``bias_stddev``, ``dynamic_bias_*``, ``precision``,
each with the channel's prefix): the variance of the error about its constant offset
``mean`` at time t is white noise + turn-on bias (random sign: ``bias_mean² +
bias_stddev²``) + Gauss-Markov bias (stationary ``σ²T/2``, or the random walk's ``σ²t`` when
T = 0) + quantisation (``precision²/12``). A template without these parameters gets
covariance type UNKNOWN (NavSatFix) or zeros.

The world is a plane: roll, pitch and altitude are exactly zero, so their variances are 0.
An accelerometer measures specific force, so a level IMU at rest reads +g upwards (REP 145):
``linear_acceleration.z`` is standard gravity, exactly (the model has no vertical axis, so
no noise on it either); x and y are the model's (``sensors/imu.py``, which leaves gravity
out of the plane: on a slope a real IMU would also show its projection there).

Wheel odometry states the covariance its noise model gives it over time
(:func:`odometry_pose_variances`); a robot's ground truth (the ``Pose`` role) is exact, so
its covariance is zero. Frames follow REP 105 per robot: ``map`` -> ``<robot>/odom``
(identity, on ``/tf_static``: the world knows no localisation error to correct) ->
``<robot>/base_link`` (the true pose, on ``/tf``); a wheel odometry's own estimate is its
``nav_msgs/Odometry`` in ``<robot>/odom``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from .geo import enu_to_geodetic, yaw_quaternion
from .names import ros_path
from .roles import Source

Msg = dict[str, Any]

NAVSAT_STATUS_FIX = 0
NAVSAT_SERVICE_GPS = 1
COVARIANCE_TYPE_UNKNOWN = 0
COVARIANCE_TYPE_DIAGONAL_KNOWN = 2
#: REP 145: a covariance whose first element is -1 says "this part is not provided".
NOT_PROVIDED = (-1.0, *([0.0] * 8))
#: Standard gravity (m/s²): what a level accelerometer at rest reads on z (REP 145).
GRAVITY = 9.80665


def header(stamp: tuple[int, int], frame_id: str) -> Msg:
    """A ``std_msgs/Header``."""
    return {"stamp": {"sec": stamp[0], "nanosec": stamp[1]}, "frame_id": frame_id}


def variance(params: Mapping[str, Any], prefix: str, t_s: float) -> float | None:
    """The error variance of a Gazebo-noise channel at ``t_s`` (None: no noise model)."""
    if f"{prefix}stddev" not in params:
        return None
    sd = float(params[f"{prefix}stddev"])
    bm = float(params.get(f"{prefix}bias_mean", 0.0))
    bs = float(params.get(f"{prefix}bias_stddev", 0.0))
    sigma = float(params.get(f"{prefix}dynamic_bias_stddev", 0.0))
    tau = float(params.get(f"{prefix}dynamic_bias_correlation_time", 0.0))
    q = float(params.get(f"{prefix}precision", 0.0))
    gm = sigma * sigma * (tau / 2 if tau > 0 else t_s)
    return sd * sd + bm * bm + bs * bs + gm + q * q / 12


def _diag3(a: float, b: float, c: float) -> list[float]:
    return [a, 0.0, 0.0, 0.0, b, 0.0, 0.0, 0.0, c]


def _vec(x: float = 0.0, y: float = 0.0, z: float = 0.0) -> Msg:
    return {"x": x, "y": y, "z": z}


def navsatfix(src: Source, v: Mapping[str, Any], p: Mapping[str, Any], ctx: Context) -> Msg:
    """``sensor_msgs/NavSatFix``: the fix on the WGS 84 ellipsoid, horizontal covariance."""
    lat, lon = enu_to_geodetic(v["x"], v["y"], ctx.origin)
    var = variance(p, "", ctx.t_s)
    return {
        "header": header(ctx.stamp, src.frame_id),
        "status": {"status": NAVSAT_STATUS_FIX, "service": NAVSAT_SERVICE_GPS},
        "latitude": lat,
        "longitude": lon,
        "altitude": 0.0,
        "position_covariance": _diag3(var, var, 0.0) if var is not None else [0.0] * 9,
        "position_covariance_type": (
            COVARIANCE_TYPE_DIAGONAL_KNOWN if var is not None else COVARIANCE_TYPE_UNKNOWN
        ),
    }


def deviation_variance(params: Mapping[str, Any]) -> float:
    """Mean square of a compass's deviation δ(θ) = B sin θ + C cos θ + D sin 2θ + E cos 2θ
    over a turn: (B² + C² + D² + E²) / 2.

    The deviation is an error like the turn-on bias (fixed for a heading, unknown to the
    receiver), which the covariance includes: left out, a compass with ~1° of deviation
    and 0.5° of noise (the MDE world's) stated 7.6e-5 rad², a third of its real 2.5e-4.
    """
    return sum(float(params.get(f"deviation{k}", 0.0)) ** 2 for k in "BCDE") / 2


def heading_imu(src: Source, v: Mapping[str, Any], p: Mapping[str, Any], ctx: Context) -> Msg:
    """``sensor_msgs/Imu`` of a compass: orientation only (yaw; roll and pitch are 0)."""
    var = (variance(p, "", ctx.t_s) or 0.0) + deviation_variance(p)
    return {
        "header": header(ctx.stamp, src.frame_id),
        "orientation": yaw_quaternion(v["yaw"]),
        "orientation_covariance": _diag3(0.0, 0.0, var),
        "angular_velocity": _vec(),
        "angular_velocity_covariance": list(NOT_PROVIDED),
        "linear_acceleration": _vec(),
        "linear_acceleration_covariance": list(NOT_PROVIDED),
    }


def imu(src: Source, v: Mapping[str, Any], p: Mapping[str, Any], ctx: Context) -> Msg:
    """``sensor_msgs/Imu`` of a gyro and accelerometer: no orientation."""
    g = variance(p, "gyro_", ctx.t_s) or 0.0
    a = variance(p, "accel_", ctx.t_s) or 0.0
    return {
        "header": header(ctx.stamp, src.frame_id),
        "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0},
        "orientation_covariance": list(NOT_PROVIDED),
        "angular_velocity": _vec(z=v["gyro_z"]),
        "angular_velocity_covariance": _diag3(0.0, 0.0, g),
        "linear_acceleration": _vec(v["accel_x"], v["accel_y"], GRAVITY),
        "linear_acceleration_covariance": _diag3(a, a, 0.0),
    }


def _odometry(
    src: Source,
    ctx: Context,
    x: float,
    y: float,
    yaw: float,
    v: float,
    w: float,
    pose_cov: list[float] | None = None,
) -> Msg:
    return {
        "header": header(ctx.stamp, src.frame_id),
        "child_frame_id": src.child_frame_id,
        "pose": {
            "pose": {"position": _vec(x, y), "orientation": yaw_quaternion(yaw)},
            "covariance": pose_cov if pose_cov is not None else [0.0] * 36,
        },
        "twist": {"twist": {"linear": _vec(v), "angular": _vec(z=w)}, "covariance": [0.0] * 36},
    }


def odometry_pose_variances(
    p: Mapping[str, Any], t_s: float, period_s: float
) -> tuple[float, float]:
    """Variances of dead reckoning's travel (centre of the axle) and yaw after ``t_s`` s.

    Each wheel's travel is the sum of its speed readings times the period (``sensors/
    odometry.py``), so a reading's white error (noise and quantisation, variance ``q`` in
    (m/s)²) adds up as a random walk, ``q * period * t`` in m², and its constant error
    (turn-on bias; the wandering bias taken at its stationary variance, ``b``) grows with
    time, ``b * t²``. The wheels' errors are independent: the centre's travel has half a
    wheel's variance, the yaw ``(r - l) / track`` twice a wheel's over ``track²``.
    """
    white = float(p.get("stddev", 0.0)) ** 2 + float(p.get("precision", 0.0)) ** 2 / 12
    bias = (variance(p, "", t_s) or 0.0) - white
    wheel = white * period_s * t_s + bias * t_s * t_s
    track = float(p.get("track", 0.0)) or 1.0
    return wheel / 2, 2 * wheel / (track * track)


def odometry_pose_cov(v: Mapping[str, Any], p: Mapping[str, Any], ctx: Context) -> list[float]:
    """The 6x6 pose covariance of wheel odometry from its noise model.

    The yaw's variance ``Y`` is :func:`odometry_pose_variances`'. The position's comes
    mostly from that yaw error, carried over the distance: for a path of length ``d`` at
    constant speed with the yaw error a random walk, ``d² Y / 3`` across the path and
    ``d² Y² / 12`` along it (the second-order shortening), plus the travel's own variance
    along it. ``d`` and the direction are the straight line from the odometry frame's
    start (``x``, ``y``) to the pose: exact for a straight drive, an underestimate of the
    distance after turns. The configured wheel-radius errors (``scaleError*``) are a
    miscalibration, not noise, and are not included.
    """
    travel, yaw = odometry_pose_variances(p, ctx.t_s, ctx.period_s)
    dx, dy = v["x"] - float(p.get("x", 0.0)), v["y"] - float(p.get("y", 0.0))
    d2 = dx * dx + dy * dy
    along = travel + d2 * yaw * yaw / 12
    across = d2 * yaw / 3
    phi = math.atan2(dy, dx) if d2 > 0 else v["yaw"]
    c, s = math.cos(phi), math.sin(phi)
    cov = [0.0] * 36
    cov[0] = along * c * c + across * s * s
    cov[7] = along * s * s + across * c * c
    cov[1] = cov[6] = (along - across) * c * s
    cov[35] = yaw
    return cov


def odometry(src: Source, v: Mapping[str, Any], p: Mapping[str, Any], ctx: Context) -> Msg:
    """``nav_msgs/Odometry`` of dead reckoning: the pose in the robot's ``odom`` frame, with
    the covariance its noise model gives (the template gives no twist: zeros)."""
    cov = odometry_pose_cov(v, p, ctx)
    return _odometry(src, ctx, v["x"], v["y"], v["yaw"], 0.0, 0.0, cov)


def ground_truth(src: Source, v: Mapping[str, Any], p: Mapping[str, Any], ctx: Context) -> Msg:
    """``nav_msgs/Odometry`` of a robot's true pose and (body-frame) twist: exact, so its
    covariance is zero."""
    return _odometry(
        src, ctx, v["x"], v["y"], v["yaw"], v.get("speed", 0.0), v.get("yaw_rate", 0.0)
    )


def odom_frame(src: Source) -> str:
    """The REP 105 ``odom`` frame of the robot ``src`` belongs to (itself, if a robot)."""
    return f"{ros_path(src.robot or src.leaf)}/odom"


def transform(src: Source, v: Mapping[str, Any], ctx: Context) -> Msg:
    """A ``geometry_msgs/TransformStamped`` from the robot's ``odom`` frame to its base
    (the true pose: ``map`` -> ``odom`` is the identity, :func:`static_transform`)."""
    return {
        "header": header(ctx.stamp, odom_frame(src)),
        "child_frame_id": src.child_frame_id,
        "transform": {"translation": _vec(v["x"], v["y"]), "rotation": yaw_quaternion(v["yaw"])},
    }


def static_transform(src: Source, stamp: tuple[int, int]) -> Msg:
    """``map`` -> the robot's ``odom`` frame: the identity (for ``/tf_static``)."""
    return {
        "header": header(stamp, src.frame_id),
        "child_frame_id": odom_frame(src),
        "transform": {"translation": _vec(), "rotation": yaw_quaternion(0.0)},
    }


def laser_scan(src: Source, v: Mapping[str, Any], p: Mapping[str, Any], ctx: Context) -> Msg:
    """``sensor_msgs/LaserScan``: beams from ``angle_min`` to ``angle_max`` (evenly spaced).

    A beam without an echo holds ``range_max`` in the Data buffers (finite numbers only);
    in the message it is +inf, as REP 117 asks: a reader takes ``range_min <= r <=
    range_max`` as a hit, so ``range_max`` itself drew a wall of phantom obstacles along
    the scan's outer arc (Foxglove's 3D panel, a costmap).
    """
    ranges: Sequence[float] = v["ranges"]
    lo = float(p.get("angle_min", 0.0))
    hi = float(p.get("angle_max", 0.0))
    n = len(ranges)
    if "range_max" in p:
        far = float(p["range_max"])
        ranges = [math.inf if r >= far else r for r in ranges]
    return {
        "header": header(ctx.stamp, src.frame_id),
        "angle_min": lo,
        "angle_max": hi,
        "angle_increment": (hi - lo) / (n - 1) if n > 1 else 0.0,
        "time_increment": 0.0,  # every beam of a scan is cast at one instant
        "scan_time": ctx.period_s,
        "range_min": float(p.get("range_min", 0.0)),
        "range_max": float(p.get("range_max", 0.0)),
        "ranges": list(ranges),
        "intensities": [],
    }


#: The joint names a wheel command carries (left, right).
WHEEL_JOINTS = ["left_wheel_joint", "right_wheel_joint"]


def wheel_command(src: Source, v: Mapping[str, Any], p: Mapping[str, Any], ctx: Context) -> Msg:
    """``sensor_msgs/JointState``: the powers the robot's motors are commanded, in % as
    ``effort`` (position and velocity empty: not commanded)."""
    return {
        "header": header(ctx.stamp, src.frame_id),
        "name": list(WHEEL_JOINTS),
        "position": [],
        "velocity": [],
        "effort": [v["left"], v["right"]],
    }


class Context:
    """What a builder needs besides the values: the stamp, the time, the geodetic origin."""

    __slots__ = ("origin", "period_s", "stamp", "t_s")

    def __init__(
        self, stamp: tuple[int, int], t_s: float, period_s: float, origin: tuple[float, float]
    ) -> None:
        self.stamp = stamp
        self.t_s = t_s
        self.period_s = period_s
        self.origin = origin


Builder = Callable[[Source, Mapping[str, Any], Mapping[str, Any], Context], Msg]

#: role name -> the function building its message
BUILDERS: dict[str, Builder] = {
    "NavSatFix": navsatfix,
    "Heading": heading_imu,
    "Imu": imu,
    "Odometry": odometry,
    "LaserScan": laser_scan,
    "Pose": ground_truth,
    "WheelCommand": wheel_command,
}


def fields_of(src: Source, values: Mapping[str, float]) -> dict[str, Any]:
    """``src``'s fields read from every Data buffer's value (an array field: a list)."""
    fields: dict[str, Any] = {}
    for name, buf in src.buffers.items():
        fields[name] = [values[b] for b in buf] if isinstance(buf, tuple) else values[buf]
    return fields


def build(src: Source, values: Mapping[str, float], params: Mapping[str, Any], ctx: Context) -> Msg:
    """The message of ``src`` given every Data buffer's value (``values``) now."""
    return BUILDERS[src.role.name](src, fields_of(src, values), params, ctx)
