"""``site_tool``: generate, import, validate and render search sites from the command line.

Examples::

    site_tool generate --config small --seed 7 -o small7.yaml --png small7.png
    site_tool generate --width-cells 50 --height-cells 40 --rooms 35 --seed 1 -o custom.yaml
    site_tool import-lay plan.lay -o plan.yaml --departure-name edge
    site_tool validate plan.yaml
    site_tool render small7.yaml -o small7.png

Every command exits with 0 on success and 1 on an invalid site or bad input, printing the
error (file, line and column or key) to stderr. The site's warnings (a sealed void read as
solid, a departure point inside a room, ...) go to stderr as ``warning: ...`` lines.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

from swarm_sim.sites.errors import SiteError
from swarm_sim.sites.generator import PRESETS, generate_layout, resolve_config, with_size
from swarm_sim.sites.layout import LayoutMode, import_layout, layout_to_site, write_layout
from swarm_sim.sites.model import CELL_M, Site
from swarm_sim.sites.site_file import load_site, save_site
from swarm_sim.sites.validation import DEFAULT_ROBOT_RADIUS_M, validate_site

__all__ = ['build_parser', 'load_any', 'main']


def load_any(path: str | Path) -> Site:
    """Load a site from a ``.yaml``/``.yml`` site file or a ``.lay`` layout (default import
    options)."""
    suffix = Path(path).suffix.lower()
    if suffix == '.lay':
        return import_layout(path).site
    if suffix in ('.yaml', '.yml'):
        return load_site(path)
    msg = f'{path}: unknown site file type {suffix!r}; use a .yaml site file or a .lay layout'
    raise SiteError(msg)


def _summary(site: Site) -> str:
    points = ', '.join(
        f'{name} ({p.x_m:.2f}, {p.y_m:.2f}) m' for name, p in site.departure_points.items()
    )
    return (
        f'{site.name}: {site.width_m:.2f} x {site.height_m:.2f} m, {len(site.rooms)} rooms, '
        f'{len(site.doors)} doors, {len(site.walls)} walls, '
        f'{"one entrance" if site.entrance else "no entrance"}; departure points: {points}'
    )


def _log_warnings(site: Site) -> None:
    for warning in site.warnings:
        print(f'warning: {warning}', file=sys.stderr)


def _render(site: Site, path: str) -> None:
    from swarm_sim.sites.plotting import render_site  # matplotlib only when drawing

    render_site(site, path)
    print(f'wrote {path}')


def _generate(args: argparse.Namespace) -> int:
    config = resolve_config(args.config)
    sizes = (args.width_cells, args.height_cells, args.rooms)
    if any(v is not None for v in sizes):
        config = with_size(
            config,
            width_cells=args.width_cells or config.width_cells,
            height_cells=args.height_cells or config.height_cells,
            rooms=config.rooms if args.rooms is None else args.rooms,
        )
    if args.victims is not None:
        config = replace(config, victims=args.victims)
    layout = generate_layout(config, args.seed)
    name = args.name or f'{config.name}-seed{args.seed}'
    site = layout_to_site(
        layout, mode=LayoutMode.LABELLED, cell_m=config.cell_m, name=name, seed=args.seed
    ).site
    _log_warnings(site)
    save_site(site, args.output)
    print(f'wrote {args.output}: {_summary(site)}')
    if args.lay:
        write_layout(layout, args.lay)
        print(f'wrote {args.lay}')
    if args.png:
        _render(site, args.png)
    return 0


def _parse_departure(text: str) -> tuple[str, tuple[float, float]]:
    try:
        name, place = text.split('=', 1)
        line, column = (float(v) for v in place.split(','))
    except ValueError:
        msg = f'expected NAME=LINE,COLUMN (e.g. center=15.5,30.5), got {text!r}'
        raise argparse.ArgumentTypeError(msg) from None
    return name, (line, column)


def _import_lay(args: argparse.Namespace) -> int:
    result = import_layout(
        args.layout,
        mode=args.mode,
        cell_m=args.cell_m,
        name=args.name,
        departure_name=args.departure_name,
        departures=dict(args.departure) if args.departure else None,
        max_door_cells=args.max_door_cells,
    )
    voids = f', {result.voids_found} sealed voids read as solid' if result.voids_found else ''
    print(
        f'{args.layout}: {result.mode.value} layout, found {result.rooms_found} rooms and '
        f'{result.doors_found} doors{voids}'
    )
    _log_warnings(result.site)
    save_site(result.site, args.output)
    print(f'wrote {args.output}: {_summary(result.site)}')
    if args.png:
        _render(result.site, args.png)
    return 0


def _validate(args: argparse.Namespace) -> int:
    site = load_any(args.site)
    validate_site(site, robot_radius_m=args.robot_radius_m)
    _log_warnings(site)
    print(f'{args.site}: valid. {_summary(site)}')
    return 0


def _render_command(args: argparse.Namespace) -> int:
    site = load_any(args.site)
    _log_warnings(site)
    _render(site, args.output)
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``site_tool``."""
    parser = argparse.ArgumentParser(
        prog='site_tool', description='Generate, import, validate and render search sites.'
    )
    commands = parser.add_subparsers(dest='command', required=True)

    generate = commands.add_parser('generate', help='generate a site (Table II or any size)')
    generate.add_argument('--config', default='small', choices=sorted(PRESETS))
    generate.add_argument('--width-cells', type=int, help='override the width [cells]')
    generate.add_argument('--height-cells', type=int, help='override the height [cells]')
    generate.add_argument('--rooms', type=int, help='override the number of rooms')
    generate.add_argument('--victims', type=int, help='rooms holding a victim')
    generate.add_argument('--seed', type=int, required=True)
    generate.add_argument('--name', help='site name (default: <config>-seed<seed>)')
    generate.add_argument('-o', '--output', required=True, help='site file to write (.yaml)')
    generate.add_argument('--lay', help='also write the labelled .lay layout here')
    generate.add_argument('--png', help='also render the site to this PNG')
    generate.set_defaults(run=_generate)

    imports = commands.add_parser('import-lay', help='import a .lay text layout')
    imports.add_argument('layout', help='the .lay file')
    imports.add_argument('-o', '--output', required=True, help='site file to write (.yaml)')
    imports.add_argument('--mode', default='auto', choices=[m.value for m in LayoutMode])
    imports.add_argument('--cell-m', type=float, default=CELL_M, help='grid spacing [m]')
    imports.add_argument('--name', help='site name (default: the file name)')
    imports.add_argument(
        '--departure-name', default='edge', help="name of the departure point marked 'D'"
    )
    imports.add_argument(
        '--departure',
        action='append',
        type=_parse_departure,
        metavar='NAME=LINE,COLUMN',
        help='explicit departure point at a (fractional) line and column; repeatable',
    )
    imports.add_argument(
        '--max-door-cells',
        type=int,
        default=1,
        help='widest door gap of an unlabelled plan, in missing characters (default 1)',
    )
    imports.add_argument('--png', help='also render the site to this PNG')
    imports.set_defaults(run=_import_lay)

    validate = commands.add_parser('validate', help='check a .yaml site file or .lay layout')
    validate.add_argument('site')
    validate.add_argument('--robot-radius-m', type=float, default=DEFAULT_ROBOT_RADIUS_M)
    validate.set_defaults(run=_validate)

    render = commands.add_parser('render', help='draw a site to a PNG, rooms labelled by id')
    render.add_argument('site', help='a .yaml site file or .lay layout')
    render.add_argument('-o', '--output', required=True, help='PNG to write')
    render.set_defaults(run=_render_command)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``site_tool``; returns the exit code."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.run(args))
    except (SiteError, OSError) as err:
        print(f'error: {err}', file=sys.stderr)
        return 1


if __name__ == '__main__':
    sys.exit(main())
