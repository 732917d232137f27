#version 460
#extension GL_GOOGLE_include_directive : require
// shadow: any-hit test of each queued shadow ray; unoccluded ones add their contribution.
#include "shared/stage_common.glsl"
STAGE_PUSH(BounceConstants);

void main() {
  uint idx = gl_GlobalInvocationID.x;
  uint count = queueCount(QUEUE_SHADOW);
  if (idx >= count) return;
  if (idx == 0u) atomicAdd(g.stats.v[STAT_SHADOW_RAYS], count);
  uint path = queueItem(QUEUE_SHADOW, idx);
  vec4 o = g.shadowOrigin.v[path];
  vec3 d = g.shadowDirection.v[path].xyz;
  if (!traceAny(o.xyz, d, 0.0f, o.w)) g.pathRadiance.v[path].xyz += g.shadowRadiance.v[path].xyz;
}
