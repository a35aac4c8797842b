#include "render/gltf_car.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>
#include <tiny_gltf.h>

#include "common/nesting_depth.hpp"
#include "common/regular_file.hpp"

namespace surroundd::render {
namespace {

// Bounds a car model must keep (docs/robustness.md): a file, and each file it names, of at most
// 256 MiB; JSON nested at most 64 levels; nodes nested at most 64; at most 4 million vertices
// (a detailed car has a few hundred thousand; each costs ~100 bytes while it loads).
constexpr std::size_t kMaxCarModelFileBytes = std::size_t{256} << 20;
constexpr std::size_t kMaxJsonDepth = 64;
constexpr int kMaxNodeDepth = 64;
constexpr std::size_t kMaxVertices = std::size_t{4} << 20;

// glTF (+Y up, front +Z, so +X left) to the vehicle frame (x forward, y left, z up): a cyclic
// permutation, so no mirror and the triangles keep their winding.
// NOLINTNEXTLINE(cert-err58-cpp): cv::Matx stores nine doubles; its constructor throws nothing.
const cv::Matx33d kVehicleFromGltf(0, 0, 1,  //
                                   1, 0, 0,  //
                                   0, 1, 0);

class GltfReader {
 public:
  GltfReader(const std::filesystem::path& file, const tinygltf::Model& model)
      : file_(file), model_(model) {}

  [[noreturn]] void fail(std::string_view what) const {
    throw CarModelError(fmt::format("car model '{}': {}", file_.string(), what));
  }

  // Accessor `index` as `components` doubles per element (normalized integers to 0..1).
  std::vector<double> read(int index, int components, std::string_view what) const {
    if (index < 0 || static_cast<std::size_t>(index) >= model_.accessors.size()) {
      fail(fmt::format("{}: no accessor {}", what, index));
    }
    const tinygltf::Accessor& accessor = model_.accessors[static_cast<std::size_t>(index)];
    if (accessor.sparse.isSparse) fail(fmt::format("{}: sparse accessors are not read", what));
    if (tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(accessor.type)) != components) {
      fail(fmt::format("{}: expected {} components per element", what, components));
    }
    if (accessor.bufferView < 0 ||
        static_cast<std::size_t>(accessor.bufferView) >= model_.bufferViews.size()) {
      fail(fmt::format("{}: no buffer view", what));
    }
    const tinygltf::BufferView& view =
        model_.bufferViews[static_cast<std::size_t>(accessor.bufferView)];
    if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model_.buffers.size()) {
      fail(fmt::format("{}: no buffer", what));
    }
    const std::vector<unsigned char>& buffer =
        model_.buffers[static_cast<std::size_t>(view.buffer)].data;
    const int componentBytes =
        tinygltf::GetComponentSizeInBytes(static_cast<std::uint32_t>(accessor.componentType));
    const int stride = accessor.ByteStride(view);
    if (componentBytes <= 0 || stride <= 0) fail(fmt::format("{}: unknown component type", what));
    const std::size_t start = view.byteOffset + accessor.byteOffset;
    const std::size_t elementBytes = static_cast<std::size_t>(componentBytes) * components;
    if (accessor.count > 0 &&
        (start + (accessor.count - 1) * static_cast<std::size_t>(stride) + elementBytes >
             view.byteOffset + view.byteLength ||
         view.byteOffset + view.byteLength > buffer.size())) {
      fail(fmt::format("{}: reaches past its buffer", what));
    }
    std::vector<double> values;
    values.reserve(accessor.count * static_cast<std::size_t>(components));
    for (std::size_t i = 0; i < accessor.count; ++i) {
      const unsigned char* element = buffer.data() + start + i * static_cast<std::size_t>(stride);
      for (int c = 0; c < components; ++c) {
        values.push_back(component(element + static_cast<std::size_t>(c) * componentBytes,
                                   accessor.componentType, accessor.normalized));
      }
    }
    return values;
  }

  const tinygltf::Model& model() const { return model_; }

 private:
  template <class T>
  static double as(const unsigned char* p) {
    T value;
    std::memcpy(&value, p, sizeof(T));
    return static_cast<double>(value);
  }
  static double component(const unsigned char* p, int type, bool normalized) {
    switch (type) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT:
        return as<float>(p);
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return as<std::uint8_t>(p) / (normalized ? 255.0 : 1.0);
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
        return as<std::uint16_t>(p) / (normalized ? 65535.0 : 1.0);
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        return as<std::uint32_t>(p);
      case TINYGLTF_COMPONENT_TYPE_BYTE:
        return normalized ? std::max(as<std::int8_t>(p) / 127.0, -1.0) : as<std::int8_t>(p);
      case TINYGLTF_COMPONENT_TYPE_SHORT:
        return normalized ? std::max(as<std::int16_t>(p) / 32767.0, -1.0) : as<std::int16_t>(p);
      default:
        return std::numeric_limits<double>::quiet_NaN();
    }
  }

  const std::filesystem::path& file_;
  const tinygltf::Model& model_;
};

// A node's own transform: its matrix, or translation * rotation * scale.
cv::Matx44d localTransform(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) {
    cv::Matx44d m;
    for (int k = 0; k < 16; ++k) m(k % 4, k / 4) = node.matrix[static_cast<std::size_t>(k)];
    return m;  // glTF stores it column by column
  }
  cv::Matx44d t = cv::Matx44d::eye();
  if (node.translation.size() == 3) {
    for (int k = 0; k < 3; ++k) t(k, 3) = node.translation[static_cast<std::size_t>(k)];
  }
  cv::Matx44d r = cv::Matx44d::eye();
  if (node.rotation.size() == 4) {
    const double x = node.rotation[0], y = node.rotation[1], z = node.rotation[2],
                 w = node.rotation[3];
    const cv::Matx33d q(1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),
                        2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
                        2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y));
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) r(i, j) = q(i, j);
    }
  }
  cv::Matx44d s = cv::Matx44d::eye();
  if (node.scale.size() == 3) {
    for (int k = 0; k < 3; ++k) s(k, k) = node.scale[static_cast<std::size_t>(k)];
  }
  return t * r * s;
}

// `v` made unit length; divided by its largest component first, so that no square overflows.
cv::Vec3d direction(const cv::Vec3d& v) {
  const double largest = std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])});
  return largest > 0 ? cv::normalize(v / largest) : v;
}

// Base colour factors are linear; the car's colours are as shown, as its textures are (sRGB).
float shown(double linear) {
  return static_cast<float>(std::pow(std::clamp(linear, 0.0, 1.0), 1 / 2.2));
}

class CarLoader {
 public:
  explicit CarLoader(const GltfReader& reader) : reader_(reader) {}

  void node(int index, const cv::Matx44d& parent, int depth) {
    const auto& nodes = reader_.model().nodes;
    if (index < 0 || static_cast<std::size_t>(index) >= nodes.size()) {
      reader_.fail(fmt::format("node {} does not exist", index));
    }
    // glTF's nodes form trees (a node has one parent). A node reached twice would be walked again
    // with everything below it: 12 levels of 8 children naming one node took all memory.
    visited_.resize(nodes.size());
    if (visited_[static_cast<std::size_t>(index)]) {
      reader_.fail(
          fmt::format("node {} has more than one parent, or is its own ancestor "
                      "(glTF's nodes form trees)",
                      index));
    }
    if (depth > kMaxNodeDepth) {
      reader_.fail(fmt::format("node {} lies deeper than {} levels", index, kMaxNodeDepth));
    }
    visited_[static_cast<std::size_t>(index)] = true;
    const tinygltf::Node& n = nodes[static_cast<std::size_t>(index)];
    const cv::Matx44d transform = parent * localTransform(n);
    if (n.mesh >= 0) mesh(n.mesh, transform);
    for (const int child : n.children) node(child, transform, depth + 1);
  }

  // The model's box scaled on each axis to the vehicle's, standing on the ground.
  CarModel finish(const processing::VehicleDimensions& car) {
    if (model_.vertices.empty()) reader_.fail("its default scene has no triangles");
    cv::Vec3d lo(std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
                 std::numeric_limits<double>::max());
    cv::Vec3d hi = -lo;
    // NaN in a file, or a transform that overflows, would leave the car drawn nowhere.
    const auto finite = [](const cv::Vec3d& v) {
      return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
    };
    for (std::size_t i = 0; i < positions_.size(); ++i) {
      if (!finite(positions_[i]) || !finite(normals_[i])) {
        reader_.fail("its vertices or normals are not all finite numbers");
      }
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], positions_[i][k]);
        hi[k] = std::max(hi[k], positions_[i][k]);
      }
    }
    if (!finite(hi - lo)) reader_.fail("it is too large to measure (its size overflows)");
    const processing::VehicleDimensions::Box box = car.box();
    const cv::Vec3d target(box.lengthM, box.widthM, car.heightM);
    const cv::Vec3d targetLow(box.centreXM - box.lengthM / 2, box.centreYM - box.widthM / 2, 0);
    const cv::Vec3d extent = hi - lo;
    const double largest = std::max({extent[0], extent[1], extent[2], 1e-9});
    cv::Vec3d scale;
    cv::Vec3d normalScale;  // the inverse of `scale`, up to a factor, finite for any extent
    for (int k = 0; k < 3; ++k) {
      // A flat model (a picture on a plane) keeps its thickness of zero.
      const bool flat = extent[k] <= 1e-9;
      scale[k] = flat ? 1.0 : target[k] / extent[k];
      normalScale[k] = flat ? 1.0 / largest : extent[k] / largest / target[k];
    }
    for (std::size_t i = 0; i < model_.vertices.size(); ++i) {
      CarVertex& v = model_.vertices[i];
      // Normals take the inverse transpose of the scaling.
      const cv::Vec3d normal = direction(direction(normals_[i]).mul(normalScale));
      for (int k = 0; k < 3; ++k) {
        v.position[k] = static_cast<float>(targetLow[k] + (positions_[i][k] - lo[k]) * scale[k]);
        v.normal[k] = static_cast<float>(normal[k]);
      }
    }
    return std::move(model_);
  }

 private:
  void mesh(int index, const cv::Matx44d& transform) {
    const auto& meshes = reader_.model().meshes;
    if (static_cast<std::size_t>(index) >= meshes.size()) {
      reader_.fail(fmt::format("mesh {} does not exist", index));
    }
    const cv::Matx33d linear = kVehicleFromGltf * transform.get_minor<3, 3>(0, 0);
    const cv::Matx33d normalTransform = linear.inv().t();
    for (const tinygltf::Primitive& primitive :
         meshes[static_cast<std::size_t>(index)].primitives) {
      // Points and lines have no surface to show.
      if (primitive.mode != -1 && primitive.mode != TINYGLTF_MODE_TRIANGLES) continue;
      const auto position = primitive.attributes.find("POSITION");
      if (position == primitive.attributes.end()) continue;
      const std::string what = fmt::format("mesh {}", index);
      const std::vector<double> points = reader_.read(position->second, 3, what + " POSITION");
      const std::size_t count = points.size() / 3;
      std::vector<double> normals;
      if (const auto n = primitive.attributes.find("NORMAL"); n != primitive.attributes.end()) {
        normals = reader_.read(n->second, 3, what + " NORMAL");
        if (normals.size() != points.size()) reader_.fail(what + ": a normal per vertex expected");
      }
      const Material material = this->material(primitive.material);
      std::vector<double> uvs;
      if (material.texture >= 0) {
        const auto uv = primitive.attributes.find("TEXCOORD_" + std::to_string(material.texCoord));
        if (uv != primitive.attributes.end()) uvs = reader_.read(uv->second, 2, what + " TEXCOORD");
        if (uvs.size() != count * 2)
          reader_.fail(what + ": its texture needs a TEXCOORD per vertex");
      }
      std::vector<std::size_t> indices;
      if (primitive.indices >= 0) {
        for (const double i : reader_.read(primitive.indices, 1, what + " indices")) {
          if (!(i >= 0 && i < static_cast<double>(count)))
            reader_.fail(what + ": an index past its vertices");
          indices.push_back(static_cast<std::size_t>(i));
        }
      } else {
        for (std::size_t i = 0; i < count; ++i) indices.push_back(i);
      }
      const std::size_t first = model_.vertices.size();
      // Meshes may be shared by nodes: the bound is on what all of them add up to.
      if (first + indices.size() > kMaxVertices) {
        reader_.fail(fmt::format("more than {} vertices in its default scene", kMaxVertices));
      }
      for (std::size_t t = 0; t + 3 <= indices.size(); t += 3) {
        std::array<cv::Vec3d, 3> corner;
        for (int k = 0; k < 3; ++k) {
          const std::size_t i = indices[t + static_cast<std::size_t>(k)];
          const cv::Vec4d p =
              transform * cv::Vec4d(points[i * 3], points[i * 3 + 1], points[i * 3 + 2], 1);
          corner[static_cast<std::size_t>(k)] = kVehicleFromGltf * cv::Vec3d(p[0], p[1], p[2]);
        }
        // Without normals in the file: the face's, flat.
        const cv::Vec3d face = (corner[1] - corner[0]).cross(corner[2] - corner[0]);
        for (int k = 0; k < 3; ++k) {
          const std::size_t i = indices[t + static_cast<std::size_t>(k)];
          const cv::Vec3d normal =
              normals.empty() ? face
                              : normalTransform * cv::Vec3d(normals[i * 3], normals[i * 3 + 1],
                                                            normals[i * 3 + 2]);
          CarVertex v{};
          std::copy(material.colour.begin(), material.colour.end(), v.colour);
          if (!uvs.empty()) {
            v.uv[0] = static_cast<float>(uvs[i * 2]);
            v.uv[1] = static_cast<float>(uvs[i * 2 + 1]);
          }
          model_.vertices.push_back(v);
          positions_.push_back(corner[static_cast<std::size_t>(k)]);
          normals_.push_back(normal);
        }
      }
      const std::size_t added = model_.vertices.size() - first;
      if (added == 0) continue;
      // Consecutive triangles of one texture are one part.
      if (!model_.parts.empty() && model_.parts.back().texture == material.texture &&
          model_.parts.back().first + model_.parts.back().count == first) {
        model_.parts.back().count += added;
      } else {
        model_.parts.push_back({first, added, material.texture});
      }
    }
  }

  struct Material {
    std::array<float, 3> colour{0.8F, 0.8F, 0.8F};  // glTF's default base colour, as shown
    int texture = -1;                               // into model_.textures
    int texCoord = 0;
  };

  Material material(int index) {
    Material m;
    const auto& materials = reader_.model().materials;
    if (index < 0) return m;
    if (static_cast<std::size_t>(index) >= materials.size()) {
      reader_.fail(fmt::format("material {} does not exist", index));
    }
    const auto& pbr = materials[static_cast<std::size_t>(index)].pbrMetallicRoughness;
    if (pbr.baseColorFactor.size() >= 3) {
      for (std::size_t k = 0; k < 3; ++k) m.colour[k] = shown(pbr.baseColorFactor[k]);
    }
    if (pbr.baseColorTexture.index >= 0) {
      m.texture = texture(pbr.baseColorTexture.index);
      m.texCoord = pbr.baseColorTexture.texCoord;
    }
    return m;
  }

  // glTF texture `index` as an index into model_.textures, each image converted once.
  int texture(int index) {
    const tinygltf::Model& model = reader_.model();
    if (static_cast<std::size_t>(index) >= model.textures.size() ||
        model.textures[static_cast<std::size_t>(index)].source < 0 ||
        static_cast<std::size_t>(model.textures[static_cast<std::size_t>(index)].source) >=
            model.images.size()) {
      reader_.fail(fmt::format("texture {} has no image", index));
    }
    const int source = model.textures[static_cast<std::size_t>(index)].source;
    if (const auto known = std::find(textureSources_.begin(), textureSources_.end(), source);
        known != textureSources_.end()) {
      return static_cast<int>(known - textureSources_.begin());
    }
    const tinygltf::Image& image = model.images[static_cast<std::size_t>(source)];
    if (image.width <= 0 || image.height <= 0 || image.component < 1 || image.component > 4 ||
        (image.bits != 8 && image.bits != 16) ||
        image.image.size() != static_cast<std::size_t>(image.width) * image.height *
                                  image.component * (image.bits / 8)) {
      reader_.fail(fmt::format("image {} ('{}') could not be decoded", source, image.uri));
    }
    const cv::Mat raw(image.height, image.width,
                      CV_MAKETYPE(image.bits == 8 ? CV_8U : CV_16U, image.component),
                      const_cast<unsigned char*>(image.image.data()));
    cv::Mat eight;
    raw.convertTo(eight, CV_8U, image.bits == 8 ? 1.0 : 1.0 / 257);
    static constexpr std::array<int, 5> kToRgba{-1, cv::COLOR_GRAY2RGBA, -1, cv::COLOR_RGB2RGBA,
                                                -1};
    cv::Mat rgba;
    if (image.component == 4) {
      rgba = eight;
    } else if (image.component == 2) {
      // Grey and alpha: the grey in all three.
      std::vector<cv::Mat> channels;
      cv::split(eight, channels);
      cv::merge(std::vector<cv::Mat>{channels[0], channels[0], channels[0], channels[1]}, rgba);
    } else {
      cv::cvtColor(eight, rgba, kToRgba[static_cast<std::size_t>(image.component)]);
    }
    model_.textures.push_back(rgba);
    textureSources_.push_back(source);
    return static_cast<int>(model_.textures.size()) - 1;
  }

  const GltfReader& reader_;
  CarModel model_;
  std::vector<cv::Vec3d> positions_;  // per vertex, vehicle axes, before the fit to the box
  std::vector<cv::Vec3d> normals_;
  std::vector<int> textureSources_;  // the glTF image of each of model_.textures
  std::vector<bool> visited_;        // per glTF node
};

// What tinygltf reads besides the model file (external buffers and images) goes through
// readRegularFile: a `uri` naming a FIFO hung --check-config and stalled a reload for 76 s, one
// naming /dev/zero would never end.
bool readReferencedFile(std::vector<unsigned char>* out, std::string* error,
                        const std::string& path, void* /*userData*/) {
  try {
    const std::string bytes = readRegularFile(path, kMaxCarModelFileBytes);
    out->assign(bytes.begin(), bytes.end());
    return true;
  } catch (const FileReadError& e) {
    *error += std::string(e.what()) + "\n";
    return false;
  }
}

bool referencedFileExists(const std::string& path, void* /*userData*/) {
  std::error_code ignored;
  return std::filesystem::exists(path, ignored);
}

std::string pathAsWritten(const std::string& path, void* /*userData*/) { return path; }

bool writeNothing(std::string* error, const std::string& /*path*/,
                  const std::vector<unsigned char>& /*bytes*/, void* /*userData*/) {
  *error = "the car model is only read";
  return false;
}

// The JSON of a .gltf file, or of a .glb's first chunk (its binary chunk may hold any bytes).
std::string_view jsonOf(std::string_view bytes, bool binary) {
  if (!binary) return bytes;
  constexpr std::size_t kHeaderBytes = 20;  // magic, version, length; chunk length and type
  if (bytes.size() < kHeaderBytes) return {};
  std::uint32_t length = 0;
  std::memcpy(&length, bytes.data() + 12, sizeof length);
  return bytes.substr(kHeaderBytes, length);
}

}  // namespace

CarModel loadGltfCar(const std::filesystem::path& file, const processing::VehicleDimensions& car) {
  const std::string extension = file.extension().string();
  if (extension != ".glb" && extension != ".gltf") {
    throw CarModelError(
        fmt::format("car model '{}': expected a .glb or .gltf file", file.string()));
  }
  const bool binary = extension == ".glb";
  std::string bytes;
  try {
    bytes = readRegularFile(file, kMaxCarModelFileBytes);
  } catch (const FileReadError& e) {
    throw CarModelError(fmt::format("car model {}", e.what()));
  }
  // tinygltf's JSON parser recurses per level: 20 000 nested '[' overflowed the stack. A car
  // model's JSON nests a handful of levels (extras included, a few dozen).
  if (const std::size_t depth = nestingDepth(jsonOf(bytes, binary)); depth > kMaxJsonDepth) {
    throw CarModelError(
        fmt::format("car model '{}': its JSON nests {} levels deep, more than "
                    "the {} a glTF file needs",
                    file.string(), depth, kMaxJsonDepth));
  }
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks(
      {&referencedFileExists, &pathAsWritten, &readReferencedFile, &writeNothing, nullptr});
  tinygltf::Model model;
  std::string error;
  std::string warning;
  const std::string folder = file.parent_path().string();
  const bool loaded =
      binary ? loader.LoadBinaryFromMemory(&model, &error, &warning,
                                           reinterpret_cast<const unsigned char*>(bytes.data()),
                                           static_cast<unsigned int>(bytes.size()), folder)
             : loader.LoadASCIIFromString(&model, &error, &warning, bytes.data(),
                                          static_cast<unsigned int>(bytes.size()), folder);
  if (!loaded) {
    while (!error.empty() && (error.back() == '\n' || error.back() == ' ')) error.pop_back();
    throw CarModelError(fmt::format("car model '{}': not glTF 2.0 that can be read: {}",
                                    file.string(), error.empty() ? warning : error));
  }
  const GltfReader reader(file, model);
  CarLoader parts(reader);
  if (model.scenes.empty()) reader.fail("it has no scene");
  const auto scene = static_cast<std::size_t>(std::max(model.defaultScene, 0));
  if (scene >= model.scenes.size()) reader.fail("its default scene does not exist");
  for (const int node : model.scenes[scene].nodes) parts.node(node, cv::Matx44d::eye(), 0);
  return parts.finish(car);
}

}  // namespace surroundd::render
