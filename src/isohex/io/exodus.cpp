// Exodus II (.exo, .e, .ex2) reader and writer, through Debian's libexodusii.
//
// The writer puts one HEX8 element block per isohex block (ids and names as in
// solver_sets.hpp), an element id map holding each hex's position in the mesh (so the
// reader restores the hex order although Exodus stores elements block by block), side set 1
// "boundary" with every boundary quad as (element, Exodus side), node set 1 "boundary" with
// the boundary nodes and, when the mesh has fixed vertices, node set 2 "fixed".
//
// The library keeps global state (its options and last error message), so every call into
// it holds one mutex. Its failures become isohex::Error naming the file and the step.
//
// It is opened on first use (dlopen), not linked: it pulls in some fifty shared libraries
// (netCDF, HDF5, Open MPI, GnuTLS, ICU, ...) whose loading was 25 of the 28 ms that every
// isohex command took to start (`isohex --version`), though few runs touch an Exodus file.

#include "isohex/error.hpp"
#include "isohex/io/format_support.hpp"
#include "isohex/io/mesh_io.hpp"
#include "isohex/io/solver_sets.hpp"

#include <exodusII.h>
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <dlfcn.h>
#include <cmath>
#include <mutex>
#include <numeric>
#include <string>
#include <unistd.h>
#include <vector>

namespace isohex::io {

namespace {

namespace fs = std::filesystem;

std::mutex& exodus_mutex() {
  static std::mutex m;
  return m;
}

// The library's functions this file calls, with their declared types.
#define ISOHEX_EXODUS_FUNCTIONS(X)                                                                                \
  X(ex_create_int) X(ex_open_int) X(ex_close) X(ex_opts) X(ex_get_err) X(ex_put_init) X(ex_put_coord)             \
  X(ex_put_coord_names) X(ex_put_elem_block) X(ex_put_elem_conn) X(ex_put_names) X(ex_put_id_map)                 \
  X(ex_put_side_set_param) X(ex_put_side_set) X(ex_put_node_set_param) X(ex_put_node_set) X(ex_get_names)        \
  X(ex_get_init) X(ex_get_coord) X(ex_get_id_map) X(ex_get_ids) X(ex_get_elem_block) X(ex_get_elem_conn)         \
  X(ex_get_node_set_param) X(ex_get_node_set) X(ex_put_variable_param) X(ex_put_variable_names) X(ex_put_time)   \
  X(ex_put_var)

struct ExodusApi {
#define ISOHEX_EXODUS_MEMBER(f) decltype(&::f) f = nullptr;
  ISOHEX_EXODUS_FUNCTIONS(ISOHEX_EXODUS_MEMBER)
#undef ISOHEX_EXODUS_MEMBER
};

const ExodusApi* loaded_api = nullptr;  // set by load_exodus(), under exodus_mutex()

/// Opens the library once (the caller holds exodus_mutex()); throws, naming `file`, where it
/// cannot be loaded.
void load_exodus(const fs::path& file) {
  static ExodusApi table;
  static std::string failure;
  static bool tried = false;
  if (!tried) {
    tried = true;
    // Never closed: the library's atexit handlers and buffers live as long as the process.
    if (void* lib = dlopen(ISOHEX_EXODUS_LIBRARY, RTLD_NOW | RTLD_LOCAL); !lib) {
      const char* why = dlerror();
      failure = fmt::format("cannot load {} (Debian package libexodusii5): {}", ISOHEX_EXODUS_LIBRARY,
                            why ? why : "unknown error");
    } else {
#define ISOHEX_EXODUS_BIND(f)                                                                  \
  table.f = reinterpret_cast<decltype(&::f)>(dlsym(lib, #f));                                     \
  if (!table.f && failure.empty()) failure = fmt::format("{} has no function {}", ISOHEX_EXODUS_LIBRARY, #f);
      ISOHEX_EXODUS_FUNCTIONS(ISOHEX_EXODUS_BIND)
#undef ISOHEX_EXODUS_BIND
    }
    if (failure.empty()) loaded_api = &table;
  }
  if (!loaded_api) throw Error(fmt::format("{}: Exodus II is not available: {}", file.string(), failure));
}

/// The library's functions, once load_exodus() has succeeded.
const ExodusApi& api() { return *loaded_api; }

/// The library's last error message, for an exception.
std::string last_exodus_error() {
  const char* msg = nullptr;
  const char* func = nullptr;
  int code = 0;
  api().ex_get_err(&msg, &func, &code);
  std::string out = msg && *msg ? msg : "unknown error";
  if (func && *func) out += fmt::format(" (in {})", func);
  return out;
}

/// Throws isohex::Error unless `status` is a success (>= 0; > 0 is a mere warning).
void check(int status, const fs::path& file, std::string_view step) {
  if (status < 0) throw Error(fmt::format("{}: Exodus II: {} failed: {}", file.string(), step, last_exodus_error()));
}

/// Closes the file when the scope ends, also on an exception.
class ExodusFile {
 public:
  explicit ExodusFile(int id) : id_(id) {}
  ExodusFile(const ExodusFile&) = delete;
  ExodusFile& operator=(const ExodusFile&) = delete;
  ~ExodusFile() {
    if (id_ >= 0) api().ex_close(id_);
  }
  [[nodiscard]] int id() const { return id_; }
  /// Closes now, reporting a failure (the final flush happens here).
  void close(const fs::path& file) {
    const int id = id_;
    id_ = -1;
    check(api().ex_close(id), file, "closing");
  }

 private:
  int id_;
};

/// Names as the library takes them: an array of writable C strings.
class NameList {
 public:
  explicit NameList(const std::vector<std::string>& names) : names_(names) {
    for (std::string& n : names_) ptrs_.push_back(n.data());
  }
  char** get() { return ptrs_.data(); }

 private:
  std::vector<std::string> names_;
  std::vector<char*> ptrs_;
};

// WriteOptions' fields as results at one time step (time 0): nodal variables in node order,
// element variables block by block in the file's element order (`order`: file position -> hex).
void put_fields(int id, const fs::path& file, const WriteOptions& options, const BlockTable& blocks,
                const std::vector<Index>& order) {
  if (options.cell_fields.empty() && options.point_fields.empty()) return;
  const auto declare = [&](ex_entity_type type, const std::vector<DataField>& fields) {
    if (fields.empty()) return;
    std::vector<std::string> names;
    for (const DataField& f : fields) names.push_back(f.name);
    NameList list(names);
    const int n = static_cast<int>(fields.size());
    check(api().ex_put_variable_param(id, type, n), file, "declaring the variables");
    check(api().ex_put_variable_names(id, type, n, list.get()), file, "writing the variable names");
  };
  declare(EX_NODAL, options.point_fields);
  declare(EX_ELEM_BLOCK, options.cell_fields);
  const double time = 0;
  check(api().ex_put_time(id, 1, &time), file, "writing the time step");
  for (std::size_t k = 0; k < options.point_fields.size(); ++k) {
    const DataField& f = options.point_fields[k];
    check(api().ex_put_var(id, 1, EX_NODAL, static_cast<int>(k) + 1, 1, static_cast<int64_t>(f.values.size()),
                           f.values.data()),
          file, fmt::format("writing the nodal variable {}", f.name));
  }
  for (std::size_t k = 0; k < options.cell_fields.size(); ++k) {
    const DataField& f = options.cell_fields[k];
    std::size_t at = 0;
    for (std::size_t b = 0; b < blocks.values.size(); ++b) {
      std::vector<double> values;
      for (; at < order.size() && blocks.of_hex[order[at]] == static_cast<Index>(b); ++at) values.push_back(f.values[order[at]]);
      check(api().ex_put_var(id, 1, EX_ELEM_BLOCK, static_cast<int>(k) + 1, blocks.file_ids[b],
                             static_cast<int64_t>(values.size()), values.data()),
            file, fmt::format("writing the element variable {}", f.name));
    }
  }
}

void write_exodus_file(const fs::path& tmp, const fs::path& file, const HexMesh& mesh, const WriteOptions& options) {
  int comp_ws = 8, io_ws = 8;  // doubles in memory and in the file
  // Classic netCDF (64-bit offsets), not netCDF-4/HDF5: its bytes depend only on the data,
  // so the output is deterministic, and every Exodus reader handles it.
  const int id = api().ex_create_int(tmp.c_str(), EX_CLOBBER | EX_LARGE_MODEL, &comp_ws, &io_ws, EX_API_VERS_NODOT);
  if (id < 0) throw Error(fmt::format("{}: Exodus II: cannot create the file: {}", file.string(), last_exodus_error()));
  ExodusFile exo(id);

  const BlockTable blocks = block_table(mesh);
  const std::vector<BoundaryFace> faces = boundary_faces(mesh);
  const std::vector<Index> bnodes = boundary_nodes(mesh);
  std::vector<int> fixed_nodes;
  for (std::size_t v = 0; v < mesh.fixed.size(); ++v)
    if (mesh.fixed[v]) fixed_nodes.push_back(static_cast<int>(v) + 1);
  const int num_node_sets = (bnodes.empty() ? 0 : 1) + (fixed_nodes.empty() ? 0 : 1);
  std::vector<const FaceSet*> named;  // the mesh's non-empty face sets: side sets 2, 3, ...
  for (const FaceSet& fs : mesh.face_sets)
    if (!fs.faces.empty()) named.push_back(&fs);
  const int num_side_sets = (faces.empty() ? 0 : 1) + static_cast<int>(named.size());
  check(api().ex_put_init(id, "isohex hex mesh", 3, mesh.num_vertices(), mesh.num_hexes(),
                    static_cast<int64_t>(blocks.values.size()), num_node_sets, num_side_sets),
        file, "writing the header");

  if (!mesh.points.empty()) {
    std::vector<double> xyz[3];
    for (int d = 0; d < 3; ++d) {
      xyz[d].reserve(mesh.points.size());
      for (const Vec3& p : mesh.points) xyz[d].push_back(p[d]);
    }
    check(api().ex_put_coord(id, xyz[0].data(), xyz[1].data(), xyz[2].data()), file, "writing the coordinates");
    std::vector<std::string> axes = {"x", "y", "z"};
    NameList axis_names(axes);
    check(api().ex_put_coord_names(id, axis_names.get()), file, "writing the coordinate names");
  }

  // Elements block by block (hex order within a block); file position -> hex.
  std::vector<Index> order(mesh.hexes.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](Index a, Index b) { return blocks.of_hex[a] < blocks.of_hex[b]; });
  std::vector<int> position_of_hex(mesh.hexes.size());
  for (std::size_t i = 0; i < order.size(); ++i) position_of_hex[order[i]] = static_cast<int>(i) + 1;
  std::vector<std::string> names;
  std::size_t at = 0;
  for (std::size_t b = 0; b < blocks.values.size(); ++b) {
    std::vector<int> conn;
    for (; at < order.size() && blocks.of_hex[order[at]] == static_cast<Index>(b); ++at)
      for (const Index v : mesh.hexes[order[at]]) conn.push_back(v + 1);
    const ex_entity_id bid = blocks.file_ids[b];
    check(api().ex_put_elem_block(id, bid, "HEX8", static_cast<int64_t>(conn.size() / 8), 8, 0), file,
          fmt::format("writing element block {}", bid));
    check(api().ex_put_elem_conn(id, bid, conn.data()), file, fmt::format("writing element block {}", bid));
    names.push_back(block_name(blocks.values[b]));
  }
  if (!names.empty()) {
    NameList block_names(names);
    check(api().ex_put_names(id, EX_ELEM_BLOCK, block_names.get()), file, "writing the block names");
    std::vector<int> map(order.size());
    for (std::size_t i = 0; i < order.size(); ++i) map[i] = order[i] + 1;
    check(api().ex_put_id_map(id, EX_ELEM_MAP, map.data()), file, "writing the element id map");
  }

  if (!faces.empty()) {
    std::vector<int> elems, sides;
    for (const BoundaryFace& f : faces) {
      elems.push_back(position_of_hex[f.hex]);
      sides.push_back(kExodusSideOfVtkFace[f.face]);
    }
    check(api().ex_put_side_set_param(id, 1, static_cast<int64_t>(faces.size()), 0), file, "writing the side set");
    check(api().ex_put_side_set(id, 1, elems.data(), sides.data()), file, "writing the side set");
  }
  if (num_side_sets > 0) {
    std::vector<std::string> sset;
    if (!faces.empty()) sset.emplace_back("boundary");
    ex_entity_id next = faces.empty() ? 1 : 2;
    for (const FaceSet* fs : named) {
      std::vector<int> elems, sides;
      for (const auto& [h, f] : fs->faces) {
        elems.push_back(position_of_hex[static_cast<std::size_t>(h)]);
        sides.push_back(kExodusSideOfVtkFace[static_cast<std::size_t>(f)]);
      }
      check(api().ex_put_side_set_param(id, next, static_cast<int64_t>(elems.size()), 0), file,
            fmt::format("writing side set {}", fs->name));
      check(api().ex_put_side_set(id, next, elems.data(), sides.data()), file, fmt::format("writing side set {}", fs->name));
      sset.push_back(fs->name);
      ++next;
    }
    NameList sset_names(sset);
    check(api().ex_put_names(id, EX_SIDE_SET, sset_names.get()), file, "writing the side set names");
  }

  put_fields(id, file, options, blocks, order);

  std::vector<std::string> nset;
  ex_entity_id next_set = 1;
  auto put_node_set = [&](const std::vector<int>& nodes, const char* name) {
    check(api().ex_put_node_set_param(id, next_set, static_cast<int64_t>(nodes.size()), 0), file,
          fmt::format("writing node set {}", name));
    check(api().ex_put_node_set(id, next_set, nodes.data()), file, fmt::format("writing node set {}", name));
    nset.emplace_back(name);
    ++next_set;
  };
  if (!bnodes.empty()) {
    std::vector<int> nodes(bnodes.begin(), bnodes.end());
    for (int& n : nodes) ++n;
    put_node_set(nodes, "boundary");
  }
  if (!fixed_nodes.empty()) put_node_set(fixed_nodes, "fixed");
  if (!nset.empty()) {
    NameList nset_names(nset);
    check(api().ex_put_names(id, EX_NODE_SET, nset_names.get()), file, "writing the node set names");
  }
  exo.close(file);
}

/// Names of the `count` entities of `type`, as the library returns them.
std::vector<std::string> entity_names(int id, ex_entity_type type, std::size_t count, const fs::path& file) {
  // Room for the longest name the format allows, whatever the library's current limit.
  constexpr std::size_t kRoom = 256;
  std::vector<std::vector<char>> storage(count, std::vector<char>(kRoom + 1, '\0'));
  std::vector<char*> ptrs;
  for (auto& s : storage) ptrs.push_back(s.data());
  if (count) check(api().ex_get_names(id, type, ptrs.data()), file, "reading names");
  std::vector<std::string> out;
  for (auto& s : storage) out.emplace_back(s.data());
  return out;
}

HexMesh read_exodus_file(const fs::path& file, const ReadOptions& options, ReadReport& report) {
  if (!fs::exists(file)) throw Error(fmt::format("{}: cannot open: no such file", file.string()));
  int comp_ws = 8, io_ws = 0;
  float version = 0;
  const int id = api().ex_open_int(file.c_str(), EX_READ, &comp_ws, &io_ws, &version, EX_API_VERS_NODOT);
  if (id < 0)
    throw Error(fmt::format("{}: not a readable Exodus II file: {}", file.string(), last_exodus_error()));
  ExodusFile exo(id);

  char title[MAX_LINE_LENGTH + 1] = {};
  int dim = 0, num_nodes = 0, num_elems = 0, num_blocks = 0, num_nsets = 0, num_ssets = 0;
  check(api().ex_get_init(id, title, &dim, &num_nodes, &num_elems, &num_blocks, &num_nsets, &num_ssets), file,
        "reading the header");
  if (dim != 3) throw Error(fmt::format("{}: Exodus II: the mesh is {}-dimensional, not 3-dimensional", file.string(), dim));
  if (num_nodes < 0 || num_elems < 0 || num_blocks < 0)
    throw Error(fmt::format("{}: Exodus II: negative counts in the header", file.string()));

  HexMesh mesh;
  if (num_nodes > 0) {
    std::vector<double> xyz[3];
    for (auto& c : xyz) c.resize(static_cast<std::size_t>(num_nodes));
    check(api().ex_get_coord(id, xyz[0].data(), xyz[1].data(), xyz[2].data()), file, "reading the coordinates");
    mesh.points.resize(static_cast<std::size_t>(num_nodes));
    for (std::size_t v = 0; v < mesh.points.size(); ++v) {
      mesh.points[v] = Vec3(xyz[0][v], xyz[1][v], xyz[2][v]);
      if (!mesh.points[v].allFinite())
        throw Error(fmt::format("{}: Exodus II: node {} has a non-finite coordinate", file.string(), v + 1));
    }
  }

  // Elements in file order; the element id map (1..n when the file has none) orders them.
  std::vector<int> map(static_cast<std::size_t>(num_elems));
  if (num_elems > 0) check(api().ex_get_id_map(id, EX_ELEM_MAP, map.data()), file, "reading the element id map");
  std::vector<int> block_ids(static_cast<std::size_t>(num_blocks));
  if (num_blocks > 0) check(api().ex_get_ids(id, EX_ELEM_BLOCK, block_ids.data()), file, "reading the element block ids");
  const std::vector<std::string> names = entity_names(id, EX_ELEM_BLOCK, block_ids.size(), file);

  std::vector<Hex> hexes;
  std::vector<Index> set_of_hex;
  std::vector<int> hex_map;
  std::size_t position = 0;  // of the block's first element in the file
  for (std::size_t b = 0; b < block_ids.size(); ++b) {
    char type[MAX_STR_LENGTH + 1] = {};
    int count = 0, per = 0, attrs = 0;
    check(api().ex_get_elem_block(id, block_ids[b], type, &count, &per, &attrs), file,
          fmt::format("reading element block {}", block_ids[b]));
    if (count < 0 || position + static_cast<std::size_t>(count) > map.size())
      throw Error(fmt::format("{}: Exodus II: element block {} holds more elements than the file declares",
                              file.string(), block_ids[b]));
    const bool hex = istarts_with(type, "HEX") && per == 8;
    if (!hex) {
      if (count > 0 && !options.skip_non_hex)
        throw Error(fmt::format("{}: Exodus II: element block {} has {} elements of type {} with {} nodes, not "
                                "linear hexahedra (HEX8); read with skip_non_hex to drop them",
                                file.string(), block_ids[b], count, type, per));
      report.skipped_cells += static_cast<std::size_t>(count);
      position += static_cast<std::size_t>(count);
      continue;
    }
    std::vector<int> conn(static_cast<std::size_t>(count) * 8);
    if (count > 0)
      check(api().ex_get_elem_conn(id, block_ids[b], conn.data()), file, fmt::format("reading element block {}", block_ids[b]));
    for (int e = 0; e < count; ++e) {
      Hex h;
      for (int k = 0; k < 8; ++k) {
        const int n = conn[static_cast<std::size_t>(e) * 8 + static_cast<std::size_t>(k)];
        if (n < 1 || n > num_nodes)
          throw Error(fmt::format("{}: Exodus II: element {} of block {} names node {}, outside 1..{}", file.string(),
                                  e + 1, block_ids[b], n, num_nodes));
        h[static_cast<std::size_t>(k)] = n - 1;
      }
      hexes.push_back(h);
      set_of_hex.push_back(static_cast<Index>(b));
      hex_map.push_back(map[position + static_cast<std::size_t>(e)]);
    }
    position += static_cast<std::size_t>(count);
  }

  std::vector<std::size_t> order(hexes.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return hex_map[a] < hex_map[b]; });
  std::vector<Index> sorted_sets;
  for (const std::size_t h : order) {
    mesh.hexes.push_back(hexes[h]);
    sorted_sets.push_back(set_of_hex[h]);
  }
  const std::vector<Index> file_ids(block_ids.begin(), block_ids.end());
  mesh.blocks = blocks_from_sets(names, file_ids, sorted_sets);

  // Fixed vertices: the node set named "fixed" (as the writer names it).
  if (num_nsets > 0) {
    std::vector<int> nset_ids(static_cast<std::size_t>(num_nsets));
    check(api().ex_get_ids(id, EX_NODE_SET, nset_ids.data()), file, "reading the node set ids");
    const std::vector<std::string> nset_names = entity_names(id, EX_NODE_SET, nset_ids.size(), file);
    for (std::size_t s = 0; s < nset_ids.size(); ++s) {
      if (nset_names[s] != "fixed") continue;
      int count = 0, factors = 0;
      check(api().ex_get_node_set_param(id, nset_ids[s], &count, &factors), file, "reading node set fixed");
      std::vector<int> nodes(static_cast<std::size_t>(std::max(count, 0)));
      if (count > 0) check(api().ex_get_node_set(id, nset_ids[s], nodes.data()), file, "reading node set fixed");
      mesh.fixed.assign(mesh.points.size(), 0);
      for (const int n : nodes) {
        if (n < 1 || n > num_nodes)
          throw Error(fmt::format("{}: Exodus II: node set fixed names node {}, outside 1..{}", file.string(), n,
                                  num_nodes));
        mesh.fixed[static_cast<std::size_t>(n - 1)] = 1;
      }
    }
  }
  exo.close(file);
  report.format = fmt::format("Exodus II (file version {:.2f})", version);
  return mesh;
}

}  // namespace

HexMesh read_exodus(const fs::path& file, const ReadOptions& options, ReadReport* report) {
  ReadReport local;
  const std::lock_guard lock(exodus_mutex());
  load_exodus(file);
  api().ex_opts(EX_DEFAULT);  // no printing, no abort: failures are reported by exception
  return read_exodus_file(file, options, report ? *report : local);
}

void write_exodus(const fs::path& file, const HexMesh& mesh, const WriteOptions& options) {
  check_mesh_for_writing(file, mesh);
  check_fields_for_writing(file, mesh, options);
  static std::atomic<unsigned> counter{0};
  fs::path dir = file.parent_path();
  if (dir.empty()) dir = ".";
  if (!fs::is_directory(dir))
    throw Error(fmt::format("{}: cannot write: folder {} does not exist", file.string(), dir.string()));
  // The library writes the file itself, so write_atomically's stream cannot be used; the same
  // temporary-then-rename scheme is done here.
  const fs::path tmp = dir / fmt::format(".{}.tmp{}.{}", file.filename().string(), ::getpid(), counter++);
  try {
    {
      const std::lock_guard lock(exodus_mutex());
      load_exodus(file);
      api().ex_opts(EX_DEFAULT);
      write_exodus_file(tmp, file, mesh, options);
    }
    std::error_code ec;
    fs::rename(tmp, file, ec);
    if (ec) throw Error(fmt::format("{}: cannot rename temporary file into place: {}", file.string(), ec.message()));
  } catch (...) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw;
  }
}

}  // namespace isohex::io
