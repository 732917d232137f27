#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_buffer_reference : require
#extension GL_EXT_scalar_block_layout : require
// texture_tool: the shared texture lookup (shaders/shared/texture.h) on the device, for the
// CPU/GPU parity test: for input i = (u, v, texture index, 0), the lookup of that texture at (u, v).
#define NUSSELT_STANDALONE_KERNEL
#include "shared/texture.h"

layout(local_size_x = WORKGROUP_SIZE) in;

layout(push_constant, std430) uniform Push {
  Textures textures;
  Uints texels;
  Vec4s inputs;
  Vec4s result;
  uint count;
} pcTex;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pcTex.count) return;
  vec4 in4 = pcTex.inputs.v[i];
  GpuTexture t = pcTex.textures.v[uint(in4.z)];
  pcTex.result.v[i] = textureLookup(pcTex.texels, t, vec2(in4.x, in4.y));
}
