// render_loop.cpp: passes, stop conditions, checkpoints, progress and the record of a render.
#include "render/render_loop.h"

#include <csignal>
#include <cstdio>

#include "render/guide.h"
#include "render/mlt_integrator.h"
#include "util/error.h"
#include "util/progress.h"
#include "util/stop_signal.h"

namespace nusselt {

namespace {

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

RenderLoop::RenderLoop(Renderer& renderer, RenderRecord base, const RenderRecord& previous, RenderLoopOptions options)
    : m_renderer(renderer), m_base(std::move(base)), m_previous(previous), m_options(std::move(options)) {
  m_start = m_lastCheckpoint = std::chrono::steady_clock::now();
  // The record names the traversal that ran (the renderer resolved auto).
  m_base.settings.traversal = m_renderer.settings().traversal;
  m_base.settings.guideTrainPass = m_renderer.settings().guideTrainPass;  // resolved by the renderer too
  if (m_options.progress) {
    const RenderSettings& s = m_renderer.settings();
    // Paths per spp: one per pixel, or the mutations of an iteration for Metropolis (chains x
    // steps; docs/mlt.md).
    const std::uint64_t paths = m_renderer.mlt() ? std::uint64_t(m_renderer.mlt()->report().chains) * s.mltSteps
                                                 : std::uint64_t(s.width) * s.height;
    m_progress = std::make_unique<Progress>("render", m_options.spp, paths, false, m_options.quiet);
    m_progress->update(m_renderer.samplesDone());
  }
}

RenderLoop::~RenderLoop() = default;

double RenderLoop::seconds() const { return secondsSince(m_start); }

bool RenderLoop::interrupted() const { return g_stopSignal != 0; }

bool RenderLoop::step() {
  if (m_renderer.samplesDone() >= m_options.spp || g_stopSignal != 0) return false;
  if (m_options.timeBudget > 0 && seconds() >= m_options.timeBudget) return false;
  if (m_options.trainingWithinBudget && m_options.timeBudget > 0) planTraining();
  try {
    m_renderer.renderPass(m_options.spp - m_renderer.samplesDone());
  } catch (const Error& e) {
    // The device was lost or ran out of memory mid-render: its film cannot be read any more.
    const std::string saved =
        m_checkpointSpp > 0 ? "; the last checkpoint (" + std::to_string(m_checkpointSpp) + " spp) is in " +
                                  m_options.output + ": continue with --resume " + m_options.output
        : m_previous.spp > 0 ? "; the resumed file still holds its " + std::to_string(m_previous.spp) + " spp"
                             : "; no checkpoint had been written yet (see --checkpoint)";
    throw Error(std::string(e.what()) + " after " + std::to_string(m_renderer.samplesDone()) + " spp" + saved);
  }
  if (m_progress) m_progress->update(m_renderer.samplesDone());
  // A periodic checkpoint: the output file always holds a resumable image, so a crash, a power
  // cut or a lost device loses at most one interval of work.
  if (m_options.checkpointSeconds > 0 && !m_options.output.empty() && m_renderer.samplesDone() < m_options.spp &&
      secondsSince(m_lastCheckpoint) >= m_options.checkpointSeconds) {
    write(m_options.output, true);
    m_checkpointSpp = m_renderer.samplesDone();
    m_lastCheckpoint = std::chrono::steady_clock::now();
  }
  return true;
}

// At the end of each training iteration k (2^(k+1) - 1 spp trained), iteration k + 1 would trace
// twice its samples, in about twice its time t: it runs if it would still leave twice that time,
// 4t, for rendering with its guide (now + 2t + 4t within the budget); otherwise the training ends
// and the rest of the budget samples iteration k's guide without recording. So the training takes
// at most about a third of the budget (measured against a half: docs/guiding.md, "How much
// training"). Iterations 0 and 1 always run: the first pass's time includes the pipelines'
// compilation at their first dispatch (lavapipe) and the photon pre-pass.
void RenderLoop::planTraining() {
  const std::uint32_t trained = m_renderer.guideTrainedSpp();
  if (trained == m_iterationEndSpp || !guideIterationEnds(trained)) return;  // mid-iteration, or seen
  if (trained >= guideTrainingSpp(m_renderer.settings())) return;              // the training is over
  const double now = seconds(), last = now - m_iterationEndSeconds;
  m_iterationEndSpp = trained;
  m_iterationEndSeconds = now;
  if (trained < 3) return;
  if (now + 6.0 * last > m_options.timeBudget && m_renderer.endTraining()) m_trainingEndedAt = trained;
}

void RenderLoop::run() {
  while (step()) {
  }
  if (!m_progress) return;
  const double sec = seconds();
  const RenderStats st = m_renderer.stats();
  char extra[64];
  std::snprintf(extra, sizeof extra, "%.2f Mrays/s",
                (st.rays + st.shadowRays - m_previous.stats.rays - m_previous.stats.shadowRays) / 1e6 /
                    std::max(1e-9, sec));
  m_progress->finish(extra);
}

RenderRecord RenderLoop::record(bool checkpoint) const {
  RenderRecord r = m_base;
  r.spp = m_renderer.samplesDone();
  r.interrupted = g_stopSignal != 0;
  r.checkpoint = checkpoint;
  r.stats = m_renderer.stats();
  r.renderSeconds = m_previous.renderSeconds + seconds();
  r.totalSeconds = m_previous.totalSeconds + secondsSince(m_start) + m_base.totalSeconds;
  r.timeBudget = m_options.timeBudget;
  r.settings.guideTrainSpp = m_renderer.settings().guideTrainSpp;  // planTraining may have ended it early
  if (const DeviceGuide* guide = m_renderer.guide()) r.guideHash = guide->hashText();
  return r;
}

void RenderLoop::write(const std::string& path, bool checkpoint, const std::string& png, float exposure) {
  Image img = m_renderer.image(m_options.variance);
  writeExr(path, img, makeMetadata(record(checkpoint)));
  if (!png.empty()) writePng(png, img, exposure);
}

}  // namespace nusselt
