"""Each test process holds a DDS domain of its own; discovery stays on this machine."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
from swarm_runtime.dds_isolation import (
    DOMAIN_BASE_ENV_VAR,
    MAX_TEST_DOMAIN_ID,
    DomainsExhaustedError,
    dds_test_environment,
    preferred_test_domain,
    reserve_test_domain,
)


def test_this_test_process_runs_in_its_reserved_domain_on_localhost() -> None:
    domain = int(os.environ['ROS_DOMAIN_ID'])
    assert 1 <= domain <= MAX_TEST_DOMAIN_ID
    assert os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] == 'LOCALHOST'
    assert 'ROS_STATIC_PEERS' not in os.environ


def test_the_preferred_domain_is_the_base_plus_the_worker_number() -> None:
    assert preferred_test_domain({}) == 40
    assert preferred_test_domain({'PYTEST_XDIST_WORKER': 'gw3'}) == 43
    assert preferred_test_domain({DOMAIN_BASE_ENV_VAR: '70', 'PYTEST_XDIST_WORKER': 'gw1'}) == 71


@pytest.mark.parametrize('base', ['0', '102', 'x'])
def test_a_base_that_leaves_the_usable_ids_is_an_error(base: str) -> None:
    with pytest.raises(ValueError, match=DOMAIN_BASE_ENV_VAR):
        preferred_test_domain({DOMAIN_BASE_ENV_VAR: base, 'PYTEST_XDIST_WORKER': 'gw0'})


def test_a_held_domain_is_skipped_and_free_again_after_release(tmp_path: Path) -> None:
    first = reserve_test_domain(50, lock_dir=tmp_path)
    second = reserve_test_domain(50, lock_dir=tmp_path)
    assert (first.domain_id, second.domain_id) == (50, 51)
    first.release()
    third = reserve_test_domain(50, lock_dir=tmp_path)
    assert third.domain_id == 50
    second.release()
    third.release()


def test_the_search_wraps_round_and_fails_when_every_id_is_held(tmp_path: Path) -> None:
    held = [reserve_test_domain(MAX_TEST_DOMAIN_ID, lock_dir=tmp_path)]
    held.append(reserve_test_domain(MAX_TEST_DOMAIN_ID, lock_dir=tmp_path))
    assert [r.domain_id for r in held] == [MAX_TEST_DOMAIN_ID, 1]
    held += [reserve_test_domain(1, lock_dir=tmp_path) for _ in range(MAX_TEST_DOMAIN_ID - 2)]
    assert sorted(r.domain_id for r in held) == list(range(1, MAX_TEST_DOMAIN_ID + 1))
    with pytest.raises(DomainsExhaustedError):
        reserve_test_domain(1, lock_dir=tmp_path)
    for reservation in held:
        reservation.release()


def test_another_process_does_not_get_a_domain_this_one_holds(tmp_path: Path) -> None:
    held = reserve_test_domain(60, lock_dir=tmp_path)
    code = (
        'import sys\n'
        'from pathlib import Path\n'
        'from swarm_runtime.dds_isolation import reserve_test_domain\n'
        'print(reserve_test_domain(60, lock_dir=Path(sys.argv[1])).domain_id)\n'
    )
    result = subprocess.run(
        [sys.executable, '-c', code, str(tmp_path)], capture_output=True, text=True, check=True
    )
    assert int(result.stdout) == 61
    held.release()


def test_the_environment_names_the_domain_and_keeps_discovery_local() -> None:
    assert dds_test_environment(7) == {
        'ROS_DOMAIN_ID': '7',
        'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST',
    }
