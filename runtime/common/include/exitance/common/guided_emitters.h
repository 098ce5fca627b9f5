// Guided next-event estimation (issue 11, docs/lighting-core.md "Emitter guiding"): where the light
// reaches a region only through part of an emitter (a door ajar, a lamp behind a slat), sampling
// the whole emitter by area wastes most shadow rays. The emitters are cut into patches, and per
// region (EmitterGuidingCache, a grid cell and normal class) a learned distribution over patches,
// proportional to each patch's estimated unoccluded contribution, is one component of a one-sample
// mixture with the scene's default next-event sampling (emitters by power, uniform by area).
//
// Patches (built once per scene on the host):
//  - An emitter whose share of the power is at least 1 / target gets 4^L congruent sub-triangles
//    of its own (midpoint subdivision in barycentric space, L as large as 4^L <= share * target,
//    at most kEmitterPatchMaxLevel), each 4^-L of its area.
//  - Runs of consecutive dimmer emitters share one patch (their shares summing to at most
//    1 / target), inside which the default sampling picks one by power.
// So a patch's default probability P0 is its emitters' power share / 4^L, and the mixture's area
// density is exactly the default's times a per-patch ratio:
//   p(x) = p_default(x) * ((1 - a) + a * q(patch(x)) / P0(patch(x))),  a = guided_probability,
// which both next-event samples and the MIS weights of emitters hit by continuation rays use. The
// defensive (1 - a) keeps p >= (1 - a) p_default: a badly learned table costs at most 1 / (1 - a)
// of the default's variance, and the estimator stays unbiased whatever was learned.
//
// The same random numbers as unguided next-event estimation: u_choose picks the component (below
// a: guided) and, rescaled, the patch by CDF inversion, whose remainder picks the emitter of a
// shared patch; the 2-D sample places the point in the patch (kept kGuideEdgeMargin inside it, so
// the point's patch, found again from its barycentrics, is the one sampled).
//
// Tables are read through emitter_guide_word(EMITTER_GUIDE_REF, i) (C++: a pointer; GLSL: defined
// by the includer over its buffer) and the record's CDF through guide_cdf_at, as guided_direction.h.
#ifndef EXITANCE_COMMON_GUIDED_EMITTERS_H
#define EXITANCE_COMMON_GUIDED_EMITTERS_H
#include "exitance/common/distribution.h"
#include "exitance/common/guided_direction.h"
#include "exitance/common/sampling.h"

#ifdef __cplusplus
#define EMITTER_GUIDE_REF const uint*
#define EMITTER_GUIDE_NONE nullptr
namespace exitance {
inline uint emitter_guide_word(const uint* table, uint i) { return table[i]; }
}  // namespace exitance
#else
#define EMITTER_GUIDE_REF uint
#define EMITTER_GUIDE_NONE 0u
#endif

EXITANCE_NAMESPACE_BEGIN

const uint kEmitterPatchMaxLevel = 6u;  // 4096 sub-triangles of one emitter
const uint kEmitterPatchNone = 0xFFFFFFFFu;

// The learned next-event strategy at one vertex.
struct EmitterGuide {
  float guided_probability;        // a; 0: the default sampling exactly (no table is read)
  GUIDE_CDF_REF cdf;               // the record's patch CDF: patch_count + 1 values
  uint patch_count;
  EMITTER_GUIDE_REF emitter_patch;    // per emitter (index into the emitter list): first patch << 3 | level
  EMITTER_GUIDE_REF patch_emitters;   // per patch: first emitter, one past its last emitter
  EMITTER_GUIDE_REF triangle_emitter; // per scene triangle: its emitter index, kEmitterPatchNone if none
  // Punctual lights: the record's learned distribution over them (count + 1 values), mixed with the
  // default choice by power with probability punctual_guided_probability (0: the default exactly).
  float punctual_guided_probability;
  GUIDE_CDF_REF punctual_cdf;
  uint punctual_count;             // 0: no punctual tables
};

EXITANCE_FN EmitterGuide emitter_guide_none() {
  EmitterGuide g;
  g.guided_probability = 0.0f;
  g.cdf = GUIDE_CDF_NONE;
  g.patch_count = 0u;
  g.emitter_patch = EMITTER_GUIDE_NONE;
  g.patch_emitters = EMITTER_GUIDE_NONE;
  g.triangle_emitter = EMITTER_GUIDE_NONE;
  g.punctual_guided_probability = 0.0f;
  g.punctual_cdf = GUIDE_CDF_NONE;
  g.punctual_count = 0u;
  return g;
}

// Whether a record's strategy samples a learned distribution (area or punctual); where it does not,
// next-event estimation's density is the default's.
EXITANCE_FN bool emitter_guide_samples_learned(EmitterGuide g) {
  return g.guided_probability > 0.0f || g.punctual_guided_probability > 0.0f;
}

// Which vertices of a texel's sample `sample` teach the tables (both backends): every vertex in the
// first kEmitterEveryLearningSamples; after them, one sample in kEmitterLaterLearningStride, at
// vertices whose record samples a learned distribution (they keep improving it). Vertices that
// neither learn nor sample a learned distribution take the default's code path
// (EmitterGuidingCache::learning and vertex_site; emitter_guide.glsl).
const uint kEmitterEveryLearningSamples = 64u;
const uint kEmitterLaterLearningStride = 8u;
const uint kEmitterLearnNone = 0u;
const uint kEmitterLearnEverywhere = 1u;
const uint kEmitterLearnWhereSampled = 2u;
EXITANCE_FN uint emitter_learning_of_sample(uint sample_index) {
  if (sample_index < kEmitterEveryLearningSamples) return kEmitterLearnEverywhere;
  return sample_index % kEmitterLaterLearningStride == 0u ? kEmitterLearnWhereSampled : kEmitterLearnNone;
}
EXITANCE_FN bool emitter_vertex_learns(uint learning, bool has_record, bool sampling_learned) {
  return has_record && (learning == kEmitterLearnEverywhere || (learning == kEmitterLearnWhereSampled && sampling_learned));
}

// ---- Sub-triangles: midpoint subdivision in barycentric space ----
// A triangle with corners (A, B, C) has children 0: (A, AB, AC), 1: (AB, B, BC), 2: (AC, BC, C) and
// 3: (BC, AC, AB) (the middle one, turned), where XY is the midpoint; sub-triangle s of level L is
// the path of L base-4 digits, most significant first. Corners are (b1, b2) barycentrics.
// Branch-free (selects): the child of each level depends on the point, which branches mispredict.
EXITANCE_FN uint emitter_sub_triangle_of(uint level, float b1, float b2) {
  float l0 = 1.0f - b1 - b2;
  float l1 = b1;
  float l2 = b2;
  uint index = 0u;
  for (uint k = 0u; k < level; ++k) {
    bool corner0 = l0 > 0.5f;
    bool corner1 = !corner0 && l1 > 0.5f;
    bool corner2 = !corner0 && !corner1 && l2 > 0.5f;
    bool middle = !corner0 && !corner1 && !corner2;
    uint child = corner0 ? 0u : (corner1 ? 1u : (corner2 ? 2u : 3u));
    // Corner child c: l' = 2 l - e_c; the middle one (turned): l' = 1 - 2 l.
    float scale = middle ? -2.0f : 2.0f;
    float offset = middle ? 1.0f : 0.0f;
    l0 = scale * l0 + offset - (corner0 ? 1.0f : 0.0f);
    l1 = scale * l1 + offset - (corner1 ? 1.0f : 0.0f);
    l2 = scale * l2 + offset - (corner2 ? 1.0f : 0.0f);
    index = index * 4u + child;
  }
  return index;
}

// The barycentrics (b1, b2) of the point at local barycentrics (c1, c2) of sub-triangle `index`.
EXITANCE_FN vec2 emitter_sub_triangle_point(uint level, uint index, float c1, float c2) {
  vec2 a = vec2(0.0f, 0.0f);
  vec2 b = vec2(1.0f, 0.0f);
  vec2 c = vec2(0.0f, 1.0f);
  for (uint k = 0u; k < level; ++k) {
    uint child = (index >> (2u * (level - 1u - k))) & 3u;
    vec2 ab = (a + b) * 0.5f;
    vec2 ac = (a + c) * 0.5f;
    vec2 bc = (b + c) * 0.5f;
    if (child == 0u) {
      b = ab, c = ac;
    } else if (child == 1u) {
      a = ab, c = bc;
    } else if (child == 2u) {
      a = ac, b = bc;
    } else {
      a = bc, b = ac, c = ab;
    }
  }
  return a + (b - a) * c1 + (c - a) * c2;
}

// ---- Patches ----
EXITANCE_FN uint emitter_patch_level(EmitterGuide g, uint emitter) { return emitter_guide_word(g.emitter_patch, emitter) & 7u; }

// The patch of the point at barycentrics (b1, b2) of emitter `emitter`.
EXITANCE_FN uint emitter_patch_of(EmitterGuide g, uint emitter, float b1, float b2) {
  uint word = emitter_guide_word(g.emitter_patch, emitter);
  return (word >> 3u) + emitter_sub_triangle_of(word & 7u, b1, b2);
}

// P0: the default sampling's probability of the patch (its emitters' power share / 4^level).
EXITANCE_FN float emitter_patch_default_probability(CDF_REF, EmitterGuide g, uint patch_index) {
  uint first = emitter_guide_word(g.patch_emitters, 2u * patch_index);
  uint end = emitter_guide_word(g.patch_emitters, 2u * patch_index + 1u);
  float share = float(cdf_at(cdf, end) - cdf_at(cdf, first));
  return share / float(1u << (2u * emitter_patch_level(g, first)));
}

// p_mixture / p_default at a point of patch `patch`; 1 for the default strategy.
EXITANCE_FN float emitter_guide_ratio(CDF_REF, EmitterGuide g, uint patch_index) {
  if (!(g.guided_probability > 0.0f)) return 1.0f;
  float p0 = emitter_patch_default_probability(cdf, g, patch_index);
  float q = guide_bin_probability(g.cdf, patch_index);
  return (1.0f - g.guided_probability) + (p0 > 0.0f ? g.guided_probability * q / p0 : 0.0f);
}

// The ratio at barycentrics (b1, b2) of scene triangle `tri` (an emitter hit by a continuation ray).
EXITANCE_FN float emitter_guide_ratio_at_triangle(CDF_REF, EmitterGuide g, uint tri, float b1, float b2) {
  if (!(g.guided_probability > 0.0f)) return 1.0f;
  uint emitter = emitter_guide_word(g.triangle_emitter, tri);
  if (emitter == kEmitterPatchNone) return 1.0f;
  return emitter_guide_ratio(cdf, g, emitter_patch_of(g, emitter, b1, b2));
}

// CDF inversion over `count` cells (as guide_sample_bin, for any count): the cell k with
// cdf[k] <= u < cdf[k + 1], then back over cells of probability 0. A fixed number of steps with a
// select each (the branchy search mispredicted on every step).
EXITANCE_FN uint emitter_guide_sample_cell(GUIDE_CDF_REF cdf, uint count, float u) {
  uint step = 1u;
  while (step * 2u <= count) step *= 2u;
  uint cell = 0u;  // largest k < count with cdf[k] <= u
  for (; step > 0u; step /= 2u) {
    uint candidate = cell + step;
    cell = candidate < count && guide_cdf_at(cdf, min(candidate, count)) <= u ? candidate : cell;
  }
  while (cell > 0u && !(guide_bin_probability(cdf, cell) > 0.0f)) --cell;
  return cell;
}
EXITANCE_FN uint emitter_guide_sample_patch(EmitterGuide g, float u) { return emitter_guide_sample_cell(g.cdf, g.patch_count, u); }

// A guided sample: the emitter (index into the emitter list) and the barycentrics on its triangle,
// from the component's number u (the mixture's u_choose rescaled) and the 2-D sample (u1, u2).
// `patch` is the one sampled (not found again from the barycentrics: at level 6 the edge margin is
// below float resolution).
struct EmitterPoint {
  uint emitter;
  uint patch_index;
  vec2 barycentrics;
};

EXITANCE_FN EmitterPoint emitter_guide_sample(CDF_REF, uint emitter_count, EmitterGuide g, float u, float u1, float u2) {
  uint patch_index = emitter_guide_sample_patch(g, u);
  float q = guide_bin_probability(g.cdf, patch_index);
  float remainder = q > 0.0f ? min(max((u - guide_cdf_at(g.cdf, patch_index)) / q, 0.0f), 0.99999994f) : 0.5f;
  uint first = emitter_guide_word(g.patch_emitters, 2u * patch_index);
  uint end = emitter_guide_word(g.patch_emitters, 2u * patch_index + 1u);
  EmitterPoint p;
  p.emitter = first;
  p.patch_index = patch_index;
  if (end - first > 1u) {  // a shared patch: its emitters by power
    double lo = cdf_at(cdf, first);
    double width = cdf_at(cdf, end) - lo;
    float pmf;
    p.emitter = min(max(sample_cdf(cdf, emitter_count, float(lo + width * double(remainder)), pmf), first), end - 1u);
  }
  uint word = emitter_guide_word(g.emitter_patch, p.emitter);
  vec2 local = sample_triangle_barycentrics(guide_inside_cell(u1), guide_inside_cell(u2));
  p.barycentrics = emitter_sub_triangle_point(word & 7u, patch_index - (word >> 3u), local.x, local.y);
  return p;
}

// The area-light sample of next-event estimation: u_choose below a picks the guided component
// (u_choose rescaled into it), else the default, emitters by power (u_choose rescaled; used as is
// when a = 0, so unguided vertices compute what they did before guiding), the point uniform by
// area from (u1, u2). The patch is reported whenever the vertex has tables (for learning).
EXITANCE_FN EmitterPoint emitter_mixture_sample(CDF_REF, uint emitter_count, EmitterGuide g, float u_choose, float u1,
                                                float u2) {
  float guided = g.guided_probability;
  if (guided > 0.0f && u_choose < guided)
    return emitter_guide_sample(cdf, emitter_count, g, rescaled_unit(u_choose, 0.0f, guided), u1, u2);
  EmitterPoint p;
  float pmf;
  float u_default = guided > 0.0f ? rescaled_unit(u_choose, guided, 1.0f - guided) : u_choose;
  p.emitter = sample_cdf(cdf, emitter_count, u_default, pmf);
  p.barycentrics = sample_triangle_barycentrics(u1, u2);
  p.patch_index = g.patch_count > 0u ? emitter_patch_of(g, p.emitter, p.barycentrics.x, p.barycentrics.y) : kEmitterPatchNone;
  return p;
}

// The mixture's probability of punctual light `light`, whichever component would choose it.
EXITANCE_FN float punctual_mixture_probability(CDF_REF, EmitterGuide g, uint light) {
  float guided = g.punctual_count > 0u ? g.punctual_guided_probability : 0.0f;
  float probability = cdf_pmf(cdf, light);
  if (guided > 0.0f) probability = (1.0f - guided) * probability + guided * guide_bin_probability(g.punctual_cdf, light);
  return probability;
}

// The punctual light of next-event estimation: u_choose below the guided probability picks from
// the learned distribution, else by power (u_choose rescaled; as is without tables). `probability`
// is the mixture's probability of the light, whichever component chose it (a discrete choice).
EXITANCE_FN uint punctual_mixture_sample(CDF_REF, uint punctual_count, EmitterGuide g, float u_choose,
                                         OUT(float) probability) {
  float guided = g.punctual_count > 0u ? g.punctual_guided_probability : 0.0f;
  uint light;
  if (guided > 0.0f && u_choose < guided) {
    light = emitter_guide_sample_cell(g.punctual_cdf, g.punctual_count, rescaled_unit(u_choose, 0.0f, guided));
  } else {
    float pmf;
    light = sample_cdf(cdf, punctual_count, guided > 0.0f ? rescaled_unit(u_choose, guided, 1.0f - guided) : u_choose, pmf);
  }
  probability = punctual_mixture_probability(cdf, g, light);
  return light;
}

EXITANCE_NAMESPACE_END
#endif
