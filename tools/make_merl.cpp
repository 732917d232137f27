// make_merl: writes a MERL-format binary file (the MERL 100 layout, docs/measured.md) from one of
// nusselt's analytic models, for tests and the documentation. The output is a tabulated
// analytic model, not measured data: the repository ships no MERL files.
//   build/make_merl --model ward --param ks=0.3 --param ax=0.2 --param ay=0.2 -o ward.binary
//   build/make_merl --model lambert --param rho=0.5 -o lambert.binary
// Each node holds f at its (theta_h, theta_d, phi_d) directions (phi_h = 0) divided by the
// format's scale factors; nodes whose directions lie below the surface are written as -1, the
// format's "not measured", as real files mark them.
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "brdf/merl.h"
#include "brdf/registry.h"
#include "util/error.h"

int main(int argc, char** argv) {
  using namespace nusselt;
  std::string model, out, set = "typical";
  std::vector<std::string> params;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "make_merl: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--model") model = next();
    else if (a == "--param") params.push_back(next());
    else if (a == "--set") set = next();
    else if (a == "-o") out = next();
    else {
      std::fprintf(stderr,
                   "usage: make_merl --model NAME [--set typical|hard] [--param name=value ...] -o FILE.binary\n");
      return 2;
    }
  }
  if (model.empty() || out.empty()) {
    std::fprintf(stderr, "usage: make_merl --model NAME [--set typical|hard] [--param name=value ...] -o FILE.binary\n");
    return 2;
  }
  try {
    const ModelSpec* m = findModel(model);
    if (!m || m->delta || m->measured) throw Error("--model " + model + ": not an analytic, non-delta model (" + knownModelNames() + ")");
    NamedParams values = set == "hard" ? hardParams(*m) : typicalParams(*m);
    for (const std::string& p : params) {
      auto pv = parseParamArgument(p);
      bool replaced = false;
      for (auto& v : values)
        if (v.first == pv.first) v.second = pv.second, replaced = true;
      if (!replaced) values.push_back(pv);
    }
    shared::BrdfParams packed = packParams(*m, values, "--param");
    writeMerlFile(out, tabulateMerl(m->id, packed));
    std::printf("wrote %s: %s (%s parameters) tabulated in the MERL layout\n", out.c_str(), model.c_str(), set.c_str());
  } catch (const Error& e) {
    std::fprintf(stderr, "make_merl: %s\n", e.what());
    return 1;
  }
  return 0;
}
