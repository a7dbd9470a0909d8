// The shape expression parser (grammar in implicit.hpp): recursive descent over the text,
// every error naming the 1-based column where the unexpected text starts.
#include "isohex/volume/implicit.hpp"

#include "isohex/error.hpp"

#include <fmt/format.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <span>

namespace isohex {

namespace {

// One argument of a primitive: how messages name it, and whether it must be > 0.
struct Param {
  std::string_view name;
  bool positive = false;
};

constexpr Param kSphere[] = {{"centre x"}, {"centre y"}, {"centre z"}, {"radius", true}};
constexpr Param kBox[] = {{"first corner x"}, {"first corner y"}, {"first corner z"},
                          {"second corner x"}, {"second corner y"}, {"second corner z"}};
constexpr Param kCylinder[] = {{"first end x"}, {"first end y"}, {"first end z"}, {"second end x"},
                               {"second end y"}, {"second end z"}, {"radius", true}};
// A torus' 4th and 5th numbers are its radii, or the start of an axis when three more follow.
constexpr Param kTorusHead[] = {{"centre x"}, {"centre y"}, {"centre z"}, {"major radius (or axis x)"},
                                {"minor radius (or axis y)"}};
constexpr Param kTorusTail[] = {{"axis z"}, {"major radius", true}, {"minor radius", true}};
constexpr Param kPlane[] = {{"point x"}, {"point y"}, {"point z"}, {"normal x"}, {"normal y"}, {"normal z"}};

constexpr std::string_view kKnown = "sphere, box, cylinder, torus, plane, union, intersection, difference";

class Parser {
 public:
  explicit Parser(std::string_view text) : text_(text) {}

  Shape parse() {
    Shape s = shape();
    skip_space();
    if (pos_ < text_.size()) fail(pos_, fmt::format("unexpected '{}' after the end of the shape", excerpt(pos_)));
    return s;
  }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;

  [[noreturn]] void fail(std::size_t at, std::string_view what) const {
    throw Error(fmt::format("shape expression, column {}: {}", at + 1, what));
  }

  void skip_space() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }

  // What stands at `at`, for messages: a word, a number, one character or "the end".
  std::string excerpt(std::size_t at) const {
    if (at >= text_.size()) return "the end";
    std::size_t end = at;
    while (end < text_.size() && end - at < 20 &&
           (std::isalnum(static_cast<unsigned char>(text_[end])) || text_[end] == '.' || text_[end] == '_'))
      ++end;
    if (end == at) end = at + 1;
    return std::string(text_.substr(at, end - at));
  }

  // The next non-space character (0 at the end), not consumed.
  char peek() {
    skip_space();
    return pos_ < text_.size() ? text_[pos_] : '\0';
  }

  void expect(char c, std::string_view after) {
    if (peek() != c) {
      const std::string found = pos_ < text_.size() ? fmt::format("'{}'", excerpt(pos_)) : "the end";
      fail(pos_, fmt::format("expected '{}' after {}, found {}", c, after, found));
    }
    ++pos_;
  }

  std::string_view word() {
    skip_space();
    const std::size_t start = pos_;
    while (pos_ < text_.size() && (std::isalpha(static_cast<unsigned char>(text_[pos_])) || text_[pos_] == '_')) ++pos_;
    return text_.substr(start, pos_ - start);
  }

  double number(std::string_view what, std::string_view shape_name, bool positive) {
    skip_space();
    const std::size_t start = pos_;
    std::size_t end = pos_;
    while (end < text_.size() && (std::isdigit(static_cast<unsigned char>(text_[end])) || text_[end] == '.' ||
                                  text_[end] == 'e' || text_[end] == 'E' || text_[end] == '+' || text_[end] == '-'))
      ++end;
    std::string_view token = text_.substr(start, end - start);
    if (!token.empty() && token.front() == '+') token.remove_prefix(1);
    double v = 0;
    const auto [p, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
    if (token.empty() || ec != std::errc() || p != token.data() + token.size() || !std::isfinite(v)) {
      const std::string found = start < text_.size() ? fmt::format("'{}'", start == end ? excerpt(start) : std::string(text_.substr(start, end - start))) : "the end";
      fail(start, fmt::format("expected the {} of the {} (a number), found {}", what, shape_name, found));
    }
    if (positive && !(v > 0)) fail(start, fmt::format("the {} of the {} must be positive, found {}", what, shape_name, v));
    pos_ = end;
    return v;
  }

  // The numbers of `params`, separated by commas; the caller consumes the closing ')'.
  std::vector<double> numbers(std::span<const Param> params, std::string_view shape_name,
                              std::vector<std::size_t>* columns = nullptr) {
    std::vector<double> v;
    for (std::size_t i = 0; i < params.size(); ++i) {
      if (i) expect(',', fmt::format("the {}", params[i - 1].name));
      skip_space();
      if (columns) columns->push_back(pos_);
      v.push_back(number(params[i].name, shape_name, params[i].positive));
    }
    return v;
  }

  Shape shape() {
    skip_space();
    const std::size_t at = pos_;
    const std::string_view name = word();
    if (name.empty()) {
      const std::string found = at < text_.size() ? fmt::format("'{}'", excerpt(at)) : "the end";
      fail(at, fmt::format("expected a shape ({}), found {}", kKnown, found));
    }
    const bool known = name == "sphere" || name == "box" || name == "cylinder" || name == "torus" || name == "plane" ||
                       name == "union" || name == "intersection" || name == "difference";
    if (!known) fail(at, fmt::format("unknown shape '{}' (known: {})", name, kKnown));
    expect('(', fmt::format("'{}'", name));
    if (name == "union" || name == "intersection" || name == "difference") return csg(name);
    return primitive(name, at);
  }

  Shape csg(std::string_view name) {
    std::vector<Shape> operands;
    operands.push_back(shape());
    while (peek() == ',') {
      ++pos_;
      operands.push_back(shape());
    }
    if (peek() != ')') {
      const std::string found = pos_ < text_.size() ? fmt::format("'{}'", excerpt(pos_)) : "the end";
      fail(pos_, fmt::format("expected ',' or ')' after shape {} of the {}, found {}", operands.size(), name, found));
    }
    if (operands.size() < 2) fail(pos_, fmt::format("{} needs at least two shapes, found one", name));
    ++pos_;
    const CsgOp op = name == "union" ? CsgOp::unite : name == "intersection" ? CsgOp::intersect : CsgOp::subtract;
    return Shape{Csg{op, std::move(operands)}};
  }

  Shape primitive(std::string_view name, std::size_t at) {
    std::vector<std::size_t> col;
    auto vec = [](const std::vector<double>& v, std::size_t i) { return Vec3(v[i], v[i + 1], v[i + 2]); };
    if (name == "sphere") {
      const auto v = numbers(kSphere, name);
      expect(')', "the radius");
      return Shape::sphere(vec(v, 0), v[3]);
    }
    if (name == "box") {
      const auto v = numbers(kBox, name, &col);
      expect(')', "the second corner z");
      for (int d = 0; d < 3; ++d)
        if (!(v[d] < v[d + 3]))
          fail(col[d + 3], fmt::format("the box's second corner {} ({}) must be above its first corner {} ({})", "xyz"[d],
                                       v[d + 3], "xyz"[d], v[d]));
      return Shape::box(vec(v, 0), vec(v, 3));
    }
    if (name == "cylinder") {
      const auto v = numbers(kCylinder, name);
      expect(')', "the radius");
      if (vec(v, 0) == vec(v, 3)) fail(at, "the cylinder's two ends coincide");
      return Shape::cylinder(vec(v, 0), vec(v, 3), v[6]);
    }
    if (name == "torus") {
      // Five numbers, or eight when an axis follows the centre.
      auto v = numbers(kTorusHead, name, &col);
      Vec3 axis(0, 0, 1);
      if (peek() == ',') {
        ++pos_;
        std::vector<std::size_t> tail_col;
        const std::vector<double> tail = numbers(kTorusTail, name, &tail_col);
        axis = Vec3(v[3], v[4], tail[0]);
        if (!(axis.norm() > 0)) fail(col[3], "the torus axis is zero");
        v = {v[0], v[1], v[2], tail[1], tail[2]};
        col = {col[0], col[1], col[2], tail_col[1], tail_col[2]};
      } else {
        for (int i : {3, 4})
          if (!(v[i] > 0))
            fail(col[i], fmt::format("the {} radius of the torus must be positive, found {}", i == 3 ? "major" : "minor", v[i]));
      }
      expect(')', "the minor radius");
      if (!(v[4] < v[3]))
        fail(col[4], fmt::format("the torus's minor radius ({}) must be below its major radius ({})", v[4], v[3]));
      return Shape::torus(vec(v, 0), axis, v[3], v[4]);
    }
    const auto v = numbers(kPlane, name, &col);
    expect(')', "the normal z");
    if (!(vec(v, 3).norm() > 0)) fail(col[3], "the plane's normal is zero");
    return Shape::plane(vec(v, 0), vec(v, 3));
  }
};

}  // namespace

Shape parse_shape(std::string_view text) { return Parser(text).parse(); }

}  // namespace isohex
