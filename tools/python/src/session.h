#pragma once
// What the Python objects hold: a surface (control mesh, limit surface, projector) shared by its
// regions and maps, a region that keeps its surface alive, and a map that keeps both surfaces and
// regions alive (the Mapping references them). Long calls run without the GIL through
// PythonProgress.
#include <pybind11/pybind11.h>

#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "elastic/core/progress.h"
#include "elastic/mapping/map_decal.h"
#include "elastic/mapping/map_regions.h"
#include "elastic/mesh/polygon_mesh.h"
#include "elastic/metrics/map_metrics.h"
#include "elastic/projection/closest_point.h"
#include "elastic/regions/region.h"
#include "elastic/surface/limit_surface.h"
#include "elastic/transfer/tangent_frames.h"

namespace elastic::python {

namespace py = pybind11;

struct SurfaceState {
  std::string name;
  std::shared_ptr<PolygonMesh> mesh;
  std::unique_ptr<LimitSurface> surface;
  std::unique_ptr<SurfaceProjector> projector;
};

struct RegionState {
  std::shared_ptr<const SurfaceState> surface;
  Region region;
};

struct MapState {
  std::shared_ptr<const SurfaceState> source, target;
  std::shared_ptr<const RegionState> source_region, target_region;
  MapResult result;
  MapMetrics metrics, naive_metrics;  // docs/metrics.md, as `elastic map` reports them
  /// A placed decal (place_decal): its placement, and the region cut along its relaxed boundary
  /// that the Mapping references (target_region holds a copy for the transfer).
  std::optional<DecalGeometry> decal;
  std::unique_ptr<Region> placed_region;
  /// The map's differential per grid triangle, built on first use (transport_vectors).
  std::once_flag differential_once;
  std::unique_ptr<MapDifferential> differential;
};

/// A progress callback for the library that calls a Python callable (or nothing) under the GIL
/// and watches for Ctrl-C: a pending KeyboardInterrupt, or an exception raised by the callable,
/// asks the work to stop and is raised by rethrow() once it has returned.
/// The callable receives (stage: str, iteration: int, total: int, energy: float,
/// gradient: float); returning False stops the work as well (no exception).
class PythonProgress {
 public:
  explicit PythonProgress(py::object callable) : callable_(std::move(callable)) {}
  ProgressCallback callback();
  /// Raises the stored Python error, if any (call with the GIL held).
  void rethrow();
  bool stopped() const { return stopped_; }

 private:
  py::object callable_;
  std::mutex mutex_;
  std::exception_ptr error_;
  bool stopped_ = false;
};

/// Runs `work` on a thread of its own while the calling thread waits without the GIL, watching for
/// Ctrl-C: on a pending KeyboardInterrupt the call raises it at once and the work finishes unseen
/// in the background (so it must own what it touches, shared_ptrs captured by value, and write no
/// file). For the long steps the library gives no progress callback: reading a mesh, building a
/// limit surface and its search structure, building a region. Exceptions of `work` are rethrown.
void run_interruptible(std::function<void()> work);

/// Measures a placement of the map's particles on its target as `elastic map` does
/// (docs/metrics.md): the map's rest scale, the target's normals, particles without a valid
/// surface point (or flagged in `outside`) left out.
MapMetrics measure_on_target(const MapState& map, const Eigen::Matrix3Xd& positions,
                             const std::vector<SurfacePoint>& points,
                             std::vector<char> outside = {});

/// The metrics' scalars as a dict (the keys of the CLI report's "metrics").
py::dict metrics_dict(const MapMetrics& metrics);

void bind_geometry(py::module_& m);
void bind_map(py::module_& m);

}  // namespace elastic::python
