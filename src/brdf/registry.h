// registry.h: the catalogue of reflectance models as the CPU sees it: names, parameters with
// defaults and ranges, and the packing of parameter values into the shared BrdfParams block.
// The formulas themselves live only in shaders/shared/brdf/<model>.h.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "../../shaders/shared/brdf/dispatch.h"

namespace nusselt {

using shared::BrdfParams;

// A parameter value as written in a scene or on the command line.
struct ParamValue {
  enum class Kind { Number, String, Array } kind = Kind::Number;
  double number = 0;
  std::string text;
  std::vector<ParamValue> items;
  static ParamValue num(double v) { ParamValue p; p.kind = Kind::Number; p.number = v; return p; }
  static ParamValue str(std::string v) { ParamValue p; p.kind = Kind::String; p.text = std::move(v); return p; }
};
using NamedParams = std::vector<std::pair<std::string, ParamValue>>;
// An array of numbers (e.g. a lafortune lobe [Cx, Cy, Cz, n]).
inline ParamValue arrayValue(std::vector<ParamValue> items) {
  ParamValue p;
  p.kind = ParamValue::Kind::Array;
  p.items = std::move(items);
  return p;
}

enum class ParamKind {
  Scalar,  // one float
  Colour,  // three floats (RGB); a single number is broadcast to all three
  Choice,  // one of a list of names, stored as its index (a number is accepted too)
  Lobes,   // lafortune: [[Cx, Cy, Cz, n], ...], up to LAFORTUNE_MAX_LOBES; stored as the count at
           // offset, the lobes from offset + 1 (4 floats each). minValue/maxValue bound Cx, Cy, Cz;
           // n must lie in (0, lobeMaxExponent].
};

struct ParamSpec {
  std::string name;
  ParamKind kind = ParamKind::Scalar;
  std::uint32_t offset = 0;          // first float in BrdfParams
  float defaultValue[3] = {0, 0, 0};
  float minValue = 0;                // inclusive
  float maxValue = 0;                // inclusive
  bool minExclusive = false;         // (0, 1] style ranges
  std::vector<std::string> choices;  // Choice only
  std::vector<float> defaultLobes;   // Lobes only: 4 floats per lobe
  float lobeMaxExponent = 0;         // Lobes only
  std::string doc;
};

struct ModelSpec {
  std::string name;
  std::uint32_t id = 0;  // MODEL_* in shaders/shared/brdf/dispatch.h
  bool delta = false;    // mirror, dielectric: never evaluated or light-sampled
  bool measured = false; // merl: a table read from a file (loadMerl, src/brdf/merl.h), no parameters
  std::vector<ParamSpec> params;
  std::string summary;
  // The catalogue's parameter sets (docs/brdf-models.md): typical (= the defaults) and hard
  // (numerically hardest), plus named variants (e.g. ward's other normalisations).
  NamedParams typical;
  NamedParams hard;
  std::vector<std::pair<std::string, NamedParams>> variants;
};


// The analytic catalogue (the 20 models of docs/models.md).
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
