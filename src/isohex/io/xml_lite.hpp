#pragma once
/// \file xml_lite.hpp
/// \brief The small XML subset that VTK XML files use, parsed into a flat element tree.
///
/// Handles elements, attributes (with the five predefined entities and character
/// references), comments, processing instructions, DOCTYPE and CDATA. Element text is not
/// copied: each element keeps the byte ranges of its non-blank character data, so that
/// megabytes of ASCII or base64 array data are decoded in place.
///
/// VTK's `<AppendedData>` holds raw bytes that are not XML, so parsing stops right after
/// its `_` marker and reports where the appended bytes begin. Elements still open at that
/// point are accepted as they are (VTK's own reader does the same).

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace isohex::io::xml {

/// One element of the document.
struct Element {
  std::string_view name;
  std::vector<std::pair<std::string_view, std::string>> attributes;  ///< values entity-decoded
  std::vector<std::size_t> children;                ///< indices into Document::elements
  std::vector<std::pair<std::size_t, std::size_t>> text;  ///< [begin, end) of non-blank text
  std::size_t offset = 0;                           ///< byte offset of its '<'

  /// The value of attribute `key`, or nullptr when absent.
  [[nodiscard]] const std::string* attribute(std::string_view key) const;
};

/// A parsed document; elements[0] is the root.
struct Document {
  std::string_view text;            ///< the parsed text (owned by the caller)
  std::vector<Element> elements;
  /// Index of the <AppendedData> element, if any.
  std::optional<std::size_t> appended_element;
  /// Byte offset of the first byte after <AppendedData>'s '_' marker.
  std::size_t appended_begin = 0;

  [[nodiscard]] const Element& root() const { return elements.front(); }
  /// Children of `parent` named `name`, in document order.
  [[nodiscard]] std::vector<const Element*> children(const Element& parent, std::string_view name) const;
  /// The only child of `parent` named `name`: nullptr if none, an error if several.
  [[nodiscard]] const Element* only_child(const Element& parent, std::string_view name,
                                          const std::filesystem::path& file) const;
};

/// Parses `text`; throws isohex::Error "FILE: line L (byte B): fault" on malformed XML.
Document parse(std::string_view text, const std::filesystem::path& file);

/// "line L (byte B)" for byte offset `offset` of `text`, for error messages.
std::string position(std::string_view text, std::size_t offset);

}  // namespace isohex::io::xml
