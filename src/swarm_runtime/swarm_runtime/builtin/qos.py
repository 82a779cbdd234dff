"""``rclpy.qos``: QoS profiles, policies, presets and the compatibility check.

How the built-in runtime uses QoS when it connects publishers to subscriptions:

- **Matching** follows DDS request/offer rules (:func:`qos_check_compatible`): a RELIABLE
  subscription does not receive from a BEST_EFFORT publisher; a TRANSIENT_LOCAL subscription
  does not receive from a VOLATILE publisher; deadline and liveliness must be offered at
  least as strictly as requested. Unmatched pairs are reported once as a warning on the
  subscription's node logger, as rclpy's default incompatible-QoS handler does.
- **SYSTEM_DEFAULT** resolves to the DDS defaults: publishers RELIABLE, subscriptions
  BEST_EFFORT, VOLATILE durability, KEEP_LAST depth 1. **BEST_AVAILABLE** resolves as rmw
  does: a publisher offers RELIABLE + TRANSIENT_LOCAL; a subscription requests RELIABLE
  unless a BEST_EFFORT publisher exists, and TRANSIENT_LOCAL only if every existing
  publisher offers it.
- **History**: each subscription queues at most ``depth`` undelivered messages (KEEP_LAST
  drops the oldest; KEEP_ALL keeps everything); a depth of 0 means 1.
- **TRANSIENT_LOCAL** publishers keep their last ``depth`` messages and hand them to a
  TRANSIENT_LOCAL subscription that matches later (latching).
- Delivery is in-process and lossless, so RELIABLE and BEST_EFFORT only differ in matching.
"""

from __future__ import annotations

import warnings
from enum import Enum, IntEnum
from typing import Any

from .duration import Duration

__all__ = [
    'DeadlineBestAvailable',
    'DurabilityPolicy',
    'HistoryPolicy',
    'InvalidQoSProfileException',
    'LivelinessLeaseDurationeBestAvailable',
    'LivelinessPolicy',
    'QoSCompatibility',
    'QoSDurabilityPolicy',
    'QoSHistoryPolicy',
    'QoSLivelinessPolicy',
    'QoSPolicyKind',
    'QoSPresetProfiles',
    'QoSProfile',
    'QoSReliabilityPolicy',
    'ReliabilityPolicy',
    'qos_check_compatible',
    'qos_policy_name_from_kind',
    'qos_profile_action_status_default',
    'qos_profile_best_available',
    'qos_profile_default',
    'qos_profile_parameter_events',
    'qos_profile_parameters',
    'qos_profile_sensor_data',
    'qos_profile_services_default',
    'qos_profile_system_default',
    'qos_profile_unknown',
]

_INFINITE_NS = 2**63 - 1


class InvalidQoSProfileException(Exception):  # noqa: N818 - the rclpy name
    """A QoSProfile was built with invalid arguments."""

    def __init__(self, *args: Any) -> None:
        super().__init__('Invalid QoSProfile', *args)


class QoSPolicyKind(IntEnum):
    """The QoS policies, as in rmw's incompatible-QoS events."""

    INVALID = 1 << 0
    DURABILITY = 1 << 1
    DEADLINE = 1 << 2
    LIVELINESS = 1 << 3
    RELIABILITY = 1 << 4
    HISTORY = 1 << 5
    LIFESPAN = 1 << 6
    DEPTH = 1 << 7
    LIVELINESS_LEASE_DURATION = 1 << 8
    AVOID_ROS_NAMESPACE_CONVENTIONS = 1 << 9


def qos_policy_name_from_kind(policy_kind: QoSPolicyKind | int) -> str:
    """Return the name of a QoS policy kind, e.g. ``'RELIABILITY'``."""
    return QoSPolicyKind(policy_kind).name


class QoSPolicyEnum(IntEnum):
    """Base of the policy enums, with the short lowercase keys the ros2 CLI uses."""

    @classmethod
    def short_keys(cls) -> list[str]:
        """Return the lowercase member names."""
        return [name.lower() for name in cls.__members__]

    @classmethod
    def get_from_short_key(cls, name: str) -> int:
        """Return the value of a member given its case-insensitive name."""
        return cls[name.upper()].value

    @property
    def short_key(self) -> str:
        """The lowercase member name."""
        return self.name.lower()


class HistoryPolicy(QoSPolicyEnum):
    """How many samples are kept (values as rmw_qos_history_policy_e)."""

    SYSTEM_DEFAULT = 0
    KEEP_LAST = 1
    KEEP_ALL = 2
    UNKNOWN = 3


class ReliabilityPolicy(QoSPolicyEnum):
    """Whether delivery is guaranteed (values as rmw_qos_reliability_policy_e)."""

    SYSTEM_DEFAULT = 0
    RELIABLE = 1
    BEST_EFFORT = 2
    UNKNOWN = 3
    BEST_AVAILABLE = 4


class DurabilityPolicy(QoSPolicyEnum):
    """Whether late joiners get old samples (values as rmw_qos_durability_policy_e)."""

    SYSTEM_DEFAULT = 0
    TRANSIENT_LOCAL = 1
    VOLATILE = 2
    UNKNOWN = 3
    BEST_AVAILABLE = 4


class LivelinessPolicy(QoSPolicyEnum):
    """How liveliness is asserted (values as rmw_qos_liveliness_policy_e)."""

    SYSTEM_DEFAULT = 0
    AUTOMATIC = 1
    MANUAL_BY_TOPIC = 3
    UNKNOWN = 4
    BEST_AVAILABLE = 5


# The older names, still used by a lot of node code.
QoSHistoryPolicy = HistoryPolicy
QoSReliabilityPolicy = ReliabilityPolicy
QoSDurabilityPolicy = DurabilityPolicy
QoSLivelinessPolicy = LivelinessPolicy

#: Deadline that matches most endpoints while staying as strict as possible.
DeadlineBestAvailable = Duration(nanoseconds=_INFINITE_NS - 1)
#: Liveliness lease duration that matches most endpoints (the rclpy spelling, typo included).
LivelinessLeaseDurationeBestAvailable = Duration(nanoseconds=_INFINITE_NS - 1)

_UNSPECIFIED = Duration()

# rmw_qos_profile_default: what unspecified QoSProfile fields take.
_DEFAULTS: dict[str, Any] = {
    'depth': 10,
    'reliability': ReliabilityPolicy.RELIABLE,
    'durability': DurabilityPolicy.VOLATILE,
    'lifespan': _UNSPECIFIED,
    'deadline': _UNSPECIFIED,
    'liveliness': LivelinessPolicy.SYSTEM_DEFAULT,
    'liveliness_lease_duration': _UNSPECIFIED,
    'avoid_ros_namespace_conventions': False,
}


class QoSProfile:
    """A set of QoS policies. ``history`` and/or ``depth`` are required (rclpy rule)."""

    __slots__ = (
        '_avoid_ros_namespace_conventions',
        '_deadline',
        '_depth',
        '_durability',
        '_history',
        '_lifespan',
        '_liveliness',
        '_liveliness_lease_duration',
        '_reliability',
    )
    _FIELDS = (
        'history',
        'depth',
        'reliability',
        'durability',
        'lifespan',
        'deadline',
        'liveliness',
        'liveliness_lease_duration',
        'avoid_ros_namespace_conventions',
    )

    def __init__(self, **kwargs: Any) -> None:
        unknown = [key for key in kwargs if key not in self._FIELDS]
        if unknown:
            raise AssertionError(f'Invalid arguments passed to constructor: {unknown!r}')
        if 'history' not in kwargs:
            if 'depth' not in kwargs:
                raise InvalidQoSProfileException('History and/or depth settings are required.')
            kwargs['history'] = HistoryPolicy.KEEP_LAST
        self.history = kwargs['history']
        if self.history == HistoryPolicy.KEEP_LAST and 'depth' not in kwargs:
            raise InvalidQoSProfileException('History set to KEEP_LAST without a depth setting.')
        for field in self._FIELDS[1:]:
            setattr(self, field, kwargs.get(field, _DEFAULTS[field]))

    @property
    def history(self) -> HistoryPolicy:
        """History policy."""
        return self._history

    @history.setter
    def history(self, value: HistoryPolicy | int) -> None:
        self._history = HistoryPolicy(_policy_value(value, HistoryPolicy, 'history'))

    @property
    def depth(self) -> int:
        """History depth (KEEP_LAST)."""
        return self._depth

    @depth.setter
    def depth(self, value: int) -> None:
        if not isinstance(value, int) or isinstance(value, bool):
            raise AssertionError(f'depth must be an int, got {value!r}')
        if self._history == HistoryPolicy.KEEP_LAST and value == 0:
            warnings.warn(
                "A zero depth with KEEP_LAST doesn't make sense; no data could be stored. "
                'This will be interpreted as SYSTEM_DEFAULT',
                stacklevel=2,
            )
        self._depth = value

    @property
    def reliability(self) -> ReliabilityPolicy:
        """Reliability policy."""
        return self._reliability

    @reliability.setter
    def reliability(self, value: ReliabilityPolicy | int) -> None:
        self._reliability = ReliabilityPolicy(
            _policy_value(value, ReliabilityPolicy, 'reliability')
        )

    @property
    def durability(self) -> DurabilityPolicy:
        """Durability policy."""
        return self._durability

    @durability.setter
    def durability(self, value: DurabilityPolicy | int) -> None:
        self._durability = DurabilityPolicy(_policy_value(value, DurabilityPolicy, 'durability'))

    @property
    def liveliness(self) -> LivelinessPolicy:
        """Liveliness policy."""
        return self._liveliness

    @liveliness.setter
    def liveliness(self, value: LivelinessPolicy | int) -> None:
        self._liveliness = LivelinessPolicy(_policy_value(value, LivelinessPolicy, 'liveliness'))

    @property
    def lifespan(self) -> Duration:
        """Lifespan of a sample (0: unspecified)."""
        return self._lifespan

    @lifespan.setter
    def lifespan(self, value: Duration) -> None:
        self._lifespan = _duration_value(value, 'lifespan')

    @property
    def deadline(self) -> Duration:
        """Expected maximum period between samples (0: unspecified)."""
        return self._deadline

    @deadline.setter
    def deadline(self, value: Duration) -> None:
        self._deadline = _duration_value(value, 'deadline')

    @property
    def liveliness_lease_duration(self) -> Duration:
        """Liveliness lease (0: unspecified)."""
        return self._liveliness_lease_duration

    @liveliness_lease_duration.setter
    def liveliness_lease_duration(self, value: Duration) -> None:
        self._liveliness_lease_duration = _duration_value(value, 'liveliness_lease_duration')

    @property
    def avoid_ros_namespace_conventions(self) -> bool:
        """Whether topic names skip the ROS mangling."""
        return self._avoid_ros_namespace_conventions

    @avoid_ros_namespace_conventions.setter
    def avoid_ros_namespace_conventions(self, value: bool) -> None:
        if not isinstance(value, bool):
            raise AssertionError(f'avoid_ros_namespace_conventions must be a bool, got {value!r}')
        self._avoid_ros_namespace_conventions = value

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, QoSProfile):
            return False
        return all(getattr(self, field) == getattr(other, field) for field in self._FIELDS)

    __hash__ = None  # type: ignore[assignment]

    def __str__(self) -> str:
        fields = ', '.join(f'{field}={getattr(self, field)}' for field in self._FIELDS)
        return f'{type(self).__name__}({fields})'

    __repr__ = __str__


def _policy_value(value: Any, policy: type[IntEnum], name: str) -> int:
    if not isinstance(value, int) or isinstance(value, bool):
        raise AssertionError(f'{name} must be a {policy.__name__} or int, got {value!r}')
    return value


def _duration_value(value: Any, name: str) -> Duration:
    if not isinstance(value, Duration):
        raise AssertionError(f'{name} must be an rclpy.duration.Duration, got {value!r}')
    return value


def _profile(**kwargs: Any) -> QoSProfile:
    return QoSProfile(**kwargs)


#: Used for initialisation; not a profile to use.
qos_profile_unknown = _profile(
    history=HistoryPolicy.UNKNOWN,
    depth=0,
    reliability=ReliabilityPolicy.UNKNOWN,
    durability=DurabilityPolicy.UNKNOWN,
    liveliness=LivelinessPolicy.UNKNOWN,
)
#: The rmw default: RELIABLE, VOLATILE, KEEP_LAST 10.
qos_profile_default = _profile(history=HistoryPolicy.KEEP_LAST, depth=10)
#: Whatever the middleware's defaults are.
qos_profile_system_default = _profile(
    history=HistoryPolicy.SYSTEM_DEFAULT,
    depth=0,
    reliability=ReliabilityPolicy.SYSTEM_DEFAULT,
    durability=DurabilityPolicy.SYSTEM_DEFAULT,
)
#: Sensor streams: BEST_EFFORT, VOLATILE, KEEP_LAST 5.
qos_profile_sensor_data = _profile(
    history=HistoryPolicy.KEEP_LAST, depth=5, reliability=ReliabilityPolicy.BEST_EFFORT
)
#: Services: RELIABLE, VOLATILE, KEEP_LAST 10.
qos_profile_services_default = _profile(history=HistoryPolicy.KEEP_LAST, depth=10)
#: Parameter services: RELIABLE, VOLATILE, KEEP_LAST 1000.
qos_profile_parameters = _profile(history=HistoryPolicy.KEEP_LAST, depth=1000)
#: /parameter_events: RELIABLE, VOLATILE, KEEP_LAST 1000.
qos_profile_parameter_events = _profile(history=HistoryPolicy.KEEP_LAST, depth=1000)
#: Match the majority of endpoints, as strictly as possible.
qos_profile_best_available = _profile(
    history=HistoryPolicy.KEEP_LAST,
    depth=10,
    reliability=ReliabilityPolicy.BEST_AVAILABLE,
    durability=DurabilityPolicy.BEST_AVAILABLE,
    deadline=DeadlineBestAvailable,
    liveliness=LivelinessPolicy.BEST_AVAILABLE,
    liveliness_lease_duration=LivelinessLeaseDurationeBestAvailable,
)
#: Action status topics: RELIABLE, TRANSIENT_LOCAL, KEEP_LAST 1.
qos_profile_action_status_default = _profile(
    history=HistoryPolicy.KEEP_LAST, depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL
)


class QoSPresetProfiles(Enum):
    """The predefined profiles by name."""

    UNKNOWN = qos_profile_unknown
    DEFAULT = qos_profile_default
    SYSTEM_DEFAULT = qos_profile_system_default
    SENSOR_DATA = qos_profile_sensor_data
    SERVICES_DEFAULT = qos_profile_services_default
    PARAMETERS = qos_profile_parameters
    PARAMETER_EVENTS = qos_profile_parameter_events
    ACTION_STATUS_DEFAULT = qos_profile_action_status_default
    BEST_AVAILABLE = qos_profile_best_available

    @classmethod
    def short_keys(cls) -> list[str]:
        """Return the lowercase member names."""
        return [name.lower() for name in cls.__members__]

    @classmethod
    def get_from_short_key(cls, name: str) -> QoSProfile:
        """Return a profile given its case-insensitive name."""
        return cls[name.upper()].value


class QoSCompatibility(IntEnum):
    """Result of :func:`qos_check_compatible`."""

    OK = 0
    WARNING = 1
    ERROR = 2


def _requested_ns(duration: Duration) -> int:
    """Unspecified (0) deadlines and leases mean 'infinite'."""
    return duration.nanoseconds if duration.nanoseconds > 0 else _INFINITE_NS


def qos_check_compatible(
    publisher_qos: QoSProfile, subscription_qos: QoSProfile
) -> tuple[QoSCompatibility, str]:
    """Check whether a publisher and a subscription with these profiles can communicate.

    Returns ``(QoSCompatibility.ERROR, reason)`` when they cannot, ``WARNING`` when it depends
    on policies left to the middleware (SYSTEM_DEFAULT, UNKNOWN, BEST_AVAILABLE), else ``OK``.
    """
    pub, sub = publisher_qos, subscription_qos
    errors: list[str] = []
    warnings_: list[str] = []
    undecided_reliability = {ReliabilityPolicy.SYSTEM_DEFAULT, ReliabilityPolicy.UNKNOWN}
    undecided_durability = {DurabilityPolicy.SYSTEM_DEFAULT, DurabilityPolicy.UNKNOWN}

    if pub.reliability == ReliabilityPolicy.BEST_EFFORT and (
        sub.reliability == ReliabilityPolicy.RELIABLE
    ):
        errors.append('Best effort publisher and reliable subscription;')
    elif pub.reliability in undecided_reliability and sub.reliability == ReliabilityPolicy.RELIABLE:
        warnings_.append(
            f'Publisher reliability is {pub.reliability.name} and subscription is RELIABLE;'
        )
    elif (
        pub.reliability == ReliabilityPolicy.BEST_EFFORT
        and sub.reliability in undecided_reliability
    ):
        warnings_.append(
            f'Publisher reliability is BEST_EFFORT and subscription is {sub.reliability.name};'
        )

    if pub.durability == DurabilityPolicy.VOLATILE and (
        sub.durability == DurabilityPolicy.TRANSIENT_LOCAL
    ):
        errors.append('Volatile publisher and transient local subscription;')
    elif (
        pub.durability in undecided_durability
        and sub.durability == DurabilityPolicy.TRANSIENT_LOCAL
    ):
        warnings_.append(
            f'Publisher durability is {pub.durability.name} and subscription is TRANSIENT_LOCAL;'
        )
    elif pub.durability == DurabilityPolicy.VOLATILE and sub.durability in undecided_durability:
        warnings_.append(
            f'Publisher durability is VOLATILE and subscription is {sub.durability.name};'
        )

    if _requested_ns(pub.deadline) > _requested_ns(sub.deadline):
        errors.append('Subscription deadline is shorter than the publisher deadline;')

    if pub.liveliness == LivelinessPolicy.AUTOMATIC and (
        sub.liveliness == LivelinessPolicy.MANUAL_BY_TOPIC
    ):
        errors.append("Publisher's liveliness is automatic and subscription's is manual by topic;")
    if _requested_ns(pub.liveliness_lease_duration) > _requested_ns(sub.liveliness_lease_duration):
        errors.append('Subscription liveliness lease duration is shorter than the publisher one;')

    if errors:
        return QoSCompatibility.ERROR, 'ERROR: ' + ' '.join(errors)
    if warnings_:
        return QoSCompatibility.WARNING, 'WARNING: ' + ' '.join(warnings_)
    return QoSCompatibility.OK, ''
