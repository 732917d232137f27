#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_shuffle : require
#define NUSSELT_SUBGROUPS 1
// sample_tool: draws directions with a BSDF sampling strategy for `nusselt sample` and the GPU
// tests. MODEL_ID and SAMPLER (SAMPLER_QUADTREE, _COSINE, _UNIFORM, _ANALYTIC or _TABULATED) are
// specialization constants (one model and strategy per pipeline, as in shade).
// Inputs: SampleToolConstants (count, first, seed, v) as push constants; in Globals the sampler's
// tables and materials.v[0] = the material (info.z = its QuadSet, or its TabSet for tabulated). Outputs per sample i: film.v[i] = (w, pdf or 0 on failure),
// filmSq.v[i] = (f rgb, 1 if the sample succeeded; -1 on an idle lane: pc.idleLanes). Counters: stats (bound violations, trial
// failures). Sample i uses u = rng2(i, 0, RNG_DIM_BSDF, seed) (and the quadtree the stream of u):
// the CPU reproduces it bit for bit up to float differences.
#include "shared/layout.h"
#include "shared/bsdf_sampling.h"
STAGE_PUSH(SampleToolConstants);

layout(local_size_x = WORKGROUP_SIZE) in;
layout(constant_id = 0) const uint MODEL_ID = 0u;
layout(constant_id = 1) const uint SAMPLER = SAMPLER_QUADTREE;
// Binned sampling of gltf_pbr texel parameters (materials.v[0].params, flag MATERIAL_BINNED) with
// Globals.roughnessBins: the GPU side of the binned sampler's parity test (bsdf_sampling.h).
layout(constant_id = 2) const bool BINNED = false;

void main() {
  uint local = gl_GlobalInvocationID.x;
  if (local >= pc.count) return;
  uint i = pc.first + local;
  if (((pc.idleLanes >> (gl_SubgroupInvocationID & 31u)) & 1u) != 0u) {  // an idle lane: marked, no draw
    g.film.v[i] = vec4(0.0f);
    g.filmSq.v[i] = vec4(0.0f, 0.0f, 0.0f, -1.0f);
    return;
  }
  GpuMaterial M = g.materials.v[0];
  vec3 v = pc.v.xyz;
  uint seed = pc.seed;
  vec2 u = rng2(i, 0u, RNG_DIM_BSDF, seed);
  vec3 w;
  float pdf;
  vec3 f;
  bool ok;
  if (BINNED && MODEL_ID == MODEL_GLTF_PBR && SAMPLER == SAMPLER_QUADTREE && (M.info.y & MATERIAL_BINNED) != 0u)
    ok = binnedSample(g.roughnessBins, M.params, v, u, w, pdf, f);
  else
    ok = strategySample(SAMPLER, MODEL_ID, M.info.z, M.params, v, u, w, pdf, f);
  g.film.v[i] = vec4(w, ok ? pdf : 0.0f);
  g.filmSq.v[i] = vec4(f, ok ? 1.0f : 0.0f);
}
