"""The msc_pf node's parameters: the controller configuration plus the node's own (ROS-free).

Every parameter is a field of :class:`MscPfNodeConfig`: the node's own settings (robot ID,
seed, the waypoint steering) and, at the top level, every field of
:class:`msc_pf.settings.MscPfConfig` (``scheme``, ``period_s``, and the sections as
``particle_filter.n_particles``, ``phases.gamma1_dbm``, ...). :data:`MSC_PF_PARAMETERS` is its
spec: the node declares it, the spawner parses ``--param`` with it, and
``config/msc_pf.yaml`` and the table in docs/msc_pf.md are generated from it.
"""

from __future__ import annotations

from dataclasses import dataclass

from swarm_common.params import ParameterSpec, parameter, section

from msc_pf.errors import ParameterError
from msc_pf.settings import MscPfConfig

__all__ = ['MSC_PF_PARAMETERS', 'NODE_NAME', 'MscPfNodeConfig']

NODE_NAME = 'msc_pf'


@dataclass(frozen=True)
class MscPfNodeConfig:
    """Everything the msc_pf node reads from its parameters."""

    robot_id: int = parameter(
        -1, 'numeric robot ID; -1 takes it from the namespace (r3 -> 3)', ge=-1
    )
    seed: int = parameter(
        0, 'seed of the robot controller (random search direction, PF, MSC draws)', ge=0
    )
    drive_rate_hz: float = parameter(
        10.0, 'rate of cmd_vel while steering toward the period waypoint', unit='Hz', gt=0.0
    )
    max_yaw_rate_rad_s: float = parameter(
        2.0, 'yaw-rate limit of the base', unit='rad/s', gt=0.0, read_only=False
    )
    heading_gain: float = parameter(
        2.0, 'yaw rate per radian of heading error', unit='1/s', gt=0.0, read_only=False
    )
    odom_timeout_s: float = parameter(
        1.0,
        'stop when the last odometry is older than this',
        unit='s',
        gt=0.0,
        read_only=False,
    )
    target_ids: tuple[int, ...] = parameter(
        (-1,), 'emitter IDs that are targets; [-1] accepts every emitter'
    )
    controller: MscPfConfig = section(MscPfConfig, prefix='')

    @property
    def accepted_targets(self) -> frozenset[int] | None:
        """The target emitter IDs, or None for every emitter."""
        return None if self.target_ids == (-1,) else frozenset(self.target_ids)


MSC_PF_PARAMETERS = ParameterSpec(MscPfNodeConfig, error=ParameterError)
