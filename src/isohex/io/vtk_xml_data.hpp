#pragma once
/// \file vtk_xml_data.hpp
/// \brief Decoding the data of one VTK XML `<DataArray>`: ascii, base64 `binary`, and
/// `appended` (raw or base64), uncompressed or zlib-compressed, either byte order.
///
/// Binary data is preceded by a header of UInt32 or UInt64 words (VTKFile's header_type):
/// uncompressed, one word with the byte count; zlib-compressed, [number of blocks,
/// uncompressed block size, uncompressed size of the last block (0: full), compressed size
/// of each block], then the blocks, each a complete zlib stream. Every declared size is
/// checked against the expected value count and the bytes the file holds before anything
/// is allocated, so that corrupt headers cannot trigger huge allocations.

#include "isohex/io/xml_lite.hpp"

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string_view>
#include <vector>

namespace isohex::io::vtkxml {

/// The scalar types of VTK XML data arrays.
enum class Scalar : std::uint8_t { Int8, UInt8, Int16, UInt16, Int32, UInt32, Int64, UInt64, Float32, Float64 };

/// Parses a VTK XML type name ("Int32", "Float64", ...); false if it is not one.
bool scalar_from_name(std::string_view name, Scalar& out);
/// Bytes per value.
std::size_t scalar_size(Scalar s);
/// True for the integer types.
bool is_integer(Scalar s);

/// File-wide settings (from <VTKFile> and <AppendedData>) that govern array data.
struct Context {
  const std::filesystem::path& file;
  std::string_view text;            ///< the whole file
  bool big_endian = false;          ///< byte_order="BigEndian"
  std::size_t header_bytes = 4;     ///< 4 (UInt32) or 8 (UInt64)
  bool zlib = false;                ///< compressor="vtkZLibDataCompressor"
  bool has_appended = false;        ///< an <AppendedData> element exists
  bool appended_base64 = false;     ///< its encoding is base64 rather than raw
  std::size_t appended_begin = 0;   ///< byte offset just past its '_'
};

/// Decoded values in native byte order. The bytes live in the array or, for uncompressed
/// raw appended data in native order, directly in the file text (no copy).
class Array {
 public:
  Array() = default;
  Array(Array&&) = default;
  Array& operator=(Array&&) = default;
  Array(const Array&) = delete;
  Array& operator=(const Array&) = delete;

  [[nodiscard]] Scalar type() const { return type_; }
  [[nodiscard]] std::size_t size() const { return size_; }
  [[nodiscard]] const unsigned char* data() const { return data_; }
  /// How the data was stored: "ascii", "binary", "appended raw" or "appended base64".
  [[nodiscard]] const char* format() const { return format_; }

 private:
  friend class Decoder;
  Scalar type_ = Scalar::UInt8;
  std::size_t size_ = 0;
  const unsigned char* data_ = nullptr;
  std::vector<unsigned char> storage_;
  const char* format_ = "";
};

/// Decodes the values of <DataArray> `element`, which must hold exactly `count` scalars
/// (tuples times components). Throws isohex::Error naming the file, the place and the fault.
Array decode(const xml::Element& element, std::size_t count, const Context& context);

/// Typed, alignment-safe read access to an Array's values.
template <class T>
struct View {
  const unsigned char* data;
  std::size_t n;
  T operator[](std::size_t i) const {
    T v;
    std::memcpy(&v, data + i * sizeof(T), sizeof(T));
    return v;
  }
  [[nodiscard]] std::size_t size() const { return n; }
};

/// Calls `fn(View<T>)` with T the C++ type of the array's values.
template <class Fn>
decltype(auto) visit(const Array& a, Fn&& fn) {
  const unsigned char* d = a.data();
  const std::size_t n = a.size();
  switch (a.type()) {
    case Scalar::Int8: return fn(View<std::int8_t>{d, n});
    case Scalar::UInt8: return fn(View<std::uint8_t>{d, n});
    case Scalar::Int16: return fn(View<std::int16_t>{d, n});
    case Scalar::UInt16: return fn(View<std::uint16_t>{d, n});
    case Scalar::Int32: return fn(View<std::int32_t>{d, n});
    case Scalar::UInt32: return fn(View<std::uint32_t>{d, n});
    case Scalar::Int64: return fn(View<std::int64_t>{d, n});
    case Scalar::UInt64: return fn(View<std::uint64_t>{d, n});
    case Scalar::Float32: return fn(View<float>{d, n});
    case Scalar::Float64: break;
  }
  return fn(View<double>{d, n});
}

}  // namespace isohex::io::vtkxml
