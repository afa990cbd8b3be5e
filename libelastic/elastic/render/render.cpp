// Embree ray tracer for preview pictures; see render.h for what is drawn and how.
#include "elastic/render/render.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <utility>

#include "elastic/core/detail/embree_handles.h"
#include "elastic/core/error.h"

namespace elastic {
namespace {

using detail::check_embree;
using detail::EmbreeDevice;
using detail::EmbreeScene;

// ---------------------------------------------------------------------------------------------------
// Counter-based random numbers: SplitMix64's finaliser hashes (seed, pixel, sample, stream) into a
// state, and each draw hashes the next counter value. No state is shared between pixels, so the
// numbers do not depend on which thread computes which pixel.

std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

class SampleRandom {
 public:
  SampleRandom(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample, std::uint64_t stream)
      : state_(mix64(mix64(mix64(seed + 0x9E3779B97F4A7C15ull) ^ pixel) ^ (sample * 4 + stream))) {}
  /// Uniform in [0, 1) with 53 random bits.
  double next() {
    state_ += 0x9E3779B97F4A7C15ull;
    return static_cast<double>(mix64(state_) >> 11) * 0x1.0p-53;
  }

 private:
  std::uint64_t state_;
};

// ---------------------------------------------------------------------------------------------------
// Per-object data the shader needs.

struct PreparedObject {
  const SceneObject* object = nullptr;
  SurfaceColoring source = SurfaceColoring::Plain;
  std::vector<Image> loaded_textures;                // when read here
  const std::vector<Image>* textures = nullptr;      // look.textures or loaded_textures
  std::vector<Eigen::Vector3d> vertex_normals;       // unit, or zero where undefined
  std::vector<std::array<int, 3>> triangle_corners;  // corner indices (into face_vertices)
  std::vector<int> triangle_face;
  std::vector<std::pair<int, int>> wire_edges;  // the wireframe's polygon edges (vertex pairs)
  double wire_radius = 0.0;
};

std::string object_name(size_t k) {
  return "object " + std::to_string(k);
}

[[noreturn]] void bad_object(size_t k, const std::string& problem) {
  throw InvalidInputError("render", object_name(k) + ": " + problem);
}

/// Rejects what would index out of range or read garbage.
void check_mesh(const PolygonMesh& mesh, size_t k) {
  const size_t nv = mesh.positions.size();
  for (const Eigen::Vector3d& p : mesh.positions) {
    if (!p.allFinite()) {
      bad_object(k, "a vertex position is not finite");
    }
  }
  const int nf = mesh.num_faces();
  if (nf > 0) {
    if (mesh.face_offsets.front() != 0 ||
        mesh.face_offsets.back() != static_cast<int>(mesh.face_vertices.size())) {
      bad_object(k, "face offsets do not match the corner list");
    }
    for (int f = 0; f < nf; ++f) {
      if (mesh.face_size(f) < 3) {
        bad_object(k, "face " + std::to_string(f) + " has < 3 corners");
      }
    }
  }
  for (int v : mesh.face_vertices) {
    if (v < 0 || static_cast<size_t>(v) >= nv) {
      bad_object(k, "a face index is out of range");
    }
  }
  if (mesh.has_texcoords()) {
    if (mesh.corner_texcoords.size() != mesh.face_vertices.size()) {
      bad_object(k, "corner texture coordinates do not match the corners");
    }
    for (int t : mesh.corner_texcoords) {
      if (t < 0 || static_cast<size_t>(t) >= mesh.texcoords.size()) {
        bad_object(k, "a texture coordinate index is out of range");
      }
    }
  }
  if (mesh.has_vertex_colors() && mesh.vertex_colors.size() != nv) {
    bad_object(k, "vertex colours do not match the vertices");
  }
  if (mesh.has_face_colors() && mesh.face_colors.size() != static_cast<size_t>(nf)) {
    bad_object(k, "face colours do not match the faces");
  }
  if (!mesh.face_materials.empty()) {
    if (mesh.face_materials.size() != static_cast<size_t>(nf)) {
      bad_object(k, "face materials do not match the faces");
    }
    for (int m : mesh.face_materials) {
      if (m < -1 || m >= static_cast<int>(mesh.materials.size())) {
        bad_object(k, "a face material index is out of range");
      }
    }
  }
}

bool any_texture(const std::vector<Image>& textures) {
  return std::any_of(textures.begin(), textures.end(), [](const Image& i) { return !i.empty(); });
}

bool any_texture_file(const PolygonMesh& mesh) {
  return std::any_of(mesh.materials.begin(), mesh.materials.end(),
                     [](const Material& m) { return !m.diffuse_texture.empty(); });
}

/// Chooses the colour source and gets the textures it needs.
void resolve_colors(PreparedObject& prepared, size_t k) {
  const PolygonMesh& mesh = prepared.object->mesh;
  const ObjectLook& look = prepared.object->look;
  const bool has_materials = !mesh.materials.empty() && !mesh.face_materials.empty();
  if (!look.textures.empty() && look.textures.size() != mesh.materials.size()) {
    bad_object(k, std::to_string(look.textures.size()) + " textures for " +
                      std::to_string(mesh.materials.size()) + " materials");
  }
  const bool wants_texture = look.colors == SurfaceColoring::Texture ||
                             (look.colors == SurfaceColoring::Auto && mesh.has_texcoords());
  prepared.textures = &look.textures;
  if (wants_texture && look.textures.empty() && has_materials && any_texture_file(mesh)) {
    for (const Material& material : mesh.materials) {
      prepared.loaded_textures.push_back(
          material.diffuse_texture.empty() ? Image() : read_image(material.diffuse_texture));
    }
    prepared.textures = &prepared.loaded_textures;
  }
  const bool textured = mesh.has_texcoords() && has_materials && any_texture(*prepared.textures);
  switch (look.colors) {
    case SurfaceColoring::Auto:
      prepared.source = textured                   ? SurfaceColoring::Texture
                        : mesh.has_face_colors()   ? SurfaceColoring::FaceColors
                        : mesh.has_vertex_colors() ? SurfaceColoring::VertexColors
                        : has_materials            ? SurfaceColoring::Materials
                                                   : SurfaceColoring::Plain;
      return;
    case SurfaceColoring::FaceColors:
      if (!mesh.has_face_colors()) {
        bad_object(k, "has no face colours to show");
      }
      break;
    case SurfaceColoring::VertexColors:
      if (!mesh.has_vertex_colors()) {
        bad_object(k, "has no vertex colours to show");
      }
      break;
    case SurfaceColoring::Texture:
      if (!textured) {
        bad_object(k, "has no textured material with texture coordinates to show");
      }
      break;
    case SurfaceColoring::Materials:
      if (!has_materials) {
        bad_object(k, "has no materials to show");
      }
      break;
    case SurfaceColoring::Plain:
      break;
  }
  prepared.source = look.colors;
}

/// Newell's normal of face f: sum of p_i x p_{i+1}; twice the polygon's vector area, exact for
/// planar polygons and a robust average for warped ones.
Eigen::Vector3d newell_normal(const PolygonMesh& mesh, int f) {
  const std::span<const int> face = mesh.face(f);
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < face.size(); ++i) {
    n += mesh.positions[face[i]].cross(mesh.positions[face[(i + 1) % face.size()]]);
  }
  return n;
}

void compute_vertex_normals(PreparedObject& prepared) {
  const PolygonMesh& mesh = prepared.object->mesh;
  // Summing the unnormalised Newell normals weights each face by its area.
  prepared.vertex_normals.assign(mesh.positions.size(), Eigen::Vector3d::Zero());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d n = newell_normal(mesh, f);
    for (int v : mesh.face(f)) {
      prepared.vertex_normals[v] += n;
    }
  }
  for (Eigen::Vector3d& n : prepared.vertex_normals) {
    const double length = n.norm();
    n = length > 0.0 ? Eigen::Vector3d(n / length) : Eigen::Vector3d::Zero();
  }
}

/// The polygon edges (each once), as vertex pairs.
std::vector<std::pair<int, int>> polygon_edges(const PolygonMesh& mesh) {
  std::vector<std::pair<int, int>> edges;
  edges.reserve(mesh.face_vertices.size());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const std::span<const int> face = mesh.face(f);
    for (size_t i = 0; i < face.size(); ++i) {
      const int a = face[i], b = face[(i + 1) % face.size()];
      if (a != b) {
        edges.emplace_back(std::min(a, b), std::max(a, b));
      }
    }
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  return edges;
}

Eigen::Vector3f to_float(const Eigen::Vector3d& v) {
  return v.cast<float>();
}

// ---------------------------------------------------------------------------------------------------
// The tracer: Embree scene plus everything the per-pixel work reads (all const during rendering).

class Tracer {
 public:
  Tracer(const Scene& scene, const Camera& camera, const RenderOptions& options)
      : camera_(camera),
        options_(options),
        frame_(camera_frame(camera)),
        surfaces_(device_.get(), "render"),
        wires_(device_.get(), "render") {
    const Eigen::AlignedBox3d box = bounding_box(scene);
    if (!box.isEmpty()) {
      shift_ = box.center();
    }
    diagonal_ = box.isEmpty() ? 1.0 : std::max(box.diagonal().norm(), 1e-300);
    // World size of one pixel at the target's distance: the wire radius that gives the requested
    // screen width there (nearer wires look wider, farther ones thinner, as tubes do).
    const double pixel_size =
        2.0 * (camera.target - camera.eye).norm() * frame_.tan_half_height / camera.height;
    key_ = (options.key_light_direction.x() * frame_.right +
            options.key_light_direction.y() * frame_.up -
            options.key_light_direction.z() * frame_.forward)
               .normalized();

    prepared_.resize(scene.objects.size());
    for (size_t k = 0; k < scene.objects.size(); ++k) {
      PreparedObject& prepared = prepared_[k];
      prepared.object = &scene.objects[k];
      const ObjectLook& look = prepared.object->look;
      check_mesh(prepared.object->mesh, k);
      if (look.wireframe && !(look.wire_width_px > 0.0 && std::isfinite(look.wire_width_px))) {
        bad_object(k, "wire width must be a positive number of pixels");
      }
      prepared.wire_radius = 0.5 * look.wire_width_px * pixel_size;
      if (look.surface) {
        resolve_colors(prepared, k);
        compute_vertex_normals(prepared);
        add_triangles(static_cast<int>(k));
      }
      if (look.wireframe) {
        add_curves(static_cast<int>(k));
      }
    }
    // Robust (watertight) triangle tests: no background pixels leaking through shared edges.
    rtcSetSceneFlags(surfaces_.get(), RTC_SCENE_FLAG_ROBUST);
    rtcCommitScene(surfaces_.get());
    rtcCommitScene(wires_.get());
    check_embree(device_.get(), "render", "build the scene");
    wire_slack_ = static_cast<float>(options.wire_depth_tolerance * diagonal_);
  }

  /// Premultiplied RGBA seen along the ray from the eye through continuous pixel (px, py). `seen`,
  /// when given, receives what the ray hit: -1 the background, k object k's surface, n + k object
  /// k's wireframe (n objects).
  Eigen::Vector4f trace(double px, double py, SampleRandom& random, int* seen = nullptr) const {
    const Eigen::Vector3d direction = camera_ray_direction(camera_, frame_, px, py);
    const Eigen::Vector3d origin = camera_.eye - shift_;
    const Eigen::Vector3d view = -direction;  // towards the eye
    RTCRayHit query = make_ray(origin, direction, 0.0, std::numeric_limits<float>::infinity());
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    rtcIntersect1(surfaces_.get(), &context, &query);
    // Wires win over the surface seen when they are in front of it or at most `wire_slack_`
    // behind it along the ray (a grid on the limit surface lies just under the control mesh).
    RTCRayHit wire = make_ray(origin, direction, 0.0,
                              query.hit.geomID == RTC_INVALID_GEOMETRY_ID
                                  ? std::numeric_limits<float>::infinity()
                                  : query.ray.tfar + wire_slack_);
    rtcInitIntersectContext(&context);
    rtcIntersect1(wires_.get(), &context, &wire);

    if (wire.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
      const int object = wire_objects_[wire.hit.geomID];
      if (seen != nullptr) {
        *seen = static_cast<int>(prepared_.size()) + object;
      }
      const PreparedObject& prepared = prepared_[static_cast<size_t>(object)];
      Eigen::Vector3d n(wire.hit.Ng_x, wire.hit.Ng_y, wire.hit.Ng_z);
      n = n.norm() > 0.0 ? Eigen::Vector3d(n.normalized()) : view;
      if (n.dot(view) < 0.0) {
        n = -n;
      }
      const Eigen::Vector3f c = prepared.object->look.wire_color;
      const auto light = static_cast<float>(lighting(n, 1.0));
      return {c.x() * light, c.y() * light, c.z() * light, 1.0f};
    }
    if (query.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
      if (seen != nullptr) {
        *seen = -1;
      }
      return background(py);
    }

    const int object = surface_objects_[query.hit.geomID];
    if (seen != nullptr) {
      *seen = object;
    }
    const PreparedObject& prepared = prepared_[static_cast<size_t>(object)];
    const PolygonMesh& mesh = prepared.object->mesh;
    const std::array<int, 3>& corners = prepared.triangle_corners[query.hit.primID];
    const int face = prepared.triangle_face[query.hit.primID];
    // Embree's barycentrics: the hit is (1-u-v) p0 + u p1 + v p2.
    const double u = query.hit.u, v = query.hit.v;
    const std::array<double, 3> b{1.0 - u - v, u, v};
    std::array<int, 3> vertex{};
    Eigen::Vector3d point = Eigen::Vector3d::Zero(), smooth = Eigen::Vector3d::Zero();
    for (int i = 0; i < 3; ++i) {
      vertex[i] = mesh.face_vertices[corners[i]];
      point += b[i] * (mesh.positions[vertex[i]] - shift_);
      smooth += b[i] * prepared.vertex_normals[vertex[i]];
    }
    Eigen::Vector3d geometric = (mesh.positions[vertex[1]] - mesh.positions[vertex[0]])
                                    .cross(mesh.positions[vertex[2]] - mesh.positions[vertex[0]]);
    geometric = geometric.norm() > 0.0 ? Eigen::Vector3d(geometric.normalized()) : view;
    // Two-sided: light the side the ray sees; keep the smooth normal on that side too.
    if (geometric.dot(view) < 0.0) {
      geometric = -geometric;
    }
    if (smooth.norm() > 0.0) {
      smooth.normalize();
    }
    if (smooth.dot(geometric) < 0.0) {
      smooth = -smooth;
    }
    if (smooth.norm() == 0.0) {
      smooth = geometric;
    }

    const double visibility = occlusion(point, geometric, random);
    const Eigen::Vector3f base = surface_color(prepared, face, corners, vertex, b);
    const auto light = static_cast<float>(lighting(smooth, visibility));
    return {base.x() * light, base.y() * light, base.z() * light, 1.0f};
  }

  /// Sets busy[y * width + x] = 1 for every pixel within about a pixel of a wireframe edge's
  /// projection (its tube's projected half width plus 1.5 pixels), whether or not the edge is
  /// hidden: a conservative cover of the pixels a thin wire may touch between pixel centres.
  void mark_wires(std::vector<unsigned char>& busy) const {
    const int width = camera_.width, height = camera_.height;
    // Pixels per world unit at depth 1 along the view axis.
    const double pixels_per_unit = height / (2.0 * frame_.tan_half_height);
    const double near = 1e-6 * std::max((camera_.target - camera_.eye).norm(), 1e-300);
    // A segment longer than this on screen is marked over this many steps only (a wire passing
    // through the eye's plane); the rest of it may alias.
    const double max_steps = 8.0 * (width + height);
    for (const PreparedObject& prepared : prepared_) {
      const PolygonMesh& mesh = prepared.object->mesh;
      for (const auto& [first, second] : prepared.wire_edges) {
        Eigen::Vector3d a = mesh.positions[static_cast<size_t>(first)];
        Eigen::Vector3d b = mesh.positions[static_cast<size_t>(second)];
        double da = (a - camera_.eye).dot(frame_.forward),
               db = (b - camera_.eye).dot(frame_.forward);
        if (da < near && db < near) {
          continue;
        }
        // Clip to the near plane.
        if (da < near) {
          a += (near - da) / (db - da) * (b - a);
          da = near;
        } else if (db < near) {
          b += (near - db) / (da - db) * (a - b);
          db = near;
        }
        const Eigen::Vector2d pa = project(camera_, a).pixel, pb = project(camera_, b).pixel;
        const double steps = std::min(max_steps, std::ceil(2.0 * (pb - pa).norm()) + 1.0);
        for (double i = 0.0; i <= steps; i += 1.0) {
          const double t = i / steps;
          const Eigen::Vector2d p = (1.0 - t) * pa + t * pb;
          const double depth = (1.0 - t) * da + t * db;
          const double reach = prepared.wire_radius * pixels_per_unit / depth + 1.5;
          if (!(reach < width + height)) {
            continue;  // so close to the eye that it covers the picture: left to the colour test
          }
          const auto x0 = static_cast<int>(std::floor(p.x() - reach));
          const auto x1 = static_cast<int>(std::floor(p.x() + reach));
          const auto y0 = static_cast<int>(std::floor(p.y() - reach));
          const auto y1 = static_cast<int>(std::floor(p.y() + reach));
          for (int y = std::max(y0, 0); y <= std::min(y1, height - 1); ++y) {
            for (int x = std::max(x0, 0); x <= std::min(x1, width - 1); ++x) {
              busy[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)] =
                  1;
            }
          }
        }
      }
    }
  }

 private:
  static RTCRayHit make_ray(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                            double tnear, float tfar) {
    RTCRayHit query{};
    query.ray.org_x = static_cast<float>(origin.x());
    query.ray.org_y = static_cast<float>(origin.y());
    query.ray.org_z = static_cast<float>(origin.z());
    query.ray.dir_x = static_cast<float>(direction.x());
    query.ray.dir_y = static_cast<float>(direction.y());
    query.ray.dir_z = static_cast<float>(direction.z());
    query.ray.tnear = static_cast<float>(tnear);
    query.ray.tfar = tfar;
    query.ray.mask = 0xFFFFFFFFu;
    query.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    query.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    return query;
  }

  Eigen::Vector4f background(double py) const {
    if (options_.transparent_background) {
      return Eigen::Vector4f::Zero();
    }
    const auto t = static_cast<float>(std::clamp(py / camera_.height, 0.0, 1.0));
    const Eigen::Vector3f c = (1.0f - t) * options_.background_top + t * options_.background_bottom;
    return {c.x(), c.y(), c.z(), 1.0f};
  }

  /// Lambert: ambient and headlight scaled by the ambient-occlusion visibility, plus the key light.
  double lighting(const Eigen::Vector3d& n, double visibility) const {
    const Eigen::Vector3d view = -frame_.forward;
    return (options_.ambient + options_.headlight * std::max(0.0, n.dot(view))) * visibility +
           options_.key_light * std::max(0.0, n.dot(key_));
  }

  /// Fraction of cosine-weighted hemisphere rays around `normal` that escape within the radius.
  double occlusion(const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                   SampleRandom& random) const {
    const int count = options_.ambient_occlusion_samples;
    if (count <= 0) {
      return 1.0;
    }
    // Start the rays a little off the surface so they do not hit their own triangle through
    // single-precision round-off (1e-5 of the scene is ~100 float ulps of its extent).
    const double offset = 1e-5 * diagonal_;
    const auto radius = static_cast<float>(options_.ambient_occlusion_radius * diagonal_);
    const Eigen::Vector3d origin = point + offset * normal;
    // Orthonormal tangents (Frisvad-style choice of a helper axis).
    const Eigen::Vector3d helper =
        std::abs(normal.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    const Eigen::Vector3d t1 = normal.cross(helper).normalized();
    const Eigen::Vector3d t2 = normal.cross(t1);
    int open = 0;
    for (int i = 0; i < count; ++i) {
      // Cosine-weighted: a uniform point on the unit disk lifted onto the hemisphere (Malley).
      const double r = std::sqrt(random.next()), phi = 2.0 * std::numbers::pi * random.next();
      const double x = r * std::cos(phi), y = r * std::sin(phi);
      const double z = std::sqrt(std::max(0.0, 1.0 - x * x - y * y));
      const Eigen::Vector3d d = x * t1 + y * t2 + z * normal;
      RTCRay ray = make_ray(origin, d, 0.0, radius).ray;
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      rtcOccluded1(surfaces_.get(), &context, &ray);  // wires cast no occlusion
      // Embree sets tfar to -inf when the ray is blocked.
      if (ray.tfar >= 0.0f) {
        ++open;
      }
    }
    return static_cast<double>(open) / count;
  }

  Eigen::Vector3f material_color(const PreparedObject& prepared, int face) const {
    const PolygonMesh& mesh = prepared.object->mesh;
    const int m = mesh.face_materials.empty() ? -1 : mesh.face_materials[face];
    return m >= 0 ? mesh.materials[m].diffuse.cast<float>() : prepared.object->look.plain_color;
  }

  Eigen::Vector3f surface_color(const PreparedObject& prepared, int face,
                                const std::array<int, 3>& corners, const std::array<int, 3>& vertex,
                                const std::array<double, 3>& b) const {
    const PolygonMesh& mesh = prepared.object->mesh;
    switch (prepared.source) {
      case SurfaceColoring::FaceColors:
        return mesh.face_colors[face];
      case SurfaceColoring::VertexColors: {
        Eigen::Vector3f c = Eigen::Vector3f::Zero();
        for (int i = 0; i < 3; ++i) {
          c += static_cast<float>(b[i]) * mesh.vertex_colors[vertex[i]];
        }
        return c;
      }
      case SurfaceColoring::Texture: {
        Eigen::Vector3f under = material_color(prepared, face);
        const int m = mesh.face_materials[face];
        if (m < 0 || (*prepared.textures)[m].empty()) {
          return under;
        }
        Eigen::Vector2d uv = Eigen::Vector2d::Zero();
        for (int i = 0; i < 3; ++i) {
          uv += b[i] * mesh.texcoords[mesh.corner_texcoords[corners[i]]];
        }
        const Eigen::Vector4f texel = sample((*prepared.textures)[m], uv, ImageWrap::Repeat);
        // Straight alpha: the texel covers the material colour by its alpha.
        return texel.head<3>() * texel.w() + under * (1.0f - texel.w());
      }
      case SurfaceColoring::Materials:
        return material_color(prepared, face);
      case SurfaceColoring::Auto:
      case SurfaceColoring::Plain:
        break;
    }
    return prepared.object->look.plain_color;
  }

  void attach(RTCGeometry geometry, int object, bool curve) {
    rtcCommitGeometry(geometry);
    const unsigned id = rtcAttachGeometry((curve ? wires_ : surfaces_).get(), geometry);
    rtcReleaseGeometry(geometry);
    std::vector<int>& objects = curve ? wire_objects_ : surface_objects_;
    if (objects.size() <= id) {
      objects.resize(id + 1, -1);
    }
    objects[id] = object;
  }

  void add_triangles(int k) {
    PreparedObject& prepared = prepared_[static_cast<size_t>(k)];
    const PolygonMesh& mesh = prepared.object->mesh;
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const int first = mesh.face_offsets[f];
      for (int j = 1; j + 1 < mesh.face_size(f); ++j) {
        prepared.triangle_corners.push_back({first, first + j, first + j + 1});
        prepared.triangle_face.push_back(f);
      }
    }
    if (prepared.triangle_corners.empty()) {
      return;
    }
    RTCGeometry geometry = rtcNewGeometry(device_.get(), RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), mesh.positions.size()));
    auto* indices = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(unsigned), prepared.triangle_corners.size()));
    if (!vertices || !indices) {
      rtcReleaseGeometry(geometry);
      check_embree(device_.get(), "render", "allocate triangles");
      throw Error("render", "Embree could not allocate the triangles of " + object_name(k));
    }
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
      const Eigen::Vector3f p = to_float(mesh.positions[v] - shift_);
      for (int c = 0; c < 3; ++c) {
        vertices[3 * v + c] = p[c];
      }
    }
    for (size_t t = 0; t < prepared.triangle_corners.size(); ++t) {
      for (int c = 0; c < 3; ++c) {
        indices[3 * t + c] =
            static_cast<unsigned>(mesh.face_vertices[prepared.triangle_corners[t][c]]);
      }
    }
    attach(geometry, k, false);
  }

  void add_curves(int k) {
    PreparedObject& prepared = prepared_[static_cast<size_t>(k)];
    const PolygonMesh& mesh = prepared.object->mesh;
    prepared.wire_edges = polygon_edges(mesh);
    const std::vector<std::pair<int, int>>& edges = prepared.wire_edges;
    if (edges.empty()) {
      return;
    }
    // One two-vertex round linear curve (a capsule-like tube) per edge: vertices (x, y, z, radius).
    RTCGeometry geometry = rtcNewGeometry(device_.get(), RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                4 * sizeof(float), 2 * edges.size()));
    auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
        geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(unsigned), edges.size()));
    if (!vertices || !indices) {
      rtcReleaseGeometry(geometry);
      check_embree(device_.get(), "render", "allocate curves");
      throw Error("render", "Embree could not allocate the edges of " + object_name(k));
    }
    const auto radius = static_cast<float>(prepared.wire_radius);
    for (size_t e = 0; e < edges.size(); ++e) {
      const Eigen::Vector3f a = to_float(mesh.positions[edges[e].first] - shift_);
      const Eigen::Vector3f b = to_float(mesh.positions[edges[e].second] - shift_);
      float* out = vertices + 8 * e;
      for (int c = 0; c < 3; ++c) {
        out[c] = a[c];
        out[4 + c] = b[c];
      }
      out[3] = radius;
      out[7] = radius;
      indices[e] = static_cast<unsigned>(2 * e);
    }
    attach(geometry, k, true);
  }

  EmbreeDevice device_{"render"};
  const Camera& camera_;
  const RenderOptions& options_;
  CameraFrame frame_;
  EmbreeScene surfaces_;  // the objects' triangles
  EmbreeScene wires_;     // the wireframe tubes
  float wire_slack_ = 0.0f;
  Eigen::Vector3d shift_ = Eigen::Vector3d::Zero();
  double diagonal_ = 1.0;
  Eigen::Vector3d key_ = Eigen::Vector3d::UnitZ();
  std::vector<PreparedObject> prepared_;
  std::vector<int> surface_objects_;  // object of each geometry ID in surfaces_
  std::vector<int> wire_objects_;     // object of each geometry ID in wires_
};

void check_options(const RenderOptions& options) {
  const auto bad = [](const std::string& what) { throw InvalidInputError("render", what); };
  if (options.samples_per_pixel < 1 || options.samples_per_pixel > 256) {
    bad("samples per pixel " + std::to_string(options.samples_per_pixel) + " is outside 1..256");
  }
  if (!(options.adaptive_threshold >= 0.0 && options.adaptive_threshold <= 1.0)) {
    bad("adaptive threshold " + std::to_string(options.adaptive_threshold) + " is outside 0..1");
  }
  if (options.ambient_occlusion_samples < 0 || options.ambient_occlusion_samples > 256) {
    bad("ambient occlusion samples " + std::to_string(options.ambient_occlusion_samples) +
        " is outside 0..256");
  }
  if (options.ambient_occlusion_samples > 0 && !(options.ambient_occlusion_radius > 0.0)) {
    bad("ambient occlusion radius must be positive");
  }
  if (!options.key_light_direction.allFinite() || !(options.key_light_direction.norm() > 0.0)) {
    bad("key light direction is zero or not finite");
  }
  if (!std::isfinite(options.ambient) || !std::isfinite(options.headlight) ||
      !std::isfinite(options.key_light)) {
    bad("light intensities must be finite");
  }
  if (!(options.wire_depth_tolerance >= 0.0) || !std::isfinite(options.wire_depth_tolerance)) {
    bad("wire depth tolerance must be a finite number >= 0");
  }
  if (options.threads < 0) {
    bad("thread count " + std::to_string(options.threads) + " is negative");
  }
}

}  // namespace

Eigen::AlignedBox3d bounding_box(const PolygonMesh& mesh) {
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& p : mesh.positions) {
    box.extend(p);
  }
  return box;
}

Eigen::AlignedBox3d bounding_box(const Scene& scene) {
  Eigen::AlignedBox3d box;
  for (const SceneObject& object : scene.objects) {
    box.extend(bounding_box(object.mesh));
  }
  return box;
}

Eigen::Vector3d vector_area(const PolygonMesh& mesh) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int f = 0; f < mesh.num_faces(); ++f) {
    sum += newell_normal(mesh, f);
  }
  return 0.5 * sum;
}

MaterialTextures load_material_textures(const PolygonMesh& mesh,
                                        const ImageReadOptions& read_options) {
  MaterialTextures result;
  for (const Material& material : mesh.materials) {
    Image image;
    if (!material.diffuse_texture.empty()) {
      try {
        image = read_image(material.diffuse_texture, read_options);
      } catch (const Error& e) {
        result.warnings.push_back(e.what());
      }
    }
    result.images.push_back(std::move(image));
  }
  return result;
}

namespace {

constexpr int kTile = 16;

/// Calls f(x, y) for every pixel, in parallel over 16 x 16 tiles (each pixel by one task).
template <typename F>
void for_pixels(const Camera& camera, const F& f) {
  const int tiles_x = (camera.width + kTile - 1) / kTile;
  const int tiles_y = (camera.height + kTile - 1) / kTile;
  tbb::parallel_for(tbb::blocked_range<int>(0, tiles_x * tiles_y), [&](const auto& range) {
    for (int tile = range.begin(); tile != range.end(); ++tile) {
      const int x0 = (tile % tiles_x) * kTile, y0 = (tile / tiles_x) * kTile;
      for (int y = y0; y < std::min(y0 + kTile, camera.height); ++y) {
        for (int x = x0; x < std::min(x0 + kTile, camera.width); ++x) {
          f(x, y);
        }
      }
    }
  });
}

/// Whether pixel (x, y) needs all its rays: a wire may touch it, or it or a neighbour (8-connected)
/// sees something else at its centre, or their centre colours differ by more than `threshold` in
/// a channel.
bool needs_all_rays(int x, int y, int width, int height, const std::vector<Eigen::Vector4f>& centre,
                    const std::vector<int>& seen, const std::vector<unsigned char>& busy,
                    float threshold) {
  const auto at = [&](int px, int py) {
    return static_cast<size_t>(py) * static_cast<size_t>(width) + static_cast<size_t>(px);
  };
  const size_t here = at(x, y);
  if (busy[here] != 0) {
    return true;
  }
  for (int ny = std::max(y - 1, 0); ny <= std::min(y + 1, height - 1); ++ny) {
    for (int nx = std::max(x - 1, 0); nx <= std::min(x + 1, width - 1); ++nx) {
      const size_t there = at(nx, ny);
      if (seen[there] != seen[here] ||
          (centre[there] - centre[here]).cwiseAbs().maxCoeff() > threshold) {
        return true;
      }
    }
  }
  return false;
}

}  // namespace

Image render(const Scene& scene, const Camera& camera, const RenderOptions& options) {
  check_options(options);
  const int arena_threads = options.threads > 0 ? options.threads : tbb::task_arena::automatic;
  tbb::task_arena arena(arena_threads);
  Image image;
  arena.execute([&] {
    const Tracer tracer(scene, camera, options);
    image = Image(camera.width, camera.height);
    const int samples = options.samples_per_pixel;
    // Stratify on a k x k grid when the sample count is a perfect square.
    const auto root = static_cast<int>(std::lround(std::sqrt(static_cast<double>(samples))));
    const bool stratified = root * root == samples;
    const auto index = [&](int x, int y) {
      return static_cast<std::uint64_t>(y) * static_cast<std::uint64_t>(camera.width) +
             static_cast<std::uint64_t>(x);
    };
    // Back from premultiplied alpha to the straight alpha Image stores.
    const auto store = [&](int x, int y, Eigen::Vector4f average) {
      if (average.w() > 0.0f) {
        average.head<3>() /= average.w();
      }
      image.at(x, y) = average.cwiseMax(0.0f).cwiseMin(1.0f);
    };
    // All `samples` jittered rays of a pixel, averaged.
    const auto all_rays = [&](int x, int y) {
      const std::uint64_t pixel = index(x, y);
      Eigen::Vector4f sum = Eigen::Vector4f::Zero();
      for (int s = 0; s < samples; ++s) {
        SampleRandom jitter(options.seed, pixel, static_cast<std::uint64_t>(s), 0);
        SampleRandom shading(options.seed, pixel, static_cast<std::uint64_t>(s), 1);
        double jx = jitter.next(), jy = jitter.next();
        if (stratified) {
          // Stratum (column, row) = (s mod root, s div root).
          const int column = s % root, row = s / root;
          jx = (column + jx) / root;
          jy = (row + jy) / root;
        }
        sum += tracer.trace(x + jx, y + jy, shading);
      }
      return Eigen::Vector4f(sum / static_cast<float>(samples));
    };
    if (samples == 1 || !(options.adaptive_threshold > 0.0)) {
      for_pixels(camera, [&](int x, int y) { store(x, y, all_rays(x, y)); });
      return;
    }
    // Adaptive antialiasing (see RenderOptions::adaptive_threshold): one ray through every pixel
    // centre first (its own random stream, sample number `samples`), then all rays where needed.
    const size_t count = static_cast<size_t>(camera.width) * static_cast<size_t>(camera.height);
    std::vector<Eigen::Vector4f> centre(count);
    std::vector<int> seen(count);
    for_pixels(camera, [&](int x, int y) {
      const std::uint64_t pixel = index(x, y);
      SampleRandom shading(options.seed, pixel, static_cast<std::uint64_t>(samples), 1);
      centre[pixel] = tracer.trace(x + 0.5, y + 0.5, shading, &seen[pixel]);
    });
    std::vector<unsigned char> busy(count, 0);
    tracer.mark_wires(busy);
    const auto threshold = static_cast<float>(options.adaptive_threshold);
    for_pixels(camera, [&](int x, int y) {
      const bool all =
          needs_all_rays(x, y, camera.width, camera.height, centre, seen, busy, threshold);
      store(x, y, all ? all_rays(x, y) : centre[index(x, y)]);
    });
  });
  return image;
}

}  // namespace elastic
