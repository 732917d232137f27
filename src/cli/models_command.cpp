// models_command.cpp: `nusselt models`, the catalogue of reflectance models as the program knows
// it: every model of the list (shaders/shared/brdf/models.h) with its parameters, their kinds,
// allowed ranges, defaults (the typical set) and the hard set. --markdown prints the tables that
// docs/models.md carries, so the page is regenerated from the program, not typed.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>
#include <string>

#include "brdf/registry.h"
#include "cli/commands.h"
#include "util/error.h"

namespace nusselt {
namespace {

std::string valueText(const ParamValue& v) {
  char buf[64];
  switch (v.kind) {
    case ParamValue::Kind::Number: std::snprintf(buf, sizeof buf, "%.6g", v.number); return buf;
    case ParamValue::Kind::String: return v.text;
    case ParamValue::Kind::Array: {
      std::string r = "[";
      for (std::size_t i = 0; i < v.items.size(); ++i) r += (i ? ", " : "") + valueText(v.items[i]);
      return r + "]";
    }
  }
  return "";
}

std::string setValue(const NamedParams& set, const std::string& name) {
  for (const auto& [n, v] : set)
    if (n == name) return valueText(v);
  return "(default)";
}

const char* kindName(ParamKind k) {
  return k == ParamKind::Colour ? "colour" : k == ParamKind::Choice ? "choice" : k == ParamKind::Lobes ? "lobes" : "scalar";
}

int modelsCommand(bool markdown) {
  for (std::uint32_t id = 0; id < MODEL_COUNT; ++id) {
    const ModelSpec& m = modelById(id);
    const std::string traits = std::string(m.delta ? ", delta" : "") + (m.measured ? ", measured: --file" : "");
    if (markdown) {
      std::printf("### %s (id %u%s)\n%s\n\n", m.name.c_str(), m.id, m.delta ? ", delta" : "", m.summary.c_str());
      if (m.params.empty()) {
        std::printf("No parameters%s.\n\n", m.measured ? ": the material names its file (\"file\" in NUSSELT_brdf, --file)" : "");
        continue;
      }
      std::printf("| parameter | kind | allowed | typical (default) | hard | meaning |\n|---|---|---|---|---|---|\n");
      for (const ParamSpec& p : m.params)
        std::printf("| %s | %s | %s | %s | %s | %s |\n", p.name.c_str(), kindName(p.kind), describeRange(p).c_str(),
                    setValue(m.typical, p.name).c_str(), setValue(m.hard, p.name).c_str(), p.doc.c_str());
      for (const auto& [name, values] : m.variants) {
        std::string t;
        for (const auto& [n, v] : values) t += (t.empty() ? "" : ", ") + n + " = " + valueText(v);
        std::printf("\nvariant `%s`: %s\n", name.c_str(), t.c_str());
      }
      std::printf("\n");
      continue;
    }
    std::printf("%-18s id %2u%s: %s\n", m.name.c_str(), m.id, traits.c_str(), m.summary.c_str());
    for (const ParamSpec& p : m.params)
      std::printf("    %-14s %-6s %-40s default %s, hard %s: %s\n", p.name.c_str(), kindName(p.kind),
                  describeRange(p).c_str(), setValue(m.typical, p.name).c_str(), setValue(m.hard, p.name).c_str(),
                  p.doc.c_str());
  }
  return kExitOk;
}

}  // namespace

void registerModelsCommand(CLI::App& app, CommandRunner& run) {
  auto markdown = std::make_shared<bool>(false);
  CLI::App* c = app.add_subcommand("models", "List the reflectance models with their parameters (ranges, defaults = the "
                                              "typical set, hard set); use the names in NUSSELT_brdf and --model");
  c->add_flag("--markdown", *markdown, "Print the parameter tables of docs/models.md");
  c->callback([markdown, &run] { run = [markdown] { return modelsCommand(*markdown); }; });
}

}  // namespace nusselt
