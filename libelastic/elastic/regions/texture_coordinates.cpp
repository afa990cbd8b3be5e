#include "elastic/regions/texture_coordinates.h"

#include "elastic/core/error.h"

namespace elastic {

Eigen::Vector2d texture_coordinate(const LimitSurface& surface, const SurfacePoint& p) {
  const PolygonMesh& mesh = surface.control_mesh();
  if (!mesh.has_texcoords()) {
    throw InvalidInputError(surface.name(), "the mesh has no texture coordinates");
  }
  const int f = surface.control_face(p.face);
  const int n = mesh.face_size(f);
  const int offset = mesh.face_offsets[static_cast<size_t>(f)];
  auto corner = [&](int k) -> Eigen::Vector2d {
    const int c = offset + ((k % n) + n) % n;
    return mesh.texcoords[static_cast<size_t>(mesh.corner_texcoords[static_cast<size_t>(c)])];
  };
  const double u = p.u, v = p.v;
  if (surface.triangular_domain()) {
    return (1.0 - u - v) * corner(0) + u * corner(1) + v * corner(2);
  }
  auto bilinear = [&](const Eigen::Vector2d& c0, const Eigen::Vector2d& c1,
                      const Eigen::Vector2d& c2, const Eigen::Vector2d& c3) -> Eigen::Vector2d {
    return (1.0 - u) * (1.0 - v) * c0 + u * (1.0 - v) * c1 + u * v * c2 + (1.0 - u) * v * c3;
  };
  if (n == 4) {
    return bilinear(corner(0), corner(1), corner(2), corner(3));
  }
  // n-gon: sub-face i is the quad (corner i, mid(i, i+1), centroid, mid(i-1, i)).
  const int i = p.face - surface.first_ptex_face(f);
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (int k = 0; k < n; ++k) {
    centroid += corner(k);
  }
  centroid /= static_cast<double>(n);
  return bilinear(corner(i), 0.5 * (corner(i) + corner(i + 1)), centroid,
                  0.5 * (corner(i - 1) + corner(i)));
}

}  // namespace elastic
