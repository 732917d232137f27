// settings.cpp: RenderStats' folds.
#include "render/settings.h"

namespace nusselt {

void RenderStats::add(const RenderStats& other) {
#define NUSSELT_STAT_ADD(ID, index, name, what) name += other.name;
  NUSSELT_STATS(NUSSELT_STAT_ADD)
#undef NUSSELT_STAT_ADD
}

void RenderStats::addDevice(const std::uint32_t* counters) {
#define NUSSELT_STAT_ADD_DEVICE(ID, index, name, what) name += counters[shared::STAT_##ID];
  NUSSELT_STATS(NUSSELT_STAT_ADD_DEVICE)
#undef NUSSELT_STAT_ADD_DEVICE
}

}  // namespace nusselt
