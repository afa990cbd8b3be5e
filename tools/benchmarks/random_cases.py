#!/usr/bin/env python3
"""Maps no one chose: draws `elastic map` cases at random over the shared meshes and runs them.

Each case: a target mesh, a disk on it (a random vertex as the centre, a radius of 5, 10, 15 or 25% of the
bounding box's diagonal), a source that is the rectangle image, the ellipse of the checker image, or a disk
drawn the same way on another random mesh, and 500, 2,000 or 5,000 particles. The draw depends only on the
seed, so a case list can be repeated on another build. Prints one line per case (exit code, seconds, folds,
worst sigma_min, the first error line) and a summary; with --out, each case's report lands in that folder.

    tools/benchmarks/random_cases.py --elastic build/tools/elastic/elastic --seed 7 --count 24
    tools/benchmarks/random_cases.py --list --seed 7 --count 24      # the cases only

A disk may land where the region is not a disk or is too small for the tessellation; the tool then refuses
it with a message, which counts as a clear refusal, not a failure. A failure is a crash, a timeout, exit 70
(a folded or unconverged map), or exit 0 with folds.
"""
import argparse
import json
import math
import os
import random
import subprocess
import sys
import time

MESHES = [
    'armadillo.obj', 'beetle.obj', 'bob_tri.obj', 'bunny.obj', 'camelhead.off', 'decimated-max.obj',
    'fandisk.off', 'fandisk_quads.off', 'hand_lowres.obj', 'mountain.obj', 'nefertiti-lowres.obj',
    'spot.obj', 'torus.obj', 'wavy_vase_open_low_res.obj', 'osd_catmark_pawn.obj', 'cylinder.obj',
]


def vertices(path):
    """The vertex positions of an OBJ or OFF file (enough of each format for the shared meshes)."""
    with open(path) as f:
        if path.endswith('.obj'):
            return [tuple(map(float, line.split()[1:4])) for line in f if line.startswith('v ')]
        lines = [line for line in f if line.strip() and not line.startswith('#')]
    first = 1 if lines[0].strip() == 'OFF' else 0
    count = int(lines[first].split()[0])
    return [tuple(map(float, line.split()[:3])) for line in lines[first + 1:first + 1 + count]]


def random_disk(rng, meshes, cache):
    mesh = rng.choice(MESHES)
    if mesh not in cache:
        cache[mesh] = vertices(os.path.join(meshes, mesh))
    v = cache[mesh]
    lo = [min(p[j] for p in v) for j in range(3)]
    hi = [max(p[j] for p in v) for j in range(3)]
    centre = rng.choice(v)
    radius = math.dist(lo, hi) * rng.choice([0.05, 0.1, 0.15, 0.25])
    return mesh, f'disk:{centre[0]:.5g},{centre[1]:.5g},{centre[2]:.5g},{radius:.4g}'


def cases(seed, count, meshes):
    rng = random.Random(seed)
    cache = {}
    out = []
    for _ in range(count):
        target, target_region = random_disk(rng, meshes, cache)
        kind = rng.choice(['image', 'image_ellipse', 'mesh'])
        particles = rng.choice([500, 2000, 5000])
        if kind == 'mesh':
            source, source_region = random_disk(rng, meshes, cache)
            args = ['--source', os.path.join(meshes, source), '--source-region', source_region]
        elif kind == 'image':
            args = ['--source-image', os.path.join(meshes, 'pmp_logo_512.png')]
        else:
            args = ['--source-image', os.path.join(meshes, 'texel_checker.png'), '--source-region',
                    'ellipse']
        args += ['--target', os.path.join(meshes, target), '--target-region', target_region,
                 '--particles', str(particles)]
        out.append(args)
    return out


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--elastic', default=os.path.join(here, '../../build/tools/elastic/elastic'))
    parser.add_argument('--meshes', default=os.path.join(here, '../../../shared/meshes'))
    parser.add_argument('--seed', type=int, default=7)
    parser.add_argument('--count', type=int, default=24)
    parser.add_argument('--threads', type=int, default=2)
    parser.add_argument('--timeout', type=float, default=300.0, help='seconds per case')
    parser.add_argument('--out', help='folder for the reports (case<k>.json)')
    parser.add_argument('--list', action='store_true', help='print the cases and stop')
    a = parser.parse_args()
    todo = cases(a.seed, a.count, a.meshes)
    if a.list:
        for k, args in enumerate(todo, 1):
            print(k, ' '.join(args))
        return 0
    if a.out:
        os.makedirs(a.out, exist_ok=True)
    failures = refusals = 0
    for k, args in enumerate(todo, 1):
        report = os.path.join(a.out, f'case{k}.json') if a.out else os.devnull
        command = [a.elastic, 'map', *args, '--threads', str(a.threads), '-q', '--report', report]
        start = time.monotonic()
        try:
            run = subprocess.run(command, capture_output=True, text=True, timeout=a.timeout)
            code, text = run.returncode, run.stdout + run.stderr
        except subprocess.TimeoutExpired:
            code, text = 'timeout', ''
        seconds = time.monotonic() - start
        folds = sigma = ''
        if a.out and code == 0:
            with open(report) as f:
                r = json.load(f)
            folds, sigma = r['folds'], f"{r['sigma_min']:.3f}"
        error = next((line for line in text.splitlines() if line.startswith('elastic:')), '')
        refused = code in (64, 65, 66)  # usage, bad input, missing input: a clear refusal
        failed = not refused and (code != 0 or (folds not in ('', 0)))
        failures += failed
        refusals += refused
        print(f'{k:3d} exit {code} {seconds:7.2f} s folds {folds} sigma_min {sigma} '
              f'{"FAIL " if failed else ""}{error[:160]}', flush=True)
    print(f'{len(todo)} cases: {len(todo) - failures - refusals} mapped, {refusals} refused, '
          f'{failures} failed')
    return 1 if failures else 0


if __name__ == '__main__':
    sys.exit(main())
