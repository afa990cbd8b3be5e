// The only translation unit of the project that includes CGAL's parameterization package (slow to
// compile): the three baseline flattenings of a Region.
#include "elastic/baselines/cgal_flattening.h"

// ARAP's MVC post-processor builds a CGAL constrained triangulation, whose Compact_container trips
// GCC's -Wnull-dereference after inlining (a false positive inside CGAL, reported at optimisation
// time, so system-header suppression does not catch it). This file holds nothing but the CGAL
// calls, so the warning is silenced for the whole translation unit.
#pragma GCC diagnostic ignored "-Wnull-dereference"

#include <CGAL/Eigen_solver_traits.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_parameterization/ARAP_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/Discrete_conformal_map_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/Error_code.h>
#include <CGAL/Surface_mesh_parameterization/LSCM_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/Two_vertices_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/parameterize.h>

#include <Eigen/SparseLU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>

#include "elastic/core/error.h"

namespace elastic {

namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using Point2 = Kernel::Point_2;
using Point3 = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point3>;
using VertexIndex = Mesh::Vertex_index;
using HalfedgeIndex = Mesh::Halfedge_index;
namespace SMP = CGAL::Surface_mesh_parameterization;

// Correspondence parameter s in [0,1) of every boundary vertex (normalised arc length from the
// anchor), in the order of region.boundary.
std::vector<double> boundary_parameters(const Region& region) {
  const SurfaceCurve curve = region.boundary_curve();
  const std::vector<double> arc = curve.arc_lengths();
  const double total = curve.length();
  std::vector<double> s(arc.size());
  for (size_t k = 0; k < arc.size(); ++k) {
    double value = std::fmod(arc[k] / total - region.anchor, 1.0);
    if (value < 0.0) {
      value += 1.0;
    }
    s[k] = value;
  }
  return s;
}

// A model of CGAL's border parameterizer concept: the boundary vertices on the unit circle at angle
// 2 pi s (s = normalised arc length from the anchor). Circular_border_arc_length_parameterizer_3
// does the same from an arbitrary start vertex; starting at the anchor makes the DCM flattenings of
// any two regions agree at s = 0, so their alignment is only a scale (up to the discretisation).
class AnchoredCircleBorder {
 public:
  AnchoredCircleBorder(const Region* region, const std::vector<double>* parameters)
      : region_(region), parameters_(parameters) {}

  template <typename UvMap, typename IndexMap, typename ParameterizedMap>
  SMP::Error_code parameterize(const Mesh& /*mesh*/, HalfedgeIndex /*bhd*/, UvMap uvmap,
                               IndexMap /*vimap*/, ParameterizedMap vpmap) const {
    for (size_t k = 0; k < region_->boundary.size(); ++k) {
      const double angle = 2.0 * std::numbers::pi * (*parameters_)[k];
      const VertexIndex v(static_cast<Mesh::size_type>(region_->boundary[k]));
      put(uvmap, v, Point2(std::cos(angle), std::sin(angle)));
      put(vpmap, v, true);
    }
    return SMP::OK;
  }
  bool is_border_convex() const { return true; }

 private:
  const Region* region_;
  const std::vector<double>* parameters_;
};

// CGAL's ARAP solves the same global system (its matrix depends only on the mesh) twice per
// iteration, and its default Eigen_solver_traits<SparseLU> factorises it every time: 100 sparse LU
// factorisations for 50 iterations. This model of the same solver concept keeps the factorisation
// while the matrix is unchanged (compared entry by entry, O(nnz), far cheaper than a
// factorisation), so the results are those of the default traits, bit for bit, about ten times
// faster.
class CachedSparseLuTraits : public CGAL::Eigen_solver_traits<
                                 Eigen::SparseLU<CGAL::Eigen_sparse_matrix<double>::EigenType>> {
  using Base =
      CGAL::Eigen_solver_traits<Eigen::SparseLU<CGAL::Eigen_sparse_matrix<double>::EigenType>>;
  using EigenMatrix = CGAL::Eigen_sparse_matrix<double>::EigenType;

 public:
  using Base::linear_solver;
  bool linear_solver(const Matrix& A, const Vector& B, Vector& X, NT& D) {
    D = 1;
    const EigenMatrix& a = A.eigen_object();
    Cache& cache = *cache_;
    if (!cache.valid || !same(cache.matrix, a)) {
      cache.matrix = a;
      cache.matrix.makeCompressed();
      cache.lu.compute(cache.matrix);
      cache.valid = cache.lu.info() == Eigen::Success;
      if (!cache.valid) {
        return false;
      }
    }
    X = cache.lu.solve(B);
    return cache.lu.info() == Eigen::Success;
  }

 private:
  struct Cache {
    EigenMatrix matrix;
    Eigen::SparseLU<EigenMatrix> lu;
    bool valid = false;
  };
  static bool same(const EigenMatrix& cached, const EigenMatrix& a) {
    if (!a.isCompressed() || cached.rows() != a.rows() || cached.cols() != a.cols() ||
        cached.nonZeros() != a.nonZeros()) {
      return false;
    }
    const auto nnz = static_cast<size_t>(a.nonZeros());
    const auto outer = static_cast<size_t>(a.outerSize()) + 1;
    return std::equal(a.outerIndexPtr(), a.outerIndexPtr() + outer, cached.outerIndexPtr()) &&
           std::equal(a.innerIndexPtr(), a.innerIndexPtr() + nnz, cached.innerIndexPtr()) &&
           std::equal(a.valuePtr(), a.valuePtr() + nnz, cached.valuePtr());
  }
  std::shared_ptr<Cache> cache_ = std::make_shared<Cache>();
};

// The boundary vertex (index into region.boundary) whose parameter is cyclically nearest `target`.
size_t nearest_parameter(const std::vector<double>& s, double target) {
  size_t best = 0;
  double best_distance = 2.0;
  for (size_t k = 0; k < s.size(); ++k) {
    const double d = std::abs(s[k] - target);
    const double cyclic = std::min(d, 1.0 - d);
    if (cyclic < best_distance) {
      best_distance = cyclic;
      best = k;
    }
  }
  return best;
}

// The region as a CGAL Surface_mesh: vertex i of the mesh is region vertex i.
Mesh region_mesh(const Region& region, const std::string& name) {
  if (region.positions.empty() || region.triangles.empty()) {
    throw InvalidInputError(name, "region is empty (no triangles)");
  }
  if (region.boundary.size() < 3) {
    throw InvalidInputError(name, "region has no boundary loop");
  }
  const int nv = region.num_vertices();
  for (int v : region.boundary) {
    if (v < 0 || v >= nv) {
      throw InvalidInputError(name, "boundary vertex index out of range");
    }
  }
  Mesh mesh;
  mesh.reserve(static_cast<Mesh::size_type>(nv), static_cast<Mesh::size_type>(3 * nv),
               static_cast<Mesh::size_type>(region.num_triangles()));
  for (const Eigen::Vector3d& p : region.positions) {
    mesh.add_vertex(Point3(p.x(), p.y(), p.z()));
  }
  for (const Eigen::Vector3i& t : region.triangles) {
    if (t.minCoeff() < 0 || t.maxCoeff() >= nv || t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) {
      throw InvalidInputError(name, "region triangle with an invalid vertex index");
    }
    const auto f = mesh.add_face(VertexIndex(static_cast<Mesh::size_type>(t[0])),
                                 VertexIndex(static_cast<Mesh::size_type>(t[1])),
                                 VertexIndex(static_cast<Mesh::size_type>(t[2])));
    if (f == Mesh::null_face()) {
      throw InvalidInputError(name, "region is not a manifold, consistently oriented mesh");
    }
  }
  return mesh;
}

// The mesh's border halfedge leaving boundary vertex 0 (a deterministic start for CGAL's
// traversals) and its used vertices, after checking that it is a topological disk: one border
// cycle and Euler characteristic 1 over the used vertices.
struct DiskBorder {
  HalfedgeIndex start = Mesh::null_halfedge();
  long used_vertices = 0;
};

DiskBorder disk_border(const Mesh& mesh, const Region& region, const std::string& name) {
  DiskBorder out;
  int border_cycles = 0;
  std::vector<char> seen(mesh.number_of_halfedges(), 0);
  for (HalfedgeIndex h : mesh.halfedges()) {
    if (!mesh.is_border(h) || seen[h.idx()]) {
      continue;
    }
    ++border_cycles;
    for (HalfedgeIndex g : CGAL::halfedges_around_face(h, mesh)) {
      seen[g.idx()] = 1;
    }
  }
  const VertexIndex v0(static_cast<Mesh::size_type>(region.boundary[0]));
  for (HalfedgeIndex h : CGAL::halfedges_around_source(v0, mesh)) {
    if (mesh.is_border(h)) {
      out.start = h;
    }
  }
  for (VertexIndex v : mesh.vertices()) {
    out.used_vertices += mesh.is_isolated(v) ? 0 : 1;
  }
  const long euler = out.used_vertices - static_cast<long>(mesh.number_of_edges()) +
                     static_cast<long>(mesh.number_of_faces());
  if (border_cycles != 1 || euler != 1 || out.start == Mesh::null_halfedge()) {
    throw InvalidInputError(name, "region is not a topological disk with one boundary loop (" +
                                      std::to_string(border_cycles) +
                                      " boundary loops, Euler characteristic " +
                                      std::to_string(euler) + ")");
  }
  return out;
}

using UvMap = Mesh::Property_map<VertexIndex, Point2>;

// CGAL's parameterizer of `kind` into uvmap; s: the boundary vertices' parameters.
void parameterize(Mesh& mesh, const Region& region, const std::vector<double>& s, BaselineKind kind,
                  const DiskBorder& border, const CgalFlatteningOptions& options,
                  const UvMap& uvmap) {
  const std::string& name = options.name;
  SMP::Error_code status = SMP::OK;
  switch (kind) {
    case BaselineKind::Lscm: {
      // Two pins make LSCM's minimiser unique; which vertices are pinned changes the map
      // (slightly), where they are pinned only changes it by a similarity. Pinning the
      // correspondence points s = 0 and s = 0.5 treats source and target alike.
      const auto a =
          VertexIndex(static_cast<Mesh::size_type>(region.boundary[nearest_parameter(s, 0.0)]));
      const auto b =
          VertexIndex(static_cast<Mesh::size_type>(region.boundary[nearest_parameter(s, 0.5)]));
      using Border = SMP::Two_vertices_parameterizer_3<Mesh>;
      using Parameterizer = SMP::LSCM_parameterizer_3<Mesh, Border>;
      status = SMP::parameterize(mesh, Parameterizer(Border(a, b)), border.start, uvmap);
      break;
    }
    case BaselineKind::Arap: {
      if (options.arap_iterations < 1) {
        throw InvalidInputError(name, "ARAP needs at least one iteration");
      }
      if (border.used_vertices > options.arap_max_vertices) {
        throw NumericalError(
            name, "region has " + std::to_string(border.used_vertices) +
                      " vertices, more than ARAP's limit of " +
                      std::to_string(options.arap_max_vertices) +
                      " (CGAL's ARAP post-processor is quadratic in the region size; coarsen "
                      "the tessellation or raise arap_max_vertices)");
      }
      using Parameterizer = SMP::ARAP_parameterizer_3<Mesh, SMP::Two_vertices_parameterizer_3<Mesh>,
                                                      CachedSparseLuTraits>;
      Parameterizer parameterizer(
          Parameterizer::Border_parameterizer(), CachedSparseLuTraits(), options.arap_lambda,
          static_cast<unsigned int>(options.arap_iterations), options.arap_tolerance);
      status = SMP::parameterize(mesh, parameterizer, border.start, uvmap);
      break;
    }
    case BaselineKind::Dcm: {
      using Parameterizer = SMP::Discrete_conformal_map_parameterizer_3<Mesh, AnchoredCircleBorder>;
      status = SMP::parameterize(mesh, Parameterizer(AnchoredCircleBorder(&region, &s)),
                                 border.start, uvmap);
      break;
    }
  }
  if (status != SMP::OK) {
    throw NumericalError(
        name, std::string("CGAL parameterization failed: ") + SMP::get_error_message(status));
  }
}

// Scales the flattening to the region's 3D area and reflects a mirrored embedding (as good as
// any) so that both regions' flattenings have the orientation of their triangles (the alignment
// fits rotations only, never reflections); counts the triangles left flipped.
void normalise(const Region& region, const std::string& name, CgalFlattening& result) {
  auto signed_area = [&](const Eigen::Vector3i& t) {
    const Eigen::Vector2d e1 =
        result.uv[static_cast<size_t>(t[1])] - result.uv[static_cast<size_t>(t[0])];
    const Eigen::Vector2d e2 =
        result.uv[static_cast<size_t>(t[2])] - result.uv[static_cast<size_t>(t[0])];
    return 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
  };
  double area = 0.0;
  for (const Eigen::Vector3i& t : region.triangles) {
    area += signed_area(t);
  }
  const double area3d = region.area();
  if (!(area3d > 0.0) || !std::isfinite(area) || area == 0.0) {
    throw NumericalError(name, "CGAL parameterization has zero or non-finite area");
  }
  const double mirror = area < 0.0 ? -1.0 : 1.0;
  result.scale = std::sqrt(area3d / std::abs(area));
  for (Eigen::Vector2d& p : result.uv) {
    p = result.scale * Eigen::Vector2d(p.x(), mirror * p.y());
  }
  for (const Eigen::Vector3i& t : region.triangles) {
    if (!(signed_area(t) > 0.0)) {
      ++result.flipped_triangles;
    }
  }
}

}  // namespace

CgalFlattening flatten_region_cgal(const Region& region, BaselineKind kind,
                                   const CgalFlatteningOptions& options) {
  Mesh mesh = region_mesh(region, options.name);
  const DiskBorder border = disk_border(mesh, region, options.name);
  const std::vector<double> s = boundary_parameters(region);
  auto uvmap = mesh.add_property_map<VertexIndex, Point2>("v:elastic_uv", Point2(0, 0)).first;
  const auto start = std::chrono::steady_clock::now();
  parameterize(mesh, region, s, kind, border, options, uvmap);
  CgalFlattening result;
  result.seconds_parameterize =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.uv.resize(static_cast<size_t>(region.num_vertices()));
  for (VertexIndex v : mesh.vertices()) {
    const Point2& p = uvmap[v];
    result.uv[v.idx()] = Eigen::Vector2d(p.x(), p.y());
  }
  normalise(region, options.name, result);
  return result;
}

}  // namespace elastic
