// film.cpp: the film's device buffers, its download as an image and its restore.
#include "render/film.h"

#include <algorithm>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "../../shaders/shared/layout.h"
#include "util/error.h"

namespace nusselt {

Film::Film(vk::Context& ctx, std::uint32_t width, std::uint32_t height) : m_ctx(ctx), m_width(width), m_height(height) {
  m_sum = vk::createBuffer(m_ctx, pixels() * 16, 0, false, "film");
  m_sumSq = vk::createBuffer(m_ctx, pixels() * 16, 0, false, "film variance");
  clear();
}

Film::~Film() {
  vk::destroyBuffer(m_ctx, m_sum);
  vk::destroyBuffer(m_ctx, m_sumSq);
}

void Film::fillGlobals(shared::Globals& g) const {
  g.film = m_sum.address;
  g.filmSq = m_sumSq.address;
  g.width = m_width;
  g.height = m_height;
}

void Film::clear() {
  VkCommandBuffer cmd = vk::beginOneShot(m_ctx);
  vkCmdFillBuffer(cmd, m_sum.buffer, 0, VK_WHOLE_SIZE, 0);
  vkCmdFillBuffer(cmd, m_sumSq.buffer, 0, VK_WHOLE_SIZE, 0);
  vk::endOneShot(m_ctx, cmd);
}

namespace {

// Mean of n samples from their sum, and the variance of that mean from the sum of squares (the
// unbiased sample variance of one sample, divided by n). The one formula of download() and merge.
void meanAndVariance(float sum, float sumSq, float n, float& mean, float* variance) {
  mean = n > 0 ? sum / n : 0.0f;
  if (!variance) return;
  double var = n > 1 ? (double(sumSq) - double(n) * mean * mean) / (double(n) - 1.0) : 0.0;
  *variance = n > 0 ? static_cast<float>(std::max(var, 0.0) / n) : 0.0f;
}

}  // namespace

void Film::resolve(Image& img, float n, bool withVariance) {
  const std::size_t values = img.sum.size();
  img.rgb.resize(values);
  if (withVariance) img.variance.resize(values);
  for (std::size_t i = 0; i < values; ++i)
    meanAndVariance(img.sum[i], img.sumSq[i], n, img.rgb[i], withVariance ? &img.variance[i] : nullptr);
}

Image Film::download(bool withVariance) {
  const std::uint64_t n = pixels();
  std::vector<glm::vec4> sum(n), sumSq(n);
  vk::downloadBuffer(m_ctx, m_sum, sum.data(), n * 16);
  vk::downloadBuffer(m_ctx, m_sumSq, sumSq.data(), n * 16);
  Image img;
  img.width = static_cast<int>(m_width);
  img.height = static_cast<int>(m_height);
  img.rgb.resize(n * 3);
  if (withVariance) img.variance.resize(n * 3);
  img.sum.resize(n * 3);
  img.sumSq.resize(n * 3);
  for (std::uint64_t i = 0; i < n; ++i) {
    float count = sum[i].w;
    for (int c = 0; c < 3; ++c) {
      img.sum[3 * i + c] = sum[i][c];
      img.sumSq[3 * i + c] = sumSq[i][c];
      meanAndVariance(sum[i][c], sumSq[i][c], count, img.rgb[3 * i + c],
                      withVariance ? &img.variance[3 * i + c] : nullptr);
    }
  }
  return img;
}

void Film::restore(const Image& saved, std::uint32_t spp) {
  const std::uint64_t n = pixels();
  if (saved.width != int(m_width) || saved.height != int(m_height))
    throw Error("the saved image is " + std::to_string(saved.width) + "x" + std::to_string(saved.height) +
                " but this render is " + std::to_string(m_width) + "x" + std::to_string(m_height));
  if (saved.sum.size() != n * 3 || saved.sumSq.size() != n * 3)
    throw Error("the saved image has no accumulation channels (sum.R/G/B, sumSq.R/G/B)");
  std::vector<glm::vec4> sum(n), sumSq(n);
  for (std::uint64_t i = 0; i < n; ++i) {
    sum[i] = glm::vec4(saved.sum[3 * i], saved.sum[3 * i + 1], saved.sum[3 * i + 2], float(spp));
    sumSq[i] = glm::vec4(saved.sumSq[3 * i], saved.sumSq[3 * i + 1], saved.sumSq[3 * i + 2], 0.0f);
  }
  vk::uploadBuffer(m_ctx, m_sum, sum.data(), n * 16);
  vk::uploadBuffer(m_ctx, m_sumSq, sumSq.data(), n * 16);
}

}  // namespace nusselt
