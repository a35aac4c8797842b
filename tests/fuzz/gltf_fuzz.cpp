// The car model loader (loadGltfCar, through tinygltf) on any .glb or .gltf: a model of triangles
// fitted to the vehicle's box, or CarModelError; anything else (a crash, unbounded memory, a
// hang) is a finding. The first byte picks the extension, the rest is the file.

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "render/gltf_car.hpp"
#include "tests/fuzz/fuzz_support.hpp"

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  surroundd::fuzz::quietLogs();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const auto file =
      surroundd::fuzz::scratchFolder() / ((data[0] & 1) != 0 ? "car.glb" : "car.gltf");
  surroundd::fuzz::writeFile(file, surroundd::fuzz::asText(data + 1, size - 1));
  try {
    const surroundd::render::CarModel model = surroundd::render::loadGltfCar(file, {});
    FUZZ_CHECK(!model.vertices.empty());
    FUZZ_CHECK(model.vertices.size() % 3 == 0);
    for (const auto& vertex : model.vertices) {
      for (const float p : vertex.position) FUZZ_CHECK(std::isfinite(p));
      for (const float n : vertex.normal) FUZZ_CHECK(std::isfinite(n));
    }
    for (const auto& part : model.parts) {
      FUZZ_CHECK(part.first + part.count <= model.vertices.size());
      FUZZ_CHECK(part.texture < static_cast<int>(model.textures.size()));
    }
  } catch (const surroundd::render::CarModelError&) {
    // the documented answer to a bad model
  }
  return 0;
}
