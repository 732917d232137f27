#version 460
#extension GL_GOOGLE_include_directive : require
// shade: one pipeline per reflectance model the scene uses (MODEL_ID is a specialization
// constant, so this kernel contains exactly one model). For each hit in its queue:
// emission (MIS-weighted), next-event estimation (a shadow ray), BSDF sampling of the next
// direction and Russian roulette, as a random walk whose transitions follow the BRDF.
#include "shared/stage_common.glsl"
#include "shared/bsdf_sampling.h"

layout(constant_id = 0) const uint MODEL_ID = 0u;
layout(constant_id = 1) const uint SAMPLER = SAMPLER_QUADTREE;

void main() {
  uint idx = gl_GlobalInvocationID.x;
  uint queue = QUEUE_SHADE_BASE + pc.modelSlot;
  if (idx >= queueCount(queue)) return;
  uint path = queueItem(queue, idx);
  uint bounce = pc.bounce;
  uint pixel = g.pathInfo.v[path].x;
  uint sampleIndex = g.frame.x;
  uint seed = g.frame.y;
  uint lighting = g.counts.w;
  uint rngMode = g.options.x;

  // ---- Hit geometry ----
  vec4 hit = g.pathHit.v[path];
  uint tri = floatBitsToUint(hit.w);
  vec3 rayO = g.pathOrigin.v[path].xyz;
  vec4 rayD = g.pathDirection.v[path];
  vec3 dir = rayD.xyz;
  float prevPdf = rayD.w;
  GpuTriangle T = g.triangles.v[tri];
  GpuTriShading S = g.shading.v[tri];
  vec3 x = T.v0.xyz + hit.y * T.e1.xyz + hit.z * T.e2.xyz;
  vec3 ngFront = normalize(cross(T.e1.xyz, T.e2.xyz));
  vec3 ns = normalize((1.0f - hit.y - hit.z) * S.n0.xyz + hit.y * S.n1.xyz + hit.z * S.n2.xyz);
  GpuMaterial M = g.materials.v[S.info.x];
  vec3 beta = g.pathThroughput.v[path].xyz;
  vec3 L = vec3(0.0f);

  // ---- Emission: one-sided emitters radiate along their geometric normal ----
  bool frontFace = dot(ngFront, dir) < 0.0f;
  if ((M.info.y & MATERIAL_EMISSIVE) != 0u && frontFace) {
    float w = 1.0f;
    if (bounce > 0u && prevPdf > 0.0f) {  // reached by a BSDF sample that light sampling could also make
      if (lighting == LIGHTING_NEE_ONLY) {
        w = 0.0f;
      } else if (lighting == LIGHTING_MIS) {
        float lightPdf = triangleLightPdf(S.info.y, tri, hit.x, -dot(ngFront, dir));
        w = powerHeuristic(prevPdf, lightPdf);
      }
    }
    L += beta * M.emission.xyz * w;
  }

  // ---- Local frame: surfaces are two-sided, shade the side the ray came from ----
  vec3 ng = frontFace ? ngFront : -ngFront;
  if (dot(ns, ng) < 0.0f) ns = -ns;
  vec3 wWorld = -dir;
  vec3 tt;
  vec3 bb;
  makeFrame(ns, tt, bb);
  vec3 wo = toLocal(wWorld, tt, bb, ns);
  if (wo.z <= 0.0f) {  // shading normal facing away from the viewer: fall back to the geometric one
    ns = ng;
    makeFrame(ns, tt, bb);
    wo = toLocal(wWorld, tt, bb, ns);
  }
  vec3 xo = offsetRay(x, ng);
  bool last = bounce >= g.frame.z;

  // ---- Next-event estimation ----
  if (!last && lighting != LIGHTING_BSDF_ONLY && !modelIsDelta(MODEL_ID)) {
    float uSel = sample1(rngMode, pixel, sampleIndex, rngDimension(bounce, RNG_DIM_LIGHT_SELECT), seed);
    vec2 uPt = sample2(rngMode, pixel, sampleIndex, rngDimension(bounce, RNG_DIM_LIGHT_POINT), seed);
    LightSample ls;
    if (sampleLight(xo, uSel, uPt, ls) && dot(ls.wi, ng) > 0.0f) {
      vec3 wiL = toLocal(ls.wi, tt, bb, ns);
      vec3 f = brdfEval(MODEL_ID, M.params, wiL, wo);
      float cosS = max(wiL.z, 0.0f);
      vec3 c = beta * f * cosS * ls.value;
      if (ls.pdf > 0.0f && lighting == LIGHTING_MIS)
        c *= powerHeuristic(ls.pdf, bsdfPdf(SAMPLER, MODEL_ID, M.info.z, M.params, wo, wiL));
      if (max(c.x, max(c.y, c.z)) > 0.0f) {
        // Stop short of the light so that the emitter itself never occludes.
        float tmax = ls.dist < 1.0e38f ? ls.dist * (1.0f - 1e-4f) : ls.dist;
        g.shadowOrigin.v[path] = vec4(xo, tmax);
        g.shadowDirection.v[path] = vec4(ls.wi, 0.0f);
        g.shadowRadiance.v[path] = vec4(c, 0.0f);
        queuePush(QUEUE_SHADOW, path);
      }
    }
  }

  g.pathRadiance.v[path].xyz += L;
  if (last) return;

  // ---- BSDF sampling: the next step of the random walk ----
  uint dimB = rngDimension(bounce, RNG_DIM_BSDF);
  vec2 uB = sample2(rngMode, pixel, sampleIndex, dimB, seed);
  vec3 wiLocal;
  vec3 weight;
  float pdf;
  float q;
  if (!bsdfSample(SAMPLER, MODEL_ID, M.info.z, M.params, wo, !frontFace, uB, uvec4(pixel, sampleIndex, dimB, seed),
                  wiLocal, weight, pdf, q))
    return;
  vec3 wi = toWorld(wiLocal, tt, bb, ns);
  // Reflection must stay above the geometric surface (else light leaks through it); refraction
  // (only delta models transmit) must cross it, and leaves from the other side.
  bool transmitted = wiLocal.z < 0.0f;
  if (transmitted != (dot(wi, ng) < 0.0f)) return;
  if (transmitted) xo = offsetRay(x, -ng);

  // ---- Russian roulette with the continuation probability of the sample (the albedo) ----
  // Surviving paths are divided by the probability (unbiased).
  float uR = sample1(rngMode, pixel, sampleIndex, rngDimension(bounce, RNG_DIM_ROULETTE), seed);
  if (!(q > 0.0f) || uR >= q) return;
  beta *= weight / q;

  g.pathOrigin.v[path] = vec4(xo, 0.0f);
  g.pathDirection.v[path] = vec4(wi, pdf);
  g.pathThroughput.v[path] = vec4(beta, 0.0f);
  queuePush(((bounce + 1u) & 1u), path);
}
