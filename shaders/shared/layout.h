// layout.h: every structure that crosses the CPU/GPU boundary, the bindings, the queue ids and
// the wavefront stage names. Included by all compute stages and by the C++ driver: there is no
// hand-written mirror of any struct (STYLE.md).
#ifndef NUSSELT_LAYOUT_H
#define NUSSELT_LAYOUT_H

#include "prelude.h"
#include "quadtree_layout.h"
#include "tabulated_layout.h"
#include "texture_layout.h"
#include "guiding_layout.h"

SHARED_BEGIN

// ---- Tunables (each with its why) ------------------------------------------------------------
// Threads per workgroup: lavapipe ran light kernels 2-4x slower at 32 than at 64; real GPUs like 64.
#define WORKGROUP_SIZE 64
// Model slots: a render has one shade pipeline (and one shade queue) per reflectance model its
// scene uses. 32 > the 20 models of the catalogue, room for measured BRDFs later.
#define MAX_MODEL_SLOTS 32
// Counters live at the head of the queue buffer; item arrays follow. Each queue has two counters,
// one per shard (QUEUE_SHARD_STRIDE apart: separate cache lines), see "Queue ids".
#define QUEUE_SHARD_STRIDE 64u
#define QUEUE_HEADER_UINTS 128
// Bounded BVH stack: depth of the tree is capped at build time to fit (src/scene/bvh.cpp).
#define BVH_STACK_SIZE 64

// ---- Queue ids --------------------------------------------------------------------------------
// A queue is path ids (queues[QUEUE_HEADER_UINTS + id * capacity + slot]) filled by two shards:
// shard 0 from the array's start (count queues[id]), shard 1 from its end backwards (count
// queues[QUEUE_SHARD_STRIDE + id]); item i is shard 0's i-th, or shard 1's (i - count0)-th
// (stage_common.glsl, queueItem). A pushing workgroup in the first half of its dispatch uses shard
// 0, the second half shard 1: lavapipe gives each of its threads a contiguous block of a
// dispatch's workgroups, so with two threads each pushes to a counter and a part of the array of
// its own instead of both contending for one cache line (docs/performance.md, "Queue shards").
// Ray queues ping-pong by bounce parity (ray queue b & 1 holds bounce b's rays), and so do the
// shadow queues: shade(b) fills shadow queue b & 1, which the trace stage of bounce b + 1 consumes
// together with that bounce's rays (PathIntegrator::recordPass).
#define QUEUE_RAY0 0u
#define QUEUE_RAY1 1u
#define QUEUE_SHADOW0 2u
#define QUEUE_SHADOW1 3u
// Rays that hit nothing, for the escape stage (environment radiance); filled only when the scene
// has an environment (Globals.environmentLight != INVALID_INDEX).
#define QUEUE_ESCAPE 4u
#define QUEUE_SHADE_BASE 5u
#define QUEUE_COUNT (QUEUE_SHADE_BASE + MAX_MODEL_SLOTS)
// Indirect dispatch sizes: one per queue (index = queue id), then the trace stage's two (index
// ARGS_TRACE0 + (b & 1) for bounce b): the workgroups of its ray queue plus those of its shadow queue.
#define ARGS_TRACE0 QUEUE_COUNT
#define ARGS_COUNT (QUEUE_COUNT + 2u)

// ---- Statistics counters (stats buffer, uint each) -----------------------------------------------
// The one list of the counters the stages keep: X(ID, index, name, description). It declares the
// STAT_<ID> indices (below, for GLSL and C++), RenderStats' fields, their fold into 64-bit totals,
// their EXR header attributes "nusselt/<name>", resume and merge (src/render/settings.h).
#define NUSSELT_STATS(X)                                                                            \
  X(NONFINITE_SAMPLES, 0, nonFiniteSamples, "samples dropped because L was NaN or Inf")             \
  X(RAYS, 1, rays, "extension rays traced")                                                         \
  X(SHADOW_RAYS, 2, shadowRays, "shadow rays traced")                                               \
  X(BVH_STACK_OVERFLOW, 3, bvhStackOverflows, "BVH traversals that ran out of stack (must stay 0)") \
  X(SAMPLER_BOUND_VIOLATIONS, 4, samplerBoundViolations, "quadtree samples whose f exceeded the leaf's bound") \
  X(SAMPLER_TRIAL_FAILURES, 5, samplerTrialFailures, "quadtree rejection loops that hit their trial cap")
#ifdef __cplusplus
#define NUSSELT_STAT_INDEX(ID, index, name, what) constexpr std::uint32_t STAT_##ID = index;
#else
#define NUSSELT_STAT_INDEX(ID, index, name, what) const uint STAT_##ID = uint(index);
#endif
NUSSELT_STATS(NUSSELT_STAT_INDEX)
#define STAT_COUNT 16u  // room in the stats buffer
// After the counters: extension rays traced per bounce (the ray queue's size when its intersect
// stage starts), for `bench render`; bounces past the last slot count in the last one.
#define STAT_PER_BOUNCE STAT_COUNT
#define STAT_BOUNCE_SLOTS 64u
#define STAT_BUFFER_UINTS (STAT_COUNT + STAT_BOUNCE_SLOTS)

// ---- Light types ----------------------------------------------------------------------------------
#define LIGHT_TRIANGLE 0u
#define LIGHT_POINT 1u
#define LIGHT_SPOT 2u
#define LIGHT_DIRECTIONAL 3u
#define LIGHT_ENVIRONMENT 4u  // the environment (Globals.environment): at most one, importance-sampled

// ---- Light-sampling modes (Globals.counts.w): MIS by default; the others exist for tests ----------
#define LIGHTING_MIS 0u
#define LIGHTING_NEE_ONLY 1u
#define LIGHTING_BSDF_ONLY 2u
// Which part of a path's radiance the stages add (Globals.radiancePart), by the scattering vertices
// between the light and the camera: emission hit at shade bounce b or escaping after it has b, a
// light sample (NEE) taken at bounce b has b + 1. Direct light has at most one (emission seen by
// the camera ray, and NEE and MIS-weighted emitter hits from its first hit), indirect light the
// rest. Caustic light is what reached a non-delta vertex through one or more delta bounces straight
// from the light (paths L S+ D ... E: an emitter hit or an escape after a delta bounce, with a
// non-delta bounce before it), the light that next-event estimation cannot sample: the first such
// contribution of a path (a caustic-only path ends there); non-caustic light is the rest (later
// caustic contributions included). Each pair splits every contribution into exactly one part, and
// the parts use the full estimator's MIS weights, so direct + indirect = caustic + non-caustic =
// all, path by path (Metropolis with part of the light outside the chains: docs/mlt.md).
#define RADIANCE_ALL 0u
#define RADIANCE_DIRECT 1u
#define RADIANCE_INDIRECT 2u
#define RADIANCE_CAUSTIC 3u
#define RADIANCE_NONCAUSTIC 4u
// Globals.primaryFresh: a Metropolis pass (mlt.h) need not store every draw of a path's primary
// sample vector; the draws it leaves out are hashes the stages compute where they read them
// (mltFreshSample), the values the mlt kernels would have stored. NONE: every draw below
// primaryDims is in primarySamples (VEGAS, the chains' starts). POOL: none is (a bootstrap path's
// draws, mltPoolSample). MUTATE: slot c's proposal stores its first GpuMlt.written[c] draws, in
// one of the chains' two vector buffers (MLT_SIDE_B of written[c]), the rest are the step's fresh
// draws (mltLargeStep of mltHash). PIXEL: none is (a path-traced sample of the light outside the
// chains: the path tracer's own numbers of its pixel and sample, mltPixelDraw).
#define PRIMARY_FRESH_NONE 0u
#define PRIMARY_FRESH_POOL 1u
#define PRIMARY_FRESH_MUTATE 2u
#define PRIMARY_FRESH_PIXEL 3u

// ---- Material flags ---------------------------------------------------------------------------------
#define MATERIAL_EMISSIVE 1u
#define MATERIAL_DELTA 2u     // every component of the material is a delta model (no light samples)
#define MATERIAL_COMBINED 4u  // a weighted sum of elementary BRDFs (GpuMaterial.components)
#define MATERIAL_TEXTURED 8u  // a texture applies (Globals.materialTextures: GpuMaterialTextures)
#define MATERIAL_ALPHA 16u    // alphaMode MASK or BLEND: hits are tested in traversal (trace.glsl)
#define MATERIAL_ABSORBING 32u  // a refracting volume that absorbs (GpuMaterial.absorption; volume.h)
// gltf_pbr whose textures vary its parameters, under the quadtree strategy: sampled by the binned
// mixture of Globals.roughnessBins (bsdf_sampling.h, "Binned sampling"); info.z is INVALID_INDEX.
#define MATERIAL_BINNED 64u

// ---- Combined materials ---------------------------------------------------------------------------
// At most this many components per material: the shade stage is specialised per tuple of component
// models (spec constants MODEL_0..MODEL_3), and every component's code is in its kernel.
#define MAX_COMPONENTS 4u
// Component choice (Globals.options.y): albedo = the random-walk source's estimator (choose k with
// probability = its albedo for wo; the choice includes the roulette); uniform = choose k with
// probability 1/n and play a separate albedo roulette (for the speed-versus-error comparison).
#define COMPONENTS_ALBEDO 0u
#define COMPONENTS_UNIFORM 1u
// Russian roulette (Globals.options.z). throughput (the default): from bounce ROULETTE_MIN_BOUNCE
// on, continue with q = min(1, largest channel of the path throughput x etaScale) and divide the
// survivors by q: no channel is ever amplified. albedo: the random-walk source's roulette, q = the
// sample's luminance albedo (its survivors' saturated channels grow by albedo_c / luminance at
// every bounce: 3.7x per bounce on the Cornell box's red wall).
#define ROULETTE_THROUGHPUT 0u
#define ROULETTE_ALBEDO 1u
// No roulette on the camera hit and the two bounces after it: short paths carry most of the
// image, and killing them costs more variance than tracing them (Mitsuba starts at its 5th
// vertex, pbrt-v4 after the first bounce).
#define ROULETTE_MIN_BOUNCE 3u
// Nodes of a component's tabulated albedo estimate (GpuComponent.albedo): cos theta_o = i / 7.
#define COMPONENT_ALBEDO_NODES 8u

// Invalid index marker.
#define INVALID_INDEX 0xffffffffu

// ---- Structures ---------------------------------------------------------------------------------

// A BVH node as the traversal reads it: the boxes of both children (the fastest layout measured
// on lavapipe) and link = (child0, child1, count0, count1): count > 0 means the child is a leaf
// holding triangles [child, child + count); count == 0 means child is an inner node index.
struct BvhNodeBoxes {
  vec4 min0;
  vec4 max0;
  vec4 min1;
  vec4 max1;
  uvec4 link;
};
STATIC_ASSERT_SIZE(BvhNodeBoxes, 80);

// A BVH node as stored (48 bytes instead of 80: six 64-bit loads per node instead of ten, layout.h
// "64-bit loads"; docs/performance.md, "Compressed BVH nodes"). The child boxes are half floats
// relative to the node: a bound is origin + h * 2^(E - 127) (bvhDecodeNode, shaders/shared/
// bvh_traverse.h), h a half in [0, 1] or so, rounded outwards by the builder (a lower bound never
// above the true one, an upper never below: src/scene/bvh.cpp, encodeBvhNode). An empty slot has
// +inf lower and -inf upper halves (an inverted box).
//   origin = (bits of the float origin x, y, z (the lowest corner of the two boxes),
//             E | count0 << 8 | count1 << 14)
//   child0 = (halves lo.x | lo.y << 16, lo.z | hi.x << 16, hi.y | hi.z << 16, child0 index); child1 alike.
struct BvhNode {
  uvec4 origin;
  uvec4 child0;
  uvec4 child1;
};
STATIC_ASSERT_SIZE(BvhNode, 48);

// Intersection data of one triangle, in world space: v0 and two edges (Moller-Trumbore).
struct GpuTriangle {
  vec4 v0;
  vec4 e1;
  vec4 e2;
};
STATIC_ASSERT_SIZE(GpuTriangle, 48);

// Shading data of one triangle: vertex normals (world space, w unused) and
// info = (material index, emitter light index or INVALID_INDEX, 0, 0).
struct GpuTriShading {
  vec4 n0;
  vec4 n1;
  vec4 n2;
  uvec4 info;
};
STATIC_ASSERT_SIZE(GpuTriShading, 64);

// The parameter block of a reflectance model: 32 floats, read with brdfParam(p, i).
// Colours take three consecutive floats. The meaning of each index is defined once, in the
// model's shared header (shaders/shared/brdf/<model>.h) and its registry entry.
#define BRDF_PARAM_VEC4S 8
struct BrdfParams {
  vec4 v[BRDF_PARAM_VEC4S];
};
STATIC_ASSERT_SIZE(BrdfParams, 128);

// info = (model id, MATERIAL_* flags, quadtree set index (QuadSet) or INVALID_INDEX, shade slot).
// emission = emitted radiance (rgb), w unused.
// components = (first GpuComponent, count, 0, 0) when MATERIAL_COMBINED (then info.x is the first
// component's model and params/info.z are unused); for a single transmitting model (modelTransmits:
// rough_dielectric) (0, 0, the QuadSet of its parameters seen from the inside
// (transmissionInsideParams) or INVALID_INDEX, 0); (0, 0, 0, 0) otherwise.
// absorption = the volume's absorption coefficient sigma_a [1/m] (rgb; volume.h), w unused; read
// only when MATERIAL_ABSORBING.
struct GpuMaterial {
  uvec4 info;
  vec4 emission;
  BrdfParams params;
  uvec4 components;
  vec4 absorption;
};
STATIC_ASSERT_SIZE(GpuMaterial, 192);

// One term w * f_k of a combined material (shaders/shared/combined.h).
// info = (model id, quadtree set index or INVALID_INDEX, 1 for a gltf_pbr component sampled by the
// roughness bins (binned sampling: its textures vary it) else 0, the set of a transmitting non-delta
// component seen from the inside (transmissionInsideParams) or INVALID_INDEX); data = (weight w, 0, 0, 0);
// albedoLo, albedoHi = the component's directional albedo (without w; a transmitting component's
// over both hemispheres, R + T, seen from outside) at cos theta_o = i / 7, i = 0..3
// in albedoLo and 4..7 in albedoHi, computed on the CPU: its largest RGB channel under the throughput
// roulette (every non-delta component), its luminance under the albedo roulette (components without
// a QuadSet; quadtree components then use quadAlbedo). The choice probability must be known before
// sampling.
struct GpuComponent {
  uvec4 info;
  vec4 data;
  vec4 albedoLo;
  vec4 albedoHi;
  BrdfParams params;
};
STATIC_ASSERT_SIZE(GpuComponent, 192);

// A light. Triangle emitters: info = (LIGHT_TRIANGLE, triangle index, 0, 0), radiance from the
// material. Punctual lights (KHR_lights_punctual): position (w unused), direction the light
// points to (unit), radiance = intensity (W/sr; irradiance W/m^2 for directional),
// cone = (cos inner, cos outer, 0, 0).
struct GpuLight {
  uvec4 info;
  vec4 position;
  vec4 direction;
  vec4 intensity;
  vec4 cone;
};
STATIC_ASSERT_SIZE(GpuLight, 80);

// Indirect dispatch arguments for one queue (x, y, z, pad): matches VkDispatchIndirectCommand
// at a 16-byte stride.
struct DispatchArgs {
  uvec4 groups;
};
STATIC_ASSERT_SIZE(DispatchArgs, 16);

#ifdef __cplusplus
#define BUFREF(T) std::uint64_t
#else
#define BUFREF(T) T
layout(buffer_reference, std430, buffer_reference_align = 16) buffer BvhNodes { BvhNode v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer Triangles { GpuTriangle v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer TriShadings { GpuTriShading v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer Materials { GpuMaterial v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer Components { GpuComponent v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer Lights { GpuLight v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer Vec4s { vec4 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 8) buffer Vec2s { vec2 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer UVec4s { uvec4 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer Floats { float v[]; };
layout(buffer_reference, std430, buffer_reference_align = 4) buffer Uints { uint v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer QuadSets { QuadSet v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer QuadTables { QuadTable v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer QuadNodes { QuadNode v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer QuadLeaves { QuadLeaf v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer TabSets { TabSet v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer TabTables { TabTable v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer Textures { GpuTexture v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer MaterialTextures { GpuMaterialTextures v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) buffer TriTexcoords { GpuTriTexcoords v[]; };

// ---- 64-bit loads and stores (docs/performance.md, "64-bit loads") ----
// lavapipe performs a load or store through a buffer reference whose address may differ between
// lanes as one scalar access per lane and component (LLVM scalarises the masked gather on CPUs
// without fast gathers: a mask test, a branch, an address extraction, the load and an insert for
// each). A vec4 read as two 64-bit components costs half the accesses of four 32-bit ones; on a GPU
// both are one 16-byte access. The hot per-lane accesses of the stages (path state, BVH nodes,
// triangles, shading data, materials) go through the functions below; the layouts are unchanged.
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
layout(buffer_reference, std430, buffer_reference_align = 16) buffer Wide { u64vec2 v[]; };
vec4 wideVec4(u64vec2 a) { return uintBitsToFloat(uvec4(unpackUint2x32(a.x), unpackUint2x32(a.y))); }
uvec4 wideUVec4(u64vec2 a) { return uvec4(unpackUint2x32(a.x), unpackUint2x32(a.y)); }
u64vec2 wideBits(uvec4 v) { return u64vec2(packUint2x32(v.xy), packUint2x32(v.zw)); }
u64vec2 wideBits(vec4 v) { return wideBits(floatBitsToUint(v)); }

// Macros, so that they take members of the readonly globals block (a function parameter would
// drop the qualifier). b: any buffer reference whose elements are 16-byte aligned.
#define loadVec4(b, i) wideVec4(Wide(b).v[i])
#define loadUVec4(b, i) wideUVec4(Wide(b).v[i])
#define storeVec4(b, i, value) (Wide(b).v[i] = wideBits(value))
#define storeUVec4(b, i, value) (Wide(b).v[i] = wideBits(value))
#define loadBvhNode(b, i) wideBvhNode(Wide(b), i)
#define loadTriangle(b, i) wideTriangle(Wide(b), i)
#define loadTriShading(b, i) wideTriShading(Wide(b), i)
#define loadMaterial(b, i) wideMaterial(Wide(b), i)
#define loadLight(b, i) wideLight(Wide(b), i)
#define loadQuadNode(b, i) wideQuadNode(Wide(b), i)
#define loadQuadLeaf(b, i) wideQuadLeaf(Wide(b), i)
#define loadQuadTable(b, i) wideQuadTable(Wide(b), i)
#define loadQuadSet(b, i) wideQuadSet(Wide(b), i)
// Struct i of an array of structs of k 16-byte members: members at w.v[k i + m].
#define WIDE_V4(m) wideVec4(w.v[o + uint(m)])
#define WIDE_U4(m) wideUVec4(w.v[o + uint(m)])
BvhNode wideBvhNode(Wide w, uint i) {
  uint o = 3u * i;
  return BvhNode(WIDE_U4(0), WIDE_U4(1), WIDE_U4(2));
}
GpuTriangle wideTriangle(Wide w, uint i) {
  uint o = 3u * i;
  return GpuTriangle(WIDE_V4(0), WIDE_V4(1), WIDE_V4(2));
}
GpuTriShading wideTriShading(Wide w, uint i) {
  uint o = 4u * i;
  return GpuTriShading(WIDE_V4(0), WIDE_V4(1), WIDE_V4(2), WIDE_U4(3));
}
GpuLight wideLight(Wide w, uint i) {
  uint o = 5u * i;
  return GpuLight(WIDE_U4(0), WIDE_V4(1), WIDE_V4(2), WIDE_V4(3), WIDE_V4(4));
}
QuadNode wideQuadNode(Wide w, uint i) {
  uint o = 2u * i;
  return QuadNode(WIDE_V4(0), WIDE_U4(1));
}
QuadLeaf wideQuadLeaf(Wide w, uint i) {
  uint o = 3u * i;
  return QuadLeaf(WIDE_V4(0), WIDE_V4(1), WIDE_V4(2));
}
QuadTable wideQuadTable(Wide w, uint i) {
  uint o = 2u * i;
  return QuadTable(WIDE_U4(0), WIDE_V4(1));
}
QuadSet wideQuadSet(Wide w, uint i) {
  uint o = 2u * i;
  return QuadSet(WIDE_U4(0), WIDE_V4(1));
}
GpuMaterial wideMaterial(Wide w, uint i) {
  uint o = 12u * i;
  BrdfParams p;
  for (uint k = 0u; k < BRDF_PARAM_VEC4S; ++k) p.v[k] = wideVec4(w.v[o + 2u + k]);
  uint after = o + 2u + BRDF_PARAM_VEC4S;  // components, absorption
  return GpuMaterial(WIDE_U4(0), WIDE_V4(1), p, wideUVec4(w.v[after]), wideVec4(w.v[after + 1u]));
}
#undef WIDE_V4
#undef WIDE_U4
#endif

// The environment: an equirectangular (lat-long) radiance map and its sampling distribution
// (shaders/shared/envmap.h: convention, lookup, pdf, sampling). info = (width, height, 0, 0);
// rotation = (cos a, sin a, 0, 0) of the rotation by a about +Y (--env-rotate) from map to world;
// texels: width * height radiances (rgb, the scale applied, w unused), row-major, row 0 = the top
// (+Y); distribution: the piecewise-constant 2-D distribution over the map's texels
// (shaders/shared/distribution2d.h), conditional CDFs then the marginal CDF.
struct GpuEnvironment {
  uvec4 info;
  vec4 rotation;
  vec4 reserved;
  BUFREF(Vec4s) texels;
  BUFREF(Floats) distribution;
};
STATIC_ASSERT_SIZE(GpuEnvironment, 64);
#ifndef __cplusplus
layout(buffer_reference, std430, buffer_reference_align = 16) buffer Environments { GpuEnvironment v[]; };
#endif

// A Metropolis render's chains (shaders/shared/mlt.h, src/render/mlt_integrator.cpp).
// info = (chains, dims = primary draws per path, iteration of this step, pixels);
// pool = (first pool path of this bootstrap chunk, paths in it, pool size, 0);
// params = (large-step probability, small-step sigma, resolve scale (b x pixels / chains /
// MLT_FIXED_SCALE), iterations in this pass (the film's sample count)).
// vectorsB: the second of the chains' two vector buffers (primarySampleIndex(c, d, dims); the
// first is Globals.primarySamples): a chain's current vector is in one, its proposal goes into the
// other, and an accepted proposal becomes the current vector where it is (no copy). state: per
// chain (its current radiance L (rgb), its pixel as float bits); splats: per pixel 6 uints (r, g,
// b: low, high);
// poolF: f of every bootstrap path; start: the pool path each chain starts from; counters:
// MLT_COUNTERS uints, per pass; extent: per chain, the draws its current path read (mltExtent of
// the path's bounces, mlt.h; a small step moves those and draws the rest fresh), with MLT_SIDE_B
// when its current vector is in vectorsB; written: per chain, the draws of its proposal the
// mutation stored (PRIMARY_FRESH_MUTATE: the others are fresh, computed where they are read), with
// MLT_SIDE_B when the proposal is in vectorsB.
struct GpuMlt {
  uvec4 info;
  uvec4 pool;
  vec4 params;
  // pool = (first pool index of the chunk, its paths, pool size, the bootstrap's seed).
  // Kelemen's weights: (1 when on, 1 / b' (b' from paths independent of the chains' starts),
  // 1 / b, large-step probability); x = 0: plain expected-value splats.
  vec4 weights;
  // Light outside the chains (RenderSettings::mltPassSpp > 0), path-traced per pixel: (the number
  // of the first sample of this trace, samples per pixel per iteration, samples per pixel in this
  // trace, 0); y = 0: all light in the chains.
  uvec4 outside;
  // Chains restarted from the pass's paths (RenderSettings::mltRestart, docs/mlt.md "Restarts"):
  // (where MLT_KERNEL_START takes the starts' vectors: 0 the bootstrap pool, 1 the pass pool; the
  // number of the pass pool's first sample; 0; the pass pool's size, 0: none is recorded). Pass
  // pool path i is sample restart.y + i / pixels of pixel i % pixels (mltPixelDraw); its f goes
  // into poolF[i].
  uvec4 restart;
  BUFREF(Vec2s) vectorsB;
  BUFREF(Vec4s) state;
  BUFREF(Uints) splats;
  BUFREF(Floats) poolF;
  BUFREF(Uints) start;
  BUFREF(Uints) counters;
  BUFREF(Uints) extent;
  BUFREF(Uints) written;
};
STATIC_ASSERT_SIZE(GpuMlt, 160);
#ifndef __cplusplus
layout(buffer_reference, std430, buffer_reference_align = 16) buffer Mlts { GpuMlt v[]; };
#endif

// A VEGAS render's warp (shaders/shared/vegas.h, src/render/vegas_integrator.cpp).
// info = (warped axes, bins per axis, primary draws per path, warped bounces);
// cdf: per axis bins + 1 floats (the axis' CDF, host-written between passes); sums: per axis and
// bin two uints (the pass's sum of F^2 of the paths whose x fell in the bin, fixed point, low then
// high word), read and emptied by the host after each pass.
struct GpuVegas {
  uvec4 info;
  // (tables learned so far; where this pass's warped numbers come from, VEGAS_NUMBERS_* in
  // vegas.h; 1 while the table is still learned, 0 when it is frozen; 0).
  uvec4 epoch;
  BUFREF(Floats) cdf;
  BUFREF(Uints) sums;
};
STATIC_ASSERT_SIZE(GpuVegas, 48);
#ifndef __cplusplus
layout(buffer_reference, std430, buffer_reference_align = 16) buffer Vegases { GpuVegas v[]; };
#endif

// Per-render constants and the addresses of every buffer (buffer device addresses: no storage
// buffer binding limits the size of a scene; lavapipe caps one binding at 128 MiB).
struct Globals {
  // The image and this pass (four uints at a time: the vec4s below stay 16-byte aligned).
  uint width;            // image size in pixels
  uint height;
  uint chunkFirst;       // first path of this chunk: path p of a pass traces sample p % passSamples of
                         // pixel p / passSamples, so a pixel's samples are neighbours
  uint chunkPaths;       // paths in this chunk
  uint sampleIndex;      // sample index of the pass's first sample
  uint seed;
  uint maxDepth;
  uint pathCapacity;     // paths per chunk: the stride of the queues' item arrays
  // The scene and the render's modes.
  uint materialCount;
  uint lightCount;
  uint triangleCount;
  uint lighting;         // LIGHTING_*
  uint rngMode;          // RNG_PCG or RNG_QMC
  uint componentChoice;  // COMPONENTS_*
  uint roulette;         // ROULETTE_*
  uint passSamples;      // samples per pixel in this pass (sample indices sampleIndex + 0 .. passSamples - 1)
  // (the uints above fill their 16-byte rows; a new row of four)
  uint environmentLight; // the environment's index in the light list, or INVALID_INDEX: no environment
  uint texturedScene;    // 1: some material has a texture that applies (the HAS_TEXTURES stages), else 0
  uint alphaScene;       // 1: some material has alphaMode MASK or BLEND (the HAS_ALPHA tracing stages), else 0
  uint primaryDims;      // primary samples per path in primarySamples (PRIMARY_SAMPLES, stage_common.glsl), 0: none
  vec4 camPosition; // xyz, w = 1 for orthographic
  vec4 camRight;    // unit right * (tan(yfov/2) * aspect), or * xmag for orthographic
  vec4 camUp;       // unit up * tan(yfov/2), or * ymag for orthographic
  vec4 camForward;  // unit view direction
  vec4 sceneSphere; // bounding sphere of the scene: centre, radius (directional lights)
  vec4 background;  // Scene::background (rgb), for tools; the stages see it as a uniform environment

  BUFREF(BvhNodes) bvh;
  BUFREF(Triangles) triangles;
  BUFREF(TriShadings) shading;
  BUFREF(Materials) materials;
  BUFREF(Lights) lights;
  BUFREF(Floats) lightCdf;     // lightCount + 1 entries, cdf[0] = 0, cdf[n] = 1
  BUFREF(Vec4s) film;          // per pixel: sum of samples (rgb), w = samples taken
  BUFREF(Vec4s) filmSq;        // per pixel: sum of squared samples (rgb)
  BUFREF(Vec4s) pathOrigin;    // per path: ray origin; w: caustic parts only (else 0): 1 once the path took a non-delta bounce, 2 once its caustic light counted
  BUFREF(Vec4s) pathDirection; // per path: ray direction, w = its MIS density against light sampling (the BSDF sampler's pdf, also after a guided sample; 0: delta/camera)
  BUFREF(Vec4s) pathThroughput;// per path: throughput (rgb), w = etaScale (the product of (n_t / n_i)^2 over
                               // refractions, which undoes their radiance scaling for the roulette;
                               // guided renders: also of max(1, p_mix / p_bsdf) over guided bounces)
  BUFREF(Vec4s) pathRadiance;  // per path: radiance gathered so far (rgb)
  BUFREF(UVec4s) pathInfo;     // per path: (pixel, sample index, bounces shaded (PRIMARY_SAMPLES stages only), 0)
  BUFREF(Vec4s) pathHit;       // per path: (t, b1, b2, triangle bits)
  BUFREF(Vec4s) shadowOrigin;  // per path: shadow ray origin, w = tmax
  BUFREF(Vec4s) shadowDirection;
  BUFREF(Vec4s) shadowRadiance;// per path: contribution if unoccluded
  BUFREF(Uints) queues;        // QUEUE_HEADER_UINTS counters, then QUEUE_COUNT item arrays
  BUFREF(UVec4s) dispatchArgs; // ARGS_COUNT DispatchArgs
  BUFREF(Uints) stats;         // STAT_COUNT counters
  BUFREF(QuadSets) quadSets;   // generic sampler: one set of trees per material (GpuMaterial.info.z)
  BUFREF(QuadTables) quadTables;
  BUFREF(QuadNodes) quadNodes;
  BUFREF(QuadLeaves) quadLeaves;
  BUFREF(Uints) display;       // the preview's RGBA8 display buffer (0 when headless)
  BUFREF(Components) components; // the components of combined materials (GpuMaterial.components)
  BUFREF(TabSets) tabSets;     // tabulated sampler: one set of tables per material (GpuMaterial.info.z)
  BUFREF(TabTables) tabTables;
  BUFREF(Floats) tabData;      // the CDFs of every table
  BUFREF(Floats) measured;     // measured BRDF tables (merl: MERL_TABLE_FLOATS each, brdf/merl.h)
  BUFREF(Environments) environment; // one GpuEnvironment (0 when the scene has none)
  // glTF textures (texture_layout.h); one-entry buffers when no material is textured.
  BUFREF(Textures) textures;   // GpuTexture records
  BUFREF(Uints) texels;        // every image's RGBA8 texels, one uint each
  BUFREF(MaterialTextures) materialTextures; // per material, parallel to `materials`
  BUFREF(TriTexcoords) texcoords; // per triangle, parallel to `triangles`
  BUFREF(Vec4s) tangents;      // per triangle 3 vec4, the corners' tangents (Scene::tangents: xyz, w = bitangent
                               // sign), parallel to `triangles`; one entry when no material is normal-mapped
  BUFREF(GpuGuides) guide;     // one GpuGuide (guiding_layout.h; 0 unless the render is guided)
  BUFREF(Vec2s) primarySamples; // per path primaryDims 2-D draws (PRIMARY_SAMPLES stages only; 0 otherwise)
  BUFREF(Mlts) mlt;            // one GpuMlt of a Metropolis render; 0 otherwise
  BUFREF(Vegases) vegas;       // one GpuVegas of a VEGAS render; 0 otherwise
  // The top-level acceleration structure's device address, low and high 32 bits, for ray queries
  // (shaders/shared/trace.glsl with NUSSELT_RAY_QUERY); 0 when the GLSL BVH traces.
  uint tlasLow;
  uint tlasHigh;
  // The roughness bins of the scene's textured gltf_pbr materials (MATERIAL_BINNED; count 0: none).
  RoughnessBins roughnessBins;
  uint radiancePart;     // RADIANCE_*: every contribution (the default), or only direct or indirect light
  uint primaryFresh;     // PRIMARY_FRESH_*: which draws of a path's vector are not stored (stage_common.glsl, pathSample2)
};
STATIC_ASSERT_SIZE(Globals, 80 + 6 * 16 + 40 * 8 + 8 + 16 + 8);
// The tabulated strategy's buffers exist (shaders/shared/bsdf_sampling.h compiles it in GLSL).
#define NUSSELT_TABULATED_BUFFERS 1

// ---- Push constants: one struct per kind of stage ---------------------------------------------------
// The stages of a bounce (intersect, shade, shadow).
struct BounceConstants {
  uint bounce;     // current bounce (0 = the camera ray's hit)
  uint modelSlot;  // shade: which shade queue (slot of the material table) to consume
  uint traceMode;  // intersect: TRACE_BOTH, TRACE_RAYS or TRACE_SHADOWS (intersect.comp)
  uint reserved1;
};
#define TRACE_BOTH 0u
#define TRACE_RAYS 1u
#define TRACE_SHADOWS 2u
STATIC_ASSERT_SIZE(BounceConstants, 16);

// display (the preview): tone mapping of the film into the display buffer.
struct DisplayConstants {
  float exposureScale;  // 2^stops
  uint flags;           // DISPLAY_BGRA, DISPLAY_REINHARD
  uint reserved0;
  uint reserved1;
};
STATIC_ASSERT_SIZE(DisplayConstants, 16);
#define DISPLAY_BGRA 1u      // byte order B, G, R, A instead of R, G, B, A
#define DISPLAY_REINHARD 2u  // c / (1 + c) per channel instead of clamping to [0, 1]

// sample_tool (`nusselt sample`, the GPU sampler tests): draws `count` directions, sample indices
// first .. first + count - 1, for the known direction v (local frame).
struct SampleToolConstants {
  uint count;
  uint first;
  uint seed;
  uint idleLanes;  // lanes l of a subgroup with bit l set draw nothing (the tests' partial subgroups)
  vec4 v;
};
STATIC_ASSERT_SIZE(SampleToolConstants, 32);

// trace_tool (the traversal tests): traces rays 0 .. count - 1 of the shadow-ray arrays (origin,
// w = tmax; direction) with both scene queries of shared/trace.glsl; writes pathHit = (t, b1, b2,
// triangle bits) of traceClosest and pathInfo = (traceAny's answer 1 or 0, traceClosest's 1 or 0, 0, 0).
struct TraceToolConstants {
  uint count;
  uint reserved0;
  uint reserved1;
  uint reserved2;
};
STATIC_ASSERT_SIZE(TraceToolConstants, 16);

// The pipeline layout's push-constant range: the largest of the structs above.
#define STAGE_PUSH_BYTES 32u

// The wavefront stages see the globals at set 0, binding 0; each declares its push constants
// with STAGE_PUSH(ItsConstants) (its fields are then pc.<name>). A standalone kernel (tests,
// tools) defines NUSSELT_STANDALONE_KERNEL and declares its own.
#if !defined(__cplusplus) && !defined(NUSSELT_STANDALONE_KERNEL)
layout(set = 0, binding = 0, std430) readonly buffer GlobalsBlock { Globals g; };
#define STAGE_PUSH(T) layout(push_constant, std430) uniform PushBlock { T pc; }
#endif

// Where draw `dimension` of path slot `path` lives in Globals.primarySamples (and a Metropolis
// chain's second vector buffer, GpuMlt.vectorsB) of `dims` draws per path: blocks of 8 paths (a
// subgroup on lavapipe), each block's draws one after the other, the 8 paths' values of a draw
// side by side. Neighbouring lanes read neighbouring memory and one lane's draws stay within a
// few KiB (one plane per dimension thrashed the TLB: 2-3x slower mutations on lavapipe).
// A buffer holds primarySampleSlots(capacity) x dims vec2.
#define PRIMARY_BLOCK 8u
SHARED_FN uint primarySampleIndex(uint path, uint dimension, uint dims) {
  return ((path / PRIMARY_BLOCK) * dims + dimension) * PRIMARY_BLOCK + path % PRIMARY_BLOCK;
}
// Whether a contribution with `scatterings` vertices between light and camera, caustic or not,
// belongs to `part` (RADIANCE_*).
SHARED_FN bool radiancePartKeeps(uint part, uint scatterings, bool caustic) {
  if (part == RADIANCE_ALL) return true;
  if (part >= RADIANCE_CAUSTIC) return (part == RADIANCE_CAUSTIC) == caustic;
  return (part == RADIANCE_DIRECT) == (scatterings <= 1u);
}
SHARED_FN uint primarySampleSlots(uint capacity) { return (capacity + PRIMARY_BLOCK - 1u) / PRIMARY_BLOCK * PRIMARY_BLOCK; }

SHARED_FN float brdfParam(BrdfParams p, uint i) { return p.v[i / 4u][i % 4u]; }
SHARED_FN vec3 brdfParam3(BrdfParams p, uint i) {
  return vec3(brdfParam(p, i), brdfParam(p, i + 1u), brdfParam(p, i + 2u));
}

SHARED_END

#endif
