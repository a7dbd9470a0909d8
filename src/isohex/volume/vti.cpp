// VTK XML ImageData (.vti). The reader takes every layout VTK writes (ascii, inline base64,
// appended raw or base64, zlib-compressed, UInt32 or UInt64 headers, either byte order)
// through the XML parser and DataArray decoder of the .vtu reader (io/xml_lite,
// io/vtk_xml_data); it reads the point array named by PointData's Scalars attribute, else
// the first one-component point array. The writer writes appended raw data, uncompressed,
// in the volume's storage type.
#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/format_support.hpp"
#include "isohex/io/text_scanner.hpp"
#include "isohex/io/vtk_xml_data.hpp"
#include "isohex/io/vtk_xml_settings.hpp"
#include "isohex/io/xml_lite.hpp"
#include "isohex/volume/decode.hpp"
#include "isohex/volume/formats.hpp"

#include <fmt/format.h>

#include <cmath>
#include <ostream>

namespace isohex::volume_detail {

namespace {

namespace fs = std::filesystem;
namespace vtkxml = io::vtkxml;
namespace xml = io::xml;

ScalarType to_scalar_type(vtkxml::Scalar s) {
  switch (s) {
    case vtkxml::Scalar::Int8:
      return ScalarType::i8;
    case vtkxml::Scalar::UInt8:
      return ScalarType::u8;
    case vtkxml::Scalar::Int16:
      return ScalarType::i16;
    case vtkxml::Scalar::UInt16:
      return ScalarType::u16;
    case vtkxml::Scalar::Int32:
      return ScalarType::i32;
    case vtkxml::Scalar::UInt32:
      return ScalarType::u32;
    case vtkxml::Scalar::Float32:
      return ScalarType::f32;
    default:
      return ScalarType::f64;  // Float64, and 64-bit integers (as float values anyway)
  }
}

const char* vtk_type_name(ScalarType t) {
  switch (t) {
    case ScalarType::u8:
      return "UInt8";
    case ScalarType::i8:
      return "Int8";
    case ScalarType::u16:
      return "UInt16";
    case ScalarType::i16:
      return "Int16";
    case ScalarType::u32:
      return "UInt32";
    case ScalarType::i32:
      return "Int32";
    case ScalarType::f32:
      return "Float32";
    case ScalarType::f64:
      break;
  }
  return "Float64";
}

class VtiReader {
 public:
  VtiReader(const fs::path& file, const VolumeReadOptions& options)
      : file_(file), options_(options), text_(io::read_file(file)), doc_(xml::parse(text_, file)), ctx_{file_, text_} {}

  Volume run() {
    vtkxml::read_settings(doc_, "ImageData", "ImageData (.vti) volumes", ctx_);
    const xml::Element* image = doc_.only_child(doc_.root(), "ImageData", file_);
    if (!image) fail(doc_.root().offset, "<VTKFile> has no <ImageData> element");
    const std::array<std::int64_t, 6> whole = extent(*image, "WholeExtent");
    const Vec3 origin = numbers<3>(*image, "Origin", Vec3::Zero());
    const Vec3 spacing = numbers<3>(*image, "Spacing", Vec3::Ones());
    check_vector(file_, where(*image, "Spacing"), spacing, true);
    Eigen::Matrix<double, 9, 1> identity;
    identity << 1, 0, 0, 0, 1, 0, 0, 0, 1;
    const Eigen::Matrix<double, 9, 1> dir = numbers<9>(*image, "Direction", identity);
    Eigen::Matrix3d direction;
    for (int i = 0; i < 9; ++i) direction(i / 3, i % 3) = dir[i];  // VTK lists it row by row

    const std::array<std::int64_t, 3> dims = {whole[1] - whole[0] + 1, whole[3] - whole[2] + 1,
                                              whole[5] - whole[4] + 1};
    const std::string dims_field = where(*image, "WholeExtent");
    check_dims(file_, dims_field, dims, options_);
    const std::vector<const xml::Element*> pieces = doc_.children(*image, "Piece");
    if (pieces.empty()) fail(image->offset, "<ImageData> has no <Piece> element");
    // The source type is the first piece's; every piece is checked before allocating.
    std::vector<const xml::Element*> arrays;
    for (const xml::Element* p : pieces) arrays.push_back(&point_array(*p));
    vtkxml::Scalar first_type;
    vtkxml::scalar_from_name(*arrays.front()->attribute("type"), first_type);
    Volume v = allocate_volume(file_, dims_field, dims, to_scalar_type(first_type), options_);

    std::vector<std::uint8_t> covered(pieces.size() > 1 ? v.size() : 0, 0);
    std::size_t filled = 0;
    for (std::size_t i = 0; i < pieces.size(); ++i) filled += read_piece(*pieces[i], *arrays[i], whole, v, covered);
    if (filled != v.size())
      fail(image->offset, fmt::format("the pieces cover {} of the {} points of WholeExtent", filled, v.size()));

    const Vec3 start(static_cast<double>(whole[0]), static_cast<double>(whole[2]), static_cast<double>(whole[4]));
    const Eigen::Matrix3d axes = direction * spacing.asDiagonal();
    place_grid(v, axes, origin + axes * start, file_, where(*image, "Direction"));
    return v;
  }

 private:
  [[noreturn]] void fail(std::size_t offset, std::string_view what) const {
    io::parse_error(file_, xml::position(text_, offset), what);
  }
  std::string where(const xml::Element& e, std::string_view attribute) const {
    return fmt::format("{}: <{}> {}", xml::position(text_, e.offset), e.name, attribute);
  }

  template <int N>
  Eigen::Matrix<double, N, 1> numbers(const xml::Element& e, std::string_view key,
                                      const Eigen::Matrix<double, N, 1>& fallback) const {
    const std::string* s = e.attribute(key);
    if (!s) return fallback;
    Eigen::Matrix<double, N, 1> v;
    if (!parse_numbers(*s, v.data(), N))
      fail(e.offset, fmt::format("<{}> {}=\"{}\" is not {} finite numbers", e.name, key, io::printable(*s), N));
    return v;
  }

  std::array<std::int64_t, 6> extent(const xml::Element& e, std::string_view key) const {
    const std::string* s = e.attribute(key);
    if (!s) fail(e.offset, fmt::format("<{}> has no {} attribute", e.name, key));
    double d[6];
    std::array<std::int64_t, 6> out{};
    bool ok = parse_numbers(*s, d, 6);
    for (int i = 0; ok && i < 6; ++i) {
      ok = std::abs(d[i]) <= 4e18 && d[i] == std::trunc(d[i]);
      out[i] = ok ? static_cast<std::int64_t>(d[i]) : 0;
    }
    if (!ok) fail(e.offset, fmt::format("<{}> {}=\"{}\" is not 6 integers", e.name, key, io::printable(*s)));
    return out;
  }

  /// The piece's scalar point array: the one PointData's Scalars names, else the first
  /// with one component.
  const xml::Element& point_array(const xml::Element& piece) const {
    const xml::Element* pd = doc_.only_child(piece, "PointData", file_);
    if (!pd) fail(piece.offset, "<Piece> has no <PointData>: isohex reads volumes of point values");
    const std::string* wanted = pd->attribute("Scalars");
    const xml::Element* found = nullptr;
    for (const xml::Element* a : doc_.children(*pd, "DataArray")) {
      const std::string* name = a->attribute("Name");
      const std::string* comps = a->attribute("NumberOfComponents");
      const bool scalar = !comps || *comps == "1";
      if (wanted ? (name && *name == *wanted) : scalar) {
        if (!scalar)
          fail(a->offset, fmt::format("DataArray '{}' has {} components; isohex reads a scalar (1-component) array",
                                      io::printable(*wanted), io::printable(*comps)));
        found = a;
        break;
      }
    }
    if (!found)
      fail(pd->offset, wanted ? fmt::format("<PointData> names Scalars=\"{}\", but has no DataArray of that name",
                                            io::printable(*wanted))
                              : std::string("<PointData> has no one-component DataArray"));
    const std::string* type = found->attribute("type");
    vtkxml::Scalar s;
    if (!type || !vtkxml::scalar_from_name(*type, s))
      fail(found->offset,
           fmt::format("DataArray has unsupported type '{}'", type ? io::printable(*type) : std::string("(none)")));
    return *found;
  }

  std::size_t read_piece(const xml::Element& piece, const xml::Element& array, const std::array<std::int64_t, 6>& whole,
                         Volume& v, std::vector<std::uint8_t>& covered) const {
    const std::array<std::int64_t, 6> ext = extent(piece, "Extent");
    for (int a = 0; a < 3; ++a)
      if (ext[2 * a] > ext[2 * a + 1] || ext[2 * a] < whole[2 * a] || ext[2 * a + 1] > whole[2 * a + 1])
        fail(piece.offset, fmt::format("<Piece> Extent [{}, {}] along {} is empty or outside WholeExtent [{}, {}]",
                                       ext[2 * a], ext[2 * a + 1], "xyz"[a], whole[2 * a], whole[2 * a + 1]));
    const std::array<Index, 3> n = {static_cast<Index>(ext[1] - ext[0] + 1), static_cast<Index>(ext[3] - ext[2] + 1),
                                    static_cast<Index>(ext[5] - ext[4] + 1)};
    const std::array<Index, 3> at = {static_cast<Index>(ext[0] - whole[0]), static_cast<Index>(ext[2] - whole[2]),
                                     static_cast<Index>(ext[4] - whole[4])};
    const std::size_t count = static_cast<std::size_t>(n[0]) * static_cast<std::size_t>(n[1]) * n[2];
    const vtkxml::Array values = vtkxml::decode(array, count, ctx_);
    std::size_t newly = 0;
    vtkxml::visit(values, [&](auto view) {
      std::size_t src = 0;
      for (Index k = 0; k < n[2]; ++k)
        for (Index j = 0; j < n[1]; ++j)
          for (Index i = 0; i < n[0]; ++i, ++src) {
            const std::size_t dst = v.index(at[0] + i, at[1] + j, at[2] + k);
            v.values[dst] = static_cast<float>(view[src]);
            if (covered.empty())
              ++newly;
            else if (!covered[dst])
              covered[dst] = 1, ++newly;
          }
    });
    return newly;
  }

  const fs::path& file_;
  const VolumeReadOptions& options_;
  std::string text_;
  xml::Document doc_;
  vtkxml::Context ctx_;
};

}  // namespace

Volume read_vti(const fs::path& file, const VolumeReadOptions& options) { return VtiReader(file, options).run(); }

void write_vti(const fs::path& file, const Volume& volume) {
  const ScalarType type = storage_type(volume);
  const Index nx = volume.dims[0] - 1, ny = volume.dims[1] - 1, nz = volume.dims[2] - 1;
  io::write_atomically(file, [&](std::ostream& os) {
    const std::string extent = fmt::format("0 {} 0 {} 0 {}", nx, ny, nz);
    os << fmt::format(
        "<?xml version=\"1.0\"?>\n"
        "<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
        "  <ImageData WholeExtent=\"{0}\" Origin=\"{1:.17g} {2:.17g} {3:.17g}\" Spacing=\"{4:.17g} {5:.17g} {6:.17g}\" "
        "Direction=\"1 0 0 0 1 0 0 0 1\">\n"
        "    <Piece Extent=\"{0}\">\n"
        "      <PointData Scalars=\"values\">\n"
        "        <DataArray type=\"{7}\" Name=\"values\" format=\"appended\" offset=\"0\"/>\n"
        "      </PointData>\n"
        "      <CellData>\n      </CellData>\n"
        "    </Piece>\n"
        "  </ImageData>\n"
        "  <AppendedData encoding=\"raw\">\n   _",
        extent, volume.origin.x(), volume.origin.y(), volume.origin.z(), volume.spacing.x(), volume.spacing.y(),
        volume.spacing.z(), vtk_type_name(type));
    unsigned char header[8];
    std::uint64_t bytes = volume.size() * scalar_type_size(type);
    for (unsigned char& b : header) b = static_cast<unsigned char>(bytes & 0xff), bytes >>= 8;  // little-endian
    os.write(reinterpret_cast<const char*>(header), sizeof header);
    write_samples_le(os, volume, type);
    os << "\n  </AppendedData>\n</VTKFile>\n";
  });
}

}  // namespace isohex::volume_detail
