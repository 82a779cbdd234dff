"""Pure conversions between rclpy QoS profiles and the QoS records rosbag2 metadata holds."""

from __future__ import annotations

from typing import Any

from rosbags.interfaces import (
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)

__all__ = [
    'INFINITE_QOS_TIME',
    'matching_profile',
    'nanoseconds_to_qos_time',
    'qos_from_rosbags',
    'qos_time_to_nanoseconds',
    'qos_to_rosbags',
]

#: How rmw reports an infinite deadline/lifespan/lease (the largest sec, nsec pair).
INFINITE_QOS_TIME = QosTime(sec=2147483647, nsec=4294967295)
_INFINITE_NS = 2**63 - 1


def nanoseconds_to_qos_time(nanoseconds: int) -> QosTime:
    """A duration in nanoseconds as rosbag2's (sec, nsec); rclpy's infinity maps to rmw's."""
    if nanoseconds >= _INFINITE_NS:
        return INFINITE_QOS_TIME
    sec, nsec = divmod(int(nanoseconds), 1_000_000_000)
    return QosTime(sec=sec, nsec=nsec)


def qos_time_to_nanoseconds(value: QosTime) -> int:
    """rosbag2's (sec, nsec) as nanoseconds; rmw's infinity maps to rclpy's."""
    if (value.sec, value.nsec) == tuple(INFINITE_QOS_TIME) or value.sec >= 2147483647:
        return _INFINITE_NS
    return value.sec * 1_000_000_000 + value.nsec


def _policy_value(policy: Any) -> int:
    return int(getattr(policy, 'value', policy))


def _nanoseconds(duration: Any) -> int:
    return int(getattr(duration, 'nanoseconds', 0))


def qos_to_rosbags(profile: Any) -> Qos:
    """An rclpy ``QoSProfile`` (real or built-in) as the record written to metadata.yaml.

    Policy enums map by value: rclpy's and rosbags' enums share rmw's numbering.
    """
    return Qos(
        history=QosHistory(_policy_value(profile.history)),
        depth=int(profile.depth),
        reliability=QosReliability(_policy_value(profile.reliability)),
        durability=QosDurability(_policy_value(profile.durability)),
        deadline=nanoseconds_to_qos_time(_nanoseconds(profile.deadline)),
        lifespan=nanoseconds_to_qos_time(_nanoseconds(profile.lifespan)),
        liveliness=QosLiveliness(_policy_value(profile.liveliness)),
        liveliness_lease_duration=nanoseconds_to_qos_time(
            _nanoseconds(profile.liveliness_lease_duration)
        ),
        avoid_ros_namespace_conventions=bool(profile.avoid_ros_namespace_conventions),
    )


def _policy(enum_cls: Any, value: Any, unknown: Any) -> Any:
    """rclpy policy with the same rmw value; UNKNOWN (or a value rclpy lacks) -> SYSTEM_DEFAULT."""
    if value is unknown:
        return enum_cls(0)
    try:
        return enum_cls(value.value)
    except ValueError:
        return enum_cls(0)


def qos_from_rosbags(qos: Qos, rclpy_module: Any) -> Any:
    """A recorded QoS record as a ``QoSProfile`` of ``rclpy_module`` (real or built-in rclpy).

    UNKNOWN policies become SYSTEM_DEFAULT, a depth of 0 becomes 1 and rmw's infinite
    durations become 0 (rclpy's "use the default").
    """
    qos_module = rclpy_module.qos
    duration = rclpy_module.duration.Duration
    return qos_module.QoSProfile(
        history=_policy(qos_module.HistoryPolicy, qos.history, QosHistory.UNKNOWN),
        depth=max(int(qos.depth), 1),
        reliability=_policy(qos_module.ReliabilityPolicy, qos.reliability, QosReliability.UNKNOWN),
        durability=_policy(qos_module.DurabilityPolicy, qos.durability, QosDurability.UNKNOWN),
        deadline=duration(nanoseconds=_finite(qos.deadline)),
        lifespan=duration(nanoseconds=_finite(qos.lifespan)),
        liveliness=_policy(qos_module.LivelinessPolicy, qos.liveliness, QosLiveliness.UNKNOWN),
        liveliness_lease_duration=duration(nanoseconds=_finite(qos.liveliness_lease_duration)),
        avoid_ros_namespace_conventions=qos.avoid_ros_namespace_conventions,
    )


def _finite(value: QosTime) -> int:
    """Recorded duration for a profile: rmw's infinity becomes 0 ('use the default')."""
    nanoseconds = qos_time_to_nanoseconds(value)
    return 0 if nanoseconds >= _INFINITE_NS else nanoseconds


def matching_profile(
    rclpy_module: Any,
    *,
    all_reliable: bool,
    all_latched: bool,
    depth: int,
    **durations: Any,
) -> Any:
    """A KEEP_LAST ``QoSProfile`` that matches (or offers to) every one of a set of profiles.

    Reliable only if all of them are, transient-local only if all of them are: what
    rosbag2 subscribes with when recording and offers when replaying.
    """
    qos = rclpy_module.qos
    return qos.QoSProfile(
        history=qos.HistoryPolicy.KEEP_LAST,
        depth=depth,
        reliability=(
            qos.ReliabilityPolicy.RELIABLE if all_reliable else qos.ReliabilityPolicy.BEST_EFFORT
        ),
        durability=(
            qos.DurabilityPolicy.TRANSIENT_LOCAL if all_latched else qos.DurabilityPolicy.VOLATILE
        ),
        **durations,
    )
