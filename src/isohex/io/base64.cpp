#include "isohex/io/base64.hpp"

#include "isohex/io/text_scanner.hpp"

#include <fmt/format.h>

#include <array>
#include <cstring>

namespace isohex::io {

namespace {

constexpr signed char kInvalid = -1, kSpace = -2, kPad = -3, kEnd = -4;

constexpr std::array<signed char, 256> make_table() {
  std::array<signed char, 256> t{};
  for (auto& v : t) v = kInvalid;
  const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  for (int i = 0; i < 64; ++i) t[static_cast<unsigned char>(alphabet[i])] = static_cast<signed char>(i);
  for (char c : {' ', '\t', '\n', '\r'}) t[static_cast<unsigned char>(c)] = kSpace;
  t['='] = kPad;
  t['<'] = kEnd;
  return t;
}

constexpr std::array<signed char, 256> kTable = make_table();

}  // namespace

Base64Reader::Base64Reader(std::string_view text, std::size_t file_offset, const std::filesystem::path& file)
    : text_(text), file_offset_(file_offset), file_(file) {}

void Base64Reader::fail(std::size_t at, std::string_view what) const {
  parse_error(file_, fmt::format("byte {}", file_offset_ + at), what);
}

void Base64Reader::read(unsigned char* out, std::size_t n) {
  for (;;) {
    const std::size_t take = std::min(n, pending_size_);
    std::memcpy(out, pending_ + pending_begin_, take);
    out += take;
    n -= take;
    pending_begin_ += take;
    pending_size_ -= take;
    // Fast path: whole groups of 4 valid symbols straight into the output.
    while (n >= 3 && pos_ + 4 <= text_.size()) {
      const auto* s = reinterpret_cast<const unsigned char*>(text_.data() + pos_);
      const int a = kTable[s[0]], b = kTable[s[1]], c = kTable[s[2]], d = kTable[s[3]];
      if ((a | b | c | d) < 0) break;
      const std::uint32_t v = (std::uint32_t(a) << 18) | (std::uint32_t(b) << 12) | (std::uint32_t(c) << 6) | std::uint32_t(d);
      out[0] = static_cast<unsigned char>(v >> 16);
      out[1] = static_cast<unsigned char>(v >> 8);
      out[2] = static_cast<unsigned char>(v);
      out += 3;
      n -= 3;
      pos_ += 4;
    }
    if (n == 0) return;
    next_group(n);
  }
}

void Base64Reader::next_group(std::size_t bytes_wanted) {
  int symbols[4];
  int count = 0, pads = 0;
  const std::size_t group_start = pos_;
  while (count < 4) {
    if (pos_ >= text_.size() || kTable[static_cast<unsigned char>(text_[pos_])] == kEnd) {
      if (count == 0)
        fail(pos_, fmt::format("base64 data ends early: {} more bytes expected (file truncated or size header wrong?)",
                               bytes_wanted));
      fail(group_start, "base64 data ends inside a 4-character group (file truncated?)");
    }
    const unsigned char ch = static_cast<unsigned char>(text_[pos_]);
    const int v = kTable[ch];
    if (v == kSpace) {
      ++pos_;
      continue;
    }
    if (v == kInvalid)
      fail(pos_, ch >= 0x20 && ch < 0x7f ? fmt::format("invalid base64 character '{}'", static_cast<char>(ch))
                                         : fmt::format("invalid base64 byte 0x{:02x}", ch));
    if (v == kPad) {
      if (count < 2) fail(pos_, "misplaced base64 padding '='");
      ++pads;
      symbols[count++] = 0;
    } else {
      if (pads) fail(pos_, "base64 symbol after '=' padding in the same 4-character group");
      symbols[count++] = v;
    }
    ++pos_;
  }
  const std::uint32_t v = (std::uint32_t(symbols[0]) << 18) | (std::uint32_t(symbols[1]) << 12) |
                          (std::uint32_t(symbols[2]) << 6) | std::uint32_t(symbols[3]);
  pending_[0] = static_cast<unsigned char>(v >> 16);
  pending_[1] = static_cast<unsigned char>(v >> 8);
  pending_[2] = static_cast<unsigned char>(v);
  pending_begin_ = 0;
  pending_size_ = static_cast<std::size_t>(3 - pads);
}

}  // namespace isohex::io
