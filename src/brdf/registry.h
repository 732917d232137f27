// registry.h: the catalogue of reflectance models as the CPU sees it: names, parameters with
// defaults and ranges, and the packing of parameter values into the shared BrdfParams block.
// Each model declares its formula and its spec in shaders/shared/brdf/<model>.h (types in
// model_spec.h); the catalogue is generated from the model list, shaders/shared/brdf/models.h.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "../../shaders/shared/brdf/dispatch.h"
#include "model_spec.h"

namespace nusselt {

// The catalogue: every analytic model of the list in shaders/shared/brdf/models.h (docs/models.md).
const std::vector<ModelSpec>& allModels();
// Measured models (merl): not in allModels(), whose loops need parameter sets; found by findModel
// and modelById like the others.
const std::vector<ModelSpec>& measuredModels();
// "lambert, phong_specular, ..., merl": the names findModel knows (messages).
std::string knownModelNames();
// nullptr when unknown.
const ModelSpec* findModel(std::string_view name);
const ModelSpec& modelById(std::uint32_t id);

// Packs named values into a BrdfParams block, defaults for the others (measured models: throws,
// their block comes from loadMerl). Throws nusselt::Error
// naming `context` (e.g. "scene.gltf: materials[2] \"Floor\""), the parameter and its allowed
// range when a value is unknown, malformed, non-finite or out of range.
BrdfParams packParams(const ModelSpec& model, const NamedParams& values, const std::string& context);

// The catalogue's typical and hard parameter sets of a model.
const NamedParams& typicalParams(const ModelSpec& model);
const NamedParams& hardParams(const ModelSpec& model);

// "name=value", "name=r,g,b" or "name=[JSON array]" (the NUSSELT_brdf syntax, e.g.
// lobes=[[-1.03,-1.03,1.03,20]]) from the command line.
std::pair<std::string, ParamValue> parseParamArgument(const std::string& argument);

// Human-readable allowed range of a parameter, e.g. "[0, 1]" or "one of ward92, duer, gmd".
std::string describeRange(const ParamSpec& spec);

}  // namespace nusselt
