#pragma once
// A valid PNG of `width` x `height` 8-bit grey pixels, all zero, built by hand: a few MB for
// 20000 x 20000 pixels (400 MB decoded), written without ever holding the raw pixels.
//
// The image data is one zlib stream with one fixed-Huffman deflate block (RFC 1951 §3.2.6): every
// row is a filter byte 0 and `width` zero bytes, so the whole raw stream is zeros. It is coded as
// one literal 0 followed by back-references of length 258 at distance 1, each 13 bits (length code
// 285, 8 bits; distance code 0, 5 bits), and the remainder as literals. The Adler-32 of n zero
// bytes is (n mod 65521) << 16 | 1.

#include <array>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace elastic::test {

namespace png_bomb_detail {

/// Deflate's bit order: values are packed from the least significant bit of each byte.
class BitWriter {
 public:
  explicit BitWriter(std::string& out) : out_(out) {}
  /// `count` bits of `value`, least significant first (header fields, extra bits).
  void bits(std::uint32_t value, int count) {
    for (int i = 0; i < count; ++i) bit((value >> i) & 1u);
  }
  /// A Huffman code of `length` bits, most significant first (RFC 1951 §3.1.1).
  void code(std::uint32_t value, int length) {
    for (int i = length - 1; i >= 0; --i) bit((value >> i) & 1u);
  }
  void flush() {
    if (used_ > 0) out_ += static_cast<char>(current_);
    current_ = 0;
    used_ = 0;
  }

 private:
  void bit(std::uint32_t b) {
    current_ = static_cast<std::uint8_t>(current_ | (b << used_));
    if (++used_ == 8) flush();
  }
  std::string& out_;
  std::uint8_t current_ = 0;
  int used_ = 0;
};

inline std::uint32_t crc32(const std::string& bytes, size_t begin) {
  static const std::array<std::uint32_t, 256> table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t n = 0; n < 256; ++n) {
      std::uint32_t c = n;
      for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xedb88320u ^ (c >> 1) : c >> 1;
      t[n] = c;
    }
    return t;
  }();
  std::uint32_t c = 0xffffffffu;
  for (size_t i = begin; i < bytes.size(); ++i) {
    c = table[(c ^ static_cast<std::uint8_t>(bytes[i])) & 0xffu] ^ (c >> 8);
  }
  return c ^ 0xffffffffu;
}

inline void put_u32_be(std::string& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out += static_cast<char>((v >> shift) & 0xffu);
}

/// Appends a chunk: length, type, data, CRC of type and data.
inline void chunk(std::string& png, const char* type, const std::string& data) {
  put_u32_be(png, static_cast<std::uint32_t>(data.size()));
  const size_t start = png.size();
  png += type;
  png += data;
  put_u32_be(png, crc32(png, start));
}

}  // namespace png_bomb_detail

/// The PNG's bytes (see the file comment).
inline std::string zero_grey_png(std::uint32_t width, std::uint32_t height) {
  using namespace png_bomb_detail;
  std::string png = "\x89PNG\r\n\x1a\n";
  std::string header;
  put_u32_be(header, width);
  put_u32_be(header, height);
  header +=
      std::string("\x08\x00\x00\x00\x00", 5);  // 8 bits, grey, deflate, filter 0, no interlace
  chunk(png, "IHDR", header);

  const std::uint64_t raw = std::uint64_t{height} * (std::uint64_t{width} + 1);
  std::string z = "\x78\x01";  // zlib: deflate, 32K window; (0x78 * 256 + 0x01) % 31 == 0
  BitWriter w(z);
  w.bits(1, 1);     // BFINAL
  w.bits(1, 2);     // BTYPE 01: fixed Huffman codes
  w.code(0x30, 8);  // literal 0 (0x30 + 0 in 8 bits)
  std::uint64_t left = raw - 1;
  for (; left >= 258; left -= 258) {
    w.code(0xc5, 8);  // length symbol 285 = 258 bytes (0xc0 + 285 - 280)
    w.code(0, 5);     // distance code 0 = 1 byte back
  }
  for (; left > 0; --left) w.code(0x30, 8);
  w.code(0, 7);  // end of block, symbol 256
  w.flush();
  put_u32_be(z, static_cast<std::uint32_t>((raw % 65521u) << 16 | 1u));  // Adler-32 of zeros
  chunk(png, "IDAT", z);
  chunk(png, "IEND", "");
  return png;
}

/// Writes zero_grey_png(width, height) to `path`.
inline void write_zero_grey_png(const std::filesystem::path& path, std::uint32_t width,
                                std::uint32_t height) {
  const std::string png = zero_grey_png(width, height);
  std::ofstream(path, std::ios::binary).write(png.data(), static_cast<std::streamsize>(png.size()));
}

}  // namespace elastic::test
