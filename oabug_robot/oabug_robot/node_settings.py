"""The OA-Bug node's parameters: the controller configuration plus the node's own (ROS-free).

Every parameter is a field of :class:`OABugNodeConfig`: the node's loop settings (rates, the
staleness timeout, the own AoA tag, the Random variant's seed) and, at the top level, the
parameters of :class:`oabug_robot.settings.OABugConfig` and its perception and motion
sections. :data:`OABUG_PARAMETERS` is the spec the node declares, the spawner and the batch
runner read overrides with, and ``config/oabug.yaml`` and the table in docs/oabug.md are
generated from.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from swarm_common.params import ParameterSpec, parameter, section

from oabug_robot.errors import ParameterError
from oabug_robot.settings import OABugConfig

__all__ = ['NODE_NAME', 'OABUG_PARAMETERS', 'OABugNodeConfig']

NODE_NAME = 'oabug'


@dataclass(frozen=True)
class OABugNodeConfig:
    """Everything the OA-Bug node reads from its parameters.

    ``controller.seed`` is not a parameter: :meth:`controller_config` sets it from ``seed``
    (-1: the robot index, so that robots of one swarm draw differently).
    """

    controller: OABugConfig = section(OABugConfig, prefix='')
    control_rate_hz: float = parameter(10.0, 'control loop rate', unit='Hz', gt=0.0)
    state_rate_hz: float = parameter(
        2.0,
        'state topic rate; a step with an event or a change of staleness is always published',
        unit='Hz',
        gt=0.0,
        read_only=False,
    )
    stale_timeout_s: float = parameter(
        1.0,
        'stop when scan, imu (or gas, gas variants) is older',
        unit='s',
        gt=0.0,
        read_only=False,
    )
    own_tag_id: str = parameter(
        '', 'own AoA tag id, ignored in the bearings ("" keeps all)', read_only=False
    )
    seed: int = parameter(-1, 'seed of the Random variant; -1 uses robot_index', ge=-1)

    def controller_config(self) -> OABugConfig:
        """The controller configuration, with the seed resolved."""
        seed = self.seed if self.seed >= 0 else self.controller.robot_index
        return dataclasses.replace(self.controller, seed=seed)


OABUG_PARAMETERS = ParameterSpec(OABugNodeConfig, error=ParameterError)
