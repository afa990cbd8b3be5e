// The files `elastic paste` writes, opened with a reader we did not write (assimp, as Blender-like
// tools do), from a copy of the output folder moved to another place (issue 15): every face has a
// material of the file, no face outside the region is on the decal material, every texture is a
// bare name that resolves in the moved folder, UVs are finite and inside the image (within [0,1],
// or the input's own range where the target's UVs reach beyond it), and the PLYs' vertex counts
// and colours are what our own reader reads.
//
// Two runs, each with one paste: the demo's (the emblem onto the procedural vase, a target without
// UVs or materials; fewer particles than scripts/demo) and a textured target (spot with its
// texture, baked and displaced as well).
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "elastic/mesh/mesh_io.h"
#include "support.h"

namespace elastic {
namespace {

namespace fs = std::filesystem;

/// Runs `elastic ARGS` (stdout and stderr into files in `dir`); returns the exit code and stderr.
std::pair<int, std::string> run_elastic(const std::string& args, const fs::path& dir) {
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string command = std::string("'") + ELASTIC_CLI + "' " + args + " >'" + out.string() +
                              "' 2>'" + err.string() + "' </dev/null";
  const int status = std::system(command.c_str());
  std::ifstream in(err);
  std::stringstream text;
  text << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), text.str()};
}

/// The output folder copied to another place, and the original removed, so that nothing in the
/// copy can resolve against the place it was written to.
fs::path move_elsewhere(const fs::path& out, const fs::path& elsewhere) {
  fs::create_directories(elsewhere.parent_path());
  fs::copy(out, elsewhere, fs::copy_options::recursive);
  fs::remove_all(out);
  return elsewhere;
}

struct AssimpFile {
  Assimp::Importer importer;  // owns the scene
  const aiScene* scene = nullptr;
};

/// Opens a file with assimp (only its structural validation; no joining, no triangulation, so
/// faces are as the file has them).
void open_with_assimp(const fs::path& path, AssimpFile& file) {
  file.scene = file.importer.ReadFile(path.string(), aiProcess_ValidateDataStructure);
  ASSERT_NE(file.scene, nullptr) << path << ": " << file.importer.GetErrorString();
  ASSERT_GT(file.scene->mNumMeshes, 0u) << path;
}

std::string material_name(const aiMaterial* material) {
  aiString name;
  material->Get(AI_MATKEY_NAME, name);
  return name.C_Str();
}

/// The material's diffuse texture as the file names it (empty: none).
std::string diffuse_texture(const aiMaterial* material) {
  if (material->GetTextureCount(aiTextureType_DIFFUSE) == 0) return {};
  aiString path;
  material->GetTexture(aiTextureType_DIFFUSE, 0, &path);
  return path.C_Str();
}

bool is_png(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::array<char, 8> head{};
  in.read(head.data(), head.size());
  return in && std::string(head.data(), 4) == "\x89PNG";
}

/// The range of texture coordinates an input file holds, as assimp reads it.
struct UvRange {
  double lo = 0.0, hi = 1.0;  // always includes [0, 1]
};
UvRange input_uv_range(const fs::path& path) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path.string(), aiProcess_ValidateDataStructure);
  UvRange range;
  if (scene == nullptr) return range;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    if (!mesh->HasTextureCoords(0)) continue;
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      for (int k = 0; k < 2; ++k) {
        range.lo = std::min(range.lo, static_cast<double>(mesh->mTextureCoords[0][v][k]));
        range.hi = std::max(range.hi, static_cast<double>(mesh->mTextureCoords[0][v][k]));
      }
    }
  }
  return range;
}

/// Faces per material name of an OBJ as assimp reads it.
struct ObjCheck {
  std::map<std::string, long> faces;  // material name -> face count
  long total_faces = 0;
  std::vector<Eigen::Vector3d> decal_vertices;  // corners of the faces on `decal`
};

/// The checks every OBJ of an output folder must pass, whatever it holds: every face on a material
/// the file defines (never assimp's own default), textures as bare names of PNGs in the folder,
/// textured faces with finite UVs inside the image (`target_uv` for the target's materials,
/// [0,1] for the decal's).
ObjCheck check_obj(const fs::path& obj, const UvRange& target_uv) {
  ObjCheck check;
  AssimpFile file;
  open_with_assimp(obj, file);
  if (file.scene == nullptr) return check;
  const aiScene* scene = file.scene;
  constexpr double kUvSlack = 1e-6;  // float storage in assimp, shortest decimals in the file
  for (unsigned i = 0; i < scene->mNumMeshes; ++i) {
    const aiMesh* mesh = scene->mMeshes[i];
    const aiMaterial* material = scene->mMaterials[mesh->mMaterialIndex];
    const std::string name = material_name(material);
    check.faces[name] += mesh->mNumFaces;
    check.total_faces += mesh->mNumFaces;
    EXPECT_NE(name, AI_DEFAULT_MATERIAL_NAME)
        << obj.filename() << ": " << mesh->mNumFaces << " faces without a material of the file";
    const std::string texture = diffuse_texture(material);
    if (texture.empty()) continue;
    // A bare name that resolves beside the OBJ of the moved folder.
    EXPECT_EQ(texture.find_first_of("/\\"), std::string::npos)
        << obj.filename() << ": material '" << name << "' names " << texture;
    const fs::path resolved = obj.parent_path() / texture;
    EXPECT_TRUE(fs::is_regular_file(resolved)) << obj.filename() << ": " << texture;
    EXPECT_TRUE(is_png(resolved)) << resolved;
    // Textured faces have UVs, finite and inside the image.
    if (!mesh->HasTextureCoords(0)) {
      ADD_FAILURE() << obj.filename() << ": faces on material " << name << " have no UVs";
      continue;
    }
    const bool decal = name == "decal";
    const double lo = decal ? 0.0 : target_uv.lo, hi = decal ? 1.0 : target_uv.hi;
    int bad = 0;
    for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
      for (int k = 0; k < 2; ++k) {
        const double t = mesh->mTextureCoords[0][v][k];
        if (!std::isfinite(t) || t < lo - kUvSlack || t > hi + kUvSlack) ++bad;
      }
    }
    EXPECT_EQ(bad, 0) << obj.filename() << ": UVs of material " << name << " outside [" << lo
                      << ", " << hi << "]";
    if (decal) {
      for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
        for (unsigned k = 0; k < mesh->mFaces[f].mNumIndices; ++k) {
          const aiVector3D& p = mesh->mVertices[mesh->mFaces[f].mIndices[k]];
          check.decal_vertices.emplace_back(p.x, p.y, p.z);
        }
      }
    }
  }
  return check;
}

/// A PLY as assimp reads it against our own reader: the same vertex and face counts, and the same
/// vertex colours (8-bit in the file: assimp gives k / 255, ours too).
void check_ply_against_ours(const fs::path& ply) {
  AssimpFile file;
  open_with_assimp(ply, file);
  if (file.scene == nullptr) return;
  const PolygonMesh ours = read_mesh(ply).mesh;
  ASSERT_TRUE(ours.has_vertex_colors()) << ply;
  ASSERT_EQ(file.scene->mNumMeshes, 1u) << ply;
  const aiMesh* mesh = file.scene->mMeshes[0];
  ASSERT_EQ(static_cast<int>(mesh->mNumVertices), ours.num_vertices()) << ply;
  ASSERT_EQ(static_cast<int>(mesh->mNumFaces), ours.num_faces()) << ply;
  ASSERT_TRUE(mesh->HasVertexColors(0)) << ply << ": assimp sees no vertex colours";
  int differ = 0;
  for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
    const aiColor4D& c = mesh->mColors[0][v];
    const Eigen::Vector3f theirs(c.r, c.g, c.b);
    const Eigen::Vector3d p(mesh->mVertices[v].x, mesh->mVertices[v].y, mesh->mVertices[v].z);
    // Same vertex (float storage), same colour (half a step of 8 bits).
    if ((p - ours.positions[v]).norm() > 1e-5 * (1.0 + ours.positions[v].norm()) ||
        (theirs - ours.vertex_colors[v]).cwiseAbs().maxCoeff() > 0.5f / 255.0f + 1e-6f) {
      ++differ;
    }
  }
  EXPECT_EQ(differ, 0) << ply << ": vertices whose position or colour differ from ours";
}

/// Every file the report lists is in the moved folder.
void check_report_files(const nlohmann::json& report, const fs::path& moved) {
  ASSERT_TRUE(report.contains("files"));
  for (const auto& f : report["files"]) {
    const fs::path name = fs::path(f.get<std::string>()).filename();
    EXPECT_TRUE(fs::exists(moved / name) || fs::exists(moved / "frames" / name)) << name;
  }
}

nlohmann::json read_report(const fs::path& folder) {
  std::ifstream in(folder / "report.json");
  return nlohmann::json::parse(in);
}

// Runs `elastic paste ARGS --out DIR/run/out`, checks it succeeded, moves the output folder to
// DIR/elsewhere/copy (deleting the original) and returns the moved folder; the report is read
// from there and every file it lists must exist there.
fs::path paste_and_move(const std::string& args, const fs::path& dir, nlohmann::json& report) {
  const fs::path out = dir / "run" / "out";
  const auto [code, err] = run_elastic("paste -q " + args + " --out '" + out.string() + "'", dir);
  EXPECT_EQ(code, 0) << err;
  if (code != 0) {
    return {};
  }
  const fs::path moved = move_elsewhere(out, dir / "elsewhere" / "copy");
  report = read_report(moved);
  check_report_files(report, moved);
  return moved;
}

/// The heatmap's colour scale in the report, and its PLY as assimp reads it.
void check_heatmap(const nlohmann::json& report, const fs::path& moved) {
  ASSERT_TRUE(report.contains("heatmap")) << "no colour scale in the report";
  const nlohmann::json& scale = report["heatmap"];
  EXPECT_EQ(scale["metric"], "symmetric_dirichlet");
  EXPECT_DOUBLE_EQ(scale["min"].get<double>(), 4.0);  // the perfect value
  EXPECT_GT(scale["max"].get<double>(), scale["min"].get<double>());
  for (const char* key : {"min", "mid", "max", "fold", "excluded"}) {
    EXPECT_EQ(scale["colors"][key].size(), 3u) << key;
  }
  check_ply_against_ours(moved / "heatmap.ply");
}

TEST(AssimpOutputs, DemoPasteOntoTheVaseStandsAloneWithEveryFaceOnAMaterial) {
  const fs::path dir = test::scratch_dir("assimp_vase");
  const fs::path emblem = dir / "emblem.png";
  ASSERT_EQ(run_elastic("render --emblem '" + emblem.string() + "' --size 256 --quiet", dir).first,
            0);
  // scripts/demo's paste with 1,500 particles instead of 5,775 and fewer refined vertices.
  nlohmann::json report;
  const fs::path moved = paste_and_move(
      "--source-image '" + emblem.string() + "' --source-region ellipse --target '" +
          test::project_mesh("vase_quads.obj").string() +
          "' --target-region disk:0.55,0,0.45,0.45 --particles 1500 --baseline lscm --preview "
          "--preview-size 160 --min-vertices 4000",
      dir, report);
  ASSERT_FALSE(HasFailure());

  // The vase has no UVs and no material: outside faces are on the default material, region
  // faces on the decal, nothing else.
  const ObjCheck painted = check_obj(moved / "painted.obj", {});
  EXPECT_EQ(painted.total_faces, report["paste"]["mesh_triangles"].get<long>());
  EXPECT_EQ(painted.faces.count("decal") ? painted.faces.at("decal") : 0,
            report["paste"]["region_triangles"].get<long>())
      << "faces outside the region are on the decal material";
  EXPECT_EQ(painted.faces.count("default") ? painted.faces.at("default") : 0,
            painted.total_faces - report["paste"]["region_triangles"].get<long>());
  // The decal's faces lie in the region: within its geodesic radius 0.45 (>= the chord) of the
  // disk's centre, which is at most the disk point's distance from the surface away from it. 5%
  // of the radius on top: the disk's distances come from the heat method (region_spec.h), which
  // is approximate by a few percent on this tessellation (measured: 1.2%).
  ASSERT_FALSE(painted.decal_vertices.empty());
  const PolygonMesh ours = read_mesh(moved / "painted.obj").mesh;
  const Eigen::Vector3d centre(0.55, 0.0, 0.45);
  double off_surface = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& p : ours.positions) {
    off_surface = std::min(off_surface, (p - centre).norm());
  }
  int far = 0;
  for (const Eigen::Vector3d& p : painted.decal_vertices) {
    far += (p - centre).norm() > 1.05 * 0.45 + off_surface ? 1 : 0;
  }
  EXPECT_EQ(far, 0) << "decal faces outside the region";

  // colors.ply: counts and colours as ours; the emblem's transparent texels show the vase's own
  // default grey, never black.
  check_ply_against_ours(moved / "colors.ply");
  const PolygonMesh colors = read_mesh(moved / "colors.ply").mesh;
  int black = 0;
  for (const Eigen::Vector3f& c : colors.vertex_colors) black += c.maxCoeff() < 0.05f ? 1 : 0;
  EXPECT_EQ(black, 0) << "vertices painted black (transparent texels not blended)";

  check_heatmap(report, moved);
  EXPECT_EQ(report["heatmap"]["methods"].size(), 2u);  // ElasticPaint and LSCM on one scale
  EXPECT_TRUE(fs::exists(moved / "heatmap_lscm.ply"));
}

TEST(AssimpOutputs, TexturedSpotKeepsItsTextureInEveryOutputAfterTheFolderMoves) {
  ELASTIC_REQUIRE_SHARED_MESH(spot, "spot.obj");
  const fs::path dir = test::scratch_dir("assimp_spot");
  const fs::path emblem = dir / "emblem.png";
  ASSERT_EQ(run_elastic("render --emblem '" + emblem.string() + "' --size 128 --quiet", dir).first,
            0);
  // A disk on spot's flank, baked into its texture and raised by the emblem's luminance.
  nlohmann::json report;
  const fs::path moved = paste_and_move(
      "--source-image '" + emblem.string() + "' --source-region ellipse --target '" +
          spot.string() +
          "' --target-region disk:0.33,0.07,0.24,0.15 --particles 400 --resolution 2 "
          "--min-vertices 3000 --bake --height luminance --height-scale 0.01",
      dir, report);
  ASSERT_FALSE(HasFailure());
  const UvRange spot_uv = input_uv_range(spot);
  EXPECT_LT(spot_uv.lo, 0.0);  // spot's u reaches -0.052 (shared/meshes/README.md)

  // painted.obj: spot's own material (with its texture, copied in) outside, the decal inside.
  const ObjCheck painted = check_obj(moved / "painted.obj", spot_uv);
  EXPECT_EQ(painted.faces.count("decal") ? painted.faces.at("decal") : 0,
            report["paste"]["region_triangles"].get<long>());
  EXPECT_EQ(
      painted.faces.count("initialShadingGroup") ? painted.faces.at("initialShadingGroup") : 0,
      painted.total_faces - report["paste"]["region_triangles"].get<long>());
  EXPECT_TRUE(is_png(moved / "spot_texture.png"));

  // baked.obj: every face on spot's material, which now names baked.png.
  const ObjCheck baked = check_obj(moved / "baked.obj", spot_uv);
  ASSERT_EQ(baked.faces.size(), 1u);
  EXPECT_EQ(baked.faces.begin()->first, "initialShadingGroup");
  {
    AssimpFile file;
    open_with_assimp(moved / "baked.obj", file);
    ASSERT_NE(file.scene, nullptr);
    EXPECT_EQ(diffuse_texture(file.scene->mMaterials[file.scene->mMeshes[0]->mMaterialIndex]),
              "baked.png");
  }

  // displaced.obj keeps spot's UVs and material (check_obj asserts UVs on textured faces).
  const ObjCheck displaced = check_obj(moved / "displaced.obj", spot_uv);
  EXPECT_EQ(displaced.total_faces, report["paste"]["mesh_triangles"].get<long>());
  EXPECT_EQ(
      displaced.faces.count("initialShadingGroup") ? displaced.faces.at("initialShadingGroup") : 0,
      displaced.total_faces);

  // colors.ply: outside the region, spot's texture (not a flat grey): many distinct colours.
  check_ply_against_ours(moved / "colors.ply");
  const PolygonMesh colors = read_mesh(moved / "colors.ply").mesh;
  std::map<std::array<long, 3>, int> distinct;
  for (const Eigen::Vector3f& c : colors.vertex_colors) {
    ++distinct[{std::lround(c.x() * 255.0f), std::lround(c.y() * 255.0f),
                std::lround(c.z() * 255.0f)}];
  }
  EXPECT_GT(distinct.size(), 100u) << "spot's texture is not in its vertex colours";

  check_heatmap(report, moved);
}

}  // namespace
}  // namespace elastic
