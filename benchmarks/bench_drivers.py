"""Parser throughput of the hardware drivers: RPLidar samples decoded per second.

The A1's standard scan delivers about 2000 samples/s (up to ~8000 samples/s in express
modes); the decoder has to keep up with a wide margin on a Raspberry Pi 4 core. This bench
decodes synthetic revolutions read in chunks of several sizes, clean and with 1 % junk
bytes, through the decoder alone and through the whole pipeline (decode, assemble, bin to
LaserScan arrays), and prints samples/s with the margin over 8000 samples/s. A Pi 4 core is
roughly 3-5x slower than a desktop core: the last column divides by 5.

    python benchmarks/bench_drivers.py [--revolutions 200] [--repeats 3] [--output table.md]
"""

from __future__ import annotations

import argparse
import time
from dataclasses import dataclass

import numpy as np
from hw_drivers.fakes.lidar import FakeRPLidar, revolution_bytes
from hw_drivers.rplidar_protocol import (
    RevolutionAssembler,
    SampleStreamDecoder,
    ScanBinning,
    bin_revolution,
)

A1_PEAK_SAMPLES_PER_S = 8000.0
PI4_SLOWDOWN = 5.0


@dataclass(frozen=True)
class BenchRow:
    """One measured configuration."""

    stage: str
    chunk_bytes: int
    junk: bool
    samples: int
    samples_per_s: float

    @property
    def margin(self) -> float:
        """Throughput over the A1's peak sample rate."""
        return self.samples_per_s / A1_PEAK_SAMPLES_PER_S


def _with_junk(data: bytes, every: int, seed: int) -> bytes:
    """Insert one random byte after every ``every`` bytes (1 % for every=100)."""
    rng = np.random.default_rng(seed)
    out = bytearray()
    for start in range(0, len(data), every):
        out += data[start : start + every]
        out.append(int(rng.integers(0, 256)))
    return bytes(out)


def _measure(
    stream: bytes, chunk_bytes: int, full_pipeline: bool, repeats: int
) -> tuple[int, float]:
    best_s = float('inf')
    samples = 0
    binning = ScanBinning()
    for _ in range(repeats):
        decoder = SampleStreamDecoder()
        assembler = RevolutionAssembler()
        samples = 0
        start = time.perf_counter()
        for offset in range(0, len(stream), chunk_bytes):
            decoded = decoder.feed(stream[offset : offset + chunk_bytes])
            samples += len(decoded)
            if full_pipeline:
                for revolution in assembler.add(decoded, 0.0):
                    bin_revolution(revolution, binning)
        best_s = min(best_s, time.perf_counter() - start)
    return samples, best_s


def run(
    *, revolutions: int = 200, repeats: int = 3, chunk_sizes: tuple[int, ...] = (64, 576, 4096)
) -> list[BenchRow]:
    """Measure every configuration; return the rows (best of ``repeats``)."""
    clean = revolution_bytes(FakeRPLidar(samples_per_revolution=360), revolutions)
    streams = {False: clean, True: _with_junk(clean, 100, seed=1)}
    rows = []
    for stage, full in (('decode', False), ('decode+assemble+bin', True)):
        for junk, stream in streams.items():
            for chunk in chunk_sizes:
                samples, seconds = _measure(stream, chunk, full, repeats)
                rows.append(BenchRow(stage, chunk, junk, samples, samples / seconds))
    return rows


def format_table(rows: list[BenchRow]) -> str:
    """Markdown table of the rows."""
    lines = [
        '| stage | read chunk [B] | 1 % junk | samples | samples/s | x A1 peak (8k/s)'
        ' | est. Pi 4 x peak |',
        '|---|---:|:---:|---:|---:|---:|---:|',
    ]
    for r in rows:
        lines.append(
            f'| {r.stage} | {r.chunk_bytes} | {"yes" if r.junk else "no"} | {r.samples} |'
            f' {r.samples_per_s:,.0f} | {r.margin:.0f} | {r.margin / PI4_SLOWDOWN:.0f} |'
        )
    return '\n'.join(lines)


def main() -> None:
    """Command line."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--revolutions', type=int, default=200)
    parser.add_argument('--repeats', type=int, default=3)
    parser.add_argument('--output', default='', help='also write the table to this file')
    args = parser.parse_args()
    table = format_table(run(revolutions=args.revolutions, repeats=args.repeats))
    print(table)
    if args.output:
        with open(args.output, 'w', encoding='utf-8') as handle:
            handle.write(table + '\n')


if __name__ == '__main__':
    main()
