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
// Binned sampling (bsdf_sampling.h, "Binned sampling"): a gltf_pbr material or component whose
// textures vary its parameters (MATERIAL_BINNED, GpuComponent.info.z) under the quadtree strategy,
// in a scene that has such materials (constant 12, HAS_BINS: set by the integrator when
// Globals.roughnessBins.count > 0; without it, and in modules without the scene features or the
// quadtree, the code is not there).
#define NUSSELT_BINNED (NUSSELT_SCENE_FEATURES && NUSSELT_WITH_QUADTREE)
#if NUSSELT_BINNED
layout(constant_id = 12) const bool HAS_BINS = false;
#endif

#if SHADE_COMBINED
// 1..MAX_COMPONENTS: the number of components of the combined material.
layout(constant_id = 2) const uint COMPONENT_COUNT = 1u;
layout(constant_id = 3) const uint MODEL_0 = 0u;
layout(constant_id = 4) const uint MODEL_1 = 0u;
layout(constant_id = 5) const uint MODEL_2 = 0u;
layout(constant_id = 6) const uint MODEL_3 = 0u;
// A module built for materials of at most NUSSELT_COMBINED_SLOTS components (CMakeLists.txt:
// shade_combined_c2_*) has no code for the slots above: lavapipe inlines every slot's calls (each
// with every model) before it folds COMPONENT_COUNT, so the slots a material does not use cost
// pipeline-creation time all the same (and glslang keeps a call under a constant-false condition:
// only the preprocessor removes it).
#ifndef NUSSELT_COMBINED_SLOTS
#define NUSSELT_COMBINED_SLOTS 4
#endif
#if NUSSELT_COMBINED_SLOTS != 2 && NUSSELT_COMBINED_SLOTS != 4
#error "NUSSELT_COMBINED_SLOTS: 2 or 4 (MAX_COMPONENTS)"
#endif

// ---- Combined materials: per-component terms (model = a specialization constant) ----
// w_k f_k(wi, wo); 0 for delta components (never evaluated).
vec3 componentEval(uint model, GpuComponent C, vec3 wi, vec3 wo) {
  return modelIsDelta(model) ? vec3(0.0f) : C.data.x * brdfEval(model, C.params, wi, wo);
}
// A gltf_pbr component whose textures vary its parameters samples the roughness bins
// (GpuComponent.info.z = 1, set by the renderer only where HAS_BINS is).
bool componentBinned(uint model, GpuComponent C) {
#if NUSSELT_BINNED
  return HAS_BINS && model == MODEL_GLTF_PBR && C.info.z != 0u;
#else
  return false;
#endif
}

// pdf_k(wi): the component's sampler's density (bsdfPdf, or the binned mixture's).
float componentPdf(uint model, GpuComponent C, vec3 wo, vec3 wi) {
#if NUSSELT_BINNED
  if (componentBinned(model, C)) return binnedPdf(g.roughnessBins, C.params, wo, wi);
#endif
  return bsdfPdf(SAMPLER, model, C.info.y, C.params, wo, wi);
}

// The component's sample (bsdfSample, or the binned mixture's).
bool componentSample(uint model, GpuComponent C, vec3 wo, bool inside, vec2 u, out vec3 wi, out vec3 weight,
                     out float pdf, out float q) {
#if NUSSELT_BINNED
  if (componentBinned(model, C)) return binnedBsdfSample(g.roughnessBins, C.params, wo, u, wi, weight, pdf, q);
#endif
  return bsdfSample(SAMPLER, model, C.info.y, C.params, wo, inside, u, wi, weight, pdf, q);
}

// c_k pdf_k(wi): the component's share of the MIS density (0 for delta components).
float componentMisPdf(uint model, GpuComponent C, float c, vec3 wo, vec3 wi) {
  return c > 0.0f ? c * componentPdf(model, C, wo, wi) : 0.0f;
}
#endif

// ---- The material's parameters at the hit (textures; docs/scenes.md, "Textures") ----
// texturedParams: a model's parameters (its factors on entry) under the base-colour texture's RGB
// `base` and the metallic-roughness texture's B, G (`mr`; 1 where the material has none): gltf_pbr's
// baseColor x base, metallic x mr.x, roughness x mr.y; a transmitting model's tint x base (glTF's
// tinted transmission); other models unchanged. Used for the material itself and for each
// component of a combined one.
void texturedParams(uint model, vec3 base, vec2 mr, inout BrdfParams params) {
  if (model == MODEL_GLTF_PBR) {
    for (uint k = 0u; k < 3u; ++k) params.v[(GLTF_PBR_BASE_COLOR + k) / 4u][(GLTF_PBR_BASE_COLOR + k) % 4u] *= base[k];
    params.v[GLTF_PBR_METALLIC / 4u][GLTF_PBR_METALLIC % 4u] *= mr.x;
    params.v[GLTF_PBR_ROUGHNESS / 4u][GLTF_PBR_ROUGHNESS % 4u] *= mr.y;
  }
  uint tint = modelTintParam(model);
  if (tint != INVALID_INDEX)
    for (uint k = 0u; k < 3u; ++k) params.v[(tint + k) / 4u][(tint + k) % 4u] *= base[k];
}

#if NUSSELT_SCENE_FEATURES
// The base-colour texture's RGB (sRGB decoded) and the metallic-roughness texture's (B, G) at the
// hit, 1 where the material has none (texture_table.cpp applies them to gltf_pbr and the
// transmitting models only: MaterialTextureUse).
void materialTexels(uint material, uint tri, float b1, float b2, out vec3 base, out vec2 mr) {
  GpuMaterialTextures T = g.materialTextures.v[material];
  GpuTriTexcoords uv = g.texcoords.v[tri];
  base = vec3(1.0f);
  mr = vec2(1.0f);
  if (T.maps.x != INVALID_INDEX) base = textureAtHit(texelBuffer(), g.textures.v[T.maps.x], uv, b1, b2).xyz;
  if (T.maps.y != INVALID_INDEX) mr = textureAtHit(texelBuffer(), g.textures.v[T.maps.y], uv, b1, b2).zy;
}

// evalParams: params (the model's factors on entry) and emission at the hit; any model's emission
// x emissiveTexture.rgb (sRGB decoded); model INVALID_INDEX (a combined material, whose components
// shadeMaterial textures): the emission only.
void evalParams(uint model, uint material, uint tri, float b1, float b2, inout BrdfParams params,
                inout vec3 emission) {
  GpuMaterialTextures T = g.materialTextures.v[material];
  if (T.maps.z != INVALID_INDEX) emission *= textureAtHit(texelBuffer(), g.textures.v[T.maps.z], g.texcoords.v[tri], b1, b2).xyz;
  if (model == INVALID_INDEX || (T.maps.x == INVALID_INDEX && T.maps.y == INVALID_INDEX)) return;
  vec3 base;
  vec2 mr;
  materialTexels(material, tri, b1, b2, base, mr);
  texturedParams(model, base, mr, params);
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

// ---- transmissionTexture: its R at the hit, or -1 when the material has none ----
float transmissionAt(uint material, uint tri, float b1, float b2) {
  uint tex = g.materialTextures.v[material].transmission.x;
  return tex == INVALID_INDEX ? -1.0f : sceneTexture(tex, tri, b1, b2).x;
}
#else
// A module without textures (NUSSELT_SCENE_FEATURES 0, stage_common.glsl): empty stand-ins.
void evalParams(uint model, uint material, uint tri, float b1, float b2, inout BrdfParams params,
                inout vec3 emission) {}
void materialTexels(uint material, uint tri, float b1, float b2, out vec3 base, out vec2 mr) {
  base = vec3(1.0f);
  mr = vec2(1.0f);
}
vec3 normalMapped(uint material, uint tri, float b1, float b2, vec3 ns, vec3 ngFront) { return ns; }
float transmissionAt(uint material, uint tri, float b1, float b2) { return -1.0f; }
#endif


// Where a ray hit: the material, the triangle and the barycentrics (texture lookups).
struct ShadeHit {
  uint material;
  uint tri;
  float b1, b2;
};

// One step of the walk as the material's sampler drew it: the local direction, the factor the
// throughput is multiplied by (weight, divided by the choice and albedo-roulette probabilities),
// the density for MIS at the next hit and for the guide's record, the eta scale of a transmission,
// whether the sample was a delta lobe's, and for the guide's training record the sample's
// (guide density, BRDF-sampler density, alpha) (guiding_layout.h, record c; x = -1: the vertex
// does not sample the guide's mixture).
struct PathStep {
  vec3 wiLocal;
  vec3 factor;
  float pdf;
  float etaScale;
  bool delta;
  vec3 selection;
};

// The guide's side of a sample at a vertex of region gv (guiding.h, guideDescend), for both kinds of
// material: guided, the direction drawn from the guide, into wiLocal (false, the path ends: the
// region has no mass there, or the direction is below the surface, where f cos = 0); otherwise the
// guide's density at wiLocal, the material's own sample. pdfG: the guide's density per steradian.
bool guideSide(GuideVertex gv, bool guided, float uDescent, PathKey k, uint bounce, vec3 tt, vec3 bb, vec3 ns,
               inout vec3 wiLocal, out float pdfG) {
  vec3 w = guided ? vec3(0.0f) : toWorld(wiLocal, tt, bb, ns);
  pdfG = guideDescend(gv, guided, uDescent, k, bounce, w);
  if (!guided) return true;
  if (!(pdfG > 0.0f)) return false;
  wiLocal = toLocal(w, tt, bb, ns);
  return wiLocal.z > 0.0f;
}

// ---- The material at a hit: one interface, two implementations ----
// ShadeMaterial      what the material needs at this hit (set up once by shadeMaterial)
// shadeLightSamples  whether next-event estimation applies (not for delta materials)
// shadeTransmits     whether f is not zero below the surface (light samples on both sides)
// shadeEval          f(wi, wo) (rgb) for a light sample
// shadeMisPdf        the density MIS weighs a light sample in direction wi against: shadeSample's
//                    (at a guided vertex, its BRDF sampler's)
// shadeSample        the next direction, its factor and density (PathStep); false ends the walk
// nextEvent and continuePath below are written once over them.
#if !SHADE_COMBINED
// ---- A single-model material (MODEL_ID); guided where the guide has learned (guiding.h) ----
struct ShadeMaterial {
  GpuMaterial M;
  GuideVertex gv;  // the guide's region (path guiding): never for delta or transmitting models
#if NUSSELT_BINNED
  bool binned;     // MATERIAL_BINNED, with HAS_BINS and MODEL_ID gltf_pbr
#endif
};

// inside: the path arrived from the inside (the back of the front face). A transmitting model
// (modelTransmits: rough_dielectric) is then shaded in the frame turned over, with its parameters
// seen from the inside (transmissionInsideParams: eta -> 1 / eta) and their sampler tables
// (GpuMaterial.components.z), as the smooth dielectric takes 1 / eta there (dielectric.h).
// The guide is off for transmitting models (alpha = 0): its mixture covers the upper hemisphere only.
// x, ng: the hit point and its geometric normal on the path's side (the guide's region, guideVertex).
// hit: unused (evalParams textured M's parameters before).
ShadeMaterial shadeMaterial(GpuMaterial M, vec3 x, vec3 ng, vec3 wo, uint roulette, ShadeHit hit, bool inside) {
  ShadeMaterial m;
  m.M = M;
  if (modelTransmits(MODEL_ID) && inside) {
    m.M.params = transmissionInsideParams(MODEL_ID, M.params);
    m.M.info.z = M.components.z;
  }
  m.gv = GuideVertex(0u, 0.0f);
  if (GUIDING && !modelIsDelta(MODEL_ID) && !modelTransmits(MODEL_ID)) m.gv = guideVertex(x, ng);
#if NUSSELT_BINNED
  m.binned = HAS_BINS && MODEL_ID == MODEL_GLTF_PBR && (M.info.y & MATERIAL_BINNED) != 0u;
#endif
  return m;
}

// The BSDF sampler's density of wi (bsdfPdf, or the binned mixture's).
float shadeBsdfPdf(ShadeMaterial m, vec3 wo, vec3 wi) {
#if NUSSELT_BINNED
  if (HAS_BINS && m.binned) return binnedPdf(g.roughnessBins, m.M.params, wo, wi);
#endif
  return bsdfPdf(SAMPLER, MODEL_ID, m.M.info.z, m.M.params, wo, wi);
}

// The BSDF sampler's sample (bsdfSample, or the binned mixture's).
bool shadeBsdfSample(ShadeMaterial m, vec3 wo, bool inside, vec2 u, out vec3 wi, out vec3 weight, out float pdf,
                     out float q) {
#if NUSSELT_BINNED
  if (HAS_BINS && m.binned) return binnedBsdfSample(g.roughnessBins, m.M.params, wo, u, wi, weight, pdf, q);
#endif
  return bsdfSample(SAMPLER, MODEL_ID, m.M.info.z, m.M.params, wo, inside, u, wi, weight, pdf, q);
}

bool shadeLightSamples(ShadeMaterial m) { return !modelIsDelta(MODEL_ID); }

bool shadeTransmits(ShadeMaterial m) { return modelTransmits(MODEL_ID); }

vec3 shadeEval(ShadeMaterial m, vec3 wi, vec3 wo) { return brdfEval(MODEL_ID, m.M.params, wi, wo); }

// MIS against light sampling weighs the BRDF sampler's density, also at a guided vertex (not the
// mixture's: continuePath stores the same for an emitter hit, so the weights still sum to 1; NEE
// then needs no descent of the guide. docs/guiding.md, "Sampling").
float shadeMisPdf(ShadeMaterial m, vec3 wo, vec3 wi) {
  return shadeBsdfPdf(m, wo, wi);
}

// BSDF sampling, or the guide with probability alpha (one-sample MIS); uR: the roulette's number
// (the albedo roulette decides here, with the sample's continuation probability q).
bool shadeSample(ShadeMaterial m, PathKey k, uint bounce, uint roulette, vec3 wo, bool inside, vec3 tt, vec3 bb,
                 vec3 ns, float uR, out PathStep s) {
  s.wiLocal = vec3(0.0f, 0.0f, 1.0f);
  s.factor = vec3(0.0f);
  s.pdf = 0.0f;
  s.etaScale = 1.0f;
  s.delta = modelIsDelta(MODEL_ID);
  s.selection = vec3(-1.0f, 0.0f, 0.0f);
  uint dimB = rngDimension(bounce, RNG_DIM_BSDF);
  vec2 uB = pathSample2(k, dimB);
  vec3 wiLocal;
  vec3 weight;
  float pdf;
  float q;
  vec2 uG = vec2(1.0f);
  if (GUIDING && m.gv.alpha > 0.0f) uG = pathSample2(k, rngDimension(bounce, RNG_DIM_GUIDE));
  bool guided = GUIDING && uG.x < m.gv.alpha;
  if (!guided && !shadeBsdfSample(m, wo, inside, uB, wiLocal, weight, pdf, q)) return false;
  // Training records need both densities wherever the guide could be chosen, also where alpha is
  // 0 (the trainer estimates from them what another alpha would do: GuideTree::observeSelection).
  bool record = GUIDING && !modelIsDelta(MODEL_ID) && guideRecording();
  if (GUIDING && (m.gv.alpha > 0.0f || record)) {
    // One descent of the guide's tree for every lane: a guided lane draws its direction, the
    // others look up the guide's density at their BSDF sample (guiding.h, guideDescend).
    float pdfG;
    if (!guideSide(m.gv, guided, uG.y, k, bounce, tt, bb, ns, wiLocal, pdfG)) return false;
    if (guided) {
      weight = brdfEval(MODEL_ID, m.M.params, wiLocal, wo) * wiLocal.z;  // f cos, over the mixture below
      pdf = 1.0f;
      q = 1.0f;
    }
    float pdfB = guided ? shadeBsdfPdf(m, wo, wiLocal) : pdf;
    s.selection = vec3(pdfG, pdfB, m.gv.alpha);
    if (m.gv.alpha > 0.0f) {
      // The mixture's density, for the weight f cos / pdf and for MIS at the next hit.
      float pdfMix = guideMixturePdf(m.gv.alpha, pdfG, pdfB);
      if (!(pdfMix > 0.0f)) return false;
      weight *= pdf / pdfMix;
      if (guided) q = min(1.0f, luminance(weight));
      pdf = pdfMix;
    }
  }
  // The albedo roulette: with the continuation probability of the sample (the source's).
  if (roulette == ROULETTE_ALBEDO) {
    if (!(q > 0.0f) || uR >= q) return false;
    s.factor = weight / q;
  } else {
    s.factor = weight;
  }
  s.wiLocal = wiLocal;
  s.pdf = pdf;
  s.etaScale = transmissionEtaScale(MODEL_ID, m.M.params, inside);
  return true;
}

#else
// ---- A combined material: sum_k w_k f_k (shaders/shared/combined.h, docs/models.md) ----
struct ShadeMaterial {
  GpuComponent C0, C1, C2, C3;
  vec4 a;            // choice weights a_k = w_k A_k(wo), from wo only
  vec4 c;            // MIS probabilities (0 for delta components, which have no MIS density)
  uint mode;         // the choice mode (combinedChoiceMode)
  bool lightSamples; // no delta flag on the material
  // Path guiding: whether the guide's mixture applies (a non-delta component, none transmitting
  // with a density, the throughput roulette: the albedo choice's own roulette stays unguided),
  // and the vertex's region (alpha 0 elsewhere).
  bool guidable;
  GuideVertex gv;
};

// A transmitting non-delta component (rough_dielectric) seen from the inside: its parameters from
// there (transmissionInsideParams) and their tables (GpuComponent.info.w), as a single-model
// material takes them (delta components handle the side in their own sampling).
void insideComponent(uint model, inout GpuComponent C) {
  if (!modelTransmits(model) || modelIsDelta(model)) return;
  C.params = transmissionInsideParams(model, C.params);
  C.info.y = C.info.w;
}

// Whether component `model` scatters below the surface with a density (light samples there).
bool componentTransmits(uint model) { return modelTransmits(model) && !modelIsDelta(model); }

bool shadeTransmits(ShadeMaterial m);

// hit: a textured material's components take the textures at the hit (texturedParams: gltf_pbr's
// base colour and metallic-roughness, the transmitting models' tint), and the transmission
// texture's R (transmissionAt) sets the weights below. inside: the path arrived from the inside
// (insideComponent).
ShadeMaterial shadeMaterial(GpuMaterial M, vec3 x, vec3 ng, vec3 wo, uint roulette, ShadeHit hit, bool inside) {
  ShadeMaterial m;
  m.a = vec4(0.0f);
  uint first = M.components.x;
  m.mode = combinedChoiceMode(g.componentChoice, roulette);
  if (COMPONENT_COUNT > 0u) m.C0 = g.components.v[first];
  if (COMPONENT_COUNT > 1u) m.C1 = g.components.v[first + 1u];
#if NUSSELT_COMBINED_SLOTS > 2
  if (COMPONENT_COUNT > 2u) m.C2 = g.components.v[first + 2u];
#endif
#if NUSSELT_COMBINED_SLOTS > 3
  if (COMPONENT_COUNT > 3u) m.C3 = g.components.v[first + 3u];
#endif
  float transmissionR = -1.0f;
  if (HAS_TEXTURES && (M.info.y & MATERIAL_TEXTURED) != 0u) {
    transmissionR = transmissionAt(hit.material, hit.tri, hit.b1, hit.b2);
    vec3 base;
    vec2 mr;
    materialTexels(hit.material, hit.tri, hit.b1, hit.b2, base, mr);
    if (COMPONENT_COUNT > 0u) texturedParams(MODEL_0, base, mr, m.C0.params);
    if (COMPONENT_COUNT > 1u) texturedParams(MODEL_1, base, mr, m.C1.params);
#if NUSSELT_COMBINED_SLOTS > 2
    if (COMPONENT_COUNT > 2u) texturedParams(MODEL_2, base, mr, m.C2.params);
#endif
#if NUSSELT_COMBINED_SLOTS > 3
    if (COMPONENT_COUNT > 3u) texturedParams(MODEL_3, base, mr, m.C3.params);
#endif
  }
  if (inside) {
    if (COMPONENT_COUNT > 0u) insideComponent(MODEL_0, m.C0);
    if (COMPONENT_COUNT > 1u) insideComponent(MODEL_1, m.C1);
#if NUSSELT_COMBINED_SLOTS > 2
    if (COMPONENT_COUNT > 2u) insideComponent(MODEL_2, m.C2);
#endif
#if NUSSELT_COMBINED_SLOTS > 3
    if (COMPONENT_COUNT > 3u) insideComponent(MODEL_3, m.C3);
#endif
  }
  // The transmission combination {gltf_pbr, 1 - w; glass, w} under a transmission texture: the
  // glass takes w R at this hit, gltf_pbr the rest (Material::transmissionTextured).
  if (COMPONENT_COUNT == 2u && transmissionR >= 0.0f) {
    float wt = m.C1.data.x * transmissionR;
    m.C1.data.x = wt;
    m.C0.data.x = 1.0f - wt;
  }
  if (COMPONENT_COUNT > 0u) m.a.x = componentChoiceWeight(m.mode, SAMPLER, MODEL_0, m.C0, wo);
  if (COMPONENT_COUNT > 1u) m.a.y = componentChoiceWeight(m.mode, SAMPLER, MODEL_1, m.C1, wo);
#if NUSSELT_COMBINED_SLOTS > 2
  if (COMPONENT_COUNT > 2u) m.a.z = componentChoiceWeight(m.mode, SAMPLER, MODEL_2, m.C2, wo);
#endif
#if NUSSELT_COMBINED_SLOTS > 3
  if (COMPONENT_COUNT > 3u) m.a.w = componentChoiceWeight(m.mode, SAMPLER, MODEL_3, m.C3, wo);
#endif
  vec4 P = combinedChoiceProbabilities(m.mode, COMPONENT_COUNT, m.a);
  m.c = combinedMisProbabilities(P);
  // Delta components take no light samples and have no MIS density: their c is dropped.
  if (modelIsDelta(MODEL_0)) m.c.x = 0.0f;
  if (modelIsDelta(MODEL_1)) m.c.y = 0.0f;
#if NUSSELT_COMBINED_SLOTS > 2
  if (modelIsDelta(MODEL_2)) m.c.z = 0.0f;
#endif
#if NUSSELT_COMBINED_SLOTS > 3
  if (modelIsDelta(MODEL_3)) m.c.w = 0.0f;
#endif
  m.lightSamples = (M.info.y & MATERIAL_DELTA) == 0u;
  m.guidable = GUIDING && m.lightSamples && roulette != ROULETTE_ALBEDO && !shadeTransmits(m);
  m.gv = GuideVertex(0u, 0.0f);
  if (m.guidable) m.gv = guideVertex(x, ng);
  return m;
}

bool shadeLightSamples(ShadeMaterial m) { return m.lightSamples; }

// A transmitting non-delta component takes light samples below the surface (its f is not zero
// there; the others' f and densities are 0 below).
bool shadeTransmits(ShadeMaterial m) {
#if NUSSELT_COMBINED_SLOTS > 2
  return (COMPONENT_COUNT > 0u && componentTransmits(MODEL_0)) || (COMPONENT_COUNT > 1u && componentTransmits(MODEL_1)) ||
         (COMPONENT_COUNT > 2u && componentTransmits(MODEL_2)) || (COMPONENT_COUNT > 3u && componentTransmits(MODEL_3));
#else
  return (COMPONENT_COUNT > 0u && componentTransmits(MODEL_0)) || (COMPONENT_COUNT > 1u && componentTransmits(MODEL_1));
#endif
}

// The sum of the non-delta components.
vec3 shadeEval(ShadeMaterial m, vec3 wi, vec3 wo) {
  vec3 f = vec3(0.0f);
  if (COMPONENT_COUNT > 0u) f += componentEval(MODEL_0, m.C0, wi, wo);
  if (COMPONENT_COUNT > 1u) f += componentEval(MODEL_1, m.C1, wi, wo);
#if NUSSELT_COMBINED_SLOTS > 2
  if (COMPONENT_COUNT > 2u) f += componentEval(MODEL_2, m.C2, wi, wo);
#endif
#if NUSSELT_COMBINED_SLOTS > 3
  if (COMPONENT_COUNT > 3u) f += componentEval(MODEL_3, m.C3, wi, wo);
#endif
  return f;
}

float shadeMisPdf(ShadeMaterial m, vec3 wo, vec3 wi) {
  float pdf = 0.0f;
  if (COMPONENT_COUNT > 0u) pdf += componentMisPdf(MODEL_0, m.C0, m.c.x, wo, wi);
  if (COMPONENT_COUNT > 1u) pdf += componentMisPdf(MODEL_1, m.C1, m.c.y, wo, wi);
#if NUSSELT_COMBINED_SLOTS > 2
  if (COMPONENT_COUNT > 2u) pdf += componentMisPdf(MODEL_2, m.C2, m.c.z, wo, wi);
#endif
#if NUSSELT_COMBINED_SLOTS > 3
  if (COMPONENT_COUNT > 3u) pdf += componentMisPdf(MODEL_3, m.C3, m.c.w, wo, wi);
#endif
  return pdf;
}

// The component choice (albedo mode under the albedo roulette: includes the roulette), then the
// chosen component's sample; factor w_k f_k cos / (P_k pdf_k), with uniform mode's separate albedo
// roulette (uR) under the albedo roulette.
// Guided (m.guidable, in a guided render): the choice as unguided; a delta component chosen samples
// as unguided (the delta lobes keep their rate), a non-delta one is replaced by the guide with
// probability alpha (one-sample MIS within the non-delta part, of probability P_nd = sum of the
// non-delta P_k). A non-delta direction's density is then alpha P_nd p_guide + (1 - alpha) p_bsdf,
// p_bsdf = sum_k P_k pdf_k over the non-delta components (shadeMisPdf), and its factor the
// material's whole f cos over it. docs/guiding.md, "Sampling".
bool shadeSample(ShadeMaterial m, PathKey k, uint bounce, uint roulette, vec3 wo, bool inside, vec3 tt, vec3 bb,
                 vec3 ns, float uR, out PathStep s) {
  s.wiLocal = vec3(0.0f, 0.0f, 1.0f);
  s.factor = vec3(0.0f);
  s.pdf = 0.0f;
  s.etaScale = 1.0f;
  s.delta = false;
  s.selection = vec3(-1.0f, 0.0f, 0.0f);
  float uC = pathSample1(k, rngDimension(bounce, RNG_DIM_COMPONENT));
  uint j;
  float pk;
  if (!combinedPick(m.mode, COMPONENT_COUNT, m.a, uC, j, pk) || !(pk > 0.0f)) return false;
  vec2 uG = vec2(1.0f);
  if (GUIDING && m.gv.alpha > 0.0f) uG = pathSample2(k, rngDimension(bounce, RNG_DIM_GUIDE));
  uint modelJ = j == 0u ? MODEL_0 : (j == 1u ? MODEL_1 : (j == 2u ? MODEL_2 : MODEL_3));
  bool guided = GUIDING && uG.x < m.gv.alpha && !modelIsDelta(modelJ);
  if (guided) j = MAX_COMPONENTS;  // no component samples

  uint dimB = rngDimension(bounce, RNG_DIM_BSDF);
  vec2 uB = pathSample2(k, dimB);
  vec3 wiLocal = vec3(0.0f, 0.0f, 1.0f);
  vec3 weight = vec3(0.0f);
  float pdf = 0.0f;
  float qk;  // the component's own continuation: not used (the choice above is the roulette)
  bool ok = false;
  bool delta = false;
  float wk = 0.0f;
  float etaK = 1.0f;  // transmissionEtaScale of the chosen component
  if (COMPONENT_COUNT > 0u && j == 0u) {
    ok = componentSample(MODEL_0, m.C0, wo, inside, uB, wiLocal, weight, pdf, qk);
    delta = modelIsDelta(MODEL_0);
    wk = m.C0.data.x;
    etaK = transmissionEtaScale(MODEL_0, m.C0.params, inside);
  }
  if (COMPONENT_COUNT > 1u && j == 1u) {
    ok = componentSample(MODEL_1, m.C1, wo, inside, uB, wiLocal, weight, pdf, qk);
    delta = modelIsDelta(MODEL_1);
    wk = m.C1.data.x;
    etaK = transmissionEtaScale(MODEL_1, m.C1.params, inside);
  }
#if NUSSELT_COMBINED_SLOTS > 2
  if (COMPONENT_COUNT > 2u && j == 2u) {
    ok = componentSample(MODEL_2, m.C2, wo, inside, uB, wiLocal, weight, pdf, qk);
    delta = modelIsDelta(MODEL_2);
    wk = m.C2.data.x;
    etaK = transmissionEtaScale(MODEL_2, m.C2.params, inside);
  }
#endif
#if NUSSELT_COMBINED_SLOTS > 3
  if (COMPONENT_COUNT > 3u && j == 3u) {
    ok = componentSample(MODEL_3, m.C3, wo, inside, uB, wiLocal, weight, pdf, qk);
    delta = modelIsDelta(MODEL_3);
    wk = m.C3.data.x;
    etaK = transmissionEtaScale(MODEL_3, m.C3.params, inside);
  }
#endif
  if (!guided && (!ok || !(wk > 0.0f))) return false;

  // Training records need both densities wherever the guide could be chosen, also where alpha is
  // 0 (as single-model materials: GuideTree::observeSelection); with them, the factor of a
  // non-delta sample is the mixture's (at alpha 0: f cos / p_bsdf, the estimate the densities
  // describe).
  bool record = GUIDING && m.guidable && guideRecording();
  if (GUIDING && !delta && (m.gv.alpha > 0.0f || record)) {
    float pdfG;
    if (!guideSide(m.gv, guided, uG.y, k, bounce, tt, bb, ns, wiLocal, pdfG)) return false;
    // The guide's share of the density: P_nd p_guide (recorded as the guide's density, so that
    // the trainer's alpha p_guide + (1 - alpha) p_bsdf is this sample's density).
    pdfG *= m.c.x + m.c.y + m.c.z + m.c.w;
    if (guided) etaK = 1.0f;
    float pdfB = shadeMisPdf(m, wo, wiLocal);
    float pdfMix = guideMixturePdf(m.gv.alpha, pdfG, pdfB);
    if (!(pdfMix > 0.0f)) return false;
    s.wiLocal = wiLocal;
    s.factor = shadeEval(m, wiLocal, wo) * (wiLocal.z / pdfMix);
    s.pdf = pdfMix;
    s.etaScale = etaK;
    s.selection = vec3(pdfG, pdfB, m.gv.alpha);
    return true;
  }

  float p = pk;
  if (roulette == ROULETTE_ALBEDO && m.mode == COMPONENTS_UNIFORM) {
    float q = combinedUniformContinuation(m.a);
    if (!(q > 0.0f) || uR >= q) return false;
    p *= q;
  }
  s.wiLocal = wiLocal;
  s.factor = weight * (wk / p);
  // MIS density of the sampled direction: sum over the non-delta components (0 after a delta lobe).
  s.pdf = delta ? 0.0f : shadeMisPdf(m, wo, wiLocal);
  s.etaScale = etaK;
  s.delta = delta;
  return true;
}
#endif

// ---- Next-event estimation: a light sample, its shadow ray queued with the MIS-weighted value ----
// Above the geometric surface (xo: x offset along ng); a transmitting material (shadeTransmits)
// also takes lights behind it: sampled from x itself, |cos|, the shadow ray offset to the light's
// side (offsetRay with -ng), and only where the shading frame puts the light on the same side
// (else light would pass through the surface on one normal and not the other).
void nextEvent(ShadeMaterial m, uint path, PathKey k, uint bounce, uint lighting, vec3 x, vec3 xo, vec3 ng, vec3 tt,
               vec3 bb, vec3 ns, vec3 wo, vec3 beta) {
  float uSel = pathSample1(k, rngDimension(bounce, RNG_DIM_LIGHT_SELECT));
  vec2 uPt = pathSample2(k, rngDimension(bounce, RNG_DIM_LIGHT_POINT));
  LightSample ls;
  bool transmits = shadeTransmits(m);
  if (sampleLight(transmits ? x : xo, uSel, uPt, ls) &&
      (dot(ls.wi, ng) > 0.0f || (transmits && dot(ls.wi, ng) < 0.0f))) {
    bool behind = transmits && dot(ls.wi, ng) < 0.0f;
    vec3 wiL = toLocal(ls.wi, tt, bb, ns);
    if (transmits && (wiL.z < 0.0f) != behind) return;
    vec3 f = shadeEval(m, wiL, wo);
    float cosS = transmits ? abs(wiL.z) : max(wiL.z, 0.0f);
    vec3 c = beta * f * cosS * ls.value;
    if (ls.pdf > 0.0f && lighting == LIGHTING_MIS) c *= powerHeuristic(ls.pdf, shadeMisPdf(m, wo, wiL));
    if (max(c.x, max(c.y, c.z)) > 0.0f) {
      // Stop short of the light so that the emitter itself never occludes.
      float tmax = ls.dist < 1.0e38f ? ls.dist * (1.0f - 1e-4f) : ls.dist;
      storeVec4(g.shadowOrigin, path, vec4(behind ? offsetRay(x, -ng) : xo, tmax));
      storeVec4(g.shadowDirection, path, vec4(ls.wi, 0.0f));
      storeVec4(g.shadowRadiance, path, vec4(c, 0.0f));
      queuePush(QUEUE_SHADOW0 + (bounce & 1u), path);
    }
  }
}

// ---- Path continuation: the sampled step becomes the next ray, or the walk ends ----
// Reflection must stay above the geometric surface (else light leaks through it); refraction
// (delta models and transmitting ones: modelTransmits) must cross it, and leaves from the other
// side (offsetRay with -ng). Then the throughput
// roulette (the default; the albedo roulette decided in shadeSample): survivors are divided by
// the probability.
void continuePath(PathStep s, uint path, uint bounce, uint roulette, vec3 x, vec3 xo, vec3 ng, vec3 tt, vec3 bb,
                  vec3 ns, vec3 beta, float etaScale, float uR, float causticState) {
  vec3 wi = toWorld(s.wiLocal, tt, bb, ns);
  bool transmitted = s.wiLocal.z < 0.0f;
  if (transmitted != (dot(wi, ng) < 0.0f)) return;
  if (transmitted) xo = offsetRay(x, -ng);
  beta *= s.factor;
  if (roulette != ROULETTE_ALBEDO) {
    if (transmitted) etaScale *= s.etaScale;
    // A guided sample's weight is f cos / p_mix, smaller than BSDF sampling's f cos / p_bsdf where
    // the guide expects more light: the throughput roulette would end most of the samples the
    // guide sends towards bright light. So the roulette's scale gains p_mix / p_bsdf where that
    // is above 1 (never below: the roulette never ends more than it would unguided; with the
    // ratio itself its factors below 1 compound over bounces into rare heavy survivors).
    // docs/guiding.md, "Russian roulette".
    if (GUIDING && s.selection.z > 0.0f && s.selection.y > 0.0f) etaScale *= max(1.0f, s.pdf / s.selection.y);
    if (!throughputRoulette(bounce, beta, etaScale, uR)) return;
  }
  if (GUIDING && !guidePhotons()) {
    // The splat is the luminance that arrives through the sample over this value
    // (guiding_layout.h, record b): L_i / p with the new throughput x p (the roulette's 1 / q
    // cancels), or L_i f cos / p (f cos / p = the sample's factor) with the new throughput over
    // the factor.
    float fl = luminance(s.factor);
    float value = guideLearnsProduct() ? (fl > 0.0f ? luminance(beta) / fl : -1.0f) : luminance(beta) * s.pdf;
    guideRecordSample(path, bounce, ng, wi, s.delta ? -1.0f : value, s.selection);
  }
  // The density an emitter or environment hit weighs against light sampling (shadeMisPdf): at a
  // vertex that sampled the guide's mixture, the BRDF sampler's (never 0 there, which would read
  // as a delta bounce: a direction the BRDF sampler cannot draw gets a weight that rounds to 0).
  float misPdf = GUIDING && s.selection.z > 0.0f ? max(s.selection.y, 1e-30f) : s.pdf;
  storeVec4(g.pathOrigin, path, vec4(xo, causticState));
  storeVec4(g.pathDirection, path, vec4(wi, misPdf));
  storeVec4(g.pathThroughput, path, vec4(beta, etaScale));
  queuePush(((bounce + 1u) & 1u), path);
}

void main() {
  uint idx = gl_GlobalInvocationID.x;
  uint queue = QUEUE_SHADE_BASE + pc.modelSlot;
  if (idx >= queueCount(queue)) return;
  uint path = queueItem(queue, idx);
  uint bounce = pc.bounce;
  // With primary samples, the bounces this path has shaded: a Metropolis chain moves the draws its
  // path read (mlt.h, mltExtent).
  if (PRIMARY_SAMPLES) g.pathInfo.v[path].z = bounce + 1u;
  PathKey key = pathKey(path);  // every draw: pathSample1/2(key, dimension) (stage_common.glsl)
  uint lighting = g.lighting;
  uint roulette = g.roulette;

  // ---- Hit geometry ----
  vec4 hit = loadVec4(g.pathHit, path);
  uint tri = floatBitsToUint(hit.w);
  vec4 rayD = loadVec4(g.pathDirection, path);
  vec3 dir = rayD.xyz;
  float prevPdf = rayD.w;
  GpuTriangle T = loadTriangle(g.triangles, tri);
  GpuTriShading S = loadTriShading(g.shading, tri);
  vec3 x = T.v0.xyz + hit.y * T.e1.xyz + hit.z * T.e2.xyz;
  vec3 ngFront = normalize(cross(T.e1.xyz, T.e2.xyz));
  vec3 ns = normalize((1.0f - hit.y - hit.z) * S.n0.xyz + hit.y * S.n1.xyz + hit.z * S.n2.xyz);
  GpuMaterial M = loadMaterial(g.materials, S.info.x);
  // evalParams: the parameters and emission at this point (differ from M's only where textured).
  vec3 Le = M.emission.xyz;
#if SHADE_COMBINED
  if (HAS_TEXTURES && (M.info.y & MATERIAL_TEXTURED) != 0u) evalParams(INVALID_INDEX, S.info.x, tri, hit.y, hit.z, M.params, Le);
#else
  if (HAS_TEXTURES && (M.info.y & MATERIAL_TEXTURED) != 0u) evalParams(MODEL_ID, S.info.x, tri, hit.y, hit.z, M.params, Le);
#endif
  if (HAS_TEXTURES && (M.info.y & MATERIAL_TEXTURED) != 0u) ns = normalMapped(S.info.x, tri, hit.y, hit.z, ns, ngFront);
  vec4 throughput = loadVec4(g.pathThroughput, path);
  vec3 beta = throughput.xyz;
  float etaScale = throughput.w;
  vec3 L = vec3(0.0f);
  // The guide's photon pre-pass (guidePhotons, docs/guiding.md): this path is a photon whose
  // throughput is its power over the scale in its radiance's w (photon.comp).
  bool photon = GUIDING && guidePhotons();
  if (GUIDING && !photon) guideRecordArrival(path, bounce, x);  // training record (guiding.h)
  bool frontFace = dot(ngFront, dir) < 0.0f;
  vec3 ng = frontFace ? ngFront : -ngFront;  // the geometric normal on the side the ray came from

  // ---- Beer-Lambert: a ray that meets an absorbing material from the back came from inside ----
  // (shared/volume.h; docs/scenes.md, "Volumes"): the segment of length hit.x (dir is a unit
  // vector) is attenuated before anything at this vertex counts.
  if ((M.info.y & MATERIAL_ABSORBING) != 0u && !frontFace) beta *= volumeTransmittance(M.absorption.xyz, hit.x);
  // A photon's arrival after at least one bounce (indirect light; NEE keeps the direct) is a
  // training record: where, from where, the luminance of its power.
  if (photon && bounce >= 1u) {
    float power = luminance(beta) * g.pathRadiance.v[path].w;
    if (power > 0.0f && isFinite(power)) guideRecordPhoton(path, bounce, x, ng, -dir, power);
  }

  // Caustic light (RADIANCE_CAUSTIC, NONCAUSTIC; layout.h): the path's state in pathOrigin.w (0: no
  // non-delta bounce yet, 1: one, 2: its caustic light counted), and whether it arrived here by a
  // delta bounce (pdf 0).
  uint part = g.radiancePart;
  float causticState = part >= RADIANCE_CAUSTIC ? g.pathOrigin.v[path].w : 0.0f;
  bool caustic = causticState == 1.0f && bounce > 0u && prevPdf == 0.0f;
  bool emits = (M.info.y & MATERIAL_EMISSIVE) != 0u && frontFace && !photon;
  if (caustic && emits) causticState = 2.0f;
  float causticF = 0.0f;

  // ---- Emission: one-sided emitters radiate along their geometric normal ----
  if (emits) {
    float w = 1.0f;
    if (bounce > 0u && prevPdf > 0.0f) {  // reached by a BSDF sample that light sampling could also make
      if (lighting == LIGHTING_NEE_ONLY) {
        w = 0.0f;
      } else if (lighting == LIGHTING_MIS) {
        float lightPdf = triangleLightPdf(S.info.y, tri, hit.x, -dot(ngFront, dir));
        w = powerHeuristic(prevPdf, lightPdf);
      }
    }
    if (radiancePartKeeps(part, bounce, caustic)) L += beta * Le * w;
    // A Metropolis pass of the light outside the chains keeps, in its radiance's w, the luminance
    // of the caustic light it leaves to them: the chains' f of its vector (mlt.h, pass pools).
    else if (PRIMARY_SAMPLES && part == RADIANCE_NONCAUSTIC && caustic) causticF = luminance(max(beta * Le * w, vec3(0.0f)));
  }

  // ---- Local frame: surfaces are two-sided, shade the side the ray came from ----
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
  // Direct light only (RADIANCE_DIRECT): nothing after the second vertex counts, so the path ends
  // there; caustic light only, nothing after its caustic light.
  bool last = bounce >= g.maxDepth || (part == RADIANCE_DIRECT && bounce >= 1u) ||
              (part == RADIANCE_CAUSTIC && causticState == 2.0f);

  ShadeMaterial m = shadeMaterial(M, x, ng, wo, roulette, ShadeHit(S.info.x, tri, hit.y, hit.z), !frontFace);
  if (!last && !photon && lighting != LIGHTING_BSDF_ONLY && shadeLightSamples(m) && radiancePartKeeps(part, bounce + 1u, false))
    nextEvent(m, path, key, bounce, lighting, x, xo, ng, tt, bb, ns, wo, beta);

  if (L != vec3(0.0f) || (PRIMARY_SAMPLES && causticF != 0.0f)) {
    vec4 R = loadVec4(g.pathRadiance, path);
    storeVec4(g.pathRadiance, path, vec4(R.xyz + L, PRIMARY_SAMPLES && causticF != 0.0f ? causticF : R.w));
  }
  if (last) return;

  // ---- The next step of the random walk: the material's sample, then the roulette ----
  float uR = pathSample1(key, rngDimension(bounce, RNG_DIM_ROULETTE));
  PathStep s;
  if (!shadeSample(m, key, bounce, roulette, wo, !frontFace, tt, bb, ns, uR, s)) return;
  if (causticState == 0.0f && !s.delta && part >= RADIANCE_CAUSTIC) causticState = 1.0f;
  continuePath(s, path, bounce, roulette, x, xo, ng, tt, bb, ns, beta, etaScale, uR, causticState);
}
