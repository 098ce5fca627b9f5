#include "exitance/bake/import/gltf_materials.h"

#include <cmath>
#include <filesystem>
#include <map>

#include "exitance/bake/import/image_decode.h"
#include "exitance/bake/input_error.h"

namespace exitance {
namespace {

const tinygltf::Value& member(const tinygltf::Value& object, const std::string& key) {
  static const tinygltf::Value null_value;
  return object.IsObject() && object.Has(key) ? object.Get(key) : null_value;
}

float finite_number(const tinygltf::Value& v, float fallback, const std::string& file, const std::string& element) {
  if (v.Type() == tinygltf::NULL_TYPE) return fallback;
  if (!v.IsNumber()) throw InputError(file, element, "expected a number");
  const double d = v.GetNumberAsDouble();
  if (!std::isfinite(d)) throw InputError(file, element, "is not finite");
  return float(d);
}

Vec3 rgb_factor(const std::vector<double>& factor, Vec3 fallback, const std::string& file, const std::string& element) {
  if (factor.empty()) return fallback;
  if (factor.size() < 3) throw InputError(file, element, "needs at least 3 components");
  Vec3 c{float(factor[0]), float(factor[1]), float(factor[2])};
  if (!is_finite(c) || c.x < 0 || c.y < 0 || c.z < 0) throw InputError(file, element, "must be finite and >= 0");
  return c;
}

Texture::Wrap wrap_mode(int gl_wrap) {
  if (gl_wrap == TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE) return Texture::Wrap::ClampToEdge;
  if (gl_wrap == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT) return Texture::Wrap::MirroredRepeat;
  return Texture::Wrap::Repeat;
}

std::string image_name_hint(const tinygltf::Image& image) {
  if (image.mimeType == "image/jpeg") return "image.jpg";
  if (image.mimeType == "image/png") return "image.png";
  const std::string ext = std::filesystem::path(image.uri).extension().string();
  return ext.empty() || image.uri.rfind("data:", 0) == 0 ? "image.png" : "image" + ext;
}

class TextureImporter {
 public:
  TextureImporter(const tinygltf::Model& model, const std::string& file, Scene& scene)
      : model_(model), file_(file), scene_(scene) {}

  // Colour textures (base colour, emissive) are sRGB-encoded; data textures (normal maps) are not.
  enum class Encoding { Srgb, Data };

  TextureBinding bind(const tinygltf::TextureInfo& info, const std::string& element) {
    return bind(info.index, info.texCoord, info.extensions, element, Encoding::Srgb);
  }

  TextureBinding bind(int index, int tex_coord, const tinygltf::ExtensionMap& extensions, const std::string& element,
                      Encoding encoding) {
    TextureBinding binding;
    if (index < 0) return binding;
    if (size_t(index) >= model_.textures.size())
      throw InputError(file_, element, "texture " + std::to_string(index) + " does not exist");
    const tinygltf::Texture& texture = model_.textures[size_t(index)];
    const std::string texture_element = "texture " + std::to_string(index);
    if (texture.source < 0 || size_t(texture.source) >= model_.images.size())
      throw InputError(file_, texture_element, "image " + std::to_string(texture.source) + " does not exist");
    int sampler_wrap_s = TINYGLTF_TEXTURE_WRAP_REPEAT, sampler_wrap_t = TINYGLTF_TEXTURE_WRAP_REPEAT;
    if (texture.sampler >= 0) {
      if (size_t(texture.sampler) >= model_.samplers.size())
        throw InputError(file_, texture_element, "sampler " + std::to_string(texture.sampler) + " does not exist");
      sampler_wrap_s = model_.samplers[size_t(texture.sampler)].wrapS;
      sampler_wrap_t = model_.samplers[size_t(texture.sampler)].wrapT;
    }
    const auto key = std::make_tuple(texture.source, sampler_wrap_s, sampler_wrap_t, encoding == Encoding::Data);
    auto found = cache_.find(key);
    if (found == cache_.end()) {
      const tinygltf::Image& image = model_.images[size_t(texture.source)];
      const std::string image_element = "image " + std::to_string(texture.source);
      if (image.image.empty())
        throw InputError(file_, image_element,
                         image.uri.empty() ? "has no data" : "file '" + image.uri + "' is missing or unreadable");
      Texture decoded = encoding == Encoding::Srgb
                            ? decode_srgb_image(image.image, image_name_hint(image), file_, image_element)
                            : decode_data_image(image.image, image_name_hint(image), file_, image_element);
      decoded.wrap_s = wrap_mode(sampler_wrap_s);
      decoded.wrap_t = wrap_mode(sampler_wrap_t);
      scene_.textures.push_back(std::move(decoded));
      found = cache_.emplace(key, int(scene_.textures.size() - 1)).first;
    }
    binding.texture = found->second;
    binding.transform.tex_coord = tex_coord;
    auto ext = extensions.find("KHR_texture_transform");
    if (ext != extensions.end()) {
      const tinygltf::Value& t = ext->second;
      const std::string ext_element = element + " KHR_texture_transform";
      const tinygltf::Value& offset = member(t, "offset");
      const tinygltf::Value& scale = member(t, "scale");
      if (offset.IsArray() && offset.ArrayLen() == 2)
        binding.transform.offset = {finite_number(offset.Get(0), 0, file_, ext_element),
                                    finite_number(offset.Get(1), 0, file_, ext_element)};
      if (scale.IsArray() && scale.ArrayLen() == 2)
        binding.transform.scale = {finite_number(scale.Get(0), 1, file_, ext_element),
                                   finite_number(scale.Get(1), 1, file_, ext_element)};
      binding.transform.rotation = finite_number(member(t, "rotation"), 0, file_, ext_element);
      const tinygltf::Value& tex_coord = member(t, "texCoord");
      if (tex_coord.IsInt()) binding.transform.tex_coord = tex_coord.GetNumberAsInt();
    }
    if (binding.transform.tex_coord != 0 && binding.transform.tex_coord != 1)
      throw InputError(file_, element, "texCoord " + std::to_string(binding.transform.tex_coord) + " is not supported (0 or 1)");
    return binding;
  }

 private:
  const tinygltf::Model& model_;
  const std::string& file_;
  Scene& scene_;
  std::map<std::tuple<int, int, int, bool>, int> cache_;
};

}  // namespace

uint32_t import_gltf_materials(const tinygltf::Model& model, const std::string& file, Scene& scene,
                               Diagnostics& diagnostics) {
  TextureImporter textures(model, file, scene);
  for (size_t i = 0; i < model.materials.size(); ++i) {
    const tinygltf::Material& source = model.materials[i];
    const std::string element = "material " + std::to_string(i);
    Material material;
    material.name = source.name;
    const auto& pbr = source.pbrMetallicRoughness;
    material.base_color = rgb_factor(pbr.baseColorFactor, {1, 1, 1}, file, element + " baseColorFactor");
    material.base_color_texture = textures.bind(pbr.baseColorTexture, element + " baseColorTexture");
    material.metallic = float(pbr.metallicFactor);
    if (!std::isfinite(material.metallic) || material.metallic < 0 || material.metallic > 1)
      throw InputError(file, element, "metallicFactor must be in [0, 1]");
    float strength = 1.0f;
    auto ext = source.extensions.find("KHR_materials_emissive_strength");
    if (ext != source.extensions.end()) {
      strength = finite_number(member(ext->second, "emissiveStrength"), 1.0f, file, element + " emissiveStrength");
      if (strength < 0) throw InputError(file, element, "emissiveStrength is negative");
    }
    material.emission = rgb_factor(source.emissiveFactor, {0, 0, 0}, file, element + " emissiveFactor") * strength;
    material.emissive_texture = textures.bind(source.emissiveTexture, element + " emissiveTexture");
    material.double_sided = source.doubleSided;
    const tinygltf::NormalTextureInfo& normal = source.normalTexture;
    material.normal_texture = textures.bind(normal.index, normal.texCoord, normal.extensions,
                                            element + " normalTexture", TextureImporter::Encoding::Data);
    material.normal_scale = float(normal.scale);
    if (!std::isfinite(material.normal_scale))
      throw InputError(file, element + " normalTexture", "scale is not finite");
    if (pbr.baseColorFactor.size() == 4) {
      material.base_alpha = float(pbr.baseColorFactor[3]);
      if (!std::isfinite(material.base_alpha) || material.base_alpha < 0 || material.base_alpha > 1)
        throw InputError(file, element + " baseColorFactor", "alpha must be in [0, 1]");
    }
    if (source.alphaMode == "MASK" || source.alphaMode == "BLEND") {
      material.alpha_mode = source.alphaMode == "MASK" ? Material::AlphaMode::Mask : Material::AlphaMode::Blend;
      material.alpha_cutoff = float(source.alphaCutoff);
      if (!std::isfinite(material.alpha_cutoff) || material.alpha_cutoff < 0)
        throw InputError(file, element + " alphaCutoff", "must be a finite number >= 0");
      if (material.alpha_mode == Material::AlphaMode::Blend && max_component(material.emission) > 0) {
        // Stochastic transparency of an emitter would need its light sampling weighted by coverage.
        diagnostics.warn(file + ": " + element + ": alphaMode BLEND on an emissive material: treated as OPAQUE");
        material.alpha_mode = Material::AlphaMode::Opaque;
      }
    } else if (source.alphaMode != "OPAQUE" && !source.alphaMode.empty()) {
      throw InputError(file, element + " alphaMode", "'" + source.alphaMode + "' is not OPAQUE, MASK or BLEND");
    }
    if (max_component(material.base_color) > 1.0f) {
      diagnostics.warn(file + ": " + element + ": baseColorFactor above 1 clamped (energy would not be conserved)");
      material.base_color = min(material.base_color, Vec3{1, 1, 1});
    }
    if (material.metallic >= 1.0f && max_component(material.base_color) > 0.0f)
      diagnostics.warn(file + ": " + element + ": metallicFactor is 1 (the glTF default), so its diffuse albedo is 0");
    scene.materials.push_back(std::move(material));
  }
  // Keep alpha only where a MASK or BLEND material's base colour reads it.
  std::vector<uint8_t> alpha_read(scene.textures.size(), 0);
  for (const Material& m : scene.materials)
    if (m.alpha_mode != Material::AlphaMode::Opaque && m.base_color_texture.texture >= 0)
      alpha_read[size_t(m.base_color_texture.texture)] = 1;
  for (size_t t = 0; t < scene.textures.size(); ++t)
    if (!alpha_read[t]) std::vector<float>().swap(scene.textures[t].alpha);
  Material fallback;
  fallback.name = "(default)";
  fallback.metallic = 0.0f;  // glTF's default material is metallic 1; a baker treats unmaterialed meshes as white diffuse
  scene.materials.push_back(fallback);
  return uint32_t(scene.materials.size() - 1);
}

}  // namespace exitance
