"""Site generator benchmark: speed, and the structure of the sites against the authors' generator.

For each Table II configuration, generates seeded sites and reports

* the time per site: the labelled layout alone, and the full site (conversion to walls,
  rooms and doors, plus validation), wall-clock and process CPU time (which a contended
  machine inflates far less);
* the room interiors' size in cells (min / median / max over all rooms);
* corridor doors (``/``) and inner doors (``#``, nested rooms) per site;
* the number of full-length horizontal and vertical corridors (min-max);
* isolated islands per site (wall groups not attached to the outer wall);
* how often the requested room count was met;

next to what the authors' generator (SwarmSearchSimulation, measured on 100 Small, 20 Medium
and 10 Big sites) gives. One process. Example::

    python benchmarks/bench_sites.py --sites 100 --out sites.md
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import ndimage
from swarm_sim.sites import PRESETS, Layout, generate_layout, layout_to_site

# The authors' generator, as measured: interior cells (min, median, max), doors per site
# (corridor, inner), corridors (horizontal range, vertical range).
AUTHORS = {
    'small': ((1, 8, 135), (18.9, 11.1), ('1', '3-5')),
    'medium': (None, (44.4, 15.7), ('2-3', '4-6')),
    'big': (None, (81.2, 38.8), ('3-4', '7-9')),
}
DEFAULT_SITES = {'small': 100, 'medium': 20, 'big': 10}


@dataclass(frozen=True)
class ConfigResult:
    """Measurements over the sites of one configuration."""

    config: str
    sites: int
    layout_ms: float
    site_ms: float
    site_cpu_ms: float
    interior_cells: tuple[int, float, int]
    corridor_doors: float
    inner_doors: float
    horizontal_corridors: tuple[int, int]
    vertical_corridors: tuple[int, int]
    islands: float
    rooms_met: float


def _full_corridors(layout: Layout, axis: int) -> int:
    inner = layout.codes[1:-1, 1:-1] == ord(' ')
    lines = np.all(inner, axis=1) if axis == 0 else np.all(inner, axis=0)
    return int(ndimage.label(lines)[1])


def _islands(layout: Layout) -> int:
    walls, _ = ndimage.label(layout.codes == ord('%'))
    border = np.concatenate([walls[0], walls[-1], walls[:, 0], walls[:, -1]])
    return len(set(np.unique(walls).tolist()) - set(border.tolist()) - {0})


def _interior_sizes(layout: Layout) -> list[int]:
    codes = layout.codes
    interior = codes >= ord('0')  # digits and room letters; walls and doors sort below '0'
    groups, count = ndimage.label(interior)
    return np.bincount(groups.ravel())[1:].tolist() if count else []


def measure(config: str, sites: int, first_seed: int = 0) -> ConfigResult:
    """Generate ``sites`` sites of ``config`` from consecutive seeds and measure them."""
    layout_s, site_s, cpu_s = [], [], []
    sizes: list[int] = []
    corridor_doors, inner_doors, islands, met = [], [], [], 0
    horizontal, vertical = [], []
    for seed in range(first_seed, first_seed + sites):
        start, start_cpu = time.perf_counter(), time.process_time()
        layout = generate_layout(config, seed)
        layout_s.append(time.perf_counter() - start)
        site = layout_to_site(layout, mode='labelled', seed=seed).site
        site_s.append(time.perf_counter() - start)
        cpu_s.append(time.process_time() - start_cpu)
        met += len(site.rooms) == PRESETS[config].rooms
        inner = layout.codes[1:-1, 1:-1]
        corridor_doors.append(int(np.count_nonzero(inner == ord('/'))))
        inner_doors.append(int(np.count_nonzero(inner == ord('#'))))
        sizes += _interior_sizes(layout)
        horizontal.append(_full_corridors(layout, 0))
        vertical.append(_full_corridors(layout, 1))
        islands.append(_islands(layout))
    return ConfigResult(
        config=config,
        sites=sites,
        layout_ms=1e3 * statistics.median(layout_s),
        site_ms=1e3 * statistics.median(site_s),
        site_cpu_ms=1e3 * statistics.median(cpu_s),
        interior_cells=(min(sizes), float(np.median(sizes)), max(sizes)),
        corridor_doors=float(np.mean(corridor_doors)),
        inner_doors=float(np.mean(inner_doors)),
        horizontal_corridors=(min(horizontal), max(horizontal)),
        vertical_corridors=(min(vertical), max(vertical)),
        islands=float(np.mean(islands)),
        rooms_met=met / sites,
    )


def format_table(results: list[ConfigResult]) -> str:
    """Markdown table of the results with the authors' values in brackets."""
    header = (
        '| config | sites | layout ms | site ms | site CPU ms | interior cells min/med/max '
        '| doors / per site | doors # per site | corridors H | corridors V | islands '
        '| rooms met |\n'
        '|---|---|---|---|---|---|---|---|---|---|---|---|\n'
    )
    rows = []
    for r in results:
        cells, doors, corridors = AUTHORS.get(r.config, (None, None, None))
        lo, med, hi = r.interior_cells
        cell_text = f'{lo}/{med:g}/{hi}' + (f' ({cells[0]}/{cells[1]}/{cells[2]})' if cells else '')
        slash = f'{r.corridor_doors:.1f}' + (f' ({doors[0]})' if doors else '')
        hash_ = f'{r.inner_doors:.1f}' + (f' ({doors[1]})' if doors else '')
        h = f'{r.horizontal_corridors[0]}-{r.horizontal_corridors[1]}'
        v = f'{r.vertical_corridors[0]}-{r.vertical_corridors[1]}'
        if corridors:
            h += f' ({corridors[0]})'
            v += f' ({corridors[1]})'
        rows.append(
            f'| {r.config} | {r.sites} | {r.layout_ms:.1f} | {r.site_ms:.1f} | '
            f'{r.site_cpu_ms:.1f} | {cell_text} | '
            f'{slash} | {hash_} | {h} | {v} | {r.islands:.1f} | {100 * r.rooms_met:.0f} % |'
        )
    note = "\nIn brackets: the authors' generator. Times are medians per site.\n"
    return header + '\n'.join(rows) + '\n' + note


def run(
    configs: list[str] | None = None, sites: int | None = None, out: Path | None = None
) -> list[ConfigResult]:
    """Measure ``configs`` (default all) with ``sites`` sites each (default 100/20/10), print
    the table and write it to ``out`` if given."""
    results = [
        measure(config, sites if sites is not None else DEFAULT_SITES[config])
        for config in (configs or list(PRESETS))
    ]
    table = format_table(results)
    print(table)
    if out is not None:
        out.write_text(table)
    return results


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--configs', nargs='+', choices=sorted(PRESETS), help='default: all')
    parser.add_argument('--sites', type=int, help='sites per configuration (default 100/20/10)')
    parser.add_argument('--out', type=Path, help='also write the table to this file')
    args = parser.parse_args(argv)
    run(args.configs, args.sites, args.out)
    return 0


if __name__ == '__main__':
    sys.exit(main())
