#include "aim.h"

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <sstream>
#include <utility>

#include "elastic/core/error.h"
#include "job_file.h"

namespace elastic::cli {

Eigen::Vector3d resolve_up(const std::string& flag_value, const PolygonMesh& mesh,
                           std::string* reason, const std::string& flag) {
  if (flag_value.empty() || flag_value == "auto") {
    const UpAxisGuess guess = guess_up_axis(mesh);
    if (reason != nullptr) {
      *reason =
          std::string("guessed (confidence ") + to_string(guess.confidence) + "): " + guess.reason;
    }
    return guess.direction;
  }
  try {
    const Eigen::Vector3d up = parse_up_direction(flag_value, flag);
    if (reason != nullptr) *reason = "given by " + flag;
    return up;
  } catch (const InvalidInputError& e) {
    throw UsageError(e.what());
  }
}

std::string direction_name(const Eigen::Vector3d& d) {
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(std::abs(d[axis]) - 1.0) < 1e-12) {
      return std::string(d[axis] > 0 ? "+" : "-") + "xyz"[axis];
    }
  }
  std::ostringstream out;
  out.precision(4);
  out << '(' << d.x() << ", " << d.y() << ", " << d.z() << ')';
  return out.str();
}

RegionFigures region_figures(const Region& region) {
  RegionFigures f;
  Eigen::Vector3d vector_area = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3i& t : region.triangles) {
    const Eigen::Vector3d& a = region.positions[static_cast<size_t>(t[0])];
    const Eigen::Vector3d& b = region.positions[static_cast<size_t>(t[1])];
    const Eigen::Vector3d& c = region.positions[static_cast<size_t>(t[2])];
    const Eigen::Vector3d n = (b - a).cross(c - a);
    f.area += 0.5 * n.norm();
    f.centroid += 0.5 * n.norm() * (a + b + c) / 3.0;
    vector_area += 0.5 * n;
  }
  if (f.area > 0.0) f.centroid /= f.area;
  if (vector_area.norm() > 0.0) f.normal = vector_area.normalized();
  const size_t nb = region.boundary.size();
  for (size_t i = 0; i < nb; ++i) {
    f.perimeter += (region.positions[static_cast<size_t>(region.boundary[(i + 1) % nb])] -
                    region.positions[static_cast<size_t>(region.boundary[i])])
                       .norm();
  }
  if (nb > 0) f.anchor = region.boundary_curve().locate(0.0).position;  // s = 0: the anchor

  // Dijkstra over the triangles' edges from all boundary vertices at once.
  const size_t n = region.positions.size();
  std::vector<std::vector<int>> neighbours(n);
  for (const Eigen::Vector3i& t : region.triangles) {
    for (int k = 0; k < 3; ++k) {
      neighbours[static_cast<size_t>(t[k])].push_back(t[(k + 1) % 3]);
      neighbours[static_cast<size_t>(t[(k + 1) % 3])].push_back(t[k]);
    }
  }
  std::vector<double> distance(n, std::numeric_limits<double>::infinity());
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  for (const int b : region.boundary) {
    distance[static_cast<size_t>(b)] = 0.0;
    queue.emplace(0.0, b);
  }
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > distance[static_cast<size_t>(v)]) continue;
    for (const int w : neighbours[static_cast<size_t>(v)]) {
      const double through =
          d + (region.positions[static_cast<size_t>(w)] - region.positions[static_cast<size_t>(v)])
                  .norm();
      if (through < distance[static_cast<size_t>(w)]) {
        distance[static_cast<size_t>(w)] = through;
        queue.emplace(through, w);
      }
    }
  }
  for (const double d : distance) {
    if (std::isfinite(d)) f.geodesic_radius = std::max(f.geodesic_radius, d);
  }
  return f;
}

Camera aim_camera(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& normal,
                  const Eigen::Vector3d& up, double fov, int width, int height, double fill) {
  // Three-quarter view: the normal raised towards up (a region facing up or down is seen from
  // its normal, tilted by orbit_view's fallback when the normal is along up).
  Eigen::Vector3d view = orbit_view(normal, 0.0, 25.0, up);
  if (std::abs(normal.normalized().dot(up.normalized())) > 0.95) {
    // Seen straight along up the picture has no horizon: lean back a little along the most
    // horizontal axis instead.
    Eigen::Vector3d side = Eigen::Vector3d::UnitY();
    if (std::abs(up.normalized().dot(side)) > 0.5) side = Eigen::Vector3d::UnitZ();
    view = (normal.normalized() + 0.6 * (side - side.dot(up.normalized()) * up.normalized()))
               .normalized();
  }
  Camera camera = frame_points(points, view, kFramingFov, width, height, fill, up);
  camera.fov_deg = fov;  // the same eye: a narrower angle magnifies
  return camera;
}

PolygonMesh region_outline(const Region& region) {
  PolygonMesh outline;
  outline.positions = region.positions;
  if (region.boundary.size() >= 3) outline.add_face(region.boundary);
  return outline;
}

PolygonMesh lifted_region(const Region& region, double offset) {
  std::vector<Eigen::Vector3d> normals(region.positions.size(), Eigen::Vector3d::Zero());
  PolygonMesh mesh;
  for (const Eigen::Vector3i& t : region.triangles) {
    const Eigen::Vector3d& a = region.positions[static_cast<size_t>(t[0])];
    const Eigen::Vector3d n = (region.positions[static_cast<size_t>(t[1])] - a)
                                  .cross(region.positions[static_cast<size_t>(t[2])] - a);
    for (int k = 0; k < 3; ++k) normals[static_cast<size_t>(t[k])] += n;  // area-weighted
    mesh.add_face({t[0], t[1], t[2]});
  }
  mesh.positions = region.positions;
  for (size_t v = 0; v < normals.size(); ++v) {
    if (normals[v].norm() > 0.0) mesh.positions[v] += offset * normals[v].normalized();
  }
  return mesh;
}

}  // namespace elastic::cli
