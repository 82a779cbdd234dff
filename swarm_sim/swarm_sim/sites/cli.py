"""``site_tool``: generate, import, validate and render search sites from the command line.

Examples::

    site_tool generate --config small --seed 7 -o small7.yaml --png small7.png
    site_tool generate --width-cells 50 --height-cells 40 --rooms 35 --seed 1 -o custom.yaml
    site_tool import-lay plan.lay -o plan.yaml --departure-name edge
    site_tool validate plan.yaml
    site_tool render small7.yaml -o small7.png

Every command exits with 0 on success and 2 on an invalid site or bad input (``validate``
also refuses a site without rooms, which ``import-lay`` writes with a warning), printing the
error as one line (file, line and column or key) on stderr; ``--debug`` adds the traceback.
Outputs are checked before anything is built (each must have a suffix its reader takes:
``.yaml``/``.yml`` site files, ``.lay`` layouts, ``.png``/``.svg``/``.pdf`` pictures, and
none may be an input or another output) and written under a temporary name first, so a
failed command leaves no partial file and never overwrites its input.
The site's warnings (a sealed void read as solid, a departure point inside a room, ...) go
to stderr as ``warning: ...`` lines.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import Final

from swarm_common.cli import ToolParser, run_tool
from swarm_common.errors import UsageError
from swarm_common.outputs import check_output_file

from swarm_sim.sites.errors import SiteError
from swarm_sim.sites.generator import PRESETS, generate_layout, resolve_config, with_size
from swarm_sim.sites.layout import LayoutMode, import_layout, layout_to_site, write_layout
from swarm_sim.sites.model import CELL_M, Site
from swarm_sim.sites.site_file import load_site, save_site
from swarm_sim.sites.validation import DEFAULT_ROBOT_RADIUS_M, require_rooms, validate_site

__all__ = ['build_parser', 'load_any', 'main']


def load_any(path: str | Path) -> Site:
    """Load a site from a ``.yaml``/``.yml`` site file or a ``.lay`` layout (default import
    options)."""
    if Path(path).is_dir():
        msg = f'{path}: is a directory; expected a .yaml site file or a .lay layout'
        raise SiteError(msg)
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


_SITE_SUFFIXES: Final = ('.yaml', '.yml')
_LAYOUT_SUFFIXES: Final = ('.lay',)
_PICTURE_SUFFIXES: Final = ('.png', '.svg', '.pdf')


def _same_file(a: Path, b: Path) -> bool:
    if a.resolve() == b.resolve():
        return True
    try:
        return a.exists() and b.exists() and a.samefile(b)
    except OSError:
        return False


def _check_outputs(
    args: argparse.Namespace, inputs: Sequence[str], outputs: dict[str, tuple[str, ...]]
) -> None:
    """Every output the command will write can be written, has a suffix its reader takes
    (``site_tool validate`` for site files and layouts), and is neither an input nor another
    output; checked before any work, so a refused command writes nothing.

    Args:
        args: the parsed arguments.
        inputs: the input files of the command.
        outputs: option -> the suffixes its file may have.

    Raises:
        UsageError: a suffix that does not fit, or an output that is an input or another
            output.
        OutputError: an output that cannot be written.
    """
    seen: list[tuple[str, Path]] = [('the input', Path(path)) for path in inputs]
    for option, suffixes in outputs.items():
        value = getattr(args, option.lstrip('-').replace('-', '_'), None)
        if value is None:
            continue
        path = Path(value)
        check_output_file(path, option=option)  # a directory, an unwritable place: say so
        if path.suffix.lower() not in suffixes:
            names = ', '.join(suffixes[:-1]) + ' or ' + suffixes[-1] if len(suffixes) > 1 else ''
            msg = (
                f'{option} {value}: expected a {names or suffixes[0]} file name, got '
                f'{repr(path.suffix) if path.suffix else "no suffix"}'
            )
            raise UsageError(msg)
        for what, other in seen:
            if _same_file(path, other):
                if what == 'the input':
                    msg = f'{option} {value}: is the input file; it is never overwritten'
                else:
                    msg = f'{option} {value}: is also the output of {what}'
                raise UsageError(msg)
        seen.append((option, path))


def _check_name(name: str | None) -> None:
    if name is not None and not name.strip():
        raise UsageError(f'--name must not be empty, got {name!r}')


def _check_size_option(option: str, value: int | None) -> None:
    if value is not None and value <= 0:
        raise UsageError(f'{option} must be a positive integer, got {value}')


def _generate(args: argparse.Namespace) -> int:
    if args.seed < 0:
        raise SiteError(f'--seed must be >= 0, got {args.seed}')
    _check_size_option('--width-cells', args.width_cells)
    _check_size_option('--height-cells', args.height_cells)
    _check_size_option('--rooms', args.rooms)
    _check_name(args.name)
    outputs = {'--output': _SITE_SUFFIXES, '--lay': _LAYOUT_SUFFIXES, '--png': _PICTURE_SUFFIXES}
    _check_outputs(args, (), outputs)
    config = resolve_config(args.config)
    sizes = (args.width_cells, args.height_cells, args.rooms)
    if any(v is not None for v in sizes):
        config = with_size(
            config,
            width_cells=config.width_cells if args.width_cells is None else args.width_cells,
            height_cells=config.height_cells if args.height_cells is None else args.height_cells,
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
    _check_name(args.name)
    _check_outputs(args, (args.layout,), {'--output': _SITE_SUFFIXES, '--png': _PICTURE_SUFFIXES})
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
    if not result.site.rooms:
        print(
            'warning: the site has no rooms; the spawners and site_tool validate refuse it',
            file=sys.stderr,
        )
    save_site(result.site, args.output)
    print(f'wrote {args.output}: {_summary(result.site)}')
    if args.png:
        _render(result.site, args.png)
    return 0


def _validate(args: argparse.Namespace) -> int:
    if not args.robot_radius_m > 0.0:
        raise SiteError(f'--robot-radius-m must be > 0, got {args.robot_radius_m}')
    site = load_any(args.site)
    validate_site(site, robot_radius_m=args.robot_radius_m)
    _log_warnings(site)
    require_rooms(site, str(args.site))
    print(f'{args.site}: valid. {_summary(site)}')
    return 0


def _render_command(args: argparse.Namespace) -> int:
    _check_outputs(args, (args.site,), {'--output': _PICTURE_SUFFIXES})
    site = load_any(args.site)
    _log_warnings(site)
    _render(site, args.output)
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``site_tool``."""
    parser = ToolParser(
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
    render.add_argument('-o', '--output', required=True, help='picture to write (.png, .svg, .pdf)')
    render.set_defaults(run=_render_command)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``site_tool``; returns the exit code (0 done, 2 bad input)."""
    return run_tool('site_tool', _run, argv)


def _run(argv: list[str]) -> int:
    args = build_parser().parse_args(argv)
    return int(args.run(args))


if __name__ == '__main__':
    sys.exit(main())
