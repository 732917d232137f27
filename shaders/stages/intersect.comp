#version 460
#extension GL_GOOGLE_include_directive : require
// intersect: the trace stage of bounce b, one dispatch for both kinds of ray of that bounce:
// - the closest hit of every path in ray queue b & 1. Hits go to the shade queue of their
//   material's model; escaping rays go to the escape queue when the scene has an environment
//   (escape.comp), and end otherwise;
// - the any-hit test of every shadow ray that shade(b - 1) queued (shadow queue (b - 1) & 1):
//   unoccluded ones add their contribution to their path's radiance.
// Each half of the dispatch takes half of the ray workgroups, then half of the shadow ones (main;
// the dispatch size, ARGS_TRACE0 + (b & 1), counts both: queuePush). One dispatch and one barrier
// fewer per bounce than a shadow stage of its own; a workgroup is all of one kind, so no group
// pays for both. Timed renders (--time-stages, bench render) dispatch the two kinds separately
// (pc.traceMode) to report their GPU times apart.
#include "shared/stage_common.glsl"
STAGE_PUSH(BounceConstants);

void traceRay(uint queue, uint idx) {
  uint count = queueCount(queue);
  if (idx >= count) return;
  // Rays traced, in all and at this bounce (the queue is complete while it is consumed).
  if (idx == 0u) {
    atomicAdd(g.stats.v[STAT_RAYS], count);
    atomicAdd(g.stats.v[STAT_PER_BOUNCE + min(pc.bounce, STAT_BOUNCE_SLOTS - 1u)], count);
  }
  uint path = queueItem(queue, idx);

  vec3 o = loadVec4(g.pathOrigin, path).xyz;
  vec3 d = loadVec4(g.pathDirection, path).xyz;
  float t;
  float b1;
  float b2;
  uint tri;
  if (traceClosest(o, d, 0.0f, 3.0e38f, t, b1, b2, tri)) {
    storeVec4(g.pathHit, path, vec4(t, b1, b2, uintBitsToFloat(tri)));
    uint material = g.shading.v[tri].info.x;
    queuePush(QUEUE_SHADE_BASE + g.materials.v[material].info.w, path);
  } else if (g.environmentLight != INVALID_INDEX) {
    queuePush(QUEUE_ESCAPE, path);
  }
}

void traceShadow(uint queue, uint idx) {
  uint count = queueCount(queue);
  if (idx >= count) return;
  if (idx == 0u) atomicAdd(g.stats.v[STAT_SHADOW_RAYS], count);
  uint path = queueItem(queue, idx);
  vec4 o = loadVec4(g.shadowOrigin, path);
  vec3 d = loadVec4(g.shadowDirection, path).xyz;
  if (!traceAny(o.xyz, d, 0.0f, o.w)) {
    vec4 R = loadVec4(g.pathRadiance, path);
    storeVec4(g.pathRadiance, path, vec4(R.xyz + loadVec4(g.shadowRadiance, path).xyz, R.w));
  }
}

void main() {
  uint rayQueue = pc.bounce & 1u;
  uint shadowQueue = QUEUE_SHADOW0 + ((pc.bounce + 1u) & 1u);
  uint rayGroups = 0u;
  if (pc.traceMode != TRACE_SHADOWS) rayGroups = (queueCount(rayQueue) + WORKGROUP_SIZE - 1u) / WORKGROUP_SIZE;
  uint group = gl_WorkGroupID.x;
  if (pc.traceMode == TRACE_BOTH) {
    // Each half of the dispatch takes half of the ray groups, then half of the shadow groups (the
    // first half the first ones, which the queue shards fill from the pushes of the previous
    // stage's first half): lavapipe's threads take contiguous halves of a dispatch, and rays
    // first, shadow rays after left the thread with the closest hits busy long after the other
    // (docs/performance.md, "Queue shards"). The dispatch counts the groups of both shards of
    // both queues, so it can hold a few more groups than ceil(count / WORKGROUP_SIZE) of each
    // kind; their lanes return in traceRay or traceShadow.
    uint half0 = gl_NumWorkGroups.x / 2u;  // groups in half 0 (dispatchHalf)
    uint rays0 = rayGroups / 2u;
    uint h = dispatchHalf();
    uint p = group - h * half0;
    uint raysHere = h == 0u ? rays0 : rayGroups - rays0;
    if (p < raysHere) traceRay(rayQueue, (h * rays0 + p) * WORKGROUP_SIZE + gl_LocalInvocationID.x);
    else traceShadow(shadowQueue, (h * (half0 - rays0) + p - raysHere) * WORKGROUP_SIZE + gl_LocalInvocationID.x);
    return;
  }
  if (group < rayGroups) traceRay(rayQueue, gl_GlobalInvocationID.x);
  else if (pc.traceMode != TRACE_RAYS) traceShadow(shadowQueue, (group - rayGroups) * WORKGROUP_SIZE + gl_LocalInvocationID.x);
}
