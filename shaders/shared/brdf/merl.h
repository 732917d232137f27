// merl: a measured isotropic BRDF in the layout of the MERL 100 database (Matusik, Pfister, Brand
// and McMillan, "A Data-Driven Reflectance Model", SIGGRAPH 2003), docs/measured.md:
//   f(wi, wo) = trilinear interpolation of the table at (u_h, u_d, u_p), the Rusinkiewicz
//   half/difference angles of (wi, wo) in table units:
//     u_h = 90 sqrt(theta_h / (pi/2))   in [0, 89] (the format's square-root mapping; clamped)
//     u_d = 90 theta_d / (pi/2)         in [0, 89] (clamped)
//     u_p = 180 phi_d / pi              periodic, period 180 (f(phi_d) = f(phi_d + pi): reciprocity)
//   Node (i, j, k) sits at u = (i, j, k): theta_h = (i/90)^2 90 deg, theta_d = j deg, phi_d = k deg.
//   The table holds rgb per node (already scaled by 1/1500, 1.15/1500, 1.66/1500 and with the
//   format's "not measured" entries filled: src/brdf/merl.cpp), as float.
// The interpolant is linear in each table coordinate within a cell, so its maximum over a box of
// table coordinates lies at a node of the cells the box meets: the quadtree builder bounds f
// exactly from the nodes (src/quadtree/quadtree_build.cpp, merlBound).
// Parameters: the table slot (an integer; on the CPU an index into the process's table store,
// on the GPU into the render's measured-table buffer) and a 48-bit hash of the table's content
// (two 24-bit halves: the quadtree cache key tells two files apart by it, not by the slot).
// Table access: MERL_TABLE_FETCH(slot, i): GLSL reads g.measured (layout.h); C++ the store
// (g_merlTables, filled by src/brdf/merl.cpp); standalone kernels define their own.
#ifndef NUSSELT_BRDF_MERL_H
#define NUSSELT_BRDF_MERL_H
#include "common.h"
SHARED_BEGIN

#define MERL_SLOT 0u
#define MERL_HASH_LO 1u
#define MERL_HASH_HI 2u
#define MERL_THETA_H_RES 90u
#define MERL_THETA_D_RES 90u
#define MERL_PHI_D_RES 180u
#define MERL_NODES (MERL_THETA_H_RES * MERL_THETA_D_RES * MERL_PHI_D_RES)
#define MERL_TABLE_FLOATS (3u * MERL_NODES)  // rgb per node, node index (i * 90 + j) * 180 + k
#define MERL_MAX_TABLES 64u                  // per process (CPU store) and per render (GPU buffer)

#ifdef __cplusplus
inline const float* g_merlTables[MERL_MAX_TABLES] = {};
#define MERL_TABLE_FETCH(slot, i) (::nusselt::shared::g_merlTables[slot][i])
#elif !defined(MERL_TABLE_FETCH)
#define MERL_TABLE_FETCH(slot, i) (g.measured.v[(slot) * MERL_TABLE_FLOATS + (i)])
#endif

// The table coordinates (u_h, u_d, u_p) of a pair of directions above the surface (the format's
// std_coords_to_half_diff_coords, with wi as its "in"): h = normalize(wi + wo); d = wi in the
// frame (t, b, h), t = dh/dtheta_h, b = z x h / |z x h| (t = x, b = y at h = z). Angles through the
// portable atan2 (docs: same on CPU and GPU), u_p in [0, 180).
SHARED_FN vec3 merlCoordinates(vec3 wi, vec3 wo) {
  vec3 h = normalize(wi + wo);
  float s = sqrt(h.x * h.x + h.y * h.y);
  vec3 t = vec3(1.0f, 0.0f, 0.0f);
  vec3 b = vec3(0.0f, 1.0f, 0.0f);
  if (s > 1e-12f) {
    t = vec3(h.x * h.z / s, h.y * h.z / s, -s);
    b = vec3(-h.y / s, h.x / s, 0.0f);
  }
  float dx = dot(wi, t);
  float dy = dot(wi, b);
  float dz = dot(wi, h);
  float thetaH = portableAtan2(s, h.z);
  float thetaD = portableAtan2(sqrt(dx * dx + dy * dy), dz);
  float phiD = portableAtan2(dy, dx);
  float uh = 90.0f * sqrt(max(thetaH, 0.0f) * (2.0f / NUSSELT_PI));
  float ud = thetaD * (180.0f / NUSSELT_PI);
  float up = phiD * (180.0f / NUSSELT_PI);
  if (up < 0.0f) up += 180.0f;
  if (up >= 180.0f) up -= 180.0f;
  return vec3(clamp(uh, 0.0f, 89.0f), clamp(ud, 0.0f, 89.0f), clamp(up, 0.0f, 179.99998f));
}

SHARED_FN vec3 merlNode(uint slot, uint i, uint j, uint k) {
  uint n = 3u * ((i * MERL_THETA_D_RES + j) * MERL_PHI_D_RES + k);
  return vec3(MERL_TABLE_FETCH(slot, n), MERL_TABLE_FETCH(slot, n + 1u), MERL_TABLE_FETCH(slot, n + 2u));
}

// Trilinear interpolation of the table at table coordinates u (merlCoordinates).
SHARED_FN vec3 merlLookup(uint slot, vec3 u) {
  uint i0 = min(uint(u.x), MERL_THETA_H_RES - 2u);
  uint j0 = min(uint(u.y), MERL_THETA_D_RES - 2u);
  uint k0 = min(uint(u.z), MERL_PHI_D_RES - 1u);
  uint k1 = k0 + 1u == MERL_PHI_D_RES ? 0u : k0 + 1u;  // phi_d = 180 deg is node 0 again
  float fi = u.x - float(i0);
  float fj = u.y - float(j0);
  float fk = u.z - float(k0);
  vec3 c00 = mix(merlNode(slot, i0, j0, k0), merlNode(slot, i0, j0, k1), fk);
  vec3 c01 = mix(merlNode(slot, i0, j0 + 1u, k0), merlNode(slot, i0, j0 + 1u, k1), fk);
  vec3 c10 = mix(merlNode(slot, i0 + 1u, j0, k0), merlNode(slot, i0 + 1u, j0, k1), fk);
  vec3 c11 = mix(merlNode(slot, i0 + 1u, j0 + 1u, k0), merlNode(slot, i0 + 1u, j0 + 1u, k1), fk);
  return mix(mix(c00, c01, fj), mix(c10, c11, fj), fi);
}

SHARED_FN vec3 merlEval(BrdfParams p, vec3 wi, vec3 wo) {
  if (wi.z <= 0.0f || wo.z <= 0.0f) return vec3(0.0f);
  uint slot = uint(brdfParam(p, MERL_SLOT) + 0.5f);
  return merlLookup(slot, merlCoordinates(wi, wo));
}

SHARED_END

// ---- Traits read by the model list (models.h) ----
// MERL_DELTA: 0 (evaluated and light-sampled).
// MERL_ANALYTIC: 0: the analytic strategy samples the cosine.
#define MERL_DELTA 0
#define MERL_ANALYTIC 0

#ifdef __cplusplus
#include "../../../src/brdf/model_spec.h"
namespace nusselt::models {
// Measured: no parameters (the table comes from a file: loadMerl, src/brdf/merl.h).
inline void merlSpec(ModelSpec& m) {
  m.name = "merl";
  m.measured = true;
  m.summary = "measured isotropic BRDF in the MERL 100 binary layout, trilinearly interpolated (docs/measured.md)";
}
}  // namespace nusselt::models
#endif

#endif
