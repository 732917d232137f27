// models.h: THE list of reflectance models. Everything that enumerates models (ids, the
// evaluation, analytic-sampling and delta-sampling switches, the CPU catalogue of names and
// parameters, the tree builder's traits) is generated from NUSSELT_MODELS below.
//
// Adding a model (docs/models.md, "Adding a model"):
//   1. write shaders/shared/brdf/<name>.h: parameter offsets, <fn>Eval, the traits <NAME>_DELTA
//      and <NAME>_ANALYTIC (and <fn>AnalyticSample/Pdf or <fn>DeltaSample/... when they are 1),
//      and in its C++ section <fn>Spec (name, parameters, catalogue sets, optional tree traits);
//   2. include it below and add its line to NUSSELT_MODELS with the next free id.
// Ids are stable numbers (they are written into quadtree cache keys and EXR headers): never
// renumber; they must equal the position in the list (checked at compile time in C++).
#ifndef NUSSELT_BRDF_MODELS_H
#define NUSSELT_BRDF_MODELS_H
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
#include "thin_dielectric.h"
#include "rough_dielectric.h"
#include "rough_thin_dielectric.h"

// X(id, NAME, fn): MODEL_<NAME> = id; <NAME>_DELTA, <NAME>_ANALYTIC and the functions <fn>Eval,
// <fn>Spec, ... come from the model's header. These are the only X(id, NAME, fn) lines of the file:
// CMakeLists.txt (one shade module per model) and tests/cli/models.sh read them as the list.
#define NUSSELT_MODELS(X)                  \
  X(0u, LAMBERT, lambert)                  \
  X(1u, PHONG_SPECULAR, phongSpecular)     \
  X(2u, PHONG, phong)                      \
  X(3u, LEWIS, lewis)                      \
  X(4u, BLINN, blinn)                      \
  X(5u, TORRANCE_SPARROW, torranceSparrow) \
  X(6u, WARD, ward)                        \
  X(7u, ASHIKHMIN_SHIRLEY, ashikhminShirley) \
  X(8u, LAFORTUNE, lafortune)              \
  X(9u, MINNAERT, minnaert)                \
  X(10u, OREN_NAYAR, orenNayar)            \
  X(11u, SCHLICK, schlick)                 \
  X(12u, STRAUSS, strauss)                 \
  X(13u, BEARD_MAXWELL, beardMaxwell)      \
  X(14u, HTSG, htsg)                       \
  X(15u, POULIN_FOURNIER, poulinFournier)  \
  X(16u, COUPLED, coupled)                 \
  X(17u, MIRROR, mirror)                   \
  X(18u, DIELECTRIC, dielectric)           \
  X(19u, GLTF_PBR, gltfPbr)                \
  X(20u, MERL, merl)                       \
  X(21u, THIN_DIELECTRIC, thinDielectric)   \
  X(22u, ROUGH_DIELECTRIC, roughDielectric) \
  X(23u, ROUGH_THIN_DIELECTRIC, roughThinDielectric)

// The models the dispatch switches below and in analytic_sampling.h contain: all of them, or
// only one in a shade module built for a single model (CMakeLists.txt: -DNUSSELT_SHADE_MODEL_ID,
// _NAME and _FN from this list). lavapipe inlines every case before it folds the specialization
// constant that selects one, so a one-model module turns into a pipeline about 10x faster
// (bench pipelines). The ids are defined for every model either way.
#define NUSSELT_MODEL_APPLY(X, id, NAME, fn) X(id, NAME, fn)
// The models of most combined materials: glTF's (gltf_loader.cpp: partial or textured
// transmission is {gltf_pbr, 1 - w; a dielectric, w}) and the usual diffuse base and ideal lobe
// (lambert, mirror). The combined shade modules built for them alone (shade_combined_c2l_sN,
// -DNUSSELT_DISPATCH_LEAN=1; CMakeLists.txt) dispatch over these seven instead of all the models,
// and lavapipe creates their pipelines that much faster. Each line is NUSSELT_MODEL_APPLY(X, ...)
// with the arguments of the model's line in NUSSELT_MODELS (checked against it at compile time in
// C++), not X(id, NAME, fn): CMakeLists.txt (SHADE_MODELS) and tests/cli/models.sh read every
// X(id, NAME, fn) line of this file as a model of the list.
#define NUSSELT_LEAN_COMBINATION_MODELS(X)                              \
  NUSSELT_MODEL_APPLY(X, 0u, LAMBERT, lambert)                          \
  NUSSELT_MODEL_APPLY(X, 17u, MIRROR, mirror)                           \
  NUSSELT_MODEL_APPLY(X, 18u, DIELECTRIC, dielectric)                   \
  NUSSELT_MODEL_APPLY(X, 19u, GLTF_PBR, gltfPbr)                        \
  NUSSELT_MODEL_APPLY(X, 21u, THIN_DIELECTRIC, thinDielectric)          \
  NUSSELT_MODEL_APPLY(X, 22u, ROUGH_DIELECTRIC, roughDielectric)        \
  NUSSELT_MODEL_APPLY(X, 23u, ROUGH_THIN_DIELECTRIC, roughThinDielectric)
#ifdef NUSSELT_SHADE_MODEL_ID
#define NUSSELT_DISPATCH_MODELS(X) \
  NUSSELT_MODEL_APPLY(X, NUSSELT_SHADE_MODEL_ID, NUSSELT_SHADE_MODEL_NAME, NUSSELT_SHADE_MODEL_FN)
#elif defined(NUSSELT_DISPATCH_LEAN)
#define NUSSELT_DISPATCH_MODELS(X) NUSSELT_LEAN_COMBINATION_MODELS(X)
#else
#define NUSSELT_DISPATCH_MODELS(X) NUSSELT_MODELS(X)
#endif

SHARED_BEGIN
// MODEL_LAMBERT = 0u, ...
#define NUSSELT_MODEL_ID(id, NAME, fn) SHARED_CONST uint MODEL_##NAME = id;
NUSSELT_MODELS(NUSSELT_MODEL_ID)
#undef NUSSELT_MODEL_ID
#define NUSSELT_MODEL_PLUS_ONE(id, NAME, fn) +1u
SHARED_CONST uint MODEL_COUNT = 0u NUSSELT_MODELS(NUSSELT_MODEL_PLUS_ONE);
#undef NUSSELT_MODEL_PLUS_ONE
SHARED_END

#ifdef __cplusplus
// The ids in namespace nusselt too (they were macros once; host code names them unqualified).
namespace nusselt {
#define NUSSELT_MODEL_USING(id, NAME, fn) using shared::MODEL_##NAME;
NUSSELT_MODELS(NUSSELT_MODEL_USING)
#undef NUSSELT_MODEL_USING
using shared::MODEL_COUNT;
}  // namespace nusselt
namespace nusselt::shared::model_list_check {
#define NUSSELT_MODEL_ID_ITEM(id, NAME, fn) id,
constexpr uint ids[] = {NUSSELT_MODELS(NUSSELT_MODEL_ID_ITEM)};
#undef NUSSELT_MODEL_ID_ITEM
constexpr bool idsArePositions() {
  for (uint i = 0; i < MODEL_COUNT; ++i)
    if (ids[i] != i) return false;
  return true;
}
static_assert(idsArePositions(), "models.h: model ids must be 0, 1, 2, ... in list order");
#define NUSSELT_LEAN_MODEL_CHECK(id, NAME, fn) static_assert(MODEL_##NAME == id, "models.h: NUSSELT_LEAN_COMBINATION_MODELS: " #NAME "'s id");
NUSSELT_LEAN_COMBINATION_MODELS(NUSSELT_LEAN_MODEL_CHECK)
#undef NUSSELT_LEAN_MODEL_CHECK
}  // namespace nusselt::shared::model_list_check
namespace nusselt {
// Whether `model` is one of NUSSELT_LEAN_COMBINATION_MODELS (the combined shade module built for
// them alone serves combinations of these only).
inline bool leanCombinationModel(shared::uint model) {
#define NUSSELT_LEAN_MODEL_IS(id, NAME, fn) if (model == id) return true;
  NUSSELT_LEAN_COMBINATION_MODELS(NUSSELT_LEAN_MODEL_IS)
#undef NUSSELT_LEAN_MODEL_IS
  return false;
}
}  // namespace nusselt
#endif

#endif
