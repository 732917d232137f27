// The path guide's data structure (src/guiding/guide_tree.h, shaders/shared/guiding.h) on the
// CPU: the equal-area map, the density of the flattened trees (integrates to 1 over the sphere),
// their sampler against that density (chi-square), the spatial and directional refinement rules,
// the memory cap, the training records' splat arithmetic, and the selection probability learned
// per region.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>

#include "guiding/guide_tree.h"
#include "test_quadtree_chi2.h"

using namespace nusselt;
using namespace nusselt::guiding;

namespace {

glm::vec3 uniformSphere(std::mt19937& rng) {
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  float z = 2.0f * U(rng) - 1.0f;
  float phi = 6.2831853f * U(rng);
  float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// A radiance field over the sphere with a sharp lobe, a broad one and a floor (no cell is empty).
double radiance(glm::vec3 d) {
  const glm::vec3 a = glm::normalize(glm::vec3(0.3f, -0.5f, 0.8f));
  const glm::vec3 b = glm::normalize(glm::vec3(-0.7f, 0.2f, -0.3f));
  return 50.0 * std::exp(200.0 * (glm::dot(d, a) - 1.0)) + 2.0 * std::exp(4.0 * (glm::dot(d, b) - 1.0)) + 0.01;
}

// A one-leaf guide trained for `iterations` iterations on uniform directions weighted by radiance().
GuideTree trainedTree(std::uint32_t iterations, std::uint32_t maxDirDepth, std::uint32_t splatsPerIteration = 200000) {
  GuideSettings s;
  s.spatialThreshold = 1e30;  // one spatial leaf
  s.maxDirDepth = maxDirDepth;
  GuideTree t(glm::vec3(0.0f), glm::vec3(1.0f), s);
  std::mt19937 rng(7);
  for (std::uint32_t it = 0; it < iterations; ++it) {
    for (std::uint32_t i = 0; i < splatsPerIteration; ++i) {
      glm::vec3 d = uniformSphere(rng);
      t.splat(glm::vec3(0.5f), d, radiance(d) * 4.0 * M_PI);  // radiance / (uniform pdf 1 / 4 pi)
    }
    t.endIteration(it);
  }
  return t;
}

struct Flat {
  std::vector<shared::GuideSpatialNode> spatial;
  std::vector<shared::GuideDirNode> dir;
  shared::GuideHostView view;
};
Flat flatten(const GuideTree& t) {
  Flat f;
  t.flatten(f.spatial, f.dir);
  f.view.g.boundsMin = shared::vec4(t.boundsMin(), 0.0f);
  f.view.g.boundsMax = shared::vec4(t.boundsMax(), 0.0f);
  f.view.spatial = f.spatial.data();
  f.view.dir = f.dir.data();
  return f;
}

// Energy of the old tree in the cell [x0, x0 + size) x [y0, y0 + size) (uniform within its leaves).
double cellEnergy(const DirTree& t, double x0, double y0, double size) {
  std::uint32_t node = 0;
  double cx0 = 0, cy0 = 0, csize = 1;
  for (;;) {
    csize *= 0.5;
    int c = 0;
    if (x0 >= cx0 + csize) { c += 1; cx0 += csize; }
    if (y0 >= cy0 + csize) { c += 2; cy0 += csize; }
    const double e = t.nodes()[node].energy[c];
    if (csize <= size) return e;  // the cell is this tree cell
    if (t.nodes()[node].child[c] == 0) return e * (size * size) / (csize * csize);
    node = t.nodes()[node].child[c];
  }
}

}  // namespace

TEST(Guiding, MapRoundTripsAndIsEqualArea) {
  std::mt19937 rng(3);
  for (int i = 0; i < 10000; ++i) {
    glm::vec3 d = uniformSphere(rng);
    shared::vec2 p = shared::guideDirectionToSquare(d);
    ASSERT_GE(p.x, 0.0f);
    ASSERT_LT(p.x, 1.0f);
    ASSERT_GE(p.y, 0.0f);
    ASSERT_LT(p.y, 1.0f);
    shared::vec3 e = shared::guideSquareToDirection(p);
    EXPECT_LT(glm::length(e - d), 1e-5f) << i;
  }
  // Equal area: directions uniform on the sphere land uniformly in the square (chi-square over an
  // 8 x 8 grid, 64000 samples, significance 0.001).
  const int n = 8, N = 64000;
  std::vector<int> bins(n * n, 0);
  for (int i = 0; i < N; ++i) {
    shared::vec2 p = shared::guideDirectionToSquare(uniformSphere(rng));
    bins[int(p.y * n) * n + int(p.x * n)]++;
  }
  double chi2 = 0, expected = double(N) / (n * n);
  for (int b : bins) chi2 += (b - expected) * (b - expected) / expected;
  EXPECT_GT(qttest::gammaQ(0.5 * (n * n - 1), 0.5 * chi2), 0.001) << "chi2 " << chi2;
}

TEST(Guiding, PdfIntegratesToOneOverTheSphere) {
  const std::uint32_t depth = 8;
  GuideTree t = trainedTree(5, depth);
  Flat f = flatten(t);
  ASSERT_GT(t.samplingTree(0).total(), 0.0);
  ASSERT_GE(t.samplingTree(0).depth(), 4u) << "the test tree must be refined";
  ASSERT_LE(t.samplingTree(0).depth(), depth);
  const std::uint32_t root = f.spatial[0].info.y;
  // Midpoint rule on the finest cells: exact for the piecewise-constant density, in the map and
  // through directions (per steradian, 4 pi per unit of the map).
  const int n = 1 << depth;
  double sumSquare = 0, sumSphere = 0;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      shared::vec2 p((x + 0.5f) / n, (y + 0.5f) / n);
      sumSquare += shared::guideSquarePdf(f.view, root, p);
      sumSphere += shared::guideDirPdf(f.view, root, shared::guideSquareToDirection(p)) * 4.0 * M_PI;
    }
  EXPECT_NEAR(sumSquare / (double(n) * n), 1.0, 1e-4);
  EXPECT_NEAR(sumSphere / (double(n) * n), 1.0, 1e-4);
}

TEST(Guiding, SamplingMatchesPdfChiSquare) {
  const std::uint32_t depth = 8;
  GuideTree t = trainedTree(5, depth);
  Flat f = flatten(t);
  const std::uint32_t root = f.spatial[0].info.y;
  // Bins: a 64 x 64 grid of the map (finer than most leaves, coarser than the deepest: the
  // expected count of a bin integrates the density over its finest cells, exactly).
  const int g = 64, fine = 1 << depth, per = fine / g;
  std::vector<double> expected(g * g, 0.0);
  for (int y = 0; y < fine; ++y)
    for (int x = 0; x < fine; ++x)
      expected[(y / per) * g + x / per] +=
          shared::guideSquarePdf(f.view, root, shared::vec2((x + 0.5f) / fine, (y + 0.5f) / fine)) / (double(fine) * fine);
  const int N = 1000000;
  std::vector<double> observed(g * g, 0.0);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  int failed = 0;
  for (int i = 0; i < N; ++i) {
    shared::vec3 d;
    float u = std::min(U(rng), NUSSELT_ONE_MINUS_EPS);
    shared::vec2 uc(std::min(U(rng), NUSSELT_ONE_MINUS_EPS), std::min(U(rng), NUSSELT_ONE_MINUS_EPS));
    if (!shared::guideDirSample(f.view, root, u, uc, d)) {
      ++failed;
      continue;
    }
    shared::vec2 p = shared::guideDirectionToSquare(d);
    observed[int(p.y * g) * g + int(p.x * g)] += 1;
  }
  EXPECT_EQ(failed, 0);
  // Pool bins below 5 expected; significance 0.01.
  double chi2 = 0, poolE = 0, poolO = 0;
  int dof = -1;
  for (int b = 0; b < g * g; ++b) {
    const double e = expected[b] * N;
    if (e < 5) {
      poolE += e;
      poolO += observed[b];
      continue;
    }
    chi2 += (observed[b] - e) * (observed[b] - e) / e;
    ++dof;
  }
  if (poolE > 0) {
    chi2 += (poolO - poolE) * (poolO - poolE) / std::max(poolE, 1e-12);
    ++dof;
  }
  ASSERT_GT(dof, 100);
  const double pValue = qttest::gammaQ(0.5 * dof, 0.5 * chi2);
  EXPECT_GT(pValue, 0.01) << "chi2 " << chi2 << " on " << dof << " degrees of freedom";
}

TEST(Guiding, DirectionalRefinementSplitsCellsAboveRho) {
  GuideTree t = trainedTree(3, 12);
  const DirTree& old = t.samplingTree(0);  // trained; the building tree is its refinement
  const DirTree& now = t.buildingTree(0);
  const double total = old.total(), rho = t.settings().dirThreshold;
  ASSERT_GT(now.nodeCount(), 1u);
  // Every cell of the refined tree: inner cells hold more than rho of the energy, leaf cells at
  // most rho (or sit at the depth cap).
  struct Item {
    std::uint32_t node;
    double x0, y0, size;
    std::uint32_t depth;
  };
  std::vector<Item> stack{{0, 0, 0, 1, 0}};
  int leaves = 0, inner = 0;
  while (!stack.empty()) {
    Item it = stack.back();
    stack.pop_back();
    for (int c = 0; c < 4; ++c) {
      const double h = it.size / 2;
      const double x0 = it.x0 + ((c & 1) ? h : 0), y0 = it.y0 + ((c & 2) ? h : 0);
      const double share = cellEnergy(old, x0, y0, h) / total;
      const std::uint32_t child = now.nodes()[it.node].child[c];
      if (child) {
        ++inner;
        EXPECT_GT(share, rho);
        stack.push_back({child, x0, y0, h, it.depth + 1});
      } else {
        ++leaves;
        if (it.depth + 1 < 12) EXPECT_LE(share, rho) << "leaf cell at depth " << it.depth + 1;
      }
    }
  }
  EXPECT_GT(inner, 10);
  EXPECT_EQ(now.total(), 0.0);  // energies start again
}

TEST(Guiding, SpatialLeavesSplitAboveCSqrtTwoToTheIteration) {
  GuideSettings s;
  s.spatialThreshold = 100;
  // Box 4 x 2 x 1: the first split is along x, the next ones along the then longest axes.
  auto run = [&](std::uint32_t iteration, int samples) {
    GuideTree t(glm::vec3(0.0f), glm::vec3(4.0f, 2.0f, 1.0f), s);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> U(0.0f, 1.0f);
    for (int i = 0; i < samples; ++i)
      t.splat(glm::vec3(4 * U(rng), 2 * U(rng), U(rng)), glm::vec3(0, 0, 1), 1.0);
    t.endIteration(iteration);
    return t;
  };
  // 100 splats: not more than 100 sqrt(1): no split.
  EXPECT_EQ(run(0, 100).leafCount(), 1u);
  // 1000 at iteration 0: halves 500, 250, 125, 62.5: four levels of splits, 16 leaves.
  GuideTree a = run(0, 1000);
  EXPECT_EQ(a.leafCount(), 16u);
  // 1000 at iteration 2 (threshold 200): 500, 250, 125: 8 leaves.
  EXPECT_EQ(run(2, 1000).leafCount(), 8u);
  // The first split is x = 2 (the midpoint of the longest axis): points either side of it lie in
  // different leaves; the leaf finder of the GPU (guideLeafInfo) agrees with the CPU's.
  Flat f = flatten(a);
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  for (int i = 0; i < 1000; ++i) {
    glm::vec3 x(4 * U(rng), 2 * U(rng), U(rng));
    const std::uint32_t leaf = a.findLeaf(x);
    shared::uvec4 info = shared::guideLeafInfo(f.view, x);
    EXPECT_EQ(info.x, GUIDE_SPATIAL_LEAF);
    // Leaves are numbered by the flattened roots' order: compare through the leaf's root.
    std::uint32_t root = 0;
    for (std::uint32_t l = 0; l < leaf; ++l) root += std::uint32_t(a.samplingTree(l).nodeCount());
    EXPECT_EQ(info.y, root);
  }
  EXPECT_NE(a.findLeaf(glm::vec3(1.99f, 1.0f, 0.5f)), a.findLeaf(glm::vec3(2.01f, 1.0f, 0.5f)));
}

TEST(Guiding, MemoryCapIsEnforcedAndReported) {
  GuideSettings s;
  s.spatialThreshold = 200;
  s.memoryCap = 48 * 1024;  // 48 KiB: far below what these splats would build
  GuideTree t(glm::vec3(0.0f), glm::vec3(1.0f), s);
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  bool capped = false;
  for (std::uint32_t it = 0; it < 4; ++it) {
    for (int i = 0; i < 100000; ++i) {
      glm::vec3 d = uniformSphere(rng);
      t.splat(glm::vec3(U(rng), U(rng), U(rng)), d, radiance(d));
    }
    IterationReport r = t.endIteration(it);
    EXPECT_LE(r.bytes, s.memoryCap) << "iteration " << it;
    EXPECT_EQ(r.bytes, t.bytes());
    capped = capped || r.capped;
    std::vector<shared::GuideSpatialNode> sp;
    std::vector<shared::GuideDirNode> dir;
    t.flatten(sp, dir);
    EXPECT_EQ(sp.size() * sizeof(sp[0]) + dir.size() * sizeof(dir[0]), r.bytes);
  }
  EXPECT_TRUE(capped) << "the cap must have been reached for the test to mean anything";
  // The next iteration's trees fit too.
  std::uint64_t building = 0;
  for (std::uint32_t l = 0; l < t.leafCount(); ++l) building += t.buildingTree(l).nodeCount();
  EXPECT_LE(building * sizeof(shared::GuideDirNode), s.memoryCap);
}

TEST(Guiding, SplatsRadianceFromLaterInThePathOverThroughputAndPdf) {
  GuideSettings s;
  s.spatialThreshold = 1e30;
  GuideTree t(glm::vec3(0.0f), glm::vec3(1.0f), s);
  // Path 0: vertex 0 (arrival 0) sampled with luminance(beta) x pdf = 2; its NEE added 0.5, so the
  // ray arrived at vertex 1 with 0.5; vertex 1: value 4, arrival at vertex 2 with 1.0, which ended
  // the path (value 0); final radiance 1.5. Splats: (1.5 - 0.5) / 2 and (1.5 - 1.0) / 4.
  // Path 1: one sample whose ray left the scene (arrival -1): a splat of 0 (counted).
  // Path 2: a delta sample (-1) then a sample of value 1 whose next arrival is 0.25; radiance 1.
  const std::uint32_t n = 4;
  const std::uint32_t R = GUIDE_RECORD_VEC4S;
  std::vector<glm::vec4> rec(3 * n * R, glm::vec4(0.0f));
  auto set = [&](int p, int k, glm::vec4 a, glm::vec4 b) {
    rec[(p * n + k) * R] = a;
    rec[(p * n + k) * R + 1] = b;
    rec[(p * n + k) * R + 2] = glm::vec4(-1.0f, 0.0f, 0.0f, 0.0f);  // not a mixture vertex
  };
  const glm::vec4 up(0, 0, 1, 0);
  set(0, 0, {0.5f, 0.5f, 0.5f, 0.0f}, up + glm::vec4(0, 0, 0, 2.0f));
  set(0, 1, {0.5f, 0.5f, 0.5f, 0.5f}, up + glm::vec4(0, 0, 0, 4.0f));
  set(0, 2, {0.5f, 0.5f, 0.5f, 1.0f}, glm::vec4(0.0f));
  set(1, 0, {0.5f, 0.5f, 0.5f, 0.0f}, up + glm::vec4(0, 0, 0, 3.0f));
  set(1, 1, {0.0f, 0.0f, 0.0f, -1.0f}, glm::vec4(0.0f));
  set(2, 0, {0.5f, 0.5f, 0.5f, 0.0f}, up + glm::vec4(0, 0, 0, -1.0f));
  set(2, 1, {0.5f, 0.5f, 0.5f, 0.0f}, up + glm::vec4(0, 0, 0, 1.0f));
  set(2, 2, {0.5f, 0.5f, 0.5f, 0.25f}, glm::vec4(0.0f));
  std::vector<glm::vec4> L = {glm::vec4(1.5f), glm::vec4(0.0f), glm::vec4(1.0f)};
  EXPECT_EQ(splatPaths(t, rec.data(), n, L.data(), 3), 4u);
  EXPECT_NEAR(t.buildingTree(0).total(), 0.5 + 0.125 + 0.75, 1e-12);
  EXPECT_EQ(t.leafSamples(0), 4.0);
}

// The selection probability per region (GuideTree::observeSelection, learnAlphas) on a one-leaf
// guide trained on radiance() (a sharp lobe, a broad one, a floor): vertices whose "BRDF sampler"
// is uniform over the sphere (p_bsdf = 1 / 4 pi), sampled with alpha = 0 (the leaf's first alpha).
// Where the integrand is radiance(), the guide approximates it and the learned alpha must be the
// largest candidate that beats BRDF sampling; where the integrand is constant, BRDF sampling is
// exact (zero variance): every alpha > 0 adds variance and the leaf must fall back to 0.
namespace {
struct Learned {
  float alpha;
  std::array<double, kAlphaCandidates.size()> moment;  // true second moments (quadrature)
};
Learned learnedAlpha(double (*integrand)(glm::vec3), std::uint32_t vertices) {
  GuideTree t = trainedTree(5, 8);
  Flat f = flatten(t);
  const std::uint32_t root = f.spatial[0].info.y;
  const double pB = 1.0 / (4.0 * M_PI);
  // The true second moment of F / p_c per candidate: midpoint rule on 1024^2 cells of the map.
  Learned out{};
  const int fine = 1024;
  for (int y = 0; y < fine; ++y)
    for (int x = 0; x < fine; ++x) {
      const shared::vec2 p((x + 0.5f) / fine, (y + 0.5f) / fine);
      const double pG = shared::guideSquarePdf(f.view, root, p) / (4.0 * M_PI);
      const shared::vec3 d = shared::guideSquareToDirection(p);
      const double F = integrand(glm::vec3(d.x, d.y, d.z));
      for (std::size_t c = 0; c < kAlphaCandidates.size(); ++c) {
        const double pc = kAlphaCandidates[c] * pG + (1.0 - kAlphaCandidates[c]) * pB;
        out.moment[c] += F * F / pc * (4.0 * M_PI / (double(fine) * fine));
      }
    }
  std::mt19937 rng(11);
  for (std::uint32_t i = 0; i < vertices; ++i) {
    glm::vec3 d = uniformSphere(rng);
    const double pG = shared::guideDirPdf(f.view, root, shared::vec3(d.x, d.y, d.z));
    t.observeSelection(0, integrand(d) / pB, pG, pB, 0.0);
  }
  EXPECT_EQ(t.leafSelection(0).vertices, double(vertices));
  t.endIteration(5);
  EXPECT_EQ(t.leafAlphaVertices(0), double(vertices));
  out.alpha = t.leafAlpha(0);
  return out;
}
double constantRadiance(glm::vec3) { return 1.0; }
std::size_t candidateIndex(float alpha) {
  for (std::size_t c = 0; c < kAlphaCandidates.size(); ++c)
    if (kAlphaCandidates[c] == alpha) return c;
  ADD_FAILURE() << "alpha " << alpha << " is not a candidate";
  return 0;
}
}  // namespace

TEST(Guiding, LearnedAlphaPrefersAGoodGuideAndFallsBackWhereBsdfSamplingIsExact) {
  // radiance(): the guide wins; the learned alpha's true second moment is within 10 % of the best
  // candidate's (10^5 vertices, of which about 250 see the sharp lobe that dominates the moment)
  // and below BRDF sampling's.
  Learned a = learnedAlpha(&radiance, 100000);
  const double best = *std::min_element(a.moment.begin(), a.moment.end());
  std::printf("learned alpha %.2f: second moment %.4g (alpha 0: %.4g, best candidate: %.4g)\n", a.alpha,
              a.moment[candidateIndex(a.alpha)], a.moment[0], best);
  EXPECT_GT(a.alpha, 0.0f);
  EXPECT_LE(a.moment[candidateIndex(a.alpha)], 1.1 * best) << "alpha " << a.alpha;
  EXPECT_LT(best, a.moment[0]);
  // A constant integrand: BRDF sampling is exact, every alpha > 0 adds variance: alpha = 0.
  Learned b = learnedAlpha(&constantRadiance, 100000);
  EXPECT_EQ(b.alpha, 0.0f);
  EXPECT_EQ(*std::min_element(b.moment.begin(), b.moment.end()), b.moment[0]);
  // Too few vertices: the leaf keeps its alpha (0).
  GuideTree t = trainedTree(5, 8);
  for (int i = 0; i < 10; ++i) t.observeSelection(0, 1000.0, 100.0, 0.01, 0.0);
  t.endIteration(5);
  EXPECT_EQ(t.leafAlpha(0), 0.0f);
  EXPECT_EQ(t.leafAlphaVertices(0), 0.0);
}
