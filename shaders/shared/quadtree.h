// quadtree.h: the generic BRDF sampler of Montes, Urena, Garcia and Lastra (GRAPP 2008), shared by
// the CPU (tests, `nusselt sample --cpu`) and the GPU (shade stages, sample_tool).
//
// Domain: the unit disc (x, y) = (sin t cos p, sin t sin p) of the upper hemisphere; a density
// proportional to f on the disc is proportional to f cos(theta) per unit solid angle.
// One tree per tabulated known direction v_k; it samples w with disc density f(w, v_k) / a_k,
// a_k = integral of f(., v_k) over the disc (the directional albedo of the luminance of f).
// Convention: brdfEval(model, p, w, v): the sampled direction is the FIRST argument (wi, towards
// the light) and the known direction the second (wo, towards the viewer). docs/sampler.md.
//
// Buffer access: GLSL reads the buffer references of the Globals `g`; C++ reads host arrays
// through the thread-local QuadHost pointer that the CPU sampler sets (QuadHostScope in
// src/quadtree/sampler_tables.h). The sampling logic exists once.
#ifndef NUSSELT_QUADTREE_H
#define NUSSELT_QUADTREE_H
#include "brdf/dispatch.h"
#include "mass_descent.h"
#include "rng.h"
#include "warp.h"

#ifdef __cplusplus
SHARED_BEGIN
struct QuadHost {
  const QuadSet* sets = nullptr;
  const QuadTable* tables = nullptr;
  const QuadNode* nodes = nullptr;
  const QuadLeaf* leaves = nullptr;
  std::uint64_t boundViolations = 0;  // samples during which f > M was seen in their leaf
  std::uint64_t trialFailures = 0;    // samples that hit QT_MAX_TRIALS (returned false)
  std::uint64_t trials = 0;           // total rejection trials (proposal draws, statistics)
  std::uint64_t evaluations = 0;      // trials that evaluated f (inside leaf & disc)
  std::uint64_t samples = 0;          // calls of quadSample that reached a leaf
  std::uint64_t nodeReads = 0;        // inner nodes read by the descents
  // Optional, per leaf (global leaf index): evaluations of f and accepted samples; the test of
  // "every leaf accepts at least 1 / n_max of its candidates" reads them.
  std::uint64_t* leafEvaluations = nullptr;
  std::uint64_t* leafAccepted = nullptr;
  // Optional: called for every evaluation with f > e (global leaf index, the point, f, e).
  void (*onViolation)(std::uint32_t leaf, vec3 w, float f, float e) = nullptr;
};
inline thread_local QuadHost* g_quadHost = nullptr;
inline void quadCountTrials(std::uint32_t evals, std::uint32_t trials, std::uint32_t depth, std::uint32_t leaf, bool accepted) {
  QuadHost* h = g_quadHost;
  h->nodeReads += depth;
  h->trials += trials;
  h->evaluations += evals;
  h->samples++;
  if (h->leafEvaluations) h->leafEvaluations[leaf] += evals;
  if (h->leafAccepted && accepted) h->leafAccepted[leaf]++;
}
SHARED_END
#define QT_SET(i) (::nusselt::shared::g_quadHost->sets[i])
#define QT_TABLE(i) (::nusselt::shared::g_quadHost->tables[i])
#define QT_NODE(i) (::nusselt::shared::g_quadHost->nodes[i])
#define QT_LEAF(i) (::nusselt::shared::g_quadHost->leaves[i])
#define QT_COUNT_BOUND_VIOLATION() (::nusselt::shared::g_quadHost->boundViolations++)
#define QT_REPORT_VIOLATION(leaf, w, f, e) \
  if (::nusselt::shared::g_quadHost->onViolation) ::nusselt::shared::g_quadHost->onViolation(leaf, w, f, e)
#define QT_COUNT_TRIAL_FAILURE() (::nusselt::shared::g_quadHost->trialFailures++)
#define QT_COUNT_TRIALS(evals, n, depth, leaf, ok) ::nusselt::shared::quadCountTrials(evals, n, depth, leaf, ok)
#else
#define QT_SET(i) loadQuadSet(g.quadSets, i)
#define QT_TABLE(i) loadQuadTable(g.quadTables, i)
#define QT_NODE(i) loadQuadNode(g.quadNodes, i)
#define QT_LEAF(i) loadQuadLeaf(g.quadLeaves, i)
#define QT_COUNT_BOUND_VIOLATION() atomicAdd(g.stats.v[STAT_SAMPLER_BOUND_VIOLATIONS], 1u)
#define QT_REPORT_VIOLATION(leaf, w, f, e)
#define QT_COUNT_TRIAL_FAILURE() atomicAdd(g.stats.v[STAT_SAMPLER_TRIAL_FAILURES], 1u)
#define QT_COUNT_TRIALS(evals, n, depth, leaf, ok)
#endif

SHARED_BEGIN

// Angles within this fraction of a table step snap to the table (float error of the caller's
// direction): no defensive term there, so the weight f cos / pdf is exactly the table's albedo.
#define QT_SNAP 1e-3f

// ---- Tables -------------------------------------------------------------------------------------

// The known direction of a table (canonical frame), the same float vector in builder and sampler.
SHARED_FN vec3 quadTableDirection(QuadTable T) {
  float cp = uintBitsToFloat(T.info.y);
  float sp = uintBitsToFloat(T.info.z);
  return vec3(T.data.w * cp, T.data.w * sp, T.data.y);
}

// Canonical frame of a known direction v: isotropic sets rotate v to azimuth 0
// (frame = (cos phi_v, sin phi_v, 1, 1)); anisotropic sets reflect it into the first quadrant
// (frame = (1, 0, sign x, sign y)). toCanonical(w) = R(-phi) S w; fromCanonical = S R(phi).
SHARED_FN vec4 quadFrame(bool aniso, vec3 v) {
  if (aniso) return vec4(1.0f, 0.0f, v.x < 0.0f ? -1.0f : 1.0f, v.y < 0.0f ? -1.0f : 1.0f);
  float s2 = v.x * v.x + v.y * v.y;
  if (s2 < 1e-30f) return vec4(1.0f, 0.0f, 1.0f, 1.0f);
  float inv = inversesqrt(s2);
  return vec4(v.x * inv, v.y * inv, 1.0f, 1.0f);
}
SHARED_FN vec3 quadToCanonical(vec4 fr, vec3 w) {
  float x = fr.z * w.x;
  float y = fr.w * w.y;
  return vec3(fr.x * x + fr.y * y, -fr.y * x + fr.x * y, w.z);
}
SHARED_FN vec3 quadFromCanonical(vec4 fr, vec3 w) {
  float x = fr.x * w.x - fr.y * w.y;
  float y = fr.y * w.x + fr.x * w.y;
  return vec3(fr.z * x, fr.w * y, w.z);
}

// Position of the (canonical) known direction in the table grid: tables k0, k1 along theta with
// weight t of k1, j0, j1 along phi with weight s of j1; returns whether it sits on a table
// (within QT_SNAP of a step in both coordinates: then t = s = 0).
SHARED_FN bool quadGrid(QuadSet S, vec3 vc, OUT(uvec4) idx, OUT(vec2) ts) {
  uint nt = S.info.y;
  uint np = S.info.z;
  float sinT = sqrt(vc.x * vc.x + vc.y * vc.y);
  float theta = atan(sinT, max(vc.z, 0.0f));
  float ft = theta / S.data.y;
  float kf = min(floor(ft), float(nt - 1u));
  float t = clamp(ft - kf, 0.0f, 1.0f);
  bool exact = true;
  if (t < QT_SNAP) t = 0.0f;
  else if (t > 1.0f - QT_SNAP && kf + 1.0f < float(nt)) { kf += 1.0f; t = 0.0f; }
  else exact = false;
  uint k0 = uint(kf);
  uint k1 = min(k0 + 1u, nt - 1u);
  uint j0 = 0u;
  uint j1 = 0u;
  float s = 0.0f;
  if (np > 1u && sinT > 0.0f) {
    float phi = atan(abs(vc.y), abs(vc.x));
    float fp = phi / S.data.z;
    float jf = min(floor(fp), float(np - 1u));
    s = clamp(fp - jf, 0.0f, 1.0f);
    if (s < QT_SNAP) s = 0.0f;
    else if (s > 1.0f - QT_SNAP && jf + 1.0f < float(np)) { jf += 1.0f; s = 0.0f; }
    else exact = false;
    j0 = uint(jf);
    j1 = min(j0 + 1u, np - 1u);
  }
  if (k0 == nt - 1u && ft > kf + QT_SNAP) exact = false;  // beyond the last table
  idx = uvec4(k0, k1, j0, j1);
  ts = vec2(t, s);
  return exact;
}

// Luminance of f(w, v) (the density the trees are built on).
SHARED_FN float quadEvalLum(uint model, BrdfParams p, vec3 w, vec3 v) {
  float f = luminance(brdfEval(model, p, w, v));
  return isFinite(f) ? max(f, 0.0f) : 0.0f;
}

// Corner c (bit 0: the second theta table idx.y, bit 1: the second phi table idx.w) of the mixture
// between tables: its weight, and its table with mass = a_up (+ a_low for transmitting sets).
SHARED_FN float quadCornerWeight(vec2 ts, uint c) {
  return ((c & 1u) != 0u ? ts.x : 1.0f - ts.x) * ((c & 2u) != 0u ? ts.y : 1.0f - ts.y);
}
// The index of corner c's (upper) table; a transmitting set's lower table is S.info.y * S.info.z
// further.
SHARED_FN uint quadCornerIndex(QuadSet S, uvec4 idx, uint c) {
  uint k = (c & 1u) != 0u ? idx.y : idx.x;
  uint j = (c & 2u) != 0u ? idx.w : idx.z;
  return S.info.x + k * S.info.z + j;
}
SHARED_FN QuadTable quadCornerTable(QuadSet S, uvec4 idx, uint c, OUT(float) mass) {
  uint i = quadCornerIndex(S, idx, c);
  QuadTable T = QT_TABLE(i);
  mass = T.data.x;
  if ((S.info.w & QT_SET_TRANSMITS) != 0u) mass += QT_TABLE(i + S.info.y * S.info.z).data.x;
  return T;
}

// Corner c's term of the mixture's sum at wc: weight f(wc, v_c) / mass (0 without weight or mass).
SHARED_FN float quadCornerTerm(QuadSet S, uint model, BrdfParams p, uvec4 idx, vec2 ts, vec3 wc, uint c) {
  float wt = quadCornerWeight(ts, c);
  if (wt <= 0.0f) return 0.0f;
  float mass;
  QuadTable T = quadCornerTable(S, idx, c, mass);
  if (mass <= 0.0f) return 0.0f;
  return wt * quadEvalLum(model, p, wc, quadTableDirection(T)) / mass;
}

// The mixture's density at wc from the sum over its corners of w_c f(wc, v_c) / mass: (1 - eps)
// sum |cos| plus the defensive cosine's eps |cos| / pi (transmitting sets: eps |cos| / (2 pi), a
// cosine on either side).
SHARED_FN float quadMixtureFromSum(bool transmits, float sum, float eps, vec3 wc) {
  if (transmits) return (1.0f - eps) * sum * abs(wc.z) + eps * abs(wc.z) * (0.5f * NUSSELT_INV_PI);
  return (1.0f - eps) * sum * wc.z + eps * wc.z * NUSSELT_INV_PI;
}

// Solid-angle density of the mixture at the canonical direction wc (wc.z > 0): the (bi)linear
// mixture of the neighbouring trees, plus eps cos / pi when the direction is between tables.
// Transmitting sets (QT_SET_TRANSMITS): wc on either side, each tree pair's density
// f |cos| / (a_up + a_low), and the defensive part eps |cos| / (2 pi) (a cosine on each side).
SHARED_FN float quadMixturePdf(QuadSet S, uint model, BrdfParams p, uvec4 idx, vec2 ts, float eps, vec3 wc) {
  bool transmits = (S.info.w & QT_SET_TRANSMITS) != 0u;
  if (wc.z <= 0.0f && !(transmits && wc.z < 0.0f)) return 0.0f;
  float sum = 0.0f;
  for (uint c = 0u; c < 4u; ++c) sum += quadCornerTerm(S, model, p, idx, ts, wc, c);
  return quadMixtureFromSum(transmits, sum, eps, wc);
}

// quadMixturePdf for a direction the sampler drew from the tree of corner `chosen` (c = 0 .. 3 as
// there: bit 0 the second theta table, bit 1 the second phi table; 4: from the defensive cosine),
// whose luminance fl = f(wc, v_k) (at wc's mirror image: the same value, f being symmetric) the
// rejection already evaluated: f is evaluated at the other corners only. A lane's other corners
// are found by index, so a subgroup evaluates f once per other corner (isotropic sets: once),
// whichever corner each lane drew from; only lanes that drew the defensive cosine evaluate the
// chosen corner's f too, in a branch that the other lanes skip.
SHARED_FN float quadMixturePdfKnown(QuadSet S, uint model, BrdfParams p, uvec4 idx, vec2 ts, float eps, vec3 wc,
                                    uint chosen, float fl) {
  bool transmits = (S.info.w & QT_SET_TRANSMITS) != 0u;
  if (wc.z <= 0.0f && !(transmits && wc.z < 0.0f)) return 0.0f;
  uint known = chosen < 4u ? chosen : 0u;
  float sum = 0.0f;
  for (uint i = 0u; i < 3u; ++i) sum += quadCornerTerm(S, model, p, idx, ts, wc, i < known ? i : i + 1u);
  {
    float wt = quadCornerWeight(ts, known);
    float mass;
    QuadTable T = quadCornerTable(S, idx, known, mass);
    if (wt > 0.0f && mass > 0.0f) {
      float f = fl;
      if (chosen >= 4u) f = quadEvalLum(model, p, wc, quadTableDirection(T));
      sum += wt * f / mass;
    }
  }
  return quadMixtureFromSum(transmits, sum, eps, wc);
}

// ---- Public interface ---------------------------------------------------------------------------

// Density per unit solid angle with which quadSample draws w for the known direction v (both in
// the local frame, normal +z). 0 below the surface (transmitting sets: 0 in the plane of the
// surface only). For MIS; no tree descent.
SHARED_FN float quadPdf(uint set, uint model, BrdfParams p, vec3 v, vec3 w) {
  if (v.z <= 0.0f || !(w.z > 0.0f || w.z < 0.0f)) return 0.0f;
  QuadSet S = QT_SET(set);
  vec4 fr = quadFrame((S.info.w & QT_SET_ANISOTROPIC) != 0u, v);
  uvec4 idx;
  vec2 ts;
  bool exact = quadGrid(S, quadToCanonical(fr, v), idx, ts);
  return quadMixturePdf(S, model, p, idx, ts, exact ? 0.0f : S.data.x, quadToCanonical(fr, w));
}

// Tabulated directional albedo (luminance) at polar angle acos(cosTheta) and azimuth phi of the
// known direction, interpolated (bi)linearly between tables: the Russian-roulette continuation
// probability of the random-walk source. Transmitting sets: both discs (R + T, the transmitted
// part with its radiance scaling).
SHARED_FN float quadAlbedo(uint set, float cosTheta, float phi) {
  QuadSet S = QT_SET(set);
  float c = clamp(cosTheta, 0.0f, 1.0f);
  vec3 v = vec3(cosFromSin(c) * cos(phi), cosFromSin(c) * sin(phi), c);
  vec4 fr = quadFrame((S.info.w & QT_SET_ANISOTROPIC) != 0u, v);
  uvec4 idx;
  vec2 ts;
  quadGrid(S, quadToCanonical(fr, v), idx, ts);
  uint np = S.info.z;
  float a00 = QT_TABLE(S.info.x + idx.x * np + idx.z).data.x;
  float a10 = QT_TABLE(S.info.x + idx.y * np + idx.z).data.x;
  float a01 = QT_TABLE(S.info.x + idx.x * np + idx.w).data.x;
  float a11 = QT_TABLE(S.info.x + idx.y * np + idx.w).data.x;
  if ((S.info.w & QT_SET_TRANSMITS) != 0u) {
    uint lower = S.info.x + S.info.y * np;
    a00 += QT_TABLE(lower + idx.x * np + idx.z).data.x;
    a10 += QT_TABLE(lower + idx.y * np + idx.z).data.x;
    a01 += QT_TABLE(lower + idx.x * np + idx.w).data.x;
    a11 += QT_TABLE(lower + idx.y * np + idx.w).data.x;
  }
  return mix(mix(a00, a10, ts.x), mix(a01, a11, ts.x), ts.y);
}

// Inverse CDF of the density proportional to exp(k (t - 1/2)) on [0, 1]; k = 0 is uniform (the
// builder sets |k| < QT_MIN_SLOPE to 0, so the formulas below never cancel badly).
// m = exp(-|k|) (quadExpTail), computed once per sample for its leaf (quadLeafProposal), not per trial.
SHARED_FN float quadExpTail(float k) { return exp(-abs(k)); }
SHARED_FN float quadExpSample(float k, float m, float u) {
  if (k == 0.0f) return u;
  // One logarithm for either sign (exp(-k) = m for k > 0, exp(k) = m for k < 0).
  float l = portableLog(k > 0.0f ? u + (1.0f - u) * m : (1.0f - u) + u * m);
  float t = k > 0.0f ? 1.0f + l / k : l / k;
  return clamp(t, 0.0f, 1.0f);
}
// (cos, sin) of pi t for t in [-2, 2], reduced so that t = 0, +-1, +-2 give sin = 0 exactly: the
// seams of the half disc (isotropic sets, mirrored at y = 0) neither overlap nor leave a gap.
SHARED_FN vec2 quadCosSinPi(float t) {
  float ss = 1.0f;
  float sc = 1.0f;
  float a = t;
  if (a < 0.0f) { a = -a; ss = -1.0f; }
  if (a > 1.0f) { a = 2.0f - a; ss = -ss; }
  if (a > 0.5f) { a = 1.0f - a; sc = -1.0f; }
  float ph = a * NUSSELT_PI;
  return vec2(sc * cos(ph), ss * sin(ph));
}
// Integral of exp(k (t - 1/2)) over [0, 1].
SHARED_FN float quadExpMass(float k) { return k == 0.0f ? 1.0f : (exp(0.5f * k) - exp(-0.5f * k)) / k; }

// ---- The tree descent, by mass only --------------------------------------------------------------

// The leaf a descent reached: link = QT_LEAF_BIT | leaf index; box = (x0, x1, y0, y1), the square
// of the descent in the stored (canonical) disc (unused below polar nodes, whose leaves carry their
// own box); prob = the probability of reaching this leaf (the mirror's 1/2 included); depth = the
// nodes read; mirrored = 1 when the sample is to be mirrored to y < 0 (isotropic sets).
struct QuadDescent {
  vec4 box;
  uint link;
  float prob;
  uint depth;
  uint mirrored;
};
STATIC_ASSERT_SIZE(QuadDescent, 32);

// Descends the tree rooted at node `root` in proportion to the children's masses with the uniform
// number u (mass_descent.h: rescaled at each level, fresh numbers from pcg4d(stream + (0, 0, 0,
// level - 1)) once it runs out of resolution). The root's children are the inner squares and the
// polar rim (quadtree_layout.h); isotropic sets store the half disc y >= 0 and mirror it with
// probability 1/2, decided by the first bit of u. False when the descent ends without a leaf.
SHARED_FN bool quadDescend(uint root, bool aniso, float u, uvec4 stream, OUT(QuadDescent) d) {
  d.box = vec4(-1.0f, 1.0f, -1.0f, 1.0f);
  d.link = QT_EMPTY;
  d.prob = 0.0f;
  d.depth = 0u;
  d.mirrored = 0u;
  float ux = u;
  float prob = 1.0f;
  if (!aniso) {
    bool mirrored = ux >= 0.5f;
    ux = mirrored ? 2.0f * ux - 1.0f : 2.0f * ux;
    d.mirrored = mirrored ? 1u : 0u;
    prob = 0.5f;
  }
  // The stream's level 1 (the first node below the root) takes its number at stream.w.
  uvec4 s = uvec4(stream.x, stream.y, stream.z, stream.w - 1u);
  MassDescent m = massDescentStart(ux);
  float share;
  QuadNode R = QT_NODE(root);
  uint rc = massDescendStep(R.mass, s, m, share);
  if (!(share > 0.0f)) return false;
  float x0 = -1.0f, x1 = 1.0f, y0 = -1.0f, y1 = 1.0f;
  if (!aniso) {
    y0 = 0.0f;
    if (rc == 0u) x1 = 0.0f;
    else x0 = 0.0f;
  }
  uint link = R.child[rc];
  uint depth = 1u;
  for (uint l = 0u; l < QT_MAX_DESCENT; ++l) {
    if ((link & QT_LEAF_BIT) != 0u) break;
    ++depth;
    QuadNode N = QT_NODE(link);
    uint c = massDescendStep(N.mass, s, m, share);
    if (!(share > 0.0f)) return false;
    float xm = 0.5f * (x0 + x1);  // square geometry (unused below polar nodes)
    float ym = 0.5f * (y0 + y1);
    if ((c & 1u) != 0u) x0 = xm; else x1 = xm;
    if ((c & 2u) != 0u) y0 = ym; else y1 = ym;
    link = N.child[c];
  }
  d.box = vec4(x0, x1, y0, y1);
  d.link = link;
  d.depth = depth;
  d.prob = prob * m.prob;
  return (link & QT_LEAF_BIT) != 0u && link != QT_EMPTY;
}

// ---- Rejection in the leaf ------------------------------------------------------------------------

// The proposal of a leaf, as its trials read it: the leaf's envelope and box (quadtree_layout.h,
// QuadLeaf) with what every trial would otherwise recompute (exp(-|k|) of the slopes; the polar
// box's squared cosines, powers and mixture weight), and the side of the disc.
struct QuadProposal {
  vec4 box;   // the descent's square (x0, x1, y0, y1)
  vec4 pbox;  // polar: (c0^2, c1^2, t0, t1) = (u0, u1, p0, p1)
  vec4 env;   // (A, k1, k2, B)
  vec4 aux;   // (exp(-|k1|), exp(-|k2|), s, pE: probability of the exponential part)
  vec4 rim;   // (g0, g1: c0^(2 - s), c1^(2 - s), side, kind as a float)
};
STATIC_ASSERT_SIZE(QuadProposal, 80);

SHARED_FN QuadProposal quadLeafProposal(QuadDescent d, float side) {
  QuadLeaf L = QT_LEAF(d.link & ~QT_LEAF_BIT);
  uint kind = uint(L.data.z + 0.5f);
  float A = L.data.x;
  float s = L.data.w;
  float k1 = L.env.x;
  float k2 = L.env.y;
  float B = L.env.z;
  bool polar = kind != QT_PROPOSAL_SQUARE;
  // Polar box: cos theta in [c0, c1], phi / pi in [p0, p1]; the exponential part is uniform in
  // (c^2, phi) times its slopes, the cos^-s part has disc density ~ c^-s: c^(2-s) uniform.
  float c0 = L.box.x;
  float c1 = L.box.y;
  float u0 = c0 * c0;
  float u1 = c1 * c1;
  float pE = 1.0f;
  float g0 = 0.0f;
  float g1 = 0.0f;
  if (polar && B > 0.0f) {
    g0 = pow(c0, 2.0f - s);
    g1 = pow(c1, 2.0f - s);
    float wE = A * quadExpMass(k1) * quadExpMass(k2) * 0.5f * (u1 - u0);
    float wB = B * (g1 - g0) / (2.0f - s);
    pE = wE / (wE + wB);
  }
  QuadProposal q;
  q.box = d.box;
  q.pbox = vec4(u0, u1, L.box.z, L.box.w);
  q.env = vec4(A, k1, k2, B);
  q.aux = vec4(quadExpTail(k1), quadExpTail(k2), s, pE);
  q.rim = vec4(g0, g1, side, float(kind));
  return q;
}

// Trial `trial` of the rejection in a leaf: a point wc drawn from the proposal with
// pcg4d(stream + (0, 0, 0, trial)), discarded when outside the leaf's region (evaluated = false),
// else fl = the luminance of f(wc, vk) and e the envelope there; true when accepted (f / e).
SHARED_FN bool quadTrial(uint model, BrdfParams p, vec3 vk, QuadProposal q, uvec4 stream, uint trial, OUT(vec3) wc,
                         OUT(float) fl, OUT(float) e, OUT(bool) evaluated) {
  wc = vec3(0.0f);
  fl = 0.0f;
  e = 0.0f;
  evaluated = false;
  uint kind = uint(q.rim.w);
  bool polar = kind != QT_PROPOSAL_SQUARE;
  float s = q.aux.z;
  float k1 = q.env.y;
  float k2 = q.env.z;
  float B = q.env.w;
  uvec4 h = pcg4d(uvec4(stream.x, stream.y, stream.z, stream.w + trial));
  float a = float(h.x >> 8u) * (1.0f / 16777216.0f);
  float b = float(h.y >> 8u) * (1.0f / 16777216.0f);
  float cc = float(h.z >> 8u) * (1.0f / 16777216.0f);
  float cm = float(h.w >> 8u) * (1.0f / 16777216.0f);
  float x = 0.0f;
  float y = 0.0f;
  float co;
  bool inside = true;
  // The exponential proposal of the square and of the polar box's first part: computed once for
  // both kinds (lavapipe runs every branch body that some lane of the subgroup takes).
  float t1 = quadExpSample(k1, q.aux.x, a);
  float t2 = quadExpSample(k2, q.aux.y, b);
  if (polar) {
    float u0 = q.pbox.x;
    float u1 = q.pbox.y;
    if (cm < q.aux.w) {
      co = sqrt(mix(u0, u1, t1));
    } else {
      co = pow(mix(q.rim.x, q.rim.y, a), 1.0f / (2.0f - s));
      t1 = clamp((co * co - u0) / (u1 - u0), 0.0f, 1.0f);
      t2 = b;
    }
    if (co <= 0.0f) inside = false;
    float r = cosFromSin(co);
    vec2 cs = quadCosSinPi(mix(q.pbox.z, q.pbox.w, t2));
    x = r * cs.x;
    y = r * cs.y;
    if (kind == QT_PROPOSAL_POLAR_CUT && (x < q.box.x || x > q.box.y || y < q.box.z || y > q.box.w)) inside = false;
  } else {
    x = mix(q.box.x, q.box.y, t1);
    y = mix(q.box.z, q.box.w, t2);
    float r2 = x * x + y * y;
    if (r2 >= 1.0f) inside = false;
    co = cosFromSin(sqrt(r2));
  }
  if (!(inside && co > 0.0f)) return false;
  e = q.env.x * exp(k1 * (t1 - 0.5f) + k2 * (t2 - 0.5f));
  if (B > 0.0f) e += B * pow(co, -s);
  wc = vec3(x, y, q.rim.z * co);
  fl = quadEvalLum(model, p, wc, vk);
  evaluated = true;
  return cc * e < fl;
}

// The end of a leaf's rejection (serial or shared): its counters, and the accepted point mirrored
// when the descent says so.
SHARED_FN bool quadLeafSampleEnd(bool violated, bool accepted, uint mirrored, INOUT(vec3) wc) {
  if (violated) QT_COUNT_BOUND_VIOLATION();
  if (!accepted) {
    QT_COUNT_TRIAL_FAILURE();
    return false;
  }
  if (mirrored != 0u) wc.y = -wc.y;
  return true;
}

// Draws the canonical direction wc (mirrored when d says so) in the leaf d reached, with density
// proportional to f(., vk) over the leaf's region (disc measure), and returns fl = the luminance
// of f there (at the unmirrored point: the same value, f being symmetric). Rejection in the same
// leaf (restarting at the root would break proportionality): a trial draws a point from the
// proposal (density proportional to the envelope e); points outside the leaf's region are
// discarded before f is evaluated; the others are accepted with probability f / e. Trial t draws
// from pcg4d(stream + (0, 0, 0, t)): the sample is the first accepted trial. False after
// QT_MAX_TRIALS rejected trials (counted as a trial failure); samples that saw f > e in a trial
// up to the accepted one are counted as bound violations. side = -1: a lower-disc tree
// (QT_SET_TRANSMITS): f is evaluated at, and wc returned as, the point below the surface.
// With subgroups (GLSL stages that define NUSSELT_SUBGROUPS) and a model whose evaluation is
// costly (modelCostlyEval), the lanes share the trials (quadLeafSampleShared below): the same
// first accepted trial, in fewer rounds.
SHARED_FN bool quadLeafSampleSerial(uint model, BrdfParams p, vec3 vk, QuadDescent d, QuadProposal q, uvec4 stream,
                                    OUT(vec3) wc, OUT(float) fl) {
  wc = vec3(0.0f);
  fl = 0.0f;
  uint link = d.link;
  bool accepted = false;
  bool violated = false;
  uint trial = 0u;
  uint evaluations = 0u;
  for (; trial < QT_MAX_TRIALS; ++trial) {
    vec3 w;
    float f;
    float e;
    bool evaluated;
    bool ok = quadTrial(model, p, vk, q, stream, trial, w, f, e, evaluated);
    if (!evaluated) continue;
    ++evaluations;
    wc = w;
    fl = f;
    if (f > e) {
      violated = true;
      QT_REPORT_VIOLATION(link & ~QT_LEAF_BIT, w, f, e);
    }
    if (ok) { accepted = true; break; }
  }
  QT_COUNT_TRIALS(evaluations, trial + 1u, d.depth, link & ~QT_LEAF_BIT, accepted);
  return quadLeafSampleEnd(violated, accepted, d.mirrored, wc);
}

#if !defined(__cplusplus) && defined(NUSSELT_SUBGROUPS)
// Shared trials. A lane whose sample is accepted early would idle while the subgroup's slowest
// lane goes on trying (lavapipe and GPUs run a loop until its last lane leaves): every round,
// each lane runs one trial for one of the samples still open instead, the open samples dealt
// round-robin over the lanes (lane rank r works for open sample r mod k, on that sample's trial
// next + r / k). A sample takes the first accepted of its trials in trial order, which is the
// accepted trial of the serial loop: the same point, bit for bit. The lanes exchange the sample's
// proposal, parameters and stream with subgroupShuffle (on lavapipe one vpermd per component).
// Subgroups of at most 32 lanes (one word of the ballots); wider ones run the serial loop.

// The lane of the n-th (from 0) set bit of m; full: m has the subgroup's every lane (then lane n).
uint quadNthLane(uint m, uint n, bool full) {
  if (full) return n;
  for (uint i = 0u; i < n && i < 32u; ++i) m &= m - 1u;
  return uint(findLSB(m));
}
QuadProposal quadShuffleProposal(QuadProposal q, uint lane) {
  QuadProposal r;
  r.box = subgroupShuffle(q.box, lane);
  r.pbox = subgroupShuffle(q.pbox, lane);
  r.env = subgroupShuffle(q.env, lane);
  r.aux = subgroupShuffle(q.aux, lane);
  r.rim = subgroupShuffle(q.rim, lane);
  return r;
}
BrdfParams quadShuffleParams(BrdfParams p, uint lane) {
  BrdfParams r;
  for (uint i = 0u; i < uint(BRDF_PARAM_VEC4S); ++i) r.v[i] = subgroupShuffle(p.v[i], lane);
  return r;
}

bool quadLeafSampleShared(uint model, BrdfParams p, vec3 vk, QuadDescent d, QuadProposal q, uvec4 stream,
                          OUT(vec3) wc, OUT(float) fl) {
  wc = vec3(0.0f);
  fl = 0.0f;
  uint lane = gl_SubgroupInvocationID;
  uint members = subgroupBallot(true).x;
  uint nMembers = bitCount(members);
  bool full = nMembers == gl_SubgroupSize;
  uint rank = bitCount(members & ((1u << lane) - 1u));
  bool done = false;
  bool accepted = false;
  bool violated = false;
  uint next = 0u;  // the next trial of this lane's sample
  for (uint round = 0u; round < QT_MAX_TRIALS; ++round) {
    uint open = subgroupBallot(!done).x;
    uint k = bitCount(open);
    if (k == 0u) break;
    // The open sample this lane works for, and its trial.
    bool own = k == nMembers;  // every sample open (the first round): each lane its own
    uint target = own ? lane : quadNthLane(open, rank % k, k == gl_SubgroupSize);
    uint trial;
    QuadProposal tq;
    BrdfParams tp;
    vec3 tvk;
    uvec4 ts;
    if (own) {
      trial = next;
      tq = q;
      tp = p;
      tvk = vk;
      ts = stream;
    } else {
      trial = subgroupShuffle(next, target) + rank / k;
      tq = quadShuffleProposal(q, target);
      tp = quadShuffleParams(p, target);
      tvk = subgroupShuffle(vk, target);
      ts = subgroupShuffle(stream, target);
    }
    vec3 tw = vec3(0.0f);
    float tf = 0.0f;
    float te = 0.0f;
    bool evaluated = false;
    bool ok = false;
    if (trial < QT_MAX_TRIALS) ok = quadTrial(model, tp, tvk, tq, ts, trial, tw, tf, te, evaluated);
    uint okMask = subgroupBallot(ok).x;
    uint violMask = subgroupBallot(evaluated && tf > te).x;
    // This lane's sample, if open: its workers are the member lanes of rank openRank + i k, in
    // the order of their trials.
    uint winner = lane;
    bool justAccepted = false;
    if (!done) {
      uint openRank = own ? rank : bitCount(open & ((1u << lane) - 1u));
      uint count = own ? 1u : (nMembers - openRank + k - 1u) / k;
      bool found = false;
      for (uint i = 0u; i < count && !found; ++i) {
        uint w = own ? lane : quadNthLane(members, openRank + i * k, full);
        if (((violMask >> w) & 1u) != 0u) violated = true;
        if (((okMask >> w) & 1u) != 0u) {
          found = true;
          winner = w;
        }
      }
      if (found) {
        done = true;
        accepted = true;
        justAccepted = true;
      } else {
        next += count;
        if (next >= QT_MAX_TRIALS) done = true;
      }
    }
    vec3 ww = subgroupShuffle(tw, winner);
    float wf = subgroupShuffle(tf, winner);
    if (justAccepted) {
      wc = ww;
      fl = wf;
    }
  }
  return quadLeafSampleEnd(violated, accepted, d.mirrored, wc);
}
#endif

SHARED_FN bool quadLeafSample(uint model, BrdfParams p, vec3 vk, QuadDescent d, uvec4 stream, float side, OUT(vec3) wc,
                              OUT(float) fl) {
  QuadProposal q = quadLeafProposal(d, side);
#if !defined(__cplusplus) && defined(NUSSELT_SUBGROUPS)
  if (modelCostlyEval(model) && gl_SubgroupSize <= 32u) return quadLeafSampleShared(model, p, vk, d, q, stream, wc, fl);
#endif
  return quadLeafSampleSerial(model, p, vk, d, q, stream, wc, fl);
}

// ---- Sampling -------------------------------------------------------------------------------------

// Draws w for the known direction v (local frame, v.z > 0) with density quadPdf (returned in
// pdf, per unit solid angle) and returns f = brdfEval(model, p, w, v) (rgb); w may lie below the
// surface for a transmitting set (QT_SET_TRANSMITS). u: two uniform
// numbers (component choice and tree descent); the descent's fresh numbers and the in-leaf
// rejection draw from the stream of u (rngStreamKey(u.x, u.y, 0, RNG_REJECTION_STREAM), rng.h),
// so the sample is a function of u alone. Returns false (w = 0, pdf = 0, f = 0) when v is below
// the surface, the table has no mass, or the rejection failed (quadLeafSample).
SHARED_FN bool quadSample(uint set, uint model, BrdfParams p, vec3 v, vec2 u, OUT(vec3) w, OUT(float) pdf,
                          OUT(vec3) f) {
  w = vec3(0.0f);
  pdf = 0.0f;
  f = vec3(0.0f);
  if (v.z <= 0.0f) return false;
  QuadSet S = QT_SET(set);
  bool aniso = (S.info.w & QT_SET_ANISOTROPIC) != 0u;
  vec4 fr = quadFrame(aniso, v);
  uvec4 idx;
  vec2 ts;
  bool exact = quadGrid(S, quadToCanonical(fr, v), idx, ts);
  float eps = exact ? 0.0f : S.data.x;
  uint np = S.info.z;
  vec3 wc = vec3(0.0f);

  // ---- Component: defensive cosine (probability eps) or one of the neighbouring trees ----
  bool transmits = (S.info.w & QT_SET_TRANSMITS) != 0u;
  float massAll = 0.0f;  // a_up + a_low of the chosen table (transmitting sets)
  float uy = u.y;
  uint chosen = 4u;  // the corner of the chosen tree (quadMixturePdfKnown); 4: the defensive cosine
  float fl = 0.0f;   // the luminance of f(wc, v_k) there
  if (uy < eps) {
    if (transmits) {  // a cosine on either side, 1/2 each
      bool below = u.x >= 0.5f;
      wc = squareToCosineHemisphere(vec2(below ? 2.0f * u.x - 1.0f : 2.0f * u.x, min(uy / eps, NUSSELT_ONE_MINUS_EPS)));
      if (below) wc.z = -wc.z;
    } else {
      wc = squareToCosineHemisphere(vec2(u.x, min(uy / eps, NUSSELT_ONE_MINUS_EPS)));
    }
  } else {
    uy = (uy - eps) / (1.0f - eps);
    chosen = 0u;
    if (uy >= 1.0f - ts.x) { uy = (uy - (1.0f - ts.x)) / ts.x; chosen = 1u; }
    else uy = uy / (1.0f - ts.x);
    if (uy >= 1.0f - ts.y) chosen |= 2u;
    uint ti = quadCornerIndex(S, idx, chosen);
    QuadTable T = QT_TABLE(ti);
    vec3 vk = quadTableDirection(T);
    // Transmitting sets: the lower disc with probability a_low / (a_up + a_low), by what is left of uy.
    float side = 1.0f;
    massAll = T.data.x;
    if (transmits) {
      uy = uy >= 1.0f - ts.y ? (uy - (1.0f - ts.y)) / ts.y : uy / (1.0f - ts.y);
      QuadTable L = QT_TABLE(ti + S.info.y * np);
      massAll = T.data.x + L.data.x;
      if (L.data.x > 0.0f && uy * massAll >= T.data.x) {
        T = L;
        side = -1.0f;
      }
    }
    if (T.data.x <= 0.0f || T.info.x == QT_EMPTY) return false;

    // Further numbers: from `base`, the stream of u, hashed once more per draw. One hash of a key
    // that differs from another key in one component only is strongly correlated with that key's
    // hash (pcg4d mixes the first output little: chi-square 18000 on 2047 dof for lambert, when
    // the descent number and the rejection were keyed on the same pixel key), the double hash is
    // not. Trials use base.w + trial; the descent's fresh numbers base.z ^ const.
    uvec4 base = rngStreamKey(u.x, u.y, 0u, RNG_REJECTION_STREAM);
    QuadDescent d;
    if (!quadDescend(T.info.x, aniso, u.x, uvec4(base.x, base.y, base.z ^ 0x5bd1e995u, base.w), d)) return false;
    if (!quadLeafSample(model, p, vk, d, base, side, wc, fl)) return false;
    if (eps == 0.0f && ts.x == 0.0f && ts.y == 0.0f) {
      // On a table: one component, pdf = f(w, v_k) |cos| / a_k (transmitting: a_up + a_low) with
      // the f already evaluated (at the mirror image for a mirrored sample: the same value, f
      // being symmetric).
      w = quadFromCanonical(fr, wc);
      pdf = fl * abs(wc.z) / massAll;
      f = brdfEval(model, p, w, v);
      return pdf > 0.0f;
    }
  }
  w = quadFromCanonical(fr, wc);
  pdf = quadMixturePdfKnown(S, model, p, idx, ts, eps, wc, chosen, fl);
  f = brdfEval(model, p, w, v);
  return pdf > 0.0f;
}

SHARED_END
#endif
