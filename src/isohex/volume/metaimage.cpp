// MetaImage (ITK/VTK MetaIO): "Key = Value" header lines ending with ElementDataFile, which
// is LOCAL (data follows, .mha) or names a data file (.mhd). Binary data, raw or zlib
// (CompressedData), either byte order; ASCII data (BinaryData = False).
#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/format_support.hpp"
#include "isohex/io/text_scanner.hpp"
#include "isohex/volume/decode.hpp"
#include "isohex/volume/formats.hpp"

#include <fmt/format.h>

#include <optional>

namespace isohex::volume_detail {

namespace {

namespace fs = std::filesystem;

struct MetaHeader {
  std::optional<std::array<std::int64_t, 3>> dims;
  std::optional<ScalarType> type;
  std::optional<Vec3> spacing, size;  // ElementSpacing, ElementSize (the fallback)
  Vec3 origin = Vec3::Zero();
  Eigen::Matrix3d directions = Eigen::Matrix3d::Identity();  // row i: direction of axis i
  bool msb = false, binary = true, compressed = false;
  std::int64_t header_size = 0;
  std::string data_file;        // "LOCAL" or a path
  std::size_t data_offset = 0;  // LOCAL: where the data starts
};

std::optional<ScalarType> meta_type(std::string_view name) {
  // MetaIO's MET_LONG and MET_ULONG are 4 bytes, whatever the platform's long.
  static constexpr std::pair<std::string_view, ScalarType> kTypes[] = {
      {"MET_UCHAR", ScalarType::u8},  {"MET_CHAR", ScalarType::i8},  {"MET_USHORT", ScalarType::u16},
      {"MET_SHORT", ScalarType::i16}, {"MET_UINT", ScalarType::u32}, {"MET_INT", ScalarType::i32},
      {"MET_ULONG", ScalarType::u32}, {"MET_LONG", ScalarType::i32}, {"MET_FLOAT", ScalarType::f32},
      {"MET_DOUBLE", ScalarType::f64}};
  for (const auto& [n, t] : kTypes)
    if (lowercase(n) == lowercase(name)) return t;
  return std::nullopt;
}

class HeaderParser {
 public:
  HeaderParser(const fs::path& file, std::string_view text) : file_(file), text_(text) {}

  MetaHeader run() {
    std::size_t pos = 0, line = 0;
    bool ended = false;
    while (pos < text_.size() && !ended) {
      std::size_t end = text_.find('\n', pos);
      if (end == std::string_view::npos) end = text_.size();
      const std::string_view raw = trim(text_.substr(pos, end - pos));
      pos = std::min(end + 1, text_.size());
      ++line;
      if (raw.empty()) continue;
      const std::size_t eq = raw.find('=');
      if (eq == std::string_view::npos)
        fail(file_, fmt::format("line {}", line), fmt::format("'{}' is not a 'Key = Value' line", io::printable(raw)));
      const std::string key = lowercase(trim(raw.substr(0, eq)));
      const std::string_view value = trim(raw.substr(eq + 1));
      ended = key == "elementdatafile";
      field(key, value);
    }
    if (!ended) fail(file_, "ElementDataFile", "is missing (it must be the header's last line)");
    h_.data_offset = pos;
    if (!h_.dims) fail(file_, "DimSize", "is missing");
    if (!h_.type) fail(file_, "ElementType", "is missing");
    if (!ndims_seen_) fail(file_, "NDims", "is missing");
    return h_;
  }

 private:
  Vec3 vector(std::string_view key, std::string_view value) const {
    double v[3];
    if (!parse_numbers(value, v, 3)) fail(file_, key, fmt::format("'{}' is not 3 numbers", io::printable(value)));
    return {v[0], v[1], v[2]};
  }

  bool boolean(std::string_view key, std::string_view value) const {
    const std::string v = lowercase(value);
    if (v == "true" || v == "1") return true;
    if (v == "false" || v == "0") return false;
    fail(file_, key, fmt::format("'{}' is neither True nor False", io::printable(value)));
  }

  void field(const std::string& key, std::string_view value) {
    if (key == "objecttype") {
      if (lowercase(value) != "image")
        fail(file_, "ObjectType", fmt::format("'{}' is not Image", io::printable(value)));
    } else if (key == "ndims") {
      std::int64_t n = 0;
      if (!io::parse_int(value, n)) fail(file_, "NDims", fmt::format("'{}' is not an integer", io::printable(value)));
      if (n != 3) fail(file_, "NDims", fmt::format("isohex reads 3-D volumes; this one has NDims {}", n));
      ndims_seen_ = true;
    } else if (key == "dimsize") {
      std::array<std::int64_t, 3> d{};
      double v[3];
      if (!parse_numbers(value, v, 3)) fail(file_, "DimSize", fmt::format("'{}' is not 3 sizes", io::printable(value)));
      for (int a = 0; a < 3; ++a) {
        if (!(v[a] >= -9e18 && v[a] <= 9e18) || v[a] != static_cast<double>(static_cast<std::int64_t>(v[a])))
          fail(file_, "DimSize", fmt::format("'{}' is not 3 integers", io::printable(value)));
        d[a] = static_cast<std::int64_t>(v[a]);
      }
      h_.dims = d;
    } else if (key == "elementtype") {
      h_.type = meta_type(value);
      if (!h_.type)
        fail(file_, "ElementType",
             fmt::format("unsupported type '{}' (isohex reads MET_UCHAR, MET_CHAR, MET_USHORT, "
                         "MET_SHORT, MET_UINT, MET_INT, MET_FLOAT, MET_DOUBLE)",
                         io::printable(value)));
    } else if (key == "elementspacing") {
      h_.spacing = vector("ElementSpacing", value);
    } else if (key == "elementsize") {
      h_.size = vector("ElementSize", value);
    } else if (key == "offset" || key == "origin" || key == "position") {
      h_.origin = vector("Offset", value);
    } else if (key == "transformmatrix" || key == "rotation" || key == "orientation") {
      double m[9];
      if (!parse_numbers(value, m, 9)) fail(file_, "TransformMatrix", "is not 9 numbers");
      for (int i = 0; i < 9; ++i) h_.directions(i / 3, i % 3) = m[i];
    } else if (key == "elementbyteordermsb" || key == "binarydatabyteordermsb") {
      h_.msb = boolean(key == "elementbyteordermsb" ? "ElementByteOrderMSB" : "BinaryDataByteOrderMSB", value);
    } else if (key == "binarydata") {
      h_.binary = boolean("BinaryData", value);
    } else if (key == "compresseddata") {
      h_.compressed = boolean("CompressedData", value);
    } else if (key == "headersize") {
      if (!io::parse_int(value, h_.header_size) || h_.header_size < -1)
        fail(file_, "HeaderSize", fmt::format("'{}' is not an integer >= -1", io::printable(value)));
    } else if (key == "elementnumberofchannels") {
      if (value != "1")
        fail(file_, "ElementNumberOfChannels",
             fmt::format("is {}; isohex reads scalar volumes (1)", io::printable(value)));
    } else if (key == "elementdatafile") {
      if (value.empty()) fail(file_, "ElementDataFile", "is empty");
      if (lowercase(value).starts_with("list") || value.find('%') != std::string_view::npos)
        fail(file_, "ElementDataFile", "file lists and numbered series are not supported; use one data file or LOCAL");
      h_.data_file = std::string(value);
    }
    // Other keys (AnatomicalOrientation, CenterOfRotation, ElementMin/Max, ...) do not change the values.
  }

  const fs::path& file_;
  std::string_view text_;
  MetaHeader h_;
  bool ndims_seen_ = false;
};

}  // namespace

Volume read_metaimage(const fs::path& file, const VolumeReadOptions& options) {
  const MetaHeader h = parse_header(file, [&](std::string_view text, bool) { return HeaderParser(file, text).run(); });
  const std::size_t count = check_dims(file, "DimSize", *h.dims, options);
  const Vec3 spacing = h.spacing ? *h.spacing : h.size.value_or(Vec3::Ones());
  check_vector(file, h.spacing ? "ElementSpacing" : "ElementSize", spacing, true);

  const bool local = lowercase(h.data_file) == "local";
  fs::path data = local ? file : fs::path(h.data_file);
  if (!local && data.is_relative()) data = file.parent_path() / data;
  if (!local && !fs::exists(data))
    fail(file, "ElementDataFile", fmt::format("data file {} does not exist", data.string()));
  const std::size_t bytes = count * scalar_type_size(*h.type);
  std::size_t offset = local ? h.data_offset : 0;
  if (h.header_size == -1) {
    if (h.compressed || !h.binary) fail(file, "HeaderSize", "-1 (data at the end) needs uncompressed binary data");
    const std::size_t size = size_of_file(data);
    if (size < bytes + offset)
      fail(data, "data", fmt::format("has {} bytes, fewer than the {} that DimSize and ElementType need", size, bytes));
    offset = size - bytes;
  } else {
    offset += static_cast<std::size_t>(h.header_size);
  }
  if (h.binary && !h.compressed) {
    const std::size_t size = size_of_file(data);
    if (size < offset || size - offset < bytes)
      fail(data, "data",
           fmt::format("has {} bytes of data after byte {}, but DimSize {} x {} x {} of {} needs {} "
                       "(truncated, or the header lies)",
                       size > offset ? size - offset : 0, offset, (*h.dims)[0], (*h.dims)[1], (*h.dims)[2],
                       scalar_type_name(*h.type), bytes));
  }

  Volume v = allocate_volume(file, "DimSize", *h.dims, *h.type, options);
  if (!h.binary) {
    const std::string text = io::read_file(data);
    io::TextScanner scanner(text, data, offset);
    read_ascii_samples(scanner, v, "ASCII data");
  } else {
    FileSource src(data, offset);
    if (h.compressed) {
      InflateSource inflated(src, data, "compressed data");
      read_samples(inflated, *h.type, h.msb, v, data, "compressed data");
    } else {
      read_samples(src, *h.type, h.msb, v, data, "data");
    }
  }
  Eigen::Matrix3d axes;
  for (int j = 0; j < 3; ++j) axes.col(j) = h.directions.row(j).transpose() * spacing[j];
  place_grid(v, axes, h.origin, file, "TransformMatrix");
  return v;
}

}  // namespace isohex::volume_detail
