"""Mapping a million points forward through the Python binding beside the C++ call.

    PYTHONPATH=build/python python3 tools/python/benchmarks/forward_1m.py [--runs 5]

The plane -> cap map (grid.off disk 0.45 onto hemisphere.off, 2,000 particles) and a million
source points on a Vogel spiral (the same as build/tools/benchmarks/bench_mapping, whose C++ time
this script reads from its JSON output): prints both medians and the ratio (the bar: 1.5).
Conversions in and out of NumPy are timed; the closest-point query that makes the points is not.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

import elastic

root = Path(__file__).resolve().parents[3]
meshes = Path(os.environ.get("ELASTIC_SHARED_DIR", root.parent / "shared")) / "meshes"
parser = argparse.ArgumentParser()
parser.add_argument("--runs", type=int, default=5)
parser.add_argument("--bench", default=str(root / "build/tools/benchmarks/bench_mapping"))
args = parser.parse_args()

n = 1_000_000
i = np.arange(n, dtype=np.float64)
r = 0.44 * np.sqrt((i + 0.5) / n)
theta = np.pi * (3.0 - np.sqrt(5.0)) * i
points = np.stack([0.5 + r * np.cos(theta), 0.5 + r * np.sin(theta), np.zeros(n)], axis=1)

plane = elastic.Surface(str(meshes / "grid.off"))
cap = elastic.Surface(str(meshes / "hemisphere.off"))
m = elastic.map_regions(plane.region("disk:0.5,0.5,0,0.45"), cap.region("boundary"),
                        particles=2000)
source = plane.closest(points)
seconds = []
for _ in range(args.runs):
    start = time.perf_counter()
    out = m.forward(source["face"], source["uv"])
    seconds.append(time.perf_counter() - start)
python_ms = 1e3 * statistics.median(seconds)

run = subprocess.run([args.bench, "--benchmark_format=json", f"--benchmark_repetitions={args.runs}",
                      "--benchmark_filter=ForwardMillion"], capture_output=True, text=True,
                     check=True)
report = json.loads(run.stdout)
cpp = [b for b in report["benchmarks"] if b.get("aggregate_name") == "median"][0]
cpp_ms = cpp["real_time"]
print(f"{n:,} points, {int(out['inside'].sum()):,} inside (C++: {int(cpp['inside']):,}); "
      f"median of {args.runs}: Python binding {python_ms:.1f} ms, C++ {cpp_ms:.1f} ms, "
      f"ratio {python_ms / cpp_ms:.2f}")
sys.exit(0)
