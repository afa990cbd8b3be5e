// Up-axis guess from the ends a model stands on, its open ends and its height field; see up_axis.h.
#include "elastic/render/up_axis.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <numeric>
#include <optional>
#include <span>
#include <sstream>
#include <unordered_map>
#include <utility>

#include "elastic/core/error.h"

namespace elastic {
namespace {

/// Area of the convex hull of 2D points (Andrew's monotone chain; collinear points dropped).
double hull_area(std::vector<Eigen::Vector2d> p) {
  if (p.size() < 3) return 0.0;
  std::sort(p.begin(), p.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  const auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a,
                        const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Eigen::Vector2d> hull(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {  // lower chain
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], p[i]) <= 0.0) --k;
    hull[k++] = p[i];
  }
  for (size_t i = p.size() - 1, lower = k + 1; i-- > 0;) {  // upper chain
    while (k >= lower && cross(hull[k - 2], hull[k - 1], p[i]) <= 0.0) --k;
    hull[k++] = p[i];
  }
  hull.resize(k - 1);  // the last point repeats the first
  double twice = 0.0;  // shoelace formula
  for (size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2d& a = hull[i];
    const Eigen::Vector2d& b = hull[(i + 1) % hull.size()];
    twice += a.x() * b.y() - b.x() * a.y();
  }
  return 0.5 * std::abs(twice);
}

/// The box of the points, checked. \throws InvalidInputError for no points or a non-finite one.
Eigen::AlignedBox3d checked_box(const std::vector<Eigen::Vector3d>& points) {
  if (points.empty()) throw InvalidInputError("up axis", "no points");
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& p : points) {
    if (!p.allFinite()) throw InvalidInputError("up axis", "a point is not finite");
    box.extend(p);
  }
  return box;
}

/// Evidence per signed axis, indexed 2 a + (sign < 0): [+x, -x, +y, -y, +z, -z]. For + the base is
/// the lowest end along a, for - the highest.
struct Evidence {
  std::vector<double> footprints = std::vector<double>(6, 0.0);
  std::vector<double> open_ends = std::vector<double>(6, 0.0);
  std::vector<double> flat_ends = std::vector<double>(6, 0.0);
};

/// Height of p above the base of signed axis `index` (0 at the base's extreme).
double height_above_base(const Eigen::Vector3d& p, const Eigen::AlignedBox3d& box, int index) {
  const int a = index / 2;
  return index % 2 == 0 ? p[a] - box.min()[a] : box.max()[a] - p[a];
}

/// Cross-section of the box across axis a (0 for a box flat in another axis).
double cross_section(const Eigen::Vector3d& extent, int a) {
  return extent[(a + 1) % 3] * extent[(a + 2) % 3];
}

/// Hull area of the points within `slab` (fraction of the extent) of the base of `index`, over the
/// cross-section.
double footprint(const std::vector<Eigen::Vector3d>& points, const Eigen::AlignedBox3d& box,
                 int index, double slab) {
  const int a = index / 2, u = (a + 1) % 3, v = (a + 2) % 3;
  const double area = cross_section(box.sizes(), a);
  std::vector<Eigen::Vector2d> base;
  for (const Eigen::Vector3d& p : points) {
    if (height_above_base(p, box, index) <= slab * box.sizes()[a]) base.emplace_back(p[u], p[v]);
  }
  return area > 0.0 ? hull_area(std::move(base)) / area : 0.0;
}

UpAxisGuess make_guess(int axis, int sign, UpAxisConfidence confidence, const Evidence& evidence,
                       std::string reason) {
  UpAxisGuess guess;
  guess.axis = axis;
  guess.sign = sign;
  guess.direction = sign * Eigen::Vector3d::Unit(axis);
  guess.footprints = evidence.footprints;
  guess.open_ends = evidence.open_ends;
  guess.flat_ends = evidence.flat_ends;
  guess.confidence = confidence;
  guess.reason = std::move(reason);
  return guess;
}

std::string percent(double fraction) {
  std::ostringstream out;
  out.precision(2);
  out << 100.0 * fraction << '%';
  return out.str();
}

/// Rule 1: a box flat along one axis.
std::optional<UpAxisGuess> flat_rule(const Eigen::AlignedBox3d& box, const UpAxisOptions& options) {
  const Eigen::Vector3d extent = box.sizes();
  int thin = 0;
  extent.minCoeff(&thin);
  if (extent[thin] > options.flat_ratio * extent.maxCoeff()) return std::nullopt;
  return make_guess(thin, 1, UpAxisConfidence::High, Evidence{},
                    std::string("the model is flat along ") + "xyz"[thin]);
}

/// Rules 4 and 5: the footprints, and the convention where they do not decide.
UpAxisGuess footprint_rule(const Evidence& evidence, const UpAxisOptions& options) {
  const std::vector<double>& f = evidence.footprints;
  int convention_axis = 0;
  options.convention.cwiseAbs().maxCoeff(&convention_axis);
  const int convention_sign = options.convention[convention_axis] < 0.0 ? -1 : 1;
  const std::string convention =
      std::string(convention_sign > 0 ? "+" : "-") + "xyz"[convention_axis];
  const int index = static_cast<int>(std::max_element(f.begin(), f.end()) - f.begin());
  const int axis = index / 2;
  const double best = f[static_cast<size_t>(index)];
  const double opposite = f[static_cast<size_t>(index ^ 1)];
  if (!(best >= options.min_footprint)) {
    return make_guess(convention_axis, convention_sign, UpAxisConfidence::Low, evidence,
                      "no side to stand on (largest footprint " + percent(best) +
                          " of the box); the convention " + convention + " taken");
  }
  if (opposite >= options.symmetric_ratio * best) {
    return make_guess(axis, 1, UpAxisConfidence::Medium, evidence,
                      std::string("both ends of ") + "xyz"[axis] + " are bases (" +
                          percent(f[2 * axis]) + " and " + percent(f[2 * axis + 1]) +
                          " of the box); + taken");
  }
  double others = 0.0;
  for (int i = 0; i < 6; ++i) {
    if (i / 2 != axis) others = std::max(others, f[static_cast<size_t>(i)]);
  }
  const int sign = index % 2 == 0 ? 1 : -1;
  const std::string stands = std::string("the model stands on its ") +
                             (sign > 0 ? "lowest " : "highest ") + "xyz"[axis] + " (a base of " +
                             percent(best) + " of the box's cross-section";
  if (opposite <= options.clear_opposite * best && best >= options.clear_ratio * others) {
    return make_guess(axis, sign, UpAxisConfidence::High, evidence, stands + ")");
  }
  if (convention_axis == axis && convention_sign != sign) {
    return make_guess(axis, convention_sign, UpAxisConfidence::Low, evidence,
                      std::string("the footprints of the two ends of ") + "xyz"[axis] + " (" +
                          percent(f[2 * axis]) + " and " + percent(f[2 * axis + 1]) +
                          ") do not decide; the convention " + convention + " taken");
  }
  return make_guess(axis, sign, UpAxisConfidence::Low, evidence, stands + ", by a small margin)");
}

/// The boundary loops of a mesh (edges of one face), each as its vertices, and the boundary's
/// length-weighted centroid (the midpoints of its edges).
struct Boundary {
  std::vector<std::vector<int>> loops;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  bool empty() const { return loops.empty(); }
};

Boundary find_boundary(const PolygonMesh& mesh) {
  std::unordered_map<std::uint64_t, int> uses;
  const auto key = [](int a, int b) {
    return (std::uint64_t(std::uint32_t(std::min(a, b))) << 32) | std::uint32_t(std::max(a, b));
  };
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const std::span<const int> c = mesh.face(f);
    for (size_t i = 0; i < c.size(); ++i) ++uses[key(c[i], c[(i + 1) % c.size()])];
  }
  // Loops: connected pieces of the boundary edges (union-find over their vertices).
  std::vector<int> parent(mesh.positions.size());
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&parent](int v) {
    while (parent[static_cast<size_t>(v)] != v) {
      int& up = parent[static_cast<size_t>(v)];
      up = parent[static_cast<size_t>(up)];  // path halving
      v = up;
    }
    return v;
  };
  Boundary boundary;
  double length = 0.0;
  std::vector<char> on_boundary(mesh.positions.size(), 0);
  for (const auto& [edge, count] : uses) {
    if (count != 1) continue;
    const int a = static_cast<int>(edge >> 32), b = static_cast<int>(edge & 0xffffffffu);
    const Eigen::Vector3d& pa = mesh.positions[static_cast<size_t>(a)];
    const Eigen::Vector3d& pb = mesh.positions[static_cast<size_t>(b)];
    length += (pb - pa).norm();
    boundary.centroid += 0.5 * (pb - pa).norm() * (pa + pb);
    on_boundary[static_cast<size_t>(a)] = on_boundary[static_cast<size_t>(b)] = 1;
    parent[static_cast<size_t>(root(a))] = root(b);
  }
  if (length > 0.0) boundary.centroid /= length;
  std::unordered_map<int, size_t> loop_of_root;
  for (int v = 0; v < static_cast<int>(on_boundary.size()); ++v) {
    if (!on_boundary[static_cast<size_t>(v)]) continue;
    const auto [it, added] = loop_of_root.emplace(root(v), boundary.loops.size());
    if (added) boundary.loops.emplace_back();
    boundary.loops[it->second].push_back(v);
  }
  return boundary;
}

/// Open ends: per signed axis, the largest hull (over the cross-section) of a boundary loop lying
/// within `rim_slab` of that base.
std::vector<double> open_ends(const PolygonMesh& mesh, const Boundary& boundary,
                              const Eigen::AlignedBox3d& box, const UpAxisOptions& options) {
  std::vector<double> ends(6, 0.0);
  for (int index = 0; index < 6; ++index) {
    const int a = index / 2, u = (a + 1) % 3, v = (a + 2) % 3;
    const double area = cross_section(box.sizes(), a);
    if (!(area > 0.0)) continue;
    for (const std::vector<int>& loop : boundary.loops) {
      std::vector<Eigen::Vector2d> rim;
      for (const int i : loop) {
        const Eigen::Vector3d& p = mesh.positions[static_cast<size_t>(i)];
        if (height_above_base(p, box, index) > options.rim_slab * box.sizes()[a]) break;
        rim.emplace_back(p[u], p[v]);
      }
      if (rim.size() < loop.size()) continue;  // the loop leaves the slab
      ends[static_cast<size_t>(index)] =
          std::max(ends[static_cast<size_t>(index)], hull_area(std::move(rim)) / area);
    }
  }
  return ends;
}

/// A face's vector area (half the sum of p_i x p_(i+1): a polygon's area times its normal) and the
/// mean of its corners.
std::pair<Eigen::Vector3d, Eigen::Vector3d> face_vector_area(const PolygonMesh& mesh, int f) {
  const std::span<const int> c = mesh.face(f);
  Eigen::Vector3d twice = Eigen::Vector3d::Zero(), mean = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < c.size(); ++i) {
    const Eigen::Vector3d& p = mesh.positions[static_cast<size_t>(c[i])];
    twice += p.cross(mesh.positions[static_cast<size_t>(c[(i + 1) % c.size()])]);
    mean += p;
  }
  return {0.5 * twice, mean / static_cast<double>(std::max<size_t>(c.size(), 1))};
}

/// Flat ends: per signed axis, the area of the faces within `base_slab` of that base whose normal
/// is within `flat_degrees` of the axis (either way: the winding does not matter), over the
/// cross-section.
std::vector<double> flat_ends(const PolygonMesh& mesh, const Eigen::AlignedBox3d& box,
                              const UpAxisOptions& options) {
  std::vector<double> ends(6, 0.0);
  const double cosine = std::cos(options.flat_degrees * std::numbers::pi / 180.0);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const auto [vector_area, centre] = face_vector_area(mesh, f);
    const double area = vector_area.norm();
    if (!(area > 0.0)) continue;
    for (int index = 0; index < 6; ++index) {
      const int a = index / 2;
      if (std::abs(vector_area[a]) >= cosine * area &&
          height_above_base(centre, box, index) <= options.base_slab * box.sizes()[a]) {
        ends[static_cast<size_t>(index)] += area;
      }
    }
  }
  for (int index = 0; index < 6; ++index) {
    const double section = cross_section(box.sizes(), index / 2);
    ends[static_cast<size_t>(index)] =
        section > 0.0 ? ends[static_cast<size_t>(index)] / section : 0.0;
  }
  return ends;
}

/// Rule 2: open ends.
std::optional<UpAxisGuess> open_end_rule(const Evidence& evidence, const UpAxisOptions& options) {
  const std::vector<double>& open = evidence.open_ends;
  const int index = static_cast<int>(std::max_element(open.begin(), open.end()) - open.begin());
  if (!(open[static_cast<size_t>(index)] >= options.min_rim)) return std::nullopt;
  const int axis = index / 2, sign = index % 2 == 0 ? 1 : -1;
  const size_t other = static_cast<size_t>(index ^ 1);
  if (open[other] >= options.min_rim || evidence.flat_ends[other] >= options.min_flat) {
    return make_guess(axis, 1, UpAxisConfidence::Medium, evidence,
                      std::string("both ends of ") + "xyz"[axis] +
                          " are open or flat (a tube or an open container); + taken");
  }
  return make_guess(axis, sign, UpAxisConfidence::High, evidence,
                    std::string("the model's open end (") +
                        percent(open[static_cast<size_t>(index)]) +
                        " of the box's cross-section) is its " +
                        (sign > 0 ? "lowest " : "highest ") + "xyz"[axis]);
}

/// Rule 3: an open mesh that is a height field over two axes.
std::optional<UpAxisGuess> height_field_rule(const PolygonMesh& mesh, const Boundary& boundary,
                                             const Evidence& evidence,
                                             const Eigen::AlignedBox3d& box,
                                             const UpAxisOptions& options) {
  if (boundary.empty()) return std::nullopt;
  Eigen::Vector3d vector_area = Eigen::Vector3d::Zero(), centroid = Eigen::Vector3d::Zero();
  double area = 0.0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const auto [face_area, centre] = face_vector_area(mesh, f);
    vector_area += face_area;
    area += face_area.norm();
    centroid += face_area.norm() * centre;
  }
  if (!(area > 0.0) || vector_area.norm() < options.height_field * area) return std::nullopt;
  int axis = 0;
  vector_area.cwiseAbs().maxCoeff(&axis);
  if (std::abs(vector_area[axis]) < std::cos(std::numbers::pi / 6.0) * vector_area.norm()) {
    return std::nullopt;
  }
  const double rise = (centroid[axis] / area - boundary.centroid[axis]) / box.sizes()[axis];
  const std::string what = std::string("the model is a height field over ") +
                           "xyz"[(axis + 1) % 3] + "xyz"[(axis + 2) % 3] + " (|vector area| " +
                           percent(vector_area.norm() / area) + " of its area)";
  if (std::abs(rise) < 0.02) {
    return make_guess(axis, 1, UpAxisConfidence::Medium, evidence,
                      what + " whose rim is level with its middle; + taken");
  }
  return make_guess(axis, rise > 0.0 ? 1 : -1, UpAxisConfidence::High, evidence,
                    what + " whose rim is below its middle");
}

}  // namespace

const char* to_string(UpAxisConfidence confidence) {
  switch (confidence) {
    case UpAxisConfidence::High:
      return "high";
    case UpAxisConfidence::Medium:
      return "medium";
    case UpAxisConfidence::Low:
      return "low";
  }
  return "low";
}

std::string UpAxisGuess::name() const {
  return std::string(sign > 0 ? "+" : "-") + "xyz"[axis];
}

UpAxisGuess guess_up_axis(const std::vector<Eigen::Vector3d>& points,
                          const UpAxisOptions& options) {
  const Eigen::AlignedBox3d box = checked_box(points);
  if (std::optional<UpAxisGuess> flat = flat_rule(box, options)) return *flat;
  Evidence evidence;
  for (int index = 0; index < 6; ++index) {
    evidence.footprints[static_cast<size_t>(index)] =
        footprint(points, box, index, options.base_slab);
  }
  return footprint_rule(evidence, options);
}

UpAxisGuess guess_up_axis(const PolygonMesh& mesh, const UpAxisOptions& options) {
  const Eigen::AlignedBox3d box = checked_box(mesh.positions);
  if (std::optional<UpAxisGuess> flat = flat_rule(box, options)) return *flat;
  Evidence evidence;
  for (int index = 0; index < 6; ++index) {
    evidence.footprints[static_cast<size_t>(index)] =
        footprint(mesh.positions, box, index, options.base_slab);
  }
  const Boundary boundary = find_boundary(mesh);
  evidence.open_ends = open_ends(mesh, boundary, box, options);
  evidence.flat_ends = flat_ends(mesh, box, options);
  if (std::optional<UpAxisGuess> open = open_end_rule(evidence, options)) return *open;
  if (std::optional<UpAxisGuess> field =
          height_field_rule(mesh, boundary, evidence, box, options)) {
    return *field;
  }
  return footprint_rule(evidence, options);
}

Eigen::Vector3d parse_up_direction(const std::string& text, const std::string& name) {
  std::string axis = text;
  int sign = 1;
  if (!axis.empty() && (axis[0] == '+' || axis[0] == '-')) {
    sign = axis[0] == '-' ? -1 : 1;
    axis.erase(0, 1);
  }
  if (axis == "x" || axis == "y" || axis == "z") {
    return sign * Eigen::Vector3d::Unit(axis[0] - 'x');
  }
  Eigen::Vector3d d;
  char c1 = 0, c2 = 0;
  std::istringstream in(text);
  std::string rest;
  if (in >> d.x() >> c1 >> d.y() >> c2 >> d.z() && c1 == ',' && c2 == ',' && !(in >> rest) &&
      d.allFinite() && d.norm() > 0.0) {
    return d.normalized();
  }
  throw InvalidInputError(name,
                          "expected x, y, z, -x, -y, -z or X,Y,Z (non-zero), got '" + text + "'");
}

}  // namespace elastic
