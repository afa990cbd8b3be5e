#pragma once
// A fixed, generic rigid motion (a rotation about a skew axis and a translation) for the tests that
// map a region onto a rigidly moved copy of itself: the answer is the motion, known in advance.

#include <Eigen/Geometry>

#include "elastic/mesh/polygon_mesh.h"

namespace elastic::test {

/// Rotation by 0.7 rad about (1, 2, 3), then translation by (0.3, -1.2, 2.5).
inline Eigen::Isometry3d rigid_motion() {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  m.pretranslate(Eigen::Vector3d(0.3, -1.2, 2.5));
  return m;
}

/// `mesh` with every position moved by `motion`.
inline PolygonMesh moved(PolygonMesh mesh, const Eigen::Isometry3d& motion) {
  for (Eigen::Vector3d& p : mesh.positions) p = motion * p;
  return mesh;
}

}  // namespace elastic::test
