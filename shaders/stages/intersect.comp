#version 460
#extension GL_GOOGLE_include_directive : require
// intersect: closest hit for every path in the current ray queue. Hits go to the shade queue of
// their material's model; escaping rays go to the escape queue when the scene has an environment
// (escape.comp), and end otherwise.
#include "shared/stage_common.glsl"
STAGE_PUSH(BounceConstants);

void main() {
  uint queue = pc.bounce & 1u;
  uint idx = gl_GlobalInvocationID.x;
  uint count = queueCount(queue);
  if (idx >= count) return;
  // Rays traced, in all and at this bounce (the queue is complete while it is consumed).
  if (idx == 0u) {
    atomicAdd(g.stats.v[STAT_RAYS], count);
    atomicAdd(g.stats.v[STAT_PER_BOUNCE + min(pc.bounce, STAT_BOUNCE_SLOTS - 1u)], count);
  }
  uint path = queueItem(queue, idx);

  vec3 o = g.pathOrigin.v[path].xyz;
  vec3 d = g.pathDirection.v[path].xyz;
  float t;
  float b1;
  float b2;
  uint tri;
  if (traceClosest(o, d, 0.0f, 3.0e38f, t, b1, b2, tri)) {
    g.pathHit.v[path] = vec4(t, b1, b2, uintBitsToFloat(tri));
    uint material = g.shading.v[tri].info.x;
    queuePush(QUEUE_SHADE_BASE + g.materials.v[material].info.w, path);
  } else if (g.environmentLight != INVALID_INDEX) {
    queuePush(QUEUE_ESCAPE, path);
  }
}
