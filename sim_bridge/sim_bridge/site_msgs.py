"""Site <-> ``swarm_interfaces/Site`` message, the ground truth the simulator latches on
``/sim/site`` (reliable, transient local, depth 1).

Pure functions: no node, no publishing. Message classes come through
:mod:`swarm_runtime.ros`, so the real generated classes are used on a ROS machine. Every
value is put in with the type the field has (Python float for float64, int for int32/int64,
lists of floats for float64[]), as ROS_PYTHON_CHECK_FIELDS=1 demands.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from swarm_common.stamps import stamp_from_seconds
from swarm_runtime.ros import message_module
from swarm_sim.sites.errors import SiteError
from swarm_sim.sites.model import DeparturePoint, Door, Room, Site

__all__ = ['NO_SEED', 'site_from_ros', 'site_to_ros']

NO_SEED = -1
"""``seed`` of a site message whose site was not generated."""


def _floats(values: np.ndarray | tuple[float, ...]) -> list[float]:
    return [float(v) for v in np.asarray(values, dtype=np.float64).ravel()]


def _stamp(time_s: float) -> Any:
    builtin_interfaces = message_module('builtin_interfaces')
    return stamp_from_seconds(time_s, builtin_interfaces.Time)


def _door_to_msg(door: Door) -> Any:
    swarm_interfaces = message_module('swarm_interfaces')
    x0, y0, x1, y1 = door.segment
    return swarm_interfaces.SiteDoor(
        x0=float(x0),
        y0=float(y0),
        x1=float(x1),
        y1=float(y1),
        room_ids=[int(i) for i in door.room_ids],
    )


def site_to_ros(site: Site, *, time_s: float = 0.0, frame_id: str = 'world') -> Any:
    """The ``swarm_interfaces/Site`` message of ``site``, stamped ``time_s`` [s] in ``frame_id``."""
    swarm_interfaces = message_module('swarm_interfaces')
    std_msgs = message_module('std_msgs')
    rooms = [
        swarm_interfaces.SiteRoom(
            id=int(room.room_id),
            label=room.label,
            has_victim=bool(room.has_victim),
            rects=_floats(room.rects),
            polygon=[] if room.polygon is None else _floats(room.polygon),
        )
        for room in site.rooms
    ]
    departures = [
        swarm_interfaces.SiteDeparturePoint(
            name=point.name,
            x=float(point.x_m),
            y=float(point.y_m),
            heading=math.nan if point.heading_rad is None else float(point.heading_rad),
        )
        for point in site.departure_points.values()
    ]
    return swarm_interfaces.Site(
        header=std_msgs.Header(stamp=_stamp(time_s), frame_id=frame_id),
        name=site.name,
        seed=NO_SEED if site.seed is None else int(site.seed),
        width_m=float(site.width_m),
        height_m=float(site.height_m),
        grid_m=0.0 if site.grid_m is None else float(site.grid_m),
        walls=_floats(site.walls),
        rooms=rooms,
        doors=[_door_to_msg(door) for door in site.doors],
        entrance=[] if site.entrance is None else [_door_to_msg(site.entrance)],
        departure_points=departures,
    )


def _door_from_msg(msg: Any) -> Door:
    return Door((msg.x0, msg.y0, msg.x1, msg.y1), tuple(int(i) for i in msg.room_ids))


def site_from_ros(msg: Any) -> Site:
    """The site a ``swarm_interfaces/Site`` message describes (structurally checked; run
    :func:`~swarm_sim.sites.validation.validate_site` for the geometric invariants).

    Raises:
        SiteError: the message is malformed (e.g. a walls array not a multiple of 4).
    """
    rooms = tuple(
        Room(
            room.id,
            np.asarray(room.rects, dtype=np.float64).reshape(-1, 4),
            label=room.label,
            has_victim=room.has_victim,
            polygon=np.asarray(room.polygon, dtype=np.float64).reshape(-1, 2)
            if len(room.polygon)
            else None,
        )
        for room in msg.rooms
    )
    walls = np.asarray(msg.walls, dtype=np.float64)
    if walls.size % 4:
        msg_text = f'Site message walls hold {walls.size} values, not a multiple of 4'
        raise SiteError(msg_text)
    departures = {
        point.name: DeparturePoint(
            point.name, point.x, point.y, None if math.isnan(point.heading) else point.heading
        )
        for point in msg.departure_points
    }
    return Site(
        name=msg.name,
        width_m=msg.width_m,
        height_m=msg.height_m,
        walls=walls.reshape(-1, 4),
        rooms=rooms,
        doors=tuple(_door_from_msg(door) for door in msg.doors),
        entrance=_door_from_msg(msg.entrance[0]) if len(msg.entrance) else None,
        departure_points=departures,
        grid_m=msg.grid_m if msg.grid_m > 0 else None,
        seed=None if msg.seed == NO_SEED else msg.seed,
    )
