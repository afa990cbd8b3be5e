#include "elastic/transfer/color_source.h"

#include <algorithm>
#include <cmath>

#include "elastic/core/error.h"
#include "elastic/mesh/default_material.h"
#include "elastic/regions/texture_coordinates.h"

namespace elastic {

std::vector<std::pair<int, double>> control_vertex_weights(const LimitSurface& surface,
                                                           const SurfacePoint& p) {
  const PolygonMesh& mesh = surface.control_mesh();
  const int f = surface.control_face(p.face);
  const std::span<const int> corners = mesh.face(f);
  const int n = static_cast<int>(corners.size());
  auto vertex = [&](int k) { return corners[static_cast<size_t>(((k % n) + n) % n)]; };
  const double u = p.u, v = p.v;
  std::vector<std::pair<int, double>> w;
  if (surface.triangular_domain()) {
    w = {{vertex(0), 1.0 - u - v}, {vertex(1), u}, {vertex(2), v}};
    return w;
  }
  // Bilinear weights of the ptex square's corners (0,0), (1,0), (1,1), (0,1).
  const double w00 = (1.0 - u) * (1.0 - v), w10 = u * (1.0 - v), w11 = u * v, w01 = (1.0 - u) * v;
  if (n == 4) {
    w = {{vertex(0), w00}, {vertex(1), w10}, {vertex(2), w11}, {vertex(3), w01}};
    return w;
  }
  // Sub-face i of an n-gon: (c_i, mid(i, i+1), centroid, mid(i-1, i)), expanded into the corners.
  const int i = p.face - surface.first_ptex_face(f);
  w.reserve(static_cast<size_t>(n) + 4);
  w.emplace_back(vertex(i), w00 + 0.5 * w10 + 0.5 * w01);
  w.emplace_back(vertex(i + 1), 0.5 * w10);
  w.emplace_back(vertex(i - 1), 0.5 * w01);
  for (int k = 0; k < n; ++k) {
    w.emplace_back(vertex(k), w11 / n);
  }
  return w;
}

double interpolate_vertex_scalar(const LimitSurface& surface, const std::vector<double>& values,
                                 const SurfacePoint& p) {
  if (static_cast<int>(values.size()) != surface.control_mesh().num_vertices()) {
    throw InvalidInputError(surface.name(),
                            "expected one scalar per control vertex (" +
                                std::to_string(surface.control_mesh().num_vertices()) + "), got " +
                                std::to_string(values.size()));
  }
  double s = 0.0;
  for (const auto& [vertex, weight] : control_vertex_weights(surface, p)) {
    s += weight * values[static_cast<size_t>(vertex)];
  }
  return s;
}

Eigen::Vector4f ColorSource::color(const SurfacePoint& p) const {
  switch (kind_) {
    case ColorSourceKind::Texture:
      return sample(image_, texture_coordinate(*surface_, p), ImageWrap::Repeat);
    case ColorSourceKind::VertexColors: {
      const auto& colors = surface_->control_mesh().vertex_colors;
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (const auto& [vertex, weight] : control_vertex_weights(*surface_, p)) {
        c += weight * colors[static_cast<size_t>(vertex)].cast<double>();
      }
      return Eigen::Vector4f(static_cast<float>(c.x()), static_cast<float>(c.y()),
                             static_cast<float>(c.z()), 1.0f);
    }
    case ColorSourceKind::VertexScalars: {
      double s = 0.0;
      for (const auto& [vertex, weight] : control_vertex_weights(*surface_, p)) {
        s += weight * values_[static_cast<size_t>(vertex)];
      }
      const auto g = static_cast<float>(std::clamp((s - lo_) / (hi_ - lo_), 0.0, 1.0));
      return Eigen::Vector4f(g, g, g, 1.0f);
    }
  }
  return Eigen::Vector4f::Zero();
}

Eigen::Vector2d ColorSource::texcoord(const SurfacePoint& p) const {
  if (kind_ != ColorSourceKind::Texture) {
    return Eigen::Vector2d::Zero();
  }
  return texture_coordinate(*surface_, p);
}

ColorSource ColorSource::texture(const LimitSurface& surface, const std::filesystem::path& image,
                                 const ImageReadOptions& read_options) {
  if (!surface.control_mesh().has_texcoords()) {
    throw InvalidInputError(surface.name(),
                            "has no texture coordinates (needed for a texture colour source)");
  }
  std::filesystem::path path = image;
  if (path.empty()) {
    path = first_diffuse_texture(surface.control_mesh());
    if (path.empty()) {
      throw InvalidInputError(surface.name(),
                              "has no material with a diffuse texture (map_Kd); give an image");
    }
  }
  return texture(surface, read_image(path, read_options), path);
}

ColorSource ColorSource::texture(const LimitSurface& surface, Image image,
                                 std::filesystem::path path) {
  if (!surface.control_mesh().has_texcoords()) {
    throw InvalidInputError(surface.name(),
                            "has no texture coordinates (needed for a texture colour source)");
  }
  if (image.empty()) {
    throw InvalidInputError(path.string(), "the texture image is empty");
  }
  ColorSource s;
  s.surface_ = &surface;
  s.kind_ = ColorSourceKind::Texture;
  s.image_ = std::move(image);
  s.image_path_ = std::move(path);
  return s;
}

ColorSource ColorSource::vertex_colors(const LimitSurface& surface) {
  if (!surface.control_mesh().has_vertex_colors()) {
    throw InvalidInputError(surface.name(), "has no per-vertex colours");
  }
  ColorSource s;
  s.surface_ = &surface;
  s.kind_ = ColorSourceKind::VertexColors;
  return s;
}

ColorSource ColorSource::vertex_scalars(const LimitSurface& surface, std::vector<double> values,
                                        double lo, double hi) {
  if (static_cast<int>(values.size()) != surface.control_mesh().num_vertices()) {
    throw InvalidInputError(surface.name(),
                            "expected one scalar per control vertex (" +
                                std::to_string(surface.control_mesh().num_vertices()) + "), got " +
                                std::to_string(values.size()));
  }
  for (double v : values) {
    if (!std::isfinite(v)) {
      throw InvalidInputError(surface.name(), "a vertex scalar is not finite");
    }
  }
  if (!(hi > lo) || !std::isfinite(hi - lo)) {
    throw InvalidInputError(surface.name(), "the scalar range needs lo < hi");
  }
  ColorSource s;
  s.surface_ = &surface;
  s.kind_ = ColorSourceKind::VertexScalars;
  s.values_ = std::move(values);
  s.lo_ = lo;
  s.hi_ = hi;
  return s;
}

}  // namespace elastic
