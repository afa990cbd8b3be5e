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

/// The resolution N actually used: options.resolution, or the one nearest to
/// options.target_triangles; even when there are n-gon sub-faces (so that they get N/2 segments).
int tessellation_resolution(const LimitSurface& surface, const TessellationOptions& options) {
  const PolygonMesh& mesh = surface.control_mesh();
  const bool loop = surface.triangular_domain();
  // Catmull-Clark ptex faces come in two sizes: a quad's covers a whole control face, an n-gon's
  // sub-face a quarter-like piece whose edges are half control edges. Sampling every control edge
  // with N segments (N even when there are n-gons) makes both sides of every edge agree.
  long quads = 0, subfaces = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    if (loop || mesh.face_size(f) == 4) {
      ++quads;
    } else {
      subfaces += mesh.face_size(f);
    }
  }
  const bool need_even = !loop && subfaces > 0;
  int n = options.resolution;
  if (options.target_triangles < 0 || options.max_triangles < 0) {
    throw InvalidInputError(surface.name(),
                            "tessellation target_triangles " +
                                std::to_string(options.target_triangles) + " or max_triangles " +
                                std::to_string(options.max_triangles) + " is negative");
  }
  // Triangles per N^2: 1 per Loop triangle, 2 per quad, 1/2 per n-gon sub-face (N/2 segments).
  const double per_n2 =
      loop ? static_cast<double>(quads)
           : 2.0 * static_cast<double>(quads) + 0.5 * static_cast<double>(subfaces);
  if (options.target_triangles > 0) {
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
  if (options.target_triangles == 0 && options.max_triangles > 0) {
    const int step = need_even ? 2 : 1;
    while (n > step && per_n2 * static_cast<double>(n) * static_cast<double>(n) >
                           static_cast<double>(options.max_triangles)) {
      n -= step;
    }
  }
  return n;
}

namespace {

/// Builds the tessellation face by face. Samples on control vertices, control edges, n-gon spokes
/// and n-gon centres are made once and shared by the faces that meet there (their slots hold the
/// sample's index, -1 before it is made).
class Tessellator {
 public:
  Tessellator(const LimitSurface& surface, int n)
      : surface_(surface),
        mesh_(surface.control_mesh()),
        n_(n),
        half_(n / 2),
        edges_(mesh_),
        vertex_ids_(static_cast<size_t>(mesh_.num_vertices()), -1),
        edge_ids_(static_cast<size_t>(edges_.size()) * static_cast<size_t>(n - 1), -1),
        centre_ids_(static_cast<size_t>(mesh_.num_faces()), -1),
        spoke_offset_(static_cast<size_t>(mesh_.num_faces()) + 1, 0) {
    out_.resolution = n;
    // Spokes of n-gons (sub-face i's edge 1, from the midpoint of control edge i to the centre),
    // N/2 - 1 interior samples each; spoke_offset_[f] is the first spoke of face f.
    const bool loop = surface.triangular_domain();
    for (int f = 0; f < mesh_.num_faces(); ++f) {
      const bool split = !loop && mesh_.face_size(f) != 4;
      spoke_offset_[static_cast<size_t>(f) + 1] =
          spoke_offset_[static_cast<size_t>(f)] + (split ? mesh_.face_size(f) : 0);
    }
    spoke_ids_.assign(
        static_cast<size_t>(spoke_offset_.back()) * static_cast<size_t>(std::max(half_ - 1, 0)),
        -1);
  }

  LimitTessellation run() {
    for (int f = 0; f < mesh_.num_faces(); ++f) {
      if (surface_.triangular_domain()) {
        triangle_face(f);
      } else {
        quad_face(f);
      }
    }
    out_.positions.resize(out_.points.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, out_.points.size(), 1024),
                      [&](const tbb::blocked_range<size_t>& range) {
                        for (size_t i = range.begin(); i != range.end(); ++i) {
                          out_.positions[i] = surface_.position(out_.points[i]);
                        }
                      });
    return std::move(out_);
  }

 private:
  int make(int* slot, const SurfacePoint& p) {
    if (slot && *slot >= 0) {
      return *slot;
    }
    const int id = static_cast<int>(out_.points.size());
    out_.points.push_back(p);
    if (slot) {
      *slot = id;
    }
    return id;
  }

  // Sample s of N along control edge e of face f (from corner e towards corner e+1).
  int* edge_slot(int f, int e, int s) {
    const auto fv = mesh_.face(f);
    const size_t k = fv.size();
    const int a = fv[static_cast<size_t>(e) % k], b = fv[(static_cast<size_t>(e) + 1) % k];
    if (s == 0) {
      return &vertex_ids_[static_cast<size_t>(a)];
    }
    if (s == n_) {
      return &vertex_ids_[static_cast<size_t>(b)];
    }
    const int canonical = a < b ? s : n_ - s;
    return &edge_ids_[static_cast<size_t>(edges_.id(a, b)) * static_cast<size_t>(n_ - 1) +
                      static_cast<size_t>(canonical - 1)];
  }

  // Sample `index` (1 .. N/2 - 1) inside spoke `spoke` of n-gon f.
  int* spoke_slot(int f, int spoke, int index) {
    return &spoke_ids_[static_cast<size_t>(spoke_offset_[static_cast<size_t>(f)] + spoke) *
                           static_cast<size_t>(half_ - 1) +
                       static_cast<size_t>(index - 1)];
  }

  void add_triangle(int a, int b, int c, int face) {
    out_.triangles.emplace_back(a, b, c);
    out_.triangle_face.push_back(face);
  }

  int& at(int i, int j, int m) {
    return grid_[static_cast<size_t>(j) * static_cast<size_t>(m + 1) + static_cast<size_t>(i)];
  }

  // Loop: a triangle grid, (i, j) with i + j <= N at (u, v) = (i, j) / N.
  void triangle_face(int f) {
    const int n = n_;
    const int first = surface_.first_ptex_face(f);
    grid_.assign(static_cast<size_t>(n + 1) * static_cast<size_t>(n + 1), -1);
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
        at(i, j, n) = make(slot, p);
      }
    }
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i + j < n; ++i) {
        add_triangle(at(i, j, n), at(i + 1, j, n), at(i, j + 1, n), first);
        if (i + j + 2 <= n) {
          add_triangle(at(i + 1, j, n), at(i + 1, j + 1, n), at(i, j + 1, n), first);
        }
      }
    }
  }

  // The shared slot of grid sample (i, j) of an m x m quad grid: of control face f itself (a
  // quad), or of its sub-face `sub` (an n-gon of k corners); null inside.
  int* quad_slot(int f, int k, int sub, int i, int j, int m) {
    if (k == 4) {
      // Quad: edges 0..3 are control edges 0..3 at parameters u, v, 1-u, 1-v.
      if (j == 0) {
        return edge_slot(f, 0, i);
      }
      if (i == m) {
        return edge_slot(f, 1, j);
      }
      if (j == m) {
        return edge_slot(f, 2, m - i);
      }
      if (i == 0) {
        return edge_slot(f, 3, m - j);
      }
      return nullptr;
    }
    // Sub-face `sub`: (0,0) corner vertex, edge 0 = first half of control edge `sub`, edge 3 =
    // second half of control edge sub-1, edge 1 = spoke `sub` (midpoint -> centre), edge 2 = spoke
    // sub-1 (centre <- midpoint), (1,1) = face centre.
    const int prev = (sub + k - 1) % k;
    if (i == m && j == m) {
      return &centre_ids_[static_cast<size_t>(f)];
    }
    if (j == 0) {
      return edge_slot(f, sub, i);
    }
    if (i == 0) {
      return edge_slot(f, prev, n_ - j);
    }
    if (i == m) {
      return spoke_slot(f, sub, j);
    }
    if (j == m) {
      return spoke_slot(f, prev, i);
    }
    return nullptr;
  }

  // Catmull-Clark: an N x N grid on a quad, an N/2 x N/2 grid on each sub-face of an n-gon.
  void quad_face(int f) {
    const int k = mesh_.face_size(f);
    const int first = surface_.first_ptex_face(f);
    const bool split = k != 4;
    const int m = split ? half_ : n_;
    for (int sub = 0; sub < (split ? k : 1); ++sub) {
      const int ptex = first + sub;
      grid_.assign(static_cast<size_t>(m + 1) * static_cast<size_t>(m + 1), -1);
      for (int j = 0; j <= m; ++j) {
        for (int i = 0; i <= m; ++i) {
          const SurfacePoint p{ptex, static_cast<double>(i) / m, static_cast<double>(j) / m};
          at(i, j, m) = make(quad_slot(f, k, sub, i, j, m), p);
        }
      }
      for (int j = 0; j < m; ++j) {
        for (int i = 0; i < m; ++i) {
          add_triangle(at(i, j, m), at(i + 1, j, m), at(i + 1, j + 1, m), ptex);
          add_triangle(at(i, j, m), at(i + 1, j + 1, m), at(i, j + 1, m), ptex);
        }
      }
    }
  }

  const LimitSurface& surface_;
  const PolygonMesh& mesh_;
  int n_;
  int half_;
  EdgeIndex edges_;
  std::vector<int> vertex_ids_;
  std::vector<int> edge_ids_;
  std::vector<int> centre_ids_;
  std::vector<int64_t> spoke_offset_;
  std::vector<int> spoke_ids_;
  std::vector<int> grid_;
  LimitTessellation out_;
};

}  // namespace

LimitTessellation tessellate(const LimitSurface& surface, const TessellationOptions& options) {
  return Tessellator(surface, tessellation_resolution(surface, options)).run();
}

}  // namespace elastic
