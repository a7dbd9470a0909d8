#include "isohex/io/text_scanner.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>

namespace isohex::io {

void parse_error(const std::filesystem::path& file, std::string_view where, std::string_view what) {
  throw Error(fmt::format("{}: {}: {}", file.string(), where, what));
}

TextScanner::TextScanner(std::string_view text, std::filesystem::path file, std::size_t offset)
    : text_(text), file_(std::move(file)) {
  seek(offset);
}

void TextScanner::seek(std::size_t offset) {
  for (std::size_t i = pos_; i < offset && i < text_.size(); ++i)
    if (text_[i] == '\n') ++line_;
  pos_ = std::min(offset, text_.size());
}

static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

bool TextScanner::skip_space() {
  while (pos_ < text_.size() && is_space(text_[pos_])) {
    if (text_[pos_] == '\n') ++line_;
    ++pos_;
  }
  return pos_ < text_.size();
}

std::string_view TextScanner::next() {
  if (!skip_space()) return {};
  const std::size_t start = pos_;
  while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
  return text_.substr(start, pos_ - start);
}

std::string_view TextScanner::expect(std::string_view what) {
  std::string_view t = next();
  if (t.empty()) fail(fmt::format("unexpected end of file, expected {}", what));
  return t;
}

std::string_view TextScanner::rest_of_line() {
  const std::size_t start = pos_;
  while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
  std::string_view line = text_.substr(start, pos_ - start);
  if (pos_ < text_.size()) {
    ++pos_;
    ++line_;
  }
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  return line;
}

static std::string shown(std::string_view token) {
  return token.size() > 40 ? std::string(token.substr(0, 40)) + "..." : std::string(token);
}

double TextScanner::next_double(std::string_view what) {
  std::string_view t = expect(what);
  double v;
  if (!parse_double(t, v)) fail(fmt::format("expected {} (a finite number), found '{}'", what, shown(t)));
  return v;
}

std::int64_t TextScanner::next_int(std::string_view what, std::int64_t lo, std::int64_t hi) {
  std::string_view t = expect(what);
  std::int64_t v;
  if (!parse_int(t, v)) fail(fmt::format("expected {} (an integer), found '{}'", what, shown(t)));
  if (v < lo || v > hi) fail(fmt::format("{} {} is out of range [{}, {}]", what, v, lo, hi));
  return v;
}

void TextScanner::fail(std::string_view what) const {
  parse_error(file_, fmt::format("line {}", line_), what);
}

bool parse_double(std::string_view t, double& v) {
  if (!t.empty() && t.front() == '+') t.remove_prefix(1);
  auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  if (ec == std::errc::result_out_of_range) return false;
  if (ec != std::errc() || p != t.data() + t.size()) {
    // Fortran-style exponents (1.0D+03) appear in Abaqus and old MEDIT files.
    std::string s(t);
    for (char& c : s)
      if (c == 'd' || c == 'D') c = 'e';
    auto [p2, ec2] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec2 != std::errc() || p2 != s.data() + s.size()) return false;
  }
  return std::isfinite(v);
}

bool parse_int(std::string_view t, std::int64_t& v) {
  if (!t.empty() && t.front() == '+') t.remove_prefix(1);
  auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
  return ec == std::errc() && p == t.data() + t.size();
}

}  // namespace isohex::io
