// stage_common.glsl: what every wavefront stage shares (GLSL only): extensions, the globals,
// queues, ray offsets, light sampling and the scene queries (trace.glsl). Included first by
// each shaders/stages/*.comp.
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_scalar_block_layout : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_shuffle : require
#extension GL_KHR_shader_subgroup_vote : require
// Shared code may use the subgroup operations above (quadtree.h: shared rejection trials).
#define NUSSELT_SUBGROUPS 1
#ifdef NUSSELT_RAY_QUERY
#extension GL_EXT_ray_query : require
#endif

// Module variants (CMakeLists.txt): lavapipe inlines every call before it folds specialization
// constants, so code that a constant switches off still costs pipeline-creation time (bench
// pipelines: shade pipelines 25-40 % slower with the texture and guiding code present but off).
// The shade and escape stages are therefore compiled twice: NUSSELT_SCENE_FEATURES 0 (no
// textures, no guiding: the constants below are plain false and their functions are empty
// stand-ins) and 1 (module <stage>_f: HAS_TEXTURES and GUIDING are specialization constants);
// intersect and shadow likewise with NUSSELT_ALPHA (module <stage>_a: alpha coverage). A module
// that sets neither (the other stages, the tools) gets everything.
#ifndef NUSSELT_SCENE_FEATURES
#define NUSSELT_SCENE_FEATURES 1
#endif
#ifndef NUSSELT_ALPHA
#define NUSSELT_ALPHA 1
#endif

#include "shared/layout.h"
#include "shared/rng.h"
#include "shared/mlt.h"
#include "shared/warp.h"
#include "shared/texture.h"
#include "shared/volume.h"
#include "shared/alpha.h"

// ---- The path's random numbers: the primary sample source (issue 19) ----------------------------
// Every draw of a path goes through pathSample2 / pathSample1 (key, dimension), the dimensions of
// rng.h. The default source hashes (pixel, sample index, dimension, seed) (or QMC: sample2). A
// stage specialised with PRIMARY_SAMPLES (constant 11; no integrator sets it yet) reads the first
// g.primaryDims dimensions of a path from g.primarySamples instead (layout.h, primarySampleIndex): the primary sample
// vector that a primary-sample-space Metropolis chain mutates (dimensions beyond them still hash).
// The samplers' further numbers follow their primary numbers (rng.h, rngStreamKey), so a path is
// a function of this vector. Off, the branch is compiled out and the images are those of the hash.
#if NUSSELT_SCENE_FEATURES
layout(constant_id = 11) const bool PRIMARY_SAMPLES = false;
#else
const bool PRIMARY_SAMPLES = false;
#endif

// The key of one path sample: its pixel and sample index, the render's mode and seed, and the
// path's slot (the index of its state and of its primary samples). With PRIMARY_SAMPLES, the
// buffer that holds the slot's vector (Globals.primarySamples, or a Metropolis chain's second
// buffer), the draws of it that are stored (the first `written`; all of them unless the pass
// leaves some out, Globals.primaryFresh) and the key of the others (mltFreshSample).
struct PathKey {
  uint rngMode;
  uint pixel;
  uint sampleIndex;
  uint seed;
  uint path;
  uint written;
  uvec2 freshKey;
  Vec2s vectors;
};

PathKey makePathKey(uint pixel, uint sampleIndex, uint path) {
  PathKey k = PathKey(g.rngMode, pixel, sampleIndex, g.seed, path, 0xffffffffu, uvec2(0u), g.primarySamples);
  if (PRIMARY_SAMPLES && g.primaryFresh != PRIMARY_FRESH_NONE) {
    Mlts mlt = g.mlt;
    k.written = 0u;
    if (g.primaryFresh == PRIMARY_FRESH_POOL) {
      uvec4 pool = mlt.v[0].pool;
      k.freshKey = uvec2(pool.x + path, pool.w);
    } else if (g.primaryFresh == PRIMARY_FRESH_PIXEL) {
      uvec4 pool = mlt.v[0].pool;
      k.freshKey = uvec2(pool.x + path % pool.y, mlt.v[0].outside.x + path / pool.y);
    } else {
      uint w = mlt.v[0].written.v[path];
      k.written = w & MLT_COUNT;
      if ((w & MLT_SIDE_B) != 0u) k.vectors = mlt.v[0].vectorsB;
      k.freshKey = uvec2(mlt.v[0].info.z, g.seed);
    }
  }
  return k;
}

PathKey pathKey(uint path) {
  uvec4 info = loadUVec4(g.pathInfo, path);
  return makePathKey(info.x, info.y, path);
}

vec2 pathSample2(PathKey k, uint dimension) {
  if (PRIMARY_SAMPLES && dimension < g.primaryDims) {
    if (dimension >= k.written) {
      if (g.primaryFresh == PRIMARY_FRESH_PIXEL)
        return mltPixelDraw(k.rngMode, k.freshKey.x, k.freshKey.y, dimension, k.seed, uvec2(g.width, g.height));
      return mltFreshSample(g.primaryFresh, k.path, dimension, k.freshKey);
    }
    return k.vectors.v[primarySampleIndex(k.path, dimension, g.primaryDims)];
  }
  return sample2(k.rngMode, k.pixel, k.sampleIndex, dimension, k.seed);
}

float pathSample1(PathKey k, uint dimension) { return pathSample2(k, dimension).x; }

// ---- Alpha coverage (glTF alphaMode; docs/scenes.md, "Alpha") ---------------------------------
// The tracing stages of a scene with MASK or BLEND materials test every candidate hit (constant
// 9, set by the integrator for intersect and shadow only; false elsewhere, the tools included).
#if NUSSELT_ALPHA
layout(constant_id = 9) const bool HAS_ALPHA = false;
#else
const bool HAS_ALPHA = false;
#endif

// The texel buffer as a plain reference (the globals block is readonly, and a member of it cannot
// be passed to a function parameter without that qualifier).
Uints texelBuffer() {
  Uints t = g.texels;
  return t;
}

#if NUSSELT_ALPHA
// alpha = baseColorFactor.a x the base-colour texture's alpha of a MASK or BLEND material at
// barycentrics (b1, b2) of triangle tri. (C++ twin: AlphaTester in src/render/texture_table.cpp.)
float alphaAt(uint material, uint tri, float b1, float b2) {
  GpuMaterialTextures T = g.materialTextures.v[material];
  float alpha = T.baseColorFactor.w;
  if (T.alpha.y != INVALID_INDEX)
    alpha *= textureAtHit(texelBuffer(), g.textures.v[T.alpha.y], g.texcoords.v[tri], b1, b2).w;
  return alpha;
}

// The expected coverage of a point: 1 for opaque materials, MASK 0 or 1 by the cutoff, BLEND
// alpha (the probability that alphaPasses lets a ray stop there). Light sampling weights an
// emitter's point by it, so that it agrees with what rays that meet the emitter see.
float alphaCoverage(uint material, uint tri, float b1, float b2) {
  if ((g.materials.v[material].info.y & MATERIAL_ALPHA) == 0u) return 1.0f;
  float alpha = alphaAt(material, tri, b1, b2);
  if (g.materialTextures.v[material].alpha.x == ALPHA_MASK) return alpha >= g.materialTextures.v[material].factors.w ? 1.0f : 0.0f;
  return clamp(alpha, 0.0f, 1.0f);
}

// Whether a candidate hit of triangle tri at barycentrics (b1, b2) of the ray (origin, dir)
// counts: the rule of shared/alpha.h (alphaTest) with the material's mode, alpha and cutoff.
bool alphaPasses(uint tri, float b1, float b2, vec3 origin, vec3 dir) {
  uint material = g.shading.v[tri].info.x;
  if ((g.materials.v[material].info.y & MATERIAL_ALPHA) == 0u) return true;
  GpuMaterialTextures T = g.materialTextures.v[material];
  return alphaTest(T.alpha.x, alphaAt(material, tri, b1, b2), T.factors.w, tri, origin, dir);
}
#else
bool alphaPasses(uint tri, float b1, float b2, vec3 origin, vec3 dir) { return true; }
#endif

#include "shared/trace.glsl"
#include "shared/envmap.h"
#include "shared/guiding.h"

layout(local_size_x = WORKGROUP_SIZE) in;

// The shade stages of a scene without an environment compile its light-sampling branch out: a
// render builds only what its scene needs (lavapipe's Mesa 22.3 ran every branch body a subgroup
// reached, taken or not; reference/lavapipe.md). Constant 7: after the shade stages' own 0..6.
layout(constant_id = 7) const bool HAS_ENVIRONMENT = true;
#if NUSSELT_SCENE_FEATURES
// Likewise the texture lookups of a scene without textures (Globals.texturedScene; constant 8).
layout(constant_id = 8) const bool HAS_TEXTURES = true;
// Path guiding (issue 16, docs/guiding.md): the shade and escape stages of a guided render only;
// without it every guiding branch is compiled out, and images are those of an unguided build.
layout(constant_id = 10) const bool GUIDING = false;
#else
const bool HAS_TEXTURES = false;
const bool GUIDING = false;
#endif

// ---- Queues ---------------------------------------------------------------------------------

// Which half of its dispatch this workgroup is in (0 or 1): lavapipe gives each of its threads a
// contiguous block of a dispatch's workgroups, so with two threads the halves are the threads'.
// The queue shards (layout.h, "Queue ids") and the trace stage's split (intersect.comp) use it.
uint dispatchHalf() { return gl_WorkGroupID.x >= gl_NumWorkGroups.x / 2u ? 1u : 0u; }

uint queueCount(uint queue) { return g.queues.v[queue] + g.queues.v[QUEUE_SHARD_STRIDE + queue]; }

// Item i < queueCount(queue): shard 0's items first, then shard 1's (layout.h, "Queue ids").
uint queueItem(uint queue, uint i) {
  uint first = g.queues.v[queue];
  uint slot = i < first ? i : g.pathCapacity - 1u - (i - first);
  return g.queues.v[QUEUE_HEADER_UINTS + queue * g.pathCapacity + slot];
}

// Push a path id. Lanes of a subgroup may push to different queues (intersect sends each hit
// to its model's shade queue): the lanes pushing to the same queue as the first remaining lane
// take one atomic together, then the others repeat (at most one round per distinct queue; one
// atomic per subgroup and queue instead of one per lane, which halves the cost on lavapipe).
// The same lane keeps the queue's indirect dispatch size current (each push adds the workgroups
// it opens in its shard: ceil(count / WORKGROUP_SIZE) per shard), so that no stage between
// producer and consumer has to turn counts into dispatch sizes (PathIntegrator::recordPass).
void queuePush(uint queue, uint path) {
  for (int round = 0; round < 128; ++round) {
    uint leader = subgroupBroadcastFirst(queue);
    if (leader == queue) {
      uvec4 ballot = subgroupBallot(true);
      uint n = subgroupBallotBitCount(ballot);
      uint rank = subgroupBallotExclusiveBitCount(ballot);
      uint shard = dispatchHalf();
      uint base = 0u;
      if (subgroupElect()) {
        base = atomicAdd(g.queues.v[shard * QUEUE_SHARD_STRIDE + queue], n);
        // Only a push that opens a workgroup (crosses a multiple of WORKGROUP_SIZE) touches the
        // dispatch sizes: one in WORKGROUP_SIZE / subgroup size pushes, so the two cores rarely
        // contend for their cache line (the count's atomic is the only one of the others).
        // Each shard opens its own workgroups: the dispatch has ceil(count0 / WORKGROUP_SIZE) +
        // ceil(count1 / WORKGROUP_SIZE) of them, at most one more than the items need (its
        // consumer's lanes past queueCount return).
        uint groups = (base + n + WORKGROUP_SIZE - 1u) / WORKGROUP_SIZE;
        uint opened = groups - (base + WORKGROUP_SIZE - 1u) / WORKGROUP_SIZE;
        if (opened > 0u) {
          Uints args = Uints(g.dispatchArgs);
          atomicAdd(args.v[4u * queue], opened);
          args.v[4u * queue + 1u] = 1u;
          args.v[4u * queue + 2u] = 1u;
          // The trace stage that consumes this queue runs the workgroups of its ray queue and of
          // its shadow queue in one dispatch: each push adds the workgroups it opened there too
          // (a shard's pushes' ranges are disjoint, so they sum to its ceil(count /
          // WORKGROUP_SIZE)). Ray queue q feeds trace(b) with b & 1 = q; shadow queue s (filled at
          // bounce b, s = b & 1) feeds trace(b + 1).
          if (queue <= QUEUE_SHADOW1) {
            uint trace = ARGS_TRACE0 + (queue <= QUEUE_RAY1 ? queue : (queue - QUEUE_SHADOW0) ^ 1u);
            atomicAdd(args.v[4u * trace], opened);
            args.v[4u * trace + 1u] = 1u;
            args.v[4u * trace + 2u] = 1u;
          }
        }
      }
      base = subgroupBroadcastFirst(base) + rank;
      uint slot = shard == 0u ? base : g.pathCapacity - 1u - base;
      g.queues.v[QUEUE_HEADER_UINTS + queue * g.pathCapacity + slot] = path;
      return;
    }
  }
}

// ---- Rays -----------------------------------------------------------------------------------

// Move a ray origin off a surface along its geometric normal n by a few ulps of the position
// (Waechter and Binder, "A Fast and Robust Method for Avoiding Self-Intersection", Ray Tracing
// Gems, ch. 6, 2019). Their fixed constants assume a scene of size ~1 near the origin: near the
// origin they add an absolute 1/65536, which is 15 % of a scene of size 1e-4. Here both the
// near-origin threshold and that offset scale with the scene's bounding radius, so scenes from
// 1e-4 to 1e6 units behave alike; elsewhere the offset is 256 ulps of each coordinate.
vec3 offsetRay(vec3 p, vec3 n) {
  const float intScale = 256.0f;
  float scale = max(g.sceneSphere.w, 1e-30f);
  float origin = scale / 32.0f;
  float floatScale = scale / 65536.0f;
  ivec3 of = ivec3(intScale * n.x, intScale * n.y, intScale * n.z);
  vec3 pi = vec3(intBitsToFloat(floatBitsToInt(p.x) + ((p.x < 0.0f) ? -of.x : of.x)),
                 intBitsToFloat(floatBitsToInt(p.y) + ((p.y < 0.0f) ? -of.y : of.y)),
                 intBitsToFloat(floatBitsToInt(p.z) + ((p.z < 0.0f) ? -of.z : of.z)));
  return vec3(abs(p.x) < origin ? p.x + floatScale * n.x : pi.x,
              abs(p.y) < origin ? p.y + floatScale * n.y : pi.y,
              abs(p.z) < origin ? p.z + floatScale * n.z : pi.z);
}

// ---- Triangles ------------------------------------------------------------------------------

vec3 triangleNormalUnnormalized(uint tri) {
  GpuTriangle t = loadTriangle(g.triangles, tri);
  return cross(t.e1.xyz, t.e2.xyz);
}

// ---- Textures (shared/texture.h; docs/scenes.md, "Textures") ------------------------------------

// Texture `tex` (an index into g.textures) at barycentrics (b1, b2) of triangle tri.
vec4 sceneTexture(uint tex, uint tri, float b1, float b2) {
  return textureAtHit(texelBuffer(), g.textures.v[tex], g.texcoords.v[tri], b1, b2);
}

// The emitted radiance of `material` at barycentrics (b1, b2) of triangle tri: its emission times
// its emissive texture when one applies. Light selection and its pdf use the emission factor only
// (src/render/device_scene.cpp), so the texture enters as a value at the sampled or hit point and
// both estimators (light sampling and BSDF sampling, with MIS) stay unbiased.
vec3 texturedEmission(uint material, vec3 emission, uint tri, float b1, float b2) {
#if NUSSELT_SCENE_FEATURES
  if (!HAS_TEXTURES || (g.materials.v[material].info.y & MATERIAL_TEXTURED) == 0u) return emission;
  uint tex = g.materialTextures.v[material].maps.z;
  return tex == INVALID_INDEX ? emission : emission * sceneTexture(tex, tri, b1, b2).xyz;
#else
  return emission;
#endif
}

// ---- Lights ---------------------------------------------------------------------------------

// Probability of selecting light i (the CDF is proportional to estimated power).
float lightSelectPdf(uint i) { return g.lightCdf.v[i + 1u] - g.lightCdf.v[i]; }

// Light index for u in [0, 1): binary search over the CDF (at most 32 iterations).
uint selectLight(float u) {
  uint lo = 0u;
  uint hi = g.lightCount;  // the CDF has lightCount + 1 entries
  for (int it = 0; it < 32 && lo + 1u < hi; ++it) {
    uint mid = (lo + hi) / 2u;
    if (g.lightCdf.v[mid] <= u) lo = mid; else hi = mid;
  }
  return lo;
}

// Solid-angle pdf with which light sampling would have chosen the point hit at distance t on
// emitting triangle tri seen under cosLight (> 0); used for MIS when a BSDF ray hits an emitter.
float triangleLightPdf(uint lightIndex, uint tri, float t, float cosLight) {
  float area = 0.5f * length(triangleNormalUnnormalized(tri));
  return lightSelectPdf(lightIndex) * t * t / max(area * cosLight, 1e-30f);
}

// A light sample seen from point x: direction wi (unit, world), distance (inf for directional),
// the radiance or irradiance it carries divided by its pdf, and the solid-angle pdf (0 for
// punctual lights, which no BSDF sample can hit).
struct LightSample {
  vec3 wi;
  float dist;
  vec3 value;   // Le / pdf (area lights) or I / r^2 / pSelect (punctual)
  float pdf;    // solid angle, including the selection probability; 0: delta light
};

bool sampleLight(vec3 x, float uSelect, vec2 uPoint, out LightSample ls) {
  ls.wi = vec3(0.0f);
  ls.dist = 0.0f;
  ls.value = vec3(0.0f);
  ls.pdf = 0.0f;
  if (g.lightCount == 0u) return false;
  uint li = selectLight(uSelect);
  float pSelect = lightSelectPdf(li);
  if (pSelect <= 0.0f) return false;
  GpuLight light = loadLight(g.lights, li);
  uint type = light.info.x;
  if (type == LIGHT_TRIANGLE) {
    uint tri = light.info.y;
    GpuTriangle t = loadTriangle(g.triangles, tri);
    vec2 b = squareToTriangle(uPoint);
    vec3 y = t.v0.xyz + b.x * t.e1.xyz + b.y * t.e2.xyz;
    vec3 nu = cross(t.e1.xyz, t.e2.xyz);
    float area2 = length(nu);
    vec3 ny = nu / area2;
    vec3 d = y - x;
    float dist2 = dot(d, d);
    if (dist2 <= 0.0f) return false;
    float dist = sqrt(dist2);
    ls.wi = d / dist;
    float cosLight = -dot(ls.wi, ny);   // emitters radiate on their front side only
    if (cosLight <= 0.0f) return false;
    ls.pdf = pSelect * dist2 / (0.5f * area2 * cosLight);
    uint material = g.shading.v[tri].info.x;
    vec3 Le = g.materials.v[material].emission.xyz;
    if (HAS_TEXTURES) Le = texturedEmission(material, Le, tri, b.x, b.y);
#if NUSSELT_SCENE_FEATURES && NUSSELT_ALPHA
    // An emitter with alpha (MASK or BLEND): the sampled point emits as much as rays that meet the
    // emitter there see on average (a cut-out point nothing, a BLEND point alpha of it).
    if (HAS_TEXTURES) Le *= alphaCoverage(material, tri, b.x, b.y);
#endif
    ls.value = Le / ls.pdf;
    ls.dist = dist;
    return ls.pdf > 0.0f && isFinite(ls.pdf);
  }
  if (HAS_ENVIRONMENT && type == LIGHT_ENVIRONMENT) {
    // The environment map, importance-sampled (shaders/shared/envmap.h); shadow rays go to infinity.
    GpuEnvironment E = g.environment.v[0];
    float pdf;
    ls.wi = envSample(E, uPoint, pdf);
    if (!(pdf > 0.0f)) return false;
    ls.pdf = pSelect * pdf;
    ls.dist = 3.0e38f;
    ls.value = envRadiance(E, ls.wi) / ls.pdf;
    return isFinite(ls.pdf);
  }
  if (type == LIGHT_DIRECTIONAL) {
    ls.wi = -light.direction.xyz;
    ls.dist = 3.0e38f;
    ls.value = light.intensity.xyz / pSelect;
    return true;
  }
  // point and spot
  vec3 d = light.position.xyz - x;
  float dist2 = dot(d, d);
  if (dist2 <= 0.0f) return false;
  ls.dist = sqrt(dist2);
  ls.wi = d / ls.dist;
  float falloff = 1.0f;
  if (type == LIGHT_SPOT) {
    // glTF KHR_lights_punctual's suggested smooth cone attenuation.
    float cd = dot(-ls.wi, light.direction.xyz);
    float cosInner = light.cone.x;
    float cosOuter = light.cone.y;
    float s = clamp((cd - cosOuter) / max(cosInner - cosOuter, 1e-4f), 0.0f, 1.0f);
    falloff = s * s;
  }
  ls.value = light.intensity.xyz * (falloff / (dist2 * pSelect));
  return falloff > 0.0f;
}

// ---- Deterministic sums ------------------------------------------------------------------------

// Adds x (>= 0, x * scale < 2^64) to the 64-bit fixed-point integer words[at] (low word) and
// words[at + 1] (high word) of `scale` units per unit (a power of two, so every step below is
// exact): the carry of the low word goes to the high word. Integer additions commute, so many
// invocations' adds give the same sum in any order (the Metropolis and VEGAS splats).
void atomicAddFixed64(Uints words, uint at, float x, float scale) {
  float hiUnit = 4294967296.0f / scale;  // one unit of the high word
  uint hi = uint(floor(x * (scale * (1.0f / 4294967296.0f))));
  float rest = x - float(hi) * hiUnit;
  uint lo = uint(min(rest * scale + 0.5f, 4294967040.0f));
  uint old = atomicAdd(words.v[at], lo);
  uint carry = old + lo < old ? 1u : 0u;
  if (hi + carry != 0u) atomicAdd(words.v[at + 1u], hi + carry);
}
