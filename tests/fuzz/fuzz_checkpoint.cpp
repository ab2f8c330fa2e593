// libFuzzer harness: the checkpoint reader, as AleFlow::load_checkpoint and read_checkpoint_mesh
// read a 2D file (sections config, mesh, state, bodies, end), without a flow. Two modes, by the
// first byte's lowest bit:
//   raw:    the rest is the file: the framing (magic, version, section lengths, CRC-32s) is
//           what gets exercised, nearly every input is refused by its checksum;
//   framed: the rest is split at "SECT" into section payloads, framed here with correct
//           lengths and checksums, so that the payload readers (mesh arrays, history levels,
//           body records) see arbitrary data.
// Every input is read or refused with an alefsi::Error; anything else is a finding.
// Seeds: tests/fuzz/corpus/checkpoint.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "alefsi/physics/rigid_body.hpp"
#include "alefsi/sim/checkpoint.hpp"
#include "alefsi/sim/flow_state.hpp"

namespace {
using namespace alefsi;

template <class T>
void put(std::vector<char>& out, const T& v) {
  const char* p = reinterpret_cast<const char*>(&v);
  out.insert(out.end(), p, p + sizeof v);
}
void put_section(std::vector<char>& out, std::string_view name, std::string_view payload) {
  put(out, std::uint32_t(name.size()));
  out.insert(out.end(), name.begin(), name.end());
  put(out, std::uint64_t(payload.size()));
  out.insert(out.end(), payload.begin(), payload.end());
  std::uint32_t crc = detail::crc32(0, name.data(), name.size());
  crc = detail::crc32(crc, payload.data(), payload.size());
  put(out, crc);
}
std::vector<char> framed(std::string_view rest) {
  std::vector<char> out(checkpoint_magic, checkpoint_magic + 8);
  put(out, checkpoint_version);
  for (const char* name : {"config", "mesh", "state", "bodies"}) {
    const std::size_t cut = rest.find("SECT");
    put_section(out, name, rest.substr(0, cut));
    rest = cut == std::string_view::npos ? std::string_view() : rest.substr(cut + 4);
  }
  put_section(out, "end", {});
  return out;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view rest(reinterpret_cast<const char*>(data) + 1, size - 1);
  std::vector<char> bytes = (data[0] & 1) ? framed(rest) : std::vector<char>(rest.begin(), rest.end());
  try {
    CheckpointReader r("fuzz.bin", std::move(bytes));
    r.section("config");
    r.get<std::int32_t>("dimension");
    for (const char* what : {"element pair", "time scheme", "equations", "rigid-body model"}) r.get_string(what);
    const auto tags = r.get_vector<int>("body tags");
    const Mesh<2> mesh = read_mesh<2>(r);
    FlowState<2, RigidBodyTraits<2>> s;
    s.bodies.resize(tags.size() > 4 ? 4 : tags.size());
    std::vector<int> mine(s.bodies.size());
    for (std::size_t b = 0; b < mine.size(); ++b) mine[b] = tags[b];
    read_state(r, s, mine, 3 * mesh.n_nodes());
    r.finish();
  } catch (const Error&) {
    // a typed refusal
  }
  return 0;
}
