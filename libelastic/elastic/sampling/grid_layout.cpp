#include "elastic/sampling/grid_layout.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <string>

#include "elastic/core/error.h"
#include "elastic/core/triangle_locator_2d.h"
#include "elastic/sampling/annulus_triangulation.h"
#include "elastic/sampling/boundary_sampler.h"

namespace elastic {
namespace {

constexpr long kMinParticles = 16;
constexpr long kMaxParticles = 5'000'000;
constexpr int kMinInterior = 4;

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.x() * b.y() - a.y() * b.x();
}

/// The region flattened, oriented counter-clockwise, scaled to the 3D area and centred.
struct ScaledFlattening {
  std::vector<Eigen::Vector2d> uv;
  FlatteningMethod method = FlatteningMethod::Conformal;
};

ScaledFlattening scaled_flattening(const Region& region, const GridLayoutOptions& options) {
  const RegionFlattening flat =
      flatten_region(region, FlatteningOptions{.method = options.flattening});
  if (flat.folded_triangles > 0) {
    throw NumericalError(options.name, "the flattening folds " +
                                           std::to_string(flat.folded_triangles) +
                                           " triangles; cannot lay out a grid");
  }
  ScaledFlattening out;
  out.method = flat.method;
  out.uv = flat.uv;
  // Orientation: the boundary must run counter-clockwise in the plane (interior on the left).
  double boundary_area = 0.0;
  const size_t nb = region.boundary.size();
  for (size_t k = 0; k < nb; ++k) {
    boundary_area += cross2(out.uv[region.boundary[k]], out.uv[region.boundary[(k + 1) % nb]]);
  }
  if (boundary_area < 0.0) {
    for (Eigen::Vector2d& p : out.uv) {
      p.x() = -p.x();
    }
  }
  double area2 = 0.0;
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const Eigen::Vector3i& t : region.triangles) {
    const Eigen::Vector2d &a = out.uv[t[0]], &b = out.uv[t[1]], &c = out.uv[t[2]];
    const double area = 0.5 * std::abs(cross2(b - a, c - a));
    area2 += area;
    centroid += area * (a + b + c) / 3.0;
  }
  const double area3 = region.area();
  if (!(area2 > 0.0) || !(area3 > 0.0)) {
    throw InvalidInputError(options.name, "the region has zero area");
  }
  centroid /= area2;
  // Uniform scale so that planar area = surface area: lattice steps then approximate surface
  // lengths on average over the region.
  const double scale = std::sqrt(area3 / area2);
  for (Eigen::Vector2d& p : out.uv) {
    p = scale * (p - centroid);
  }
  return out;
}

/// One evaluation of the layout for a spacing h: boundary particles, kept lattice points, selected
/// cells.
struct Lattice {
  double h = 0.0;
  Eigen::Vector2d offset = Eigen::Vector2d::Zero();  ///< lattice origin
  int i0 = 0, j0 = 0;                                ///< lattice index of local point (0, 0)
  int nx = 0, ny = 0;                                ///< lattice points per row / column
  std::vector<BoundarySampler::Sample> boundary;
  std::vector<Eigen::Vector2d> boundary2d;
  std::vector<char> cells;  ///< (nx-1) x (ny-1), 1 when the cell is a quad of the grid
  int interior = 0;         ///< lattice points used by selected cells
  int count() const { return interior + static_cast<int>(boundary.size()); }
  Eigen::Vector2d point(int i, int j) const { return offset + h * Eigen::Vector2d(i0 + i, j0 + j); }
  bool cell(int a, int b) const {
    return a >= 0 && b >= 0 && a < nx - 1 && b < ny - 1 &&
           cells[static_cast<size_t>(b) * (nx - 1) + a];
  }
};

// Keeps only the largest edge-connected group of selected cells (ties: the first in scan order).
bool keep_largest_component(Lattice& L) {
  const int cx = L.nx - 1;
  std::vector<int> label(L.cells.size(), -1);
  int best_label = -1, best_size = 0, labels = 0;
  for (int start = 0; start < static_cast<int>(L.cells.size()); ++start) {
    if (!L.cells[start] || label[start] >= 0) {
      continue;
    }
    int size = 0;
    std::deque<int> queue{start};
    label[start] = labels;
    while (!queue.empty()) {
      const int c = queue.front();
      queue.pop_front();
      ++size;
      const int a = c % cx, b = c / cx;
      const int nbr[4][2] = {{a - 1, b}, {a + 1, b}, {a, b - 1}, {a, b + 1}};
      for (const auto& n : nbr) {
        if (!L.cell(n[0], n[1])) {
          continue;
        }
        const int id = n[1] * cx + n[0];
        if (label[id] < 0) {
          label[id] = labels;
          queue.push_back(id);
        }
      }
    }
    if (size > best_size) {
      best_size = size;
      best_label = labels;
    }
    ++labels;
  }
  bool changed = false;
  for (size_t c = 0; c < L.cells.size(); ++c) {
    if (L.cells[c] && label[c] != best_label) {
      L.cells[c] = 0;
      changed = true;
    }
  }
  return changed;
}

// Selects unselected cells enclosed by selected ones (not reachable from outside through unselected
// cells sharing an edge; cells meeting only at a corner do not connect, as the corner belongs to
// the selected cells).
void fill_holes(Lattice& L) {
  const int cx = L.nx - 1, cy = L.ny - 1;
  std::vector<char> outside(L.cells.size(), 0);
  std::deque<int> queue;
  for (int b = 0; b < cy; ++b) {
    for (int a = 0; a < cx; ++a) {
      const int id = b * cx + a;
      if ((a == 0 || b == 0 || a == cx - 1 || b == cy - 1) && !L.cells[id]) {
        outside[id] = 1;
        queue.push_back(id);
      }
    }
  }
  while (!queue.empty()) {
    const int c = queue.front();
    queue.pop_front();
    const int a = c % cx, b = c / cx;
    const int nbr[4][2] = {{a - 1, b}, {a + 1, b}, {a, b - 1}, {a, b + 1}};
    for (const auto& n : nbr) {
      if (n[0] < 0 || n[1] < 0 || n[0] >= cx || n[1] >= cy) {
        continue;
      }
      const int id = n[1] * cx + n[0];
      if (!L.cells[id] && !outside[id]) {
        outside[id] = 1;
        queue.push_back(id);
      }
    }
  }
  for (size_t c = 0; c < L.cells.size(); ++c) {
    if (!L.cells[c] && !outside[c]) {
      L.cells[c] = 1;
    }
  }
}

// Removes cells that touch another selected cell only at a corner (a "pinch" vertex), which would
// make the outline non-simple. Returns true when something was removed.
bool remove_pinches(Lattice& L) {
  const int cx = L.nx - 1;
  bool changed = false;
  auto neighbours = [&](int a, int b) {
    return int(L.cell(a - 1, b)) + int(L.cell(a + 1, b)) + int(L.cell(a, b - 1)) +
           int(L.cell(a, b + 1));
  };
  for (int j = 1; j < L.ny - 1; ++j) {
    for (int i = 1; i < L.nx - 1; ++i) {
      const bool c00 = L.cell(i - 1, j - 1), c10 = L.cell(i, j - 1);
      const bool c01 = L.cell(i - 1, j), c11 = L.cell(i, j);
      int a0 = -1, b0 = -1, a1 = -1, b1 = -1;
      if (c00 && c11 && !c10 && !c01) {
        a0 = i - 1, b0 = j - 1, a1 = i, b1 = j;
      } else if (c10 && c01 && !c00 && !c11) {
        a0 = i, b0 = j - 1, a1 = i - 1, b1 = j;
      } else {
        continue;
      }
      // Remove the less connected of the two (the second one on ties): deterministic.
      if (neighbours(a0, b0) < neighbours(a1, b1)) {
        L.cells[static_cast<size_t>(b0) * cx + a0] = 0;
      } else {
        L.cells[static_cast<size_t>(b1) * cx + a1] = 0;
      }
      changed = true;
    }
  }
  return changed;
}

int count_used_points(const Lattice& L) {
  int n = 0;
  for (int j = 0; j < L.ny; ++j) {
    for (int i = 0; i < L.nx; ++i) {
      if (L.cell(i - 1, j - 1) || L.cell(i, j - 1) || L.cell(i - 1, j) || L.cell(i, j)) {
        ++n;
      }
    }
  }
  return n;
}

Lattice build_lattice(const Region& region, const ScaledFlattening& flat,
                      const BoundarySampler& sampler, double h, const Eigen::Vector2d& offset,
                      const GridLayoutOptions& options) {
  Lattice L;
  L.h = h;
  L.offset = offset;
  // Boundary particles at equal 3D arc length: s_k = k / M.
  const long m_long = std::lround(sampler.length() / h);
  const int m = static_cast<int>(std::clamp<long>(m_long, 3, 4 * kMaxParticles));
  L.boundary.resize(m);
  L.boundary2d.resize(m);
  const int nb = static_cast<int>(region.boundary.size());
  for (int k = 0; k < m; ++k) {
    L.boundary[k] = sampler.at(static_cast<double>(k) / m);
    const BoundarySampler::Sample& s = L.boundary[k];
    L.boundary2d[k] = (1.0 - s.t) * flat.uv[region.boundary[s.segment]] +
                      s.t * flat.uv[region.boundary[(s.segment + 1) % nb]];
  }
  Eigen::Vector2d lo = L.boundary2d[0], hi = L.boundary2d[0];
  for (const Eigen::Vector2d& p : L.boundary2d) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  L.i0 = static_cast<int>(std::ceil((lo.x() - offset.x()) / h));
  L.j0 = static_cast<int>(std::ceil((lo.y() - offset.y()) / h));
  L.nx = static_cast<int>(std::floor((hi.x() - offset.x()) / h)) - L.i0 + 1;
  L.ny = static_cast<int>(std::floor((hi.y() - offset.y()) / h)) - L.j0 + 1;
  if (L.nx < 2 || L.ny < 2) {
    L.nx = L.ny = 0;
    return L;
  }
  std::vector<char> keep(static_cast<size_t>(L.nx) * L.ny, 0);

  // Inside test by scanlines: crossings of each lattice row with the polygon's edges (half-open
  // rule), then a point is inside when an odd number of crossings lies to its left.
  std::vector<double> xs;
  for (int j = 0; j < L.ny; ++j) {
    const double y = L.point(0, j).y();
    xs.clear();
    for (int k = 0; k < m; ++k) {
      const Eigen::Vector2d& p = L.boundary2d[k];
      const Eigen::Vector2d& q = L.boundary2d[(k + 1) % m];
      if ((p.y() <= y) != (q.y() <= y)) {
        xs.push_back(p.x() + (y - p.y()) / (q.y() - p.y()) * (q.x() - p.x()));
      }
    }
    std::sort(xs.begin(), xs.end());
    size_t left = 0;
    for (int i = 0; i < L.nx; ++i) {
      const double x = L.point(i, j).x();
      while (left < xs.size() && xs[left] < x) {
        ++left;
      }
      keep[static_cast<size_t>(j) * L.nx + i] = (left % 2 == 1) ? 1 : 0;
    }
  }
  // Clearance: reject points closer than clearance * h to any polygon edge (each edge visits the
  // lattice points in its bounding box grown by the clearance).
  const double clear = options.clearance * h;
  for (int k = 0; k < m; ++k) {
    const Eigen::Vector2d& p = L.boundary2d[k];
    const Eigen::Vector2d& q = L.boundary2d[(k + 1) % m];
    const Eigen::Vector2d elo = p.cwiseMin(q).array() - clear, ehi = p.cwiseMax(q).array() + clear;
    const int ia = std::max(0, static_cast<int>(std::ceil((elo.x() - offset.x()) / h)) - L.i0);
    const int ib =
        std::min(L.nx - 1, static_cast<int>(std::floor((ehi.x() - offset.x()) / h)) - L.i0);
    const int ja = std::max(0, static_cast<int>(std::ceil((elo.y() - offset.y()) / h)) - L.j0);
    const int jb =
        std::min(L.ny - 1, static_cast<int>(std::floor((ehi.y() - offset.y()) / h)) - L.j0);
    const Eigen::Vector2d pq = q - p;
    const double len2 = pq.squaredNorm();
    for (int j = ja; j <= jb; ++j) {
      for (int i = ia; i <= ib; ++i) {
        char& flag = keep[static_cast<size_t>(j) * L.nx + i];
        if (!flag) {
          continue;
        }
        const Eigen::Vector2d x = L.point(i, j);
        const double t = len2 > 0.0 ? std::clamp((x - p).dot(pq) / len2, 0.0, 1.0) : 0.0;
        if ((x - (p + t * pq)).squaredNorm() < clear * clear) {
          flag = 0;
        }
      }
    }
  }
  // Cells with four kept corners, cleaned to one simple, hole-free patch.
  L.cells.assign(static_cast<size_t>(L.nx - 1) * (L.ny - 1), 0);
  for (int b = 0; b + 1 < L.ny; ++b) {
    for (int a = 0; a + 1 < L.nx; ++a) {
      const auto k = [&](int i, int j) { return keep[static_cast<size_t>(j) * L.nx + i] != 0; };
      L.cells[static_cast<size_t>(b) * (L.nx - 1) + a] =
          k(a, b) && k(a + 1, b) && k(a, b + 1) && k(a + 1, b + 1);
    }
  }
  keep_largest_component(L);
  fill_holes(L);
  for (int guard = 0; guard < 1000; ++guard) {
    const bool pinched = remove_pinches(L);
    const bool split = keep_largest_component(L);
    if (!pinched && !split) {
      break;
    }
  }
  L.interior = count_used_points(L);
  return L;
}

// The band triangulation of step 4 with the guarantee of docs/sampling.md: no triangle has all
// three corners on the boundary (such a triangle could not move at all while the boundary is held,
// and where the boundary turns sharply, at a rectangle's corner or a polygon's vertex, its
// corners land nearly collinear on a smooth target curve: a fold no relaxation can undo). Each
// such triangle gets a free point at its centroid, strictly inside it and so inside the band, and
// the band is triangulated again with those points; repeated until none is left (one round in
// practice: a free point's triangles all have it as a corner).
struct BandTriangulation {
  std::vector<Eigen::Vector3i> triangles;  ///< indices: points, then boundary, then steiner
  std::vector<Eigen::Vector2d> steiner;    ///< the free points added, in index order
};

BandTriangulation triangulate_band(const std::vector<Eigen::Vector2d>& flat_positions, int interior,
                                   const std::vector<int>& boundary_ids,
                                   const std::vector<int>& outline, const std::string& name) {
  constexpr int kMaxRounds = 4;
  const int m = static_cast<int>(boundary_ids.size());
  std::vector<Eigen::Vector2d> points = flat_positions;
  BandTriangulation band;
  AnnulusTriangulationOptions options{.name = name, .steiner = {}};
  for (int round = 0;; ++round) {
    band.triangles = triangulate_annulus(points, boundary_ids, outline, options).triangles;
    const auto on_boundary = [&](int index) { return index >= interior && index < interior + m; };
    int added = 0;
    for (const Eigen::Vector3i& t : band.triangles) {
      if (on_boundary(t[0]) && on_boundary(t[1]) && on_boundary(t[2])) {
        const Eigen::Vector2d centroid = (points[t[0]] + points[t[1]] + points[t[2]]) / 3.0;
        options.steiner.push_back(static_cast<int>(points.size()));
        points.push_back(centroid);
        band.steiner.push_back(centroid);
        ++added;
      }
    }
    if (added == 0) {
      return band;
    }
    if (round + 1 == kMaxRounds) {
      throw NumericalError(name,
                           "grid layout: band triangles with every corner on the boundary "
                           "remain after " +
                               std::to_string(kMaxRounds) + " rounds");
    }
  }
}

}  // namespace

GridLayoutResult layout_particle_grid(const Region& region, const GridLayoutOptions& options) {
  const long n_req = options.particles;
  if (n_req < kMinParticles || n_req > kMaxParticles) {
    throw InvalidInputError(options.name, "absurd particle count " + std::to_string(n_req) +
                                              " (expected " + std::to_string(kMinParticles) +
                                              " .. " + std::to_string(kMaxParticles) + ")");
  }
  if (!region.surface || region.num_triangles() == 0 || region.boundary.size() < 3) {
    throw InvalidInputError(options.name, "the region is empty");
  }
  if (!(options.clearance > 1.0 / std::sqrt(2.0)) || !(options.count_tolerance > 0.0)) {
    throw InvalidInputError(options.name,
                            "grid layout options out of range (clearance must exceed "
                            "1/sqrt(2), count tolerance must be positive)");
  }

  const ScaledFlattening flat = scaled_flattening(region, options);
  const BoundarySampler sampler(region, options.name);
  const double area = region.area();
  const double length = sampler.length();
  const double n = static_cast<double>(n_req);

  // First guess: interior ~ (A - L (c + 1/2) h) / h^2 (the band loses about (c + 1/2) h along the
  // boundary), boundary ~ L / h. Solving N h^2 + L (c - 1/2) h - A = 0 for h > 0.
  const double bcoef = length * (options.clearance - 0.5);
  const double h_first = (-bcoef + std::sqrt(bcoef * bcoef + 4.0 * n * area)) / (2.0 * n);

  // Spacing search on the actual count, for a few lattice offsets (the count is a step function of
  // h; shifting the lattice moves the steps, which helps small counts).
  const Eigen::Vector2d offsets[] = {
      {0.0, 0.0}, {0.5, 0.5}, {0.25, 0.25}, {0.5, 0.0}, {0.125, 0.375}};
  Lattice best;
  double best_error = std::numeric_limits<double>::infinity();
  int steps = 0;
  for (const Eigen::Vector2d& offset_fraction : offsets) {
    double h = h_first;
    double h_small = 0.0, h_big = std::numeric_limits<double>::infinity();  // count > N at h_small
    for (int step = 0; step < options.max_search_steps; ++step) {
      ++steps;
      Lattice L = build_lattice(region, flat, sampler, h, offset_fraction * h, options);
      const double count = static_cast<double>(L.count());
      const double error = std::abs(count - n) / n;
      const bool usable = L.interior >= kMinInterior;
      if (usable && error < best_error) {
        best_error = error;
        best = std::move(L);
      } else if (!usable && best.nx == 0 && best_error == std::numeric_limits<double>::infinity()) {
        best = std::move(L);  // keep something to report on
      }
      if (usable && error <= options.count_tolerance) {
        break;
      }
      if (count > n) {
        h_small = std::max(h_small, h);
      } else {
        h_big = std::min(h_big, h);
      }
      if (h_small > 0.0 && std::isfinite(h_big)) {
        if (h_big / h_small < 1.0 + 1e-9) {
          break;
        }
        h = std::sqrt(h_small * h_big);
      } else {
        // count ~ 1/h^2: rescale, within a factor of 2 per step.
        h *= std::clamp(std::sqrt(std::max(count, 1.0) / n), 0.5, 2.0);
      }
    }
    if (best_error <= options.count_tolerance) {
      break;
    }
  }
  if (!std::isfinite(best_error)) {
    throw InvalidInputError(options.name, "region too small or too thin for " +
                                              std::to_string(n_req) +
                                              " particles: the grid would have fewer than " +
                                              std::to_string(kMinInterior) + " interior particles");
  }
  if (best_error > options.max_count_error) {
    throw NumericalError(options.name, "could not lay out " + std::to_string(n_req) +
                                           " particles within " +
                                           std::to_string(100.0 * options.max_count_error) +
                                           "% (closest: " + std::to_string(best.count()) + ")");
  }

  // Particle numbering: lattice points in row order, then boundary particles in curve order.
  const Lattice& L = best;
  std::vector<int> point_id(static_cast<size_t>(L.nx) * L.ny, -1);
  std::vector<Eigen::Vector2d> flat_positions;
  std::vector<char> regular;
  for (int j = 0; j < L.ny; ++j) {
    for (int i = 0; i < L.nx; ++i) {
      const int around = int(L.cell(i - 1, j - 1)) + int(L.cell(i, j - 1)) + int(L.cell(i - 1, j)) +
                         int(L.cell(i, j));
      if (around == 0) {
        continue;
      }
      point_id[static_cast<size_t>(j) * L.nx + i] = static_cast<int>(flat_positions.size());
      flat_positions.push_back(L.point(i, j));
      regular.push_back(around == 4 ? 1 : 0);
    }
  }
  int interior = static_cast<int>(flat_positions.size());  // lattice points; + band points below
  const int m = static_cast<int>(L.boundary.size());
  for (int k = 0; k < m; ++k) {
    flat_positions.push_back(L.boundary2d[k]);
    regular.push_back(0);
  }
  const auto id = [&](int i, int j) { return point_id[static_cast<size_t>(j) * L.nx + i]; };

  // Outline of the selected cells, counter-clockwise: cell edges with no selected cell on their
  // right.
  std::map<int, int> next_on_outline;
  int first_outline = std::numeric_limits<int>::max();
  std::vector<Eigen::Vector4i> quads;
  for (int b = 0; b + 1 < L.ny; ++b) {
    for (int a = 0; a + 1 < L.nx; ++a) {
      if (!L.cell(a, b)) {
        continue;
      }
      const int v00 = id(a, b), v10 = id(a + 1, b), v11 = id(a + 1, b + 1), v01 = id(a, b + 1);
      quads.emplace_back(v00, v10, v11, v01);
      const auto edge = [&](bool open, int from, int to) {
        if (!open) {
          return;
        }
        next_on_outline[from] = to;
        first_outline = std::min(first_outline, from);
      };
      edge(!L.cell(a, b - 1), v00, v10);
      edge(!L.cell(a + 1, b), v10, v11);
      edge(!L.cell(a, b + 1), v11, v01);
      edge(!L.cell(a - 1, b), v01, v00);
    }
  }
  std::vector<int> outline;
  for (int v = first_outline;;) {
    outline.push_back(v);
    v = next_on_outline.at(v);
    if (v == first_outline) {
      break;
    }
    if (outline.size() > next_on_outline.size()) {
      throw NumericalError(options.name, "grid layout: the quad outline is not one simple loop");
    }
  }
  if (outline.size() != next_on_outline.size()) {
    throw NumericalError(options.name, "grid layout: the quad outline is not one simple loop");
  }
  std::vector<int> boundary_ids(m);
  for (int k = 0; k < m; ++k) {
    boundary_ids[k] = interior + k;
  }
  BandTriangulation band =
      triangulate_band(flat_positions, interior, boundary_ids, outline, options.name);
  // Renumber: lattice points, then the band's free points, then the boundary particles in curve
  // order (the numbering the rest of the layout and ParticleGrid expect).
  const int steiner = static_cast<int>(band.steiner.size());
  for (Eigen::Vector3i& t : band.triangles) {
    for (int c = 0; c < 3; ++c) {
      if (t[c] >= interior + m) {
        t[c] -= m;  // free band point s: interior + m + s -> interior + s
      } else if (t[c] >= interior) {
        t[c] += steiner;  // boundary particle k: interior + k -> interior + steiner + k
      }
    }
  }
  flat_positions.insert(flat_positions.begin() + interior, band.steiner.begin(),
                        band.steiner.end());
  regular.insert(regular.begin() + interior, static_cast<size_t>(steiner), char(0));
  interior += steiner;

  // Surface points: interior particles through the flattening, boundary particles from the curve.
  GridLayoutResult result;
  ParticleGrid& grid = result.grid;
  const int total = interior + m;
  grid.source_points.resize(total);
  std::vector<Eigen::Vector3d> positions(total);
  const bool with_uv = !region.texcoords.empty();
  if (with_uv) {
    grid.source_uv.resize(total);
  }
  const TriangleLocator2D locator(flat.uv, region.triangles);
  tbb::parallel_for(0, interior, [&](int p) {
    TriangleLocator2D::Hit hit = locator.locate(flat_positions[p], 1e-9);
    if (!hit.found()) {
      hit = locator.nearest(flat_positions[p]);  // round-off at the region's edge only
    }
    const Eigen::Vector3d& w = hit.barycentric;
    grid.source_points[p] = region.point_in_triangle(hit.triangle, w[1], w[2]);
    positions[p] = region.surface->position(grid.source_points[p]);
    if (with_uv) {
      const Eigen::Vector3i& t = region.triangles[hit.triangle];
      grid.source_uv[p] = w[0] * region.texcoords[t[0]] + w[1] * region.texcoords[t[1]] +
                          w[2] * region.texcoords[t[2]];
    }
  });
  for (int k = 0; k < m; ++k) {
    const BoundarySampler::Sample& s = L.boundary[k];
    grid.source_points[interior + k] = s.point;
    positions[interior + k] = s.position;
    if (with_uv) {
      const Eigen::Vector3i& t = region.triangles[s.triangle];
      grid.source_uv[interior + k] = s.barycentric[0] * region.texcoords[t[0]] +
                                     s.barycentric[1] * region.texcoords[t[1]] +
                                     s.barycentric[2] * region.texcoords[t[2]];
    }
  }

  // The OpenMesh grid.
  std::vector<GridMesh::VertexHandle> vh(total);
  for (int p = 0; p < total; ++p) {
    vh[p] =
        grid.mesh.add_vertex(GridMesh::Point(positions[p].x(), positions[p].y(), positions[p].z()));
  }
  for (const Eigen::Vector4i& q : quads) {
    if (!grid.mesh.add_face({vh[q[0]], vh[q[1]], vh[q[2]], vh[q[3]]}).is_valid()) {
      throw NumericalError(options.name, "grid layout: a quad could not be added to the grid mesh");
    }
  }
  for (const Eigen::Vector3i& t : band.triangles) {
    if (!grid.mesh.add_face({vh[t[0]], vh[t[1]], vh[t[2]]}).is_valid()) {
      throw NumericalError(options.name,
                           "grid layout: a band triangle could not be added to the grid mesh");
    }
  }
  grid.is_boundary.assign(total, 0);
  grid.boundary_loop.resize(m);
  grid.boundary_parameter.resize(m);
  for (int k = 0; k < m; ++k) {
    grid.is_boundary[interior + k] = 1;
    grid.boundary_loop[k] = interior + k;
    grid.boundary_parameter[k] = L.boundary[k].s;
  }
  grid.build_springs();

  result.spacing = L.h;
  result.interior_particles = interior;
  result.band_points = steiner;
  result.boundary_particles = m;
  result.quads = static_cast<int>(quads.size());
  result.band_triangles = static_cast<int>(band.triangles.size());
  result.count_error = (static_cast<double>(total) - n) / n;
  result.search_steps = steps;
  result.flattening = flat.method;
  result.flat_positions = std::move(flat_positions);
  result.is_regular = std::move(regular);
  return result;
}

}  // namespace elastic
