# docs/python.md: the plane -> cap map from Python, a colour paste through it, and the metrics
# table beside CGAL's LSCM on the same grid. Run by the tests (tools/python/tests/test_docs.py).
import os
import sys
import tempfile

import elastic

meshes = os.path.join(os.environ.get("ELASTIC_SHARED_DIR", "../shared"), "meshes")
plane = elastic.Surface(os.path.join(meshes, "grid.off"))
cap = elastic.Surface(os.path.join(meshes, "hemisphere.off"))

# The source: a disk of radius 0.45 on the plane; the target: the whole cap.
m = elastic.map_regions(plane.region("disk:0.5,0.5,0,0.45"), cap.region("boundary"),
                        particles=2000)
if not m.ok:
    sys.exit(f"the map failed: {m.reason}, {m.folds} folds")

# Colour: an image pasted onto the cap through its own map, written as `elastic paste` would.
image, ellipse = elastic.image_source(os.path.join(meshes, "pmp_logo_512.png"), shape="ellipse")
decal = elastic.map_regions(ellipse, cap.region("boundary"), particles=2000)
out = tempfile.mkdtemp(prefix="elastic-")
files = decal.paste(os.path.join(out, "pasted"))
print("wrote", len(files), "files, e.g.", os.path.basename(files[0]))

# The metrics table: ElasticPaint and LSCM on the same particle grid (docs/metrics.md).
rows = {"ElasticPaint": m.metrics(), "LSCM": m.baseline("lscm")["metrics"]}
print(f"{'method':<14}{'length energy':>15}{'sym. Dirichlet':>16}{'angle err.':>12}{'folds':>7}")
for name, metrics in rows.items():
    print(f"{name:<14}{metrics['length_energy']:>15.5f}{metrics['symmetric_dirichlet']:>16.4f}"
          f"{metrics['angle_error_mean_deg']:>12.3f}{metrics['folds']:>7}")
