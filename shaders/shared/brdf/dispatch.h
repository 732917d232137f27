// dispatch.h: model ids and the one switch that maps a model id to its shared definition.
// In a shade stage the model id is a specialization constant, so the switch folds to the one
// model that stage serves (lavapipe runs every reachable branch body: see README "Design").
#ifndef NUSSELT_BRDF_DISPATCH_H
#define NUSSELT_BRDF_DISPATCH_H
#include "../layout.h"
#include "lambert.h"
#include "phong_specular.h"
#include "phong.h"
#include "lewis.h"
#include "blinn.h"
#include "torrance_sparrow.h"
#include "ward.h"
#include "ashikhmin_shirley.h"
#include "lafortune.h"
#include "minnaert.h"
#include "oren_nayar.h"
#include "schlick.h"
#include "strauss.h"
#include "beard_maxwell.h"
#include "htsg.h"
#include "poulin_fournier.h"
#include "coupled.h"
#include "mirror.h"
#include "dielectric.h"
#include "gltf_pbr.h"
#include "merl.h"
SHARED_BEGIN

// Model ids: stable numbers, also written into cache keys and EXR headers.
#define MODEL_LAMBERT 0u
#define MODEL_PHONG_SPECULAR 1u
#define MODEL_PHONG 2u
#define MODEL_LEWIS 3u
#define MODEL_BLINN 4u
#define MODEL_TORRANCE_SPARROW 5u
#define MODEL_WARD 6u
#define MODEL_ASHIKHMIN_SHIRLEY 7u
#define MODEL_LAFORTUNE 8u
#define MODEL_MINNAERT 9u
#define MODEL_OREN_NAYAR 10u
#define MODEL_SCHLICK 11u
#define MODEL_STRAUSS 12u
#define MODEL_BEARD_MAXWELL 13u
#define MODEL_HTSG 14u
#define MODEL_POULIN_FOURNIER 15u
#define MODEL_COUPLED 16u
#define MODEL_MIRROR 17u
#define MODEL_DIELECTRIC 18u
#define MODEL_GLTF_PBR 19u
#define MODEL_MERL 20u  // measured (a table per material: docs/measured.md)
#define MODEL_COUNT 21u

// Delta models (mirror, dielectric) are never evaluated or light-sampled: sample them
// analytically (mirrorReflectance, dielectricReflectance / dielectricRefract).
SHARED_FN bool modelIsDelta(uint model) { return model == MODEL_MIRROR || model == MODEL_DIELECTRIC; }

// BRDF value f(wi, wo) [1/sr] in the local frame (normal +z); wi towards the light, wo towards
// the viewer. Zero for delta models and for directions below the surface.
SHARED_FN vec3 brdfEval(uint model, BrdfParams p, vec3 wi, vec3 wo) {
  switch (model) {
    case MODEL_LAMBERT: return lambertEval(p, wi, wo);
    case MODEL_PHONG_SPECULAR: return phongSpecularEval(p, wi, wo);
    case MODEL_PHONG: return phongEval(p, wi, wo);
    case MODEL_LEWIS: return lewisEval(p, wi, wo);
    case MODEL_BLINN: return blinnEval(p, wi, wo);
    case MODEL_TORRANCE_SPARROW: return torranceSparrowEval(p, wi, wo);
    case MODEL_WARD: return wardEval(p, wi, wo);
    case MODEL_ASHIKHMIN_SHIRLEY: return ashikhminShirleyEval(p, wi, wo);
    case MODEL_LAFORTUNE: return lafortuneEval(p, wi, wo);
    case MODEL_MINNAERT: return minnaertEval(p, wi, wo);
    case MODEL_OREN_NAYAR: return orenNayarEval(p, wi, wo);
    case MODEL_SCHLICK: return schlickEval(p, wi, wo);
    case MODEL_STRAUSS: return straussEval(p, wi, wo);
    case MODEL_BEARD_MAXWELL: return beardMaxwellEval(p, wi, wo);
    case MODEL_HTSG: return htsgEval(p, wi, wo);
    case MODEL_POULIN_FOURNIER: return poulinFournierEval(p, wi, wo);
    case MODEL_COUPLED: return coupledEval(p, wi, wo);
    case MODEL_MIRROR: return mirrorEval(p, wi, wo);
    case MODEL_DIELECTRIC: return dielectricEval(p, wi, wo);
    case MODEL_GLTF_PBR: return gltfPbrEval(p, wi, wo);
    case MODEL_MERL: return merlEval(p, wi, wo);
    default: break;
  }
  return vec3(0.0f);
}

SHARED_END
#endif
