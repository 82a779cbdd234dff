"""The three schemes of the paper's evaluation and the features each one uses (spec 1.9).

| feature                                             | MSC | MSC+PF | proposed |
|-----------------------------------------------------|-----|--------|----------|
| eq. (1) history-based search                        | yes | yes    | yes      |
| PF localisation                                     | -   | yes    | yes      |
| (b-1) parallel formation toward max-weight particle | -   | -      | yes      |
| eq. (8) direct approach after convergence           | -   | yes    | yes      |
| MSC near the target (RSSI > gamma2)                 | yes | yes    | yes      |
| stored converged estimates + R*N_r after a capture  | -   | -      | yes      |
"""

from __future__ import annotations

from enum import StrEnum

__all__ = ['Scheme']


class Scheme(StrEnum):
    """Swarm control scheme, selected by the ``scheme`` parameter."""

    MSC = 'msc'
    """Reference: eq. (1) search, then MSC alone."""
    MSC_PF = 'msc_pf'
    """Reference: MSC plus a PF; eq. (8) once the estimate has converged."""
    PROPOSED = 'proposed'
    """Proposed swarm control: PF, far-field formation, eq. (8), stored estimates."""

    @property
    def uses_particle_filter(self) -> bool:
        """Robots localise targets with the particle filter."""
        return self is not Scheme.MSC

    @property
    def uses_far_formation(self) -> bool:
        """Far from the target (RSSI < gamma1) the swarm flies in parallel formation (b-1)."""
        return self is Scheme.PROPOSED

    @property
    def uses_direct_approach(self) -> bool:
        """A converged estimate is approached with eq. (8) (b-2)."""
        return self is not Scheme.MSC

    @property
    def uses_stored_estimates(self) -> bool:
        """After a capture, robots re-target on stored converged estimates with R*N_r (c-2)."""
        return self is Scheme.PROPOSED
