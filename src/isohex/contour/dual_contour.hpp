#pragma once
/// \file dual_contour.hpp
/// \brief The uniform dual-contouring hex mesher (the "before" mesh of Shepherd et al. 2006,
/// §2.3: LBIE-Mesher's uniform stage), with its boundary on the isosurface and always a
/// closed, consistently oriented 2-manifold.
///
/// The region is sampled on a grid of cell size h centred in its domain box, with one layer
/// of outside points around it. Every inside grid point becomes one hex whose 8 corners are
/// the dual vertices of the 8 grid cells around it, in VTK order (positively oriented). A
/// cell's dual vertex is
///  - its centre when all 8 corners are inside;
///  - otherwise (one vertex per inside component of the cell, see cell_cases.hpp) the
///    minimiser of the QEF of the component's Hermite data (crossings on its edges by
///    LevelSet::root, normals from the gradient), clamped to the cell, then projected onto
///    the surface its crossings belong to (at most h away); if projection fails, the crossing
///    nearest to the clamped point, which is on the surface.
///
/// Where the solid meets the domain box, cells reach past the box: their crossings with the
/// padding layer lie on the box face. Such *box vertices* are put on the box face(s) and, if
/// the cell also crosses the isosurface, moved within the face onto it. They are counted
/// apart and not held to the on-surface check, since the box face, not the isosurface, is
/// the boundary there.
///
/// Before vertices are placed, non-manifold cells are repaired (cell_cases.hpp,
/// sampled_grid.hpp): by flips that keep marching cubes' topology of the samples (sequences of
/// simple points, and moves of one-sample cavities), and where none exists by forced edits:
/// inside points made outside where outside parts touch along an edge, then outside points
/// inside where they touch at a vertex, each phase repeated until nothing changes (each is
/// monotone, so the repair ends).
/// Every stage is parallel (oneTBB) and writes disjoint parts of its output, and vertices
/// and hexes are numbered in grid order, so the mesh is the same bit for bit for any number
/// of threads.

#include "isohex/contour/region.hpp"
#include "isohex/mesh/hex_mesh.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string_view>
#include <vector>

namespace isohex::contour {

/// The sampling grid: `points` per axis, `h` apart, the first at `origin`.
struct DualGrid {
  std::array<Index, 3> points{1, 1, 1};
  Vec3 origin{0, 0, 0};
  double h = 1;
};

/// The grid of cell size `h` centred in `domain`: floor(extent / h) + 1 points per axis, all
/// within the box (faces included). With the volume's box and h equal to its spacing the
/// grid is the volume's own grid.
DualGrid make_grid(const Aabb& domain, double h);

/// What a flip of the manifold repair is (ExtractReport::Edit, RepairCounts::Edit).
enum class RepairKind : std::uint8_t {
  simple,     ///< a simple point: marching cubes' topology of the samples kept
  relocated,  ///< half of a moved one-sample cavity (removed here, made again nearby): topology kept
  forced,     ///< a forced carve or fill: may change the topology
  degenerate, ///< a fill of a zero-volume cavity (every sample at L == 0): removes a surface of zero
              ///< volume, and of zero area for fewer than 4 samples, which would give collapsed quads
  zero_level, ///< a fill of a sample at L == 0 on a real surface on which dual contouring would put
              ///< several vertices: a simple point, topology kept (fill_zero_level_samples)
  pinch,      ///< a fill where the sides touch with zero width at a sample at L == 0 that several
              ///< cells' dual vertices would share (fill_shared_pins): may change the topology
              ///< by connections of zero width (two cavities touching at one point come apart)
  thin,       ///< a carve of a filament thinner than a fraction of a cell (carve_thin_features):
              ///< a simple point (topology kept) or a speck of one sample (a component removed)
};

/// Where a mesh vertex lies (ExtractResult::vertex_place); values ≥ 0 name a surface of the
/// region (an index into Region::surfaces).
enum : std::int8_t { kInteriorVertex = -1, kBoxVertex = -2 };

struct ExtractOptions {
  double cell_size = 0;      ///< h in world units; 0 = use `resolution`
  Index resolution = 64;     ///< cells along the domain's longest axis when cell_size is 0
  Index min_component = 0;   ///< drop connected parts with fewer hexes than this
  /// Carve filaments within this many cells of the isosurface (carve_thin_features); 0 = keep them.
  double thin_features = 0;
  /// Called as each stage starts ("sampling", "manifold repair", ...), e.g. for progress.
  std::function<void(std::string_view stage)> on_stage;
};

/// What happened, with per-stage times in seconds.
struct ExtractReport {
  DualGrid grid;
  std::size_t inside_points = 0;       ///< inside after repair and component removal
  std::size_t filled_points = 0;       ///< made inside by the manifold repair
  std::size_t carved_points = 0;       ///< made outside by the manifold repair
  std::size_t simple_points = 0;       ///< of the filled and carved, simple points (topology kept)
  std::size_t relocated_points = 0;    ///< of the filled and carved, flips that moved one-sample
                                       ///< cavities, two per cavity (topology kept)
  std::size_t forced_points = 0;       ///< of the filled and carved, edits that may change topology
  std::size_t degenerate_components = 0;  ///< zero-volume cavities filled (all samples at L == 0)
  std::size_t degenerate_points = 0;      ///< of the filled, their samples
  std::size_t zero_level_points = 0;      ///< of the filled, samples at L == 0 made inside (simple; topology kept)
  std::size_t pinch_points = 0;           ///< of the filled, pinches of zero width made inside (RepairKind::pinch)
  std::size_t thin_points = 0;            ///< made outside before the repair: filaments thinner than thin_features (RepairKind::thin)
  /// Every flip of the repair in the order made: grid point (i, j, k), its state after the
  /// flip (true = made inside), and its kind. Applied to the samples, the simple, zero_level and
  /// relocated ones keep marching cubes' topology and all of them give the mesh's topology; the
  /// degenerate ones (first) remove only surfaces of zero volume.
  struct Edit {
    std::array<Index, 3> point;
    bool inside;
    RepairKind kind;
    [[nodiscard]] bool keeps_topology() const {
      return kind == RepairKind::simple || kind == RepairKind::relocated || kind == RepairKind::zero_level;
    }
  };
  std::vector<Edit> edits;
  std::size_t repair_rounds = 0;
  std::size_t dropped_components = 0;  ///< parts below min_component
  std::size_t dropped_hexes = 0;
  std::size_t components = 0;          ///< connected parts kept (counted when min_component > 1)
  std::size_t split_cells = 0;         ///< cells with more than one dual vertex
  std::size_t surface_vertices = 0;    ///< vertices on a surface of the region
  std::size_t box_vertices = 0;        ///< vertices on the domain box (not checked against a surface)
  std::size_t projection_fallbacks = 0;  ///< projection failed (or refused); a zero in the cell or the nearest crossing used
  std::size_t separated_vertices = 0;    ///< surface vertices placed again: within 0.01 cells of a neighbour cell's
  double time_sample = 0, time_repair = 0, time_components = 0, time_vertices = 0, time_hexes = 0;
};

struct ExtractResult {
  HexMesh mesh;
  std::vector<std::int8_t> vertex_place;  ///< per vertex: surface index, kInteriorVertex or kBoxVertex
  ExtractReport report;
};

/// Meshes `region`. Throws isohex::Error for a bad cell size or a grid over 2^31 vertices.
ExtractResult extract_hex_mesh(const Region& region, const ExtractOptions& options);

/// How far the surface vertices are from their surfaces.
struct SurfaceDistance {
  double max_relative = 0;      ///< max |L_k(v)| / scale (value range of an isosurface, radius of a sphere)
  std::size_t checked = 0;      ///< surface vertices measured
  std::size_t off_surface = 0;  ///< of those, relative distance above 1e-6
  std::size_t box_vertices = 0; ///< vertices on the domain box, excluded
  std::vector<double> max_relative_per_surface;    ///< per surface of the region
  std::vector<std::size_t> checked_per_surface;    ///< per surface of the region
  /// max over the box vertices of their distance to the domain box's surface / its largest side
  /// (they may slide in its faces: optimize/slide.hpp).
  double box_max_relative = 0;
  /// Vertices the optimisation released into a band about their surface (`released`, see
  /// BoundarySurface::loosen), measured apart: not in the figures above.
  std::size_t released = 0;
  double released_max_relative = 0;  ///< max |L_k(v)| / scale over them
};
SurfaceDistance surface_distance(const Region& region, const HexMesh& mesh, const std::vector<std::int8_t>& vertex_place,
                                 const std::vector<std::uint8_t>* released = nullptr);

}  // namespace isohex::contour
