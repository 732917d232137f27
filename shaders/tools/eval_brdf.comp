#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_scalar_block_layout : require
// eval_brdf: evaluates one model (specialization constant MODEL) at a list of direction pairs:
// the GPU side of the CPU/GPU parity test of the shared BRDF definitions.
#define NUSSELT_STANDALONE_KERNEL
#include "shared/layout.h"

layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer PairBuffer { vec4 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer ParamBuffer { BrdfParams p; };
layout(buffer_reference, std430, buffer_reference_align = 16) writeonly buffer ResultBuffer { vec4 v[]; };
layout(push_constant, std430) uniform Push {
  PairBuffer pairs;    // 2 vec4 per pair: wi, wo (local frame)
  ParamBuffer params;
  ResultBuffer result; // f(wi, wo), rgb
  uint count;
  Floats measured;     // measured tables (merl), or 0
} pcEval;
#define MERL_TABLE_FETCH(slot, i) (pcEval.measured.v[(slot) * MERL_TABLE_FLOATS + (i)])
#include "shared/brdf/dispatch.h"

layout(local_size_x = WORKGROUP_SIZE) in;
layout(constant_id = 0) const uint MODEL = 0u;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pcEval.count) return;
  vec3 wi = pcEval.pairs.v[2u * i].xyz;
  vec3 wo = pcEval.pairs.v[2u * i + 1u].xyz;
  pcEval.result.v[i] = vec4(brdfEval(MODEL, pcEval.params.p, wi, wo), 0.0f);
}
