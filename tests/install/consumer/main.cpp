// A program outside the project that uses the installed library: builds a limit surface of a cube
// and checks that a face centre lies inside the cube's hull.
#include <elastic/mesh/polygon_mesh.h>
#include <elastic/surface/limit_surface.h>

#include <cstdio>

int main() {
  elastic::PolygonMesh cube;
  for (int i = 0; i < 8; ++i) {
    cube.positions.emplace_back(i & 1 ? 1.0 : -1.0, i & 2 ? 1.0 : -1.0, i & 4 ? 1.0 : -1.0);
  }
  cube.add_face({0, 2, 3, 1});
  cube.add_face({4, 5, 7, 6});
  cube.add_face({0, 1, 5, 4});
  cube.add_face({2, 6, 7, 3});
  cube.add_face({0, 4, 6, 2});
  cube.add_face({1, 3, 7, 5});
  const elastic::LimitSurface surface(cube);
  const Eigen::Vector3d p = surface.position(surface.face_center(0));
  std::printf("face centre of the limit cube: %.6f %.6f %.6f\n", p.x(), p.y(), p.z());
  return p.cwiseAbs().maxCoeff() < 1.0 ? 0 : 1;
}
