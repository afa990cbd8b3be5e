"""Sixteen small pastes: one after another with the CLI, then as a batch on 2 local workers.

    PYTHONPATH=build/python python3 tools/python/benchmarks/batch_16.py [--workers 2]

Each paste: the shared pmp_logo_512.png (ellipse) onto a disk of spot.obj or onto the whole
hemisphere.off, 1,000 to 2,500 particles, default flags (no previews). Both runs write into fresh
folders under a temporary directory; times are wall times of the whole set (the batch's includes
starting its LocalCluster). Prints both and the ratio batch / sequential.
"""

import argparse
import json
import os
import subprocess
import tempfile
import time
from pathlib import Path

from elastic import batch

root = Path(__file__).resolve().parents[3]
meshes = Path(os.environ.get("ELASTIC_SHARED_DIR", root.parent / "shared")) / "meshes"



def main():
    from distributed import Client, LocalCluster

    parser = argparse.ArgumentParser()
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    work = Path(tempfile.mkdtemp(prefix="elastic-batch-bench-"))
    targets = [("spot.obj", "disk:0.358,-0.032,0.073,0.25"), ("hemisphere.off", "boundary")]
    jobs = []
    for k in range(16):
        mesh, region = targets[k % 2]
        job = {"command": "paste", "source-image": str(meshes / "pmp_logo_512.png"),
               "source-region": "ellipse", "target": str(meshes / mesh), "target-region": region,
               "particles": 1000 + 100 * k, "out": f"paste{k}"}
        path = work / f"job{k:02d}.json"
        path.write_text(json.dumps(job))
        jobs.append(str(path))

    tool = batch.find_tool()
    start = time.perf_counter()
    for k, job in enumerate(jobs):
        folder = work / "sequential" / f"job{k:02d}"
        subprocess.run([tool, "paste", "--job", job, "-q", "--threads", "1", "--out", str(folder)],
                       check=True, stdout=subprocess.DEVNULL)
    sequential = time.perf_counter() - start

    start = time.perf_counter()
    with LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as cluster, Client(cluster) as client:
        summary = batch.run_batch(jobs, client, str(work / "batch"))
    parallel = time.perf_counter() - start
    assert summary["ok"] == 16, summary
    print(f"16 pastes: sequential CLI {sequential:.1f} s, batch on {args.workers} workers "
          f"{parallel:.1f} s, ratio {parallel / sequential:.2f} (1 thread per paste in both)")


if __name__ == "__main__":  # the LocalCluster's workers are spawned processes that import this file
    main()
