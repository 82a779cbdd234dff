"""The ``runtime_independent`` marker of the root conftest.py: a marked test starts no node."""

from __future__ import annotations

import pytest


@pytest.mark.runtime_independent(reason="checks the marker's own guard")
def test_a_runtime_independent_test_cannot_start_a_node() -> None:
    from swarm_runtime.ros import Node

    with pytest.raises(AssertionError, match='marked runtime_independent but starts a ROS node'):
        Node('guarded')
