#version 460
#extension GL_GOOGLE_include_directive : require
// photon: the start of the path guide's photon pre-pass (docs/guiding.md, "Photon pre-pass"), in
// place of the camera stage: path i of the chunk is photon chunkFirst + i, emitted from a light
// sample and queued as the bounce-0 ray; the trace and shade stages carry it on (the shade stage in
// photon mode: guidePhotons, guiding.h). The photon's power is (throughput) x (its radiance's w):
// the throughput starts at power / luminance(power) (luminance 1, so the throughput roulette acts
// on what the bounces take away, as for a camera path) and w keeps luminance(power).
// Triangle emitters: a uniform point (the light's selection probability as NEE's, lightCdf),
// a cosine-distributed direction about the front normal: power = Le cos / pdf = Le pi area /
// pSelect. Point and spot lights: a uniform direction, power = I falloff 4 pi / pSelect.
// Directional lights and the environment emit no photons (the pass skips them).
#include "shared/stage_common.glsl"

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= g.chunkPaths) return;
  uint photon = g.chunkFirst + i;
  PathKey key = makePathKey(photon, g.sampleIndex, i);
  g.pathInfo.v[i] = uvec4(photon, g.sampleIndex, 0u, 0u);
  g.pathRadiance.v[i] = vec4(0.0f);
  if (g.lightCount == 0u) return;
  float uSel = pathSample1(key, rngDimension(0u, RNG_DIM_LIGHT_SELECT));
  vec2 uPt = pathSample2(key, rngDimension(0u, RNG_DIM_LIGHT_POINT));
  vec2 uDir = pathSample2(key, 0u);
  uint li = selectLight(uSel);
  float pSelect = lightSelectPdf(li);
  if (!(pSelect > 0.0f)) return;
  GpuLight light = g.lights.v[li];
  uint type = light.info.x;
  vec3 origin;
  vec3 dir;
  vec3 power;
  if (type == LIGHT_TRIANGLE) {
    uint tri = light.info.y;
    GpuTriangle t = g.triangles.v[tri];
    vec2 b = squareToTriangle(uPt);
    vec3 y = t.v0.xyz + b.x * t.e1.xyz + b.y * t.e2.xyz;
    vec3 nu = cross(t.e1.xyz, t.e2.xyz);
    float area2 = length(nu);
    if (!(area2 > 0.0f)) return;
    vec3 ny = nu / area2;
    vec3 tt;
    vec3 bb;
    makeFrame(ny, tt, bb);
    dir = toWorld(squareToCosineHemisphere(uDir), tt, bb, ny);
    origin = offsetRay(y, ny);
    uint material = g.shading.v[tri].info.x;
    power = g.materials.v[material].emission.xyz * (NUSSELT_PI * 0.5f * area2 / pSelect);
  } else if (type == LIGHT_POINT || type == LIGHT_SPOT) {
    float z = 1.0f - 2.0f * uDir.x;
    float r = sqrt(max(0.0f, 1.0f - z * z));
    float phi = 2.0f * NUSSELT_PI * uDir.y;
    dir = vec3(r * cos(phi), r * sin(phi), z);
    origin = light.position.xyz;
    float falloff = 1.0f;
    if (type == LIGHT_SPOT) {
      float cd = dot(dir, light.direction.xyz);
      float s = clamp((cd - light.cone.y) / max(light.cone.x - light.cone.y, 1e-4f), 0.0f, 1.0f);
      falloff = s * s;
    }
    power = light.intensity.xyz * (falloff * 4.0f * NUSSELT_PI / pSelect);
  } else {
    return;
  }
  float lum = luminance(power);
  if (!(lum > 0.0f) || !isFinite(lum)) return;
  g.pathOrigin.v[i] = vec4(origin, 0.0f);
  g.pathDirection.v[i] = vec4(dir, 0.0f);
  g.pathThroughput.v[i] = vec4(power / lum, 1.0f);
  g.pathRadiance.v[i] = vec4(0.0f, 0.0f, 0.0f, lum);
  queuePush(QUEUE_RAY0, i);
}
