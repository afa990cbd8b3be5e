// `--target-place` as a user meets it: a rectangle image placed on a curved closed mesh pastes
// fold-free with a report that says where it went; the job file repeats it; flags that belong to
// drawn regions are refused; a decal too large for a thin part is refused naming the flag and the
// SCALE that fits; `compare` measures the exponential-map decal beside it; `bench decals` judges
// each case against the exponential map.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_run.h"
#include "support.h"

namespace elastic {
namespace {

namespace fs = std::filesystem;
using test::run_elastic;

std::string mesh(const std::string& name) {
  return test::project_mesh(name).string();
}

TEST(DecalCli, ARectangleImagePlacedOnATorusPastesFoldFree) {
  const fs::path dir = test::scratch_dir("decal");
  const std::string emblem = (dir / "emblem.png").string();
  ASSERT_EQ(run_elastic("render --emblem " + emblem + " --size 64 --quiet", dir).code, 0);
  const std::string report = (dir / "report.json").string();
  const test::CliRun run = run_elastic(
      "paste --source-image " + emblem + " --image-width 0.3 --target " + mesh("torus_quads.obj") +
          " --target-place 1.31127,0,0,30,1.2 --particles 400 --out " + (dir / "out").string() +
          " --report " + report + " --quiet",
      dir);
  ASSERT_EQ(run.code, 0) << run.err;
  const nlohmann::json r = nlohmann::json::parse(std::ifstream(report));
  const nlohmann::json& map = r.contains("map") ? r["map"] : r;
  EXPECT_EQ(map["folds"], 0);
  EXPECT_TRUE(map["converged"].get<bool>());
  EXPECT_EQ(map["boundary"]["mode"], "free");
  const nlohmann::json& decal = map["decal"];
  EXPECT_EQ(decal["angle_deg"], 30.0);
  EXPECT_EQ(decal["scale"], 1.2);
  // The centre is the torus's outer equator point; the map keeps lengths, so the target region
  // is 1.2^2 times the 0.3 x 0.3 image within the distortion.
  EXPECT_NEAR(decal["centre"][0].get<double>(), 1.31127, 1e-4);
  EXPECT_NEAR(decal["target_area"].get<double>(), 0.09 * 1.44, 0.09 * 1.44 * 0.02);
  EXPECT_TRUE(fs::exists(dir / "out" / "painted.obj"));

  // The report is a job file: the same decal again, bit for bit.
  const std::string again = (dir / "again.json").string();
  ASSERT_EQ(run_elastic("paste --job " + report + " --out " + (dir / "again").string() +
                            " --report " + again + " --quiet",
                        dir)
                .code,
            0);
  const nlohmann::json r2 = nlohmann::json::parse(std::ifstream(again));
  const nlohmann::json& map2 = r2.contains("map") ? r2["map"] : r2;
  EXPECT_EQ(map2["energy"]["length"], map["energy"]["length"]);
}

TEST(DecalCli, RefusesWhatDoesNotApplyAndWhatCannotFit) {
  const fs::path dir = test::scratch_dir("decal_refuse");
  const std::string base = "map --source " + mesh("plane_quads.obj") +
                           " --source-region disk:0,0,0,0.5 --target " + mesh("torus_quads.obj") +
                           " --particles 300 ";
  const auto first_line = [](const std::string& text) { return text.substr(0, text.find('\n')); };
  // A drawn region and a placement at once; flags of a drawn target.
  for (const std::string& flags :
       {std::string("--target-place 1.31,0,0 --target-region disk:1.31,0,0,0.2"),
        std::string("--target-place 1.31,0,0 --rest-scale area"),
        std::string("--target-place 1.31,0,0 --boundary fixed"),
        std::string("--target-place 1,2")}) {
    const test::CliRun run = run_elastic(base + flags, dir);
    EXPECT_EQ(run.code, 64) << flags << ": " << run.err;
    EXPECT_NE(first_line(run.err).find("--"), std::string::npos) << run.err;
  }
  // Around the tube (circumference 2.2) a decal of radius 1.2 meets itself.
  const test::CliRun wrap = run_elastic(base + "--target-place 1.31127,0,0,0,2.4", dir);
  EXPECT_EQ(wrap.code, 65) << wrap.err;
  EXPECT_EQ(wrap.err.rfind("elastic: --target-place: the decal overlaps itself", 0), 0u)
      << wrap.err;
  EXPECT_NE(wrap.err.find("SCALE at most about"), std::string::npos) << wrap.err;
  EXPECT_EQ(test::count_lines(wrap.err), 1) << wrap.err;
}

TEST(DecalCli, CompareAndBenchMeasureTheExponentialMap) {
  const fs::path dir = test::scratch_dir("decal_compare");
  const test::CliRun run = run_elastic(
      "compare --source " + mesh("plane_quads.obj") + " --source-region disk:0,0,0,0.6 --target " +
          mesh("sphere_quads.obj") + " --target-place 0.3,0.5,0.8,10 --particles 400",
      dir);
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_NE(run.out.find("| expmap | ok |"), std::string::npos) << run.out;
  EXPECT_EQ(run.out.find("| lscm |"), std::string::npos) << run.out;

  const fs::path root = fs::path(ELASTIC_MESHES_DIR).parent_path();
  std::ofstream(dir / "cases.json") << R"({"particles": 300,
    "sources": [{"name": "disk", "source": "meshes/plane_quads.obj",
                 "source_region": "disk:0,0,0,0.5", "radius": 0.5}],
    "sizes": [{"name": "half", "fraction": 0.5}],
    "targets": [{"name": "sphere", "target": "meshes/sphere_quads.obj",
                 "point": [0.299733, 0.499558, 0.799286], "feature_size": 1.0},
                {"name": "nowhere", "target": "meshes/sphere_quads.obj",
                 "point": [0, 0, 9], "feature_size": 1.0}]})";
  const test::CliRun bench =
      run_elastic("bench decals -q --cases " + (dir / "cases.json").string() + " --root " +
                      root.string() + " --report " + (dir / "d.json").string(),
                  dir);
  ASSERT_EQ(bench.code, 0) << bench.err;
  const nlohmann::json report = nlohmann::json::parse(std::ifstream(dir / "d.json"));
  ASSERT_EQ(report["cases"].size(), 2u);
  const nlohmann::json& c = report["cases"][0];
  ASSERT_FALSE(c.contains("error")) << c.dump();
  const bool expected =
      c["exit"] == 0 && c["elastic"]["folds"] == 0 &&
      c["elastic"]["length_energy"].get<double>() < c["expmap"]["length_energy"].get<double>() &&
      c["elastic"]["symmetric_dirichlet"].get<double>() <
          c["expmap"]["symmetric_dirichlet"].get<double>();
  EXPECT_EQ(c["pass"].get<bool>(), expected) << c.dump();
  EXPECT_TRUE(c["pass"].get<bool>()) << c.dump();  // a half-radius disk on the sphere
  EXPECT_FALSE(report["cases"][1]["pass"].get<bool>());
  EXPECT_NE(report["cases"][1]["error"].get<std::string>().find("--target-place"),
            std::string::npos);
  EXPECT_NE(bench.out.find("of 2 cases pass"), std::string::npos) << bench.out;
}

}  // namespace
}  // namespace elastic
