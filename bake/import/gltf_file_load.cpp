#include "exitance/bake/import/gltf_file_load.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>

#include "exitance/bake/import/gltf_json_validation.h"
#include "exitance/bake/input_error.h"

namespace exitance {
namespace {

constexpr uint32_t kGlbMagic = 0x46546C67;      // "glTF"
constexpr uint32_t kChunkJson = 0x4E4F534A;     // "JSON"
constexpr uint32_t kChunkBin = 0x004E4942;      // "BIN\0"
constexpr size_t kMaxFileBytes = size_t(4) << 30;  // refuse > 4 GiB inputs outright

uint32_t read_u32(const std::vector<unsigned char>& bytes, size_t offset) {
  uint32_t v;
  std::memcpy(&v, bytes.data() + offset, 4);
  return v;  // glTF is little-endian; so is every platform we build for
}

std::vector<unsigned char> read_file(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path, "file", "does not exist or is not a file");
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(path, "file", "cannot be read: " + ec.message());
  if (size == 0) throw InputError(path, "file", "is empty");
  if (size > kMaxFileBytes) throw InputError(path, "file", "is larger than 4 GiB");
  std::ifstream in(path, std::ios::binary);
  std::vector<unsigned char> bytes(size);
  if (!in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(size)))
    throw InputError(path, "file", "cannot be read");
  return bytes;
}

// Where the chunks of a .glb file lie (after check_glb_container).
struct GlbChunks {
  size_t json_offset = 0, json_length = 0;
  uint64_t bin_length = 0;  // 0: no BIN chunk
};

// The container checks tinygltf leaves to chance: every size is compared with the real file.
GlbChunks check_glb_container(const std::vector<unsigned char>& bytes, const std::string& path) {
  if (bytes.size() < 12) throw InputError(path, "glb header", "file is shorter than the 12-byte header");
  if (read_u32(bytes, 0) != kGlbMagic) throw InputError(path, "glb header", "wrong magic (not \"glTF\")");
  const uint32_t version = read_u32(bytes, 4);
  if (version != 2) throw InputError(path, "glb header", "container version " + std::to_string(version) + " is not 2");
  const uint32_t length = read_u32(bytes, 8);
  if (length > bytes.size())
    throw InputError(path, "glb header", "declared length " + std::to_string(length) + " exceeds the file size " +
                                             std::to_string(bytes.size()));
  if (length < 20) throw InputError(path, "glb header", "no JSON chunk");
  const uint32_t json_length = read_u32(bytes, 12);
  if (read_u32(bytes, 16) != kChunkJson) throw InputError(path, "glb chunk 0", "first chunk is not JSON");
  if (json_length == 0 || json_length > length - 20)
    throw InputError(path, "glb chunk 0", "JSON chunk length " + std::to_string(json_length) + " runs past the file");
  GlbChunks chunks{20, json_length, 0};
  size_t offset = 20 + size_t(json_length);
  offset = (offset + 3) & ~size_t(3);
  if (offset + 8 <= length) {
    const uint32_t bin_length = read_u32(bytes, offset);
    const uint32_t bin_type = read_u32(bytes, offset + 4);
    if (bin_type == kChunkBin && bin_length > length - offset - 8)
      throw InputError(path, "glb chunk 1", "BIN chunk length " + std::to_string(bin_length) + " runs past the file");
    if (bin_type == kChunkBin) chunks.bin_length = bin_length;
  }
  return chunks;
}

// One line, printable: nlohmann's message without its "[json.exception.parse_error.101] " tag.
std::string json_error_text(const std::string& what) {
  std::string text = what.rfind("[json.exception.", 0) == 0 && what.find("] ") != std::string::npos
                         ? what.substr(what.find("] ") + 2)
                         : what;
  for (char& c : text)
    if (static_cast<unsigned char>(c) < 0x20) c = ' ';
  return text;
}

nlohmann::json parse_json(const unsigned char* begin, const unsigned char* end, const std::string& path) {
  try {
    return nlohmann::json::parse(begin, end);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, "glTF", "JSON " + json_error_text(e.what()));
  }
}

// tinygltf opens external files through these callbacks: only the files the validator resolved
// and checked (regular files, sizes known) can be opened, and no more than the bytes it allows.
std::string normal_path(const std::string& path) { return std::filesystem::path(path).lexically_normal().string(); }

bool readable_file_exists(const std::string& path, void* user) {
  return static_cast<const GltfExternalFiles*>(user)->readable.count(normal_path(path)) > 0;
}

std::string unexpanded_path(const std::string& path, void*) { return path; }  // no ~ or $VAR expansion

bool read_readable_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  const auto& readable = static_cast<const GltfExternalFiles*>(user)->readable;
  const auto found = readable.find(normal_path(path));
  if (found == readable.end()) {
    if (err) *err = "not a file this glTF may read";
    return false;
  }
  std::ifstream in(found->first, std::ios::binary);
  out->resize(size_t(found->second));
  if (!in.read(reinterpret_cast<char*>(out->data()), std::streamsize(out->size()))) {
    out->clear();
    if (err) *err = "cannot be read";
    return false;
  }
  return true;
}

bool refuse_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err = "writing is not allowed";
  return false;
}

// Keeps the encoded bytes; decoding waits until a material actually needs the image.
bool keep_image_bytes(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void*) {
  image->as_is = true;
  image->image.assign(bytes, bytes + size);
  image->width = image->height = -1;
  return true;
}

std::string first_line(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  return line.empty() ? "could not be parsed" : line;
}

}  // namespace

bool is_supported_gltf_extension(const std::string& name) {
  return name == "KHR_lights_punctual" || name == "KHR_materials_emissive_strength" ||
         name == "KHR_texture_transform";
}

tinygltf::Model load_gltf_model(const std::string& path, Diagnostics& diagnostics) {
  std::vector<unsigned char> bytes = read_file(path);
  const bool is_glb = bytes.size() >= 4 && read_u32(bytes, 0) == kGlbMagic;
  const std::string extension = std::filesystem::path(path).extension().string();
  std::optional<GlbChunks> glb;
  if (is_glb || extension == ".glb" || extension == ".GLB") glb = check_glb_container(bytes, path);

  // Our own schema checks first, on the JSON tinygltf is about to read.
  const unsigned char* json_begin = bytes.data() + (glb ? glb->json_offset : 0);
  const nlohmann::json document =
      parse_json(json_begin, json_begin + (glb ? glb->json_length : bytes.size()), path);
  const std::string base_dir = std::filesystem::path(path).parent_path().string();
  GltfExternalFiles files = validate_gltf_json(document, path, base_dir,
                                               glb ? std::optional<uint64_t>(glb->bin_length) : std::nullopt);

  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(keep_image_bytes, nullptr);
  loader.SetFsCallbacks(
      tinygltf::FsCallbacks{readable_file_exists, unexpanded_path, read_readable_file, refuse_write, &files});
  tinygltf::Model model;
  std::string err, warn;
  bool ok = false;
  try {
    if (is_glb) {
      ok = loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), unsigned(bytes.size()), base_dir);
    } else {
      std::string text(bytes.begin(), bytes.end());
      ok = loader.LoadASCIIFromString(&model, &err, &warn, text.c_str(), unsigned(text.size()), base_dir);
    }
  } catch (const std::exception& e) {
    throw InputError(path, "glTF", std::string("parser failed: ") + e.what());
  }
  if (!ok) throw InputError(path, "glTF", first_line(err.empty() ? warn : err));
  // The validator already resolved every buffer; this only guards against a tinygltf surprise.
  for (size_t i = 0; i < model.buffers.size(); ++i)
    if (model.buffers[i].data.empty())
      throw InputError(path, "buffer " + std::to_string(i), "has no data (missing or unreadable uri '" +
                                                                model.buffers[i].uri + "')");
  if (!warn.empty()) diagnostics.warn(path + ": glTF: " + first_line(warn));
  return model;
}

}  // namespace exitance
