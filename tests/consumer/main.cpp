// A program outside the project, built against the installed isohex (tests/install_consumer.sh):
// it must find the headers, link the library and its dependencies, and compute the same things
// as the build tree. Exits 1 on any wrong value.
#include <isohex/io/mesh_io.hpp>
#include <isohex/mesh/generate.hpp>
#include <isohex/quality/hex_quality.hpp>
#include <isohex/sheets/cut.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: consumer OUT.vtu\n");
    return 2;
  }
  using namespace isohex;
  using io::read_mesh;
  using io::write_mesh;
  const HexMesh box = box_mesh(6, 6, 6, Vec3::Zero(), Vec3(2, 2, 2));
  // A cut (the sheets library, the optimiser) through the cube: two blocks.
  const CutResult r = cut(box, {parse_shape("plane(1.1,1,1, 1,0.3,0.2)")});
  double worst = 1;
  for (Index h = 0; h < r.mesh.num_hexes(); ++h) worst = std::min(worst, scaled_jacobian(r.mesh.corners(h)));
  // A zlib-compressed .vtu written and read back (the io library and zlib).
  write_mesh(argv[1], r.mesh);
  const HexMesh back = read_mesh(argv[1]);
  const bool ok = back.num_hexes() == r.mesh.num_hexes() && back.points == r.mesh.points && worst > 0.2 &&
                  r.mesh.num_hexes() > box.num_hexes();
  std::printf("consumer: %lld hexes after the cut, min scaled Jacobian %.4f, .vtu round trip %s\n",
              static_cast<long long>(r.mesh.num_hexes()), worst, ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
