#include "elastic/surface/limit_tessellation.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "elastic/core/error.h"

namespace elastic {
namespace {

/// Undirected edge numbering of the control mesh: id of edge (a, b) by binary search.
class EdgeIndex {
 public:
  explicit EdgeIndex(const PolygonMesh& mesh) : nv_(mesh.num_vertices()) {
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const auto fv = mesh.face(f);
      const size_t n = fv.size();
      for (size_t i = 0; i < n; ++i) {
        keys_.push_back(key(fv[i], fv[(i + 1) % n]));
      }
    }
    std::sort(keys_.begin(), keys_.end());
    keys_.erase(std::unique(keys_.begin(), keys_.end()), keys_.end());
  }
  int size() const { return static_cast<int>(keys_.size()); }
  int id(int a, int b) const {
    return static_cast<int>(std::lower_bound(keys_.begin(), keys_.end(), key(a, b)) -
                            keys_.begin());
  }

 private:
  int64_t key(int a, int b) const {
    return static_cast<int64_t>(std::min(a, b)) * nv_ + std::max(a, b);
  }
  int64_t nv_;
  std::vector<int64_t> keys_;
};

}  // namespace

LimitTessellation tessellate(const LimitSurface& surface, const TessellationOptions& options) {
  const PolygonMesh& mesh = surface.control_mesh();
  const bool loop = surface.triangular_domain();
  const int nf = mesh.num_faces();

  // Catmull-Clark ptex faces come in two sizes: a quad's covers a whole control face, an n-gon's
  // sub-face a quarter-like piece whose edges are half control edges. Sampling every control edge
  // with N segments (N even when there are n-gons) makes both sides of every edge agree.
  long quads = 0, subfaces = 0;
  for (int f = 0; f < nf; ++f) {
    if (loop || mesh.face_size(f) == 4) {
      ++quads;
    } else {
      subfaces += mesh.face_size(f);
    }
  }
  const bool need_even = !loop && subfaces > 0;
  int n = options.resolution;
  if (options.target_triangles < 0) {
    throw InvalidInputError(surface.name(), "tessellation target_triangles " +
                                                std::to_string(options.target_triangles) +
                                                " is negative");
  }
  if (options.target_triangles > 0) {
    // Triangles per N^2: 1 per Loop triangle, 2 per quad, 1/2 per n-gon sub-face (N/2 segments).
    const double per_n2 =
        loop ? static_cast<double>(quads)
             : 2.0 * static_cast<double>(quads) + 0.5 * static_cast<double>(subfaces);
    const double exact = std::sqrt(static_cast<double>(options.target_triangles) / per_n2);
    // Nearest admissible resolution (even when needed, so that sub-faces get N/2 segments).
    const long step = need_even ? 2 : 1;
    n = static_cast<int>(
        std::clamp(step * std::lround(exact / static_cast<double>(step)), step, 1024L));
  } else if (n < 1 || n > 1024) {
    throw InvalidInputError(surface.name(), "tessellation resolution " + std::to_string(n) +
                                                " is out of range 1..1024");
  }
  if (need_even && n % 2 == 1) {
    n = std::min(n + 1, 1024);
  }

  LimitTessellation out;
  out.resolution = n;
  const EdgeIndex edges(mesh);
  std::vector<int> vertex_ids(static_cast<size_t>(mesh.num_vertices()), -1);
  std::vector<int> edge_ids(static_cast<size_t>(edges.size()) * static_cast<size_t>(n - 1), -1);
  std::vector<int> centre_ids(static_cast<size_t>(nf), -1);
  // Spokes of n-gons (sub-face i's edge 1, from the midpoint of control edge i to the centre), N/2
  // - 1 interior samples each; spoke_offset[f] is the first spoke of face f.
  std::vector<int64_t> spoke_offset(static_cast<size_t>(nf) + 1, 0);
  const int half = n / 2;
  for (int f = 0; f < nf; ++f) {
    const bool split = !loop && mesh.face_size(f) != 4;
    spoke_offset[static_cast<size_t>(f) + 1] =
        spoke_offset[static_cast<size_t>(f)] + (split ? mesh.face_size(f) : 0);
  }
  std::vector<int> spoke_ids(
      static_cast<size_t>(spoke_offset.back()) * static_cast<size_t>(std::max(half - 1, 0)), -1);

  auto make = [&](int* slot, const SurfacePoint& p) {
    if (slot && *slot >= 0) {
      return *slot;
    }
    const int id = static_cast<int>(out.points.size());
    out.points.push_back(p);
    if (slot) {
      *slot = id;
    }
    return id;
  };
  // Sample s of N along control edge e of face f (from corner e towards corner e+1).
  auto edge_slot = [&](int f, int e, int s) -> int* {
    const auto fv = mesh.face(f);
    const size_t k = fv.size();
    const int a = fv[static_cast<size_t>(e) % k], b = fv[(static_cast<size_t>(e) + 1) % k];
    if (s == 0) {
      return &vertex_ids[static_cast<size_t>(a)];
    }
    if (s == n) {
      return &vertex_ids[static_cast<size_t>(b)];
    }
    const int canonical = a < b ? s : n - s;
    return &edge_ids[static_cast<size_t>(edges.id(a, b)) * static_cast<size_t>(n - 1) +
                     static_cast<size_t>(canonical - 1)];
  };
  auto add_triangle = [&](int a, int b, int c, int face) {
    out.triangles.emplace_back(a, b, c);
    out.triangle_face.push_back(face);
  };

  std::vector<int> grid;
  for (int f = 0; f < nf; ++f) {
    const int k = mesh.face_size(f);
    const int first = surface.first_ptex_face(f);
    if (loop) {
      // Triangle grid: (i, j) with i + j <= N at (u, v) = (i, j) / N.
      auto at = [&](int i, int j) -> int& {
        return grid[static_cast<size_t>(j) * static_cast<size_t>(n + 1) + static_cast<size_t>(i)];
      };
      grid.assign(static_cast<size_t>(n + 1) * static_cast<size_t>(n + 1), -1);
      for (int j = 0; j <= n; ++j) {
        for (int i = 0; i + j <= n; ++i) {
          const SurfacePoint p{first, static_cast<double>(i) / n, static_cast<double>(j) / n};
          int* slot = nullptr;
          if (j == 0) {
            slot = edge_slot(f, 0, i);
          } else if (i + j == n) {
            slot = edge_slot(f, 1, j);
          } else if (i == 0) {
            slot = edge_slot(f, 2, n - j);
          }
          at(i, j) = make(slot, p);
        }
      }
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i + j < n; ++i) {
          add_triangle(at(i, j), at(i + 1, j), at(i, j + 1), first);
          if (i + j + 2 <= n) {
            add_triangle(at(i + 1, j), at(i + 1, j + 1), at(i, j + 1), first);
          }
        }
      }
      continue;
    }
    const bool split = k != 4;
    const int m = split ? half : n;
    auto at = [&](int i, int j) -> int& {
      return grid[static_cast<size_t>(j) * static_cast<size_t>(m + 1) + static_cast<size_t>(i)];
    };
    for (int sub = 0; sub < (split ? k : 1); ++sub) {
      const int ptex = first + sub;
      grid.assign(static_cast<size_t>(m + 1) * static_cast<size_t>(m + 1), -1);
      for (int j = 0; j <= m; ++j) {
        for (int i = 0; i <= m; ++i) {
          const SurfacePoint p{ptex, static_cast<double>(i) / m, static_cast<double>(j) / m};
          int* slot = nullptr;
          if (!split) {
            // Quad: edges 0..3 are control edges 0..3 at parameters u, v, 1-u, 1-v.
            if (j == 0) {
              slot = edge_slot(f, 0, i);
            } else if (i == m) {
              slot = edge_slot(f, 1, j);
            } else if (j == m) {
              slot = edge_slot(f, 2, m - i);
            } else if (i == 0) {
              slot = edge_slot(f, 3, m - j);
            }
          } else {
            // Sub-face `sub`: (0,0) corner vertex, edge 0 = first half of control edge `sub`, edge
            // 3 = second half of control edge sub-1, edge 1 = spoke `sub` (midpoint -> centre),
            // edge 2 = spoke sub-1 (centre <- midpoint), (1,1) = face centre.
            const int prev = (sub + k - 1) % k;
            if (i == m && j == m) {
              slot = &centre_ids[static_cast<size_t>(f)];
            } else if (j == 0) {
              slot = edge_slot(f, sub, i);
            } else if (i == 0) {
              slot = edge_slot(f, prev, n - j);
            } else if (i == m) {
              slot = &spoke_ids[static_cast<size_t>(spoke_offset[static_cast<size_t>(f)] + sub) *
                                    static_cast<size_t>(half - 1) +
                                static_cast<size_t>(j - 1)];
            } else if (j == m) {
              slot = &spoke_ids[static_cast<size_t>(spoke_offset[static_cast<size_t>(f)] + prev) *
                                    static_cast<size_t>(half - 1) +
                                static_cast<size_t>(i - 1)];
            }
          }
          at(i, j) = make(slot, p);
        }
      }
      for (int j = 0; j < m; ++j) {
        for (int i = 0; i < m; ++i) {
          add_triangle(at(i, j), at(i + 1, j), at(i + 1, j + 1), ptex);
          add_triangle(at(i, j), at(i + 1, j + 1), at(i, j + 1), ptex);
        }
      }
    }
  }

  out.positions.resize(out.points.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, out.points.size(), 1024),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t i = range.begin(); i != range.end(); ++i) {
                        out.positions[i] = surface.position(out.points[i]);
                      }
                    });
  return out;
}

}  // namespace elastic
