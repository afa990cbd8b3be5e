#include "elastic/particles/grid_subdivision.h"

#include <cmath>
#include <span>

#include "elastic/core/error.h"

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

}  // namespace

GridSubdivisionResult subdivide_grid(const ParticleGrid& grid, const SurfaceProjector& source,
                                     const SurfaceCurve& source_curve,
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

  const int ne = static_cast<int>(mesh.n_edges());
  const int nf = static_cast<int>(mesh.n_faces());
  for (const auto fh : mesh.faces()) {
    const auto valence = mesh.valence(fh);
    if (valence != 3 && valence != 4) {
      throw InvalidInputError(name, "face " + std::to_string(fh.idx()) + " has " +
                                        std::to_string(valence) +
                                        " corners (grids have triangles and quads)");
    }
  }

  GridSubdivisionResult result;
  result.coarse_particles = np;

  // Indices of the refined particles: old ones keep theirs, then one per edge, then one per quad.
  std::vector<int> face_particle(static_cast<size_t>(nf), -1);
  int next = np + ne;
  for (const auto fh : mesh.faces()) {
    if (mesh.valence(fh) == 4) {
      face_particle[static_cast<size_t>(fh.idx())] = next++;
    }
  }
  const int n_new = next;
  result.edge_particles = ne;
  result.face_particles = n_new - np - ne;

  result.parents.resize(static_cast<size_t>(n_new));
  for (int i = 0; i < np; ++i) {
    result.parents[static_cast<size_t>(i)] = {{i, -1, -1, -1}, 1};
  }
  for (const auto eh : mesh.edges()) {
    const auto heh = mesh.halfedge_handle(eh, 0);
    result.parents[static_cast<size_t>(np + eh.idx())] = {
        {mesh.from_vertex_handle(heh).idx(), mesh.to_vertex_handle(heh).idx(), -1, -1}, 2};
  }
  for (const auto fh : mesh.faces()) {
    const int p = face_particle[static_cast<size_t>(fh.idx())];
    if (p < 0) {
      continue;
    }
    SubdivisionParents& parents = result.parents[static_cast<size_t>(p)];
    for (const auto vh : mesh.fv_range(fh)) {
      parents.parent[static_cast<size_t>(parents.count++)] = vh.idx();
    }
  }

  // Boundary edges: the mesh's boundary must be exactly the boundary loop, edge k joining loop[k]
  // and loop[k+1]. Their edge particles become boundary particles at the mid-parameter.
  const size_t m = grid.boundary_loop.size();
  std::vector<int> boundary_edge(m, -1);
  std::vector<char> edge_on_boundary(static_cast<size_t>(ne), 0);
  for (size_t k = 0; k < m; ++k) {
    const int a = grid.boundary_loop[k], b = grid.boundary_loop[(k + 1) % m];
    if (a < 0 || a >= np || b < 0 || b >= np) {
      throw InvalidInputError(name, "boundary loop index out of range");
    }
    const auto heh = mesh.find_halfedge(mesh.vertex_handle(static_cast<unsigned>(a)),
                                        mesh.vertex_handle(static_cast<unsigned>(b)));
    if (!heh.is_valid() || !mesh.is_boundary(mesh.edge_handle(heh))) {
      throw InvalidInputError(name, "boundary particles " + std::to_string(a) + " and " +
                                        std::to_string(b) +
                                        " are consecutive on the curve but not joined by a "
                                        "boundary edge of the grid");
    }
    const int e = mesh.edge_handle(heh).idx();
    boundary_edge[k] = e;
    edge_on_boundary[static_cast<size_t>(e)] = 1;
  }
  int mesh_boundary_edges = 0;
  for (const auto eh : mesh.edges()) {
    mesh_boundary_edges += mesh.is_boundary(eh) ? 1 : 0;
  }
  if (mesh_boundary_edges != static_cast<int>(m)) {
    throw InvalidInputError(name, "the grid's boundary has " + std::to_string(mesh_boundary_edges) +
                                      " edges but the boundary loop " + std::to_string(m) +
                                      " particles (holes or a second boundary)");
  }

  // Source placement.
  ParticleGrid& out = result.grid;
  out.source_points.resize(static_cast<size_t>(n_new));
  out.is_boundary.assign(static_cast<size_t>(n_new), 0);
  std::vector<Eigen::Vector3d> positions(static_cast<size_t>(n_new));
  const Eigen::Matrix3Xd coarse = grid.source_positions();
  const LimitSurface& surface = source.surface();
  for (int i = 0; i < np; ++i) {
    out.source_points[static_cast<size_t>(i)] = grid.source_points[static_cast<size_t>(i)];
    out.is_boundary[static_cast<size_t>(i)] = grid.is_boundary[static_cast<size_t>(i)];
    positions[static_cast<size_t>(i)] = coarse.col(i);
  }

  // Boundary: loop[k], then the particle of edge (loop[k], loop[k+1]), keeps the loop's
  // counter-clockwise order; the parameters interleave the same way.
  const std::vector<double> cumulative = source_curve.arc_lengths();
  const double total = source_curve.length();
  out.boundary_loop.reserve(2 * m);
  out.boundary_parameter.reserve(2 * m);
  for (size_t k = 0; k < m; ++k) {
    const int p = np + boundary_edge[k];
    const double s =
        mid_parameter(grid.boundary_parameter[k], grid.boundary_parameter[(k + 1) % m]);
    const SurfaceCurve::Location at = source_curve.locate(s, cumulative, total);
    positions[static_cast<size_t>(p)] = at.position;
    if (options.boundary_point) {
      out.source_points[static_cast<size_t>(p)] = options.boundary_point(s);
    } else {
      // The chord point is within the tessellation's tolerance of the surface; its closest point,
      // warm-started at a neighbour on the curve, is the surface point under it.
      out.source_points[static_cast<size_t>(p)] =
          source
              .closest(at.position, grid.source_points[static_cast<size_t>(grid.boundary_loop[k])])
              .point;
    }
    out.is_boundary[static_cast<size_t>(p)] = 1;
    out.boundary_loop.push_back(grid.boundary_loop[k]);
    out.boundary_parameter.push_back(grid.boundary_parameter[k]);
    out.boundary_loop.push_back(p);
    out.boundary_parameter.push_back(s);
  }
  result.boundary_particles = static_cast<int>(m);

  // Interior new particles: average in the plane, else the magnet of the average 3D position.
  std::vector<int> magnet;  // refined indices placed by the magnet
  for (int p = np; p < n_new; ++p) {
    if (p < np + ne && edge_on_boundary[static_cast<size_t>(p - np)]) {
      continue;
    }
    const SubdivisionParents& parents = result.parents[static_cast<size_t>(p)];
    bool placed = false;
    if (use_plane) {
      Eigen::Vector2d w = Eigen::Vector2d::Zero();
      for (int k = 0; k < parents.count; ++k) {
        w += options.plane_coordinates[static_cast<size_t>(parents.parent[static_cast<size_t>(k)])];
      }
      w /= parents.count;
      SurfacePoint q;
      if (options.plane_to_surface(w, q) && q.valid()) {
        out.source_points[static_cast<size_t>(p)] = q;
        positions[static_cast<size_t>(p)] = surface.position(q);
        placed = true;
      }
    }
    if (!placed) {
      magnet.push_back(p);
    }
  }
  if (!magnet.empty()) {
    std::vector<Eigen::Vector3d> queries(magnet.size());
    std::vector<SurfacePoint> hints(magnet.size());
    for (size_t k = 0; k < magnet.size(); ++k) {
      const SubdivisionParents& parents = result.parents[static_cast<size_t>(magnet[k])];
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      for (int j = 0; j < parents.count; ++j) {
        x += coarse.col(parents.parent[static_cast<size_t>(j)]);
      }
      queries[k] = x / parents.count;
      hints[k] = grid.source_points[static_cast<size_t>(parents.parent[0])];
    }
    std::vector<ClosestPoint> answers(magnet.size());
    source.closest(std::span<const Eigen::Vector3d>(queries), std::span<ClosestPoint>(answers),
                   std::span<const SurfacePoint>(hints));
    for (size_t k = 0; k < magnet.size(); ++k) {
      out.source_points[static_cast<size_t>(magnet[k])] = answers[k].point;
      positions[static_cast<size_t>(magnet[k])] = answers[k].position;
    }
  }
  result.magnet_placements = static_cast<int>(magnet.size());

  if (!grid.source_uv.empty()) {
    out.source_uv.resize(static_cast<size_t>(n_new));
    for (int p = 0; p < n_new; ++p) {
      const SubdivisionParents& parents = result.parents[static_cast<size_t>(p)];
      Eigen::Vector2d uv = Eigen::Vector2d::Zero();
      for (int k = 0; k < parents.count; ++k) {
        uv += grid.source_uv[static_cast<size_t>(parents.parent[static_cast<size_t>(k)])];
      }
      out.source_uv[static_cast<size_t>(p)] = uv / parents.count;
    }
  }

  // Connectivity. Halfedge h of a face runs a -> b; the face's corners in order with the edge
  // particles between them. Sub-faces keep the parent's counter-clockwise turning.
  GridMesh& refined = out.mesh;
  refined.reserve(static_cast<size_t>(n_new),
                  2 * static_cast<size_t>(ne) + 4 * static_cast<size_t>(nf),
                  4 * static_cast<size_t>(nf));
  for (int p = 0; p < n_new; ++p) {
    const Eigen::Vector3d& x = positions[static_cast<size_t>(p)];
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
          name, "cannot refine face " + std::to_string(parent_face) + " (non-manifold grid)");
    }
  };
  std::vector<int> corner, edge;  // corner[k], and the particle of edge (corner[k], corner[k+1])
  for (const auto fh : mesh.faces()) {
    corner.clear();
    edge.clear();
    for (const auto heh : mesh.fh_range(fh)) {
      corner.push_back(mesh.from_vertex_handle(heh).idx());
      edge.push_back(np + mesh.edge_handle(heh).idx());
    }
    const int f = fh.idx();
    if (corner.size() == 3) {
      // Corner triangles (c_k, e_k, e_{k-1}) and the middle one (e_0, e_1, e_2).
      for (int k = 0; k < 3; ++k) {
        add({corner[k], edge[k], edge[(k + 2) % 3]}, f);
      }
      add({edge[0], edge[1], edge[2]}, f);
    } else {
      const int centre = face_particle[static_cast<size_t>(f)];
      for (int k = 0; k < 4; ++k) {
        add({corner[k], edge[k], centre, edge[(k + 3) % 4]}, f);
      }
    }
  }
  out.build_springs();
  return result;
}

}  // namespace elastic
