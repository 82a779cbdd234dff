"""Test-session settings shared by every package's tests.

The suite runs the way a careful robot deployment should be checked: generated message
classes validate every field assignment (as Jazzy does with ROS_PYTHON_CHECK_FIELDS=1), and
the built-in runtime round-trips every published message through CDR, so a value that a
robot could not serialize fails here. Both are set before any test module imports a
message class; an explicit setting in the environment wins.

BLAS runs single-threaded: the suite already uses both cores through pytest-xdist, and a
multi-threaded BLAS on top oversubscribes them (a GP-heavy test module then takes 40x longer
on a busy machine).
"""

import os

os.environ.setdefault('ROS_PYTHON_CHECK_FIELDS', '1')
os.environ.setdefault('SWARM_RUNTIME_CDR_ROUNDTRIP', '1')
os.environ.setdefault('MPLBACKEND', 'Agg')
for _blas_threads in ('OPENBLAS_NUM_THREADS', 'OMP_NUM_THREADS', 'MKL_NUM_THREADS'):
    os.environ.setdefault(_blas_threads, '1')


def pytest_configure(config: object) -> None:
    """Under CI, property-based tests draw the same examples every run (no flaky landings).

    Locally they keep drawing fresh examples, which is where new failures get found; a
    failure found either way is replayed from Hypothesis' example database or its report.
    """
    if os.environ.get('CI', '').lower() != 'true':
        return
    from hypothesis import settings

    settings.register_profile('ci', derandomize=True, database=None)
    settings.load_profile('ci')
