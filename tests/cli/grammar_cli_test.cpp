// One CLI grammar (issue 15, item 4), through the real binary: the same flag names for the same
// things in every subcommand (old names kept as aliases), -q/--quiet everywhere, one exit code per
// kind of mistake (docs/cli.md), every error one "elastic: " line naming the flag or file, output
// formats from the extension, report keys named one way (docs/file-formats.md). Each test fails on
// the behaviour issue 15 measured.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_run.h"
#include "support.h"

namespace elastic {
namespace {

namespace fs = std::filesystem;
using test::CliRun;
using test::count_lines;
using test::count_of;

CliRun elastic(const std::string& args, const fs::path& dir) {
  return test::run_elastic(args, dir);
}

std::string mesh(const std::string& name) {
  return test::project_mesh(name).string();
}

/// A failed run: the exit code, exactly one stderr line, "elastic: " first, naming `names`.
void expect_one_line_error(const CliRun& run, int code, const std::string& names) {
  EXPECT_EQ(run.code, code) << run.err;
  EXPECT_EQ(count_lines(run.err), 1) << run.err;
  EXPECT_EQ(run.err.rfind("elastic: ", 0), 0u) << run.err;
  EXPECT_NE(run.err.find(names), std::string::npos) << "'" << names << "' not in: " << run.err;
  EXPECT_EQ(run.err.find("internal error"), std::string::npos) << run.err;
}

/// The subcommands `elastic --help` lists (and the nested ones of those that have them).
std::vector<std::string> subcommands(const fs::path& dir) {
  std::vector<std::string> names;
  const auto list = [&](const std::string& help) {
    std::vector<std::string> found;
    const size_t at = help.find("Subcommands:");
    if (at == std::string::npos) {
      return found;
    }
    std::istringstream lines(help.substr(at));
    std::string line;
    std::getline(lines, line);
    while (std::getline(lines, line)) {
      std::istringstream words(line);
      std::string word;
      if (words >> word) {
        found.push_back(word);
      }
    }
    return found;
  };
  for (const std::string& top : list(elastic("--help", dir).out)) {
    const std::vector<std::string> nested = list(elastic(top + " --help", dir).out);
    if (nested.empty()) {
      names.push_back(top);
    }
    for (const std::string& n : nested) {
      names.push_back(top);
      names.back().append(" ").append(n);
    }
  }
  return names;
}

TEST(Grammar, SampleNamesItsSourceLikeEveryOtherSubcommand) {
  const fs::path dir = test::scratch_dir("grammar_sample");
  const std::string rest = " --particles 100 -q --report ";
  const CliRun now =
      elastic("sample --source " + mesh("plane_quads.obj") + " --source-region disk:0,0,0,0.8" +
                  rest + (dir / "a.json").string(),
              dir);
  ASSERT_EQ(now.code, 0) << now.err;
  // The old names still work for one release, with the same result.
  const CliRun old = elastic("sample --mesh " + mesh("plane_quads.obj") +
                                 " --region disk:0,0,0,0.8" + rest + (dir / "b.json").string(),
                             dir);
  ASSERT_EQ(old.code, 0) << old.err;
  const nlohmann::json a = nlohmann::json::parse(std::ifstream(dir / "a.json"));
  const nlohmann::json b = nlohmann::json::parse(std::ifstream(dir / "b.json"));
  EXPECT_EQ(a["particles"], b["particles"]);
  // The job records the new names, so a report repeats the run with them.
  EXPECT_TRUE(a["job"].contains("source-region")) << a["job"].dump();
  EXPECT_FALSE(a["job"].contains("region")) << a["job"].dump();
  // A missing source names the new flag.
  expect_one_line_error(elastic("sample --source-region disk:0,0,0,0.8", dir), 64, "--source");
}

TEST(Grammar, EverySubcommandTakesQuiet) {
  const fs::path dir = test::scratch_dir("grammar_quiet");
  const std::vector<std::string> names = subcommands(dir);
  ASSERT_GE(names.size(), 10u);
  for (const std::string& name : names) {
    SCOPED_TRACE(name);
    const CliRun help = elastic(name + " --help", dir);
    EXPECT_NE(help.out.find("-q,--quiet"), std::string::npos) << help.out;
  }
  // And -q really quiets: the commands that print progress lines only print results.
  const CliRun shapes =
      elastic("shapes -q --out " + (dir / "shapes").string() + " --only plane", dir);
  EXPECT_EQ(shapes.code, 0) << shapes.err;
  EXPECT_TRUE(shapes.out.empty()) << shapes.out;
  EXPECT_TRUE(fs::exists(dir / "shapes" / "plane_quads.obj"));
  const CliRun render = elastic(
      "render -q " + mesh("plane_quads.obj") + " --size 32 --out " + (dir / "plane.png").string(),
      dir);
  EXPECT_EQ(render.code, 0) << render.err;
  EXPECT_TRUE(render.out.empty()) << render.out;
  EXPECT_EQ(elastic("info -q " + mesh("plane_quads.obj"), dir).code, 0);
  EXPECT_EQ(elastic("version -q", dir).code, 0);
}

TEST(Grammar, ResolutionsHaveOneNameEachAndTheOldOneStillWorks) {
  const fs::path dir = test::scratch_dir("grammar_resolution");
  // Three different things, three names.
  const std::string info = elastic("info --help", dir).out;
  const std::string shapes = elastic("shapes --help", dir).out;
  const std::string paste = elastic("paste --help", dir).out;
  EXPECT_NE(info.find("--tessellation"), std::string::npos) << info;
  EXPECT_NE(shapes.find("--segments"), std::string::npos) << shapes;
  EXPECT_NE(paste.find("--target-tessellation"), std::string::npos) << paste;
  EXPECT_EQ(elastic("info --tessellation 2 " + mesh("plane_quads.obj"), dir).code, 0);
  EXPECT_EQ(elastic("info --resolution 2 " + mesh("plane_quads.obj"), dir).code, 0);
  EXPECT_EQ(elastic("shapes -q --segments 8 --only plane --out " + (dir / "a").string(), dir).code,
            0);
  EXPECT_EQ(
      elastic("shapes -q --resolution 8 --only plane --out " + (dir / "b").string(), dir).code, 0);
  EXPECT_EQ(test::slurp(dir / "a" / "plane_quads.obj"), test::slurp(dir / "b" / "plane_quads.obj"));
  // info's JSON file is a --report like every other; --json FILE stays for one release.
  EXPECT_EQ(
      elastic("info -q " + mesh("plane_quads.obj") + " --report " + (dir / "r.json").string(), dir)
          .code,
      0);
  EXPECT_EQ(
      elastic("info -q " + mesh("plane_quads.obj") + " --json " + (dir / "j.json").string(), dir)
          .code,
      0);
  EXPECT_EQ(test::slurp(dir / "r.json"), test::slurp(dir / "j.json"));
  // It says how deep the limit surface was refined (a small mesh: everywhere the full depth).
  const nlohmann::json facts = nlohmann::json::parse(std::ifstream(dir / "r.json"));
  EXPECT_EQ(facts.at("limit_surface").at("isolation_level"), 6);
  EXPECT_EQ(facts.at("limit_surface").at("smooth_isolation_level"), 6);
  // A shape flag is not an info flag.
  EXPECT_EQ(elastic("info --segments 2 " + mesh("plane_quads.obj"), dir).code, 64);
}

TEST(Grammar, ParticlesOutOfRangeIsTheSameUsageErrorEverywhere) {
  const fs::path dir = test::scratch_dir("grammar_particles");
  const std::string source = " --source " + mesh("plane_quads.obj") +
                             " --source-region disk:0,0,0,0.8 --target " + mesh("cap_quads.obj");
  for (const char* count : {"0", "5000001"}) {
    SCOPED_TRACE(count);
    const std::string p = std::string(" --particles ") + count;
    expect_one_line_error(
        elastic("sample --source " + mesh("plane_quads.obj") + " --source-region boundary" + p,
                dir),
        64, "--particles");
    for (const char* command : {"map", "compare"}) {
      expect_one_line_error(elastic(std::string(command).append(source).append(p), dir), 64,
                            "--particles");
    }
    expect_one_line_error(
        elastic(std::string("paste").append(source).append(p).append(" --out ").append(
                    (dir / "out").string()),
                dir),
        64, "--particles");
  }
  // In a job file too.
  std::ofstream(dir / "job.json") << R"({"command": "map", "particles": 0})";
  expect_one_line_error(elastic("map" + source + " --job " + (dir / "job.json").string(), dir), 64,
                        "particles");
}

TEST(Grammar, ParseErrorsAreOneElasticLineNamingTheFlag) {
  const fs::path dir = test::scratch_dir("grammar_parse");
  expect_one_line_error(elastic("map --no-such-flag", dir), 64, "--no-such-flag");
  expect_one_line_error(elastic("sample --particles many", dir), 64, "--particles");
  expect_one_line_error(elastic("map --solver newton --target x.obj", dir), 64, "--solver");
  expect_one_line_error(elastic("info", dir), 64, "mesh");
  expect_one_line_error(elastic("no-such-subcommand", dir), 64, "no-such-subcommand");
  // Malformed flag values are usage errors too (64), whatever the flag.
  const std::string base =
      "map --source " + mesh("plane_quads.obj") + " --target " + mesh("cap_quads.obj");
  expect_one_line_error(elastic(base + " --source-anchor nan,0,0", dir), 64, "--source-anchor");
  expect_one_line_error(elastic(base + " --source-region disk:0,0", dir), 64, "--source-region");
  // A value that is well formed but does not fit the input is bad input (65).
  expect_one_line_error(elastic(base + " --source-region disk:0,0,50,0.5", dir), 65,
                        "--source-region");
}

TEST(Grammar, OutputFormatsComeFromTheExtensionOrAreRefused) {
  const fs::path dir = test::scratch_dir("grammar_formats");
  expect_one_line_error(
      elastic("render " + mesh("plane_quads.obj") + " --out " + (dir / "a.jpg").string(), dir), 64,
      "a.jpg");
  EXPECT_FALSE(fs::exists(dir / "a.jpg"));
  expect_one_line_error(elastic("render --emblem " + (dir / "e.bmp").string(), dir), 64, "e.bmp");
  EXPECT_FALSE(fs::exists(dir / "e.bmp"));
  expect_one_line_error(elastic("region " + mesh("plane_quads.obj") + " disk:0,0,0,0.5 --preview " +
                                    (dir / "p.gif").string(),
                                dir),
                        64, "p.gif");
  // Upper case is the same extension.
  EXPECT_EQ(elastic("render -q " + mesh("plane_quads.obj") + " --size 16 --out " +
                        (dir / "A.PNG").string(),
                    dir)
                .code,
            0);
  const std::string png = test::slurp(dir / "A.PNG");
  EXPECT_EQ(png.substr(1, 3), "PNG");
}

TEST(Grammar, VersionTakesAJobFileLikeEverySubcommand) {
  const fs::path dir = test::scratch_dir("grammar_version");
  std::ofstream(dir / "job.json") << R"({"command": "version"})";
  const CliRun run = elastic("version --job " + (dir / "job.json").string(), dir);
  EXPECT_EQ(run.code, 0) << run.err;
  EXPECT_EQ(run.out.rfind("elastic ", 0), 0u) << run.out;
  std::ofstream(dir / "other.json") << R"({"command": "map"})";
  expect_one_line_error(elastic("version --job " + (dir / "other.json").string(), dir), 64,
                        "other.json");
}

// The allocator the tool was linked with is the one serving malloc, and says so (allocator.h).
TEST(Grammar, VersionNamesTheAllocatorServingMalloc) {
  const fs::path dir = test::scratch_dir("grammar_allocator");
  const CliRun run = elastic("version", dir);
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_NE(run.out.find("kernel thp: "), std::string::npos) << run.out;
  if (ELASTIC_CLI_JEMALLOC) {
    EXPECT_NE(run.out.find("allocator: jemalloc "), std::string::npos) << run.out;
    EXPECT_NE(run.out.find("(thp:always)"), std::string::npos) << run.out;
  } else {
    EXPECT_NE(run.out.find("allocator: glibc malloc"), std::string::npos) << run.out;
  }
}

TEST(Grammar, ReportKeysAreNamedOneWayAndDocumented) {
  const fs::path dir = test::scratch_dir("grammar_keys");
  ASSERT_EQ(elastic("sample -q --source " + mesh("plane_quads.obj") +
                        " --source-region disk:0,0,0,0.8 --particles 150 --report " +
                        (dir / "sample.json").string(),
                    dir)
                .code,
            0);
  ASSERT_EQ(elastic("map -q --source " + mesh("plane_quads.obj") +
                        " --source-region disk:0,0,0,0.8 --target " + mesh("cap_quads.obj") +
                        " --particles 150 --report " + (dir / "map.json").string(),
                    dir)
                .code,
            0);
  const nlohmann::json sample = nlohmann::json::parse(std::ifstream(dir / "sample.json"));
  const nlohmann::json map = nlohmann::json::parse(std::ifstream(dir / "map.json"));
  const std::string formats =
      test::slurp(fs::path(ELASTIC_MESHES_DIR).parent_path() / "docs" / "file-formats.md");
  // The same quantity has the same key (and the same value: one grid, one seed) in both.
  for (const char* key :
       {"particles", "boundary_particles", "springs", "springs_normal", "springs_angular"}) {
    SCOPED_TRACE(key);
    ASSERT_TRUE(sample.contains(key)) << sample.dump();
    ASSERT_TRUE(map.contains(key));
    EXPECT_EQ(sample[key], map[key]);
    EXPECT_NE(formats.find(std::string("`") + key + "`"), std::string::npos);
  }
  for (const char* key : {"spacing_min", "spacing_median", "spacing_max", "density_ratio"}) {
    SCOPED_TRACE(key);
    ASSERT_TRUE(sample["sampling"].contains(key)) << sample.dump();
    EXPECT_EQ(sample["sampling"][key], map["sampling"][key]);
    EXPECT_NE(formats.find(std::string("`") + key + "`"), std::string::npos);
  }
  // The adaptive sampling's own verdict: under "adaptive" in sample, in "sampling" in map.
  for (const char* key : {"iterations", "converged", "stalled"}) {
    SCOPED_TRACE(key);
    ASSERT_TRUE(sample["adaptive"].contains(key)) << sample.dump();
    EXPECT_EQ(sample["adaptive"][key], map["sampling"][key]);
    EXPECT_NE(formats.find(std::string("`") + key + "`"), std::string::npos);
  }
  EXPECT_EQ(sample["adaptive"]["last_max_move"], map["sampling"]["last_move"]);
  EXPECT_FALSE(sample.contains("normal_springs"));
  EXPECT_FALSE(sample.contains("angular_springs"));
}

TEST(Grammar, OneLengthEnergyPerStdoutAndImageSourcesRecordTheirRegion) {
  const fs::path dir = test::scratch_dir("grammar_paste");
  const std::string emblem = (dir / "emblem.png").string();
  ASSERT_EQ(elastic("render -q --emblem " + emblem + " --size 64", dir).code, 0);
  const fs::path out = dir / "out";
  const CliRun run =
      elastic("paste --source-image " + emblem + " --target " + mesh("cap_quads.obj") +
                  " --target-region disk:0,0,1,0.5 --particles 150 "
                  "--min-vertices 500 --preview --preview-size 64 "
                  "--height luminance --out " +
                  out.string(),
              dir);
  ASSERT_EQ(run.code, 0) << run.err;
  EXPECT_EQ(count_of(run.out, "length energy"), 1) << run.out;
  // The job names the region the run used: the image's rectangle, not the mesh default.
  const nlohmann::json report = nlohmann::json::parse(std::ifstream(out / "report.json"));
  EXPECT_EQ(report["job"]["source-region"], "rectangle");
  // A height paste is previewed as shading of the displaced surface.
  EXPECT_TRUE(fs::exists(out / "preview_height.png"));
  // The report repeats the run.
  const CliRun again = elastic(
      "paste -q --job " + (out / "report.json").string() + " --out " + (dir / "again").string(),
      dir);
  EXPECT_EQ(again.code, 0) << again.err;
}

TEST(Grammar, ImageErrorsGiveAReason) {
  const fs::path dir = test::scratch_dir("grammar_images");
  std::ofstream(dir / "empty.png").close();
  std::ofstream(dir / "text.png") << "not an image\n";
  for (const char* name : {"empty.png", "text.png"}) {
    SCOPED_TRACE(name);
    const CliRun run = elastic(
        "map --source-image " + (dir / name).string() + " --target " + mesh("cap_quads.obj"), dir);
    expect_one_line_error(run, 65, name);
    EXPECT_EQ(run.err.find("()"), std::string::npos) << run.err;
  }
}

TEST(Grammar, EveryFailingSubcommandPrintsExactlyOneStderrLine) {
  const fs::path dir = test::scratch_dir("grammar_one_line");
  const std::string missing = (dir / "missing.obj").string();
  const std::string plane = mesh("plane_quads.obj"), cap = mesh("cap_quads.obj");
  const std::vector<std::pair<std::string, int>> runs = {
      {"info " + missing, 66},
      {"locate " + plane, 64},
      {"locate " + plane + " 1,2", 64},
      {"region " + plane + " disk:0,0,9,0.5", 65},
      {"sample --source " + missing + " --source-region boundary", 66},
      {"map --source " + plane + " --target " + missing, 66},
      {"paste --source " + plane + " --source-region disk:0,0,0,0.5 --target " + cap, 64},
      {"compare --source " + plane + " --target " + cap + " --baselines nope", 64},
      {"render " + missing + " --out " + (dir / "x.png").string(), 66},
      {"shapes --only teapot", 64},
      {"bench table1 --no-such-flag", 64},
      {"bench robustness --cases " + missing, 66},
      {"version --no-such-flag", 64},
      // A map that fails its verdict (one solver iteration): exit 70, one line.
      {"map --source " + plane + " --source-region disk:0,0,0,0.8 --target " + cap +
           " --particles 150 --max-iterations 1",
       70},
  };
  for (const auto& [args, code] : runs) {
    SCOPED_TRACE(args);
    const CliRun run = elastic(args, dir);
    EXPECT_EQ(run.code, code) << run.err;
    EXPECT_EQ(count_lines(run.err), 1) << run.err;
    EXPECT_EQ(run.err.rfind("elastic: ", 0), 0u) << run.err;
  }
}

}  // namespace
}  // namespace elastic
