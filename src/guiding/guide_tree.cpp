// guide_tree.cpp: training, refinement and flattening of the path guide (guide_tree.h).
#include "guiding/guide_tree.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>
#include <utility>
#include <vector>

namespace nusselt::guiding {

namespace {
constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
}

// ---- Directional quadtree -------------------------------------------------------------------------

void DirTree::splat(glm::vec2 p, double value) {
  descend(p, [&](std::uint32_t node, std::uint32_t c, float, float, float) { m_nodes[node].energy[c] += value; });
}

double DirTree::leafSide(glm::vec2 p) const {
  return descend(p, [](std::uint32_t, std::uint32_t, float, float, float) {});
}

namespace {
// The box of splatBox(p, side, value) on the map, for the splat and for pdfWithout alike: u (cos
// theta, x) ends at the poles, so the box is cut there and its value renormalised to the rest;
// phi (y) wraps around, so a box crossing y = 0 or 1 is two parts (side <= 1/2). point: no box
// (side 0, or nothing left after the cut): splat(p, value).
struct SplatBox {
  bool point = true;
  double x0 = 0, x1 = 0, perArea = 0;
  int parts = 0;
  std::array<double, 2> y0{}, y1{};
  SplatBox(glm::vec2 p, double side, double value) {
    const double h = 0.5 * side;
    x0 = std::max(0.0, double(p.x) - h);
    x1 = std::min(1.0, double(p.x) + h);
    const double width = x1 - x0;
    if (!(side > 0) || !(width > 0)) return;
    point = false;
    perArea = value / (width * side);
    const double by0 = double(p.y) - h, by1 = double(p.y) + h;
    if (by0 < 0.0) {
      add(by0 + 1.0, 1.0);
      add(0.0, by1);
    } else if (by1 > 1.0) {
      add(by0, 1.0);
      add(0.0, by1 - 1.0);
    } else {
      add(by0, by1);
    }
  }
  // The box's value within the cell [cx0, cx0 + s) x [cy0, cy0 + s) (a box, not a point).
  double within(double cx0, double cy0, double s) const {
    const double ox = std::min(x1, cx0 + s) - std::max(x0, cx0);
    if (!(ox > 0)) return 0.0;
    double oy = 0;
    for (int i = 0; i < parts; ++i) {
      const double o = std::min(y1[i], cy0 + s) - std::max(y0[i], cy0);
      if (o > 0) oy += o;
    }
    return perArea * ox * oy;
  }

 private:
  void add(double a, double b) {
    y0[parts] = a;
    y1[parts] = b;
    ++parts;
  }
};
}  // namespace

void DirTree::splatBox(glm::vec2 p, double side, double value) {
  const SplatBox box(p, side, value);
  if (box.point) {
    splat(p, value);
    return;
  }
  for (int i = 0; i < box.parts; ++i) splatBoxInto(0, 0.0, 0.0, 1.0, box.x0, box.x1, box.y0[i], box.y1[i], box.perArea);
}

// Adds valuePerArea x (the overlap of the box [bx0, bx1] x [by0, by1] with each child cell of
// `node`, whose cell is [x0, x0 + size) x [y0, y0 + size)) to the child's energy, and recurses
// into inner children: the children's overlaps sum to the node's, so every level receives the
// same total.
void DirTree::splatBoxInto(std::uint32_t node, double x0, double y0, double size, double bx0, double bx1, double by0,
                           double by1, double valuePerArea) {
  const double h = 0.5 * size;
  for (std::uint32_t c = 0; c < 4; ++c) {
    const double cx0 = x0 + ((c & 1u) ? h : 0.0), cy0 = y0 + ((c & 2u) ? h : 0.0);
    const double ox = std::min(bx1, cx0 + h) - std::max(bx0, cx0);
    const double oy = std::min(by1, cy0 + h) - std::max(by0, cy0);
    if (!(ox > 0) || !(oy > 0)) continue;
    m_nodes[node].energy[c] += valuePerArea * ox * oy;
    const std::uint32_t child = m_nodes[node].child[c];
    if (child != 0) splatBoxInto(child, cx0, cy0, h, bx0, bx1, by0, by1, valuePerArea);
  }
}

double DirTree::pdfWithout(glm::vec2 p, glm::vec2 q, double side, double value) const {
  // The splat's share of a cell [x0, x0 + s) x [y0, y0 + s): what splatBox gave it.
  const SplatBox box(q, side, value);
  auto share = [&](double x0, double y0, double s) {
    if (box.point) return (q.x >= x0 && q.x < x0 + s && q.y >= y0 && q.y < y0 + s) ? value : 0.0;
    return box.within(x0, y0, s);
  };
  double pdf = 1.0;
  bool empty = false;
  descend(p, [&](std::uint32_t node, std::uint32_t c, float cx0, float cy0, float side) {
    if (empty) return;
    const Node& N = m_nodes[node];
    const double all = N.energy[0] + N.energy[1] + N.energy[2] + N.energy[3];
    const double px0 = cx0 - ((c & 1u) ? side : 0.0f), py0 = cy0 - ((c & 2u) ? side : 0.0f);  // the node's cell
    const double T = all - share(px0, py0, 2.0 * side);
    const double e = N.energy[c] - share(cx0, cy0, side);
    // What the splat alone held is 0 up to rounding: no energy left.
    const double eps = 1e-12 * all;
    if (!(T > eps) || !(e > eps)) empty = true;
    else pdf *= 4.0 * e / T;
  });
  return empty ? 0.0 : pdf;
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
  // Nodes 0 .. roots - 1: the roots of the orientation classes (guideSpatialRoot), each a leaf.
  m_settings.orientations = std::clamp<std::uint32_t>(m_settings.orientations, 1u, GUIDE_ORIENTATIONS);
  for (std::uint32_t o = 0; o < m_settings.orientations; ++o) {
    SpatialNode root;
    root.lo = lo;
    root.hi = hi;
    root.leaf = o;
    m_nodes.push_back(root);
    Leaf leaf;
    leaf.orientation = o;
    m_leaves.push_back(leaf);
  }
  m_keepCap = keepCap();
}

std::uint32_t GuideTree::findLeaf(glm::vec3 x, std::uint32_t o) const { return m_nodes[findNode(x, o)].leaf; }

std::uint32_t GuideTree::findNode(glm::vec3 x, std::uint32_t o) const {
  glm::vec3 lo = m_lo, hi = m_hi;
  std::uint32_t node = shared::guideSpatialRoot(m_settings.orientations, o);
  for (std::uint32_t d = 0; d < GUIDE_MAX_SPATIAL_DEPTH; ++d) {
    const SpatialNode& n = m_nodes[node];
    if (n.axis == GUIDE_SPATIAL_LEAF) return node;
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
  return node;  // not reached: the builder stays below the bound
}

void GuideTree::leafBounds(std::uint32_t leaf, glm::vec3& lo, glm::vec3& hi) const {
  for (const SpatialNode& n : m_nodes)
    if (n.axis == GUIDE_SPATIAL_LEAF && n.leaf == leaf) {
      lo = n.lo;
      hi = n.hi;
      return;
    }
  lo = hi = glm::vec3(0.0f);
}

void GuideTree::splatDirection(std::uint32_t leafIndex, glm::vec3 d, double value) {
  DirTree& t = m_leaves[leafIndex].building;
  const shared::vec2 q = shared::guideDirectionToSquare(shared::vec3(d.x, d.y, d.z));
  const glm::vec2 p(q.x, q.y);
  if (m_settings.dirFilter) t.splatBox(p, t.leafSide(p), value);
  else t.splat(p, value);
}

void GuideTree::splatInLeaf(std::uint32_t leafIndex, glm::vec3 d, double value, double count) {
  m_leaves[leafIndex].samples += count;
  if (value > 0 && std::isfinite(value)) splatDirection(leafIndex, d, value);
}

void GuideTree::splatAt(std::uint32_t leafIndex, glm::vec3 x, std::uint32_t o, glm::vec3 d, double value, double count) {
  if (splatsStayInTheirLeaf()) {
    splatInLeaf(leafIndex, d, value, count);
    ++m_splats;
    return;
  }
  m_leaves[leafIndex].samples += count;
  ++m_splats;
  if (!(value > 0) || !std::isfinite(value)) return;
  // The box of x's region's size around x, within the root box.
  const SpatialNode& home = m_nodes[findNode(x, o)];
  const glm::dvec3 half = 0.5 * (glm::dvec3(home.hi) - glm::dvec3(home.lo));
  const glm::dvec3 lo = glm::max(glm::dvec3(x) - half, glm::dvec3(m_lo));
  const glm::dvec3 hi = glm::min(glm::dvec3(x) + half, glm::dvec3(m_hi));
  const glm::dvec3 ext = hi - lo;
  const double volume = ext.x * ext.y * ext.z;
  if (!(volume > 0)) {  // x outside the root box (rounding): its own region only
    splatDirection(leafIndex, d, value);
    return;
  }
  // Every leaf of x's orientation class the box overlaps gets the share of its overlapped volume
  // (children in order).
  std::uint32_t stack[GUIDE_MAX_SPATIAL_DEPTH + 2];
  std::uint32_t top = 0;
  stack[top++] = shared::guideSpatialRoot(m_settings.orientations, o);
  while (top > 0) {
    const SpatialNode& n = m_nodes[stack[--top]];
    const glm::dvec3 o = glm::min(hi, glm::dvec3(n.hi)) - glm::max(lo, glm::dvec3(n.lo));
    if (!(o.x > 0) || !(o.y > 0) || !(o.z > 0)) continue;
    if (n.axis == GUIDE_SPATIAL_LEAF) {
      splatDirection(n.leaf, d, value * (o.x * o.y * o.z / volume));
      continue;
    }
    stack[top++] = n.child + 1;
    stack[top++] = n.child;
  }
}

// ---- The selection probability per region ---------------------------------------------------------
// A vertex's estimate through its sample is y = F / p_mix (F = f cos L_i, drawn with density p_mix
// = a p_guide + (1 - a) p_bsdf). With alpha_c instead of a, the same estimate's second moment is
// E_{p_c}[(F / p_c)^2] = E_{p_mix}[y^2 p_mix / p_c]: every candidate's second moment is estimated
// from the same samples by reweighting (unbiased wherever p_mix > 0 covers F, which the BRDF
// sampler's share guarantees). observeSelection sums, per candidate, the difference to alpha = 0,
// d_c = y^2 p_mix (1 / p_bsdf - 1 / p_c), and its square (for the test in learnAlphas).

void GuideTree::observeSelection(std::uint32_t leafIndex, double y, double pdfGuide, double pdfBsdf, double alpha) {
  SelectionStats& st = m_leaves[leafIndex].selection;
  const double pMix = alpha * pdfGuide + (1.0 - alpha) * pdfBsdf;
  if (!(pMix > 0) || !std::isfinite(pMix) || !(pdfGuide >= 0) || !(pdfBsdf >= 0) || !std::isfinite(y)) return;
  st.vertices += 1;
  if (!(y > 0)) return;  // nothing came back: 0 under every alpha
  // The BRDF sampler has density wherever f cos > 0 (bsdf_sampling.h): a contribution without it
  // is a rounding case (a direction at the horizon) that says nothing about alpha.
  if (!(pdfBsdf > 0)) return;
  const double w = y * y * pMix;
  for (std::size_t c = 1; c < kAlphaCandidates.size(); ++c) {
    const double a = kAlphaCandidates[c];
    const double pc = a * pdfGuide + (1.0 - a) * pdfBsdf;  // > 0: pdfBsdf > 0 and a < 1
    const double d = w * (1.0 / pdfBsdf - 1.0 / pc);
    st.gain[c] += d;
    st.gainSq[c] += d * d;
  }
}

void GuideTree::observeSelectionAt(std::uint32_t leafIndex, glm::vec3 d, double value, double y, double pdfGuide,
                                   double pdfBsdf, double alpha) {
  if (!leaveOneOut()) {
    observeSelection(leafIndex, y, pdfGuide, pdfBsdf, alpha);
    return;
  }
  const double pMix = alpha * pdfGuide + (1.0 - alpha) * pdfBsdf;
  if (!(pMix > 0) || !std::isfinite(pMix) || !(pdfGuide >= 0) || !(pdfBsdf >= 0) || !std::isfinite(y)) return;
  Leaf& l = m_leaves[leafIndex];
  if (l.keepSeen++ % l.keepStride != 0) return;
  // A contribution without the BRDF sampler's density is a rounding case (observeSelection): it
  // counts as a vertex whose estimate is 0 under every alpha.
  const bool counts = y > 0 && pdfBsdf > 0;
  const shared::vec2 q = shared::guideDirectionToSquare(shared::vec3(d.x, d.y, d.z));
  l.kept.push_back({glm::vec2(q.x, q.y), value > 0 && std::isfinite(value) ? value : 0.0, float(counts ? y : 0.0), float(pMix),
                    float(pdfBsdf)});
  if (l.kept.size() >= 2 * std::size_t(m_keepCap)) {
    std::size_t n = 0;
    for (std::size_t k = 0; k < l.kept.size(); k += 2) l.kept[n++] = l.kept[k];
    l.kept.resize(n);
    l.keepStride *= 2;
  }
}

std::uint32_t GuideTree::keepCap() const {
  const std::uint64_t share = m_settings.alphaKeptTotal / std::max<std::uint64_t>(1, m_leaves.size());
  const std::uint64_t cap = std::max<std::uint64_t>(m_settings.alphaKeepMin, std::min<std::uint64_t>(m_settings.alphaKeep, share));
  return static_cast<std::uint32_t>(std::max<std::uint64_t>(1, cap));
}

std::uint64_t GuideTree::keptVertices() const {
  std::uint64_t n = 0;
  for (const Leaf& l : m_leaves) n += l.kept.size();
  return n;
}

// Leave-one-out scoring (GuideSettings::alphaLeaveOneOut): each kept vertex's d_c with the density
// of this iteration's tree without its own splat, the tree the alpha will sample. The leaves are
// independent: scored on every core, each leaf's sums in its vertices' order (deterministic).
void GuideTree::scoreKept() {
  const unsigned t = std::max(1u, std::min<unsigned>(std::thread::hardware_concurrency(), leafCount()));
  auto body = [&](unsigned i) {
    for (std::size_t li = i; li < m_leaves.size(); li += t) {
      Leaf& l = m_leaves[li];
      SelectionStats& st = l.selection;
      const DirTree& tree = l.building;
      const double F = m_settings.floor;
      for (const Leaf::Kept& k : l.kept) {
        st.vertices += 1;
        if (!(k.y > 0)) continue;
        const double side = m_settings.dirFilter ? tree.leafSide(k.p) : 0.0;
        const double pg = ((1.0 - F) * tree.pdfWithout(k.p, k.p, side, k.value) + F) * NUSSELT_INV_4PI;
        const double w = double(k.y) * k.y * k.pMix;
        for (std::size_t c = 1; c < kAlphaCandidates.size(); ++c) {
          const double a = kAlphaCandidates[c];
          const double pc = a * pg + (1.0 - a) * k.pBsdf;  // > 0: pBsdf > 0 and a < 1
          const double dd = w * (1.0 / k.pBsdf - 1.0 / pc);
          st.gain[c] += dd;
          st.gainSq[c] += dd * dd;
        }
      }
      l.scoredLeaveOneOut = !l.kept.empty();
      l.kept.clear();
      l.kept.shrink_to_fit();
      l.keepSeen = 0;
      l.keepStride = 1;
    }
  };
  std::vector<std::thread> pool;
  for (unsigned i = 1; i < t; ++i) pool.emplace_back(body, i);
  body(0u);
  for (std::thread& th : pool) th.join();
}

// At the end of an iteration, for each leaf whose guide had mass (else its samples say nothing
// about a guide: with leave-one-out the guide the alpha will sample, else the one the vertices
// were drawn with) and that saw at least alphaMinVertices vertices: the candidate with the largest
// estimated gain (the smallest second moment) is taken when its gain is significant (z-test of the
// mean of the d_c: mean / standard error > alphaZ), else alpha = 0 (BRDF sampling alone: where the
// guide does not pay, it is not used). Other leaves keep their alpha.
void GuideTree::learnAlphas() {
  if (leaveOneOut()) scoreKept();
  for (Leaf& l : m_leaves) {
    SelectionStats& st = l.selection;
    if (m_settings.alpha >= 0) {
      l.alpha = m_settings.alpha;
    } else if ((l.scoredLeaveOneOut ? l.building.total() : l.sampling.total()) > 0 &&
               st.vertices >= m_settings.alphaMinVertices) {
      std::size_t best = 1;
      for (std::size_t c = 2; c < kAlphaCandidates.size(); ++c)
        if (st.gain[c] > st.gain[best]) best = c;
      const double n = st.vertices;
      const double mean = st.gain[best] / n;
      const double var = std::max(0.0, st.gainSq[best] / n - mean * mean) * n / (n - 1.0);
      const bool significant = mean > 0 && mean > m_settings.alphaZ * std::sqrt(var / n);
      l.alpha = significant ? kAlphaCandidates[best] : 0.0f;
      l.alphaVertices = n;
    }
    st = SelectionStats{};
    l.scoredLeaveOneOut = false;
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

  // 0. Each region's alpha, from the vertices of the iteration (sampled with its guide).
  learnAlphas();

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
    half.alphaVertices *= 0.5;
    m_leaves[li].samples *= 0.5;
    m_leaves[li].alphaVertices *= 0.5;
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

  m_keepCap = keepCap();  // for the next iteration's regions
  rep.leaves = leafCount();
  for (const Leaf& l : m_leaves) rep.dirNodes += l.sampling.nodeCount();
  rep.bytes = bytes();
  rep.dirThreshold = rho;
  double alphaSum = 0;
  for (const Leaf& l : m_leaves)
    if (l.sampling.total() > 0 && leafGuideAlpha(l) > 0) {
      ++rep.guidedLeaves;
      alphaSum += leafGuideAlpha(l);
    }
  rep.meanAlpha = rep.guidedLeaves ? alphaSum / rep.guidedLeaves : 0.0;
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
    // The floor: each cell's mass (1 - floor) x its energy + floor x the total x its area, so
    // that the density the descent samples and guideSquarePdf reads is (1 - floor) x the tree's
    // + floor (uniform over the map, hence over the sphere). The nodes' children follow their
    // parent in the array: a cell's area is known when its node is reached.
    const double total = t.total();
    const double fl = total > 0 ? std::clamp(m_settings.floor, 0.0, 1.0) : 0.0;
    std::vector<double> childArea(t.nodeCount(), 0.25);
    for (std::size_t i = 0; i < t.nodes().size(); ++i) {
      const DirTree::Node& n = t.nodes()[i];
      shared::GuideDirNode g{};
      for (int c = 0; c < 4; ++c) {
        const double mass = fl > 0 ? (1.0 - fl) * n.energy[c] + fl * total * childArea[i] : n.energy[c];
        g.mass[c] = static_cast<float>(mass);
        g.child[c] = n.child[c] == 0 ? 0u : n.child[c] + offset;
        if (n.child[c] != 0) childArea[n.child[c]] = 0.25 * childArea[i];
      }
      dir.push_back(g);
    }
  }
  for (std::size_t i = 0; i < m_nodes.size(); ++i) {
    const SpatialNode& n = m_nodes[i];
    if (n.axis != GUIDE_SPATIAL_LEAF) {
      // The split as findNode computes it from the box (guideLeafInfo reads it).
      const float mid = 0.5f * (n.lo[n.axis] + n.hi[n.axis]);
      spatial[i].info = shared::uvec4(n.axis, n.child, shared::floatBitsToUint(mid), 0u);
      continue;
    }
    const DirTree& t = m_leaves[n.leaf].sampling;
    const float alpha = t.total() > 0 ? leafGuideAlpha(m_leaves[n.leaf]) : 0.0f;
    spatial[i].info = shared::uvec4(GUIDE_SPATIAL_LEAF, roots[n.leaf], shared::floatBitsToUint(alpha), 0u);
  }
}

// ---- Training records -----------------------------------------------------------------------------

std::uint64_t splatPaths(GuideTree& tree, const glm::vec4* records, std::uint32_t recordsPerPath,
                         const glm::vec4* pathRadiance, std::uint32_t paths, unsigned threads) {
  if (recordsPerPath < 2) return 0;
  const std::uint32_t perPath = recordsPerPath - 1;  // splat slots per path: vertices 0 .. recordsPerPath - 2
  // Calls fn(p, k, x, d, sample record, arrived-after radiance) for every splat of paths [p0, p1), in order.
  auto forEachSplat = [&](std::uint32_t p0, std::uint32_t p1, auto&& fn) {
    for (std::uint32_t p = p0; p < p1; ++p) {
      const glm::vec4 L = pathRadiance[p];
      const double lEnd = shared::luminance(shared::vec3(L.x, L.y, L.z));
      if (!std::isfinite(lEnd)) continue;  // dropped from the film too
      for (std::uint32_t k = 0; k < perPath; ++k) {
        const glm::vec4* r = records + shared::guideRecordIndex(p, k, paths);
        const glm::vec4 b = r[1];
        if (b.w == 0.0f) break;       // the path ended at vertex k
        if (!(b.w > 0.0f)) continue;  // a delta sample: the path goes on, nothing to splat
        const float arrived = records[shared::guideRecordIndex(p, k + 1, paths)].w;
        // What reached vertex k through its sample: everything the path gathered from vertex k + 1's
        // arrival on; nothing when that ray left a scene without environment (-1).
        const double after = arrived < 0.0f ? 0.0 : std::max(0.0, lEnd - double(arrived));
        fn(p, k, r[0], b, r[2], after);
      }
    }
  };
  unsigned t = threads ? threads : std::max(1u, std::thread::hardware_concurrency());
  t = std::min<unsigned>(t, tree.leafCount());
  if (t < 2 || !tree.splatsStayInTheirLeaf() || paths < 4096u) {
    std::uint64_t splats = 0;
    forEachSplat(0, paths, [&](std::uint32_t, std::uint32_t, glm::vec4 a, glm::vec4 b, glm::vec4 c, double after) {
      const std::uint32_t o = std::uint32_t(c.w);
      const std::uint32_t leaf = tree.findLeaf(glm::vec3(a), o);
      const double value = after / double(b.w);
      tree.splatAt(leaf, glm::vec3(a), o, glm::vec3(b), value);
      // The same radiance is the vertex's estimate through its sample (y = F / p_mix).
      if (c.x >= 0.0f) tree.observeSelectionAt(leaf, glm::vec3(b), value, after, c.x, c.y, c.z);
      ++splats;
    });
    return splats;
  }
  // In parallel, the same operations per leaf in the same order: 1. threads over path ranges
  // read the records once (findLeaf only reads the tree) and list each splat with its leaf, in
  // path order, and count the splats per leaf; 2. the leaves shared among the threads by their
  // splats (largest first, to the least loaded; a fixed rule); 3. each thread reads the lists of
  // the ranges in order and applies the splats of its own leaves. The records are read once: a
  // chunk's records are scattered over a buffer of hundreds of MiB, the lists are dense.
  struct Listed {
    glm::vec3 d;
    float bw;  // the record's b.w: the splat's value is after / bw
    glm::vec3 selection;
    std::uint32_t leaf;
    double after;
  };
  std::vector<std::vector<Listed>> lists(t);
  std::vector<std::vector<std::uint64_t>> counts(t, std::vector<std::uint64_t>(tree.leafCount(), 0));
  auto run = [&](auto&& body) {
    std::vector<std::thread> pool;
    for (unsigned i = 1; i < t; ++i) pool.emplace_back(body, i);
    body(0u);
    for (std::thread& th : pool) th.join();
  };
  run([&](unsigned i) {
    const std::uint32_t p0 = std::uint32_t(std::uint64_t(paths) * i / t), p1 = std::uint32_t(std::uint64_t(paths) * (i + 1) / t);
    lists[i].reserve(std::size_t(p1 - p0) * 4);
    forEachSplat(p0, p1, [&](std::uint32_t, std::uint32_t, glm::vec4 a, glm::vec4 b, glm::vec4 c, double after) {
      const std::uint32_t leaf = tree.findLeaf(glm::vec3(a), std::uint32_t(c.w));
      lists[i].push_back({glm::vec3(b), b.w, glm::vec3(c), leaf, after});
      ++counts[i][leaf];
    });
  });
  std::vector<std::pair<std::uint64_t, std::uint32_t>> byCount(tree.leafCount());
  for (std::uint32_t l = 0; l < tree.leafCount(); ++l) {
    std::uint64_t n = 0;
    for (unsigned i = 0; i < t; ++i) n += counts[i][l];
    byCount[l] = {n, l};
  }
  std::sort(byCount.begin(), byCount.end(), [](auto& x, auto& y) { return x.first != y.first ? x.first > y.first : x.second < y.second; });
  std::vector<unsigned> owner(tree.leafCount(), 0);
  std::vector<std::uint64_t> load(t, 0);
  for (auto& [n, l] : byCount) {
    const unsigned i = unsigned(std::min_element(load.begin(), load.end()) - load.begin());
    owner[l] = i;
    load[i] += n;
  }
  run([&](unsigned i) {
    for (const std::vector<Listed>& list : lists)
      for (const Listed& e : list) {
        if (owner[e.leaf] != i) continue;
        const double value = e.after / double(e.bw);
        tree.splatInLeaf(e.leaf, e.d, value);
        if (e.selection.x >= 0.0f)
          tree.observeSelectionAt(e.leaf, e.d, value, e.after, e.selection.x, e.selection.y, e.selection.z);
      }
  });
  std::uint64_t total = 0;
  for (const std::vector<Listed>& list : lists) total += list.size();
  tree.addSplats(total);
  return total;
}

void appendPhotons(const glm::vec4* records, std::uint32_t recordsPerPath, std::uint32_t photons,
                   std::vector<PhotonSplat>& out) {
  for (std::uint32_t p = 0; p < photons; ++p) {
    for (std::uint32_t k = 1; k < recordsPerPath; ++k) {
      const glm::vec4* r = records + shared::guideRecordIndex(p, k, photons);
      const glm::vec4 a = r[0], b = r[1];
      if (!(b.w >= 1.0f) || !(a.w > 0.0f) || !std::isfinite(a.w)) continue;  // b.w = 1 + orientation
      out.push_back({glm::vec3(a), std::uint32_t(b.w - 1.0f), glm::vec3(b), a.w});
    }
  }
}

std::vector<IterationReport> trainPhotons(GuideTree& tree, const std::vector<PhotonSplat>& splats,
                                          std::uint32_t rounds, double count) {
  std::vector<IterationReport> reports;
  for (std::uint32_t round = 0; round < rounds; ++round) {
    for (const PhotonSplat& s : splats) tree.splat(s.x, s.orientation, s.d, double(s.value), count);
    reports.push_back(tree.endIteration(0));
    reports.back().iteration = round;
    reports.back().photons = true;
  }
  return reports;
}

}  // namespace nusselt::guiding
