// guide.h: the path guide of a render (issue 16, docs/guiding.md): the trainer's tree
// (src/guiding/guide_tree.h), its flat arrays on the device, the per-path training records the
// shade stages write, and the training schedule: iterations of 1, 2, 4, ... samples per pixel
// (Mueller et al. 2017), each trained from the paths of the iteration before it (their records
// splatted on the CPU in path order, so the same settings give bit-identical images).
#pragma once
#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "guiding/guide_tree.h"
#include "vk/vk.h"

namespace nusselt {

namespace shared {
struct Globals;
}

class DeviceGuide {
 public:
  // A guide over the box [lo, hi] for a render whose chunks hold at most `pathCapacity` paths of
  // at most maxDepth + 1 vertices. Throws nusselt::Error when the buffers do not fit the device.
  DeviceGuide(vk::Context& ctx, glm::vec3 lo, glm::vec3 hi, const guiding::GuideSettings& settings,
              std::uint32_t pathCapacity, std::uint32_t maxDepth);
  ~DeviceGuide();
  DeviceGuide(const DeviceGuide&) = delete;
  DeviceGuide& operator=(const DeviceGuide&) = delete;

  // Device bytes a guide needs (before allocating): the cap, the records and the GpuGuide.
  static std::uint64_t bytesFor(std::uint64_t memoryCap, std::uint32_t pathCapacity, std::uint32_t maxDepth);
  static std::uint32_t recordsPerPath(std::uint32_t maxDepth);

  void fillGlobals(shared::Globals& g) const;
  // Whether the shade stages write training records (the GpuGuide's info.x).
  void setRecording(bool on);
  bool recording() const { return m_recording; }
  // The records' buffer (cleared before every recorded chunk: a path whose camera ray leaves the
  // scene writes no record, and its slot must read "ended", not a previous chunk's path).
  const vk::Buffer& records() const { return m_records; }
  // After a chunk of `paths` paths (recording): splats their records with their final radiance
  // (the path radiance buffer).
  void consumeChunk(const vk::Buffer& pathRadiance, std::uint32_t paths);
  // The photon pre-pass (docs/guiding.md): setPhotons(true) makes the stages trace photons and
  // write photon records (the GpuGuide's info = (records per path, 1)); consumePhotons splats a
  // chunk's photon records in photon order; endPhotons trains the tree the first iteration samples
  // from them (guiding::trainPhotons, kPhotonRounds rounds, reported with photons = true).
  void setPhotons(bool on);
  void consumePhotons(std::uint32_t photons);
  // countWeight: what each photon splat counts towards the spatial split rule.
  void endPhotons(double countWeight = 1.0);
  // Tests: keep the photon pre-pass's splats after endPhotons (photonSplats()).
  void keepPhotonSplats(bool keep) { m_keepPhotons = keep; }
  const std::vector<guiding::PhotonSplat>& photonSplats() const { return m_photons; }
  // Rounds of the photons' training: the directional trees refined 3 times by their energy.
  static constexpr std::uint32_t kPhotonRounds = 4;
  // The end of training iteration k: refines the tree and uploads the arrays the shade stages
  // sample from next.
  void endIteration(std::uint32_t iteration);

  const std::vector<guiding::IterationReport>& reports() const { return m_reports; }
  double trainingSeconds() const { return m_seconds; }  // CPU time of downloads, splats, refinement
  std::uint64_t deviceBytes() const;
  const guiding::GuideTree& tree() const { return m_tree; }
  // A 64-bit FNV-1a hash of the arrays the shade stages sample from (spatial and directional
  // nodes, the regions' alphas with them), as last uploaded: the render record states it, and a
  // resumed render, which trains its guide again, checks that it learned the same one.
  std::uint64_t hash() const { return m_hash; }
  std::string hashText() const;  // hash() as 16 hex digits (the record's nusselt/guideHash)

 private:
  void upload();

  vk::Context& m_ctx;
  guiding::GuideTree m_tree;
  std::uint32_t m_recordsPerPath = 0;
  std::uint32_t m_capacity = 0;
  bool m_recording = false;
  vk::Buffer m_info;     // one GpuGuide (host visible)
  vk::Buffer m_arrays;   // spatial nodes then directional nodes (the cap's bytes)
  vk::Buffer m_records;  // capacity x recordsPerPath x GUIDE_RECORD_VEC4S vec4
  std::vector<glm::vec4> m_hostRecords, m_hostRadiance;
  std::vector<guiding::PhotonSplat> m_photons;  // the pre-pass's splats until endPhotons
  bool m_keepPhotons = false;
  std::vector<guiding::IterationReport> m_reports;
  double m_seconds = 0;
  std::uint64_t m_hash = 0;
};

}  // namespace nusselt
