// Writer for VTK XML UnstructuredGrid (.vtu) files, laid out as VTK's own writer does:
// appended raw data with UInt64 headers, zlib-compressed in 32 KiB blocks by default,
// or inline ascii DataArrays. Arrays are serialized chunk by chunk, never copied whole.
#include "isohex/io/mesh_io.hpp"

#include "isohex/error.hpp"
#include "isohex/io/atomic_file.hpp"
#include "isohex/io/format_support.hpp"

#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <zlib.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace isohex::io {

namespace {

namespace fs = std::filesystem;

/// Uncompressed size of each zlib block, as VTK writes them.
constexpr std::size_t kBlockBytes = 32768;
/// Blocks compressed in parallel per round: bounds the uncompressed staging memory.
constexpr std::size_t kBlocksPerRound = 256;
/// Values per staging chunk when streaming uncompressed or ascii data.
constexpr std::size_t kChunkValues = 1 << 16;
constexpr std::uint8_t kVtkHexahedron = 12;
/// Mesh data (random-looking coordinates, small-integer ids) compresses almost as well at
/// zlib's fastest level as at its default (within 0.5% on a 1M-hex ball), 2-3x faster.
constexpr int kZlibLevel = Z_BEST_SPEED;

/// One DataArray: its XML description and a generator of its values.
struct Column {
  const char* section;  ///< "PointData", "CellData", "Points" or "Cells"
  const char* name;
  const char* type;     ///< "UInt8", "Int32", "Int64" or "Float64"
  std::size_t value_size;
  int components;
  std::size_t count;    ///< number of values (tuples times components)
  /// Writes values [first, first+n) in native byte order to `out`.
  std::function<void(std::size_t first, std::size_t n, unsigned char* out)> fill;
  int per_line;         ///< ascii values per line

  [[nodiscard]] std::size_t bytes() const { return count * value_size; }
};

template <class T>
void store(unsigned char* out, std::size_t i, T v) {
  std::memcpy(out + i * sizeof(T), &v, sizeof(T));
}

/// The mesh's arrays, in the order VTK writes them. Their generators check the data, so an
/// invalid mesh fails in mid-write (and write_atomically discards the partial file).
std::vector<Column> columns(const fs::path& file, const HexMesh& mesh, const WriteOptions& options) {
  const std::size_t np = mesh.points.size(), nh = mesh.hexes.size();
  if (mesh.has_blocks() && mesh.blocks.size() != nh)
    throw Error(fmt::format("{}: cannot write: {} block ids for {} hexes", file.string(), mesh.blocks.size(), nh));
  if (mesh.has_fixed() && mesh.fixed.size() != np)
    throw Error(fmt::format("{}: cannot write: {} fixed flags for {} vertices", file.string(), mesh.fixed.size(), np));
  std::vector<Column> cols;
  if (mesh.has_fixed())
    cols.push_back({"PointData", "fixed", "UInt8", 1, 1, np,
                    [&mesh](std::size_t f, std::size_t n, unsigned char* out) {
                      for (std::size_t i = 0; i < n; ++i) out[i] = mesh.fixed[f + i] ? 1 : 0;
                    },
                    20});
  // The fields (checked before the write began) as Float64 arrays.
  const auto field = [](const char* section, const DataField& d) {
    return Column{section, d.name.c_str(), "Float64", 8, 1, d.values.size(),
                  [&d](std::size_t f, std::size_t n, unsigned char* out) {
                    std::memcpy(out, d.values.data() + f, n * sizeof(double));
                  },
                  6};
  };
  for (const DataField& d : options.point_fields) cols.push_back(field("PointData", d));
  if (mesh.has_blocks())
    cols.push_back({"CellData", "block", "Int32", 4, 1, nh,
                    [&mesh](std::size_t f, std::size_t n, unsigned char* out) {
                      std::memcpy(out, mesh.blocks.data() + f, n * sizeof(Index));
                    },
                    10});
  for (const DataField& d : options.cell_fields) cols.push_back(field("CellData", d));
  cols.push_back({"Points", "Points", "Float64", 8, 3, 3 * np,
                  [&mesh, &file](std::size_t f, std::size_t n, unsigned char* out) {
                    for (std::size_t i = 0; i < n; ++i) {
                      const double v = mesh.points[(f + i) / 3][static_cast<Eigen::Index>((f + i) % 3)];
                      if (!std::isfinite(v))
                        throw Error(fmt::format("{}: cannot write: vertex {} has a non-finite coordinate",
                                                file.string(), (f + i) / 3));
                      store(out, i, v);
                    }
                  },
                  6});
  cols.push_back({"Cells", "connectivity", "Int64", 8, 1, 8 * nh,
                  [&mesh, &file, np](std::size_t f, std::size_t n, unsigned char* out) {
                    for (std::size_t i = 0; i < n; ++i) {
                      const Index id = mesh.hexes[(f + i) / 8][(f + i) % 8];
                      if (id < 0 || static_cast<std::size_t>(id) >= np)
                        throw Error(fmt::format("{}: cannot write: hex {} refers to vertex {}, but the mesh has {}",
                                                file.string(), (f + i) / 8, id, np));
                      store(out, i, std::int64_t{id});
                    }
                  },
                  8});
  cols.push_back({"Cells", "offsets", "Int64", 8, 1, nh,
                  [](std::size_t f, std::size_t n, unsigned char* out) {
                    for (std::size_t i = 0; i < n; ++i) store(out, i, static_cast<std::int64_t>(8 * (f + i + 1)));
                  },
                  10});
  cols.push_back({"Cells", "types", "UInt8", 1, 1, nh,
                  [](std::size_t, std::size_t n, unsigned char* out) { std::memset(out, kVtkHexahedron, n); }, 20});
  return cols;
}

void put_u64(std::string& s, std::uint64_t v) { s.append(reinterpret_cast<const char*>(&v), sizeof v); }

/// A column compressed as VTK does: header [nblocks, block size, last block size, sizes...]
/// then the blocks. Blocks are compressed in parallel, a round at a time.
std::string compress_column(const fs::path& file, const Column& c) {
  const std::size_t total = c.bytes();
  const std::size_t nblocks = (total + kBlockBytes - 1) / kBlockBytes;
  std::vector<std::uint64_t> sizes;
  std::string data;
  std::vector<unsigned char> raw;
  std::vector<std::vector<unsigned char>> packed(std::min(nblocks, kBlocksPerRound));
  for (std::size_t first = 0; first < nblocks; first += kBlocksPerRound) {
    const std::size_t last = std::min(nblocks, first + kBlocksPerRound);
    const std::size_t begin = first * kBlockBytes, end = std::min(total, last * kBlockBytes);
    raw.resize(end - begin);
    c.fill(begin / c.value_size, (end - begin) / c.value_size, raw.data());
    tbb::parallel_for(first, last, [&](std::size_t b) {
      const std::size_t off = b * kBlockBytes - begin;
      const std::size_t len = std::min(kBlockBytes, end - begin - off);
      std::vector<unsigned char>& out = packed[b - first];
      uLongf out_len = compressBound(len);
      out.resize(out_len);
      if (compress2(out.data(), &out_len, raw.data() + off, len, kZlibLevel) != Z_OK)
        throw Error(fmt::format("{}: zlib compression failed", file.string()));
      out.resize(out_len);
    });
    for (std::size_t b = first; b < last; ++b) {
      sizes.push_back(packed[b - first].size());
      data.append(reinterpret_cast<const char*>(packed[b - first].data()), packed[b - first].size());
    }
  }
  std::string out;
  out.reserve((3 + nblocks) * 8 + data.size());
  put_u64(out, nblocks);
  put_u64(out, kBlockBytes);
  put_u64(out, total % kBlockBytes);
  for (std::uint64_t s : sizes) put_u64(out, s);
  out += data;
  return out;
}

/// Streams an uncompressed column (header word, then the values) to `os`.
void write_raw_column(std::ostream& os, const Column& c) {
  const std::uint64_t header = c.bytes();
  os.write(reinterpret_cast<const char*>(&header), sizeof header);
  std::vector<unsigned char> buf(std::min(c.count, kChunkValues) * c.value_size);
  for (std::size_t f = 0; f < c.count; f += kChunkValues) {
    const std::size_t n = std::min(kChunkValues, c.count - f);
    c.fill(f, n, buf.data());
    os.write(reinterpret_cast<const char*>(buf.data()), static_cast<std::streamsize>(n * c.value_size));
  }
}

/// Writes a column's values as text: integers exactly, doubles with 17 significant digits.
void write_ascii_values(std::ostream& os, const Column& c) {
  std::vector<unsigned char> buf(std::min(c.count, kChunkValues) * c.value_size);
  fmt::memory_buffer text;
  std::size_t on_line = 0;
  for (std::size_t f = 0; f < c.count; f += kChunkValues) {
    const std::size_t n = std::min(kChunkValues, c.count - f);
    c.fill(f, n, buf.data());
    for (std::size_t i = 0; i < n; ++i) {
      if (on_line == 0) text.append(std::string_view("          "));
      const unsigned char* p = buf.data() + i * c.value_size;
      if (c.value_size == 1) {
        fmt::format_to(std::back_inserter(text), "{}", unsigned{*p});
      } else if (c.value_size == 4) {
        std::int32_t v;
        std::memcpy(&v, p, 4);
        fmt::format_to(std::back_inserter(text), "{}", v);
      } else if (c.type[0] == 'F') {
        double v;
        std::memcpy(&v, p, 8);
        fmt::format_to(std::back_inserter(text), "{:.17g}", v);
      } else {
        std::int64_t v;
        std::memcpy(&v, p, 8);
        fmt::format_to(std::back_inserter(text), "{}", v);
      }
      const bool end_line = ++on_line == static_cast<std::size_t>(c.per_line) || f + i + 1 == c.count;
      text.push_back(end_line ? '\n' : ' ');
      if (end_line) on_line = 0;
    }
    os.write(text.data(), static_cast<std::streamsize>(text.size()));
    text.clear();
  }
}

const char* byte_order() { return std::endian::native == std::endian::big ? "BigEndian" : "LittleEndian"; }

/// Writes the XML up to the end of <UnstructuredGrid>: sections in VTK's order, each
/// DataArray written by `array`, which gets the column and its index.
void write_xml_head(std::ostream& os, const HexMesh& mesh, const std::vector<Column>& cols, bool compress,
                    const std::function<void(std::ostream&, const Column&, std::size_t)>& array) {
  os << "<?xml version=\"1.0\"?>\n"
     << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"" << byte_order()
     << "\" header_type=\"UInt64\"" << (compress ? " compressor=\"vtkZLibDataCompressor\"" : "") << ">\n"
     << "  <UnstructuredGrid>\n"
     << "    <Piece NumberOfPoints=\"" << mesh.points.size() << "\" NumberOfCells=\"" << mesh.hexes.size() << "\">\n";
  for (const char* section : {"PointData", "CellData", "Points", "Cells"}) {
    os << "      <" << section << ">\n";
    for (std::size_t i = 0; i < cols.size(); ++i)
      if (std::strcmp(cols[i].section, section) == 0) array(os, cols[i], i);
    os << "      </" << section << ">\n";
  }
  os << "    </Piece>\n  </UnstructuredGrid>\n";
}

std::string array_attributes(const Column& c, const char* format) {
  std::string s = fmt::format("<DataArray type=\"{}\" Name=\"{}\"", c.type, c.name);
  if (c.components != 1) s += fmt::format(" NumberOfComponents=\"{}\"", c.components);
  return s + fmt::format(" format=\"{}\"", format);
}

void write_appended(std::ostream& os, const fs::path& file, const HexMesh& mesh, const std::vector<Column>& cols,
                    bool compress) {
  std::vector<std::string> packed;
  std::vector<std::uint64_t> offsets;
  std::uint64_t offset = 0;
  for (const Column& c : cols) {
    offsets.push_back(offset);
    if (compress) {
      packed.push_back(compress_column(file, c));
      offset += packed.back().size();
    } else {
      offset += 8 + c.bytes();
    }
  }
  write_xml_head(os, mesh, cols, compress, [&](std::ostream& o, const Column& c, std::size_t i) {
    o << "        " << array_attributes(c, "appended") << " offset=\"" << offsets[i] << "\"/>\n";
  });
  os << "  <AppendedData encoding=\"raw\">\n   _";
  for (std::size_t i = 0; i < cols.size(); ++i) {
    if (compress)
      os.write(packed[i].data(), static_cast<std::streamsize>(packed[i].size()));
    else
      write_raw_column(os, cols[i]);
  }
  os << "\n  </AppendedData>\n</VTKFile>\n";
}

void write_ascii(std::ostream& os, const HexMesh& mesh, const std::vector<Column>& cols) {
  write_xml_head(os, mesh, cols, false, [](std::ostream& o, const Column& c, std::size_t) {
    o << "        " << array_attributes(c, "ascii") << ">\n";
    write_ascii_values(o, c);
    o << "        </DataArray>\n";
  });
  os << "</VTKFile>\n";
}

}  // namespace

void write_vtu(const fs::path& file, const HexMesh& mesh, const WriteOptions& options) {
  check_fields_for_writing(file, mesh, options);
  write_atomically(file, [&](std::ostream& os) {
    const std::vector<Column> cols = columns(file, mesh, options);
    if (options.binary)
      write_appended(os, file, mesh, cols, options.compress);
    else
      write_ascii(os, mesh, cols);
  });
}

}  // namespace isohex::io
