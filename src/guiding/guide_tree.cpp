// guide_tree.cpp: training, refinement and flattening of the path guide (guide_tree.h).
#include "guiding/guide_tree.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace nusselt::guiding {

namespace {
constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
}

// ---- Directional quadtree -------------------------------------------------------------------------

void DirTree::splat(glm::vec2 p, double value) {
  // The same cell geometry as guideSquarePdf (dyadic, exact in floats).
  std::uint32_t node = 0;
  float x0 = 0.0f, y0 = 0.0f, size = 1.0f;
  for (std::uint32_t d = 0; d <= GUIDE_MAX_DIR_DEPTH; ++d) {
    size *= 0.5f;
    std::uint32_t c = 0;
    if (p.x >= x0 + size) {
      c += 1;
      x0 += size;
    }
    if (p.y >= y0 + size) {
      c += 2;
      y0 += size;
    }
    m_nodes[node].energy[c] += value;
    if (m_nodes[node].child[c] == 0) return;
    node = m_nodes[node].child[c];
  }
}

double DirTree::total() const {
  const Node& r = m_nodes[0];
  return r.energy[0] + r.energy[1] + r.energy[2] + r.energy[3];
}

DirTree DirTree::refined(double threshold, std::uint32_t maxDepth) const {
  DirTree out;
  const double total = this->total();
  if (!(total > 0)) return out;
  struct Item {
    std::uint32_t oldNode;  // kNone: the cell was a leaf here (energy spread uniformly)
    std::array<double, 4> share;
    std::uint32_t newNode;
    std::uint32_t depth;  // depth of the item's child cells
  };
  std::vector<Item> stack;
  Item root{0, {}, 0, 1};
  for (int c = 0; c < 4; ++c) root.share[c] = m_nodes[0].energy[c] / total;
  stack.push_back(root);
  while (!stack.empty()) {
    Item it = stack.back();
    stack.pop_back();
    for (int c = 0; c < 4; ++c) {
      const double s = it.share[c];
      if (!(s > threshold) || it.depth >= maxDepth) continue;
      const std::uint32_t nn = static_cast<std::uint32_t>(out.m_nodes.size());
      out.m_nodes.push_back(Node{});
      out.m_nodes[it.newNode].child[c] = nn;
      Item child{kNone, {}, nn, it.depth + 1};
      const std::uint32_t oc = it.oldNode == kNone ? 0 : m_nodes[it.oldNode].child[c];
      if (oc != 0) {
        child.oldNode = oc;
        for (int k = 0; k < 4; ++k) child.share[k] = m_nodes[oc].energy[k] / total;
      } else {
        for (int k = 0; k < 4; ++k) child.share[k] = s / 4;
      }
      stack.push_back(child);
    }
  }
  return out;
}

std::uint32_t DirTree::depth() const {
  std::uint32_t deepest = 1;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> stack{{0, 1}};
  while (!stack.empty()) {
    auto [n, d] = stack.back();
    stack.pop_back();
    deepest = std::max(deepest, d);
    for (int c = 0; c < 4; ++c)
      if (m_nodes[n].child[c] != 0) stack.push_back({m_nodes[n].child[c], d + 1});
  }
  return deepest;
}

// ---- Spatial tree ----------------------------------------------------------------------------------

GuideTree::GuideTree(glm::vec3 lo, glm::vec3 hi, const GuideSettings& settings) : m_settings(settings) {
  // Padded by 1e-3 of the largest side: no box is degenerate (a flat scene gets a thin slab)
  // and points on the scene's boundary are inside.
  const glm::vec3 ext = hi - lo;
  const float pad = 1e-3f * std::max({ext.x, ext.y, ext.z, 1e-6f});
  lo -= glm::vec3(pad);
  hi += glm::vec3(pad);
  m_lo = lo;
  m_hi = hi;
  SpatialNode root;
  root.lo = lo;
  root.hi = hi;
  m_nodes.push_back(root);
  m_leaves.push_back(Leaf{});
}

std::uint32_t GuideTree::findLeaf(glm::vec3 x) const {
  glm::vec3 lo = m_lo, hi = m_hi;
  std::uint32_t node = 0;
  for (std::uint32_t d = 0; d < GUIDE_MAX_SPATIAL_DEPTH; ++d) {
    const SpatialNode& n = m_nodes[node];
    if (n.axis == GUIDE_SPATIAL_LEAF) return n.leaf;
    const std::uint32_t a = n.axis;
    const float mid = 0.5f * (lo[a] + hi[a]);
    if (x[a] < mid) {
      hi[a] = mid;
      node = n.child;
    } else {
      lo[a] = mid;
      node = n.child + 1;
    }
  }
  return m_nodes[node].leaf;  // not reached: the builder stays below the bound
}

void GuideTree::splat(glm::vec3 x, glm::vec3 d, double value) {
  Leaf& leaf = m_leaves[findLeaf(x)];
  leaf.samples += 1;
  ++m_splats;
  if (value > 0 && std::isfinite(value)) {
    shared::vec2 p = shared::guideDirectionToSquare(shared::vec3(d.x, d.y, d.z));
    leaf.building.splat(glm::vec2(p.x, p.y), value);
  }
}

std::uint64_t GuideTree::bytesOf(std::size_t spatialNodes, std::uint64_t dirNodes) const {
  return std::uint64_t(spatialNodes) * sizeof(shared::GuideSpatialNode) + dirNodes * sizeof(shared::GuideDirNode);
}

std::uint64_t GuideTree::bytes() const {
  std::uint64_t dir = 0;
  for (const Leaf& l : m_leaves) dir += l.sampling.nodeCount();
  return bytesOf(m_nodes.size(), dir);
}

IterationReport GuideTree::endIteration(std::uint32_t iteration) {
  IterationReport rep;
  rep.iteration = iteration;
  rep.splats = m_splats;
  m_splats = 0;

  // 1. The iteration's trees become the ones sampled.
  for (Leaf& l : m_leaves) l.sampling = l.building;

  // 2. Spatial refinement: split leaves with too many splats (in node order, children after
  //    their parent, so a split leaf is looked at again), within the memory cap.
  std::uint64_t dirNodes = 0;
  for (const Leaf& l : m_leaves) dirNodes += l.sampling.nodeCount();
  const double threshold = m_settings.spatialThreshold * std::sqrt(std::pow(2.0, double(iteration)));
  for (std::size_t i = 0; i < m_nodes.size(); ++i) {
    if (m_nodes[i].axis != GUIDE_SPATIAL_LEAF) continue;
    const std::uint32_t li = m_nodes[i].leaf;
    if (!(m_leaves[li].samples > threshold) || m_nodes[i].depth >= m_settings.maxSpatialDepth) continue;
    const std::uint64_t more = bytesOf(m_nodes.size() + 2, dirNodes + m_leaves[li].sampling.nodeCount());
    if (more > m_settings.memoryCap) {
      rep.capped = true;
      continue;
    }
    const glm::vec3 lo = m_nodes[i].lo, hi = m_nodes[i].hi;
    const glm::vec3 ext = hi - lo;
    std::uint32_t axis = 0;
    if (ext.y > ext[axis]) axis = 1;
    if (ext.z > ext[axis]) axis = 2;
    const float mid = 0.5f * (lo[axis] + hi[axis]);
    const std::uint32_t first = static_cast<std::uint32_t>(m_nodes.size());
    Leaf half = m_leaves[li];
    half.samples *= 0.5;
    m_leaves[li].samples *= 0.5;
    const std::uint32_t li2 = static_cast<std::uint32_t>(m_leaves.size());
    m_leaves.push_back(half);
    dirNodes += half.sampling.nodeCount();
    SpatialNode a, b;
    a.leaf = li;
    b.leaf = li2;
    a.depth = b.depth = m_nodes[i].depth + 1;
    a.lo = b.lo = lo;
    a.hi = b.hi = hi;
    a.hi[axis] = mid;
    b.lo[axis] = mid;
    m_nodes[i].axis = axis;
    m_nodes[i].child = first;
    m_nodes.push_back(a);
    m_nodes.push_back(b);
  }

  // 3. Directional refinement by energy; rho doubles until the trees fit the cap.
  double rho = m_settings.dirThreshold;
  std::vector<DirTree> next(m_leaves.size());
  for (int attempt = 0; attempt < 64; ++attempt) {
    std::uint64_t nodes = 0;
    for (std::size_t l = 0; l < m_leaves.size(); ++l) {
      next[l] = m_leaves[l].sampling.refined(rho, m_settings.maxDirDepth);
      nodes += next[l].nodeCount();
    }
    if (bytesOf(m_nodes.size(), nodes) <= m_settings.memoryCap) break;
    rep.capped = true;
    rho *= 2;
  }
  for (std::size_t l = 0; l < m_leaves.size(); ++l) {
    m_leaves[l].building = std::move(next[l]);
    m_leaves[l].samples = 0;
  }

  rep.leaves = leafCount();
  for (const Leaf& l : m_leaves) rep.dirNodes += l.sampling.nodeCount();
  rep.bytes = bytes();
  rep.dirThreshold = rho;
  return rep;
}

void GuideTree::flatten(std::vector<shared::GuideSpatialNode>& spatial, std::vector<shared::GuideDirNode>& dir) const {
  spatial.assign(m_nodes.size(), shared::GuideSpatialNode{});
  dir.clear();
  std::vector<std::uint32_t> roots(m_leaves.size());
  for (std::size_t l = 0; l < m_leaves.size(); ++l) {
    const DirTree& t = m_leaves[l].sampling;
    const std::uint32_t offset = static_cast<std::uint32_t>(dir.size());
    roots[l] = offset;
    for (const DirTree::Node& n : t.nodes()) {
      shared::GuideDirNode g{};
      for (int c = 0; c < 4; ++c) {
        g.mass[c] = static_cast<float>(n.energy[c]);
        g.child[c] = n.child[c] == 0 ? 0u : n.child[c] + offset;
      }
      dir.push_back(g);
    }
  }
  for (std::size_t i = 0; i < m_nodes.size(); ++i) {
    const SpatialNode& n = m_nodes[i];
    if (n.axis != GUIDE_SPATIAL_LEAF) {
      spatial[i].info = shared::uvec4(n.axis, n.child, 0u, 0u);
      continue;
    }
    const DirTree& t = m_leaves[n.leaf].sampling;
    const float alpha = t.total() > 0 ? m_settings.alpha : 0.0f;
    spatial[i].info = shared::uvec4(GUIDE_SPATIAL_LEAF, roots[n.leaf], shared::floatBitsToUint(alpha), 0u);
  }
}

// ---- Training records -----------------------------------------------------------------------------

std::uint64_t splatPaths(GuideTree& tree, const glm::vec4* records, std::uint32_t recordsPerPath,
                         const glm::vec4* pathRadiance, std::uint32_t paths) {
  std::uint64_t splats = 0;
  if (recordsPerPath < 2) return 0;
  for (std::uint32_t p = 0; p < paths; ++p) {
    const glm::vec4 L = pathRadiance[p];
    const double lEnd = shared::luminance(shared::vec3(L.x, L.y, L.z));
    if (!std::isfinite(lEnd)) continue;  // dropped from the film too
    const glm::vec4* r = records + std::size_t(p) * recordsPerPath * 2;
    for (std::uint32_t k = 0; k + 1 < recordsPerPath; ++k) {
      const glm::vec4 a = r[2 * k], b = r[2 * k + 1];
      if (b.w == 0.0f) break;  // the path ended at vertex k
      if (!(b.w > 0.0f)) continue;  // a delta sample: the path goes on, nothing to splat
      const float arrived = r[2 * (k + 1)].w;
      // What reached vertex k through its sample: everything the path gathered from vertex k + 1's
      // arrival on; nothing when that ray left a scene without environment (-1).
      const double after = arrived < 0.0f ? 0.0 : std::max(0.0, lEnd - double(arrived));
      tree.splat(glm::vec3(a), glm::vec3(b), after / double(b.w));
      ++splats;
    }
  }
  return splats;
}

}  // namespace nusselt::guiding
