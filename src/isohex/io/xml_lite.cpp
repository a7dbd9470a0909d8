#include "isohex/io/xml_lite.hpp"

#include "isohex/io/text_scanner.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>

namespace isohex::io::xml {

namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

bool is_name_end(char c) { return is_space(c) || c == '/' || c == '>' || c == '='; }

/// Appends code point `cp` as UTF-8; false if it is not a valid XML character.
bool append_utf8(std::string& out, std::uint32_t cp) {
  if (cp == 0 || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
  if (cp < 0x80) {
    out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    out += static_cast<char>(0xC0 | (cp >> 6));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    out += static_cast<char>(0xE0 | (cp >> 12));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    out += static_cast<char>(0xF0 | (cp >> 18));
    out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  }
  return true;
}

/// The parser state: a cursor, the document built so far and the stack of open elements.
class Parser {
 public:
  Parser(std::string_view text, const std::filesystem::path& file) : t_(text), file_(file) { doc_.text = text; }

  Document run() {
    while (pos_ < t_.size() && !done_) {
      if (t_[pos_] == '<')
        markup();
      else
        character_data();
    }
    if (done_) return std::move(doc_);
    if (doc_.elements.empty()) fail(t_.size(), "no XML element found (empty or not an XML file)");
    if (!open_.empty()) {
      const Element& e = doc_.elements[open_.back()];
      fail(t_.size(), fmt::format("unexpected end of file inside <{}> opened at {} (file truncated?)", e.name,
                                  position(t_, e.offset)));
    }
    return std::move(doc_);
  }

 private:
  [[noreturn]] void fail(std::size_t at, std::string_view what) const { parse_error(file_, position(t_, at), what); }

  /// Index of `needle` at or after `from`; fails naming `construct` if it never comes.
  std::size_t find(std::string_view needle, std::size_t from, std::string_view construct) const {
    const std::size_t at = t_.find(needle, from);
    if (at == std::string_view::npos)
      fail(pos_, fmt::format("unterminated {} (no '{}' before the end of the file)", construct, needle));
    return at;
  }

  bool starts_with(std::string_view s) const { return t_.substr(pos_, s.size()) == s; }

  void skip_space() {
    while (pos_ < t_.size() && is_space(t_[pos_])) ++pos_;
  }

  void add_text(std::size_t begin, std::size_t end) {
    while (begin < end && is_space(t_[begin])) ++begin;
    while (end > begin && is_space(t_[end - 1])) --end;
    if (begin == end) return;
    if (open_.empty()) fail(begin, "text outside the root element");
    doc_.elements[open_.back()].text.emplace_back(begin, end);
  }

  void character_data() {
    std::size_t end = t_.find('<', pos_);
    if (end == std::string_view::npos) end = t_.size();
    add_text(pos_, end);
    pos_ = end;
  }

  void markup() {
    if (starts_with("<?")) {
      pos_ = find("?>", pos_ + 2, "processing instruction") + 2;
    } else if (starts_with("<!--")) {
      pos_ = find("-->", pos_ + 4, "comment") + 3;
    } else if (starts_with("<![CDATA[")) {
      const std::size_t end = find("]]>", pos_ + 9, "CDATA section");
      add_text(pos_ + 9, end);
      pos_ = end + 3;
    } else if (starts_with("<!")) {
      pos_ = find(">", pos_ + 2, "declaration") + 1;
    } else if (starts_with("</")) {
      end_tag();
    } else {
      start_tag();
    }
  }

  std::string_view name_at(std::size_t at) const {
    std::size_t end = at;
    while (end < t_.size() && !is_name_end(t_[end])) ++end;
    return t_.substr(at, end - at);
  }

  void end_tag() {
    const std::size_t at = pos_;
    const std::string_view name = name_at(pos_ + 2);
    pos_ += 2 + name.size();
    skip_space();
    if (pos_ >= t_.size() || t_[pos_] != '>') fail(at, fmt::format("malformed end tag </{}", name));
    ++pos_;
    if (open_.empty()) fail(at, fmt::format("end tag </{}> without a matching start tag", name));
    const Element& e = doc_.elements[open_.back()];
    if (e.name != name)
      fail(at, fmt::format("end tag </{}> does not match <{}> opened at {}", name, e.name, position(t_, e.offset)));
    open_.pop_back();
  }

  void start_tag() {
    const std::size_t at = pos_;
    const std::string_view name = name_at(pos_ + 1);
    if (name.empty()) fail(at, "expected an element name after '<'");
    if (open_.empty() && !doc_.elements.empty()) fail(at, fmt::format("second root element <{}>", name));
    pos_ += 1 + name.size();
    Element e;
    e.name = name;
    e.offset = at;
    const bool self_closed = attributes(e);
    const std::size_t index = doc_.elements.size();
    if (!open_.empty()) doc_.elements[open_.back()].children.push_back(index);
    doc_.elements.push_back(std::move(e));
    if (name == "AppendedData") return appended(index, self_closed);
    if (!self_closed) open_.push_back(index);
  }

  /// Reads attributes up to '>' or '/>'; true for '/>'.
  bool attributes(Element& e) {
    for (;;) {
      skip_space();
      if (pos_ >= t_.size()) fail(e.offset, fmt::format("unterminated start tag <{}", e.name));
      if (t_[pos_] == '>') {
        ++pos_;
        return false;
      }
      if (starts_with("/>")) {
        pos_ += 2;
        return true;
      }
      const std::size_t at = pos_;
      const std::string_view key = name_at(pos_);
      if (key.empty()) fail(at, fmt::format("unexpected '{}' in start tag <{}>", t_[pos_], e.name));
      pos_ += key.size();
      skip_space();
      if (pos_ >= t_.size() || t_[pos_] != '=') fail(at, fmt::format("attribute '{}' has no '=value'", key));
      ++pos_;
      skip_space();
      if (pos_ >= t_.size() || (t_[pos_] != '"' && t_[pos_] != '\''))
        fail(at, fmt::format("value of attribute '{}' is not quoted", key));
      const char quote = t_[pos_];
      const std::size_t end = find(std::string_view(&quote, 1), pos_ + 1, "attribute value");
      e.attributes.emplace_back(key, decode_entities(pos_ + 1, end));
      pos_ = end + 1;
    }
  }

  std::string decode_entities(std::size_t begin, std::size_t end) const {
    std::string out;
    out.reserve(end - begin);
    for (std::size_t i = begin; i < end; ++i) {
      if (t_[i] != '&') {
        out += t_[i];
        continue;
      }
      const std::size_t semi = t_.find(';', i);
      if (semi == std::string_view::npos || semi >= end) fail(i, "unterminated entity reference '&'");
      const std::string_view ent = t_.substr(i + 1, semi - i - 1);
      if (!decode_entity(ent, out)) fail(i, fmt::format("unknown entity '&{};'", ent));
      i = semi;
    }
    return out;
  }

  static bool decode_entity(std::string_view ent, std::string& out) {
    static constexpr std::pair<std::string_view, char> kNamed[] = {
        {"lt", '<'}, {"gt", '>'}, {"amp", '&'}, {"quot", '"'}, {"apos", '\''}};
    for (const auto& [n, c] : kNamed)
      if (ent == n) {
        out += c;
        return true;
      }
    if (ent.size() < 2 || ent[0] != '#') return false;
    const bool hex = ent[1] == 'x';
    const std::string_view digits = ent.substr(hex ? 2 : 1);
    std::uint32_t cp = 0;
    auto [p, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), cp, hex ? 16 : 10);
    if (ec != std::errc() || p != digits.data() + digits.size() || digits.empty()) return false;
    return append_utf8(out, cp);
  }

  /// Finds the '_' that starts the appended bytes, and stops parsing: what follows is not XML.
  void appended(std::size_t index, bool self_closed) {
    doc_.appended_element = index;
    if (self_closed) fail(doc_.elements[index].offset, "<AppendedData/> is empty: it has no '_' data marker");
    skip_space();
    if (pos_ >= t_.size() || t_[pos_] != '_')
      fail(pos_, "<AppendedData> content must begin with '_' (file truncated or not written by VTK?)");
    doc_.appended_begin = pos_ + 1;
    done_ = true;
  }

  std::string_view t_;
  const std::filesystem::path& file_;
  std::size_t pos_ = 0;
  bool done_ = false;
  Document doc_;
  std::vector<std::size_t> open_;
};

}  // namespace

const std::string* Element::attribute(std::string_view key) const {
  for (const auto& [k, v] : attributes)
    if (k == key) return &v;
  return nullptr;
}

std::vector<const Element*> Document::children(const Element& parent, std::string_view name) const {
  std::vector<const Element*> out;
  for (std::size_t c : parent.children)
    if (elements[c].name == name) out.push_back(&elements[c]);
  return out;
}

const Element* Document::only_child(const Element& parent, std::string_view name,
                                    const std::filesystem::path& file) const {
  const std::vector<const Element*> found = children(parent, name);
  if (found.size() > 1)
    parse_error(file, position(text, found[1]->offset),
                fmt::format("<{}> has more than one <{}>", parent.name, name));
  return found.empty() ? nullptr : found.front();
}

Document parse(std::string_view text, const std::filesystem::path& file) { return Parser(text, file).run(); }

std::string position(std::string_view text, std::size_t offset) {
  offset = std::min(offset, text.size());
  const auto line = 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(offset), '\n');
  return fmt::format("line {} (byte {})", line, offset);
}

}  // namespace isohex::io::xml
