// `elastic studio`: a local web page to pick both regions by clicking, run the map, watch it relax
// and save the job file that repeats it (docs/studio.md). The server is tools/studio.
#if __has_include(<malloc.h>)
#include <malloc.h>  // mallopt (glibc)
#endif

#include <filesystem>
#include <iostream>

#include "command.h"
#include "job_file.h"
#include "studio_server.h"

namespace elastic::cli {
namespace {

struct StudioArgs {
  StudioOptions options{};
  std::vector<std::string> roots;
  std::string web;
  std::string work_dir = "elastic-studio";
  bool quiet = false;
};

// The page's files: --web, else the build tree's copy, else the installed one beside the tool.
std::filesystem::path web_dir(const std::string& given) {
  if (!given.empty()) {
    return given;
  }
  std::filesystem::path build = ELASTIC_STUDIO_WEB_DIR;
  if (std::filesystem::exists(build / "index.html")) {
    return build;
  }
  std::error_code error;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", error);
  return exe.parent_path().parent_path() / "share" / "elastic" / "studio";
}

int run_studio(StudioArgs& args) {
  namespace fs = std::filesystem;
#ifdef M_ARENA_MAX
  // One malloc arena for the whole server. glibc gives every thread an arena of its own, and the
  // HTTP server answers each request on whichever of its pool threads is free: the first live
  // re-solves served by each pool thread then page-faulted their working memory in afresh (its
  // arena was cold). Measured on the live drag (spot -> bob, 2,000 particles, 2 cores): the
  // region cut took 0.085 s on the first 8 updates and 0.04 s afterwards, and a whole update
  // 0.157 s median; with one arena the cut takes 0.043 s from the first update and the update
  // 0.131 s. A tool linked with jemalloc ignores this and has one arena anyway
  // (tools/elastic/allocator.cpp, narenas:1).
  mallopt(M_ARENA_MAX, 1);
#endif
  StudioOptions options = args.options;
  options.web_dir = web_dir(args.web);
  // The page may load files under the current folder, the start meshes' folders and every --root.
  std::vector<std::string> roots = args.roots;
  roots.push_back(".");
  for (const std::string& mesh : {args.options.source, args.options.target}) {
    if (!mesh.empty()) {
      roots.push_back(fs::absolute(mesh).parent_path().string());
    }
  }
  for (const std::string& root : roots) {
    std::error_code error;
    const fs::path canonical = fs::canonical(root, error);
    if (error || !fs::is_directory(canonical)) {
      throw UsageError("--root: '" + root + "' is not a folder");
    }
    options.roots.push_back(canonical);
  }
  options.work_dir = fs::absolute(args.work_dir);
  if (!args.quiet) {
    options.log = [](const std::string& line) { std::cerr << "elastic studio: " << line << '\n'; };
  }
  serve_studio(options, [](const std::string& url) {
    std::cout << "elastic studio: open " << url << " (Ctrl-C stops the server)" << std::endl;
  });
  return kOk;
}

}  // namespace
}  // namespace elastic::cli

ELASTIC_COMMAND(
    "studio", "Pick regions by clicking, run and watch the map in a web page", [](CLI::App& sub) {
      auto a = std::make_shared<elastic::cli::StudioArgs>();
      sub.add_option("--source", a->options.source, "Mesh or image to load as the source");
      sub.add_option("--target", a->options.target, "Mesh to load as the target");
      sub.add_option("--port", a->options.port, "Port on 127.0.0.1 (0: any free port)")
          ->check(CLI::Range(0, 65535));
      sub.add_option("--root", a->roots,
                     "A folder whose files the page may load (repeatable; the current folder and "
                     "the start meshes' folders always)");
      sub.add_option("--work-dir", a->work_dir,
                     "Where the points files of drawn polygons are written");
      sub.add_option("--frame-interval", a->options.frame_interval,
                     "Send every k-th relaxation frame to the page")
          ->check(CLI::Range(1L, 1000L));
      sub.add_option("--web", a->web, "The page's folder (default: the build's or installed copy)");
      sub.add_flag("-q,--quiet", a->quiet, "Print only the URL, not the requests that fail");
      sub.footer(
          "Example:\n  elastic studio --source ../shared/meshes/spot.obj --target "
          "../shared/meshes/bob_tri.obj\nprints the URL of the page; open it in a browser.");
      return [a] { return elastic::cli::run_studio(*a); };
    });
