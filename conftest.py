"""Test-session settings shared by every package's tests.

The suite runs the way a careful robot deployment should be checked: generated message
classes validate every field assignment (as Jazzy does with ROS_PYTHON_CHECK_FIELDS=1), and
the built-in runtime round-trips every published message through CDR, so a value that a
robot could not serialize fails here. Both are set before any test module imports a
message class; an explicit setting in the environment wins.

The same tests run on either ROS runtime (``SWARM_RUNTIME=builtin`` or ``rclpy``, see
docs/runtime.md). Every test process (each pytest-xdist worker) gets a DDS domain
of its own (``ROS_DOMAIN_ID``: ``SWARM_TEST_DOMAIN_BASE``, default 40, plus the worker
number, or the next id no other test process on the machine holds) and discovery stays on
this host (``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``); both are set before rclpy is
imported, and child processes that tests start inherit them (swarm_runtime.dds_isolation).
Tests marked ``builtin_only(reason)`` hold only on the built-in runtime (bit-exact
determinism, virtual wall time) and are skipped on real rclpy with their reason. Tests
marked ``runtime_independent(reason)`` cannot see which runtime is in use (batch runners,
protocol parsers, processes that choose their runtime themselves); ``make test-rclpy``
deselects them (``-m 'not runtime_independent'``), since they would only repeat the
built-in leg, and such a test that starts a ROS node fails.

The workspace's Python packages are imported here, from wherever they are installed (the
development virtualenv or a colcon overlay), before pytest collects anything: pytest's
importlib import mode would otherwise take a package's source directory (``bayes_swarm/``,
which holds the package ``bayes_swarm/bayes_swarm``) for the package when it imports the
tests under it, and ``bayes_swarm.batch_sim`` would not be found from an overlay.

BLAS runs single-threaded: the suite already uses both cores through pytest-xdist, and a
multi-threaded BLAS on top oversubscribes them (a GP-heavy test module then takes 40x longer
on a busy machine).
"""

from __future__ import annotations

import atexit
import importlib
import os
from pathlib import Path

import pytest
from swarm_runtime.dds_isolation import isolate_test_process  # imports nothing of ROS

os.environ.setdefault('ROS_PYTHON_CHECK_FIELDS', '1')
os.environ.setdefault('SWARM_RUNTIME_CDR_ROUNDTRIP', '1')
os.environ.setdefault('MPLBACKEND', 'Agg')
for _blas_threads in ('OPENBLAS_NUM_THREADS', 'OMP_NUM_THREADS', 'MKL_NUM_THREADS'):
    os.environ.setdefault(_blas_threads, '1')


# Before anything imports rclpy: a DDS domain of this process's own, discovery on this host
# (swarm_runtime.dds_isolation). The reservation lives as long as this process.
_DOMAIN = isolate_test_process()
atexit.register(_DOMAIN.release)


def _import_workspace_packages() -> None:
    """Import every ament_python package of the workspace from its installed location."""
    root = Path(__file__).resolve().parent
    for setup_py in sorted([*root.glob('*/setup.py'), *root.glob('src/*/setup.py')]):
        name = setup_py.parent.name
        if not (setup_py.parent / name / '__init__.py').is_file():
            continue
        try:
            importlib.import_module(name)
        except ImportError:
            continue  # not installed: its tests report that themselves


_import_workspace_packages()


def pytest_configure(config: pytest.Config) -> None:
    """Register the runtime marker; under CI, fixed Hypothesis examples.

    Under CI, property-based tests draw the same examples every run (no flaky landings).
    Locally they keep drawing fresh examples, which is where new failures get found; a
    failure found either way is replayed from Hypothesis' example database or its report.
    """
    config.addinivalue_line(
        'markers',
        'builtin_only(reason): holds only on the built-in runtime (bit-exact determinism, '
        'virtual wall time); skipped on real rclpy',
    )
    config.addinivalue_line(
        'markers',
        'runtime_independent(reason): cannot see which ROS runtime is in use and starts no '
        'node; make test-rclpy leaves it to the built-in leg',
    )
    # rosidl's parser (imported by rclpy's type support) uses an old lark.
    config.addinivalue_line('filterwarnings', "ignore:module 'sre_:DeprecationWarning:lark")
    if os.environ.get('CI', '').lower() != 'true':
        return
    from hypothesis import settings

    settings.register_profile('ci', derandomize=True, database=None)
    settings.load_profile('ci')


def _marker_reason(item: pytest.Item, name: str) -> str | None:
    """The reason string of ``item``'s ``name`` marker; None without the marker."""
    marker = item.get_closest_marker(name)
    if marker is None:
        return None
    reason = marker.kwargs.get('reason') or (marker.args[0] if marker.args else '')
    if not isinstance(reason, str) or not reason:
        msg = f'{item.nodeid}: {name} needs a reason string'
        raise pytest.UsageError(msg)
    return reason


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Check the markers' reasons; on real rclpy, skip ``builtin_only`` tests with theirs."""
    for item in items:
        _marker_reason(item, 'runtime_independent')
    marked = [(item, _marker_reason(item, 'builtin_only')) for item in items]
    from swarm_runtime.ros import using_real_rclpy

    if not using_real_rclpy():
        return
    for item, reason in marked:
        if reason is not None:
            item.add_marker(pytest.mark.skip(reason=f'built-in runtime only: {reason}'))


@pytest.fixture(autouse=True)
def _runtime_independent_starts_no_node(
    request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Fail a ``runtime_independent`` test that constructs a ROS node (of either runtime)."""
    if request.node.get_closest_marker('runtime_independent') is None:
        return
    from swarm_runtime.ros import Node

    nodeid = request.node.nodeid

    def refuse(self: object, *args: object, **kwargs: object) -> None:
        msg = f'{nodeid} is marked runtime_independent but starts a ROS node'
        raise AssertionError(msg)

    monkeypatch.setattr(Node, '__init__', refuse)
