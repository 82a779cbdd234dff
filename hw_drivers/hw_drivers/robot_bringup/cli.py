"""robot_bringup: one robot's drivers and its OA-Bug node as supervised child processes.

``robot_bringup --robot r0 --own-tag D2 --variant gas_sound --robot-index 0 --robot-count 4``
starts, in this order, the pump driver (first, so the line is held off), the lidar, gas, IMU
and AoA receiver drivers, optionally the locator host binary (after the AoA receiver is
listening), and the OA-Bug node, all in the robot's namespace with frame ids that match the
simulator's (``r0/laser``, ``r0/imu_link``, ...). If any child exits, the others are stopped
(SIGINT, then SIGTERM, then SIGKILL) and the bringup exits non-zero, so systemd's
``Restart=on-failure`` restarts the robot as a whole; only the locator host, which exits by
design whenever its connection ends, is restarted alone. ``--dry-run`` prints the commands.

Children are started with ``ros2 run`` on a ROS machine, or with ``python -m`` where ``ros2``
is missing (``--launcher`` chooses explicitly).
"""

from __future__ import annotations

import argparse
import shlex
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

__all__ = ['ChildSpec', 'build_plan', 'driver_parameters', 'main', 'run']

# executable name -> module, as in setup.py's console_scripts.
EXECUTABLES = {
    'pump_node': ('hw_drivers', 'hw_drivers.pump_node'),
    'rplidar_node': ('hw_drivers', 'hw_drivers.rplidar_node'),
    'gas_adc_node': ('hw_drivers', 'hw_drivers.gas_node'),
    'mpu6050_node': ('hw_drivers', 'hw_drivers.mpu6050_node'),
    'aoa_receiver_node': ('hw_drivers', 'hw_drivers.aoa_receiver_node'),
    'oabug': ('oabug_robot', 'oabug_robot.node'),
}
DRIVERS = ('pump_node', 'rplidar_node', 'gas_adc_node', 'mpu6050_node', 'aoa_receiver_node')


@dataclass(frozen=True)
class ChildSpec:
    """One process of the bringup; ``respawn`` restarts it alone when it exits."""

    name: str
    command: tuple[str, ...]
    settle_s: float = 0.0
    respawn: bool = False


@dataclass(frozen=True)
class BringupOptions:
    """What to start for one robot."""

    robot: str = 'r0'
    own_tag_id: str = ''
    variant: str = 'gas_sound'
    robot_index: int = 0
    robot_count: int = 1
    fake: bool = False
    with_oabug: bool = True
    gas_backend: str = 'ads1115'
    locator_command: str = ''
    params_file: str = ''
    launcher: str = 'auto'
    extra: Mapping[str, Mapping[str, Any]] = field(default_factory=dict)


def driver_parameters(robot: str, *, own_tag_id: str = '', fake: bool = False) -> dict[str, dict]:
    """Per-driver parameters that make a real robot publish what the simulator publishes.

    Frame ids follow the sim bridge (``<robot>/laser``, ``<robot>/gas_sensor``,
    ``<robot>/imu_link``, ``<robot>/base_link`` for bearings).
    """
    params: dict[str, dict[str, Any]] = {
        'pump_node': {},
        'rplidar_node': {'frame_id': f'{robot}/laser'},
        'gas_adc_node': {'frame_id': f'{robot}/gas_sensor'},
        'mpu6050_node': {'frame_id': f'{robot}/imu_link'},
        'aoa_receiver_node': {'frame_id': f'{robot}/base_link', 'own_tag_id': own_tag_id},
    }
    if fake:
        for name in DRIVERS:
            params[name]['fake_device'] = True
        params['aoa_receiver_node'].pop('fake_device')
    return params


_YAML_NON_STRINGS = {'', 'true', 'false', 'yes', 'no', 'on', 'off', 'null', '~'}


def _looks_like_a_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _format_value(value: Any) -> str:
    """A ``-p name:=value`` value; strings that YAML would read as something else are quoted.

    ROS parses command-line parameter values as YAML, so a tag id such as ``42`` would become
    an integer and fail against the string parameter.
    """
    if isinstance(value, bool):
        return 'true' if value else 'false'
    if isinstance(value, str):
        if value.lower() in _YAML_NON_STRINGS or _looks_like_a_number(value):
            return f"'{value}'"
        return value
    return str(value)


def _command(
    executable: str, namespace: str, params: Mapping[str, Any], options: BringupOptions
) -> tuple[str, ...]:
    package, module = EXECUTABLES[executable]
    launcher = options.launcher
    if launcher == 'auto':
        launcher = 'ros2' if shutil.which('ros2') else 'python'
    head = (
        ('ros2', 'run', package, executable)
        if launcher == 'ros2'
        else (sys.executable, '-m', module)
    )
    args: list[str] = ['--ros-args', '-r', f'__ns:=/{namespace}']
    if options.params_file:
        args += ['--params-file', options.params_file]
    for key, value in params.items():
        args += ['-p', f'{key}:={_format_value(value)}']
    return (*head, *args)


def build_plan(options: BringupOptions) -> list[ChildSpec]:
    """The processes to start, in order."""
    params = driver_parameters(options.robot, own_tag_id=options.own_tag_id, fake=options.fake)
    params['gas_adc_node']['backend'] = options.gas_backend
    for name, extra in options.extra.items():
        params.setdefault(name, {}).update(extra)
    plan = [
        ChildSpec(name, _command(name, options.robot, params[name], options), settle_s=0.5)
        for name in DRIVERS
    ]
    if options.locator_command:
        # The authors' locator exits whenever its TCP connection ends: respawn it alone.
        command = tuple(shlex.split(options.locator_command))
        plan.append(ChildSpec('aoa_locator', command, settle_s=0.5, respawn=True))
    if options.with_oabug:
        oabug_params = {
            'variant': options.variant,
            'robot_index': options.robot_index,
            'robot_count': options.robot_count,
            'own_tag_id': options.own_tag_id,
            **params.get('oabug', {}),
        }
        plan.append(ChildSpec('oabug', _command('oabug', options.robot, oabug_params, options)))
    return plan


def _stop_all(children: Sequence[tuple[ChildSpec, subprocess.Popen]], grace_s: float) -> None:
    """SIGINT (what ros2 launch sends), then SIGTERM, then SIGKILL; in reverse start order."""
    alive = [(spec, p) for spec, p in reversed(children) if p.poll() is None]
    for sig in (signal.SIGINT, signal.SIGTERM):
        for _, process in alive:
            if process.poll() is None:
                process.send_signal(sig)
        deadline = time.monotonic() + grace_s
        while time.monotonic() < deadline and any(p.poll() is None for _, p in alive):
            time.sleep(0.05)
    for _, process in alive:
        if process.poll() is None:
            process.kill()
            process.wait()


def run(
    options: BringupOptions,
    *,
    dry_run: bool = False,
    grace_s: float = 5.0,
    respawn_delay_s: float = 2.0,
) -> int:
    """Start the plan and supervise it; return the exit status for the process."""
    plan = build_plan(options)
    if dry_run:
        for spec in plan:
            print(' '.join(spec.command))
        return 0
    children: list[tuple[ChildSpec, subprocess.Popen]] = []
    stop = {'signal': 0}

    def on_signal(signum: int, _frame: object) -> None:
        stop['signal'] = signum

    previous = {sig: signal.signal(sig, on_signal) for sig in (signal.SIGTERM, signal.SIGINT)}
    status = 0
    try:
        for spec in plan:
            print(f'starting {spec.name}: {" ".join(spec.command)}', flush=True)
            children.append((spec, subprocess.Popen(spec.command)))
            time.sleep(spec.settle_s)
        while not stop['signal']:
            exited = [(i, spec, p) for i, (spec, p) in enumerate(children) if p.poll() is not None]
            fatal = [(spec, p) for _, spec, p in exited if not spec.respawn]
            if fatal:
                spec, process = fatal[0]
                print(f'{spec.name} exited with status {process.returncode}; stopping', flush=True)
                status = 1
                break
            for index, spec, process in exited:
                print(f'{spec.name} exited ({process.returncode}); restarting it', flush=True)
                time.sleep(respawn_delay_s)
                children[index] = (spec, subprocess.Popen(spec.command))
            time.sleep(0.2)
    finally:
        _stop_all(children, grace_s)
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    return status


def parse_args(argv: Sequence[str] | None = None) -> tuple[BringupOptions, bool]:
    """Command-line options."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--robot', default='r0', help='robot name = namespace (r0, r1, ...)')
    parser.add_argument('--own-tag', default='', help="this robot's AoA tag id, e.g. D2")
    parser.add_argument('--variant', default='gas_sound', help='OA-Bug variant (Table I)')
    parser.add_argument('--robot-index', type=int, default=0)
    parser.add_argument('--robot-count', type=int, default=1)
    parser.add_argument('--gas-backend', default='ads1115')
    parser.add_argument('--locator-command', default='', help='locator host command line')
    parser.add_argument('--params-file', default='', help='ROS parameter YAML for all nodes')
    parser.add_argument('--fake', action='store_true', help='drivers use simulated devices')
    parser.add_argument('--no-oabug', action='store_true', help='start the drivers only')
    parser.add_argument('--launcher', choices=('auto', 'ros2', 'python'), default='auto')
    parser.add_argument('--dry-run', action='store_true', help='print the commands only')
    args = parser.parse_args(argv)
    options = BringupOptions(
        robot=args.robot,
        own_tag_id=args.own_tag,
        variant=args.variant,
        robot_index=args.robot_index,
        robot_count=args.robot_count,
        fake=args.fake,
        with_oabug=not args.no_oabug,
        gas_backend=args.gas_backend,
        locator_command=args.locator_command,
        params_file=args.params_file,
        launcher=args.launcher,
    )
    return options, args.dry_run


def main(argv: Sequence[str] | None = None) -> None:
    """Entry point of ``robot_bringup``."""
    options, dry_run = parse_args(argv)
    sys.exit(run(options, dry_run=dry_run))


if __name__ == '__main__':
    main()
