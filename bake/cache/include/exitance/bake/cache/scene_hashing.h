// Scene parts into a SHA-256 stream, field by field (no struct padding): shared by the whole-bake
// key (bake_cache_key.h) and the per-stage keys (stage_cache_keys.h).
#pragma once
#include "exitance/bake/cache/sha256_stream.h"
#include "exitance/runtime/scene.h"

namespace exitance::scene_hashing {

inline void vec3(Sha256Stream& h, const Vec3& v) { h.value(v.x), h.value(v.y), h.value(v.z); }

inline void binding(Sha256Stream& h, const TextureBinding& b) {
  h.value(b.texture);
  h.value(b.transform.offset.x), h.value(b.transform.offset.y), h.value(b.transform.rotation);
  h.value(b.transform.scale.x), h.value(b.transform.scale.y), h.value(b.transform.tex_coord);
}

inline void texture(Sha256Stream& h, const Texture& t) {
  h.value(t.width), h.value(t.height), h.array(t.rgb), h.array(t.alpha), h.value(t.wrap_s), h.value(t.wrap_t);
}

}  // namespace exitance::scene_hashing
