"""Mission files: what a standalone bridge needs beyond its parameters, and its outcome file.

A bridge started on its own (``ros2 run sim_bridge sim_bridge``) reads the site, the robots'
start poses, the engine's sensor set and the mission extensions from the JSON file named by
its ``mission_file`` parameter. This is how a spawner's ``--processes`` mode hands a mission
to the bridge process: values that are not ROS parameters (a site, an (N, 3) array of poses,
a signal case or RSSI targets) go into the file; the engine's settings stay parameters.

At the mission's end (``max_sim_time_s``, every room covered with
``stop_when_all_rooms_covered``, an extension done) or when stopped, the bridge writes the
outcome file named by ``outcome_file`` (atomically: a reader sees the whole file or none):
stop reason, sim time, room entries, sampled true poses, distances and each extension's
outcome. :func:`read_outcome` reads it back.

The file format (``format`` 1)::

    {"format": 1,
     "site_file": "site.yaml",              # a site file, a .lay layout or a preset, or
     "site_geometry": {"name": ..., "walls": [[[x, y], [x, y]], ...],
                       "room_rects": [[[x0, y0, x1, y1], ...], ...]},
     "initial_poses": [[x, y, yaw], ...],
     "sensors": ["scan", "gas", ...],      # optional: the engine's sensor set
     "extensions": [{"kind": "signal", ...}, {"kind": "rssi", ...}]}

Relative paths are relative to the mission file.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from swarm_common.outputs import atomic_output
from swarm_sim.engine import SiteGeometry
from swarm_sim.errors import ConfigurationError

__all__ = [
    'FORMAT',
    'BridgeMission',
    'MissionFileError',
    'build_extension',
    'extension_outcome',
    'load_mission',
    'read_outcome',
    'rssi_entry',
    'signal_entry',
    'write_mission',
    'write_outcome',
]

FORMAT = 1


class MissionFileError(ConfigurationError):
    """A mission or outcome file cannot be read or does not describe a mission."""


@dataclass(frozen=True)
class BridgeMission:
    """A mission file's content, resolved.

    Attributes:
        site: the site (a :class:`swarm_sim.sites.model.Site` or a :class:`SiteGeometry`).
        initial_poses: (N, 3) start poses x [m], y [m], yaw [rad].
        sensors: the engine's sensor set (None: keep the configuration's).
        extensions: the mission extensions, built.
    """

    site: Any
    initial_poses: np.ndarray
    sensors: frozenset[str] | None
    extensions: tuple[Any, ...]


def signal_entry(
    case: Any,
    *,
    noise_std: float,
    relative_noise: float,
    seed: int,
) -> dict[str, Any]:
    """The mission-file entry of a signal-field search (the Bayes-Swarm extension).

    ``case`` is a :class:`swarm_sim.signal_fields.SignalCase`, possibly changed from the
    named case in its depots, direction offsets, T_max or observation rate; those are stored.
    """
    return {
        'kind': 'signal',
        'case': case.name,
        'depots_m': np.asarray(case.depots_m, dtype=float).tolist(),
        'depot_direction_offsets_deg': [float(v) for v in case.depot_direction_offsets_deg],
        'max_mission_time_s': float(case.max_mission_time_s),
        'observation_rate_hz': float(case.observation_rate_hz),
        'noise_std': float(noise_std),
        'relative_noise': float(relative_noise),
        'seed': int(seed),
    }


def rssi_entry(targets: Any, *, seed: int) -> dict[str, Any]:
    """The mission-file entry of an RSSI target field (the MSC + PF extension)."""
    config = targets.config
    return {
        'kind': 'rssi',
        'n_targets': int(config.n_targets),
        'field_size_m': float(config.field_size_m),
        'task_area_m': float(config.task_area_m),
        'positions_m': np.asarray(targets.positions_m, dtype=float).tolist(),
        'seed': int(seed),
    }


def build_extension(entry: Mapping[str, Any]) -> Any:
    """The :class:`sim_bridge.extensions.SimExtension` a mission-file entry describes.

    Raises:
        MissionFileError: an unknown kind or a missing or bad value.
    """
    kind = entry.get('kind')
    try:
        if kind == 'signal':
            from swarm_sim.signal_fields import get_case
            from swarm_sim.signal_mission import SignalMissionModel

            from sim_bridge.signal_extension import SignalExtension

            case = replace(
                get_case(str(entry['case'])),
                depots_m=np.asarray(entry['depots_m'], dtype=float).reshape(-1, 2),
                depot_direction_offsets_deg=tuple(
                    float(v) for v in entry['depot_direction_offsets_deg']
                ),
                max_mission_time_s=float(entry['max_mission_time_s']),
                observation_rate_hz=float(entry['observation_rate_hz']),
            )
            model = SignalMissionModel(
                case,
                noise_std=float(entry['noise_std']),
                relative_noise=float(entry['relative_noise']),
                seed=int(entry['seed']),
            )
            return SignalExtension(model)
        if kind == 'rssi':
            from swarm_sim.rssi_targets import RssiTargetConfig, RssiTargetField

            from sim_bridge.rssi_extension import RssiExtension

            config = RssiTargetConfig(
                n_targets=int(entry['n_targets']),
                field_size_m=float(entry['field_size_m']),
                task_area_m=float(entry['task_area_m']),
            )
            targets = RssiTargetField(config, np.asarray(entry['positions_m'], dtype=float))
            return RssiExtension(targets, seed=int(entry['seed']))
    except (KeyError, TypeError, ValueError) as err:
        msg = f'mission file: extension {kind!r}: bad or missing value: {err}'
        raise MissionFileError(msg) from err
    msg = f"mission file: unknown extension kind {kind!r} (known: 'signal', 'rssi')"
    raise MissionFileError(msg)


def extension_outcome(extension: Any) -> dict[str, Any]:
    """What a spawner reports of an extension at the end of a run (JSON values)."""
    model = getattr(extension, 'model', None)
    if model is not None:  # signal search
        return {
            'kind': 'signal',
            'found': bool(model.found),
            'found_time_s': _json_float(model.found_time_s),
            'finder': int(model.finder),
            'tau': _json_float(model.tau()),
        }
    targets = getattr(extension, 'targets', None)
    if targets is not None:  # RSSI targets
        return {
            'kind': 'rssi',
            'capture_times_s': [_json_float(t) for t in targets.capture_time_s],
            'positions_m': np.asarray(targets.positions_m, dtype=float).tolist(),
            'all_captured': bool(targets.all_captured),
        }
    return {'kind': type(extension).__name__}


def _json_float(value: float) -> float | None:
    value = float(value)
    return value if math.isfinite(value) else None


def _geometry_entry(site: SiteGeometry) -> dict[str, Any]:
    if site.room_index_at is not None:
        msg = 'a site geometry with a room_index_at function cannot go into a mission file'
        raise MissionFileError(msg)
    return {
        'name': site.name,
        'walls': np.asarray(site.walls, dtype=float).reshape(-1, 2, 2).tolist(),
        'room_rects': [np.asarray(r, dtype=float).reshape(-1, 4).tolist() for r in site.room_rects],
    }


def write_mission(
    path: Path,
    *,
    site: Any,
    initial_poses: np.ndarray,
    sensors: frozenset[str] | None = None,
    extensions: Sequence[Mapping[str, Any]] = (),
) -> Path:
    """Write a mission file (and, for a site model, its site file next to it); return it.

    ``site`` is a :class:`swarm_sim.sites.model.Site` (saved as ``<stem>.site.yaml``) or a
    :class:`SiteGeometry` (stored in the file).
    """
    path = Path(path)
    data: dict[str, Any] = {'format': FORMAT}
    if isinstance(site, SiteGeometry):
        data['site_geometry'] = _geometry_entry(site)
    else:
        from swarm_sim.sites.site_file import save_site

        site_path = path.with_name(f'{path.stem}.site.yaml')
        save_site(site, site_path)
        data['site_file'] = site_path.name
    data['initial_poses'] = np.asarray(initial_poses, dtype=float).reshape(-1, 3).tolist()
    if sensors is not None:
        data['sensors'] = sorted(sensors)
    data['extensions'] = [dict(e) for e in extensions]
    with atomic_output(path) as partial:
        partial.write_text(json.dumps(data, indent=1) + '\n', encoding='utf-8')
    return path


def _read_json(path: Path, what: str) -> dict[str, Any]:
    try:
        data = json.loads(Path(path).read_text(encoding='utf-8'))
    except OSError as err:
        msg = f'{what} {path}: {err.strerror or err}'
        raise MissionFileError(msg) from err
    except ValueError as err:
        msg = f'{what} {path}: not JSON: {err}'
        raise MissionFileError(msg) from err
    if not isinstance(data, dict) or data.get('format') != FORMAT:
        msg = f'{what} {path}: not a format-{FORMAT} {what}'
        raise MissionFileError(msg)
    return data


def load_mission(path: str | Path, *, site_seed: int = 0) -> BridgeMission:
    """Read a mission file and build its site and extensions.

    Raises:
        MissionFileError: the file cannot be read or a value is missing or bad.
        swarm_sim.sites.SiteError: its site file is invalid.
    """
    path = Path(path)
    data = _read_json(path, 'mission file')
    try:
        if 'site_geometry' in data:
            geo = data['site_geometry']
            site: Any = SiteGeometry(
                walls=np.asarray(geo['walls'], dtype=float).reshape(-1, 2, 2),
                room_rects=tuple(
                    np.asarray(r, dtype=float).reshape(-1, 4) for r in geo['room_rects']
                ),
                name=str(geo.get('name', 'site')),
            )
        else:
            from swarm_sim.site_loading import load_site

            site_file = str(data['site_file'])
            candidate = path.parent / site_file
            site = load_site(str(candidate) if candidate.exists() else site_file, seed=site_seed)
        poses = np.asarray(data['initial_poses'], dtype=float)
        if poses.ndim != 2 or poses.shape[1] != 3 or not np.all(np.isfinite(poses)):
            raise ValueError(f'initial_poses must be N rows of finite x, y, yaw, got {poses.shape}')
        sensors = frozenset(data['sensors']) if 'sensors' in data else None
        entries = data.get('extensions', [])
    except (KeyError, TypeError, ValueError) as err:
        msg = f'mission file {path}: bad or missing value: {err}'
        raise MissionFileError(msg) from err
    extensions = tuple(build_extension(e) for e in entries)
    return BridgeMission(site, poses, sensors, extensions)


def write_outcome(path: str | Path, outcome: Mapping[str, Any]) -> None:
    """Write an outcome file atomically (the ``format`` key is added)."""
    text = json.dumps({'format': FORMAT, **outcome}) + '\n'
    with atomic_output(Path(path)) as partial:
        partial.write_text(text, encoding='utf-8')
        with partial.open('rb') as handle:
            os.fsync(handle.fileno())


def read_outcome(path: str | Path) -> dict[str, Any]:
    """Read an outcome file written by :func:`write_outcome`.

    Raises:
        MissionFileError: missing, unreadable or not an outcome file.
    """
    return _read_json(Path(path), 'outcome file')
