// film.h: the image a render accumulates into. Per pixel the device holds the sum of the samples
// (rgb) and their count (w), and the sum of their squares (rgb): the raw sums that resuming and
// merging need. One invocation owns one pixel's accumulation (no float atomics), so a film is
// bit-identical run to run.
#pragma once
#include <cstdint>

#include "io/image.h"
#include "vk/vk.h"

namespace nusselt {

namespace shared {
struct Globals;
}

class Film {
 public:
  Film(vk::Context& ctx, std::uint32_t width, std::uint32_t height);
  ~Film();
  Film(const Film&) = delete;
  Film& operator=(const Film&) = delete;

  std::uint32_t width() const { return m_width; }
  std::uint32_t height() const { return m_height; }
  std::uint64_t pixels() const { return std::uint64_t(m_width) * m_height; }
  std::uint64_t deviceBytes() const { return m_sum.size + m_sumSq.size; }
  // Device bytes a film of this size needs (checked before anything is allocated).
  static std::uint64_t bytesFor(std::uint64_t pixels) { return pixels * 32; }

  // The film's buffers and size in the globals every stage reads.
  void fillGlobals(shared::Globals& g) const;
  // All sums to zero.
  void clear();
  // The estimate: mean = sum / count per pixel, the variance of the mean when withVariance, and
  // always the raw sums (Image::sum, Image::sumSq).
  Image download(bool withVariance);
  // Continue from saved sums of `spp` samples per pixel. Throws nusselt::Error when the saved
  // image does not fit this film.
  void restore(const Image& saved, std::uint32_t spp);

  // Means (and variances of the mean, when withVariance) of image.sum / image.sumSq for `count`
  // samples in every pixel: what download() computes, for sums added up on the host (merge).
  static void resolve(Image& image, float count, bool withVariance);

 private:
  vk::Context& m_ctx;
  std::uint32_t m_width = 0, m_height = 0;
  vk::Buffer m_sum;    // vec4 per pixel: sum of samples (rgb), samples taken (w)
  vk::Buffer m_sumSq;  // vec4 per pixel: sum of squared samples (rgb)
};

}  // namespace nusselt
