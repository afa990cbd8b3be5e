// Round trips through every format (write, read back, compare bit for bit: the writers print the
// shortest text that reads back exactly), small hand-written files for each feature of the readers,
// and every error case as a tiny file.

#include "elastic/mesh/mesh_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <random>

#include "elastic/core/error.h"
#include "elastic/mesh/default_material.h"
#include "support.h"

namespace elastic {
namespace {

namespace fs = std::filesystem;

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string bytes(static_cast<size_t>(fs::file_size(path)), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return bytes;
}

/// A closed mesh of triangles and quads with random coordinates that use all 53 mantissa bits, and
/// per-corner attributes with seams, colours, two materials, a crease and a corner.
PolygonMesh awkward_mesh(bool float_exact = false) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1e3, 1e3);
  auto value = [&] {
    const double x = u(rng) * 1e-3 * std::pow(10.0, static_cast<double>(rng() % 7) - 3.0);
    return float_exact ? static_cast<double>(static_cast<float>(x)) : x;
  };
  PolygonMesh m;
  // A triangular prism: two triangles and three quads.
  for (int i = 0; i < 6; ++i) m.positions.emplace_back(value(), value(), value());
  m.add_face({0, 2, 1});
  m.add_face({3, 4, 5});
  m.add_face({0, 1, 4, 3});
  m.add_face({1, 2, 5, 4});
  m.add_face({2, 0, 3, 5});
  for (size_t c = 0; c < m.face_vertices.size(); ++c) {
    m.texcoords.emplace_back(value(), value());
    m.corner_texcoords.push_back(static_cast<int>(c));
  }
  for (size_t c = 0; c < m.face_vertices.size(); ++c) {
    m.normals.emplace_back(value(), value(), value());
    m.corner_normals.push_back(static_cast<int>(m.face_vertices.size() - 1 - c));
  }
  // Colours on the 8-bit grid, so that formats storing bytes give them back exactly.
  for (int i = 0; i < 6; ++i) {
    m.vertex_colors.emplace_back(static_cast<float>(i * 40) / 255.0f,
                                 static_cast<float>(255 - i) / 255.0f, 0.0f);
  }
  m.materials.push_back({"red", {1.0, 0.0, 0.0}, {}});
  m.materials.push_back({"textured", {0.25, 0.5, 0.75}, {}});
  m.face_materials = {0, 0, 1, 1, 0};
  m.creases.push_back({0, 1, 2.5});
  m.corners.emplace_back(5, 10.0);
  return m;
}

void expect_same_geometry(const PolygonMesh& a, const PolygonMesh& b) {
  ASSERT_EQ(a.num_vertices(), b.num_vertices());
  for (int v = 0; v < a.num_vertices(); ++v) {
    // Bit-exact: operator== on doubles, no tolerance.
    EXPECT_EQ(a.positions[static_cast<size_t>(v)], b.positions[static_cast<size_t>(v)])
        << "vertex " << v;
  }
  EXPECT_EQ(a.face_offsets, b.face_offsets);
  EXPECT_EQ(a.face_vertices, b.face_vertices);
}

/// The attribute value each corner sees (pools may be renumbered by a format, the values must not).
template <class T>
std::vector<T> corner_values(const std::vector<T>& pool, const std::vector<int>& corners) {
  std::vector<T> out;
  for (int i : corners) out.push_back(pool[static_cast<size_t>(i)]);
  return out;
}

TEST(MeshIo, FormatFromExtension) {
  EXPECT_EQ(format_from_extension("a/b.OBJ"), MeshFormat::Obj);
  EXPECT_EQ(format_from_extension("x.off"), MeshFormat::Off);
  EXPECT_EQ(format_from_extension("x.Ply"), MeshFormat::Ply);
  EXPECT_EQ(format_from_extension("x.stl"), MeshFormat::Stl);
  EXPECT_EQ(format_from_extension("x.mesh"), MeshFormat::Auto);
  EXPECT_EQ(format_from_extension("obj"), MeshFormat::Auto);
}

TEST(MeshIo, ObjRoundTripKeepsEverything) {
  const fs::path dir = test::scratch_dir("obj_round_trip");
  PolygonMesh m = awkward_mesh();
  const fs::path texture = dir / "textures" / "wood.png";
  fs::create_directories(texture.parent_path());
  write_text(texture, "not really a png");
  m.materials[1].diffuse_texture = texture;
  write_mesh(dir / "prism.obj", m);
  ASSERT_TRUE(fs::exists(dir / "prism.mtl"));
  EXPECT_NE(read_text(dir / "prism.mtl").find("map_Kd textures/wood.png"), std::string::npos);

  const MeshReadResult r = read_mesh(dir / "prism.obj");
  EXPECT_TRUE(r.warnings.empty());
  expect_same_geometry(m, r.mesh);
  EXPECT_EQ(r.mesh.texcoords, m.texcoords);
  EXPECT_EQ(r.mesh.corner_texcoords, m.corner_texcoords);
  EXPECT_EQ(r.mesh.normals, m.normals);
  EXPECT_EQ(r.mesh.corner_normals, m.corner_normals);
  // Colours are written as text of the float values: exact too.
  EXPECT_EQ(r.mesh.vertex_colors, m.vertex_colors);
  ASSERT_EQ(r.mesh.materials.size(), 2u);
  EXPECT_EQ(r.mesh.materials[0].name, "red");
  EXPECT_EQ(r.mesh.materials[1].diffuse, m.materials[1].diffuse);
  EXPECT_TRUE(fs::equivalent(r.mesh.materials[1].diffuse_texture, texture));
  EXPECT_EQ(r.mesh.face_materials, m.face_materials);
  ASSERT_EQ(r.mesh.creases.size(), 1u);
  EXPECT_EQ(r.mesh.creases[0].v0, 0);
  EXPECT_EQ(r.mesh.creases[0].v1, 1);
  EXPECT_EQ(r.mesh.creases[0].sharpness, 2.5);
  EXPECT_EQ(r.mesh.corners, m.corners);
}

TEST(MeshIo, ObjFacesWithoutAMaterialAreWrittenUnderTheDefinedDefault) {
  // Faces without a material, before and after faces with one: every face is under a `usemtl`
  // (a reader would otherwise pick a material of its own for the first ones), and the .mtl
  // defines "default" as default_material() says.
  const fs::path dir = test::scratch_dir("obj_default_material");
  PolygonMesh m = awkward_mesh();
  m.face_materials = {-1, 0, -1, 1, -1};
  write_mesh(dir / "p.obj", m);
  const std::string obj = read_text(dir / "p.obj");
  const size_t first_face = obj.find("\nf ");
  ASSERT_NE(first_face, std::string::npos);
  EXPECT_NE(obj.rfind("usemtl default\n", first_face), std::string::npos) << obj;
  const std::string mtl = read_text(dir / "p.mtl");
  EXPECT_NE(mtl.find("newmtl default\nKd 0.8 0.8 0.8\n"), std::string::npos) << mtl;
  const MeshReadResult r = read_mesh(dir / "p.obj");
  ASSERT_EQ(r.mesh.materials.size(), 3u);
  const Material& d = r.mesh.materials[static_cast<size_t>(r.mesh.face_materials[0])];
  EXPECT_EQ(d.name, default_material().name);
  EXPECT_EQ(d.diffuse, default_material().diffuse);
  EXPECT_TRUE(d.diffuse_texture.empty());
  EXPECT_EQ(r.mesh.face_materials[2], r.mesh.face_materials[0]);
  EXPECT_EQ(r.mesh.face_materials[1], 0);

  // assign_default_material does the same in memory, reusing a material named "default".
  PolygonMesh n = awkward_mesh();
  n.face_materials.clear();
  EXPECT_EQ(assign_default_material(n), n.num_faces());
  EXPECT_EQ(n.materials.back().name, "default");
  EXPECT_EQ(assign_default_material(n), 0);
  n.face_materials[0] = -1;
  const size_t count = n.materials.size();
  EXPECT_EQ(assign_default_material(n), 1);
  EXPECT_EQ(n.materials.size(), count);
}

TEST(MeshIo, ObjWithoutAttributesWhenAsked) {
  const fs::path dir = test::scratch_dir("obj_plain");
  MeshWriteOptions options;
  options.texcoords = false;
  options.normals = false;
  options.write_materials = false;
  write_mesh(dir / "p.obj", awkward_mesh(), options);
  EXPECT_FALSE(fs::exists(dir / "p.mtl"));
  const MeshReadResult r = read_mesh(dir / "p.obj");
  expect_same_geometry(awkward_mesh(), r.mesh);
  EXPECT_FALSE(r.mesh.has_texcoords());
  EXPECT_FALSE(r.mesh.has_normals());
}

TEST(MeshIo, OffRoundTrip) {
  const fs::path dir = test::scratch_dir("off_round_trip");
  const PolygonMesh m = awkward_mesh();
  write_mesh(dir / "p.off", m);
  const MeshReadResult r = read_mesh(dir / "p.off");
  expect_same_geometry(m, r.mesh);
  // COFF stores colours as bytes; the test colours are on the byte grid.
  EXPECT_EQ(r.mesh.vertex_colors, m.vertex_colors);
}

TEST(MeshIo, PlyRoundTripAsciiAndBinary) {
  for (const bool binary : {false, true}) {
    SCOPED_TRACE(binary ? "binary" : "ascii");
    const fs::path dir = test::scratch_dir(binary ? "ply_binary" : "ply_ascii");
    const PolygonMesh m = awkward_mesh();
    MeshWriteOptions options;
    options.binary = binary;
    write_mesh(dir / "p.ply", m, options);
    EXPECT_EQ(read_text(dir / "p.ply")
                  .find(binary ? "format binary_little_endian 1.0\n" : "format ascii 1.0\n"),
              4u);
    const MeshReadResult r = read_mesh(dir / "p.ply");
    expect_same_geometry(m, r.mesh);
    EXPECT_EQ(r.mesh.vertex_colors, m.vertex_colors);
    // UVs with seams go to a per-corner `texcoord` list; values per corner are kept exactly.
    EXPECT_EQ(corner_values(r.mesh.texcoords, r.mesh.corner_texcoords),
              corner_values(m.texcoords, m.corner_texcoords));
    // Per-corner normals that differ at a vertex have no per-vertex PLY form: not written.
    EXPECT_FALSE(r.mesh.has_normals());
  }
}

TEST(MeshIo, PlyFaceColoursRoundTrip) {
  // Per-face colours (a heatmap) survive PLY in both encodings; values on the byte grid are exact.
  const fs::path dir = test::scratch_dir("ply_face_colors");
  PolygonMesh m = awkward_mesh();
  for (int f = 0; f < m.num_faces(); ++f) {
    m.face_colors.emplace_back(static_cast<float>(f) / 255.0f, 1.0f,
                               static_cast<float>(3 * f) / 255.0f);
  }
  for (const bool binary : {false, true}) {
    SCOPED_TRACE(binary ? "binary" : "ascii");
    MeshWriteOptions options;
    options.binary = binary;
    write_mesh(dir / "p.ply", m, options);
    const MeshReadResult r = read_mesh(dir / "p.ply");
    expect_same_geometry(m, r.mesh);
    EXPECT_EQ(r.mesh.face_colors, m.face_colors);
  }
  // A colour array of the wrong size is refused by the writer, naming the problem.
  m.face_colors.pop_back();
  EXPECT_THROW(write_mesh(dir / "q.ply", m), InvalidInputError);
}

TEST(MeshIo, PlyPerVertexAttributes) {
  const fs::path dir = test::scratch_dir("ply_per_vertex");
  PolygonMesh m = awkward_mesh();
  m.texcoords.clear();
  m.normals.clear();
  for (int v = 0; v < m.num_vertices(); ++v) {
    m.texcoords.emplace_back(0.125 * v, 1.0 / (v + 3));
    m.normals.emplace_back(v, -v, 1.0 / 3.0);
  }
  m.corner_texcoords = m.face_vertices;
  m.corner_normals = m.face_vertices;
  for (const bool binary : {false, true}) {
    MeshWriteOptions options;
    options.binary = binary;
    write_mesh(dir / "p.ply", m, options);
    const MeshReadResult r = read_mesh(dir / "p.ply");
    expect_same_geometry(m, r.mesh);
    EXPECT_EQ(r.mesh.texcoords, m.texcoords);
    EXPECT_EQ(r.mesh.corner_texcoords, m.corner_texcoords);
    EXPECT_EQ(r.mesh.normals, m.normals);
    EXPECT_EQ(r.mesh.corner_normals, m.corner_normals);
  }
}

/// The corner positions of the fan triangulation of every face, in order: what an STL file holds.
std::vector<Eigen::Vector3d> fan_corner_positions(const PolygonMesh& m) {
  std::vector<Eigen::Vector3d> out;
  for (int f = 0; f < m.num_faces(); ++f) {
    const auto face = m.face(f);
    for (size_t k = 1; k + 1 < face.size(); ++k) {
      for (int v : {face[0], face[k], face[k + 1]})
        out.push_back(m.positions[static_cast<size_t>(v)]);
    }
  }
  return out;
}

TEST(MeshIo, StlRoundTripAsciiAndBinary) {
  for (const bool binary : {false, true}) {
    SCOPED_TRACE(binary ? "binary" : "ascii");
    const fs::path dir = test::scratch_dir(binary ? "stl_binary" : "stl_ascii");
    // ASCII keeps doubles exactly; binary STL stores floats, exact for float-representable values.
    const PolygonMesh m = awkward_mesh(binary);
    MeshWriteOptions options;
    options.binary = binary;
    write_mesh(dir / "p.stl", m, options);
    if (binary) {
      EXPECT_EQ(fs::file_size(dir / "p.stl"), 84u + 50u * 8u);
    }
    const MeshReadResult r = read_mesh(dir / "p.stl");
    EXPECT_TRUE(r.mesh.is_triangle_mesh());
    EXPECT_EQ(r.mesh.num_faces(), 8);     // 2 triangles + 3 quads split in two
    EXPECT_EQ(r.mesh.num_vertices(), 6);  // welded back (numbered in order of first use)
    EXPECT_EQ(fan_corner_positions(r.mesh), fan_corner_positions(m));
  }
}

TEST(MeshIo, StlWeldsOnlyIdenticalPoints) {
  const fs::path dir = test::scratch_dir("stl_weld");
  // Two triangles sharing an edge, one corner also given as -0 (equal to 0: welded) and one point
  // differing in the last bit (not welded).
  const double close = std::nextafter(1.0, 2.0);
  const std::string text =
      "solid t\n"
      "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
      "endloop\nendfacet\n"
      "facet normal 0 0 1\nouter loop\nvertex 1 0 -0\nvertex 1 1 0\nvertex 0 1 0\n"
      "endloop\nendfacet\n"
      "facet normal 0 0 1\nouter loop\nvertex 1 0 0\nvertex 1.0000000000000002 1 0\n"
      "vertex 1 1 0\nendloop\nendfacet\nendsolid t\n";
  ASSERT_EQ(close, 1.0000000000000002);
  write_text(dir / "w.stl", text);
  const MeshReadResult r = read_mesh(dir / "w.stl");
  EXPECT_EQ(r.mesh.num_vertices(), 5);
  EXPECT_EQ(r.mesh.num_faces(), 3);
}

TEST(MeshIo, ObjFeatures) {
  const fs::path dir = test::scratch_dir("obj_features");
  // Tabs, runs of spaces, CRLF, comments, unknown statements, negative indices, an n-gon, all four
  // corner syntaxes, vertex colours, a missing material library, `t corner` tags.
  const std::string text =
      "# comment\r\nmtllib missing.mtl\r\no thing\r\ng group\r\ns 1\r\n"
      "v 0 0 0 1 0 0\r\nv\t1  0 0 0 1 0\r\nv 1 1 0 0 0 1\r\nv 0 1 0 1 1 1\r\nv 0.5 1.5 0 0.5 0.5 "
      "0.5\r\n"
      "vt 0 0\r\nvt 1 0\r\nvt 1 1\r\nvn 0 0 1\r\n"
      "usemtl skin\r\n"
      "f 1/1/1 2/2/1 3/3/1\r\n"
      "f -5//-1 -3//-1 -2//-1\r\n"
      "f 4/1 3/2 5/3\r\n"
      "f 1 3 4\r\n"
      "f 1 2 3 5 4\r\n"
      "l 1 2\r\n"
      "t corner 2/1/0 0 4 7.5\r\n"
      "bsdf pbr\r\n";
  write_text(dir / "f.obj", text);
  const MeshReadResult r = read_mesh(dir / "f.obj");
  const PolygonMesh& m = r.mesh;
  EXPECT_EQ(m.num_vertices(), 5);
  EXPECT_EQ(m.num_faces(), 5);
  EXPECT_EQ(std::vector<int>(m.face(1).begin(), m.face(1).end()), (std::vector<int>{0, 2, 3}));
  EXPECT_EQ(m.face_size(4), 5);
  ASSERT_EQ(m.vertex_colors.size(), 5u);
  EXPECT_EQ(m.vertex_colors[1], Eigen::Vector3f(0, 1, 0));
  // Corners without vt / vn point at an added neutral entry.
  ASSERT_TRUE(m.has_texcoords());
  EXPECT_EQ(m.texcoords.size(), 4u);
  EXPECT_EQ(m.texcoords[static_cast<size_t>(m.corner_texcoords[3])], Eigen::Vector2d::Zero());
  EXPECT_EQ(m.corner_texcoords[7], 1);
  ASSERT_TRUE(m.has_normals());
  EXPECT_EQ(m.corner_normals[3], 0);
  // The unknown material keeps its name.
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_EQ(m.materials[0].name, "skin");
  EXPECT_EQ(m.face_materials, (std::vector<int>{0, 0, 0, 0, 0}));
  EXPECT_EQ(m.corners, (std::vector<std::pair<int, double>>{{0, 7.5}, {4, 7.5}}));
  // Warnings: missing mtl, the `l` element, default texcoords, default normals.
  EXPECT_EQ(r.warnings.size(), 4u);
  EXPECT_NE(r.warnings[0].find("missing.mtl"), std::string::npos);
}

TEST(MeshIo, MtlTextureOptionsAndUnknownKeywords) {
  const fs::path dir = test::scratch_dir("mtl_options");
  fs::create_directories(dir / "mat");
  write_text(
      dir / "mat" / "lib.mtl",
      "newmtl a\nbsdf pbr\nKd 0.1 0.2 0.3\nKs 0 0.25 0\nmap_Kd -s 2 2 1 -clamp on tex/a b.png\n"
      "newmtl b\nmap_Kd ..\\shared.png\n");
  write_text(dir / "m.obj", "mtllib mat/lib.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl b\nf 1 2 3\n");
  const MeshReadResult r = read_mesh(dir / "m.obj");
  ASSERT_EQ(r.mesh.materials.size(), 2u);
  EXPECT_EQ(r.mesh.materials[0].diffuse, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_EQ(r.mesh.materials[0].diffuse_texture, dir / "mat" / "tex" / "a b.png");
  EXPECT_EQ(r.mesh.materials[1].diffuse_texture, dir / "shared.png");
  EXPECT_EQ(r.mesh.face_materials, std::vector<int>{1});
  MeshReadOptions no_materials;
  no_materials.load_materials = false;
  EXPECT_EQ(read_mesh(dir / "m.obj", no_materials).mesh.materials.size(), 1u);  // "b", by name only
}

TEST(MeshIo, OffVariants) {
  const fs::path dir = test::scratch_dir("off_variants");
  // Counts on the header line, comments, blank lines, integer colours, a face colour.
  write_text(dir / "a.off",
             "COFF 4 2 0\n# comment\n\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n1 1 0 0 0 255 255\n"
             "0 1 0 51 51 51 255 # trailing\n3 0 1 2 1 0 0\n3 0 2 3\n");
  const MeshReadResult a = read_mesh(dir / "a.off");
  EXPECT_EQ(a.mesh.num_faces(), 2);
  ASSERT_EQ(a.mesh.vertex_colors.size(), 4u);
  EXPECT_EQ(a.mesh.vertex_colors[0], Eigen::Vector3f(1, 0, 0));
  EXPECT_FLOAT_EQ(a.mesh.vertex_colors[3].x(), 0.2f);
  // Real-valued colours, normals and texture coordinates.
  write_text(dir / "b.off",
             "STCNOFF\n3 1 0\n0 0 0 0 0 1 0.5 0.5 0.5 1 0.25 0.75\n1 0 0 0 0 1 1 1 1 1 0 0\n"
             "0 1 0 0 0 1 0 0 0 1 1 1\n3 0 1 2\n");
  const MeshReadResult b = read_mesh(dir / "b.off");
  EXPECT_EQ(b.mesh.vertex_colors[0], Eigen::Vector3f(0.5f, 0.5f, 0.5f));
  ASSERT_TRUE(b.mesh.has_texcoords());
  EXPECT_EQ(b.mesh.texcoords[0], Eigen::Vector2d(0.25, 0.75));
  ASSERT_TRUE(b.mesh.has_normals());
  EXPECT_EQ(b.mesh.normals[2], Eigen::Vector3d(0, 0, 1));
}

/// A binary PLY in either byte order with unusual types: float positions, ushort colours, a `uint`
/// list count with `short` indices, an unknown vertex property, an extra `edge` element before the
/// faces, and a per-face property after the list.
std::string exotic_binary_ply(bool big_endian) {
  std::string out = std::string("ply\nformat ") +
                    (big_endian ? "binary_big_endian" : "binary_little_endian") +
                    " 1.0\ncomment exotic\nelement vertex 3\nproperty float x\nproperty float y\n"
                    "property float z\nproperty uchar quality\nproperty ushort red\n"
                    "property ushort green\nproperty ushort blue\nelement edge 1\n"
                    "property int vertex1\nproperty int vertex2\nelement face 1\n"
                    "property list uint short vertex_index\nproperty double area\nend_header\n";
  auto put = [&](auto value) {
    char bytes[sizeof(value)];
    std::memcpy(bytes, &value, sizeof(value));
    if (big_endian) std::reverse(bytes, bytes + sizeof(value));
    out.append(bytes, sizeof(value));
  };
  const float xyz[3][3] = {{0, 0, 0}, {1.5f, 0, 0}, {0, -2.25f, 1}};
  for (int v = 0; v < 3; ++v) {
    for (float c : xyz[v]) put(c);
    put(static_cast<std::uint8_t>(7));
    put(static_cast<std::uint16_t>(65535));
    put(static_cast<std::uint16_t>(0));
    put(static_cast<std::uint16_t>(v == 1 ? 65535 : 0));
  }
  put(static_cast<std::int32_t>(0));
  put(static_cast<std::int32_t>(1));
  put(static_cast<std::uint32_t>(3));
  for (std::int16_t i : {0, 1, 2}) put(i);
  put(0.5);
  return out;
}

TEST(MeshIo, PlyBinaryBothByteOrdersAndExoticTypes) {
  const fs::path dir = test::scratch_dir("ply_exotic");
  for (const bool big : {false, true}) {
    SCOPED_TRACE(big ? "big endian" : "little endian");
    write_text(dir / "e.ply", exotic_binary_ply(big));
    const MeshReadResult r = read_mesh(dir / "e.ply");
    ASSERT_EQ(r.mesh.num_vertices(), 3);
    EXPECT_EQ(r.mesh.positions[1], Eigen::Vector3d(1.5, 0, 0));
    EXPECT_EQ(r.mesh.positions[2], Eigen::Vector3d(0, -2.25, 1));
    EXPECT_EQ(r.mesh.vertex_colors[1], Eigen::Vector3f(1, 0, 1));
    EXPECT_EQ(r.mesh.face_vertices, (std::vector<int>{0, 1, 2}));
  }
}

TEST(MeshIo, PlyAsciiVariants) {
  const fs::path dir = test::scratch_dir("ply_ascii_variants");
  write_text(
      dir / "a.ply",
      "ply\r\nformat ascii 1.0\r\nobj_info x\r\nelement vertex 4\r\nproperty double x\r\n"
      "property double y\r\nproperty double z\r\nproperty float s\r\nproperty float t\r\n"
      "property list uchar int junk\r\nelement face 1\r\nproperty list uchar int vertex_indices\r\n"
      "end_header\r\n0 0 0 0 0 2 5 6\r\n1 0 0 1 0 0\r\n1 1 0 1 1 1 9\r\n0 1 0 0 1 0\r\n"
      "4 0 1 2 3\r\n");
  const MeshReadResult r = read_mesh(dir / "a.ply");
  EXPECT_EQ(r.mesh.num_vertices(), 4);
  EXPECT_EQ(r.mesh.face_size(0), 4);
  ASSERT_TRUE(r.mesh.has_texcoords());
  EXPECT_EQ(r.mesh.texcoords[2], Eigen::Vector2d(1, 1));
}

TEST(MeshIo, ReadingIsIndependentOfTheFormat) {
  // The same mesh through every writer and reader gives the same positions and faces.
  const fs::path dir = test::scratch_dir("all_formats");
  PolygonMesh m = awkward_mesh(true);
  for (const char* name : {"m.obj", "m.off", "m.ply"}) {
    write_mesh(dir / name, m);
    expect_same_geometry(m, read_mesh(dir / name).mesh);
  }
  MeshWriteOptions options;
  options.format = MeshFormat::Ply;
  write_mesh(dir / "ply_without_extension.dat", m, options);
  MeshReadOptions read_options;
  read_options.format = MeshFormat::Ply;
  expect_same_geometry(m, read_mesh(dir / "ply_without_extension.dat", read_options).mesh);
}

// --- errors
// ------------------------------------------------------------------------------------------

/// Reads a file that must fail with exception type E whose message names the file (and `fragment`).
template <class E>
void expect_error(const fs::path& path, const std::string& fragment = "") {
  try {
    read_mesh(path);
    ADD_FAILURE() << path << " was accepted";
  } catch (const E& e) {
    EXPECT_EQ(e.input(), path.string());
    EXPECT_NE(std::string(e.what()).find(path.filename().string()), std::string::npos) << e.what();
    EXPECT_NE(e.problem().find(fragment), std::string::npos) << e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << path << ": wrong exception type: " << e.what();
  }
}

class MeshIoErrors : public ::testing::Test {
 protected:
  fs::path file(const std::string& name, const std::string& text) {
    const fs::path path = dir_ / name;
    write_text(path, text);
    return path;
  }
  fs::path dir_ = test::scratch_dir("errors");
};

TEST_F(MeshIoErrors, MissingFileIsAnIoError) {
  expect_error<IoError>(dir_ / "absent.obj", "no such file");
}

TEST_F(MeshIoErrors, UnknownExtension) {
  expect_error<InvalidInputError>(file("x.mesh", "v 0 0 0\n"));
}

TEST_F(MeshIoErrors, EmptyFiles) {
  for (const char* name : {"e.obj", "e.off", "e.ply", "e.stl"}) {
    expect_error<InvalidInputError>(file(name, ""), "empty file");
  }
}

TEST_F(MeshIoErrors, NoFaces) {
  expect_error<InvalidInputError>(file("points.obj", "v 0 0 0\nv 1 0 0\n"), "no faces");
}

TEST_F(MeshIoErrors, UnparsableNumbers) {
  expect_error<InvalidInputError>(file("n.obj", "v 0 0 0\nv 1 x 0\nv 0 1 0\nf 1 2 3\n"), "line 2");
  expect_error<InvalidInputError>(file("n2.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3a\n"),
                                  "line 4");
  expect_error<InvalidInputError>(file("n.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1,5 0\n3 0 1 2\n"),
                                  "line 5");
  expect_error<InvalidInputError>(
      file("n.ply",
           "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
           "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
           "0 0 0\n1 0 zero\n0 1 0\n3 0 1 2\n"),
      "line 11");
  expect_error<InvalidInputError>(
      file("n.stl",
           "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 --0\n"
           "endloop\nendfacet\nendsolid s\n"),
      "line 6");
  expect_error<InvalidInputError>(file("count.off", "OFF\nthree 1 0\n"), "line 2");
}

TEST_F(MeshIoErrors, NonFiniteCoordinates) {
  expect_error<InvalidInputError>(file("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"), "NaN");
  expect_error<InvalidInputError>(file("inf.off", "OFF\n3 1 0\n0 0 0\n1 0 inf\n0 1 0\n3 0 1 2\n"),
                                  "NaN");
  expect_error<InvalidInputError>(
      file("nan.ply",
           "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
           "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
           "end_header\n0 0 0\n1 0 -inf\n0 1 0\n3 0 1 2\n"),
      "NaN");
  expect_error<InvalidInputError>(file("nan.stl",
                                       "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n"
                                       "vertex 1 0 0\nvertex 0 1 nan\nendloop\nendfacet\n"
                                       "endsolid s\n"),
                                  "NaN");
}

TEST_F(MeshIoErrors, IndexOutOfRange) {
  expect_error<InvalidInputError>(file("r.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"), "line 4");
  expect_error<InvalidInputError>(file("r0.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"),
                                  "index 0");
  expect_error<InvalidInputError>(file("rneg.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 1 2\n"),
                                  "out of range");
  expect_error<InvalidInputError>(
      file("rvt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/2\n"),
      "texture coordinate index 2");
  expect_error<InvalidInputError>(
      file("rt.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nt crease 2/1/0 0 3 1\n"), "line 5");
  expect_error<InvalidInputError>(file("r.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"),
                                  "line 6");
  expect_error<InvalidInputError>(
      file("r.ply",
           "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
           "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
           "0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n"),
      "out of range");
}

TEST_F(MeshIoErrors, FacesWithFewerThanThreeCorners) {
  expect_error<InvalidInputError>(file("f.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n"), "line 4");
  expect_error<InvalidInputError>(file("f.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n"),
                                  "line 6");
  expect_error<InvalidInputError>(
      file("f.ply",
           "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
           "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
           "0 0 0\n1 0 0\n0 1 0\n2 0 1\n"),
      "corners");
  expect_error<InvalidInputError>(
      file("f.stl",
           "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n"
           "endfacet\nendsolid s\n"),
      "line 6");
}

TEST_F(MeshIoErrors, TruncatedFiles) {
  expect_error<InvalidInputError>(file("t.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n"), "2 of 3 vertices");
  expect_error<InvalidInputError>(file("t2.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"),
                                  "1 of 2 faces");
  expect_error<InvalidInputError>(file("t3.off", "OFF\n"), "truncated");
  expect_error<InvalidInputError>(
      file("t.ply",
           "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
           "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
           "0 0 0\n1 0 0\n0 1 0\n3 0 1\n"),
      "truncated");
  expect_error<InvalidInputError>(file("h.ply", "ply\nformat ascii 1.0\nelement vertex 3\n"),
                                  "end_header");
  // Binary PLY and STL shorter than their headers say.
  std::string ply = exotic_binary_ply(false);
  ply.resize(ply.size() - 5);
  expect_error<InvalidInputError>(file("t_bin.ply", ply), "truncated");
  const fs::path stl = dir_ / "full.stl";
  MeshWriteOptions binary;
  binary.binary = true;
  write_mesh(stl, awkward_mesh(true), binary);
  std::string bytes = read_text(stl);
  bytes.resize(bytes.size() - 30);
  expect_error<InvalidInputError>(file("t_bin.stl", bytes), "truncated");
  expect_error<InvalidInputError>(file("tiny.stl", "abc"), "truncated");
  expect_error<InvalidInputError>(
      file("t_ascii.stl", "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"),
      "truncated");
}

TEST_F(MeshIoErrors, MalformedHeaders) {
  expect_error<InvalidInputError>(file("x.off", "NOT AN OFF\n"), "OFF header");
  expect_error<InvalidInputError>(file("x.ply", "plyx\n"), "magic");
  expect_error<InvalidInputError>(
      file("y.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n"), "line 2");
  expect_error<InvalidInputError>(file("z.ply",
                                       "ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\n"
                                       "end_header\n"),
                                  "line 4");
}

TEST(MeshIoWrite, FailureLeavesTheOldFile) {
  const fs::path dir = test::scratch_dir("write_failure");
  const fs::path path = dir / "keep.obj";
  write_text(path, "old content");
  PolygonMesh bad = awkward_mesh();
  bad.face_vertices[2] = 99;  // out of range: rejected before anything is written
  EXPECT_THROW(write_mesh(path, bad), InvalidInputError);
  EXPECT_EQ(read_text(path), "old content");
  // An I/O failure: the destination is a directory, so the rename fails after writing the
  // temporary.
  fs::create_directories(dir / "a_directory.off");
  EXPECT_THROW(write_mesh(dir / "a_directory.off", awkward_mesh()), IoError);
  // No temporaries are left behind.
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) files += entry.is_regular_file() ? 1 : 0;
  EXPECT_EQ(files, 1);
  EXPECT_THROW(write_mesh(dir / "missing_folder" / "x.obj", awkward_mesh()), IoError);
}

TEST(MeshIoWrite, RejectsInconsistentMeshes) {
  const fs::path dir = test::scratch_dir("write_inconsistent");
  PolygonMesh m = awkward_mesh();
  m.corner_texcoords.pop_back();
  EXPECT_THROW(write_mesh(dir / "a.obj", m), InvalidInputError);
  m = awkward_mesh();
  m.vertex_colors.pop_back();
  EXPECT_THROW(write_mesh(dir / "a.ply", m), InvalidInputError);
  m = awkward_mesh();
  m.positions[0].y() = std::numeric_limits<double>::infinity();
  EXPECT_THROW(write_mesh(dir / "a.off", m), InvalidInputError);
  EXPECT_THROW(write_mesh(dir / "a.xyz", awkward_mesh()), InvalidInputError);
}

}  // namespace
}  // namespace elastic
