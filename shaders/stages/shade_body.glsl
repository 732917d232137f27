// shade_body.glsl: the shade stage, compiled twice: shade.comp (SHADE_COMBINED 0: single-model
// materials) and shade_combined.comp (SHADE_COMBINED 1: combined materials). Two SPIR-V modules
// instead of one with a specialization-constant branch: lavapipe inlines every call before it
// folds the constants, and the combined path (four component slots, each with every model and
// sampler) made the single-model pipelines 20x slower to create (bench pipelines: 5.1 s instead
// of 0.26 s for the default scene).
// shade: one pipeline per reflectance model the scene uses (MODEL_ID is a specialization
// constant, so this kernel contains exactly one model). For each hit in its queue:
// emission (MIS-weighted), next-event estimation (a shadow ray), BSDF sampling of the next
// direction and Russian roulette, as a random walk whose transitions follow the BRDF.
// Combined materials (COMPONENT_COUNT > 0) get one pipeline per tuple of component models
// (MODEL_0..MODEL_3): every call below that takes a component's model takes a specialization
// constant, so each kernel contains exactly its components' code (shaders/shared/combined.h).
#include "shared/stage_common.glsl"
#include "shared/combined.h"
STAGE_PUSH(BounceConstants);

#ifdef NUSSELT_SHADE_MODEL_ID
// A module built for one model (shade_<model>_sN, CMakeLists.txt): its id is a constant.
const uint MODEL_ID = NUSSELT_SHADE_MODEL_ID;
#else
layout(constant_id = 0) const uint MODEL_ID = 0u;
#endif
layout(constant_id = 1) const uint SAMPLER = SAMPLER_QUADTREE;
#if SHADE_COMBINED
// 1..MAX_COMPONENTS: the number of components of the combined material.
layout(constant_id = 2) const uint COMPONENT_COUNT = 1u;
layout(constant_id = 3) const uint MODEL_0 = 0u;
layout(constant_id = 4) const uint MODEL_1 = 0u;
layout(constant_id = 5) const uint MODEL_2 = 0u;
layout(constant_id = 6) const uint MODEL_3 = 0u;

// ---- Combined materials: per-component terms (model = a specialization constant) ----
// w_k f_k(wi, wo); 0 for delta components (never evaluated).
vec3 componentEval(uint model, GpuComponent C, vec3 wi, vec3 wo) {
  return modelIsDelta(model) ? vec3(0.0f) : C.data.x * brdfEval(model, C.params, wi, wo);
}
// c_k pdf_k(wi): the component's share of the MIS density (0 for delta components).
float componentMisPdf(uint model, GpuComponent C, float c, vec3 wo, vec3 wi) {
  return c > 0.0f ? c * bsdfPdf(SAMPLER, model, C.info.y, C.params, wo, wi) : 0.0f;
}
#endif

// ---- evalParams: the material's parameters at the hit (textures; docs/scenes.md, "Textures") ----
// params: the model's parameters (the material's factors on entry); emission: its emitted
// radiance. gltf_pbr: baseColor x baseColorTexture.rgb (sRGB decoded), metallic x B and roughness
// x G of metallicRoughnessTexture; any model: emission x emissiveTexture.rgb (sRGB decoded).
#if NUSSELT_SCENE_FEATURES
void evalParams(uint model, uint material, uint tri, float b1, float b2, inout BrdfParams params,
                inout vec3 emission) {
  GpuMaterialTextures T = g.materialTextures.v[material];
  GpuTriTexcoords uv = g.texcoords.v[tri];
  if (T.maps.z != INVALID_INDEX) emission *= textureAtHit(texelBuffer(), g.textures.v[T.maps.z], uv, b1, b2).xyz;
  if (model == MODEL_GLTF_PBR) {
    if (T.maps.x != INVALID_INDEX) {
      vec4 c = textureAtHit(texelBuffer(), g.textures.v[T.maps.x], uv, b1, b2);
      for (uint k = 0u; k < 3u; ++k)
        params.v[(GLTF_PBR_BASE_COLOR + k) / 4u][(GLTF_PBR_BASE_COLOR + k) % 4u] *= c[k];
    }
    if (T.maps.y != INVALID_INDEX) {
      vec4 mr = textureAtHit(texelBuffer(), g.textures.v[T.maps.y], uv, b1, b2);
      params.v[GLTF_PBR_METALLIC / 4u][GLTF_PBR_METALLIC % 4u] *= mr.z;
      params.v[GLTF_PBR_ROUGHNESS / 4u][GLTF_PBR_ROUGHNESS % 4u] *= mr.y;
    }
  }
}

// ---- The normal map (docs/scenes.md, "Normal maps") ----
// The shading normal from material's normal texture at the hit, or ns (the interpolated shading
// normal) unchanged when there is none. Frame: the interpolated tangent made orthogonal to ns
// (Gram-Schmidt), bitangent w cross(ns, t) with corner 0's sign w; the texel maps [0, 1] to
// [-1, 1], x and y times normalScale, and n = x t + y b + z ns. The rule that keeps paths above
// the geometric surface starts here: the mapped normal replaces ns only when it lies on the same
// side of the geometric surface (ngFront) as ns; main() then orients it to the viewer's side and
// falls back to the geometric normal when the viewer is below its hemisphere.
vec3 normalMapped(uint material, uint tri, float b1, float b2, vec3 ns, vec3 ngFront) {
  uint tex = g.materialTextures.v[material].maps.w;
  if (tex == INVALID_INDEX) return ns;
  float scale = g.materialTextures.v[material].factors.z;
  vec4 t0 = g.tangents.v[3u * tri];
  vec4 t1 = g.tangents.v[3u * tri + 1u];
  vec4 t2 = g.tangents.v[3u * tri + 2u];
  vec3 t = (1.0f - b1 - b2) * t0.xyz + b1 * t1.xyz + b2 * t2.xyz;
  t -= dot(t, ns) * ns;
  float tl = length(t);
  if (!(tl > 1e-6f)) return ns;
  t /= tl;
  vec3 bt = (t0.w < 0.0f ? -1.0f : 1.0f) * cross(ns, t);
  // A texture transform with a linear part (rotation, scale) turns the map's axes on the surface:
  // the frame follows them (textureTransformFrame), with the triangle's |dS/du|, |dS/dv| of the
  // map's coordinate set and the frame's handedness against them; then orthonormal about ns again.
  GpuTexture map = g.textures.v[tex];
  if (map.transform0 != vec4(1.0f, 0.0f, 0.0f, 1.0f)) {
    GpuTriangle T = g.triangles.v[tri];
    GpuTriTexcoords tc = g.texcoords.v[tri];
    uint set = (map.info.w & TEXTURE_FLAG_SET1) != 0u ? 1u : 0u;
    vec2 w0 = triangleTexcoord(tc, set, 0.0f, 0.0f);
    vec2 d1 = triangleTexcoord(tc, set, 1.0f, 0.0f) - w0;
    vec2 d2 = triangleTexcoord(tc, set, 0.0f, 1.0f) - w0;
    float r = d1.x * d2.y - d2.x * d1.y;
    vec3 du = (T.e1.xyz * d2.y - T.e2.xyz * d1.y) / r;
    vec3 dv = (T.e2.xyz * d1.x - T.e1.xyz * d2.x) / r;
    if (r != 0.0f && isFinite(r)) {
      textureTransformFrame(map, length(du), length(dv), dot(bt, dv) < 0.0f ? -1.0f : 1.0f, t, bt);
      t -= dot(t, ns) * ns;
      tl = length(t);
      if (!(tl > 1e-6f)) return ns;
      t /= tl;
      bt = (dot(bt, cross(ns, t)) < 0.0f ? -1.0f : 1.0f) * cross(ns, t);
    }
  }
  vec3 c = sceneTexture(tex, tri, b1, b2).xyz * 2.0f - 1.0f;
  vec3 n = c.x * scale * t + c.y * scale * bt + c.z * ns;
  float nl = length(n);
  if (!(nl > 1e-6f)) return ns;
  n /= nl;
  return dot(n, ngFront) * dot(ns, ngFront) > 0.0f ? n : ns;
}
#else
// A module without textures (NUSSELT_SCENE_FEATURES 0, stage_common.glsl): empty stand-ins.
void evalParams(uint model, uint material, uint tri, float b1, float b2, inout BrdfParams params,
                inout vec3 emission) {}
vec3 normalMapped(uint material, uint tri, float b1, float b2, vec3 ns, vec3 ngFront) { return ns; }
#endif

void main() {
  uint idx = gl_GlobalInvocationID.x;
  uint queue = QUEUE_SHADE_BASE + pc.modelSlot;
  if (idx >= queueCount(queue)) return;
  uint path = queueItem(queue, idx);
  uint bounce = pc.bounce;
  uvec4 info = g.pathInfo.v[path];
  uint pixel = info.x;
  uint sampleIndex = info.y;
  uint seed = g.seed;
  uint lighting = g.lighting;
  uint rngMode = g.rngMode;
  uint roulette = g.roulette;

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
  // evalParams: the parameters and emission at this point (differ from M's only where textured).
  vec3 Le = M.emission.xyz;
#if SHADE_COMBINED
  if (HAS_TEXTURES && (M.info.y & MATERIAL_TEXTURED) != 0u) evalParams(INVALID_INDEX, S.info.x, tri, hit.y, hit.z, M.params, Le);
#else
  if (HAS_TEXTURES && (M.info.y & MATERIAL_TEXTURED) != 0u) evalParams(MODEL_ID, S.info.x, tri, hit.y, hit.z, M.params, Le);
#endif
  if (HAS_TEXTURES && (M.info.y & MATERIAL_TEXTURED) != 0u) ns = normalMapped(S.info.x, tri, hit.y, hit.z, ns, ngFront);
  vec4 throughput = g.pathThroughput.v[path];
  vec3 beta = throughput.xyz;
  float etaScale = throughput.w;
  vec3 L = vec3(0.0f);
  if (GUIDING) guideRecordArrival(path, bounce, x);  // training record (guiding.h)

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
    L += beta * Le * w;
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
  bool last = bounce >= g.maxDepth;

#if !SHADE_COMBINED
  {
    // ---- A single-model material ----
    // The guide's region (path guiding, guiding.h): never for delta models.
    GuideVertex gv = GuideVertex(0u, 0.0f);
    if (GUIDING && !modelIsDelta(MODEL_ID)) gv = guideVertex(x);
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
        if (ls.pdf > 0.0f && lighting == LIGHTING_MIS) {
          float pdfB = bsdfPdf(SAMPLER, MODEL_ID, M.info.z, M.params, wo, wiL);
          if (GUIDING) pdfB = guideMixture(gv, ls.wi, pdfB);
          c *= powerHeuristic(ls.pdf, pdfB);
        }
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
    // Path guiding: the guide with probability alpha, the BSDF sampler otherwise (one-sample MIS).
    vec2 uG = vec2(1.0f);
    if (GUIDING && gv.alpha > 0.0f) uG = sample2(rngMode, pixel, sampleIndex, rngDimension(bounce, RNG_DIM_GUIDE), seed);
    bool guided = GUIDING && uG.x < gv.alpha;
    if (guided) {
      if (!guideSampleLocal(gv, uG.y, rngMode, pixel, sampleIndex, bounce, seed, tt, bb, ns, wiLocal)) return;
      weight = brdfEval(MODEL_ID, M.params, wiLocal, wo) * wiLocal.z;  // f cos, over the mixture below
      pdf = 1.0f;
      q = 1.0f;
    } else if (!bsdfSample(SAMPLER, MODEL_ID, M.info.z, M.params, wo, !frontFace, uB, uvec4(pixel, sampleIndex, dimB, seed),
                           wiLocal, weight, pdf, q))
      return;
    if (GUIDING && gv.alpha > 0.0f) {
      // The mixture's density, for the weight f cos / pdf and for MIS at the next hit.
      float pdfB = guided ? bsdfPdf(SAMPLER, MODEL_ID, M.info.z, M.params, wo, wiLocal) : pdf;
      float pdfMix = guideMixture(gv, toWorld(wiLocal, tt, bb, ns), pdfB);
      if (!(pdfMix > 0.0f)) return;
      weight *= pdf / pdfMix;
      if (guided) q = min(1.0f, luminance(weight));
      pdf = pdfMix;
    }
    vec3 wi = toWorld(wiLocal, tt, bb, ns);
    // Reflection must stay above the geometric surface (else light leaks through it); refraction
    // (only delta models transmit) must cross it, and leaves from the other side.
    bool transmitted = wiLocal.z < 0.0f;
    if (transmitted != (dot(wi, ng) < 0.0f)) return;
    if (transmitted) xo = offsetRay(x, -ng);

    // ---- Russian roulette: on the throughput (default), or with the continuation probability
    // of the sample (the source's albedo roulette). Survivors are divided by the probability.
    float uR = sample1(rngMode, pixel, sampleIndex, rngDimension(bounce, RNG_DIM_ROULETTE), seed);
    if (roulette == ROULETTE_ALBEDO) {
      if (!(q > 0.0f) || uR >= q) return;
      beta *= weight / q;
    } else {
      beta *= weight;
      if (transmitted) etaScale *= transmissionEtaScale(MODEL_ID, M.params, !frontFace);
      if (!throughputRoulette(bounce, beta, etaScale, uR)) return;
    }

    if (GUIDING) guideRecordSample(path, bounce, wi, modelIsDelta(MODEL_ID) ? -1.0f : luminance(beta) * pdf);
    g.pathOrigin.v[path] = vec4(xo, 0.0f);
    g.pathDirection.v[path] = vec4(wi, pdf);
    g.pathThroughput.v[path] = vec4(beta, etaScale);
    queuePush(((bounce + 1u) & 1u), path);
    return;
  }

#else
  // ---- A combined material: sum_k w_k f_k (shaders/shared/combined.h, docs/models.md) ----
  GpuComponent C0, C1, C2, C3;
  vec4 a = vec4(0.0f);  // choice weights a_k = w_k A_k(wo), from wo only
  uint first = M.components.x;
  uint mode = combinedChoiceMode(g.componentChoice, roulette);
  if (COMPONENT_COUNT > 0u) { C0 = g.components.v[first]; a.x = componentChoiceWeight(mode, SAMPLER, MODEL_0, C0, wo); }
  if (COMPONENT_COUNT > 1u) { C1 = g.components.v[first + 1u]; a.y = componentChoiceWeight(mode, SAMPLER, MODEL_1, C1, wo); }
  if (COMPONENT_COUNT > 2u) { C2 = g.components.v[first + 2u]; a.z = componentChoiceWeight(mode, SAMPLER, MODEL_2, C2, wo); }
  if (COMPONENT_COUNT > 3u) { C3 = g.components.v[first + 3u]; a.w = componentChoiceWeight(mode, SAMPLER, MODEL_3, C3, wo); }
  vec4 P = combinedChoiceProbabilities(mode, COMPONENT_COUNT, a);
  vec4 c = combinedMisProbabilities(P);
  // Delta components take no light samples and have no MIS density: their c is dropped below.
  if (modelIsDelta(MODEL_0)) c.x = 0.0f;
  if (modelIsDelta(MODEL_1)) c.y = 0.0f;
  if (modelIsDelta(MODEL_2)) c.z = 0.0f;
  if (modelIsDelta(MODEL_3)) c.w = 0.0f;

  // ---- Next-event estimation: the sum of the non-delta components ----
  if (!last && lighting != LIGHTING_BSDF_ONLY && (M.info.y & MATERIAL_DELTA) == 0u) {
    float uSel = sample1(rngMode, pixel, sampleIndex, rngDimension(bounce, RNG_DIM_LIGHT_SELECT), seed);
    vec2 uPt = sample2(rngMode, pixel, sampleIndex, rngDimension(bounce, RNG_DIM_LIGHT_POINT), seed);
    LightSample ls;
    if (sampleLight(xo, uSel, uPt, ls) && dot(ls.wi, ng) > 0.0f) {
      vec3 wiL = toLocal(ls.wi, tt, bb, ns);
      vec3 f = vec3(0.0f);
      float pdfB = 0.0f;
      if (COMPONENT_COUNT > 0u) { f += componentEval(MODEL_0, C0, wiL, wo); pdfB += componentMisPdf(MODEL_0, C0, c.x, wo, wiL); }
      if (COMPONENT_COUNT > 1u) { f += componentEval(MODEL_1, C1, wiL, wo); pdfB += componentMisPdf(MODEL_1, C1, c.y, wo, wiL); }
      if (COMPONENT_COUNT > 2u) { f += componentEval(MODEL_2, C2, wiL, wo); pdfB += componentMisPdf(MODEL_2, C2, c.z, wo, wiL); }
      if (COMPONENT_COUNT > 3u) { f += componentEval(MODEL_3, C3, wiL, wo); pdfB += componentMisPdf(MODEL_3, C3, c.w, wo, wiL); }
      float cosS = max(wiL.z, 0.0f);
      vec3 contrib = beta * f * cosS * ls.value;
      if (ls.pdf > 0.0f && lighting == LIGHTING_MIS) contrib *= powerHeuristic(ls.pdf, pdfB);
      if (max(contrib.x, max(contrib.y, contrib.z)) > 0.0f) {
        float tmax = ls.dist < 1.0e38f ? ls.dist * (1.0f - 1e-4f) : ls.dist;
        g.shadowOrigin.v[path] = vec4(xo, tmax);
        g.shadowDirection.v[path] = vec4(ls.wi, 0.0f);
        g.shadowRadiance.v[path] = vec4(contrib, 0.0f);
        queuePush(QUEUE_SHADOW, path);
      }
    }
  }

  g.pathRadiance.v[path].xyz += L;
  if (last) return;

  // ---- Component choice (albedo mode under the albedo roulette: includes the roulette) ----
  float uC = sample1(rngMode, pixel, sampleIndex, rngDimension(bounce, RNG_DIM_COMPONENT), seed);
  uint k;
  float pk;
  if (!combinedPick(mode, COMPONENT_COUNT, a, uC, k, pk) || !(pk > 0.0f)) return;

  // ---- Sample the chosen component ----
  uint dimB = rngDimension(bounce, RNG_DIM_BSDF);
  vec2 uB = sample2(rngMode, pixel, sampleIndex, dimB, seed);
  uvec4 key = uvec4(pixel, sampleIndex, dimB, seed);
  vec3 wiLocal = vec3(0.0f, 0.0f, 1.0f);
  vec3 weight = vec3(0.0f);
  float pdf = 0.0f;
  float qk;  // the component's own continuation: not used (the choice above is the roulette)
  bool ok = false;
  bool delta = false;
  float wk = 0.0f;
  float etaK = 1.0f;  // transmissionEtaScale of the chosen component
  if (COMPONENT_COUNT > 0u && k == 0u) {
    ok = bsdfSample(SAMPLER, MODEL_0, C0.info.y, C0.params, wo, !frontFace, uB, key, wiLocal, weight, pdf, qk);
    delta = modelIsDelta(MODEL_0);
    wk = C0.data.x;
    etaK = transmissionEtaScale(MODEL_0, C0.params, !frontFace);
  }
  if (COMPONENT_COUNT > 1u && k == 1u) {
    ok = bsdfSample(SAMPLER, MODEL_1, C1.info.y, C1.params, wo, !frontFace, uB, key, wiLocal, weight, pdf, qk);
    delta = modelIsDelta(MODEL_1);
    wk = C1.data.x;
    etaK = transmissionEtaScale(MODEL_1, C1.params, !frontFace);
  }
  if (COMPONENT_COUNT > 2u && k == 2u) {
    ok = bsdfSample(SAMPLER, MODEL_2, C2.info.y, C2.params, wo, !frontFace, uB, key, wiLocal, weight, pdf, qk);
    delta = modelIsDelta(MODEL_2);
    wk = C2.data.x;
    etaK = transmissionEtaScale(MODEL_2, C2.params, !frontFace);
  }
  if (COMPONENT_COUNT > 3u && k == 3u) {
    ok = bsdfSample(SAMPLER, MODEL_3, C3.info.y, C3.params, wo, !frontFace, uB, key, wiLocal, weight, pdf, qk);
    delta = modelIsDelta(MODEL_3);
    wk = C3.data.x;
    etaK = transmissionEtaScale(MODEL_3, C3.params, !frontFace);
  }
  if (!ok || !(wk > 0.0f)) return;
  vec3 wi = toWorld(wiLocal, tt, bb, ns);
  bool transmitted = wiLocal.z < 0.0f;
  if (transmitted != (dot(wi, ng) < 0.0f)) return;
  if (transmitted) xo = offsetRay(x, -ng);

  // ---- Weight: w_k f_k cos / (P_k pdf_k); then the throughput roulette, or (albedo roulette)
  // uniform mode's separate albedo roulette ----
  float p = pk;
  float uR = sample1(rngMode, pixel, sampleIndex, rngDimension(bounce, RNG_DIM_ROULETTE), seed);
  if (roulette == ROULETTE_ALBEDO && mode == COMPONENTS_UNIFORM) {
    float q = combinedUniformContinuation(a);
    if (!(q > 0.0f) || uR >= q) return;
    p *= q;
  }
  beta *= weight * (wk / p);
  if (roulette != ROULETTE_ALBEDO) {
    if (transmitted) etaScale *= etaK;
    if (!throughputRoulette(bounce, beta, etaScale, uR)) return;
  }

  // MIS density of the sampled direction: sum over the non-delta components (0 after a delta lobe).
  float misPdf = 0.0f;
  if (!delta) {
    if (COMPONENT_COUNT > 0u) misPdf += componentMisPdf(MODEL_0, C0, c.x, wo, wiLocal);
    if (COMPONENT_COUNT > 1u) misPdf += componentMisPdf(MODEL_1, C1, c.y, wo, wiLocal);
    if (COMPONENT_COUNT > 2u) misPdf += componentMisPdf(MODEL_2, C2, c.z, wo, wiLocal);
    if (COMPONENT_COUNT > 3u) misPdf += componentMisPdf(MODEL_3, C3, c.w, wo, wiLocal);
  }

  // Combined materials are not guided yet: their vertices only train the guide.
  if (GUIDING) guideRecordSample(path, bounce, wi, delta ? -1.0f : luminance(beta) * misPdf);
  g.pathOrigin.v[path] = vec4(xo, 0.0f);
  g.pathDirection.v[path] = vec4(wi, misPdf);
  g.pathThroughput.v[path] = vec4(beta, etaScale);
  queuePush(((bounce + 1u) & 1u), path);
#endif
}
