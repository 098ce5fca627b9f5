#include "exitance/bake/import/gltf_accessor_reader.h"

#include <tiny_gltf.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "exitance/bake/input_error.h"

namespace exitance {
namespace {

int component_size(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
    default: return 0;  // includes INT and DOUBLE, which glTF 2.0 forbids in accessors
  }
}

int type_components(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
  }
}

float decode_component(const unsigned char* p, int component_type, bool normalized) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      int8_t v; std::memcpy(&v, p, 1);
      return normalized ? std::max(float(v) / 127.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
      uint8_t v; std::memcpy(&v, p, 1);
      return normalized ? float(v) / 255.0f : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v; std::memcpy(&v, p, 2);
      return normalized ? std::max(float(v) / 32767.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v; std::memcpy(&v, p, 2);
      return normalized ? float(v) / 65535.0f : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v; std::memcpy(&v, p, 4);
      return normalized ? float(double(v) / 4294967295.0) : float(v);
    }
    default: {
      float v; std::memcpy(&v, p, 4);
      return v;
    }
  }
}

uint32_t decode_index(const unsigned char* p, int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return *p;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t v; std::memcpy(&v, p, 2); return v; }
    default: { uint32_t v; std::memcpy(&v, p, 4); return v; }
  }
}

// A validated view of `count` elements of `element_size` bytes at `stride` inside a buffer.
struct ElementSpan {
  const unsigned char* base = nullptr;
  size_t stride = 0;
};

// Resolves bufferView + byteOffset for `count` elements, checking every size against the
// buffer that really exists (never the declared lengths alone).
ElementSpan resolve_span(const tinygltf::Model& model, int buffer_view_index, size_t byte_offset, size_t count,
                         size_t element_size, bool allow_stride, const std::string& file, const std::string& element) {
  if (buffer_view_index < 0 || size_t(buffer_view_index) >= model.bufferViews.size())
    throw InputError(file, element, "bufferView " + std::to_string(buffer_view_index) + " does not exist");
  const tinygltf::BufferView& view = model.bufferViews[size_t(buffer_view_index)];
  const std::string view_name = "bufferView " + std::to_string(buffer_view_index);
  if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size())
    throw InputError(file, view_name, "buffer " + std::to_string(view.buffer) + " does not exist");
  const tinygltf::Buffer& buffer = model.buffers[size_t(view.buffer)];
  const size_t buffer_size = buffer.data.size();
  if (view.byteOffset > buffer_size || view.byteLength > buffer_size - view.byteOffset)
    throw InputError(file, view_name,
                     "byteOffset " + std::to_string(view.byteOffset) + " + byteLength " + std::to_string(view.byteLength) +
                         " exceeds the " + std::to_string(buffer_size) + " bytes of buffer " + std::to_string(view.buffer));
  size_t stride = element_size;
  if (view.byteStride != 0) {
    if (!allow_stride) throw InputError(file, view_name, "byteStride is not allowed here");
    if (view.byteStride < 4 || view.byteStride > 252 || view.byteStride % 4 != 0)
      throw InputError(file, view_name, "byteStride " + std::to_string(view.byteStride) + " is not a multiple of 4 in [4, 252]");
    stride = view.byteStride;
    if (stride < element_size)
      throw InputError(file, element, "byteStride " + std::to_string(stride) + " is smaller than the element size " +
                                          std::to_string(element_size));
  }
  if (count > 0) {
    // Overflow-safe: last byte = byte_offset + stride * (count - 1) + element_size <= view.byteLength
    if (byte_offset > view.byteLength || element_size > view.byteLength - byte_offset ||
        (count - 1) > (view.byteLength - byte_offset - element_size) / stride)
      throw InputError(file, element,
                       std::to_string(count) + " elements at byteOffset " + std::to_string(byte_offset) +
                           " run past the end of " + view_name + " (" + std::to_string(view.byteLength) + " bytes)");
  }
  return {buffer.data.data() + view.byteOffset + byte_offset, stride};
}

const tinygltf::Accessor& checked_accessor(const tinygltf::Model& model, int index, const std::string& file,
                                           const std::string& usage) {
  if (index < 0 || size_t(index) >= model.accessors.size())
    throw InputError(file, usage, "accessor " + std::to_string(index) + " does not exist");
  return model.accessors[size_t(index)];
}

// Applies sparse substitution: values listed in the sparse section replace elements.
void apply_sparse(const tinygltf::Model& model, const tinygltf::Accessor& accessor, int components,
                  std::vector<float>& out, const std::string& file, const std::string& element) {
  const auto& sparse = accessor.sparse;
  if (sparse.count <= 0 || size_t(sparse.count) > accessor.count)
    throw InputError(file, element, "sparse count " + std::to_string(sparse.count) + " is not in [1, accessor count]");
  const int index_type = sparse.indices.componentType;
  if (index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      index_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
    throw InputError(file, element, "sparse indices componentType " + std::to_string(index_type) + " is invalid");
  if (sparse.indices.byteOffset < 0 || sparse.values.byteOffset < 0)
    throw InputError(file, element, "sparse byteOffset is negative");
  const size_t count = size_t(sparse.count);
  const size_t value_size = size_t(component_size(accessor.componentType)) * size_t(components);
  ElementSpan indices = resolve_span(model, sparse.indices.bufferView, size_t(sparse.indices.byteOffset), count,
                                     size_t(component_size(index_type)), false, file, element + " sparse indices");
  ElementSpan values = resolve_span(model, sparse.values.bufferView, size_t(sparse.values.byteOffset), count,
                                    value_size, false, file, element + " sparse values");
  int64_t previous = -1;
  for (size_t i = 0; i < count; ++i) {
    const uint32_t target = decode_index(indices.base + i * indices.stride, index_type);
    if (target >= accessor.count)
      throw InputError(file, element, "sparse index " + std::to_string(target) + " is out of range");
    if (int64_t(target) <= previous)
      throw InputError(file, element, "sparse indices are not strictly increasing");
    previous = target;
    const unsigned char* src = values.base + i * values.stride;
    for (int c = 0; c < components; ++c)
      out[size_t(target) * size_t(components) + size_t(c)] =
          decode_component(src + size_t(c) * size_t(component_size(accessor.componentType)), accessor.componentType,
                           accessor.normalized);
  }
}

// Refuses counts no real file can hold before anything is allocated.
void check_count_plausible(const tinygltf::Model& model, const tinygltf::Accessor& accessor, const std::string& file,
                           const std::string& element) {
  size_t total_bytes = 0;
  for (const auto& b : model.buffers) total_bytes += b.data.size();
  // An accessor without a bufferView is all zeros (or sparse); allow up to 64 M elements of those.
  const size_t limit = accessor.bufferView >= 0 ? total_bytes : (size_t(1) << 26);
  if (accessor.count > limit)
    throw InputError(file, element, "count " + std::to_string(accessor.count) + " is larger than the data in the file");
}

}  // namespace

std::vector<float> read_accessor_floats(const tinygltf::Model& model, int index, int expected_components,
                                        const std::string& file, const std::string& usage, NonFinite non_finite) {
  const tinygltf::Accessor& accessor = checked_accessor(model, index, file, usage);
  const std::string element = "accessor " + std::to_string(index);
  const int components = type_components(accessor.type);
  const int csize = component_size(accessor.componentType);
  if (csize == 0)
    throw InputError(file, element, "componentType " + std::to_string(accessor.componentType) + " is invalid");
  if (components != expected_components)
    throw InputError(file, element,
                     "has " + std::to_string(components) + " components per element, " + usage + " needs " +
                         std::to_string(expected_components));
  check_count_plausible(model, accessor, file, element);
  std::vector<float> out(accessor.count * size_t(components), 0.0f);
  if (accessor.bufferView >= 0) {
    const size_t element_size = size_t(csize) * size_t(components);
    ElementSpan span =
        resolve_span(model, accessor.bufferView, accessor.byteOffset, accessor.count, element_size, true, file, element);
    for (size_t i = 0; i < accessor.count; ++i)
      for (int c = 0; c < components; ++c)
        out[i * size_t(components) + size_t(c)] =
            decode_component(span.base + i * span.stride + size_t(c) * size_t(csize), accessor.componentType,
                             accessor.normalized);
  }
  if (accessor.sparse.isSparse) apply_sparse(model, accessor, components, out, file, element);
  if (non_finite == NonFinite::Reject)
    for (float v : out)
      if (!std::isfinite(v)) throw InputError(file, element, "holds a NaN or infinite value (" + usage + ")");
  return out;
}

std::vector<uint32_t> read_accessor_indices(const tinygltf::Model& model, int index, const std::string& file) {
  const tinygltf::Accessor& accessor = checked_accessor(model, index, file, "indices");
  const std::string element = "accessor " + std::to_string(index);
  const int type = accessor.componentType;
  if (accessor.type != TINYGLTF_TYPE_SCALAR)
    throw InputError(file, element, "indices must be SCALAR");
  if (type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE && type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
    throw InputError(file, element, "indices componentType " + std::to_string(type) + " is not an unsigned integer type");
  if (accessor.sparse.isSparse) {
    // Rare but legal: decode through the float path is lossy above 2^24, so only accept small ranges there.
    std::vector<float> values = read_accessor_floats(model, index, 1, file, "indices");
    std::vector<uint32_t> out(values.size());
    for (size_t i = 0; i < values.size(); ++i) {
      if (values[i] < 0 || values[i] >= 16777216.0f) throw InputError(file, element, "sparse index value out of range");
      out[i] = uint32_t(values[i]);
    }
    return out;
  }
  check_count_plausible(model, accessor, file, element);
  std::vector<uint32_t> out(accessor.count, 0u);
  if (accessor.bufferView < 0) return out;
  ElementSpan span = resolve_span(model, accessor.bufferView, accessor.byteOffset, accessor.count,
                                  size_t(component_size(type)), false, file, element);
  for (size_t i = 0; i < accessor.count; ++i) out[i] = decode_index(span.base + i * span.stride, type);
  return out;
}

}  // namespace exitance
