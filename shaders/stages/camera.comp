#version 460
#extension GL_GOOGLE_include_directive : require
// camera: one primary ray per path of this chunk; initialises the path state and fills ray
// queue 0 with every path. Path i of the chunk traces sample k = (chunkFirst + i) % passSamples
// (sample index sampleIndex + k) of pixel (chunkFirst + i) / passSamples.
#include "shared/stage_common.glsl"

// Metropolis (issue 19, docs/mlt.md; constant 12, with PRIMARY_SAMPLES): draw 0 places the ray
// anywhere on the image and the path's pixel follows from it, so a chain moves across pixels.
layout(constant_id = 12) const bool IMAGE_SAMPLES = false;

// The slot of path i in ray queue 0: blocks of CAMERA_BLOCK paths (contiguous in memory and in
// the image) dealt out with stride CAMERA_BLOCK_STRIDE, so that each half of the first trace
// dispatch, and each thread's share of it on lavapipe (which gives its threads contiguous blocks
// of a dispatch's workgroups), holds paths from every part of the image: otherwise the thread that
// gets the image's costlier half (the dragon, the glass sphere) leaves the other idle, at this
// bounce and, through the queue shards (layout.h), at the next. The blocks of a whole number of
// strides are dealt; the rest keep their places. A permutation of the queue only: every path keeps
// its index, pixel and numbers, so images are unchanged.
const uint CAMERA_BLOCK = 16u * WORKGROUP_SIZE;
const uint CAMERA_BLOCK_STRIDE = 8u;
uint cameraQueueSlot(uint i) {
  uint blocks = (g.chunkPaths / (CAMERA_BLOCK * CAMERA_BLOCK_STRIDE)) * CAMERA_BLOCK_STRIDE;
  uint b = i / CAMERA_BLOCK;
  if (b >= blocks) return i;
  uint dealt = (b % CAMERA_BLOCK_STRIDE) * (blocks / CAMERA_BLOCK_STRIDE) + b / CAMERA_BLOCK_STRIDE;
  return dealt * CAMERA_BLOCK + i % CAMERA_BLOCK;
}

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= g.chunkPaths) return;
  uint global = g.chunkFirst + i;
  uint pixel = global / g.passSamples;
  uint sampleIndex = g.sampleIndex + global % g.passSamples;
  uint width = g.width;
  uint px = pixel % width;
  uint py = pixel / width;

  // Pixel jitter: dimensions 0 and 1 (box filter over the pixel).
  vec2 u = pathSample2(makePathKey(pixel, sampleIndex, i), 0u);
  if (IMAGE_SAMPLES) {
    vec2 xy = u * vec2(float(width), float(g.height));
    px = min(uint(xy.x), width - 1u);
    py = min(uint(xy.y), g.height - 1u);
    u = clamp(xy - vec2(float(px), float(py)), 0.0f, 1.0f);
    pixel = py * width + px;
  }
  float sx = ((float(px) + u.x) / float(width)) * 2.0f - 1.0f;
  float sy = 1.0f - ((float(py) + u.y) / float(g.height)) * 2.0f;

  vec3 origin;
  vec3 dir;
  if (g.camPosition.w > 0.5f) {  // orthographic
    origin = g.camPosition.xyz + sx * g.camRight.xyz + sy * g.camUp.xyz;
    dir = g.camForward.xyz;
  } else {
    origin = g.camPosition.xyz;
    dir = normalize(g.camForward.xyz + sx * g.camRight.xyz + sy * g.camUp.xyz);
  }

  storeVec4(g.pathOrigin, i, vec4(origin, 0.0f));
  storeVec4(g.pathDirection, i, vec4(dir, 0.0f));  // w = 0: no BSDF pdf yet (camera ray)
  storeVec4(g.pathThroughput, i, vec4(1.0f, 1.0f, 1.0f, 1.0f));  // w: etaScale
  storeVec4(g.pathRadiance, i, vec4(0.0f));
  storeUVec4(g.pathInfo, i, uvec4(pixel, sampleIndex, 0u, 0u));
  if (GUIDING) guideRecordStart(i);  // a training pass's first record (guiding.h)
  g.queues.v[QUEUE_HEADER_UINTS + QUEUE_RAY0 * g.pathCapacity + cameraQueueSlot(i)] = i;
  if (i == 0u) {
    g.queues.v[QUEUE_RAY0] = g.chunkPaths;
    g.dispatchArgs.v[QUEUE_RAY0] = uvec4((g.chunkPaths + WORKGROUP_SIZE - 1u) / WORKGROUP_SIZE, 1u, 1u, 0u);
    g.dispatchArgs.v[ARGS_TRACE0] = g.dispatchArgs.v[QUEUE_RAY0];
  }
}
