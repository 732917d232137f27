// registry.cpp: model and parameter specifications (names and ranges as in the BRDF catalogue,
// docs/brdf-models.md) and their packing into BrdfParams.
#include "brdf/registry.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <nlohmann/json.hpp>

#include "brdf/albedo.h"
#include "util/error.h"

namespace nusselt {
namespace {

// Every model of the list (shaders/shared/brdf/models.h), in id order, from its header's spec.
std::vector<ModelSpec> buildCatalogue(bool measured) {
  std::vector<ModelSpec> models;
  auto add = [&](std::uint32_t id, bool delta, void (*spec)(ModelSpec&)) {
    ModelSpec m;
    m.id = id;
    m.delta = delta;
    spec(m);
    if (m.measured == measured) models.push_back(std::move(m));
  };
#define NUSSELT_MODEL_SPEC(id, NAME, fn) add(MODEL_##NAME, NAME##_DELTA != 0, &models::fn##Spec);
  NUSSELT_MODELS(NUSSELT_MODEL_SPEC)
#undef NUSSELT_MODEL_SPEC
  return models;
}

std::string formatFloat(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

float checkedNumber(const ParamSpec& spec, double v, const std::string& context) {
  bool ok = std::isfinite(v) && v <= spec.maxValue &&
            (spec.minExclusive ? v > spec.minValue : v >= spec.minValue);
  if (!ok)
    throw Error(context + ": parameter \"" + spec.name + "\" = " + formatFloat(v) +
                " is outside its allowed range " + describeRange(spec));
  return static_cast<float>(v);
}

}  // namespace

const std::vector<ModelSpec>& allModels() {
  static const std::vector<ModelSpec> models = buildCatalogue(false);
  return models;
}

const std::vector<ModelSpec>& measuredModels() {
  static const std::vector<ModelSpec> models = buildCatalogue(true);
  return models;
}

std::string knownModelNames() {
  std::string known;
  for (const ModelSpec& s : allModels()) known += (known.empty() ? "" : ", ") + s.name;
  for (const ModelSpec& s : measuredModels()) known += ", " + s.name;
  return known;
}

const NamedParams& typicalParams(const ModelSpec& model) { return model.typical; }
const NamedParams& hardParams(const ModelSpec& model) { return model.hard; }

const ModelSpec* findModel(std::string_view name) {
  for (const ModelSpec& m : allModels())
    if (m.name == name) return &m;
  for (const ModelSpec& m : measuredModels())
    if (m.name == name) return &m;
  return nullptr;
}

const ModelSpec& modelById(std::uint32_t id) {
  for (const ModelSpec& m : allModels())
    if (m.id == id) return m;
  for (const ModelSpec& m : measuredModels())
    if (m.id == id) return m;
  throw Error("internal: unknown model id " + std::to_string(id));
}

std::string describeRange(const ParamSpec& spec) {
  if (spec.kind == ParamKind::Choice) {
    std::string s = "one of";
    for (size_t i = 0; i < spec.choices.size(); ++i) s += (i ? ", " : " ") + spec.choices[i];
    return s;
  }
  std::string s = (spec.minExclusive ? "(" : "[") + formatFloat(spec.minValue) + ", " +
                  (std::isinf(spec.maxValue) ? std::string("inf)") : formatFloat(spec.maxValue) + "]");
  if (spec.kind == ParamKind::Colour) s += " (a number or an [r, g, b] array)";
  if (spec.kind == ParamKind::Lobes) s += " (each of Cx, Cy, Cz)";
  return s;
}

BrdfParams packParams(const ModelSpec& model, const NamedParams& values, const std::string& context) {
  if (model.measured)
    throw Error(context + ": model \"" + model.name + "\" is measured: it reads a table from a file (\"file\" in a "
                "scene, --file on the command line), it has no parameters");
  BrdfParams p{};
  auto set = [&p](std::uint32_t i, float v) { p.v[i / 4][i % 4] = v; };
  for (const ParamSpec& spec : model.params) {
    if (spec.kind == ParamKind::Lobes) {
      set(spec.offset, static_cast<float>(spec.defaultLobes.size() / 4));
      for (size_t i = 0; i < spec.defaultLobes.size(); ++i) set(spec.offset + 1 + i, spec.defaultLobes[i]);
      continue;
    }
    int n = spec.kind == ParamKind::Colour ? 3 : 1;
    for (int c = 0; c < n; ++c) set(spec.offset + c, spec.defaultValue[c]);
  }
  for (size_t k = 0; k < values.size(); ++k) {
    const auto& [name, value] = values[k];
    for (size_t j = 0; j < k; ++j)
      if (values[j].first == name) throw Error(context + ": parameter \"" + name + "\" is given twice");
    const ParamSpec* spec = nullptr;
    for (const ParamSpec& s : model.params)
      if (s.name == name) spec = &s;
    if (!spec) {
      std::string known;
      for (const ParamSpec& s : model.params) known += (known.empty() ? "" : ", ") + s.name;
      throw Error(context + ": model \"" + model.name + "\" has no parameter \"" + name +
                  "\" (its parameters: " + (known.empty() ? "none" : known) + ")");
    }
    switch (spec->kind) {
      case ParamKind::Scalar:
        if (value.kind != ParamValue::Kind::Number)
          throw Error(context + ": parameter \"" + name + "\" must be a number in " + describeRange(*spec));
        set(spec->offset, checkedNumber(*spec, value.number, context));
        break;
      case ParamKind::Colour:
        if (value.kind == ParamValue::Kind::Number) {
          float v = checkedNumber(*spec, value.number, context);
          for (int c = 0; c < 3; ++c) set(spec->offset + c, v);
        } else if (value.kind == ParamValue::Kind::Array && value.items.size() == 3) {
          for (int c = 0; c < 3; ++c) {
            if (value.items[c].kind != ParamValue::Kind::Number)
              throw Error(context + ": parameter \"" + name + "\" must hold three numbers");
            set(spec->offset + c, checkedNumber(*spec, value.items[c].number, context));
          }
        } else {
          throw Error(context + ": parameter \"" + name + "\" must be a number or an [r, g, b] array in " +
                      describeRange(*spec));
        }
        break;
      case ParamKind::Choice: {
        int index = -1;
        if (value.kind == ParamValue::Kind::String) {
          for (size_t c = 0; c < spec->choices.size(); ++c)
            if (spec->choices[c] == value.text) index = static_cast<int>(c);
        } else if (value.kind == ParamValue::Kind::Number && value.number >= 0 &&
                   value.number < spec->choices.size() && std::floor(value.number) == value.number) {
          index = static_cast<int>(value.number);
        }
        if (index < 0)
          throw Error(context + ": parameter \"" + name + "\" must be " + describeRange(*spec));
        set(spec->offset, static_cast<float>(index));
        break;
      }
      case ParamKind::Lobes: {
        const std::string expected = "an array of 1 to " + std::to_string(LAFORTUNE_MAX_LOBES) +
                                     " lobes [Cx, Cy, Cz, n] with Cx, Cy, Cz in " + describeRange(*spec) +
                                     " and n in (0, " + formatFloat(spec->lobeMaxExponent) + "]";
        if (value.kind != ParamValue::Kind::Array || value.items.empty() ||
            value.items.size() > static_cast<size_t>(LAFORTUNE_MAX_LOBES))
          throw Error(context + ": parameter \"" + name + "\" must be " + expected);
        for (size_t j = 0; j < value.items.size(); ++j) {
          const ParamValue& l = value.items[j];
          bool ok = l.kind == ParamValue::Kind::Array && l.items.size() == 4;
          for (size_t c = 0; ok && c < 4; ++c) ok = l.items[c].kind == ParamValue::Kind::Number;
          if (!ok)
            throw Error(context + ": parameter \"" + name + "\" lobe " + std::to_string(j) + " must be [Cx, Cy, Cz, n]; " +
                        name + " must be " + expected);
          for (size_t c = 0; c < 3; ++c) set(spec->offset + 1 + 4 * j + c, checkedNumber(*spec, l.items[c].number, context));
          double n = l.items[3].number;
          if (!std::isfinite(n) || n <= 0 || n > spec->lobeMaxExponent)
            throw Error(context + ": parameter \"" + name + "\" lobe " + std::to_string(j) + " exponent n = " +
                        formatFloat(n) + " is outside its allowed range (0, " + formatFloat(spec->lobeMaxExponent) + "]");
          double cmax = std::max({std::abs(l.items[0].number), std::abs(l.items[1].number), std::abs(l.items[2].number)});
          if (n * std::log(std::max(cmax, 1e-300)) > std::log(1e6))
            throw Error(context + ": parameter \"" + name + "\" lobe " + std::to_string(j) +
                        ": its peak value max(|Cx|, |Cy|, |Cz|)^n = " + formatFloat(std::pow(cmax, n)) +
                        " exceeds the allowed 1e6 [1/sr]");
          set(spec->offset + 1 + 4 * j + 3, static_cast<float>(n));
        }
        set(spec->offset, static_cast<float>(value.items.size()));
        for (size_t j = value.items.size(); j < static_cast<size_t>(LAFORTUNE_MAX_LOBES); ++j)
          for (int c = 0; c < 4; ++c) set(spec->offset + 1 + 4 * j + c, 0.0f);
        break;
      }
    }
  }
  if (model.finishParams) model.finishParams(p);
  return p;
}

namespace {

// A JSON value of a --param argument as a ParamValue: numbers, strings and arrays of them (the
// NUSSELT_brdf extension's syntax); anything else is refused.
ParamValue fromJson(const nlohmann::json& j, const std::string& argument) {
  if (j.is_number()) return ParamValue::num(j.get<double>());
  if (j.is_string()) return ParamValue::str(j.get<std::string>());
  if (j.is_array()) {
    std::vector<ParamValue> items;
    for (const nlohmann::json& e : j) items.push_back(fromJson(e, argument));
    return arrayValue(std::move(items));
  }
  throw Error("--param \"" + argument + "\": only numbers, strings and arrays of them are allowed");
}

}  // namespace

std::pair<std::string, ParamValue> parseParamArgument(const std::string& argument) {
  auto eq = argument.find('=');
  if (eq == std::string::npos || eq == 0)
    throw Error("--param \"" + argument + "\": expected name=value, name=r,g,b or name=[JSON array]");
  std::string name = argument.substr(0, eq), rest = argument.substr(eq + 1);
  if (!rest.empty() && rest[0] == '[') {
    // The extension's JSON, e.g. lobes=[[-1.03,-1.03,1.03,20]]. Nesting is capped before parsing
    // (no parameter nests deeper than 2; the recursion of the parser and of fromJson stays small).
    int depth = 0, deepest = 0;
    for (char c : rest) {
      if (c == '[') deepest = std::max(deepest, ++depth);
      else if (c == ']') --depth;
    }
    if (deepest > 4) throw Error("--param \"" + argument + "\": arrays nest at most 4 deep");
    nlohmann::json j = nlohmann::json::parse(rest, nullptr, false);
    if (j.is_discarded()) throw Error("--param \"" + argument + "\": the value after '=' is not valid JSON");
    return {name, fromJson(j, argument)};
  }
  std::vector<ParamValue> parts;
  std::stringstream ss(rest);
  std::string item;
  while (std::getline(ss, item, ',')) {
    char* end = nullptr;
    double v = std::strtod(item.c_str(), &end);
    if (end && *end == '\0' && !item.empty()) parts.push_back(ParamValue::num(v));
    else parts.push_back(ParamValue::str(item));
  }
  if (parts.size() == 1) return {name, parts[0]};
  ParamValue array;
  array.kind = ParamValue::Kind::Array;
  array.items = parts;
  return {name, array};
}

}  // namespace nusselt
