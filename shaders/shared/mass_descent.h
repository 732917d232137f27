// mass_descent.h: descending a tree of four-child nodes in proportion to their masses, with one
// uniform number, shared by the quadtree sampler (quadtree.h, quadDescend) and the path guide's
// directional trees (guiding.h, guideSquareDescend). The trees differ in how a node is read and what a
// child link means; the step below is what they have in common: the choice of a child, the
// rescaling of the number, and the fresh numbers that take over when it runs out of resolution.
#ifndef NUSSELT_MASS_DESCENT_H
#define NUSSELT_MASS_DESCENT_H
#include "prelude.h"
#include "rng.h"
SHARED_BEGIN

// Child of a node with masses m chosen with the uniform number u in [0, 1), which is rescaled to
// the chosen child's share (one number serves several levels). t = u * total falls in
// [m0 + .. + m(c-1), m0 + .. + mc) in float arithmetic; a child whose interval is empty in floats
// (a mass below the rounding of its predecessors') is never chosen. When rounding puts t at or
// beyond the total, the heaviest child is taken: never a negligible one (which an earlier version
// of the quadtree's descent picked about once per 2^24 descents). share = the chosen child's mass
// / the node's (0: the node has no mass; then u is unchanged and child 0 is returned).
SHARED_FN uint massPickChild(vec4 m, INOUT(float) u, OUT(float) share) {
  float total = m.x + m.y + m.z + m.w;
  share = 0.0f;
  if (!(total > 0.0f)) return 0u;
  float t = u * total;
  float e1 = m.x;
  float e2 = m.x + m.y;
  float e3 = m.x + m.y + m.z;
  uint c;
  float below;
  if (t < e1) { c = 0u; below = 0.0f; }
  else if (t < e2) { c = 1u; below = e1; }
  else if (t < e3) { c = 2u; below = e2; }
  else if (t < total) { c = 3u; below = e3; }
  else {
    c = 0u;
    if (m.y > m[c]) c = 1u;
    if (m.z > m[c]) c = 2u;
    if (m.w > m[c]) c = 3u;
    below = t - m[c];
  }
  u = clamp((t - below) / m[c], 0.0f, NUSSELT_ONE_MINUS_EPS);
  share = m[c] / total;
  return c;
}

// A descent in progress. The rescaled number keeps 24 bits of resolution relative to the
// probability of the choices it made: once that probability falls below 2^-10 a fresh number
// takes over (an exact choice as well), so that a child far below 2^-24 of the total keeps its
// odds. The fresh number of level l is the first output of pcg4d(stream + (0, 0, 0, l)), stream a
// key of the caller's own (hashed from its numbers, never equal to a key of its other draws).
struct MassDescent {
  float u;          // the number, rescaled at each level
  float pathShare;  // probability of the choices since u was last fresh
  float prob;       // probability of every choice of the descent (the product of the shares)
  uint level;       // level of the next node (root: 0)
};
STATIC_ASSERT_SIZE(MassDescent, 16);

SHARED_FN MassDescent massDescentStart(float u) {
  MassDescent d;
  d.u = u;
  d.pathShare = 1.0f;
  d.prob = 1.0f;
  d.level = 0u;
  return d;
}

// One level: the child of the node with masses m (its index; share 0 when the node has no mass,
// which ends a descent).
SHARED_FN uint massDescendStep(vec4 m, uvec4 stream, INOUT(MassDescent) d, OUT(float) share) {
  if (d.pathShare < 1.0f / 1024.0f) {
    uvec4 h = pcg4d(uvec4(stream.x, stream.y, stream.z, stream.w + d.level));
    d.u = float(h.x >> 8u) * (1.0f / 16777216.0f);
    d.pathShare = 1.0f;
  }
  uint c = massPickChild(m, d.u, share);
  d.pathShare *= share;
  d.prob *= share;
  d.level += 1u;
  return c;
}

SHARED_END
#endif
