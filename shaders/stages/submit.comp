#version 460
#extension GL_GOOGLE_include_directive : require
// submit: one small workgroup between stages. Turns queue counts into indirect dispatch sizes
// (count -> ceil(count / WORKGROUP_SIZE) groups), tallies traced rays, and empties the queues
// the previous stage consumed (zeux/niagara's tasksubmit pattern).
#include "shared/stage_common.glsl"
STAGE_PUSH(SubmitConstants);

void writeArgs(uint queue) {
  uint count = g.queues.v[queue];
  g.dispatchArgs.v[queue] = uvec4((count + WORKGROUP_SIZE - 1u) / WORKGROUP_SIZE, 1u, 1u, 0u);
  if (queue == QUEUE_RAY0 || queue == QUEUE_RAY1) {
    atomicAdd(g.stats.v[STAT_RAYS], count);
    atomicAdd(g.stats.v[STAT_PER_BOUNCE + min(pc.bounce, STAT_BOUNCE_SLOTS - 1u)], count);
  }
  if (queue == QUEUE_SHADOW) atomicAdd(g.stats.v[STAT_SHADOW_RAYS], count);
}

void main() {
  uint t = gl_LocalInvocationID.x;
  if (t == 0u && pc.argsQueue != INVALID_INDEX) writeArgs(pc.argsQueue);
  for (uint q = t; q < pc.argsCount; q += WORKGROUP_SIZE) writeArgs(pc.argsFirst + q);
  // Zero after reading: the zeroed range never overlaps the ranges read above.
  for (uint q = t; q < pc.zeroCount; q += WORKGROUP_SIZE) g.queues.v[pc.zeroFirst + q] = 0u;
}
