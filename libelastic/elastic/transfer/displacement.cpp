#include "elastic/transfer/displacement.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <queue>
#include <utility>

#include "elastic/core/error.h"
#include "elastic/regions/texture_coordinates.h"

namespace elastic {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Distance from p to segment [a, b] (clamped projection).
double segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                        const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double s = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + s * ab)).norm();
}

// Edges of the triangles as sorted (min, max) vertex pairs with their use counts; boundary edges
// are used once.
std::vector<std::pair<int, int>> boundary_edges(std::span<const Eigen::Vector3i> triangles) {
  std::vector<std::pair<int, int>> edges;
  edges.reserve(triangles.size() * 3);
  for (const Eigen::Vector3i& t : triangles) {
    for (int c = 0; c < 3; ++c) {
      const int a = t[c], b = t[(c + 1) % 3];
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  std::vector<std::pair<int, int>> once;
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) {
      ++j;
    }
    if (j - i == 1) {
      once.push_back(edges[i]);
    }
    i = j;
  }
  return once;
}

void check_triangles(std::span<const Eigen::Vector3i> triangles, size_t n,
                     const std::string& name) {
  for (size_t k = 0; k < triangles.size(); ++k) {
    if (triangles[k].minCoeff() < 0 || triangles[k].maxCoeff() >= static_cast<int>(n)) {
      throw InvalidInputError(name, "triangle " + std::to_string(k) + " names a missing vertex");
    }
  }
}

}  // namespace

std::vector<double> heights_from_image(const Image& image, std::span<const Eigen::Vector2d> uv,
                                       const HeightImageOptions& options) {
  if (image.empty()) {
    throw InvalidInputError("height image", "the image is empty");
  }
  std::vector<double> heights(uv.size());
  for (size_t i = 0; i < uv.size(); ++i) {
    if (!uv[i].allFinite()) {
      throw InvalidInputError("height image",
                              "texture coordinate " + std::to_string(i) + " is not finite");
    }
    const Eigen::Vector4f c = sample(image, uv[i], options.wrap);
    double value = 0.0;
    switch (options.channel) {
      case HeightChannel::Luminance:
        value = luminance(c);
        break;
      case HeightChannel::Red:
        value = static_cast<double>(c[0]);
        break;
      case HeightChannel::Green:
        value = static_cast<double>(c[1]);
        break;
      case HeightChannel::Blue:
        value = static_cast<double>(c[2]);
        break;
      case HeightChannel::Alpha:
        value = static_cast<double>(c[3]);
        break;
    }
    heights[i] = value - options.zero_level;
  }
  return heights;
}

std::vector<double> boundary_distance(std::span<const Eigen::Vector3d> positions,
                                      std::span<const Eigen::Vector3i> triangles,
                                      double max_distance) {
  const size_t n = positions.size();
  check_triangles(triangles, n, "boundary distance");
  std::vector<std::vector<int>> neighbours(n);
  for (const Eigen::Vector3i& t : triangles) {
    for (int c = 0; c < 3; ++c) {
      neighbours[static_cast<size_t>(t[c])].push_back(t[(c + 1) % 3]);
      neighbours[static_cast<size_t>(t[c])].push_back(t[(c + 2) % 3]);
    }
  }
  const std::vector<std::pair<int, int>> edges = boundary_edges(triangles);
  std::vector<double> distance(n, kInfinity);
  std::vector<int> nearest(n, -1);  // index into `edges` of the vertex's nearest boundary edge
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  for (size_t k = 0; k < edges.size(); ++k) {
    for (const int v : {edges[k].first, edges[k].second}) {
      distance[static_cast<size_t>(v)] = 0.0;
      nearest[static_cast<size_t>(v)] = static_cast<int>(k);
    }
  }
  for (size_t v = 0; v < n; ++v) {
    if (nearest[v] >= 0) {
      queue.emplace(0.0, static_cast<int>(v));
    }
  }
  // Each vertex inherits its neighbour's nearest boundary edge when that edge is closer than the
  // one it has: the closest-feature analogue of Dijkstra. Distances are true point-segment
  // distances, so no path-length error accumulates.
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > distance[static_cast<size_t>(v)]) {
      continue;
    }
    const std::pair<int, int>& e = edges[static_cast<size_t>(nearest[static_cast<size_t>(v)])];
    for (const int w : neighbours[static_cast<size_t>(v)]) {
      const double dw = segment_distance(positions[static_cast<size_t>(w)],
                                         positions[static_cast<size_t>(e.first)],
                                         positions[static_cast<size_t>(e.second)]);
      if (dw < distance[static_cast<size_t>(w)] && dw <= max_distance) {
        distance[static_cast<size_t>(w)] = dw;
        nearest[static_cast<size_t>(w)] = nearest[static_cast<size_t>(v)];
        queue.emplace(dw, w);
      }
    }
  }
  return distance;
}

DisplacementResult displace_along_normals(std::span<const Eigen::Vector3d> positions,
                                          std::span<const Eigen::Vector3d> normals,
                                          std::span<const double> heights,
                                          std::span<const Eigen::Vector3i> triangles,
                                          const DisplacementOptions& options) {
  const size_t n = positions.size();
  const std::string& name = options.name;
  if (normals.size() != n || heights.size() != n) {
    throw InvalidInputError(
        name, "positions, normals and heights must have one entry per vertex (" +
                  std::to_string(n) + " positions, " + std::to_string(normals.size()) +
                  " normals, " + std::to_string(heights.size()) + " heights)");
  }
  if (!std::isfinite(options.scale)) {
    throw InvalidInputError(name, "scale is not finite");
  }
  if (!(options.falloff_width >= 0.0) || !std::isfinite(options.falloff_width)) {
    throw InvalidInputError(name, "falloff width must be finite and >= 0");
  }
  check_triangles(triangles, n, name);
  for (size_t i = 0; i < n; ++i) {
    if (!positions[i].allFinite() || !normals[i].allFinite()) {
      throw InvalidInputError(name, "vertex " + std::to_string(i) +
                                        " has a non-finite position "
                                        "or normal");
    }
    if (std::isinf(heights[i])) {
      throw InvalidInputError(name, "vertex " + std::to_string(i) + " has an infinite height");
    }
  }

  DisplacementResult result;
  std::vector<char> on_boundary(n, 0);
  for (const auto& [a, b] : boundary_edges(triangles)) {
    on_boundary[static_cast<size_t>(a)] = on_boundary[static_cast<size_t>(b)] = 1;
  }
  result.boundary_vertices =
      static_cast<int>(std::count(on_boundary.begin(), on_boundary.end(), 1));

  result.weights.assign(n, 1.0);
  if (options.falloff_width > 0.0) {
    result.boundary_distance = boundary_distance(positions, triangles, options.falloff_width);
    for (size_t i = 0; i < n; ++i) {
      // Smoothstep: w(0) = 0, w(1) = 1, w'(0) = w'(1) = 0, so the displaced surface leaves the
      // boundary tangentially and joins the full relief without a kink.
      const double t = std::min(result.boundary_distance[i] / options.falloff_width, 1.0);
      result.weights[i] = t * t * (3.0 - 2.0 * t);
    }
  }
  if (options.pin_boundary) {
    for (size_t i = 0; i < n; ++i) {
      if (on_boundary[i]) {
        result.weights[i] = 0.0;
      }
    }
  }

  result.positions.assign(positions.begin(), positions.end());
  for (size_t i = 0; i < n; ++i) {
    if (std::isnan(heights[i])) {
      ++result.skipped;
      result.weights[i] = 0.0;
      continue;
    }
    const Eigen::Vector3d offset = options.scale * result.weights[i] * heights[i] * normals[i];
    result.positions[i] += offset;
    result.max_displacement = std::max(result.max_displacement, offset.norm());
  }
  return result;
}

std::vector<double> sample_heights_from_image(const TargetSamples& samples,
                                              const LimitSurface& source, const Image& image,
                                              const HeightImageOptions& options) {
  if (!source.control_mesh().has_texcoords()) {
    throw InvalidInputError(source.name(), "has no texture coordinates to look up a height image");
  }
  std::vector<double> heights(static_cast<size_t>(samples.num_vertices()),
                              std::numeric_limits<double>::quiet_NaN());
  std::vector<Eigen::Vector2d> uv;
  std::vector<int> index;
  for (int i = 0; i < samples.num_vertices(); ++i) {
    if (!samples.sources[static_cast<size_t>(i)].inside) continue;
    uv.push_back(texture_coordinate(source, samples.sources[static_cast<size_t>(i)].point));
    index.push_back(i);
  }
  const std::vector<double> h = heights_from_image(image, uv, options);
  for (size_t k = 0; k < index.size(); ++k) heights[static_cast<size_t>(index[k])] = h[k];
  return heights;
}

std::vector<double> sample_heights_from_colors(const TargetSamples& samples,
                                               const ColorSource& colors, double zero_level) {
  std::vector<double> heights(static_cast<size_t>(samples.num_vertices()),
                              std::numeric_limits<double>::quiet_NaN());
  for (int i = 0; i < samples.num_vertices(); ++i) {
    const Mapping::Location& source = samples.sources[static_cast<size_t>(i)];
    if (!source.inside) continue;
    heights[static_cast<size_t>(i)] = luminance(colors.color(source.point)) - zero_level;
  }
  return heights;
}

DisplacedPaintedSurface displace_painted_surface(const PaintedSurface& painted,
                                                 std::span<const double> heights,
                                                 const DisplacementOptions& options) {
  const TargetSamples& samples = painted.samples;
  DisplacedPaintedSurface out;
  out.displacement = displace_along_normals(samples.positions, samples.normals, heights,
                                            samples.triangles, options);
  out.positions = painted.positions;
  for (int j = 0; j < samples.num_vertices(); ++j) {
    out.positions[static_cast<size_t>(painted.sample_vertex_index[static_cast<size_t>(j)])] =
        out.displacement.positions[static_cast<size_t>(j)];
  }
  return out;
}

}  // namespace elastic
