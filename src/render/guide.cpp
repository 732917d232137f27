// guide.cpp: the path guide's device buffers and training (guide.h).
#include "render/guide.h"

#include <algorithm>
#include <cstdio>
#include <cstring>

#include "../../shaders/shared/layout.h"
#include "util/error.h"

namespace nusselt {

using shared::GpuGuide;

namespace {
double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}
// The directional nodes start at this byte offset of the arrays buffer, after at most this many
// spatial nodes' bytes: the spatial array never exceeds the cap either, so both fit in cap + 32.
std::uint64_t arraysBytes(std::uint64_t cap) { return cap + sizeof(shared::GuideDirNode); }
// FNV-1a, 64 bits, continued from h over n bytes.
std::uint64_t fnv1a(std::uint64_t h, const void* data, std::size_t n) {
  const auto* b = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 0x100000001b3ull;
  return h;
}
constexpr std::uint64_t kRecordBytes = GUIDE_RECORD_VEC4S * sizeof(glm::vec4);
}  // namespace

std::uint32_t DeviceGuide::recordsPerPath(std::uint32_t maxDepth) {
  return std::min(maxDepth, GUIDE_MAX_RECORD_VERTICES) + 1;
}

std::uint64_t DeviceGuide::bytesFor(std::uint64_t memoryCap, std::uint32_t pathCapacity, std::uint32_t maxDepth) {
  return sizeof(GpuGuide) + arraysBytes(memoryCap) + std::uint64_t(pathCapacity) * recordsPerPath(maxDepth) * kRecordBytes;
}

DeviceGuide::DeviceGuide(vk::Context& ctx, glm::vec3 lo, glm::vec3 hi, const guiding::GuideSettings& settings,
                         std::uint32_t pathCapacity, std::uint32_t maxDepth)
    : m_ctx(ctx), m_tree(lo, hi, settings), m_recordsPerPath(recordsPerPath(maxDepth)), m_capacity(pathCapacity) {
  m_info = vk::createBuffer(m_ctx, sizeof(GpuGuide), 0, true, "path guide");
  m_arrays = vk::createBuffer(m_ctx, arraysBytes(settings.memoryCap), 0, true, "path guide trees");
  // Read after every training chunk (hundreds of MiB per second of rendering): mapped where the
  // device's memory is the host's, else through a staging copy.
  m_records = vk::createBuffer(m_ctx, std::uint64_t(pathCapacity) * m_recordsPerPath * kRecordBytes, 0,
                               vk::sharesHostMemory(m_ctx), "path guide training records");
  upload();
}

DeviceGuide::~DeviceGuide() {
  vk::destroyBuffer(m_ctx, m_records);
  vk::destroyBuffer(m_ctx, m_arrays);
  vk::destroyBuffer(m_ctx, m_info);
}

std::uint64_t DeviceGuide::deviceBytes() const { return m_info.size + m_arrays.size + m_records.size; }

std::string DeviceGuide::hashText() const {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(m_hash));
  return text;
}

void DeviceGuide::fillGlobals(shared::Globals& g) const { g.guide = m_info.address; }

void DeviceGuide::upload() {
  std::vector<shared::GuideSpatialNode> spatial;
  std::vector<shared::GuideDirNode> dir;
  m_tree.flatten(spatial, dir);
  const std::uint64_t spatialBytes = spatial.size() * sizeof(spatial[0]);
  // The directional array starts 32-byte aligned after the spatial one.
  const std::uint64_t dirOffset = (spatialBytes + 31) / 32 * 32;
  if (dirOffset + dir.size() * sizeof(dir[0]) > m_arrays.size)
    throw Error("path guide: the trees outgrew their buffer (a bug: the memory cap should have stopped them)");
  auto* base = static_cast<unsigned char*>(m_arrays.mapped);
  std::memcpy(base, spatial.data(), spatialBytes);
  std::memcpy(base + dirOffset, dir.data(), dir.size() * sizeof(dir[0]));
  m_hash = fnv1a(fnv1a(0xcbf29ce484222325ull, spatial.data(), spatialBytes), dir.data(), dir.size() * sizeof(dir[0]));
  GpuGuide info{};
  const glm::vec3 lo = m_tree.boundsMin(), hi = m_tree.boundsMax();
  info.boundsMin = shared::vec4(lo, 0.0f);
  info.boundsMax = shared::vec4(hi, 0.0f);
  info.info = shared::uvec4(m_recording ? m_recordsPerPath : 0u, 0u, m_tree.settings().orientations,
                            m_tree.settings().product ? 1u : 0u);
  info.spatial = m_arrays.address;
  info.dir = m_arrays.address + dirOffset;
  info.records = m_records.address;
  std::memcpy(m_info.mapped, &info, sizeof info);
}

void DeviceGuide::setRecording(bool on) {
  if (on == m_recording) return;
  m_recording = on;
  auto* info = static_cast<GpuGuide*>(m_info.mapped);
  info->info.x = on ? m_recordsPerPath : 0u;
}

void DeviceGuide::setPhotons(bool on) {
  auto* info = static_cast<GpuGuide*>(m_info.mapped);
  info->info.x = on || m_recording ? m_recordsPerPath : 0u;
  info->info.y = on ? 1u : 0u;
}

void DeviceGuide::consumePhotons(std::uint32_t photons) {
  if (photons == 0) return;
  const auto t0 = std::chrono::steady_clock::now();
  const glm::vec4* records = static_cast<const glm::vec4*>(m_records.mapped);
  if (!records) {
    m_hostRecords.resize(std::size_t(photons) * m_recordsPerPath * GUIDE_RECORD_VEC4S);
    vk::downloadBuffer(m_ctx, m_records, m_hostRecords.data(), m_hostRecords.size() * sizeof(glm::vec4));
    records = m_hostRecords.data();
  }
  guiding::appendPhotons(records, m_recordsPerPath, photons, m_photons);
  m_seconds += secondsSince(t0);
}

void DeviceGuide::endPhotons(double countWeight) {
  const auto t0 = std::chrono::steady_clock::now();
  for (const guiding::IterationReport& r : guiding::trainPhotons(m_tree, m_photons, kPhotonRounds, countWeight))
    m_reports.push_back(r);
  if (!m_keepPhotons) {
    m_photons.clear();
    m_photons.shrink_to_fit();
  }
  upload();
  m_seconds += secondsSince(t0);
}

void DeviceGuide::consumeChunk(const vk::Buffer& pathRadiance, std::uint32_t paths) {
  if (!m_recording || paths == 0) return;
  const auto t0 = std::chrono::steady_clock::now();
  const glm::vec4* records = static_cast<const glm::vec4*>(m_records.mapped);
  if (!records) {
    m_hostRecords.resize(std::size_t(paths) * m_recordsPerPath * GUIDE_RECORD_VEC4S);
    vk::downloadBuffer(m_ctx, m_records, m_hostRecords.data(), m_hostRecords.size() * sizeof(glm::vec4));
    records = m_hostRecords.data();
  }
  const glm::vec4* radiance = static_cast<const glm::vec4*>(pathRadiance.mapped);
  if (!radiance) {
    m_hostRadiance.resize(paths);
    vk::downloadBuffer(m_ctx, pathRadiance, m_hostRadiance.data(), m_hostRadiance.size() * sizeof(glm::vec4));
    radiance = m_hostRadiance.data();
  }
  guiding::splatPaths(m_tree, records, m_recordsPerPath, radiance, paths);
  m_seconds += secondsSince(t0);
}

void DeviceGuide::endIteration(std::uint32_t iteration) {
  const auto t0 = std::chrono::steady_clock::now();
  m_reports.push_back(m_tree.endIteration(iteration));
  upload();
  m_seconds += secondsSince(t0);
}

}  // namespace nusselt
