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
#include <cstring>
#include <random>

#include "guiding/guide_tree.h"
#include "render/render_record.h"
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
// floor: the guide's uniform floor (applied when flattened; the trees are the same for any floor).
GuideTree trainedTree(std::uint32_t iterations, std::uint32_t maxDirDepth, std::uint32_t splatsPerIteration = 200000,
                      double floor = 0.0) {
  GuideSettings s;
  s.spatialThreshold = 1e30;  // one spatial leaf
  s.maxDirDepth = maxDirDepth;
  s.floor = floor;
  GuideTree t(glm::vec3(0.0f), glm::vec3(1.0f), s);
  std::mt19937 rng(7);
  for (std::uint32_t it = 0; it < iterations; ++it) {
    for (std::uint32_t i = 0; i < splatsPerIteration; ++i) {
      glm::vec3 d = uniformSphere(rng);
      t.splat(glm::vec3(0.5f), 0, d, radiance(d) * 4.0 * M_PI);  // radiance / (uniform pdf 1 / 4 pi)
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
  f.view.g.info.z = t.settings().orientations;
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

// Without and with the uniform floor (GuideSettings::floor: the flattened masses mix the tree's
// energy with the cells' areas).
class GuidingFloor : public ::testing::TestWithParam<double> {};
INSTANTIATE_TEST_SUITE_P(Guiding, GuidingFloor, ::testing::Values(0.0, 0.1));

TEST_P(GuidingFloor, PdfIntegratesToOneOverTheSphere) {
  const std::uint32_t depth = 8;
  GuideTree t = trainedTree(5, depth, 200000, GetParam());
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
  // With a floor f: the density is (1 - f) x the tree's without it + f at every point (up to float
  // rounding of the masses), so no direction has density 0.
  const double fl = GetParam();
  if (fl > 0) {
    GuideTree t0 = trainedTree(5, depth, 200000, 0.0);  // the same tree (same splats), no floor
    Flat f0 = flatten(t0);
    const std::uint32_t root0 = f0.spatial[0].info.y;
    double worst = 0, lowest = 1e30;
    int emptyWithoutFloor = 0;
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        shared::vec2 p((x + 0.5f) / n, (y + 0.5f) / n);
        const double p0 = shared::guideSquarePdf(f0.view, root0, p);
        const double pf = shared::guideSquarePdf(f.view, root, p);
        const double want = (1.0 - fl) * p0 + fl;
        worst = std::max(worst, std::abs(pf - want) / want);
        lowest = std::min(lowest, pf);
        emptyWithoutFloor += p0 == 0.0;
      }
    std::printf("floor %.2f: largest relative deviation from (1 - f) p + f: %.3g; lowest density %.4g; %d of %d "
                "cells empty without the floor\n", fl, worst, lowest, emptyWithoutFloor, n * n);
    EXPECT_LT(worst, 1e-4);
    EXPECT_GE(lowest, fl * (1.0 - 1e-4));
  }
}

TEST_P(GuidingFloor, SamplingMatchesPdfChiSquare) {
  const std::uint32_t depth = 8;
  GuideTree t = trainedTree(5, depth, 200000, GetParam());
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
  int failed = 0, pdfDiffers = 0;
  for (int i = 0; i < N; ++i) {
    shared::vec3 d;
    float pdf;
    float u = std::min(U(rng), NUSSELT_ONE_MINUS_EPS);
    shared::vec2 uc(std::min(U(rng), NUSSELT_ONE_MINUS_EPS), std::min(U(rng), NUSSELT_ONE_MINUS_EPS));
    if (!shared::guideDirSample(f.view, root, u, uc, d, pdf)) {
      ++failed;
      continue;
    }
    // The sample's density is its cell's: the look-up of its map point gives it bit for bit (the
    // shade stage takes it instead of a second descent).
    shared::vec2 q(0.0f);
    const float pSquare = shared::guideSquareDescend(f.view, root, true, u, uc, q);
    if (pSquare != shared::guideSquarePdf(f.view, root, q) || pdf != pSquare * NUSSELT_INV_4PI) ++pdfDiffers;
    shared::vec2 p = shared::guideDirectionToSquare(d);
    observed[int(p.y * g) * g + int(p.x * g)] += 1;
  }
  EXPECT_EQ(failed, 0);
  EXPECT_EQ(pdfDiffers, 0);
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
      t.splat(glm::vec3(4 * U(rng), 2 * U(rng), U(rng)), 0, glm::vec3(0, 0, 1), 1.0);
    t.endIteration(iteration);
    return t;
  };
  // The splats are all of orientation class 0; the other classes' roots stay one leaf each.
  const std::uint32_t others = GUIDE_ORIENTATIONS - 1;
  // 100 splats: not more than 100 sqrt(1): no split.
  EXPECT_EQ(run(0, 100).leafCount(), 1u + others);
  // 1000 at iteration 0: halves 500, 250, 125, 62.5: four levels of splits, 16 leaves.
  GuideTree a = run(0, 1000);
  EXPECT_EQ(a.leafCount(), 16u + others);
  // 1000 at iteration 2 (threshold 200): 500, 250, 125: 8 leaves.
  EXPECT_EQ(run(2, 1000).leafCount(), 8u + others);
  // The first split is x = 2 (the midpoint of the longest axis): points either side of it lie in
  // different leaves; the leaf finder of the GPU (guideLeafInfo) agrees with the CPU's.
  Flat f = flatten(a);
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  // The same for every orientation class: each has its own root, the same point of another class
  // lies in another leaf (that class's one leaf here).
  for (int i = 0; i < 1000; ++i) {
    glm::vec3 x(4 * U(rng), 2 * U(rng), U(rng));
    const std::uint32_t o = std::uint32_t(i) % GUIDE_ORIENTATIONS;
    const std::uint32_t leaf = a.findLeaf(x, o);
    EXPECT_EQ(a.leafOrientation(leaf), o);
    if (o > 0) EXPECT_EQ(leaf, o);
    shared::uvec4 info = shared::guideLeafInfo(f.view, x, o);
    EXPECT_EQ(info.x, GUIDE_SPATIAL_LEAF);
    // Leaves are numbered by the flattened roots' order: compare through the leaf's root.
    std::uint32_t root = 0;
    for (std::uint32_t l = 0; l < leaf; ++l) root += std::uint32_t(a.samplingTree(l).nodeCount());
    EXPECT_EQ(info.y, root);
  }
  EXPECT_NE(a.findLeaf(glm::vec3(1.99f, 1.0f, 0.5f), 0), a.findLeaf(glm::vec3(2.01f, 1.0f, 0.5f), 0));
  // One root for every class (settings.orientations = 1): the classes share the leaves.
  s.orientations = 1;
  GuideTree one = run(0, 1000);
  EXPECT_EQ(one.leafCount(), 16u);
  Flat f1 = flatten(one);
  for (std::uint32_t o = 0; o < GUIDE_ORIENTATIONS; ++o) {
    const glm::vec3 x(3.0f, 0.5f, 0.25f);
    EXPECT_EQ(one.findLeaf(x, o), one.findLeaf(x, 0));
    EXPECT_EQ(shared::guideLeafInfo(f1.view, x, o).y, shared::guideLeafInfo(f1.view, x, 0).y);
  }
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
      t.splat(glm::vec3(U(rng), U(rng), U(rng)), 0, d, radiance(d));
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
  auto set = [&](std::uint32_t p, std::uint32_t k, glm::vec4 a, glm::vec4 b) {
    const std::uint32_t i = shared::guideRecordIndex(p, k, 3);
    rec[i] = a;
    rec[i + 1] = b;
    rec[i + 2] = glm::vec4(-1.0f, 0.0f, 0.0f, 0.0f);  // not a mixture vertex
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

// splatPaths on several threads (each owning some leaves, applying their splats in path order)
// builds the same trees bit for bit as one thread: random paths with delta samples, ended paths,
// escaped rays, mixture vertices and a non-finite radiance, into a tree of many regions.
TEST(Guiding, ParallelSplatsGiveTheSameTreesBitForBit) {
  GuideSettings s;
  s.spatialThreshold = 200;
  s.alpha = -1.0f;  // learned: observeSelection's statistics count too
  GuideTree base(glm::vec3(0.0f), glm::vec3(1.0f), s);
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  for (int i = 0; i < 20000; ++i) {
    glm::vec3 d = uniformSphere(rng);
    base.splat(glm::vec3(U(rng), U(rng) * U(rng), U(rng)), 0, d, radiance(d));  // uneven regions
  }
  base.endIteration(0);
  ASSERT_GE(base.leafCount(), 16u);
  const std::uint32_t n = 6, R = GUIDE_RECORD_VEC4S, paths = 20000;
  std::vector<glm::vec4> rec(std::size_t(paths) * n * R, glm::vec4(0.0f)), L(paths);
  for (std::uint32_t p = 0; p < paths; ++p) {
    const std::uint32_t len = 1 + std::uint32_t(U(rng) * (n - 1));  // vertices with a sample
    float arrival = 0.0f;
    for (std::uint32_t k = 0; k <= len && k < n; ++k) {
      glm::vec4* r = &rec[shared::guideRecordIndex(p, k, paths)];
      r[0] = glm::vec4(U(rng), U(rng) * U(rng), U(rng), k == 0 ? 0.0f : (U(rng) < 0.1f ? -1.0f : arrival));
      if (k == len) break;  // the path ended here: b.w = 0
      const glm::vec3 d = uniformSphere(rng);
      const float w = U(rng) < 0.1f ? -1.0f : 0.05f + U(rng);  // -1: a delta sample
      r[1] = glm::vec4(d, w);
      r[2] = U(rng) < 0.5f ? glm::vec4(U(rng), U(rng), 0.5f, 0.0f) : glm::vec4(-1.0f, 0.0f, 0.0f, 0.0f);
      arrival += U(rng);
    }
    L[p] = glm::vec4(glm::vec3(arrival + U(rng)), 0.0f);
  }
  L[17] = glm::vec4(NAN);
  auto run = [&](unsigned threads, std::uint64_t& splats) {
    GuideTree t = base;
    splats = splatPaths(t, rec.data(), n, L.data(), paths, threads);
    return t;
  };
  std::uint64_t n1 = 0;
  GuideTree one = run(1, n1);
  EXPECT_GT(n1, paths);
  for (unsigned threads : {2u, 3u}) {
    std::uint64_t nt = 0;
    GuideTree many = run(threads, nt);
    EXPECT_EQ(nt, n1) << threads << " threads";
    for (std::uint32_t l = 0; l < one.leafCount(); ++l) {
      EXPECT_EQ(one.leafSamples(l), many.leafSamples(l)) << "leaf " << l;
      EXPECT_EQ(0, std::memcmp(&one.leafSelection(l), &many.leafSelection(l), sizeof(SelectionStats))) << "leaf " << l;
      EXPECT_EQ(one.buildingTree(l).total(), many.buildingTree(l).total()) << "leaf " << l;
    }
    const IterationReport a = one.endIteration(1), b = many.endIteration(1);
    EXPECT_EQ(a.splats, b.splats);
    std::vector<shared::GuideSpatialNode> sa, sb;
    std::vector<shared::GuideDirNode> da, db;
    one.flatten(sa, da);
    many.flatten(sb, db);
    ASSERT_EQ(sa.size(), sb.size());
    ASSERT_EQ(da.size(), db.size());
    EXPECT_EQ(0, std::memcmp(sa.data(), sb.data(), sa.size() * sizeof(sa[0]))) << threads << " threads";
    EXPECT_EQ(0, std::memcmp(da.data(), db.data(), da.size() * sizeof(da[0]))) << threads << " threads";
    one = run(1, n1);  // endIteration changed it
  }
}

// ---- Splat filtering (GuideSettings::dirFilter, spatialFilter) --------------------------------------
namespace {
// A directional tree whose leaf cells are the 4 x 4 cells of side 1/4 (depth 2).
DirTree uniformDepth2() {
  DirTree t;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) t.splat(glm::vec2((x + 0.5f) / 4, (y + 0.5f) / 4), 1.0);
  DirTree u = t.refined(0.01, 2);
  EXPECT_EQ(u.depth(), 2u);
  return u;
}
// The overlap of [a0, a1] with [b0, b1].
double overlap(double a0, double a1, double b0, double b1) { return std::max(0.0, std::min(a1, b1) - std::max(a0, b0)); }
}  // namespace

// The leave-one-out density of the learned alpha (DirTree::pdfWithout): a tree of many cell sizes
// with 300 splats, one of them taken out, has at every point the density of the same structure
// trained on the other 299 (a density computed by the same descent without taking anything out),
// for box splats (points at the poles and the phi seam among them) and point splats.
TEST(Guiding, LeaveOneOutDensityEqualsTheTreeTrainedWithoutThatSplat) {
  GuideTree trained = trainedTree(3, 12, 50000);
  const DirTree zero = trained.buildingTree(0);  // the refined structure, energies 0
  ASSERT_GT(zero.depth(), 6u);
  std::mt19937 rng(29);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  struct Splat {
    glm::vec2 q;
    double value;
  };
  std::vector<Splat> splats;
  for (int i = 0; i < 300; ++i) {
    glm::vec2 q(U(rng), U(rng));
    if (i % 5 == 1) q.x = 1e-4f * U(rng);         // at the pole u = 0
    if (i % 5 == 2) q.y = 1.0f - 1e-4f * U(rng);  // at the phi seam
    if (i % 5 == 3) q = glm::vec2(0.3f, 0.7f) + 0.01f * glm::vec2(U(rng), U(rng));  // a lobe
    splats.push_back({glm::min(q, glm::vec2(NUSSELT_ONE_MINUS_EPS)), std::exp(4.0 * U(rng))});
  }
  for (bool box : {true, false}) {
    auto train = [&](int skip) {
      DirTree t = zero;
      for (int i = 0; i < int(splats.size()); ++i)
        if (i != skip) {
          if (box) t.splatBox(splats[i].q, t.leafSide(splats[i].q), splats[i].value);
          else t.splat(splats[i].q, splats[i].value);
        }
      return t;
    };
    const DirTree all = train(-1);
    double worst = 0;
    int positive = 0, compared = 0;
    for (int j = 0; j < int(splats.size()); j += 7) {
      const DirTree without = train(j);
      const glm::vec2 q = splats[j].q;
      const double side = box ? all.leafSide(q) : 0.0;
      for (int k = 0; k < 200; ++k) {
        // Points near the splat (its own cells) and anywhere.
        glm::vec2 p = k % 2 ? glm::vec2(U(rng), U(rng)) : q + float(side + 1e-3) * glm::vec2(U(rng) - 0.5f, U(rng) - 0.5f);
        p = glm::clamp(p, glm::vec2(0.0f), glm::vec2(NUSSELT_ONE_MINUS_EPS));
        const double want = without.pdfWithout(p, p, 0.0, 0.0);
        const double got = all.pdfWithout(p, q, side, splats[j].value);
        worst = std::max(worst, std::abs(got - want) / std::max(1.0, want));
        positive += want > 0;
        ++compared;
      }
    }
    std::printf("leave-one-out (%s splats): %d points (%d with density), largest error %.3g\n", box ? "box" : "point",
                compared, positive, worst);
    EXPECT_LT(worst, 1e-9) << (box ? "box" : "point");
    EXPECT_GT(positive, compared / 4);
  }
}

// The leave-one-out scoring keeps a bounded, systematic sample of a region's vertices: with a cap
// of 100, 10000 vertices leave between 100 and 200 (every stride-th in order, the stride a power
// of two), which is what the learned alpha's count says it saw; the cap falls to
// alphaKeptTotal / regions with many regions, not below alphaKeepMin.
TEST(Guiding, LeaveOneOutKeepsABoundedSampleOfTheVertices) {
  GuideSettings s;
  s.orientations = 1;
  s.alphaKeep = 100;
  s.alphaKeptTotal = 1000;
  s.alphaKeepMin = 10;
  s.alphaMinVertices = 1;
  GuideTree t(glm::vec3(0.0f), glm::vec3(1.0f), s);
  for (int i = 0; i < 1000; ++i) t.splat(glm::vec3(0.5f), 0, glm::vec3(0, 0, 1), 1.0);
  t.endIteration(0);  // a tree with mass
  ASSERT_EQ(t.leafCount(), 1u);
  for (int i = 0; i < 10000; ++i) t.observeSelectionAt(0, glm::vec3(0, 0, 1), 1.0, 1.0, 0.1, 0.1, 0.0);
  const std::uint64_t kept = t.keptVertices();
  EXPECT_GE(kept, 100u);
  EXPECT_LT(kept, 200u);
  EXPECT_EQ(kept, (10000u + 63u) / 64u) << "every 64th of 10000 (stride doubled six times past 200)";
  for (int i = 0; i < 1000; ++i) t.splat(glm::vec3(0.5f), 0, glm::vec3(0, 0, 1), 1.0);  // the tree they score
  t.endIteration(1);
  EXPECT_EQ(t.keptVertices(), 0u);
  EXPECT_EQ(t.leafAlphaVertices(0), double(kept));
  // The cap is alphaKeptTotal / regions when that is below alphaKeep (and not below alphaKeepMin):
  // a total of 64 over this one region keeps between 64 and 128.
  s.alphaKeptTotal = 64;
  GuideTree u(glm::vec3(0.0f), glm::vec3(1.0f), s);
  for (int i = 0; i < 10000; ++i) u.observeSelectionAt(0, glm::vec3(0, 0, 1), 1.0, 1.0, 0.1, 0.1, 0.0);
  EXPECT_LT(u.keptVertices(), 2u * 64u);
  EXPECT_GE(u.keptVertices(), 64u);
}

// The box filter of a directional splat: the box of the side of the cell the point lands in,
// centred on it, shares the value among the overlapped leaf cells by area (wrapping around in phi,
// cut at u = 0 and 1 and renormalised): on the 4 x 4 tree each cell's energy is value x its
// overlap / the box's area, computed here independently; and on a refined tree of many cell sizes
// the total grows by exactly the splatted value (up to rounding), wherever the point is.
TEST(Guiding, BoxFilteredSplatSpreadsByOverlapAndConservesItsValue) {
  struct Case {
    float x, y;
    const char* what;
  };
  for (const Case& k : {Case{0.3f, 0.4f, "interior: four cells"}, Case{0.5f, 0.05f, "across phi = 0: wraps to y ~ 1"},
                        Case{0.05f, 0.6f, "at the pole u = 0: cut, renormalised"},
                        Case{0.98f, 0.99f, "the pole u = 1 and phi = 1 at once"}, Case{0.125f, 0.375f, "a cell's centre: one cell"}}) {
    DirTree t = uniformDepth2();
    const glm::vec2 p(k.x, k.y);
    const double side = t.leafSide(p);
    EXPECT_EQ(side, 0.25) << k.what;
    t.splatBox(p, side, 3.0);
    // Expected: the box clipped in x to [0, 1], wrapped in y (three periods cover the wrap).
    const double bx0 = std::max(0.0, k.x - 0.125), bx1 = std::min(1.0, k.x + 0.125);
    const double area = (bx1 - bx0) * 0.25;
    int touched = 0;
    for (int cy = 0; cy < 4; ++cy)
      for (int cx = 0; cx < 4; ++cx) {
        const double ox = overlap(bx0, bx1, cx / 4.0, (cx + 1) / 4.0);
        double oy = 0;
        for (int w = -1; w <= 1; ++w) oy += overlap(k.y - 0.125, k.y + 0.125, cy / 4.0 + w, (cy + 1) / 4.0 + w);
        const double want = 3.0 * ox * oy / area;
        const double got = cellEnergy(t, cx / 4.0, cy / 4.0, 0.25);
        EXPECT_NEAR(got, want, 1e-12) << k.what << ": cell " << cx << ", " << cy;
        touched += got > 0;
      }
    EXPECT_NEAR(t.total(), 3.0, 1e-12) << k.what;
    std::printf("%s: %d cells\n", k.what, touched);
  }
  // Conservation on a tree of many cell sizes (the trained lobes' tree, depth up to 12), at
  // random points including the seams: each splat adds its value to the total.
  GuideTree trained = trainedTree(3, 12, 50000);
  const DirTree zero = trained.buildingTree(0);  // the refined structure, energies 0
  DirTree t = zero;
  ASSERT_GT(t.depth(), 6u);
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  double sum = 0, worst = 0;
  std::uint32_t spread = 0;
  for (int i = 0; i < 20000; ++i) {
    glm::vec2 p(U(rng), U(rng));
    if (i % 4 == 1) p.x = 1e-4f * U(rng);                  // at the pole u = 0
    if (i % 4 == 2) p.y = 1.0f - 1e-4f * U(rng);           // at the phi seam
    p = glm::min(p, glm::vec2(NUSSELT_ONE_MINUS_EPS));
    const double v = std::exp(8.0 * U(rng));
    t.splatBox(p, t.leafSide(p), v);
    sum += v;
    if (i < 2000) {  // one splat alone in the empty tree: its total is the value
      DirTree z = zero;
      z.splatBox(p, z.leafSide(p), v);
      worst = std::max(worst, std::abs(z.total() - v) / v);
    }
    DirTree one = uniformDepth2();
    one.splatBox(p, 0.25, 1.0);
    spread += cellEnergy(one, std::floor(p.x * 4) / 4, std::floor(p.y * 4) / 4, 0.25) < 1.0 - 1e-12;
  }
  std::printf("box splats: largest relative error of one splat's total %.3g (2000 splats), of 20000 splats' %.3g; "
              "%u of 20000 shared with a neighbouring cell\n", worst, std::abs(t.total() - sum) / sum, spread);
  EXPECT_LT(worst, 1e-12);
  EXPECT_NEAR(t.total(), sum, 1e-12 * sum);
  // A box the size of its cell leaves its own cell's share (1 - |dx|)(1 - |dy|) of it: almost every
  // random point shares with a neighbour.
  EXPECT_GT(spread, 19000u);
}

// The spatial filter: a splat shared among the regions a box of its region's size around the
// vertex overlaps, by the overlapped volume over the box's (clipped to the root box), each share
// in that region's directional tree; the splat count stays with the vertex's region, and the
// splat with the regions of its orientation class. Regions of the split rule's test (16 leaves of
// a 4 x 2 x 1 box in class 0, one leaf for each other class).
TEST(Guiding, SpatialFilterSharesASplatAmongRegionsByOverlappedVolume) {
  GuideSettings s;
  s.spatialThreshold = 100;
  s.spatialFilter = true;
  GuideTree t(glm::vec3(0.0f), glm::vec3(4.0f, 2.0f, 1.0f), s);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  for (int i = 0; i < 1000; ++i) t.splat(glm::vec3(4 * U(rng), 2 * U(rng), U(rng)), 0, glm::vec3(0, 0, 1), 1.0);
  t.endIteration(0);
  ASSERT_EQ(t.leafCount(), 16u + GUIDE_ORIENTATIONS - 1);
  // Near inner boundaries (shared), and at the root box's corner (the box cut there: its own
  // region only, the whole value kept).
  for (glm::vec3 x : {glm::vec3(1.9f, 0.55f, 0.45f), glm::vec3(3.0f, 1.5f, 0.8f), glm::vec3(0.01f, 0.01f, 0.01f)}) {
    GuideTree u = t;
    const std::uint32_t home = u.findLeaf(x, 0);
    u.splat(x, 0, glm::vec3(0, 0, 1), 2.0);
    glm::vec3 hlo, hhi;
    u.leafBounds(home, hlo, hhi);
    const glm::dvec3 half = 0.5 * (glm::dvec3(hhi) - glm::dvec3(hlo));
    const glm::dvec3 blo = glm::max(glm::dvec3(x) - half, glm::dvec3(u.boundsMin()));
    const glm::dvec3 bhi = glm::min(glm::dvec3(x) + half, glm::dvec3(u.boundsMax()));
    const double volume = (bhi.x - blo.x) * (bhi.y - blo.y) * (bhi.z - blo.z);
    double total = 0;
    int shared = 0;
    for (std::uint32_t l = 0; l < u.leafCount(); ++l) {
      glm::vec3 lo, hi;
      u.leafBounds(l, lo, hi);
      double v = u.leafOrientation(l) == 0 ? 1 : 0;  // other classes' regions get nothing
      for (int a = 0; a < 3; ++a) v *= overlap(blo[a], bhi[a], lo[a], hi[a]);
      const double got = u.buildingTree(l).total();
      EXPECT_NEAR(got, 2.0 * v / volume, 1e-12) << "leaf " << l;
      total += got;
      shared += got > 0;
      EXPECT_EQ(u.leafSamples(l), l == home ? 1.0 : 0.0);
    }
    EXPECT_NEAR(total, 2.0, 1e-12);
    std::printf("vertex (%.2f, %.2f, %.2f): shared among %d regions\n", x.x, x.y, x.z, shared);
    EXPECT_GE(shared, x.x < 1.0f ? 1 : 2);
  }
  // Without the filter the whole splat stays in the vertex's region.
  s.spatialFilter = false;
  GuideTree v(glm::vec3(0.0f), glm::vec3(4.0f, 2.0f, 1.0f), s);
  std::mt19937 rng2(5);
  for (int i = 0; i < 1000; ++i) v.splat(glm::vec3(4 * U(rng2), 2 * U(rng2), U(rng2)), 0, glm::vec3(0, 0, 1), 1.0);
  v.endIteration(0);
  const glm::vec3 x(1.9f, 0.55f, 0.45f);
  v.splat(x, 0, glm::vec3(0, 0, 1), 2.0);
  EXPECT_NEAR(v.buildingTree(v.findLeaf(x, 0)).total(), 2.0, 1e-12);
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

// The filter, floor and learning target settings in the EXR header (render_record.cpp): written
// for guided renders, read back as written; a guided header written before they existed reads as
// unfiltered splats without floor, trained on radiance (the behaviour of those files).
TEST(Guiding, FilterSettingsRoundTripThroughTheRecord) {
  RenderRecord r;
  r.scene = "scene.gltf";
  r.spp = 4;
  r.settings.guiding = true;
  r.settings.guideDirFilter = false;
  r.settings.guideSpatialFilter = true;
  r.settings.guideFloor = 0.05;
  r.settings.guideProduct = false;
  ImageMetadata meta = makeMetadata(r);
  RenderRecord back = readRecord("test.exr", meta);
  EXPECT_TRUE(back.settings.guiding);
  EXPECT_FALSE(back.settings.guideDirFilter);
  EXPECT_TRUE(back.settings.guideSpatialFilter);
  EXPECT_EQ(back.settings.guideFloor, 0.05);
  EXPECT_FALSE(back.settings.guideProduct);
  r.settings.guideDirFilter = true;
  r.settings.guideSpatialFilter = false;
  r.settings.guideFloor = 0;
  r.settings.guideProduct = true;
  back = readRecord("test.exr", makeMetadata(r));
  EXPECT_TRUE(back.settings.guideDirFilter);
  EXPECT_FALSE(back.settings.guideSpatialFilter);
  EXPECT_TRUE(back.settings.guideProduct);
  // An older guided header: the keys absent.
  auto drop = [](auto& v) {
    v.erase(std::remove_if(v.begin(), v.end(),
                           [](const auto& kv) {
                             return kv.first == "nusselt/guideFilter" || kv.first == "nusselt/guideSpatialFilter" ||
                                    kv.first == "nusselt/guideFloor" || kv.first == "nusselt/guideLearn";
                           }),
            v.end());
  };
  drop(meta.strings);
  drop(meta.doubles);
  back = readRecord("old.exr", meta);
  EXPECT_TRUE(back.settings.guiding);
  EXPECT_FALSE(back.settings.guideDirFilter);
  EXPECT_FALSE(back.settings.guideSpatialFilter);
  EXPECT_EQ(back.settings.guideFloor, 0.0);
  EXPECT_FALSE(back.settings.guideProduct);
}
