// format.h: numbers in messages and headers as people write them (shortest %g form that keeps
// nine significant digits: 0.5, 12000, 16).
#pragma once
#include <cstdio>
#include <string>

namespace nusselt {

inline std::string formatNumber(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace nusselt
