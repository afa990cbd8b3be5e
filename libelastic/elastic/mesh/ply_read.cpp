// Stanford PLY reading: ascii, binary_little_endian and binary_big_endian; any element and property
// layout (what is not used is skipped by its declared type), vertex x y z / colours / normals /
// texture coordinates, faces as a `vertex_indices` or `vertex_index` list, optionally with a
// per-corner `texcoord` list. Writing is ply_write.cpp.

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

/// The header: the encoding and the elements with their properties, in file order.
struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::Ascii;
  std::vector<PlyElement> elements;
};

/// One property declaration (after the keyword `property`) of the last element.
PlyProperty parse_property(std::string_view rest, LineScanner& scanner) {
  PlyProperty property;
  std::string_view type = next_token(rest);
  if (type == "list") {
    property.is_list = true;
    if (!parse_type(next_token(rest), property.count_type) || is_float_type(property.count_type)) {
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
  return property;
}

/// Reads the header up to and including `end_header` (the scanner then stands at the data).
PlyHeader read_header(LineScanner& scanner, const std::filesystem::path& path) {
  std::string_view line;
  if (!scanner.next(line) || trim(line) != "ply") {
    scanner.fail("not a PLY file (no 'ply' magic)");
  }
  PlyHeader header;
  bool have_format = false;
  bool ended = false;
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
        header.encoding = PlyEncoding::Ascii;
      } else if (name == "binary_little_endian") {
        header.encoding = PlyEncoding::BinaryLittle;
      } else if (name == "binary_big_endian") {
        header.encoding = PlyEncoding::BinaryBig;
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
      header.elements.push_back(std::move(element));
    } else if (keyword == "property") {
      if (header.elements.empty()) {
        scanner.fail("property before any element");
      }
      header.elements.back().properties.push_back(parse_property(rest, scanner));
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
  return header;
}

constexpr long long kMaxInt = std::numeric_limits<int>::max();

/// Reads the data section element by element into a mesh: the first vertex element, the first
/// face element, and the rest skipped by their declared types.
class PlyReader {
 public:
  PlyReader(PlyData& data, PlyEncoding encoding, const std::filesystem::path& path,
            MeshReadResult& result)
      : data_(data), encoding_(encoding), path_(path), result_(result), mesh_(result.mesh) {}

  void read(const std::vector<PlyElement>& elements) {
    for (const PlyElement& element : elements) {
      if (min_row_bytes(element, encoding_) == 0) {
        skip_empty(element);
        continue;
      }
      data_.check_element_fits(element);
      if (element.name == "vertex" && !seen_vertices_) {
        read_vertices(element);
      } else if (element.name == "face" && mesh_.face_offsets.empty()) {
        read_faces(element);
      } else {
        skip(element);
      }
    }
    finish();
  }

 private:
  // A colour channel as the mesh stores it (float): finite, or the file is refused.
  float color_channel(double value, double scale, long long row, const char* what) const {
    const double c = value * scale;
    if (!(std::fabs(c) <= static_cast<double>(std::numeric_limits<float>::max()))) {
      data_.fail(std::string(what) + " " + std::to_string(row) +
                 " has a colour beyond float range");
    }
    return static_cast<float>(c);
  }

  void refuse_count(const PlyElement& element, const char* what) const {
    if (element.count > kMaxInt) {
      throw InvalidInputError(path_.string(), std::to_string(element.count) + " " + what +
                                                  ": more than the library indexes (" +
                                                  std::to_string(kMaxInt) + ")");
    }
  }

  // Rows without properties hold no bytes in either encoding: nothing to read or skip, however
  // many the header declares.
  void skip_empty(const PlyElement& element) {
    if (element.count > 0) {
      result_.warnings.push_back(path_.string() + ": element '" + element.name + "' has " +
                                 std::to_string(element.count) +
                                 " rows but no properties; skipped");
    }
    if (element.name == "vertex" && !seen_vertices_ && element.count > 0) {
      throw InvalidInputError(path_.string(), "the vertex element has no x, y and z properties");
    }
  }

  // Skips other elements (edges, materials, a second vertex element...) by their declared types.
  // check_element_fits bounded the rows by the file's size, and every row reads at least one
  // byte, so skipping costs time in proportion to the file.
  void skip(const PlyElement& element) {
    for (long long row = 0; row < element.count; ++row) {
      data_.locate(element.name, row, element.count);
      for (const PlyProperty& property : element.properties) {
        const long long n = property.is_list ? data_.read_list_length(property) : 1;
        for (long long k = 0; k < n; ++k) {
          data_.read(property.type);
        }
      }
    }
  }

  void read_vertices(const PlyElement& element);
  void store_vertex(const double values[], const double scale[], long long row);
  void read_faces(const PlyElement& element);
  long long read_face_row(const PlyElement& element, long long row, std::vector<double>& uv_values);
  void finish();

  PlyData& data_;
  PlyEncoding encoding_;
  const std::filesystem::path& path_;
  MeshReadResult& result_;
  PolygonMesh& mesh_;
  bool seen_vertices_ = false;
  bool have_uv_ = false;
  bool have_normal_ = false;
  bool have_color_ = false;
  bool have_corner_uv_ = false;
  std::vector<int> corner_uv_;
  long long num_vertices_ = 0;
  // The face element's layout (read_faces).
  int indices_property_ = -1;
  int texcoord_property_ = -1;
  std::array<int, 3> face_color_property_{-1, -1, -1};
};

// The first vertex element: positions, and normals, colours and texture coordinates when all
// their components are there.
void PlyReader::read_vertices(const PlyElement& element) {
  seen_vertices_ = true;
  refuse_count(element, "vertices");
  num_vertices_ = element.count;
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
    throw InvalidInputError(path_.string(), "the vertex element has no x, y and z properties");
  }
  have_normal_ = has_role[kNx] && has_role[kNy] && has_role[kNz];
  have_color_ = has_role[kRed] && has_role[kGreen] && has_role[kBlue];
  have_uv_ = has_role[kU] && has_role[kV];
  // check_element_fits bounded the count by the file's size.
  mesh_.positions.reserve(static_cast<size_t>(element.count));
  double values[kNumRoles];
  for (long long row = 0; row < element.count; ++row) {
    data_.locate(element.name, row, element.count);
    std::fill(std::begin(values), std::end(values), 0.0);
    for (size_t p = 0; p < element.properties.size(); ++p) {
      const PlyProperty& property = element.properties[p];
      if (property.is_list) {
        const long long n = data_.read_list_length(property);
        for (long long k = 0; k < n; ++k) {
          data_.read(property.type);
        }
        continue;
      }
      const double value = data_.read(property.type);
      if (role[p] != kSkip) {
        values[role[p]] = value;
      }
    }
    store_vertex(values, scale, row);
  }
}

void PlyReader::store_vertex(const double values[], const double scale[], long long row) {
  const Eigen::Vector3d position(values[kX], values[kY], values[kZ]);
  if (!position.allFinite()) {
    data_.fail("vertex " + std::to_string(row) + " has a NaN or infinite coordinate");
  }
  mesh_.positions.push_back(position);
  if (have_normal_) {
    const Eigen::Vector3d normal(values[kNx], values[kNy], values[kNz]);
    if (!normal.allFinite()) {
      data_.fail("vertex " + std::to_string(row) + " has a NaN or infinite normal");
    }
    mesh_.normals.push_back(normal);
  }
  if (have_color_) {
    mesh_.vertex_colors.emplace_back(color_channel(values[kRed], scale[kRed], row, "vertex"),
                                     color_channel(values[kGreen], scale[kGreen], row, "vertex"),
                                     color_channel(values[kBlue], scale[kBlue], row, "vertex"));
  }
  if (have_uv_) {
    const Eigen::Vector2d uv(values[kU], values[kV]);
    if (!uv.allFinite()) {
      data_.fail("vertex " + std::to_string(row) + " has a NaN or infinite texture coordinate");
    }
    mesh_.texcoords.push_back(uv);
  }
}

// The first face element: the corner list, MeshLab's per-corner `texcoord` list, and a colour
// when the face element has red, green and blue scalars.
void PlyReader::read_faces(const PlyElement& element) {
  refuse_count(element, "faces");
  for (size_t p = 0; p < element.properties.size(); ++p) {
    const PlyProperty& property = element.properties[p];
    if (!property.is_list) {
      continue;
    }
    if (indices_property_ < 0 &&
        (property.name == "vertex_indices" || property.name == "vertex_index")) {
      indices_property_ = static_cast<int>(p);
    } else if (property.name == "texcoord") {
      texcoord_property_ = static_cast<int>(p);
    }
  }
  if (indices_property_ < 0) {
    throw InvalidInputError(path_.string(),
                            "the face element has no vertex_indices / vertex_index list");
  }
  have_corner_uv_ = texcoord_property_ >= 0;
  mesh_.face_offsets.reserve(static_cast<size_t>(element.count) + 1);
  mesh_.face_offsets.push_back(0);
  for (size_t p = 0; p < element.properties.size(); ++p) {
    const PlyProperty& property = element.properties[p];
    if (property.is_list) {
      continue;
    }
    if (property.name == "red") {
      face_color_property_[0] = static_cast<int>(p);
    }
    if (property.name == "green") {
      face_color_property_[1] = static_cast<int>(p);
    }
    if (property.name == "blue") {
      face_color_property_[2] = static_cast<int>(p);
    }
  }
  std::vector<double> uv_values;
  for (long long row = 0; row < element.count; ++row) {
    const long long corners = read_face_row(element, row, uv_values);
    if (have_corner_uv_) {
      // MeshLab's per-corner texture coordinates: u v for every corner, in corner order.
      if (uv_values.size() != static_cast<size_t>(2 * corners)) {
        data_.fail("face " + std::to_string(row) +
                   ": texcoord list does not have 2 values per corner");
      }
      for (long long k = 0; k < corners; ++k) {
        corner_uv_.push_back(static_cast<int>(corner_uv_.size()));
      }
      for (size_t k = 0; k + 1 < uv_values.size(); k += 2) {
        mesh_.texcoords.emplace_back(uv_values[k], uv_values[k + 1]);
      }
    }
    mesh_.face_offsets.push_back(static_cast<int>(mesh_.face_vertices.size()));
  }
  if (mesh_.face_offsets.size() == 1) {
    mesh_.face_offsets.clear();
  }
}

// One face row: its corners into the mesh (and its colour, when the element has one); its
// texcoord list into `uv_values`. Returns the number of corners.
long long PlyReader::read_face_row(const PlyElement& element, long long row,
                                   std::vector<double>& uv_values) {
  const bool have_face_color =
      face_color_property_[0] >= 0 && face_color_property_[1] >= 0 && face_color_property_[2] >= 0;
  data_.locate(element.name, row, element.count);
  long long corners = 0;
  Eigen::Vector3f face_color = Eigen::Vector3f::Zero();
  for (size_t p = 0; p < element.properties.size(); ++p) {
    const PlyProperty& property = element.properties[p];
    if (!property.is_list) {
      const double value = data_.read(property.type);
      for (int k = 0; k < 3; ++k) {
        if (face_color_property_[static_cast<size_t>(k)] == static_cast<int>(p)) {
          face_color[k] = color_channel(value, color_scale(property.type), row, "face");
        }
      }
      continue;
    }
    const long long n = data_.read_list_length(property);
    if (static_cast<int>(p) == indices_property_) {
      corners = n;
      if (n < 3) {
        data_.fail("face " + std::to_string(row) + " has " + std::to_string(n) +
                   " corners (at least 3)");
      }
      for (long long k = 0; k < n; ++k) {
        const long long i = data_.read_integer(property.type, "a vertex index");
        if (i < 0 || i >= num_vertices_ || !seen_vertices_) {
          data_.fail("face " + std::to_string(row) + ": vertex index " + std::to_string(i) +
                     " out of range (" + std::to_string(num_vertices_) + " vertices)");
        }
        mesh_.face_vertices.push_back(static_cast<int>(i));
      }
      if (mesh_.face_vertices.size() > static_cast<size_t>(kMaxInt)) {
        data_.fail("more face corners than the library indexes");
      }
    } else if (static_cast<int>(p) == texcoord_property_) {
      uv_values.clear();
      for (long long k = 0; k < n; ++k) {
        const double value = data_.read(property.type);
        if (!std::isfinite(value)) {
          data_.fail("face " + std::to_string(row) + " has a NaN or infinite texture coordinate");
        }
        uv_values.push_back(value);
      }
    } else {
      for (long long k = 0; k < n; ++k) {
        data_.read(property.type);
      }
    }
  }
  if (have_face_color) {
    mesh_.face_colors.push_back(face_color);
  }
  return corners;
}

// Texture coordinates and normals become per corner.
void PlyReader::finish() {
  if (have_corner_uv_) {
    // Per-corner texcoords replace per-vertex ones (which were appended to the same pool first).
    if (have_uv_) {
      const auto per_vertex = static_cast<std::ptrdiff_t>(mesh_.positions.size());
      mesh_.texcoords.erase(mesh_.texcoords.begin(), mesh_.texcoords.begin() + per_vertex);
    }
    mesh_.corner_texcoords = std::move(corner_uv_);
  } else if (have_uv_) {
    mesh_.corner_texcoords = mesh_.face_vertices;
  }
  if (have_normal_) {
    mesh_.corner_normals = mesh_.face_vertices;
  }
}

}  // namespace

MeshReadResult read_ply(const std::string& text, const std::filesystem::path& path) {
  MeshReadResult result;
  LineScanner scanner(text, path);
  const PlyHeader header = read_header(scanner, path);
  PlyData data(std::string_view(text).substr(scanner.position()), header.encoding, path,
               scanner.line_number() + 1);
  PlyReader(data, header.encoding, path, result).read(header.elements);
  return result;
}

}  // namespace elastic::detail
