// Heatmap colours: the ramp's fixed points, the automatic range against a hand-computed quantile,
// fold and outside colours, vertex colours as ramp colours of the mean value around each vertex,
// one shared scale for several maps, a PLY round trip.

#include "elastic/metrics/heatmap.h"

#include <gtest/gtest.h>

#include <cmath>

#include "elastic/core/error.h"
#include "elastic/mesh/mesh_io.h"
#include "support.h"

namespace elastic {
namespace {

// A strip of n triangles (2n + ... vertices), with per-triangle values set by hand.
MapMetrics strip_metrics(const std::vector<double>& values, Eigen::Matrix3Xd& positions) {
  const int nt = static_cast<int>(values.size());
  const int np = nt + 2;
  positions.resize(3, np);
  for (int p = 0; p < np; ++p) positions.col(p) = Eigen::Vector3d(p / 2, p % 2, 0.0);
  MapMetrics m;
  for (int t = 0; t < nt; ++t) {
    m.triangles.push_back(t % 2 == 0 ? Eigen::Vector3i(t, t + 1, t + 2)
                                     : Eigen::Vector3i(t + 1, t, t + 2));
  }
  TriangleValues& tv = m.per_triangle;
  tv.symmetric_dirichlet = values;
  tv.folded.assign(nt, 0);
  tv.excluded.assign(nt, 0);
  return m;
}

constexpr float kExact = 0.0f;  // the ramp's fixed points are exact binary fractions

TEST(Heatmap, RampFixedPoints) {
  EXPECT_TRUE(heatmap_color(4.0, 4.0, 6.0).isApprox(Eigen::Vector3f(0, 1, 0), kExact));
  EXPECT_TRUE(heatmap_color(5.0, 4.0, 6.0).isApprox(Eigen::Vector3f(1, 1, 0), kExact));
  EXPECT_TRUE(heatmap_color(6.0, 4.0, 6.0).isApprox(Eigen::Vector3f(1, 0, 0), kExact));
  // Clamped outside the range; +inf is the worst.
  EXPECT_TRUE(heatmap_color(100.0, 4.0, 6.0).isApprox(Eigen::Vector3f(1, 0, 0), kExact));
  EXPECT_TRUE(heatmap_color(1.0, 4.0, 6.0).isApprox(Eigen::Vector3f(0, 1, 0), kExact));
  EXPECT_TRUE(heatmap_color(INFINITY, 4.0, 6.0).isApprox(Eigen::Vector3f(1, 0, 0), kExact));
  // A quarter of the way: red half risen, green full.
  EXPECT_FLOAT_EQ(heatmap_color(4.5, 4.0, 6.0).x(), 0.5f);
  EXPECT_FLOAT_EQ(heatmap_color(4.5, 4.0, 6.0).y(), 1.0f);
}

TEST(Heatmap, AutomaticRangeIsAQuantileOfTheUnfoldedValues) {
  // 21 values 4, 4.1, ..., 6 plus one huge outlier that is folded (and must not set the range).
  std::vector<double> values;
  for (int k = 0; k <= 20; ++k) values.push_back(4.0 + 0.1 * k);
  values.push_back(1e6);
  Eigen::Matrix3Xd positions;
  MapMetrics m = strip_metrics(values, positions);
  m.per_triangle.folded.back() = 1;
  HeatmapOptions options;
  options.percentile = 0.5;
  const HeatmapResult h = make_heatmap(positions, m, options);
  EXPECT_DOUBLE_EQ(h.low, 4.0);          // perfect symmetric Dirichlet
  EXPECT_DOUBLE_EQ(h.high, values[10]);  // the median of the 21 unfolded values
  ASSERT_EQ(h.mesh.num_faces(), 22);
  EXPECT_TRUE(h.mesh.face_colors[0].isApprox(Eigen::Vector3f(0, 1, 0), kExact));
  EXPECT_TRUE(h.mesh.face_colors[20].isApprox(Eigen::Vector3f(1, 0, 0), kExact));
  EXPECT_TRUE(h.mesh.face_colors[21].isApprox(options.fold_color, kExact));
}

TEST(Heatmap, FixedRangeExcludedColourAndVertexAverages) {
  Eigen::Matrix3Xd positions;
  MapMetrics m = strip_metrics({4.0, 8.0, 6.0}, positions);
  m.per_triangle.excluded[2] = 1;
  HeatmapOptions options;
  options.low = 4.0;
  options.high = 8.0;
  const HeatmapResult h = make_heatmap(positions, m, options);
  EXPECT_TRUE(h.mesh.face_colors[2].isApprox(options.excluded_color, kExact));
  // Vertex 1 is in triangles 0 and 1 (values 4 and 8): the ramp colour of their mean 6, yellow
  // (a colour of the legend, not the olive (0.5, 0.5, 0) of averaged colours).
  EXPECT_TRUE(h.mesh.vertex_colors[1].isApprox(Eigen::Vector3f(1, 1, 0), kExact));
  // Vertex 0 is only in triangle 0; vertex 3 in triangle 1 and the excluded 2 (left out): red;
  // vertex 4 only in the excluded triangle.
  EXPECT_TRUE(h.mesh.vertex_colors[0].isApprox(Eigen::Vector3f(0, 1, 0), kExact));
  EXPECT_TRUE(h.mesh.vertex_colors[3].isApprox(Eigen::Vector3f(1, 0, 0), kExact));
  EXPECT_TRUE(h.mesh.vertex_colors[4].isApprox(options.excluded_color, kExact));
}

TEST(Heatmap, VerticesOfAFoldShowTheFoldColour) {
  Eigen::Matrix3Xd positions;
  MapMetrics m = strip_metrics({4.0, 4.0, 4.0}, positions);
  m.per_triangle.folded[1] = 1;
  const HeatmapResult h = make_heatmap(positions, m);
  for (const int p : {1, 2, 3}) {  // triangle 1's corners
    EXPECT_TRUE(h.mesh.vertex_colors[p].isApprox(HeatmapOptions().fold_color, kExact)) << p;
  }
  EXPECT_TRUE(h.mesh.vertex_colors[0].isApprox(Eigen::Vector3f(0, 1, 0), kExact));
}

TEST(Heatmap, SharedScaleIsTheWorstMapsAutomaticHigh) {
  Eigen::Matrix3Xd positions;
  const MapMetrics good = strip_metrics({4.0, 5.0, 6.0}, positions);
  const MapMetrics bad = strip_metrics({4.0, 10.0, 20.0}, positions);
  HeatmapOptions options;
  options.percentile = 1.0;  // the largest value: 6 and 20
  EXPECT_DOUBLE_EQ(heatmap_automatic_high(good, options), 6.0);
  const HeatmapOptions shared = shared_heatmap_scale({&good, &bad}, options);
  EXPECT_DOUBLE_EQ(*shared.low, 4.0);
  EXPECT_DOUBLE_EQ(*shared.high, 20.0);
  // On the shared scale the good map's worst triangle is green-yellow, not red.
  const HeatmapResult h = make_heatmap(positions, good, shared);
  EXPECT_DOUBLE_EQ(h.high, 20.0);
  EXPECT_FLOAT_EQ(h.mesh.face_colors[2].y(), 1.0f);
  EXPECT_FLOAT_EQ(h.mesh.face_colors[2].x(), 2.0f * 2.0f / 16.0f);
  EXPECT_THROW(shared_heatmap_scale({}), InvalidInputError);
}

TEST(Heatmap, PerfectMapIsAllGreenWithAWidenedRange) {
  Eigen::Matrix3Xd positions;
  const MapMetrics m = strip_metrics({4.0, 4.0, 4.0}, positions);
  const HeatmapResult h = make_heatmap(positions, m);
  EXPECT_GT(h.high, h.low);
  for (const auto& c : h.mesh.face_colors)
    EXPECT_TRUE(c.isApprox(Eigen::Vector3f(0, 1, 0), kExact));
}

TEST(Heatmap, WritesAndReadsBackAsPly) {
  Eigen::Matrix3Xd positions;
  const MapMetrics m = strip_metrics({4.0, 5.0, 6.0, 7.0}, positions);
  const HeatmapResult h = make_heatmap(positions, m);
  const auto path = test::scratch_dir("heatmap") / "heatmap.ply";
  write_mesh(path, h.mesh);
  const PolygonMesh back = read_mesh(path).mesh;
  ASSERT_EQ(back.num_faces(), h.mesh.num_faces());
  ASSERT_TRUE(back.has_face_colors());
  // PLY stores colours as bytes: 1/255 quantisation (half a step after rounding).
  for (int f = 0; f < back.num_faces(); ++f) {
    EXPECT_LE((back.face_colors[f] - h.mesh.face_colors[f]).cwiseAbs().maxCoeff(), 0.6f / 255.0f);
  }
}

TEST(Heatmap, RejectsBadOptions) {
  Eigen::Matrix3Xd positions;
  const MapMetrics m = strip_metrics({4.0, 5.0}, positions);
  HeatmapOptions options;
  options.percentile = 1.5;
  EXPECT_THROW(make_heatmap(positions, m, options), InvalidInputError);
  options = {};
  options.high = NAN;
  EXPECT_THROW(make_heatmap(positions, m, options), InvalidInputError);
  EXPECT_THROW(make_heatmap(Eigen::Matrix3Xd::Zero(3, 2), m), InvalidInputError);
}

}  // namespace
}  // namespace elastic
