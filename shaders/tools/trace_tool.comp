#version 460
#extension GL_GOOGLE_include_directive : require
// trace_tool: both scene queries on given rays, for the tests that hold the ray-query traversal
// against the GLSL BVH (compiled as trace_tool and trace_tool_rq, like intersect and shadow).
// Inputs and outputs: TraceToolConstants in shared/layout.h.
#include "shared/stage_common.glsl"
STAGE_PUSH(TraceToolConstants);

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.count) return;
  vec4 o = g.shadowOrigin.v[i];
  vec3 d = g.shadowDirection.v[i].xyz;
  float t;
  float b1;
  float b2;
  uint tri;
  bool hit = traceClosest(o.xyz, d, 0.0f, o.w, t, b1, b2, tri);
  g.pathHit.v[i] = vec4(t, b1, b2, uintBitsToFloat(tri));
  g.pathInfo.v[i] = uvec4(traceAny(o.xyz, d, 0.0f, o.w) ? 1u : 0u, hit ? 1u : 0u, 0u, 0u);
}
