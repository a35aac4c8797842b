// The car's own glTF model (render/gltf_car.hpp) on tests/render/models/test_car.gltf, made for
// these tests (CC0): a box body of one colour (indexed, no normals), a small yellow marker placed
// at the back and turned half a turn about the model's up axis by its node (so it ends at the
// front), and a roof quad textured with a 2x2 picture: red, green / blue, white, its first texel
// at the front left. The model spans 2 x 1.5 x 4 (width, height, length) in glTF's axes.

#include "render/gltf_car.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include "processing/surround_mesh.hpp"
#include "render/egl_context.hpp"
#include "render/surround_view.hpp"
#include "tests/support/temp_dir.hpp"

namespace surroundd::render {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

std::filesystem::path testCar() {
  return std::filesystem::path(SURROUNDD_SOURCE_DIR) / "tests/render/models/test_car.gltf";
}

bool isMarker(const CarVertex& v) { return v.colour[0] > 0.99F && v.colour[2] < 0.01F; }

TEST(GltfCar, FillsTheVehiclesBoxFrontForwardWithItsColoursAndTexture) {
  processing::VehicleDimensions car;  // 4.5 x 1.85 x 1.5
  car.xM = 0.5;
  const CarModel model = loadGltfCar(testCar(), car);
  ASSERT_FALSE(model.vertices.empty());
  cv::Vec3f lo(1e9F, 1e9F, 1e9F);
  cv::Vec3f hi = -lo;
  for (const CarVertex& v : model.vertices) {
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], v.position[k]);
      hi[k] = std::max(hi[k], v.position[k]);
    }
  }
  EXPECT_NEAR(lo[0], 0.5 - 2.25, 1e-5);
  EXPECT_NEAR(hi[0], 0.5 + 2.25, 1e-5);
  EXPECT_NEAR(lo[1], -0.925, 1e-5);
  EXPECT_NEAR(hi[1], 0.925, 1e-5);
  EXPECT_NEAR(lo[2], 0.0, 1e-5);
  EXPECT_NEAR(hi[2], 1.5, 1e-5);

  // The marker, turned to the front by its node: glTF's +Z is the vehicle's +x.
  std::size_t markers = 0;
  for (const CarVertex& v : model.vertices) {
    if (!isMarker(v)) continue;
    ++markers;
    EXPECT_GE(v.position[0], 0.5F + 1.6F * 1.125F - 1e-4F);
    EXPECT_LE(std::abs(v.position[1]), 0.3F * 0.925F + 1e-4F);
  }
  EXPECT_EQ(markers, 36u);  // six faces of two triangles

  // Three parts: body and marker untextured (one part), the roof with the texture.
  ASSERT_EQ(model.textures.size(), 1u);
  const cv::Mat& texture = model.textures[0];
  ASSERT_EQ(texture.type(), CV_8UC4);
  ASSERT_EQ(texture.size(), cv::Size(2, 2));
  EXPECT_EQ(texture.at<cv::Vec4b>(0, 0), cv::Vec4b(255, 0, 0, 255));  // RGBA
  EXPECT_EQ(texture.at<cv::Vec4b>(1, 1), cv::Vec4b(255, 255, 255, 255));
  ASSERT_EQ(model.parts.size(), 2u);
  EXPECT_EQ(model.parts[0].texture, -1);
  EXPECT_EQ(model.parts[1].texture, 0);
  EXPECT_EQ(model.parts[1].count, 6u);
  for (std::size_t i = model.parts[1].first; i < model.parts[1].first + 6; ++i) {
    const CarVertex& roof = model.vertices[i];
    EXPECT_NEAR(roof.position[2], 1.5F, 1e-5F);
    EXPECT_NEAR(roof.normal[2], 1.0F, 1e-5F);  // the file's normal, up
    // Its first texel's corner at the front left.
    if (roof.uv[0] == 0 && roof.uv[1] == 0) {
      EXPECT_GT(roof.position[0], 0.5F);
      EXPECT_GT(roof.position[1], 0.0F);
    }
  }
  // The faces without normals in the file get their own, pointing out of the box.
  for (const CarVertex& v : model.vertices) {
    const cv::Vec3f centre(0.5F, 0, 0.6F);
    const cv::Vec3f out = cv::Vec3f(v.position[0], v.position[1], v.position[2]) - centre;
    if (!isMarker(v)) {
      EXPECT_GT(out.dot(cv::Vec3f(v.normal[0], v.normal[1], v.normal[2])), 0);
    }
  }
  // The body's base colour factor (linear 0.5, 0.05, 0.05) as shown.
  EXPECT_NEAR(model.vertices[0].colour[0], std::pow(0.5, 1 / 2.2), 1e-5);
  EXPECT_NEAR(model.vertices[0].colour[1], std::pow(0.05, 1 / 2.2), 1e-5);
}

// Expects `file` refused with one CarModelError that names it and says `why`.
void refuses(const std::filesystem::path& file, const std::string& why) {
  EXPECT_THAT([&] { loadGltfCar(file, {}); },
              ThrowsMessage<CarModelError>(AllOf(HasSubstr(file.string()), HasSubstr(why))))
      << why;
}

TEST(GltfCar, AFileThatIsNoUsableGltfIsOneClearError) {
  const testing::TempDir dir;
  refuses(dir / "none.glb", "does not exist");
  refuses(dir.write("car.obj", "v 0 0 0\n"), "expected a .glb or .gltf file");
  refuses(dir.write("text.gltf", "a car\n"), "not glTF 2.0 that can be read");
  refuses(dir.write("truncated.glb", "glTF\x02"), "not glTF 2.0 that can be read");

  // The test car edited: no triangles (its primitives as points), then an index past its vertices.
  std::ifstream in(testCar());
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::string points = text;
  for (std::size_t at = 0; (at = points.find("\"attributes\"", at)) != std::string::npos; ++at) {
    points.insert(at, "\"mode\": 0, ");
    at += 12;
  }
  refuses(dir.write("points.gltf", points), "its default scene has no triangles");
  // The roof's four vertices given the body's indices, up to 7.
  std::string badIndex = text;
  const std::string roofIndices = "\"indices\": 6,";
  ASSERT_NE(badIndex.find(roofIndices), std::string::npos);
  badIndex.replace(badIndex.find(roofIndices), roofIndices.size(), "\"indices\": 1,");
  refuses(dir.write("index.gltf", badIndex), "an index past its vertices");
}

// Issue 51: files made to exhaust the loader. Each is refused with the file named, in bounded time
// and memory: a node tree that names one node many times (12 levels of 8 took all memory), JSON
// nested 20 000 deep (a stack overflow in tinygltf), a FIFO or a device where a file is expected
// (--check-config hung on a FIFO named by a buffer's uri).
TEST(GltfCar, FilesMadeToExhaustTheLoaderAreRefused) {
  const testing::TempDir dir;
  std::ifstream in(testCar());
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto edited = [&](const std::string& from, const std::string& to) {
    std::string copy = text;
    const auto at = copy.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return copy.replace(at, from.size(), to);
  };

  // The body's node made the child of the marker's and the roof's, each twice.
  refuses(dir.write("shared.gltf",
                    edited("\"name\": \"marker\",", "\"name\": \"marker\", \"children\": [0, 0],")),
          "node 0 has more than one parent");
  refuses(dir.write("cycle.gltf",
                    edited("\"name\": \"body\",", "\"name\": \"body\", \"children\": [0],")),
          "node 0 has more than one parent, or is its own ancestor");

  const std::string deep = std::string(20000, '[') + std::string(20000, ']');
  refuses(dir.write("deep.gltf", edited("\"asset\": {", "\"extras\": " + deep + ", \"asset\": {")),
          "its JSON nests 20001 levels deep");
  // The same in a .glb's JSON chunk; the binary chunk's bytes are not JSON and are not counted.
  const std::string json = "{\"a\": " + deep + "}";
  std::string glb = "glTF";
  const auto word = [&](std::uint32_t value) {
    glb.append(reinterpret_cast<const char*>(&value), sizeof value);
  };
  word(2);
  word(static_cast<std::uint32_t>(20 + json.size()));
  word(static_cast<std::uint32_t>(json.size()));
  word(0x4E4F534A);
  glb += json;
  refuses(dir.write("deep.glb", glb), "its JSON nests 20001 levels deep");

  // A FIFO as the model, and as a buffer's file; a link to /dev/zero as a buffer's file.
  const auto fifo = dir / "fifo.glb";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  refuses(fifo, "a FIFO, not a file");
  const std::string dataUri = R"("uri": "data:application/octet-stream;base64,)";
  const auto external = [&](const std::string& uri) {
    std::string copy = text;
    const auto at = copy.find(dataUri);
    const auto end = copy.find('"', at + dataUri.size());
    return copy.replace(at, end + 1 - at, "\"uri\": \"" + uri + "\"");
  };
  refuses(dir.write("fifo-buffer.gltf", external("fifo.glb")), "a FIFO, not a file");
  std::filesystem::create_symlink("/dev/zero", dir / "zero.bin");
  refuses(dir.write("zero-buffer.gltf", external("zero.bin")), "a character device, not a file");
}

// Drawn from above: the roof shows its texture the right way round (front up, left on the left),
// the marker its colour at the front, each lit as the procedural car is.
TEST(GltfCar, TheTopViewShowsTheModelTexturedTheRightWayRound) {
  const EglContext context;
  processing::PanoramaGeometry panorama;
  panorama.size = {512, 256};
  processing::VehicleDimensions car;
  car.model = testCar();
  SurroundScene scene(processing::buildSurroundMesh({}, panorama), panorama, car, {320, 180});
  scene.uploadPanorama(cv::Mat(panorama.size, CV_8UC3, cv::Scalar(90, 90, 90)));
  const cv::Size size(640, 480);
  const ViewSettings settings;
  SurroundView view(scene, size, ViewKind::kTop, settings);
  view.draw(0);
  const cv::Mat picture = view.collect().clone();
  const double pixelsPerMetre = size.height / (2 * settings.topRangeM);
  const auto at = [&](double x, double y, double z) {
    const double k = settings.topHeightM / (settings.topHeightM - z);  // nearer the eye, larger
    return picture.at<cv::Vec3b>(
        static_cast<int>(std::lround(size.height / 2.0 - x * pixelsPerMetre * k - 0.5)),
        static_cast<int>(std::lround(size.width / 2.0 - y * pixelsPerMetre * k - 0.5)));
  };
  // Lit from above: 0.35 + 0.65 x cos(the light's angle from straight up).
  const double lit = 255 * (0.35 + 0.65 / std::sqrt(1.25));
  const auto expectColour = [&](const cv::Vec3b& seen, cv::Vec3d bgr, const char* what) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(seen[c], bgr[c] * lit, 3.0) << what << " " << seen;
  };
  expectColour(at(0.675, 0.37, 1.5), {0, 0, 1}, "roof, front left: red");
  expectColour(at(0.675, -0.37, 1.5), {0, 1, 0}, "roof, front right: green");
  expectColour(at(-0.675, 0.37, 1.5), {1, 0, 0}, "roof, back left: blue");
  expectColour(at(-0.675, -0.37, 1.5), {1, 1, 1}, "roof, back right: white");
  expectColour(at(2.05, 0, 1.4), {0, 1, 1}, "marker, front: yellow");
  expectColour(at(-2.0, 0, 1.2),
               {std::pow(0.05, 1 / 2.2), std::pow(0.05, 1 / 2.2), std::pow(0.5, 1 / 2.2)},
               "body, back: its paint");
}

}  // namespace
}  // namespace surroundd::render
