// One level of 1-to-4 grid subdivision on the source surface (end of §4.3).
#include "elastic/particles/grid_subdivision.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "elastic/core/error.h"
#include "elastic/mapping/initial_map.h"
#include "elastic/regions/region_spec.h"
#include "elastic/sampling/sample_region.h"
#include "elastic/shapes/procedural_shapes.h"

namespace elastic {
namespace {

// A geodesic disk of radius 0.6 around (0.1, 0.05) on the plane z = 0, sampled with about 300
// particles.
struct PlaneDisk {
  LimitSurface surface{make_plane({.faces = ShapeFaces::Quads, .resolution = 8})};
  SurfaceProjector projector{surface};
  Region region = make_region(projector, parse_region_spec("disk:0.1,0.05,0,0.6"));
  SurfaceCurve curve = region.boundary_curve();
  ParticleGrid grid = sample(300);

  ParticleGrid sample(long particles) const {
    SampleRegionOptions options;
    options.layout.particles = particles;
    return sample_region(region, projector, options).grid;
  }
};

// Options placing interior particles by averaged disk coordinates, as mapping/refine_map does.
GridSubdivisionOptions disk_options(const ParticleGrid& grid, const RegionDiskMap& disk) {
  GridSubdivisionOptions options;
  for (const SurfacePoint& p : grid.source_points) {
    Eigen::Vector2d w;
    EXPECT_TRUE(disk.to_disk(p, w));
    options.plane_coordinates.push_back(w);
  }
  options.plane_to_surface = [&disk](const Eigen::Vector2d& w, SurfacePoint& p) {
    return disk.from_disk(w, p);
  };
  options.boundary_point = [&disk](double s) { return disk.boundary_point(s); };
  return options;
}

// Crossing-number test of x's (x, y) against the curve polygon's (x, y).
bool inside_curve(const SurfaceCurve& curve, const Eigen::Vector3d& x) {
  bool inside = false;
  const int n = curve.size();
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d& a = curve.positions[k];
    const Eigen::Vector3d& b = curve.positions[(k + 1) % n];
    if ((a.y() > x.y()) != (b.y() > x.y()) &&
        x.x() < a.x() + (x.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y())) {
      inside = !inside;
    }
  }
  return inside;
}

int euler_characteristic(const GridMesh& mesh) {
  return static_cast<int>(mesh.n_vertices()) - static_cast<int>(mesh.n_edges()) +
         static_cast<int>(mesh.n_faces());
}

// The polyline point at normalised arc length `anchor + s` from vertex 0, walked here independently
// of SurfaceCurve::locate.
Eigen::Vector3d curve_point(const SurfaceCurve& curve, double s) {
  const int n = curve.size();
  double total = 0.0;
  for (int k = 0; k < n; ++k) total += (curve.positions[(k + 1) % n] - curve.positions[k]).norm();
  double a = std::fmod(curve.anchor + s, 1.0) * total;
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d& p = curve.positions[k];
    const Eigen::Vector3d& q = curve.positions[(k + 1) % n];
    const double len = (q - p).norm();
    if (a <= len || k == n - 1) return p + (q - p) * (len > 0.0 ? std::min(a / len, 1.0) : 0.0);
    a -= len;
  }
  return curve.positions[0];
}

TEST(GridSubdivision, PlaneDiskCountsTopologyAndPlacement) {
  const PlaneDisk disk;
  const RegionDiskMap disk_map(disk.region);
  const ParticleGrid& coarse = disk.grid;
  const GridSubdivisionResult result =
      subdivide_grid(coarse, disk.projector, disk.curve, disk_options(coarse, disk_map));
  const ParticleGrid& fine = result.grid;
  const GridMesh& c = coarse.mesh;
  const GridMesh& f = fine.mesh;

  // Counts by the refinement rules (independent of how the code builds them).
  int quads = 0, triangles = 0;
  for (const auto fh : c.faces()) (c.valence(fh) == 4 ? quads : triangles)++;
  ASSERT_GT(quads, 0);
  ASSERT_GT(triangles, 0);
  EXPECT_EQ(f.n_faces(), 4 * c.n_faces());
  EXPECT_EQ(f.n_vertices(), c.n_vertices() + c.n_edges() + static_cast<size_t>(quads));
  EXPECT_EQ(f.n_edges(),
            2 * c.n_edges() + 4 * static_cast<size_t>(quads) + 3 * static_cast<size_t>(triangles));
  EXPECT_EQ(euler_characteristic(f), euler_characteristic(c));
  EXPECT_EQ(euler_characteristic(f), 1);  // a disk
  EXPECT_EQ(result.magnet_placements, 0);
  EXPECT_EQ(fine.springs.size(), f.n_edges());
  EXPECT_EQ(fine.angular_springs.size(),
            4 * static_cast<size_t>(quads) * 4 + 4 * static_cast<size_t>(triangles) * 3);

  // Old particles unchanged.
  for (int i = 0; i < coarse.num_particles(); ++i) {
    EXPECT_EQ(fine.source_points[i], coarse.source_points[i]);
    EXPECT_EQ(f.point(f.vertex_handle(i)), c.point(c.vertex_handle(i)));
  }

  // Every particle on the plane and inside the region, i.e. inside (or on) its boundary curve's
  // polygon (the region is a heat-geodesic disk, only approximately the Euclidean one); interior
  // ones at their surface point's limit position. 1e-12: the plane's limit surface is z = 0 to
  // round-off.
  const Eigen::Matrix3Xd x = fine.source_positions();
  for (int p = 0; p < fine.num_particles(); ++p) {
    EXPECT_LT(std::abs(x(2, p)), 1e-12) << p;
    if (!fine.is_boundary[p]) {
      EXPECT_TRUE(inside_curve(disk.curve, x.col(p))) << p;
      EXPECT_LT((disk.surface.position(fine.source_points[p]) - x.col(p)).norm(), 1e-12) << p;
    }
  }

  // Faces counter-clockwise seen from +z, none degenerate.
  for (const auto fh : f.faces()) {
    std::vector<Eigen::Vector2d> corners;
    for (const auto vh : f.fv_range(fh)) corners.push_back(x.col(vh.idx()).head<2>());
    double area = 0.0;
    for (size_t k = 0; k < corners.size(); ++k) {
      const Eigen::Vector2d& a = corners[k];
      const Eigen::Vector2d& b = corners[(k + 1) % corners.size()];
      area += a.x() * b.y() - a.y() * b.x();
    }
    EXPECT_GT(area, 0.0) << "face " << fh.idx();
  }

  // Boundary: twice the particles, every second one new at the mid-parameter of its neighbours,
  // on the curve polyline at that parameter, the loop still the mesh's boundary in order.
  const size_t m = coarse.boundary_loop.size();
  ASSERT_EQ(fine.boundary_loop.size(), 2 * m);
  ASSERT_EQ(fine.boundary_parameter.size(), 2 * m);
  int wraps = 0;
  for (size_t k = 0; k < 2 * m; ++k) {
    const int p = fine.boundary_loop[k];
    const double s = fine.boundary_parameter[k];
    EXPECT_TRUE(fine.is_boundary[p]);
    const double next = fine.boundary_parameter[(k + 1) % (2 * m)];
    if (next < s) ++wraps;
    if (k % 2 == 0) {
      EXPECT_EQ(p, coarse.boundary_loop[k / 2]);
      EXPECT_EQ(s, coarse.boundary_parameter[k / 2]);
    } else {
      const double a = coarse.boundary_parameter[k / 2];
      double b = coarse.boundary_parameter[(k / 2 + 1) % m];
      if (b <= a) b += 1.0;
      EXPECT_NEAR(s, std::fmod(0.5 * (a + b), 1.0), 1e-15) << k;
      // 1e-12: two arc-length walks of the same polyline differ by round-off.
      EXPECT_LT((x.col(p) - curve_point(disk.curve, s)).norm(), 1e-12) << k;
      // The new boundary particle's surface point is under it (the chord is within the region
      // tessellation's tolerance of the circle: exactly on the plane).
      EXPECT_LT((disk.surface.position(fine.source_points[p]) - x.col(p)).norm(), 1e-12) << k;
    }
    const auto heh =
        f.find_halfedge(f.vertex_handle(p), f.vertex_handle(fine.boundary_loop[(k + 1) % (2 * m)]));
    ASSERT_TRUE(heh.is_valid());
    EXPECT_TRUE(f.is_boundary(f.edge_handle(heh)));
  }
  EXPECT_EQ(wraps, 1);  // increasing parameters around the loop: one wrap at the anchor
  int boundary_edges = 0, boundary_flags = 0;
  for (const auto eh : f.edges()) boundary_edges += f.is_boundary(eh) ? 1 : 0;
  for (char b : fine.is_boundary) boundary_flags += b;
  EXPECT_EQ(boundary_edges, static_cast<int>(2 * m));
  EXPECT_EQ(boundary_flags, static_cast<int>(2 * m));
  // Counter-clockwise seen from +z: positive signed area of the boundary polygon.
  double loop_area = 0.0;
  for (size_t k = 0; k < 2 * m; ++k) {
    const Eigen::Vector3d a = x.col(fine.boundary_loop[k]);
    const Eigen::Vector3d b = x.col(fine.boundary_loop[(k + 1) % (2 * m)]);
    loop_area += a.x() * b.y() - a.y() * b.x();
  }
  EXPECT_GT(loop_area, 0.0);
  // ... and close to the curve polygon's area: its vertices lie on the curve's chords (0.5 * sum =
  // area; 1%: the segments cut off between a particle spacing of chords).
  double curve_area = 0.0;
  for (int k = 0; k < disk.curve.size(); ++k) {
    const Eigen::Vector3d& a = disk.curve.positions[k];
    const Eigen::Vector3d& b = disk.curve.positions[(k + 1) % disk.curve.size()];
    curve_area += a.x() * b.y() - a.y() * b.x();
  }
  EXPECT_LE(loop_area, curve_area * (1 + 1e-12));
  EXPECT_GT(loop_area, 0.99 * curve_area);

  // Springs' rest values are the new source distances.
  for (const Spring& s : fine.springs) {
    EXPECT_NEAR(s.rest, (x.col(s.j) - x.col(s.i)).norm(), 1e-15);
  }
}

// Without a plane, interior particles are the magnet of their parents' average: on the plane that
// is the average itself (the closest point of a point of the plane is the point).
TEST(GridSubdivision, MagnetPlacementOnThePlaneIsTheParentsAverage) {
  const PlaneDisk disk;
  const GridSubdivisionResult result = subdivide_grid(disk.grid, disk.projector, disk.curve);
  const Eigen::Matrix3Xd coarse = disk.grid.source_positions();
  const Eigen::Matrix3Xd fine = result.grid.source_positions();
  ASSERT_EQ(result.parents.size(), static_cast<size_t>(result.grid.num_particles()));
  int checked = 0;
  for (int p = disk.grid.num_particles(); p < result.grid.num_particles(); ++p) {
    if (result.grid.is_boundary[p]) continue;
    const SubdivisionParents& parents = result.parents[p];
    ASSERT_TRUE(parents.count == 2 || parents.count == 4);
    Eigen::Vector3d average = Eigen::Vector3d::Zero();
    for (int k = 0; k < parents.count; ++k) average += coarse.col(parents.parent[k]);
    average /= parents.count;
    // 1e-12: Newton on the plane converges to round-off.
    EXPECT_LT((fine.col(p) - average).norm(), 1e-12) << p;
    ++checked;
  }
  EXPECT_EQ(checked, result.magnet_placements);
  EXPECT_EQ(checked, result.edge_particles - result.boundary_particles + result.face_particles);
}

// On a curved surface (the cap), magnet-placed particles are on the limit surface.
TEST(GridSubdivision, CapParticlesStayOnTheSurface) {
  const LimitSurface cap(make_cap({.resolution = 12}));
  const SurfaceProjector projector(cap);
  const Region region = make_region(projector, parse_region_spec("boundary"));
  SampleRegionOptions options;
  options.layout.particles = 200;
  options.adaptive = false;
  const ParticleGrid grid = sample_region(region, projector, options).grid;
  const GridSubdivisionResult result = subdivide_grid(grid, projector, region.boundary_curve());
  const Eigen::Matrix3Xd x = result.grid.source_positions();
  for (int p = 0; p < result.grid.num_particles(); ++p) {
    if (result.grid.is_boundary[p]) continue;
    // 1e-9: the magnet's Newton tolerance on a unit-size surface.
    EXPECT_LT((cap.position(result.grid.source_points[p]) - x.col(p)).norm(), 1e-9) << p;
  }
  EXPECT_EQ(result.grid.mesh.n_faces(), 4 * grid.mesh.n_faces());
}

TEST(GridSubdivision, IsDeterministicAndRefinesTwice) {
  const PlaneDisk disk;
  const RegionDiskMap disk_map(disk.region);
  const GridSubdivisionOptions options = disk_options(disk.grid, disk_map);
  const GridSubdivisionResult a = subdivide_grid(disk.grid, disk.projector, disk.curve, options);
  const GridSubdivisionResult b = subdivide_grid(disk.grid, disk.projector, disk.curve, options);
  EXPECT_EQ(a.grid.source_positions(), b.grid.source_positions());
  EXPECT_EQ(a.grid.source_points, b.grid.source_points);
  EXPECT_EQ(a.grid.boundary_parameter, b.grid.boundary_parameter);
  // A second level on the refined grid: 16 times the faces, Euler characteristic kept.
  const GridSubdivisionResult c =
      subdivide_grid(a.grid, disk.projector, disk.curve, disk_options(a.grid, disk_map));
  EXPECT_EQ(c.grid.mesh.n_faces(), 16 * disk.grid.mesh.n_faces());
  EXPECT_EQ(euler_characteristic(c.grid.mesh), 1);
  EXPECT_EQ(c.grid.boundary_loop.size(), 4 * disk.grid.boundary_loop.size());
}

TEST(GridSubdivision, RejectsInconsistentGrids) {
  const PlaneDisk disk;
  ParticleGrid broken = disk.grid;
  broken.source_points.pop_back();
  EXPECT_THROW(subdivide_grid(broken, disk.projector, disk.curve), InvalidInputError);

  broken = disk.grid;
  std::swap(broken.boundary_loop[0], broken.boundary_loop[2]);  // no longer consecutive
  EXPECT_THROW(subdivide_grid(broken, disk.projector, disk.curve), InvalidInputError);

  GridSubdivisionOptions options;
  options.plane_coordinates.assign(static_cast<size_t>(disk.grid.num_particles()),
                                   Eigen::Vector2d::Zero());
  EXPECT_THROW(subdivide_grid(disk.grid, disk.projector, disk.curve, options),
               InvalidInputError);  // coordinates without plane_to_surface

  // A pentagon.
  ParticleGrid pentagon;
  std::vector<GridMesh::VertexHandle> v;
  for (int k = 0; k < 5; ++k) {
    const double a = 2.0 * M_PI * k / 5;
    v.push_back(pentagon.mesh.add_vertex(GridMesh::Point(0.3 * std::cos(a), 0.3 * std::sin(a), 0)));
    pentagon.source_points.push_back(disk.projector.closest(Eigen::Vector3d(0, 0, 0)).point);
    pentagon.is_boundary.push_back(1);
    pentagon.boundary_loop.push_back(k);
    pentagon.boundary_parameter.push_back(k / 5.0);
  }
  pentagon.mesh.add_face(v);
  try {
    GridSubdivisionOptions named;
    named.name = "pentagon grid";
    subdivide_grid(pentagon, disk.projector, disk.curve, named);
    ADD_FAILURE() << "a pentagon was accepted";
  } catch (const InvalidInputError& e) {
    EXPECT_EQ(e.input(), "pentagon grid");
  }
}

}  // namespace
}  // namespace elastic
