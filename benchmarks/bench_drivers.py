"""RPLidar parser benchmarks: throughput, and how well resynchronisation rejects junk.

Throughput: the A1's standard scan delivers about 2000 samples/s (up to ~8000 samples/s in express
modes); the decoder has to keep up with a wide margin on a Raspberry Pi 4 core. This bench
decodes synthetic revolutions read in chunks of several sizes, clean and with 1 % junk
bytes, through the decoder alone and through the whole pipeline (decode, assemble, bin to
LaserScan arrays), and prints samples/s with the margin over 8000 samples/s. A Pi 4 core is
roughly 3-5x slower than a desktop core: the last column divides by 5.

Resynchronisation quality (``--quality``), all on synthetic streams with random junk from a
seeded generator:

* phantom samples per kB of pure random junk (every sample decoded from junk is a phantom);
* junk bursts spliced between the samples of a clean stream, read in random chunk sizes:
  phantom samples, valid samples lost by the decoder and by the revolution assembler, and
  how many revolutions came out (ideal: one per revolution of the stream);
* a clean stream whose start flag drifts later every revolution: samples lost by the
  assembler;
* random bit flips: samples lost that no flip touched, and wrong samples emitted.

    python benchmarks/bench_drivers.py [--revolutions 200] [--repeats 3] [--output table.md]
    python benchmarks/bench_drivers.py --quality [--seeds 20] [--junk-kb 2000]
"""

from __future__ import annotations

import argparse
import time
from collections import Counter
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from hw_drivers.fakes.lidar import FakeRPLidar, drifting_scan_frames, revolution_bytes
from hw_drivers.rplidar_protocol import (
    SAMPLE_SIZE,
    Revolution,
    RevolutionAssembler,
    SampleStreamDecoder,
    ScanBinning,
    ScanSamples,
    bin_revolution,
    decode_samples,
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


SampleKey = tuple[int, int, int]


def _keys(samples: ScanSamples | Revolution) -> list[SampleKey]:
    """(quality, angle_q6, distance_q2) of each sample, the identity used to match samples."""
    angle_q6 = np.rint(np.asarray(samples.angle_deg) * 64.0).astype(int)
    distance_q2 = np.rint(np.asarray(samples.distance_mm) * 4.0).astype(int)
    quality = np.asarray(samples.quality).astype(int)
    return list(zip(quality.tolist(), angle_q6.tolist(), distance_q2.tolist(), strict=True))


def _frame_keys(frames: Iterable[bytes]) -> list[SampleKey]:
    data = np.frombuffer(b''.join(frames), dtype=np.uint8).reshape(-1, SAMPLE_SIZE)
    return _keys(decode_samples(data))


def _unmatched(got: list[SampleKey], want: list[SampleKey]) -> tuple[int, int]:
    """(samples in ``got`` not in ``want``, samples of ``want`` missing from ``got``)."""
    got_count, want_count = Counter(got), Counter(want)
    extra = sum((got_count - want_count).values())
    missing = sum((want_count - got_count).values())
    return extra, missing


@dataclass
class StreamResult:
    """What came out of one stream."""

    phantoms: int = 0
    decoder_lost: int = 0
    revolution_lost: int = 0
    revolutions: int = 0
    valid: int = 0


def _run_stream(
    stream: bytes,
    valid: list[SampleKey],
    closing: list[SampleKey],
    rng: np.random.Generator,
    max_chunk: int = 600,
) -> StreamResult:
    """Decode ``stream`` in random chunk sizes; match the output against the valid samples.

    ``valid`` are the samples that must come out in revolutions; ``closing`` those of the
    clean revolution at the end, which only closes the last one (it stays open itself).
    """
    decoder = SampleStreamDecoder()
    assembler = RevolutionAssembler()
    decoded: list[SampleKey] = []
    in_revolutions: list[SampleKey] = []
    revolutions = 0
    pos = 0
    while pos < len(stream):
        size = int(rng.integers(1, max_chunk + 1))
        samples = decoder.feed(stream[pos : pos + size])
        pos += size
        decoded += _keys(samples)
        for revolution in assembler.add(samples, 0.0):
            revolutions += 1
            in_revolutions += _keys(revolution)
    phantoms, decoder_lost = _unmatched(decoded, valid + closing)
    # The stream's last sample may still wait for its successor: not lost.
    decoder_lost = max(decoder_lost - getattr(decoder, 'pending_bytes', 0) // SAMPLE_SIZE, 0)
    _, revolution_lost = _unmatched(in_revolutions, valid)
    return StreamResult(phantoms, decoder_lost, revolution_lost, revolutions, len(valid))


def junk_phantoms_per_kb(total_kb: int, seed: int = 1, chunk_bytes: int = 512) -> float:
    """Samples decoded from ``total_kb`` kB of uniform random bytes, per kB."""
    rng = np.random.default_rng(seed)
    junk = rng.integers(0, 256, total_kb * 1000, dtype=np.uint8).tobytes()
    decoder = SampleStreamDecoder()
    phantoms = sum(
        len(decoder.feed(junk[i : i + chunk_bytes])) for i in range(0, len(junk), chunk_bytes)
    )
    return phantoms / total_kb


def spliced_bursts(
    seed: int, *, revolutions: int = 6, bursts: int = 40, burst_bytes: int = 250, drift_deg=0.0
) -> StreamResult:
    """``bursts`` random-junk bursts spliced between samples of ``revolutions`` turns.

    One clean revolution follows, so the last spliced revolution is closed by a start flag;
    only the spliced revolutions count as valid samples.
    """
    rng = np.random.default_rng(seed)
    frames = drifting_scan_frames(
        revolutions + 1, start_drift_deg=drift_deg, revolution_tag_mm=0.25
    )
    tail_start = max(i for i, f in enumerate(frames) if f[0] & 1)  # the closing revolution
    spliced, tail = frames[:tail_start], frames[tail_start:]
    cuts = set(rng.choice(np.arange(1, len(spliced)), size=bursts, replace=False).tolist())
    parts = []
    for i, frame in enumerate(spliced):
        if i in cuts:
            parts.append(rng.integers(0, 256, burst_bytes, dtype=np.uint8).tobytes())
        parts.append(frame)
    stream = b''.join(parts) + b''.join(tail)
    return _run_stream(stream, _frame_keys(spliced), _frame_keys(tail), rng)


def drifting_start(seed: int, *, revolutions: int = 20, drift_deg: float = 7.0) -> StreamResult:
    """A clean stream whose start flag comes ``drift_deg`` later every revolution."""
    frames = drifting_scan_frames(
        revolutions + 1, start_drift_deg=drift_deg, revolution_tag_mm=0.25
    )
    last = max(i for i, f in enumerate(frames) if f[0] & 1)  # start of the closing revolution
    rng = np.random.default_rng(seed)
    valid, closing = _frame_keys(frames[:last]), _frame_keys(frames[last:])
    return _run_stream(b''.join(frames), valid, closing, rng)


def bit_flips(seed: int, *, revolutions: int = 6, flips: int = 40) -> tuple[StreamResult, int]:
    """``flips`` random bit flips in a clean stream; also returns how many samples they hit."""
    rng = np.random.default_rng(seed)
    frames = drifting_scan_frames(revolutions + 1, revolution_tag_mm=0.25)
    data = bytearray(b''.join(frames))
    positions = rng.choice(np.arange(len(frames[:-360]) * SAMPLE_SIZE), size=flips, replace=False)
    hit = {int(p) // SAMPLE_SIZE for p in positions}
    for p in positions:
        data[int(p)] ^= 1 << int(rng.integers(0, 8))
    untouched = [f for i, f in enumerate(frames[:-360]) if i not in hit]
    result = _run_stream(bytes(data), _frame_keys(untouched), _frame_keys(frames[-360:]), rng)
    return result, len(hit)


def quality_table(seeds: int, junk_kb: int) -> str:
    """Markdown table of the resynchronisation figures (sums over ``seeds`` seeds)."""

    def total(results: list[StreamResult]) -> StreamResult:
        out = StreamResult()
        for r in results:
            out.phantoms += r.phantoms
            out.decoder_lost += r.decoder_lost
            out.revolution_lost += r.revolution_lost
            out.revolutions += r.revolutions
            out.valid += r.valid
        return out

    def pct(part: int, whole: int) -> str:
        return f'{100.0 * part / whole:.2f} %' if whole else ''

    lines = [
        '| scenario | junk [kB] | valid samples | phantom samples | phantoms per kB junk'
        ' | lost by decoder | lost in revolutions | revolutions out (ideal) |',
        '|---|---:|---:|---:|---:|---:|---:|---:|',
    ]
    per_kb = junk_phantoms_per_kb(junk_kb)
    lines.append(
        f'| pure random junk | {junk_kb} | 0 | {per_kb * junk_kb:.0f} | {per_kb:.3f} | | | |'
    )
    for drift in (0.0, 7.0):
        burst = total([spliced_bursts(s, drift_deg=drift) for s in range(seeds)])
        junk = seeds * 40 * 250 / 1000
        lines.append(
            f'| 40 bursts x 250 B in 6 turns, start drift {drift:g} deg | {junk:.0f} |'
            f' {burst.valid} | {burst.phantoms} | {burst.phantoms / junk:.3f} |'
            f' {pct(burst.decoder_lost, burst.valid)} | {pct(burst.revolution_lost, burst.valid)}'
            f' | {burst.revolutions} ({seeds * 6}) |'
        )
    drift = total([drifting_start(s) for s in range(seeds)])
    lines.append(
        f'| clean, start flag 7 deg later each turn (20 turns) | 0 | {drift.valid} |'
        f' {drift.phantoms} | | {pct(drift.decoder_lost, drift.valid)} |'
        f' {pct(drift.revolution_lost, drift.valid)} | {drift.revolutions} ({seeds * 20}) |'
    )
    flipped = [bit_flips(s) for s in range(seeds)]
    flips = total([r for r, _ in flipped])
    hit = sum(h for _, h in flipped)
    lines.append(
        f'| 40 bit flips in 6 turns ({hit} samples hit; loss counts untouched ones) | 0 |'
        f' {flips.valid} | {flips.phantoms} (corrupted samples emitted) | |'
        f' {pct(flips.decoder_lost, flips.valid)} | {pct(flips.revolution_lost, flips.valid)}'
        f' | {flips.revolutions} ({seeds * 6}) |'
    )
    return '\n'.join(lines)


def main() -> None:
    """Command line."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--revolutions', type=int, default=200)
    parser.add_argument('--repeats', type=int, default=3)
    parser.add_argument('--quality', action='store_true', help='resynchronisation figures')
    parser.add_argument('--seeds', type=int, default=20, help='streams per quality scenario')
    parser.add_argument('--junk-kb', type=int, default=2000, help='pure junk for phantoms/kB')
    parser.add_argument('--output', default='', help='also write the table to this file')
    args = parser.parse_args()
    if args.quality:
        table = quality_table(args.seeds, args.junk_kb)
    else:
        table = format_table(run(revolutions=args.revolutions, repeats=args.repeats))
    print(table)
    if args.output:
        with open(args.output, 'w', encoding='utf-8') as handle:
            handle.write(table + '\n')


if __name__ == '__main__':
    main()
