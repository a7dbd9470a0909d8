#include "isohex/io/vtk_xml_settings.hpp"

#include "isohex/io/text_scanner.hpp"

#include <fmt/format.h>

#include <string>

namespace isohex::io::vtkxml {

void read_settings(const xml::Document& doc, std::string_view type, std::string_view what, Context& ctx) {
  const auto fail = [&](std::size_t offset, std::string_view message) {
    parse_error(ctx.file, xml::position(ctx.text, offset), message);
  };
  const xml::Element& root = doc.root();
  if (root.name != "VTKFile")
    fail(root.offset, fmt::format("not a VTK XML file: the root element is <{}>, not <VTKFile>", root.name));
  const std::string* file_type = root.attribute("type");
  if (!file_type || *file_type != type)
    fail(root.offset, fmt::format("VTK XML file of type '{}'; only {} can be read",
                                  file_type ? *file_type : std::string("(none)"), what));
  if (const std::string* order = root.attribute("byte_order")) {
    if (*order != "LittleEndian" && *order != "BigEndian")
      fail(root.offset, fmt::format("unknown byte_order '{}' (expected LittleEndian or BigEndian)", *order));
    ctx.big_endian = *order == "BigEndian";
  }
  if (const std::string* header = root.attribute("header_type")) {
    if (*header != "UInt32" && *header != "UInt64")
      fail(root.offset, fmt::format("unknown header_type '{}' (expected UInt32 or UInt64)", *header));
    ctx.header_bytes = *header == "UInt64" ? 8 : 4;
  }
  if (const std::string* compressor = root.attribute("compressor")) {
    if (*compressor != "vtkZLibDataCompressor")
      fail(root.offset, fmt::format("compressor '{}' is not supported; isohex reads uncompressed data and "
                                    "vtkZLibDataCompressor (zlib) only",
                                    *compressor));
    ctx.zlib = true;
  }
  if (doc.appended_element) {
    const xml::Element& app = doc.elements[*doc.appended_element];
    const std::string* encoding = app.attribute("encoding");
    if (!encoding || (*encoding != "raw" && *encoding != "base64"))
      fail(app.offset, "<AppendedData> needs encoding=\"raw\" or encoding=\"base64\"");
    ctx.has_appended = true;
    ctx.appended_base64 = *encoding == "base64";
    ctx.appended_begin = doc.appended_begin;
  }
}

}  // namespace isohex::io::vtkxml
