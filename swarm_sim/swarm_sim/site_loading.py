"""One way to name a site on the command line: a preset, a ``.lay`` layout or a site file.

* ``small``, ``medium``, ``big``: the paper's Table II configurations, generated from a seed;
* ``path/to/plan.lay``: an ASCII layout in the authors' format;
* ``path/to/site.yaml``: a site file.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from swarm_sim.errors import ConfigurationError

__all__ = ['load_site', 'site_budget_actions']


def load_site(spec: str, *, seed: int = 0) -> Any:
    """The :class:`swarm_sim.sites.model.Site` named by ``spec`` (see the module docstring).

    Raises:
        ConfigurationError: ``spec`` is neither a preset nor an existing file of a known kind.
    """
    from swarm_sim import sites

    key = spec.strip().lower()
    if key in sites.PRESETS:
        return sites.generate_site(key, seed)
    path = Path(spec)
    if not path.is_file():
        presets = ', '.join(sites.PRESETS)
        msg = f'site {spec!r} is neither a preset ({presets}) nor an existing file'
        raise ConfigurationError(msg)
    if path.suffix.lower() == '.lay':
        return sites.import_layout(path).site
    if path.suffix.lower() in ('.yaml', '.yml'):
        loader = getattr(sites, 'load_site', None)
        if loader is None:
            msg = 'this installation cannot read site files (swarm_sim.sites.load_site missing)'
            raise ConfigurationError(msg)
        return loader(path)
    msg = f'unknown site file type {path.suffix!r} (expected .lay, .yaml or .yml)'
    raise ConfigurationError(msg)


def site_budget_actions(spec: str) -> int | None:
    """The paper's max actions per robot for a preset name (Table II), else None."""
    from swarm_sim import sites

    return sites.MAX_ACTIONS_PER_ROBOT.get(spec.strip().lower())
