#pragma once
/// \file csg_cuts.hpp
/// \brief CSG solids meshed with their exact creases, by cuts (`isohex mesh --shape EXPR
/// --features sheets`).
///
/// A structured grid fills the shape's bounding box (its faces are the faces of a box in the
/// shape, exactly; a face that no plane of the shape lies in, where a curved surface touches
/// the bounds, is pushed out by a tenth of the box); each smooth piece of the primitives' surfaces then cuts it, both sides
/// kept (cut.hpp): a sphere, a torus or a plane is one piece, a box six planes, a capped
/// cylinder its side (the cylinder lengthened past the grid) and its two cap planes. Every
/// piece becomes a conforming surface of the mesh, and where two meet the mesh has a string of
/// edges on their exact curve. Last, the hexes outside the shape (by the sign at their
/// centroids: no hex straddles a piece) are dropped. Pieces that miss the grid and planes that
/// are its own faces are skipped.

#include "isohex/mesh/hex_mesh.hpp"
#include "isohex/sheets/cut.hpp"
#include "isohex/volume/implicit.hpp"

#include <cstddef>
#include <vector>

namespace isohex {

struct CsgMeshOptions {
  /// Hex size of the grid (0: the bounding box's largest side / resolution).
  double cell_size = 0;
  int resolution = 24;
  /// Options of each cut (keep is set to both).
  CutOptions cut;
};

struct CsgMeshResult {
  HexMesh mesh;
  std::vector<Shape> pieces;      ///< the smooth surfaces cut along, in order
  std::vector<CutStep> steps;     ///< per piece (CutStep::missed: it misses the grid)
  std::size_t skipped_faces = 0;  ///< planes that are faces of the grid's box
  std::size_t grid_hexes = 0;     ///< hexes of the grid before the cuts
  std::size_t dropped_hexes = 0;  ///< outside the shape, dropped at the end
  /// Per piece, the largest |distance| of a vertex on it to it, relative to the box's diagonal.
  std::vector<double> max_distance;
};

/// The smooth pieces of the shape's primitives' surfaces (see the file comment), in the order of
/// the expression; a cylinder's side is lengthened by `reach` beyond each cap.
std::vector<Shape> smooth_pieces(const Shape& shape, double reach);

/// Meshes `shape` by cuts. Throws isohex::Error for an unbounded or empty shape, a grid over
/// 2^31 points, or a shape no hex of the grid is inside.
CsgMeshResult mesh_by_cuts(const Shape& shape, const CsgMeshOptions& options = {});

}  // namespace isohex
