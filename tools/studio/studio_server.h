#pragma once
// The HTTP side of `elastic studio` (docs/studio.md): a server on the loopback interface that
// serves the page (tools/studio/web and three.js, copied into the build) and a small JSON API over
// a StudioSession. It answers only requests addressed to itself (Host 127.0.0.1 or localhost with
// its port) from its own page (an Origin, when sent, must be the server's), serves no file outside
// its web folder, and lets the page load only files under its roots.

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace elastic::cli {

struct StudioOptions {
  std::string source;  ///< mesh or image to load on the source side at start (may be empty)
  std::string target;  ///< mesh to load on the target side at start (may be empty)
  int port = 8631;     ///< loopback port; 0: any free port
  std::filesystem::path web_dir;             ///< the page's files
  std::vector<std::filesystem::path> roots;  ///< folders whose files the page may load
  std::filesystem::path work_dir;            ///< where drawn polygons' points files go
  long frame_interval = 4;                   ///< every k-th relaxation frame goes to the page
  /// Told one line per refused or failed request ("POST /api/region: 422 elastic: ..."); empty:
  /// nobody listens.
  std::function<void(const std::string& line)> log;
};

/// Loads the start meshes, binds 127.0.0.1:port, calls `listening` with the page's URL, and serves
/// until the process is stopped. \throws IoError when the port cannot be bound; the start meshes'
/// errors as the CLI's.
void serve_studio(const StudioOptions& options,
                  const std::function<void(const std::string& url)>& listening);

}  // namespace elastic::cli
