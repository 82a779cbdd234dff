"""Named settings profiles of the Bayes-Swarm planner (ROS-free).

A profile is a set of :class:`~bayes_swarm.settings.BayesSwarmConfig` fields laid over a
case's values. ``paper`` is the as-published method and leads every results table; the other
profiles are this project's departures, each listed in docs/bayes_swarm.md.

* ``paper``: the paper's solvers (COBYLA for Eq. 1 from the robot's position, L-BFGS-B for
  Eq. 5) and the case's L, M and T_max; these are the planner's defaults, so the profile
  sets nothing.
* ``grid``: the project's polar-grid solver of Eq. 1 with a pattern search, and a multi-start
  trust-region Newton ascent for Eq. 5. Both are deterministic, so on a noise-free field a
  run does not depend on the seed at all (only the random jumps of Algorithm 1 would).
* ``estimated-penalty``: the paper's solvers, but the penalty's M and L estimated from the
  robot's belief at every decision as in Gonzalez et al.'s local penalization (M the largest
  observation, L the largest gradient norm of the GP mean over the arena), instead of the
  fixed values.
* ``estimated-penalty-log``: ``estimated-penalty`` with the acquisition and the penalty
  combined in log space (log g + sum of log phi, GPyOpt's form of local penalization): the
  same argmax in exact arithmetic, but COBYLA no longer stalls where the product of many
  peers' factors underflows (Case 3's 47 peers).
* ``weaker-within-eps``: the paper's solvers, L, M and T_max; Algorithm 2 lowers alpha to
  0.1 only when the expected source lies within eps of a known weaker source (the disc its
  robot searched and found empty), instead of within a squared distance of 2 l_robot
  (0.45 m for l_robot = 0.1 m, three times the avalanche's eps).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from bayes_swarm.errors import ConfigError

__all__ = ['PROFILES', 'Profile', 'profile_options']


@dataclass(frozen=True)
class Profile:
    """A named set of planner options (field name -> value) and what it departs from."""

    name: str
    description: str
    options: Mapping[str, Any] = field(default_factory=dict)


PROFILES: dict[str, Profile] = {
    p.name: p
    for p in (
        Profile('paper', "the paper's COBYLA / L-BFGS-B solvers and its L, M, T_max"),
        Profile(
            'grid',
            "polar-grid Eq. 1 and Newton Eq. 5 (project's departure; seed-independent)",
            {'outer_optimizer': 'grid', 'inner_optimizer': 'newton'},
        ),
        Profile(
            'estimated-penalty',
            "the paper's solvers; L and M estimated from the belief GP (local penalization)",
            {'penalty_estimate': True},
        ),
        Profile(
            'estimated-penalty-log',
            'as estimated-penalty, acquisition and penalty combined in log space',
            {'penalty_estimate': True, 'penalty_log_space': True},
        ),
        Profile(
            'weaker-within-eps',
            "the paper's solvers, L, M, T_max; a weaker source holds alpha down within eps only",
            {'weaker_source_within_eps': True},
        ),
    )
}


def profile_options(name: str) -> dict[str, Any]:
    """The planner options of profile ``name``.

    Raises:
        ConfigError: an unknown profile (the message lists the known ones).
    """
    try:
        return dict(PROFILES[name].options)
    except KeyError:
        msg = f'unknown profile {name!r}; choose one of {", ".join(PROFILES)}'
        raise ConfigError(msg) from None
