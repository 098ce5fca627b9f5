// The BVH4's quantized node layout for GPU traversal (shaders/include/bvh.glsl).
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "exitance/runtime/core/bvh4.h"
#include "exitance/runtime/core/parallel_chunks.h"

namespace exitance::vulkan {

// Quantized node for traversal (shaders/include/bvh.glsl), 64 bytes = 16 words instead of 112:
//   w0..2  origin (float bits)            w3   biased exponents e+127 of the x, y, z scales (bytes 0..2)
//   w4..9  lo.x, hi.x, lo.y, hi.y, lo.z, hi.z: four 8-bit child planes each (child i in byte i)
//   w10..13 child words (as Bvh4Node)   w14..15 zero
// A plane decodes as origin + q * 2^e: q * 2^e is exact, so the shader's float result (one rounding,
// fused or not) is the one computed here, and q is chosen so that the decoded box contains the
// float box (lo rounds down, hi rounds up): traversal stays conservative.
constexpr size_t kQuantizedNodeWords = 16;

inline std::vector<uint32_t> quantize_bvh4_nodes(const std::vector<Bvh4Node>& nodes) {
  std::vector<uint32_t> out(nodes.size() * kQuantizedNodeWords, 0u);
  auto decode = [](float origin, uint32_t q, float scale) {
    volatile float product = float(q) * scale;  // exact; volatile keeps the host from fusing differently
    return origin + product;
  };
  // On all cores: an edit quantizes the thousands of nodes above a moved instance's leaves.
  for_each_chunk(nodes.size(), [&](size_t first, size_t last) {
    for (size_t n = first; n < last; ++n) {
      const Bvh4Node& node = nodes[n];
      uint32_t* w = &out[n * kQuantizedNodeWords];
      const float* lo[3] = {node.lo_x, node.lo_y, node.lo_z};
      const float* hi[3] = {node.hi_x, node.hi_y, node.hi_z};
      uint32_t exponents = 0;
      for (int a = 0; a < 3; ++a) {
        float mn = INFINITY, mx = -INFINITY;
        for (int i = 0; i < 4; ++i)
          if (node.child[i] != kBvhEmptyChild) mn = std::min(mn, lo[a][i]), mx = std::max(mx, hi[a][i]);
        if (!(mn <= mx)) mn = mx = 0.0f;  // no children
        const float extent = mx - mn;
        int e = extent > 0 ? int(std::ceil(std::log2(double(extent) / 254.0))) : -126;
        e = std::max(e, -126);
        uint32_t qlo[4] = {255, 255, 255, 255}, qhi[4] = {0, 0, 0, 0};
        for (;; ++e) {
          if (e > 127) throw std::runtime_error("Vulkan backend: BVH bounds too large to quantize");
          const float scale = std::ldexp(1.0f, e);
          bool ok = true;
          for (int i = 0; i < 4 && ok; ++i) {
            if (node.child[i] == kBvhEmptyChild) continue;
            double fl = std::floor((double(lo[a][i]) - double(mn)) / double(scale));
            double fh = std::ceil((double(hi[a][i]) - double(mn)) / double(scale));
            int64_t l = int64_t(std::clamp(fl, 0.0, 255.0)), h = int64_t(std::clamp(fh, 0.0, 255.0));
            while (l > 0 && decode(mn, uint32_t(l), scale) > lo[a][i]) --l;
            while (h < 255 && decode(mn, uint32_t(h), scale) < hi[a][i]) ++h;
            if (decode(mn, uint32_t(l), scale) > lo[a][i] || decode(mn, uint32_t(h), scale) < hi[a][i]) ok = false;
            qlo[i] = uint32_t(l), qhi[i] = uint32_t(h);
          }
          if (ok) break;
        }
        std::memcpy(&w[a], &mn, 4);
        exponents |= uint32_t(e + 127) << (8 * a);
        for (int i = 0; i < 4; ++i) {
          w[4 + 2 * a] |= qlo[i] << (8 * i);
          w[5 + 2 * a] |= qhi[i] << (8 * i);
        }
      }
      w[3] = exponents;
      for (int i = 0; i < 4; ++i) w[10 + i] = node.child[i];
    }
  }, 256);
  return out;
}

}  // namespace exitance::vulkan
