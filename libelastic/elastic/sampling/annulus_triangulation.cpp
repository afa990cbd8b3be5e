#include "elastic/sampling/annulus_triangulation.h"

// CGAL's Compact_container trips GCC's -Wnull-dereference after inlining (a false positive inside
// CGAL, reported at optimisation time, so system-header suppression does not catch it). This file
// holds nothing but the CGAL call, so the warning is silenced for the whole translation unit.
#pragma GCC diagnostic ignored "-Wnull-dereference"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <deque>
#include <map>
#include <stdexcept>
#include <string>

#include "elastic/core/error.h"

namespace elastic {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<int, Kernel>;
// The face stores its nesting level: 0 outside the outer loop, 1 in the band, 2 inside the inner
// loop.
using FaceInfoBase = CGAL::Triangulation_face_base_with_info_2<int, Kernel>;
using FaceBase = CGAL::Constrained_triangulation_face_base_2<Kernel, FaceInfoBase>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
// No_constraint_intersection_tag: crossing constraints throw instead of being split at new points.
using Cdt =
    CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::No_constraint_intersection_tag>;

}  // namespace

AnnulusTriangulation triangulate_annulus(const std::vector<Eigen::Vector2d>& points,
                                         const std::vector<int>& outer,
                                         const std::vector<int>& inner,
                                         const AnnulusTriangulationOptions& options) {
  if (outer.size() < 3 || inner.size() < 3) {
    throw InvalidInputError(options.name,
                            "band triangulation needs two loops of at least 3 points");
  }
  Cdt cdt;
  std::map<int, Cdt::Vertex_handle> handles;
  for (const std::vector<int>* loop : {&outer, &inner}) {
    for (const int index : *loop) {
      const Eigen::Vector2d& p = points.at(static_cast<size_t>(index));
      const Cdt::Vertex_handle vh = cdt.insert(Kernel::Point_2(p.x(), p.y()));
      vh->info() = index;
      handles[index] = vh;
    }
  }
  for (const int index : options.steiner) {
    const Eigen::Vector2d& p = points.at(static_cast<size_t>(index));
    const Cdt::Vertex_handle vh = cdt.insert(Kernel::Point_2(p.x(), p.y()));
    vh->info() = index;
  }
  const size_t expected = outer.size() + inner.size() + options.steiner.size();
  // Inserting a point that is already there returns the existing vertex: fewer vertices than points
  // means two points coincide.
  if (cdt.number_of_vertices() != expected) {
    throw InvalidInputError(options.name,
                            "band triangulation: two boundary or outline points coincide");
  }
  // Outer loop first, so that a crossing is attributed to the loop that has it.
  const auto insert_loop = [&](const std::vector<int>& loop, const std::string& problem) {
    try {
      for (size_t k = 0; k < loop.size(); ++k) {
        cdt.insert_constraint(handles[loop[k]], handles[loop[(k + 1) % loop.size()]]);
      }
    } catch (const std::exception&) {
      // Cdt::Intersection_of_constraints_exception (or a CGAL precondition failure).
      throw InvalidInputError(options.name, "band triangulation: " + problem);
    }
    if (cdt.number_of_vertices() != expected) {
      throw InvalidInputError(options.name, "band triangulation: " + problem);
    }
  };
  insert_loop(outer, options.outer_label + " crosses itself");
  insert_loop(inner, options.inner_label + " crosses " + options.outer_label + " or itself");

  // Nesting levels by breadth-first flooding: crossing a constrained edge adds one level.
  for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f) {
    f->info() = -1;
  }
  std::deque<Cdt::Face_handle> border{cdt.infinite_face()};
  cdt.infinite_face()->info() = 0;
  for (int level = 0; !border.empty(); ++level) {
    std::deque<Cdt::Face_handle> queue = border;
    border.clear();
    while (!queue.empty()) {
      const Cdt::Face_handle f = queue.front();
      queue.pop_front();
      for (int e = 0; e < 3; ++e) {
        const Cdt::Face_handle n = f->neighbor(e);
        if (n->info() != -1) {
          continue;
        }
        if (cdt.is_constrained(Cdt::Edge(f, e))) {
          border.push_back(n);
        } else {
          n->info() = level;
          queue.push_back(n);
        }
      }
    }
    for (const Cdt::Face_handle& f : border) {
      if (f->info() == -1) {
        f->info() = level + 1;
      }
    }
  }

  AnnulusTriangulation result;
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (f->info() != 1) {
      continue;
    }
    // CGAL stores finite faces counter-clockwise.
    result.triangles.emplace_back(f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info());
  }
  return result;
}

}  // namespace elastic
