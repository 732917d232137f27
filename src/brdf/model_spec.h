// model_spec.h: what the CPU knows about a reflectance model besides its formula: its name,
// parameters (defaults, ranges, packing offsets), catalogue sets, and the traits the tree builder
// uses. Each model declares its own in the C++ section of shaders/shared/brdf/<model>.h (a
// function <fn>Spec(ModelSpec&)); src/brdf/registry.cpp collects them through the model list
// (shaders/shared/brdf/models.h). Kept free of the model headers so that they can include it.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "../../shaders/shared/layout.h"

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

// What the quadtree builder (src/quadtree/quadtree_build.cpp) and the tabulated strategy need to
// know about f beyond its values, for one parameter set.
struct ModelTraits {
  // f ~ cos(theta)^-rimExponent at the horizon (0: bounded there): the builder's rim envelope.
  float rimExponent = 0.0f;
  // f depends on the azimuth of wo: full-disc trees and trees over incident azimuth.
  bool anisotropic = false;
};

// Known features of f over the disc for a known direction v, beyond the ones every model gets
// (normal, mirror, rim, retro directions): points where f peaks, and ridges (lines along which
// f folds or streaks, thinner than any integration rule resolves; axis 0: x = value, axis 1:
// y = value). A model that lists ridges replaces the builder's default ridges of anisotropic
// models (the two lines through the mirror direction).
struct DiscRidge {
  int axis;
  double value;
};
struct ModelFeatures {
  std::vector<std::array<double, 2>> peaks;
  std::vector<std::array<double, 2>> lowerPeaks;  // transmitting models: peaks on the lower disc (refraction direction)
  std::vector<DiscRidge> ridges;
};

struct ModelSpec {
  std::string name;
  std::uint32_t id = 0;  // MODEL_<NAME> in shaders/shared/brdf/models.h
  bool delta = false;    // mirror, dielectric: never evaluated or light-sampled (<NAME>_DELTA)
  bool transmits = false; // f is not zero below the surface (<NAME>_TRANSMITS in the header: rough_dielectric)
  bool measured = false; // merl: a table read from a file (loadMerl, src/brdf/merl.h), no parameters
  std::vector<ParamSpec> params;
  std::string summary;
  // The catalogue's parameter sets (docs/brdf-models.md): typical (= the defaults) and hard
  // (numerically hardest), plus named variants (e.g. ward's other normalisations).
  NamedParams typical;
  NamedParams hard;
  std::vector<std::pair<std::string, NamedParams>> variants;
  // Optional hooks (nullptr: none).
  ModelTraits (*traits)(const BrdfParams&) = nullptr;                                       // default: {}
  void (*features)(const BrdfParams&, const shared::vec3& v, ModelFeatures& out) = nullptr;  // extra peaks, ridges
  void (*finishParams)(BrdfParams&) = nullptr;  // after packing (e.g. coupled's precomputed tables)
};

// Builders for the model headers' spec functions.
namespace spec {

inline ParamSpec colour(const char* name, std::uint32_t offset, float def, float lo, float hi, const char* doc) {
  ParamSpec s;
  s.name = name;
  s.kind = ParamKind::Colour;
  s.offset = offset;
  s.defaultValue[0] = s.defaultValue[1] = s.defaultValue[2] = def;
  s.minValue = lo;
  s.maxValue = hi;
  s.doc = doc;
  return s;
}

// A scalar in [lo, hi] (or (lo, hi] when loExclusive).
inline ParamSpec scalar(const char* name, std::uint32_t offset, float def, float lo, float hi, bool loExclusive,
                        const char* doc) {
  ParamSpec s;
  s.name = name;
  s.kind = ParamKind::Scalar;
  s.offset = offset;
  s.defaultValue[0] = def;
  s.minValue = lo;
  s.maxValue = hi;
  s.minExclusive = loExclusive;
  s.doc = doc;
  return s;
}

inline ParamSpec choice(const char* name, std::uint32_t offset, int def, std::vector<std::string> names,
                        const char* doc) {
  ParamSpec s;
  s.name = name;
  s.kind = ParamKind::Choice;
  s.offset = offset;
  s.defaultValue[0] = static_cast<float>(def);
  s.minValue = 0;
  s.maxValue = static_cast<float>(names.size() - 1);
  s.choices = std::move(names);
  s.doc = doc;
  return s;
}

inline std::pair<std::string, ParamValue> N(const char* name, double v) { return {name, ParamValue::num(v)}; }
inline std::pair<std::string, ParamValue> S(const char* name, const char* v) { return {name, ParamValue::str(v)}; }
inline ParamValue lobe(double cx, double cy, double cz, double n) {
  return arrayValue({ParamValue::num(cx), ParamValue::num(cy), ParamValue::num(cz), ParamValue::num(n)});
}

}  // namespace spec
}  // namespace nusselt
