#include "elastic/particles/face_folds.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <Eigen/Geometry>
#include <functional>

namespace elastic {

const std::vector<Eigen::Vector3i>& face_triangulations(int corners) {
  static const std::vector<Eigen::Vector3i> triangle = {{0, 1, 2}};
  static const std::vector<Eigen::Vector3i> quad = {{0, 1, 2}, {0, 2, 3}, {1, 2, 3}, {1, 3, 0}};
  if (corners == 3) {
    return triangle;
  }
  if (corners == 4) {
    return quad;
  }
  thread_local std::vector<Eigen::Vector3i> fans;
  fans.clear();
  for (int a = 0; a < corners; ++a) {
    for (int k = 1; k + 1 < corners; ++k) {
      fans.emplace_back(a, (a + k) % corners, (a + k + 1) % corners);
    }
  }
  return fans;
}

bool triangle_inverted(const Eigen::Vector3d& qa, const Eigen::Vector3d& qb,
                       const Eigen::Vector3d& qc, const Eigen::Vector3d& na,
                       const Eigen::Vector3d& nb, const Eigen::Vector3d& nc) {
  // "<= 0" also flags a zero-area triangle; NaN counts as inverted.
  return !((qb - qa).cross(qc - qa).dot(na + nb + nc) > 0.0);
}

int inverted_faces(const ParticleGrid& grid, const Eigen::Matrix3Xd& x,
                   const Eigen::Matrix3Xd& normals) {
  const auto faces = static_cast<int>(grid.mesh.n_faces());
  return tbb::parallel_reduce(
      tbb::blocked_range<int>(0, faces, 1024), 0,
      [&](const tbb::blocked_range<int>& range, int count) {
        std::vector<int> corners;
        for (int f = range.begin(); f != range.end(); ++f) {
          corners.clear();
          for (const auto vh : grid.mesh.fv_range(GridMesh::FaceHandle(f))) {
            corners.push_back(vh.idx());
          }
          for (const Eigen::Vector3i& t : face_triangulations(static_cast<int>(corners.size()))) {
            const int a = corners[static_cast<std::size_t>(t[0])];
            const int b = corners[static_cast<std::size_t>(t[1])];
            const int c = corners[static_cast<std::size_t>(t[2])];
            if (triangle_inverted(x.col(a), x.col(b), x.col(c), normals.col(a), normals.col(b),
                                  normals.col(c))) {
              ++count;
              break;
            }
          }
        }
        return count;
      },
      std::plus<int>());
}

}  // namespace elastic
