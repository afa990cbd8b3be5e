// Colour transfer: colour sources, the refined target, the painted surface, decal, bake, PLY.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

#include "elastic/core/error.h"
#include "elastic/image/image.h"
#include "elastic/mapping/map_regions.h"
#include "elastic/mesh/default_material.h"
#include "elastic/mesh/mesh_io.h"
#include "elastic/regions/image_source.h"
#include "elastic/regions/region_spec.h"
#include "elastic/regions/surface_partition.h"
#include "elastic/regions/texture_coordinates.h"
#include "elastic/shapes/procedural_shapes.h"
#include "elastic/surface/limit_tessellation.h"
#include "elastic/transfer/bake.h"
#include "elastic/transfer/color_source.h"
#include "elastic/transfer/output_folder.h"
#include "elastic/transfer/painted_surface.h"
#include "elastic/transfer/target_samples.h"
#include "rigid_motion.h"
#include "support.h"

namespace elastic {
namespace {

// Everything a mapping references, kept alive together.
struct MappedPair {
  std::unique_ptr<LimitSurface> source_surface, target_surface;
  std::unique_ptr<SurfaceProjector> source, target;
  std::unique_ptr<Region> from, to;
  std::unique_ptr<MapResult> result;

  MappedPair(const PolygonMesh& source_mesh, const RegionSpec& source_spec,
             const PolygonMesh& target_mesh, const RegionSpec& target_spec, int particles) {
    source_surface = std::make_unique<LimitSurface>(source_mesh);
    target_surface = std::make_unique<LimitSurface>(target_mesh);
    source = std::make_unique<SurfaceProjector>(*source_surface);
    target = std::make_unique<SurfaceProjector>(*target_surface);
    from = std::make_unique<Region>(make_region(*source, source_spec));
    to = std::make_unique<Region>(make_region(*target, target_spec));
    MapOptions options;
    options.sampling.layout.particles = particles;
    result = std::make_unique<MapResult>(map_regions(*source, *from, *target, *to, options));
  }
  const Mapping& mapping() const { return result->mapping; }
  // Sampling options that resolve boundaries by arc length and relinearise in 3D.
  TargetSamplingOptions sampling() const {
    TargetSamplingOptions options;
    options.source_region = from.get();
    options.source_particles = result->sampling.grid.source_positions();
    options.target_particles = result->relaxation.positions;
    return options;
  }
};

// A linear colour field of position, inside [0,1] on the plane [-1,1]^2.
Eigen::Vector3f linear_color(const Eigen::Vector3d& x) {
  return Eigen::Vector3f(static_cast<float>(0.5 + 0.3 * x.x()),
                         static_cast<float>(0.5 + 0.2 * x.y() - 0.1 * x.x()),
                         static_cast<float>(0.4 + 0.25 * x.y()));
}

PolygonMesh plane_with_linear_colors() {
  PolygonMesh plane = make_plane({.faces = ShapeFaces::Quads, .resolution = 8});
  for (const Eigen::Vector3d& x : plane.positions) plane.vertex_colors.push_back(linear_color(x));
  return plane;
}

// A rigidly moved disk onto itself: the reference map is the rigid motion.
std::unique_ptr<MappedPair> rigid_disk_pair(const PolygonMesh& plane,
                                            const Eigen::Isometry3d& motion) {
  RegionSpec source_spec = parse_region_spec("disk:0.1,0.05,0,0.6");
  source_spec.anchor = Eigen::Vector3d(1, 0, 0);
  RegionSpec target_spec = source_spec;
  target_spec.center = motion * source_spec.center;
  target_spec.anchor = motion * *source_spec.anchor;
  return std::make_unique<MappedPair>(plane, source_spec, test::moved(plane, motion), target_spec,
                                      400);
}

// ---------------------------------------------------------------------------------------------
// Interpolation of per-vertex values.

TEST(PaintControlWeights, SumToOneAndReproduceLinearFieldsOnAPlanarGrid) {
  // Quads, triangles (Loop) and a pentagon (n-gon sub-faces).
  PolygonMesh penta;
  for (int k = 0; k < 5; ++k) {
    const double a = 2.0 * 3.14159265358979 * k / 5.0;
    penta.positions.emplace_back(std::cos(a), std::sin(a), 0.0);
  }
  penta.add_face({0, 1, 2, 3, 4});
  const std::vector<PolygonMesh> meshes = {
      make_plane({.faces = ShapeFaces::Quads, .resolution = 4}),
      make_plane({.faces = ShapeFaces::Triangles, .resolution = 4}), penta};
  for (const PolygonMesh& mesh : meshes) {
    const LimitSurface surface(mesh);
    std::vector<double> values;
    for (const Eigen::Vector3d& x : mesh.positions)
      values.push_back(2.0 * x.x() - 3.0 * x.y() + 1.0);
    for (int f = 0; f < surface.num_faces(); ++f) {
      for (const Eigen::Vector2d& uv : {Eigen::Vector2d(0.2, 0.3), Eigen::Vector2d(0.5, 0.1)}) {
        const SurfacePoint p{f, uv.x(), uv.y()};
        double sum = 0.0;
        for (const auto& [v, w] : control_vertex_weights(surface, p)) sum += w;
        EXPECT_NEAR(sum, 1.0, 1e-14);
        // The same weights on the positions give the control face's interpolated point; a linear
        // field of position must equal the field at that point (linear precision, round-off).
        Eigen::Vector3d x = Eigen::Vector3d::Zero();
        for (const auto& [v, w] : control_vertex_weights(surface, p)) x += w * mesh.positions[v];
        EXPECT_NEAR(interpolate_vertex_scalar(surface, values, p), 2.0 * x.x() - 3.0 * x.y() + 1.0,
                    1e-13);
      }
    }
  }
}

TEST(PaintControlWeights, OnAUniformPlaneTheFieldFollowsTheLimitPosition) {
  // The uniform planar grid's limit surface is the bilinear image of each face (B-splines
  // reproduce linear functions), so the interpolated field is the field at the limit point.
  const PolygonMesh plane = plane_with_linear_colors();
  const LimitSurface surface(plane);
  const ColorSource colors = ColorSource::vertex_colors(surface);
  for (int f = 0; f < surface.num_faces(); f += 3) {
    const SurfacePoint p{f, 0.3, 0.7};
    const Eigen::Vector4f c = colors.color(p);
    // float storage of the colours: 1e-6.
    EXPECT_LT((c.head<3>() - linear_color(surface.position(p))).norm(), 1e-6f) << "face " << f;
    EXPECT_EQ(c.w(), 1.0f);
  }
}

TEST(PaintColorSource, RejectsSourcesWithoutTheData) {
  const LimitSurface plane(make_plane({.resolution = 4}));
  EXPECT_THROW(ColorSource::vertex_colors(plane), InvalidInputError);
  EXPECT_THROW(ColorSource::texture(plane), InvalidInputError);  // no UVs
  EXPECT_THROW(ColorSource::vertex_scalars(plane, {1.0, 2.0}, 0.0, 1.0), InvalidInputError);
  const std::vector<double> values(static_cast<size_t>(plane.control_mesh().num_vertices()), 0.5);
  EXPECT_THROW(ColorSource::vertex_scalars(plane, values, 1.0, 1.0), InvalidInputError);
  const ColorSource grey = ColorSource::vertex_scalars(plane, values, 0.0, 1.0);
  EXPECT_FLOAT_EQ(grey.color(SurfacePoint{0, 0.5, 0.5}).x(), 0.5f);
}

// ---------------------------------------------------------------------------------------------
// The refined target and its source locations.

TEST(PaintTransfer, LinearColourArrivesExactlyAtParticlesAndInterpolatedBetween) {
  const PolygonMesh plane = plane_with_linear_colors();
  const Eigen::Isometry3d motion = test::rigid_motion();
  const auto pair = rigid_disk_pair(plane, motion);
  const ColorSource colors = ColorSource::vertex_colors(*pair->source_surface);

  // At the particles: the field's value at their source positions (float round-off).
  const ParticleGrid& grid = pair->result->sampling.grid;
  for (int i = 0; i < grid.num_particles(); ++i) {
    const Eigen::Vector3d x = pair->source_surface->position(grid.source_points[i]);
    EXPECT_LT((colors.color(grid.source_points[i]).head<3>() - linear_color(x)).norm(), 1e-6f);
  }

  TargetSamplingOptions options = pair->sampling();
  options.max_edge = 0.05;
  const TargetSamples samples = sample_target(*pair->to, pair->mapping(), options);
  EXPECT_GE(samples.levels, 1);
  EXPECT_LE(samples.max_edge_length, 0.05);
  EXPECT_EQ(samples.unresolved, 0);
  const std::vector<Eigen::Vector4f> transferred = transfer_colors(samples, colors);
  // Between particles: the colour is the particles' colours interpolated with the vertex's
  // weights in its grid triangle (the source is flat, so the relinearised source point is the
  // same combination of the particles' positions and the field is linear).
  int interpolated = 0;
  for (int i = 0; i < samples.num_vertices(); ++i) {
    const Mapping::Location& loc = samples.sources[i];
    if (loc.triangle < 0) continue;
    const Eigen::Vector3i& tri = pair->mapping().triangles()[loc.triangle];
    Eigen::Vector3f expected = Eigen::Vector3f::Zero();
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d s = pair->source_surface->position(grid.source_points[tri[k]]);
      expected += static_cast<float>(loc.barycentric[k]) * linear_color(s);
    }
    EXPECT_LT((transferred[i].head<3>() - expected).norm(), 1e-6f) << "vertex " << i;
    ++interpolated;
  }
  EXPECT_GT(interpolated, samples.num_vertices() / 2);
  // The map is the rigid motion (1e-8, see the mapping tests), so every refined vertex, between
  // particles or on the boundary, gets the field at its pre-image. The colour field has slope
  // < 0.4, so 1e-6 covers float storage and the map's error.
  for (int i = 0; i < samples.num_vertices(); ++i) {
    const Eigen::Vector3d preimage = motion.inverse() * samples.positions[i];
    EXPECT_LT((transferred[i].head<3>() - linear_color(preimage)).norm(), 1e-6f) << "vertex " << i;
  }
  // Every vertex is on the target limit surface, with a unit normal.
  for (int i = 0; i < samples.num_vertices(); i += 7) {
    EXPECT_LT((pair->target_surface->position(samples.points[i]) - samples.positions[i]).norm(),
              1e-12);
    EXPECT_NEAR(samples.normals[i].norm(), 1.0, 1e-12);
  }
}

TEST(PaintTransfer, RefinementKeepsTheBoundaryOnTheCurveAndConforms) {
  const PolygonMesh plane = make_plane({.resolution = 8});
  const auto pair = rigid_disk_pair(plane, test::rigid_motion());
  TargetSamplingOptions options = pair->sampling();
  options.max_edge = 0.04;
  const TargetSamples s = sample_target(*pair->to, pair->mapping(), options);
  // Euler characteristic 1 and each edge used once (boundary) or twice: a conforming disk.
  std::map<std::pair<int, int>, int> edges;
  for (const Eigen::Vector3i& t : s.triangles) {
    for (int k = 0; k < 3; ++k)
      ++edges[{std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])}];
  }
  int boundary_edges = 0;
  for (const auto& [e, n] : edges) {
    EXPECT_LE(n, 2);
    boundary_edges += n == 1;
  }
  EXPECT_EQ(s.num_vertices() - static_cast<int>(edges.size()) + s.num_triangles(), 1);
  EXPECT_EQ(boundary_edges, static_cast<int>(s.boundary.size()));
  // A 1-to-4 split quadruples the triangles per level.
  EXPECT_EQ(s.num_triangles(), pair->to->num_triangles() << (2 * s.levels));
  // Boundary vertices lie on the region's circle (radius 0.6 around the centre, moved rigidly):
  // the cut's curve is the heat-method circle within about 1% of the radius (docs/regions.md);
  // what matters here is that refined boundary vertices stay on the chords' (u,v) lines, i.e. as
  // close to the circle as the coarse ones.
  const Eigen::Vector3d centre = test::rigid_motion() * Eigen::Vector3d(0.1, 0.05, 0);
  double coarse_error = 0.0, fine_error = 0.0;
  for (int v : pair->to->boundary) {
    coarse_error = std::max(coarse_error, std::abs((pair->to->positions[v] - centre).norm() - 0.6));
  }
  for (int v : s.boundary) {
    EXPECT_TRUE(s.on_boundary[v]);
    fine_error = std::max(fine_error, std::abs((s.positions[v] - centre).norm() - 0.6));
  }
  EXPECT_LE(fine_error, coarse_error + 1e-12);
}

TEST(PaintTransfer, SourceTexelLengthOfAnImagePlane) {
  const auto dir = test::scratch_dir("texel");
  write_png(dir / "img.png", Image(64, 32, Eigen::Vector4f(0.2f, 0.4f, 0.6f, 1.0f)));
  const ImagePlane plane = make_image_plane(dir / "img.png", {.width = 2.0, .resolution = 8});
  const LimitSurface surface(plane.mesh);
  const SurfaceProjector projector(surface);
  const Region region = make_region(projector, plane.region);
  // The plane is 2 x 1 for 64 x 32 texels: texels are 1/32 square.
  EXPECT_NEAR(source_texel_length(region, 64, 32), 1.0 / 32.0, 1e-12);
}

// ---------------------------------------------------------------------------------------------
// The painted surface: partition + refinement + fans.

TEST(PaintSurface, ClosedTargetStaysClosedAndAreasAddUp) {
  // A sphere (closed): the painted mesh must be watertight, every edge shared by two triangles,
  // also where outside triangles were fanned against the refined boundary.
  const PolygonMesh sphere = make_sphere({.resolution = 16});
  RegionSpec spec = parse_region_spec("disk:0,0,1,0.7");
  MappedPair pair(sphere, spec, sphere, spec, 300);
  PaintedSurfaceOptions options;
  options.resolution = 6;
  options.sampling = pair.sampling();
  options.sampling.max_edge = 0.03;
  const PaintedSurface painted =
      paint_surface(*pair.target_surface, *pair.to, pair.mapping(), options);
  ASSERT_GE(painted.samples.levels, 1);
  EXPECT_EQ(painted.resolution, 6);
  std::map<std::pair<int, int>, int> edges;
  for (const Eigen::Vector3i& t : painted.triangles) {
    for (int k = 0; k < 3; ++k)
      ++edges[{std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3])}];
  }
  int bad = 0;
  for (const auto& [e, n] : edges) bad += n != 2;
  EXPECT_EQ(bad, 0) << "edges not shared by exactly two triangles";
  EXPECT_EQ(painted.num_vertices() - static_cast<int>(edges.size()) + painted.num_triangles(), 2);
  // Every vertex is on the limit surface.
  for (int v = 0; v < painted.num_vertices(); v += 5) {
    EXPECT_LT((pair.target_surface->position(painted.points[v]) - painted.positions[v]).norm(),
              1e-12);
  }
  // Inside area: the region's, up to the finer refinement's chord error (the refined triangles
  // lie closer to the sphere; the coarse region's flat triangles at resolution 6 are inside it by
  // about h^2/8 ~ 1e-3 relative).
  double inside = 0.0;
  for (int t = 0; t < painted.num_triangles(); ++t) {
    if (!painted.triangle_inside[t]) continue;
    const Eigen::Vector3i& c = painted.triangles[t];
    inside += 0.5 * (painted.positions[c[1]] - painted.positions[c[0]])
                        .cross(painted.positions[c[2]] - painted.positions[c[0]])
                        .norm();
  }
  EXPECT_NEAR(inside, pair.to->area(), 0.01 * pair.to->area());
}

TEST(PaintSurface, AutoTessellationFollowsTheTargetsSize) {
  // The default (resolution 0) aims at 2^18 triangles for the whole target, at most 8 segments per
  // edge: a Loop plane of 2 N^2 triangles needs sqrt(2^18 / (2 N^2)) segments.
  EXPECT_EQ(kAutoTargetTriangles, 262'144);
  const LimitSurface coarse(make_plane({.faces = ShapeFaces::Triangles, .resolution = 4}));
  EXPECT_EQ(auto_target_resolution(coarse), 8);  // sqrt(2^18 / 32) = 90.5, capped
  const LimitSurface dense(make_plane({.faces = ShapeFaces::Triangles, .resolution = 128}));
  EXPECT_EQ(auto_target_resolution(dense), 3);  // sqrt(2^18 / 32768) = 2.83
  // Catmull-Clark quads count two triangles each: 128^2 quads, the same 2.83.
  const LimitSurface quads(make_plane({.faces = ShapeFaces::Quads, .resolution = 128}));
  EXPECT_EQ(auto_target_resolution(quads), 3);
  const LimitSurface huge(make_plane({.faces = ShapeFaces::Quads, .resolution = 300}));
  EXPECT_EQ(auto_target_resolution(huge), 1);  // sqrt(2^18 / 180,000) = 1.2
}

TEST(PaintSurface, PartitionSharesTheCurveAndKeepsTheAnchor) {
  const LimitSurface surface(make_cap({.resolution = 12}));
  const SurfaceProjector projector(surface);
  RegionSpec spec = parse_region_spec("disk:0,0,1,0.5");
  spec.anchor = Eigen::Vector3d(1, 0, 0.5);
  const Region region = make_region(projector, spec);
  // Re-cut at another resolution: every original boundary point is on the new boundary.
  const LimitTessellation tess = tessellate(surface, {.resolution = 5});
  const SurfacePartition part = partition_surface(surface, tess, region);
  ASSERT_EQ(part.inside_vertices.size(), part.inside.points.size());
  for (size_t i = 0; i < part.inside_vertices.size(); ++i) {
    EXPECT_EQ((part.positions[part.inside_vertices[i]] - part.inside.positions[i]).norm(), 0.0);
  }
  const SurfaceCurve fine = part.inside.boundary_curve();
  for (int v : region.boundary) {
    double best = 1e9;
    for (const Eigen::Vector3d& x : fine.positions)
      best = std::min(best, (x - region.positions[v]).norm());
    // The snap moves a point by at most 1e-6 of a tessellation edge (~0.1 here).
    EXPECT_LT(best, 1e-6);
  }
  // The anchor is the re-cut curve's point nearest to the original anchor, which lies on an
  // original chord; the polylines differ by the chords' sagitta, h^2 / (8 R) ~ 1.3e-3 for the
  // ~0.1 boundary spacing on the unit sphere.
  EXPECT_LT((fine.locate(0.0).position - region.boundary_curve().locate(0.0).position).norm(),
            2e-3);
  // Inside + outside cover the whole parameter domain: in (u, v) the cut is a planar subdivision
  // of each ptex face, so the triangles' (u, v) areas add up to the faces' (1 each for
  // Catmull-Clark) up to round-off. (3D areas do not add up: split points lie on the limit
  // surface, off the flat triangles.)
  auto uv_area = [](const std::array<Eigen::Vector2d, 3>& t) {
    const Eigen::Vector2d e1 = t[1] - t[0], e2 = t[2] - t[0];
    return 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
  };
  double total = 0.0;
  for (const auto& t : part.inside.triangle_uv) total += uv_area(t);
  for (const auto& t : part.outside_uv) total += uv_area(t);
  EXPECT_NEAR(total, surface.num_faces(), 1e-9);
}

// ---------------------------------------------------------------------------------------------
// Texture transfer, decal, bake, PLY.

std::string file_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

Image checker(int width, int height, int cell) {
  Image image(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const bool odd = ((x / cell) + (y / cell)) % 2 == 1;
      image.at(x, y) =
          odd ? Eigen::Vector4f(0.9f, 0.1f, 0.2f, 1.0f) : Eigen::Vector4f(0.1f, 0.3f, 0.95f, 1.0f);
    }
  }
  return image;
}

// Image plane -> rigidly moved copy of itself, whole rectangle: the reference map is the rigid
// motion, and the target's own texture coordinates are the source's at the pre-image.
struct TexturedPair {
  std::filesystem::path dir;
  Image source_image;
  ImagePlane plane;
  std::unique_ptr<MappedPair> pair;
  explicit TexturedPair(const std::string& name) {
    dir = test::scratch_dir(name);
    write_png(dir / "source.png", checker(32, 32, 4));
    source_image = read_image(dir / "source.png");  // as the source reads it: 8-bit values
    plane = make_image_plane(dir / "source.png", {.width = 2.0, .resolution = 8});
    // Congruent anchors at the image's bottom-left corner (the automatic anchor depends on the
    // world axes, which the motion turns).
    RegionSpec source_spec = plane.region;
    source_spec.anchor = Eigen::Vector3d(-1, -1, 0);
    RegionSpec target_spec = plane.region;
    target_spec.anchor = test::rigid_motion() * *source_spec.anchor;
    pair = std::make_unique<MappedPair>(
        plane.mesh, source_spec, test::moved(plane.mesh, test::rigid_motion()), target_spec, 400);
  }
};

TEST(PaintTexture, RigidPlaneMapTransfersTheTextureUnchanged) {
  TexturedPair t("rigid_texture");
  const ColorSource source = ColorSource::texture(*t.pair->source_surface);
  TargetSamplingOptions options = t.pair->sampling();
  options.max_source_edge = source_texel_length(*t.pair->from, 32, 32);
  const TargetSamples samples = sample_target(*t.pair->to, t.pair->mapping(), options);
  EXPECT_EQ(samples.unresolved, 0);
  // Bake into a blank texture of the same size: the target's texture space is the source's, so
  // every texel must come back as the source texel (texel centres sample pixel centres exactly,
  // up to the map's 1e-8 error times the checker's jump inside a bilinear cell: none at centres).
  const Image blank(32, 32, Eigen::Vector4f(0, 0, 0, 1));
  const BakeResult baked = bake_texture(samples, *t.pair->target_surface, source, blank);
  EXPECT_EQ(baked.texels_painted, 32 * 32);
  float worst = 0.0f;
  for (size_t i = 0; i < blank.pixels.size(); ++i) {
    worst =
        std::max(worst, (baked.image.pixels[i] - t.source_image.pixels[i]).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(worst, 1e-5f);
}

TEST(PaintTexture, DecalFilesReadBackWithTheDecalMaterialAndUnitUvs) {
  TexturedPair t("decal");
  // Target: a larger plane (so there is an outside), region = a disk inside the moved image
  // plane's copy: use the image plane itself as target with an ellipse region.
  const ColorSource source = ColorSource::texture(*t.pair->source_surface);
  PaintedSurfaceOptions options;
  options.resolution = 8;
  options.sampling = t.pair->sampling();
  options.sampling.max_edge = 0.1;
  const PaintedSurface painted =
      paint_surface(*t.pair->target_surface, *t.pair->to, t.pair->mapping(), options);
  const auto files = write_decal(t.dir / "decal.obj", painted, source);
  // obj, mtl, the decal png, and the target's own texture copied in (the moved image plane's
  // material names source.png, which already lies in this folder: used where it is).
  ASSERT_EQ(files.size(), 4u);
  EXPECT_EQ(files[3], t.dir / "source.png");
  for (const auto& f : files) EXPECT_TRUE(std::filesystem::exists(f)) << f;

  const PolygonMesh written = make_decal_mesh(painted, source, {.texture_path = files[2]});
  const PolygonMesh read = read_mesh(files[0]).mesh;
  ASSERT_EQ(read.num_faces(), written.num_faces());
  ASSERT_EQ(read.num_vertices(), written.num_vertices());
  for (int v = 0; v < read.num_vertices(); ++v) {
    EXPECT_EQ(read.positions[v], written.positions[v]);  // shortest round-trip decimal
  }
  int decal = -1;
  for (size_t m = 0; m < read.materials.size(); ++m) {
    if (read.materials[m].name == "decal") decal = static_cast<int>(m);
  }
  ASSERT_GE(decal, 0);
  EXPECT_EQ(std::filesystem::weakly_canonical(read.materials[decal].diffuse_texture),
            std::filesystem::weakly_canonical(files[2]));
  const Image png = read_image(files[2]);
  EXPECT_EQ(png.width, 32);
  int region_faces = 0;
  for (int f = 0; f < read.num_faces(); ++f) {
    if (read.face_materials[f] != decal) continue;
    ++region_faces;
    for (int k = 0; k < 3; ++k) {
      const int corner = read.face_offsets[f] + k;
      const Eigen::Vector2d uv = read.texcoords[read.corner_texcoords[corner]];
      EXPECT_GE(uv.minCoeff(), -1e-9);
      EXPECT_LE(uv.maxCoeff(), 1.0 + 1e-9);
      // Rigid map between copies of the same plane: the decal's UV at a vertex is the target's
      // own UV there (1e-7: the map's 1e-8 over a plane 2 wide).
      const SurfacePoint p = painted.points[read.face_vertices[corner]];
      EXPECT_LT((uv - texture_coordinate(*t.pair->target_surface, p)).norm(), 1e-7);
    }
  }
  EXPECT_EQ(region_faces, painted.samples.num_triangles());
}

TEST(PaintBake, CheckerChangesOnlyTexelsInsideTheRegionAndLeavesTheInputFile) {
  TexturedPair t("bake_checker");
  // Target: a plane with UVs and its own grey texture; region: a disk of radius 0.5 at the origin
  // (texture space: a circle of radius 0.25 around (0.5, 0.5) on the 2 x 2 plane).
  const std::filesystem::path grey_png = t.dir / "grey.png";
  write_png(grey_png, Image(64, 64, Eigen::Vector4f(0.5f, 0.5f, 0.5f, 1.0f)));
  const ImagePlane target_plane = make_image_plane(grey_png, {.width = 2.0, .resolution = 8});
  const LimitSurface target_surface(target_plane.mesh);
  const SurfaceProjector target(target_surface);
  const Region to = make_region(target, parse_region_spec("disk:0,0,0,0.5"));
  MapOptions map_options;
  map_options.sampling.layout.particles = 300;
  const MapResult result = map_regions(*t.pair->source, *t.pair->from, target, to, map_options);

  const std::string before = file_bytes(grey_png);
  const ColorSource source = ColorSource::texture(*t.pair->source_surface);
  const Image target_image =
      read_image(target_surface.control_mesh().materials.at(0).diffuse_texture);
  TargetSamplingOptions options;
  options.source_region = t.pair->from.get();
  options.source_particles = result.sampling.grid.source_positions();
  options.target_particles = result.relaxation.positions;
  options.max_edge = 0.05;
  const TargetSamples samples = sample_target(to, result.mapping, options);
  const BakeResult baked = bake_texture(samples, target_surface, source, target_image);
  write_png(t.dir / "baked.png", baked.image);

  // Classify texels by their centre's distance to the region's boundary polygon in texture space.
  std::vector<Eigen::Vector2d> polygon;
  for (int v : to.boundary) polygon.push_back(to.texcoords[v]);
  auto inside_polygon = [&](const Eigen::Vector2d& p) {
    bool in = false;
    for (size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
      if ((polygon[i].y() > p.y()) != (polygon[j].y() > p.y()) &&
          p.x() < (polygon[j].x() - polygon[i].x()) * (p.y() - polygon[i].y()) /
                          (polygon[j].y() - polygon[i].y()) +
                      polygon[i].x())
        in = !in;
    }
    return in;
  };
  auto distance_to_polygon = [&](const Eigen::Vector2d& p) {
    double best = 1e9;
    for (size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
      const Eigen::Vector2d ab = polygon[i] - polygon[j];
      const double s = std::clamp((p - polygon[j]).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
      best = std::min(best, (p - polygon[j] - s * ab).norm());
    }
    return best;
  };
  int checked_inside = 0, checked_outside = 0;
  const double texel = 1.0 / 64.0;
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      const Eigen::Vector2d uv((x + 0.5) / 64.0, 1.0 - (y + 0.5) / 64.0);
      // The refined boundary differs from the coarse polygon by the refinement's chords (1e-3 of
      // a texel here); a margin of a tenth of a texel keeps the classification unambiguous.
      if (distance_to_polygon(uv) < 0.1 * texel) continue;
      const bool in = inside_polygon(uv);
      const Eigen::Vector4f& got = baked.image.at(x, y);
      if (!in) {
        EXPECT_EQ(got, target_image.at(x, y)) << "outside texel " << x << "," << y;
        ++checked_outside;
      } else {
        // Inside: one of the checker's two colours, or a blend across a checker edge.
        EXPECT_NE(got, target_image.at(x, y)) << "inside texel " << x << "," << y;
        ++checked_inside;
      }
    }
  }
  EXPECT_GT(checked_inside, 500);  // pi (0.25 * 64)^2 ~ 804
  EXPECT_GT(checked_outside, 3000);
  EXPECT_EQ(before, file_bytes(grey_png)) << "the input texture file changed";
  // The written PNG reads back as what was baked (8-bit quantisation: half a step).
  const Image reread = read_image(t.dir / "baked.png");
  for (size_t i = 0; i < reread.pixels.size(); ++i) {
    EXPECT_LE((reread.pixels[i] - baked.image.pixels[i]).cwiseAbs().maxCoeff(),
              0.5f / 255.0f + 1e-6f);
  }
}

TEST(PaintBake, FeatherRampsFromTheBoundaryAndAlphaScales) {
  TexturedPair t("bake_feather");
  const ColorSource source = ColorSource::texture(*t.pair->source_surface);
  const TargetSamplingOptions options = t.pair->sampling();
  const TargetSamples samples = sample_target(*t.pair->to, t.pair->mapping(), options);
  const Image blank(32, 32, Eigen::Vector4f(0, 0, 0, 1));
  // Alpha 0.5, no feather: every texel is half the source.
  const BakeResult half = bake_texture(samples, *t.pair->target_surface, source, blank,
                                       {.alpha = 0.5f, .feather = 0.0});
  for (size_t i = 0; i < blank.pixels.size(); ++i) {
    EXPECT_LT((half.image.pixels[i].head<3>() - 0.5f * t.source_image.pixels[i].head<3>())
                  .cwiseAbs()
                  .maxCoeff(),
              1e-5f);
  }
  // Feather 4 texels on the whole-image region: the boundary is the image's border, so a texel
  // centre at distance d = min(x, y, 31 - x, 31 - y) + 0.5 gets min(d / 4, 1) of the source.
  const BakeResult feathered =
      bake_texture(samples, *t.pair->target_surface, source, blank, {.feather = 4.0});
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 32; ++x) {
      const double d = std::min({x, y, 31 - x, 31 - y}) + 0.5;
      const float w = static_cast<float>(std::min(d / 4.0, 1.0));
      EXPECT_LT((feathered.image.at(x, y).head<3>() - w * t.source_image.at(x, y).head<3>())
                    .cwiseAbs()
                    .maxCoeff(),
                1e-5f)
          << x << "," << y;
    }
  }
  EXPECT_THROW(bake_texture(samples, *t.pair->target_surface, source, blank, {.alpha = 2.0f}),
               InvalidInputError);
}

TEST(PaintPly, ColouredMeshRoundTripsThroughThePlyReader) {
  const PolygonMesh plane = plane_with_linear_colors();
  const auto pair = rigid_disk_pair(plane, test::rigid_motion());
  const ColorSource colors = ColorSource::vertex_colors(*pair->source_surface);
  PaintedSurfaceOptions options;
  options.resolution = 4;
  options.sampling = pair->sampling();
  options.sampling.max_edge = 0.08;
  const PaintedSurface painted =
      paint_surface(*pair->target_surface, *pair->to, pair->mapping(), options);
  const PolygonMesh mesh = make_colored_mesh(painted, colors);
  const auto dir = test::scratch_dir("ply");
  write_mesh(dir / "painted.ply", mesh);
  const PolygonMesh read = read_mesh(dir / "painted.ply").mesh;
  ASSERT_EQ(read.num_vertices(), mesh.num_vertices());
  ASSERT_EQ(read.num_faces(), mesh.num_faces());
  ASSERT_TRUE(read.has_vertex_colors());
  for (int v = 0; v < read.num_vertices(); ++v) {
    EXPECT_EQ(read.positions[v], mesh.positions[v]);
    // 8-bit colours: half a quantisation step.
    EXPECT_LE((read.vertex_colors[v] - mesh.vertex_colors[v]).cwiseAbs().maxCoeff(),
              0.5f / 255.0f + 1e-6f);
  }
  // Region vertices carry the field at their pre-image; the others the target's own colours,
  // which (the target is the moved plane with the same vertex colours) is the field at the
  // pre-image as well: the painted mesh is continuous across the boundary.
  const Eigen::Isometry3d inverse = test::rigid_motion().inverse();
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    EXPECT_LT((mesh.vertex_colors[v] - linear_color(inverse * mesh.positions[v])).norm(), 1e-5f);
  }
}

TEST(PaintPly, TransparentTexelsShowTheTargetsOwnColour) {
  // A fully transparent source (every texel (0, 0, 0, 0)) pasted onto the moved image plane,
  // whose own look is its checker texture: the region shows the target's texture, not black.
  TexturedPair t("transparent");
  const ColorSource clear = ColorSource::texture(
      *t.pair->source_surface, Image(32, 32, Eigen::Vector4f(0, 0, 0, 0)), "clear");
  PaintedSurfaceOptions options;
  options.resolution = 4;
  options.sampling = t.pair->sampling();
  options.sampling.max_edge = 0.1;
  const PaintedSurface painted =
      paint_surface(*t.pair->target_surface, *t.pair->to, t.pair->mapping(), options);
  const PolygonMesh mesh = make_colored_mesh(painted, clear);
  const Image checker_image = read_image(t.dir / "source.png");
  int region = 0;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    // The target's own colour: its texture at its UV (Repeat, as TargetColor documents).
    const SurfacePoint& p = painted.points[static_cast<size_t>(v)];
    const Eigen::Vector3f own =
        sample(checker_image, texture_coordinate(*t.pair->target_surface, p), ImageWrap::Repeat)
            .head<3>();
    EXPECT_LT((mesh.vertex_colors[static_cast<size_t>(v)] - own).cwiseAbs().maxCoeff(), 1e-6f) << v;
    region += painted.vertex_sample[static_cast<size_t>(v)] >= 0 ? 1 : 0;
  }
  EXPECT_GT(region, 100);
  // A target without colours, texture or material shows the default material's grey.
  PolygonMesh bare = plane_with_linear_colors();
  bare.vertex_colors.clear();
  const auto pair = rigid_disk_pair(bare, test::rigid_motion());
  const TargetColor own(*pair->target_surface);
  EXPECT_EQ(own(SurfacePoint{0, 0.5, 0.5}), Eigen::Vector3f(0.8f, 0.8f, 0.8f));
  EXPECT_EQ(own(SurfacePoint{1, 0.1, 0.2}), default_material().diffuse.cast<float>());
}

TEST(PaintFiles, OutputFolderCopiesTexturesInUnderFreeBareNames) {
  const auto dir = test::scratch_dir("output_folder");
  std::filesystem::create_directories(dir / "a");
  std::filesystem::create_directories(dir / "b");
  write_png(dir / "a" / "tex.png", Image(2, 2, Eigen::Vector4f(1, 0, 0, 1)));
  write_png(dir / "b" / "tex.png", Image(2, 2, Eigen::Vector4f(0, 0, 1, 1)));
  OutputFolder folder(dir / "out");
  EXPECT_EQ(folder.copy_in(dir / "a" / "tex.png"), dir / "out" / "tex.png");
  EXPECT_EQ(folder.copy_in(dir / "a" / ".." / "a" / "tex.png"), dir / "out" / "tex.png");  // once
  EXPECT_EQ(folder.copy_in(dir / "b" / "tex.png"), dir / "out" / "tex_2.png");
  EXPECT_EQ(read_image(dir / "out" / "tex_2.png").at(0, 0), Eigen::Vector4f(0, 0, 1, 1));
  EXPECT_THROW(folder.write_image("tex.png", Image(1, 1)), InvalidInputError);
  EXPECT_THROW(folder.write_image("sub/x.png", Image(1, 1)), InvalidInputError);
  EXPECT_THROW(folder.copy_in(dir / "missing.png"), IoError);

  // An OBJ whose materials name textures elsewhere (and one that does not exist) stands alone:
  // every face has a material, every map_Kd is a bare name of a file in the folder.
  PolygonMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  mesh.add_face({0, 1, 2});
  mesh.add_face({1, 3, 2});
  mesh.add_face({0, 2, 3});
  mesh.materials = {{"red", {1, 0, 0}, dir / "a" / "tex.png"},
                    {"lost", {0, 1, 0}, dir / "nowhere.png"}};
  mesh.face_materials = {0, 1, -1};
  folder.write_obj("m.obj", mesh);
  EXPECT_EQ(folder.warnings().size(), 1u);
  std::stringstream mtl;
  mtl << std::ifstream(dir / "out" / "m.mtl").rdbuf();
  EXPECT_NE(mtl.str().find("map_Kd tex.png\n"), std::string::npos) << mtl.str();
  EXPECT_EQ(mtl.str().find("nowhere"), std::string::npos) << mtl.str();
  // Moved elsewhere, the folder still resolves.
  std::filesystem::rename(dir / "out", dir / "moved");
  const PolygonMesh read = read_mesh(dir / "moved" / "m.obj").mesh;
  ASSERT_EQ(read.face_materials.size(), 3u);
  for (const int m : read.face_materials) EXPECT_GE(m, 0);
  EXPECT_EQ(read.materials[static_cast<size_t>(read.face_materials[2])].name, "default");
  EXPECT_EQ(read.materials[0].diffuse_texture, dir / "moved" / "tex.png");
  EXPECT_TRUE(std::filesystem::exists(read.materials[0].diffuse_texture));
}

TEST(PaintFiles, BakedAndTargetMeshesKeepTheTargetsUvsAndMaterials) {
  TexturedPair t("baked_mesh");
  PaintedSurfaceOptions options;
  options.resolution = 4;
  options.sampling = t.pair->sampling();
  const PaintedSurface painted =
      paint_surface(*t.pair->target_surface, *t.pair->to, t.pair->mapping(), options);
  const PolygonMesh target = make_target_mesh(painted);
  ASSERT_EQ(target.num_faces(), painted.num_triangles());
  ASSERT_TRUE(target.has_texcoords());
  for (int f = 0; f < target.num_faces(); ++f) {
    EXPECT_EQ(target.materials[static_cast<size_t>(target.face_materials[f])].name, "image");
    for (int k = 0; k < 3; ++k) {
      const int corner = target.face_offsets[f] + k;
      const Eigen::Vector2d& st =
          painted.triangle_uv[static_cast<size_t>(f)][static_cast<size_t>(k)];
      const Eigen::Vector2d uv = texture_coordinate(
          *t.pair->target_surface,
          SurfacePoint{painted.triangle_face[static_cast<size_t>(f)], st.x(), st.y()});
      EXPECT_EQ(target.texcoords[static_cast<size_t>(target.corner_texcoords[corner])], uv);
    }
  }
  // Pooled per vertex: about one UV per vertex on a seamless plane, not one per corner.
  EXPECT_LT(target.texcoords.size(), 2 * target.positions.size());
  std::vector<Eigen::Vector3d> moved = painted.positions;
  for (auto& p : moved) p.z() += 1.0;
  EXPECT_EQ(make_target_mesh(painted, moved).positions[0], moved[0]);
  EXPECT_THROW(make_target_mesh(painted, std::span(moved).first(3)), InvalidInputError);

  // The bake's mesh: the material that named the baked-into image names the bake.
  const PolygonMesh baked = make_baked_mesh(painted, t.dir / "baked.png", t.dir / "source.png");
  ASSERT_EQ(baked.materials.size(), 1u);
  EXPECT_EQ(baked.materials[0].diffuse_texture, t.dir / "baked.png");
  // A bake into an image of its own: one material "baked" on every face.
  const PolygonMesh own = make_baked_mesh(painted, t.dir / "baked.png", t.dir / "other.png");
  ASSERT_EQ(own.materials.size(), 1u);
  EXPECT_EQ(own.materials[0].name, "baked");
  EXPECT_EQ(own.face_materials, std::vector<int>(static_cast<size_t>(own.num_faces()), 0));
}

}  // namespace
}  // namespace elastic
