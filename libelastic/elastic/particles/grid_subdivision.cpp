#include "elastic/particles/grid_subdivision.h"

#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "elastic/core/error.h"
#include "elastic/particles/detail/parents_closest.h"

namespace elastic {

namespace {

// The parameter half-way from s_a to s_b going forward along the curve (counter-clockwise), both in
// [0,1). The forward gap wraps past 1 at the anchor; a zero gap would be two particles at one
// parameter, which the layout never produces, and is read as a full turn so the result stays
// between them in the loop's order.
double mid_parameter(double s_a, double s_b) {
  double gap = s_b - s_a;
  if (gap <= 0.0) {
    gap += 1.0;
  }
  double s = s_a + 0.5 * gap;
  if (s >= 1.0) {
    s -= 1.0;
  }
  return s;
}

// The inputs' sizes and the grid's faces (triangles and quads only).
void check_inputs(const ParticleGrid& grid, const SurfaceCurve& source_curve,
                  const GridSubdivisionOptions& options) {
  const std::string& name = options.name;
  const GridMesh& mesh = grid.mesh;
  const int np = grid.num_particles();
  if (np == 0 || mesh.n_faces() == 0) {
    throw InvalidInputError(name, "grid has no particles");
  }
  if (static_cast<int>(grid.source_points.size()) != np ||
      static_cast<int>(grid.is_boundary.size()) != np ||
      (!grid.source_uv.empty() && static_cast<int>(grid.source_uv.size()) != np)) {
    throw InvalidInputError(name, "per-particle arrays do not match the particle count");
  }
  if (grid.boundary_loop.size() != grid.boundary_parameter.size() ||
      grid.boundary_loop.size() < 3) {
    throw InvalidInputError(name, "boundary loop and parameters are inconsistent");
  }
  const bool use_plane = !options.plane_coordinates.empty();
  if (use_plane && static_cast<int>(options.plane_coordinates.size()) != np) {
    throw InvalidInputError(name, "plane coordinates do not match the particle count");
  }
  if (use_plane && !options.plane_to_surface) {
    throw InvalidInputError(name, "plane coordinates given without plane_to_surface");
  }
  if (source_curve.size() < 2) {
    throw InvalidInputError(name, "source boundary curve is empty");
  }
  for (const auto fh : mesh.faces()) {
    const auto valence = mesh.valence(fh);
    if (valence != 3 && valence != 4) {
      throw InvalidInputError(name, "face " + std::to_string(fh.idx()) + " has " +
                                        std::to_string(valence) +
                                        " corners (grids have triangles and quads)");
    }
  }
}

/// One subdivision of a grid, in steps: number the new particles and their parents, check the
/// boundary, place the particles on the source (old ones, boundary ones on the curve, interior
/// ones in the plane or by the magnet), average their texture coordinates, connect.
class GridRefiner {
 public:
  GridRefiner(const ParticleGrid& grid, const SurfaceProjector& source,
              const SurfaceCurve& source_curve, const GridSubdivisionOptions& options)
      : grid_(grid),
        source_(source),
        curve_(source_curve),
        options_(options),
        name_(options.name),
        mesh_(grid.mesh),
        np_(grid.num_particles()),
        ne_(static_cast<int>(grid.mesh.n_edges())),
        nf_(static_cast<int>(grid.mesh.n_faces())),
        out_(result_.grid) {}

  GridSubdivisionResult run() {
    result_.coarse_particles = np_;
    number_particles();
    match_boundary();
    place_coarse();
    place_boundary();
    place_interior();
    average_texcoords();
    connect();
    out_.build_springs();
    return std::move(result_);
  }

 private:
  // Indices of the refined particles: old ones keep theirs, then one per edge, then one per quad;
  // and the parents of each.
  void number_particles() {
    face_particle_.assign(static_cast<size_t>(nf_), -1);
    int next = np_ + ne_;
    for (const auto fh : mesh_.faces()) {
      if (mesh_.valence(fh) == 4) {
        face_particle_[static_cast<size_t>(fh.idx())] = next++;
      }
    }
    n_new_ = next;
    result_.edge_particles = ne_;
    result_.face_particles = n_new_ - np_ - ne_;

    result_.parents.resize(static_cast<size_t>(n_new_));
    for (int i = 0; i < np_; ++i) {
      result_.parents[static_cast<size_t>(i)] = {{i, -1, -1, -1}, 1};
    }
    for (const auto eh : mesh_.edges()) {
      const auto heh = mesh_.halfedge_handle(eh, 0);
      result_.parents[static_cast<size_t>(np_ + eh.idx())] = {
          {mesh_.from_vertex_handle(heh).idx(), mesh_.to_vertex_handle(heh).idx(), -1, -1}, 2};
    }
    for (const auto fh : mesh_.faces()) {
      const int p = face_particle_[static_cast<size_t>(fh.idx())];
      if (p < 0) {
        continue;
      }
      SubdivisionParents& parents = result_.parents[static_cast<size_t>(p)];
      for (const auto vh : mesh_.fv_range(fh)) {
        parents.parent[static_cast<size_t>(parents.count++)] = vh.idx();
      }
    }
  }

  // Boundary edges: the mesh's boundary must be exactly the boundary loop, edge k joining loop[k]
  // and loop[k+1]. Their edge particles become boundary particles at the mid-parameter.
  void match_boundary() {
    const size_t m = grid_.boundary_loop.size();
    boundary_edge_.assign(m, -1);
    edge_on_boundary_.assign(static_cast<size_t>(ne_), 0);
    for (size_t k = 0; k < m; ++k) {
      const int a = grid_.boundary_loop[k], b = grid_.boundary_loop[(k + 1) % m];
      if (a < 0 || a >= np_ || b < 0 || b >= np_) {
        throw InvalidInputError(name_, "boundary loop index out of range");
      }
      const auto heh = mesh_.find_halfedge(mesh_.vertex_handle(static_cast<unsigned>(a)),
                                           mesh_.vertex_handle(static_cast<unsigned>(b)));
      if (!heh.is_valid() || !mesh_.is_boundary(mesh_.edge_handle(heh))) {
        throw InvalidInputError(name_, "boundary particles " + std::to_string(a) + " and " +
                                           std::to_string(b) +
                                           " are consecutive on the curve but not joined by a "
                                           "boundary edge of the grid");
      }
      const int e = mesh_.edge_handle(heh).idx();
      boundary_edge_[k] = e;
      edge_on_boundary_[static_cast<size_t>(e)] = 1;
    }
    int mesh_boundary_edges = 0;
    for (const auto eh : mesh_.edges()) {
      mesh_boundary_edges += mesh_.is_boundary(eh) ? 1 : 0;
    }
    if (mesh_boundary_edges != static_cast<int>(m)) {
      throw InvalidInputError(name_, "the grid's boundary has " +
                                         std::to_string(mesh_boundary_edges) +
                                         " edges but the boundary loop " + std::to_string(m) +
                                         " particles (holes or a second boundary)");
    }
  }

  // The old particles keep their places.
  void place_coarse() {
    out_.source_points.resize(static_cast<size_t>(n_new_));
    out_.is_boundary.assign(static_cast<size_t>(n_new_), 0);
    positions_.resize(static_cast<size_t>(n_new_));
    coarse_ = grid_.source_positions();
    for (int i = 0; i < np_; ++i) {
      out_.source_points[static_cast<size_t>(i)] = grid_.source_points[static_cast<size_t>(i)];
      out_.is_boundary[static_cast<size_t>(i)] = grid_.is_boundary[static_cast<size_t>(i)];
      positions_[static_cast<size_t>(i)] = coarse_.col(i);
    }
  }

  // Boundary: loop[k], then the particle of edge (loop[k], loop[k+1]), keeps the loop's
  // counter-clockwise order; the parameters interleave the same way.
  void place_boundary() {
    const size_t m = grid_.boundary_loop.size();
    const std::vector<double> cumulative = curve_.arc_lengths();
    const double total = curve_.length();
    out_.boundary_loop.reserve(2 * m);
    out_.boundary_parameter.reserve(2 * m);
    for (size_t k = 0; k < m; ++k) {
      const int p = np_ + boundary_edge_[k];
      const double s =
          mid_parameter(grid_.boundary_parameter[k], grid_.boundary_parameter[(k + 1) % m]);
      const SurfaceCurve::Location at = curve_.locate(s, cumulative, total);
      positions_[static_cast<size_t>(p)] = at.position;
      if (options_.boundary_point) {
        out_.source_points[static_cast<size_t>(p)] = options_.boundary_point(s);
      } else {
        // The chord point is within the tessellation's tolerance of the surface; its closest
        // point, warm-started at a neighbour on the curve, is the surface point under it.
        out_.source_points[static_cast<size_t>(p)] =
            source_
                .closest(at.position,
                         grid_.source_points[static_cast<size_t>(grid_.boundary_loop[k])])
                .point;
      }
      out_.is_boundary[static_cast<size_t>(p)] = 1;
      out_.boundary_loop.push_back(grid_.boundary_loop[k]);
      out_.boundary_parameter.push_back(grid_.boundary_parameter[k]);
      out_.boundary_loop.push_back(p);
      out_.boundary_parameter.push_back(s);
    }
    result_.boundary_particles = static_cast<int>(m);
  }

  // Interior new particles: average in the plane, else the magnet of the average 3D position.
  void place_interior() {
    const bool use_plane = !options_.plane_coordinates.empty();
    const LimitSurface& surface = source_.surface();
    std::vector<int> magnet;  // refined indices placed by the magnet
    for (int p = np_; p < n_new_; ++p) {
      if (p < np_ + ne_ && edge_on_boundary_[static_cast<size_t>(p - np_)]) {
        continue;
      }
      const SubdivisionParents& parents = result_.parents[static_cast<size_t>(p)];
      bool placed = false;
      if (use_plane) {
        Eigen::Vector2d w = Eigen::Vector2d::Zero();
        for (int k = 0; k < parents.count; ++k) {
          w += options_
                   .plane_coordinates[static_cast<size_t>(parents.parent[static_cast<size_t>(k)])];
        }
        w /= parents.count;
        SurfacePoint q;
        if (options_.plane_to_surface(w, q) && q.valid()) {
          out_.source_points[static_cast<size_t>(p)] = q;
          positions_[static_cast<size_t>(p)] = surface.position(q);
          placed = true;
        }
      }
      if (!placed) {
        magnet.push_back(p);
      }
    }
    place_by_magnet(magnet);
    result_.magnet_placements = static_cast<int>(magnet.size());
  }

  // The closest points of the parents' mean positions, warm-started at the first parent.
  void place_by_magnet(const std::vector<int>& magnet) {
    if (magnet.empty()) {
      return;
    }
    const std::vector<ClosestPoint> answers = detail::closest_to_parents_mean(
        source_, result_.parents, magnet, coarse_, grid_.source_points);
    for (size_t k = 0; k < magnet.size(); ++k) {
      out_.source_points[static_cast<size_t>(magnet[k])] = answers[k].point;
      positions_[static_cast<size_t>(magnet[k])] = answers[k].position;
    }
  }

  // Texture coordinates: the parents' mean.
  void average_texcoords() {
    if (grid_.source_uv.empty()) {
      return;
    }
    out_.source_uv.resize(static_cast<size_t>(n_new_));
    for (int p = 0; p < n_new_; ++p) {
      const SubdivisionParents& parents = result_.parents[static_cast<size_t>(p)];
      Eigen::Vector2d uv = Eigen::Vector2d::Zero();
      for (int k = 0; k < parents.count; ++k) {
        uv += grid_.source_uv[static_cast<size_t>(parents.parent[static_cast<size_t>(k)])];
      }
      out_.source_uv[static_cast<size_t>(p)] = uv / parents.count;
    }
  }

  // Connectivity. Halfedge h of a face runs a -> b; the face's corners in order with the edge
  // particles between them. Sub-faces keep the parent's counter-clockwise turning.
  void connect() {
    GridMesh& refined = out_.mesh;
    refined.reserve(static_cast<size_t>(n_new_),
                    2 * static_cast<size_t>(ne_) + 4 * static_cast<size_t>(nf_),
                    4 * static_cast<size_t>(nf_));
    for (int p = 0; p < n_new_; ++p) {
      const Eigen::Vector3d& x = positions_[static_cast<size_t>(p)];
      refined.add_vertex(OpenMesh::Vec3d(x.x(), x.y(), x.z()));
    }
    auto vh = [&](int i) { return refined.vertex_handle(static_cast<unsigned>(i)); };
    auto add = [&](std::initializer_list<int> corners, int parent_face) {
      std::vector<GridMesh::VertexHandle> handles;
      for (int c : corners) {
        handles.push_back(vh(c));
      }
      if (!refined.add_face(handles).is_valid()) {
        throw NumericalError(
            name_, "cannot refine face " + std::to_string(parent_face) + " (non-manifold grid)");
      }
    };
    std::vector<int> corner, edge;  // corner[k], and the particle of edge (corner[k], corner[k+1])
    for (const auto fh : mesh_.faces()) {
      corner.clear();
      edge.clear();
      for (const auto heh : mesh_.fh_range(fh)) {
        corner.push_back(mesh_.from_vertex_handle(heh).idx());
        edge.push_back(np_ + mesh_.edge_handle(heh).idx());
      }
      const int f = fh.idx();
      if (corner.size() == 3) {
        // Corner triangles (c_k, e_k, e_{k-1}) and the middle one (e_0, e_1, e_2).
        for (int k = 0; k < 3; ++k) {
          add({corner[k], edge[k], edge[(k + 2) % 3]}, f);
        }
        add({edge[0], edge[1], edge[2]}, f);
      } else {
        const int centre = face_particle_[static_cast<size_t>(f)];
        for (int k = 0; k < 4; ++k) {
          add({corner[k], edge[k], centre, edge[(k + 3) % 4]}, f);
        }
      }
    }
  }

  const ParticleGrid& grid_;
  const SurfaceProjector& source_;
  const SurfaceCurve& curve_;
  const GridSubdivisionOptions& options_;
  const std::string& name_;
  const GridMesh& mesh_;
  int np_, ne_, nf_;
  int n_new_ = 0;
  GridSubdivisionResult result_;
  ParticleGrid& out_;
  std::vector<int> face_particle_;
  std::vector<int> boundary_edge_;
  std::vector<char> edge_on_boundary_;
  std::vector<Eigen::Vector3d> positions_;
  Eigen::Matrix3Xd coarse_;
};

}  // namespace

GridSubdivisionResult subdivide_grid(const ParticleGrid& grid, const SurfaceProjector& source,
                                     const SurfaceCurve& source_curve,
                                     const GridSubdivisionOptions& options) {
  check_inputs(grid, source_curve, options);
  return GridRefiner(grid, source, source_curve, options).run();
}

namespace detail {

std::vector<ClosestPoint> closest_to_parents_mean(const SurfaceProjector& surface,
                                                  const std::vector<SubdivisionParents>& parents,
                                                  const std::vector<int>& particles,
                                                  const Eigen::Matrix3Xd& coarse_positions,
                                                  const std::vector<SurfacePoint>& coarse_points) {
  std::vector<Eigen::Vector3d> queries(particles.size());
  std::vector<SurfacePoint> hints(particles.size());
  for (size_t k = 0; k < particles.size(); ++k) {
    const SubdivisionParents& p = parents[static_cast<size_t>(particles[k])];
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    for (int j = 0; j < p.count; ++j) {
      x += coarse_positions.col(p.parent[static_cast<size_t>(j)]);
    }
    queries[k] = x / p.count;
    hints[k] = coarse_points[static_cast<size_t>(p.parent[0])];
  }
  std::vector<ClosestPoint> answers(particles.size());
  surface.closest(std::span<const Eigen::Vector3d>(queries), std::span<ClosestPoint>(answers),
                  std::span<const SurfacePoint>(hints));
  return answers;
}

}  // namespace detail

}  // namespace elastic
