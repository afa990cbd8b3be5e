#include "elastic/transfer/bake.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <system_error>

#include "elastic/core/error.h"
#include "elastic/regions/texture_coordinates.h"

namespace elastic {
namespace {

// Texture coordinate -> continuous pixel coordinates whose integer points are texel centres.
Eigen::Vector2d to_pixels(const Eigen::Vector2d& uv, int width, int height) {
  return {uv.x() * width - 0.5, (1.0 - uv.y()) * height - 0.5};
}

double segment_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                        const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

using CornerPixels = std::vector<std::array<Eigen::Vector2d, 3>>;

// Per triangle corner: target pixel coordinates (in the triangle's own ptex face).
CornerPixels corner_pixels(const TargetSamples& samples, const LimitSurface& target, int width,
                           int height) {
  const size_t nt = samples.triangles.size();
  CornerPixels pixel(nt);
  for (size_t t = 0; t < nt; ++t) {
    for (size_t k = 0; k < 3; ++k) {
      const Eigen::Vector2d& uv = samples.triangle_uv[t][k];
      pixel[t][k] = to_pixels(
          texture_coordinate(target, SurfacePoint{samples.triangle_face[t], uv.x(), uv.y()}), width,
          height);
    }
  }
  return pixel;
}

// Distance to the region's boundary in texels, in a band of `feather` texels around it (+infinity
// beyond): the boundary edges are the refined triangles' edges used by one triangle only.
std::vector<float> boundary_distance_texels(const TargetSamples& samples, const CornerPixels& pixel,
                                            int width, int height, double feather) {
  std::vector<float> distance(static_cast<size_t>(width) * static_cast<size_t>(height),
                              std::numeric_limits<float>::infinity());
  std::map<std::pair<int, int>, int> count;
  for (const Eigen::Vector3i& c : samples.triangles) {
    for (int k = 0; k < 3; ++k) {
      ++count[{std::min(c[k], c[(k + 1) % 3]), std::max(c[k], c[(k + 1) % 3])}];
    }
  }
  const double band = feather + 1.0;
  for (size_t t = 0; t < samples.triangles.size(); ++t) {
    const Eigen::Vector3i& c = samples.triangles[t];
    for (int k = 0; k < 3; ++k) {
      const int a = c[k], b = c[(k + 1) % 3];
      if (count[{std::min(a, b), std::max(a, b)}] != 1) {
        continue;
      }
      const Eigen::Vector2d& pa = pixel[t][static_cast<size_t>(k)];
      const Eigen::Vector2d& pb = pixel[t][static_cast<size_t>((k + 1) % 3)];
      const int x0 = std::max(0, static_cast<int>(std::floor(std::min(pa.x(), pb.x()) - band)));
      const int x1 =
          std::min(width - 1, static_cast<int>(std::ceil(std::max(pa.x(), pb.x()) + band)));
      const int y0 = std::max(0, static_cast<int>(std::floor(std::min(pa.y(), pb.y()) - band)));
      const int y1 =
          std::min(height - 1, static_cast<int>(std::ceil(std::max(pa.y(), pb.y()) + band)));
      for (int y = y0; y <= y1; ++y) {
        for (int x = x0; x <= x1; ++x) {
          const double d = segment_distance(Eigen::Vector2d(x, y), pa, pb);
          float& slot = distance[static_cast<size_t>(y) * static_cast<size_t>(width) +
                                 static_cast<size_t>(x)];
          slot = std::min(slot, static_cast<float>(d));
        }
      }
    }
  }
  return distance;
}

// Per-vertex source data: texture coordinates (texture source) or colours; has[i] where the
// vertex has a source.
struct VertexSources {
  bool texture = false;
  std::vector<Eigen::Vector2d> uv;
  std::vector<Eigen::Vector4f> color;
  std::vector<char> has;

  VertexSources(const TargetSamples& samples, const ColorSource& source)
      : texture(source.kind() == ColorSourceKind::Texture),
        uv(samples.sources.size(), Eigen::Vector2d::Zero()),
        color(samples.sources.size(), Eigen::Vector4f::Zero()),
        has(samples.sources.size(), 0) {
    for (size_t i = 0; i < samples.sources.size(); ++i) {
      if (!samples.sources[i].inside) {
        continue;
      }
      has[i] = 1;
      if (texture) {
        uv[i] = source.texcoord(samples.sources[i].point);
      } else {
        color[i] = source.color(samples.sources[i].point);
      }
    }
  }
};

// Rasterises one region triangle (corners c at pixels p) into the result: every texel centre in
// the closed triangle takes the source colour at its barycentric position, blended by alpha, the
// source's alpha and the feather ramp; `painted` marks it.
void paint_triangle(const Eigen::Vector3i& c, const std::array<Eigen::Vector2d, 3>& p,
                    const VertexSources& sources, const ColorSource& source,
                    const Image& target_image, const std::vector<float>& distance,
                    const BakeOptions& options, BakeResult& result, std::vector<char>& painted) {
  const int width = target_image.width, height = target_image.height;
  const Eigen::Vector2d e1 = p[1] - p[0], e2 = p[2] - p[0];
  const double det = e1.x() * e2.y() - e1.y() * e2.x();
  if (det == 0.0) {
    return;  // zero area in texture space: covers no texel centre
  }
  const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({p[0].x(), p[1].x(), p[2].x()}))));
  const int x1 =
      std::min(width - 1, static_cast<int>(std::floor(std::max({p[0].x(), p[1].x(), p[2].x()}))));
  const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({p[0].y(), p[1].y(), p[2].y()}))));
  const int y1 =
      std::min(height - 1, static_cast<int>(std::floor(std::max({p[0].y(), p[1].y(), p[2].y()}))));
  // Closed triangle with a tolerance relative to the barycentric scale (round-off of texel
  // centres exactly on an edge).
  constexpr double kEdge = -1e-9;
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const Eigen::Vector2d d = Eigen::Vector2d(x, y) - p[0];
      const double b1 = (d.x() * e2.y() - d.y() * e2.x()) / det;
      const double b2 = (e1.x() * d.y() - e1.y() * d.x()) / det;
      const double b0 = 1.0 - b1 - b2;
      if (b0 < kEdge || b1 < kEdge || b2 < kEdge) {
        continue;
      }
      Eigen::Vector4f src;
      if (sources.texture) {
        const Eigen::Vector2d uv = b0 * sources.uv[static_cast<size_t>(c[0])] +
                                   b1 * sources.uv[static_cast<size_t>(c[1])] +
                                   b2 * sources.uv[static_cast<size_t>(c[2])];
        src = sample(source.image(), uv, ImageWrap::Repeat);
      } else {
        src = static_cast<float>(b0) * sources.color[static_cast<size_t>(c[0])] +
              static_cast<float>(b1) * sources.color[static_cast<size_t>(c[1])] +
              static_cast<float>(b2) * sources.color[static_cast<size_t>(c[2])];
      }
      const size_t index =
          static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
      float ramp = 1.0f;
      if (options.feather > 0.0) {
        ramp = static_cast<float>(
            std::clamp(static_cast<double>(distance[index]) / options.feather, 0.0, 1.0));
      }
      const float w = options.alpha * std::clamp(src.w(), 0.0f, 1.0f) * ramp;
      const Eigen::Vector4f& in = target_image.at(x, y);
      Eigen::Vector4f out = in;
      out.head<3>() = (1.0f - w) * in.head<3>() + w * src.head<3>();
      result.image.at(x, y) = out;
      painted[index] = 1;
    }
  }
}

}  // namespace

BakeResult bake_texture(const TargetSamples& samples, const LimitSurface& target,
                        const ColorSource& source, const Image& target_image,
                        const BakeOptions& options) {
  const std::string& name = options.name;
  if (!target.control_mesh().has_texcoords()) {
    throw InvalidInputError(target.name(), "has no texture coordinates to bake into");
  }
  if (target_image.empty()) {
    throw InvalidInputError(name, "the target image is empty");
  }
  if (!(options.alpha >= 0.0f && options.alpha <= 1.0f)) {
    throw InvalidInputError(name, "alpha must be in [0, 1]");
  }
  if (!(options.feather >= 0.0) || !std::isfinite(options.feather)) {
    throw InvalidInputError(name, "feather must be a finite width >= 0 (texels)");
  }
  const int width = target_image.width, height = target_image.height;
  BakeResult result;
  result.image = target_image;
  const CornerPixels pixel = corner_pixels(samples, target, width, height);
  const std::vector<float> distance =
      options.feather > 0.0
          ? boundary_distance_texels(samples, pixel, width, height, options.feather)
          : std::vector<float>();
  const VertexSources sources(samples, source);
  std::vector<char> painted(static_cast<size_t>(width) * static_cast<size_t>(height), 0);
  for (size_t t = 0; t < samples.triangles.size(); ++t) {
    const Eigen::Vector3i& c = samples.triangles[t];
    if (sources.has[static_cast<size_t>(c[0])] && sources.has[static_cast<size_t>(c[1])] &&
        sources.has[static_cast<size_t>(c[2])]) {
      paint_triangle(c, pixel[t], sources, source, target_image, distance, options, result,
                     painted);
    }
  }
  for (size_t i = 0; i < painted.size(); ++i) {
    if (!painted[i]) {
      continue;
    }
    ++result.texels_painted;
    if (result.image.pixels[i] != target_image.pixels[i]) {
      ++result.texels_changed;
    }
  }
  return result;
}

PolygonMesh make_baked_mesh(const PaintedSurface& painted,
                            const std::filesystem::path& baked_texture,
                            const std::filesystem::path& input_texture) {
  if (!painted.surface->control_mesh().has_texcoords()) {
    throw InvalidInputError(painted.surface->name(),
                            "has no texture coordinates to show a baked texture");
  }
  PolygonMesh mesh = make_target_mesh(painted);
  const auto same = [](const std::filesystem::path& a, const std::filesystem::path& b) {
    std::error_code ec;
    return std::filesystem::weakly_canonical(a, ec) == std::filesystem::weakly_canonical(b, ec);
  };
  bool named = false;
  for (Material& m : mesh.materials) {
    if (!m.diffuse_texture.empty() && same(m.diffuse_texture, input_texture)) {
      m.diffuse_texture = baked_texture;
      named = true;
    }
  }
  if (!named) {
    Material baked;
    baked.name = "baked";
    baked.diffuse = Eigen::Vector3d::Ones();
    baked.diffuse_texture = baked_texture;
    mesh.materials = {baked};
    mesh.face_materials.assign(static_cast<size_t>(mesh.num_faces()), 0);
  }
  return mesh;
}

}  // namespace elastic
