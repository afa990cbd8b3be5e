// The paste entry point (transfer/paste.h) and the height helpers it uses (displacement.h): the
// displaced region against heights computed here from a colour that is linear on the source, the
// files written, the option checks and cancellation.
#include "elastic/transfer/paste.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "elastic/core/error.h"
#include "elastic/mesh/default_material.h"
#include "elastic/shapes/procedural_shapes.h"
#include "mapped_pair.h"

namespace elastic {
namespace {

TEST(Paste, LuminanceIsRec709Luma) {
  EXPECT_DOUBLE_EQ(luminance({1.0f, 0.0f, 0.0f, 1.0f}), 0.2126);
  EXPECT_DOUBLE_EQ(luminance({0.0f, 1.0f, 0.0f, 0.0f}), 0.7152);
  EXPECT_DOUBLE_EQ(luminance({0.0f, 0.0f, 1.0f, 1.0f}), 0.0722);
  EXPECT_NEAR(luminance({1.0f, 1.0f, 1.0f, 0.5f}), 1.0, 1e-15);  // alpha is not read
}

TEST(Paste, FirstDiffuseTextureIsTheFirstMaterialWithOne) {
  PolygonMesh mesh;
  EXPECT_TRUE(first_diffuse_texture(mesh).empty());
  Material plain, a, b;
  a.diffuse_texture = "a.png";
  b.diffuse_texture = "b.png";
  mesh.materials = {plain, a, b};
  EXPECT_EQ(first_diffuse_texture(mesh), std::filesystem::path("a.png"));
}

// The source plane's colour, linear in position (x, y in [-1, 1]): the colour at a source point
// is this function of its limit position (linear precision, color_source.h).
Eigen::Vector3f plane_color(const Eigen::Vector3d& p) {
  return {static_cast<float>(0.5 + 0.25 * p.x()), static_cast<float>(0.5 - 0.25 * p.y()), 0.25f};
}

std::unique_ptr<test::Mapped> colored_plane_onto_cap() {
  PolygonMesh plane = make_plane({.resolution = 8});
  for (const Eigen::Vector3d& p : plane.positions) plane.vertex_colors.push_back(plane_color(p));
  return test::map_pair(plane, make_cap(), parse_region_spec("disk:0,0,0,0.6"),
                        parse_region_spec("boundary"), 200);
}

PasteOptions small_paste() {
  PasteOptions options;
  options.resolution = 4;
  options.max_levels = 3;
  options.min_vertices = 500;
  return options;
}

TEST(Paste, LuminanceReliefRisesAlongTheTargetNormal) {
  const auto m = colored_plane_onto_cap();
  PasteOptions options = small_paste();
  options.height = PasteHeight::Luminance;
  options.height_scale = 0.05;
  options.height_zero = 0.25;
  const PasteResult pasted = paste(*m->source, m->from, *m->target, m->to, m->result, options);
  ASSERT_TRUE(pasted.colors.has_value());
  EXPECT_EQ(pasted.colors->kind(), ColorSourceKind::VertexColors);  // Auto: no texture
  ASSERT_TRUE(pasted.displaced.has_value());
  EXPECT_FALSE(pasted.baked.has_value());
  EXPECT_FALSE(pasted.detail.has_value());
  EXPECT_FALSE(pasted.cancelled);

  const TargetSamples& samples = pasted.painted.samples;
  const std::vector<Eigen::Vector3d>& moved = pasted.displaced->positions;
  ASSERT_EQ(moved.size(), pasted.painted.positions.size());
  int checked = 0;
  double largest = 0.0;
  for (int i = 0; i < samples.num_vertices(); ++i) {
    const Mapping::Location& source = samples.sources[static_cast<size_t>(i)];
    const size_t v =
        static_cast<size_t>(pasted.painted.sample_vertex_index[static_cast<size_t>(i)]);
    const Eigen::Vector3d shift = moved[v] - pasted.painted.positions[v];
    if (!source.inside || samples.on_boundary[static_cast<size_t>(i)]) {
      EXPECT_NEAR(shift.norm(), 0.0, 1e-9) << "vertex " << i << " must stay";
      continue;
    }
    const Eigen::Vector3d c = plane_color(source.position).cast<double>();
    const double height = 0.2126 * c.x() + 0.7152 * c.y() + 0.0722 * c.z() - 0.25;
    const Eigen::Vector3d expected = 0.05 * height * samples.normals[static_cast<size_t>(i)];
    EXPECT_NEAR((shift - expected).norm(), 0.0, 1e-6) << "vertex " << i;
    largest = std::max(largest, shift.norm());
    ++checked;
  }
  EXPECT_GT(checked, 100);
  EXPECT_NEAR(pasted.displaced->displacement.max_displacement, largest, 1e-12);
  // Outside the region the painted mesh does not move.
  for (size_t v = 0; v < moved.size(); ++v) {
    if (pasted.painted.vertex_sample[v] < 0) {
      EXPECT_TRUE(moved[v] == pasted.painted.positions[v]) << "vertex " << v;
    }
  }

  // The files of `elastic paste` for a vertex-colour height paste, in its order.
  const std::filesystem::path dir =
      std::filesystem::path(ELASTIC_TEST_OUTPUT_DIR) / "paste_luminance_relief";
  std::filesystem::remove_all(dir);
  OutputFolder folder(dir);
  const std::vector<std::filesystem::path> written = write_paste(folder, pasted);
  ASSERT_EQ(written.size(), 3u);
  EXPECT_EQ(written[0].filename(), "colors.ply");
  EXPECT_EQ(written[1].filename(), "displaced.obj");
  EXPECT_EQ(written[2].filename(), "displaced.mtl");
  for (const auto& file : written) EXPECT_TRUE(std::filesystem::exists(file)) << file;
}

TEST(Paste, RefusesWhatTheInputsCannotGive) {
  const auto m = colored_plane_onto_cap();
  PasteOptions no_color = small_paste();
  no_color.color = PasteColor::None;
  no_color.height = PasteHeight::Luminance;
  EXPECT_THROW(paste(*m->source, m->from, *m->target, m->to, m->result, no_color),
               InvalidInputError);
  PasteOptions bake_nothing = small_paste();
  bake_nothing.color = PasteColor::None;
  bake_nothing.bake = true;
  EXPECT_THROW(paste(*m->source, m->from, *m->target, m->to, m->result, bake_nothing),
               InvalidInputError);
  PasteOptions no_texture = small_paste();
  no_texture.color = PasteColor::Texture;  // the plane has no material texture
  EXPECT_THROW(paste(*m->source, m->from, *m->target, m->to, m->result, no_texture),
               InvalidInputError);
  PasteOptions bad_alpha = small_paste();
  bad_alpha.alpha = 1.5f;
  EXPECT_THROW(paste(*m->source, m->from, *m->target, m->to, m->result, bad_alpha),
               InvalidInputError);
}

TEST(Paste, ProgressCanCancelBetweenSteps) {
  const auto m = colored_plane_onto_cap();
  PasteOptions options = small_paste();
  options.height = PasteHeight::Luminance;
  std::vector<std::string> stages;
  options.progress = [&](const Progress& p) {
    stages.emplace_back(p.stage);
    return p.stage != "height";
  };
  const PasteResult pasted = paste(*m->source, m->from, *m->target, m->to, m->result, options);
  EXPECT_TRUE(pasted.cancelled);
  EXPECT_FALSE(pasted.displaced.has_value());
  EXPECT_GT(pasted.painted.num_triangles(), 0);
  EXPECT_EQ(stages, (std::vector<std::string>{"paint", "height"}));
}

}  // namespace
}  // namespace elastic
