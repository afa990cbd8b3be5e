// Material textures are held to ImageReadOptions::max_pixels like every image: one beyond the
// limit is skipped with a warning that names the file, the size and the way to raise the limit.

#include <gtest/gtest.h>

#include <fstream>

#include "elastic/mesh/mesh_io.h"
#include "elastic/render/render.h"
#include "png_bomb.h"
#include "support.h"

namespace elastic {
namespace {

namespace fs = std::filesystem;

TEST(TextureLimits, TextureBeyondTheLimitBecomesAWarning) {
  const fs::path dir = test::scratch_dir("texture_limits");
  test::write_zero_grey_png(dir / "tex.png", 40, 25);  // 1000 pixels
  std::ofstream(dir / "m.mtl") << "newmtl m\nmap_Kd tex.png\n";
  std::ofstream(dir / "m.obj") << "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\n"
                                  "vt 0 1\nusemtl m\nf 1/1 2/2 3/3\n";
  const PolygonMesh mesh = read_mesh(dir / "m.obj").mesh;
  const MaterialTextures refused =
      load_material_textures(mesh, {.max_pixels = 999, .limit_name = "--max-image-pixels"});
  ASSERT_EQ(refused.images.size(), 1u);
  EXPECT_TRUE(refused.images[0].empty());
  ASSERT_EQ(refused.warnings.size(), 1u);
  EXPECT_NE(refused.warnings[0].find("tex.png: image of 40 x 25 = 1000 pixels is larger than the "
                                     "limit of 999 pixels; raise it with --max-image-pixels"),
            std::string::npos)
      << refused.warnings[0];
  const MaterialTextures read = load_material_textures(mesh, {.max_pixels = 1000});
  ASSERT_EQ(read.images.size(), 1u);
  EXPECT_EQ(read.images[0].width, 40);
  EXPECT_TRUE(read.warnings.empty());
}

}  // namespace
}  // namespace elastic
