// Stanford PLY: ascii, binary_little_endian and binary_big_endian; any element and property layout
// (what is not used is skipped by its declared type), vertex x y z / colours / normals / texture
// coordinates, faces as a `vertex_indices` or `vertex_index` list, optionally with a per-corner
// `texcoord` list.

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <unordered_map>

#include "elastic/mesh/detail/io_common.h"

namespace elastic::detail {

namespace {

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

bool parse_type(std::string_view name, PlyType& type) {
  static const std::pair<std::string_view, PlyType> names[] = {
      {"char", PlyType::Int8},      {"int8", PlyType::Int8},       {"uchar", PlyType::UInt8},
      {"uint8", PlyType::UInt8},    {"short", PlyType::Int16},     {"int16", PlyType::Int16},
      {"ushort", PlyType::UInt16},  {"uint16", PlyType::UInt16},   {"int", PlyType::Int32},
      {"int32", PlyType::Int32},    {"uint", PlyType::UInt32},     {"uint32", PlyType::UInt32},
      {"float", PlyType::Float32},  {"float32", PlyType::Float32}, {"double", PlyType::Float64},
      {"float64", PlyType::Float64}};
  for (const auto& [n, t] : names) {
    if (n == name) {
      type = t;
      return true;
    }
  }
  return false;
}

size_t type_size(PlyType type) {
  switch (type) {
    case PlyType::Int8:
    case PlyType::UInt8:
      return 1;
    case PlyType::Int16:
    case PlyType::UInt16:
      return 2;
    case PlyType::Int32:
    case PlyType::UInt32:
    case PlyType::Float32:
      return 4;
    case PlyType::Float64:
      return 8;
  }
  return 0;
}

bool is_float_type(PlyType type) {
  return type == PlyType::Float32 || type == PlyType::Float64;
}

/// Full-scale value of an integer colour channel of this type (colours in [0, max] map to [0, 1]).
double color_scale(PlyType type) {
  switch (type) {
    case PlyType::UInt16:
    case PlyType::Int16:
      return 1.0 / 65535.0;
    case PlyType::Float32:
    case PlyType::Float64:
      return 1.0;
    default:
      return 1.0 / 255.0;
  }
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::Float32;
  bool is_list = false;
  PlyType count_type = PlyType::UInt8;
};

struct PlyElement {
  std::string name;
  long long count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyEncoding { Ascii, BinaryLittle, BinaryBig };

/// The name of a type as the header writes it (for messages).
const char* type_name(PlyType type) {
  switch (type) {
    case PlyType::Int8:
      return "char";
    case PlyType::UInt8:
      return "uchar";
    case PlyType::Int16:
      return "short";
    case PlyType::UInt16:
      return "ushort";
    case PlyType::Int32:
      return "int";
    case PlyType::UInt32:
      return "uint";
    case PlyType::Float32:
      return "float";
    case PlyType::Float64:
      return "double";
  }
  return "?";
}

/// The range of values a type holds; an ASCII value outside it is refused, so that an ASCII file
/// holds nothing its binary twin could not (and no value is later converted out of range).
void type_range(PlyType type, double& lo, double& hi) {
  switch (type) {
    case PlyType::Int8:
      lo = -128.0, hi = 127.0;
      return;
    case PlyType::UInt8:
      lo = 0.0, hi = 255.0;
      return;
    case PlyType::Int16:
      lo = -32768.0, hi = 32767.0;
      return;
    case PlyType::UInt16:
      lo = 0.0, hi = 65535.0;
      return;
    case PlyType::Int32:
      lo = -2147483648.0, hi = 2147483647.0;
      return;
    case PlyType::UInt32:
      lo = 0.0, hi = 4294967295.0;
      return;
    case PlyType::Float32:
      lo = -static_cast<double>(std::numeric_limits<float>::max());
      hi = static_cast<double>(std::numeric_limits<float>::max());
      return;
    case PlyType::Float64:
      lo = -std::numeric_limits<double>::max();
      hi = std::numeric_limits<double>::max();
      return;
  }
}

/// Fewest bytes one row of `element` occupies: in binary, its scalars and list counts (a list may
/// be empty); in ASCII, one token and one separator per property. Zero for an element without
/// properties, whose rows hold nothing in either encoding.
size_t min_row_bytes(const PlyElement& element, PlyEncoding encoding) {
  size_t bytes = 0;
  for (const PlyProperty& property : element.properties) {
    if (encoding == PlyEncoding::Ascii) {
      bytes += 2;
    } else {
      bytes += type_size(property.is_list ? property.count_type : property.type);
    }
  }
  return bytes;
}

/// Reads the values of the data section one at a time, in any of the three encodings, reporting
/// errors with the element and row they occurred in. Every value is checked against its declared
/// type; integers (list lengths, indices) are checked to be whole numbers before any conversion.
class PlyData {
 public:
  PlyData(std::string_view data, PlyEncoding encoding, const std::filesystem::path& path,
          int first_line)
      : data_(data), encoding_(encoding), path_(path), line_(first_line) {}

  void locate(const std::string& element, long long row, long long rows) {
    element_ = &element;
    row_ = row;
    rows_ = rows;
  }

  /// Bytes not read yet.
  size_t remaining() const { return data_.size() - pos_; }

  /// Refuses an element whose declared rows cannot fit in the bytes that remain (so a count in the
  /// header never costs more time or memory than the file's size).
  void check_element_fits(const PlyElement& element) const {
    const size_t row_bytes = min_row_bytes(element, encoding_);
    if (row_bytes == 0) {
      return;
    }
    // In ASCII the last token of the file needs no separator after it.
    const size_t available = remaining() + (encoding_ == PlyEncoding::Ascii ? 1 : 0);
    if (static_cast<unsigned long long>(element.count) > available / row_bytes) {
      throw InvalidInputError(path_.string(),
                              "truncated file: element '" + element.name + "' declares " +
                                  std::to_string(element.count) + " rows of at least " +
                                  std::to_string(row_bytes) + " bytes, but only " +
                                  std::to_string(remaining()) + " bytes of data remain");
    }
  }

  /// A value of the declared type (as a double, which holds every PLY type exactly).
  double read(PlyType type) {
    if (encoding_ == PlyEncoding::Ascii) {
      return read_ascii(type);
    }
    const size_t size = type_size(type);
    if (pos_ + size > data_.size()) {
      fail("truncated file: the binary data ends in " + where());
    }
    unsigned char bytes[8];
    std::memcpy(bytes, data_.data() + pos_, size);
    pos_ += size;
    const bool swap =
        (encoding_ == PlyEncoding::BinaryBig) != (std::endian::native == std::endian::big);
    if (swap) {
      std::reverse(bytes, bytes + size);
    }
    switch (type) {
      case PlyType::Int8:
        return static_cast<double>(static_cast<signed char>(bytes[0]));
      case PlyType::UInt8:
        return static_cast<double>(bytes[0]);
      case PlyType::Int16:
        return static_cast<double>(as<std::int16_t>(bytes));
      case PlyType::UInt16:
        return static_cast<double>(as<std::uint16_t>(bytes));
      case PlyType::Int32:
        return static_cast<double>(as<std::int32_t>(bytes));
      case PlyType::UInt32:
        return static_cast<double>(as<std::uint32_t>(bytes));
      case PlyType::Float32:
        return static_cast<double>(as<float>(bytes));
      case PlyType::Float64:
        return as<double>(bytes);
    }
    return 0.0;
  }

  /// A value that must be a whole number (a list length or an index, possibly stored in a float
  /// type): NaN, infinities and fractions are refused before the conversion to an integer.
  long long read_integer(PlyType type, const std::string& what) {
    const double value = read(type);
    // 2^62 is far beyond any count a file can back and well inside long long.
    if (!std::isfinite(value) || value != std::floor(value) || std::fabs(value) > 0x1p62) {
      fail(what + " in " + where() + " is " + number_text(value) + ", not a whole number");
    }
    return static_cast<long long>(value);
  }

  /// A list length: whole, not negative, and no more items than the remaining bytes can hold.
  long long read_list_length(const PlyProperty& property) {
    const long long n =
        read_integer(property.count_type, "the length of list '" + property.name + "'");
    if (n < 0) {
      fail("negative length " + std::to_string(n) + " of list '" + property.name + "' in " +
           where());
    }
    const unsigned long long item_bytes =
        encoding_ == PlyEncoding::Ascii ? 2 : type_size(property.type);
    const size_t available = remaining() + (encoding_ == PlyEncoding::Ascii ? 1 : 0);
    if (static_cast<unsigned long long>(n) > available / item_bytes) {
      fail("truncated file: list '" + property.name + "' in " + where() + " has " +
           std::to_string(n) + " items, more than the remaining " + std::to_string(remaining()) +
           " bytes hold");
    }
    return n;
  }

  /// "element 'face' row 3 of 10" (1-based row).
  std::string where() const {
    return "element '" + *element_ + "' row " + std::to_string(row_ + 1) + " of " +
           std::to_string(rows_);
  }

  [[noreturn]] void fail(const std::string& problem) const {
    if (encoding_ == PlyEncoding::Ascii) {
      throw InvalidInputError(path_.string(), "line " + std::to_string(line_) + ": " + problem);
    }
    throw InvalidInputError(path_.string(), problem);
  }

 private:
  template <class T>
  static T as(const unsigned char* bytes) {
    T value;
    std::memcpy(&value, bytes, sizeof(T));
    return value;
  }

  static std::string number_text(double value) {
    std::string text;
    append_number(text, value);
    return text;
  }

  double read_ascii(PlyType type) {
    while (pos_ < data_.size() && (is_space(data_[pos_]) || data_[pos_] == '\n')) {
      if (data_[pos_] == '\n') {
        ++line_;
      }
      ++pos_;
    }
    if (pos_ >= data_.size()) {
      fail("truncated file: it ends in " + where());
    }
    size_t end = pos_;
    while (end < data_.size() && !is_space(data_[end]) && data_[end] != '\n') {
      ++end;
    }
    const std::string_view token = data_.substr(pos_, end - pos_);
    pos_ = end;
    double value = 0.0;
    if (!parse_double(token, value)) {
      fail("cannot parse number '" + std::string(token) + "'");
    }
    double lo = 0.0;
    double hi = 0.0;
    type_range(type, lo, hi);
    if (is_float_type(type)) {
      // NaN and infinities are values of a float type; the caller decides whether to keep them.
      if (std::isfinite(value) && (value < lo || value > hi)) {
        fail("value " + std::string(token) + " in " + where() + " is beyond the range of " +
             type_name(type));
      }
    } else if (!(value >= lo && value <= hi) || value != std::floor(value)) {
      fail("value " + std::string(token) + " in " + where() +
           " is not a whole number in the range of " + type_name(type) + " [" + number_text(lo) +
           ", " + number_text(hi) + "]");
    }
    return value;
  }

  std::string_view data_;
  PlyEncoding encoding_;
  const std::filesystem::path& path_;
  size_t pos_ = 0;
  int line_;
  const std::string* element_ = nullptr;
  long long row_ = 0;
  long long rows_ = 0;
};

/// Roles of vertex properties the mesh keeps.
enum VertexRole { kX, kY, kZ, kNx, kNy, kNz, kRed, kGreen, kBlue, kU, kV, kNumRoles, kSkip };

int vertex_role(std::string_view name) {
  static const std::pair<std::string_view, int> roles[] = {{"x", kX},
                                                           {"y", kY},
                                                           {"z", kZ},
                                                           {"nx", kNx},
                                                           {"ny", kNy},
                                                           {"nz", kNz},
                                                           {"red", kRed},
                                                           {"green", kGreen},
                                                           {"blue", kBlue},
                                                           {"diffuse_red", kRed},
                                                           {"diffuse_green", kGreen},
                                                           {"diffuse_blue", kBlue},
                                                           {"u", kU},
                                                           {"v", kV},
                                                           {"s", kU},
                                                           {"t", kV},
                                                           {"texture_u", kU},
                                                           {"texture_v", kV},
                                                           {"texture_s", kU},
                                                           {"texture_t", kV}};
  for (const auto& [n, r] : roles) {
    if (n == name) {
      return r;
    }
  }
  return kSkip;
}

}  // namespace

MeshReadResult read_ply(const std::string& text, const std::filesystem::path& path) {
  MeshReadResult result;
  PolygonMesh& mesh = result.mesh;
  LineScanner scanner(text, path);
  std::string_view line;
  if (!scanner.next(line) || trim(line) != "ply") {
    scanner.fail("not a PLY file (no 'ply' magic)");
  }

  PlyEncoding encoding = PlyEncoding::Ascii;
  bool have_format = false;
  bool ended = false;
  std::vector<PlyElement> elements;
  while (scanner.next(line)) {
    std::string_view rest = line;
    const std::string_view keyword = next_token(rest);
    if (keyword.empty() || keyword == "comment" || keyword == "obj_info") {
      continue;
    }
    if (keyword == "end_header") {
      ended = true;
      break;
    }
    if (keyword == "format") {
      const std::string_view name = next_token(rest);
      if (name == "ascii") {
        encoding = PlyEncoding::Ascii;
      } else if (name == "binary_little_endian") {
        encoding = PlyEncoding::BinaryLittle;
      } else if (name == "binary_big_endian") {
        encoding = PlyEncoding::BinaryBig;
      } else {
        scanner.fail("unknown PLY format '" + std::string(name) + "'");
      }
      have_format = true;
    } else if (keyword == "element") {
      PlyElement element;
      element.name = std::string(next_token(rest));
      element.count = expect_int(rest, scanner, "element count");
      if (element.name.empty() || element.count < 0) {
        scanner.fail("invalid element declaration");
      }
      elements.push_back(std::move(element));
    } else if (keyword == "property") {
      if (elements.empty()) {
        scanner.fail("property before any element");
      }
      PlyProperty property;
      std::string_view type = next_token(rest);
      if (type == "list") {
        property.is_list = true;
        if (!parse_type(next_token(rest), property.count_type) ||
            is_float_type(property.count_type)) {
          scanner.fail("invalid list count type");
        }
        type = next_token(rest);
      }
      if (!parse_type(type, property.type)) {
        scanner.fail("unknown property type '" + std::string(type) + "'");
      }
      property.name = std::string(next_token(rest));
      if (property.name.empty()) {
        scanner.fail("property without a name");
      }
      elements.back().properties.push_back(std::move(property));
    } else {
      scanner.fail("unknown header keyword '" + std::string(keyword) + "'");
    }
  }
  if (!ended) {
    throw InvalidInputError(path.string(), "truncated file: no end_header");
  }
  if (!have_format) {
    throw InvalidInputError(path.string(), "no format line in the PLY header");
  }

  PlyData data(std::string_view(text).substr(scanner.position()), encoding, path,
               scanner.line_number() + 1);
  constexpr long long kMaxInt = std::numeric_limits<int>::max();
  bool seen_vertices = false;
  bool have_uv = false;
  bool have_normal = false;
  bool have_color = false;
  bool have_corner_uv = false;
  std::vector<int> corner_uv;
  long long num_vertices = 0;
  // A colour channel as the mesh stores it (float): finite, or the file is refused.
  auto color_channel = [&](double value, double scale, long long row, const char* what) {
    const double c = value * scale;
    if (!(std::fabs(c) <= static_cast<double>(std::numeric_limits<float>::max()))) {
      data.fail(std::string(what) + " " + std::to_string(row) + " has a colour beyond float range");
    }
    return static_cast<float>(c);
  };
  for (const PlyElement& element : elements) {
    if (min_row_bytes(element, encoding) == 0) {
      // Rows without properties hold no bytes in either encoding: nothing to read or skip, however
      // many the header declares.
      if (element.count > 0) {
        result.warnings.push_back(path.string() + ": element '" + element.name + "' has " +
                                  std::to_string(element.count) +
                                  " rows but no properties; skipped");
      }
      if (element.name == "vertex" && !seen_vertices && element.count > 0) {
        throw InvalidInputError(path.string(), "the vertex element has no x, y and z properties");
      }
      continue;
    }
    data.check_element_fits(element);
    if (element.name == "vertex" && !seen_vertices) {
      seen_vertices = true;
      if (element.count > kMaxInt) {
        throw InvalidInputError(path.string(), std::to_string(element.count) +
                                                   " vertices: more than the library indexes (" +
                                                   std::to_string(kMaxInt) + ")");
      }
      num_vertices = element.count;
      std::vector<int> role(element.properties.size());
      bool has_role[kNumRoles] = {};
      double scale[kNumRoles];
      std::fill(std::begin(scale), std::end(scale), 1.0);
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        role[p] = property.is_list ? kSkip : vertex_role(property.name);
        if (role[p] != kSkip) {
          has_role[role[p]] = true;
          if (role[p] >= kRed && role[p] <= kBlue) {
            scale[role[p]] = color_scale(property.type);
          }
        }
      }
      if (!has_role[kX] || !has_role[kY] || !has_role[kZ]) {
        throw InvalidInputError(path.string(), "the vertex element has no x, y and z properties");
      }
      have_normal = has_role[kNx] && has_role[kNy] && has_role[kNz];
      have_color = has_role[kRed] && has_role[kGreen] && has_role[kBlue];
      have_uv = has_role[kU] && has_role[kV];
      // check_element_fits bounded the count by the file's size.
      mesh.positions.reserve(static_cast<size_t>(element.count));
      double values[kNumRoles];
      for (long long row = 0; row < element.count; ++row) {
        data.locate(element.name, row, element.count);
        std::fill(std::begin(values), std::end(values), 0.0);
        for (size_t p = 0; p < element.properties.size(); ++p) {
          const PlyProperty& property = element.properties[p];
          if (property.is_list) {
            const long long n = data.read_list_length(property);
            for (long long k = 0; k < n; ++k) {
              data.read(property.type);
            }
            continue;
          }
          const double value = data.read(property.type);
          if (role[p] != kSkip) {
            values[role[p]] = value;
          }
        }
        const Eigen::Vector3d position(values[kX], values[kY], values[kZ]);
        if (!position.allFinite()) {
          data.fail("vertex " + std::to_string(row) + " has a NaN or infinite coordinate");
        }
        mesh.positions.push_back(position);
        if (have_normal) {
          const Eigen::Vector3d normal(values[kNx], values[kNy], values[kNz]);
          if (!normal.allFinite()) {
            data.fail("vertex " + std::to_string(row) + " has a NaN or infinite normal");
          }
          mesh.normals.push_back(normal);
        }
        if (have_color) {
          mesh.vertex_colors.emplace_back(
              color_channel(values[kRed], scale[kRed], row, "vertex"),
              color_channel(values[kGreen], scale[kGreen], row, "vertex"),
              color_channel(values[kBlue], scale[kBlue], row, "vertex"));
        }
        if (have_uv) {
          const Eigen::Vector2d uv(values[kU], values[kV]);
          if (!uv.allFinite()) {
            data.fail("vertex " + std::to_string(row) +
                      " has a NaN or infinite texture coordinate");
          }
          mesh.texcoords.push_back(uv);
        }
      }
    } else if (element.name == "face" && mesh.face_offsets.empty()) {
      if (element.count > kMaxInt) {
        throw InvalidInputError(path.string(), std::to_string(element.count) +
                                                   " faces: more than the library indexes (" +
                                                   std::to_string(kMaxInt) + ")");
      }
      int indices_property = -1;
      int texcoord_property = -1;
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        if (!property.is_list) {
          continue;
        }
        if (indices_property < 0 &&
            (property.name == "vertex_indices" || property.name == "vertex_index")) {
          indices_property = static_cast<int>(p);
        } else if (property.name == "texcoord") {
          texcoord_property = static_cast<int>(p);
        }
      }
      if (indices_property < 0) {
        throw InvalidInputError(path.string(),
                                "the face element has no vertex_indices / vertex_index list");
      }
      have_corner_uv = texcoord_property >= 0;
      mesh.face_offsets.reserve(static_cast<size_t>(element.count) + 1);
      mesh.face_offsets.push_back(0);
      // Optional per-face colour (red green blue scalars on the face element).
      std::array<int, 3> face_color_property{-1, -1, -1};
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const PlyProperty& property = element.properties[p];
        if (property.is_list) {
          continue;
        }
        if (property.name == "red") {
          face_color_property[0] = static_cast<int>(p);
        }
        if (property.name == "green") {
          face_color_property[1] = static_cast<int>(p);
        }
        if (property.name == "blue") {
          face_color_property[2] = static_cast<int>(p);
        }
      }
      const bool have_face_color =
          face_color_property[0] >= 0 && face_color_property[1] >= 0 && face_color_property[2] >= 0;
      std::vector<double> uv_values;
      for (long long row = 0; row < element.count; ++row) {
        data.locate(element.name, row, element.count);
        long long corners = 0;
        Eigen::Vector3f face_color = Eigen::Vector3f::Zero();
        for (size_t p = 0; p < element.properties.size(); ++p) {
          const PlyProperty& property = element.properties[p];
          if (!property.is_list) {
            const double value = data.read(property.type);
            for (int k = 0; k < 3; ++k) {
              if (face_color_property[static_cast<size_t>(k)] == static_cast<int>(p)) {
                face_color[k] = color_channel(value, color_scale(property.type), row, "face");
              }
            }
            continue;
          }
          const long long n = data.read_list_length(property);
          if (static_cast<int>(p) == indices_property) {
            corners = n;
            if (n < 3) {
              data.fail("face " + std::to_string(row) + " has " + std::to_string(n) +
                        " corners (at least 3)");
            }
            for (long long k = 0; k < n; ++k) {
              const long long i = data.read_integer(property.type, "a vertex index");
              if (i < 0 || i >= num_vertices || !seen_vertices) {
                data.fail("face " + std::to_string(row) + ": vertex index " + std::to_string(i) +
                          " out of range (" + std::to_string(num_vertices) + " vertices)");
              }
              mesh.face_vertices.push_back(static_cast<int>(i));
            }
            if (mesh.face_vertices.size() > static_cast<size_t>(kMaxInt)) {
              data.fail("more face corners than the library indexes");
            }
          } else if (static_cast<int>(p) == texcoord_property) {
            uv_values.clear();
            for (long long k = 0; k < n; ++k) {
              const double value = data.read(property.type);
              if (!std::isfinite(value)) {
                data.fail("face " + std::to_string(row) +
                          " has a NaN or infinite texture coordinate");
              }
              uv_values.push_back(value);
            }
          } else {
            for (long long k = 0; k < n; ++k) {
              data.read(property.type);
            }
          }
        }
        if (have_corner_uv) {
          // MeshLab's per-corner texture coordinates: u v for every corner, in corner order.
          if (uv_values.size() != static_cast<size_t>(2 * corners)) {
            data.fail("face " + std::to_string(row) +
                      ": texcoord list does not have 2 values per corner");
          }
          for (long long k = 0; k < corners; ++k) {
            corner_uv.push_back(static_cast<int>(corner_uv.size()));
          }
          for (size_t k = 0; k + 1 < uv_values.size(); k += 2) {
            result.mesh.texcoords.emplace_back(uv_values[k], uv_values[k + 1]);
          }
        }
        if (have_face_color) {
          mesh.face_colors.push_back(face_color);
        }
        mesh.face_offsets.push_back(static_cast<int>(mesh.face_vertices.size()));
      }
      if (mesh.face_offsets.size() == 1) {
        mesh.face_offsets.clear();
      }
    } else {
      // Skip other elements (edges, materials, a second vertex element...) by their declared
      // types. check_element_fits bounded the rows by the file's size, and every row reads at
      // least one byte, so skipping costs time in proportion to the file.
      for (long long row = 0; row < element.count; ++row) {
        data.locate(element.name, row, element.count);
        for (const PlyProperty& property : element.properties) {
          const long long n = property.is_list ? data.read_list_length(property) : 1;
          for (long long k = 0; k < n; ++k) {
            data.read(property.type);
          }
        }
      }
    }
  }
  if (have_corner_uv) {
    // Per-corner texcoords replace per-vertex ones (which were appended to the same pool first).
    if (have_uv) {
      const auto per_vertex = static_cast<std::ptrdiff_t>(mesh.positions.size());
      mesh.texcoords.erase(mesh.texcoords.begin(), mesh.texcoords.begin() + per_vertex);
    }
    mesh.corner_texcoords = std::move(corner_uv);
  } else if (have_uv) {
    mesh.corner_texcoords = mesh.face_vertices;
  }
  if (have_normal) {
    mesh.corner_normals = mesh.face_vertices;
  }
  return result;
}

namespace {

/// The per-vertex values of a per-corner attribute, when every corner of a vertex has the same
/// value.
template <class T>
bool per_vertex_values(const PolygonMesh& mesh, const std::vector<T>& pool,
                       const std::vector<int>& corners, std::vector<T>& out) {
  out.assign(mesh.positions.size(), T::Zero());
  std::vector<char> set(mesh.positions.size(), 0);
  for (size_t c = 0; c < corners.size(); ++c) {
    const auto v = static_cast<size_t>(mesh.face_vertices[c]);
    const T& value = pool[static_cast<size_t>(corners[c])];
    if (!set[v]) {
      set[v] = 1;
      out[v] = value;
    } else if (out[v] != value) {
      return false;
    }
  }
  return true;
}

/// Output in either encoding: numbers as text separated by spaces, or little-endian binary.
class PlyWriter {
 public:
  explicit PlyWriter(bool binary) : binary_(binary) {}
  void real(double value) {
    if (binary_) {
      raw(value);
    } else {
      separate();
      append_number(out, value);
    }
  }
  void integer(int value) {
    if (binary_) {
      raw(static_cast<std::int32_t>(value));
    } else {
      separate();
      append_number(out, value);
    }
  }
  void byte(int value) {
    if (binary_) {
      out += static_cast<char>(static_cast<unsigned char>(value));
    } else {
      separate();
      append_number(out, value);
    }
  }
  void end_row() {
    if (!binary_) {
      out += '\n';
    }
    first_ = true;
  }
  std::string out;

 private:
  template <class T>
  void raw(T value) {
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    if constexpr (std::endian::native == std::endian::big) {
      std::reverse(bytes, bytes + sizeof(T));
    }
    out.append(bytes, sizeof(T));
  }
  void separate() {
    if (!first_) {
      out += ' ';
    }
    first_ = false;
  }
  bool binary_;
  bool first_ = true;
};

}  // namespace

std::string write_ply(const PolygonMesh& mesh, const MeshWriteOptions& options) {
  std::vector<Eigen::Vector3d> vertex_normals;
  std::vector<Eigen::Vector2d> vertex_uvs;
  const bool normals = options.normals && mesh.has_normals() &&
                       per_vertex_values(mesh, mesh.normals, mesh.corner_normals, vertex_normals);
  const bool uv = options.texcoords && mesh.has_texcoords();
  const bool vertex_uv =
      uv && per_vertex_values(mesh, mesh.texcoords, mesh.corner_texcoords, vertex_uvs);
  const bool corner_uv = uv && !vertex_uv;
  const bool colors = options.vertex_colors && mesh.has_vertex_colors();
  const bool face_colors = options.face_colors && mesh.has_face_colors() &&
                           mesh.face_colors.size() == static_cast<size_t>(mesh.num_faces());
  int max_face = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    max_face = std::max(max_face, mesh.face_size(f));
  }
  // List lengths are uchar when they fit, as most readers expect.
  const bool byte_counts = max_face <= 127;

  PlyWriter w(options.binary);
  std::string& out = w.out;
  out = "ply\nformat ";
  out += options.binary ? "binary_little_endian 1.0\n" : "ascii 1.0\n";
  out +=
      "comment written by libelastic\nelement vertex " + std::to_string(mesh.num_vertices()) + "\n";
  out += "property double x\nproperty double y\nproperty double z\n";
  if (normals) {
    out += "property double nx\nproperty double ny\nproperty double nz\n";
  }
  if (colors) {
    out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  }
  if (vertex_uv) {
    out += "property double u\nproperty double v\n";
  }
  out += "element face " + std::to_string(mesh.num_faces()) + "\n";
  const char* count_type = byte_counts ? "uchar" : "int";
  out += std::string("property list ") + count_type + " int vertex_indices\n";
  if (corner_uv) {
    out += std::string("property list ") + count_type + " double texcoord\n";
  }
  if (face_colors) {
    out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  }
  out += "end_header\n";
  auto count = [&](int n) {
    if (byte_counts) {
      w.byte(n);
    } else {
      w.integer(n);
    }
  };
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    for (int k = 0; k < 3; ++k) {
      w.real(mesh.positions[v][k]);
    }
    if (normals) {
      for (int k = 0; k < 3; ++k) {
        w.real(vertex_normals[v][k]);
      }
    }
    if (colors) {
      for (int k = 0; k < 3; ++k) {
        w.byte(to_byte(mesh.vertex_colors[v][k]));
      }
    }
    if (vertex_uv) {
      w.real(vertex_uvs[v][0]);
      w.real(vertex_uvs[v][1]);
    }
    w.end_row();
  }
  for (int f = 0; f < mesh.num_faces(); ++f) {
    count(mesh.face_size(f));
    for (int v : mesh.face(f)) {
      w.integer(v);
    }
    if (corner_uv) {
      count(2 * mesh.face_size(f));
      for (int c = mesh.face_offsets[static_cast<size_t>(f)];
           c < mesh.face_offsets[static_cast<size_t>(f) + 1]; ++c) {
        const Eigen::Vector2d& t =
            mesh.texcoords[static_cast<size_t>(mesh.corner_texcoords[static_cast<size_t>(c)])];
        w.real(t[0]);
        w.real(t[1]);
      }
    }
    if (face_colors) {
      for (int k = 0; k < 3; ++k) {
        w.byte(to_byte(mesh.face_colors[static_cast<size_t>(f)][k]));
      }
    }
    w.end_row();
  }
  return std::move(w.out);
}

}  // namespace elastic::detail
