// libFuzzer harness: the gmsh reader (MSH 2.2 ASCII, 4.1 ASCII and binary, either byte order)
// on arbitrary bytes, as a 2D and as a 3D mesh. Every input is read or refused with an
// alefsi::Error (ParseError, MeshError, ...); anything else (a crash, another exception, a
// sanitizer report, an allocation beyond -malloc_limit_mb, a hang) is a finding.
// Seeds: tests/fuzz/corpus/gmsh (the files of tests/data/gmsh). tests/CMakeLists.txt builds it
// with clang (-fsanitize=fuzzer,address,undefined) and runs it for a fixed number of inputs.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "alefsi/mesh/io/gmsh.hpp"

namespace {
template <int D>
void read_as(const std::string& bytes) {
  std::istringstream in(bytes);
  try {
    const auto g = alefsi::read_gmsh<D>(in, "fuzz.msh");
    (void)g.mesh.n_cells();
  } catch (const alefsi::Error&) {
    // a typed refusal: what the reader must do with a bad file
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  read_as<2>(bytes);
  read_as<3>(bytes);
  return 0;
}
