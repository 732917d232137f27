#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_scalar_block_layout : require
// env_tool: the environment's shared functions (shaders/shared/envmap.h) on the device, for the
// CPU/GPU parity test: for input i, a sample from the uniform pair (u.x, u.y) and the density and
// radiance in the direction d.
#define NUSSELT_STANDALONE_KERNEL
#include "shared/envmap.h"

layout(local_size_x = WORKGROUP_SIZE) in;

layout(push_constant, std430) uniform Push {
  Environments env;  // one GpuEnvironment
  Vec4s inputs;      // 2 vec4 per item: (u.x, u.y, 0, 0), (d, 0)
  Vec4s result;      // 3 vec4 per item: (sampled direction, its pdf), (envPdf(d), 0, 0, 0), (envRadiance(d), 0)
  uint count;
} pcEnv;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pcEnv.count) return;
  GpuEnvironment E = pcEnv.env.v[0];
  vec4 u = pcEnv.inputs.v[2u * i];
  vec3 d = pcEnv.inputs.v[2u * i + 1u].xyz;
  float pdf;
  vec3 s = envSample(E, vec2(u.x, u.y), pdf);
  pcEnv.result.v[3u * i] = vec4(s, pdf);
  pcEnv.result.v[3u * i + 1u] = vec4(envPdf(E, d), 0.0f, 0.0f, 0.0f);
  pcEnv.result.v[3u * i + 2u] = vec4(envRadiance(E, d), 0.0f);
}
