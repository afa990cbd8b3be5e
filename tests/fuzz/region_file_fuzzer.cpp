// libFuzzer target for the region specifications and their files (regions/region_spec.h): the
// input is read as a `points:` curve file, as a `uv:` polygon file, and (its first line) as a
// spec string given on the command line. Each must either parse or throw elastic::Error; a curve
// that parses holds only finite numbers, as many rows as the file has, and at least 3.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "elastic/core/error.h"
#include "elastic/regions/region_spec.h"
#include "fuzz_scratch.h"

namespace {

void parse(const std::string& text) {
  try {
    const elastic::RegionSpec spec = elastic::parse_region_spec(text, "--fuzz-region");
    for (const Eigen::Vector3d& p : spec.points) {
      if (!p.allFinite()) std::abort();
    }
    for (const Eigen::Vector2d& p : spec.uv_polygon) {
      if (!p.allFinite()) std::abort();
    }
    if (spec.kind == elastic::RegionSpec::Kind::Points && spec.points.size() < 3) std::abort();
    if (spec.kind == elastic::RegionSpec::Kind::UvPolygon && spec.uv_polygon.size() < 3) {
      std::abort();
    }
    if (spec.kind == elastic::RegionSpec::Kind::Disk &&
        !(spec.radius > 0.0 && std::isfinite(spec.radius) && spec.center.allFinite())) {
      std::abort();
    }
  } catch (const elastic::Error&) {
    // A refusal with a message: the expected outcome for most inputs.
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string file = elastic::fuzz::write_scratch_file(data, size, ".txt").string();
  parse("points:" + file);
  parse("uv:" + file + ";anchor=0,0,1");
  // The first line as a spec string (disk:..., anchors, unknown kinds), never naming a file.
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  const std::string line = bytes.substr(0, bytes.find('\n'));
  if (line.rfind("points:", 0) != 0 && line.rfind("uv:", 0) != 0) parse(line);
  return 0;
}
