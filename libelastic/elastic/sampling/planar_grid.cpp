#include "elastic/sampling/planar_grid.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <string>

#include "elastic/core/error.h"
#include "elastic/sampling/annulus_triangulation.h"

namespace elastic {
namespace {

// Keeps only the largest edge-connected group of selected cells (ties: the first in scan order).
bool keep_largest_component(PlanarLattice& L) {
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
void fill_holes(PlanarLattice& L) {
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
bool remove_pinches(PlanarLattice& L) {
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

int count_used_points(const PlanarLattice& L) {
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

// Signed double area of the triangle (a, b, c).
double orientation(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const Eigen::Vector2d u = b - a, v = c - a;
  return u.x() * v.y() - u.y() * v.x();
}

// The band triangulation of step 2 with the guarantee of docs/sampling.md: no triangle has all
// three corners on the boundary. Such a triangle could not move at all while the boundary is
// held, and where the boundary turns sharply (a rectangle's corner, a polygon's tip) its corners
// land nearly collinear on a smooth target curve: a fold no relaxation can undo. Each such
// triangle gets a free point at its centroid, strictly inside it and so inside the band, and the
// band is triangulated again with those points (Delaunay keeps the triangles well shaped). A
// free point's own triangles all have it as a corner, but the new Delaunay triangulation may still
// join three boundary points elsewhere (in a long thin tip); after delaunay_rounds rounds any such
// triangle left is split at its centroid into three triangles that each have the new point as a
// corner, which ends the loop for every polygon.
struct BandTriangulation {
  std::vector<Eigen::Vector3i> triangles;  ///< indices: points, then boundary, then steiner
  std::vector<Eigen::Vector2d> steiner;    ///< the free points added, in index order
};

BandTriangulation triangulate_band(const std::vector<Eigen::Vector2d>& flat_positions, int interior,
                                   const std::vector<int>& boundary_ids,
                                   const std::vector<int>& outline, const std::string& name,
                                   int delaunay_rounds) {
  const int m = static_cast<int>(boundary_ids.size());
  std::vector<Eigen::Vector2d> points = flat_positions;
  BandTriangulation band;
  AnnulusTriangulationOptions options{
      .name = name,
      .outer_label =
          "the boundary particles' polygon (in the flattened region; a part of the "
          "region is narrower than the particle spacing: use more particles)",
      .inner_label = "the grid outline",
      .steiner = {}};
  const auto on_boundary = [&](int index) { return index >= interior && index < interior + m; };
  const auto frozen = [&](const Eigen::Vector3i& t) {
    return on_boundary(t[0]) && on_boundary(t[1]) && on_boundary(t[2]);
  };
  // The centroid of a triangle as a new point; it must be strictly inside (it is, up to round-off
  // on a triangle too thin for double precision, which constrained Delaunay does not produce).
  const auto add_centroid = [&](const Eigen::Vector3i& t) {
    const Eigen::Vector2d &a = points[t[0]], &b = points[t[1]], &c = points[t[2]];
    const Eigen::Vector2d centroid = (a + b + c) / 3.0;
    if (!(orientation(a, b, centroid) > 0.0 && orientation(b, c, centroid) > 0.0 &&
          orientation(c, a, centroid) > 0.0)) {
      throw NumericalError(name, "grid layout: a band triangle is too thin to take a free point");
    }
    const int index = static_cast<int>(points.size());
    points.push_back(centroid);
    band.steiner.push_back(centroid);
    return index;
  };
  for (int round = 0;; ++round) {
    band.triangles = triangulate_annulus(points, boundary_ids, outline, options).triangles;
    if (round == delaunay_rounds) {
      break;
    }
    int added = 0;
    for (const Eigen::Vector3i& t : band.triangles) {
      if (frozen(t)) {
        options.steiner.push_back(add_centroid(t));
        ++added;
      }
    }
    if (added == 0) {
      return band;
    }
  }
  // Last resort: split what is left at its centroid, without re-triangulating.
  std::vector<Eigen::Vector3i> split;
  split.reserve(band.triangles.size());
  for (const Eigen::Vector3i& t : band.triangles) {
    if (!frozen(t)) {
      split.push_back(t);
      continue;
    }
    const int c = add_centroid(t);
    split.emplace_back(t[0], t[1], c);
    split.emplace_back(t[1], t[2], c);
    split.emplace_back(t[2], t[0], c);
  }
  band.triangles = std::move(split);
  return band;
}

// The quads of the selected cells and their outline, counter-clockwise: cell edges with no
// selected cell on their right. `point_id` numbers the lattice points (-1: unused).
void add_quads_and_outline(const PlanarLattice& L, const std::vector<int>& point_id,
                           const std::string& name, PlanarGrid& grid) {
  const auto id = [&](int i, int j) { return point_id[static_cast<size_t>(j) * L.nx + i]; };
  std::map<int, int> next_on_outline;
  int first_outline = std::numeric_limits<int>::max();
  for (int b = 0; b + 1 < L.ny; ++b) {
    for (int a = 0; a + 1 < L.nx; ++a) {
      if (!L.cell(a, b)) {
        continue;
      }
      const int v00 = id(a, b), v10 = id(a + 1, b), v11 = id(a + 1, b + 1), v01 = id(a, b + 1);
      grid.quads.emplace_back(v00, v10, v11, v01);
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
  for (int v = first_outline;;) {
    grid.outline.push_back(v);
    v = next_on_outline.at(v);
    if (v == first_outline) {
      break;
    }
    if (grid.outline.size() > next_on_outline.size()) {
      throw NumericalError(name, "grid layout: the quad outline is not one simple loop");
    }
  }
  if (grid.outline.size() != next_on_outline.size()) {
    throw NumericalError(name, "grid layout: the quad outline is not one simple loop");
  }
}

// Lattice points of L (its frame: h, offset, i0, j0, nx, ny) inside the polygon and at least
// `clear` from each of its edges, as flags in row order.
std::vector<char> kept_points(const std::vector<Eigen::Vector2d>& polygon, const PlanarLattice& L,
                              double clear) {
  const int m = static_cast<int>(polygon.size());
  const double h = L.h;
  const Eigen::Vector2d& offset = L.offset;
  std::vector<char> keep(static_cast<size_t>(L.nx) * L.ny, 0);

  // Inside test by scanlines: crossings of each lattice row with the polygon's edges (half-open
  // rule), then a point is inside when an odd number of crossings lies to its left.
  std::vector<double> xs;
  for (int j = 0; j < L.ny; ++j) {
    const double y = L.point(0, j).y();
    xs.clear();
    for (int k = 0; k < m; ++k) {
      const Eigen::Vector2d& p = polygon[k];
      const Eigen::Vector2d& q = polygon[(k + 1) % m];
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
  for (int k = 0; k < m; ++k) {
    const Eigen::Vector2d& p = polygon[k];
    const Eigen::Vector2d& q = polygon[(k + 1) % m];
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
  return keep;
}

}  // namespace

PlanarLattice select_lattice_cells(const std::vector<Eigen::Vector2d>& polygon, double h,
                                   const Eigen::Vector2d& offset,
                                   const PlanarLatticeOptions& options) {
  PlanarLattice L;
  L.h = h;
  L.offset = offset;
  const int m = static_cast<int>(polygon.size());
  if (m < 3) {
    return L;
  }
  Eigen::Vector2d lo = polygon[0], hi = polygon[0];
  for (const Eigen::Vector2d& p : polygon) {
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
  const std::vector<char> keep = kept_points(polygon, L, options.clearance * h);
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
  L.points = count_used_points(L);
  return L;
}

PlanarGrid build_planar_grid(const std::vector<Eigen::Vector2d>& polygon, const PlanarLattice& L,
                             const PlanarGridOptions& options) {
  const std::string& name = options.name;
  if (L.nx < 2 || L.ny < 2 || std::find(L.cells.begin(), L.cells.end(), char(1)) == L.cells.end()) {
    throw InvalidInputError(name, "grid layout: no lattice cell fits inside the boundary");
  }
  PlanarGrid grid;
  // Numbering: lattice points in row order, then boundary particles in curve order (the band's
  // free points are inserted between the two at the end).
  std::vector<int> point_id(static_cast<size_t>(L.nx) * L.ny, -1);
  for (int j = 0; j < L.ny; ++j) {
    for (int i = 0; i < L.nx; ++i) {
      const int around = int(L.cell(i - 1, j - 1)) + int(L.cell(i, j - 1)) + int(L.cell(i - 1, j)) +
                         int(L.cell(i, j));
      if (around == 0) {
        continue;
      }
      point_id[static_cast<size_t>(j) * L.nx + i] = static_cast<int>(grid.points.size());
      grid.points.push_back(L.point(i, j));
      grid.regular.push_back(around == 4 ? 1 : 0);
    }
  }
  const int lattice = static_cast<int>(grid.points.size());
  const int m = static_cast<int>(polygon.size());
  for (int k = 0; k < m; ++k) {
    grid.points.push_back(polygon[k]);
    grid.regular.push_back(0);
  }
  add_quads_and_outline(L, point_id, name, grid);
  std::vector<int> boundary_ids(m);
  for (int k = 0; k < m; ++k) {
    boundary_ids[k] = lattice + k;
  }
  BandTriangulation band = triangulate_band(grid.points, lattice, boundary_ids, grid.outline, name,
                                            std::max(0, options.delaunay_rounds));
  // Renumber: lattice points, then the band's free points, then the boundary particles in curve
  // order.
  const int steiner = static_cast<int>(band.steiner.size());
  for (Eigen::Vector3i& t : band.triangles) {
    for (int c = 0; c < 3; ++c) {
      if (t[c] >= lattice + m) {
        t[c] -= m;  // free band point s: lattice + m + s -> lattice + s
      } else if (t[c] >= lattice) {
        t[c] += steiner;  // boundary particle k: lattice + k -> lattice + steiner + k
      }
    }
  }
  grid.points.insert(grid.points.begin() + lattice, band.steiner.begin(), band.steiner.end());
  grid.regular.insert(grid.regular.begin() + lattice, static_cast<size_t>(steiner), char(0));
  grid.triangles = std::move(band.triangles);
  grid.lattice_points = lattice;
  grid.band_points = steiner;
  grid.boundary_points = m;
  return grid;
}

}  // namespace elastic
