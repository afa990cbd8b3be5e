// Wavefront OBJ: reading (v, vt, vn, f, mtllib, usemtl, OpenSubdiv `t` tags, `v x y z r g b`
// colours) and writing.

#include <cmath>
#include <limits>
#include <set>
#include <unordered_map>

#include "elastic/mesh/detail/io_common.h"

namespace elastic::detail {

namespace {

/// The largest 0-based index a pool was referenced with, and the line, so that a forward reference
/// (legal in practice) is accepted and an out-of-range one is reported where it was made.
struct MaxReference {
  long long index = -1;
  int line = 0;
  void note(long long i, int at) {
    if (i > index) {
      index = i;
      line = at;
    }
  }
};

struct ObjTag {
  std::string_view name;
  std::vector<long long> ints;
  std::vector<double> floats;
};

/// `t name nint/nfloat/nstring int... float... string...` (OpenSubdiv's regression-shape syntax).
ObjTag parse_tag(std::string_view rest, const LineScanner& scanner) {
  ObjTag tag;
  tag.name = next_token(rest);
  const std::string_view counts = next_token(rest);
  long long n[3] = {0, 0, 0};
  std::string_view c = counts;
  for (int k = 0; k < 3; ++k) {
    const size_t slash = c.find('/');
    const std::string_view part = c.substr(0, slash);
    if (!parse_int(part, n[k]) || n[k] < 0) {
      scanner.fail("cannot parse tag argument counts '" + std::string(counts) + "'");
    }
    if (slash == std::string_view::npos) {
      break;
    }
    c.remove_prefix(slash + 1);
  }
  for (long long i = 0; i < n[0]; ++i) {
    tag.ints.push_back(expect_int(rest, scanner, "tag integer"));
  }
  for (long long i = 0; i < n[1]; ++i) {
    tag.floats.push_back(expect_double(rest, scanner, "tag value"));
    if (!std::isfinite(tag.floats.back())) {
      scanner.fail("tag value is NaN or infinite");
    }
  }
  return tag;
}

/// Reads an OBJ file line by line into a mesh: one handler per keyword, then the checks and
/// clean-ups that need the whole file (references, per-corner attributes, colours, warnings).
class ObjReader {
 public:
  ObjReader(const std::string& text, const std::filesystem::path& path,
            const MeshReadOptions& options)
      : scanner_(text, path), path_(path), options_(options), mesh_(result_.mesh) {
    mesh_.face_offsets.push_back(0);
  }

  MeshReadResult read() {
    std::string_view line;
    while (scanner_.next(line)) {
      std::string_view rest = line;
      const std::string_view keyword = next_token(rest);
      if (keyword.empty() || keyword.front() == '#') {
        continue;
      }
      if (keyword == "v") {
        read_vertex(rest);
      } else if (keyword == "vt") {
        read_texcoord(rest);
      } else if (keyword == "vn") {
        read_normal(rest);
      } else if (keyword == "f") {
        read_face(rest);
      } else if (keyword == "mtllib") {
        if (options_.load_materials) {
          read_mtllib(rest);
        }
      } else if (keyword == "usemtl") {
        read_usemtl(rest);
      } else if (keyword == "t") {
        read_tag(rest);
      } else if (keyword == "l" || keyword == "p") {
        ++skipped_elements_;
      }
      // Everything else (o, g, s, vp, curv, surf, bsdf, ...) carries nothing the library uses.
    }
    check_references();
    finish();
    return std::move(result_);
  }

 private:
  void add_material(const Material& material) {
    material_index_.try_emplace(material.name, static_cast<int>(mesh_.materials.size()));
    mesh_.materials.push_back(material);
  }

  // A corner index: 1-based, or negative = relative to the end of the pool read so far.
  int resolve(std::string_view token, size_t count, MaxReference& max_ref, const char* what) {
    long long i = 0;
    if (!parse_int(token, i)) {
      scanner_.fail(std::string("cannot parse ") + what + " index '" + std::string(token) + "'");
    }
    if (i == 0) {
      scanner_.fail(std::string(what) + " index 0 (OBJ indices start at 1)");
    }
    const long long zero_based = i > 0 ? i - 1 : static_cast<long long>(count) + i;
    if (zero_based < 0) {
      scanner_.fail(std::string(what) + " index " + std::to_string(i) + " out of range (" +
                    std::to_string(count) + " defined so far)");
    }
    if (zero_based > 2147483646LL) {
      scanner_.fail(std::string(what) + " index too large");
    }
    max_ref.note(zero_based, scanner_.line_number());
    return static_cast<int>(zero_based);
  }

  void read_vertex(std::string_view rest);
  void read_texcoord(std::string_view rest);
  void read_normal(std::string_view rest);
  void read_face(std::string_view rest);
  void read_mtllib(std::string_view rest);
  void read_usemtl(std::string_view rest);
  void read_tag(std::string_view rest);
  void check_references() const;
  template <class Pool, class Value>
  void finish_corners(std::vector<int>& corners, bool missing, Pool& pool, const Value& neutral,
                      std::vector<int>& out, const char* what);
  void finish();

  MeshReadResult result_;
  LineScanner scanner_;
  const std::filesystem::path& path_;
  const MeshReadOptions& options_;
  PolygonMesh& mesh_;
  std::vector<int> corner_uv_;
  std::vector<int> corner_normal_;
  bool corners_without_uv_ = false;
  bool corners_without_normal_ = false;
  std::vector<Eigen::Vector3f> colors_;
  size_t colored_vertices_ = 0;
  std::vector<int> face_materials_;
  bool any_usemtl_ = false;
  int current_material_ = -1;
  std::unordered_map<std::string, int> material_index_;
  MaxReference max_v_, max_vt_, max_vn_, max_tag_;
  long long skipped_elements_ = 0;
  std::set<std::string, std::less<>> ignored_tags_;
};

// `v x y z`, optionally w (1 number) or a colour r g b (3 numbers, the common extension).
void ObjReader::read_vertex(std::string_view rest) {
  Eigen::Vector3d p;
  for (int k = 0; k < 3; ++k) {
    p[k] = expect_double(rest, scanner_, "vertex coordinate");
  }
  if (!p.allFinite()) {
    scanner_.fail("vertex has a NaN or infinite coordinate");
  }
  mesh_.positions.push_back(p);
  double extra[4];
  int n_extra = 0;
  for (std::string_view t = next_token(rest); !t.empty() && n_extra < 4; t = next_token(rest)) {
    if (!parse_double(t, extra[n_extra])) {
      scanner_.fail("cannot parse vertex value '" + std::string(t) + "'");
    }
    ++n_extra;
  }
  if (n_extra >= 3) {
    for (int k = 0; k < 3; ++k) {
      // Colours are stored as float: finite there, or the file is refused.
      if (!(std::fabs(extra[k]) <= static_cast<double>(std::numeric_limits<float>::max()))) {
        scanner_.fail("vertex colour is NaN, infinite or beyond float range");
      }
    }
    colors_.resize(mesh_.positions.size(), Eigen::Vector3f::Ones());
    colors_.back() = Eigen::Vector3f(static_cast<float>(extra[0]), static_cast<float>(extra[1]),
                                     static_cast<float>(extra[2]));
    ++colored_vertices_;
  }
}

// `vt u [v]`.
void ObjReader::read_texcoord(std::string_view rest) {
  Eigen::Vector2d uv;
  uv[0] = expect_double(rest, scanner_, "texture coordinate");
  const std::string_view t = next_token(rest);
  uv[1] = 0.0;
  if (!t.empty() && !parse_double(t, uv[1])) {
    scanner_.fail("cannot parse texture coordinate '" + std::string(t) + "'");
  }
  if (!uv.allFinite()) {
    scanner_.fail("texture coordinate is NaN or infinite");
  }
  mesh_.texcoords.push_back(uv);
}

// `vn x y z`.
void ObjReader::read_normal(std::string_view rest) {
  Eigen::Vector3d n;
  for (int k = 0; k < 3; ++k) {
    n[k] = expect_double(rest, scanner_, "normal coordinate");
  }
  if (!n.allFinite()) {
    scanner_.fail("normal is NaN or infinite");
  }
  mesh_.normals.push_back(n);
}

// `f v[/vt[/vn]] ...`: at least three corners, each with its optional texture coordinate and
// normal.
void ObjReader::read_face(std::string_view rest) {
  int corners = 0;
  for (std::string_view corner = next_token(rest); !corner.empty(); corner = next_token(rest)) {
    const size_t s1 = corner.find('/');
    const std::string_view vtok = corner.substr(0, s1);
    mesh_.face_vertices.push_back(resolve(vtok, mesh_.positions.size(), max_v_, "vertex"));
    int uv = -1;
    int normal = -1;
    if (s1 != std::string_view::npos) {
      std::string_view tail = corner.substr(s1 + 1);
      const size_t s2 = tail.find('/');
      const std::string_view uvtok = tail.substr(0, s2);
      if (!uvtok.empty()) {
        uv = resolve(uvtok, mesh_.texcoords.size(), max_vt_, "texture");
      }
      if (s2 != std::string_view::npos) {
        const std::string_view ntok = tail.substr(s2 + 1);
        if (!ntok.empty()) {
          normal = resolve(ntok, mesh_.normals.size(), max_vn_, "normal");
        }
      }
    }
    corners_without_uv_ = corners_without_uv_ || uv < 0;
    corners_without_normal_ = corners_without_normal_ || normal < 0;
    corner_uv_.push_back(uv);
    corner_normal_.push_back(normal);
    ++corners;
  }
  if (corners < 3) {
    scanner_.fail("face with " + std::to_string(corners) + " corners (at least 3)");
  }
  mesh_.face_offsets.push_back(static_cast<int>(mesh_.face_vertices.size()));
  face_materials_.push_back(current_material_);
}

// `mtllib file...`: a name with spaces is written as is; several names are separated by spaces.
void ObjReader::read_mtllib(std::string_view rest) {
  const std::string_view names = trim(rest);
  std::vector<std::string> files;
  if (std::filesystem::exists(path_.parent_path() / std::string(names))) {
    files.emplace_back(names);
  } else {
    std::string_view list = names;
    for (std::string_view t = next_token(list); !t.empty(); t = next_token(list)) {
      files.emplace_back(t);
    }
  }
  for (const std::string& file : files) {
    std::vector<Material> materials;
    const std::filesystem::path mtl = path_.parent_path() / file;
    if (!read_mtl(mtl, materials)) {
      result_.warnings.push_back(path_.string() + ": line " +
                                 std::to_string(scanner_.line_number()) + ": material library " +
                                 mtl.string() + " not found; materials ignored");
      continue;
    }
    for (const Material& m : materials) {
      add_material(m);
    }
  }
}

// `usemtl name`.
void ObjReader::read_usemtl(std::string_view rest) {
  const std::string name(trim(rest));
  any_usemtl_ = true;
  const auto it = material_index_.find(name);
  if (it != material_index_.end()) {
    current_material_ = it->second;
  } else {
    // Unknown (library missing or not loaded): keep the grouping under a default material.
    current_material_ = static_cast<int>(mesh_.materials.size());
    Material placeholder;
    placeholder.name = name;
    add_material(placeholder);
  }
}

// `t crease|corner ...` (OpenSubdiv's tags); other tags are noted and ignored.
void ObjReader::read_tag(std::string_view rest) {
  const ObjTag tag = parse_tag(rest, scanner_);
  auto sharpness = [&](size_t k) {
    if (tag.floats.empty()) {
      scanner_.fail("tag '" + std::string(tag.name) + "' without a value");
    }
    return tag.floats.size() > 1 && k < tag.floats.size() ? tag.floats[k] : tag.floats[0];
  };
  if (tag.name == "crease") {
    // Vertex pairs (0-based, as OpenSubdiv writes them); one sharpness, or one per edge.
    for (size_t j = 0; j + 1 < tag.ints.size(); j += 2) {
      for (size_t k = j; k < j + 2; ++k) {
        if (tag.ints[k] < 0) {
          scanner_.fail("negative vertex index in crease tag");
        }
        max_tag_.note(tag.ints[k], scanner_.line_number());
      }
      mesh_.creases.push_back(
          {static_cast<int>(tag.ints[j]), static_cast<int>(tag.ints[j + 1]), sharpness(j / 2)});
    }
  } else if (tag.name == "corner") {
    for (size_t j = 0; j < tag.ints.size(); ++j) {
      if (tag.ints[j] < 0) {
        scanner_.fail("negative vertex index in corner tag");
      }
      max_tag_.note(tag.ints[j], scanner_.line_number());
      mesh_.corners.emplace_back(static_cast<int>(tag.ints[j]), sharpness(j));
    }
  } else {
    ignored_tags_.emplace(tag.name);
  }
}

// Indices may refer forward (a face before its vertices): checked once the pools are complete.
void ObjReader::check_references() const {
  auto check_max = [&](const MaxReference& ref, size_t count, const char* what) {
    if (ref.index >= static_cast<long long>(count)) {
      throw InvalidInputError(path_.string(), "line " + std::to_string(ref.line) + ": " + what +
                                                  " index " + std::to_string(ref.index + 1) +
                                                  " out of range (" + std::to_string(count) +
                                                  " defined)");
    }
  };
  check_max(max_v_, mesh_.positions.size(), "vertex");
  check_max(max_vt_, mesh_.texcoords.size(), "texture coordinate");
  check_max(max_vn_, mesh_.normals.size(), "normal");
  if (max_tag_.index >= static_cast<long long>(mesh_.positions.size())) {
    throw InvalidInputError(path_.string(), "line " + std::to_string(max_tag_.line) +
                                                ": tag vertex " + std::to_string(max_tag_.index) +
                                                " out of range (" +
                                                std::to_string(mesh_.positions.size()) +
                                                " vertices, tags count from 0)");
  }
}

// Per-corner attributes are all-or-nothing in PolygonMesh: corners the file left without one
// point at an added neutral entry.
template <class Pool, class Value>
void ObjReader::finish_corners(std::vector<int>& corners, bool missing, Pool& pool,
                               const Value& neutral, std::vector<int>& out, const char* what) {
  bool any = false;
  for (int i : corners) {
    any = any || i >= 0;
  }
  if (!any) {
    pool.clear();
    return;
  }
  if (missing) {
    const int fill = static_cast<int>(pool.size());
    pool.push_back(neutral);
    for (int& i : corners) {
      if (i < 0) {
        i = fill;
      }
    }
    result_.warnings.push_back(path_.string() + ": some face corners have no " + what +
                               "; they were given a default one");
  }
  out = std::move(corners);
}

void ObjReader::finish() {
  if (mesh_.face_offsets.size() == 1) {
    mesh_.face_offsets.clear();
  }
  finish_corners(corner_uv_, corners_without_uv_, mesh_.texcoords, Eigen::Vector2d::Zero().eval(),
                 mesh_.corner_texcoords, "texture coordinate");
  finish_corners(corner_normal_, corners_without_normal_, mesh_.normals,
                 Eigen::Vector3d::Zero().eval(), mesh_.corner_normals, "normal");
  // A file without any `f` line leaves the pools as read; an unused pool is harmless.

  if (colored_vertices_ == mesh_.positions.size() && colored_vertices_ > 0) {
    mesh_.vertex_colors = std::move(colors_);
  } else if (colored_vertices_ > 0) {
    result_.warnings.push_back(path_.string() + ": only " + std::to_string(colored_vertices_) +
                               " of " + std::to_string(mesh_.positions.size()) +
                               " vertices have a colour; colours ignored");
  }
  if (any_usemtl_) {
    mesh_.face_materials = std::move(face_materials_);
  }
  if (skipped_elements_ > 0) {
    result_.warnings.push_back(path_.string() + ": skipped " + std::to_string(skipped_elements_) +
                               " line/point elements (l, p)");
  }
  for (const std::string& tag : ignored_tags_) {
    result_.warnings.push_back(path_.string() + ": ignored tag 't " + tag + "'");
  }
}

}  // namespace

MeshReadResult read_obj(const std::string& text, const std::filesystem::path& path,
                        const MeshReadOptions& options) {
  return ObjReader(text, path, options).read();
}

std::string write_obj(const PolygonMesh& mesh, const MeshWriteOptions& options,
                      const std::string& mtl_file_name) {
  std::string out;
  out.reserve(mesh.positions.size() * 60 + mesh.face_vertices.size() * 16 + 64);
  out += "# written by libelastic\n";
  if (!mtl_file_name.empty()) {
    out += "mtllib " + mtl_file_name + "\n";
  }
  const bool colors = options.vertex_colors && mesh.has_vertex_colors();
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const Eigen::Vector3d& p = mesh.positions[v];
    out += 'v';
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      append_number(out, p[k]);
    }
    if (colors) {
      for (int k = 0; k < 3; ++k) {
        out += ' ';
        append_number(out, static_cast<double>(mesh.vertex_colors[v][k]));
      }
    }
    out += '\n';
  }
  const bool uv = options.texcoords && mesh.has_texcoords();
  const bool normals = options.normals && mesh.has_normals();
  if (uv) {
    for (const Eigen::Vector2d& t : mesh.texcoords) {
      out += "vt ";
      append_number(out, t[0]);
      out += ' ';
      append_number(out, t[1]);
      out += '\n';
    }
  }
  if (normals) {
    for (const Eigen::Vector3d& n : mesh.normals) {
      out += "vn";
      for (int k = 0; k < 3; ++k) {
        out += ' ';
        append_number(out, n[k]);
      }
      out += '\n';
    }
  }
  // With a material library, every face is written under a `usemtl`: OBJ has no "no material"
  // statement, and readers put faces before the first `usemtl` on a material of their own choice
  // (often the library's first). Faces without a material are written under "default", which
  // write_mtl defines (default_material()) unless the mesh has a material of that name.
  const bool materials = !mesh.materials.empty();
  int current_material = -2;  // no `usemtl` written yet
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const int material =
        mesh.face_materials.empty() ? -1 : mesh.face_materials[static_cast<size_t>(f)];
    if (materials && material != current_material) {
      current_material = material;
      out += "usemtl ";
      out += current_material >= 0 ? mesh.materials[static_cast<size_t>(current_material)].name
                                   : std::string("default");
      out += '\n';
    }
    out += 'f';
    for (int c = mesh.face_offsets[static_cast<size_t>(f)];
         c < mesh.face_offsets[static_cast<size_t>(f) + 1]; ++c) {
      out += ' ';
      append_number(out, mesh.face_vertices[static_cast<size_t>(c)] + 1);
      if (uv || normals) {
        out += '/';
        if (uv) {
          append_number(out, mesh.corner_texcoords[static_cast<size_t>(c)] + 1);
        }
        if (normals) {
          out += '/';
          append_number(out, mesh.corner_normals[static_cast<size_t>(c)] + 1);
        }
      }
    }
    out += '\n';
  }
  // OpenSubdiv tags: vertex indices count from 0.
  for (const Crease& c : mesh.creases) {
    out += "t crease 2/1/0 ";
    append_number(out, c.v0);
    out += ' ';
    append_number(out, c.v1);
    out += ' ';
    append_number(out, c.sharpness);
    out += '\n';
  }
  for (const auto& [v, sharpness] : mesh.corners) {
    out += "t corner 1/1/0 ";
    append_number(out, v);
    out += ' ';
    append_number(out, sharpness);
    out += '\n';
  }
  return out;
}

}  // namespace elastic::detail
