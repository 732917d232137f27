// fuzz_brdf_params.cpp: libFuzzer target for the NUSSELT_brdf parameter parsing (issue 8).
//
// Two input forms, chosen by the first non-blank byte:
//   '{'   a NUSSELT_brdf extension object as a scene writes it:
//         {"model": "ward", "params": {"rho_d": [0.5, 0.5, 0.5], "variant": "duer", ...}}
//         converted to ParamValues the way the glTF loader converts tinygltf values;
//   else  the command line: the first line is a model name, every further line one
//         --param argument ("name=value" or "name=r,g,b") through parseParamArgument.
// Then findModel + packParams. nusselt::Error is the documented failure. A crash, sanitizer
// report, any other exception, or a packed parameter block holding NaN/Inf is a finding.
//
// The coupled model is skipped unless NUSSELT_FUZZ_COUPLED=1: packing it runs the albedo
// quadrature for its tables (~1 s under ASan for every new m, cached without bound), which would
// turn this fuzzer into a benchmark of that quadrature.
//
// With NUSSELT_FUZZ_EVAL=1 in the environment the accepted block is also evaluated
// (brdfEval, the shared CPU/GPU code) at directions taken from the input, and a non-finite or
// negative value is a finding too: accepted parameters must never give the renderer a NaN.
// NUSSELT_FUZZ_SKIP=model1,model2 leaves models out (e.g. one with a known finding).
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include <nlohmann/json.hpp>

#include "brdf/registry.h"
#include "util/error.h"

namespace {

using Json = nlohmann::json;
using nusselt::ParamValue;

[[noreturn]] void finding(const std::string& what) {
  std::fprintf(stderr, "fuzz_brdf_params: %s\n", what.c_str());
  std::abort();
}

// Rejection of malformed JSON is the harness's business, not the code under test's.
struct NotParams {};

ParamValue toParamValue(const Json& v, int depth) {
  if (depth > 8) throw NotParams{};
  if (v.is_number()) return ParamValue::num(v.get<double>());
  if (v.is_string()) return ParamValue::str(v.get<std::string>());
  if (v.is_array()) {
    ParamValue p;
    p.kind = ParamValue::Kind::Array;
    for (const Json& item : v) p.items.push_back(toParamValue(item, depth + 1));
    return p;
  }
  throw NotParams{};
}

bool parseInput(const std::string& text, std::string* model, nusselt::NamedParams* params) {
  std::size_t first = text.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && text[first] == '{') {
    Json root = Json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (root.is_discarded() || !root.is_object()) return false;
    auto m = root.find("model");
    if (m == root.end() || !m->is_string()) return false;
    *model = m->get<std::string>();
    auto p = root.find("params");
    if (p != root.end()) {
      if (!p->is_object()) return false;
      try {
        for (auto it = p->begin(); it != p->end(); ++it) params->emplace_back(it.key(), toParamValue(it.value(), 0));
      } catch (const NotParams&) {
        return false;
      }
    }
    return true;
  }
  std::size_t nl = text.find('\n');
  *model = text.substr(0, nl);
  while (nl != std::string::npos) {
    std::size_t next = text.find('\n', nl + 1);
    std::string line = text.substr(nl + 1, next == std::string::npos ? std::string::npos : next - nl - 1);
    nl = next;
    if (line.empty()) continue;
    params->push_back(nusselt::parseParamArgument(line));  // may throw nusselt::Error
  }
  return true;
}

void evaluate(std::uint32_t id, const nusselt::BrdfParams& p, const std::string& text) {
  // Directions from a hash of the input, plus the hard ones: normal, grazing, just above.
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
  const float grazing[] = {1.0f, 0.5f, 1e-3f, 1e-7f, 0.0f};
  for (float cz : grazing) {
    for (int k = 0; k < 4; ++k) {
      h = h * 6364136223846793005ull + 1442695040888963407ull;
      float phi1 = float(h >> 40) / float(1 << 24) * 6.2831853f;
      float cz2 = grazing[(h >> 8) % 5];
      float phi2 = float((h >> 16) & 0xffffff) / float(1 << 24) * 6.2831853f;
      float s1 = std::sqrt(std::max(0.0f, 1 - cz * cz)), s2 = std::sqrt(std::max(0.0f, 1 - cz2 * cz2));
      glm::vec3 wi(s1 * std::cos(phi1), s1 * std::sin(phi1), cz), wo(s2 * std::cos(phi2), s2 * std::sin(phi2), cz2);
      glm::vec3 f = nusselt::shared::brdfEval(id, p, wi, wo);
      for (int c = 0; c < 3; ++c)
        if (!std::isfinite(f[c]) || f[c] < 0)
          finding("brdfEval of model " + std::to_string(id) + " gave " + std::to_string(f[c]) + " at wi.z=" +
                  std::to_string(cz) + " wo.z=" + std::to_string(cz2));
    }
  }
}

bool envFlag(const char* name) {
  const char* e = std::getenv(name);
  return e && std::strcmp(e, "1") == 0;
}

bool skipped(const std::string& model) {
  static const std::string list = [] {
    const char* e = std::getenv("NUSSELT_FUZZ_SKIP");
    return "," + std::string(e ? e : "") + ",";
  }();
  return list.find("," + model + ",") != std::string::npos;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool eval = envFlag("NUSSELT_FUZZ_EVAL"), coupled = envFlag("NUSSELT_FUZZ_COUPLED");
  if (size > 4096) return 0;  // parameter blocks are small; keep the fuzzer on the parsing
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    std::string modelName;
    nusselt::NamedParams params;
    if (!parseInput(text, &modelName, &params)) return 0;
    const nusselt::ModelSpec* spec = nusselt::findModel(modelName);
    if (!spec || (spec->id == nusselt::MODEL_COUPLED && !coupled) || skipped(spec->name)) return 0;
    for (const nusselt::ParamSpec& ps : spec->params) (void)nusselt::describeRange(ps);
    nusselt::BrdfParams packed = nusselt::packParams(*spec, params, "fuzz");
    for (int i = 0; i < BRDF_PARAM_VEC4S; ++i)
      for (int c = 0; c < 4; ++c)
        if (!std::isfinite(packed.v[i][c]))
          finding("packParams accepted input and packed a non-finite value at float " + std::to_string(4 * i + c));
    if (eval && !spec->delta) evaluate(spec->id, packed, text);
  } catch (const nusselt::Error&) {
    // The documented failure.
  }
  return 0;
}
