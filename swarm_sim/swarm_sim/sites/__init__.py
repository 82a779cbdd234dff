"""Search sites for the OA-Bug simulation: model, generator, layout importer, site files.

A :class:`Site` holds a building's walls, rooms, doors, entrance and departure points in
metres. Sites come from :func:`generate_site` (the paper's Small/Medium/Big configurations
or any size), from the authors' text layouts (:func:`import_layout`) or from YAML site files
(:func:`load_site`); every one is checked by :func:`validate_site`. Drawing lives in
:mod:`swarm_sim.sites.plotting` (matplotlib) and ROS messages in
:mod:`sim_bridge.site_msgs`, so importing this package pulls in neither.
"""

from swarm_sim.sites.errors import (
    GeneratorError,
    LayoutError,
    SiteError,
    SiteFileError,
    SiteValidationError,
    SiteWarning,
)
from swarm_sim.sites.generator import (
    BIG,
    MAX_ACTIONS_PER_ROBOT,
    MEDIUM,
    PRESETS,
    SMALL,
    GeneratorConfig,
    generate_layout,
    generate_site,
)
from swarm_sim.sites.layout import Layout, LayoutImport, LayoutMode, import_layout, layout_to_site
from swarm_sim.sites.model import CELL_M, NO_ROOM, DeparturePoint, Door, Room, Site
from swarm_sim.sites.room_lookup import RoomLookup
from swarm_sim.sites.site_file import load_site, save_site
from swarm_sim.sites.validation import validate_site

__all__ = [
    'BIG',
    'CELL_M',
    'MAX_ACTIONS_PER_ROBOT',
    'MEDIUM',
    'NO_ROOM',
    'PRESETS',
    'SMALL',
    'DeparturePoint',
    'Door',
    'GeneratorConfig',
    'GeneratorError',
    'Layout',
    'LayoutError',
    'LayoutImport',
    'LayoutMode',
    'Room',
    'RoomLookup',
    'Site',
    'SiteError',
    'SiteFileError',
    'SiteValidationError',
    'SiteWarning',
    'generate_layout',
    'generate_site',
    'import_layout',
    'layout_to_site',
    'load_site',
    'save_site',
    'validate_site',
]
