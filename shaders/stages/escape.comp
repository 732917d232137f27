#version 460
#extension GL_GOOGLE_include_directive : require
// escape: rays that left the scene (the escape queue, filled by intersect) pick up the
// environment's radiance in their direction, weighted by MIS against light sampling of the
// environment: the power heuristic of the BSDF sampler's pdf of the ray's direction (path
// direction w: the pdf it was drawn with, or after a guided sample the BRDF sampler's, which
// NEE's weight uses too: shade_body.glsl, shadeMisPdf) and the pdf with which NEE would have
// drawn it (selection probability x envPdf). Camera rays and
// rays after a delta lobe (pdf 0) take weight 1. Dispatched only when the scene has an
// environment (Globals.environmentLight != INVALID_INDEX).
#include "shared/stage_common.glsl"
STAGE_PUSH(BounceConstants);

void main() {
  uint idx = gl_GlobalInvocationID.x;
  if (idx >= queueCount(QUEUE_ESCAPE)) return;
  uint path = queueItem(QUEUE_ESCAPE, idx);
  if (GUIDING && guidePhotons()) return;  // a photon that left the scene: nothing to record
  if (GUIDING) guideRecordArrival(path, pc.bounce, vec3(0.0f));  // training record (guiding.h)
  vec4 rayD = loadVec4(g.pathDirection, path);
  vec3 dir = rayD.xyz;
  float prevPdf = rayD.w;
  GpuEnvironment E = g.environment.v[0];

  // ---- MIS weight: the BSDF sample against light sampling of the environment ----
  float w = 1.0f;
  if (pc.bounce > 0u && prevPdf > 0.0f) {
    if (g.lighting == LIGHTING_NEE_ONLY) {
      w = 0.0f;
    } else if (g.lighting == LIGHTING_MIS) {
      float lightPdf = lightSelectPdf(g.environmentLight) * envPdf(E, dir);
      w = powerHeuristic(prevPdf, lightPdf);
    }
  }
  // Caustic light (layout.h, RADIANCE_CAUSTIC): after a delta bounce (pdf 0) that followed a
  // non-delta one, its path's first (pathOrigin.w = 1: shade_body.glsl).
  bool caustic = g.radiancePart >= RADIANCE_CAUSTIC && pc.bounce > 0u && prevPdf == 0.0f && g.pathOrigin.v[path].w == 1.0f;
  if (w > 0.0f && radiancePartKeeps(g.radiancePart, pc.bounce, caustic)) {
    vec3 beta = loadVec4(g.pathThroughput, path).xyz;
    vec4 R = loadVec4(g.pathRadiance, path);
    storeVec4(g.pathRadiance, path, vec4(R.xyz + beta * envRadiance(E, dir) * w, R.w));
  } else if (PRIMARY_SAMPLES && w > 0.0f && g.radiancePart == RADIANCE_NONCAUSTIC && caustic) {
    // The caustic light a Metropolis pass leaves to the chains: its luminance in w (shade_body.glsl).
    vec3 beta = loadVec4(g.pathThroughput, path).xyz;
    vec4 R = loadVec4(g.pathRadiance, path);
    storeVec4(g.pathRadiance, path, vec4(R.xyz, luminance(max(beta * envRadiance(E, dir) * w, vec3(0.0f)))));
  }
}
