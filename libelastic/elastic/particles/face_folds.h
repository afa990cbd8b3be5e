#pragma once
/// \file
/// The fold test of a grid face, the one definition (docs/metrics.md, "Folds") that the map
/// metrics, the pass/fail verdict built on them, and the choice of the boundary correspondence's
/// offset share.
///
/// A target triangle (qa, qb, qc) is inverted when its normal (qb - qa) x (qc - qa) has a
/// non-positive dot product with the sum of the unit surface normals at its three corners (the sum
/// is robust to one corner's normal being off, e.g. where a face straddles a sharp fold of the
/// surface). A face is inverted when a triangle of *any* of its triangulations is (a quad: the four
/// triangles of its two diagonal splits), since one split alone hides a quad whose corner has
/// moved inside the triangle of the other three. The metrics add degenerate (collapsed) triangles,
/// which need the source triangle, to their `folds`.
///
/// The solvers guard the same test: SpringSystem::folded_corners (what the line search keeps) and
/// the injectivity barrier (infinite as a triangle inverts) see each triangle along the sum of its
/// corners' normals. Until 2026-12-04 they used each corner's own normal, which disagrees with this
/// test where the normal turns by more than 90 degrees within one face: a quad wrapping the
/// armadillo's snout converged "fold-free" for the solver and folded for the report.

#include <Eigen/Core>
#include <vector>

#include "elastic/particles/particle_grid.h"

namespace elastic {

/// Local corner triples of every triangulation of a face with `corners` corners: {0,1,2} for a
/// triangle, both diagonal splits of a quad, every fan of a larger polygon.
const std::vector<Eigen::Vector3i>& face_triangulations(int corners);

/// Whether the target triangle (qa, qb, qc) points against the sum of its corners' unit surface
/// normals (see the file comment). A zero-area triangle counts as inverted.
bool triangle_inverted(const Eigen::Vector3d& qa, const Eigen::Vector3d& qb,
                       const Eigen::Vector3d& qc, const Eigen::Vector3d& na,
                       const Eigen::Vector3d& nb, const Eigen::Vector3d& nc);

/// Faces of `grid` with an inverted triangle in some triangulation, at positions `x` (3 x #P) with
/// unit surface normals `normals` (3 x #P).
int inverted_faces(const ParticleGrid& grid, const Eigen::Matrix3Xd& x,
                   const Eigen::Matrix3Xd& normals);

}  // namespace elastic
