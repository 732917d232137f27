// render_loop.h: the one loop that drives a Renderer for `render` and `preview`: sample passes up
// to a target spp or a time budget, stop signals (SIGINT, SIGTERM: stop after the pass under way),
// periodic checkpoints to the output file, progress, and the EXR record of what was rendered
// (render_record.h). A device lost mid-render becomes an error that says where the last
// checkpoint is.
#pragma once
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "render/render_record.h"
#include "render/renderer.h"

namespace nusselt {

class Progress;

struct RenderLoopOptions {
  std::uint32_t spp = 64;        // stop at this many samples per pixel in all (a resumed render's included)
  double timeBudget = 0;         // seconds of sampling; stop at the first pass boundary after it (0: none)
  double checkpointSeconds = 0;  // rewrite `output` every this many seconds (0: never)
  std::string output;            // the render's EXR (checkpoints and the final image)
  bool variance = false;         // write the variance of the mean (var.R/G/B)
  bool quiet = false;
  bool progress = true;          // a progress bar on a terminal, a summary line otherwise
  // Guided renders with a time budget: end the guide's training at the end of an iteration when the
  // next one (twice its samples) would leave less than twice its own time for rendering with its guide
  // (docs/guiding.md, "Training within a time budget"). Off when the training spp were asked for
  // (--guide-train) or come from a resumed render's record.
  bool trainingWithinBudget = false;
};

class RenderLoop {
 public:
  // `base`: the record's fixed part (scene, device, models, source, settings, camera); `previous`:
  // the record of the render this one resumes (spp 0 when it starts afresh), whose times and
  // counters carry on.
  RenderLoop(Renderer& renderer, RenderRecord base, const RenderRecord& previous, RenderLoopOptions options);
  ~RenderLoop();
  RenderLoop(const RenderLoop&) = delete;
  RenderLoop& operator=(const RenderLoop&) = delete;

  // One sample pass, unless the loop is over: returns false once the target spp is reached, the
  // time budget is spent or a stop signal arrived (then nothing was rendered). Writes a checkpoint
  // when one is due. Throws nusselt::Error when a pass fails, saying what is saved where.
  bool step();
  // step() until it returns false; then the progress summary.
  void run();
  bool interrupted() const;

  // The record of the image as it stands.
  RenderRecord record(bool checkpoint) const;
  // Writes the image as it stands (with its record) to `path`; PNG too when png is not empty.
  void write(const std::string& path, bool checkpoint = false, const std::string& png = "", float exposure = 0.0f);
  // Seconds of sampling so far (this run; the previous render's are in the record).
  double seconds() const;
  // The preview's display exposure, recorded with its saves.
  void setDisplayExposure(double stops) { m_base.displayExposure = stops; }
  // The training spp the time budget ended the guide's training at (0: it did not).
  std::uint32_t trainingEndedAt() const { return m_trainingEndedAt; }

 private:
  Renderer& m_renderer;
  RenderRecord m_base;
  RenderRecord m_previous;
  RenderLoopOptions m_options;
  std::unique_ptr<Progress> m_progress;
  std::chrono::steady_clock::time_point m_start;
  std::chrono::steady_clock::time_point m_lastCheckpoint;
  std::uint32_t m_checkpointSpp = 0;
  // trainingWithinBudget: the training spp at the end of the last iteration seen, when it ended (s).
  void planTraining();
  std::uint32_t m_iterationEndSpp = 0;
  double m_iterationEndSeconds = 0;
  std::uint32_t m_trainingEndedAt = 0;
};

}  // namespace nusselt
