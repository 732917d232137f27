// settings.cpp: the names of the render modes (command line, EXR header, messages).
#include "render/settings.h"

namespace nusselt {

const char* lightingModeName(LightingMode mode) {
  switch (mode) {
    case LightingMode::Mis: return "mis";
    case LightingMode::NeeOnly: return "nee";
    case LightingMode::BsdfOnly: return "bsdf";
  }
  return "?";
}

const char* samplerName(SamplerKind kind) {
  switch (kind) {
    case SamplerKind::Quadtree: return "quadtree";
    case SamplerKind::Cosine: return "cosine";
    case SamplerKind::Uniform: return "uniform";
    case SamplerKind::Analytic: return "analytic";
    case SamplerKind::Tabulated: return "tabulated";
  }
  return "?";
}

const char* componentSelectionName(ComponentSelection mode) {
  return mode == ComponentSelection::Uniform ? "uniform" : "albedo";
}

bool parseComponentSelection(const std::string& name, ComponentSelection& mode) {
  for (ComponentSelection m : {ComponentSelection::Albedo, ComponentSelection::Uniform})
    if (name == componentSelectionName(m)) {
      mode = m;
      return true;
    }
  return false;
}

bool parseSampler(const std::string& name, SamplerKind& kind) {
  for (SamplerKind k : {SamplerKind::Quadtree, SamplerKind::Cosine, SamplerKind::Uniform, SamplerKind::Analytic,
                        SamplerKind::Tabulated})
    if (name == samplerName(k)) {
      kind = k;
      return true;
    }
  return false;
}

const char* rouletteModeName(RouletteMode mode) { return mode == RouletteMode::Albedo ? "albedo" : "throughput"; }

bool parseRouletteMode(const std::string& name, RouletteMode& mode) {
  for (RouletteMode m : {RouletteMode::Throughput, RouletteMode::Albedo})
    if (name == rouletteModeName(m)) {
      mode = m;
      return true;
    }
  return false;
}

const char* rngModeName(RngMode mode) { return mode == RngMode::Qmc ? "qmc" : "pcg"; }

}  // namespace nusselt
