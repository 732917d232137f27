// test_pipeline_store.cpp: a context keeps its compute pipelines (ContextOptions::reusePipelines,
// vk::PipelineStore) and hands the same one out for the same stage and specialization; without the
// option every request builds its own; a renderer built again on kept pipelines renders the same
// bits as one built on fresh pipelines in a context that keeps none.
#include <gtest/gtest.h>

#include <cstring>

#include "../support/test_support.h"
#include "render/renderer.h"
#include "../../shaders/shared/layout.h"

using namespace nusselt;

namespace {

// A Globals binding (the layout every stage uses) over a small buffer.
struct Binding {
  vk::Context& ctx;
  vk::Buffer buffer;
  vk::GlobalsBinding binding;
  explicit Binding(vk::Context& c) : ctx(c) {
    buffer = vk::createBuffer(ctx, 256, 0, true, "test globals");
    binding = vk::createGlobalsBinding(ctx, buffer.buffer, STAGE_PUSH_BYTES);
  }
  ~Binding() {
    vk::destroyGlobalsBinding(ctx, binding);
    vk::destroyBuffer(ctx, buffer);
  }
};

RenderSettings smallSettings() {
  RenderSettings s;
  s.width = s.height = 16;
  s.spp = 4;
  s.maxDepth = 5;
  s.seed = 7;
  return s;
}

Image renderIn(vk::Context& ctx, const Scene& scene, const RenderSettings& s) {
  Renderer r(ctx, scene, s);
  r.render(s.spp);
  return r.image(true);
}

}  // namespace

TEST(PipelineStore, TheSameStageAndSpecializationIsBuiltOnce) {
  vk::Context& ctx = test::context();
  ASSERT_TRUE(ctx.pipelineStore.enabled);
  Binding b(ctx);
  const std::uint64_t created = ctx.pipelineStore.created, reused = ctx.pipelineStore.reused;
  // sample_tool with specialization constants no other test of this binary asks for (model 0,
  // strategy 1 with binned sampling on: the binned mode is a gltf_pbr mode), so the first request
  // builds.
  const std::vector<std::uint32_t> specA{0u, 1u, 1u}, specB{0u, 2u, 1u};
  vk::ComputePipeline a = vk::createComputePipeline(ctx, b.binding.layout, "sample_tool", specA);
  EXPECT_TRUE(a.kept);
  EXPECT_EQ(ctx.pipelineStore.created, created + 1);
  vk::destroyComputePipeline(ctx, a);  // the context's: left alive
  vk::ComputePipeline a2 = vk::createComputePipeline(ctx, b.binding.layout, "sample_tool", specA);
  EXPECT_EQ(ctx.pipelineStore.created, created + 1);
  EXPECT_EQ(ctx.pipelineStore.reused, reused + 1);
  vk::ComputePipeline other = vk::createComputePipeline(ctx, b.binding.layout, "sample_tool", specB);
  EXPECT_EQ(ctx.pipelineStore.created, created + 2);
  EXPECT_NE(other.pipeline, a2.pipeline);
  // A second binding with the same push-constant size shares the layout, so its pipelines too.
  Binding b2(ctx);
  EXPECT_EQ(b2.binding.layout, b.binding.layout);
  vk::ComputePipeline a3 = vk::createComputePipeline(ctx, b2.binding.layout, "sample_tool", specA);
  EXPECT_EQ(a3.pipeline, a2.pipeline);
  EXPECT_EQ(ctx.pipelineStore.reused, reused + 2);
  vk::destroyComputePipeline(ctx, a2);
  vk::destroyComputePipeline(ctx, other);
  vk::destroyComputePipeline(ctx, a3);
  EXPECT_EQ(test::validationMessages(), 0u);
}

TEST(PipelineStore, OffBuildsEveryRequest) {
  vk::Context ctx;
  vk::ContextOptions o;
  o.validation = test::context().validation;
  o.reusePipelines = false;
  vk::createContext(ctx, o);
  {
    Binding b(ctx);
    Binding b2(ctx);
    EXPECT_NE(b.binding.layout, b2.binding.layout);
    vk::ComputePipeline a = vk::createComputePipeline(ctx, b.binding.layout, "accumulate");
    vk::ComputePipeline a2 = vk::createComputePipeline(ctx, b.binding.layout, "accumulate");
    EXPECT_FALSE(a.kept);
    EXPECT_NE(a.pipeline, a2.pipeline);
    EXPECT_EQ(ctx.pipelineStore.created + ctx.pipelineStore.reused, 0u);
    vk::destroyComputePipeline(ctx, a);
    vk::destroyComputePipeline(ctx, a2);
  }
  EXPECT_EQ(ctx.validationMessages.load(), 0u);
  vk::destroyContext(ctx);
}

// The default scene and the combined-material scene (its pipeline is the slowest to build), each
// rendered twice in a context that keeps pipelines (the second renderer gets every pipeline from
// the store) and once in a context that keeps none: the three images are bit-identical. (One
// context at a time: volk holds one device's functions.)
TEST(PipelineStore, KeptPipelinesRenderTheSameBits) {
  const std::vector<std::string> paths{"", "scenes/tests/combined.gltf"};
  auto sceneOf = [](const std::string& path) { return path.empty() ? test::defaultScene() : test::loadTestScene(path); };
  const RenderSettings s = smallSettings();
  vk::ContextOptions o;
  o.validation = test::context().validation;
  std::vector<Image> own;
  {
    vk::Context fresh;
    o.reusePipelines = false;
    vk::createContext(fresh, o);
    for (const std::string& path : paths) own.push_back(renderIn(fresh, sceneOf(path), s));
    EXPECT_EQ(fresh.pipelineStore.created + fresh.pipelineStore.reused, 0u);
    EXPECT_EQ(fresh.validationMessages.load(), 0u);
    vk::destroyContext(fresh);
  }
  vk::Context keeping;
  o.reusePipelines = true;
  vk::createContext(keeping, o);
  for (std::size_t i = 0; i < paths.size(); ++i) {
    Scene scene = sceneOf(paths[i]);
    Image first = renderIn(keeping, scene, s);
    const std::uint64_t created = keeping.pipelineStore.created, reused = keeping.pipelineStore.reused;
    Image second = renderIn(keeping, scene, s);
    EXPECT_EQ(keeping.pipelineStore.created, created) << paths[i] << ": the second renderer built pipelines";
    EXPECT_GT(keeping.pipelineStore.reused, reused) << paths[i];
    ASSERT_EQ(first.rgb.size(), own[i].rgb.size());
    EXPECT_EQ(std::memcmp(first.rgb.data(), second.rgb.data(), first.rgb.size() * sizeof(float)), 0) << paths[i];
    EXPECT_EQ(std::memcmp(first.rgb.data(), own[i].rgb.data(), first.rgb.size() * sizeof(float)), 0) << paths[i];
  }
  EXPECT_EQ(keeping.validationMessages.load(), 0u);
  vk::destroyContext(keeping);
}
