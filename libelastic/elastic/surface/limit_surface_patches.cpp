// The patch table of the limit surface (limit_surface.h): adaptive refinement, the positions of
// every refined vertex and end-cap point, and each patch's control points gathered into one
// contiguous block in the order the evaluator reads them (limit_surface_evaluation.cpp).
#include <opensubdiv/far/patchMap.h>
#include <opensubdiv/far/patchTable.h>
#include <opensubdiv/far/patchTableFactory.h>
#include <opensubdiv/far/primvarRefiner.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "elastic/core/error.h"
#include "elastic/surface/detail/limit_surface_impl.h"
#include "elastic/surface/limit_surface.h"

namespace elastic {
namespace {

namespace Far = OpenSubdiv::Far;
using limit_surface_detail::PatchKind;
using limit_surface_detail::PatchRecord;

/// Primvar type for OpenSubdiv's refiner and stencil tables, in double precision. The weights come
/// as float or double depending on the table, hence the templated AddWithWeight.
struct Point3 {
  double x = 0.0, y = 0.0, z = 0.0;
  void Clear(void* = nullptr) { x = y = z = 0.0; }
  template <class W>
  void AddWithWeight(const Point3& src, W weight) {
    const double w = static_cast<double>(weight);
    x += w * src.x;
    y += w * src.y;
    z += w * src.z;
  }
};

/// Positions of every refined vertex (all levels), then the end caps' local points. Patch control
/// point indices address this concatenation.
/// \throws InvalidInputError naming `name` when the table has local points but no stencils.
std::vector<Point3> refined_points(const PolygonMesh& mesh, const Far::TopologyRefiner& refiner,
                                   const Far::PatchTable& table, const std::string& name) {
  const int num_refined = refiner.GetNumVerticesTotal();
  const int num_local = table.GetNumLocalPoints();
  std::vector<Point3> points(static_cast<size_t>(num_refined + num_local));
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const Eigen::Vector3d& x = mesh.positions[static_cast<size_t>(v)];
    points[static_cast<size_t>(v)] = {x.x(), x.y(), x.z()};
  }
  Far::PrimvarRefinerReal<double> primvar(refiner);
  Point3* src = points.data();
  for (int level = 1; level <= refiner.GetMaxLevel(); ++level) {
    Point3* dst = src + refiner.GetLevel(level - 1).GetNumVertices();
    primvar.Interpolate(level, src, dst);
    src = dst;
  }
  if (num_local > 0) {
    // PatchTable::ComputeLocalPointValues asserts on double-precision tables: use the stencils.
    const auto* stencils = table.GetLocalPointStencilTable<double>();
    if (!stencils) {
      throw InvalidInputError(name, "OpenSubdiv built no local point stencils");
    }
    stencils->UpdateValues(points.data(), points.data() + num_refined);
  }
  return points;
}

/// How a patch of kind `type` with parameters `param` is evaluated (all but its control points).
PatchRecord patch_record(Far::PatchDescriptor::Type type, const Far::PatchParam& param,
                         bool triangle) {
  PatchRecord rec;
  const int depth = param.GetDepth();
  const bool non_quad = param.NonQuadRoot();
  rec.scale = std::ldexp(1.0, depth - (non_quad ? 1 : 0));
  rec.origin_u = param.GetU();
  rec.origin_v = param.GetV();
  switch (type) {
    case Far::PatchDescriptor::REGULAR:
      rec.kind = PatchKind::BSpline;
      break;
    case Far::PatchDescriptor::GREGORY_BASIS:
      rec.kind = PatchKind::Gregory;
      break;
    case Far::PatchDescriptor::GREGORY_TRIANGLE:
      rec.kind = PatchKind::GregoryTriangle;
      break;
    default:
      rec.kind = PatchKind::OpenSubdiv;
      break;
  }
  rec.rotated_triangle = triangle && param.IsTriangleRotated();
  if (rec.rotated_triangle) {
    // PatchParam::NormalizeTriangle: s = (2^depth - U) - u * 2^depth.
    rec.origin_u = std::ldexp(1.0, depth) - param.GetU();
    rec.origin_v = std::ldexp(1.0, depth) - param.GetV();
  }
  // OpenSubdiv scales derivatives by 2^depth, which is right for quads but twice the ptex
  // derivative under a non-quad root (whose sub-faces are already one level down).
  rec.derivative_fix = non_quad ? 0.5 : 1.0;
  return rec;
}

/// Substitutes the phantom points of a regular patch's 4x4 net beyond boundary edges by linear
/// extrapolation (the rule OpenSubdiv applies to the basis weights): row 0 / column 3 / row 3 /
/// column 0 for boundary bits 1 / 2 / 4 / 8. The substitutions commute, so corners come out right
/// in any order.
void substitute_phantom_points(std::array<Eigen::Vector3d, 16>& p, int boundary) {
  auto at = [&](int row, int col) -> Eigen::Vector3d& {
    return p[4 * static_cast<size_t>(row) + static_cast<size_t>(col)];
  };
  for (int j = 0; j < 4; ++j) {
    if (boundary & 8) {
      at(j, 0) = 2.0 * at(j, 1) - at(j, 2);
    }
    if (boundary & 2) {
      at(j, 3) = 2.0 * at(j, 2) - at(j, 1);
    }
  }
  for (int j = 0; j < 4; ++j) {
    if (boundary & 1) {
      at(0, j) = 2.0 * at(1, j) - at(2, j);
    }
    if (boundary & 4) {
      at(3, j) = 2.0 * at(2, j) - at(1, j);
    }
  }
}

/// The number of control points the gathered block holds (each patch's own: 16 for a regular
/// one, its phantom points substituted).
size_t gathered_size(const Far::PatchTable& table) {
  size_t total_points = 0;
  for (int array = 0; array < table.GetNumPatchArrays(); ++array) {
    total_points +=
        static_cast<size_t>(table.GetPatchArrayDescriptor(array).GetNumControlVertices()) *
        static_cast<size_t>(table.GetNumPatches(array));
  }
  return total_points;
}

}  // namespace

void LimitSurface::Impl::build_patches(int isolation, int smooth_isolation) {
  Far::PatchTableFactory::Options patch_options(static_cast<unsigned int>(isolation));
  patch_options.SetPatchPrecision<double>();
  // Gregory basis end caps around extraordinary vertices; for Loop the factory makes them Gregory
  // triangles. Smooth corners keep the legacy sharp patches (the factory default).
  patch_options.SetEndCapType(Far::PatchTableFactory::Options::ENDCAP_GREGORY_BASIS);
  patch_options.generateVaryingTables = false;
  patch_options.generateVaryingLocalPoints = false;

  Far::TopologyRefiner::AdaptiveOptions adaptive = patch_options.GetRefineAdaptiveOptions();
  adaptive.SetSecondaryLevel(smooth_isolation);
  refiner->RefineAdaptive(adaptive);
  patch_table.reset(Far::PatchTableFactory::Create(*refiner, patch_options));
  if (!patch_table) {
    fail("OpenSubdiv could not build the patch table");
  }
  const std::vector<Point3> points = refined_points(mesh, *refiner, *patch_table, name);
  auto point = [&](Far::Index i) -> Eigen::Vector3d {
    if (i < 0) {
      return Eigen::Vector3d::Zero();
    }
    const Point3& q = points[static_cast<size_t>(i)];
    return {q.x, q.y, q.z};
  };

  // Gather each patch's control points so that evaluation reads one contiguous block. The block is
  // allocated at its exact size: on meshes with many extraordinary vertices it holds tens of
  // millions of points (8.7 million for the 70,000-face nefertiti-lowres.obj), and growing it by
  // doubling touched (and the kernel zeroed) about three times its final size, which dominated
  // loading. Every patch of an array has the same number of points, so each patch's block is
  // known up front and the patches are gathered in parallel (0.45 s of that scan's loading on one
  // thread); the block is the same whatever the thread count.
  patches.assign(static_cast<size_t>(patch_table->GetNumPatchesTotal()), PatchRecord{});
  patch_points.clear();
  patch_points.resize(gathered_size(*patch_table));
  int first_patch = 0;
  size_t first_point = 0;
  for (int array = 0; array < patch_table->GetNumPatchArrays(); ++array) {
    const Far::PatchDescriptor desc = patch_table->GetPatchArrayDescriptor(array);
    const bool regular = desc.GetType() == Far::PatchDescriptor::REGULAR;
    const int per_patch = desc.GetNumControlVertices();  // 16 for a regular patch
    const int count = patch_table->GetNumPatches(array);
    tbb::parallel_for(
        tbb::blocked_range<int>(0, count, 1024), [&](const tbb::blocked_range<int>& r) {
          for (int i = r.begin(); i != r.end(); ++i) {
            const Far::ConstIndexArray cvs = patch_table->GetPatchVertices(array, i);
            const Far::PatchParam param = patch_table->GetPatchParam(array, i);
            PatchRecord& rec = patches[static_cast<size_t>(first_patch) + static_cast<size_t>(i)];
            rec = patch_record(desc.GetType(), param, triangle);
            const size_t at = first_point + static_cast<size_t>(per_patch) * static_cast<size_t>(i);
            rec.first_point = static_cast<int>(at);
            rec.num_points = cvs.size();
            Eigen::Vector3d* out = patch_points.data() + at;
            if (regular) {
              std::array<Eigen::Vector3d, 16> p;
              for (int k = 0; k < 16; ++k) {
                p[static_cast<size_t>(k)] = point(cvs[k]);
              }
              substitute_phantom_points(p, param.GetBoundary());
              std::copy(p.begin(), p.end(), out);
            } else {
              for (int k = 0; k < cvs.size(); ++k) {
                out[k] = point(cvs[k]);
              }
            }
          }
        });
    if (count > 0) {
      max_patch_points = std::max(max_patch_points, per_patch);
    }
    first_patch += count;
    first_point += static_cast<size_t>(per_patch) * static_cast<size_t>(count);
  }
  patch_map = std::make_unique<Far::PatchMap>(*patch_table);
}

}  // namespace elastic
