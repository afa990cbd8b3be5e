#include "elastic/transfer/tangent_frames.h"

#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "elastic/core/error.h"

namespace elastic {

Eigen::Matrix3d TangentFrame::matrix() const {
  Eigen::Matrix3d m;
  m.col(0) = tangent;
  m.col(1) = bitangent;
  m.col(2) = normal;
  return m;
}

Eigen::Vector3d TangentFrame::to_world(const Eigen::Vector3d& local) const {
  return local.x() * tangent + local.y() * bitangent + local.z() * normal;
}

Eigen::Vector3d TangentFrame::to_local(const Eigen::Vector3d& world) const {
  return {tangent.dot(world), bitangent.dot(world), normal.dot(world)};
}

TangentFrame make_tangent_frame(const Eigen::Vector3d& normal,
                                const Eigen::Vector3d& tangent_hint) {
  const double nn = normal.norm();
  if (!(nn > 0.0) || !std::isfinite(nn)) {
    throw NumericalError("tangent frame", "the normal is zero or not finite");
  }
  TangentFrame f;
  f.normal = normal / nn;
  const Eigen::Vector3d t = tangent_hint - tangent_hint.dot(f.normal) * f.normal;
  // The hint must keep a usable tangential part: below 1e-10 of its length its direction is
  // round-off.
  if (!(t.norm() > 1e-10 * tangent_hint.norm())) {
    throw NumericalError("tangent frame", "the tangent hint is parallel to the normal");
  }
  f.tangent = t.normalized();
  f.bitangent = f.normal.cross(f.tangent);
  return f;
}

TangentFrame surface_frame(const LimitSurface& surface, const SurfacePoint& p) {
  const SurfaceDerivatives d = surface.derivatives(p);
  const Eigen::Vector3d n = d.du.cross(d.dv);
  if (!(n.norm() > 1e-14 * d.du.norm() * d.dv.norm()) || !(d.du.norm() > 0.0)) {
    throw NumericalError(surface.name(), "singular parametrisation at face " +
                                             std::to_string(p.face) + ": no tangent frame");
  }
  return make_tangent_frame(n, d.du);
}

Eigen::Matrix3d minimal_rotation(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  // Rodrigues with c = a x b, cos = a.b: R = I + [c]x + [c]x^2 / (1 + cos). Exact for unit a, b,
  // and well conditioned unless a ~ -b.
  const Eigen::Vector3d c = a.cross(b);
  const double cosine = a.dot(b);
  if (cosine < -1.0 + 1e-12) {
    // Half turn about any axis perpendicular to a: R = 2 k k^T - I.
    Eigen::Vector3d k = a.unitOrthogonal();
    return 2.0 * k * k.transpose() - Eigen::Matrix3d::Identity();
  }
  Eigen::Matrix3d cx;
  cx << 0.0, -c.z(), c.y(), c.z(), 0.0, -c.x(), -c.y(), c.x(), 0.0;
  return Eigen::Matrix3d::Identity() + cx + cx * cx / (1.0 + cosine);
}

namespace {

// Edges and unit normal of a triangle given as columns; `ok` false when degenerate. A triangle is
// degenerate when its doubled area is below 1e-12 of its longest edge squared (a needle or a point:
// J would amplify round-off by more than 1e12).
struct TriangleFrame {
  Eigen::Vector3d e1, e2, normal, a1, a2;  // edges from corner 0; unit normal; plane basis
  bool ok = false;
};

TriangleFrame triangle_frame(const Eigen::Matrix3d& corners) {
  TriangleFrame f;
  f.e1 = corners.col(1) - corners.col(0);
  f.e2 = corners.col(2) - corners.col(0);
  const Eigen::Vector3d n = f.e1.cross(f.e2);
  const double longest =
      std::max({f.e1.squaredNorm(), f.e2.squaredNorm(), (f.e2 - f.e1).squaredNorm()});
  if (!(n.norm() > 1e-12 * longest)) {
    return f;
  }
  f.normal = n.normalized();
  f.a1 = f.e1.normalized();
  f.a2 = f.normal.cross(f.a1);
  f.ok = true;
  return f;
}

// The 2x2 matrix of the affine map in the planes' bases (a1, a2): columns are images of a1, a2.
Eigen::Matrix2d planar_jacobian(const TriangleFrame& s, const TriangleFrame& t) {
  Eigen::Matrix2d es, et;  // edges in the plane bases, as columns
  es << s.a1.dot(s.e1), s.a1.dot(s.e2), s.a2.dot(s.e1), s.a2.dot(s.e2);
  et << t.a1.dot(t.e1), t.a1.dot(t.e2), t.a2.dot(t.e1), t.a2.dot(t.e2);
  return et * es.inverse();
}

// The orthogonal 2x2 matrix nearest to A in the Frobenius norm: maximise tr(Q^T A) over rotations
// (angle atan2(c - b, a + d)) when det A > 0, over reflections (atan2(b + c, a - d)) otherwise.
Eigen::Matrix2d nearest_orthogonal(const Eigen::Matrix2d& m) {
  const double a = m(0, 0), b = m(0, 1), c = m(1, 0), d = m(1, 1);
  Eigen::Matrix2d q;
  if (m.determinant() >= 0.0) {
    const double theta = std::atan2(c - b, a + d);
    q << std::cos(theta), -std::sin(theta), std::sin(theta), std::cos(theta);
  } else {
    const double phi = std::atan2(b + c, a - d);
    q << std::cos(phi), std::sin(phi), std::sin(phi), -std::cos(phi);
  }
  return q;
}

Eigen::Matrix<double, 3, 2> plane_basis(const TriangleFrame& f) {
  Eigen::Matrix<double, 3, 2> b;
  b.col(0) = f.a1;
  b.col(1) = f.a2;
  return b;
}

// The unit limit normal (du x dv) at p; NumericalError where it vanishes.
Eigen::Vector3d limit_normal(const LimitSurface& surface, const SurfacePoint& p) {
  const SurfaceDerivatives d = surface.derivatives(p);
  const Eigen::Vector3d n = d.du.cross(d.dv);
  if (!(n.norm() > 1e-14 * d.du.norm() * d.dv.norm())) {
    throw NumericalError(surface.name(),
                         "singular parametrisation at face " + std::to_string(p.face));
  }
  return n.normalized();
}

double point_triangle_distance_squared(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                       const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  // Ericson, Real-Time Collision Detection §5.1.5: closest point by Voronoi regions.
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) {
    return ap.squaredNorm();
  }
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) {
    return bp.squaredNorm();
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    const double v = d1 / (d1 - d3);
    return (p - (a + v * ab)).squaredNorm();
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) {
    return cp.squaredNorm();
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    const double w = d2 / (d2 - d6);
    return (p - (a + w * ac)).squaredNorm();
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return (p - (b + w * (c - b))).squaredNorm();
  }
  const double denom = 1.0 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  return (p - (a + ab * v + ac * w)).squaredNorm();
}

}  // namespace

Eigen::Matrix3d triangle_jacobian(const Eigen::Matrix3d& source, const Eigen::Matrix3d& target) {
  const TriangleFrame s = triangle_frame(source);
  if (!s.ok) {
    throw NumericalError("triangle map", "degenerate source triangle");
  }
  const TriangleFrame t = triangle_frame(target);
  // J = E_t (E_s^T E_s)^-1 E_s^T with E = [e1 e2]: the pseudo-inverse maps the source plane onto
  // edge coordinates and annihilates the source normal. The target may be degenerate (collapsed).
  Eigen::Matrix<double, 3, 2> es, et;
  es << s.e1, s.e2;
  et << t.e1, t.e2;
  const Eigen::Matrix2d gram = es.transpose() * es;
  return et * gram.inverse() * es.transpose();
}

Eigen::Matrix3d triangle_rotation(const Eigen::Matrix3d& source, const Eigen::Matrix3d& target) {
  const TriangleFrame s = triangle_frame(source);
  const TriangleFrame t = triangle_frame(target);
  if (!s.ok || !t.ok) {
    throw NumericalError("triangle map", "degenerate triangle");
  }
  const Eigen::Matrix2d q = nearest_orthogonal(planar_jacobian(s, t));
  return plane_basis(t) * q * plane_basis(s).transpose() + t.normal * s.normal.transpose();
}

MapDifferential::MapDifferential(const LimitSurface& source,
                                 const std::vector<SurfacePoint>& source_points,
                                 const LimitSurface& target,
                                 const std::vector<SurfacePoint>& target_points,
                                 const std::vector<Eigen::Vector3i>& triangles)
    : source_(&source), target_(&target), target_points_(target_points), triangles_(triangles) {
  const int n = static_cast<int>(source_points.size());
  if (static_cast<int>(target_points.size()) != n) {
    throw InvalidInputError("map differential", "source and target particle counts differ (" +
                                                    std::to_string(n) + " and " +
                                                    std::to_string(target_points.size()) + ")");
  }
  source_positions_.resize(3, n);
  target_positions_.resize(3, n);
  std::vector<Eigen::Vector3d> target_normals(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    // Positions evaluated on the surfaces, as Mapping does, so J is the map Mapping interpolates.
    source_positions_.col(i) = source.position(source_points[i]);
    const SurfaceDerivatives d = target.derivatives(target_points[i]);
    target_positions_.col(i) = d.position;
    target_normals[static_cast<size_t>(i)] = d.du.cross(d.dv).normalized();
  }
  const size_t m = triangles_.size();
  jacobians_.assign(m, Eigen::Matrix3d::Zero());
  rotations_.assign(m, Eigen::Matrix3d::Zero());
  degenerate_.assign(m, 0);
  folded_.assign(m, 0);
  for (size_t k = 0; k < m; ++k) {
    const Eigen::Vector3i& tri = triangles_[k];
    if (tri.minCoeff() < 0 || tri.maxCoeff() >= n) {
      throw InvalidInputError("map differential",
                              "triangle " + std::to_string(k) + " names a missing particle");
    }
    Eigen::Matrix3d s, t;
    for (int c = 0; c < 3; ++c) {
      s.col(c) = source_positions_.col(tri[c]);
      t.col(c) = target_positions_.col(tri[c]);
    }
    const TriangleFrame fs = triangle_frame(s), ft = triangle_frame(t);
    if (!fs.ok || !ft.ok) {
      degenerate_[k] = 1;
      continue;
    }
    jacobians_[k] = triangle_jacobian(s, t);
    rotations_[k] = triangle_rotation(s, t);
    const Eigen::Vector3d nt =
        (target_normals[static_cast<size_t>(tri[0])] + target_normals[static_cast<size_t>(tri[1])] +
         target_normals[static_cast<size_t>(tri[2])]);
    folded_[k] = ft.normal.dot(nt) < 0.0 ? 1 : 0;
  }
}

MapDifferential::MapDifferential(const LimitSurface& source, const LimitSurface& target,
                                 const MapResult& result)
    : MapDifferential(source, result.sampling.grid.source_points, target, result.relaxation.points,
                      result.mapping.triangles()) {}

void MapDifferential::check_triangle(int t) const {
  if (t < 0 || t >= num_triangles()) {
    throw InvalidInputError("map differential", "grid triangle " + std::to_string(t) +
                                                    " out of range (" +
                                                    std::to_string(num_triangles()) + ")");
  }
  if (degenerate_[static_cast<size_t>(t)]) {
    throw NumericalError("map differential",
                         "grid triangle " + std::to_string(t) + " is degenerate");
  }
}

const Eigen::Matrix3d& MapDifferential::jacobian(int t) const {
  check_triangle(t);
  return jacobians_[static_cast<size_t>(t)];
}

bool MapDifferential::folded(int t) const {
  check_triangle(t);
  return folded_[static_cast<size_t>(t)] != 0;
}

int MapDifferential::nearest_triangle(const Eigen::Vector3d& source_position) const {
  int best = -1;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (int k = 0; k < num_triangles(); ++k) {
    if (degenerate_[static_cast<size_t>(k)]) {
      continue;
    }
    const Eigen::Vector3i& tri = triangles_[static_cast<size_t>(k)];
    const double d2 = point_triangle_distance_squared(
        source_position, source_positions_.col(tri[0]), source_positions_.col(tri[1]),
        source_positions_.col(tri[2]));
    if (d2 < best_d2) {
      best_d2 = d2;
      best = k;
    }
  }
  if (best < 0) {
    throw NumericalError("map differential", "no usable grid triangle");
  }
  return best;
}

Eigen::Matrix3d MapDifferential::transport(const SurfacePoint& source, const SurfacePoint& target,
                                           int triangle, VectorTransport mode) const {
  if (!source_ || !source.valid() || !target.valid()) {
    throw InvalidInputError("map differential", "transport needs a source and a target point");
  }
  if (triangle < 0) {
    triangle = nearest_triangle(source_->position(source));
  }
  check_triangle(triangle);
  const Eigen::Vector3i& tri = triangles_[static_cast<size_t>(triangle)];
  const Eigen::Vector3d ms =
      (source_positions_.col(tri[1]) - source_positions_.col(tri[0]))
          .cross(source_positions_.col(tri[2]) - source_positions_.col(tri[0]))
          .normalized();
  Eigen::Vector3d mt = (target_positions_.col(tri[1]) - target_positions_.col(tri[0]))
                           .cross(target_positions_.col(tri[2]) - target_positions_.col(tri[0]))
                           .normalized();
  const Eigen::Vector3d ns = limit_normal(*source_, source);
  const Eigen::Vector3d nt = limit_normal(*target_, target);
  // The source grid is counter-clockwise seen from the source normal side, so ms.ns > 0 unless the
  // limit surface turns by more than 90 degrees within one triangle. On the target, a folded
  // triangle has mt.nt < 0: rotate -mt (the same plane) onto nt, and the tangential part of the map
  // keeps its orientation reversal.
  const double flip = mt.dot(nt) < 0.0 ? -1.0 : 1.0;
  mt *= flip;
  const Eigen::Matrix3d& tangential = mode == VectorTransport::Stretch
                                          ? jacobians_[static_cast<size_t>(triangle)]
                                          : rotations_[static_cast<size_t>(triangle)];
  // rotations_ already maps ms to the triangle's own target normal (flip * mt); replace that
  // normal part by ms -> mt so both modes send the source normal to the target normal.
  Eigen::Matrix3d middle = tangential;
  if (mode == VectorTransport::Rotation) {
    middle -= flip * mt * ms.transpose();
  }
  middle += mt * ms.transpose();
  return minimal_rotation(mt, nt) * middle * minimal_rotation(ns, ms);
}

Eigen::Matrix3d MapDifferential::transport_forward(const SurfacePoint& source,
                                                   const Mapping::Location& image,
                                                   VectorTransport mode) const {
  if (!image.inside) {
    throw InvalidInputError("map differential", "the point maps outside");
  }
  return transport(source, image.point, image.triangle, mode);
}

Eigen::Matrix3d MapDifferential::transport_inverse(const SurfacePoint& target,
                                                   const Mapping::Location& preimage,
                                                   VectorTransport mode) const {
  if (!preimage.inside) {
    throw InvalidInputError("map differential", "the point has no source");
  }
  return transport(preimage.point, target, preimage.triangle, mode);
}

TangentFrame MapDifferential::transport_frame(const TangentFrame& frame, const SurfacePoint& source,
                                              const SurfacePoint& target, int triangle,
                                              VectorTransport mode) const {
  const Eigen::Matrix3d t = transport(source, target, triangle, mode);
  return make_tangent_frame(limit_normal(*target_, target), t * frame.tangent);
}

VectorTransferResult transfer_vectors(const MapDifferential& differential,
                                      std::span<const SurfacePoint> target_points,
                                      std::span<const Mapping::Location> sources,
                                      std::span<const Eigen::Vector3d> source_vectors,
                                      std::span<const TangentFrame> source_frames,
                                      std::span<const TangentFrame> target_frames,
                                      const VectorTransferOptions& options) {
  const size_t n = target_points.size();
  if (sources.size() != n || source_vectors.size() != n ||
      (!source_frames.empty() && source_frames.size() != n) ||
      (!target_frames.empty() && target_frames.size() != n)) {
    throw InvalidInputError(options.name,
                            "target points, sources, vectors and frames must have one entry per "
                            "sample (" +
                                std::to_string(n) + " target points)");
  }
  VectorTransferResult result;
  result.vectors.assign(n, Eigen::Vector3d::Zero());
  for (size_t i = 0; i < n; ++i) {
    if (!source_vectors[i].allFinite()) {
      throw InvalidInputError(options.name, "vector " + std::to_string(i) + " is not finite");
    }
    const Mapping::Location& from = sources[i];
    if (!from.inside) {
      ++result.without_source;
      continue;
    }
    int triangle = from.triangle;
    if (triangle < 0) {
      triangle = differential.nearest_triangle(from.position);
    }
    if (differential.folded(triangle)) {
      ++result.folded;
    }
    const Eigen::Matrix3d t =
        differential.transport(from.point, target_points[i], triangle, options.mode);
    const Eigen::Vector3d world =
        source_frames.empty() ? source_vectors[i] : source_frames[i].to_world(source_vectors[i]);
    const Eigen::Vector3d out = t * world;
    result.vectors[i] = target_frames.empty() ? out : target_frames[i].to_local(out);
  }
  return result;
}

}  // namespace elastic
