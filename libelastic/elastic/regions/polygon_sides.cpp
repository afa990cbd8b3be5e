#include "elastic/regions/polygon_sides.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <unordered_map>

#include "elastic/core/error.h"
#include "elastic/regions/heat_geodesics.h"

namespace elastic::regions_detail {
namespace {

/// The chord's slacks tried in turn (polygon_sides.h).
constexpr std::array<double, 2> kSlacks{0.01, 0.25};

/// The chord's bands and the heat bands of one polygon (polygon_sides.h).
class SideBands {
 public:
  SideBands(const std::vector<Eigen::Vector3d>& positions,
            const std::vector<Eigen::Vector3i>& triangles, const std::vector<MeshLocation>& corners,
            const std::string& name)
      : x_(positions), triangles_(triangles), corners_(corners), name_(name) {
    for (const MeshLocation& c : corners) {
      where_.push_back(position_of(x_, triangles_, c));
    }
    index_vertices();
  }

  /// The chord's bound with this slack, plus room for the certificate.
  double chord_bound(size_t i, size_t j, double slack) const {
    return (1.0 + slack) * (where_[i] - where_[j]).norm() + 2.0 * max_edge_ + 2.0 * mean_edge_;
  }
  /// Whether the chord's band for `bound` holds every path of this length or shorter.
  bool certifies(double bound, double length) const {
    return length + 2.0 * max_edge_ + tolerance() <= bound;
  }
  /// The smallest bound whose band holds every path of this length or shorter.
  double enclosing(double length) const { return length + 2.0 * max_edge_ + 2.0 * tolerance(); }

  /// The triangles with a corner v with |v - a| + |v - b| <= bound, in increasing order.
  std::vector<int> chord(size_t i, size_t j, double bound) const {
    const Eigen::Vector3d& a = where_[i];
    const Eigen::Vector3d& b = where_[j];
    std::vector<int> band;
    const auto take = [&](int v) {
      const Eigen::Vector3d& x = x_[static_cast<size_t>(v)];
      if ((x - a).norm() + (x - b).norm() <= bound) {
        for (const int t : vertex_triangles_[static_cast<size_t>(v)]) {
          band.push_back(t);
        }
      }
    };
    // Every such v is within `bound` of a: in a's cell or r cells from it.
    const int r = static_cast<int>(std::ceil(bound / cell_size_));
    const double cells_searched = std::pow(2.0 * r + 1.0, 3.0);
    if (cells_searched > static_cast<double>(cells_.size())) {
      for (size_t v = 0; v < x_.size(); ++v) {
        take(static_cast<int>(v));
      }
    } else {
      const Eigen::Vector3i c = cell(a);
      for (int dx = -r; dx <= r; ++dx) {
        for (int dy = -r; dy <= r; ++dy) {
          for (int dz = -r; dz <= r; ++dz) {
            const auto found = cells_.find(key(c + Eigen::Vector3i(dx, dy, dz)));
            if (found != cells_.end()) {
              std::for_each(found->second.begin(), found->second.end(), take);
            }
          }
        }
      }
    }
    std::sort(band.begin(), band.end());
    band.erase(std::unique(band.begin(), band.end()), band.end());
    return band;
  }

  std::vector<char> heat(size_t i, size_t j) {
    if (!heat_) {
      heat_ = std::make_unique<HeatGeodesics>(x_, triangles_, name_);
      dist_.resize(corners_.size());
    }
    for (const size_t k : {i, j}) {
      if (dist_[k].size() == 0) {
        dist_[k] = heat_->distance(corners_[k]);
      }
    }
    return geodesic_band(triangles_, dist_[i], dist_[j], 0.5, 4.0 * heat_->mean_edge_length());
  }

 private:
  /// Round-off of the path's length (CGAL measures it between ends moved kInside into their
  /// triangles) and of the 3D distances.
  double tolerance() const { return 1e-9 * diagonal_; }
  Eigen::Vector3i cell(const Eigen::Vector3d& x) const {
    return (x / cell_size_).array().floor().cast<int>();
  }
  static std::uint64_t key(const Eigen::Vector3i& c) {
    const auto h = [](int v) { return static_cast<std::uint64_t>(static_cast<std::uint32_t>(v)); };
    return (h(c.x()) * 73856093ULL) ^ (h(c.y()) * 19349663ULL) ^ (h(c.z()) * 83492791ULL);
  }

  // Vertices hashed in cells as wide as the widest side's first bound (a side's first band is
  // within a's cell and its 26 neighbours), each vertex's triangles, and the edge lengths.
  void index_vertices() {
    const auto& x = x_;
    const auto& triangles = triangles_;
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (const Eigen::Vector3d& p : x) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    diagonal_ = x.empty() ? 0.0 : (hi - lo).norm();
    double sum = 0.0;
    vertex_triangles_.resize(x.size());
    for (size_t t = 0; t < triangles.size(); ++t) {
      for (int k = 0; k < 3; ++k) {
        const double e = (x[static_cast<size_t>(triangles[t][k])] -
                          x[static_cast<size_t>(triangles[t][(k + 1) % 3])])
                             .norm();
        sum += e;
        max_edge_ = std::max(max_edge_, e);
        vertex_triangles_[static_cast<size_t>(triangles[t][k])].push_back(static_cast<int>(t));
      }
    }
    mean_edge_ = triangles.empty() ? 0.0 : sum / (3.0 * static_cast<double>(triangles.size()));
    cell_size_ = 4.0 * mean_edge_;
    for (size_t i = 0; i < where_.size(); ++i) {
      cell_size_ = std::max(cell_size_, chord_bound(i, (i + 1) % where_.size(), kSlacks[0]));
    }
    if (!(cell_size_ > 0.0)) {
      cell_size_ = 1.0;
    }
    for (size_t v = 0; v < x.size(); ++v) {
      cells_[key(cell(x[v]))].push_back(static_cast<int>(v));
    }
  }

  const std::vector<Eigen::Vector3d>& x_;
  const std::vector<Eigen::Vector3i>& triangles_;
  const std::vector<MeshLocation>& corners_;
  const std::string& name_;
  std::vector<Eigen::Vector3d> where_;  // the corners in 3D
  double diagonal_ = 0.0;               // of the tessellation's bounding box
  double mean_edge_ = 0.0;
  double max_edge_ = 0.0;
  double cell_size_ = 1.0;
  std::vector<std::vector<int>> vertex_triangles_;
  std::unordered_map<std::uint64_t, std::vector<int>> cells_;
  std::unique_ptr<HeatGeodesics> heat_;
  std::vector<Eigen::VectorXd> dist_;
};

/// The exact shortest path of the side from corner i to corner j.
PolygonSide side_path(ExactGeodesics& geodesics, SideBands& bands,
                      const std::vector<MeshLocation>& corners, size_t i, size_t j) {
  for (const double slack : kSlacks) {
    const double bound = bands.chord_bound(i, j, slack);
    try {
      GeodesicPath path = geodesics.path(corners[i], corners[j], bands.chord(i, j, bound));
      if (bands.certifies(bound, path.length)) {
        return {std::move(path), SideBand::Chord};
      }
      return {
          geodesics.path(corners[i], corners[j], bands.chord(i, j, bands.enclosing(path.length))),
          SideBand::Enclosing};
    } catch (const Error&) {
      // The chord's band does not connect the ends, or pinches into a non-manifold.
    }
  }
  return {geodesics.path(corners[i], corners[j], bands.heat(i, j)), SideBand::Heat};
}

}  // namespace

std::vector<PolygonSide> polygon_sides(const std::vector<Eigen::Vector3d>& positions,
                                       const std::vector<Eigen::Vector3i>& triangles,
                                       const std::vector<MeshLocation>& corners,
                                       const std::string& name) {
  ExactGeodesics geodesics(positions, triangles, name);
  SideBands bands(positions, triangles, corners, name);
  std::vector<PolygonSide> sides;
  for (size_t i = 0; i < corners.size(); ++i) {
    sides.push_back(side_path(geodesics, bands, corners, i, (i + 1) % corners.size()));
  }
  return sides;
}

}  // namespace elastic::regions_detail
