// Construction of the limit surface (limit_surface.h): validation against the manifold policy, the
// OpenSubdiv refiner, the ptex numbering, then the patches (limit_surface_patches.cpp) and the ptex
// adjacency (limit_surface_walk.cpp); and the small queries. Evaluation, curvature and walking
// live in their own files (detail/limit_surface_impl.h lists them).
#include "elastic/surface/limit_surface.h"

#include <opensubdiv/far/error.h>
#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/ptexIndices.h>
#include <opensubdiv/far/topologyDescriptor.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "elastic/core/error.h"
#include "elastic/mesh/mesh_validation.h"
#include "elastic/surface/detail/limit_surface_impl.h"

namespace elastic {
namespace {

namespace Far = OpenSubdiv::Far;
namespace Sdc = OpenSubdiv::Sdc;

// ---------------------------------------------------------------------------------------------
// OpenSubdiv reports topology problems through process-wide callbacks that print by default. The
// library never prints: the callbacks keep the last message of the calling thread, which the
// constructor turns into an InvalidInputError when the factory gives up.
thread_local std::string osd_last_message;

void osd_error_callback(Far::ErrorType /*type*/, const char* message) {
  osd_last_message = message ? message : "OpenSubdiv error";
}
void osd_warning_callback(const char* message) {
  osd_last_message = message ? message : "OpenSubdiv warning";
}
void install_osd_callbacks() {
  static std::once_flag once;
  std::call_once(once, [] {
    Far::SetErrorCallback(osd_error_callback);
    Far::SetWarningCallback(osd_warning_callback);
  });
}

/// The scheme `requested` resolves to for a mesh that is (or not) all triangles; an empty
/// optional when Loop is forced on other faces.
std::optional<SubdivisionScheme> resolve_scheme(SubdivisionScheme requested, bool all_triangles) {
  switch (requested) {
    case SubdivisionScheme::Automatic:
      return all_triangles ? SubdivisionScheme::Loop : SubdivisionScheme::CatmullClark;
    case SubdivisionScheme::Loop:
      if (!all_triangles) {
        return std::nullopt;
      }
      return SubdivisionScheme::Loop;
    case SubdivisionScheme::CatmullClark:
      return SubdivisionScheme::CatmullClark;
  }
  return std::nullopt;
}

/// The arrays a Far::TopologyDescriptor points into (it owns none of them).
struct TopologyArrays {
  std::vector<int> verts_per_face;
  std::vector<Far::Index> crease_pairs;
  std::vector<float> crease_weights;
  std::vector<Far::Index> corner_vertices;
  std::vector<float> corner_weights;

  TopologyArrays(const PolygonMesh& mesh, bool use_creases) {
    verts_per_face.resize(static_cast<size_t>(mesh.num_faces()));
    for (int f = 0; f < mesh.num_faces(); ++f) {
      verts_per_face[static_cast<size_t>(f)] = mesh.face_size(f);
    }
    if (!use_creases) {
      return;
    }
    for (const Crease& c : mesh.creases) {
      crease_pairs.push_back(c.v0);
      crease_pairs.push_back(c.v1);
      crease_weights.push_back(static_cast<float>(c.sharpness));
    }
    for (const auto& [v, sharpness] : mesh.corners) {
      corner_vertices.push_back(v);
      corner_weights.push_back(static_cast<float>(sharpness));
    }
  }

  Far::TopologyDescriptor descriptor(const PolygonMesh& mesh) const {
    Far::TopologyDescriptor desc;
    desc.numVertices = mesh.num_vertices();
    desc.numFaces = mesh.num_faces();
    desc.numVertsPerFace = verts_per_face.data();
    desc.vertIndicesPerFace = mesh.face_vertices.data();
    desc.numCreases = static_cast<int>(crease_weights.size());
    desc.creaseVertexIndexPairs = crease_pairs.data();
    desc.creaseWeights = crease_weights.data();
    desc.numCorners = static_cast<int>(corner_weights.size());
    desc.cornerVertexIndices = corner_vertices.data();
    desc.cornerWeights = corner_weights.data();
    return desc;
  }
};

}  // namespace

// ---------------------------------------------------------------------------------------------
// Input validation. OpenSubdiv accepts non-manifold topology silently (it tags it and makes it
// sharp), so the mesh must pass the manifold policy of mesh/ (manifold_problem, its wording too)
// first; what a limit surface can carry (zero-area faces, several components, unreferenced
// vertices) is accepted.
ManifoldRequirements LimitSurface::Impl::requirements() {
  ManifoldRequirements r;
  r.allow_several_components = true;
  r.allow_zero_area_faces = true;
  r.allow_unreferenced_vertices = true;
  r.validation.max_examples = 5;
  return r;
}

void LimitSurface::Impl::validate_topology(const LimitSurfaceOptions& options) {
  if (options.isolation_level < 1 || options.isolation_level > 10) {
    fail("isolation_level " + std::to_string(options.isolation_level) + " is out of range 1..10");
  }
  if (options.smooth_isolation_level != -1 &&
      (options.smooth_isolation_level < 1 ||
       options.smooth_isolation_level > options.isolation_level)) {
    fail("smooth_isolation_level " + std::to_string(options.smooth_isolation_level) +
         " is out of range 1..isolation_level (" + std::to_string(options.isolation_level) +
         ") or -1");
  }
  const int nf = mesh.num_faces();
  if (nf > 0 &&
      (static_cast<int>(mesh.face_offsets.size()) != nf + 1 || mesh.face_offsets.front() != 0 ||
       mesh.face_offsets.back() != static_cast<int>(mesh.face_vertices.size()))) {
    fail("inconsistent face offsets");
  }
  const ManifoldRequirements required = requirements();
  const std::string problem =
      manifold_problem(mesh, validate_mesh(mesh, required.validation), required);
  if (!problem.empty()) {
    fail(problem);
  }
  if (options.use_creases) {
    validate_creases();
  }
}

// Creases must be edges of the mesh and corners its vertices, with finite sharpness >= 0.
void LimitSurface::Impl::validate_creases() const {
  const int nv = mesh.num_vertices();
  const int nf = mesh.num_faces();
  // Undirected edges as sorted keys min * nv + max, to check that creases are edges.
  std::vector<int64_t> edges;
  edges.reserve(mesh.face_vertices.size());
  for (int f = 0; f < nf; ++f) {
    const auto fv = mesh.face(f);
    const size_t n = fv.size();
    for (size_t i = 0; i < n; ++i) {
      const int a = fv[i], b = fv[(i + 1) % n];
      edges.push_back(static_cast<int64_t>(std::min(a, b)) * nv + std::max(a, b));
    }
  }
  std::sort(edges.begin(), edges.end());
  for (const Crease& c : mesh.creases) {
    const int64_t key = static_cast<int64_t>(std::min(c.v0, c.v1)) * nv + std::max(c.v0, c.v1);
    const bool in_range = c.v0 >= 0 && c.v0 < nv && c.v1 >= 0 && c.v1 < nv;
    if (!in_range || !std::binary_search(edges.begin(), edges.end(), key)) {
      fail("crease (" + std::to_string(c.v0) + ", " + std::to_string(c.v1) +
           ") is not an edge of the mesh");
    }
    if (!std::isfinite(c.sharpness) || c.sharpness < 0.0) {
      fail("crease (" + std::to_string(c.v0) + ", " + std::to_string(c.v1) +
           ") has an invalid sharpness");
    }
  }
  for (const auto& [v, sharpness] : mesh.corners) {
    if (v < 0 || v >= nv) {
      fail("corner tag on vertex " + std::to_string(v) + ", which does not exist");
    }
    if (!std::isfinite(sharpness) || sharpness < 0.0) {
      fail("corner tag on vertex " + std::to_string(v) + " has an invalid sharpness");
    }
  }
}

void LimitSurface::Impl::build_refiner(const LimitSurfaceOptions& options) {
  const std::optional<SubdivisionScheme> resolved =
      resolve_scheme(options.scheme, mesh.is_triangle_mesh());
  if (!resolved) {
    fail("the Loop scheme needs a triangle mesh, and this mesh has other faces");
  }
  scheme = *resolved;
  triangle = scheme == SubdivisionScheme::Loop;
  domain = PtexDomain(triangle);

  const TopologyArrays arrays(mesh, options.use_creases);
  const Far::TopologyDescriptor desc = arrays.descriptor(mesh);
  Sdc::Options sdc;
  sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
  sdc.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_ALL);
  using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
  const Sdc::SchemeType type = triangle ? Sdc::SCHEME_LOOP : Sdc::SCHEME_CATMARK;

  install_osd_callbacks();
  osd_last_message.clear();
  refiner.reset(Factory::Create(desc, Factory::Options(type, sdc)));
  if (!refiner) {
    fail("OpenSubdiv cannot build the topology" +
         (osd_last_message.empty() ? std::string() : ": " + osd_last_message));
  }
  check_refiner_manifold();
}

// OpenSubdiv's own verdict on vertex manifoldness, a safety net behind the manifold policy (which
// already rejects a vertex whose faces form more than one fan), in the policy's words.
void LimitSurface::Impl::check_refiner_manifold() const {
  const Far::TopologyLevel& base = refiner->GetLevel(0);
  MeshValidation flagged;
  for (int v = 0; v < base.GetNumVertices(); ++v) {
    if (base.GetVertexFaces(v).size() > 0 && base.IsVertexNonManifold(v)) {
      if (flagged.non_manifold_vertices.count++ < requirements().validation.max_examples) {
        flagged.non_manifold_vertices.examples.push_back(v);
      }
    }
  }
  if (flagged.non_manifold_vertices.count > 0) {
    fail(manifold_problem(mesh, flagged, requirements()));
  }
}

// Ptex numbering from OpenSubdiv itself (adaptive refinement changes nothing about it), and the
// first face and corner of each control vertex.
void LimitSurface::Impl::build_ptex_numbering() {
  const Far::PtexIndices ptex(*refiner);
  const int nf = mesh.num_faces();
  control_to_ptex.resize(static_cast<size_t>(nf) + 1);
  for (int f = 0; f < nf; ++f) {
    control_to_ptex[static_cast<size_t>(f)] = ptex.GetFaceId(f);
  }
  control_to_ptex[static_cast<size_t>(nf)] = ptex.GetNumFaces();
  ptex_to_control.resize(static_cast<size_t>(ptex.GetNumFaces()));
  for (int f = 0; f < nf; ++f) {
    for (int i = control_to_ptex[static_cast<size_t>(f)];
         i < control_to_ptex[static_cast<size_t>(f) + 1]; ++i) {
      ptex_to_control[static_cast<size_t>(i)] = f;
    }
  }

  vertex_face_corner.assign(static_cast<size_t>(mesh.num_vertices()), {-1, -1});
  for (int f = 0; f < nf; ++f) {
    const auto fv = mesh.face(f);
    for (int c = 0; c < static_cast<int>(fv.size()); ++c) {
      auto& slot = vertex_face_corner[static_cast<size_t>(fv[static_cast<size_t>(c)])];
      if (slot.first < 0) {
        slot = {f, c};
      }
    }
  }
}

// =============================================================================================
LimitSurface::LimitSurface(const PolygonMesh& mesh, const LimitSurfaceOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.mesh = mesh;
  m.name = options.name;
  m.validate_topology(options);
  m.build_refiner(options);
  m.build_ptex_numbering();
  m.smooth_isolation_level = options.smooth_isolation_level != -1 ? options.smooth_isolation_level
                             : mesh.num_faces() > kDenseMeshFaces
                                 ? std::min(2, options.isolation_level)
                                 : options.isolation_level;
  m.build_patches(options.isolation_level, m.smooth_isolation_level);
  if (m.patch_table->GetNumPtexFaces() != static_cast<int>(m.ptex_to_control.size())) {
    m.fail("OpenSubdiv's patch table and ptex indices disagree on the number of ptex faces");
  }
  m.build_adjacency();
}

LimitSurface::~LimitSurface() = default;
LimitSurface::LimitSurface(LimitSurface&&) noexcept = default;
LimitSurface& LimitSurface::operator=(LimitSurface&&) noexcept = default;

SubdivisionScheme LimitSurface::scheme() const {
  return impl_->scheme;
}
const std::string& LimitSurface::name() const {
  return impl_->name;
}
int LimitSurface::num_faces() const {
  return static_cast<int>(impl_->ptex_to_control.size());
}

int LimitSurface::smooth_isolation_level() const {
  return impl_->smooth_isolation_level;
}

int LimitSurface::control_face(int ptex_face) const {
  if (ptex_face < 0 || ptex_face >= num_faces()) {
    impl_->fail("ptex face " + std::to_string(ptex_face) + " does not exist");
  }
  return impl_->ptex_to_control[static_cast<size_t>(ptex_face)];
}

int LimitSurface::first_ptex_face(int control_face) const {
  if (control_face < 0 || control_face >= impl_->mesh.num_faces()) {
    impl_->fail("control face " + std::to_string(control_face) + " does not exist");
  }
  return impl_->control_to_ptex[static_cast<size_t>(control_face)];
}

const PolygonMesh& LimitSurface::control_mesh() const {
  return impl_->mesh;
}

bool LimitSurface::in_domain(const SurfacePoint& p, double tolerance) const {
  if (p.face < 0 || p.face >= num_faces()) {
    return false;
  }
  return impl_->domain.contains(p.uv(), tolerance);  // also rejects NaN
}

SurfacePoint LimitSurface::vertex_point(int control_vertex) const {
  const Impl& m = *impl_;
  if (control_vertex < 0 || control_vertex >= m.mesh.num_vertices()) {
    m.fail("control vertex " + std::to_string(control_vertex) + " does not exist");
  }
  const auto [f, c] = m.vertex_face_corner[static_cast<size_t>(control_vertex)];
  if (f < 0) {
    m.fail("control vertex " + std::to_string(control_vertex) + " belongs to no face");
  }
  const int first = m.control_to_ptex[static_cast<size_t>(f)];
  if (m.triangle || m.mesh.face_size(f) == 4) {
    const Eigen::Vector2d uv = m.domain.corner(c);
    return {first, uv.x(), uv.y()};
  }
  return {first + c, 0.0, 0.0};  // an n-gon's sub-face c has the corner vertex at (0, 0)
}

SurfacePoint LimitSurface::face_center(int ptex_face) const {
  if (ptex_face < 0 || ptex_face >= num_faces()) {
    impl_->fail("ptex face " + std::to_string(ptex_face) + " does not exist");
  }
  const Eigen::Vector2d c = impl_->domain.centre();
  return {ptex_face, c.x(), c.y()};
}

}  // namespace elastic
